/* The solver's check for fluid particles going through a wall (src/mps/walls.c,
 * lub_mps_check): particleGen-style walls (one wall layer, two dummy layers) with a fluid
 * particle placed, and given the velocity that brought it there in a step of dt (its
 * position before the step is r - u dt), at the places the criterion must tell apart:
 *
 *   - through the wall layer into the wall (from in front of it to behind it within the
 *     step): LUB_STEP_ESCAPED with that particle's index and the wall's patch name, on a
 *     plane (2-D and 3-D, at a wall particle's column and between two), through both
 *     dummy layers in one step, into the upper wall, and all round a cylinder whose dummy
 *     layers are not aligned with its wall particles;
 *   - not through it: just in front of the wall layer (pushed onto it), on it, a quarter
 *     spacing into it, sliding along the wall, at rest behind it (a particle that did not
 *     cross it in the step), beside the open end of a wall with a range and into its dummy
 *     layers from the side (the oil can reach the dummy particles round the end of a wall
 *     without crossing the wall layer): LUB_STEP_OK.
 *
 * Then through lub_mps_step: a particle driven into the wall stops the step with
 * LUB_STEP_ESCAPED, and a sheared channel with collisions and a fluid pressed onto the lower
 * wall by gravity run without a false alarm.  Last, a related failure that is not an escape:
 * particles squeezed into a group apart from the rest, which touches no surface particle and
 * makes the pressure equation singular (test_isolated_group).
 */
#include <math.h>
#include <stdlib.h>
#include <unistd.h>

#include "geometry/discretise.h"
#include "flow.h" /* generate() */
#include "geometry/geometry.h"
#include "models/collision/collision.h"
#include "mps/mps.h"
#include "test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct {
    lub_particles P;
    lub_geometry g;
    lub_mps m;
    lub_collision collision; /* the collision model's defaults (scene_open) */
    double l0, dt;
} scene;

/* The particles of dict and the scenes' solver settings (water, Crank-Nicolson viscosity,
 * particle indices kept: no sorting) in *c, for the caller to adjust before scene_solver. */
static void scene_particles(scene *s, const char *dict, lub_mps_config *c)
{
    memset(s, 0, sizeof *s);
    s->collision = lub_collision_defaults();
    generate(dict, &s->P, &s->g);
    lub_mps_config_defaults(c);
    c->rho = 1000;
    c->nu = 1e-6;
    c->viscosity = LUB_VISCOSITY_CN;
    c->reorder_interval = 0;
}

static void scene_solver(scene *s, const lub_mps_config *c)
{
    lub_mps_init(&s->m, &s->P, c, s->g.dmin, s->g.dmax, s->g.periodic);
    s->l0 = s->P.levels[0].l0;
    s->dt = 1e-3;
}

static void scene_open(scene *s, const char *dict, int collision)
{
    lub_mps_config c;
    scene_particles(s, dict, &c);
    c.alpha = 1e-6 / (s->P.levels[0].l0 * s->P.levels[0].l0); /* closed channels */
    scene_solver(s, &c);
    if (collision) lub_collision_attach(&s->m, &s->collision);
}

static void scene_close(scene *s)
{
    lub_mps_free(&s->m);
    lub_particles_free(&s->P);
    lub_geometry_free(&s->g);
}

/* The wall particle of patch `name` nearest to point p. */
static size_t wall_near(const scene *s, const char *name, const double p[3])
{
    int patch = lub_particles_find_patch(&s->P, name);
    size_t best = 0;
    double bd = INFINITY;
    for (size_t i = 0; i < s->P.n; i++) {
        if (s->P.kind[i] != LUB_WALL || s->P.patch[i] != patch) continue;
        double d = 0;
        for (int k = 0; k < s->P.dim; k++) d += (s->P.x[k][i] - p[k]) * (s->P.x[k][i] - p[k]);
        if (d < bd) bd = d, best = i;
    }
    return best;
}

