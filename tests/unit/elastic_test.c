/* Unit tests of src/models/elastic: the elasticWall reader, the load balance (T-51..T-53) and
 * the half-space influence coefficients (T-46..T-49, T-62..T-65).
 *
 * Reference solutions, derived here independently of the code.
 *
 * Line load (Flamant; Johnson, Contact Mechanics 2.19).  A line load P per unit length on a
 * half-space in plane strain moves the surface normally by u(x) = -(2 (1 - nu^2)/(pi E_Y))
 * P ln|x| + C = -(4 / (pi E)) P ln|x| + C, E the equivalent modulus (2/E = sum (1 - nu^2)/E_Y)
 * used by the thesis.  The logarithm never decays: in 2-D the displacement is defined only up
 * to a constant C, fixed by choosing where u = 0.  T-46 writes the kernel as ln(r/b), zero at
 * the distance b (Hertz half-width) from the load.
 *
 * Uniform strip p on [c - w/2, c + w/2].  Superposing line loads p ds,
 *     u(x) = -(4 p / (pi E)) int ln(|x - s| / b) ds = -(4 p / (pi E)) [F(x - c + w/2) - F(x - c
 *            - w/2) - w ln b],   F(t) = t ln|t| - t   (d/dt F = ln|t|, F(0) = 0),
 * and its slope du/dx = -(4 p / (pi E)) ln|(x - c + w/2) / (x - c - w/2)| (Johnson 2.31).  The
 * tests compare differences u(x1) - u(x2), which are free of the constant, and the absolute
 * value with the ln(r/b) convention, each also against a Gauss-Legendre quadrature of the line
 * load that knows nothing of the closed forms.
 *
 * Hertz line contact.  p = p_H sqrt(1 - x^2/b^2), p_H = E b / (4 R) (so that W = pi b p_H / 2
 * gives b^2 = 8 W R / (pi E), T-49): inside the contact dv/dx = -(4/(pi E)) PV int p/(x - s) ds
 * = -(4/(pi E)) pi p_H x / b = -x / R, so v(x) - v(0) = -x^2/(2R): the gap h0 + x^2/(2R) + v
 * is flat.  With the ln(r/b) reference, v(0) = -(4 p_H b/(pi E)) int_{-1}^{1} sqrt(1 - t^2)
 * ln|t| dt = (4 p_H b/(pi E)) (pi/4)(1 + 2 ln 2) = b^2 (1 + 2 ln 2) / (4 R)
 * (int_0^{pi/2} cos^2 t ln sin t dt = -(pi/8)(1 + 2 ln 2)).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "geometry/geometry.h"
#include "io/dict.h"
#include "models/elastic.h"
#include "models/models.h"
#include "test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* the thesis' soft-EHL case (methods.md 6.2) */
static const double E_ = 1.966e7, W_ = 1000.0, R_ = 0.01;

/* ---- independent references --------------------------------------------------------------- */

/* F(t) = t ln|t| - t, F(0) = 0 */
static double antider(double t)
{
    return t == 0.0 ? 0.0 : t * log(fabs(t)) - t;
}

/* closed-form displacement of a unit-pressure strip [c - w/2, c + w/2] at x, kernel ln(r/b) */
static double strip_u(double x, double c, double w, double b)
{
    return -4.0 / (M_PI * E_) * (antider(x - c + 0.5 * w) - antider(x - c - 0.5 * w) - w * log(b));
}

/* 20-point Gauss-Legendre: the positive nodes and their weights on [-1, 1], by Newton's
 * method on P_20 (three-term recurrence) */
static double gl_x[10], gl_w[10];
static void gauss_legendre(void)
{
    const int n = 20;
    for (int i = 0; i < n / 2; i++) {
        double x = cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; it++) {
            double p0 = 1.0, p1 = x;
            for (int k = 2; k <= n; k++) {
                double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (x * p1 - p0) / (x * x - 1.0);
            double dx = p1 / dp;
            x -= dx;
            if (fabs(dx) < 1e-16) break;
        }
        gl_x[i] = x;
        gl_w[i] = 2.0 / ((1.0 - x * x) * dp * dp);
    }
}

/* int_{lo}^{hi} ln(t / b) dt for 0 <= lo < hi, graded towards t = 0 (the integrable
 * singularity) so that every panel is smooth: Gauss-Legendre per panel */
