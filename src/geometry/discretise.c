/* lubkit geometry discretisation (see discretise.h for the lattice and the rules). */
#include "geometry/discretise.h"
#include "particles/weight.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static const char *const axis_names[] = {"x", "y", "z"};

/* A generated point before it becomes a particle. */
typedef struct {
    double x[3];
    uint8_t kind, level;
    uint16_t wall;
} gen_pt;

typedef struct {
    gen_pt *p;
    size_t n, cap;
} gen_vec;

typedef struct {
    const lub_geometry *g;
    gen_vec pts;
    double origin[LUB_MAX_LEVELS][3]; /* lattice origin per level and direction */
    double tol;                       /* geometric tolerance (1e-6 of the finest l0) */
    int level;                        /* level being generated */
    int wall;                         /* wall being generated */
    int only;                         /* >= 0: lub_geometry_discretise_range: this level */
    double xlo, xhi;                  /*   owns [xlo, xhi] (walls: padded), no other level */
} gen_ctx;

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* ---- levels and lattice --------------------------------------------------------------- */

/* The level that owns x: the first whose region contains it, else the last. */
static int level_of(const lub_geometry *g, double x)
{
    for (int k = 0; k < g->nlevels; k++)
        if (g->levels[k].has_region && x >= g->levels[k].xmin && x <= g->levels[k].xmax) return k;
    return g->levels[g->nlevels - 1].has_region ? -1 : g->nlevels - 1;
}

/* Whether the level being generated takes a point at x: it owns x, or (a range) x lies in
 * the range. */
static int takes(const gen_ctx *c, double x)
{
    if (c->only >= 0) return x >= c->xlo && x <= c->xhi;
    return level_of(c->g, x) == c->level;
}

static int in_domain(const lub_geometry *g, const double *x, double tol)
{
    for (int d = 0; d < g->dim; d++) {
        if (g->periodic[d]) {
            if (x[d] < g->dmin[d] || x[d] >= g->dmax[d]) return 0;
        } else if (x[d] < g->dmin[d] - tol || x[d] > g->dmax[d] + tol)
            return 0;
    }
    return 1;
}

/* An axis-aligned plane normal: the axis, or -1. */
static int plane_axis(const lub_wall *w)
{
    for (int d = 0; d < 3; d++)
        if (fabs(fabs(w->normal[d]) - 1.0) < 1e-12) return d;
    return -1;
}

static void set_origins(gen_ctx *c)
{
    const lub_geometry *g = c->g;
    for (int d = 0; d < 3; d++) {
        int found = 0;
        double o = 0.0;
        for (int i = 0; i < g->nwalls && !found && !g->periodic[d]; i++) {
            const lub_wall *w = &g->walls[i];
            if (w->type == LUB_WALL_PLANE && plane_axis(w) == d) {
                o = w->point[d];
                found = 1;
            } else if (w->type == LUB_WALL_BOX && d < g->dim) {
                o = w->min[d];
                found = 1;
            }
        }
        for (int k = 0; k < g->nlevels; k++)
            c->origin[k][d] = found ? o : g->dmin[d] + 0.5 * g->levels[k].l0;
    }
}

/* Lattice indices i0..i1 of level k in direction d whose points lie in [a, b] (tolerant). */
static void lattice_span(const gen_ctx *c, int k, int d, double a, double b, long *i0, long *i1)
{
    double l0 = c->g->levels[k].l0, o = c->origin[k][d];
    *i0 = (long)ceil((a - o) / l0 - 1e-6);
    *i1 = (long)floor((b - o) / l0 + 1e-6);
}

/* Fatal unless coordinate v of direction d lies on every level's lattice. */
static void check_on_lattice(const gen_ctx *c, const lub_wall *w, int d, double v, const char *what)
{
    if (v < c->g->dmin[d] - c->tol || v > c->g->dmax[d] + c->tol) return; /* no particles */
    for (int k = 0; k < c->g->nlevels; k++) {
        double l0 = c->g->levels[k].l0, q = (v - c->origin[k][d]) / l0;
        if (fabs(q - round(q)) > 1e-6)
            lub_node_error(w->node,
                           "wall '%s': %s %s = %g is not on the particle lattice (spacing l0 = "
                           "%g through %s = %g); move it by a multiple of l0",
                           w->name, what, axis_names[d], v, l0, axis_names[d], c->origin[k][d]);
    }
}

/* ---- collecting points ---------------------------------------------------------------- */

static void push(gen_ctx *c, const double *x, int kind)
{
    const lub_geometry *g = c->g;
    double p[3] = {x[0], x[1], g->dim == 3 ? x[2] : 0.0};
    if (!in_domain(g, p, c->tol)) return;
    if (!takes(c, p[0])) return;
    gen_vec *v = &c->pts;
    if (v->n == v->cap) {
        v->cap = v->cap ? 2 * v->cap : 1024;
        v->p = lub_realloc(v->p, v->cap * sizeof *v->p);
    }
    gen_pt *q = &v->p[v->n++];
    memcpy(q->x, p, sizeof p);
    q->kind = (uint8_t)kind;
    q->level = (uint8_t)c->level;
    q->wall = (uint16_t)c->wall;
}

/* Iterate the lattice of the current level in the box [lo, hi] (clipped to the domain). */
typedef double (*depth_fn)(const lub_wall *w, const double *x, int dim);

static void lattice_wall(gen_ctx *c, const lub_wall *w, const double *lo, const double *hi,
                         depth_fn depth)
{
    const lub_geometry *g = c->g;
    int k = c->level, L = g->dummy_layers;
    double l0 = g->levels[k].l0, tol = 1e-6 * l0;
    long i0[3] = {0, 0, 0}, i1[3] = {0, 0, 0};
    for (int d = 0; d < g->dim; d++)
        lattice_span(c, k, d, fmax(lo[d], g->dmin[d]), fmin(hi[d], g->dmax[d]), &i0[d], &i1[d]);
    for (long a = i0[0]; a <= i1[0]; a++)
        for (long b = i0[1]; b <= i1[1]; b++)
            for (long e = i0[2]; e <= i1[2]; e++) {
                double x[3] = {c->origin[k][0] + a * l0, c->origin[k][1] + b * l0,
                               g->dim == 3 ? c->origin[k][2] + e * l0 : 0.0};
                double dep = depth(w, x, g->dim);
                if (dep < -tol || dep > L * l0 + tol) continue;
                push(c, x, dep <= tol ? LUB_WALL : LUB_DUMMY);
            }
}

/* Depth behind an axis-aligned plane. */
static double plane_depth(const lub_wall *w, const double *x, int dim)
{
    (void)dim;
    double d[3] = {x[0] - w->point[0], x[1] - w->point[1], x[2] - w->point[2]};
    return -dot3(d, w->normal);
}

/* Depth behind a box face, measured in the max-norm so that the dummy layers fill the
 * corners as full squares (cubes): behind a tank wall (fluid inside) the depth is the
 * largest distance outside over the directions; inside a block (fluid outside) the smallest
 * distance to a face.  Fluid-side points get a negative depth. */
static double box_depth(const lub_wall *w, const double *x, int dim)
{
    double out = -INFINITY; /* max over d of the excess outside */
    for (int d = 0; d < dim; d++) out = fmax(out, fmax(w->min[d] - x[d], x[d] - w->max[d]));
    /* out > 0 outside, <= 0 inside (minus the distance to the nearest face) */
    return w->fluid_inside ? out : -out;
}

