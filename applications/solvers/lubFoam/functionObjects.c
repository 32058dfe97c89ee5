/* lubFoam function objects: tables written during the run under
 * postProcessing/<name>/<startTime>/ (controlDict `functions`, as in OpenFOAM).
 *
 *     functions:
 *       totals:       { type: totals, interval: 100 }         # every 100 steps
 *       wallPressure: { type: wallPressure, patch: cylinder, bin: 2.5e-5,
 *                       from: -0.0045, to: 0.0045,             # x range (default: domain)
 *                       timeStart: 0.024, timeEnd: 0.030 }     # averaging window
 *                     (3-D: `zRange: [z0, z1]` takes only the wall particles with z in
 *                     [z0, z1], e.g. the mid-plane row of a finite bearing; without it the
 *                     bins pool every z)
 *
 * totals.dat:  # t[s] mass[kg/m] momentumX[kg/s] momentumY[kg/s] momentumZ[kg/s]
 *              kineticEnergy[J/m] fluidParticles (3-D: [kg], [kg*m/s], [J])
 *              (per unit depth in 2-D: particle mass rho l0^d; multi-resolution: each point
 *              of space on one level (T-27), every fluid particle with the mass rho l0^d of
 *              its level times the owned part of its cell, lub_levels_owned_fraction;
 *              fluidParticles: those whose x their level owns)
 * p.dat:       # x p n   wall pressure of the patch averaged over the window and the bin
 *              (n: samples; multi-resolution: the wall particles in the part of x their
 *              level owns, as the elasticWall load); rewritten at every write time and at
 *              the end, with a second line "# samples S steps from t = A to t = B" (the
 *              steps averaged so far); not written while it holds no sample (a run that
 *              ends before the window or restarts after it), so that the latest start
 *              time's table is the latest average, as the tutorials' Allruns take it.  A
 *              run restarted inside the window continues the average: it reads the p.dat
 *              of an earlier start whose last sample is the step it restarts from (sum =
 *              p n per bin, exact to round-off) and writes the whole window's mean under
 *              its own start time.  If no such table exists (the earlier run was stopped
 *              between writing its time folder and its table, or the table was deleted), or
 *              the one there began before timeStart (changed since), it says so and
 *              averages from its start time only.
 *
 *       wallLoad:     { type: wallLoad, patch: cylinder, bin: 2.5e-5, from: ..., to: ...,
 *                       timeStart: 0.024, timeEnd: 0.030 }     # every step of the window
 *
 * load.dat:    # t[s] load[N/m] particles   the load of the step: the integral over
 *              [from, to] of the wall pressure of the patch at that step, binned as
 *              wallPressure bins it (the mean pressure of the bin's wall particles times the
 *              bin width; a bin with no wall particle adds nothing; 3-D: the mean over z
 *              (over zRange when given), per unit width: times z1 - z0 it is the load over
 *              the strip when the wall particles lie in rows l0 apart and z1 - z0 is their
 *              count times l0), and the number of wall particles counted.  One row per step
 *              (or per `interval` steps) inside the window, appended during the run: the
 *              per-step history of what wallPressure averages, to see whether the window
 *              holds one steady state.
 *       forces:       { type: forces, patch: arc, interval: 10 }   # every 10 steps
 *
 * forces.dat:  # t[s] Fx[N/m] Fy[N/m] Fz[N/m]   the force the fluid exerted on the patch in
 *              the step (2-D: per unit depth; 3-D: [N]), the sum over its wall and dummy
 *              particles of the fluid's wall_forces (models/fluid.h): with the MPH fluid
 *              the pair forces of (K-6) and of the surface tension (K-8) on them, the load
 *              with the adhesion of the surface-tension model, which the wall pressure pLoad
 *              (pressure pairs only) leaves out.  MPH only: the MPS fluid's wall force needs
 *              the body's shape (rigidBodies); wallLoad gives the MPS load.
 * The cost table (postProcessing/cost/<startTime>/cost.dat) is written by lubFoam itself.
 *
 * lubFoam -parallel: totals, wallPressure and wallLoad sum over the owned particles of every
 * rank (each rank its slab's part, lub_par_sum_doubles: the same sums as a serial run's in
 * another order, equal to round-off), and rank 0 alone keeps the tables, their running
 * state and their files.  forces (MPH only, not parallel) is refused by lubFoam -parallel.
 *
 * The models' own tables (elasticWall.dat: src/models/elasticWall/io.c) are opened and
 * written with these (lub_scene_functions_start, lub_scene_functions_execute).
 */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "io/table.h"
