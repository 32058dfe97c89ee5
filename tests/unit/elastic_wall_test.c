/* Unit tests of src/models/elasticWall: the elasticWall model in the particle solver.
 *
 *   - the running mean: the exponential mean with a = 2/(N + 1) follows a linearly rising
 *     pressure with the lag of the box mean over the last N steps, (N - 1)/2 steps, and a
 *     constant pressure p as p (1 - (1 - a)^n) from zero;
 *   - the wall update for a given mean pressure: the load balance step of T-51, the
 *     displacement against the direct influence sum (T-46..T-49), the target positions of
 *     the wall (T-50) and dummy particles, and that the velocity set before the step carries
 *     each particle to its target in one step (velocity = dy/dt); a second update with the
 *     same mean moves the whole patch by dh0 only;
 *   - the mean update after a step, the crossing check (the state unchanged), the restart
 *     state, and bad input;
 *   - two resolution levels (T-62..T-65): the pressure segments are the wall particles whose
 *     x their level owns, once each, tiling x; every wall particle of both levels (the
 *     overlaps included) goes to T-50 with the displacement of those segments only (the
 *     others carry a mean pressure of 1e9 Pa, which must not matter); the load is the owned
 *     sum, and each level's mean takes its own wall pressure.
 *
 * The particles come from the geometry module as particleGen makes them: a cylinder of
 * R = 1 mm over a plane, l0 = 10 um.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "geometry/discretise.h"
#include "geometry/geometry.h"
#include "models/elasticWall/elasticWall.h"
#include "models/multiResolution/levels.h"
#include "mps/mps.h"
#include "models/multiResolution/opt.h"
#include "test.h"

static const char *geom_text = "dimension: 2\n"
                               "l0: 1.0e-5\n"
                               "domain: { min: [-2.0e-4, -3.0e-5], max: [2.0e-4, 1.0e-4] }\n"
                               "periodic: [x]\n"
                               "walls:\n"
                               "  lowerWall: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                               "  cylinder:  { type: cylinder, lowestPoint: [0, 3.0e-5], "
                               "radius: 1.0e-3, range: [-2.0e-4, 2.0e-4] }\n"
                               "fluid:\n"
                               "  - { type: layer, wall: lowerWall, thickness: 2.0e-5 }\n";

static void write_file(char *path, const char *text)
{
    int fd = mkstemp(path);
    if (fd < 0 || write(fd, text, strlen(text)) != (ssize_t)strlen(text)) abort();
    close(fd);
}

typedef struct {
    lub_geometry g;
    lub_particles P;
    lub_mps m;
    char models[64];
} setup;

static void setup_make(setup *s, const char *models_text, const double *patch_velocity)
{
    char gpath[] = "/tmp/lubewgXXXXXX";
    write_file(gpath, geom_text);
    lub_geometry_read(&s->g, gpath);
    unlink(gpath);
    memset(&s->P, 0, sizeof s->P);
    lub_geometry_discretise(&s->g, &s->P, 0, NULL);
    lub_mps_config c;
    lub_mps_config_defaults(&c);
    c.rho = 810;
    c.nu = 4.5e-4;
    int cyl = lub_particles_find_patch(&s->P, "cylinder");
    if (patch_velocity)
        for (int d = 0; d < 3; d++) c.patch_velocity[cyl][d] = patch_velocity[d];
    lub_mps_init(&s->m, &s->P, &c, s->g.dmin, s->g.dmax, s->g.periodic);
    strcpy(s->models, "/tmp/lubewmXXXXXX");
    write_file(s->models, models_text);
}

static void setup_free(setup *s)
{
    unlink(s->models);
    lub_mps_free(&s->m);
    lub_particles_free(&s->P);
    lub_geometry_free(&s->g);
}

static const char *models_ok =
    "movingWalls: { lowerWall: { velocity: [1.0, 0] } }\n"
    "elasticWall: { patch: cylinder, E: 1.0e7, load: 100, rampTime: 1.0e-4, relaxation: 1.0e-2,"
    " averageSteps: 10 }\n";

/* ---- the running mean ------------------------------------------------------------------ */

