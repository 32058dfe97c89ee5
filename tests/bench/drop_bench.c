/* Free drops with the two-potential surface tension and the MPH fluid
 * (src/models/surfaceTension/, doc/methods.md §9), measured for the tables of methods.md §9
 * (not part of make test):
 *
 *     build/bench/drop_bench laplace DIM R0     a drop of the lattice points within R0 l0,
 *                                               relaxing; its inside pressure read as P and
 *                                               as the force across two cuts (mechanical),
 *                                               against sigma / R (2-D), 2 sigma / R (3-D)
 *     build/bench/drop_bench oscillate DIM R0   the drop set moving in mode 2; the period of
 *                                               <x^2> - <y^2> (about the settled drop's own;
 *                                               LUB_NO_OFFSET=1: about 0) against Rayleigh's,
 *                                               the decay rate against Lamb's
 *     build/bench/drop_bench slab DIM T         a slab T l0 thick, periodic across (LUB_WIDTH
 *                                               l0, 20): its tension (the force across a
 *                                               normal cut) and energy per area
 *     build/bench/drop_bench check DIM R0       the diagnostic sums below from the neighbour
 *                                               lists against the same over all pairs, after
 *                                               LUB_ANNEAL (20) steps of kicks: PASS/FAIL
 *                                               lines, exit 1 on a failure
 *                                               (tests/cases/dropBench runs it)
 *
 * l0 = 0.1 mm, rho 1000; environment: LUB_STEPS (steps of LUB_DT, 2e-5 s), LUB_NU (1e-4),
 * LUB_KAPPA (3e3), LUB_LAMBDA (1), LUB_GRADIENT (plain | corrected: the MPH fluid's gradient),
 * LUB_SIGMA (0.03), LUB_AMP (the mode-2 amplitude eps, 0.1), LUB_RELAX (steps with nu 1e-4, lambda
 * 1 before the mode is set moving, after the annealing if any; an oscillating drop is annealed with
 * these viscosities too), LUB_EVERY (steps between printed lines, 100), LUB_PACK=rings (2-D:
 * concentric rings l0 apart instead of the lattice disc), LUB_ANNEAL=N (N steps of random velocity
 * kicks first, their standard deviation LUB_NOISE m/s, 0.01, falling to 0; LUB_SEED seeds them,
 * 12345), LUB_DUMP=FILE (laplace: x, y, P, the virial pressure of each particle at the end, in l0
 * and dp).  The laplace drop's inside pressure is read three ways: the mean P of (K-7a), the force
 * across the two cuts, and the virial (the trace of the pair forces' stress) of the interior
 * particles; at the end a radial profile.  The pair sums run over the library's cell-linked
 * neighbour lists (pairs_build); the last line gives the cost: steps, wall time and its phases (the
 * library's step and the diagnostics).  The library's step is the cost: in 3-D a drop of 7,000
 * particles takes 0.6-1.6 s per step on one thread, a reading of the diagnostics (every LUB_EVERY
 * steps) 0.1-0.35 s (about 2 s over all pairs).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/timer.h"
#include "io/dict.h"
#include "models/fluid/mph.h"
#include "models/model.h"
#include "mps/mps.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

extern const lub_model_type lub_model_surfaceTension;
extern const lub_fluid_type lub_fluid_mph;

typedef struct {
    lub_model model;
    lub_scene scene;
    lub_dict *dict;
    double seconds; /* in the model's forces (inside lub_mph_step's assembly phase) */
} driver;

static int hook(void *ctx, const lub_mps *m, double *const acc[3])
{
    driver *d = ctx;
    const double t0 = lub_wtime();
    const int r = d->model.type->particle_forces(&d->model, m, acc);
    d->seconds += lub_wtime() - t0;
    return r;
}

/* ---- the mechanical stress across a cut, from the pair forces ------------------------------
 * The model's forces are sums of antisymmetric pair terms (methods.md §9, (K-8)) and the
 * fluid's pressure term too ((K-6): dV (P_i + P_j) e_ij w_p'), so the force that the particles
 * on one side of a plane exert on those of the other side is the sum over the pairs whose
 * segment crosses the plane (Irving-Kirkwood).  Formed here over all pairs (no walls; x
 * periodic with period Lx if Lx > 0), at rest (the viscous terms left out). */
static double k_wa(int dim, double l0, double h, double r)
{
    if (!(r < h)) return 0.0;
    const double q = r / h, lh = l0 / h;
    return q * (1 - q) * (1 - q) * (dim == 2 ? lh * lh : lh * lh * lh) * 15.0 / M_PI;
}
static double k_dwa(int dim, double l0, double h, double r)
{
    if (!(r < h)) return 0.0;
    const double q = r / h, lh = l0 / h;
    return (1 - q) * (1 - 3 * q) / h * (dim == 2 ? lh * lh : lh * lh * lh) * 15.0 / M_PI;
}

typedef struct {
    double a, k, ch, n0a, hs, l0;
    double a_energy; /* Kondo's a [KC]: the continuum interface's energy sigma */
    int dim;
    double Lx;
} stmodel;

/* The pairs of the diagnostic sums below (every pair closer than h_s): the library's
 * cell-linked lists (src/mps/neighbours.h), built afresh for the particles' current positions
 * by pairs_build, or every j of every i (all = 1: the reference that `drop_bench check`
 * compares the lists with).  A list holds the pairs within 1.01 h_s and each sum keeps those
 * that sep() puts within h_s: the two paths sum the same terms, computed the same way, and
 * differ only in the order of the summation.  The all-pairs sums cost O(N^2): a 3-D drop of
 * 7,000 particles spent seconds per reading on them. */
typedef struct {
    lub_neighbours nb;
    int all, ready;
    size_t n;
} pairs;

