/* lubkit MPS: the solver's dictionaries (see mps.h).
 *
 * system/schemes.yaml (defaults in etc/templates/schemes.yaml):
 *
 *     effectiveRadius:  3.1          # re / l0 (T-6)
 *     gradient:         lsmps        # standard (T-13) | lsmps (T-15)
 *     minPressureShift: true         # p_hat of T-14 in the gradient
 *     negativePressure: clip         # clip | keep | cavitation
 *     dummyVelocity:    mirror       # mirror (ghost 2 U - u_i) | wall (U) | extrapolate | flux
 *     pressure:         { alpha: 0, gamma: 0.2, predictor: 0.1, trend: 0 }   # T-9; lub_mps_step
 *     freeSurface:      { beta: 0.97, asymmetry: 0.2, test: sector, sectorAngle: 60,
 *                         exposedAngle: 150 }
 *                       # T-12 + geometric tests (test: sector | centroid | pnd)
 *     neighbourSkin:    0.2
 *     lsmpsDetMin:      1.0e-2
 *     laplacian:        { viscosity: standard, pressure: standard, lsmpsRcond: 1e-3,
 *                         stabilization: { strength: 1, onset: 3 } }
 *                       # standard | lsmps | lsmpsStabilized (mps/lsmps.h)
 *     particleOrder:    cells        # cells | rows
 *     reorderInterval:  1
 *
 * system/solution.yaml:
 *
 *     p: { solver: pcg, preconditioner: amg, cycle: W, tolerance: 1e-8, maxIter: 2000,
 *          warmStart: true, onFailure: stop }          # cycle V | W; stop | continue
 *     U: { solver: pcg, preconditioner: jacobi, tolerance: 1e-8, maxIter: 500 }
 *     (solver petsc: ksp cg | gmres | bcgs, pc hypre | gamg | jacobi | bjacobi | sor | none)
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "io/case.h"
#include "io/dict.h"
#include "mps/mps.h"
#include "mps/lsmps.h"
#include "mps/operators.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

void lub_mps_config_defaults(lub_mps_config *c)
{
    memset(c, 0, sizeof *c);
    c->re_l0 = 3.1;
    c->gradient = LUB_GRADIENT_LSMPS;
    c->min_pressure_shift = 1;
    c->clip_negative = 1;
    c->alpha = 0.0;
    c->gamma = 0.2;
    c->source = LUB_SOURCE_PND;
    c->predictor = 0.1;
    c->trend = 0.0;
    c->beta = 0.97;
    c->surface_test = LUB_SURFACE_SECTOR;
    c->asymmetry = 0.2;
    c->cone_cos = cos(M_PI / 6);             /* sectorAngle 60 degrees */
    c->exposed_cos = cos(75.0 * M_PI / 180); /* exposedAngle 150 degrees */
    c->skin = 0.0;
    c->lsmps_det_min = LUB_MPS_LSMPS_DET_MIN;
    c->reorder_interval = 1;
    c->lap_viscosity = LUB_LAPLACIAN_STANDARD;
    c->lap_pressure = LUB_LAPLACIAN_STANDARD;
    c->lsmps_rcond = LUB_LSMPS_RCOND_MIN;
    c->stab_strength = LUB_LSMPS_STAB_STRENGTH;
    c->stab_onset = LUB_LSMPS_STAB_ONSET;
    c->surf_viscosity = 0;
    c->surf_pressure = 0;
    c->surf_weight = LUB_LSMPS_BC_WEIGHT;
    c->order_rows = 0;
    c->dummy_velocity = LUB_DUMMY_MIRROR;
    c->p_solver = lub_linsolver_defaults();
    c->p_solver.pcg.tolerance = 1e-8;
    c->p_solver.pcg.precond = LUB_PRECOND_AMG;
    c->p_solver.pcg.warm_start = 1;
    c->v_solver = lub_linsolver_defaults();
    c->v_solver.pcg.tolerance = 1e-8;
    c->v_solver.pcg.precond = LUB_PRECOND_JACOBI;
    c->v_solver.pcg.warm_start = 1;
    c->viscosity = LUB_VISCOSITY_NONE;
}

void lub_mps_film_defaults(lub_mps_config *c)
{
    c->trend = 0.1;
    c->dummy_velocity = LUB_DUMMY_FLUX;
    c->lap_viscosity = LUB_LAPLACIAN_STABILIZED;
    c->surf_viscosity = 1; /* stressFree */
    c->surf_weight = LUB_LSMPS_BC_WEIGHT;
    c->film_defaults = 1;
}

