/* probe: running one sampling set over its time folders (see probe.h).
 *
 * Each kind reads the first time folder to resolve what the set names (fields, patch, bins),
 * then samples every time folder with src/post.  Without -average a table is written per time;
 * with it, the samples of all times are pooled and one table is written at the end.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/error.h"
#include "particles/particles_io.h"
#include "models/transport.h"
#include "models/models.h"
#include "post/film.h"
#include "post/sample.h"
#include "post/wallshape.h"
#include "probe.h"

void probe_ctx_free(probe_ctx *x)
{
    if (x->geom_state > 0) lub_geometry_free(&x->geom);
    x->geom_state = 0;
    lub_dict_free(x->models);
    x->models = NULL;
    x->ew_state = 0;
}

/* ---- the case's dictionaries, read when a set needs them ------------------------------ */

/* system/particleGenDict.yaml: NULL when absent and not required. */
static const lub_geometry *ctx_geometry(probe_ctx *x, const char *why)
{
    if (x->geom_state == 0) {
        char path[LUB_PATH_MAX];
        struct stat st;
        lub_case_path(&x->c, path, "system/particleGenDict.yaml");
        if (stat(path, &st) != 0) {
            x->geom_state = -1;
        } else {
            lub_geometry_read(&x->geom, path);
            x->geom_state = 1;
        }
    }
    if (x->geom_state < 0 && why)
        lub_fatal("%s needs the wall geometry of system/particleGenDict.yaml, which case '%s' "
                  "does not have",
                  why, x->c.root);
    return x->geom_state > 0 ? &x->geom : NULL;
}

static const lub_refscales *ctx_scales(probe_ctx *x)
{
    if (!x->have_scales) {
        char path[LUB_PATH_MAX];
        struct stat st;
        if (stat(lub_case_path(&x->c, path, "system/reynoldsRefDict.yaml"), &st) != 0)
            lub_fatal("-dimensionless scales with R, h0 and U1 + U2 of the Reynolds reference, "
                      "which reads system/reynoldsRefDict.yaml: case '%s' has none (template: "
                      "etc/templates/reynoldsRefDict.yaml)",
                      x->c.root);
        lub_refscales_read(&x->scales, &x->c);
        x->have_scales = 1;
    }
    return &x->scales;
}

/* The elasticWall entry of constant/models.yaml (read against the geometry), or NULL when
 * the case has none. */
static const lub_elastic_wall *ctx_elastic(probe_ctx *x)
{
    if (x->ew_state == 0) {
        char path[LUB_PATH_MAX];
        struct stat st;
        x->ew_state = -1;
        if (stat(lub_case_path(&x->c, path, "constant/models.yaml"), &st) == 0 &&
            ctx_geometry(x, NULL)) {
            x->models = lub_dict_read(path);
            lub_node *root = lub_dict_root(x->models);
            lub_models_declare(root);
            if (lub_elastic_wall_read(root, &x->geom, &x->ew)) x->ew_state = 1;
            lub_dict_finish(x->models);
        }
    }
    return x->ew_state > 0 ? &x->ew : NULL;
}

/* The resolution levels of a multi-resolution case (models/multiResolution/levels.h), read as the
 * solver reads them (constant/models.yaml multiResolution against system/particleGenDict.yaml,
 * checked against the particles P: fatal with file:line when they disagree), or NULL when
 * models.yaml has no multiResolution entry. */
static const lub_levels *ctx_levels(probe_ctx *x, const lub_particles *P)
{
    if (x->levels_state == 0) {
        char path[LUB_PATH_MAX], geo[LUB_PATH_MAX];
        x->levels_state = -1;
        lub_dict *d = lub_dict_read_optional(lub_case_path(&x->c, path, "constant/models.yaml"));
        if (!d) return NULL;
        lub_node *root = lub_dict_root(d);
        lub_models_declare(root);
        lub_node *mr = lub_dict_find(root, "multiResolution");
        if (mr) {
            lub_levels_read_case(&x->levels, mr,
                                 lub_case_path(&x->c, geo, "system/particleGenDict.yaml"), P);
            x->levels_state = 1;
        }
        lub_dict_free(d);
    }
    return x->levels_state > 0 ? &x->levels : NULL;
}

/* M^0 of a multi-resolution run (T-27): the multiResolution mass0 of the first of the times
 * whose uniform/state.yaml has one (lubFoam writes the run's M^0 there), into *m0 and the
 * time's name into from; 0 when none has. */
static int state_mass0(const lub_case *c, const lub_time *times, size_t nt, double *m0, char *from,
                       size_t size)
{
    for (size_t i = 0; i < nt; i++) {
        char path[LUB_PATH_MAX];
        lub_dict *d =
            lub_dict_read_optional(lub_case_pathf(c, path, "%s/uniform/state.yaml", times[i].name));
        if (!d) continue;
        lub_node *mr = lub_dict_map_or(lub_dict_root(d), "multiResolution");
        int found = mr && lub_dict_has(mr, "mass0");
        if (found) {
            *m0 = lub_dict_real(mr, "mass0", LUB_NONNEGATIVE);
            snprintf(from, size, "%s/uniform/state.yaml", times[i].name);
        }
        lub_dict_free(d);
        if (found) return 1;
    }
    return 0;
}

static double ctx_rho(probe_ctx *x)
{
    if (!x->have_rho) {
        char path[LUB_PATH_MAX];
        double nu;
        lub_transport_read(lub_case_path(&x->c, path, "constant/transportProperties.yaml"), &x->rho,
                           &nu);
        x->have_rho = 1;
    }
    return x->rho;
}

/* ---- one run -------------------------------------------------------------------------- */

typedef struct {
    probe_ctx *x;
    probe_spec *s;
    probe_sink *k;
    lub_time *times;
    size_t nt;
    lub_particles P;         /* the time folder being sampled */
    char file[LUB_PATH_MAX]; /* its particles.h5 */
    lub_post_fields f;       /* resolved fields (wallPressure, line, points) */
    const double *vals[LUB_POST_MAX_COLS];
    int pcol;                /* column of p in f, or -1 */
    const lub_refscales *sc; /* -dimensionless, else NULL */
    probe_block b;
} job;

/* Times of a set: the command-line selection, cut to the averaging window. */
static void job_times(job *j)
{
    const lub_args *a = j->x->a;
    const probe_spec *s = j->s;
    j->nt = lub_case_select_times(&j->x->c, a->time, a->latest_time, a->no_zero, &j->times);
    if (!s->average) return;
    size_t m = 0;
    char avail[512] = "";
    size_t len = 0;
    for (size_t i = 0; i < j->nt; i++) {
        double v = j->times[i].value, tol = 1e-9 * fmax(fabs(v), 1e-300);
        if (len < sizeof avail - 16)
            len += (size_t)snprintf(avail + len, sizeof avail - len, "%s%s", i ? " " : "",
                                    j->times[i].name);
        if (v >= s->t0 - tol && v <= s->t1 + tol) j->times[m++] = j->times[i];
    }
    if (m == 0) {
        free(j->times);
        probe_error(s->average_node,
                    "%sno time folder of case '%s' in the averaging window [%g, %g] (selected "
                    "times: %s)",
                    s->average_node ? "" : "-average: ", j->x->c.root, s->t0, s->t1, avail);
    }
    j->nt = m;
}

