/* lubkit model collision (see collision.h). */
#include <math.h>
#include <stdio.h>

#include "models/collision/collision.h"
#include "core/error.h"
#include "models/model.h"
#include "parallel/par.h"

lub_collision lub_collision_defaults(void)
{
    return (lub_collision){.distance = 0.8, .restitution = 0.2};
}

/* Collision (methods.md §2 step 7): a fluid particle closer than the collision distance to
 * another particle and approaching it loses the approaching part of the relative normal
 * velocity, with restitution e: half of (1 + e) of it against a fluid particle (equal
 * masses), all of it against a wall or dummy particle (infinite mass).
 *
 * Then the walls' planes (lubkit): a fluid particle closer than d_w = sqrt(dc^2 - l0^2/4) to
 * the plane through a wall patch's particles around it (lub_mps_wall_plane, the plane the
 * through-wall check uses) and still approaching it after the pairs loses all of its
 * approach along the plane's normal, with the same e.  d_w is the distance at which the pair
 * rule stops a particle coming straight at a wall line between two of its particles (l0
 * apart), so on a 2-D wall the plane rule adds to the pairs only for a particle coming in
 * obliquely.  A 3-D wall's particles stand on a square lattice: a particle at the centre of
 * a square is sqrt(2)/2 l0 from its four corners and, coming along the normal, meets them
 * only at 0.37 l0 from the plane and almost edge-on, so the pairs let it through the holes
 * (tutorials/wedge3D at h0/4: a particle of the film crept into a hole of the roller's wall
 * over 0.5 ms and went through at step 536).  The plane closes them.  Only where the wall is
 * a plane within re (planar): at a patch's edge the fitted plane cuts the corner (a box
 * tank's particles stopped there kept the 3-D hydrostatic tank from settling).
 *
 * Each particle's change is computed from the velocities before the collision step, so the
 * result does not depend on the order or the number of threads.  The pairs are those of the
 * lists at r* (lub_collision_apply makes them complete), at the current positions. */
#define PLANE_GATE 1.2  /* l0: a fluid particle this close to a wall particle is tested */
#define PLANE_FLAT 0.25 /* l0: the most a wall particle may stand off the plane */

/* Whether the wall particles of patch `patch` within re of i lie on the plane (cw, n) within
 * PLANE_FLAT l0: not where two faces of a patch meet (a box tank's edge, a roller's end),
 * whose least-squares plane runs across the corner, nor on a wall curved within re (a body of
 * a few l0 in radius). */
static int planar(const lub_mps *m, size_t i, unsigned patch, const double cw[3], const double n[3])
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    double *const x[3] = {P->x[0], P->x[1], P->x[2]};
    const double re2 = m->re * m->re, tol = PLANE_FLAT * m->l0;
    for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
        const size_t j = nb->j[q];
        if (P->kind[j] != LUB_WALL || P->patch[j] != patch) continue;
        double v[3];
        if (!(lub_neighbours_r(nb, x, i, j, v) < re2)) continue;
        const double t = (v[0] - cw[0]) * n[0] + (v[1] - cw[1]) * n[1] + (v[2] - cw[2]) * n[2];
        if (fabs(t) > tol) return 0;
    }
    return 1;
}
#define PLANE_MAXPAT 4 /* the patches tested per particle (a corner: two or three) */
static void collide(const lub_collision *c, lub_mps *m, double dt, size_t *nplane)
{
    lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const size_t n = P->n;
    const int dim = m->dim;
    const double dc = c->distance * m->l0, e = c->restitution;
    const double dw2 = dc * dc - 0.25 * m->l0 * m->l0,
                 gate2 = PLANE_GATE * PLANE_GATE * m->l0 * m->l0;
    const double dw = dw2 > 0 ? sqrt(dw2) : 0.0;
    double *du[3] = {m->grad[0], m->grad[1], m->grad[2]};
    double *x[3] = {P->x[0], P->x[1], P->x[2]};
    size_t planes = 0;
#pragma omp parallel for schedule(static) reduction(+ : planes)
    for (size_t i = 0; i < n; i++) {
        double acc[3] = {0, 0, 0};
        /* a fixed-band particle keeps its given velocity (it still stops the others) */
        if (P->kind[i] == LUB_FLUID && !(m->fixed && m->fixed[i])) {
            unsigned pat[PLANE_MAXPAT];
            size_t wnear[PLANE_MAXPAT];
            double wr2[PLANE_MAXPAT];
            int npat = 0;
            for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                const size_t j = nb->j[q];
                double v[3];
                const double r2 = lub_neighbours_r(nb, x, i, j, v); /* now, not at the build */
                if (dw > 0 && P->kind[j] == LUB_WALL && r2 < gate2) {
                    /* the patches near i, each with its nearest wall particle */
                    int k = 0;
                    while (k < npat && pat[k] != P->patch[j]) k++;
                    if (k == npat && npat < PLANE_MAXPAT)
                        pat[npat] = P->patch[j], wr2[npat++] = INFINITY;
                    if (k < npat && r2 < wr2[k]) wr2[k] = r2, wnear[k] = j;
                }
                if (r2 >= dc * dc || r2 <= 0) continue;
                const double r = sqrt(r2);
                double vn = 0, ev[3] = {0, 0, 0};
                for (int d = 0; d < dim; d++) {
                    ev[d] = v[d] / r;
                    vn += (P->u[d][i] - P->u[d][j]) * ev[d];
                }
                if (vn <= 0) continue; /* separating */
                double f = P->kind[j] == LUB_FLUID ? 0.5 * (1 + e) : (1 + e);
                for (int d = 0; d < dim; d++) acc[d] -= f * vn * ev[d];
            }
            for (int k = 0; k < npat; k++) {
                double cw[3], nw[3];
                if (!lub_mps_wall_plane(m, i, pat[k], cw, nw)) continue;
                /* cw: the wall particles' centroid from i; nw: the normal into the fluid */
                const double s = -(cw[0] * nw[0] + cw[1] * nw[1] + cw[2] * nw[2]);
                if (!(s < dw) || !planar(m, i, pat[k], cw, nw)) continue;
                const size_t w = wnear[k];
                double vn = 0;
                for (int d = 0; d < dim; d++) vn += (P->u[d][i] + acc[d] - P->u[d][w]) * nw[d];
                if (vn >= 0) continue; /* leaving the wall, or along it */
                for (int d = 0; d < dim; d++) acc[d] -= (1 + e) * vn * nw[d];
                planes++;
            }
        }
        for (int d = 0; d < 3; d++) du[d][i] = acc[d];
    }
    for (int d = 0; d < dim; d++)
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) {
            P->u[d][i] += du[d][i];
            P->x[d][i] += du[d][i] * dt;
        }
    if (nplane) *nplane = planes;
}

