/* lubkit MPS: one semi-implicit MPS step for one resolution level (see mps.h): the steps of
 * the method (methods.md §2).  The models act through lub_mps.hooks (forces, after the
 * correction) and the given particles (lub_mps.fixed, .inside); the walls' checks are
 * mps/walls.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "mps/lsmps.h"
#include "mps/mps.h"
#include "mps/operators.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

const char *const lub_mps_phase_names[] = {
    "neighbourSearch", "viscositySolve", "assembly", "pressureSolve",
    "gradient",        "other",          "output",   NULL};

/* Operator masks: particles take part by kind (particles.h: fluid 0, wall 1, dummy 2). */
#define K_FLUID LUB_MPS_KIND(LUB_FLUID)
#define K_WALL  LUB_MPS_KIND(LUB_WALL)
#define K_DUMMY LUB_MPS_KIND(LUB_DUMMY)

static void *alloc_doubles(size_t n)
{
    return lub_calloc(n ? n : 1, sizeof(double));
}

/* The neighbour lists' skin: lists reaching list_l0 l0 beyond re (a formulation's or a
 * model's wider kernel) have a larger one, the weights still of re (pairs beyond re stored
 * with w = 0). */
static double list_skin(const lub_mps_config *c, double l0)
{
    const double re = c->re_l0 * l0;
    double skin = c->skin;
    if (c->list_l0 * l0 > re * (1 + skin)) skin = c->list_l0 * l0 / re - 1;
    return skin;
}

double lub_mps_list_radius(const lub_mps_config *c, double l0)
{
    return c->re_l0 * l0 * (1.0 + list_skin(c, l0)); /* lub_neighbours' rs */
}

void lub_mps_init(lub_mps *m, lub_particles *P, const lub_mps_config *c, const double lo[3],
                  const double hi[3], const int periodic[3])
{
    memset(m, 0, sizeof *m);
    m->c = *c;
    m->P = P;
    m->dim = P->dim;
    if (P->nlevels > 1)
        lub_bug("lub_mps_init: the particles have %d resolution levels; a solver takes one "
                "(multi-resolution: one solver per level, models/multiResolution/opt.h)",
                P->nlevels);
    m->l0 = P->levels[0].l0;
    if (!(m->l0 > 0)) lub_fatal("particle file has no valid l0 for level 0");
    m->re = c->re_l0 * m->l0;
    m->steps = P->step;
    lub_mps_reference(m->dim, m->l0, m->re, &m->n0, &m->lambda0);
    P->levels[0].re = m->re;
    P->levels[0].n0 = m->n0;
    P->levels[0].lambda0 = m->lambda0;
    for (int d = 0; d < 3; d++) {
        m->lo[d] = lo[d];
        m->hi[d] = hi[d];
        m->periodic[d] = periodic[d];
    }
    lub_neighbours_init(&m->nb, m->dim, m->re, list_skin(c, m->l0), lo, hi, periodic);
    lub_neighbours_set_order(&m->nb, c->order_rows ? m->l0 : 0.0);
    lub_csr_init(&m->A);
    lub_csr_init(&m->A2);
    lub_bicgstab_work_init(&m->bw);
    lub_linsolver_init(&m->psolver, &c->p_solver);
    lub_linsolver_init(&m->vsolver, &c->v_solver);

    /* work arrays for the capacity: particles generated between steps (multi-resolution)
     * need no allocation */
    size_t n = P->cap > P->n ? P->cap : P->n;
    m->cap = n;
    static const char *const gbar_names[3] = {"gradPx", "gradPy", "gradPz"};
    for (int d = 0; d < 3; d++)
        m->gbar[d] = (c->predictor > 0 || LUB_DUMMY_CONTINUES(c->dummy_velocity)) && d < m->dim
                         ? lub_particles_extra(P, gbar_names[d])
                         : NULL;
    static const char *const gtr_names[3] = {"gradPTrendx", "gradPTrendy", "gradPTrendz"};
    for (int d = 0; d < 3; d++)
        m->gtr[d] = m->gbar[d] && c->predictor > 0 && c->trend > 0
                        ? lub_particles_extra(P, gtr_names[d])
                        : NULL;
    m->cav =
        c->clip_negative == LUB_NEGATIVE_CAVITATION ? lub_particles_extra(P, "cavitation") : NULL;
    m->surf = NULL;
    m->surf_fresh = 0;
    if (c->surface_test == LUB_SURFACE_SECTOR && c->exposed_cos < c->cone_cos) {
        m->surf_fresh = lub_particles_find_extra(P, "surface") == NULL;
        m->surf = lub_particles_extra(P, "surface");
    }
    for (int d = 0; d < 3; d++) {
        m->us[d] = alloc_doubles(n);
        m->bv[d] = alloc_doubles(n);
        m->xv[d] = alloc_doubles(n);
        m->grad[d] = alloc_doubles(n);
        m->kap[d] = LUB_DUMMY_CONTINUES(c->dummy_velocity) ? alloc_doubles(n) : NULL;
    }
    m->pnd = alloc_doubles(n);
    m->div = c->source == LUB_SOURCE_MIXED ? alloc_doubles(n) : NULL;
    m->lap = alloc_doubles(n);
    m->b = alloc_doubles(n);
    m->x = alloc_doubles(n);
    m->surface = lub_calloc(n ? n : 1, 1);
    m->anchor = lub_calloc(n ? n : 1, 1);
    m->lapflag = lub_calloc(n ? n : 1, 1);
    if ((c->surf_viscosity && LUB_LAPLACIAN_FITTED(c->lap_viscosity)) ||
        (c->surf_pressure && LUB_LAPLACIAN_FITTED(c->lap_pressure))) {
        for (int d = 0; d < 3; d++) m->bcn[d] = alloc_doubles(n);
        m->bcd = alloc_doubles(n);
        m->bcdiag = alloc_doubles(n);
        m->bcs = lub_calloc(n ? n : 1, 1);
    }
    m->lsmps_g0 = lub_mps_lsmps_reference(m->dim, m->l0, m->re);
    {
        const int h = (int)ceil(m->re / m->l0), hz = m->dim == 3 ? h : 0;
        m->nlattice = 0;
        for (int a = -h; a <= h; a++)
            for (int b = -h; b <= h; b++)
                for (int c3 = -hz; c3 <= hz; c3++) {
                    const double r = m->l0 * sqrt((double)(a * a + b * b + c3 * c3));
                    if (r > 0 && r < m->re) m->nlattice++;
                }
    }
    m->row = lub_calloc(n ? n : 1, sizeof *m->row);
    m->prow = lub_calloc(n ? n : 1, sizeof *m->prow);
    m->scratch = lub_malloc((n ? n : 1) * sizeof(double));
    m->fixed = c->fixed_flags ? lub_calloc(n ? n : 1, 1) : NULL;
    m->inside = c->fixed_flags ? lub_calloc(n ? n : 1, 1) : NULL;
    for (int k = 0; k < LUB_T_COUNT; k++) lub_timers_add(&m->tm, lub_mps_phase_names[k]);
}

void lub_mps_free(lub_mps *m)
{
    if (m->fstate_free) m->fstate_free(m->fstate);
    for (int d = 0; d < 3; d++) free(m->pacc[d]);
    for (int d = 0; d < 3; d++) {
        free(m->us[d]);
        free(m->bv[d]);
        free(m->xv[d]);
        free(m->grad[d]);
        free(m->kap[d]);
    }
    free(m->pnd);
    free(m->div);
    free(m->lap);
    free(m->b);
    free(m->x);
    free(m->surface);
    free(m->anchor);
    free(m->row);
    free(m->prow);
    free(m->scratch);
    free(m->fixed);
    free(m->inside);
    free(m->gidx);
    free(m->colmap);
    free(m->conn);
    lub_neighbours_free(&m->nb);
    lub_csr_free(&m->A);
    lub_csr_free(&m->A2);
    lub_bicgstab_work_free(&m->bw);
    free(m->lapc);
    free(m->lapflag);
    for (int d = 0; d < 3; d++) free(m->bcn[d]);
    free(m->bcd);
    free(m->bcdiag);
    free(m->bcs);
    lub_linsolver_free(&m->psolver);
    lub_linsolver_free(&m->vsolver);
}

/* Sort every per-particle array into cell order (or lattice rows: particleOrder, see
 * neighbours.h, lub_neighbours_order).  In cell order, right after the sort, the neighbour
 * lists ascend in j, and so do the rows of the matrices assembled from them (which then need
 * no sorting, csr.h), and a particle's neighbours lie near it in memory; both fade as the
 * particles move to other cells, so the sort is repeated every step by default
 * (reorderInterval 1: on the thesis wedge 10% faster than lattice rows sorted every 50 steps,
 * the sort included). */
void lub_mps_reorder(lub_mps *m)
{
    lub_particles *P = m->P;
    double *x[3] = {P->x[0], P->x[1], P->x[2]};
    lub_neighbours_order(&m->nb, P->n, x);
    void *arrays[16 + LUB_MAX_EXTRA];
    size_t sizes[16 + LUB_MAX_EXTRA];
    int k = 0;
    for (int d = 0; d < 3; d++) {
        arrays[k] = P->x[d], sizes[k++] = sizeof(double);
        arrays[k] = P->u[d], sizes[k++] = sizeof(double);
    }
    arrays[k] = P->p, sizes[k++] = sizeof(double);
    arrays[k] = P->kind, sizes[k++] = sizeof *P->kind;
    arrays[k] = P->patch, sizes[k++] = sizeof *P->patch;
    arrays[k] = P->level, sizes[k++] = sizeof *P->level;
    arrays[k] = P->id, sizes[k++] = sizeof *P->id;
    for (int e = 0; e < P->nextra; e++) arrays[k] = P->extra[e].v, sizes[k++] = sizeof(double);
    if (m->fixed) arrays[k] = m->fixed, sizes[k++] = sizeof *m->fixed;
    if (m->inside) arrays[k] = m->inside, sizes[k++] = sizeof *m->inside;
    lub_reorder_set(P->n, m->nb.perm, m->scratch, k, arrays, sizes);
}