static void read_linsolver(lub_node *map, lub_linsolver_options *o, int *cont)
{
    static const char *const fail[] = {"stop", "continue", NULL};
    if (!map) return;
    o->kind = lub_dict_choice(map, "solver", lub_linsolver_choice_names, o->kind);
    if (o->kind == LUB_LINSOLVER_PETSC && !lub_petsc_available())
        lub_node_error(lub_dict_find(map, "solver"),
                       "solver 'petsc': this lubkit was built without PETSc (install petsc-dev, "
                       "e.g. bin/installDeps, and rebuild: make), or choose cholmod or pcg");
    o->petsc.ksp = lub_dict_choice(map, "ksp", lub_petsc_ksp_names, o->petsc.ksp);
    o->petsc.pc = lub_dict_choice(map, "pc", lub_petsc_pc_names, o->petsc.pc);
    o->pcg.precond =
        lub_dict_choice(map, "preconditioner", lub_precond_choice_names, o->pcg.precond);
    o->pcg.tolerance =
        lub_dict_real_or(map, "tolerance", o->pcg.tolerance, (lub_range){0.0, 1.0, 1, 1});
    o->pcg.max_iter = (int)lub_dict_int_or(map, "maxIter", o->pcg.max_iter, 1, 100000000);
    o->pcg.warm_start = lub_dict_bool_or(map, "warmStart", o->pcg.warm_start);
    o->pcg.cycle = 1 + lub_dict_choice(map, "cycle", lub_amg_cycle_names, o->pcg.cycle - 1);
    o->cholmod.ordering =
        lub_dict_choice(map, "ordering", lub_cholmod_ordering_names, o->cholmod.ordering);
    *cont = lub_dict_choice(map, "onFailure", fail, 0);
}

