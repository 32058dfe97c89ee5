/* lubkit linalg: PETSc KSP solvers (see petsc_solver.h).  Compiled with PETSc's flags only
 * when the build has PETSc (Makefile: PETSC=1 defines LUB_HAVE_PETSC for this file). */
#include "linalg/petsc_solver.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

const char *const lub_petsc_ksp_names[] = {"cg", "gmres", "bcgs", NULL};
const char *const lub_petsc_pc_names[] = {"hypre", "gamg", "jacobi", "bjacobi",
                                          "sor",   "none", NULL};

lub_petsc_options lub_petsc_defaults(void)
{
    lub_petsc_options o = {LUB_PETSC_KSP_CG, LUB_PETSC_PC_HYPRE};
    return o;
}

#ifndef LUB_HAVE_PETSC

int lub_petsc_available(void)
{
    return 0;
}
const char *lub_petsc_version(void)
{
    return "no PETSc in this build";
}
lub_petsc *lub_petsc_new(const lub_petsc_options *o)
{
    (void)o;
    lub_bug("lub_petsc_new in a build without PETSc");
}
void lub_petsc_free(lub_petsc *s)
{
    (void)s;
}
lub_solve_status lub_petsc_setup(lub_petsc *s, const lub_csr *A, const lub_pcg_options *o,
                                 lub_solve_result *res)
{
    (void)s, (void)A, (void)o, (void)res;
    lub_bug("lub_petsc_setup in a build without PETSc");
}
lub_solve_status lub_petsc_solve(lub_petsc *s, const lub_csr *A, int nrhs, const double *const *b,
                                 double *const *x, const lub_pcg_options *o, lub_solve_result *res)
{
    (void)s, (void)A, (void)nrhs, (void)b, (void)x, (void)o, (void)res;
    lub_bug("lub_petsc_solve in a build without PETSc");
}
lub_solve_status lub_petsc_solve_other(lub_petsc *s, const lub_csr *B, int nrhs,
                                       const double *const *b, double *const *x,
                                       const lub_pcg_options *o, lub_solve_result *res)
{
    (void)s, (void)B, (void)nrhs, (void)b, (void)x, (void)o, (void)res;
    lub_bug("lub_petsc_solve_other in a build without PETSc");
}

#else

#include <petscksp.h>

_Static_assert(sizeof(PetscInt) == sizeof(int), "lub_csr's int indices are PetscInt");
_Static_assert(sizeof(PetscScalar) == sizeof(double), "a real, double PETSc");

struct lub_petsc {
    lub_petsc_options o;
    MPI_Comm comm;
    Mat A;
    Vec b, x;
    KSP ksp;
    int n, nnz;     /* size of A and of the vectors (0: none yet) */
    int *ptr, *col; /* the pattern A was made with (MatUpdateMPIAIJWithArrays needs it) */
    int n_cap, nnz_cap;
    /* a distributed matrix (A->colmap): its rows in global columns, sorted within each row
     * (MatUpdateMPIAIJWithArrays copies the values of a row in the order of its global
     * columns), perm[k] the entry of A's row that is the k-th of the sorted row */
    int dist, nglobal;
    int *gcol, *perm;
    double *gval;
    int g_cap;
    Vec rv;            /* the residual (distributed) */
    double *r;         /* residual work, n_cap */
    const lub_csr *As; /* the CSR and stamp of the last set-up */
    unsigned long stamp;
    int ready;
    /* lub_petsc_solve_other: the other operator B (its pattern, sorted rows as gcol/perm/
     * gval) and its BiCGStab, preconditioned from A */
    Mat B;
    KSP kspb;
    int bn, bnnz, *bptr, *bcol, bn_cap, bnnz_cap;
    int *bgcol, *bperm;
    double *bgval;
    int bg_cap;
};

static char version[64];

static void petsc_finish(void)
{
    PetscBool up = PETSC_FALSE, down = PETSC_FALSE;
    PetscInitialized(&up);
    PetscFinalized(&down);
    if (up && !down) PetscFinalize();
}

