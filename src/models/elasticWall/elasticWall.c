/* lubkit model elasticWall: the elastic cylinder in the particle solver (see elasticWall.h). */
#include "models/elasticWall/elasticWall.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "models/models.h"

static void figures(lub_mps_elastic *w, double t);

/* ---- set-up ------------------------------------------------------------------------------ */

typedef struct {
    double x;
    uint64_t id;
    size_t i;
} patch_pt;

static int pt_cmp(const void *a, const void *b)
{
    const patch_pt *u = a, *v = b;
    if (u->x != v->x) return u->x < v->x ? -1 : 1;
    return (u->id > v->id) - (u->id < v->id);
}

typedef struct {
    uint64_t id;
    int slot;
} id_slot;

static int id_cmp(const void *a, const void *b)
{
    uint64_t x = ((const id_slot *)a)->id, y = ((const id_slot *)b)->id;
    return (x > y) - (x < y);
}

/* Slot of particle id on level part l, or -1. */
static int find_slot(const lub_mps_elastic_level *l, uint64_t id)
{
    int lo = 0, hi = l->nw + l->nd - 1;
    while (lo <= hi) {
        int mid = lo + (hi - lo) / 2;
        uint64_t s = l->sorted_id[mid];
        if (s == id) return l->sorted_slot[mid];
        if (s < id)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}

/* Particle index of every slot of a level, after the solver reordered (or, multi-resolution,
 * compacted) its particles.  Checking the ids costs O(nw + nd); the map is rebuilt only when
 * they moved. */
static void refresh_map(lub_mps_elastic_level *l, int patch)
{
    const lub_particles *P = l->m->P;
    const int n = l->nw + l->nd;
    int same = 1;
    for (int s = 0; s < n && same; s++) same = l->idx[s] < P->n && P->id[l->idx[s]] == l->ids[s];
    if (same) return;
    int found = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] == LUB_FLUID || P->patch[i] != patch) continue;
        int s = find_slot(l, P->id[i]);
        if (s < 0)
            lub_bug("elasticWall: particle id %llu joined the patch", (unsigned long long)P->id[i]);
        l->idx[s] = i;
        found++;
    }
    if (found != n) lub_bug("elasticWall: %d of %d patch particles found", found, n);
}

static void refresh_maps(lub_mps_elastic *w)
{
    for (int k = 0; k < w->nlevels; k++) refresh_map(&w->lv[k], w->patch);
}

/* Linear interpolation position of x among the sorted wall slots of a level: slot *a and
 * weight *f of slot *a + 1 (clamped to the end slots). */
static void bracket(const lub_mps_elastic_level *l, double x, int *a, double *f)
{
    if (l->nw == 1 || x <= l->xw[0]) {
        *a = 0, *f = 0.0;
        return;
    }
    if (x >= l->xw[l->nw - 1]) {
        *a = l->nw - 2, *f = 1.0;
        return;
    }
    int lo = 0, hi = l->nw - 1; /* xw[lo] <= x < xw[hi] */
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (l->xw[mid] <= x)
            lo = mid;
        else
            hi = mid;
    }
    *a = lo;
    *f = (x - l->xw[lo]) / (l->xw[lo + 1] - l->xw[lo]);
}

/* The displacement of a level interpolated at slot a, weight f (v: the level's targets). */
static inline double interp(const lub_mps_elastic_level *l, const double *v, int a, double f)
{
    return l->nw == 1 ? v[0] : (1.0 - f) * v[a] + f * v[a + 1];
}

/* The elasticWall entry of the start's uniform/state.yaml: 1 and the values, or 0. */
static int read_state(lub_mps_elastic *w, const char *path)
{
    lub_dict *d = w->state_dict = path ? lub_dict_read_optional(path) : NULL;
    if (!d) return 0;
    lub_node *root = lub_dict_root(d);
    lub_models_declare_state(root); /* the solver's and the other models' entries */
    lub_node *s = lub_dict_map_or(root, "elasticWall");
    if (s) {
        w->h0 = lub_dict_real(s, "h0", LUB_ANY);
        w->samples = lub_dict_int(s, "samples", 0, 1L << 62);
        w->target_mean = lub_dict_real(s, "loadTargetMean", LUB_NONNEGATIVE);
    }
    lub_dict_finish(d);
    lub_dict_free(d);
    w->state_dict = NULL;
    return s != NULL;
}

