/* lubkit geometry: the case geometry of system/particleGenDict.yaml.
 *
 * One reader for the whole dictionary (lub_geometry_read), used by particleGen (which turns
 * it into particles) and by reynoldsRef (which derives the gap h(x) from the same walls), so
 * that both see the same case and the strict unknown-key check covers every entry.
 *
 * Dictionary layout (2-D example, the thesis wedge):
 *
 *     dimension:   2
 *     l0:          5.0e-6            # single resolution; or `levels:` below
 *     levels:                        # multi-resolution: each level owns an x-interval
 *       - { l0: 5.0e-6, region: [-0.0036, 0.0030] }   # fine level owns [a1, a2]
 *       - { l0: 4.0e-5 }                               # last level owns the rest
 *     domain:      { min: [-0.0045, -2.0e-5], max: [0.0045, 3.0e-4] }
 *     periodic:    [x]               # periodic directions: period = domain extent
 *     dummyLayers: 2                 # dummy layers behind every wall (default 2)
 *     wallGap:     1.0               # minimum fluid-wall distance in l0 (default 1.0)
 *     walls:
 *       lowerWall: { type: plane, point: [0, 0], normal: [0, 1] }     # normal into fluid
 *       cylinder:  { type: cylinder, lowestPoint: [0, 4.0e-5], radius: 0.04,
 *                    range: [-0.0045, 0.0045] }   # x-extent of the arc (optional)
 *       ramp:      { type: segment, from: [0, 0], to: [1, 0.1], fluid: above }
 *       profile:   { type: polyline, points: [[0, 0], [1, 0.2], [2, 0]], fluid: above }
 *       pad:       { type: polygon, points: [[0, 1], [2, 0.9], [2, 1.5], [0, 1.5]] }
 *       tank:      { type: box, min: [0, 0], max: [1.61, 0.8], fluid: inside }
 *       ball:      { type: sphere, centre: [0, 0, 1], radius: 0.1 }             # 3-D
 *       shaft:     { type: cylinder, centre: [0, 0, 1], axis: [0, 0, 1], radius: 0.1 } # 3-D
 *       roller:    { type: cylinder, lowestPoint: [0, 4.0e-5, 0], radius: 0.01,
 *                    length: 9.6e-4 }     # 3-D: a roller of finite length (flat ends)
 *     fluid:
 *       - { type: layer, wall: lowerWall, thickness: 8.0e-5 }   # film on a wall
 *       - { type: box, min: [0, 0], max: [0.6, 0.3] }
 *       - { type: between, lower: lowerWall, upper: cylinder, height: 8.0e-5 }
 *     jitter:      { amplitude: 0.25, seed: 1 }   # disordered start (optional)
 *
 * cylinder: `centre` or `lowestPoint`; fluid `outside` (default) or `inside`.  In 3-D it is
 * infinitely long unless `length` is given: then it is the solid between two flat ends
 * (discs of the radius) at length/2 either side of the centre (or lowest point) along the
 * axis, a roller of finite length; with the axis along x, y or z its ends must lie on the
 * particle lattice (as the faces of a box).
 * cylinder (2-D, no range; 3-D without length), sphere: `fluidLayers: K` (default 0) puts
 * the first K rows of fluid on the surfaces k l0 (k = 1..K) out from the wall, body-fitted
 * (discretise.h).
 * box, sphere: fluid `inside` or `outside` (box default inside: a tank; sphere outside).
 * segment, polyline (2-D): fluid `above` (default) or `below`; polyline x must increase.
 * polygon (2-D): a closed solid body (fluid outside): at least 3 vertices in any order
 * around it, either orientation (stored counter-clockwise), a repeated first vertex at the
 * end dropped; the boundary must not cross or touch itself.
 * `between ... height` fills from the lower wall up to `height` above the lower wall's
 * surface, and not inside or beyond the upper wall.
 * `jitter` (single resolution only): every fluid particle moved from its lattice point by a
 * random displacement, uniform in the disk (ball) of radius amplitude l0, amplitude in
 * [0, 0.5); the same seed gives the same particles (discretise.h).
 */
#ifndef LUB_GEOMETRY_GEOMETRY_H
#define LUB_GEOMETRY_GEOMETRY_H

#include "io/dict.h"
#include "particles/particles.h"

