/* reynoldsRef: the 1-D Reynolds-equation reference of a case (methods.md 5, thesis 3-2).
 *
 * Reads the case's geometry (system/particleGenDict.yaml), oil (transportProperties), wall
 * motion (models.yaml movingWalls) and system/reynoldsRefDict.yaml; for each time asked for
 * (the dictionary's `time`, or the time folders -time / -latestTime select) moves the walls
 * by their velocities to that time, samples the gap h(x) = (upper wall height) - (lower wall
 * height) on a uniform grid between the inlet and the outlet, solves the Reynolds equation
 * (T-32, methods.md §5.1 and §5.5, with the squeeze term dh/dt of the moving walls) with the chosen
 * boundary condition, writes postProcessing/reynoldsRef/<time>/p.dat (# x p h [X P H]) and
 * prints a short report.
 * With an elasticWall in models.yaml (soft EHL) the gap follows from the pressure and the
 * load instead (reynoldsRefEHL.c, src/reynolds/ehl.h).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/args.h"
#include "core/error.h"
#include "core/timer.h"
#include "geometry/geometry.h"
#include "io/case.h"
#include "io/dict.h"
#include "io/table.h"
#include "reynolds/refcase.h"
#include "reynolds/reynolds.h"
#include "reynolds/reynolds2d.h"
#include "reynoldsRef.h"

void reynoldsRef_table_write(const lub_case *c, const char *out_file, const char *tname,
                             const lub_refgap *G, const double *h, const double *p,
                             const lub_refscales *d, char *written)
{
    char path[LUB_PATH_MAX];
    lub_output o;
    if (out_file) {
        lub_output_open(&o, out_file);
    } else {
        lub_postproc_path(c, "reynoldsRef", tname, "p.dat", path);
        lub_output_open(&o, path);
    }
    lub_table_write_header(o.fp, d ? "x[m] p[Pa] h[m] X P H" : "x[m] p[Pa] h[m]");
    for (int i = 0; i <= G->n; i++) {
        double x = G->xa + i * G->dx;
        double row[6] = {x, p[i], h[i], 0.0, 0.0, 0.0};
        if (d) {
            row[3] = x / d->sx;
            row[4] = p[i] * d->sp;
            row[5] = h[i] / d->h0;
        }
        lub_table_write_row(o.fp, row, d ? 6 : 3);
    }
    lub_output_close(&o);
    if (out_file)
        snprintf(written, LUB_PATH_MAX, "%s", o.path);
    else
        snprintf(written, LUB_PATH_MAX, "postProcessing/reynoldsRef/%s/p.dat", tname);
}

/* The report's line on the time of the walls: what moving them to t did to the gap. */
static void report_time(const lub_refcase *rc, const lub_refgap *G)
{
    const double *dl = rc->disp[0], *du = rc->disp[1];
    const int history = lub_wall_motion_is_history(&rc->motion[rc->wl]) ||
                        lub_wall_motion_is_history(&rc->motion[rc->wu]);
    if (rc->t == 0.0)
        lub_message("at t        0 s (the walls of system/particleGenDict.yaml)");
    else if (G->moving_shape || history)
        lub_message("at t        %g s: the walls moved by their %s, lower by (%g, %g) m, "
                    "upper by (%g, %g) m",
                    rc->t, history ? "motions" : "velocities", dl[0], dl[1], du[0], du[1]);
    else
        lub_message("at t        %g s (names the output; the gap does not change with time: "
                    "no wall moves across the film)",
                    rc->t);
}

