/* lubkit linalg: sparse Cholesky through SuiteSparse CHOLMOD.
 *
 *     lub_cholmod *s = lub_cholmod_new(&opts);                 once (cholmod_start)
 *     each step:  assemble A (csr.h);
 *                 lub_cholmod_factorize(s, &A, LUB_PATTERN_COMPARE, &res);
 *                 lub_cholmod_solve(s, &A, nrhs, b, x, res);  one result per right-hand side
 *     lub_cholmod_free(s);                                     cholmod_finish
 *
 * The CSR arrays of the full symmetric matrix are its CSC arrays too, so they are handed to
 * CHOLMOD without a copy as a cholmod_sparse with stype = 1 (CHOLMOD reads the upper
 * triangle of the CSC, i.e. the lower part of each CSR row, and ignores the rest).
 *
 * The symbolic analysis (fill-reducing ordering, elimination tree, supernodes) is the costly
 * part that depends only on the pattern.  It is redone only when the pattern changed:
 *   LUB_PATTERN_COMPARE  compare A's pattern with the one analysed last (a copy is kept;
 *                        memcmp of n + nnz ints, small next to a factorisation);
 *   LUB_PATTERN_SAME     the caller knows it did not change (e.g. a neighbour list with a
 *                        skin, pairs beyond re stored as explicit zeros);
 *   LUB_PATTERN_CHANGED  re-analyse.
 * A factorisation that meets a non-positive pivot returns LUB_SOLVE_NOT_POSDEF with the
 * (original, unpermuted) column in res->column; it never stops the program.  Every CHOLMOD
 * call's return value and Common->status are checked.  Solves use cholmod_solve2 with
 * workspace kept between calls.  CHOLMOD itself allocates inside factorize/solve only when
 * sizes grow.
 *
 * res->residual after lub_cholmod_solve is the true ||b - A x|| / ||b|| (one SpMV each), so
 * that the log reports the same figure for every solver.
 */
#ifndef LUB_LINALG_CHOLMOD_SOLVER_H
#define LUB_LINALG_CHOLMOD_SOLVER_H

#include "linalg/csr.h"
#include "linalg/solve_result.h"

typedef enum {
    LUB_PATTERN_COMPARE = 0,
    LUB_PATTERN_SAME = 1,
    LUB_PATTERN_CHANGED = 2
} lub_pattern_hint;

/* Fill-reducing ordering; index = position in lub_cholmod_ordering_names. */
typedef enum {
    LUB_CHOLMOD_ORDER_AUTO = 0, /* CHOLMOD default: AMD, then METIS/NESDIS if fill is high */
    LUB_CHOLMOD_ORDER_AMD = 1,
    LUB_CHOLMOD_ORDER_METIS = 2
} lub_cholmod_ordering;
extern const char *const lub_cholmod_ordering_names[]; /* NULL-terminated */

/* Factor form; index = position in lub_cholmod_factor_names. */
typedef enum {
    LUB_CHOLMOD_AUTO = 0, /* CHOLMOD chooses from the flop count */
    LUB_CHOLMOD_SIMPLICIAL = 1,
    LUB_CHOLMOD_SUPERNODAL = 2
} lub_cholmod_factor_kind;
extern const char *const lub_cholmod_factor_names[]; /* NULL-terminated */

typedef struct lub_cholmod_options {
    lub_cholmod_ordering ordering;
    lub_cholmod_factor_kind factor;
} lub_cholmod_options;

lub_cholmod_options lub_cholmod_defaults(void); /* auto, auto */

typedef struct lub_cholmod lub_cholmod; /* opaque: holds the cholmod_common */

lub_cholmod *lub_cholmod_new(const lub_cholmod_options *o);
void lub_cholmod_free(lub_cholmod *s);

/* Symbolic analysis of A's pattern, unconditionally (lub_cholmod_factorize calls it when
 * needed; exposed to time it).  LUB_SOLVE_OK or LUB_SOLVE_FAILED. */
lub_solve_status lub_cholmod_analyse(lub_cholmod *s, const lub_csr *A, lub_solve_result *res);

/* Analyse (if needed) and factorise A (finished, lub_csr_finish).  Fills res (iterations 0,
 * residual 0) and returns its status: LUB_SOLVE_OK, LUB_SOLVE_NOT_POSDEF (res->column) or
 * LUB_SOLVE_FAILED. */
lub_solve_status lub_cholmod_factorize(lub_cholmod *s, const lub_csr *A, lub_pattern_hint hint,
                                       lub_solve_result *res);

/* Solve A x_k = b_k, k < nrhs, with the factor of the last successful lub_cholmod_factorize,
 * which must be of this A (same stamp: a bug otherwise).  res[k] per right-hand side.
 * Returns the worst status. */
lub_solve_status lub_cholmod_solve(lub_cholmod *s, const lub_csr *A, int nrhs,
                                   const double *const *b, double *const *x, lub_solve_result *res);

/* Statistics: number of symbolic analyses and numeric factorisations done, and the number
 * of nonzeros in the current factor L (0 when none). */
void lub_cholmod_stats(const lub_cholmod *s, long *analyses, long *factorizations, double *lnz);

#endif
