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

/* The coefficients L_ij of (LSMPS-L) for the particles i of mask->i, from their neighbours j
 * of mask->j within re (w_ij > 0): coef[q] for each entry q of i's list (0 for a neighbour
 * outside mask->j).  flag[i] = 1 where M_i is ill-conditioned (its coefficients are left
 * untouched: the caller takes the standard Laplacian), else 0; particles outside mask->i are
 * not touched.  rcond_min <= 0 selects LUB_LSMPS_RCOND_MIN.  Returns the number flagged.
 * coef has the lists' capacity (nb->cap_pairs entries). */
size_t lub_mps_lsmps_laplacian(const lub_neighbours *nb, const lub_mps_mask *mask, int dim,
                               double l0, double rcond_min, double *coef, uint8_t *flag);

/* lap f_i = sum_q coef[q] (f_j - f_i) for the particles of mask->i whose flag is 0 (the
 * others untouched), e.g. to check the coefficients on a field. */
void lub_mps_lsmps_apply(const lub_neighbours *nb, const lub_mps_mask *mask, const double *coef,
                         const uint8_t *flag, const double *f, double *lap);

#endif