static double quad_log(double lo, double hi, double b)
{
    double s = 0.0;
    double edges[64];
    int ne = 0;
    if (lo == 0.0) {
        /* panels [hi 2^-k-1, hi 2^-k] down to 1e-300-ish, plus the last [0, tiny] exactly */
        double a = hi;
        edges[ne++] = hi;
        for (int k = 0; k < 60; k++) edges[ne++] = a *= 0.5;
        double t = edges[ne - 1]; /* [0, t]: exact, t (ln(t/b) - 1) */
        s += t * (log(t / b) - 1.0);
        for (int k = ne - 1; k > 0; k--) {
            double a0 = edges[k], a1 = edges[k - 1], m = 0.5 * (a0 + a1), r = 0.5 * (a1 - a0);
            for (int q = 0; q < 10; q++)
                s += r * gl_w[q] * (log((m + r * gl_x[q]) / b) + log((m - r * gl_x[q]) / b));
        }
        return s;
    }
    int np = 16;
    for (int k = 0; k < np; k++) {
        double a0 = lo + (hi - lo) * k / np, a1 = lo + (hi - lo) * (k + 1) / np;
        double m = 0.5 * (a0 + a1), r = 0.5 * (a1 - a0);
        for (int q = 0; q < 10; q++)
            s += r * gl_w[q] * (log((m + r * gl_x[q]) / b) + log((m - r * gl_x[q]) / b));
    }
    return s;
}

/* quadrature of the line load over the strip: -(4/(pi E)) int ln(|x - s|/b) ds */
static double strip_u_quad(double x, double c, double w, double b)
{
    double a0 = c - 0.5 * w, a1 = c + 0.5 * w, s;
    if (x <= a0)
        s = quad_log(a0 - x, a1 - x, b);
    else if (x >= a1)
        s = quad_log(x - a1, x - a0, b);
    else
        s = quad_log(0.0, x - a0, b) + quad_log(0.0, a1 - x, b);
    return -4.0 / (M_PI * E_) * s;
}

/* ---- a(K) --------------------------------------------------------------------------------- */

static void test_a_function(void)
{
    /* values by hand: a(0) = ln(1/2) - 1, a(1/2) = 1 (ln 1 - 1) - 0 = -1,
     * a(1) = 1.5 (ln 1.5 - 1) - 0.5 (ln 0.5 - 1) */
    CHECK_NEAR(lub_elastic_a(0.0), log(0.5) - 1.0, 1e-15);
    CHECK_NEAR(lub_elastic_a(0.5), -1.0, 1e-15);
    CHECK_NEAR(lub_elastic_a(1.0), 1.5 * (log(1.5) - 1.0) - 0.5 * (log(0.5) - 1.0), 1e-14);
    /* a(K) = int_{K-1/2}^{K+1/2} ln t dt: for large K the midpoint rule plus its error terms,
     * (Euler-Maclaurin) ln K - 1/(24 K^2) - 1/(320 K^4) - 1/(2688 K^6) (second, fourth and
     * sixth derivatives of ln t: -1/t^2, -6/t^4, -120/t^6); the next term is below 1e-16 for
     * K >= 40 */
    for (double K = 40.0; K < 2e6; K *= 7.3) {
        double k2 = 1.0 / (K * K);
        double ref = log(K) - k2 / 24.0 - k2 * k2 / 320.0 - k2 * k2 * k2 / 2688.0;
        CHECK_NEAR(lub_elastic_a(K), ref, 4e-16 * fabs(ref));
    }
    /* continuity where the evaluation switches form (K = 1) and near the kink K = 1/2 */
    CHECK_NEAR(lub_elastic_a(1.0 - 1e-13), lub_elastic_a(1.0), 1e-12);
    CHECK_NEAR(lub_elastic_a(0.5 + 1e-12), -1.0, 1e-10);
    CHECK_NEAR(lub_elastic_a(0.5 - 1e-12), -1.0, 1e-10);
}

/* ---- the strip: closed form, slope, quadrature -------------------------------------------- */

