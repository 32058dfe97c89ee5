/* lubkit models: a scene's models, built from constant/models.yaml (models/model.h). */
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "models/model.h"
#include "models/models.h"

void lub_scene_read(lub_scene *s, const char *models_path, lub_particles *P,
                    const lub_geometry *geo, lub_mps_config *c)
{
    memset(s, 0, sizeof *s);
    s->P = P;
    s->geo = geo;
    s->dict = lub_dict_read_optional(models_path);
    lub_node *root = s->dict ? lub_dict_root(s->dict) : NULL;
    lub_models_declare(root);
    for (int k = 0; lub_model_types[k]; k++) {
        lub_node *entry = lub_dict_map_or(root, lub_model_types[k]->name);
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

void lub_scene_attach(lub_scene *s, lub_mps *const *levels, int nlevels)
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