/* The fluid particle nearest to point p (the one the tests move around). */
static size_t fluid_near(const scene *s, const double p[3])
{
    size_t best = 0;
    double bd = INFINITY;
    for (size_t i = 0; i < s->P.n; i++) {
        if (s->P.kind[i] != LUB_FLUID) continue;
        double d = 0;
        for (int k = 0; k < s->P.dim; k++) d += (s->P.x[k][i] - p[k]) * (s->P.x[k][i] - p[k]);
        if (d < bd) bd = d, best = i;
    }
    return best;
}

/* Put fluid particle i at `to`, arriving from `from` in one step (u = (to - from) / dt),
 * every other particle at rest, build the lists and check.  Prints the message of a
 * result other than `expect`. */
static lub_step_status place(scene *s, size_t i, const double from[3], const double to[3],
                             long *bad, char *msg, size_t msgsize)
{
    lub_particles *P = &s->P;
    for (size_t j = 0; j < P->n; j++)
        for (int k = 0; k < 3; k++) P->u[k][j] = 0;
    for (int k = 0; k < P->dim; k++) {
        P->x[k][i] = to[k];
        P->u[k][i] = (to[k] - from[k]) / s->dt;
    }
    double *x[3] = {P->x[0], P->x[1], P->x[2]};
    lub_neighbours_build(&s->m.nb, P->n, x);
    return lub_mps_check(&s->m, s->dt, bad, msg, msgsize);
}

/* Expect LUB_STEP_ESCAPED naming particle i and the patch. */
#define EXPECT_THROUGH(s, i, from, to, patch)                                                      \
    do {                                                                                           \
        long bad_;                                                                                 \
        char msg_[512];                                                                            \
        lub_step_status st_ = place(s, i, from, to, &bad_, msg_, sizeof msg_);                     \
        CHECK(st_ == LUB_STEP_ESCAPED);                                                            \
        CHECK(bad_ == (long)(i));                                                                  \
        CHECK_STR(msg_, "went through the wall '" patch "'");                                      \
        char id_[64];                                                                              \
        snprintf(id_, sizeof id_, "fluid particle id %llu ", (unsigned long long)(s)->P.id[i]);    \
        CHECK_STR(msg_, id_);                                                                      \
    } while (0)

#define EXPECT_OK(s, i, from, to)                                                                  \
    do {                                                                                           \
        long bad_;                                                                                 \
        char msg_[512];                                                                            \
        lub_step_status st_ = place(s, i, from, to, &bad_, msg_, sizeof msg_);                     \
        if (st_ != LUB_STEP_OK) printf("  unexpected: %s\n", msg_);                                \
        CHECK(st_ == LUB_STEP_OK);                                                                 \
        CHECK(bad_ == -1);                                                                         \
    } while (0)

/* Channel of height 10 l0 between wall layers at y = 0 (lower) and y = 10 l0 (upper), each
 * with two dummy layers, periodic in x, filled with fluid. */
static const char *channel2 = "dimension: 2\n"
                              "l0: 0.001\n"
                              "domain: { min: [0, -0.004], max: [0.02, 0.014] }\n"
                              "periodic: [x]\n"
                              "dummyLayers: 2\n"
                              "walls:\n"
                              "  lower: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                              "  upper: { type: plane, point: [0, 0.01], normal: [0, -1] }\n"
                              "fluid:\n"
                              "  - { type: box, min: [0, 0], max: [0.02, 0.01] }\n";

/* A point at (a, b) l0 from wall particle w (b > 0: into the fluid of the lower wall). */
#define AT(s, w, a, b)                                                                             \
    {                                                                                              \
        (s)->P.x[0][w] + (a) * (s)->l0, (s)->P.x[1][w] + (b) * (s)->l0, 0                          \
    }

