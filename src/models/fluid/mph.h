/* lubkit fluid mph: Moving Particle Hydrodynamics (Kondo), integrated implicitly in the bulk
 * and shear viscosity (MPH-I); doc/methods.md §8 (K-1..K-7a).
 *
 *     fluid: { type: mph, bulkViscosity: 0.1, bulkModulus: 1.0e4 }   # constant/models.yaml
 *
 * with rho, nu of constant/transportProperties.yaml (mu = rho nu).  The step, on the solver
 * state of mps/mps.h (lub_mps):
 *
 *   1. x^{k+1} = x^k + dt u^k (fluid; walls and dummies with their patch velocity)
 *   2. neighbour lists of every particle, reaching h_v = 3.5 l0 (lub_mps_config.list_l0)
 *   3. n_i (h_p = 1.75 l0) and P^kap_i = kappa max(n_i - n0, 0) of every particle
 *   4. u* = u^k + dt g (the models' forces hooks)
 *   5. [rho0/dt I + V + C Lambda C^T] u^{k+1} = rho0/dt u* - C P^kap + wall terms: the d N
 *      fluid velocities at once, one SPD system (system/solution.yaml U)
 *   6. P_i = P^kap_i + lambda sum_j (u_ij.e_ij) w_p'_ij (K-7a) of every particle, walls
 *      included (their load: probe wallPressure); P^kap_i kept as the field pKappa
 *
 * divergence: corrected replaces the sum s_i = sum_j u_ij.g_ij of the bulk viscosity by
 * sum_j u_ij.B_i g_ij, B_i = -(sum_j g_ij r_ij^T)^-1, exact for linear fields (mph.c,
 * correction): a shear on shifted rows then dissipates nothing through lambda.
 *
 * gradient: corrected replaces kappa's pair force (P_i + P_j) g_ij between fluid particles by
 * (P_i Bg_i + P_j Bg_j) g_ij, Bg_i = -(I + M^W_i)(M^F_i)^-1 (M over the fluid and over the
 * wall and dummy neighbours; the wall pairs stay central): each particle's own pressure has
 * the virial -P I, so a sheared packing's fabric carries no shear stress (the internal
 * friction of methods.md §8); lambda's part through its divergence s_i = sum_j u_ij.B_ij g_ij
 * with the same Bg (in place of divergence: corrected's B).  Momentum and angular momentum
 * exact; kappa's part conserves no energy (mph.c, correction_gradient).
 *
 * shifting: beta (0, off by default) moves each fluid particle in tension or without
 * pressure (P_i <= 0) with a full neighbourhood (n_i >= 0.95 n0) after the step by beta
 * l0^2/lambda_max times -grad of the potential sum_pairs (1 - r/h_s)^3 over all its
 * neighbours (walls and dummies included): the lattice's zone-edge modes, which a sustained
 * tension drives (methods.md §5.5, "Sustained tension is unstable") and nothing else in MPH
 * resists, relax by beta a step.  Velocities stay: momentum exact; angular momentum and
 * energy not exactly (mph.c, shift).
 *
 * Walls (the seed is silent, as Kondo's code): wall and dummy particles alike count in n_i,
 * carry their prescribed velocity, get P from (K-7a) and exchange the same pair forces; the
 * wall must be at least h_v thick (a wall layer and 3 dummy layers: particleGenDict
 * dummyLayers >= 3, checked at start-up).  A rigid body's force (models/fluid.h wall_forces)
 * is the reaction of the pair forces its particles exchanged with the fluid in the step.
 *
 * The kernels, the operators and the energy are exposed for the tests
 * (tests/unit/mph_test.c).
 */
#ifndef LUB_MODELS_FLUID_MPH_H
#define LUB_MODELS_FLUID_MPH_H

#include "mps/mps.h"

#define LUB_MPH_HP 1.75 /* pressure kernel radius h_p / l0 */
#define LUB_MPH_HV 3.5  /* viscosity kernel radius h_v / l0 */

/* w(r, h) = (1 - r/h)^2 / (S h^d), S = pi/(6 l0^2) (2-D), 2 pi/(15 l0^3) (3-D), so that
 * l0^-d int w dV = 1; 0 for r >= h.  lub_mph_dw: dw/dr. */
double lub_mph_w(int dim, double l0, double h, double r);
double lub_mph_dw(int dim, double l0, double h, double r);
/* shifting: the radius of the shifting potential sum_pairs (1 - r/h_s)^3 (h_s / l0: 1.75 in
 * 2-D, 1.9 in 3-D, where its Hessian on the lattice is positive semi-definite), and the
 * largest eigenvalue of that Hessian over the Brillouin zone (l0 = 1): the stiffest
 * arrangement mode, which a step of shifting relaxes by beta. */
double lub_mph_shifting_radius(int dim);
double lub_mph_shifting_stiffness(int dim);
/* n0 = sum_j w(|r_j|, h_p) over the square (cubic) lattice of spacing l0 around a point. */
double lub_mph_n0(int dim, double l0);
/* The stability limit of the explicit elastic term: dt sqrt(kappa/rho0)/l0 < 2 / (l0
 * max_k |a(k)|), a(k) = sum_j w_p'(r_j) e_j (exp(i k.r_j) - 1) over the lattice: the
 * symplectic Euler step of the stiffest lattice compression wave (omega dt < 2). */
double lub_mph_elastic_limit(int dim);
/* The viscous term's response to a shear across layers of particles l0 apart, the particles
 * spread evenly within each layer (body-fitted rows: particleGen's fluidLayers), over the
 * continuum's: (d+2) sum_k int (-w_v'(r) r) e_t^2 e_n^2 over the layers n = k l0, the kernel
 * normalised as l0^-d int w dV = 1.  0.9603 in 2-D (methods.md §8, Accuracy).
 * viscousNormalisation: layers divides the viscous coefficient by it. */
double lub_mph_layer_quadrature(int dim);

/* One MPH-I step of dt (the fluid's step, models/fluid.h). */
lub_step_status lub_mph_step(lub_mps *m, double dt, long *bad, char *msg, size_t msgsize);

/* The operators at the current positions and velocities (the lists built afresh), for every
 * particle i: pnd (n_i, h_p), div (sum_j (u_ij.e_ij) w_p'_ij, which tends to -div u) and visc
 * (-2 (d+2) sum_j (u_ij.e_ij) e_ij w_v'_ij / r_ij, the viscous term of (K-6) per unit mu,
 * which tends to lap u + 2 grad div u).  Any output may be NULL. */
void lub_mph_operators(lub_mps *m, double *pnd, double *div, double *const visc[3]);

/* The energy of methods.md §8 after a step (its n_i, lists and positions x, velocities u),
 * per unit depth in 2-D (J/m): part[0] kinetic sum m |u|^2/2 of the fluid, part[1] elastic
 * sum (kappa/2) max(n_i - n0, 0)^2 dV of every particle, part[2] potential -sum m g.x of the
 * fluid (g: the body acceleration), part[3] -(dt/2) sum u.F of the fluid, F = m g plus the
 * elastic pair forces: the first-order term of the step's modified energy.  The step is
 * symplectic Euler in its conservative part (x += dt u, then u += dt F(x)/m), which
 * conserves not part[0..2] but their sum with part[3] to O(dt^2) (exactly in free fall,
 * where part[0..2] alone rise by m |g|^2 dt^2 / 2 per particle and step).  Returns the sum of
 * the four, which the dissipative terms make decrease.  part may be NULL. */
double lub_mph_energy(const lub_mps *m, const double g[3], double dt, double part[4]);

#endif
