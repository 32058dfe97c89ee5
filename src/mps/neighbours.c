/* lubkit MPS: cell-linked-list neighbour search (see neighbours.h). */
#include "mps/neighbours.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "particles/weight.h"

/* The cells are made this much (relative) larger than rs, so that the round-off of
 * (x - lo) / h never puts two particles closer than rs two cells apart. */
#define CELL_MARGIN 1e-9
/* Cells are at least rs / reach wide (neighbours.h), and a particle's candidates are those of
 * the (2 reach + 1)^d cells around its own: with reach 2, 25 cells of rs / 2 in 2-D cover
 * 6.25 rs^2 against 9 rs^2 for 9 cells of rs (31% fewer candidates for the same pairs). */
#define R_MAX        LUB_NEIGHBOURS_MAX_REACH
#define MAX_SEGMENTS ((2 * R_MAX + 1) * (2 * R_MAX + 1) * (2 * R_MAX + 1))
/* Arrays grow with this headroom so that a slowly growing pair count does not reallocate
 * every step. */
#define HEADROOM 1.25
/* The binning runs on several threads from this many particles on, and while the cells
 * number at most this many per particle (each thread counts into an array of all cells). */
#define BIN_PARALLEL_MIN           4096
#define BIN_CELLS_PER_PARTICLE_MAX 16

static const char axis_name[3] = {'x', 'y', 'z'};

void lub_neighbours_init(lub_neighbours *nb, int dim, double re, double skin, const double lo[3],
                         const double hi[3], const int periodic[3])
{
    memset(nb, 0, sizeof *nb);
    if (dim != 2 && dim != 3) lub_fatal("neighbour search: dimension %d, expected 2 or 3", dim);
    if (!(re > 0) || !isfinite(re))
        lub_fatal("neighbour search: effective radius re = %g, expected a positive number", re);
    if (!(skin >= 0) || !isfinite(skin))
        lub_fatal("neighbour search: skin = %g, expected a number >= 0", skin);
    nb->dim = dim;
    nb->re = re;
    nb->rs = re * (1.0 + skin);
    lub_neighbours_set_box(nb, lo, hi, periodic);
}

/* The cell grid for cells at least rs / reach wide; returns the number of cells. */
static double cell_grid(lub_neighbours *nb, const double lo[3], const double hi[3],
                        const int periodic[3], int reach)
{
    double ncells = 1.0;
    for (int d = 0; d < 3; d++) {
        if (d >= nb->dim) {
            nb->lo[d] = 0.0, nb->hi[d] = 1.0, nb->periodic[d] = 0, nb->period[d] = 1.0;
            nb->nc[d] = 1, nb->h[d] = 1.0, nb->inv_h[d] = 1.0;
            continue;
        }
        double L = hi[d] - lo[d];
        if (!(L > 0) || !isfinite(L))
            lub_fatal("neighbour search: box in %c from %g to %g, expected lo < hi", axis_name[d],
                      lo[d], hi[d]);
        int per = periodic && periodic[d];
        /* With a period of at least 2 rs a pair closer than rs has exactly one such image. */
        if (per && L < 2.0 * nb->rs)
            lub_fatal("neighbour search: the period %g in %c is shorter than twice the search "
                      "radius 2 rs = %g",
                      L, axis_name[d], 2.0 * nb->rs);
        double m = floor(L * reach / (nb->rs * (1.0 + CELL_MARGIN)));
        if (m < 1) m = 1;
        /* A periodic direction has more cells than the reach (cell_segments wraps once); just
         * above 2 rs, every image is examined, so the missing margin does not matter. */
        if (per && m < reach + 1) m = reach + 1;
        if (m > 1e8) m = 1e8;
        nb->lo[d] = lo[d], nb->hi[d] = hi[d], nb->periodic[d] = per, nb->period[d] = L;
        nb->nc[d] = (int)m;
        nb->h[d] = L / m;
        nb->inv_h[d] = m / L;
        ncells *= m;
    }
    nb->reach = reach;
    return ncells;
}

