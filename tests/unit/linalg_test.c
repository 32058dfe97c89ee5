/* Unit tests of src/linalg: CSR assembly, PCG (none, jacobi, ic0, sgs), CHOLMOD, the front.
 *
 * References are independent of the code under test: dense matrices, manufactured exact
 * solutions (x_exact chosen, b = A x_exact computed densely or stencil by stencil), the
 * analytic eigenvalues of the finite-difference Laplacians for the condition numbers, and
 * hand-worked small matrices.  Accuracy checks use the rigorous bound
 *     ||x - x_exact|| / ||x_exact|| <= kappa(A) ||b - A x|| / ||b||,
 * with the residual recomputed here from the stencil, not taken from the solver.
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "linalg/bicgstab.h"
#include "linalg/csr.h"
#include "linalg/linsolve.h"
#include "test.h"

/* ---- helpers ------------------------------------------------------------------------- */

static unsigned long long rng_state = 88172645463325252ULL;
static double rnd(void) /* uniform [0, 1), xorshift64 */
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

static const double PI = 3.14159265358979323846;

/* Fill A from a dense symmetric matrix D (n x n, row-major), entries != 0 plus the diagonal,
 * each row handed over in a shuffled column order to exercise the sorting. */
static void csr_from_dense(lub_csr *A, int n, const double *D)
{
    lub_csr_begin(A, n);
    for (int i = 0; i < n; i++) {
        int len = 0;
        for (int j = 0; j < n; j++)
            if (D[i * n + j] != 0 || i == j) len++;
        lub_csr_set_row_length(A, i, len);
    }
    lub_csr_alloc(A);
    for (int i = 0; i < n; i++) {
        int *c = lub_csr_row_col(A, i);
        double *v = lub_csr_row_val(A, i);
        int len = 0;
        for (int j = n - 1; j >= 0; j--) /* reversed order */
            if (D[i * n + j] != 0 || i == j) {
                c[len] = j;
                v[len] = D[i * n + j];
                len++;
            }
        for (int k = len - 1; k > 0; k--) { /* then shuffled */
            int m = (int)(rnd() * (k + 1));
            int tc = c[k];
            double tv = v[k];
            c[k] = c[m];
            v[k] = v[m];
            c[m] = tc;
            v[m] = tv;
        }
    }
    lub_csr_finish(A);
}

/* lub_csr_finish on a 4-row matrix whose row 2 has the columns c[0..len) (the other rows
 * only their diagonal), in a child process: lub_csr_finish stops a bad matrix with lub_bug
 * (abort).  Returns 1 if the child aborted, its message in msg; 0 if it returned. */
