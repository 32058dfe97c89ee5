/* lubkit MPS: the LSMPS Laplacian (methods.md §1; Tamai & Koshizuka 2014, type A, degree 2).
 *
 * The standard MPS Laplacian (T-3) is exact on a full lattice but of order zero on a
 * disordered arrangement: no refinement makes it converge on moving particles.  LSMPS fits
 * around particle i the polynomial of degree 2 without a constant term (type A: it passes
 * through f_i) to the neighbours' differences f_j - f_i by weighted least squares,
 *
 *     f_j - f_i ~ a . p(r_ij / l0),   p(s) = (s_x, s_y, s_x^2, s_y^2, s_x s_y)      (2-D)
 *                                      p(s) = (s_x, s_y, s_z, s_x^2, s_y^2, s_z^2,
 *                                              s_x s_y, s_x s_z, s_y s_z)            (3-D)
 *     M_i = sum_j w_ij p_ij p_ij^T,   a_i = M_i^-1 sum_j w_ij p_ij (f_j - f_i),
 *
 * w_ij the kernel of T-6, and takes lap f_i = (2 / l0^2) (a_xx + a_yy (+ a_zz)).  Written as
 * pair coefficients,
 *
 *     lap f_i = sum_j L_ij (f_j - f_i),   L_ij = (2 / l0^2) w_ij c_i . p_ij,
 *     c_i = M_i^-1 e,   e = 1 on the squares' entries, 0 elsewhere,            (LSMPS-L)
 *
 * it reproduces every polynomial of degree <= 2 exactly (to round-off) on any arrangement
 * where M_i is regular, so it is consistent (first order on disordered particles, second on
 * a lattice: methods.md §1).  L_ij differs from L_ji: a matrix built from it is not
 * symmetric (linalg/bicgstab.h).
 *
 * M_i needs neighbours that fix a quadratic: at least 5 (9 in 3-D) spread in every direction,
 * about three rows across.  Where the factorisation of M_i (lsq.h, pivoted Cholesky in l0
 * units) gives a pivot ratio below rcond_min (a film two particles thick, a free-surface
 * particle with a one-sided neighbourhood, a splash) the particle is flagged, and the caller
 * uses the standard Laplacian (T-3) there.
 */
#ifndef LUB_MPS_LSMPS_H
#define LUB_MPS_LSMPS_H

#include <stddef.h>
#include <stdint.h>

#include "mps/neighbours.h"
#include "mps/operators.h"

/* Default smallest pivot ratio of M_i (in l0 units) accepted. */
#define LUB_LSMPS_RCOND_MIN 1e-3

/* A boundary condition inside the fit (methods.md §1, (1.3); derived: Matsunaga and Koshizuka
 * put the boundary conditions into the least-squares objective, lubkit's sources do not print
 * how).  Where d_i > 0 the objective of particle i gets one more row, at the boundary point
 * x_b = x_i + d_i n_i (s_b = d_i n_i / l0),
 *
 *     J_i(a) = sum_j w_ij (f_j - f_i - a . p_ij)^2 + mu_i (t_i - r_i . a)^2,
 *     mu_i = weight w(d_i, re) sum_j w_ij   (w of T-6: the row fades as the surface leaves
 *                                           the neighbourhood),
 *
 *   NEUMANN    n . grad f(x_b) = 0:  r_i = n_i . grad_s p(s_b),  t_i = 0 (the stress-free
 *              surface for the velocity, to leading order du/dn = 0);
 *   DIRICHLET  f(x_b) = 0:           r_i = p(s_b),               t_i = 0 - f_i (the free
 *              surface for the pressure, P = 0 on it),
 *
 * whose minimiser is a_i = M'_i^-1 (sum_j w_ij p_ij (f_j - f_i) + mu_i r_i t_i), M'_i = M_i +
 * mu_i r_i r_i^T: the pair coefficients are those of (LSMPS-L) with M'_i for M_i, and a
 * Dirichlet row adds the coefficient of the boundary value, L_ib = (2/l0^2) mu_i c'_i . r_i,
 *
 *     lap f_i = sum_j L_ij (f_j - f_i) + L_ib (0 - f_i),   c'_i = M'_i^-1 e.
 *
 * Every quadratic that satisfies the condition at x_b is still reproduced exactly (its
 * residual is zero at every row), whatever mu_i; one that violates it is not. */
