/* lubkit fluid mps: semi-implicit MPS (methods.md §1-2; src/mps/), the default formulation
 * of models/fluid.h.
 *
 *     fluid:     { type: mps }                  # constant/models.yaml
 *     viscosity: { scheme: crankNicolson }      # explicit (T-7) | crankNicolson (T-31); none
 *                                               #   without the entry
 * with constant/transportProperties.yaml (rho, nu), system/schemes.yaml and
 * system/solution.yaml (mps/mps.h, lub_mps_config_read). */
#include <stdio.h>

#include "core/error.h"
#include "models/fluid.h"
#include "models/transport.h"
#include "mps/operators.h"

static void mps_read(lub_mps_config *c, const lub_case *cs, lub_node *models, lub_node *entry)
{
    (void)entry;
    static const char *const visc[] = {"explicit", "crankNicolson", NULL};
    char path[LUB_PATH_MAX];
    lub_mps_config_defaults(c);
    lub_transport_read(lub_case_path(cs, path, "constant/transportProperties.yaml"), &c->rho,
                       &c->nu);
    lub_node *v = lub_dict_map_or(models, "viscosity");
    c->viscosity = v ? 1 + lub_dict_choice(v, "scheme", visc, 1) : LUB_VISCOSITY_NONE;
    /* a film (the implicit viscosity on one resolution, no rigid body) takes the schemes
     * measured best on films (tutorials/README.md, "The defaults"); the rest the thesis'
     * standard MPS: the overlapping particles were measured better with it, the bodies'
     * viscous force sums T-3's pairs (mps_wall_forces), the explicit step has only T-3 */
    if (c->viscosity == LUB_VISCOSITY_CN && !lub_dict_find(models, "multiResolution") &&
        !lub_dict_find(models, "rigidBodies"))
        lub_mps_film_defaults(c);
    lub_mps_config_read(c, cs->root);
    /* the fitted viscous Laplacians are rows of the implicit system (T-31): the explicit
     * step (T-7) sums T-3's pairs, and would ignore the key */
    static const char *const lap[] = {"standard", "lsmps", "lsmpsStabilized"};
    if (c->viscosity == LUB_VISCOSITY_EXPLICIT && LUB_LAPLACIAN_FITTED(c->lap_viscosity))
        lub_node_error(lub_dict_find(v, "scheme"),
                       "viscosity scheme 'explicit' takes the standard Laplacian (T-3, T-7), but "
                       "system/schemes.yaml has laplacian.viscosity '%s', which only the "
                       "implicit step has: set scheme: crankNicolson here, or "
                       "laplacian.viscosity: standard there",
                       lap[c->lap_viscosity]);
}

static void mps_header_level(const lub_mps *m)
{
    lub_message("MPS: l0 %g m, re %g m (%g l0), n0 %.10g, lambda0 %.10g m^2", m->l0, m->re,
                m->c.re_l0, m->n0, m->lambda0);
}

