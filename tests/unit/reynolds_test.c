/* Unit tests of src/reynolds: the 1-D Reynolds solver against closed-form solutions.
 *
 * Rigid cylinder over a plane, h = h0 + x^2/(2R).  With a = sqrt(2 R h0), x = a xi,
 * xi = tan(gamma), h = h0 sec^2(gamma).  Integrating the flux form once,
 *     h^3/(12 mu) dp/dx = U/2 (h - h*),   U = U1 + U2,  h* = h0 (1 + t^2) the gap where
 * dp/dx = 0, so dp = (6 mu U a / h0^2) (xi^2 - t^2)/(1 + xi^2)^3 dxi
 *                  = (6 mu U a / h0^2) (sin^2 g cos^2 g - t^2 cos^4 g) dg, and
 *     p(gamma) = (6 mu U a / h0^2) [A(g) - A(ga) - t^2 (B(g) - B(ga))],
 *     A(g) = g/8 - sin(4g)/32,  B(g) = 3g/8 + sin(2g)/4 + sin(4g)/32.
 * Full Sommerfeld on [xa, xb]: p(xb) = 0 fixes t^2 = (A(gb) - A(ga)) / (B(gb) - B(ga)).
 * Reynolds condition: p = dp/dx = 0 at the exit b = a t, so t solves
 *     A(g*) - A(ga) - tan^2(g*) (B(g*) - B(ga)) = 0,   g* = atan(t);
 * for ga -> -pi/2 this is Martin's t = 0.475 (T-37).
 * Load: W = int p dx = [x p] - int x dp = -int x dp (p = 0 at both ends), and with
 * u = 1 + xi^2 (du = 2 xi dxi), x dp = (6 mu U a^2/h0^2) (u - us)/(2 u^3) du, so
 *     W = -(12 mu U R / h0) J,  J = 1/2 [ -1/(2 us) + 1/ua - us/(2 ua^2) ],
 * us = 1 + t^2, ua = 1 + xi_a^2; for xi_a -> -inf, W = 3 mu U R / (h0 (1 + t^2)), the
 * classical 2.448 mu U R / h0.
 */
#include <stdlib.h>

#include "reynolds/reynolds.h"
#include "test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* thesis wedge (methods.md 6.1) */
static const double R = 0.04, H0 = 4.0e-5, U1 = 1.2, MU = 850.0 * 2.25e-4;

static double fa(double g)
{
    return g / 8.0 - sin(4.0 * g) / 32.0;
}
static double fb(double g)
{
    return 3.0 * g / 8.0 + sin(2.0 * g) / 4.0 + sin(4.0 * g) / 32.0;
}
static double cyl_a(void)
{
    return sqrt(2.0 * R * H0);
}
static double cyl_h(double x)
{
    return H0 + x * x / (2.0 * R);
}

/* closed-form pressure for the flux parameter t2 = t^2, inlet xa */
static double cyl_p(double x, double xa, double t2, double u)
{
    double a = cyl_a(), g = atan(x / a), ga = atan(xa / a);
    return 6.0 * MU * u * a / (H0 * H0) * (fa(g) - fa(ga) - t2 * (fb(g) - fb(ga)));
}

static double cyl_t2_sommerfeld(double xa, double xb)
{
    double ga = atan(xa / cyl_a()), gb = atan(xb / cyl_a());
    return (fa(gb) - fa(ga)) / (fb(gb) - fb(ga));
}

/* Reynolds exit parameter t (b = a t) by bisection; ga = -pi/2 for an inlet at -infinity */
static double cyl_t_reynolds(double ga)
{
    double lo = 1e-9, hi = M_PI / 2 - 1e-9;
    for (int it = 0; it < 200; it++) {
        double g = 0.5 * (lo + hi), t = tan(g);
        double v = fa(g) - fa(ga) - t * t * (fb(g) - fb(ga));
        if (v > 0.0)
            lo = g;
        else
            hi = g;
    }
    return tan(0.5 * (lo + hi));
}