typedef enum {
    LUB_WALL_PLANE,
    LUB_WALL_SEGMENT,
    LUB_WALL_CYLINDER,
    LUB_WALL_POLYLINE,
    LUB_WALL_BOX,
    LUB_WALL_SPHERE,
    LUB_WALL_POLYGON
} lub_wall_type;

typedef struct {
    char name[LUB_NAME_MAX];
    lub_wall_type type;
    const lub_node *node;       /* the dictionary entry (for messages) */
    double point[3], normal[3]; /* plane: a point and the unit normal into the fluid */
    double from[3], to[3];      /* segment */
    double centre[3], radius;   /* cylinder (2-D circle; 3-D with axis), sphere */
    double axis[3];             /* 3-D cylinder axis (unit) */
    double *pts;                /* polyline, polygon (counter-clockwise): npts points (x, y) */
    int npts;
    double min[3], max[3]; /* box; polygon: its bounding box */
    int fluid_inside;      /* cylinder, sphere, box */
    int fluid_above;       /* segment, polyline */
    int has_range;         /* cylinder arc / plane limited in x */
    double range[2];
    int fluid_layers; /* cylinder, sphere: fluid on this many surfaces k l0 out (discretise.h) */
    int has_length;   /* 3-D cylinder of finite length (flat ends) */
    double length;    /* along the axis, centred on the centre */
} lub_wall;

typedef enum { LUB_REGION_LAYER, LUB_REGION_BOX, LUB_REGION_BETWEEN } lub_region_type;

typedef struct {
    lub_region_type type;
    const lub_node *node;
    int wall;              /* layer: wall index */
    double thickness;      /* layer */
    double min[3], max[3]; /* box */
    int lower, upper;      /* between: wall indices */
    double height;         /* between */
} lub_region;

typedef struct {
    double l0;
    double xmin, xmax; /* owned x-interval (the last level: everything not owned before) */
    int has_region;
    const lub_node *node;
} lub_level_spec;

typedef struct {
    const lub_dict *dict; /* the dictionary read (owned) */
    int dim;
    double dmin[3], dmax[3]; /* domain */
    int periodic[3];
    int dummy_layers;
    double wall_gap; /* in l0 */
    int nlevels;
    lub_level_spec levels[LUB_MAX_LEVELS];
    int nwalls;
    lub_wall *walls;
    int nregions;
    lub_region *regions;
    double jitter;               /* fluid displacement radius in l0 (0: on the lattice) */
    unsigned long jitter_seed;   /* seed of the displacements */
    const lub_node *jitter_node; /* the `jitter` entry, or NULL */
} lub_geometry;

/* Read system/particleGenDict.yaml (path given) strictly; fatal with file:line on bad input.
 * Calls lub_dict_finish. */
void lub_geometry_read(lub_geometry *g, const char *path);
void lub_geometry_free(lub_geometry *g);

/* Wall index by name, or -1. */
int lub_geometry_find_wall(const lub_geometry *g, const char *name);

/* Height of a wall's surface at x (2-D, or the z = 0 section in 3-D) as seen from the gap:
 * for the upper wall of a gap (upper != 0) the lowest point of its surface at x, for the
 * lower wall the highest (a polygon over a film: its lower surface, a vertical face at x
 * included).  Returns 1 and sets *y, or 0 when the wall does not span x. */
int lub_wall_height(const lub_wall *w, double x, int upper, double *y);

/* The same on the vertical line through (x, z) in 3-D (lub_wall_height is z = 0): a sphere's
 * or a cylinder's surface, a plane with a z-component in its normal, a box's or a finite
 * roller's extent in z.  The 2-D walls (segment, polyline, polygon) do not depend on z. */
int lub_wall_height_at(const lub_wall *w, double x, double z, int upper, double *y);

/* Signed distance from point x to the wall surface, positive on the fluid side. */
double lub_wall_distance(const lub_wall *w, const double *x, int dim);

/* w = w0 translated by d (3 components): every point of its definition moved (a plane's
 * point, a segment's ends, a cylinder's or sphere's centre, the vertices of a polyline, a
 * box, the x-range of an arc or plane), its shape and fluid side kept.  w->pts is w's own
 * array (kept, the moved vertices written into it): it must hold w0->npts points, or be
 * NULL when w0 has none.  A rigid wall moving at velocity v is at time t the wall of t = 0
 * translated by v t (reynoldsRef's reference at time t). */
void lub_wall_translate(lub_wall *w, const lub_wall *w0, const double *d);

#endif