static int finish_row2(const int *c, int len, char *msg, size_t size)
{
    int fd[2];
    msg[0] = '\0';
    if (pipe(fd) != 0) return -1;
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        dup2(fd[1], 2);
        close(fd[0]);
        lub_csr A;
        lub_csr_init(&A);
        lub_csr_begin(&A, 4);
        for (int i = 0; i < 4; i++) lub_csr_set_row_length(&A, i, i == 2 ? len : 1);
        lub_csr_alloc(&A);
        for (int i = 0; i < 4; i++)
            for (int k = 0; k < lub_csr_row_length(&A, i); k++) {
                lub_csr_row_col(&A, i)[k] = i == 2 ? c[k] : i;
                lub_csr_row_val(&A, i)[k] = 1.0;
            }
        lub_csr_finish(&A);
        _exit(0);
    }
    close(fd[1]);
    size_t got = 0;
    ssize_t r;
    while (got + 1 < size && (r = read(fd[0], msg + got, size - 1 - got)) > 0) got += (size_t)r;
    msg[got] = '\0';
    close(fd[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT;
}

/* The rows lub_csr_finish refuses (an internal error: assembly bugs), sorted or not, and
 * rows it takes: the diagonal first, last, alone, or in a row that needed sorting. */
static void test_csr_finish_checks(void)
{
    char msg[1024];
    static const struct {
        int c[5], len;
        const char *what; /* NULL: accepted */
    } rows[] = {
        {{1, 2, 4}, 3, "a column out of range"},
        {{-1, 2, 3}, 3, "a column out of range"},
        {{4, 2, 1}, 3, "a column out of range"},
        {{1, 2, 2, 3}, 4, "a repeated column"},
        {{3, 2, 1, 2}, 4, "a repeated column"},
        {{0, 1, 3}, 3, "no diagonal entry"},
        {{3, 1}, 2, "no diagonal entry"},
        {{2}, 1, NULL},
        {{2, 3}, 2, NULL},
        {{0, 1, 2}, 3, NULL},
        {{3, 0, 2, 1}, 4, NULL},
    };
    for (size_t t = 0; t < sizeof rows / sizeof rows[0]; t++) {
        const int aborted = finish_row2(rows[t].c, rows[t].len, msg, sizeof msg);
        if (rows[t].what) {
            CHECK(aborted == 1);
            CHECK_STR(msg, "row 2 of 4");
            CHECK_STR(msg, rows[t].what);
        } else {
            CHECK(aborted == 0);
        }
    }
}

/* lub_csr_finish sorts each row with its values: rows of interleaved ascending runs (as
 * assembled from neighbour lists in cell order), reversed, shuffled and sorted rows, and
 * rows longer than the merge buffer (sorted by insertion).  Value of (i, j): i + j / 1000. */
static void test_csr_sort_rows(void)
{
    const int n = 600;
    lub_csr A;
    lub_csr_init(&A);
    lub_csr_begin(&A, n);
    for (int i = 0; i < n; i++) lub_csr_set_row_length(&A, i, i < 3 ? n : 1 + i % 60);
    lub_csr_alloc(&A);
    for (int i = 0; i < n; i++) {
        int *c = lub_csr_row_col(&A, i);
        double *v = lub_csr_row_val(&A, i);
        const int len = lub_csr_row_length(&A, i);
        /* the columns: the diagonal and the len - 1 columns after it (cyclic) */
        for (int k = 0; k < len; k++) c[k] = (i + k) % n;
        switch (i % 4) {
        case 0: { /* r ascending runs interleaved: every r-th column in turn */
            const int r = 1 + i % 9;
            int *t = malloc((size_t)len * sizeof *t), m = 0;
            for (int q = 0; q < r; q++)
                for (int k = q; k < len; k += r) t[m++] = c[k];
            for (int k = 0; k < len; k++) c[k] = t[k];
            free(t);
            break;
        }
        case 1: /* reversed */
            for (int k = 0; k < len / 2; k++) {
                int t = c[k];
                c[k] = c[len - 1 - k];
                c[len - 1 - k] = t;
            }
            break;
        case 2: /* shuffled */
            for (int k = len - 1; k > 0; k--) {
                int m = (int)(rnd() * (k + 1)), t = c[k];
                c[k] = c[m];
                c[m] = t;
            }
            break;
        default: /* as generated: sorted except for the cyclic wrap */
            break;
        }
        for (int k = 0; k < len; k++) v[k] = i + c[k] / 1000.0;
    }
    lub_csr_finish(&A);
    int ok_sorted = 1, ok_val = 1, ok_diag = 1, ok_len = 1;
    for (int i = 0; i < n; i++) {
        if (lub_csr_row_length(&A, i) != (i < 3 ? n : 1 + i % 60)) ok_len = 0;
        for (int k = A.row_ptr[i]; k < A.row_ptr[i + 1]; k++) {
            if (k > A.row_ptr[i] && A.col[k] <= A.col[k - 1]) ok_sorted = 0;
            if (A.val[k] != i + A.col[k] / 1000.0) ok_val = 0;
        }
        if (A.col[A.diag[i]] != i) ok_diag = 0;
    }
    CHECK(ok_len);
    CHECK(ok_sorted);
    CHECK(ok_val);
    CHECK(ok_diag);
    lub_csr_free(&A);
}

/* 1-D Poisson, n interior points, Dirichlet ends: tridiag(-1, 2, -1). */
static void poisson1d(lub_csr *A, int n)
{
    lub_csr_begin(A, n);
    for (int i = 0; i < n; i++) lub_csr_set_row_length(A, i, 1 + (i > 0) + (i < n - 1));
    lub_csr_alloc(A);
    for (int i = 0; i < n; i++) {
        int *c = lub_csr_row_col(A, i);
        double *v = lub_csr_row_val(A, i);
        int k = 0;
        c[k] = i, v[k++] = 2.0;
        if (i < n - 1) c[k] = i + 1, v[k++] = -1.0;
        if (i > 0) c[k] = i - 1, v[k++] = -1.0;
    }
    lub_csr_finish(A);
}

/* eigenvalues 4 sin^2(k pi / (2(n+1))), k = 1..n */
static double kappa1d(int n)
{
    double a = sin(n * PI / (2.0 * (n + 1))), b = sin(PI / (2.0 * (n + 1)));
    return a * a / (b * b);
}

/* 2-D Poisson on an m x m grid, 5-point stencil, Dirichlet boundary. */
/* diag(1, 2, ..., n): no off-diagonal couplings, nothing for the AMG to aggregate */
static void diagonal(lub_csr *A, int n)
{
    lub_csr_begin(A, n);
    for (int i = 0; i < n; i++) lub_csr_set_row_length(A, i, 1);
    lub_csr_alloc(A);
    for (int i = 0; i < n; i++) *lub_csr_row_col(A, i) = i, *lub_csr_row_val(A, i) = 1.0 + i;
    lub_csr_finish(A);
}

static void poisson2d(lub_csr *A, int m)
{
    int n = m * m;
    lub_csr_begin(A, n);
    for (int i = 0; i < n; i++) {
        int ix = i % m, iy = i / m;
        lub_csr_set_row_length(A, i, 1 + (ix > 0) + (ix < m - 1) + (iy > 0) + (iy < m - 1));
    }
    lub_csr_alloc(A);
    for (int i = 0; i < n; i++) {
        int ix = i % m, iy = i / m, k = 0;
        int *c = lub_csr_row_col(A, i);
        double *v = lub_csr_row_val(A, i);
        if (iy < m - 1) c[k] = i + m, v[k++] = -1.0; /* unsorted on purpose */
        if (ix > 0) c[k] = i - 1, v[k++] = -1.0;
        c[k] = i, v[k++] = 4.0;
        if (iy > 0) c[k] = i - m, v[k++] = -1.0;
        if (ix < m - 1) c[k] = i + 1, v[k++] = -1.0;
    }
    lub_csr_finish(A);
}

/* eigenvalues 4 sin^2(k pi/(2(m+1))) + 4 sin^2(l pi/(2(m+1))) */
static double kappa2d(int m)
{
    return kappa1d(m);
}

/* y = A x with the 5-point stencil written out (independent of lub_csr_spmv) */
static void apply2d(int m, const double *x, double *y)
{
    for (int iy = 0; iy < m; iy++)
        for (int ix = 0; ix < m; ix++) {
            int i = iy * m + ix;
            double s = 4.0 * x[i];
            if (ix > 0) s -= x[i - 1];
            if (ix < m - 1) s -= x[i + 1];
            if (iy > 0) s -= x[i - m];
            if (iy < m - 1) s -= x[i + m];
            y[i] = s;
        }
}

static void apply1d(int n, const double *x, double *y)
{
    for (int i = 0; i < n; i++)
        y[i] = 2.0 * x[i] - (i > 0 ? x[i - 1] : 0.0) - (i < n - 1 ? x[i + 1] : 0.0);
}

static double norm(int n, const double *x)
{
    double s = 0;
    for (int i = 0; i < n; i++) s += x[i] * x[i];
    return sqrt(s);
}

static double rel_err(int n, const double *x, const double *xe)
{
    double s = 0;
    for (int i = 0; i < n; i++) s += (x[i] - xe[i]) * (x[i] - xe[i]);
    return sqrt(s) / norm(n, xe);
}

/* ||b - A x|| / ||b|| with the stencil apply */
static double rel_res(int n, void (*apply)(int, const double *, double *), int dim, const double *b,
                      const double *x)
{
    double *y = malloc((size_t)n * sizeof *y);
    apply(dim, x, y);
    double s = 0;
    for (int i = 0; i < n; i++) s += (b[i] - y[i]) * (b[i] - y[i]);
    free(y);
    return sqrt(s) / norm(n, b);
}

/* The round-off floor of a computed relative residual: evaluating b - A x in floating point
 * errs by up to about (row length) eps |A| |x| entrywise; two correct evaluations (the
 * solver's and the test's) may differ by that much. */
static double res_floor(int n, void (*apply)(int, const double *, double *), int dim,
                        const double *b, const double *x)
{
    double *ax = calloc((size_t)n, sizeof *ax), *y = calloc((size_t)n, sizeof *y);
    for (int i = 0; i < n; i++) ax[i] = fabs(x[i]);
    apply(dim, ax, y); /* |A| |x| = (2 diag(A) - A) |x| for these M-matrices */
    double s = 0;
    for (int i = 0; i < n; i++) {
        double t = 2.0 * (dim == n ? 2.0 : 4.0) * ax[i] - y[i]; /* 1-D: dim == n */
        s += t * t;
    }
    free(ax);
    free(y);
    return 5 * 2.2e-16 * sqrt(s) / norm(n, b);
}

/* a smooth field plus noise, so that every mode is present */
static void manufactured(int n, double *xe, int seed)
{
    for (int i = 0; i < n; i++)
        xe[i] = sin(0.37 * (i + seed)) + 0.5 * cos(0.011 * i * (seed + 1)) + 0.1 * rnd();
}

/* ---- CSR ----------------------------------------------------------------------------- */

static void test_csr_random_pattern_matches_dense(void)
{
    lub_csr A;
    lub_csr_init(&A);
    /* several assemblies into the same arrays: growing, then shrinking sizes */
    const int sizes[] = {30, 75, 12, 75};
    for (int t = 0; t < 4; t++) {
        int n = sizes[t];
        double *D = calloc((size_t)n * n, sizeof *D);
        for (int i = 0; i < n; i++) {
            D[i * n + i] = 1.0 + rnd();
            for (int j = 0; j < i; j++)
                if (rnd() < 0.15) D[i * n + j] = D[j * n + i] = rnd() - 0.5;
        }
        unsigned long stamp = A.stamp;
        csr_from_dense(&A, n, D);
        CHECK(A.stamp == stamp + 1);
        CHECK(A.n == n);
        int nnz = 0, ok_get = 1, ok_sorted = 1, ok_diag = 1;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                if (D[i * n + j] != 0) nnz++;
                if (lub_csr_get(&A, i, j) != D[i * n + j]) ok_get = 0;
            }
        for (int i = 0; i < n; i++) {
            for (int k = A.row_ptr[i] + 1; k < A.row_ptr[i + 1]; k++)
                if (A.col[k] <= A.col[k - 1]) ok_sorted = 0;
            if (A.col[A.diag[i]] != i || A.val[A.diag[i]] != D[i * n + i]) ok_diag = 0;
        }
        CHECK(A.nnz == nnz);
        CHECK(ok_get);
        CHECK(ok_sorted);
        CHECK(ok_diag);
        CHECK(lub_csr_asymmetry(&A) == 0.0);
        /* SpMV against the dense product */
        double *x = malloc((size_t)n * sizeof *x), *y = malloc((size_t)n * sizeof *y);
        for (int i = 0; i < n; i++) x[i] = rnd() - 0.5;
        lub_csr_spmv(&A, x, y);
        double maxd = 0;
        for (int i = 0; i < n; i++) {
            double s = 0;
            for (int j = 0; j < n; j++) s += D[i * n + j] * x[j];
            maxd = fmax(maxd, fabs(s - y[i]));
        }
        CHECK_NEAR(maxd, 0.0, 1e-14);
        /* an asymmetric perturbation of one off-diagonal entry is detected, with its size
         * relative to the largest entry */
        int k0 = -1;
        for (int i = 0; i < n && k0 < 0; i++)
            if (lub_csr_row_length(&A, i) > 1)
                k0 = A.diag[i] == A.row_ptr[i] ? A.diag[i] + 1 : A.row_ptr[i];
        CHECK(k0 >= 0);
        if (k0 >= 0) {
            double amax = 0;
            for (int k = 0; k < A.nnz; k++) amax = fmax(amax, fabs(A.val[k]));
            A.val[k0] += 0.25 * amax;
            CHECK_NEAR(lub_csr_asymmetry(&A), 0.25 * amax / fmax(amax, fabs(A.val[k0])), 1e-15);
        }
        free(x);
        free(y);
        free(D);
    }
    lub_csr_free(&A);
}

/* ---- PCG ----------------------------------------------------------------------------- */

static void check_pcg_poisson(int dim, int size, lub_precond pc, double tol)
{
    lub_csr A;
    lub_csr_init(&A);
    int n;
    double kappa;
    void (*apply)(int, const double *, double *);
    if (dim == 1) {
        poisson1d(&A, size);
        n = size, kappa = kappa1d(size), apply = apply1d;
    } else {
        poisson2d(&A, size);
        n = size * size, kappa = kappa2d(size), apply = apply2d;
    }
    double *xe = malloc((size_t)n * sizeof *xe), *b = malloc((size_t)n * sizeof *b),
           *x = malloc((size_t)n * sizeof *x);
    manufactured(n, xe, 3);
    apply(size, xe, b);
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    lub_pcg_options o = lub_pcg_defaults();
    o.precond = pc;
    o.tolerance = tol;
    o.max_iter = 10 * n;
    lub_solve_result r;
    lub_pcg_solve(&w, &A, b, x, &o, &r);
    double res = rel_res(n, apply, size, b, x);
    CHECK(r.converged);
    CHECK(r.status == LUB_SOLVE_OK);
    CHECK(r.iterations > 0);
    CHECK(res <= tol);
    CHECK_NEAR(r.residual, res, 1e-6 * res + res_floor(n, apply, size, b, x));
    CHECK(rel_err(n, x, xe) <= kappa * res);
    if (r.status != LUB_SOLVE_OK || rel_err(n, x, xe) > kappa * res)
        printf("  dim %d %s: it %d res %g err %g kappa %g\n", dim, lub_precond_choice_names[pc],
               r.iterations, res, rel_err(n, x, xe), kappa);
    lub_pcg_work_free(&w);
    lub_csr_free(&A);
    free(xe);
    free(b);
    free(x);
}

