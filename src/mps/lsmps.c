/* lubkit MPS: the LSMPS Laplacian (see lsmps.h). */
#include "mps/lsmps.h"

#include <math.h>
#include <string.h>

#include "core/error.h"
#include "mps/lsq.h"
#include "particles/weight.h"

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

/* p(r_ij / l0) of pair q */
static inline void pair_basis(const lub_neighbours *nb, size_t q, int dim, double il0, double p[MT])
{
    const double s[3] = {nb->dx[0][q] * il0, nb->dx[1][q] * il0,
                         dim == 3 ? nb->dx[2][q] * il0 : 0.0};
    basis(dim, s, p);
}

/* r_i of a boundary row (lsmps.h) at s_b = delta n: p(s_b) (Dirichlet) or its derivative
 * along n (Neumann) */
static void bc_row(int dim, int kind, const double n[3], double delta, double r[MT])
{
    const double s[3] = {delta * n[0], delta * n[1], dim == 3 ? delta * n[2] : 0.0};
    if (kind == LUB_LSMPS_BC_DIRICHLET) {
        basis(dim, s, r);
        return;
    }
    if (dim == 2) {
        r[0] = n[0], r[1] = n[1];
        r[2] = 2 * s[0] * n[0], r[3] = 2 * s[1] * n[1], r[4] = s[0] * n[1] + s[1] * n[0];
        return;
    }
    r[0] = n[0], r[1] = n[1], r[2] = n[2];
    r[3] = 2 * s[0] * n[0], r[4] = 2 * s[1] * n[1], r[5] = 2 * s[2] * n[2];
    r[6] = s[0] * n[1] + s[1] * n[0], r[7] = s[0] * n[2] + s[2] * n[0];
    r[8] = s[1] * n[2] + s[2] * n[1];
}

/* c = M_i^-1 e of (LSMPS-L) for particle i from its neighbours of the kinds mj, with the
 * boundary row of bc where bc->d[i] > 0 (M'_i = M_i + mu r r^T; *mu_r = mu c . r, the
 * Dirichlet value's coefficient over 2/l0^2, else 0); returns 0 (c untouched) where M_i is
 * ill-conditioned (pivot ratio below rcond_min) */
static int fit(const lub_neighbours *nb, const lub_mps_mask *mask, unsigned mj, size_t i, int dim,
               double il0, double rcond_min, const lub_lsmps_bc *bc, double c[MT], double *mu_r)
{
    double M[MT][MT], wsum = 0;
    const int m = dim == 2 ? 5 : 9;
    for (int a = 0; a < m; a++)
        for (int b = 0; b < m; b++) M[a][b] = 0.0;
    for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
        const double w = nb->w[q];
        if (w <= 0 || !takes_part(mask, mj, nb->j[q])) continue;
        double p[MT];
        pair_basis(nb, q, dim, il0, p);
        wsum += w;
        for (int a = 0; a < m; a++)
            for (int b = 0; b <= a; b++) M[a][b] += w * p[a] * p[b];
    }
    double r[MT] = {0}, mu = 0;
    *mu_r = 0.0;
    if (bc && bc->d[i] > 0 && wsum > 0) {
        const double n[3] = {bc->n[0][i], bc->n[1][i], dim == 3 ? bc->n[2][i] : 0.0};
        bc_row(dim, bc->kind, n, bc->d[i] * il0, r);
        /* the kernel's weight of the boundary point, as a neighbour's: the condition
         * binds where the surface cuts the neighbourhood, fades as it leaves it */
        const double rr = bc->d[i] * il0 / bc->re_l0;
        mu = rr < 1 ? bc->weight * wsum * (1 - rr) * (1 - rr) : 0.0;
        for (int a = 0; a < m; a++)
            for (int b = 0; b <= a; b++) M[a][b] += mu * r[a] * r[b];
    }
    for (int a = 0; a < m; a++)
        for (int b = a + 1; b < m; b++) M[a][b] = M[b][a];
    lub_lsq_factor F;
    if (!(M[0][0] > 0) || !(lub_lsq_factorise(M, m, rcond_min, &F) >= rcond_min)) return 0;
    double e[MT] = {0};
    for (int a = dim; a < 2 * dim; a++) e[a] = 1.0;
    lub_lsq_solve(&F, e, c);
    if (mu > 0 && bc->kind == LUB_LSMPS_BC_DIRICHLET) {
        double cr = 0;
        for (int a = 0; a < m; a++) cr += c[a] * r[a];
        *mu_r = mu * cr;
    }
    return 1;
}

/* Row i's pair coefficients L_ij = scale w_ij c . p_ij of (LSMPS-L) into coef (0 for a
 * neighbour outside mj or beyond re) */
static void row(const lub_neighbours *nb, const lub_mps_mask *mask, unsigned mj, size_t i, int dim,
                double il0, double scale, const double c[MT], double *coef)
{
    const int m = dim == 2 ? 5 : 9;
    for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
        const double w = nb->w[q];
        if (w <= 0 || !takes_part(mask, mj, nb->j[q])) {
            coef[q] = 0.0;
            continue;
        }
        double p[MT], cp = 0.0;
        pair_basis(nb, q, dim, il0, p);
        for (int a = 0; a < m; a++) cp += c[a] * p[a];
        coef[q] = scale * w * cp;
    }
}

