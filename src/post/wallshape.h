/* lubkit post-processing: the wall particles of one patch as a curve y(x), its load and the
 * elastic wall's deformation (probe wallShape, probe totals -patch).
 *
 * A 2-D wall patch that is a graph y(x) (a cylinder's lower arc, a plane) carries the
 * vertical load per unit length
 *
 *     L = integral of p dx = sum_k p_k w_k
 *
 * over its wall particles sorted by x, w_k the segment widths of lub_elastic_segment_widths
 * (half-way to each neighbour), exactly the sum the elasticWall model balances against its
 * load (models/elasticWall/elasticWall.h).
 *
 * Multi-resolution (particles of several levels, and the geometry g of
 * system/particleGenDict.yaml with the same levels): every level has its own wall particles
 * in the overlaps, so the curve is made of the wall particles in the part of x their level
 * owns (particleGen's ownership: the first level whose region holds x, else the last; as
 * models/multiResolution/levels.h), each point of x once, as the elasticWall model counts its load.
 * Without g (or with a single level) every wall particle of the patch is on the curve.
 *
 * The elastic wall (models/elastic.h, models/elasticWall/elasticWall.h) puts wall particle k at
 *
 *     y_k = y_f + h0 + s_k + v_k                                                    (T-50)
 *
 * y_f the surface beneath the cylinder's lowest point (lub_elastic_floor), h0 the rigid-body
 * position (uniform/state.yaml of the time folder), s_k the undeformed shape (the particle
 * field elasticShape that the solver writes; in a file without it, a particleGen file, the
 * circle of the geometry: s = R - sqrt(R^2 - (x - x_c)^2), which T-50's (x - x_c)^2/(2R)
 * approximates to (x - x_c)^4/(8R^3)) and v_k the elastic displacement.  lub_wall_shape
 * returns x, y, v = y - y_f - h0 - s, and the film thickness h = y - (the surface beneath at
 * x), the gap that reynoldsRef's h(x) describes.
 */
#ifndef LUB_POST_WALLSHAPE_H
#define LUB_POST_WALLSHAPE_H

#include <stddef.h>
#include <stdint.h>

#include "geometry/geometry.h"
#include "models/elastic.h"
#include "particles/particles.h"

/* The wall particles (kind wall) of patch on the curve (see above; g may be NULL), sorted by
 * x (ties by id): their indices into *idx (allocated; free it).  Returns the count. */
size_t lub_wall_curve(const lub_particles *P, int patch, const lub_geometry *g, size_t **idx);

/* sum_k f_k w_k over the wall particles of the curve of patch (see above; g may be NULL) into
 * *out.  Returns 0, or -1 when two of them share an x (the patch is not a graph y(x)); *out =
 * 0 without particles. */
int lub_wall_integral(const lub_particles *P, int patch, const lub_geometry *g, const double *f,
                      double *out);

typedef struct {
    double x, y, v, h; /* see above */
    uint64_t id;
} lub_wall_shape_row;

/* The shape of the elastic wall e (its patch's index in P: patch) at rigid-body position
 * h0, one row per wall particle of the curve sorted by x, into *rows (allocated; free it); g
 * is the geometry e was read against.  h is NAN where no surface lies beneath.  Returns the
 * count. */
size_t lub_wall_shape(const lub_particles *P, int patch, const lub_geometry *g,
                      const lub_elastic_wall *e, double h0, lub_wall_shape_row **rows);

#endif