static double cyl_load_reynolds(double xa, double t, double u)
{
    double us = 1.0 + t * t, xia = xa / cyl_a(), ua = 1.0 + xia * xia;
    double j = 0.5 * (-1.0 / (2.0 * us) + 1.0 / ua - us / (2.0 * ua * ua));
    return -12.0 * MU * u * R / H0 * j;
}

/* A problem on [xa, xb] with n cells, h from f at nodes (and exact face values if faces). */
typedef struct {
    lub_reynolds_problem pb;
    lub_reynolds_result res;
    double *h, *hf, *p;
} setup;

static void setup_make(setup *s, int n, double xa, double xb, double (*f)(double), int faces)
{
    lub_reynolds_problem_init(&s->pb);
    s->pb.n = n;
    s->pb.xa = xa;
    s->pb.xb = xb;
    s->pb.mu = MU;
    s->h = malloc((size_t)(n + 1) * sizeof(double));
    s->hf = malloc((size_t)n * sizeof(double));
    s->p = malloc((size_t)(n + 1) * sizeof(double));
    double dx = (xb - xa) / n;
    for (int i = 0; i <= n; i++) s->h[i] = f(xa + i * dx);
    for (int i = 0; i < n; i++) s->hf[i] = f(xa + (i + 0.5) * dx);
    s->pb.h = s->h;
    s->pb.h_face = faces ? s->hf : NULL;
    s->res.p = s->p;
}

static void setup_free(setup *s)
{
    free(s->h);
    free(s->hf);
    free(s->p);
}

/* Reynolds condition, rigid cylinder, inlet far upstream: exit and load against the closed
 * forms above, and Martin's 0.475. */
static void test_cylinder_reynolds(void)
{
    double a = cyl_a();
    /* Martin's constant is the xi_a -> -inf root, to the three digits he gives */
    double t_inf = cyl_t_reynolds(-M_PI / 2);
    CHECK_NEAR(t_inf, 0.475, 0.0005);
    /* classical load coefficient 2.448 (4.896 with the mean speed), to its four digits */
    CHECK_NEAR(3.0 / (1.0 + t_inf * t_inf), 2.448, 0.0006);

    double xa = -20.0 * a, xb = 2.0 * a;
    double t_fin = cyl_t_reynolds(atan(xa / a));
    double w_ref = cyl_load_reynolds(xa, t_fin, U1);
    double err_b[2], err_w[2];
    for (int g = 0; g < 2; g++) {
        int n = g == 0 ? 2200 : 4400; /* dx = a/100, a/200 */
        double dx = (xb - xa) / n;
        setup s;
        setup_make(&s, n, xa, xb, cyl_h, 1);
        s.pb.u1 = U1;
        CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
        /* the discrete complementarity problem puts the free exit between two nodes; the
         * flux-based exit (dp/dx = 0 where q = Um h) is second order: within a (dx/a)^2
         * fraction of a, i.e. a hundredth / two-hundredth of a cell here */
        CHECK_NEAR(s.res.x_exit, a * t_fin, (dx / a) * (dx / a) * a);
        /* the inlet at -20 a moves the exit from Martin's by t_fin - t_inf (about 4e-5 a);
         * Martin's value is given to 0.0005 */
        CHECK_NEAR(s.res.x_exit, 0.475 * a, 0.0005 * a + fabs(t_fin - t_inf) * a + dx);
        /* second-order scheme: the relative load error is O((dx/a)^2) = 1e-4 .. 2.5e-5 */
        CHECK_REL(s.res.load, w_ref, (dx / a) * (dx / a));
        err_b[g] = fabs(s.res.x_exit - a * t_fin);
        err_w[g] = fabs(s.res.load - w_ref);
        /* p >= 0 everywhere, p = 0 beyond the exit */
        int neg = 0, beyond = 0;
        for (int i = 0; i <= n; i++) {
            double x = xa + i * dx;
            neg += s.p[i] < 0.0;
            if (x > s.res.x_exit + dx) beyond += s.p[i] != 0.0;
        }
        CHECK(neg == 0);
        CHECK(beyond == 0);
        /* the whole pressure curve: second-order accurate against the closed form */
        double emax = 0.0;
        for (int i = 0; i <= n; i++) {
            double x = xa + i * dx;
            double pr = x < a * t_fin ? cyl_p(x, xa, t_fin * t_fin, U1) : 0.0;
            emax = fmax(emax, fabs(s.p[i] - pr));
        }
        CHECK(emax < (dx / a) * (dx / a) * s.res.p_max);
        CHECK_REL(s.res.p_max, cyl_p(-a * t_fin, xa, t_fin * t_fin, U1), (dx / a) * (dx / a));
        CHECK_NEAR(s.res.x_max, -a * t_fin, dx);
        CHECK(s.res.iterations <= 2); /* projected sweep exact, one confirming solve */
        printf("  n %d: exit/a %.7f (exact %.7f), W %.6f (exact %.6f), p err %.2e, Pmax %.5f, "
               "it %d\n",
               n, s.res.x_exit / a, t_fin, s.res.load, w_ref, emax / s.res.p_max,
               s.res.p_max * pow(H0, 1.5) / (MU * U1 * sqrt(R)), s.res.iterations);
        setup_free(&s);
    }
    /* refinement: the load error falls at least like dx^1.5 (by 2.8 for a halved cell); the
     * exit error is far below its bound on both grids and not monotone (it depends on where
     * the exit falls between faces) */
    printf("  exit errors/a %.3e %.3e, load errors %.3e %.3e\n", err_b[0] / a, err_b[1] / a,
           err_w[0], err_w[1]);
    CHECK(err_w[1] < err_w[0] / 2.8);
}

