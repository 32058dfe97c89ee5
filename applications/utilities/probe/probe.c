/* probe: sample particle fields from the time folders of a case (design.md, issue 5).
 *
 *     probe wallPressure -patch cylinder -bin 2.5e-5 -average 0.024:0.030
 *     probe line -field p -from -0.004 -to 0.003 -bin 2.5e-5 -latestTime | postErr - ref.dat
 *     probe points -field p,U -at "0 2e-5; 1e-4 2e-5"
 *     probe film -bin 2e-5
 *     probe totals
 *     probe                      (every set of system/probeDict.yaml)
 *
 * The sampling itself is src/post (shared with the solver's function objects); this program
 * turns options or dictionary entries into sampling sets (probeDict.c), runs them over the
 * selected time folders (probeRun.c) and writes the tables (probeOutput.c).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/args.h"
#include "core/error.h"
#include "io/dict.h"
#include "probe.h"

static const char *description =
    "Subcommands (one per run; without one, the sets of system/probeDict.yaml are run):\n"
    "  wallPressure -patch NAME [-field LIST] [-bin DX] [-arc] [-facing DIR] [-from A -to B]\n"
    "      the wall particles (kind wall, not the dummies) of a patch.  Without -bin one row\n"
    "      per particle, sorted by x: '# x y p' (with -arc: '# s x y p'; -average: per\n"
    "      particle id); with -bin DX the mean per bin of x (or s): '# x p n'.  -arc:\n"
    "      against the arc length s along the wall of system/particleGenDict.yaml (2-D\n"
    "      cylinder: s = R theta from its lowest point, positive towards +x; plane,\n"
    "      segment, polyline: length along it; polygon: along its closed boundary from its\n"
    "      first vertex, counter-clockwise).  -facing down (up): only the wall particles\n"
    "      whose surface faces down (up), within 60 degrees (the normal from the centroid of\n"
    "      the dummy particles behind them): the lower face of a closed body (a polygon pad\n"
    "      over a film) without its top and steep faces, each x once.  Multi-resolution,\n"
    "      with -bin: the wall particles in the part of x their level owns, each x once.\n"
    "  line [-field LIST] [-from X0 -to X1] [-bin DX]\n"
    "      the fluid particles binned by x: per bin the mean over the film thickness of each\n"
    "      field and the count n of samples: '# x p n'.\n"
    "  points -at 'x y; x y ...' [-field LIST] [-history]\n"
    "      kernel-weighted (Shepard) mean at each point over the fluid and wall particles\n"
    "      within the effective radius re (of the level of the nearest particle), with the\n"
    "      MPS weight w(r) = (r/re - 1)^2 (T-6): sum w f / sum w.  '# x y p n' (n: particles\n"
    "      used).  A point with no particle within re is left out with a warning.\n"
    "      -history: one point, one row per time folder: '# t p n', the pressure history\n"
    "      at the point (e.g. the film centre of a squeeze film, beside reynoldsRef -series:\n"
    "      postErr -x t -yref pc history.dat postProcessing/reynoldsRef/0/pc.dat); a time\n"
    "      with no particle within re gives a row of nan and a warning.\n"
    "  film [-from X0 -to X1] [-bin DX]\n"
    "      the oil film per bin of x: '# x h surface bottom contact n filled full' (with\n"
    "      -dimensionless, X H after n).  Each bin is judged on its particles and, where it\n"
    "      is narrower than 3 l0, on those within 1.5 l0 of its centre: particle rows are\n"
    "      about l0 apart, and a narrower strip of a disordered film misses some of them (a\n"
    "      bin with no particle is not an air gap).  surface: y of the highest fluid\n"
    "      particle (the free surface: MPS puts p = 0 on the surface particles); bottom:\n"
    "      the wall surface under the film (highest\n"
    "      wall particle below the lowest fluid particle, if closer than 2 l0; else that\n"
    "      fluid particle); contact = 1 when a wall particle lies less than 2 l0 above the\n"
    "      surface (the oil touches the upper wall); h = (upper wall where contact, else\n"
    "      surface) - bottom, so that under a cylinder h is the gap of reynoldsRef, at its\n"
    "      narrowest in the bin (the lowest wall particle: where a wall rises by more than l0\n"
    "      across a bin, use narrower bins); n: fluid particles in the bin (0 in a narrow\n"
    "      bin that has a row from its neighbours' particles); filled: the part of the gap\n"
    "      between the walls that the particles' cells (l0 around each) cover, 1 when full,\n"
    "      0 where no wall lies above the oil; full = 1 when the gap is full from wall to\n"
    "      wall: no two consecutive heights (walls and fluid) 2 l0 apart, no empty row.\n"
    "      Comment lines give the inlet meniscus, where the gap becomes full and stays\n"
    "      full downstream (the upstream edge of the longest run of full bins, upstream by\n"
    "      the sign of the mean fluid x-velocity): the inlet of a Reynolds reference\n"
    "      (reynoldsRef -inlet); the outlet meniscus (downstream edge of that run); and\n"
    "      upperWallContact, where the oil first touches the upper wall upstream of the\n"
    "      inlet: an inlet roll (oil piled ahead of a cylinder) touches it above an air gap,\n"
    "      which is not part of the film (contact 1, full 0, filled < 1 between the two).\n"
    "      Each to a bin width (l0 + DX/2 where DX < 2 l0), and to l0/slope with the wall's\n"
    "      slope there (particle rows are l0 apart); any -bin works.  With several times,\n"
    "      the mean over the times with a full film, and its range.\n"
    "  totals [-patch NAME]\n"
    "      per time: '# t mass momentumX momentumY momentumZ kineticEnergy fluidParticles'\n"
    "      over the fluid particles, particle mass rho l0^d (per unit depth in 2-D; rho from\n"
    "      constant/transportProperties.yaml).  With -patch, the load on that wall patch, the\n"
    "      integral of p dx over its wall particles sorted by x (each owns the half-way\n"
    "      intervals to its neighbours), as column 'load'; when the patch is the elasticWall\n"
    "      patch of constant/models.yaml also 'loadMean', the same integral of the running mean\n"
    "      pWallMean that the load balance uses (0 in a file without it: the mean starts at 0).\n"
    "      Multi-resolution (constant/models.yaml multiResolution): each fluid particle counts\n"
    "      with the particle mass of its level times the part of its cell (x -+ l0/2) that its\n"
    "      level owns (T-27: each point of space on one level, as lubFoam's totals function\n"
    "      object counts; fluidParticles: those whose x their level owns), and the columns\n"
    "      'massError[%] fluidLevel0 fluidLevel1 ...' follow: 100 (mass / M0 - 1), with M0 the\n"
    "      multiResolution mass0 of the first selected time folder whose uniform/state.yaml has\n"
    "      one (the run's M^0), else the mass at the first time selected (comment lines say\n"
    "      which), and the counted particles of each level.\n"
    "      Multi-resolution: the wall particles in the part of x their level owns (the levels\n"
    "      of system/particleGenDict.yaml), each x once, as the elasticWall load.\n"
    "  wallShape -patch NAME [-from A -to B]\n"
    "      the elastic wall (elasticWall in constant/models.yaml, on patch NAME): per wall\n"
    "      particle, sorted by x: '# x y v h'.  v = y - y_f - h0 - s is the elastic displacement\n"
    "      (T-50: y = y_f + h0 + s + v, y_f the surface beneath the cylinder's lowest point, h0\n"
    "      the rigid-body position of the time folder's uniform/state.yaml, s the undeformed\n"
    "      shape, the particle field elasticShape: the circle, which T-50's (x - x_c)^2/(2R)\n"
    "      approximates); h = y - (the surface beneath at x), the film thickness that\n"
    "      reynoldsRef's h describes.  A comment line gives h0.  A particleGen file (no state)\n"
    "      uses the elasticWall h0 and the circle: v = 0.  -dimensionless adds X = x/b and\n"
    "      H = h R/b^2 (T-54..T-58); -average the mean per particle over the times.\n"
    "      Multi-resolution: the wall particles in the part of x their level owns.\n"
    "  front\n"
    "      the surge front of a collapsing column (dam break, flowing towards +x over a\n"
    "      floor), per time: '# t xFront yTop fluidParticles'.  xFront: the largest x of the\n"
    "      fluid particles in the two lowest particle rows (less than 1.5 l0 above the lowest\n"
    "      fluid particle), plus l0/2, the edge of its cell: at t = 0 the face of the column;\n"
    "      yTop: the highest fluid particle plus l0/2 (y is the vertical in 2-D, z in 3-D).\n"
    "  particles [-field LIST] [-from X0 -to X1]\n"
    "      every particle (fluid, wall, dummy) with x in [X0, X1] (default: all), one row\n"
    "      each in the file's order: '# x y kind patch p' (3-D: x y z ...); kind 0 fluid, 1\n"
    "      wall, 2 dummy; patch the index of its wall patch, -1 for fluid (a comment line\n"
    "      names the patches).  A picture of the particles (gnuplot: plot ... with points,\n"
    "      the colour by kind or patch), e.g. the oil around a rolling body.  No -average.\n"
    "\n"
    "Fields (-field, comma-separated): p, U (columns Ux Uy [Uz]), Ux, Uy, Uz, and the\n"
    "optional fields of the particle files (pMean, pnd ...); default p.\n"
    "Bins: [X0 + k DX, X0 + (k+1) DX), the last one closed at X1; x is the bin centre and\n"
    "bins without samples are left out.  Default range: the domain's x-extent in\n"
    "system/particleGenDict.yaml (with -arc, the extent of the patch); default DX: 4 l0 (line,\n"
    "film).\n"
    "\n"
    "z-range (3-D): -z Z0:Z1 (probeDict: z: [Z0, Z1]) keeps only the particles with z in\n"
    "[Z0, Z1] for wallPressure, line, film and particles: a slab across the width, e.g. the\n"
    "mid-plane of a bearing of finite width (-z -5e-6:5e-6 takes the particle row at z = 0\n"
    "at l0 = 1e-5), or the rows near its side (line -field Uz: the side leakage).  A 2-D\n"
    "case, or a slab with no particle, is an error.\n"
    "\n"
    "Times: every time folder unless -time, -latestTime or -noZero select some.  With one time,\n"
    "or with -average, the output is one table that postErr reads directly.  With several\n"
    "times and no -average a leading column t (the time folder) is added and the rows of all\n"
    "times follow each other (one table: select one time, or average, for postErr).\n"
    "-average T0:T1 pools the samples of the selected times in [T0, T1]: the mean per bin is\n"
    "sum / count over all of them (as the wallPressure function object averages), n is the\n"
    "count; points, film and totals average their per-time values over the times.\n"
    "-dimensionless adds the thesis' X = x/sqrt(R h0) (S = s/sqrt(R h0) with -arc), P =\n"
    "h0^1.5 p/(mu (U1+U2) sqrt(R)) for p, and H = h/h0 for the film (T-38, T-39), with R, h0,\n"
    "U1 + U2 computed exactly as reynoldsRef does (its dictionaries are read).\n"
    "\n"
    "Output: a table ('# name[unit] ...' header, %.17g) on standard output, or -o FILE\n"
    "(written atomically; a relative name is taken relative to the -case directory).\n"
    "\n"
    "Sets: system/probeDict.yaml names sampling sets, each a mapping with 'type' (a\n"
    "subcommand) and the options as keys: patch, field (name, 'p,U' or [p, U]), from, to, bin,\n"
    "arc, at ([[x, y], ...]), average ([T0, T1]), dimensionless.  'probe' runs every set and\n"
    "'probe -set NAME' one (repeatable); each writes postProcessing/probe/<time>/<NAME>.dat per\n"
    "time folder (averaged: under the window's last time; totals, front: one table under the\n"
    "first time), or with -o FILE (one set) that file.  -average and -dimensionless on the "
    "command\n"
    "line override the sets'.  Template: etc/templates/probeDict.yaml.\n"
    "\n"
    "Examples:\n"
    "  probe line -field p -bin 2.5e-5 -latestTime | postErr - postProcessing/reynoldsRef/0/p.dat\n"
    "  probe wallPressure -patch cylinder -bin 2.5e-5 -average 0.024:0.030 -dimensionless\n"
    "  probe wallPressure -patch cylinder -arc -time 0.03\n"
    "  probe points -field p,U -at '0 2e-5; 1e-4 2e-5' -time 0.01:0.02\n"
    "  probe film -bin 2e-5 -latestTime\n"
    "  probe totals -o totals.dat\n"
    "  probe totals -patch cylinder              (load history of the elastic wall)\n"
    "  probe wallShape -patch cylinder -latestTime -dimensionless\n"
    "  probe front -o postProcessing/probe/front.dat   (dam break: surge front against t)\n"
    "  probe particles -field U -from 0.02 -to 0.06 -time 0.1   (a picture's particles)\n"
    "  probe -set pWall -latestTime\n"
    "\n"
    "Errors (exit 1): an unknown subcommand, patch (the patches are listed) or field (the\n"
    "fields of the file are listed), an option that does not apply to the subcommand, no time\n"
    "folder selected or none in the -average window, -from >= -to, -bin <= 0, a malformed\n"
    "-at point list or -average window, and bad dictionaries (file:line).";

/* Which options each subcommand takes. */
enum {
    O_PATCH,
    O_FIELD,
    O_FROM,
    O_TO,
    O_BIN,
    O_ARC,
    O_AT,
    O_DIMLESS,
    O_FACING,
    O_HISTORY,
    O_Z,
    O_N
};
static const char *const opt_names[O_N] = {"-patch",  "-field",   "-from", "-to",
                                           "-bin",    "-arc",     "-at",   "-dimensionless",
                                           "-facing", "-history", "-z"};
