/* The models constant/models.yaml may list: one line per model, its folder src/models/<name>/
 * defining `const lub_model_type lub_model_<name>` (models/model.h).  The order is the order
 * in which the models of a scene act at each point of the step and are listed in the log.
 * Then the fluid's formulations (`fluid: { type: <name> }`, models/fluid.h), the default
 * first: src/models/fluid/<name>.c defining `const lub_fluid_type lub_fluid_<name>`.
 * Included by models/registry.c with LUB_MODEL and LUB_FLUID defined (no include guard). */
LUB_MODEL(gravity)
LUB_MODEL(movingWalls)
LUB_MODEL(collision)
LUB_MODEL(elasticWall)
LUB_MODEL(multiResolution)
LUB_MODEL(wallHeating)
LUB_MODEL(rigidBodies)
LUB_MODEL(surfaceTension)
LUB_FLUID(mps)
LUB_FLUID(mph)
