/* lubkit MPS: weighted least-squares interpolation between resolution levels (see lsq.h). */
#include "mps/lsq.h"

#include <math.h>
#include <string.h>

#include "core/error.h"
#include "particles/weight.h"

enum { MT = LUB_LSQ_MAX_TERMS, MF = LUB_LSQ_MAX_FIELDS };

lub_lsq_options lub_lsq_defaults(int dim, double l0, double re)
{
    lub_lsq_options o;
    memset(&o, 0, sizeof o);
    o.dim = dim;
    o.order = 1;
    o.l0 = l0;
    o.re = re;
    o.rcond_min = LUB_LSQ_RCOND_MIN;
    return o;
}

int lub_lsq_terms(int dim, int order)
{
    if (order <= 0) return 1;
    if (order == 1) return 1 + dim;
    return 1 + dim + dim * (dim + 1) / 2;
}

const char *lub_lsq_status_name(lub_lsq_status s)
{
    switch (s) {
    case LUB_LSQ_OK:
        return "ok";
    case LUB_LSQ_TOO_FEW:
        return "too few neighbours";
    case LUB_LSQ_SINGULAR:
        return "singular moment matrix";
    case LUB_LSQ_EMPTY:
        return "no neighbour within re";
    }
    return "unknown";
}

/* q(s) of lsq.h with m terms (m = 1 + d or the second-order count). */
static void basis(int dim, int m, const double s[3], double q[MT])
{
    q[0] = 1.0;
    for (int a = 0; a < dim; a++) q[1 + a] = s[a];
    if (m <= 1 + dim) return;
    if (dim == 2) {
        q[3] = 0.5 * s[0] * s[0];
        q[4] = 0.5 * s[1] * s[1];
        q[5] = s[0] * s[1];
    } else {
        q[4] = 0.5 * s[0] * s[0];
        q[5] = 0.5 * s[1] * s[1];
        q[6] = 0.5 * s[2] * s[2];
        q[7] = s[0] * s[1];
        q[8] = s[0] * s[2];
        q[9] = s[1] * s[2];
    }
}

double lub_lsq_factorise(const double M[MT][MT], int m, double rcond_min, lub_lsq_factor *F)
{
    F->m = m;
    const double sc = 1.0 / sqrt(M[0][0]); /* M_00 = sum_j w_j > 0 */
    for (int a = 0; a < m; a++) {
        F->dsc[a] = sc;
        F->perm[a] = a;
    }
    for (int a = 0; a < m; a++)
        for (int b = 0; b < m; b++) F->A[a][b] = M[a][b] * F->dsc[a] * F->dsc[b];
    double first = 0.0, last = 0.0;
    for (int k = 0; k < m; k++) {
        int p = k;
        for (int i = k + 1; i < m; i++)
            if (F->A[i][i] > F->A[p][p]) p = i;
        if (p != k) {
            for (int j = 0; j < m; j++) {
                double t = F->A[k][j];
                F->A[k][j] = F->A[p][j];
                F->A[p][j] = t;
            }
            for (int i = 0; i < m; i++) {
                double t = F->A[i][k];
                F->A[i][k] = F->A[i][p];
                F->A[i][p] = t;
            }
            int t = F->perm[k];
            F->perm[k] = F->perm[p];
            F->perm[p] = t;
        }
        const double piv = F->A[k][k];
        if (k == 0) first = piv;
        if (!(piv > rcond_min * first)) return first > 0.0 && piv > 0.0 ? piv / first : 0.0;
        last = piv;
        double c[MT];
        for (int i = k + 1; i < m; i++) c[i] = F->A[i][k];
        for (int i = k + 1; i < m; i++) {
            const double l = c[i] / piv;
            for (int j = k + 1; j <= i; j++) F->A[i][j] -= l * c[j];
            F->A[i][k] = l;
        }
        /* keep the trailing block symmetric (the pivot search and swaps read both halves) */
        for (int i = k + 1; i < m; i++)
            for (int j = k + 1; j < i; j++) F->A[j][i] = F->A[i][j];
    }
    return last / first;
}

void lub_lsq_solve(const lub_lsq_factor *F, const double b[MT], double a[MT])
{
    const int m = F->m;
    double y[MT];
    for (int i = 0; i < m; i++) y[i] = b[F->perm[i]] * F->dsc[F->perm[i]];
    for (int i = 0; i < m; i++)
        for (int j = 0; j < i; j++) y[i] -= F->A[i][j] * y[j];
    for (int i = 0; i < m; i++) y[i] /= F->A[i][i];
    for (int i = m - 1; i >= 0; i--)
        for (int j = i + 1; j < m; j++) y[i] -= F->A[j][i] * y[j];
    for (int i = 0; i < m; i++) a[F->perm[i]] = y[i] * F->dsc[F->perm[i]];
}

