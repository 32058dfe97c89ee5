/* lubkit post-processing: the oil film's shape (see film.h). */
#include "post/film.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

struct lub_film_entry {
    double y, l0;
    int fluid;
};

int lub_film_init(lub_film *f, double from, double to, double dx)
{
    memset(f, 0, sizeof *f);
    if (lub_bins_init(&f->bins, from, to, dx) != 0) return -1;
    size_t n = (size_t)f->bins.nbins;
    f->surface = lub_malloc(n * sizeof *f->surface);
    f->bottom = lub_malloc(n * sizeof *f->bottom);
    f->h = lub_malloc(n * sizeof *f->h);
    f->filled = lub_malloc(n * sizeof *f->filled);
    f->fluid = lub_malloc(n * sizeof *f->fluid);
    f->contact = lub_malloc(n * sizeof *f->contact);
    f->full = lub_malloc(n * sizeof *f->full);
    f->n = lub_malloc(n * sizeof *f->n);
    f->start = lub_malloc((n + 1) * sizeof *f->start);
    f->ecap = 1; /* strips index into e even when empty */
    f->e = lub_malloc(f->ecap * sizeof *f->e);
    return 0;
}

void lub_film_free(lub_film *f)
{
    free(f->surface);
    free(f->bottom);
    free(f->h);
    free(f->filled);
    free(f->fluid);
    free(f->contact);
    free(f->full);
    free(f->n);
    free(f->start);
    free(f->e);
    memset(f, 0, sizeof *f);
}

/* The bins whose strip holds a particle at x of spacing l0: its own bin and those whose
 * centre is closer than LUB_FILM_STRIP l0 (see film.h), as [*lo, *hi].  Returns 0 when there
 * are none. */
static int strip_bins(const lub_bins *b, double x, double l0, int *lo, int *hi)
{
    int own = lub_bins_find(b, x);
    *lo = own >= 0 ? own : b->nbins;
    *hi = own;
    const double reach = LUB_FILM_STRIP * l0;
    double a = fmax(x - reach, b->from), c = fmin(x + reach, b->to);
    if (a <= c)
        for (int k = lub_bins_find(b, a), k1 = lub_bins_find(b, c); k <= k1; k++)
            if (fabs(x - lub_bins_centre(b, k)) < reach) {
                if (k < *lo) *lo = k;
                if (k > *hi) *hi = k;
            }
    return *hi >= 0;
}

static int entry_cmp(const void *a, const void *b)
{
    double ya = ((const lub_film_entry *)a)->y, yb = ((const lub_film_entry *)b)->y;
    return (ya > yb) - (ya < yb);
}

/* The strips of every bin: fluid and wall particles, each bin's sorted by y.  A bin's strip
 * is a run of bins, so [lo, hi] holds every bin a particle belongs to. */
static void film_strips(lub_film *f, const lub_particles *P)
{
    const lub_bins *b = &f->bins;
    int nb = b->nbins;
    /* pass 0 counts bin k's particles in start[k + 1]; their prefix sums make start[k] the
     * first entry of bin k, and shifted up by one, start[k + 1] is the fill cursor of bin k,
     * which pass 1 moves on to the end of bin k = start of bin k + 1 */
    memset(f->start, 0, (size_t)(nb + 1) * sizeof *f->start);
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i < P->n; i++) {
            if (P->kind[i] == LUB_DUMMY) continue;
            double l0 = P->levels[P->level[i]].l0;
            int lo, hi;
            if (!strip_bins(b, P->x[0][i], l0, &lo, &hi)) continue;
            lub_film_entry en = {P->x[1][i], l0, P->kind[i] == LUB_FLUID};
            for (int k = lo; k <= hi; k++) {
                if (pass == 0)
                    f->start[k + 1]++;
                else
                    f->e[f->start[k + 1]++] = en;
            }
        }
        if (pass == 1) break;
        for (int k = 0; k < nb; k++) f->start[k + 1] += f->start[k];
        size_t need = f->start[nb];
        if (need > f->ecap) {
            f->ecap = need + need / 4;
            f->e = lub_realloc(f->e, f->ecap * sizeof *f->e);
        }
        memmove(f->start + 1, f->start, (size_t)nb * sizeof *f->start);
    }
    for (int k = 0; k < nb; k++)
        qsort(f->e + f->start[k], f->start[k + 1] - f->start[k], sizeof *f->e, entry_cmp);
}