static const int applies[PROBE_NKINDS][O_N] = {
    [PROBE_WALL] = {1, 1, 1, 1, 1, 1, 0, 1, 1, 0, 1},
    [PROBE_LINE] = {0, 1, 1, 1, 1, 0, 0, 1, 0, 0, 1},
    [PROBE_POINTS] = {0, 1, 0, 0, 0, 0, 1, 1, 0, 1, 0},
    [PROBE_FILM] = {0, 0, 1, 1, 1, 0, 0, 1, 0, 0, 1},
    [PROBE_TOTALS] = {1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    [PROBE_SHAPE] = {1, 0, 1, 1, 0, 0, 0, 1, 0, 0, 0},
    [PROBE_FRONT] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    [PROBE_PARTICLES] = {0, 1, 1, 1, 0, 0, 0, 0, 0, 0, 1},
};

static const char *in_case(const lub_case *c, const char *path, char *buf)
{
    if (!path || strcmp(path, "-") == 0 || path[0] == '/' || strcmp(c->root, ".") == 0) return path;
    return lub_case_path(c, buf, path);
}

static probe_kind find_kind(const char *name)
{
    for (int k = 0; probe_kind_names[k]; k++)
        if (strcmp(name, probe_kind_names[k]) == 0) return (probe_kind)k;
    const char *near = lub_closest(name, probe_kind_names, PROBE_NKINDS);
    char hint[64] = "";
    if (near) snprintf(hint, sizeof hint, " (did you mean '%s'?)", near);
    lub_fatal(
        "unknown subcommand '%s'%s; the subcommands are: wallPressure line points film "
        "totals wallShape front particles (or none: the sets of system/probeDict.yaml); see probe "
        "-help",
        name, hint);
}

int main(int argc, char **argv)
{
    static const char *patch = NULL, *field = NULL, *at = NULL, *average = NULL, *out = NULL,
                      *facing = NULL, *zr = NULL;
    static double from = NAN, to = NAN, bin = NAN;
    static int arc = 0, dimensionless = 0, history = 0;
    static lub_strlist set_names = {0};
    lub_option opts[] = {
        {"-patch", "NAME", "wallPressure, wallShape: the wall patch; totals: add its load",
         LUB_OPT_STR, &patch},
        {"-field", "LIST", "fields, e.g. p or p,U or pMean (default p)", LUB_OPT_STR, &field},
        {"-from", "X0", "start of the x-range (with -arc: of s)", LUB_OPT_REAL, &from},
        {"-to", "X1", "end of the x-range", LUB_OPT_REAL, &to},
        {"-bin", "DX", "bin width (wallPressure: bins instead of one row per particle)",
         LUB_OPT_REAL, &bin},
        {"-arc", NULL, "wallPressure: against the arc length s along the wall", LUB_OPT_FLAG, &arc},
        {"-facing", "DIR",
         "wallPressure: only the wall particles facing DIR (down or up): a body's lower "
         "(upper) face",
         LUB_OPT_STR, &facing},
        {"-at", "'x y; x y'", "points: where to sample", LUB_OPT_STR, &at},
        {"-z", "Z0:Z1",
         "wallPressure, line, film, particles (3-D): only the particles with z in [Z0, Z1]",
         LUB_OPT_STR, &zr},
        {"-history", NULL, "points: one point, one row per time: '# t p n'", LUB_OPT_FLAG,
         &history},
        {"-average", "T0:T1", "average over the selected times in [T0, T1]", LUB_OPT_STR, &average},
        {"-dimensionless", NULL, "add X (S), P, H columns (thesis T-38, T-39)", LUB_OPT_FLAG,
         &dimensionless},
        {"-set", "NAME", "run set NAME of system/probeDict.yaml (repeatable)", LUB_OPT_MULTI,
         &set_names},
        {"-o", "FILE", "write the table to FILE instead of standard output", LUB_OPT_STR, &out},
        {0}};
    lub_program_info info = {
        .name = "probe",
        .summary = "sample particle fields of the time folders: wall pressure, lines, points, "
                   "film, totals, the elastic wall's shape",
        .usage = "[SUBCOMMAND] [OPTIONS]",
        .description = description,
        .dictionaries = "system/probeDict.yaml (without a subcommand, or with -set)\n"
                        "system/particleGenDict.yaml (default x-range; -arc; wallShape)\n"
                        "constant/models.yaml (wallShape, totals -patch: elasticWall)\n"
                        "<time>/uniform/state.yaml (wallShape: h0)\n"
                        "constant/transportProperties.yaml (totals: rho; -dimensionless)\n"
                        "system/reynoldsRefDict.yaml, constant/models.yaml (-dimensionless)",
        .time_selection = 1,
        .has_case = 1,
        .min_args = 0,
        .max_args = 1};
    lub_args a;
    lub_args_parse(&a, argc, argv, &info, opts);

    /* option values that are wrong whatever the set */
    if (!isnan(bin) && !(bin > 0.0)) lub_fatal("-bin must be > 0, found %g", bin);
    if (!isnan(from) && !isnan(to) && !(from < to))
        lub_fatal("-from (%g) must be less than -to (%g)", from, to);
    double t0 = NAN, t1 = NAN;
    if (average && probe_parse_window(average, &t0, &t1))
        lub_fatal("-average '%s': expected a time window T0:T1 with T0 <= T1, e.g. -average "
                  "0.024:0.030",
                  average);
    int facing_dir = 0;
    if (facing) {
        if (strcmp(facing, "down") == 0)
            facing_dir = -1;
        else if (strcmp(facing, "up") == 0)
            facing_dir = 1;
        else
            lub_fatal("-facing '%s': expected down or up", facing);
    }
    double z0 = NAN, z1 = NAN;
    if (zr && probe_parse_window(zr, &z0, &z1))
        lub_fatal("-z '%s': expected a z-range Z0:Z1 with Z0 <= Z1, e.g. -z -5e-6:5e-6", zr);
    int given[O_N] = {patch != NULL, field != NULL, !isnan(from),   !isnan(to), !isnan(bin), arc,
                      at != NULL,    dimensionless, facing != NULL, history,    zr != NULL};

    probe_ctx x;
    memset(&x, 0, sizeof x);
    x.a = &a;
    lub_case_open(&x.c, a.case_dir);
    char obuf[LUB_PATH_MAX];
    const char *opath = in_case(&x.c, out, obuf);

    if (a.npos == 1) {
        /* a subcommand and its options */
        probe_kind kind = find_kind(a.pos[0]);
        if (set_names.n) lub_fatal("-set runs sets of system/probeDict.yaml: give no subcommand");
        for (int o = 0; o < O_N; o++)
            if (given[o] && !applies[kind][o])
                lub_fatal("option '%s' does not apply to '%s'; see probe -help", opt_names[o],
                          probe_kind_names[kind]);
        if ((kind == PROBE_WALL || kind == PROBE_SHAPE) && !patch)
            lub_fatal("%s needs -patch NAME (a wall of the case, e.g. -patch cylinder)",
                      probe_kind_names[kind]);
        if (kind == PROBE_PARTICLES && average)
            lub_fatal("-average does not apply to 'particles' (one row per particle and time)");
        if (kind == PROBE_POINTS && !at)
            lub_fatal("points needs -at 'x y; x y ...' (the points to sample)");
        probe_spec s;
        probe_spec_init(&s, kind, probe_kind_names[kind]);
        s.patch = patch;
        if (field) {
            if (strlen(field) >= sizeof s.fields) lub_fatal("-field: the list is too long");
            snprintf(s.fields, sizeof s.fields, "%s", field);
        }
        s.from = from;
        s.to = to;
        s.bin = bin;
        s.arc = arc;
        s.facing = facing_dir;
        s.dimensionless = dimensionless;
        s.history = history;
        if (zr) s.has_z = 1, s.z0 = z0, s.z1 = z1;
        if (average) s.average = 1, s.t0 = t0, s.t1 = t1;
        char err[512];
        if (at && probe_parse_points(&s, at, err, sizeof err)) {
            probe_spec_free(&s);
            lub_fatal("-at '%s': %s; e.g. -at '0 2e-5; 1e-4 2e-5'", at, err);
        }
        probe_sink k;
        probe_sink_init(&k, &x.c, opath, 0, s.name);
        probe_run(&x, &s, &k);
        probe_sink_close(&k);
        probe_spec_free(&s);
    } else {
        /* the sets of system/probeDict.yaml */
        for (int o = 0; o < O_N; o++)
            if (given[o] && o != O_DIMLESS)
                lub_fatal("option '%s' belongs to a subcommand; the sets take their settings "
                          "from system/probeDict.yaml",
                          opt_names[o]);
        probe_sets S;
        probe_sets_read(&S, &x.c);
        int *run = lub_calloc((size_t)S.n, sizeof *run);
        if (set_names.n == 0)
            for (int i = 0; i < S.n; i++) run[i] = 1;
        for (size_t i = 0; i < set_names.n; i++) run[probe_sets_find(&S, set_names.items[i])] = 1;
        int nrun = 0;
        for (int i = 0; i < S.n; i++) nrun += run[i];
        if (out && nrun > 1)
            lub_fatal("-o FILE takes one set (%d would run); choose it with -set NAME", nrun);
        for (int i = 0; i < S.n; i++) {
            if (!run[i]) continue;
            probe_spec *s = &S.sets[i];
            if (dimensionless && s->kind != PROBE_TOTALS && s->kind != PROBE_FRONT &&
                s->kind != PROBE_PARTICLES)
                s->dimensionless = 1;
            if (average && s->kind == PROBE_PARTICLES)
                lub_fatal("-average does not apply to set '%s' of type particles (one row per "
                          "particle and time)",
                          s->name);
            if (average) s->average = 1, s->t0 = t0, s->t1 = t1, s->average_node = NULL;
            probe_sink k;
            probe_sink_init(&k, &x.c, opath, out == NULL, s->name);
            probe_run(&x, s, &k);
            probe_sink_close(&k);
            if (k.files)
                lub_message("set %-16s %-12s %zu file%s, the last %s", s->name,
                            probe_kind_names[s->kind], k.files, k.files == 1 ? "" : "s",
                            k.last_path);
        }
        free(run);
        probe_sets_free(&S);
    }
    probe_ctx_free(&x);
    lub_strlist_free(&set_names);
    return 0;
}
