/* lubkit Reynolds equation over the bearing's area (see reynolds2d.h, doc/methods.md §5.6). */
#include "reynolds/reynolds2d.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

void lub_reynolds2d_problem_init(lub_reynolds2d_problem *pb)
{
    memset(pb, 0, sizeof *pb);
    pb->bc = LUB_REYNOLDS_BC_REYNOLDS;
}

/* The discrete system on the unknown nodes i = 1..m-1, j = 1..nz-1 (p = 0 on the sides, at
 * the inlet, at x node m or the cut exit), unknown u = (i - 1)(nz - 1) + j - 1. */
typedef struct {
    const lub_reynolds2d_problem *pb;
    int m;              /* x node of the right boundary */
    double cut;         /* > 0: node m-1's right neighbour is the exit at this distance */
    int nzi, nu;        /* unknowns per x column, unknowns */
    lub_csr A;          /* M with the active set applied */
    double *a0;         /* M's values without it */
    double *f, *b, *p;  /* per unknown */
    unsigned char *act; /* the active set (p = 0 held) */
    lub_linsolver ls;
    int linear_iters;
} sys2d;

static double face_gap(const lub_reynolds2d_problem *pb, int i)
{
    return pb->h_face ? pb->h_face[i] : 0.5 * (pb->h[i] + pb->h[i + 1]);
}

/* The gap at node (i, j), at the x face (x_i + dx/2, z_j) and at the z face (x_i, z_j + dz/2):
 * from h_area when the gap varies across, else h(x) (reynolds2d.h). */
static double gap_node(const lub_reynolds2d_problem *pb, int i, int j)
{
    return pb->h_area ? pb->h_area[(size_t)i * (pb->nz + 1) + j] : pb->h[i];
}
static double gap_face_x(const lub_reynolds2d_problem *pb, int i, int j)
{
    if (!pb->h_area) return face_gap(pb, i);
    if (pb->h_face_x) return pb->h_face_x[(size_t)i * (pb->nz + 1) + j];
    return 0.5 * (gap_node(pb, i, j) + gap_node(pb, i + 1, j));
}
static double gap_face_z(const lub_reynolds2d_problem *pb, int i, int j)
{
    if (!pb->h_area) return pb->h[i];
    if (pb->h_face_z) return pb->h_face_z[(size_t)i * pb->nz + j];
    return 0.5 * (gap_node(pb, i, j) + gap_node(pb, i, j + 1));
}
static double squeeze_at(const lub_reynolds2d_problem *pb, int i, int j)
{
    if (pb->h_area) return pb->dhdt_area ? pb->dhdt_area[(size_t)i * (pb->nz + 1) + j] : pb->dhdt;
    return pb->dhdt_nodes ? pb->dhdt_nodes[i] : pb->dhdt;
}

/* The gap at x_i + s dx (0 <= s <= 1) on row j: the quadratic through node, face and node
 * when the face gaps are given, else linear (as reynolds.c). */
static double gap_in_cell(const lub_reynolds2d_problem *pb, int i, int j, double s)
{
    double h0 = gap_node(pb, i, j), h1 = gap_node(pb, i + 1, j);
    if (!(pb->h_area ? pb->h_face_x : pb->h_face)) return h0 + s * (h1 - h0);
    double hm = gap_face_x(pb, i, j);
    return h0 * 2.0 * (s - 0.5) * (s - 1.0) - hm * 4.0 * s * (s - 1.0) + h1 * 2.0 * s * (s - 0.5);
}

/* Assemble M and f: the balance of the control volume vx dz around each node (vx = dx, or
 * (dx + cut)/2 at the cut exit) of the fluxes h^3/(12 mu) grad p through its four faces,
 * each with its face's gap, against the wedge term Um (h_r - h_l) dz and the squeeze and
 * source terms times the volume.  Columns in increasing order: west, south, the node,
 * north, east.  The diagonal sums the z coefficients first (as + an), which is 2 an exactly
 * when the gap is uniform in z. */
