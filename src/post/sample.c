/* lubkit post-processing: sampling particle fields (see sample.h). */
#include "post/sample.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "io/dict.h"
#include "particles/weight.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---- fields --------------------------------------------------------------------------- */

static const char *const VEL_NAMES[3] = {"Ux", "Uy", "Uz"};

char *lub_post_fields_available(const lub_particles *P, char *buf, size_t size)
{
    size_t len = (size_t)snprintf(buf, size, "p U Ux Uy%s", P->dim == 3 ? " Uz" : "");
    for (int e = 0; e < P->nextra && len < size; e++)
        len += (size_t)snprintf(buf + len, size - len, " %s", P->extra[e].name);
    return buf;
}

/* Append a column; -1 when full. */
static int push_col(lub_post_fields *f, lub_post_source src, int comp, const char *field,
                    const char *column)
{
    if (f->n >= LUB_POST_MAX_COLS) return -1;
    lub_post_column *c = &f->col[f->n++];
    c->src = src;
    c->comp = comp;
    snprintf(c->field, sizeof c->field, "%s", field ? field : "");
    snprintf(c->column, sizeof c->column, "%s", column);
    return 0;
}

/* Columns of one name; 0, 1 when the name is unknown, -1 when there are too many. */
static int resolve(lub_post_fields *f, const char *name, const lub_particles *P)
{
    for (int e = 0; e < P->nextra; e++)
        if (strcmp(name, P->extra[e].name) == 0) return push_col(f, LUB_POST_EXTRA, 0, name, name);
    if (strcmp(name, "p") == 0 || strcmp(name, "pressure") == 0)
        return push_col(f, LUB_POST_PRESSURE, 0, NULL, "p[Pa]");
    if (strcmp(name, "U") == 0 || strcmp(name, "u") == 0 || strcmp(name, "velocity") == 0) {
        for (int d = 0; d < P->dim; d++) {
            char col[16];
            snprintf(col, sizeof col, "%s[m/s]", VEL_NAMES[d]);
            if (push_col(f, LUB_POST_VELOCITY, d, NULL, col)) return -1;
        }
        return 0;
    }
    for (int d = 0; d < P->dim; d++) {
        char lower[4] = {'u', VEL_NAMES[d][1], '\0', '\0'};
        if (strcmp(name, VEL_NAMES[d]) == 0 || strcmp(name, lower) == 0) {
            char col[16];
            snprintf(col, sizeof col, "%s[m/s]", VEL_NAMES[d]);
            return push_col(f, LUB_POST_VELOCITY, d, NULL, col);
        }
    }
    return 1;
}

int lub_post_fields_parse(lub_post_fields *f, const char *list, const lub_particles *P, char *err,
                          size_t errsize)
{
    memset(f, 0, sizeof *f);
    char buf[1024], avail[1024];
    if (!list || strlen(list) >= sizeof buf) {
        snprintf(err, errsize, "the field list is %s", list ? "too long" : "missing");
        return -1;
    }
    strcpy(buf, list);
    lub_post_fields_available(P, avail, sizeof avail);
    int count = 0;
    for (char *tok = buf, *next; tok; tok = next) {
        /* split by hand: strtok would skip an empty name ("p,,U") */
        next = strchr(tok, ',');
        if (next) *next++ = '\0';
        while (*tok == ' ' || *tok == '\t') tok++;
        size_t len = strlen(tok);
        while (len && (tok[len - 1] == ' ' || tok[len - 1] == '\t')) tok[--len] = '\0';
        if (!len) {
            snprintf(err, errsize, "empty field name in '%s'", list);
            return -1;
        }
        int before = f->n, rc = resolve(f, tok, P);
        if (rc < 0) {
            snprintf(err, errsize, "too many columns in '%s' (at most %d)", list,
                     LUB_POST_MAX_COLS);
            return -1;
        }
        if (rc > 0) {
            /* suggest among the names offered */
            const char *names[LUB_MAX_EXTRA + 8];
            size_t nn = 0;
            const char *std[] = {"p", "U", "Ux", "Uy", "Uz"};
            for (int k = 0; k < (P->dim == 3 ? 5 : 4); k++) names[nn++] = std[k];
            for (int e = 0; e < P->nextra; e++) names[nn++] = P->extra[e].name;
            const char *near = lub_closest(tok, names, nn);
            char hint[LUB_NAME_MAX + 32] = "";
            if (near) snprintf(hint, sizeof hint, " (did you mean '%s'?)", near);
            snprintf(err, errsize, "unknown field '%s'%s; the fields are: %s", tok, hint, avail);
            return -1;
        }
        for (int c = before; c < f->n; c++)
            for (int k = 0; k < before; k++)
                if (strcmp(f->col[c].column, f->col[k].column) == 0) {
                    snprintf(err, errsize, "field '%s' is listed twice in '%s'", tok, list);
                    return -1;
                }
        count++;
    }
    if (count == 0) {
        snprintf(err, errsize, "no field named in '%s'; the fields are: %s", list, avail);
        return -1;
    }
    return 0;
}