#include "lubFoam.h"
#include "models/multiResolution/levels.h"

enum { FO_TOTALS, FO_WALLPRESSURE, FO_WALLLOAD, FO_FORCES };

typedef struct {
    int type;
    char name[64];
    long interval;
    FILE *fp;     /* totals, wallLoad, forces: appended during the run */
    double *f[3]; /* forces: the fluid's force on each particle, allocated once */
    size_t fcap;  /* forces: their length */
    /* wallPressure */
    int patch;
    double from, to, bin, t0, t1;
    int has_z; /* 3-D: only the wall particles with z in [z0, z1] */
    double z0, z1;
    int nbins;
    double *sum;
    long *count;
    double *psum; /* -parallel: this step's sums and counts of this rank, then of all */
    long *pcount;
    long samples; /* steps averaged */
    double tfirst, tlast;
} fo;

struct lubfoam_functions {
    int n;
    fo *f;
};

/* Samples line of a wallPressure p.dat: 1 and S, A, B if the file has it. */
static int read_samples_line(const char *path, long *S, double *A, double *B)
{
    FILE *fp = fopen(path, "r");
    if (!fp) return 0;
    char line[512];
    int found = 0;
    while (fgets(line, sizeof line, fp) && line[0] == '#')
        if (sscanf(line, "# samples %ld steps from t = %lg to t = %lg", S, A, B) == 3) {
            found = 1;
            break;
        }
    fclose(fp);
    return found;
}

static void wall_pressure_not_continued(const fo *o, const lubfoam_run *r, const char *dir)
{
    lub_warning("function '%s': no earlier average ending at the start time %g was found under "
                "%s: the wall pressure is averaged from t = %g on, not from timeStart %g",
                o->name, r->t, dir, r->t, o->t0);
}

static int wall_pressure_resume_state(fo *o, lubfoam_run *r);

/* A run that starts inside the averaging window of o (at its first step included) continues
 * the average of the earlier run it restarts from: the p.dat of the latest earlier start time
 * whose last sample is the start step (see the header).  Returns 1 if it did. */