static void test_plane_through(void)
{
    scene s;
    scene_open(&s, channel2, 0);
    const double c[3] = {0.01, 0, 0};
    const size_t w = wall_near(&s, "lower", c);
    const size_t i = fluid_near(&s, (double[3]){0.01, 0.001, 0});
    {
        /* between two wall particles, from 0.2 in front to 0.5 behind */
        double from[3] = AT(&s, w, 0.5, 0.2), to[3] = AT(&s, w, 0.5, -0.5);
        EXPECT_THROUGH(&s, i, from, to, "lower");
    }
    {
        /* at a wall particle's column, slowly: 0.2 behind before, 0.3 now */
        double from[3] = AT(&s, w, 0.05, -0.2), to[3] = AT(&s, w, 0.05, -0.3);
        EXPECT_THROUGH(&s, i, from, to, "lower");
    }
    {
        /* through the wall layer and into the second dummy layer within one step */
        double from[3] = AT(&s, w, 0.3, 0.9), to[3] = AT(&s, w, 0.3, -1.8);
        EXPECT_THROUGH(&s, i, from, to, "lower");
    }
    {
        /* obliquely */
        double from[3] = AT(&s, w, -0.6, 0.3), to[3] = AT(&s, w, 0.4, -0.4);
        EXPECT_THROUGH(&s, i, from, to, "lower");
    }
    {
        /* into the upper wall (the particle above back in the fluid, at rest) */
        for (int k = 0; k < 2; k++) s.P.x[k][i] = s.P.x[k][w] + (k ? 1.0 : 0.5) * s.l0;
        const size_t wu = wall_near(&s, "upper", (double[3]){0.01, 0.01, 0});
        const size_t iu = fluid_near(&s, (double[3]){0.01, 0.009, 0});
        double from[3] = AT(&s, wu, 0.5, -0.1), to[3] = AT(&s, wu, 0.5, 0.6);
        EXPECT_THROUGH(&s, iu, from, to, "upper");
    }
    scene_close(&s);
}

static void test_plane_not_through(void)
{
    scene s;
    scene_open(&s, channel2, 0);
    const size_t w = wall_near(&s, "lower", (double[3]){0.01, 0, 0});
    const size_t i = fluid_near(&s, (double[3]){0.01, 0.001, 0});
    {
        /* just in front of the wall layer, pushed onto it (collision distance 0.8 l0 from
         * the wall particles is at 0.62 l0 above the layer between two of them) */
        double from[3] = AT(&s, w, 0.5, 0.9), to[3] = AT(&s, w, 0.5, 0.05);
        EXPECT_OK(&s, i, from, to);
    }
    {
        /* on the wall layer, and a fifth of a spacing into it */
        double from[3] = AT(&s, w, 0.5, 0.6), to[3] = AT(&s, w, 0.5, 0.0);
        EXPECT_OK(&s, i, from, to);
        double to2[3] = AT(&s, w, 0.5, -0.2);
        EXPECT_OK(&s, i, from, to2);
    }
    {
        /* sliding along the wall: one spacing above it, and compressed to 0.3 */
        double from[3] = AT(&s, w, -0.4, 1.0), to[3] = AT(&s, w, 0.5, 1.0);
        EXPECT_OK(&s, i, from, to);
        double from2[3] = AT(&s, w, -0.4, 0.3), to2[3] = AT(&s, w, 0.5, 0.3);
        EXPECT_OK(&s, i, from2, to2);
    }
    {
        /* behind the wall layer, but it was there before the step (it came round an open
         * end of a wall, say): not through the wall in this step */
        double at[3] = AT(&s, w, 0.5, -0.6);
        EXPECT_OK(&s, i, at, at);
        double from[3] = AT(&s, w, 0.2, -0.5), to[3] = AT(&s, w, 0.5, -1.2);
        EXPECT_OK(&s, i, from, to);
    }
    scene_close(&s);
}

/* A lower wall that ends (range) in a domain open beyond it: the oil can flow round its end
 * into the region under it, next to the dummy particles, without crossing the wall layer. */
