/* Tests of the 2-D (finite-width) Reynolds solver, src/reynolds/reynolds2d.h, against
 * references that do not come from it:
 *   - a manufactured solution p = P sin(pi x/L) cos(pi z/W) on a curved gap, its source derived
 *     by hand below: second-order convergence of the grid error, the same answer through the
 *     complementarity path (p > 0 inside: nothing cavitates), the flows' volume balance;
 *   - the wide limit: the mid-plane of a long roller tends to the 1-D solution (reynolds.c,
 *     Reynolds condition) like 1/cosh(pi W/(2 L_p)), L_p the pressurised length;
 *   - the short-bearing limit: an inclined slider of width W << L against Ocvirk's closed
 *     form p = 6 mu Um h'/h^3 (z^2 - W^2/4) (doc/methods.md (5.7)), error ~ (W/L)^2;
 *   - the linear solvers: PCG with AMG gives CHOLMOD's answer to its tolerance;
 *   - bad input. */
#include <math.h>
#include <stdlib.h>

#include "reynolds/reynolds.h"
#include "reynolds/reynolds2d.h"
#include "test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* --- the manufactured solution ---------------------------------------------------------- */

static const double MS_L = 2e-3, MS_H0 = 2e-5, MS_P = 1e6, MS_MU = 0.1, MS_U1 = 1.0, MS_U2 = 0.5,
                    MS_DHDT = -1e-4;

/* h = h0 (2 - x/L + (x/L)^2/2) on [0, L]: converging, then less so */
static double ms_h(double x)
{
    double s = x / MS_L;
    return MS_H0 * (2.0 - s + 0.5 * s * s);
}
static double ms_dh(double x)
{
    return MS_H0 * (-1.0 + x / MS_L) / MS_L;
}
static double ms_p(double x, double z, double w)
{
    return MS_P * sin(M_PI * x / MS_L) * cos(M_PI * z / w);
}
/* s = d/dx(k dp/dx) + d/dz(k dp/dz) - Um h' - dh/dt, k = h^3/(12 mu):
 * k' p_x + k (p_xx + p_zz) with k' = h^2 h'/(4 mu). */
static double ms_source(double x, double z, double w)
{
    double h = ms_h(x), dh = ms_dh(x), k = h * h * h / (12.0 * MS_MU),
           dk = h * h * dh / (4.0 * MS_MU);
    double a = M_PI / MS_L, b = M_PI / w;
    double px = MS_P * a * cos(a * x) * cos(b * z);
    double lap = -(a * a + b * b) * ms_p(x, z, w);
    return dk * px + k * lap - 0.5 * (MS_U1 + MS_U2) * dh - MS_DHDT;
}

typedef struct {
    double *h, *hf, *src, *p;
} ms_arrays;

/* Set up pb for the manufactured problem on an (nx, nz) grid of [0, L] x [-W/2, W/2]. */
static void ms_problem(lub_reynolds2d_problem *pb, ms_arrays *a, int nx, int nz, double w,
                       lub_reynolds_bc bc)
{
    lub_reynolds2d_problem_init(pb);
    pb->nx = nx;
    pb->nz = nz;
    pb->xa = 0.0;
    pb->xb = MS_L;
    pb->width = w;
    pb->u1 = MS_U1;
    pb->u2 = MS_U2;
    pb->dhdt = MS_DHDT;
    pb->mu = MS_MU;
    pb->bc = bc;
    double dx = MS_L / nx;
    a->h = malloc((size_t)(nx + 1) * sizeof *a->h);
    a->hf = malloc((size_t)nx * sizeof *a->hf);
    a->src = malloc((size_t)(nx + 1) * (nz + 1) * sizeof *a->src);
    a->p = malloc((size_t)(nx + 1) * (nz + 1) * sizeof *a->p);
    for (int i = 0; i <= nx; i++) {
        a->h[i] = ms_h(i * dx);
        if (i < nx) a->hf[i] = ms_h((i + 0.5) * dx);
        for (int j = 0; j <= nz; j++)
            a->src[i * (nz + 1) + j] = ms_source(i * dx, lub_reynolds2d_z(pb, j), w);
    }
    pb->h = a->h;
    pb->h_face = a->hf;
    pb->source = a->src;
}

