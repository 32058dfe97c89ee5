/* lubkit elasticWall model: reader, load balance and influence coefficients (see elastic.h). */
#include "models/elastic.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---- reader ------------------------------------------------------------------------------ */

/* Fatal at node: name is not a wall of g (with the list and a did-you-mean). */
static _Noreturn void not_a_wall(const lub_node *node, const lub_geometry *g, const char *name)
{
    char list[1024] = "";
    size_t len = 0;
    const char *names[256] = {0};
    int nn = g->nwalls < 256 ? g->nwalls : 256;
    for (int k = 0; k < nn; k++) {
        names[k] = g->walls[k].name;
        if (len < sizeof list)
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", k ? ", " : "", names[k]);
    }
    const char *near = lub_closest(name, names, (size_t)nn);
    if (near)
        lub_node_error(node,
                       "elasticWall: patch '%s' is not a wall of the geometry (did you mean "
                       "'%s'? walls: %s)",
                       name, near, list);
    lub_node_error(node, "elasticWall: patch '%s' is not a wall of the geometry (walls: %s)", name,
                   nn ? list : "none");
}

static const char *wall_type_name(lub_wall_type t)
{
    static const char *const names[] = {"plane", "segment", "cylinder", "polyline",
                                        "box",   "sphere",  "polygon"};
    return (int)t >= 0 && (int)t < 7 ? names[t] : "wall";
}

/* h0^0 from the geometry: the lowest point of the cylinder above the highest surface of the
 * other walls beneath it.  Returns 0 when no wall lies beneath. */
static int h0_from_geometry(const lub_geometry *g, const lub_elastic_wall *e, double *h0)
{
    double y;
    if (!lub_elastic_floor(g, e, e->x_centre, &y)) return 0;
    *h0 = e->y_lowest - y;
    return 1;
}

int lub_elastic_floor(const lub_geometry *g, const lub_elastic_wall *e, double x, double *y)
{
    double best = -INFINITY;
    double slack = 1e-12 * fmax(e->radius, fabs(e->y_lowest));
    for (int w = 0; w < g->nwalls; w++) {
        double yw;
        if (w == e->patch || !lub_wall_height(&g->walls[w], x, 0, &yw)) continue;
        if (yw <= e->y_lowest + slack && yw > best) best = yw;
    }
    if (!(best > -INFINITY)) return 0;
    *y = best;
    return 1;
}

int lub_elastic_segment_widths(int n, const double *x, double fallback, double *w)
{
    for (int k = 1; k < n; k++)
        if (!(x[k] > x[k - 1])) return -1;
    if (n == 1) w[0] = fallback;
    if (n < 2) return 0;
    w[0] = x[1] - x[0];
    w[n - 1] = x[n - 1] - x[n - 2];
    for (int k = 1; k < n - 1; k++) w[k] = 0.5 * (x[k + 1] - x[k - 1]);
    return 0;
}