static void neighbours(lub_mps *m, int rebuild)
{
    lub_particles *P = m->P;
    double *x[3] = {P->x[0], P->x[1], P->x[2]};
    lub_timer_start(&m->tm, LUB_T_NEIGHBOUR);
    if (!rebuild && lub_neighbours_update(&m->nb, x) != 0) rebuild = 1;
    if (rebuild) {
        /* nothing reads a dummy particle's own list (its PND, velocity or pressure is never
         * formed; it enters the others' sums as their neighbour) */
        m->nb.list_kind = P->kind;
        m->nb.list_kinds = K_FLUID | K_WALL;
        lub_neighbours_build(&m->nb, P->n, x);
        m->st.nrebuild++;
    }
    lub_timer_stop(&m->tm, LUB_T_NEIGHBOUR);
}

void lub_mps_relist(lub_mps *m)
{
    neighbours(m, 1);
}

/* One per-particle array from m->cap to cap elements (NULL stays NULL), the new tail zeroed
 * as lub_mps_init's calloc left it. */
/* lub_regrow, an array the configuration does not use (NULL) left out */
static void *regrow(void *a, size_t old, size_t cap, size_t size)
{
    return a ? lub_regrow(a, old, cap, size) : NULL;
}

void lub_mps_resize(lub_mps *m, size_t cap)
{
    if (cap <= m->cap) return;
    if (m->fstate) lub_bug("lub_mps_resize: a formulation's own arrays (not re-sized)");
    const size_t old = m->cap;
    lub_particles *P = m->P;
    lub_particles_reserve(P, cap);
    for (int d = 0; d < 3; d++) {
        m->us[d] = regrow(m->us[d], old, cap, sizeof(double));
        m->bv[d] = regrow(m->bv[d], old, cap, sizeof(double));
        m->xv[d] = regrow(m->xv[d], old, cap, sizeof(double));
        m->grad[d] = regrow(m->grad[d], old, cap, sizeof(double));
        m->kap[d] = regrow(m->kap[d], old, cap, sizeof(double));
        m->pacc[d] = regrow(m->pacc[d], old, cap, sizeof(double));
    }
    m->pnd = regrow(m->pnd, old, cap, sizeof(double));
    m->div = regrow(m->div, old, cap, sizeof(double));
    m->lap = regrow(m->lap, old, cap, sizeof(double));
    m->b = regrow(m->b, old, cap, sizeof(double));
    m->x = regrow(m->x, old, cap, sizeof(double));
    m->surface = regrow(m->surface, old, cap, 1);
    m->anchor = regrow(m->anchor, old, cap, 1);
    m->lapflag = regrow(m->lapflag, old, cap, 1);
    for (int d = 0; d < 3; d++) m->bcn[d] = regrow(m->bcn[d], old, cap, sizeof(double));
    m->bcd = regrow(m->bcd, old, cap, sizeof(double));
    m->bcdiag = regrow(m->bcdiag, old, cap, sizeof(double));
    m->bcs = regrow(m->bcs, old, cap, 1);
    m->row = regrow(m->row, old, cap, sizeof *m->row);
    m->prow = regrow(m->prow, old, cap, sizeof *m->prow);
    m->scratch = regrow(m->scratch, old, cap, sizeof(double));
    m->fixed = regrow(m->fixed, old, cap, 1);
    m->inside = regrow(m->inside, old, cap, 1);
    m->gidx = regrow(m->gidx, old, cap, sizeof(double));
    m->colmap = regrow(m->colmap, old, cap, sizeof *m->colmap);
    m->conn = regrow(m->conn, old, cap, 1);
    /* the solver's fields kept in the particles (their extra fields) moved with them */
    static const char *const gbar_names[3] = {"gradPx", "gradPy", "gradPz"};
    for (int d = 0; d < 3; d++)
        if (m->gbar[d]) m->gbar[d] = lub_particles_find_extra(P, gbar_names[d]);
    static const char *const gtr_names[3] = {"gradPTrendx", "gradPTrendy", "gradPTrendz"};
    for (int d = 0; d < 3; d++)
        if (m->gtr[d]) m->gtr[d] = lub_particles_find_extra(P, gtr_names[d]);
    if (m->cav) m->cav = lub_particles_find_extra(P, "cavitation");
    if (m->surf) m->surf = lub_particles_find_extra(P, "surface");
    m->cap = cap;
}

/* The halo or the migration would overfill the slab (lub_par.grow): the particles and the
 * solver's arrays re-sized once for n and the margin again, between steps (the exchanges
 * come first in a step, before any array of the step is formed), and said. */
static void grow_slab(void *ctx, size_t n, const char *what)
{
    lub_mps *m = ctx;
    const size_t old = m->cap, cap = n + (size_t)ceil(m->par->margin * (double)n);
    lub_mps_resize(m, cap);
    lub_warning("step %ld: the %s brings %zu particles to this rank, beyond its capacity %zu: "
                "the particles and the solver's arrays re-sized to %zu (the slab's count and "
                "the margin %g again; balance in system/decomposeParDict.yaml keeps the slabs "
                "even)",
                m->steps + 1, what, n, old, cap, m->par->margin);
}

void lub_mps_set_parallel(lub_mps *m, lub_par *d)
{
    if (m->fixed) lub_bug("lub_mps_set_parallel: given particles (not parallel)");
    m->par = d;
    d->grow = grow_slab;
    d->grow_ctx = m;
    if (!m->gidx) {
        m->gidx = alloc_doubles(m->cap);
        m->colmap = lub_calloc(m->cap ? m->cap : 1, sizeof *m->colmap);
        m->conn = lub_calloc(m->cap ? m->cap : 1, 1);
    }
}

/* The unknowns' rows, after the caller set m->row[i] >= 0 for every particle that is an
 * unknown (-1 the others): the owned particles' rows numbered 0 .. nrows-1 (prow: their
 * particles), which is returned.  On several ranks (m->par) the halo's unknowns follow as
 * the columns nrows .. *ncols-1 (prow: their particles too), whose global rows (m->colmap)
 * come from their owners (so
 * that a rank takes its neighbour's decision on which particle is an unknown); *nglobal:
 * the rows of all ranks.  Serial: *ncols = *nglobal = nrows. */
static int number_rows(lub_mps *m, int *ncols, int *nglobal)
{
    lub_par *d = m->par;
    const size_t nown = d ? d->nown : m->P->n;
    int nu = 0;
    for (size_t i = 0; i < nown; i++)
        if (m->row[i] >= 0) m->prow[nu] = (int)i, m->row[i] = nu++;
    *ncols = nu;
    *nglobal = nu;
    if (!d) return nu;
    const long off = lub_par_exscan(nu);
    *nglobal = (int)lub_par_sum_long(nu);
    for (size_t i = 0; i < nown; i++) m->gidx[i] = m->row[i] >= 0 ? (double)(off + m->row[i]) : -1;
    lub_par_refresh(d, m->gidx, sizeof *m->gidx);
    for (int r = 0; r < nu; r++) m->colmap[r] = (int)off + r;
    int nc = nu;
    for (size_t i = nown; i < nown + d->nhalo; i++) {
        if (m->gidx[i] >= 0) {
            m->colmap[nc] = (int)m->gidx[i];
            m->prow[nc] = (int)i; /* the halo particle of a column (isolated_groups_ranks) */
            m->row[i] = nc++;
        } else {
            m->row[i] = -1;
        }
    }
    *ncols = nc;
    return nu;
}

/* Pass 1 of the CSR assembly of an MPS matrix over the unknowns prow[0..nrows) of
 * number_rows: row r has the diagonal and one entry per neighbour j with w_ij > 0 that is
 * itself an unknown (one of this rank's rows or a halo column); on several ranks the matrix
 * is distributed (linalg/csr.h). */
static void begin_rows(lub_mps *m, int nrows, int ncols, int nglobal)
{
    lub_csr_begin(&m->A, nrows);
    if (m->par) lub_csr_set_distributed(&m->A, ncols, m->colmap, nglobal);
    const lub_neighbours *nb = &m->nb;
#pragma omp parallel for schedule(static)
    for (int r = 0; r < nrows; r++) {
        size_t i = (size_t)m->prow[r];
        int len = 1;
        for (size_t q = nb->start[i]; q < nb->end[i]; q++)
            if (nb->w[q] > 0 && m->row[nb->j[q]] >= 0) len++;
        lub_csr_set_row_length(&m->A, r, len);
    }
    lub_csr_alloc(&m->A);
}

/* Viscosity and body force -> u* (T-7 explicit, T-31 Crank-Nicolson).  Wall and dummy
 * particles keep their prescribed velocity and act as Dirichlet values, and so do the fluid
 * particles of a multi-resolution fixed band (m->fixed: the thesis' fixed temporary velocity,
 * T-25, T-26, the Dirichlet condition of the implicit viscosity step of §2-2-2 (3)).
 *
 * dummy_velocity: wall particles lie on the wall and carry its velocity U.  Dummy particles
 * lie behind it, where the no-slip profile continued through the wall is 2 U - u (mirror
 * image), not U; giving them U makes the wall partly slip (Poiseuille flow comes out with a
 * slip velocity of a few percent of u_max).  With `dummyVelocity: mirror` (default) a dummy
 * j seen from fluid particle i takes the ghost value 2 U_j - u_i, i.e. the pair term
 * w_ij (u_j - u_i) becomes 2 w_ij (U_j - u_i); `wall` keeps U_j.  The mirror continues the
 * profile about i's own distance from the wall, not j's depth behind it: it is exact for a
 * linear profile only where the two are equal, and leaves a slip, of second order in
 * l0/H but large (plane Poiseuille flow four particles across, on the lattice rows: +8.3% in
 * the flow rate, +2.2% at eight; with the wall's U, of first order: +24%, +11%).  `extrapolate`
 * continues the no-slip profile through the wall (doc/methods.md §2.8, (2.8a)): with the wall's
 * plane around i (lub_mps_wall_plane), i at the distance d_i in front of it, j at the depth d_j
 * behind it, u_g = U_j - (d_j / d_i) (u_i - U_j) + (kappa_t / 2) d_j (d_i + d_j), the linear
 * continuation (Morris, Fox and Zhu's ghost, [MFZ97]) plus the profile's curvature at the wall,
 * which the momentum balance there gives: at a wall moving without acceleration, nu lap u = G/rho -
 * g, kappa = (G/rho - g)/nu with G the smoothed running mean of the pressure gradient at i (the
 * predictor's), its part along the wall (kappa_t).  The ghost is then exact for the quadratic
 * profile of a lubricating film, and so is the Laplacian T-3 on the lattice rows
 * (tests/unit/mps_flow_test.c, test_dummy_velocity). */
