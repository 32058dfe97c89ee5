/* lubkit models: the registry of model types (models/registry.h, models/model.h). */

#include "core/error.h"
#include "models/fluid.h"
#include "models/model.h"

#define LUB_MODEL(name) extern const lub_model_type lub_model_##name;
#define LUB_FLUID(name) extern const lub_fluid_type lub_fluid_##name;
#include "models/registry.h"
#undef LUB_MODEL
#undef LUB_FLUID

#define LUB_MODEL(name) &lub_model_##name,
#define LUB_FLUID(name)
const lub_model_type *const lub_model_types[] = {
#include "models/registry.h"
    NULL};
#undef LUB_MODEL
#undef LUB_FLUID

#define LUB_MODEL(name)
#define LUB_FLUID(name) &lub_fluid_##name,
const lub_fluid_type *const lub_fluid_types[] = {
#include "models/registry.h"
    NULL};
#undef LUB_MODEL
#undef LUB_FLUID

const lub_fluid_type *lub_fluid_type_read(lub_node *models)
{
    const char *names[16];
    int n = 0;
    for (; lub_fluid_types[n] && n < 15; n++) names[n] = lub_fluid_types[n]->name;
    names[n] = NULL;
    lub_node *entry = lub_dict_map_or(models, "fluid");
    return lub_fluid_types[lub_dict_choice(entry, "type", names, 0)];
}