/* ---- sampled walls -------------------------------------------------------------------- */

/* Curve (2-D) given by points, sampled at spacing ~l0 (n = round(length / l0) intervals,
 * both ends included), dummy layers offset along the local normal toward the solid. */
static void sample_curve(gen_ctx *c, const double *pts, int npts, int fluid_above)
{
    const lub_geometry *g = c->g;
    double l0 = g->levels[c->level].l0;
    int nseg = npts - 1;
    double *len = lub_malloc((size_t)nseg * sizeof *len),
           *nx = lub_malloc((size_t)nseg * sizeof *nx), *ny = lub_malloc((size_t)nseg * sizeof *ny),
           total = 0.0;
    for (int i = 0; i < nseg; i++) {
        double tx = pts[2 * i + 2] - pts[2 * i], ty = pts[2 * i + 3] - pts[2 * i + 1];
        len[i] = hypot(tx, ty);
        total += len[i];
        /* normal into the fluid: (-ty, tx) points up when x increases */
        double s = (tx > 0) == (fluid_above != 0) ? 1.0 : -1.0;
        nx[i] = -s * ty / len[i];
        ny[i] = s * tx / len[i];
    }
    long nint = lround(total / l0);
    if (nint < 1) nint = 1;
    double ds = total / (double)nint;
    int seg = 0;
    double s0 = 0.0; /* arc length at the start of seg */
    for (long i = 0; i <= nint; i++) {
        double s = i * ds;
        while (seg < nseg - 1 && s > s0 + len[seg]) s0 += len[seg++];
        double t = (s - s0) / len[seg];
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        double x[3] = {pts[2 * seg] + t * (pts[2 * seg + 2] - pts[2 * seg]),
                       pts[2 * seg + 1] + t * (pts[2 * seg + 3] - pts[2 * seg + 1]), 0};
        double n[2] = {nx[seg], ny[seg]};
        /* at a vertex use the mean normal of both segments */
        if (t > 1 - 1e-9 && seg + 1 < nseg) n[0] += nx[seg + 1], n[1] += ny[seg + 1];
        if (t < 1e-9 && seg > 0) n[0] += nx[seg - 1], n[1] += ny[seg - 1];
        double nn = hypot(n[0], n[1]);
        n[0] /= nn, n[1] /= nn;
        for (int j = 0; j <= g->dummy_layers; j++) {
            double y[3] = {x[0] - j * l0 * n[0], x[1] - j * l0 * n[1], 0};
            push(c, y, j ? LUB_DUMMY : LUB_WALL);
        }
    }
    free(len);
    free(nx);
    free(ny);
}

/* Inclined 2-D plane: the line clipped to the domain, sampled at l0 from the plane point. */
static void sample_plane2(gen_ctx *c, const lub_wall *w)
{
    const lub_geometry *g = c->g;
    double l0 = g->levels[c->level].l0, L = g->dummy_layers * l0;
    double t[2] = {w->normal[1], -w->normal[0]};
    double s0 = -INFINITY, s1 = INFINITY;
    for (int d = 0; d < 2; d++) {
        double a = g->dmin[d] - L - w->point[d], b = g->dmax[d] + L - w->point[d];
        if (d == 0 && w->has_range) a = w->range[0] - w->point[0], b = w->range[1] - w->point[0];
        if (fabs(t[d]) < 1e-15) continue;
        double u = a / t[d], v = b / t[d];
        s0 = fmax(s0, fmin(u, v));
        s1 = fmin(s1, fmax(u, v));
    }
    for (long i = (long)ceil(s0 / l0 - 1e-9); i <= (long)floor(s1 / l0 + 1e-9); i++)
        for (int j = 0; j <= g->dummy_layers; j++) {
            double x[3] = {w->point[0] + i * l0 * t[0] - j * l0 * w->normal[0],
                           w->point[1] + i * l0 * t[1] - j * l0 * w->normal[1], 0};
            push(c, x, j ? LUB_DUMMY : LUB_WALL);
        }
}

/* Two unit vectors perpendicular to n and to each other; e1 points as far down (-y) as
 * possible, so that angle 0 of a ring is its lowest point. */
static void perp_basis(const double *n, double *e1, double *e2)
{
    double down[3] = {0, -1, 0};
    double a = dot3(down, n);
    for (int d = 0; d < 3; d++) e1[d] = down[d] - a * n[d];
    double m = sqrt(dot3(e1, e1));
    if (m < 1e-9) { /* n vertical: any horizontal direction */
        e1[0] = 1, e1[1] = 0, e1[2] = 0;
        a = dot3(e1, n);
        for (int d = 0; d < 3; d++) e1[d] -= a * n[d];
        m = sqrt(dot3(e1, e1));
    }
    for (int d = 0; d < 3; d++) e1[d] /= m;
    e2[0] = n[1] * e1[2] - n[2] * e1[1];
    e2[1] = n[2] * e1[0] - n[0] * e1[2];
    e2[2] = n[0] * e1[1] - n[1] * e1[0];
}

/* Inclined 3-D plane: a square grid on the plane through its point. */
static void sample_plane3(gen_ctx *c, const lub_wall *w)
{
    const lub_geometry *g = c->g;
    double l0 = g->levels[c->level].l0;
    double e1[3], e2[3];
    perp_basis(w->normal, e1, e2);
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int corner = 0; corner < 8; corner++) {
        double q[3];
        for (int d = 0; d < 3; d++)
            q[d] = ((corner >> d) & 1 ? g->dmax[d] : g->dmin[d]) - w->point[d];
        double u = dot3(q, e1), v = dot3(q, e2);
        lo[0] = fmin(lo[0], u), hi[0] = fmax(hi[0], u);
        lo[1] = fmin(lo[1], v), hi[1] = fmax(hi[1], v);
    }
    /* a tangent along a coordinate axis follows that axis' lattice (periodic seams) */
    double off[2] = {0.0, 0.0};
    const double *e[2] = {e1, e2};
    for (int a = 0; a < 2; a++)
        for (int d = 0; d < 3; d++)
            if (fabs(fabs(e[a][d]) - 1.0) < 1e-12)
                off[a] = fmod((c->origin[c->level][d] - w->point[d]) * e[a][d], l0);
    for (long i = (long)floor(lo[0] / l0) - 1; i <= (long)ceil(hi[0] / l0); i++)
        for (long m = (long)floor(lo[1] / l0) - 1; m <= (long)ceil(hi[1] / l0); m++)
            for (int j = 0; j <= g->dummy_layers; j++) {
                double x[3], u = i * l0 + off[0], v = m * l0 + off[1];
                for (int d = 0; d < 3; d++)
                    x[d] = w->point[d] + u * e1[d] + v * e2[d] - j * l0 * w->normal[d];
                if (w->has_range && (x[0] < w->range[0] || x[0] > w->range[1])) continue;
                push(c, x, j ? LUB_DUMMY : LUB_WALL);
            }
}

/* Radius of layer j of a round wall: j > 0 the dummy layers behind the surface, j = 0 the
 * wall, j < 0 the fluid layers in front of it (fluidLayers). */
static double layer_radius(const lub_wall *w, int j, double l0)
{
    return w->fluid_inside ? w->radius + j * l0 : w->radius - j * l0;
}

static int layer_kind(int j)
{
    return j > 0 ? LUB_DUMMY : j == 0 ? LUB_WALL : LUB_FLUID;
}

