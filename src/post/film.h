/* lubkit post-processing: the oil film's shape from the particles (probe film).
 *
 * Particles are sorted into bins of x (2-D; in 3-D the bins take every z).  In each bin:
 *
 *   surface  y of the highest fluid particle: the free surface.  MPS imposes p = 0 on the
 *            surface particles themselves (thesis 2), so the surface lies at their centres,
 *            and a layer generated with thickness T on a wall (particleGen: wall particles on
 *            the wall surface, fluid rows l0 .. T above it) has its surface at exactly T;
 *   bottom   the lower boundary of the film: the height of the highest wall particle (kind
 *            wall, not dummy: wall particles lie on the wall surface) below the lowest fluid
 *            particle, when it is closer than 2 l0 to it (the film rests on the wall); else
 *            the lowest fluid particle (a free lower surface);
 *   contact  1 when the lowest wall particle above the highest fluid particle is closer than
 *            2 l0 to it: the film fills the gap up to an upper wall (a free surface has at
 *            least one empty lattice row, 2 l0 between particle centres, below a wall);
 *   h        the film thickness: top - bottom, top being the upper wall (its lowest wall
 *            particle in the bin) where contact = 1 and the surface elsewhere, so that under
 *            the cylinder of the wedge h is the gap h(x) of the Reynolds reference;
 *   n        the fluid particles in the bin.
 *
 * l0 is the spacing of the level of the particle concerned (multi-resolution).  Bins with no
 * fluid particle have n = 0 and no values.
 *
 * The inlet meniscus is where the free surface meets the upper wall: going downstream (+x
 * when the mean fluid x-velocity is >= 0, else -x), the edge of the first bin in contact;
 * the outlet meniscus is the downstream edge of the last bin of that contact run.  Their
 * resolution is the bin width, and l0/slope where the wall's slope is small: particle rows
 * are l0 apart, so a free surface less than 2 l0 below the wall is as full as the lattice
 * allows (in the thesis wedge, l0 = 5 um, the contact starts where the cylinder is 2 l0
 * above the 80 um layer, 0.2 mm upstream of where the continuous surface would meet it).
 */
#ifndef LUB_POST_FILM_H
#define LUB_POST_FILM_H

#include "particles/particles.h"
#include "post/sample.h"

/* Contact distance in l0 (see above). */
#define LUB_FILM_CONTACT 2.0

typedef struct {
    lub_bins bins;
    /* per bin, from the last lub_film_sample */
    double *ytop, *ybot;             /* highest and lowest fluid particle */
    double *l0top, *l0bot;           /* l0 of their levels */
    double *wall_above, *wall_below; /* nearest wall particle above ytop / below ybot */
    long *n;                         /* fluid particles */
    double mean_u;                   /* mean x-velocity of the fluid */
} lub_film;

/* One bin's result. */
typedef struct {
    double x, h, surface, bottom;
    int contact;
    long n;
} lub_film_row;

/* Bins as lub_bins_init; 0, or -1 on a bad range or width. */
int lub_film_init(lub_film *f, double from, double to, double dx);
void lub_film_free(lub_film *f);
/* Sample one set of particles (replacing the previous sample). */
void lub_film_sample(lub_film *f, const lub_particles *P);
/* Bin k of the last sample: 1 and row filled, or 0 when the bin holds no fluid. */
int lub_film_row_at(const lub_film *f, int k, lub_film_row *row);
/* Inlet and outlet meniscus of the last sample: 1 and positions, or 0 when no bin is in
 * contact with an upper wall. */
int lub_film_meniscus(const lub_film *f, double *inlet, double *outlet);

#endif
