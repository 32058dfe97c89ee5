/* Unit tests of src/reynolds/ehl: the soft-EHL Reynolds reference (Reynolds equation, half-space
 * deformation and load balance solved together).
 *
 * Independent references:
 *   - rigid limit (E -> infinity): the closed-form Reynolds solution of a rigid cylinder with
 *     the inlet at xa (tests/unit/reynolds_test.c derives it): with a = sqrt(2 R h0),
 *     W = -(12 mu U R / h0) J, J = (1/2)[-1/(2 us) + 1/ua - us/(2 ua^2)], us = 1 + t^2,
 *     ua = 1 + (xa/a)^2, and t the exit parameter (b = a t) solving
 *     A(g*) - A(ga) - t^2 (B(g*) - B(ga)) = 0, A(g) = g/8 - sin(4g)/32,
 *     B(g) = 3g/8 + sin(2g)/4 + sin(4g)/32, g* = atan t, ga = atan(xa/a).
 *     Given W, h0 follows by a fixed-point iteration (a depends on h0).
 *   - the discrete equations themselves, rebuilt here from the returned p and h0 with the
 *     displacement summed directly (lub_elastic_displacement_direct): the Reynolds
 *     complementarity conditions, the gap formula (T-50) and the load, to round-off;
 *   - the dry Hertz limit: as the speed falls at fixed load the pressure tends to
 *     p_H sqrt(1 - x^2/b^2) (T-49, T-55) and the central film becomes flat; and the film
 *     follows the elastic-isoviscous asymptote h ~ (mu U)^(3/5) W^(-1/5) of the literature
 *     (Herrebrugh 1968; Moes' line-contact asymptotes): only the speed exponent is checked;
 *   - grid refinement: the scheme is second order, so differences between successive grids
 *     fall by 4 when the cell is halved.
 */
#include <stdlib.h>

#include "models/elastic.h"
#include "reynolds/ehl.h"
#include "test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* the thesis' soft-EHL case (methods.md 6.2) */
static const double R = 0.01, U1 = 0.8, MU = 810.0 * 4.5e-4, W = 1000.0, E = 1.966e7;

typedef struct {
    lub_ehl_problem pb;
    lub_ehl_result res;
    double *p, *h, *v;
    lub_ehl_status st;
} run_t;

static void run_make(run_t *r, int n, double xa, double xb, double u1, double e_mod)
{
    lub_ehl_problem_init(&r->pb);
    r->pb.n = n;
    r->pb.xa = xa;
    r->pb.xb = xb;
    r->pb.u1 = u1;
    r->pb.mu = MU;
    r->pb.radius = R;
    r->pb.E = e_mod;
    r->pb.load = W;
    r->p = calloc((size_t)n + 1, sizeof(double));
    r->h = calloc((size_t)n + 1, sizeof(double));
    r->v = calloc((size_t)n + 1, sizeof(double));
    r->res = (lub_ehl_result){.p = r->p, .h = r->h, .v = r->v};
}

static void run_solve(run_t *r)
{
    r->st = lub_ehl_solve(&r->pb, &r->res);
}

static void run_free(run_t *r)
{
    free(r->p);
    free(r->h);
    free(r->v);
}

/* ---- rigid closed form -------------------------------------------------------------------- */

static double fa(double g)
{
    return g / 8.0 - sin(4.0 * g) / 32.0;
}
static double fb(double g)
{
    return 3.0 * g / 8.0 + sin(2.0 * g) / 4.0 + sin(4.0 * g) / 32.0;
}

static double exit_t(double ga)
{
    double lo = 1e-9, hi = M_PI / 2 - 1e-9;
    for (int it = 0; it < 200; it++) {
        double g = 0.5 * (lo + hi), t = tan(g);
        if (fa(g) - fa(ga) - t * t * (fb(g) - fb(ga)) > 0.0)
            lo = g;
        else
            hi = g;
    }
    return tan(0.5 * (lo + hi));
}

/* h0 of a rigid cylinder carrying W with the inlet at xa, and its exit */
static double rigid_h0(double xa, double u, double *x_exit)
{
    double h0 = 2.448 * MU * u * R / W;
    for (int it = 0; it < 200; it++) {
        double a = sqrt(2.0 * R * h0), t = exit_t(atan(xa / a));
        double us = 1.0 + t * t, xia = xa / a, ua = 1.0 + xia * xia;
        double j = 0.5 * (-1.0 / (2.0 * us) + 1.0 / ua - us / (2.0 * ua * ua));
        h0 = -12.0 * MU * u * R * j / W;
        *x_exit = a * t;
    }
    return h0;
}

