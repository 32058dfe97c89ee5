/* Unit tests of src/models/multiResolution/levels: the multiResolution entry of
 * constant/models.yaml, checked against the levels of system/particleGenDict.yaml, and the regions
 * of the overlapping particle technique (methods.md §3; thesis §2-2).
 *
 * Reference numbers, by hand, for the thesis wedge with OPT (methods.md §6.1, case 6; the
 * geometry of tutorials/wedge/cylinderFlatOPT): fine l0 = 5 um owns [a1, a2] = [-3.6, 3.0] mm,
 * coarse l0 = 40 um the rest of the 20 mm period.
 *     Nr = 40 / 5 = 8 (T-19), L = 6 x 40 + 12 x 5 = 300 um (T-24),
 *     fine band 4 x 5 = 20 um, coarse band 4 x 40 = 160 um (T-25, T-26),
 *     fine margin 60 um past a1, a2; coarse margin 240 um inside them:
 *     overlaps [-3.66, -3.36] mm and [2.76, 3.06] mm,
 *     fine extended region [-3.66, 3.06] mm, coarse hole (-3.36, 2.76) mm.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "geometry/discretise.h"
#include "geometry/geometry.h"
#include "io/dict.h"
#include "models/multiResolution/levels.h"
#include "test.h"

static char geo_path[256];

/* Write particleGenDict text to a temporary file and read it. */
static void read_geometry(lub_geometry *g, const char *text)
{
    snprintf(geo_path, sizeof geo_path, "/tmp/lub_levels_test_%ld.yaml", (long)getpid());
    FILE *f = fopen(geo_path, "w");
    fputs(text, f);
    fclose(f);
    lub_geometry_read(g, geo_path);
}

/* the OPT wedge of the thesis (as tutorials/wedge/cylinderFlatOPT/system/particleGenDict) */
static const char *wedge_geo =
    "dimension:   2\n"
    "levels:\n"
    "  - { l0: 5.0e-6, region: [-0.0036, 0.0030] }\n"
    "  - { l0: 4.0e-5 }\n"
    "domain:      { min: [-0.01, -1.2e-4], max: [0.01, 1.4e-3] }\n"
    "periodic:    [x]\n"
    "walls:\n"
    "  lowerWall: { type: plane, point: [0, 0], normal: [0, 1] }\n"
    "  cylinder:  { type: cylinder, lowestPoint: [0, 4.0e-5], radius: 0.04, "
    "range: [-0.01, 0.01] }\n"
    "fluid:\n"
    "  - { type: layer, wall: lowerWall, thickness: 8.0e-5 }\n";

/* and its models.yaml (as the tutorial's) */
static const char *wedge_models =
    "gravity:     { g: [0, -9.81] }\n"
    "multiResolution: { levels: [ {l0: 5e-6}, {l0: 4e-5} ], fineRegion: [-0.0036, 0.0030],\n"
    "                   massCorrection: { cMax: 0.24, cMin: 0.048, relax: 10 } }\n";

/* Parse models text, read multiResolution against g, finish the dictionary.  The dictionary
 * is kept in models_dict until freed, so that a fatal error (longjmp) does not leak it. */
static lub_dict *models_dict;
static void read_levels(lub_levels *L, const char *models, const lub_geometry *g)
{
    models_dict = lub_dict_parse("constant/models.yaml", models);
    lub_node *r = lub_dict_root(models_dict);
    lub_node *mr = lub_dict_map(r, "multiResolution");
    lub_dict_find(r, "gravity");
    lub_levels_read(L, mr, g);
    lub_dict_finish(models_dict);
    lub_dict_free(models_dict);
    models_dict = NULL;
}

/* Expect a fatal error whose message contains sub and "<file>:<line>:" (file NULL: the
 * models dictionary). */
static void check_bad(const char *geo, const char *models, const char *file, int line,
                      const char *sub, int srcline)
{
    lub_geometry g;
    read_geometry(&g, geo);
    lub_levels L;
    int before = test_failed_checks_;
    CHECK_FATAL(read_levels(&L, models, &g), sub);
    lub_dict_free(models_dict);
    models_dict = NULL;
    char loc[400];
    snprintf(loc, sizeof loc, "%s:%d:", file ? file : "constant/models.yaml", line);
    CHECK_STR(test_last_error, loc);
    printf("  > %s\n", test_last_error); /* the message, for the log */
    if (test_failed_checks_ != before) printf("  (case at line %d)\n", srcline);
    lub_geometry_free(&g);
}
#define BAD(geo, models, file, line, sub) check_bad(geo, models, file, line, sub, __LINE__)

