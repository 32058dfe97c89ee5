/* lubkit linalg: CSR assembly, SpMV and checks (see csr.h for the storage convention). */
#include "linalg/csr.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

void lub_csr_init(lub_csr *A)
{
    memset(A, 0, sizeof *A);
}

void lub_csr_free(lub_csr *A)
{
    free(A->row_ptr);
    free(A->col);
    free(A->val);
    free(A->diag);
    lub_csr_init(A);
}

void lub_csr_begin(lub_csr *A, int n)
{
    if (n < 0) lub_bug("negative matrix size %d", n);
    if (n > A->n_cap || !A->row_ptr) {
        /* grow by a margin so that a slowly growing particle count does not reallocate at
         * every step */
        int cap = n + n / 8 + 16;
        A->row_ptr = lub_realloc(A->row_ptr, (size_t)(cap + 1) * sizeof *A->row_ptr);
        A->diag = lub_realloc(A->diag, (size_t)cap * sizeof *A->diag);
        A->n_cap = cap;
    }
    A->n = n;
    A->ncols = n;
    A->colmap = NULL;
    A->nglobal = 0;
    A->nnz = 0;
    A->row_ptr[0] = 0;
    A->finished = 0;
}

void lub_csr_set_distributed(lub_csr *A, int ncols, const int *colmap, int nglobal)
{
    if (ncols < A->n || !colmap || nglobal < A->n)
        lub_bug("distributed matrix of %d rows: %d columns, %d global", A->n, ncols, nglobal);
    A->ncols = ncols;
    A->colmap = colmap;
    A->nglobal = nglobal;
}

void lub_csr_alloc(lub_csr *A)
{
    long long nnz = 0;
    for (int i = 0; i < A->n; i++) {
        int len = A->row_ptr[i + 1];
        if (len < 1 || len > A->ncols) lub_bug("row %d of %d has length %d", i, A->n, len);
        nnz += len;
        if (nnz > INT_MAX)
            lub_fatal_run("sparse matrix of %d rows has more than %d entries (int indices)", A->n,
                          INT_MAX);
        A->row_ptr[i + 1] = (int)nnz;
    }
    if (nnz > A->nnz_cap || !A->col) {
        long long cap = nnz + nnz / 8 + 64;
        if (cap > INT_MAX) cap = INT_MAX;
        A->col = lub_realloc(A->col, (size_t)cap * sizeof *A->col);
        A->val = lub_realloc(A->val, (size_t)cap * sizeof *A->val);
        A->nnz_cap = (int)cap;
    }
    A->nnz = (int)nnz;
}

/* Sort row i's columns (insertion sort: O(len) when the row is already nearly sorted). */
static void sort_row(int *c, double *v, int len)
{
    for (int k = 1; k < len; k++) {
        int ck = c[k];
        if (c[k - 1] <= ck) continue;
        double vk = v[k];
        int m = k - 1;
        while (m >= 0 && c[m] > ck) {
            c[m + 1] = c[m];
            v[m + 1] = v[m];
            m--;
        }
        c[m + 1] = ck;
        v[m + 1] = vk;
    }
}

void lub_csr_finish(lub_csr *A)
{
    const int n = A->n;
    int bad_row = -1, bad_kind = 0;
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) {
        int *c = A->col + A->row_ptr[i];
        double *v = A->val + A->row_ptr[i];
        const int len = A->row_ptr[i + 1] - A->row_ptr[i];
        /* one pass over a row that is already strictly increasing (the usual case: rows
         * assembled from sorted neighbour lists), finding the diagonal on the way; a row that
         * is not is sorted first */
        int d = -1, k = 1;
        for (; k < len && c[k - 1] < c[k]; k++) d = c[k - 1] == i ? k - 1 : d;
        if (k < len) {
            sort_row(c, v, len);
            d = -1;
            for (k = 1; k < len && c[k - 1] < c[k]; k++) d = c[k - 1] == i ? k - 1 : d;
        }
        if (len > 0 && c[len - 1] == i) d = len - 1;
        int kind = 0;
        if (len > 0 && (c[0] < 0 || c[len - 1] >= A->ncols))
            kind = 1;
        else if (k < len)
            kind = 2; /* sorted, but not strictly: a repeated column */
        else if (d < 0)
            kind = 3;
        A->diag[i] = d < 0 ? -1 : A->row_ptr[i] + d;
        if (kind) {
#pragma omp critical(lub_csr_finish_bad)
            if (bad_row < 0 || i < bad_row) {
                bad_row = i;
                bad_kind = kind;
            }
        }
    }
    if (bad_row >= 0) {
        static const char *what[] = {"", "a column out of range", "a repeated column",
                                     "no diagonal entry"};
        lub_bug("sparse matrix row %d of %d has %s", bad_row, n, what[bad_kind]);
    }
    A->stamp++;
    A->finished = 1;
}

void lub_csr_spmv(const lub_csr *A, const double *x, double *y)
{
    const int n = A->n;
    const int *rp = A->row_ptr, *col = A->col;
    const double *val = A->val;
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) {
        double s = 0.0;
        for (int k = rp[i]; k < rp[i + 1]; k++) s += val[k] * x[col[k]];
        y[i] = s;
    }
}

double lub_csr_get(const lub_csr *A, int i, int j)
{
    int lo = A->row_ptr[i], hi = A->row_ptr[i + 1] - 1;
    while (lo <= hi) {
        int mid = lo + (hi - lo) / 2;
        if (A->col[mid] == j) return A->val[mid];
        if (A->col[mid] < j)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return 0.0;
}

double lub_csr_asymmetry(const lub_csr *A)
{
    double amax = 0.0, dmax = 0.0;
    for (int i = 0; i < A->n; i++) {
        for (int k = A->row_ptr[i]; k < A->row_ptr[i + 1]; k++) {
            int j = A->col[k];
            double d = fabs(A->val[k] - lub_csr_get(A, j, i));
            if (d > dmax || d != d) dmax = d;
            if (fabs(A->val[k]) > amax) amax = fabs(A->val[k]);
        }
    }
    if (dmax != dmax) return dmax; /* NaN propagates */
    return amax > 0 ? dmax / amax : 0.0;
}