static void ms_free(ms_arrays *a)
{
    free(a->h);
    free(a->hf);
    free(a->src);
    free(a->p);
}

/* max |p - p_exact| / P over the nodes */
static double ms_error(const lub_reynolds2d_problem *pb, const double *p)
{
    double e = 0.0, dx = (pb->xb - pb->xa) / pb->nx;
    for (int i = 0; i <= pb->nx; i++)
        for (int j = 0; j <= pb->nz; j++) {
            double d = fabs(p[lub_reynolds2d_index(pb, i, j)] -
                            ms_p(i * dx, lub_reynolds2d_z(pb, j), pb->width));
            e = e > d ? e : d;
        }
    return e / MS_P;
}

/* (c) the grid error falls as dx^2 + dz^2 (ratio 4 per halving; measured 3.99-4.00). */
static void test_manufactured_order(void)
{
    double w = 0.6 * MS_L, e[3];
    int n[3] = {16, 32, 64};
    for (int k = 0; k < 3; k++) {
        lub_reynolds2d_problem pb;
        ms_arrays a;
        ms_problem(&pb, &a, n[k], n[k], w, LUB_REYNOLDS_BC_FULL_SOMMERFELD);
        lub_reynolds2d_result r = {.p = a.p};
        CHECK(lub_reynolds2d_solve(&pb, &r) == LUB_REYNOLDS_OK);
        e[k] = ms_error(&pb, a.p);
        ms_free(&a);
    }
    printf("  manufactured: max error / P = %.3e %.3e %.3e (16, 32, 64 cells), orders %.3f "
           "%.3f\n",
           e[0], e[1], e[2], log2(e[0] / e[1]), log2(e[1] / e[2]));
    CHECK(e[2] < 1e-3);
    CHECK_NEAR(log2(e[0] / e[1]), 2.0, 0.1);
    CHECK_NEAR(log2(e[1] / e[2]), 2.0, 0.1);
}

/* The complementarity path on a problem whose solution is positive inside: no node
 * cavitates and the answer is the linear one; the flows balance the sources. */
static void test_manufactured_reynolds(void)
{
    double w = 0.6 * MS_L;
    lub_reynolds2d_problem pb, pf;
    ms_arrays a, b;
    ms_problem(&pb, &a, 64, 32, w, LUB_REYNOLDS_BC_REYNOLDS);
    ms_problem(&pf, &b, 64, 32, w, LUB_REYNOLDS_BC_FULL_SOMMERFELD);
    lub_reynolds2d_result r = {.p = a.p}, rf = {.p = b.p};
    CHECK(lub_reynolds2d_solve(&pb, &r) == LUB_REYNOLDS_OK);
    CHECK(lub_reynolds2d_solve(&pf, &rf) == LUB_REYNOLDS_OK);
    CHECK(r.n_cavitated == 0);
    double d = 0.0;
    for (int q = 0; q < 65 * 33; q++) d = fmax(d, fabs(a.p[q] - b.p[q]));
    CHECK(d <= 1e-9 * MS_P);
    /* the load: integral of P sin cos = P (2L/pi)(2W/pi) */
    CHECK_REL(rf.load, MS_P * 4.0 * MS_L * w / (M_PI * M_PI), 2e-3);
    ms_free(&a);
    ms_free(&b);
    /* q_in - q_out - leakage = integral of (dh/dt + s) over the area (trapezoid rule), to
     * second order: the flows are one-sided differences at the boundaries, not the scheme's
     * own fluxes (measured 0.38% and 0.095% of the source's integral at 64 x 32 and 128 x 64
     * cells) */
    double gap[2];
    for (int k = 0; k < 2; k++) {
        int nx = 64 << k, nz = 32 << k;
        ms_problem(&pf, &b, nx, nz, w, LUB_REYNOLDS_BC_FULL_SOMMERFELD);
        rf.p = b.p;
        CHECK(lub_reynolds2d_solve(&pf, &rf) == LUB_REYNOLDS_OK);
        double src = 0.0, dx = MS_L / nx, dz = w / nz;
        for (int i = 0; i <= nx; i++)
            for (int j = 0; j <= nz; j++)
                src += (i == 0 || i == nx ? 0.5 : 1.0) * (j == 0 || j == nz ? 0.5 : 1.0) *
                       (MS_DHDT + b.src[i * (nz + 1) + j]);
        src *= dx * dz;
        gap[k] = fabs(rf.q_in - rf.q_out - rf.leakage - src) / fabs(src);
        ms_free(&b);
    }
    CHECK(gap[0] < 5e-3);
    CHECK_NEAR(log2(gap[0] / gap[1]), 2.0, 0.2);
}