int lub_elastic_wall_read(lub_node *root, const lub_geometry *g, lub_elastic_wall *e)
{
    memset(e, 0, sizeof *e);
    lub_node *ew = lub_dict_map_or(root, "elasticWall");
    if (!ew) return 0;
    e->node = ew;

    lub_node *pn = lub_dict_get(ew, "patch");
    e->patch_node = pn;
    const char *name = lub_dict_str(ew, "patch");
    e->patch = lub_geometry_find_wall(g, name);
    if (e->patch < 0) not_a_wall(pn, g, name);
    const lub_wall *w = &g->walls[e->patch];
    e->patch_name = w->name;
    if (w->type != LUB_WALL_CYLINDER || g->dim != 2 || w->fluid_inside)
        lub_node_error(pn,
                       "elasticWall: patch '%s' must be a 2-D cylinder with the fluid outside "
                       "(the ball of T-50, y = h0 + x^2/(2R) + v), but it is a %s%s%s",
                       name, g->dim != 2 ? "3-D " : "", wall_type_name(w->type),
                       w->type == LUB_WALL_CYLINDER && w->fluid_inside ? " with the fluid inside"
                                                                       : "");
    e->radius = w->radius;
    e->x_centre = w->centre[0];
    e->y_lowest = w->centre[1] - w->radius;

    e->E = lub_dict_real(ew, "E", LUB_POSITIVE);
    e->load = lub_dict_real(ew, "load", LUB_POSITIVE);
    e->ramp_node = lub_dict_find(ew, "rampTime");
    e->ramp_time = lub_dict_real_or(ew, "rampTime", 0.0, LUB_NONNEGATIVE);
    e->relaxation = lub_dict_real_or(ew, "relaxation", 5e-6, (lub_range){0.0, 1.0, 1, 0});
    e->clamp = lub_dict_real_or(ew, "clamp", 0.2, LUB_POSITIVE);
    e->average_steps = lub_dict_int_or(ew, "averageSteps", 1000, 1, 1000000000L);
    lub_node *hn = lub_dict_find(ew, "h0");
    if (hn) {
        e->h0 = lub_node_real(hn, LUB_POSITIVE);
    } else if (!h0_from_geometry(g, e, &e->h0)) {
        lub_node_error(ew,
                       "elasticWall: no wall lies beneath the lowest point (%g, %g) of '%s', so "
                       "the initial position h0 cannot be taken from the geometry: give 'h0'",
                       e->x_centre, e->y_lowest, name);
    }
    e->b = lub_elastic_hertz_half_width(e->load, e->radius, e->E);
    e->p_hertz = lub_elastic_hertz_pressure(e->load, e->b);
    return 1;
}

void lub_elastic_wall_check_ramp(const lub_elastic_wall *e, double end_time, const char *what)
{
    if (e->ramp_time > end_time)
        lub_node_error(e->ramp_node ? e->ramp_node : e->node,
                       "elasticWall: the load ramp (rampTime %g s) is longer than the run (%s)",
                       e->ramp_time, what);
}

double lub_elastic_load_at(const lub_elastic_wall *e, double t)
{
    if (e->ramp_time > 0.0 && t < e->ramp_time) return e->load * fmax(t, 0.0) / e->ramp_time;
    return e->load;
}

double lub_elastic_dh0(const lub_elastic_wall *e, double integral, double load)
{
    double s; /* beta / clamp, saturated (T-51, T-52) */
    if (load > 0.0) {
        s = (integral / load - 1.0) / e->clamp;
        s = s > 1.0 ? 1.0 : s < -1.0 ? -1.0 : s;
    } else {
        s = integral > 0.0 ? 1.0 : 0.0;
    }
    return e->relaxation * e->h0 * s;
}

double lub_elastic_hertz_half_width(double load, double radius, double E)
{
    return sqrt(8.0 * load * radius / (M_PI * E));
}

double lub_elastic_hertz_pressure(double load, double b)
{
    return 2.0 * load / (M_PI * b);
}

/* ---- influence coefficients -------------------------------------------------------------- */

double lub_elastic_a(double K)
{
    if (K >= 1.0) {
        /* (K+1/2) ln(K+1/2) - (K-1/2) ln(K-1/2) - 1 with ln(K +- 1/2) = ln K + ln(1 +- z):
         * ln K + z^-1 atanh(z) - 1 + ln(1 - z^2)/2, free of the cancellation of large terms */
        double z = 0.5 / K;
        return log(K) + (atanh(z) / z - 1.0) + 0.5 * log1p(-z * z);
    }
    double ap = K + 0.5, am = fabs(K - 0.5);
    double tm = am > 0.0 ? (K - 0.5) * (log(am) - 1.0) : 0.0; /* x (ln|x| - 1) -> 0 */
    return ap * (log(ap) - 1.0) - tm;
}

double lub_elastic_coefficient(double d, double l, double E, double b)
{
    return -4.0 / (M_PI * E) * l * (lub_elastic_a(fabs(d) / l) + log(l / b));
}

