/* reynoldsRef: the 1-D Reynolds-equation reference of a case (methods.md 5, thesis 3-2).
 *
 * Reads the case's geometry (system/particleGenDict.yaml), oil (transportProperties), wall
 * motion (models.yaml movingWalls) and system/reynoldsRefDict.yaml; samples the gap
 * h(x) = (upper wall height) - (lower wall height) on a uniform grid between the inlet and
 * the outlet; solves the Reynolds equation (T-32) with the chosen boundary condition; writes
 * postProcessing/reynoldsRef/<time>/p.dat (# x p h [X P H]) and prints a short report.
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
#include "models/models.h"
#include "models/transport.h"
#include "reynolds/reynolds.h"

#define DICT "system/reynoldsRefDict.yaml"

/* The settings of system/reynoldsRefDict.yaml. */
typedef struct {
    lub_dict *dict;
    const char *lower, *upper; /* wall names */
    lub_node *lower_node, *upper_node, *inlet_node, *outlet_node;
    double inlet, outlet;
    long cells;
    int bc;
    double exit_x;
    double time;
    double tolerance;
    long max_iterations;
} ref_settings;

static void settings_read(ref_settings *s, const char *path)
{
    s->dict = lub_dict_read(path);
    lub_node *root = lub_dict_root(s->dict);
    s->lower_node = lub_dict_get(root, "lowerWall");
    s->lower = lub_dict_str(root, "lowerWall");
    s->upper_node = lub_dict_get(root, "upperWall");
    s->upper = lub_dict_str(root, "upperWall");
    s->inlet_node = lub_dict_get(root, "inlet");
    s->inlet = lub_dict_real(root, "inlet", LUB_ANY);
    s->outlet_node = lub_dict_get(root, "outlet");
    s->outlet = lub_dict_real(root, "outlet", LUB_ANY);
    if (!(s->outlet > s->inlet))
        lub_node_error(s->outlet_node, "'outlet' must be > inlet (%g), found '%s'", s->inlet,
                       lub_node_text(s->outlet_node));
    s->cells = lub_dict_int_or(root, "cells", 4000, 2, 10000000);
    s->bc =
        lub_dict_choice(root, "boundaryCondition", lub_reynolds_bc_names, LUB_REYNOLDS_BC_REYNOLDS);
    if (s->bc == LUB_REYNOLDS_BC_GIVEN_EXIT) {
        lub_node *e = lub_dict_get(root, "exit");
        s->exit_x = lub_dict_real(root, "exit", LUB_ANY);
        if (!(s->exit_x > s->inlet && s->exit_x <= s->outlet))
            lub_node_error(e, "'exit' must be in (inlet, outlet] = (%g, %g], found '%s'", s->inlet,
                           s->outlet, lub_node_text(e));
    } else {
        lub_node *e = lub_dict_find(root, "exit");
        if (e)
            lub_node_error(e,
                           "'exit' is used only with 'boundaryCondition: givenExit' (here "
                           "'%s')",
                           lub_reynolds_bc_names[s->bc]);
    }
    s->time = lub_dict_real_or(root, "time", 0.0, LUB_NONNEGATIVE);
    s->tolerance = lub_dict_real_or(root, "tolerance", 1e-12, (lub_range){0.0, 1e-3, 1, 0});
    s->max_iterations = lub_dict_int_or(root, "maxIterations", 0, 0, 1000000000);
    lub_dict_finish(s->dict);
}

/* Wall index by name, fatal at the dictionary entry naming it. */
static int find_wall(const lub_geometry *g, const char *name, lub_node *node)
{
    int w = lub_geometry_find_wall(g, name);
    if (w >= 0) return w;
    char list[1024] = "";
    size_t len = 0;
    const char *names[256] = {0};
    int nn = g->nwalls < 256 ? g->nwalls : 256;
    for (int k = 0; k < nn; k++) {
        names[k] = g->walls[k].name;
        if (len < sizeof list)
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", k ? ", " : "", names[k]);
    }
    const char *near = lub_closest(name, names, (size_t)nn);
    lub_node_error(node, "'%s' is not a wall of system/particleGenDict.yaml%s%s%s (walls: %s)",
                   name, near ? " (did you mean '" : "", near ? near : "", near ? "'?)" : "",
                   nn ? list : "none");
}