/* Start PETSc once: no signal handlers of its own (lubFoam's SIGINT/SIGTERM stop is
 * lubFoam's), no options from a command line it does not own; finalised at exit. */
static void petsc_start(void)
{
    PetscBool up = PETSC_FALSE;
    PetscInitialized(&up);
    if (up) return;
    if (PetscOptionsSetValue(NULL, "-no_signal_handler", "true") || PetscInitializeNoArguments())
        lub_fatal_run("PETSc did not start (PetscInitialize failed: MPI?)");
    atexit(petsc_finish);
}

int lub_petsc_available(void)
{
    return 1;
}

const char *lub_petsc_version(void)
{
    if (!version[0])
        snprintf(version, sizeof version, "PETSc %d.%d.%d", PETSC_VERSION_MAJOR,
                 PETSC_VERSION_MINOR, PETSC_VERSION_SUBMINOR);
    return version;
}

lub_petsc *lub_petsc_new(const lub_petsc_options *o)
{
    petsc_start();
    lub_petsc *s = lub_calloc(1, sizeof *s);
    s->o = *o;
    s->comm = PETSC_COMM_SELF;
    return s;
}

static void destroy_other(lub_petsc *s)
{
    if (s->kspb) KSPDestroy(&s->kspb);
    if (s->B) MatDestroy(&s->B);
    s->bn = s->bnnz = 0;
}

static void destroy_objects(lub_petsc *s)
{
    destroy_other(s);
    if (s->ksp) KSPDestroy(&s->ksp);
    if (s->A) MatDestroy(&s->A);
    if (s->b) VecDestroy(&s->b);
    if (s->x) VecDestroy(&s->x);
    if (s->rv) VecDestroy(&s->rv);
    s->n = s->nnz = 0;
}

void lub_petsc_free(lub_petsc *s)
{
    if (!s) return;
    destroy_objects(s);
    free(s->ptr);
    free(s->col);
    free(s->r);
    free(s->gcol);
    free(s->perm);
    free(s->gval);
    free(s->bptr);
    free(s->bcol);
    free(s->bgcol);
    free(s->bperm);
    free(s->bgval);
    free(s);
}

/* PETSc calls return an error code; PETSc has printed the trace when it is not 0. */
#define TRY(call)                                                                                  \
    do {                                                                                           \
        if ((call) != 0) goto fail;                                                                \
    } while (0)

/* cols: A's columns as PETSc takes them (global and sorted: distributed_columns) */
static int same_pattern(const lub_petsc *s, const lub_csr *A, const int *cols)
{
    return s->A && s->dist == (A->colmap != NULL) && s->nglobal == A->nglobal && s->n == A->n &&
           s->nnz == A->nnz && !memcmp(s->ptr, A->row_ptr, (size_t)(A->n + 1) * sizeof *s->ptr) &&
           !memcmp(s->col, cols, (size_t)A->nnz * sizeof *s->col);
}

/* A matrix's rows in global columns (A->colmap of its local ones; serial: its own), each
 * row sorted, into gcol and its values into gval (perm: where each came from); the three
 * arrays grow to *cap entries as needed (not in the time loop once the lists settle). */
static void sorted_rows(const lub_csr *A, int **gcol, int **perm, double **gval, int *cap)
{
    if (A->nnz > *cap) {
        free(*gcol), free(*perm), free(*gval);
        *cap = A->nnz + A->nnz / 8 + 16;
        *gcol = lub_malloc((size_t)*cap * sizeof **gcol);
        *perm = lub_malloc((size_t)*cap * sizeof **perm);
        *gval = lub_malloc((size_t)*cap * sizeof **gval);
    }
    int *gc = *gcol, *pm = *perm;
    for (int i = 0; i < A->n; i++) {
        const int a = A->row_ptr[i], b = A->row_ptr[i + 1];
        for (int k = a; k < b; k++) { /* insertion sort: a few tens of entries */
            const int g = A->colmap ? A->colmap[A->col[k]] : A->col[k];
            int l = k - 1;
            while (l >= a && gc[l] > g) {
                gc[l + 1] = gc[l];
                pm[l + 1] = pm[l];
                l--;
            }
            gc[l + 1] = g;
            pm[l + 1] = k;
        }
    }
    for (int k = 0; k < A->nnz; k++) (*gval)[k] = A->val[pm[k]];
}

