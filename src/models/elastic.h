/* lubkit elasticWall model: the soft-EHL elastic cylinder (methods.md 4, thesis 4-2, 4-3).
 *
 *     elasticWall: { patch: cylinder, E: 1.966e7, load: 1000, rampTime: 2e-3,
 *                    relaxation: 5e-6, clamp: 0.2, averageSteps: 1000, h0: 4.5e-6 }
 *
 * The wall particles of `patch` (a 2-D cylinder over the film) take the vertical position
 *
 *     y_i = h0 + (x_i - x_c)^2 / (2R) + v_i                                        (T-50)
 *
 * (x_c the x of the cylinder's lowest point, R its radius), with the elastic displacement of a
 * plane-strain half-space under the wall pressure, piecewise constant on segments of width l_j
 * centred on x_j (T-46..T-49; T-62..T-65 with a width per resolution level):
 *
 *     v_i = -(4 / (pi E)) sum_j { a(K_ij) + ln(l_j / b) } p_j l_j,   K_ij = |x_i - x_j| / l_j
 *     a(K) = (K + 1/2)(ln(K + 1/2) - 1) - (K - 1/2)(ln|K - 1/2| - 1)
 *     b    = sqrt(8 W R / (pi E))                       (Hertz half-width, T-49 = T-58)
 *
 * Derivation, and what the constants mean.  The surface displacement of a half-space in plane
 * strain under a line load P per unit length is -(2 (1 - nu^2) / (pi E_Young)) P ln|x| + C
 * (Flamant; Johnson, Contact Mechanics 2.19).  Writing the contact ("equivalent") modulus
 * E' by 2/E' = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 this is -(4 / (pi E')) P ln|x| + C, and
 * integrating over a strip of width l gives exactly
 *     int_{x_j - l/2}^{x_j + l/2} ln|x - s| ds = l (a(K) + ln l),   K = |x - x_j| / l,
 * so l_j (a(K) + ln(l_j / b)) = int ln(|x - s| / b) ds: the 2-D displacement, defined only up
 * to a constant, is measured from the points at distance b from the load (the ln(l/b) term).
 * The constant shifts every v_i by the same amount and is absorbed by h0, which is therefore a
 * position parameter, not the film thickness.  Hence:
 *   - E in T-46 is the equivalent modulus E' of the contact, the one of Hertz's line contact
 *     b = sqrt(8 W R / (pi E')) (Ping Huang's "comprehensive" modulus, thesis ref. [97]); the
 *     thesis calls its E = 1.966e7 Pa "Young's modulus" and uses it in T-46 and T-49 as is,
 *     and so does this model: there is no Poisson ratio key.  For a cylinder of Young's
 *     modulus E_c and Poisson ratio nu on a rigid plane, E = 2 E_c / (1 - nu^2).
 *   - T-62 prints the reference term as ln(l_o / b) with one l_o for every segment.  The
 *     exact strip integral needs ln(l_oj / b), the width of the loaded segment j; this model
 *     uses that, so a coarse segment equals the sum of the fine segments it covers.  (With a
 *     common l_o the difference is sum_j p_j l_oj ln(l_oj / l_o), the same for every i and
 *     absorbed by h0; with l_o = l_o of the displaced particle i it would put a step into v
 *     where the levels meet.)
 *
 * Load balance (T-51, T-52) and ramp (T-53):
 *     beta = (integral of p dx) / W(t) - 1,
 *     dh0  = alpha h0^0 clamp(beta / clamp, -1, 1)   per step,
 *     W(t) = W min(t / rampTime, 1).
 */
#ifndef LUB_MODELS_ELASTIC_H
#define LUB_MODELS_ELASTIC_H

#include <stddef.h>

#include "geometry/geometry.h"
#include "io/dict.h"

/* ---- the elasticWall entry of constant/models.yaml -------------------------------------- */

