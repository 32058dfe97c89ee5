/* Unit tests of src/mps/lsq: least-squares interpolation from another resolution level.
 *
 * References: a polynomial of degree <= p lies in the span of the order-p basis, so the fit
 * reproduces it exactly on any arrangement with a regular moment matrix; the tests therefore
 * demand round-off agreement (1e-12 relative for values) on randomly jittered lattices at the
 * scale and position of the thesis wedge (l0 = 5 um and 40 um, |x| up to 4 mm), in 2-D and
 * 3-D.  Failure cases are built so that the moment matrix is singular in exact arithmetic
 * (collinear / coplanar points, two rows for a second derivative) or has fewer neighbours
 * than terms.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "mps/lsq.h"
#include "particles/weight.h"
#include "test.h"

/* deterministic random numbers in [0, 1) (xorshift64*) */
static uint64_t rng_state = 88172645463325252ull;
static double urand(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

enum { NMAX = 4096 };
static double px[3][NMAX];
static double fld[4][NMAX];

/* A lattice of spacing l0 in the box centre +- half (each direction), every point moved by
 * up to +-jitter l0; returns the count. */
static size_t jittered_lattice(int dim, double l0, const double centre[3], double half,
                               double jitter)
{
    const int m = (int)floor(half / l0);
    size_t n = 0;
    for (int c = (dim == 3 ? -m : 0); c <= (dim == 3 ? m : 0); c++)
        for (int b = -m; b <= m; b++)
            for (int a = -m; a <= m; a++) {
                if (n >= NMAX) return n;
                int ijk[3] = {a, b, c};
                for (int d = 0; d < 3; d++)
                    px[d][n] =
                        d < dim ? centre[d] + l0 * (ijk[d] + jitter * (2 * urand() - 1)) : 0.0;
                n++;
            }
    return n;
}

/* Fields: a general polynomial of degree deg (1 or 2) per field k, coefficients c[k][...],
 * in coordinates relative to an origin o (so that the values at the wedge's positions stay
 * of order one relative to their variation). */
typedef struct {
    double c0, g[3], h[6]; /* value, gradient, xx yy zz xy xz yz */
} poly;

static double poly_at(const poly *p, const double *x, const double *o)
{
    double r[3] = {x[0] - o[0], x[1] - o[1], x[2] - o[2]};
    return p->c0 + p->g[0] * r[0] + p->g[1] * r[1] + p->g[2] * r[2] +
           0.5 * (p->h[0] * r[0] * r[0] + p->h[1] * r[1] * r[1] + p->h[2] * r[2] * r[2]) +
           p->h[3] * r[0] * r[1] + p->h[4] * r[0] * r[2] + p->h[5] * r[1] * r[2];
}

static void poly_grad(const poly *p, const double *x, const double *o, double g[3])
{
    double r[3] = {x[0] - o[0], x[1] - o[1], x[2] - o[2]};
    g[0] = p->g[0] + p->h[0] * r[0] + p->h[3] * r[1] + p->h[4] * r[2];
    g[1] = p->g[1] + p->h[1] * r[1] + p->h[3] * r[0] + p->h[5] * r[2];
    g[2] = p->g[2] + p->h[2] * r[2] + p->h[4] * r[0] + p->h[5] * r[1];
}

/* random polynomial: value scale V, over a length L the gradient and curvature terms change
 * the value by about V */
static poly random_poly(int dim, int deg, double V, double L)
{
    poly p;
    memset(&p, 0, sizeof p);
    p.c0 = V * (2 * urand() - 1);
    for (int d = 0; d < dim; d++) p.g[d] = V / L * (2 * urand() - 1);
    if (deg >= 2) {
        int used[6] = {1, 1, dim == 3, 1, dim == 3, dim == 3};
        for (int c = 0; c < 6; c++)
            if (used[c]) p.h[c] = V / (L * L) * (2 * urand() - 1);
    }
    return p;
}

static void fill_fields(size_t n, int nf, const poly *P, const double *o)
{
    for (int k = 0; k < nf; k++)
        for (size_t j = 0; j < n; j++) {
            double x[3] = {px[0][j], px[1][j], px[2][j]};
            fld[k][j] = poly_at(&P[k], x, o);
        }
}

static const double *const X[3] = {px[0], px[1], px[2]};
static const double *const F[4] = {fld[0], fld[1], fld[2], fld[3]};

/* Max relative errors of value, gradient and second derivatives over ntarget random points
 * inside the inner part of the cloud. */
static void exactness(int dim, int order, int deg, double l0, const double centre[3], int ntarget,
                      double *ev, double *eg, double *eh, int *bad_status)
{
    const double re = 3.1 * l0;
    size_t n = jittered_lattice(dim, l0, centre, 6 * l0, 0.3);
    poly P[3];
    const double L = 10 * l0;
    P[0] = random_poly(dim, deg, 1.2, L);  /* u [m/s] */
    P[1] = random_poly(dim, deg, 0.05, L); /* v */
    P[2] = random_poly(dim, deg, 3e5, L);  /* p [Pa] */
    fill_fields(n, 3, P, centre);
    lub_lsq_options o = lub_lsq_defaults(dim, l0, re);
    o.order = order;
    *ev = *eg = *eh = 0.0;
    *bad_status = 0;
    for (int t = 0; t < ntarget; t++) {
        double xt[3] = {0, 0, 0};
        for (int d = 0; d < dim; d++) xt[d] = centre[d] + 2 * l0 * (2 * urand() - 1);
        double val[3], gr[3][3], he[3][6];
        lub_lsq_result r = lub_lsq_interpolate(&o, xt, X, n, NULL, 3, F, val, gr, he);
        if (r.status != LUB_LSQ_OK || r.order != order) (*bad_status)++;
        for (int k = 0; k < 3; k++) {
            double V = fabs(P[k].c0) + 1e-300, G = 0, H = 0, g[3];
            for (int d = 0; d < 3; d++) G = fmax(G, fabs(P[k].g[d]));
            for (int c = 0; c < 6; c++) H = fmax(H, fabs(P[k].h[c]));
            /* scales: value ~ V + G L (the field varies by that much over the cloud) */
            double vs = fmax(V, G * L);
            *ev = fmax(*ev, fabs(val[k] - poly_at(&P[k], xt, centre)) / vs);
            poly_grad(&P[k], xt, centre, g);
            for (int d = 0; d < dim; d++) *eg = fmax(*eg, fabs(gr[k][d] - g[d]) / fmax(G, H * L));
            if (order == 2)
                for (int c = 0; c < 6; c++) *eh = fmax(*eh, fabs(he[k][c] - P[k].h[c]) / H);
        }
    }
}

static void test_linear_exact_2d(void)
{
    /* fine level of the wedge near the outlet boundary, and the coarse level at the inlet */
    const double c1[3] = {0.0030, 2.0e-5, 0}, c2[3] = {-0.0036, 4.0e-5, 0};
    double ev, eg, eh;
    int bad;
    exactness(2, 1, 1, 5e-6, c1, 200, &ev, &eg, &eh, &bad);
    printf("  2-D order 1, l0 5e-6: value %.2e, gradient %.2e\n", ev, eg);
    CHECK(bad == 0);
    CHECK(ev < 1e-12);
    CHECK(eg < 1e-10);
    exactness(2, 1, 1, 4e-5, c2, 200, &ev, &eg, &eh, &bad);
    printf("  2-D order 1, l0 4e-5: value %.2e, gradient %.2e\n", ev, eg);
    CHECK(bad == 0);
    CHECK(ev < 1e-12);
    CHECK(eg < 1e-10);
}

static void test_linear_exact_3d(void)
{
    const double c[3] = {0.0030, 2.0e-5, -1.0e-4};
    double ev, eg, eh;
    int bad;
    exactness(3, 1, 1, 5e-6, c, 200, &ev, &eg, &eh, &bad);
    printf("  3-D order 1: value %.2e, gradient %.2e\n", ev, eg);
    CHECK(bad == 0);
    CHECK(ev < 1e-12);
    CHECK(eg < 1e-10);
}

static void test_quadratic_exact_second_order(void)
{
    const double c[3] = {-0.0036, 3.0e-5, 2.0e-5};
    double ev, eg, eh;
    int bad;
    exactness(2, 2, 2, 5e-6, c, 200, &ev, &eg, &eh, &bad);
    printf("  2-D order 2, quadratic: value %.2e, gradient %.2e, second %.2e\n", ev, eg, eh);
    CHECK(bad == 0);
    CHECK(ev < 1e-12);
    CHECK(eg < 1e-10);
    CHECK(eh < 1e-8);
    exactness(3, 2, 2, 4e-5, c, 100, &ev, &eg, &eh, &bad);
    printf("  3-D order 2, quadratic: value %.2e, gradient %.2e, second %.2e\n", ev, eg, eh);
    CHECK(bad == 0);
    CHECK(ev < 1e-12);
    CHECK(eg < 1e-10);
    CHECK(eh < 1e-8);
    /* the second-order variant is still exact for linear fields */
    exactness(2, 2, 1, 5e-6, c, 50, &ev, &eg, &eh, &bad);
    CHECK(bad == 0);
    CHECK(ev < 1e-12);
    /* and the first-order fit is not exact for a quadratic (the test can fail) */
    exactness(2, 1, 2, 5e-6, c, 50, &ev, &eg, &eh, &bad);
    printf("  2-D order 1 on a quadratic: value %.2e (not exact)\n", ev);
    CHECK(ev > 1e-6);
}

/* 1 and 2 neighbours in 2-D: too few for a gradient; the weighted mean is returned. */
static void test_too_few_neighbours(void)
{
    const double l0 = 1e-5, re = 3.1 * l0, xt[3] = {0.001, 0.0002, 0};
    lub_lsq_options o = lub_lsq_defaults(2, l0, re);
    px[0][0] = xt[0] + 0.5 * l0, px[1][0] = xt[1];
    px[0][1] = xt[0], px[1][1] = xt[1] - 2.0 * l0;
    px[0][2] = xt[0] + 10 * l0, px[1][2] = xt[1]; /* outside re: ignored */
    px[2][0] = px[2][1] = px[2][2] = 0;
    fld[0][0] = 1.0, fld[0][1] = 3.0, fld[0][2] = 100.0;
    double val[1] = {-7}, gr[1][3] = {{9, 9, 9}};
    lub_lsq_result r = lub_lsq_interpolate(&o, xt, X, 3, NULL, 1, F, val, gr, NULL);
    CHECK(r.status == LUB_LSQ_TOO_FEW);
    CHECK(r.order == 0);
    CHECK(r.n == 2);
    double w0 = lub_mps_weight(0.5 * l0, re), w1 = lub_mps_weight(2.0 * l0, re);
    CHECK_NEAR(val[0], (w0 * 1.0 + w1 * 3.0) / (w0 + w1), 1e-15);
    CHECK(gr[0][0] == 0 && gr[0][1] == 0 && gr[0][2] == 0);

    r = lub_lsq_interpolate(&o, xt, X, 1, NULL, 1, F, val, gr, NULL);
    CHECK(r.status == LUB_LSQ_TOO_FEW && r.order == 0 && r.n == 1);
    CHECK_NEAR(val[0], 1.0, 0);

    /* none within re: nothing written */
    size_t far[1] = {2};
    val[0] = -7;
    r = lub_lsq_interpolate(&o, xt, X, 1, far, 1, F, val, gr, NULL);
    CHECK(r.status == LUB_LSQ_EMPTY && r.order == -1 && r.n == 0);
    CHECK(val[0] == -7);
    CHECK(strcmp(lub_lsq_status_name(LUB_LSQ_TOO_FEW), "too few neighbours") == 0);

    /* order 2 with 5 good neighbours (6 terms): too few for order 2, order 1 exact */
    const double off[5][2] = {{1, 0}, {-1, 0.2}, {0.1, 1}, {0.3, -1.1}, {1.2, 1.3}};
    for (int j = 0; j < 5; j++) {
        px[0][j] = xt[0] + off[j][0] * l0, px[1][j] = xt[1] + off[j][1] * l0;
        fld[0][j] = 2.0 + 3e4 * (px[0][j] - xt[0]) - 5e4 * (px[1][j] - xt[1]);
    }
    o.order = 2;
    r = lub_lsq_interpolate(&o, xt, X, 5, NULL, 1, F, val, gr, NULL);
    CHECK(r.status == LUB_LSQ_TOO_FEW && r.order == 1 && r.n == 5);
    CHECK_NEAR(val[0], 2.0, 1e-13);
    CHECK_REL(gr[0][0], 3e4, 1e-10);
    CHECK_REL(gr[0][1], -5e4, 1e-10);
}

/* Collinear neighbours in 2-D (any direction, also through the target or off it, and nearly
 * collinear): singular; coplanar in 3-D: singular. */
static void test_collinear_singular(void)
{
    const double l0 = 5e-6, re = 3.1 * l0, xt[3] = {-0.0036, 3e-5, 0};
    lub_lsq_options o = lub_lsq_defaults(2, l0, re);
    const double dirs[3][2] = {{1, 0}, {0, 1}, {0.6, 0.8}};
    for (int t = 0; t < 3; t++)
        for (int shifted = 0; shifted < 2; shifted++) {
            /* 7 points on a line, through xt or 0.7 l0 beside it */
            for (int j = 0; j < 7; j++) {
                double s = (j - 3) * 0.8 * l0, n = shifted ? 0.7 * l0 : 0.0;
                px[0][j] = xt[0] + s * dirs[t][0] - n * dirs[t][1];
                px[1][j] = xt[1] + s * dirs[t][1] + n * dirs[t][0];
                px[2][j] = 0;
                fld[0][j] = 1.0 + j;
            }
            double val[1], gr[1][3];
            lub_lsq_result r = lub_lsq_interpolate(&o, xt, X, 7, NULL, 1, F, val, gr, NULL);
            if (r.status != LUB_LSQ_SINGULAR || r.order != 0)
                printf("  direction %d shifted %d: status %d order %d rcond %g\n", t, shifted,
                       r.status, r.order, r.rcond);
            CHECK(r.status == LUB_LSQ_SINGULAR);
            CHECK(r.order == 0);
            CHECK(isfinite(val[0]) && val[0] >= 1.0 && val[0] <= 7.0);
        }
    /* nearly collinear: 1e-6 l0 off the line */
    for (int j = 0; j < 7; j++) {
        px[0][j] = xt[0] + (j - 3) * 0.8 * l0;
        px[1][j] = xt[1] + (j % 2 ? 1e-6 : 0.0) * l0;
    }
    double val[1], gr[1][3];
    lub_lsq_result r = lub_lsq_interpolate(&o, xt, X, 7, NULL, 1, F, val, gr, NULL);
    CHECK(r.status == LUB_LSQ_SINGULAR && r.order == 0);
    /* coplanar in 3-D: a 5 x 5 patch in the plane z = 0.3 l0 */
    lub_lsq_options o3 = lub_lsq_defaults(3, l0, re);
    size_t n = 0;
    for (int b = -2; b <= 2; b++)
        for (int a = -2; a <= 2; a++, n++) {
            px[0][n] = xt[0] + a * l0, px[1][n] = xt[1] + b * l0, px[2][n] = 0.3 * l0;
            fld[0][n] = a + 2.0 * b;
        }
    const double xt3[3] = {xt[0], xt[1], 0};
    r = lub_lsq_interpolate(&o3, xt3, X, n, NULL, 1, F, val, gr, NULL);
    CHECK(r.status == LUB_LSQ_SINGULAR && r.order == 0);
}

/* Two rows of particles (a film two particles thick): the second derivative across the rows
 * is undetermined, order 2 falls back to order 1, which is exact for a linear field. */
static void test_second_order_fallback(void)
{
    const double l0 = 5e-6, re = 3.1 * l0, xt[3] = {0.0012, 0.4 * l0, 0};
    lub_lsq_options o = lub_lsq_defaults(2, l0, re);
    o.order = 2;
    size_t n = 0;
    for (int row = 0; row < 2; row++)
        for (int a = -4; a <= 4; a++, n++) {
            px[0][n] = xt[0] + (a + 0.5 * row) * l0;
            px[1][n] = row * l0;
            px[2][n] = 0;
            fld[0][n] = 0.7 - 2e3 * (px[0][n] - xt[0]) + 9e3 * px[1][n];
        }
    double val[1], gr[1][3], he[1][6];
    lub_lsq_result r = lub_lsq_interpolate(&o, xt, X, n, NULL, 1, F, val, gr, he);
    CHECK(r.status == LUB_LSQ_SINGULAR);
    CHECK(r.order == 1);
    CHECK(r.rcond > 1e-6);
    CHECK_NEAR(val[0], 0.7 + 9e3 * xt[1], 1e-13);
    CHECK_REL(gr[0][0], -2e3, 1e-10);
    CHECK_REL(gr[0][1], 9e3, 1e-10);
    CHECK(he[0][0] == 0 && he[0][1] == 0 && he[0][3] == 0);
}

/* A one-sided neighbourhood (target on a free surface, sources below it only) is regular for
 * order 1; candidates given by an index list that includes far particles. */
static void test_one_sided_and_index_list(void)
{
    const double l0 = 4e-5, re = 3.1 * l0, c[3] = {0.004, 0, 0};
    size_t n = jittered_lattice(2, l0, c, 6 * l0, 0.2);
    size_t idx[NMAX], m = 0;
    for (size_t j = 0; j < n; j++)
        if (px[1][j] <= 0.0) idx[m++] = j; /* lower half only, plus far ones (beyond re) */
    for (size_t j = 0; j < n; j++) fld[0][j] = -3.0 + 1e4 * (px[0][j] - c[0]) + 4e4 * px[1][j];
    lub_lsq_options o = lub_lsq_defaults(2, l0, re);
    const double xt[3] = {c[0] + 0.3 * l0, 0.1 * l0, 0};
    double val[1], gr[1][3];
    lub_lsq_result r = lub_lsq_interpolate(&o, xt, X, m, idx, 1, F, val, gr, NULL);
    CHECK(r.status == LUB_LSQ_OK && r.order == 1);
    CHECK(r.n < (int)m);
    printf("  one-sided: %d neighbours of %zu candidates, rcond %.3f\n", r.n, m, r.rcond);
    CHECK_NEAR(val[0], -3.0 + 1e4 * 0.3 * l0 + 4e4 * 0.1 * l0, 1e-12 * 3.0);
    CHECK_REL(gr[0][0], 1e4, 1e-10);
    CHECK_REL(gr[0][1], 4e4, 1e-10);
}

/* Periodic x: a target just inside the upper end of the period sees particles wrapped to
 * the lower end; the field is linear in the unwrapped coordinate. */
static void test_periodic_image(void)
{
    const double l0 = 4e-5, re = 3.1 * l0, lo = -0.01, hi = 0.01, period = hi - lo;
    const double xt[3] = {hi - 0.5 * l0, 3e-5, 0};
    size_t n = 0;
    for (int b = -3; b <= 3; b++)
        for (int a = -4; a <= 4; a++, n++) {
            double xu = xt[0] + (a + 0.1 * b) * l0; /* unwrapped */
            px[0][n] = xu >= hi ? xu - period : xu;
            px[1][n] = xt[1] + b * l0 * 0.9;
            px[2][n] = 0;
            fld[0][n] = 1.5 + 2e3 * (xu - xt[0]) - 1e3 * (px[1][n] - xt[1]);
        }
    lub_lsq_options o = lub_lsq_defaults(2, l0, re);
    o.period[0] = period;
    double val[1], gr[1][3];
    lub_lsq_result r = lub_lsq_interpolate(&o, xt, X, n, NULL, 1, F, val, gr, NULL);
    CHECK(r.status == LUB_LSQ_OK);
    CHECK_NEAR(val[0], 1.5, 1e-12 * 1.5);
    CHECK_REL(gr[0][0], 2e3, 1e-10);
    /* without the period the wrapped particles are out of reach: still a fit, fewer points */
    o.period[0] = 0;
    lub_lsq_result r2 = lub_lsq_interpolate(&o, xt, X, n, NULL, 1, F, val, gr, NULL);
    CHECK(r2.n < r.n);
}

int main(void)
{
    RUN(test_linear_exact_2d);
    RUN(test_linear_exact_3d);
    RUN(test_quadratic_exact_second_order);
    RUN(test_too_few_neighbours);
    RUN(test_collinear_singular);
    RUN(test_second_order_fallback);
    RUN(test_one_sided_and_index_list);
    RUN(test_periodic_image);
    return test_summary();
}
