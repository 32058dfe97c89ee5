/* lubkit geometry: reader of system/particleGenDict.yaml and the analytic wall functions
 * (see geometry.h for the dictionary layout). */
#include "geometry/geometry.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

static const char *const wall_types[] = {"plane", "segment", "cylinder", "polyline",
                                         "box",   "sphere",  "polygon",  NULL};
static const char *const region_types[] = {"layer", "box", "between", NULL};
static const char *const axis_names[] = {"x", "y", "z", NULL};

/* ---- small vector helpers ------------------------------------------------------------- */

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double norm3(const double *a)
{
    return sqrt(dot3(a, a));
}

/* Read a point of `dim` components into out[3] (z = 0 in 2-D). */
static void read_point(lub_node *map, const char *key, int dim, double *out)
{
    out[0] = out[1] = out[2] = 0.0;
    lub_dict_vec(map, key, out, dim, dim, LUB_ANY);
}

/* Unit vector from the dictionary; a zero vector is an error at its node. */
static void read_unit(lub_node *map, const char *key, int dim, double *out)
{
    read_point(map, key, dim, out);
    double n = norm3(out);
    if (!(n > 0.0) || !isfinite(n))
        lub_node_error(lub_dict_get(map, key), "'%s' must be a non-zero vector",
                       lub_node_path(lub_dict_get(map, key)));
    for (int d = 0; d < 3; d++) out[d] /= n;
}

/* ---- walls ---------------------------------------------------------------------------- */

static void read_range(lub_wall *w, lub_node *m)
{
    lub_node *r = lub_dict_find(m, "range");
    if (!r) return;
    lub_dict_vec(m, "range", w->range, 2, 2, LUB_ANY);
    if (!(w->range[0] < w->range[1]))
        lub_node_error(r, "'%s' must be an x-interval [a, b] with a < b, found [%g, %g]",
                       lub_node_path(r), w->range[0], w->range[1]);
    w->has_range = 1;
}

static void read_cylinder(lub_wall *w, lub_node *m, int dim)
{
    w->radius = lub_dict_real(m, "radius", LUB_POSITIVE);
    w->fluid_inside =
        lub_dict_choice(m, "fluid", (const char *const[]){"outside", "inside", NULL}, 0);
    if (dim == 3) {
        w->axis[2] = 1.0;
        if (lub_dict_has(m, "axis")) read_unit(m, "axis", 3, w->axis);
    }
    int hc = lub_dict_has(m, "centre"), hl = lub_dict_has(m, "lowestPoint");
    if (hc == hl)
        lub_node_error(m, "cylinder '%s' needs exactly one of 'centre' and 'lowestPoint'%s",
                       w->name, hc ? ", found both" : "");
    if (hc) {
        read_point(m, "centre", dim, w->centre);
    } else {
        double low[3];
        read_point(m, "lowestPoint", dim, low);
        /* the centre lies R above the lowest point, along +y made perpendicular to the axis */
        double up[3] = {0, 1, 0};
        if (dim == 3) {
            double a = dot3(up, w->axis);
            for (int d = 0; d < 3; d++) up[d] -= a * w->axis[d];
            double n = norm3(up);
            if (n < 1e-12)
                lub_node_error(lub_dict_get(m, "lowestPoint"),
                               "cylinder '%s': 'lowestPoint' needs an axis that is not "
                               "vertical (use 'centre')",
                               w->name);
            for (int d = 0; d < 3; d++) up[d] /= n;
        }
        for (int d = 0; d < 3; d++) w->centre[d] = low[d] + w->radius * up[d];
    }
    read_range(w, m);
    lub_node *ln = lub_dict_find(m, "length");
    if (ln) {
        if (dim != 3)
            lub_node_error(ln,
                           "cylinder '%s': 'length' makes a 3-D roller of finite length; a 2-D "
                           "cylinder is a circle",
                           w->name);
        if (w->fluid_inside)
            lub_node_error(ln, "cylinder '%s': 'length' (a roller) needs the fluid outside it",
                           w->name);
        w->length = lub_dict_real(m, "length", LUB_POSITIVE);
        w->has_length = 1;
    }
}

/* fluidLayers of a round wall: a 2-D cylinder must be a whole circle (its rings close) */
static void read_fluid_layers(lub_wall *w, lub_node *m, int dim)
{
    w->fluid_layers = (int)lub_dict_int_or(m, "fluidLayers", 0, 0, 100);
    lub_node *n = lub_dict_find(m, "fluidLayers");
    if (n && w->fluid_layers > 0 && w->type == LUB_WALL_CYLINDER && dim == 2 && w->has_range)
        lub_node_error(n, "wall '%s': fluidLayers needs a whole circle (no range)", w->name);
    if (n && w->fluid_layers > 0 && w->type == LUB_WALL_CYLINDER && w->has_length)
        lub_node_error(n,
                       "wall '%s': fluidLayers is for an infinitely long cylinder, not a roller "
                       "of finite length (length)",
                       w->name);
}

