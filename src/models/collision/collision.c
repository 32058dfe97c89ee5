/* lubkit model collision (see collision.h). */
#include <math.h>
#include <stdio.h>

#include "models/collision/collision.h"
#include "models/model.h"

lub_collision lub_collision_defaults(void)
{
    return (lub_collision){.distance = 0.8, .restitution = 0.2};
}

/* Collision (methods.md §2 step 7): a fluid particle closer than the collision distance to
 * another particle and approaching it loses the approaching part of the relative normal
 * velocity, with restitution e: half of (1 + e) of it against a fluid particle (equal
 * masses), all of it against a wall or dummy particle (infinite mass).  Each particle's
 * change is computed from the velocities before the collision step, so the result does not
 * depend on the order or the number of threads.  The pairs are those of the lists at r*
 * (lub_collision_apply makes them complete), at the current positions. */
static void collide(const lub_collision *c, lub_mps *m, double dt)
{
    lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    const size_t n = P->n;
    const double dc = c->distance * m->l0, e = c->restitution;
    double *du[3] = {m->grad[0], m->grad[1], m->grad[2]};
    double *x[3] = {P->x[0], P->x[1], P->x[2]};
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        double acc[3] = {0, 0, 0};
        /* a fixed-band particle keeps its given velocity (it still stops the others) */
        if (P->kind[i] == LUB_FLUID && !(m->fixed && m->fixed[i])) {
            for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
                const size_t j = nb->j[q];
                double v[3];
                const double r2 = lub_neighbours_r(nb, x, i, j, v); /* now, not at the build */
                if (r2 >= dc * dc || r2 <= 0) continue;
                const double r = sqrt(r2);
                double vn = 0, ev[3] = {0, 0, 0};
                for (int d = 0; d < m->dim; d++) {
                    ev[d] = v[d] / r;
                    vn += (P->u[d][i] - P->u[d][j]) * ev[d];
                }
                if (vn <= 0) continue; /* separating */
                double f = P->kind[j] == LUB_FLUID ? 0.5 * (1 + e) : (1 + e);
                for (int d = 0; d < m->dim; d++) acc[d] -= f * vn * ev[d];
            }
        }
        for (int d = 0; d < 3; d++) du[d][i] = acc[d];
    }
    for (int d = 0; d < m->dim; d++)
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) {
            P->u[d][i] += du[d][i];
            P->x[d][i] += du[d][i] * dt;
        }
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
    collide(c, m, dt);
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

const lub_model_type lub_model_collision = {
    .name = "collision",
    .size = sizeof(lub_collision),
    .read = collision_read,
    .describe = collision_describe,
    .after_correction = collision_after_correction,
};
