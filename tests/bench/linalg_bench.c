/* Benchmark of the linear solvers of src/linalg on an MPS-like pressure Poisson matrix
 * (not part of make test).
 *
 * The matrix: particles on an nx x ny square lattice of spacing l0 = 1 (a 2-D tank), the
 * neighbours within re = 3.1 l0 (28 per interior particle), weights w = (r/re - 1)^2,
 *     A_ij = -w_ij,   A_ii = sum_j w_ij  (+ the weights of Dirichlet neighbours),
 * the negated Laplacian of T-9 up to its constant factor.  The top row of the tank is a free
 * surface: the lattice is continued by ghost particles with p = 0 (Dirichlet) above it, whose
 * weights go to the diagonal only; the side and bottom walls simply have no neighbours
 * outside (Neumann-like).  So the matrix is SPD with the condition number of a Poisson
 * problem with one Dirichlet side, the hard case for CG.
 *
 * Build and run (from the repository root):
 *     cc -std=c11 -O2 -fopenmp -Isrc -I/usr/include/suitesparse -D_POSIX_C_SOURCE=200809L \
 *        tests/bench/linalg_bench.c src/linalg/[a-z]*.c src/core/error.c \
 *        -o /tmp/linalg_bench -lcholmod -lsuitesparseconfig -lm
 *     OMP_NUM_THREADS=2 /tmp/linalg_bench [nx ny [reps [pcg]]]  (default 400 200 3: 80,000;
 *                                                              pcg: skip CHOLMOD)
 *     OMP_NUM_THREADS=1 LUB_BENCH_CPU=1 /tmp/linalg_bench     (CPU time, see now())
 * Each figure is the best of reps runs (wall time, omp_get_wtime).
 */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "linalg/linsolve.h"

static const double RE = 3.1;

static int nx, ny;
static int noff, offx[64], offy[64];
static double offw[64];

static void offsets(void)
{
    noff = 0;
    for (int dy = -3; dy <= 3; dy++)
        for (int dx = -3; dx <= 3; dx++) {
            double r = sqrt((double)(dx * dx + dy * dy));
            if ((dx || dy) && r <= RE) {
                offx[noff] = dx;
                offy[noff] = dy;
                double t = r / RE - 1.0;
                offw[noff] = t * t;
                noff++;
            }
        }
}

/* Two-pass assembly as the MPS code will do it (csr.h). */
static void assemble(lub_csr *A)
{
    const int n = nx * ny;
    lub_csr_begin(A, n);
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; i++) {
        int ix = i % nx, iy = i / nx, len = 1;
        for (int k = 0; k < noff; k++) {
            int jx = ix + offx[k], jy = iy + offy[k];
            if (jx >= 0 && jx < nx && jy >= 0 && jy < ny) len++;
        }
        lub_csr_set_row_length(A, i, len);
    }
    lub_csr_alloc(A);
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; i++) {
        int ix = i % nx, iy = i / nx, m = 1;
        int *c = lub_csr_row_col(A, i);
        double *v = lub_csr_row_val(A, i);
        double diag = 0.0;
        for (int k = 0; k < noff; k++) {
            int jx = ix + offx[k], jy = iy + offy[k];
            if (jx >= 0 && jx < nx && jy >= 0 && jy < ny) {
                c[m] = jy * nx + jx;
                v[m++] = -offw[k];
                diag += offw[k];
            } else if (jy >= ny && jx >= 0 && jx < nx) {
                diag += offw[k]; /* Dirichlet ghost above the free surface */
            }
        }
        c[0] = i; /* diagonal first: lub_csr_finish sorts */
        v[0] = diag;
    }
    lub_csr_finish(A);
}

/* Wall time, or with LUB_BENCH_CPU=1 the CPU time of the process: with 1 thread on a machine
 * shared with other jobs, the CPU time is what the wall time would be on a quiet one. */