lub_lsq_result lub_lsq_interpolate(const lub_lsq_options *o, const double xt[3],
                                   const double *const x[3], size_t n, const size_t *idx, int nf,
                                   const double *const *f, double *value, double (*grad)[3],
                                   double (*hess)[6])
{
    const int dim = o->dim;
    if ((dim != 2 && dim != 3) || (o->order != 1 && o->order != 2) || !(o->l0 > 0) ||
        !(o->re > 0) || nf < 1 || nf > MF)
        lub_bug("lsq: dim %d, order %d, l0 %g, re %g, %d fields", dim, o->order, o->l0, o->re, nf);
    const double rcond_min = o->rcond_min > 0 ? o->rcond_min : LUB_LSQ_RCOND_MIN;
    const int mmax = lub_lsq_terms(dim, o->order);
    const double il0 = 1.0 / o->l0, re2 = o->re * o->re;

    /* (LSQ-1) at the requested order; lower orders use the leading blocks (nested basis) */
    double M[MT][MT], B[MF][MT], sw = 0.0, swf[MF];
    memset(M, 0, sizeof M);
    memset(B, 0, sizeof B);
    memset(swf, 0, sizeof swf);
    int cnt = 0;
    for (size_t jj = 0; jj < n; jj++) {
        const size_t j = idx ? idx[jj] : jj;
        double r[3] = {0.0, 0.0, 0.0}, r2 = 0.0;
        for (int a = 0; a < dim; a++) {
            double d = x[a][j] - xt[a];
            if (o->period[a] > 0) d -= o->period[a] * nearbyint(d / o->period[a]);
            r[a] = d;
            r2 += d * d;
        }
        if (!(r2 < re2)) continue;
        const double w = lub_mps_weight(sqrt(r2), o->re);
        double s[3] = {r[0] * il0, r[1] * il0, r[2] * il0}, q[MT];
        basis(dim, mmax, s, q);
        for (int a = 0; a < mmax; a++) {
            const double wq = w * q[a];
            for (int b = a; b < mmax; b++) M[a][b] += wq * q[b];
            for (int k = 0; k < nf; k++) B[k][a] += wq * f[k][j];
        }
        sw += w;
        for (int k = 0; k < nf; k++) swf[k] += w * f[k][j];
        cnt++;
    }
    for (int a = 0; a < mmax; a++)
        for (int b = 0; b < a; b++) M[a][b] = M[b][a];

    lub_lsq_result res = {LUB_LSQ_OK, -1, cnt, 0.0};
    if (cnt == 0) {
        res.status = LUB_LSQ_EMPTY;
        return res;
    }

    for (int order = o->order; order >= 1; order--) {
        const int m = lub_lsq_terms(dim, order);
        lub_lsq_status why = LUB_LSQ_OK;
        lub_lsq_factor F;
        double rc = 0.0;
        if (cnt < m)
            why = LUB_LSQ_TOO_FEW;
        else if ((rc = lub_lsq_factorise(M, m, rcond_min, &F)) < rcond_min)
            why = LUB_LSQ_SINGULAR;
        if (why != LUB_LSQ_OK) {
            if (res.status == LUB_LSQ_OK) res.status = why; /* the reason of the first failure */
            continue;
        }
        res.order = order;
        res.rcond = rc;
        for (int k = 0; k < nf; k++) {
            double a[MT], d[MT], r[MT];
            lub_lsq_solve(&F, B[k], a);
            /* one step of iterative refinement */
            for (int i = 0; i < m; i++) {
                double s = B[k][i];
                for (int j = 0; j < m; j++) s -= M[i][j] * a[j];
                r[i] = s;
            }
            lub_lsq_solve(&F, r, d);
            for (int i = 0; i < m; i++) a[i] += d[i];

            value[k] = a[0];
            if (grad)
                for (int c = 0; c < 3; c++) grad[k][c] = c < dim ? a[1 + c] * il0 : 0.0;
            if (hess) {
                const double s2 = il0 * il0;
                for (int c = 0; c < 6; c++) hess[k][c] = 0.0;
                if (order == 2 && dim == 2) {
                    hess[k][0] = a[3] * s2;
                    hess[k][1] = a[4] * s2;
                    hess[k][3] = a[5] * s2;
                } else if (order == 2) {
                    for (int c = 0; c < 6; c++) hess[k][c] = a[4 + c] * s2;
                }
            }
        }
        return res;
    }

    /* order 0: the kernel-weighted mean (Shepard); no derivative information */
    res.order = 0;
    res.rcond = 1.0;
    for (int k = 0; k < nf; k++) {
        value[k] = swf[k] / sw;
        if (grad) grad[k][0] = grad[k][1] = grad[k][2] = 0.0;
        if (hess)
            for (int c = 0; c < 6; c++) hess[k][c] = 0.0;
    }
    return res;
}