int lub_post_fields_arrays(const lub_post_fields *f, const lub_particles *P, const double **vals,
                           char *err, size_t errsize)
{
    for (int c = 0; c < f->n; c++) {
        const lub_post_column *col = &f->col[c];
        switch (col->src) {
        case LUB_POST_PRESSURE:
            vals[c] = P->p;
            break;
        case LUB_POST_VELOCITY:
            vals[c] = P->u[col->comp];
            break;
        case LUB_POST_EXTRA:
            vals[c] = lub_particles_find_extra(P, col->field);
            if (!vals[c]) {
                snprintf(err, errsize, "no field '%s'", col->field);
                return -1;
            }
            break;
        }
    }
    return 0;
}

/* ---- accumulators --------------------------------------------------------------------- */

void lub_accum_init(lub_accum *a, int nrows, int ncols)
{
    a->nrows = nrows;
    a->ncols = ncols;
    a->sum = lub_calloc((size_t)nrows * (size_t)(ncols > 0 ? ncols : 1), sizeof *a->sum);
    a->count = lub_calloc((size_t)nrows, sizeof *a->count);
}

void lub_accum_clear(lub_accum *a)
{
    memset(a->sum, 0, (size_t)a->nrows * (size_t)a->ncols * sizeof *a->sum);
    memset(a->count, 0, (size_t)a->nrows * sizeof *a->count);
}

void lub_accum_free(lub_accum *a)
{
    free(a->sum);
    free(a->count);
    memset(a, 0, sizeof *a);
}

/* ---- bins ----------------------------------------------------------------------------- */

int lub_bins_init(lub_bins *b, double from, double to, double dx)
{
    memset(b, 0, sizeof *b);
    if (!isfinite(from) || !isfinite(to) || !isfinite(dx) || !(dx > 0.0) || !(to > from)) return -1;
    /* a range that is a whole number of bins up to round-off gets no sliver bin */
    double n = ceil((to - from) / dx - 1e-9);
    if (n < 1.0) n = 1.0;
    if (n > LUB_BINS_MAX) return -1;
    b->from = from;
    b->to = to;
    b->dx = dx;
    b->nbins = (int)n;
    return 0;
}

int lub_bins_find(const lub_bins *b, double x)
{
    if (!(x >= b->from && x <= b->to)) return -1;
    int k = (int)floor((x - b->from) / b->dx);
    if (k >= b->nbins) k = b->nbins - 1;
    if (k < 0) k = 0;
    return k;
}

double lub_bins_lower(const lub_bins *b, int k)
{
    return b->from + k * b->dx;
}

double lub_bins_upper(const lub_bins *b, int k)
{
    return k == b->nbins - 1 ? b->to : b->from + (k + 1) * b->dx;
}

double lub_bins_centre(const lub_bins *b, int k)
{
    return 0.5 * (lub_bins_lower(b, k) + lub_bins_upper(b, k));
}

/* ---- sampling ------------------------------------------------------------------------- */