static void test_open_end(void)
{
    scene s;
    scene_open(&s,
               "dimension: 2\n"
               "l0: 0.001\n"
               "domain: { min: [-0.01, -0.01], max: [0.02, 0.01] }\n"
               "dummyLayers: 2\n"
               "walls:\n"
               "  shelf: { type: plane, point: [0, 0], normal: [0, 1], range: [0, 0.01] }\n"
               "fluid:\n"
               "  - { type: box, min: [0, 0], max: [0.01, 0.005] }\n",
               0);
    const size_t we = wall_near(&s, "shelf", (double[3]){0.011, 0, 0}); /* the end */
    const size_t i = fluid_near(&s, (double[3]){0.009, 0.001, 0});
    {
        /* beside the end, going down past the level of the wall layer */
        double from[3] = AT(&s, we, 0.6, 0.3), to[3] = AT(&s, we, 0.6, -0.5);
        EXPECT_OK(&s, i, from, to);
        double from2[3] = AT(&s, we, 0.3, 0.3), to2[3] = AT(&s, we, 0.3, -0.5);
        EXPECT_OK(&s, i, from2, to2);
    }
    {
        /* under the wall, into the dummy layers from the side */
        double from[3] = AT(&s, we, 0.7, -1.2), to[3] = AT(&s, we, -0.5, -1.3);
        EXPECT_OK(&s, i, from, to);
    }
    {
        /* but through the wall layer two spacings from the end */
        double from[3] = AT(&s, we, -1.5, 0.2), to[3] = AT(&s, we, -1.5, -0.5);
        EXPECT_THROUGH(&s, i, from, to, "shelf");
    }
    scene_close(&s);
}

/* 3-D: plates at z = 0 and z = 8 l0, periodic in x and y. */
static const char *plates3 = "dimension: 3\n"
                             "l0: 0.001\n"
                             "domain: { min: [0, 0, -0.004], max: [0.008, 0.008, 0.012] }\n"
                             "periodic: [x, y]\n"
                             "dummyLayers: 2\n"
                             "walls:\n"
                             "  lower: { type: plane, point: [0, 0, 0], normal: [0, 0, 1] }\n"
                             "  upper: { type: plane, point: [0, 0, 0.008], normal: [0, 0, -1] }\n"
                             "fluid:\n"
                             "  - { type: box, min: [0, 0, 0], max: [0.008, 0.008, 0.008] }\n";

static void test_plane_3d(void)
{
    scene s;
    scene_open(&s, plates3, 0);
    const size_t w = wall_near(&s, "lower", (double[3]){0.004, 0.004, 0});
    const size_t i = fluid_near(&s, (double[3]){0.004, 0.004, 0.001});
#define AT3(a, b, c) {s.P.x[0][w] + (a)*s.l0, s.P.x[1][w] + (b)*s.l0, s.P.x[2][w] + (c)*s.l0}
    {
        /* at the centre of a square of wall particles, and at a column */
        double from[3] = AT3(0.5, 0.5, 0.2), to[3] = AT3(0.5, 0.5, -0.4);
        EXPECT_THROUGH(&s, i, from, to, "lower");
        double from2[3] = AT3(0.1, -0.2, 0.3), to2[3] = AT3(0.1, -0.2, -0.6);
        EXPECT_THROUGH(&s, i, from2, to2, "lower");
    }
    {
        /* pushed onto the wall layer, sliding along it, at rest behind it */
        double from[3] = AT3(0.5, 0.5, 0.9), to[3] = AT3(0.5, 0.5, 0.05);
        EXPECT_OK(&s, i, from, to);
        double from2[3] = AT3(-0.3, 0.2, 1.0), to2[3] = AT3(0.5, 0.5, 1.0);
        EXPECT_OK(&s, i, from2, to2);
        double at[3] = AT3(0.5, 0.5, -0.6);
        EXPECT_OK(&s, i, at, at);
    }
#undef AT3
    scene_close(&s);
}

/* A cylinder of radius 8 l0 (fluid outside): every layer is a full ring with its own number
 * of particles, so the dummy particles are not behind the wall particles.  Through the wall
 * layer at 36 angles: from 0.2 l0 outside to 0.5 l0 inside; not through: pushed onto it from
 * 0.6 outside to 0.05 outside. */