/* 2-D circle (or one ring of a 3-D cylinder, in the plane spanned by e1, e2 around cen). */
static void sample_ring(gen_ctx *c, const lub_wall *w, const double *cen, const double *e1,
                        const double *e2, double r, int kind, int full)
{
    const lub_geometry *g = c->g;
    double l0 = g->levels[c->level].l0;
    if (r <= 0.5 * l0) {
        if (r > 0) return;
        push(c, cen, kind);
        return;
    }
    long n;
    double dphi;
    if (full) {
        /* the whole ring is in the domain: close it with n equal steps of about l0 */
        n = lround(2 * M_PI * r / l0);
        if (n < 3) n = 3;
        dphi = 2 * M_PI / (double)n;
    } else {
        /* a partial arc: exactly l0 of arc length between neighbours, from the lowest
         * point both ways */
        dphi = l0 / r;
        n = (long)floor(2 * M_PI / dphi);
    }
    for (long i = 0; i < n; i++) {
        /* angles 0, +d, -d, +2d, ... for the partial arc; 0..n-1 steps for the full ring */
        double phi = full ? i * dphi : ((i + 1) / 2) * dphi * (i % 2 ? 1.0 : -1.0);
        if (!full && fabs(phi) > M_PI + 1e-12) continue;
        if (!full && i > 0 && fabs(fabs(phi) - M_PI) < 1e-12 && phi < 0) continue;
        double x[3];
        for (int d = 0; d < 3; d++) x[d] = cen[d] + r * (cos(phi) * e1[d] + sin(phi) * e2[d]);
        if (w->has_range && (x[0] < w->range[0] - c->tol || x[0] > w->range[1] + c->tol)) continue;
        push(c, x, kind);
    }
}

/* Whether a sphere/ring of radius r around cen lies wholly in the domain (non-periodic). */
static int ring_inside(const lub_geometry *g, const double *cen, double r, int dims)
{
    for (int d = 0; d < dims; d++)
        if (cen[d] - r < g->dmin[d] || cen[d] + r > g->dmax[d] || g->periodic[d]) return 0;
    return 1;
}

/* A 3-D cylinder of finite length (a roller with flat ends, geometry.h; fluid outside):
 * rings of radius R - j l0 (j = 0 .. dummyLayers) at the axial positions t from -length/2 to
 * +length/2 (the lattice's when the axis is a coordinate axis, t0 + i step; else
 * round(length / l0) equal steps), and on the end planes t = +-(length/2 - j l0) a square
 * grid (the lattice of the two other directions for a coordinate axis) inside radius
 * R - (dummyLayers + 1/2) l0, at least l0/2 from the innermost ring.  A point is a wall
 * particle where it lies on the surface (the outer ring, and every point of an end plane's
 * outer layer), a dummy where it lies j l0 deep (the smaller of its radial and axial
 * depths). */
static void sample_roller(gen_ctx *c, const lub_wall *w, const double *e1, const double *e2,
                          double t0, double step, int lattice)
{
    const lub_geometry *g = c->g;
    const int L = g->dummy_layers;
    const double l0 = g->levels[c->level].l0, half = 0.5 * w->length;
    long i0, i1;
    if (lattice) {
        step = fabs(step); /* {t0 + i step} over all integers i is the same set */
        i0 = (long)ceil((-half - t0) / step - 1e-6);
        i1 = (long)floor((half - t0) / step + 1e-6);
    } else {
        long n = lround(w->length / l0);
        step = w->length / (double)(n < 1 ? 1 : n);
        t0 = -half;
        i0 = 0;
        i1 = n < 1 ? 1 : n;
    }
    for (long i = i0; i <= i1; i++) {
        double t = t0 + i * step, cen[3];
        long e = lround((half - fabs(t)) / l0); /* axial depth in layers */
        for (int d = 0; d < 3; d++) cen[d] = w->centre[d] + t * w->axis[d];
        for (int j = 0; j <= L; j++)
            sample_ring(c, w, cen, e1, e2, layer_radius(w, j, l0),
                        (e < j ? e : j) ? LUB_DUMMY : LUB_WALL, 1);
    }
    /* the flat ends; the grid searched only where the domain is */
    const double rmax = w->radius - (L + 0.5) * l0;
    if (!(rmax > 0)) return;
    for (int side = -1; side <= 1; side += 2)
        for (int j = 0; j <= L; j++) {
            double t = side * (half - j * l0), cen[3];
            for (int d = 0; d < 3; d++) cen[d] = w->centre[d] + t * w->axis[d];
            double off[2] = {0, 0}, lo[2] = {-rmax, -rmax}, hi[2] = {rmax, rmax};
            const double *e[2] = {e1, e2};
            for (int k = 0; k < 2; k++) {
                double plo = INFINITY, phi = -INFINITY;
                for (int corner = 0; corner < 8; corner++) {
                    double q[3];
                    for (int d = 0; d < 3; d++)
                        q[d] = ((corner >> d) & 1 ? g->dmax[d] : g->dmin[d]) - cen[d];
                    plo = fmin(plo, dot3(q, e[k])), phi = fmax(phi, dot3(q, e[k]));
                }
                lo[k] = fmax(lo[k], plo), hi[k] = fmin(hi[k], phi);
                for (int d = 0; d < 3 && lattice; d++)
                    if (fabs(fabs(e[k][d]) - 1.0) < 1e-12) {
                        double q = (c->origin[c->level][d] - cen[d]) * e[k][d] / l0;
                        off[k] = (q - floor(q)) * l0;
                    }
            }
            for (long a = (long)floor((lo[0] - off[0]) / l0); a * l0 + off[0] <= hi[0]; a++)
                for (long b = (long)floor((lo[1] - off[1]) / l0); b * l0 + off[1] <= hi[1]; b++) {
                    double u = off[0] + a * l0, v = off[1] + b * l0, x[3];
                    if (u * u + v * v > rmax * rmax) continue;
                    for (int d = 0; d < 3; d++) x[d] = cen[d] + u * e1[d] + v * e2[d];
                    if (w->has_range &&
                        (x[0] < w->range[0] - c->tol || x[0] > w->range[1] + c->tol))
                        continue;
                    push(c, x, j ? LUB_DUMMY : LUB_WALL);
                }
        }
}

/* The layers j0..j1 of a cylinder (layer_radius); a roller of finite length (3-D, `length`)
 * its wall and dummy layers only (geometry.c refuses fluidLayers on it). */