static void test_mean_window(void)
{
    const long N = 200;
    const double a = lub_mps_elastic_mean_weight(N);
    CHECK_NEAR(a, 2.0 / 201.0, 1e-15);
    CHECK_NEAR(lub_mps_elastic_mean_weight(1), 1.0, 0.0); /* no averaging */
    /* a rising pressure p_k = c k: after the start-up the exponential mean equals the box
     * mean of the last N samples, both (N - 1)/2 steps behind */
    double mean = 0.0, c = 3.0;
    long n = 20 * N;
    for (long k = 1; k <= n; k++) mean += a * (c * (double)k - mean);
    double box = 0.0;
    for (long k = n - N + 1; k <= n; k++) box += c * (double)k / (double)N;
    CHECK_NEAR(mean, box, 1e-9 * box);
    CHECK_NEAR(c * (double)n - mean, c * (double)(N - 1) / 2.0, 1e-6);
    /* a constant pressure from zero: p (1 - (1 - a)^n) */
    mean = 0.0;
    for (long k = 1; k <= 150; k++) mean += a * (5.0 - mean);
    CHECK_NEAR(mean, 5.0 * (1.0 - pow(1.0 - a, 150)), 1e-12);
}

/* ---- the wall update ------------------------------------------------------------------- */

/* Wall particles of the cylinder sorted by x: count, indices. */
static int wall_slots(const lub_particles *P, int patch, size_t *idx)
{
    int n = 0;
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] == LUB_WALL && P->patch[i] == patch) idx[n++] = i;
    for (int a = 1; a < n; a++) /* insertion sort by x */
        for (int b = a; b > 0 && P->x[0][idx[b]] < P->x[0][idx[b - 1]]; b--) {
            size_t t = idx[b];
            idx[b] = idx[b - 1];
            idx[b - 1] = t;
        }
    return n;
}