static void test_strip_closed_form(void)
{
    double b = lub_elastic_hertz_half_width(W_, R_, E_), w = 2.5e-6, c = 1.0e-4;
    double worst_diff = 0.0, worst_abs = 0.0, worst_quad = 0.0;
    /* targets inside the strip, on its edges, near and far (up to 4000 widths) */
    double xs[] = {c,           c + 0.1 * w, c + 0.5 * w,  c - 0.5 * w,   c + 0.9 * w,
                   c + 1.7 * w, c - 3.2 * w, c + 25.0 * w, c - 400.0 * w, c + 4000.0 * w};
    int nx = (int)(sizeof xs / sizeof xs[0]);
    double scale = 4.0 / (M_PI * E_) * w; /* |u| per unit pressure is of order scale ln(b/w) */
    for (int i = 0; i < nx; i++) {
        double u = lub_elastic_coefficient(xs[i] - c, w, E_, b);
        /* absolute value: the ln(r/b) reference of T-46 */
        worst_abs = fmax(worst_abs, fabs(u - strip_u(xs[i], c, w, b)) / scale);
        worst_quad = fmax(worst_quad, fabs(u - strip_u_quad(xs[i], c, w, b)) / scale);
        for (int j = 0; j < nx; j++) {
            /* differences: free of the constant */
            double du = u - lub_elastic_coefficient(xs[j] - c, w, E_, b);
            double dref = strip_u(xs[i], c, w, b) - strip_u(xs[j], c, w, b);
            worst_diff = fmax(worst_diff, fabs(du - dref) / scale);
        }
    }
    printf("  strip: max error / (4 w/(pi E)): differences %.2e, absolute %.2e, quadrature %.2e\n",
           worst_diff, worst_abs, worst_quad);
    /* the closed form F(x - c + w/2) - F(x - c - w/2) cancels to w ln|x - c| for far targets,
     * losing |x - c| / w = 4000 of its own digits: 4000 eps */
    CHECK(worst_diff < 4e-12);
    CHECK(worst_abs < 4e-12);
    CHECK(worst_quad < 1e-11);

    /* slope (Johnson 2.31) by central differences outside the strip and inside it */
    double xsl[] = {c + 0.2 * w, c - 0.3 * w, c + 2.0 * w, c - 50.0 * w};
    for (int i = 0; i < 4; i++) {
        double hstep = 1e-4 * w, x = xsl[i];
        double d = (lub_elastic_coefficient(x + hstep - c, w, E_, b) -
                    lub_elastic_coefficient(x - hstep - c, w, E_, b)) /
                   (2.0 * hstep);
        double ref = -4.0 / (M_PI * E_) * log(fabs((x - c + 0.5 * w) / (x - c - 0.5 * w)));
        CHECK_NEAR(d, ref, 1e-6 * 4.0 / (M_PI * E_));
    }
    /* symmetric in the offset, proportional to 1/E */
    CHECK_NEAR(lub_elastic_coefficient(3e-6, w, E_, b), lub_elastic_coefficient(-3e-6, w, E_, b),
               0.0);
    CHECK_REL(lub_elastic_coefficient(3e-6, w, 2.0 * E_, b),
              0.5 * lub_elastic_coefficient(3e-6, w, E_, b), 1e-15);
}

/* ---- Hertz: the flat contact -------------------------------------------------------------- */

/* exact mean of sqrt(1 - t^2) over [t0, t1] within [-1, 1] */
static double ellipse_mean(double t0, double t1)
{
    t0 = fmax(t0, -1.0);
    t1 = fmin(t1, 1.0);
    if (!(t1 > t0)) return 0.0;
    double G1 = 0.5 * (t1 * sqrt(1.0 - t1 * t1) + asin(t1));
    double G0 = 0.5 * (t0 * sqrt(1.0 - t0 * t0) + asin(t0));
    return (G1 - G0) / (t1 - t0);
}