void lub_neighbours_set_box(lub_neighbours *nb, const double lo[3], const double hi[3],
                            const int periodic[3])
{
    /* cells of rs / 2, unless their grid would be very large (a big, sparsely filled box):
     * then cells of rs, 2^d times fewer */
    double ncells = cell_grid(nb, lo, hi, periodic, LUB_NEIGHBOURS_MAX_REACH);
    if (ncells > LUB_NEIGHBOURS_FINE_CELLS_MAX) ncells = cell_grid(nb, lo, hi, periodic, 1);
    if (ncells > 4.0e9)
        lub_fatal("neighbour search: %.3g cells of size %g in the box, more than the 4e9 "
                  "supported: is the box much larger than the particles?",
                  ncells, nb->rs);
    nb->ncells = (size_t)ncells;
    if (nb->order_h > 0) lub_neighbours_set_order(nb, nb->order_h);
    if (nb->ncells + 1 > nb->cap_cells) {
        free(nb->cell_start);
        nb->cap_cells = nb->ncells + 1;
        nb->cell_start = lub_malloc(nb->cap_cells * sizeof *nb->cell_start);
    }
}

void lub_neighbours_free(lub_neighbours *nb)
{
    free(nb->start);
    free(nb->end);
    free(nb->j);
    for (int d = 0; d < 3; d++) free(nb->dx[d]), free(nb->xs[d]);
    free(nb->w);
    free(nb->perm);
    free(nb->cell);
    free(nb->spos);
    free(nb->cell_start);
    free(nb->tcount);
    free(nb->order_count);
    memset(nb, 0, sizeof *nb);
}

void lub_neighbours_set_order(lub_neighbours *nb, double h)
{
    if (!(h >= 0) || !isfinite(h))
        lub_fatal("neighbour search: sort spacing %g, expected a number >= 0", h);
    nb->order_h = h;
    if (h == 0) return;
    size_t most = 1;
    for (int d = 0; d < 3; d++) {
        double m = d < nb->dim ? floor((nb->hi[d] - nb->lo[d]) / h) + 1.0 : 1.0;
        if (m > 1e8)
            lub_fatal("neighbour search: %.3g rows of spacing %g in %c, more than the 1e8 "
                      "supported",
                      m, h, axis_name[d]);
        nb->order_n[d] = (uint32_t)m;
        if ((size_t)m > most) most = (size_t)m;
    }
    if (most + 1 > nb->cap_order) {
        free(nb->order_count);
        nb->cap_order = most + 1;
        nb->order_count = lub_malloc(nb->cap_order * sizeof *nb->order_count);
    }
}

static void reserve_particles(lub_neighbours *nb, size_t n)
{
    if (n > UINT32_MAX - 1)
        lub_fatal("neighbour search: %zu particles, more than the %u supported", n,
                  (unsigned)(UINT32_MAX - 1));
    if (n <= nb->cap_n && nb->start) return;
    size_t cap = (size_t)(n * HEADROOM) + 16;
    nb->start = lub_realloc(nb->start, cap * sizeof *nb->start);
    nb->end = lub_realloc(nb->end, cap * sizeof *nb->end);
    nb->perm = lub_realloc(nb->perm, cap * sizeof *nb->perm);
    nb->cell = lub_realloc(nb->cell, cap * sizeof *nb->cell);
    nb->spos = lub_realloc(nb->spos, cap * sizeof *nb->spos);
    for (int d = 0; d < nb->dim; d++) nb->xs[d] = lub_realloc(nb->xs[d], cap * sizeof(double));
    nb->cap_n = cap;
}

static void reserve_pairs(lub_neighbours *nb, size_t npairs)
{
    if (npairs <= nb->cap_pairs && nb->j) return;
    size_t cap = (size_t)(npairs * HEADROOM) + 64;
    /* The old contents are not needed: free + malloc avoids copying them. */
    free(nb->j);
    nb->j = lub_malloc(cap * sizeof *nb->j);
    for (int d = 0; d < nb->dim; d++) {
        free(nb->dx[d]);
        nb->dx[d] = lub_malloc(cap * sizeof(double));
    }
    free(nb->w);
    nb->w = lub_malloc(cap * sizeof(double));
    nb->cap_pairs = cap;
}

/* Particles [*i0, *i1) of chunk b of nblocks equal chunks of n: the binning's per-thread
 * chunks and the lists' storage blocks (neighbours.h, Storage). */