static void assemble(sys2d *S)
{
    const lub_reynolds2d_problem *pb = S->pb;
    const int nzi = S->nzi, m = S->m;
    const double dx = (pb->xb - pb->xa) / pb->nx, dz = pb->width / pb->nz;
    const double um = 0.5 * (pb->u1 + pb->u2), c12 = 1.0 / (12.0 * pb->mu);
    lub_csr *A = &S->A;
    lub_csr_begin(A, S->nu);
    for (int i = 1; i < m; i++)
        for (int j = 1; j <= nzi; j++) {
            int u = (i - 1) * nzi + j - 1;
            lub_csr_set_row_length(A, u, 1 + (i > 1) + (i < m - 1) + (j > 1) + (j < nzi));
        }
    lub_csr_alloc(A);
    if (!S->a0) S->a0 = lub_malloc((size_t)A->nnz * sizeof *S->a0);
    for (int i = 1; i < m; i++) {
        int cut = i == m - 1 && S->cut > 0.0;
        double dl = dx, dr = cut ? S->cut : dx, vx = 0.5 * (dl + dr);
        for (int j = 1; j <= nzi; j++) {
            double hl = gap_face_x(pb, i - 1, j);
            double hr = cut ? gap_in_cell(pb, i, j, 0.5 * S->cut / dx) : gap_face_x(pb, i, j);
            double hs = gap_face_z(pb, i, j - 1), hn = gap_face_z(pb, i, j);
            double aw = hl * hl * hl * c12 * dz / dl, ae = hr * hr * hr * c12 * dz / dr;
            double as = hs * hs * hs * c12 * vx / dz, an = hn * hn * hn * c12 * vx / dz;
            int u = (i - 1) * nzi + j - 1, k = 0;
            int *c = lub_csr_row_col(A, u);
            double *v = lub_csr_row_val(A, u);
            if (i > 1) c[k] = u - nzi, v[k++] = -aw;
            if (j > 1) c[k] = u - 1, v[k++] = -as;
            c[k] = u, v[k++] = aw + ae + (as + an);
            if (j < nzi) c[k] = u + 1, v[k++] = -an;
            if (i < m - 1) c[k] = u + nzi, v[k++] = -ae;
            double s = pb->source ? pb->source[i * (pb->nz + 1) + j] : 0.0;
            S->f[u] = um * (hr - hl) * dz + (squeeze_at(pb, i, j) + s) * vx * dz;
        }
    }
    lub_csr_finish(A);
    memcpy(S->a0, A->val, (size_t)A->nnz * sizeof *S->a0);
}

/* Solve M p = -f with p = 0 on the active set: its rows become p_u = 0 and its columns are
 * zeroed, which keeps M symmetric and its pattern (explicit zeros). */
static int solve_masked(sys2d *S)
{
    lub_csr *A = &S->A;
    for (int u = 0; u < S->nu; u++) {
        for (int k = A->row_ptr[u]; k < A->row_ptr[u + 1]; k++) {
            int c = A->col[k];
            A->val[k] = S->act[u] || S->act[c] ? (c == u ? 1.0 : 0.0) : S->a0[k];
        }
        S->b[u] = S->act[u] ? 0.0 : -S->f[u];
    }
    lub_csr_finish(A); /* a new stamp: the solver sets up again */
    const double *bb[1] = {S->b};
    double *xx[1] = {S->p};
    lub_solve_result r;
    lub_solve_status st = lub_linsolver_solve(&S->ls, A, 1, bb, xx, &r);
    S->linear_iters += r.iterations;
    return st == LUB_SOLVE_OK ? 0 : -1;
}

/* Primal-dual active-set iteration on the complementarity problem (as reynolds.c): free the
 * active nodes whose multiplier w = M p + f is negative, hold the free ones with p < 0.
 * Returns the iterations, -1 when the linear solve failed, -2 not converged. */
static int active_set(sys2d *S, double tol, int max_it)
{
    const lub_csr *A = &S->A;
    double fmax = 0.0, dmax = 0.0;
    for (int u = 0; u < S->nu; u++) {
        fmax = fmax > fabs(S->f[u]) ? fmax : fabs(S->f[u]);
        double d = S->a0[A->diag[u]];
        dmax = dmax > d ? dmax : d;
    }
    for (int it = 1; it <= max_it; it++) {
        if (solve_masked(S) != 0) return -1;
        double pmax = 0.0;
        for (int u = 0; u < S->nu; u++) pmax = pmax > fabs(S->p[u]) ? pmax : fabs(S->p[u]);
        double tol_p = tol * pmax, tol_w = tol * (fmax + dmax * pmax);
        int changed = 0;
        for (int u = 0; u < S->nu; u++) {
            if (S->act[u]) {
                double w = S->f[u];
                for (int k = A->row_ptr[u]; k < A->row_ptr[u + 1]; k++)
                    w += S->a0[k] * S->p[A->col[k]];
                if (w < -tol_w) {
                    S->act[u] = 0;
                    changed = 1;
                }
            } else if (S->p[u] < -tol_p) {
                S->act[u] = 1;
                changed = 1;
            }
        }
        if (!changed) {
            for (int u = 0; u < S->nu; u++)
                if (S->p[u] < 0.0) S->p[u] = 0.0; /* round-off below tol_p */
            return it;
        }
    }
    return -2;
}

