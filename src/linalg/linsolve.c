/* lubkit linalg: the solver front (see linsolve.h). */
#include "linalg/linsolve.h"

#include <stdio.h>
#include <string.h>

#include "core/error.h"

const char *const lub_linsolver_choice_names[] = {"cholmod", "pcg", "petsc", NULL};

lub_linsolver_options lub_linsolver_defaults(void)
{
    lub_linsolver_options o;
    memset(&o, 0, sizeof o);
    o.kind = LUB_LINSOLVER_PCG;
    o.pcg = lub_pcg_defaults();
    o.cholmod = lub_cholmod_defaults();
    o.petsc = lub_petsc_defaults();
    o.pattern = LUB_PATTERN_COMPARE;
    return o;
}

void lub_linsolver_init(lub_linsolver *s, const lub_linsolver_options *o)
{
    memset(s, 0, sizeof *s);
    s->o = *o;
    lub_pcg_work_init(&s->pcg);
    if (o->kind == LUB_LINSOLVER_CHOLMOD)
        s->chol = lub_cholmod_new(&o->cholmod);
    else if (o->kind == LUB_LINSOLVER_PETSC)
        s->petsc = lub_petsc_new(&o->petsc);
    else if (o->kind != LUB_LINSOLVER_PCG)
        lub_bug("unknown linear solver %d", (int)o->kind);
}

void lub_linsolver_free(lub_linsolver *s)
{
    lub_pcg_work_free(&s->pcg);
    lub_cholmod_free(s->chol);
    lub_petsc_free(s->petsc);
    memset(s, 0, sizeof *s);
}

void lub_linsolver_describe(const lub_linsolver *s, char *buf, size_t size)
{
    if (s->o.kind == LUB_LINSOLVER_CHOLMOD) {
        snprintf(buf, size, "cholmod (ordering %s, %s)",
                 lub_cholmod_ordering_names[s->o.cholmod.ordering],
                 lub_cholmod_factor_names[s->o.cholmod.factor]);
    } else if (s->o.kind == LUB_LINSOLVER_PETSC) {
        snprintf(buf, size, "petsc (ksp %s, pc %s%s), tolerance %g, maxIter %d%s",
                 lub_petsc_ksp_names[s->o.petsc.ksp], lub_petsc_pc_names[s->o.petsc.pc],
                 s->o.petsc.pc == LUB_PETSC_PC_HYPRE ? " BoomerAMG" : "", s->o.pcg.tolerance,
                 s->o.pcg.max_iter, s->o.pcg.warm_start ? ", warm start" : "");
    } else {
        snprintf(buf, size, "pcg (%s%s), tolerance %g, maxIter %d%s",
                 lub_precond_choice_names[s->o.pcg.precond],
                 s->o.pcg.precond == LUB_PRECOND_AMG
                     ? (s->o.pcg.cycle == 1 ? ", V-cycle" : ", W-cycle")
                     : "",
                 s->o.pcg.tolerance, s->o.pcg.max_iter, s->o.pcg.warm_start ? ", warm start" : "");
    }
}

lub_solve_status lub_linsolver_setup(lub_linsolver *s, const lub_csr *A, lub_solve_result *res)
{
    lub_solve_result local;
    if (!res) res = &local;
    s->ready = 0;
    if (A->colmap && s->o.kind != LUB_LINSOLVER_PETSC)
        lub_bug("a distributed matrix for the serial solver %s (only petsc solves over ranks)",
                lub_linsolver_choice_names[s->o.kind]);
    if (s->o.kind == LUB_LINSOLVER_CHOLMOD) {
        lub_cholmod_factorize(s->chol, A, s->o.pattern, res);
    } else if (s->o.kind == LUB_LINSOLVER_PETSC) {
        lub_petsc_setup(s->petsc, A, &s->o.pcg, res);
    } else {
        memset(res, 0, sizeof *res);
        res->column = -1;
        res->ic_shift = lub_pcg_setup(&s->pcg, A, &s->o.pcg);
        res->status = LUB_SOLVE_OK;
        res->converged = 1;
    }
    s->setup_result = *res;
    s->A = A;
    s->stamp = A->stamp;
    s->ready = 1;
    return res->status;
}

lub_solve_status lub_linsolver_solve(lub_linsolver *s, const lub_csr *A, int nrhs,
                                     const double *const *b, double *const *x,
                                     lub_solve_result *res)
{
    if (nrhs < 1) lub_bug("lub_linsolver_solve with %d right-hand sides", nrhs);
    if (!s->ready || s->A != A || s->stamp != A->stamp) lub_linsolver_setup(s, A, NULL);
    if (s->setup_result.status != LUB_SOLVE_OK) {
        for (int k = 0; k < nrhs; k++) res[k] = s->setup_result;
        return s->setup_result.status;
    }
    if (s->o.kind == LUB_LINSOLVER_CHOLMOD) return lub_cholmod_solve(s->chol, A, nrhs, b, x, res);
    if (s->o.kind == LUB_LINSOLVER_PETSC)
        return lub_petsc_solve(s->petsc, A, nrhs, b, x, &s->o.pcg, res);
    lub_solve_status worst = LUB_SOLVE_OK;
    for (int k0 = 0; k0 < nrhs; k0 += LUB_PCG_MAX_RHS) {
        const int m = nrhs - k0 < LUB_PCG_MAX_RHS ? nrhs - k0 : LUB_PCG_MAX_RHS;
        lub_pcg_solve_multi(&s->pcg, A, m, b + k0, x + k0, &s->o.pcg, res + k0);
    }
    for (int k = 0; k < nrhs; k++)
        if (res[k].status > worst) worst = res[k].status;
    return worst;
}
