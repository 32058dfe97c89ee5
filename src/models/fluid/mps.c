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
    lub_mps_config_read(c, cs->root);
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
    lub_message("Schemes: gradient %s%s, gamma %g, alpha %g, surface beta %g, viscosity %s; "
                "particles sorted into %s",
                m->c.gradient == LUB_GRADIENT_LSMPS ? "lsmps" : "standard",
                m->c.min_pressure_shift ? " (min-pressure shift)" : "", m->c.gamma, m->c.alpha,
                m->c.beta,
                m->c.viscosity == LUB_VISCOSITY_NONE       ? "none"
                : m->c.viscosity == LUB_VISCOSITY_EXPLICIT ? "explicit"
                                                           : "crankNicolson",
                order);
    lub_message("Solvers: p %s; U %s", ps, vs);
}

static void mps_log(const lub_mps *m, double dt, double pit, char *buf, size_t size)
{
    (void)dt;
    int vit = 0; /* the viscosity iterations: the sum over the velocity components */
    for (int d = 0; d < m->dim; d++) vit += m->st.v[d].iterations;
    snprintf(buf, size, "p %3d it %8.2e (mean %.1f)  U %3d it  surf %-6zu ", m->st.p.iterations,
             m->st.p.residual, pit, vit, m->st.nsurface);
}

const lub_fluid_type lub_fluid_mps = {
    .name = "mps",
    .read = mps_read,
    .step = lub_mps_step,
    .header_level = mps_header_level,
    .header = mps_header,
    .log = mps_log,
};
