/* lubkit linalg: aggregation AMG preconditioner (see amg.h). */
#include "linalg/amg.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

void lub_amg_init(lub_amg *g)
{
    memset(g, 0, sizeof *g);
    g->theta = 0.5;
    g->alpha = 1.8;
    g->coarse_max = 400;
    g->dense_budget = 180.0;
    g->cycle = 2;
    for (int l = 0; l < LUB_AMG_MAX_LEVELS; l++) lub_csr_init(&g->lev[l].own);
}

void lub_amg_free(lub_amg *g)
{
    for (int l = 0; l < LUB_AMG_MAX_LEVELS; l++) {
        lub_csr_free(&g->lev[l].own);
        free(g->lev[l].agg);
        free(g->lev[l].b);
        free(g->lev[l].x);
        free(g->lev[l].tmp);
        free(g->lev[l].r2);
        free(g->lev[l].e2);
        free(g->lev[l].valf);
        free(g->lev[l].mstart);
        free(g->lev[l].mrows);
    }
    free(g->dense);
    free(g->mark);
    memset(g, 0, sizeof *g);
}

int lub_amg_dense_max(const lub_amg *g, int n)
{
    if (!(g->dense_budget > 0)) return g->coarse_max;
    int m = (int)cbrt(3.0 * g->dense_budget * (double)n);
    if (m < 64) m = 64;
    return m < g->coarse_max ? m : g->coarse_max;
}

static void grow_int(int **p, int *cap, int n)
{
    if (n <= *cap && *p) return;
    *cap = n + n / 8 + 16;
    *p = lub_realloc(*p, (size_t)*cap * sizeof **p);
}

/* Greedy aggregation on the strong connections of the rows [r0, r1), numbering the aggregates
 * from 0; returns their number.  Only connections inside the range count (the rows of other
 * ranges are aggregated by other threads at the same time), so the aggregates depend on the
 * ranges, not on the timing. */
static int aggregate_rows(const lub_csr *A, double theta, int *agg, int r0, int r1)
{
    int nc = 0;
    for (int i = r0; i < r1; i++) agg[i] = -1;
    /* pass 1: a node with all strong neighbours free starts an aggregate with them */
    for (int i = r0; i < r1; i++) {
        if (agg[i] >= 0) continue;
        double mx = 0;
        for (int k = A->row_ptr[i]; k < A->row_ptr[i + 1]; k++)
            if (A->col[k] != i && -A->val[k] > mx) mx = -A->val[k];
        const double cut = theta * mx;
        int free_all = 1;
        for (int k = A->row_ptr[i]; k < A->row_ptr[i + 1] && free_all; k++) {
            int j = A->col[k];
            if (j != i && j >= r0 && j < r1 && -A->val[k] > 0 && -A->val[k] >= cut && agg[j] >= 0)
                free_all = 0;
        }
        if (!free_all) continue;
        agg[i] = nc;
        for (int k = A->row_ptr[i]; k < A->row_ptr[i + 1]; k++) {
            int j = A->col[k];
            if (j != i && j >= r0 && j < r1 && -A->val[k] > 0 && -A->val[k] >= cut) agg[j] = nc;
        }
        nc++;
    }
    /* pass 2: the rest join the aggregate of their strongest aggregated neighbour */
    for (int i = r0; i < r1; i++) {
        if (agg[i] >= 0) continue;
        double best = 0;
        int bj = -1;
        for (int k = A->row_ptr[i]; k < A->row_ptr[i + 1]; k++) {
            int j = A->col[k];
            if (j != i && j >= r0 && j < r1 && agg[j] >= 0 && -A->val[k] > best)
                best = -A->val[k], bj = j;
        }
        agg[i] = bj >= 0 ? agg[bj] : nc++;
    }
    return nc;
}

/* Aggregation of all rows: in nb contiguous ranges of rows at once (the smoother's blocks),
 * the aggregates of range t numbered after those of ranges 0 .. t-1.  Returns their number. */