/* Bilinear interpolation of a field on the (nx + 1) x (nz + 1) nodes of [xa, xb] x
 * [-W/2, W/2] at fractional node coordinates (si, sj). */
static double bilinear(const double *q, int nx, int nz, double si, double sj)
{
    int i = (int)si, j = (int)sj;
    if (i >= nx) i = nx - 1;
    if (j >= nz) j = nz - 1;
    double a = si - i, c = sj - j;
    const double *r0 = q + (size_t)i * (nz + 1), *r1 = r0 + nz + 1;
    return (1.0 - a) * ((1.0 - c) * r0[j] + c * r0[j + 1]) +
           a * ((1.0 - c) * r1[j] + c * r1[j + 1]);
}

enum { COARSEST_X = 32, COARSEST_Z = 8 };

static lub_reynolds_status solve_grid(const lub_reynolds2d_problem *pb, double *p, int *its,
                                      int *ncav, int *lin_its);

/* The start of the active set: the cavitated region of the problem on a grid of half the
 * cells in each direction, interpolated.  Returns 0, or a status of the coarse solve. */
static lub_reynolds_status coarse_start(const lub_reynolds2d_problem *pb, sys2d *S, int *its,
                                        int *lin_its)
{
    const int nx = pb->nx, nz = pb->nz;
    int nxc = (nx + 1) / 2, nzc = 2 * ((nz / 2 + 1) / 2), even = nx % 2 == 0;
    const int area = pb->h_area != NULL;
    double *hc = area ? NULL : lub_malloc((size_t)(nxc + 1) * sizeof *hc);
    double *hfc = even && !area ? lub_malloc((size_t)nxc * sizeof *hfc) : NULL;
    double *rc = pb->dhdt_nodes && !area ? lub_malloc((size_t)(nxc + 1) * sizeof *rc) : NULL;
    size_t nc = (size_t)(nxc + 1) * (nzc + 1);
    double *sc = pb->source ? lub_malloc(nc * sizeof *sc) : NULL;
    double *pc = lub_malloc(nc * sizeof *pc);
    /* a gap varying across: its nodes (and dh/dt) interpolated, the faces the nodes' means */
    double *hac = area ? lub_malloc(nc * sizeof *hac) : NULL;
    double *rac = area && pb->dhdt_area ? lub_malloc(nc * sizeof *rac) : NULL;
    for (int i = 0; i <= nxc; i++) {
        double sf = (double)i * nx / nxc;
        int k = (int)sf;
        if (k >= nx) k = nx - 1;
        double w = sf - k;
        if (hc) hc[i] = (1.0 - w) * pb->h[k] + w * pb->h[k + 1];
        if (rc) rc[i] = (1.0 - w) * pb->dhdt_nodes[k] + w * pb->dhdt_nodes[k + 1];
        if (hfc && i < nxc) hfc[i] = pb->h[2 * i + 1];
        for (int j = 0; j <= nzc; j++) {
            size_t q = (size_t)i * (nzc + 1) + j;
            double sj = (double)j * nz / nzc;
            if (sc) sc[q] = bilinear(pb->source, nx, nz, sf, sj);
            if (hac) hac[q] = bilinear(pb->h_area, nx, nz, sf, sj);
            if (rac) rac[q] = bilinear(pb->dhdt_area, nx, nz, sf, sj);
        }
    }
    lub_reynolds2d_problem cp = *pb;
    cp.nx = nxc;
    cp.nz = nzc;
    cp.h = hc;
    cp.h_face = hfc;
    cp.dhdt_nodes = rc;
    cp.source = sc;
    cp.h_area = hac;
    cp.h_face_x = cp.h_face_z = NULL;
    cp.dhdt_area = rac;
    int itc = 0, ncav = 0;
    lub_reynolds_status st = solve_grid(&cp, pc, &itc, &ncav, lin_its);
    if (st == LUB_REYNOLDS_OK) {
        for (int i = 1; i < S->m; i++)
            for (int j = 1; j <= S->nzi; j++)
                S->act[(i - 1) * S->nzi + j - 1] =
                    !(bilinear(pc, nxc, nzc, (double)i * nxc / nx, (double)j * nzc / nz) > 0.0);
        *its += itc;
    }
    free(hc);
    free(hfc);
    free(rc);
    free(sc);
    free(pc);
    free(hac);
    free(rac);
    return st;
}

