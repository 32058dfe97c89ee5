/* lubkit physics models: the names constant/models.yaml may contain, and the readers shared
 * by the programs that only need part of it.
 *
 *     gravity:         { g: [0, -9.81] }
 *     movingWalls:     { lowerWall: { velocity: [1.2, 0] } }
 *     viscosity:       { scheme: crankNicolson }
 *     collision:       { ... }
 *     elasticWall:     { patch: cylinder, E: 1.966e7, ... }
 *     multiResolution: { levels: [...], fineRegion: [...], ... }
 *
 * A scene lists only the models it uses.  A program that reads only some of them calls
 * lub_models_declare() first, so that a misspelt model name is still an error at
 * lub_dict_finish() ("unknown key 'movingWall' (did you mean 'movingWalls'?)").
 */
#ifndef LUB_MODELS_MODELS_H
#define LUB_MODELS_MODELS_H

#include "geometry/geometry.h"
#include "io/dict.h"

/* Mark every model name (models/registry.h) and the fluid's keys as known in the root
 * mapping of models.yaml. */
void lub_models_declare(lub_node *root);

/* The same for the root of a time folder's uniform/state.yaml: the solver's entries (time,
 * step, deltaT) and the models' (each model reads its own). */
void lub_models_declare_state(lub_node *root);

/* movingWalls: { <wallName>: { velocity: [u, v(, w)] } } (models/movingWalls/movingWalls.c).
 * Fills vel[w] (velocity of wall w of g, zero when not listed; 2-D vectors get w = 0) and
 * moving[w] (1 when listed); both sized g->nwalls.  A name that is not a wall of the geometry
 * is fatal with file:line and the list of wall names.  root may be NULL (no models).
 * Returns the number of walls listed. */
int lub_moving_walls_read(lub_node *root, const lub_geometry *g, double (*vel)[3], int *moving);

#endif
