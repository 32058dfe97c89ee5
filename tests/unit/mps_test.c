/* Unit tests of src/mps: neighbour search against a brute-force O(n^2) search, reference
 * values against a hand enumeration, and the operators against analytic fields. */
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mps/neighbours.h"
#include "particles/particles.h"
#include "mps/lsmps.h"
#include "mps/mps.h"
#include "mps/operators.h"
#include "particles/weight.h"
#include "test.h"

/* deterministic random numbers in [0, 1) (xorshift64*) */
static uint64_t rng_state = 88172645463325252ull;
static double rnd(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

/* the weight written out again, independently of weight.h */
static double w_ref(double r, double re)
{
    return r < re ? (r / re - 1) * (r / re - 1) : 0.0;
}

typedef struct {
    size_t n, cap;
    double *x[3];
    uint8_t *kind;
} cloud;

static void cloud_init(cloud *c, size_t cap)
{
    c->n = 0, c->cap = cap;
    for (int d = 0; d < 3; d++) c->x[d] = calloc(cap, sizeof(double));
    c->kind = calloc(cap, 1);
}
static void cloud_add(cloud *c, double x, double y, double z, int kind)
{
    if (c->n == c->cap) abort();
    c->x[0][c->n] = x, c->x[1][c->n] = y, c->x[2][c->n] = z, c->kind[c->n] = (uint8_t)kind;
    c->n++;
}
static void cloud_free(cloud *c)
{
    for (int d = 0; d < 3; d++) free(c->x[d]);
    free(c->kind);
}

typedef struct {
    uint32_t j;
    double d[3];
} bpair;

static int bpair_cmp(const void *a, const void *b)
{
    const bpair *p = a, *q = b;
    if (p->j != q->j) return p->j < q->j ? -1 : 1;
    return p->d[0] < q->d[0] ? -1 : p->d[0] > q->d[0];
}

/* Whether two builds hold the same lists (pairs, order, displacements and weights, bit for
 * bit), wherever in their arrays they are stored. */
static int same_lists(const lub_neighbours *a, const lub_neighbours *b)
{
    if (a->n != b->n || a->npairs != b->npairs || a->dim != b->dim) return 0;
    for (size_t i = 0; i < a->n; i++) {
        const size_t len = a->end[i] - a->start[i];
        if (b->end[i] - b->start[i] != len) return 0;
        const size_t p = a->start[i], q = b->start[i];
        if (len == 0) continue;
        if (memcmp(a->j + p, b->j + q, len * sizeof *a->j) != 0 ||
            memcmp(a->w + p, b->w + q, len * sizeof *a->w) != 0)
            return 0;
        for (int d = 0; d < a->dim; d++)
            if (memcmp(a->dx[d] + p, b->dx[d] + q, len * sizeof(double)) != 0) return 0;
    }
    return 1;
}

/* Compare the lists with a brute-force search over all pairs (minimum image by rounding in
 * periodic directions).  Returns the number of particles whose lists differ. */
static size_t compare_brute(const lub_neighbours *nb, const cloud *c, const double lo[3],
                            const double hi[3], const int per[3])
{
    const int dim = nb->dim;
    const double rs = nb->rs, re = nb->re;
    bpair *a = malloc(c->n * sizeof *a), *b = malloc(c->n * sizeof *b);
    size_t bad = 0, total = 0;
    for (size_t i = 0; i < c->n; i++) {
        size_t na = 0;
        for (size_t j = 0; j < c->n; j++) {
            if (j == i) continue;
            double d[3] = {0, 0, 0}, r2 = 0;
            for (int k = 0; k < dim; k++) {
                d[k] = c->x[k][j] - c->x[k][i];
                if (per[k]) d[k] -= (hi[k] - lo[k]) * round(d[k] / (hi[k] - lo[k]));
                r2 += d[k] * d[k];
            }
            if (r2 < rs * rs) a[na].j = (uint32_t)j, memcpy(a[na].d, d, sizeof d), na++;
        }
        size_t nl = nb->end[i] - nb->start[i];
        int ok = nl == na;
        b = realloc(b, (nl + 1) * sizeof *b);
        for (size_t m = 0; m < nl; m++) {
            size_t k = nb->start[i] + m;
            b[m].j = nb->j[k];
            for (int q = 0; q < 3; q++) b[m].d[q] = q < dim ? nb->dx[q][k] : 0.0;
            double r = 0;
            for (int q = 0; q < dim; q++) r += b[m].d[q] * b[m].d[q];
            r = sqrt(r);
            if (fabs(nb->w[k] - w_ref(r, re)) > 1e-14) ok = 0;
        }
        qsort(a, na, sizeof *a, bpair_cmp);
        qsort(b, nl, sizeof *b, bpair_cmp);
        if (ok) {
            for (size_t m = 0; m < na && ok; m++) {
                if (a[m].j != b[m].j) ok = 0;
                for (int q = 0; q < dim; q++)
                    if (fabs(a[m].d[q] - b[m].d[q]) > 1e-12 * rs) ok = 0;
            }
        }
        if (!ok) {
            if (bad < 3)
                printf("  particle %zu: %zu neighbours by brute force, %zu in the lists\n", i, na,
                       nl);
            if (bad < 1 && getenv("MPS_TEST_DEBUG")) {
                for (size_t m = 0; m < na || m < nl; m++)
                    printf("    %u %g %g | %u %g %g\n", m < na ? a[m].j : 0, m < na ? a[m].d[0] : 0,
                           m < na ? a[m].d[1] : 0, m < nl ? b[m].j : 0, m < nl ? b[m].d[0] : 0,
                           m < nl ? b[m].d[1] : 0);
            }
            bad++;
        }
        total += na;
    }
    if (total != nb->npairs) bad++;
    free(a);
    free(b);
    return bad;
}

/* Random particles in a box, with extra particles within rs of every face (the periodic
 * seam), some exactly on lo and hi, and in periodic directions some outside the box. */
static void random_cloud(cloud *c, int dim, size_t n, const double lo[3], const double hi[3],
                         const int per[3], double rs)
{
    cloud_init(c, n + 64);
    for (size_t i = 0; i < n; i++) {
        double p[3] = {0, 0, 0};
        for (int d = 0; d < dim; d++) p[d] = lo[d] + (hi[d] - lo[d]) * rnd();
        if (i % 4 == 0) { /* near a face */
            int d = (int)(rnd() * dim);
            double band = fmin(rs, hi[d] - lo[d]);
            p[d] = rnd() < 0.5 ? lo[d] + band * rnd() : hi[d] - band * rnd();
        }
        cloud_add(c, p[0], p[1], p[2], 0);
    }
    for (int d = 0; d < dim; d++) {
        /* generic fractions: no pair exactly rs apart (a tie decided by round-off) */
        double p[3] = {lo[0] + 0.4871 * (hi[0] - lo[0]), lo[1] + 0.5317 * (hi[1] - lo[1]), 0};
        if (dim == 3) p[2] = lo[2] + 0.4637 * (hi[2] - lo[2]);
        p[d] = lo[d], cloud_add(c, p[0], p[1], p[2], 0);
        p[d] = hi[d], cloud_add(c, p[0], p[1], p[2], 0);
        if (per[d]) {
            p[d] = hi[d] + 0.3137 * rs, cloud_add(c, p[0], p[1], p[2], 0);
            p[d] = lo[d] - 0.2219 * rs, cloud_add(c, p[0], p[1], p[2], 0);
            p[d] = lo[d] - 1e-15, cloud_add(c, p[0], p[1], p[2], 0);
            p[d] = nextafter(lo[d], -INFINITY), cloud_add(c, p[0], p[1], p[2], 0);
            p[d] = hi[d] + 2.5 * (hi[d] - lo[d]), cloud_add(c, p[0], p[1], p[2], 0);
        }
    }
}

/* Build nb (initialised on its box lo..hi) for n random particles in lo..chi (random_cloud,
 * which adds particles near and beyond the periodic ends); returns the pairs found and in
 * *bad the number of particles whose list differs from the brute-force one. */
static size_t build_random(lub_neighbours *nb, int dim, size_t n, const double lo[3],
                           const double chi[3], const double hi[3], const int per[3], size_t *bad)
{
    cloud c;
    random_cloud(&c, dim, n, lo, chi, per, nb->rs);
    lub_neighbours_build(nb, c.n, c.x);
    *bad = compare_brute(nb, &c, lo, hi, per);
    cloud_free(&c);
    return nb->npairs;
}

static void check_search(int dim, size_t n, const double lo[3], const double hi[3],
                         const int per[3], double re, double skin, size_t escaped_expected)
{
    cloud c;
    random_cloud(&c, dim, n, lo, hi, per, re * (1 + skin));
    /* particles outside the box in the non-periodic directions */
    size_t extra = 0;
    for (int d = 0; d < dim; d++)
        if (!per[d]) {
            double p[3] = {lo[0] + 0.3 * (hi[0] - lo[0]), lo[1] + 0.6 * (hi[1] - lo[1]),
                           dim == 3 ? lo[2] + 0.5 * (hi[2] - lo[2]) : 0.0};
            double q[3] = {p[0], p[1], p[2]};
            p[d] = lo[d] - 0.4 * re, q[d] = lo[d] - 0.9 * re; /* a pair of escapers */
            cloud_add(&c, p[0], p[1], p[2], 0), cloud_add(&c, q[0], q[1], q[2], 0);
            p[d] = hi[d] + 3.0 * re, cloud_add(&c, p[0], p[1], p[2], 0);
            extra += 3;
        }
    lub_neighbours nb;
    lub_neighbours_init(&nb, dim, re, skin, lo, hi, per);
    size_t esc = lub_neighbours_build(&nb, c.n, c.x);
    CHECK(esc == extra + escaped_expected);
    CHECK(nb.nescaped == esc);
    CHECK(nb.npairs > 0);
    CHECK(compare_brute(&nb, &c, lo, hi, per) == 0);

    /* the same lists with one and two threads */
    int nt = omp_get_max_threads();
    lub_neighbours nb1;
    lub_neighbours_init(&nb1, dim, re, skin, lo, hi, per);
    omp_set_num_threads(1);
    lub_neighbours_build(&nb1, c.n, c.x);
    omp_set_num_threads(nt > 1 ? nt : 2);
    lub_neighbours_build(&nb, c.n, c.x);
    omp_set_num_threads(nt);
    CHECK(nb1.npairs == nb.npairs);
    CHECK(same_lists(&nb1, &nb));
    lub_neighbours_free(&nb1);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

/* The predictor's running mean (lub_mps_predictor_update) on a gradient that changes by k a
 * step, as a particle's does moving through a steady film: the plain mean (b = 0) lags the
 * next step's gradient by the closed form k/a, Holt's forecast G + T (b > 0) not at all; on a
 * constant it settles to the constant, and b = 0 is the plain G += a (x - G) to the last bit. */
static void test_predictor_trend(void)
{
    const double a = 0.1, k = 3.0, c = 250.0;
    for (int trend = 0; trend < 2; trend++) {
        const double b = trend ? 0.1 : 0.0;
        double G = 0, T = 0, Gplain = 0, x = c;
        for (int n = 0; n < 2000; n++) {
            x = c + k * n;
            lub_mps_predictor_update(&G, &T, x, a, b);
            Gplain += a * (x - Gplain);
            if (!trend) CHECK(G == Gplain && T == 0.0);
        }
        /* the forecast for the next step, whose gradient is x + k: the plain mean stands
         * at x - k (1 - a)/a (k/a behind it), Holt's at x + k */
        CHECK_NEAR(G + T, trend ? x + k : x - k * (1 - a) / a, 1e-9 * x);
    }
    double G = 0, T = 0;
    for (int n = 0; n < 2000; n++) lub_mps_predictor_update(&G, &T, c, a, 0.1);
    CHECK_NEAR(G + T, c, 1e-9 * c);
}

static void test_weight(void)
{
    CHECK(lub_mps_weight(0.0, 2.0) == 1.0);
    CHECK(lub_mps_weight(1.0, 2.0) == 0.25);
    CHECK(lub_mps_weight(2.0, 2.0) == 0.0);
    CHECK(lub_mps_weight(3.0, 2.0) == 0.0);
    CHECK_NEAR(lub_mps_weight(1.5, 2.0), 0.0625, 1e-16);
    /* the branch-free form for listed pairs: the same bits from 0 to past re */
    int same = 1;
    for (int k = 0; k <= 4000; k++) {
        const double re = 3.1e-6, r = 1.5 * re * k / 4000.0 + (k % 7) * 1e-22;
        same &= lub_mps_weight_pair(r, 1.0 / re, re) == lub_mps_weight(r, re);
    }
    same &= lub_mps_weight_pair(3.1e-6, 1.0 / 3.1e-6, 3.1e-6) == 0.0;
    CHECK(same);
}

static void test_search_2d(void)
{
    const double lo[3] = {-0.3, 1.0, 0}, hi[3] = {1.7, 1.9, 0};
    const int none[3] = {0, 0, 0}, px[3] = {1, 0, 0}, pxy[3] = {1, 1, 0};
    check_search(2, 1500, lo, hi, none, 0.13, 0.0, 0);
    check_search(2, 1500, lo, hi, px, 0.13, 0.0, 0);
    check_search(2, 1500, lo, hi, pxy, 0.13, 0.0, 0);
    /* skin: lists to re (1 + skin), pairs beyond re with w = 0 */
    check_search(2, 1500, lo, hi, pxy, 0.1, 0.3, 0);
    /* one cell in y (box thinner than re), x periodic */
    const double hi2[3] = {1.7, 1.05, 0};
    check_search(2, 800, lo, hi2, px, 0.13, 0.0, 0);
}

static void test_search_3d(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1.0, 0.8, 0.6};
    const int none[3] = {0, 0, 0}, pxz[3] = {1, 0, 1}, all[3] = {1, 1, 1};
    check_search(3, 1500, lo, hi, none, 0.15, 0.0, 0);
    check_search(3, 1500, lo, hi, pxz, 0.15, 0.0, 0);
    check_search(3, 1500, lo, hi, all, 0.15, 0.0, 0);
}

/* Periods of exactly 2 rs and just above: two cells per direction, each the neighbour of
 * the other from both sides; the pair image must still be unique. */
static void test_search_short_period(void)
{
    const double lo[3] = {0, 0, 0}, hi2[3] = {0.5, 0.5, 0}, hi3[3] = {0.5, 0.5, 0.6};
    const int pxy[3] = {1, 1, 0}, all[3] = {1, 1, 1};
    check_search(2, 400, lo, hi2, pxy, 0.25, 0.0, 0);
    check_search(2, 400, lo, hi2, pxy, 0.24, 0.0, 0);
    check_search(3, 600, lo, hi3, all, 0.25, 0.0, 0);
}

static void test_search_bad_input(void)
{
    lub_neighbours nb;
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    const int px[3] = {1, 0, 0};
    CHECK_FATAL(lub_neighbours_init(&nb, 2, 0.6, 0.0, lo, hi, px), "shorter than twice");
    CHECK_STR(test_last_error, "in x");
    CHECK_FATAL(lub_neighbours_init(&nb, 2, 0.4, 0.3, lo, hi, px), "shorter than twice");
    CHECK_FATAL(lub_neighbours_init(&nb, 2, 0.0, 0.0, lo, hi, px), "effective radius");
    CHECK_FATAL(lub_neighbours_init(&nb, 2, 0.1, -1.0, lo, hi, px), "skin");
    CHECK_FATAL(lub_neighbours_init(&nb, 4, 0.1, 0.0, lo, hi, px), "dimension");
    const double hi_bad[3] = {1, 0, 1};
    CHECK_FATAL(lub_neighbours_init(&nb, 2, 0.1, 0.0, lo, hi_bad, px), "box in y");
    /* a period of exactly 2 re is accepted, with complete lists (every image examined) */
    lub_neighbours_init(&nb, 2, 0.5, 0.0, lo, hi, px);
    size_t bad;
    CHECK(build_random(&nb, 2, 300, lo, hi, hi, px, &bad) > 0);
    CHECK(bad == 0);
    lub_neighbours_free(&nb);
}

/* NaN and far-away particles do not crash the search; they are counted and have no
 * spurious neighbours. */
static void test_search_escaped(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
    const int px[3] = {1, 0, 0};
    cloud c;
    cloud_init(&c, 8);
    cloud_add(&c, 0.5, 0.5, 0, 0);
    cloud_add(&c, 0.55, 0.5, 0, 0);
    cloud_add(&c, NAN, 0.5, 0, 0);
    cloud_add(&c, 0.5, NAN, 0, 0);
    cloud_add(&c, 0.5, 1e300, 0, 0);
    cloud_add(&c, 0.5, -INFINITY, 0, 0);
    lub_neighbours nb;
    lub_neighbours_init(&nb, 2, 0.2, 0.0, lo, hi, px);
    CHECK(lub_neighbours_build(&nb, c.n, c.x) == 4);
    CHECK(nb.npairs == 2);
    CHECK(nb.end[0] - nb.start[0] == 1 && nb.j[nb.start[0]] == 1);
    CHECK(nb.end[1] - nb.start[1] == 1 && nb.j[nb.start[1]] == 0);
    for (size_t i = 2; i < c.n; i++) CHECK(nb.end[i] == nb.start[i]);
    /* no particles at all */
    CHECK(lub_neighbours_build(&nb, 0, c.x) == 0);
    CHECK(nb.npairs == 0);
    CHECK(lub_neighbours_update(&nb, c.x) == 0);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

/* Cell order: perm is a permutation with non-decreasing cells; after reordering every
 * array and rebuilding, the lists are the same pairs under the relabelling. */
static void test_reorder(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
    const int per[3] = {1, 0, 0};
    cloud c;
    random_cloud(&c, 2, 600, lo, hi, per, 0.1);
    const size_t n = c.n;
    lub_neighbours nb;
    lub_neighbours_init(&nb, 2, 0.1, 0.0, lo, hi, per);
    lub_neighbours_build(&nb, n, c.x);
    double *pnd = malloc(n * sizeof *pnd);
    lub_mps_pnd(&nb, NULL, pnd);

    uint32_t *perm = malloc(n * sizeof *perm);
    memcpy(perm, nb.perm, n * sizeof *perm);
    char *seen = calloc(n, 1);
    int isperm = 1, sorted = 1;
    for (size_t k = 0; k < n; k++) {
        if (perm[k] >= n || seen[perm[k]])
            isperm = 0;
        else
            seen[perm[k]] = 1;
        if (k > 0 && nb.cell[perm[k]] < nb.cell[perm[k - 1]]) sorted = 0;
    }
    CHECK(isperm);
    CHECK(sorted);

    uint8_t *u8 = malloc(n);
    uint16_t *u16 = malloc(n * 2);
    uint64_t *u64 = malloc(n * 8);
    for (size_t i = 0; i < n; i++)
        u8[i] = (uint8_t)(i % 251), u16[i] = (uint16_t)(i * 7), u64[i] = i * 1000003ull;
    void *scratch = malloc(n * 8);
    void *arrays[6] = {c.x[0], c.x[1], u8, u16, u64, pnd};
    size_t sizes[6] = {8, 8, 1, 2, 8, 8};
    lub_reorder_set(n, perm, scratch, 6, arrays, sizes);
    int ok = 1;
    for (size_t k = 0; k < n; k++) {
        size_t i = perm[k];
        if (u8[k] != (uint8_t)(i % 251) || u16[k] != (uint16_t)(i * 7) || u64[k] != i * 1000003ull)
            ok = 0;
    }
    CHECK(ok);
    /* after sorting, the cell order is the identity and the PND is carried along */
    lub_neighbours_build(&nb, n, c.x);
    int ident = 1;
    for (size_t k = 0; k < n; k++) ident &= nb.perm[k] == k;
    CHECK(ident);
    double *pnd2 = malloc(n * sizeof *pnd2), err = 0;
    lub_mps_pnd(&nb, NULL, pnd2);
    for (size_t k = 0; k < n; k++) err = fmax(err, fabs(pnd2[k] - pnd[k]));
    CHECK(err < 1e-13);
    CHECK(compare_brute(&nb, &c, lo, hi, per) == 0);
    free(pnd), free(pnd2), free(perm), free(seen), free(u8), free(u16), free(u64);
    free(scratch);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

/* Lattice-row order (lub_neighbours_order): perm is a permutation, sorted by the rows of
 * spacing h (z, then y, then x; x fastest) as computed here independently, stable in the
 * particle index among equal rows; periodic positions outside the box count at their image,
 * escaped ones in the edge rows.  After reordering and rebuilding, the lists are complete. */
static void check_order(int dim)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 0.5, 0.3}, h = 0.037;
    const int per[3] = {1, 0, 1};
    cloud c;
    cloud_init(&c, 1200);
    for (size_t i = 0; i < 1000; i++) {
        double p[3] = {0, 0, 0};
        for (int d = 0; d < dim; d++) p[d] = lo[d] + (hi[d] - lo[d]) * rnd();
        /* a few rows shared by several particles in every direction (stability) */
        if (i % 7 == 0) p[0] = 0.5 * h + h * floor(27 * rnd());
        if (i % 50 == 1) p[0] += 2.0 * (hi[0] - lo[0]); /* a periodic image */
        if (i % 97 == 3) p[1] = hi[1] + 0.3;            /* escaped: the last y row */
        if (i % 89 == 5) p[1] = lo[1] - 0.2;            /* escaped: the first y row */
        cloud_add(&c, p[0], p[1], p[2], 0);
    }
    const size_t n = c.n;
    lub_neighbours nb;
    lub_neighbours_init(&nb, dim, 0.1, 0.0, lo, hi, per);
    lub_neighbours_set_order(&nb, h);
    size_t escaped = lub_neighbours_order(&nb, n, c.x);
    CHECK(escaped == 11 + 12);
    long *key = malloc(n * sizeof *key);
    for (size_t i = 0; i < n; i++) {
        long k = 0;
        for (int d = dim - 1; d >= 0; d--) {
            double v = c.x[d][i], L = hi[d] - lo[d];
            if (per[d]) v -= L * floor((v - lo[d]) / L);
            long rows = (long)floor(L / h) + 1, r = (long)floor((v - lo[d]) / h);
            r = r < 0 ? 0 : r >= rows ? rows - 1 : r;
            k = k * rows + r;
        }
        key[i] = k;
    }
    char *seen = calloc(n, 1);
    int isperm = 1, sorted = 1;
    for (size_t k = 0; k < n; k++) {
        uint32_t i = nb.perm[k];
        if (i >= n || seen[i])
            isperm = 0;
        else
            seen[i] = 1;
        if (k > 0 && isperm) {
            uint32_t a = nb.perm[k - 1];
            if (key[i] < key[a] || (key[i] == key[a] && i < a)) sorted = 0;
        }
    }
    CHECK(isperm);
    CHECK(sorted);
    void *scratch = malloc(n * 8);
    void *arrays[3] = {c.x[0], c.x[1], dim == 3 ? c.x[2] : NULL};
    size_t sizes[3] = {8, 8, 8};
    lub_reorder_set(n, nb.perm, scratch, 3, arrays, sizes);
    lub_neighbours_build(&nb, n, c.x);
    CHECK(compare_brute(&nb, &c, lo, hi, per) == 0);
    /* h = 0: cell order, as lub_neighbours_bin */
    lub_neighbours_set_order(&nb, 0.0);
    lub_neighbours_order(&nb, n, c.x);
    int cells = 1;
    for (size_t k = 1; k < n; k++) cells &= nb.cell[nb.perm[k]] >= nb.cell[nb.perm[k - 1]];
    CHECK(cells);
    CHECK_FATAL(lub_neighbours_set_order(&nb, -1.0), "sort spacing");
    free(key), free(seen), free(scratch);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

static void test_order_2d(void)
{
    check_order(2);
}
static void test_order_3d(void)
{
    check_order(3);
}

/* The binning runs in chunks of particles on several threads once there are enough of
 * them: its result is the serial counting sort's, a permutation stable by cell (checked
 * here from the cells directly), the same with 1, 2 and 3 threads, escaped particles
 * included.  The particles fill y < 0.5 of a box of height `height`: 0.5 (a quarter of a
 * cell per particle) or 5 (2.5 cells per particle, most of them empty, as in a wedge's box;
 * the scan over the cells then runs on the threads too). */
static void bin_threads(double height)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1.0, height, 0};
    const int per[3] = {1, 0, 0};
    const size_t n = 20000;
    cloud c;
    cloud_init(&c, n);
    size_t nesc = 0;
    for (size_t k = 0; k < n; k++) {
        double y = 0.5 * rnd();
        if (k % 997 == 1) y = hi[1] + 0.05, nesc++;  /* escaped */
        cloud_add(&c, 2.0 * rnd() - 0.5, y, 0.0, 0); /* x: periodic images too */
    }
    lub_neighbours a, b;
    lub_neighbours_init(&a, 2, 0.02, 0.0, lo, hi, per);
    lub_neighbours_init(&b, 2, 0.02, 0.0, lo, hi, per);
    const int nt = omp_get_max_threads();
    omp_set_num_threads(1);
    const size_t ea = lub_neighbours_build(&a, n, c.x);
    int same = 1;
    for (int t = 2; t <= 3; t++) {
        omp_set_num_threads(t);
        const size_t eb = lub_neighbours_build(&b, n, c.x);
        same &= ea == eb && a.npairs == b.npairs;
        same &= memcmp(a.perm, b.perm, n * sizeof *a.perm) == 0;
        same &= memcmp(a.cell, b.cell, n * sizeof *a.cell) == 0;
        same &= memcmp(a.cell_start, b.cell_start, (a.ncells + 1) * sizeof *a.cell_start) == 0;
        same &= same_lists(&a, &b);
    }
    omp_set_num_threads(nt);
    CHECK(same);
    CHECK(ea == nesc);
    int stable = 1;
    for (size_t k = 1; k < n; k++) {
        const uint32_t p = a.perm[k - 1], q = a.perm[k];
        stable &= a.cell[p] < a.cell[q] || (a.cell[p] == a.cell[q] && p < q);
    }
    CHECK(stable);
    CHECK(a.cell_start[a.ncells] == n);
    CHECK(compare_brute(&b, &c, lo, hi, per) == 0);
    lub_neighbours_free(&a);
    lub_neighbours_free(&b);
    cloud_free(&c);
}