static void sample_cylinder(gen_ctx *c, const lub_wall *w, int j0, int j1)
{
    const lub_geometry *g = c->g;
    double l0 = g->levels[c->level].l0;
    if (g->dim == 2) {
        double e1[3] = {0, -1, 0}, e2[3] = {1, 0, 0};
        for (int j = j0; j <= j1; j++) {
            double r = layer_radius(w, j, l0);
            int full = !w->has_range && ring_inside(g, w->centre, r, 2);
            sample_ring(c, w, w->centre, e1, e2, r, layer_kind(j), full);
        }
        return;
    }
    /* 3-D: rings along the axis; on the lattice when the axis is a coordinate axis */
    double e1[3], e2[3];
    perp_basis(w->axis, e1, e2);
    int ax = -1;
    for (int d = 0; d < 3; d++)
        if (fabs(fabs(w->axis[d]) - 1.0) < 1e-12) ax = d;
    double lo = INFINITY, hi = -INFINITY;
    for (int corner = 0; corner < 8; corner++) {
        double q[3];
        for (int d = 0; d < 3; d++)
            q[d] = ((corner >> d) & 1 ? g->dmax[d] : g->dmin[d]) - w->centre[d];
        double t = dot3(q, w->axis);
        lo = fmin(lo, t), hi = fmax(hi, t);
    }
    long i0, i1;
    double t0 = 0.0, step = l0;
    if (ax >= 0) {
        /* lattice coordinates of direction ax, expressed as t along the axis */
        lattice_span(c, c->level, ax, g->dmin[ax], g->dmax[ax], &i0, &i1);
        t0 = (c->origin[c->level][ax] - w->centre[ax]) * w->axis[ax];
        step = l0 * w->axis[ax];
    } else {
        i0 = (long)floor(lo / l0);
        i1 = (long)ceil(hi / l0);
    }
    if (!w->has_length) {
        for (long i = i0; i <= i1; i++) {
            double t = t0 + i * step, cen[3];
            for (int d = 0; d < 3; d++) cen[d] = w->centre[d] + t * w->axis[d];
            for (int j = j0; j <= j1; j++)
                sample_ring(c, w, cen, e1, e2, layer_radius(w, j, l0), layer_kind(j), 1);
        }
        return;
    }
    if (j0 < 0) return; /* no body-fitted fluid rows on a roller (geometry.c refuses it) */
    sample_roller(c, w, e1, e2, t0, step, ax >= 0);
}

/* Sphere: rings of constant polar angle about the vertical axis, from the lowest point;
 * the layers j0..j1 (layer_radius). */
static void sample_sphere(gen_ctx *c, const lub_wall *w, int j0, int j1)
{
    const lub_geometry *g = c->g;
    double l0 = g->levels[c->level].l0;
    double up[3] = {0, 1, 0}, e1[3] = {1, 0, 0}, e2[3] = {0, 0, 1};
    for (int j = j0; j <= j1; j++) {
        double r = layer_radius(w, j, l0);
        int kind = layer_kind(j);
        if (r <= 0.5 * l0) {
            if (r > 0) continue;
            push(c, w->centre, kind);
            continue;
        }
        long nt = lround(M_PI * r / l0);
        if (nt < 2) nt = 2;
        for (long i = 0; i <= nt; i++) {
            double th = M_PI * (double)i / (double)nt, rr = r * sin(th);
            double cen[3];
            for (int d = 0; d < 3; d++) cen[d] = w->centre[d] - r * cos(th) * up[d];
            if (rr < 1e-9 * r) {
                push(c, cen, kind); /* pole */
                continue;
            }
            sample_ring(c, w, cen, e1, e2, rr, kind, 1);
        }
    }
}

/* A candidate point of a polygon, and its cell of side l0/2 (for the spacing check). */
typedef struct {
    double x[2];
    long cx, cy;
    int layer, keep;
} poly_pt;

static int poly_cell_cmp(const void *a, const void *b)
{
    const poly_pt *p = *(const poly_pt *const *)a, *q = *(const poly_pt *const *)b;
    if (p->cx != q->cx) return p->cx < q->cx ? -1 : 1;
    if (p->cy != q->cy) return p->cy < q->cy ? -1 : 1;
    return (p > q) - (p < q); /* generation order */
}

/* First entry of the sorted cell index whose cell is (cx, cy) or after it. */
static size_t poly_cell_find(poly_pt *const *idx, size_t n, long cx, long cy)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (idx[mid]->cx < cx || (idx[mid]->cx == cx && idx[mid]->cy < cy))
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Closed polygon (2-D; counter-clockwise, solid inside, fluid outside).  Layer j = 0 (the
 * wall particles) .. dummyLayers is the boundary moved j l0 inwards, each vertex along its
 * mitre (the point j l0 from the lines of both its edges), so that the layers of an
 * axis-aligned corner, convex or concave, are the lattice's rows and columns, the corner
 * square included.  Each edge of a layer is divided into round(length / l0) equal steps
 * from its first vertex, so the vertices are particles (corners are not cut) and no vertex
 * is placed twice.  A dummy is kept only inside the body and at least j l0 from every edge
 * (a layer folding over itself in a thin part or at a sharp corner is cut off; an edge the
 * offset turns round is dropped), and a point only if no point placed before it (the wall
 * layer first, then the dummy layers in turn) lies within 0.5 l0: no double particles at a
 * vertex, an edge shorter than l0/2 or a body thinner than its layers. */
static void sample_polygon(gen_ctx *c, const lub_wall *w)
{
    const lub_geometry *g = c->g;
    const double l0 = g->levels[c->level].l0, h = 0.5 * l0;
    const int n = w->npts, L = g->dummy_layers;
    const double *v = w->pts;
    double *t = lub_malloc(2 * (size_t)n * sizeof *t),
           *mit = lub_malloc(2 * (size_t)n * sizeof *mit);
    for (int i = 0; i < n; i++) { /* unit tangents of the edges i -> i + 1 */
        int k = (i + 1) % n;
        double tx = v[2 * k] - v[2 * i], ty = v[2 * k + 1] - v[2 * i + 1], len = hypot(tx, ty);
        t[2 * i] = tx / len, t[2 * i + 1] = ty / len;
    }
    for (int i = 0; i < n; i++) { /* mitre of vertex i: m . n_a = m . n_b = 1 */
        int a = (i + n - 1) % n;
        double nax = -t[2 * a + 1], nay = t[2 * a], nbx = -t[2 * i + 1], nby = t[2 * i];
        double den = 1.0 + nax * nbx + nay * nby; /* > 0: no edge folds back (read_polygon) */
        mit[2 * i] = (nax + nbx) / den, mit[2 * i + 1] = (nay + nby) / den;
    }
    poly_pt *q = NULL;
    size_t nq = 0, cap = 0;
    for (int j = 0; j <= L; j++)
        for (int i = 0; i < n; i++) {
            int k = (i + 1) % n;
            double a[2] = {v[2 * i] + j * l0 * mit[2 * i], v[2 * i + 1] + j * l0 * mit[2 * i + 1]};
            double b[2] = {v[2 * k] + j * l0 * mit[2 * k], v[2 * k + 1] + j * l0 * mit[2 * k + 1]};
            double ex = b[0] - a[0], ey = b[1] - a[1];
            if (ex * t[2 * i] + ey * t[2 * i + 1] <= 0.0) continue; /* turned round */
            long steps = lround(hypot(ex, ey) / l0);
            if (steps < 1) steps = 1;
            for (long m = 0; m < steps; m++) {
                double s = (double)m / (double)steps, x[3] = {a[0] + s * ex, a[1] + s * ey, 0};
                if (j > 0 && !(lub_wall_distance(w, x, 2) <= -(j * l0 - 1e-6 * l0))) continue;
                if (nq == cap) {
                    cap = cap ? 2 * cap : 256;
                    q = lub_realloc(q, cap * sizeof *q);
                }
                q[nq++] =
                    (poly_pt){{x[0], x[1]}, (long)floor(x[0] / h), (long)floor(x[1] / h), j, 1};
            }
        }
    /* the spacing check, in generation order, on an index sorted by cell */
    poly_pt **idx = lub_malloc((nq ? nq : 1) * sizeof *idx);
    for (size_t i = 0; i < nq; i++) idx[i] = &q[i];
    qsort(idx, nq, sizeof *idx, poly_cell_cmp);
    for (size_t i = 0; i < nq; i++) {
        poly_pt *p = &q[i];
        for (long cx = p->cx - 1; cx <= p->cx + 1 && p->keep; cx++)
            for (long cy = p->cy - 1; cy <= p->cy + 1 && p->keep; cy++)
                for (size_t r = poly_cell_find(idx, nq, cx, cy);
                     r < nq && idx[r]->cx == cx && idx[r]->cy == cy && idx[r] < p; r++)
                    if (idx[r]->keep &&
                        hypot(idx[r]->x[0] - p->x[0], idx[r]->x[1] - p->x[1]) < h * (1 - 1e-9)) {
                        p->keep = 0;
                        break;
                    }
    }
    for (size_t i = 0; i < nq; i++)
        if (q[i].keep)
            push(c, (double[]){q[i].x[0], q[i].x[1], 0}, q[i].layer ? LUB_DUMMY : LUB_WALL);
    free(idx);
    free(q);
    free(t);
    free(mit);
}

