/* lubkit Reynolds reference of a case (see refcase.h).  Moved out of reynoldsRef.c so that
 * probe -dimensionless uses the same R, h0 and U1 + U2. */
#include "reynolds/refcase.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "linalg/linsolve.h"
#include "models/models.h"
#include "models/transport.h"
#include "reynolds/reynolds.h"

const char *const lub_refcase_ehl_modes[] = {"auto", "on", "off", NULL};

static void settings_read(lub_refcase_settings *s, const char *path)
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
    s->exit_x = 0.0;
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
    s->time_node = lub_dict_find(root, "time");
    s->tolerance = lub_dict_real_or(root, "tolerance", 1e-12, (lub_range){0.0, 1e-3, 1, 0});
    s->max_iterations = lub_dict_int_or(root, "maxIterations", 0, 0, 1000000000);
    s->bc_node = lub_dict_find(root, "boundaryCondition");
    s->cells_node = lub_dict_find(root, "cells");
    lub_node *se = lub_dict_map_or(root, "softEHL");
    s->ehl_mode_node = lub_dict_find(se, "mode");
    s->ehl_mode = lub_dict_choice(se, "mode", lub_refcase_ehl_modes, LUB_REFCASE_EHL_AUTO);
    s->ehl_tolerance = lub_dict_real_or(se, "tolerance", 1e-8, (lub_range){0.0, 1e-3, 1, 0});
    s->ehl_max_iterations = lub_dict_int_or(se, "maxIterations", 400, 1, 1000000);
    /* the finite width (reynolds2d.h): nz and linearSolver belong to it */
    s->width_node = lub_dict_find(root, "width");
    s->width = lub_dict_real_or(root, "width", 0.0, LUB_POSITIVE);
    lub_node *nz = lub_dict_find(root, "nz"), *ls = lub_dict_find(root, "linearSolver");
    if (!s->width_node && (nz || ls))
        lub_node_error(nz ? nz : ls,
                       "'%s' belongs to the finite-width reference: give 'width' too (the "
                       "bearing's length across the motion, m)",
                       nz ? "nz" : "linearSolver");
    s->nz = lub_dict_int_or(root, "nz", 32, 2, 100000);
    if (s->nz % 2)
        lub_node_error(nz,
                       "'nz' must be even, so that the mid-plane z = 0 is a grid line "
                       "(found %ld)",
                       s->nz);
    static const char *const solvers[] = {"cholmod", "pcg", NULL}; /* lub_linsolver_kind */
    s->solver = lub_dict_choice(root, "linearSolver", solvers, LUB_LINSOLVER_CHOLMOD);
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

