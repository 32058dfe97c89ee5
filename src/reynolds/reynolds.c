/* lubkit Reynolds equation: 1-D finite-volume / finite-difference solver (see reynolds.h). */
#include "reynolds/reynolds.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

const char *const lub_reynolds_bc_names[] = {"reynolds", "halfSommerfeld", "fullSommerfeld",
                                             "givenExit", NULL};

const char *lub_reynolds_status_string(lub_reynolds_status s)
{
    switch (s) {
    case LUB_REYNOLDS_OK:
        return "ok";
    case LUB_REYNOLDS_BAD_INPUT:
        return "bad input (grid, viscosity, speeds or exit)";
    case LUB_REYNOLDS_BAD_GAP:
        return "gap h <= 0 or not finite";
    case LUB_REYNOLDS_NOT_CONVERGED:
        return "active set did not converge";
    case LUB_REYNOLDS_SINGULAR:
        return "singular tridiagonal system";
    }
    return "unknown status";
}

void lub_reynolds_problem_init(lub_reynolds_problem *pb)
{
    memset(pb, 0, sizeof *pb);
    pb->bc = LUB_REYNOLDS_BC_REYNOLDS;
}

/* The discrete system on unknown nodes 1..m-1 (p_0 = p_m = 0), written as the linear
 * complementarity operator M p + f (M = minus the flux-difference operator, an M-matrix):
 *     lo_i p_{i-1} + di_i p_i + up_i p_{i+1} + f_i  = 0 where the film is full,
 *                                                    = w_i >= 0 where it is cavitated. */
typedef struct {
    int m;
    double *lo, *di, *up, *f;
    double *cp, *dp; /* Thomas work */
    unsigned char *active;
} system_t;

static void system_alloc(system_t *s, int n)
{
    size_t sz = (size_t)(n + 1) * sizeof(double);
    s->lo = lub_malloc(sz);
    s->di = lub_malloc(sz);
    s->up = lub_malloc(sz);
    s->f = lub_malloc(sz);
    s->cp = lub_malloc(sz);
    s->dp = lub_malloc(sz);
    s->active = lub_calloc((size_t)n + 1, 1);
}

static void system_free(system_t *s)
{
    free(s->lo);
    free(s->di);
    free(s->up);
    free(s->f);
    free(s->cp);
    free(s->dp);
    free(s->active);
}

/* Gap at the midpoint of cell [x_i, x_{i+1}] (a face). */
static double face_gap(const lub_reynolds_problem *pb, int i)
{
    return pb->h_face ? pb->h_face[i] : 0.5 * (pb->h[i] + pb->h[i + 1]);
}

static double node_dhdt(const lub_reynolds_problem *pb, int i)
{
    return pb->dhdt_nodes ? pb->dhdt_nodes[i] : pb->dhdt;
}

/* Gap at x_i + s dx, 0 <= s <= 1: quadratic through node, face and node when the face gap is
 * given (third-order), else linear. */
static double gap_in_cell(const lub_reynolds_problem *pb, int i, double s)
{
    double h0 = pb->h[i], h1 = pb->h[i + 1];
    if (!pb->h_face) return h0 + s * (h1 - h0);
    double hm = pb->h_face[i];
    /* Lagrange basis on s = 0, 1/2, 1 */
    return h0 * 2.0 * (s - 0.5) * (s - 1.0) - hm * 4.0 * s * (s - 1.0) + h1 * 2.0 * s * (s - 0.5);
}

/* Assemble rows 1..m-1.  Finite volume: the control volume of node i spans the face midpoints;
 * the flux q = Um h - h^3/(12 mu) dp/dx at each face, and dq/dx = -dh/dt (T-32):
 *   k_r (p_{i+1} - p_i)/d_r - k_l (p_i - p_{i-1})/d_l = Um (h_r - h_l) + dh/dt_i V_i.
 * When cut_delta > 0 the right neighbour of node m-1 is the given exit at distance cut_delta
 * (Shortley-Weller cut cell) instead of a grid node. */
