/* lubkit model rigidBodies: solid bodies moved by the fluid (methods.md §7; issue 30).
 *
 *     rigidBodies:
 *       roller:                          # the body's name (its table, log and state)
 *         patch:    cylinder             # a wall of system/particleGenDict.yaml: a 2-D
 *                                        #   cylinder, a polygon, a 3-D sphere (a cylinder
 *                                        #   with the fluid inside, a housing: held only)
 *         density:  7850                 # [kg/m^3]
 *         velocity: [0.475, 0]           # initial V [m/s] (default 0)
 *         omega:    -38                  # initial angular velocity [rad/s] (3-D: a vector)
 *         hold:     [y, rotation]        # held velocity components (x, y, z, rotation)
 *         load:     { force: [0, -10], torque: 0 }              # applied [N/m, N in 2-D]
 *         spring:   { stiffness: 1e3, damping: 0, anchor: [0, 0] }
 *         contact:  { walls: [plate], stiffness: 1e6, friction: 0.3,
 *                     tangentialStiffness: 2.9e5, dampingRatio: 0.3, distance: 0,
 *                     bodies: [ball2] }      # other bodies (circles, spheres) it touches,
 *                                            #   with these parameters; walls: optional then
 *
 * The body (models/rigidBodies/body.h: its equations, constraints and contact) has the mass,
 * centre and inertia of the wall's shape, not of its particles: a particle sum misses
 * m l0^2/6 per cell of the inertia and puts the surface half a layer off (methods.md §7).
 * Gravity is the scene's (the configuration's g and the other models' forces).
 *
 * Every step (explicit coupling, as seed 003 S): before the fluid's step the body moves from
 * t to t + dt under the fluid's force and torque of the last step (frozen), and every wall
 * and dummy particle of its patch takes the velocity (x_target - x)/dt that brings it to
 * x_target = x_G + R (x0 - x_G0) at the end of the step (mps.h patch_moved: the step moves
 * it, the viscous step sees it; the chord velocity, the mean over the step).  After the
 * step the particles are put exactly on x_target (no drift of round-off), their velocity
 * set to V + omega x (x - x_G), and the force and torque the fluid exerted in the step are
 * taken from the formulation (models/fluid.h wall_forces: with mps, the wall pressure over
 * the body's surface and the reaction of the viscous terms, fluid/mps.c; with mph, the
 * reaction of the pair forces of (K-6) and of surface tension, fluid/mph.c, which makes
 * fluid + body conserve momentum and angular momentum to round-off):
 *
 *     F = sum_{i in patch} f_i,   T = sum_{i in patch} (x_i - x_G) x f_i.
 *
 * The offsets x0 - x_G0 (body frame) are the particle fields rigidX0, rigidY0 (rigidZ0),
 * so that they travel with the particles and their files; the body's state (x_G, q or theta,
 * V, omega, the fluid's F and T of the last step, the contacts' tangential springs) is its
 * entry of uniform/state.yaml (%.17g): a restart repeats the uninterrupted run exactly.
 *
 * What the MPS step assumes of wall particles, and how a body meets it: they move in step 3
 * with their velocity and are not corrected (mps.h patch_moved keeps the velocity given here);
 * the neighbour lists follow them (kept while no particle moved more than half the skin since
 * the build, the snap after the step included, which is round-off); a wall particle of the
 * body above the free surface takes the open-side test with its dummies behind it (step.c
 * free_surface) and gets p = 0 there, which the surface integral then counts as nothing;
 * lub_mps_check's test of a fluid particle through a wall takes the positions before the step
 * as r - u dt, which the chord velocity makes exact for the body's particles.  The
 * multi-resolution driver's still walls are refused (check).
 *
 * One resolution level only; a body must not cross a periodic side (its particles would be
 * wrapped apart).  Light bodies (rho_s below about rho_f) make the explicit coupling
 * unstable (added mass, methods.md §7). */
#include <errno.h>
#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "io/table.h"
#include "models/model.h"
#include "models/rigidBodies/body.h"

#define MAX_BODIES      LUB_BODY_MAX_BODIES
#define STEPS_PER_CYCLE 20.0 /* time steps per period of the contact (RK4: 1e-4 per period) */

static const char *const offset_field[3] = {"rigidX0", "rigidY0", "rigidZ0"};

enum { SHAPE_CIRCLE, SHAPE_SPHERE, SHAPE_POLYGON, SHAPE_HOUSING };

typedef struct {
    char name[LUB_NAME_MAX];
    int patch;
    int shape;
    double *poly; /* polygon vertices relative to x_G0 (body frame), counter-clockwise */
    int npts;
    double density;
    double ds; /* circle, sphere: the surface per wall particle */
    lub_body b;
    lub_body_state s;
    double F[3], T[3]; /* the fluid's force and torque of the last step (world) */
    lub_node *contact_node;
    int nwall; /* wall particles of the patch */
    FILE *table;
} rigid_body;

typedef struct {
    int n;
    rigid_body body[MAX_BODIES];
    int npairs; /* contacts between bodies: pair[k].a lists pair[k].b in its contact */
    lub_body_pair pair[LUB_BODY_MAX_PAIRS];
    double xi[LUB_BODY_MAX_PAIRS][3]; /* their tangential springs */
    lub_node *pair_node[LUB_BODY_MAX_PAIRS];
    double zeta[MAX_BODIES]; /* each body's contact damping ratio */
    lub_mps *level;
    double *area[3], *f[3]; /* work arrays (P->cap), allocated once */
    int checked;            /* the contact's period checked against dt */
} rigid;

