/* lubkit fluid mph: Moving Particle Hydrodynamics, MPH-I (see mph.h; doc/methods.md §8).
 *
 * Pairs r_ij = x_j - x_i, e_ij = r_ij / r_ij, u_ij = u_j - u_i.  With g_ij = e_ij w_p'(r_ij)
 * (antisymmetric: g_ji = -g_ij) and s_i = sum_j u_ij.g_ij (-> -div u), the dissipation
 * function (K-4) is D = sum_i (lambda/2) s_i^2 dV + (viscous part), and its gradient
 * dD/du_a = lambda dV sum_i s_i ds_i/du_a with ds_i/du_a = g_ia (i != a), -sum_j g_aj (i = a)
 * gives the bulk term of (K-6) with P_i = lambda s_i of (K-7a).  Taken implicitly (backward
 * Euler, u^{k+1}), its matrix is lambda sum_i D_i D_i^T, D_i = grad_u s_i (C Lambda C^T of
 * methods.md §8): symmetric positive semi-definite, and it couples fluid particles a, b
 * through every i within h_p of both, so that |x_a - x_b| < 2 h_p = h_v: the viscous term's
 * reach, and the neighbour lists' (list_l0 = 3.5).  The sum over i runs over every particle,
 * walls included: their s_i (K-7a) holds the fluid's unknown velocities and their own known
 * ones (the latter go to the right-hand side).  The viscous term of (K-6),
 * -2 mu (d+2) sum_j (u_ij.e_ij) e_ij w_v'_ij / r_ij, is c_aj e e^T (u_a - u_j) with
 * c_aj = -2 mu (d+2) w_v'_ij / r_ij > 0: a symmetric positive semi-definite matrix V.  With
 * rho0/dt I the system is SPD, one row per velocity component of a fluid particle (unknown
 * d r + c for fluid particle r, component c).
 *
 * Energy (methods.md §8): the conservative part (elastic, body force) is explicit and the
 * dissipative part implicit; over a step the elastic and potential energy change by the work
 * of the forces at x^{k+1} on the displacement dt u^k (symplectic Euler), so E decreases
 * only up to the step's O(dt^2) splitting error, which the dissipation outweighs in the
 * tests (tests/unit/mph_test.c). */
#include "models/fluid/mph.h"

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "models/fluid.h"
#include "models/transport.h"
#include "mps/operators.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---- kernels ---------------------------------------------------------------------------- */

/* 1 / (S h^d): S = pi / (6 l0^2) (2-D), 2 pi / (15 l0^3) (3-D) [KC], methods.md §8 */
static double kernel_coefficient(int dim, double l0, double h)
{
    const double s = dim == 2 ? M_PI / 6.0 : 2.0 * M_PI / 15.0;
    const double q = l0 / h;
    return (dim == 2 ? q * q : q * q * q) / s;
}

double lub_mph_w(int dim, double l0, double h, double r)
{
    if (!(r < h)) return 0.0;
    const double t = 1.0 - r / h;
    return kernel_coefficient(dim, l0, h) * t * t;
}

double lub_mph_dw(int dim, double l0, double h, double r)
{
    if (!(r < h)) return 0.0;
    return -2.0 * kernel_coefficient(dim, l0, h) * (1.0 - r / h) / h;
}

double lub_mph_n0(int dim, double l0)
{
    const double h = LUB_MPH_HP * l0;
    const int k = (int)ceil(LUB_MPH_HP), kz = dim == 3 ? k : 0;
    double n0 = 0.0;
    for (int a = -k; a <= k; a++)
        for (int b = -k; b <= k; b++)
            for (int c = -kz; c <= kz; c++) {
                const double r = l0 * sqrt((double)(a * a + b * b + c * c));
                if (r > 0) n0 += lub_mph_w(dim, l0, h, r);
            }
    return n0;
}

double lub_mph_elastic_limit(int dim)
{
    /* longitudinal plane waves xi_j = xi exp(i k.x_j) on the lattice (l0 = 1): the elastic
     * potential (kappa/2) sum_i (n_i - n0)^2 dV gives rho0 omega^2 = kappa |a(k)|^2 with
     * dn_i = a(k).xi exp(i k.x_i); the explicit step is stable for omega dt < 2.  Scanned
     * over the Brillouin zone in steps of pi/32 (2-D: max |a| 0.9977 at k = (pi/2, 0),
     * limit 2.005; 3-D: 1.083, limit 1.85) */
    const int nk = 64, kz = dim == 3 ? nk : 0;
    const double h = LUB_MPH_HP;
    double amax = 0;
    for (int p = 0; p <= nk; p++)
        for (int q = 0; q <= nk; q++)
            for (int t = 0; t <= kz; t++) {
                const double k[3] = {M_PI * p / nk, M_PI * (2.0 * q - nk) / nk,
                                     dim == 3 ? M_PI * (2.0 * t - nk) / nk : 0.0};
                double complex a[3] = {0, 0, 0};
                for (int x = -2; x <= 2; x++)
                    for (int y = -2; y <= 2; y++)
                        for (int z = dim == 3 ? -2 : 0; z <= (dim == 3 ? 2 : 0); z++) {
                            const double r = sqrt((double)(x * x + y * y + z * z));
                            if (!(r > 0 && r < h)) continue;
                            const double dw = lub_mph_dw(dim, 1.0, h, r);
                            const double complex ph =
                                cexp(I * (k[0] * x + k[1] * y + k[2] * z)) - 1.0;
                            a[0] += dw * x / r * ph;
                            a[1] += dw * y / r * ph;
                            a[2] += dw * z / r * ph;
                        }
                const double v =
                    sqrt(creal(a[0] * conj(a[0]) + a[1] * conj(a[1]) + a[2] * conj(a[2])));
                if (v > amax) amax = v;
            }
    return 2.0 / amax;
}

double lub_mph_shifting_radius(int dim)
{
    return dim == 3 ? 1.9 : 1.75;
}

double lub_mph_shifting_stiffness(int dim)
{
    /* the Hessian of sum_pairs phi(r), phi = (1 - r/h)^3, for the plane wave xi_j = xi
     * exp(i k.x_j) of the lattice: sum_j K_j (1 - cos k.r_j), K = phi'' e e^T + (phi'/r)(I -
     * e e^T); its largest eigenvalue over k in [0, pi]^d in steps of pi/24 (2-D: 4.684;
     * 3-D: 6.672; the (pi, pi) mode's 2.099 in 2-D, tests/unit/mph_test.c).  The smallest is
     * 0 at k -> 0 in 2-D, -0.3% of the largest in 3-D at h 1.9 (at 1.75 -3%, 2.0 -3%: the
     * reason for that radius). */
    const double h = lub_mph_shifting_radius(dim);
    const int nk = 24, kz = dim == 3 ? nk : 0, R = (int)ceil(h);
    double lmax = 0;
    for (int p = 0; p <= nk; p++)
        for (int q = 0; q <= nk; q++)
            for (int t = 0; t <= kz; t++) {
                const double k[3] = {M_PI * p / nk, M_PI * q / nk, M_PI * t / nk};
                double K[9] = {0};
                for (int x = -R; x <= R; x++)
                    for (int y = -R; y <= R; y++)
                        for (int z = dim == 3 ? -R : 0; z <= (dim == 3 ? R : 0); z++) {
                            const double r = sqrt((double)(x * x + y * y + z * z));
                            if (!(r > 0 && r < h)) continue;
                            const double e[3] = {x / r, y / r, z / r}, u = 1.0 - r / h;
                            const double d1 = -3.0 * u * u / h, d2 = 6.0 * u / (h * h);
                            const double c = 1.0 - cos(k[0] * x + k[1] * y + k[2] * z);
                            for (int a = 0; a < dim; a++)
                                for (int b = 0; b < dim; b++)
                                    K[3 * a + b] +=
                                        c * ((d2 - d1 / r) * e[a] * e[b] + (a == b ? d1 / r : 0.0));
                        }
                /* the largest eigenvalue of the symmetric K (power iteration) */
                double v[3] = {1.0, 0.7, dim == 3 ? 0.4 : 0.0}, lam = 0;
                for (int it = 0; it < 200; it++) {
                    double w[3] = {0, 0, 0}, nn = 0;
                    for (int a = 0; a < dim; a++)
                        for (int b = 0; b < dim; b++) w[a] += K[3 * a + b] * v[b];
                    for (int a = 0; a < dim; a++) nn += w[a] * w[a];
                    nn = sqrt(nn);
                    if (nn == 0) break;
                    for (int a = 0; a < dim; a++) v[a] = w[a] / nn;
                    lam = nn;
                }
                if (lam > lmax) lmax = lam;
            }
    return lmax;
}