static void test_wedge_round_trip(void)
{
    lub_geometry g;
    read_geometry(&g, wedge_geo);
    lub_levels L;
    read_levels(&L, wedge_models, &g);
    CHECK(L.dim == 2 && L.nlevels == 2);
    CHECK(L.periodic && L.xmin == -0.01 && L.xmax == 0.01);
    CHECK(L.level[0].l0 == 5e-6 && L.level[1].l0 == 4e-5);
    CHECK(L.level[0].region[0] == -0.0036 && L.level[0].region[1] == 0.0030);
    CHECK(L.level[0].bounded[0] && L.level[0].bounded[1]);
    CHECK(L.level[0].nr == 8 && L.level[1].nr == 1);
    CHECK(L.level[0].dt_factor == 1 && L.level[1].dt_factor == 8);
    CHECK(!L.common_dt);
    CHECK(L.overlap_coarse == 6 && L.overlap_fine == 12);
    CHECK_NEAR(lub_levels_overlap(&L, 0), 3.0e-4, 1e-18);
    CHECK_NEAR(L.level[0].band, 2.0e-5, 1e-19);
    CHECK_NEAR(L.level[1].band, 1.6e-4, 1e-18);
    CHECK_NEAR(L.level[0].ext[0], -0.00366, 1e-15);
    CHECK_NEAR(L.level[0].ext[1], 0.00306, 1e-15);
    CHECK(!L.level[0].has_hole);
    CHECK(L.level[1].has_hole);
    CHECK_NEAR(L.level[1].hole[0], -0.00336, 1e-15);
    CHECK_NEAR(L.level[1].hole[1], 0.00276, 1e-15);
    CHECK(L.level[1].ext[0] == -0.01 && L.level[1].ext[1] == 0.01);
    CHECK(L.nboundaries == 2);
    const lub_level_boundary *a1 = &L.boundary[0], *a2 = &L.boundary[1];
    CHECK(a1->x == -0.0036 && a1->fine == 0 && a1->coarse == 1 && a1->side == 0);
    CHECK(a2->x == 0.0030 && a2->fine == 0 && a2->coarse == 1 && a2->side == 1);
    CHECK_NEAR(a1->lo, -0.00366, 1e-15);
    CHECK_NEAR(a1->hi, -0.00336, 1e-15);
    CHECK_NEAR(a2->lo, 0.00276, 1e-15);
    CHECK_NEAR(a2->hi, 0.00306, 1e-15);
    CHECK(L.mass_correction);
    CHECK(L.c_max == 0.24 && L.c_min == 0.048 && L.relax == 10 && L.threshold == 0.002);
    CHECK(L.line == 2 && strcmp(L.file, "constant/models.yaml") == 0);
    char desc[512];
    lub_levels_describe(&L, desc, sizeof desc);
    printf("  %s\n", desc);
    CHECK_STR(desc, "2 levels: l0 5e-06 in [-0.0036, 0.003], 4e-05; Nr 8; overlap 0.0003 m");

    /* the same with every default written out, and with the minimal entry */
    lub_levels M;
    read_levels(&M,
                "multiResolution:\n"
                "  Nr: 8\n"
                "  commonDeltaT: false\n"
                "  overlap: { coarse: 6, fine: 12 }\n"
                "  fixedBand: 4\n"
                "  massCorrection: { cMax: 0.24, cMin: 0.048, relax: 10, threshold: 0.002 }\n",
                &g);
    CHECK(M.level[0].nr == 8 && M.nboundaries == 2 && M.boundary[1].hi == L.boundary[1].hi);
    CHECK(M.level[1].band == L.level[1].band && M.c_min == L.c_min);
    read_levels(&M, "multiResolution: {}\n", &g);
    CHECK(M.level[0].nr == 8 && !M.mass_correction && M.boundary[0].lo == L.boundary[0].lo);
    lub_geometry_free(&g);
}

/* Which level owns x, which are present, fixed, generating, and in which overlap (the
 * numbers of the file comment; points kept off the edges). */
