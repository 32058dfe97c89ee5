/* The machine's memory bandwidth, for reading the speed figures of make bench: the solver's
 * big phases (matrix products and sweeps, neighbour-list sweeps) stream arrays far larger
 * than the caches, and the same binary can run 1.5 times slower in one hour than in the next
 * on a shared machine.  Prints one line: the best of 10 passes over 256 MB arrays of a sum
 * (read) and a copy (read and write; the bytes counted are those of the arrays, not the
 * write-allocate traffic), on the threads of OMP_NUM_THREADS.
 *
 *     memory_bench
 */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

int main(void)
{
    const size_t n = (size_t)32 << 20; /* 32 M doubles, 256 MB per array */
    double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    if (!a || !b) {
        fprintf(stderr, "memory_bench: out of memory\n");
        return 1;
    }
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) a[i] = 1.0, b[i] = 0.0; /* first touch by the same threads */
    double tread = 1e30, tcopy = 1e30, check = 0.0;
    for (int rep = 0; rep < 10; rep++) {
        double t = omp_get_wtime();
        double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0; /* four chains: not latency-bound */
#pragma omp parallel for schedule(static) reduction(+ : s0, s1, s2, s3)
        for (size_t i = 0; i < n; i += 4)
            s0 += a[i], s1 += a[i + 1], s2 += a[i + 2], s3 += a[i + 3];
        t = omp_get_wtime() - t;
        if (t < tread) tread = t;
        check += s0 + s1 + s2 + s3;
        t = omp_get_wtime();
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) b[i] = a[i];
        t = omp_get_wtime() - t;
        if (t < tcopy) tcopy = t;
    }
    const double mb = (double)n * sizeof *a;
    printf("memory bandwidth on %d thread(s): read %.1f GB/s, copy %.1f GB/s%s\n",
           omp_get_max_threads(), mb / tread * 1e-9, 2.0 * mb / tcopy * 1e-9,
           check == 10.0 * (double)n && b[n - 1] == 1.0 ? "" : " (check failed)");
    free(a);
    free(b);
    return 0;
}
