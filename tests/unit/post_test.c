/* Unit tests of src/post: fields, bins, accumulators, binning, point sampling, totals, arc
 * length and the film.  Expected values are worked out by hand in the comments.
 *
 * For tests/cases/probe: "-setFields CASE SRC NEW A B C U0 UY V0" reads CASE/SRC/particles.h5,
 * gives every particle the analytic fields
 *     p = A x + B y + C,   U = (U0 + UY y, V0, 0),   pMean = 2 p
 * and writes them (positions unchanged, time = NEW) as the time folder CASE/NEW.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/args.h"
#include "geometry/discretise.h"
#include "io/case.h"
#include "particles/particles_io.h"
#include "particles/particles.h"
#include "post/film.h"
#include "post/sample.h"
#include "test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---- helpers -------------------------------------------------------------------------- */

/* A 2-D set with one level of spacing l0 and re = 3.1 l0, and patches "lower", "upper". */
static void setup(lub_particles *P, double l0)
{
    lub_particles_init(P, 2, 64);
    P->nlevels = 1;
    P->levels[0] = (lub_level){.l0 = l0, .re = 3.1 * l0, .n0 = 1.0, .lambda0 = 1.0};
    lub_particles_patch(P, "lower");
    lub_particles_patch(P, "upper");
}

static size_t add(lub_particles *P, double x, double y, int kind, int patch)
{
    double xy[2] = {x, y};
    return lub_particles_add(P, xy, kind, kind == LUB_FLUID ? 0 : patch, 0);
}

/* ---- fields --------------------------------------------------------------------------- */

static void test_fields(void)
{
    lub_particles P;
    setup(&P, 1.0);
    add(&P, 0, 0, LUB_FLUID, 0);
    lub_particles_extra(&P, "pMean");
    lub_post_fields f;
    char err[1024];
    CHECK(lub_post_fields_parse(&f, "p,U", &P, err, sizeof err) == 0);
    CHECK(f.n == 3);
    CHECK(strcmp(f.col[0].column, "p[Pa]") == 0 && f.col[0].src == LUB_POST_PRESSURE);
    CHECK(strcmp(f.col[1].column, "Ux[m/s]") == 0 && f.col[1].comp == 0);
    CHECK(strcmp(f.col[2].column, "Uy[m/s]") == 0 && f.col[2].comp == 1);
    CHECK(lub_post_fields_parse(&f, " pMean , uy", &P, err, sizeof err) == 0);
    CHECK(f.n == 2 && f.col[0].src == LUB_POST_EXTRA && strcmp(f.col[0].column, "pMean") == 0);
    CHECK(f.col[1].src == LUB_POST_VELOCITY && f.col[1].comp == 1);
    /* aliases */
    CHECK(lub_post_fields_parse(&f, "pressure,velocity", &P, err, sizeof err) == 0 && f.n == 3);

    CHECK(lub_post_fields_parse(&f, "pMaen", &P, err, sizeof err) == -1);
    CHECK_STR(err, "unknown field 'pMaen' (did you mean 'pMean'?)");
    CHECK_STR(err, "the fields are: p U Ux Uy pMean");
    CHECK(lub_post_fields_parse(&f, "Uz", &P, err, sizeof err) == -1); /* 2-D */
    CHECK_STR(err, "unknown field 'Uz'");
    CHECK(lub_post_fields_parse(&f, "p,U,p", &P, err, sizeof err) == -1);
    CHECK_STR(err, "listed twice");
    CHECK(lub_post_fields_parse(&f, "U,Ux", &P, err, sizeof err) == -1);
    CHECK_STR(err, "listed twice");
    CHECK(lub_post_fields_parse(&f, "p,,U", &P, err, sizeof err) == -1);
    CHECK_STR(err, "empty field name");
    CHECK(lub_post_fields_parse(&f, "", &P, err, sizeof err) == -1);

    /* arrays, and an optional field missing from a later set of particles */
    const double *v[LUB_POST_MAX_COLS];
    CHECK(lub_post_fields_parse(&f, "pMean,Ux", &P, err, sizeof err) == 0);
    CHECK(lub_post_fields_arrays(&f, &P, v, err, sizeof err) == 0);
    CHECK(v[0] == lub_particles_find_extra(&P, "pMean") && v[1] == P.u[0]);
    lub_particles Q;
    setup(&Q, 1.0);
    add(&Q, 0, 0, LUB_FLUID, 0);
    CHECK(lub_post_fields_arrays(&f, &Q, v, err, sizeof err) == -1);
    CHECK_STR(err, "no field 'pMean'");
    lub_particles_free(&Q);
    lub_particles_free(&P);

    /* 3-D: U has three columns */
    lub_particles_init(&P, 3, 4);
    CHECK(lub_post_fields_parse(&f, "U", &P, err, sizeof err) == 0 && f.n == 3);
    CHECK(strcmp(f.col[2].column, "Uz[m/s]") == 0);
    lub_particles_free(&P);
}