/* The patch's particles of one level: walls sorted by x into slots, then dummies, with the
 * maps from ids to slots. */
static void collect_level(lub_mps_elastic *w, int k)
{
    lub_mps_elastic_level *l = &w->lv[k];
    const lub_particles *P = l->m->P;
    const lub_elastic_wall *e = &w->e;
    int nw = 0, nd = 0;
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] != LUB_FLUID && P->patch[i] == w->patch) {
            nw += P->kind[i] == LUB_WALL;
            nd += P->kind[i] == LUB_DUMMY;
        }
    if (nw == 0 && (nd > 0 || w->nlevels == 1))
        lub_node_error(e->patch_node, "elasticWall: patch '%s' has no wall particles%s",
                       e->patch_name, w->nlevels > 1 ? " on a level that has dummy particles" : "");
    const int ns = nw + nd;
    patch_pt *pts = w->tmp_pts = lub_malloc((ns ? (size_t)ns : 1) * sizeof *pts);
    nw = nd = 0;
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] == LUB_WALL && P->patch[i] == w->patch)
            pts[nw++] = (patch_pt){P->x[0][i], P->id[i], i};
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] == LUB_DUMMY && P->patch[i] == w->patch)
            pts[nw + nd++] = (patch_pt){P->x[0][i], P->id[i], i};
    qsort(pts, (size_t)nw, sizeof *pts, pt_cmp);
    qsort(pts + nw, (size_t)nd, sizeof *pts, pt_cmp);
    l->nw = nw;
    l->nd = nd;
    const size_t m1 = ns ? (size_t)ns : 1, w1 = nw ? (size_t)nw : 1, d1 = nd ? (size_t)nd : 1;
    l->xw = lub_malloc(w1 * sizeof *l->xw);
    l->floor = lub_malloc(w1 * sizeof *l->floor);
    l->ids = lub_malloc(m1 * sizeof *l->ids);
    l->idx = lub_malloc(m1 * sizeof *l->idx);
    l->sorted_id = lub_malloc(m1 * sizeof *l->sorted_id);
    l->sorted_slot = lub_malloc(m1 * sizeof *l->sorted_slot);
    l->da = lub_malloc(d1 * sizeof *l->da);
    l->df = lub_malloc(d1 * sizeof *l->df);
    id_slot *is = w->tmp_ids = lub_malloc(m1 * sizeof *is);
    for (int s = 0; s < ns; s++) {
        l->ids[s] = pts[s].id;
        l->idx[s] = pts[s].i;
        is[s] = (id_slot){pts[s].id, s};
    }
    qsort(is, (size_t)ns, sizeof *is, id_cmp);
    for (int s = 0; s < ns; s++) {
        if (s > 0 && is[s].id == is[s - 1].id)
            lub_fatal("elasticWall: two particles of patch '%s' have the id %llu", e->patch_name,
                      (unsigned long long)is[s].id);
        l->sorted_id[s] = is[s].id;
        l->sorted_slot[s] = is[s].slot;
    }
    free(is);
    w->tmp_ids = NULL;
    for (int q = 0; q < nw; q++) l->xw[q] = pts[q].x;
    free(pts);
    w->tmp_pts = NULL;
}

typedef struct {
    double x;
    uint64_t id;
    int level, slot;
} seg_pt;

static int seg_cmp(const void *a, const void *b)
{
    const seg_pt *u = a, *v = b;
    if (u->x != v->x) return u->x < v->x ? -1 : 1;
    return (u->id > v->id) - (u->id < v->id);
}

/* The pressure segments (sources of the kernel): the wall slots whose x their level owns
 * (every slot in single resolution), sorted by x (ties by id), with their widths. */