static void assemble(const lub_reynolds_problem *pb, system_t *s, int m, double cut_delta)
{
    double dx = (pb->xb - pb->xa) / pb->n;
    double um = 0.5 * (pb->u1 + pb->u2);
    double c12 = 1.0 / (12.0 * pb->mu);
    s->m = m;
    for (int i = 1; i < m; i++) {
        double dl = dx, dr = dx;
        double hl = face_gap(pb, i - 1), hr;
        if (i == m - 1 && cut_delta > 0.0) {
            dr = cut_delta;
            hr = gap_in_cell(pb, i, 0.5 * cut_delta / dx);
        } else {
            hr = face_gap(pb, i);
        }
        double kl = hl * hl * hl * c12 / dl, kr = hr * hr * hr * c12 / dr;
        double vol = 0.5 * (dl + dr);
        s->lo[i] = -kl;
        s->up[i] = -kr;
        s->di[i] = kl + kr;
        s->f[i] = um * (hr - hl) + node_dhdt(pb, i) * vol;
    }
    s->lo[1] = 0.0;     /* p_0 = 0 */
    s->up[m - 1] = 0.0; /* p_m = 0 */
}

/* Thomas algorithm for M p = -f on rows 1..m-1, rows flagged active replaced by p_i = 0.
 * p_0 and p_m are set to 0.  M is an M-matrix, so no pivoting is needed; a zero pivot means
 * a degenerate input. */
static int thomas(system_t *s, double *p)
{
    int m = s->m;
    double cprev = 0.0, dprev = 0.0;
    for (int i = 1; i < m; i++) {
        double lo = s->lo[i], di = s->di[i], up = s->up[i], r = -s->f[i];
        if (s->active[i]) {
            lo = 0.0;
            di = 1.0;
            up = 0.0;
            r = 0.0;
        }
        double piv = di - lo * cprev;
        if (!(fabs(piv) > 0.0)) return -1;
        s->cp[i] = up / piv;
        s->dp[i] = (r - lo * dprev) / piv;
        cprev = s->cp[i];
        dprev = s->dp[i];
    }
    p[0] = 0.0;
    p[m] = 0.0;
    for (int i = m - 1; i >= 1; i--) p[i] = s->dp[i] - s->cp[i] * p[i + 1];
    return 0;
}

/* Projected Thomas sweep (Brennan-Schwartz): eliminate in the direction of the flow, then
 * back-substitute against it clipping at 0.  Back-substituting into node i with p_{i+1} = 0
 * gives the solution of the full-film problem ending at x_{i+1}, which is negative exactly
 * when that end lies beyond the free exit (dp/dx > 0 there); so for a film that ruptures once
 * downstream the clipped sweep is the exact discrete complementarity solution.  It marks the
 * clipped nodes active as the initial guess of the active-set iteration. */
static int projected_sweep(system_t *s, double *p, int forward)
{
    int m = s->m;
    memset(s->active, 0, (size_t)m + 1);
    double cprev = 0.0, dprev = 0.0;
    p[0] = p[m] = 0.0;
    if (forward) {
        for (int i = 1; i < m; i++) {
            double piv = s->di[i] - s->lo[i] * cprev;
            if (!(fabs(piv) > 0.0)) return -1;
            s->cp[i] = s->up[i] / piv;
            s->dp[i] = (-s->f[i] - s->lo[i] * dprev) / piv;
            cprev = s->cp[i];
            dprev = s->dp[i];
        }
        for (int i = m - 1; i >= 1; i--) {
            double v = s->dp[i] - s->cp[i] * p[i + 1];
            s->active[i] = !(v > 0.0);
            p[i] = s->active[i] ? 0.0 : v;
        }
    } else {
        for (int i = m - 1; i >= 1; i--) {
            double piv = s->di[i] - s->up[i] * cprev;
            if (!(fabs(piv) > 0.0)) return -1;
            s->cp[i] = s->lo[i] / piv;
            s->dp[i] = (-s->f[i] - s->up[i] * dprev) / piv;
            cprev = s->cp[i];
            dprev = s->dp[i];
        }
        for (int i = 1; i < m; i++) {
            double v = s->dp[i] - s->cp[i] * p[i - 1];
            s->active[i] = !(v > 0.0);
            p[i] = s->active[i] ? 0.0 : v;
        }
    }
    return 0;
}

