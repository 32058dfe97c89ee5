/* lubkit run control (see control.h). */
#include "io/control.h"

#include <math.h>
#include <stdlib.h>

#include "core/error.h"

void lub_control_read(lub_control *c, const char *path)
{
    static const char *const start[] = {"startTime", "latestTime", NULL};
    static const char *const stop[] = {"endTime", "nSteps", NULL};
    static const char *const wctl[] = {"runTime", "timeStep", NULL};
    c->dict = lub_dict_read(path);
    lub_node *r = lub_dict_root(c->dict);
    c->application = lub_dict_str_or(r, "application", "lubFoam");
    c->start_from = lub_dict_choice(r, "startFrom", start, LUB_START_LATESTTIME);
    c->start_time = lub_dict_real_or(r, "startTime", 0.0, LUB_NONNEGATIVE);
    c->stop_at = lub_dict_choice(r, "stopAt", stop, LUB_STOP_ENDTIME);
    if (c->stop_at == LUB_STOP_ENDTIME)
        c->end_time = lub_dict_real(r, "endTime", LUB_NONNEGATIVE);
    else
        c->end_time = lub_dict_real_or(r, "endTime", INFINITY, LUB_NONNEGATIVE);
    c->n_steps = lub_dict_int_or(r, "nSteps", 0, 0, 1000000000000L);
    if (c->stop_at == LUB_STOP_NSTEPS && c->n_steps < 1)
        lub_node_error(lub_dict_find(r, "stopAt"), "stopAt: nSteps needs 'nSteps' >= 1");
    c->delta_t = lub_dict_real(r, "deltaT", LUB_POSITIVE);
    c->adjust_time_step = lub_dict_bool_or(r, "adjustTimeStep", 0);
    c->max_courant = lub_dict_real_or(r, "maxCourant", 0.24, LUB_BETWEEN(1e-6, 10.0));
    c->max_diffusion = lub_dict_real_or(r, "maxDiffusion", 0.5, LUB_POSITIVE);
    c->write_control = lub_dict_choice(r, "writeControl", wctl, LUB_WRITE_RUNTIME);
    c->write_interval = lub_dict_real(r, "writeInterval", LUB_POSITIVE);
    if (c->write_control == LUB_WRITE_TIMESTEP) {
        lub_node *w = lub_dict_find(r, "writeInterval");
        if (c->write_interval != floor(c->write_interval))
            lub_node_error(w, "'writeInterval' must be a whole number of steps with "
                              "writeControl: timeStep, found '%s'",
                           lub_node_text(w));
    }
    c->purge_write = (int)lub_dict_int_or(r, "purgeWrite", 0, 0, 1000000);
    c->time_precision = (int)lub_dict_int_or(r, "timePrecision", 6, 1, 17);
    c->log_interval = lub_dict_int_or(r, "logInterval", 100, 1, 1000000000L);
    c->functions = lub_dict_map_or(r, "functions");
    if (c->stop_at == LUB_STOP_ENDTIME && c->end_time < c->start_time)
        lub_node_error(lub_dict_find(r, "endTime"), "'endTime' (%g) is before 'startTime' (%g)",
                       c->end_time, c->start_time);
}

void lub_control_free(lub_control *c)
{
    lub_dict_free(c->dict);
    c->dict = NULL;
}

int lub_control_write_due(const lub_control *c, double t0, double t, long step0, long step,
                          double dt)
{
    if (c->write_control == LUB_WRITE_TIMESTEP) {
        long every = (long)c->write_interval;
        return (step - step0) % every == 0;
    }
    /* the write grid is t0 + k writeInterval: due when this step crossed a grid point */
    double k_now = floor((t - t0) / c->write_interval + 1e-3 * dt / c->write_interval);
    double k_before =
        floor((t - dt - t0) / c->write_interval + 1e-3 * dt / c->write_interval);
    return k_now > k_before && k_now >= 1;
}

int lub_control_finished(const lub_control *c, double t, long steps_done, double dt)
{
    if (c->stop_at == LUB_STOP_NSTEPS) return steps_done >= c->n_steps;
    return t >= c->end_time - 1e-3 * dt;
}
