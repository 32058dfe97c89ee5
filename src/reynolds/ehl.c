/* lubkit soft EHL: coupled Reynolds-elasticity-load Newton solver (see ehl.h). */
#include "reynolds/ehl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "models/elastic.h"
#include "reynolds/reynolds.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

const char *lub_ehl_status_string(lub_ehl_status s)
{
    switch (s) {
    case LUB_EHL_OK:
        return "ok";
    case LUB_EHL_BAD_INPUT:
        return "bad input (grid, speeds, viscosity, modulus, load or shape)";
    case LUB_EHL_NOT_CONVERGED:
        return "the Newton iteration did not converge";
    case LUB_EHL_SINGULAR:
        return "singular Newton system";
    case LUB_EHL_RIGID_FAILED:
        return "no rigid load balance (no film of the rigid cylinder carries the load on this "
               "grid: refine it near the contact)";
    }
    return "unknown status";
}

void lub_ehl_problem_init(lub_ehl_problem *pb)
{
    memset(pb, 0, sizeof *pb);
}

/* ---- dense LU with partial pivoting (row-major, blocked right-looking) -------------------- */

enum { LU_BLOCK = 64 };

/* Factorise the m x m matrix a in place; piv[k] = row swapped with k.  0, or -1 singular. */
static int lu_factor(int m, double *a, int *piv)
{
    for (int k0 = 0; k0 < m; k0 += LU_BLOCK) {
        int k1 = k0 + LU_BLOCK < m ? k0 + LU_BLOCK : m;
        /* the panel: columns k0..k1-1, whole rows swapped */
        for (int k = k0; k < k1; k++) {
            int p = k;
            double big = fabs(a[(size_t)k * m + k]);
            for (int i = k + 1; i < m; i++) {
                double t = fabs(a[(size_t)i * m + k]);
                if (t > big) {
                    big = t;
                    p = i;
                }
            }
            piv[k] = p;
            if (!(big > 0.0)) return -1;
            double *rk = a + (size_t)k * m;
            if (p != k) {
                double *rp = a + (size_t)p * m;
                for (int j = 0; j < m; j++) {
                    double t = rk[j];
                    rk[j] = rp[j];
                    rp[j] = t;
                }
            }
            double inv = 1.0 / rk[k];
            for (int i = k + 1; i < m; i++) {
                double *ri = a + (size_t)i * m, l = ri[k] * inv;
                ri[k] = l;
                if (l != 0.0)
                    for (int j = k + 1; j < k1; j++) ri[j] -= l * rk[j];
            }
        }
        if (k1 >= m) break;
        /* U12 = L11^-1 A12 */
        for (int k = k0; k < k1; k++) {
            const double *rk = a + (size_t)k * m;
            for (int i = k + 1; i < k1; i++) {
                double *ri = a + (size_t)i * m, l = ri[k];
                if (l == 0.0) continue;
#pragma omp simd
                for (int j = k1; j < m; j++) ri[j] -= l * rk[j];
            }
        }
        /* A22 -= L21 U12 */
#pragma omp parallel for schedule(static) if ((double)(m - k1) * (m - k1) > 1e6)
        for (int i = k1; i < m; i++) {
            double *ri = a + (size_t)i * m;
            for (int k = k0; k < k1; k++) {
                double l = ri[k];
                if (l == 0.0) continue;
                const double *rk = a + (size_t)k * m;
#pragma omp simd
                for (int j = k1; j < m; j++) ri[j] -= l * rk[j];
            }
        }
    }
    return 0;
}

static void lu_solve(int m, const double *a, const int *piv, double *x)
{
    for (int k = 0; k < m; k++) {
        if (piv[k] != k) {
            double t = x[k];
            x[k] = x[piv[k]];
            x[piv[k]] = t;
        }
    }
    for (int i = 1; i < m; i++) {
        const double *ri = a + (size_t)i * m;
        double s = 0.0;
        for (int j = 0; j < i; j++) s += ri[j] * x[j];
        x[i] -= s;
    }
    for (int i = m - 1; i >= 0; i--) {
        const double *ri = a + (size_t)i * m;
        double s = x[i];
        for (int j = i + 1; j < m; j++) s -= ri[j] * x[j];
        x[i] = s / ri[i];
    }
}

/* ---- the discrete problem --------------------------------------------------------------- */

