/* lubkit linalg: preconditioned conjugate gradients (see pcg.h).
 *
 * CG in the Hestenes-Stiefel form with the vector operations fused so that each iteration
 * streams the vectors as few times as possible:
 *     q = A p with p.q                     (one pass over A)
 *     x += alpha p, r -= alpha q with r.r  (one pass over x, r, p, q)
 *     z = M^-1 r with r.z                  (jacobi: one pass; ic0/sgs: sweeps then a dot)
 *     p = z + beta p
 */
#include "linalg/pcg.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

const char *const lub_precond_choice_names[] = {"none", "jacobi", "ic0", "sgs",
                                                "bic0", "amg",    NULL};

const char *const lub_amg_cycle_names[] = {"V", "W", NULL};

lub_pcg_options lub_pcg_defaults(void)
{
    lub_pcg_options o = {1e-8, 1000, LUB_PRECOND_JACOBI, 0, 1.0, 0, 2};
    return o;
}

void lub_pcg_work_init(lub_pcg_work *w)
{
    memset(w, 0, sizeof *w);
    lub_amg_init(&w->amg);
}

void lub_pcg_work_free(lub_pcg_work *w)
{
    free(w->r);
    free(w->z);
    free(w->p);
    free(w->q);
    free(w->dinv);
    free(w->l_ptr);
    free(w->l_col);
    free(w->l_val);
    free(w->mark);
    free(w->l_first);
    lub_amg_free(&w->amg);
    lub_pcg_work_init(w);
}

/* Grow the vectors to n (with a margin, see lub_csr_begin). */
static void work_grow(lub_pcg_work *w, int n)
{
    if (n <= w->n_cap && w->r) return;
    int cap = n + n / 8 + 16;
    size_t sz = (size_t)cap * sizeof(double);
    /* the CG vectors: one set per right-hand side of lub_pcg_solve_multi */
    w->r = lub_realloc(w->r, LUB_PCG_MAX_RHS * sz);
    w->z = lub_realloc(w->z, LUB_PCG_MAX_RHS * sz);
    w->p = lub_realloc(w->p, LUB_PCG_MAX_RHS * sz);
    w->q = lub_realloc(w->q, LUB_PCG_MAX_RHS * sz);
    w->dinv = lub_realloc(w->dinv, sz);
    w->l_ptr = lub_realloc(w->l_ptr, (size_t)(cap + 1) * sizeof(int));
    w->l_first = lub_realloc(w->l_first, (size_t)cap * sizeof(int));
    free(w->mark);
    w->mark = lub_malloc((size_t)cap * sizeof(int));
    for (int i = 0; i < cap; i++) w->mark[i] = -1;
    w->n_cap = cap;
}

/* ---- preconditioners ---------------------------------------------------------------- */

static void setup_diag(lub_pcg_work *w, const lub_csr *A)
{
    const int n = A->n;
    const int *diag = A->diag;
    const double *val = A->val;
    double *dinv = w->dinv;
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) {
        double d = val[diag[i]];
        /* a non-positive diagonal cannot come from an SPD matrix: keep the step finite and
         * let CG report the breakdown */
        dinv[i] = d > 0 ? 1.0 / d : 1.0;
    }
}

/* Split the rows into nb contiguous blocks of about equal nonzeros (block IC(0)). */
static void ic0_blocks(lub_pcg_work *w, const lub_csr *A, int nb)
{
    const int n = A->n;
    if (nb < 1) nb = 1;
    if (nb > LUB_PCG_MAX_BLOCKS) nb = LUB_PCG_MAX_BLOCKS;
    if (nb > n) nb = n > 0 ? n : 1;
    w->nblocks = nb;
    w->blk[0] = 0;
    int i = 0;
    for (int t = 1; t < nb; t++) {
        long target = (long)A->nnz * t / nb;
        while (i < n && A->row_ptr[i] < target) i++;
        w->blk[t] = i;
    }
    w->blk[nb] = n;
}