/* Solve on pb's grid into p (all nodes). */
static lub_reynolds_status solve_grid(const lub_reynolds2d_problem *pb, double *p, int *its,
                                      int *ncav, int *lin_its)
{
    const int nx = pb->nx, nz = pb->nz;
    const double dx = (pb->xb - pb->xa) / nx;
    sys2d S;
    memset(&S, 0, sizeof S);
    S.pb = pb;
    S.m = nx;
    S.nzi = nz - 1;
    if (pb->bc == LUB_REYNOLDS_BC_GIVEN_EXIT) {
        /* node k with x_k <= exit < x_{k+1}; within round-off of a node it is that node,
         * else node k's right neighbour is the exit (cut cell), as in 1-D */
        double se = (pb->exit_x - pb->xa) / dx;
        int k = (int)floor(se);
        double frac = se - k;
        if (k >= nx) k = nx, frac = 0.0;
        if (frac < 1e-9)
            S.m = k;
        else if (frac > 1.0 - 1e-9)
            S.m = k + 1;
        else
            S.m = k + 1, S.cut = frac * dx;
    }
    for (size_t q = 0; q < (size_t)(nx + 1) * (nz + 1); q++) p[q] = 0.0;
    if (S.m < 2 || S.nzi < 1) return LUB_REYNOLDS_OK;
    S.nu = (S.m - 1) * S.nzi;
    lub_csr_init(&S.A);
    S.f = lub_malloc((size_t)S.nu * sizeof *S.f);
    S.b = lub_malloc((size_t)S.nu * sizeof *S.b);
    S.p = lub_calloc((size_t)S.nu, sizeof *S.p);
    S.act = lub_calloc((size_t)S.nu, 1);
    lub_linsolver_options o = lub_linsolver_defaults();
    o.kind = LUB_LINSOLVER_CHOLMOD;
    if (pb->solver) o = *pb->solver;
    o.pattern = LUB_PATTERN_SAME; /* the active set only changes values */
    lub_linsolver_init(&S.ls, &o);
    assemble(&S);

    lub_reynolds_status st = LUB_REYNOLDS_OK;
    if (pb->bc == LUB_REYNOLDS_BC_REYNOLDS) {
        double tol = pb->tolerance > 0.0 ? pb->tolerance : 1e-12;
        if (o.kind != LUB_LINSOLVER_CHOLMOD && tol < 100.0 * o.pcg.tolerance)
            tol = 100.0 * o.pcg.tolerance;
        int max_it = pb->max_iterations > 0 ? pb->max_iterations : nx + nz + 10;
        if (nx >= COARSEST_X && nz >= COARSEST_Z) st = coarse_start(pb, &S, its, lin_its);
        if (st == LUB_REYNOLDS_OK) {
            int it = active_set(&S, tol, max_it);
            if (it == -1) st = LUB_REYNOLDS_SINGULAR;
            if (it == -2) st = LUB_REYNOLDS_NOT_CONVERGED;
            if (it > 0) *its += it;
            for (int u = 0; u < S.nu; u++) *ncav += S.act[u];
        }
    } else if (solve_masked(&S) != 0) {
        st = LUB_REYNOLDS_SINGULAR;
    }
    if (st == LUB_REYNOLDS_OK)
        for (int i = 1; i < S.m; i++)
            for (int j = 1; j <= S.nzi; j++) p[i * (nz + 1) + j] = S.p[(i - 1) * S.nzi + j - 1];
    *lin_its += S.linear_iters;
    lub_linsolver_free(&S.ls);
    lub_csr_free(&S.A);
    free(S.a0);
    free(S.f);
    free(S.b);
    free(S.p);
    free(S.act);
    return st;
}