static void segments(lub_mps_elastic *w, const lub_levels *L)
{
    const lub_elastic_wall *e = &w->e;
    seg_pt *pts = w->tmp_pts = lub_malloc((size_t)w->nw * sizeof *pts);
    int n = 0;
    for (int k = 0; k < w->nlevels; k++) {
        const lub_mps_elastic_level *l = &w->lv[k];
        for (int q = 0; q < l->nw; q++) {
            if (L) {
                lub_level_where where;
                lub_levels_locate(L, l->xw[q], &where);
                if (where.owner != k) continue;
            }
            pts[n++] = (seg_pt){l->xw[q], l->ids[q], k, q};
        }
    }
    if (n == 0)
        lub_node_error(e->patch_node,
                       "elasticWall: patch '%s' has no wall particles in the parts of x their "
                       "levels own",
                       e->patch_name);
    qsort(pts, (size_t)n, sizeof *pts, seg_cmp);
    w->ns = n;
    w->src_level = lub_malloc((size_t)n * sizeof *w->src_level);
    w->src_slot = lub_malloc((size_t)n * sizeof *w->src_slot);
    w->xs = lub_malloc((size_t)n * sizeof *w->xs);
    w->ws = lub_malloc((size_t)n * sizeof *w->ws);
    w->pw = lub_calloc((size_t)n, sizeof *w->pw);
    for (int s = 0; s < n; s++) {
        w->src_level[s] = pts[s].level;
        w->src_slot[s] = pts[s].slot;
        w->xs[s] = pts[s].x;
    }
    free(pts);
    w->tmp_pts = NULL;
    /* each level's own spacing inside its part, the half-way widths where two levels meet
     * (T-62..T-65: l_oj of the segment j; elastic.h) */
    if (lub_elastic_segment_widths(n, w->xs, w->l0, w->ws) != 0)
        lub_node_error(e->patch_node,
                       "elasticWall: two wall particles of patch '%s' share an x: the elastic "
                       "wall must be a graph y(x) with one wall layer",
                       e->patch_name);
}

/* The set-up; everything it allocates hangs on w, so that the init can free it when a fatal
 * error leaves in the middle (a test catching the error leaks nothing). */