static void distributed_rows(lub_petsc *s, const lub_csr *A)
{
    sorted_rows(A, &s->gcol, &s->perm, &s->gval, &s->g_cap);
}

/* BoomerAMG's set-up is remade every step (the particles move, the matrix changes), so its
 * cost, not its iteration count, decides: hypre's defaults (Falgout coarsening, classical
 * interpolation) build dense coarse levels in 3-D.  lubkit's defaults are hypre's own
 * recommendation for 3-D problems, measured (doc/performance.md, "BoomerAMG's set-up"):
 * HMIS coarsening, extended+i interpolation truncated to 4 entries a row, one level of
 * aggressive coarsening; the 3-D roller at h0/3 (172,174 particles) 2.4 times faster per step
 * on one process, 4.2 pressure iterations a step against 3.1.  Entered in PETSc's options
 * database unless set there already: PETSC_OPTIONS in the environment overrides each.
 * prefix: the KSP's options prefix ("" or "other_": lub_petsc_solve_other's). */
static int hypre_defaults(const char *prefix)
{
    static const char *const opt[][2] = {{"pc_hypre_boomeramg_coarsen_type", "HMIS"},
                                         {"pc_hypre_boomeramg_interp_type", "ext+i"},
                                         {"pc_hypre_boomeramg_P_max", "4"},
                                         {"pc_hypre_boomeramg_agg_nl", "1"}};
    for (size_t k = 0; k < sizeof opt / sizeof opt[0]; k++) {
        char name[96];
        snprintf(name, sizeof name, "-%s%s", prefix, opt[k][0]);
        PetscBool set = PETSC_FALSE;
        TRY(PetscOptionsHasName(NULL, NULL, name, &set));
        if (!set) TRY(PetscOptionsSetValue(NULL, name, opt[k][1]));
    }
    return 0;
fail:
    return -1;
}

/* The KSP with its method, preconditioner and norm, made once per matrix object. */
/* *ksp of method type (lub_petsc_ksp) with the options' preconditioner; prefix: its options
 * prefix ("" the main KSP's; "other_" lub_petsc_solve_other's, so that options meant for the
 * symmetric solves, -ksp_type cg, stay theirs) */
static int make_ksp(lub_petsc *s, KSP *ksp, lub_petsc_ksp type, const char *prefix)
{
    static const char *const kt[] = {KSPCG, KSPGMRES, KSPBCGS};
    static const char *const pt[] = {PCHYPRE, PCGAMG, PCJACOBI, PCBJACOBI, PCSOR, PCNONE};
    PC pc;
    TRY(KSPCreate(s->comm, ksp));
    TRY(KSPSetType(*ksp, kt[type]));
    TRY(KSPGetPC(*ksp, &pc));
    TRY(PCSetType(pc, pt[s->o.pc]));
    if (s->o.pc == LUB_PETSC_PC_HYPRE) {
        TRY(hypre_defaults(prefix));
        TRY(PCHYPRESetType(pc, "boomeramg"));
    }
    /* ||b - A x|| / ||b|| as lubkit's PCG: GMRES only knows it with right preconditioning */
    if (type == LUB_PETSC_KSP_GMRES) TRY(KSPSetPCSide(*ksp, PC_RIGHT));
    TRY(KSPSetNormType(*ksp, KSP_NORM_UNPRECONDITIONED));
    if (prefix[0]) TRY(KSPSetOptionsPrefix(*ksp, prefix));
    TRY(KSPSetFromOptions(*ksp));
    return 0;
fail:
    return -1;
}

