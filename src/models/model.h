/* lubkit models: what a scene simulates besides the fluid, each model one folder
 * src/models/<name>/ and one line of src/models/registry.h (methods.md §2-4).
 *
 * A scene lists its models in constant/models.yaml; the solver builds those, and only those,
 * and calls them at the named points of the step (methods.md §2).  As OpenFOAM's run-time
 * selection tables, a name of models.yaml selects a table of operations that its folder
 * fills in (lub_model_type; any operation may be NULL); as SWIFT's scheme folders, each
 * model keeps its state, its dictionary entry, its fields and its output in its folder.
 *
 * The operations, in the order a run calls them:
 *
 *   read        read and check its entry (m->entry, of constant/models.yaml), fatal with
 *               file:line on bad input; the particles (s->P) and the geometry (s->geo) are
 *               there, the solvers not yet
 *   check       after every model's read and the unknown-key check of models.yaml: the
 *               combinations with other models (a misspelt key is reported first)
 *   configure   its part of the fluid's configuration (the walls' velocities: movingWalls),
 *               before the solvers are built
 *   forces      step 2 of every level's step: add a uniform body acceleration (gravity)
 *   after_correction   step 9, after the velocity and position correction: collision
 *
 * Adding a model: a folder src/models/<name>/ with <name>.c defining
 * `const lub_model_type lub_model_<name>`, and the line LUB_MODEL(<name>) in registry.h.
 */
#ifndef LUB_MODELS_MODEL_H
#define LUB_MODELS_MODEL_H

#include <stddef.h>
#include <stdio.h>

#include "geometry/geometry.h"
#include "io/dict.h"
#include "mps/mps.h"
#include "particles/particles.h"

#define LUB_MAX_MODELS 16

typedef struct lub_scene lub_scene;
typedef struct lub_model lub_model;

typedef struct lub_model_type {
    const char *name; /* its key in constant/models.yaml */
    size_t size;      /* bytes of its state (m->state, zeroed), 0 for none */

    void (*read)(lub_model *m, lub_scene *s);
    void (*check)(lub_model *m, lub_scene *s);
    void (*configure)(lub_model *m, lub_scene *s, lub_mps_config *c);
    /* its entry in the "Models:" line of the log's header */
    void (*describe)(const lub_model *m, const lub_scene *s, char *buf, size_t size);

    /* inside the step of each level's solver f (mps.h lub_mps_hooks) */
    int (*forces)(lub_model *m, const lub_mps *f, double dt, double acc[3]);
    void (*after_correction)(lub_model *m, lub_mps *f, double dt);

    void (*free)(lub_model *m);
} lub_model_type;

struct lub_model {
    const lub_model_type *type;
    lub_node *entry; /* its entry of constant/models.yaml */
    void *state;     /* type->size bytes */
};

/* The models of a run. */
struct lub_scene {
    lub_particles *P;        /* the particles (every level) */
    const lub_geometry *geo; /* the geometry (system/particleGenDict.yaml); set-up only */
    lub_dict *dict;          /* constant/models.yaml (NULL: none) */
    int nmodels;
    lub_model model[LUB_MAX_MODELS]; /* in the order of the registry */
};

/* The registry: every model type, NULL-terminated, in the order of registry.h (the order
 * in which the models of a scene act at each point). */
extern const lub_model_type *const lub_model_types[];
const lub_model_type *lub_model_type_find(const char *name);

/* Read constant/models.yaml (models_path; a missing file lists no model) and set up the
 * models it lists: read, then check, then configure on c.  Fatal (exit 1) with file:line on
 * bad input, a misspelt model name or key included. */
void lub_scene_read(lub_scene *s, const char *models_path, lub_particles *P,
                    const lub_geometry *geo, lub_mps_config *c);
/* Attach the models' in-step operations to the solvers of the levels (mps.h hooks). */
void lub_scene_attach(lub_scene *s, lub_mps *const *levels, int nlevels);
/* The "Models:" list of the header ("none (constant/models.yaml)" without a model). */
void lub_scene_describe(const lub_scene *s, char *buf, size_t size);
/* The model of that name, or NULL when the scene does not list it. */
lub_model *lub_scene_find(const lub_scene *s, const char *name);
void lub_scene_free(lub_scene *s);

#endif