static int wall_pressure_resume(fo *o, lubfoam_run *r)
{
    double eps = 0.5 * r->dt + 1e-12 * fabs(r->t);
    if (!(r->t >= o->t0 - eps) || !(r->t <= o->t1 + eps) || !(o->t0 < o->t1)) return 0;
    /* the state kept in the start folder; the tables under postProcessing/ for a folder
     * written before that was kept */
    const int kept = wall_pressure_resume_state(o, r);
    if (kept >= 0) return kept;
    /* at the window's first step, an earlier run held one sample at most (the start step's,
     * which the caller takes again from the start state): nothing to warn about */
    const int at_first = r->t <= o->t0 + eps;
    char dir[LUB_PATH_MAX];
    lub_case_pathf(&r->cs, dir, "postProcessing/%s", o->name);
    DIR *dp = opendir(dir);
    if (!dp) {
        if (!at_first) wall_pressure_not_continued(o, r, dir);
        return 0;
    }
    double best_t = -INFINITY, early_t = -INFINITY, early_A = 0;
    char best[LUB_PATH_MAX] = "", early[LUB_PATH_MAX] = "";
    long bestS = 0;
    double bestA = 0;
    struct dirent *de;
    while ((de = readdir(dp))) {
        char *end;
        double tv = strtod(de->d_name, &end);
        if (end == de->d_name || *end || !(tv < r->t + eps) || !(tv > best_t)) continue;
        char path[LUB_PATH_MAX];
        long S;
        double A, B;
        if (snprintf(path, sizeof path, "%s/%s/p.dat", dir, de->d_name) >= (int)sizeof path)
            continue;
        if (!read_samples_line(path, &S, &A, &B) || fabs(B - r->t) > eps) continue;
        if (A < o->t0 - eps) {
            /* an average begun before this window (timeStart changed since): it holds
             * samples the window excludes, which cannot be taken out again */
            if (tv > early_t) early_t = tv, early_A = A, snprintf(early, sizeof early, "%s", path);
            continue;
        }
        best_t = tv;
        bestS = S;
        bestA = A;
        snprintf(best, sizeof best, "%s", path);
    }
    closedir(dp);
    if (!best[0] && early[0]) {
        lub_warning("function '%s': the average of %s began at t = %g, before timeStart %g "
                    "(changed since that run?): not continued; the wall pressure is averaged "
                    "from t = %g on",
                    o->name, early, early_A, o->t0, r->t);
        return 0;
    }
    if (!best[0]) {
        if (!at_first) wall_pressure_not_continued(o, r, dir);
        return 0;
    }
    lub_table t;
    lub_table_read(&t, best);
    int cx = lub_table_col(&t, "x"), cp = lub_table_col(&t, "p"), cn = lub_table_col(&t, "n");
    for (size_t k = 0; k < t.nrow; k++) {
        double b = (lub_table_at(&t, k, (size_t)cx) - o->from) / o->bin - 0.5;
        int ib = (int)lround(b);
        if (fabs(b - ib) > 1e-6 || ib < 0 || ib >= o->nbins)
            lub_fatal_run("function '%s': %s has a bin at x = %g that is not a bin of this "
                          "run (from %g, bin %g): the bins changed since that run",
                          o->name, best, lub_table_at(&t, k, (size_t)cx), o->from, o->bin);
        long n = lround(lub_table_at(&t, k, (size_t)cn));
        o->count[ib] += n;
        o->sum[ib] += lub_table_at(&t, k, (size_t)cp) * (double)n;
    }
    lub_table_free(&t);
    o->samples = bestS;
    o->tfirst = bestA;
    o->tlast = r->t;
    lub_message("function '%s': continues the average of %s (%ld steps from t = %g)", o->name, best,
                bestS, bestA);
    return 1;
}

/* The running state of a wallPressure in a time folder: uniform/functionObjects/<name>.dat,
 *     # bin sum[Pa] n
 *     # wallPressure <name>: samples S steps from t = A to t = B; from F bin W bins N
 * then one row per bin that holds samples: its index, the sum of the samples (17 digits:
 * read back exactly) and their number.  Written with every time folder, so that a restart
 * from any written time continues the average, bit for bit as the run that was not
 * stopped. */
static void wall_pressure_state_path(const fo *o, const char *dir, char *path)
{
    if (snprintf(path, LUB_PATH_MAX, "%s/uniform/functionObjects/%s.dat", dir, o->name) >=
        LUB_PATH_MAX)
        lub_fatal_run("path too long: '%s/uniform/functionObjects/%s.dat'", dir, o->name);
}

/* From the start folder's state: 1 continued, 0 nothing to continue (no sample yet, or bins
 * or window changed: said so), -1 no state there (a folder written before it was kept). */