static void read_polyline(lub_wall *w, lub_node *m)
{
    lub_node *pts = lub_dict_seq(m, "points");
    size_t n = lub_node_size(pts);
    if (n < 2) lub_node_error(pts, "polyline '%s' needs at least 2 points, found %zu", w->name, n);
    w->pts = lub_malloc(2 * n * sizeof *w->pts);
    w->npts = (int)n;
    for (size_t i = 0; i < n; i++) {
        lub_node *p = lub_node_item(pts, i);
        if (lub_node_type_of(p) != LUB_NODE_SEQUENCE || lub_node_size(p) != 2)
            lub_node_error(p, "polyline '%s': point %zu must be [x, y]", w->name, i);
        w->pts[2 * i] = lub_node_real(lub_node_item(p, 0), LUB_ANY);
        w->pts[2 * i + 1] = lub_node_real(lub_node_item(p, 1), LUB_ANY);
        if (i > 0 && !(w->pts[2 * i] > w->pts[2 * i - 2]))
            lub_node_error(p,
                           "polyline '%s': x must increase from point to point, found x = %g "
                           "after x = %g",
                           w->name, w->pts[2 * i], w->pts[2 * i - 2]);
    }
}

/* Whether the closed segments p-q and r-s have a point in common. */
static int segments_meet(const double *p, const double *q, const double *r, const double *s)
{
    double d1 = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
    double d2 = (q[0] - p[0]) * (s[1] - p[1]) - (q[1] - p[1]) * (s[0] - p[0]);
    double d3 = (s[0] - r[0]) * (p[1] - r[1]) - (s[1] - r[1]) * (p[0] - r[0]);
    double d4 = (s[0] - r[0]) * (q[1] - r[1]) - (s[1] - r[1]) * (q[0] - r[0]);
    if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
        return 1;
    /* collinear or touching: an end of one segment on the other */
    const double *a[4] = {r, s, p, q}, *b0[4] = {p, p, r, r}, *b1[4] = {q, q, s, s};
    const double d[4] = {d1, d2, d3, d4};
    for (int k = 0; k < 4; k++)
        if (d[k] == 0.0 && a[k][0] >= fmin(b0[k][0], b1[k][0]) &&
            a[k][0] <= fmax(b0[k][0], b1[k][0]) && a[k][1] >= fmin(b0[k][1], b1[k][1]) &&
            a[k][1] <= fmax(b0[k][1], b1[k][1]))
            return 1;
    return 0;
}

/* A closed polygon: vertices in any order around it and either orientation, stored
 * counter-clockwise (the solid on the left of every edge); the first vertex repeated at the
 * end is dropped.  Refused: fewer than 3 vertices, a zero-length edge, zero area, adjacent
 * edges folding back onto each other, edges that cross or touch (the boundary must be a
 * simple closed curve). */
