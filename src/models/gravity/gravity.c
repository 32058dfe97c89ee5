/* lubkit model gravity: a uniform body acceleration (methods.md §2, the g of T-7 and T-31).
 *
 *     gravity: { g: [0, -9.81] }      # m/s^2, one component per dimension
 *
 * It acts in step 2 of every level's step (forces): the viscous step adds dt g to u*. */
#include <stdio.h>

#include "models/model.h"

typedef struct {
    double g[3];
    int dim;
} gravity;

static void gravity_read(lub_model *m, lub_scene *s)
{
    lub_node_expect_map(m->entry);
    gravity *g = m->state;
    g->dim = s->P->dim;
    lub_dict_vec(m->entry, "g", g->g, g->dim, g->dim, LUB_ANY);
}

static int gravity_forces(lub_model *m, const lub_mps *f, double dt, double acc[3])
{
    (void)f, (void)dt;
    const gravity *g = m->state;
    for (int d = 0; d < 3; d++) acc[d] += g->g[d];
    return 1;
}

static void gravity_describe(const lub_model *m, const lub_scene *s, char *buf, size_t size)
{
    (void)s;
    const gravity *g = m->state;
    size_t len = (size_t)snprintf(buf, size, "gravity (%g", g->g[0]);
    for (int d = 1; d < g->dim && len < size; d++)
        len += (size_t)snprintf(buf + len, size - len, ", %g", g->g[d]);
    if (len < size) snprintf(buf + len, size - len, ") m/s^2");
}

const lub_model_type lub_model_gravity = {
    .name = "gravity",
    .size = sizeof(gravity),
    .read = gravity_read,
    .describe = gravity_describe,
    .forces = gravity_forces,
};
