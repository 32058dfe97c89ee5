/* lubkit MPS: discrete operators (see operators.h). */
#include "mps/operators.h"

#include <math.h>

#include "core/error.h"
#include "particles/weight.h"

/* Kind array and bit masks for i and j; kind NULL when everyone takes part. */
typedef struct {
    const uint8_t *ikind, *jkind;
    unsigned i, j;
} mask_view;

static mask_view view(const lub_mps_mask *m)
{
    mask_view v = {NULL, NULL, LUB_MPS_ALL, LUB_MPS_ALL};
    if (m && m->kind) {
        v.i = m->i, v.j = m->j;
        /* a full mask needs no per-particle test */
        v.ikind = (m->i & LUB_MPS_ALL) == LUB_MPS_ALL ? NULL : m->kind;
        v.jkind = (m->j & LUB_MPS_ALL) == LUB_MPS_ALL ? NULL : m->kind;
    }
    return v;
}

/* a kind above 7 is not in any bit mask (and must not shift by more than the width) */
static inline int takes_part(const uint8_t *kind, unsigned bits, size_t i)
{
    return !kind || (kind[i] < 8 && ((bits >> kind[i]) & 1u));
}

void lub_mps_pnd(const lub_neighbours *nb, const lub_mps_mask *mask, double *pnd)
{
    const mask_view mv = view(mask);
    const size_t n = nb->n;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        if (!takes_part(mv.ikind, mv.i, i)) continue;
        double s = 0.0;
        /* (T-4) */
        for (size_t k = nb->start[i]; k < nb->end[i]; k++)
            if (takes_part(mv.jkind, mv.j, nb->j[k])) s += nb->w[k];
        pnd[i] = s;
    }
}

void lub_mps_laplacian(const lub_neighbours *nb, const lub_mps_mask *mask, double n0,
                       double lambda0, const double *phi, double *lap)
{
    const mask_view mv = view(mask);
    const size_t n = nb->n;
    const double c = lub_mps_laplacian_coefficient(nb->dim, lambda0, n0, 1.0); /* (T-3) */
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        if (!takes_part(mv.ikind, mv.i, i)) continue;
        const double phii = phi[i];
        double s = 0.0;
        for (size_t k = nb->start[i]; k < nb->end[i]; k++) {
            const size_t j = nb->j[k];
            if (takes_part(mv.jkind, mv.j, j)) s += (phi[j] - phii) * nb->w[k];
        }
        lap[i] = c * s;
    }
}

/* p_hat_i of (T-14): the minimum over i and its (masked) neighbours within re. */
static inline double min_pressure(const lub_neighbours *nb, const mask_view *mv, const double *p,
                                  size_t i)
{
    double ph = p[i];
    for (size_t k = nb->start[i]; k < nb->end[i]; k++) {
        const size_t j = nb->j[k];
        if (nb->w[k] > 0.0 && takes_part(mv->jkind, mv->j, j) && p[j] < ph) ph = p[j];
    }
    return ph;
}

/* n0 b_i = sum_j w_ij (p_j - ph) r_ij / |r_ij|^2 and, if moments, the moment matrix
 * n0 M_i = sum_j w_ij e_ij e_ij^T (upper triangle, m[a][c] for a <= c); pairs at distance 0
 * have no direction and are skipped. */
static inline void gradient_sums(const lub_neighbours *nb, const mask_view *mv, const double *p,
                                 size_t i, double ph, double b[3], double m[3][3], int moments,
                                 const int dim)
{
    b[0] = b[1] = b[2] = 0.0;
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++) m[a][c] = 0.0;
    for (size_t k = nb->start[i]; k < nb->end[i]; k++) {
        const size_t j = nb->j[k];
        const double w = nb->w[k];
        if (w == 0.0 || !takes_part(mv->jkind, mv->j, j)) continue;
        double e[3] = {nb->dx[0][k], nb->dx[1][k], dim == 3 ? nb->dx[2][k] : 0.0};
        const double r2 = e[0] * e[0] + e[1] * e[1] + (dim == 3 ? e[2] * e[2] : 0.0);
        if (!(r2 > 0.0)) continue;
        const double q = w / r2;
        const double f = (p[j] - ph) * q;
        for (int a = 0; a < dim; a++) b[a] += f * e[a];
        if (moments)
            for (int a = 0; a < dim; a++)
                for (int c = a; c < dim; c++) m[a][c] += q * e[a] * e[c];
    }
}