static inline void block_range(size_t n, int b, int nblocks, size_t *i0, size_t *i1)
{
    *i0 = n * (size_t)b / (size_t)nblocks;
    *i1 = n * (size_t)(b + 1) / (size_t)nblocks;
}

/* Bring a coordinate of a periodic direction into [lo, lo + L); NaN stays NaN. */
static inline double wrap(double x, double lo, double L)
{
    if (x >= lo && x < lo + L) return x;
    double y = x - L * floor((x - lo) / L);
    if (y >= lo + L) y -= L; /* round-off of the floor above */
    if (y < lo) y = lo;
    return y;
}

/* Cell coordinate of position x in direction d, clamped into the grid (NaN -> 0). */
static inline int cell_coord(const lub_neighbours *nb, int d, double x)
{
    double t = (x - nb->lo[d]) * nb->inv_h[d];
    if (!(t >= 0)) return 0;
    if (t >= nb->nc[d]) return nb->nc[d] - 1;
    return (int)t;
}

/* Position of particle i as used by the search (wrapped in periodic directions), and
 * whether it escaped the box. */
static inline int search_position(const lub_neighbours *nb, double *const x[3], size_t i,
                                  double xi[3])
{
    int escaped = 0;
    for (int d = 0; d < nb->dim; d++) {
        double v = x[d][i];
        if (nb->periodic[d]) {
            v = wrap(v, nb->lo[d], nb->period[d]);
            if (v != v) escaped = 1;
        } else if (!(v >= nb->lo[d] && v <= nb->hi[d])) {
            escaped = 1;
        }
        xi[d] = v;
    }
    return escaped;
}

size_t lub_neighbours_bin(lub_neighbours *nb, size_t n, double *const x[3])
{
    reserve_particles(nb, n);
    nb->n = n;
    const int dim = nb->dim;
    const size_t nx = (size_t)nb->nc[0], ny = (size_t)nb->nc[1];
    size_t *count = nb->cell_start;

    /* Counting sort of the particles by cell, stable in the particle index, in nt contiguous
     * chunks of particles at once: each chunk counts its particles per cell, the chunks'
     * places in a cell follow the chunk order, so the result is that of a serial sort.  (One
     * chunk when the cells outnumber the particles many times over: the counts would cost
     * more than the particles.  The thesis wedge's box holds 5.7 cells per particle, its film
     * filling a thin part of it, and sorts faster on two threads.) */
    const size_t ncells = nb->ncells;
    int nt = omp_get_max_threads();
    if (nt > 64) nt = 64;
    if (n < BIN_PARALLEL_MIN || ncells > BIN_CELLS_PER_PARTICLE_MAX * n) nt = 1;
    if ((size_t)nt * ncells > nb->cap_tcount) {
        free(nb->tcount);
        nb->cap_tcount = (size_t)nt * ncells;
        nb->tcount = lub_malloc(nb->cap_tcount * sizeof *nb->tcount);
    }
    size_t esc[64] = {0};
#pragma omp parallel for schedule(static, 1) num_threads(nt) if (nt > 1)
    for (int t = 0; t < nt; t++) {
        uint32_t *cnt = nb->tcount + (size_t)t * ncells;
        memset(cnt, 0, ncells * sizeof *cnt);
        size_t i0, i1;
        block_range(n, t, nt, &i0, &i1);
        for (size_t i = i0; i < i1; i++) {
            double xi[3] = {0, 0, 0};
            esc[t] += (size_t)search_position(nb, x, i, xi);
            size_t c = (size_t)cell_coord(nb, 0, xi[0]) + nx * (size_t)cell_coord(nb, 1, xi[1]);
            if (dim == 3) c += nx * ny * (size_t)cell_coord(nb, 2, xi[2]);
            nb->cell[i] = (uint32_t)c;
            cnt[c]++;
        }
    }
    /* cell starts; tcount becomes each chunk's next place in each cell: a scan over the
     * cells, in nt ranges of cells at once (each range's total, their running sum, then the
     * starts within each range) */
    size_t escaped = 0;
    for (int t = 0; t < nt; t++) escaped += esc[t];
    size_t part[65] = {0};
#pragma omp parallel num_threads(nt) if (nt > 1)
    {
        const size_t nr = (size_t)omp_get_num_threads(), r = (size_t)omp_get_thread_num();
        const size_t c0 = ncells * r / nr, c1 = ncells * (r + 1) / nr;
        size_t s = 0;
        for (size_t c = c0; c < c1; c++)
            for (int t = 0; t < nt; t++) s += nb->tcount[(size_t)t * ncells + c];
        part[r + 1] = s;
#pragma omp barrier
#pragma omp single
        for (size_t q = 0; q < nr; q++) part[q + 1] += part[q];
        size_t k = part[r];
        for (size_t c = c0; c < c1; c++) {
            count[c] = k;
            for (int t = 0; t < nt; t++) {
                uint32_t *cnt = nb->tcount + (size_t)t * ncells;
                const uint32_t m = cnt[c];
                cnt[c] = (uint32_t)k;
                k += m;
            }
        }
    }
    count[ncells] = n; /* every particle is in one cell */
#pragma omp parallel for schedule(static, 1) num_threads(nt) if (nt > 1)
    for (int t = 0; t < nt; t++) {
        uint32_t *next = nb->tcount + (size_t)t * ncells;
        size_t i0, i1;
        block_range(n, t, nt, &i0, &i1);
        for (size_t i = i0; i < i1; i++) {
            const size_t kk = next[nb->cell[i]]++;
            double xi[3];
            search_position(nb, x, i, xi);
            nb->perm[kk] = (uint32_t)i;
            nb->spos[i] = (uint32_t)kk;
            for (int d = 0; d < dim; d++) nb->xs[d][kk] = xi[d];
        }
    }
    nb->nescaped = escaped;
    return escaped;
}