/* ---- bins ----------------------------------------------------------------------------- */

static void test_bins(void)
{
    lub_bins b;
    CHECK(lub_bins_init(&b, 0.0, 1.0, 0.25) == 0 && b.nbins == 4);
    CHECK(lub_bins_find(&b, 0.0) == 0);
    CHECK(lub_bins_find(&b, 0.2499) == 0);
    CHECK(lub_bins_find(&b, 0.25) == 1);
    CHECK(lub_bins_find(&b, 1.0) == 3); /* the last bin is closed */
    CHECK(lub_bins_find(&b, 1.0001) == -1 && lub_bins_find(&b, -1e-12) == -1);
    CHECK(lub_bins_find(&b, NAN) == -1);
    CHECK_NEAR(lub_bins_centre(&b, 0), 0.125, 1e-15);
    CHECK_NEAR(lub_bins_centre(&b, 3), 0.875, 1e-15);
    /* 0.3 / 0.1 = 2.9999999999999996 in floating point: 3 bins, not 4 */
    CHECK(lub_bins_init(&b, 0.0, 0.3, 0.1) == 0 && b.nbins == 3);
    /* a partial last bin: [0.5, 0.7], centre 0.6 */
    CHECK(lub_bins_init(&b, 0.0, 0.7, 0.25) == 0 && b.nbins == 3);
    CHECK_NEAR(lub_bins_centre(&b, 2), 0.6, 1e-15);
    CHECK_NEAR(lub_bins_upper(&b, 2), 0.7, 0);
    CHECK(lub_bins_init(&b, 0.0, 1.0, 0.0) == -1);
    CHECK(lub_bins_init(&b, 0.0, 1.0, -0.1) == -1);
    CHECK(lub_bins_init(&b, 1.0, 1.0, 0.1) == -1);
    CHECK(lub_bins_init(&b, 2.0, 1.0, 0.1) == -1);
    CHECK(lub_bins_init(&b, 0.0, 1.0, 1e-9) == -1); /* 1e9 bins */
    CHECK(lub_bins_init(&b, 0.0, INFINITY, 1.0) == -1);
}

/* A linear field sampled in bins symmetric about their centres comes back exactly; the
 * accumulator pools several sets (time average = sum / count). */
static void test_sample_bins(void)
{
    lub_particles P;
    setup(&P, 0.1);
    /* fluid at x = 0.05, 0.15, ..., 0.95 in two rows; walls of patch 1 at x = 0.05 .. 0.95 */
    for (int i = 0; i < 10; i++)
        for (int r = 0; r < 2; r++) {
            size_t k = add(&P, 0.05 + 0.1 * i, 0.1 * (r + 1), LUB_FLUID, 0);
            P.p[k] = 3.0 * P.x[0][k] + 7.0 * P.x[1][k] - 1.0;
        }
    for (int i = 0; i < 10; i++) {
        size_t k = add(&P, 0.05 + 0.1 * i, 0.0, LUB_WALL, 1);
        P.p[k] = 100.0;
        k = add(&P, 0.05 + 0.1 * i, 0.5, LUB_WALL, 0);
        P.p[k] = -5.0;
    }
    lub_bins b;
    lub_accum a;
    CHECK(lub_bins_init(&b, 0.0, 1.0, 0.2) == 0);
    lub_accum_init(&a, b.nbins, 1);
    const double *v[1] = {P.p};
    CHECK(lub_sample_bins(&a, &b, &P, LUB_FLUID, -1, NULL, v) == 20);
    for (int k = 0; k < 5; k++) {
        /* bin k: x = 0.2k + 0.05, 0.2k + 0.15, y = 0.1, 0.2: mean 3 (0.2k + 0.1) + 7 0.15 - 1 */
        CHECK_NEAR(lub_accum_mean(&a, k, 0), 3.0 * (0.2 * k + 0.1) + 0.05, 1e-13);
        CHECK(a.count[k] == 4.0);
    }
    /* the wall particles of patch 1 only */
    lub_accum_clear(&a);
    CHECK(lub_sample_bins(&a, &b, &P, LUB_WALL, 1, NULL, v) == 10);
    CHECK(lub_accum_mean(&a, 2, 0) == 100.0 && a.count[2] == 2.0);
    /* pooling a second set with p doubled: mean 1.5 times the first */
    lub_accum_clear(&a);
    lub_sample_bins(&a, &b, &P, LUB_FLUID, -1, NULL, v);
    for (size_t i = 0; i < P.n; i++) P.p[i] *= 2.0;
    lub_sample_bins(&a, &b, &P, LUB_FLUID, -1, NULL, v);
    CHECK_NEAR(lub_accum_mean(&a, 0, 0), 1.5 * (3.0 * 0.1 + 0.05), 1e-13);
    CHECK(a.count[0] == 8.0);
    /* a coordinate of the caller's (here y): rows by height */
    lub_bins by;
    lub_accum ay;
    CHECK(lub_bins_init(&by, 0.0, 0.3, 0.15) == 0);
    lub_accum_init(&ay, by.nbins, 1);
    CHECK(lub_sample_bins(&ay, &by, &P, LUB_FLUID, -1, P.x[1], v) == 20);
    CHECK(ay.count[0] == 10.0 && ay.count[1] == 10.0);
    lub_accum_free(&ay);
    lub_accum_free(&a);
    lub_particles_free(&P);
}

