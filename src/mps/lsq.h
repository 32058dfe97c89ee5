/* lubkit MPS: weighted least-squares interpolation from the particles of another resolution
 * level (multi-resolution, methods.md §3; thesis §2-2-1).
 *
 * Where the overlapping particle technique (OPT) needs a value of level A at a point where
 * level A has no computed value, it takes it from level B by least squares:
 *   (a) a particle generated in a level's generation layer at the far edge of an overlap gets
 *       its velocity and pressure from the level the fluid comes from;
 *   (b) in the fixed-velocity band of each level (T-25, T-26) the temporary velocity (and the
 *       pressure used as a boundary value) is interpolated from the other level.
 *
 * Method (LSMPS-type, Tamai & Koshizuka 2014; the same weighting as T-15).  Around the target
 * point x_t fit the local polynomial of degree p (p = 1: value and gradient; p = 2: also the
 * second derivatives) to the source particles j within the source level's effective radius,
 *
 *     f(x_t + r) ~ a . q(r / l0),
 *     q(s) = [1, s_x, s_y (, s_z)]                                        p = 1 (1 + d terms)
 *          + [s_x^2/2, s_y^2/2 (, s_z^2/2), s_x s_y (, s_x s_z, s_y s_z)]  p = 2 (6 / 10 terms)
 *
 * minimising sum_j w_j (f_j - a . q_j)^2 with w_j = w(|r_j|, re) the kernel of T-6 (weight.h)
 * and r_j = x_j - x_t (nearest periodic image).  The normal equations
 *
 *     M a = b,   M = sum_j w_j q_j q_j^T,   b = sum_j w_j f_j q_j                 (LSQ-1)
 *
 * give f(x_t) = a_0, grad f = a_{1..d} / l0 and the second derivatives a_{d+1..} / l0^2.
 * Scaling the basis by l0 of the source level keeps M of order one whatever the units; M
 * (divided by the total weight sum_j w_j) is factorised by a Cholesky decomposition with
 * symmetric (diagonal) pivoting, which detects rank deficiency: the fit is refused when a
 * pivot falls below rcond_min times the largest (the pivot ratio estimates 1/cond(M)).  M is
 * deliberately not equilibrated column by column: in l0 units a neighbourhood that spreads
 * over much less than l0 in some direction (nearly collinear points) is nearly singular, and
 * it must be refused, not rescaled to look regular.
 * One step of iterative refinement on (LSQ-1) follows.  The estimate reproduces every
 * polynomial of degree <= p exactly (to round-off) whenever M is regular, on any particle
 * arrangement: a polynomial of degree p lies in the span of q, so its residual is zero.
 *
 * Failure and fallback.  Order p needs at least as many neighbours (within re) as terms
 * (3 / 6 in 2-D, 4 / 10 in 3-D), and neighbours that determine the polynomial: collinear
 * neighbours in 2-D (coplanar in 3-D) cannot fix a gradient across their line; two rows of
 * particles cannot fix a second derivative across them.  When order 2 is impossible the fit
 * falls back to order 1; when order 1 is impossible it falls back to the kernel-weighted
 * mean (Shepard: a_0 = sum w_j f_j / sum w_j, order 0, zeroth-order accurate, no gradient).
 * The result says which order was returned and why the requested one was not (status): the
 * caller decides whether a fallback is acceptable (e.g. skip generating a particle).  With
 * no neighbour within re nothing is written.
 *
 * Cost and memory: one pass over the candidates, an m x m factorisation (m <= 10) and nf
 * solves.  No allocation: fixed-size arrays on the stack; thread-safe.
 */
#ifndef LUB_MPS_LSQ_H
#define LUB_MPS_LSQ_H

#include <stddef.h>

#define LUB_LSQ_MAX_TERMS  10 /* second order in 3-D */
#define LUB_LSQ_MAX_FIELDS 8  /* fields interpolated with one factorisation */
#define LUB_LSQ_RCOND_MIN  1e-6

typedef enum {
    LUB_LSQ_OK = 0,       /* the requested order was fitted */
    LUB_LSQ_TOO_FEW = 1,  /* fewer neighbours within re than terms of the requested order */
    LUB_LSQ_SINGULAR = 2, /* enough neighbours, but the moment matrix (in l0 units) is
                             singular or ill-conditioned (pivot ratio < rcond_min): collinear
                             (2-D) or coplanar (3-D) neighbours; for order 2 also two rows */
    LUB_LSQ_EMPTY = 3     /* no neighbour within re: nothing written */
} lub_lsq_status;