static int aggregate(const lub_csr *A, double theta, int *agg, int nb)
{
    const int n = A->n;
    int count[LUB_AMG_MAX_BLOCKS + 1] = {0};
    if (nb < 1 || n <= LUB_LINALG_OMP_MIN) nb = 1;
    if (nb > LUB_AMG_MAX_BLOCKS) nb = LUB_AMG_MAX_BLOCKS;
#pragma omp parallel for schedule(static, 1) num_threads(nb) if (nb > 1)
    for (int t = 0; t < nb; t++) {
        const int r0 = (int)((long)n * t / nb), r1 = (int)((long)n * (t + 1) / nb);
        count[t + 1] = aggregate_rows(A, theta, agg, r0, r1);
    }
    for (int t = 0; t < nb; t++) count[t + 1] += count[t];
    if (nb > 1)
#pragma omp parallel for schedule(static, 1) num_threads(nb)
        for (int t = 0; t < nb; t++) {
            const int r0 = (int)((long)n * t / nb), r1 = (int)((long)n * (t + 1) / nb);
            for (int i = r0; i < r1; i++) agg[i] += count[t];
        }
    return count[nb];
}

/* The members of each aggregate in increasing order (a counting sort of agg): the rows the
 * Galerkin product sums and the restriction gathers. */
static void members(lub_amg_level *lv, int n)
{
    const int nc = lv->nc;
    grow_int(&lv->mstart, &lv->mstart_cap, nc + 1);
    grow_int(&lv->mrows, &lv->mrows_cap, n);
    int *ms = lv->mstart, *mr = lv->mrows;
    memset(ms, 0, (size_t)(nc + 1) * sizeof *ms);
    for (int i = 0; i < n; i++) ms[lv->agg[i] + 1]++;
    for (int I = 0; I < nc; I++) ms[I + 1] += ms[I];
    for (int i = 0; i < n; i++) mr[ms[lv->agg[i]]++] = i;
    for (int I = nc; I > 0; I--) ms[I] = ms[I - 1]; /* the fill advanced each start to the next */
    ms[0] = 0;
}

/* C = P^T A P for the piecewise-constant P of agg: C_IJ = sum_{i in I, j in J} a_ij, one
 * coarse row per thread at a time (each with its own marker array), the fine rows of an
 * aggregate in increasing order: the same sums in the same order whatever the threads. */
static void galerkin(lub_amg *g, const lub_csr *A, const lub_amg_level *lv, lub_csr *C)
{
    const int nc = lv->nc, nt = omp_get_max_threads();
    const int *agg = lv->agg, *ms = lv->mstart, *mr = lv->mrows;
    const int par = A->n > LUB_LINALG_OMP_MIN;
    grow_int(&g->mark, &g->mark_cap, (par ? nt : 1) * nc);
    /* pass 1: row lengths (distinct coarse columns) */
    lub_csr_begin(C, nc);
#pragma omp parallel if (par)
    {
        int *mark = g->mark + (size_t)omp_get_thread_num() * nc;
        for (int I = 0; I < nc; I++) mark[I] = -1;
#pragma omp for schedule(static)
        for (int I = 0; I < nc; I++) {
            int len = 0;
            for (int t = ms[I]; t < ms[I + 1]; t++) {
                const int i = mr[t];
                for (int k = A->row_ptr[i]; k < A->row_ptr[i + 1]; k++) {
                    const int J = agg[A->col[k]];
                    if (mark[J] != I) mark[J] = I, len++;
                }
            }
            lub_csr_set_row_length(C, I, len);
        }
    }
    lub_csr_alloc(C);
    /* pass 2: sums; mark[J] = position of J in the current coarse row */
#pragma omp parallel if (par)
    {
        int *mark = g->mark + (size_t)omp_get_thread_num() * nc;
        for (int I = 0; I < nc; I++) mark[I] = -1;
#pragma omp for schedule(static)
        for (int I = 0; I < nc; I++) {
            int *c = lub_csr_row_col(C, I);
            double *v = lub_csr_row_val(C, I);
            int len = 0;
            for (int t = ms[I]; t < ms[I + 1]; t++) {
                const int i = mr[t];
                for (int k = A->row_ptr[i]; k < A->row_ptr[i + 1]; k++) {
                    const int J = agg[A->col[k]];
                    if (mark[J] < 0) {
                        mark[J] = len;
                        c[len] = J;
                        v[len++] = 0.0;
                    }
                    v[mark[J]] += A->val[k];
                }
            }
            for (int q = 0; q < len; q++) mark[c[q]] = -1;
        }
    }
    lub_csr_finish(C);
}