/* The rigid reference at the walls' time rc->t: solve, write, report. */
static void reference(const lub_case *c, const lub_refcase *rc, const lub_refgap *G,
                      const char *out_file, const char *tname, int dimensionless, double t_start)
{
    const lub_refcase_settings *s = &rc->s;
    double *p = lub_malloc((size_t)(G->n + 1) * sizeof *p);
    lub_reynolds_result res;
    double t_solve = lub_wtime();
    lub_reynolds_status st = lub_refcase_solve(rc, G, p, &res);
    t_solve = lub_wtime() - t_solve;
    if (st != LUB_REYNOLDS_OK)
        lub_fatal_run("the Reynolds solve failed: %s (%d cells on [%g, %g], %s, t = %g s)",
                      lub_reynolds_status_string(st), G->n, G->xa, G->xb,
                      lub_reynolds_bc_names[s->bc], rc->t);

    /* output and report */
    lub_refscales d;
    if (dimensionless) lub_refcase_scales(rc, G, &d);
    char written[LUB_PATH_MAX];
    reynoldsRef_table_write(c, out_file, tname, G, G->h, p, dimensionless ? &d : NULL, written);

    lub_message("grid        %d cells on [%g, %g] m, dx = %.4g m", G->n, G->xa, G->xb, G->dx);
    lub_message("walls       lower '%s' U1 = %g m/s, upper '%s' U2 = %g m/s%s", s->lower, rc->u1,
                s->upper, rc->u2, G->moving_shape ? ", dh/dt != 0 (wall motion)" : "");
    lub_message("oil         rho = %g kg/m^3, nu = %g m^2/s, mu = %g Pa s", rc->rho, rc->nu,
                rc->mu);
    lub_message("gap         h0 = %.6g m (minimum, at x = %.6g m)", G->h0, G->x_h0);
    lub_message("condition   %s%s", lub_reynolds_bc_names[s->bc],
                s->bc == LUB_REYNOLDS_BC_REYNOLDS ? " (p >= 0; p = dp/dx = 0 at the free exit)"
                                                  : "");
    if (s->bc == LUB_REYNOLDS_BC_REYNOLDS)
        lub_message("active set  %d iteration%s, %d cavitated nodes", res.iterations,
                    res.iterations == 1 ? "" : "s", res.n_cavitated);
    lub_message("exit        x = %.6g m%s", res.x_exit,
                res.x_exit >= G->xb ? " (the outlet: the film is full up to it)" : "");
    lub_message("peak        p = %.6g Pa at x = %.6g m", res.p_max, res.x_max);
    lub_message("load        W = %.6g N/m", res.load);
    if (dimensionless) {
        lub_message("R, h0       R = %g m, h0 = %g m, sqrt(R h0) = %.6g m", d.radius, G->h0, d.sx);
        lub_message("exit        X = %.5f (Martin, T-37: X = 0.475 sqrt(2) = %.5f)",
                    res.x_exit / d.sx, 0.475 * sqrt(2.0));
        lub_message("peak        P = %.5f at X = %.5f", res.p_max * d.sp, res.x_max / d.sx);
        lub_message("load        W h0/(mu (U1+U2) R) = %.5f",
                    res.load * G->h0 / (rc->mu * d.uref * d.radius));
    }
    lub_message("written     %s", written);
    lub_message("time        solve %.3g s, total %.3g s", t_solve, lub_wtime() - t_start);
    free(p);
}

/* p(x, z) as "# x z p" rows, a blank line after each x column (gnuplot's splot reads the
 * grid), to postProcessing/reynoldsRef/<tname>/p2d.dat. */
static void table2d_write(const lub_case *c, const char *tname, const lub_reynolds2d_problem *pb,
                          const double *p, char *written)
{
    char path[LUB_PATH_MAX];
    lub_output o;
    lub_postproc_path(c, "reynoldsRef", tname, "p2d.dat", path);
    lub_output_open(&o, path);
    lub_table_write_header(o.fp, "x[m] z[m] p[Pa]");
    double dx = (pb->xb - pb->xa) / pb->nx;
    for (int i = 0; i <= pb->nx; i++) {
        for (int j = 0; j <= pb->nz; j++) {
            double row[3] = {pb->xa + i * dx, lub_reynolds2d_z(pb, j),
                             p[lub_reynolds2d_index(pb, i, j)]};
            lub_table_write_row(o.fp, row, 3);
        }
        fputc('\n', o.fp);
    }
    lub_output_close(&o);
    snprintf(written, LUB_PATH_MAX, "postProcessing/reynoldsRef/%s/p2d.dat", tname);
}

