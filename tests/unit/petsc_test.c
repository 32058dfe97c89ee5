/* Tests of the PETSc solver front (src/linalg/petsc_solver.h) through lub_linsolver: the
 * answer of CG with BoomerAMG against CHOLMOD's direct solution, BoomerAMG's iteration count
 * flat as the grid is refined, a warm start at the solution, a values-only update and a
 * pattern change, the other Krylov methods and preconditioners.  In a build without PETSc it
 * prints SKIP and checks that the name is there but the solver is not. */
#include <math.h>
#include <stdlib.h>

#include "linalg/linsolve.h"
#include "test.h"

/* A variable-coefficient 5-point operator on an m x m grid with Dirichlet sides:
 * k(x) = 1 + 100 x (two decades, as the film's h^3 varies), plus a shift s on the diagonal. */
static void operator2d(lub_csr *A, int m, double s)
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
        double kl = 1.0 + 100.0 * (ix + 0.5) / (m + 1), kr = 1.0 + 100.0 * (ix + 1.5) / (m + 1);
        double ky = 1.0 + 100.0 * (ix + 1.0) / (m + 1);
        int *c = lub_csr_row_col(A, i);
        double *v = lub_csr_row_val(A, i);
        if (iy > 0) c[k] = i - m, v[k++] = -ky;
        if (ix > 0) c[k] = i - 1, v[k++] = -kl;
        c[k] = i, v[k++] = kl + kr + 2.0 * ky + s;
        if (ix < m - 1) c[k] = i + 1, v[k++] = -kr;
        if (iy < m - 1) c[k] = i + m, v[k++] = -ky;
    }
    lub_csr_finish(A);
}

static double max_rel_diff(const double *a, const double *b, int n)
{
    double d = 0.0, s = 0.0;
    for (int i = 0; i < n; i++) {
        d = fmax(d, fabs(a[i] - b[i]));
        s = fmax(s, fabs(b[i]));
    }
    return d / s;
}

/* Solve A x = b with o; returns the result of the one right-hand side. */
static lub_solve_result solve(const lub_linsolver_options *o, const lub_csr *A, const double *b,
                              double *x)
{
    lub_linsolver s;
    lub_linsolver_init(&s, o);
    lub_solve_result r;
    const double *bb[1] = {b};
    double *xx[1] = {x};
    lub_linsolver_solve(&s, A, 1, bb, xx, &r);
    lub_linsolver_free(&s);
    return r;
}

static lub_linsolver_options petsc_options(lub_petsc_ksp ksp, lub_petsc_pc pc, double tol)
{
    lub_linsolver_options o = lub_linsolver_defaults();
    o.kind = LUB_LINSOLVER_PETSC;
    o.petsc.ksp = ksp;
    o.petsc.pc = pc;
    o.pcg.tolerance = tol;
    o.pcg.max_iter = 2000;
    o.pcg.warm_start = 0;
    return o;
}

/* CG + BoomerAMG = CHOLMOD to the tolerance (||x - x*|| <= cond ||r||: measured 1e-11 at
 * 1e-10), its iterations flat under refinement (m = 40, 80, 160: measured 7, 7, 7), the
 * residual reported the true one. */
static void test_cg_hypre_matches_cholmod(void)
{
    int its[3], ms[3] = {40, 80, 160};
    for (int k = 0; k < 3; k++) {
        int m = ms[k], n = m * m;
        lub_csr A;
        lub_csr_init(&A);
        operator2d(&A, m, 0.0);
        double *b = malloc((size_t)n * sizeof *b), *x0 = calloc((size_t)n, sizeof *x0),
               *x1 = calloc((size_t)n, sizeof *x1), *r = malloc((size_t)n * sizeof *r);
        for (int i = 0; i < n; i++) b[i] = 1.0 + sin(0.37 * i);
        lub_linsolver_options oc = lub_linsolver_defaults();
        oc.kind = LUB_LINSOLVER_CHOLMOD;
        lub_linsolver_options op = petsc_options(LUB_PETSC_KSP_CG, LUB_PETSC_PC_HYPRE, 1e-10);
        lub_solve_result rc = solve(&oc, &A, b, x0), rp = solve(&op, &A, b, x1);
        CHECK(rc.status == LUB_SOLVE_OK && rp.status == LUB_SOLVE_OK);
        CHECK(max_rel_diff(x1, x0, n) < 1e-8);
        CHECK(rp.residual <= 1e-10);
        lub_csr_spmv(&A, x1, r);
        double rn = 0.0, bn = 0.0;
        for (int i = 0; i < n; i++) rn += (b[i] - r[i]) * (b[i] - r[i]), bn += b[i] * b[i];
        CHECK_REL(rp.residual, sqrt(rn / bn), 1e-6);
        its[k] = rp.iterations;
        free(b), free(x0), free(x1), free(r);
        lub_csr_free(&A);
    }
    printf("  cg + BoomerAMG to 1e-10: %d, %d, %d iterations on 40^2, 80^2, 160^2 unknowns\n",
           its[0], its[1], its[2]);
    CHECK(its[0] > 0 && its[0] <= 20);
    CHECK(its[2] <= its[0] + 4); /* multigrid: flat */
}

