/* lubkit models: a scene's models, built from constant/models.yaml (models/model.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "models/model.h"
#include "models/models.h"

void lub_scene_read(lub_scene *s, const lub_case *cs, lub_particles *P, const lub_geometry *geo,
                    lub_mps_config *c)
{
    memset(s, 0, sizeof *s);
    s->cs = cs;
    s->P = P;
    s->geo = geo;
    lub_case_path(cs, s->models_path, "constant/models.yaml");
    s->dict = lub_dict_read_optional(s->models_path);
    lub_node *root = s->dict ? lub_dict_root(s->dict) : NULL;
    lub_models_declare(root);
    s->fluid = lub_fluid_type_read(root);
    s->fluid->read(c, cs, root, lub_dict_find(root, "fluid"));
    for (int k = 0; lub_model_types[k]; k++) {
        /* found, not looked into: a model that reads its entry elsewhere (elasticWall: from
         * its own copy of the file) leaves it unjudged here */
        lub_node *entry = lub_dict_find(root, lub_model_types[k]->name);
        if (!entry) continue;
        if (s->nmodels == LUB_MAX_MODELS)
            lub_bug("more than %d models: raise LUB_MAX_MODELS", LUB_MAX_MODELS);
        lub_model *m = &s->model[s->nmodels++];
        m->type = lub_model_types[k];
        m->entry = entry;
        m->state = m->type->size ? lub_calloc(1, m->type->size) : NULL;
        if (m->type->build || m->type->advance) {
            if (s->driver)
                lub_bug("models '%s' and '%s' both drive the solvers", s->driver->type->name,
                        m->type->name);
            s->driver = m;
        }
        if (m->type->read) m->type->read(m, s);
    }
    if (s->dict) lub_dict_finish(s->dict); /* a misspelt key before the combinations */
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->check) s->model[k].type->check(&s->model[k], s);
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->configure) s->model[k].type->configure(&s->model[k], s, c);
}

/* The in-step hooks of every solver: each model's operation, in the registry's order. */
static int scene_forces(void *ctx, const lub_mps *f, double dt, double acc[3])
{
    lub_scene *s = ctx;
    int any = 0;
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->forces) any |= s->model[k].type->forces(&s->model[k], f, dt, acc);
    return any;
}

static void scene_after_correction(void *ctx, lub_mps *f, double dt)
{
    lub_scene *s = ctx;
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->after_correction)
            s->model[k].type->after_correction(&s->model[k], f, dt);
}

static int scene_particle_forces(void *ctx, const lub_mps *f, double *const acc[3])
{
    lub_scene *s = ctx;
    int any = 0;
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->particle_forces)
            any |= s->model[k].type->particle_forces(&s->model[k], f, acc);
    return any;
}

static void attach(lub_scene *s, lub_mps *const *levels, int nlevels)
{
    int forces = 0, after = 0, pforces = 0;
    for (int k = 0; k < s->nmodels; k++) {
        forces |= s->model[k].type->forces != NULL;
        after |= s->model[k].type->after_correction != NULL;
        pforces |= s->model[k].type->particle_forces != NULL;
    }
    for (int l = 0; l < nlevels; l++) {
        lub_mps_hooks *h = &levels[l]->hooks;
        h->ctx = s;
        h->forces = forces ? scene_forces : NULL;
        h->after_correction = after ? scene_after_correction : NULL;
        h->particle_forces = pforces ? scene_particle_forces : NULL;
    }
}

