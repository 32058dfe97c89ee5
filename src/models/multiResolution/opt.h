/* lubkit MPS: the overlapping particle technique (OPT, multi-resolution; methods.md §3,
 * thesis §2-2, Shibata's OPT).
 *
 * Each resolution level is its own MPS system (mps.h: one lub_mps per level, with its own
 * l0, re = effectiveRadius l0, n0, lambda0, neighbour lists, viscosity and pressure solves);
 * the levels never interact pairwise.  They are coupled in the overlaps
 * (models/multiResolution/levels.h for the regions): in the fixed band at the far edge of each
 * level's overlap (T-25, T-26) the level's particles are not computed, their velocity and pressure
 * are given, interpolated by weighted least squares (mps/lsq.h) from the other level's particles,
 * and each level's free particles see them as boundary values.  Any number of levels from 2 up
 * (LUB_MAX_LEVELS): level k is coupled with its neighbours k - 1 and k + 1 only, at the boundaries
 * between them, so a middle level has fixed bands at both ends of each piece of its ring (given by
 * the finer level at its hole, by the coarser level at its outer edges):
 *
 *     viscosity (T-31):  the band's velocities are Dirichlet values of the implicit solve
 *                        (§2-2-2 (3): velocities fixed outside L_outer);
 *     pressure (T-9):    the band's pressures are Dirichlet values, like those of the free
 *                        surface but not zero;
 *     correction (T-16, T-17): a band particle keeps its given velocity and moves with it.
 *
 * The band is 4 l0 wide, wider than re = 3.1 l0, so that a free particle's neighbourhood is
 * complete: the level's particles end at the outer edge of the band, and the truncated
 * neighbourhoods there (PND deficit, one-sided) fall on Dirichlet particles only.  The
 * sources of an interpolation are the other level's fluid and wall particles that are not in
 * a band themselves (the two bands of an overlap never meet: models/multiResolution/levels.c checks
 * it), so every level is interpolated from the same state, that of the start of the step.  Dummy
 * particles are not sources: they carry the wall velocity behind the wall, not the no-slip
 * profile continued through it (step.c, dummy_velocity).  Particles move between the levels
 * by deletion past a level's extended region and generation in one-cell layers at its edges
 * (lub_opt_transfer, after every step).
 *
 * The fit is second order (LSQ, lsq.h) so that the parabola of a Poiseuille film is carried
 * exactly; where the neighbours cannot fix it (near a wall on a coarse level) it falls back to
 * first order or to the weighted mean, and the fallbacks are counted (lub_opt_stats).
 *
 * Free surface in the overlaps.  The band particles are not pushed apart by the pressure, so
 * next to a band a level's particles come to stand irregularly, and a computed particle there
 * can see a hole on one side: its PND falls below beta n0 with a one-sided neighbourhood, the
 * free-surface test of T-12 (step.c) flags it, it gets P = 0 among neighbours at the film's
 * pressure, and the pressure gradient throws it out of the film (the thesis OPT wedge: a
 * coarse particle next to the band at a1, 25 m/s after 6.3 ms).  The other level is computed
 * freely there and knows whether the place is full of fluid: a computed particle in an
 * overlap is marked inside (lub_mps.inside) when the other level's particles' PND at its
 * position, with that level's re, is at least beta n0 of that level, and an inside particle is
 * not a surface particle.  At a real free surface (a layer's top, a film's rupture crossing
 * the overlap) the other level's PND is deficient as well, and the test is the usual one.
 * (The thesis uses the virtual-light test, which by itself sees such an interior hole as
 * shadowed.)
 *
 * Given particles and curved walls.  A band particle moves with its interpolated velocity,
 * without the pressure that keeps computed particles off the walls; where the wall is curved
 * (the cylinder at a1) the other level's coarser velocity field can carry it into the wall.
 * Such a particle is deleted after the step (lub_mps_buried; counted in stats.nburied), not
 * reported as a wall crossing: it is outside the part of x its level owns, so the mass is
 * unchanged, and the generation layer or the band's inflow replaces it.
 *
 * Walls.  A level's walls must stay in the part of x the level covers, so in a multi-
 * resolution run the wall and dummy particles keep their positions (mps.h still_walls) and
 * only carry their patch velocity: every wall must be at rest or a plane sliding along itself
 * (movingWalls), which is translation invariant.  Other moving walls are refused at set-up.
 * The exception is a wall that a model moves while keeping its particles' x (mps.h
 * patch_moved): the elastic wall (models/elasticWall/elasticWall.h, Multi-resolution), whose
 * particles on every level move vertically with the one displacement computed from the wall
 * pressure of the levels owning each x (T-62..T-67), before each step of every level (commonDeltaT:
 * the configuration refuses sub-stepping with it).  Its band particles (T-25, T-26) take
 * the other level's pressure like any wall particle's; lub_opt_moving_wall takes the
 * generation cells again without it and skips the cells behind it, since the wall leaves the
 * place where the geometry puts it.
 *
 * Particles.  particleGen generates each level only in the part of x it owns; at set-up each
 * level's overlap margins are filled from the geometry (lub_geometry_discretise_range) when
 * they hold none of the level's particles (a start from particleGen's file; a restart finds
 * them filled).  The levels are split into one lub_particles each, with every field, id and
 * extra field, and merged back (lub_opt_merge) for the time folders, level 0 first, each
 * level in its memory order: a restart splits the file into the same arrays, so it repeats
 * the uninterrupted run exactly.
 *
 * Time steps.  Every level takes the same dt (commonDeltaT, T-60), or level k + 1 takes
 * dt_{k+1} = Nr_k dt_k (T-19) while level k takes Nr_k sub-steps, recursively down to level
 * 0 (lub_opt_step): one step of the coarsest level is the product of the Nr finest steps.
 *
 * Mass correction (T-27..T-29, T-61; massCorrection in multiResolution).  After each step
 * (each step of the coarsest level when sub-stepping) the mass M of T-27 is counted; when
 * |M - M^0| > threshold M^0 the coarser level's fluid particles in each overlap (outside its
 * fixed band, which is given anyway) move with the x-velocity correction
 *
 *     du = -s B sgn(M - M^0),   B = max(min(|M - M^0| / (rho A C_relax dt), cMax), cMin),
 *
 * s = +1 at a boundary where the fine level owns the x below it (a2), -1 where it owns the x
 * above it (a1); A is the summed cross-section of the overlaps' fluid (the fine level's fluid
 * particles in each overlap times l0_fine^d over the overlap's length: the film thickness in
 * 2-D, per unit depth) and dt the coarsest level's step.  With more than two levels each
 * boundary between levels k and k + 1 corrects level k + 1's fluid in its own overlap with
 * its own s (a middle level is the coarser level of its inner boundaries only).  Why one
 * level and this sign: the
 * levels conserve their own particles except at the far edges of their extended regions
 * (deletion, generation), which lie away from the boundary a where the ownership of T-27
 * changes, so M changes only by the two levels' fluxes through a,
 *
 *     dM/dt = rho s (F_coarse(a) - F_fine(a))      (F: volume flux in +x through a),
 *
 * and a correction given to the particles of both levels alike moves both fluxes equally and
 * leaves M unchanged.  Moving the coarser level's particles alone changes M by
 * -rho B A sgn(M - M^0) dt per step: with B unlimited the error falls by the factor
 * 1 - 1/C_relax per step (T-28's relaxation), and at most at the rate rho cMax A.  The thesis
 * (T-27) gives "the particles in the overlap region" and the sign sgn(M^k - M^0) without the
 * direction; the coarser level is also the one whose accuracy matters less (the fine level's
 * solution near a boundary is left alone).  The correction is a correction of the particles'
 * motion, not of their momentum: at the end of the step they are displaced by du dt, the
 * distance du adds over the step, and their velocity is left as the step computed it.  Added
 * to the stored velocity instead, it would be added again at every step while the error
 * lasts (a body force B / dt, whose effect on M is set by the viscous drag, not by T-28)
 * and be diffused through the film by the implicit viscosity step (nu dt / l0^2 is about 1
 * on the thesis' coarse level); as a displacement, M moves back by rho B A dt per
 * step.  M^0 is the mass at the start of the run (lubFoam keeps it in
 * uniform/state.yaml); lub_opt_stats reports M, B and the particles corrected.
 *
 * Ids.  Generated particles take ids from next_id on (set-up: one past the largest id of the
 * particles; lubFoam keeps it in uniform/state.yaml, so that a restart continues it).
 *
 * Mass (T-27): M = rho sum over the fluid particles of l0_level^d f (per unit depth in 2-D),
 * f the part of the particle's cell that lies where its level owns x
 * (lub_levels_owned_fraction): each point of space counted on one level.
 */