static void test_wall_update(void)
{
    setup s;
    setup_make(&s, models_ok, NULL);
    lub_particles *P = &s.P;
    lub_mps_elastic w;
    CHECK(lub_mps_elastic_init(&w, &s.m, &s.g, s.models, NULL, 1e-3, "endTime") == 1);
    const int cyl = w.patch;
    CHECK(s.m.c.patch_moved[cyl] == 1);
    const double h00 = w.e.h0, base0 = w.y_floor + h00; /* the lowest point */
    CHECK_NEAR(h00, 3.0e-5, 1e-18);
    CHECK(w.h0 == h00 && w.samples == 0 && w.y_floor == 0.0);
    size_t *idx = malloc(P->n * sizeof *idx);
    int nw = wall_slots(P, cyl, idx);
    CHECK(nw == w.nw && nw > 30);
    /* the undeformed start: nothing moved, the shape is the arc above its lowest point */
    double *shape = lub_particles_find_extra(P, "elasticShape");
    double *mean = lub_particles_find_extra(P, "pWallMean");
    CHECK(shape && mean);
    for (int k = 0; k < nw; k++) CHECK_NEAR(P->x[1][idx[k]], base0 + shape[idx[k]], 1e-18);

    /* a Hertz-like mean pressure on the wall particles */
    double *xs = malloc((size_t)nw * sizeof *xs), *ws = malloc((size_t)nw * sizeof *ws);
    double *ps = malloc((size_t)nw * sizeof *ps), *vs = malloc((size_t)nw * sizeof *vs);
    double L = 0.0;
    for (int k = 0; k < nw; k++) {
        double x = P->x[0][idx[k]], q = 1.0 - (x / 1.5e-4) * (x / 1.5e-4);
        xs[k] = x;
        ps[k] = mean[idx[k]] = q > 0 ? 4.0e5 * sqrt(q) : 0.0;
    }
    CHECK(lub_elastic_segment_widths(nw, xs, 1e-5, ws) == 0);
    for (int k = 0; k < nw; k++) L += ps[k] * ws[k];
    lub_elastic_displacement_direct(nw, xs, ws, nw, xs, w.e.E, w.e.b, ps, vs);

    /* one update at t = 5e-5 (half the ramp: W = 50 N/m) */
    const double t = 5.0e-5, dt = 2.5e-7;
    double *y0 = malloc(P->n * sizeof *y0);
    for (size_t i = 0; i < P->n; i++) y0[i] = P->x[1][i];
    char msg[512];
    w.target_mean = 40.0; /* the averaged load target (state) */
    double dh0 = lub_elastic_dh0(&w.e, L, 40.0);
    CHECK(dh0 > 0); /* L > W: the wall rises */
    CHECK(lub_mps_elastic_before(&w, t, dt, msg, sizeof msg) == LUB_STEP_OK);
    CHECK(w.h0 == h00 + dh0);
    double vmax = 0;
    for (int k = 0; k < nw; k++) {
        size_t i = idx[k];
        double target = base0 + dh0 + shape[i] + vs[k]; /* T-50 */
        CHECK_NEAR(P->x[1][i] + P->u[1][i] * dt, target, 1e-16);
        CHECK(P->u[0][i] == 0.0);
        vmax = fmax(vmax, fabs(vs[k]));
    }
    CHECK(vmax > 1e-7); /* the test deforms the wall */
    /* dummies: the displacement of the wall, linearly interpolated at their x */
    int nd = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_DUMMY || P->patch[i] != cyl) continue;
        double x = P->x[0][i], v;
        int k = 0;
        while (k < nw - 2 && xs[k + 1] <= x) k++;
        double f = (x - xs[k]) / (xs[k + 1] - xs[k]);
        f = f < 0 ? 0 : f > 1 ? 1 : f;
        v = (1 - f) * vs[k] + f * vs[k + 1];
        CHECK_NEAR(P->x[1][i] + P->u[1][i] * dt, base0 + dh0 + shape[i] + v, 1e-16);
        nd++;
    }
    CHECK(nd == w.nd && nd > 0);
    /* the lower wall is not the model's */
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] != LUB_FLUID && P->patch[i] != cyl) CHECK(P->u[1][i] == 0.0);

    /* the step moves walls and dummies with their velocity (mps.h step 3) */
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] != LUB_FLUID && P->patch[i] == cyl) P->x[1][i] += P->u[1][i] * dt;
    /* same mean again: the shape holds, the patch moves by the new dh0: dy/dt = dh0/dt */
    double h0a = w.h0;
    CHECK(lub_mps_elastic_before(&w, t, dt, msg, sizeof msg) == LUB_STEP_OK);
    double dh0b = w.h0 - h0a;
    CHECK_NEAR(dh0b, dh0, 1e-20);
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] != LUB_FLUID && P->patch[i] == cyl)
            CHECK_NEAR(P->u[1][i], dh0b / dt, 1e-9 * fabs(dh0b / dt));

    /* after the step: the mean takes the step's wall pressure with weight 2/(N + 1) */
    const double a = 2.0 / 11.0;
    for (size_t i = 0; i < P->n; i++) P->p[i] = 1.0e5;
    lub_mps_elastic_after(&w, t + dt);
    CHECK(w.samples == 1);
    for (int k = 0; k < nw; k++) CHECK_NEAR(mean[idx[k]], ps[k] + a * (1.0e5 - ps[k]), 1e-9);
    double Lm = 0, Li = 0;
    for (int k = 0; k < nw; k++) Lm += mean[idx[k]] * ws[k], Li += 1.0e5 * ws[k];
    CHECK_NEAR(w.load, Lm, 1e-9 * Lm);
    CHECK_NEAR(w.load_instant, Li, 1e-9 * Li);
    CHECK_NEAR(w.load_target, 100 * (t + dt) / 1e-4, 1e-9);
    CHECK_NEAR(w.target_mean, 40.0 + a * (w.load_target - 40.0), 1e-12);

    /* a reorder of the particles is followed (the map is rebuilt from the ids) */
    for (size_t i = 0, j = P->n - 1; i < j; i++, j--) {
        double tx = P->x[0][i], ty = P->x[1][i], tp = P->p[i], tm = mean[i], ts = shape[i];
        uint64_t tid = P->id[i];
        uint8_t tk = P->kind[i];
        uint16_t tpa = P->patch[i];
        P->x[0][i] = P->x[0][j], P->x[1][i] = P->x[1][j], P->p[i] = P->p[j];
        mean[i] = mean[j], shape[i] = shape[j], P->id[i] = P->id[j], P->kind[i] = P->kind[j];
        P->patch[i] = P->patch[j];
        P->x[0][j] = tx, P->x[1][j] = ty, P->p[j] = tp, mean[j] = tm, shape[j] = ts;
        P->id[j] = tid, P->kind[j] = tk, P->patch[j] = tpa;
    }
    double load_before = w.load;
    lub_mps_elastic_after(&w, t + 2 * dt);
    CHECK_NEAR(w.load, load_before + a * (Li - load_before), 1e-9 * Li);

    free(idx);
    free(xs);
    free(ws);
    free(ps);
    free(vs);
    free(y0);
    lub_mps_elastic_free(&w);
    setup_free(&s);
}