double lub_mph_layer_quadrature(int dim)
{
    /* l0 = 1, the layers n = +-k (k = 1, 2, 3: the layer n = 0 has e_n = 0), t the distance
     * within a layer from the foot of the normal: 2-D int dt over the line, 3-D int 2 pi t dt
     * over the plane with e_t^2 averaged over the azimuth (1/2).  Midpoint rule: w_v' is
     * continuous and vanishes at h_v, so 2e4 points per layer give 1e-8. */
    const double h = LUB_MPH_HV;
    const int nq = 20000;
    double s = 0;
    for (int k = 1; k < h; k++) {
        const double tmax = sqrt(h * h - (double)(k * k)), dt = tmax / nq;
        for (int q = 0; q < nq; q++) {
            const double t = (q + 0.5) * dt, r2 = t * t + (double)(k * k), r = sqrt(r2);
            const double f = -lub_mph_dw(dim, 1.0, h, r) * r * t * t * (double)(k * k) / (r2 * r2);
            s += 2.0 * (dim == 2 ? 2.0 * f : M_PI * t * f) * dt; /* 2: the layers +-k */
        }
    }
    return (dim + 2) * s;
}

/* ---- the corrected divergence ----------------------------------------------------------- */

/* (K-7a)'s s_i = sum_j u_ij.g_ij, g_ij = e_ij w_p'(r_ij), is of zeroth order: for a linear
 * field u_ij = G r_ij it gives sum_ab G_ab M_ba, M_i = sum_j g_ij r_ij^T (symmetric), which
 * is -tr G only where M_i = -I.  On the lattice interior M = -0.998 I (2-D), but on rows of
 * particles shifted against each other, as a shear flow leaves them, M_i is not isotropic
 * and a shear (tr G = 0) gets s != 0: lambda s^2 dissipates where the continuum's bulk
 * viscosity does nothing.  With lambda >> mu (a squeeze film's 1e5 mu) the sheared packing
 * locks: plane Poiseuille flow on the lattice at lambda = 1e4 Pa s, mu 0.1 Pa s stalls at
 * 5-10% of its flux for tens of ms at a time (doc/methods.md §8, Accuracy).
 *
 * divergence: corrected takes s_i = sum_j u_ij.B_i g_ij, B_i = -M_i^-1 (symmetric), which is
 * -div u exactly for every linear field on any arrangement.  The bulk dissipation (lambda/2)
 * sum_i s_i^2 dV is still a quadratic form, positive semi-definite (energy only decreases);
 * sum_a ds_i/du_a = 0 (differences u_j - u_i: momentum kept); and s_i of a rigid rotation
 * u = W x (W antisymmetric) is -tr W = 0 (angular momentum kept).  The force on a is
 * -lambda dV sum_i s_i ds_i/du_a = dV sum_j lambda (s_a B_a + s_j B_j) g_aj, antisymmetric in
 * a, j.  Where M_i is too deficient to invert (a particle with neighbours on a line or none:
 * its smallest eigenvalue of -M below CORR_MIN of the lattice's), B_i = I, the plain sum,
 * which keeps all three properties too (g_ij parallel to r_ij). */
#define CORR_MIN 0.2

/* gradient: corrected (issue 29; doc/methods.md §8, the internal friction).  Kappa's pair
 * force (P_i + P_j) g_ij of (K-6) is central, and its virial on particle i, sum_j (P_i +
 * P_j) g_ij r_ij^T, is P M_i for a uniform P: on a packing that a shear keeps disordered and
 * anisotropic (M_i,xy != 0, the fabric) it carries a shear stress P M_xy, an internal
 * friction of about 0.015 (the jittered channel: M_xy/m0 = 0.01-0.015, and kappa's pair
 * virial 57% of the shear stress in the half of the channel at 138 Pa).  The corrected
 * force renormalises the kernel gradient per particle, as B_i does for the divergence:
 *
 *     f_ij = (P_i Bg_i + P_j Bg_j) g_ij            fluid i, j
 *     f_ij = (P_i + P_j) g_ij                      i or j a wall or dummy particle
 *     Bg_i = -(I + M^W_i) (M^F_i)^-1               M^F, M^W: M_i over i's fluid, and its
 *                                                  wall and dummy neighbours
 *
 * so that Bg_i M^F_i + M^W_i = -I: each fluid particle's own pressure has the isotropic
 * virial -P_i I over all its pairs (in the bulk M^W = 0, Bg = B of the divergence).  The
 * wall pairs stay central: with Bg = -M_i^-1 on them too (the fluid's fabric rotating its
 * wall pairs) flat walls push a sheared film along (the jittered channel at a mean 95 Pa:
 * +0.011 N/m over both walls, a tenth of their shear load; the flux rose 9% from 13 to 182
 * Pa); with that B on the fluid pairs and the wall pairs central, the near-wall rows keep
 * part of the friction (-6.6%).
 * Momentum: f_ji = -f_ij.  Angular momentum: the torque of i's pairs is the antisymmetric
 * part of Bg_i M^F_i + M^W_i = -I, none; a wall's pairs are central (fluid and rigid bodies
 * together keep it exactly, as with the plain force).  Energy: the force is no longer the
 * gradient of (K-3)'s potential (the elastic energy changes at sum_i P_i s_i dV, the force's
 * power is -sum_i P_i s^g_i dV with the corrected s^g): not conserved (it grows where little
 * dissipation damps the particles: methods.md §8).  Where M^F_i is too deficient to invert
 * (CORR_MIN), Bg_i = I.
 *
 * Lambda's pair force is the gradient of the dissipation (lambda/2) sum_i s_i^2 dV, so it is
 * renormalised through the divergence: with gradient: corrected s_i = sum_j u_ij.B_ij g_ij,
 * B_ij = Bg_i between fluid particles, I on wall pairs and for the wall particles' own sums
 * (pair_b).  Then s_i = -div u exactly for linear fields (Bg_i M^F_i + M^W_i = -I), a rigid
 * rotation has none, the force lambda (s_i B_ij + s_j B_ji) g_ij has kappa's structure, and
 * the dissipation stays a positive semi-definite quadratic form: the system SPD, the energy
 * decreasing through it.  This replaces divergence: corrected's B_i on every pair. */

/* m0: -M = m0 I on the lattice interior, m0 = sum_j r_j (-w_p'(r_j)) / d (l0 = 1). */
static double lattice_m(int dim)
{
    const double h = LUB_MPH_HP;
    const int k = (int)ceil(h), kz = dim == 3 ? k : 0;
    double s = 0;
    for (int a = -k; a <= k; a++)
        for (int b = -k; b <= k; b++)
            for (int c = -kz; c <= kz; c++) {
                const double r = sqrt((double)(a * a + b * b + c * c));
                if (r > 0 && r < h) s -= r * lub_mph_dw(dim, 1.0, h, r);
            }
    return s / dim;
}

/* B = -M^-1 for the symmetric M (row-major 3 x 3, dim x dim used), or I where the smallest
 * eigenvalue of -M is below CORR_MIN m0. */