static void test_hertz_flat_contact(void)
{
    double b = lub_elastic_hertz_half_width(W_, R_, E_);
    double ph = lub_elastic_hertz_pressure(W_, b);
    CHECK_NEAR(b, sqrt(8.0 * 1000.0 * 0.01 / (M_PI * 1.966e7)), 1e-18);
    CHECK_REL(b, 1.1381e-3, 1e-4);  /* methods.md 6.2: b = 1.14 mm */
    CHECK_REL(ph, 0.55939e6, 1e-4); /* p_H = 0.56 MPa */
    CHECK_REL(ph, E_ * b / (4.0 * R_), 1e-14);
    double errs[2];
    for (int g = 0; g < 2; g++) {
        int n = g ? 4000 : 2000; /* segments over [-b, b] */
        double l = 2.0 * b / n;
        double *x = malloc((size_t)n * sizeof *x), *ls = malloc((size_t)n * sizeof *ls);
        double *p = malloc((size_t)n * sizeof *p), *v = malloc((size_t)n * sizeof *v);
        for (int j = 0; j < n; j++) {
            x[j] = -b + (j + 0.5) * l;
            ls[j] = l;
            p[j] = ph * ellipse_mean((x[j] - 0.5 * l) / b, (x[j] + 0.5 * l) / b);
        }
        lub_elastic_kernel *k = lub_elastic_kernel_create(n, x, ls, n, x, E_, b);
        lub_elastic_displacement(k, p, v);
        lub_elastic_kernel_free(k);
        /* v(0): the mean of the two centre segments (x = -l/2, l/2) minus the parabola */
        double v0 = 0.5 * (v[n / 2 - 1] + v[n / 2]) + (0.25 * l * l) / (2.0 * R_);
        double dmax = 0.0; /* flatness of x^2/(2R) + v over |x| < 0.9 b, relative to b^2/R */
        for (int i = 0; i < n; i++)
            if (fabs(x[i]) < 0.9 * b)
                dmax = fmax(dmax, fabs(x[i] * x[i] / (2.0 * R_) + v[i] - v0) / (b * b / R_));
        double v0ref = b * b * (1.0 + 2.0 * log(2.0)) / (4.0 * R_);
        printf("  Hertz, %d segments: flatness %.2e b^2/R, v(0) = %.9e (exact %.9e)\n", n, dmax, v0,
               v0ref);
        CHECK(dmax < 2e-5);
        CHECK_REL(v0, v0ref, 2e-5);
        errs[g] = dmax;
        free(x);
        free(ls);
        free(p);
        free(v);
    }
    CHECK(errs[1] < 0.6 * errs[0]); /* converges with the segment width */
}

/* ---- fast evaluation against the direct sum ----------------------------------------------- */

static uint64_t rng = 88172645463325252ull;
static double rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}

static double max_abs(const double *a, int n)
{
    double m = 0.0;
    for (int i = 0; i < n; i++) m = fmax(m, fabs(a[i]));
    return m;
}

