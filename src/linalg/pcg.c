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

lub_pcg_options lub_pcg_defaults(void)
{
    lub_pcg_options o = {1e-8, 1000, LUB_PRECOND_JACOBI, 0, 1.0, 0};
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
    w->r = lub_realloc(w->r, sz);
    w->z = lub_realloc(w->z, sz);
    w->p = lub_realloc(w->p, sz);
    w->q = lub_realloc(w->q, sz);
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

/* q = A p, returns p.q */
static double spmv_dot(const lub_csr *A, const double *p, double *q)
{
    const int n = A->n;
    const int *rp = A->row_ptr, *col = A->col;
    const double *val = A->val;
    double s = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) {
        double t = 0.0;
        for (int k = rp[i]; k < rp[i + 1]; k++) t += val[k] * p[col[k]];
        q[i] = t;
        s += p[i] * t;
    }
    return s;
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
    const int n = A->n;
    if (!(o->tolerance > 0 && isfinite(o->tolerance)) || o->max_iter < 0 ||
        (o->precond == LUB_PRECOND_SGS && !(o->omega > 0 && o->omega < 2)))
        lub_bug("bad PCG options: tolerance %g, max_iter %d, omega %g", o->tolerance, o->max_iter,
                o->omega);
    if (!w->ready || w->A != A || w->stamp != A->stamp || w->precond != o->precond ||
        (o->precond == LUB_PRECOND_SGS && w->omega != o->omega) ||
        (o->precond == LUB_PRECOND_BIC0 && w->blocks_opt != o->blocks))
        lub_pcg_setup(w, A, o);
    memset(res, 0, sizeof *res);
    res->column = -1;
    res->ic_shift = w->ic_shift;

    double *r = w->r, *z = w->z, *p = w->p, *q = w->q;
    const double bnorm = sqrt(dot(n, b, b));
    if (!isfinite(bnorm)) {
        res->residual0 = NAN;
        finish(res, LUB_SOLVE_NONFINITE, 0, NAN);
        return;
    }
    if (bnorm == 0.0) {
        /* the exact solution of A x = 0 */
        memset(x, 0, (size_t)n * sizeof *x);
        finish(res, LUB_SOLVE_OK, 0, 0.0);
        return;
    }
    double rr;
    if (o->warm_start) {
        rr = residual(A, b, x, r);
    } else {
        memset(x, 0, (size_t)n * sizeof *x);
        memcpy(r, b, (size_t)n * sizeof *r);
        rr = bnorm * bnorm;
    }
    const double tol = o->tolerance;
    double rel = sqrt(rr) / bnorm;
    res->residual0 = rel;
    if (!isfinite(rel)) {
        finish(res, LUB_SOLVE_NONFINITE, 0, rel);
        return;
    }
    if (rel <= tol) {
        finish(res, LUB_SOLVE_OK, 0, rel);
        return;
    }

    double rz = precond_dot(w, A, r, z);
    memcpy(p, z, (size_t)n * sizeof *p);
    int it = 0;
    lub_solve_status st = LUB_SOLVE_NOT_CONVERGED;
    while (it < o->max_iter) {
        if (!(rz > 0)) {
            st = isfinite(rz) ? LUB_SOLVE_BREAKDOWN : LUB_SOLVE_NONFINITE;
            break;
        }
        double pq = spmv_dot(A, p, q);
        if (!(pq > 0)) {
            st = isfinite(pq) ? LUB_SOLVE_BREAKDOWN : LUB_SOLVE_NONFINITE;
            break;
        }
        double alpha = rz / pq;
        rr = update_xr(n, alpha, p, q, x, r);
        it++;
        if (!isfinite(rr)) {
            st = LUB_SOLVE_NONFINITE;
            break;
        }
        int restart = 0;
        if (sqrt(rr) <= tol * bnorm) {
            /* the recursive residual drifts from b - A x: decide on the true one */
            rr = residual(A, b, x, r);
            if (sqrt(rr) <= tol * bnorm) {
                st = LUB_SOLVE_OK;
                break;
            }
            restart = 1;
        }
        double rz_new = precond_dot(w, A, r, z);
        if (restart) {
            memcpy(p, z, (size_t)n * sizeof *p);
        } else {
            update_p(n, rz_new / rz, z, p);
        }
        rz = rz_new;
    }
    /* the reported residual is always the true one */
    if (st != LUB_SOLVE_OK) rr = residual(A, b, x, r);
    rel = sqrt(rr) / bnorm;
    if (st != LUB_SOLVE_OK && !isfinite(rel)) st = LUB_SOLVE_NONFINITE;
    finish(res, st, it, rel);
}