/* --- the wide limit --------------------------------------------------------------------- */

/* The thesis wedge's roller: R = 40 mm, h0 = 40 um, U1 = 1 m/s, mu = 0.19 Pa s, inlet 4
 * sqrt(R h0) upstream, outlet 2 downstream; Reynolds condition. */
static const double WL_R = 0.04, WL_H0 = 4e-5, WL_MU = 0.19125;

static void wl_gap(int nx, double xa, double xb, double *h, double *hf)
{
    double dx = (xb - xa) / nx;
    for (int i = 0; i <= nx; i++) {
        double x = xa + i * dx;
        h[i] = WL_H0 + x * x / (2.0 * WL_R);
        if (i < nx) {
            double xm = x + 0.5 * dx;
            hf[i] = WL_H0 + xm * xm / (2.0 * WL_R);
        }
    }
}

/* (a) The mid-plane pressure tends to the 1-D solution as W grows: the end effect is a
 * decaying solution of the Laplacian, cosh(pi z/L)/cosh(pi W/(2 L)) for a film of length L,
 * so at the mid-plane the difference falls like exp(-pi W/(2 L)).  With L_p the pressurised
 * length (inlet to exit) this is a bound: the pressure is concentrated near the contact and
 * decays faster.  Measured (nx 240, dz = 2 dx): W/L_p = 1, 2, 4: difference / 1-D peak
 * 0.104, 6.5e-3, 2.7e-5, i.e. exp(-2.7 W/L_p) against the bound's exp(-1.57 W/L_p). */
static void test_wide_limit(void)
{
    const double s = sqrt(WL_R * WL_H0), xa = -4.0 * s, xb = 2.0 * s;
    const int nx = 240;
    double h[nx + 1], hf[nx];
    wl_gap(nx, xa, xb, h, hf);
    lub_reynolds_problem p1;
    lub_reynolds_problem_init(&p1);
    p1.n = nx;
    p1.xa = xa;
    p1.xb = xb;
    p1.h = h;
    p1.h_face = hf;
    p1.u1 = 1.0;
    p1.mu = WL_MU;
    double q1[nx + 1];
    lub_reynolds_result r1 = {.p = q1};
    CHECK(lub_reynolds_solve(&p1, &r1) == LUB_REYNOLDS_OK);
    double lp = r1.x_exit - xa; /* pressurised length */
    double ratio[3] = {1.0, 2.0, 4.0}, err[3];
    for (int k = 0; k < 3; k++) {
        lub_reynolds2d_problem pb;
        lub_reynolds2d_problem_init(&pb);
        pb.nx = nx;
        pb.width = ratio[k] * lp;
        pb.nz = 2 * (int)ceil(0.25 * pb.width / ((xb - xa) / nx)); /* dz <= 2 dx */
        pb.xa = xa;
        pb.xb = xb;
        pb.h = h;
        pb.h_face = hf;
        pb.u1 = 1.0;
        pb.mu = WL_MU;
        double *p = malloc((size_t)(nx + 1) * (pb.nz + 1) * sizeof *p);
        lub_reynolds2d_result r = {.p = p};
        CHECK(lub_reynolds2d_solve(&pb, &r) == LUB_REYNOLDS_OK);
        double e = 0.0;
        for (int i = 0; i <= nx; i++)
            e = fmax(e, fabs(p[lub_reynolds2d_index(&pb, i, pb.nz / 2)] - q1[i]));
        err[k] = e / r1.p_max;
        /* the 2-D film is never above the 1-D one (the sides only drain it) */
        int below = 1;
        for (int i = 0; i <= nx; i++)
            below &= p[lub_reynolds2d_index(&pb, i, pb.nz / 2)] <= q1[i] * (1.0 + 1e-9);
        CHECK(below);
        CHECK(r.leakage > 0.0);
        free(p);
    }
    printf("  wide limit: W/L_p = 1, 2, 4: mid-plane difference / 1-D peak %.3g %.3g %.3g; "
           "exp(-pi W/(2 L_p)) ratios %.3g %.3g, measured %.3g %.3g\n",
           err[0], err[1], err[2], exp(M_PI / 2), exp(M_PI), err[0] / err[1], err[1] / err[2]);
    CHECK(err[2] < 0.02);
    CHECK(err[0] / err[1] > 0.5 * exp(M_PI / 2));
    CHECK(err[1] / err[2] > 0.5 * exp(M_PI));
}