void lub_scene_build(lub_scene *s, const lub_mps_config *c, const char *state_path, double end_time,
                     const char *end_what)
{
    snprintf(s->state_path, sizeof s->state_path, "%s", state_path ? state_path : "");
    s->end_time = end_time;
    snprintf(s->end_what, sizeof s->end_what, "%s", end_what ? end_what : "");
    if (s->driver) {
        s->driver->type->build(s->driver, s, c);
    } else {
        if (s->P->nlevels > 1)
            lub_fatal("%s: the particles have %d resolution levels but there is no "
                      "'multiResolution' entry: add one (e.g. 'multiResolution: { commonDeltaT: "
                      "true }', etc/templates/models.yaml) or generate a single level (l0 in "
                      "system/particleGenDict.yaml)",
                      s->models_path, s->P->nlevels);
        lub_mps_init(&s->single, s->P, c, s->geo->dmin, s->geo->dmax, s->geo->periodic);
        s->nlevels = 1;
        s->level[0] = &s->single;
        s->nr = 1;
        s->dt_factor[0] = 1;
    }
    if (s->nlevels < 1 || s->nlevels > LUB_MAX_LEVELS || s->nr < 1)
        lub_bug("lub_scene_build: %d levels, %d steps per step", s->nlevels, s->nr);
    attach(s, s->level, s->nlevels);
    if (s->par) {
        if (s->nlevels != 1) lub_bug("lub_scene_build: %d levels on several ranks", s->nlevels);
        lub_mps_set_parallel(s->level[0], s->par);
    }
    /* the models' restart state: each model reads its entry of the start's state.yaml */
    lub_dict *st = state_path ? lub_dict_read_optional(state_path) : NULL;
    s->state = st ? lub_dict_root(st) : NULL;
    lub_models_declare_state(s->state);
    /* the driver last: it gathers the levels (their fields included) into the particles */
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->init && &s->model[k] != s->driver)
            s->model[k].type->init(&s->model[k], s);
    if (s->driver && s->driver->type->init) s->driver->type->init(s->driver, s);
    if (st) {
        lub_dict_finish(st);
        lub_dict_free(st);
    }
    s->state = NULL;
}

void lub_scene_describe(const lub_scene *s, char *buf, size_t size)
{
    size_t len = 0;
    buf[0] = '\0';
    for (int k = 0; k < s->nmodels && len < size; k++) {
        const lub_model *m = &s->model[k];
        char one[512];
        if (m->type->describe)
            m->type->describe(m, s, one, sizeof one);
        else
            snprintf(one, sizeof one, "%s", m->type->name);
        if (!one[0]) continue; /* nothing to say (movingWalls with every wall at rest) */
        len += (size_t)snprintf(buf + len, size - len, "%s%s", len ? "; " : "", one);
    }
}

void lub_scene_header(const lub_scene *s)
{
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->header) s->model[k].type->header(&s->model[k], s);
}

void lub_scene_header_fluid(const lub_scene *s)
{
    if (s->driver && s->driver->type->header_levels)
        s->driver->type->header_levels(s->driver, s);
    else if (s->fluid->header_level)
        s->fluid->header_level(s->level[0]);
    if (s->fluid->header) s->fluid->header(s->level[0]);
}

void lub_scene_functions_start(lub_scene *s, const char *start, double t)
{
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->functions_start)
            s->model[k].type->functions_start(&s->model[k], s, start, t);
}

lub_step_status lub_scene_before_step(lub_scene *s, double t, double dt, char *msg, size_t msgsize)
{
    msg[0] = '\0';
    for (int k = 0; k < s->nmodels; k++) {
        if (!s->model[k].type->before_step) continue;
        lub_step_status st = s->model[k].type->before_step(&s->model[k], s, t, dt, msg, msgsize);
        if (st != LUB_STEP_OK) return st;
    }
    return LUB_STEP_OK;
}

lub_step_status lub_scene_advance(lub_scene *s, double dt, long *bad, char *msg, size_t msgsize)
{
    if (s->driver) return s->driver->type->advance(s->driver, s, s->nr * dt, bad, msg, msgsize);
    return s->fluid->step(s->level[0], dt, bad, msg, msgsize);
}

void lub_scene_after_step(lub_scene *s, double t)
{
    /* the driver last: it gathers the levels into the particles the output reads */
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->after_step && &s->model[k] != s->driver)
            s->model[k].type->after_step(&s->model[k], s, t);
    if (s->driver && s->driver->type->after_step) s->driver->type->after_step(s->driver, s, t);
}