/* Copy the strictly lower pattern of A, restricted to the columns of each row's own block,
 * into the IC(0) factor arrays (rows are sorted: the dropped columns come first). */
static void ic0_pattern(lub_pcg_work *w, const lub_csr *A)
{
    const int n = A->n;
    int nl = 0;
    w->l_ptr[0] = 0;
    for (int t = 0; t < w->nblocks; t++) {
        const int b0 = w->blk[t];
        for (int i = b0; i < w->blk[t + 1]; i++) {
            int k = A->row_ptr[i];
            while (A->col[k] < b0) k++;
            w->l_first[i] = k;
            nl += A->diag[i] - k;
            w->l_ptr[i + 1] = nl;
        }
    }
    if (nl > w->nnz_cap || !w->l_col) {
        int cap = nl + nl / 8 + 64;
        w->l_col = lub_realloc(w->l_col, (size_t)cap * sizeof(int));
        w->l_val = lub_realloc(w->l_val, (size_t)cap * sizeof *w->l_val);
        w->nnz_cap = cap;
    }
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++)
        memcpy(w->l_col + w->l_ptr[i], A->col + w->l_first[i],
               (size_t)(w->l_ptr[i + 1] - w->l_ptr[i]) * sizeof(int));
}

/* IC(0) of the rows [r0, r1), row by row: for k < i in the pattern of row i,
 *     L_ik = (a_ik - sum_{j < k} L_ij L_kj) / L_kk,   L_ii = sqrt(a_ii - sum_{k < i} L_ik^2),
 * the sums running over the pattern only (zero fill).  mark[j] holds the position of L_ij
 * while row i is processed (blocks touch disjoint parts of mark).  Returns -1 on success,
 * else the row of the first non-positive pivot.  The diagonal used is (1 + shift) a_ii. */
static int ic0_factor_rows(lub_pcg_work *w, const lub_csr *A, double shift, int r0, int r1)
{
    const int *lp = w->l_ptr, *lc = w->l_col;
    float *lv = w->l_val;
    double *dinv = w->dinv;
    int *mark = w->mark;
    for (int i = r0; i < r1; i++) {
        const int b = lp[i], e = lp[i + 1];
        const double *arow = A->val + w->l_first[i]; /* aligned with L's row i */
        for (int m = b; m < e; m++) mark[lc[m]] = m;
        double d = (1.0 + shift) * A->val[A->diag[i]];
        for (int m = b; m < e; m++) {
            const int k = lc[m];
            double s = arow[m - b];
            /* row k of L, columns j < k; L_ij is final since j < k was done before */
            for (int t = lp[k]; t < lp[k + 1]; t++) {
                int pos = mark[lc[t]];
                if (pos >= 0) s -= lv[pos] * lv[t];
            }
            s *= dinv[k];
            lv[m] = (float)s;
            s = lv[m]; /* the factor is the stored one */
            d -= s * s;
        }
        for (int m = b; m < e; m++) mark[lc[m]] = -1;
        if (!(d > 0)) return i;
        dinv[i] = 1.0 / sqrt(d);
    }
    return -1;
}

/* All blocks (in parallel); returns the first failing row or -1. */
static int ic0_factor(lub_pcg_work *w, const lub_csr *A, double shift)
{
    int bad = -1;
    const int nb = w->nblocks;
#pragma omp parallel for schedule(static, 1) if (nb > 1) reduction(max : bad)
    for (int t = 0; t < nb; t++) {
        int r = ic0_factor_rows(w, A, shift, w->blk[t], w->blk[t + 1]);
        if (r > bad) bad = r;
    }
    return bad;
}

/* z = (L L^T)^-1 r on the rows [r0, r1): forward L y = r (rows of L), backward L^T z = y
 * (columns of L^T are the rows of L, so the backward sweep scatters). */
