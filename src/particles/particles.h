/* lubkit particles: structure-of-arrays storage for 2-D and 3-D particles.
 *
 * Positions and velocities are stored as separate component arrays (x[0..2][i]) so that hot
 * loops stream through memory.  In 2-D the z components exist and are zero.
 * Kinds follow the file format: 0 fluid, 1 wall, 2 dummy (wall ghost layer).
 */
#ifndef LUB_PARTICLES_PARTICLES_H
#define LUB_PARTICLES_PARTICLES_H

#include <stddef.h>
#include <stdint.h>

enum { LUB_FLUID = 0, LUB_WALL = 1, LUB_DUMMY = 2 };

#define LUB_MAX_LEVELS 8
#define LUB_MAX_PATCHES 64
#define LUB_MAX_EXTRA 16
#define LUB_NAME_MAX 64

/* Per-level reference values (written as /level<k> attributes). */
typedef struct {
    double l0, re, n0, lambda0;
} lub_level;

/* An optional extra scalar field (pMean, pnd, surface ...). */
typedef struct {
    char name[LUB_NAME_MAX];
    double *v;
} lub_extra_field;

typedef struct {
    int dim;         /* 2 or 3 */
    size_t n, cap;   /* count and capacity */
    double *x[3];    /* position components */
    double *u[3];    /* velocity components */
    double *p;       /* pressure */
    uint8_t *kind;   /* LUB_FLUID, LUB_WALL, LUB_DUMMY */
    uint16_t *patch; /* index into patch_names (fluid: 0, meaningless) */
    uint8_t *level;  /* resolution level, 0 = finest */
    uint64_t *id;    /* stable id */

    double time;
    long step;
    int nlevels;
    lub_level levels[LUB_MAX_LEVELS];
    int npatches;
    char patch_names[LUB_MAX_PATCHES][LUB_NAME_MAX];
    int nextra;
    lub_extra_field extra[LUB_MAX_EXTRA];
} lub_particles;

void lub_particles_init(lub_particles *P, int dim, size_t cap);
void lub_particles_free(lub_particles *P);
/* Grow capacity to at least cap (never shrinks); extra fields grow too. */
void lub_particles_reserve(lub_particles *P, size_t cap);
/* Append one particle; returns its index.  Velocity and pressure zero, id = index. */
size_t lub_particles_add(lub_particles *P, const double *x, int kind, int patch, int level);
/* Index of a patch name, adding it when absent. */
int lub_particles_patch(lub_particles *P, const char *name);
/* Index of a patch name, or -1. */
int lub_particles_find_patch(const lub_particles *P, const char *name);
/* Add (or find) an extra field, zero-initialised; returns its array. */
double *lub_particles_extra(lub_particles *P, const char *name);
double *lub_particles_find_extra(const lub_particles *P, const char *name);

#endif