/* Dense Cholesky of the coarsest matrix (lower triangle, row-major); -1 if not SPD. */
static int coarse_factor(lub_amg *g, const lub_csr *A)
{
    const int n = A->n;
    size_t need = (size_t)n * (size_t)n;
    if (need > g->dense_cap || !g->dense) {
        /* with headroom (as grow_int): the coarsest size changes by a few rows from step to
         * step, and growing it to the exact size would reallocate whenever it grows */
        const size_t m = (size_t)n + (size_t)n / 8 + 16;
        g->dense = lub_realloc(g->dense, m * m * sizeof *g->dense);
        g->dense_cap = m * m;
    }
    double *D = g->dense;
    memset(D, 0, need * sizeof *D);
    for (int i = 0; i < n; i++)
        for (int k = A->row_ptr[i]; k < A->row_ptr[i + 1]; k++)
            D[(size_t)i * n + A->col[k]] = A->val[k];
    for (int j = 0; j < n; j++) {
        double s = D[(size_t)j * n + j];
        for (int k = 0; k < j; k++) s -= D[(size_t)j * n + k] * D[(size_t)j * n + k];
        if (!(s > 0)) return -1;
        s = sqrt(s);
        D[(size_t)j * n + j] = s;
        for (int i = j + 1; i < n; i++) {
            double t = D[(size_t)i * n + j];
            for (int k = 0; k < j; k++) t -= D[(size_t)i * n + k] * D[(size_t)j * n + k];
            D[(size_t)i * n + j] = t / s;
        }
    }
    g->dense_n = n;
    return 0;
}

/* The level's matrix values in single precision, for its smoother (see amg.h). */
static void smoother_values(lub_amg_level *lv)
{
    const lub_csr *A = lv->A;
    const int nnz = A->nnz;
    if (nnz > lv->valf_cap || !lv->valf) {
        lv->valf_cap = nnz + nnz / 8 + 64;
        lv->valf = lub_realloc(lv->valf, (size_t)lv->valf_cap * sizeof *lv->valf);
    }
    const double *val = A->val;
    float *vf = lv->valf;
#pragma omp parallel for schedule(static) if (nnz > 16 * LUB_LINALG_OMP_MIN)
    for (int k = 0; k < nnz; k++) vf[k] = (float)val[k];
}

int lub_amg_setup(lub_amg *g, const lub_csr *A)
{
    if (!A->finished) lub_bug("lub_amg_setup on a matrix not finished (lub_csr_finish)");
    g->nlev = 0;
    g->coarse_gs = 0;
    g->nblocks = g->blocks > 0 ? g->blocks : omp_get_max_threads();
    if (g->nblocks > LUB_AMG_MAX_BLOCKS) g->nblocks = LUB_AMG_MAX_BLOCKS;
    const lub_csr *M = A;
    const int dense_max = lub_amg_dense_max(g, A->n);
    for (int l = 0;; l++) {
        lub_amg_level *lv = &g->lev[l];
        lv->A = M;
        const int n = M->n;
        if (n > lv->n_cap || !lv->tmp) {
            lv->n_cap = n + n / 8 + 16;
            lv->b = lub_realloc(lv->b, (size_t)lv->n_cap * sizeof *lv->b);
            lv->x = lub_realloc(lv->x, (size_t)lv->n_cap * sizeof *lv->x);
            lv->tmp = lub_realloc(lv->tmp, (size_t)lv->n_cap * sizeof *lv->tmp);
            if (l > 0) { /* the W-cycle repeats the cycles of the coarse levels only */
                lv->r2 = lub_realloc(lv->r2, (size_t)lv->n_cap * sizeof *lv->r2);
                lv->e2 = lub_realloc(lv->e2, (size_t)lv->n_cap * sizeof *lv->e2);
            }
        }
        g->nlev = l + 1;
        if (n <= dense_max) return coarse_factor(g, M);
        smoother_values(lv); /* every level but a dense coarsest one is smoothed */
        grow_int(&lv->agg, &lv->agg_cap, n);
        lv->nc = aggregate(M, g->theta, lv->agg, g->nblocks);
        if (lv->nc > 0.9 * n || l == LUB_AMG_MAX_LEVELS - 1) {
            /* no real coarsening (e.g. no off-diagonal couplings): this level is the
             * coarsest, solved by the dense Cholesky if coarse_max allows (the cost budget
             * gives way: the exact solve is better than none), else smoothed */
            if (n <= g->coarse_max) return coarse_factor(g, M);
            g->coarse_gs = 1;
            return 0;
        }
        members(lv, n);
        galerkin(g, M, lv, &g->lev[l + 1].own);
        M = &g->lev[l + 1].own;
    }
}