static void ic0_apply_rows(const lub_pcg_work *w, int r0, int r1, const double *r, double *z)
{
    const int *lp = w->l_ptr, *lc = w->l_col;
    const float *lv = w->l_val;
    const double *dinv = w->dinv;
    for (int i = r0; i < r1; i++) {
        double s = r[i];
        for (int m = lp[i]; m < lp[i + 1]; m++) s -= lv[m] * z[lc[m]];
        z[i] = s * dinv[i];
    }
    for (int i = r1 - 1; i >= r0; i--) {
        double zi = z[i] * dinv[i];
        z[i] = zi;
        for (int m = lp[i]; m < lp[i + 1]; m++) z[lc[m]] -= lv[m] * zi;
    }
}

static void ic0_apply(const lub_pcg_work *w, const double *r, double *z)
{
    const int nb = w->nblocks;
#pragma omp parallel for schedule(static, 1) if (nb > 1)
    for (int t = 0; t < nb; t++) ic0_apply_rows(w, w->blk[t], w->blk[t + 1], r, z);
}

/* SSOR: z = (D/omega + U)^-1 D (D/omega + L)^-1 r (the factor omega/(2-omega) of the
 * textbook M is dropped: CG does not depend on the scale of M). */
static void sgs_apply(const lub_pcg_work *w, const lub_csr *A, double omega, const double *r,
                      double *z)
{
    const int n = A->n;
    const int *rp = A->row_ptr, *col = A->col, *diag = A->diag;
    const double *val = A->val, *dinv = w->dinv;
    for (int i = 0; i < n; i++) {
        double s = r[i];
        for (int k = rp[i]; k < diag[i]; k++) s -= val[k] * z[col[k]];
        z[i] = omega * s * dinv[i];
    }
    /* backward: (D/omega + U) z = D y, y held in z */
    for (int i = n - 1; i >= 0; i--) {
        double s = 0.0;
        for (int k = diag[i] + 1; k < rp[i + 1]; k++) s += val[k] * z[col[k]];
        z[i] = z[i] - omega * s * dinv[i];
    }
}

double lub_pcg_setup(lub_pcg_work *w, const lub_csr *A, const lub_pcg_options *o)
{
    if (!A->finished) lub_bug("lub_pcg_setup on a matrix not finished (lub_csr_finish)");
    work_grow(w, A->n);
    w->precond = o->precond;
    w->precond_used = o->precond;
    w->omega = o->omega;
    w->blocks_opt = o->blocks;
    w->amg.cycle = o->cycle;
    w->ic_shift = 0.0;
    switch (o->precond) {
    case LUB_PRECOND_NONE:
        break;
    case LUB_PRECOND_JACOBI:
    case LUB_PRECOND_SGS:
        setup_diag(w, A);
        break;
    case LUB_PRECOND_IC0:
    case LUB_PRECOND_BIC0: {
        ic0_blocks(w, A,
                   o->precond != LUB_PRECOND_BIC0 ? 1
                   : o->blocks > 0                ? o->blocks
                                                  : omp_get_max_threads());
        ic0_pattern(w, A);
        double shift = 0.0;
        while (ic0_factor(w, A, shift) >= 0) {
            shift = shift == 0.0 ? 1e-3 : 10.0 * shift;
            if (shift > 100.0) {
                /* not even A + 100 diag(A) factors: A is far from SPD; Jacobi lets CG run
                 * and report the breakdown */
                w->precond_used = LUB_PRECOND_JACOBI;
                setup_diag(w, A);
                shift = -1.0;
                break;
            }
        }
        w->ic_shift = shift;
        break;
    }
    case LUB_PRECOND_AMG:
        if (lub_amg_setup(&w->amg, A) != 0) {
            w->precond_used = LUB_PRECOND_JACOBI;
            setup_diag(w, A);
            w->ic_shift = -1.0;
        }
        break;
    default:
        lub_bug("unknown preconditioner %d", (int)o->precond);
    }
    w->A = A;
    w->stamp = A->stamp;
    w->ready = 1;
    return w->ic_shift;
}

