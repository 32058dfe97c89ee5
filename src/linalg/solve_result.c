/* lubkit linalg: names and descriptions of solve outcomes. */
#include "linalg/solve_result.h"

#include <stdio.h>

const char *lub_solve_status_name(lub_solve_status s)
{
    switch (s) {
    case LUB_SOLVE_OK:
        return "converged";
    case LUB_SOLVE_NOT_CONVERGED:
        return "not converged";
    case LUB_SOLVE_BREAKDOWN:
        return "breakdown (matrix not positive definite)";
    case LUB_SOLVE_NOT_POSDEF:
        return "matrix not positive definite";
    case LUB_SOLVE_NONFINITE:
        return "non-finite value";
    case LUB_SOLVE_FAILED:
        return "failed";
    }
    return "unknown status";
}

void lub_solve_result_describe(const lub_solve_result *r, char *buf, size_t size)
{
    int m;
    switch (r->status) {
    case LUB_SOLVE_NOT_POSDEF:
        m = snprintf(buf, size, "%s: non-positive pivot at column %d",
                     lub_solve_status_name(r->status), r->column);
        break;
    case LUB_SOLVE_OK:
    case LUB_SOLVE_NOT_CONVERGED:
    case LUB_SOLVE_BREAKDOWN:
    case LUB_SOLVE_NONFINITE:
        m = snprintf(buf, size, "%s after %d iterations: relative residual %.3g (initial %.3g)",
                     lub_solve_status_name(r->status), r->iterations, r->residual, r->residual0);
        break;
    default:
        m = snprintf(buf, size, "%s", lub_solve_status_name(r->status));
        break;
    }
    if (r->ic_shift > 0 && m >= 0 && (size_t)m < size)
        snprintf(buf + m, size - (size_t)m, " [IC(0) diagonal shift %.3g]", r->ic_shift);
}