static double max_diff(const double *a, const double *b, int n)
{
    double m = 0.0;
    for (int i = 0; i < n; i++) m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

/* The Reynolds grid: sources at the nodes, targets at the nodes and at the faces (two
 * kernels), given in shuffled order. */
static void test_toeplitz_equals_direct(void)
{
    int n = 1500;
    double b = lub_elastic_hertz_half_width(W_, R_, E_), xa = -0.0025, dx = 3.7e-3 / n;
    double *x = malloc(n * sizeof *x), *l = malloc(n * sizeof *l), *xf = malloc(n * sizeof *xf);
    double *p = malloc(n * sizeof *p), *v = malloc(n * sizeof *v), *vd = malloc(n * sizeof *vd);
    int *perm = malloc(n * sizeof *perm);
    for (int i = 0; i < n; i++) perm[i] = i;
    for (int i = n - 1; i > 0; i--) { /* shuffle: the kernel sorts */
        int j = (int)(rnd() * (i + 1)), t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
    }
    for (int i = 0; i < n; i++) {
        x[i] = xa + perm[i] * dx;
        xf[i] = xa + (perm[i] + 0.5) * dx;
        l[i] = dx;
        p[i] = 1e6 * rnd();
    }
    for (int t = 0; t < 2; t++) {
        const double *xt = t ? xf : x;
        lub_elastic_kernel *k = lub_elastic_kernel_create(n, x, l, n, xt, E_, b);
        lub_elastic_kernel_info info;
        lub_elastic_kernel_get_info(k, &info);
        CHECK(info.toeplitz_blocks == 1 && info.dense_blocks == 0 && !info.on_the_fly);
        CHECK(info.bytes == (size_t)(2 * n - 1) * sizeof(double));
        lub_elastic_displacement(k, p, v);
        lub_elastic_displacement_direct(n, x, l, n, xt, E_, b, p, vd);
        double e = max_diff(v, vd, n) / max_abs(vd, n);
        printf("  uniform grid, %s: Toeplitz vs direct %.2e (relative to max |v|)\n",
               t ? "faces" : "nodes", e);
        CHECK(e < 1e-13);
        /* evaluating again gives the same (the workspace is reset) */
        double v0 = v[7];
        lub_elastic_displacement(k, p, v);
        CHECK(v[7] == v0);
        lub_elastic_kernel_free(k);
    }
    free(x);
    free(l);
    free(xf);
    free(p);
    free(v);
    free(vd);
    free(perm);
}

/* An OPT-like patch (T-62..T-65): coarse segments of width 4 l on both sides of a fine run of
 * width l, tiling the line.  The run-block evaluation equals the direct sum; the coarse
 * segments equal the sum of the fine segments they cover (additivity of the strip integral,
 * which holds with the per-segment ln(l_j/b) and not with one common l_o). */
static void test_mixed_widths(void)
{
    double b = lub_elastic_hertz_half_width(W_, R_, E_), l = 2.5e-6, L = 4.0 * l;
    int nf = 400, nc = 60, n = nf + 2 * nc; /* fine [0, 400 l), coarse on both sides */
    double *x = malloc(n * sizeof *x), *w = malloc(n * sizeof *w), *p = malloc(n * sizeof *p);
    double *v = malloc(n * sizeof *v), *vd = malloc(n * sizeof *vd);
    for (int j = 0; j < nc; j++) {
        x[j] = -(nc - j - 0.5) * L; /* left coarse, ends at 0 */
        x[nc + nf + j] = nf * l + (j + 0.5) * L;
        w[j] = w[nc + nf + j] = L;
    }
    for (int j = 0; j < nf; j++) {
        x[nc + j] = (j + 0.5) * l;
        w[nc + j] = l;
    }
    for (int j = 0; j < n; j++) p[j] = 5e5 * (0.2 + rnd());
    lub_elastic_kernel *k = lub_elastic_kernel_create(n, x, w, n, x, E_, b);
    lub_elastic_kernel_info info;
    lub_elastic_kernel_get_info(k, &info);
    printf("  OPT patch: %d target runs, %d source runs, %d Toeplitz + %d dense blocks, %zu "
           "bytes\n",
           info.target_runs, info.source_runs, info.toeplitz_blocks, info.dense_blocks, info.bytes);
    CHECK(info.target_runs == 3 && info.source_runs == 3);
    CHECK(info.toeplitz_blocks == 5 && info.dense_blocks == 4);
    lub_elastic_displacement(k, p, v);
    lub_elastic_displacement_direct(n, x, w, n, x, E_, b, p, vd);
    double e = max_diff(v, vd, n) / max_abs(vd, n);
    printf("  OPT patch: blocks vs direct %.2e\n", e);
    CHECK(e < 1e-13);
    lub_elastic_kernel_free(k);

    /* the same pressure on an all-fine tiling: each coarse segment split into 4 */
    int m = nf + 2 * nc * 4;
    double *xs = malloc(m * sizeof *xs), *ws = malloc(m * sizeof *ws), *ps = malloc(m * sizeof *ps);
    int q = 0;
    for (int j = 0; j < n; j++) {
        int parts = w[j] > 1.5 * l ? 4 : 1;
        for (int s = 0; s < parts; s++) {
            xs[q] = x[j] - 0.5 * w[j] + (s + 0.5) * l;
            ws[q] = l;
            ps[q] = p[j];
            q++;
        }
    }
    CHECK(q == m);
    double *vf = malloc(n * sizeof *vf);
    lub_elastic_kernel *kf = lub_elastic_kernel_create(m, xs, ws, n, x, E_, b);
    lub_elastic_displacement(kf, ps, vf);
    lub_elastic_kernel_free(kf);
    e = max_diff(v, vf, n) / max_abs(v, n);
    printf("  coarse segments vs their fine sub-segments: %.2e\n", e);
    CHECK(e < 1e-13);
    /* the literal T-62 with a common l_o = l (the fine width) in the reference term differs by
     * sum_j p_j l_j ln(l_j / l) (4/(pi E)), the same for every target: a constant */
    double shift = 0.0;
    for (int j = 0; j < n; j++) shift += 4.0 / (M_PI * E_) * p[j] * w[j] * log(w[j] / l);
    CHECK(shift > 0.0);
    free(xs);
    free(ws);
    free(ps);
    free(vf);
    free(x);
    free(w);
    free(p);
    free(v);
    free(vd);
}

/* Wall particles of a cylinder sampled at arc-length spacing (not uniform in x): one irregular
 * run, dense; and the same with the dense storage forbidden (computed on the fly). */
static void test_irregular_patch(void)
{
    double b = lub_elastic_hertz_half_width(W_, R_, E_), l = 2.5e-6, d = l / R_;
    int n = 801;
    double *x = malloc(n * sizeof *x), *w = malloc(n * sizeof *w), *p = malloc(n * sizeof *p);
    double *v = malloc(n * sizeof *v), *vd = malloc(n * sizeof *vd);
    for (int j = 0; j < n; j++) {
        x[j] = R_ * sin((j - n / 2) * 40.0 * d); /* 40 l apart: spacing varies along the arc */
        w[j] = l;
        p[j] = 1e5 * rnd();
    }
    lub_elastic_displacement_direct(n, x, w, n, x, E_, b, p, vd);
    size_t keep = lub_elastic_dense_max();
    for (int fly = 0; fly < 2; fly++) {
        if (fly) lub_elastic_set_dense_max(1000);
        lub_elastic_kernel *k = lub_elastic_kernel_create(n, x, w, n, x, E_, b);
        lub_elastic_kernel_info info;
        lub_elastic_kernel_get_info(k, &info);
        CHECK(info.toeplitz_blocks == 0 && info.dense_blocks == 1 && info.on_the_fly == fly);
        lub_elastic_displacement(k, p, v);
        double e = max_diff(v, vd, n) / max_abs(vd, n);
        printf("  arc patch (%s): vs direct %.2e\n", fly ? "on the fly" : "dense", e);
        CHECK(e < 1e-13);
        lub_elastic_kernel_free(k);
    }
    lub_elastic_set_dense_max(keep);
    free(x);
    free(w);
    free(p);
    free(v);
    free(vd);
}

/* ---- the reader ----------------------------------------------------------------------------- */

static char geo_path[256];

static void geometry_from(lub_geometry *g, const char *text)
{
    snprintf(geo_path, sizeof geo_path, "/tmp/lub_elastic_test_%ld.yaml", (long)getpid());
    FILE *f = fopen(geo_path, "w");
    fputs(text, f);
    fclose(f);
    lub_geometry_read(g, geo_path);
}

static const char *geo_text = "dimension: 2\n"
                              "l0: 2.5e-6\n"
                              "domain: { min: [-0.0038, -1.0e-5], max: [0.0038, 8.0e-4] }\n"
                              "periodic: [x]\n"
                              "walls:\n"
                              "  lowerWall: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                              "  cylinder:  { type: cylinder, lowestPoint: [1.0e-4, 4.5e-6], "
                              "radius: 0.01, range: [-0.0038, 0.0038] }\n"
                              "fluid:\n"
                              "  - { type: layer, wall: lowerWall, thickness: 3.0e-5 }\n";

/* read models text with the geometry; fatal errors propagate */
static int read_models(const lub_geometry *g, const char *text, lub_elastic_wall *e)
{
    lub_dict *d = lub_dict_parse("constant/models.yaml", text);
    lub_models_declare(lub_dict_root(d));
    lub_catcher c;
    if (lub_error_catch(&c) == 0) {
        int r = lub_elastic_wall_read(lub_dict_root(d), g, e);
        lub_dict_finish(d);
        lub_error_uncatch();
        lub_dict_free(d);
        return r;
    }
    lub_dict_free(d);
    lub_fatal_at(NULL, 0, 0, "%s", c.message); /* re-raise to the test's catcher */
}

static void test_reader(void)
{
    lub_geometry g;
    geometry_from(&g, geo_text);
    lub_elastic_wall e;
    CHECK(read_models(&g, "gravity: { g: [0, -10] }\n", &e) == 0);
    CHECK(read_models(&g,
                      "elasticWall: { patch: cylinder, E: 1.966e7, load: 1000, rampTime: 2e-3,\n"
                      "               relaxation: 5e-6, averageSteps: 1000 }\n",
                      &e) == 1);
    CHECK(e.patch == 1 && strcmp(e.patch_name, "cylinder") == 0);
    CHECK_NEAR(e.radius, 0.01, 0.0);
    CHECK_NEAR(e.x_centre, 1.0e-4, 1e-18);
    CHECK_NEAR(e.y_lowest, 4.5e-6, 1e-18);
    CHECK_NEAR(e.h0, 4.5e-6, 1e-18); /* from the geometry: lowest point above the plane */
    CHECK_NEAR(e.E, 1.966e7, 0.0);
    CHECK_NEAR(e.load, 1000.0, 0.0);
    CHECK_NEAR(e.ramp_time, 2e-3, 0.0);
    CHECK_NEAR(e.clamp, 0.2, 0.0); /* default */
    CHECK(e.average_steps == 1000);
    CHECK_REL(e.b, sqrt(8.0 * 1000.0 * 0.01 / (M_PI * 1.966e7)), 1e-15);
    CHECK_REL(e.p_hertz, 2.0 * 1000.0 / (M_PI * e.b), 1e-15);
    /* defaults of the optional keys, and h0 given */
    CHECK(read_models(&g, "elasticWall: { patch: cylinder, E: 2e7, load: 50, h0: 1e-5 }\n", &e) ==
          1);
    CHECK(e.ramp_time == 0.0 && e.relaxation == 5e-6 && e.clamp == 0.2 && e.average_steps == 1000 &&
          e.h0 == 1e-5);

#define BAD(text, sub)                                                                             \
    do {                                                                                           \
        CHECK_FATAL(read_models(&g, text, &e), sub);                                               \
    } while (0)
    BAD("gravity: { g: [0, -10] }\nelasticWall: { patch: cylindre, E: 1e7, load: 1 }\n",
        "constant/models.yaml:2:23: elasticWall: patch 'cylindre' is not a wall of the geometry "
        "(did you mean 'cylinder'? walls: lowerWall, cylinder)");
    BAD("elasticWall: { patch: lowerWall, E: 1e7, load: 1 }\n",
        "constant/models.yaml:1:23: elasticWall: patch 'lowerWall' must be a 2-D cylinder");
    BAD("elasticWall: { patch: cylinder, E: 0, load: 1 }\n", "constant/models.yaml:1:36:");
    BAD("elasticWall: { patch: cylinder, E: -2e7, load: 1 }\n", "'elasticWall.E' must be > 0");
    BAD("elasticWall: { patch: cylinder, E: 1e7, load: 0 }\n", "models.yaml:1:");
    BAD("elasticWall: { patch: cylinder, E: 1e7 }\n", "missing required key 'load'");
    BAD("elasticWall: { E: 1e7, load: 1000 }\n", "missing required key 'patch'");
    BAD("elasticWall: { patch: cylinder, E: 1e7, load: 1, averageSteps: 0 }\n",
        "constant/models.yaml:1:64:");
    BAD("elasticWall: { patch: cylinder, E: 1e7, load: 1, rampTime: -1 }\n", "rampTime");
    BAD("elasticWall: { patch: cylinder, E: 1e7, load: 1, relaxation: 0 }\n", "relaxation");
    BAD("elasticWall: { patch: cylinder, E: 1e7, load: 1, clamp: 0 }\n", "clamp");
    BAD("elasticWall: { patch: cylinder, E: 1e7, load: 1, h0: -1e-6 }\n", "h0");
    BAD("elasticWall: { patch: cylinder, E: 1e7, load: 1, youngs: 3 }\n",
        "constant/models.yaml:1:50: unknown key 'youngs'");
    BAD("elasticWall: { patch: cylinder, E: 1e7, laod: 1000 }\n", "missing required key 'load'");
    BAD("elasticWall: [1, 2]\n", "constant/models.yaml:1:");
    lub_geometry_free(&g);

    /* no wall beneath the cylinder: h0 must be given */
    geometry_from(&g, "dimension: 2\nl0: 1e-5\n"
                      "domain: { min: [-0.001, -1.0e-4], max: [0.001, 8.0e-4] }\n"
                      "walls:\n"
                      "  ball: { type: cylinder, lowestPoint: [0, 1e-5], radius: 0.01, "
                      "range: [-0.001, 0.001] }\n"
                      "  top: { type: plane, point: [0, 7e-4], normal: [0, -1] }\n"
                      "fluid:\n  - { type: box, min: [-0.001, -1e-4], max: [0.001, 0] }\n");
    BAD("elasticWall: { patch: ball, E: 1e7, load: 1 }\n",
        "constant/models.yaml:1:14: elasticWall: no wall lies beneath");
    CHECK(read_models(&g, "elasticWall: { patch: ball, E: 1e7, load: 1, h0: 2e-6 }\n", &e) == 1);
    lub_geometry_free(&g);
    unlink(geo_path);
#undef BAD
}

/* ---- load balance ------------------------------------------------------------------------- */

static void test_load_balance(void)
{
    lub_elastic_wall e = {
        .load = 1000.0, .ramp_time = 2e-3, .relaxation = 5e-6, .clamp = 0.2, .h0 = 4.5e-6};
    /* T-53 */
    CHECK_NEAR(lub_elastic_load_at(&e, 0.0), 0.0, 0.0);
    CHECK_NEAR(lub_elastic_load_at(&e, 5e-4), 250.0, 1e-12);
    CHECK_NEAR(lub_elastic_load_at(&e, 2e-3), 1000.0, 0.0);
    CHECK_NEAR(lub_elastic_load_at(&e, 4e-3), 1000.0, 0.0);
    /* T-51, T-52: alpha h0^0 = 2.25e-11 m */
    double step = 5e-6 * 4.5e-6;
    CHECK_NEAR(lub_elastic_dh0(&e, 1000.0, 1000.0), 0.0, 0.0);
    CHECK_NEAR(lub_elastic_dh0(&e, 1100.0, 1000.0), 0.5 * step, 1e-25); /* beta = 0.1 */
    CHECK_NEAR(lub_elastic_dh0(&e, 950.0, 1000.0), -0.25 * step, 1e-25);
    CHECK_NEAR(lub_elastic_dh0(&e, 1200.0, 1000.0), step, 1e-25); /* saturated at 0.2 */
    CHECK_NEAR(lub_elastic_dh0(&e, 5000.0, 1000.0), step, 0.0);
    CHECK_NEAR(lub_elastic_dh0(&e, 0.0, 1000.0), -step, 0.0);
    CHECK_NEAR(lub_elastic_dh0(&e, 10.0, 0.0), step, 0.0); /* t = 0 of the ramp */
    CHECK_NEAR(lub_elastic_dh0(&e, 0.0, 0.0), 0.0, 0.0);
    e.clamp = 0.5;
    CHECK_NEAR(lub_elastic_dh0(&e, 1200.0, 1000.0), 0.4 * step, 1e-25);

    /* the ramp must fit in the run */
    lub_dict *d =
        lub_dict_parse("constant/models.yaml", "elasticWall: { patch: cylinder, E: 1e7, load: 1,\n"
                                               "               rampTime: 2e-3 }\n");
    lub_node *ew = lub_dict_find(lub_dict_root(d), "elasticWall");
    e.node = ew;
    e.ramp_node = lub_dict_find(ew, "rampTime");
    lub_elastic_wall_check_ramp(&e, 5e-3, "endTime 0.005");
    lub_elastic_wall_check_ramp(&e, 2e-3, "endTime 0.002");
    CHECK_FATAL(lub_elastic_wall_check_ramp(&e, 1e-3, "endTime 0.001 of system/controlDict.yaml"),
                "constant/models.yaml:2:26: elasticWall: the load ramp (rampTime 0.002 s) is "
                "longer than the run (endTime 0.001 of system/controlDict.yaml)");
    lub_dict_free(d);
}

int main(void)
{
    lub_set_program("elastic_test");
    gauss_legendre();
    RUN(test_a_function);
    RUN(test_strip_closed_form);
    RUN(test_hertz_flat_contact);
    RUN(test_toeplitz_equals_direct);
    RUN(test_mixed_widths);
    RUN(test_irregular_patch);
    RUN(test_reader);
    RUN(test_load_balance);
    return test_summary();
}