static void test_pcg_poisson1d_each_preconditioner(void)
{
    for (int pc = 0; lub_precond_choice_names[pc]; pc++) check_pcg_poisson(1, 200, pc, 1e-10);
}

static void test_pcg_poisson2d_each_preconditioner(void)
{
    for (int pc = 0; lub_precond_choice_names[pc]; pc++) check_pcg_poisson(2, 50, pc, 1e-10);
}

/* For a tridiagonal matrix IC(0) has no dropped fill: it is the exact Cholesky factor, known
 * in closed form for tridiag(-1, 2, -1): L_ii = sqrt((i+2)/(i+1)), L_i,i-1 = -sqrt(i/(i+1)).
 * L is stored in single precision (pcg.h), so it matches to float round-off, and PCG, whose
 * preconditioned matrix is then I + E with ||E|| <~ kappa(A) 2^-24 ~ 2e-3 (n = 300), gains
 * about 2.7 digits per iteration: 1e-12 within 4 iterations (1 with an exact factor). */
static void test_ic0_exact_on_tridiagonal(void)
{
    lub_csr A;
    lub_csr_init(&A);
    int n = 300;
    poisson1d(&A, n);
    double *xe = malloc(n * sizeof *xe), *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x);
    manufactured(n, xe, 1);
    apply1d(n, xe, b);
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    lub_pcg_options o = lub_pcg_defaults();
    o.precond = LUB_PRECOND_IC0;
    o.tolerance = 1e-12;
    lub_solve_result r;
    lub_pcg_solve(&w, &A, b, x, &o, &r);
    double maxd = 0, maxo = 0;
    for (int i = 0; i < n; i++) {
        maxd = fmax(maxd, fabs(1.0 / w.dinv[i] - sqrt((i + 2.0) / (i + 1.0))));
        CHECK(w.l_ptr[i + 1] - w.l_ptr[i] == (i > 0));
        if (i > 0) maxo = fmax(maxo, fabs(w.l_val[w.l_ptr[i]] + sqrt(i / (i + 1.0))));
    }
    /* each row rounds L_i,i-1 to float (relative 2^-24) and the recursion
     * L_ii^2 = 2 - L_i,i-1^2, L_i+1,i = -1 / L_ii passes the error on with a factor <= 1, so
     * the errors add up along the chain: at most n 2^-24 */
    CHECK_NEAR(maxd, 0.0, n * 0x1p-24);
    CHECK_NEAR(maxo, 0.0, n * 0x1p-24);
    CHECK(r.converged);
    CHECK(r.iterations <= 4);
    CHECK(r.ic_shift == 0.0);
    CHECK(rel_err(n, x, xe) <= kappa1d(n) * r.residual * 1.01);
    lub_pcg_work_free(&w);
    lub_csr_free(&A);
    free(xe);
    free(b);
    free(x);
}

static int iterations_2d(int m, lub_precond pc, double tol)
{
    lub_csr A;
    lub_csr_init(&A);
    poisson2d(&A, m);
    int n = m * m;
    double *xe = malloc(n * sizeof *xe), *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x);
    manufactured(n, xe, 2);
    apply2d(m, xe, b);
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    lub_pcg_options o = lub_pcg_defaults();
    o.precond = pc;
    o.tolerance = tol;
    o.max_iter = 10000;
    lub_solve_result r;
    lub_pcg_solve(&w, &A, b, x, &o, &r);
    CHECK(r.converged);
    lub_pcg_work_free(&w);
    lub_csr_free(&A);
    free(xe);
    free(b);
    free(x);
    return r.iterations;
}

/* The point of IC(0) and SSOR: fewer iterations than Jacobi (a property, not a timing). */
static void test_ic0_fewer_iterations_than_jacobi(void)
{
    int jac = iterations_2d(80, LUB_PRECOND_JACOBI, 1e-8);
    int ic0 = iterations_2d(80, LUB_PRECOND_IC0, 1e-8);
    int sgs = iterations_2d(80, LUB_PRECOND_SGS, 1e-8);
    CHECK(ic0 < jac);
    CHECK(sgs < jac);
    /* on the 5-point Laplacian the condition number of IC(0) is still O(h^-2), with a
     * constant about 3-4 times smaller: iterations drop by about half */
    CHECK(ic0 < 0.7 * jac);
    printf("  2-D Poisson 80x80, tol 1e-8: iterations jacobi %d, ic0 %d, sgs %d\n", jac, ic0, sgs);
}

/* Block IC(0) with 2 blocks: the factor is IC(0) of the two diagonal
 * blocks, so it still converges to the exact solution, in no fewer iterations than ic0
 * (it drops couplings) and fewer than jacobi. */
static void test_bic0_two_blocks(void)
{
    int m = 80, n = m * m;
    lub_csr A;
    lub_csr_init(&A);
    poisson2d(&A, m);
    double *xe = malloc(n * sizeof *xe), *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x);
    manufactured(n, xe, 2);
    apply2d(m, xe, b);
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    lub_pcg_options o = lub_pcg_defaults();
    o.precond = LUB_PRECOND_BIC0;
    o.blocks = 2;
    o.tolerance = 1e-8;
    lub_solve_result r;
    lub_pcg_solve(&w, &A, b, x, &o, &r);
    CHECK(w.nblocks == 2);
    CHECK(w.blk[1] > n / 2 - 2 * m && w.blk[1] < n / 2 + 2 * m); /* balanced by nonzeros */
    double res = rel_res(n, apply2d, m, b, x);
    CHECK(r.converged && res <= 1e-8);
    CHECK(rel_err(n, x, xe) <= kappa2d(m) * res);
    int ic0 = iterations_2d(m, LUB_PRECOND_IC0, 1e-8);
    int jac = iterations_2d(m, LUB_PRECOND_JACOBI, 1e-8);
    CHECK(r.iterations >= ic0 && r.iterations < jac);
    printf("  2-D Poisson 80x80: bic0 (2 blocks) %d iterations\n", r.iterations);
    lub_pcg_work_free(&w);
    lub_csr_free(&A);
    free(xe);
    free(b);
    free(x);
}

static void test_warm_start_from_exact_solution(void)
{
    int m = 40, n = m * m;
    lub_csr A;
    lub_csr_init(&A);
    poisson2d(&A, m);
    double *xe = malloc(n * sizeof *xe), *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x);
    manufactured(n, xe, 5);
    apply2d(m, xe, b);
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    for (int pc = 0; lub_precond_choice_names[pc]; pc++) {
        lub_pcg_options o = lub_pcg_defaults();
        o.precond = pc;
        o.warm_start = 1;
        memcpy(x, xe, n * sizeof *x);
        lub_solve_result r;
        lub_pcg_solve(&w, &A, b, x, &o, &r);
        CHECK(r.converged);
        CHECK(r.iterations <= 1);
        CHECK(r.residual0 <= 1e-8);
        CHECK(rel_err(n, x, xe) <= 1e-12);
        /* the same solve cold needs many iterations: the warm start is what made it cheap */
        o.warm_start = 0;
        lub_pcg_solve(&w, &A, b, x, &o, &r);
        CHECK(r.converged && r.iterations > 10);
        CHECK(r.residual0 == 1.0);
    }
    lub_pcg_work_free(&w);
    lub_csr_free(&A);
    free(xe);
    free(b);
    free(x);
}

static void test_pcg_not_converged_reports_residual(void)
{
    int m = 60, n = m * m;
    lub_csr A;
    lub_csr_init(&A);
    poisson2d(&A, m);
    double *xe = malloc(n * sizeof *xe), *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x);
    manufactured(n, xe, 7);
    apply2d(m, xe, b);
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    lub_pcg_options o = lub_pcg_defaults();
    o.max_iter = 3;
    o.tolerance = 1e-8;
    lub_solve_result r;
    lub_pcg_solve(&w, &A, b, x, &o, &r);
    CHECK(!r.converged);
    CHECK(r.status == LUB_SOLVE_NOT_CONVERGED);
    CHECK(r.iterations == 3);
    double res = rel_res(n, apply2d, m, b, x);
    CHECK_REL(r.residual, res, 1e-10);
    CHECK(res > 1e-3 && res < 1.0);
    char buf[200];
    lub_solve_result_describe(&r, buf, sizeof buf);
    CHECK_STR(buf, "not converged after 3 iterations");
    lub_pcg_work_free(&w);
    lub_csr_free(&A);
    free(xe);
    free(b);
    free(x);
}

/* b = 0 gives x = 0; a NaN in b is reported, not iterated on; diag(1, -1) breaks CG down
 * (p.Ap = 0 for b = (1, 1)). */
