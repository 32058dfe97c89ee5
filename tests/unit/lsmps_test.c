/* Unit tests of the stabilized LSMPS Laplacian (src/mps/lsmps.h, (SLSMPS); doc/methods.md
 * §1, (1.2)) against independent references: polynomials of degree 2 (exact), a smooth field's
 * Laplacian written out (observed order on jittered particles, the project notes' (methods2 §11)
 * test), the penalised least-squares problem solved directly, the lattice moments summed by hand,
 * and a manufactured Poisson solution on a jittered disk with a Dirichlet edge. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "linalg/bicgstab.h"
#include "linalg/csr.h"
#include "mps/lsmps.h"
#include "mps/neighbours.h"
#include "mps/operators.h"
#include "particles/weight.h"
#include "test.h"

/* deterministic random numbers in [0, 1) (xorshift64*) */
static uint64_t rng_state = 88172645463325252ull;
static double rnd(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

/* the weight written out again, independently of weight.h */
static double w_ref(double r, double re)
{
    return r < re ? (r / re - 1) * (r / re - 1) : 0.0;
}

/* particles with a kind each: 0 fluid (rows), 1 wall (in the fit, no row), 2 dummy (neither) */
typedef struct {
    size_t n, cap;
    double *x[3];
    uint8_t *kind;
} cloud;

static void cloud_init(cloud *c, size_t cap)
{
    c->n = 0, c->cap = cap;
    for (int d = 0; d < 3; d++) c->x[d] = calloc(cap, sizeof(double));
    c->kind = calloc(cap, 1);
}
static void cloud_add(cloud *c, const double p[3], int kind)
{
    if (c->n == c->cap) abort();
    for (int d = 0; d < 3; d++) c->x[d][c->n] = p[d];
    c->kind[c->n++] = (uint8_t)kind;
}
static void cloud_free(cloud *c)
{
    for (int d = 0; d < 3; d++) free(c->x[d]);
    free(c->kind);
}

static void build_open(lub_neighbours *nb, const cloud *c, int dim, double re)
{
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (size_t i = 0; i < c->n; i++)
        for (int d = 0; d < dim; d++)
            lo[d] = fmin(lo[d], c->x[d][i] - 1e-6), hi[d] = fmax(hi[d], c->x[d][i] + 1e-6);
    const int none[3] = {0, 0, 0};
    lub_neighbours_init(nb, dim, re, 0.0, lo, hi, none);
    CHECK(lub_neighbours_build(nb, c->n, c->x) == 0);
}

static lub_lsmps_stabilization options(int dim, double l0, double re)
{
    lub_lsmps_stabilization o = {0};
    lub_mps_reference(dim, l0, re, &o.n0, &o.lambda0);
    o.g0 = lub_mps_lsmps_reference(dim, l0, re);
    o.strength = LUB_LSMPS_STAB_STRENGTH;
    o.onset = LUB_LSMPS_STAB_ONSET;
    return o;
}

/* lap f_i = sum_q coef[q] (f_j - f_i) */
static double apply_row(const lub_neighbours *nb, const double *coef, const double *f, size_t i)
{
    double s = 0;
    for (size_t q = nb->start[i]; q < nb->end[i]; q++) s += coef[q] * (f[nb->j[q]] - f[i]);
    return s;
}

/* The 2-D second-order fit's moment system of particle i: M = sum_j w_ij p p^T and rhs = sum_j
 * w_ij p (f_j - f_i), p = (s_x, s_y, s_x^2, s_y^2, s_x s_y), s = r_ij / l0 (M, rhs zeroed
 * here; 10 x 10 for the callers' solver); returns sum_j w_ij */
static double moments2(const lub_neighbours *nb, size_t i, const double *f, double l0,
                       double M[10][10], double rhs[10])
{
    double wsum = 0;
    memset(M, 0, 10 * sizeof M[0]);
    memset(rhs, 0, 10 * sizeof rhs[0]);
    for (size_t k = nb->start[i]; k < nb->end[i]; k++) {
        const double w = nb->w[k], sx = nb->dx[0][k] / l0, sy = nb->dx[1][k] / l0;
        const double p[5] = {sx, sy, sx * sx, sy * sy, sx * sy}, df = f[nb->j[k]] - f[i];
        wsum += w;
        for (int a = 0; a < 5; a++) {
            rhs[a] += w * p[a] * df;
            for (int bb = 0; bb < 5; bb++) M[a][bb] += w * p[a] * p[bb];
        }
    }
    return wsum;
}

static double smooth(double x, double y)
{
    return sin(2 * x) * cos(3 * y) + x * x * y;
}
static double smooth_lap(double x, double y)
{
    return -13 * sin(2 * x) * cos(3 * y) + 2 * y;
}

/* g0 = e . M^-1 e on the full lattice against the moments summed here: by the lattice's
 * symmetry the squares' block of M is A on the diagonal and B off it (A = sum w s_x^4, B =
 * sum w s_x^2 s_y^2), uncoupled from the rest, and e is its eigenvector: g0 = d / (A + (d-1) B).
 * (2-D, re = 3.1 l0: 0.1232.) */
static void test_reference(void)
{
    for (int dim = 2; dim <= 3; dim++)
        for (int k = 0; k < 2; k++) {
            const double l0 = 0.01, re = (k ? 2.1 : 3.1) * l0;
            double A = 0, B = 0;
            const int mz = dim == 3 ? 4 : 0;
            for (int c = -mz; c <= mz; c++)
                for (int b = -4; b <= 4; b++)
                    for (int a = -4; a <= 4; a++) {
                        double w = w_ref(l0 * sqrt(a * a + b * b + c * c), re);
                        A += w * a * a * a * a;
                        B += w * a * a * b * b;
                    }
            const double g0 = dim / (A + (dim - 1) * B), got = lub_mps_lsmps_reference(dim, l0, re);
            printf("  %d-D, re %.1f l0: g0 %.6f (moments: %.6f)\n", dim, re / l0, got, g0);
            CHECK_REL(got, g0, 1e-12);
        }
}

/* a lattice of (2m+1)^dim particles around org, jittered by up to jitter l0 */
static void lattice(cloud *c, int dim, int m, double l0, const double org[3], double jitter)
{
    size_t nside = (size_t)(2 * m + 1);
    cloud_init(c, dim == 2 ? nside * nside : nside * nside * nside);
    int mz = dim == 3 ? m : 0;
    for (int k = -mz; k <= mz; k++)
        for (int j = -m; j <= m; j++)
            for (int i = -m; i <= m; i++) {
                double p[3] = {org[0] + i * l0, org[1] + j * l0, dim == 3 ? org[2] + k * l0 : 0};
                for (int d = 0; d < dim; d++) p[d] += jitter * l0 * (2 * rnd() - 1);
                cloud_add(c, p, 0);
            }
}

/* Inside the fluid, the stabilisation is off (theta = 1): every polynomial of degree <= 2
 * reproduced to round-off on particles jittered by up to 0.3 l0, 2-D and 3-D. */
static void check_poly(int dim)
{
    const double l0 = 0.1, re = 3.1 * l0, org[3] = {0.37, -0.21, 0.13};
    const int m = dim == 2 ? 8 : 5;
    cloud c;
    lattice(&c, dim, m, l0, org, 0.3);
    lub_neighbours nb;
    build_open(&nb, &c, dim, re);
    double *coef = malloc(nb.npairs * sizeof *coef), *f = malloc(c.n * sizeof *f),
           *theta = malloc(c.n * sizeof *theta);
    uint8_t *flag = calloc(c.n, 1);
    const lub_lsmps_stabilization o = options(dim, l0, re);
    lub_mps_lsmps_stabilized(&nb, NULL, dim, l0, &o, coef, flag, theta);
    for (size_t i = 0; i < c.n; i++) {
        double x = c.x[0][i], y = c.x[1][i], z = c.x[2][i];
        f[i] = 3 + x - 2 * y + 1.5 * x * x - 0.7 * x * y + 2.5 * y * y;
        if (dim == 3) f[i] += z + 0.8 * z * z - 1.1 * y * z;
    }
    const double exact = dim == 2 ? 8.0 : 9.6;
    double maxerr = 0, thmin = 1;
    size_t ninside = 0, nflag = 0;
    for (size_t i = 0; i < c.n; i++) {
        int in = 1;
        for (int d = 0; d < dim; d++) in &= fabs(c.x[d][i] - org[d]) <= (m - 4 + 0.3) * l0;
        if (!in) continue;
        ninside++;
        nflag += flag[i];
        thmin = fmin(thmin, theta[i]);
        maxerr = fmax(maxerr, fabs(apply_row(&nb, coef, f, i) - exact));
    }
    printf("  %d-D, quadratic, jitter 0.3 l0: %zu interior, min theta %g, max error %.3g of %g\n",
           dim, ninside, thmin, maxerr, exact);
    CHECK(ninside > 20 && nflag == 0);
    CHECK(thmin == 1.0);
    CHECK(maxerr <= 1e-9 * exact);
    free(coef), free(f), free(theta), free(flag);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}
static void test_poly_2d(void)
{
    check_poly(2);
}
static void test_poly_3d(void)
{
    check_poly(3);
}

/* the project notes' (methods2 §11) test: f = sin 2x cos 3y + x^2 y on particles jittered by up to
 * 0.15 l0, re = 3.1 l0, l0 = 1/20, 1/40, 1/80, the particles of a fixed square of side 0.5: the
 * relative RMS error falls at an observed order of at least 0.8 (first order on disordered
 * particles), as LSMPS's; the standard Laplacian's (T-3) does not (order below 0.3). */
static void test_rate(void)
{
    const double org[3] = {0.5, 0.5, 0};
    double es[3], estd[3];
    for (int k = 0; k < 3; k++) {
        const double l0 = 1.0 / (20 << k), re = 3.1 * l0;
        const int m = (int)lround(0.5 / l0) + 4;
        cloud c;
        lattice(&c, 2, m, l0, org, 0.15);
        lub_neighbours nb;
        build_open(&nb, &c, 2, re);
        const lub_lsmps_stabilization o = options(2, l0, re);
        double *coef = malloc(nb.npairs * sizeof *coef), *f = malloc(c.n * sizeof *f),
               *lstd = malloc(c.n * sizeof *lstd), *theta = malloc(c.n * sizeof *theta);
        uint8_t *flag = calloc(c.n, 1);
        lub_mps_lsmps_stabilized(&nb, NULL, 2, l0, &o, coef, flag, theta);
        for (size_t i = 0; i < c.n; i++) f[i] = smooth(c.x[0][i], c.x[1][i]);
        lub_mps_laplacian(&nb, NULL, o.n0, o.lambda0, f, lstd);
        double s1 = 0, s2 = 0, sr = 0;
        size_t cnt = 0, blended = 0;
        for (size_t i = 0; i < c.n; i++) {
            if (fabs(c.x[0][i] - org[0]) > 0.25 || fabs(c.x[1][i] - org[1]) > 0.25) continue;
            const double ex = smooth_lap(c.x[0][i], c.x[1][i]), e1 = apply_row(&nb, coef, f, i);
            blended += flag[i] || theta[i] < 1;
            s1 += (e1 - ex) * (e1 - ex);
            s2 += (lstd[i] - ex) * (lstd[i] - ex);
            sr += ex * ex;
            cnt++;
        }
        es[k] = sqrt(s1 / sr), estd[k] = sqrt(s2 / sr);
        printf("  l0 = 1/%d: %zu particles, %zu blended, relative RMS error stabilized %.3g, "
               "standard %.3g\n",
               20 << k, cnt, blended, es[k], estd[k]);
        CHECK(blended == 0);
        free(coef), free(f), free(lstd), free(theta), free(flag);
        lub_neighbours_free(&nb);
        cloud_free(&c);
    }
    for (int k = 0; k < 2; k++) {
        double os = log2(es[k] / es[k + 1]), od = log2(estd[k] / estd[k + 1]);
        printf("  observed order 1/%d -> 1/%d: stabilized %.2f, standard %.2f\n", 20 << k, 40 << k,
               os, od);
        CHECK(os >= 0.8);
        CHECK(od < 0.3);
    }
}

/* The biased neighbourhoods (2-D, l0 = 0.1, jitter 0.15 l0 on the fluid particles):
 *   0  half-plane: fluid y <= 0, the free surface at y = 0;
 *   1  corner: fluid x <= 0, y <= 0;
 *   2  free sheet two particles thick (y = 0, l0);
 *   3  film two particles thick between walls: fluid rows y = l0, 2 l0, wall rows y = 0, 3 l0
 *      (in the fit), two dummy rows beyond each (out of it). */
static void biased(cloud *c, int shape)
{
    const double l0 = 0.1;
    cloud_init(c, 25 * 25);
    for (int j = -12; j <= 12; j++)
        for (int i = -12; i <= 12; i++) {
            int kind = 0;
            if (shape == 0 && j > 0) continue;
            if (shape == 1 && (j > 0 || i > 0)) continue;
            if (shape == 2 && (j < 0 || j > 1)) continue;
            if (shape == 3) {
                if (j < -2 || j > 5) continue;
                kind = j == 1 || j == 2 ? 0 : j == 0 || j == 3 ? 1 : 2;
            }
            double p[3] = {i * l0, j * l0, 0};
            if (kind == 0)
                for (int d = 0; d < 2; d++) p[d] += 0.15 * l0 * (2 * rnd() - 1);
            cloud_add(c, p, kind);
        }
}

/* the particles of shape whose neighbourhood the test looks at: within 4 l0 of the
 * surface, the corner or the sheet, 4 l0 or more from the cloud's cut edges */
static int looked_at(const cloud *c, int shape, size_t i)
{
    const double x = c->x[0][i] / 0.1, y = c->x[1][i] / 0.1;
    if (c->kind[i] != 0) return 0;
    switch (shape) {
    case 0:
        return fabs(x) < 8 && y > -4;
    case 1:
        return x > -5 && y > -5;
    default:
        return fabs(x) < 8;
    }
}

/* On the biased neighbourhoods the stabilized rows keep the sign: every pair coefficient
 * L_ij >= 0 and the diagonal sum_j L_ij > 0 (an M-matrix row), where plain LSMPS (1.1) loses
 * it (negative coefficients; negative row sums on the surface and in the sheet: the test
 * fails for it); with the default penalty, and with the positivity bound alone (strength 0:
 * the test fails without the bound).  Their error on the smooth field stays within the larger of
 * LSMPS's and the standard row's (T-3 of the same neighbours), and a quadratic stays exact (theta =
 * 1) one row below a plane surface, where lubkit's lsmps switches to the standard row. */
static void test_biased(void)
{
    const double l0 = 0.1, re = 3.1 * l0;
    static const char *const name[] = {"half-plane", "corner", "free sheet", "film"};
    for (int run = 0; run < 8; run++) {
        /* the defaults, then the positivity bound alone (strength 0) */
        const int shape = run % 4;
        cloud c;
        biased(&c, shape);
        lub_neighbours nb;
        build_open(&nb, &c, 2, re);
        lub_lsmps_stabilization o = options(2, l0, re);
        if (run >= 4) o.strength = 0;
        lub_mps_mask mk = {c.kind, LUB_MPS_KIND(0), LUB_MPS_KIND(0) | LUB_MPS_KIND(1)};
        double *cs = malloc(nb.npairs * sizeof *cs), *cl = malloc(nb.npairs * sizeof *cl),
               *th = malloc(c.n * sizeof *th), *f = malloc(c.n * sizeof *f),
               *q = malloc(c.n * sizeof *q);
        uint8_t *fs = calloc(c.n, 1), *fl = calloc(c.n, 1);
        lub_mps_lsmps_stabilized(&nb, &mk, 2, l0, &o, cs, fs, th);
        lub_mps_lsmps_laplacian(&nb, &mk, 2, l0, 0.0, NULL, cl, fl);
        for (size_t i = 0; i < c.n; i++) {
            const double x = c.x[0][i], y = c.x[1][i];
            f[i] = smooth(x, y);
            q[i] = 1.5 * x * x - 0.7 * x * y + 2.5 * y * y + x; /* lap 8 */
        }
        const double cstd = lub_mps_laplacian_coefficient(2, o.lambda0, o.n0, 1.0);
        size_t cnt = 0, nflag = 0, nblend = 0, lsign = 0, ssign = 0, worse = 0, nbelow = 0;
        double thmin = 1, emax = 0, estd = 0, qbelow = 0;
        for (size_t i = 0; i < c.n; i++) {
            if (!looked_at(&c, shape, i)) continue;
            cnt++;
            if (fs[i]) {
                nflag++;
                continue;
            }
            thmin = fmin(thmin, th[i]);
            nblend += th[i] < 1;
            /* sign: every L_ij >= 0, sum > 0; the same of plain LSMPS */
            double sum = 0, lsum = 0, s = 0;
            int neg = 0, lneg = 0;
            for (size_t k = nb.start[i]; k < nb.end[i]; k++) {
                const size_t j = nb.j[k];
                if (nb.w[k] <= 0 || c.kind[j] == 2) continue;
                sum += cs[k], neg |= cs[k] < 0;
                if (!fl[i]) lsum += cl[k], lneg |= cl[k] < 0;
                s += cstd * nb.w[k] * (f[j] - f[i]);
            }
            ssign += neg || !(sum > 0);
            lsign += !fl[i] && (lneg || !(lsum > 0));
            /* the error against LSMPS's and the standard row's */
            const double ex = smooth_lap(c.x[0][i], c.x[1][i]);
            const double e = fabs(apply_row(&nb, cs, f, i) - ex), es = fabs(s - ex),
                         el = fl[i] ? es : fabs(apply_row(&nb, cl, f, i) - ex);
            emax = fmax(emax, e), estd = fmax(estd, es);
            worse += e > fmax(el, es) * (1 + 1e-12) + 1e-12;
            /* one row below the plane surface: the quadratic exact */
            if (shape == 0 && c.x[1][i] < -0.5 * l0 && c.x[1][i] > -1.5 * l0) {
                nbelow++;
                qbelow = fmax(qbelow, fabs(apply_row(&nb, cs, q, i) - 8.0));
                CHECK(th[i] == 1.0);
            }
        }
        printf("  %-10s%s: %zu particles, %zu flagged, %zu blended (min theta %.3g), sign lost "
               "in %zu rows (plain LSMPS: %zu); max error %.3g (standard row %.3g)\n",
               name[shape], run >= 4 ? " (strength 0)" : "", cnt, nflag, nblend, thmin, ssign,
               lsign, emax, estd);
        /* the sheet's singular M (two rows: no second derivative across them) is flagged */
        CHECK(cnt > 10 && (nflag == 0 || shape == 2) && nflag < cnt / 2);
        CHECK(ssign == 0);
        CHECK(worse == 0);
        if (shape != 3) CHECK(lsign > 0 && nblend > 0); /* a test with teeth */
        if (run == 0) {
            printf("  half-plane: one row below the surface, %zu particles, quadratic error "
                   "%.3g\n",
                   nbelow, qbelow);
            CHECK(nbelow > 10 && qbelow < 1e-9 * 8);
        }
        free(cs), free(cl), free(th), free(f), free(q), free(fs), free(fl);
        lub_neighbours_free(&nb);
        cloud_free(&c);
    }
}

/* Solve the small dense system A x = b (n <= 10) by Gaussian elimination with partial
 * pivoting (the test's own solver, independent of lsq.h's Cholesky). */
static void dense_solve(int n, double A[10][10], double b[10], double x[10])
{
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int r = k + 1; r < n; r++)
            if (fabs(A[r][k]) > fabs(A[p][k])) p = r;
        for (int cc = 0; cc < n; cc++) {
            double t = A[k][cc];
            A[k][cc] = A[p][cc], A[p][cc] = t;
        }
        double t = b[k];
        b[k] = b[p], b[p] = t;
        for (int r = k + 1; r < n; r++) {
            const double f = A[r][k] / A[k][k];
            for (int cc = k; cc < n; cc++) A[r][cc] -= f * A[k][cc];
            b[r] -= f * b[k];
        }
    }
    for (int k = n - 1; k >= 0; k--) {
        double s = b[k];
        for (int cc = k + 1; cc < n; cc++) s -= A[k][cc] * x[cc];
        x[k] = s / A[k][k];
    }
}

