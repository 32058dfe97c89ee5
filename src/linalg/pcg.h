/* lubkit linalg: preconditioned conjugate gradients for the symmetric positive definite
 * systems of the MPS step (pressure Poisson T-9, implicit viscosity T-31).
 *
 *     lub_pcg_work w;  lub_pcg_work_init(&w);           once
 *     lub_pcg_options o = lub_pcg_defaults();  o.precond = LUB_PRECOND_IC0; ...
 *     each step:  assemble A (csr.h);
 *                 lub_pcg_solve(&w, &A, b, x, &o, &res);   x holds the initial guess when
 *                                                          o.warm_start (previous pressure)
 *                 if (!res.converged) ... the caller decides (log, stop with exit 2, ...)
 *     lub_pcg_work_free(&w);
 *
 * The preconditioner is built by lub_pcg_setup, which lub_pcg_solve calls by itself when A
 * has been re-assembled (A->stamp) or the preconditioner changed since the last set-up, so
 * several right-hand sides with the same matrix (the velocity components of T-31) share one
 * set-up.  The work arrays grow when n or nnz grows and are reused otherwise: in steady state
 * neither lub_pcg_setup nor lub_pcg_solve allocates.
 *
 * Convergence: ||b - A x|| / ||b|| <= tolerance, checked on the TRUE residual: when the
 * recursively updated residual says converged, b - A x is recomputed and the iteration
 * continues (restarted from the true residual) if the drift put it above the tolerance.
 * b = 0 gives x = 0 at once.
 *
 * Preconditioners (the index is the position in lub_precond_choice_names):
 *   none    M = I
 *   jacobi  M = diag(A); fully parallel (OpenMP), fused with the vector updates
 *   ic0     incomplete Cholesky with zero fill, L on the lower pattern of A (stored in
 *           single precision); its two triangular solves are sequential.  If a pivot is
 *           not positive (possible for an SPD matrix that is not an M-matrix) the
 *           factorisation is repeated for A + s diag(A) with s = 1e-3, 1e-2, ...
 *           (Manteuffel's shift); the shift used is reported in lub_solve_result.ic_shift;
 *           if even s = 100 fails, Jacobi is used and ic_shift = -1.
 *   sgs     symmetric Gauss-Seidel / SSOR with relaxation omega (default 1) straight on the
 *           rows of A (no set-up beyond 1/a_ii); sequential sweeps.
 *   bic0    block IC(0): the rows are split into contiguous blocks balanced by nonzeros, one
 *           per OpenMP thread unless options.blocks says otherwise, and the couplings
 *           between blocks are dropped from the factor, so the factorisation and both
 *           sweeps run in parallel; more iterations than ic0 (2 blocks: +20% on the 80k
 *           MPS-like matrix).  With 1 block it is ic0.
 *   amg     one W-cycle (or V-cycle: options.cycle) of aggregation algebraic multigrid
 *           (amg.h): an iteration count that hardly grows with the particle count,
 *           block-parallel smoothing and aggregation.  The fastest here: 80k MPS-like
 *           unknowns to 1e-8 in 12 iterations (W-cycle; 19 with the V-cycle), about 7
 *           times faster than ic0 on 2 threads (tests/bench/linalg_bench.c, 2026-11-26:
 *           92 ms against 666).  If its coarsest matrix is not
 *           positive definite, Jacobi is used and ic_shift = -1.
 * bic0 and amg iterate differently with a different number of threads (blocks).
 * With OpenMP (OMP_NUM_THREADS) SpMV, dot products and vector updates are parallel.
 */
#ifndef LUB_LINALG_PCG_H
#define LUB_LINALG_PCG_H

#include "linalg/amg.h"
#include "linalg/csr.h"
#include "linalg/solve_result.h"

typedef enum {
    LUB_PRECOND_NONE = 0,
    LUB_PRECOND_JACOBI = 1,
    LUB_PRECOND_IC0 = 2,
    LUB_PRECOND_SGS = 3,
    LUB_PRECOND_BIC0 = 4,
    LUB_PRECOND_AMG = 5
} lub_precond;