/* Cylinder squeezed toward the plane at V while the plane slides, Reynolds condition.  With
 * dh/dt = -V the flux grows as q = q0 + V x, so h^3/(12 mu) dp/dx = Um h - q0 - V x; with
 * h = h0 u, u = 1 + xi^2, x = a xi:  p(b) = 0 reads
 *     Um h0 I2 - q0 I3 - V a J3 = 0  over [xi_a, xi_b],
 * I2 = int dxi/u^2 = [g/2 + sin(2g)/4], I3 = int dxi/u^3 = B(g), J3 = int xi dxi/u^3 =
 * [-1/(4 u^2)], and dp/dx(b) = 0 gives q0 = Um h0 u_b - V a xi_b: one equation for xi_b. */
static double squeeze_exit_eq(double xib, double xia, double um, double v)
{
    double a = cyl_a(), gb = atan(xib), ga = atan(xia), ub = 1 + xib * xib, ua = 1 + xia * xia;
    double i2 = gb / 2 + sin(2 * gb) / 4 - ga / 2 - sin(2 * ga) / 4;
    double i3 = fb(gb) - fb(ga), j3 = -1.0 / (4 * ub * ub) + 1.0 / (4 * ua * ua);
    double q0 = um * H0 * ub - v * a * xib;
    return um * H0 * i2 - q0 * i3 - v * a * j3;
}

static void test_cylinder_squeeze_reynolds(void)
{
    double a = cyl_a(), xa = -20.0 * a, xb = 2.0 * a, v = 0.005, um = 0.5 * U1;
    double lo = 1e-6, hi = 1.9;
    double glo = squeeze_exit_eq(lo, xa / a, um, v), ghi = squeeze_exit_eq(hi, xa / a, um, v);
    CHECK(glo * ghi < 0.0);
    for (int it = 0; it < 200; it++) {
        double mid = 0.5 * (lo + hi), g = squeeze_exit_eq(mid, xa / a, um, v);
        if ((g > 0) == (glo > 0))
            lo = mid;
        else
            hi = mid;
    }
    double xib = 0.5 * (lo + hi);
    int n = 4400;
    double dx = (xb - xa) / n;
    setup s;
    setup_make(&s, n, xa, xb, cyl_h, 1);
    s.pb.u1 = U1;
    s.pb.dhdt = -v;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
    CHECK_NEAR(s.res.x_exit, a * xib, (dx / a) * (dx / a) * a);
    CHECK(xib > 0.6); /* the squeeze moves the exit well past the sliding-only 0.475 */
    printf("  squeeze + sliding: exit/a %.7f (exact %.7f)\n", s.res.x_exit / a, xib);
    setup_free(&s);
}