typedef struct {
    const lub_ehl_problem *pb;
    int n;
    double dx, um, c12; /* cell, mean speed, 1/(12 mu dx) */
    double b;
    double *x, *xf; /* nodes, faces */
    double *g, *gf; /* undeformed gap without h0 at nodes and faces */
    double *cf;     /* Toeplitz coefficients face f <- node j: cf[f - j + n] */
    lub_elastic_kernel *kf, *kn;
    double pref; /* pressure scale of the merit function */
    /* state and work */
    double *vf, *hf;               /* displacement and gap at the faces */
    double *r, *d;                 /* residual and diagonal at nodes 1..n-1 */
    unsigned char *act, *act_prev; /* cavitated nodes, now and before the last step */
    double *jac, *rhs;
    int *piv, *free_idx, *col_of;
    double *p_try, *p_new, *dp, *hf_old;
    /* the exact complementarity solve on the current gap, for the cavitated set */
    lub_reynolds_problem lcp;
    double *lcp_h, *lcp_p;
} ehl_t;

/* Gap at the faces for pressure p, rigid-body position h0 and compliance s. */
static void faces_gap(ehl_t *e, const double *p, double h0, double s)
{
    lub_elastic_displacement(e->kf, p, e->vf);
    for (int f = 0; f < e->n; f++) e->hf[f] = h0 + e->gf[f] + s * e->vf[f];
}

/* Residuals of the Reynolds equation at nodes 1..n-1 (the flux form of lub_reynolds_solve
 * with face gaps), the active (cavitated) set and the merit (mean square of the residual over
 * pref: p_i on the cavitated set, r_i/d_i elsewhere, plus the squared relative load error).
 *
 * The cavitated set is that of the exact complementarity solution for the current gap
 * (lub_reynolds_solve: projected sweep, finite), not the primal-dual rule p_i <= r_i/d_i,
 * which moves the free exit by one node per Newton iteration.  At the solution both agree
 * (the complementarity problem of an M-matrix has one solution).
 *
 * Returns -1 when the gap is not positive somewhere or the solve fails, else 0; *load_err the
 * relative load error. */
static int residual(ehl_t *e, const double *p, double h0, double s, double *merit, double *load_err)
{
    faces_gap(e, p, h0, s);
    int n = e->n;
    for (int f = 0; f < n; f++)
        if (!(e->hf[f] > 0.0)) return -1;
    /* node gaps only enter the solver's input check: the mean of the neighbouring faces */
    e->lcp_h[0] = e->hf[0];
    e->lcp_h[n] = e->hf[n - 1];
    for (int i = 1; i < n; i++) e->lcp_h[i] = 0.5 * (e->hf[i - 1] + e->hf[i]);
    lub_reynolds_result rr = {.p = e->lcp_p};
    if (lub_reynolds_solve(&e->lcp, &rr) != LUB_REYNOLDS_OK) return -1;
    for (int i = 1; i < n; i++) e->act[i] = !(e->lcp_p[i] > 0.0);
    double sum = 0.0, load = 0.0;
    for (int i = 1; i < n; i++) {
        double hl = e->hf[i - 1], hr = e->hf[i];
        double kl = hl * hl * hl * e->c12, kr = hr * hr * hr * e->c12;
        double r = kl * (p[i] - p[i - 1]) + kr * (p[i] - p[i + 1]) + e->um * (hr - hl);
        e->r[i] = r;
        e->d[i] = kl + kr;
        double F = e->act[i] ? p[i] : r / e->d[i];
        sum += F * F;
        load += p[i];
    }
    *load_err = (load * e->dx - e->pb->load) / e->pb->load;
    *merit = sum / ((n - 1) * e->pref * e->pref) + *load_err * *load_err;
    return 0;
}

/* The Newton direction at (p, h0) for the active set from the last residual():
 * dp (n + 1 values, 0 at the ends) and *dh0.  Returns 0, or -1 singular. */