void lub_elastic_displacement_direct(int ns, const double *xs, const double *ls, int nt,
                                     const double *xt, double E, double b, const double *p,
                                     double *v)
{
    for (int i = 0; i < nt; i++) {
        double s = 0.0;
        for (int j = 0; j < ns; j++)
            s += lub_elastic_coefficient(xt[i] - xs[j], ls[j], E, b) * p[j];
        v[i] = s;
    }
}

/* A run: sorted points start .. start + n - 1; uniform (dx > 0) on x0 + k dx with width l
 * (segments), or irregular (dx = 0). */
typedef struct {
    int start, n;
    double x0, dx, l;
} run_t;

/* A block: target run tr, source run sr; Toeplitz (c[j - i + nt_r - 1]) or dense (c[i ns_s +
 * j]) or, with c == NULL, computed on the fly. */
typedef struct {
    int tr, sr, toeplitz;
    double *c;
} block_t;

struct lub_elastic_kernel {
    int ns, nt;
    double E, b;
    int *ps, *pt;    /* sorted position -> caller index */
    double *xs, *ls; /* sources, sorted */
    double *xt;      /* targets, sorted */
    run_t *rs, *rt;
    int nrs, nrt;
    block_t *blocks;
    int nblocks;
    double *wp, *wv; /* workspace: gathered pressure, sorted displacement */
    lub_elastic_kernel_info info;
};

/* Indices sorted by x (ties by index, so the order is deterministic). */
typedef struct {
    double x;
    int i;
} sort_key;

static int key_cmp(const void *a, const void *b)
{
    const sort_key *u = a, *v = b;
    if (u->x < v->x) return -1;
    if (u->x > v->x) return 1;
    return (u->i > v->i) - (u->i < v->i);
}

static int *sort_index(int n, const double *x)
{
    sort_key *k = lub_malloc((size_t)n * sizeof *k);
    for (int i = 0; i < n; i++) k[i] = (sort_key){x[i], i};
    qsort(k, (size_t)n, sizeof *k, key_cmp);
    int *perm = lub_malloc((size_t)n * sizeof *perm);
    for (int i = 0; i < n; i++) perm[i] = k[i].i;
    free(k);
    return perm;
}

static const double run_tol = 1e-9; /* of the spacing */
static size_t dense_max = (size_t)256 << 20;

size_t lub_elastic_dense_max(void)
{
    return dense_max;
}
void lub_elastic_set_dense_max(size_t bytes)
{
    dense_max = bytes;
}
enum { MIN_RUN = 8 }; /* shorter uniform stretches join an irregular run */

/* Points k..k+m-1 lie on x_k + q dx, dx = (x_last - x_k)/(m - 1), to run_tol dx? */
static int on_lattice(const double *x, int k, int m, double *dx)
{
    *dx = (x[k + m - 1] - x[k]) / (m - 1);
    if (!(*dx > 0.0)) return 0;
    for (int q = 1; q < m - 1; q++)
        if (fabs(x[k + q] - (x[k] + q * *dx)) > run_tol * *dx) return 0;
    return 1;
}

/* Split sorted points into runs: uniform runs (at least MIN_RUN points on a lattice of
 * constant spacing, and of constant width when l != NULL), and irregular runs (the points in
 * between, any spacing).  A uniform candidate grows while consecutive spacings (and widths)
 * agree; if the fitted lattice does not hold all its points (slow drift) it is halved until it
 * does or is too short.  Returns the run count; *runs allocated. */