static int wall_pressure_resume_state(fo *o, lubfoam_run *r)
{
    char dir[LUB_PATH_MAX], path[LUB_PATH_MAX];
    lub_case_path(&r->cs, dir, r->start_name);
    wall_pressure_state_path(o, dir, path);
    FILE *fp = fopen(path, "r");
    if (!fp) return -1;
    char line[512];
    long S = -1;
    double A = 0, B = 0, from = 0, bin = 0;
    int nbins = 0;
    while (fgets(line, sizeof line, fp) && line[0] == '#')
        if (sscanf(line,
                   "# wallPressure %*s samples %ld steps from t = %lg to t = %lg; from %lg bin "
                   "%lg bins %d",
                   &S, &A, &B, &from, &bin, &nbins) == 6)
            break;
    if (S < 0) {
        fclose(fp);
        lub_fatal("%s: not the state of a wallPressure function object (its second line is "
                  "'# wallPressure NAME: samples S steps from t = A to t = B; from F bin W bins "
                  "N')",
                  path);
    }
    if (S == 0) {
        fclose(fp);
        return 0;
    }
    const double eps = 0.5 * r->dt + 1e-12 * fabs(r->t);
    if (nbins != o->nbins || from != o->from || bin != o->bin) {
        fclose(fp);
        lub_warning("function '%s': the bins changed since the run that wrote %s (from %g, bin "
                    "%g): its average is not continued; the wall pressure is averaged from t = "
                    "%g on",
                    o->name, path, from, bin, r->t);
        return 0;
    }
    if (A < o->t0 - eps) {
        fclose(fp);
        lub_warning("function '%s': the average of %s began at t = %g, before timeStart %g "
                    "(changed since that run?): not continued; the wall pressure is averaged "
                    "from t = %g on",
                    o->name, path, A, o->t0, r->t);
        return 0;
    }
    long ib, n;
    double sum;
    int lineno = 2;
    while (fgets(line, sizeof line, fp)) {
        lineno++;
        if (line[0] == '#') continue;
        if (sscanf(line, "%ld %lg %ld", &ib, &sum, &n) != 3 || ib < 0 || ib >= o->nbins || n < 0) {
            fclose(fp);
            lub_fatal_at(path, lineno, 1, "expected 'bin sum n' with a bin below %d", o->nbins);
        }
        o->sum[ib] = sum;
        o->count[ib] = n;
    }
    fclose(fp);
    o->samples = S;
    o->tfirst = A;
    o->tlast = B;
    lub_message("function '%s': continues the average of %s (%ld steps from t = %g)", o->name, path,
                S, A);
    return 1;
}

static void wall_pressure(fo *o, lubfoam_run *r);