static void pick_wall(rigid_body *rb, lub_node *patch_node, const lub_geometry *g, int dim)
{
    int w = lub_geometry_find_wall(g, lub_node_text(patch_node));
    if (w < 0)
        lub_node_error(patch_node, "rigidBodies: '%s' is not a wall of the geometry",
                       lub_node_text(patch_node));
    const lub_wall *wl = &g->walls[w];
    if (wl->type == LUB_WALL_CYLINDER && dim == 2 && !wl->fluid_inside && !wl->has_range)
        rb->shape = SHAPE_CIRCLE;
    else if (wl->type == LUB_WALL_SPHERE && !wl->fluid_inside)
        rb->shape = SHAPE_SPHERE;
    else if (wl->type == LUB_WALL_POLYGON)
        rb->shape = SHAPE_POLYGON;
    else if (wl->type == LUB_WALL_CYLINDER && dim == 2 && !wl->has_range)
        rb->shape = SHAPE_HOUSING; /* fluid inside: held only (rigid_read) */
    else
        lub_node_error(patch_node,
                       "rigidBodies: wall '%s' is not a closed body: expected a 2-D cylinder "
                       "(no range), a polygon or a 3-D sphere (fluid outside)",
                       wl->name);
    double rho = rb->density, c[2];
    switch (rb->shape) {
    case SHAPE_HOUSING: /* its mass and inertia are those of the disc it encloses (unused) */
    case SHAPE_CIRCLE:
        lub_body_circle(&rb->b, rho, wl->radius);
        memcpy(rb->s.x, wl->centre, sizeof rb->s.x);
        break;
    case SHAPE_SPHERE:
        lub_body_sphere(&rb->b, rho, wl->radius);
        memcpy(rb->s.x, wl->centre, sizeof rb->s.x);
        break;
    default:
        lub_body_polygon(&rb->b, rho, wl->pts, wl->npts, c);
        rb->s.x[0] = c[0], rb->s.x[1] = c[1], rb->s.x[2] = 0.0;
        rb->npts = wl->npts;
        rb->poly = lub_malloc(2 * (size_t)wl->npts * sizeof(double));
        for (int k = 0; k < wl->npts; k++)
            rb->poly[2 * k] = wl->pts[2 * k] - c[0],
                         rb->poly[2 * k + 1] = wl->pts[2 * k + 1] - c[1];
    }
}

static void read_contact(rigid_body *rb, lub_node *e, const lub_geometry *g, int dim, double *zeta)
{
    lub_body *b = &rb->b;
    rb->contact_node = e;
    lub_node_expect_map(e);
    /* plane walls, or other bodies (read_pairs), or both */
    lub_node *walls =
        lub_dict_has(e, "bodies") ? lub_dict_seq_or(e, "walls") : lub_dict_seq(e, "walls");
    size_t nw = walls ? lub_node_size(walls) : 0;
    if ((walls && nw == 0) || nw > LUB_BODY_MAX_PLANES)
        lub_node_error(walls, "rigidBodies: contact walls: 1 to %d plane walls, found %zu",
                       LUB_BODY_MAX_PLANES, nw);
    if (rb->shape == SHAPE_POLYGON)
        lub_node_error(e, "rigidBodies: contact of a polygon body is not implemented (a 2-D "
                          "cylinder or a sphere)");
    for (size_t k = 0; k < nw; k++) {
        lub_node *it = lub_node_item(walls, k);
        int w = lub_geometry_find_wall(g, lub_node_text(it));
        if (w < 0)
            lub_node_error(it, "rigidBodies: '%s' is not a wall of the geometry",
                           lub_node_text(it));
        if (g->walls[w].type != LUB_WALL_PLANE)
            lub_node_error(it, "rigidBodies: contact with wall '%s': only plane walls",
                           lub_node_text(it));
        memcpy(b->plane[k].point, g->walls[w].point, sizeof b->plane[k].point);
        memcpy(b->plane[k].normal, g->walls[w].normal, sizeof b->plane[k].normal);
    }
    (void)dim;
    b->nplanes = (int)nw;
    b->kn = lub_dict_real(e, "stiffness", LUB_POSITIVE);
    b->kt = lub_dict_real_or(e, "tangentialStiffness", 2.0 / 7.0 * b->kn, LUB_NONNEGATIVE);
    b->mu = lub_dict_real(e, "friction", LUB_NONNEGATIVE);
    b->distance = lub_dict_real_or(e, "distance", 0.0, LUB_NONNEGATIVE);
    *zeta = lub_dict_real_or(e, "dampingRatio", 0.3, LUB_NONNEGATIVE);
    lub_body_contact_damping(b, *zeta);
}

/* The contacts between bodies: each body's `contact: { bodies: [...] }`, with its parameters
 * (read after every body, for the names and the masses). */