static void test_pcg_special_cases(void)
{
    lub_csr A;
    lub_csr_init(&A);
    poisson1d(&A, 10);
    double b[10] = {0}, x[10];
    for (int i = 0; i < 10; i++) x[i] = 1.0;
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    lub_pcg_options o = lub_pcg_defaults();
    o.warm_start = 1;
    lub_solve_result r;
    lub_pcg_solve(&w, &A, b, x, &o, &r);
    CHECK(r.converged && r.iterations == 0);
    CHECK(norm(10, x) == 0.0);
    b[3] = NAN;
    lub_pcg_solve(&w, &A, b, x, &o, &r);
    CHECK(r.status == LUB_SOLVE_NONFINITE && !r.converged);

    double D[4] = {1, 0, 0, -1};
    csr_from_dense(&A, 2, D);
    double b2[2] = {1, 1}, x2[2];
    o = lub_pcg_defaults();
    o.precond = LUB_PRECOND_NONE;
    lub_pcg_solve(&w, &A, b2, x2, &o, &r);
    CHECK(r.status == LUB_SOLVE_BREAKDOWN && !r.converged);
    lub_pcg_work_free(&w);
    lub_csr_free(&A);
}

/* An SPD matrix on which IC(0) breaks down: the 4-cycle with off-diagonals t = 0.6 on three
 * edges and s = -0.5 on the fourth.  By hand: L00 = 1, L11^2 = 1 - t^2 = 0.64,
 * L22^2 = 1 - t^2/0.64 = 0.4375, L33^2 = 1 - s^2 - t^2/0.4375 = -0.0729 (the dropped fill
 * (1,3) is what the exact factor needs; A itself is SPD, its full Cholesky exists).  The
 * shifted factorisation must be used and PCG must still solve the system. */
static void test_ic0_shift_on_breakdown(void)
{
    const double t = 0.6, s = -0.5;
    double D[16] = {1, t, 0, s, t, 1, t, 0, 0, t, 1, t, s, 0, t, 1};
    lub_csr A;
    lub_csr_init(&A);
    csr_from_dense(&A, 4, D);
    double xe[4] = {1, -2, 3, 0.5}, b[4], x[4];
    for (int i = 0; i < 4; i++) {
        b[i] = 0;
        for (int j = 0; j < 4; j++) b[i] += D[4 * i + j] * xe[j];
    }
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    lub_pcg_options o = lub_pcg_defaults();
    o.precond = LUB_PRECOND_IC0;
    o.tolerance = 1e-13;
    lub_solve_result r;
    lub_pcg_solve(&w, &A, b, x, &o, &r);
    CHECK(r.ic_shift > 0);
    CHECK(w.precond_used == LUB_PRECOND_IC0);
    CHECK(r.converged);
    CHECK(r.iterations <= 4); /* CG: at most n iterations in exact arithmetic (+ round-off) */
    for (int i = 0; i < 4; i++) CHECK_NEAR(x[i], xe[i], 1e-11);
    char buf[200];
    lub_solve_result_describe(&r, buf, sizeof buf);
    CHECK_STR(buf, "IC(0) diagonal shift");
    lub_pcg_work_free(&w);
    lub_csr_free(&A);
}

/* The AMG V-cycle and W-cycle (here with the 2-block hybrid smoother) must be symmetric
 * positive definite operators for CG: u.M^-1 v =
 * v.M^-1 u (to round-off) and u.M^-1 u > 0 for random u, v; with a single level (n <=
 * coarse_max, dense Cholesky) it is A^-1 and PCG converges in one iteration; on the 2-D
 * Poisson matrix (3 levels) it needs fewer iterations than IC(0). */
static void test_amg_preconditioner(void)
{
    int m = 80, n = m * m;
    lub_csr A;
    lub_csr_init(&A);
    poisson2d(&A, m);
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    w.amg.blocks = 2; /* the hybrid (block) Gauss-Seidel smoother, whatever the threads */
    lub_pcg_options o = lub_pcg_defaults();
    o.precond = LUB_PRECOND_AMG;
    lub_pcg_setup(&w, &A, &o);
    CHECK(w.amg.nblocks == 2);
    CHECK(w.amg.nlev >= 3);
    CHECK(w.amg.lev[1].A->n < n / 3);
    CHECK(lub_csr_asymmetry(w.amg.lev[1].A) < 1e-15);
    double *u = malloc(n * sizeof *u), *v = malloc(n * sizeof *v), *mu = malloc(n * sizeof *mu),
           *mv = malloc(n * sizeof *mv);
    for (int t = 0; t < 6; t++) {
        w.amg.cycle = t < 3 ? 1 : 2; /* V, then W */
        for (int i = 0; i < n; i++) u[i] = rnd() - 0.5, v[i] = rnd() - 0.5;
        lub_pcg_precond_apply(&w, &A, u, mu);
        lub_pcg_precond_apply(&w, &A, v, mv);
        double umv = 0, vmu = 0, umu = 0, scale = 0;
        for (int i = 0; i < n; i++) {
            umv += u[i] * mv[i];
            vmu += v[i] * mu[i];
            umu += u[i] * mu[i];
            scale += fabs(u[i] * mv[i]);
        }
        CHECK_NEAR(umv, vmu, 1e-13 * scale);
        CHECK(umu > 0);
    }
    int amg = iterations_2d(m, LUB_PRECOND_AMG, 1e-8);
    int ic0 = iterations_2d(m, LUB_PRECOND_IC0, 1e-8);
    CHECK(amg < ic0);
    printf("  2-D Poisson 80x80: amg %d iterations (%d levels), ic0 %d\n", amg, w.amg.nlev, ic0);
    /* one level (64 unknowns, below lub_amg_dense_max's floor): exact */
    CHECK(iterations_2d(8, LUB_PRECOND_AMG, 1e-12) == 1);
    /* no off-diagonal couplings, n > coarse_max: nothing to aggregate, the single level is
     * smoothed by Gauss-Seidel, which is exact for a diagonal matrix */
    int nd = 1000;
    diagonal(&A, nd);
    for (int i = 0; i < nd; i++) u[i] = 1.0;
    lub_solve_result r;
    lub_pcg_solve(&w, &A, u, v, &o, &r);
    CHECK(w.amg.nlev == 1 && w.amg.coarse_gs == 1);
    CHECK(r.converged && r.iterations == 1);
    CHECK_NEAR(v[nd - 1], 1.0 / nd, 1e-15);
    lub_pcg_work_free(&w);
    lub_csr_free(&A);
    free(u);
    free(v);
    free(mu);
    free(mv);
}

/* The MPS-like pressure matrix of tests/bench/linalg_bench.c, small: particles on an
 * nx x ny lattice (l0 = 1), neighbours within re = 3.1, w = (r/re - 1)^2, A_ij = -w_ij,
 * A_ii = sum of w over all neighbours including Dirichlet (p = 0) ghosts above the free
 * surface at the top; walls elsewhere have no neighbours outside. */
static void mps_lattice(lub_csr *A, int nx, int ny)
{
    const double re = 3.1;
    int n = nx * ny;
    lub_csr_begin(A, n);
    for (int i = 0; i < n; i++) {
        int ix = i % nx, iy = i / nx, len = 1;
        for (int dy = -3; dy <= 3; dy++)
            for (int dx = -3; dx <= 3; dx++)
                if ((dx || dy) && dx * dx + dy * dy <= re * re && ix + dx >= 0 && ix + dx < nx &&
                    iy + dy >= 0 && iy + dy < ny)
                    len++;
        lub_csr_set_row_length(A, i, len);
    }
    lub_csr_alloc(A);
    for (int i = 0; i < n; i++) {
        int ix = i % nx, iy = i / nx, len = 1;
        int *c = lub_csr_row_col(A, i);
        double *v = lub_csr_row_val(A, i);
        double d = 0;
        for (int dy = -3; dy <= 3; dy++)
            for (int dx = -3; dx <= 3; dx++) {
                double r = sqrt((double)(dx * dx + dy * dy));
                if (!(dx || dy) || r > re) continue;
                double w = (r / re - 1) * (r / re - 1);
                int jx = ix + dx, jy = iy + dy;
                if (jx >= 0 && jx < nx && jy >= 0 && jy < ny) {
                    c[len] = jy * nx + jx;
                    v[len++] = -w;
                    d += w;
                } else if (jy >= ny && jx >= 0 && jx < nx) {
                    d += w;
                }
            }
        c[0] = i;
        v[0] = d;
    }
    lub_csr_finish(A);
}

/* The V-cycle's residual after the forward sweep from 0, taken from the upper triangle (and
 * the columns in earlier smoother blocks), equals b - A x from its definition to round-off:
 * the whole V-cycle gives the same z both ways, with one block (plain Gauss-Seidel) and with
 * 2 and 3 blocks (hybrid), on the MPS-like matrix (5,000 unknowns: above LUB_LINALG_OMP_MIN,
 * so the finest level is smoothed in blocks). */
static void test_amg_fused_residual(void)
{
    lub_csr A;
    lub_csr_init(&A);
    mps_lattice(&A, 100, 50);
    const int n = A.n;
    CHECK(n > LUB_LINALG_OMP_MIN);
    double *r = malloc(n * sizeof *r), *z0 = malloc(n * sizeof *z0), *z1 = malloc(n * sizeof *z1);
    for (int i = 0; i < n; i++) r[i] = rnd() - 0.5;
    for (int blocks = 1; blocks <= 3; blocks++) {
        lub_pcg_work w;
        lub_pcg_work_init(&w);
        w.amg.blocks = blocks;
        lub_pcg_options o = lub_pcg_defaults();
        o.precond = LUB_PRECOND_AMG;
        lub_pcg_setup(&w, &A, &o);
        CHECK(w.amg.nblocks == blocks && w.amg.nlev >= 3);
        w.amg.unfused = 1;
        lub_pcg_precond_apply(&w, &A, r, z0);
        w.amg.unfused = 0;
        lub_pcg_precond_apply(&w, &A, r, z1);
        double d = 0, zmax = 0;
        for (int i = 0; i < n; i++) {
            d = fmax(d, fabs(z1[i] - z0[i]));
            zmax = fmax(zmax, fabs(z0[i]));
        }
        CHECK(zmax > 0);
        CHECK(d <= 1e-12 * zmax);
        printf("  fused residual, %d block(s): largest difference %.2e of max |z| %.3g\n", blocks,
               d, zmax);
        lub_pcg_work_free(&w);
    }
    free(r);
    free(z0);
    free(z1);
    lub_csr_free(&A);
}