/* Pressure gradient of the fluid particles (T-13 or T-15) from P->p at the current
 * positions; returns the number of LSMPS fallbacks. */
static size_t pressure_gradient(lub_mps *m, double *const grad[3])
{
    const lub_particles *P = m->P;
    lub_mps_mask gm = {P->kind, K_FLUID, K_FLUID | K_WALL};
    if (m->c.gradient == LUB_GRADIENT_LSMPS)
        return lub_mps_gradient_lsmps(&m->nb, &gm, m->n0, m->c.min_pressure_shift,
                                      m->c.lsmps_det_min, P->p, grad);
    lub_mps_gradient(&m->nb, &gm, m->n0, m->c.min_pressure_shift, P->p, grad);
    return 0;
}

/* out_i = (f_i + sum_j w_ij f_j / sum_j w_ij) / 2 over the fluid neighbours j of each fluid
 * particle i (out_i = f_i without any): a smoothing that keeps linear fields in a full
 * neighbourhood and damps the particle-scale noise of f by half or more. */
static void smooth_fluid(lub_mps *m, double *const f[3], double *const out[3])
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const int dim = m->dim;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_FLUID) continue;
        double sw = 0, s[3] = {0, 0, 0};
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            const size_t j = nb->j[q];
            const double w = nb->w[q];
            if (w <= 0 || P->kind[j] != LUB_FLUID) continue;
            sw += w;
            for (int d = 0; d < dim; d++) s[d] += w * f[d][j];
        }
        for (int d = 0; d < dim; d++) out[d][i] = sw > 0 ? 0.5 * (f[d][i] + s[d] / sw) : f[d][i];
    }
}

/* ---- the LSMPS Laplacians (laplacian.viscosity / .pressure: lsmps or lsmpsStabilized, kind;
 * mps/lsmps.h) ---------------------------------------------------------------------------
 *
 * Their pair coefficients L_ij for the fluid particles from their fluid and wall neighbours
 * (dummy particles carry neither a velocity of the flow nor a pressure: the wall particles'
 * prescribed values enter the fit as Dirichlet values instead of the dummies' mirror
 * images).  Rows whose moment matrix is ill-conditioned (m->lapflag) keep the standard T-3
 * row.  The nonsymmetric system is solved by BiCGStab, preconditioned by the solver of the
 * standard matrix of the same particles (its AMG, IC(0), Jacobi or CHOLMOD factor), which
 * lies spectrally close to it. */
static int open_side(const lub_mps *m, size_t i, const double c[3], double ccos);

/* |c_i| below this times sum_j w_ij l0: a neighbourhood without a direction (surface_rows) */
#define LUB_SURFACE_ROW_CMIN 1e-3

/* The free surface's rows in the fits (laplacian.freeSurface; methods.md §1, (1.3)).  A fluid
 * particle gets one where it is a surface particle or has one among its fluid neighbours: its
 * neighbourhood is cut by the surface.  The outward normal n_i = -c_i / |c_i|, c_i = sum_j
 * w_ij r_ij over all its neighbours, walls and dummies included (the direction in which the
 * PND falls: away from a wall beside the surface too).  Where that sum has no direction,
 * |c_i| <= LUB_SURFACE_ROW_CMIN sum_j w_ij l0 (a complete neighbourhood: the surface particle
 * it sees is its outermost neighbour, 3 l0 away; one neighbour missing at re's edge gives
 * 0.009 in 3-D, 0.024 in 2-D, a lattice round-off), c_i over the non-surface neighbours,
 * which points away from the surface particles, so that d_i reaches re: no row.  Until
 * 2026-11-28 such a particle's normal was the round-off's direction (a particle 3 l0 inside
 * the roller's side face got one along x on one side of the mid-plane and at 46 degrees to z
 * on the other: tests/cases/wedge3D's mirror symmetry).  (The non-surface sum everywhere
 * was tried: the reduced wedge at h0/8 with E 3.58% against 1.92% with this.)  The
 * distance to the surface d_i = l0/2
 * + max(0, max_{j surface} r_ij . n_i): the surface lies half a spacing beyond the outermost
 * particles (T-12's surface particles), as the particles' volumes end there.  d_i = 0 (no
 * row) elsewhere.  The surface flags: the pressure's (m->surface, fresh, at r*), or for the
 * viscous step at r^k the last step's (the "surface" field, which moves with the particles
 * when they are sorted), and where there is none (first step, or another freeSurface.test)
 * the geometric test of free_surface without its history: PND below beta n0 and an open
 * side of sectorAngle. */
static void surface_rows(lub_mps *m, int for_pressure)
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const size_t n = P->n;
    const int dim = m->dim;
    uint8_t *fs = m->bcs;
    if (for_pressure) {
        memcpy(fs, m->surface, n);
    } else if (m->surf && !m->surf_fresh) {
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) fs[i] = P->kind[i] == LUB_FLUID && m->surf[i] > 0;
    } else {
        /* on several ranks the owned particles' test, their halo copies the owners' flags: a
         * halo particle's own neighbourhood is cut by the halo's edge (its PND falls short
         * there and it would be taken for a surface particle; with sfc's cuts that changed
         * the first step's rows and the answer by 1e-3, tests/cases/parallel) */
        const double lim = m->c.beta * m->n0;
        const size_t nown = m->par ? m->par->nown : n;
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < nown; i++) {
            fs[i] = 0;
            if (P->kind[i] != LUB_FLUID) continue;
            double c[3] = {0, 0, 0}, wsum = 0;
            for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                wsum += nb->w[q];
                for (int d = 0; d < dim; d++) c[d] += nb->w[q] * nb->dx[d][q];
            }
            fs[i] = wsum < lim && open_side(m, i, c, m->c.cone_cos);
        }
        if (m->par) lub_par_refresh(m->par, fs, sizeof *fs);
    }
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        m->bcd[i] = 0.0;
        if (P->kind[i] != LUB_FLUID) continue;
        int cut = fs[i];
        /* c over all the neighbours (ca) and over the non-surface ones (cb) */
        double ca[3] = {0, 0, 0}, cb[3] = {0, 0, 0}, ws = 0;
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            if (nb->w[q] <= 0) continue;
            ws += nb->w[q];
            for (int d = 0; d < dim; d++) ca[d] += nb->w[q] * nb->dx[d][q];
            if (fs[nb->j[q]]) {
                cut = 1;
                continue;
            }
            for (int d = 0; d < dim; d++) cb[d] += nb->w[q] * nb->dx[d][q];
        }
        const double can = sqrt(ca[0] * ca[0] + ca[1] * ca[1] + ca[2] * ca[2]);
        const double *c = can > LUB_SURFACE_ROW_CMIN * ws * m->l0 ? ca : cb;
        const double cn = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        if (!cut || !(cn > 0)) continue;
        double out = 0;
        for (int d = 0; d < 3; d++) m->bcn[d][i] = -c[d] / cn;
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            if (nb->w[q] <= 0 || !fs[nb->j[q]]) continue;
            double rn = 0;
            for (int d = 0; d < dim; d++) rn += nb->dx[d][q] * m->bcn[d][i];
            out = fmax(out, rn);
        }
        m->bcd[i] = 0.5 * m->l0 + out;
    }
}

static void lsmps_coefficients(lub_mps *m, int kind, const lub_lsmps_bc *bc)
{
    const lub_particles *P = m->P;
    if (m->lapc_cap < m->nb.cap_pairs) { /* the lists grew (rare after the first steps) */
        free(m->lapc);
        m->lapc_cap = m->nb.cap_pairs;
        m->lapc = lub_malloc(m->lapc_cap * sizeof *m->lapc);
    }
    lub_mps_mask lm = {P->kind, K_FLUID, K_FLUID | K_WALL};
    if (kind == LUB_LAPLACIAN_STABILIZED) {
        /* (1.2): the blend with T-3 takes care of the surface and of the sign; the rows whose
         * M_i is singular are flagged (the standard row, as below) */
        const lub_lsmps_stabilization o = {
            m->n0,           m->lambda0,       m->lsmps_g0, m->c.stab_strength,
            m->c.stab_onset, m->c.lsmps_rcond, bc};
        m->st.nlapfallback +=
            lub_mps_lsmps_stabilized(&m->nb, &lm, m->dim, m->l0, &o, m->lapc, m->lapflag, m->lap);
        size_t nblend = 0;
#pragma omp parallel for schedule(static) reduction(+ : nblend)
        for (size_t i = 0; i < P->n; i++)
            nblend += P->kind[i] == LUB_FLUID && !m->lapflag[i] && m->lap[i] < 1.0;
        m->st.nlapblend += nblend;
        return;
    }
    lub_mps_lsmps_laplacian(&m->nb, &lm, m->dim, m->l0, m->c.lsmps_rcond, bc, m->lapc, m->lapflag);
    /* near a free surface (PND of all neighbours, dummies included, below beta n0) the fit
     * extrapolates from a one-sided neighbourhood: its second derivatives are poor and the
     * operator can lose the sign of a diffusion (it blew up within 15 steps at the outlet of
     * the reduced wedge).  There, and wherever the diagonal sum_j L_ij is not positive, the
     * standard row (stabilized LSMPS also keeps the conventional scheme at the surface,
     * methods.md §1) */
    const lub_neighbours *nb = &m->nb;
    const double lim = m->c.beta * m->n0;
    size_t nflag = 0;
#pragma omp parallel for schedule(static) reduction(+ : nflag)
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_FLUID) continue;
        if (!m->lapflag[i]) {
            double wsum = 0, asum = 0;
            for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                wsum += nb->w[q];
                if (nb->w[q] > 0 && P->kind[nb->j[q]] != LUB_DUMMY) asum += m->lapc[q];
            }
            /* a row with the surface's condition in its fit is no extrapolation */
            const int bcrow = bc && bc->d[i] > 0;
            if ((wsum < lim && !bcrow) || !(asum > 0)) m->lapflag[i] = 1;
        }
        nflag += m->lapflag[i];
    }
    m->st.nlapfallback += nflag;
}

typedef struct {
    lub_linsolver *s;
    const lub_csr *S;
} surrogate;

/* z = S^-1 r with the set-up of the solver of the standard matrix S */
static void surrogate_apply(void *ctx, const double *r, double *z)
{
    surrogate *g = ctx;
    if (g->s->o.kind == LUB_LINSOLVER_PCG) {
        lub_pcg_precond_apply(&g->s->pcg, g->S, r, z);
    } else {
        lub_solve_result res;
        const double *b[1] = {r};
        double *x[1] = {z};
        lub_linsolver_solve(g->s, g->S, 1, b, x, &res);
    }
}