static void read_pairs(rigid *r)
{
    for (int k = 0; k < r->n; k++) {
        rigid_body *rb = &r->body[k];
        lub_node *list = rb->contact_node ? lub_dict_seq_or(rb->contact_node, "bodies") : NULL;
        for (size_t i = 0; list && i < lub_node_size(list); i++) {
            lub_node *it = lub_node_item(list, i);
            const char *name = lub_node_text(it);
            int o = -1;
            for (int j = 0; j < r->n; j++)
                if (!strcmp(r->body[j].name, name)) o = j;
            if (o < 0 || o == k)
                lub_node_error(it, "rigidBodies: body '%s': contact with '%s': %s", rb->name, name,
                               o < 0 ? "no such body" : "itself");
            if (r->body[o].shape != SHAPE_CIRCLE && r->body[o].shape != SHAPE_SPHERE)
                lub_node_error(it,
                               "rigidBodies: body '%s': contact with '%s': only between circles "
                               "or spheres",
                               rb->name, name);
            for (int q = 0; q < r->npairs; q++)
                if ((r->pair[q].a == k && r->pair[q].b == o) ||
                    (r->pair[q].a == o && r->pair[q].b == k))
                    lub_node_error(it,
                                   "rigidBodies: the contact of '%s' and '%s' is listed twice "
                                   "(once is enough: it acts on both)",
                                   rb->name, name);
            if (r->npairs == LUB_BODY_MAX_PAIRS)
                lub_node_error(it, "rigidBodies: at most %d contacts between bodies",
                               LUB_BODY_MAX_PAIRS);
            lub_body_pair *p = &r->pair[r->npairs];
            p->a = k, p->b = o;
            p->kn = rb->b.kn, p->kt = rb->b.kt, p->mu = rb->b.mu, p->distance = rb->b.distance;
            r->pair_node[r->npairs++] = it;
        }
    }
}

static void read_body(rigid_body *rb, const char *name, lub_node *e, lub_scene *s, double *zeta)
{
    const int dim = s->P->dim;
    lub_node_expect_map(e);
    snprintf(rb->name, sizeof rb->name, "%s", name);
    rb->b.dim = dim;
    rb->s.q[0] = 1.0;
    lub_node *pn = lub_dict_get(e, "patch");
    const char *patch = lub_node_text(pn);
    rb->patch = lub_particles_find_patch(s->P, patch);
    if (rb->patch < 0) lub_node_error(pn, "rigidBodies: the particles have no patch '%s'", patch);
    rb->density = lub_dict_real(e, "density", LUB_POSITIVE);
    pick_wall(rb, pn, s->geo, dim);
    lub_dict_vec_or(e, "velocity", rb->s.V, dim, dim, LUB_ANY);
    if (dim == 2)
        rb->s.omega[2] = lub_dict_real_or(e, "omega", 0.0, LUB_ANY);
    else
        lub_dict_vec_or(e, "omega", rb->s.omega, 3, 3, LUB_ANY);
    lub_node *hold = lub_dict_seq_or(e, "hold");
    static const char *const words3[] = {"x", "y", "z", "rotation", NULL};
    static const char *const words2[] = {"x", "y", "rotation", NULL};
    for (size_t k = 0; hold && k < lub_node_size(hold); k++) {
        lub_node *it = lub_node_item(hold, k);
        const char *wd = lub_node_text(it);
        const char *const *words = dim == 2 ? words2 : words3;
        int found = -1;
        for (int a = 0; words[a]; a++)
            if (!strcmp(wd, words[a])) found = a;
        if (found < 0)
            lub_node_error(it, "rigidBodies: hold: expected %s, found '%s'",
                           dim == 2 ? "x, y or rotation" : "x, y, z or rotation", wd);
        rb->b.hold[dim == 2 && found == 2 ? 3 : found] = 1;
    }
    lub_node *load = lub_dict_map_or(e, "load");
    if (load) {
        lub_dict_vec_or(load, "force", rb->b.load, dim, dim, LUB_ANY);
        if (dim == 2)
            rb->b.load_torque[2] = lub_dict_real_or(load, "torque", 0.0, LUB_ANY);
        else
            lub_dict_vec_or(load, "torque", rb->b.load_torque, 3, 3, LUB_ANY);
    }
    lub_node *spring = lub_dict_map_or(e, "spring");
    memcpy(rb->b.anchor, rb->s.x, sizeof rb->b.anchor);
    if (spring) {
        rb->b.spring_k = lub_dict_real(spring, "stiffness", LUB_NONNEGATIVE);
        rb->b.spring_c = lub_dict_real_or(spring, "damping", 0.0, LUB_NONNEGATIVE);
        lub_dict_vec_or(spring, "anchor", rb->b.anchor, dim, dim, LUB_ANY);
    }
    lub_node *contact = lub_dict_map_or(e, "contact");
    if (contact) read_contact(rb, contact, s->geo, dim, zeta);
    if (rb->shape == SHAPE_HOUSING && !(rb->b.hold[0] && rb->b.hold[1] && rb->b.hold[3]))
        lub_node_error(pn,
                       "rigidBodies: wall '%s' holds the fluid inside (a housing): it can only "
                       "be held (hold: [x, y, rotation]; with omega, a prescribed rotation)",
                       patch);
}

static void rigid_read(lub_model *m, lub_scene *s)
{
    rigid *r = m->state;
    lub_node_expect_map(m->entry);
    size_t n = lub_node_size(m->entry);
    if (n == 0 || n > MAX_BODIES)
        lub_node_error(m->entry, "rigidBodies: 1 to %d bodies, found %zu", MAX_BODIES, n);
    if (!s->geo)
        lub_node_error(m->entry, "rigidBodies: needs the geometry (system/particleGenDict.yaml)");
    r->n = (int)n;
    for (size_t k = 0; k < n; k++) {
        read_body(&r->body[k], lub_node_key_at(m->entry, k), lub_node_value_at(m->entry, k), s,
                  &r->zeta[k]);
        for (size_t j = 0; j < k; j++)
            if (r->body[j].patch == r->body[k].patch)
                lub_node_error(lub_node_value_at(m->entry, k),
                               "rigidBodies: patch '%s' belongs to body '%s' already",
                               s->P->patch_names[r->body[k].patch], r->body[j].name);
    }
    read_pairs(r);
    /* the pairs' damping from the masses of both (every body read) */
    lub_body b[MAX_BODIES];
    for (int k = 0; k < r->n; k++) b[k] = r->body[k].b;
    for (int q = 0; q < r->npairs; q++)
        lub_body_pair_damping(&r->pair[q], b, r->zeta[r->pair[q].a]);
}

