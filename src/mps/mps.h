/* lubkit MPS: the semi-implicit MPS solver for one resolution level (methods.md §2).
 *
 * The step follows the thesis (Figure 1):
 *
 *     1. neighbour lists at r^k (cell-linked list; kept while particles move < skin re / 2)
 *     2. viscosity and body force -> u*           explicit (T-7) or Crank-Nicolson (T-31)
 *        (pressure predictor: with the force -G/rho of the running mean G of the pressure
 *        gradient, which is then added back: u* += dt G / rho)
 *        and the models' per-particle forces at r^k (surface tension): u* += dt F/m
 *     3. temporary positions r* = r^k + u* dt      (T-8); walls move with their velocity
 *     4. PND n* at r*                              (T-11)
 *     5. free surface: n* < beta n0, refined by geometric tests   (T-12): the neighbours'
 *        centroid off-centre and an open side (an empty sector or cone around the particle)
 *     6. pressure Poisson equation                 (T-9, T-10), Dirichlet p = 0 on the surface
 *        (with alpha = 0 also on a group of particles that touches no surface particle: its
 *        pressure would be undetermined; st.nisolated)
 *     7. pressure gradient                         standard (T-13, T-14) or LSMPS (T-15)
 *     8. u^{k+1} = u* - dt/rho grad p, r^{k+1} = r* + (u^{k+1} - u*) dt   (T-16, T-17)
 *     9. the models' corrections (collision), periodic wrap, checks (non-finite values, the
 *        domain box, a fluid particle through a wall: lub_mps_check)
 *
 * Models act at named points of the step through lub_mps.hooks (src/models/model.h fills
 * them in for the models of a scene): forces in step 2 (gravity), particle forces after it
 * (surface tension), after the correction in step 9 (collision).  The step knows no model by name.
 *
 * Pressure predictor (schemes.yaml pressure.predictor, not in the thesis).  Without it, a
 * steady flow balances grad p / rho = nu lap(u*) with u* = u + dt grad p / rho: the viscous
 * step acts on the pressure's velocity increment too, and at a no-slip wall the Laplacian of
 * that increment is of order dt grad p / l0^2, an error of relative size nu dt / l0^2
 * (9 in the thesis wedge).  The wedge pressure then comes out 20-25% low and the periodic
 * step bearing's pressure gradient 22% low (tests/unit/mps_flow_test.c).  With the viscous
 * step made under the force -G/rho, G the running mean of the pressure gradient at the
 * particle (G += a (grad p - G) each step, a = predictor), and dt G / rho added back after
 * it, the steady balance is exact and the pressure equation (PND source) is unchanged.  The
 * running mean (rather than the last gradient) keeps the step-to-step noise of the
 * pressure out of the feedback, which otherwise grows near free surfaces.  A running mean
 * lags, though: a particle that moves through a steady film, or sits in a squeeze film whose
 * pressure grows, feels the gradient of (1 - a)/a steps ago, and the balance is off by the
 * change since (the inclined pad's film 5% low at h0/4 with a = 0.1).  With pressure.trend
 * b > 0 the mean carries its trend T too (Holt's linear smoothing, lub_mps_predictor_update)
 * and the viscous step feels the forecast G + T, which has no lag for a gradient changing
 * linearly along the path.  G is stored as the particle fields gradPx, gradPy (gradPz),
 * T as gradPTrendx, ..., so a restart is exact.
 *
 * Walls are one layer of wall particles (pressure solved) with dummy layers behind them (PND
 * only).  Wall and dummy particles move with the velocity of their patch (movingWalls), or,
 * on a patch with patch_moved set, with the velocity a model gave them before the step
 * (elasticWall: models/elasticWall/elasticWall.h).
 *
 * Configuration comes from system/schemes.yaml, system/solution.yaml (lub_mps_config_read),
 * constant/transportProperties.yaml and constant/models.yaml (the fluid and the models of
 * src/models/ fill in the rest); the state is a lub_particles
 * plus work arrays allocated once (lub_mps_init): the step never allocates.
 */
#ifndef LUB_MPS_MPS_H
#define LUB_MPS_MPS_H