lub_solve_status lub_petsc_setup(lub_petsc *s, const lub_csr *A, const lub_pcg_options *o,
                                 lub_solve_result *res)
{
    (void)o;
    memset(res, 0, sizeof *res);
    res->column = -1;
    res->status = LUB_SOLVE_FAILED;
    s->ready = 0;
    /* serial: our CSR as it is; distributed: its rows in global columns, sorted */
    const int dist = A->colmap != NULL;
    const int *cols = A->col;
    const double *vals = A->val;
    const int N = dist ? A->nglobal : A->n;
    if (dist) {
        distributed_rows(s, A);
        cols = s->gcol;
        vals = s->gval;
    }
    int same = same_pattern(s, A, cols);
    /* a new matrix is made by every rank or none (MatCreateMPIAIJWithArrays is collective) */
    if (dist && MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_LAND, PETSC_COMM_WORLD))
        goto fail;
    if (same) {
        /* the values only, into the matrix PETSc already holds */
        TRY(MatUpdateMPIAIJWithArrays(s->A, A->n, A->n, N, N, A->row_ptr, cols, vals));
    } else {
        destroy_objects(s);
        if (A->n > s->n_cap) {
            free(s->ptr);
            free(s->r);
            s->ptr = lub_malloc((size_t)(A->n + 1) * sizeof *s->ptr);
            s->r = lub_malloc((size_t)A->n * sizeof *s->r);
            s->n_cap = A->n;
        }
        if (A->nnz > s->nnz_cap) {
            free(s->col);
            s->col = lub_malloc((size_t)A->nnz * sizeof *s->col);
            s->nnz_cap = A->nnz;
        }
        memcpy(s->ptr, A->row_ptr, (size_t)(A->n + 1) * sizeof *s->ptr);
        memcpy(s->col, cols, (size_t)A->nnz * sizeof *s->col);
        s->dist = dist;
        s->nglobal = A->nglobal;
        /* this process's rows (all of them on one), global columns; a distributed matrix
         * on every rank (PETSc was started on MPI_COMM_WORLD: parallel/par.h) */
        s->comm = dist ? PETSC_COMM_WORLD : PETSC_COMM_SELF;
        TRY(MatCreateMPIAIJWithArrays(s->comm, A->n, A->n, N, N, A->row_ptr, cols, vals, &s->A));
        TRY(MatSetOption(s->A, MAT_SYMMETRIC, PETSC_TRUE));
        TRY(MatSetOption(s->A, MAT_SPD, PETSC_TRUE));
        TRY(VecCreateMPIWithArray(s->comm, 1, A->n, N, NULL, &s->b));
        TRY(VecCreateMPIWithArray(s->comm, 1, A->n, N, NULL, &s->x));
        if (dist) TRY(MatCreateVecs(s->A, NULL, &s->rv));
        s->n = A->n;
        s->nnz = A->nnz;
        if (make_ksp(s, &s->ksp, s->o.ksp, "")) goto fail;
    }
    TRY(KSPSetOperators(s->ksp, s->A, s->A));
    TRY(KSPSetUp(s->ksp));
    res->status = LUB_SOLVE_OK;
    res->converged = 1;
    s->As = A;
    s->stamp = A->stamp;
    s->ready = 1;
    return LUB_SOLVE_OK;
fail:
    destroy_objects(s); /* start afresh next time */
    return res->status;
}

static lub_solve_status reason_status(KSPConvergedReason why)
{
    if (why > 0) return LUB_SOLVE_OK;
    switch (why) {
    case KSP_DIVERGED_ITS:
        return LUB_SOLVE_NOT_CONVERGED;
    case KSP_DIVERGED_NANORINF:
        return LUB_SOLVE_NONFINITE;
    case KSP_DIVERGED_BREAKDOWN:
    case KSP_DIVERGED_BREAKDOWN_BICG:
    case KSP_DIVERGED_INDEFINITE_PC:
    case KSP_DIVERGED_INDEFINITE_MAT:
        return LUB_SOLVE_BREAKDOWN;
    default:
        return LUB_SOLVE_FAILED;
    }
}