/* The blend is the minimiser of the penalised objective J_i of lsmps.h: at every particle of
 * the corner, with lambda_i = (1/theta_i - 1)/g_i, the normal equations
 * (M + lambda e e^T) a = sum_j w p (f_j - f_i) + lambda s_i e, solved here directly, give the
 * same Laplacian (2/l0^2) e.a as the coefficients. */
static void test_objective(void)
{
    const double l0 = 0.1, re = 3.1 * l0;
    cloud c;
    biased(&c, 1);
    lub_neighbours nb;
    build_open(&nb, &c, 2, re);
    const lub_lsmps_stabilization o = options(2, l0, re);
    double *cs = malloc(nb.npairs * sizeof *cs), *th = malloc(c.n * sizeof *th),
           *f = malloc(c.n * sizeof *f);
    uint8_t *fs = calloc(c.n, 1);
    lub_mps_lsmps_stabilized(&nb, NULL, 2, l0, &o, cs, fs, th);
    for (size_t i = 0; i < c.n; i++) f[i] = smooth(c.x[0][i], c.x[1][i]);
    const double cstd = lub_mps_laplacian_coefficient(2, o.lambda0, o.n0, 1.0);
    double dmax = 0, scale = 0;
    size_t nblend = 0;
    for (size_t i = 0; i < c.n; i++) {
        if (!looked_at(&c, 1, i) || fs[i] || !(th[i] < 1)) continue;
        nblend++;
        double M[10][10], b[10], s = 0;
        moments2(&nb, i, f, l0, M, b);
        for (size_t k = nb.start[i]; k < nb.end[i]; k++) s += cstd * nb.w[k] * (f[nb.j[k]] - f[i]);
        s *= 0.5 * l0 * l0; /* the target of e.a */
        /* g = e.M^-1 e */
        double M2[10][10], e[10] = {0, 0, 1, 1, 0}, cvec[10];
        memcpy(M2, M, sizeof M);
        dense_solve(5, M2, e, cvec);
        const double g = cvec[2] + cvec[3], lam = (1.0 / th[i] - 1.0) / g;
        for (int a = 2; a <= 3; a++) {
            b[a] += lam * s;
            for (int bb = 2; bb <= 3; bb++) M[a][bb] += lam;
        }
        double a[10];
        dense_solve(5, M, b, a);
        const double lap = 2.0 / (l0 * l0) * (a[2] + a[3]), got = apply_row(&nb, cs, f, i);
        dmax = fmax(dmax, fabs(lap - got));
        scale = fmax(scale, fabs(lap));
    }
    printf("  corner: %zu blended particles, penalised least squares against the blend: max "
           "difference %.3g (of %.3g)\n",
           nblend, dmax, scale);
    CHECK(nblend >= 5);
    CHECK(dmax <= 1e-8 * scale);
    free(cs), free(th), free(f), free(fs);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

/* A manufactured Poisson solution: u = exp(x) sin(2y) + x^2 y on the disk |x| < R = 1 of
 * particles jittered by 0.15 l0; the particles within l0 of the edge hold u (Dirichlet, as a
 * free surface's particles hold P = 0: in the fit, with nothing beyond them), the others solve
 * sum_j L_ij (u_j - u_i) = lap u (= -3 exp(x) sin(2y) + 2y) by BiCGStab.  op: 0 the standard
 * Laplacian (T-3), 1 the stabilized one, 2 LSMPS with lubkit's switch for `lsmps` (step.c:
 * the standard row where the PND is below 0.97 n0 or the row sum is not positive).  Returns
 * the relative RMS error of u; nblend: the rows blended (1) or switched (2).
 *
 * Measured (RMS of four draws, R/l0 = 8, 16, 32, 64): stabilized 2.2%, 0.86%, 0.37%, 0.15%
 * (orders 1.4, 1.2, 1.3); standard 4.5%, 3.0%, 1.3%, 0.72% (0.6, 1.2, 0.9: its O(1) errors
 * on jittered particles are random, and the solve averages them); lsmps with the switch
 * 4.3%, 2.2%, 1.0%, 0.53%: the switch takes the standard row at 15-25% of the particles, the
 * interior ones whose PND the jitter puts below 0.97 n0.  The test: the stabilized order at
 * least 0.8 at each doubling to 32, which the standard operator fails at the first, and the
 * stabilized error below both others at each resolution. */
/* Solve sum_j L_ij (x_j - x_i) = lap(i) for the particles of kind 0 of c, the others holding
 * u (Dirichlet), with the pair coefficients coef on nb's pairs, by BiCGStab; returns the
 * relative RMS error of the solution against u over the unknowns.  Shared by the two
 * manufactured Poisson tests. */
static double solve_dirichlet(const cloud *c, const lub_neighbours *nb, const double *coef,
                              const double *u, double (*lap)(double x, double y))
{
    int *row = malloc(c->n * sizeof *row), nu = 0;
    for (size_t i = 0; i < c->n; i++) row[i] = c->kind[i] == 0 ? nu++ : -1;
    double *b = malloc(nu * sizeof *b), *x = calloc(nu, sizeof *x);
    lub_csr A;
    lub_csr_init(&A);
    lub_csr_begin(&A, nu);
    for (size_t i = 0; i < c->n; i++) {
        if (row[i] < 0) continue;
        int len = 1;
        for (size_t q = nb->start[i]; q < nb->end[i]; q++)
            len += nb->w[q] > 0 && row[nb->j[q]] >= 0;
        lub_csr_set_row_length(&A, row[i], len);
    }
    lub_csr_alloc(&A);
    for (size_t i = 0; i < c->n; i++) {
        const int r = row[i];
        if (r < 0) continue;
        int *col = lub_csr_row_col(&A, r), e = 0;
        double *val = lub_csr_row_val(&A, r), diag = 0;
        b[r] = -lap(c->x[0][i], c->x[1][i]);
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            const size_t j = nb->j[q];
            if (nb->w[q] <= 0) continue;
            diag += coef[q];
            if (row[j] >= 0)
                col[e] = row[j], val[e++] = -coef[q];
            else
                b[r] += coef[q] * u[j];
        }
        col[e] = r, val[e] = diag;
    }
    lub_csr_finish(&A);
    lub_bicgstab_work w;
    lub_bicgstab_work_init(&w);
    lub_solve_result res;
    CHECK(lub_bicgstab_solve(&w, &A, b, x, NULL, NULL, 1e-12, 20000, 0, &res) == LUB_SOLVE_OK);
    double e2 = 0, r2 = 0;
    for (size_t i = 0; i < c->n; i++)
        if (row[i] >= 0) e2 += (x[row[i]] - u[i]) * (x[row[i]] - u[i]), r2 += u[i] * u[i];
    lub_bicgstab_work_free(&w);
    lub_csr_free(&A);
    free(row), free(b), free(x);
    return sqrt(e2 / r2);
}