/* Flow from right to left: the mirror image (tests the reversed projected sweep). */
static void test_cylinder_reversed(void)
{
    double a = cyl_a(), xa = -3.0 * a, xb = 3.0 * a;
    int n = 3000;
    setup s, r;
    setup_make(&s, n, xa, xb, cyl_h, 0);
    setup_make(&r, n, xa, xb, cyl_h, 0);
    s.pb.u1 = U1;
    r.pb.u1 = -U1;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
    CHECK(lub_reynolds_solve(&r.pb, &r.res) == LUB_REYNOLDS_OK);
    double d = 0.0;
    for (int i = 0; i <= n; i++) d = fmax(d, fabs(s.p[i] - r.p[n - i]));
    CHECK(d <= 1e-9 * s.res.p_max);
    CHECK_REL(r.res.load, s.res.load, 1e-12);
    CHECK(r.res.iterations <= 2);
    setup_free(&s);
    setup_free(&r);
}

/* Parallel plates, upper plate approaching at V: h'' p = -12 mu V / h^3 ... the parabola
 * p = 6 mu V (x - xa)(xb - x)/h^3 (positive: the film is squeezed out).  Second differences
 * are exact on a parabola, so the nodal values are exact to round-off, and the trapezoid
 * load misses exactly L dx^2 |p''|/12 = mu V L^3/h^3 / n^2. */
static double plate_h(double x)
{
    (void)x;
    return 2.0e-5;
}

static void test_squeeze_film(void)
{
    double xa = -0.001, xb = 0.002, v = 0.01, hh = 2.0e-5, l = xb - xa;
    int n = 300;
    for (int bc = 0; bc < 3; bc++) {
        setup s;
        setup_make(&s, n, xa, xb, plate_h, 0);
        s.pb.dhdt = -v;
        s.pb.bc =
            bc == 0 ? LUB_REYNOLDS_BC_REYNOLDS
                    : (bc == 1 ? LUB_REYNOLDS_BC_FULL_SOMMERFELD : LUB_REYNOLDS_BC_HALF_SOMMERFELD);
        CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
        double pc = 6.0 * MU * v * (l / 2) * (l / 2) / (hh * hh * hh);
        double e = 0.0;
        for (int i = 0; i <= n; i++) {
            double x = xa + i * l / n;
            e = fmax(e, fabs(s.p[i] - 6.0 * MU * v * (x - xa) * (xb - x) / (hh * hh * hh)));
        }
        CHECK(e <= 1e-9 * pc);
        CHECK_REL(s.res.p_max, pc, 1e-12);
        CHECK_NEAR(s.res.x_max, 0.5 * (xa + xb), 1e-9 * l);
        double w = MU * v * l * l * l / (hh * hh * hh);
        CHECK_REL(s.res.load, w * (1.0 - 1.0 / ((double)n * n)), 1e-10);
        CHECK_NEAR(s.res.x_exit, xb, 1e-12);
        setup_free(&s);
    }
    /* the same squeeze rate given per node */
    {
        setup s;
        setup_make(&s, n, xa, xb, plate_h, 0);
        double *rate = malloc((size_t)(n + 1) * sizeof(double));
        for (int i = 0; i <= n; i++) rate[i] = -v;
        s.pb.dhdt = 123.0; /* ignored when the array is given */
        s.pb.dhdt_nodes = rate;
        CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
        CHECK_REL(s.res.p_max, 6.0 * MU * v * (l / 2) * (l / 2) / (hh * hh * hh), 1e-12);
        free(rate);
        setup_free(&s);
    }
    /* separating plates under the Reynolds condition: the film cavitates entirely */
    setup s;
    setup_make(&s, n, xa, xb, plate_h, 0);
    s.pb.dhdt = v;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
    double pm = 0.0;
    for (int i = 0; i <= n; i++) pm = fmax(pm, fabs(s.p[i]));
    CHECK(pm == 0.0);
    CHECK(s.res.load == 0.0);
    CHECK(s.res.n_cavitated == n - 1);
    CHECK(s.res.x_exit == xa);
    setup_free(&s);
}