/* The finite-width reference (width in reynoldsRefDict.yaml, reynolds2d.h) at the walls'
 * time: solve over the area, write p2d.dat and the mid-plane's p.dat, report. */
static void reference2d(const lub_case *c, const lub_refcase *rc, lub_refgap *G,
                        const char *out_file, const char *tname, int dimensionless, double t_start)
{
    const lub_refcase_settings *s = &rc->s;
    /* the gap over the area: h(x, z) of the walls on every line (x, z) (a ball over a plane),
     * the same numbers on every z for walls uniform across (the roller) */
    lub_refgap_sample_area(G, rc);
    lub_reynolds2d_problem pb;
    lub_reynolds2d_problem_init(&pb);
    pb.nx = G->n;
    pb.nz = (int)s->nz;
    pb.xa = G->xa;
    pb.xb = G->xb;
    pb.width = s->width;
    pb.h_area = G->ha;
    pb.h_face_x = G->hfx;
    pb.h_face_z = G->hfz;
    pb.dhdt_area = G->dhdta;
    pb.u1 = rc->u1;
    pb.u2 = rc->u2;
    pb.mu = rc->mu;
    pb.bc = (lub_reynolds_bc)s->bc;
    pb.exit_x = s->exit_x;
    pb.tolerance = s->tolerance;
    pb.max_iterations = (int)s->max_iterations;
    lub_linsolver_options lo = lub_linsolver_defaults();
    lo.kind = (lub_linsolver_kind)s->solver;
    lo.pcg.precond = LUB_PRECOND_AMG;
    lo.pcg.tolerance = 1e-11;
    lo.pcg.max_iter = 10000;
    pb.solver = &lo;
    size_t nn = (size_t)(pb.nx + 1) * (pb.nz + 1);
    double *p = lub_malloc(nn * sizeof *p), *mid = lub_malloc((size_t)(pb.nx + 1) * sizeof *mid);
    lub_reynolds2d_result res = {.p = p};
    double t_solve = lub_wtime();
    lub_reynolds_status st = lub_reynolds2d_solve(&pb, &res);
    t_solve = lub_wtime() - t_solve;
    if (st != LUB_REYNOLDS_OK)
        lub_fatal_run("the 2-D Reynolds solve failed: %s (%d x %d cells on [%g, %g] x [%g, %g], "
                      "%s, t = %g s)",
                      lub_reynolds_status_string(st), pb.nx, pb.nz, G->xa, G->xb, -0.5 * pb.width,
                      0.5 * pb.width, lub_reynolds_bc_names[s->bc], rc->t);
    for (int i = 0; i <= pb.nx; i++) mid[i] = p[lub_reynolds2d_index(&pb, i, pb.nz / 2)];

    lub_refscales d;
    if (dimensionless) lub_refcase_scales(rc, G, &d);
    char written[LUB_PATH_MAX], written2d[LUB_PATH_MAX] = "";
    reynoldsRef_table_write(c, out_file, tname, G, G->h, mid, dimensionless ? &d : NULL, written);
    if (!out_file) table2d_write(c, tname, &pb, p, written2d);

    lub_message("grid        %d x %d cells on [%g, %g] x [%g, %g] m, dx = %.4g m, dz = %.4g m",
                pb.nx, pb.nz, G->xa, G->xb, -0.5 * pb.width, 0.5 * pb.width, G->dx,
                pb.width / pb.nz);
    lub_message("walls       lower '%s' U1 = %g m/s, upper '%s' U2 = %g m/s%s", s->lower, rc->u1,
                s->upper, rc->u2, G->moving_shape ? ", dh/dt != 0 (wall motion)" : "");
    lub_message("oil         rho = %g kg/m^3, nu = %g m^2/s, mu = %g Pa s", rc->rho, rc->nu,
                rc->mu);
    if (G->varies_across)
        lub_message("gap         h0 = %.6g m (minimum at the mid-plane, x = %.6g m), varying "
                    "across the width (smallest node %.6g m at x = %.6g m, z = %.6g m)",
                    G->h0, G->x_h0, G->h0_area, G->x_h0_area, G->z_h0_area);
    else
        lub_message("gap         h0 = %.6g m (minimum, at x = %.6g m), uniform across the width",
                    G->h0, G->x_h0);
    lub_message("condition   %s, p = 0 at the sides z = +-%g m%s", lub_reynolds_bc_names[s->bc],
                0.5 * pb.width,
                s->bc == LUB_REYNOLDS_BC_REYNOLDS ? " (p >= 0; p = dp/dx = 0 at the free exit)"
                                                  : "");
    lub_message("solver      %s", lo.kind == LUB_LINSOLVER_CHOLMOD ? "cholmod" : "pcg (amg)");
    if (s->bc == LUB_REYNOLDS_BC_REYNOLDS)
        lub_message("active set  %d iteration%s (all grid levels), %d cavitated nodes",
                    res.iterations, res.iterations == 1 ? "" : "s", res.n_cavitated);
    if (lo.kind == LUB_LINSOLVER_PCG)
        lub_message("pcg         %d iterations in all", res.linear_iters);
    lub_message("exit        x = %.6g m at the mid-plane%s", res.x_exit,
                res.x_exit >= G->xb ? " (the outlet: the film is full up to it)" : "");
    lub_message("peak        p = %.6g Pa at x = %.6g m, z = %.6g m", res.p_max, res.x_max,
                res.z_max);
    lub_message("load        W = %.6g N (%.6g N/m over the width)", res.load, res.load / pb.width);
    /* the outlet's flow only where the film is full: a cavitated film does not conserve
     * volume in the Reynolds model (Um h is carried on through it) */
    if (s->bc == LUB_REYNOLDS_BC_FULL_SOMMERFELD)
        lub_message("leakage     Q = %.6g m^3/s out of the sides (inlet %.6g, outlet %.6g m^3/s)",
                    res.leakage, res.q_in, res.q_out);
    else
        lub_message("leakage     Q = %.6g m^3/s out of the sides (inlet %.6g m^3/s)", res.leakage,
                    res.q_in);
    if (dimensionless) {
        lub_message("R, h0       R = %g m, h0 = %g m, sqrt(R h0) = %.6g m", d.radius, G->h0, d.sx);
        lub_message("peak        P = %.5f (all nodes)", res.p_max * d.sp);
        lub_message("load        W h0/(mu (U1+U2) R B) = %.5f (B the width)",
                    res.load / pb.width * G->h0 / (rc->mu * d.uref * d.radius));
    }
    lub_message("written     %s (the mid-plane z = 0)", written);
    if (written2d[0]) lub_message("written     %s", written2d);
    lub_message("time        solve %.3g s, total %.3g s", t_solve, lub_wtime() - t_start);
    free(p);
    free(mid);
}