/* Primal-dual active-set iteration for the complementarity problem (Hintermueller, Ito and
 * Kunisch 2002): solve with p = 0 on the active set, then free active nodes whose multiplier
 * w = M p + f is negative (film would pull) and activate free nodes with p < 0.  For an
 * M-matrix it converges in finitely many steps from any start; from the projected sweep it
 * usually stops after the first (confirming) solve.  Returns iterations, -1 singular,
 * -2 not converged. */
static int active_set(system_t *s, double *p, double tol, int max_it)
{
    int m = s->m;
    double fmax = 0.0, dmax = 0.0;
    for (int i = 1; i < m; i++) {
        fmax = fmax > fabs(s->f[i]) ? fmax : fabs(s->f[i]);
        dmax = dmax > s->di[i] ? dmax : s->di[i];
    }
    for (int it = 1; it <= max_it; it++) {
        if (thomas(s, p) != 0) return -1;
        double pmax = 0.0;
        for (int i = 1; i < m; i++) pmax = pmax > fabs(p[i]) ? pmax : fabs(p[i]);
        double tol_p = tol * pmax, tol_w = tol * (fmax + dmax * pmax);
        int changed = 0;
        for (int i = 1; i < m; i++) {
            if (s->active[i]) {
                double w = s->lo[i] * p[i - 1] + s->up[i] * p[i + 1] + s->f[i];
                if (w < -tol_w) {
                    s->active[i] = 0;
                    changed = 1;
                }
            } else if (p[i] < -tol_p) {
                s->active[i] = 1;
                changed = 1;
            }
        }
        if (!changed) {
            for (int i = 1; i < m; i++)
                if (p[i] < 0.0) p[i] = 0.0; /* round-off below tol_p */
            return it;
        }
    }
    return -2;
}

/* Complementarity (Reynolds condition) solve on the uniform grid of pb, into p; returns the
 * active-set iterations (all levels), -1 singular, -2 not converged.
 *
 * 1. The projected sweep, confirmed by at most LCP_QUICK active-set solves: exact for a film
 *    that ruptures once downstream, the usual case.
 * 2. Otherwise (the film ruptures and reforms, or cavitates upstream) the active set moves
 *    only a node or so per iteration, which would cost O(n^2).  So the same problem is solved
 *    on a grid of half the cells (recursively), and its cavitated region, interpolated, is
 *    the starting set: the boundaries then have only a cell or two to move on each level,
 *    and the whole solve stays O(n). */
enum { LCP_QUICK = 3, LCP_COARSEST = 32 };