/* Inclined-plane slider, h = h1 + (h2 - h1) x/L: h^3 p' = 6 mu U (h - hm), hm =
 * 2 h1 h2/(h1 + h2), p = 6 mu U/m [1/h1 - 1/h + hm/2 (1/h^2 - 1/h1^2)], m = dh/dx. */
static const double SL_L = 0.01, SL_H1 = 2.0e-5, SL_H2 = 1.0e-5;
static double slider_h(double x)
{
    return SL_H1 + (SL_H2 - SL_H1) * x / SL_L;
}
static double slider_p(double x)
{
    double m = (SL_H2 - SL_H1) / SL_L, hm = 2.0 * SL_H1 * SL_H2 / (SL_H1 + SL_H2);
    double h = slider_h(x);
    return 6.0 * MU * U1 / m *
           (1.0 / SL_H1 - 1.0 / h + 0.5 * hm * (1.0 / (h * h) - 1.0 / (SL_H1 * SL_H1)));
}

/* max-norm error on n cells for the slider (sl = 1) or the full-Sommerfeld cylinder */
static double grid_error(int n, int sl)
{
    double a = cyl_a();
    double xa = sl ? 0.0 : -3.0 * a, xb = sl ? SL_L : 2.0 * a;
    setup s;
    setup_make(&s, n, xa, xb, sl ? slider_h : cyl_h, 0);
    s.pb.u1 = U1;
    s.pb.bc = LUB_REYNOLDS_BC_FULL_SOMMERFELD;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
    double t2 = cyl_t2_sommerfeld(xa, xb), e = 0.0, pm = 0.0;
    for (int i = 0; i <= n; i++) {
        double x = xa + i * (xb - xa) / n;
        double pr = sl ? slider_p(x) : cyl_p(x, xa, t2, U1);
        e = fmax(e, fabs(s.p[i] - pr));
        pm = fmax(pm, fabs(pr));
    }
    setup_free(&s);
    return e / pm;
}

static void test_order_of_accuracy(void)
{
    for (int sl = 1; sl >= 0; sl--) {
        double e1 = grid_error(40, sl), e2 = grid_error(80, sl), e3 = grid_error(160, sl);
        double o1 = log2(e1 / e2), o2 = log2(e2 / e3);
        printf("  %s: errors %.3e %.3e %.3e, orders %.3f %.3f\n",
               sl ? "slider" : "cylinder (full Sommerfeld)", e1, e2, e3, o1, o2);
        CHECK(o1 >= 1.9);
        CHECK(o2 >= 1.9);
    }
}

/* Full Sommerfeld on a symmetric interval: p is odd in x (h even), so it has as much
 * suction as pressure; half Sommerfeld is the same curve with negatives set to zero. */
