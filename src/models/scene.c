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

static void attach(lub_scene *s, lub_mps *const *levels, int nlevels)
{
    int forces = 0, after = 0;
    for (int k = 0; k < s->nmodels; k++) {
        forces |= s->model[k].type->forces != NULL;
        after |= s->model[k].type->after_correction != NULL;
    }
    for (int l = 0; l < nlevels; l++) {
        lub_mps_hooks *h = &levels[l]->hooks;
        h->ctx = s;
        h->forces = forces ? scene_forces : NULL;
        h->after_correction = after ? scene_after_correction : NULL;
    }
}

void lub_scene_init(lub_scene *s, lub_mps *const *level, int nlevels,
                    const struct lub_levels *levels, const char *state_path, double end_time,
                    const char *end_what)
{
    if (nlevels < 1 || nlevels > LUB_MAX_LEVELS) lub_bug("lub_scene_init: %d levels", nlevels);
    s->nlevels = nlevels;
    for (int k = 0; k < nlevels; k++) s->level[k] = level[k];
    s->levels = levels;
    snprintf(s->state_path, sizeof s->state_path, "%s", state_path ? state_path : "");
    s->end_time = end_time;
    snprintf(s->end_what, sizeof s->end_what, "%s", end_what ? end_what : "");
    attach(s, level, nlevels);
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->init) s->model[k].type->init(&s->model[k], s);
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

void lub_scene_after_step(lub_scene *s, double t)
{
    for (int k = 0; k < s->nmodels; k++)
        if (s->model[k].type->after_step) s->model[k].type->after_step(&s->model[k], s, t);
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

lub_model *lub_scene_find(const lub_scene *s, const char *name)
{
    for (int k = 0; k < s->nmodels; k++)
        if (strcmp(s->model[k].type->name, name) == 0) return (lub_model *)&s->model[k];
    return NULL;
}

void lub_scene_free(lub_scene *s)
{
    for (int k = 0; k < s->nmodels; k++) {
        lub_model *m = &s->model[k];
        if (m->type->free) m->type->free(m);
        free(m->state);
    }
    if (s->dict) lub_dict_free(s->dict);
    memset(s, 0, sizeof *s);
}