#include <stdint.h>

#include "core/timer.h"
#include "linalg/bicgstab.h"
#include "linalg/linsolve.h"
#include "mps/neighbours.h"
#include "parallel/par.h"
#include "particles/particles.h"

enum { LUB_GRADIENT_STANDARD = 0, LUB_GRADIENT_LSMPS = 1 };
/* pressure.source: the PND deviation alone (T-9), or with the divergence of u* (mixed) */
enum { LUB_SOURCE_PND = 0, LUB_SOURCE_MIXED = 1 };
/* One step of the predictor's running mean of a pressure-gradient component at a particle:
 * Holt's linear exponential smoothing (methods.md §2.2, [Ho57]) of the newest value x with
 * the level weight a (pressure.predictor) and the trend weight b (pressure.trend).  The
 * forecast for the next step is *G + *T; with b = 0 and *T = 0 it is the plain running mean
 * G += a (x - G). */
static inline void lub_mps_predictor_update(double *G, double *T, double x, double a, double b)
{
    const double f = *G + *T, g = f + a * (x - f);
    *T = b * (g - *G) + (1.0 - b) * *T;
    *G = g;
}

enum { LUB_VISCOSITY_NONE = 0, LUB_VISCOSITY_EXPLICIT = 1, LUB_VISCOSITY_CN = 2 };
enum { LUB_NEGATIVE_KEEP = 0, LUB_NEGATIVE_CLIP = 1, LUB_NEGATIVE_CAVITATION = 2 };
enum { LUB_SURFACE_SECTOR = 0, LUB_SURFACE_CENTROID = 1, LUB_SURFACE_PND = 2 };
/* laplacian.viscosity / .pressure: T-3, LSMPS (1.1), stabilized LSMPS (1.2) */
enum { LUB_LAPLACIAN_STANDARD = 0, LUB_LAPLACIAN_LSMPS = 1, LUB_LAPLACIAN_STABILIZED = 2 };
/* the fitted (LSMPS) Laplacians: pair coefficients, nonsymmetric rows */
#define LUB_LAPLACIAN_FITTED(k) ((k) != LUB_LAPLACIAN_STANDARD)
/* dummyVelocity: the wall's U, the mirror ghost 2 U - u_i, or the no-slip profile extrapolated */
enum { LUB_DUMMY_WALL = 0, LUB_DUMMY_MIRROR = 1, LUB_DUMMY_EXTRAPOLATE = 2, LUB_DUMMY_FLUX = 3 };
/* extrapolate and flux continue the no-slip profile (and need its curvature) */
#define LUB_DUMMY_CONTINUES(v) ((v) == LUB_DUMMY_EXTRAPOLATE || (v) == LUB_DUMMY_FLUX)