/* The dense coarsest level: its factor, computed at every set-up (m^3/3 multiply-adds), costs
 * at most dense_budget multiply-adds per unknown of the finest level (m the largest such
 * size, not below 64, not above coarse_max), and the coarsening stops at the first level
 * that small; with dense_budget 0, coarse_max alone decides. */
static void test_amg_dense_limit(void)
{
    lub_amg g;
    lub_amg_init(&g);
    int ok = 1;
    for (int n = 1; n <= 2000000; n = n * 3 / 2 + 1) {
        const int m = lub_amg_dense_max(&g, n);
        const double budget = g.dense_budget * n;
        if (m > 64 && m < g.coarse_max)
            ok &= (double)m * m * m / 3 <= budget && (m + 1.0) * (m + 1) * (m + 1) / 3 > budget;
        ok &= m >= 64 && m <= g.coarse_max;
        ok &= m == g.coarse_max || m == 64 || (double)m * m * m / 3 <= budget;
    }
    CHECK(ok);
    CHECK(lub_amg_dense_max(&g, 2600) == 111 && lub_amg_dense_max(&g, 56000) == 311);
    CHECK(lub_amg_dense_max(&g, 10) == 64 && lub_amg_dense_max(&g, 10000000) == 400);
    g.dense_budget = 0;
    CHECK(lub_amg_dense_max(&g, 2600) == 400);
    lub_amg_free(&g);

    /* the hierarchy: 2-D Poisson, 2,025 unknowns: level 1 (356 unknowns) is dense by
     * coarse_max alone, but its factor (15 M multiply-adds) would cost 41 times the budget
     * (180 x 2,025): one level more, dense at most 103; both solve in a few iterations */
    lub_csr A;
    lub_csr_init(&A);
    poisson2d(&A, 45);
    double *b = malloc(A.n * sizeof *b), *x = malloc(A.n * sizeof *x);
    for (int i = 0; i < A.n; i++) b[i] = rnd() - 0.5;
    int ncs[2] = {0, 0};
    for (int budget = 0; budget < 2; budget++) {
        lub_pcg_work w;
        lub_pcg_work_init(&w);
        if (!budget) w.amg.dense_budget = 0;
        lub_pcg_options o = lub_pcg_defaults();
        o.precond = LUB_PRECOND_AMG;
        lub_solve_result r;
        lub_pcg_solve(&w, &A, b, x, &o, &r);
        const int dmax = lub_amg_dense_max(&w.amg, A.n), L = w.amg.nlev;
        const int nc = w.amg.lev[L - 1].A->n, nprev = L > 1 ? w.amg.lev[L - 2].A->n : 0;
        CHECK(r.converged);
        CHECK(!w.amg.coarse_gs && w.amg.dense_n == nc);
        CHECK(nc <= dmax && nprev > dmax);
        CHECK(dmax == (budget ? 103 : 400));
        ncs[budget] = nc;
        printf("  2-D Poisson 45x45, dense_budget %g: %d levels, the dense one %d unknowns, %d "
               "iterations to 1e-8\n",
               w.amg.dense_budget, L, nc, r.iterations);
        lub_pcg_work_free(&w);
    }
    /* the case tests the budget: coarse_max alone stops on a level above it */
    CHECK(ncs[0] > 103 && ncs[1] <= 103);
    free(b);
    free(x);

    /* a level that does not coarsen (a diagonal matrix: no couplings) above the budget but
     * within coarse_max is still solved exactly by the dense factor: PCG in one iteration */
    const int nd = 200;
    diagonal(&A, nd);
    double *u = malloc(nd * sizeof *u), *v = calloc(nd, sizeof *v);
    for (int i = 0; i < nd; i++) u[i] = 1.0;
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    lub_pcg_options o = lub_pcg_defaults();
    o.precond = LUB_PRECOND_AMG;
    o.tolerance = 1e-12;
    lub_solve_result r;
    lub_pcg_solve(&w, &A, u, v, &o, &r);
    CHECK(lub_amg_dense_max(&w.amg, nd) == 64);
    CHECK(w.amg.nlev == 1 && !w.amg.coarse_gs && w.amg.dense_n == nd);
    CHECK(r.converged && r.iterations == 1);
    lub_pcg_work_free(&w);
    free(u);
    free(v);
    lub_csr_free(&A);
}

/* PCG iterations to 1e-10 on the MPS-like matrix (random right-hand side) with AMG: cycle 1
 * (V) or 2 (W), coarse_max as given; the hierarchy's levels in *nlev. */
static int amg_iterations(const lub_csr *A, const double *b, int cycle, int coarse_max, int *nlev)
{
    const int n = A->n;
    double *x = calloc(n, sizeof *x);
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    w.amg.blocks = 2;
    w.amg.coarse_max = coarse_max;
    w.amg.dense_budget = 0; /* coarse_max alone decides */
    lub_pcg_options o = lub_pcg_defaults();
    o.precond = LUB_PRECOND_AMG;
    o.tolerance = 1e-10;
    o.cycle = cycle;
    lub_solve_result r;
    lub_pcg_solve(&w, A, b, x, &o, &r);
    CHECK(r.converged);
    *nlev = w.amg.nlev;
    lub_pcg_work_free(&w);
    free(x);
    return r.iterations;
}

/* The W-cycle does what it is for: its coarse correction approximates an exact solve on
 * level 1 better than the V-cycle's, so PCG with it needs fewer iterations than with the
 * V-cycle, at least half the way down to those of the two-grid method (level 1 solved
 * exactly by the dense Cholesky: the limit of any cycle), on the MPS-like matrix with 4 or
 * more levels (coarse_max 100).  The aggregation, done in
 * 2 blocks of rows at once, keeps every aggregate inside one block and numbers them densely. */
static void test_amg_cycles(void)
{
    lub_csr A;
    lub_csr_init(&A);
    mps_lattice(&A, 160, 80);
    const int n = A.n;
    double *b = malloc(n * sizeof *b);
    for (int i = 0; i < n; i++) b[i] = rnd() - 0.5;
    int lv, lw, l2;
    const int v = amg_iterations(&A, b, 1, 100, &lv);
    const int wc = amg_iterations(&A, b, 2, 100, &lw);
    /* two-grid: coarse_max above the size of level 1, which is then solved exactly */
    const int tg = amg_iterations(&A, b, 1, n / 2, &l2);
    CHECK(lv >= 4 && lw == lv && l2 == 2);
    CHECK(wc < v);
    CHECK(wc - tg <= (v - tg) / 2); /* at least half the way from the V-cycle to two-grid */
    printf(
        "  MPS-like 160x80 to 1e-10: V-cycle %d iterations, W-cycle %d, two-grid %d (%d levels)\n",
        v, wc, tg, lv);

    lub_pcg_work w;
    lub_pcg_work_init(&w);
    w.amg.blocks = 2;
    lub_pcg_options o = lub_pcg_defaults();
    o.precond = LUB_PRECOND_AMG;
    lub_pcg_setup(&w, &A, &o);
    const lub_amg_level *l0 = &w.amg.lev[0];
    int ok = 1, half = n / 2, nc = l0->nc;
    int *blk = malloc(nc * sizeof *blk), *seen = calloc(nc, sizeof *seen);
    for (int I = 0; I < nc; I++) blk[I] = -1;
    for (int i = 0; i < n; i++) {
        const int I = l0->agg[i], t = i < half ? 0 : 1;
        if (I < 0 || I >= nc) {
            ok = 0;
            break;
        }
        if (blk[I] >= 0 && blk[I] != t) ok = 0;
        blk[I] = t;
        seen[I] = 1;
    }
    for (int I = 0; I < nc && ok; I++) ok = seen[I];
    CHECK(ok);
    lub_pcg_work_free(&w);
    free(blk);
    free(seen);
    free(b);
    lub_csr_free(&A);
}

/* On the MPS-like matrix every preconditioner and CHOLMOD give the same solution (CHOLMOD's,
 * backward stable, as the reference: both within kappa * residual of the truth), and the
 * iteration counts are ordered amg < ic0 < jacobi. */