static int correction(int dim, const double M[9], double m0, double B[9])
{
    double A[9]; /* -M */
    for (int k = 0; k < 9; k++) A[k] = -M[k], B[k] = 0.0;
    double lmin;
    if (dim == 2) {
        const double t = 0.5 * (A[0] + A[4]), d = 0.5 * (A[0] - A[4]);
        lmin = t - sqrt(d * d + A[1] * A[1]);
    } else { /* the symmetric 3 x 3 eigenvalues by the trigonometric formula */
        const double p1 = A[1] * A[1] + A[2] * A[2] + A[5] * A[5];
        const double q = (A[0] + A[4] + A[8]) / 3.0;
        const double p2 =
            (A[0] - q) * (A[0] - q) + (A[4] - q) * (A[4] - q) + (A[8] - q) * (A[8] - q) + 2.0 * p1;
        const double p = sqrt(p2 / 6.0);
        if (p == 0) {
            lmin = q;
        } else {
            double C[9];
            for (int k = 0; k < 9; k++) C[k] = (A[k] - (k % 4 == 0 ? q : 0.0)) / p;
            const double det = C[0] * (C[4] * C[8] - C[5] * C[7]) -
                               C[1] * (C[3] * C[8] - C[5] * C[6]) +
                               C[2] * (C[3] * C[7] - C[4] * C[6]);
            const double r = fmax(-1.0, fmin(1.0, det / 2.0));
            lmin = q + 2.0 * p * cos(acos(r) / 3.0 + 2.0 * M_PI / 3.0);
        }
    }
    if (!(lmin > CORR_MIN * m0)) {
        B[0] = B[4] = B[8] = 1.0;
        return 0;
    }
    if (dim == 2) {
        const double det = A[0] * A[4] - A[1] * A[3];
        B[0] = A[4] / det, B[4] = A[0] / det;
        B[1] = -A[1] / det, B[3] = -A[3] / det;
        B[8] = 1.0;
        return 1;
    }
    const double c0 = A[4] * A[8] - A[5] * A[7], c1 = A[5] * A[6] - A[3] * A[8],
                 c2 = A[3] * A[7] - A[4] * A[6];
    const double det = A[0] * c0 + A[1] * c1 + A[2] * c2;
    B[0] = c0 / det, B[1] = (A[2] * A[7] - A[1] * A[8]) / det,
    B[2] = (A[1] * A[5] - A[2] * A[4]) / det;
    B[3] = c1 / det, B[4] = (A[0] * A[8] - A[2] * A[6]) / det,
    B[5] = (A[2] * A[3] - A[0] * A[5]) / det;
    B[6] = c2 / det, B[7] = (A[1] * A[6] - A[0] * A[7]) / det,
    B[8] = (A[0] * A[4] - A[1] * A[3]) / det;
    return 1;
}

/* Bg = -(I + MW) MF^-1 (gradient: corrected, above), or I where MF is deficient */
static void correction_gradient(int dim, const double MF[9], const double MW[9], double m0,
                                double Bg[9])
{
    double Bf[9];
    const int ok = correction(dim, MF, m0, Bf);
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            double v = 0;
            for (int c = 0; c < 3; c++) v += ((a == c ? 1.0 : 0.0) + MW[3 * a + c]) * Bf[3 * c + b];
            Bg[3 * a + b] = ok ? v : (a == b ? 1.0 : 0.0);
        }
}

/* out = B_i v (v itself with the plain sum) */
static inline void bmul(const double *B, size_t i, const double v[3], double out[3])
{
    if (!B) {
        for (int d = 0; d < 3; d++) out[d] = v[d];
        return;
    }
    const double *b = B + 9 * i;
    for (int d = 0; d < 3; d++)
        out[d] = b[3 * d] * v[0] + b[3 * d + 1] * v[1] + b[3 * d + 2] * v[2];
}

/* ---- the formulation's state ------------------------------------------------------------ */

typedef struct {
    size_t cap;        /* particles the arrays hold (lub_mps.cap) */
    double hp, hv;     /* kernel radii [m] */
    double hs;         /* shifting: the potential's radius [m] */
    double shift_lmax; /* shifting: lub_mph_shifting_stiffness */
    double n0;
    double vscale;     /* the viscous coefficient over the continuum's 2 (d+2) (viscous_layers) */
    double *pk;        /* P^kap_i */
    double *s;         /* s_i = sum_j u_ij.g_ij */
    double *G[3];      /* sum_j g_ij */
    double *rhs, *sol; /* d cap */
    int *pos;          /* cap: the column block of a particle in the row being assembled, -1 */
    int *blkp;         /* the particles of the column blocks of that row */
    double *blk;       /* their d x d blocks */
    size_t blk_cap;    /* blocks they hold (grown with the lists, rarely after the first steps) */
    size_t nfar;       /* bulk pairs (a, b) beyond the lists (none expected; counted) */
    double *pload;     /* the particle field pLoad (wall particles; see wall_load) */
    double *pkout;     /* the particle field pKappa: P^kap_i, kappa's part of P */
    double *B;         /* divergence: corrected: B_i (3 x 3 per particle, row-major), NULL
                          with the plain sum (B_i = I; see correction) */
    double *Bg;        /* gradient: corrected: Bg_i of the fluid particles (3 x 3, row-major,
                          not symmetric), NULL with the plain pair force */
    double *Gd[3];     /* gradient: corrected: sum_j B_ij g_ij (B_ij = Bg_i between fluid
                          particles, else I): -ds_i/du_i of the bulk viscosity's divergence */
    double m0;         /* the lattice interior's -M = m0 I (correction) */
} mph_state;

/* out = B_ij v, the renormalisation of pair (i, j) on particle i's side in the bulk
 * viscosity's divergence s_i = sum_j u_ij.B_ij g_ij: Bg_i between fluid particles with
 * gradient: corrected (I on a wall pair, and for a wall particle's own sum), B_i with
 * divergence: corrected, else I */
static inline void pair_b(const lub_mps *m, const mph_state *S, size_t i, size_t j,
                          const double v[3], double out[3])
{
    if (S->Bg)
        bmul(m->P->kind[i] == LUB_FLUID && m->P->kind[j] == LUB_FLUID ? S->Bg : NULL, i, v, out);
    else
        bmul(S->B, i, v, out);
}

/* out = sum_j B_ij g_ij = -ds_i/du_i */
static inline void diag_b(const mph_state *S, size_t i, double out[3])
{
    if (S->Bg) {
        for (int d = 0; d < 3; d++) out[d] = S->Gd[d][i];
        return;
    }
    const double G[3] = {S->G[0][i], S->G[1][i], S->G[2][i]};
    bmul(S->B, i, G, out);
}

static void state_free(void *p)
{
    mph_state *S = p;
    if (!S) return;
    free(S->pk);
    free(S->s);
    for (int d = 0; d < 3; d++) free(S->G[d]);
    free(S->rhs);
    free(S->sol);
    free(S->pos);
    free(S->blkp);
    free(S->blk);
    free(S->B);
    free(S->Bg);
    for (int d = 0; d < 3; d++) free(S->Gd[d]);
    free(S);
}

/* The state, allocated at the first step for the solver's capacity (lub_mps_init). */
static mph_state *state(lub_mps *m)
{
    if (m->fstate) return m->fstate;
    mph_state *S = lub_calloc(1, sizeof *S);
    const size_t n = m->cap ? m->cap : 1;
    S->cap = n;
    S->hp = LUB_MPH_HP * m->l0;
    S->hv = LUB_MPH_HV * m->l0;
    S->hs = lub_mph_shifting_radius(m->dim) * m->l0;
    S->shift_lmax = m->c.mph_shifting > 0 ? lub_mph_shifting_stiffness(m->dim) : 1.0;
    S->n0 = lub_mph_n0(m->dim, m->l0);
    S->vscale = m->c.viscous_layers ? 1.0 / lub_mph_layer_quadrature(m->dim) : 1.0;
    S->pk = lub_calloc(n, sizeof(double));
    S->s = lub_calloc(n, sizeof(double));
    for (int d = 0; d < 3; d++) S->G[d] = lub_calloc(n, sizeof(double));
    S->rhs = lub_calloc(3 * n, sizeof(double));
    S->sol = lub_calloc(3 * n, sizeof(double));
    S->pos = lub_malloc(n * sizeof(int));
    for (size_t i = 0; i < n; i++) S->pos[i] = -1;
    S->pload = lub_particles_extra(m->P, "pLoad");
    S->pkout = lub_particles_extra(m->P, "pKappa");
    if (m->c.divergence_corrected || m->c.gradient_corrected) S->m0 = lattice_m(m->dim);
    /* gradient: corrected renormalises lambda's pair force and its divergence with Bg too
     * (the wall pairs central), in place of divergence: corrected's B on every pair */
    if (m->c.divergence_corrected && !m->c.gradient_corrected)
        S->B = lub_calloc(9 * n, sizeof(double));
    if (m->c.gradient_corrected) {
        S->Bg = lub_calloc(9 * n, sizeof(double));
        for (int d = 0; d < 3; d++) S->Gd[d] = lub_calloc(n, sizeof(double));
    }
    m->fstate = S;
    m->fstate_free = state_free;
    if (m->c.list_l0 < LUB_MPH_HV)
        lub_bug("mph: the neighbour lists reach %g l0, the viscosity kernel %g l0", m->c.list_l0,
                LUB_MPH_HV);
    return S;
}

/* ---- the step's parts ------------------------------------------------------------------- */

/* Lists of every particle (walls and dummies carry n_i and P_i too), at the current
 * positions; rebuild: from scratch, else updated while the skin allows. */