static int newton_direction(ehl_t *e, const double *p, double s, double *dp, double *dh0)
{
    int n = e->n, nf = 0;
    for (int i = 1; i < n; i++) {
        e->col_of[i] = -1;
        if (!e->act[i]) {
            e->col_of[i] = nf;
            e->free_idx[nf++] = i;
        }
    }
    int m = nf + 1; /* free pressures and h0 */
    double *J = e->jac;
    const double *cf = e->cf;
    for (int a = 0; a < nf; a++) {
        int i = e->free_idx[a];
        double hl = e->hf[i - 1], hr = e->hf[i];
        double kl = hl * hl * hl * e->c12, kr = hr * hr * hr * e->c12;
        /* d r_i / d h_left, d h_right (the face gaps) */
        double al = 3.0 * hl * hl * e->c12 * (p[i] - p[i - 1]) - e->um;
        double ar = 3.0 * hr * hr * e->c12 * (p[i] - p[i + 1]) + e->um;
        double *row = J + (size_t)a * m;
        double sal = s * al, sar = s * ar;
        /* dense part: face i-1 and face i see node j through cf[(i-1) - j + n], cf[i - j + n] */
        const double *cl = cf + (i - 1) + n, *cr = cf + i + n;
        double rhs = -e->r[i];
        for (int q = 0; q < nf; q++) {
            int j = e->free_idx[q];
            row[q] = sal * cl[-j] + sar * cr[-j];
        }
        /* tridiagonal part */
        row[a] += kl + kr;
        if (i > 1 && e->col_of[i - 1] >= 0) row[e->col_of[i - 1]] -= kl;
        if (i < n - 1 && e->col_of[i + 1] >= 0) row[e->col_of[i + 1]] -= kr;
        row[nf] = al + ar; /* h0 */
        /* known steps of the cavitated nodes: dp_j = -p_j */
        for (int j = 1; j < n; j++) {
            if (!e->act[j] || p[j] == 0.0) continue;
            double Jij = sal * cl[-j] + sar * cr[-j];
            if (j == i - 1) Jij -= kl;
            if (j == i + 1) Jij -= kr;
            rhs += Jij * p[j];
        }
        e->rhs[a] = rhs;
    }
    /* load row: sum dp_j dx = W - sum p_j dx */
    double *row = J + (size_t)nf * m, load = 0.0, known = 0.0;
    for (int q = 0; q < nf; q++) row[q] = 1.0;
    row[nf] = 0.0;
    for (int j = 1; j < n; j++) {
        load += p[j];
        if (e->act[j]) known += p[j];
    }
    e->rhs[nf] = e->pb->load / e->dx - load + known;
    /* row equilibration */
    for (int a = 0; a < m; a++) {
        double *ra = J + (size_t)a * m, big = 0.0;
        for (int q = 0; q < m; q++) big = fmax(big, fabs(ra[q]));
        if (!(big > 0.0)) return -1;
        double sc = 1.0 / big;
        for (int q = 0; q < m; q++) ra[q] *= sc;
        e->rhs[a] *= sc;
    }
    if (lu_factor(m, J, e->piv) != 0) return -1;
    lu_solve(m, J, e->piv, e->rhs);
    dp[0] = dp[n] = 0.0;
    for (int i = 1; i < n; i++) dp[i] = e->act[i] ? -p[i] : e->rhs[e->col_of[i]];
    *dh0 = e->rhs[nf];
    return 0;
}

static double min_gap(const ehl_t *e)
{
    double h = INFINITY;
    for (int f = 0; f < e->n; f++) h = fmin(h, e->hf[f]);
    return h;
}

/* Newton iterations at compliance s from (p, h0) until the tolerance or max_it; returns the
 * iterations used (> 0) when converged, -(iterations) when not, and updates p, h0 only on
 * success.  *budget counts down the iterations left overall. */