/* Solve A2 x_k = b_k (k < nrhs) by BiCGStab preconditioned with the solver s set up on the
 * standard matrix A; res[k] per right-hand side; returns the worst status.  With PETSc (and
 * so on several ranks) PETSc's BiCGStab with s's preconditioner (BoomerAMG) of A. */
static lub_solve_status lsmps_solve(lub_mps *m, lub_linsolver *s, int nrhs, double *const *b,
                                    double *const *x, lub_solve_result *res)
{
    lub_solve_result sr;
    lub_solve_status worst = lub_linsolver_setup(s, &m->A, &sr);
    if (worst != LUB_SOLVE_OK) {
        for (int k = 0; k < nrhs; k++) res[k] = sr;
        return worst;
    }
    if (s->o.kind == LUB_LINSOLVER_PETSC)
        return lub_petsc_solve_other(s->petsc, &m->A2, nrhs, (const double *const *)b, x, &s->o.pcg,
                                     res);
    surrogate g = {s, &m->A};
    for (int k = 0; k < nrhs; k++) {
        lub_solve_status st = lub_bicgstab_solve(
            &m->bw, &m->A2, b[k], x[k], surrogate_apply, &g, s->o.pcg.tolerance, s->o.pcg.max_iter,
            s->o.kind == LUB_LINSOLVER_PCG ? s->o.pcg.warm_start : 1, &res[k]);
        if (st != LUB_SOLVE_OK && worst == LUB_SOLVE_OK) worst = st;
    }
    return worst;
}

/* dummyVelocity extrapolate, fluid particle i: the walls around it (gp) and the curvature of
 * the no-slip profile at them, kappa = (G/rho - g)/nu from the smoothed running mean G of the
 * pressure gradient, which the viscous step has just put into m->grad; kept in m->kap for
 * the wall forces (see dummy_velocity) */
static void ghost_setup(lub_mps *m, size_t i, const double *g, lub_mps_ghost_planes *gp,
                        double kap[3])
{
    lub_mps_ghost_planes_of(m, i, gp);
    const double nu_inv = m->c.nu > 0 ? 1.0 / m->c.nu : 0.0;
    for (int d = 0; d < m->dim; d++) {
        kap[d] = (m->grad[d][i] / m->c.rho - g[d]) * nu_inv;
        m->kap[d][i] = kap[d];
    }
}

/* g: the body acceleration of the step, body: whether there is one (lub_mps_step) */
static int viscosity(lub_mps *m, double dt, const double *g, int body, char *msg, size_t msgsize)
{
    lub_particles *P = m->P;
    const size_t n = P->n;
    const int dim = m->dim;
    /* a fixed-band particle (m->fixed) keeps its given velocity: u* = u, a Dirichlet value */
    const uint8_t *fix = m->fixed;
    lub_timer_start(&m->tm, LUB_T_VISCOSITY);
    for (int d = 0; d < 3; d++) memcpy(m->us[d], P->u[d], n * sizeof(double));
    /* pressure predictor: the viscous step feels the running mean of the pressure gradient,
     * smoothed over the fluid neighbours (m->grad is free until the gradient phase) */
    const double rinv = m->c.predictor > 0 ? 1.0 / m->c.rho : 0.0;
    double *const *gold = rinv != 0.0 ? m->grad : NULL;
    if (m->gtr[0]) {
        /* with the trend the forecast G + T (m->bv is free until the implicit step) */
        for (int d = 0; d < m->dim; d++)
#pragma omp parallel for schedule(static)
            for (size_t i = 0; i < n; i++) m->bv[d][i] = m->gbar[d][i] + m->gtr[d][i];
        smooth_fluid(m, m->bv, m->grad);
    } else if (m->gbar[0])
        smooth_fluid(m, m->gbar, m->grad);
    /* dummyVelocity extrapolate: the curvature of the no-slip profile at the wall from the
     * same smoothed running mean G of the pressure gradient, (G/rho - g)/nu (dummy_velocity) */
    const int xtra = LUB_DUMMY_CONTINUES(m->c.dummy_velocity);
    /* flux: the wall particles carry the slip of (2.8b) (lub_mps_ghost) */
    const int flux = m->c.dummy_velocity == LUB_DUMMY_FLUX;
    if (m->c.viscosity == LUB_VISCOSITY_EXPLICIT) {
        /* (T-3, T-7) with the dummy particles' ghost velocity (see dummy_velocity) */
        const double cl = lub_mps_laplacian_coefficient(dim, m->lambda0, m->n0, 1.0), nu = m->c.nu;
        const lub_neighbours *nb = &m->nb;
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) {
            if (P->kind[i] != LUB_FLUID || (fix && fix[i])) continue;
            double acc[3] = {0, 0, 0}, kap[3] = {0, 0, 0}, a[3];
            lub_mps_ghost_planes gp;
            if (xtra) ghost_setup(m, i, g, &gp, kap);
            for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                double w = nb->w[q];
                size_t j = nb->j[q];
                double f = 1.0;
                a[0] = a[1] = a[2] = 0.0;
                if (P->kind[j] == LUB_DUMMY || (flux && P->kind[j] == LUB_WALL))
                    f = lub_mps_ghost(m, i, j, xtra ? &gp : NULL, xtra ? kap : NULL, a);
                for (int d = 0; d < dim; d++) acc[d] += w * (f * (P->u[d][j] - P->u[d][i]) + a[d]);
            }
            for (int d = 0; d < dim; d++)
                m->us[d][i] += dt * (nu * cl * acc[d] + g[d] - (gold ? rinv * gold[d][i] : 0.0));
        }
    } else if (m->c.viscosity == LUB_VISCOSITY_CN) {
        /* (T-31): u*_i - (dt nu/2) <lap u*>_i = u_i + (dt nu/2) <lap u^k>_i + dt g, with the
         * wall, dummy (and fixed-band) velocities known.  Rows: the other fluid particles;
         * symmetric since w_ij is. */
        const double k = lub_mps_laplacian_coefficient(dim, m->lambda0, m->n0, 0.5 * dt * m->c.nu);
        const lub_neighbours *nb = &m->nb;
        for (size_t i = 0; i < n; i++)
            m->row[i] = P->kind[i] == LUB_FLUID && !(fix && fix[i]) ? 0 : -1;
        int ncols, nglobal;
        const int nf = number_rows(m, &ncols, &nglobal);
        begin_rows(m, nf, ncols, nglobal);
#pragma omp parallel for schedule(static)
        for (int r = 0; r < nf; r++) {
            size_t i = (size_t)m->prow[r];
            int *col = lub_csr_row_col(&m->A, r);
            double *val = lub_csr_row_val(&m->A, r);
            double wsum = 0, rhs[3] = {0, 0, 0}, kap[3] = {0, 0, 0}, a[3];
            int e = 0, dg = -1; /* the diagonal in column order (the lists are sorted) */
            lub_mps_ghost_planes gp;
            if (xtra) ghost_setup(m, i, g, &gp, kap);
            for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                double w = nb->w[q];
                if (w <= 0) continue;
                size_t j = nb->j[q];
                /* a dummy's ghost velocity (dummy_velocity): the pair term w (f (U_j - u_i)
                 * + a), f = 2 for the mirror; a enters both halves of (T-31) */
                double f = 1.0;
                a[0] = a[1] = a[2] = 0.0;
                if (P->kind[j] == LUB_DUMMY || (flux && P->kind[j] == LUB_WALL))
                    f = lub_mps_ghost(m, i, j, xtra ? &gp : NULL, xtra ? kap : NULL, a);
                wsum += f * w;
                for (int d = 0; d < dim; d++)
                    rhs[d] += f * w * (P->u[d][j] - P->u[d][i]) + 2.0 * w * a[d];
                if (m->row[j] >= 0) {
                    if (dg < 0 && m->row[j] > r) dg = e++;
                    col[e] = m->row[j];
                    val[e++] = -k * w;
                } else {
                    for (int d = 0; d < dim; d++) rhs[d] += f * w * P->u[d][j];
                }
            }
            if (dg < 0) dg = e;
            col[dg] = r;
            val[dg] = 1.0 + k * wsum;
            for (int d = 0; d < dim; d++) {
                m->bv[d][r] =
                    P->u[d][i] + k * rhs[d] + dt * (g[d] - (gold ? rinv * gold[d][i] : 0.0));
                m->xv[d][r] = P->u[d][i]; /* initial guess */
            }
        }
        lub_csr_finish(&m->A);
        const double *b[3] = {m->bv[0], m->bv[1], m->bv[2]};
        double *x[3] = {m->xv[0], m->xv[1], m->xv[2]};
        lub_solve_status s;
        if (LUB_LAPLACIAN_FITTED(m->c.lap_viscosity)) {
            /* (T-31) with the LSMPS Laplacian: u*_i - h sum_j L_ij (u*_j - u*_i) = u_i +
             * h sum_j L_ij (u_j - u_i) + dt (g - G/rho), h = dt nu / 2, the wall particles'
             * velocities known; the rows of flagged particles keep T-3's (above) */
            lub_lsmps_bc bc = {LUB_LSMPS_BC_NEUMANN,
                               {m->bcn[0], m->bcn[1], m->bcn[2]},
                               m->bcd,
                               m->c.surf_weight,
                               m->re / m->l0,
                               NULL};
            if (m->c.surf_viscosity) surface_rows(m, 0);
            lsmps_coefficients(m, m->c.lap_viscosity, m->c.surf_viscosity ? &bc : NULL);
            const double h = 0.5 * dt * m->c.nu;
            lub_csr_begin(&m->A2, nf);
            if (m->par) lub_csr_set_distributed(&m->A2, m->A.ncols, m->colmap, m->A.nglobal);
            for (int r = 0; r < nf; r++)
                lub_csr_set_row_length(&m->A2, r, lub_csr_row_length(&m->A, r));
            lub_csr_alloc(&m->A2);
#pragma omp parallel for schedule(static)
            for (int r = 0; r < nf; r++) {
                size_t i = (size_t)m->prow[r];
                int *col = lub_csr_row_col(&m->A2, r);
                double *val = lub_csr_row_val(&m->A2, r);
                const int len = lub_csr_row_length(&m->A, r);
                if (m->lapflag[i]) { /* the standard row and right-hand side */
                    memcpy(col, lub_csr_row_col(&m->A, r), (size_t)len * sizeof *col);
                    memcpy(val, lub_csr_row_val(&m->A, r), (size_t)len * sizeof *val);
                    continue;
                }
                double asum = 0, rhs[3] = {0, 0, 0}, kap[3] = {0, 0, 0};
                int e = 0;
                /* flux: a wall particle's Dirichlet value carries the slip of (2.8b), as in
                 * the standard rows above: the fit then holds the parabola plus the slip on
                 * the rows, whose trapezoid sum is the film's flux to O((l0/h)^3) */
                lub_mps_ghost_planes gp;
                if (flux) ghost_setup(m, i, g, &gp, kap);
                for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                    const size_t j = nb->j[q];
                    if (nb->w[q] <= 0) continue;
                    const double a = P->kind[j] == LUB_DUMMY ? 0.0 : m->lapc[q];
                    double uj[3] = {P->u[0][j], P->u[1][j], P->u[2][j]}, s[3];
                    if (flux && P->kind[j] == LUB_WALL) {
                        lub_mps_ghost(m, i, j, &gp, kap, s);
                        for (int d = 0; d < dim; d++) uj[d] += s[d];
                    }
                    asum += a;
                    for (int d = 0; d < dim; d++) rhs[d] += a * (uj[d] - P->u[d][i]);
                    if (m->row[j] >= 0) {
                        col[e] = m->row[j];
                        val[e++] = -h * a;
                    } else {
                        for (int d = 0; d < dim; d++) rhs[d] += a * uj[d];
                    }
                }
                col[e] = r;
                val[e++] = 1.0 + h * asum;
                if (e != len) lub_bug("LSMPS viscosity row %d: %d entries, expected %d", r, e, len);
                for (int d = 0; d < dim; d++)
                    m->bv[d][r] =
                        P->u[d][i] + h * rhs[d] + dt * (g[d] - (gold ? rinv * gold[d][i] : 0.0));
            }
            lub_csr_finish(&m->A2);
            s = lsmps_solve(m, &m->vsolver, dim, m->bv, x, m->st.v);
        } else {
            s = lub_linsolver_solve(&m->vsolver, &m->A, dim, b, x, m->st.v);
        }
        if (s != LUB_SOLVE_OK && !m->c.v_continue) {
            char d[256];
            for (int c = 0; c < dim; c++)
                if (m->st.v[c].status != LUB_SOLVE_OK) {
                    lub_solve_result_describe(&m->st.v[c], d, sizeof d);
                    snprintf(msg, msgsize, "viscosity solve (component %d) failed: %s", c, d);
                    break;
                }
            lub_timer_stop(&m->tm, LUB_T_VISCOSITY);
            return -1;
        }
        for (int d = 0; d < dim; d++)