static void pairs_build(pairs *pp, const stmodel *M, const lub_particles *P)
{
    pp->n = P->n;
    if (pp->all) return;
    /* x (and z in 3-D) periodic with the period Lx where Lx > 0; elsewhere the particles'
     * bounding box (particles outside would be clamped into the boundary cells: still exact) */
    double lo[3] = {0, 0, 0}, hi[3] = {M->l0, M->l0, M->l0};
    int periodic[3] = {0, 0, 0};
    for (int q = 0; q < M->dim; q++) {
        if (q != 1 && M->Lx > 0) {
            periodic[q] = 1, hi[q] = M->Lx;
            continue;
        }
        lo[q] = INFINITY, hi[q] = -INFINITY;
        for (size_t i = 0; i < P->n; i++)
            lo[q] = fmin(lo[q], P->x[q][i]), hi[q] = fmax(hi[q], P->x[q][i]);
        lo[q] -= M->l0, hi[q] += M->l0;
    }
    if (!pp->ready)
        lub_neighbours_init(&pp->nb, M->dim, M->hs, 0.01, lo, hi, periodic);
    else
        lub_neighbours_set_box(&pp->nb, lo, hi, periodic);
    pp->ready = 1;
    lub_neighbours_build(&pp->nb, P->n, P->x);
}

static void pairs_free(pairs *pp)
{
    if (pp->ready) lub_neighbours_free(&pp->nb);
    pp->ready = 0;
}

/* the candidates j of particle i: entries q from pairs_begin to pairs_end, j = pairs_j */
static size_t pairs_begin(const pairs *pp, size_t i)
{
    return pp->all ? 0 : pp->nb.start[i];
}
static size_t pairs_end(const pairs *pp, size_t i)
{
    return pp->all ? pp->n : pp->nb.end[i];
}
static size_t pairs_j(const pairs *pp, size_t q)
{
    return pp->all ? q : pp->nb.j[q];
}

static void cut_stress(const stmodel *M, const lub_particles *P, const pairs *pp, int ax, int tg,
                       double xc, const double centre[3], double rc, double out[3]);

/* The model's coefficient a (methods.md §9), found here again: the flat interface of a
 * lattice slab (16 rows, periodic over 10 l0 across) pulls sigma, its tension per unit a
 * from the force across a cut normal to it (cut_stress). */
static double st_calibrate(stmodel *M, double sigma, int all)
{
    lub_particles S;
    lub_particles_init(&S, M->dim, 1);
    for (int a = 0; a < 10; a++)
        for (int b = 0; b < 16; b++)
            for (int c = 0; c < (M->dim == 3 ? 10 : 1); c++) {
                const double x[3] = {a * M->l0, b * M->l0, c * M->l0};
                lub_particles_add(&S, x, LUB_FLUID, 0, 0);
            }
    const double Lx = M->Lx, ctr[3] = {0, 0, 0};
    double o[3];
    M->Lx = 10 * M->l0, M->a = 1.0;
    pairs pp = {.all = all};
    pairs_build(&pp, M, &S);
    cut_stress(M, &S, &pp, 0, 1, 4.5 * M->l0, ctr, 0, o);
    M->Lx = Lx;
    pairs_free(&pp);
    lub_particles_free(&S);
    return sigma / (-0.5 * o[0]);
}

static void st_setup(stmodel *M, int dim, double l0, double sigma, double Lx, int all)
{
    M->dim = dim, M->l0 = l0, M->hs = 3.5 * l0, M->Lx = Lx;
    M->k = dim == 2 ? 0.350778153 : 0.326976006;
    const double IN = dim == 2 ? 0.024679383 : 0.021425779;
    const double IX = dim == 2 ? 0.226126699 : 0.233977488;
    M->a_energy = sigma / (M->hs * (IN + M->k * M->k * IX));
    const double R2 = dim == 2 ? M->hs * M->hs / 10.0 : 2.0 * M->hs * M->hs / 21.0;
    M->ch = M->hs / R2;
    M->n0a = 0;
    const int hz = dim == 3 ? 4 : 0;
    for (int x = -4; x <= 4; x++)
        for (int y = -4; y <= 4; y++)
            for (int z = -hz; z <= hz; z++) {
                const double r = l0 * sqrt((double)(x * x + y * y + z * z));
                if (r > 0) M->n0a += k_wa(dim, l0, M->hs, r);
            }
    M->a = st_calibrate(M, sigma, all);
}

static double sep(const stmodel *M, const lub_particles *P, size_t i, size_t j, double r[3])
{
    double r2 = 0;
    for (int q = 0; q < 3; q++) {
        r[q] = q < M->dim ? P->x[q][j] - P->x[q][i] : 0.0;
        if (q != 1 && M->Lx > 0) r[q] -= M->Lx * round(r[q] / M->Lx);
        r2 += r[q] * r[q];
    }
    return sqrt(r2);
}

/* The attractive number density n^a_i and the vector chi_i of (K-8) of every particle, over
 * the pairs within h_s (allocated here; the caller frees them) */
static void densities(const stmodel *M, const lub_particles *P, const pairs *pp, double **na_out,
                      double *chi[3])
{
    const int dim = M->dim;
    const size_t n = P->n;
    double *na = lub_calloc(n, sizeof(double));
    for (int q = 0; q < 3; q++) chi[q] = lub_calloc(n, sizeof(double));
    for (size_t i = 0; i < n; i++)
        for (size_t q = pairs_begin(pp, i); q < pairs_end(pp, i); q++) {
            const size_t j = pairs_j(pp, q);
            double r[3];
            const double d = sep(M, P, i, j, r);
            if (j == i || !(d < M->hs)) continue;
            na[i] += k_wa(dim, M->l0, M->hs, d);
            const double wg = lub_mph_w(dim, M->l0, M->hs, d);
            for (int q = 0; q < dim; q++) chi[q][i] += M->ch * r[q] * wg;
        }
    *na_out = na;
}

/* The force per length (2-D) or area (3-D) across the plane x[ax] = xc, restricted to the
 * crossing points within rc of centre (rc <= 0: anywhere), that the side above exerts... on
 * the side above from below: returned along ax (normal: + pushes apart, a pressure) and
 * along tg (tangential) in out[0], out[1]; and the same from the P pairs alone in out[2]. */