size_t lub_mps_lsmps_laplacian(const lub_neighbours *nb, const lub_mps_mask *mask, int dim,
                               double l0, double rcond_min, const lub_lsmps_bc *bc, double *coef,
                               uint8_t *flag)
{
    const size_t n = nb->n;
    const double il0 = 1.0 / l0, scale = 2.0 / (l0 * l0);
    const unsigned mi = mask ? mask->i : LUB_MPS_ALL, mj = mask ? mask->j : LUB_MPS_ALL;
    if (rcond_min <= 0) rcond_min = LUB_LSMPS_RCOND_MIN;
    size_t nflag = 0;
#pragma omp parallel for schedule(static) reduction(+ : nflag)
    for (size_t i = 0; i < n; i++) {
        if (!takes_part(mask, mi, i)) continue;
        double c[MT], mu_r;
        if (!fit(nb, mask, mj, i, dim, il0, rcond_min, bc, c, &mu_r)) {
            flag[i] = 1;
            if (bc && bc->diag) bc->diag[i] = 0.0;
            nflag++;
            continue;
        }
        row(nb, mask, mj, i, dim, il0, scale, c, coef);
        if (bc && bc->diag) bc->diag[i] = scale * mu_r;
        flag[i] = 0;
    }
    return nflag;
}

double lub_mps_lsmps_reference(int dim, double l0, double re)
{
    if ((dim != 2 && dim != 3) || !(l0 > 0) || !(re > 0))
        lub_bug("LSMPS reference: dim %d, l0 %g, re %g", dim, l0, re);
    /* M of (LSMPS-L) over every lattice node within re of the centre node, in l0 units */
    const int r = (int)ceil(re / l0) + 1, rz = dim == 3 ? r : 0, m = dim == 2 ? 5 : 9;
    double M[MT][MT] = {{0}};
    for (int k = -rz; k <= rz; k++)
        for (int j = -r; j <= r; j++)
            for (int i = -r; i <= r; i++) {
                if (i == 0 && j == 0 && k == 0) continue;
                const double s[3] = {i, j, k};
                const double w = lub_mps_weight(l0 * sqrt((double)(i * i + j * j + k * k)), re);
                if (w <= 0) continue;
                double p[MT];
                basis(dim, s, p);
                for (int a = 0; a < m; a++)
                    for (int b = 0; b < m; b++) M[a][b] += w * p[a] * p[b];
            }
    lub_lsq_factor F;
    if (!(lub_lsq_factorise(M, m, LUB_LSMPS_RCOND_MIN, &F) >= LUB_LSMPS_RCOND_MIN))
        lub_bug("LSMPS reference: re %g l0 holds too few lattice neighbours", re / l0);
    double e[MT] = {0}, c[MT], g = 0;
    for (int a = dim; a < 2 * dim; a++) e[a] = 1.0;
    lub_lsq_solve(&F, e, c);
    for (int a = dim; a < 2 * dim; a++) g += c[a];
    return g;
}

size_t lub_mps_lsmps_stabilized(const lub_neighbours *nb, const lub_mps_mask *mask, int dim,
                                double l0, const lub_lsmps_stabilization *o, double *coef,
                                uint8_t *flag, double *theta)
{
    const size_t n = nb->n;
    const double il0 = 1.0 / l0, scale = 2.0 / (l0 * l0);
    /* S_ij = sc w_ij (T-3) */
    const double sc = 2.0 * dim / (o->lambda0 * o->n0), g0 = o->g0;
    const unsigned mi = mask ? mask->i : LUB_MPS_ALL, mj = mask ? mask->j : LUB_MPS_ALL;
    const double rcond_min = o->rcond_min > 0 ? o->rcond_min : LUB_LSMPS_RCOND_MIN;
    if (!(g0 > 0) || !(o->n0 > 0) || !(o->lambda0 > 0) || !(o->strength >= 0) || !(o->onset >= 1))
        lub_bug("stabilized LSMPS: g0 %g, n0 %g, lambda0 %g, strength %g, onset %g", g0, o->n0,
                o->lambda0, o->strength, o->onset);
    size_t nflag = 0;
#pragma omp parallel for schedule(static) reduction(+ : nflag)
    for (size_t i = 0; i < n; i++) {
        if (!takes_part(mask, mi, i)) continue;
        double c[MT], mu_r;
        if (!fit(nb, mask, mj, i, dim, il0, rcond_min, o->bc, c, &mu_r)) {
            flag[i] = 1;
            if (theta) theta[i] = 0.0;
            if (o->bc && o->bc->diag) o->bc->diag[i] = 0.0;
            nflag++;
            continue;
        }
        double g = 0;
        for (int a = dim; a < 2 * dim; a++) g += c[a];
        /* the bias penalty: theta = 1 / (1 + lambda g), lambda g0 = strength (rho - onset) */
        const double rho = g / g0, over = rho - o->onset;
        double th = over > 0 ? 1.0 / (1.0 + o->strength * over * rho) : 1.0;
        /* LSMPS's coefficients A_ij (in coef), and the positivity bound on theta:
         * theta A + (1 - theta) S >= 0 for A < 0: theta <= S / (S - A) */
        row(nb, mask, mj, i, dim, il0, scale, c, coef);
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            const double S = sc * nb->w[q];
            if (coef[q] < 0) th = fmin(th, S / (S - coef[q]));
        }
        /* (the max: the coefficient that bounds theta is zero but for round-off) */
        for (size_t q = nb->start[i]; q < nb->end[i]; q++)
            if (nb->w[q] > 0 && takes_part(mask, mj, nb->j[q]))
                coef[q] = fmax(0.0, th * coef[q] + (1.0 - th) * sc * nb->w[q]);
        if (theta) theta[i] = th;
        if (o->bc && o->bc->diag) o->bc->diag[i] = th * scale * mu_r;
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