static int reynolds_lcp(const lub_reynolds_problem *pb, system_t *s, double *p, double tol,
                        int max_it)
{
    int n = pb->n;
    double um = 0.5 * (pb->u1 + pb->u2);
    assemble(pb, s, n, 0.0);
    if (projected_sweep(s, p, um >= 0.0) != 0) return -1;
    int it = active_set(s, p, tol, n < LCP_COARSEST ? max_it : LCP_QUICK);
    if (it != -2 || n < LCP_COARSEST) return it;

    /* the coarse problem: every other node (its faces are the fine odd nodes) when n is even,
     * linear interpolation otherwise */
    int nc = (n + 1) / 2, even = n % 2 == 0;
    double *hc = lub_malloc((size_t)(nc + 1) * sizeof *hc);
    double *hfc = even ? lub_malloc((size_t)nc * sizeof *hfc) : NULL;
    double *rc = pb->dhdt_nodes ? lub_malloc((size_t)(nc + 1) * sizeof *rc) : NULL;
    double *pc = lub_malloc((size_t)(nc + 1) * sizeof *pc);
    for (int i = 0; i <= nc; i++) {
        double sf = (double)i * n / nc; /* fine index of coarse node i */
        int k = (int)sf;
        if (k >= n) k = n - 1;
        double w = sf - k;
        hc[i] = (1.0 - w) * pb->h[k] + w * pb->h[k + 1];
        if (rc) rc[i] = (1.0 - w) * pb->dhdt_nodes[k] + w * pb->dhdt_nodes[k + 1];
        if (hfc && i < nc) hfc[i] = pb->h[2 * i + 1];
    }
    lub_reynolds_problem cp = *pb;
    cp.n = nc;
    cp.h = hc;
    cp.h_face = hfc;
    cp.dhdt_nodes = rc;
    system_t sc;
    system_alloc(&sc, nc);
    int itc = reynolds_lcp(&cp, &sc, pc, tol, max_it);
    system_free(&sc);
    if (itc >= 0) {
        /* a fine node starts cavitated where the interpolated coarse pressure is zero */
        for (int i = 1; i < n; i++) {
            double sc_ = (double)i * nc / n;
            int k = (int)sc_;
            if (k >= nc) k = nc - 1;
            double w = sc_ - k;
            s->active[i] = !((1.0 - w) * pc[k] + w * pc[k + 1] > 0.0);
        }
        it = active_set(s, p, tol, max_it);
        if (it >= 0) it += itc + LCP_QUICK;
    } else {
        it = itc;
    }
    free(hc);
    free(hfc);
    free(rc);
    free(pc);
    return it;
}

static lub_reynolds_status check_input(const lub_reynolds_problem *pb)
{
    if (!pb->h || pb->n < 2 || !isfinite(pb->xa) || !isfinite(pb->xb) || !(pb->xb > pb->xa) ||
        !(pb->mu > 0.0) || !isfinite(pb->mu) || !isfinite(pb->u1) || !isfinite(pb->u2) ||
        !isfinite(pb->dhdt) || pb->tolerance < 0.0 || pb->max_iterations < 0 || (int)pb->bc < 0 ||
        pb->bc > LUB_REYNOLDS_BC_GIVEN_EXIT)
        return LUB_REYNOLDS_BAD_INPUT;
    if (pb->bc == LUB_REYNOLDS_BC_GIVEN_EXIT && !(pb->exit_x > pb->xa && pb->exit_x <= pb->xb))
        return LUB_REYNOLDS_BAD_INPUT;
    for (int i = 0; i <= pb->n; i++) {
        if (!(pb->h[i] > 0.0) || !isfinite(pb->h[i])) return LUB_REYNOLDS_BAD_GAP;
        if (pb->dhdt_nodes && !isfinite(pb->dhdt_nodes[i])) return LUB_REYNOLDS_BAD_INPUT;
        if (i < pb->n && pb->h_face && (!(pb->h_face[i] > 0.0) || !isfinite(pb->h_face[i])))
            return LUB_REYNOLDS_BAD_GAP;
    }
    return LUB_REYNOLDS_OK;
}

/* Peak: largest node, refined by the parabola through it and its neighbours when both lie in
 * the solved film (last = last node whose value belongs to the film). */
static int find_peak(const lub_reynolds_problem *pb, const double *p, int last,
                     lub_reynolds_result *res)
{
    double dx = (pb->xb - pb->xa) / pb->n;
    int imax = 0;
    for (int i = 1; i <= pb->n; i++)
        if (p[i] > p[imax]) imax = i;
    res->p_max = p[imax];
    res->x_max = lub_reynolds_node_x(pb, imax);
    if (imax > 0 && imax < last) {
        double pm = p[imax - 1], p0 = p[imax], pp = p[imax + 1];
        double curv = pp - 2.0 * p0 + pm;
        if (curv < 0.0) {
            double sv = -(pp - pm) / (2.0 * curv);
            if (fabs(sv) <= 1.0) {
                res->p_max = p0 - (pp - pm) * (pp - pm) / (8.0 * curv);
                res->x_max += sv * dx;
            }
        }
    }
    return imax;
}