/* -z Z0:Z1 (3-D): keep the particles with z in [z0, z1] (a slab across the width, e.g. the
 * mid-plane of a finite bearing), in their order; every sampler then sees the slab alone. */
static void keep_slab(job *j)
{
    lub_particles *P = &j->P;
    if (P->dim != 3)
        probe_error(j->s->z_node, "%sa z-range needs a 3-D case; %s is %d-D",
                    j->s->z_node ? "" : "-z: ", j->file, P->dim);
    size_t m = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (!(P->x[2][i] >= j->s->z0 && P->x[2][i] <= j->s->z1)) continue;
        for (int d = 0; d < 3; d++) P->x[d][m] = P->x[d][i], P->u[d][m] = P->u[d][i];
        P->p[m] = P->p[i];
        P->kind[m] = P->kind[i];
        P->patch[m] = P->patch[i];
        P->level[m] = P->level[i];
        P->id[m] = P->id[i];
        for (int e = 0; e < P->nextra; e++) P->extra[e].v[m] = P->extra[e].v[i];
        m++;
    }
    if (m == 0)
        probe_error(j->s->z_node, "%sno particle of %s has z in [%g, %g]",
                    j->s->z_node ? "" : "-z: ", j->file, j->s->z0, j->s->z1);
    P->n = m;
}

static void job_read(job *j, size_t it)
{
    struct stat st;
    lub_case_pathf(&j->x->c, j->file, "%s/particles.h5", j->times[it].name);
    if (stat(j->file, &st) != 0)
        lub_fatal("time folder '%s' of case '%s' has no particles.h5 (%s)", j->times[it].name,
                  j->x->c.root, j->file);
    lub_particles_read(&j->P, j->file);
    if (j->s->has_z) keep_slab(j);
}

/* Fields of the set, resolved against the first time folder. */
static void job_fields(job *j)
{
    char err[1536];
    if (lub_post_fields_parse(&j->f, j->s->fields, &j->P, err, sizeof err))
        probe_error(j->s->field_node, "%s%s (in %s)", j->s->field_node ? "" : "-field: ", err,
                    j->file);
    j->pcol = -1;
    for (int c = 0; c < j->f.n; c++)
        if (j->f.col[c].src == LUB_POST_PRESSURE) j->pcol = c;
}

static void job_arrays(job *j)
{
    char err[256];
    if (lub_post_fields_arrays(&j->f, &j->P, j->vals, err, sizeof err))
        lub_fatal("%s: %s, which the set '%s' samples (it is in the first time folder, %s)",
                  j->file, err, j->s->name, j->times[0].name);
}

/* Patch index of the set's patch in the current particles; fatal listing the patches. */
static int job_patch(job *j)
{
    const probe_spec *s = j->s;
    int p = lub_particles_find_patch(&j->P, s->patch);
    if (p >= 0) return p;
    const char *names[LUB_MAX_PATCHES];
    char list[LUB_MAX_PATCHES * (LUB_NAME_MAX + 1)] = "";
    size_t len = 0;
    for (int k = 0; k < j->P.npatches; k++) {
        names[k] = j->P.patch_names[k];
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", k ? " " : "", names[k]);
    }
    const char *near = lub_closest(s->patch, names, (size_t)j->P.npatches);
    char hint[LUB_NAME_MAX + 32] = "";
    if (near) snprintf(hint, sizeof hint, " (did you mean '%s'?)", near);
    probe_error(s->patch_node, "%sno patch '%s' in %s%s; the patches are: %s",
                s->patch_node ? "" : "-patch: ", s->patch, j->file, hint,
                j->P.npatches ? list : "none (no walls)");
}

/* Write the block of time `it` (or of the window, averaged). */
static void job_emit(job *j, size_t it)
{
    size_t last = j->nt - 1;
    if (j->s->average) {
        probe_sink_write(j->k, &j->b, j->times[last].name, j->times[last].value);
        return;
    }
    probe_sink_write(j->k, &j->b, j->times[it].name, j->times[it].value);
}

static void header_add(char *h, size_t size, const char *name)
{
    size_t len = strlen(h);
    snprintf(h + len, size - len, "%s%s", len ? " " : "", name);
}

/* Default x-range of bins: the domain of particleGenDict.yaml, else the extent of the
 * particles of the given kind (-1: all). */
static void job_xrange(job *j, int kind)
{
    probe_spec *s = j->s;
    if (!isnan(s->from) && !isnan(s->to)) return;
    double lo = INFINITY, hi = -INFINITY;
    const lub_geometry *g = ctx_geometry(j->x, NULL);
    if (g) {
        lo = g->dmin[0];
        hi = g->dmax[0];
    } else {
        for (size_t i = 0; i < j->P.n; i++)
            if (kind < 0 || j->P.kind[i] == kind) {
                lo = fmin(lo, j->P.x[0][i]);
                hi = fmax(hi, j->P.x[0][i]);
            }
    }
    if (isnan(s->from)) s->from = lo;
    if (isnan(s->to)) s->to = hi;
}

static void job_bins(job *j, lub_bins *b)
{
    probe_spec *s = j->s;
    if (isnan(s->bin)) s->bin = 4.0 * j->P.levels[0].l0;
    if (!isfinite(s->from) || !isfinite(s->to))
        probe_error(s->node,
                    "set '%s': no particles to bin (nothing gives the range; set -from "
                    "and -to)",
                    s->name);
    if (!(s->from < s->to))
        probe_error(s->node, "%s'from' (%.9g) must be less than 'to' (%.9g)",
                    s->node ? "" : "-from, -to: ", s->from, s->to);
    if (lub_bins_init(b, s->from, s->to, s->bin) != 0)
        probe_error(s->node, "%sbin width %g on [%.9g, %.9g] gives more than %d bins",
                    s->node ? "" : "-bin: ", s->bin, s->from, s->to, LUB_BINS_MAX);
}

/* Coordinate and scaled columns of a binned table: "x[m] <fields> n [X] [P]". */
static void binned_header(job *j, const char *coord, const char *coord_dimless, char *h,
                          size_t size)
{
    h[0] = '\0';
    header_add(h, size, coord);
    for (int c = 0; c < j->f.n; c++) header_add(h, size, j->f.col[c].column);
    header_add(h, size, "n");
    if (j->sc) {
        header_add(h, size, coord_dimless);
        if (j->pcol >= 0) header_add(h, size, "P");
    }
}