static void read_polygon(lub_wall *w, lub_node *m)
{
    lub_node *pts = lub_dict_seq(m, "points");
    size_t n = lub_node_size(pts);
    w->pts = lub_malloc(2 * (n ? n : 1) * sizeof *w->pts);
    for (size_t i = 0; i < n; i++) {
        lub_node *p = lub_node_item(pts, i);
        if (lub_node_type_of(p) != LUB_NODE_SEQUENCE || lub_node_size(p) != 2)
            lub_node_error(p, "polygon '%s': point %zu must be [x, y]", w->name, i);
        w->pts[2 * i] = lub_node_real(lub_node_item(p, 0), LUB_ANY);
        w->pts[2 * i + 1] = lub_node_real(lub_node_item(p, 1), LUB_ANY);
    }
    if (n > 1 && w->pts[0] == w->pts[2 * n - 2] && w->pts[1] == w->pts[2 * n - 1]) n--;
    if (n < 3)
        lub_node_error(pts, "polygon '%s' needs at least 3 different points, found %zu", w->name,
                       n);
    w->npts = (int)n;
    double *v = w->pts, area2 = 0.0, ext = 0.0;
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + 1) % n;
        area2 += v[2 * i] * v[2 * j + 1] - v[2 * j] * v[2 * i + 1];
        ext = fmax(ext, fmax(fabs(v[2 * i]), fabs(v[2 * i + 1])));
        if (v[2 * i] == v[2 * j] && v[2 * i + 1] == v[2 * j + 1])
            lub_node_error(lub_node_item(pts, j), "polygon '%s': point %zu repeats point %zu",
                           w->name, j, i);
    }
    for (size_t i = 0; i < n; i++) {
        size_t h = (i + n - 1) % n, j = (i + 1) % n;
        double ax = v[2 * i] - v[2 * h], ay = v[2 * i + 1] - v[2 * h + 1];
        double bx = v[2 * j] - v[2 * i], by = v[2 * j + 1] - v[2 * i + 1];
        double cr = ax * by - ay * bx, dt = ax * bx + ay * by;
        if (fabs(cr) <= 1e-12 * hypot(ax, ay) * hypot(bx, by) && dt < 0)
            lub_node_error(lub_node_item(pts, i),
                           "polygon '%s': the edges at point %zu fold back onto each other",
                           w->name, i);
    }
    for (size_t i = 0; i < n; i++) /* edges that are not neighbours must not meet */
        for (size_t k = i + 1; k < n; k++) {
            size_t j = (i + 1) % n, l = (k + 1) % n;
            if (k == j || l == i) continue; /* neighbours share a vertex */
            if (segments_meet(v + 2 * i, v + 2 * j, v + 2 * k, v + 2 * l))
                lub_node_error(pts,
                               "polygon '%s': its edges %zu-%zu and %zu-%zu cross or touch; the "
                               "points must go once around the body",
                               w->name, i, j, k, l);
        }
    if (!(fabs(area2) > 1e-24 * ext * ext))
        lub_node_error(pts, "polygon '%s' encloses no area", w->name);
    if (area2 < 0) /* clockwise: reverse */
        for (size_t i = 0; i < n / 2; i++)
            for (int d = 0; d < 2; d++) {
                double t = v[2 * i + d];
                v[2 * i + d] = v[2 * (n - 1 - i) + d];
                v[2 * (n - 1 - i) + d] = t;
            }
    for (int d = 0; d < 2; d++) {
        w->min[d] = INFINITY, w->max[d] = -INFINITY;
        for (size_t i = 0; i < n; i++) {
            w->min[d] = fmin(w->min[d], v[2 * i + d]);
            w->max[d] = fmax(w->max[d], v[2 * i + d]);
        }
    }
}

static void read_wall(lub_geometry *g, lub_wall *w, const char *name, lub_node *m)
{
    int dim = g->dim;
    if (strlen(name) >= LUB_NAME_MAX)
        lub_node_error(m, "wall name '%.40s...' is longer than %d characters", name,
                       LUB_NAME_MAX - 1);
    snprintf(w->name, sizeof w->name, "%s", name);
    w->node = m;
    w->type = (lub_wall_type)lub_dict_choice(m, "type", wall_types, -1);
    lub_node *tn = lub_dict_get(m, "type");
    switch (w->type) {
    case LUB_WALL_PLANE:
        read_point(m, "point", dim, w->point);
        read_unit(m, "normal", dim, w->normal);
        read_range(w, m);
        if (w->has_range && fabs(w->normal[1]) < 1e-12 && fabs(w->normal[2]) < 1e-12)
            lub_node_error(lub_dict_get(m, "range"),
                           "plane '%s': 'range' limits a plane in x, which needs a normal "
                           "that is not along x",
                           name);
        break;
    case LUB_WALL_SEGMENT:
        if (dim != 2) lub_node_error(tn, "wall '%s': type 'segment' is 2-D only", name);
        read_point(m, "from", dim, w->from);
        read_point(m, "to", dim, w->to);
        if (w->from[0] == w->to[0])
            lub_node_error(m,
                           "segment '%s' must not be vertical (from.x = to.x = %g); use a "
                           "plane or a box",
                           name, w->from[0]);
        w->fluid_above =
            !lub_dict_choice(m, "fluid", (const char *const[]){"above", "below", NULL}, 0);
        break;
    case LUB_WALL_CYLINDER:
        read_cylinder(w, m, dim);
        read_fluid_layers(w, m, dim);
        break;
    case LUB_WALL_POLYLINE:
        if (dim != 2) lub_node_error(tn, "wall '%s': type 'polyline' is 2-D only", name);
        read_polyline(w, m);
        w->fluid_above =
            !lub_dict_choice(m, "fluid", (const char *const[]){"above", "below", NULL}, 0);
        break;
    case LUB_WALL_BOX:
        read_point(m, "min", dim, w->min);
        read_point(m, "max", dim, w->max);
        for (int d = 0; d < dim; d++)
            if (!(w->min[d] < w->max[d]))
                lub_node_error(m,
                               "box '%s': min must be below max in every direction, found "
                               "%s: %g >= %g",
                               name, axis_names[d], w->min[d], w->max[d]);
        w->fluid_inside =
            !lub_dict_choice(m, "fluid", (const char *const[]){"inside", "outside", NULL}, 0);
        break;
    case LUB_WALL_SPHERE:
        if (dim != 3)
            lub_node_error(tn,
                           "wall '%s': type 'sphere' is 3-D only (a circle in 2-D is a "
                           "'cylinder')",
                           name);
        read_point(m, "centre", dim, w->centre);
        w->radius = lub_dict_real(m, "radius", LUB_POSITIVE);
        w->fluid_inside =
            lub_dict_choice(m, "fluid", (const char *const[]){"outside", "inside", NULL}, 0);
        read_fluid_layers(w, m, dim);
        break;
    case LUB_WALL_POLYGON:
        if (dim != 2) lub_node_error(tn, "wall '%s': type 'polygon' is 2-D only", name);
        read_polygon(w, m);
        break;
    }
}