static void test_mps_like_matrix_all_solvers(void)
{
    int nx = 60, ny = 30, n = nx * ny;
    lub_csr A;
    lub_csr_init(&A);
    mps_lattice(&A, nx, ny);
    CHECK(lub_csr_asymmetry(&A) == 0.0);
    double *b = malloc(n * sizeof *b), *xd = malloc(n * sizeof *xd), *x = malloc(n * sizeof *x);
    for (int i = 0; i < n; i++) b[i] = rnd() - 0.5;
    lub_cholmod_options co = lub_cholmod_defaults();
    lub_cholmod *ch = lub_cholmod_new(&co);
    lub_solve_result r;
    CHECK(lub_cholmod_factorize(ch, &A, LUB_PATTERN_COMPARE, &r) == LUB_SOLVE_OK);
    const double *bb[1] = {b};
    double *xx[1] = {xd};
    CHECK(lub_cholmod_solve(ch, &A, 1, bb, xx, &r) == LUB_SOLVE_OK);
    CHECK(r.residual < 1e-13);
    lub_cholmod_free(ch);
    int its[6] = {0};
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    for (int pc = 0; lub_precond_choice_names[pc]; pc++) {
        lub_pcg_options o = lub_pcg_defaults();
        o.precond = pc;
        o.tolerance = 1e-10;
        o.max_iter = 5000;
        lub_pcg_solve(&w, &A, b, x, &o, &r);
        CHECK(r.converged && r.residual <= 1e-10);
        its[pc] = r.iterations;
        /* kappa of this matrix: lambda_max <= 2 max a_ii = 2 sum w = 8.3 (Gershgorin);
         * lambda_min ~ c (pi / (2 H))^2 = 0.0062 for the Laplacian with one Dirichlet side
         * at H = ny + 1 = 31, c = sum w r^2 / (2 d) = 2.4 the stencil's diffusion
         * coefficient: kappa ~ 1.4e3, bounded here by 1e4.  Both solutions are within
         * kappa times their residual (1e-10 and 1e-13) of the truth. */
        CHECK(rel_err(n, x, xd) <= 1e4 * (1e-10 + 1e-13));
    }
    CHECK(its[LUB_PRECOND_AMG] < its[LUB_PRECOND_IC0]);
    CHECK(its[LUB_PRECOND_IC0] < its[LUB_PRECOND_JACOBI]);
    printf("  MPS-like 60x30, tol 1e-10: iterations jacobi %d, ic0 %d, sgs %d, bic0 %d, amg %d\n",
           its[1], its[2], its[3], its[4], its[5]);
    lub_pcg_work_free(&w);
    lub_csr_free(&A);
    free(b);
    free(xd);
    free(x);
}

/* One work struct across matrices of changing size (the particle count changes from step to
 * step): the arrays grow when needed and every solve is still right. */
static void test_pcg_work_reuse_across_sizes(void)
{
    lub_pcg_work w;
    lub_pcg_work_init(&w);
    lub_csr A;
    lub_csr_init(&A);
    const int sizes[] = {100, 60, 7, 30};
    for (int t = 0; t < 4; t++) {
        int dim = t % 2 ? 2 : 1, size = sizes[t], n = dim == 1 ? size : size * size;
        if (dim == 1)
            poisson1d(&A, size);
        else
            poisson2d(&A, size);
        double *xe = malloc(n * sizeof *xe), *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x);
        manufactured(n, xe, t);
        (dim == 1 ? apply1d : apply2d)(size, xe, b);
        for (int pc = 0; lub_precond_choice_names[pc]; pc++) {
            lub_pcg_options o = lub_pcg_defaults();
            o.precond = pc;
            o.tolerance = 1e-10;
            lub_solve_result r;
            lub_pcg_solve(&w, &A, b, x, &o, &r);
            double res = rel_res(n, dim == 1 ? apply1d : apply2d, size, b, x);
            CHECK(r.converged && res <= 1e-10);
            CHECK(rel_err(n, x, xe) <= (dim == 1 ? kappa1d(size) : kappa2d(size)) * res);
        }
        free(xe);
        free(b);
        free(x);
    }
    lub_csr_free(&A);
    lub_pcg_work_free(&w);
}

/* ---- CHOLMOD ------------------------------------------------------------------------- */

static void test_cholmod_poisson(void)
{
    for (int dim = 1; dim <= 2; dim++) {
        int size = dim == 1 ? 500 : 60, n = dim == 1 ? size : size * size;
        double kappa = dim == 1 ? kappa1d(size) : kappa2d(size);
        void (*apply)(int, const double *, double *) = dim == 1 ? apply1d : apply2d;
        lub_csr A;
        lub_csr_init(&A);
        if (dim == 1)
            poisson1d(&A, size);
        else
            poisson2d(&A, size);
        double *xe = malloc(n * sizeof *xe), *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x);
        manufactured(n, xe, 11);
        apply(size, xe, b);
        for (int kind = 0; lub_cholmod_factor_names[kind]; kind++) {
            lub_cholmod_options co = lub_cholmod_defaults();
            co.factor = kind;
            lub_cholmod *s = lub_cholmod_new(&co);
            lub_solve_result r;
            CHECK(lub_cholmod_factorize(s, &A, LUB_PATTERN_COMPARE, &r) == LUB_SOLVE_OK);
            const double *bb[1] = {b};
            double *xx[1] = {x};
            CHECK(lub_cholmod_solve(s, &A, 1, bb, xx, &r) == LUB_SOLVE_OK);
            double res = rel_res(n, apply, size, b, x);
            /* backward stable: residual at round-off level */
            CHECK(res < 1e-13);
            CHECK_NEAR(r.residual, res, 1e-6 * res + res_floor(n, apply, size, b, x));
            CHECK(rel_err(n, x, xe) <= kappa * fmax(res, 1e-16));
            lub_cholmod_free(s);
        }
        lub_csr_free(&A);
        free(xe);
        free(b);
        free(x);
    }
}

/* diag(1, 2, ..., n) with a_55 = -1 and a few couplings away from row 5: the failing pivot
 * is column 5 whatever the ordering.  Also an indefinite 2 x 2 block [[1, 2], [2, 1]]. */
static void test_cholmod_indefinite_fails_with_column(void)
{
    int n = 12;
    double *D = calloc(n * n, sizeof *D);
    for (int i = 0; i < n; i++) D[i * n + i] = i + 1.0;
    D[5 * n + 5] = -1.0;
    D[0 * n + 1] = D[1 * n + 0] = 0.3;
    D[8 * n + 10] = D[10 * n + 8] = 0.5;
    lub_csr A;
    lub_csr_init(&A);
    csr_from_dense(&A, n, D);
    lub_cholmod_options co = lub_cholmod_defaults();
    lub_cholmod *s = lub_cholmod_new(&co);
    lub_solve_result r;
    CHECK(lub_cholmod_factorize(s, &A, LUB_PATTERN_COMPARE, &r) == LUB_SOLVE_NOT_POSDEF);
    CHECK(r.status == LUB_SOLVE_NOT_POSDEF && !r.converged);
    CHECK(r.column == 5);
    char buf[200];
    lub_solve_result_describe(&r, buf, sizeof buf);
    CHECK_STR(buf, "column 5");

    /* through the front: the solve reports the set-up failure and leaves x alone */
    lub_linsolver_options o = lub_linsolver_defaults();
    o.kind = LUB_LINSOLVER_CHOLMOD;
    lub_linsolver ls;
    lub_linsolver_init(&ls, &o);
    double B2[4] = {1, 2, 2, 1};
    csr_from_dense(&A, 2, B2);
    double b[2] = {1, 0}, x[2] = {7, 7};
    const double *bb[1] = {b};
    double *xx[1] = {x};
    CHECK(lub_linsolver_solve(&ls, &A, 1, bb, xx, &r) == LUB_SOLVE_NOT_POSDEF);
    CHECK(r.column == 0 || r.column == 1);
    CHECK(x[0] == 7 && x[1] == 7);
    lub_linsolver_free(&ls);
    lub_cholmod_free(s);
    lub_csr_free(&A);
    free(D);
}

/* Re-analysis only when the pattern changes; new values with the same pattern re-use the
 * analysis and still give the right solution. */
static void test_cholmod_reanalyse_on_pattern_change(void)
{
    int m = 30, n = m * m;
    lub_csr A;
    lub_csr_init(&A);
    poisson2d(&A, m);
    double *xe = malloc(n * sizeof *xe), *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x);
    manufactured(n, xe, 13);
    lub_cholmod_options co = lub_cholmod_defaults();
    lub_cholmod *s = lub_cholmod_new(&co);
    lub_solve_result r;
    long na, nf;
    const double *bb[1] = {b};
    double *xx[1] = {x};
    for (int pass = 0; pass < 3; pass++) {
        /* scale the matrix: same pattern, new values; b = (c A) xe */
        poisson2d(&A, m);
        double c = 1.0 + pass;
        for (int k = 0; k < A.nnz; k++) A.val[k] *= c;
        apply2d(m, xe, b);
        for (int i = 0; i < n; i++) b[i] *= c;
        lub_cholmod_factorize(s, &A, pass == 2 ? LUB_PATTERN_SAME : LUB_PATTERN_COMPARE, &r);
        CHECK(lub_cholmod_solve(s, &A, 1, bb, xx, &r) == LUB_SOLVE_OK);
        CHECK(rel_err(n, x, xe) <= kappa2d(m) * 1e-14);
    }
    lub_cholmod_stats(s, &na, &nf, NULL);
    CHECK(na == 1 && nf == 3);
    /* a new pattern (1-D matrix of the same size) is detected by the comparison */
    poisson1d(&A, n);
    apply1d(n, xe, b);
    lub_cholmod_factorize(s, &A, LUB_PATTERN_COMPARE, &r);
    CHECK(lub_cholmod_solve(s, &A, 1, bb, xx, &r) == LUB_SOLVE_OK);
    CHECK(rel_err(n, x, xe) <= kappa1d(n) * 1e-15);
    lub_cholmod_stats(s, &na, &nf, NULL);
    CHECK(na == 2 && nf == 4);
    lub_cholmod_free(s);
    lub_csr_free(&A);
    free(xe);
    free(b);
    free(x);
}

