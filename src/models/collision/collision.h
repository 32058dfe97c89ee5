/* lubkit model collision: particles closer than a collision distance stop approaching
 * (methods.md §2 step 7), and so do fluid particles closer than sqrt(d^2 - l0^2/4) to a wall's
 * plane (methods.md (2.7a): a 3-D wall's particles leave holes that the pairs do not close).
 *
 *     collision: { distance: 0.8, restitution: 0.2 }    # distance in l0, in (0, 1]; e in [0, 1]
 *
 * It acts in every level's step after the velocity and position correction (mps.h hooks,
 * after_correction), before the periodic wrap and the checks. */
#ifndef LUB_MODELS_COLLISION_H
#define LUB_MODELS_COLLISION_H

#include "mps/mps.h"

typedef struct {
    double distance;    /* collision distance, in l0 of the level */
    double restitution; /* e */
} lub_collision;

/* The defaults: distance 0.8 l0, restitution 0.2. */
lub_collision lub_collision_defaults(void);

/* The collision step on the solver m after its correction of a step dt: the neighbour lists
 * made complete for the collision distance, then the velocity changes and the positions. */
void lub_collision_apply(const lub_collision *c, lub_mps *m, double dt);

/* For a solver used without a scene (tests, benchmarks): collisions with c (kept, not
 * copied) after every correction.  Replaces m's hooks. */
void lub_collision_attach(lub_mps *m, const lub_collision *c);

#endif