static lub_reynolds_status check_input(const lub_reynolds2d_problem *pb)
{
    if ((!pb->h && !pb->h_area) || pb->nx < 2 || pb->nz < 2 || pb->nz % 2 || !isfinite(pb->xa) ||
        !isfinite(pb->xb) || !(pb->xb > pb->xa) || !(pb->width > 0.0) || !isfinite(pb->width) ||
        !(pb->mu > 0.0) || !isfinite(pb->mu) || !isfinite(pb->u1) || !isfinite(pb->u2) ||
        !isfinite(pb->dhdt) || pb->tolerance < 0.0 || pb->max_iterations < 0 || (int)pb->bc < 0 ||
        pb->bc > LUB_REYNOLDS_BC_GIVEN_EXIT)
        return LUB_REYNOLDS_BAD_INPUT;
    if (pb->bc == LUB_REYNOLDS_BC_GIVEN_EXIT && !(pb->exit_x > pb->xa && pb->exit_x <= pb->xb))
        return LUB_REYNOLDS_BAD_INPUT;
    if (pb->h_area) {
        const int nx = pb->nx, nz = pb->nz;
        for (size_t q = 0; q < (size_t)(nx + 1) * (nz + 1); q++) {
            if (!(pb->h_area[q] > 0.0) || !isfinite(pb->h_area[q])) return LUB_REYNOLDS_BAD_GAP;
            if (pb->dhdt_area && !isfinite(pb->dhdt_area[q])) return LUB_REYNOLDS_BAD_INPUT;
        }
        for (size_t q = 0; pb->h_face_x && q < (size_t)nx * (nz + 1); q++)
            if (!(pb->h_face_x[q] > 0.0) || !isfinite(pb->h_face_x[q])) return LUB_REYNOLDS_BAD_GAP;
        for (size_t q = 0; pb->h_face_z && q < (size_t)(nx + 1) * nz; q++)
            if (!(pb->h_face_z[q] > 0.0) || !isfinite(pb->h_face_z[q])) return LUB_REYNOLDS_BAD_GAP;
        return LUB_REYNOLDS_OK;
    }
    if (!pb->h) return LUB_REYNOLDS_BAD_INPUT;
    for (int i = 0; i <= pb->nx; i++) {
        if (!(pb->h[i] > 0.0) || !isfinite(pb->h[i])) return LUB_REYNOLDS_BAD_GAP;
        if (pb->dhdt_nodes && !isfinite(pb->dhdt_nodes[i])) return LUB_REYNOLDS_BAD_INPUT;
        if (i < pb->nx && pb->h_face && (!(pb->h_face[i] > 0.0) || !isfinite(pb->h_face[i])))
            return LUB_REYNOLDS_BAD_GAP;
    }
    return LUB_REYNOLDS_OK;
}

/* The trapezoid weight of node k of n + 1. */
static double trap(int k, int n)
{
    return k == 0 || k == n ? 0.5 : 1.0;
}

