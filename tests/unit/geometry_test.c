/* Unit tests of src/geometry: the particleGenDict reader, the analytic wall functions and
 * the discretisation into wall, dummy and fluid particles.  Expected values are computed by
 * hand from the geometry (counts of lattice points, circle arithmetic). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "geometry/discretise.h"
#include "geometry/geometry.h"
#include "test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static char tmp_path[256];

/* Write a dictionary to a temporary file and return its path. */
static const char *dict_file(const char *text)
{
    snprintf(tmp_path, sizeof tmp_path, "/tmp/lub_geometry_test_%ld.yaml", (long)getpid());
    FILE *f = fopen(tmp_path, "w");
    fputs(text, f);
    fclose(f);
    return tmp_path;
}

static void read_text(lub_geometry *g, const char *text)
{
    lub_geometry_read(g, dict_file(text));
}

/* Expect a fatal error mentioning sub and the line number `line` of the temp file. */
#define CHECK_BAD(text, line, sub)                                                                 \
    do {                                                                                           \
        lub_geometry g_;                                                                           \
        memset(&g_, 0, sizeof g_);                                                                 \
        const char *p_ = dict_file(text);                                                          \
        CHECK_FATAL(lub_geometry_read(&g_, p_), sub);                                              \
        char loc_[300];                                                                            \
        snprintf(loc_, sizeof loc_, "%s:%d:", p_, line);                                           \
        CHECK_STR(test_last_error, loc_);                                                          \
        lub_geometry_free(&g_);                                                                    \
    } while (0)

static const char *wedge_text = "dimension: 2\n"
                                "l0: 5.0e-6\n"
                                "domain: { min: [-0.0045, -2.0e-5], max: [0.0045, 3.0e-4] }\n"
                                "periodic: [x]\n"
                                "walls:\n"
                                "  lowerWall: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                                "  cylinder: { type: cylinder, lowestPoint: [0, 4.0e-5], "
                                "radius: 0.04, range: [-0.0045, 0.0045] }\n"
                                "fluid:\n"
                                "  - { type: layer, wall: lowerWall, thickness: 8.0e-5 }\n";

static void test_read_wedge(void)
{
    lub_geometry g;
    read_text(&g, wedge_text);
    CHECK(g.dim == 2);
    CHECK(g.nlevels == 1);
    CHECK_NEAR(g.levels[0].l0, 5e-6, 0);
    CHECK(g.periodic[0] == 1 && g.periodic[1] == 0);
    CHECK(g.dummy_layers == 2);
    CHECK_NEAR(g.wall_gap, 1.0, 0);
    CHECK(g.nwalls == 2);
    CHECK(lub_geometry_find_wall(&g, "cylinder") == 1);
    CHECK(lub_geometry_find_wall(&g, "nothing") == -1);
    const lub_wall *c = &g.walls[1];
    CHECK(c->type == LUB_WALL_CYLINDER);
    CHECK_NEAR(c->centre[1], 0.04 + 4e-5, 1e-15);
    CHECK(c->has_range);
    CHECK(g.nregions == 1 && g.regions[0].type == LUB_REGION_LAYER && g.regions[0].wall == 0);
    lub_geometry_free(&g);
}

/* Heights and distances against hand-computed values. */
static void test_wall_functions(void)
{
    lub_geometry g;
    read_text(&g, "dimension: 2\nl0: 0.1\ndomain: { min: [-3, -3], max: [3, 3] }\n"
                  "walls:\n"
                  "  p:  { type: plane, point: [0, 1], normal: [-1, 1] }\n"
                  "  s:  { type: segment, from: [2, 1], to: [0, 0], fluid: below }\n"
                  "  c:  { type: cylinder, centre: [0, 2], radius: 1 }\n"
                  "  pl: { type: polyline, points: [[0, 0], [1, 1], [2, 0]] }\n"
                  "  b:  { type: box, min: [-1, -1], max: [1, 0.5] }\n");
    double y;
    const lub_wall *p = &g.walls[0], *s = &g.walls[1], *c = &g.walls[2], *pl = &g.walls[3],
                   *b = &g.walls[4];
    /* plane y = 1 + x */
    CHECK(lub_wall_height(p, 2.0, 0, &y) && fabs(y - 3.0) < 1e-14);
    CHECK_NEAR(lub_wall_distance(p, (double[]){0, 2}, 2), 1 / sqrt(2.0), 1e-14);
    CHECK_NEAR(lub_wall_distance(p, (double[]){0, 0}, 2), -1 / sqrt(2.0), 1e-14);
    /* segment y = x/2 on [0, 2], fluid below */
    CHECK(lub_wall_height(s, 1.0, 1, &y) && fabs(y - 0.5) < 1e-14);
    CHECK(!lub_wall_height(s, 2.5, 1, &y));
    CHECK_NEAR(lub_wall_distance(s, (double[]){1, -0.5}, 2), 2 / sqrt(5.0), 1e-14);
    /* beyond the end: distance to (2, 1), above the extended line -> solid side */
    CHECK_NEAR(lub_wall_distance(s, (double[]){3, 2}, 2), -sqrt(2.0), 1e-14);
    /* circle centre (0, 2), R = 1: upper wall of a gap -> lowest point 2 - sqrt(1 - x^2) */
    CHECK(lub_wall_height(c, 0.6, 1, &y) && fabs(y - 1.2) < 1e-14);
    CHECK(lub_wall_height(c, 0.6, 0, &y) && fabs(y - 2.8) < 1e-14);
    CHECK(!lub_wall_height(c, 1.5, 1, &y));
    /* a 2-D circle is a cylinder extruded in z: the same height on every z (reynoldsRef
     * over a width) */
    CHECK(lub_wall_height_at(c, 0.6, 5.0, 1, &y) && fabs(y - 1.2) < 1e-14);
    CHECK_NEAR(lub_wall_distance(c, (double[]){0, 0}, 2), 1.0, 1e-14);
    CHECK_NEAR(lub_wall_distance(c, (double[]){0, 2.5}, 2), -0.5, 1e-14);
    /* polyline tent */
    CHECK(lub_wall_height(pl, 1.5, 0, &y) && fabs(y - 0.5) < 1e-14);
    CHECK_NEAR(lub_wall_distance(pl, (double[]){1, 2}, 2), 1.0, 1e-14);
    CHECK_NEAR(lub_wall_distance(pl, (double[]){1, 0}, 2), -1 / sqrt(2.0), 1e-14);
    /* box tank (fluid inside): floor is the lower wall, lid the upper */
    CHECK(lub_wall_height(b, 0, 0, &y) && y == -1.0);
    CHECK(lub_wall_height(b, 0, 1, &y) && y == 0.5);
    CHECK_NEAR(lub_wall_distance(b, (double[]){0, 0}, 2), 0.5, 1e-14);
    CHECK_NEAR(lub_wall_distance(b, (double[]){2, 1.5}, 2), -sqrt(2.0), 1e-14);
    lub_geometry_free(&g);
}

static void test_wall_functions_3d(void)
{
    lub_geometry g;
    read_text(&g, "dimension: 3\nl0: 0.1\ndomain: { min: [-3, -3, -3], max: [3, 3, 3] }\n"
                  "walls:\n"
                  "  ball:  { type: sphere, centre: [0, 2, 0.6], radius: 1 }\n"
                  "  shaft: { type: cylinder, centre: [0, 0, 0], axis: [1, 0, 0], radius: 0.5 }\n"
                  "  floor: { type: plane, point: [0, -1, 0], normal: [0, 1, 0] }\n");
    double y;
    /* z = 0 section of the sphere: circle of radius 0.8 around (0, 2) */
    CHECK(lub_wall_height(&g.walls[0], 0, 1, &y) && fabs(y - 1.2) < 1e-14);
    CHECK_NEAR(lub_wall_distance(&g.walls[0], (double[]){0, 2, 0.6}, 3), -1.0, 1e-14);
    /* cylinder along x: its section at any x is y = -0.5 (lower surface) */
    CHECK(lub_wall_height(&g.walls[1], 2.0, 1, &y) && fabs(y + 0.5) < 1e-14);
    CHECK_NEAR(lub_wall_distance(&g.walls[1], (double[]){7, 0, 1.5}, 3), 1.0, 1e-14);
    CHECK(lub_wall_height(&g.walls[2], 1.0, 0, &y) && fabs(y + 1.0) < 1e-14);
    /* off the z = 0 section (lub_wall_height_at): the sphere's lowest point over (x, z) is
     * 2 - sqrt(1 - x^2 - (z - 0.6)^2); the line misses it beyond its radius */
    CHECK(lub_wall_height_at(&g.walls[0], 0.6, 0.6, 1, &y) && fabs(y - 1.2) < 1e-14);
    CHECK(lub_wall_height_at(&g.walls[0], 0.0, 1.2, 1, &y) && fabs(y - 1.2) < 1e-14);
    CHECK(lub_wall_height_at(&g.walls[0], 0.48, 0.0, 1, &y) && fabs(y - 1.36) < 1e-14);
    CHECK(!lub_wall_height_at(&g.walls[0], 0.0, 1.7, 1, &y));
    /* z = 0 is lub_wall_height */
    double y0;
    CHECK(lub_wall_height(&g.walls[0], 0.3, 1, &y0) &&
          lub_wall_height_at(&g.walls[0], 0.3, 0.0, 1, &y) && y == y0);
    /* the cylinder along x: its lower surface over (x, z) is -sqrt(0.25 - z^2) */
    CHECK(lub_wall_height_at(&g.walls[1], 2.0, 0.3, 1, &y) && fabs(y + 0.4) < 1e-14);
    lub_geometry_free(&g);
    /* a tilted plane y = -0.5 z (normal (0, 2, 1)) and a roller of finite length along z */
    read_text(&g, "dimension: 3\nl0: 0.1\ndomain: { min: [-3, -3, -3], max: [3, 3, 3] }\n"
                  "walls:\n"
                  "  tilt:   { type: plane, point: [0, 0, 0], normal: [0, 2, 1] }\n"
                  "  roller: { type: cylinder, lowestPoint: [0, 1, 0], radius: 1, length: 1.0 }\n");
    CHECK(lub_wall_height_at(&g.walls[0], 0.7, 0.8, 0, &y) && fabs(y + 0.4) < 1e-14);
    CHECK(lub_wall_height_at(&g.walls[1], 0.6, 0.5, 1, &y) && fabs(y - 1.2) < 1e-14);
    CHECK(!lub_wall_height_at(&g.walls[1], 0.6, 0.6, 1, &y)); /* beyond its end */
    lub_geometry_free(&g);
}

static void test_read_levels(void)
{
    lub_geometry g;
    read_text(&g, "dimension: 2\n"
                  "levels:\n"
                  "  - { l0: 5.0e-6, region: [-0.0036, 0.0030] }\n"
                  "  - { l0: 4.0e-5 }\n"
                  "domain: { min: [-0.0048, -4.0e-5], max: [0.0048, 3.0e-4] }\n"
                  "periodic: [x]\n"
                  "walls:\n"
                  "  lowerWall: { type: plane, point: [0, 0], normal: [0, 1] }\n");
    CHECK(g.nlevels == 2);
    CHECK(g.levels[0].has_region && g.levels[0].xmin == -0.0036 && g.levels[0].xmax == 0.0030);
    CHECK(!g.levels[1].has_region && g.levels[1].xmin == -0.0048);
    lub_geometry_free(&g);
}

/* Every bad-input class: exit-1 fatal with file:line of the offending entry. */
static void test_bad_input(void)
{
    CHECK_BAD("dimension: 2\nl0: -1e-6\ndomain: { min: [0, 0], max: [1, 1] }\n", 2,
              "'l0' must be > 0");
    CHECK_BAD("dimension: 2\nl0: 0\ndomain: { min: [0, 0], max: [1, 1] }\n", 2, "'l0' must be > 0");
    CHECK_BAD("dimension: 4\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\n", 1,
              "'dimension' must be between 2 and 3");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 2], max: [1, 1] }\n", 3,
              "min must be below max");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\n"
              "walls:\n  lowerWall: { type: plane, point: [0, 0], normal: [0, 1] }\n"
              "fluid:\n  - { type: layer, wall: lowerWal, thickness: 0.5 }\n",
              7, "unknown wall 'lowerWal' (did you mean 'lowerWall'?)");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\n"
              "walls:\n  a: { type: plane, point: [0, 0], normal: [0, 1] }\n"
              "  b: { type: cylinder, centre: [0, 0], radius: 1 }\n"
              "fluid:\n  - { type: between, lower: a, upper: cylindr, height: 0.5 }\n",
              8, "unknown wall 'cylindr'");
    CHECK_BAD("dimension: 2\nlevels:\n  - { l0: 0.1, region: [0, 0.5] }\n"
              "  - { l0: 0.2, region: [0.5, 0.8] }\n"
              "domain: { min: [0, 0], max: [1, 1] }\n",
              3, "do not cover the domain: x from 0.8");
    CHECK_BAD("dimension: 2\nlevels:\n  - { l0: 0.1 }\n  - { l0: 0.2 }\n"
              "domain: { min: [0, 0], max: [1, 1] }\n",
              3, "needs 'region");
    CHECK_BAD("dimension: 2\nlevels:\n  - { l0: 0.2, region: [0, 0.5] }\n  - { l0: 0.1 }\n"
              "domain: { min: [0, 0], max: [1, 1] }\n",
              4, "from fine to coarse");
    CHECK_BAD("dimension: 2\nl0: 0.3\ndomain: { min: [0, 0], max: [1, 1] }\nperiodic: [x]\n", 4,
              "not a multiple of l0 = 0.3");
    CHECK_BAD("dimension: 2\nlevels:\n  - { l0: 0.1, region: [0, 0.5] }\n  - { l0: 0.3 }\n"
              "domain: { min: [0, 0], max: [1.0, 1] }\nperiodic: [x]\n",
              6, "not a multiple of l0 = 0.3");
    CHECK_BAD("dimension: 2\nlevels:\n  - { l0: 0.1, region: [0, 0.5] }\n  - { l0: 0.25 }\n"
              "domain: { min: [0, 0], max: [1.2, 1] }\nperiodic: [x]\n",
              6, "not a multiple of l0 = 0.25");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\nwalls:\n"
              "  p: { type: polyline, points: [[0, 0], [0.5, 1], [0.5, 0]] }\n",
              5, "x must increase");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\nwalls:\n"
              "  c: { type: cylinder, centre: [0, 0],\n        radius: 0 }\n",
              6, "'walls.c.radius' must be > 0");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\nwalls:\n"
              "  c: { type: cylinder, centre: [0, 0], radius: -2 }\n",
              5, "must be > 0");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\n"
              "fluid:\n  - { type: box, min: [0.2, 0.2], max: [1.5, 0.5] }\n",
              5, "outside the domain");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\nwalls:\n"
              "  p: { type: plane, point: [0, 0], normal: [0, 1], nromal: [0, 1] }\n",
              5, "unknown key 'nromal'");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\nwalls:\n"
              "  p: { type: plan, point: [0, 0], normal: [0, 1] }\n",
              5, "did you mean 'plane'");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\nwalls:\n"
              "  p: { type: plane, point: [0, 0], normal: [0, 0] }\n",
              5, "non-zero vector");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\nwalls:\n"
              "  s: { type: sphere, centre: [0, 0], radius: 1 }\n",
              5, "3-D only");
    CHECK_BAD("dimension: 2\nl0: 0.1\nlevels: [ { l0: 0.1 } ]\n"
              "domain: { min: [0, 0], max: [1, 1] }\n",
              3, "not both");
    CHECK_BAD("dimension: 2\ndomain: { min: [0, 0], max: [1, 1] }\n", 1,
              "missing required key 'l0'");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\nperiodic: [q]\n", 4,
              "found 'q'");
}