enum { LUB_LSMPS_BC_NEUMANN = 0, LUB_LSMPS_BC_DIRICHLET = 1 };
/* Default weight of the boundary row (system/schemes.yaml laplacian.freeSurface.weight):
 * chosen in tutorials/convergence/wedgeB at h0/8 (stress-free row, (1.2) in both terms;
 * relative L2 3.6% at 1, 3.3% at 3, 2.6% at 10, 2.5% at 30, 2.2% at 100, 2.7% at 1000; at h0/4
 * 7.5%, 7.0%, 6.8%, 6.7%, 7.0% at 1, 10, 30, 100, 1000).  Above about 3 the stabilized rows just
 * below a plane surface are blended a little (theta >= 0.89, the positivity bound). */
#define LUB_LSMPS_BC_WEIGHT 100.0
typedef struct {
    int kind;           /* LUB_LSMPS_BC_* */
    const double *n[3]; /* n[d][i]: the boundary's outward unit normal seen from particle i */
    const double *d;    /* d[i]: the distance from x_i to the boundary along n_i (<= 0: no row) */
    double weight;      /* the row's weight: mu_i = weight w(d_i, re) sum_j w_ij */
    double re_l0;       /* re / l0 (the kernel T-6 of the boundary point) */
    double *diag;       /* DIRICHLET: L_ib of each particle (0 where no row; NULL: not wanted) */
} lub_lsmps_bc;

/* The coefficients L_ij of (LSMPS-L) for the particles i of mask->i, from their neighbours j
 * of mask->j within re (w_ij > 0): coef[q] for each entry q of i's list (0 for a neighbour
 * outside mask->j).  flag[i] = 1 where M_i is ill-conditioned (its coefficients are left
 * untouched: the caller takes the standard Laplacian), else 0; particles outside mask->i are
 * not touched.  rcond_min <= 0 selects LUB_LSMPS_RCOND_MIN.  bc (may be NULL): a boundary
 * row in the fits of the particles with bc->d[i] > 0.  Returns the number flagged.
 * coef has the lists' capacity (nb->cap_pairs entries). */
size_t lub_mps_lsmps_laplacian(const lub_neighbours *nb, const lub_mps_mask *mask, int dim,
                               double l0, double rcond_min, const lub_lsmps_bc *bc, double *coef,
                               uint8_t *flag);

