/* lubkit geometry discretisation: walls -> wall + dummy particles, fluid regions -> fluid
 * particles, per resolution level.
 *
 * Lattice.  Every level k has a square (cubic) lattice of spacing l0_k.  In a periodic
 * direction it is cell-centred, dmin + (i + 1/2) l0, so the period holds exactly
 * period / l0 points and the distance across the seam is l0.  In the other directions it
 * passes through the first axis-aligned plane (or box face) perpendicular to that direction,
 * else through dmin + l0/2; all levels share that origin.  Axis-aligned planes and boxes are
 * discretised on the lattice itself (their faces must lie on it), so corners of tanks are
 * filled without gaps or duplicates; inclined planes, segments, polylines, cylinders and
 * spheres are sampled along their surface at arc-length spacing l0, with the dummy layers as
 * offset surfaces k l0 behind (concentric arcs R -/+ k l0 on cylinders and spheres).  A
 * polygon (a closed body) has a wall particle at every corner and round(length / l0) equal
 * steps along each edge; its dummy layers are the boundary moved k l0 inwards, each corner
 * along its mitre (discretise.c, sample_polygon).
 *
 * Ownership.  A point (wall, dummy or fluid) belongs to the level that owns its x (the first
 * level whose region contains x, else the last level).
 *
 * Fluid.  Lattice points inside a region, on the fluid side of every wall, and at least
 * 0.999 wallGap l0 from every wall and dummy particle (0.999 so that round-off does not remove
 * the lattice row exactly one l0 from a wall).  A region left without particles is an error.
 * A cylinder or sphere with fluidLayers K has its first K rows of fluid body-fitted instead:
 * on the offset surfaces R +- k l0 (k = 1..K) on its fluid side, sampled as its dummy layers,
 * kept by the same rules (and as far from the layers of the walls before it), and the
 * lattice fluid keeps 0.999 wallGap l0 from them too.  Against a curved wall the lattice
 * leaves its first row 0.87 to 1.9 l0 from the wall particles, a gap across which the MPS
 * viscous term couples the fluid to the wall too weakly: the fluid slips (methods.md §7.2).
 *
 * Jitter (g->jitter > 0, lub_geometry_discretise only).  Each fluid particle is then moved
 * from its lattice point by a displacement uniform in the disk (ball) of radius jitter l0, a
 * function of the seed and the point's lattice indices alone (a counter-based generator), so
 * a case gives the same particles on every machine; periodic directions wrap, and a draw
 * that would leave the domain or enter a wall is drawn again.  A disordered start for the
 * convergence of the operators on particles off the lattice (issue 26).
 */
#ifndef LUB_GEOMETRY_DISCRETISE_H
#define LUB_GEOMETRY_DISCRETISE_H

#include "geometry/geometry.h"
#include "particles/particles.h"

/* Reference values of a level on a full regular lattice around an interior particle:
 * re = 3.1 l0, n0 (T-4), lambda0 (T-5) with w(r) = (r/re - 1)^2 for r < re (T-6). */
void lub_level_reference(int dim, double l0, lub_level *lev);

/* Upper bound of the particle count: lattice points of every level in the part of the
 * domain it owns, plus the sampled walls. */
double lub_geometry_estimate(const lub_geometry *g);

/* Bytes of memory one particle needs during generation and in lub_particles. */
#define LUB_GEN_BYTES_PER_PARTICLE 160.0

/* Fill P (initialised here with g->dim) with the wall, dummy and fluid particles of g and
 * set its levels and patches.  Fatal (exit 1, with the dictionary location) when the
 * estimated count exceeds the memory (mem_bytes; 0: physical memory of the machine), when a
 * fluid region ends up empty, or when an axis-aligned wall face is off the lattice.
 * region_counts (may be NULL; g->nregions entries) receives the fluid particles found in each
 * region (a particle inside two overlapping regions counts for both). */
void lub_geometry_discretise(const lub_geometry *g, lub_particles *P, double mem_bytes,
                             size_t *region_counts);

/* The wall, dummy and fluid particles level `level` would have in x in [xlo, xhi] if it
 * owned that range (same lattice, same wall sampling and fluid rules as
 * lub_geometry_discretise), into P (initialised here; all levels and patches of g set).  An
 * empty result is not an error.  The multi-resolution solver fills the overlap margins with
 * it (particleGen generates each level only where it owns x; models/multiResolution/opt.h). */
void lub_geometry_discretise_range(const lub_geometry *g, int level, double xlo, double xhi,
                                   lub_particles *P);

/* 1 when point x lies behind wall w (inside its solid, deeper than tol) within the wall's
 * span (x-range for planes, segments and polylines). */
int lub_wall_behind(const lub_wall *w, const double *x, int dim, double tol);

/* 1 when point x is fluid by the geometry alone: inside a fluid region (within tol) and
 * behind no wall.  Unlike the particles, no wallGap is kept from the walls: a film between
 * two walls is fluid from one surface to the other. */
int lub_geometry_fluid_at(const lub_geometry *g, const double *x, double tol);

#endif