void lub_collision_apply(const lub_collision *c, lub_mps *m, double dt)
{
    /* the lists of r* hold every pair now closer than the collision distance while no
     * particle moved (r* to now: the correction) more than half their difference */
    lub_particles *P = m->P;
    lub_timer_start(&m->tm, LUB_T_NEIGHBOUR);
    double *x[3] = {P->x[0], P->x[1], P->x[2]};
    const double lim = 0.5 * (m->re - c->distance * m->l0);
    const int rebuild = lub_neighbours_moved(&m->nb, x, lim) != 0;
    lub_timer_stop(&m->tm, LUB_T_NEIGHBOUR);
    if (rebuild) lub_mps_relist(m);
    lub_timer_start(&m->tm, LUB_T_OTHER);
    size_t planes = 0;
    collide(c, m, dt, &planes);
    m->st.nwallplane += planes;
    lub_timer_stop(&m->tm, LUB_T_OTHER);
}

static void attached(void *ctx, lub_mps *m, double dt)
{
    lub_collision_apply(ctx, m, dt);
}

void lub_collision_attach(lub_mps *m, const lub_collision *c)
{
    m->hooks = (lub_mps_hooks){.ctx = (void *)c, .after_correction = attached};
}

/* ---- the model ----------------------------------------------------------------------- */

static void collision_read(lub_model *m, lub_scene *s)
{
    (void)s;
    lub_node_expect_map(m->entry);
    lub_collision *c = m->state;
    *c = lub_collision_defaults();
    c->distance = lub_dict_real_or(m->entry, "distance", c->distance, (lub_range){0.0, 1.0, 1, 0});
    c->restitution = lub_dict_real_or(m->entry, "restitution", c->restitution, LUB_UNIT);
}

static void collision_after_correction(lub_model *m, lub_mps *f, double dt)
{
    lub_collision_apply(m->state, f, dt);
}

static void collision_describe(const lub_model *m, const lub_scene *s, char *buf, size_t size)
{
    (void)s;
    const lub_collision *c = m->state;
    snprintf(buf, size, "collision (distance %g l0, restitution %g)", c->distance, c->restitution);
}

/* How often the walls' planes acted: zero on a 2-D wall of evenly spaced particles as a rule;
 * in 3-D, the particles that would otherwise have gone through a wall's holes. */
static void collision_summary(const lub_model *m, const lub_scene *s, double t)
{
    (void)m;
    (void)t;
    long k = 0;
    for (int l = 0; l < s->nlevels; l++) k += (long)s->level[l]->st.nwallplane;
    k = lub_par_sum_long(k);
    lub_message("collision: %ld particle-steps stopped at a wall's plane (doc/methods.md §2.7)", k);
}

const lub_model_type lub_model_collision = {
    .name = "collision",
    .size = sizeof(lub_collision),
    .read = collision_read,
    .describe = collision_describe,
    .after_correction = collision_after_correction,
    .summary = collision_summary,
};