/* ---- points --------------------------------------------------------------------------- */

static void test_sample_point(void)
{
    lub_particles P;
    setup(&P, 1.0);
    /* a 11 x 11 lattice of fluid, p = 2x - 3y + 5, Ux = 4 */
    for (int i = 0; i <= 10; i++)
        for (int j = 0; j <= 10; j++) {
            size_t k = add(&P, i, j, LUB_FLUID, 0);
            P.p[k] = 2.0 * i - 3.0 * j + 5.0;
            P.u[0][k] = 4.0;
        }
    size_t kd = add(&P, 5.2, 5.0, LUB_DUMMY, 0); /* dummies never count */
    P.p[kd] = 1e9;
    const double *v[2] = {P.p, P.u[0]};
    double out[2], re = 0;
    /* at a lattice site inside: the neighbourhood is symmetric, the linear field exact */
    double q[3] = {5.0, 5.0, 0.0};
    size_t n = lub_sample_point(&P, q, v, 2, out, &re);
    CHECK_NEAR(re, 3.1, 0);
    /* lattice points within 3.1 of a site: 29 (|i|,|j| with i^2 + j^2 < 9.61) */
    CHECK(n == 29);
    CHECK_NEAR(out[0], 2.0 * 5 - 3.0 * 5 + 5.0, 1e-12);
    CHECK_NEAR(out[1], 4.0, 1e-14);
    /* anywhere: a constant field is exact */
    double q2[3] = {0.3, 9.7, 0.0};
    CHECK(lub_sample_point(&P, q2, v, 2, out, NULL) > 0);
    CHECK_NEAR(out[1], 4.0, 1e-14);
    /* far away: nothing within re */
    double q3[3] = {20.0, 20.0, 0.0};
    out[0] = -1.0;
    CHECK(lub_sample_point(&P, q3, v, 2, out, &re) == 0);
    CHECK(out[0] == -1.0);
    lub_particles_free(&P);
}

/* ---- totals --------------------------------------------------------------------------- */

static void test_totals(void)
{
    lub_particles P;
    setup(&P, 0.5);
    size_t a = add(&P, 0, 0, LUB_FLUID, 0), b = add(&P, 1, 0, LUB_FLUID, 0);
    size_t w = add(&P, 0, -1, LUB_WALL, 0);
    P.u[0][a] = 1.0, P.u[1][a] = 2.0;
    P.u[0][b] = -3.0;
    P.u[0][w] = 100.0; /* walls are not fluid */
    lub_totals t;
    /* m = 1000 0.5^2 = 250 per particle (2-D, per unit depth) */
    lub_totals_compute(&t, &P, 1000.0);
    CHECK(t.nfluid == 2);
    CHECK_NEAR(t.mass, 500.0, 1e-12);
    CHECK_NEAR(t.momentum[0], 250.0 * (1.0 - 3.0), 1e-12);
    CHECK_NEAR(t.momentum[1], 500.0, 1e-12);
    CHECK(t.momentum[2] == 0.0);
    CHECK_NEAR(t.kinetic, 0.5 * 250.0 * (1.0 + 4.0 + 9.0), 1e-12);
    /* two levels: a coarse particle of l0 = 1 weighs 1000 */
    P.nlevels = 2;
    P.levels[1] = (lub_level){.l0 = 1.0, .re = 3.1};
    P.level[b] = 1;
    lub_totals_compute(&t, &P, 1000.0);
    CHECK_NEAR(t.mass, 1250.0, 1e-12);
    lub_particles_free(&P);
}