/* The wall would come within l0/2 of the plane: refused, nothing changed. */
static void test_crossing(void)
{
    setup s;
    setup_make(&s,
               "elasticWall: { patch: cylinder, E: 1.0e7, load: 100, relaxation: 1.0,"
               " averageSteps: 10 }\n",
               NULL);
    lub_particles *P = &s.P;
    lub_mps_elastic w;
    CHECK(lub_mps_elastic_init(&w, &s.m, &s.g, s.models, NULL, 0, ""));
    /* no pressure, full load: beta = -1, dh0 = -relaxation h0^0 = -h0: the wall on the plane */
    char msg[512];
    w.target_mean = 100.0;
    double *u = malloc(P->n * sizeof *u);
    memcpy(u, P->u[1], P->n * sizeof *u);
    CHECK(lub_mps_elastic_before(&w, 0.0, 1e-7, msg, sizeof msg) == LUB_STEP_ESCAPED);
    CHECK_STR(msg, "within");
    CHECK_STR(msg, "l0/2");
    CHECK(w.h0 == w.e.h0);
    CHECK(memcmp(u, P->u[1], P->n * sizeof *u) == 0);
    free(u);
    lub_mps_elastic_free(&w);
    setup_free(&s);
}

/* The state of uniform/state.yaml and the particle fields restore the model exactly. */
static void test_restart_state(void)
{
    setup s;
    setup_make(&s, models_ok, NULL);
    lub_mps_elastic w;
    lub_mps_elastic_init(&w, &s.m, &s.g, s.models, NULL, 0, "");
    char msg[256];
    for (size_t i = 0; i < s.P.n; i++) s.P.p[i] = 2.0e4;
    for (int k = 0; k < 5; k++) {
        CHECK(lub_mps_elastic_before(&w, k * 1e-7, 1e-7, msg, sizeof msg) == LUB_STEP_OK);
        lub_mps_elastic_after(&w, (k + 1) * 1e-7);
    }
    char state[] = "/tmp/lubewsXXXXXX";
    write_file(state, "time: 5.0e-7\nstep: 5\ndeltaT: 1.0e-7\n");
    FILE *fp = fopen(state, "a");
    lub_mps_elastic_write_state(&w, fp);
    fclose(fp);
    lub_mps_elastic w2;
    CHECK(lub_mps_elastic_init(&w2, &s.m, &s.g, s.models, state, 0, ""));
    CHECK(w2.h0 == w.h0);
    CHECK(w2.samples == 5);
    CHECK(w2.target_mean == w.target_mean && w.target_mean > 0);
    CHECK(w2.load == w.load);
    lub_mps_elastic_free(&w2);
    /* the particles carry the fields, the state has no entry: incomplete */
    char bare[] = "/tmp/lubewbXXXXXX";
    write_file(bare, "time: 5.0e-7\nstep: 5\n");
    CHECK_FATAL(lub_mps_elastic_init(&w2, &s.m, &s.g, s.models, bare, 0, ""), "incomplete");
    CHECK_FATAL(lub_mps_elastic_init(&w2, &s.m, &s.g, s.models, NULL, 0, ""), "elasticShape");
    unlink(state);
    unlink(bare);
    lub_mps_elastic_free(&w);
    setup_free(&s);
}