static int find_runs(int n, const double *x, const double *l, run_t **runs)
{
    run_t *r = lub_malloc((size_t)n * sizeof *r);
    int nr = 0, k = 0, irr = -1; /* irr: start of the pending irregular run */
    while (k < n) {
        int e = k + 1;
        if (e < n && x[e] > x[k] && (!l || fabs(l[e] - l[k]) <= 1e-12 * l[k])) {
            double s = x[e] - x[k];
            for (e++; e < n && fabs(x[e] - x[e - 1] - s) <= run_tol * s &&
                      (!l || fabs(l[e] - l[k]) <= 1e-12 * l[k]);
                 e++)
                ;
        }
        int m = e - k;
        double dx = 0.0;
        while (m >= MIN_RUN && !on_lattice(x, k, m, &dx)) m /= 2;
        if (m < MIN_RUN) {
            if (irr < 0) irr = k;
            k++;
            continue;
        }
        if (irr >= 0) r[nr++] = (run_t){irr, k - irr, x[irr], 0.0, 0.0};
        irr = -1;
        r[nr++] = (run_t){k, m, x[k], dx, l ? l[k] : 0.0};
        k += m;
    }
    if (irr >= 0) r[nr++] = (run_t){irr, n - irr, x[irr], 0.0, 0.0};
    *runs = r;
    return nr;
}

lub_elastic_kernel *lub_elastic_kernel_create(int ns, const double *xs, const double *ls, int nt,
                                              const double *xt, double E, double b)
{
    if (ns < 1 || nt < 1 || !(E > 0.0) || !(b > 0.0) || !xs || !ls || !xt)
        lub_bug("elastic kernel: bad arguments (ns %d, nt %d, E %g, b %g)", ns, nt, E, b);
    for (int j = 0; j < ns; j++)
        if (!(ls[j] > 0.0) || !isfinite(xs[j]))
            lub_bug("elastic kernel: segment %d has x %g, width %g", j, xs[j], ls[j]);
    for (int i = 0; i < nt; i++)
        if (!isfinite(xt[i])) lub_bug("elastic kernel: target %d at x %g", i, xt[i]);

    lub_elastic_kernel *k = lub_calloc(1, sizeof *k);
    k->ns = ns;
    k->nt = nt;
    k->E = E;
    k->b = b;
    k->ps = sort_index(ns, xs);
    k->pt = sort_index(nt, xt);
    k->xs = lub_malloc((size_t)ns * sizeof(double));
    k->ls = lub_malloc((size_t)ns * sizeof(double));
    k->xt = lub_malloc((size_t)nt * sizeof(double));
    for (int j = 0; j < ns; j++) {
        k->xs[j] = xs[k->ps[j]];
        k->ls[j] = ls[k->ps[j]];
    }
    for (int i = 0; i < nt; i++) k->xt[i] = xt[k->pt[i]];
    k->nrs = find_runs(ns, k->xs, k->ls, &k->rs);
    k->nrt = find_runs(nt, k->xt, NULL, &k->rt);
    k->wp = lub_malloc((size_t)ns * sizeof(double));
    k->wv = lub_malloc((size_t)nt * sizeof(double));

    /* blocks: Toeplitz where both runs have more than one point and the same spacing (to
     * run_tol over the block's extent), dense otherwise */
    k->nblocks = k->nrt * k->nrs;
    k->blocks = lub_calloc((size_t)k->nblocks, sizeof *k->blocks);
    size_t dense_bytes = 0, toep_bytes = 0;
    for (int a = 0; a < k->nrt; a++)
        for (int c = 0; c < k->nrs; c++) {
            const run_t *T = &k->rt[a], *S = &k->rs[c];
            block_t *B = &k->blocks[a * k->nrs + c];
            B->tr = a;
            B->sr = c;
            B->toeplitz = T->dx > 0.0 && S->dx > 0.0 &&
                          fabs(T->dx - S->dx) * (T->n + S->n) <= run_tol * fmin(T->dx, S->dx);
            if (B->toeplitz)
                toep_bytes += (size_t)(T->n + S->n - 1) * sizeof(double);
            else
                dense_bytes += (size_t)T->n * (size_t)S->n * sizeof(double);
        }
    int on_the_fly = dense_bytes > dense_max;
    int ntoep = 0, ndense = 0;
    for (int q = 0; q < k->nblocks; q++) {
        block_t *B = &k->blocks[q];
        const run_t *T = &k->rt[B->tr], *S = &k->rs[B->sr];
        if (B->toeplitz) {
            /* C(xt_i - xs_j) with xt_i - xs_j = (T.x0 - S.x0) - (j - i) dx, d = j - i */
            int len = T->n + S->n - 1;
            double dx = 0.5 * (T->dx + S->dx), off = T->x0 - S->x0;
            B->c = lub_malloc((size_t)len * sizeof(double));
            for (int m = 0; m < len; m++) {
                int d = m - (T->n - 1);
                B->c[m] = lub_elastic_coefficient(off - d * dx, S->l, E, b);
            }
            ntoep++;
        } else {
            ndense++;
            if (on_the_fly) continue;
            B->c = lub_malloc((size_t)T->n * (size_t)S->n * sizeof(double));
            for (int i = 0; i < T->n; i++)
                for (int j = 0; j < S->n; j++)
                    B->c[(size_t)i * S->n + j] = lub_elastic_coefficient(
                        k->xt[T->start + i] - k->xs[S->start + j], k->ls[S->start + j], E, b);
        }
    }
    k->info = (lub_elastic_kernel_info){
        k->nrt, k->nrs, ntoep, ndense, on_the_fly, toep_bytes + (on_the_fly ? 0 : dense_bytes)};
    return k;
}

