/* lubFoam -parallel: the run on the ranks of mpirun (src/parallel/par.h, doc/parallel.md).
 *
 * The start on the slabs: every rank reads the small dictionaries itself and its slice of
 * the start's particle file (about N / P rows); the slices go to the slabs' owners (cuts at
 * the quantiles of the coordinate over all ranks), and the scene is built on the rank's slab,
 * its solver's arrays sized for the slab, its halo and a margin: no rank holds the whole
 * case.  The start-up figures and checks that need the whole case are collective (the
 * particle counts, the stability limits, the models' checks).  What is not parallel yet is
 * refused here, before anything is written, naming it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "io/dict.h"
#include "models/fluid.h"
#include "lubFoam.h"

int lubfoam_wants_parallel(int argc, char **argv)
{
    for (int k = 1; k < argc; k++)
        if (strcmp(argv[k], "-parallel") == 0) return 1;
    return 0;
}

/* The models a parallel run has: the others are refused (exit 1) by their names in
 * constant/models.yaml, before any model reads its entry (a model's start-up on a slab,
 * which it does not know of, could fail with another message first). */
static int parallel_model(const char *name)
{
    return strcmp(name, "gravity") == 0 || strcmp(name, "movingWalls") == 0 ||
           strcmp(name, "collision") == 0;
}

void lubfoam_parallel_start(lubfoam_run *r, const lub_geometry *geo)
{
    char path[LUB_PATH_MAX];
    lub_par_read_dict(&r->pd, lub_case_path(&r->cs, path, "system/decomposeParDict.yaml"), geo->dim,
                      lub_par_size());
    lub_dict *md = lub_dict_read_optional(lub_case_path(&r->cs, path, "constant/models.yaml"));
    lub_node *root = md ? lub_dict_root(md) : NULL;
    for (int k = 0; root && lub_model_types[k]; k++) {
        const char *name = lub_model_types[k]->name;
        if (lub_dict_find(root, name) && !parallel_model(name))
            lub_fatal("%s: the model '%s' does not run in parallel yet (lubFoam -parallel "
                      "takes gravity, movingWalls and collision): run it without -parallel "
                      "(doc/parallel.md)",
                      path, name);
    }
    if (md) lub_dict_free(md);
    r->parallel = 1;
}

void lubfoam_parallel_distribute(lubfoam_run *r, const lub_geometry *geo, const lub_particles *S,
                                 const uint64_t *place, const char *path)
{
    if (r->pd.method == LUB_PAR_SFC) {
        /* the curve's cells as wide as the halo will be: the neighbour lists' radius of the
         * schemes and l0 (a model's wider lists, known later, make the halo reach further
         * cells: lub_par's halo takes as many as the width needs) */
        lub_mps_config c;
        lub_mps_config_defaults(&c);
        lub_mps_config_read(&c, r->cs.root);
        const double l0 = S->levels[0].l0;
        lub_par_init_sfc(&r->par, geo->dim, lub_mps_list_radius(&c, l0) + l0, geo->dmin, geo->dmax,
                         geo->periodic);
    } else {
        const int axis = r->pd.axis < 0 ? lub_par_longest_axis(S) : r->pd.axis;
        /* the halo's width is the solver's (lubfoam_parallel_capacity) */
        lub_par_init(&r->par, axis, 0.0, geo->dmin[axis], geo->dmax[axis], geo->periodic[axis]);
    }
    r->par.interval = r->pd.interval;
    r->par.imbalance = r->pd.imbalance;
    r->par.margin = r->pd.margin;
    lub_par_set_weights(&r->par, r->pd.weight);
    r->most = lub_par_distribute(&r->par, S, place, &r->P, path);
}

void lubfoam_parallel_capacity(lubfoam_run *r, const lub_mps_config *cfg)
{
    const lub_scene *sc = &r->scene;
    if (strcmp(sc->fluid->name, "mps") != 0)
        lub_fatal("%s: fluid type '%s' does not run in parallel yet (lubFoam -parallel takes "
                  "the semi-implicit MPS fluid, type mps): run it without -parallel",
                  sc->models_path, sc->fluid->name);
    if (r->P.nlevels != 1)
        lub_fatal("%s: resolution levels do not run in parallel yet", sc->models_path);
    const int implicit = cfg->viscosity == LUB_VISCOSITY_CN;
    const int p_bad = cfg->p_solver.kind != LUB_LINSOLVER_PETSC;
    if (p_bad || (implicit && cfg->v_solver.kind != LUB_LINSOLVER_PETSC))
        lub_fatal("%s/system/solution.yaml: lubFoam -parallel solves the %s equation over the "
                  "ranks with PETSc only; the solver %s is serial: set '%s: { solver: petsc, "
                  "ksp: cg, pc: hypre }'",
                  r->cs.root, p_bad ? "pressure" : "viscosity",
                  lub_linsolver_choice_names[p_bad ? cfg->p_solver.kind : cfg->v_solver.kind],
                  p_bad ? "p" : "U");
    /* the halo: every particle within the lists' radius re (1 + skin) of the slab, and l0
     * for the moves within the step (the Courant limit keeps them below l0) */
    const double l0 = r->P.levels[0].l0;
    r->par.width = lub_mps_list_radius(cfg, l0) + l0;
    /* the capacity of the slab: its particles, its halo now and the margin for the
     * migration (a slab that fills later is re-sized between steps: lub_mps_resize) */
    const size_t nhalo = lub_par_halo_count(&r->par, &r->P), n = r->par.nown + nhalo;
    const size_t cap = n + (size_t)ceil(r->pd.margin * (double)n);
    lub_particles_reserve(&r->P, cap ? cap : 1);
    r->scene.par = &r->par;
}