/* ---- discretisation ------------------------------------------------------------------- */

static size_t count_of(const lub_particles *P, int kind, int level)
{
    size_t n = 0;
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] == kind && (level < 0 || P->level[i] == level)) n++;
    return n;
}

static void generate(const char *text, lub_geometry *g, lub_particles *P, size_t *rc)
{
    read_text(g, text);
    lub_geometry_discretise(g, P, 0.0, rc);
}

/* Square-lattice n0 of (T-4) by hand: the shells of a 2-D lattice inside re = 3.1 l0 are
 * r/l0 = 1 (4 points), sqrt2 (4), 2 (4), sqrt5 (8), sqrt8 (4), 3 (4); sqrt10 > 3.1. */
static double n0_2d_by_shells(double *lambda0_over_l0sq)
{
    const double r[] = {1, sqrt(2.0), 2, sqrt(5.0), sqrt(8.0), 3};
    const int m[] = {4, 4, 4, 8, 4, 4};
    double n0 = 0, num = 0;
    for (int i = 0; i < 6; i++) {
        double w = (1 - r[i] / 3.1) * (1 - r[i] / 3.1);
        n0 += m[i] * w;
        num += m[i] * w * r[i] * r[i];
    }
    *lambda0_over_l0sq = num / n0;
    return n0;
}

/* A plane with a layer, periodic in x: 10 columns of l0 = 0.1, wall at y = 0, dummies at
 * -0.1 and -0.2, fluid rows 0.1 .. 0.5. */