/* ---- the front: names, multiple right-hand sides ------------------------------------- */

static void test_linsolver_names(void)
{
    CHECK(strcmp(lub_linsolver_choice_names[LUB_LINSOLVER_CHOLMOD], "cholmod") == 0);
    CHECK(strcmp(lub_linsolver_choice_names[LUB_LINSOLVER_PCG], "pcg") == 0);
    CHECK(strcmp(lub_linsolver_choice_names[LUB_LINSOLVER_PETSC], "petsc") == 0);
    CHECK(lub_linsolver_choice_names[3] == NULL);
    CHECK(strcmp(lub_precond_choice_names[LUB_PRECOND_JACOBI], "jacobi") == 0);
    CHECK(strcmp(lub_precond_choice_names[LUB_PRECOND_IC0], "ic0") == 0);
    CHECK(strcmp(lub_precond_choice_names[LUB_PRECOND_SGS], "sgs") == 0);
    CHECK(strcmp(lub_precond_choice_names[LUB_PRECOND_BIC0], "bic0") == 0);
    CHECK(strcmp(lub_precond_choice_names[LUB_PRECOND_AMG], "amg") == 0);
    CHECK(lub_precond_choice_names[6] == NULL);
    lub_linsolver_options o = lub_linsolver_defaults();
    o.pcg.precond = LUB_PRECOND_IC0;
    o.pcg.warm_start = 1;
    lub_linsolver s;
    lub_linsolver_init(&s, &o);
    char buf[200];
    lub_linsolver_describe(&s, buf, sizeof buf);
    CHECK_STR(buf, "pcg (ic0), tolerance 1e-08, maxIter 1000, warm start");
    lub_linsolver_free(&s);
}

static void test_multiple_rhs(void)
{
    int m = 40, n = m * m, nrhs = 3;
    lub_csr A;
    lub_csr_init(&A);
    poisson2d(&A, m);
    double *xe[3], *b[3], *x[3], *x1 = malloc(n * sizeof *x1);
    for (int k = 0; k < nrhs; k++) {
        xe[k] = malloc(n * sizeof(double));
        b[k] = malloc(n * sizeof(double));
        x[k] = calloc(n, sizeof(double));
        manufactured(n, xe[k], 17 + 5 * k);
        apply2d(m, xe[k], b[k]);
    }
    const lub_linsolver_kind kinds[2] = {LUB_LINSOLVER_CHOLMOD, LUB_LINSOLVER_PCG};
    for (int t = 0; t < 2; t++) {
        lub_linsolver_options o = lub_linsolver_defaults();
        o.kind = kinds[t];
        o.pcg.precond = LUB_PRECOND_IC0;
        o.pcg.tolerance = 1e-10;
        lub_linsolver s;
        lub_linsolver_init(&s, &o);
        lub_solve_result r[3];
        CHECK(lub_linsolver_solve(&s, &A, nrhs, (const double *const *)b, x, r) == LUB_SOLVE_OK);
        for (int k = 0; k < nrhs; k++) {
            double res = rel_res(n, apply2d, m, b[k], x[k]);
            CHECK(r[k].converged);
            CHECK(res <= 1e-10);
            CHECK(rel_err(n, x[k], xe[k]) <= kappa2d(m) * res);
            /* the same right-hand side alone gives the same answer */
            const double *bk[1] = {b[k]};
            double *xk[1] = {x1};
            memset(x1, 0, n * sizeof *x1);
            lub_solve_result r1;
            lub_linsolver_solve(&s, &A, 1, bk, xk, &r1);
            CHECK(rel_err(n, x1, x[k]) <= (t == 0 ? 1e-13 : 1e-15));
        }
        lub_linsolver_free(&s);
    }
    for (int k = 0; k < nrhs; k++) {
        free(xe[k]);
        free(b[k]);
        free(x[k]);
    }
    free(x1);
    lub_csr_free(&A);
}

/* lub_pcg_solve_multi: each right-hand side is the CG it would be alone.  On the 2-D Poisson
 * matrix (72 x 72: above LUB_LINALG_OMP_MIN, so the loops are parallel) with Jacobi and AMG:
 * three right-hand sides needing different iteration counts (a smooth one, a rough one, and
 * a warm start near the solution) give the solutions and iteration counts of three
 * single solves (1e-13: the parallel sums may add in another order); a zero and a non-finite
 * right-hand side stop at once (x = 0, LUB_SOLVE_NONFINITE) while the third one converges as
 * alone; max_iter stops all of them with the true residual; and lub_linsolver_solve with five
 * right-hand sides (3 + 2) gives the single solves' answers. */
static void test_pcg_multi(void)
{
    const int m = 72, n = m * m;
    CHECK(n > LUB_LINALG_OMP_MIN);
    lub_csr A;
    lub_csr_init(&A);
    poisson2d(&A, m);
    double *xe[5], *b[5], *x[5], *x1 = malloc(n * sizeof *x1);
    for (int k = 0; k < 5; k++) {
        xe[k] = malloc(n * sizeof(double));
        b[k] = malloc(n * sizeof(double));
        x[k] = malloc(n * sizeof(double));
        manufactured(n, xe[k], 3 + 7 * k);
    }
    for (int i = 0; i < n; i++) xe[1][i] = rnd() - 0.5; /* rough: more iterations */
    for (int k = 0; k < 5; k++) apply2d(m, xe[k], b[k]);
    const lub_precond pcs[2] = {LUB_PRECOND_JACOBI, LUB_PRECOND_AMG};
    for (int t = 0; t < 2; t++) {
        lub_pcg_options o = lub_pcg_defaults();
        o.precond = pcs[t];
        o.tolerance = 1e-9;
        o.warm_start = 1;
        o.max_iter = 5000;
        lub_pcg_work w;
        lub_pcg_work_init(&w);
        /* initial guesses: 0, 0, and the solution disturbed by 1e-6 */
        for (int i = 0; i < n; i++)
            x[0][i] = x[1][i] = 0.0, x[2][i] = xe[2][i] * (1 + 1e-6 * rnd());
        double *x2 = malloc(n * sizeof *x2);
        memcpy(x2, x[2], n * sizeof *x2);
        lub_solve_result r[3], r1;
        lub_pcg_solve_multi(&w, &A, 3, (const double *const *)b, x, &o, r);
        int it[3];
        for (int k = 0; k < 3; k++) {
            if (k == 2)
                memcpy(x1, x2, n * sizeof *x1);
            else
                memset(x1, 0, n * sizeof *x1);
            lub_pcg_solve(&w, &A, b[k], x1, &o, &r1);
            CHECK(r[k].converged && r1.converged);
            CHECK(r[k].iterations == r1.iterations);
            CHECK_NEAR(r[k].residual, r1.residual, 1e-13 * r1.residual + 1e-300);
            CHECK(rel_err(n, x[k], x1) <= 1e-13);
            CHECK(r[k].residual <= 1e-9);
            CHECK(rel_err(n, x[k], xe[k]) <= kappa2d(m) * r[k].residual);
            it[k] = r[k].iterations;
        }
        /* they did stop at different iterations: the warm start one first */
        CHECK(it[2] < it[0] && it[2] < it[1]);
        /* two right-hand sides (their initial residuals in one pass, as three's): the same */
        {
            double *y[2] = {x[0], x[1]};
            const double *bb2[2] = {b[0], b[2]};
            lub_solve_result r2[2];
            memset(y[0], 0, n * sizeof *y[0]);
            memcpy(y[1], x2, n * sizeof *y[1]);
            lub_pcg_solve_multi(&w, &A, 2, bb2, y, &o, r2);
            CHECK(r2[0].converged && r2[0].iterations == it[0]);
            CHECK(r2[1].converged && r2[1].iterations == it[2]);
            CHECK_NEAR(r2[0].residual, r[0].residual, 1e-13 * r[0].residual + 1e-300);
            CHECK_NEAR(r2[1].residual, r[2].residual, 1e-13 * r[2].residual + 1e-300);
            CHECK(rel_err(n, y[1], x[2]) <= 1e-13);
        }
        printf("  %s, 3 right-hand sides: %d, %d, %d iterations, as alone\n", t ? "amg" : "jacobi",
               it[0], it[1], it[2]);
        /* a zero and a non-finite right-hand side beside a normal one */
        double *bz = calloc(n, sizeof *bz), *bn = malloc(n * sizeof *bn);
        memcpy(bn, b[0], n * sizeof *bn);
        bn[n / 2] = NAN;
        const double *bb[3] = {bz, bn, b[0]};
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < n; i++) x[k][i] = 1.0;
        for (int i = 0; i < n; i++) x[2][i] = 0.0;
        lub_pcg_solve_multi(&w, &A, 3, bb, x, &o, r);
        CHECK(r[0].status == LUB_SOLVE_OK && r[0].iterations == 0 && x[0][n - 1] == 0.0);
        CHECK(r[1].status == LUB_SOLVE_NONFINITE && r[1].iterations == 0);
        CHECK(r[2].converged && r[2].iterations == it[0]);
        /* max_iter: all three stop there, not converged, with the true residual */
        o.max_iter = 3;
        for (int k = 0; k < 3; k++) memset(x[k], 0, n * sizeof *x[k]);
        lub_pcg_solve_multi(&w, &A, 3, (const double *const *)b, x, &o, r);
        for (int k = 0; k < 3; k++) {
            CHECK(r[k].status == LUB_SOLVE_NOT_CONVERGED && r[k].iterations == 3);
            CHECK_NEAR(r[k].residual, rel_res(n, apply2d, m, b[k], x[k]), 1e-10);
        }
        free(bz);
        free(bn);
        free(x2);
        lub_pcg_work_free(&w);
    }
    /* five right-hand sides through lub_linsolver_solve: two fused calls */
    lub_linsolver_options lo = lub_linsolver_defaults();
    lo.kind = LUB_LINSOLVER_PCG;
    lo.pcg.precond = LUB_PRECOND_JACOBI;
    lo.pcg.tolerance = 1e-9;
    lub_linsolver s;
    lub_linsolver_init(&s, &lo);
    lub_solve_result r5[5], r1;
    for (int k = 0; k < 5; k++) memset(x[k], 0, n * sizeof *x[k]);
    CHECK(lub_linsolver_solve(&s, &A, 5, (const double *const *)b, x, r5) == LUB_SOLVE_OK);
    for (int k = 0; k < 5; k++) {
        const double *bk[1] = {b[k]};
        double *xk[1] = {x1};
        memset(x1, 0, n * sizeof *x1);
        lub_linsolver_solve(&s, &A, 1, bk, xk, &r1);
        CHECK(r5[k].converged && r5[k].iterations == r1.iterations);
        CHECK(rel_err(n, x[k], x1) <= 1e-13);
    }
    lub_linsolver_free(&s);
    for (int k = 0; k < 5; k++) {
        free(xe[k]);
        free(b[k]);
        free(x[k]);
    }
    free(x1);
    lub_csr_free(&A);
}