static double lap_disk(double x, double y)
{
    return -3 * exp(x) * sin(2 * y) + 2 * y;
}
static double lap_surface(double x, double y)
{
    return -3 * exp(x) * cos(2 * y) + 2 * y * y + 2 * x * x;
}

static double poisson(double l0, int op, size_t *nblend)
{
    const double R = 1.0, re = 3.1 * l0;
    const int m = (int)ceil(R / l0) + 1;
    cloud c;
    cloud_init(&c, (size_t)(2 * m + 1) * (2 * m + 1));
    for (int j = -m; j <= m; j++)
        for (int i = -m; i <= m; i++) {
            double p[3] = {i * l0 + 0.15 * l0 * (2 * rnd() - 1),
                           j * l0 + 0.15 * l0 * (2 * rnd() - 1), 0};
            const double r = hypot(p[0], p[1]);
            if (r < R) cloud_add(&c, p, r > R - l0 ? 1 : 0);
        }
    lub_neighbours nb;
    build_open(&nb, &c, 2, re);
    const lub_lsmps_stabilization o = options(2, l0, re);
    lub_mps_mask mk = {c.kind, LUB_MPS_KIND(0), LUB_MPS_KIND(0) | LUB_MPS_KIND(1)};
    double *coef = malloc(nb.npairs * sizeof *coef), *th = malloc(c.n * sizeof *th);
    uint8_t *flag = calloc(c.n, 1);
    const double cstd = lub_mps_laplacian_coefficient(2, o.lambda0, o.n0, 1.0);
    if (op == 1) {
        CHECK(lub_mps_lsmps_stabilized(&nb, &mk, 2, l0, &o, coef, flag, th) == 0);
    } else if (op == 2) {
        lub_mps_lsmps_laplacian(&nb, &mk, 2, l0, 0.0, NULL, coef, flag);
        for (size_t i = 0; i < c.n; i++) {
            if (c.kind[i]) continue;
            double ws = 0, as = 0;
            for (size_t q = nb.start[i]; q < nb.end[i]; q++) ws += nb.w[q], as += coef[q];
            if (flag[i] || ws < 0.97 * o.n0 || !(as > 0)) {
                th[i] = 0;
                for (size_t q = nb.start[i]; q < nb.end[i]; q++) coef[q] = cstd * nb.w[q];
            } else
                th[i] = 1;
        }
    } else {
        for (size_t q = 0; q < nb.npairs; q++) coef[q] = cstd * nb.w[q];
    }
    *nblend = 0;
    for (size_t i = 0; i < c.n; i++) *nblend += c.kind[i] == 0 && op && th[i] < 1;
    double *u = malloc(c.n * sizeof *u);
    for (size_t i = 0; i < c.n; i++)
        u[i] = exp(c.x[0][i]) * sin(2 * c.x[1][i]) + c.x[0][i] * c.x[0][i] * c.x[1][i];
    const double err = solve_dirichlet(&c, &nb, coef, u, lap_disk);
    free(coef), free(th), free(flag), free(u);
    lub_neighbours_free(&nb);
    cloud_free(&c);
    return err;
}