/* The other x conditions in the wide limit (W = 4 (xb - xa)): the mid-plane is the 1-D
 * solution of the same condition on the same x grid, the given exit between two nodes (the
 * cut cell) included; half-Sommerfeld clips, full-Sommerfeld keeps the negative loop. */
static void test_wide_limit_conditions(void)
{
    const double s = sqrt(WL_R * WL_H0), xa = -4.0 * s, xb = 2.0 * s;
    const int nx = 120;
    double h[nx + 1], hf[nx];
    wl_gap(nx, xa, xb, h, hf);
    lub_reynolds_bc bcs[3] = {LUB_REYNOLDS_BC_HALF_SOMMERFELD, LUB_REYNOLDS_BC_FULL_SOMMERFELD,
                              LUB_REYNOLDS_BC_GIVEN_EXIT};
    for (int k = 0; k < 3; k++) {
        lub_reynolds_problem p1;
        lub_reynolds_problem_init(&p1);
        p1.n = nx;
        p1.xa = xa;
        p1.xb = xb;
        p1.h = h;
        p1.h_face = hf;
        p1.u1 = 1.0;
        p1.mu = WL_MU;
        p1.bc = bcs[k];
        p1.exit_x = 0.37 * s; /* between nodes */
        double q1[nx + 1];
        lub_reynolds_result r1 = {.p = q1};
        CHECK(lub_reynolds_solve(&p1, &r1) == LUB_REYNOLDS_OK);
        lub_reynolds2d_problem pb;
        lub_reynolds2d_problem_init(&pb);
        pb.nx = nx;
        pb.width = 4.0 * (xb - xa);
        pb.nz = 60;
        pb.xa = xa;
        pb.xb = xb;
        pb.h = h;
        pb.h_face = hf;
        pb.u1 = 1.0;
        pb.mu = WL_MU;
        pb.bc = bcs[k];
        pb.exit_x = p1.exit_x;
        double *p = malloc((size_t)(nx + 1) * (pb.nz + 1) * sizeof *p);
        lub_reynolds2d_result r = {.p = p};
        CHECK(lub_reynolds2d_solve(&pb, &r) == LUB_REYNOLDS_OK);
        double e = 0.0, pmin = 0.0;
        for (int i = 0; i <= nx; i++) {
            double pm = p[lub_reynolds2d_index(&pb, i, pb.nz / 2)];
            e = fmax(e, fabs(pm - q1[i]));
            pmin = fmin(pmin, pm);
        }
        CHECK(e <= 1e-4 * r1.p_max);
        CHECK(bcs[k] == LUB_REYNOLDS_BC_FULL_SOMMERFELD ? pmin < -0.1 * r1.p_max : pmin == 0.0);
        if (bcs[k] == LUB_REYNOLDS_BC_GIVEN_EXIT) CHECK(r.x_exit == p1.exit_x);
        free(p);
    }
}

/* --- the short-bearing limit ------------------------------------------------------------ */

/* (b) An inclined slider, h = h1 (1 - x/(2L)) (h1/h2 = 2), full Sommerfeld (p > 0 anyway in
 * a converging gap), width W << L.  Ocvirk's short-bearing form neglects the pressure flow
 * along x: at x = L/2 its relative error is of order (W/L)^2 (the neglected term over the
 * kept one), so halving W/L divides it by about 4. */