typedef struct {
    /* system/schemes.yaml */
    double re_l0;           /* re / l0 (T-6; 3.1) */
    int gradient;           /* LUB_GRADIENT_* */
    int min_pressure_shift; /* p_hat of T-14 */
    int clip_negative;      /* LUB_NEGATIVE_*: negative pressure kept, set to 0 after the
                               solve, or held at 0 by the cavitation condition */
    double alpha, gamma;    /* T-9 */
    int source;             /* LUB_SOURCE_*: the pressure equation's source (step.c, pressure) */
    double predictor;       /* weight of the newest pressure gradient in the running mean
                               that the viscous predictor feels (0: off; see lub_mps_step) */
    double trend;           /* weight of the newest change in that mean's trend (Holt's
                               linear smoothing, lub_mps_predictor_update; 0: none) */
    double beta;            /* free surface: n* < beta n0 (T-12) */
    int surface_test;       /* LUB_SURFACE_*: the geometric test of a low-PND particle */
    double asymmetry;       /* centroid offset / l0 above which a low-PND particle is on the
                               surface (centroid and sector tests) */
    double cone_cos;        /* sector test: cosine of half the opening of the empty sector */
    double exposed_cos;     /* sector test: the same of exposedAngle (<= cone_cos): a wider
                               empty sector makes a surface particle by itself, a narrower one
                               only where the surface reaches it (step.c, free_surface) */
    double skin;            /* neighbour search radius re (1 + skin) */
    double lsmps_det_min;   /* LSMPS fallback threshold */
    int lap_viscosity;      /* LUB_LAPLACIAN_*: the Laplacian of the viscous term */
    int lap_pressure;       /* LUB_LAPLACIAN_*: the Laplacian of the pressure equation */
    double lsmps_rcond;     /* LSMPS Laplacian: smallest pivot ratio of M_i (mps/lsmps.h) */
    double stab_strength;   /* stabilized LSMPS: the bias penalty's strength and onset */
    double stab_onset;      /* (lub_lsmps_stabilization, mps/lsmps.h) */
    int surf_viscosity;     /* fitted viscosity: the stress-free row at the free surface (1) */
    int surf_pressure;      /* fitted pressure: the surface point P = 0 in the fit (1) */
    double surf_weight;     /* their weight (lub_lsmps_bc.weight) */
    int reorder_interval;   /* steps between sorts of the particles (0: never) */
    int order_rows;         /* the sort: 0 cell order, 1 lattice rows of l0 */
    int dummy_velocity;     /* LUB_DUMMY_*: the dummies' velocity in the viscous term (step.c,
                               dummy_velocity) */
    int film_defaults;      /* the defaults were a film's (lub_mps_film_defaults) */
    double list_l0;         /* set by the fluid's formulation or a model, not read: the
                               neighbour lists reach at least list_l0 l0 when built (MPH:
                               h_v = 3.5 l0, models/fluid/mph.c), by a larger skin; their
                               weights w stay those of re (0 beyond); 0: re (1 + skin) */

    /* system/solution.yaml */
    lub_linsolver_options p_solver, v_solver;
    int p_continue, v_continue; /* continue the run when a solve fails */

    /* constant/ */
    double rho, nu;
    int gravity;   /* a uniform body acceleration g given with the configuration (callers */
    double g[3];   /* without models; the models of a scene add theirs: hooks.forces) */
    int viscosity; /* LUB_VISCOSITY_* */
    double bulk_viscosity, bulk_modulus; /* MPH lambda [Pa s], kappa [Pa] (models/fluid/mph.c) */
    int viscous_layers;       /* MPH: the viscous coefficient 2 (d+2) over lub_mph_layer_quadrature
                                 (viscousNormalisation: layers; 0: the continuum's) */
    int divergence_corrected; /* MPH: the bulk viscosity's divergence renormalised, exact
                                 for linear velocity fields (divergence: corrected; 0:
                                 Kondo's kernel sum, plain) */
    double mph_shifting;      /* MPH: particle shifting, beta per step (shifting; 0: off) */
    int gradient_corrected;   /* MPH: kappa's pair force with the renormalised kernel gradient
                                 (P_i B_i + P_j B_j) g_ij (gradient: corrected; 0: (K-6)'s
                                 (P_i + P_j) g_ij, plain) */
    double patch_velocity[LUB_MAX_PATCHES][3]; /* wall velocities (movingWalls); on a patch
                                                  a model moves: a velocity of its largest
                                                  speed (lubFoam's Courant number), or 0 */
    int patch_moved[LUB_MAX_PATCHES]; /* 1: a model sets the velocity of the patch's wall and
                                         dummy particles before each step (elasticWall, a
                                         movingWalls motion history) */
    int patch_rigid[LUB_MAX_PATCHES]; /* 1: the patch is a rigid body that may turn
                                         (rigidBodies): the walls' own quantities of
                                         surfaceTension follow it every step */

    /* set by a model that drives the solvers (multiResolution), not read from a dictionary */
    int fixed_flags; /* allocate lub_mps.fixed: particles whose velocity and pressure are given */
    int still_walls; /* wall and dummy particles keep their positions while carrying their
                        patch velocity: every wall is at rest or a plane sliding along itself,
                        so that the walls of a level stay in the part of x the level covers;
                        except on the patches a model moves (patch_moved), whose particles move
                        with the velocity it gives them (elasticWall: vertically, x kept) */
} lub_mps_config;