/* A wall referred to by name from key `key` of map m; fatal with a suggestion if unknown. */
static int wall_ref(const lub_geometry *g, lub_node *m, const char *key)
{
    lub_node *v = lub_dict_get(m, key);
    const char *name = lub_node_text(v);
    int i = lub_geometry_find_wall(g, name);
    if (i >= 0) return i;
    const char **names = lub_malloc((size_t)(g->nwalls + 1) * sizeof *names);
    for (int k = 0; k < g->nwalls; k++) names[k] = g->walls[k].name;
    const char *near = lub_closest(name, names, (size_t)g->nwalls);
    char msg[256];
    if (near)
        snprintf(msg, sizeof msg, " (did you mean '%s'?)", near);
    else if (g->nwalls == 0)
        snprintf(msg, sizeof msg, " (no walls are defined)");
    else
        snprintf(msg, sizeof msg, " (walls: %s%s)", names[0], g->nwalls > 1 ? ", ..." : "");
    free(names);
    lub_node_error(v, "'%s': unknown wall '%s'%s", lub_node_path(v), name, msg);
}

static void read_region(lub_geometry *g, lub_region *r, lub_node *m)
{
    int dim = g->dim;
    r->node = m;
    r->type = (lub_region_type)lub_dict_choice(m, "type", region_types, -1);
    r->wall = r->lower = r->upper = -1;
    switch (r->type) {
    case LUB_REGION_LAYER:
        r->wall = wall_ref(g, m, "wall");
        r->thickness = lub_dict_real(m, "thickness", LUB_POSITIVE);
        break;
    case LUB_REGION_BOX: {
        read_point(m, "min", dim, r->min);
        read_point(m, "max", dim, r->max);
        for (int d = 0; d < dim; d++) {
            if (!(r->min[d] < r->max[d]))
                lub_node_error(m,
                               "fluid box: min must be below max in every direction, found "
                               "%s: %g >= %g",
                               axis_names[d], r->min[d], r->max[d]);
            double tol = 1e-9 * (g->dmax[d] - g->dmin[d]);
            if (r->min[d] < g->dmin[d] - tol || r->max[d] > g->dmax[d] + tol)
                lub_node_error(m, "fluid box %s-interval [%g, %g] lies outside the domain [%g, %g]",
                               axis_names[d], r->min[d], r->max[d], g->dmin[d], g->dmax[d]);
        }
        break;
    }
    case LUB_REGION_BETWEEN:
        r->lower = wall_ref(g, m, "lower");
        r->upper = wall_ref(g, m, "upper");
        r->height = lub_dict_real(m, "height", LUB_POSITIVE);
        if (r->lower == r->upper)
            lub_node_error(m, "fluid 'between' needs two different walls, found '%s' twice",
                           g->walls[r->lower].name);
        if (dim == 3 && g->walls[r->lower].type == LUB_WALL_PLANE &&
            fabs(g->walls[r->lower].normal[1]) < 1e-12)
            lub_node_error(m, "fluid 'between': the lower wall '%s' must not be vertical",
                           g->walls[r->lower].name);
        break;
    }
}

/* ---- levels --------------------------------------------------------------------------- */