size_t lub_neighbours_order(lub_neighbours *nb, size_t n, double *const x[3])
{
    if (nb->order_h == 0) return lub_neighbours_bin(nb, n, x);
    reserve_particles(nb, n);
    const int dim = nb->dim;
    const double inv = 1.0 / nb->order_h;
    /* Least significant digit radix sort: a stable counting sort by the x row, then by the y
     * row (then z).  The keys go into cell[], the passes alternate between spos[] and perm[]. */
    uint32_t *key = nb->cell, *src = nb->spos, *dst = nb->perm;
    size_t escaped = 0;
    for (size_t i = 0; i < n; i++) src[i] = (uint32_t)i;
    for (int d = 0; d < dim; d++) {
        const uint32_t rows = nb->order_n[d];
        for (size_t i = 0; i < n; i++) {
            double xi[3] = {0, 0, 0};
            int out = search_position(nb, x, i, xi);
            if (d == 0) escaped += (size_t)out;
            double r = floor((xi[d] - nb->lo[d]) * inv);
            key[i] = r >= 0 && r < rows ? (uint32_t)r : r >= rows ? rows - 1 : 0; /* NaN: 0 */
        }
        size_t *count = nb->order_count;
        memset(count, 0, ((size_t)rows + 1) * sizeof *count);
        for (size_t k = 0; k < n; k++) count[key[src[k]] + 1]++;
        for (uint32_t r = 0; r < rows; r++) count[r + 1] += count[r];
        for (size_t k = 0; k < n; k++) dst[count[key[src[k]]]++] = src[k];
        uint32_t *t = src;
        src = dst, dst = t;
    }
    if (src != nb->perm) memcpy(nb->perm, src, n * sizeof *src);
    nb->nescaped = escaped;
    return escaped;
}

/* A run of particles in cell order (consecutive cells of one row) and the periodic shift to
 * add to their positions. */
typedef struct {
    size_t k0, k1;
    double s[3];
} segment;

/* Neighbour cell coordinate c in direction d: wrapped with its shift, or 0 if outside. */
static inline int neighbour_coord(const lub_neighbours *nb, int d, int *c, double *s)
{
    *s = 0.0;
    if (*c < 0) {
        if (!nb->periodic[d]) return 0;
        *c += nb->nc[d];
        *s = -nb->period[d];
    } else if (*c >= nb->nc[d]) {
        if (!nb->periodic[d]) return 0;
        *c -= nb->nc[d];
        *s = nb->period[d];
    }
    return 1;
}

/* Append the particles of cells [x0, x1] of one row (first cell of the row: base) with the
 * shift s, merged with the previous segment when they follow it with the same shift. */
