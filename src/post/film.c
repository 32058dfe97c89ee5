/* lubkit post-processing: the oil film's shape (see film.h). */
#include "post/film.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

int lub_film_init(lub_film *f, double from, double to, double dx)
{
    memset(f, 0, sizeof *f);
    if (lub_bins_init(&f->bins, from, to, dx) != 0) return -1;
    size_t n = (size_t)f->bins.nbins;
    f->ytop = lub_malloc(n * sizeof *f->ytop);
    f->ybot = lub_malloc(n * sizeof *f->ybot);
    f->l0top = lub_malloc(n * sizeof *f->l0top);
    f->l0bot = lub_malloc(n * sizeof *f->l0bot);
    f->wall_above = lub_malloc(n * sizeof *f->wall_above);
    f->wall_below = lub_malloc(n * sizeof *f->wall_below);
    f->n = lub_calloc(n, sizeof *f->n);
    return 0;
}

void lub_film_free(lub_film *f)
{
    free(f->ytop);
    free(f->ybot);
    free(f->l0top);
    free(f->l0bot);
    free(f->wall_above);
    free(f->wall_below);
    free(f->n);
    memset(f, 0, sizeof *f);
}

void lub_film_sample(lub_film *f, const lub_particles *P)
{
    int nb = f->bins.nbins;
    for (int k = 0; k < nb; k++) {
        f->ytop[k] = -INFINITY;
        f->ybot[k] = INFINITY;
        f->wall_above[k] = INFINITY;
        f->wall_below[k] = -INFINITY;
        f->l0top[k] = f->l0bot[k] = 0.0;
        f->n[k] = 0;
    }
    /* the fluid column of each bin */
    double usum = 0.0;
    size_t nf = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_FLUID) continue;
        usum += P->u[0][i];
        nf++;
        int k = lub_bins_find(&f->bins, P->x[0][i]);
        if (k < 0) continue;
        double y = P->x[1][i], l0 = P->levels[P->level[i]].l0;
        if (y > f->ytop[k]) f->ytop[k] = y, f->l0top[k] = l0;
        if (y < f->ybot[k]) f->ybot[k] = y, f->l0bot[k] = l0;
        f->n[k]++;
    }
    f->mean_u = nf ? usum / (double)nf : 0.0;
    /* the wall surfaces nearest to it, above and below */
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_WALL) continue;
        int k = lub_bins_find(&f->bins, P->x[0][i]);
        if (k < 0 || f->n[k] == 0) continue;
        double y = P->x[1][i];
        if (y > f->ytop[k] && y < f->wall_above[k]) f->wall_above[k] = y;
        if (y < f->ybot[k] && y > f->wall_below[k]) f->wall_below[k] = y;
    }
}

int lub_film_row_at(const lub_film *f, int k, lub_film_row *row)
{
    if (k < 0 || k >= f->bins.nbins || f->n[k] == 0) return 0;
    row->x = lub_bins_centre(&f->bins, k);
    row->n = f->n[k];
    row->surface = f->ytop[k];
    row->bottom = f->ybot[k] - f->wall_below[k] < LUB_FILM_CONTACT * f->l0bot[k] ? f->wall_below[k]
                                                                                 : f->ybot[k];
    row->contact = f->wall_above[k] - f->ytop[k] < LUB_FILM_CONTACT * f->l0top[k];
    row->h = (row->contact ? f->wall_above[k] : f->ytop[k]) - row->bottom;
    return 1;
}

int lub_film_meniscus(const lub_film *f, double *inlet, double *outlet)
{
    int nb = f->bins.nbins, down = f->mean_u >= 0.0 ? 1 : -1;
    int k0 = down > 0 ? 0 : nb - 1;
    lub_film_row r;
    int first = -1, last = -1;
    for (int j = 0, k = k0; j < nb; j++, k += down) {
        int c = lub_film_row_at(f, k, &r) && r.contact;
        if (c && first < 0) first = k;
        if (c) last = k;
        if (!c && first >= 0) break;
    }
    if (first < 0) return 0;
    if (down > 0) {
        *inlet = lub_bins_lower(&f->bins, first);
        *outlet = lub_bins_upper(&f->bins, last);
    } else {
        *inlet = lub_bins_upper(&f->bins, first);
        *outlet = lub_bins_lower(&f->bins, last);
    }
    return 1;
}