static void test_sommerfeld(void)
{
    double a = cyl_a(), xa = -3.0 * a, xb = 3.0 * a;
    int n = 3000;
    setup f, hs;
    setup_make(&f, n, xa, xb, cyl_h, 0);
    setup_make(&hs, n, xa, xb, cyl_h, 0);
    f.pb.u1 = hs.pb.u1 = U1;
    f.pb.bc = LUB_REYNOLDS_BC_FULL_SOMMERFELD;
    hs.pb.bc = LUB_REYNOLDS_BC_HALF_SOMMERFELD;
    CHECK(lub_reynolds_solve(&f.pb, &f.res) == LUB_REYNOLDS_OK);
    CHECK(lub_reynolds_solve(&hs.pb, &hs.res) == LUB_REYNOLDS_OK);
    double pmin = 0.0, odd = 0.0, clip = 0.0;
    int neg_half = 0;
    for (int i = 0; i <= n; i++) {
        pmin = fmin(pmin, f.p[i]);
        odd = fmax(odd, fabs(f.p[i] + f.p[n - i]));
        clip = fmax(clip, fabs(hs.p[i] - fmax(f.p[i], 0.0)));
        neg_half += hs.p[i] < 0.0;
    }
    CHECK(pmin < -0.5 * f.res.p_max);
    CHECK_REL(-pmin, f.res.p_max, 1e-6);
    CHECK(odd <= 1e-9 * f.res.p_max);
    CHECK(clip == 0.0);
    CHECK(neg_half == 0);
    CHECK_NEAR(f.res.load, 0.0, 1e-9 * hs.res.load);
    CHECK(hs.res.load > 0.0);
    /* both cross zero at the minimum gap, x = 0 (linear interpolation on an odd curve) */
    double dx = (xb - xa) / n;
    CHECK_NEAR(f.res.x_exit, 0.0, 1e-9 * dx);
    CHECK_NEAR(hs.res.x_exit, 0.0, 1e-9 * dx);
    /* the Sommerfeld peak against the closed form */
    double t2 = cyl_t2_sommerfeld(xa, xb), g = atan(sqrt(t2));
    CHECK_REL(f.res.p_max, cyl_p(-a * tan(g), xa, t2, U1), 1e-5);
    setup_free(&f);
    setup_free(&hs);
}

/* Given exit between two nodes: p = 0 there and beyond, the full-film closed form on
 * [xa, exit] elsewhere (Shortley-Weller cut cell, second order). */
static void test_given_exit(void)
{
    double a = cyl_a(), xa = -3.0 * a, xb = 2.0 * a, xe = 0.3 * a + 1e-3 * a / 7.0;
    double emax[2];
    for (int g = 0; g < 2; g++) {
        int n = g == 0 ? 500 : 1000;
        double dx = (xb - xa) / n;
        setup s;
        setup_make(&s, n, xa, xb, cyl_h, 1);
        s.pb.u1 = U1;
        s.pb.bc = LUB_REYNOLDS_BC_GIVEN_EXIT;
        s.pb.exit_x = xe;
        CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
        CHECK(s.res.x_exit == xe);
        double t2 = cyl_t2_sommerfeld(xa, xe), e = 0.0;
        int beyond = 0;
        for (int i = 0; i <= n; i++) {
            double x = xa + i * dx;
            if (x >= xe)
                beyond += s.p[i] != 0.0;
            else
                e = fmax(e, fabs(s.p[i] - cyl_p(x, xa, t2, U1)));
        }
        CHECK(beyond == 0);
        emax[g] = e / s.res.p_max;
        CHECK(emax[g] < 1e-3);
        setup_free(&s);
    }
    CHECK(emax[1] < emax[0] / 3.0);
    /* an exit on a node and an exit at the outlet */
    setup s;
    setup_make(&s, 100, 0.0, 1.0, plate_h, 0);
    s.pb.dhdt = -1e-3;
    s.pb.bc = LUB_REYNOLDS_BC_GIVEN_EXIT;
    s.pb.exit_x = 0.5;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
    CHECK(s.p[50] == 0.0 && s.p[49] > 0.0);
    CHECK_REL(s.p[25], 6.0 * MU * 1e-3 * 0.25 * 0.25 / pow(2e-5, 3), 1e-9);
    s.pb.exit_x = 1.0;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
    CHECK_REL(s.p[50], 6.0 * MU * 1e-3 * 0.5 * 0.5 / pow(2e-5, 3), 1e-9);
    setup_free(&s);
}

/* Two converging-diverging regions: the film ruptures and reforms, so the projected sweep is
 * not the answer and the active set has to correct it.  Reference: projected Gauss-Seidel
 * (an independent, slow algorithm for the same discrete problem) run to convergence. */
