/* lubkit models: the fluid, a choice of formulation like the models (models/model.h).
 *
 *     fluid: { type: mps }      # constant/models.yaml; the default
 *
 * A formulation is one file src/models/fluid/<type>.c defining `const lub_fluid_type
 * lub_fluid_<type>` and one LUB_FLUID line of models/registry.h.  It reads its dictionaries
 * into the solver's configuration and brings its step; it shares the solver's state (mps/mps.h
 * lub_mps: the particles and their fields, the neighbour lists, the wall and dummy particles
 * and their checks, the linear solvers, the timers), and with it the models' hooks, the
 * output and the run control.  Semi-implicit MPS (methods.md §2) is `mps`; Moving Particle
 * Hydrodynamics (methods.md §8) is `mph` (models/fluid/mph.h), a second file with its own
 * step over the same state.  A model
 * that drives the levels itself (multiResolution) couples steps of `mps` and refuses others.
 */
#ifndef LUB_MODELS_FLUID_H
#define LUB_MODELS_FLUID_H

#include <stddef.h>

#include "geometry/geometry.h"
#include "io/case.h"
#include "io/dict.h"
#include "mps/mps.h"

typedef struct lub_fluid_type {
    const char *name; /* fluid: { type: <name> } */
    /* Its dictionaries into c: constant/transportProperties.yaml, its keys of
     * constant/models.yaml (models: the root, may be NULL; entry: the fluid entry, may be
     * NULL), system/schemes.yaml, system/solution.yaml.  Fatal (exit 1) with file:line. */
    void (*read)(lub_mps_config *c, const lub_case *cs, lub_node *models, lub_node *entry);
    /* One step of dt of solver m (*bad and msg as for lub_mps_step). */
    lub_step_status (*step)(lub_mps *m, double dt, long *bad, char *msg, size_t msgsize);
    /* The header line of a solver of one resolution level, and the formulation's lines
     * (schemes, linear solvers). */
    void (*header_level)(const lub_mps *m);
    void (*header)(const lub_mps *m);
    /* Its start-up checks (NULL: none), after the header and the Courant and diffusion
     * numbers (lubFoam): its parameters against the step dt and the body acceleration g of
     * the scene's models (uniform, m/s^2), the case's geometry (system/particleGenDict.yaml)
     * against its needs; printed as the MPS solver's, fatal (exit 1, file:line where there is
     * one) for a combination that cannot work. */
    void (*check)(const lub_mps *m, const lub_geometry *geo, double dt, const double g[3]);
    /* Its part of the log line after the step (dt; pit: the mean pressure iterations per
     * step so far). */
    void (*log)(const lub_mps *m, double dt, double pit, char *buf, size_t size);
    /* The force the fluid exerted in the step just taken on each particle of patch (wall and
     * dummy: f[d][i], 0 on the other particles) [N; N/m in 2-D], the reaction of what the
     * step did to the fluid, so that fluid and body exchange momentum (rigidBodies,
     * methods.md §7.2).  area[d][i]: the outward area vector (normal into the fluid times
     * the surface it stands for, m^2; m in 2-D) of each wall particle of the patch, from the
     * body's shape; omega: the patch's angular velocity (world frame, rad/s; the patch
     * moves rigidly).  A formulation whose pressure acts through the surface and whose
     * viscous term is the Laplacian of the velocity components uses them (mps); a
     * pair-force formulation (MPH: f_i = the sum over fluid j of the pair forces of (K-6),
     * (K-8)) may ignore them.  NULL: the formulation cannot move bodies. */
    void (*wall_forces)(const lub_mps *m, int patch, double *const area[3], const double omega[3],
                        double *const f[3]);
} lub_fluid_type;

/* The formulations, NULL-terminated, the default first. */
extern const lub_fluid_type *const lub_fluid_types[];

/* The fluid entry of constant/models.yaml's root (may be NULL): its type (default the first
 * registered), fatal with file:line for an unknown one. */
const lub_fluid_type *lub_fluid_type_read(lub_node *models);

#endif