/* The nodal table p of G's grid at x (linear between nodes). */
static double at_x(const lub_refgap *G, const double *v, double x)
{
    double f = (x - G->xa) / G->dx;
    int i = (int)floor(f);
    if (i < 0) return v[0];
    if (i >= G->n) return v[G->n];
    f -= i;
    return (1.0 - f) * v[i] + f * v[i + 1];
}

/* -series: the reference at every time of times[0..nt), one row each of
 * postProcessing/reynoldsRef/<first time>/pc.dat (or out_file): '# t pc load h', pc and h at
 * x = xc. */
static void series(const lub_case *c, lub_refcase *rc, const lub_time *times, size_t nt, double xc,
                   int given_x, const char *out_file, double t_start)
{
    const lub_refcase_settings *s = &rc->s;
    if (rc->ehl)
        lub_fatal("-series: the soft-EHL reference is steady (constant/models.yaml "
                  "elasticWall): a time series needs the rigid reference (softEHL: {mode: off} "
                  "in system/reynoldsRefDict.yaml)");
    if (s->width > 0.0)
        lub_fatal("-series: the time series is of the 1-D reference (the infinitely wide "
                  "film); system/reynoldsRefDict.yaml gives a finite width %g m: leave out "
                  "'width' for the series, or run reynoldsRef -time LIST for the finite width's "
                  "p2d.dat at each time",
                  s->width);
    if (!(xc >= s->inlet && xc <= s->outlet))
        lub_fatal("-at %g: the point must lie in [inlet, outlet] = [%g, %g] of "
                  "system/reynoldsRefDict.yaml",
                  xc, s->inlet, s->outlet);
    char path[LUB_PATH_MAX];
    lub_output o;
    if (out_file) {
        lub_output_open(&o, out_file);
    } else {
        lub_postproc_path(c, "reynoldsRef", times[0].name, "pc.dat", path);
        lub_output_open(&o, path);
    }
    lub_table_write_header(o.fp, "t[s] pc[Pa] load[N/m] h[m]");
    fprintf(o.fp, "# pc, h at x = %.9g m (%s); %s condition; %ld cells on [%g, %g] m\n", xc,
            given_x ? "-at" : "the film centre, midway between inlet and outlet",
            lub_reynolds_bc_names[s->bc], s->cells, s->inlet, s->outlet);
    double pmin = INFINITY, pmax = -INFINITY, tmin = 0, tmax = 0, t_solve = 0;
    for (size_t k = 0; k < nt; k++) {
        lub_refcase_move(rc, times[k].value, NULL);
        lub_refgap G;
        lub_refgap_sample(&G, rc);
        double *p = lub_malloc((size_t)(G.n + 1) * sizeof *p);
        lub_reynolds_result res;
        double t0 = lub_wtime();
        lub_reynolds_status st = lub_refcase_solve(rc, &G, p, &res);
        t_solve += lub_wtime() - t0;
        if (st != LUB_REYNOLDS_OK)
            lub_fatal_run("the Reynolds solve failed: %s (%d cells on [%g, %g], %s, t = %g s)",
                          lub_reynolds_status_string(st), G.n, G.xa, G.xb,
                          lub_reynolds_bc_names[s->bc], rc->t);
        double row[4] = {times[k].value, at_x(&G, p, xc), res.load, at_x(&G, G.h, xc)};
        lub_table_write_row(o.fp, row, 4);
        if (row[1] < pmin) pmin = row[1], tmin = row[0];
        if (row[1] > pmax) pmax = row[1], tmax = row[0];
        free(p);
        lub_refgap_free(&G);
    }
    lub_output_close(&o);
    lub_message("series      %zu times, t = %s .. %s s", nt, times[0].name, times[nt - 1].name);
    lub_message("point       x = %.6g m%s", xc, given_x ? "" : " (the film centre)");
    char ml[200], mu[200];
    lub_wall_motion_describe(&rc->motion[rc->wl], rc->g.dim, ml, sizeof ml);
    lub_wall_motion_describe(&rc->motion[rc->wu], rc->g.dim, mu, sizeof mu);
    lub_message("walls       lower '%s' %s, upper '%s' %s", s->lower, ml, s->upper, mu);
    lub_message("oil         rho = %g kg/m^3, nu = %g m^2/s, mu = %g Pa s", rc->rho, rc->nu,
                rc->mu);
    lub_message("condition   %s", lub_reynolds_bc_names[s->bc]);
    lub_message("pc          max %.6g Pa at t = %g s, min %.6g Pa at t = %g s", pmax, tmax, pmin,
                tmin);
    if (out_file)
        lub_message("written     %s", o.path);
    else
        lub_message("written     postProcessing/reynoldsRef/%s/pc.dat", times[0].name);
    lub_message("time        solve %.3g s, total %.3g s", t_solve, lub_wtime() - t_start);
}

