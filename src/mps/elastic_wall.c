/* lubkit MPS: the elasticWall model in the particle solver (see elastic_wall.h). */
#include "mps/elastic_wall.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "models/models.h"

static void figures(lub_mps_elastic *w, const lub_particles *P, double t);

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

/* Slot of particle id, or -1. */
static int find_slot(const lub_mps_elastic *w, uint64_t id)
{
    int lo = 0, hi = w->nw + w->nd - 1;
    while (lo <= hi) {
        int mid = lo + (hi - lo) / 2;
        uint64_t s = w->sorted_id[mid];
        if (s == id) return w->sorted_slot[mid];
        if (s < id)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}

/* Particle index of every slot, after the solver reordered the particles.  Checking the
 * ids costs O(nw + nd); the map is rebuilt only when they moved. */
static void refresh_map(lub_mps_elastic *w, const lub_particles *P)
{
    const int n = w->nw + w->nd;
    int same = 1;
    for (int s = 0; s < n && same; s++) same = w->idx[s] < P->n && P->id[w->idx[s]] == w->ids[s];
    if (same) return;
    int found = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] == LUB_FLUID || P->patch[i] != w->patch) continue;
        int s = find_slot(w, P->id[i]);
        if (s < 0)
            lub_bug("elasticWall: particle id %llu joined the patch", (unsigned long long)P->id[i]);
        w->idx[s] = i;
        found++;
    }
    if (found != n) lub_bug("elasticWall: %d of %d patch particles found", found, n);
}

/* Linear interpolation position of x among the sorted wall slots: slot *a and weight *f of
 * slot *a + 1 (clamped to the end slots). */
static void bracket(const lub_mps_elastic *w, double x, int *a, double *f)
{
    if (w->nw == 1 || x <= w->xw[0]) {
        *a = 0, *f = 0.0;
        return;
    }
    if (x >= w->xw[w->nw - 1]) {
        *a = w->nw - 2, *f = 1.0;
        return;
    }
    int lo = 0, hi = w->nw - 1; /* xw[lo] <= x < xw[hi] */
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (w->xw[mid] <= x)
            lo = mid;
        else
            hi = mid;
    }
    *a = lo;
    *f = (x - w->xw[lo]) / (w->xw[lo + 1] - w->xw[lo]);
}

static inline double interp(const lub_mps_elastic *w, const double *v, int a, double f)
{
    return w->nw == 1 ? v[0] : (1.0 - f) * v[a] + f * v[a + 1];
}

