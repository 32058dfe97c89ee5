/* lubkit linalg: one front for the linear solvers, selected by name as in
 * system/solution.yaml (issue 4), e.g.
 *
 *     p:                          # pressure Poisson equation (T-9)
 *       solver: pcg               # lub_linsolver_choice_names: cholmod | pcg | petsc
 *       preconditioner: amg       # none | jacobi | ic0 | sgs | bic0 | amg
 *       tolerance: 1e-8           # relative residual ||b - A x|| / ||b|| (pcg)
 *       maxIter: 1000             # (pcg)
 *       warmStart: true           # start from the previous solution (pcg)
 *       ksp: cg                   # petsc: cg | gmres | bcgs (petsc_solver.h)
 *       pc: hypre                 # petsc: hypre (BoomerAMG) | gamg | jacobi | ...
 *
 * The reader of the dictionary (the solver) fills lub_linsolver_options with
 * lub_dict_choice(map, "solver", lub_linsolver_choice_names, LUB_LINSOLVER_PCG) and so on;
 * the enum values are the indices in the name arrays.
 *
 *     lub_linsolver s;  lub_linsolver_init(&s, &opts);
 *     each step:  assemble A;
 *                 lub_linsolver_setup(&s, &A, &res)  factorise / build the preconditioner
 *                 lub_linsolver_solve(&s, &A, nrhs, b, x, res)   x: initial guesses if warm
 *     lub_linsolver_free(&s);
 * lub_linsolver_solve calls setup itself when it was not done for this assembly of A.
 */
#ifndef LUB_LINALG_LINSOLVE_H
#define LUB_LINALG_LINSOLVE_H

#include "linalg/cholmod_solver.h"
#include "linalg/csr.h"
#include "linalg/pcg.h"
#include "linalg/petsc_solver.h"
#include "linalg/solve_result.h"

typedef enum {
    LUB_LINSOLVER_CHOLMOD = 0,
    LUB_LINSOLVER_PCG = 1,
    LUB_LINSOLVER_PETSC = 2 /* only where lub_petsc_available() */
} lub_linsolver_kind;

/* NULL-terminated, indexed by lub_linsolver_kind (for lub_dict_choice). */
extern const char *const lub_linsolver_choice_names[];

typedef struct lub_linsolver_options {
    lub_linsolver_kind kind;
    lub_pcg_options pcg;         /* tolerance, max_iter, precond, warm_start, omega (and the
                                    tolerance, max_iter, warm_start of petsc) */
    lub_petsc_options petsc;     /* ksp, pc */
    lub_cholmod_options cholmod; /* ordering, factor kind */
    lub_pattern_hint pattern;    /* cholmod: how to decide on re-analysis (COMPARE) */
} lub_linsolver_options;

/* pcg with the lub_pcg_defaults, cholmod defaults, pattern compare. */
lub_linsolver_options lub_linsolver_defaults(void);

typedef struct lub_linsolver {
    lub_linsolver_options o;
    lub_pcg_work pcg;
    lub_cholmod *chol; /* NULL unless kind == cholmod */
    lub_petsc *petsc;  /* NULL unless kind == petsc */
    const lub_csr *A;  /* matrix of the last successful set-up, and its stamp */
    unsigned long stamp;
    lub_solve_result setup_result; /* of the last set-up (cholmod: NOT_POSDEF + column) */
    int ready;
} lub_linsolver;

void lub_linsolver_init(lub_linsolver *s, const lub_linsolver_options *o);
void lub_linsolver_free(lub_linsolver *s);

/* "pcg (ic0), tolerance 1e-08, maxIter 1000, warm start" for the log. */
void lub_linsolver_describe(const lub_linsolver *s, char *buf, size_t size);

/* Factorise (cholmod) or build the preconditioner (pcg) for A.  Returns the status:
 * cholmod may return LUB_SOLVE_NOT_POSDEF / LUB_SOLVE_FAILED (details in *res if res is not
 * NULL); pcg always LUB_SOLVE_OK (res->ic_shift reports an IC(0) shift). */
lub_solve_status lub_linsolver_setup(lub_linsolver *s, const lub_csr *A, lub_solve_result *res);

/* Solve A x_k = b_k for k < nrhs (several right-hand sides share the set-up: the velocity
 * components of T-31).  With warm_start (pcg), x_k holds the initial guess.  res[k] per
 * right-hand side; returns the worst status.  When the set-up failed, every res[k] carries
 * its status (and column) and x is left untouched. */
lub_solve_status lub_linsolver_solve(lub_linsolver *s, const lub_csr *A, int nrhs,
                                     const double *const *b, double *const *x,
                                     lub_solve_result *res);

#endif
