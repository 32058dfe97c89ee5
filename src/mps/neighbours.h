/* lubkit MPS: neighbour search with a cell-linked list (methods.md §2 step 1).
 *
 * Usage, once per time step (no allocation once the arrays have grown to the run's size):
 *
 *     lub_neighbours nb;
 *     lub_neighbours_init(&nb, dim, re, skin, lo, hi, periodic);     once
 *     ...
 *     size_t escaped = lub_neighbours_build(&nb, n, P->x);            every step
 *     for (size_t i = 0; i < nb.n; i++)
 *         for (size_t k = nb.start[i]; k < nb.end[i]; k++)
 *             j = nb.j[k], r_ij = (nb.dx[0][k], nb.dx[1][k], nb.dx[2][k]), w_ij = nb.w[k]
 *     lub_neighbours_free(&nb);                                       at the end
 *
 * Lists are full (j is in i's list and i in j's), in the caller's particle order (the
 * neighbours of i are entries start[i] .. end[i]-1), each list ordered by neighbouring
 * cell, then by index within a cell: ascending j once the particles are sorted into cell
 * order (lub_neighbours_bin, or _order with h = 0; no periodic direction, whose wrapped cells
 * come first), nearly so while few have moved to another cell since (the rows of a matrix
 * assembled from the lists then come out sorted or nearly: csr.h).  r_ij
 * = r_j - r_i is the minimum-image displacement in periodic directions.  Pairs are those with
 * |r_ij| < rs = re (1 + skin); w_ij = w(|r_ij|, re) (weight.h), so pairs beyond re (possible only
 * with skin > 0) are stored with w = 0.  |r_ij| is not stored: the sweeps are memory-bound,
 * and the operators that need it form it from r_ij.
 *
 * Order for cache locality: after lub_neighbours_bin (or _build), perm[k] is the index of the
 * k-th particle in cell order; after lub_neighbours_order, in the order set by
 * lub_neighbours_set_order (rows of l0: better for the pressure solve).  To sort the caller's
 * structure-of-arrays data:
 *
 *     lub_neighbours_order(&nb, n, x);                   (or lub_neighbours_bin)
 *     lub_reorder(n, nb.perm, scratch, x[0], sizeof(double)); ... for every per-particle array
 *     lub_neighbours_build(&nb, n, x);                   (the lists refer to the new order)
 *
 * Sorting every few tens of steps is enough: particles move far less than a cell per step.
 *
 * Box: cells cover [lo, hi] in each direction.  A periodic direction has period hi - lo,
 * which must be at least 2 rs (so that the pair image within rs is unique); particles
 * outside [lo, hi) there are wrapped for the search (the caller's arrays are not modified).
 * Particles outside a non-periodic direction's [lo, hi] (or with a non-finite coordinate)
 * are clamped into the boundary cells: the search stays exact for them (clamping never
 * separates two particles closer than rs by more than two cells), only slower if many pile
 * up, and they are counted in the return value and in nb.nescaped so that the solver can
 * stop the run.  A particle with a NaN or infinite coordinate has no neighbours.
 *
 * Lists of some particles only: set nb.list_kind (a kind per particle, e.g. P->kind) and
 * nb.list_kinds (a bit per kind) before the build; the others get empty lists.
 *
 * Storage: the particles are split into one block of consecutive particles per thread, and
 * each block's lists follow each other in the arrays from the block's place on; unused
 * entries may lie between two blocks (so end[i] is not always start[i + 1]).  A block's
 * place comes from its pair count in the previous build with a margin, so that a build is a
 * single sweep over the candidates; only when there is no previous build (or it had another
 * number of blocks) or a block outgrows its margin does a counting sweep come first, which
 * gives every block its exact place (nb.ncounted counts those builds).
 * OpenMP over particles; the lists (their pairs and order) do not depend on the number of
 * threads, only where they are stored.
 */
#ifndef LUB_MPS_NEIGHBOURS_H
#define LUB_MPS_NEIGHBOURS_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