/* The elasticWall entry of the start's uniform/state.yaml: 1 and the values, or 0. */
static int read_state(lub_mps_elastic *w, const char *path)
{
    lub_dict *d = w->state_dict = path ? lub_dict_read_optional(path) : NULL;
    if (!d) return 0;
    lub_node *root = lub_dict_root(d);
    /* the solver's own entries (lubFoam reads them) */
    lub_dict_find(root, "time");
    lub_dict_find(root, "step");
    lub_dict_find(root, "deltaT");
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

/* The set-up; everything it allocates hangs on w, so that lub_mps_elastic_init can free it
 * when a fatal error leaves in the middle (a test catching the error leaks nothing). */
static int init(lub_mps_elastic *w, lub_mps *m, const lub_geometry *g, const char *models_path,
                const char *state_path, double end_time, const char *end_what)
{
    lub_particles *P = m->P;
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

    w->patch = lub_particles_find_patch(P, e->patch_name);
    if (w->patch < 0)
        lub_node_error(e->patch_node,
                       "elasticWall: the particles have no patch '%s' (run particleGen after "
                       "adding the wall)",
                       e->patch_name);
    const double *vel = m->c.patch_velocity[w->patch];
    if (vel[0] != 0.0 || vel[1] != 0.0 || vel[2] != 0.0)
        lub_node_error(e->patch_node,
                       "elasticWall: patch '%s' moves (movingWalls gives it (%g, %g) m/s), but "
                       "the elastic cylinder is at rest: its particles move only vertically, "
                       "with the load balance and the deformation",
                       e->patch_name, vel[0], vel[1]);
    w->l0 = m->l0;
    w->weight = lub_mps_elastic_mean_weight(e->average_steps);

    /* the patch's particles: walls sorted by x, then dummies */
    int nw = 0, nd = 0;
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] != LUB_FLUID && P->patch[i] == w->patch) {
            nw += P->kind[i] == LUB_WALL;
            nd += P->kind[i] == LUB_DUMMY;
        }
    if (nw == 0)
        lub_node_error(e->patch_node, "elasticWall: patch '%s' has no wall particles",
                       e->patch_name);
    patch_pt *pts = w->tmp_pts = lub_malloc((size_t)(nw + nd) * sizeof *pts);
    nw = nd = 0;
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] == LUB_WALL && P->patch[i] == w->patch)
            pts[nw++] = (patch_pt){P->x[0][i], P->id[i], i};
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] == LUB_DUMMY && P->patch[i] == w->patch)
            pts[nw + nd++] = (patch_pt){P->x[0][i], P->id[i], i};
    qsort(pts, (size_t)nw, sizeof *pts, pt_cmp);
    qsort(pts + nw, (size_t)nd, sizeof *pts, pt_cmp);
    w->nw = nw;
    w->nd = nd;
    const int ns = nw + nd;
    w->xw = lub_malloc((size_t)nw * sizeof *w->xw);
    w->ww = lub_malloc((size_t)nw * sizeof *w->ww);
    w->floor = lub_malloc((size_t)nw * sizeof *w->floor);
    w->pw = lub_calloc((size_t)nw, sizeof *w->pw);
    w->v = lub_calloc((size_t)nw, sizeof *w->v);
    w->ids = lub_malloc((size_t)ns * sizeof *w->ids);
    w->idx = lub_malloc((size_t)ns * sizeof *w->idx);
    w->sorted_id = lub_malloc((size_t)ns * sizeof *w->sorted_id);
    w->sorted_slot = lub_malloc((size_t)ns * sizeof *w->sorted_slot);
    w->da = lub_malloc((nd ? (size_t)nd : 1) * sizeof *w->da);
    w->df = lub_malloc((nd ? (size_t)nd : 1) * sizeof *w->df);
    id_slot *is = w->tmp_ids = lub_malloc((size_t)ns * sizeof *is);
    for (int s = 0; s < ns; s++) {
        w->ids[s] = pts[s].id;
        w->idx[s] = pts[s].i;
        is[s] = (id_slot){pts[s].id, s};
    }
    qsort(is, (size_t)ns, sizeof *is, id_cmp);
    for (int s = 0; s < ns; s++) {
        if (s > 0 && is[s].id == is[s - 1].id)
            lub_fatal("elasticWall: two particles of patch '%s' have the id %llu", e->patch_name,
                      (unsigned long long)is[s].id);
        w->sorted_id[s] = is[s].id;
        w->sorted_slot[s] = is[s].slot;
    }
    free(is);
    w->tmp_ids = NULL;
    for (int k = 0; k < nw; k++) w->xw[k] = pts[k].x;
    free(pts);
    w->tmp_pts = NULL;
    if (lub_elastic_segment_widths(nw, w->xw, w->l0, w->ww) != 0)
        lub_node_error(e->patch_node,
                       "elasticWall: two wall particles of patch '%s' share an x: the elastic "
                       "wall must be a graph y(x) with one wall layer",
                       e->patch_name);

    /* surfaces beneath; the reference y_f + h0^0 = the lowest point */
    if (!lub_elastic_floor(g, e, e->x_centre, &w->y_floor)) w->y_floor = e->y_lowest - e->h0;
    for (int k = 0; k < nw; k++)
        if (!lub_elastic_floor(g, e, w->xw[k], &w->floor[k])) w->floor[k] = -INFINITY;
    for (int q = 0; q < nd; q++) bracket(w, P->x[0][w->idx[nw + q]], &w->da[q], &w->df[q]);
    bracket(w, e->x_centre, &w->kc, &w->fc);

    w->K = lub_elastic_kernel_create(nw, w->xw, w->ww, nw, w->xw, e->E, e->b);

    /* state: a restart (fields and state entry) or a fresh start */
    const double *had_shape = lub_particles_find_extra(P, LUB_ELASTIC_FIELD_SHAPE);
    int restart = read_state(w, state_path);
    if (!had_shape != !restart)
        lub_fatal("elasticWall: %s", had_shape
                                         ? "the start time's particles carry the model's fields "
                                           "(elasticShape) but its uniform/state.yaml has no "
                                           "elasticWall entry: the state is incomplete"
                                         : "the start time's uniform/state.yaml has an "
                                           "elasticWall entry but its particles lack the field "
                                           "elasticShape: the state is incomplete");
    w->shape = lub_particles_extra(P, LUB_ELASTIC_FIELD_SHAPE);
    w->mean = lub_particles_extra(P, LUB_ELASTIC_FIELD_MEAN);
    if (!restart) {
        const double R = e->radius, xc = e->x_centre, yc = e->y_lowest + R;
        for (int s = 0; s < ns; s++) {
            size_t i = w->idx[s];
            double dx = P->x[0][i] - xc;
            if (P->x[1][i] > yc || fabs(dx) >= R)
                lub_node_error(e->patch_node,
                               "elasticWall: patch '%s' reaches above the centre of its "
                               "cylinder (particle at (%g, %g), centre y %g): T-50 describes the "
                               "lower half; limit the arc with 'range' in "
                               "system/particleGenDict.yaml",
                               e->patch_name, P->x[0][i], P->x[1][i], yc);
            /* the undeformed shape: where particleGen put the particle, relative to the
             * lowest point of the cylinder */
            w->shape[i] = P->x[1][i] - e->y_lowest;
            w->mean[i] = 0.0;
        }
        w->h0 = e->h0;
        w->samples = 0;
        w->target_mean = 0.0;
        for (int s = 0; s < ns; s++) {
            size_t i = w->idx[s];
            P->x[1][i] = w->y_floor + w->h0 + w->shape[i];
            for (int c = 0; c < 3; c++) P->u[c][i] = 0.0;
        }
        for (int k = 0; k < nw; k++) {
            double gap = P->x[1][w->idx[k]] - w->floor[k];
            if (gap < 0.5 * w->l0)
                lub_node_error(e->node,
                               "elasticWall: at h0 = %g m the wall particle at x = %g lies %g m "
                               "above the surface beneath, less than l0/2 = %g m: h0 is where "
                               "the undeformed wall starts (v = 0), the clearance, not the "
                               "equilibrium position that reynoldsRef prints (which includes "
                               "the elastic displacement and may be negative)",
                               w->h0, w->xw[k], gap, 0.5 * w->l0);
        }
    }
    for (int k = 0; k < nw; k++) w->pw[k] = w->mean[w->idx[k]];
    lub_elastic_displacement(w->K, w->pw, w->v);
    m->c.patch_moved[w->patch] = 1;
    double vmin = INFINITY, vmax = -INFINITY, gmin = INFINITY;
    for (int k = 0; k < nw; k++) {
        vmin = fmin(vmin, w->v[k]);
        vmax = fmax(vmax, w->v[k]);
        gmin = fmin(gmin, P->x[1][w->idx[k]] - w->floor[k]);
    }
    w->vmin = vmin, w->vmax = vmax, w->gap_min = gmin;
    w->centre = w->h0 + interp(w, w->v, w->kc, w->fc);
    figures(w, P, P->time);
    return 1;
}