static double short_bearing_error(double w_over_l, int nx, int nz)
{
    const double L = 1e-2, h1 = 4e-5, mu = 0.1, u1 = 2.0;
    double w = w_over_l * L, dx = L / nx;
    double *h = malloc((size_t)(nx + 1) * sizeof *h);
    double *p = malloc((size_t)(nx + 1) * (nz + 1) * sizeof *p);
    for (int i = 0; i <= nx; i++) h[i] = h1 * (1.0 - 0.5 * i * dx / L);
    lub_reynolds2d_problem pb;
    lub_reynolds2d_problem_init(&pb);
    pb.nx = nx;
    pb.nz = nz;
    pb.xa = 0.0;
    pb.xb = L;
    pb.width = w;
    pb.h = h; /* linear: the face gap is the mean */
    pb.u1 = u1;
    pb.mu = mu;
    pb.bc = LUB_REYNOLDS_BC_FULL_SOMMERFELD;
    lub_reynolds2d_result r = {.p = p};
    CHECK(lub_reynolds2d_solve(&pb, &r) == LUB_REYNOLDS_OK);
    /* Ocvirk at x = L/2, z = 0 (doc/methods.md (5.7)) */
    double hc = h[nx / 2], dh = -0.5 * h1 / L;
    double po = 6.0 * mu * 0.5 * u1 * dh / (hc * hc * hc) * (0.0 - 0.25 * w * w);
    double e = fabs(p[lub_reynolds2d_index(&pb, nx / 2, nz / 2)] - po) / po;
    free(h);
    free(p);
    return e;
}

static void test_short_bearing(void)
{
    double e1 = short_bearing_error(0.1, 200, 16), e2 = short_bearing_error(0.05, 400, 16);
    printf("  short bearing: W/L = 0.1, 0.05: centre pressure against Ocvirk's %.3e %.3e "
           "(ratio %.2f; (W/L)^2 gives 4)\n",
           e1, e2, e1 / e2);
    CHECK(e1 < 0.02);
    CHECK(e1 / e2 > 3.5 && e1 / e2 < 4.5);
}

/* --- solvers and input ------------------------------------------------------------------ */

/* PCG with AMG gives CHOLMOD's answer to its tolerance, on the complementarity path too. */
static void test_pcg_matches_cholmod(void)
{
    double w = 0.6 * MS_L;
    lub_reynolds2d_problem pb, pc;
    ms_arrays a, b;
    ms_problem(&pb, &a, 64, 32, w, LUB_REYNOLDS_BC_REYNOLDS);
    ms_problem(&pc, &b, 64, 32, w, LUB_REYNOLDS_BC_REYNOLDS);
    lub_linsolver_options o = lub_linsolver_defaults();
    o.pcg.precond = LUB_PRECOND_AMG;
    o.pcg.tolerance = 1e-10;
    pc.solver = &o;
    lub_reynolds2d_result r = {.p = a.p}, rc = {.p = b.p};
    CHECK(lub_reynolds2d_solve(&pb, &r) == LUB_REYNOLDS_OK);
    CHECK(lub_reynolds2d_solve(&pc, &rc) == LUB_REYNOLDS_OK);
    CHECK(rc.linear_iters > 0);
    double d = 0.0;
    for (int q = 0; q < 65 * 33; q++) d = fmax(d, fabs(a.p[q] - b.p[q]));
    CHECK(d <= 1e-8 * MS_P);
    ms_free(&a);
    ms_free(&b);
}

static void test_bad_input(void)
{
    double w = 0.6 * MS_L;
    lub_reynolds2d_problem pb;
    ms_arrays a;
    ms_problem(&pb, &a, 16, 8, w, LUB_REYNOLDS_BC_FULL_SOMMERFELD);
    lub_reynolds2d_result r = {.p = a.p};
    pb.nz = 7;
    CHECK(lub_reynolds2d_solve(&pb, &r) == LUB_REYNOLDS_BAD_INPUT); /* odd nz: no mid-plane */
    pb.nz = 8;
    pb.width = 0.0;
    CHECK(lub_reynolds2d_solve(&pb, &r) == LUB_REYNOLDS_BAD_INPUT);
    pb.width = w;
    a.h[3] = -1e-6;
    CHECK(lub_reynolds2d_solve(&pb, &r) == LUB_REYNOLDS_BAD_GAP);
    ms_free(&a);
}

int main(void)
{
    (void)test_last_error;
    RUN(test_manufactured_order);
    RUN(test_manufactured_reynolds);
    RUN(test_wide_limit);
    RUN(test_wide_limit_conditions);
    RUN(test_short_bearing);
    RUN(test_pcg_matches_cholmod);
    RUN(test_bad_input);
    return test_summary();
}