size_t lub_sample_bins(lub_accum *a, const lub_bins *b, const lub_particles *P, int kind, int patch,
                       const double *coord, const double *const *vals)
{
    if (a->nrows != b->nbins) lub_bug("accumulator of %d rows for %d bins", a->nrows, b->nbins);
    const double *xs = coord ? coord : P->x[0];
    double v[LUB_POST_MAX_COLS];
    if (a->ncols > LUB_POST_MAX_COLS) lub_bug("%d columns", a->ncols);
    size_t added = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != kind || (patch >= 0 && P->patch[i] != patch)) continue;
        int k = lub_bins_find(b, xs[i]);
        if (k < 0) continue;
        for (int c = 0; c < a->ncols; c++) v[c] = vals[c][i];
        lub_accum_add(a, k, v);
        added++;
    }
    return added;
}

/* A wall or dummy particle of the patch, by x. */
typedef struct {
    double x;
    size_t i;
} x_index;

static int x_index_cmp(const void *a, const void *b)
{
    const x_index *p = a, *q = b;
    if (p->x != q->x) return p->x < q->x ? -1 : 1;
    return (p->i > q->i) - (p->i < q->i);
}

/* Add j to the centroid sum c of i's dummy neighbours: j a dummy of i's level within r. */
static void facing_add(const lub_particles *P, size_t i, size_t j, double r, double *c, int *nd)
{
    if (P->kind[j] != LUB_DUMMY || P->level[j] != P->level[i]) return;
    double v[3] = {0, 0, 0}, d2 = 0;
    for (int d = 0; d < P->dim; d++) {
        v[d] = P->x[d][i] - P->x[d][j];
        d2 += v[d] * v[d];
    }
    if (d2 > r * r) return;
    for (int d = 0; d < 3; d++) c[d] += v[d];
    (*nd)++;
}

size_t lub_wall_facing(const lub_particles *P, int patch, int dir, unsigned char *on)
{
    size_t n = 0, marked = 0;
    x_index *s = lub_malloc((P->n ? P->n : 1) * sizeof *s);
    for (size_t i = 0; i < P->n; i++) {
        on[i] = 0;
        if (P->kind[i] != LUB_FLUID && P->patch[i] == patch) s[n++] = (x_index){P->x[0][i], i};
    }
    qsort(s, n, sizeof *s, x_index_cmp);
    for (size_t k = 0; k < n; k++) {
        size_t i = s[k].i;
        if (P->kind[i] != LUB_WALL) continue;
        const double r = 1.5 * P->levels[P->level[i]].l0;
        double c[3] = {0, 0, 0}; /* sum of (x_i - x_dummy): along the outward normal */
        int nd = 0;
        for (size_t q = k; q-- > 0 && s[k].x - s[q].x <= r;) facing_add(P, i, s[q].i, r, c, &nd);
        for (size_t q = k + 1; q < n && s[q].x - s[k].x <= r; q++)
            facing_add(P, i, s[q].i, r, c, &nd);
        double len = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        if (nd && len > 0 && (dir < 0 ? -c[1] : c[1]) > 0.5 * len) on[i] = 1, marked++;
    }
    free(s);
    return marked;
}

static double dist2(const lub_particles *P, size_t i, const double *xq)
{
    double r2 = 0.0;
    for (int d = 0; d < P->dim; d++) {
        double dx = P->x[d][i] - xq[d];
        r2 += dx * dx;
    }
    return r2;
}