static void neighbours(lub_mps *m, int rebuild)
{
    lub_particles *P = m->P;
    double *x[3] = {P->x[0], P->x[1], P->x[2]};
    lub_timer_start(&m->tm, LUB_T_NEIGHBOUR);
    m->nb.list_kind = NULL;
    if (!rebuild && lub_neighbours_update(&m->nb, x) != 0) rebuild = 1;
    if (rebuild) {
        lub_neighbours_build(&m->nb, P->n, x);
        m->st.nrebuild++;
    }
    lub_timer_stop(&m->tm, LUB_T_NEIGHBOUR);
}

static double pair_r(const lub_neighbours *nb, size_t q, int dim, double e[3])
{
    double r2 = 0;
    for (int d = 0; d < dim; d++) r2 += nb->dx[d][q] * nb->dx[d][q];
    const double r = sqrt(r2);
    for (int d = 0; d < 3; d++) e[d] = d < dim && r > 0 ? nb->dx[d][q] / r : 0.0;
    return r;
}

/* n_i, G_i = sum_j g_ij and P^kap_i = kappa max(n_i - n0, 0) of every particle (step 3). */
static void density(lub_mps *m, mph_state *S)
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const int dim = m->dim;
    const double kappa = m->c.bulk_modulus, l0 = m->l0;
#pragma omp parallel for schedule(static) if (P->n >= LUB_LINALG_OMP_MIN)
    for (size_t i = 0; i < P->n; i++) {
        /* M_i = sum_j g_ij r_ij^T: MF over the fluid neighbours, MW over the rest */
        double n = 0, G[3] = {0, 0, 0}, GW[3] = {0, 0, 0}, MF[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0},
               MW[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
        const int wantm = S->B || (S->Bg && P->kind[i] == LUB_FLUID);
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            double e[3];
            const double r = pair_r(nb, q, dim, e);
            if (!(r < S->hp) || r == 0) continue;
            n += lub_mph_w(dim, l0, S->hp, r);
            const double dw = lub_mph_dw(dim, l0, S->hp, r);
            for (int d = 0; d < dim; d++) G[d] += e[d] * dw;
            if (!wantm) continue;
            const int fl = P->kind[nb->j[q]] == LUB_FLUID;
            double *M = fl ? MF : MW;
            for (int d = 0; !fl && d < dim; d++) GW[d] += e[d] * dw;
            for (int a = 0; a < dim; a++)
                for (int b = 0; b < dim; b++) M[3 * a + b] += e[a] * e[b] * dw * r;
        }
        m->pnd[i] = n;
        for (int d = 0; d < 3; d++) S->G[d][i] = G[d];
        if (S->B) {
            double M[9];
            for (int k = 0; k < 9; k++) M[k] = MF[k] + MW[k];
            correction(dim, M, S->m0, S->B + 9 * i);
        }
        if (S->Bg && P->kind[i] == LUB_FLUID) {
            correction_gradient(dim, MF, MW, S->m0, S->Bg + 9 * i);
            double GF[3], Gb[3];
            for (int d = 0; d < 3; d++) GF[d] = G[d] - GW[d];
            bmul(S->Bg, i, GF, Gb);
            for (int d = 0; d < 3; d++) S->Gd[d][i] = Gb[d] + GW[d];
        } else if (S->Bg) {
            for (int d = 0; d < 3; d++) S->Gd[d][i] = G[d];
        }
        S->pk[i] = kappa * fmax(n - S->n0, 0.0);
    }
}

/* s_i = sum_j u_ij.g_ij of every particle, at the current velocities. */
static void divergence(lub_mps *m, mph_state *S, double *s)
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const int dim = m->dim;
#pragma omp parallel for schedule(static) if (P->n >= LUB_LINALG_OMP_MIN)
    for (size_t i = 0; i < P->n; i++) {
        double T[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}; /* sum_j u_ij g_ij^T */
        double v = 0;                              /* sum_j u_ij.B_ij g_ij (pair_b), Bg */
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            double e[3];
            const double r = pair_r(nb, q, dim, e);
            if (!(r < S->hp) || r == 0) continue;
            const size_t j = nb->j[q];
            const double dw = lub_mph_dw(dim, m->l0, S->hp, r);
            if (S->Bg) {
                double g[3], bg[3];
                for (int d = 0; d < 3; d++) g[d] = e[d] * dw;
                pair_b(m, S, i, j, g, bg);
                for (int a = 0; a < dim; a++) v += (P->u[a][j] - P->u[a][i]) * bg[a];
                continue;
            }
            for (int a = 0; a < dim; a++)
                for (int b = 0; b < dim; b++) T[3 * a + b] += (P->u[a][j] - P->u[a][i]) * e[b] * dw;
        }
        /* plain, divergence: corrected: sum_j u_ij.B_i g_ij = sum_ab T_ab B_ab (B symmetric) */
        for (int a = 0; !S->Bg && a < dim; a++) {
            if (!S->B) v += T[4 * a];
            for (int b = 0; S->B && b < dim; b++) v += T[3 * a + b] * S->B[9 * i + 3 * a + b];
        }
        s[i] = v;
    }
}

/* Kappa's pair force per dV on particle i from its neighbour j (e = e_ij, dw = w_p'(r_ij)):
 * (P^kap_i + P^kap_j) g_ij, or with gradient: corrected (P^kap_i Bg_i + P^kap_j Bg_j) g_ij
 * between fluid particles (the wall pairs central; see correction_gradient). */
static inline void pair_elastic(const lub_mps *m, const mph_state *S, size_t i, size_t j,
                                const double e[3], double dw, double f[3])
{
    if (!S->Bg || m->P->kind[i] != LUB_FLUID || m->P->kind[j] != LUB_FLUID) {
        const double c = (S->pk[i] + S->pk[j]) * dw; /* (K-6)'s order of operations */
        for (int d = 0; d < 3; d++) f[d] = c * e[d];
        return;
    }
    double g[3];
    for (int d = 0; d < 3; d++) g[d] = e[d] * dw;
    double bi[3], bj[3];
    bmul(S->Bg, i, g, bi);
    bmul(S->Bg, j, g, bj);
    for (int d = 0; d < 3; d++) f[d] = S->pk[i] * bi[d] + S->pk[j] * bj[d];
}

/* The pressure pair force per dV on particle i from its neighbour j (e = e_ij, dw =
 * w_p'(r_ij)), as the step gave it: (P_i + P_j) g_ij with the plain sum and the plain
 * gradient; kappa's part as pair_elastic, lambda's lambda (s_i B_i + s_j B_j) g_ij with
 * divergence: corrected (s, P at u^{k+1}). */
static void pair_pressure(const lub_mps *m, const mph_state *S, size_t i, size_t j,
                          const double e[3], double dw, double f[3])
{
    const lub_particles *P = m->P;
    double g[3];
    for (int d = 0; d < 3; d++) g[d] = e[d] * dw;
    if (!S->B && !S->Bg) {
        for (int d = 0; d < 3; d++) f[d] = (P->p[i] + P->p[j]) * g[d];
        return;
    }
    double bi[3], bj[3];
    pair_b(m, S, i, j, g, bi);
    pair_b(m, S, j, i, g, bj);
    const double lam = m->c.bulk_viscosity;
    if (!S->Bg) { /* divergence: corrected alone, in its own order of operations */
        for (int d = 0; d < 3; d++)
            f[d] = (S->pk[i] + S->pk[j]) * g[d] + lam * (S->s[i] * bi[d] + S->s[j] * bj[d]);
        return;
    }
    double fk[3];
    pair_elastic(m, S, i, j, e, dw, fk);
    for (int d = 0; d < 3; d++) f[d] = fk[d] + lam * (S->s[i] * bi[d] + S->s[j] * bj[d]);
}

/* Step 5: assemble the SPD system of the fluid velocities (see the top of the file) into
 * m->A and S->rhs, u* in m->us.  Serial: the bulk term scatters into the blocks of a row
 * through S->pos. */