static inline int add_cells(const lub_neighbours *nb, segment *seg, int ns, size_t base, int x0,
                            int x1, const double s[3])
{
    const size_t k0 = nb->cell_start[base + (size_t)x0], k1 = nb->cell_start[base + (size_t)x1 + 1];
    if (k0 == k1) return ns;
    if (ns > 0 && seg[ns - 1].k1 == k0 && seg[ns - 1].s[0] == s[0] && seg[ns - 1].s[1] == s[1] &&
        seg[ns - 1].s[2] == s[2]) {
        seg[ns - 1].k1 = k1;
        return ns;
    }
    seg[ns].k0 = k0, seg[ns].k1 = k1;
    seg[ns].s[0] = s[0], seg[ns].s[1] = s[1], seg[ns].s[2] = s[2];
    return ns + 1;
}

/* The particles of the (2 reach + 1)^d cells around cell c as at most MAX_SEGMENTS
 * segments: the cells of one row are contiguous in cell order, so a row is one run (two or
 * three across a periodic seam), usually 5 in 2-D and 25 in 3-D. */
static int cell_segments(const lub_neighbours *nb, size_t c, segment *seg)
{
    const int nx = nb->nc[0], ny = nb->nc[1];
    const int cx = (int)(c % (size_t)nx), cy = (int)((c / (size_t)nx) % (size_t)ny);
    const int cz = (int)(c / ((size_t)nx * (size_t)ny));
    const int reach = nb->reach;
    const int oz = nb->dim == 3 ? reach : 0;
    const int xa = cx - reach, xb = cx + reach;
    const double L = nb->periodic[0] ? nb->period[0] : 0.0;
    int ns = 0;
    for (int dz = -oz; dz <= oz; dz++) {
        int z = cz + dz;
        double sz;
        if (!neighbour_coord(nb, 2, &z, &sz)) continue;
        for (int dy = -reach; dy <= reach; dy++) {
            int y = cy + dy;
            double sy;
            if (!neighbour_coord(nb, 1, &y, &sy)) continue;
            const size_t base = (size_t)nx * ((size_t)y + (size_t)ny * (size_t)z);
            double s[3] = {0.0, sy, sz};
            if (!nb->periodic[0]) {
                ns = add_cells(nb, seg, ns, base, xa < 0 ? 0 : xa, xb >= nx ? nx - 1 : xb, s);
                continue;
            }
            /* periodic in x (nx > reach): the wrapped cells on the left, the row's
             * own, the wrapped ones on the right, each with its shift */
            if (xa < 0) {
                s[0] = -L;
                ns = add_cells(nb, seg, ns, base, xa + nx, nx - 1, s);
            }
            s[0] = 0.0;
            ns = add_cells(nb, seg, ns, base, xa < 0 ? 0 : xa, xb >= nx ? nx - 1 : xb, s);
            if (xb >= nx) {
                s[0] = L;
                ns = add_cells(nb, seg, ns, base, 0, xb - nx, s);
            }
        }
    }
    return ns;
}

/* Squared distance of candidate k from particle i, written once so that the counting and
 * the storing sweep make the same floating-point decisions. */
static inline double dist2(int dim, const double *const xs[3], size_t k, const double p[3],
                           double d[3])
{
    d[0] = xs[0][k] + p[0], d[1] = xs[1][k] + p[1];
    double r2 = d[0] * d[0] + d[1] * d[1];
    if (dim == 3) d[2] = xs[2][k] + p[2], r2 += d[2] * d[2];
    return r2;
}

static inline int has_list(const lub_neighbours *nb, size_t i)
{
    return !nb->list_kind || (nb->list_kinds >> nb->list_kind[i] & 1u);
}

/* Count the pairs of every block into count[b].  The particle itself is among the
 * candidates once (own cell, no shift) at distance 0 when its position is finite.
 *
 * The particle loops here and in the solver split the particles into halves (static
 * schedule; here one block per thread, the same halves), although the halves' work differs
 * (lists for some kinds only): handing out chunks as threads come free (tried: dynamic, 512)
 * cut the threads' waiting, but each thread then wrote and read particles all over the
 * arrays, and the pressure solve that follows ran 3-24% slower on the thesis wedge (mostly
 * about 10%), a net loss.  The same half of the particles on the same thread in every phase
 * keeps the data in that core's caches. */
