/* parallel/par: the Hilbert curve of the sfc decomposition (lub_par_hilbert) against the
 * definition of a Hilbert curve (every cell of the 2^bits square or cube once, each step to a
 * face neighbour, beginning at the origin); the slabs' cuts by a parallel selection
 * (lub_par_quantiles), weighted or not, against the
 * order statistics of the whole sorted set, which the all-gather it replaced computed: on one
 * process (MPI's singleton start, no mpirun) the selection runs its bisection and reductions
 * as on many ranks, with every coordinate here.  The cuts over several ranks, and the start
 * on the slabs, are tested under mpirun by tests/cases/parallel.  In a build without MPI it
 * prints SKIP. */
#include <math.h>
#include <stdlib.h>

#include "parallel/par.h"
#include "test.h"

static int cmp(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The reference: cut r = the floor(r n / parts)-th smallest of the sorted coordinates. */
static void sorted_cuts(const double *x, size_t n, int parts, double *cut)
{
    double *s = malloc((n ? n : 1) * sizeof *s);
    for (size_t i = 0; i < n; i++) s[i] = x[i];
    qsort(s, n, sizeof *s, cmp);
    cut[0] = -INFINITY;
    cut[parts] = INFINITY;
    for (int r = 1; r < parts; r++) {
        const size_t k = (size_t)((double)r * (double)n / parts);
        cut[r] = n ? s[k < n ? k : n - 1] : 0.0;
    }
    free(s);
}

static int same_cuts(const double *x, size_t n, int parts)
{
    double a[65], b[65];
    lub_par_quantiles(x, NULL, n, parts, a);
    sorted_cuts(x, n, parts, b);
    int ok = 1;
    for (int r = 0; r <= parts; r++) ok &= a[r] == b[r];
    return ok;
}

static void test_quantiles(void)
{
    enum { N = 5003 };
    double *x = malloc(N * sizeof *x);
    srand(7);
    /* coordinates of both signs over many decades, in random order */
    for (int i = 0; i < N; i++)
        x[i] = (rand() % 2 ? -1 : 1) * pow(10.0, -8 + 10.0 * rand() / (double)RAND_MAX);
    for (int parts = 1; parts <= 64; parts = parts * 3 + 1) CHECK(same_cuts(x, N, parts));
    /* a lattice: columns of equal coordinates (they stay together on one rank) */
    for (int i = 0; i < N; i++) x[i] = 2.5e-6 * (double)((i * 7919) % 61) - 7.5e-5;
    CHECK(same_cuts(x, N, 8));
    CHECK(same_cuts(x, N, 61));
    CHECK(same_cuts(x, N, 64));
    /* one value; extremes; few coordinates for many slabs; none */
    for (int i = 0; i < N; i++) x[i] = 0.125;
    CHECK(same_cuts(x, N, 5));
    x[0] = -1e308, x[1] = 1e308, x[2] = -0.0, x[3] = 5e-324;
    CHECK(same_cuts(x, 4, 3));
    CHECK(same_cuts(x, 3, 16));
    CHECK(same_cuts(x, 0, 4));
    free(x);
}

/* The weighted reference: the pairs sorted by coordinate, cut r the first coordinate at
 * which the running sum of the weights exceeds floor(r W / parts) (the last when none). */
typedef struct {
    double x;
    uint64_t w;
} xw;
static int cmp_xw(const void *a, const void *b)
{
    return cmp(&((const xw *)a)->x, &((const xw *)b)->x);
}
static int same_weighted_cuts(const double *x, const uint64_t *w, size_t n, int parts)
{
    double a[65], b[65];
    lub_par_quantiles(x, w, n, parts, a);
    xw *s = malloc((n ? n : 1) * sizeof *s);
    uint64_t total = 0;
    for (size_t i = 0; i < n; i++) s[i].x = x[i], s[i].w = w[i], total += w[i];
    qsort(s, n, sizeof *s, cmp_xw);
    b[0] = -INFINITY, b[parts] = INFINITY;
    for (int r = 1; r < parts; r++) {
        const uint64_t want = (uint64_t)((double)r * (double)total / parts);
        uint64_t sum = 0;
        size_t k = 0;
        while (k < n) { /* the whole run of equal coordinates counts at once */
            size_t e = k;
            while (e < n && s[e].x == s[k].x) sum += s[e++].w;
            if (sum > want) break;
            k = e;
        }
        b[r] = n ? s[k < n ? k : n - 1].x : 0.0;
    }
    free(s);
    int ok = 1;
    for (int r = 0; r <= parts; r++) ok &= a[r] == b[r];
    return ok;
}

/* Weighted cuts (decomposeParDict weights): against the weighted order statistics of the
 * sorted set; with all weights equal the unweighted cuts; a heavy half moves the cuts into it. */
static void test_weighted_quantiles(void)
{
    enum { N = 4001 };
    double *x = malloc(N * sizeof *x);
    uint64_t *w = malloc(N * sizeof *w);
    srand(11);
    for (int i = 0; i < N; i++) {
        x[i] = (rand() % 2 ? -1 : 1) * pow(10.0, -6 + 6.0 * rand() / (double)RAND_MAX);
        w[i] = (uint64_t)(1 + rand() % 3) * 250; /* the three kinds' weights 0.25, 0.5, 0.75 */
    }
    for (int parts = 1; parts <= 64; parts = parts * 3 + 1)
        CHECK(same_weighted_cuts(x, w, N, parts));
    /* a lattice with its columns of equal coordinates */
    for (int i = 0; i < N; i++) x[i] = 1e-5 * (double)((i * 7919) % 53);
    CHECK(same_weighted_cuts(x, w, N, 8));
    CHECK(same_weighted_cuts(x, w, N, 53));
    /* equal weights: the unweighted cuts */
    for (int i = 0; i < N; i++) w[i] = 1000;
    double a[9], b[9];
    lub_par_quantiles(x, w, N, 8, a);
    lub_par_quantiles(x, NULL, N, 8, b);
    int same = 1;
    for (int r = 0; r <= 8; r++) same &= a[r] == b[r];
    CHECK(same);
    /* x = 0 .. N-1, the first 2001 of weight 3, the rest 1: W = 8003, the 2-way cut where the
     * running weight 3 (k + 1) first exceeds floor(W / 2) = 4001: k = 1333 (unweighted 2000) */
    for (int i = 0; i < N; i++) x[i] = i, w[i] = i < 2001 ? 3 : 1;
    lub_par_quantiles(x, w, N, 2, a);
    CHECK(a[1] == 1333.0);
    lub_par_quantiles(x, NULL, N, 2, a);
    CHECK(a[1] == 2000.0);
    free(x);
    free(w);
}

/* The curve over the 2^bits cube of dim dimensions: the keys are 0 .. 2^(dim bits) - 1, each
 * once (a permutation: the curve visits every cell once), consecutive keys are cells one
 * face apart (Manhattan distance 1: the curve never jumps), key 0 is the origin. */
static int hilbert_curve_ok(int dim, int bits)
{
    const uint64_t side = 1ull << bits, n = dim == 3 ? side * side * side : side * side;
    uint32_t(*cell)[3] = malloc(n * sizeof *cell);
    unsigned char *seen = calloc(n, 1);
    int ok = 1;
    for (uint64_t q = 0; q < n; q++) {
        const uint32_t c[3] = {(uint32_t)(q % side), (uint32_t)(q / side % side),
                               dim == 3 ? (uint32_t)(q / side / side) : 0};
        const uint64_t k = lub_par_hilbert(c, dim, bits);
        if (k >= n || seen[k]) {
            ok = 0;
            break;
        }
        seen[k] = 1;
        for (int d = 0; d < 3; d++) cell[k][d] = c[d];
    }
    for (uint64_t k = 1; ok && k < n; k++) {
        long step = 0;
        for (int d = 0; d < 3; d++) step += labs((long)cell[k][d] - (long)cell[k - 1][d]);
        ok = step == 1;
    }
    if (ok) ok = cell[0][0] == 0 && cell[0][1] == 0 && cell[0][2] == 0;
    free(cell);
    free(seen);
    return ok;
}

static void test_hilbert(void)
{
    for (int bits = 1; bits <= 6; bits++) CHECK(hilbert_curve_ok(2, bits));
    for (int bits = 1; bits <= 5; bits++) CHECK(hilbert_curve_ok(3, bits));
    /* the largest cubes of the key's 63 bits: the corners' keys in range, distinct */
    const uint32_t a[3] = {0, 0, 0}, b[3] = {(1u << 21) - 1, (1u << 21) - 1, (1u << 21) - 1};
    CHECK(lub_par_hilbert(a, 3, 21) == 0);
    CHECK(lub_par_hilbert(b, 3, 21) < (1ull << 63) && lub_par_hilbert(b, 3, 21) > 0);
    const uint32_t e[3] = {(1u << 30) - 1, 0, 0};
    CHECK(lub_par_hilbert(e, 2, 30) == (1ull << 60) - 1); /* the curve ends at (side-1, 0) */
}

int main(int argc, char **argv)
{
    RUN(test_hilbert);
    if (!lub_par_available()) {
        printf("SKIP par_test (the selection): this lubkit was built without MPI\n");
        return test_summary();
    }
    lub_par_start(&argc, &argv);
    RUN(test_quantiles);
    RUN(test_weighted_quantiles);
    return test_summary();
}
