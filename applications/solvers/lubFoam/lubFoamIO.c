/* lubFoam: start time, restart state and time folders. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/args.h"
#include "core/error.h"
#include "io/dict.h"
#include "particles/particles_io.h"
#include "models/models.h"
#include "lubFoam.h"

static int has_particles(const lub_case *c, const char *name)
{
    char p[LUB_PATH_MAX];
    struct stat st;
    lub_case_pathf(c, p, "%s/particles.h5", name);
    return stat(p, &st) == 0;
}

/* startFrom: startTime in a case that holds results after the start time (an Allrun run
 * again without Allclean, a case copied with its results): the run overwrites the time
 * folders and postProcessing/<name>/<start>/ tables it writes again and leaves the others,
 * so that the case mixes two runs.  Said in the log, with what is there. */
static void warn_earlier_results(const lub_case *cs, const char *start)
{
    double t0 = 0;
    lub_parse_real(start, &t0);
    lub_time *t;
    size_t n = lub_case_times(cs, &t), first = n;
    for (size_t k = 0; k < n && first == n; k++)
        if (t[k].value > t0 + 1e-9 * fmax(fabs(t0), 1e-300)) first = k;
    char tables[512] = "", dir[LUB_PATH_MAX], sub[LUB_PATH_MAX];
    size_t len = 0, ntables = 0;
    DIR *d = opendir(lub_case_path(cs, dir, "postProcessing"));
    struct dirent *e;
    while (d && (e = readdir(d))) {
        struct stat st;
        if (e->d_name[0] == '.') continue;
        if (snprintf(sub, sizeof sub, "%s/%s/%s", dir, e->d_name, start) >= (int)sizeof sub ||
            stat(sub, &st) != 0 || !S_ISDIR(st.st_mode))
            continue;
        if (len < sizeof tables)
            len += (size_t)snprintf(tables + len, sizeof tables - len, "%s%s", ntables ? "," : "",
                                    e->d_name);
        ntables++;
    }
    if (d) closedir(d);
    if (first < n || ntables) {
        char folders[256] = "";
        if (first < n)
            snprintf(folders, sizeof folders, "%zu later time folder%s (%s%s%s)", n - first,
                     n - first > 1 ? "s" : "", t[first].name, n - first > 1 ? " to " : "",
                     n - first > 1 ? t[n - 1].name : "");
        char pp[768] = "";
        if (ntables)
            snprintf(pp, sizeof pp, "%sthe tables postProcessing/%s%s%s/%s/",
                     first < n ? " and " : "", ntables > 1 ? "{" : "", tables,
                     ntables > 1 ? "}" : "", start);
        lub_warning("startFrom: startTime %s, and the case holds results of an earlier run: "
                    "%s%s: this run overwrites those it writes again and leaves the others as "
                    "they are, so that the case mixes two runs (startFrom: latestTime "
                    "continues the earlier run; lubClean removes its results)",
                    start, folders, pp);
    }
    free(t);
}

/* -parallel: the rank-slice read.  Each rank reads its rows of the file (about N / size, by
 * hyperslabs: the file is read once over the ranks, not once per rank), and the slices go to
 * the slabs' owners: each rank then holds its slab, in the solver's order, and never the
 * whole case (doc/parallel.md, per-rank capacity).  An error in one rank's rows is every
 * rank's (rank 0 prints it, as the start-up's other errors). */
static void read_start_parallel(lubfoam_run *r, const lub_geometry *geo, const char *path)
{
    lub_particles_info info;
    lub_particles_read_info(path, &info);
    const int q = lub_par_rank(), size = lub_par_size();
    const size_t first = (size_t)((unsigned long long)q * info.n / (unsigned long long)size);
    const size_t count =
        (size_t)((unsigned long long)(q + 1) * info.n / (unsigned long long)size) - first;
    uint64_t *place = lub_malloc((count ? count : 1) * sizeof *place);
    lub_particles S;
    lub_catcher c;
    if (lub_error_catch(&c) == 0) {
        lub_particles_read_rows(&S, path, first, count, place);
        lub_error_uncatch();
        lub_par_raise(LUB_EXIT_INPUT, NULL);
    } else {
        lub_par_raise(c.status, c.message);
    }
    lubfoam_parallel_distribute(r, geo, &S, place, path);
    lub_particles_free(&S);
    free(place);
}