/* The defaults of every entry (those of etc/templates/schemes.yaml and solution.yaml). */
void lub_mps_config_defaults(lub_mps_config *c);
/* A film's defaults, over lub_mps_config_defaults' (the thesis' standard MPS): where the
 * viscosity is implicit on a single resolution without rigid bodies (src/models/fluid/mps.c),
 * the measured choice of tutorials/README.md ("The defaults"): pressure.trend 0.1 (where the
 * predictor is on), dummyVelocity flux, laplacian.viscosity lsmpsStabilized with the
 * stress-free surface row (weight 100).  Entries of system/schemes.yaml override them. */
void lub_mps_film_defaults(lub_mps_config *c);
/* Read the case's (case_dir: its root) system/schemes.yaml and system/solution.yaml into c
 * (set to the defaults, and rho, nu and the viscosity scheme, by the caller: the fluid of
 * src/models/fluid/mps.c).  Fatal (exit 1) with file:line on bad input. */
void lub_mps_config_read(lub_mps_config *c, const char *case_dir);

/* What the last step did, for the log and the cost table. */
typedef struct {
    lub_solve_result p, v[3];
    size_t nsurface, nunknowns, nfallback, nrebuild;
    size_t nlapfallback;            /* LSMPS Laplacian rows taken as standard (lsmps.h) */
    size_t nlapblend;               /* stabilized LSMPS rows blended with T-3 (theta < 1) */
    size_t nisolated;               /* particles of groups touching no Dirichlet particle, taken as
                                       surface particles (step.c, isolated_groups) */
    unsigned long long isolated_id; /* the id of the first of them */
    double umax;                    /* largest fluid speed after the step */
    /* The compression that holds the pressure (methods.md §2.5, (2.5b)): the mean and the
     * largest (n* - n0)/n0 of the interior fluid particles (fluid, not on a free surface, PND at
     * least beta n0: a full neighbourhood) at the step's r*; 0 when there are none. */
    double compression, compression_max;
    /* since the start: fluid particles the collision model stopped at a wall's plane (its
     * walls' holes: src/models/collision/collision.c) */
    size_t nwallplane;
} lub_mps_stats;

/* Phases timed in every run (cost.dat columns). */
enum {
    LUB_T_NEIGHBOUR,
    LUB_T_VISCOSITY,
    LUB_T_ASSEMBLY,
    LUB_T_PSOLVE,
    LUB_T_GRADIENT,
    LUB_T_OTHER,
    LUB_T_OUTPUT,
    LUB_T_COUNT
};
extern const char *const lub_mps_phase_names[]; /* neighbourSearch, viscositySolve, ... */

typedef struct lub_mps lub_mps;

/* What the models do inside the step (methods.md §2), at its named points; ctx is passed
 * back.  Each may be NULL. */
typedef struct {
    void *ctx;
    /* step 2, viscosity and body force: add the step's uniform body acceleration [m/s^2] to
     * acc (it holds the configuration's g); returns 1 if it added one */
    int (*forces)(void *ctx, const lub_mps *m, double dt, double acc[3]);
    /* step 9, after the correction (u^{k+1}, r^{k+1}) and before the periodic wrap and the
     * checks: a change of the fluid particles' velocities and positions (collision) */
    void (*after_correction)(void *ctx, lub_mps *m, double dt);
    /* forces that depend on the particles (surface tension): add each fluid particle's
     * acceleration [m/s^2] to acc[d][i] (zeroed by the caller), from the lists of the step
     * (complete to list_l0 l0) at the current positions; returns 1 if it added any.  The
     * fluid's step adds dt acc to u* (lub_mps_particle_forces): MPS after the viscous step
     * (at r^k), MPH in its step 4 (at x^{k+1}) */
    int (*particle_forces)(void *ctx, const lub_mps *m, double *const acc[3]);
} lub_mps_hooks;

struct lub_mps {
    lub_mps_config c;
    lub_mps_hooks hooks; /* zero: no model acts in the step */
    lub_particles *P;
    int dim;
    double l0, re, n0, lambda0;
    double lo[3], hi[3];
    int periodic[3];

