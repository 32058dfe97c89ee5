/* lubkit MPS: the elasticWall model in the particle solver (methods.md 4; thesis 4-2, 4-3).
 *
 * The dictionary entry, the influence coefficients, the ramp and the load-balance step are
 * src/models/elastic.h; this is what the solver does with them each step.
 *
 * Wall update.  The wall particles of the patch (kind wall) are sorted by x into slots
 * k = 0..nw-1 (ties by id).  Before every step (lub_mps_elastic_before, from time t):
 *
 *     L     = sum_k pbar_k w_k                            (integral of the mean wall pressure)
 *     h0   += dh0 = alpha h0^0 clamp((L / W_bar - 1) / clamp, -1, 1)     (T-51, T-52, T-53)
 *     v_k   = sum_j C(x_k - x_j, w_j) pbar_j                                   (T-46..T-49)
 *     y_k   = y_f + h0 + s_k + v_k                                                   (T-50)
 *
 * W_bar: the load W(t) of T-53 in the running mean of the pressure (see Load balance).
 * w_k: the segment widths of the sorted x (lub_elastic_segment_widths), so that sum p w is
 * the integral of p dx, the vertical load (w_k = l0 cos(theta_k) on the arc).  y_f: the
 * surface beneath the cylinder's lowest point (lub_elastic_floor), so that y_f + h0 is the
 * lowest point of the undeformed cylinder and h0 at the start is the clearance.  s_k: the
 * undeformed shape, the height of the particle above the cylinder's lowest point where
 * particleGen put it: the circle, of which T-50's (x - x_c)^2/(2R) is the parabolic
 * approximation (they differ by (x - x_c)^4/(8R^3): 0.05 um at 0.8 mm from the contact
 * for R = 0.01 m, 0.1% of the gap; reynoldsRef uses the parabola).  Keeping the particles'
 * own shape means no jump at the start: the parabola lies up to 28 um below the arc of the
 * tutorial at x = 3.8 mm and 40 um below the 1 mm cylinder of the test at x = 0.7 mm.
 * Each dummy particle of the patch keeps its height above the wall: y_d = y_f + h0 + s_d +
 * v(x_d), v(x_d) interpolated linearly between the two wall slots around x_d, so the wall
 * keeps its layers.  The patch moves only vertically, never in x.
 *
 * Motion.  The particles are not moved here: their velocity is set to (0, (y_target - y)/dt)
 * and the step moves every wall and dummy particle with its velocity (mps.h step 3), so the
 * wall arrives at y_target at the end of the step and the viscous step sees the wall's true
 * velocity dy/dt (the no-slip ghost velocity of the dummies, 2 U - u_i, uses it).  The patch
 * is marked in lub_mps_config.patch_moved so that the step does not overwrite these
 * velocities with the movingWalls velocity.
 *
 * Averaging.  After every step (lub_mps_elastic_after) the wall pressure p_k of the step
 * enters a running mean with a fixed window, an exponential mean stored per particle (the
 * particle field pWallMean):
 *
 *     pbar_k += a (p_k - pbar_k),   a = 2 / (N + 1),   N = averageSteps,
 *
 * starting from pbar = 0.  This weight gives the samples the same mean age, (N - 1)/2 steps,
 * as the thesis' mean over the last N steps (a box window): both follow a pressure rising
 * linearly in time with the same lag, and both reduce uncorrelated noise by about the same
 * factor (variance ratio a/(2 - a) = 1/N against 1/N).  A box window would need N pressures
 * per wall particle in every restart file (3,000 x 1,000 doubles in the thesis case); the
 * exponential mean needs one.  There is deliberately no start-up correction (dividing by
 * 1 - (1 - a)^n, or the plain mean of the first samples): that would let the first, noisy
 * samples deform the wall by their full amount within a step, a wall velocity of microns per
 * time step; from pbar = 0 the deformation grows in over about N steps, together with the
 * load ramp (rampTime should be at least N steps).
 *
 * Load balance: T-51 with two choices, and how fast it must be.  With the reference term
 * ln(l/b) of T-46 the displacement has a uniform part, (4 L / (pi E)) ln(b / l) + ..., that
 * lifts the loaded part of the wall with the mean load at once (77 um at the contact centre
 * in the thesis case): a spring, which is what keeps the coupled wall stable (the mean
 * pressure rises, the wall lifts, the pressure falls).  The rigid-body position h0 must
 * compensate it: the equilibrium h0 is reynoldsRef's `position` line, -45.4 um in the thesis
 * case, while the wall starts undeformed (v = 0) at its clearance h0^0 = 4.5 um; h0 cannot
 * start at -45 um (the undeformed wall would lie below the plane, which
 * lub_mps_elastic_init refuses).  So h0 must travel |h0_eq - h0^0| (50 um there) while the
 * load ramps up, at most alpha h0^0 per step: the thesis' alpha = 5e-6 allows 2.25e-11 m
 * per step, 1.1 um in 5 ms.
 *   1. The relaxation is the user's (elasticWall relaxation), to be chosen for the travel:
 *      alpha >= |h0_eq - h0^0| / (h0^0 n_ramp), n_ramp the steps of the ramp.  The reduced
 *      case (tutorials/softEHL/cylinderFlatReduced, tests/cases/softEHL) uses that minimum,
 *      5e-3 for 50 um in 400 steps, and its mean load is within 1.1% of W two averageSteps
 *      after the ramp (with 3e-3, 5% later); the thesis tutorial uses 1e-3 (5.6e-4 needed).
 *   2. beta = L / W_bar - 1, W_bar the load W(t) averaged like the pressure (the same
 *      exponential mean, kept in the state), where T-51 takes W(t): the mean pressure lags
 *      the pressure by (N - 1)/2 steps, so during a ramp a film carrying exactly W(t) would
 *      show beta = -1 at the start and -(N - 1) / (2 k) after k >> N steps, below -clamp
 *      for about the first 2.5 N steps (2,500 in the thesis case), and the balance would
 *      drive the wall down at full speed while the film forms.  After the ramp W_bar tends
 *      to W within a few N steps.
 * Moving the contact centre h0 + v(x_c) instead of h0 (which removes the uniform part from
 * what the balance must travel) was tried and rejected: without the spring the flanks of
 * the loaded wall sink towards the plane as the mean pressure grows, squeeze the film and
 * raise the pressure further, and the run diverged within 120 steps in the case where T-51
 * settles in 800.
 *
 * Restart.  uniform/state.yaml holds `elasticWall: { h0, samples, loadTargetMean }`
 * (%.17g), and the particle fields pWallMean (the mean) and elasticShape (s: the undeformed
 * shape) travel with the particles in particles.h5; x_k, w_k, the influence coefficients
 * and the interpolation of the dummies are rebuilt from the (never changing) x of the
 * particles in the same order, so a restarted run repeats the uninterrupted one exactly.
 *
 * Start.  Without elasticShape in the particles (a particleGen file) the wall starts
 * undeformed at y_f + h0^0 + s, h0^0 the elasticWall h0 (default the clearance: then nothing
 * moves).
 *
 * Crossing.  The step is refused (LUB_STEP_ESCAPED, the solver writes the state and exits
 * 2) when a wall particle would come closer than l0/2 (l0 of its level) to the surface
 * beneath it.
 *
 * Multi-resolution (thesis 4-3, T-60..T-67; lub_mps_elastic_init_levels with the levels'
 * solvers of models/multiResolution/opt.h).  Every level has its own wall and dummy particles of
 * the patch in its extended region, the overlaps included, and keeps its own slots, dummy
 * interpolation (between its own wall slots) and running means.  What couples them:
 *   - the pressure segments, the sources of T-46, count each point of x once: they are the
 *     wall particles of the level that owns their x (lub_levels_locate's owner: the fine
 *     level inside [a1, a2], the coarse one outside), sorted by x, with the half-way widths
 *     of lub_elastic_segment_widths over them: each level's own spacing inside its part
 *     (l_oj of T-62, T-64; l0 cos theta on the arc), an intermediate width for the two
 *     segments where the levels meet, so that the segments tile x.  Each coefficient is
 *     T-46 with the segment's own width (models/elastic.h: a coarse segment equals the fine
 *     segments it covers).  T-62 as printed sums over all N = N_fine + N_coarse wall
 *     particles, which would count the overlaps, where both levels have walls, twice;
 *   - the displacement is evaluated at every wall particle of every level, the overlaps
 *     included, from those segments: both levels' walls take one shape, to the linear
 *     interpolation between their particles (tests/cases/softEHLOPT: a fine wall particle
 *     of an overlap lies within 0.02 l0_fine of the coarse wall, within the derived bound);
 *   - the load L of T-51 is the same owned sum (T-66, T-67: the integral over the fine region
 *     plus that over the coarse region), so one h0 moves the wall of every level;
 *   - each level's wall particles average their own pressure (pWallMean) after each step;
 *     the means of those that do not own their x (in the overlaps) are kept, not used.
 * Every level takes the same steps (commonDeltaT, T-60; lub_mps_config_read refuses
 * sub-stepping with the elastic wall, file:line): the wall is deformed and moved before each
 * step of all levels from one displacement, as in the thesis, which chose one dt so that the
 * deformation would not lose accuracy.  The multi-resolution driver keeps walls still
 * (mps.h still_walls) except the patches a model moves (patch_moved), whose particles move
 * with the velocity given here, vertically, keeping their x: each level's part of the wall
 * stays in the level's part of x.  As the wall moves away from where the geometry puts it,
 * the driver's generation cells leave the wall out and skip the cells behind it
 * (lub_opt_moving_wall, which lubFoam calls after the set-up).  Exact restart: the file is
 * split into the levels in the same order, and the slots, segments and coefficients are
 * rebuilt from the particles' x.  The header line of lubFoam lists each level's wall and
 * dummy particles and pressure segments.
 *
 * Cost: one evaluation of the influence coefficients (dense: nw^2 multiply-adds; multi-
 * resolution: all wall particles times the owned ones) and O(nw + nd) work per step; the
 * particle-index map of the slots is rebuilt (O(N + n log n)) only when the solver has
 * reordered (or, multi-resolution, compacted) the particles.  No allocation after
 * lub_mps_elastic_init.
 */