/* Cells are at least rs / reach wide (reach: 2, or 1 when cells of rs / 2 would number more
 * than LUB_NEIGHBOURS_FINE_CELLS_MAX): every particle within rs of a point lies in the cells
 * at most `reach` cells away from the point's cell in each direction (a user of the cell
 * grid, such as models/multiResolution/opt.c, must look that far). */
#define LUB_NEIGHBOURS_MAX_REACH      2
#define LUB_NEIGHBOURS_FINE_CELLS_MAX 16777216.0
/* Storage blocks of the lists (see Storage above): one per thread, at most this many. */
#define LUB_NEIGHBOURS_MAX_BLOCKS 256

typedef struct {
    int dim;   /* 2 or 3 */
    double re; /* effective radius of the weight */
    double rs; /* search radius re (1 + skin) */
    double lo[3], hi[3];
    int periodic[3];
    double period[3]; /* hi - lo */

    /* cell grid (row-major, x fastest); unused directions have one cell */
    int nc[3];
    double h[3], inv_h[3]; /* cell size >= rs / reach */
    int reach;             /* cells examined on each side (1 or LUB_NEIGHBOURS_MAX_REACH) */
    size_t ncells;

    /* results of the last build */
    size_t n;        /* particles */
    size_t npairs;   /* entries in the lists (each pair twice) */
    size_t *start;   /* [n] first entry of particle i's list */
    size_t *end;     /* [n] one past its last */
    uint32_t *j;     /* [cap_pairs] neighbour index */
    double *dx[3];   /* [cap_pairs] r_j - r_i, minimum image; dx[2] is NULL in 2-D */
    double *w;       /* [cap_pairs] w(|r_ij|, re) */
    uint32_t *perm;  /* [n] cell order: perm[k] = index of the k-th particle */
    size_t nescaped; /* particles outside the box in a non-periodic direction, or non-finite */

    /* whose lists are built (set before a build; list_kind NULL: every particle's): particle
     * i gets its list when bit list_kind[i] of list_kinds is set, otherwise an empty one.
     * It still appears in the others' lists.  The solver leaves out the dummy particles',
     * which nothing reads (a fifth of the particles in the wedge). */
    const uint8_t *list_kind;
    unsigned list_kinds;

    /* internal */
    uint32_t *cell;     /* [n] cell of particle i */
    uint32_t *spos;     /* [n] position of particle i in cell order */
    double *xs[3];      /* [n] positions (wrapped) in cell order */
    size_t *cell_start; /* [ncells + 1] */
    uint32_t *tcount;   /* [threads x ncells] per-thread cell counts of the binning */
    size_t cap_tcount;
    size_t cap_n, cap_pairs, cap_cells;
    /* storage blocks (see Storage above): their number in the last build (0: none yet) and
     * their pair counts, the next build's estimates */
    int nblocks;
    size_t block_pairs[LUB_NEIGHBOURS_MAX_BLOCKS];
    size_t ncounted; /* builds that needed the counting sweep */

    /* sort order of lub_neighbours_order: rows of spacing order_h (0: cell order) */
    double order_h;
    uint32_t order_n[3]; /* rows in each direction */
    size_t *order_count; /* [max order_n + 1] */
    size_t cap_order;
} lub_neighbours;

/* Set up an empty search structure.  skin >= 0 enlarges the search radius for
 * lub_neighbours_update (0: lists hold exactly the pairs closer than re).  Bad values (re
 * not positive, lo >= hi, a period shorter than 2 rs) are fatal input errors. */
void lub_neighbours_init(lub_neighbours *nb, int dim, double re, double skin, const double lo[3],
                         const double hi[3], const int periodic[3]);
/* Change the box (keeps the arrays; same checks as init). */
void lub_neighbours_set_box(lub_neighbours *nb, const double lo[3], const double hi[3],
                            const int periodic[3]);
void lub_neighbours_free(lub_neighbours *nb);

/* Sort particles into cells: fills cell, perm, and the cell-ordered positions.  x[d][i] are
 * the position components (x[2] unused in 2-D, may be NULL); not modified.  Returns the
 * number of escaped particles. */