static void mps_header(const lub_mps *m)
{
    char ps[256], vs[256];
    lub_linsolver_describe(&m->psolver, ps, sizeof ps);
    lub_linsolver_describe(&m->vsolver, vs, sizeof vs);
    char order[64];
    if (m->c.reorder_interval == 1)
        snprintf(order, sizeof order, "%s every step", m->c.order_rows ? "rows" : "cells");
    else if (m->c.reorder_interval > 1)
        snprintf(order, sizeof order, "%s every %d steps", m->c.order_rows ? "rows" : "cells",
                 m->c.reorder_interval);
    else
        snprintf(order, sizeof order, "never");
    char pred[64] = "predictor off";
    if (m->c.predictor > 0 && m->c.trend > 0)
        snprintf(pred, sizeof pred, "predictor %g with trend %g", m->c.predictor, m->c.trend);
    else if (m->c.predictor > 0)
        snprintf(pred, sizeof pred, "predictor %g", m->c.predictor);
    lub_message("Schemes: gradient %s%s, gamma %g, alpha %g, %s, surface beta %g, viscosity %s; "
                "particles sorted into %s",
                m->c.gradient == LUB_GRADIENT_LSMPS ? "lsmps" : "standard",
                m->c.min_pressure_shift ? " (min-pressure shift)" : "", m->c.gamma, m->c.alpha,
                pred, m->c.beta,
                m->c.viscosity == LUB_VISCOSITY_NONE       ? "none"
                : m->c.viscosity == LUB_VISCOSITY_EXPLICIT ? "explicit"
                                                           : "crankNicolson",
                order);
    /* the Laplacians and the walls' viscous representation decide a film's accuracy
     * (tutorials/README.md, "The slender wedge and the choice of Laplacian"): said here */
    static const char *const lap[] = {"standard", "lsmps", "lsmpsStabilized"};
    static const char *const dummy[] = {"wall", "mirror", "extrapolate", "flux"};
    const int fv = LUB_LAPLACIAN_FITTED(m->c.lap_viscosity),
              fp = LUB_LAPLACIAN_FITTED(m->c.lap_pressure);
    lub_message("Laplacians: viscosity %s%s, pressure %s%s; dummyVelocity %s (defaults: %s)",
                lap[m->c.lap_viscosity],
                fv && m->c.surf_viscosity ? " (stress-free surface row)" : "",
                lap[m->c.lap_pressure], fp && m->c.surf_pressure ? " (surface point row)" : "",
                dummy[m->c.dummy_velocity],
                m->c.film_defaults ? "a film's: implicit viscosity, one resolution, no rigid body"
                                   : "the thesis' standard MPS");
    lub_message("Solvers: p %s; U %s", ps, vs);
}

static void mps_log(const lub_mps *m, double dt, double pit, char *buf, size_t size)
{
    (void)dt;
    int vit = 0; /* the viscosity iterations: the sum over the velocity components */
    for (int d = 0; d < m->dim; d++) vit += m->st.v[d].iterations;
    snprintf(buf, size,
             "p %3d it %8.2e (mean %.1f)  U %3d it  surf %-6zu PND %+.2f%% (max %+.2f%%) ",
             m->st.p.iterations, m->st.p.residual, pit, vit, m->st.nsurface,
             100 * m->st.compression, 100 * m->st.compression_max);
}

/* The force on the particles of a body's patch (rigidBodies; methods.md §7).
 *
 * Pressure: -p_i a_i on each wall particle i, the pressure the step solved there (T-9, T-10)
 * over the surface a_i it stands for, if a fluid particle lies within re of it: a wall
 * particle without one has a pressure from the other walls' particles alone (two bodies
 * within re of each other in air would push each other apart by their wall particles'
 * number density, before they touch), which is no fluid's.  Not the reaction of the
 * pressure-gradient terms that the wall particles put into their fluid neighbours' gradient (T-13,
 * T-14): those are differences p_j - p_i (or p_j - p_hat_i), blind to the pressure's level, and
 * their sum over a body scales with its perimeter times rho g re, not with its volume (Archimedes
 * would fail); nor do MPS's fluid-fluid gradient terms cancel in pairs (the difference form
 * is symmetric in i, j, not antisymmetric), so the fluid's own momentum is not conserved
 * either and no reaction could make fluid + body conserve it exactly.  The surface integral
 * of the wall pressure is what the pressure field exerts on the body's surface.
 *
 * Viscosity: the reaction of the Laplacian terms (T-3) between each fluid particle i and
 * the patch's wall and dummy particles j, rho l0^d nu (2d / (lambda0 n0)) f_j w_ij (u_j -
 * u*_i), f_j = 2 for a dummy with mirrored velocity (the ghost 2 U - u_i), else 1 (with
 * dummyVelocity extrapolate the ghost's pair term f (U_j - u*_i) + a of lub_mps_ghost): the
 * Laplacian's pair terms are antisymmetric, so the viscous momentum the fluid gains the body
 * loses.  u*_i is the velocity after the viscous step (the implicit half of T-31; the
 * explicit scheme took u^k, a difference of O(dt)), u_j the body particle's velocity of the
 * step; the weights are those of the lists after the step (r*).  With the LSMPS Laplacian
 * the standard coefficients stand in for the fitted ones.
 *
 * The Laplacian form mu lap(u) = div(mu grad u) is the momentum equation of an
 * incompressible fluid, but the traction its pair terms carry through a surface is
 * mu (grad u) n, not mu (grad u + grad u^T) n: a rigid rotation, whose stress is zero, would
 * still pass mu grad(u) n = mu omega x n.  At a wall moving rigidly with the no-slip fluid,
 * (grad u)^T n is the wall's own, -omega x n (the tangential derivatives of u.n are the
 * wall's, and incompressibility gives its normal derivative), so each wetted wall particle
 * gets -mu omega x a_i besides: over a body in the fluid no force, a torque -2 mu A omega in
 * 2-D (area A; -2 mu V omega in 3-D).  Without it the torque on a cylinder turning in a
 * fixed one tends to 5/8 of the closed form as l0 -> 0 (methods.md §7.2).  Only where the
 * fluid touches the wall (the pressure's test, a fluid particle within re): the term
 * corrects the traction the fluid's pair terms carry, and a wall in air carries none.  On
 * every wall particle it braked a roller turning in air by -2 mu A omega (issue 30: the
 * rollingCylinder roller, dry, at 1.5 m/s^2 with nu = 3.2e-3 m^2/s). */
