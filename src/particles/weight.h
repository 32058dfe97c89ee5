/* lubkit MPS: the weight function, and the reference values of a lattice of particles.
 *
 * Every MPS sum (PND, Laplacian, gradients, reference values n0 and lambda0) weighs a pair
 * through this one function, so that n0 and lambda0 stay consistent with the operators.  It
 * lives with the particles, below the solver, so that a particle set (particleGen's levels)
 * has its reference values without the solver (src/LAYERS).
 */
#ifndef LUB_PARTICLES_WEIGHT_H
#define LUB_PARTICLES_WEIGHT_H

/* thesis (T-6), Kondo & Koshizuka 2008: w(r) = (r/re - 1)^2 for r < re, 0 otherwise.
 * Finite at r = 0 (w = 1) and with w' = 0 at r = re, so PND varies smoothly as particles
 * cross the effective radius. */
static inline double lub_mps_weight(double r, double re)
{
    /* 1/re is hoisted out of the callers' loops: a multiply per pair, not a division */
    const double q = r * (1.0 / re) - 1.0;
    return r < re ? q * q : 0.0;
}

/* The same value for a finite r >= 0 (a listed pair's distance), written without a branch
 * so that a loop over pairs vectorises (the neighbour search's); inv_re = 1.0 / re. */
static inline double lub_mps_weight_pair(double r, double inv_re, double re)
{
    const double q = r * inv_re - 1.0;
    return (double)(r < re) * (q * q);
}

/* Reference PND n0 and lambda0 (T-4, T-5) of a full square (2-D) or cubic (3-D) lattice of
 * spacing l0, around one of its particles:
 *     n0 = sum_j w(|r_j|, re),   lambda0 = sum_j |r_j|^2 w(|r_j|, re) / n0.
 * With the particles (not the solver): the particle files carry them per level
 * (geometry/discretise.h, lub_level_reference). */
void lub_mps_reference(int dim, double l0, double re, double *n0, double *lambda0);

#endif