#ifndef LUB_MODELS_OPT_H
#define LUB_MODELS_OPT_H

#include <stddef.h>
#include <stdint.h>

#include "geometry/geometry.h"
#include "models/multiResolution/levels.h"
#include "mps/lsq.h"
#include "mps/mps.h"

/* The fluid mass per level (T-27). */
typedef struct {
    size_t fluid[LUB_MAX_LEVELS]; /* fluid particles of each level */
    size_t owned[LUB_MAX_LEVELS]; /* of them, those whose x their level owns */
    double mass; /* rho sum l0_k^d f over the fluid particles (f: owned fraction of the cell)
                    [kg, or kg/m in 2-D] */
} lub_opt_mass;

/* What the coupling did in the last step. */
typedef struct {
    size_t nfixed[LUB_MAX_LEVELS];     /* particles given by interpolation (fluid and wall) */
    size_t nlower;                     /* fits below second order (fallback to order 1 or 0) */
    size_t nempty;                     /* given particles without any source within re: they
                                          kept their previous values */
    size_t ndeleted[LUB_MAX_LEVELS];   /* fluid particles deleted past the extended region */
    size_t ngenerated[LUB_MAX_LEVELS]; /* fluid particles generated in the generation layers */
    size_t nfull;                      /* generations skipped: the level's capacity is full */
    size_t nburied[LUB_MAX_LEVELS];    /* given fluid particles deleted behind a wall */
    size_t ninside[LUB_MAX_LEVELS];    /* computed particles in an overlap inside the other
                                          level's fluid (no free surface there) */
    long piter, viter; /* pressure and viscosity iterations of all the level steps taken */
    double mass;       /* M (T-27) after the step [kg, or kg/m in 2-D] */
    double correction; /* the mass correction's B sgn(M - M^0) of the step [m/s], 0 if none */
    double area;       /* A of T-28: the overlaps' fluid cross-section [m^(d-1)] */
    size_t ncorrected; /* particles given the correction */
} lub_opt_stats;