static void cut_stress(const stmodel *M, const lub_particles *P, const pairs *pp, int ax, int tg,
                       double xc, const double centre[3], double rc, double out[3])
{
    const int dim = M->dim;
    const size_t n = P->n;
    double *na, *chi[3];
    densities(M, P, pp, &na, chi);
    for (size_t i = 0; i < n; i++) na[i] = fmin(na[i] - M->n0a, 0.0);
    const double dA = dim == 2 ? M->l0 * M->l0 : M->l0 * M->l0 * M->l0;
    const double hp = LUB_MPH_HP * M->l0, ak2 = M->a * M->k * M->k * M->ch;
    double Fn = 0, Ft = 0, Fp = 0;
    for (size_t i = 0; i < n; i++) {
        if (!(P->x[ax][i] < xc)) continue; /* i below, j above */
        for (size_t q = pairs_begin(pp, i); q < pairs_end(pp, i); q++) {
            const size_t j = pairs_j(pp, q);
            double r[3];
            const double d = sep(M, P, i, j, r);
            if (j == i || !(d < M->hs) || !(P->x[ax][i] + r[ax] >= xc)) continue;
            /* the crossing point */
            const double t = (xc - P->x[ax][i]) / r[ax];
            double off2 = 0;
            for (int q = 0; q < dim; q++)
                if (q != ax) {
                    double o = P->x[q][i] + t * r[q] - centre[q];
                    if (q != 1 && M->Lx > 0) o -= M->Lx * round(o / M->Lx);
                    off2 += o * o;
                }
            if (rc > 0 && off2 > rc * rc) continue;
            /* the force on j from i: e_ji = -r/d */
            double e[3], v[3], vr = 0;
            for (int q = 0; q < 3; q++) {
                e[q] = -r[q] / d;
                v[q] = q < dim ? chi[q][i] - chi[q][j] : 0.0;
                vr += v[q] * -r[q];
            }
            const double cpp = M->a * (na[i] + na[j]) * k_dwa(dim, M->l0, M->hs, d);
            const double pr = d < hp ? (P->p[i] + P->p[j]) * lub_mph_dw(dim, M->l0, hp, d) : 0;
            const double wg = lub_mph_w(dim, M->l0, M->hs, d);
            const double dwg = lub_mph_dw(dim, M->l0, M->hs, d);
            double f[3];
            for (int q = 0; q < 3; q++)
                f[q] = dA * ((cpp + pr) * e[q] - ak2 * (wg * v[q] + vr * e[q] * dwg));
            Fn += f[ax], Ft += f[tg], Fp += dA * pr * e[ax];
        }
    }
    /* the whole cut: per length in 2-D, and in 3-D per length of the slab's period along z
     * (Lx, as along x) */
    const double area = rc <= 0    ? (dim == 3 && M->Lx > 0 ? M->Lx : 1.0)
                        : dim == 2 ? 2 * rc
                                   : M_PI * rc * rc;
    out[0] = Fn / area, out[1] = Ft / area, out[2] = Fp / area;
    free(na);
    for (int q = 0; q < 3; q++) free(chi[q]);
}

/* The mechanical (virial) pressure of the particles within rc of centre: the trace of the
 * stress of every pair force on them (the fluid's pressure pairs and (K-8)'s CPP and DGP
 * pairs, at rest), -(1/(2 d dV)) sum_j r_ij . f_ij per particle i (f_ij on i from j), its
 * mean over those particles; out[0] all pairs, out[1] the P pairs alone, out[2] the mean
 * of P, out[3] the count. */
static void virial(const stmodel *M, const lub_particles *P, const pairs *pp,
                   const double centre[3], double rc, double out[4], double *wi, double *nai)
{
    const int dim = M->dim;
    const size_t n = P->n;
    double *na, *chi[3];
    densities(M, P, pp, &na, chi);
    for (size_t i = 0; i < n; i++) {
        if (nai) nai[i] = na[i] / M->n0a;
        na[i] = fmin(na[i] - M->n0a, 0.0);
    }
    const double dA = dim == 2 ? M->l0 * M->l0 : M->l0 * M->l0 * M->l0;
    const double hp = LUB_MPH_HP * M->l0, ak2 = M->a * M->k * M->k * M->ch;
    double sa = 0, sp = 0, sP = 0;
    size_t cnt = 0;
    for (size_t i = 0; i < n; i++) {
        double off2 = 0;
        for (int q = 0; q < dim; q++) off2 += (P->x[q][i] - centre[q]) * (P->x[q][i] - centre[q]);
        if (off2 > rc * rc) continue;
        cnt++, sP += P->p[i];
        const double sa0 = sa;
        for (size_t q = pairs_begin(pp, i); q < pairs_end(pp, i); q++) {
            const size_t j = pairs_j(pp, q);
            double r[3];
            const double d = sep(M, P, i, j, r);
            if (j == i || !(d < M->hs)) continue;
            /* the force on i from j: e_ij = r/d, (chi_j - chi_i) */
            double e[3], v[3], vr = 0;
            for (int q = 0; q < 3; q++) {
                e[q] = r[q] / d;
                v[q] = q < dim ? chi[q][j] - chi[q][i] : 0.0;
                vr += v[q] * r[q];
            }
            const double cpp = M->a * (na[i] + na[j]) * k_dwa(dim, M->l0, M->hs, d);
            const double pr = d < hp ? (P->p[i] + P->p[j]) * lub_mph_dw(dim, M->l0, hp, d) : 0;
            const double wg = lub_mph_w(dim, M->l0, M->hs, d);
            const double dwg = lub_mph_dw(dim, M->l0, M->hs, d);
            double rf = 0, rfp = 0;
            for (int q = 0; q < dim; q++) {
                rf += r[q] * dA * ((cpp + pr) * e[q] - ak2 * (wg * v[q] + vr * e[q] * dwg));
                rfp += r[q] * dA * pr * e[q];
            }
            sa += -rf / (2 * dim * dA), sp += -rfp / (2 * dim * dA);
        }
        if (wi) wi[i] = sa - sa0;
    }
    out[0] = cnt ? sa / cnt : 0, out[1] = cnt ? sp / cnt : 0, out[2] = cnt ? sP / cnt : 0;
    out[3] = (double)cnt;
    free(na);
    for (int q = 0; q < 3; q++) free(chi[q]);
}

/* The surface potential (K-7b) and the elastic energy sum (kappa/2) max(n - n0, 0)^2 dV of
 * every particle (per unit depth in 2-D), over the pairs within h_s. */