static int assemble(lub_mps *m, mph_state *S, double dt)
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const int dim = m->dim, dd = dim * dim;
    const double rho = m->c.rho, mu = m->c.rho * m->c.nu, lam = m->c.bulk_viscosity;
    const double l0 = m->l0;
    int nf = 0;
    for (size_t i = 0; i < P->n; i++) {
        m->row[i] = P->kind[i] == LUB_FLUID ? nf : -1;
        if (P->kind[i] == LUB_FLUID) m->prow[nf++] = (int)i;
    }
    /* pass 1: a fluid particle's rows hold the blocks of itself and of its fluid neighbours */
    lub_csr_begin(&m->A, dim * nf);
    size_t most = 0;
    for (int r = 0; r < nf; r++) {
        const size_t i = (size_t)m->prow[r];
        size_t k = 1;
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) k += P->kind[nb->j[q]] == LUB_FLUID;
        if (k > most) most = k;
        for (int c = 0; c < dim; c++) lub_csr_set_row_length(&m->A, dim * r + c, dim * (int)k);
    }
    lub_csr_alloc(&m->A);
    if (most > S->blk_cap) {
        free(S->blkp);
        free(S->blk);
        S->blk_cap = most + most / 4;
        S->blkp = lub_malloc(S->blk_cap * sizeof *S->blkp);
        S->blk = lub_malloc(S->blk_cap * 9 * sizeof *S->blk);
    }
    const double visc = -2.0 * mu * (dim + 2) * S->vscale;
    for (int r = 0; r < nf; r++) {
        const size_t a = (size_t)m->prow[r];
        int nk = 0;
        S->pos[a] = nk, S->blkp[nk++] = (int)a;
        for (size_t q = nb->start[a]; q < nb->end[a]; q++) {
            const size_t j = nb->j[q];
            if (P->kind[j] == LUB_FLUID) S->pos[j] = nk, S->blkp[nk++] = (int)j;
        }
        memset(S->blk, 0, (size_t)nk * 9 * sizeof *S->blk);
        double *B0 = S->blk, rhs[3];
        for (int c = 0; c < dim; c++) {
            B0[c * dim + c] = rho / dt;
            rhs[c] = rho / dt * m->us[c][a];
        }
        /* viscous term c_aj e e^T (u_a - u_j), and the elastic pair forces
         * (P^kap_a + P^kap_j) g_aj, explicit */
        for (size_t q = nb->start[a]; q < nb->end[a]; q++) {
            double e[3];
            const double rr = pair_r(nb, q, dim, e);
            if (!(rr < S->hv) || rr == 0) continue;
            const size_t j = nb->j[q];
            const double cv = visc * lub_mph_dw(dim, l0, S->hv, rr) / rr;
            double *Bj = P->kind[j] == LUB_FLUID ? S->blk + (size_t)S->pos[j] * dd : NULL;
            for (int c = 0; c < dim; c++)
                for (int c2 = 0; c2 < dim; c2++) {
                    const double v = cv * e[c] * e[c2];
                    B0[c * dim + c2] += v;
                    if (Bj)
                        Bj[c * dim + c2] -= v;
                    else
                        rhs[c] += v * P->u[c2][j];
                }
            if (rr < S->hp) {
                double f[3];
                pair_elastic(m, S, a, j, e, lub_mph_dw(dim, l0, S->hp, rr), f);
                for (int c = 0; c < dim; c++) rhs[c] += f[c];
            }
        }
        /* bulk viscosity: lambda sum_i D_ia D_ib^T over i = a and the particles within h_p */
        if (lam > 0) {
            for (size_t qa = nb->start[a]; qa <= nb->end[a]; qa++) {
                size_t i;
                double Dia[3] = {0, 0, 0};
                double v[3] = {0, 0, 0};
                if (qa == nb->end[a]) { /* i = a: D_aa = -sum_j B_aj g_aj */
                    i = a;
                    diag_b(S, a, v);
                    for (int c = 0; c < dim; c++) v[c] = -v[c];
                } else {
                    double e[3];
                    const double rr = pair_r(nb, qa, dim, e);
                    if (!(rr < S->hp) || rr == 0) continue;
                    i = nb->j[qa];
                    /* D_ia = B_ia g_ia, g_ia = e_ia w'(r), e_ia = -e_ai */
                    const double dw = lub_mph_dw(dim, l0, S->hp, rr);
                    for (int c = 0; c < dim; c++) v[c] = -e[c] * dw;
                }
                if (i == a)
                    for (int c = 0; c < 3; c++) Dia[c] = v[c];
                else
                    pair_b(m, S, i, a, v, Dia);
                for (size_t qi = nb->start[i]; qi <= nb->end[i]; qi++) {
                    size_t b;
                    double Dib[3], v2[3] = {0, 0, 0};
                    if (qi == nb->end[i]) {
                        b = i;
                        diag_b(S, i, v2);
                        for (int c = 0; c < dim; c++) v2[c] = -v2[c];
                    } else {
                        double e[3];
                        const double rr = pair_r(nb, qi, dim, e);
                        if (!(rr < S->hp) || rr == 0) continue;
                        b = nb->j[qi];
                        const double dw = lub_mph_dw(dim, l0, S->hp, rr);
                        for (int c = 0; c < dim; c++) v2[c] = e[c] * dw;
                    }
                    if (b == i)
                        for (int c = 0; c < 3; c++) Dib[c] = v2[c];
                    else
                        pair_b(m, S, i, b, v2, Dib);
                    if (P->kind[b] == LUB_FLUID) {
                        if (S->pos[b] < 0) { /* beyond the lists: cannot be (2 h_p = h_v) */
                            S->nfar++;
                            continue;
                        }
                        double *Bb = S->blk + (size_t)S->pos[b] * dd;
                        for (int c = 0; c < dim; c++)
                            for (int c2 = 0; c2 < dim; c2++)
                                Bb[c * dim + c2] += lam * Dia[c] * Dib[c2];
                    } else {
                        double du = 0;
                        for (int c = 0; c < dim; c++) du += Dib[c] * P->u[c][b];
                        for (int c = 0; c < dim; c++) rhs[c] -= lam * Dia[c] * du;
                    }
                }
            }
        }
        for (int c = 0; c < dim; c++) {
            const int row = dim * r + c;
            int *col = lub_csr_row_col(&m->A, row);
            double *val = lub_csr_row_val(&m->A, row);
            int e = 0;
            for (int k = 0; k < nk; k++) {
                const int cb = dim * m->row[S->blkp[k]];
                for (int c2 = 0; c2 < dim; c2++) {
                    col[e] = cb + c2;
                    val[e++] = S->blk[(size_t)k * dd + c * dim + c2];
                }
            }
            S->rhs[row] = rhs[c];
            S->sol[row] = P->u[c][a]; /* initial guess: u^k */
        }
        for (int k = 0; k < nk; k++) S->pos[S->blkp[k]] = -1;
    }
    lub_csr_finish(&m->A);
    return nf;
}

/* pLoad of the wall particles (kind wall): the wall-normal load per unit wall area of the
 * pressure pair forces the fluid exerts on each, -n_i.sum_j (P_i + P_j) g_ij dV / l0^(d-1)
 * over its fluid neighbours j (the force on i of the pair term of (K-6)), n_i the unit
 * normal into the fluid, from the centroid of its wall and dummy neighbours within h_v to
 * x_i.  Summed over a patch's wall particles (times l0^(d-1)) it is the load on the patch
 * (the dummies' pairs with the fluid left out: none while the fluid keeps 1.75 l0 from
 * them).  P_i of (K-7a) itself sees the fluid's compression on one side only and comes out
 * near half the fluid's pressure at the wall (doc/methods.md §8). */
static void wall_load(lub_mps *m, mph_state *S)
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const int dim = m->dim;
    const double dV = dim == 2 ? m->l0 * m->l0 : m->l0 * m->l0 * m->l0;
    const double area = dim == 2 ? m->l0 : m->l0 * m->l0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_WALL) {
            S->pload[i] = 0.0;
            continue;
        }
        double F[3] = {0, 0, 0}, c[3] = {0, 0, 0};
        int nc = 0;
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            double e[3];
            const double r = pair_r(nb, q, dim, e);
            if (!(r < S->hv) || r == 0) continue;
            const size_t j = nb->j[q];
            if (P->kind[j] != LUB_FLUID) {
                for (int d = 0; d < dim; d++) c[d] += nb->dx[d][q];
                nc++;
            } else if (r < S->hp) {
                double f[3];
                pair_pressure(m, S, i, j, e, lub_mph_dw(dim, m->l0, S->hp, r), f);
                for (int d = 0; d < dim; d++) F[d] += f[d] * dV;
            }
        }
        double nn = 0, fn = 0;
        for (int d = 0; d < dim; d++) nn += c[d] * c[d];
        nn = sqrt(nn);
        if (nc && nn > 0)
            for (int d = 0; d < dim; d++) fn += F[d] * -c[d] / nn;
        S->pload[i] = -fn / area;
    }
}