void lub_refcase_read(lub_refcase *rc, const lub_case *c)
{
    char path[LUB_PATH_MAX];
    memset(rc, 0, sizeof *rc);
    lub_refcase_settings *s = &rc->s;
    settings_read(s, lub_case_path(c, path, "system/reynoldsRefDict.yaml"));

    lub_geometry_read(&rc->g, lub_case_path(c, path, "system/particleGenDict.yaml"));
    rc->wl = find_wall(&rc->g, s->lower, s->lower_node);
    rc->wu = find_wall(&rc->g, s->upper, s->upper_node);
    if (rc->wl == rc->wu)
        lub_node_error(s->upper_node, "'upperWall' and 'lowerWall' are the same wall '%s'",
                       s->upper);
    for (int k = 0; k < 2; k++) {
        const lub_wall *w0 = &rc->g.walls[k ? rc->wu : rc->wl];
        rc->wt[k].pts = w0->npts ? lub_malloc(2 * (size_t)w0->npts * sizeof *w0->pts) : NULL;
    }
    rc->lower = &rc->wt[0];
    rc->upper = &rc->wt[1];

    lub_transport_read(lub_case_path(c, path, "constant/transportProperties.yaml"), &rc->rho,
                       &rc->nu);
    rc->mu = rc->rho * rc->nu;

    lub_dict *md = lub_dict_read(lub_case_path(c, path, "constant/models.yaml"));
    lub_models_declare(lub_dict_root(md));
    rc->vel = lub_malloc((size_t)rc->g.nwalls * sizeof *rc->vel);
    rc->moving = lub_malloc((size_t)rc->g.nwalls * sizeof *rc->moving);
    rc->motion = lub_malloc((size_t)rc->g.nwalls * sizeof *rc->motion);
    lub_moving_walls_read(lub_dict_root(md), &rc->g, rc->motion, rc->moving);
    lub_refcase_move(rc, 0.0, NULL);
    int elastic = lub_elastic_wall_read(lub_dict_root(md), &rc->g, &rc->ew);
    lub_dict_finish(md);
    rc->u1 = rc->vel[rc->wl][0];
    rc->u2 = rc->vel[rc->wu][0];

    /* soft EHL: the elastic cylinder must be the upper wall, the exit free */
    rc->ehl = elastic && s->ehl_mode != LUB_REFCASE_EHL_OFF;
    if (s->ehl_mode == LUB_REFCASE_EHL_ON && !elastic)
        lub_node_error(s->ehl_mode_node,
                       "softEHL mode 'on' needs the elasticWall model in constant/models.yaml "
                       "(patch, E, load; template etc/templates/models.yaml)");
    if (rc->ehl && rc->ew.patch != rc->wu)
        lub_node_error(rc->ew.patch_node,
                       "elasticWall: patch '%s' must be the upper wall of the Reynolds reference "
                       "('upperWall: %s' in system/reynoldsRefDict.yaml), or set 'softEHL: "
                       "{mode: off}' there for the rigid reference",
                       rc->ew.patch_name, s->upper);
    if (rc->ehl && s->bc != LUB_REYNOLDS_BC_REYNOLDS)
        lub_node_error(s->bc_node,
                       "soft EHL solves the free exit: 'boundaryCondition' must be 'reynolds' "
                       "(found '%s'), or set 'softEHL: {mode: off}' for the rigid reference",
                       lub_reynolds_bc_names[s->bc]);
    if (rc->ehl && s->width_node)
        lub_node_error(s->width_node,
                       "the finite-width reference is rigid: remove 'width', or set 'softEHL: "
                       "{mode: off}' for the rigid reference over the width");
    if (rc->ehl && s->cells > 8000)
        lub_node_error(s->cells_node,
                       "soft EHL solves a dense Newton system (time ~ cells^3, 0.05 s per "
                       "iteration at 1000 cells): at most 8000 cells, found %ld (the scheme is "
                       "second order: 1000-2000 cells are plenty)",
                       s->cells);
    /* a steady gap: the cylinder at rest, the lower wall sliding along itself */
    const double *vl = rc->vel[rc->wl], *vu = rc->vel[rc->wu];
    int flat = rc->lower->type == LUB_WALL_PLANE && fabs(rc->lower->normal[0]) < 1e-12;
    if (rc->ehl && (lub_wall_motion_is_history(&rc->motion[rc->wl]) ||
                    lub_wall_motion_is_history(&rc->motion[rc->wu])))
        lub_node_error(rc->ew.node,
                       "soft EHL is steady: the walls '%s' and '%s' must move at constant "
                       "velocities (constant/models.yaml movingWalls gives a motion history)",
                       s->lower, s->upper);
    if (rc->ehl && (vu[0] != 0.0 || vu[1] != 0.0 || vl[1] != 0.0 || (vl[0] != 0.0 && !flat)))
        lub_node_error(rc->ew.node,
                       "soft EHL is steady: the elastic cylinder '%s' must be at rest and the "
                       "lower wall '%s' may only slide along x%s (constant/models.yaml "
                       "movingWalls gives the cylinder (%g, %g) m/s, the lower wall (%g, %g) m/s)",
                       rc->ew.patch_name, s->lower, flat ? "" : ", being a plane parallel to x",
                       vu[0], vu[1], vl[0], vl[1]);
    lub_dict_free(md);
    rc->ew.node = rc->ew.patch_node = rc->ew.ramp_node = NULL; /* freed with md */
}

/* Wall w0 with motion mo, translated to time t into w (w->pts its own array). */
static void wall_at(lub_wall *w, const lub_wall *w0, const lub_wall_motion *mo, double t)
{
    double d[3];
    lub_wall_motion_displacement(mo, t, d);
    lub_wall_translate(w, w0, d);
}