static void read_levels(lub_geometry *g, lub_node *root)
{
    lub_node *l0n = lub_dict_find(root, "l0");
    lub_node *lv = lub_dict_seq_or(root, "levels");
    if (l0n && lv) lub_node_error(lv, "give either 'l0' (single resolution) or 'levels', not both");
    if (!l0n && !lv)
        lub_node_error(root, "missing required key 'l0' (or 'levels' for multi-resolution)");
    if (l0n) {
        g->nlevels = 1;
        g->levels[0].l0 = lub_node_real(l0n, LUB_POSITIVE);
        g->levels[0].xmin = g->dmin[0];
        g->levels[0].xmax = g->dmax[0];
        g->levels[0].node = l0n;
        return;
    }
    size_t n = lub_node_size(lv);
    if (n < 1 || n > LUB_MAX_LEVELS)
        lub_node_error(lv, "'levels' must list 1 to %d levels, found %zu", LUB_MAX_LEVELS, n);
    g->nlevels = (int)n;
    for (size_t k = 0; k < n; k++) {
        lub_node *m = lub_node_expect_map(lub_node_item(lv, k));
        lub_level_spec *s = &g->levels[k];
        s->node = m;
        s->l0 = lub_dict_real(m, "l0", LUB_POSITIVE);
        if (k > 0 && !(s->l0 > g->levels[k - 1].l0))
            lub_node_error(m,
                           "levels go from fine to coarse: level %zu has l0 = %g, not "
                           "larger than level %zu's l0 = %g",
                           k, s->l0, k - 1, g->levels[k - 1].l0);
        double r[2];
        if (lub_dict_vec_or(m, "region", r, 2, 2, LUB_ANY)) {
            if (!(r[0] < r[1]))
                lub_node_error(lub_dict_get(m, "region"),
                               "level %zu: 'region' must be an x-interval [a1, a2] with a1 < "
                               "a2, found [%g, %g]",
                               k, r[0], r[1]);
            s->xmin = r[0];
            s->xmax = r[1];
            s->has_region = 1;
        } else if (k + 1 < n) {
            lub_node_error(m,
                           "level %zu needs 'region: [a1, a2]' (only the last level owns "
                           "the rest of the domain)",
                           k);
        } else {
            s->xmin = g->dmin[0];
            s->xmax = g->dmax[0];
        }
    }
    /* Coverage: when the last level has a region too, the intervals must cover the domain. */
    if (g->levels[n - 1].has_region) {
        double x = g->dmin[0], tol = 1e-9 * (g->dmax[0] - g->dmin[0]);
        for (int pass = 0; pass < g->nlevels && x < g->dmax[0] - tol; pass++)
            for (int k = 0; k < g->nlevels; k++)
                if (g->levels[k].xmin <= x + tol && g->levels[k].xmax > x) x = g->levels[k].xmax;
        if (x < g->dmax[0] - tol)
            lub_node_error(lv,
                           "the level regions do not cover the domain: x from %g is owned by "
                           "no level (domain x: [%g, %g]); drop 'region' from the last level "
                           "to let it own the rest",
                           x, g->dmin[0], g->dmax[0]);
    }
}

/* A disordered start: `jitter: { amplitude, seed }`.  Below l0/2, so that a particle stays
 * nearer its own lattice point than any other; one level only, so that no particle is
 * moved into the x-range of another level. */
static void read_jitter(lub_geometry *g, lub_node *root)
{
    lub_node *j = lub_dict_map_or(root, "jitter");
    if (!j) return;
    g->jitter_node = j;
    g->jitter = lub_dict_real(j, "amplitude", (lub_range){0.0, 0.5, 0, 1});
    g->jitter_seed = (unsigned long)lub_dict_int_or(j, "seed", 1, 0, 2147483647L);
    if (g->nlevels > 1 && g->jitter > 0)
        lub_node_error(j,
                       "jitter needs a single resolution (l0), found %d levels: a jittered "
                       "particle could leave the x-range of its level",
                       g->nlevels);
}

/* The lattice of every level must tile each periodic direction exactly. */
static void check_periodic(const lub_geometry *g, lub_node *pn)
{
    for (int d = 0; d < g->dim; d++) {
        if (!g->periodic[d]) continue;
        double period = g->dmax[d] - g->dmin[d];
        for (int k = 0; k < g->nlevels; k++) {
            double l0 = g->levels[k].l0, q = period / l0;
            if (fabs(q - round(q)) > 1e-9 * q || round(q) < 1)
                lub_node_error(pn,
                               "periodic length in %s (%g) is not a multiple of l0 = %g%s "
                               "(period / l0 = %.10g); make the domain %g or %g long",
                               axis_names[d], period, l0, g->nlevels > 1 ? " of a level" : "", q,
                               floor(q) * l0 > 0 ? floor(q) * l0 : ceil(q) * l0, ceil(q) * l0);
        }
    }
}