static double wavy_h(double x)
{
    return 3.0e-5 + 2.0e-5 * cos(4.0 * M_PI * x / 0.01);
}

static void test_rupture_and_reformation(void)
{
    int n = 200;
    setup s;
    setup_make(&s, n, 0.0, 0.01, wavy_h, 0);
    s.pb.u1 = U1;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
    /* projected Gauss-Seidel on the same finite-difference equations */
    double dx = 0.01 / n, c = 1.0 / (12.0 * MU), um = 0.5 * U1;
    double *q = calloc((size_t)n + 1, sizeof(double));
    for (int sweep = 0; sweep < 400000; sweep++) {
        double change = 0.0;
        for (int i = 1; i < n; i++) {
            double hl = 0.5 * (s.h[i - 1] + s.h[i]), hr = 0.5 * (s.h[i] + s.h[i + 1]);
            double kl = hl * hl * hl * c / dx, kr = hr * hr * hr * c / dx;
            double v = (kl * q[i - 1] + kr * q[i + 1] - um * (hr - hl)) / (kl + kr);
            v = fmax(v, 0.0);
            change = fmax(change, fabs(v - q[i]));
            q[i] = v;
        }
        if (change == 0.0) break;
    }
    double e = 0.0, pm = 0.0;
    int zero_runs = 0;
    for (int i = 0; i <= n; i++) {
        e = fmax(e, fabs(q[i] - s.p[i]));
        pm = fmax(pm, q[i]);
        if (i > 0 && i < n && s.p[i] == 0.0 && s.p[i - 1] > 0.0) zero_runs++;
    }
    CHECK(e <= 1e-9 * pm);
    CHECK(zero_runs == 2); /* two cavitated zones */
    /* the exit reported is the first rupture downstream of the peak, in the cell before the
     * first cavitated node there */
    int imax = 0, j;
    for (int i = 1; i <= n; i++)
        if (s.p[i] > s.p[imax]) imax = i;
    for (j = imax + 1; j < n && s.p[j] > 0.0; j++) continue;
    CHECK(s.res.x_exit > (j - 2) * dx && s.res.x_exit <= (j + 1) * dx);
    CHECK(s.res.iterations >= 2);
    printf("  wavy gap: %d active-set iterations, %d cavitated nodes\n", s.res.iterations,
           s.res.n_cavitated);
    free(q);
    setup_free(&s);
}

/* The same gap on a fine grid: the discrete complementarity conditions checked directly from
 * the finite-difference equations (p >= 0; w = flux imbalance >= 0 where p = 0, |w| tiny
 * where p > 0), and the active-set work stays logarithmic in n (coarse-grid start). */
static void test_rupture_fine_grid(void)
{
    int n = 3200;
    setup s;
    setup_make(&s, n, 0.0, 0.01, wavy_h, 0);
    s.pb.u1 = U1;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
    double dx = 0.01 / n, c = 1.0 / (12.0 * MU), um = 0.5 * U1;
    double wmin = 0.0, rmax = 0.0, scale = 0.0, pneg = 0.0;
    for (int i = 1; i < n; i++) {
        double hl = 0.5 * (s.h[i - 1] + s.h[i]), hr = 0.5 * (s.h[i] + s.h[i + 1]);
        double kl = hl * hl * hl * c / dx, kr = hr * hr * hr * c / dx;
        /* w = -(flux difference) + source, as the solver's sign convention M p + f */
        double w = (kl + kr) * s.p[i] - kl * s.p[i - 1] - kr * s.p[i + 1] + um * (hr - hl);
        scale = fmax(scale, fabs(um * (hr - hl)));
        pneg = fmin(pneg, s.p[i]);
        if (s.p[i] > 0.0)
            rmax = fmax(rmax, fabs(w));
        else
            wmin = fmin(wmin, w);
    }
    CHECK(pneg == 0.0);
    CHECK(rmax <= 1e-8 * scale);
    CHECK(wmin >= -1e-8 * scale);
    CHECK(s.res.iterations < 100);
    printf("  wavy gap, %d cells: %d active-set iterations\n", n, s.res.iterations);
    setup_free(&s);
}