/* Bin k from its strip e[0 .. m) (sorted by y). */
static void film_bin(lub_film *f, int k, const lub_film_entry *e, size_t m)
{
    size_t i0 = m, i1 = 0; /* lowest and highest fluid particle */
    for (size_t i = 0; i < m; i++)
        if (e[i].fluid) {
            if (i0 == m) i0 = i;
            i1 = i;
        }
    f->fluid[k] = i0 < m;
    f->contact[k] = f->full[k] = 0;
    f->filled[k] = 0.0;
    if (i0 == m) return;
    /* the entries next to the fluid's ends are wall particles: all others are fluid */
    int below = i0 > 0, above = i1 + 1 < m;
    double ytop = e[i1].y, ybot = e[i0].y;
    double wbelow = below ? e[i0 - 1].y : -INFINITY, wabove = above ? e[i1 + 1].y : INFINITY;
    f->surface[k] = ytop;
    f->bottom[k] = ybot - wbelow < LUB_FILM_CONTACT * e[i0].l0 ? wbelow : ybot;
    f->contact[k] = wabove - ytop < LUB_FILM_CONTACT * e[i1].l0;
    f->h[k] = (f->contact[k] ? wabove : ytop) - f->bottom[k];
    if (!below || !above) return;
    /* from the wall below to the wall above: no two consecutive heights 2 l0 apart, and the
     * part of the gap the cells [y - l0/2, y + l0/2] cover (swept in the order of y, which is
     * the order of the cells' lower ends on one level; across levels a coarse cell is
     * counted from where the cells before it end) */
    int full = 1;
    double covered = 0.0, upto = wbelow;
    for (size_t i = i0 - 1; i <= i1 + 1; i++) {
        if (i > i0 - 1 && e[i].y - e[i - 1].y >= LUB_FILM_CONTACT * fmax(e[i].l0, e[i - 1].l0))
            full = 0;
        double a = fmax(e[i].y - 0.5 * e[i].l0, upto), c = fmin(e[i].y + 0.5 * e[i].l0, wabove);
        if (c > a) covered += c - a, upto = c;
    }
    f->full[k] = full;
    f->filled[k] = covered / (wabove - wbelow);
}

void lub_film_sample(lub_film *f, const lub_particles *P)
{
    int nb = f->bins.nbins;
    double usum = 0.0;
    size_t nf = 0;
    memset(f->n, 0, (size_t)nb * sizeof *f->n);
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_FLUID) continue;
        usum += P->u[0][i];
        nf++;
        int k = lub_bins_find(&f->bins, P->x[0][i]);
        if (k >= 0) f->n[k]++;
    }
    f->mean_u = nf ? usum / (double)nf : 0.0;
    film_strips(f, P);
    for (int k = 0; k < nb; k++) film_bin(f, k, f->e + f->start[k], f->start[k + 1] - f->start[k]);
}

int lub_film_row_at(const lub_film *f, int k, lub_film_row *row)
{
    if (k < 0 || k >= f->bins.nbins || !f->fluid[k]) return 0;
    row->x = lub_bins_centre(&f->bins, k);
    row->n = f->n[k];
    row->surface = f->surface[k];
    row->bottom = f->bottom[k];
    row->contact = f->contact[k];
    row->h = f->h[k];
    row->filled = f->filled[k];
    row->full = f->full[k];
    return 1;
}

int lub_film_meniscus(const lub_film *f, lub_film_ends *e)
{
    const lub_bins *b = &f->bins;
    int nb = b->nbins, down = f->mean_u >= 0.0 ? 1 : -1;
    /* the longest run of full bins (most bins; on a tie the upstream one), [best0, best1] */
    int best0 = -1, best1 = -1, run0 = -1;
    for (int k = 0; k <= nb; k++) {
        int full = k < nb && f->fluid[k] && f->full[k];
        if (full && run0 < 0) run0 = k;
        if (!full && run0 >= 0) {
            int len = k - run0, bestlen = best1 - best0 + 1;
            if (best0 < 0 || len > bestlen || (len == bestlen && down < 0))
                best0 = run0, best1 = k - 1;
            run0 = -1;
        }
    }
    if (best0 < 0) return 0;
    int first = down > 0 ? best0 : best1, last = down > 0 ? best1 : best0;
    /* upstream from the inlet through the bins where the oil touches the upper wall */
    int c = first;
    while (c - down >= 0 && c - down < nb && f->fluid[c - down] && f->contact[c - down]) c -= down;
    if (down > 0) {
        e->inlet = lub_bins_lower(b, first);
        e->outlet = lub_bins_upper(b, last);
        e->contact = lub_bins_lower(b, c);
    } else {
        e->inlet = lub_bins_upper(b, first);
        e->outlet = lub_bins_lower(b, last);
        e->contact = lub_bins_upper(b, c);
    }
    return 1;
}