#ifndef LUB_MODELS_ELASTICWALL_H
#define LUB_MODELS_ELASTICWALL_H

#include <stdint.h>
#include <stdio.h>

#include "geometry/geometry.h"
#include "io/dict.h"
#include "models/elastic.h"
#include "models/multiResolution/levels.h"
#include "mps/mps.h"

/* The patch's particles on one resolution level (single resolution: the only one). */
typedef struct {
    lub_mps *m; /* the level's solver; the particles are m->P */
    double l0;
    int nw, nd;           /* wall slots k < nw sorted by x (ties by id), dummies q < nd */
    int t0;               /* the wall slots are the kernel's targets t0 .. t0 + nw - 1 */
    double *xw, *floor;   /* x and the surface beneath, per wall slot */
    uint64_t *ids;        /* ids of the patch particles (walls by slot, then dummies) */
    size_t *idx;          /* their particle index (idx[k], idx[nw + q]) */
    uint64_t *sorted_id;  /* ids sorted, with ... */
    int *sorted_slot;     /* ... the slot of each */
    int *da;              /* dummy q: wall slots da[q], da[q] + 1 ... */
    double *df;           /* ... with weight 1 - df[q], df[q] */
    double *mean, *shape; /* the particle fields pWallMean, elasticShape */
} lub_mps_elastic_level;