static void rigid_check(lub_model *m, lub_scene *s)
{
    if (s->driver)
        lub_node_error(m->entry, "rigidBodies: not with %s (one resolution level only)",
                       s->driver->type->name);
    if (!s->fluid->wall_forces)
        lub_node_error(m->entry, "rigidBodies: the fluid '%s' gives no force on walls",
                       s->fluid->name);
}

static void rigid_configure(lub_model *m, lub_scene *s, lub_mps_config *c)
{
    (void)s;
    const rigid *r = m->state;
    for (int k = 0; k < r->n; k++) c->patch_moved[r->body[k].patch] = 1;
    for (int k = 0; k < r->n; k++) c->patch_rigid[r->body[k].patch] = 1;
}

/* the body-frame offset of particle i into r0, its world offset R r0 into r */
static void offset(const lub_particles *P, double *const x0[3], const double R[3][3], size_t i,
                   double r[3])
{
    double r0[3] = {x0[0][i], x0[1][i], P->dim == 3 ? x0[2][i] : 0.0};
    for (int a = 0; a < 3; a++) r[a] = R[a][0] * r0[0] + R[a][1] * r0[1] + R[a][2] * r0[2];
}

static void fields(lub_particles *P, double *x0[3])
{
    x0[2] = NULL;
    for (int d = 0; d < P->dim; d++) x0[d] = lub_particles_find_extra(P, offset_field[d]);
}

static void vec_entry(lub_node *st, const char *key, double *out, int n)
{
    lub_dict_vec(st, key, out, n, n, LUB_ANY);
}

static void rigid_init(lub_model *m, lub_scene *s)
{
    rigid *r = m->state;
    r->level = s->level[0];
    lub_particles *P = r->level->P;
    const int dim = P->dim;
    for (int d = 0; d < 3; d++) {
        r->area[d] = lub_calloc(P->cap, sizeof(double));
        r->f[d] = lub_calloc(P->cap, sizeof(double));
    }
    /* gravity: the configuration's and the other models' body accelerations */
    double g[3] = {0, 0, 0};
    if (r->level->c.gravity) memcpy(g, r->level->c.g, sizeof g);
    for (int k = 0; k < s->nmodels; k++)
        if (&s->model[k] != m && s->model[k].type->forces)
            s->model[k].type->forces(&s->model[k], r->level, 0.0, g);
    lub_node *st = lub_dict_map_or(s->state, "rigidBodies");
    int fresh = lub_particles_find_extra(P, offset_field[0]) == NULL;
    if (!fresh && !st)
        lub_fatal("%s: the particles carry rigidX0 but the state has no rigidBodies entry",
                  s->state_path);
    double *x0[3];
    for (int d = 0; d < dim; d++) lub_particles_extra(P, offset_field[d]);
    fields(P, x0);
    for (int k = 0; k < r->n; k++) {
        rigid_body *rb = &r->body[k];
        memcpy(rb->b.g, g, sizeof g);
        lub_node *bs = st ? lub_dict_map_or(st, rb->name) : NULL;
        if (st && !bs) lub_fatal("%s: rigidBodies: no state of body '%s'", s->state_path, rb->name);
        rb->nwall = 0;
        for (size_t i = 0; i < P->n; i++) {
            if (P->kind[i] == LUB_FLUID || P->patch[i] != rb->patch) continue;
            rb->nwall += P->kind[i] == LUB_WALL;
            if (fresh)
                for (int d = 0; d < dim; d++) x0[d][i] = P->x[d][i] - rb->s.x[d];
        }
        if (rb->nwall == 0)
            lub_fatal("rigidBodies: body '%s': its patch has no wall particles", rb->name);
        if (rb->shape == SHAPE_CIRCLE) rb->ds = 2.0 * M_PI * rb->b.radius / rb->nwall;
        if (rb->shape == SHAPE_HOUSING) rb->ds = -2.0 * M_PI * rb->b.radius / rb->nwall;
        if (rb->shape == SHAPE_SPHERE)
            rb->ds = 4.0 * M_PI * rb->b.radius * rb->b.radius / rb->nwall;
        if (bs) {
            vec_entry(bs, "x", rb->s.x, dim);
            vec_entry(bs, "V", rb->s.V, dim);
            vec_entry(bs, "F", rb->F, dim);
            if (dim == 2) {
                rb->s.angle = lub_dict_real(bs, "angle", LUB_ANY);
                rb->s.omega[2] = lub_dict_real(bs, "omega", LUB_ANY);
                rb->T[2] = lub_dict_real(bs, "T", LUB_ANY);
                rb->s.q[0] = cos(0.5 * rb->s.angle), rb->s.q[3] = sin(0.5 * rb->s.angle);
            } else {
                vec_entry(bs, "q", rb->s.q, 4);
                vec_entry(bs, "omega", rb->s.omega, 3);
                vec_entry(bs, "T", rb->T, 3);
            }
            lub_node *xi = lub_dict_seq_or(bs, "xi");
            size_t nx = xi ? lub_node_size(xi) : 0;
            if (nx != (size_t)rb->b.nplanes && (xi || rb->b.nplanes))
                lub_fatal("%s: rigidBodies: body '%s': %zu tangential springs, expected %d",
                          s->state_path, rb->name, nx, rb->b.nplanes);
            for (size_t p = 0; p < nx; p++) {
                lub_node *it = lub_node_item(xi, p);
                if (lub_node_size(it) != 3)
                    lub_node_error(it, "rigidBodies: xi: expected 3 numbers");
                for (int d = 0; d < 3; d++)
                    rb->s.xi[p][d] = lub_node_real(lub_node_item(it, (size_t)d), LUB_ANY);
            }
            lub_node *xb = lub_dict_seq_or(bs, "xiBodies");
            size_t nb = xb ? lub_node_size(xb) : 0, got = 0;
            for (int q = 0; q < r->npairs; q++) {
                if (r->pair[q].a != k) continue;
                if (got >= nb)
                    lub_fatal("%s: rigidBodies: body '%s': too few xiBodies for its contacts",
                              s->state_path, rb->name);
                lub_node *it = lub_node_item(xb, got++);
                if (lub_node_size(it) != 3)
                    lub_node_error(it, "rigidBodies: xiBodies: expected 3 numbers");
                for (int d = 0; d < 3; d++)
                    r->xi[q][d] = lub_node_real(lub_node_item(it, (size_t)d), LUB_ANY);
            }
            if (got != nb)
                lub_fatal("%s: rigidBodies: body '%s': %zu xiBodies, expected %zu", s->state_path,
                          rb->name, nb, got);
        }
    }
}