void lub_refcase_move(lub_refcase *rc, double t, const lub_node *node)
{
    if (!(t >= 0.0) || !isfinite(t)) lub_bug("lub_refcase_move: t = %g", t);
    wall_at(&rc->wt[0], &rc->g.walls[rc->wl], &rc->motion[rc->wl], t);
    wall_at(&rc->wt[1], &rc->g.walls[rc->wu], &rc->motion[rc->wu], t);
    for (int w = 0; w < rc->g.nwalls; w++) lub_wall_motion_velocity(&rc->motion[w], t, rc->vel[w]);
    lub_wall_motion_displacement(&rc->motion[rc->wl], t, rc->disp[0]);
    lub_wall_motion_displacement(&rc->motion[rc->wu], t, rc->disp[1]);
    rc->u1 = rc->vel[rc->wl][0];
    rc->u2 = rc->vel[rc->wu][0];
    rc->t = t;
    rc->t_node = node;
}

void lub_refcase_free(lub_refcase *rc)
{
    free(rc->wt[0].pts);
    free(rc->wt[1].pts);
    free(rc->vel);
    free(rc->moving);
    if (rc->motion) lub_moving_walls_free(rc->motion, rc->g.nwalls);
    free(rc->motion);
    lub_dict_free(rc->s.dict);
    lub_geometry_free(&rc->g);
    memset(rc, 0, sizeof *rc);
}

/* " at t = 0.002 s (moved by (u t, v t) m)" when the walls are those of a time t > 0 at
 * which wall w has moved, else "". */
static const char *moved_note(const lub_refcase *rc, const lub_wall *w, char *buf, size_t size)
{
    const double *v = rc->disp[w == rc->lower ? 0 : 1];
    buf[0] = '\0';
    if (rc->t > 0.0 && (v[0] != 0.0 || v[1] != 0.0 || v[2] != 0.0))
        snprintf(buf, size, " at t = %g s (moved by (%g, %g) m from system/particleGenDict.yaml)",
                 rc->t, v[0], v[1]);
    return buf;
}

/* Height of wall w (rc->lower or rc->upper) at x, fatal (at the inlet or outlet entry) when
 * the wall does not span x. */
static double wall_y(const lub_refcase *rc, const lub_wall *w, double x, int upper)
{
    const lub_refcase_settings *s = &rc->s;
    double y;
    char note[160];
    if (!lub_wall_height(w, x, upper, &y))
        lub_node_error(x < 0.5 * (s->inlet + s->outlet) ? s->inlet_node : s->outlet_node,
                       "the %s wall '%s'%s does not span [inlet, outlet] = [%g, %g]: no "
                       "surface at x = %.9g",
                       upper ? "upper" : "lower", w->name, moved_note(rc, w, note, sizeof note),
                       s->inlet, s->outlet, x);
    return y;
}

/* Slope dy/dx of a wall surface at x, by central differences inside [xa, xb]. */
static double wall_slope(const lub_refcase *rc, const lub_wall *w, double x, int upper, double dx)
{
    const lub_refcase_settings *s = &rc->s;
    double d = 1e-3 * dx, xl = fmax(x - d, s->inlet), xr = fmin(x + d, s->outlet);
    return (wall_y(rc, w, xr, upper) - wall_y(rc, w, xl, upper)) / (xr - xl);
}

/* The smallest gap on the 2n + 1 sample points of [inlet, outlet] with both walls moved to
 * time t, or NAN when a wall does not span a point. */
static double min_gap_at(const lub_refcase *rc, double t, int n)
{
    const lub_refcase_settings *s = &rc->s;
    lub_wall w[2];
    double m = INFINITY;
    for (int k = 0; k < 2; k++) {
        const lub_wall *w0 = &rc->g.walls[k ? rc->wu : rc->wl];
        w[k].pts = w0->npts ? lub_malloc(2 * (size_t)w0->npts * sizeof *w0->pts) : NULL;
        wall_at(&w[k], w0, &rc->motion[k ? rc->wu : rc->wl], t);
    }
    for (int i = 0; i <= 2 * n && !isnan(m); i++) {
        double x = s->inlet + 0.5 * i * (s->outlet - s->inlet) / n, yl, yu;
        if (!lub_wall_height(&w[0], x, 0, &yl) || !lub_wall_height(&w[1], x, 1, &yu))
            m = NAN;
        else
            m = fmin(m, yu - yl);
    }
    free(w[0].pts);
    free(w[1].pts);
    return m;
}

