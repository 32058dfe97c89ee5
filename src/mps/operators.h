/* lubkit MPS: discrete operators on neighbour lists (methods.md §1).
 *
 * Every operator takes the lists of lub_neighbours (built once per step), raw per-particle
 * arrays, and an optional mask; OpenMP over particles i.  Lists and arrays are in the same
 * particle order.  The operators use the pair data stored in the lists (r_ij, |r_ij|, w_ij),
 * so a pair weight is always lub_mps_weight (weight.h).
 *
 * Mask: which particles take part, by kind (particles.h: LUB_FLUID, LUB_WALL, LUB_DUMMY).
 *
 *     lub_mps_mask m = {P->kind, LUB_MPS_KIND(LUB_FLUID) | LUB_MPS_KIND(LUB_WALL),
 *                                LUB_MPS_KIND(LUB_FLUID) | LUB_MPS_KIND(LUB_WALL)};
 *
 * A particle i whose kind is not in m.i gets no output: its entry of the output array is
 * left untouched (so the caller can keep or pre-set it).  A neighbour j whose kind is not in
 * m.j does not enter the sums (nor the minimum pressure p_hat_i).  A NULL mask, or a NULL
 * kind array, means every particle takes part both ways.  Examples: PND of every particle
 * with mask NULL (dummies count); pressure gradient on fluid only, from fluid and wall
 * neighbours (dummy particles carry no pressure), with the mask above but i = fluid.
 */
#ifndef LUB_MPS_OPERATORS_H
#define LUB_MPS_OPERATORS_H

#include <stddef.h>
#include <stdint.h>

#include "mps/neighbours.h"
#include "particles/weight.h"

#define LUB_MPS_KIND(k) (1u << (k))
#define LUB_MPS_ALL     0xffu

typedef struct {
    const uint8_t *kind; /* per-particle kind 0..7 (a larger kind takes part only where
                          * the mask is LUB_MPS_ALL), or NULL: everyone takes part */
    unsigned i;          /* bit k set: particles of kind k get an output */
    unsigned j;          /* bit k set: particles of kind k count as neighbours */
} lub_mps_mask;

/* Default for the LSMPS degeneracy test (see lub_mps_gradient_lsmps). */
#define LUB_MPS_LSMPS_DET_MIN 1e-2

/* The reference values n0 and lambda0 (T-4, T-5): lub_mps_reference, particles/weight.h. */

/* The coefficient of the Laplacian (T-3) times a caller's factor: scale 2d / (lambda0 n0),
 * formed in that order (scale 2 d, then the division), so that the viscous step's factor
 * dt nu / 2 (T-31) gives the bits of the expression written out. */
static inline double lub_mps_laplacian_coefficient(int dim, double lambda0, double n0, double scale)
{
    return scale * 2.0 * dim / (lambda0 * n0);
}

/* PND n_i = sum_{j != i} w_ij (T-4, T-11). */
void lub_mps_pnd(const lub_neighbours *nb, const lub_mps_mask *mask, double *pnd);

/* Standard Laplacian (T-3, T-10): lap_i = (2d / (lambda0 n0)) sum_j (phi_j - phi_i) w_ij.
 * Exact (to round-off) at a particle whose neighbourhood within re is a full square / cubic
 * lattice with the n0 and lambda0 of that lattice, for every polynomial of degree <= 3:
 * odd moments of the neighbourhood vanish and its second moment is (lambda0 n0 / d) I. */
void lub_mps_laplacian(const lub_neighbours *nb, const lub_mps_mask *mask, double n0,
                       double lambda0, const double *phi, double *lap);

/* Standard gradient (T-13, T-14):
 *     grad_i = (d / n0) sum_j (p_j - p_hat_i) r_ij / |r_ij|^2 w_ij,
 *     p_hat_i = min(p_i, p_j over the neighbours) if shift, else p_i.
 * grad[d] receives component d (grad[2] unused in 2-D).  Exact for linear fields at a
 * particle whose neighbourhood is a full lattice (second moment (n0/d) I), with or without
 * the shift: the shift adds (p_i - p_hat_i) (d/n0) sum_j w_ij r_ij / |r_ij|^2, which
 * vanishes on any point-symmetric neighbourhood.  Pairs at distance 0 are skipped. */
void lub_mps_gradient(const lub_neighbours *nb, const lub_mps_mask *mask, double n0, int shift,
                      const double *p, double *const grad[3]);

/* LSMPS-type gradient (T-15):
 *     M_i = (1/n0) sum_j w_ij e_ij e_ij^T,  e_ij = r_ij / |r_ij|,
 *     grad_i = M_i^{-1} (1/n0) sum_j w_ij (p_j - p_hat_i) r_ij / |r_ij|^2.
 * Without the shift, exact for linear fields on any particle arrangement where M_i is
 * regular; with the shift, the error is (p_i - p_hat_i) M_i^{-1} (1/n0) sum_j w_ij
 * r_ij / |r_ij|^2 (zero on symmetric neighbourhoods, small where p is smooth).
 * Degenerate M_i (one-sided or collinear neighbours): when
 *     det(M_i) / (tr(M_i) / d)^d < det_min
 * (a scale-free isotropy ratio: 1 for a full lattice, 0.95 for a half plane, 0.81 for a
 * row of particles plus one neighbour beside it, 0 for collinear neighbours, about 4/cond(M)
 * in 2-D and 3.4/cond(M) in 3-D when ill-conditioned) the particle gets the standard
 * gradient instead.  det_min <= 0 selects LUB_MPS_LSMPS_DET_MIN (1e-2, cond(M) above about
 * 400).  Returns the number of such fallbacks. */
size_t lub_mps_gradient_lsmps(const lub_neighbours *nb, const lub_mps_mask *mask, double n0,
                              int shift, double det_min, const double *p, double *const grad[3]);

#endif