static int newton(ehl_t *e, double *p, double *h0, double s, double tol, int max_it, int *budget,
                  int *singular, lub_ehl_result *res)
{
    int n = e->n;
    double *pt = e->p_try, *dp = e->dp;
    double ht = *h0, merit, lerr;
    memcpy(pt, p, (size_t)(n + 1) * sizeof *pt);
    if (residual(e, pt, ht, s, &merit, &lerr) != 0) return -1;
    unsigned char *act_prev = e->act_prev;
    /* non-monotone line search (Grippo, Lampariello and Lucidi): a step is accepted when it
     * lowers the merit below the largest of the last NM accepted values, so that Newton's full
     * steps are kept through the kinks of the cavitated set */
    enum { NM = 4 };
    double hist[NM];
    for (int k = 0; k < NM; k++) hist[k] = merit;
    for (int it = 1; it <= max_it && *budget > 0; it++) {
        (*budget)--;
        res->iterations++;
        memcpy(act_prev, e->act, (size_t)n + 1);
        memcpy(e->hf_old, e->hf, (size_t)n * sizeof(double));
        double hmin_old = min_gap(e), dh0;
        if (newton_direction(e, pt, s, dp, &dh0) != 0) {
            *singular = 1;
            return -it;
        }
        /* backtracking: keep the gap positive and decrease the merit */
        double lambda = 1.0, merit_new = 0.0, lerr_new = 0.0;
        int ok = 0;
        double *pn = e->p_new;
        for (int hv = 0; hv <= 12; hv++) { /* down to lambda = 2^-12 */
            for (int i = 0; i <= n; i++) pn[i] = fmax(pt[i] + lambda * dp[i], 0.0);
            double ref = hist[0];
            for (int k = 1; k < NM; k++) ref = fmax(ref, hist[k]);
            if (residual(e, pn, ht + lambda * dh0, s, &merit_new, &lerr_new) == 0 &&
                (merit_new <= (1.0 - 1e-4 * lambda) * ref || merit < 1e-28)) {
                ok = 1;
                break;
            }
            lambda *= 0.5;
        }
        /* no acceptable step, or only a tiny one: the start lies outside Newton's basin at
         * this compliance; the continuation retries with a smaller step at once */
        if (!ok || lambda < 1.0 / 16.0) return -it;
        /* change of the film over the step (residual() left the new face gaps in hf) */
        double hmin_new = min_gap(e), change = 0.0;
        for (int f = 0; f < n; f++) change = fmax(change, fabs(e->hf[f] - e->hf_old[f]));
        change /= hmin_new;
        memcpy(pt, pn, (size_t)(n + 1) * sizeof *pt);
        ht += lambda * dh0;
        merit = merit_new;
        lerr = lerr_new;
        hist[it % NM] = merit;
        int same = memcmp(act_prev, e->act, (size_t)n + 1) == 0;
        res->change = change;
        res->hmin_change = fabs(hmin_new - hmin_old) / hmin_new;
        res->load_error = lerr;
        if (change <= tol && fabs(lerr) <= tol && same && lambda == 1.0) {
            memcpy(p, pt, (size_t)(n + 1) * sizeof *p);
            *h0 = ht;
            return it;
        }
    }
    return -max_it;
}

/* Rigid load balance (s = 0): h0 with sum p dx = W by a secant on ln h0 against ln load,
 * with lub_reynolds_solve on h0 + g.  Fills p; returns 0 or -1. */
static int rigid_balance(ehl_t *e, double *p, double *h0_out, double *h_nodes)
{
    const lub_ehl_problem *pb = e->pb;
    int n = e->n;
    double *hf = lub_malloc((size_t)n * sizeof *hf);
    lub_reynolds_problem rp;
    lub_reynolds_problem_init(&rp);
    rp.n = n;
    rp.xa = pb->xa;
    rp.xb = pb->xb;
    rp.h = h_nodes;
    rp.h_face = hf;
    rp.u1 = pb->u1;
    rp.u2 = pb->u2;
    rp.mu = pb->mu;
    rp.tolerance = pb->lcp_tolerance;
    lub_reynolds_result rr = {.p = p};
    /* the infinite-inlet rigid cylinder: W = 2.448 mu (U1 + U2) R / h0 */
    double gmin = INFINITY;
    for (int i = 0; i <= n; i++) gmin = fmin(gmin, e->g[i]);
    double h0 = 2.448 * pb->mu * fabs(pb->u1 + pb->u2) * pb->radius / pb->load;
    double lh_prev = 0.0, ll_prev = 0.0;
    int have_prev = 0, status = -1;
    for (int it = 0; it < 200; it++) {
        for (int i = 0; i <= n; i++) h_nodes[i] = h0 + e->g[i];
        for (int f = 0; f < n; f++) hf[f] = h0 + e->gf[f];
        double lh = log(h0), ll;
        if (h0 + gmin <= 0.0 || lub_reynolds_solve(&rp, &rr) != LUB_REYNOLDS_OK) break;
        if (!(rr.load > 0.0)) {
            if (it > 60) break;
            h0 *= 0.1; /* no pressure: come closer */
            have_prev = 0;
            continue;
        }
        ll = log(rr.load / pb->load);
        if (fabs(ll) < 1e-13) {
            status = 0;
            break;
        }
        double slope = have_prev && lh != lh_prev ? (ll - ll_prev) / (lh - lh_prev) : -1.0;
        if (!(slope < -0.05)) slope = -1.0; /* the load falls with h0 roughly as 1/h0 */
        double step = -ll / slope;
        step = fmax(fmin(step, 2.0), -2.0);
        lh_prev = lh;
        ll_prev = ll;
        have_prev = 1;
        h0 = exp(lh + step);
    }
    *h0_out = h0;
    free(hf);
    return status;
}