static void test_poisson(void)
{
    /* RMS over four jitter draws: one draw's order scatters by +-0.5 */
    double e[3][3] = {{0}};
    size_t nbl[3][3] = {{0}};
    for (int k = 0; k < 3; k++)
        for (int seed = 0; seed < 4; seed++)
            for (int v = 0; v < 3; v++) {
                size_t nb1;
                const double x = poisson(1.0 / (8 << k), v, &nb1);
                e[v][k] += 0.25 * x * x, nbl[v][k] += nb1;
            }
    for (int k = 0; k < 3; k++) {
        for (int v = 0; v < 3; v++) e[v][k] = sqrt(e[v][k]);
        printf("  R/l0 = %d: relative RMS error of u: stabilized %.3g (%zu rows blended), "
               "standard %.3g, lsmps with lubkit's switch %.3g (%zu rows standard)\n",
               8 << k, e[1][k], nbl[1][k] / 4, e[0][k], e[2][k], nbl[2][k] / 4);
    }
    for (int k = 0; k < 2; k++) {
        const double os = log2(e[1][k] / e[1][k + 1]), od = log2(e[0][k] / e[0][k + 1]),
                     ol = log2(e[2][k] / e[2][k + 1]);
        printf("  observed order R/l0 = %d -> %d: stabilized %.2f, standard %.2f, lsmps %.2f\n",
               8 << k, 16 << k, os, od, ol);
        CHECK(os >= 0.8);
    }
    CHECK(log2(e[0][0] / e[0][1]) < 0.8); /* the standard operator fails the same test */
    for (int k = 0; k < 3; k++) CHECK(e[1][k] < e[0][k] && e[1][k] < e[2][k]);
}