typedef struct {
    int dim;          /* 2 or 3 */
    int order;        /* requested order: 1 (value + gradient) or 2 (+ second derivatives) */
    double l0;        /* particle spacing of the source level (scales the basis) */
    double re;        /* effective radius of the source level (kernel support, T-6) */
    double period[3]; /* period of each direction, 0 when not periodic: offsets r_j are
                         taken to the nearest periodic image */
    double rcond_min; /* smallest accepted pivot ratio; <= 0 selects LUB_LSQ_RCOND_MIN */
} lub_lsq_options;

typedef struct {
    lub_lsq_status status; /* LUB_LSQ_OK, or why the requested order could not be used */
    int order;             /* order returned: the requested one, a lower one (fallback), 0 for
                              the weighted mean (gradient and second derivatives set to 0), or
                              -1 with LUB_LSQ_EMPTY (nothing written) */
    int n;                 /* neighbours within re */
    double rcond;          /* pivot ratio of the fit returned (1 for the weighted mean) */
} lub_lsq_result;

/* Options with the defaults: order 1, no periodicity, rcond_min LUB_LSQ_RCOND_MIN. */
lub_lsq_options lub_lsq_defaults(int dim, double l0, double re);

/* Estimate nf fields at the point xt from the source particles.
 *
 *   x[3]      positions of the source particles, component arrays (lub_particles.x; x[2]
 *             unused in 2-D)
 *   n, idx    the candidates: particles idx[0..n-1], or 0..n-1 when idx is NULL.  Candidates
 *             at or beyond re are skipped, so a cell-list query may pass a superset.
 *   nf, f     f[k][j]: field k of particle j (e.g. {u[0], u[1], p}); 1 <= nf <= 8
 *   value     value[k]: the estimate of field k at xt
 *   grad      grad[k][0..dim-1] (may be NULL): the gradient of field k at xt
 *   hess      hess[k][0..5] (may be NULL): xx, yy, zz, xy, xz, yz second derivatives
 *             (zero unless order 2 was fitted; zz, xz, yz zero in 2-D)
 *
 * Never fatal on data: the status reports a fit that could not be made (see above). */
lub_lsq_result lub_lsq_interpolate(const lub_lsq_options *o, const double xt[3],
                                   const double *const x[3], size_t n, const size_t *idx, int nf,
                                   const double *const *f, double *value, double (*grad)[3],
                                   double (*hess)[6]);

/* The small symmetric positive semi-definite solves of the fits (also used by the LSMPS
 * Laplacian, mps/lsmps.h).  lub_lsq_factorise: the leading m x m block of M (symmetric,
 * full), scaled by M_00, S = M / M_00, then P S P^T = L diag(piv) L^T with diagonal pivoting
 * (largest remaining diagonal first).  No column equilibration: the basis is in units of l0,
 * so a direction in which the neighbours spread over much less than l0 (nearly collinear
 * points) shows up as a small pivot instead of being scaled back to one.  Returns the pivot
 * ratio piv_min / piv_max (pivots do not increase), or stops at the first pivot below
 * rcond_min times the first and returns its ratio (0 when it is not positive; M_00 must be
 * positive).  lub_lsq_solve: M a = b with the factorisation (the original, unscaled
 * unknowns); only after a factorisation whose ratio is at least rcond_min. */
typedef struct {
    double A[LUB_LSQ_MAX_TERMS][LUB_LSQ_MAX_TERMS]; /* L below the diagonal, pivots on it */
    double dsc[LUB_LSQ_MAX_TERMS];
    int perm[LUB_LSQ_MAX_TERMS];
    int m;
} lub_lsq_factor;
double lub_lsq_factorise(const double M[LUB_LSQ_MAX_TERMS][LUB_LSQ_MAX_TERMS], int m,
                         double rcond_min, lub_lsq_factor *F);
void lub_lsq_solve(const lub_lsq_factor *F, const double b[LUB_LSQ_MAX_TERMS],
                   double a[LUB_LSQ_MAX_TERMS]);

/* Number of polynomial terms of order p in dim dimensions (1 + d, or 1 + d + d(d+1)/2). */
int lub_lsq_terms(int dim, int order);

/* Name of a status, for messages ("ok", "too few neighbours", ...). */
const char *lub_lsq_status_name(lub_lsq_status s);

#endif
