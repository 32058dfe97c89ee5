/* Tests of the 2-D (finite-width) Reynolds solver, src/reynolds/reynolds2d.h, against
 * references that do not come from it:
 *   - a manufactured solution p = P sin(pi x/L) cos(pi z/W) on a curved gap, its source derived
 *     by hand below: second-order convergence of the grid error, the same answer through the
 *     complementarity path (p > 0 inside: nothing cavitates), the flows' volume balance;
 *   - the wide limit: the mid-plane of a long roller tends to the 1-D solution (reynolds.c,
 *     Reynolds condition) like 1/cosh(pi W/(2 L_p)), L_p the pressurised length;
 *   - the short-bearing limit: an inclined slider of width W << L against Ocvirk's closed
 *     form p = 6 mu Um h'/h^3 (z^2 - W^2/4) (doc/methods.md (5.7)), error ~ (W/L)^2;
 *   - a gap varying across (h_area, the point contact of a ball over a plane): a manufactured
 *     p on h = h0 + ((x - xc)^2 + z^2)/(2R) with a squeeze rate varying over the area, second
 *     order; the gap uniform in z given as h_area gives the h(x) solution bit for bit;
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

/* --- a gap varying across (h_area) ------------------------------------------------------- */

/* The point contact: a ball of radius R over a plane, h = h0 + ((x - xc)^2 + z^2)/(2R) (the
 * paraboloid of the ball's lowest point), on [0, L] x [-W/2, W/2]; dh/dt varying over the
 * area.  The manufactured p is ms_p; its source (k = h^3/(12 mu), k_x = h^2 h_x/(4 mu)):
 *   s = k_x p_x + k_z p_z + k (p_xx + p_zz) - Um h_x - dh/dt. */
static const double PC_R = 0.02, PC_XC = 0.4 * 2e-3;

static double pc_h(double x, double z)
{
    return MS_H0 + ((x - PC_XC) * (x - PC_XC) + z * z) / (2.0 * PC_R);
}
static double pc_dhdt(double x, double z, double w)
{
    return MS_DHDT * (1.0 + 0.5 * z / w + 0.3 * x / MS_L);
}
static double pc_source(double x, double z, double w)
{
    double h = pc_h(x, z), hx = (x - PC_XC) / PC_R, hz = z / PC_R;
    double k = h * h * h / (12.0 * MS_MU), c = h * h / (4.0 * MS_MU);
    double a = M_PI / MS_L, b = M_PI / w;
    double px = MS_P * a * cos(a * x) * cos(b * z), pz = -MS_P * b * sin(a * x) * sin(b * z);
    double lap = -(a * a + b * b) * ms_p(x, z, w);
    return c * hx * px + c * hz * pz + k * lap - 0.5 * (MS_U1 + MS_U2) * hx - pc_dhdt(x, z, w);
}

typedef struct {
    double *h, *fx, *fz, *r, *src, *p;
} pc_arrays;

/* The manufactured point contact on an (nx, nz) grid; faces sampled (faces != 0) or NULL
 * (the nodes' means). */
static void pc_problem(lub_reynolds2d_problem *pb, pc_arrays *a, int nx, int nz, double w,
                       int faces, lub_reynolds_bc bc)
{
    lub_reynolds2d_problem_init(pb);
    pb->nx = nx;
    pb->nz = nz;
    pb->xb = MS_L;
    pb->width = w;
    pb->u1 = MS_U1;
    pb->u2 = MS_U2;
    pb->mu = MS_MU;
    pb->bc = bc;
    size_t nn = (size_t)(nx + 1) * (nz + 1);
    double dx = MS_L / nx, dz = w / nz;
    a->h = malloc(nn * sizeof *a->h);
    a->r = malloc(nn * sizeof *a->r);
    a->src = malloc(nn * sizeof *a->src);
    a->p = malloc(nn * sizeof *a->p);
    a->fx = malloc((size_t)nx * (nz + 1) * sizeof *a->fx);
    a->fz = malloc((size_t)(nx + 1) * nz * sizeof *a->fz);
    for (int i = 0; i <= nx; i++)
        for (int j = 0; j <= nz; j++) {
            double x = i * dx, z = lub_reynolds2d_z(pb, j);
            a->h[i * (nz + 1) + j] = pc_h(x, z);
            a->r[i * (nz + 1) + j] = pc_dhdt(x, z, w);
            a->src[i * (nz + 1) + j] = pc_source(x, z, w);
            if (i < nx) a->fx[i * (nz + 1) + j] = pc_h(x + 0.5 * dx, z);
            if (j < nz) a->fz[i * nz + j] = pc_h(x, z + 0.5 * dz);
        }
    pb->h_area = a->h;
    pb->h_face_x = faces ? a->fx : NULL;
    pb->h_face_z = faces ? a->fz : NULL;
    pb->dhdt_area = a->r;
    pb->source = a->src;
}

static void pc_free(pc_arrays *a)
{
    free(a->h);
    free(a->fx);
    free(a->fz);
    free(a->r);
    free(a->src);
    free(a->p);
}

/* The grid error falls as dx^2 + dz^2 with the faces' gaps sampled and with the nodes'
 * means; the complementarity path gives the same (p > 0 inside: nothing cavitates). */