static void test_bad_input(void)
{
    setup s;
    setup_make(&s, 10, 0.0, 1.0, plate_h, 0);
    s.pb.u1 = 1.0;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_OK);
    s.h[3] = 0.0;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_BAD_GAP);
    s.h[3] = NAN;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_BAD_GAP);
    s.h[3] = 2e-5;
    s.pb.h_face = s.hf;
    s.hf[9] = -1.0;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_BAD_GAP);
    s.pb.h_face = NULL;
    s.pb.mu = 0.0;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_BAD_INPUT);
    s.pb.mu = MU;
    s.pb.bc = LUB_REYNOLDS_BC_GIVEN_EXIT;
    s.pb.exit_x = 1.5;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_BAD_INPUT);
    s.pb.exit_x = 0.0;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_BAD_INPUT);
    s.pb.bc = LUB_REYNOLDS_BC_REYNOLDS;
    s.pb.n = 1;
    CHECK(lub_reynolds_solve(&s.pb, &s.res) == LUB_REYNOLDS_BAD_INPUT);
    CHECK_STR(lub_reynolds_status_string(LUB_REYNOLDS_NOT_CONVERGED), "converge");
    CHECK_STR(lub_reynolds_bc_names[LUB_REYNOLDS_BC_GIVEN_EXIT], "givenExit");
    CHECK(lub_reynolds_bc_names[4] == NULL);
    setup_free(&s);
}

/* Inflection points: of exp(-x^2) at -/+ 1/sqrt(2) (second order in dx); none on either side
 * of the parabola 1 - x^2 (the ends of the film instead); none of a curve nowhere positive. */
static void test_inflections(void)
{
    enum { N = 6000 };
    static double p[N + 1];
    const double xa = -3.0, xb = 3.0, dx = (xb - xa) / N;
    for (int i = 0; i <= N; i++) {
        double x = xa + i * dx;
        p[i] = exp(-x * x);
    }
    double xl = 0, xr = 0;
    CHECK(lub_reynolds_inflections(N, xa, xb, p, &xl, &xr) == 3);
    CHECK_NEAR(xl, -sqrt(0.5), 1e-5);
    CHECK_NEAR(xr, sqrt(0.5), 1e-5);
    /* shifted: the peak off the grid's middle */
    for (int i = 0; i <= N; i++) {
        double x = xa + i * dx - 0.5;
        p[i] = exp(-x * x);
    }
    CHECK(lub_reynolds_inflections(N, xa, xb, p, &xl, &xr) == 3);
    CHECK_NEAR(xl, 0.5 - sqrt(0.5), 1e-5);
    CHECK_NEAR(xr, 0.5 + sqrt(0.5), 1e-5);
    /* concave everywhere, zero at -1 and 1, cavitated (0) beyond 1 */
    for (int i = 0; i <= N; i++) {
        double x = -1.0 + i * (3.0 / N);
        p[i] = x < 1.0 ? 1.0 - x * x : 0.0;
    }
    CHECK(lub_reynolds_inflections(N, -1.0, 2.0, p, &xl, &xr) == 0);
    CHECK(xl == -1.0);
    CHECK_NEAR(xr, 1.0, 3.0 / N);
    for (int i = 0; i <= N; i++) p[i] = -1.0;
    CHECK(lub_reynolds_inflections(N, xa, xb, p, &xl, &xr) == -1);
}

int main(void)
{
    (void)test_last_error;
    RUN(test_cylinder_reynolds);
    RUN(test_cylinder_squeeze_reynolds);
    RUN(test_cylinder_reversed);
    RUN(test_squeeze_film);
    RUN(test_order_of_accuracy);
    RUN(test_sommerfeld);
    RUN(test_given_exit);
    RUN(test_rupture_and_reformation);
    RUN(test_rupture_fine_grid);
    RUN(test_bad_input);
    RUN(test_inflections);
    return test_summary();
}