#pragma omp parallel for schedule(static)
            for (int r = 0; r < nf; r++) m->us[d][m->prow[r]] = m->xv[d][r];
    } else if (body || rinv != 0.0) {
        for (int d = 0; d < dim; d++)
#pragma omp parallel for schedule(static)
            for (size_t i = 0; i < n; i++)
                if (P->kind[i] == LUB_FLUID && !(fix && fix[i]))
                    m->us[d][i] += dt * (g[d] - (gold ? rinv * gold[d][i] : 0.0));
    }
    if (rinv != 0.0)
        /* u* is the velocity the viscous step gives under the last pressure gradient; the
         * pressure equation below works, as usual, on u* without that gradient */
        for (int d = 0; d < dim; d++)
#pragma omp parallel for schedule(static)
            for (size_t i = 0; i < n; i++)
                if (P->kind[i] == LUB_FLUID && !(fix && fix[i]))
                    m->us[d][i] += dt * rinv * gold[d][i];
    /* the halo's u*: its positions r* and the divergence of u* need them */
    if (m->par)
        for (int d = 0; d < dim; d++) lub_par_refresh(m->par, m->us[d], sizeof(double));
    lub_timer_stop(&m->tm, LUB_T_VISCOSITY);
    return 0;
}

/* An open side of particle i: an empty sector (2-D) or cone (3-D) of full opening angle
 * 2 acos(ccos), holding no neighbour within re of any kind, anywhere around i.
 *
 * 2-D exactly: the largest angular gap between consecutive neighbours (sorted by angle) is
 * at least the opening.  3-D by sampling: the cone of half-angle acos(ccos) around one of 27
 * axes (the direction away from the neighbours' weighted centroid c, and the 26 lattice
 * directions) is empty; the 26 directions are within 35.3 degrees of any direction, so an
 * empty cone of half-angle theta always leaves one of half-angle theta - 35.3 degrees around
 * some axis, and the direction away from the centroid finds the open side of a flat or
 * gently curved surface at once. */
static int open_side(const lub_mps *m, size_t i, const double c[3], double ccos)
{
    const lub_neighbours *nb = &m->nb;
    const lub_particles *P = m->P;
    /* a wall particle: the solid behind it (the direction of its dummy neighbours) counts as
     * covered, so that its open side must face the fluid side of the wall: a wall particle
     * above a free surface has one, one under a full film has none, whatever dummies a
     * corner of the wall lacks behind it */
    double sd[3] = {0, 0, 0}, sn = 0;
    if (P->kind[i] == LUB_WALL) {
        for (size_t q = nb->start[i]; q < nb->end[i]; q++)
            if (nb->w[q] > 0 && P->kind[nb->j[q]] == LUB_DUMMY)
                for (int d = 0; d < m->dim; d++) sd[d] += nb->w[q] * nb->dx[d][q];
        sn = sqrt(sd[0] * sd[0] + sd[1] * sd[1] + sd[2] * sd[2]);
    }
    if (m->dim == 2) {
        double ang[160];
        int na = 0;
        if (sn > 0) { /* the solid half-plane, every 15 degrees */
            const double a0 = atan2(sd[1], sd[0]);
            for (int k = -6; k <= 6; k++) ang[na++] = remainder(a0 + k * M_PI / 12, 2 * M_PI);
        }
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            if (nb->w[q] <= 0) continue;
            if (na == (int)(sizeof ang / sizeof *ang)) return 0; /* crowded: not a surface */
            ang[na++] = atan2(nb->dx[1][q], nb->dx[0][q]);
        }
        if (na < 2) return 1;
        for (int k = 1; k < na; k++) { /* insertion sort: a few dozen angles */
            double v = ang[k];
            int l = k - 1;
            while (l >= 0 && ang[l] > v) ang[l + 1] = ang[l], l--;
            ang[l + 1] = v;
        }
        double gap = ang[0] + 2 * M_PI - ang[na - 1];
        for (int k = 1; k < na; k++) gap = fmax(gap, ang[k] - ang[k - 1]);
        return gap >= 2 * acos(ccos);
    }
    for (int a = 0; a < 27; a++) {
        double v[3];
        if (a == 26) {
            v[0] = -c[0], v[1] = -c[1], v[2] = -c[2];
        } else {
            int b = a < 13 ? a : a + 1; /* 0..26 without the centre 13 */
            v[0] = b % 3 - 1, v[1] = (b / 3) % 3 - 1, v[2] = b / 9 - 1;
        }
        double vn = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (vn <= 0) continue;
        /* an axis into the solid half (wall particle): covered */
        if (sn > 0 && v[0] * sd[0] + v[1] * sd[1] + v[2] * sd[2] >= 0) continue;
        int empty = 1;
        for (size_t q = nb->start[i]; q < nb->end[i] && empty; q++) {
            if (nb->w[q] <= 0) continue;
            double dot = 0, r2 = 0;
            for (int d = 0; d < 3; d++) {
                dot += nb->dx[d][q] * v[d];
                r2 += nb->dx[d][q] * nb->dx[d][q];
            }
            if (dot >= ccos * sqrt(r2) * vn) empty = 0;
        }
        if (empty) return 1;
    }
    return 0;
}

/* The compression that holds the pressure (methods.md §2.5, (2.5b)): with the PND source
 * a steady pressure needs a lasting PND excess of about dt^2 lap(p) / (gamma rho), volume
 * that a squeeze film's walls must first squeeze out (its pressure lags by tau = 12 mu dt^2 /
 * (gamma rho h^2)).  The mean and the largest (n* - n0)/n0 over the interior fluid particles
 * (not surface, PND >= beta n0) go to the log line, so that a run shows it. */
static void compression(lub_mps *m)
{
    const lub_particles *P = m->P;
    const size_t n = m->par ? m->par->nown : P->n; /* on several ranks: the owned, summed */
    const double lim = m->c.beta * m->n0;
    double sum = 0, big = -INFINITY;
    size_t k = 0;
#pragma omp parallel for schedule(static) reduction(+ : sum, k) reduction(max : big)
    for (size_t i = 0; i < n; i++) {
        if (P->kind[i] != LUB_FLUID || m->surface[i] || m->pnd[i] < lim) continue;
        double e = (m->pnd[i] - m->n0) / m->n0;
        sum += e;
        k++;
        if (e > big) big = e;
    }
    if (m->par) {
        sum = lub_par_sum(sum);
        k = (size_t)lub_par_sum_long((long)k);
        big = lub_par_max(big);
    }
    m->st.compression = k ? sum / (double)k : 0.0;
    m->st.compression_max = k ? big : 0.0;
}

