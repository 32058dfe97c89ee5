/* lubkit post-processing: wall curves, loads and the elastic wall's shape (see wallshape.h). */
#include "post/wallshape.h"

#include <math.h>
#include <stdlib.h>

#include "core/error.h"

typedef struct {
    double x;
    uint64_t id;
    size_t i;
} curve_pt;

static int curve_cmp(const void *a, const void *b)
{
    const curve_pt *u = a, *v = b;
    if (u->x != v->x) return u->x < v->x ? -1 : 1;
    return (u->id > v->id) - (u->id < v->id);
}

/* particleGen's owner of x (geometry.h levels; models/multiResolution/levels.h lub_levels_locate)
 */
static int owner(const lub_geometry *g, double x)
{
    for (int k = 0; k < g->nlevels - 1; k++)
        if (g->levels[k].has_region && x >= g->levels[k].xmin && x <= g->levels[k].xmax) return k;
    return g->nlevels - 1;
}

/* Wall particle i of patch on the curve (see wallshape.h). */
static int on_curve(const lub_particles *P, int patch, const lub_geometry *g, size_t i)
{
    if (P->kind[i] != LUB_WALL || (int)P->patch[i] != patch) return 0;
    if (!g || P->nlevels < 2 || g->nlevels != P->nlevels) return 1;
    return owner(g, P->x[0][i]) == P->level[i];
}

size_t lub_wall_curve(const lub_particles *P, int patch, const lub_geometry *g, size_t **idx)
{
    size_t n = 0;
    for (size_t i = 0; i < P->n; i++) n += on_curve(P, patch, g, i);
    curve_pt *c = lub_malloc((n ? n : 1) * sizeof *c);
    n = 0;
    for (size_t i = 0; i < P->n; i++)
        if (on_curve(P, patch, g, i)) c[n++] = (curve_pt){P->x[0][i], P->id[i], i};
    qsort(c, n, sizeof *c, curve_cmp);
    *idx = lub_malloc((n ? n : 1) * sizeof **idx);
    for (size_t k = 0; k < n; k++) (*idx)[k] = c[k].i;
    free(c);
    return n;
}

int lub_wall_integral(const lub_particles *P, int patch, const lub_geometry *g, const double *f,
                      double *out)
{
    size_t *idx;
    size_t n = lub_wall_curve(P, patch, g, &idx);
    *out = 0.0;
    if (n == 0) {
        free(idx);
        return 0;
    }
    double *x = lub_malloc(n * sizeof *x), *w = lub_malloc(n * sizeof *w);
    for (size_t k = 0; k < n; k++) x[k] = P->x[0][idx[k]];
    int rc = lub_elastic_segment_widths((int)n, x, P->levels[0].l0, w);
    if (rc == 0) {
        double s = 0.0;
        for (size_t k = 0; k < n; k++) s += f[idx[k]] * w[k];
        *out = s;
    }
    free(x);
    free(w);
    free(idx);
    return rc;
}

size_t lub_wall_shape(const lub_particles *P, int patch, const lub_geometry *g,
                      const lub_elastic_wall *e, double h0, lub_wall_shape_row **rows)
{
    size_t *idx;
    size_t n = lub_wall_curve(P, patch, g, &idx);
    const double *shape = lub_particles_find_extra(P, LUB_ELASTIC_FIELD_SHAPE);
    double yf;
    if (!lub_elastic_floor(g, e, e->x_centre, &yf)) yf = e->y_lowest - e->h0;
    const double R = e->radius;
    lub_wall_shape_row *r = lub_malloc((n ? n : 1) * sizeof *r);
    for (size_t k = 0; k < n; k++) {
        size_t i = idx[k];
        double x = P->x[0][i], y = P->x[1][i], dx = x - e->x_centre, s, below;
        s = shape ? shape[i] : R - sqrt(fmax(R * R - dx * dx, 0.0));
        r[k].x = x;
        r[k].y = y;
        r[k].v = y - yf - h0 - s;
        r[k].h = lub_elastic_floor(g, e, x, &below) ? y - below : NAN;
        r[k].id = P->id[i];
    }
    free(idx);
    *rows = r;
    return n;
}