static void count_sweep(lub_neighbours *nb, int nblocks, size_t *count)
{
    const size_t n = nb->n;
    const int dim = nb->dim;
    const double rs2 = nb->rs * nb->rs;
    const double *const xs[3] = {nb->xs[0], nb->xs[1], nb->xs[2]};
#pragma omp parallel for schedule(static, 1)
    for (int b = 0; b < nblocks; b++) {
        segment seg[MAX_SEGMENTS];
        int ns = 0;
        size_t last_cell = (size_t)-1, i0, i1, total = 0;
        block_range(n, b, nblocks, &i0, &i1);
        for (size_t i = i0; i < i1; i++) {
            if (!has_list(nb, i)) continue;
            const size_t c = nb->cell[i], ki = nb->spos[i];
            if (c != last_cell) ns = cell_segments(nb, c, seg), last_cell = c;
            const double xi[3] = {xs[0][ki], xs[1][ki], dim == 3 ? xs[2][ki] : 0.0};
            size_t m = 0;
            for (int s = 0; s < ns; s++) {
                const double p[3] = {seg[s].s[0] - xi[0], seg[s].s[1] - xi[1], seg[s].s[2] - xi[2]};
#pragma omp simd reduction(+ : m)
                for (size_t k = seg[s].k0; k < seg[s].k1; k++) {
                    double d[3];
                    m += dist2(dim, xs, k, p, d) < rs2;
                }
            }
            double d[3];
            const double p0[3] = {-xi[0], -xi[1], -xi[2]};
            total += m - (dist2(dim, xs, ki, p0, d) < rs2);
        }
        count[b] = total;
    }
}

/* The candidates of one segment for particle ki (sorted index), stored from place m on (see
 * fill_sweep); returns the next free place.  dim is a literal at the call sites, so that
 * the loop keeps its pointers in registers. */
static inline size_t store_candidates(const double *const xs[3], const segment *sg,
                                      const double p[3], size_t ki, size_t m, size_t end,
                                      double rs2, uint32_t *restrict J, double *restrict DX,
                                      double *restrict DY, double *restrict DZ, double *restrict W,
                                      const int dim)
{
    for (size_t k = sg->k0; k < sg->k1; k++) {
        double d[3];
        const double r2 = dist2(dim, xs, k, p, d);
        if (m < end) {
            J[m] = (uint32_t)k, DX[m] = d[0], DY[m] = d[1], W[m] = r2;
            if (dim == 3) DZ[m] = d[2];
        }
        m += (r2 < rs2) & (k != ki);
    }
    return m;
}

/* Store the pairs of block b from place place[b] on, within room[b] entries: the sorted
 * index k, displacement and squared distance of every candidate are written at the next
 * free place, which advances only for a pair (no unpredictable branch; nothing is written
 * beyond the block's room, so a thread never writes into another block's); then the
 * particle's pairs get their (T-6) weight and particle index.  count[b] becomes the block's
 * pairs; returns 1 if a block had not the room for them (its lists are then incomplete). */