static void test_rigid_limit(void)
{
    double xa = -0.0025, xb = 0.0012, xe;
    double h0 = rigid_h0(xa, U1, &xe);
    double a = sqrt(2.0 * R * h0);
    run_t r;
    run_make(&r, 800, xa, xb, U1, 1e15); /* 4 W/(pi E) = 1.3e-12 m: rigid to 1e-7 */
    run_solve(&r);
    CHECK(r.st == LUB_EHL_OK);
    double dx = (xb - xa) / 800;
    printf("  rigid limit: h_min %.9e (closed form %.9e), exit %.6e (%.6e), %d iterations\n",
           r.res.h_min, h0, r.res.x_exit, xe, r.res.iterations);
    CHECK_REL(r.res.h_min, h0, 4.0 * (dx / a) * (dx / a) + 1e-6);
    CHECK_NEAR(r.res.x_exit, xe, 0.02 * dx + (dx / a) * (dx / a) * a);
    CHECK_REL(r.res.h0_rigid, h0, 4.0 * (dx / a) * (dx / a));
    CHECK_NEAR(r.res.x_min, 0.0, dx);
    CHECK(r.res.iterations <= 6);
    run_free(&r);
}

/* ---- the discrete equations, rebuilt independently ---------------------------------------- */

static void test_discrete_equations(void)
{
    int n = 400;
    double xa = -0.0025, xb = 0.0015;
    run_t r;
    run_make(&r, n, xa, xb, U1, E);
    run_solve(&r);
    CHECK(r.st == LUB_EHL_OK);
    double dx = (xb - xa) / n, b = lub_elastic_hertz_half_width(W, R, E);
    CHECK_REL(r.res.b, b, 1e-15);
    double *x = malloc((n + 1) * sizeof *x), *xf = malloc(n * sizeof *xf);
    double *l = malloc((n + 1) * sizeof *l), *v = malloc((n + 1) * sizeof *v);
    double *vf = malloc(n * sizeof *vf);
    for (int i = 0; i <= n; i++) {
        x[i] = xa + (xb - xa) * i / n;
        l[i] = dx;
    }
    for (int f = 0; f < n; f++) xf[f] = xa + (f + 0.5) * dx;
    lub_elastic_displacement_direct(n + 1, x, l, n + 1, x, E, b, r.p, v);
    lub_elastic_displacement_direct(n + 1, x, l, n, xf, E, b, r.p, vf);
    /* T-50 at the nodes; the displacement returned */
    double eh = 0.0, ev = 0.0, hmin = INFINITY, load = 0.0;
    for (int i = 0; i <= n; i++) {
        double h = r.res.h0 + x[i] * x[i] / (2.0 * R) + v[i];
        eh = fmax(eh, fabs(h - r.h[i]));
        ev = fmax(ev, fabs(v[i] - r.v[i]));
        hmin = fmin(hmin, r.h[i]);
        if (i < n) load += 0.5 * (r.p[i] + r.p[i + 1]) * dx;
    }
    CHECK(eh < 1e-12 * hmin);
    CHECK(ev < 1e-12 * hmin);
    CHECK(hmin > 0.0);
    CHECK(r.res.h0 < 0.0); /* the rigid-body position is negative: v(0) >> film */
    /* load balance (trapezoid rule) */
    printf("  load %.12f N/m (W = %g), error %.2e, h0 = %.6e m, h_min = %.6e m\n", load, W,
           (load - W) / W, r.res.h0, r.res.h_min);
    CHECK_REL(load, W, 1e-9);
    CHECK_REL(r.res.load, W, 1e-9);
    /* the Reynolds complementarity conditions with the face gaps h0 + x_f^2/(2R) + v_f */
    double c = 1.0 / (12.0 * MU * dx), um = 0.5 * U1, scale = 0.0, rmax = 0.0, wmin = 0.0;
    int neg = 0;
    for (int i = 1; i < n; i++) {
        double hl = r.res.h0 + xf[i - 1] * xf[i - 1] / (2.0 * R) + vf[i - 1];
        double hr = r.res.h0 + xf[i] * xf[i] / (2.0 * R) + vf[i];
        double kl = hl * hl * hl * c, kr = hr * hr * hr * c;
        double w = kl * (r.p[i] - r.p[i - 1]) + kr * (r.p[i] - r.p[i + 1]) + um * (hr - hl);
        scale = fmax(scale, fabs(um * (hr - hl)));
        neg += r.p[i] < 0.0;
        if (r.p[i] > 0.0)
            rmax = fmax(rmax, fabs(w));
        else
            wmin = fmin(wmin, w);
    }
    printf("  Reynolds residual %.2e, complementarity %.2e (of the Couette term %.2e), "
           "%d cavitated, exit %.6e m\n",
           rmax, wmin, scale, r.res.n_cavitated, r.res.x_exit);
    CHECK(neg == 0);
    CHECK(rmax < 1e-8 * scale);
    CHECK(wmin > -1e-8 * scale);
    CHECK(r.res.n_cavitated > 0 && r.res.x_exit < xb); /* a free exit inside [xa, xb] */
    /* the thesis' stopping rule, and the exact complementarity solve on the final gap */
    CHECK(r.res.hmin_change < 1e-6);
    CHECK(r.res.lcp_diff < 1e-9);
    /* h_centre: the film at x = 0, a node here */
    CHECK_REL(r.res.h_centre, r.h[(int)lround(-xa / dx)], 1e-12);
    free(x);
    free(xf);
    free(l);
    free(v);
    free(vf);
    run_free(&r);
}