void lubfoam_parallel_setup(lubfoam_run *r, const lubfoam_functions *fos)
{
    char path[LUB_PATH_MAX];
    lub_case_path(&r->cs, path, "system/decomposeParDict.yaml");
    const int size = lub_par_size(), axis = r->par.axis;
    const char *fo = lubfoam_functions_unparallel(fos);
    if (fo)
        lub_fatal("%s/system/controlDict.yaml: the function object '%s' (type forces) does not "
                  "run in parallel yet (totals, wallPressure and wallLoad do): remove it for the "
                  "parallel run",
                  r->cs.root, fo);
    const lub_mps *m = r->scene.level[0];
    if (r->par.width != m->nb.rs + m->l0)
        lub_bug("the halo's width %.17g, the solver's lists %.17g + l0", r->par.width, m->nb.rs);
    const size_t total = r->par.ntotal;
    /* what each rank holds: its slab or range, not the case (doc/parallel.md, per-rank
     * capacity) */
    const double cap = lub_par_max((double)r->P.cap);
    if (r->par.method == LUB_PAR_SFC) {
        const lub_par *d = &r->par;
        char cells[96];
        snprintf(cells, sizeof cells, d->dim == 3 ? "%d x %d x %d" : "%d x %d", d->ncell[0],
                 d->ncell[1], d->ncell[2]);
        double h = d->csize[0];
        for (int k = 1; k < d->dim; k++) h = fmin(h, d->csize[k]);
        char axes[16] = "";
        for (int j = 0; j < d->ncurve; j++)
            snprintf(axes + strlen(axes), sizeof axes - strlen(axes), "%s%c", j ? ", " : "",
                     "xyz"[d->curve[j]]);
        lub_message("Parallel: %d ranks, sfc: ranges of a Hilbert curve over %s cells of at "
                    "least %g m (the curve through %s%s), %zu particles, at most %zu per rank "
                    "(mean %.0f), halo width %g m",
                    size, cells, h, axes, d->ncurve < d->dim ? "; the cells across it one key" : "",
                    total, r->most, (double)total / size, d->width);
        lub_message("Ranges: each rank's particles and solver sized for its range of the curve, "
                    "its halo and a margin of %g: capacity at most %.0f particles per rank, "
                    "%.1f%% of the case",
                    r->pd.margin, cap, total ? 100 * cap / (double)total : 0.0);
    } else {
        char cuts[256] = "";
        size_t len = 0;
        for (int k = 1; k < size && len + 32 < sizeof cuts; k++)
            len += (size_t)snprintf(cuts + len, sizeof cuts - len, "%s%.9g", k > 1 ? " " : "",
                                    r->par.cut[k]);
        lub_message("Parallel: %d ranks, slabs along %c (%s), %zu particles, at most %zu per "
                    "rank (mean %.0f), halo width %g m%s%s",
                    size, "xyz"[axis],
                    r -> pd.axis<0 ? "auto: the fluid's longest" : "given", total, r->most,
                                 (double)total / size, r->par.width, size> 1
                             ? ", cuts at "
                             : "",
                    cuts);
        lub_message("Slabs: each rank's particles and solver sized for its slab, its halo and "
                    "a margin of %g: capacity at most %.0f particles per rank, %.1f%% of the "
                    "case",
                    r->pd.margin, cap, total ? 100 * cap / (double)total : 0.0);
    }
    if (r->par.weighted)
        lub_message("Weights: the cuts give each rank about 1/%d of the particles' weight, "
                    "fluid %g, wall %g, dummy %g (decomposeParDict weights), not of their count",
                    size, r->pd.weight[0], r->pd.weight[1], r->pd.weight[2]);
    /* the particle files: collective when the build's HDF5 is Open MPI's and the ids are
     * the rows (0 .. N-1, as particleGen numbers them), else gathered to rank 0 */
    const int dense = lub_par_ids_dense(&r->par, &r->P);
    r->collective = r->pd.write != LUB_PAR_WRITE_GATHER && lub_particles_collective() && dense;
    if (r->pd.write == LUB_PAR_WRITE_COLLECTIVE && !dense)
        lub_warning("%s: writeParticles collective, but the particles' ids are not 0 .. %zu "
                    "(the rows of a particle file): gathered to rank 0 instead",
                    path, total - 1);
    lub_message("Particle files: %s", r->collective
                                          ? "written collectively (MPI-IO: every rank its rows)"
                                      : r->pd.write == LUB_PAR_WRITE_GATHER
                                          ? "gathered to rank 0 (writeParticles: gather)"
                                      : !lub_particles_collective()
                                          ? "gathered to rank 0 (this build has the serial HDF5)"
                                          : "gathered to rank 0 (the ids are not 0 .. N-1)");
}

void lubfoam_collective_check(const lubfoam_run *r,
                              void (*check)(const lubfoam_run *r, const void *ctx), const void *ctx)
{
    if (!r->parallel) {
        check(r, ctx);
        return;
    }
    lub_catcher c;
    const char *msg = NULL;
    int status = LUB_EXIT_INPUT;
    if (lub_error_catch(&c) == 0) {
        check(r, ctx);
        lub_error_uncatch();
    } else {
        msg = c.message;
        status = c.status;
    }
    lub_par_raise(status, msg);
}

void lubfoam_parallel_free(lubfoam_run *r)
{
    if (!r->parallel) return;
    lub_par_free(&r->par);
    if (r->G.cap) lub_particles_free(&r->G);
    if (r->R.cap) lub_particles_free(&r->R);
    free(r->place);
}