static void test_cylinder(void)
{
    scene s;
    scene_open(&s,
               "dimension: 2\n"
               "l0: 0.001\n"
               "domain: { min: [-0.015, -0.015], max: [0.015, 0.015] }\n"
               "dummyLayers: 2\n"
               "walls:\n"
               "  disk: { type: cylinder, centre: [0, 0], radius: 0.008 }\n"
               "fluid:\n"
               "  - { type: box, min: [-0.013, -0.013], max: [0.013, 0.013] }\n",
               0);
    int through = 0, ok = 0;
    const int na = 36;
    for (int k = 0; k < na; k++) {
        const double phi = 2 * M_PI * (k + 0.3) / na, c = cos(phi), sn = sin(phi);
        const double R = 0.008, l0 = s.l0;
        const size_t i = fluid_near(&s, (double[3]){(R + l0) * c, (R + l0) * sn, 0});
        double from[3] = {(R + 0.2 * l0) * c, (R + 0.2 * l0) * sn, 0};
        double to[3] = {(R - 0.5 * l0) * c, (R - 0.5 * l0) * sn, 0};
        long bad;
        char msg[512];
        if (place(&s, i, from, to, &bad, msg, sizeof msg) == LUB_STEP_ESCAPED && bad == (long)i &&
            strstr(msg, "'disk'"))
            through++;
        else
            printf("  angle %.1f deg: not seen (%s)\n", phi * 180 / M_PI, msg);
        double from2[3] = {(R + 0.6 * l0) * c, (R + 0.6 * l0) * sn, 0};
        double to2[3] = {(R + 0.05 * l0) * c, (R + 0.05 * l0) * sn, 0};
        if (place(&s, i, from2, to2, &bad, msg, sizeof msg) == LUB_STEP_OK)
            ok++;
        else
            printf("  angle %.1f deg: false alarm: %s\n", phi * 180 / M_PI, msg);
        /* put it back where it came from for the next angle */
        double home[3] = {(R + l0) * c, (R + l0) * sn, 0};
        for (int d = 0; d < 2; d++) s.P.x[d][i] = home[d];
    }
    printf("  cylinder: through the wall seen at %d of %d angles, no alarm at %d of %d\n", through,
           na, ok, na);
    CHECK(through == na);
    CHECK(ok == na);
    scene_close(&s);
}

/* lub_mps_step: a fluid particle next to the lower wall driven into it (one spacing a step)
 * stops the step; the index is that of the particle. */
static void test_step_escape(void)
{
    scene s;
    scene_open(&s, channel2, 0);
    const size_t i = fluid_near(&s, (double[3]){0.01, 0.001, 0});
    const uint64_t id = s.P.id[i];
    s.P.u[1][i] = -1.6 * s.l0 / s.dt;
    long bad;
    char msg[512];
    lub_step_status st = lub_mps_step(&s.m, s.dt, &bad, msg, sizeof msg);
    printf("  %s\n", msg);
    CHECK(st == LUB_STEP_ESCAPED);
    CHECK(bad == (long)i);
    CHECK(bad >= 0 && s.P.id[bad] == id);
    CHECK_STR(msg, "went through the wall 'lower'");
    scene_close(&s);
}

/* lub_mps_step without an alarm: a channel sheared by the lower wall at 1 l0 per 10 steps
 * (the fluid slides along both walls) and the fluid pressed onto the lower wall by gravity,
 * both with collisions, 200 steps each. */
static void test_step_no_alarm(void)
{
    for (int k = 0; k < 2; k++) {
        scene s;
        scene_open(&s, channel2, 1);
        if (k == 0)
            s.m.c.patch_velocity[lub_particles_find_patch(&s.P, "lower")][0] = 0.1 * s.l0 / s.dt;
        else
            s.m.c.gravity = 1, s.m.c.g[1] = -9.81;
        long bad = -1;
        char msg[512] = "";
        lub_step_status st = LUB_STEP_OK;
        int n = 0;
        for (; n < 200 && st == LUB_STEP_OK; n++)
            st = lub_mps_step(&s.m, s.dt, &bad, msg, sizeof msg);
        if (st != LUB_STEP_OK) printf("  %s: step %d: %s\n", k ? "gravity" : "shear", n, msg);
        CHECK(st == LUB_STEP_OK);
        scene_close(&s);
    }
}