static void test_bin_threads(void)
{
    bin_threads(0.5);
    bin_threads(5.0);
}

/* Lists of some kinds only (list_kind, list_kinds): a particle of another kind gets an empty
 * list and stays in the others'; the lists built are those of a full build, entry for entry
 * (the full build is itself checked against brute force above). */
static void check_list_kinds(int dim, const int per[3])
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1.0, 0.6, 0.4}, re = 0.08;
    cloud c;
    random_cloud(&c, dim, dim == 2 ? 3000 : 6000, lo, hi, per, re);
    for (size_t i = 0; i < c.n; i++) c.kind[i] = (uint8_t)(rnd() * 3); /* fluid, wall, dummy */
    lub_neighbours full, part;
    lub_neighbours_init(&full, dim, re, 0.0, lo, hi, per);
    lub_neighbours_init(&part, dim, re, 0.0, lo, hi, per);
    lub_neighbours_build(&full, c.n, c.x);
    part.list_kind = c.kind;
    part.list_kinds = LUB_MPS_KIND(LUB_FLUID) | LUB_MPS_KIND(LUB_WALL);
    lub_neighbours_build(&part, c.n, c.x);
    size_t bad = 0, pairs = 0, ndummy = 0;
    for (size_t i = 0; i < c.n; i++) {
        const size_t nf = full.end[i] - full.start[i], np = part.end[i] - part.start[i];
        if (c.kind[i] == LUB_DUMMY) {
            ndummy++;
            bad += np != 0;
            continue;
        }
        pairs += nf;
        if (np != nf) {
            bad++;
            continue;
        }
        for (size_t m = 0; m < nf; m++) {
            const size_t a = full.start[i] + m, b = part.start[i] + m;
            int same = full.j[a] == part.j[b] && full.w[a] == part.w[b];
            for (int d = 0; d < dim; d++) same &= full.dx[d][a] == part.dx[d][b];
            bad += !same;
        }
    }
    CHECK(ndummy > c.n / 4 && bad == 0 && part.npairs == pairs && pairs < full.npairs);
    printf("  %d-D: %zu particles, %zu dummies: %zu pairs instead of %zu, the rest identical\n",
           dim, c.n, ndummy, part.npairs, full.npairs);
    lub_neighbours_free(&full);
    lub_neighbours_free(&part);
    cloud_free(&c);
}