/* A level's state K (sub-stepping): positions, velocities, pressures, kinds and given flags
 * at the start of its step, binned. */
typedef struct {
    lub_particles P;
    uint8_t *fixed;
    lub_neighbours cells;
} lub_opt_saved;

typedef struct {
    lub_levels L;
    int nlevels, dim;
    lub_particles P[LUB_MAX_LEVELS];     /* the particles of each level (nlevels = 1 each) */
    lub_mps m[LUB_MAX_LEVELS];           /* and its solver */
    lub_neighbours src[LUB_MAX_LEVELS];  /* cell list of each level's particles (cell >= re of
                                            the level): the sources of the interpolation */
    lub_lsq_options lsq[LUB_MAX_LEVELS]; /* fit from level k's particles */
    int nthreads;
    size_t cap_cand; /* candidate buffer per thread */
    size_t *cand;
    uint64_t next_id;              /* id of the next particle created */
    size_t filled[LUB_MAX_LEVELS]; /* particles added to each level's margins at set-up */
    lub_opt_stats st;
    size_t total_generated[LUB_MAX_LEVELS], total_deleted[LUB_MAX_LEVELS], total_full;
    size_t total_buried[LUB_MAX_LEVELS];
    uint8_t *drop[LUB_MAX_LEVELS]; /* scratch: particles to delete (capacity of the level) */

    /* particle transfer: the generation cells of each level, one lattice point each (the
     * cell's centre) in the level's generation layers where the geometry allows fluid */
    size_t ngen[LUB_MAX_LEVELS];
    double *gen[LUB_MAX_LEVELS];     /* positions, 3 per cell */
    uint8_t *gen_ok[LUB_MAX_LEVELS]; /* decision of the last pass */
    double fill[LUB_MAX_LEVELS];     /* fill fraction of the level's fluid at its surface */

    /* sub-stepping (T-19..T-22): nr steps of the finest level per step of the coarsest (the
     * product of the Nr; 1 with commonDeltaT); the state K of every coarser level k >= 1 at
     * the start of its current step is kept for the finer level's values between K and K + 1
     * (allocated at set-up when nr > 1) */
    int nr;
    lub_opt_saved K[LUB_MAX_LEVELS];
    double *gen_val[LUB_MAX_LEVELS]; /* u (3), p, grad p (3) per cell */

    double rho;   /* density (the mass of T-27) */
    double mass0; /* M^0 of the mass correction (set-up: the mass of the particles given) */
    uint8_t moved[LUB_MAX_PATCHES]; /* walls a model moves (lub_opt_moving_wall) */
} lub_opt;