size_t lub_neighbours_bin(lub_neighbours *nb, size_t n, double *const x[3]);
/* The order lub_neighbours_order sorts the particles into: lattice rows of spacing h (h = l0,
 * the particle spacing), x fastest, then y, then z, stable in the particle index; h = 0: cell
 * order (lub_neighbours_bin).  Cells are re (about 3 l0) wide, and within a cell the particles
 * keep whatever order they had; sorting by rows of l0 instead makes the order of every
 * neighbourhood the same lexicographic lattice order, and the incomplete-Cholesky
 * preconditioned pressure solve takes about 25% fewer iterations (the wedge).  Allocates the
 * counts for the box (call it after init; set_box keeps it). */
void lub_neighbours_set_order(lub_neighbours *nb, double h);
/* Fill perm with the order set by lub_neighbours_set_order (perm[k] = index of the k-th
 * particle).  Uses the internal arrays as scratch: the lists and positions of the last build
 * are then invalid, so rebuild (lub_neighbours_build) after reordering the particles.  Returns
 * the number of escaped particles. */
size_t lub_neighbours_order(lub_neighbours *nb, size_t n, double *const x[3]);
/* Bin, then build the lists.  Returns the number of escaped particles. */
size_t lub_neighbours_build(lub_neighbours *nb, size_t n, double *const x[3]);
/* Recompute dx, r and w of the stored pairs for moved positions x of the same particles in
 * the same order, e.g. the PND at the temporary positions (T-11) without a new search.  The
 * lists still hold every pair closer than re while each particle has moved less than
 * skin re / 2 since the build; returns the number of particles that moved further (0: the
 * lists are complete and updated; otherwise they are left as they were: rebuild). */
size_t lub_neighbours_update(lub_neighbours *nb, double *const x[3]);
/* The number of particles that moved further than lim from their position at the last build
 * (minimum image).  The lists hold every pair now closer than re - 2 lim while it is 0: a
 * sweep over a shorter distance (the collision model's) can use them with the current
 * positions (lub_neighbours_r). */
size_t lub_neighbours_moved(const lub_neighbours *nb, double *const x[3], double lim);

/* Minimum image of a coordinate difference v for period L (L = 0: not periodic).  Positions
 * kept within the box need at most one period added or removed; the floor is the rare
 * fallback for positions further out. */
static inline double lub_min_image(double v, double L)
{
    if (L == 0.0) return v;
    const double half = 0.5 * L;
    if (v > half) {
        v -= L;
        if (v > half) v -= L * floor(v / L + 0.5);
    } else if (v < -half) {
        v += L;
        if (v < -half) v -= L * floor(v / L + 0.5);
    }
    return v;
}

/* r_ij = r_j - r_i at the positions x (minimum image in periodic directions), not at those
 * of the last build or update: for a pair of the lists after the particles have moved on.
 * Returns |r_ij|^2; v (3 components, v[2] = 0 in 2-D) may be NULL. */
static inline double lub_neighbours_r(const lub_neighbours *nb, double *const x[3], size_t i,
                                      size_t j, double *v)
{
    double r2 = 0.0, c[3] = {0.0, 0.0, 0.0};
    for (int d = 0; d < nb->dim; d++) {
        c[d] = lub_min_image(x[d][j] - x[d][i], nb->periodic[d] ? nb->period[d] : 0.0);
        r2 += c[d] * c[d];
    }
    if (v) v[0] = c[0], v[1] = c[1], v[2] = c[2];
    return r2;
}

/* Apply a permutation to one per-particle array of n elements of elsize bytes:
 * a_new[k] = a_old[perm[k]].  scratch holds at least n * elsize bytes. */
void lub_reorder(size_t n, const uint32_t *perm, void *scratch, void *a, size_t elsize);
/* The same for count arrays (arrays[m] with element size elsize[m]; NULL entries skipped). */
void lub_reorder_set(size_t n, const uint32_t *perm, void *scratch, int count, void *const *arrays,
                     const size_t *elsize);

#endif