/* Minimum of the sampled film over nodes and faces, refined by the parabola through the
 * smallest sample and its neighbours (half a cell apart). */
static void film_minimum(const ehl_t *e, const double *h, double *hmin, double *xmin)
{
    int n = e->n, best = 0;
    double dx = e->dx;
    double vmin = h[0];
    for (int k = 1; k <= 2 * n; k++) {
        double v = k % 2 ? e->hf[k / 2] : h[k / 2];
        if (v < vmin) {
            vmin = v;
            best = k;
        }
    }
    *hmin = vmin;
    *xmin = e->pb->xa + 0.5 * best * dx;
    if (best > 0 && best < 2 * n) {
        double gm = best % 2 ? h[best / 2] : e->hf[best / 2 - 1];
        double gp = best % 2 ? h[best / 2 + 1] : e->hf[best / 2];
        double curv = gm - 2.0 * vmin + gp;
        if (curv > 0.0) {
            *xmin += 0.25 * dx * (gm - gp) / curv;
            *hmin -= (gp - gm) * (gp - gm) / (8.0 * curv);
        }
    }
}

static lub_ehl_status check_input(const lub_ehl_problem *pb)
{
    if (pb->n < 4 || !isfinite(pb->xa) || !isfinite(pb->xb) || !(pb->xb > pb->xa) ||
        !(pb->mu > 0.0) || !isfinite(pb->mu) || !isfinite(pb->u1) || !isfinite(pb->u2) ||
        !(pb->radius > 0.0) || !isfinite(pb->radius) || !isfinite(pb->x_centre) || !(pb->E > 0.0) ||
        !isfinite(pb->E) || !(pb->load > 0.0) || !isfinite(pb->load) || pb->b < 0.0 ||
        !isfinite(pb->b) || pb->tolerance < 0.0 || pb->max_iterations < 0 ||
        pb->lcp_tolerance < 0.0 || (pb->shape && !pb->shape_face) || pb->u1 + pb->u2 == 0.0)
        return LUB_EHL_BAD_INPUT;
    if (pb->shape)
        for (int i = 0; i <= pb->n; i++)
            if (!isfinite(pb->shape[i]) || (i < pb->n && !isfinite(pb->shape_face[i])))
                return LUB_EHL_BAD_INPUT;
    return LUB_EHL_OK;
}

static void ehl_free(ehl_t *e)
{
    free(e->x);
    free(e->xf);
    free(e->g);
    free(e->gf);
    free(e->cf);
    lub_elastic_kernel_free(e->kf);
    lub_elastic_kernel_free(e->kn);
    free(e->vf);
    free(e->hf);
    free(e->r);
    free(e->d);
    free(e->act);
    free(e->act_prev);
    free(e->jac);
    free(e->rhs);
    free(e->piv);
    free(e->free_idx);
    free(e->col_of);
    free(e->p_try);
    free(e->p_new);
    free(e->dp);
    free(e->hf_old);
    free(e->lcp_h);
    free(e->lcp_p);
}