lubfoam_functions *lubfoam_functions_read(lubfoam_run *r)
{
    static const char *const types[] = {"totals", "wallPressure", "wallLoad", "forces", NULL};
    lubfoam_functions *F = lub_calloc(1, sizeof *F);
    lub_node *fs = r->ctl.functions;
    size_t n = fs ? lub_node_size(fs) : 0;
    F->f = lub_calloc(n ? n : 1, sizeof *F->f);
    for (size_t k = 0; k < n; k++) {
        const char *name = lub_node_key_at(fs, k);
        lub_node *d = lub_node_expect_map(lub_node_value_at(fs, k));
        fo *o = &F->f[F->n++];
        snprintf(o->name, sizeof o->name, "%s", name);
        o->type = lub_dict_choice(d, "type", types, -1);
        o->interval = lub_dict_int_or(d, "interval", 1, 1, 1L << 40);
        if (o->type != FO_TOTALS) {
            const char *patch = lub_dict_str(d, "patch");
            o->patch = lub_particles_find_patch(&r->P, patch);
            if (o->patch < 0) {
                char list[512] = "";
                size_t len = 0;
                for (int p = 0; p < r->P.npatches && len < sizeof list; p++)
                    len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", p ? ", " : "",
                                            r->P.patch_names[p]);
                lub_node_error(lub_dict_get(d, "patch"),
                               "function '%s': no patch '%s' in the particles (patches: %s)", name,
                               patch, list);
            }
            if (o->type == FO_FORCES) {
                /* the pair-force formulation needs no body shape (models/fluid.h) */
                if (strcmp(r->scene.fluid->name, "mph") != 0 || !r->scene.fluid->wall_forces)
                    lub_node_error(lub_dict_get(d, "type"),
                                   "function '%s': forces needs the fluid 'mph' (constant/"
                                   "models.yaml fluid: { type: mph }), whose wall force is a sum "
                                   "of pair forces; with '%s' use wallLoad",
                                   name, r->scene.fluid->name);
                o->fcap = r->P.cap > r->P.n ? r->P.cap : r->P.n + 1;
                for (int c = 0; c < 3; c++) o->f[c] = lub_calloc(o->fcap, sizeof(double));
                continue;
            }
            o->from = lub_dict_real_or(d, "from", r->scene.level[0]->lo[0], LUB_ANY);
            o->to = lub_dict_real_or(d, "to", r->scene.level[0]->hi[0], LUB_ANY);
            if (!(o->to > o->from))
                lub_node_error(d, "function '%s': 'to' (%g) must be greater than 'from' (%g)", name,
                               o->to, o->from);
            lub_node *zn = lub_dict_find(d, "zRange");
            if (zn) {
                double z[2];
                if (r->P.dim != 3)
                    lub_node_error(zn,
                                   "function '%s': 'zRange' needs a 3-D case (this one is "
                                   "2-D)",
                                   name);
                lub_dict_vec(d, "zRange", z, 2, 2, LUB_ANY);
                if (!(z[0] <= z[1]))
                    lub_node_error(zn,
                                   "function '%s': 'zRange' is [z0, z1] with z0 <= z1, found "
                                   "[%g, %g]",
                                   name, z[0], z[1]);
                o->has_z = 1, o->z0 = z[0], o->z1 = z[1];
            }
            o->bin = lub_dict_real_or(d, "bin", 4 * r->scene.level[0]->l0, LUB_POSITIVE);
            o->t0 = lub_dict_real_or(d, "timeStart", 0.0, LUB_NONNEGATIVE);
            o->t1 = lub_dict_real_or(d, "timeEnd", INFINITY, LUB_NONNEGATIVE);
            if (o->t1 < o->t0)
                lub_node_error(lub_dict_get(d, "timeEnd"),
                               "function '%s': timeEnd (%g) is earlier than timeStart (%g): the "
                               "window would hold no step",
                               name, o->t1, o->t0);
            /* counted in double: a tiny bin made more bins than an int holds (the cast was
             * undefined behaviour, and the message said -2147483648 bins) */
            const double nb = ceil((o->to - o->from) / o->bin - 1e-9);
            if (!(nb >= 1 && nb <= 10000000))
                lub_node_error(lub_dict_find(d, "bin") ? lub_dict_find(d, "bin") : d,
                               "function '%s': bin %g makes %.4g bins over [%g, %g]: at most "
                               "10^7 bins (a bin of at least %.4g)",
                               name, o->bin, nb, o->from, o->to, (o->to - o->from) / 1e7);
            o->nbins = (int)nb;
            o->sum = lub_calloc((size_t)o->nbins, sizeof *o->sum);
            o->count = lub_calloc((size_t)o->nbins, sizeof *o->count);
            o->psum = lub_calloc((size_t)o->nbins, sizeof *o->psum);
            o->pcount = lub_calloc((size_t)o->nbins, sizeof *o->pcount);
        }
    }
    return F;
}

const char *lubfoam_functions_unparallel(const lubfoam_functions *F)
{
    for (int k = 0; F && k < F->n; k++)
        if (F->f[k].type == FO_FORCES) return F->f[k].name;
    return NULL;
}

