/* lubkit model elasticWall: the model's operations (models/model.h) around the solver part
 * (elasticWall.h): set-up, the step, its log, its table and its restart state.
 *
 * With the model a table is always written, every max(1, averageSteps / 20) steps (the
 * running mean changes on the scale of averageSteps):
 * postProcessing/elasticWall/<startTime>/elasticWall.dat
 *     # t h0 centre load loadTarget loadTargetMean beta loadInstant vMin vMax gapMin
 * h0 the rigid-body position of T-50, centre = h0 + v(x_c), load the integral of the mean
 * wall pressure (what the load balance sees), loadTarget W(t) (T-53), loadTargetMean W(t)
 * in the same running mean (what the balance compares the load with), beta = load /
 * loadTarget - 1, loadInstant the integral of the wall pressure of the step, v the elastic
 * displacement, gapMin the smallest distance of a wall particle to the surface beneath.
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "io/table.h"
#include "models/elasticWall/elasticWall.h"
#include "models/model.h"
#include "models/multiResolution/levels.h"

typedef struct {
    lub_mps_elastic w;
    FILE *table; /* elasticWall.dat */
    long interval;
} elastic_model;

/* With multiResolution (s->levels, read before this check): what the elastic wall across
 * levels cannot run yet, refused with the entries' lines.  It moves every level's wall each
 * step from one deformation: every level takes the same steps (T-60); it is tested on two
 * levels (tests/cases/softEHLOPT). */
/* The entry read and checked when the scene is read (its fields again at the init, which
 * needs the solvers), so that a bad entry stops a program that only reads the case's
 * dictionaries (lubDict's check of an edit) as it stops lubFoam; after the checks of the
 * combination with multiResolution, which come first. */
static void check_entry(lub_scene *s)
{
    lub_elastic_wall e;
    lub_elastic_wall_read(lub_dict_root(s->dict), s->geo, &e);
}

static void elastic_check(lub_model *m, lub_scene *s)
{
    const lub_levels *L = s->levels;
    if (!L || L->nlevels < 2) {
        check_entry(s);
        return;
    }
    const char *file = L->file[0] ? L->file : "constant/models.yaml";
    if (L->nlevels > 2)
        lub_node_error(m->entry,
                       "model 'elasticWall' with 'multiResolution' (%s:%d) runs on 2 levels "
                       "only, and the case has %d (system/particleGenDict.yaml's levels): the "
                       "elastic wall across more levels is not supported in this version",
                       file, L->line, L->nlevels);
    int nr = 1;
    for (int k = 0; k < L->nlevels - 1; k++)
        if (L->level[k].nr > nr) nr = L->level[k].nr;
    if (nr > 1)
        lub_node_error(m->entry,
                       "model 'elasticWall' with 'multiResolution' needs one time step on every "
                       "level: add 'commonDeltaT: true' to multiResolution (%s:%d; it sub-steps "
                       "with Nr %d): the wall is deformed and moved before every step of every "
                       "level from one pressure field (thesis T-60: dt_coarse = dt_fine)",
                       file, L->line, nr);
    check_entry(s);
}

static void elastic_init(lub_model *m, lub_scene *s)
{
    elastic_model *e = m->state;
    /* every level's part of the wall (elasticWall.h, Multi-resolution) */
    lub_mps_elastic_init_levels(&e->w, s->level, s->nlevels, s->levels, s->geo, s->models_path,
                                s->state_path, s->end_time, s->end_what);
}

static void elastic_header(const lub_model *m, const lub_scene *s)
{
    (void)s;
    const lub_mps_elastic *w = &((const elastic_model *)m->state)->w;
    lub_message("elasticWall: patch %s (%d wall, %d dummy particles), E %g Pa, load %g N/m "
                "over rampTime %g s, b %g m, p_H %g Pa, mean of %ld steps, load balance "
                "alpha %g (at most %g m per step), clamp %g; h0 %.6g m, %ld samples",
                w->e.patch_name, w->nw, w->nd, w->e.E, w->e.load, w->e.ramp_time, w->e.b,
                w->e.p_hertz, w->e.average_steps, w->e.relaxation, w->e.relaxation * w->e.h0,
                w->e.clamp, w->h0, w->samples);
    if (w->nlevels > 1) {
        /* the segments of the deformation and the load: each point of x on one level */
        char lv[128 * LUB_MAX_LEVELS];
        size_t len = 0;
        for (int k = 0; k < w->nlevels && len < sizeof lv; k++) {
            int owned = 0;
            for (int q = 0; q < w->ns; q++) owned += w->src_level[q] == k;
            len += (size_t)snprintf(lv + len, sizeof lv - len,
                                    "%slevel %d: %d wall, %d dummy particles, %d of them "
                                    "pressure segments",
                                    k ? "; " : "", k, w->lv[k].nw, w->lv[k].nd, owned);
        }
        lub_message("elasticWall: %s (the wall pressure where the level owns x; the "
                    "deformation at every wall particle)",
                    lv);
    }
}