static void test_wedge_locate(void)
{
    lub_geometry g;
    read_geometry(&g, wedge_geo);
    lub_levels L;
    read_levels(&L, wedge_models, &g);
    struct {
        double x;
        int owner;
        unsigned present, fixed, generate;
        int boundary;
    } t[] = {
        {0.0, 0, 1, 0, 0, -1},       /* contact: fine only */
        {-0.0050, 1, 2, 0, 0, -1},   /* inlet, upstream of the overlap: coarse only */
        {0.0050, 1, 2, 0, 0, -1},    /* outlet */
        {-0.003700, 1, 2, 0, 0, -1}, /* just upstream of the fine level's reach */
        {-0.003658, 1, 3, 1, 1, 0},  /* fine generation layer (2 um from its edge) */
        {-0.003650, 1, 3, 1, 0, 0},  /* fine band, not its generation layer */
        {-0.003620, 1, 3, 0, 0, 0},  /* both free */
        {-0.0036, 0, 3, 0, 0, 0},    /* a1 itself belongs to the fine level */
        {-0.003450, 0, 3, 2, 0, 0},  /* coarse band (90 um from its edge) */
        {-0.003390, 0, 3, 2, 2, 0},  /* coarse generation layer (30 um) */
        {-0.003300, 0, 1, 0, 0, -1}, /* inside the coarse level's hole */
        {0.002700, 0, 1, 0, 0, -1},  /* hole, outlet side */
        {0.002790, 0, 3, 2, 2, 1},   /* coarse generation layer at a2 */
        {0.002900, 0, 3, 2, 0, 1},   /* coarse band */
        {0.003010, 1, 3, 0, 0, 1},   /* past a2: coarse owns, fine free */
        {0.003050, 1, 3, 1, 0, 1},   /* fine band */
        {0.003057, 1, 3, 1, 1, 1},   /* fine generation layer */
        {0.003100, 1, 2, 0, 0, -1},  /* past the fine level's reach */
        {0.0150, 1, 2, 0, 0, -1},    /* periodic: -0.005 + 0.02 */
        {0.0199, 0, 1, 0, 0, -1},    /* -0.0001 + 0.02 */
        {0.02, 0, 1, 0, 0, -1},      /* 0 + 0.02 */
        {-0.0236, 0, 3, 0, 0, 0},    /* -0.0036 - 0.02: a1 */
    };
    int bad = 0;
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
        lub_level_where w;
        lub_levels_locate(&L, t[i].x, &w);
        if (w.owner != t[i].owner || w.present != t[i].present || w.fixed != t[i].fixed ||
            w.generate != t[i].generate || w.boundary != t[i].boundary) {
            printf("  x = %g: owner %d present %u fixed %u generate %u boundary %d; expected "
                   "%d %u %u %u %d\n",
                   t[i].x, w.owner, w.present, w.fixed, w.generate, w.boundary, t[i].owner,
                   t[i].present, t[i].fixed, t[i].generate, t[i].boundary);
            bad++;
        }
    }
    CHECK(bad == 0);
    /* the band and generation layer widths: scan x at 0.1 um and measure them */
    double fixed_len[2] = {0, 0}, gen_len[2] = {0, 0}, both = 0, dx = 1e-7;
    for (double x = -0.0040; x < -0.0032; x += dx) {
        lub_level_where w;
        lub_levels_locate(&L, x, &w);
        for (int k = 0; k < 2; k++) {
            if (w.fixed >> k & 1u) fixed_len[k] += dx;
            if (w.generate >> k & 1u) gen_len[k] += dx;
        }
        if (w.present == 3) both += dx;
        CHECK(!(w.fixed == 3)); /* the bands never meet */
    }
    CHECK_NEAR(fixed_len[0], 2e-5, 2 * dx);
    CHECK_NEAR(fixed_len[1], 1.6e-4, 2 * dx);
    CHECK_NEAR(gen_len[0], 5e-6, 2 * dx);
    CHECK_NEAR(gen_len[1], 4e-5, 2 * dx);
    CHECK_NEAR(both, 3e-4, 2 * dx); /* the overlap is L long */
    lub_geometry_free(&g);
}

/* Three nested levels in a non-periodic domain; l0 ratios 2 and 4; explicit Nr; and the
 * owner of every particle particleGen generates agrees with lub_levels_locate. */
static const char *three_geo = "dimension: 2\n"
                               "levels:\n"
                               "  - { l0: 0.01, region: [0.4, 0.6] }\n"
                               "  - { l0: 0.02, region: [0.2, 0.8] }\n"
                               "  - { l0: 0.08 }\n"
                               "domain: { min: [0, -0.24], max: [1.28, 1] }\n"
                               "walls:\n"
                               "  floor: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                               "fluid:\n"
                               "  - { type: layer, wall: floor, thickness: 0.16 }\n";