void lubfoam_functions_start(lubfoam_functions *F, lubfoam_run *r)
{
    /* -parallel: rank 0 keeps the tables; every rank takes part in the sums */
    const int writer = lubfoam_writer_rank(r);
    for (int k = 0; k < F->n; k++) {
        fo *o = &F->f[k];
        if (!writer && o->type != FO_WALLPRESSURE) continue;
        if (o->type == FO_TOTALS) {
            char path[LUB_PATH_MAX];
            lub_postproc_path(&r->cs, o->name, r->start_name, "totals.dat", path);
            o->fp = fopen(path, "w");
            if (!o->fp) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
            /* units as probe totals writes them: per unit depth in 2-D */
            lub_table_write_header(
                o->fp, r->P.dim == 2 ? "t[s] mass[kg/m] momentumX[kg/s] momentumY[kg/s] "
                                       "momentumZ[kg/s] kineticEnergy[J/m] fluidParticles"
                                     : "t[s] mass[kg] momentumX[kg*m/s] momentumY[kg*m/s] "
                                       "momentumZ[kg*m/s] kineticEnergy[J] fluidParticles");
            /* on disk at once: a run killed before the first row leaves a table with its
             * header, not an empty file */
            fflush(o->fp);
        } else if (o->type == FO_FORCES) {
            char path[LUB_PATH_MAX];
            lub_postproc_path(&r->cs, o->name, r->start_name, "forces.dat", path);
            o->fp = fopen(path, "w");
            if (!o->fp) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
            lub_table_write_header(o->fp, r->P.dim == 2 ? "t[s] Fx[N/m] Fy[N/m] Fz[N/m]"
                                                        : "t[s] Fx[N] Fy[N] Fz[N]");
            fflush(o->fp);
        } else if (o->type == FO_WALLLOAD) {
            char path[LUB_PATH_MAX];
            lub_postproc_path(&r->cs, o->name, r->start_name, "load.dat", path);
            o->fp = fopen(path, "w");
            if (!o->fp) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
            lub_table_write_header(o->fp, "t[s] load[N/m] particles");
            fflush(o->fp);
        } else {
            /* -parallel: rank 0 continues the average; the others learn whether it did */
            int resumed = writer ? wall_pressure_resume(o, r) : 0;
            if (r->parallel) resumed = lub_par_max(resumed) > 0;
            /* a restart that continues no earlier average samples its start state, as the
             * run that wrote it did after that step (wall_pressure keeps to the window) */
            if (!resumed && r->step > 0 && r->step % o->interval == 0) wall_pressure(o, r);
        }
    }
    lub_scene_functions_start(&r->scene, r->start_name, r->t);
}

static void totals(fo *o, lubfoam_run *r)
{
    const lub_particles *P = &r->P;
    const lub_scene *sc = &r->scene;
    double mom[3] = {0, 0, 0}, ke = 0, mass = 0;
    size_t nf = 0;
    if (sc->levels) {
        /* resolution levels: each point of space counted on the level that owns it (T-27):
         * the particle mass of its level times the owned part of its cell; the count is of
         * the particles whose x their level owns (as probe totals and the mass correction) */
        lub_levels_sums s;
        memset(&s, 0, sizeof s);
        lub_levels_sum(sc->levels, P, &s);
        double m[LUB_MAX_LEVELS];
        for (int k = 0; k < sc->nlevels; k++) {
            m[k] = sc->level[k]->c.rho * pow(sc->level[k]->l0, P->dim);
            nf += s.owned[k];
            for (int d = 0; d < 3; d++) mom[d] += m[k] * s.fu[k][d];
            ke += 0.5 * m[k] * s.fu2[k];
        }
        mass = lub_levels_mass(&s, sc->nlevels, m);
    } else {
        const double mp = sc->level[0]->c.rho * pow(sc->level[0]->l0, P->dim);
        for (size_t i = 0; i < P->n; i++) {
            if (P->kind[i] != LUB_FLUID) continue;
            nf++;
            for (int d = 0; d < P->dim; d++) {
                mom[d] += mp * P->u[d][i];
                ke += 0.5 * mp * P->u[d][i] * P->u[d][i];
            }
        }
        if (r->parallel) { /* the owned particles of every rank (P holds this rank's) */
            double s[5] = {mom[0], mom[1], mom[2], ke, (double)nf};
            lub_par_sum_doubles(s, 5);
            mom[0] = s[0], mom[1] = s[1], mom[2] = s[2], ke = s[3], nf = (size_t)s[4];
        }
        mass = mp * (double)nf;
    }
    if (!lubfoam_writer_rank(r)) return;
    double row[7] = {r->t, mass, mom[0], mom[1], mom[2], ke, (double)nf};
    lub_table_write_row(o->fp, row, 7);
    fflush(o->fp);
}