/* ||b - M x|| / ||b|| of a distributed matrix (x, b placed in s->x, s->b), over all ranks */
static double distributed_residual(lub_petsc *s, Mat M, double bn)
{
    PetscReal rn = 0.0;
    if (MatMult(M, s->x, s->rv) || VecAYPX(s->rv, -1.0, s->b) || VecNorm(s->rv, NORM_2, &rn))
        return NAN;
    return (double)rn / bn;
}

/* Solve with ksp, whose operator is M (PETSc's copy of A, the same rows) */
static lub_solve_status ksp_solve(lub_petsc *s, KSP ksp, Mat M, const lub_csr *A, int nrhs,
                                  const double *const *b, double *const *x,
                                  const lub_pcg_options *o, lub_solve_result *res)
{
    lub_solve_status worst = LUB_SOLVE_OK;
    if (KSPSetTolerances(ksp, o->tolerance, 0.0, PETSC_DEFAULT, o->max_iter) ||
        KSPSetInitialGuessNonzero(ksp, o->warm_start ? PETSC_TRUE : PETSC_FALSE))
        lub_fatal_run("PETSc: KSPSetTolerances failed");
    for (int k = 0; k < nrhs; k++) {
        lub_solve_result *r = &res[k];
        memset(r, 0, sizeof *r);
        r->column = -1;
        double bn = 0.0;
        if (s->dist) { /* over every rank's rows */
            PetscReal v = 0.0;
            if (VecPlaceArray(s->b, b[k]) || VecNorm(s->b, NORM_2, &v) || VecResetArray(s->b))
                v = NAN;
            bn = (double)v;
        } else {
            for (int i = 0; i < A->n; i++) bn += b[k][i] * b[k][i];
            bn = sqrt(bn);
        }
        if (!isfinite(bn)) {
            r->status = LUB_SOLVE_NONFINITE;
        } else if (bn == 0.0) {
            memset(x[k], 0, (size_t)A->n * sizeof *x[k]);
            r->status = LUB_SOLVE_OK;
        } else {
            KSPConvergedReason why = KSP_CONVERGED_ITERATING;
            PetscInt its = 0;
            if (o->warm_start && s->dist) {
                r->residual0 = NAN;
                if (!VecPlaceArray(s->b, b[k]) && !VecPlaceArray(s->x, x[k]))
                    r->residual0 = distributed_residual(s, M, bn);
                VecResetArray(s->b);
                VecResetArray(s->x);
            } else if (o->warm_start) {
                lub_csr_spmv(A, x[k], s->r);
                double r0 = 0.0;
                for (int i = 0; i < A->n; i++) r0 += (b[k][i] - s->r[i]) * (b[k][i] - s->r[i]);
                r->residual0 = sqrt(r0) / bn;
            } else {
                r->residual0 = 1.0;
            }
            /* the caller's arrays in PETSc's vectors, no copy */
            if (VecPlaceArray(s->b, b[k]) || VecPlaceArray(s->x, x[k]) ||
                KSPSolve(ksp, s->b, s->x) || KSPGetConvergedReason(ksp, &why) ||
                KSPGetIterationNumber(ksp, &its))
                why = KSP_DIVERGED_PC_FAILED;
            r->iterations = (int)its;
            r->status = reason_status(why);
            /* the true residual, as the other solvers report it */
            if (s->dist) {
                r->residual = distributed_residual(s, M, bn);
            } else {
                lub_csr_spmv(A, x[k], s->r);
                double rn = 0.0;
                for (int i = 0; i < A->n; i++) rn += (b[k][i] - s->r[i]) * (b[k][i] - s->r[i]);
                r->residual = sqrt(rn) / bn;
            }
            if (VecResetArray(s->b) || VecResetArray(s->x)) r->status = LUB_SOLVE_FAILED;
            if (r->status == LUB_SOLVE_OK && !isfinite(r->residual))
                r->status = LUB_SOLVE_NONFINITE;
        }
        r->converged = r->status == LUB_SOLVE_OK;
        if (r->status > worst) worst = r->status;
    }
    return worst;
}