static int init(lub_mps_elastic *w, lub_mps *const *ms, int nlevels, const lub_levels *L,
                const lub_geometry *g, const char *models_path, const char *state_path,
                double end_time, const char *end_what)
{
    lub_dict *d = w->dict = lub_dict_read_optional(models_path);
    if (!d) return 0;
    lub_node *root = lub_dict_root(d);
    lub_models_declare(root);
    if (!lub_elastic_wall_read(root, g, &w->e)) return 0;
    lub_dict_finish(d);
    lub_elastic_wall *e = &w->e;
    /* the name belongs to the geometry, which the caller may free */
    snprintf(w->patch_name, sizeof w->patch_name, "%s", e->patch_name);
    e->patch_name = w->patch_name;
    if (end_time > 0) lub_elastic_wall_check_ramp(e, end_time, end_what);

    w->nlevels = nlevels;
    w->patch = lub_particles_find_patch(ms[0]->P, e->patch_name);
    if (w->patch < 0)
        lub_node_error(e->patch_node,
                       "elasticWall: the particles have no patch '%s' (run particleGen after "
                       "adding the wall)",
                       e->patch_name);
    for (int k = 0; k < nlevels; k++) {
        lub_mps *m = ms[k];
        if (lub_particles_find_patch(m->P, e->patch_name) != w->patch)
            lub_bug("elasticWall: patch '%s' has another index on level %d", e->patch_name, k);
        const double *vel = m->c.patch_velocity[w->patch];
        if (vel[0] != 0.0 || vel[1] != 0.0 || vel[2] != 0.0)
            lub_node_error(e->patch_node,
                           "elasticWall: patch '%s' moves (movingWalls gives it (%g, %g) m/s), "
                           "but the elastic cylinder is at rest: its particles move only "
                           "vertically, with the load balance and the deformation",
                           e->patch_name, vel[0], vel[1]);
        w->lv[k].m = m;
        w->lv[k].l0 = m->l0;
    }
    w->l0 = ms[0]->l0;
    w->weight = lub_mps_elastic_mean_weight(e->average_steps);

    /* the patch's particles of each level; the targets: every wall slot, level by level */
    w->nw = w->nd = 0;
    for (int k = 0; k < nlevels; k++) {
        collect_level(w, k);
        w->lv[k].t0 = w->nw;
        w->nw += w->lv[k].nw;
        w->nd += w->lv[k].nd;
    }
    if (w->nw == 0)
        lub_node_error(e->patch_node, "elasticWall: patch '%s' has no wall particles",
                       e->patch_name);
    w->xt = lub_malloc((size_t)w->nw * sizeof *w->xt);
    w->v = lub_calloc((size_t)w->nw, sizeof *w->v);
    for (int k = 0; k < nlevels; k++)
        memcpy(w->xt + w->lv[k].t0, w->lv[k].xw, (size_t)w->lv[k].nw * sizeof *w->xt);
    segments(w, L);

    /* surfaces beneath; the reference y_f + h0^0 = the lowest point */
    if (!lub_elastic_floor(g, e, e->x_centre, &w->y_floor)) w->y_floor = e->y_lowest - e->h0;
    for (int k = 0; k < nlevels; k++) {
        lub_mps_elastic_level *l = &w->lv[k];
        const lub_particles *P = l->m->P;
        for (int q = 0; q < l->nw; q++)
            if (!lub_elastic_floor(g, e, l->xw[q], &l->floor[q])) l->floor[q] = -INFINITY;
        for (int q = 0; q < l->nd; q++)
            bracket(l, P->x[0][l->idx[l->nw + q]], &l->da[q], &l->df[q]);
    }
    w->lc = 0;
    if (L) {
        lub_level_where where;
        lub_levels_locate(L, e->x_centre, &where);
        w->lc = where.owner;
    }
    if (w->lv[w->lc].nw == 0) lub_bug("elasticWall: no wall particles on the level of x_c");
    bracket(&w->lv[w->lc], e->x_centre, &w->kc, &w->fc);

    w->K = lub_elastic_kernel_create(w->ns, w->xs, w->ws, w->nw, w->xt, e->E, e->b);

    /* state: a restart (fields and state entry) or a fresh start */
    const int had_shape = lub_particles_find_extra(ms[0]->P, LUB_ELASTIC_FIELD_SHAPE) != NULL;
    for (int k = 1; k < nlevels; k++)
        if ((lub_particles_find_extra(ms[k]->P, LUB_ELASTIC_FIELD_SHAPE) != NULL) != had_shape)
            lub_bug("elasticWall: the field elasticShape on some levels only");
    int restart = read_state(w, state_path);
    if (!had_shape != !restart)
        lub_fatal("elasticWall: %s", had_shape
                                         ? "the start time's particles carry the model's fields "
                                           "(elasticShape) but its uniform/state.yaml has no "
                                           "elasticWall entry: the state is incomplete"
                                         : "the start time's uniform/state.yaml has an "
                                           "elasticWall entry but its particles lack the field "
                                           "elasticShape: the state is incomplete");
    for (int k = 0; k < nlevels; k++) {
        lub_mps_elastic_level *l = &w->lv[k];
        l->shape = lub_particles_extra(l->m->P, LUB_ELASTIC_FIELD_SHAPE);
        l->mean = lub_particles_extra(l->m->P, LUB_ELASTIC_FIELD_MEAN);
    }
    if (!restart) {
        const double R = e->radius, xc = e->x_centre, yc = e->y_lowest + R;
        w->h0 = e->h0;
        w->samples = 0;
        w->target_mean = 0.0;
        for (int k = 0; k < nlevels; k++) {
            lub_mps_elastic_level *l = &w->lv[k];
            lub_particles *P = l->m->P;
            const int n = l->nw + l->nd;
            for (int s = 0; s < n; s++) {
                size_t i = l->idx[s];
                double dx = P->x[0][i] - xc;
                if (P->x[1][i] > yc || fabs(dx) >= R)
                    lub_node_error(e->patch_node,
                                   "elasticWall: patch '%s' reaches above the centre of its "
                                   "cylinder (particle at (%g, %g), centre y %g): T-50 describes "
                                   "the lower half; limit the arc with 'range' in "
                                   "system/particleGenDict.yaml",
                                   e->patch_name, P->x[0][i], P->x[1][i], yc);
                /* the undeformed shape: where particleGen put the particle, relative to the
                 * lowest point of the cylinder */
                l->shape[i] = P->x[1][i] - e->y_lowest;
                l->mean[i] = 0.0;
            }
            for (int s = 0; s < n; s++) {
                size_t i = l->idx[s];
                P->x[1][i] = w->y_floor + w->h0 + l->shape[i];
                for (int c = 0; c < 3; c++) P->u[c][i] = 0.0;
            }
            for (int q = 0; q < l->nw; q++) {
                double gap = P->x[1][l->idx[q]] - l->floor[q];
                if (gap < 0.5 * l->l0)
                    lub_node_error(e->node,
                                   "elasticWall: at h0 = %g m the wall particle at x = %g lies "
                                   "%g m above the surface beneath, less than l0/2 = %g m: h0 is "
                                   "where the undeformed wall starts (v = 0), the clearance, not "
                                   "the equilibrium position that reynoldsRef prints (which "
                                   "includes the elastic displacement and may be negative)",
                                   w->h0, l->xw[q], gap, 0.5 * l->l0);
            }
        }
    }
    for (int s = 0; s < w->ns; s++) {
        const lub_mps_elastic_level *l = &w->lv[w->src_level[s]];
        w->pw[s] = l->mean[l->idx[w->src_slot[s]]];
    }
    lub_elastic_displacement(w->K, w->pw, w->v);
    double vmin = INFINITY, vmax = -INFINITY, gmin = INFINITY;
    for (int k = 0; k < nlevels; k++) {
        lub_mps_elastic_level *l = &w->lv[k];
        l->m->c.patch_moved[w->patch] = 1;
        for (int q = 0; q < l->nw; q++) {
            vmin = fmin(vmin, w->v[l->t0 + q]);
            vmax = fmax(vmax, w->v[l->t0 + q]);
            gmin = fmin(gmin, l->m->P->x[1][l->idx[q]] - l->floor[q]);
        }
    }
    w->vmin = vmin, w->vmax = vmax, w->gap_min = gmin;
    const lub_mps_elastic_level *lc = &w->lv[w->lc];
    w->centre = w->h0 + interp(lc, w->v + lc->t0, w->kc, w->fc);
    figures(w, ms[0]->P->time);
    return 1;
}

