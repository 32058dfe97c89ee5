/* lubkit model movingWalls: walls moving with a given velocity (methods.md §2, step 8).
 *
 *     movingWalls: { lowerWall: { velocity: [1.2, 0] } }     # m/s, per wall of the geometry
 *
 * The wall and dummy particles of a listed patch carry its velocity in every step (mps.h
 * patch_velocity): the viscous step sees it, and they move with it (a multi-resolution run
 * keeps them in place: every moving wall must then be a plane sliding along itself). */
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "models/model.h"
#include "models/models.h"

int lub_moving_walls_read(lub_node *root, const lub_geometry *g, double (*vel)[3], int *moving)
{
    for (int w = 0; w < g->nwalls; w++) {
        vel[w][0] = vel[w][1] = vel[w][2] = 0.0;
        moving[w] = 0;
    }
    lub_node *mw = lub_dict_map_or(root, "movingWalls");
    if (!mw) return 0;
    size_t n = lub_node_size(mw);
    for (size_t i = 0; i < n; i++) {
        const char *name = lub_node_key_at(mw, i);
        lub_node *entry = lub_node_value_at(mw, i);
        int w = lub_geometry_find_wall(g, name);
        if (w < 0) {
            char list[1024] = "";
            size_t len = 0;
            const char *names[256] = {0};
            int nn = g->nwalls < 256 ? g->nwalls : 256;
            for (int k = 0; k < nn; k++) {
                names[k] = g->walls[k].name;
                if (len < sizeof list)
                    len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", k ? ", " : "",
                                            g->walls[k].name);
            }
            const char *near = lub_closest(name, names, (size_t)nn);
            if (near)
                lub_node_error(entry,
                               "movingWalls: '%s' is not a wall of the geometry (did you mean "
                               "'%s'? walls: %s)",
                               name, near, list);
            lub_node_error(entry, "movingWalls: '%s' is not a wall of the geometry (walls: %s)",
                           name, nn ? list : "none");
        }
        lub_node_expect_map(entry);
        double v[3] = {0.0, 0.0, 0.0};
        lub_dict_vec(entry, "velocity", v, 2, 3, LUB_ANY);
        memcpy(vel[w], v, sizeof v);
        moving[w] = 1;
    }
    return (int)n;
}

typedef struct {
    double velocity[LUB_MAX_PATCHES][3]; /* per patch of the particles */
} moving_walls;

static void moving_walls_read(lub_model *m, lub_scene *s)
{
    moving_walls *mw = m->state;
    const lub_particles *P = s->P;
    /* the names are patches of the particle file: present them as walls */
    lub_geometry geo = {0};
    lub_wall walls[LUB_MAX_PATCHES];
    memset(walls, 0, sizeof walls);
    geo.dim = P->dim;
    geo.nwalls = P->npatches;
    geo.walls = walls;
    for (int k = 0; k < P->npatches; k++)
        snprintf(walls[k].name, sizeof walls[k].name, "%s", P->patch_names[k]);
    int moving[LUB_MAX_PATCHES];
    lub_moving_walls_read(lub_dict_root(s->dict), &geo, mw->velocity, moving);
}

static void moving_walls_configure(lub_model *m, lub_scene *s, lub_mps_config *c)
{
    const moving_walls *mw = m->state;
    for (int k = 0; k < s->P->npatches; k++)
        memcpy(c->patch_velocity[k], mw->velocity[k], sizeof mw->velocity[k]);
}

/* "movingWalls lowerWall (1.2, 0) m/s, ...": the walls that move (nothing when all rest) */
static void moving_walls_describe(const lub_model *m, const lub_scene *s, char *buf, size_t size)
{
    const moving_walls *mw = m->state;
    const lub_particles *P = s->P;
    size_t len = 0;
    buf[0] = '\0';
    for (int k = 0; k < P->npatches && len < size; k++) {
        const double *v = mw->velocity[k];
        if (v[0] == 0 && v[1] == 0 && v[2] == 0) continue;
        len += (size_t)snprintf(buf + len, size - len, "%s%s (%g", len ? ", " : "movingWalls ",
                                P->patch_names[k], v[0]);
        for (int d = 1; d < P->dim && len < size; d++)
            len += (size_t)snprintf(buf + len, size - len, ", %g", v[d]);
        if (len < size) len += (size_t)snprintf(buf + len, size - len, ") m/s");
    }
}

const lub_model_type lub_model_movingWalls = {
    .name = "movingWalls",
    .size = sizeof(moving_walls),
    .read = moving_walls_read,
    .configure = moving_walls_configure,
    .describe = moving_walls_describe,
};