/* Load, peak, flows and the mid-plane exit (reynolds2d.h). */
static void figures(const lub_reynolds2d_problem *pb, lub_reynolds2d_result *res)
{
    const int nx = pb->nx, nz = pb->nz, jm = nz / 2;
    const double dx = (pb->xb - pb->xa) / nx, dz = pb->width / nz;
    const double um = 0.5 * (pb->u1 + pb->u2), c12 = 1.0 / (12.0 * pb->mu);
    const double *p = res->p;
#define P(i, j) p[(size_t)(i) * (nz + 1) + (j)]
    double load = 0.0, leak = 0.0, qin = 0.0, qout = 0.0;
    int im = 0, jmx = 0;
    for (int i = 0; i <= nx; i++) {
        double h0 = gap_node(pb, i, 0), h1 = gap_node(pb, i, nz);
        double k0 = h0 * h0 * h0 * c12, k1 = h1 * h1 * h1 * c12;
        for (int j = 0; j <= nz; j++) {
            load += trap(i, nx) * trap(j, nz) * P(i, j);
            if (P(i, j) > P(im, jmx)) im = i, jmx = j;
        }
        /* -k dp/dz out of z = +W/2, +k dp/dz out of z = -W/2 (one-sided, second order) */
        double gt = (3.0 * P(i, nz) - 4.0 * P(i, nz - 1) + P(i, nz - 2)) / (2.0 * dz);
        double gb = (-3.0 * P(i, 0) + 4.0 * P(i, 1) - P(i, 2)) / (2.0 * dz);
        leak += trap(i, nx) * (k0 * gb - k1 * gt);
    }
    for (int j = 0; j <= nz; j++) {
        double ha = gap_node(pb, 0, j), hb = gap_node(pb, nx, j);
        double ka = ha * ha * ha * c12, kb = hb * hb * hb * c12;
        double ga = (-3.0 * P(0, j) + 4.0 * P(1, j) - P(2, j)) / (2.0 * dx);
        double gb = (3.0 * P(nx, j) - 4.0 * P(nx - 1, j) + P(nx - 2, j)) / (2.0 * dx);
        qin += trap(j, nz) * (um * ha - ka * ga);
        qout += trap(j, nz) * (um * hb - kb * gb);
    }
    res->load = load * dx * dz;
    res->leakage = leak * dx;
    res->q_in = qin * dz;
    res->q_out = qout * dz;
    /* the peak: the vertex of the parabolas through the largest node and its neighbours in x
     * and in z (each correction only when the node is a maximum inside the grid) */
    res->p_max = P(im, jmx);
    res->x_max = pb->xa + im * dx;
    res->z_max = lub_reynolds2d_z(pb, jmx);
    if (im > 0 && im < nx) {
        double pm = P(im - 1, jmx), pp = P(im + 1, jmx), cv = pp - 2.0 * P(im, jmx) + pm;
        if (cv < 0.0 && fabs(pp - pm) <= -2.0 * cv) {
            res->p_max -= (pp - pm) * (pp - pm) / (8.0 * cv);
            res->x_max -= dx * (pp - pm) / (2.0 * cv);
        }
    }
    if (jmx > 0 && jmx < nz) {
        double pm = P(im, jmx - 1), pp = P(im, jmx + 1), cv = pp - 2.0 * P(im, jmx) + pm;
        if (cv < 0.0 && fabs(pp - pm) <= -2.0 * cv) {
            res->p_max -= (pp - pm) * (pp - pm) / (8.0 * cv);
            res->z_max -= dz * (pp - pm) / (2.0 * cv);
        }
    }

    /* the exit along the mid-plane, downstream of its peak */
    int i0 = 0;
    for (int i = 1; i <= nx; i++)
        if (P(i, jm) > P(i0, jm)) i0 = i;
    int j = i0 < nx ? i0 + 1 : nx;
    while (j < nx && P(j, jm) > 0.0) j++;
    double xj = pb->xa + j * dx;
    if (pb->bc == LUB_REYNOLDS_BC_GIVEN_EXIT) {
        res->x_exit = pb->exit_x;
    } else if (!(P(i0, jm) > 0.0)) {
        res->x_exit = pb->xa;
    } else if (j >= nx && P(nx - 1, jm) > 0.0 && pb->bc == LUB_REYNOLDS_BC_REYNOLDS) {
        res->x_exit = pb->xb;
    } else if (pb->bc == LUB_REYNOLDS_BC_REYNOLDS) {
        /* p ~ (x_e - x)^2 at a free exit: sqrt(p) is linear through the last two nodes */
        double s1 = sqrt(P(j - 1, jm)), s0 = j >= 2 ? sqrt(fmax(P(j - 2, jm), 0.0)) : 0.0;
        res->x_exit = s0 > s1 ? xj - dx + dx * s1 / (s0 - s1) : xj;
        if (res->x_exit > xj) res->x_exit = xj;
    } else {
        double pk = P(j - 1, jm), pj = P(j, jm);
        res->x_exit = xj - dx + (pk > pj ? pk / (pk - pj) : 1.0) * dx;
    }
#undef P
}

lub_reynolds_status lub_reynolds2d_solve(const lub_reynolds2d_problem *pb,
                                         lub_reynolds2d_result *res)
{
    lub_reynolds_status st = check_input(pb);
    if (st != LUB_REYNOLDS_OK) return st;
    res->iterations = res->n_cavitated = res->linear_iters = 0;
    st = solve_grid(pb, res->p, &res->iterations, &res->n_cavitated, &res->linear_iters);
    if (st != LUB_REYNOLDS_OK) return st;
    if (pb->bc == LUB_REYNOLDS_BC_HALF_SOMMERFELD)
        for (size_t q = 0; q < (size_t)(pb->nx + 1) * (pb->nz + 1); q++)
            if (res->p[q] < 0.0) res->p[q] = 0.0;
    if (pb->bc != LUB_REYNOLDS_BC_REYNOLDS) res->iterations = 0;
    figures(pb, res);
    return LUB_REYNOLDS_OK;
}