/* The free surface's condition inside the fit (lsmps.h, lub_lsmps_bc; methods.md §1, (1.3)).
 * The half-plane of test_biased (fluid y <= 0 jittered by 0.15 l0, its top row the surface
 * particles), its surface h = l0/2 above the top row: the particles within re + l0/2 of it
 * (the surface particles and their neighbours, as step.c picks them) get the stress-free row
 * n . grad f(x_b) = 0, n = (0, 1), d = h - y_i.  bc_half_plane fills n and d. */
static void bc_half_plane(const cloud *c, double l0, double re, double *n[3], double *d)
{
    const double h = 0.5 * l0;
    for (size_t i = 0; i < c->n; i++) {
        n[0][i] = 0, n[1][i] = 1, n[2][i] = 0;
        d[i] = c->kind[i] == 0 && h - c->x[1][i] < re + 0.5 * l0 ? h - c->x[1][i] : 0.0;
    }
}

/* smooth fields with du/dy = 0 at y = h (the surface) and their Laplacians */
static double sfree(double x, double y, double h)
{
    return sin(2 * x) * cos(3 * (y - h)) + x * x * (y - h) * (y - h);
}
static double sfree_lap(double x, double y, double h)
{
    return -13 * sin(2 * x) * cos(3 * (y - h)) + 2 * (y - h) * (y - h) + 2 * x * x;
}

/* In the rows cut by the surface (the particles with a surface row): (a) a quadratic that
 * satisfies the condition, u = 1.5 x^2 - 0.8 x + 2 (y - h)^2 + 0.3 (lap 7), is reproduced to
 * round-off by the stabilized Laplacian with the row, at every such row (theta = 1: the row
 * fixes the fit that the one-sided neighbourhood leaves loose), where without it the blend
 * with T-3 misses it (the test fails without the row); (b) one that violates it, u + 0.9 (y -
 * h) + 0.5 x (y - h) (the same lap 7), is not (the row is in the fit: the test fails for the
 * operator without it, which reproduces both); (c) the minimiser of the objective with the row,
 * solved here directly, gives the same Laplacian as the pair coefficients; (d) a smooth field
 * with du/dn = 0 at the surface: the error of the surface rows with the row against without. */
