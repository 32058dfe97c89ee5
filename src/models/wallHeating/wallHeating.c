/* lubkit model wallHeating: a wall whose particles heat up at a constant rate.
 *
 *     wallHeating: { patch: tank, rate: 50 }     # a wall patch of the particles; rate [K/s]
 *
 * The wall particles of the patch carry a temperature rise T (the particle field "T", 0 on
 * the other particles), which grows by rate dt with every step: T = rate (t - t_0) from the
 * run's first start t_0.  The temperature does not act on the flow.
 *
 * The example of the model interface (models/model.h), and the model tests/cases/wallHeating
 * adds as one folder and one registry line: its entry (read, with file:line errors), its
 * field in the particle files (init), its action at a point of the step (before_step notes
 * the step's start, after_step heats), its restart state (write_state: the temperature in
 * uniform/state.yaml, from which init sets the field at a restart), its table
 * (postProcessing/wallHeating/<startTime>/wallHeating.dat: # t T), its part of the log line,
 * its header line and its summary at the end. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "io/table.h"
#include "models/model.h"

#define FIELD "T"

typedef struct {
    int patch;
    char patch_name[LUB_NAME_MAX];
    double rate;    /* [K/s] */
    double T;       /* the wall's temperature rise now [K] (the state) */
    double t_start; /* time at the start of the step being taken */
    FILE *table;
} heating;

static void heating_read(lub_model *m, lub_scene *s)
{
    heating *h = m->state;
    lub_node_expect_map(m->entry);
    const char *name = lub_dict_str(m->entry, "patch");
    h->patch = lub_particles_find_patch(s->P, name);
    if (h->patch < 0) {
        const char *names[LUB_MAX_PATCHES];
        for (int k = 0; k < s->P->npatches; k++) names[k] = s->P->patch_names[k];
        const char *near = lub_closest(name, names, (size_t)s->P->npatches);
        lub_node_error(lub_dict_get(m->entry, "patch"),
                       "wallHeating: the particles have no patch '%s'%s%s%s", name,
                       near ? " (did you mean '" : "", near ? near : "", near ? "'?)" : "");
    }
    snprintf(h->patch_name, sizeof h->patch_name, "%s", name);
    h->rate = lub_dict_real(m->entry, "rate", LUB_ANY);
}

/* T on the patch's wall particles of every level */
static void set_field(heating *h, lub_scene *s)
{
    for (int k = 0; k < s->nlevels; k++) {
        lub_particles *P = s->level[k]->P;
        double *T = lub_particles_extra(P, FIELD);
        for (size_t i = 0; i < P->n; i++)
            T[i] = P->kind[i] == LUB_WALL && P->patch[i] == h->patch ? h->T : 0.0;
    }
}

static void heating_init(lub_model *m, lub_scene *s)
{
    heating *h = m->state;
    lub_node *st = lub_dict_map_or(s->state, "wallHeating");
    h->T = st ? lub_dict_real(st, "T", LUB_ANY) : 0.0;
    set_field(h, s);
}

static void heating_describe(const lub_model *m, const lub_scene *s, char *buf, size_t size)
{
    (void)s;
    const heating *h = m->state;
    snprintf(buf, size, "wallHeating (%s, %g K/s)", h->patch_name, h->rate);
}

static void heating_header(const lub_model *m, const lub_scene *s)
{
    (void)s;
    const heating *h = m->state;
    lub_message("wallHeating: patch %s at T %g K, rising %g K/s", h->patch_name, h->T, h->rate);
}

static void heating_functions_start(lub_model *m, lub_scene *s, const char *start, double t)
{
    heating *h = m->state;
    char path[LUB_PATH_MAX];
    lub_postproc_path(s->cs, "wallHeating", start, "wallHeating.dat", path);
    h->table = fopen(path, "w");
    if (!h->table) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
    lub_table_write_header(h->table, "t[s] T[K]");
    double row[2] = {t, h->T};
    lub_table_write_row(h->table, row, 2);
}

static lub_step_status heating_before_step(lub_model *m, lub_scene *s, double t, double dt,
                                           char *msg, size_t msgsize)
{
    (void)s, (void)dt, (void)msg, (void)msgsize;
    ((heating *)m->state)->t_start = t;
    return LUB_STEP_OK;
}

static void heating_after_step(lub_model *m, lub_scene *s, double t)
{
    heating *h = m->state;
    h->T += h->rate * (t - h->t_start);
    set_field(h, s);
}

static void heating_functions_execute(lub_model *m, lub_scene *s, double t, long step)
{
    (void)s, (void)step;
    heating *h = m->state;
    if (!h->table) return;
    double row[2] = {t, h->T};
    lub_table_write_row(h->table, row, 2);
    fflush(h->table);
}

static void heating_log(const lub_model *m, const lub_scene *s, char *buf, size_t size)
{
    (void)s;
    snprintf(buf, size, "  wall T %.4g K", ((const heating *)m->state)->T);
}

static void heating_write_state(const lub_model *m, const lub_scene *s, FILE *fp)
{
    (void)s;
    fprintf(fp, "wallHeating:\n  T: %.17g   # the wall's temperature rise [K]\n",
            ((const heating *)m->state)->T);
}

static void heating_summary(const lub_model *m, const lub_scene *s, double t)
{
    (void)s;
    const heating *h = m->state;
    lub_message("wallHeating: t %.9g s: patch %s at T %.9g K", t, h->patch_name, h->T);
}

static void heating_free(lub_model *m)
{
    heating *h = m->state;
    if (h->table) fclose(h->table);
}

const lub_model_type lub_model_wallHeating = {
    .name = "wallHeating",
    .size = sizeof(heating),
    .read = heating_read,
    .init = heating_init,
    .describe = heating_describe,
    .header = heating_header,
    .functions_start = heating_functions_start,
    .before_step = heating_before_step,
    .after_step = heating_after_step,
    .functions_execute = heating_functions_execute,
    .log = heating_log,
    .write_state = heating_write_state,
    .summary = heating_summary,
    .free = heating_free,
};