/* Height of wall w at x, fatal (at the inlet or outlet entry) when the wall does not span x. */
static double wall_y(const ref_settings *s, const lub_wall *w, double x, int upper)
{
    double y;
    if (!lub_wall_height(w, x, upper, &y))
        lub_node_error(x < 0.5 * (s->inlet + s->outlet) ? s->inlet_node : s->outlet_node,
                       "the %s wall '%s' does not span [inlet, outlet] = [%g, %g]: no surface "
                       "at x = %.9g",
                       upper ? "upper" : "lower", w->name, s->inlet, s->outlet, x);
    return y;
}

/* Slope dy/dx of a wall surface at x, by central differences inside [xa, xb]. */
static double wall_slope(const ref_settings *s, const lub_wall *w, double x, int upper, double dx)
{
    double d = 1e-3 * dx, xl = fmax(x - d, s->inlet), xr = fmin(x + d, s->outlet);
    return (wall_y(s, w, xr, upper) - wall_y(s, w, xl, upper)) / (xr - xl);
}

/* The gap on the grid: h at the n + 1 nodes and n face midpoints, dh/dt at the nodes, and
 * the minimum gap h0 (for -dimensionless). */
typedef struct {
    int n;
    double xa, xb, dx;
    double *h, *hf, *dhdt;
    double h0, x_h0;
    int moving_shape; /* dh/dt != 0 somewhere */
} ref_gap;

/* h(x) = (upper wall height) - (lower wall height) at nodes and faces; fatal (naming
 * reynoldsRefDict.yaml:line) when a wall does not span the interval or the gap is <= 0. */
static void gap_sample(ref_gap *G, const ref_settings *s, const lub_wall *lower,
                       const lub_wall *upper)
{
    int n = G->n = (int)s->cells;
    G->xa = s->inlet;
    G->xb = s->outlet;
    double dx = G->dx = (G->xb - G->xa) / n;
    G->h = lub_malloc((size_t)(n + 1) * sizeof *G->h);
    G->hf = lub_malloc((size_t)n * sizeof *G->hf);
    G->dhdt = lub_malloc((size_t)(n + 1) * sizeof *G->dhdt);
    G->h0 = INFINITY;
    G->x_h0 = G->xa;
    int i_h0 = 0;
    for (int i = 0; i <= 2 * n; i++) {
        double x = i == 2 * n ? G->xb : G->xa + 0.5 * i * dx;
        double gap = wall_y(s, upper, x, 1) - wall_y(s, lower, x, 0);
        if (!(gap > 0.0))
            lub_node_error(s->upper_node,
                           "the gap between '%s' and '%s' is %s at x = %.9g: it must be > 0 "
                           "on [inlet, outlet] = [%g, %g]",
                           s->lower, s->upper, gap == 0.0 ? "zero" : "negative", x, G->xa, G->xb);
        if (i % 2 == 0)
            G->h[i / 2] = gap;
        else
            G->hf[i / 2] = gap;
        if (gap < G->h0) {
            G->h0 = gap;
            G->x_h0 = x;
            i_h0 = i;
        }
    }
    /* the minimum between samples: vertex of the parabola through the smallest sample and its
     * neighbours (half a cell apart) */
    if (i_h0 > 0 && i_h0 < 2 * n) {
        double gm = i_h0 % 2 ? G->h[i_h0 / 2] : G->hf[i_h0 / 2 - 1];
        double gp = i_h0 % 2 ? G->h[i_h0 / 2 + 1] : G->hf[i_h0 / 2];
        double curv = gm - 2.0 * G->h0 + gp;
        if (curv > 0.0) {
            G->x_h0 += 0.25 * dx * (gm - gp) / curv;
            G->h0 -= (gp - gm) * (gp - gm) / (8.0 * curv);
        }
    }
}

/* dh/dt at fixed x for walls translating with velocities vl (lower) and vu (upper): the
 * normal speeds, and each surface carried along x (-U dy/dx), which vanishes for walls
 * parallel to x (the squeeze term of T-32). */
static void gap_motion(ref_gap *G, const ref_settings *s, const lub_wall *lower,
                       const lub_wall *upper, const double *vl, const double *vu)
{
    G->moving_shape = 0;
    for (int i = 0; i <= G->n; i++) {
        double x = G->xa + i * G->dx, r = vu[1] - vl[1];
        if (vu[0] != 0.0) r -= vu[0] * wall_slope(s, upper, x, 1, G->dx);
        if (vl[0] != 0.0) r += vl[0] * wall_slope(s, lower, x, 0, G->dx);
        G->dhdt[i] = r;
        G->moving_shape |= r != 0.0;
    }
}

static void gap_free(ref_gap *G)
{
    free(G->h);
    free(G->hf);
    free(G->dhdt);
}