static _Noreturn void reraise(int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    lub_vfatal_at(status, NULL, 0, 0, fmt, ap);
}

int lub_mps_elastic_init_levels(lub_mps_elastic *w, lub_mps *const *m, int nlevels,
                                const lub_levels *L, const lub_geometry *g, const char *models_path,
                                const char *state_path, double end_time, const char *end_what)
{
    memset(w, 0, sizeof *w);
    if (nlevels < 1 || nlevels > LUB_MAX_LEVELS || (nlevels > 1 && !L))
        lub_bug("lub_mps_elastic_init_levels: %d levels%s", nlevels, L ? "" : " without levels");
    lub_catcher c;
    if (lub_error_catch(&c) == 0) {
        int r = init(w, m, nlevels, L, g, models_path, state_path, end_time, end_what);
        lub_error_uncatch();
        if (!r) lub_mps_elastic_free(w);
        return r;
    }
    lub_mps_elastic_free(w);
    reraise(c.status, "%s", c.message); /* to the program (exit) or a test's catcher */
}

int lub_mps_elastic_init(lub_mps_elastic *w, lub_mps *m, const lub_geometry *g,
                         const char *models_path, const char *state_path, double end_time,
                         const char *end_what)
{
    return lub_mps_elastic_init_levels(w, &m, 1, NULL, g, models_path, state_path, end_time,
                                       end_what);
}

void lub_mps_elastic_free(lub_mps_elastic *w)
{
    if (!w) return;
    lub_elastic_kernel_free(w->K);
    for (int k = 0; k < LUB_MAX_LEVELS; k++) {
        lub_mps_elastic_level *l = &w->lv[k];
        free(l->xw);
        free(l->floor);
        free(l->ids);
        free(l->idx);
        free(l->sorted_id);
        free(l->sorted_slot);
        free(l->da);
        free(l->df);
    }
    free(w->src_level);
    free(w->src_slot);
    free(w->xs);
    free(w->ws);
    free(w->pw);
    free(w->xt);
    free(w->v);
    free(w->tmp_pts);
    free(w->tmp_ids);
    lub_dict_free(w->state_dict);
    lub_dict_free(w->dict);
    memset(w, 0, sizeof *w);
}