static void binned_block(job *j, const lub_bins *bins, const lub_accum *acc, const char *coord,
                         const char *coord_dimless)
{
    char h[2048];
    binned_header(j, coord, coord_dimless, h, sizeof h);
    int nc = 2 + j->f.n + (j->sc ? 1 + (j->pcol >= 0) : 0);
    probe_block_begin(&j->b, h, nc);
    double row[LUB_POST_MAX_COLS + 8];
    for (int k = 0; k < bins->nbins; k++) {
        if (acc->count[k] == 0.0) continue;
        int m = 0;
        double xc = lub_bins_centre(bins, k);
        row[m++] = xc;
        for (int c = 0; c < j->f.n; c++) row[m++] = lub_accum_mean(acc, k, c);
        row[m++] = acc->count[k];
        if (j->sc) {
            row[m++] = xc / j->sc->sx;
            if (j->pcol >= 0) row[m++] = lub_accum_mean(acc, k, j->pcol) * j->sc->sp;
        }
        probe_block_row(&j->b, row);
    }
}

/* ---- line: fluid particles binned along x --------------------------------------------- */

static void run_line(job *j)
{
    lub_bins bins;
    lub_accum acc = {0};
    for (size_t it = 0; it < j->nt; it++) {
        job_read(j, it);
        if (it == 0) {
            job_fields(j);
            job_xrange(j, LUB_FLUID);
            job_bins(j, &bins);
            lub_accum_init(&acc, bins.nbins, j->f.n);
        }
        job_arrays(j);
        if (lub_sample_bins(&acc, &bins, &j->P, LUB_FLUID, -1, NULL, j->vals) == 0)
            lub_warning("time %s: no fluid particle in [%g, %g]", j->times[it].name, bins.from,
                        bins.to);
        lub_particles_free(&j->P);
        if (!j->s->average || it == j->nt - 1) {
            binned_block(j, &bins, &acc, "x[m]", "X");
            job_emit(j, it);
            lub_accum_clear(&acc);
        }
    }
    lub_accum_free(&acc);
}

/* ---- wallPressure: the wall particles of a patch -------------------------------------- */

typedef struct {
    uint64_t id;
    int row;
} id_row;

static int id_cmp(const void *a, const void *b)
{
    uint64_t x = ((const id_row *)a)->id, y = ((const id_row *)b)->id;
    return (x > y) - (x < y);
}

typedef struct {
    double key;
    int row;
} key_row;

static int key_cmp(const void *a, const void *b)
{
    const key_row *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->row > y->row) - (x->row < y->row);
}

/* Arc length of every wall particle of the patch into s[] (others: NAN). */
static void arc_coords(job *j, const lub_wall *w, int patch, double *s)
{
    for (size_t i = 0; i < j->P.n; i++) {
        s[i] = NAN;
        if (j->P.kind[i] != LUB_WALL || j->P.patch[i] != patch) continue;
        double x[3] = {j->P.x[0][i], j->P.x[1][i], j->P.x[2][i]};
        lub_wall_arc(w, j->P.dim, x, &s[i]);
    }
}

static const lub_wall *arc_wall(job *j)
{
    const probe_spec *s = j->s;
    const lub_geometry *g = ctx_geometry(j->x, "-arc");
    int w = lub_geometry_find_wall(g, s->patch);
    if (w < 0)
        probe_error(s->patch_node,
                    "%s-arc: patch '%s' is not a wall of system/particleGenDict.yaml, so its "
                    "arc length is unknown",
                    s->patch_node ? "" : "-patch: ", s->patch);
    double x0[3] = {0, 0, 0}, dummy;
    if (lub_wall_arc(&g->walls[w], g->dim, x0, &dummy) != 0)
        probe_error(s->node,
                    "-arc: arc length is defined along 2-D cylinder, plane, segment, polyline and "
                    "polygon walls; wall '%s' is not one of them%s",
                    s->patch, g->dim == 3 ? " (the case is 3-D)" : "");
    return &g->walls[w];
}

/* -facing: no coordinate (NAN) for the wall particles of the patch that do not face the
 * direction asked for (lub_wall_facing). */
static void facing_filter(job *j, int patch, double *coord)
{
    unsigned char *on = lub_malloc(j->P.n ? j->P.n : 1);
    lub_wall_facing(&j->P, patch, j->s->facing, on);
    for (size_t i = 0; i < j->P.n; i++)
        if (j->P.kind[i] == LUB_WALL && j->P.patch[i] == patch && !on[i]) coord[i] = NAN;
    free(on);
}

static void run_wall_binned(job *j)
{
    lub_bins bins;
    lub_accum acc = {0};
    const lub_wall *w = j->s->arc ? arc_wall(j) : NULL;
    double *coord = NULL;
    for (size_t it = 0; it < j->nt; it++) {
        job_read(j, it);
        int patch = job_patch(j);
        if (w) {
            coord = lub_realloc(coord, (j->P.n ? j->P.n : 1) * sizeof *coord);
            arc_coords(j, w, patch, coord);
        }
        if (it == 0) {
            job_fields(j);
            if (w && (isnan(j->s->from) || isnan(j->s->to))) {
                double lo = INFINITY, hi = -INFINITY;
                for (size_t i = 0; i < j->P.n; i++)
                    if (!isnan(coord[i])) lo = fmin(lo, coord[i]), hi = fmax(hi, coord[i]);
                if (isnan(j->s->from)) j->s->from = lo;
                if (isnan(j->s->to)) j->s->to = hi;
            } else if (!w) {
                job_xrange(j, LUB_WALL);
            }
            job_bins(j, &bins);
            lub_accum_init(&acc, bins.nbins, j->f.n);
        }
        job_arrays(j);
        /* multi-resolution: the wall particles of the level that owns their x only (each x
         * once, as the wallPressure function object and the elasticWall load): the others
         * get no coordinate */
        const lub_levels *L = j->P.nlevels > 1 ? ctx_levels(j->x, &j->P) : NULL;
        if ((L || j->s->facing) && !w) {
            coord = lub_realloc(coord, (j->P.n ? j->P.n : 1) * sizeof *coord);
            memcpy(coord, j->P.x[0], j->P.n * sizeof *coord);
        }
        if (j->s->facing) facing_filter(j, patch, coord);
        if (L) {
            for (size_t i = 0; i < j->P.n; i++) {
                if (j->P.kind[i] != LUB_WALL) continue;
                lub_level_where lw;
                lub_levels_locate(L, j->P.x[0][i], &lw);
                if (lw.owner != j->P.level[i]) coord[i] = NAN;
            }
        }
        if (lub_sample_bins(&acc, &bins, &j->P, LUB_WALL, patch, coord, j->vals) == 0)
            lub_warning("time %s: no wall particle of patch '%s' in [%g, %g]", j->times[it].name,
                        j->s->patch, bins.from, bins.to);
        lub_particles_free(&j->P);
        if (!j->s->average || it == j->nt - 1) {
            binned_block(j, &bins, &acc, w ? "s[m]" : "x[m]", w ? "S" : "X");
            job_emit(j, it);
            lub_accum_clear(&acc);
        }
    }
    free(coord);
    lub_accum_free(&acc);
}