static void test_three_levels(void)
{
    lub_geometry g;
    read_geometry(&g, three_geo);
    lub_levels L;
    read_levels(&L, "multiResolution: { overlap: { coarse: 2, fine: 3 }, fixedBand: 1.5 }\n", &g);
    CHECK(L.nlevels == 3 && !L.periodic);
    CHECK(L.level[0].nr == 2 && L.level[1].nr == 4 && L.level[2].nr == 1);
    CHECK(L.level[0].dt_factor == 1 && L.level[1].dt_factor == 2 && L.level[2].dt_factor == 8);
    CHECK(L.nboundaries == 4);
    const double xs[4] = {0.2, 0.4, 0.6, 0.8};
    const int fine[4] = {1, 0, 0, 1};
    for (int i = 0; i < 4; i++) CHECK(L.boundary[i].x == xs[i] && L.boundary[i].fine == fine[i]);
    /* 0.2: levels 1 | 2: [0.2 - 3 x 0.02, 0.2 + 2 x 0.08] */
    CHECK_NEAR(L.boundary[0].lo, 0.14, 1e-15);
    CHECK_NEAR(L.boundary[0].hi, 0.36, 1e-15);
    /* 0.4: levels 0 | 1: [0.4 - 3 x 0.01, 0.4 + 2 x 0.02] */
    CHECK_NEAR(L.boundary[1].lo, 0.37, 1e-15);
    CHECK_NEAR(L.boundary[1].hi, 0.44, 1e-15);
    CHECK_NEAR(L.level[1].ext[0], 0.14, 1e-15);
    CHECK_NEAR(L.level[1].hole[0], 0.44, 1e-15);
    CHECK_NEAR(L.level[2].hole[0], 0.36, 1e-15);
    CHECK_NEAR(lub_levels_overlap(&L, 1), 0.22, 1e-15);
    lub_level_where w;
    lub_levels_locate(&L, 0.30, &w); /* level 2's band: 0.06 from its hole, band 0.12 */
    CHECK(w.owner == 1 && w.present == 6 && w.fixed == 4 && w.boundary == 0);
    lub_levels_locate(&L, 0.50, &w);
    CHECK(w.owner == 0 && w.present == 1);
    lub_levels_locate(&L, 1.20, &w);
    CHECK(w.owner == 2 && w.present == 4 && w.fixed == 0 && w.boundary == -1);
    /* the domain ends are not boundaries: no band there */
    lub_levels_locate(&L, 0.001, &w);
    CHECK(w.owner == 2 && w.fixed == 0 && w.generate == 0);

    /* Nr as one value or one per pair; commonDeltaT */
    read_levels(&L, "multiResolution: { Nr: 3, overlap: { coarse: 2, fine: 3 }, fixedBand: 1 }\n",
                &g);
    CHECK(L.level[0].nr == 3 && L.level[1].nr == 3 && L.level[2].dt_factor == 9);
    read_levels(&L,
                "multiResolution: { Nr: [2, 5], overlap: { coarse: 2, fine: 3 }, fixedBand: 1 "
                "}\n",
                &g);
    CHECK(L.level[0].nr == 2 && L.level[1].nr == 5 && L.level[2].dt_factor == 10);
    read_levels(&L,
                "multiResolution: { commonDeltaT: true, overlap: { coarse: 2, fine: 3 },\n"
                "                   fixedBand: 1, levels: [ {}, {fixedBand: 2}, {l0: 0.08} ] }\n",
                &g);
    CHECK(L.common_dt && L.level[0].nr == 1 && L.level[2].dt_factor == 1);
    CHECK_NEAR(L.level[0].band, 0.01, 1e-16);
    CHECK_NEAR(L.level[1].band, 0.04, 1e-16);

    /* every particle particleGen makes is owned by its level */
    lub_particles P;
    lub_geometry_discretise(&g, &P, 0, NULL);
    read_levels(&L, "multiResolution: { overlap: { coarse: 2, fine: 3 }, fixedBand: 1.5 }\n", &g);
    size_t bad = 0;
    int seen[3] = {0, 0, 0};
    for (size_t i = 0; i < P.n; i++) {
        lub_levels_locate(&L, P.x[0][i], &w);
        if (w.owner != P.level[i]) bad++;
        if (!(w.present >> P.level[i] & 1u)) bad++;
        seen[P.level[i]] = 1;
    }
    printf("  %zu particles, %zu disagree with particleGen's levels\n", P.n, bad);
    CHECK(bad == 0 && seen[0] && seen[1] && seen[2]);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* A fine region at the end of a non-periodic domain: one boundary only. */
static void test_region_at_domain_end(void)
{
    lub_geometry g;
    read_geometry(&g, "dimension: 2\n"
                      "levels:\n  - { l0: 0.01, region: [0, 0.3] }\n  - { l0: 0.04 }\n"
                      "domain: { min: [0, 0], max: [1.2, 1] }\n");
    lub_levels L;
    read_levels(&L, "multiResolution: {}\n", &g);
    CHECK(L.nboundaries == 1 && L.boundary[0].x == 0.3 && L.boundary[0].side == 1);
    CHECK(!L.level[0].bounded[0] && L.level[0].bounded[1]);
    CHECK(L.level[0].ext[0] == 0.0);
    CHECK(isinf(L.level[1].hole[0]) && L.level[1].hole[0] < 0);
    lub_level_where w;
    lub_levels_locate(&L, 0.001, &w);
    CHECK(w.owner == 0 && w.present == 1 && w.fixed == 0);
    lub_levels_locate(&L, 0.2, &w); /* inside the coarse margin 0.3 - 6 x 0.04 = 0.06 */
    CHECK(w.present == 3 && w.fixed == 2);
    lub_geometry_free(&g);
}

static void test_time_weight(void)
{
    /* T-20 corrected: at b = 0 the coarse value is the level-K one */
    CHECK(lub_levels_time_weight(0, 8) == 1.0);
    CHECK(lub_levels_time_weight(4, 8) == 0.5);
    CHECK(lub_levels_time_weight(7, 8) == 0.125);
    CHECK(lub_levels_time_weight(0, 1) == 1.0);
}

/* Every bad input: fatal, with file:line of the entry at fault. */
static void test_bad_input(void)
{
    const char *one = "dimension: 2\nl0: 5.0e-6\n"
                      "domain: { min: [-0.01, 0], max: [0.01, 1e-3] }\nperiodic: [x]\n";
    const char *ratio = "dimension: 2\nlevels:\n"
                        "  - { l0: 2.0e-5, region: [-0.004, 0.004] }\n  - { l0: 5.0e-5 }\n"
                        "domain: { min: [-0.01, 0], max: [0.01, 1e-3] }\nperiodic: [x]\n";
    const char *small = "dimension: 2\nlevels:\n"
                        "  - { l0: 5.0e-6, region: [-0.0001, 0.0001] }\n  - { l0: 4.0e-5 }\n"
                        "domain: { min: [-0.01, 0], max: [0.01, 1e-3] }\nperiodic: [x]\n";
    const char *seam = "dimension: 2\nlevels:\n"
                       "  - { l0: 5.0e-6, region: [-0.0036, 0.0030] }\n  - { l0: 4.0e-5 }\n"
                       "domain: { min: [-0.00364, 0], max: [0.00304, 1e-3] }\nperiodic: [x]\n";
    const char *touch = "dimension: 2\nlevels:\n"
                        "  - { l0: 5.0e-6, region: [-0.01, 0.0030] }\n  - { l0: 4.0e-5 }\n"
                        "domain: { min: [-0.01, 0], max: [0.01, 1e-3] }\nperiodic: [x]\n";
    const char *nonper = "dimension: 2\nlevels:\n"
                         "  - { l0: 0.01, region: [0.05, 0.6] }\n  - { l0: 0.04 }\n"
                         "domain: { min: [0, 0], max: [1.2, 1] }\n";
    const char *unnested = "dimension: 2\nlevels:\n"
                           "  - { l0: 0.01, region: [0.4, 0.6] }\n"
                           "  - { l0: 0.02, region: [0.5, 0.8] }\n"
                           "  - { l0: 0.08 }\n"
                           "domain: { min: [0, 0], max: [1.28, 1] }\n";
    const char *shared = "dimension: 2\nlevels:\n"
                         "  - { l0: 0.01, region: [0.4, 0.6] }\n"
                         "  - { l0: 0.02, region: [0.4, 0.8] }\n"
                         "  - { l0: 0.08 }\n"
                         "domain: { min: [0, 0], max: [1.28, 1] }\n";
    char gl[300];
    snprintf(gl, sizeof gl, "%s:4", geo_path); /* particleGenDict's line of wedge level 1 */

    /* fewer than 2 levels: in particleGenDict, and in a restated list */
    BAD(one, "multiResolution: { Nr: 2 }\n", NULL, 1, "needs at least 2 resolution levels");
    CHECK_STR(test_last_error, "gives a single l0");
    BAD(wedge_geo, "multiResolution:\n  levels: [ {l0: 5e-6} ]\n", NULL, 2,
        "'levels' must list at least 2 levels, found 1");
    BAD(wedge_geo, "multiResolution:\n  levels: [ {l0: 5e-6}, {l0: 4e-5}, {l0: 8e-5} ]\n", NULL, 2,
        "lists 3 levels but");
    /* restated levels that disagree with particleGenDict (or are not ordered) */
    BAD(wedge_geo, "multiResolution:\n  levels:\n    - {l0: 5e-6}\n    - {l0: 8e-5}\n", NULL, 4,
        "level 1 has l0 = 8e-05 here but l0 = 4e-05 in");
    CHECK_STR(test_last_error, gl);
    BAD(wedge_geo, "multiResolution:\n  levels: [ {l0: 4e-5}, {l0: 5e-6} ]\n", NULL, 2,
        "level 0 has l0 = 4e-05 here but l0 = 5e-06");
    BAD(wedge_geo, "multiResolution:\n  fineRegion: [-0.0032, 0.0030]\n", NULL, 2,
        "'fineRegion' [-0.0032, 0.003] differs from level 0's region [-0.0036, 0.003]");
    BAD(wedge_geo,
        "multiResolution:\n  levels: [ {region: [-0.0036, 0.0030]}, {} ]\n"
        "  fineRegion: [-0.0036, 0.0030]\n",
        NULL, 3, "either as 'fineRegion' or in 'levels'");
    BAD(wedge_geo, "multiResolution:\n  levels: [ {}, {region: [-0.01, 0.01]} ]\n", NULL, 2,
        "level 1 has no region in");
    BAD(wedge_geo, "multiResolution:\n  levels: [ {region: [-0.0036, 0.0031]}, {} ]\n", NULL, 2,
        "level 0's region [-0.0036, 0.0031] differs from [-0.0036, 0.003]");
    /* not nested (in particleGenDict: its line of the coarser level) */
    BAD(unnested, "multiResolution: {}\n", geo_path, 4, "levels are not nested");
    BAD(shared, "multiResolution: {}\n", geo_path, 4, "levels are not nested");
    BAD(touch, "multiResolution: {}\n", geo_path, 3, "reaches the periodic ends of x");
    /* an overlap longer than a level region */
    BAD(small, "multiResolution: {}\n", NULL, 1, "an overlap is longer than a level region");
    CHECK_STR(test_last_error, "meet inside level 0's region");
    BAD(wedge_geo, "multiResolution:\n  overlap: { coarse: 100 }\n", NULL, 2,
        "an overlap is longer than a level region");
    BAD(seam, "multiResolution: {}\n", NULL, 1, "meet across the periodic seam");
    BAD(nonper, "multiResolution: {}\n", NULL, 1, "reaches past the domain's x [0, 1.2]");
    /* l0 ratio not an integer where Nr defaults to it; explicit Nr or commonDeltaT accept it */
    BAD(ratio, "multiResolution: {}\n", NULL, 1, "is 2.5 times level 0's");
    CHECK_STR(test_last_error, "give 'Nr'");
    {
        lub_geometry g;
        read_geometry(&g, ratio);
        lub_levels L;
        read_levels(&L, "multiResolution: { Nr: 2 }\n", &g);
        CHECK(L.level[0].nr == 2);
        read_levels(&L, "multiResolution: { commonDeltaT: yes }\n", &g);
        CHECK(L.level[0].nr == 1 && L.common_dt);
        lub_geometry_free(&g);
    }
    /* Nr */
    BAD(wedge_geo, "multiResolution:\n  Nr: 0\n", NULL, 2,
        "'multiResolution.Nr' must be between 1 and 1024, found '0'");
    BAD(wedge_geo, "multiResolution:\n  Nr: -3\n", NULL, 2, "must be between 1 and 1024");
    BAD(wedge_geo, "multiResolution:\n  Nr: 2.5\n", NULL, 2, "expects an integer");
    BAD(wedge_geo, "multiResolution:\n  Nr: [8, 2]\n", NULL, 2,
        "'Nr' lists 2 values; 2 levels need 1");
    BAD(wedge_geo, "multiResolution:\n  Nr: { a: 1 }\n", NULL, 2, "expects an integer or a list");
    BAD(wedge_geo, "multiResolution:\n  Nr: 8\n  commonDeltaT: true\n", NULL, 2,
        "either 'Nr' or 'commonDeltaT: true'");
    BAD(wedge_geo, "multiResolution:\n  commonDeltaT: maybe\n", NULL, 2, "commonDeltaT");
    /* bands, overlap */
    BAD(wedge_geo, "multiResolution:\n  fixedBand: 7\n", NULL, 2,
        "fixed-velocity bands of levels 0 and 1");
    BAD(wedge_geo, "multiResolution:\n  fixedBand: 0.5\n", NULL, 2,
        "'multiResolution.fixedBand' must be >= 1");
    BAD(wedge_geo, "multiResolution:\n  overlap: { coarse: -1 }\n", NULL, 2,
        "'multiResolution.overlap.coarse' must be >= 0");
    BAD(wedge_geo, "multiResolution:\n  overlap: { coarse: 4, fine: 0 }\n", NULL, 2,
        "do not fit in their overlap");
    /* mass correction */
    BAD(wedge_geo, "multiResolution:\n  massCorrection: { cMin: 0.05 }\n", NULL, 2,
        "missing required key 'cMax'");
    BAD(wedge_geo, "multiResolution:\n  massCorrection:\n    cMax: 0.1\n    cMin: 0.2\n", NULL, 4,
        "cMin (0.2) must not exceed cMax (0.1)");
    BAD(wedge_geo, "multiResolution:\n  massCorrection: { cMax: 0.1, threshold: 1 }\n", NULL, 2,
        "'multiResolution.massCorrection.threshold' must be >= 0 and < 1");
    BAD(wedge_geo, "multiResolution:\n  massCorrection: { cMax: 0.1, relax: 0 }\n", NULL, 2,
        "'multiResolution.massCorrection.relax' must be > 0");
    /* types and unknown keys (reported by lub_dict_finish) */
    BAD(wedge_geo, "multiResolution: true\n", NULL, 1, "expects a mapping");
    BAD(wedge_geo, "multiResolution:\n  fixedBands: 4\n", NULL, 2,
        "unknown key 'fixedBands' in 'multiResolution' (did you mean 'fixedBand'?)");
    BAD(wedge_geo, "multiResolution:\n  massCorrection: { cMax: 0.1, cmin: 0.01 }\n", NULL, 2,
        "unknown key 'cmin' in 'multiResolution.massCorrection' (did you mean 'cMin'?)");
    BAD(wedge_geo, "multiResolution:\n  levels: [ {l0: 5e-6, regoin: [0, 1]}, {} ]\n", NULL, 2,
        "unknown key 'regoin'");
    BAD(wedge_geo, "multiResolution:\n  levels: 2\n", NULL, 2, "levels");
}

/* lub_levels_read_case: particleGenDict from its path; the particles must carry its levels. */
static void test_read_case(void)
{
    lub_geometry g;
    read_geometry(&g, three_geo);
    lub_particles P;
    lub_geometry_discretise(&g, &P, 0, NULL);
    lub_dict *d =
        lub_dict_parse("constant/models.yaml",
                       "multiResolution: { overlap: { coarse: 2, fine: 3 }, fixedBand: 1.5 }\n");
    lub_node *mr = lub_dict_map(lub_dict_root(d), "multiResolution");
    lub_levels L;
    lub_levels_read_case(&L, mr, geo_path, &P);
    CHECK(L.nlevels == 3 && L.level[2].l0 == 0.08);
    P.levels[1].l0 = 0.025;
    CHECK_FATAL(lub_levels_read_case(&L, mr, geo_path, &P), "the particles' level 1 has l0");
    CHECK_STR(test_last_error, "constant/models.yaml:1:");
    CHECK_STR(test_last_error, "run particleGen again");
    P.nlevels = 1;
    CHECK_FATAL(lub_levels_read_case(&L, mr, geo_path, &P),
                "the particles have 1 resolution level but");
    lub_levels_read_case(&L, mr, geo_path, NULL);
    CHECK(L.nlevels == 3);
    lub_dict_free(d);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* The film across a boundary (lub_levels_gap): under the wedge's cylinder the clearance
 * R - sqrt(R^2 - x^2) + h0 between the plane and the cylinder; without the cylinder the depth
 * of the 80 um layer; where no fluid region reaches, none. */
static void test_gap(void)
{
    lub_geometry g;
    read_geometry(&g, wedge_geo);
    const double R = 0.04, h0 = 4e-5;
    const double xs[] = {-0.0036, 0.0030, 0.0, -0.0095};
    for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++) {
        const double x = xs[i], h = h0 + R - sqrt(R * R - x * x);
        lub_level_gap gp;
        lub_levels_gap(&g, x, 1.25e-6, &gp);
        CHECK(gp.kind == LUB_GAP_WALLS);
        CHECK(gp.wall_lo == 0 && gp.wall_hi == 1);
        CHECK_NEAR(gp.h, h, 1e-15);
        CHECK_NEAR(gp.ylo, 0.0, 1e-15);
        printf("  x = %g: gap %.9g m (by hand %.9g), %.3f coarse particles across\n", x, gp.h, h,
               gp.h / 4e-5);
    }
    lub_geometry_free(&g);

    /* no cylinder: the layer's depth (the free surface at 80 um) */
    char text[2048];
    snprintf(text, sizeof text, "%s", wedge_geo);
    char *cyl = strstr(text, "  cylinder:");
    char *end = strstr(cyl, "fluid:");
    memmove(cyl, end, strlen(end) + 1);
    read_geometry(&g, text);
    lub_level_gap gp;
    lub_levels_gap(&g, -0.0036, 1.25e-6, &gp);
    CHECK(gp.kind == LUB_GAP_FLUID);
    CHECK(gp.wall_lo == 0 && gp.wall_hi == -1);
    CHECK_NEAR(gp.h, 8e-5, 1e-15);
    CHECK_NEAR(gp.yhi, 1.4e-3, 1e-15);
    lub_geometry_free(&g);

    /* a box of fluid away from x: none */
    snprintf(text, sizeof text, "%s", wedge_geo);
    char *layer = strstr(text, "  - { type: layer");
    snprintf(layer, sizeof text - (size_t)(layer - text),
             "  - { type: box, min: [0.005, 0], max: [0.008, 5e-5] }\n");
    read_geometry(&g, text);
    lub_levels_gap(&g, -0.0036, 1.25e-6, &gp);
    CHECK(gp.kind == LUB_GAP_NONE);
    lub_levels_gap(&g, 0.006, 1.25e-6, &gp); /* the box under the cylinder */
    CHECK(gp.kind == LUB_GAP_WALLS);
    CHECK_NEAR(gp.h, h0 + R - sqrt(R * R - 0.006 * 0.006), 1e-15);
    lub_geometry_free(&g);
}

/* The owned part of a particle's cell (T-27, lub_levels_owned_fraction), on the thesis'
 * wedge levels (fine 5 um owns [-3.6, 3.0] mm, coarse 40 um the rest of the 20 mm period):
 * cells wholly inside or outside, cells straddling a1 and a2 (by hand), and the sums over a
 * lattice of each level covering the whole period at any offset: the owned lengths over l0,
 * 1320 fine and 335 coarse cells, whatever the lattice's phase (the space counted once). */
static void test_owned_fraction(void)
{
    lub_geometry g;
    read_geometry(&g, wedge_geo);
    lub_levels L;
    read_levels(&L, wedge_models, &g);
    const double lf = 5e-6, lc = 4e-5, a1 = -0.0036, a2 = 0.003;
    CHECK_NEAR(lub_levels_owned_fraction(&L, 0, 0.0), 1.0, 0);
    CHECK_NEAR(lub_levels_owned_fraction(&L, 1, 0.0), 0.0, 0);
    CHECK_NEAR(lub_levels_owned_fraction(&L, 0, -0.005), 0.0, 0);
    CHECK_NEAR(lub_levels_owned_fraction(&L, 1, -0.005), 1.0, 0);
    /* straddling: a fine cell centred 1 um inside a1 has 3.5 of its 5 um inside; a coarse
     * cell centred 10 um outside a2 has 30 of its 40 um outside; across the periodic seam a
     * coarse cell is wholly owned */
    CHECK_NEAR(lub_levels_owned_fraction(&L, 0, a1 + 1e-6), 3.5 / 5, 1e-9);
    CHECK_NEAR(lub_levels_owned_fraction(&L, 1, a1 + 1e-6), (lc / 2 - 1e-6) / lc, 1e-9);
    CHECK_NEAR(lub_levels_owned_fraction(&L, 1, a2 + 1e-5), 30.0 / 40, 1e-9);
    CHECK_NEAR(lub_levels_owned_fraction(&L, 1, 0.01), 1.0, 1e-12);
    CHECK_NEAR(lub_levels_owned_fraction(&L, 1, -0.01 + 1e-6), 1.0, 1e-12);
    for (int ph = 0; ph < 4; ph++) {
        const double phase = 0.3 * ph; /* lattice offset in l0 */
        double s0 = 0, s1 = 0;
        for (int i = 0; i < 4000; i++)
            s0 += lub_levels_owned_fraction(&L, 0, -0.01 + (i + phase) * lf);
        for (int i = 0; i < 500; i++)
            s1 += lub_levels_owned_fraction(&L, 1, -0.01 + (i + phase) * lc);
        CHECK_NEAR(s0, (a2 - a1) / lf, 1e-6);
        CHECK_NEAR(s1, (0.02 - (a2 - a1)) / lc, 1e-6);
    }
    lub_geometry_free(&g);
}

int main(void)
{
    RUN(test_wedge_round_trip);
    RUN(test_wedge_locate);
    RUN(test_three_levels);
    RUN(test_region_at_domain_end);
    RUN(test_time_weight);
    RUN(test_bad_input);
    RUN(test_read_case);
    RUN(test_gap);
    RUN(test_owned_fraction);
    unlink(geo_path);
    return test_summary();
}