/* "T0:T1:N": N + 1 times from T0 to T1 (N >= 1, 0 <= T0 < T1) */
static size_t parse_grid(const char *text, int precision, lub_time **times)
{
    double t0, t1;
    long n;
    char tail;
    if (sscanf(text, "%lf:%lf:%ld%c", &t0, &t1, &n, &tail) != 3 || !(t0 >= 0) || !(t1 > t0) ||
        n < 1 || n > 10000000)
        lub_fatal("-grid '%s': expected T0:T1:N, N + 1 times from T0 >= 0 to T1 > T0 (N >= 1), "
                  "e.g. -grid 0:1:200",
                  text);
    *times = lub_malloc((size_t)(n + 1) * sizeof **times);
    for (long k = 0; k <= n; k++) {
        double t = k == n ? t1 : t0 + (t1 - t0) * (double)k / (double)n;
        (*times)[k].value = t;
        lub_time_name(t, precision, (*times)[k].name, sizeof(*times)[k].name);
    }
    return (size_t)n + 1;
}

int main(int argc, char **argv)
{
    static int dimensionless = 0;
    static const char *out_file = NULL;
    static double inlet = NAN, at = NAN;
    static int series_flag = 0;
    static const char *grid = NULL;
    lub_option opts[] = {
        {"-dimensionless", NULL,
         "add the thesis' X = x/sqrt(R h0), P (T-38, T-39), H = h/h0; soft EHL: X = x/b, "
         "P = p/p_H, H = h R/b^2 (T-54..T-58)",
         LUB_OPT_FLAG, &dimensionless},
        {"-o", "FILE",
         "write the table to FILE ('-': standard output) instead of postProcessing (one "
         "time only)",
         LUB_OPT_STR, &out_file},
        {"-inlet", "X",
         "the inlet x instead of 'inlet' of system/reynoldsRefDict.yaml (e.g. the inlet "
         "meniscus of an MPS run: probe film)",
         LUB_OPT_REAL, &inlet},
        {"-series", NULL,
         "a time series: '# t pc load h' at every selected time folder (or -grid) in "
         "postProcessing/reynoldsRef/<first time>/pc.dat",
         LUB_OPT_FLAG, &series_flag},
        {"-grid", "T0:T1:N", "-series: N + 1 times from T0 to T1 instead of the time folders",
         LUB_OPT_STR, &grid},
        {"-at", "X",
         "-series: pc and h at x = X (default: the film centre, midway between "
         "inlet and outlet)",
         LUB_OPT_REAL, &at},
        {0}};
    lub_program_info info = {
        .name = "reynoldsRef",
        .summary = "1-D Reynolds-equation reference pressure of a case",
        .usage = "[OPTIONS]",
        .description =
            "Samples the gap h(x) between the lower and upper wall of the case geometry on a\n"
            "uniform grid from the inlet to the outlet and solves the Reynolds equation\n"
            "  d/dx(h^3/(12 mu) dp/dx) = (U1+U2)/2 dh/dx + dh/dt   (thesis T-32)\n"
            "with the Reynolds (free exit, p >= 0), half-Sommerfeld, full-Sommerfeld or\n"
            "given-exit condition.  U1, U2: x-velocities of the lower and upper wall\n"
            "(movingWalls); dh/dt from their y-velocities and, for a wall not parallel\n"
            "to x, from its shape carried along by its x-velocity.  Writes\n"
            "postProcessing/reynoldsRef/<time>/p.dat with columns x p h (and X P H with\n"
            "-dimensionless, which needs a cylinder as the upper wall: R its radius, h0 the\n"
            "minimum gap).\n"
            "Time: the reference at time t takes the gap at t, every moving wall translated\n"
            "by its velocity times t from its place in system/particleGenDict.yaml (t = 0),\n"
            "as lubFoam moves it (a squeeze film: h(t) = h(0) - V t).  t is 'time' of\n"
            "reynoldsRefDict.yaml (default 0), or each time folder of the case that -time,\n"
            "-latestTime or -noZero select (one table per time, e.g. -time '0.001:0.003'\n"
            "for every time a squeeze run wrote there).  Walls sliding along themselves\n"
            "(a rigid wedge's plane) leave the gap as it is: t then only names the output.\n"
            "A gap that has closed by t is an error giving the time the walls touch.\n"
            "Motion histories (movingWalls motion: sinusoidal or table): the walls at t are\n"
            "displaced by d(t) and dh/dt comes from their velocities d'(t) at t.\n"
            "Series (-series): the reference at every time folder selected (every one\n"
            "without -time, -latestTime, -noZero) or at the times of -grid T0:T1:N, one row\n"
            "per time of postProcessing/reynoldsRef/<first time>/pc.dat: '# t pc load h',\n"
            "pc the pressure and h the gap at the film centre (midway between inlet and\n"
            "outlet) or at -at X, load the integral of p (methods.md §5.5 (c): the squeeze\n"
            "film's p_c(t)).  With boundaryCondition reynolds the film carries no tension\n"
            "(p >= 0: 0 while the walls open), with fullSommerfeld it does.\n"
            "Soft EHL (constant/models.yaml elasticWall, softEHL in reynoldsRefDict.yaml):\n"
            "the upper wall is an elastic cylinder carrying the load W; the gap\n"
            "h = h0 + x^2/(2R) + v(x), v from the half-space influence coefficients (thesis\n"
            "T-46..T-49) applied to the pressure, and h0 such that the integral of p is W\n"
            "are solved together with the Reynolds equation (Newton's method).  Reports\n"
            "h_min, h(0), the peak, the exit and the load error.\n"
            "Finite width ('width' in reynoldsRefDict.yaml, with 'nz' cells across): the\n"
            "2-D Reynolds equation over the bearing's area, z across the motion,\n"
            "  d/dx(h^3/(12 mu) dp/dx) + d/dz(h^3/(12 mu) dp/dz) = (U1+U2)/2 dh/dx + dh/dt\n"
            "with the gap h(x, z) of the walls over the area (uniform in z for a roller\n"
            "along z; a sphere over a plane gives the point contact, h about\n"
            "h0 + (x^2 + z^2)/(2R)), p = 0 at the sides z = +-width/2 and the same x\n"
            "conditions; solved by CHOLMOD (or 'linearSolver: pcg', with AMG).  Writes\n"
            "p2d.dat (x z p, a blank line between x columns: gnuplot splot) beside p.dat,\n"
            "which then holds the mid-plane z = 0, and reports the load [N] and the side\n"
            "leakage [m^3/s] (doc/methods.md 5.6).",
        .dictionaries = "system/reynoldsRefDict.yaml\nsystem/particleGenDict.yaml\n"
                        "constant/transportProperties.yaml\nconstant/models.yaml\n"
                        "system/controlDict.yaml (timePrecision, optional)",
        .time_selection = 1,
        .has_case = 1,
        .min_args = 0,
        .max_args = 0};
    lub_args a;
    lub_args_parse(&a, argc, argv, &info, opts);
    if (out_file && strcmp(out_file, "-") == 0) lub_set_quiet(1); /* stdout is the table */
    double t_start = lub_wtime();

    /* the case: settings, geometry, oil, wall motion (src/reynolds/refcase.h) */
    lub_case c;
    lub_case_open(&c, a.case_dir);
    char path[LUB_PATH_MAX];
    lub_refcase rc;
    lub_refcase_read(&rc, &c);
    if (isfinite(inlet)) {
        double end = rc.s.bc == LUB_REYNOLDS_BC_GIVEN_EXIT ? rc.s.exit_x : rc.s.outlet;
        if (!(inlet < end))
            lub_fatal("-inlet %g: the inlet must lie before the %s (%g) of "
                      "system/reynoldsRefDict.yaml",
                      inlet, rc.s.bc == LUB_REYNOLDS_BC_GIVEN_EXIT ? "exit" : "outlet", end);
        rc.s.inlet = inlet;
    }
    const lub_refcase_settings *s = &rc.s;
    if (dimensionless) lub_refcase_check_scales(&rc);

    /* the times: the time folders selected on the command line, else the dictionary's time,
     * named with the run's timePrecision (the solver owns the rest of controlDict, so it is
     * not checked here) */
    lub_time *times;
    size_t nt = 1;
    int from_folders = a.time || a.latest_time || a.no_zero;
    if ((grid || isfinite(at)) && !series_flag)
        lub_fatal("%s belongs to -series (a time series of the film-centre pressure)",
                  grid ? "-grid" : "-at");
    if (series_flag) {
        if (grid && from_folders)
            lub_fatal("-series: give either -grid or a time folder selection (-time, "
                      "-latestTime, -noZero), not both");
        if (grid) {
            int precision = 6;
            lub_dict *cd =
                lub_dict_read_optional(lub_case_path(&c, path, "system/controlDict.yaml"));
            if (cd) {
                precision = (int)lub_dict_int_or(lub_dict_root(cd), "timePrecision", 6, 1, 17);
                lub_dict_free(cd);
            }
            nt = parse_grid(grid, precision, &times);
        } else {
            nt = lub_case_select_times(&c, a.time, a.latest_time, a.no_zero, &times);
        }
        for (size_t k = 0; k < nt; k++)
            if (!(times[k].value >= 0.0))
                lub_fatal("time folder '%s': the reference needs a time >= 0", times[k].name);
        series(&c, &rc, times, nt, isfinite(at) ? at : 0.5 * (s->inlet + s->outlet), isfinite(at),
               out_file, t_start);
        free(times);
        lub_refcase_free(&rc);
        return 0;
    }
    if (from_folders) {
        nt = lub_case_select_times(&c, a.time, a.latest_time, a.no_zero, &times);
    } else {
        int precision = 6;
        lub_dict *cd = lub_dict_read_optional(lub_case_path(&c, path, "system/controlDict.yaml"));
        if (cd) {
            precision = (int)lub_dict_int_or(lub_dict_root(cd), "timePrecision", 6, 1, 17);
            lub_dict_free(cd);
        }
        times = lub_malloc(sizeof *times);
        times[0].value = s->time;
        lub_time_name(s->time, precision, times[0].name, sizeof times[0].name);
    }
    if (out_file && nt > 1)
        lub_fatal("-o writes one table, but the time selection has %zu times (%s to %s): "
                  "select one, or leave out -o to write postProcessing/reynoldsRef/<time>/",
                  nt, times[0].name, times[nt - 1].name);
    for (size_t k = 0; k < nt; k++)
        if (!(times[k].value >= 0.0))
            lub_fatal("time folder '%s': the reference needs a time >= 0", times[k].name);

    for (size_t k = 0; k < nt; k++) {
        /* the walls at t, the gap between them, and the Reynolds equation on it */
        lub_refcase_move(&rc, times[k].value, from_folders ? NULL : s->time_node);
        lub_refgap G;
        lub_refgap_sample(&G, &rc);
        report_time(&rc, &G);
        if (rc.ehl) /* soft EHL: the gap follows from the pressure (reynoldsRefEHL.c) */
            reynoldsRef_soft_ehl(&c, &rc, &G, out_file, times[k].name, dimensionless, t_start);
        else if (s->width > 0.0) /* the finite width */
            reference2d(&c, &rc, &G, out_file, times[k].name, dimensionless, t_start);
        else
            reference(&c, &rc, &G, out_file, times[k].name, dimensionless, t_start);
        lub_refgap_free(&G);
    }
    free(times);
    lub_refcase_free(&rc);
    return 0;
}
