/* lubFoam -parallel: the run on the ranks of mpirun (src/parallel/par.h, doc/parallel.md).
 *
 * Every rank reads the dictionaries and the start's particles itself, and builds the scene
 * on all of them (the models' start-up checks see the whole case); then each keeps the
 * particles of its slab (system/decomposeParDict.yaml) and the steps run on the slabs.
 * What is not parallel yet is refused here, before anything is written, naming it. */
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "models/fluid.h"
#include "lubFoam.h"

int lubfoam_wants_parallel(int argc, char **argv)
{
    for (int k = 1; k < argc; k++)
        if (strcmp(argv[k], "-parallel") == 0) return 1;
    return 0;
}

/* The models, formulation and schemes a parallel run has (the others refused, exit 1). */
static void refuse_unparallel(const lubfoam_run *r, const lubfoam_functions *fos)
{
    const lub_scene *sc = &r->scene;
    const lub_mps *m = sc->level[0];
    for (int k = 0; k < sc->nmodels; k++) {
        const char *name = sc->model[k].type->name;
        if (strcmp(name, "gravity") != 0 && strcmp(name, "movingWalls") != 0 &&
            strcmp(name, "collision") != 0)
            lub_fatal("%s: the model '%s' does not run in parallel yet (lubFoam -parallel "
                      "takes gravity, movingWalls and collision): run it without -parallel "
                      "(doc/parallel.md)",
                      sc->models_path, name);
    }
    if (strcmp(sc->fluid->name, "mps") != 0)
        lub_fatal("%s: fluid type '%s' does not run in parallel yet (lubFoam -parallel takes "
                  "the semi-implicit MPS fluid, type mps): run it without -parallel",
                  sc->models_path, sc->fluid->name);
    if (sc->nlevels != 1)
        lub_fatal("%s: resolution levels do not run in parallel yet", sc->models_path);
    if (LUB_LAPLACIAN_FITTED(m->c.lap_pressure) || LUB_LAPLACIAN_FITTED(m->c.lap_viscosity))
        lub_fatal("%s/system/schemes.yaml: the LSMPS Laplacians (laplacian: lsmps, "
                  "lsmpsStabilized) do not run in parallel yet (its BiCGStab solve is serial): use "
                  "laplacian: standard",
                  r->cs.root);
    const int implicit = m->c.viscosity == LUB_VISCOSITY_CN;
    if (m->c.p_solver.kind != LUB_LINSOLVER_PETSC ||
        (implicit && m->c.v_solver.kind != LUB_LINSOLVER_PETSC))
        lub_fatal("%s/system/solution.yaml: lubFoam -parallel solves the %s equation over the "
                  "ranks with PETSc only; the solver %s is serial: set '%s: { solver: petsc, "
                  "ksp: cg, pc: hypre }'",
                  r->cs.root, m->c.p_solver.kind != LUB_LINSOLVER_PETSC ? "pressure" : "viscosity",
                  lub_linsolver_choice_names[m->c.p_solver.kind != LUB_LINSOLVER_PETSC
                                                 ? m->c.p_solver.kind
                                                 : m->c.v_solver.kind],
                  m->c.p_solver.kind != LUB_LINSOLVER_PETSC ? "p" : "U");
    const char *fo = lubfoam_functions_unparallel(fos);
    if (fo)
        lub_fatal("%s/system/controlDict.yaml: the function object '%s' (type forces) does not "
                  "run in parallel yet (totals, wallPressure and wallLoad do): remove it for the "
                  "parallel run",
                  r->cs.root, fo);
}

void lubfoam_parallel_setup(lubfoam_run *r, const lub_geometry *geo, const lubfoam_functions *fos)
{
    char path[LUB_PATH_MAX];
    const int size = lub_par_size();
    lub_par_dict pd;
    lub_par_read_dict(&pd, lub_case_path(&r->cs, path, "system/decomposeParDict.yaml"), r->P.dim,
                      size);
    const int ax = pd.axis;
    refuse_unparallel(r, fos);

    lub_mps *m = r->scene.level[0];
    const int axis = ax < 0 ? lub_par_longest_axis(&r->P) : ax;
    /* the halo: every particle within the lists' radius re (1 + skin) of the slab, and l0
     * for the moves within the step (the Courant limit keeps them below l0) */
    lub_par_init(&r->par, axis, m->nb.rs + m->l0, geo->dmin[axis], geo->dmax[axis],
                 geo->periodic[axis]);
    r->par.interval = pd.interval;
    r->par.imbalance = pd.imbalance;
    const size_t total = r->P.n, most = lub_par_decompose(&r->par, &r->P);
    lub_mps_set_parallel(m, &r->par);
    r->parallel = 1;
    char cuts[256] = "";
    size_t len = 0;
    for (int k = 1; k < size && len + 32 < sizeof cuts; k++)
        len += (size_t)snprintf(cuts + len, sizeof cuts - len, "%s%.9g", k > 1 ? " " : "",
                                r->par.cut[k]);
    lub_message("Parallel: %d ranks, slabs along %c (%s), %zu particles, at most %zu per rank "
                "(mean %.0f), halo width %g m%s%s",
                size, "xyz"[axis], ax < 0 ? "auto: the fluid's longest" : "given", total, most,
                (double)total / size, r->par.width, size > 1 ? ", cuts at " : "", cuts);
    /* the particle files: collective when the build's HDF5 is Open MPI's and the ids are
     * the rows (0 .. N-1, as particleGen numbers them), else gathered to rank 0 */
    const int dense = lub_par_ids_dense(&r->par, &r->P);
    r->collective = pd.write != LUB_PAR_WRITE_GATHER && lub_particles_collective() && dense;
    if (pd.write == LUB_PAR_WRITE_COLLECTIVE && !dense)
        lub_warning("%s: writeParticles collective, but the particles' ids are not 0 .. %zu "
                    "(the rows of a particle file): gathered to rank 0 instead",
                    path, total - 1);
    lub_message("Particle files: %s",
                r->collective ? "written collectively (MPI-IO: every rank its rows)"
                : pd.write == LUB_PAR_WRITE_GATHER ? "gathered to rank 0 (writeParticles: gather)"
                : !lub_particles_collective()
                    ? "gathered to rank 0 (this build has the serial HDF5)"
                    : "gathered to rank 0 (the ids are not 0 .. N-1)");
}

void lubfoam_parallel_free(lubfoam_run *r)
{
    if (!r->parallel) return;
    lub_par_free(&r->par);
    if (r->G.cap) lub_particles_free(&r->G);
    if (r->R.cap) lub_particles_free(&r->R);
    free(r->place);
}