void lub_pcg_precond_apply(lub_pcg_work *w, const lub_csr *A, const double *r, double *z)
{
    const int n = A->n;
    switch (w->precond_used) {
    case LUB_PRECOND_NONE:
        memcpy(z, r, (size_t)n * sizeof *z);
        break;
    case LUB_PRECOND_JACOBI: {
        const double *dinv = w->dinv;
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
        for (int i = 0; i < n; i++) z[i] = dinv[i] * r[i];
        break;
    }
    case LUB_PRECOND_IC0:
    case LUB_PRECOND_BIC0:
        ic0_apply(w, r, z);
        break;
    case LUB_PRECOND_SGS:
        sgs_apply(w, A, w->omega, r, z);
        break;
    case LUB_PRECOND_AMG:
        lub_amg_apply(&w->amg, r, z);
        break;
    }
}

/* ---- fused vector kernels ------------------------------------------------------------ */

static double dot(int n, const double *a, const double *b)
{
    double s = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) s += a[i] * b[i];
    return s;
}

/* q_k = A p_k for the m vectors (1 <= m <= LUB_PCG_MAX_RHS) in one pass over the matrix,
 * pq[k] = p_k.q_k.  The matrix is read once for all of them: the sweep is bandwidth-bound, so
 * m vectors cost much less than m products.  Each q_k and pq[k] is summed in the same order
 * as with m = 1. */
static void spmv_dot(const lub_csr *A, int m, double *const *p, double *const *q, double *pq)
{
    const int n = A->n;
    const int *rp = A->row_ptr, *col = A->col;
    const double *val = A->val;
    if (m == 1) {
        const double *p0 = p[0];
        double *q0 = q[0], s0 = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s0) if (n > LUB_LINALG_OMP_MIN)
        for (int i = 0; i < n; i++) {
            double t0 = 0.0;
            for (int k = rp[i]; k < rp[i + 1]; k++) t0 += val[k] * p0[col[k]];
            q0[i] = t0;
            s0 += p0[i] * t0;
        }
        pq[0] = s0;
    } else if (m == 2) {
        const double *p0 = p[0], *p1 = p[1];
        double *q0 = q[0], *q1 = q[1], s0 = 0.0, s1 = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s0, s1) if (n > LUB_LINALG_OMP_MIN)
        for (int i = 0; i < n; i++) {
            double t0 = 0.0, t1 = 0.0;
            for (int k = rp[i]; k < rp[i + 1]; k++) {
                const double a = val[k];
                const int j = col[k];
                t0 += a * p0[j];
                t1 += a * p1[j];
            }
            q0[i] = t0;
            q1[i] = t1;
            s0 += p0[i] * t0;
            s1 += p1[i] * t1;
        }
        pq[0] = s0;
        pq[1] = s1;
    } else {
        const double *p0 = p[0], *p1 = p[1], *p2 = p[2];
        double *q0 = q[0], *q1 = q[1], *q2 = q[2], s0 = 0.0, s1 = 0.0, s2 = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s0, s1, s2) if (n > LUB_LINALG_OMP_MIN)
        for (int i = 0; i < n; i++) {
            double t0 = 0.0, t1 = 0.0, t2 = 0.0;
            for (int k = rp[i]; k < rp[i + 1]; k++) {
                const double a = val[k];
                const int j = col[k];
                t0 += a * p0[j];
                t1 += a * p1[j];
                t2 += a * p2[j];
            }
            q0[i] = t0;
            q1[i] = t1;
            q2[i] = t2;
            s0 += p0[i] * t0;
            s1 += p1[i] * t1;
            s2 += p2[i] * t2;
        }
        pq[0] = s0;
        pq[1] = s1;
        pq[2] = s2;
    }
}