static _Noreturn void reraise(int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    lub_vfatal_at(status, NULL, 0, 0, fmt, ap);
}

int lub_mps_elastic_init(lub_mps_elastic *w, lub_mps *m, const lub_geometry *g,
                         const char *models_path, const char *state_path, double end_time,
                         const char *end_what)
{
    memset(w, 0, sizeof *w);
    lub_catcher c;
    if (lub_error_catch(&c) == 0) {
        int r = init(w, m, g, models_path, state_path, end_time, end_what);
        lub_error_uncatch();
        if (!r) lub_mps_elastic_free(w);
        return r;
    }
    lub_mps_elastic_free(w);
    reraise(c.status, "%s", c.message); /* to the program (exit) or a test's catcher */
}

void lub_mps_elastic_free(lub_mps_elastic *w)
{
    if (!w) return;
    lub_elastic_kernel_free(w->K);
    free(w->xw);
    free(w->ww);
    free(w->floor);
    free(w->pw);
    free(w->v);
    free(w->ids);
    free(w->idx);
    free(w->sorted_id);
    free(w->sorted_slot);
    free(w->da);
    free(w->df);
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

/* The mean wall pressure gathered by slot (w->pw), and its integral. */
static double mean_load(lub_mps_elastic *w)
{
    double L = 0.0;
    for (int k = 0; k < w->nw; k++) {
        w->pw[k] = w->mean[w->idx[k]];
        L += w->pw[k] * w->ww[k];
    }
    return L;
}

lub_step_status lub_mps_elastic_before(lub_mps_elastic *w, lub_mps *m, double t, double dt,
                                       char *msg, size_t msgsize)
{
    lub_particles *P = m->P;
    refresh_map(w, P);
    const double L = mean_load(w);
    /* T-51, T-52 against the load target averaged like the pressure (a ramp is no deficit) */
    const double dh0 = lub_elastic_dh0(&w->e, L, w->target_mean);
    lub_elastic_displacement(w->K, w->pw, w->v); /* T-46..T-49 */
    const double vc = interp(w, w->v, w->kc, w->fc);
    const double h0 = w->h0 + dh0;

    /* targets (T-50) and the crossing check, before anything changes */
    const double base = w->y_floor + h0;
    double gmin = INFINITY, vmin = INFINITY, vmax = -INFINITY;
    int kmin = 0;
    for (int k = 0; k < w->nw; k++) {
        double gap = base + w->shape[w->idx[k]] + w->v[k] - w->floor[k];
        if (gap < gmin) gmin = gap, kmin = k;
        vmin = fmin(vmin, w->v[k]);
        vmax = fmax(vmax, w->v[k]);
    }
    if (gmin < 0.5 * w->l0) {
        snprintf(msg, msgsize,
                 "elasticWall: at t = %.9g s the wall particle of '%s' at x = %g would come "
                 "within %g m of the surface beneath (less than l0/2 = %g m): h0 %g m, elastic "
                 "displacement %g m, mean load %g N/m of %g",
                 t, w->e.patch_name, w->xw[kmin], gmin, 0.5 * w->l0, h0, w->v[kmin], L,
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
    const int nw = w->nw, nd = w->nd;
#pragma omp parallel for schedule(static) if (nw + nd > 4096)
    for (int s = 0; s < nw + nd; s++) {
        size_t i = w->idx[s];
        double v = s < nw ? w->v[s] : interp(w, w->v, w->da[s - nw], w->df[s - nw]);
        double y = base + w->shape[i] + v;
        P->u[0][i] = 0.0;
        P->u[1][i] = (y - P->x[1][i]) * rdt;
        P->u[2][i] = 0.0;
    }
    return LUB_STEP_OK;
}

/* Load figures of the current mean and wall pressure at time t. */
static void figures(lub_mps_elastic *w, const lub_particles *P, double t)
{
    double inst = 0.0;
    for (int k = 0; k < w->nw; k++) inst += P->p[w->idx[k]] * w->ww[k];
    w->load_instant = inst;
    w->load = mean_load(w);
    w->load_target = lub_elastic_load_at(&w->e, t);
}

void lub_mps_elastic_after(lub_mps_elastic *w, lub_mps *m, double t)
{
    const lub_particles *P = m->P;
    refresh_map(w, P);
    const double a = w->weight;
    w->samples++;
    w->target_mean += a * (lub_elastic_load_at(&w->e, t) - w->target_mean);
    for (int k = 0; k < w->nw; k++) {
        size_t i = w->idx[k];
        w->mean[i] += a * (P->p[i] - w->mean[i]);
    }
    figures(w, P, t);
}

void lub_mps_elastic_write_state(const lub_mps_elastic *w, FILE *fp)
{
    fprintf(fp, "elasticWall:\n");
    fprintf(fp, "  h0:      %.17g   # rigid-body position of T-50 [m]\n", w->h0);
    fprintf(fp, "  samples: %ld   # wall pressures in the running mean pWallMean\n", w->samples);
    fprintf(fp, "  loadTargetMean: %.17g   # the load W(t) averaged like the pressure [N/m]\n",
            w->target_mean);
}