/* ---- arc length ----------------------------------------------------------------------- */

static void test_arc(void)
{
    lub_wall w;
    memset(&w, 0, sizeof w);
    double s, x[3] = {0, 0, 0};
    /* cylinder centre (0, 2), R = 2: lowest point (0, 0) is s = 0; (2, 2) is a quarter turn */
    w.type = LUB_WALL_CYLINDER;
    w.centre[1] = 2.0;
    w.radius = 2.0;
    CHECK(lub_wall_arc(&w, 2, x, &s) == 0 && s == 0.0);
    x[0] = 2.0, x[1] = 2.0;
    CHECK(lub_wall_arc(&w, 2, x, &s) == 0);
    CHECK_NEAR(s, M_PI, 1e-14);
    x[0] = -2.0;
    lub_wall_arc(&w, 2, x, &s);
    CHECK_NEAR(s, -M_PI, 1e-14);
    /* plane through (1, 1) with normal (0, 1): s = x - 1; normal (0, -1) too (t_x > 0) */
    w.type = LUB_WALL_PLANE;
    w.point[0] = w.point[1] = 1.0;
    w.normal[1] = 1.0;
    x[0] = 3.5, x[1] = 1.0;
    CHECK(lub_wall_arc(&w, 2, x, &s) == 0);
    CHECK_NEAR(s, 2.5, 1e-15);
    w.normal[1] = -1.0;
    lub_wall_arc(&w, 2, x, &s);
    CHECK_NEAR(s, 2.5, 1e-15);
    /* segment (0,0) -> (3,4): the point (3,4) is at s = 5 */
    w.type = LUB_WALL_SEGMENT;
    w.from[0] = w.from[1] = 0.0;
    w.to[0] = 3.0, w.to[1] = 4.0;
    x[0] = 3.0, x[1] = 4.0;
    CHECK(lub_wall_arc(&w, 2, x, &s) == 0);
    CHECK_NEAR(s, 5.0, 1e-14);
    /* polyline (0,0) (1,0) (1,2): the point (1, 1.5) is at s = 1 + 1.5 */
    double pts[6] = {0, 0, 1, 0, 1, 2};
    w.type = LUB_WALL_POLYLINE;
    w.pts = pts;
    w.npts = 3;
    x[0] = 1.0, x[1] = 1.5;
    CHECK(lub_wall_arc(&w, 2, x, &s) == 0);
    CHECK_NEAR(s, 2.5, 1e-14);
    /* polygon (0,0) (1,0) (1,2) closed back to (0,0): (0.5, 1) on the closing edge is at
     * s = 1 + 2 + sqrt(5)/2 */
    w.type = LUB_WALL_POLYGON;
    x[0] = 0.5, x[1] = 1.0;
    CHECK(lub_wall_arc(&w, 2, x, &s) == 0);
    CHECK_NEAR(s, 3 + sqrt(5.0) / 2, 1e-14);
    /* unsupported */
    w.type = LUB_WALL_BOX;
    CHECK(lub_wall_arc(&w, 2, x, &s) == -1);
    w.type = LUB_WALL_CYLINDER;
    CHECK(lub_wall_arc(&w, 3, x, &s) == -1);
}

/* The wall particles facing down and up (lub_wall_facing) of particleGen's bodies: the pad
 * (0, 0.2), (4, 0.1), (4, 1), (0, 1) with l0 = 0.1 has 40 steps on its lower face, 41
 * particles with the corners, all on y = 0.2 - 0.025 x, and 41 on its top; a whole circle
 * (R = 0.5, round(2 pi R / l0) = 31 particles at angles k 2 pi/31 from its lowest point)
 * those within 60 degrees of the bottom, |k| <= 5 (11), and of the top, k = 11 .. 20 (10). */