/* Dimensionless scales of the thesis (T-38, T-39): X = x/sx, P = p sp, H = h/h0. */
typedef struct {
    int on;
    double radius, uref, sx, sp;
} ref_scales;

/* The table "# x p h [X P H]" to out_file, or postProcessing/reynoldsRef/<time>/p.dat. */
static void table_write(const lub_case *c, const char *out_file, const char *tname,
                        const ref_gap *G, const double *p, const ref_scales *d, char *written)
{
    char path[LUB_PATH_MAX];
    lub_output o;
    if (out_file) {
        lub_output_open(&o, out_file);
    } else {
        lub_postproc_path(c, "reynoldsRef", tname, "p.dat", path);
        lub_output_open(&o, path);
    }
    lub_table_write_header(o.fp, d->on ? "x[m] p[Pa] h[m] X P H" : "x[m] p[Pa] h[m]");
    for (int i = 0; i <= G->n; i++) {
        double x = G->xa + i * G->dx;
        double row[6] = {x, p[i], G->h[i], 0.0, 0.0, 0.0};
        if (d->on) {
            row[3] = x / d->sx;
            row[4] = p[i] * d->sp;
            row[5] = G->h[i] / G->h0;
        }
        lub_table_write_row(o.fp, row, d->on ? 6 : 3);
    }
    lub_output_close(&o);
    if (out_file)
        snprintf(written, LUB_PATH_MAX, "%s", o.path);
    else
        snprintf(written, LUB_PATH_MAX, "postProcessing/reynoldsRef/%s/p.dat", tname);
}