void lubfoam_read_start(lubfoam_run *r, const lub_geometry *geo)
{
    const lub_control *c = &r->ctl;
    char name[64], path[LUB_PATH_MAX];
    if (c->start_from == LUB_START_LATESTTIME) {
        lub_time *t;
        size_t n = lub_case_times(&r->cs, &t);
        int found = 0;
        for (size_t k = n; k-- > 0;)
            if (has_particles(&r->cs, t[k].name)) {
                snprintf(name, sizeof name, "%s", t[k].name);
                found = 1;
                break;
            }
        free(t);
        if (!found)
            lub_fatal("case '%s' has no time folder with particles.h5: run particleGen first",
                      r->cs.root);
    } else {
        lub_time_name(c->start_time, c->time_precision, name, sizeof name);
        if (!has_particles(&r->cs, name))
            lub_fatal("startTime %g: no file '%s/%s/particles.h5' (startFrom: startTime)",
                      c->start_time, r->cs.root, name);
    }
    snprintf(r->start_name, sizeof r->start_name, "%s", name);
    if (c->start_from == LUB_START_STARTTIME) warn_earlier_results(&r->cs, name);
    lub_case_pathf(&r->cs, path, "%s/particles.h5", name);
    if (r->parallel)
        read_start_parallel(r, geo, path);
    else
        lub_particles_read(&r->P, path);
    r->t = r->P.time;
    r->step = r->P.step;
    r->dt = c->delta_t;

    /* uniform/state.yaml: the exact time and time step of a run that wrote this folder */
    lub_dict *st =
        lub_dict_read_optional(lub_case_pathf(&r->cs, path, "%s/uniform/state.yaml", name));
    if (st) {
        lub_node *root = lub_dict_root(st);
        r->t = lub_dict_real(root, "time", LUB_NONNEGATIVE);
        r->step = lub_dict_int(root, "step", 0, 1L << 62);
        double dt = lub_dict_real_or(root, "deltaT", c->delta_t, LUB_POSITIVE);
        lub_models_declare_state(root); /* the models read their own entries */
        if (c->adjust_time_step) r->dt = dt < c->delta_t ? dt : c->delta_t;
        /* the write grid of the case's first run (absent: a state written before it was
         * kept, taken as starting here) */
        r->write_origin = lub_dict_real_or(root, "writeOrigin", r->t, LUB_NONNEGATIVE);
        r->write_origin_step = lub_dict_int_or(root, "writeOriginStep", r->step, 0, 1L << 62);
        lub_dict_finish(st);
        lub_dict_free(st);
    } else {
        r->write_origin = r->t;
        r->write_origin_step = r->step;
    }
    r->start_time = r->t;
}

static void write_state(const lubfoam_run *r, const char *dir)
{
    char udir[LUB_PATH_MAX + 16], path[LUB_PATH_MAX + 32];
    snprintf(udir, sizeof udir, "%s/uniform", dir);
    if (lub_mkdir_p(udir) != 0) lub_fatal_run("cannot create '%s': %s", udir, strerror(errno));
    snprintf(path, sizeof path, "%s/state.yaml", udir);
    /* flushed to disk (fsync) before the folder is renamed into place */
    lub_atomic_file af;
    FILE *fp = lub_atomic_open(&af, path);
    if (!fp) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
    af.sync_dir = 0; /* the folder is synced when it is renamed into place */
    fprintf(fp, "# written by lubFoam: what an exact restart needs\n");
    fprintf(fp, "time:   %.17g\n", r->t);
    fprintf(fp, "step:   %ld\n", r->step);
    fprintf(fp, "deltaT: %.17g\n", r->dt);
    fprintf(fp, "writeOrigin:     %.17g   # the write grid: writeOrigin + k writeInterval\n",
            r->write_origin);
    fprintf(fp, "writeOriginStep: %ld   # (writeControl: timeStep: steps from this one)\n",
            r->write_origin_step);
    lub_scene_write_state(&r->scene, fp);
    if (lub_atomic_close(&af) != 0) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
}