/* A pool on a plane under gravity with a free surface (alpha = 0), re = 2.1 l0, and four of its
 * fluid particles moved far above it: squeezed together (a square of side 0.4 l0) they see only
 * each other, their PND is above the surface threshold, so none is a surface particle, and
 * the pressure equation is singular on them (their rows sum to zero).  The step takes them as
 * surface particles (st.nisolated = 4, p = 0) and gives the pool the pressure it gets when the
 * four are far apart instead (each alone: a surface particle by its PND), to round-off. */
static const char *pool2 = "dimension: 2\n"
                           "l0: 0.001\n"
                           "domain: { min: [0, -0.004], max: [0.03, 0.03] }\n"
                           "dummyLayers: 2\n"
                           "walls:\n"
                           "  lower: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                           "fluid:\n"
                           "  - { type: box, min: [0.002, 0], max: [0.018, 0.008] }\n";

static void pool_step(int squeezed, scene *s, size_t moved[4], lub_step_status *st, char *msg,
                      size_t msgsize)
{
    lub_mps_config c;
    scene_particles(s, pool2, &c);
    c.alpha = 0;
    c.re_l0 = 2.1;
    c.gravity = 1, c.g[1] = -9.81; /* a pressure in the pool */
    c.clip_negative = LUB_NEGATIVE_KEEP;
    scene_solver(s, &c);
    /* the four fluid particles nearest the pool's upper right corner, moved to (0.022, 0.02) */
    const double corner[3] = {0.0175, 0.0075, 0};
    for (int k = 0; k < 4; k++) {
        moved[k] = fluid_near(s, corner);
        const double a = squeezed ? 0.4 * s->l0 : 5 * s->l0;
        s->P.x[0][moved[k]] = 0.022 + a * (k % 2);
        s->P.x[1][moved[k]] = 0.020 + a * (k / 2);
    }
    long bad;
    *st = lub_mps_step(&s->m, s->dt, &bad, msg, msgsize);
}

static void test_isolated_group(void)
{
    scene a, b;
    size_t ma[4], mb[4];
    lub_step_status sa, sb;
    char msg[512] = "";
    pool_step(1, &a, ma, &sa, msg, sizeof msg);
    if (sa != LUB_STEP_OK) printf("  squeezed: %s\n", msg);
    pool_step(0, &b, mb, &sb, msg, sizeof msg);
    if (sb != LUB_STEP_OK) printf("  apart: %s\n", msg);
    CHECK(sa == LUB_STEP_OK && sb == LUB_STEP_OK);
    CHECK(a.m.st.nisolated == 4 && b.m.st.nisolated == 0);
    CHECK(a.P.n == b.P.n && memcmp(ma, mb, sizeof ma) == 0);
    int clump_zero = 1;
    for (int k = 0; k < 4; k++) clump_zero &= a.P.p[ma[k]] == 0.0 && a.m.surface[ma[k]];
    CHECK(clump_zero);
    double dmax = 0, pmax = 0;
    size_t npool = 0;
    for (size_t i = 0; i < a.P.n; i++) {
        if (a.P.kind[i] != LUB_FLUID || i == ma[0] || i == ma[1] || i == ma[2] || i == ma[3])
            continue;
        dmax = fmax(dmax, fabs(a.P.p[i] - b.P.p[i]));
        pmax = fmax(pmax, fabs(b.P.p[i]));
        npool++;
    }
    printf("  pool of %zu particles: pressure up to %.3g Pa, largest difference %.3g Pa\n", npool,
           pmax, dmax);
    CHECK(pmax > 0 && dmax <= 1e-9 * pmax);
    scene_close(&a);
    scene_close(&b);
}