/* shifting (doc/methods.md §8, "Particle shifting"): each fluid particle without pressure
 * or in tension (P_i <= 0: a compression's pair forces hold the arrangement themselves,
 * and shifting a compressed film lowers its pressure) with a full neighbourhood (n_i >=
 * SHIFT_NMIN n0: not at a free surface, where the shift would push it out) moves by
 * c sum_j phi'(r_ij) e_ij, -c times the gradient of the potential sum_pairs phi(r),
 * phi = (1 - r/h_s)^3, over every neighbour within h_s (walls and dummies too), c = beta
 * l0^2/lambda_max: one step of gradient descent on a potential whose Hessian on the
 * lattice is positive semi-definite, relaxing its stiffest mode by beta.  The zone-edge
 * modes, which a sustained tension drives and which leave every n_i and s_i unchanged
 * (methods.md §5.5), are among the stiffest.  The shifts are computed from the positions
 * of the step, then applied; velocities stay (momentum exact). */
#define SHIFT_NMIN 0.95
static void shift(lub_mps *m, mph_state *S)
{
    lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const int dim = m->dim;
    const double h = S->hs, c = m->c.mph_shifting * m->l0 * m->l0 / S->shift_lmax;
    double *dx = S->rhs; /* 3 cap, free after the solve */
    for (size_t i = 0; i < P->n; i++) {
        double d[3] = {0, 0, 0};
        if (P->kind[i] == LUB_FLUID && P->p[i] <= 0 && m->pnd[i] >= SHIFT_NMIN * S->n0)
            for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                double e[3];
                const double r = pair_r(nb, q, dim, e);
                if (!(r < h) || r == 0) continue;
                const double u = 1.0 - r / h, d1 = -3.0 * u * u / h;
                for (int k = 0; k < dim; k++) d[k] += c * d1 * e[k];
            }
        for (int k = 0; k < 3; k++) dx[3 * i + k] = d[k];
    }
    for (size_t i = 0; i < P->n; i++)
        for (int k = 0; k < dim; k++) P->x[k][i] += dx[3 * i + k];
}

/* Wrap periodic coordinates into [lo, hi). */
static void wrap(lub_mps *m)
{
    lub_particles *P = m->P;
    for (int d = 0; d < m->dim; d++) {
        if (!m->periodic[d]) continue;
        const double lo = m->lo[d], L = m->hi[d] - m->lo[d];
        double *x = P->x[d];
        for (size_t i = 0; i < P->n; i++)
            if (x[i] < lo || x[i] >= lo + L) {
                x[i] = lo + fmod(x[i] - lo, L);
                if (x[i] < lo) x[i] += L;
                if (x[i] >= lo + L) x[i] -= L;
            }
    }
}

lub_step_status lub_mph_step(lub_mps *m, double dt, long *bad, char *msg, size_t msgsize)
{
    lub_particles *P = m->P;
    const size_t n = P->n;
    const int dim = m->dim;
    *bad = -1;
    msg[0] = '\0';
    memset(&m->st, 0, sizeof m->st);
    if (n > m->cap) lub_bug("mph: %zu particles, the solver holds %zu", n, m->cap);
    mph_state *S = state(m);

    /* 1. x^{k+1} = x^k + dt u^k; walls and dummies move with their patch velocity (unless a
     * model set it: patch_moved) */
    lub_timer_start(&m->tm, LUB_T_OTHER);
    for (size_t i = 0; i < n; i++)
        if (P->kind[i] != LUB_FLUID && !m->c.patch_moved[P->patch[i]])
            for (int d = 0; d < dim; d++) P->u[d][i] = m->c.patch_velocity[P->patch[i]][d];
    for (int d = 0; d < dim; d++)
        for (size_t i = 0; i < n; i++) P->x[d][i] += dt * P->u[d][i];
    lub_timer_stop(&m->tm, LUB_T_OTHER);

    /* 2. neighbours at x^{k+1}, built afresh (an update keeps only the pairs within re),
     * the particles sorted first every reorderInterval steps (the global step: a restart
     * sorts at the same steps); 3. n_i, P^kap */
    if (m->c.reorder_interval > 0 && m->steps % m->c.reorder_interval == 0) {
        lub_timer_start(&m->tm, LUB_T_NEIGHBOUR);
        lub_mps_reorder(m);
        lub_timer_stop(&m->tm, LUB_T_NEIGHBOUR);
    }
    m->built = 1;
    neighbours(m, 1);
    lub_timer_start(&m->tm, LUB_T_ASSEMBLY);
    density(m, S);

    /* 4. u* = u^k + dt (F^s/m + g) (the configuration's and the models' body acceleration,
     * the models' per-particle forces) */
    double g[3] = {m->c.g[0], m->c.g[1], m->c.g[2]};
    if (m->hooks.forces) m->hooks.forces(m->hooks.ctx, m, dt, g);
    for (int d = 0; d < dim; d++)
        for (size_t i = 0; i < n; i++)
            m->us[d][i] = P->kind[i] == LUB_FLUID ? P->u[d][i] + dt * g[d] : P->u[d][i];
    lub_mps_particle_forces(m, dt, m->us); /* F^s / m (surface tension), explicit */

    /* 5. the velocities at k+1 */
    const int nf = assemble(m, S, dt);
    lub_timer_stop(&m->tm, LUB_T_ASSEMBLY);
    lub_timer_start(&m->tm, LUB_T_VISCOSITY);
    const double *b[1] = {S->rhs};
    double *x[1] = {S->sol};
    lub_solve_status st =
        nf > 0 ? lub_linsolver_solve(&m->vsolver, &m->A, 1, b, x, m->st.v) : LUB_SOLVE_OK;
    lub_timer_stop(&m->tm, LUB_T_VISCOSITY);
    if (st != LUB_SOLVE_OK && !m->c.v_continue) {
        char d[256];
        lub_solve_result_describe(&m->st.v[0], d, sizeof d);
        snprintf(msg, msgsize, "MPH velocity solve (%d unknowns) failed: %s", dim * nf, d);
        return LUB_STEP_SOLVE_FAILED;
    }
    for (int r = 0; r < nf; r++)
        for (int d = 0; d < dim; d++) P->u[d][m->prow[r]] = S->sol[dim * r + d];

    /* 6. P_i = P^kap_i + lambda s_i (K-7a), every particle */
    lub_timer_start(&m->tm, LUB_T_GRADIENT);
    divergence(m, S, S->s);
    for (size_t i = 0; i < n; i++) P->p[i] = S->pk[i] + m->c.bulk_viscosity * S->s[i];
    memcpy(S->pkout, S->pk, n * sizeof *S->pkout);
    wall_load(m, S);
    lub_timer_stop(&m->tm, LUB_T_GRADIENT);

    if (m->c.mph_shifting > 0) shift(m, S);

    /* the models' corrections (collision), periodic wrap, checks */
    if (m->hooks.after_correction) m->hooks.after_correction(m->hooks.ctx, m, dt);
    lub_timer_start(&m->tm, LUB_T_OTHER);
    wrap(m);
    lub_step_status s = lub_mps_check(m, dt, bad, msg, msgsize);
    m->st.umax = lub_mps_max_speed(m);
    m->st.nunknowns = (size_t)(dim * nf);
    lub_timer_stop(&m->tm, LUB_T_OTHER);
    m->iterations[1] += m->st.v[0].iterations;
    m->steps++;
    return s;
}

void lub_mph_operators(lub_mps *m, double *pnd, double *div, double *const visc[3])
{
    mph_state *S = state(m);
    const lub_particles *P = m->P;
    const int dim = m->dim;
    neighbours(m, 1);
    m->built = 0; /* the next step builds its own */
    density(m, S);
    if (pnd) memcpy(pnd, m->pnd, P->n * sizeof *pnd);
    if (div) divergence(m, S, div);
    if (!visc) return;
    const lub_neighbours *nb = &m->nb;
    for (size_t i = 0; i < P->n; i++) {
        double v[3] = {0, 0, 0};
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            double e[3];
            const double r = pair_r(nb, q, dim, e);
            if (!(r < S->hv) || r == 0) continue;
            const size_t j = nb->j[q];
            double ue = 0;
            for (int d = 0; d < dim; d++) ue += (P->u[d][j] - P->u[d][i]) * e[d];
            const double f =
                -2.0 * (dim + 2) * S->vscale * ue * lub_mph_dw(dim, m->l0, S->hv, r) / r;
            for (int d = 0; d < dim; d++) v[d] += f * e[d];
        }
        for (int d = 0; d < dim; d++) visc[d][i] = v[d];
    }
}