static void test_plane_layer(void)
{
    lub_geometry g;
    lub_particles P;
    size_t rc[1];
    generate("dimension: 2\nl0: 0.1\ndomain: { min: [0, -0.3], max: [1, 1] }\n"
             "periodic: [x]\n"
             "walls:\n  floor: { type: plane, point: [0, 0], normal: [0, 1] }\n"
             "fluid:\n  - { type: layer, wall: floor, thickness: 0.5 }\n",
             &g, &P, rc);
    CHECK(count_of(&P, LUB_WALL, -1) == 10);
    CHECK(count_of(&P, LUB_DUMMY, -1) == 20);
    CHECK(count_of(&P, LUB_FLUID, -1) == 50);
    CHECK(rc[0] == 50);
    CHECK(P.npatches == 1 && strcmp(P.patch_names[0], "floor") == 0);
    double xmin = 1, xmax = 0;
    int bad = 0;
    for (size_t i = 0; i < P.n; i++) {
        double x = P.x[0][i], y = P.x[1][i];
        xmin = fmin(xmin, x), xmax = fmax(xmax, x);
        /* cell-centred in x, on the rows k l0 in y */
        double qx = (x - 0.05) / 0.1, qy = y / 0.1;
        if (fabs(qx - round(qx)) > 1e-9 || fabs(qy - round(qy)) > 1e-9) bad++;
        if (P.kind[i] == LUB_WALL && fabs(y) > 1e-12) bad++;
        if (P.kind[i] == LUB_DUMMY && !(fabs(y + 0.1) < 1e-12 || fabs(y + 0.2) < 1e-12)) bad++;
        if (P.kind[i] == LUB_FLUID && !(y > 0.05 && y < 0.55)) bad++;
        if (P.x[2][i] != 0.0) bad++;
    }
    CHECK(bad == 0);
    /* periodic seam: first column at min + l0/2, last at max - l0/2: l0 apart across it */
    CHECK_NEAR(xmin, 0.05, 1e-12);
    CHECK_NEAR(xmax, 0.95, 1e-12);
    CHECK_NEAR(1.0 - xmax + xmin, 0.1, 1e-12);
    double l0sq;
    double n0 = n0_2d_by_shells(&l0sq);
    CHECK(P.nlevels == 1);
    CHECK_REL(P.levels[0].re, 0.31, 1e-14);
    CHECK_REL(P.levels[0].n0, n0, 1e-12);
    CHECK_REL(P.levels[0].lambda0, l0sq * 0.01, 1e-12);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* A 2-D tank: box [0, 1] x [0, 0.6], fluid inside, l0 = 0.1, 2 dummy layers.  Lattice
 * points within 0.2 outside or on the box: 15 x 11 = 165, less 9 x 5 = 45 inside; the wall
 * layer is the box outline, 11 x 7 - 45 = 32.  Fluid box [0, 0.5] x [0, 0.3]: 6 x 4 lattice
 * points, of which those on the walls (x = 0 or y = 0) go: 5 x 3 = 15. */
static void test_tank_2d(void)
{
    lub_geometry g;
    lub_particles P;
    generate("dimension: 2\nl0: 0.1\ndomain: { min: [-0.3, -0.3], max: [1.3, 0.9] }\n"
             "walls:\n  tank: { type: box, min: [0, 0], max: [1, 0.6], fluid: inside }\n"
             "fluid:\n  - { type: box, min: [0, 0], max: [0.5, 0.3] }\n",
             &g, &P, NULL);
    CHECK(count_of(&P, LUB_WALL, -1) == 32);
    CHECK(count_of(&P, LUB_DUMMY, -1) == 88);
    CHECK(count_of(&P, LUB_FLUID, -1) == 15);
    /* no duplicates: all pairs at least l0 apart (the lattice) */
    double dmin = INFINITY;
    for (size_t i = 0; i < P.n; i++)
        for (size_t j = i + 1; j < P.n; j++)
            dmin = fmin(dmin, hypot(P.x[0][i] - P.x[0][j], P.x[1][i] - P.x[1][j]));
    CHECK_NEAR(dmin, 0.1, 1e-12);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* The same tank made of three planes with the corner filled: floor and two side walls. */
static void test_tank_planes(void)
{
    lub_geometry g;
    lub_particles P;
    generate("dimension: 2\nl0: 0.1\ndomain: { min: [-0.2, -0.2], max: [1.2, 0.6] }\n"
             "walls:\n"
             "  floor: { type: plane, point: [0, 0], normal: [0, 1] }\n"
             "  left:  { type: plane, point: [0, 0], normal: [1, 0] }\n"
             "  right: { type: plane, point: [1, 0], normal: [-1, 0] }\n"
             "fluid:\n  - { type: box, min: [0, 0], max: [1, 0.3] }\n",
             &g, &P, NULL);
    /* lattice 15 x 9 = 135 points; fluid side x in 0.1..0.9, y in 0.1..0.6: 9 x 6 = 54;
     * the wall layer is the U: floor x 0..1 (11) + sides y 0.1..0.6 (2 x 6) = 23 */
    CHECK(count_of(&P, LUB_WALL, -1) == 23);
    CHECK(count_of(&P, LUB_DUMMY, -1) == 135 - 54 - 23);
    CHECK(count_of(&P, LUB_FLUID, -1) == 9 * 3);
    double dmin = INFINITY;
    for (size_t i = 0; i < P.n; i++)
        for (size_t j = i + 1; j < P.n; j++)
            dmin = fmin(dmin, hypot(P.x[0][i] - P.x[0][j], P.x[1][i] - P.x[1][j]));
    CHECK_NEAR(dmin, 0.1, 1e-12);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* Cylinder arc: R = 1, l0 = 0.05, range |x| <= 0.5, domain below y = 0.5 (bottom arc only).
 * Angles from the lowest point in steps l0/r: |x| = r sin(phi) <= 0.5 keeps i <= 10 on each
 * side for r = 1, 0.95 and 0.9: 21 points per layer. */
static void test_cylinder_arc(void)
{
    lub_geometry g;
    lub_particles P;
    generate("dimension: 2\nl0: 0.05\ndomain: { min: [-2, -2], max: [2, 0.5] }\n"
             "walls:\n  c: { type: cylinder, centre: [0, 0], radius: 1, range: [-0.5, 0.5] }\n",
             &g, &P, NULL);
    CHECK(count_of(&P, LUB_WALL, -1) == 21);
    CHECK(count_of(&P, LUB_DUMMY, -1) == 42);
    double ang[64];
    int n = 0, bad = 0;
    for (size_t i = 0; i < P.n; i++) {
        double r = hypot(P.x[0][i], P.x[1][i]);
        if (P.kind[i] == LUB_WALL) {
            if (fabs(r - 1.0) > 1e-12) bad++;
            ang[n++] = atan2(P.x[0][i], -P.x[1][i]);
        } else if (fabs(r - 0.95) > 1e-12 && fabs(r - 0.9) > 1e-12) {
            bad++;
        }
    }
    CHECK(bad == 0);
    /* sorted angles: neighbours exactly l0 apart along the arc */
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n; j++)
            if (ang[j] < ang[i]) {
                double t = ang[i];
                ang[i] = ang[j], ang[j] = t;
            }
    for (int i = 0; i + 1 < n; i++) CHECK_NEAR((ang[i + 1] - ang[i]) * 1.0, 0.05, 1e-12);
    lub_particles_free(&P);
    lub_geometry_free(&g);
    /* a full circle inside the domain closes with n = round(2 pi R / l0) equal steps */
    generate("dimension: 2\nl0: 0.05\ndomain: { min: [-2, -2], max: [2, 2] }\n"
             "walls:\n  c: { type: cylinder, centre: [0, 0], radius: 1 }\n",
             &g, &P, NULL);
    CHECK(count_of(&P, LUB_WALL, -1) == 126);
    double step = 2 * M_PI / 126;
    for (size_t i = 0; i + 1 < P.n && P.kind[i + 1] == LUB_WALL; i++) {
        double d = hypot(P.x[0][i + 1] - P.x[0][i], P.x[1][i + 1] - P.x[1][i]);
        CHECK_NEAR(d, 2 * sin(step / 2), 1e-12);
        CHECK(fabs(d - 0.05) < 0.005 * 0.05);
    }
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* Small wedge: fluid keeps >= 0.999 wallGap l0 from every wall and dummy particle (minimum
 * image across the periodic seam), never lies inside the cylinder, and the gap under the
 * cylinder holds the rows that keep that distance. */
static void test_wedge_gap(void)
{
    lub_geometry g;
    lub_particles P;
    size_t rc[1];
    generate("dimension: 2\nl0: 0.01\ndomain: { min: [-0.5, -0.03], max: [0.5, 0.3] }\n"
             "periodic: [x]\nwallGap: 1.5\n"
             "walls:\n  floor: { type: plane, point: [0, 0], normal: [0, 1] }\n"
             "  cyl: { type: cylinder, lowestPoint: [0, 0.05], radius: 1 }\n"
             "fluid:\n  - { type: layer, wall: floor, thickness: 0.1 }\n",
             &g, &P, rc);
    double dmin = INFINITY;
    int inside = 0;
    for (size_t i = 0; i < P.n; i++) {
        if (P.kind[i] != LUB_FLUID) continue;
        if (hypot(P.x[0][i], P.x[1][i] - 1.05) < 1.0) inside++;
        for (size_t j = 0; j < P.n; j++) {
            if (P.kind[j] == LUB_FLUID) continue;
            double dx = P.x[0][i] - P.x[0][j];
            dx -= round(dx);
            dmin = fmin(dmin, hypot(dx, P.x[1][i] - P.x[1][j]));
        }
    }
    CHECK(dmin >= 0.999 * 1.5 * 0.01);
    CHECK(inside == 0);
    /* the lattice is cell-centred in x (no column at x = 0); in the column x = 0.005 the
     * cylinder surface is at 1.05 - sqrt(1 - 0.005^2) = 0.0500125 and its nearest particles
     * at (0, 0.05), (0.01, 0.05005): rows y = 0.02 and 0.03 keep 1.5 l0 from both walls,
     * y = 0.01 and 0.04 do not */
    size_t col = 0;
    for (size_t i = 0; i < P.n; i++)
        if (P.kind[i] == LUB_FLUID && fabs(P.x[0][i] - 0.005) < 1e-9) col++;
    CHECK(col == 2);
    CHECK(rc[0] == count_of(&P, LUB_FLUID, -1));
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* Two levels, periodic in x [0, 2): fine l0 = 0.05 owns [0.5, 1.0] (10 columns), coarse
 * 0.1 the rest (15 columns); fluid layer 0.2 thick: 4 fine rows, 2 coarse rows. */
static void test_levels(void)
{
    lub_geometry g;
    lub_particles P;
    generate("dimension: 2\n"
             "levels:\n  - { l0: 0.05, region: [0.5, 1.0] }\n  - { l0: 0.1 }\n"
             "domain: { min: [0, -0.3], max: [2, 1] }\nperiodic: [x]\n"
             "walls:\n  floor: { type: plane, point: [0, 0], normal: [0, 1] }\n"
             "fluid:\n  - { type: layer, wall: floor, thickness: 0.2 }\n",
             &g, &P, NULL);
    CHECK(P.nlevels == 2);
    CHECK(count_of(&P, LUB_WALL, 0) == 10 && count_of(&P, LUB_DUMMY, 0) == 20);
    CHECK(count_of(&P, LUB_FLUID, 0) == 40);
    CHECK(count_of(&P, LUB_WALL, 1) == 15 && count_of(&P, LUB_DUMMY, 1) == 30);
    CHECK(count_of(&P, LUB_FLUID, 1) == 30);
    int bad = 0;
    for (size_t i = 0; i < P.n; i++) {
        int fine = P.x[0][i] >= 0.5 && P.x[0][i] <= 1.0;
        if (fine != (P.level[i] == 0)) bad++;
    }
    CHECK(bad == 0);
    double l0sq, n0 = n0_2d_by_shells(&l0sq);
    CHECK_REL(P.levels[0].l0, 0.05, 0);
    CHECK_REL(P.levels[1].re, 0.31, 1e-14);
    CHECK_REL(P.levels[1].n0, n0, 1e-12); /* n0 does not depend on l0 */
    CHECK_REL(P.levels[1].lambda0, l0sq * 0.01, 1e-12);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* 3-D tank: box [0, 0.4]^3, l0 = 0.1, 2 dummy layers: 9^3 = 729 lattice points within the
 * dummy shell or on the box, 27 strictly inside; wall layer 5^3 - 3^3 = 98.  Fluid box
 * [0, 0.4] x [0, 0.2] x [0, 0.4]: points not on the walls: 3 x 2 x 3 = 18. */
static void test_tank_3d(void)
{
    lub_geometry g;
    lub_particles P;
    generate("dimension: 3\nl0: 0.1\ndomain: { min: [-0.3, -0.3, -0.3], max: [0.7, 0.7, 0.7] }\n"
             "walls:\n  tank: { type: box, min: [0, 0, 0], max: [0.4, 0.4, 0.4] }\n"
             "fluid:\n  - { type: box, min: [0, 0, 0], max: [0.4, 0.2, 0.4] }\n",
             &g, &P, NULL);
    CHECK(count_of(&P, LUB_WALL, -1) == 98);
    CHECK(count_of(&P, LUB_DUMMY, -1) == 729 - 27 - 98);
    CHECK(count_of(&P, LUB_FLUID, -1) == 18);
    double l0sq;
    (void)n0_2d_by_shells(&l0sq);
    CHECK(P.levels[0].n0 > 4.178307937 * 2); /* 3-D lattice: more neighbours */
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* 3-D plane (periodic x and z), sphere and cylinder walls: surfaces at R. */
static void test_walls_3d(void)
{
    lub_geometry g;
    lub_particles P;
    generate("dimension: 3\nl0: 0.05\n"
             "domain: { min: [-1, -0.2, -1], max: [1, 1.5, 1] }\nperiodic: [x, z]\n"
             "walls:\n  floor: { type: plane, point: [0, 0, 0], normal: [0, 1, 0] }\n"
             "  ball: { type: sphere, centre: [0.5, 0.8, 0], radius: 0.3 }\n"
             "  shaft: { type: cylinder, centre: [-0.5, 0.8, 0], axis: [0, 0, 1], "
             "radius: 0.2 }\n"
             "fluid:\n  - { type: layer, wall: floor, thickness: 0.1 }\n",
             &g, &P, NULL);
    int bad = 0;
    size_t nb = 0, ns = 0, nf = 0;
    for (size_t i = 0; i < P.n; i++) {
        double *c = (double[]){P.x[0][i], P.x[1][i], P.x[2][i]};
        if (P.kind[i] != LUB_WALL) continue;
        if (P.patch[i] == 1) {
            nb++;
            if (fabs(sqrt(pow(c[0] - 0.5, 2) + pow(c[1] - 0.8, 2) + c[2] * c[2]) - 0.3) > 1e-12)
                bad++;
        } else if (P.patch[i] == 2) {
            ns++;
            if (fabs(hypot(c[0] + 0.5, c[1] - 0.8) - 0.2) > 1e-12) bad++;
        } else {
            nf++;
        }
    }
    CHECK(bad == 0);
    CHECK(nf == 40 * 40); /* periodic 2 / 0.05 in x and z */
    /* sphere: about 4 pi R^2 / l0^2 = 452 points; cylinder 40 rings of round(2 pi 0.2/0.05) */
    CHECK(nb > 400 && nb < 500);
    CHECK(ns == 40 * 25);
    CHECK(count_of(&P, LUB_FLUID, -1) == 40 * 40 * 2);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* A roller of finite length (3-D cylinder with `length`): its signed distance and section
 * against the closed forms, its particles counted by hand, and the fluid around it against
 * the volume of the solid.  R = 0.5, length 1 along z, l0 = 0.1, the lattice through 0 in
 * every direction (domain from -2.05): rings of radius 0.5, 0.4, 0.3 of round(2 pi r / l0)
 * = 31, 25, 19 points at the 11 lattice z from -0.5 to 0.5; on the end planes z = +-0.5,
 * +-0.4, +-0.3 the lattice points inside radius R - 2.5 l0 = 0.25: i^2 + j^2 <= 6.25 for
 * |i|, |j| <= 2, the 25 but the 4 corners (8 > 6.25): 21. */
static void test_roller(void)
{
    lub_geometry g;
    lub_particles P;
    size_t rc[1];
    generate("dimension: 3\nl0: 0.1\n"
             "domain: { min: [-2.05, -2.05, -2.05], max: [2.05, 2.05, 2.05] }\n"
             "walls:\n  roller: { type: cylinder, centre: [0, 0, 0], radius: 0.5, length: 1 }\n"
             "fluid:\n  - { type: box, min: [-1, -1, -1], max: [1, 1, 1] }\n",
             &g, &P, rc);
    const lub_wall *w = &g.walls[0];
    /* distance: beside the round surface, beyond an end, off the rim, inside */
    CHECK_NEAR(lub_wall_distance(w, (double[]){0.8, 0, 0}, 3), 0.3, 1e-14);
    CHECK_NEAR(lub_wall_distance(w, (double[]){0, 0.2, -0.9}, 3), 0.4, 1e-14);
    CHECK_NEAR(lub_wall_distance(w, (double[]){0, -0.8, 0.9}, 3), 0.5, 1e-14);
    CHECK_NEAR(lub_wall_distance(w, (double[]){0.1, 0, 0.3}, 3), -0.2, 1e-14);
    CHECK_NEAR(lub_wall_distance(w, (double[]){0.35, 0, 0.1}, 3), -0.15, 1e-14);
    double y;
    CHECK(lub_wall_height(w, 0.3, 1, &y) && fabs(y + 0.4) < 1e-14); /* the z = 0 section */
    size_t rings = 11 * (31 + 25 + 19), ends = 2 * 3 * 21;
    size_t nw = 0, nd = 0, bad = 0;
    for (size_t i = 0; i < P.n; i++) {
        if (P.kind[i] == LUB_FLUID) continue;
        double x = P.x[0][i], yy = P.x[1][i], z = P.x[2][i], r = hypot(x, yy);
        /* depth behind the surface: the smaller of the radial and the axial one */
        double depth = fmin(0.5 - r, 0.5 - fabs(z));
        if (depth < -1e-12 || depth > 0.2 + 1e-12) bad++;
        if ((P.kind[i] == LUB_WALL) != (depth < 1e-9)) bad++;
        if (P.kind[i] == LUB_WALL)
            nw++;
        else
            nd++;
    }
    CHECK(bad == 0);
    CHECK(nw + nd == rings + ends);
    /* walls: the outer rings, the inner rings on the end planes, the end grids' outer layer */
    CHECK(nw == 11 * 31 + 2 * (25 + 19) + 2 * 21);
    CHECK(lub_geometry_estimate(&g) >= (double)P.n);
    /* the fluid: the box's 21^3 lattice points but the solid and a shell of up to 1 l0
     * (wallGap) around it, between the solids grown by 0.4 l0 and by 1.1 l0 */
    const double l0 = 0.1, R = 0.5, L = 1.0;
    double out = (double)(21 * 21 * 21) - (double)rc[0];
    CHECK(out * pow(l0, 3) > M_PI * pow(R + 0.4 * l0, 2) * (L + 0.8 * l0));
    CHECK(out * pow(l0, 3) < M_PI * pow(R + 1.1 * l0, 2) * (L + 2.2 * l0));
    CHECK(count_of(&P, LUB_FLUID, -1) == rc[0]);
    lub_particles_free(&P);
    lub_geometry_free(&g);

    /* the lowest point, a section beside the roller (no height), an axis along x */
    read_text(&g, "dimension: 3\nl0: 0.1\ndomain: { min: [-3, -3, -3], max: [3, 3, 3] }\n"
                  "walls:\n  a: { type: cylinder, lowestPoint: [0, 0.1, 2], radius: 1, "
                  "length: 1 }\n"
                  "  b: { type: cylinder, centre: [0, 0, 0], axis: [1, 0, 0], radius: 1, "
                  "length: 2 }\n");
    CHECK(!lub_wall_height(&g.walls[0], 0.0, 1, &y)); /* z = 0 lies beyond its end at 1.5 */
    CHECK(lub_wall_height(&g.walls[1], 0.9, 1, &y) && fabs(y + 1) < 1e-14);
    CHECK(!lub_wall_height(&g.walls[1], 1.1, 1, &y));
    CHECK_NEAR(lub_wall_distance(&g.walls[1], (double[]){1.5, 0, 0}, 3), 0.5, 1e-14);
    lub_geometry_free(&g);

    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [-1, -1], max: [1, 1] }\nwalls:\n"
              "  c: { type: cylinder, centre: [0, 0], radius: 0.5, length: 1 }\n",
              5, "'length' makes a 3-D roller");
    CHECK_BAD("dimension: 3\nl0: 0.1\ndomain: { min: [-1, -1, -1], max: [1, 1, 1] }\nwalls:\n"
              "  c: { type: cylinder, centre: [0, 0, 0], radius: 0.5, length: 1,\n"
              "       fluid: inside }\n",
              5, "needs the fluid outside");
    CHECK_BAD("dimension: 3\nl0: 0.1\ndomain: { min: [-1, -1, -1], max: [1, 1, 1] }\nwalls:\n"
              "  c: { type: cylinder, centre: [0, 0, 0], radius: 0.5, length: -1 }\n",
              5, "length");
    /* body-fitted fluid rows (fluidLayers) are for a whole, infinitely long cylinder */
    CHECK_BAD(
        "dimension: 3\nl0: 0.1\ndomain: { min: [-1, -1, -1], max: [1, 1, 1] }\nwalls:\n"
        "  c: { type: cylinder, centre: [0, 0, 0], radius: 0.5, length: 1, fluidLayers: 2 }\n",
        5, "not a roller of finite length");
    read_text(&g, "dimension: 3\nl0: 0.1\n"
                  "domain: { min: [-2.05, -2.05, -2.05], max: [2.05, 2.05, 2.05] }\n"
                  "walls:\n  roller: { type: cylinder, centre: [0, 0, 0], radius: 0.5, "
                  "length: 1.05 }\n");
    CHECK_FATAL(lub_geometry_discretise(&g, &P, 0.0, NULL), "end z = -0.525 is not on the");
    lub_geometry_free(&g);
}

/* Bad input found while discretising: empty region, off-lattice wall, too many particles. */
static void test_bad_discretise(void)
{
    lub_geometry g;
    lub_particles P;
    read_text(&g, "dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\n"
                  "walls:\n  floor: { type: plane, point: [0, 2], normal: [0, 1] }\n"
                  "fluid:\n  - { type: layer, wall: floor, thickness: 0.5 }\n");
    CHECK_FATAL(lub_geometry_discretise(&g, &P, 0.0, NULL), "has no particles");
    CHECK_STR(test_last_error, ":7:");
    lub_geometry_free(&g);
    read_text(&g, "dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\n"
                  "walls:\n  floor: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                  "  cyl: { type: cylinder, centre: [0.5, 0.5], radius: 2, fluid: outside }\n"
                  "fluid:\n  - { type: layer, wall: floor, thickness: 0.5 }\n");
    CHECK_FATAL(lub_geometry_discretise(&g, &P, 0.0, NULL), "has no particles");
    lub_geometry_free(&g);
    read_text(&g, "dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\n"
                  "walls:\n  floor: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                  "  lid: { type: plane, point: [0, 0.55], normal: [0, -1] }\n");
    CHECK_FATAL(lub_geometry_discretise(&g, &P, 0.0, NULL), "not on the particle lattice");
    CHECK_STR(test_last_error, ":6:");
    lub_geometry_free(&g);
    read_text(&g, "dimension: 3\nl0: 1e-7\ndomain: { min: [0, 0, 0], max: [1, 1, 1] }\n");
    CHECK_FATAL(lub_geometry_discretise(&g, &P, 0.0, NULL), "l0 = 1e-07 over the domain");
    CHECK_STR(test_last_error, ":2:");
    lub_geometry_free(&g);
    /* the limit follows the memory given: 10 x 10 lattice, 1 kB is too little */
    read_text(&g, "dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\n");
    CHECK_FATAL(lub_geometry_discretise(&g, &P, 1000.0, NULL), "more than the");
    lub_geometry_free(&g);
}

/* Segment and polyline walls: wall points on the curve, n = round(length / l0) equal steps
 * (segment (0,0)-(1,0.5): length 1.118, 11 steps, 12 points), dummies 1 and 2 l0 behind. */
static void test_curves(void)
{
    lub_geometry g;
    lub_particles P;
    generate("dimension: 2\nl0: 0.1\ndomain: { min: [-1, -1], max: [3, 2] }\n"
             "walls:\n  s: { type: segment, from: [0, 0], to: [1, 0.5] }\n"
             "  p: { type: polyline, points: [[1.5, 0], [2, 0.5], [2.5, 0]], fluid: below }\n",
             &g, &P, NULL);
    size_t nw[2] = {0, 0}, nd[2] = {0, 0};
    int bad = 0;
    double step = hypot(1, 0.5) / 11;
    for (size_t i = 0; i < P.n; i++) {
        int w = P.patch[i];
        double d = lub_wall_distance(&g.walls[w], (double[]){P.x[0][i], P.x[1][i]}, 2);
        if (P.kind[i] == LUB_WALL) {
            nw[w]++;
            if (fabs(d) > 1e-12) bad++;
            if (w == 0) { /* on the lattice of the segment: s = k step from `from` */
                double s = hypot(P.x[0][i], P.x[1][i]) / step;
                if (fabs(s - round(s)) > 1e-9) bad++;
            }
        } else {
            nd[w]++;
            if (w == 0 && !(fabs(d + 0.1) < 1e-12 || fabs(d + 0.2) < 1e-12)) bad++;
            if (w == 1 && !(d < -0.05 && d > -0.2 - 1e-12)) bad++;
        }
    }
    CHECK(bad == 0);
    CHECK(nw[0] == 12 && nd[0] == 24);
    /* polyline: length 2 sqrt(0.5) = 1.414, 14 steps, 15 points */
    CHECK(nw[1] == 15);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* Fluid between a floor and a cylinder (R = 1, lowest point 0.1 above the floor) up to
 * 0.3, l0 = 0.02, periodic x in [-1, 1).  Column x = 0.01: cylinder surface at
 * 1.1 - sqrt(1 - 0.01^2) = 0.10005, the nearest cylinder particles at (0, 0.1) and
 * (0.02, 0.1002): rows 0.02 .. 0.08 keep one l0 from both walls (4 rows).  Column
 * x = 0.99: the cylinder is at 0.96, so the rows 0.02 .. 0.30 are filled (15 rows). */
static void test_between(void)
{
    lub_geometry g;
    lub_particles P;
    size_t rc[1];
    generate("dimension: 2\nl0: 0.02\ndomain: { min: [-1, -0.06], max: [1, 1.2] }\n"
             "periodic: [x]\n"
             "walls:\n  floor: { type: plane, point: [0, 0], normal: [0, 1] }\n"
             "  cyl: { type: cylinder, lowestPoint: [0, 0.1], radius: 1 }\n"
             "fluid:\n  - { type: between, lower: floor, upper: cyl, height: 0.3 }\n",
             &g, &P, rc);
    size_t c1 = 0, c2 = 0;
    int bad = 0;
    for (size_t i = 0; i < P.n; i++) {
        if (P.kind[i] != LUB_FLUID) continue;
        double x = P.x[0][i], y = P.x[1][i];
        if (fabs(x - 0.01) < 1e-9) c1++;
        if (fabs(x - 0.99) < 1e-9) c2++;
        if (y > 0.3 + 1e-9 || y < 0.02 - 1e-9) bad++;
        if (hypot(x, y - 1.1) < 1.0) bad++;
    }
    CHECK(bad == 0);
    CHECK(c1 == 4);
    CHECK(c2 == 15);
    CHECK(rc[0] == count_of(&P, LUB_FLUID, -1));
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* Walls at the level that owns them: a cylinder arc (R = 1, lowest point (0, 0.05)) with
 * fine l0 = 0.01 in [-0.2, 0.2] and coarse 0.04 elsewhere; arc neighbours are l0 of their
 * level apart (angles from the lowest point in steps l0 / R), all at radius R. */
static void test_levels_arc(void)
{
    lub_geometry g;
    lub_particles P;
    generate("dimension: 2\n"
             "levels:\n  - { l0: 0.01, region: [-0.2, 0.2] }\n  - { l0: 0.04 }\n"
             "domain: { min: [-0.8, -0.2], max: [0.8, 0.5] }\nperiodic: [x]\n"
             "walls:\n  cyl: { type: cylinder, lowestPoint: [0, 0.05], radius: 1 }\n",
             &g, &P, NULL);
    double ang[2][256];
    int n[2] = {0, 0}, bad = 0;
    for (size_t i = 0; i < P.n; i++) {
        if (P.kind[i] != LUB_WALL) continue;
        double x = P.x[0][i], y = P.x[1][i] - 1.05;
        int k = P.level[i];
        if (fabs(hypot(x, y) - 1.0) > 1e-12) bad++;
        if ((fabs(x) <= 0.2) != (k == 0)) bad++;
        if (n[k] < 256) ang[k][n[k]++] = atan2(x, -y);
    }
    CHECK(bad == 0);
    /* fine: |x| = sin(phi) <= 0.2 -> phi <= 0.20136, i <= 20 each side: 41 points;
     * coarse: sin(phi) > 0.2 -> i >= 6; domain top y = 0.5 -> cos(phi) >= 0.55 ->
     * phi <= 0.9884; domain side |x| <= 0.8 -> phi <= 0.9273: i = 6 .. 23, 36 points */
    CHECK(n[0] == 41);
    CHECK(n[1] == 36);
    for (int k = 0; k < 2; k++) {
        for (int i = 0; i < n[k]; i++)
            for (int j = i + 1; j < n[k]; j++)
                if (ang[k][j] < ang[k][i]) {
                    double t = ang[k][i];
                    ang[k][i] = ang[k][j], ang[k][j] = t;
                }
        double l0 = k ? 0.04 : 0.01;
        for (int i = 0; i + 1 < n[k]; i++) {
            double d = ang[k][i + 1] - ang[k][i];
            if (k == 1 && d > 0.1) continue; /* the fine part between the coarse sides */
            CHECK_NEAR(d, l0, 1e-12);
        }
    }
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* ---- closed polygons ------------------------------------------------------------------ */

/* Reading: orientation (stored counter-clockwise whatever the input), the repeated closing
 * vertex dropped, the bad polygons refused at their line; the wall functions of the pad
 * (0, 0.2), (4, 0.1), (4, 1), (0, 1) by hand: lower surface y = 0.2 - 0.025 x. */
static void test_polygon_read(void)
{
    lub_geometry g;
    read_text(&g, "dimension: 2\nl0: 0.1\ndomain: { min: [-1, -1], max: [5, 2] }\nwalls:\n"
                  "  pad: { type: polygon, points: [[0, 1], [4, 1], [4, 0.1], [0, 0.2], [0, 1]] }\n"
                  "  tri: { type: polygon, points: [[1, -0.5], [2, -0.5], [1.5, -0.2]] }\n");
    const lub_wall *w = &g.walls[0];
    CHECK(w->type == LUB_WALL_POLYGON && w->npts == 4);
    double area2 = 0;
    for (int i = 0; i < 4; i++) {
        int j = (i + 1) % 4;
        area2 += w->pts[2 * i] * w->pts[2 * j + 1] - w->pts[2 * j] * w->pts[2 * i + 1];
    }
    CHECK_NEAR(area2, 2 * 4 * (1 - 0.15), 1e-12); /* counter-clockwise: positive */
    CHECK(g.walls[1].npts == 3);
    double y;
    CHECK(lub_wall_height(w, 2.0, 1, &y) && fabs(y - 0.15) < 1e-15);
    CHECK(lub_wall_height(w, 2.0, 0, &y) && y == 1.0);
    CHECK(lub_wall_height(w, 0.0, 1, &y) && fabs(y - 0.2) < 1e-15); /* the front face's foot */
    CHECK(lub_wall_height(w, 4.0, 1, &y) && fabs(y - 0.1) < 1e-15);
    CHECK(!lub_wall_height(w, 4.5, 1, &y));
    double k = sqrt(1 + 0.025 * 0.025);
    CHECK_NEAR(lub_wall_distance(w, (double[]){2, 0.5}, 2), -0.35 / k, 1e-14);
    CHECK_NEAR(lub_wall_distance(w, (double[]){2, 0}, 2), 0.15 / k, 1e-14);
    CHECK_NEAR(lub_wall_distance(w, (double[]){5, 1.5}, 2), hypot(1, 0.5), 1e-14);
    CHECK_NEAR(lub_wall_distance(w, (double[]){0.1, 0.9}, 2), -0.1, 1e-14);
    /* translated by (0.5, -0.05): the lower surface at x = 2.5 is 0.15 - 0.05 */
    lub_wall m;
    m.pts = lub_malloc(8 * sizeof *m.pts);
    lub_wall_translate(&m, w, (double[]){0.5, -0.05, 0});
    CHECK(lub_wall_height(&m, 2.5, 1, &y) && fabs(y - 0.1) < 1e-15);
    CHECK(m.pts != w->pts && w->pts[0] == 0.0);
    free(m.pts);
    lub_geometry_free(&g);

    const char *head = "dimension: 2\nl0: 0.1\ndomain: { min: [-1, -1], max: [5, 2] }\nwalls:\n";
    char text[512];
#define POLY_BAD(points, sub)                                                                      \
    snprintf(text, sizeof text, "%s  p: { type: polygon, points: %s }\n", head, points);           \
    CHECK_BAD(text, 5, sub)
    POLY_BAD("[[0, 0], [1, 0]]", "needs at least 3 different points, found 2");
    POLY_BAD("[[0, 0], [1, 0], [0, 0]]", "needs at least 3 different points, found 2");
    POLY_BAD("[[0, 0], [1, 1], [1, 0], [0, 1]]", "cross or touch");
    POLY_BAD("[[0, 0], [2, 0], [2, 1], [1, 0], [1, -1]]", "cross or touch");
    POLY_BAD("[[0, 0], [1, 0], [1, 0], [0, 1]]", "point 2 repeats point 1");
    POLY_BAD("[[0, 0], [2, 0], [1, 0], [1, 1]]", "the edges at point 1 fold back");
    POLY_BAD("[[0, 0], [1], [0, 1]]", "point 1 must be [x, y]");
#undef POLY_BAD
    CHECK_BAD("dimension: 3\nl0: 0.1\ndomain: { min: [-1, -1, -1], max: [5, 2, 1] }\nwalls:\n"
              "  p: { type: polygon, points: [[0, 0], [1, 0], [0, 1]] }\n",
              5, "type 'polygon' is 2-D only");
}

/* Length along the closed boundary of polygon w (counter-clockwise from vertex 0) of the
 * point x on it: the edge nearest to x, computed here for the test. */
static double boundary_arc(const lub_wall *w, const double *x)
{
    double s = 0, best = INFINITY, at = 0;
    for (int i = 0; i < w->npts; i++) {
        const double *a = w->pts + 2 * i, *b = w->pts + 2 * ((i + 1) % w->npts);
        double tx = b[0] - a[0], ty = b[1] - a[1], len = hypot(tx, ty);
        double q = ((x[0] - a[0]) * tx + (x[1] - a[1]) * ty) / len;
        q = q < 0 ? 0 : q > len ? len : q;
        double d = hypot(a[0] + q * tx / len - x[0], a[1] + q * ty / len - x[1]);
        if (d < best - 1e-12) best = d, at = s + q;
        s += len;
    }
    return at;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The checks every polygon body must pass (patch w of P, level lev, spacing l0, dummy
 * layers L): wall particles on the boundary (round-off), consecutive along it between
 * gap_lo and gap_hi apart (the closing step included, so no gap anywhere), no two particles
 * of the body within 0.5 l0, dummies inside at depths from l0 to L l0 / sin(45 deg) (the
 * mitre of a right-angled concave corner), no fluid inside the body or closer than 0.999 l0
 * to a particle of it.  Returns the number of wall particles. */
static size_t check_polygon_body(const lub_geometry *g, const lub_particles *P, int w, int lev,
                                 double l0, double gap_lo, double gap_hi)
{
    const lub_wall *pw = &g->walls[w];
    int L = g->dummy_layers, bad_on = 0, bad_dummy = 0, bad_fluid = 0;
    double perimeter = 0;
    for (int i = 0; i < pw->npts; i++) {
        int j = (i + 1) % pw->npts;
        perimeter +=
            hypot(pw->pts[2 * j] - pw->pts[2 * i], pw->pts[2 * j + 1] - pw->pts[2 * i + 1]);
    }
    double *s = lub_malloc((P->n + 1) * sizeof *s), dmin = INFINITY;
    size_t nw = 0;
    for (size_t i = 0; i < P->n; i++) {
        double x[2] = {P->x[0][i], P->x[1][i]}, d = lub_wall_distance(pw, x, 2);
        if (P->kind[i] == LUB_FLUID) {
            if (d < 0) bad_fluid++;
            continue;
        }
        if (P->patch[i] != w || P->level[i] != lev) continue;
        if (P->kind[i] == LUB_WALL) {
            if (fabs(d) > 1e-12 * (1 + perimeter)) bad_on++;
            s[nw++] = boundary_arc(pw, x);
        } else if (!(d <= -l0 * (1 - 1e-9) && d >= -L * l0 * sqrt(2.0) * (1 + 1e-9))) {
            bad_dummy++;
        }
        for (size_t j = 0; j < P->n; j++) {
            if (j == i) continue;
            double r = hypot(P->x[0][j] - x[0], P->x[1][j] - x[1]);
            if (P->kind[j] == LUB_FLUID) {
                if (r < 0.999 * l0) bad_fluid++;
            } else if (P->patch[j] == w) {
                dmin = fmin(dmin, r);
            }
        }
    }
    CHECK(bad_on == 0);
    CHECK(bad_dummy == 0);
    CHECK(bad_fluid == 0);
    CHECK(dmin >= 0.5 * l0);
    qsort(s, nw, sizeof *s, cmp_double);
    double glo = INFINITY, ghi = 0;
    for (size_t i = 0; i < nw; i++) {
        double gap = i + 1 < nw ? s[i + 1] - s[i] : s[0] + perimeter - s[i];
        glo = fmin(glo, gap), ghi = fmax(ghi, gap);
    }
    if (!(glo >= gap_lo - 1e-12 && ghi <= gap_hi + 1e-12))
        printf("  spacing along the boundary from %.15g to %.15g, expected [%g, %g]\n", glo, ghi,
               gap_lo, gap_hi);
    CHECK(glo >= gap_lo - 1e-12 && ghi <= gap_hi + 1e-12);
    free(s);
    return nw;
}

/* PND (T-4) at particle i over all particles, with re = 3.1 l0 and w = (1 - r/re)^2. */
static double pnd_at(const lub_particles *P, size_t i, double l0)
{
    double re = 3.1 * l0, n = 0;
    for (size_t j = 0; j < P->n; j++) {
        double r = hypot(P->x[0][j] - P->x[0][i], P->x[1][j] - P->x[1][i]);
        if (j != i && r < re) n += (1 - r / re) * (1 - r / re);
    }
    return n;
}

/* A square of side 2 = 20 l0 about (0.52, 0.31), turned by 30 degrees, given clockwise from
 * an arbitrary corner, in oil: 4 x 20 wall particles exactly l0 apart along the boundary
 * (the perimeter over l0), the dummy layers the squares of side 18 and 16 l0 inside
 * (4 x 18 + 4 x 16 = 136); the fluid lattice stays out of it. */
static void test_polygon_square(void)
{
    lub_geometry g;
    lub_particles P;
    char text[1024], pts[512] = "";
    double c = cos(M_PI / 6), s = sin(M_PI / 6);
    const double corner[4][2] = {{1, 1}, {1, -1}, {-1, -1}, {-1, 1}}; /* clockwise */
    for (int k = 0; k < 4; k++) {
        int i = (k + 2) % 4; /* start at the third corner */
        double x = 0.52 + c * corner[i][0] - s * corner[i][1];
        double y = 0.31 + s * corner[i][0] + c * corner[i][1];
        snprintf(pts + strlen(pts), sizeof pts - strlen(pts), "%s[%.17g, %.17g]", k ? ", " : "", x,
                 y);
    }
    snprintf(text, sizeof text,
             "dimension: 2\nl0: 0.1\ndomain: { min: [-2, -2], max: [3, 3] }\nwalls:\n"
             "  sq: { type: polygon, points: [%s] }\n"
             "fluid:\n  - { type: box, min: [-2, -2], max: [3, 3] }\n",
             pts);
    generate(text, &g, &P, NULL);
    CHECK(count_of(&P, LUB_WALL, -1) == 80);
    CHECK(count_of(&P, LUB_DUMMY, -1) == 136);
    CHECK(check_polygon_body(&g, &P, 0, 0, 0.1, 0.1, 0.1) == 80);
    CHECK(count_of(&P, LUB_FLUID, -1) > 1500);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* A concave L-shape, [0, 3] x [0, 1] and [0, 1] x [0, 2.5], in oil, l0 = 0.1 and the
 * lattice through 0: the wall particles are the 2 (3 + 2.5) / l0 = 110 lattice points of
 * the boundary, dummy layer j the L-shape moved j l0 in (its concave corner along the
 * mitre to (1 - j l0, 1 - j l0)) with 2 (3 + 2.5) / l0 - 8 j points: 102 + 94.  The layers
 * fill the body like the lattice: the PND (T-4) of every wall particle is n0 of the full
 * lattice less the points 3 l0 deep, which no layer reaches (w(3 l0) for a particle on a
 * straight edge, 2 w(3 l0) at the concave corner, none at a convex one), never more. */
static void test_polygon_concave(void)
{
    lub_geometry g;
    lub_particles P;
    generate("dimension: 2\nl0: 0.1\ndomain: { min: [-1.05, -1.05], max: [4.05, 3.55] }\n"
             "walls:\n  ell: { type: polygon, points: [[1, 2.5], [0, 2.5], [0, 0], [3, 0], "
             "[3, 1], [1, 1]] }\n"
             "fluid:\n  - { type: box, min: [-1.05, -1.05], max: [4.05, 3.55] }\n",
             &g, &P, NULL);
    CHECK(count_of(&P, LUB_WALL, -1) == 110);
    CHECK(count_of(&P, LUB_DUMMY, -1) == 102 + 94);
    CHECK(check_polygon_body(&g, &P, 0, 0, 0.1, 0.1, 0.1) == 110);
    double n0 = P.levels[0].n0, w3 = (1 - 3 / 3.1) * (1 - 3 / 3.1);
    int bad = 0, corner = 0;
    for (size_t i = 0; i < P.n; i++) {
        if (P.kind[i] != LUB_WALL) continue;
        double n = pnd_at(&P, i, 0.1), x = P.x[0][i], y = P.x[1][i];
        int concave = fabs(x - 1) < 1e-9 && fabs(y - 1) < 1e-9;
        int convex = 0;
        const double vx[5][2] = {{0, 0}, {3, 0}, {3, 1}, {1, 2.5}, {0, 2.5}};
        for (int k = 0; k < 5; k++) convex |= hypot(x - vx[k][0], y - vx[k][1]) < 1e-9;
        double missing = concave ? 2 * w3 : convex ? 0 : w3;
        /* a straight-edge particle within 3 l0 of a corner may miss less: between */
        if (!(n <= n0 * (1 + 1e-12) && n >= n0 - missing - 1e-9 * n0)) bad++;
        if (concave) {
            corner++;
            CHECK_NEAR(n, n0 - 2 * w3, 1e-9 * n0);
        }
    }
    CHECK(bad == 0);
    CHECK(corner == 1);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* The pad of an inclined slider: (0, 0.2), (4, 0.1), (4, 1), (0, 1), given clockwise, over a
 * plane with oil between.  Wall particles: round(length / l0) steps per edge, 40 + 9 + 40 + 8
 * = 97 (the perimeter 97.0125 l0), l0 apart but on the inclined face 4.00125 / 40 =
 * 1.0003 l0; dummies inside; no oil in the pad; the gap of the plane to the pad's lower
 * face filled (the column x = 2.05: the face at 0.14875, oil at 0.1 only, the rows one l0
 * from both walls). */
static void test_polygon_pad(void)
{
    lub_geometry g;
    lub_particles P;
    size_t rc[1];
    generate("dimension: 2\nl0: 0.1\ndomain: { min: [-1, -0.3], max: [5, 2] }\n"
             "walls:\n  floor: { type: plane, point: [0, -0.1], normal: [0, 1] }\n"
             "  pad: { type: polygon, points: [[0, 1], [4, 1], [4, 0.1], [0, 0.2]] }\n"
             "fluid:\n  - { type: layer, wall: floor, thickness: 0.6 }\n",
             &g, &P, rc);
    size_t nw = 0;
    for (size_t i = 0; i < P.n; i++) nw += P.kind[i] == LUB_WALL && P.patch[i] == 1;
    CHECK(nw == 97);
    CHECK(check_polygon_body(&g, &P, 1, 0, 0.1, 0.1, 4.00125 / 40 * (1 + 1e-12)) == 97);
    size_t col = 0;
    for (size_t i = 0; i < P.n; i++)
        if (P.kind[i] == LUB_FLUID && fabs(P.x[0][i] - 2.05) < 1e-9) col++;
    CHECK(col == 1);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* A polygon across two levels: the block [0, 4] x [0, 1], fine l0 = 0.05 in [1, 2], coarse
 * 0.1 elsewhere.  Each level has the body where it owns x, sampled at its own l0: fine
 * wall particles at x = 1, 1.05 .. 2 on the lower and upper face (2 x 21), coarse ones on
 * the rest of the boundary, 2 (40 + 10) - 2 x 11 = 78; the fine level's particles of the
 * range [0.775, 2.225] (the multi-resolution overlap: discretise_range), 2 x 29 wall
 * particles (x = 0.8 .. 2.2), lie on the same boundary l0 apart. */
static void test_polygon_levels(void)
{
    lub_geometry g;
    lub_particles P, R;
    generate("dimension: 2\nlevels:\n  - { l0: 0.05, region: [1, 2] }\n  - { l0: 0.1 }\n"
             "domain: { min: [-1, -1], max: [5, 2] }\n"
             "walls:\n  block: { type: polygon, points: [[0, 0], [4, 0], [4, 1], [0, 1]] }\n",
             &g, &P, NULL);
    CHECK(count_of(&P, LUB_WALL, 0) == 42);
    CHECK(count_of(&P, LUB_WALL, 1) == 78);
    int bad = 0;
    for (size_t i = 0; i < P.n; i++) {
        double x = P.x[0][i];
        if ((x >= 1 && x <= 2) != (P.level[i] == 0)) bad++;
        if (P.kind[i] == LUB_WALL &&
            fabs(lub_wall_distance(&g.walls[0], (double[]){x, P.x[1][i]}, 2)) > 1e-12)
            bad++;
    }
    CHECK(bad == 0);
    lub_geometry_discretise_range(&g, 0, 0.775, 2.225, &R);
    CHECK(count_of(&R, LUB_WALL, 0) == 58);
    bad = 0;
    for (size_t i = 0; i < R.n; i++) {
        double x = R.x[0][i], y = R.x[1][i];
        if (R.kind[i] == LUB_WALL) {
            double q = x / 0.05;
            if (fabs(q - round(q)) > 1e-9 || !(fabs(y) < 1e-12 || fabs(y - 1) < 1e-12)) bad++;
        } else if (R.kind[i] == LUB_DUMMY &&
                   !(lub_wall_distance(&g.walls[0], (double[]){x, y}, 2) < -0.05 * (1 - 1e-9))) {
            bad++;
        }
    }
    CHECK(bad == 0);
    lub_particles_free(&R);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* A disordered start (jitter): a channel of 20 x 20 lattice points between two planes,
 * periodic in x, amplitude 0.25.  Each fluid particle lies within 0.25 l0 of its own
 * lattice point (the nearest one, since the amplitude is below l0/2), off it for almost
 * all, inside the channel and at least (1 - 0.25) l0 from the wall rows; the count is the
 * lattice's.  The displacement is uniform in the disk of radius r = 0.25 l0: its mean is 0
 * (standard deviation of the mean of one component r/(2 sqrt N) = 0.025 r for N = 400) and
 * its mean square is r^2/2 (standard deviation of the mean r^2/sqrt(12 N) = 0.0144 r^2):
 * checked to 5 standard deviations.  The same seed gives the same particles, another seed
 * others.  Bad amplitudes and levels are refused. */
static const char *jitter_channel(double amplitude, long seed, char *buf, size_t n)
{
    snprintf(buf, n,
             "dimension: 2\nl0: 0.1\ndomain: { min: [0, -0.3], max: [2, 2.4] }\n"
             "periodic: [x]\n"
             "walls:\n  lower: { type: plane, point: [0, 0], normal: [0, 1] }\n"
             "  upper: { type: plane, point: [0, 2.1], normal: [0, -1] }\n"
             "fluid:\n  - { type: box, min: [0, 0], max: [2, 2.1] }\n"
             "jitter: { amplitude: %g, seed: %ld }\n",
             amplitude, seed);
    return buf;
}

static void test_jitter(void)
{
    char text[1024];
    lub_geometry g, g2, g3;
    lub_particles P, P2, P3;
    generate(jitter_channel(0.25, 7, text, sizeof text), &g, &P, NULL);
    CHECK_NEAR(g.jitter, 0.25, 0);
    CHECK(g.jitter_seed == 7);
    CHECK(count_of(&P, LUB_FLUID, -1) == 400);
    CHECK(count_of(&P, LUB_WALL, -1) == 40);
    const double l0 = 0.1, r = 0.25 * l0;
    double sx = 0, sy = 0, s2 = 0, dmax = 0, ymin = 1e9, ymax = -1e9;
    int n = 0, on_lattice = 0, outside = 0;
    for (size_t i = 0; i < P.n; i++) {
        if (P.kind[i] != LUB_FLUID) continue;
        double x = P.x[0][i], y = P.x[1][i];
        if (x < 0 || x >= 2) outside++;
        /* nearest lattice point: columns at (i + 1/2) l0 (periodic), rows at k l0 */
        double dx = x - (floor(x / l0) + 0.5) * l0, dy = y - round(y / l0) * l0;
        double d = sqrt(dx * dx + dy * dy);
        dmax = fmax(dmax, d);
        if (d < 1e-3 * r) on_lattice++;
        sx += dx, sy += dy, s2 += d * d, n++;
        ymin = fmin(ymin, y), ymax = fmax(ymax, y);
    }
    printf("  jitter 0.25: %d particles, largest displacement %.4f l0, mean (%.4f, %.4f) r, "
           "mean square %.4f r^2, y in [%.4f, %.4f]\n",
           n, dmax / l0, sx / n / r, sy / n / r, s2 / n / (r * r), ymin, ymax);
    CHECK(outside == 0);
    CHECK(dmax <= r * (1 + 1e-12));
    CHECK(on_lattice <= 2);
    CHECK(fabs(sx / n) < 0.125 * r && fabs(sy / n) < 0.125 * r);
    CHECK(fabs(s2 / n / (r * r) - 0.5) < 0.072);
    CHECK(ymin >= 0.75 * l0 - 1e-12 && ymax <= 2.1 - 0.75 * l0 + 1e-12);

    generate(jitter_channel(0.25, 7, text, sizeof text), &g2, &P2, NULL);
    generate(jitter_channel(0.25, 8, text, sizeof text), &g3, &P3, NULL);
    int same = P2.n == P.n, differ = 0;
    for (size_t i = 0; same && i < P.n; i++)
        for (int d = 0; d < 2; d++) {
            if (P2.x[d][i] != P.x[d][i]) same = 0;
            if (P3.x[d][i] != P.x[d][i]) differ++;
        }
    CHECK(same);
    CHECK(differ > 700);
    lub_particles_free(&P3);
    lub_geometry_free(&g3);
    lub_particles_free(&P2);
    lub_geometry_free(&g2);
    lub_particles_free(&P);
    lub_geometry_free(&g);

    /* amplitude 0: the lattice itself */
    generate(jitter_channel(0, 7, text, sizeof text), &g, &P, NULL);
    int off = 0;
    for (size_t i = 0; i < P.n; i++)
        if (P.kind[i] == LUB_FLUID) {
            double qx = P.x[0][i] / l0 - 0.5, qy = P.x[1][i] / l0;
            if (fabs(qx - round(qx)) > 1e-9 || fabs(qy - round(qy)) > 1e-9) off++;
        }
    CHECK(off == 0);
    lub_particles_free(&P);
    lub_geometry_free(&g);

    CHECK_BAD(jitter_channel(0.5, 7, text, sizeof text), 10, "'jitter.amplitude' must be");
    CHECK_BAD(jitter_channel(-0.1, 7, text, sizeof text), 10, "'jitter.amplitude' must be");
    CHECK_BAD(jitter_channel(0.2, -1, text, sizeof text), 10, "'jitter.seed' must be");
    CHECK_BAD("dimension: 2\nlevels:\n  - { l0: 0.1, region: [0, 0.5] }\n  - { l0: 0.2 }\n"
              "domain: { min: [0, 0], max: [1, 1] }\n"
              "jitter: { amplitude: 0.2 }\n",
              6, "jitter needs a single resolution");
    CHECK_BAD("dimension: 2\nl0: 0.1\ndomain: { min: [0, 0], max: [1, 1] }\n"
              "jitter: { amplitude: 0.2, sed: 3 }\n",
              4, "unknown key 'sed'");
}

int main(void)
{
    RUN(test_read_wedge);
    RUN(test_wall_functions);
    RUN(test_wall_functions_3d);
    RUN(test_read_levels);
    RUN(test_bad_input);
    RUN(test_plane_layer);
    RUN(test_tank_2d);
    RUN(test_tank_planes);
    RUN(test_cylinder_arc);
    RUN(test_wedge_gap);
    RUN(test_levels);
    RUN(test_levels_arc);
    RUN(test_tank_3d);
    RUN(test_walls_3d);
    RUN(test_roller);
    RUN(test_curves);
    RUN(test_between);
    RUN(test_bad_discretise);
    RUN(test_polygon_read);
    RUN(test_polygon_square);
    RUN(test_polygon_concave);
    RUN(test_polygon_pad);
    RUN(test_polygon_levels);
    RUN(test_jitter);
    unlink(tmp_path);
    return test_summary();
}