/* Fatal: the gap at x is <= 0 at time rc->t.  When it was open at t = 0, the walls have
 * moved into each other: the message gives the time at which they touch (bisection on the
 * smallest sampled gap) and names the time's entry. */
_Noreturn static void gap_closed(const lub_refcase *rc, double x, double gap)
{
    const lub_refcase_settings *s = &rc->s;
    const char *what = gap == 0.0 ? "zero" : "negative";
    double g0 = rc->t > 0.0 ? min_gap_at(rc, 0.0, (int)s->cells) : NAN;
    if (!(g0 > 0.0))
        lub_node_error(s->upper_node,
                       "the gap between '%s' and '%s' is %s at x = %.9g: it must be > 0 on "
                       "[inlet, outlet] = [%g, %g]",
                       s->lower, s->upper, what, x, s->inlet, s->outlet);
    /* the first closed time: samples of [0, t] with the motions' turning points (a motion
     * history may close and open the gap again), then bisection after the last open one */
    const int ns = 400;
    double tk[400 + 2 * 64 + 1];
    int nk = 0;
    for (int k = 1; k <= ns; k++) tk[nk++] = rc->t * k / ns;
    nk += lub_wall_motion_breaks(&rc->motion[rc->wl], 0.0, rc->t, tk + nk, 64);
    nk += lub_wall_motion_breaks(&rc->motion[rc->wu], 0.0, rc->t, tk + nk, 64);
    double ta = 0.0, tb = rc->t;
    for (int k = 0; k < nk; k++) /* the earliest closed sample */
        if (tk[k] < tb && !(min_gap_at(rc, tk[k], (int)s->cells) > 0.0)) tb = tk[k];
    for (int k = 0; k < nk; k++) /* the latest open sample before it */
        if (tk[k] < tb && tk[k] > ta) ta = tk[k];
    for (int it = 0; it < 200 && tb - ta > 1e-12 * rc->t; it++) {
        double tm = 0.5 * (ta + tb), gm = min_gap_at(rc, tm, (int)s->cells);
        if (gm > 0.0)
            ta = tm;
        else
            tb = tm;
    }
    char ml[200], mu[200], msg[1024];
    lub_wall_motion_describe(&rc->motion[rc->wl], rc->g.dim, ml, sizeof ml);
    lub_wall_motion_describe(&rc->motion[rc->wu], rc->g.dim, mu, sizeof mu);
    snprintf(msg, sizeof msg,
             "at t = %g s the gap between '%s' and '%s' is %s at x = %.9g m: the walls (lower: "
             "%s, upper: %s; constant/models.yaml movingWalls) close the gap "
             "(%.6g m at t = 0) at t = %.6g s; a reference needs t below that",
             rc->t, s->lower, s->upper, what, x, ml, mu, g0, tb);
    if (rc->t_node) lub_node_error(rc->t_node, "%s", msg);
    lub_fatal("%s", msg);
}

