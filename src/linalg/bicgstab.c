/* lubkit linalg: right-preconditioned BiCGStab (see bicgstab.h).
 *
 * H. A. van der Vorst, Bi-CGSTAB: a fast and smoothly converging variant of Bi-CG for the
 * solution of nonsymmetric linear systems, SIAM J. Sci. Stat. Comput. 13 (1992) 631-644;
 * the right-preconditioned form as in Saad, Iterative Methods for Sparse Linear Systems,
 * 2nd ed. (2003), Algorithm 7.7 with M^-1 applied to the search directions. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "linalg/bicgstab.h"

void lub_bicgstab_work_init(lub_bicgstab_work *w)
{
    memset(w, 0, sizeof *w);
}

void lub_bicgstab_work_free(lub_bicgstab_work *w)
{
    free(w->r);
    memset(w, 0, sizeof *w);
}

static void reserve(lub_bicgstab_work *w, int n)
{
    if (n <= w->n_cap) return;
    free(w->r);
    int cap = n + n / 8 + 16;
    double *a = lub_malloc((size_t)8 * (size_t)cap * sizeof *a);
    w->r = a, w->r0 = a + cap, w->p = a + 2 * cap, w->v = a + 3 * cap;
    w->s = a + 4 * cap, w->t = a + 5 * cap, w->ph = a + 6 * cap, w->sh = a + 7 * cap;
    w->n_cap = cap;
}

static double dot(int n, const double *a, const double *b)
{
    double s = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) s += a[i] * b[i];
    return s;
}

static void apply(lub_precond_fn M, void *ctx, int n, const double *r, double *z)
{
    if (M)
        M(ctx, r, z);
    else
        memcpy(z, r, (size_t)n * sizeof *z);
}

/* r = b - A x */
static void residual(const lub_csr *A, const double *b, const double *x, double *r)
{
    lub_csr_spmv(A, x, r);
    const int n = A->n;
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) r[i] = b[i] - r[i];
}

lub_solve_status lub_bicgstab_solve(lub_bicgstab_work *w, const lub_csr *A, const double *b,
                                    double *x, lub_precond_fn precond, void *ctx, double tolerance,
                                    int max_iter, int warm, lub_solve_result *res)
{
    const int n = A->n;
    memset(res, 0, sizeof *res);
    res->column = -1;
    reserve(w, n > 0 ? n : 1);
    if (!warm) memset(x, 0, (size_t)n * sizeof *x);
    const double bn = sqrt(dot(n, b, b));
    if (!isfinite(bn)) {
        res->status = LUB_SOLVE_NONFINITE;
        return res->status;
    }
    if (bn == 0.0) {
        memset(x, 0, (size_t)n * sizeof *x);
        res->status = LUB_SOLVE_OK;
        res->converged = 1;
        return res->status;
    }
    double *r = w->r, *r0 = w->r0, *p = w->p, *v = w->v, *s = w->s, *t = w->t, *ph = w->ph,
           *sh = w->sh;
    residual(A, b, x, r);
    double rn = sqrt(dot(n, r, r));
    res->residual0 = rn / bn;
    memcpy(r0, r, (size_t)n * sizeof *r0);
    double rho_old = 1.0, alpha = 1.0, omega = 1.0;
    lub_solve_status st = LUB_SOLVE_NOT_CONVERGED;
    int it = 0;
    if (rn <= tolerance * bn) st = LUB_SOLVE_OK;
    while (st == LUB_SOLVE_NOT_CONVERGED && it < max_iter) {
        const double rho = dot(n, r0, r);
        if (!isfinite(rho)) {
            st = LUB_SOLVE_NONFINITE;
            break;
        }
        if (rho == 0.0) {
            st = LUB_SOLVE_BREAKDOWN;
            break;
        }
        if (it == 0) {
            memcpy(p, r, (size_t)n * sizeof *p);
        } else {
            const double beta = (rho / rho_old) * (alpha / omega);
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
            for (int i = 0; i < n; i++) p[i] = r[i] + beta * (p[i] - omega * v[i]);
        }
        apply(precond, ctx, n, p, ph);
        lub_csr_spmv(A, ph, v);
        const double r0v = dot(n, r0, v);
        if (r0v == 0.0 || !isfinite(r0v)) {
            st = isfinite(r0v) ? LUB_SOLVE_BREAKDOWN : LUB_SOLVE_NONFINITE;
            break;
        }
        alpha = rho / r0v;
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
        for (int i = 0; i < n; i++) s[i] = r[i] - alpha * v[i];
        it++;
        if (sqrt(dot(n, s, s)) <= tolerance * bn) {
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
            for (int i = 0; i < n; i++) x[i] += alpha * ph[i];
            st = LUB_SOLVE_OK;
            break;
        }
        apply(precond, ctx, n, s, sh);
        lub_csr_spmv(A, sh, t);
        const double tt = dot(n, t, t), ts = dot(n, t, s);
        if (tt == 0.0 || !isfinite(tt)) {
            st = isfinite(tt) ? LUB_SOLVE_BREAKDOWN : LUB_SOLVE_NONFINITE;
            break;
        }
        omega = ts / tt;
#pragma omp parallel for schedule(static) if (n > LUB_LINALG_OMP_MIN)
        for (int i = 0; i < n; i++) {
            x[i] += alpha * ph[i] + omega * sh[i];
            r[i] = s[i] - omega * t[i];
        }
        rn = sqrt(dot(n, r, r));
        if (!isfinite(rn)) {
            st = LUB_SOLVE_NONFINITE;
            break;
        }
        if (rn <= tolerance * bn) {
            st = LUB_SOLVE_OK;
            break;
        }
        if (omega == 0.0) {
            st = LUB_SOLVE_BREAKDOWN;
            break;
        }
        rho_old = rho;
    }
    /* the true residual of the iterate returned */
    residual(A, b, x, r);
    rn = sqrt(dot(n, r, r));
    res->iterations = it;
    res->residual = rn / bn;
    if (st == LUB_SOLVE_OK && !(res->residual <= 10 * tolerance)) st = LUB_SOLVE_NOT_CONVERGED;
    if (!isfinite(rn)) st = LUB_SOLVE_NONFINITE;
    res->status = st;
    res->converged = st == LUB_SOLVE_OK;
    return st;
}