/* One Gauss-Seidel sweep (forward or backward) for A x = b on the rows [r0, r1) only, with
 * the level's single-precision values vf ("hybrid" Gauss-Seidel: Gauss-Seidel inside a
 * block, Jacobi between blocks, so that blocks run in parallel).
 *   xo == NULL: the sweep from x = 0, forward: the unknowns outside the range and those not
 *       yet swept are 0, so only the lower part of each row inside the range is read (columns
 *       are sorted: those of earlier blocks come first, then the ones below the diagonal);
 *   xo != NULL: the sweep from the current x, reading the unknowns outside the range from
 *       xo (a copy of x made before the sweep: another block may be updating them).  A row
 *       whose columns all lie in the range takes them from x, without a test per entry. */
static void gs_rows(const lub_csr *A, const float *vf, const double *b, double *x, const double *xo,
                    int r0, int r1, int forward)
{
    const int *rp = A->row_ptr, *col = A->col, *diag = A->diag;
    if (!xo) {
        if (!forward) lub_bug("Gauss-Seidel sweep from 0 must be forward");
        for (int i = r0; i < r1; i++) {
            double s = b[i];
            int k = rp[i];
            while (k < diag[i] && col[k] < r0) k++;
            for (; k < diag[i]; k++) s -= vf[k] * x[col[k]];
            x[i] = s / vf[diag[i]];
        }
        return;
    }
    for (int t = r0; t < r1; t++) {
        const int i = forward ? t : r0 + r1 - 1 - t;
        const int k0 = rp[i], k1 = rp[i + 1], d = diag[i];
        double s = b[i];
        if (col[k0] >= r0 && col[k1 - 1] < r1) {
            for (int k = k0; k < d; k++) s -= vf[k] * x[col[k]];
            for (int k = d + 1; k < k1; k++) s -= vf[k] * x[col[k]];
        } else {
            for (int k = k0; k < k1; k++) {
                const int j = col[k];
                if (j == i) continue;
                s -= vf[k] * (j >= r0 && j < r1 ? x[j] : xo[j]);
            }
        }
        x[i] = s / vf[d];
    }
}

/* A sweep over all rows: one block per thread on the finest levels.  The forward sweep
 * (from 0) and the backward sweep are transposes of each other, which keeps the V-cycle
 * symmetric. */
static void gs_sweep(lub_amg *g, lub_amg_level *lv, const double *b, double *x, int forward,
                     int from_zero)
{
    const lub_csr *A = lv->A;
    const int n = A->n;
    const int nb = n > LUB_LINALG_OMP_MIN ? g->nblocks : 1;
    if (nb == 1) {
        /* one block: nothing outside it (x itself serves as xo) */
        gs_rows(A, lv->valf, b, x, from_zero ? NULL : x, 0, n, forward);
        return;
    }
    const double *xo = NULL;
    if (!from_zero) {
        memcpy(lv->tmp, x, (size_t)n * sizeof *x);
        xo = lv->tmp;
    }
#pragma omp parallel for schedule(static, 1) num_threads(nb)
    for (int t = 0; t < nb; t++) {
        int r0 = (int)((long)n * t / nb), r1 = (int)((long)n * (t + 1) / nb);
        gs_rows(A, lv->valf, b, x, xo, r0, r1, forward);
    }
}

/* res = b - A x, with the level's single-precision values vf (those its smoother uses) */
static void residual(const lub_csr *A, const float *vf, const double *b, const double *x,
                     double *res)
{
    const int n = A->n;
    const int *rp = A->row_ptr, *col = A->col;
    const float *val = vf;
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) {
        double s = b[i];
        for (int k = rp[i]; k < rp[i + 1]; k++) s -= val[k] * x[col[k]];
        res[i] = s;
    }
}

/* The same residual right after the forward sweep from 0 (gs_sweep(.., 1, 1)), for half the
 * work: that sweep made row i exact for the unknowns it saw, b_i = sum_{r0 <= j <= i} a_ij x_j
 * (r0: the first row of i's block; the other blocks' unknowns were 0 to it), so
 *     (b - A x)_i = - sum_{j > i} a_ij x_j - sum_{j < r0} a_ij x_j,
 * the strict upper part of the row and its few columns in earlier blocks (columns are sorted,
 * so those come first).  Equal to residual() to round-off (unit test). */