/* ---- the step ---------------------------------------------------------------------------- */

double lub_mps_elastic_mean_weight(long average_steps)
{
    return 2.0 / ((double)average_steps + 1.0);
}

double lub_mps_elastic_beta(const lub_mps_elastic *w)
{
    return w->load_target > 0.0 ? w->load / w->load_target - 1.0 : 0.0;
}

double lub_mps_elastic_balance_beta(const lub_mps_elastic *w)
{
    return w->target_mean > 0.0 ? w->load / w->target_mean - 1.0 : 0.0;
}

/* The mean wall pressure gathered by segment (w->pw), and its integral (each point of x on
 * the level that owns it). */
static double mean_load(lub_mps_elastic *w)
{
    double L = 0.0;
    for (int s = 0; s < w->ns; s++) {
        const lub_mps_elastic_level *l = &w->lv[w->src_level[s]];
        w->pw[s] = l->mean[l->idx[w->src_slot[s]]];
        L += w->pw[s] * w->ws[s];
    }
    return L;
}

lub_step_status lub_mps_elastic_before(lub_mps_elastic *w, double t, double dt, char *msg,
                                       size_t msgsize)
{
    refresh_maps(w);
    const double L = mean_load(w);
    /* T-51, T-52 against the load target averaged like the pressure (a ramp is no deficit) */
    const double dh0 = lub_elastic_dh0(&w->e, L, w->target_mean);
    lub_elastic_displacement(w->K, w->pw, w->v); /* T-46..T-49, T-62..T-65 */
    const lub_mps_elastic_level *lc = &w->lv[w->lc];
    const double vc = interp(lc, w->v + lc->t0, w->kc, w->fc);
    const double h0 = w->h0 + dh0;

    /* targets (T-50) and the crossing check, before anything changes: the closest approach,
     * and the wall particle nearest to crossing its level's l0/2 */
    const double base = w->y_floor + h0;
    double gmin = INFINITY, vmin = INFINITY, vmax = -INFINITY, worst = INFINITY;
    int kbad = 0, qbad = 0;
    for (int k = 0; k < w->nlevels; k++) {
        const lub_mps_elastic_level *l = &w->lv[k];
        for (int q = 0; q < l->nw; q++) {
            const double v = w->v[l->t0 + q];
            const double gap = base + l->shape[l->idx[q]] + v - l->floor[q];
            gmin = fmin(gmin, gap);
            if (gap - 0.5 * l->l0 < worst) worst = gap - 0.5 * l->l0, kbad = k, qbad = q;
            vmin = fmin(vmin, v);
            vmax = fmax(vmax, v);
        }
    }
    if (worst < 0) {
        const lub_mps_elastic_level *l = &w->lv[kbad];
        const double gap = worst + 0.5 * l->l0;
        char lev[32] = "";
        if (w->nlevels > 1) snprintf(lev, sizeof lev, " (level %d)", kbad);
        snprintf(msg, msgsize,
                 "elasticWall: at t = %.9g s the wall particle of '%s'%s at x = %g would come "
                 "within %g m of the surface beneath (less than l0/2 = %g m): h0 %g m, elastic "
                 "displacement %g m, mean load %g N/m of %g",
                 t, w->e.patch_name, lev, l->xw[qbad], gap, 0.5 * l->l0, h0, w->v[l->t0 + qbad], L,
                 w->target_mean);
        return LUB_STEP_ESCAPED;
    }
    w->h0 = h0;
    w->centre = h0 + vc;
    w->gap_min = gmin;
    w->vmin = vmin;
    w->vmax = vmax;

    /* velocities that carry the wall to its target in this step */
    const double rdt = 1.0 / dt;
    for (int k = 0; k < w->nlevels; k++) {
        const lub_mps_elastic_level *l = &w->lv[k];
        lub_particles *P = l->m->P;
        const double *v = w->v + l->t0;
        const int nw = l->nw, nd = l->nd;
#pragma omp parallel for schedule(static) if (nw + nd > 4096)
        for (int s = 0; s < nw + nd; s++) {
            size_t i = l->idx[s];
            double vs = s < nw ? v[s] : interp(l, v, l->da[s - nw], l->df[s - nw]);
            double y = base + l->shape[i] + vs;
            P->u[0][i] = 0.0;
            P->u[1][i] = (y - P->x[1][i]) * rdt;
            P->u[2][i] = 0.0;
        }
    }
    return LUB_STEP_OK;
}