lub_ehl_status lub_ehl_solve(const lub_ehl_problem *pb, lub_ehl_result *res)
{
    lub_ehl_status st = check_input(pb);
    if (st != LUB_EHL_OK) return st;
    int n = pb->n;
    double tol = pb->tolerance > 0.0 ? pb->tolerance : 1e-8;
    int budget = pb->max_iterations > 0 ? pb->max_iterations : 400;

    ehl_t e;
    memset(&e, 0, sizeof e);
    e.pb = pb;
    e.n = n;
    e.dx = (pb->xb - pb->xa) / n;
    e.um = 0.5 * (pb->u1 + pb->u2);
    e.c12 = 1.0 / (12.0 * pb->mu * e.dx);
    e.b = pb->b > 0.0 ? pb->b : lub_elastic_hertz_half_width(pb->load, pb->radius, pb->E);
    e.pref = lub_elastic_hertz_pressure(pb->load,
                                        lub_elastic_hertz_half_width(pb->load, pb->radius, pb->E));
    size_t nn = (size_t)n + 1;
    e.x = lub_malloc(nn * sizeof(double));
    e.xf = lub_malloc(nn * sizeof(double));
    e.g = lub_malloc(nn * sizeof(double));
    e.gf = lub_malloc(nn * sizeof(double));
    double *w = lub_malloc(nn * sizeof(double));
    for (int i = 0; i <= n; i++) {
        e.x[i] = pb->xa + (pb->xb - pb->xa) * (double)i / (double)n; /* lub_reynolds_node_x */
        double d = e.x[i] - pb->x_centre;
        e.g[i] = d * d / (2.0 * pb->radius) + (pb->shape ? pb->shape[i] : 0.0);
        w[i] = e.dx;
    }
    for (int f = 0; f < n; f++) {
        e.xf[f] = pb->xa + (f + 0.5) * e.dx;
        double d = e.xf[f] - pb->x_centre;
        e.gf[f] = d * d / (2.0 * pb->radius) + (pb->shape ? pb->shape_face[f] : 0.0);
    }
    /* influence of the node segments on the faces (Newton) and the nodes (output) */
    e.kf = lub_elastic_kernel_create(n + 1, e.x, w, n, e.xf, pb->E, e.b);
    e.kn = lub_elastic_kernel_create(n + 1, e.x, w, n + 1, e.x, pb->E, e.b);
    free(w);
    /* Toeplitz table of the Jacobian: face f from node j at (f - j + 1/2) dx */
    e.cf = lub_malloc((size_t)(2 * n + 1) * sizeof(double));
    for (int k = 0; k <= 2 * n; k++)
        e.cf[k] = lub_elastic_coefficient((k - n + 0.5) * e.dx, e.dx, pb->E, e.b);
    e.vf = lub_malloc(nn * sizeof(double));
    e.hf = lub_malloc(nn * sizeof(double));
    e.r = lub_calloc(nn, sizeof(double));
    e.d = lub_calloc(nn, sizeof(double));
    e.act = lub_calloc(nn, 1);
    e.act_prev = lub_calloc(nn, 1);
    e.jac = lub_malloc(nn * nn * sizeof(double));
    e.rhs = lub_malloc(nn * sizeof(double));
    e.piv = lub_malloc(nn * sizeof(int));
    e.free_idx = lub_malloc(nn * sizeof(int));
    e.col_of = lub_malloc(nn * sizeof(int));
    e.p_try = lub_malloc(nn * sizeof(double));
    e.dp = lub_malloc(nn * sizeof(double));
    e.p_new = lub_malloc(nn * sizeof(double));
    e.hf_old = lub_malloc(nn * sizeof(double));
    e.lcp_h = lub_malloc(nn * sizeof(double));
    e.lcp_p = lub_malloc(nn * sizeof(double));
    lub_reynolds_problem_init(&e.lcp);
    e.lcp.n = n;
    e.lcp.xa = pb->xa;
    e.lcp.xb = pb->xb;
    e.lcp.h = e.lcp_h;
    e.lcp.h_face = e.hf;
    e.lcp.u1 = pb->u1;
    e.lcp.u2 = pb->u2;
    e.lcp.mu = pb->mu;
    e.lcp.tolerance = pb->lcp_tolerance;

    memset(res->p, 0, nn * sizeof(double));
    res->b = e.b;
    res->iterations = res->stages = 0;
    res->change = res->hmin_change = res->load_error = NAN;

    /* stage 0: the rigid cylinder carrying the load */
    double *p = res->p, h0;
    if (rigid_balance(&e, p, &h0, res->h) != 0) {
        ehl_free(&e);
        return LUB_EHL_RIGID_FAILED;
    }
    res->h0_rigid = h0;

    /* continuation in the compliance s: 0 -> 1, geometric (the solution changes with ln s
     * once the deformation exceeds the film).  First stage where the deformation of the
     * load, of order 4 W / (pi E / s), is a tenth of the rigid film; then s *= q, q adapted
     * to the Newton iterations a stage needed. */
    double *p_prev = lub_malloc(nn * sizeof(double)), *p_save = lub_malloc(nn * sizeof(double));
    memcpy(p_prev, p, nn * sizeof(double));
    double delta = 4.0 * pb->load / (M_PI * pb->E);
    double s_first = fmin(1.0, fmax(1e-9, 0.1 * h0 / delta));
    double h0_prev = h0, s = 0.0, s_prev = 0.0, q = 4.0;
    int singular = 0;
    st = LUB_EHL_OK;
    while (s < 1.0) {
        double s_new = s > 0.0 ? fmin(1.0, s * q) : s_first;
        int last = s_new >= 1.0;
        /* predictor: linear extrapolation in ln s from the last two stages, if it keeps h > 0 */
        memcpy(p_save, p, nn * sizeof(double));
        double h0_try = h0;
        if (s_prev > 0.0) {
            double f = log(s_new / s) / log(s / s_prev);
            for (int i = 0; i <= n; i++) p[i] = fmax(p[i] + f * (p[i] - p_prev[i]), 0.0);
            h0_try = h0 + f * (h0 - h0_prev);
            double dummy, lerr;
            if (residual(&e, p, h0_try, s_new, &dummy, &lerr) != 0) {
                memcpy(p, p_save, nn * sizeof(double));
                h0_try = h0;
            }
        }
        int it = newton(&e, p, &h0_try, s_new, last ? tol : fmax(tol, 1e-2), last ? 30 : 10,
                        &budget, &singular, res);
        if (it > 0) {
            memcpy(p_prev, p_save, nn * sizeof(double));
            h0_prev = h0;
            s_prev = s;
            s = s_new;
            h0 = h0_try;
            res->stages++;
            if (it <= 3)
                q = fmin(q * q, 1e3);
            else if (it >= 7)
                q = sqrt(q);
        } else {
            memcpy(p, p_save, nn * sizeof(double));
            if (s > 0.0)
                q = sqrt(q);
            else
                s_first *= 0.1;
            if (budget <= 0 || q < 1.0 + 1e-4 || s_first < 1e-12) {
                st = singular ? LUB_EHL_SINGULAR : LUB_EHL_NOT_CONVERGED;
                break;
            }
            singular = 0;
        }
    }
    free(p_prev);
    free(p_save);

    /* the film, the displacement and the figures at the last iterate */
    double merit, lerr;
    residual(&e, p, h0, s, &merit, &lerr);
    double *v = res->v ? res->v : lub_malloc(nn * sizeof(double));
    lub_elastic_displacement(e.kn, p, v);
    for (int i = 0; i <= n; i++) res->h[i] = h0 + e.g[i] + s * v[i];
    res->h0 = h0;
    film_minimum(&e, res->h, &res->h_min, &res->x_min);
    double vc = 0.0, gc = 0.0;
    for (int j = 1; j < n; j++)
        vc += lub_elastic_coefficient(pb->x_centre - e.x[j], e.dx, pb->E, e.b) * p[j];
    if (pb->shape && pb->x_centre >= pb->xa && pb->x_centre <= pb->xb) {
        double sc = (pb->x_centre - pb->xa) / e.dx;
        int k = (int)sc < n ? (int)sc : n - 1;
        gc = pb->shape[k] + (sc - k) * (pb->shape[k + 1] - pb->shape[k]);
    }
    res->h_centre = h0 + gc + s * vc;
    double load = 0.0;
    res->n_cavitated = 0;
    for (int i = 1; i < n; i++) {
        load += p[i];
        res->n_cavitated += p[i] == 0.0;
    }
    res->load = load * e.dx;
    res->load_error = (res->load - pb->load) / pb->load;

    /* the exact complementarity solve on the final gap: exit, peak, and the check */
    lub_reynolds_problem rp;
    lub_reynolds_problem_init(&rp);
    rp.n = n;
    rp.xa = pb->xa;
    rp.xb = pb->xb;
    rp.h = res->h;
    rp.h_face = e.hf;
    rp.u1 = pb->u1;
    rp.u2 = pb->u2;
    rp.mu = pb->mu;
    rp.tolerance = pb->lcp_tolerance;
    double *pl = lub_malloc(nn * sizeof(double));
    lub_reynolds_result rr = {.p = pl};
    res->lcp_diff = NAN;
    if (lub_reynolds_solve(&rp, &rr) == LUB_REYNOLDS_OK) {
        double dmax = 0.0;
        for (int i = 0; i <= n; i++) dmax = fmax(dmax, fabs(pl[i] - p[i]));
        res->lcp_diff = rr.p_max > 0.0 ? dmax / rr.p_max : dmax;
        res->p_max = rr.p_max;
        res->x_max = rr.x_max;
        res->x_exit = rr.x_exit;
    } else {
        res->p_max = res->x_max = res->x_exit = NAN;
    }
    free(pl);
    if (!res->v) free(v);
    ehl_free(&e);
    return st;
}