/* r = b - A x, returns r.r */
static double residual(const lub_csr *A, const double *b, const double *x, double *r)
{
    const int n = A->n;
    const int *rp = A->row_ptr, *col = A->col;
    const double *val = A->val;
    double s = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) {
        double t = b[i];
        for (int k = rp[i]; k < rp[i + 1]; k++) t -= val[k] * x[col[k]];
        r[i] = t;
        s += t * t;
    }
    return s;
}

/* r_k = b_k - A x_k and rr[k] = r_k.r_k for m = 2 or 3 right-hand sides in one pass over A
 * (the warm starts of lub_pcg_solve_multi); per right-hand side the arithmetic of residual. */
static void residual_multi(const lub_csr *A, int m, const double *const *b, double *const *x,
                           double *const *r, double *rr)
{
    const int n = A->n;
    const int *rp = A->row_ptr, *col = A->col;
    const double *val = A->val;
    if (m == 2) {
        const double *b0 = b[0], *b1 = b[1], *x0 = x[0], *x1 = x[1];
        double *r0 = r[0], *r1 = r[1], s0 = 0.0, s1 = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s0, s1) if (n > LUB_LINALG_OMP_MIN)
        for (int i = 0; i < n; i++) {
            double t0 = b0[i], t1 = b1[i];
            for (int k = rp[i]; k < rp[i + 1]; k++) {
                const double a = val[k];
                const int j = col[k];
                t0 -= a * x0[j];
                t1 -= a * x1[j];
            }
            r0[i] = t0;
            r1[i] = t1;
            s0 += t0 * t0;
            s1 += t1 * t1;
        }
        rr[0] = s0;
        rr[1] = s1;
    } else {
        const double *b0 = b[0], *b1 = b[1], *b2 = b[2], *x0 = x[0], *x1 = x[1], *x2 = x[2];
        double *r0 = r[0], *r1 = r[1], *r2 = r[2], s0 = 0.0, s1 = 0.0, s2 = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s0, s1, s2) if (n > LUB_LINALG_OMP_MIN)
        for (int i = 0; i < n; i++) {
            double t0 = b0[i], t1 = b1[i], t2 = b2[i];
            for (int k = rp[i]; k < rp[i + 1]; k++) {
                const double a = val[k];
                const int j = col[k];
                t0 -= a * x0[j];
                t1 -= a * x1[j];
                t2 -= a * x2[j];
            }
            r0[i] = t0;
            r1[i] = t1;
            r2[i] = t2;
            s0 += t0 * t0;
            s1 += t1 * t1;
            s2 += t2 * t2;
        }
        rr[0] = s0;
        rr[1] = s1;
        rr[2] = s2;
    }
}

/* x += alpha p, r -= alpha q, returns r.r */
static double update_xr(int n, double alpha, const double *p, const double *q, double *x, double *r)
{
    double s = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) {
        x[i] += alpha * p[i];
        double ri = r[i] - alpha * q[i];
        r[i] = ri;
        s += ri * ri;
    }
    return s;
}

/* z = M^-1 r, returns r.z (Jacobi fused into one pass) */
static double precond_dot(lub_pcg_work *w, const lub_csr *A, const double *r, double *z)
{
    const int n = A->n;
    if (w->precond_used == LUB_PRECOND_JACOBI) {
        const double *dinv = w->dinv;
        double s = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s) if (n > LUB_LINALG_OMP_MIN)
        for (int i = 0; i < n; i++) {
            double zi = dinv[i] * r[i];
            z[i] = zi;
            s += r[i] * zi;
        }
        return s;
    }
    lub_pcg_precond_apply(w, A, r, z);
    return dot(n, r, z);
}

/* p = z + beta p */
static void update_p(int n, double beta, const double *z, double *p)
{
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) p[i] = z[i] + beta * p[i];
}

static void finish(lub_solve_result *res, lub_solve_status st, int it, double rel)
{
    res->status = st;
    res->converged = st == LUB_SOLVE_OK;
    res->iterations = it;
    res->residual = rel;
}

