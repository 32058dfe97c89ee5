/* lubkit post-processing: the oil film's shape from the particles (probe film).
 *
 * Particles are sorted into bins of x (2-D; in 3-D the bins take every z).  Each bin is
 * judged on its strip: its own particles and, where the bin is narrower than 3 l0, also
 * those within 1.5 l0 of its centre (LUB_FILM_STRIP; each particle with the l0 of its level).
 * Particle rows are about l0 apart, but a narrow strip holds no particle of some of them: a
 * particle of a disordered arrangement leaves its column's narrow bin, and a bin of l0 over
 * a moving lattice holds 0, 1 or 2 columns.  Such a bin shows an empty row, or no particle
 * at all, inside a full film.  A strip of 2 l0 was not enough in a lubricating film, whose
 * columns shift by up to l0/2 against each other: in the reduced wedge one strip of 2 l0
 * inside the pressurised film had consecutive heights 2.3 l0 apart (a row's particles on
 * both sides just outside it), which ended the film there; in a strip of 3 l0 two or three
 * columns share each row and consecutive heights stay less than 2 l0 apart.  In the strip of
 * each bin (fluid particles, and the wall particles: kind wall, not dummy, which lie on the
 * wall surface):
 *
 *   surface  y of the highest fluid particle: the free surface.  MPS imposes p = 0 on the
 *            surface particles themselves (thesis 2), so the surface lies at their centres,
 *            and a layer generated with thickness T on a wall (particleGen: wall particles on
 *            the wall surface, fluid rows l0 .. T above it) has its surface at exactly T;
 *   bottom   the lower boundary of the film: the height of the highest wall particle below the
 *            lowest fluid particle, when it is closer than 2 l0 to it (the film rests on the
 *            wall); else the lowest fluid particle (a free lower surface);
 *   contact  1 when the lowest wall particle above the highest fluid particle is closer than
 *            2 l0 to it: the oil touches an upper wall (a free surface has at least one empty
 *            lattice row, 2 l0 between particle centres, below a wall);
 *   h        the film thickness: top - bottom, top being the upper wall (its lowest wall
 *            particle) where contact = 1 and the surface elsewhere, so that under the
 *            cylinder of the wedge h is the gap h(x) of the Reynolds reference;
 *   filled   how much of the gap between the walls (the wall particles next to the fluid,
 *            below and above it) the oil fills: the part of it covered by the particles'
 *            cells, [y - l0/2, y + l0/2] for each fluid and wall particle, so that a full
 *            lattice gives 1 and k empty rows in a gap of height g give 1 - k l0/g; 0 where
 *            no wall lies above or below the fluid (no gap to fill);
 *   full     1 when the gap is full from wall to wall: consecutive heights (the wall below,
 *            the fluid particles and wall particles between, the wall above) are all closer
 *            than 2 l0 (the larger l0 of the two), so that no empty row lies anywhere
 *            between the walls.  Under an inlet roll (the meniscus of oil piled ahead of a
 *            cylinder touches the cylinder above an air gap) contact = 1 but full = 0;
 *   n        the fluid particles in the bin itself (bins do not overlap: n sums to the fluid
 *            particles in the range).
 *
 * A bin whose strip holds no fluid particle has no values.
 *
 * The film of a Reynolds reference is where the gap is full from wall to wall: its inlet is
 * where the gap becomes full and stays full downstream up to its outlet.  lub_film_meniscus
 * takes the longest run of full bins (most bins; on a tie the upstream one), downstream
 * being +x when the mean fluid x-velocity is >= 0, else -x: the inlet is the upstream edge
 * of its first bin, the outlet the downstream edge of its last.  Their resolution is the bin
 * width (1.5 l0 + DX/2 for bins narrower than 3 l0, whose strips reach 1.5 l0), and l0/slope
 * where the wall's slope is small: particle rows are l0 apart, so a surface less than 2 l0
 * below the wall is as full as the lattice allows (in the thesis wedge, l0 = 5 um, the gap
 * fills where the cylinder is 2 l0 above the oil, 0.2 mm upstream of where a continuous
 * surface would meet it).  The contact point is where the oil first touches the upper wall,
 * going upstream from the inlet through bins in contact: upstream of the inlet by the length
 * of the air gap under a roll, at the inlet where there is none.
 */
#ifndef LUB_POST_FILM_H
#define LUB_POST_FILM_H

#include "particles/particles.h"
#include "post/sample.h"

/* Contact distance in l0 (see above): heights this far apart have an empty row between. */
#define LUB_FILM_CONTACT 2.0
/* Half-width of the strip of a narrow bin, in l0 (see above). */
#define LUB_FILM_STRIP 1.5

/* A particle of a strip (film.c). */
typedef struct lub_film_entry lub_film_entry;

typedef struct {
    lub_bins bins;
    /* per bin, from the last lub_film_sample */
    double *surface, *bottom, *h, *filled;
    unsigned char *fluid, *contact, *full; /* fluid: the strip holds fluid */
    long *n;                               /* fluid particles in the bin */
    double mean_u;                         /* mean x-velocity of the fluid */
    /* the strips: bin k holds e[start[k] .. start[k + 1]), sorted by y */
    size_t *start;
    lub_film_entry *e;
    size_t ecap;
} lub_film;

/* One bin's result. */
typedef struct {
    double x, h, surface, bottom, filled;
    int contact, full;
    long n;
} lub_film_row;

/* The film's ends, positions in x. */
typedef struct {
    double inlet, outlet; /* ends of the longest run of full bins */
    double contact;       /* upstream end of the contact run through the inlet */
} lub_film_ends;

/* Bins as lub_bins_init; 0, or -1 on a bad range or width. */
int lub_film_init(lub_film *f, double from, double to, double dx);
void lub_film_free(lub_film *f);
/* Sample one set of particles (replacing the previous sample). */
void lub_film_sample(lub_film *f, const lub_particles *P);
/* Bin k of the last sample: 1 and row filled, or 0 when its strip holds no fluid. */
int lub_film_row_at(const lub_film *f, int k, lub_film_row *row);
/* The film's ends in the last sample: 1 and e filled, or 0 when no bin is full. */
int lub_film_meniscus(const lub_film *f, lub_film_ends *e);

#endif