static void discretise_wall(gen_ctx *c, const lub_wall *w)
{
    const lub_geometry *g = c->g;
    double l0 = g->levels[c->level].l0, L = g->dummy_layers * l0;
    double lo[3], hi[3];
    for (int d = 0; d < 3; d++) lo[d] = g->dmin[d], hi[d] = g->dmax[d];
    switch (w->type) {
    case LUB_WALL_PLANE: {
        int ax = plane_axis(w);
        if (ax >= 0 && ax < g->dim) {
            if (w->normal[ax] > 0)
                lo[ax] = w->point[ax] - L, hi[ax] = w->point[ax];
            else
                lo[ax] = w->point[ax], hi[ax] = w->point[ax] + L;
            if (w->has_range) lo[0] = fmax(lo[0], w->range[0]), hi[0] = fmin(hi[0], w->range[1]);
            lattice_wall(c, w, lo, hi, plane_depth);
        } else if (g->dim == 2) {
            sample_plane2(c, w);
        } else {
            sample_plane3(c, w);
        }
        break;
    }
    case LUB_WALL_BOX:
        for (int d = 0; d < g->dim; d++) {
            lo[d] = fmax(lo[d], w->min[d] - L);
            hi[d] = fmin(hi[d], w->max[d] + L);
        }
        lattice_wall(c, w, lo, hi, box_depth);
        break;
    case LUB_WALL_SEGMENT: {
        double pts[4] = {w->from[0], w->from[1], w->to[0], w->to[1]};
        sample_curve(c, pts, 2, w->fluid_above);
        break;
    }
    case LUB_WALL_POLYLINE:
        sample_curve(c, w->pts, w->npts, w->fluid_above);
        break;
    case LUB_WALL_CYLINDER:
        sample_cylinder(c, w, 0, g->dummy_layers);
        break;
    case LUB_WALL_SPHERE:
        sample_sphere(c, w, 0, g->dummy_layers);
        break;
    case LUB_WALL_POLYGON:
        sample_polygon(c, w);
        break;
    }
}

/* ---- cell grid for distance queries --------------------------------------------------- */

typedef struct {
    int dim, n[3], per[3];
    double lo[3], h[3], period[3];
    long *head, *next;
    gen_pt *const *pts; /* the generation array, which may move while fluid is added */
    size_t npts;
} cell_grid;

static long cell_index(const cell_grid *cg, const int *ci)
{
    return ((long)ci[2] * cg->n[1] + ci[1]) * cg->n[0] + ci[0];
}

static void cell_of(const cell_grid *cg, const double *x, int *ci)
{
    ci[0] = ci[1] = ci[2] = 0;
    for (int d = 0; d < cg->dim; d++) {
        int i = (int)floor((x[d] - cg->lo[d]) / cg->h[d]);
        ci[d] = i < 0 ? 0 : i >= cg->n[d] ? cg->n[d] - 1 : i;
    }
}

static void grid_build(cell_grid *cg, const lub_geometry *g, gen_pt *const *ptsp, size_t n,
                       double h)
{
    memset(cg, 0, sizeof *cg);
    cg->dim = g->dim;
    cg->pts = ptsp;
    const gen_pt *pts = *ptsp;
    cg->npts = n;
    /* keep the cell count near the point count: coarser cells are still correct */
    double cap = 4.0 * (double)n + 1024.0;
    for (;;) {
        double total = 1.0;
        for (int d = 0; d < 3; d++) {
            double ext = d < g->dim ? g->dmax[d] - g->dmin[d] : 0.0;
            double nd = d < g->dim ? floor(ext / h) : 1.0;
            if (nd < 1) nd = 1;
            total *= nd;
        }
        if (total <= cap) break;
        h *= 2.0;
    }
    for (int d = 0; d < 3; d++) {
        if (d >= g->dim) {
            cg->n[d] = 1, cg->h[d] = 1.0;
            continue;
        }
        double ext = g->dmax[d] - g->dmin[d];
        cg->n[d] = (int)fmax(1.0, floor(ext / h));
        cg->h[d] = ext / cg->n[d];
        cg->lo[d] = g->dmin[d];
        cg->per[d] = g->periodic[d];
        cg->period[d] = ext;
    }
    long nc = (long)cg->n[0] * cg->n[1] * cg->n[2];
    cg->head = lub_malloc((size_t)nc * sizeof *cg->head);
    cg->next = lub_malloc((n ? n : 1) * sizeof *cg->next);
    for (long i = 0; i < nc; i++) cg->head[i] = -1;
    /* insert in reverse so each cell lists its points in increasing index */
    for (size_t i = n; i-- > 0;) {
        int ci[3];
        cell_of(cg, pts[i].x, ci);
        long c = cell_index(cg, ci);
        cg->next[i] = cg->head[c];
        cg->head[c] = (long)i;
    }
}

static void grid_free(cell_grid *cg)
{
    free(cg->head);
    free(cg->next);
}

/* Index of the first point j < limit with |x_j - x| < r (minimum image in periodic
 * directions; r must not exceed the cell size), or -1. */
static long grid_find(const cell_grid *cg, const double *x, double r, size_t limit)
{
    int ci[3], lo[3], hi[3];
    cell_of(cg, x, ci);
    for (int d = 0; d < 3; d++) {
        lo[d] = ci[d] - 1, hi[d] = ci[d] + 1;
        if (d >= cg->dim || cg->n[d] <= 2) {
            lo[d] = 0, hi[d] = cg->n[d] - 1; /* all cells: no double visits on wrap */
        } else if (!cg->per[d]) {
            if (lo[d] < 0) lo[d] = 0;
            if (hi[d] >= cg->n[d]) hi[d] = cg->n[d] - 1;
        }
    }
    double r2 = r * r;
    long best = -1;
    for (int a = lo[2]; a <= hi[2]; a++)
        for (int b = lo[1]; b <= hi[1]; b++)
            for (int e = lo[0]; e <= hi[0]; e++) {
                int cc[3] = {e, b, a};
                for (int d = 0; d < 3; d++)
                    if (cg->per[d]) cc[d] = ((cc[d] % cg->n[d]) + cg->n[d]) % cg->n[d];
                for (long j = cg->head[cell_index(cg, cc)]; j >= 0; j = cg->next[j]) {
                    if ((size_t)j >= limit) break;
                    double s = 0.0;
                    for (int d = 0; d < cg->dim; d++) {
                        double dx = (*cg->pts)[j].x[d] - x[d];
                        if (cg->per[d]) dx -= cg->period[d] * round(dx / cg->period[d]);
                        s += dx * dx;
                    }
                    if (s < r2 && (best < 0 || j < best)) best = j;
                }
            }
    return best;
}