/* Add the wall pressure of o's patch at this step to sum, count (bins in x). */
static void wall_pressure_bin(const fo *o, const lubfoam_run *r, double *sum, long *count)
{
    const lub_particles *P = &r->P;
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_WALL || P->patch[i] != o->patch) continue;
        double x = P->x[0][i];
        if (x < o->from || x >= o->to) continue;
        if (o->has_z && !(P->x[2][i] >= o->z0 && P->x[2][i] <= o->z1)) continue;
        /* resolution levels: each x on the level that owns it */
        if (r->scene.nlevels > 1 && lub_scene_owner(&r->scene, x) != P->level[i]) continue;
        int b = (int)((x - o->from) / o->bin);
        if (b >= o->nbins) b = o->nbins - 1;
        sum[b] += P->p[i];
        count[b]++;
    }
}

/* Add this step's wall pressure of o's patch to o->sum, o->count; -parallel: every rank's
 * owned wall particles, summed over the ranks first (rank 0's o->sum, o->count only). */
static void wall_pressure_sample(fo *o, const lubfoam_run *r)
{
    if (!r->parallel) {
        wall_pressure_bin(o, r, o->sum, o->count);
        return;
    }
    const size_t nb = (size_t)o->nbins;
    memset(o->psum, 0, nb * sizeof *o->psum);
    memset(o->pcount, 0, nb * sizeof *o->pcount);
    wall_pressure_bin(o, r, o->psum, o->pcount);
    lub_par_sum_doubles(o->psum, nb);
    lub_par_sum_longs(o->pcount, nb);
    if (!lubfoam_writer_rank(r)) return;
    for (size_t b = 0; b < nb; b++) {
        o->sum[b] += o->psum[b];
        o->count[b] += o->pcount[b];
    }
}

static int in_window(const fo *o, const lubfoam_run *r)
{
    return !(r->t < o->t0 - 0.5 * r->dt || r->t > o->t1 + 0.5 * r->dt);
}

static void wall_pressure(fo *o, lubfoam_run *r)
{
    if (!in_window(o, r)) return;
    wall_pressure_sample(o, r);
    if (!o->samples++) o->tfirst = r->t;
    o->tlast = r->t;
}

static void wall_load(fo *o, lubfoam_run *r)
{
    if (!in_window(o, r)) return;
    memset(o->sum, 0, (size_t)o->nbins * sizeof *o->sum);
    memset(o->count, 0, (size_t)o->nbins * sizeof *o->count);
    wall_pressure_sample(o, r);
    if (!lubfoam_writer_rank(r)) return;
    double load = 0;
    long np = 0;
    for (int b = 0; b < o->nbins; b++) {
        if (!o->count[b]) continue;
        /* the last bin may be cut short by `to` */
        double w = fmin(o->bin, o->to - (o->from + b * o->bin));
        load += o->sum[b] / (double)o->count[b] * w;
        np += o->count[b];
    }
    double row[3] = {r->t, load, (double)np};
    lub_table_write_row(o->fp, row, 3);
}

/* The force of the fluid on o's patch in the step just taken (models/fluid.h wall_forces;
 * MPH: pair forces, so no area vectors and no angular velocity are needed). */
static void forces(fo *o, lubfoam_run *r)
{
    const lub_particles *P = &r->P;
    if (P->n > o->fcap) lub_bug("forces: %zu particles, %zu allocated", P->n, o->fcap);
    double *none[3] = {NULL, NULL, NULL};
    const double omega[3] = {0, 0, 0};
    r->scene.fluid->wall_forces(r->scene.level[0], o->patch, none, omega, o->f);
    double F[3] = {0, 0, 0};
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] != LUB_FLUID && P->patch[i] == o->patch)
            for (int d = 0; d < 3; d++) F[d] += o->f[d][i];
    double row[4] = {r->t, F[0], F[1], F[2]};
    lub_table_write_row(o->fp, row, 4);
}