size_t lub_sample_point(const lub_particles *P, const double *xq, const double *const *vals,
                        int ncols, double *out, double *re_used)
{
    /* the nearest fluid or wall particle fixes the level, hence re */
    size_t nearest = P->n;
    double best = INFINITY;
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] == LUB_DUMMY) continue;
        double r2 = dist2(P, i, xq);
        if (r2 < best) best = r2, nearest = i;
    }
    if (nearest == P->n) return 0;
    double re = P->levels[P->level[nearest]].re;
    if (re_used) *re_used = re;
    if (!(best < re * re)) return 0;

    double wsum = 0.0, s[LUB_POST_MAX_COLS] = {0};
    size_t used = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] == LUB_DUMMY) continue;
        double r2 = dist2(P, i, xq);
        if (!(r2 < re * re)) continue;
        double w = lub_mps_weight(sqrt(r2), re); /* thesis (T-6) */
        if (w <= 0.0) continue;
        wsum += w;
        for (int c = 0; c < ncols; c++) s[c] += w * vals[c][i];
        used++;
    }
    if (used == 0 || !(wsum > 0.0)) return 0;
    for (int c = 0; c < ncols; c++) out[c] = s[c] / wsum;
    return used;
}

void lub_totals_compute(lub_totals *t, const lub_particles *P, double rho)
{
    /* sums per level, times the level's particle mass at the end: the mass is then exactly
     * m n, and the sums carry no factor m through the additions */
    double su[LUB_MAX_LEVELS][3] = {{0}}, su2[LUB_MAX_LEVELS] = {0};
    size_t n[LUB_MAX_LEVELS] = {0};
    memset(t, 0, sizeof *t);
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_FLUID) continue;
        int k = P->level[i];
        n[k]++;
        for (int d = 0; d < P->dim; d++) {
            su[k][d] += P->u[d][i];
            su2[k] += P->u[d][i] * P->u[d][i];
        }
    }
    for (int k = 0; k < P->nlevels && k < LUB_MAX_LEVELS; k++) {
        double m = rho * pow(P->levels[k].l0, P->dim);
        t->nfluid += n[k];
        t->mass += m * (double)n[k];
        for (int d = 0; d < 3; d++) t->momentum[d] += m * su[k][d];
        t->kinetic += 0.5 * m * su2[k];
    }
}

/* Projection of point x on the line through a with unit direction t. */
static double along(const double *x, const double *a, double tx, double ty)
{
    return (x[0] - a[0]) * tx + (x[1] - a[1]) * ty;
}

int lub_wall_arc(const lub_wall *w, int dim, const double *x, double *s)
{
    if (dim != 2) return -1;
    switch (w->type) {
    case LUB_WALL_CYLINDER: {
        /* angle from the lowest point (0, -R) seen from the centre, positive towards +x */
        double theta = atan2(x[0] - w->centre[0], -(x[1] - w->centre[1]));
        *s = w->radius * theta;
        return 0;
    }
    case LUB_WALL_PLANE: {
        double tx = w->normal[1], ty = -w->normal[0];
        double len = hypot(tx, ty);
        tx /= len, ty /= len;
        if (tx < 0.0 || (tx == 0.0 && ty < 0.0)) tx = -tx, ty = -ty;
        *s = along(x, w->point, tx, ty);
        return 0;
    }
    case LUB_WALL_SEGMENT: {
        double tx = w->to[0] - w->from[0], ty = w->to[1] - w->from[1], len = hypot(tx, ty);
        *s = along(x, w->from, tx / len, ty / len);
        return 0;
    }
    case LUB_WALL_POLYLINE:
    case LUB_WALL_POLYGON: {
        /* a polygon: the closed boundary from its first vertex, counter-clockwise */
        int closed = w->type == LUB_WALL_POLYGON, nedges = closed ? w->npts : w->npts - 1;
        double start = 0.0, best = INFINITY;
        for (int k = 0; k < nedges; k++) {
            const double *a = w->pts + 2 * k, *b = w->pts + 2 * ((k + 1) % w->npts);
            double tx = b[0] - a[0], ty = b[1] - a[1], len = hypot(tx, ty);
            if (len > 0.0) {
                double q = along(x, a, tx / len, ty / len);
                double qc = q < 0.0 ? 0.0 : q > len ? len : q;
                double px = a[0] + qc * tx / len - x[0], py = a[1] + qc * ty / len - x[1];
                double d2 = px * px + py * py;
                if (d2 < best) best = d2, *s = start + qc;
            }
            start += len;
        }
        return isfinite(best) ? 0 : -1;
    }
    default:
        return -1;
    }
}