static void test_area_manufactured(void)
{
    double w = 0.6 * MS_L;
    for (int faces = 1; faces >= 0; faces--) {
        double e[3];
        int n[3] = {16, 32, 64};
        for (int k = 0; k < 3; k++) {
            lub_reynolds2d_problem pb;
            pc_arrays a;
            pc_problem(&pb, &a, n[k], n[k], w, faces, LUB_REYNOLDS_BC_FULL_SOMMERFELD);
            lub_reynolds2d_result r = {.p = a.p};
            CHECK(lub_reynolds2d_solve(&pb, &r) == LUB_REYNOLDS_OK);
            double m = 0.0, dx = MS_L / n[k];
            for (int i = 0; i <= n[k]; i++)
                for (int j = 0; j <= n[k]; j++)
                    m = fmax(m, fabs(a.p[i * (n[k] + 1) + j] -
                                     ms_p(i * dx, lub_reynolds2d_z(&pb, j), w)));
            e[k] = m / MS_P;
            if (k == 2) { /* the Reynolds condition: no node cavitates, the same answer */
                lub_reynolds2d_problem pr;
                pc_arrays b;
                pc_problem(&pr, &b, n[k], n[k], w, faces, LUB_REYNOLDS_BC_REYNOLDS);
                lub_reynolds2d_result rr = {.p = b.p};
                CHECK(lub_reynolds2d_solve(&pr, &rr) == LUB_REYNOLDS_OK);
                CHECK(rr.n_cavitated == 0);
                double d = 0.0;
                for (int q = 0; q < (n[k] + 1) * (n[k] + 1); q++)
                    d = fmax(d, fabs(a.p[q] - b.p[q]));
                CHECK(d <= 1e-9 * MS_P);
                pc_free(&b);
            }
            pc_free(&a);
        }
        printf("  point contact, faces %s: max error / P = %.3e %.3e %.3e (16, 32, 64 cells), "
               "orders %.3f %.3f\n",
               faces ? "sampled" : "means", e[0], e[1], e[2], log2(e[0] / e[1]), log2(e[1] / e[2]));
        CHECK(e[2] < 1e-3);
        CHECK_NEAR(log2(e[0] / e[1]), 2.0, 0.15);
        CHECK_NEAR(log2(e[1] / e[2]), 2.0, 0.15);
    }
}

/* The roller's gap h(x) given as h_area (every z the same; x faces the same, z faces the
 * nodes' means = the node) gives the h(x) path's pressure bit for bit: the Reynolds
 * condition (a cavitated exit, the coarse-grid start) and a given exit between nodes (the
 * cut cell); the figures to round-off. */
static void test_area_uniform(void)
{
    const double s = sqrt(WL_R * WL_H0), xa = -4.0 * s, xb = 2.0 * s;
    const int nx = 120, nz = 32;
    double h[nx + 1], hf[nx];
    wl_gap(nx, xa, xb, h, hf);
    double *ha = malloc((size_t)(nx + 1) * (nz + 1) * sizeof *ha);
    double *fx = malloc((size_t)nx * (nz + 1) * sizeof *fx);
    for (int i = 0; i <= nx; i++)
        for (int j = 0; j <= nz; j++) {
            ha[i * (nz + 1) + j] = h[i];
            if (i < nx) fx[i * (nz + 1) + j] = hf[i];
        }
    lub_reynolds_bc bcs[2] = {LUB_REYNOLDS_BC_REYNOLDS, LUB_REYNOLDS_BC_GIVEN_EXIT};
    for (int k = 0; k < 2; k++) {
        lub_reynolds2d_problem p1, p2;
        lub_reynolds2d_problem_init(&p1);
        p1.nx = nx;
        p1.nz = nz;
        p1.xa = xa;
        p1.xb = xb;
        p1.width = 1.5 * (xb - xa);
        p1.h = h;
        p1.h_face = hf;
        p1.u1 = 1.0;
        p1.mu = WL_MU;
        p1.bc = bcs[k];
        p1.exit_x = xa + 0.8137 * (xb - xa);
        p2 = p1;
        p2.h = p2.h_face = NULL;
        p2.h_area = ha;
        p2.h_face_x = fx;
        double *q1 = malloc((size_t)(nx + 1) * (nz + 1) * sizeof *q1);
        double *q2 = malloc((size_t)(nx + 1) * (nz + 1) * sizeof *q2);
        lub_reynolds2d_result r1 = {.p = q1}, r2 = {.p = q2};
        CHECK(lub_reynolds2d_solve(&p1, &r1) == LUB_REYNOLDS_OK);
        CHECK(lub_reynolds2d_solve(&p2, &r2) == LUB_REYNOLDS_OK);
        int same = 1;
        for (int q = 0; q < (nx + 1) * (nz + 1); q++) same &= q1[q] == q2[q];
        CHECK(same);
        CHECK(r1.n_cavitated == r2.n_cavitated);
        if (k == 0) CHECK(r1.n_cavitated > 0);
        CHECK(r1.load == r2.load);
        CHECK_REL(r2.leakage, r1.leakage, 1e-12);
        CHECK_REL(r2.q_in, r1.q_in, 1e-12);
        free(q1);
        free(q2);
    }
    free(ha);
    free(fx);
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
    lub_reynolds2d_problem pa;
    pc_arrays c;
    pc_problem(&pa, &c, 16, 8, w, 1, LUB_REYNOLDS_BC_FULL_SOMMERFELD);
    r.p = c.p;
    c.fz[5] = 0.0;
    CHECK(lub_reynolds2d_solve(&pa, &r) == LUB_REYNOLDS_BAD_GAP);
    c.fz[5] = c.h[5];
    c.h[9 * 9 + 4] = NAN;
    CHECK(lub_reynolds2d_solve(&pa, &r) == LUB_REYNOLDS_BAD_GAP);
    pc_free(&c);
}

int main(void)
{
    (void)test_last_error;
    RUN(test_manufactured_order);
    RUN(test_manufactured_reynolds);
    RUN(test_wide_limit);
    RUN(test_wide_limit_conditions);
    RUN(test_short_bearing);
    RUN(test_area_manufactured);
    RUN(test_area_uniform);
    RUN(test_pcg_matches_cholmod);
    RUN(test_bad_input);
    return test_summary();
}