static void energies(const stmodel *M, const lub_particles *P, const pairs *pp, double kappa,
                     double *Vs, double *Ve)
{
    const int dim = M->dim;
    const double hp = LUB_MPH_HP * M->l0, n0 = lub_mph_n0(dim, M->l0);
    const double dA = dim == 2 ? M->l0 * M->l0 : M->l0 * M->l0 * M->l0;
    *Vs = *Ve = 0;
    for (size_t i = 0; i < P->n; i++) {
        double na = 0, np = 0, chi[3] = {0, 0, 0};
        for (size_t q = pairs_begin(pp, i); q < pairs_end(pp, i); q++) {
            const size_t j = pairs_j(pp, q);
            double r[3];
            const double d = sep(M, P, i, j, r);
            if (j == i || !(d < M->hs)) continue;
            na += k_wa(dim, M->l0, M->hs, d);
            np += lub_mph_w(dim, M->l0, hp, d);
            const double wg = lub_mph_w(dim, M->l0, M->hs, d);
            for (int q = 0; q < dim; q++) chi[q] += M->ch * r[q] * wg;
        }
        const double N = fmin(na - M->n0a, 0.0), e = fmax(np - n0, 0.0);
        *Vs += 0.5 * M->a *
               (N * N + M->k * M->k * (chi[0] * chi[0] + chi[1] * chi[1] + chi[2] * chi[2])) * dA;
        *Ve += 0.5 * kappa * e * e * dA;
    }
}

/* The number density n_i of the fluid's pressure kernel (h_p) of particle i. */
static double number_density(const stmodel *M, const lub_particles *P, const pairs *pp, size_t i)
{
    const double hp = LUB_MPH_HP * M->l0;
    double np = 0;
    for (size_t q = pairs_begin(pp, i); q < pairs_end(pp, i); q++) {
        const size_t j = pairs_j(pp, q);
        double r[3];
        const double d = sep(M, P, i, j, r);
        if (j != i && d < hp) np += lub_mph_w(M->dim, M->l0, hp, d);
    }
    return np;
}

/* drop_bench check: every diagnostic sum from the lists against the same over all pairs, on
 * the drop as it is (annealed: off the lattice), and the calibration's a on its periodic
 * slab.  Differences relative to each quantity's scale (n0^a; the largest |chi|; dp; the
 * energies and a themselves); tol: the round-off of a different summation order.  Returns
 * the number of failures. */
static int check_pairs(const stmodel *M, const stmodel *Ma, const lub_particles *P, double kappa,
                       double dp, double rin)
{
    const double tol = 1e-12;
    int fails = 0;
    pairs pl = {.all = 0}, pa = {.all = 1};
    pairs_build(&pl, M, P), pairs_build(&pa, Ma, P);
    const size_t n = P->n;
    double cx[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++)
        for (int q = 0; q < M->dim; q++) cx[q] += P->x[q][i] / n;
    double e[8] = {0}, *na[2], *chi[2][3];
    const char *what[8] = {"the calibration's a (relative)",
                           "n^a (over n0^a)",
                           "chi (over its largest)",
                           "the cuts' stress (over dp)",
                           "the virial, interior and per particle (over dp)",
                           "the energies (relative)",
                           "n (over n0)",
                           ""};
    e[0] = fabs(M->a - Ma->a) / Ma->a;
    densities(M, P, &pl, &na[0], chi[0]);
    densities(Ma, P, &pa, &na[1], chi[1]);
    double chimax = 0;
    for (size_t i = 0; i < n; i++)
        for (int q = 0; q < M->dim; q++) chimax = fmax(chimax, fabs(chi[1][q][i]));
    for (size_t i = 0; i < n; i++) {
        e[1] = fmax(e[1], fabs(na[0][i] - na[1][i]) / M->n0a);
        for (int q = 0; q < M->dim; q++)
            e[2] = fmax(e[2], fabs(chi[0][q][i] - chi[1][q][i]) / chimax);
    }
    for (int ax = 0; ax < M->dim; ax++) {
        double o[2][3];
        cut_stress(M, P, &pl, ax, (ax + 1) % M->dim, cx[ax], cx, rin, o[0]);
        cut_stress(Ma, P, &pa, ax, (ax + 1) % M->dim, cx[ax], cx, rin, o[1]);
        for (int k = 0; k < 3; k++) e[3] = fmax(e[3], fabs(o[0][k] - o[1][k]) / dp);
    }
    double v[2][4], *w[2];
    for (int k = 0; k < 2; k++) w[k] = lub_calloc(n, sizeof(double));
    virial(M, P, &pl, cx, rin, v[0], w[0], NULL);
    virial(Ma, P, &pa, cx, rin, v[1], w[1], NULL);
    for (int k = 0; k < 3; k++) e[4] = fmax(e[4], fabs(v[0][k] - v[1][k]) / dp);
    if (v[0][3] != v[1][3]) e[4] = INFINITY;
    /* the per-particle sums are running totals (wi = the particle's share): compared as such */
    for (size_t i = 0; i < n; i++) e[4] = fmax(e[4], fabs(w[0][i] - w[1][i]) / dp);
    double Vs[2], Ve[2];
    energies(M, P, &pl, kappa, &Vs[0], &Ve[0]);
    energies(Ma, P, &pa, kappa, &Vs[1], &Ve[1]);
    e[5] = fmax(fabs(Vs[0] - Vs[1]) / fabs(Vs[1]), fabs(Ve[0] - Ve[1]) / fmax(fabs(Ve[1]), 1e-300));
    const double n0 = lub_mph_n0(M->dim, M->l0);
    for (size_t i = 0; i < n; i++)
        e[6] = fmax(e[6], fabs(number_density(M, P, &pl, i) - number_density(Ma, P, &pa, i)) / n0);
    for (int k = 0; k < 7; k++) {
        printf("%s %d-D drop of %zu particles: %s, lists against all pairs: %.2e (tol %.0e)\n",
               e[k] <= tol ? "PASS" : "FAIL", M->dim, n, what[k], e[k], tol);
        fails += !(e[k] <= tol);
    }
    printf("  (%zu pairs within 1.01 h_s in the lists; the interior's virial %.6f dp)\n",
           pl.nb.npairs, v[0][0] / dp);
    for (int k = 0; k < 2; k++) {
        free(na[k]), free(w[k]);
        for (int q = 0; q < 3; q++) free(chi[k][q]);
    }
    pairs_free(&pl);
    return fails;
}