static void test_wall_facing(void)
{
    const char *path = "/tmp/lub_post_test_facing.yaml";
    FILE *f = fopen(path, "w");
    fputs("dimension: 2\nl0: 0.1\ndomain: { min: [-1, -1], max: [5, 5] }\nwalls:\n"
          "  pad: { type: polygon, points: [[0, 0.2], [4, 0.1], [4, 1], [0, 1]] }\n"
          "  ring: { type: cylinder, centre: [2, 3], radius: 0.5 }\n",
          f);
    fclose(f);
    lub_geometry g;
    lub_particles P;
    lub_geometry_read(&g, path);
    lub_geometry_discretise(&g, &P, 0.0, NULL);
    unlink(path);
    unsigned char *on = malloc(P.n);
    size_t n = lub_wall_facing(&P, 0, -1, on);
    CHECK(n == 41);
    int bad = 0;
    for (size_t i = 0; i < P.n; i++)
        if (on[i] && (P.patch[i] != 0 || fabs(P.x[1][i] - (0.2 - 0.025 * P.x[0][i])) > 1e-12))
            bad++;
    CHECK(bad == 0);
    CHECK(lub_wall_facing(&P, 0, 1, on) == 41);
    for (size_t i = 0; i < P.n; i++)
        if (on[i] && fabs(P.x[1][i] - 1.0) > 1e-12) bad++;
    CHECK(bad == 0);
    CHECK(lub_wall_facing(&P, 1, -1, on) == 11);
    for (size_t i = 0; i < P.n; i++)
        if (on[i] && !(P.x[1][i] < 3 - 0.5 * cos(5.5 * 2 * M_PI / 31))) bad++;
    CHECK(lub_wall_facing(&P, 1, 1, on) == 10);
    for (size_t i = 0; i < P.n; i++)
        if (on[i] && !(P.x[1][i] > 3 - 0.5 * cos(10.5 * 2 * M_PI / 31))) bad++;
    CHECK(bad == 0);
    free(on);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* ---- film ----------------------------------------------------------------------------- */

/* Columns of a lattice with l0 = 1: a lower wall at y = 0 (dummy below), a film of rows
 * 1 .. top(i), and an upper wall at y = wall(i) where given. */
static void test_film(void)
{
    lub_particles P;
    setup(&P, 1.0);
    /* x = 0.5 .. 9.5: rows up to 4 (a free layer 4 thick) for x < 5; for x > 5 a gap filled
     * to 2 under an upper wall at y = 3 */
    for (int i = 0; i < 10; i++) {
        double x = 0.5 + i;
        add(&P, x, 0.0, LUB_WALL, 0);
        add(&P, x, -1.0, LUB_DUMMY, 0);
        int top = i < 5 ? 4 : 2;
        for (int r = 1; r <= top; r++) {
            size_t k = add(&P, x, r, LUB_FLUID, 0);
            P.u[0][k] = 1.0; /* flow towards +x */
        }
        if (i >= 5)
            add(&P, x, 3.0, LUB_WALL, 1), add(&P, x, 4.0, LUB_DUMMY, 1);
        else
            add(&P, x, 6.5, LUB_WALL, 1); /* far above the free surface: no contact */
    }
    lub_film f;
    CHECK(lub_film_init(&f, 0.0, 10.0, 1.0) == 0);
    lub_film_sample(&f, &P);
    lub_film_row r;
    CHECK(lub_film_row_at(&f, 2, &r) == 1);
    CHECK(r.x == 2.5 && r.surface == 4.0 && r.bottom == 0.0 && r.contact == 0 && r.n == 4);
    CHECK(r.h == 4.0);
    /* the cells cover [0, 0.5] (wall), [0.5, 4.5] (fluid), [6, 6.5] (wall) of the gap 6.5 */
    CHECK(r.full == 0);
    CHECK_NEAR(r.filled, 5.0 / 6.5, 1e-15);
    CHECK(lub_film_row_at(&f, 7, &r) == 1);
    CHECK(r.surface == 2.0 && r.bottom == 0.0 && r.contact == 1 && r.h == 3.0 && r.n == 2);
    CHECK(r.full == 1 && r.filled == 1.0);
    lub_film_ends e;
    /* the ends within 1.5 l0 + DX/2 = 2 (bins of l0: strips of 3 l0, see film.h) */
    CHECK(lub_film_meniscus(&f, &e) == 1);
    CHECK(fabs(e.inlet - 5.0) <= 2.0 && e.outlet == 10.0 && fabs(e.contact - 5.0) <= 2.0);
    /* flow towards -x: the inlet is the upstream (+x) end of the full run */
    for (size_t i = 0; i < P.n; i++) P.u[0][i] = -1.0;
    lub_film_sample(&f, &P);
    CHECK(lub_film_meniscus(&f, &e) == 1);
    CHECK(e.inlet == 10.0 && fabs(e.outlet - 5.0) <= 2.0 && e.contact == 10.0);
    lub_film_free(&f);

    /* a film with no wall: a drop column from y = 5 to 7, bottom and surface free */
    lub_particles Q;
    setup(&Q, 1.0);
    for (int r = 5; r <= 7; r++) add(&Q, 0.5, r, LUB_FLUID, 0);
    add(&Q, 0.5, 2.0, LUB_WALL, 0); /* 3 l0 below: not touching */
    CHECK(lub_film_init(&f, 0.0, 3.0, 1.0) == 0);
    lub_film_sample(&f, &Q);
    CHECK(lub_film_row_at(&f, 0, &r) == 1);
    CHECK(r.bottom == 5.0 && r.surface == 7.0 && r.h == 2.0 && r.contact == 0);
    CHECK(r.full == 0 && r.filled == 0.0);  /* no wall above: no gap to fill */
    CHECK(lub_film_row_at(&f, 2, &r) == 0); /* no fluid within 1.5 l0 of its centre */
    CHECK(lub_film_meniscus(&f, &e) == 0);
    lub_film_free(&f);
    CHECK(lub_film_init(&f, 1.0, 0.0, 1.0) == -1);
    lub_particles_free(&Q);
    lub_particles_free(&P);
}

/* The inlet of a wedge's film between parallel walls, known by construction.  Lattice l0 = 1,
 * columns x = i + 1/2 (i = 0 .. 69), lower wall y = 0, upper wall y = 10 (wall particles on
 * the surfaces, a dummy row behind each), flow towards +x:
 *
 *   x in [0, 10)    a layer, rows 1 .. 3, far below the upper wall
 *   x in [10, 20)   the inlet roll: the layer, an air gap (rows 4, 5 empty) and the roll,
 *                   rows 6 .. 9, touching the upper wall: contact, but not full
 *   x in [20, 50)   the full film, rows 1 .. 9
 *   x in [50, 70)   past the outlet meniscus: rows 1 .. 4, detached from the upper wall
 *
 * so that the inlet is at 20, the outlet at 50 and the contact at 10.  The filled fraction of
 * the gap 10 is 0.4, 0.8, 1 and 0.5 in the four parts (cells of l0 around the particles,
 * half of each wall's cell inside the gap).  With mirror, x -> 70 - x and the flow towards -x
 * (inlet 50, outlet 20, contact 60).  jitter > 0 moves each fluid particle by up to jitter in
 * x and y (a deterministic sequence from seed). */
enum { ROLL_XA = 10, ROLL_XIN = 20, ROLL_XOUT = 50, ROLL_N = 70, ROLL_H = 10 };

static double roll_rand(unsigned long *s) /* uniform in [-1, 1) (xorshift64) */
{
    *s ^= *s << 13, *s ^= *s >> 7, *s ^= *s << 17;
    return (double)(*s >> 11) / 4503599627370496.0 - 1.0;
}

static void roll_case(lub_particles *P, double jitter, unsigned long seed, int mirror)
{
    setup(P, 1.0);
    unsigned long s = 88172645463325252UL ^ seed;
    for (int i = 0; i < ROLL_N; i++) {
        double x = i + 0.5, X = mirror ? ROLL_N - x : x;
        add(P, X, 0.0, LUB_WALL, 0), add(P, X, -1.0, LUB_DUMMY, 0);
        add(P, X, ROLL_H, LUB_WALL, 1), add(P, X, ROLL_H + 1.0, LUB_DUMMY, 1);
        for (int r = 1; r < ROLL_H; r++) {
            int fluid = x < ROLL_XA     ? r <= 3
                        : x < ROLL_XIN  ? r <= 3 || r >= 6
                        : x < ROLL_XOUT ? 1
                                        : r <= 4;
            if (!fluid) continue;
            double dx = jitter * roll_rand(&s), dy = jitter * roll_rand(&s);
            size_t k = add(P, X + dx, r + dy, LUB_FLUID, 0);
            P->u[0][k] = mirror ? -1.0 : 1.0;
        }
    }
}

/* The filled fraction of bin k of a roll_case, computed independently: the part of 1e5 points
 * in (0, 10) that lie in a cell [y - 1/2, y + 1/2] of a fluid particle of the bin's strip (in
 * the bin, or within 1.5 l0 = 1.5 of its centre) or in the walls' half cells [0, 1/2],
 * [9.5, 10]. */
static double roll_filled(const lub_particles *P, const lub_bins *b, int k)
{
    enum { M = 100000 };
    static unsigned char hit[M];
    memset(hit, 0, sizeof hit);
    double c = lub_bins_centre(b, k), dy = (double)ROLL_H / M;
    for (size_t i = 0; i < P->n; i++) {
        double x = P->x[0][i], y = P->x[1][i];
        if (P->kind[i] != LUB_FLUID || !(lub_bins_find(b, x) == k || fabs(x - c) < 1.5)) continue;
        int m0 = (int)floor((y - 0.5) / dy) - 1, m1 = (int)ceil((y + 0.5) / dy) + 1;
        for (int m = m0 < 0 ? 0 : m0; m < M && m <= m1; m++)
            if (fabs((m + 0.5) * dy - y) <= 0.5) hit[m] = 1;
    }
    long n = 0;
    for (int m = 0; m < M; m++) {
        double y = (m + 0.5) * dy;
        n += hit[m] || y <= 0.5 || y >= ROLL_H - 0.5;
    }
    return (double)n / M;
}

/* On the lattice with bins on the lattice's cell edges (widths 1, 2, 5, 10 from 0): bins of
 * 3 l0 and wider (their strip is the bin) give the ends exactly, and each bin the filled
 * fraction of its part exactly; narrower bins (strips reaching 1.5 l0 from the centre, see
 * film.h) give the ends within 1.5 l0 + DX/2 and the exact values where their strip lies
 * inside one part. */
static void test_film_roll_lattice(void)
{
    static const double widths[] = {1.0, 2.0, 5.0, 10.0};
    for (int mirror = 0; mirror < 2; mirror++) {
        lub_particles P;
        roll_case(&P, 0.0, 0, mirror);
        for (size_t w = 0; w < sizeof widths / sizeof *widths; w++) {
            const double dx = widths[w], narrow = dx < 2 * LUB_FILM_STRIP;
            const double tol = narrow ? LUB_FILM_STRIP + 0.5 * dx : 0.0;
            const double reach = narrow ? LUB_FILM_STRIP : 0.5 * dx;
            lub_film f;
            CHECK(lub_film_init(&f, 0.0, ROLL_N, dx) == 0);
            lub_film_sample(&f, &P);
            lub_film_ends e;
            CHECK(lub_film_meniscus(&f, &e) == 1);
            double in = mirror ? ROLL_N - ROLL_XIN : ROLL_XIN;
            double out = mirror ? ROLL_N - ROLL_XOUT : ROLL_XOUT;
            double touch = mirror ? ROLL_N - ROLL_XA : ROLL_XA;
            int ends = fabs(e.inlet - in) <= tol && fabs(e.outlet - out) <= tol &&
                       fabs(e.contact - touch) <= tol;
            if (!ends)
                printf("  mirror %d, bin %g: inlet %g outlet %g contact %g\n", mirror, dx, e.inlet,
                       e.outlet, e.contact);
            CHECK(ends);
            for (int k = 0; k < f.bins.nbins; k++) {
                lub_film_row r;
                CHECK(lub_film_row_at(&f, k, &r) == 1);
                double x = mirror ? ROLL_N - r.x : r.x;
                int part = x < ROLL_XA ? 0 : x < ROLL_XIN ? 1 : x < ROLL_XOUT ? 2 : 3;
                static const double a[] = {0, ROLL_XA, ROLL_XIN, ROLL_XOUT},
                                    b[] = {ROLL_XA, ROLL_XIN, ROLL_XOUT, ROLL_N};
                CHECK(r.n == (long)dx * (part == 0 ? 3 : part == 1 ? 7 : part == 2 ? 9 : 4));
                if (x - reach < a[part] - 1e-9 || x + reach > b[part] + 1e-9) continue;
                static const double filled[] = {0.4, 0.8, 1.0, 0.5};
                static const int contact[] = {0, 1, 1, 0}, full[] = {0, 0, 1, 0};
                CHECK_NEAR(r.filled, filled[part], 1e-15);
                CHECK(r.contact == contact[part] && r.full == full[part]);
            }
            lub_film_free(&f);
        }
        lub_particles_free(&P);
    }
}

/* Jittered (fluid moved by up to 0.3 l0, as the particles of a run are) and with bins not on
 * the lattice (from -0.37, or on the cells' centres): each end within a bin width of its
 * place, or within 1.5 l0 + DX/2 where bins are narrower than 3 l0 (their strips reach 1.5 l0
 * from the centre); every bin whose strip lies inside one part judged as that part.  Bins of l0 and
 * 1.5 l0 among them: such bins hold no particle of some rows (a jittered particle leaves its
 * column's bin), which an earlier version took for air, ending the film there. */
static void test_film_roll_jittered(void)
{
    static const double widths[] = {0.5, 1.0, 1.5, 2.0, 3.0, 5.0};
    static const double froms[] = {0.0, -0.37, -0.5};
    int nbad = 0;
    for (int mirror = 0; mirror < 2; mirror++)
        for (unsigned long seed = 1; seed <= 5; seed++) {
            lub_particles P;
            roll_case(&P, 0.3, seed, mirror);
            for (size_t w = 0; w < sizeof widths / sizeof *widths; w++)
                for (size_t o = 0; o < sizeof froms / sizeof *froms; o++) {
                    double dx = widths[w], tol = fmax(dx, 1.5 + 0.5 * dx);
                    lub_film f;
                    CHECK(lub_film_init(&f, froms[o], ROLL_N, dx) == 0);
                    lub_film_sample(&f, &P);
                    lub_film_ends e;
                    int ok = lub_film_meniscus(&f, &e) == 1;
                    double in = mirror ? ROLL_N - ROLL_XIN : ROLL_XIN;
                    double out = mirror ? ROLL_N - ROLL_XOUT : ROLL_XOUT;
                    double touch = mirror ? ROLL_N - ROLL_XA : ROLL_XA;
                    ok = ok && fabs(e.inlet - in) < tol && fabs(e.outlet - out) < tol &&
                         fabs(e.contact - touch) < tol;
                    /* bins whose strip (the bin, widened to 3 l0) lies inside one part */
                    double reach = fmax(0.5 * dx, 1.5);
                    for (int k = 0; k < f.bins.nbins; k++) {
                        lub_film_row r;
                        if (!lub_film_row_at(&f, k, &r)) {
                            ok = 0;
                            continue;
                        }
                        double ref = roll_filled(&P, &f.bins, k);
                        if (!(fabs(r.filled - ref) < 1e-3)) {
                            ok = 0;
                            printf("  bin %g x %g: filled %.6f, point-sampled %.6f\n", dx, r.x,
                                   r.filled, ref);
                        }
                        double x = mirror ? ROLL_N - r.x : r.x;
                        for (int part = 0; part < 4; part++) {
                            static const double a[] = {0, ROLL_XA, ROLL_XIN, ROLL_XOUT},
                                                b[] = {ROLL_XA, ROLL_XIN, ROLL_XOUT, ROLL_N};
                            if (x - reach < a[part] + 0.5 || x + reach > b[part] - 0.5) continue;
                            static const int contact[] = {0, 1, 1, 0}, full[] = {0, 0, 1, 0};
                            int good = r.contact == contact[part] && r.full == full[part];
                            ok = ok && good;
                        }
                    }
                    if (!ok && nbad++ < 5)
                        printf("  mirror %d seed %lu bin %g from %g: inlet %g outlet %g contact "
                               "%g\n",
                               mirror, seed, dx, froms[o], e.inlet, e.outlet, e.contact);
                    CHECK(ok);
                    lub_film_free(&f);
                }
            lub_particles_free(&P);
        }
}

/* ---- the helper of tests/cases/probe ------------------------------------------------- */

static int set_fields(int argc, char **argv)
{
    if (argc != 11) {
        fprintf(stderr, "usage: post_test -setFields CASE SRC NEW A B C U0 UY V0\n");
        return 1;
    }
    lub_set_program("post_test");
    double v[6], t;
    for (int k = 0; k < 6; k++)
        if (lub_parse_real(argv[5 + k], &v[k])) {
            fprintf(stderr, "post_test: '%s' is not a number\n", argv[5 + k]);
            return 1;
        }
    if (lub_parse_real(argv[4], &t)) {
        fprintf(stderr, "post_test: '%s' is not a time\n", argv[4]);
        return 1;
    }
    lub_case c;
    lub_case_open(&c, argv[2]);
    char path[LUB_PATH_MAX], dir[LUB_PATH_MAX];
    lub_particles P;
    lub_particles_read(&P, lub_case_pathf(&c, path, "%s/particles.h5", argv[3]));
    double *pm = lub_particles_extra(&P, "pMean");
    for (size_t i = 0; i < P.n; i++) {
        double x = P.x[0][i], y = P.x[1][i];
        P.p[i] = v[0] * x + v[1] * y + v[2];
        P.u[0][i] = v[3] + v[4] * y;
        P.u[1][i] = v[5];
        P.u[2][i] = 0.0;
        pm[i] = 2.0 * P.p[i];
    }
    P.time = t;
    lub_timedir_begin(&c, argv[4], dir);
    lub_particles_write(&P, dir);
    lub_timedir_commit(&c, argv[4], dir);
    lub_particles_free(&P);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && strcmp(argv[1], "-setFields") == 0) return set_fields(argc, argv);
    RUN(test_fields);
    RUN(test_bins);
    RUN(test_sample_bins);
    RUN(test_sample_point);
    RUN(test_totals);
    RUN(test_arc);
    RUN(test_wall_facing);
    RUN(test_film);
    RUN(test_film_roll_lattice);
    RUN(test_film_roll_jittered);
    return test_summary();
}