double lub_mph_energy(const lub_mps *m, const double g[3], double dt, double part[4])
{
    const lub_particles *P = m->P;
    const mph_state *S = m->fstate;
    const lub_neighbours *nb = &m->nb;
    const int dim = m->dim;
    const double dV = dim == 2 ? m->l0 * m->l0 : m->l0 * m->l0 * m->l0;
    const double mass = m->c.rho * dV;
    double e[4] = {0, 0, 0, 0};
    for (size_t i = 0; i < P->n; i++) {
        if (S) {
            const double dn = fmax(m->pnd[i] - S->n0, 0.0);
            e[1] += 0.5 * m->c.bulk_modulus * dn * dn * dV;
        }
        if (P->kind[i] != LUB_FLUID) continue;
        double F[3] = {mass * g[0], mass * g[1], mass * g[2]};
        if (S)
            for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                double ev[3];
                const double r = pair_r(nb, q, dim, ev);
                if (!(r < S->hp) || r == 0) continue;
                double f[3];
                pair_elastic(m, S, i, nb->j[q], ev, lub_mph_dw(dim, m->l0, S->hp, r), f);
                for (int d = 0; d < dim; d++) F[d] += f[d] * dV;
            }
        for (int d = 0; d < dim; d++) {
            e[0] += 0.5 * mass * P->u[d][i] * P->u[d][i];
            e[2] -= mass * g[d] * P->x[d][i];
            e[3] -= 0.5 * dt * P->u[d][i] * F[d];
        }
    }
    if (part)
        for (int k = 0; k < 4; k++) part[k] = e[k];
    return e[0] + e[1] + e[2] + e[3];
}

/* ---- the formulation (models/fluid.h) --------------------------------------------------- */

/* The force on the particles of a body's patch (rigidBodies; methods.md §7.2): the reaction
 * of the pair forces of (K-6) the step gave the fluid, so that fluid + body conserve
 * momentum and, the pair forces being central, angular momentum.  With P = P^kap + lambda s
 * after the step (K-7a; s at u^{k+1}), the step's elastic and bulk-viscous force on fluid
 * particle a, lambda dV sum_i s_i ds_i/du_a - C P^kap, is dV sum_j (P_a + P_j) g_aj over all
 * its neighbours j: pair terms antisymmetric in a, j (g_ja = -g_aj).  So is the viscous term
 * -c_aj e e^T (u_a - u_j) dV (backward Euler: u^{k+1} of the fluid, the velocity the step
 * gave the wall particle).  Wall particle b of the patch gets, over its fluid neighbours a,
 *
 *     f_b = dV sum_a [ (P_b + P_a) g_ba - c_ba e_ba (e_ba.(u_b - u_a)) ]  + rho dV acc_b,
 *
 * acc_b the reaction of the models' explicit pair forces (surface tension's F^s, stored on
 * the wall particles by particle_forces, models/model.h).  The pairs with the patch's own
 * and other walls' particles are left out: the former cancel over the body, the latter do
 * not act on the fluid (a body that comes within h_p of a wall needs the contact of §7.3).
 * The geometry is the step's (its lists at x^{k+1}), the velocities those before the body
 * model resets the wall's to V + omega x r.  Wall and dummy particles alike (a dummy within
 * h_v of the fluid exchanges viscous pairs).  area and omega are not used. */
static void mph_wall_forces(const lub_mps *m, int patch, double *const area[3],
                            const double omega[3], double *const f[3])
{
    (void)area, (void)omega;
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const mph_state *S = m->fstate;
    const int dim = m->dim;
    const double dV = dim == 2 ? m->l0 * m->l0 : m->l0 * m->l0 * m->l0;
    const double visc = -2.0 * m->c.rho * m->c.nu * (dim + 2) * (S ? S->vscale : 1.0);
    const double mass = m->c.rho * dV;
    for (size_t b = 0; b < P->n; b++) {
        for (int d = 0; d < 3; d++) f[d][b] = 0.0;
        if (P->kind[b] == LUB_FLUID || P->patch[b] != patch || !S) continue;
        double F[3] = {0, 0, 0};
        for (size_t q = nb->start[b]; q < nb->end[b]; q++) {
            const size_t a = nb->j[q];
            if (P->kind[a] != LUB_FLUID) continue;
            double e[3];
            const double r = pair_r(nb, q, dim, e);
            if (!(r < S->hv) || r == 0) continue;
            const double cv = visc * lub_mph_dw(dim, m->l0, S->hv, r) / r;
            double ue = 0;
            for (int d = 0; d < dim; d++) ue += (P->u[d][b] - P->u[d][a]) * e[d];
            double fp[3] = {0, 0, 0};
            if (r < S->hp) pair_pressure(m, S, b, a, e, lub_mph_dw(dim, m->l0, S->hp, r), fp);
            for (int d = 0; d < dim; d++) F[d] += fp[d] - cv * ue * e[d];
        }
        for (int d = 0; d < dim; d++)
            f[d][b] = F[d] * dV + (m->pacc[d] ? mass * m->pacc[d][b] : 0.0);
    }
}

/* The MPS pressure equation's schemes, which MPH does not solve: an entry of one would be read
 * and ignored, a silent change of the run a user did not ask for (negativePressure: clip does
 * not clip MPH's tension, a laplacian is not MPH's).  MPH takes effectiveRadius,
 * neighbourSkin, particleOrder and reorderInterval of system/schemes.yaml (its lists). */
static void mph_refuse_mps_schemes(const lub_case *cs)
{
    static const char *const mps_only[] = {"gradient",      "minPressureShift", "negativePressure",
                                           "dummyVelocity", "pressure",         "freeSurface",
                                           "lsmpsDetMin",   "laplacian",        NULL};
    char path[LUB_PATH_MAX];
    lub_dict *d = lub_dict_read(lub_case_path(cs, path, "system/schemes.yaml"));
    lub_node *r = lub_dict_root(d);
    for (int k = 0; mps_only[k]; k++) {
        lub_node *n = lub_dict_find(r, mps_only[k]);
        if (n)
            lub_node_error(n,
                           "'%s' is a scheme of the fluid 'mps' (the semi-implicit MPS pressure "
                           "equation), which the fluid 'mph' (constant/models.yaml) does not "
                           "solve: remove the entry (MPH reads effectiveRadius, neighbourSkin, "
                           "particleOrder and reorderInterval here; its own settings are "
                           "fluid: { type: mph, ... }'s, doc/methods.md §8)",
                           mps_only[k]);
    }
    lub_dict_free(d);
}

static void mph_read(lub_mps_config *c, const lub_case *cs, lub_node *models, lub_node *entry)
{
    char path[LUB_PATH_MAX];
    lub_mps_config_defaults(c);
    lub_transport_read(lub_case_path(cs, path, "constant/transportProperties.yaml"), &c->rho,
                       &c->nu);
    /* fluid: { type: mph } is there (the type was read from it) */
    c->bulk_viscosity = lub_dict_real(entry, "bulkViscosity", LUB_NONNEGATIVE);
    c->bulk_modulus = lub_dict_real(entry, "bulkModulus", LUB_POSITIVE);
    /* the viscous coefficient 2 (d+2) is the continuum's; on layers of particles l0 apart
     * (fluidLayers on a body) a shear across them gets lub_mph_layer_quadrature of it (0.96
     * in 2-D): 'layers' divides by that (methods.md §8, Accuracy) */
    static const char *const norms[] = {"continuum", "layers", NULL};
    c->viscous_layers = lub_dict_choice(entry, "viscousNormalisation", norms, 0) == 1;
    /* the bulk viscosity's divergence: Kondo's kernel sum, or renormalised so that a shear
     * on any arrangement has none (correction, methods.md §8) */
    static const char *const divs[] = {"plain", "corrected", NULL};
    c->divergence_corrected = lub_dict_choice(entry, "divergence", divs, 0) == 1;
    /* kappa's pair force: (K-6)'s central one, or with the kernel gradient renormalised so
     * that a packing's fabric carries no shear stress (correction_gradient, methods.md §8) */
    c->gradient_corrected = lub_dict_choice(entry, "gradient", divs, 0) == 1;
    /* particle shifting: beta per step, off by default (shift, methods.md §8) */
    c->mph_shifting = lub_dict_real_or(entry, "shifting", 0.0, LUB_BETWEEN(0.0, 1.0));
    lub_node *v = lub_dict_find(models, "viscosity");
    if (v)
        lub_node_error(v, "'viscosity' belongs to the fluid 'mps'; the fluid 'mph' takes its "
                          "shear viscosity mu = rho nu (constant/transportProperties.yaml) "
                          "implicitly, always: remove the entry");
    lub_node *mr = lub_dict_find(models, "multiResolution");
    if (mr)
        lub_node_error(mr, "the fluid 'mph' takes one resolution level: multiResolution couples "
                           "levels of the fluid 'mps' (semi-implicit MPS) only");
    mph_refuse_mps_schemes(cs);
    lub_mps_config_read(c, cs->root);
    /* MPH's own: lists to h_v, no pressure predictor nor clipping (the MPS pressure
     * equation is not solved); its viscosity is implicit (lubFoam's diffusion-number check
     * of implicit viscosity holds for it) */
    c->list_l0 = LUB_MPH_HV;
    c->predictor = 0.0;
    c->clip_negative = LUB_NEGATIVE_KEEP;
    c->viscosity = LUB_VISCOSITY_CN;
}

