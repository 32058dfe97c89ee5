/* lubkit physics models: the names of constant/models.yaml (see models.h). */
#include "models/models.h"

#include "models/model.h"

/* The keys of constant/models.yaml that are not models of the registry (models/registry.h):
 * the fluid's (models/fluid.h; viscosity: the formulation mps's). */
static const char *const other_keys[] = {"fluid", "viscosity", NULL};

void lub_models_declare(lub_node *root)
{
    if (!root) return;
    for (int i = 0; lub_model_types[i]; i++) lub_dict_find(root, lub_model_types[i]->name);
    for (int i = 0; other_keys[i]; i++) lub_dict_find(root, other_keys[i]);
}

void lub_models_declare_state(lub_node *root)
{
    if (!root) return;
    lub_dict_find(root, "time");
    lub_dict_find(root, "step");
    lub_dict_find(root, "deltaT");
    lub_dict_find(root, "writeOrigin"); /* the write grid of the case's first run */
    lub_dict_find(root, "writeOriginStep");
    for (int i = 0; lub_model_types[i]; i++) lub_dict_find(root, lub_model_types[i]->name);
    for (int i = 0; other_keys[i]; i++) lub_dict_find(root, other_keys[i]);
}