/* Set up from the particles P of all levels (not modified; its arrays are copied), the levels
 * L (models/multiResolution/levels.h, checked against P), the solver configuration c (the same for
 * every level; lub_mps_init per level) and the geometry g (domain, walls; used for the margins, the
 * generation cells and the walls' check, not kept).  headroom: extra capacity per level, as a
 * fraction of its count (for particles generated later).  Fatal (exit 1) for a moving wall
 * that is not a plane sliding along itself, a patch moved by a model, or an extended region
 * across the periodic seam. */
void lub_opt_init(lub_opt *o, const lub_levels *L, const lub_particles *P, const lub_mps_config *c,
                  const lub_geometry *g, double headroom);
void lub_opt_free(lub_opt *o);

/* The wall `patch` (index in the particles) is moved by a model (elasticWall, after
 * lub_opt_init; mps.h patch_moved): its particles leave the place where the geometry g puts
 * the wall, so the generation cells are taken again without it (the lattice points of the
 * generation layers where the other walls allow fluid, also those the wall covered at the
 * start), and a cell whose nearest wall or dummy particle of the level is a dummy of that
 * wall lies behind it and is skipped (lub_opt_transfer). */
void lub_opt_moving_wall(lub_opt *o, const lub_geometry *g, int patch);

/* One step of length dt on every level: flags the fixed bands, interpolates their velocity
 * and pressure from the neighbouring levels, then lub_mps_step on each level, then the
 * particle transfer (lub_opt_transfer).  With sub-stepping (nr > 1) dt is the coarsest
 * level's step, and each level k from the coarsest down takes one step of its dt_k as
 * follows (the thesis' Fig. 3 order, recursively):
 *   - its bands are interpolated: at its boundaries with the coarser level k + 1 from k + 1's
 *     state K (saved at the start of k + 1's current step) and its state K + 1 (now), in
 *     time with the weights of lub_levels_time_weight (T-20..T-22 corrected: (Nr_k - b)/Nr_k
 *     for K at k's sub-step b); at its boundaries with the finer level k - 1 from k - 1 as it
 *     is, at the start of k's step;
 *   - its state K is saved (k >= 1), it takes its step, then level k - 1 takes its Nr_{k-1}
 *     sub-steps of dt_k / Nr_{k-1} in the same way;
 *   - its transfer follows, at the end of its step: from k + 1 at the weight of b + 1, from
 *     k - 1 as its sub-steps left it (at the same time).
 * For two levels: the coarse level's step (its band from the fine level at K), the fine
 * level's Nr sub-steps, the coarse level's transfer from the fine level at K + 1.  Last, the
 * mass count and correction (T-27..T-29, above) with the coarsest dt.  On failure *level is
 * the level, *bad the particle index in it and msg names the level; as lub_mps_step. */