    lub_neighbours nb;
    lub_csr A; /* pressure, then viscosity matrix */
    /* the LSMPS Laplacian (laplacian.viscosity / .pressure: lsmps): its pair coefficients
     * (lapc, the lists' capacity), the rows that fall back to T-3 (lapflag), the
     * nonsymmetric matrix (A2; the standard one in A preconditions it) and BiCGStab */
    double *lapc;
    size_t lapc_cap;
    uint8_t *lapflag;
    /* the free surface's row in the fits (laplacian.freeSurface, methods.md (1.3)): the
     * outward normal, the distance to the surface (0: no row) and the Dirichlet row's
     * coefficient L_ib of each particle, the surface flags they were formed from; NULL
     * unless configured */
    double *bcn[3], *bcd, *bcdiag;
    uint8_t *bcs;
    double lsmps_g0; /* stabilized LSMPS: g0 of the level (lub_mps_lsmps_reference) */
    lub_csr A2;
    lub_bicgstab_work bw;
    double *dinv;
    lub_linsolver psolver, vsolver;

    size_t cap;
    double *us[3]; /* u* */
    double *pnd;
    double *div; /* pressure.source mixed: the divergence of u* at r* (fluid particles) */ /* n* */
    uint8_t *surface;
    uint8_t *anchor;       /* pressure row next to a Dirichlet particle (step.c, isolated_groups) */
    int nlattice;          /* lattice neighbours within re (2-D: 28 at re = 3.1 l0, 12 at 2.1) */
    int *row;              /* unknown index of a particle, -1 */
    int *prow;             /* particle of an unknown */
    double *b, *x;         /* right-hand side and solution (pressure) */
    double *bv[3], *xv[3]; /* viscosity */
    double *grad[3];
    double *kap[3];  /* dummyVelocity extrapolate: the curvature of the no-slip profile the
                        viscous step of the last step took at each fluid particle, (G/rho -
                        g)/nu (step.c, dummy_velocity), for the wall forces; else NULL */
    double *gbar[3]; /* predictor: running mean of the pressure gradient (particle extra
                        fields gradPx, gradPy, gradPz, so that it is saved and reordered) */
    double *gtr[3];  /* pressure.trend > 0: that mean's trend per step (particle extra fields
                        gradPTrendx, gradPTrendy, gradPTrendz), else NULL */
    double *cav;     /* negativePressure cavitation: 1 where the pressure is held at 0 (particle
                        extra field "cavitation", so that it is saved and reordered), else NULL */
    double *surf;    /* sector test: 1 where the particle was on the free surface at the last
                        step (particle extra field "surface": saved and reordered), else NULL */
    int surf_fresh;  /* the start's particles carry no "surface" field: the first step takes
                        the geometric test alone */
    double *lap;     /* scratch: theta_i of the last stabilized LSMPS coefficients (step.c) */
    /* Given particles: the pressure-equation contributions (and the velocities) of a model,
     * set before the step (multiResolution's fixed band, T-25, T-26).  Reordered with the
     * particles; NULL unless config.fixed_flags. */
    uint8_t *fixed;  /* 1 where a fluid or wall particle's velocity and pressure are given: it
                        is a Dirichlet row of the viscosity (fluid) and pressure equations, keeps
                        its velocity through the step and moves with it (r* = r + u dt, no
                        correction, no collision) */
    uint8_t *inside; /* 1 where a model knows the particle is inside the fluid, so that it is not
                        on a free surface whatever its own PND (multiResolution: the other
                        level's particles fill the neighbourhood, opt.h, Free surface in the
                        overlaps) */
    void *scratch;
    long steps; /* global step count (from the particle file) */
    int built;  /* neighbour lists built once */

    double *pacc[3]; /* hooks.particle_forces' accelerations (allocated at the first step
                        that has the hook); on wall and dummy particles the reactions of the
                        pair forces, kept until the next step (models/model.h) */
    /* a formulation's own work arrays (models/fluid.h; NULL for mps), freed by
     * lub_mps_free with fstate_free */
    void *fstate;
    void (*fstate_free)(void *fstate);