/* h(x) = (upper wall height) - (lower wall height) at nodes and faces. */
static void gap_heights(lub_refgap *G, const lub_refcase *rc)
{
    const lub_refcase_settings *s = &rc->s;
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
        double gap = wall_y(rc, rc->upper, x, 1) - wall_y(rc, rc->lower, x, 0);
        if (!(gap > 0.0)) {
            lub_refgap_free(G);
            gap_closed(rc, x, gap);
        }
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
 * normal speeds, and each surface, at its place at time rc->t, carried along x (-U dy/dx),
 * which vanishes for walls parallel to x (the squeeze term of T-32, 12 dh/dt of
 * methods.md §5.1; its 6 h d(U1+U2)/dx is 0 for rigid walls). */
static void gap_motion(lub_refgap *G, const lub_refcase *rc)
{
    const double *vl = rc->vel[rc->wl], *vu = rc->vel[rc->wu];
    G->moving_shape = 0;
    for (int i = 0; i <= G->n; i++) {
        double x = G->xa + i * G->dx, r = vu[1] - vl[1];
        if (vu[0] != 0.0) r -= vu[0] * wall_slope(rc, rc->upper, x, 1, G->dx);
        if (vl[0] != 0.0) r += vl[0] * wall_slope(rc, rc->lower, x, 0, G->dx);
        G->dhdt[i] = r;
        G->moving_shape |= r != 0.0;
    }
}

void lub_refgap_sample(lub_refgap *G, const lub_refcase *rc)
{
    memset(G, 0, sizeof *G);
    gap_heights(G, rc);
    gap_motion(G, rc);
}

void lub_refgap_free(lub_refgap *G)
{
    free(G->h);
    free(G->hf);
    free(G->dhdt);
    free(G->ha);
    free(G->hfx);
    free(G->hfz);
    free(G->dhdta);
    G->h = G->hf = G->dhdt = G->ha = G->hfx = G->hfz = G->dhdta = NULL;
}

/* Height of wall w over (x, z) of the area, fatal at the width entry when it has none. */
static double wall_y_at(const lub_refcase *rc, const lub_wall *w, double x, double z, int upper)
{
    const lub_refcase_settings *s = &rc->s;
    double y;
    char note[160];
    if (!lub_wall_height_at(w, x, z, upper, &y))
        lub_node_error(s->width_node,
                       "the %s wall '%s'%s does not span the area [inlet, outlet] x [-width/2, "
                       "width/2] = [%g, %g] x [%g, %g]: no surface over (x, z) = (%.9g, %.9g)",
                       upper ? "upper" : "lower", w->name, moved_note(rc, w, note, sizeof note),
                       s->inlet, s->outlet, -0.5 * s->width, 0.5 * s->width, x, z);
    return y;
}

/* The gap over (x, z), fatal at the width entry when it is <= 0. */
static double gap_at(const lub_refcase *rc, double x, double z)
{
    double gap = wall_y_at(rc, rc->upper, x, z, 1) - wall_y_at(rc, rc->lower, x, z, 0);
    if (!(gap > 0.0))
        lub_node_error(rc->s.width_node,
                       "the gap between '%s' and '%s' is %s at (x, z) = (%.9g, %.9g) at t = %g "
                       "s: it must be > 0 over the area",
                       rc->s.lower, rc->s.upper, gap == 0.0 ? "zero" : "negative", x, z, rc->t);
    return gap;
}

/* The slope of wall w's surface along x (dir 0) or z (dir 2) at (x, z), by central
 * differences inside the area. */
static double wall_slope_at(const lub_refcase *rc, const lub_wall *w, double x, double z, int dir,
                            int upper, double step)
{
    const lub_refcase_settings *s = &rc->s;
    double d = 1e-3 * step;
    if (dir == 0) {
        double xl = fmax(x - d, s->inlet), xr = fmin(x + d, s->outlet);
        return (wall_y_at(rc, w, xr, z, upper) - wall_y_at(rc, w, xl, z, upper)) / (xr - xl);
    }
    double zl = fmax(z - d, -0.5 * s->width), zr = fmin(z + d, 0.5 * s->width);
    return (wall_y_at(rc, w, x, zr, upper) - wall_y_at(rc, w, x, zl, upper)) / (zr - zl);
}

void lub_refgap_sample_area(lub_refgap *G, const lub_refcase *rc)
{
    const int n = G->n, nz = G->nz = (int)rc->s.nz;
    const double w = G->width = rc->s.width, dz = w / nz;
    size_t nn = (size_t)(n + 1) * (nz + 1);
    G->ha = lub_malloc(nn * sizeof *G->ha);
    G->dhdta = lub_malloc(nn * sizeof *G->dhdta);
    G->hfx = lub_malloc((size_t)n * (nz + 1) * sizeof *G->hfx);
    G->hfz = lub_malloc((size_t)(n + 1) * nz * sizeof *G->hfz);
    G->h0_area = INFINITY;
    G->varies_across = 0;
    const double *vl = rc->vel[rc->wl], *vu = rc->vel[rc->wu];
    /* z_j as reynolds2d.h's lub_reynolds2d_z, so that z = 0 is exactly the mid-plane */
#define ZJ(j) (-0.5 * w + w * (double)(j) / (double)nz)
    for (int i = 0; i <= n; i++) {
        double x = i == n ? G->xb : G->xa + i * G->dx, xf = G->xa + (i + 0.5) * G->dx;
        for (int j = 0; j <= nz; j++) {
            double z = ZJ(j);
            size_t q = (size_t)i * (nz + 1) + j;
            double h = G->ha[q] = gap_at(rc, x, z);
            if (i < n) G->hfx[q] = gap_at(rc, xf, z);
            if (j < nz) G->hfz[(size_t)i * nz + j] = gap_at(rc, x, ZJ(j) + 0.5 * dz);
            if (h < G->h0_area) G->h0_area = h, G->x_h0_area = x, G->z_h0_area = z;
            double r = vu[1] - vl[1];
            if (vu[0] != 0.0) r -= vu[0] * wall_slope_at(rc, rc->upper, x, z, 0, 1, G->dx);
            if (vl[0] != 0.0) r += vl[0] * wall_slope_at(rc, rc->lower, x, z, 0, 0, G->dx);
            if (vu[2] != 0.0) r -= vu[2] * wall_slope_at(rc, rc->upper, x, z, 2, 1, dz);
            if (vl[2] != 0.0) r += vl[2] * wall_slope_at(rc, rc->lower, x, z, 2, 0, dz);
            G->dhdta[q] = r;
            G->moving_shape |= r != 0.0;
            if (j > 0 && (h != G->ha[q - 1] || r != G->dhdta[q - 1])) G->varies_across = 1;
        }
    }
#undef ZJ
}

lub_reynolds_status lub_refcase_solve(const lub_refcase *rc, const lub_refgap *G, double *p,
                                      lub_reynolds_result *res)
{
    const lub_refcase_settings *s = &rc->s;
    lub_reynolds_problem pb;
    lub_reynolds_problem_init(&pb);
    pb.n = G->n;
    pb.xa = G->xa;
    pb.xb = G->xb;
    pb.h = G->h;
    pb.h_face = G->hf;
    pb.u1 = rc->u1;
    pb.u2 = rc->u2;
    pb.dhdt_nodes = G->dhdt;
    pb.mu = rc->mu;
    pb.bc = (lub_reynolds_bc)s->bc;
    pb.exit_x = s->exit_x;
    pb.tolerance = s->tolerance;
    pb.max_iterations = (int)s->max_iterations;
    memset(res, 0, sizeof *res);
    res->p = p;
    return lub_reynolds_solve(&pb, res);
}

void lub_refcase_check_scales(const lub_refcase *rc)
{
    if (rc->upper->type != LUB_WALL_CYLINDER)
        lub_node_error(rc->s.upper_node,
                       "-dimensionless needs a cylinder as the upper wall (R is its "
                       "radius), but '%s' is not a cylinder",
                       rc->s.upper);
    if (rc->u1 + rc->u2 == 0.0)
        lub_node_error(rc->s.lower_node,
                       "-dimensionless scales p with U1 + U2, which is 0 here (set the "
                       "wall speeds in constant/models.yaml movingWalls)");
}

void lub_refcase_scales(const lub_refcase *rc, const lub_refgap *G, lub_refscales *d)
{
    lub_refcase_check_scales(rc);
    d->radius = rc->upper->radius;
    d->uref = rc->u1 + rc->u2;
    if (rc->ehl) { /* T-54..T-58 */
        d->h0 = rc->ew.b * rc->ew.b / rc->ew.radius;
        d->sx = rc->ew.b;
        d->sp = 1.0 / rc->ew.p_hertz;
        return;
    }
    d->h0 = G->h0;
    d->sx = sqrt(d->radius * G->h0);
    d->sp = pow(G->h0, 1.5) / (rc->mu * d->uref * sqrt(d->radius));
}

void lub_refscales_read(lub_refscales *d, const lub_case *c)
{
    lub_refcase rc;
    lub_refgap G;
    lub_refcase_read(&rc, c);
    lub_refcase_check_scales(&rc);
    lub_refgap_sample(&G, &rc);
    lub_refcase_scales(&rc, &G, d);
    lub_refgap_free(&G);
    lub_refcase_free(&rc);
}
