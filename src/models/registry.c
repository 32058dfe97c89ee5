/* lubkit models: the registry of model types (models/registry.h, models/model.h). */
#include <string.h>

#include "models/model.h"

#define LUB_MODEL(name) extern const lub_model_type lub_model_##name;
#include "models/registry.h"
#undef LUB_MODEL

#define LUB_MODEL(name) &lub_model_##name,
const lub_model_type *const lub_model_types[] = {
#include "models/registry.h"
    NULL};
#undef LUB_MODEL

const lub_model_type *lub_model_type_find(const char *name)
{
    for (int k = 0; lub_model_types[k]; k++)
        if (strcmp(lub_model_types[k]->name, name) == 0) return lub_model_types[k];
    return NULL;
}