static void test_bad_input(void)
{
    setup s;
    lub_mps_elastic w;
    setup_make(&s, "elasticWall: { patch: lowerWall, E: 1.0e7, load: 100 }\n", NULL);
    CHECK_FATAL(lub_mps_elastic_init(&w, &s.m, &s.g, s.models, NULL, 0, ""), "2-D cylinder");
    CHECK_STR(test_last_error, ":1:");
    setup_free(&s);
    setup_make(&s, "elasticWall: { patch: cylinder, E: 1.0e7, load: 100, rampTime: 2e-3 }\n", NULL);
    CHECK_FATAL(lub_mps_elastic_init(&w, &s.m, &s.g, s.models, NULL, 1e-3, "endTime 0.001"),
                "longer than the run");
    setup_free(&s);
    const double moving[3] = {0.5, 0, 0};
    setup_make(&s, "elasticWall: { patch: cylinder, E: 1.0e7, load: 100 }\n", moving);
    CHECK_FATAL(lub_mps_elastic_init(&w, &s.m, &s.g, s.models, NULL, 0, ""), "at rest");
    setup_free(&s);
    setup_make(&s, "elasticWall: { patch: cylinder, E: 1.0e7, load: 100, h0: 2.0e-6 }\n", NULL);
    CHECK_FATAL(lub_mps_elastic_init(&w, &s.m, &s.g, s.models, NULL, 0, ""), "l0/2");
    setup_free(&s);
    setup_make(&s, "elasticWall: { patch: cylinder, E: -1, load: 100 }\n", NULL);
    CHECK_FATAL(lub_mps_elastic_init(&w, &s.m, &s.g, s.models, NULL, 0, ""), "E' must be > 0");
    setup_free(&s);
    setup_make(&s, "elasticWall: { patch: cylinder, E: 1e7, load: 100, averageSteps: 0 }\n", NULL);
    CHECK_FATAL(lub_mps_elastic_init(&w, &s.m, &s.g, s.models, NULL, 0, ""), "averageSteps");
    setup_free(&s);
    /* no elasticWall: nothing to do */
    setup_make(&s, "gravity: { g: [0, -10] }\n", NULL);
    CHECK(lub_mps_elastic_init(&w, &s.m, &s.g, s.models, NULL, 0, "") == 0);
    CHECK(s.m.c.patch_moved[lub_particles_find_patch(&s.P, "cylinder")] == 0);
    lub_mps_elastic_free(&w);
    setup_free(&s);
}

/* ---- multi-resolution ------------------------------------------------------------------- */

/* The cylinder over the plane with two levels (fine 10 um owns [-0.2, 0.2] mm, coarse 20 um
 * the rest of the 1.2 mm period; overlaps 6 x 20 + 12 x 10 = 240 um at each boundary). */