static void test_list_kinds(void)
{
    const int px[3] = {1, 0, 0}, none[3] = {0, 0, 0};
    check_list_kinds(2, px);
    check_list_kinds(3, none);
}

/* Cells of rs / 2 (reach 2) unless their grid would exceed LUB_NEIGHBOURS_FINE_CELLS_MAX
 * cells: then cells of rs (reach 1), 8 times fewer in 3-D; the lists are complete either way
 * (a big, sparsely filled 3-D box: 260^3 half cells, 130^3 full ones). */
static void test_cell_reach(void)
{
    const double lo[3] = {0, 0, 0}, small[3] = {0.1, 0.1, 0.1}, big[3] = {1.3, 1.3, 1.3};
    const int none[3] = {0, 0, 0};
    const double re = 0.01;
    for (int t = 0; t < 2; t++) {
        const double *hi = t ? big : small;
        lub_neighbours nb;
        lub_neighbours_init(&nb, 3, re, 0.0, lo, hi, none);
        CHECK(nb.reach == (t ? 1 : 2));
        CHECK(t ? nb.ncells <= 131 * 131 * 131 : nb.nc[0] >= 19);
        /* the particles fill the small box (dense: about 30 neighbours each) */
        size_t bad;
        CHECK(build_random(&nb, 3, 8000, lo, small, hi, none, &bad) > 10 * 8000);
        CHECK(bad == 0);
        lub_neighbours_free(&nb);
    }
}