/* the outward area vector of wall particle i of body rb (world frame) */
static void area_vector(const rigid_body *rb, const double R[3][3], const double r0[3],
                        const double r[3], double l0, double a[3])
{
    a[0] = a[1] = a[2] = 0.0;
    if (rb->shape != SHAPE_POLYGON) { /* a housing's ds < 0: its normal points inwards */
        const double len = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        for (int d = 0; d < 3; d++) a[d] = rb->ds * r[d] / len;
        return;
    }
    /* on an edge: its outward normal times its particle spacing (particleGen: round(length /
     * l0) equal steps); at a corner half of each of the two edges' */
    double ab[2] = {0, 0};
    for (int k = 0; k < rb->npts; k++) {
        const double *p = rb->poly + 2 * k, *q = rb->poly + 2 * ((k + 1) % rb->npts);
        const double ex = q[0] - p[0], ey = q[1] - p[1], len = hypot(ex, ey);
        const double t = ((r0[0] - p[0]) * ex + (r0[1] - p[1]) * ey) / (len * len);
        const double dist = fabs((r0[0] - p[0]) * ey - (r0[1] - p[1]) * ex) / len;
        if (dist > 1e-6 * l0 || t < -1e-6 || t > 1 + 1e-6) continue;
        double steps = fmax(1.0, round(len / l0));
        const double w = (t < 1e-6 || t > 1 - 1e-6 ? 0.5 : 1.0) * len / steps;
        ab[0] += w * ey / len, ab[1] += -w * ex / len;
    }
    for (int d = 0; d < 2; d++) a[d] = R[d][0] * ab[0] + R[d][1] * ab[1];
}

static lub_step_status rigid_before_step(lub_model *m, lub_scene *s, double t, double dt, char *msg,
                                         size_t msgsize)
{
    (void)s, (void)t, (void)msg, (void)msgsize;
    rigid *r = m->state;
    lub_particles *P = r->level->P;
    if (!r->checked) {
        r->checked = 1;
        for (int k = 0; k < r->n; k++) {
            const lub_body *b = &r->body[k].b;
            const double lim = lub_body_dt_limit(b, STEPS_PER_CYCLE);
            if (dt > lim)
                lub_node_error(r->body[k].contact_node,
                               "rigidBodies: body '%s': the contact's period (normal 2 pi "
                               "sqrt(M/k) or tangential) is %g s, resolved by dt = %g s only "
                               "with stiffness <= %g (tangentialStiffness <= %g): %g steps "
                               "per period needed, or deltaT <= %g s",
                               r->body[k].name, lim * STEPS_PER_CYCLE, dt,
                               b->kn * (lim / dt) * (lim / dt), b->kt * (lim / dt) * (lim / dt),
                               STEPS_PER_CYCLE, lim);
        }
        lub_body b[MAX_BODIES];
        for (int k = 0; k < r->n; k++) b[k] = r->body[k].b;
        for (int q = 0; q < r->npairs; q++) {
            const lub_body_pair *p = &r->pair[q];
            const double lim = lub_body_pair_dt_limit(p, b, STEPS_PER_CYCLE);
            if (dt > lim)
                lub_node_error(r->pair_node[q],
                               "rigidBodies: the contact of '%s' and '%s': its period (normal 2 "
                               "pi sqrt(m/k), m = 1/(1/M_a + 1/M_b), or tangential) is %g s, "
                               "resolved by dt = %g s only with stiffness <= %g "
                               "(tangentialStiffness <= %g): %g steps per period needed, or "
                               "deltaT <= %g s",
                               r->body[p->a].name, r->body[p->b].name, lim * STEPS_PER_CYCLE, dt,
                               p->kn * (lim / dt) * (lim / dt), p->kt * (lim / dt) * (lim / dt),
                               STEPS_PER_CYCLE, lim);
        }
    }
    /* all bodies together: the contacts between them act at every Runge-Kutta stage */
    lub_body b[MAX_BODIES];
    lub_body_state st[MAX_BODIES];
    double F[MAX_BODIES][3], T[MAX_BODIES][3];
    for (int k = 0; k < r->n; k++) {
        b[k] = r->body[k].b, st[k] = r->body[k].s;
        memcpy(F[k], r->body[k].F, sizeof F[k]);
        memcpy(T[k], r->body[k].T, sizeof T[k]);
    }
    lub_bodies_step(r->n, b, st, (const double(*)[3])F, (const double(*)[3])T, r->npairs, r->pair,
                    r->xi, dt);
    double *x0[3];
    fields(P, x0);
    for (int k = 0; k < r->n; k++) {
        rigid_body *rb = &r->body[k];
        rb->s = st[k];
        double R[3][3];
        lub_body_rotation(&rb->b, &rb->s, R);
        for (size_t i = 0; i < P->n; i++) {
            if (P->kind[i] == LUB_FLUID || P->patch[i] != rb->patch) continue;
            double o[3];
            offset(P, x0, R, i, o);
            for (int d = 0; d < P->dim; d++) P->u[d][i] = (rb->s.x[d] + o[d] - P->x[d][i]) / dt;
        }
    }
    return LUB_STEP_OK;
}

