/* lubkit linalg: BiCGStab for the nonsymmetric systems of the LSMPS Laplacian.
 *
 * The LSMPS Laplacian (src/mps/lsmps.h, Tamai & Koshizuka 2014) gives each particle its own
 * least-squares coefficients, so the matrix of an implicit viscosity step or of a pressure
 * equation built with it is not symmetric (its pattern is: j is a neighbour of i when i is one
 * of j).  CG needs a symmetric positive definite matrix; BiCGStab (van der Vorst 1992) needs
 * neither, at two products and two preconditioner applications an iteration.
 *
 * Right preconditioning, A M^-1 y = b, x = M^-1 y: the residual BiCGStab monitors is then the
 * true residual b - A x of the unpreconditioned system, the quantity the tolerance is about
 * (as for lub_pcg_solve).  The preconditioner is a callback, so that it can be built on
 * another matrix: the standard MPS matrix of the same particles (symmetric positive definite,
 * spectrally close to the LSMPS one) with the project's AMG or Jacobi (lub_pcg_precond_apply),
 * which the symmetric set-ups require.
 *
 *     lub_bicgstab_work w;  lub_bicgstab_work_init(&w);
 *     lub_bicgstab_solve(&w, &A, b, x, precond, ctx, tolerance, max_iter, warm, &res);
 *     lub_bicgstab_work_free(&w);
 *
 * The work vectors grow with n and are kept: no allocation once they are large enough.
 */
#ifndef LUB_LINALG_BICGSTAB_H
#define LUB_LINALG_BICGSTAB_H

#include "linalg/csr.h"
#include "linalg/solve_result.h"

/* z = M^-1 r (n values), with the caller's context; NULL: no preconditioner (z = r). */
typedef void (*lub_precond_fn)(void *ctx, const double *r, double *z);

typedef struct {
    int n_cap;
    double *r, *r0, *p, *v, *s, *t, *ph, *sh; /* n_cap each */
} lub_bicgstab_work;

void lub_bicgstab_work_init(lub_bicgstab_work *w);
void lub_bicgstab_work_free(lub_bicgstab_work *w);

/* Solve A x = b to the relative residual ||b - A x|| / ||b|| <= tolerance (true residual,
 * checked at exit), at most max_iter iterations; warm: x holds the initial guess, else the
 * solve starts from 0.  Never fatal: res says what happened (LUB_SOLVE_BREAKDOWN when
 * rho or omega vanish, LUB_SOLVE_NONFINITE on NaN/Inf, LUB_SOLVE_NOT_CONVERGED); x then holds
 * the last iterate.  b = 0 gives x = 0. */
lub_solve_status lub_bicgstab_solve(lub_bicgstab_work *w, const lub_csr *A, const double *b,
                                    double *x, lub_precond_fn precond, void *ctx, double tolerance,
                                    int max_iter, int warm, lub_solve_result *res);

#endif