typedef struct {
    int patch;              /* index of the elastic wall in the geometry */
    const char *patch_name; /* its name (owned by the geometry) */
    double radius;          /* R of T-50 [m] */
    double x_centre;        /* x_c: x of the lowest point of the undeformed cylinder [m] */
    double y_lowest;        /* y of that point [m] */
    double E;               /* equivalent modulus E' of T-46, T-49 [Pa] */
    double load;            /* W, load per unit length [N/m] */
    double ramp_time;       /* T-53 [s]; 0: full load from the start */
    double relaxation;      /* alpha of T-51 */
    double clamp;           /* |beta| at which dh0 saturates (T-51: 0.2) */
    long average_steps;     /* steps in the running mean of the wall pressure */
    double h0;              /* h0^0: initial rigid-body position above the wall below [m] */
    double b;               /* Hertz half-width sqrt(8 W R / (pi E)) (T-49) [m] */
    double p_hertz;         /* Hertz pressure 2 W / (pi b) (T-55) [Pa] */
    const lub_node *node;   /* the elasticWall entry, its patch and rampTime (messages) */
    const lub_node *patch_node, *ramp_node;
} lub_elastic_wall;

/* Read the elasticWall entry of models.yaml (root may be NULL): 0 when there is none, 1 when
 * read into e.  Keys and defaults:
 *     patch         required; a wall of g, a 2-D cylinder with the fluid outside
 *     E             required, > 0 [Pa]     equivalent modulus (see above)
 *     load          required, > 0 [N/m]    W
 *     rampTime      0, >= 0 [s]            T-53
 *     relaxation    5e-6, in (0, 1]        alpha of T-51
 *     clamp         0.2, > 0               |beta| at which dh0 saturates (T-51)
 *     averageSteps  1000, >= 1             running mean of the wall pressure
 *     h0            > 0 [m]; default: the height of the cylinder's lowest point above the
 *                   highest other wall surface beneath it (fatal when there is none)
 * Every error is fatal with file:line:column (exit 1). */
int lub_elastic_wall_read(lub_node *root, const lub_geometry *g, lub_elastic_wall *e);

/* Fatal (at rampTime) when the ramp is longer than the run: rampTime > end_time.  what names
 * the end time in the message (e.g. "endTime 0.005 of system/controlDict.yaml"). */
void lub_elastic_wall_check_ramp(const lub_elastic_wall *e, double end_time, const char *what);

/* The load at time t (T-53). */
double lub_elastic_load_at(const lub_elastic_wall *e, double t);

/* Rigid-body step of the cylinder (T-51, T-52) for the pressure integral `integral` [N/m] and
 * the current load `load`: alpha h0^0 clamp((integral/load - 1) / clamp, -1, 1).  A load <= 0
 * (t = 0 of the ramp) counts as beta = +infinity when integral > 0, else 0. */
double lub_elastic_dh0(const lub_elastic_wall *e, double integral, double load);

/* Hertz line contact: half-width b = sqrt(8 W R / (pi E)) (T-49) and p_H = 2 W / (pi b). */
double lub_elastic_hertz_half_width(double load, double radius, double E);
double lub_elastic_hertz_pressure(double load, double b);

/* The surface beneath the cylinder at x: the highest surface (lub_wall_height, seen from
 * above) of the walls of g other than the elastic patch that lies at or below the undeformed
 * cylinder's lowest point.  Returns 1 and sets *y, or 0 when no such wall spans x.  At x_c
 * this is the surface that the default h0 (the clearance) is measured from. */
int lub_elastic_floor(const lub_geometry *g, const lub_elastic_wall *e, double x, double *y);

/* Widths of the pressure segments of n points sorted by x (x[k] < x[k+1]): each point owns
 * the half-way intervals to its neighbours, w_k = (x[k+1] - x[k-1]) / 2, and an end point
 * the mirror of its inner half, w_0 = x[1] - x[0] (n = 1: w_0 = fallback).  On a uniform
 * lattice every width is the spacing; sum_k p_k w_k is the trapezoid-like integral of p dx
 * that the load balance uses.  Returns 0, or -1 when the points are not strictly sorted. */
int lub_elastic_segment_widths(int n, const double *x, double fallback, double *w);

/* Particle fields of the model in the particle solver (models/elasticWall/elasticWall.h; saved in
 * particles.h5): the running mean of the wall pressure and the undeformed shape. */
#define LUB_ELASTIC_FIELD_MEAN  "pWallMean"
#define LUB_ELASTIC_FIELD_SHAPE "elasticShape"