void lub_geometry_read(lub_geometry *g, const char *path)
{
    memset(g, 0, sizeof *g);
    lub_dict *dict = lub_dict_read(path);
    g->dict = dict;
    lub_node *root = lub_dict_root(dict);

    g->dim = (int)lub_dict_int(root, "dimension", 2, 3);
    lub_node *dom = lub_dict_map(root, "domain");
    read_point(dom, "min", g->dim, g->dmin);
    read_point(dom, "max", g->dim, g->dmax);
    for (int d = 0; d < g->dim; d++)
        if (!(g->dmin[d] < g->dmax[d]))
            lub_node_error(dom,
                           "domain: min must be below max in every direction, found %s: "
                           "%g >= %g",
                           axis_names[d], g->dmin[d], g->dmax[d]);
    read_levels(g, root);

    lub_node *pn = lub_dict_seq_or(root, "periodic");
    if (pn) {
        for (size_t i = 0; i < lub_node_size(pn); i++) {
            lub_node *it = lub_node_item(pn, i);
            const char *s = lub_node_text(it);
            int d = -1;
            for (int k = 0; k < g->dim; k++)
                if (strcmp(s, axis_names[k]) == 0) d = k;
            if (d < 0)
                lub_node_error(it, "'periodic' lists directions among %s, found '%s'",
                               g->dim == 2 ? "x, y" : "x, y, z", s);
            g->periodic[d] = 1;
        }
        check_periodic(g, pn);
    }
    g->dummy_layers = (int)lub_dict_int_or(root, "dummyLayers", 2, 0, 10);
    g->wall_gap = lub_dict_real_or(root, "wallGap", 1.0, LUB_BETWEEN(0.0, 10.0));
    read_jitter(g, root);

    lub_node *wn = lub_dict_map_or(root, "walls");
    size_t nw = wn ? lub_node_size(wn) : 0;
    if (nw > LUB_MAX_PATCHES)
        lub_node_error(wn, "at most %d walls, found %zu", LUB_MAX_PATCHES, nw);
    g->walls = lub_calloc(nw ? nw : 1, sizeof *g->walls);
    for (size_t i = 0; i < nw; i++) {
        const char *name = lub_node_key_at(wn, i);
        lub_node *m = lub_node_expect_map(lub_node_value_at(wn, i));
        g->nwalls = (int)i + 1;
        read_wall(g, &g->walls[i], name, m);
    }

    lub_node *fn = lub_dict_seq_or(root, "fluid");
    size_t nr = fn ? lub_node_size(fn) : 0;
    g->regions = lub_calloc(nr ? nr : 1, sizeof *g->regions);
    for (size_t i = 0; i < nr; i++) {
        g->nregions = (int)i + 1;
        read_region(g, &g->regions[i], lub_node_expect_map(lub_node_item(fn, i)));
    }
    lub_dict_finish(dict);
}

void lub_geometry_free(lub_geometry *g)
{
    if (!g) return;
    for (int i = 0; i < g->nwalls; i++) free(g->walls[i].pts);
    free(g->walls);
    free(g->regions);
    if (g->dict) lub_dict_free((lub_dict *)g->dict);
    memset(g, 0, sizeof *g);
}

int lub_geometry_find_wall(const lub_geometry *g, const char *name)
{
    for (int i = 0; i < g->nwalls; i++)
        if (strcmp(g->walls[i].name, name) == 0) return i;
    return -1;
}

void lub_wall_translate(lub_wall *w, const lub_wall *w0, const double *d)
{
    double *pts = w->pts;
    if (w0->npts > 0 && !pts) lub_bug("lub_wall_translate: no vertex array for '%s'", w0->name);
    *w = *w0;
    w->pts = w0->npts > 0 ? pts : NULL;
    for (int k = 0; k < 3; k++) {
        w->point[k] += d[k];
        w->from[k] += d[k];
        w->to[k] += d[k];
        w->centre[k] += d[k];
        w->min[k] += d[k];
        w->max[k] += d[k];
    }
    for (int i = 0; i < w0->npts; i++) {
        w->pts[2 * i] = w0->pts[2 * i] + d[0];
        w->pts[2 * i + 1] = w0->pts[2 * i + 1] + d[1];
    }
    w->range[0] += d[0];
    w->range[1] += d[0];
}

/* ---- wall functions ------------------------------------------------------------------- */

/* Heights y where the line (x, y, z) crosses the round surface of a circle (2-D: z = 0), a
 * 3-D cylinder or a sphere: the roots of |perp(d)|^2 = R^2, d = (x, y, z) - centre.  Returns
 * 0 when the line misses the surface (or runs along a vertical axis). */
