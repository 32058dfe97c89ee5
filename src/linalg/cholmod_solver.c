/* lubkit linalg: CHOLMOD Cholesky of a lub_csr (see cholmod_solver.h). */
#include "linalg/cholmod_solver.h"

#include <cholmod.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

const char *const lub_cholmod_ordering_names[] = {"auto", "amd", "metis", NULL};
const char *const lub_cholmod_factor_names[] = {"auto", "simplicial", "supernodal", NULL};

struct lub_cholmod {
    cholmod_common c;
    cholmod_factor *L;
    cholmod_dense *X, *Y, *E; /* cholmod_solve2 workspace, reused */
    double *B;                /* packed right-hand sides when nrhs > 1 */
    size_t b_cap;
    /* pattern of the last analysis */
    int *pat_ptr, *pat_col;
    int pat_n, pat_nnz, pat_cap_n, pat_cap_nnz;
    int analysed;
    /* the matrix of the current valid factor */
    const lub_csr *A;
    unsigned long stamp;
    int factored;
    long analyses, factorizations;
};

lub_cholmod_options lub_cholmod_defaults(void)
{
    lub_cholmod_options o = {LUB_CHOLMOD_ORDER_AUTO, LUB_CHOLMOD_AUTO};
    return o;
}

lub_cholmod *lub_cholmod_new(const lub_cholmod_options *o)
{
    lub_cholmod *s = lub_calloc(1, sizeof *s);
    if (!cholmod_start(&s->c)) lub_fatal_run("CHOLMOD: cholmod_start failed");
    /* CHOLMOD would print its warnings (not positive definite) on stdout: the status is
     * reported to the caller instead */
    s->c.print = 0;
    /* LL' rather than CHOLMOD's default simplicial LDL': LDL' succeeds on an indefinite
     * matrix with nonzero pivots, and a non-positive pivot is the diagnostic wanted here
     * (the Poisson and viscosity matrices must be SPD) */
    s->c.final_ll = 1;
    switch (o->ordering) {
    case LUB_CHOLMOD_ORDER_AUTO:
        break;
    case LUB_CHOLMOD_ORDER_AMD:
        s->c.nmethods = 1;
        s->c.method[0].ordering = CHOLMOD_AMD;
        s->c.postorder = 1;
        break;
    case LUB_CHOLMOD_ORDER_METIS:
        s->c.nmethods = 1;
        s->c.method[0].ordering = CHOLMOD_METIS;
        s->c.postorder = 1;
        break;
    default:
        lub_bug("unknown CHOLMOD ordering %d", (int)o->ordering);
    }
    switch (o->factor) {
    case LUB_CHOLMOD_AUTO:
        s->c.supernodal = CHOLMOD_AUTO;
        break;
    case LUB_CHOLMOD_SIMPLICIAL:
        s->c.supernodal = CHOLMOD_SIMPLICIAL;
        break;
    case LUB_CHOLMOD_SUPERNODAL:
        s->c.supernodal = CHOLMOD_SUPERNODAL;
        break;
    default:
        lub_bug("unknown CHOLMOD factor kind %d", (int)o->factor);
    }
    return s;
}

void lub_cholmod_free(lub_cholmod *s)
{
    if (!s) return;
    if (s->L) cholmod_free_factor(&s->L, &s->c);
    if (s->X) cholmod_free_dense(&s->X, &s->c);
    if (s->Y) cholmod_free_dense(&s->Y, &s->c);
    if (s->E) cholmod_free_dense(&s->E, &s->c);
    cholmod_finish(&s->c);
    free(s->B);
    free(s->pat_ptr);
    free(s->pat_col);
    free(s);
}