/* ---- translation and an extra undeformed shape --------------------------------------------- */

static void test_shift_and_shape(void)
{
    int n = 200;
    double xa = -0.0025, xb = 0.0015, dx = (xb - xa) / n;
    run_t a, s, c;
    run_make(&a, n, xa, xb, U1, E);
    run_solve(&a);
    /* the cylinder 10 cells downstream, the grid too: the same solution */
    run_make(&s, n, xa + 10 * dx, xb + 10 * dx, U1, E);
    s.pb.x_centre = 10 * dx;
    run_solve(&s);
    /* a lower wall 1 um lower everywhere: shape = +1e-6, h0 1 um smaller, p the same */
    double *sh = malloc((n + 1) * sizeof *sh), *shf = malloc(n * sizeof *shf);
    for (int i = 0; i <= n; i++) sh[i] = 1e-6;
    for (int f = 0; f < n; f++) shf[f] = 1e-6;
    run_make(&c, n, xa, xb, U1, E);
    c.pb.shape = sh;
    c.pb.shape_face = shf;
    run_solve(&c);
    CHECK(a.st == LUB_EHL_OK && s.st == LUB_EHL_OK && c.st == LUB_EHL_OK);
    double dps = 0.0, dpc = 0.0, dh = 0.0, pmax = a.res.p_max;
    for (int i = 0; i <= n; i++) {
        dps = fmax(dps, fabs(s.p[i] - a.p[i]));
        dpc = fmax(dpc, fabs(c.p[i] - a.p[i]));
        dh = fmax(dh, fabs(c.h[i] - a.h[i]));
    }
    CHECK(dps < 1e-8 * pmax);
    CHECK(dpc < 1e-8 * pmax);
    CHECK(dh < 1e-8 * a.res.h_min);
    CHECK_NEAR(c.res.h0, a.res.h0 - 1e-6, 1e-8 * a.res.h_min);
    CHECK_NEAR(s.res.x_max, a.res.x_max + 10 * dx, 1e-9 * dx + 1e-12);
    CHECK_REL(s.res.h_centre, a.res.h_centre, 1e-9);
    free(sh);
    free(shf);
    run_free(&a);
    run_free(&s);
    run_free(&c);
}

/* ---- grid refinement -------------------------------------------------------------------- */

static void test_grid_convergence(void)
{
    int ns[4] = {100, 200, 400, 800};
    double h0[4], pm[4], hm[4];
    for (int g = 0; g < 4; g++) {
        run_t r;
        run_make(&r, ns[g], -0.0025, 0.0012, U1, E);
        run_solve(&r);
        CHECK(r.st == LUB_EHL_OK);
        h0[g] = r.res.h0;
        pm[g] = r.res.p_max;
        hm[g] = r.res.h_min;
        printf("  %4d cells: h0 %.10e  h_min %.10e  p_max %.8e  (%d iterations, %d stages)\n",
               ns[g], h0[g], hm[g], pm[g], r.res.iterations, r.res.stages);
        run_free(&r);
    }
    /* observed order from three successive grids: log2 of the ratio of differences */
    for (int g = 0; g < 2; g++) {
        double o_h0 = log2(fabs(h0[g + 1] - h0[g]) / fabs(h0[g + 2] - h0[g + 1]));
        double o_pm = log2(fabs(pm[g + 1] - pm[g]) / fabs(pm[g + 2] - pm[g + 1]));
        double o_hm = log2(fabs(hm[g + 1] - hm[g]) / fabs(hm[g + 2] - hm[g + 1]));
        printf("  observed order (%d/%d/%d cells): h0 %.2f, p_max %.2f, h_min %.2f\n", ns[g],
               ns[g + 1], ns[g + 2], o_h0, o_pm, o_hm);
        CHECK(o_h0 > 1.8 && o_h0 < 2.3);
        CHECK(o_pm > 1.8 && o_pm < 2.3);
        CHECK(o_hm > 1.5);
    }
    /* and the finest grid's discretisation error is small: Richardson estimate */
    CHECK(fabs(pm[3] - pm[2]) / 3.0 < 1e-5 * pm[3]);
    CHECK(fabs(hm[3] - hm[2]) / 3.0 < 1e-5 * hm[3]);
}

