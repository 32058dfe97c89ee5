/* lubkit run control: system/controlDict.yaml (OpenFOAM's names, design.md).
 *
 *     application:    lubFoam
 *     startFrom:      latestTime      # startTime | latestTime
 *     startTime:      0
 *     stopAt:         endTime         # endTime | nSteps
 *     endTime:        0.03
 *     nSteps:         0               # with stopAt: nSteps
 *     deltaT:         1.0e-6
 *     adjustTimeStep: false           # true: dt from maxCourant, at most deltaT
 *     maxCourant:     0.24
 *     maxDiffusion:   0.5             # limit of nu dt / l0^2 with explicit viscosity
 *     writeControl:   runTime         # runTime | timeStep
 *     writeInterval:  0.001           # seconds (runTime) or steps (timeStep)
 *     purgeWrite:     0               # keep only the last N written times (0: all)
 *     timePrecision:  6
 *     logInterval:    100             # steps between log lines (a terminal also gets a bar)
 *     functions:      { ... }         # function objects, read by the solver
 *
 * Write times are kept on an exact grid: with runTime the k-th write happens at the first
 * step whose time reaches start + k writeInterval (within dt/1000), so round-off in the
 * accumulated time never skips or doubles a write.
 */
#ifndef LUB_IO_CONTROL_H
#define LUB_IO_CONTROL_H

#include "io/dict.h"

enum { LUB_START_STARTTIME, LUB_START_LATESTTIME };
enum { LUB_STOP_ENDTIME, LUB_STOP_NSTEPS };
enum { LUB_WRITE_RUNTIME, LUB_WRITE_TIMESTEP };

typedef struct {
    lub_dict *dict;     /* kept open: the solver reads `functions` from it */
    const char *application;
    int start_from;
    double start_time;
    int stop_at;
    double end_time;
    long n_steps;
    double delta_t;
    int adjust_time_step;
    double max_courant;
    double max_diffusion;
    int write_control;
    double write_interval; /* seconds or steps */
    int purge_write;
    int time_precision;
    long log_interval;
    lub_node *functions; /* NULL when absent */
} lub_control;

/* Read controlDict strictly (lub_dict_finish is left to the caller, after `functions` has
 * been read).  Fatal with file:line on bad input. */
void lub_control_read(lub_control *c, const char *path);
void lub_control_free(lub_control *c);

/* 1 when the step just taken (from t - dt to t, ending step `step`) is a write step: with
 * runTime, when it crossed a point of the grid t0 + k writeInterval (k >= 1); with timeStep,
 * every writeInterval steps counted from step0. */
int lub_control_write_due(const lub_control *c, double t0, double t, long step0, long step,
                          double dt);

/* Is the run over at time t / step? */
int lub_control_finished(const lub_control *c, double t, long steps_done, double dt);

#endif