    /* A run on several ranks (parallel/par.h; NULL: serial): the particles this rank owns
     * are P's first par->nown; during a step the halo follows them (lub_mps_set_parallel) */
    lub_par *par;
    double *gidx;  /* [cap] the global row of a particle's unknown (-1: none), for the halo */
    int *colmap;   /* [cap] the global row of each local column of A */
    uint8_t *conn; /* [cap] the isolated-group search: connected to a Dirichlet particle */

    lub_mps_stats st;
    double iterations[2]; /* pressure and viscosity iterations of every step so far */
    lub_timers tm;
};

/* Set up the solver for particles P (the state lives in P; its capacity must not change
 * while the solver runs: the work arrays are allocated for P->cap particles, so P->n may grow
 * up to it between steps).  domain box and periodicity from lo/hi/periodic.  Computes re, n0
 * and lambda0 from l0 (level 0) and writes them into P->levels[0].  P must hold one
 * resolution level: a multi-resolution set is solved level by level (models/multiResolution/opt.h).
 */
void lub_mps_init(lub_mps *m, lub_particles *P, const lub_mps_config *c, const double lo[3],
                  const double hi[3], const int periodic[3]);
void lub_mps_free(lub_mps *m);
/* The neighbour lists' radius re (1 + skin) of a solver of configuration c and spacing l0
 * (the halo of a rank: parallel/par.h). */
double lub_mps_list_radius(const lub_mps_config *c, double l0);
/* Every per-particle array of the solver and the particles P to capacity cap (nothing when
 * cap <= m->cap), their contents kept: one allocation between steps, when the particles of
 * a rank's slab outgrow it (lub_mps_set_parallel). */
void lub_mps_resize(lub_mps *m, size_t cap);

/* Solve on several ranks (parallel/par.h): this rank's particles are P's first d->nown
 * (lub_par_distribute done).  Each step then migrates, builds the halo, refreshes it after
 * each phase whose result a neighbour reads (u* after the viscous step, the free-surface
 * flags, the global rows of the unknowns, the pressure after the solve), solves the pressure
 * and viscosity equations over all ranks (a distributed CSR: linalg/csr.h, PETSc only) and
 * leaves P->n = d->nown.  The step's status, statistics and the largest speed are those of
 * all ranks.  A migration or halo beyond the capacity re-sizes the solver and the particles
 * (d->grow: lub_mps_resize for the count and d->margin again, with a warning).  Refused here
 * (lub_bug; lubFoam refuses them first): the LSMPS Laplacians, given particles
 * (multiResolution), a formulation with its own step. */
void lub_mps_set_parallel(lub_mps *m, lub_par *d);

/* Status of a step. */
typedef enum {
    LUB_STEP_OK = 0,
    LUB_STEP_SOLVE_FAILED, /* a linear solve failed and the dictionary says stop */
    LUB_STEP_NONFINITE,    /* NaN or Inf in a particle value */
    LUB_STEP_ESCAPED,      /* a particle left the domain through a non-periodic side, or a
                              fluid particle went through a wall (elasticWall: a wall would
                              cross the plate, models/elasticWall/elasticWall.h) */
} lub_step_status;

/* Advance by dt.  On failure, *bad is the index of the first offending particle (or -1) and
 * msg describes it; the particle state is then undefined (the caller keeps its last good
 * time folder). */
lub_step_status lub_mps_step(lub_mps *m, double dt, long *bad, char *msg, size_t msgsize);

/* The checks at the end of lub_mps_step (mps/walls.c, shared by the fluid's formulations), on
 * the current state: the first particle with a
 * non-finite value (LUB_STEP_NONFINITE) or outside the domain box in a non-periodic direction
 * (LUB_STEP_ESCAPED), then the first fluid particle that went through a wall in the step of
 * length dt that brought the particles here, their positions before it being r - u dt
 * (LUB_STEP_ESCAPED, naming the wall's patch; the criterion is described in walls.c).  *bad
 * and msg as for lub_mps_step.  Uses the neighbour lists of the step: a caller that places
 * particles itself builds them first (lub_neighbours_build(&m->nb, P->n, P->x)). */
lub_step_status lub_mps_check(lub_mps *m, double dt, long *bad, char *msg, size_t msgsize);