/* ---- dry Hertz limit ---------------------------------------------------------------------- */

/* L1 mean of P - sqrt(1 - X^2) over |X| < 1.5, and the flatness of the film over |X| < 1/2 */
static void hertz_errors(const run_t *r, double *l1, double *flat, double *pmax)
{
    double b = lub_elastic_hertz_half_width(W, R, E), ph = lub_elastic_hertz_pressure(W, b);
    int n = r->pb.n, cnt = 0;
    double s = 0.0, hlo = INFINITY, hhi = 0.0;
    for (int i = 0; i <= n; i++) {
        double X = (r->pb.xa + (r->pb.xb - r->pb.xa) * i / n) / b;
        if (fabs(X) > 1.5) continue;
        double ref = fabs(X) < 1.0 ? sqrt(1.0 - X * X) : 0.0;
        s += fabs(r->p[i] / ph - ref);
        cnt++;
        if (fabs(X) < 0.5) {
            hlo = fmin(hlo, r->h[i]);
            hhi = fmax(hhi, r->h[i]);
        }
    }
    *l1 = s / cnt;
    *flat = (hhi - hlo) / hlo;
    *pmax = r->res.p_max / ph;
}

static void test_dry_hertz_limit(void)
{
    double speeds[3] = {0.8, 0.08, 0.008}, l1[3], flat[3], pmax[3], hc[3];
    for (int k = 0; k < 3; k++) {
        run_t r;
        run_make(&r, 300, -0.0025, 0.0015, speeds[k], E);
        run_solve(&r);
        CHECK(r.st == LUB_EHL_OK);
        hertz_errors(&r, &l1[k], &flat[k], &pmax[k]);
        hc[k] = r.res.h_centre;
        double minh = INFINITY;
        for (int i = 0; i <= 300; i++) minh = fmin(minh, r.h[i]);
        CHECK(minh > 0.0 && r.res.h0 < 0.0);
        printf("  U1 = %g: P_max %.4f, mean |P - Hertz| %.4f, central film variation %.3f, "
               "H_c = %.5f, h0 = %.4e m (%d iterations)\n",
               speeds[k], pmax[k], l1[k], flat[k], hc[k] * R / (r.res.b * r.res.b), r.res.h0,
               r.res.iterations);
        run_free(&r);
    }
    for (int k = 1; k < 3; k++) {
        CHECK(l1[k] < 0.5 * l1[k - 1]); /* the pressure approaches the Hertz ellipse */
        CHECK(flat[k] < 0.7 * flat[k - 1]);
        double expo = log(hc[k - 1] / hc[k]) / log(10.0);
        printf("  film exponent d ln h_c / d ln U = %.3f\n", expo);
        CHECK(expo > 0.55 && expo < 0.66); /* elastic-isoviscous: 3/5 */
    }
    CHECK_NEAR(pmax[2], 1.0, 0.005);
    CHECK(l1[2] < 0.02);
    CHECK(flat[2] < 0.1);
}

static void test_bad_input(void)
{
    run_t r;
    run_make(&r, 50, -0.0025, 0.0012, U1, E);
    r.pb.n = 3;
    run_solve(&r);
    CHECK(r.st == LUB_EHL_BAD_INPUT);
    r.pb.n = 50;
    r.pb.E = 0.0;
    run_solve(&r);
    CHECK(r.st == LUB_EHL_BAD_INPUT);
    r.pb.E = E;
    r.pb.load = -1.0;
    run_solve(&r);
    CHECK(r.st == LUB_EHL_BAD_INPUT);
    r.pb.load = W;
    r.pb.u1 = 0.0;
    run_solve(&r);
    CHECK(r.st == LUB_EHL_BAD_INPUT);
    r.pb.u1 = U1;
    r.pb.xb = r.pb.xa;
    run_solve(&r);
    CHECK(r.st == LUB_EHL_BAD_INPUT);
    r.pb.xb = 0.0012;
    double sh[51];
    r.pb.shape = sh; /* without shape_face */
    run_solve(&r);
    CHECK(r.st == LUB_EHL_BAD_INPUT);
    r.pb.shape = NULL;
    r.pb.max_iterations = 1; /* too few to converge */
    run_solve(&r);
    CHECK(r.st == LUB_EHL_NOT_CONVERGED);
    CHECK_STR(lub_ehl_status_string(LUB_EHL_NOT_CONVERGED), "did not converge");
    run_free(&r);
}

int main(void)
{
    (void)test_last_error;
    RUN(test_rigid_limit);
    RUN(test_discrete_equations);
    RUN(test_shift_and_shape);
    RUN(test_grid_convergence);
    RUN(test_dry_hertz_limit);
    RUN(test_bad_input);
    return test_summary();
}