static void table_row(elastic_model *e, double t)
{
    const lub_mps_elastic *w = &e->w;
    double row[11] = {t,
                      w->h0,
                      w->centre,
                      w->load,
                      w->load_target,
                      w->target_mean,
                      lub_mps_elastic_beta(w),
                      w->load_instant,
                      w->vmin,
                      w->vmax,
                      w->gap_min};
    lub_table_write_row(e->table, row, 11);
    fflush(e->table);
}

static void elastic_functions_start(lub_model *m, lub_scene *s, const char *start, double t)
{
    elastic_model *e = m->state;
    char path[LUB_PATH_MAX];
    lub_postproc_path(s->cs, "elasticWall", start, "elasticWall.dat", path);
    e->table = fopen(path, "w");
    if (!e->table) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
    lub_table_write_header(e->table, "t[s] h0[m] centre[m] load[N/m] loadTarget[N/m] "
                                     "loadTargetMean[N/m] beta loadInstant[N/m] vMin[m] "
                                     "vMax[m] gapMin[m]");
    long n = e->w.e.average_steps / 20;
    e->interval = n > 1 ? n : 1;
    table_row(e, t);
}

static lub_step_status elastic_before_step(lub_model *m, lub_scene *s, double t, double dt,
                                           char *msg, size_t msgsize)
{
    (void)s;
    return lub_mps_elastic_before(&((elastic_model *)m->state)->w, t, dt, msg, msgsize);
}

static void elastic_after_step(lub_model *m, lub_scene *s, double t)
{
    (void)s;
    lub_mps_elastic_after(&((elastic_model *)m->state)->w, t);
}

static void elastic_functions_execute(lub_model *m, lub_scene *s, double t, long step)
{
    (void)s;
    elastic_model *e = m->state;
    if (e->table && step % e->interval == 0) table_row(e, t);
}

/* The load error and position, for the log line. */
static void elastic_log(const lub_model *m, const lub_scene *s, char *buf, size_t size)
{
    (void)s;
    const lub_mps_elastic *w = &((const elastic_model *)m->state)->w;
    snprintf(buf, size, "  load %.4g/%.4g N/m (%+.2f%%) h0 %.5g m", w->load, w->load_target,
             100.0 * lub_mps_elastic_beta(w), w->h0);
}

static void elastic_write_state(const lub_model *m, const lub_scene *s, FILE *fp)
{
    (void)s;
    lub_mps_elastic_write_state(&((const elastic_model *)m->state)->w, fp);
}

static void elastic_summary(const lub_model *m, const lub_scene *s, double t)
{
    (void)s;
    const lub_mps_elastic *w = &((const elastic_model *)m->state)->w;
    lub_message("elasticWall: t %.9g s: mean load %.6g N/m of %.6g (%+.3f%%), h0 %.9g m, "
                "centre %.9g m, v in [%.6g, %.6g] m, closest approach %.6g m, fluid particles "
                "inside the cylinder %ld (at most %ld)",
                t, w->load, w->load_target, 100.0 * lub_mps_elastic_beta(w), w->h0, w->centre,
                w->vmin, w->vmax, w->gap_min, w->inside, w->inside_max);
}

static void elastic_free(lub_model *m)
{
    elastic_model *e = m->state;
    if (e->table) fclose(e->table);
    lub_mps_elastic_free(&e->w);
}

const lub_model_type lub_model_elasticWall = {
    .name = "elasticWall",
    .size = sizeof(elastic_model),
    .check = elastic_check,
    .init = elastic_init,
    .header = elastic_header,
    .functions_start = elastic_functions_start,
    .before_step = elastic_before_step,
    .after_step = elastic_after_step,
    .functions_execute = elastic_functions_execute,
    .log = elastic_log,
    .write_state = elastic_write_state,
    .summary = elastic_summary,
    .free = elastic_free,
};