/* Free exit of the Reynolds condition.  The discrete complementarity solution only knows
 * the exit to the cell: p_{j-1} > 0 = p_j.  At the exit dp/dx = 0, i.e. the flux
 * q = Um h - h^3/(12 mu) dp/dx equals Um h (T-36).  The discrete flux through the face just
 * downstream of the peak is second-order accurate; carried on downstream by the discrete
 * conservation law F_{i+1/2} = F_{i-1/2} - dh/dt_i dx (through the cavitated nodes too), the
 * exit is the zero of phi = Um h_face - F (negative in the film, where phi = h^3/(12 mu) dp/dx)
 * near that cell, linearly interpolated between faces: second order.  Only a zero within a
 * few cells of the discrete exit counts, so that a local pressure minimum inside a full film
 * is not taken for the exit. */
static double reynolds_exit(const lub_reynolds_problem *pb, const double *p, int imax)
{
    int n = pb->n;
    double dx = (pb->xb - pb->xa) / n;
    double um = 0.5 * (pb->u1 + pb->u2);
    if (imax >= n - 1) return pb->xb;
    int j = imax + 1;
    while (j < n && p[j] > 0.0) j++;
    if (j >= n) return pb->xb; /* the film is full up to the outlet */
    int lo = j - 3 > imax + 1 ? j - 3 : imax + 1, hi = j + 2 < n - 1 ? j + 2 : n - 1;
    double hf = face_gap(pb, imax);
    double flux = um * hf - hf * hf * hf / (12.0 * pb->mu) * (p[imax + 1] - p[imax]) / dx;
    double phi_prev = 0.0;
    for (int f = imax; f <= hi; f++) {
        if (f > imax) flux -= node_dhdt(pb, f) * dx;
        double phi = um * face_gap(pb, f) - flux;
        if (f >= lo && phi >= 0.0 && phi_prev < 0.0)
            return pb->xa + (f + 0.5) * dx - dx * phi / (phi - phi_prev);
        phi_prev = phi;
    }
    return lub_reynolds_node_x(pb, j); /* no zero near the discrete exit: the cell's end */
}