/* Unbinned: one row per wall particle (by id), sorted by its coordinate. */
static void run_wall_particles(job *j)
{
    const probe_spec *s = j->s;
    const lub_wall *w = s->arc ? arc_wall(j) : NULL;
    double *coord = NULL;
    id_row *ids = NULL;
    key_row *order = NULL;
    size_t nids = 0;
    lub_accum acc = {0};
    int dim = 0, ncoord = 0;
    for (size_t it = 0; it < j->nt; it++) {
        job_read(j, it);
        int patch = job_patch(j);
        coord = lub_realloc(coord, (j->P.n ? j->P.n : 1) * sizeof *coord);
        if (w)
            arc_coords(j, w, patch, coord);
        else
            memcpy(coord, j->P.x[0], j->P.n * sizeof *coord);
        if (s->facing) facing_filter(j, patch, coord);
        if (it == 0) {
            job_fields(j);
            dim = j->P.dim;
            ncoord = (w ? 1 : 0) + dim;
            ids = lub_malloc((j->P.n ? j->P.n : 1) * sizeof *ids);
            for (size_t i = 0; i < j->P.n; i++)
                if (j->P.kind[i] == LUB_WALL && j->P.patch[i] == patch) {
                    ids[nids].id = j->P.id[i];
                    ids[nids].row = (int)nids;
                    nids++;
                }
            if (nids == 0)
                probe_error(s->patch_node, "%spatch '%s' has no wall particles in %s",
                            s->patch_node ? "" : "-patch: ", s->patch, j->file);
            qsort(ids, nids, sizeof *ids, id_cmp);
            lub_accum_init(&acc, (int)nids, ncoord + j->f.n);
            order = lub_malloc(nids * sizeof *order);
        }
        job_arrays(j);
        double row[LUB_POST_MAX_COLS + 8];
        for (size_t i = 0; i < j->P.n; i++) {
            if (j->P.kind[i] != LUB_WALL || j->P.patch[i] != patch) continue;
            if (isnan(coord[i]) || (!isnan(s->from) && coord[i] < s->from) ||
                (!isnan(s->to) && coord[i] > s->to))
                continue;
            id_row key = {j->P.id[i], 0}, *hit = bsearch(&key, ids, nids, sizeof *ids, id_cmp);
            if (!hit)
                lub_fatal("%s: wall particle %llu of patch '%s' is not in the first time folder "
                          "(%s); the wall particles changed: average with -bin",
                          j->file, (unsigned long long)j->P.id[i], s->patch, j->times[0].name);
            int m = 0;
            if (w) row[m++] = coord[i];
            for (int d = 0; d < dim; d++) row[m++] = j->P.x[d][i];
            for (int c = 0; c < j->f.n; c++) row[m++] = j->vals[c][i];
            lub_accum_add(&acc, hit->row, row);
        }
        lub_particles_free(&j->P);
        if (s->average && it != j->nt - 1) continue;

        /* the table, sorted by the (mean) coordinate */
        char h[2048] = "";
        static const char *const axes[3] = {"x[m]", "y[m]", "z[m]"};
        if (w) header_add(h, sizeof h, "s[m]");
        for (int d = 0; d < dim; d++) header_add(h, sizeof h, axes[d]);
        for (int c = 0; c < j->f.n; c++) header_add(h, sizeof h, j->f.col[c].column);
        if (j->sc) {
            header_add(h, sizeof h, w ? "S" : "X");
            if (j->pcol >= 0) header_add(h, sizeof h, "P");
        }
        int nc = ncoord + j->f.n + (j->sc ? 1 + (j->pcol >= 0) : 0);
        probe_block_begin(&j->b, h, nc);
        size_t nrow = 0;
        for (size_t r = 0; r < nids; r++)
            if (acc.count[r] > 0.0)
                order[nrow++] = (key_row){lub_accum_mean(&acc, (int)r, 0), (int)r};
        qsort(order, nrow, sizeof *order, key_cmp);
        for (size_t q = 0; q < nrow; q++) {
            int r = order[q].row, m = 0;
            for (int c = 0; c < ncoord + j->f.n; c++) row[m++] = lub_accum_mean(&acc, r, c);
            if (j->sc) {
                row[m++] = lub_accum_mean(&acc, r, 0) / j->sc->sx;
                if (j->pcol >= 0) row[m++] = lub_accum_mean(&acc, r, ncoord + j->pcol) * j->sc->sp;
            }
            probe_block_row(&j->b, row);
        }
        if (nrow == 0)
            lub_warning("time %s: no wall particle of patch '%s' in the range", j->times[it].name,
                        s->patch);
        job_emit(j, it);
        lub_accum_clear(&acc);
    }
    free(coord);
    free(ids);
    free(order);
    lub_accum_free(&acc);
}

/* ---- points: kernel-weighted means at given points ------------------------------------ */

/* points -history: one point, a row '# t <fields> n' per time, one table under the first
 * time (as the other time series: totals, front) */
static void run_point_history(job *j)
{
    const probe_spec *s = j->s;
    if (s->npts != 1)
        probe_error(s->history_node ? s->history_node : s->at_node,
                    "%shistory samples one point, but %zu are given", s->history_node ? "" : "-",
                    s->npts);
    if (s->average)
        probe_error(s->average_node,
                    "%saverage does not apply to a history (one row per time): leave it out",
                    s->average_node ? "" : "-");
    if (j->sc)
        probe_error(s->node, "%sdimensionless does not apply to a history", s->node ? "" : "-");
    for (size_t it = 0; it < j->nt; it++) {
        job_read(j, it);
        if (it == 0) {
            job_fields(j);
            if (s->pts_dim != j->P.dim)
                probe_error(s->at_node, "%sthe point has %d coordinates, but the case is %d-D (%s)",
                            s->at_node ? "" : "-at: ", s->pts_dim, j->P.dim, j->file);
            char h[2048] = "";
            header_add(h, sizeof h, "t[s]");
            for (int c = 0; c < j->f.n; c++) header_add(h, sizeof h, j->f.col[c].column);
            header_add(h, sizeof h, "n");
            probe_block_begin(&j->b, h, j->f.n + 2);
            const double *p = s->pts;
            if (j->P.dim == 3)
                probe_block_comment(&j->b, "at (%.9g, %.9g, %.9g): the Shepard mean over re", p[0],
                                    p[1], p[2]);
            else
                probe_block_comment(&j->b, "at (%.9g, %.9g): the Shepard mean over re", p[0], p[1]);
        }
        job_arrays(j);
        double out[LUB_POST_MAX_COLS + 1], row[LUB_POST_MAX_COLS + 2], re = 0.0;
        size_t used = lub_sample_point(&j->P, s->pts, j->vals, j->f.n, out, &re);
        row[0] = j->times[it].value;
        for (int c = 0; c < j->f.n; c++) row[1 + c] = used ? out[c] : NAN;
        row[1 + j->f.n] = (double)used;
        if (!used)
            lub_warning("time %s: no fluid or wall particle within re = %g of the point: nan",
                        j->times[it].name, re);
        probe_block_row(&j->b, row);
        lub_particles_free(&j->P);
    }
    probe_sink_write(j->k, &j->b, j->times[0].name, j->times[0].value);
}