static void mph_header_level(const lub_mps *m)
{
    lub_message("MPH: l0 %g m, h_p %g m (1.75 l0), h_v %g m (3.5 l0), n0 %.10g; rho0 %g kg/m^3, "
                "mu %g Pa s, bulkViscosity lambda %g Pa s, bulkModulus kappa %g Pa",
                m->l0, LUB_MPH_HP * m->l0, LUB_MPH_HV * m->l0, lub_mph_n0(m->dim, m->l0), m->c.rho,
                m->c.rho * m->c.nu, m->c.bulk_viscosity, m->c.bulk_modulus);
    lub_message("MPH: divergence %s",
                m->c.gradient_corrected
                    ? "corrected with the gradient's Bg (the bulk viscosity's s_i = sum_j "
                      "u_ij.Bg_i g_ij between fluid particles, u_ij.g_ij on wall pairs: exact "
                      "for linear fields)"
                : m->c.divergence_corrected
                    ? "corrected (the bulk viscosity's s_i = sum_j u_ij.B_i g_ij, B_i = "
                      "-(sum_j g_ij r_ij^T)^-1: exact for linear fields, no bulk dissipation "
                      "in a shear)"
                    : "plain (Kondo's s_i = sum_j u_ij.g_ij of (K-7a))");
    lub_message("MPH: gradient %s",
                m->c.gradient_corrected
                    ? "corrected (the pair force (P_i Bg_i + P_j Bg_j) g_ij between fluid "
                      "particles, Bg_i = -(I + M^W_i)(M^F_i)^-1, central at walls: a packing's "
                      "fabric carries no shear stress; kappa's part conserves no energy "
                      "exactly)"
                    : "plain ((K-6)'s central (P_i + P_j) g_ij)");
    if (m->c.mph_shifting > 0)
        lub_message("MPH: shifting %g: the fluid particles in tension (P <= 0) with a full "
                    "neighbourhood move down the gradient of sum (1 - r/h_s)^3, h_s %g l0, the "
                    "lattice's stiffest mode by %g a step (methods.md §8: momentum kept; "
                    "angular momentum and energy not exactly)",
                    m->c.mph_shifting, lub_mph_shifting_radius(m->dim), m->c.mph_shifting);
    else
        lub_message("MPH: shifting off (a sustained tension lets the particles pair up after "
                    "some tens of ms, methods.md §5.5: fluid.shifting holds them, 0.3 in "
                    "tutorials/squeeze/oscillatingPlateMPH)");
    if (m->c.viscous_layers)
        lub_message("MPH: viscousNormalisation layers: the viscous coefficient 2 (d+2) over "
                    "%.6f, its response to a shear across layers l0 apart",
                    lub_mph_layer_quadrature(m->dim));
}

static void mph_header(const lub_mps *m)
{
    char vs[256];
    lub_linsolver_describe(&m->vsolver, vs, sizeof vs);
    lub_message("Schemes: MPH-I (x explicit, elastic term explicit, bulk and shear viscosity "
                "backward Euler, all velocity components in one SPD system)");
    lub_message("Solvers: U %s", vs);
}

/* The fluid's height along g: the extent of the fluid particles plus l0. */
static double fluid_height(const lub_mps *m, const double g[3], double gn)
{
    const lub_particles *P = m->P;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_FLUID) continue;
        double h = 0;
        for (int d = 0; d < m->dim; d++) h -= g[d] * P->x[d][i] / gn;
        lo = fmin(lo, h), hi = fmax(hi, h);
    }
    return hi >= lo ? hi - lo + m->l0 : 0.0;
}

static void mph_check(const lub_mps *m, const lub_geometry *geo, double dt, const double g[3])
{
    /* the elastic term is explicit (symplectic Euler): stable while the stiffest lattice
     * compression wave has omega dt < 2 (lub_mph_elastic_limit: 2.00 in 2-D, 1.85 in 3-D);
     * above 1 a compression wave crosses more than l0 per step (Kondo's samples run
     * 0.2-1.6, methods.md §8) */
    const double ce = dt * sqrt(m->c.bulk_modulus / m->c.rho) / m->l0;
    const double lim = lub_mph_elastic_limit(m->dim);
    lub_message("MPH: elastic number dt sqrt(kappa/rho0)/l0 %.4g (explicit; stable below %.3g, "
                "resolved below 1)",
                ce, lim);
    if (!(ce < lim))
        lub_fatal("MPH: the elastic number dt sqrt(kappa/rho0)/l0 = %.4g (deltaT %g s, "
                  "bulkModulus %g Pa, rho %g kg/m^3, l0 %g m) is beyond the stability limit "
                  "%.3g of its explicit step: reduce deltaT to at most %.4g s or bulkModulus "
                  "(constant/models.yaml fluid)",
                  ce, dt, m->c.bulk_modulus, m->c.rho, m->l0, lim,
                  0.9 * lim * m->l0 / sqrt(m->c.bulk_modulus / m->c.rho));
    if (ce > 1)
        lub_warning("MPH: the elastic number dt sqrt(kappa/rho0)/l0 = %.4g is above 1: a "
                    "compression wave crosses more than l0 per step (stable up to %.3g)",
                    ce, lim);
    double gn = 0;
    for (int d = 0; d < m->dim; d++) gn += g[d] * g[d];
    gn = sqrt(gn);
    if (gn > 0) {
        const double H = fluid_height(m, g, gn);
        const double comp = m->c.rho * gn * H / m->c.bulk_modulus;
        lub_message("MPH: hydrostatic compression rho0 |g| H / kappa %.3g (H %g m, the fluid's "
                    "height along g; keep below 1e-2)",
                    comp, H);
        if (comp > 1e-2)
            lub_warning("MPH: the hydrostatic compression rho0 |g| H / kappa = %.3g is above "
                        "1e-2: kappa carries the weight by compressing the fluid by that "
                        "fraction; raise bulkModulus (and lower deltaT with it)",
                        comp);
    }
    lub_message("MPH: free surfaces need no condition (P^kap = 0 where n_i < n0; tension only "
                "through -lambda div u)");
    /* walls: h_v = 3.5 l0 thick, a wall layer and three dummy layers (a fluid particle l0/2
     * in front of the wall layer sees 3 l0 behind it) */
    if (geo && geo->nwalls > 0 && geo->dummy_layers < 3) {
        const lub_node *root = lub_dict_root(geo->dict);
        const lub_node *dl = lub_dict_find((lub_node *)root, "dummyLayers");
        const char *why = "the fluid 'mph' (constant/models.yaml) needs walls one viscosity "
                          "kernel radius h_v = 3.5 l0 thick: a wall layer and at least 3 dummy "
                          "layers (dummyLayers: 3), then run particleGen";
        if (dl) lub_node_error(dl, "dummyLayers: %d: %s", geo->dummy_layers, why);
        lub_node_error(lub_dict_find((lub_node *)root, "walls"), "no dummyLayers (default 2): %s",
                       why);
    }
}

static void mph_log(const lub_mps *m, double dt, double pit, char *buf, size_t size)
{
    (void)dt, (void)pit;
    snprintf(buf, size, "U %3d it %8.2e  ", m->st.v[0].iterations, m->st.v[0].residual);
}

const lub_fluid_type lub_fluid_mph = {
    .name = "mph",
    .read = mph_read,
    .step = lub_mph_step,
    .header_level = mph_header_level,
    .header = mph_header,
    .check = mph_check,
    .log = mph_log,
    .wall_forces = mph_wall_forces,
};