/* ---- behind walls, fluid regions ------------------------------------------------------ */

/* Whether x lies within the x-span of a wall that is open at its ends (a plane with a
 * range, a segment, a polyline); always 1 for the others. */
static int in_span(const lub_wall *w, const double *x)
{
    switch (w->type) {
    case LUB_WALL_PLANE:
        return !w->has_range || (x[0] >= w->range[0] && x[0] <= w->range[1]);
    case LUB_WALL_SEGMENT:
        return x[0] >= fmin(w->from[0], w->to[0]) && x[0] <= fmax(w->from[0], w->to[0]);
    case LUB_WALL_POLYLINE:
        return x[0] >= w->pts[0] && x[0] <= w->pts[2 * (w->npts - 1)];
    default:
        return 1;
    }
}

int lub_wall_behind(const lub_wall *w, const double *x, int dim, double tol)
{
    return in_span(w, x) && lub_wall_distance(w, x, dim) < -tol;
}

static int in_region(const lub_geometry *g, const lub_region *r, const double *x, double tol)
{
    switch (r->type) {
    case LUB_REGION_LAYER: {
        if (!in_span(&g->walls[r->wall], x)) return 0; /* no rounded ends on open walls */
        double d = lub_wall_distance(&g->walls[r->wall], x, g->dim);
        return d >= -tol && d <= r->thickness + tol;
    }
    case LUB_REGION_BOX:
        for (int d = 0; d < g->dim; d++)
            if (x[d] < r->min[d] - tol || x[d] > r->max[d] + tol) return 0;
        return 1;
    case LUB_REGION_BETWEEN: {
        const lub_wall *lw = &g->walls[r->lower];
        double above;
        if (g->dim == 2) {
            double yl;
            if (!lub_wall_height(lw, x[0], 0, &yl)) return 0;
            above = x[1] - yl;
        } else {
            above = lub_wall_distance(lw, x, 3);
        }
        if (above < -tol || above > r->height + tol) return 0;
        return lub_wall_distance(&g->walls[r->upper], x, g->dim) >= -tol;
    }
    }
    return 0;
}

int lub_geometry_fluid_at(const lub_geometry *g, const double *x, double tol)
{
    int inside = 0;
    for (int r = 0; r < g->nregions && !inside; r++) inside = in_region(g, &g->regions[r], x, tol);
    if (!inside) return 0;
    for (int w = 0; w < g->nwalls; w++)
        if (lub_wall_behind(&g->walls[w], x, g->dim, 0.0)) return 0;
    return 1;
}

/* Bounding box of a region's lattice search (domain, narrowed where cheap to know). */
static void region_bbox(const lub_geometry *g, const lub_region *r, double *lo, double *hi)
{
    for (int d = 0; d < 3; d++) lo[d] = g->dmin[d], hi[d] = g->dmax[d];
    if (r->type == LUB_REGION_BOX) {
        for (int d = 0; d < g->dim; d++) lo[d] = r->min[d], hi[d] = r->max[d];
        return;
    }
    const lub_wall *w = &g->walls[r->type == LUB_REGION_LAYER ? r->wall : r->lower];
    double t = r->type == LUB_REGION_LAYER ? r->thickness : r->height;
    int ax = w->type == LUB_WALL_PLANE ? plane_axis(w) : -1;
    if (ax >= 0 && ax < g->dim) {
        if (w->normal[ax] > 0)
            lo[ax] = w->point[ax], hi[ax] = w->point[ax] + t;
        else
            lo[ax] = w->point[ax] - t, hi[ax] = w->point[ax];
    }
}

/* ---- reference values and estimate ---------------------------------------------------- */

void lub_level_reference(int dim, double l0, lub_level *lev)
{
    /* re = 3.1 l0, the thesis' choice; lubFoam recomputes all three from the
     * effectiveRadius of system/schemes.yaml and writes them back with its time folders */
    lev->l0 = l0;
    lev->re = 3.1 * l0;
    lub_mps_reference(dim, l0, lev->re, &lev->n0, &lev->lambda0); /* (T-4, T-5) */
}

double lub_geometry_estimate(const lub_geometry *g)
{
    double total = 0.0, other = 1.0, taken = 0.0;
    for (int d = 1; d < g->dim; d++) other *= g->dmax[d] - g->dmin[d];
    for (int k = 0; k < g->nlevels; k++) {
        const lub_level_spec *s = &g->levels[k];
        double len;
        if (s->has_region) {
            len = fmax(0.0, fmin(s->xmax, g->dmax[0]) - fmax(s->xmin, g->dmin[0]));
            taken += len;
        } else {
            len = fmax(0.0, g->dmax[0] - g->dmin[0] - taken);
        }
        total += len * other / pow(s->l0, g->dim);
    }
    double l0 = g->levels[0].l0, layers = g->dummy_layers + 1.0;
    for (int i = 0; i < g->nwalls; i++) {
        const lub_wall *w = &g->walls[i];
        double ext = 0.0;
        for (int d = 0; d < g->dim; d++) ext = fmax(ext, g->dmax[d] - g->dmin[d]);
        switch (w->type) {
        case LUB_WALL_CYLINDER:
            if (g->dim == 3 && w->has_length) /* rings over the length, two flat ends */
                total += layers * (2 * M_PI * w->radius / l0 * (fmin(ext, w->length) / l0 + 1) +
                                   2 * fmin(M_PI * w->radius * w->radius, ext * ext) / (l0 * l0));
            else
                total += layers * 2 * M_PI * w->radius / l0 * (g->dim == 3 ? ext / l0 : 1.0);
            break;
        case LUB_WALL_SPHERE:
            total += layers * 4 * M_PI * w->radius * w->radius / (l0 * l0);
            break;
        case LUB_WALL_SEGMENT:
            total += layers * hypot(w->to[0] - w->from[0], w->to[1] - w->from[1]) / l0;
            break;
        case LUB_WALL_POLYGON:
            for (int j = 0; j < w->npts; j++)
                total += layers *
                         hypot(w->pts[2 * ((j + 1) % w->npts)] - w->pts[2 * j],
                               w->pts[2 * ((j + 1) % w->npts) + 1] - w->pts[2 * j + 1]) /
                         l0;
            break;
        case LUB_WALL_POLYLINE:
            for (int j = 0; j + 1 < w->npts; j++)
                total += layers *
                         hypot(w->pts[2 * j + 2] - w->pts[2 * j],
                               w->pts[2 * j + 3] - w->pts[2 * j + 1]) /
                         l0;
            break;
        default: /* on the lattice, or an inclined plane across the domain */
            total += layers * pow(ext / l0 * 1.5, g->dim - 1);
            break;
        }
    }
    return total;
}

static double machine_memory(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    return pages > 0 && size > 0 ? (double)pages * (double)size : INFINITY;
}

