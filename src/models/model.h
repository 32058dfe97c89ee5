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
 *   build       (the driver only) set up the fluid's solvers itself: s->nlevels, s->level,
 *               s->levels, s->nr, s->dt_factor (multiResolution: one solver per resolution
 *               level); without a driver the scene builds one solver for the particles
 *   init        after the solvers (s->level): its fields in the particles of the levels
 *               (saved in the time folders), its restart state (s->state: its entry of the
 *               start's uniform/state.yaml), checks against endTime; the driver's last
 *   describe    its entry in the "Models:" line of the log's header (default: its name)
 *   header      its lines of the log's header (after the "Models:" line)
 *   functions_start    its tables under postProcessing/ (a run with a step to take)
 *
 * and at every step (methods.md §2), from time t to t + dt:
 *
 *   before_step        before the step of every level (elasticWall: the wall's motion); a
 *                      failure stops the run with the state before the step kept
 *   advance            (the driver only) the step of every level, s->nr steps of dt of the
 *                      finest level (multiResolution: the coupling, sub-steps, transfer and
 *                      mass correction); without a driver the scene takes the solver's step
 *   forces             step 2 of every level's step: add a uniform body acceleration
 *   particle_forces    with the explicit forces (MPS: after the viscous step; MPH: its
 *                      step 4): add each fluid particle's acceleration (surface tension)
 *   after_correction   step 9, after the velocity and position correction: collision
 *   after_step         after every level's step, the time now t + dt (elasticWall: the
 *                      running mean of the wall pressure); the driver's last (it gathers the
 *                      levels into the scene's particles)
 *   warn               after after_step: warnings about the step (each once, as it sees fit)
 *   functions_execute  its tables, after after_step
 *   log                its part of the log line
 *
 * and write_state (its entry in the time folders' uniform/state.yaml, for an exact restart),
 * summary (its lines at the end of the run), free.  A driver also describes the levels:
 * header_levels (the levels' header lines), log_levels (their part of the log line), and
 * which level owns a point (owner: each point of space counted on one level, T-27).
 *
 * Adding a model: a folder src/models/<name>/ with <name>.c defining
 * `const lub_model_type lub_model_<name>`, and the line LUB_MODEL(<name>) in registry.h
 * (src/README.md names the example).
 */
#ifndef LUB_MODELS_MODEL_H
#define LUB_MODELS_MODEL_H

#include <stddef.h>
#include <stdio.h>

#include "geometry/geometry.h"
#include "io/case.h"
#include "io/dict.h"
#include "models/fluid.h"
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
    void (*build)(lub_model *m, lub_scene *s, const lub_mps_config *c);
    void (*init)(lub_model *m, lub_scene *s);
    /* its entry in the "Models:" line of the log's header */
    void (*describe)(const lub_model *m, const lub_scene *s, char *buf, size_t size);
    void (*header)(const lub_model *m, const lub_scene *s);
    void (*header_levels)(const lub_model *m, const lub_scene *s);
    /* start: the name of the start time folder (postProcessing/<name>/<start>/) */
    void (*functions_start)(lub_model *m, lub_scene *s, const char *start, double t);

    lub_step_status (*before_step)(lub_model *m, lub_scene *s, double t, double dt, char *msg,
                                   size_t msgsize);
    /* inside the step of each level's solver f (mps.h lub_mps_hooks) */
    int (*forces)(lub_model *m, const lub_mps *f, double dt, double acc[3]);
    /* inside the step of each level's solver f: add the acceleration of forces that depend on
     * the particles (surface tension) to acc[d][i] of the fluid particles; 1 if it added
     * any (mps.h lub_mps_hooks.particle_forces).  A pair force's reaction on a wall or
     * dummy particle goes to its acc[d][i] too, in the same units (force over a fluid
     * particle's mass rho l0^d): the step ignores it, a body's force takes it (fluid/mph.c
     * wall_forces) */
    int (*particle_forces)(lub_model *m, const lub_mps *f, double *const acc[3]);
    void (*after_correction)(lub_model *m, lub_mps *f, double dt);
    lub_step_status (*advance)(lub_model *m, lub_scene *s, double dt, long *bad, char *msg,
                               size_t msgsize);
    void (*after_step)(lub_model *m, lub_scene *s, double t);
    void (*warn)(lub_model *m, lub_scene *s, long step);
    void (*functions_execute)(lub_model *m, lub_scene *s, double t, long step);
    void (*log)(const lub_model *m, const lub_scene *s, char *buf, size_t size);
    /* dt: the finest level's; pit: the mean pressure iterations per step so far */
    void (*log_levels)(const lub_model *m, const lub_scene *s, double dt, double pit, char *buf,
                       size_t size);
    int (*owner)(const lub_model *m, double x);

    void (*write_state)(const lub_model *m, const lub_scene *s, FILE *fp);
    void (*summary)(const lub_model *m, const lub_scene *s, double t);
    void (*free)(lub_model *m);
} lub_model_type;

struct lub_model {
    const lub_model_type *type;
    lub_node *entry; /* its entry of constant/models.yaml */
    void *state;     /* type->size bytes */
};

struct lub_levels;

/* The models of a run. */
struct lub_scene {
    const lub_case *cs;             /* the case */
    lub_particles *P;               /* the particles (every level) */
    const lub_geometry *geo;        /* the geometry (system/particleGenDict.yaml); set-up only */
    char models_path[LUB_PATH_MAX]; /* constant/models.yaml */
    lub_dict *dict;                 /* constant/models.yaml (NULL: none) */
    const lub_fluid_type *fluid;    /* its formulation (fluid: { type }, models/fluid.h) */
    int nmodels;
    lub_model model[LUB_MAX_MODELS]; /* in the order of the registry */
    lub_model *driver; /* the model with build and advance (multiResolution), or NULL */

    /* the fluid's solvers (lub_scene_build) */
    int nlevels;
    lub_mps *level[LUB_MAX_LEVELS];  /* the solver of each resolution level, finest first */
    const struct lub_levels *levels; /* multi-resolution: the levels (NULL: one level); the
                                        driver sets it when it reads its entry */
    int nr;                          /* steps of the finest level per step of the scene */
    long dt_factor[LUB_MAX_LEVELS];  /* a level's dt over the finest level's */
    lub_mps single;                  /* without a driver: the solver */
    lub_par *par; /* a run on several ranks (parallel/par.h; NULL: serial): the particles are
                     this rank's slab, the models' start-up checks are collective; set before
                     lub_scene_build, which gives it to the solver before the models' init */

    /* set-up (lub_scene_build) */
    char state_path[LUB_PATH_MAX]; /* the start folder's uniform/state.yaml (may not exist) */
    lub_node *state;               /* its root during the models' init (NULL: none) */
    double end_time;               /* > 0: the run's end time (checks against it) */
    char end_what[128];            /* how to name it in a message */
};

/* The registry: every model type, NULL-terminated, in the order of registry.h (the order
 * in which the models of a scene act at each point). */
extern const lub_model_type *const lub_model_types[];

/* Read the case's constant/models.yaml (a missing file lists no model): the fluid's
 * formulation reads its dictionaries into c (models/fluid.h), then the models it lists are
 * set up: read, then check, then configure on c.  Fatal (exit 1) with file:line on bad input,
 * a misspelt model name or key included. */
void lub_scene_read(lub_scene *s, const lub_case *cs, lub_particles *P, const lub_geometry *geo,
                    lub_mps_config *c);
/* Build the fluid's solvers from c (the driver's build, else one solver for the particles;
 * particles of several levels need a driver), attach the models' in-step operations to them
 * (mps.h hooks), on several ranks (s->par) give the solver the decomposition
 * (lub_mps_set_parallel), and call every model's init.  state_path: the start folder's
 * uniform/state.yaml (may not exist); end_time > 0: the run's end time, named end_what in
 * messages. */
void lub_scene_build(lub_scene *s, const lub_mps_config *c, const char *state_path, double end_time,
                     const char *end_what);
/* The "Models:" list of the header (empty without a model). */
void lub_scene_describe(const lub_scene *s, char *buf, size_t size);
/* The fluid's header lines: its levels (the driver's header_levels, else the formulation's
 * line of the one solver), its schemes and solvers. */
void lub_scene_header_fluid(const lub_scene *s);
/* Every model's header lines. */
void lub_scene_header(const lub_scene *s);
void lub_scene_functions_start(lub_scene *s, const char *start, double t);
/* Before the step from t to t + dt: the first failure (msg) stops the others. */
lub_step_status lub_scene_before_step(lub_scene *s, double t, double dt, char *msg, size_t msgsize);
/* The step of every level: s->nr steps of dt on the finest level (the driver's advance, else
 * the solver's step).  *bad and msg as for lub_mps_step. */
lub_step_status lub_scene_advance(lub_scene *s, double dt, long *bad, char *msg, size_t msgsize);
/* After the step, the time now t. */
void lub_scene_after_step(lub_scene *s, double t);
/* The models' warnings after the step (step: the step count now). */
void lub_scene_warn(lub_scene *s, long step);
/* The models' tables after the step (step: the step count now). */
void lub_scene_functions_execute(lub_scene *s, double t, long step);
/* The models' parts of the log line, each with its leading separator. */
void lub_scene_log(const lub_scene *s, char *buf, size_t size);
/* The fluid's part of the log line (the driver's log_levels, else the formulation's; dt: the
 * finest level's, pit: the mean pressure iterations per step so far). */
void lub_scene_log_fluid(const lub_scene *s, double dt, double pit, char *buf, size_t size);

/* The Courant number u_max dt / l0 of the last step (T-18), the largest over the levels, each
 * with its own dt = dt_factor dt (dt: the finest level's); *umax (may be NULL): the speed
 * there. */
double lub_scene_courant(const lub_scene *s, double dt, double *umax);
/* The finest level's dt at which that Courant number is max_courant: 1 and *dt, or 0 when
 * no particle moves. */
int lub_scene_dt_limit(const lub_scene *s, double max_courant, double *dt);
/* The pressure and viscosity iterations of every level's every step so far. */
void lub_scene_iterations(const lub_scene *s, double *p, double *v);
/* Build every level's neighbour lists afresh at its next step (after writing a time folder:
 * an exact restart, lub_mps_rebuild_lists). */
void lub_scene_rebuild_lists(lub_scene *s);
/* The level that owns x (each point of space on one level, T-27; 0 with one level). */
int lub_scene_owner(const lub_scene *s, double x);
void lub_scene_write_state(const lub_scene *s, FILE *fp);
void lub_scene_summary(const lub_scene *s, double t);
void lub_scene_free(lub_scene *s);

#endif