/* Particles in random order sorted into cell order (lub_neighbours_order with h = 0, as
 * lubFoam does every step by default) and rebuilt: every list ascends in j (no periodic
 * direction, whose wrapped cells would come first), so the rows of a matrix assembled from
 * them need no sorting; the lists stay complete. */
static void test_sorted_lists(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {0.4, 0.2, 0.1};
    const int per[3] = {0, 0, 0};
    for (int dim = 2; dim <= 3; dim++) {
        cloud c;
        cloud_init(&c, 1500);
        for (int k = 0; k < 1500; k++)
            cloud_add(&c, hi[0] * rnd(), hi[1] * rnd(), dim == 3 ? hi[2] * rnd() : 0.0, 0);
        lub_neighbours nb;
        lub_neighbours_init(&nb, dim, 0.03, 0.0, lo, hi, per);
        lub_neighbours_set_order(&nb, 0.0);
        lub_neighbours_order(&nb, c.n, c.x);
        void *scratch = malloc(c.n * 8);
        void *arrays[3] = {c.x[0], c.x[1], c.x[2]};
        size_t sizes[3] = {8, 8, 8};
        lub_reorder_set(c.n, nb.perm, scratch, 3, arrays, sizes);
        lub_neighbours_build(&nb, c.n, c.x);
        CHECK(compare_brute(&nb, &c, lo, hi, per) == 0);
        int ascending = 1;
        for (size_t i = 0; i < c.n; i++)
            for (size_t q = nb.start[i] + 1; q < nb.end[i]; q++) ascending &= nb.j[q - 1] < nb.j[q];
        CHECK(ascending);
        CHECK(nb.npairs > 10 * c.n);
        free(scratch);
        lub_neighbours_free(&nb);
        cloud_free(&c);
    }
}

/* n0 and lambda0 of the square lattice at re = 3.1 l0, by hand: the nodes within 3.1 are
 *   (1,0) x4 at 1, (1,1) x4 at sqrt 2, (2,0) x4 at 2, (2,1) x8 at sqrt 5,
 *   (2,2) x4 at sqrt 8 = 2.83, (3,0) x4 at 3;   (3,1) at sqrt 10 = 3.16 is outside. */
static void test_reference_2d(void)
{
    const double re = 3.1;
    const double rr[6] = {1, sqrt(2), 2, sqrt(5), sqrt(8), 3}, cnt[6] = {4, 4, 4, 8, 4, 4};
    double n0 = 0, s = 0;
    for (int k = 0; k < 6; k++) {
        double w = (rr[k] / re - 1) * (rr[k] / re - 1);
        n0 += cnt[k] * w;
        s += cnt[k] * rr[k] * rr[k] * w;
    }
    double n0c, l0c;
    lub_mps_reference(2, 1.0, re, &n0c, &l0c);
    CHECK_REL(n0c, n0, 1e-14);
    CHECK_REL(l0c, s / n0, 1e-14);
    /* scaling: n0 is scale-free, lambda0 goes with l0^2 */
    lub_mps_reference(2, 5e-6, 3.1 * 5e-6, &n0c, &l0c);
    CHECK_REL(n0c, n0, 1e-13);
    CHECK_REL(l0c, s / n0 * 25e-12, 1e-13);
    /* re = 2.1 l0: (1,0) x4, (1,1) x4, (2,0) x4 */
    lub_mps_reference(2, 1.0, 2.1, &n0c, &l0c);
    double a = pow(1 / 2.1 - 1, 2), b = pow(sqrt(2) / 2.1 - 1, 2), c = pow(2 / 2.1 - 1, 2);
    CHECK_REL(n0c, 4 * (a + b + c), 1e-14);
    CHECK_REL(l0c, 4 * (a + 2 * b + 4 * c) / (4 * (a + b + c)), 1e-14);
}