static const char *geom_levels = "dimension: 2\n"
                                 "levels:\n"
                                 "  - { l0: 1.0e-5, region: [-2.0e-4, 2.0e-4] }\n"
                                 "  - { l0: 2.0e-5 }\n"
                                 "domain: { min: [-6.0e-4, -6.0e-5], max: [6.0e-4, 3.0e-4] }\n"
                                 "periodic: [x]\n"
                                 "walls:\n"
                                 "  lowerWall: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                                 "  cylinder:  { type: cylinder, lowestPoint: [0, 4.0e-5], "
                                 "radius: 1.0e-3, range: [-6.0e-4, 6.0e-4] }\n"
                                 "fluid:\n"
                                 "  - { type: layer, wall: lowerWall, thickness: 2.0e-5 }\n";

/* A Hertz-like mean pressure of half-width 70 um (inside the fine level's part that no
 * overlap reaches, |x| < 80 um). */
static double hertz_like(double x)
{
    double q = 1.0 - (x / 7.0e-5) * (x / 7.0e-5);
    return q > 0 ? 4.0e5 * sqrt(q) : 0.0;
}

/* The elastic wall across two levels (T-62..T-65): the pressure segments are the wall
 * particles whose x their level owns, each x once, with the half-way widths (the levels'
 * spacings inside their parts); the displacement is evaluated at every wall particle of both
 * levels (the overlaps included) from those segments only, so both levels' walls take one
 * shape; the load is the same owned sum; each level's mean takes its own wall pressure. */
static void test_levels(void)
{
    lub_geometry g;
    lub_particles P0;
    memset(&P0, 0, sizeof P0);
    char gpath[] = "/tmp/lubewgXXXXXX";
    write_file(gpath, geom_levels);
    lub_geometry_read(&g, gpath);
    unlink(gpath);
    lub_geometry_discretise(&g, &P0, 0, NULL);
    lub_dict *md =
        lub_dict_parse("constant/models.yaml", "multiResolution: { commonDeltaT: true }\n");
    lub_levels L;
    lub_levels_read(&L, lub_dict_map(lub_dict_root(md), "multiResolution"), &g);
    lub_dict_finish(md);
    lub_dict_free(md);
    lub_mps_config c;
    lub_mps_config_defaults(&c);
    c.rho = 810;
    c.nu = 4.5e-4;
    lub_opt o;
    lub_opt_init(&o, &L, &P0, &c, &g, 0.0);
    char models[] = "/tmp/lubewmXXXXXX";
    write_file(models, models_ok);
    lub_mps *ms[2] = {&o.m[0], &o.m[1]};
    lub_mps_elastic w;
    CHECK(lub_mps_elastic_init_levels(&w, ms, 2, &o.L, &g, models, NULL, 1e-3, "endTime") == 1);
    const int cyl = w.patch;
    CHECK(w.nlevels == 2 && o.m[0].c.patch_moved[cyl] && o.m[1].c.patch_moved[cyl]);

    /* every wall particle of a level is a target; the owned ones are the segments, once */
    int nw[2] = {0, 0}, nown = 0;
    for (int k = 0; k < 2; k++)
        for (size_t i = 0; i < o.P[k].n; i++) {
            if (o.P[k].kind[i] != LUB_WALL || o.P[k].patch[i] != cyl) continue;
            nw[k]++;
            lub_level_where lw;
            lub_levels_locate(&o.L, o.P[k].x[0][i], &lw);
            nown += lw.owner == k;
        }
    CHECK(w.lv[0].nw == nw[0] && w.lv[1].nw == nw[1] && w.nw == nw[0] + nw[1]);
    CHECK(w.ns == nown && nown < w.nw && nw[0] > 40 && nw[1] > 20);
    double wsum = 0;
    for (int s = 0; s < w.ns; s++) {
        const lub_mps_elastic_level *l = &w.lv[w.src_level[s]];
        lub_level_where lw;
        lub_levels_locate(&o.L, w.xs[s], &lw);
        CHECK(lw.owner == w.src_level[s] && l->xw[w.src_slot[s]] == w.xs[s]);
        if (s > 0) CHECK(w.xs[s] > w.xs[s - 1]);
        wsum += w.ws[s];
    }
    /* the half-way widths tile x from the first to the last segment */
    CHECK_NEAR(wsum, w.xs[w.ns - 1] - w.xs[0] + 0.5 * (w.ws[0] + w.ws[w.ns - 1]), 1e-15);

    /* a mean pressure on the owned wall particles, garbage on the others (never read) */
    double *xs = malloc((size_t)w.ns * sizeof *xs), *ps = malloc((size_t)w.ns * sizeof *ps);
    double Lsum = 0;
    for (int k = 0; k < 2; k++) {
        lub_particles *P = &o.P[k];
        double *mean = lub_particles_find_extra(P, "pWallMean");
        for (size_t i = 0; i < P->n; i++) {
            if (P->kind[i] != LUB_WALL || P->patch[i] != cyl) continue;
            lub_level_where lw;
            lub_levels_locate(&o.L, P->x[0][i], &lw);
            mean[i] = lw.owner == k ? hertz_like(P->x[0][i]) : 1.0e9;
        }
    }
    for (int s = 0; s < w.ns; s++) {
        xs[s] = w.xs[s];
        ps[s] = hertz_like(xs[s]);
        Lsum += ps[s] * w.ws[s];
    }
    const double t = 5.0e-5, dt = 2.5e-7, h00 = w.h0, base0 = w.y_floor + h00;
    w.target_mean = 40.0;
    const double dh0 = lub_elastic_dh0(&w.e, Lsum, 40.0);
    char msg[512];
    CHECK(lub_mps_elastic_before(&w, t, dt, msg, sizeof msg) == LUB_STEP_OK);
    CHECK(w.h0 == h00 + dh0);
    /* each wall particle of each level goes to T-50 with v from the owned segments */
    double vmax = 0;
    for (int k = 0; k < 2; k++) {
        lub_particles *P = &o.P[k];
        const double *shape = lub_particles_find_extra(P, "elasticShape");
        for (size_t i = 0; i < P->n; i++) {
            if (P->kind[i] != LUB_WALL || P->patch[i] != cyl) continue;
            double x = P->x[0][i], v;
            lub_elastic_displacement_direct(w.ns, xs, w.ws, 1, &x, w.e.E, w.e.b, ps, &v);
            CHECK_NEAR(P->x[1][i] + P->u[1][i] * dt, base0 + dh0 + shape[i] + v, 1e-16);
            vmax = fmax(vmax, fabs(v));
        }
    }
    CHECK(vmax > 1e-7);
    /* one shape: a fine and a coarse wall particle at the same x in an overlap would be at
     * the same height (T-50 with one h0 and one v: checked above at every particle); the
     * overlaps hold both levels' walls */
    int nover = 0;
    for (int q = 0; q < w.lv[0].nw; q++) {
        lub_level_where lw;
        lub_levels_locate(&o.L, w.lv[0].xw[q], &lw);
        nover += lw.present == 3u && lw.owner == 1;
    }
    CHECK(nover > 10); /* fine wall particles where the coarse level owns x */

    /* after the step: each level's mean takes its own wall pressure; the load is owned */
    const double a = 2.0 / 11.0;
    for (int k = 0; k < 2; k++)
        for (size_t i = 0; i < o.P[k].n; i++) o.P[k].p[i] = (k + 1) * 1.0e5;
    lub_mps_elastic_after(&w, t + dt);
    double Lm = 0, Li = 0;
    for (int s = 0; s < w.ns; s++) {
        const int k = w.src_level[s];
        const double pk = (k + 1) * 1.0e5;
        Lm += (ps[s] + a * (pk - ps[s])) * w.ws[s];
        Li += pk * w.ws[s];
    }
    for (int k = 0; k < 2; k++) {
        const lub_mps_elastic_level *l = &w.lv[k];
        const double *mean = lub_particles_find_extra(&o.P[k], "pWallMean");
        for (int q = 0; q < l->nw; q++) {
            const double x = l->xw[q];
            lub_level_where lw;
            lub_levels_locate(&o.L, x, &lw);
            const double m0 = lw.owner == k ? hertz_like(x) : 1.0e9;
            CHECK_NEAR(mean[l->idx[q]], m0 + a * ((k + 1) * 1.0e5 - m0), 1e-9 * fabs(m0) + 1e-9);
        }
    }
    CHECK_NEAR(w.load, Lm, 1e-9 * Lm);
    CHECK_NEAR(w.load_instant, Li, 1e-9 * Li);

    free(xs);
    free(ps);
    lub_mps_elastic_free(&w);
    unlink(models);
    lub_opt_free(&o);
    lub_particles_free(&P0);
    lub_geometry_free(&g);
}

int main(void)
{
    RUN(test_mean_window);
    RUN(test_wall_update);
    RUN(test_crossing);
    RUN(test_restart_state);
    RUN(test_bad_input);
    RUN(test_levels);
    return test_summary();
}