void lubfoam_output_init(lubfoam_run *r)
{
    if (r->collective) { /* every rank: the buffers of its rows */
        const size_t rows =
            lub_par_row_first(&r->par, r->par.rank + 1) - lub_par_row_first(&r->par, r->par.rank);
        lub_particles_writer_init(&r->writer, rows);
        lub_particles_init(&r->R, r->P.dim, rows ? rows : 1);
        r->R.nextra = 0;
        r->place = lub_malloc((rows ? rows : 1) * sizeof *r->place);
    }
    if (!lubfoam_writer_rank(r)) return;
    lub_case_clean(&r->cs);
    if (!r->collective)
        lub_particles_writer_init(&r->writer, r->parallel ? r->par.ntotal : r->P.cap);
    r->writer.sync_dir = 0; /* into temporary time folders, synced by lub_timedir_commit */
    lub_xdmf_series_scan(&r->series, &r->cs);
}

void lubfoam_output_free(lubfoam_run *r)
{
    if (r->collective || lubfoam_writer_rank(r)) lub_particles_writer_free(&r->writer);
    if (!lubfoam_writer_rank(r)) return;
    lub_xdmf_series_free(&r->series);
}

static void finish_write(lubfoam_run *r, lubfoam_functions *fos, const char *name, const char *dir,
                         const lub_particles *W);

void lubfoam_write(lubfoam_run *r, lubfoam_functions *fos)
{
    char name[64], dir[LUB_PATH_MAX];
    lub_time_name(r->t, r->ctl.time_precision, name, sizeof name);
    r->P.time = r->t;
    r->P.step = r->step;
    /* -parallel: every rank's particles to the rank writing their rows, and the file written
     * collectively; or every rank's particles to rank 0, which writes the file a serial run
     * writes (the writer puts them in id order) */
    const lub_particles *W = &r->P;
    if (r->collective) {
        const size_t first = lub_par_rows(&r->par, &r->P, &r->R, r->place);
        dir[0] = '\0';
        if (lubfoam_writer_rank(r)) lub_timedir_begin(&r->cs, name, dir);
        lub_par_bcast_text(dir, sizeof dir, 0);
        /* (the file's time is the output phase's, not the communication's of the cost) */
        lub_particles_writer_write_rows(&r->writer, &r->R, r->place, first, r->par.ntotal, dir);
        if (!lubfoam_writer_rank(r)) return;
        lub_particles H = r->R; /* the file's header and size, for the index */
        H.n = r->par.ntotal;
        finish_write(r, fos, name, dir, &H);
        return;
    }
    if (r->parallel) {
        if (r->G.cap == 0 && r->par.rank == 0) {
            lub_particles_init(&r->G, r->P.dim, r->par.ntotal);
            r->G.nextra = 0;
        }
        lub_par_gather(&r->par, &r->P, &r->G);
        W = &r->G;
    }
    if (!lubfoam_writer_rank(r)) return;
    lub_timedir_begin(&r->cs, name, dir);
    lub_particles_writer_write(&r->writer, W, dir);
    finish_write(r, fos, name, dir, W);
}

/* Rank 0, after the particle file: the rest of the time folder, its commit, the index and
 * the purge. */
static void finish_write(lubfoam_run *r, lubfoam_functions *fos, const char *name, const char *dir,
                         const lub_particles *W)
{
    write_state(r, dir);
    lubfoam_functions_write_state(fos, r, dir);
    lub_timedir_commit(&r->cs, name, dir);
    lub_xdmf_series_put(&r->series, name, W);

    if (r->nwritten == r->capwritten) {
        r->capwritten = r->capwritten ? 2 * r->capwritten : 16;
        r->written = lub_realloc(r->written, r->capwritten * sizeof *r->written);
    }
    snprintf(r->written[r->nwritten++], 64, "%s", name);
    if (r->ctl.purge_write > 0 && r->nwritten > (size_t)r->ctl.purge_write) {
        /* out of particles.xdmf first: a run stopped in between leaves an unlisted folder,
         * never a listed one that is gone */
        char old[LUB_PATH_MAX];
        lub_xdmf_series_remove(&r->series, r->written[0]);
        lub_rm_rf(lub_case_path(&r->cs, old, r->written[0]));
        memmove(r->written, r->written + 1, (r->nwritten - 1) * sizeof *r->written);
        r->nwritten--;
    }
}