static void check_surface_rows(double weight)
{
    const double l0 = 0.1, re = 3.1 * l0, h = 0.5 * l0;
    rng_state = 88172645463325252ull;
    cloud c;
    biased(&c, 0);
    lub_neighbours nb;
    build_open(&nb, &c, 2, re);
    double *n[3], *d = malloc(c.n * sizeof *d);
    for (int k = 0; k < 3; k++) n[k] = malloc(c.n * sizeof *n[k]);
    bc_half_plane(&c, l0, re, n, d);
    const lub_lsmps_bc bc = {LUB_LSMPS_BC_NEUMANN, {n[0], n[1], n[2]}, d, weight, re / l0, NULL};
    lub_lsmps_stabilization o = options(2, l0, re), ob = o;
    ob.bc = &bc;
    lub_mps_mask mk = {c.kind, LUB_MPS_KIND(0), LUB_MPS_KIND(0) | LUB_MPS_KIND(1)};
    double *cb = malloc(nb.npairs * sizeof *cb), *c0 = malloc(nb.npairs * sizeof *c0),
           *cl = malloc(nb.npairs * sizeof *cl), *cl0 = malloc(nb.npairs * sizeof *cl0),
           *tb = malloc(c.n * sizeof *tb), *t0 = malloc(c.n * sizeof *t0);
    double *qa = malloc(c.n * sizeof *qa), *qb = malloc(c.n * sizeof *qb),
           *fs = malloc(c.n * sizeof *fs);
    uint8_t *gb = calloc(c.n, 1), *g0 = calloc(c.n, 1), *gl = calloc(c.n, 1), *gl0 = calloc(c.n, 1);
    lub_mps_lsmps_stabilized(&nb, &mk, 2, l0, &ob, cb, gb, tb);
    lub_mps_lsmps_stabilized(&nb, &mk, 2, l0, &o, c0, g0, t0);
    lub_mps_lsmps_laplacian(&nb, &mk, 2, l0, 0.0, &bc, cl, gl);
    lub_mps_lsmps_laplacian(&nb, &mk, 2, l0, 0.0, NULL, cl0, gl0);
    for (size_t i = 0; i < c.n; i++) {
        const double x = c.x[0][i], y = c.x[1][i];
        qa[i] = 1.5 * x * x - 0.8 * x + 2 * (y - h) * (y - h) + 0.3;
        qb[i] = qa[i] + 0.9 * (y - h) + 0.5 * x * (y - h);
        fs[i] = sfree(x, y, h);
    }
    const double cstd = lub_mps_laplacian_coefficient(2, o.lambda0, o.n0, 1.0);
    size_t nrows = 0, nflag = 0, nexact0 = 0, nneg = 0, nneg0 = 0;
    double ea = 0, ea0 = 0, ela = 0, eb = 0, ebl0 = 0, thmin = 1, dmax = 0, dscale = 0;
    double sb = 0, s0 = 0, sl = 0, sl0 = 0, sstd = 0, sr = 0;
    for (size_t i = 0; i < c.n; i++) {
        if (!looked_at(&c, 0, i) || !(d[i] > 0)) continue;
        nrows++;
        if (gb[i] || gl[i] || gl0[i]) {
            nflag++;
            continue;
        }
        thmin = fmin(thmin, tb[i]);
        ea = fmax(ea, fabs(apply_row(&nb, cb, qa, i) - 7));
        ela = fmax(ela, fabs(apply_row(&nb, cl, qa, i) - 7));
        eb = fmax(eb, fabs(apply_row(&nb, cb, qb, i) - 7));
        const double e0 = g0[i] ? INFINITY : fabs(apply_row(&nb, c0, qa, i) - 7);
        ea0 = fmax(ea0, e0);
        nexact0 += e0 < 1e-9 * 7;
        ebl0 = fmax(ebl0, fabs(apply_row(&nb, cl0, qb, i) - 7));
        /* the sign of LSMPS's rows with the row and without */
        int neg = 0, neg0 = 0;
        for (size_t k = nb.start[i]; k < nb.end[i]; k++)
            if (nb.w[k] > 0) neg |= cl[k] < 0, neg0 |= cl0[k] < 0;
        nneg += neg, nneg0 += neg0;
        /* the smooth field: each operator's error */
        const double ex = sfree_lap(c.x[0][i], c.x[1][i], h);
        double st = 0;
        for (size_t k = nb.start[i]; k < nb.end[i]; k++)
            if (nb.w[k] > 0) st += cstd * nb.w[k] * (fs[nb.j[k]] - fs[i]);
        const double e1 = apply_row(&nb, cb, fs, i) - ex, e2 = apply_row(&nb, c0, fs, i) - ex,
                     e3 = apply_row(&nb, cl, fs, i) - ex, e4 = apply_row(&nb, cl0, fs, i) - ex;
        sb += e1 * e1, s0 += e2 * e2, sl += e3 * e3, sl0 += e4 * e4, sstd += (st - ex) * (st - ex);
        sr += ex * ex;
        /* the objective with the row minimised directly: (M + mu r r^T) a = sum_j w p df */
        double M[10][10], rhs[10];
        const double wsum = moments2(&nb, i, fs, l0, M, rhs);
        /* d/dy of (s_x, s_y, s_x^2, s_y^2, s_x s_y) at s_b = (0, d/l0) */
        const double db = d[i] / l0, r[5] = {0, 1, 0, 2 * db, 0};
        const double mu = wsum * w_ref(d[i], re) * weight;
        for (int a = 0; a < 5; a++)
            for (int bb = 0; bb < 5; bb++) M[a][bb] += mu * r[a] * r[bb];
        double av[10];
        dense_solve(5, M, rhs, av);
        const double lap = 2.0 / (l0 * l0) * (av[2] + av[3]);
        dmax = fmax(dmax, fabs(lap - apply_row(&nb, cl, fs, i)));
        dscale = fmax(dscale, fabs(lap));
    }
    printf(
        "  weight %g, half-plane, %zu rows cut by the surface (%zu flagged): a quadratic with "
        "du/dn = 0 at the surface: max error %.3g of 7 with the row (stabilized, min theta %.3g; "
        "LSMPS %.3g), %.3g without (stabilized, exact in %zu rows); one without: %.3g (LSMPS "
        "without the row %.3g)\n",
        weight, nrows, nflag, ea, thmin, ela, ea0, nexact0, eb, ebl0);
    printf("  LSMPS rows with a negative coefficient: %zu with the row, %zu without; the "
           "objective minimised directly against the coefficients: max difference %.3g of %.3g\n",
           nneg, nneg0, dmax, dscale);
    const double rb = sqrt(sb / sr), r0 = sqrt(s0 / sr), rl = sqrt(sl / sr), rl0 = sqrt(sl0 / sr),
                 rs = sqrt(sstd / sr);
    printf("  smooth field with du/dn = 0 at the surface, relative RMS error of these rows: "
           "stabilized %.3g with the row, %.3g without; LSMPS %.3g with, %.3g without; T-3 %.3g\n",
           rb, r0, rl, rl0, rs);
    CHECK(nrows > 30 && nflag == 0);
    CHECK(ela <= 1e-9 * 7);              /* LSMPS with the row: exact, whatever the weight */
    CHECK(ea0 > 0.1 && nexact0 < nrows); /* the blend without the row is not */
    CHECK(eb > 1 && ebl0 < 1e-9 * 7);    /* the violating field: the row is in the fit */
    CHECK(dmax <= 1e-8 * dscale);
    if (weight <= 1) {
        /* a row of the neighbours' weight: the stabilized rows are all LSMPS's (theta 1),
         * exact, and the row restores the sign that LSMPS loses at the surface */
        CHECK(thmin == 1.0 && ea <= 1e-9 * 7);
        CHECK(nneg == 0 && nneg0 > 0);
    }
    CHECK(rb < 0.5 * r0 && rb < rl0 && rb < rs);
    free(cb), free(c0), free(cl), free(cl0), free(tb), free(t0), free(qa), free(qb), free(fs);
    free(gb), free(g0), free(gl), free(gl0), free(d);
    for (int k = 0; k < 3; k++) free(n[k]);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}