/* ---- BiCGStab (linalg/bicgstab.h) ------------------------------------------------------ */

/* A 2-D convection-diffusion matrix on an m x m grid (Dirichlet, h = 1/(m+1)):
 * -lap u + c (u_x + u_y) with central differences, nonsymmetric for c != 0 (c = 0: the
 * symmetric Poisson matrix). */
static double *convdiff(int m, double c)
{
    int n = m * m;
    double h = 1.0 / (m + 1), *D = calloc((size_t)n * n, sizeof *D);
    for (int j = 0; j < m; j++)
        for (int i = 0; i < m; i++) {
            int r = j * m + i;
            D[r * n + r] = 4 / (h * h);
            double e = -1 / (h * h) + c / (2 * h), w = -1 / (h * h) - c / (2 * h);
            if (i + 1 < m) D[r * n + r + 1] = e;
            if (i > 0) D[r * n + r - 1] = w;
            if (j + 1 < m) D[r * n + r + m] = e;
            if (j > 0) D[r * n + r - m] = w;
        }
    return D;
}

typedef struct {
    lub_pcg_work *w;
    const lub_csr *S;
} surrogate;

static void surrogate_apply(void *ctx, const double *r, double *z)
{
    surrogate *s = ctx;
    lub_pcg_precond_apply(s->w, s->S, r, z);
}

/* BiCGStab solves a nonsymmetric system to the tolerance (true residual), reaching the
 * solution the right-hand side was made from; with the AMG of the symmetric (c = 0) matrix as
 * the preconditioner, as the LSMPS systems use the standard MPS matrix's, in fewer
 * iterations than without; a capped run reports NOT_CONVERGED with its residual; b = 0 gives
 * x = 0. */
static void test_bicgstab(void)
{
    const int m = 24, n = m * m;
    double *D = convdiff(m, 5.0), *D0 = convdiff(m, 0.0);
    lub_csr A, S;
    lub_csr_init(&A), lub_csr_init(&S);
    csr_from_dense(&A, n, D);
    csr_from_dense(&S, n, D0);
    CHECK(lub_csr_asymmetry(&A) > 0.01);
    double *xe = malloc(n * sizeof *xe), *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x);
    for (int i = 0; i < n; i++) xe[i] = rnd() - 0.5;
    lub_csr_spmv(&A, xe, b);
    lub_bicgstab_work w;
    lub_bicgstab_work_init(&w);
    lub_solve_result res;
    CHECK(lub_bicgstab_solve(&w, &A, b, x, NULL, NULL, 1e-10, 1000, 0, &res) == LUB_SOLVE_OK);
    double err = 0, nrm = 0;
    for (int i = 0; i < n; i++) err += (x[i] - xe[i]) * (x[i] - xe[i]), nrm += xe[i] * xe[i];
    printf("  BiCGStab, no preconditioner: %d iterations, residual %.2g, error %.2g\n",
           res.iterations, res.residual, sqrt(err / nrm));
    CHECK(res.residual <= 1e-10 && sqrt(err / nrm) < 1e-7);
    const int plain = res.iterations;
    lub_pcg_work pw;
    lub_pcg_work_init(&pw);
    lub_pcg_options o = lub_pcg_defaults();
    o.precond = LUB_PRECOND_AMG;
    lub_pcg_setup(&pw, &S, &o);
    surrogate sg = {&pw, &S};
    CHECK(lub_bicgstab_solve(&w, &A, b, x, surrogate_apply, &sg, 1e-10, 1000, 0, &res) ==
          LUB_SOLVE_OK);
    err = 0;
    for (int i = 0; i < n; i++) err += (x[i] - xe[i]) * (x[i] - xe[i]);
    printf("  BiCGStab, AMG of the symmetric part: %d iterations (%d without), error %.2g\n",
           res.iterations, plain, sqrt(err / nrm));
    CHECK(res.iterations < plain && sqrt(err / nrm) < 1e-7);
    /* warm start from the solution: no iteration */
    CHECK(lub_bicgstab_solve(&w, &A, b, x, surrogate_apply, &sg, 1e-8, 1000, 1, &res) ==
              LUB_SOLVE_OK &&
          res.iterations == 0);
    CHECK(lub_bicgstab_solve(&w, &A, b, x, NULL, NULL, 1e-10, 2, 0, &res) ==
          LUB_SOLVE_NOT_CONVERGED);
    printf("  capped at 2 iterations: residual %.3g\n", res.residual);
    CHECK(res.iterations == 2 && res.residual > 1e-10);
    memset(b, 0, n * sizeof *b);
    for (int i = 0; i < n; i++) x[i] = 1;
    CHECK(lub_bicgstab_solve(&w, &A, b, x, NULL, NULL, 1e-10, 10, 1, &res) == LUB_SOLVE_OK);
    int zero = 1;
    for (int i = 0; i < n; i++) zero &= x[i] == 0;
    CHECK(zero);
    b[3] = NAN;
    CHECK(lub_bicgstab_solve(&w, &A, b, x, NULL, NULL, 1e-10, 10, 0, &res) == LUB_SOLVE_NONFINITE);
    lub_pcg_work_free(&pw);
    lub_bicgstab_work_free(&w);
    lub_csr_free(&A), lub_csr_free(&S);
    free(D), free(D0), free(xe), free(b), free(x);
}

int main(void)
{
    RUN(test_bicgstab);
    RUN(test_csr_random_pattern_matches_dense);
    RUN(test_csr_sort_rows);
    RUN(test_csr_finish_checks);
    RUN(test_pcg_poisson1d_each_preconditioner);
    RUN(test_pcg_poisson2d_each_preconditioner);
    RUN(test_ic0_exact_on_tridiagonal);
    RUN(test_ic0_fewer_iterations_than_jacobi);
    RUN(test_bic0_two_blocks);
    RUN(test_warm_start_from_exact_solution);
    RUN(test_pcg_not_converged_reports_residual);
    RUN(test_pcg_special_cases);
    RUN(test_ic0_shift_on_breakdown);
    RUN(test_amg_preconditioner);
    RUN(test_amg_fused_residual);
    RUN(test_amg_cycles);
    RUN(test_amg_dense_limit);
    RUN(test_pcg_work_reuse_across_sizes);
    RUN(test_mps_like_matrix_all_solvers);
    RUN(test_cholmod_poisson);
    RUN(test_cholmod_indefinite_fails_with_column);
    RUN(test_cholmod_reanalyse_on_pattern_change);
    RUN(test_linsolver_names);
    RUN(test_multiple_rhs);
    RUN(test_pcg_multi);
    /* release the OpenMP thread pool (ours and the one CHOLMOD's supernodal factorisation
     * starts with its compiled-in 4 threads), whose thread stacks valgrind would otherwise
     * list as possibly lost */
    omp_pause_resource_all(omp_pause_hard);
    return test_summary();
}