static void rigid_after_step(lub_model *m, lub_scene *s, double t)
{
    (void)t;
    rigid *r = m->state;
    lub_mps *f = r->level;
    lub_particles *P = f->P;
    const int dim = P->dim;
    double *x0[3];
    fields(P, x0);
    for (int k = 0; k < r->n; k++) {
        rigid_body *rb = &r->body[k];
        double R[3][3];
        lub_body_rotation(&rb->b, &rb->s, R);
        /* the fluid's force, on the particles where the step left them */
        for (size_t i = 0; i < P->n; i++) {
            for (int d = 0; d < 3; d++) r->area[d][i] = 0.0;
            if (P->kind[i] != LUB_WALL || P->patch[i] != rb->patch) continue;
            double o[3], r0[3] = {x0[0][i], x0[1][i], dim == 3 ? x0[2][i] : 0.0}, a[3];
            offset(P, x0, R, i, o);
            area_vector(rb, R, r0, o, f->l0, a);
            for (int d = 0; d < 3; d++) r->area[d][i] = a[d];
        }
        double w[3];
        lub_body_omega_world(&rb->b, &rb->s, w);
        s->fluid->wall_forces(f, rb->patch, r->area, w, r->f);
        double F[3] = {0, 0, 0}, T[3] = {0, 0, 0};
        for (size_t i = 0; i < P->n; i++) {
            if (P->kind[i] == LUB_FLUID || P->patch[i] != rb->patch) continue;
            double o[3], fi[3] = {r->f[0][i], r->f[1][i], dim == 3 ? r->f[2][i] : 0.0}, u[3];
            offset(P, x0, R, i, o);
            F[0] += fi[0], F[1] += fi[1], F[2] += fi[2];
            T[0] += o[1] * fi[2] - o[2] * fi[1];
            T[1] += o[2] * fi[0] - o[0] * fi[2];
            T[2] += o[0] * fi[1] - o[1] * fi[0];
            /* exactly on the body, with its velocity now */
            lub_body_point_velocity(&rb->b, &rb->s, o, u);
            for (int d = 0; d < dim; d++) {
                P->x[d][i] = rb->s.x[d] + o[d];
                P->u[d][i] = u[d];
            }
        }
        memcpy(rb->F, F, sizeof F);
        memcpy(rb->T, T, sizeof T);
    }
}

static void rigid_describe(const lub_model *m, const lub_scene *s, char *buf, size_t size)
{
    const rigid *r = m->state;
    size_t len = (size_t)snprintf(buf, size, "rigidBodies (");
    for (int k = 0; k < r->n && len < size; k++)
        len += (size_t)snprintf(buf + len, size - len, "%s%s on %s", k ? ", " : "", r->body[k].name,
                                s->P->patch_names[r->body[k].patch]);
    if (len < size) snprintf(buf + len, size - len, ")");
}