static void check_memory(const lub_geometry *g, double mem)
{
    if (mem <= 0) mem = machine_memory();
    double est = lub_geometry_estimate(g), need = est * LUB_GEN_BYTES_PER_PARTICLE;
    if (need <= mem && est < 4e9) return;
    char dom[256];
    if (g->dim == 2)
        snprintf(dom, sizeof dom, "[%g, %g] x [%g, %g]", g->dmin[0], g->dmax[0], g->dmin[1],
                 g->dmax[1]);
    else
        snprintf(dom, sizeof dom, "[%g, %g] x [%g, %g] x [%g, %g]", g->dmin[0], g->dmax[0],
                 g->dmin[1], g->dmax[1], g->dmin[2], g->dmax[2]);
    lub_node_error(g->levels[0].node,
                   "l0 = %g over the domain %s needs up to %.3g particles (%.3g GB), more "
                   "than the %.3g GB of memory; use a larger l0 or a smaller domain",
                   g->levels[0].l0, dom, est, need / 1e9, mem / 1e9);
}

/* ---- jitter: a disordered start -------------------------------------------------------- */

/* splitmix64's finaliser (Steele, Lea and Flood 2014): a bijective mix of 64 bits, used as a
 * counter-based generator, so that a fluid particle's displacement depends only on the seed
 * and its lattice indices (not on the order of generation or the size of the domain). */
static uint64_t mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* Move the fluid point x of lattice indices (a, b, e) by a displacement uniform in the disk
 * (ball) of radius jitter l0 (rejection from the square: draws outside the disk are drawn
 * again).  A periodic direction wraps; a displacement that leaves the domain or puts the
 * point behind a wall is drawn again too, and after 64 draws the point stays where it is.
 * The lattice point kept wallGap l0 from the wall particles, so the moved one keeps
 * (wallGap - jitter) l0. */
static void jitter_point(const gen_ctx *c, long a, long b, long e, double *x)
{
    const lub_geometry *g = c->g;
    const double r = g->jitter * g->levels[c->level].l0;
    uint64_t h = mix64(g->jitter_seed);
    h = mix64(h ^ (uint64_t)a);
    h = mix64(h ^ (uint64_t)b);
    h = mix64(h ^ (uint64_t)e);
    uint64_t k = 0;
    for (int draw = 0; draw < 64; draw++) {
        double d[3] = {0, 0, 0}, s2 = 0;
        for (int q = 0; q < g->dim; q++) {
            d[q] = 2.0 * (double)(mix64(h + k++) >> 11) * 0x1.0p-53 - 1.0;
            s2 += d[q] * d[q];
        }
        if (s2 > 1.0) continue;
        double y[3] = {x[0], x[1], x[2]};
        for (int q = 0; q < g->dim; q++) {
            y[q] += r * d[q];
            if (g->periodic[q]) {
                double L = g->dmax[q] - g->dmin[q];
                if (y[q] < g->dmin[q]) y[q] += L;
                if (y[q] >= g->dmax[q]) y[q] -= L;
            }
        }
        if (!in_domain(g, y, 0.0)) continue;
        int solid = 0;
        for (int w = 0; w < g->nwalls && !solid; w++)
            solid = lub_wall_behind(&g->walls[w], y, g->dim, 0.0);
        if (solid) continue;
        memcpy(x, y, sizeof y);
        return;
    }
}

/* ---- the whole generation ------------------------------------------------------------- */

/* The generation: every level in what it owns (only < 0), or level `only` in [xlo, xhi]
 * (walls generated over [xlo - pad, xhi + pad] so that the fluid keeps its gap from the
 * walls just outside the range, then cut to the range). */
/* The body-fitted fluid of the round walls with fluidLayers K: the surfaces k l0 out from
 * the wall (k = 1..K), sampled as its dummy layers are, into c->pts after the nw wall
 * points.  A point is kept where the lattice fluid would be (in a region, in the domain,
 * behind no wall, 0.999 wallGap l0 from every wall and dummy point) and as far from the
 * kept layers of the walls before; counted into rc. */
static void fluid_layers(gen_ctx *c, size_t nw, double h, size_t *rc)
{
    const lub_geometry *g = c->g;
    cell_grid cg;
    grid_build(&cg, g, &c->pts.p, nw, h);
    for (int i = 0; i < g->nwalls; i++) {
        const lub_wall *w = &g->walls[i];
        if (w->fluid_layers <= 0) continue;
        const size_t others = c->pts.n; /* the layers of the walls before end here */
        c->wall = i;
        for (int k = 0; k < g->nlevels; k++) {
            if (c->only >= 0 && k != c->only) continue;
            c->level = k;
            const size_t a = c->pts.n;
            if (w->type == LUB_WALL_SPHERE)
                sample_sphere(c, w, -w->fluid_layers, -1);
            else
                sample_cylinder(c, w, -w->fluid_layers, -1);
            const double l0 = g->levels[k].l0, tol = 1e-6 * l0, gap = 0.999 * g->wall_gap * l0;
            size_t m = a;
            for (size_t p = a; p < c->pts.n; p++) {
                const gen_pt q = c->pts.p[p];
                int keep = 0;
                for (int r = 0; r < g->nregions && !keep; r++)
                    keep = in_region(g, &g->regions[r], q.x, tol);
                for (int b = 0; b < g->nwalls && keep; b++)
                    keep = !lub_wall_behind(&g->walls[b], q.x, g->dim, tol);
                if (keep && gap > 0 && grid_find(&cg, q.x, gap, nw) >= 0) keep = 0;
                for (size_t o = nw; o < others && keep; o++) {
                    double s2 = 0;
                    for (int d = 0; d < g->dim; d++)
                        s2 += (c->pts.p[o].x[d] - q.x[d]) * (c->pts.p[o].x[d] - q.x[d]);
                    keep = s2 >= gap * gap;
                }
                if (!keep) continue;
                for (int r = 0; r < g->nregions; r++)
                    if (in_region(g, &g->regions[r], q.x, tol)) rc[r]++;
                c->pts.p[m++] = q;
            }
            c->pts.n = m;
        }
    }
    grid_free(&cg);
}