static int fill_sweep(lub_neighbours *nb, int nblocks, const size_t *place, const size_t *room,
                      size_t *count)
{
    const size_t n = nb->n;
    const int dim = nb->dim;
    const double rs2 = nb->rs * nb->rs, re = nb->re, inv_re = 1.0 / re;
    const double *const xs[3] = {nb->xs[0], nb->xs[1], nb->xs[2]};
    uint32_t *restrict J = nb->j;
    const uint32_t *restrict perm = nb->perm;
    double *restrict DX = nb->dx[0], *restrict DY = nb->dx[1], *restrict DZ = nb->dx[2];
    double *restrict W = nb->w;
    int overflow = 0;
#pragma omp parallel for schedule(static, 1) reduction(| : overflow)
    for (int b = 0; b < nblocks; b++) {
        segment seg[MAX_SEGMENTS];
        int ns = 0;
        size_t last_cell = (size_t)-1, i0, i1;
        block_range(n, b, nblocks, &i0, &i1);
        const size_t lim = place[b] + room[b];
        size_t m = place[b];
        for (size_t i = i0; i < i1; i++) {
            nb->start[i] = m;
            if (!has_list(nb, i)) {
                nb->end[i] = m;
                continue;
            }
            const size_t c = nb->cell[i], ki = nb->spos[i];
            if (c != last_cell) ns = cell_segments(nb, c, seg), last_cell = c;
            const double xi[3] = {xs[0][ki], xs[1][ki], dim == 3 ? xs[2][ki] : 0.0};
            const size_t m0 = m;
            for (int s = 0; s < ns; s++) {
                const double p[3] = {seg[s].s[0] - xi[0], seg[s].s[1] - xi[1], seg[s].s[2] - xi[2]};
                if (dim == 2)
                    m = store_candidates(xs, &seg[s], p, ki, m, lim, rs2, J, DX, DY, DZ, W, 2);
                else
                    m = store_candidates(xs, &seg[s], p, ki, m, lim, rs2, J, DX, DY, DZ, W, 3);
            }
            if (m > lim) {
                /* out of room: the caller counts and fills again */
                overflow = 1;
                nb->end[i] = m = lim;
                for (size_t r = i + 1; r < i1; r++) nb->start[r] = nb->end[r] = lim;
                break;
            }
            /* the particle's pairs at once: r^2 becomes the (T-6) weight (in a loop that
             * vectorises), the sorted index the particle index */
            for (size_t q = m0; q < m; q++) W[q] = lub_mps_weight_pair(sqrt(W[q]), inv_re, re);
            for (size_t q = m0; q < m; q++) J[q] = perm[J[q]];
            nb->end[i] = m;
        }
        count[b] = m - place[b];
    }
    return overflow;
}

/* The blocks' places one after the other, each with the given room; returns the extent. */
static size_t place_blocks(int nblocks, const size_t *room, size_t *place)
{
    size_t at = 0;
    for (int b = 0; b < nblocks; b++) place[b] = at, at += room[b];
    return at;
}

size_t lub_neighbours_build(lub_neighbours *nb, size_t n, double *const x[3])
{
    size_t escaped = lub_neighbours_bin(nb, n, x);
    int nblocks = omp_get_max_threads();
    if (nblocks > LUB_NEIGHBOURS_MAX_BLOCKS) nblocks = LUB_NEIGHBOURS_MAX_BLOCKS;
    if (nblocks < 1) nblocks = 1;
    size_t place[LUB_NEIGHBOURS_MAX_BLOCKS], room[LUB_NEIGHBOURS_MAX_BLOCKS];
    size_t count[LUB_NEIGHBOURS_MAX_BLOCKS];
    int filled = 0;
    if (nb->nblocks == nblocks) {
        /* one sweep: each block in the room of its last count with a margin (in the thesis
         * wedge's 96-step sample and the dam break no build after the first outgrew it) */
        for (int b = 0; b < nblocks; b++)
            room[b] = nb->block_pairs[b] + nb->block_pairs[b] / 32 + 1024;
        reserve_pairs(nb, place_blocks(nblocks, room, place));
        filled = !fill_sweep(nb, nblocks, place, room, count);
    }
    if (!filled) {
        /* count first: every block gets its exact room */
        count_sweep(nb, nblocks, room);
        reserve_pairs(nb, place_blocks(nblocks, room, place));
        int mismatch = fill_sweep(nb, nblocks, place, room, count);
        for (int b = 0; b < nblocks; b++) mismatch |= count[b] != room[b];
        if (mismatch) lub_bug("neighbour search: the counting and storing sweeps disagree");
        nb->ncounted++;
    }
    nb->npairs = 0;
    for (int b = 0; b < nblocks; b++) nb->npairs += count[b], nb->block_pairs[b] = count[b];
    nb->nblocks = nblocks;
    return escaped;
}

/* Pairs of particle i at the new positions; dim is a literal at the call sites so that the
 * component loops unroll. */
static inline void update_particle(lub_neighbours *nb, double *const x[3], size_t i,
                                   const double L[3], const int dim)
{
    const double re = nb->re;
    const double xi[3] = {x[0][i], x[1][i], dim == 3 ? x[2][i] : 0.0};
    for (size_t k = nb->start[i]; k < nb->end[i]; k++) {
        const size_t j = nb->j[k];
        double r2 = 0.0;
        for (int d = 0; d < dim; d++) {
            const double v = lub_min_image(x[d][j] - xi[d], L[d]);
            nb->dx[d][k] = v;
            r2 += v * v;
        }
        nb->w[k] = lub_mps_weight(sqrt(r2), re);
    }
}