/* The collision model's wall planes (src/models/collision/collision.c): in 3-D a particle
 * coming along the normal at the centre of a square of wall particles, 0.5 l0 from the
 * wall's plane, is 0.87 l0 from the four corners, beyond the pair rule's 0.8 l0, and would
 * go on into the hole (tutorials/wedge3D at h0/4: through the roller's wall at step 536);
 * within sqrt(0.8^2 - 0.5^2) l0 = 0.62 l0 of the plane it loses its approach with the
 * restitution e: u_n = +e v.  On a 2-D wall coming straight at a wall particle (0.7 l0) the
 * pair rule alone acts (u_n = +e v, not more: the plane finds it leaving). */
static void collide_at(scene *s, size_t i, const double at[3], double v, int axis)
{
    lub_particles *P = &s->P;
    for (size_t j = 0; j < P->n; j++)
        for (int k = 0; k < 3; k++) P->u[k][j] = 0;
    for (int k = 0; k < P->dim; k++) P->x[k][i] = at[k];
    P->u[axis][i] = -v;
    double *x[3] = {P->x[0], P->x[1], P->x[2]};
    lub_neighbours_build(&s->m.nb, P->n, x);
    lub_collision_apply(&s->collision, &s->m, s->dt);
}

static void test_collision_wall_plane(void)
{
    const double v = 0.1, e = lub_collision_defaults().restitution;
    scene s;
    scene_open(&s, plates3, 1);
    const size_t w = wall_near(&s, "lower", (double[3]){0.004, 0.004, 0});
    const size_t i = fluid_near(&s, (double[3]){0.004, 0.004, 0.001});
    const double l0 = s.l0;
    {
        const double at[3] = {s.P.x[0][w] + 0.5 * l0, s.P.x[1][w] + 0.5 * l0, 0.5 * l0};
        const size_t before = s.m.st.nwallplane;
        collide_at(&s, i, at, v, 2);
        printf("  3-D, centre of a square 0.5 l0 above the plane: u_z %.6g (e v = %g), %zu stop\n",
               s.P.u[2][i], e * v, s.m.st.nwallplane - before);
        CHECK(fabs(s.P.u[2][i] - e * v) < 1e-12 * v);
        CHECK(fabs(s.P.u[0][i]) < 1e-12 * v && fabs(s.P.u[1][i]) < 1e-12 * v);
        CHECK(fabs(s.P.x[2][i] - (at[2] + (1 + e) * v * s.dt)) < 1e-12 * l0);
        CHECK(s.m.st.nwallplane - before == 1);
        /* farther than 0.62 l0 from the plane: nothing */
        const double at2[3] = {at[0], at[1], 0.7 * l0};
        collide_at(&s, i, at2, v, 2);
        CHECK(s.P.u[2][i] == -v);
    }
    scene_close(&s);

    scene_open(&s, channel2, 1);
    {
        const size_t w2 = wall_near(&s, "lower", (double[3]){0.004, 0, 0});
        const size_t i2 = fluid_near(&s, (double[3]){0.004, 0.001, 0});
        const double at[3] = {s.P.x[0][w2], s.P.x[1][w2] + 0.7 * s.l0, 0};
        const size_t before = s.m.st.nwallplane;
        collide_at(&s, i2, at, v, 1);
        printf("  2-D, 0.7 l0 above a wall particle: u_y %.6g (e v = %g), %zu plane stops\n",
               s.P.u[1][i2], e * v, s.m.st.nwallplane - before);
        CHECK(fabs(s.P.u[1][i2] - e * v) < 1e-12 * v);
        CHECK(s.m.st.nwallplane == before);
    }
    scene_close(&s);
}

int main(void)
{
    RUN(test_plane_through);
    RUN(test_plane_not_through);
    RUN(test_open_end);
    RUN(test_plane_3d);
    RUN(test_cylinder);
    RUN(test_step_escape);
    RUN(test_step_no_alarm);
    RUN(test_isolated_group);
    RUN(test_collision_wall_plane);
    return test_summary();
}