static void run_points(job *j)
{
    const probe_spec *s = j->s;
    if (s->history) {
        run_point_history(j);
        return;
    }
    lub_accum acc = {0};
    int dim = 0;
    for (size_t it = 0; it < j->nt; it++) {
        job_read(j, it);
        if (it == 0) {
            job_fields(j);
            dim = j->P.dim;
            if (s->pts_dim != dim)
                probe_error(s->at_node,
                            "%sthe points have %d coordinates, but the case is %d-D (%s): give "
                            "%s",
                            s->at_node ? "" : "-at: ", s->pts_dim, dim, j->file,
                            dim == 2 ? "'x y; x y ...'" : "'x y z; x y z ...'");
            lub_accum_init(&acc, (int)s->npts, j->f.n + 1);
        }
        job_arrays(j);
        double out[LUB_POST_MAX_COLS + 1];
        for (size_t q = 0; q < s->npts; q++) {
            double re = 0.0;
            size_t used = lub_sample_point(&j->P, s->pts + 3 * q, j->vals, j->f.n, out, &re);
            if (!used) {
                char where[128];
                const double *p = s->pts + 3 * q;
                if (dim == 3)
                    snprintf(where, sizeof where, "(%g, %g, %g)", p[0], p[1], p[2]);
                else
                    snprintf(where, sizeof where, "(%g, %g)", p[0], p[1]);
                lub_warning("time %s: no fluid or wall particle within re = %g of point %zu %s: "
                            "left out",
                            j->times[it].name, re, q + 1, where);
                continue;
            }
            out[j->f.n] = (double)used;
            lub_accum_add(&acc, (int)q, out);
        }
        lub_particles_free(&j->P);
        if (s->average && it != j->nt - 1) continue;

        char h[2048] = "";
        static const char *const axes[3] = {"x[m]", "y[m]", "z[m]"};
        for (int d = 0; d < dim; d++) header_add(h, sizeof h, axes[d]);
        for (int c = 0; c < j->f.n; c++) header_add(h, sizeof h, j->f.col[c].column);
        header_add(h, sizeof h, "n");
        if (j->sc) {
            header_add(h, sizeof h, "X");
            if (j->pcol >= 0) header_add(h, sizeof h, "P");
        }
        probe_block_begin(&j->b, h, dim + j->f.n + 1 + (j->sc ? 1 + (j->pcol >= 0) : 0));
        double row[LUB_POST_MAX_COLS + 8];
        for (size_t q = 0; q < s->npts; q++) {
            if (acc.count[q] == 0.0) continue;
            int m = 0;
            for (int d = 0; d < dim; d++) row[m++] = s->pts[3 * q + (size_t)d];
            for (int c = 0; c < j->f.n; c++) row[m++] = lub_accum_mean(&acc, (int)q, c);
            /* samples: particles used, summed over the times */
            row[m++] = acc.sum[q * (size_t)acc.ncols + (size_t)j->f.n];
            if (j->sc) {
                row[m++] = s->pts[3 * q] / j->sc->sx;
                if (j->pcol >= 0) row[m++] = lub_accum_mean(&acc, (int)q, j->pcol) * j->sc->sp;
            }
            probe_block_row(&j->b, row);
        }
        job_emit(j, it);
        lub_accum_clear(&acc);
    }
    lub_accum_free(&acc);
}

/* ---- film: thickness and free surface ------------------------------------------------- */

/* Sums of one end of the film over the times (mean, range). */
typedef struct {
    double sum, min, max;
} film_end;

static void film_end_add(film_end *e, double x, size_t before)
{
    if (!before) e->min = e->max = x;
    e->sum += x;
    e->min = fmin(e->min, x);
    e->max = fmax(e->max, x);
}

/* "# NAME x = MEAN [X = ..] (the times, the range)" */
static void film_end_comment(job *j, const char *name, const film_end *e, size_t n, size_t nt)
{
    double x = e->sum / (double)n;
    char X[48] = "", of[160] = "";
    if (j->sc) snprintf(X, sizeof X, " X = %.6g", x / j->sc->sx);
    if (nt > 1)
        snprintf(of, sizeof of, " (mean of the %zu of %zu times with a full film; %.9g to %.9g)", n,
                 nt, e->min, e->max);
    probe_block_comment(&j->b, "%s x = %.9g%s%s", name, x, X, of);
}