lub_step_status lub_opt_step(lub_opt *o, double dt, int *level, long *bad, char *msg,
                             size_t msgsize);

/* The interpolation of the fixed bands alone (the first half of lub_opt_step): after it each
 * level's fixed particles carry their given values. */
void lub_opt_couple(lub_opt *o);

/* The particle transfer after a step of length dt (the last part of lub_opt_step):
 *   deletion:   a level's fluid particles outside its extended region (past the far edge of
 *               an overlap, or into its hole) are deleted;
 *   generation: in each generation cell (one l0 wide at the far edge of an overlap, thesis
 *               §2-2-1, Fig. 2) a fluid particle is created at the cell's centre when the
 *               other level's fluid fills the cell and this level's particles have left it.
 * "Fills": the fraction of the part of B's neighbourhood of the cell centre c that is not
 * wall which B's fluid occupies, n_B,fluid(c) / (n0_B - n_B,wall+dummy(c)) (PND sums of T-4),
 * exceeds its value half a spacing above a plane free surface of B's lattice (lub_opt.fill,
 * 0.601 in 2-D at re = 3.1 l0): a cell centre inside the fluid B's particles represent is
 * filled, one above it, at the surface itself, or beside a dry wall is not; beside a wetted
 * wall the fraction exceeds 1.  "Left": the level's nearest particle is at least
 * l0 - |u| dt / 2 from c, u the velocity at c: in a uniform inflow a particle is then created
 * every l0 / |u| on average, at the spacing l0 (the plain test "the cell holds no particle"
 * creates the next particle when the last is half a cell away, at half the spacing).  The
 * new particle's velocity, pressure and pressure gradient (the predictor's running mean
 * gradP*) are interpolated from B by least squares (lsq.h); it starts in the fixed band.
 * Cells inside walls are never candidates: they are the lattice points of the layer where
 * particleGen's rules (lub_geometry_discretise_range over a full-domain box) allow fluid.
 * Particle ids continue from next_id.  Without room in the level's arrays (the capacity is
 * allocated at set-up) a generation is skipped and counted (stats.nfull). */
void lub_opt_transfer(lub_opt *o, double dt);

/* The particles of all levels into P (initialised by the caller with the same dimension;
 * grown if needed, so reserve lub_opt_capacity() before a time loop): level 0 first, each in
 * memory order, with the levels' reference values (l0, re, n0, lambda0), patches and extra
 * fields.  P's time and step are left to the caller. */
void lub_opt_merge(const lub_opt *o, lub_particles *P);
/* Sum of the levels' capacities. */
size_t lub_opt_capacity(const lub_opt *o);

/* Set M^0 of the mass correction (a restart: the value of the run it continues). */
void lub_opt_set_mass0(lub_opt *o, double mass0);

/* Fluid counts and mass (T-27), rho from the solver configuration. */
void lub_opt_mass_count(const lub_opt *o, lub_opt_mass *out);

/* Build every level's neighbour lists afresh at its next step (after writing a time folder:
 * exact restart, as lub_mps_rebuild_lists). */
void lub_opt_rebuild_lists(lub_opt *o);

/* Largest ratio u_max dt_k / l0 over the levels after the last step, dt_k = dt_factor dt
 * (the Courant number of T-18 of each level, for the finest dt = 1), and the level where it
 * is. */
double lub_opt_courant_per_dt(const lub_opt *o, int *level);

#endif