static double env(const char *name, double def)
{
    const char *e = getenv(name);
    return e ? atof(e) : def;
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr,
                "usage: drop_bench laplace|oscillate|check DIM R0, drop_bench slab DIM T\n");
        return 1;
    }
    const int osc = strcmp(argv[1], "oscillate") == 0, dim = atoi(argv[2]);
    const int chk = strcmp(argv[1], "check") == 0;
    const int slab = strcmp(argv[1], "slab") == 0, W = (int)env("LUB_WIDTH", 20);
    const double R0 = atof(argv[3]);
    const double l0 = 1e-4, rho = 1000, sigma = env("LUB_SIGMA", 0.03);
    const double nu = env("LUB_NU", 1e-4), kappa = env("LUB_KAPPA", 3e3);
    const double lambda = env("LUB_LAMBDA", 1.0), dt = env("LUB_DT", 2e-5);
    const long nsteps = (long)env("LUB_STEPS", 3000), every = (long)env("LUB_EVERY", 100);
    const double amp = env("LUB_AMP", 0.1);
    lub_particles P;
    lub_particles_init(&P, dim, 1);
    P.nlevels = 1;
    P.levels[0].l0 = l0;
    const int n = (int)ceil(R0), nz = dim == 3 ? n : 0;
    if (slab) /* x (and z) periodic over W l0, y from 0 to R0 l0 */
        for (int a = 0; a < W; a++)
            for (int b = 0; b < (int)R0; b++)
                for (int c = 0; c < (dim == 3 ? W : 1); c++) {
                    const double x[3] = {a * l0, b * l0, c * l0};
                    lub_particles_add(&P, x, LUB_FLUID, 0, 0);
                }
    /* LUB_PACK=rings (2-D): concentric rings l0 apart, round(2 pi k) particles on the ring
     * of radius k l0, the last one within R0 l0: a surface of one particle per l0 */
    const char *pack = getenv("LUB_PACK");
    const int rings = pack && strcmp(pack, "rings") == 0 && dim == 2 && !slab;
    for (int k = 0; rings && k < R0; k++) {
        const int nk = k ? (int)lround(2 * M_PI * k) : 1;
        for (int q = 0; q < nk; q++) {
            const double th = 2 * M_PI * (q + 0.5 * (k % 2)) / nk;
            const double x[3] = {k * l0 * cos(th), k * l0 * sin(th), 0};
            lub_particles_add(&P, x, LUB_FLUID, 0, 0);
        }
    }
    for (int a = -n; a <= n && !slab && !rings; a++)
        for (int b = -n; b <= n; b++)
            for (int c = -nz; c <= nz; c++)
                if (a * a + b * b + c * c < R0 * R0) {
                    const double x[3] = {a * l0, b * l0, c * l0};
                    lub_particles_add(&P, x, LUB_FLUID, 0, 0);
                }
    const double R = dim == 2 ? l0 * sqrt(P.n / M_PI) : l0 * cbrt(3.0 * P.n / (4 * M_PI));
    lub_mps_config c;
    lub_mps_config_defaults(&c);
    c.rho = rho, c.nu = nu, c.bulk_viscosity = lambda, c.bulk_modulus = kappa;
    c.list_l0 = LUB_MPH_HV, c.predictor = 0, c.clip_negative = LUB_NEGATIVE_KEEP;
    c.v_solver.kind = LUB_LINSOLVER_PCG;
    c.v_solver.pcg.precond = LUB_PRECOND_JACOBI;
    c.v_solver.pcg.tolerance = 1e-10;
    /* LUB_GRADIENT=corrected: the MPH fluid's `gradient: corrected` (doc/methods.md §8) */
    const char *grad = getenv("LUB_GRADIENT");
    if (grad && strcmp(grad, "corrected") && strcmp(grad, "plain"))
        lub_fatal("LUB_GRADIENT: expected plain or corrected, found '%s'", grad);
    c.gradient_corrected = grad && !strcmp(grad, "corrected");
    char text[256];
    snprintf(text, sizeof text, "surfaceTension: { sigma: %.12g }\n", sigma);
    driver d;
    memset(&d, 0, sizeof d);
    d.dict = lub_dict_parse("constant/models.yaml", text);
    d.scene.P = &P;
    d.scene.dict = d.dict;
    d.scene.fluid = &lub_fluid_mph;
    d.model.type = &lub_model_surfaceTension;
    d.model.entry = lub_dict_find(lub_dict_root(d.dict), "surfaceTension");
    d.model.state = lub_calloc(1, d.model.type->size);
    d.model.type->read(&d.model, &d.scene);
    d.model.type->configure(&d.model, &d.scene, &c);
    const double L = R0 * (osc ? 1.6 : 1) * l0 + 8 * l0;
    double lo[3] = {-L, -L, -L}, hi[3] = {L, L, L};
    int periodic[3] = {0, 0, 0};
    if (slab) {
        lo[0] = lo[2] = -0.5 * l0, hi[0] = hi[2] = (W - 0.5) * l0;
        lo[1] = -10 * l0, hi[1] = (R0 + 10) * l0;
        periodic[0] = 1, periodic[2] = dim == 3;
    }
    stmodel M;
    st_setup(&M, dim, l0, sigma, slab ? W * l0 : 0.0, 0);
    pairs pp = {.all = 0};
    double tdiag = 0, t0 = lub_wtime();
    lub_mps m;
    lub_mps_init(&m, &P, &c, lo, hi, periodic);
    d.scene.nlevels = 1, d.scene.level[0] = &m;
    d.model.type->init(&d.model, &d.scene);
    m.hooks.ctx = &d, m.hooks.particle_forces = hook;
    const double dp = (dim == 2 ? 1 : 2) * sigma / R;
    /* the interior: farther than 2 h_s from the surface (the surface forces reach h_s, through
     * n^a and chi of neighbours within h_s), or within R/2 if that is larger */
    const double rin = fmax(R - 2 * 3.5 * l0, 0.5 * R);
    const double omega2 = (dim == 2 ? 6.0 : 8.0) * sigma / (rho * R * R * R);
    const double T = 2 * M_PI / sqrt(omega2);
    /* LUB_ANNEAL=N steps with random velocity kicks (zero mean, standard deviation LUB_NOISE
     * m/s per step falling linearly to 0): the drop shaken out of its first packing */
    const long nanneal = (long)env("LUB_ANNEAL", chk ? 20 : 0);
    const double noise = env("LUB_NOISE", 0.01);
    srand((unsigned)env("LUB_SEED", 12345));
    if (osc && nanneal > 0) /* annealed with the relaxation's viscosities, as it settles */
        m.c.nu = 1e-4, m.c.bulk_viscosity = 1.0;
    for (long k = 0; k < nanneal; k++) {
        const double s = noise * (1.0 - (double)k / nanneal);
        double mean[3] = {0, 0, 0};
        for (size_t i = 0; i < P.n; i++)
            for (int q = 0; q < dim; q++) {
                /* a normal deviate from Box-Muller */
                const double u1 = (rand() + 1.0) / (RAND_MAX + 2.0), u2 = rand() / (RAND_MAX + 1.0);
                const double g = sqrt(-2 * log(u1)) * cos(2 * M_PI * u2);
                P.u[q][i] += s * g, mean[q] += s * g / P.n;
            }
        for (size_t i = 0; i < P.n; i++)
            for (int q = 0; q < dim; q++) P.u[q][i] -= mean[q];
        /* and their rigid rotation (about the centroid), which no viscosity would damp: a
         * spinning drop's centrifugal pressure would add to its Laplace pressure */
        if (dim == 3) { /* omega = I^-1 L, u -= omega x r */
            double cx[3] = {0, 0, 0}, L[3] = {0, 0, 0}, I[3][3] = {{0}};
            for (size_t i = 0; i < P.n; i++)
                for (int q = 0; q < 3; q++) cx[q] += P.x[q][i] / P.n;
            for (size_t i = 0; i < P.n; i++) {
                const double r[3] = {P.x[0][i] - cx[0], P.x[1][i] - cx[1], P.x[2][i] - cx[2]};
                const double *u[3] = {&P.u[0][i], &P.u[1][i], &P.u[2][i]};
                L[0] += r[1] * *u[2] - r[2] * *u[1], L[1] += r[2] * *u[0] - r[0] * *u[2];
                L[2] += r[0] * *u[1] - r[1] * *u[0];
                const double rr = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
                for (int p = 0; p < 3; p++)
                    for (int q = 0; q < 3; q++) I[p][q] += (p == q ? rr : 0.0) - r[p] * r[q];
            }
            /* I w = L by Cramer's rule (I symmetric positive definite) */
            const double det = I[0][0] * (I[1][1] * I[2][2] - I[1][2] * I[2][1]) -
                               I[0][1] * (I[1][0] * I[2][2] - I[1][2] * I[2][0]) +
                               I[0][2] * (I[1][0] * I[2][1] - I[1][1] * I[2][0]);
            double w[3];
            for (int c = 0; c < 3; c++) {
                double A[3][3];
                for (int p = 0; p < 3; p++)
                    for (int q = 0; q < 3; q++) A[p][q] = q == c ? L[p] : I[p][q];
                w[c] = (A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                        A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                        A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0])) /
                       det;
            }
            for (size_t i = 0; i < P.n; i++) {
                const double r[3] = {P.x[0][i] - cx[0], P.x[1][i] - cx[1], P.x[2][i] - cx[2]};
                P.u[0][i] -= w[1] * r[2] - w[2] * r[1];
                P.u[1][i] -= w[2] * r[0] - w[0] * r[2];
                P.u[2][i] -= w[0] * r[1] - w[1] * r[0];
            }
        }
        if (dim == 2) {
            double cx[2] = {0, 0}, L = 0, I = 0;
            for (size_t i = 0; i < P.n; i++) cx[0] += P.x[0][i] / P.n, cx[1] += P.x[1][i] / P.n;
            for (size_t i = 0; i < P.n; i++) {
                const double x = P.x[0][i] - cx[0], y = P.x[1][i] - cx[1];
                L += x * P.u[1][i] - y * P.u[0][i], I += x * x + y * y;
            }
            for (size_t i = 0; i < P.n; i++) {
                P.u[0][i] += L / I * (P.x[1][i] - cx[1]);
                P.u[1][i] -= L / I * (P.x[0][i] - cx[0]);
            }
        }
        char amsg[512];
        long abad;
        if (lub_mph_step(&m, dt, &abad, amsg, sizeof amsg) != LUB_STEP_OK) {
            printf("annealing step %ld failed: %s\n", k, amsg);
            return 1;
        }
    }
    m.c.nu = nu, m.c.bulk_viscosity = lambda;
    /* LUB_RELAX steps with nu 1e-4, lambda 1 Pa s (after the annealing, if any): the drop
     * settles before the mode is set moving (the oscillation about equilibrium) */
    const long nrelax = (long)env("LUB_RELAX", 0);
    if (nrelax > 0) {
        m.c.nu = 1e-4, m.c.bulk_viscosity = 1.0;
        char rmsg[512];
        long rbad;
        for (long k = 0; k < nrelax; k++)
            if (lub_mph_step(&m, dt, &rbad, rmsg, sizeof rmsg) != LUB_STEP_OK) {
                printf("relaxation step %ld failed: %s\n", k, rmsg);
                return 1;
            }
        m.c.nu = nu, m.c.bulk_viscosity = lambda;
    }
    if (chk) {
        stmodel Ma;
        st_setup(&Ma, dim, l0, sigma, 0.0, 1);
        printf("check %d-D: %zu particles after %ld steps of kicks\n", dim, P.n, nanneal);
        const int fails = check_pairs(&M, &Ma, &P, kappa, dp, rin);
        lub_mps_free(&m);
        d.model.type->free(&d.model);
        free(d.model.state);
        lub_dict_free(d.dict);
        lub_particles_free(&P);
        return fails ? 1 : 0;
    }
    /* the settled drop's own <x^2> - <y^2> (a jammed packing is not quite round): the
     * oscillation is measured about it, or its crossings alternate unevenly and the extremes
     * of one side stand higher than the other's as the amplitude decays */
    double D0 = 0;
    if (osc) { /* the velocity of mode 2 at its equilibrium crossing: u = eps omega (x, -y) */
        const double v = amp * sqrt(omega2);
        double cx[2] = {0, 0};
        for (size_t i = 0; i < P.n; i++) cx[0] += P.x[0][i] / P.n, cx[1] += P.x[1][i] / P.n;
        for (size_t i = 0; i < P.n; i++)
            D0 += ((P.x[0][i] - cx[0]) * (P.x[0][i] - cx[0]) -
                   (P.x[1][i] - cx[1]) * (P.x[1][i] - cx[1])) /
                  P.n;
        if (getenv("LUB_NO_OFFSET")) D0 = 0;
        printf("the settled drop's <x^2> - <y^2>: %.4g l0^2 (the oscillation measured about it)\n",
               D0 / (l0 * l0));
        for (size_t i = 0; i < P.n; i++) {
            P.u[0][i] = v * (P.x[0][i] - cx[0]);
            P.u[1][i] = -v * (P.x[1][i] - cx[1]);
        }
    }
    printf("%s %d-D: %zu particles, R = %.3f l0 (R0 %.2f), dp %.4g Pa, T %.4g s (%.0f steps); "
           "kappa %g, lambda %g, nu %g\n",
           argv[1], dim, P.n, R / l0, R0, dp, T, T / dt, kappa, lambda, nu);
    const double *pc = lub_particles_find_extra(&P, "pCohesive");
    char msg[512];
    long bad;
    double sum = 0, sumn = 0, summ = 0, sumv = 0;
    if (slab) { /* the tension of the lattice slab as built (P = 0) */
        double o[3];
        const double ctr[3] = {0, 0, 0};
        pairs_build(&pp, &M, &P);
        cut_stress(&M, &P, &pp, 0, 1, 0.5 * l0 * (W / 2 - 0.5) + 0.25 * l0 * 0, ctr, 0, o);
        printf("lattice slab: tension %.5g N/m = %.4f sigma (a %.6g Pa; Kondo's energy "
               "calibration, a %.6g Pa, would pull %.4f sigma)\n",
               -0.5 * o[0], -0.5 * o[0] / sigma, M.a, M.a_energy,
               -0.5 * o[0] / sigma * M.a_energy / M.a);
        double Vs, Ve;
        energies(&M, &P, &pp, kappa, &Vs, &Ve);
        const double area = dim == 2 ? 2 * W * l0 : 2 * W * W * l0 * l0;
        printf("lattice slab: energy per area %.5g = %.4f sigma (surface %.4f, elastic %.4f)\n",
               (Vs + Ve) / area, (Vs + Ve) / area / sigma, Vs / area / sigma, Ve / area / sigma);
    }
    /* the oscillation: D(t) = <x^2> - <y^2> about the centroid, its zero crossings (linear
     * interpolation) and its extremes between them */
    double Dprev = 0, tcross[64], ext[64], dext = 0;
    int ncross = 0;
    for (long k = 1; k <= nsteps; k++) {
        if (lub_mph_step(&m, dt, &bad, msg, sizeof msg) != LUB_STEP_OK) {
            printf("step %ld failed: %s\n", k, msg);
            return 1;
        }
        if (osc) {
            double cx[2] = {0, 0}, sx = 0, sy = 0;
            for (size_t i = 0; i < P.n; i++) cx[0] += P.x[0][i] / P.n, cx[1] += P.x[1][i] / P.n;
            for (size_t i = 0; i < P.n; i++) {
                sx += (P.x[0][i] - cx[0]) * (P.x[0][i] - cx[0]) / P.n;
                sy += (P.x[1][i] - cx[1]) * (P.x[1][i] - cx[1]) / P.n;
            }
            const double D = sx - sy - D0;
            if (fabs(D) > fabs(dext)) dext = D;
            if (k > 1 && (D > 0) != (Dprev > 0) && ncross < 64) {
                tcross[ncross] = (k - 1 + Dprev / (Dprev - D)) * dt;
                ext[ncross++] = fabs(dext);
                dext = 0;
            }
            Dprev = D;
        }
        if (k % every) continue;
        const double td = lub_wtime();
        pairs_build(&pp, &M, &P);
        double cx[3] = {0, 0, 0}, ke = 0;
        for (size_t i = 0; i < P.n; i++)
            for (int q = 0; q < dim; q++)
                cx[q] += P.x[q][i] / P.n, ke += 0.5 * P.u[q][i] * P.u[q][i] / P.n;
        double sp = 0, sc = 0, sx = 0, sy = 0;
        int cnt = 0;
        for (size_t i = 0; i < P.n; i++) {
            double r2 = 0;
            for (int q = 0; q < dim; q++) r2 += (P.x[q][i] - cx[q]) * (P.x[q][i] - cx[q]);
            if (r2 < rin * rin) sp += P.p[i], sc += pc[i], cnt++;
            sx += (P.x[0][i] - cx[0]) * (P.x[0][i] - cx[0]);
            sy += (P.x[1][i] - cx[1]) * (P.x[1][i] - cx[1]);
        }
        if (slab) {
            double o[3];
            const double ctr[3] = {0, 0, 0};
            cut_stress(&M, &P, &pp, 0, 1, (W / 2 - 0.5) * l0, ctr, 0, o);
            double ymin = INFINITY, ymax = -INFINITY;
            for (size_t i = 0; i < P.n; i++)
                ymin = fmin(ymin, P.x[1][i]), ymax = fmax(ymax, P.x[1][i]);
            printf("t %.5f: slab tension %.5g N/m = %.4f sigma (P pairs %.4g); thickness %.3f "
                   "l0, rms u %.3g\n",
                   k * dt, -0.5 * o[0], -0.5 * o[0] / sigma, -0.5 * o[2], (ymax - ymin) / l0,
                   sqrt(2 * ke));
            if (k > nsteps / 2) sum += -0.5 * o[0] / sigma, sumn++;
            double Vs, Ve;
            energies(&M, &P, &pp, kappa, &Vs, &Ve);
            const double area = dim == 2 ? 2 * W * l0 : 2 * W * W * l0 * l0;
            printf("  energy per area %.4f sigma (surface %.4f, elastic %.4f)\n",
                   (Vs + Ve) / area / sigma, Vs / area / sigma, Ve / area / sigma);
            tdiag += lub_wtime() - td;
            continue;
        }
        /* the mechanical pressure: the force across the interior parts of the two cuts
         * through the centroid (x and y), per length (area) */
        double o[3], o2[3];
        cut_stress(&M, &P, &pp, 1, 0, cx[1], cx, rin, o);
        cut_stress(&M, &P, &pp, 0, 1, cx[0], cx, rin, o2);
        const double pm = 0.5 * (o[0] + o2[0]);
        printf("  cuts through the centre: interior pressure %.5g Pa = %.4f dp (P pairs %.4f "
               "dp)\n",
               pm, pm / dp, 0.5 * (o[2] + o2[2]) / dp);
        double vo[4];
        virial(&M, &P, &pp, cx, rin, vo, NULL, NULL);
        printf("  virial over the interior: %.4f dp (P pairs %.4f dp, mean P %.4f dp, %.0f "
               "particles)\n",
               vo[0] / dp, vo[1] / dp, vo[2] / dp, vo[3]);
        if (!osc && k > nsteps / 2) sumv += vo[0];
        if (!osc && k > nsteps / 2) summ += pm;
        if (!osc && k > nsteps / 2) sum += (sp + sc) / cnt, sumn++;
        printf("t %.5f: P %.5g pc %.5g sum/dp %.4f  rms u %.3g  <x2>-<y2> %.4g l0^2\n", k * dt,
               sp / cnt, sc / cnt, (sp + sc) / cnt / dp, sqrt(2 * ke), (sx - sy) / P.n / (l0 * l0));
        fflush(stdout);
        tdiag += lub_wtime() - td;
    }
    if (!osc && !slab) { /* the radial profile at the end: bins of l0 from the centroid */
        double cx[3] = {0, 0, 0}, vo[4];
        for (size_t i = 0; i < P.n; i++)
            for (int q = 0; q < dim; q++) cx[q] += P.x[q][i] / P.n;
        double *wi = lub_calloc(P.n, sizeof(double)), *nai = lub_calloc(P.n, sizeof(double));
        pairs_build(&pp, &M, &P);
        virial(&M, &P, &pp, cx, 10 * R, vo, wi, nai);
        const double n0 = lub_mph_n0(dim, l0);
        const int nb = (int)(R / l0) + 3;
        printf("radial profile (r/l0, count, P/dp, virial/dp, n/n0, n^a/n0^a):\n");
        for (int b = 0; b < nb; b++) {
            double sp = 0, sv = 0, sn = 0, sa = 0;
            int cnt = 0;
            for (size_t i = 0; i < P.n; i++) {
                double r2 = 0;
                for (int q = 0; q < dim; q++) r2 += (P.x[q][i] - cx[q]) * (P.x[q][i] - cx[q]);
                if ((int)(sqrt(r2) / l0) != b) continue;
                const double np = number_density(&M, &P, &pp, i);
                sp += P.p[i], sv += wi[i], sn += np / n0, sa += nai[i], cnt++;
            }
            if (cnt)
                printf("  %2d %4d %8.4f %8.4f %8.5f %8.5f\n", b, cnt, sp / cnt / dp, sv / cnt / dp,
                       sn / cnt, sa / cnt);
        }
        if (getenv("LUB_DUMP")) {
            FILE *fp = fopen(getenv("LUB_DUMP"), "w");
            for (size_t i = 0; i < P.n; i++)
                fprintf(fp, "%g %g %g %g %g\n", (P.x[0][i] - cx[0]) / l0, (P.x[1][i] - cx[1]) / l0,
                        P.p[i] / dp, wi[i] / dp, nai[i]);
            fclose(fp);
        }
        free(wi), free(nai);
    }
    if (osc) {
        printf("zero crossings:");
        for (int q = 0; q < ncross; q++) printf(" %.5f", tcross[q]);
        printf("\n");
        /* the period from the first to the last crossing of an even count after it */
        const int last = ncross - 1 - (ncross - 1) % 2;
        if (last >= 2) {
            const double Tm = (tcross[last] - tcross[0]) / (last / 2);
            printf("period %.5g s over %d periods, Rayleigh %.5g s: ratio %.4f\n", Tm, last / 2, T,
                   Tm / T);
        }
        /* decay: the extremes of D between successive crossings, half a period apart */
        if (ncross >= 4) {
            const double rate =
                log(ext[1] / ext[ncross - 1]) /
                (0.5 * (tcross[ncross - 1] + tcross[ncross - 2]) - 0.5 * (tcross[1] + tcross[0]));
            printf("amplitude decay rate %.4g 1/s (extremes %.4g ... %.4g l0^2); Lamb %.4g 1/s\n",
                   rate, ext[1] / (l0 * l0), ext[ncross - 1] / (l0 * l0),
                   (dim == 2 ? 4.0 : 5.0) * nu / (R * R));
        }
    }
    if (slab)
        printf("mean tension over the second half: %.4f sigma\n", sum / sumn);
    else if (!osc)
        printf("mean over the second half: P + pCohesive %.4f of dp, the mechanical pressure %.4f "
               "(cuts), %.4f (virial)\n",
               sum / sumn / dp, summ / sumn / dp, sumv / sumn / dp);
    /* where the time went (the library's phases: src/mps/mps.h; the assembly holds n_i, the
     * surface tension's forces and the viscous system's assembly) */
    const double tw = lub_wtime() - t0, *ts = m.tm.seconds;
    const long ksteps = nanneal + nrelax + nsteps;
    if (ksteps > 0)
        printf("cost: %ld steps of %zu particles in %.1f s, %.3g s per step (%.3g us per "
               "particle-step); lub_mph_step: neighbours %.1f s, assembly %.1f s (the surface "
               "tension's forces %.1f s), viscous solve %.1f s (%.1f PCG iterations per step), "
               "divergence %.1f s, other %.1f s; the diagnostics %.1f s\n",
               ksteps, P.n, tw, tw / ksteps, 1e6 * tw / ksteps / P.n, ts[LUB_T_NEIGHBOUR],
               ts[LUB_T_ASSEMBLY], d.seconds, ts[LUB_T_VISCOSITY], m.iterations[1] / ksteps,
               ts[LUB_T_GRADIENT], ts[LUB_T_OTHER], tdiag);
    pairs_free(&pp);
    lub_mps_free(&m);
    d.model.type->free(&d.model);
    free(d.model.state);
    lub_dict_free(d.dict);
    lub_particles_free(&P);
    return 0;
}