static int round_roots(const lub_wall *w, double x, double z, double *ylo, double *yhi)
{
    double d0[3] = {x - w->centre[0], -w->centre[1], z - w->centre[2]};
    double ey[3] = {0, 1, 0};
    int axis = w->axis[0] != 0 || w->axis[1] != 0 || w->axis[2] != 0;
    if (w->type == LUB_WALL_CYLINDER && !axis) d0[2] = 0.0; /* a 2-D circle: extruded in z */
    if (w->type == LUB_WALL_CYLINDER && axis) {
        /* 3-D cylinder: remove the axial components */
        double a0 = dot3(d0, w->axis), ay = w->axis[1];
        for (int d = 0; d < 3; d++) {
            d0[d] -= a0 * w->axis[d];
            ey[d] -= ay * w->axis[d];
        }
    }
    double A = dot3(ey, ey), B = 2.0 * dot3(d0, ey), C = dot3(d0, d0) - w->radius * w->radius;
    if (A < 1e-24) return 0;
    double disc = B * B - 4.0 * A * C;
    if (disc < 0.0) return 0;
    double s = sqrt(disc);
    *ylo = (-B - s) / (2.0 * A);
    *yhi = (-B + s) / (2.0 * A);
    if (w->type == LUB_WALL_CYLINDER && w->has_length) {
        /* a roller of finite length: the line must meet its round surface between the ends */
        const double c[3] = {x - w->centre[0], -w->centre[1], z - w->centre[2]};
        for (int k = 0; k < 2; k++) {
            double y = k ? *yhi : *ylo, q[3] = {c[0], c[1] + y, c[2]};
            if (fabs(dot3(q, w->axis)) > 0.5 * w->length * (1 + 1e-12)) return 0;
        }
    }
    return 1;
}

/* Height of a polyline at x (x inside its span). */
static double polyline_at(const lub_wall *w, double x)
{
    int n = w->npts, i = 0;
    while (i < n - 2 && x > w->pts[2 * (i + 1)]) i++;
    double x0 = w->pts[2 * i], y0 = w->pts[2 * i + 1];
    double x1 = w->pts[2 * i + 2], y1 = w->pts[2 * i + 3];
    return y0 + (y1 - y0) * (x - x0) / (x1 - x0);
}

int lub_wall_height(const lub_wall *w, double x, int upper, double *y)
{
    return lub_wall_height_at(w, x, 0.0, upper, y);
}

int lub_wall_height_at(const lub_wall *w, double x, double z, int upper, double *y)
{
    if (w->has_range && (x < w->range[0] || x > w->range[1])) return 0;
    switch (w->type) {
    case LUB_WALL_PLANE: {
        if (fabs(w->normal[1]) < 1e-12) return 0; /* vertical: no height */
        /* n . ((x, y, z) - p) = 0 */
        *y = w->point[1] -
             (w->normal[0] * (x - w->point[0]) + w->normal[2] * (z - w->point[2])) / w->normal[1];
        return 1;
    }
    case LUB_WALL_SEGMENT: {
        double a = fmin(w->from[0], w->to[0]), b = fmax(w->from[0], w->to[0]);
        if (x < a || x > b) return 0;
        *y = w->from[1] + (w->to[1] - w->from[1]) * (x - w->from[0]) / (w->to[0] - w->from[0]);
        return 1;
    }
    case LUB_WALL_POLYLINE:
        if (x < w->pts[0] || x > w->pts[2 * (w->npts - 1)]) return 0;
        *y = polyline_at(w, x);
        return 1;
    case LUB_WALL_CYLINDER:
    case LUB_WALL_SPHERE: {
        double lo, hi;
        if (!round_roots(w, x, z, &lo, &hi)) return 0;
        /* the surface point facing the gap: fluid outside -> the upper wall's lowest point,
         * the lower wall's highest; fluid inside (a bearing shell) the other way round */
        *y = (upper != 0) == !w->fluid_inside ? lo : hi;
        return 1;
    }
    case LUB_WALL_BOX:
        if (x < w->min[0] || x > w->max[0]) return 0;
        if (w->max[2] != w->min[2] && (z < w->min[2] || z > w->max[2])) return 0;
        *y = (upper != 0) == !w->fluid_inside ? w->min[1] : w->max[1];
        return 1;
    case LUB_WALL_POLYGON: {
        /* where the vertical line at x meets the boundary (both ends of a vertical edge on
         * it): the lowest point for the upper wall of a gap, the highest for the lower */
        int found = 0;
        double lo = INFINITY, hi = -INFINITY;
        for (int i = 0; i < w->npts; i++) {
            const double *a = w->pts + 2 * i, *b = w->pts + 2 * ((i + 1) % w->npts);
            if (x < fmin(a[0], b[0]) || x > fmax(a[0], b[0])) continue;
            double ya = a[1], yb = b[1];
            if (a[0] != b[0]) ya = yb = a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0]);
            lo = fmin(lo, fmin(ya, yb));
            hi = fmax(hi, fmax(ya, yb));
            found = 1;
        }
        if (!found) return 0;
        *y = upper ? lo : hi;
        return 1;
    }
    }
    return 0;
}