/* Free surface (T-12): n* < beta n0, refined by a geometric test (freeSurface.test):
 *
 *   sector (default): the particle also has an open side, an empty sector (2-D) or cone
 *     (3-D) of opening sectorAngle around it that holds no particle within re, fluid, wall or
 *     dummy (open_side).  This is the idea of the thesis' virtual-light test (Shibata: light
 *     reaches a surface particle from some direction through its neighbours' shadows).  A
 *     particle inside a full film whose PND dropped (a transient rarefaction, a particle
 *     beside a curved wall, whose neighbours' centroid is off-centre) has neighbours on every
 *     side, fluid or wall, with gaps between them of 20-40 degrees: it is not a surface
 *     particle.  Taken as one (the centroid test did so at a few steps in a hundred in a
 *     lubricating film), its P = 0 in the film's high-pressure zone drops the whole film's
 *     pressure to a third at that step (tests/unit/mps_test.c test_surface_film).  The
 *     sector test is applied after the centroid test, which keeps its cost to the few
 *     particles with a low PND and an off-centre neighbourhood.
 *     The sector's opening tells a surface from a void: a particle on a free surface has an
 *     empty half-plane in front of it (180 degrees, 150-180 in a dip of a rough surface, more
 *     on a convex corner), while a void inside a full film, a hole of a few l0 that the
 *     disordered particles leave for a step (a fluid particle in the peak of
 *     tutorials/convergence/wedgeB at h0/12 saw 85 degrees), and a surface particle in a
 *     concave corner (a meniscus against a wall) leave narrower gaps.  So an empty sector of
 *     exposedAngle (default 150 degrees) makes a surface particle by itself; a narrower one of
 *     at least sectorAngle only where the surface reaches it: the particle, or a neighbour
 *     within re, was a surface particle at the step before (the "surface" field, saved with
 *     the particles).  The surface spreads from outside as the thesis' virtual light does,
 *     and a void that no surface reaches is no free surface: its PND deficit lowers its
 *     pressure and the liquid closes it (negativePressure clip or cavitation keeps that
 *     pressure at zero or above).  A trapped bubble, which was open to the outside when it
 *     closed, keeps its surface.  The first step of a run whose particles carry no "surface"
 *     field (the 0/ of particleGen) takes the geometric test alone.
 *   centroid: the weighted centroid of the neighbours is further than `asymmetry` l0 from
 *     the particle (alone: the test of the earlier builds).
 *   pnd: the PND test alone.
 *
 * In a multi-resolution overlap (m->inside, set by models/multiResolution/opt.c) a particle where
 * the other level's particles fill the neighbourhood is not on a surface, whatever its own PND. */
static void free_surface(lub_mps *m)
{
    lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const size_t n = P->n;
    const double lim = m->c.beta * m->n0, asym = m->c.asymmetry * m->l0;
    const int test = m->c.surface_test;
    const double ccos = m->c.cone_cos;
    double *prev = m->surf;
    const int reach = prev && !m->surf_fresh;
    size_t ns = 0;
#pragma omp parallel for schedule(static) reduction(+ : ns)
    for (size_t i = 0; i < n; i++) {
        uint8_t s = 0;
        if (P->kind[i] != LUB_DUMMY) {
            double c[3] = {0, 0, 0}, wsum = 0, wpres = 0;
            for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                double w = nb->w[q];
                wsum += w;
                if (P->kind[nb->j[q]] != LUB_DUMMY) wpres += w;
                for (int d = 0; d < m->dim; d++) c[d] += w * nb->dx[d][q];
            }
            if (wpres <= 0) {
                s = 1; /* no pressure neighbour: nothing to couple to */
            } else if (m->pnd[i] < lim && !(m->inside && m->inside[i])) {
                double off = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / wsum;
                if (test == LUB_SURFACE_PND)
                    s = 1;
                else
                    s = (asym <= 0 || off > asym);
                if (s && test == LUB_SURFACE_SECTOR) s = (uint8_t)open_side(m, i, c, ccos);
                /* narrower than exposedAngle: a surface particle only where the surface
                 * reaches it (the particle or a neighbour was one at the step before) */
                if (s && reach && !(prev[i] > 0) && !open_side(m, i, c, m->c.exposed_cos)) {
                    s = 0;
                    for (size_t q = nb->start[i]; q < nb->end[i] && !s; q++)
                        if (nb->w[q] > 0 && prev[nb->j[q]] > 0) s = 1;
                }
            }
        }
        m->surface[i] = s;
        ns += s;
    }
    m->st.nsurface = ns;
    if (m->par) { /* the halo's flags are their owners' (the pressure rows' columns) */
        lub_par_refresh(m->par, m->surface, sizeof *m->surface);
        ns = 0;
        for (size_t i = 0; i < m->par->nown; i++) ns += m->surface[i];
        m->st.nsurface = (size_t)lub_par_sum_long((long)ns);
    }
    if (prev) { /* this step's surface, for the next step's */
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) prev[i] = m->surface[i];
    }
    m->surf_fresh = 0;
}

/* Groups of pressure unknowns connected, through the matrix, to no Dirichlet particle (a
 * surface, cavitation-held or given-pressure neighbour within re): particles squeezed together
 * apart from the rest, whose PND is above the surface threshold, so that none of them is a
 * surface particle.  With alpha = 0 their pressure is undetermined (their rows sum to zero:
 * the matrix is singular), and the solve fails.  Such a group is small and its particles have
 * few neighbours, so the search starts only from the rows with fewer than half the lattice's
 * neighbours and no Dirichlet one (m->anchor, from the assembly), and explores at most
 * ISOLATED_MAX rows from each (more: taken as connected, as a large group has a surface of its
 * own).  Marks the particles of each group found as surface particles and returns their
 * number.  Costs one pass over the rows when there is no such candidate (the usual case). */
#define ISOLATED_MAX 256
static size_t isolated_groups(lub_mps *m, int nu)
{
    const lub_particles *P = m->P;
    const lub_csr *A = &m->A;
    /* state of a row: 0 not seen, -1 connected, k > 0 seen by the search from row k - 1;
     * and the search's queue: 2 nu ints within the scratch's n doubles */
    int *state = m->scratch, *queue = state + nu;
    memset(state, 0, (size_t)nu * sizeof *state);
    const int few = m->nlattice / 2;
    size_t count = 0;
    for (int r = 0; r < nu; r++) {
        if (state[r] || m->anchor[r] || A->row_ptr[r + 1] - A->row_ptr[r] - 1 >= few) continue;
        const int mark = r + 1;
        int head = 0, tail = 0, connected = 0;
        state[r] = mark;
        queue[tail++] = r;
        while (head < tail && !connected) {
            const int s = queue[head++];
            if (m->anchor[s] || tail > ISOLATED_MAX) {
                connected = 1;
                break;
            }
            for (int k = A->row_ptr[s]; k < A->row_ptr[s + 1]; k++) {
                const int c = A->col[k];
                if (state[c] == -1) {
                    connected = 1;
                    break;
                }
                if (state[c] != mark) state[c] = mark, queue[tail++] = c;
            }
        }
        for (int t = 0; t < tail; t++) state[queue[t]] = -1;
        if (connected) continue;
        for (int t = 0; t < tail; t++) { /* the whole group, explored: no Dirichlet row */
            const size_t i = (size_t)m->prow[queue[t]];
            if (count == 0) m->st.isolated_id = (unsigned long long)P->id[i];
            m->surface[i] = 1;
            count++;
        }
    }
    return count;
}

/* isolated_groups on several ranks (m->par), exactly: "connected to a Dirichlet particle"
 * spreads from the anchored rows over the matrix's graph, within the rank's rows and across
 * the slab boundaries through the halo's copy of the flag (m->conn, refreshed from its
 * owners), until no rank's halo copy changes: a few rounds, one per slab boundary a path of
 * connection crosses (the flag only ever turns on, so the rounds end).  The rows left
 * unconnected are the groups: marked as surface particles, their number returned (this
 * rank's; the caller sums them).  Unlike the serial search, which explores at most
 * ISOLATED_MAX rows from a few candidates, every group is found, whatever its size and
 * however many ranks it spans; a rank cannot tell a large unconnected group from a
 * connected one without the other ranks' rows. */
static size_t isolated_groups_ranks(lub_mps *m, int nu, int ncols)
{
    const lub_par *d = m->par;
    const lub_csr *A = &m->A;
    const size_t nown = d->nown, n = nown + d->nhalo;
    uint8_t *conn = m->conn;
    int *queue = m->scratch;
    memset(conn, 0, n);
    for (int r = 0; r < nu; r++)
        if (m->anchor[r]) conn[m->prow[r]] = 1;
    for (;;) {
        int head = 0, tail = 0;
        for (int r = 0; r < nu; r++) { /* the seeds: anchored, or next to a connected halo */
            const size_t i = (size_t)m->prow[r];
            for (int k = A->row_ptr[r]; k < A->row_ptr[r + 1] && !conn[i]; k++)
                if (A->col[k] >= nu && conn[m->prow[A->col[k]]]) conn[i] = 1;
            if (conn[i]) queue[tail++] = r;
        }
        while (head < tail) {
            const int s = queue[head++];
            for (int k = A->row_ptr[s]; k < A->row_ptr[s + 1]; k++) {
                const int c = A->col[k];
                if (c < nu && !conn[m->prow[c]]) conn[m->prow[c]] = 1, queue[tail++] = c;
            }
        }
        long before = 0, after = 0;
        for (int c = nu; c < ncols; c++) before += conn[m->prow[c]];
        lub_par_refresh(m->par, conn, 1);
        for (int c = nu; c < ncols; c++) after += conn[m->prow[c]];
        if (lub_par_sum_long(after != before) == 0) break;
    }
    size_t count = 0;
    for (int r = 0; r < nu; r++) {
        const size_t i = (size_t)m->prow[r];
        if (conn[i]) continue;
        if (count == 0) m->st.isolated_id = (unsigned long long)m->P->id[i];
        m->surface[i] = 1;
        count++;
    }
    return count;
}

/* Pressure Poisson equation (T-9, T-10), negated so that the matrix is symmetric positive
 * definite: c sum_j w_ij (P_i - P_j) + alpha P_i = gamma rho / dt^2 (n*_i - n0) / n0,
 * c = 2d / (lambda0 n0), over fluid and wall particles; surface particles are Dirichlet
 * (P = 0), dummy particles carry no pressure.
 *
 * Negative pressure (schemes.yaml negativePressure): `keep`; `clip`, set to 0 after the solve
 * (the thesis); or `cavitation`, the complementarity condition P >= 0, (A P - b)_i >= 0,
 * P_i (A P - b)_i = 0 of a liquid that cannot carry tension, which is what the Reynolds
 * boundary condition (p = dp/dx = 0 at the film's rupture) expresses for a film.  Clipping
 * after the solve is not that: the solve still pulls the pressure near the rupture down
 * towards the negative values it finds past it, and the film's pressure falls to zero before
 * the Reynolds exit.  The condition is met by an active set lagged by one step: a particle
 * whose solved pressure was negative is held at P = 0 (a Dirichlet particle, like a surface
 * particle) from the next step on, and released when its row would give it a positive
 * pressure, b_i + c sum_j w_ij P_j > 0 (the multiplier changes sign).  In a steady flow the
 * set settles to the complementarity solution; each step costs one solve, as with clip.
 * The set is the particle field "cavitation" (saved with the particles: exact restart). */