/* One solver object over several assemblies: the same pattern (values only), a warm start
 * at the solution (no iterations), then a new pattern (a larger matrix). */
static void test_reuse_and_pattern_change(void)
{
    int m = 30, n = m * m;
    lub_csr A;
    lub_csr_init(&A);
    lub_linsolver_options o = petsc_options(LUB_PETSC_KSP_CG, LUB_PETSC_PC_HYPRE, 1e-10);
    o.pcg.warm_start = 1;
    lub_linsolver s;
    lub_linsolver_init(&s, &o);
    int m2 = 40, n2 = m2 * m2;
    double *b = malloc((size_t)n2 * sizeof *b), *x = calloc((size_t)n2, sizeof *x),
           *xc = calloc((size_t)n2, sizeof *xc);
    for (int i = 0; i < n2; i++) b[i] = cos(0.11 * i);
    const double *bb[1] = {b};
    double *xx[1] = {x};
    lub_solve_result r;
    lub_linsolver_options oc = lub_linsolver_defaults();
    oc.kind = LUB_LINSOLVER_CHOLMOD;
    for (int step = 0; step < 3; step++) {
        int mm = step < 2 ? m : m2, nn = mm * mm;
        operator2d(&A, mm, step == 1 ? 10.0 : 0.0); /* step 1: new values, same pattern */
        CHECK(lub_linsolver_solve(&s, &A, 1, bb, xx, &r) == LUB_SOLVE_OK);
        solve(&oc, &A, b, xc);
        CHECK(max_rel_diff(x, xc, nn) < 1e-8);
        (void)n;
    }
    /* warm start at the solution: converged at once */
    CHECK(lub_linsolver_solve(&s, &A, 1, bb, xx, &r) == LUB_SOLVE_OK);
    CHECK(r.iterations == 0);
    CHECK(r.residual0 <= 1e-10);
    char d[256];
    lub_linsolver_describe(&s, d, sizeof d);
    CHECK_STR(d, "petsc (ksp cg, pc hypre BoomerAMG), tolerance 1e-10");
    lub_linsolver_free(&s);
    free(b), free(x), free(xc);
    lub_csr_free(&A);
}

/* Every Krylov method and preconditioner of the names reaches CHOLMOD's answer. */
static void test_each_method(void)
{
    int m = 24, n = m * m;
    lub_csr A;
    lub_csr_init(&A);
    operator2d(&A, m, 0.0);
    double *b = malloc((size_t)n * sizeof *b), *x0 = calloc((size_t)n, sizeof *x0),
           *x1 = calloc((size_t)n, sizeof *x1);
    for (int i = 0; i < n; i++) b[i] = 1.0;
    lub_linsolver_options oc = lub_linsolver_defaults();
    oc.kind = LUB_LINSOLVER_CHOLMOD;
    solve(&oc, &A, b, x0);
    for (int k = 0; lub_petsc_ksp_names[k]; k++)
        for (int p = 0; lub_petsc_pc_names[p]; p++) {
            lub_linsolver_options o = petsc_options(k, p, 1e-11);
            memset(x1, 0, (size_t)n * sizeof *x1);
            lub_solve_result r = solve(&o, &A, b, x1);
            if (!(r.status == LUB_SOLVE_OK && max_rel_diff(x1, x0, n) < 1e-7))
                printf("  ksp %s pc %s: status %d, %d iterations, difference %g\n",
                       lub_petsc_ksp_names[k], lub_petsc_pc_names[p], (int)r.status, r.iterations,
                       max_rel_diff(x1, x0, n));
            CHECK(r.status == LUB_SOLVE_OK);
            CHECK(max_rel_diff(x1, x0, n) < 1e-7);
        }
    /* too few iterations: not converged, reported, the program goes on */
    lub_linsolver_options o = petsc_options(LUB_PETSC_KSP_CG, LUB_PETSC_PC_NONE, 1e-12);
    o.pcg.max_iter = 3;
    memset(x1, 0, (size_t)n * sizeof *x1);
    lub_solve_result r = solve(&o, &A, b, x1);
    CHECK(r.status == LUB_SOLVE_NOT_CONVERGED);
    CHECK(r.iterations == 3);
    free(b), free(x0), free(x1);
    lub_csr_free(&A);
}

int main(void)
{
    (void)test_last_error;
    if (!lub_petsc_available()) {
        printf("SKIP petsc_test: %s (make PETSC=1 after bin/installDeps)\n", lub_petsc_version());
        CHECK(!strcmp(lub_linsolver_choice_names[LUB_LINSOLVER_PETSC], "petsc"));
        return test_summary();
    }
    printf("  %s\n", lub_petsc_version());
    RUN(test_cg_hypre_matches_cholmod);
    RUN(test_reuse_and_pattern_change);
    RUN(test_each_method);
    return test_summary();
}
