/* Benchmark of the elastic half-space displacement (src/models/elastic.h, T-46..T-49): the
 * time of one evaluation of v from p over a uniform patch of N segments, N = 1000 and 3000
 * (not part of make test: a time depends on the machine and its load; moved here from
 * tests/unit/elastic_test.c, which asserted a bound on it).
 *
 *     build/bench/elastic_bench        (make bench builds and runs it)
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "models/elastic.h"

static const double E_ = 1.966e7, W_ = 1000.0, R_ = 0.01;

static uint64_t rng = 88172645463325252ull;
static double rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}

int main(void)
{
    double b = lub_elastic_hertz_half_width(W_, R_, E_);
    int sizes[] = {1000, 3000};
    for (int s = 0; s < 2; s++) {
        int n = sizes[s];
        double *x = malloc(n * sizeof *x), *w = malloc(n * sizeof *w);
        double *p = malloc(n * sizeof *p), *v = malloc(n * sizeof *v);
        if (!x || !w || !p || !v) return 1;
        for (int j = 0; j < n; j++) {
            x[j] = j * 2.5e-6;
            w[j] = 2.5e-6;
            p[j] = rnd();
        }
        lub_elastic_kernel *k = lub_elastic_kernel_create(n, x, w, n, x, E_, b);
        struct timespec t0, t1;
        int reps = s ? 20 : 100;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        for (int r = 0; r < reps; r++) lub_elastic_displacement(k, p, v);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        double dt = (t1.tv_sec - t0.tv_sec + 1e-9 * (t1.tv_nsec - t0.tv_nsec)) / reps;
        printf("elastic displacement, N = %d: %.3f ms per evaluation (%.2f ns per pair)\n", n,
               1e3 * dt, 1e9 * dt / ((double)n * n));
        lub_elastic_kernel_free(k);
        free(x);
        free(w);
        free(p);
        free(v);
    }
    return 0;
}