static void residual_after_forward(const lub_amg *g, const lub_amg_level *lv, const double *x,
                                   double *res)
{
    const lub_csr *A = lv->A;
    const int n = A->n;
    const int nb = n > LUB_LINALG_OMP_MIN ? g->nblocks : 1;
    const int *rp = A->row_ptr, *col = A->col, *diag = A->diag;
    const float *val = lv->valf;
#pragma omp parallel for schedule(static, 1) num_threads(nb) if (nb > 1)
    for (int t = 0; t < nb; t++) {
        const int r0 = (int)((long)n * t / nb), r1 = (int)((long)n * (t + 1) / nb);
        for (int i = r0; i < r1; i++) {
            double s = 0.0;
            for (int k = rp[i]; k < diag[i] && col[k] < r0; k++) s -= val[k] * x[col[k]];
            for (int k = diag[i] + 1; k < rp[i + 1]; k++) s -= val[k] * x[col[k]];
            res[i] = s;
        }
    }
}

/* One cycle on level l for A_l x = b from x = 0: pre-smoothing, the coarse correction (the
 * cycle on level l + 1, repeated g->cycle times on the levels above the coarsest: V or W),
 * post-smoothing. */
static void mg_cycle(lub_amg *g, int l, const double *b, double *x)
{
    lub_amg_level *lv = &g->lev[l];
    const lub_csr *A = lv->A;
    const int n = A->n;
    if (l == g->nlev - 1) {
        if (g->coarse_gs) { /* symmetric: forward from 0, then backward */
            memset(x, 0, (size_t)n * sizeof *x);
            gs_sweep(g, lv, b, x, 1, 1);
            gs_sweep(g, lv, b, x, 0, 0);
            return;
        }
        const double *D = g->dense;
        for (int i = 0; i < n; i++) {
            double s = b[i];
            for (int k = 0; k < i; k++) s -= D[(size_t)i * n + k] * x[k];
            x[i] = s / D[(size_t)i * n + i];
        }
        for (int i = n - 1; i >= 0; i--) {
            double s = x[i];
            for (int k = i + 1; k < n; k++) s -= D[(size_t)k * n + i] * x[k];
            x[i] = s / D[(size_t)i * n + i];
        }
        return;
    }
    lub_amg_level *c = &g->lev[l + 1];
    const int *agg = lv->agg;
    gs_sweep(g, lv, b, x, 1, 1); /* from 0: reads no x it has not written */
    /* restrict the residual: b_c = P^T (b - A x) */
    double *res = lv->tmp;
    if (g->unfused)
        residual(A, lv->valf, b, x, res);
    else
        residual_after_forward(g, lv, x, res);
    /* (gathered per aggregate, its members in increasing order: the sums of a serial
     * scatter c->b[agg[i]] += res[i], in parallel) */
    const int nc = lv->nc, *ms = lv->mstart, *mr = lv->mrows;
    double *bc = c->b;
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
    for (int I = 0; I < nc; I++) {
        double s = 0.0;
        for (int t = ms[I]; t < ms[I + 1]; t++) s += res[mr[t]];
        bc[I] = s;
    }
    mg_cycle(g, l + 1, c->b, c->x);
    if (l + 1 < g->nlev - 1) {
        /* W-cycle: further cycles on the coarse level for its residual (the coarsest level
         * is solved exactly); the coarse levels cost a fraction of the finest, and on the MPS
         * pressure matrix the W-cycle reaches the iteration count of an exact coarse solve */
        const lub_csr *Ac = c->A;
        const int ncl = Ac->n;
        for (int k = 1; k < g->cycle; k++) {
            residual(Ac, c->valf, c->b, c->x, c->r2);
            mg_cycle(g, l + 1, c->r2, c->e2);
            double *xcl = c->x;
            const double *e = c->e2;
#pragma omp parallel for schedule(static) if (ncl > LUB_LINALG_OMP_MIN)
            for (int i = 0; i < ncl; i++) xcl[i] += e[i];
        }
    }
    const double alpha = g->alpha;
    const double *xc = c->x;
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) x[i] += alpha * xc[agg[i]];
    gs_sweep(g, lv, b, x, 0, 0);
}

void lub_amg_apply(lub_amg *g, const double *r, double *z)
{
    mg_cycle(g, 0, r, z);
}