/* The wall of patch `patch` around fluid particle i, as the least-squares line (plane in 3-D)
 * through the patch's wall particles within re of i (mps/walls.c): cw, their centroid
 * relative to i, and n, the unit normal into the fluid (from the centroid of the patch's
 * dummy neighbours towards the wall layer).  Returns 0 (cw, n unset) when i has fewer than
 * two wall or no dummy neighbours of the patch.  Used by the check of a particle through a
 * wall and by the dummy particles' extrapolated velocity (dummyVelocity: extrapolate). */
int lub_mps_wall_plane(const lub_mps *m, size_t i, unsigned patch, double cw[3], double n[3]);

/* The dummy particles' velocity in the viscous term (system/schemes.yaml dummyVelocity; the
 * derivation is at step.c, dummy_velocity).  The pair term of fluid particle i and dummy
 * neighbour j is w_ij (u_g - u_i) = w_ij (f (U_j - u_i) + a) with the ghost velocity u_g:
 * lub_mps_ghost returns f and sets a (3 components); with dummyVelocity flux also for a wall
 * neighbour j (f = 1, a = the wall's slip of methods.md (2.8b)).  planes: the walls around i
 * (lub_mps_ghost_planes, once per i); kappa: the no-slip profile's curvature at the wall,
 * (G/rho - g)/nu with G the pressure gradient (NULL: none). */
#define LUB_GHOST_PLANES 4
typedef struct {
    int n;                            /* patches among i's dummy neighbours (at most 4) */
    unsigned patch[LUB_GHOST_PLANES]; /* their indices */
    int ok[LUB_GHOST_PLANES];         /* lub_mps_wall_plane found the wall */
    double c[LUB_GHOST_PLANES][3];    /* the wall layer's centroid relative to i */
    double nrm[LUB_GHOST_PLANES][3];  /* its normal into the fluid */
} lub_mps_ghost_planes;
void lub_mps_ghost_planes_of(const lub_mps *m, size_t i, lub_mps_ghost_planes *g);
double lub_mps_ghost(const lub_mps *m, size_t i, size_t j, const lub_mps_ghost_planes *g,
                     const double kappa[3], double a[3]);

/* Given particles (lub_mps.fixed: a multi-resolution level's fixed band, whose velocity is
 * interpolated from another level) are not computed and may drift into a curved wall with
 * that velocity; lub_mps_check does not stop the run for them.  flag[i] = 1 (P->n entries)
 * for each given fluid particle that is now more than the check's depth behind its wall
 * layer (the criterion of lub_mps_check, whatever its position before the step); returns
 * their count.  The caller removes them (models/multiResolution/opt.c). */
size_t lub_mps_buried(const lub_mps *m, double dt, uint8_t *flag);

/* Sort every per-particle array (the particles' fields and extra fields, fixed, inside) into
 * the order of system/schemes.yaml particleOrder (cells or lattice rows); the neighbour lists
 * must be built afresh after it.  The MPS step does it every reorderInterval steps; a
 * formulation's step may too (models/fluid.h), whose own arrays are formed anew each step. */
void lub_mps_reorder(lub_mps *m);

/* The per-particle forces of the models (hooks.particle_forces, if any): us[d][i] += dt
 * acc[d][i] for the fluid particles that are not given (lub_mps.fixed); the lists must be
 * those of the current positions.  Shared by the formulations (models/fluid.h). */
void lub_mps_particle_forces(lub_mps *m, double dt, double *const us[3]);

/* Build the neighbour lists afresh at the next step.  The solver calls it after writing a
 * time folder, so that a run restarted from that folder (whose lists are built afresh)
 * repeats the uninterrupted run exactly: lists kept with a skin hold the same pairs but sum
 * them in another order, and the iterative pressure solve would then stop at other iterates. */
static inline void lub_mps_rebuild_lists(lub_mps *m)
{
    m->built = 0;
}

/* Build the neighbour lists afresh now, at the current positions (a model that moved the
 * particles within the step and needs every pair: the collision model); timed as the
 * neighbour search. */
void lub_mps_relist(lub_mps *m);

/* Largest speed of all particles (fluid and moving walls). */
double lub_mps_max_speed(const lub_mps *m);

#endif