size_t lub_neighbours_moved(const lub_neighbours *nb, double *const x[3], double lim)
{
    const size_t n = nb->n;
    const int dim = nb->dim;
    double L[3];
    for (int d = 0; d < 3; d++) L[d] = d < dim && nb->periodic[d] ? nb->period[d] : 0.0;
    /* displacement since the build (positions then: xs, wrapped), minimum image */
    size_t moved = 0;
#pragma omp parallel for schedule(static) reduction(+ : moved)
    for (size_t i = 0; i < n; i++) {
        double d2 = 0.0;
        for (int d = 0; d < dim; d++) {
            const double v = lub_min_image(x[d][i] - nb->xs[d][nb->spos[i]], L[d]);
            d2 += v * v;
        }
        if (!(d2 <= lim * lim)) moved++;
    }
    return moved;
}

size_t lub_neighbours_update(lub_neighbours *nb, double *const x[3])
{
    const size_t n = nb->n;
    const int dim = nb->dim;
    double L[3];
    for (int d = 0; d < 3; d++) L[d] = d < dim && nb->periodic[d] ? nb->period[d] : 0.0;
    /* when a rebuild is due the pairs are not worth updating */
    const size_t moved = lub_neighbours_moved(nb, x, 0.5 * (nb->rs - nb->re));
    if (moved) return moved;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        if (dim == 2)
            update_particle(nb, x, i, L, 2);
        else
            update_particle(nb, x, i, L, 3);
    }
    return moved;
}

void lub_reorder(size_t n, const uint32_t *perm, void *scratch, void *a, size_t elsize)
{
    if (!a || n == 0) return;
    /* Element types by size so that the gather compiles to plain loads and stores. */
    switch (elsize) {
    case 1: {
        const uint8_t *src = a;
        uint8_t *dst = scratch;
#pragma omp parallel for schedule(static) if (n > 20000)
        for (size_t k = 0; k < n; k++) dst[k] = src[perm[k]];
        break;
    }
    case 2: {
        const uint16_t *src = a;
        uint16_t *dst = scratch;
#pragma omp parallel for schedule(static) if (n > 20000)
        for (size_t k = 0; k < n; k++) dst[k] = src[perm[k]];
        break;
    }
    case 4: {
        const uint32_t *src = a;
        uint32_t *dst = scratch;
#pragma omp parallel for schedule(static) if (n > 20000)
        for (size_t k = 0; k < n; k++) dst[k] = src[perm[k]];
        break;
    }
    case 8: {
        /* doubles and 64-bit integers alike: copied as bytes, no aliasing issue */
        const unsigned char *src = a;
        unsigned char *dst = scratch;
#pragma omp parallel for schedule(static) if (n > 20000)
        for (size_t k = 0; k < n; k++) memcpy(dst + 8 * k, src + 8 * (size_t)perm[k], 8);
        break;
    }
    default: {
        const unsigned char *src = a;
        unsigned char *dst = scratch;
        for (size_t k = 0; k < n; k++)
            memcpy(dst + elsize * k, src + elsize * (size_t)perm[k], elsize);
    }
    }
    /* back in place, on every thread: a single thread's copies were 1.4% of the thesis
     * wedge's step while the other thread waited */
    const size_t bytes = n * elsize;
#pragma omp parallel if (n > 20000)
    {
        const size_t nt = (size_t)omp_get_num_threads(), t = (size_t)omp_get_thread_num();
        const size_t b0 = bytes * t / nt, b1 = bytes * (t + 1) / nt;
        memcpy((unsigned char *)a + b0, (const unsigned char *)scratch + b0, b1 - b0);
    }
}

void lub_reorder_set(size_t n, const uint32_t *perm, void *scratch, int count, void *const *arrays,
                     const size_t *elsize)
{
    for (int m = 0; m < count; m++)
        if (arrays[m]) lub_reorder(n, perm, scratch, arrays[m], elsize[m]);
}