static void rigid_header(const lub_model *m, const lub_scene *s)
{
    const rigid *r = m->state;
    const int dim = s->P->dim;
    static const char *const shape[] = {"circle", "sphere", "polygon", "housing"};
    for (int k = 0; k < r->n; k++) {
        const rigid_body *rb = &r->body[k];
        const lub_body *b = &rb->b;
        char hold[64] = "";
        static const char *const hn[] = {"x", "y", "z", "rotation"};
        for (int a = 0; a < 4; a++)
            if (b->hold[a]) snprintf(hold + strlen(hold), sizeof hold - strlen(hold), " %s", hn[a]);
        if (dim == 2)
            lub_message("rigidBodies: %s: %s %s, density %g kg/m^3, M %.6g kg/m, I %.6g kg m, "
                        "centre (%.9g, %.9g) m, %d wall particles%s%s",
                        rb->name, shape[rb->shape], s->P->patch_names[rb->patch], rb->density,
                        b->mass, b->inertia[2], rb->s.x[0], rb->s.x[1], rb->nwall,
                        hold[0] ? "; held:" : "", hold);
        else
            lub_message("rigidBodies: %s: %s %s, density %g kg/m^3, M %.6g kg, I (%.6g, %.6g, "
                        "%.6g) kg m^2, centre (%.9g, %.9g, %.9g) m, %d wall particles%s%s",
                        rb->name, shape[rb->shape], s->P->patch_names[rb->patch], rb->density,
                        b->mass, b->inertia[0], b->inertia[1], b->inertia[2], rb->s.x[0],
                        rb->s.x[1], rb->s.x[2], rb->nwall, hold[0] ? "; held:" : "", hold);
        if (b->nplanes)
            lub_message("rigidBodies: %s: contact with %d plane(s): k_n %g, k_t %g, c_n %g, c_t "
                        "%g, friction %g, distance %g m; dt <= %g s (%g steps per period)",
                        rb->name, b->nplanes, b->kn, b->kt, b->cn, b->ct, b->mu, b->distance,
                        lub_body_dt_limit(b, STEPS_PER_CYCLE), STEPS_PER_CYCLE);
    }
    lub_body b[MAX_BODIES];
    for (int k = 0; k < r->n; k++) b[k] = r->body[k].b;
    for (int q = 0; q < r->npairs; q++) {
        const lub_body_pair *p = &r->pair[q];
        lub_message("rigidBodies: contact of %s and %s: k_n %g, k_t %g, c_n %g, c_t %g, friction "
                    "%g, distance %g m; dt <= %g s (%g steps per period)",
                    r->body[p->a].name, r->body[p->b].name, p->kn, p->kt, p->cn, p->ct, p->mu,
                    p->distance, lub_body_pair_dt_limit(p, b, STEPS_PER_CYCLE), STEPS_PER_CYCLE);
    }
}

/* the contact force and torque on body k: its planes' and the other bodies' */
static void contact_sum(const rigid *r, int k, lub_body_contact_sum *c)
{
    lub_body_contact(&r->body[k].b, &r->body[k].s, c);
    lub_body b[MAX_BODIES];
    lub_body_state st[MAX_BODIES];
    for (int j = 0; j < r->n; j++) b[j] = r->body[j].b, st[j] = r->body[j].s;
    for (int q = 0; q < r->npairs; q++) {
        const lub_body_pair *p = &r->pair[q];
        double f[3], ta[3], tb[3], del;
        if ((p->a != k && p->b != k) || !lub_body_pair_contact(p, b, st, r->xi[q], f, ta, tb, &del))
            continue;
        c->ncontacts++;
        for (int d = 0; d < 3; d++)
            c->F[d] += p->b == k ? f[d] : -f[d], c->T[d] += p->b == k ? tb[d] : ta[d];
    }
}

static void row(const rigid *r, int k, int dim, double t, FILE *fp)
{
    const rigid_body *rb = &r->body[k];
    lub_body_contact_sum c;
    contact_sum(r, k, &c);
    double v[32];
    size_t n = 0;
    v[n++] = t;
    if (dim == 2) {
        double a[] = {rb->s.x[0], rb->s.x[1], rb->s.angle, rb->s.V[0], rb->s.V[1], rb->s.omega[2],
                      rb->F[0],   rb->F[1],   rb->T[2],    c.F[0],     c.F[1],     c.T[2]};
        memcpy(v + n, a, sizeof a);
        n += sizeof a / sizeof a[0];
    } else {
        double w[3];
        lub_body_omega_world(&rb->b, &rb->s, w);
        for (int d = 0; d < 3; d++) v[n++] = rb->s.x[d];
        for (int d = 0; d < 4; d++) v[n++] = rb->s.q[d];
        for (int d = 0; d < 3; d++) v[n++] = rb->s.V[d];
        for (int d = 0; d < 3; d++) v[n++] = w[d];
        for (int d = 0; d < 3; d++) v[n++] = rb->F[d];
        for (int d = 0; d < 3; d++) v[n++] = rb->T[d];
        for (int d = 0; d < 3; d++) v[n++] = c.F[d];
        for (int d = 0; d < 3; d++) v[n++] = c.T[d];
    }
    lub_table_write_row(fp, v, n);
}

static void rigid_functions_start(lub_model *m, lub_scene *s, const char *start, double t)
{
    rigid *r = m->state;
    const int dim = s->P->dim;
    for (int k = 0; k < r->n; k++) {
        rigid_body *rb = &r->body[k];
        char path[LUB_PATH_MAX], file[LUB_NAME_MAX + 8];
        snprintf(file, sizeof file, "%s.dat", rb->name);
        lub_postproc_path(s->cs, "rigidBodies", start, file, path);
        rb->table = fopen(path, "w");
        if (!rb->table) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
        if (dim == 2)
            lub_table_write_header(rb->table,
                                   "t[s] x[m] y[m] angle[rad] Vx[m/s] Vy[m/s] omega[rad/s] "
                                   "Fx[N/m] Fy[N/m] T[N] Fcx[N/m] Fcy[N/m] Tc[N]");
        else
            lub_table_write_header(
                rb->table, "t[s] x[m] y[m] z[m] qw qx qy qz Vx[m/s] Vy[m/s] Vz[m/s] "
                           "omegax[rad/s] omegay[rad/s] omegaz[rad/s] Fx[N] Fy[N] Fz[N] Tx[N*m] "
                           "Ty[N*m] Tz[N*m] Fcx[N] Fcy[N] Fcz[N] Tcx[N*m] Tcy[N*m] Tcz[N*m]");
        row(r, k, dim, t, rb->table);
    }
}