static void discretise(const lub_geometry *g, lub_particles *P, int only, double xlo, double xhi,
                       size_t *region_counts)
{
    gen_ctx c;
    memset(&c, 0, sizeof c);
    c.g = g;
    c.tol = 1e-6 * g->levels[0].l0;
    c.only = only;
    const double pad = only >= 0 ? (g->wall_gap + 1.0) * g->levels[only].l0 : 0.0;
    c.xlo = xlo - pad;
    c.xhi = xhi + pad;
    set_origins(&c);
    for (int i = 0; i < g->nwalls; i++) {
        const lub_wall *w = &g->walls[i];
        int ax = w->type == LUB_WALL_PLANE ? plane_axis(w) : -1;
        if (ax >= 0 && ax < g->dim) check_on_lattice(&c, w, ax, w->point[ax], "plane point");
        if (w->type == LUB_WALL_CYLINDER && w->has_length)
            for (int d = 0; d < 3; d++)
                if (fabs(fabs(w->axis[d]) - 1.0) < 1e-12)
                    for (int s = -1; s <= 1; s += 2)
                        check_on_lattice(&c, w, d, w->centre[d] + s * 0.5 * w->length, "end");
        for (int d = 0; d < g->dim && w->type == LUB_WALL_BOX; d++) {
            check_on_lattice(&c, w, d, w->min[d], "min");
            check_on_lattice(&c, w, d, w->max[d], "max");
        }
    }

    /* walls, level by level */
    for (int i = 0; i < g->nwalls; i++) {
        c.wall = i;
        size_t before = c.pts.n;
        for (int k = 0; k < g->nlevels; k++) {
            if (only >= 0 && k != only) continue;
            c.level = k;
            discretise_wall(&c, &g->walls[i]);
        }
        if (c.pts.n == before && only < 0)
            lub_warning("%s:%d: wall '%s' has no particles inside the domain",
                        lub_node_file(g->walls[i].node), lub_node_line(g->walls[i].node),
                        g->walls[i].name);
    }
    size_t nw = c.pts.n;

    /* duplicates (corners shared by lattice walls) are merged, a wall point winning over a
     * dummy; then a wall point that lies behind any wall (its own included, for merged
     * points) becomes a dummy: a wall particle is on a surface and faces the fluid */
    double lmax = g->levels[g->nlevels - 1].l0;
    double gapmax = 0.999 * g->wall_gap * lmax;
    cell_grid cg;
    grid_build(&cg, g, &c.pts.p, nw, fmax(lmax, gapmax));
    long *first = lub_malloc((nw ? nw : 1) * sizeof *first);
    for (size_t i = 0; i < nw; i++) {
        first[i] = grid_find(&cg, c.pts.p[i].x, 1e-6 * g->levels[c.pts.p[i].level].l0, i);
        /* keep the first; a wall point wins over a dummy at the same place */
        if (first[i] >= 0 && c.pts.p[i].kind == LUB_WALL) c.pts.p[first[i]].kind = LUB_WALL;
    }
    grid_free(&cg);
    size_t m = 0;
    for (size_t i = 0; i < nw; i++)
        if (first[i] < 0) c.pts.p[m++] = c.pts.p[i];
    free(first);
    nw = m;
    c.pts.n = m;
    for (size_t i = 0; i < nw; i++) {
        gen_pt *q = &c.pts.p[i];
        if (q->kind != LUB_WALL) continue;
        for (int b = 0; b < g->nwalls; b++)
            if (lub_wall_behind(&g->walls[b], q->x, g->dim, 1e-6 * g->levels[q->level].l0)) {
                q->kind = LUB_DUMMY;
                break;
            }
    }

    /* the body-fitted fluid of round walls, then the fluid on each level's lattice, which
     * keeps its distance from both */
    size_t *rc = lub_calloc(g->nregions ? (size_t)g->nregions : 1, sizeof *rc);
    c.xlo = xlo;
    c.xhi = xhi;
    if (g->nregions) fluid_layers(&c, nw, fmax(lmax, gapmax), rc);
    nw = c.pts.n;
    grid_build(&cg, g, &c.pts.p, nw, fmax(lmax, gapmax));
    for (int k = 0; k < g->nlevels && g->nregions; k++) {
        if (only >= 0 && k != only) continue;
        double l0 = g->levels[k].l0, tol = 1e-6 * l0, gap = 0.999 * g->wall_gap * l0;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int r = 0; r < g->nregions; r++) {
            double a[3], b[3];
            region_bbox(g, &g->regions[r], a, b);
            for (int d = 0; d < 3; d++) lo[d] = fmin(lo[d], a[d]), hi[d] = fmax(hi[d], b[d]);
        }
        if (only >= 0)
            lo[0] = fmax(lo[0], xlo), hi[0] = fmin(hi[0], xhi);
        else if (g->levels[k].has_region)
            lo[0] = fmax(lo[0], g->levels[k].xmin), hi[0] = fmin(hi[0], g->levels[k].xmax);
        long i0[3] = {0, 0, 0}, i1[3] = {0, 0, 0};
        for (int d = 0; d < g->dim; d++)
            lattice_span(&c, k, d, fmax(lo[d], g->dmin[d]), fmin(hi[d], g->dmax[d]), &i0[d],
                         &i1[d]);
        c.level = k;
        for (long a = i0[0]; a <= i1[0]; a++)
            for (long b = i0[1]; b <= i1[1]; b++)
                for (long e = i0[2]; e <= i1[2]; e++) {
                    double x[3] = {c.origin[k][0] + a * l0, c.origin[k][1] + b * l0,
                                   g->dim == 3 ? c.origin[k][2] + e * l0 : 0.0};
                    if (!takes(&c, x[0]) || !in_domain(g, x, c.tol)) continue;
                    int inside = 0;
                    for (int r = 0; r < g->nregions; r++)
                        if (in_region(g, &g->regions[r], x, tol)) inside = 1;
                    if (!inside) continue;
                    int solid = 0;
                    for (int w = 0; w < g->nwalls && !solid; w++)
                        solid = lub_wall_behind(&g->walls[w], x, g->dim, tol);
                    if (solid) continue;
                    if (gap > 0 && grid_find(&cg, x, gap, nw) >= 0) continue;
                    for (int r = 0; r < g->nregions; r++)
                        if (in_region(g, &g->regions[r], x, tol)) rc[r]++;
                    if (g->jitter > 0 && only < 0) jitter_point(&c, a, b, e, x);
                    push(&c, x, LUB_FLUID);
                }
    }
    grid_free(&cg);
    for (int r = 0; r < g->nregions && only < 0; r++)
        if (rc[r] == 0) {
            const lub_region *rg = &g->regions[r];
            char what[256];
            if (rg->type == LUB_REGION_LAYER)
                snprintf(what, sizeof what, "layer of %g on wall '%s'", rg->thickness,
                         g->walls[rg->wall].name);
            else if (rg->type == LUB_REGION_BETWEEN)
                snprintf(what, sizeof what, "between '%s' and '%s' up to %g",
                         g->walls[rg->lower].name, g->walls[rg->upper].name, rg->height);
            else
                snprintf(what, sizeof what, "box [%g, %g] x [%g, %g]%s", rg->min[0], rg->max[0],
                         rg->min[1], rg->max[1], g->dim == 3 ? " x ..." : "");
            free(rc);
            free(c.pts.p);
            lub_node_error(rg->node,
                           "fluid region %d (%s) has no particles: it lies outside the domain, "
                           "inside a wall, or closer than wallGap = %g l0 (l0 = %g) to the "
                           "wall particles",
                           r, what, g->wall_gap, g->levels[0].l0);
        }
    if (region_counts) memcpy(region_counts, rc, (size_t)g->nregions * sizeof *rc);
    free(rc);

    /* into P: walls and dummies first (in wall order), then the fluid */
    lub_particles_init(P, g->dim, c.pts.n);
    for (int i = 0; i < g->nwalls; i++) lub_particles_patch(P, g->walls[i].name);
    P->nlevels = g->nlevels;
    for (int k = 0; k < g->nlevels; k++)
        lub_level_reference(g->dim, g->levels[k].l0, &P->levels[k]);
    for (size_t i = 0; i < c.pts.n; i++) {
        const gen_pt *q = &c.pts.p[i];
        if (only >= 0 && !(q->x[0] >= xlo && q->x[0] <= xhi)) continue; /* padding */
        lub_particles_add(P, q->x, q->kind, q->kind == LUB_FLUID ? 0 : q->wall, q->level);
    }
    free(c.pts.p);
}

void lub_geometry_discretise(const lub_geometry *g, lub_particles *P, double mem_bytes,
                             size_t *region_counts)
{
    check_memory(g, mem_bytes);
    discretise(g, P, -1, 0.0, 0.0, region_counts);
}

void lub_geometry_discretise_range(const lub_geometry *g, int level, double xlo, double xhi,
                                   lub_particles *P)
{
    if (level < 0 || level >= g->nlevels || !(xlo <= xhi))
        lub_bug("discretise_range: level %d of %d, x in [%g, %g]", level, g->nlevels, xlo, xhi);
    discretise(g, P, level, xlo, xhi, NULL);
}