static void read_schemes(lub_mps_config *c, const char *path)
{
    static const char *const grad[] = {"standard", "lsmps", NULL};
    static const char *const neg[] = {"keep", "clip", "cavitation", NULL};
    static const char *const dummy[] = {"wall", "mirror", "extrapolate", "flux", NULL};
    lub_dict *d = lub_dict_read(path);
    lub_node *r = lub_dict_root(d);
    c->re_l0 = lub_dict_real_or(r, "effectiveRadius", 3.1, LUB_BETWEEN(1.5, 6.0));
    c->gradient = lub_dict_choice(r, "gradient", grad, LUB_GRADIENT_LSMPS);
    c->min_pressure_shift = lub_dict_bool_or(r, "minPressureShift", 1);
    c->clip_negative = lub_dict_choice(r, "negativePressure", neg, LUB_NEGATIVE_CLIP);
    c->dummy_velocity = lub_dict_choice(r, "dummyVelocity", dummy, c->dummy_velocity);
    lub_node *p = lub_dict_map_or(r, "pressure");
    c->alpha = lub_dict_real_or(p, "alpha", 0.0, LUB_NONNEGATIVE);
    c->gamma = lub_dict_real_or(p, "gamma", 0.2, (lub_range){0.0, 1.0, 1, 0});
    c->predictor = lub_dict_real_or(p, "predictor", c->predictor, LUB_BETWEEN(0.0, 1.0));
    /* a default trend (a film's, lub_mps_film_defaults) goes with the predictor: off where
     * the dictionary turns the predictor off */
    if (!lub_dict_find(p, "trend") && c->predictor == 0) c->trend = 0.0;
    c->trend = lub_dict_real_or(p, "trend", c->trend, LUB_BETWEEN(0.0, 1.0));
    if (c->trend > 0 && c->predictor == 0)
        lub_node_error(lub_dict_find(p, "trend"),
                       "pressure.trend %g smooths the predictor's running mean, but the "
                       "predictor is off (predictor: 0): set predictor > 0, or remove trend",
                       c->trend);
    static const char *const sources[] = {"pnd", "mixed", NULL};
    c->source = lub_dict_choice(p, "source", sources, LUB_SOURCE_PND);
    lub_node *fs = lub_dict_map_or(r, "freeSurface");
    c->beta = lub_dict_real_or(fs, "beta", 0.97, (lub_range){0.0, 1.0, 1, 1});
    static const char *const stest[] = {"sector", "centroid", "pnd", NULL};
    c->surface_test = lub_dict_choice(fs, "test", stest, LUB_SURFACE_SECTOR);
    if (c->surface_test != LUB_SURFACE_PND)
        c->asymmetry = lub_dict_real_or(fs, "asymmetry", 0.2, LUB_BETWEEN(0.0, 10.0));
    else if (lub_dict_find(fs, "asymmetry"))
        lub_node_error(lub_dict_find(fs, "asymmetry"),
                       "freeSurface: 'asymmetry' has no use with test: pnd");
    if (c->surface_test == LUB_SURFACE_SECTOR) {
        const double sector = lub_dict_real_or(fs, "sectorAngle", 60.0, LUB_BETWEEN(10.0, 179.0));
        c->cone_cos = cos(0.5 * sector * M_PI / 180.0);
        /* default 150 degrees, or the sector's opening when that is wider */
        const double exposed =
            lub_dict_real_or(fs, "exposedAngle", fmax(150.0, sector), LUB_BETWEEN(10.0, 179.0));
        if (exposed < sector)
            lub_node_error(lub_dict_find(fs, "exposedAngle"),
                           "freeSurface: exposedAngle (%g degrees) must be at least sectorAngle "
                           "(%g degrees): an empty sector of exposedAngle makes a surface "
                           "particle by itself, one of sectorAngle only where the surface "
                           "reaches it",
                           exposed, sector);
        c->exposed_cos = cos(0.5 * exposed * M_PI / 180.0);
    } else {
        static const char *const only[] = {"sectorAngle", "exposedAngle"};
        for (int k = 0; k < 2; k++)
            if (lub_dict_find(fs, only[k]))
                lub_node_error(lub_dict_find(fs, only[k]),
                               "freeSurface: '%s' belongs to test: sector (the test is '%s')",
                               only[k], stest[c->surface_test]);
    }
    c->skin = lub_dict_real_or(r, "neighbourSkin", 0.0, LUB_BETWEEN(0.0, 1.0));
    c->lsmps_det_min =
        lub_dict_real_or(r, "lsmpsDetMin", LUB_MPS_LSMPS_DET_MIN, (lub_range){0.0, 1.0, 1, 1});
    static const char *const lap[] = {"standard", "lsmps", "lsmpsStabilized", NULL};
    lub_node *ls = lub_dict_map_or(r, "laplacian");
    c->lap_viscosity = lub_dict_choice(ls, "viscosity", lap, c->lap_viscosity);
    c->lap_pressure = lub_dict_choice(ls, "pressure", lap, c->lap_pressure);
    c->lsmps_rcond = lub_dict_real_or(ls, "lsmpsRcond", c->lsmps_rcond, LUB_BETWEEN(1e-12, 0.5));
    lub_node *stab = lub_dict_map_or(ls, "stabilization");
    c->stab_strength = lub_dict_real_or(stab, "strength", c->stab_strength, LUB_BETWEEN(0.0, 1e6));
    c->stab_onset = lub_dict_real_or(stab, "onset", c->stab_onset, LUB_BETWEEN(1.0, 1e6));
    lub_node *lfs = lub_dict_map_or(ls, "freeSurface");
    static const char *const vbc[] = {"none", "stressFree", NULL};
    static const char *const pbc[] = {"none", "surfacePoint", NULL};
    c->surf_viscosity = lub_dict_choice(lfs, "viscosity", vbc, c->surf_viscosity);
    c->surf_pressure = lub_dict_choice(lfs, "pressure", pbc, c->surf_pressure);
    c->surf_weight = lub_dict_real_or(lfs, "weight", c->surf_weight, LUB_BETWEEN(1e-6, 1e6));
    /* a film's default dummies carry the wall slip into the fitted viscous rows (E); with
     * the standard Laplacian the mirror measured better (tutorials/README.md, "The dummies'
     * velocity") */
    if (c->film_defaults && !lub_dict_find(r, "dummyVelocity") &&
        !LUB_LAPLACIAN_FITTED(c->lap_viscosity))
        c->dummy_velocity = LUB_DUMMY_MIRROR;
    static const char *const order[] = {"cells", "rows", NULL};
    c->order_rows = lub_dict_choice(r, "particleOrder", order, c->order_rows);
    c->reorder_interval =
        (int)lub_dict_int_or(r, "reorderInterval", c->reorder_interval, 0, 1000000);
    lub_dict_finish(d);
    lub_dict_free(d);
}

static void read_solution(lub_mps_config *c, const char *path)
{
    lub_dict *d = lub_dict_read_optional(path);
    lub_node *r = d ? lub_dict_root(d) : NULL;
    read_linsolver(lub_dict_map_or(r, "p"), &c->p_solver, &c->p_continue);
    read_linsolver(lub_dict_map_or(r, "U"), &c->v_solver, &c->v_continue);
    if (d) {
        lub_dict_finish(d);
        lub_dict_free(d);
    }
}

void lub_mps_config_read(lub_mps_config *c, const char *case_dir)
{
    lub_case cs;
    char path[LUB_PATH_MAX];
    lub_case_open(&cs, case_dir);
    read_schemes(c, lub_case_path(&cs, path, "system/schemes.yaml"));
    read_solution(c, lub_case_path(&cs, path, "system/solution.yaml"));
}