int main(int argc, char **argv)
{
    static int dimensionless = 0;
    static const char *out_file = NULL;
    lub_option opts[] = {
        {"-dimensionless", NULL, "add the thesis' X = x/sqrt(R h0), P (T-38, T-39), H = h/h0",
         LUB_OPT_FLAG, &dimensionless},
        {"-o", "FILE", "write the table to FILE ('-': standard output) instead of postProcessing",
         LUB_OPT_STR, &out_file},
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
            "minimum gap).",
        .dictionaries = "system/reynoldsRefDict.yaml\nsystem/particleGenDict.yaml\n"
                        "constant/transportProperties.yaml\nconstant/models.yaml\n"
                        "system/controlDict.yaml (timePrecision, optional)",
        .time_selection = 0,
        .has_case = 1,
        .min_args = 0,
        .max_args = 0};
    lub_args a;
    lub_args_parse(&a, argc, argv, &info, opts);
    if (out_file && strcmp(out_file, "-") == 0) lub_set_quiet(1); /* stdout is the table */
    double t_start = lub_wtime();

    /* the case: settings, geometry, oil, wall motion */
    lub_case c;
    lub_case_open(&c, a.case_dir);
    char path[LUB_PATH_MAX];
    ref_settings s;
    settings_read(&s, lub_case_path(&c, path, DICT));

    lub_geometry g;
    lub_geometry_read(&g, lub_case_path(&c, path, "system/particleGenDict.yaml"));
    int wl = find_wall(&g, s.lower, s.lower_node), wu = find_wall(&g, s.upper, s.upper_node);
    if (wl == wu)
        lub_node_error(s.upper_node, "'upperWall' and 'lowerWall' are the same wall '%s'", s.upper);
    const lub_wall *lower = &g.walls[wl], *upper = &g.walls[wu];

    double rho, nu;
    lub_transport_read(lub_case_path(&c, path, "constant/transportProperties.yaml"), &rho, &nu);
    double mu = rho * nu;

    lub_dict *md = lub_dict_read(lub_case_path(&c, path, "constant/models.yaml"));
    lub_models_declare(lub_dict_root(md));
    double(*vel)[3] = lub_malloc((size_t)g.nwalls * sizeof *vel);
    int *moving = lub_malloc((size_t)g.nwalls * sizeof *moving);
    lub_moving_walls_read(lub_dict_root(md), &g, vel, moving);
    lub_dict_finish(md);
    lub_dict_free(md);
    double u1 = vel[wl][0], u2 = vel[wu][0];

    ref_scales d = {.on = dimensionless, .uref = u1 + u2};
    if (d.on) {
        if (upper->type != LUB_WALL_CYLINDER)
            lub_node_error(s.upper_node,
                           "-dimensionless needs a cylinder as the upper wall (R is its "
                           "radius), but '%s' is not a cylinder",
                           s.upper);
        if (d.uref == 0.0)
            lub_node_error(s.lower_node,
                           "-dimensionless scales p with U1 + U2, which is 0 here (set the "
                           "wall speeds in constant/models.yaml movingWalls)");
        d.radius = upper->radius;
    }

    /* time folder name of the output, with the run's timePrecision (the solver owns the rest
     * of controlDict, so it is not checked here) */
    int precision = 6;
    lub_dict *cd = lub_dict_read_optional(lub_case_path(&c, path, "system/controlDict.yaml"));
    if (cd) {
        precision = (int)lub_dict_int_or(lub_dict_root(cd), "timePrecision", 6, 1, 17);
        lub_dict_free(cd);
    }
    char tname[64];
    lub_time_name(s.time, precision, tname, sizeof tname);

    /* the gap, and the Reynolds equation on it */
    ref_gap G;
    gap_sample(&G, &s, lower, upper);
    gap_motion(&G, &s, lower, upper, vel[wl], vel[wu]);

    lub_reynolds_problem pb;
    lub_reynolds_problem_init(&pb);
    pb.n = G.n;
    pb.xa = G.xa;
    pb.xb = G.xb;
    pb.h = G.h;
    pb.h_face = G.hf;
    pb.u1 = u1;
    pb.u2 = u2;
    pb.dhdt_nodes = G.dhdt;
    pb.mu = mu;
    pb.bc = (lub_reynolds_bc)s.bc;
    pb.exit_x = s.exit_x;
    pb.tolerance = s.tolerance;
    pb.max_iterations = (int)s.max_iterations;
    double *p = lub_malloc((size_t)(G.n + 1) * sizeof *p);
    lub_reynolds_result res = {.p = p};
    double t_solve = lub_wtime();
    lub_reynolds_status st = lub_reynolds_solve(&pb, &res);
    t_solve = lub_wtime() - t_solve;
    if (st != LUB_REYNOLDS_OK)
        lub_fatal_run("the Reynolds solve failed: %s (%d cells on [%g, %g], %s)",
                      lub_reynolds_status_string(st), G.n, G.xa, G.xb, lub_reynolds_bc_names[s.bc]);

    /* output and report */
    if (d.on) {
        d.sx = sqrt(d.radius * G.h0);
        d.sp = pow(G.h0, 1.5) / (mu * d.uref * sqrt(d.radius));
    }
    char written[LUB_PATH_MAX];
    table_write(&c, out_file, tname, &G, p, &d, written);

    lub_message("grid        %d cells on [%g, %g] m, dx = %.4g m", G.n, G.xa, G.xb, G.dx);
    lub_message("walls       lower '%s' U1 = %g m/s, upper '%s' U2 = %g m/s%s", s.lower, u1,
                s.upper, u2, G.moving_shape ? ", dh/dt != 0 (wall motion)" : "");
    lub_message("oil         rho = %g kg/m^3, nu = %g m^2/s, mu = %g Pa s", rho, nu, mu);
    lub_message("gap         h0 = %.6g m (minimum, at x = %.6g m)", G.h0, G.x_h0);
    lub_message("condition   %s%s", lub_reynolds_bc_names[s.bc],
                s.bc == LUB_REYNOLDS_BC_REYNOLDS ? " (p >= 0; p = dp/dx = 0 at the free exit)"
                                                 : "");
    if (s.bc == LUB_REYNOLDS_BC_REYNOLDS)
        lub_message("active set  %d iteration%s, %d cavitated nodes", res.iterations,
                    res.iterations == 1 ? "" : "s", res.n_cavitated);
    lub_message("exit        x = %.6g m%s", res.x_exit,
                res.x_exit >= G.xb ? " (the outlet: the film is full up to it)" : "");
    lub_message("peak        p = %.6g Pa at x = %.6g m", res.p_max, res.x_max);
    lub_message("load        W = %.6g N/m", res.load);
    if (d.on) {
        lub_message("R, h0       R = %g m, h0 = %g m, sqrt(R h0) = %.6g m", d.radius, G.h0, d.sx);
        lub_message("exit        X = %.5f (Martin, T-37: X = 0.475 sqrt(2) = %.5f)",
                    res.x_exit / d.sx, 0.475 * sqrt(2.0));
        lub_message("peak        P = %.5f at X = %.5f", res.p_max * d.sp, res.x_max / d.sx);
        lub_message("load        W h0/(mu (U1+U2) R) = %.5f",
                    res.load * G.h0 / (mu * d.uref * d.radius));
    }
    lub_message("written     %s", written);
    lub_message("time        solve %.3g s, total %.3g s", t_solve, lub_wtime() - t_start);

    free(p);
    gap_free(&G);
    free(vel);
    free(moving);
    lub_dict_free(s.dict);
    lub_geometry_free(&g);
    return 0;
}