/* The divergence of u* at r* of every fluid particle into m->div (pressure.source mixed), by
 * the scheme's gradient (T-13 or T-15) of each velocity component over the fluid, wall and
 * dummy neighbours (the walls' particles carry their wall's velocity), without the pressure
 * gradient's minimum shift; m->grad is free until step 7. */
static void divergence(lub_mps *m)
{
    const lub_particles *P = m->P;
    const size_t n = P->n;
    lub_mps_mask vm = {P->kind, K_FLUID, K_FLUID | K_WALL | K_DUMMY};
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) m->div[i] = 0.0;
    for (int d = 0; d < m->dim; d++) {
        if (m->c.gradient == LUB_GRADIENT_LSMPS)
            lub_mps_gradient_lsmps(&m->nb, &vm, m->n0, 0, m->c.lsmps_det_min, m->us[d], m->grad);
        else
            lub_mps_gradient(&m->nb, &vm, m->n0, 0, m->us[d], m->grad);
        const double *gd = m->grad[d];
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++)
            if (P->kind[i] == LUB_FLUID) m->div[i] += gd[i];
    }
}

/* The right-hand side of particle i's row (T-9 negated): the PND term src (n*_i - n0), and
 * with source mixed the projection's -rho/dt div u* (dsrc) besides it in the fluid rows of
 * full PND (n*_i >= dlim).  The same for the standard and the LSMPS rows, and for the
 * cavitation's release test, which asks what the row would give. */
static double row_source(const lub_mps *m, size_t i, double src, double dsrc, double dlim)
{
    double b = src * (m->pnd[i] - m->n0);
    if (dsrc > 0 && m->P->kind[i] == LUB_FLUID && m->pnd[i] >= dlim) b -= dsrc * m->div[i];
    return b;
}

static int pressure(lub_mps *m, double dt, char *msg, size_t msgsize)
{
    lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const size_t n = P->n;
    const double c = lub_mps_laplacian_coefficient(m->dim, m->lambda0, m->n0, 1.0);
    const double src = m->c.gamma * m->c.rho / (dt * dt) / m->n0;
    /* mixed source: the projection's rho/dt div u* (the steady pressure needs no lasting PND
     * excess) besides the PND term, which keeps the particle density in check */
    const double dsrc = m->div ? m->c.rho / dt : 0.0;
    const double dlim = m->c.beta * m->n0; /* a full neighbourhood: away from the surface */
    if (m->div) divergence(m);
    const double alpha = m->c.alpha;
    /* multi-resolution fixed band: the given pressure P->p of a fixed particle is a Dirichlet
     * value (it wins over the free-surface test, whose truncated neighbourhood at the edge of
     * a level's region means nothing); it enters the rows of its neighbours as c w_ij P_j */
    const uint8_t *fix = m->fixed;

    /* groups touching no Dirichlet particle would make the matrix singular
     * (isolated_groups): they are taken as surface particles (p = 0), and the matrix is
     * assembled again */
    int retried = 0;
assemble:
    lub_timer_start(&m->tm, LUB_T_ASSEMBLY);
    size_t nfix = 0;
    for (size_t i = 0; i < n; i++) {
        int unknown = P->kind[i] != LUB_DUMMY && !m->surface[i] && !(m->cav && m->cav[i] > 0);
        if (fix && fix[i] && P->kind[i] != LUB_DUMMY) unknown = 0, nfix++;
        m->row[i] = unknown ? 0 : -1;
    }
    int ncols, nglobal;
    const int nu = number_rows(m, &ncols, &nglobal);
    m->st.nunknowns = (size_t)nglobal;
    if (nglobal > 0 && m->st.nsurface == 0 && nfix == 0 && alpha == 0) {
        lub_timer_stop(&m->tm, LUB_T_ASSEMBLY);
        snprintf(msg, msgsize,
                 "the pressure equation has no Dirichlet particle (no free surface) and "
                 "alpha = 0, so it is singular: set pressure.alpha > 0 in system/schemes.yaml "
                 "for a closed domain");
        return -1;
    }
    begin_rows(m, nu, ncols, nglobal);
#pragma omp parallel for schedule(static)
    for (int r = 0; r < nu; r++) {
        size_t i = (size_t)m->prow[r];
        int *col = lub_csr_row_col(&m->A, r);
        double *val = lub_csr_row_val(&m->A, r);
        double wsum = 0, bfix = 0;
        int e = 0, dg = -1; /* the diagonal in column order (the lists are sorted) */
        uint8_t anchored = 0;
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            double w = nb->w[q];
            size_t j = nb->j[q];
            if (w <= 0 || P->kind[j] == LUB_DUMMY) continue;
            wsum += w;
            if (m->row[j] >= 0) {
                if (dg < 0 && m->row[j] > r) dg = e++;
                col[e] = m->row[j];
                val[e++] = -c * w;
            } else {
                anchored = 1; /* a Dirichlet neighbour */
                if (fix && fix[j]) bfix += w * P->p[j];
            }
        }
        m->anchor[r] = anchored;
        if (dg < 0) dg = e;
        col[dg] = r;
        val[dg] = c * wsum + alpha;
        m->b[r] = row_source(m, i, src, dsrc, dlim);
        if (fix) m->b[r] += c * bfix;
        m->x[r] = P->p[i]; /* warm start from the previous pressure */
    }
    lub_csr_finish(&m->A);
    if (alpha == 0 && !retried) {
        size_t k = m->par ? isolated_groups_ranks(m, nu, ncols) : isolated_groups(m, nu);
        /* every rank assembles again when one found a group (the rows are numbered over all) */
        if (m->par) {
            if (lub_par_first(k > 0) >= 0) {
                /* the first rank's first particle is the one named */
                const int who = lub_par_first(k > 0);
                char idtext[32];
                snprintf(idtext, sizeof idtext, "%llu", m->st.isolated_id);
                lub_par_bcast_text(idtext, sizeof idtext, who);
                m->st.isolated_id = strtoull(idtext, NULL, 10);
                lub_par_refresh(m->par, m->surface, sizeof *m->surface);
            }
            k = (size_t)lub_par_sum_long((long)k);
        }
        if (k > 0) {
            m->st.nisolated = k;
            m->st.nsurface += k;
            retried = 1;
            lub_timer_stop(&m->tm, LUB_T_ASSEMBLY);
            goto assemble;
        }
    }
    const int lsmps = LUB_LAPLACIAN_FITTED(m->c.lap_pressure);
    if (lsmps && nu > 0) {
        /* the LSMPS Laplacian in the fluid rows: sum_j L_ij (P_i - P_j) + alpha P_i = b_i, the
         * Dirichlet neighbours' given pressures moved to b; the wall particles' rows (and the
         * flagged fluid rows) stay those of T-10 above, which A keeps for the preconditioner */
        lub_lsmps_bc bc = {LUB_LSMPS_BC_DIRICHLET,
                           {m->bcn[0], m->bcn[1], m->bcn[2]},
                           m->bcd,
                           m->c.surf_weight,
                           m->re / m->l0,
                           m->bcdiag};
        if (m->c.surf_pressure) surface_rows(m, 1);
        lsmps_coefficients(m, m->c.lap_pressure, m->c.surf_pressure ? &bc : NULL);
        lub_csr_begin(&m->A2, nu);
        if (m->par) lub_csr_set_distributed(&m->A2, m->A.ncols, m->colmap, m->A.nglobal);
        for (int r = 0; r < nu; r++)
            lub_csr_set_row_length(&m->A2, r, lub_csr_row_length(&m->A, r));
        lub_csr_alloc(&m->A2);
#pragma omp parallel for schedule(static)
        for (int r = 0; r < nu; r++) {
            size_t i = (size_t)m->prow[r];
            int *col = lub_csr_row_col(&m->A2, r);
            double *val = lub_csr_row_val(&m->A2, r);
            const int len = lub_csr_row_length(&m->A, r);
            if (P->kind[i] != LUB_FLUID || m->lapflag[i]) {
                memcpy(col, lub_csr_row_col(&m->A, r), (size_t)len * sizeof *col);
                memcpy(val, lub_csr_row_val(&m->A, r), (size_t)len * sizeof *val);
                continue;
            }
            double asum = 0, bfix = 0;
            int e = 0;
            for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                const size_t j = nb->j[q];
                if (nb->w[q] <= 0 || P->kind[j] == LUB_DUMMY) continue;
                const double a = m->lapc[q];
                asum += a;
                if (m->row[j] >= 0) {
                    col[e] = m->row[j];
                    val[e++] = -a;
                } else if (fix && fix[j]) {
                    bfix += a * P->p[j];
                }
            }
            /* the surface point's P = 0 in the fit (1.3): L_ib (0 - P_i) */
            if (m->c.surf_pressure) asum += m->bcdiag[i];
            col[e] = r;
            val[e++] = asum + alpha;
            if (e != len) lub_bug("LSMPS pressure row %d: %d entries, expected %d", r, e, len);
            m->b[r] = row_source(m, i, src, dsrc, dlim) + bfix;
        }
        lub_csr_finish(&m->A2);
    }
    lub_timer_stop(&m->tm, LUB_T_ASSEMBLY);

    lub_timer_start(&m->tm, LUB_T_PSOLVE);
    const double *b = m->b;
    double *x = m->x;
    lub_solve_status s = LUB_SOLVE_OK;
    if (nglobal > 0 && lsmps) {
        double *bb = m->b;
        s = lsmps_solve(m, &m->psolver, 1, &bb, &x, &m->st.p);
    } else if (nglobal > 0) {
        s = lub_linsolver_solve(&m->psolver, &m->A, 1, &b, &x, &m->st.p);
    }
    lub_timer_stop(&m->tm, LUB_T_PSOLVE);
    if (s != LUB_SOLVE_OK && !m->c.p_continue) {
        char d[256];
        lub_solve_result_describe(&m->st.p, d, sizeof d);
        snprintf(msg, msgsize, "pressure solve failed: %s", d);
        if (s == LUB_SOLVE_NOT_POSDEF && m->st.p.column >= 0 && m->st.p.column < nu) {
            size_t i = (size_t)m->prow[m->st.p.column];
            size_t len = strlen(msg);
            snprintf(msg + len, msgsize - len, " (particle id %llu at %g %g)",
                     (unsigned long long)P->id[i], P->x[0][i], P->x[1][i]);
        }
        return -1;
    }
    const int clip = m->c.clip_negative != LUB_NEGATIVE_KEEP;
    double *cav = m->cav;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        if (fix && fix[i] && P->kind[i] != LUB_DUMMY) { /* given: keep it */
            if (cav) cav[i] = 0;
            continue;
        }
        const int r = m->row[i];
        double p = r >= 0 && r < nu ? m->x[r] : 0.0;
        P->p[i] = (clip && p < 0) ? 0.0 : p;
        if (cav && r >= 0) cav[i] = p < 0;
    }
    /* the halo's pressures: the gradient and the cavitation release read them */
    if (m->par) lub_par_refresh(m->par, P->p, sizeof *P->p);
    if (cav) {
        /* release the held particles whose row would now give them a positive pressure */
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) {
            if (!(cav[i] > 0)) continue;
            if (P->kind[i] == LUB_DUMMY || m->surface[i] || (fix && fix[i])) {
                cav[i] = 0;
                continue;
            }
            double f = row_source(m, i, src, dsrc, dlim);
            const int lrow = lsmps && P->kind[i] == LUB_FLUID && !m->lapflag[i];
            for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                size_t j = nb->j[q];
                if (nb->w[q] > 0 && P->kind[j] != LUB_DUMMY)
                    f += (lrow ? m->lapc[q] : c * nb->w[q]) * P->p[j];
            }
            if (f > 0) cav[i] = 0;
        }
    }
    return 0;
}