static void rigid_functions_execute(lub_model *m, lub_scene *s, double t, long step)
{
    (void)step;
    rigid *r = m->state;
    for (int k = 0; k < r->n; k++) {
        if (!r->body[k].table) continue;
        row(r, k, s->P->dim, t, r->body[k].table);
        fflush(r->body[k].table);
    }
}

static void rigid_log(const lub_model *m, const lub_scene *s, char *buf, size_t size)
{
    const rigid *r = m->state;
    size_t len = 0;
    buf[0] = '\0';
    for (int k = 0; k < r->n && len < size; k++) {
        const rigid_body *rb = &r->body[k];
        if (s->P->dim == 2)
            len += (size_t)snprintf(buf + len, size - len,
                                    "  %s V (%.4g, %.4g) w %.4g F (%.4g, %.4g)", rb->name,
                                    rb->s.V[0], rb->s.V[1], rb->s.omega[2], rb->F[0], rb->F[1]);
        else
            len += (size_t)snprintf(
                buf + len, size - len, "  %s V (%.4g, %.4g, %.4g) F (%.4g, %.4g, %.4g)", rb->name,
                rb->s.V[0], rb->s.V[1], rb->s.V[2], rb->F[0], rb->F[1], rb->F[2]);
    }
}

static void put_vec(FILE *fp, const char *key, const double *v, int n, const char *what)
{
    fprintf(fp, "    %s: [", key);
    for (int d = 0; d < n; d++) fprintf(fp, "%s%.17g", d ? ", " : "", v[d]);
    fprintf(fp, "]   # %s\n", what);
}

static void rigid_write_state(const lub_model *m, const lub_scene *s, FILE *fp)
{
    const rigid *r = m->state;
    const int dim = s->P->dim;
    fprintf(fp, "rigidBodies:\n");
    for (int k = 0; k < r->n; k++) {
        const rigid_body *rb = &r->body[k];
        fprintf(fp, "  %s:\n", rb->name);
        put_vec(fp, "x", rb->s.x, dim, "centre [m]");
        put_vec(fp, "V", rb->s.V, dim, "velocity [m/s]");
        put_vec(fp, "F", rb->F, dim, "the fluid's force of the last step [N]");
        if (dim == 2) {
            fprintf(fp, "    angle: %.17g   # [rad]\n", rb->s.angle);
            fprintf(fp, "    omega: %.17g   # [rad/s]\n", rb->s.omega[2]);
            fprintf(fp, "    T: %.17g   # the fluid's torque of the last step [N]\n", rb->T[2]);
        } else {
            put_vec(fp, "q", rb->s.q, 4, "orientation (w, x, y, z)");
            put_vec(fp, "omega", rb->s.omega, 3, "angular velocity, body frame [rad/s]");
            put_vec(fp, "T", rb->T, 3, "the fluid's torque of the last step [N m]");
        }
        int listed = 0;
        for (int q = 0; q < r->npairs; q++) listed += r->pair[q].a == k;
        if (listed) {
            fprintf(fp,
                    "    xiBodies:   # the tangential springs of its contacts with bodies [m]\n");
            for (int q = 0; q < r->npairs; q++)
                if (r->pair[q].a == k)
                    fprintf(fp, "      - [%.17g, %.17g, %.17g]\n", r->xi[q][0], r->xi[q][1],
                            r->xi[q][2]);
        }
        if (rb->b.nplanes) {
            fprintf(fp, "    xi:   # the contacts' tangential springs [m]\n");
            for (int p = 0; p < rb->b.nplanes; p++)
                fprintf(fp, "      - [%.17g, %.17g, %.17g]\n", rb->s.xi[p][0], rb->s.xi[p][1],
                        rb->s.xi[p][2]);
        }
    }
}

static void rigid_summary(const lub_model *m, const lub_scene *s, double t)
{
    const rigid *r = m->state;
    for (int k = 0; k < r->n; k++) {
        const rigid_body *rb = &r->body[k];
        if (s->P->dim == 2)
            lub_message("rigidBodies: t %.9g s: %s at (%.9g, %.9g) m, angle %.9g rad, V (%.6g, "
                        "%.6g) m/s, omega %.6g rad/s",
                        t, rb->name, rb->s.x[0], rb->s.x[1], rb->s.angle, rb->s.V[0], rb->s.V[1],
                        rb->s.omega[2]);
        else
            lub_message(
                "rigidBodies: t %.9g s: %s at (%.9g, %.9g, %.9g) m, V (%.6g, %.6g, %.6g) m/s", t,
                rb->name, rb->s.x[0], rb->s.x[1], rb->s.x[2], rb->s.V[0], rb->s.V[1], rb->s.V[2]);
    }
}

static void rigid_free(lub_model *m)
{
    rigid *r = m->state;
    for (int k = 0; k < r->n; k++) {
        if (r->body[k].table) fclose(r->body[k].table);
        free(r->body[k].poly);
    }
    for (int d = 0; d < 3; d++) free(r->area[d]), free(r->f[d]);
}

const lub_model_type lub_model_rigidBodies = {
    .name = "rigidBodies",
    .size = sizeof(rigid),
    .read = rigid_read,
    .check = rigid_check,
    .configure = rigid_configure,
    .init = rigid_init,
    .describe = rigid_describe,
    .header = rigid_header,
    .functions_start = rigid_functions_start,
    .before_step = rigid_before_step,
    .after_step = rigid_after_step,
    .functions_execute = rigid_functions_execute,
    .log = rigid_log,
    .write_state = rigid_write_state,
    .summary = rigid_summary,
    .free = rigid_free,
};