/* ---- influence coefficients ------------------------------------------------------------- */

/* a(K) of T-47 for K >= 0 (a(1/2) = ln 1 - 1 + 0 = -1: x ln x -> 0), accurate to round-off
 * for large K (written as ln K + (atanh(z)/z - 1) + ln(1 - z^2)/2, z = 1/(2K)). */
double lub_elastic_a(double K);

/* Displacement at distance d from the centre of a segment of width l carrying unit pressure:
 * -(4 / (pi E)) l (a(|d| / l) + ln(l / b))   [m/Pa]. */
double lub_elastic_coefficient(double d, double l, double E, double b);

/* Influence of ns pressure segments (centres xs, widths ls) on nt points xt:
 *     v[i] = sum_j C(xt[i] - xs[j], ls[j]) p[j].
 * Set up once (the coefficients depend on x-offsets only); evaluated without allocation.
 *
 * Storage.  Points are sorted by x and split into runs of constant spacing (and, for
 * segments, constant width); the block of a target run and a source run with the same
 * spacing is Toeplitz (C depends on i - j only) and stored as one vector of nt_r + ns_s - 1
 * coefficients; other blocks (irregular points, different spacings) are stored dense, or,
 * when the dense blocks would exceed lub_elastic_dense_max bytes, computed on the fly at each
 * evaluation (slow: a logarithm per pair).  A uniform patch (a Reynolds grid, wall particles
 * on an x-lattice) therefore costs O(N) memory; an OPT patch of a fine run between two
 * coarse runs has five Toeplitz blocks (fine-fine and the four coarse-coarse pairs) and four
 * dense fine-coarse blocks.  Uniform runs have at least 8 points lying within 1e-9 of the
 * spacing from a fitted lattice.  Every evaluation is a direct sum, O(nt ns) multiply-adds
 * (vectorised; OpenMP over targets for blocks of more than 2^20 pairs).  Measured on one core
 * of the development machine: 0.3 ns per pair, 2.6 ms for 3,041 wall particles on an
 * x-lattice (Toeplitz, 48 kB); 4.1 ms for 3,041 particles at arc-length spacing l0 on the
 * R = 0.01 m cylinder as particleGen places them (dense, 70 MB, set up in 0.4 s).  lubFoam
 * takes about 4 us per particle-step, 0.2 s per step for the thesis' 50,558 particles, so the
 * deformation costs 1-2% of a step and no FFT is used (a convolution by FFT would also need
 * the Toeplitz structure the arc does not have). */
typedef struct lub_elastic_kernel lub_elastic_kernel;

/* Limit of the dense blocks' storage [bytes] (default 256 MiB); lub_elastic_set_dense_max
 * changes it for kernels created afterwards (tests). */
size_t lub_elastic_dense_max(void);
void lub_elastic_set_dense_max(size_t bytes);

/* Allocate and precompute.  ns, nt >= 1; widths > 0; E, b > 0 (checked: lub_bug). */
lub_elastic_kernel *lub_elastic_kernel_create(int ns, const double *xs, const double *ls, int nt,
                                              const double *xt, double E, double b);
void lub_elastic_kernel_free(lub_elastic_kernel *k);

/* v[0..nt) from p[0..ns), in the caller's order of xt and xs.  No allocation; uses the
 * kernel's workspace, so one kernel must not be evaluated by two threads at once. */
void lub_elastic_displacement(lub_elastic_kernel *k, const double *p, double *v);

/* What the set-up chose: runs of targets and sources, Toeplitz and dense blocks, bytes of
 * stored coefficients, and whether dense blocks are computed on the fly. */
typedef struct {
    int target_runs, source_runs, toeplitz_blocks, dense_blocks, on_the_fly;
    size_t bytes;
} lub_elastic_kernel_info;
void lub_elastic_kernel_get_info(const lub_elastic_kernel *k, lub_elastic_kernel_info *info);

/* Reference: the same sum with every coefficient computed anew, in the given order (tests,
 * tiny patches).  O(nt ns) logarithms. */
void lub_elastic_displacement_direct(int ns, const double *xs, const double *ls, int nt,
                                     const double *xt, double E, double b, const double *p,
                                     double *v);

#endif