void lub_mps_particle_forces(lub_mps *m, double dt, double *const us[3])
{
    if (!m->hooks.particle_forces) return;
    const lub_particles *P = m->P;
    if (!m->pacc[0]) /* the first step with the hook: for the capacity, never again */
        for (int d = 0; d < 3; d++) m->pacc[d] = alloc_doubles(m->cap);
    for (int d = 0; d < 3; d++) memset(m->pacc[d], 0, P->n * sizeof(double));
    if (!m->hooks.particle_forces(m->hooks.ctx, m, m->pacc)) return;
    const uint8_t *fix = m->fixed;
    for (int d = 0; d < m->dim; d++)
        for (size_t i = 0; i < P->n; i++)
            if (P->kind[i] == LUB_FLUID && !(fix && fix[i])) us[d][i] += dt * m->pacc[d][i];
}

/* Wrap periodic coordinates into [lo, hi). */
static void wrap(lub_mps *m)
{
    lub_particles *P = m->P;
    for (int d = 0; d < m->dim; d++) {
        if (!m->periodic[d]) continue;
        const double lo = m->lo[d], L = m->hi[d] - m->lo[d];
        double *x = P->x[d];
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < P->n; i++) {
            if (x[i] < lo || x[i] >= lo + L) {
                x[i] = lo + fmod(x[i] - lo, L);
                if (x[i] < lo) x[i] += L;
                if (x[i] >= lo + L) x[i] -= L; /* fmod of a tiny negative */
            }
        }
    }
}

lub_step_status lub_mps_step(lub_mps *m, double dt, long *bad, char *msg, size_t msgsize)
{
    lub_particles *P = m->P;
    const int dim = m->dim;
    *bad = -1;
    msg[0] = '\0';
    memset(&m->st, 0, sizeof m->st);
    lub_par *par = m->par;

    /* 1. neighbours at r^k; the particles sorted every reorder_interval steps */
    /* the reorder schedule follows the global step, so that a restarted run sorts at the
     * same steps as an uninterrupted one (exact restart) */
    /* lists reaching beyond re (list_l0) are complete to their radius only when built: the
     * update keeps the pairs within re */
    int rebuild = !m->built || m->c.list_l0 * m->l0 > m->re;
    m->built = 1;
    lub_timer_start(&m->tm, LUB_T_NEIGHBOUR);
    /* several ranks: the owned particles that left the slab to their owner, then (sorted
     * among themselves) the halo after them; the lists are new every step */
    if (par) {
        if (par->interval > 0 && m->steps % par->interval == 0)
            lub_par_rebalance(par, P, par->imbalance); /* new cuts: the migration moves them */
        lub_par_migrate(par, P);
    }
    if (m->c.reorder_interval > 0 && m->steps % m->c.reorder_interval == 0) {
        lub_mps_reorder(m);
        rebuild = 1;
    }
    if (par) {
        lub_par_halo(par, P);
        rebuild = 1;
    }
    lub_timer_stop(&m->tm, LUB_T_NEIGHBOUR);
    const size_t n = P->n;
    /* walls and dummies move with their patch velocity (unless a model set it: patch_moved) */
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++)
        if (P->kind[i] != LUB_FLUID && !m->c.patch_moved[P->patch[i]])
            for (int d = 0; d < dim; d++) P->u[d][i] = m->c.patch_velocity[P->patch[i]][d];
    neighbours(m, rebuild);

    /* 2. viscosity and body force (the configuration's g and the models': gravity) */
    double g[3] = {m->c.g[0], m->c.g[1], m->c.g[2]};
    int body = m->c.gravity;
    if (m->hooks.forces && m->hooks.forces(m->hooks.ctx, m, dt, g)) body = 1;
    if (viscosity(m, dt, g, body, msg, msgsize)) {
        if (par) P->n = par->nown; /* every rank fails together: the solve is theirs */
        return LUB_STEP_SOLVE_FAILED;
    }
    /* the models' per-particle forces (surface tension), explicit at r^k */
    lub_mps_particle_forces(m, dt, m->us);

    /* 3. temporary positions (T-8); with still_walls only the fluid moves (the walls are at
     * rest or slide along themselves: their particles carry the velocity in place), and the
     * walls a model moves (patch_moved: elasticWall, vertically) */
    lub_timer_start(&m->tm, LUB_T_OTHER);
    for (int d = 0; d < dim; d++) {
        double *x = P->x[d];
        const double *us = m->us[d];
        if (m->c.still_walls) {
            const uint8_t *kind = P->kind;
            const uint16_t *patch = P->patch;
            const int *moved = m->c.patch_moved;
#pragma omp parallel for schedule(static)
            for (size_t i = 0; i < n; i++)
                if (kind[i] == LUB_FLUID || moved[patch[i]]) x[i] += us[i] * dt;
        } else {
#pragma omp parallel for schedule(static)
            for (size_t i = 0; i < n; i++) x[i] += us[i] * dt;
        }
    }
    lub_timer_stop(&m->tm, LUB_T_OTHER);
    neighbours(m, 0);

    /* 4. PND at r* (T-11), 5. free surface */
    lub_timer_start(&m->tm, LUB_T_ASSEMBLY);
    lub_mps_mask pm = {P->kind, K_FLUID | K_WALL, K_FLUID | K_WALL | K_DUMMY};
    lub_mps_pnd(&m->nb, &pm, m->pnd);
    free_surface(m);
    compression(m);
    lub_timer_stop(&m->tm, LUB_T_ASSEMBLY);

    /* 6. pressure */
    if (pressure(m, dt, msg, msgsize)) {
        if (par) P->n = par->nown;
        return LUB_STEP_SOLVE_FAILED;
    }

    /* 7. gradient, 8. correction (T-16, T-17); a fixed-band particle keeps u* (given) */
    lub_timer_start(&m->tm, LUB_T_GRADIENT);
    m->st.nfallback = pressure_gradient(m, m->grad);
    const double f = dt / m->c.rho;
    const uint8_t *fix = m->fixed;
    for (int d = 0; d < dim; d++) {
        double *u = P->u[d], *x = P->x[d];
        const double *us = m->us[d], *gr = m->grad[d];
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) {
            if (P->kind[i] != LUB_FLUID || (fix && fix[i])) continue;
            u[i] = us[i] - f * gr[i];
            x[i] += (u[i] - us[i]) * dt;
        }
    }
    if (m->gbar[0]) {
        /* the running mean (dummyVelocity extrapolate without the predictor: weight 0.1) */
        const double a = m->c.predictor > 0 ? m->c.predictor : 0.1, b = m->c.trend;
        for (int d = 0; d < dim; d++) {
            double *gb = m->gbar[d], *tr = m->gtr[d];
            const double *gr = m->grad[d];
            /* without the trend (tr NULL) T stays 0: the plain mean, to the bit */
#pragma omp parallel for schedule(static)
            for (size_t i = 0; i < n; i++)
                if (P->kind[i] == LUB_FLUID) {
                    double t0 = 0.0;
                    lub_mps_predictor_update(gb + i, tr ? tr + i : &t0, gr[i], a, tr ? b : 0.0);
                }
        }
    }
    lub_timer_stop(&m->tm, LUB_T_GRADIENT);

    /* 9. the models' corrections (collision), periodic wrap, checks; on several ranks, of
     * the owned particles (the halo, whose sums missed its far neighbours, is dropped) */
    if (m->hooks.after_correction) {
        /* on several ranks the corrections (collision: the pairs within the collision
         * distance) read the halo's velocities and positions after the correction: their
         * owners' (the halo's own correction summed gradients that missed the neighbours
         * beyond the halo, and in another order) */
        if (par)
            for (int d = 0; d < dim; d++) {
                lub_par_refresh(par, P->u[d], sizeof(double));
                lub_par_refresh(par, P->x[d], sizeof(double));
            }
        m->hooks.after_correction(m->hooks.ctx, m, dt);
    }
    lub_timer_start(&m->tm, LUB_T_OTHER);
    if (par) P->n = par->nown;
    wrap(m);
    lub_step_status s = lub_mps_check(m, dt, bad, msg, msgsize);
    if (par) { /* every rank stops with the first failing rank's status and message */
        const int who = lub_par_first(s != LUB_STEP_OK);
        if (who >= 0) {
            char text[1024];
            snprintf(text, sizeof text, "%d %s", (int)s, msg);
            lub_par_bcast_text(text, sizeof text, who);
            char *rest = NULL;
            s = (lub_step_status)strtol(text, &rest, 10);
            snprintf(msg, msgsize, "%s", rest && *rest == ' ' ? rest + 1 : text);
            if (who != par->rank) *bad = -1;
        }
    }
    m->st.umax = lub_mps_max_speed(m);
    lub_timer_stop(&m->tm, LUB_T_OTHER);
    m->iterations[0] += m->st.p.iterations;
    for (int d = 0; d < dim; d++) m->iterations[1] += m->st.v[d].iterations;
    m->steps++;
    return s;
}