static void run_film(job *j)
{
    const probe_spec *s = j->s;
    lub_film film = {0};
    lub_accum acc = {0};
    enum { H, SURFACE, BOTTOM, CONTACT, N, FILLED, FULL, NCOLS };
    film_end in = {0}, out = {0}, touch = {0};
    size_t nmen = 0, ntimes = 0;
    for (size_t it = 0; it < j->nt; it++) {
        job_read(j, it);
        if (it == 0) {
            job_xrange(j, -1);
            lub_bins bins;
            job_bins(j, &bins); /* validates the range and width */
            if (lub_film_init(&film, s->from, s->to, s->bin) != 0) lub_bug("film bins");
            lub_accum_init(&acc, film.bins.nbins, NCOLS);
        }
        lub_film_sample(&film, &j->P);
        lub_particles_free(&j->P);
        lub_film_row r;
        size_t found = 0;
        for (int k = 0; k < film.bins.nbins; k++) {
            if (!lub_film_row_at(&film, k, &r)) continue;
            double v[NCOLS] = {r.h,         r.surface, r.bottom,      (double)r.contact,
                               (double)r.n, r.filled,  (double)r.full};
            lub_accum_add(&acc, k, v);
            found++;
        }
        if (!found)
            lub_warning("time %s: no fluid particle in [%g, %g]", j->times[it].name, film.bins.from,
                        film.bins.to);
        lub_film_ends e;
        if (lub_film_meniscus(&film, &e)) {
            film_end_add(&in, e.inlet, nmen);
            film_end_add(&out, e.outlet, nmen);
            film_end_add(&touch, e.contact, nmen);
            nmen++;
        }
        ntimes++;
        if (s->average && it != j->nt - 1) continue;

        char h[256] = "x[m] h[m] surface[m] bottom[m] contact n";
        if (j->sc) header_add(h, sizeof h, "X H");
        header_add(h, sizeof h, "filled full");
        probe_block_begin(&j->b, h, 8 + (j->sc ? 2 : 0));
        for (int k = 0; k < film.bins.nbins; k++) {
            if (acc.count[k] == 0.0) continue;
            double xc = lub_bins_centre(&film.bins, k), row[10];
            int m = 0;
            row[m++] = xc;
            row[m++] = lub_accum_mean(&acc, k, H);
            row[m++] = lub_accum_mean(&acc, k, SURFACE);
            row[m++] = lub_accum_mean(&acc, k, BOTTOM);
            row[m++] = lub_accum_mean(&acc, k, CONTACT);
            row[m++] = acc.sum[(size_t)k * NCOLS + N];
            if (j->sc) {
                row[m++] = xc / j->sc->sx;
                row[m++] = row[1] / j->sc->h0;
            }
            row[m++] = lub_accum_mean(&acc, k, FILLED);
            row[m++] = lub_accum_mean(&acc, k, FULL);
            probe_block_row(&j->b, row);
        }
        if (nmen) {
            film_end_comment(j, "inletMeniscus", &in, nmen, ntimes);
            film_end_comment(j, "outletMeniscus", &out, nmen, ntimes);
            film_end_comment(j, "upperWallContact", &touch, nmen, ntimes);
        } else {
            probe_block_comment(&j->b, "inletMeniscus none (the gap is nowhere full from wall to "
                                       "wall)");
        }
        job_emit(j, it);
        lub_accum_clear(&acc);
        in = out = touch = (film_end){0};
        nmen = ntimes = 0;
    }
    lub_film_free(&film);
    lub_accum_free(&acc);
}

/* ---- wallShape: the elastic wall's deformation ---------------------------------------- */

/* The elastic wall of the set's patch; fatal when the case has none on it. */
static const lub_elastic_wall *job_elastic(job *j, const char *what)
{
    const probe_spec *s = j->s;
    ctx_geometry(j->x, what);
    const lub_elastic_wall *e = ctx_elastic(j->x);
    if (!e)
        probe_error(s->node,
                    "%s needs the elasticWall model in constant/models.yaml of case '%s' "
                    "(template: etc/templates/models.yaml)",
                    what, j->x->c.root);
    if (strcmp(e->patch_name, s->patch) != 0)
        probe_error(s->patch_node,
                    "%spatch '%s' is not the elastic wall: elasticWall in constant/models.yaml "
                    "names '%s'",
                    s->patch_node ? "" : "-patch: ", s->patch, e->patch_name);
    return e;
}

/* h0 of time folder `it`: its uniform/state.yaml (elasticWall.h0), else the elasticWall h0
 * (a particleGen folder).  *from names the source. */
static double job_h0(job *j, size_t it, const lub_elastic_wall *e, const char **from)
{
    char path[LUB_PATH_MAX];
    lub_case_pathf(&j->x->c, path, "%s/uniform/state.yaml", j->times[it].name);
    lub_dict *d = lub_dict_read_optional(path);
    lub_node *m = d ? lub_dict_map_or(lub_dict_root(d), "elasticWall") : NULL;
    double h0 = e->h0;
    *from = "the elasticWall h0 of constant/models.yaml: no state in this time folder";
    if (m) {
        h0 = lub_dict_real(m, "h0", LUB_ANY);
        *from = "uniform/state.yaml";
    }
    lub_dict_free(d);
    return h0;
}

static void run_shape(job *j)
{
    const probe_spec *s = j->s;
    const lub_elastic_wall *e = job_elastic(j, "wallShape");
    enum { X, Y, V, H, NC };
    id_row *ids = NULL;
    size_t nids = 0;
    lub_accum acc = {0};
    key_row *order = NULL;
    double h0sum = 0.0;
    size_t nh0 = 0;
    const char *h0from = "";
    for (size_t it = 0; it < j->nt; it++) {
        job_read(j, it);
        int patch = job_patch(j);
        double h0 = job_h0(j, it, e, &h0from);
        h0sum += h0;
        nh0++;
        lub_wall_shape_row *rows;
        size_t n = lub_wall_shape(&j->P, patch, &j->x->geom, e, h0, &rows);
        lub_particles_free(&j->P);
        if (it == 0) {
            if (n == 0)
                probe_error(s->patch_node, "%spatch '%s' has no wall particles in %s",
                            s->patch_node ? "" : "-patch: ", s->patch, j->file);
            ids = lub_malloc(n * sizeof *ids);
            for (size_t k = 0; k < n; k++) ids[k] = (id_row){rows[k].id, (int)k};
            nids = n;
            qsort(ids, nids, sizeof *ids, id_cmp);
            lub_accum_init(&acc, (int)nids, NC);
            order = lub_malloc(nids * sizeof *order);
        }
        for (size_t k = 0; k < n; k++) {
            const lub_wall_shape_row *r = &rows[k];
            if ((!isnan(s->from) && r->x < s->from) || (!isnan(s->to) && r->x > s->to)) continue;
            id_row key = {r->id, 0}, *hit = bsearch(&key, ids, nids, sizeof *ids, id_cmp);
            if (!hit)
                lub_fatal("%s: wall particle %llu of patch '%s' is not in the first time folder "
                          "(%s)",
                          j->file, (unsigned long long)r->id, s->patch, j->times[0].name);
            double v[NC] = {r->x, r->y, r->v, r->h};
            lub_accum_add(&acc, hit->row, v);
        }
        free(rows);
        if (s->average && it != j->nt - 1) continue;

        char h[256] = "x[m] y[m] v[m] h[m]";
        if (j->sc) header_add(h, sizeof h, "X H");
        probe_block_begin(&j->b, h, NC + (j->sc ? 2 : 0));
        size_t nrow = 0;
        for (size_t r = 0; r < nids; r++)
            if (acc.count[r] > 0.0)
                order[nrow++] = (key_row){lub_accum_mean(&acc, (int)r, X), (int)r};
        qsort(order, nrow, sizeof *order, key_cmp);
        for (size_t q = 0; q < nrow; q++) {
            int r = order[q].row;
            double row[NC + 2];
            for (int c = 0; c < NC; c++) row[c] = lub_accum_mean(&acc, r, c);
            if (j->sc) {
                row[NC] = row[X] / j->sc->sx;
                row[NC + 1] = row[H] / j->sc->h0;
            }
            probe_block_row(&j->b, row);
        }
        if (nh0 == 1)
            probe_block_comment(&j->b, "h0 = %.17g m (%s)", h0sum, h0from);
        else
            probe_block_comment(&j->b, "h0 = %.17g m (mean over %zu times)", h0sum / (double)nh0,
                                nh0);
        job_emit(j, it);
        lub_accum_clear(&acc);
        h0sum = 0.0;
        nh0 = 0;
    }
    free(ids);
    free(order);
    lub_accum_free(&acc);
}