typedef struct {
    lub_dict *dict;          /* constant/models.yaml (owns e's nodes) */
    lub_dict *state_dict;    /* set-up only: uniform/state.yaml being read */
    void *tmp_pts, *tmp_ids; /* set-up only: sort buffers */
    lub_elastic_wall e;      /* the entry (h0^0 = e.h0; e.patch_name is patch_name) */
    char patch_name[LUB_NAME_MAX];
    int patch;      /* patch index in the particles (the same on every level) */
    double l0;      /* of the finest level */
    double y_floor; /* y_f: surface beneath the lowest point */

    /* state */
    double h0;          /* rigid-body position of T-50 */
    long samples;       /* pressure samples in the running mean */
    double target_mean; /* the load W(t) in the same running mean */

    /* the patch on each level */
    int nlevels;
    lub_mps_elastic_level lv[LUB_MAX_LEVELS];
    int nw, nd; /* wall and dummy particles of all levels */

    /* the pressure segments (T-46, T-62): the wall slots whose x their level owns, each
     * point of x on one level, sorted by x; the kernel's sources */
    int ns;
    int *src_level, *src_slot; /* level and wall slot of segment s */
    double *xs, *ws;           /* its x and width */
    double *pw;                /* the mean pressure gathered by segment */
    double *xt, *v;            /* the kernel's targets (every wall slot of every level, level by
                                  level) and their displacement */
    int lc, kc; /* x_c between wall slots kc, kc + 1 of level lc (which owns x_c) ... */
    double fc;  /* ... with weight fc */
    lub_elastic_kernel *K;
    double weight; /* 2 / (N + 1) */

    /* figures of the last step */
    double load;         /* integral of the mean wall pressure [N/m] */
    double load_instant; /* integral of the wall pressure of the last step */
    double load_target;  /* W(t) */
    double vmin, vmax;   /* displacement range over the wall slots */
    double centre;       /* h0 + v(x_c): the contact centre above y_f */
    double gap_min;      /* smallest distance of a wall particle to the surface beneath */
    /* fluid particles inside the cylinder: more than l0/4 above its wall layer (linear
     * between the wall slots, within their x span), now and at most over the run; the first
     * one seen (inside_x, inside_id).  The oil gets there round an open end of the arc (a
     * periodic seam where its ends do not meet, as the elastic displacement is not periodic;
     * the end of its range), which the through-wall check of mps/walls.c does not see */
    long inside, inside_max;
    double inside_t, inside_x[2];
    uint64_t inside_id;
} lub_mps_elastic;