/* Most blocks of the block IC(0) (one per OpenMP thread). */
#define LUB_PCG_MAX_BLOCKS 64
/* lub_pcg_solve_multi: at most this many right-hand sides at once (a velocity per dimension) */
#define LUB_PCG_MAX_RHS 3

/* NULL-terminated, indexed by lub_precond: usable with lub_dict_choice (src/io/dict.h). */
extern const char *const lub_precond_choice_names[];
/* The AMG cycles by name, indexed by lub_pcg_options.cycle - 1: "V", "W". */
extern const char *const lub_amg_cycle_names[];

typedef struct lub_pcg_options {
    double tolerance; /* relative residual ||b - A x|| / ||b|| */
    int max_iter;     /* >= 0 */
    lub_precond precond;
    int warm_start; /* 1: x given to lub_pcg_solve is the initial guess; 0: start from 0 */
    double omega;   /* SSOR relaxation, 0 < omega < 2 (sgs only) */
    int blocks;     /* bic0: number of blocks; 0 = one per OpenMP thread */
    int cycle;      /* amg: 1 V-cycle, 2 W-cycle (default) */
} lub_pcg_options;

/* tolerance 1e-8, max_iter 1000, jacobi, no warm start, omega 1, blocks 0, W-cycle. */
lub_pcg_options lub_pcg_defaults(void);

typedef struct lub_pcg_work {
    int n_cap, nnz_cap;
    double *r, *z, *p, *q; /* CG vectors: LUB_PCG_MAX_RHS sets of n_cap each */
    double *dinv;          /* 1 / a_ii (jacobi, sgs) or 1 / L_ii (ic0) */
    /* IC(0) factor: strictly lower part of L in CSR (own copy of the lower pattern of A) */
    int *l_ptr, *l_col;
    int *l_first; /* n: first entry of row i of A kept in L (block IC(0)) */
    int nblocks, blk[LUB_PCG_MAX_BLOCKS + 1]; /* row ranges of the blocks */
    float *l_val; /* single precision: the sweeps are bandwidth-bound, and a rounded L
                     is still an exact factor of an SPD M = L L^T */
    int *mark;    /* n, -1 outside the IC(0) factorisation of a row */
    lub_amg amg;  /* amg */
    /* what the preconditioner was built for */
    const lub_csr *A;
    unsigned long stamp;
    lub_precond precond, precond_used;
    double omega;
    int blocks_opt;
    double ic_shift;
    int ready;
} lub_pcg_work;

void lub_pcg_work_init(lub_pcg_work *w);
void lub_pcg_work_free(lub_pcg_work *w);

/* Build the preconditioner o->precond for A (finished, lub_csr_finish).  Returns the IC(0)
 * diagonal shift used (0: none; -1: fell back to Jacobi; 0 for other preconditioners). */
double lub_pcg_setup(lub_pcg_work *w, const lub_csr *A, const lub_pcg_options *o);

/* Solve A x = b.  x: initial guess if o->warm_start, overwritten by the solution (the last
 * iterate when not converged).  Never stops the program; see res->status.  A bad option
 * (tolerance <= 0 or not finite, max_iter < 0, omega outside (0, 2)) is a bug of the caller. */
void lub_pcg_solve(lub_pcg_work *w, const lub_csr *A, const double *b, double *x,
                   const lub_pcg_options *o, lub_solve_result *res);

/* Solve A x_k = b_k for nrhs (1 to LUB_PCG_MAX_RHS) right-hand sides: one CG each, with the
 * same results as nrhs calls of lub_pcg_solve (to round-off of the parallel sums; exactly on
 * one thread), but with their matrix products (and, with a warm start, their initial
 * residuals) fused into one pass over A.  res[k] per right-hand side. */
void lub_pcg_solve_multi(lub_pcg_work *w, const lub_csr *A, int nrhs, const double *const *b,
                         double *const *x, const lub_pcg_options *o, lub_solve_result *res);

/* Apply the preconditioner set up in w: z = M^-1 r (exposed for tests). */
void lub_pcg_precond_apply(lub_pcg_work *w, const lub_csr *A, const double *r, double *z);

#endif