/* ---- time series (totals, front): one row per time, or their mean with -average -------- */

static void series_row(job *j, const double *row, double *sum, int nc)
{
    if (j->s->average)
        for (int c = 0; c < nc; c++) sum[c] += row[c];
    else
        probe_block_row(&j->b, row);
}

/* Write the series: the mean row under the window's last time with -average, else one table
 * of all times under the first time, like the function objects' time series. */
static void series_emit(job *j, double *sum, int nc)
{
    if (j->s->average) {
        for (int c = 0; c < nc; c++) sum[c] /= (double)j->nt;
        probe_block_row(&j->b, sum);
        probe_block_comment(&j->b, "mean over the %zu time folders %s .. %s", j->nt,
                            j->times[0].name, j->times[j->nt - 1].name);
        job_emit(j, j->nt - 1);
        return;
    }
    probe_sink_write(j->k, &j->b, j->times[0].name, j->times[0].value);
}

/* ---- totals: one row per time --------------------------------------------------------- */

/* Multi-resolution totals (T-27): each fluid particle with the particle mass of its level
 * times the owned part of its cell (lub_levels_sum), as lubFoam's totals function object
 * counts them; owned[k]: the particles whose x their level owns. */
static void owned_totals(const lub_particles *P, const lub_levels *L, double rho, lub_totals *t,
                         size_t owned[LUB_MAX_LEVELS])
{
    lub_levels_sums s;
    memset(&s, 0, sizeof s);
    memset(t, 0, sizeof *t);
    lub_levels_sum(L, P, &s);
    double m[LUB_MAX_LEVELS];
    for (int k = 0; k < LUB_MAX_LEVELS; k++) owned[k] = s.owned[k];
    for (int k = 0; k < L->nlevels; k++) {
        m[k] = rho * pow(L->level[k].l0, P->dim);
        t->nfluid += owned[k];
        for (int d = 0; d < 3; d++) t->momentum[d] += m[k] * s.fu[k][d];
        t->kinetic += 0.5 * m[k] * s.fu2[k];
    }
    t->mass = lub_levels_mass(&s, L->nlevels, m);
}

static void run_totals(job *j)
{
    double rho = ctx_rho(j->x);
    enum { NFIX = 7, NC = NFIX + 3 + LUB_MAX_LEVELS };
    double sum[NC] = {0};
    int dim = 2, nc = NFIX;
    /* -patch: the load on the patch; loadMean when it is the elastic wall */
    const lub_elastic_wall *e = j->s->patch ? ctx_elastic(j->x) : NULL;
    int mean = e && strcmp(e->patch_name, j->s->patch) == 0;
    if (j->s->patch) nc += 1 + mean;
    /* multi-resolution: the mass error against M^0 and the particles of each level */
    const lub_levels *L = NULL;
    const int mcol = nc;
    double mass0 = NAN;
    char mass0_from[LUB_PATH_MAX + 64] = "";
    int have_state = 0;
    for (size_t it = 0; it < j->nt; it++) {
        job_read(j, it);
        dim = j->P.dim;
        lub_totals t;
        size_t owned[LUB_MAX_LEVELS];
        if (it == 0 && j->P.nlevels > 1) {
            L = ctx_levels(j->x, &j->P);
            if (!L)
                lub_warning("%s has %d resolution levels but constant/models.yaml has no "
                            "'multiResolution' entry: the totals count every fluid particle of "
                            "every level (an overlap twice)",
                            j->file, j->P.nlevels);
            else {
                nc += 1 + L->nlevels;
                have_state =
                    state_mass0(&j->x->c, j->times, j->nt, &mass0, mass0_from, sizeof mass0_from);
            }
        }
        if (L && j->P.nlevels != L->nlevels)
            lub_fatal("%s has %d resolution levels but the first time selected, %s, has %d",
                      j->file, j->P.nlevels, j->times[0].name, L->nlevels);
        if (L)
            owned_totals(&j->P, L, rho, &t, owned);
        else
            lub_totals_compute(&t, &j->P, rho);
        double row[NC] = {j->times[it].value, t.mass,    t.momentum[0],   t.momentum[1],
                          t.momentum[2],      t.kinetic, (double)t.nfluid};
        if (j->s->patch) {
            int patch = job_patch(j);
            if (dim != 2)
                probe_error(j->s->patch_node,
                            "%sthe load on a patch (the integral of p dx along it) is 2-D only; "
                            "%s is %d-D",
                            j->s->patch_node ? "" : "totals -patch: ", j->file, dim);
            /* multi-resolution: each x on the level that owns it (post/wallshape.h) */
            const lub_geometry *g = ctx_geometry(j->x, NULL);
            if (lub_wall_integral(&j->P, patch, g, j->P.p, &row[NFIX]) != 0)
                probe_error(j->s->patch_node,
                            "%spatch '%s' is not a curve y(x) in %s (two wall particles share "
                            "an x), so its load (the integral of p dx) is not defined",
                            j->s->patch_node ? "" : "-patch: ", j->s->patch, j->file);
            const double *pm = lub_particles_find_extra(&j->P, LUB_ELASTIC_FIELD_MEAN);
            row[NFIX + 1] = 0.0;
            if (mean && pm) lub_wall_integral(&j->P, patch, g, pm, &row[NFIX + 1]);
        }
        if (L) {
            if (it == 0 && !have_state) {
                mass0 = t.mass;
                snprintf(mass0_from, sizeof mass0_from,
                         "the mass at the first time selected, %s (no uniform/state.yaml with "
                         "multiResolution mass0 in the times selected)",
                         j->times[0].name);
            }
            row[mcol] = mass0 > 0 ? 100.0 * (t.mass / mass0 - 1.0) : 0.0;
            for (int k = 0; k < L->nlevels; k++) row[mcol + 1 + k] = (double)owned[k];
        }
        lub_particles_free(&j->P);
        if (it == 0) {
            char h[1024];
            int len = snprintf(h, sizeof h, "%s%s%s",
                               dim == 2 ? "t[s] mass[kg/m] momentumX[kg/s] momentumY[kg/s] "
                                          "momentumZ[kg/s] kineticEnergy[J/m] fluidParticles"
                                        : "t[s] mass[kg] momentumX[kg*m/s] momentumY[kg*m/s] "
                                          "momentumZ[kg*m/s] kineticEnergy[J] fluidParticles",
                               j->s->patch ? " load[N/m]" : "", mean ? " loadMean[N/m]" : "");
            if (L) {
                len += snprintf(h + len, sizeof h - (size_t)len, " massError[%%]");
                for (int k = 0; k < L->nlevels; k++)
                    len += snprintf(h + len, sizeof h - (size_t)len, " fluidLevel%d", k);
            }
            probe_block_begin(&j->b, h, nc);
            if (L) {
                probe_block_comment(&j->b,
                                    "multiResolution, %d levels: mass, momentum, kineticEnergy "
                                    "and fluidParticles count each fluid particle where its "
                                    "level owns x (T-27: each point of space on one level), "
                                    "fluidLevel<k> those of level k",
                                    L->nlevels);
                probe_block_comment(&j->b, "massError = 100 (mass / M0 - 1), M0 = %.17g %s: %s%s",
                                    mass0, dim == 2 ? "kg/m" : "kg", have_state ? "mass0 of " : "",
                                    mass0_from);
            }
        }
        series_row(j, row, sum, nc);
    }
    series_emit(j, sum, nc);
}

