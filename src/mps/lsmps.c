/* lubkit MPS: the LSMPS Laplacian (see lsmps.h). */
#include "mps/lsmps.h"

#include <math.h>
#include <string.h>

#include "mps/lsq.h"

enum { MT = LUB_LSQ_MAX_TERMS };

static inline int takes_part(const lub_mps_mask *m, unsigned bits, size_t i)
{
    return !m || !m->kind || (m->kind[i] < 8 && ((bits >> m->kind[i]) & 1u));
}

/* p(s) of lsmps.h, the squares after the linear terms (entries dim .. 2 dim - 1); returns the
 * number of terms (5 in 2-D, 9 in 3-D) */
static inline int basis(int dim, const double s[3], double p[MT])
{
    if (dim == 2) {
        p[0] = s[0], p[1] = s[1];
        p[2] = s[0] * s[0], p[3] = s[1] * s[1], p[4] = s[0] * s[1];
        return 5;
    }
    p[0] = s[0], p[1] = s[1], p[2] = s[2];
    p[3] = s[0] * s[0], p[4] = s[1] * s[1], p[5] = s[2] * s[2];
    p[6] = s[0] * s[1], p[7] = s[0] * s[2], p[8] = s[1] * s[2];
    return 9;
}

size_t lub_mps_lsmps_laplacian(const lub_neighbours *nb, const lub_mps_mask *mask, int dim,
                               double l0, double rcond_min, double *coef, uint8_t *flag)
{
    const size_t n = nb->n;
    const double il0 = 1.0 / l0, scale = 2.0 / (l0 * l0);
    const unsigned mi = mask ? mask->i : LUB_MPS_ALL, mj = mask ? mask->j : LUB_MPS_ALL;
    if (rcond_min <= 0) rcond_min = LUB_LSMPS_RCOND_MIN;
    size_t nflag = 0;
#pragma omp parallel for schedule(static) reduction(+ : nflag)
    for (size_t i = 0; i < n; i++) {
        if (!takes_part(mask, mi, i)) continue;
        double M[MT][MT];
        int m = dim == 2 ? 5 : 9;
        for (int a = 0; a < m; a++)
            for (int b = 0; b < m; b++) M[a][b] = 0.0;
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            const double w = nb->w[q];
            if (w <= 0 || !takes_part(mask, mj, nb->j[q])) continue;
            double s[3] = {nb->dx[0][q] * il0, nb->dx[1][q] * il0,
                           dim == 3 ? nb->dx[2][q] * il0 : 0.0},
                   p[MT];
            basis(dim, s, p);
            for (int a = 0; a < m; a++)
                for (int b = 0; b <= a; b++) M[a][b] += w * p[a] * p[b];
        }
        for (int a = 0; a < m; a++)
            for (int b = a + 1; b < m; b++) M[a][b] = M[b][a];
        lub_lsq_factor F;
        if (!(M[0][0] > 0) || !(lub_lsq_factorise(M, m, rcond_min, &F) >= rcond_min)) {
            flag[i] = 1;
            nflag++;
            continue;
        }
        /* c = M^-1 e, e = 1 on the squares */
        double e[MT] = {0}, c[MT];
        for (int a = dim; a < 2 * dim; a++) e[a] = 1.0;
        lub_lsq_solve(&F, e, c);
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            const double w = nb->w[q];
            if (w <= 0 || !takes_part(mask, mj, nb->j[q])) {
                coef[q] = 0.0;
                continue;
            }
            double s[3] = {nb->dx[0][q] * il0, nb->dx[1][q] * il0,
                           dim == 3 ? nb->dx[2][q] * il0 : 0.0},
                   p[MT], cp = 0.0;
            basis(dim, s, p);
            for (int a = 0; a < m; a++) cp += c[a] * p[a];
            coef[q] = scale * w * cp;
        }
        flag[i] = 0;
    }
    return nflag;
}

void lub_mps_lsmps_apply(const lub_neighbours *nb, const lub_mps_mask *mask, const double *coef,
                         const uint8_t *flag, const double *f, double *lap)
{
    const size_t n = nb->n;
    const unsigned mi = mask ? mask->i : LUB_MPS_ALL;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        if (!takes_part(mask, mi, i) || flag[i]) continue;
        double s = 0.0;
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) s += coef[q] * (f[nb->j[q]] - f[i]);
        lap[i] = s;
    }
}
