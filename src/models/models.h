/* lubkit physics models: the names constant/models.yaml may contain, and the readers shared
 * by the programs that only need part of it.
 *
 *     gravity:         { g: [0, -9.81] }
 *     movingWalls:     { lowerWall: { velocity: [1.2, 0] } }
 *                      { plate: { motion: sinusoidal, amplitude: [0, 2e-4], frequency: 1 } }
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

#include <stddef.h>

#include "geometry/geometry.h"
#include "io/dict.h"

/* Mark every model name (models/registry.h) and the fluid's keys as known in the root
 * mapping of models.yaml. */
void lub_models_declare(lub_node *root);

/* The same for the root of a time folder's uniform/state.yaml: the solver's entries (time,
 * step, deltaT) and the models' (each model reads its own). */
void lub_models_declare_state(lub_node *root);

/* A wall's motion (movingWalls, models/movingWalls/movingWalls.c): a rigid translation
 * d(t) from where particleGen put the wall (t = 0), d(0) = 0, and its velocity d'(t).
 *
 *     motion: constant,   velocity: [u, v]               d = V t (the default)
 *     motion: sinusoidal, amplitude: [ax, ay], frequency: f, phase: phi (rad, default 0)
 *                         d = A (sin(2 pi f t + phi) - sin(phi)),  d' = 2 pi f A cos(...)
 *     motion: table,      table: [[t, dx, dy], ...]     (times increasing)
 *                         d = D(t) - D(0), D linear between the rows, held beyond the
 *                         first and last; d' the slope of the row interval holding t (the
 *                         later one at a row, 0 beyond the ends) */
enum { LUB_MOTION_CONSTANT, LUB_MOTION_SINUSOIDAL, LUB_MOTION_TABLE };
extern const char *const lub_motion_names[]; /* constant, sinusoidal, table */

typedef struct {
    int kind;            /* LUB_MOTION_* */
    double velocity[3];  /* constant */
    double amplitude[3]; /* sinusoidal [m] */
    double frequency;    /* sinusoidal [Hz] (> 0) */
    double phase;        /* sinusoidal [rad] */
    int nrows;           /* table */
    double *time;        /* table: nrows times */
    double (*disp)[3];   /* table: nrows displacements D */
    double d0[3];        /* table: D(0) */
} lub_wall_motion;

/* The displacement d(t) and the velocity d'(t) of a motion (3 components each). */
void lub_wall_motion_displacement(const lub_wall_motion *m, double t, double d[3]);
void lub_wall_motion_velocity(const lub_wall_motion *m, double t, double v[3]);
/* The largest speed |d'| over [t0, t1] and a velocity that has it (v, may be NULL). */
double lub_wall_motion_max_speed(const lub_wall_motion *m, double t0, double t1, double v[3]);
/* 1 when the motion is not constant (the wall's particles are placed at x0 + d(t)). */
int lub_wall_motion_is_history(const lub_wall_motion *m);
/* "sinusoidal, amplitude (0, 0.0002) m, 1 Hz, phase 0 rad" (dim components). */
void lub_wall_motion_describe(const lub_wall_motion *m, int dim, char *buf, size_t size);
/* The times in (t0, t1) at which d' changes sign or jumps in some component (the turning
 * points of a sinusoid, a table's rows), at most max of them, increasing; returns the count. */
int lub_wall_motion_breaks(const lub_wall_motion *m, double t0, double t1, double *out, int max);

/* movingWalls: { <wallName>: { velocity: [u, v(, w)] } } or a motion (above)
 * (models/movingWalls/movingWalls.c).  Fills motion[w] (wall w of g: constant zero velocity
 * when not listed; 2-D vectors get w = 0) and moving[w] (1 when listed); both sized
 * g->nwalls.  A name that is not a wall of the geometry, an unknown motion, a missing or
 * misplaced entry (amplitude of a constant motion ...), a frequency <= 0, a table whose
 * times do not increase: fatal with file:line.  root may be NULL (no models).  Returns the
 * number of walls listed; lub_moving_walls_free frees the tables of n motions. */
int lub_moving_walls_read(lub_node *root, const lub_geometry *g, lub_wall_motion *motion,
                          int *moving);
void lub_moving_walls_free(lub_wall_motion *motion, int n);

#endif