lub_solve_status lub_petsc_solve(lub_petsc *s, const lub_csr *A, int nrhs, const double *const *b,
                                 double *const *x, const lub_pcg_options *o, lub_solve_result *res)
{
    if (!s->ready || s->As != A || s->stamp != A->stamp)
        lub_bug("lub_petsc_solve without a set-up of this matrix");
    return ksp_solve(s, s->ksp, s->A, A, nrhs, b, x, o, res);
}

/* B into PETSc (a matrix of its own, remade when its pattern changes) and its BiCGStab with
 * its own preconditioner built from s->A (the pc of the options: set up from A, not B). */
static int other_setup(lub_petsc *s, const lub_csr *B)
{
    sorted_rows(B, &s->bgcol, &s->bperm, &s->bgval, &s->bg_cap);
    const int N = s->dist ? B->nglobal : B->n;
    int same = s->B && s->bn == B->n && s->bnnz == B->nnz &&
               !memcmp(s->bptr, B->row_ptr, (size_t)(B->n + 1) * sizeof *s->bptr) &&
               !memcmp(s->bcol, s->bgcol, (size_t)B->nnz * sizeof *s->bcol);
    if (s->dist && MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_LAND, PETSC_COMM_WORLD))
        return -1;
    if (same) {
        TRY(MatUpdateMPIAIJWithArrays(s->B, B->n, B->n, N, N, B->row_ptr, s->bgcol, s->bgval));
    } else {
        destroy_other(s);
        if (B->n >= s->bn_cap) {
            free(s->bptr);
            s->bn_cap = B->n + 1;
            s->bptr = lub_malloc((size_t)s->bn_cap * sizeof *s->bptr);
        }
        if (B->nnz > s->bnnz_cap) {
            free(s->bcol);
            s->bnnz_cap = B->nnz;
            s->bcol = lub_malloc((size_t)s->bnnz_cap * sizeof *s->bcol);
        }
        memcpy(s->bptr, B->row_ptr, (size_t)(B->n + 1) * sizeof *s->bptr);
        memcpy(s->bcol, s->bgcol, (size_t)B->nnz * sizeof *s->bcol);
        TRY(MatCreateMPIAIJWithArrays(s->comm, B->n, B->n, N, N, B->row_ptr, s->bgcol, s->bgval,
                                      &s->B));
        s->bn = B->n;
        s->bnnz = B->nnz;
        if (make_ksp(s, &s->kspb, LUB_PETSC_KSP_BCGS, "other_")) return -1;
    }
    TRY(KSPSetOperators(s->kspb, s->B, s->A));
    TRY(KSPSetUp(s->kspb));
    return 0;
fail:
    return -1;
}

lub_solve_status lub_petsc_solve_other(lub_petsc *s, const lub_csr *B, int nrhs,
                                       const double *const *b, double *const *x,
                                       const lub_pcg_options *o, lub_solve_result *res)
{
    if (!s->ready || !s->A) lub_bug("lub_petsc_solve_other without a set-up");
    if (B->n != s->n || (B->colmap != NULL) != s->dist || (s->dist && B->nglobal != s->nglobal))
        lub_bug("lub_petsc_solve_other: B (%d rows) is not on A's rows (%d)", B->n, s->n);
    if (other_setup(s, B)) {
        destroy_other(s);
        for (int k = 0; k < nrhs; k++) {
            memset(&res[k], 0, sizeof res[k]);
            res[k].column = -1;
            res[k].status = LUB_SOLVE_FAILED;
        }
        return LUB_SOLVE_FAILED;
    }
    return ksp_solve(s, s->kspb, s->B, B, nrhs, b, x, o, res);
}

#endif