/* 3-D: an independent brute-force enumeration of the cubic lattice. */
static void test_reference_3d(void)
{
    const double l0 = 0.01, re = 3.1 * l0;
    double n0 = 0, s = 0;
    int count = 0;
    for (int a = -5; a <= 5; a++)
        for (int b = -5; b <= 5; b++)
            for (int c = -5; c <= 5; c++) {
                double r = l0 * sqrt(a * a + b * b + c * c);
                if ((a || b || c) && r < re) {
                    n0 += w_ref(r, re), s += r * r * w_ref(r, re);
                    count++;
                }
            }
    CHECK(count == 122); /* the nodes with a^2 + b^2 + c^2 <= 9, minus the centre */
    double n0c, l0c;
    lub_mps_reference(3, l0, re, &n0c, &l0c);
    CHECK_REL(n0c, n0, 1e-13);
    CHECK_REL(l0c, s / n0, 1e-13);
}

/* A (2m+1)^d lattice of spacing l0 with its origin off zero; the particles at least re
 * from the edge are "interior" (their neighbourhood is the full lattice). */
static void lattice(cloud *c, int dim, int m, double l0, const double org[3], double jitter)
{
    size_t nside = (size_t)(2 * m + 1);
    cloud_init(c, dim == 2 ? nside * nside : nside * nside * nside);
    int mz = dim == 3 ? m : 0;
    for (int k = -mz; k <= mz; k++)
        for (int j = -m; j <= m; j++)
            for (int i = -m; i <= m; i++) {
                double p[3] = {org[0] + i * l0, org[1] + j * l0, dim == 3 ? org[2] + k * l0 : 0};
                for (int d = 0; d < dim; d++) p[d] += jitter * l0 * (2 * rnd() - 1);
                cloud_add(c, p[0], p[1], p[2], 0);
            }
}

static int interior(const cloud *c, int dim, size_t i, const double org[3], double half)
{
    for (int d = 0; d < dim; d++)
        if (fabs(c->x[d][i] - org[d]) > half + 1e-9) return 0;
    return 1;
}

static void build_open(lub_neighbours *nb, const cloud *c, int dim, double re)
{
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (size_t i = 0; i < c->n; i++)
        for (int d = 0; d < dim; d++)
            lo[d] = fmin(lo[d], c->x[d][i]), hi[d] = fmax(hi[d], c->x[d][i]);
    const int none[3] = {0, 0, 0};
    lub_neighbours_init(nb, dim, re, 0.0, lo, hi, none);
    CHECK(lub_neighbours_build(nb, c->n, c->x) == 0);
}