void lub_elastic_kernel_free(lub_elastic_kernel *k)
{
    if (!k) return;
    for (int q = 0; q < k->nblocks; q++) free(k->blocks[q].c);
    free(k->blocks);
    free(k->ps);
    free(k->pt);
    free(k->xs);
    free(k->ls);
    free(k->xt);
    free(k->rs);
    free(k->rt);
    free(k->wp);
    free(k->wv);
    free(k);
}

void lub_elastic_kernel_get_info(const lub_elastic_kernel *k, lub_elastic_kernel_info *info)
{
    *info = k->info;
}

/* v[i] += sum_j c[j] p[j], j < n: the inner product every block reduces to */
static inline double dot(const double *restrict c, const double *restrict p, int n)
{
    double s = 0.0;
#pragma omp simd reduction(+ : s)
    for (int j = 0; j < n; j++) s += c[j] * p[j];
    return s;
}

/* Work above which the targets of a block are shared among OpenMP threads. */
enum { PARALLEL_WORK = 1 << 20 };

static void block_apply(const lub_elastic_kernel *k, const block_t *B, const double *wp, double *wv)
{
    const run_t *T = &k->rt[B->tr], *S = &k->rs[B->sr];
    const double *ps = wp + S->start;
    double *vt = wv + T->start;
    int nt = T->n, ns = S->n;
    int par = (double)nt * ns > PARALLEL_WORK;
    if (B->toeplitz) {
        /* row i uses c[j - i + nt - 1], j = 0..ns-1: a contiguous window of c */
#pragma omp parallel for schedule(static) if (par)
        for (int i = 0; i < nt; i++) vt[i] += dot(B->c + (nt - 1 - i), ps, ns);
    } else if (B->c) {
#pragma omp parallel for schedule(static) if (par)
        for (int i = 0; i < nt; i++) vt[i] += dot(B->c + (size_t)i * ns, ps, ns);
    } else {
#pragma omp parallel for schedule(static) if (par)
        for (int i = 0; i < nt; i++) {
            double s = 0.0, x = k->xt[T->start + i];
            for (int j = 0; j < ns; j++)
                s += lub_elastic_coefficient(x - k->xs[S->start + j], k->ls[S->start + j], k->E,
                                             k->b) *
                     ps[j];
            vt[i] += s;
        }
    }
}

void lub_elastic_displacement(lub_elastic_kernel *k, const double *p, double *v)
{
    for (int j = 0; j < k->ns; j++) k->wp[j] = p[k->ps[j]];
    for (int i = 0; i < k->nt; i++) k->wv[i] = 0.0;
    for (int q = 0; q < k->nblocks; q++) block_apply(k, &k->blocks[q], k->wp, k->wv);
    for (int i = 0; i < k->nt; i++) v[k->pt[i]] = k->wv[i];
}
