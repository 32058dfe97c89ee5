/* lubkit linalg: PETSc's Krylov solvers (KSP) for the pressure and viscosity systems, e.g.
 * CG with hypre's BoomerAMG (issue 31), selected in system/solution.yaml:
 *
 *     p: { solver: petsc, ksp: cg, pc: hypre, tolerance: 1e-8, maxIter: 2000 }
 *
 *     lub_petsc *s = lub_petsc_new(&opts);                  once (PETSc started on first use)
 *     each step:  assemble A (csr.h);
 *                 lub_petsc_setup(s, &A, &pcg_opts, &res);  the matrix and preconditioner
 *                 lub_petsc_solve(s, &A, nrhs, b, x, &pcg_opts, res);
 *     lub_petsc_free(s);
 *
 * The matrix is a PETSc AIJ matrix made from the rows of our CSR (MatCreateMPIAIJWithArrays:
 * this process's rows with global column numbers): serially on PETSC_COMM_SELF; a
 * distributed CSR (csr.h: A->colmap, lubFoam -parallel) on PETSC_COMM_WORLD, each rank's
 * rows in global columns (sorted within each row), the norms over all ranks, and a new
 * matrix made by every rank when any rank's pattern changed.  While the pattern stays (compared, as CHOLMOD's analysis is: row pointers
 * and columns kept), only the values are copied in (MatUpdateMPIAIJWithArrays: no
 * allocation on our side); a new pattern makes a new matrix.  The right-hand sides and
 * solutions are the caller's arrays placed in two PETSc vectors (VecPlaceArray: no copy).
 * hypre builds its hierarchy in every set-up (BoomerAMG allocates inside PCSetUp).
 *
 * Convergence: ||b - A x|| / ||b|| <= tolerance on the unpreconditioned residual (CG and
 * BiCGStab with left, GMRES with right preconditioning), the same test as lubkit's PCG; the
 * result's residual is recomputed here with one SpMV (as lub_cholmod_solve does).  PETSc's own
 * options (the PETSC_OPTIONS environment variable, e.g. "-ksp_monitor
 * -pc_hypre_boomeramg_strong_threshold 0.5") are applied after ours, for experiments.
 *
 * PETSc (and MPI under it) is started once per program, by the first lub_petsc_new, with its
 * signal handlers off (lubFoam's stop signal stays lubFoam's), and finalised at exit.  A build
 * without PETSc (make PETSC=0, or petsc-dev not installed) has the names but no solver:
 * lub_petsc_available() is 0 and the dictionary reader reports it.
 */
#ifndef LUB_LINALG_PETSC_SOLVER_H
#define LUB_LINALG_PETSC_SOLVER_H

#include "linalg/csr.h"
#include "linalg/pcg.h"
#include "linalg/solve_result.h"

/* Krylov methods and preconditioners by name (NULL-terminated, indexed by the enums). */
typedef enum { LUB_PETSC_KSP_CG = 0, LUB_PETSC_KSP_GMRES, LUB_PETSC_KSP_BCGS } lub_petsc_ksp;
typedef enum {
    LUB_PETSC_PC_HYPRE = 0, /* hypre BoomerAMG */
    LUB_PETSC_PC_GAMG,      /* PETSc's smoothed-aggregation AMG */
    LUB_PETSC_PC_JACOBI,
    LUB_PETSC_PC_BJACOBI, /* block Jacobi, ILU(0) in the blocks */
    LUB_PETSC_PC_SOR,     /* SSOR sweeps within each process's rows (PETSc's AIJ of a
                             distributed matrix has no incomplete Cholesky: bjacobi) */
    LUB_PETSC_PC_NONE
} lub_petsc_pc;
extern const char *const lub_petsc_ksp_names[];
extern const char *const lub_petsc_pc_names[];

typedef struct lub_petsc_options {
    lub_petsc_ksp ksp;
    lub_petsc_pc pc;
} lub_petsc_options;

/* cg with hypre */
lub_petsc_options lub_petsc_defaults(void);

/* 1 when this build has PETSc. */
int lub_petsc_available(void);
/* "PETSc 3.18.5" or "no PETSc in this build" */
const char *lub_petsc_version(void);

typedef struct lub_petsc lub_petsc; /* opaque */

/* A solver (lub_bug in a build without PETSc: the reader checks lub_petsc_available). */
lub_petsc *lub_petsc_new(const lub_petsc_options *o);
void lub_petsc_free(lub_petsc *s);

/* Copy A (finished) into the PETSc matrix and set the preconditioner up.  LUB_SOLVE_OK or
 * LUB_SOLVE_FAILED (a PETSc error, printed by PETSc). */
lub_solve_status lub_petsc_setup(lub_petsc *s, const lub_csr *A, const lub_pcg_options *o,
                                 lub_solve_result *res);

/* Solve A x_k = b_k, k < nrhs, with the set-up of this A (tolerance, maxIter, warm start of
 * o).  res[k] per right-hand side: iterations, the true relative residual.  Returns the worst
 * status. */
lub_solve_status lub_petsc_solve(lub_petsc *s, const lub_csr *A, int nrhs, const double *const *b,
                                 double *const *x, const lub_pcg_options *o, lub_solve_result *res);

/* Solve B x_k = b_k, k < nrhs, by BiCGStab preconditioned by the preconditioner (the
 * configured pc, e.g. BoomerAMG) of the matrix A of the last lub_petsc_setup: B is another
 * operator on the same rows and columns (distributed as A is), e.g. a nonsymmetric LSMPS
 * Laplacian whose standard counterpart is A (mps/step.c).  Tolerance, maxIter, warm start of
 * o; res[k] with the true residual of B.  Returns the worst status. */
lub_solve_status lub_petsc_solve_other(lub_petsc *s, const lub_csr *B, int nrhs,
                                       const double *const *b, double *const *x,
                                       const lub_pcg_options *o, lub_solve_result *res);

#endif