/* Load figures of the current mean and wall pressure at time t. */
static void figures(lub_mps_elastic *w, double t)
{
    double inst = 0.0;
    for (int s = 0; s < w->ns; s++) {
        const lub_mps_elastic_level *l = &w->lv[w->src_level[s]];
        inst += l->m->P->p[l->idx[w->src_slot[s]]] * w->ws[s];
    }
    w->load_instant = inst;
    w->load = mean_load(w);
    w->load_target = lub_elastic_load_at(&w->e, t);
}

/* w->inside: the fluid particles of every level more than l0/4 above the level's wall layer
 * (the wall slots sorted by x, at their current heights; linear between them, which lies
 * above the arc, as the chord of a circle's lower side does); the first one found, at the
 * first time any is, into inside_t, inside_x, inside_id */
static void count_inside(lub_mps_elastic *w, double t)
{
    long total = 0;
    for (int k = 0; k < w->nlevels; k++) {
        const lub_mps_elastic_level *l = &w->lv[k];
        const lub_particles *P = l->m->P;
        const int nw = l->nw;
        if (nw < 2) continue;
        const double margin = 0.25 * l->m->l0;
        long c = 0;
        size_t first = (size_t)-1;
#pragma omp parallel for schedule(static) reduction(+ : c) reduction(min : first)
        for (size_t i = 0; i < P->n; i++) {
            const double x = P->x[0][i];
            if (P->kind[i] != LUB_FLUID || x < l->xw[0] || x > l->xw[nw - 1]) continue;
            int a;
            double f;
            bracket(l, x, &a, &f);
            const double ya = P->x[1][l->idx[a]], yb = P->x[1][l->idx[a + 1]];
            const double y = ya + (yb - ya) * f;
            if (P->x[1][i] > y + margin) {
                c++;
                if (i < first) first = i;
            }
        }
        if (c > 0 && w->inside_max == 0 && total == 0) {
            w->inside_t = t;
            w->inside_x[0] = P->x[0][first], w->inside_x[1] = P->x[1][first];
            w->inside_id = P->id[first];
        }
        total += c;
    }
    w->inside = total;
    if (total > w->inside_max) w->inside_max = total;
}

void lub_mps_elastic_after(lub_mps_elastic *w, double t)
{
    refresh_maps(w);
    const double a = w->weight;
    w->samples++;
    w->target_mean += a * (lub_elastic_load_at(&w->e, t) - w->target_mean);
    for (int k = 0; k < w->nlevels; k++) {
        lub_mps_elastic_level *l = &w->lv[k];
        const double *p = l->m->P->p;
        for (int q = 0; q < l->nw; q++) {
            size_t i = l->idx[q];
            l->mean[i] += a * (p[i] - l->mean[i]);
        }
    }
    figures(w, t);
    const long before = w->inside_max;
    count_inside(w, t);
    if (before == 0 && w->inside > 0)
        lub_warning("elasticWall: at t = %.6g s fluid particle id %llu is inside the cylinder "
                    "'%s', at (%.6g, %.6g), more than l0/4 above its wall layer (%ld in all): "
                    "the oil flows round an open end of the arc (a periodic seam where its "
                    "ends do not meet, or the end of its range) and is lost to the film",
                    w->inside_t, (unsigned long long)w->inside_id, w->patch_name, w->inside_x[0],
                    w->inside_x[1], w->inside);
}

void lub_mps_elastic_write_state(const lub_mps_elastic *w, FILE *fp)
{
    fprintf(fp, "elasticWall:\n");
    fprintf(fp, "  h0:      %.17g   # rigid-body position of T-50 [m]\n", w->h0);
    fprintf(fp, "  samples: %ld   # wall pressures in the running mean pWallMean\n", w->samples);
    fprintf(fp, "  loadTargetMean: %.17g   # the load W(t) averaged like the pressure [N/m]\n",
            w->target_mean);
}