void lubfoam_functions_execute(lubfoam_functions *F, lubfoam_run *r)
{
    lub_scene_functions_execute(&r->scene, r->t, r->step);
    for (int k = 0; k < F->n; k++) {
        fo *o = &F->f[k];
        if (r->step % o->interval != 0) continue;
        if (o->type == FO_TOTALS)
            totals(o, r);
        else if (o->type == FO_WALLLOAD)
            wall_load(o, r);
        else if (o->type == FO_FORCES)
            forces(o, r);
        else
            wall_pressure(o, r);
    }
}

void lubfoam_functions_write(lubfoam_functions *F, lubfoam_run *r)
{
    if (!lubfoam_writer_rank(r)) return; /* -parallel: rank 0 holds the tables */
    for (int k = 0; k < F->n; k++) {
        fo *o = &F->f[k];
        /* rows kept in stdio's buffer between writes */
        if (o->type == FO_WALLLOAD || o->type == FO_FORCES) fflush(o->fp);
        /* nothing averaged (outside the window): no table, which would hide the earlier
         * run's average from whoever takes the latest start time's */
        if (o->type != FO_WALLPRESSURE || !o->samples) continue;
        char path[LUB_PATH_MAX];
        lub_postproc_path(&r->cs, o->name, r->start_name, "p.dat", path);
        lub_atomic_file af;
        FILE *fp = lub_atomic_open(&af, path);
        if (!fp) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
        lub_table_write_header(fp, "x[m] p[Pa] n");
        fprintf(fp, "# samples %ld steps from t = %.17g to t = %.17g\n", o->samples, o->tfirst,
                o->tlast);
        for (int b = 0; b < o->nbins; b++) {
            if (!o->count[b]) continue;
            double row[3] = {o->from + (b + 0.5) * o->bin, o->sum[b] / (double)o->count[b],
                             (double)o->count[b]};
            lub_table_write_row(fp, row, 3);
        }
        if (lub_atomic_close(&af) != 0)
            lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
    }
}

void lubfoam_functions_write_state(lubfoam_functions *F, const lubfoam_run *r, const char *dir)
{
    (void)r;
    for (int k = 0; k < F->n; k++) {
        fo *o = &F->f[k];
        if (o->type != FO_WALLPRESSURE) continue;
        char sub[LUB_PATH_MAX + 32], path[LUB_PATH_MAX];
        snprintf(sub, sizeof sub, "%s/uniform/functionObjects", dir);
        if (lub_mkdir_p(sub) != 0) lub_fatal_run("cannot create '%s': %s", sub, strerror(errno));
        wall_pressure_state_path(o, dir, path);
        lub_atomic_file af;
        FILE *fp = lub_atomic_open(&af, path);
        if (!fp) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
        af.sync_dir = 0; /* in the temporary time folder, synced when renamed into place */
        lub_table_write_header(fp, "bin sum[Pa] n");
        fprintf(fp,
                "# wallPressure %s: samples %ld steps from t = %.17g to t = %.17g; from %.17g "
                "bin %.17g bins %d\n",
                o->name, o->samples, o->tfirst, o->tlast, o->from, o->bin, o->nbins);
        for (int b = 0; b < o->nbins; b++)
            if (o->count[b]) fprintf(fp, "%d %.17g %ld\n", b, o->sum[b], o->count[b]);
        if (lub_atomic_close(&af) != 0)
            lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
    }
}

void lubfoam_functions_free(lubfoam_functions *F)
{
    if (!F) return;
    for (int k = 0; k < F->n; k++) {
        if (F->f[k].fp) fclose(F->f[k].fp);
        free(F->f[k].sum);
        free(F->f[k].count);
        free(F->f[k].psum);
        free(F->f[k].pcount);
        for (int d = 0; d < 3; d++) free(F->f[k].f[d]);
    }
    free(F->f);
    free(F);
}