lub_reynolds_status lub_reynolds_solve(const lub_reynolds_problem *pb, lub_reynolds_result *res)
{
    lub_reynolds_status st = check_input(pb);
    if (st != LUB_REYNOLDS_OK) return st;

    int n = pb->n;
    double dx = (pb->xb - pb->xa) / n;
    double *p = res->p;
    double tol = pb->tolerance > 0.0 ? pb->tolerance : 1e-12;
    int max_it = pb->max_iterations > 0 ? pb->max_iterations : n + 10;
    system_t s;
    system_alloc(&s, n);
    res->iterations = 0;
    res->n_cavitated = 0;

    int m = n, last = n; /* last: last node belonging to the solved film */
    double cut = 0.0;
    if (pb->bc == LUB_REYNOLDS_BC_GIVEN_EXIT) {
        /* node k with x_k <= exit < x_{k+1}; an exit within round-off of a node is that node,
         * otherwise node k's right neighbour is the exit itself (cut cell) */
        double se = (pb->exit_x - pb->xa) / dx;
        int k = (int)floor(se);
        double frac = se - k;
        if (k >= n) {
            k = n;
            frac = 0.0;
        }
        if (frac < 1e-9) {
            m = last = k;
        } else if (frac > 1.0 - 1e-9) {
            m = last = k + 1;
        } else {
            m = k + 1;
            last = k;
            cut = frac * dx;
        }
    }
    for (int i = 0; i <= n; i++) p[i] = 0.0;

    if (m >= 2) {
        if (pb->bc == LUB_REYNOLDS_BC_REYNOLDS) {
            int it = reynolds_lcp(pb, &s, p, tol, max_it); /* assembles its own levels */
            if (it < 0) {
                system_free(&s);
                return it == -1 ? LUB_REYNOLDS_SINGULAR : LUB_REYNOLDS_NOT_CONVERGED;
            }
            res->iterations = it;
            for (int i = 1; i < m; i++) res->n_cavitated += s.active[i];
        } else {
            assemble(pb, &s, m, cut);
            if (thomas(&s, p) != 0) {
                system_free(&s);
                return LUB_REYNOLDS_SINGULAR;
            }
        }
    }
    system_free(&s);

    int imax = find_peak(pb, p, last, res);

    /* exit of the pressurised film */
    if (pb->bc == LUB_REYNOLDS_BC_GIVEN_EXIT) {
        res->x_exit = pb->exit_x;
    } else if (pb->bc == LUB_REYNOLDS_BC_REYNOLDS) {
        res->x_exit = res->p_max > 0.0 ? reynolds_exit(pb, p, imax) : pb->xa; /* no film */
    } else {
        /* first zero crossing of p downstream of the peak (p_n = 0, so there is one),
         * linear interpolation */
        int j = imax < n ? imax + 1 : n;
        while (j < n && p[j] > 0.0) j++;
        double pk = p[j - 1], pj = p[j];
        double frac = pk > pj ? pk / (pk - pj) : 1.0;
        res->x_exit = lub_reynolds_node_x(pb, j - 1) + frac * dx;
    }

    if (pb->bc == LUB_REYNOLDS_BC_HALF_SOMMERFELD)
        for (int i = 0; i <= n; i++)
            if (p[i] < 0.0) p[i] = 0.0;

    /* load W = integral of p dx, trapezoid rule on the grid */
    double w = 0.0;
    for (int i = 0; i < n; i++) w += 0.5 * (p[i] + p[i + 1]);
    res->load = w * dx;
    return LUB_REYNOLDS_OK;
}

int lub_reynolds_inflections(int n, double xa, double xb, const double *p, double *xl, double *xr)
{
    if (n < 2) return -1;
    const double dx = (xb - xa) / n;
    int im = 0;
    for (int i = 1; i <= n; i++)
        if (p[i] > p[im]) im = i;
    if (!(p[im] > 0.0)) return -1;
#define D2(i) (p[(i)-1] - 2.0 * p[(i)] + p[(i) + 1])
#define XN(i) ((i) == n ? xb : xa + (double)(i)*dx)
    int found = 0;
    /* upstream: from the peak towards the inlet */
    *xl = xa;
    for (int i = im - 1; i >= 1; i--) {
        if (!(p[i] > 0.0)) {
            *xl = XN(i);
            break;
        }
        const double di = D2(i);
        if (di > 0.0) {
            const double dn = i + 1 <= n - 1 ? D2(i + 1) : 0.0; /* <= 0 unless i + 1 = im */
            *xl = dn < 0.0 ? XN(i) + dx * di / (di - dn) : XN(i + 1);
            found |= 1;
            break;
        }
    }
    /* downstream: from the peak towards the outlet */
    *xr = xb;
    for (int i = im + 1; i <= n - 1; i++) {
        if (!(p[i] > 0.0)) {
            *xr = XN(i);
            break;
        }
        const double di = D2(i);
        if (di > 0.0) {
            const double dp = i - 1 >= 1 ? D2(i - 1) : 0.0; /* <= 0 unless i - 1 = im */
            *xr = dp < 0.0 ? XN(i - 1) + dx * dp / (dp - di) : XN(i - 1);
            found |= 2;
            break;
        }
    }
#undef D2
#undef XN
    return found;
}
