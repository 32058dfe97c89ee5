/* The halo of method sfc's ranges against the slabs' on a film unrolled (doc/parallel.md,
 * the cost model of tutorials/README.md): NX x NZ columns of cells of the halo's width w,
 * periodic along x, every column through the film's thickness (the thin axis the curve
 * leaves out); P ranges of equal numbers of columns along lubkit's Hilbert curve over x and
 * z (lub_par_hilbert, as lubFoam -parallel numbers the cells), or P slabs along x.  The halo
 * of a rank is the area within w of its columns and outside them, sampled at S x S points a
 * cell and counted once for each rank that needs it; h = the halos' sum over the owned
 * area (the cost line's "halo ... of the owned particles" for a film of even density).
 *
 *     sfcHalo_bench NX NZ P [S]      (S = 4)
 *     sfcHalo_bench                  the roller at h0/2 (36 x 16 cells, 2 and 4 ranks: the
 *                                    measured halos' check) and the seed's bearing unrolled
 *                                    (609 x 78 cells of 4.1 l0, 64, 252 and 1024 ranks)
 *
 * Built by make bench (build/bench/sfcHalo_bench); a few seconds. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "parallel/par.h"

static int nx_, nz_, parts, samples;
static int *owner; /* [nx_ nz_]: the rank of each column */

/* The halos' area over the owned area. */
static double halo(void)
{
    double h = 0;
    for (int x = 0; x < nx_; x++)
        for (int z = 0; z < nz_; z++)
            for (int i = 0; i < samples; i++)
                for (int j = 0; j < samples; j++) {
                    const double a = (i + 0.5) / samples, b = (j + 0.5) / samples;
                    int seen[9], ns = 0;
                    for (int ox = -1; ox <= 1; ox++)
                        for (int oz = -1; oz <= 1; oz++) {
                            const int cz = z + oz, cx = ((x + ox) % nx_ + nx_) % nx_;
                            if (cz < 0 || cz >= nz_) continue;
                            const int o = owner[cx * nz_ + cz];
                            if (o == owner[x * nz_ + z]) continue;
                            /* the point's distance to the neighbour column, in cells */
                            const double dx = ox == 0 ? 0 : ox < 0 ? a : 1 - a;
                            const double dz = oz == 0 ? 0 : oz < 0 ? b : 1 - b;
                            if (dx * dx + dz * dz >= 1.0) continue;
                            int dup = 0;
                            for (int s = 0; s < ns; s++) dup |= seen[s] == o;
                            if (!dup) seen[ns++] = o;
                        }
                    h += ns;
                }
    return h / ((double)nx_ * nz_ * samples * samples);
}

typedef struct {
    uint64_t key;
    int column;
} keyed;

static int cmp_keyed(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    return (x->key > y->key) - (x->key < y->key);
}

static void estimate(int nx, int nz, int p, int s)
{
    nx_ = nx, nz_ = nz, parts = p, samples = s;
    int bits = 0;
    while ((1 << bits) < (nx > nz ? nx : nz)) bits++;
    const int n = nx * nz;
    keyed *k = malloc((size_t)n * sizeof *k);
    owner = malloc((size_t)n * sizeof *owner);
    for (int x = 0; x < nx; x++)
        for (int z = 0; z < nz; z++) {
            const uint32_t c[3] = {(uint32_t)x, (uint32_t)z, 0};
            k[x * nz + z] = (keyed){lub_par_hilbert(c, 2, bits), x * nz + z};
        }
    qsort(k, (size_t)n, sizeof *k, cmp_keyed);
    for (int q = 0; q < n; q++) owner[k[q].column] = (int)((long)q * parts / n);
    const double hs = halo();
    for (int x = 0; x < nx; x++)
        for (int z = 0; z < nz; z++) owner[x * nz + z] = (int)((long)x * parts / nx);
    printf("%4d x %3d cells, %4d ranks: halo / owned  sfc %.3f  slabs %.3f\n", nx, nz, parts, hs,
           halo());
    free(k);
    free(owner);
}

int main(int argc, char **argv)
{
    if (argc >= 4) {
        estimate(atoi(argv[1]), atoi(argv[2]), atoi(argv[3]), argc > 4 ? atoi(argv[4]) : 4);
        return 0;
    }
    estimate(36, 16, 2, 4);
    estimate(36, 16, 4, 4);
    estimate(609, 78, 64, 4);
    estimate(609, 78, 252, 4);
    estimate(609, 78, 1024, 4);
    return 0;
}