/* Distance from (px, py) to the segment a-b. */
static double seg_dist(double px, double py, double ax, double ay, double bx, double by)
{
    double ux = bx - ax, uy = by - ay, L2 = ux * ux + uy * uy;
    double t = L2 > 0 ? ((px - ax) * ux + (py - ay) * uy) / L2 : 0.0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double dx = px - (ax + t * ux), dy = py - (ay + t * uy);
    return sqrt(dx * dx + dy * dy);
}

/* Signed distance to a 2-D polyline given as n points (x, y), fluid above or below. */
static double curve_distance(const double *pts, int n, int above, const double *x)
{
    double best = INFINITY, side = 0.0;
    for (int i = 0; i + 1 < n; i++) {
        const double *a = pts + 2 * i, *b = pts + 2 * i + 2;
        double dist = seg_dist(x[0], x[1], a[0], a[1], b[0], b[1]);
        if (dist < best) {
            best = dist;
            /* side of the segment's line: cross product, positive above (x increases) */
            side = (b[0] - a[0]) * (x[1] - a[1]) - (b[1] - a[1]) * (x[0] - a[0]);
        }
    }
    if (x[0] >= pts[0] && x[0] <= pts[2 * (n - 1)]) {
        /* inside the x-span the height decides the side exactly */
        int i = 0;
        while (i < n - 2 && x[0] > pts[2 * (i + 1)]) i++;
        double y = pts[2 * i + 1] + (pts[2 * i + 3] - pts[2 * i + 1]) * (x[0] - pts[2 * i]) /
                                        (pts[2 * i + 2] - pts[2 * i]);
        side = x[1] - y;
    }
    double s = side >= 0 ? 1.0 : -1.0;
    return (above ? s : -s) * best;
}

/* Signed distance to a closed polygon, positive outside: to the nearest edge, the side by
 * the crossing number of a ray from x towards +x. */
static double polygon_distance(const double *v, int n, const double *x)
{
    double best = INFINITY;
    int inside = 0;
    for (int i = 0; i < n; i++) {
        const double *a = v + 2 * i, *b = v + 2 * ((i + 1) % n);
        best = fmin(best, seg_dist(x[0], x[1], a[0], a[1], b[0], b[1]));
        if ((a[1] > x[1]) != (b[1] > x[1]) &&
            x[0] < a[0] + (x[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]))
            inside = !inside;
    }
    return inside ? -best : best;
}

double lub_wall_distance(const lub_wall *w, const double *x, int dim)
{
    double p[3] = {x[0], x[1], dim == 3 ? x[2] : 0.0};
    switch (w->type) {
    case LUB_WALL_PLANE: {
        double d[3] = {p[0] - w->point[0], p[1] - w->point[1], p[2] - w->point[2]};
        return dot3(d, w->normal);
    }
    case LUB_WALL_SEGMENT: {
        double pts[4] = {w->from[0], w->from[1], w->to[0], w->to[1]};
        if (pts[0] > pts[2]) {
            pts[0] = w->to[0], pts[1] = w->to[1], pts[2] = w->from[0], pts[3] = w->from[1];
        }
        return curve_distance(pts, 2, w->fluid_above, p);
    }
    case LUB_WALL_POLYLINE:
        return curve_distance(w->pts, w->npts, w->fluid_above, p);
    case LUB_WALL_CYLINDER:
    case LUB_WALL_SPHERE: {
        double d[3] = {p[0] - w->centre[0], p[1] - w->centre[1], p[2] - w->centre[2]};
        double a = 0.0;
        if (w->type == LUB_WALL_CYLINDER && dim == 3) {
            a = dot3(d, w->axis);
            for (int k = 0; k < 3; k++) d[k] -= a * w->axis[k];
        }
        double r = norm3(d) - w->radius;
        if (w->type == LUB_WALL_CYLINDER && w->has_length && dim == 3) {
            /* exact signed distance to the solid of finite length: outside, to the nearest
             * point of its round surface or flat ends; inside, minus the nearer of them */
            double e = fabs(a) - 0.5 * w->length;
            r = hypot(fmax(r, 0.0), fmax(e, 0.0)) + fmin(fmax(r, e), 0.0);
        }
        return w->fluid_inside ? -r : r;
    }
    case LUB_WALL_BOX: {
        /* exact signed distance to an axis-aligned box, positive outside */
        double out = 0.0, in = INFINITY;
        for (int d = 0; d < dim; d++) {
            double e = fmax(w->min[d] - p[d], p[d] - w->max[d]);
            if (e > 0) out += e * e;
            in = fmin(in, -e);
        }
        double sd = out > 0 ? sqrt(out) : -in;
        return w->fluid_inside ? -sd : sd;
    }
    case LUB_WALL_POLYGON:
        return polygon_distance(w->pts, w->npts, p);
    }
    return 0.0;
}