static void test_surface_rows(void)
{
    check_surface_rows(1.0);
    check_surface_rows(LUB_LSMPS_BC_WEIGHT);
}

/* The Dirichlet row (the free surface's P = 0 at x_b): the coefficient L_ib of the boundary
 * value against the objective minimised directly, (M + mu r r^T) a = sum_j w p (f_j - f_i) +
 * mu r (0 - f_i), r = p(s_b), on the half-plane; and a quadratic that vanishes on the surface,
 * f = (y - h)(2 + x - 3 (y - h)) (lap -6), reproduced exactly. */
static void test_surface_dirichlet(void)
{
    const double l0 = 0.1, re = 3.1 * l0, h = 0.5 * l0;
    rng_state = 88172645463325252ull;
    cloud c;
    biased(&c, 0);
    lub_neighbours nb;
    build_open(&nb, &c, 2, re);
    double *n[3], *d = malloc(c.n * sizeof *d), *diag = calloc(c.n, sizeof *diag);
    for (int k = 0; k < 3; k++) n[k] = malloc(c.n * sizeof *n[k]);
    bc_half_plane(&c, l0, re, n, d);
    const lub_lsmps_bc bc = {
        LUB_LSMPS_BC_DIRICHLET, {n[0], n[1], n[2]}, d, LUB_LSMPS_BC_WEIGHT, re / l0, diag};
    double *cl = malloc(nb.npairs * sizeof *cl), *f = malloc(c.n * sizeof *f),
           *g = malloc(c.n * sizeof *g);
    uint8_t *fl = calloc(c.n, 1);
    lub_mps_lsmps_laplacian(&nb, NULL, 2, l0, 0.0, &bc, cl, fl);
    for (size_t i = 0; i < c.n; i++) {
        const double x = c.x[0][i], y = c.x[1][i];
        f[i] = sfree(x, y, h) + 0.4;
        g[i] = (y - h) * (2 + x - 3 * (y - h));
    }
    size_t nrows = 0;
    double dmax = 0, scale = 0, eq = 0;
    for (size_t i = 0; i < c.n; i++) {
        if (!looked_at(&c, 0, i) || !(d[i] > 0) || fl[i]) continue;
        nrows++;
        double M[10][10], rhs[10];
        const double wsum = moments2(&nb, i, f, l0, M, rhs);
        const double db = d[i] / l0, r[5] = {0, db, 0, db * db, 0};
        const double mu = wsum * w_ref(d[i], re) * LUB_LSMPS_BC_WEIGHT;
        for (int a = 0; a < 5; a++) {
            rhs[a] += mu * r[a] * (0 - f[i]);
            for (int bb = 0; bb < 5; bb++) M[a][bb] += mu * r[a] * r[bb];
        }
        double av[10];
        dense_solve(5, M, rhs, av);
        const double lap = 2.0 / (l0 * l0) * (av[2] + av[3]);
        const double got = apply_row(&nb, cl, f, i) + diag[i] * (0 - f[i]);
        dmax = fmax(dmax, fabs(lap - got)), scale = fmax(scale, fabs(lap));
        eq = fmax(eq, fabs(apply_row(&nb, cl, g, i) + diag[i] * (0 - g[i]) + 6));
    }
    printf("  %zu rows: the objective with the Dirichlet row against the coefficients: max "
           "difference %.3g of %.3g; a quadratic vanishing on the surface: error %.3g of 6\n",
           nrows, dmax, scale, eq);
    CHECK(nrows > 30);
    CHECK(dmax <= 1e-8 * scale);
    CHECK(eq <= 1e-9 * 6);
    free(cl), free(f), free(g), free(fl), free(d), free(diag);
    for (int k = 0; k < 3; k++) free(n[k]);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

/* A manufactured Poisson solution with a free surface: u = exp(x) cos(2y) + x^2 y^2 (du/dy = 0
 * on y = 0) on the rectangle |x| < 1, -1.5 < y < 0 of particles jittered by 0.15 l0 (rows at
 * y = -(k + 1/2) l0: the surface y = 0 half a spacing above the top row); the particles within
 * l0 of the other three edges hold u (Dirichlet), nothing lies beyond the surface, the others
 * solve sum_j L_ij (u_j - u_i) = lap u (= -3 exp(x) cos(2y) + 2 y^2 + 2 x^2) by BiCGStab.  op:
 * 0 the standard Laplacian (T-3, whose missing neighbours act as du/dn = 0 at order zero), 1
 * the stabilized one without the surface row, 2 with it (n = (0, 1), d = -y_i within re +
 * l0/2 of the surface), 3 LSMPS (1.1) with it.  Returns the relative RMS error of u. */
static double poisson_surface(double l0, int op)
{
    const double re = 3.1 * l0;
    const int mx = (int)lround(1.0 / l0), my = (int)lround(1.5 / l0);
    cloud c;
    cloud_init(&c, (size_t)(2 * mx) * (size_t)my);
    for (int j = 0; j < my; j++)
        for (int i = 0; i < 2 * mx; i++) {
            double p[3] = {-1 + (i + 0.5) * l0 + 0.15 * l0 * (2 * rnd() - 1),
                           -(j + 0.5) * l0 + 0.15 * l0 * (2 * rnd() - 1), 0};
            const int edge = p[0] < -1 + l0 || p[0] > 1 - l0 || p[1] < -1.5 + l0;
            cloud_add(&c, p, edge);
        }
    lub_neighbours nb;
    build_open(&nb, &c, 2, re);
    lub_lsmps_stabilization o = options(2, l0, re);
    lub_mps_mask mk = {c.kind, LUB_MPS_KIND(0), LUB_MPS_KIND(0) | LUB_MPS_KIND(1)};
    double *coef = malloc(nb.npairs * sizeof *coef), *d = calloc(c.n, sizeof *d), *n[3];
    for (int k = 0; k < 3; k++) n[k] = calloc(c.n, sizeof *n[k]);
    for (size_t i = 0; i < c.n; i++) {
        n[1][i] = 1;
        d[i] = c.kind[i] == 0 && -c.x[1][i] < re + 0.5 * l0 ? -c.x[1][i] : 0.0;
    }
    const lub_lsmps_bc bc = {
        LUB_LSMPS_BC_NEUMANN, {n[0], n[1], n[2]}, d, LUB_LSMPS_BC_WEIGHT, re / l0, NULL};
    uint8_t *flag = calloc(c.n, 1);
    if (op == 1 || op == 2) {
        o.bc = op == 2 ? &bc : NULL;
        CHECK(lub_mps_lsmps_stabilized(&nb, &mk, 2, l0, &o, coef, flag, NULL) == 0);
    } else if (op == 3) {
        CHECK(lub_mps_lsmps_laplacian(&nb, &mk, 2, l0, 0.0, &bc, coef, flag) == 0);
    } else {
        const double cstd = lub_mps_laplacian_coefficient(2, o.lambda0, o.n0, 1.0);
        for (size_t q = 0; q < nb.npairs; q++) coef[q] = cstd * nb.w[q];
    }
    double *u = malloc(c.n * sizeof *u);
    for (size_t i = 0; i < c.n; i++) {
        const double X = c.x[0][i], Y = c.x[1][i];
        u[i] = exp(X) * cos(2 * Y) + X * X * Y * Y;
    }
    const double err = solve_dirichlet(&c, &nb, coef, u, lap_surface);
    free(coef), free(d), free(flag), free(u);
    for (int k = 0; k < 3; k++) free(n[k]);
    lub_neighbours_free(&nb);
    cloud_free(&c);
    return err;
}

static void test_poisson_surface(void)
{
    static const char *const name[4] = {"standard", "stabilized", "stabilized + row",
                                        "lsmps + row"};
    double e[4][3] = {{0}};
    rng_state = 88172645463325252ull; /* the draws whatever the tests before */
    for (int k = 0; k < 3; k++)
        for (int seed = 0; seed < 2; seed++)
            for (int v = 0; v < 4; v++) {
                const double x = poisson_surface(1.0 / (8 << k), v);
                e[v][k] += 0.5 * x * x;
            }
    for (int k = 0; k < 3; k++) {
        printf("  l0 = 1/%d: relative RMS error of u:", 8 << k);
        for (int v = 0; v < 4; v++)
            printf(" %s %.3g%s", name[v], sqrt(e[v][k]), v < 3 ? "," : "\n");
    }
    for (int k = 0; k < 2; k++) {
        printf("  observed order 1/%d -> 1/%d:", 8 << k, 16 << k);
        for (int v = 0; v < 4; v++)
            printf(" %s %.2f%s", name[v], 0.5 * log2(e[v][k] / e[v][k + 1]), v < 3 ? "," : "\n");
        CHECK(0.5 * log2(e[2][k] / e[2][k + 1]) >= 1.2); /* e[] holds squares: 0.5 log2 */
    }
    CHECK(0.5 * log2(e[0][0] / e[0][1]) < 1.2); /* the standard operator fails the same test */
    for (int k = 0; k < 3; k++) CHECK(e[2][k] < 0.25 * e[1][k] && e[2][k] < e[0][k]);
}

/* The row's basis (lsmps.h, the derivative of p along n at s_b) with an oblique surface, 2-D
 * and 3-D: particles of a lattice jittered by 0.15 l0 on the side n . x <= 0 of the plane
 * n . x = h (h = l0/2), n = (1, 2)/sqrt 5 or (1, 2, 2)/3; the rows within re + l0/2 of the
 * plane get the stress-free row.  u = 2 (n . x - h)^2 + (a . x)^2 + b . x with a, b along the
 * plane (du/dn = 0 on it; lap 4 + 2 |a|^2) is exact in every such row of LSMPS with the row;
 * u + 0.7 (n . x - h) is not. */
static void check_oblique(int dim)
{
    const double l0 = 0.1, re = 3.1 * l0, h = 0.5 * l0, org[3] = {0, 0, 0};
    const double n3[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3}, n2[3] = {1 / sqrt(5.0), 2 / sqrt(5.0), 0};
    const double *nv = dim == 3 ? n3 : n2;
    const double a[3] = {dim == 3 ? 0 : -nv[1], dim == 3 ? 1 / sqrt(2.0) : nv[0],
                         dim == 3 ? -1 / sqrt(2.0) : 0};
    const double b[3] = {dim == 3 ? 4.0 / 3 : -2 * nv[1], dim == 3 ? -1.0 / 3 : 2 * nv[0],
                         dim == 3 ? -1.0 / 3 : 0}; /* along the plane: n . b = 0 */
    cloud all, c;
    lattice(&all, dim, dim == 3 ? 6 : 10, l0, org, 0.15);
    cloud_init(&c, all.n);
    for (size_t i = 0; i < all.n; i++) {
        const double p[3] = {all.x[0][i], all.x[1][i], all.x[2][i]};
        if (p[0] * nv[0] + p[1] * nv[1] + p[2] * nv[2] <= 0) cloud_add(&c, p, 0);
    }
    lub_neighbours nb;
    build_open(&nb, &c, dim, re);
    double *n[3], *d = calloc(c.n, sizeof *d), *u = malloc(c.n * sizeof *u),
                  *v = malloc(c.n * sizeof *v), *coef = malloc(nb.npairs * sizeof *coef);
    uint8_t *flag = calloc(c.n, 1);
    for (int k = 0; k < 3; k++) n[k] = malloc(c.n * sizeof *n[k]);
    const double lap = 4 + 2 * (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (size_t i = 0; i < c.n; i++) {
        double t = -h, ax = 0, bx = 0;
        for (int k = 0; k < 3; k++) {
            n[k][i] = nv[k];
            t += nv[k] * c.x[k][i], ax += a[k] * c.x[k][i], bx += b[k] * c.x[k][i];
        }
        d[i] = -t < re + 0.5 * l0 ? -t : 0.0;
        u[i] = 2 * t * t + ax * ax + bx;
        v[i] = u[i] + 0.7 * t;
    }
    const lub_lsmps_bc bc = {
        LUB_LSMPS_BC_NEUMANN, {n[0], n[1], n[2]}, d, LUB_LSMPS_BC_WEIGHT, re / l0, NULL};
    lub_mps_lsmps_laplacian(&nb, NULL, dim, l0, 0.0, &bc, coef, flag);
    size_t rows = 0, nflag = 0;
    double eu = 0, ev = 0;
    for (size_t i = 0; i < c.n; i++) {
        int in = d[i] > 0;
        for (int k = 0; k < dim; k++) in &= fabs(c.x[k][i]) < 2.5 * l0;
        if (!in) continue;
        rows++;
        if (flag[i]) {
            nflag++;
            continue;
        }
        eu = fmax(eu, fabs(apply_row(&nb, coef, u, i) - lap));
        ev = fmax(ev, fabs(apply_row(&nb, coef, v, i) - lap));
    }
    printf("  %d-D, oblique surface: %zu cut rows (%zu flagged); with du/dn = 0: max error %.3g "
           "of %g; without: %.3g\n",
           dim, rows, nflag, eu, lap, ev);
    CHECK(rows >= 5 && nflag == 0);
    CHECK(eu <= 1e-9 * lap);
    CHECK(ev > 0.1);
    free(d), free(u), free(v), free(coef), free(flag);
    for (int k = 0; k < 3; k++) free(n[k]);
    lub_neighbours_free(&nb);
    cloud_free(&c);
    cloud_free(&all);
}
static void test_surface_oblique(void)
{
    check_oblique(2);
    check_oblique(3);
}

int main(void)
{
    lub_set_quiet(1);
    RUN(test_reference);
    RUN(test_poly_2d);
    RUN(test_poly_3d);
    RUN(test_rate);
    RUN(test_biased);
    RUN(test_objective);
    RUN(test_poisson);
    RUN(test_surface_rows);
    RUN(test_surface_dirichlet);
    RUN(test_surface_oblique);
    RUN(test_poisson_surface);
    return test_summary();
}
