/* lubkit linalg: aggregation algebraic multigrid, used as a PCG preconditioner ("amg").
 *
 * The thesis solved its pressure Poisson equation with aggregation AMG (Notay's AGMG,
 * methods.md §2 step 5), because the iteration count of CG with a one-level preconditioner
 * (Jacobi, IC(0)) grows with the particle count.  This is the simplest member of that
 * family:
 *   - strength of connection: j is a strong neighbour of i if -a_ij >= theta max_k(-a_ik)
 *     (theta = 0.5: with w = (r/re - 1)^2 on a lattice, the neighbours at l0 and sqrt(2) l0);
 *   - greedy aggregation: a node whose strong neighbours are all free starts an aggregate
 *     with them; the nodes left over join the aggregate of their strongest neighbour; done
 *     in the smoother's blocks of rows at once (in parallel), each on its own rows;
 *   - piecewise-constant prolongation P, Galerkin coarse matrix A_c = P^T A P;
 *   - levels until at most coarse_max unknowns, solved by a dense Cholesky; and until the
 *     Cholesky factor, computed at every set-up, costs at most a tenth of a solve's work on
 *     the finest level (lub_amg_dense_max): a system of 2,600 unknowns (the reduced wedge at
 *     h0/6) stopped at a dense level of about 370 unknowns whose factor took most of the
 *     pressure solve, now one level more (below);
 *   - one cycle per application: forward Gauss-Seidel from 0, coarse correction scaled by
 *     alpha (over-correction, which plain aggregation needs: its coarse space is too smooth
 *     to represent the error at the scale of an aggregate), backward Gauss-Seidel.  The
 *     coarse correction is one cycle on the next level (V-cycle) or two (W-cycle: the second
 *     for the residual the first left), the coarsest level solved exactly.  On the MPS
 *     pressure matrix of the thesis wedge (56,000 unknowns, 5 levels) the W-cycle needs 9-10
 *     CG iterations to 1e-5 against 17-18 with the V-cycle, the same as with an exact
 *     solve on level 1, for little more work per cycle (the coarse levels hold 6% of the
 *     nonzeros): the default.  Forward then backward sweeps, a symmetric coarse solve and a
 *     fixed alpha make either cycle symmetric, as CG requires.
 *   - the smoother reads the matrix values in single precision (a copy made at set-up):
 *     the sweeps are memory-bound, and a preconditioner needs no more than that (the
 *     IC(0) factor is stored so too); CG's own products use the double values.  A forward
 *     sweep from 0 reads only the lower triangle of each row (the rest multiplies zeros).
 * Positive definiteness is not guaranteed by theory for alpha > 1 with inexact (recursive)
 * coarse solves; it holds on the Poisson and MPS matrices (unit test), and PCG checks r.z > 0
 * at every iteration, so a failure would be reported as LUB_SOLVE_BREAKDOWN, never as a wrong
 * answer.
 * Measured on the 80k MPS-like matrix (tests/bench/linalg_bench.c): 12 CG iterations to 1e-8
 * with the W-cycle, 19 with the V-cycle, against 164 with IC(0).
 * The set-up reuses its arrays (grown, never shrunk), so it allocates nothing in steady
 * state.  With several OpenMP threads the Gauss-Seidel sweeps of the levels above
 * LUB_LINALG_OMP_MIN unknowns are "hybrid": Gauss-Seidel inside one contiguous block of rows
 * per thread, Jacobi between blocks (the forward and backward sweeps stay transposes of
 * each other), so the iteration count depends slightly on the number of threads.
 */
#ifndef LUB_LINALG_AMG_H
#define LUB_LINALG_AMG_H

#include "linalg/csr.h"

#define LUB_AMG_MAX_LEVELS 24
/* Most blocks of the smoother and the aggregation (one per OpenMP thread). */
#define LUB_AMG_MAX_BLOCKS 64

typedef struct lub_amg_level {
    const lub_csr *A; /* level 0: the caller's matrix; others: &own */
    lub_csr own;
    int *agg;        /* n: aggregate (coarse unknown) of each node (not on the coarsest level) */
    int nc;          /* number of aggregates */
    int *mstart;     /* nc + 1: the members of aggregate I are mrows[mstart[I] .. mstart[I+1]) */
    int *mrows;      /* n: the nodes of each aggregate, in increasing order */
    double *b, *x;   /* right-hand side and correction of this level (levels >= 1) */
    double *tmp;     /* residual / previous iterate */
    double *r2, *e2; /* W-cycle: residual and correction of the repeated coarse cycles */
    float *valf;     /* the values of A in single precision, for the smoother */
    int valf_cap;
    int n_cap, agg_cap, mstart_cap, mrows_cap;
} lub_amg_level;

typedef struct lub_amg {
    double theta, alpha; /* strength threshold, coarse-correction scaling */
    int coarse_max;      /* largest coarsest level for the dense Cholesky (see also
                          * lub_amg_dense_max) */
    double dense_budget; /* the dense factor's multiply-adds per unknown of the finest
                          * level, at most (lub_amg_dense_max); 0: no such limit */
    int cycle;           /* 1: V-cycle, 2: W-cycle (cycles on each coarse level) */
    int blocks;          /* smoother blocks: 0 = one per OpenMP thread */
    int nblocks;         /* used by the current set-up */
    int unfused;         /* 1: the residual after pre-smoothing from its definition b - A x
                          * (the test reference); 0 (default): from the upper triangle only */
    int nlev;
    lub_amg_level lev[LUB_AMG_MAX_LEVELS];
    /* coarsest level: dense Cholesky factor (lower, row-major), or GS sweeps when the
     * aggregation stopped coarsening above coarse_max */
    double *dense;
    size_t dense_cap;
    int dense_n, coarse_gs;
    /* Galerkin product workspace: one marker array of the coarse size per thread */
    int *mark;
    int mark_cap;
} lub_amg;

/* The largest coarsest level solved by the dense Cholesky for a finest level of n unknowns:
 * min(coarse_max, max(64, cbrt(3 dense_budget n))), or coarse_max when dense_budget is 0.
 * The factor costs m^3/3 multiply-adds at every set-up; a solve on the finest level about
 * 1,800 n (10 iterations of a cycle that reads its matrix about 6 times, 30 entries a row),
 * and dense_budget = 180 keeps the factor within a tenth of that: m = 111 for n = 2,600, 157
 * for the dam break's 7,200, 311 for the thesis wedge's 56,000 (whose coarsest level, 168,
 * is unchanged).  Measured (two threads): the reduced wedge at h0/6 (900 steps), pressure
 * solve 7.1 -> 2.3 s, 7.5 -> 7.8 iterations a step; the reduced soft EHL 10.3 -> 3.9 s. */
int lub_amg_dense_max(const lub_amg *g, int n);

/* theta 0.5, alpha 1.8, coarse_max 400, dense_budget 180. */
void lub_amg_init(lub_amg *g);
void lub_amg_free(lub_amg *g);

/* Build the hierarchy for A (finished).  Returns 0, or -1 when the coarsest matrix is not
 * positive definite (A is not SPD): the caller must not use the preconditioner then. */
int lub_amg_setup(lub_amg *g, const lub_csr *A);

/* z = M^-1 r: one V-cycle for A z = r.  r and z must not overlap. */
void lub_amg_apply(lub_amg *g, const double *r, double *z);

#endif