void lub_scene_warn(lub_scene *s, long step)
{
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->warn) s->model[k].type->warn(&s->model[k], s, step);
}

void lub_scene_functions_execute(lub_scene *s, double t, long step)
{
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->functions_execute)
            s->model[k].type->functions_execute(&s->model[k], s, t, step);
}

void lub_scene_log(const lub_scene *s, char *buf, size_t size)
{
    size_t len = 0;
    buf[0] = '\0';
    for (int k = 0; k < s->nmodels && len < size; k++)
        if (s->model[k].type->log) {
            s->model[k].type->log(&s->model[k], s, buf + len, size - len);
            len += strlen(buf + len);
        }
}

void lub_scene_log_fluid(const lub_scene *s, double dt, double pit, char *buf, size_t size)
{
    buf[0] = '\0';
    if (s->driver && s->driver->type->log_levels)
        s->driver->type->log_levels(s->driver, s, dt, pit, buf, size);
    else if (s->fluid->log)
        s->fluid->log(s->level[0], dt, pit, buf, size);
}

/* u_max dt_k / l0 of the level where it is largest, for the finest dt = 1 */
static double courant_per_dt(const lub_scene *s, int *level)
{
    double best = 0;
    int at = 0;
    for (int k = 0; k < s->nlevels; k++) {
        const double c = s->level[k]->st.umax * (double)s->dt_factor[k] / s->level[k]->l0;
        if (c > best) best = c, at = k;
    }
    *level = at;
    return best;
}

double lub_scene_courant(const lub_scene *s, double dt, double *umax)
{
    const lub_mps *m = s->level[0];
    if (s->nlevels == 1) {
        if (umax) *umax = m->st.umax;
        return m->st.umax * dt / m->l0;
    }
    int k;
    const double c = courant_per_dt(s, &k) * dt;
    if (umax) *umax = s->level[k]->st.umax;
    return c;
}

int lub_scene_dt_limit(const lub_scene *s, double max_courant, double *dt)
{
    const lub_mps *m = s->level[0];
    if (s->nlevels == 1) {
        if (!(m->st.umax > 0)) return 0;
        *dt = max_courant * m->l0 / m->st.umax;
        return 1;
    }
    int k;
    const double c = courant_per_dt(s, &k);
    if (!(c > 0)) return 0;
    *dt = max_courant / c; /* every level takes dt: the largest u_max / l0 limits it */
    return 1;
}

void lub_scene_iterations(const lub_scene *s, double *p, double *v)
{
    *p = *v = 0;
    for (int k = 0; k < s->nlevels; k++) {
        *p += s->level[k]->iterations[0];
        *v += s->level[k]->iterations[1];
    }
}

void lub_scene_rebuild_lists(lub_scene *s)
{
    for (int k = 0; k < s->nlevels; k++) lub_mps_rebuild_lists(s->level[k]);
}

int lub_scene_owner(const lub_scene *s, double x)
{
    return s->driver && s->driver->type->owner ? s->driver->type->owner(s->driver, x) : 0;
}

void lub_scene_write_state(const lub_scene *s, FILE *fp)
{
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->write_state) s->model[k].type->write_state(&s->model[k], s, fp);
}

void lub_scene_summary(const lub_scene *s, double t)
{
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->summary) s->model[k].type->summary(&s->model[k], s, t);
}

void lub_scene_free(lub_scene *s)
{
    for (int k = 0; k < s->nmodels; k++) {
        lub_model *m = &s->model[k];
        if (m->type->free) m->type->free(m);
        free(m->state);
    }
    if (s->nlevels > 0 && s->level[0] == &s->single) lub_mps_free(&s->single);
    if (s->dict) lub_dict_free(s->dict);
    memset(s, 0, sizeof *s);
}
