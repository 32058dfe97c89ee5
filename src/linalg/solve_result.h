/* lubkit linalg: the outcome of a linear solve, common to PCG and CHOLMOD.
 *
 * A solver never stops the program: it fills a lub_solve_result and the caller decides
 * (the MPS solver stops with exit 2 unless system/solution.yaml says to continue, issue 4).
 */
#ifndef LUB_LINALG_SOLVE_RESULT_H
#define LUB_LINALG_SOLVE_RESULT_H

#include <stddef.h>

typedef enum {
    LUB_SOLVE_OK = 0,            /* converged (PCG) / factorized and solved (CHOLMOD) */
    LUB_SOLVE_NOT_CONVERGED = 1, /* PCG reached its maximum number of iterations */
    LUB_SOLVE_BREAKDOWN = 2,     /* PCG: p.Ap <= 0 or r.z <= 0: matrix or preconditioner
                                    not positive definite */
    LUB_SOLVE_NOT_POSDEF = 3,    /* CHOLMOD: non-positive pivot at column 'column' */
    LUB_SOLVE_NONFINITE = 4,     /* NaN or Inf in the right-hand side or the iterates */
    LUB_SOLVE_FAILED = 5         /* any other library failure (out of memory, ...) */
} lub_solve_status;

typedef struct lub_solve_result {
    lub_solve_status status;
    int converged;    /* status == LUB_SOLVE_OK */
    int iterations;   /* PCG iterations (0 for CHOLMOD) */
    double residual;  /* final relative residual ||b - A x|| / ||b|| (true, not recursive) */
    double residual0; /* relative residual of the initial guess (PCG) */
    int column;       /* LUB_SOLVE_NOT_POSDEF: the column (row) where it failed, else -1 */
    double ic_shift;  /* IC(0): diagonal shift used (0 when none was needed) */
} lub_solve_result;

/* "converged", "not converged", ... */
const char *lub_solve_status_name(lub_solve_status s);
/* A one-line description for the log or a fatal message, e.g.
 * "not converged after 1000 iterations: relative residual 3.2e-05 (initial 1)". */
void lub_solve_result_describe(const lub_solve_result *r, char *buf, size_t size);

#endif
