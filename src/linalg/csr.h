/* lubkit linalg: symmetric sparse matrices in compressed sparse row (CSR) form.
 *
 * The pressure Poisson matrix (methods.md §2, thesis T-9) and the implicit-viscosity matrix
 * (T-31) are symmetric positive definite with one row per unknown particle and one entry per
 * neighbour within re.  They are assembled straight into CSR, row by row, by the code that
 * owns the neighbour lists (src/mps/), in two passes that reuse the arrays from step to step:
 *
 *     lub_csr_begin(&A, n);                      pass 1: row lengths
 *     for (i = 0; i < n; i++) lub_csr_set_row_length(&A, i, 1 + nneigh[i]);
 *     lub_csr_alloc(&A);                         grows col/val only when needed
 *     #pragma omp parallel for                   pass 2: fill, rows independent
 *     for (i = 0; i < n; i++) {
 *         int *c = lub_csr_row_col(&A, i); double *v = lub_csr_row_val(&A, i);
 *         ... c[k] = column, v[k] = value, for k < row length, in any order ...
 *     }
 *     lub_csr_finish(&A);                        sorts rows, locates diagonals, checks
 *
 * Storage convention: the FULL symmetric matrix is stored (both triangles), each row with
 * its column indices sorted in increasing order and exactly one diagonal entry, whose
 * position is diag[i] (so entries row_ptr[i] .. diag[i]-1 are the strictly lower part and
 * diag[i]+1 .. row_ptr[i+1]-1 the strictly upper part).  Explicit zeros are allowed: a
 * caller may keep a neighbour pair that has left re with value 0 so that the pattern stays
 * the same over several steps (the CHOLMOD solver then skips its symbolic analysis).
 *
 * Because the matrix is symmetric, this CSR is also its compressed sparse column form, which
 * is what lets CHOLMOD use the arrays without a copy (cholmod_solver.c).
 * Indices are int (CHOLMOD's int interface): nnz must stay below INT_MAX, which is checked.
 */
#ifndef LUB_LINALG_CSR_H
#define LUB_LINALG_CSR_H

#include <stddef.h>

/* Below this many rows the loops of src/linalg run on one thread: a parallel region costs
 * microseconds, and far more when the cores are shared with other processes. */
#define LUB_LINALG_OMP_MIN 4096

typedef struct lub_csr {
    int n;        /* rows = columns */
    int nnz;      /* stored entries, = row_ptr[n] after lub_csr_alloc */
    int *row_ptr; /* n + 1 */
    int *col;     /* nnz, sorted within each row after lub_csr_finish */
    double *val;  /* nnz */
    int *diag;    /* n: position of the diagonal entry of row i in col/val */
    /* capacities (arrays are grown, never shrunk, so steady state allocates nothing) */
    int n_cap;
    int nnz_cap;
    /* incremented by every lub_csr_finish: solvers compare it with the value they saw at
     * set-up to catch a solve with a stale preconditioner or factor */
    unsigned long stamp;
    int finished; /* 1 between lub_csr_finish and the next lub_csr_begin */
    /* A distributed matrix (a run on several ranks, parallel/par.h): these n rows of nglobal,
     * with local columns 0 .. ncols-1 whose global numbers are colmap[c] (the rows' own
     * first, then the columns of other ranks' unknowns).  Serial: ncols = n, colmap NULL.
     * Only the PETSc solver takes a distributed matrix (linalg/linsolve.h). */
    int ncols;
    const int *colmap;
    int nglobal;
} lub_csr;

/* An empty matrix (all arrays NULL); lub_csr_free releases the arrays. */
void lub_csr_init(lub_csr *A);
void lub_csr_free(lub_csr *A);

/* Pass 1: set the size (grows row_ptr/diag when n exceeds the capacity) and the length of
 * each row, diagonal included.  Row lengths must be >= 1. */
void lub_csr_begin(lub_csr *A, int n);
static inline void lub_csr_set_row_length(lub_csr *A, int i, int len)
{
    A->row_ptr[i + 1] = len;
}
/* After lub_csr_begin (which makes the matrix serial again): a distributed matrix of ncols
 * local columns, colmap[c] their global numbers (kept by the caller), nglobal rows in all. */
void lub_csr_set_distributed(lub_csr *A, int ncols, const int *colmap, int nglobal);

/* End of pass 1: prefix sum of the lengths, grows col/val when nnz exceeds the capacity.
 * A fatal run error (exit 2) if nnz would overflow int. */
void lub_csr_alloc(lub_csr *A);

/* Pass 2: the columns and values of row i (row length entries each). */
static inline int *lub_csr_row_col(lub_csr *A, int i)
{
    return A->col + A->row_ptr[i];
}
static inline double *lub_csr_row_val(lub_csr *A, int i)
{
    return A->val + A->row_ptr[i];
}
static inline int lub_csr_row_length(const lub_csr *A, int i)
{
    return A->row_ptr[i + 1] - A->row_ptr[i];
}

/* End of pass 2: sorts each row by column (insertion sort: rows assembled from the neighbour
 * lists of particles in cell order, the diagonal in its place, are sorted or nearly so and
 * cost about one pass), records the diagonal positions, and checks that every column is in
 * range, no column is repeated in a row and each row has its diagonal.  A violation is a bug
 * of the assembling code (lub_bug).  Parallel over rows (OpenMP). */
void lub_csr_finish(lub_csr *A);

/* y = A x (OpenMP over rows).  x and y must not overlap. */
void lub_csr_spmv(const lub_csr *A, const double *x, double *y);

/* The largest |a_ij - a_ji| over the stored entries, relative to the largest |a_ij|
 * (0 for an exactly symmetric matrix); a stored (i,j) without a stored (j,i) counts its full
 * value.  Used by the tests and as a debugging check (O(nnz log(row length))). */
double lub_csr_asymmetry(const lub_csr *A);

/* The value at (i, j), 0 when not stored (binary search in the sorted row). */
double lub_csr_get(const lub_csr *A, int i, int j);

#endif