/* ---- front: the surge front of a dam break, one row per time ------------------------- */

static void run_front(job *j)
{
    enum { NC = 4 };
    double sum[NC] = {0};
    for (size_t it = 0; it < j->nt; it++) {
        job_read(j, it);
        const lub_particles *P = &j->P;
        const int v = P->dim - 1; /* the vertical: y in 2-D, z in 3-D */
        /* the lowest fluid particle, then the front of the two lowest rows above it, each
         * particle with the l0 of its level */
        double vmin = INFINITY;
        size_t nf = 0;
        for (size_t i = 0; i < P->n; i++)
            if (P->kind[i] == LUB_FLUID) {
                vmin = fmin(vmin, P->x[v][i]);
                nf++;
            }
        double xf = -INFINITY, top = -INFINITY;
        for (size_t i = 0; i < P->n; i++) {
            if (P->kind[i] != LUB_FLUID) continue;
            const double l0 = P->levels[P->level[i]].l0;
            if (P->x[v][i] < vmin + 1.5 * l0) xf = fmax(xf, P->x[0][i] + 0.5 * l0);
            top = fmax(top, P->x[v][i] + 0.5 * l0);
        }
        if (nf == 0) {
            lub_warning("%s has no fluid particle: its front is not a number", j->file);
            xf = top = NAN;
        }
        const double row[NC] = {j->times[it].value, xf, top, (double)nf};
        if (it == 0) {
            probe_block_begin(&j->b,
                              P->dim == 2 ? "t[s] xFront[m] yTop[m] fluidParticles"
                                          : "t[s] xFront[m] zTop[m] fluidParticles",
                              NC);
            probe_block_comment(&j->b,
                                "xFront: the largest x of the fluid particles less than 1.5 l0 "
                                "above the lowest one, + l0/2; %cTop: the highest, + l0/2",
                                P->dim == 2 ? 'y' : 'z');
        }
        lub_particles_free(&j->P);
        series_row(j, row, sum, NC);
    }
    series_emit(j, sum, NC);
}

/* ---- particles: every particle in the x-range, one row each ------------------------- */

static void run_particles(job *j)
{
    const probe_spec *s = j->s;
    for (size_t it = 0; it < j->nt; it++) {
        job_read(j, it);
        const lub_particles *P = &j->P;
        const int dim = P->dim;
        if (it == 0) job_fields(j);
        job_arrays(j);
        char h[2048] = "";
        static const char *const axes[3] = {"x[m]", "y[m]", "z[m]"};
        for (int d = 0; d < dim; d++) header_add(h, sizeof h, axes[d]);
        header_add(h, sizeof h, "kind");
        header_add(h, sizeof h, "patch");
        for (int c = 0; c < j->f.n; c++) header_add(h, sizeof h, j->f.col[c].column);
        const int nc = dim + 2 + j->f.n;
        probe_block_begin(&j->b, h, nc);
        char names[1024] = "";
        size_t len = 0;
        for (int k = 0; k < P->npatches && len < sizeof names; k++)
            len +=
                (size_t)snprintf(names + len, sizeof names - len, ", %d %s", k, P->patch_names[k]);
        probe_block_comment(&j->b, "kind: 0 fluid, 1 wall, 2 dummy; patch: -1 fluid%s", names);
        double row[LUB_POST_MAX_COLS + 8];
        for (size_t i = 0; i < P->n; i++) {
            if ((!isnan(s->from) && P->x[0][i] < s->from) || (!isnan(s->to) && P->x[0][i] > s->to))
                continue;
            int m = 0;
            for (int d = 0; d < dim; d++) row[m++] = P->x[d][i];
            row[m++] = (double)P->kind[i];
            row[m++] = P->kind[i] == LUB_FLUID ? -1.0 : (double)P->patch[i];
            for (int c = 0; c < j->f.n; c++) row[m++] = j->vals[c][i];
            probe_block_row(&j->b, row);
        }
        lub_particles_free(&j->P);
        job_emit(j, it);
    }
}

/* ---- entry ---------------------------------------------------------------------------- */

void probe_run(probe_ctx *x, probe_spec *s, probe_sink *k)
{
    job j;
    memset(&j, 0, sizeof j);
    j.x = x;
    j.s = s;
    j.k = k;
    if (s->dimensionless &&
        (s->kind == PROBE_TOTALS || s->kind == PROBE_FRONT || s->kind == PROBE_PARTICLES))
        probe_error(s->node, "-dimensionless does not apply to %s", probe_kind_names[s->kind]);
    job_times(&j);
    k->tcol = !k->per_time && j.nt > 1 && !s->average && s->kind != PROBE_TOTALS &&
              s->kind != PROBE_FRONT && !s->history;
    if (s->dimensionless) j.sc = ctx_scales(x);
    switch (s->kind) {
    case PROBE_WALL:
        if (isnan(s->bin))
            run_wall_particles(&j);
        else
            run_wall_binned(&j);
        break;
    case PROBE_LINE:
        run_line(&j);
        break;
    case PROBE_POINTS:
        run_points(&j);
        break;
    case PROBE_FILM:
        run_film(&j);
        break;
    case PROBE_TOTALS:
        run_totals(&j);
        break;
    case PROBE_SHAPE:
        run_shape(&j);
        break;
    case PROBE_FRONT:
        run_front(&j);
        break;
    case PROBE_PARTICLES:
        run_particles(&j);
        break;
    default:
        lub_bug("kind %d", (int)s->kind);
    }
    probe_block_free(&j.b);
    free(j.times);
}