/* Stabilized LSMPS (methods.md §1, (1.2); after Matsunaga and Koshizuka, CMAME 389 (2022)
 * 114416, whose stabilisation terms are not printed in lubkit's sources: this is a design
 * derived from their description, "artificial stabilisation terms in the least-squares
 * objective, only near the surface").  The fit of (LSMPS-L) gets one more term, a penalty that
 * pulls the fitted Laplacian towards the standard one (T-3) of the same neighbours,
 *
 *     J_i(a) = sum_j w_ij (f_j - f_i - a . p_ij)^2 + lambda_i (e . a - s_i)^2,
 *     s_i = (l0^2 / 2) sum_j S_ij (f_j - f_i),   S_ij = 2d w_ij / (lambda0 n0)  [T-3's],
 *
 * whose minimiser gives (Sherman-Morrison on M_i + lambda_i e e^T)
 *
 *     lap f_i = sum_j L_ij (f_j - f_i),   L_ij = theta_i A_ij + (1 - theta_i) S_ij,
 *     theta_i = 1 / (1 + lambda_i g_i),   g_i = e . M_i^-1 e,                     (SLSMPS)
 *
 * A_ij the coefficients of (LSMPS-L): a blend, still linear in f, on the same pairs.  g_i is
 * the variance of the fitted Laplacian per unit noise in f (how badly the neighbourhood fixes
 * it); on a full lattice g0 (lub_mps_lsmps_reference), within 0.9-1.2 g0 on particles jittered
 * by 0.3 l0, 1.4-1.9 g0 next to a wall or one row below a free surface, 10-30 g0 on a
 * free-surface particle, 300-700 g0 in a free sheet two particles thick.  lambda_i is the
 * larger of
 *
 *   - the bias penalty  lambda_i g0 = strength max(0, g_i/g0 - onset): zero where the fit is
 *     as well determined as onset times a lattice's (then theta = 1: exactly LSMPS, every
 *     quadratic reproduced), growing with g_i, so that theta = 1 / (1 + strength rho (rho -
 *     onset)), rho = g_i/g0, goes continuously to the standard row as M_i degenerates;
 *   - the smallest penalty that makes every L_ij >= 0 (theta_i <= S_ij / (S_ij - A_ij) where
 *     A_ij < 0): the row is then that of an M-matrix (positive diagonal sum_j L_ij, weakly
 *     dominant), the property the solvers and the sign of a diffusion rely on.  The rows of
 *     LSMPS itself are all positive inside the fluid (the weight T-6 on lattices jittered by
 *     up to 0.3 l0, next to walls, below a plane surface), so this binds only at ragged
 *     surfaces.
 *
 * Where the pivot ratio of M_i is below rcond_min, g_i is taken as infinite: theta = 0 and
 * the particle is flagged (the caller's standard row, as lub_mps_lsmps_laplacian). */
typedef struct {
    double n0, lambda0;     /* T-5, T-4 of the particles' level: S_ij = 2d w_ij / (lambda0 n0) */
    double g0;              /* e . M^-1 e on the full lattice (lub_mps_lsmps_reference) */
    double strength;        /* the bias penalty's slope (>= 0; 0: only the positivity bound) */
    double onset;           /* g_i/g0 up to which the bias penalty is zero (>= 1) */
    double rcond_min;       /* as lub_mps_lsmps_laplacian (<= 0: LUB_LSMPS_RCOND_MIN) */
    const lub_lsmps_bc *bc; /* as lub_mps_lsmps_laplacian (NULL: none): M'_i for M_i in
                               A_ij and g_i; bc->diag gets theta_i L_ib */
} lub_lsmps_stabilization;

/* Defaults of strength and onset (system/schemes.yaml laplacian.stabilization): onset 3, not
 * 2, because sheared particles that come within 0.7 l0 of a wall reach rho 2.4, where the
 * blend with T-3 of their fluid and wall neighbours cost accuracy (tests/unit/mps_flow_test.c,
 * the jittered channel: 0.78% at onset 2, 0.16% at 3). */
#define LUB_LSMPS_STAB_STRENGTH 1.0
#define LUB_LSMPS_STAB_ONSET    3.0

/* g0 = e . M^-1 e of (LSMPS-L) (l0 units) for a particle of a full square (cubic) lattice of
 * spacing l0 with every lattice neighbour within re (2-D, re = 3.1 l0: 0.1232). */
double lub_mps_lsmps_reference(int dim, double l0, double re);

/* The coefficients L_ij of (SLSMPS), as lub_mps_lsmps_laplacian (coef, flag, mask); theta
 * (may be NULL) gets theta_i of each particle of mask->i (0 where flagged).  Returns the
 * number flagged. */
size_t lub_mps_lsmps_stabilized(const lub_neighbours *nb, const lub_mps_mask *mask, int dim,
                                double l0, const lub_lsmps_stabilization *o, double *coef,
                                uint8_t *flag, double *theta);

/* lap f_i = sum_q coef[q] (f_j - f_i) for the particles of mask->i whose flag is 0 (the
 * others untouched), e.g. to check the coefficients on a field. */
void lub_mps_lsmps_apply(const lub_neighbours *nb, const lub_mps_mask *mask, const double *coef,
                         const uint8_t *flag, const double *f, double *lap);

#endif