/* (T-3): on a full lattice the Laplacian is exact for polynomials of degree <= 3. */
static void check_laplacian_lattice(int dim)
{
    const double l0 = 0.1, re = 3.1 * l0, org[3] = {0.37, -0.21, 0.13};
    const int m = dim == 2 ? 7 : 5;
    cloud c;
    lattice(&c, dim, m, l0, org, 0.0);
    lub_neighbours nb;
    build_open(&nb, &c, dim, re);
    double n0, lambda0;
    lub_mps_reference(dim, l0, re, &n0, &lambda0);
    double *phi = malloc(c.n * sizeof *phi), *lap = malloc(c.n * sizeof *lap);
    double *pnd = malloc(c.n * sizeof *pnd);
    lub_mps_pnd(&nb, NULL, pnd);

    /* random quadratic + cubic: phi = sum A_ab x_a x_b + sum C_abc x_a x_b x_c + b.x + a */
    for (int trial = 0; trial < 4; trial++) {
        double A[3][3], C[3][3][3], bl[3], a0 = rnd();
        for (int p = 0; p < 3; p++) {
            bl[p] = rnd() - 0.5;
            for (int q = 0; q < 3; q++) {
                A[p][q] = trial == 0 ? (p == q) : rnd() - 0.5;
                for (int r = 0; r < 3; r++) C[p][q][r] = trial < 2 ? 0.0 : rnd() - 0.5;
            }
        }
        for (size_t i = 0; i < c.n; i++) {
            double x[3] = {c.x[0][i], c.x[1][i], c.x[2][i]}, f = a0;
            for (int p = 0; p < dim; p++) {
                f += bl[p] * x[p];
                for (int q = 0; q < dim; q++) {
                    f += A[p][q] * x[p] * x[q];
                    for (int r = 0; r < dim; r++) f += C[p][q][r] * x[p] * x[q] * x[r];
                }
            }
            phi[i] = f;
        }
        lub_mps_laplacian(&nb, NULL, n0, lambda0, phi, lap);
        double maxerr = 0, scale = 0;
        size_t nint = 0;
        for (size_t i = 0; i < c.n; i++) {
            if (!interior(&c, dim, i, org, (m - 4) * l0)) continue;
            double x[3] = {c.x[0][i], c.x[1][i], c.x[2][i]}, ex = 0;
            /* lap of x_p x_q is 2 delta_pq; of x_p x_q x_r: 2 (d_pq x_r + d_pr x_q + d_qr x_p) */
            for (int p = 0; p < dim; p++) {
                ex += 2 * A[p][p];
                for (int q = 0; q < dim; q++)
                    ex += 2 * (C[p][p][q] + C[p][q][p] + C[q][p][p]) * x[q];
            }
            maxerr = fmax(maxerr, fabs(lap[i] - ex));
            scale = fmax(scale, fabs(ex));
            CHECK_REL(pnd[i], n0, 1e-13); /* interior PND is n0 */
            nint++;
        }
        CHECK(nint >= (dim == 2 ? 49u : 27u));
        if (trial == 0) CHECK_NEAR(scale, 2.0 * dim, 1e-12); /* |r|^2 -> 2d */
        CHECK(maxerr <= 1e-10 * scale);
        if (!(maxerr <= 1e-10 * scale)) printf("  trial %d: error %g\n", trial, maxerr);
    }

    /* degree 4 is not exact (truncation error of order l0^2): for x^4 at the centre, where
     * the Laplacian 12 x^2 vanishes, the sum of w dx^4 > 0 remains */
    for (size_t i = 0; i < c.n; i++) phi[i] = pow(c.x[0][i] - org[0], 4);
    lub_mps_laplacian(&nb, NULL, n0, lambda0, phi, lap);
    size_t centre = c.n / 2;
    CHECK(fabs(lap[centre]) > 1e-3); /* 12 x^2 = 0 at the centre */

    free(phi), free(lap), free(pnd);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

static void test_laplacian_lattice_2d(void)
{
    check_laplacian_lattice(2);
}
static void test_laplacian_lattice_3d(void)
{
    check_laplacian_lattice(3);
}

/* (T-13, T-14): linear fields at interior lattice particles, with and without the shift;
 * the LSMPS gradient too (on a full lattice M = (1/d) I). */
static void check_gradient_lattice(int dim)
{
    const double l0 = 0.01, re = 3.1 * l0, org[3] = {0.37, -0.21, 0.13};
    const int m = dim == 2 ? 7 : 5;
    cloud c;
    lattice(&c, dim, m, l0, org, 0.0);
    lub_neighbours nb;
    build_open(&nb, &c, dim, re);
    double n0, lambda0;
    lub_mps_reference(dim, l0, re, &n0, &lambda0);
    double *p = malloc(c.n * sizeof *p), *g[3];
    for (int d = 0; d < 3; d++) g[d] = malloc(c.n * sizeof(double));
    const double G[3] = {3.0e5, -1.2e5, 0.7e5}, p0 = 2e5;
    for (size_t i = 0; i < c.n; i++) {
        p[i] = p0;
        for (int d = 0; d < dim; d++) p[i] += G[d] * c.x[d][i];
    }
    for (int variant = 0; variant < 3; variant++) {
        if (variant < 2)
            lub_mps_gradient(&nb, NULL, n0, variant, p, g);
        else
            CHECK(lub_mps_gradient_lsmps(&nb, NULL, n0, 1, 0.0, p, g) == 0);
        double maxerr = 0;
        for (size_t i = 0; i < c.n; i++) {
            if (!interior(&c, dim, i, org, (m - 4) * l0)) continue;
            for (int d = 0; d < dim; d++) maxerr = fmax(maxerr, fabs(g[d][i] - G[d]));
        }
        CHECK(maxerr <= 1e-10 * 3.0e5);
        if (!(maxerr <= 1e-10 * 3.0e5)) printf("  variant %d: error %g\n", variant, maxerr);
    }
    free(p);
    for (int d = 0; d < 3; d++) free(g[d]);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

static void test_gradient_lattice_2d(void)
{
    check_gradient_lattice(2);
}
static void test_gradient_lattice_3d(void)
{
    check_gradient_lattice(3);
}

/* (T-15): LSMPS reproduces linear fields on jittered particles (jitter 0.2 l0), everywhere
 * including the edges and corners of the block (M stays regular there); the standard
 * gradient does not. */
static void check_lsmps_jittered(int dim)
{
    const double l0 = 0.01, re = 3.1 * l0, org[3] = {0.5, 0.25, -0.125};
    const int m = dim == 2 ? 8 : 5;
    cloud c;
    lattice(&c, dim, m, l0, org, 0.2);
    lub_neighbours nb;
    build_open(&nb, &c, dim, re);
    double n0, lambda0;
    lub_mps_reference(dim, l0, re, &n0, &lambda0);
    double *p = malloc(c.n * sizeof *p), *g[3];
    for (int d = 0; d < 3; d++) g[d] = malloc(c.n * sizeof(double));
    const double G[3] = {-2.0e4, 5.0e4, 1.0e4}, p0 = 1e3;
    double gnorm = sqrt(G[0] * G[0] + G[1] * G[1] + (dim == 3 ? G[2] * G[2] : 0));
    for (size_t i = 0; i < c.n; i++) {
        p[i] = p0;
        for (int d = 0; d < dim; d++) p[i] += G[d] * c.x[d][i];
    }
    CHECK(lub_mps_gradient_lsmps(&nb, NULL, n0, 0, 0.0, p, g) == 0);
    double maxerr = 0;
    for (size_t i = 0; i < c.n; i++)
        for (int d = 0; d < dim; d++) maxerr = fmax(maxerr, fabs(g[d][i] - G[d]));
    CHECK(maxerr <= 1e-10 * gnorm);
    if (!(maxerr <= 1e-10 * gnorm)) printf("  LSMPS error %g of %g\n", maxerr, gnorm);

    /* the standard gradient is first-order inconsistent on jittered particles */
    lub_mps_gradient(&nb, NULL, n0, 0, p, g);
    double stderr_ = 0;
    for (size_t i = 0; i < c.n; i++)
        if (interior(&c, dim, i, org, (m - 4 + 0.2) * l0))
            for (int d = 0; d < dim; d++) stderr_ = fmax(stderr_, fabs(g[d][i] - G[d]));
    CHECK(stderr_ > 1e-3 * gnorm);

    /* with the shift, the error is (p_i - p_hat_i) M^-1 (1/n0) sum w r/|r|^2: zero at a
     * particle that holds the local minimum of p */
    CHECK(lub_mps_gradient_lsmps(&nb, NULL, n0, 1, 0.0, p, g) == 0);
    size_t nmin = 0;
    double minerr = 0;
    for (size_t i = 0; i < c.n; i++) {
        int ismin = 1;
        for (size_t k = nb.start[i]; k < nb.end[i]; k++) ismin &= p[nb.j[k]] >= p[i];
        if (!ismin) continue;
        nmin++;
        for (int d = 0; d < dim; d++) minerr = fmax(minerr, fabs(g[d][i] - G[d]));
    }
    CHECK(nmin >= 1);
    CHECK(minerr <= 1e-10 * gnorm);
    free(p);
    for (int d = 0; d < 3; d++) free(g[d]);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

static void test_lsmps_jittered_2d(void)
{
    check_lsmps_jittered(2);
}
static void test_lsmps_jittered_3d(void)
{
    check_lsmps_jittered(3);
}

/* One-sided sets: collinear particles in 2-D, a plane of particles in 3-D, and an isolated
 * particle: M is singular, every particle falls back to the standard gradient. */
static void test_lsmps_fallback(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        const double l0 = 1.0, re = 3.1;
        cloud c;
        cloud_init(&c, 200);
        for (int i = 0; i < 12; i++)
            for (int j = 0; j < (dim == 3 ? 12 : 1); j++)
                cloud_add(&c, i * l0 + 0.3, 0.1 * i, j * l0, 0); /* a line / a tilted plane */
        cloud_add(&c, 40.0, 40.0, 0.0, 0);                       /* isolated */
        lub_neighbours nb;
        build_open(&nb, &c, dim, re);
        double n0, lambda0;
        lub_mps_reference(dim, l0, re, &n0, &lambda0);
        double *p = malloc(c.n * sizeof *p), *g[3], *gs[3];
        for (int d = 0; d < 3; d++)
            g[d] = calloc(c.n, sizeof(double)), gs[d] = calloc(c.n, sizeof(double));
        for (size_t i = 0; i < c.n; i++) p[i] = 1.0 + 2.0 * c.x[0][i] - c.x[1][i] * c.x[1][i];
        CHECK(lub_mps_gradient_lsmps(&nb, NULL, n0, 1, 0.0, p, g) == c.n);
        lub_mps_gradient(&nb, NULL, n0, 1, p, gs);
        int same = 1;
        for (size_t i = 0; i < c.n; i++)
            for (int d = 0; d < dim; d++) same &= g[d][i] == gs[d][i];
        CHECK(same);
        CHECK(g[0][c.n - 1] == 0.0 && g[1][c.n - 1] == 0.0);
        free(p);
        for (int d = 0; d < 3; d++) free(g[d]), free(gs[d]);
        lub_neighbours_free(&nb);
        cloud_free(&c);
    }
    /* the threshold: a half-plane (isotropy ratio 0.95) passes the default and falls back
     * above it */
    cloud c;
    cloud_init(&c, 100);
    for (int j = 0; j <= 4; j++)
        for (int i = -4; i <= 4; i++) cloud_add(&c, i, j, 0, 0);
    lub_neighbours nb;
    build_open(&nb, &c, 2, 3.1);
    double n0, lambda0, *p = calloc(c.n, sizeof *p), *g[3] = {NULL, NULL, NULL};
    for (int d = 0; d < 2; d++) g[d] = calloc(c.n, sizeof(double));
    lub_mps_reference(2, 1.0, 3.1, &n0, &lambda0);
    uint8_t *kind = calloc(c.n, 1);
    kind[4] = 1; /* (0, 0): on the edge of the half plane */
    const lub_mps_mask mk = {kind, LUB_MPS_KIND(1), LUB_MPS_ALL};
    CHECK(lub_mps_gradient_lsmps(&nb, &mk, n0, 0, 0.0, p, g) == 0);
    CHECK(lub_mps_gradient_lsmps(&nb, &mk, n0, 0, 0.96, p, g) == 1);
    CHECK(lub_mps_gradient_lsmps(&nb, &mk, n0, 0, 0.94, p, g) == 0);
    free(p), free(g[0]), free(g[1]), free(kind);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

/* Masks: dummies (kind 2) count in the PND but not in the Laplacian or the gradient; outputs
 * of masked-out particles are untouched. */
static void test_mask(void)
{
    const double l0 = 1.0, re = 2.1, org[3] = {0, 0, 0};
    cloud c;
    lattice(&c, 2, 4, l0, org, 0.0);
    for (size_t i = 0; i < c.n; i++) c.kind[i] = c.x[1][i] < -2.5 ? 2 : (c.x[1][i] < -1.5 ? 1 : 0);
    lub_neighbours nb;
    build_open(&nb, &c, 2, re);
    const size_t n = c.n;
    double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *f = malloc(n * sizeof *f);
    for (size_t i = 0; i < n; i++) f[i] = 1.0 + c.x[0][i] + 3.0 * c.x[1][i] * c.x[1][i];

    const unsigned fw = LUB_MPS_KIND(0) | LUB_MPS_KIND(1);
    const lub_mps_mask mfluid = {c.kind, LUB_MPS_KIND(0), fw};
    for (size_t i = 0; i < n; i++) a[i] = -7.0;
    lub_mps_pnd(&nb, &mfluid, a);
    lub_mps_pnd(&nb, NULL, b);
    int ok = 1;
    for (size_t i = 0; i < n; i++) {
        double s = 0, sall = 0, slap = 0;
        for (size_t j = 0; j < n; j++) {
            if (j == i) continue;
            double r = hypot(c.x[0][j] - c.x[0][i], c.x[1][j] - c.x[1][i]);
            sall += w_ref(r, re);
            if (c.kind[j] != 2) s += w_ref(r, re), slap += (f[j] - f[i]) * w_ref(r, re);
        }
        if (fabs(b[i] - sall) > 1e-13) ok = 0;
        if (c.kind[i] == 0 ? fabs(a[i] - s) > 1e-13 : a[i] != -7.0) ok = 0;
    }
    CHECK(ok);

    double n0, lambda0;
    lub_mps_reference(2, l0, re, &n0, &lambda0);
    for (size_t i = 0; i < n; i++) a[i] = -7.0;
    lub_mps_laplacian(&nb, &mfluid, n0, lambda0, f, a);
    ok = 1;
    for (size_t i = 0; i < n; i++) {
        double slap = 0;
        for (size_t j = 0; j < n; j++) {
            double r = hypot(c.x[0][j] - c.x[0][i], c.x[1][j] - c.x[1][i]);
            if (j != i && c.kind[j] != 2) slap += (f[j] - f[i]) * w_ref(r, re);
        }
        double ex = 4.0 / (lambda0 * n0) * slap;
        if (c.kind[i] == 0 ? fabs(a[i] - ex) > 1e-12 * (1 + fabs(ex)) : a[i] != -7.0) ok = 0;
    }
    CHECK(ok);

    /* gradient: p_hat over fluid and wall neighbours only (dummies hold a very low p) */
    double *p = malloc(n * sizeof *p), *g[3] = {a, b, NULL};
    for (size_t i = 0; i < n; i++) p[i] = c.kind[i] == 2 ? -1e9 : 2.0 + c.x[1][i];
    for (size_t i = 0; i < n; i++) a[i] = b[i] = -7.0;
    lub_mps_gradient(&nb, &mfluid, n0, 1, p, g);
    ok = 1;
    for (size_t i = 0; i < n; i++) {
        if (c.kind[i] != 0) {
            ok &= a[i] == -7.0 && b[i] == -7.0;
            continue;
        }
        double ph = p[i], gx = 0, gy = 0;
        for (size_t j = 0; j < n; j++)
            if (j != i && c.kind[j] != 2 &&
                hypot(c.x[0][j] - c.x[0][i], c.x[1][j] - c.x[1][i]) < re)
                ph = fmin(ph, p[j]);
        for (size_t j = 0; j < n; j++) {
            double dx = c.x[0][j] - c.x[0][i], dy = c.x[1][j] - c.x[1][i];
            double r2 = dx * dx + dy * dy, w = w_ref(sqrt(r2), re);
            if (j == i || c.kind[j] == 2 || w == 0) continue;
            gx += (p[j] - ph) * dx / r2 * w, gy += (p[j] - ph) * dy / r2 * w;
        }
        gx *= 2 / n0, gy *= 2 / n0;
        ok &= fabs(a[i] - gx) < 1e-12 && fabs(b[i] - gy) < 1e-12;
    }
    CHECK(ok);
    free(a), free(b), free(f), free(p);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

/* Skin: lists built with skin 0.3 stay complete while particles move less than 0.15 re;
 * the updated PND equals the brute-force PND at the new positions, including across the
 * periodic seam. */
static void test_update(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0}, re = 0.1, skin = 0.3;
    const int per[3] = {1, 1, 0};
    cloud c;
    random_cloud(&c, 2, 800, lo, hi, per, re * (1 + skin));
    lub_neighbours nb;
    lub_neighbours_init(&nb, 2, re, skin, lo, hi, per);
    lub_neighbours_build(&nb, c.n, c.x);
    for (size_t i = 0; i < c.n; i++)
        for (int d = 0; d < 2; d++) c.x[d][i] += 0.1 * re * (rnd() - 0.5); /* < 0.0707 re */
    CHECK(lub_neighbours_update(&nb, c.x) == 0);
    double *pnd = malloc(c.n * sizeof *pnd);
    lub_mps_pnd(&nb, NULL, pnd);
    double err = 0;
    for (size_t i = 0; i < c.n; i++) {
        double s = 0;
        for (size_t j = 0; j < c.n; j++) {
            if (j == i) continue;
            double r2 = 0;
            for (int d = 0; d < 2; d++) {
                double v = c.x[d][j] - c.x[d][i];
                v -= round(v);
                r2 += v * v;
            }
            s += w_ref(sqrt(r2), re);
        }
        err = fmax(err, fabs(pnd[i] - s));
    }
    CHECK(err < 1e-12);
    /* lub_neighbours_moved: displacements since the build were below 0.0707 re */
    CHECK(lub_neighbours_moved(&nb, c.x, 0.071 * re) == 0);
    CHECK(lub_neighbours_moved(&nb, c.x, 0.0) == c.n);
    /* a particle beyond skin re / 2: rebuild; the lists are left as they were */
    const double dx0 = nb.dx[0][nb.start[5]];
    c.x[0][5] += 0.2 * re;
    CHECK(lub_neighbours_update(&nb, c.x) == 1);
    CHECK(nb.dx[0][nb.start[5]] == dx0);
    CHECK(lub_neighbours_moved(&nb, c.x, 0.071 * re) == 1);
    free(pnd);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

/* No allocation in steady state: rebuilding with the same or fewer particles keeps the
 * arrays; more particles grow them with headroom. */
static void test_no_realloc(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
    const int per[3] = {1, 1, 0};
    cloud c;
    random_cloud(&c, 2, 1000, lo, hi, per, 0.1);
    lub_neighbours nb;
    lub_neighbours_init(&nb, 2, 0.1, 0.0, lo, hi, per);
    lub_neighbours_build(&nb, 900, c.x);
    const void *j = nb.j, *w = nb.w, *st = nb.start;
    size_t capn = nb.cap_n, capp = nb.cap_pairs;
    for (int rep = 0; rep < 3; rep++) {
        for (size_t i = 0; i < c.n; i++) c.x[0][i] += 1e-3 * (rnd() - 0.5);
        lub_neighbours_build(&nb, 900 + 30 * (size_t)rep, c.x);
    }
    CHECK(nb.j == j && nb.w == w && nb.start == st);
    CHECK(nb.cap_n == capn && nb.cap_pairs == capp);
    lub_neighbours_build(&nb, c.n, c.x);
    CHECK(nb.cap_n >= c.n && nb.cap_pairs >= nb.npairs);
    CHECK(compare_brute(&nb, &c, lo, hi, per) == 0);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

/* The single sweep (neighbours.h, Storage): a build after one on nearly the same particles
 * stores the lists without counting; one whose blocks outgrow their room (the particles
 * pressed together: twice the pairs) counts first, as does one on another number of
 * threads; the lists are exact every time (brute force) and, on two threads, the same as on
 * one. */
static void test_one_sweep(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
    const int per[3] = {1, 0, 0};
    const double re = 0.05;
    cloud c;
    random_cloud(&c, 2, 3000, lo, hi, per, re);
    const int nt = omp_get_max_threads();
    omp_set_num_threads(2);
    lub_neighbours nb;
    lub_neighbours_init(&nb, 2, re, 0.0, lo, hi, per);
    lub_neighbours_build(&nb, c.n, c.x);
    CHECK(nb.ncounted == 1 && nb.nblocks == 2);
    CHECK(compare_brute(&nb, &c, lo, hi, per) == 0);
    for (int rep = 0; rep < 3; rep++) {
        for (size_t i = 0; i < c.n; i++) c.x[1][i] += 1e-3 * re * (rnd() - 0.5);
        lub_neighbours_build(&nb, c.n, c.x);
        CHECK(compare_brute(&nb, &c, lo, hi, per) == 0);
    }
    CHECK(nb.ncounted == 1);
    /* every particle moved to 0.7 of its height: about 1 / 0.7 times the pairs */
    const size_t before = nb.npairs;
    for (size_t i = 0; i < c.n; i++) c.x[1][i] = lo[1] + 0.7 * (c.x[1][i] - lo[1]);
    lub_neighbours_build(&nb, c.n, c.x);
    CHECK(nb.npairs > before + before / 4);
    CHECK(nb.ncounted == 2);
    CHECK(compare_brute(&nb, &c, lo, hi, per) == 0);
    /* one thread: one block, counted; the same lists as two blocks */
    lub_neighbours one;
    lub_neighbours_init(&one, 2, re, 0.0, lo, hi, per);
    omp_set_num_threads(1);
    lub_neighbours_build(&one, c.n, c.x);
    lub_neighbours_build(&nb, c.n, c.x);
    CHECK(one.nblocks == 1 && nb.nblocks == 1 && nb.ncounted == 3);
    CHECK(same_lists(&one, &nb));
    omp_set_num_threads(2);
    lub_neighbours_build(&nb, c.n, c.x);
    CHECK(nb.ncounted == 4 && nb.nblocks == 2);
    CHECK(same_lists(&one, &nb));
    omp_set_num_threads(nt);
    lub_neighbours_free(&one);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

/* The LSMPS Laplacian (mps/lsmps.h) reproduces every polynomial of degree <= 2 to round-off
 * on particles jittered by up to 0.3 l0, in 2-D and 3-D; no interior particle is flagged. */
static void check_lsmps_laplacian_poly(int dim)
{
    const double l0 = 0.1, re = 3.1 * l0, org[3] = {0.37, -0.21, 0.13};
    const int m = dim == 2 ? 8 : 5;
    cloud c;
    lattice(&c, dim, m, l0, org, 0.3);
    lub_neighbours nb;
    build_open(&nb, &c, dim, re);
    double *coef = malloc(nb.npairs * sizeof *coef), *f = malloc(c.n * sizeof *f),
           *lap = malloc(c.n * sizeof *lap);
    uint8_t *flag = calloc(c.n, 1);
    lub_mps_lsmps_laplacian(&nb, NULL, dim, l0, 0.0, NULL, coef, flag);
    /* f = 3 + x - 2y + z + 1.5 x^2 - 0.7 xy + 2.5 y^2 (+ 0.8 z^2 - 1.1 yz): lap = 8 (9.6) */
    for (size_t i = 0; i < c.n; i++) {
        double x = c.x[0][i], y = c.x[1][i], z = c.x[2][i];
        f[i] = 3 + x - 2 * y + 1.5 * x * x - 0.7 * x * y + 2.5 * y * y;
        if (dim == 3) f[i] += z + 0.8 * z * z - 1.1 * y * z;
    }
    const double exact = dim == 2 ? 8.0 : 9.6;
    lub_mps_lsmps_apply(&nb, NULL, coef, flag, f, lap);
    double maxerr = 0;
    size_t ninside = 0, nflag = 0;
    for (size_t i = 0; i < c.n; i++) {
        if (!interior(&c, dim, i, org, (m - 4 + 0.3) * l0)) continue;
        ninside++;
        nflag += flag[i];
        if (!flag[i]) maxerr = fmax(maxerr, fabs(lap[i] - exact));
    }
    printf("  LSMPS Laplacian %d-D, quadratic on jittered particles: max error %.3g of %g "
           "(%zu interior, %zu flagged)\n",
           dim, maxerr, exact, ninside, nflag);
    CHECK(ninside > 20 && nflag == 0);
    CHECK(maxerr <= 1e-9 * exact);
    free(coef), free(f), free(lap), free(flag);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}
static void test_lsmps_laplacian_poly_2d(void)
{
    check_lsmps_laplacian_poly(2);
}
static void test_lsmps_laplacian_poly_3d(void)
{
    check_lsmps_laplacian_poly(3);
}

/* Convergence (methods.md §1): f = sin 2x cos 3y + x^2 y, lap f = -13 sin 2x cos 3y + 2 y, on
 * particles jittered by up to 0.15 l0, re = 3.1 l0, in a fixed square of side 0.5 around
 * (0.5, 0.5), l0 = 1/20, 1/40, 1/80: the LSMPS Laplacian's RMS error falls at an observed
 * order of at least 0.8 (degree 2 gives first order on disordered particles), while the
 * standard Laplacian (T-3) does not converge (order below 0.3: its error on disordered
 * particles is of order zero). */
static void test_lsmps_laplacian_rate(void)
{
    const double org[3] = {0.5, 0.5, 0};
    double elsmps[3], estd[3];
    for (int k = 0; k < 3; k++) {
        const double l0 = 1.0 / (20 << k), re = 3.1 * l0;
        const int m = (int)lround(0.5 / l0) + 4;
        cloud c;
        lattice(&c, 2, m, l0, org, 0.15);
        lub_neighbours nb;
        build_open(&nb, &c, 2, re);
        double n0, lambda0;
        lub_mps_reference(2, l0, re, &n0, &lambda0);
        double *coef = malloc(nb.npairs * sizeof *coef), *f = malloc(c.n * sizeof *f),
               *lap = malloc(c.n * sizeof *lap), *lstd = malloc(c.n * sizeof *lstd);
        uint8_t *flag = calloc(c.n, 1);
        lub_mps_lsmps_laplacian(&nb, NULL, 2, l0, 0.0, NULL, coef, flag);
        for (size_t i = 0; i < c.n; i++) {
            double x = c.x[0][i], y = c.x[1][i];
            f[i] = sin(2 * x) * cos(3 * y) + x * x * y;
        }
        lub_mps_lsmps_apply(&nb, NULL, coef, flag, f, lap);
        lub_mps_laplacian(&nb, NULL, n0, lambda0, f, lstd);
        double s1 = 0, s2 = 0, sr = 0;
        size_t cnt = 0;
        for (size_t i = 0; i < c.n; i++) {
            if (!interior(&c, 2, i, org, 0.25)) continue;
            double x = c.x[0][i], y = c.x[1][i], ex = -13 * sin(2 * x) * cos(3 * y) + 2 * y;
            CHECK(!flag[i]);
            s1 += (lap[i] - ex) * (lap[i] - ex);
            s2 += (lstd[i] - ex) * (lstd[i] - ex);
            sr += ex * ex;
            cnt++;
        }
        elsmps[k] = sqrt(s1 / sr), estd[k] = sqrt(s2 / sr);
        printf("  l0 = 1/%d: %zu particles compared, relative RMS error LSMPS %.3g, standard "
               "%.3g\n",
               20 << k, cnt, elsmps[k], estd[k]);
        free(coef), free(f), free(lap), free(lstd), free(flag);
        lub_neighbours_free(&nb);
        cloud_free(&c);
    }
    for (int k = 0; k < 2; k++) {
        double ol = log2(elsmps[k] / elsmps[k + 1]), os = log2(estd[k] / estd[k + 1]);
        printf("  observed order 1/%d -> 1/%d: LSMPS %.2f, standard %.2f\n", 20 << k, 40 << k, ol,
               os);
        CHECK(ol >= 0.8);
        CHECK(os < 0.3);
    }
}

/* An ill-conditioned neighbourhood (a row of particles, here along y = x/2: no second
 * derivative across it) is flagged, its coefficients untouched. */
static void test_lsmps_laplacian_flag(void)
{
    cloud c;
    cloud_init(&c, 16);
    for (int i = 0; i < 10; i++) cloud_add(&c, 0.1 * i, 0.05 * i, 0.0, 0);
    lub_neighbours nb;
    build_open(&nb, &c, 2, 0.31);
    double *coef = malloc((nb.npairs + 1) * sizeof *coef);
    for (size_t q = 0; q < nb.npairs; q++) coef[q] = -7.0;
    uint8_t flag[16] = {0};
    CHECK(lub_mps_lsmps_laplacian(&nb, NULL, 2, 0.1, 0.0, NULL, coef, flag) == 10);
    int untouched = 1;
    for (size_t q = 0; q < nb.npairs; q++) untouched &= coef[q] == -7.0;
    CHECK(untouched);
    free(coef);
    lub_neighbours_free(&nb);
    cloud_free(&c);
}

int main(void)
{
    lub_set_quiet(1);
    RUN(test_weight);
    RUN(test_search_2d);
    RUN(test_search_3d);
    RUN(test_search_short_period);
    RUN(test_search_bad_input);
    RUN(test_search_escaped);
    RUN(test_reorder);
    RUN(test_order_2d);
    RUN(test_order_3d);
    RUN(test_sorted_lists);
    RUN(test_bin_threads);
    RUN(test_cell_reach);
    RUN(test_list_kinds);
    RUN(test_reference_2d);
    RUN(test_reference_3d);
    RUN(test_laplacian_lattice_2d);
    RUN(test_laplacian_lattice_3d);
    RUN(test_gradient_lattice_2d);
    RUN(test_gradient_lattice_3d);
    RUN(test_lsmps_jittered_2d);
    RUN(test_lsmps_jittered_3d);
    RUN(test_lsmps_fallback);
    RUN(test_lsmps_laplacian_poly_2d);
    RUN(test_lsmps_laplacian_poly_3d);
    RUN(test_lsmps_laplacian_rate);
    RUN(test_lsmps_laplacian_flag);
    RUN(test_mask);
    RUN(test_update);
    RUN(test_no_realloc);
    RUN(test_one_sweep);
    RUN(test_predictor_trend);
    return test_summary();
}