static int use_cpu;
static double now(void)
{
    if (!use_cpu) return omp_get_wtime();
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int main(int argc, char **argv)
{
    nx = argc > 2 ? atoi(argv[1]) : 400;
    ny = argc > 2 ? atoi(argv[2]) : 200;
    int reps = argc > 3 ? atoi(argv[3]) : 3;
    use_cpu = getenv("LUB_BENCH_CPU") && atoi(getenv("LUB_BENCH_CPU"));
    const double tol = 1e-8;
    offsets();
    const int n = nx * ny;
    lub_csr A;
    lub_csr_init(&A);
    double t, best;

    best = 1e30;
    for (int r = 0; r < reps + 1; r++) { /* the first assembly allocates */
        t = now();
        assemble(&A);
        if (r) best = fmin(best, now() - t);
    }
    printf("MPS-like Poisson matrix %d x %d = %d unknowns, %d nonzeros (%.1f per row), "
           "%d thread(s), best of %d, %s time\n",
           nx, ny, n, A.nnz, (double)A.nnz / n, omp_get_max_threads(), reps,
           use_cpu ? "CPU" : "wall");
    printf("  assembly (two passes + finish)   %8.2f ms\n", 1e3 * best);
    printf("  asymmetry %.3g\n", lub_csr_asymmetry(&A));

    double *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
    double *b2 = malloc(n * sizeof *b2), *x2 = malloc(n * sizeof *x2);
    unsigned s = 12345;
    for (int i = 0; i < n; i++) {
        s = s * 1103515245u + 12345u;
        b[i] = ((s >> 8) & 0xffff) / 32768.0 - 1.0; /* PND deviations: noise, all modes */
    }
    best = 1e30;
    for (int r = 0; r < 10 * reps; r++) {
        t = now();
        lub_csr_spmv(&A, b, y);
        best = fmin(best, now() - t);
    }
    printf("  SpMV                             %8.2f ms\n", 1e3 * best);

    printf("PCG, tolerance %g, random right-hand side, x0 = 0; then warm start (the previous "
           "solution) for a right-hand side changed by 1%%\n",
           tol);
    printf("  %-8s %10s %10s %6s %12s %10s %6s\n", "precond", "setup ms", "solve ms", "iter",
           "ms/iter", "warm ms", "iter");
    for (int pc = 0; lub_precond_choice_names[pc]; pc++) {
        if (pc == LUB_PRECOND_NONE) continue;
        lub_pcg_work w;
        lub_pcg_work_init(&w);
        lub_pcg_options o = lub_pcg_defaults();
        o.precond = pc;
        o.tolerance = tol;
        o.max_iter = 20000;
        lub_solve_result res, res2;
        double bs = 1e30, bsolve = 1e30, bwarm = 1e30;
        for (int r = 0; r < reps + 1; r++) {
            t = now();
            lub_pcg_setup(&w, &A, &o);
            if (r) bs = fmin(bs, now() - t);
            t = now();
            lub_pcg_solve(&w, &A, b, x, &o, &res);
            if (r) bsolve = fmin(bsolve, now() - t);
            /* warm start: next step's right-hand side differs a little */
            for (int i = 0; i < n; i++) b2[i] = b[i] * (1.0 + 0.01 * sin(0.1 * i));
            memcpy(x2, x, n * sizeof *x);
            lub_pcg_options o2 = o;
            o2.warm_start = 1;
            t = now();
            lub_pcg_solve(&w, &A, b2, x2, &o2, &res2);
            if (r) bwarm = fmin(bwarm, now() - t);
        }
        printf("  %-8s %10.2f %10.2f %6d %12.3f %10.2f %6d   %s residual %.2e%s\n",
               lub_precond_choice_names[pc], 1e3 * bs, 1e3 * bsolve, res.iterations,
               1e3 * bsolve / (res.iterations ? res.iterations : 1), 1e3 * bwarm, res2.iterations,
               lub_solve_status_name(res.status), res.residual, res.ic_shift ? " (IC shift)" : "");
        lub_pcg_work_free(&w);
    }

    {
        /* The implicit viscosity (T-31): one matrix I + c L for the 2 (3) velocity components,
         * here I + c A with c = 4 (diagonal about 6 times the off-diagonal sum: the diffusion
         * number of the tutorials), Jacobi PCG: the components one after the other against
         * lub_pcg_solve_multi, which reads the matrix once per iteration for all of them. */
        lub_csr V;
        lub_csr_init(&V);
        lub_csr_begin(&V, n);
        for (int i = 0; i < n; i++) lub_csr_set_row_length(&V, i, A.row_ptr[i + 1] - A.row_ptr[i]);
        lub_csr_alloc(&V);
        for (int i = 0; i < n; i++)
            for (int k = A.row_ptr[i]; k < A.row_ptr[i + 1]; k++) {
                V.col[k] = A.col[k];
                V.val[k] = 4.0 * A.val[k] + (A.col[k] == i ? 1.0 : 0.0);
            }
        lub_csr_finish(&V);
        double *bv[3], *xv[3];
        for (int d = 0; d < 3; d++) {
            bv[d] = malloc(n * sizeof(double));
            xv[d] = malloc(n * sizeof(double));
            for (int i = 0; i < n; i++) bv[d][i] = b[i] * (1.0 + 0.3 * d * sin(0.01 * i));
        }
        lub_pcg_work w;
        lub_pcg_work_init(&w);
        lub_pcg_options o = lub_pcg_defaults();
        o.precond = LUB_PRECOND_JACOBI;
        o.tolerance = 1e-10;
        lub_solve_result res[3];
        printf("Implicit viscosity I + 4 A, jacobi, tolerance 1e-10 (ms; iterations)\n");
        for (int nrhs = 2; nrhs <= 3; nrhs++) {
            double bsep = 1e30, bmul = 1e30;
            for (int r = 0; r < reps + 1; r++) {
                t = now();
                for (int d = 0; d < nrhs; d++) lub_pcg_solve(&w, &V, bv[d], xv[d], &o, &res[d]);
                if (r) bsep = fmin(bsep, now() - t);
                t = now();
                lub_pcg_solve_multi(&w, &V, nrhs, (const double *const *)bv, xv, &o, res);
                if (r) bmul = fmin(bmul, now() - t);
            }
            printf("  %d components: one after the other %8.2f, fused %8.2f (%.0f%%); %d", nrhs,
                   1e3 * bsep, 1e3 * bmul, 100 * bmul / bsep, res[0].iterations);
            for (int d = 1; d < nrhs; d++) printf(", %d", res[d].iterations);
            printf("\n");
        }
        lub_pcg_work_free(&w);
        for (int d = 0; d < 3; d++) free(bv[d]), free(xv[d]);
        lub_csr_free(&V);
    }

    if (argc > 4 && strcmp(argv[4], "pcg") == 0) goto done;
    int creps = reps < 2 ? reps : 2; /* factorisations take seconds */
    printf("CHOLMOD (best of %d; analyse once, then factorize + solve per step; solve "
           "includes the residual check)\n",
           creps);
    printf("  %-8s %-11s %10s %10s %10s %10s %12s %10s\n", "ordering", "factor", "analyse ms",
           "factor ms", "solve ms", "3 rhs ms", "nnz(L)", "residual");
    for (int ord = 0; lub_cholmod_ordering_names[ord]; ord++)
        for (int fk = 1; lub_cholmod_factor_names[fk]; fk++) {
            lub_cholmod_options co = {ord, fk};
            double ba = 1e30, bf = 1e30, bsv = 1e30, b3 = 1e30, lnz = 0;
            lub_solve_result res, r3[3];
            for (int r = 0; r < creps; r++) {
                lub_cholmod *ch = lub_cholmod_new(&co);
                t = now();
                lub_cholmod_analyse(ch, &A, &res);
                double ta = now() - t;
                t = now();
                if (lub_cholmod_factorize(ch, &A, LUB_PATTERN_SAME, &res) != LUB_SOLVE_OK) {
                    printf("  factorisation failed: %s\n", lub_solve_status_name(res.status));
                    return 1;
                }
                double tf = now() - t;
                ba = fmin(ba, ta);
                bf = fmin(bf, tf);
                const double *bb[3] = {b, b2, b};
                double *xx[3] = {x, x2, y};
                t = now();
                lub_cholmod_solve(ch, &A, 1, bb, xx, &res);
                bsv = fmin(bsv, now() - t);
                t = now();
                lub_cholmod_solve(ch, &A, 3, bb, xx, r3);
                b3 = fmin(b3, now() - t);
                lub_cholmod_stats(ch, NULL, NULL, &lnz);
                lub_cholmod_free(ch);
            }
            printf("  %-8s %-11s %10.1f %10.1f %10.2f %10.2f %12.0f %10.1e\n",
                   lub_cholmod_ordering_names[ord], lub_cholmod_factor_names[fk], 1e3 * ba,
                   1e3 * bf, 1e3 * bsv, 1e3 * b3, lnz, res.residual);
        }
done:
    free(b);
    free(x);
    free(y);
    free(b2);
    free(x2);
    lub_csr_free(&A);
    return 0;
}
