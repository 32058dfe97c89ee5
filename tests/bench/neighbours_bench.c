/* Benchmark of the MPS kernel: neighbour search and operators on a block of particles (a
 * square / cubic lattice of spacing l0 jittered by 0.1 l0, re = 3.1 l0, periodic in x), with 1
 * and 2 threads, in cell order.  Prints microseconds per particle for each phase.
 *
 *     neighbours_bench [n [dim]]       (default 80000 particles, 2-D)
 *
 * Not built by the Makefile; compile with
 *     cc -std=c11 -O2 -fopenmp -Isrc tests/bench/neighbours_bench.c src/mps/neighbours.c \
 *        src/mps/operators.c src/particles/weight.c src/core/error.c -lm -o neighbours_bench
 */
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "mps/neighbours.h"
#include "mps/operators.h"

/* process CPU seconds: with one thread, robust against other jobs on the machine */
static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static uint64_t state = 12345;
static double rnd(void)
{
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(state >> 11) * (1.0 / 9007199254740992.0);
}

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)atol(argv[1]) : 80000;
    const double l0 = 1.0, re = 3.1 * l0;
    const int dim = argc > 2 ? atoi(argv[2]) : 2;
    /* a block twice as long in x as in the other directions */
    size_t ny = dim == 2 ? (size_t)sqrt(n / 2.0) : (size_t)cbrt(n / 2.0);
    size_t nz = dim == 2 ? 1 : ny, nx = n / (ny * nz);
    n = nx * ny * nz;
    double *x[3] = {malloc(n * sizeof(double)), malloc(n * sizeof(double)),
                    malloc(n * sizeof(double))};
    for (size_t k = 0; k < n; k++) {
        x[0][k] = (k % nx + 0.5 + 0.1 * (2 * rnd() - 1)) * l0;
        x[1][k] = (k / nx % ny + 0.5 + 0.1 * (2 * rnd() - 1)) * l0;
        x[2][k] = dim == 2 ? 0.0 : (k / (nx * ny) + 0.5 + 0.1 * (2 * rnd() - 1)) * l0;
    }
    const double lo[3] = {0, 0, 0}, hi[3] = {nx * l0, ny * l0, nz * l0};
    const int per[3] = {1, 0, 0};
    double *f = malloc(n * sizeof(double)), *out = malloc(n * sizeof(double));
    double *g[3] = {malloc(n * sizeof(double)), malloc(n * sizeof(double)),
                    malloc(n * sizeof(double))};
    void *scratch = malloc(n * sizeof(double));
    for (size_t k = 0; k < n; k++) f[k] = sin(0.01 * x[0][k]) + x[1][k];
    double n0, lambda0;
    lub_mps_reference(dim, l0, re, &n0, &lambda0);

    lub_neighbours nb;
    lub_neighbours_init(&nb, dim, re, 0.0, lo, hi, per);
    /* sort once into cell order, as the solver will */
    lub_neighbours_bin(&nb, n, x);
    lub_reorder(n, nb.perm, scratch, x[0], sizeof(double));
    lub_reorder(n, nb.perm, scratch, x[1], sizeof(double));
    lub_reorder(n, nb.perm, scratch, x[2], sizeof(double));
    lub_neighbours_build(&nb, n, x);
    printf("# %d-D, %zu particles, %.2f neighbours per particle, re = 3.1 l0\n", dim, n,
           (double)nb.npairs / n);
    printf("# threads clock      bin    build   update      pnd laplacian gradient    lsmps   "
           "(microseconds per particle)\n");
    /* 1 thread: wall and CPU time (CPU time is robust against other jobs on the machine);
     * 2 threads: wall time */
    for (int config = 0; config < 3; config++) {
        const int threads = config < 2 ? 1 : 2;
        omp_set_num_threads(threads);
        const int reps = 20;
        double t[7] = {0};
        double (*now)(void) = config == 1 ? cpu_seconds : omp_get_wtime;
        for (int r = 0; r < reps; r++) {
            double t0 = now();
            lub_neighbours_bin(&nb, n, x);
            double t1 = now();
            lub_neighbours_build(&nb, n, x);
            double t2 = now();
            lub_neighbours_update(&nb, x);
            double t2u = now();
            lub_mps_pnd(&nb, NULL, out);
            double t3 = now();
            lub_mps_laplacian(&nb, NULL, n0, lambda0, f, out);
            double t4 = now();
            lub_mps_gradient(&nb, NULL, n0, 1, f, g);
            double t5 = now();
            lub_mps_gradient_lsmps(&nb, NULL, n0, 1, 0.0, f, g);
            double t6 = now();
            t[0] += t1 - t0, t[1] += t2 - t1, t[2] += t2u - t2, t[3] += t3 - t2u;
            t[4] += t4 - t3, t[5] += t5 - t4, t[6] += t6 - t5;
        }
        printf("%9d %5s", threads, config == 1 ? "cpu" : "wall");
        for (int k = 0; k < 7; k++) printf(" %8.4f", t[k] / reps / n * 1e6);
        printf("\n");
    }
    lub_neighbours_free(&nb);
    for (int d = 0; d < 3; d++) free(x[d]), free(g[d]);
    free(f), free(out), free(scratch);
    return 0;
}
