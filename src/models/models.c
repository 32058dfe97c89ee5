/* lubkit physics models: names and shared readers (see models.h). */
#include "models/models.h"

#include <stdio.h>
#include <string.h>

const char *const lub_model_names[] = {"gravity",     "movingWalls",     "viscosity", "collision",
                                       "elasticWall", "multiResolution", NULL};

void lub_models_declare(lub_node *root)
{
    if (!root) return;
    for (int i = 0; lub_model_names[i]; i++) lub_dict_find(root, lub_model_names[i]);
}

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