/* Read the elasticWall entry of models_path (constant/models.yaml) against the geometry g
 * (system/particleGenDict.yaml) and set the model up for the solver m (after lub_mps_init).
 * Returns 0 (w zeroed) when models.yaml has no elasticWall.  state_path is the start time's
 * uniform/state.yaml (may be NULL or missing: a fresh start).  end_time > 0: the run's
 * endTime, against which rampTime is checked (end_what names it in the message).  Fatal
 * (exit 1, file:line) on bad input: the patch is not a 2-D cylinder, has no wall particles
 * in the particles or reaches above the cylinder's centre, moves (movingWalls), the ramp is
 * longer than the run, the particles hold the model's fields but the state has no
 * elasticWall entry (or the reverse), or the start position puts the wall within l0/2 of the
 * surface beneath.  The solver m is kept (not owned) for the steps. */
int lub_mps_elastic_init(lub_mps_elastic *w, lub_mps *m, const lub_geometry *g,
                         const char *models_path, const char *state_path, double end_time,
                         const char *end_what);

/* The same for a multi-resolution run: the solvers m[0 .. nlevels) of the levels L
 * (models/multiResolution/opt.h o->m, o->L), every level with its own wall and dummy particles of
 * the patch (see Multi-resolution above).  With nlevels 1 and L NULL it is lub_mps_elastic_init.
 * Fatal, as that, also when a level has dummy particles of the patch but no wall particles. */
int lub_mps_elastic_init_levels(lub_mps_elastic *w, lub_mps *const *m, int nlevels,
                                const lub_levels *L, const lub_geometry *g, const char *models_path,
                                const char *state_path, double end_time, const char *end_what);
void lub_mps_elastic_free(lub_mps_elastic *w);

/* Before the step from t to t + dt (every level's): load balance, displacement, target
 * positions and the wall velocities.  LUB_STEP_ESCAPED with a message (and the state
 * unchanged) when the wall would come within l0/2 (of its level) of the surface beneath. */
lub_step_status lub_mps_elastic_before(lub_mps_elastic *w, double t, double dt, char *msg,
                                       size_t msgsize);

/* After the step (the time is now t): the wall pressure of each level enters the running mean
 * of its particles; the figures (load, load_target = W(t), ...) are updated. */
void lub_mps_elastic_after(lub_mps_elastic *w, double t);

/* load / load_target - 1: the error of the mean load against W(t) (0 when W is 0). */
double lub_mps_elastic_beta(const lub_mps_elastic *w);
/* beta of T-51 as the balance sees it: load / target_mean - 1 (0 when that is 0). */
double lub_mps_elastic_balance_beta(const lub_mps_elastic *w);

/* The elasticWall entry of uniform/state.yaml (an exact restart needs it). */
void lub_mps_elastic_write_state(const lub_mps_elastic *w, FILE *fp);

/* Low-level pieces (unit tests). */

/* The weight a of the exponential mean for averageSteps N (see above). */
double lub_mps_elastic_mean_weight(long average_steps);

#endif