void lub_mps_gradient(const lub_neighbours *nb, const lub_mps_mask *mask, double n0, int shift,
                      const double *p, double *const grad[3])
{
    const mask_view mv = view(mask);
    const size_t n = nb->n;
    const int dim = nb->dim;
    const double c = dim / n0; /* (T-13) */
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        if (!takes_part(mv.ikind, mv.i, i)) continue;
        const double ph = shift ? min_pressure(nb, &mv, p, i) : p[i]; /* (T-14) */
        double b[3], m[3][3];
        /* literal dimensions: the inlined loops over components unroll */
        if (dim == 2)
            gradient_sums(nb, &mv, p, i, ph, b, m, 0, 2);
        else
            gradient_sums(nb, &mv, p, i, ph, b, m, 0, 3);
        for (int a = 0; a < dim; a++) grad[a][i] = c * b[a];
    }
}

size_t lub_mps_gradient_lsmps(const lub_neighbours *nb, const lub_mps_mask *mask, double n0,
                              int shift, double det_min, const double *p, double *const grad[3])
{
    const mask_view mv = view(mask);
    const size_t n = nb->n;
    const int dim = nb->dim;
    if (!(det_min > 0)) det_min = LUB_MPS_LSMPS_DET_MIN;
    size_t fallbacks = 0;
#pragma omp parallel for schedule(static) reduction(+ : fallbacks)
    for (size_t i = 0; i < n; i++) {
        if (!takes_part(mv.ikind, mv.i, i)) continue;
        const double ph = shift ? min_pressure(nb, &mv, p, i) : p[i]; /* (T-14) */
        double b[3], m[3][3], g[3] = {0, 0, 0};
        /* (T-15): the 1/n0 factors of M_i and of the right-hand side cancel */
        if (dim == 2)
            gradient_sums(nb, &mv, p, i, ph, b, m, 1, 2);
        else
            gradient_sums(nb, &mv, p, i, ph, b, m, 1, 3);
        double det, tr;
        if (dim == 2) {
            det = m[0][0] * m[1][1] - m[0][1] * m[0][1];
            tr = m[0][0] + m[1][1];
        } else {
            det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[1][2]) -
                  m[0][1] * (m[0][1] * m[2][2] - m[1][2] * m[0][2]) +
                  m[0][2] * (m[0][1] * m[1][2] - m[1][1] * m[0][2]);
            tr = m[0][0] + m[1][1] + m[2][2];
        }
        const double mean = tr / dim;
        const double iso = tr > 0.0 ? det / (dim == 2 ? mean * mean : mean * mean * mean) : 0.0;
        if (!(iso >= det_min)) {
            /* degenerate neighbourhood: standard gradient (T-13) */
            fallbacks++;
            for (int a = 0; a < dim; a++) g[a] = dim / n0 * b[a];
        } else if (dim == 2) {
            g[0] = (m[1][1] * b[0] - m[0][1] * b[1]) / det;
            g[1] = (m[0][0] * b[1] - m[0][1] * b[0]) / det;
        } else {
            /* adjugate of the symmetric 3x3 matrix */
            const double a00 = m[1][1] * m[2][2] - m[1][2] * m[1][2];
            const double a01 = m[0][2] * m[1][2] - m[0][1] * m[2][2];
            const double a02 = m[0][1] * m[1][2] - m[0][2] * m[1][1];
            const double a11 = m[0][0] * m[2][2] - m[0][2] * m[0][2];
            const double a12 = m[0][1] * m[0][2] - m[0][0] * m[1][2];
            const double a22 = m[0][0] * m[1][1] - m[0][1] * m[0][1];
            g[0] = (a00 * b[0] + a01 * b[1] + a02 * b[2]) / det;
            g[1] = (a01 * b[0] + a11 * b[1] + a12 * b[2]) / det;
            g[2] = (a02 * b[0] + a12 * b[1] + a22 * b[2]) / det;
        }
        for (int a = 0; a < dim; a++) grad[a][i] = g[a];
    }
    return fallbacks;
}