/* The CSR arrays seen by CHOLMOD as a CSC matrix (no copy): symmetric, upper part used. */
static cholmod_sparse wrap(const lub_csr *A)
{
    cholmod_sparse M;
    memset(&M, 0, sizeof M);
    M.nrow = (size_t)A->n;
    M.ncol = (size_t)A->n;
    M.nzmax = (size_t)A->nnz;
    M.p = A->row_ptr;
    M.i = A->col;
    M.x = A->val;
    M.nz = NULL;
    M.z = NULL;
    M.stype = 1;
    M.itype = CHOLMOD_INT;
    M.xtype = CHOLMOD_REAL;
    M.dtype = CHOLMOD_DOUBLE;
    M.sorted = 1;
    M.packed = 1;
    return M;
}

static int same_pattern(const lub_cholmod *s, const lub_csr *A)
{
    return s->analysed && s->pat_n == A->n && s->pat_nnz == A->nnz &&
           memcmp(s->pat_ptr, A->row_ptr, (size_t)(A->n + 1) * sizeof(int)) == 0 &&
           memcmp(s->pat_col, A->col, (size_t)A->nnz * sizeof(int)) == 0;
}

static void keep_pattern(lub_cholmod *s, const lub_csr *A)
{
    if (A->n + 1 > s->pat_cap_n) {
        s->pat_cap_n = A->n + 1 + A->n / 8;
        s->pat_ptr = lub_realloc(s->pat_ptr, (size_t)s->pat_cap_n * sizeof(int));
    }
    if (A->nnz > s->pat_cap_nnz) {
        s->pat_cap_nnz = A->nnz + A->nnz / 8;
        s->pat_col = lub_realloc(s->pat_col, (size_t)s->pat_cap_nnz * sizeof(int));
    }
    memcpy(s->pat_ptr, A->row_ptr, (size_t)(A->n + 1) * sizeof(int));
    memcpy(s->pat_col, A->col, (size_t)A->nnz * sizeof(int));
    s->pat_n = A->n;
    s->pat_nnz = A->nnz;
}

static void result_init(lub_solve_result *res)
{
    memset(res, 0, sizeof *res);
    res->column = -1;
}

static lub_solve_status fail(lub_cholmod *s, lub_solve_result *res, lub_solve_status st)
{
    s->factored = 0;
    res->status = st;
    res->converged = 0;
    res->residual = NAN;
    return st;
}

lub_solve_status lub_cholmod_analyse(lub_cholmod *s, const lub_csr *A, lub_solve_result *res)
{
    result_init(res);
    if (!A->finished) lub_bug("lub_cholmod_analyse on a matrix not finished (lub_csr_finish)");
    cholmod_sparse M = wrap(A);
    s->factored = 0;
    if (s->L) cholmod_free_factor(&s->L, &s->c);
    s->analysed = 0;
    s->L = cholmod_analyze(&M, &s->c);
    if (!s->L || s->c.status < CHOLMOD_OK) return fail(s, res, LUB_SOLVE_FAILED);
    s->analyses++;
    keep_pattern(s, A);
    s->analysed = 1;
    res->status = LUB_SOLVE_OK;
    res->converged = 1;
    return LUB_SOLVE_OK;
}

lub_solve_status lub_cholmod_factorize(lub_cholmod *s, const lub_csr *A, lub_pattern_hint hint,
                                       lub_solve_result *res)
{
    result_init(res);
    if (!A->finished) lub_bug("lub_cholmod_factorize on a matrix not finished (lub_csr_finish)");
    s->factored = 0;
    if (hint == LUB_PATTERN_SAME && s->L && (size_t)A->n != s->L->n)
        lub_bug("LUB_PATTERN_SAME with a matrix of %d rows, analysed %zu", A->n, s->L->n);
    int analyse = !s->L || !s->analysed || hint == LUB_PATTERN_CHANGED ||
                  (hint == LUB_PATTERN_COMPARE && !same_pattern(s, A));
    if (analyse && lub_cholmod_analyse(s, A, res) != LUB_SOLVE_OK) return res->status;
    cholmod_sparse M = wrap(A);
    int ok = cholmod_factorize(&M, s->L, &s->c);
    s->factorizations++;
    if (s->c.status == CHOLMOD_NOT_POSDEF) {
        /* L->minor is a column of the permuted matrix */
        size_t k = s->L->minor;
        const int *perm = s->L->Perm;
        res->column = (k < s->L->n && perm) ? perm[k] : (int)k;
        return fail(s, res, LUB_SOLVE_NOT_POSDEF);
    }
    if (!ok || s->c.status < CHOLMOD_OK) return fail(s, res, LUB_SOLVE_FAILED);
    s->A = A;
    s->stamp = A->stamp;
    s->factored = 1;
    res->status = LUB_SOLVE_OK;
    res->converged = 1;
    return LUB_SOLVE_OK;
}