void lub_pcg_solve(lub_pcg_work *w, const lub_csr *A, const double *b, double *x,
                   const lub_pcg_options *o, lub_solve_result *res)
{
    lub_pcg_solve_multi(w, A, 1, &b, &x, o, res);
}

/* One CG per right-hand side, in lockstep: each has its own scalars and stops on its own
 * (converged, breakdown, non-finite); the matrix products of the ones still running share
 * one pass over A.  Per right-hand side the arithmetic is that of a solve of its own. */
void lub_pcg_solve_multi(lub_pcg_work *w, const lub_csr *A, int nrhs, const double *const *b,
                         double *const *x, const lub_pcg_options *o, lub_solve_result *res)
{
    const int n = A->n;
    if (nrhs < 1 || nrhs > LUB_PCG_MAX_RHS)
        lub_bug("lub_pcg_solve_multi with %d right-hand sides (1 to %d)", nrhs, LUB_PCG_MAX_RHS);
    if (!(o->tolerance > 0 && isfinite(o->tolerance)) || o->max_iter < 0 ||
        (o->precond == LUB_PRECOND_SGS && !(o->omega > 0 && o->omega < 2)))
        lub_bug("bad PCG options: tolerance %g, max_iter %d, omega %g", o->tolerance, o->max_iter,
                o->omega);
    if (!w->ready || w->A != A || w->stamp != A->stamp || w->precond != o->precond ||
        (o->precond == LUB_PRECOND_SGS && w->omega != o->omega) ||
        (o->precond == LUB_PRECOND_BIC0 && w->blocks_opt != o->blocks))
        lub_pcg_setup(w, A, o);
    if (o->cycle < 1 || o->cycle > 2) lub_bug("bad AMG cycle %d (1: V, 2: W)", o->cycle);
    w->amg.cycle = o->cycle; /* the cycle is no part of the set-up */
    const double tol = o->tolerance;
    double *r[LUB_PCG_MAX_RHS], *z[LUB_PCG_MAX_RHS], *p[LUB_PCG_MAX_RHS], *q[LUB_PCG_MAX_RHS];
    double bnorm[LUB_PCG_MAX_RHS], rz[LUB_PCG_MAX_RHS], rr[LUB_PCG_MAX_RHS];
    lub_solve_status st[LUB_PCG_MAX_RHS];
    int act[LUB_PCG_MAX_RHS], na = 0;   /* the right-hand sides still iterating */
    int inloop[LUB_PCG_MAX_RHS] = {0};  /* went into the iterations (not done at the start) */
    int start[LUB_PCG_MAX_RHS], ns = 0; /* the right-hand sides that need a start */
    for (int k = 0; k < nrhs; k++) {
        const size_t off = (size_t)k * (size_t)w->n_cap;
        r[k] = w->r + off, z[k] = w->z + off, p[k] = w->p + off, q[k] = w->q + off;
        memset(&res[k], 0, sizeof res[k]);
        res[k].column = -1;
        res[k].ic_shift = w->ic_shift;
        bnorm[k] = sqrt(dot(n, b[k], b[k]));
        if (!isfinite(bnorm[k])) {
            res[k].residual0 = NAN;
            finish(&res[k], LUB_SOLVE_NONFINITE, 0, NAN);
            continue;
        }
        if (bnorm[k] == 0.0) {
            /* the exact solution of A x = 0 */
            memset(x[k], 0, (size_t)n * sizeof *x[k]);
            finish(&res[k], LUB_SOLVE_OK, 0, 0.0);
            continue;
        }
        start[ns++] = k;
    }
    if (o->warm_start && ns > 1) {
        /* the initial residuals share one pass over A, like the products below */
        const double *bs[LUB_PCG_MAX_RHS];
        double *xs[LUB_PCG_MAX_RHS], *rs[LUB_PCG_MAX_RHS], rrs[LUB_PCG_MAX_RHS];
        for (int a = 0; a < ns; a++) bs[a] = b[start[a]], xs[a] = x[start[a]], rs[a] = r[start[a]];
        residual_multi(A, ns, bs, xs, rs, rrs);
        for (int a = 0; a < ns; a++) rr[start[a]] = rrs[a];
    }
    for (int a = 0; a < ns; a++) {
        const int k = start[a];
        if (o->warm_start) {
            if (ns == 1) rr[k] = residual(A, b[k], x[k], r[k]);
        } else {
            memset(x[k], 0, (size_t)n * sizeof *x[k]);
            memcpy(r[k], b[k], (size_t)n * sizeof *r[k]);
            rr[k] = bnorm[k] * bnorm[k];
        }
        const double rel = sqrt(rr[k]) / bnorm[k];
        res[k].residual0 = rel;
        if (!isfinite(rel)) {
            finish(&res[k], LUB_SOLVE_NONFINITE, 0, rel);
            continue;
        }
        if (rel <= tol) {
            finish(&res[k], LUB_SOLVE_OK, 0, rel);
            continue;
        }
        rz[k] = precond_dot(w, A, r[k], z[k]);
        memcpy(p[k], z[k], (size_t)n * sizeof *p[k]);
        st[k] = LUB_SOLVE_NOT_CONVERGED;
        inloop[k] = 1;
        act[na++] = k;
    }

    int it = 0;
    double *pa[LUB_PCG_MAX_RHS], *qa[LUB_PCG_MAX_RHS], pq[LUB_PCG_MAX_RHS];
    while (na > 0 && it < o->max_iter) {
        /* a breakdown stops that right-hand side; the others go on */
        int m = 0;
        for (int a = 0; a < na; a++) {
            const int k = act[a];
            if (!(rz[k] > 0)) {
                st[k] = isfinite(rz[k]) ? LUB_SOLVE_BREAKDOWN : LUB_SOLVE_NONFINITE;
                res[k].iterations = it;
                continue;
            }
            act[m++] = k;
        }
        na = m;
        if (na == 0) break;
        for (int a = 0; a < na; a++) pa[a] = p[act[a]], qa[a] = q[act[a]];
        spmv_dot(A, na, pa, qa, pq);
        it++;
        m = 0;
        for (int a = 0; a < na; a++) {
            const int k = act[a];
            if (!(pq[a] > 0)) {
                st[k] = isfinite(pq[a]) ? LUB_SOLVE_BREAKDOWN : LUB_SOLVE_NONFINITE;
                res[k].iterations = it - 1;
                continue;
            }
            rr[k] = update_xr(n, rz[k] / pq[a], p[k], q[k], x[k], r[k]);
            res[k].iterations = it;
            if (!isfinite(rr[k])) {
                st[k] = LUB_SOLVE_NONFINITE;
                continue;
            }
            int restart = 0;
            if (sqrt(rr[k]) <= tol * bnorm[k]) {
                /* the recursive residual drifts from b - A x: decide on the true one */
                rr[k] = residual(A, b[k], x[k], r[k]);
                if (sqrt(rr[k]) <= tol * bnorm[k]) {
                    st[k] = LUB_SOLVE_OK;
                    continue;
                }
                restart = 1;
            }
            const double rz_new = precond_dot(w, A, r[k], z[k]);
            if (restart) {
                memcpy(p[k], z[k], (size_t)n * sizeof *p[k]);
            } else {
                update_p(n, rz_new / rz[k], z[k], p[k]);
            }
            rz[k] = rz_new;
            act[m++] = k;
        }
        na = m;
    }
    /* the reported residual is always the true one */
    for (int k = 0; k < nrhs; k++) {
        if (!inloop[k]) continue;
        if (st[k] != LUB_SOLVE_OK) rr[k] = residual(A, b[k], x[k], r[k]);
        const double rel = sqrt(rr[k]) / bnorm[k];
        if (st[k] != LUB_SOLVE_OK && !isfinite(rel)) st[k] = LUB_SOLVE_NONFINITE;
        finish(&res[k], st[k], res[k].iterations, rel);
    }
}