static void mps_wall_forces(const lub_mps *m, int patch, double *const area[3],
                            const double omega[3], double *const f[3])
{
    const lub_particles *P = m->P;
    const size_t n = P->n;
    const int dim = m->dim;
    const lub_neighbours *nb = &m->nb;
    const double mu = m->c.viscosity == LUB_VISCOSITY_NONE ? 0.0 : m->c.rho * m->c.nu;
    for (size_t i = 0; i < n; i++) {
        int wetted = 0; /* a fluid particle within re: else p_i is no fluid's pressure */
        if (P->kind[i] == LUB_WALL && P->patch[i] == patch)
            for (size_t q = nb->start[i]; q < nb->end[i] && !wetted; q++)
                wetted = nb->w[q] > 0 && P->kind[nb->j[q]] == LUB_FLUID;
        for (int d = 0; d < 3; d++) f[d][i] = wetted && d < dim ? -P->p[i] * area[d][i] : 0.0;
        if (!wetted) continue;
        const double a[3] = {area[0][i], area[1][i], area[2][i]};
        const double wxa[3] = {omega[1] * a[2] - omega[2] * a[1], omega[2] * a[0] - omega[0] * a[2],
                               omega[0] * a[1] - omega[1] * a[0]};
        for (int d = 0; d < dim; d++) f[d][i] -= mu * wxa[d];
    }
    if (m->c.viscosity == LUB_VISCOSITY_NONE) return;
    double dv = m->c.rho;
    for (int d = 0; d < dim; d++) dv *= m->l0;
    const double k = dv * lub_mps_laplacian_coefficient(dim, m->lambda0, m->n0, m->c.nu);
    const int xtra = LUB_DUMMY_CONTINUES(m->c.dummy_velocity);
    const int flux = m->c.dummy_velocity == LUB_DUMMY_FLUX;
    for (size_t i = 0; i < n; i++) {
        if (P->kind[i] != LUB_FLUID) continue;
        lub_mps_ghost_planes gp;
        int planes = 0;
        double kap[3] = {0, 0, 0};
        if (m->kap[0])
            for (int d = 0; d < dim; d++) kap[d] = m->kap[d][i];
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            const size_t j = nb->j[q];
            if (nb->w[q] <= 0 || P->kind[j] == LUB_FLUID || P->patch[j] != patch) continue;
            double fg = 1.0, a[3] = {0, 0, 0};
            if (P->kind[j] == LUB_DUMMY || (flux && P->kind[j] == LUB_WALL)) {
                if (xtra && !planes) lub_mps_ghost_planes_of(m, i, &gp), planes = 1;
                fg = lub_mps_ghost(m, i, j, xtra ? &gp : NULL, m->kap[0] ? kap : NULL, a);
            }
            const double c = k * nb->w[q];
            for (int d = 0; d < dim; d++) f[d][j] -= c * (fg * (P->u[d][j] - m->us[d][i]) + a[d]);
        }
    }
}

const lub_fluid_type lub_fluid_mps = {
    .name = "mps",
    .read = mps_read,
    .step = lub_mps_step,
    .header_level = mps_header_level,
    .header = mps_header,
    .log = mps_log,
    .wall_forces = mps_wall_forces,
};