/* ||b - A x|| / ||b|| */
static double true_residual(const lub_csr *A, const double *b, const double *x)
{
    const int n = A->n;
    const int *rp = A->row_ptr, *col = A->col;
    const double *val = A->val;
    double rr = 0.0, bb = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : rr, bb) if (n > LUB_LINALG_OMP_MIN)
    for (int i = 0; i < n; i++) {
        double t = b[i];
        for (int k = rp[i]; k < rp[i + 1]; k++) t -= val[k] * x[col[k]];
        rr += t * t;
        bb += b[i] * b[i];
    }
    if (bb == 0.0) return rr == 0.0 ? 0.0 : INFINITY;
    return sqrt(rr / bb);
}

lub_solve_status lub_cholmod_solve(lub_cholmod *s, const lub_csr *A, int nrhs,
                                   const double *const *b, double *const *x, lub_solve_result *res)
{
    const size_t n = (size_t)A->n;
    if (nrhs < 1) lub_bug("lub_cholmod_solve with %d right-hand sides", nrhs);
    for (int k = 0; k < nrhs; k++) result_init(&res[k]);
    if (!s->factored || s->A != A || s->stamp != A->stamp) {
        /* a solve after a failed factorisation is the caller's bug too: it must have looked
         * at the status */
        lub_bug("lub_cholmod_solve without a valid factorisation of this matrix");
    }
    cholmod_dense B;
    memset(&B, 0, sizeof B);
    B.nrow = n;
    B.ncol = (size_t)nrhs;
    B.d = n;
    B.nzmax = n * (size_t)nrhs;
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    if (nrhs == 1) {
        B.x = (void *)b[0]; /* CHOLMOD only reads B */
    } else {
        if (B.nzmax > s->b_cap) {
            s->b_cap = B.nzmax;
            s->B = lub_realloc(s->B, s->b_cap * sizeof(double));
        }
        for (int k = 0; k < nrhs; k++) memcpy(s->B + (size_t)k * n, b[k], n * sizeof(double));
        B.x = s->B;
    }
    int ok = cholmod_solve2(CHOLMOD_A, s->L, &B, NULL, &s->X, NULL, &s->Y, &s->E, &s->c);
    lub_solve_status worst = LUB_SOLVE_OK;
    if (!ok || s->c.status < CHOLMOD_OK || !s->X) {
        for (int k = 0; k < nrhs; k++) {
            res[k].status = LUB_SOLVE_FAILED;
            res[k].residual = NAN;
        }
        return LUB_SOLVE_FAILED;
    }
    const double *X = s->X->x;
    for (int k = 0; k < nrhs; k++) {
        memcpy(x[k], X + (size_t)k * s->X->d, n * sizeof(double));
        double rel = true_residual(A, b[k], x[k]);
        res[k].residual = rel;
        res[k].status = isfinite(rel) ? LUB_SOLVE_OK : LUB_SOLVE_NONFINITE;
        res[k].converged = res[k].status == LUB_SOLVE_OK;
        if (res[k].status > worst) worst = res[k].status;
    }
    return worst;
}

void lub_cholmod_stats(const lub_cholmod *s, long *analyses, long *factorizations, double *lnz)
{
    if (analyses) *analyses = s->analyses;
    if (factorizations) *factorizations = s->factorizations;
    if (lnz) *lnz = s->L ? s->c.lnz : 0.0;
}
