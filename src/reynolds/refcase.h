/* lubkit Reynolds reference of a case: what the 1-D reference (methods.md 5, thesis 3-2) takes
 * from the case directory, and the thesis' dimensionless scales derived from it.
 *
 *   - system/reynoldsRefDict.yaml: the lower and upper wall, inlet, outlet, grid, boundary
 *     condition (template: etc/templates/reynoldsRefDict.yaml);
 *   - system/particleGenDict.yaml: the walls (lub_geometry);
 *   - constant/transportProperties.yaml: rho, nu (mu = rho nu);
 *   - constant/models.yaml movingWalls: U1, U2 (x-velocities of the lower and upper wall),
 *     and elasticWall (soft EHL, src/models/elastic.h).
 *
 * The gap h(x) = (upper wall height) - (lower wall height) sampled on the reference grid gives
 * the minimum gap h0, and with the upper wall a cylinder of radius R the scales of T-38, T-39:
 *
 *     X = x / sqrt(R h0),   P = h0^1.5 p / (mu (U1 + U2) sqrt(R)),   H = h / h0.
 *
 * Soft EHL (the softEHL mapping of reynoldsRefDict.yaml, mode auto: when models.yaml has an
 * elasticWall): the upper wall is the elastic cylinder, the gap h0 + x^2/(2R) + v(x) follows
 * from the pressure (src/reynolds/ehl.h) and the scales are those of T-54..T-58:
 *
 *     X = x / b,   P = p / p_H,   H = h R / b^2,   b = sqrt(8 W R / (pi E)),  p_H = 2 W/(pi b).
 *
 * Shared by reynoldsRef (which solves the Reynolds equation on the gap) and probe
 * (-dimensionless), so that both scale with the same R, h0 and U1 + U2 and their X, P columns
 * can be compared directly.  Every error is fatal (exit 1) and names the dictionary entry.
 */
#ifndef LUB_REYNOLDS_REFCASE_H
#define LUB_REYNOLDS_REFCASE_H

#include "geometry/geometry.h"
#include "io/case.h"
#include "io/dict.h"
#include "models/elastic.h"
#include "models/models.h"
#include "reynolds/reynolds.h"

/* softEHL.mode: auto (soft EHL exactly when constant/models.yaml has elasticWall), on
 * (required), off (the rigid reference even with an elasticWall). */
enum { LUB_REFCASE_EHL_AUTO, LUB_REFCASE_EHL_ON, LUB_REFCASE_EHL_OFF };
extern const char *const lub_refcase_ehl_modes[];

/* The settings of system/reynoldsRefDict.yaml (nodes kept for messages). */
typedef struct {
    lub_dict *dict;
    const char *lower, *upper; /* wall names */
    lub_node *lower_node, *upper_node, *inlet_node, *outlet_node;
    double inlet, outlet;
    long cells;
    int bc; /* lub_reynolds_bc */
    double exit_x;
    double time;         /* time: (default 0) */
    lub_node *time_node; /* time entry (or NULL) */
    double tolerance;
    long max_iterations;
    lub_node *bc_node;       /* boundaryCondition entry (or NULL) */
    lub_node *cells_node;    /* cells entry (or NULL) */
    int ehl_mode;            /* softEHL.mode */
    lub_node *ehl_mode_node; /* softEHL.mode entry (or NULL) */
    double ehl_tolerance;    /* softEHL.tolerance: film change and load error */
    long ehl_max_iterations; /* softEHL.maxIterations: Newton iterations */
    double width;            /* width: > 0 the finite-width (2-D) reference, 0: 1-D */
    lub_node *width_node;    /* width entry (or NULL) */
    long nz;                 /* nz: cells across the width (even) */
    int solver;              /* linearSolver: lub_linsolver_kind (2-D only) */
} lub_refcase_settings;

/* Everything the reference reads from a case. */
typedef struct {
    lub_refcase_settings s;
    lub_geometry g;                /* the geometry as written: the walls at t = 0 */
    int wl, wu;                    /* wall indices of the lower and upper wall */
    const lub_wall *lower, *upper; /* the lower and upper wall at time t (&wt[0], &wt[1]) */
    lub_wall wt[2];                /* g.walls[wl], g.walls[wu] moved to time t */
    double t;                      /* the time of lower and upper (lub_refcase_move) */
    const lub_node *t_node;        /* the entry t came from, or NULL (the -time option) */
    double rho, nu, mu;            /* oil; mu = rho nu */
    lub_wall_motion *motion;       /* the motion of every wall of g (movingWalls) */
    double (*vel)[3];              /* velocity of every wall of g at time t */
    double disp[2][3];             /* displacement of the lower and upper wall at time t */
    int *moving;                   /* 1 when the wall is listed in movingWalls */
    double u1, u2;                 /* x-velocities of the lower and upper wall at time t */
    int ehl;                       /* soft EHL: the elasticWall model ew is the upper wall */
    lub_elastic_wall ew;           /* constant/models.yaml elasticWall (read when present) */
} lub_refcase;

/* Read the four dictionaries strictly (fatal with file:line on bad input).  The walls are
 * those of t = 0 (the geometry as written); lub_refcase_move takes them to another time. */
void lub_refcase_read(lub_refcase *rc, const lub_case *c);
void lub_refcase_free(lub_refcase *rc);

/* The lower and upper wall at time t >= 0: each rigid wall translated from its place in
 * system/particleGenDict.yaml (t = 0) by its movingWalls displacement d(t) (V t, or the
 * motion history's: models/models.h), the walls' velocities those of t (vel, u1, u2), as
 * lubFoam moves the particles of a moving patch (a periodic domain's wrap is not applied: a wall
 * that has left [inlet, outlet] is an error when the gap is sampled).  A wall sliding along itself
 * (the rigid wedge's plane) keeps its surface, so that the gap, and the reference, do not
 * change with t.  node: the dictionary entry t came from, named by the errors of
 * lub_refgap_sample at that time (NULL: it came from the command line). */
void lub_refcase_move(lub_refcase *rc, double t, const lub_node *node);

/* The gap on the reference grid: h at the n + 1 nodes and n face midpoints, dh/dt at the
 * nodes, and the minimum gap h0 (refined between samples by a parabola) and its position. */
typedef struct {
    int n;
    double xa, xb, dx;
    double *h, *hf, *dhdt;
    double h0, x_h0;
    int moving_shape; /* dh/dt != 0 somewhere */
    /* The finite width (lub_refgap_sample_area): the gap over the area [xa, xb] x [-W/2, W/2]
     * on the (n, nz) grid of reynolds2d.h, at the nodes (index i (nz + 1) + j), the x faces
     * (i (nz + 1) + j) and the z faces (i nz + j), dh/dt at the nodes; NULL before. */
    int nz;
    double width;
    double *ha, *hfx, *hfz, *dhdta;
    double h0_area, x_h0_area, z_h0_area; /* the smallest sampled gap over the area, where */
    int varies_across;                    /* h or dh/dt is not the same on every z */
} lub_refgap;

/* Sample h (and dh/dt from the wall velocities: normal speeds, and each surface carried
 * along x) of the walls at time rc->t between the inlet and outlet; fatal (naming
 * reynoldsRefDict.yaml:line) when a wall does not span the interval or the gap is <= 0 (at
 * t > 0 with the time at which the moving walls touch). */
void lub_refgap_sample(lub_refgap *G, const lub_refcase *rc);
void lub_refgap_free(lub_refgap *G);

/* The gap over the area for the finite-width reference (width, nz of reynoldsRefDict.yaml),
 * after lub_refgap_sample: h(x, z) = (upper wall height) - (lower wall height) on the vertical
 * line through (x, z) (lub_wall_height_at: a sphere over a plane gives the point contact's
 * h0 + (x^2 + z^2)/(2R) near its lowest point), dh/dt from the walls' velocities (normal
 * speeds, and each surface carried along x and z).  Fatal (naming the width entry) when a
 * wall does not span the area or the gap is <= 0 in it.  A gap uniform in z (walls of a 2-D
 * section extruded, a roller along z) gives every z the values of the mid-plane's h(x) bit
 * for bit. */
void lub_refgap_sample_area(lub_refgap *G, const lub_refcase *rc);

/* Solve the rigid reference on the gap G (the Reynolds equation with the case's U1, U2, mu,
 * boundary condition, tolerance and iterations: what reynoldsRef solves without soft EHL):
 * p receives the G->n + 1 nodal pressures, res the derived figures (reynolds.h). */
lub_reynolds_status lub_refcase_solve(const lub_refcase *rc, const lub_refgap *G, double *p,
                                      lub_reynolds_result *res);

/* The thesis' scales (T-38, T-39): X = x/sx, P = p sp, H = h/h0. */
typedef struct {
    double radius; /* R: radius of the upper wall (a cylinder) */
    double uref;   /* U1 + U2 */
    double h0;     /* film scale, H = h / h0: the minimum gap (soft EHL: b^2 / R) */
    double sx;     /* sqrt(R h0) (soft EHL: b) */
    double sp;     /* h0^1.5 / (mu (U1 + U2) sqrt(R)) (soft EHL: 1 / p_H) */
} lub_refscales;

/* Fatal (at the reynoldsRefDict.yaml entry) unless the upper wall is a cylinder and
 * U1 + U2 != 0: the conditions of -dimensionless. */
void lub_refcase_check_scales(const lub_refcase *rc);
/* The scales with the minimum gap h0 of G (checks as lub_refcase_check_scales); in soft-EHL
 * mode those of T-54..T-58, which do not depend on G. */
void lub_refcase_scales(const lub_refcase *rc, const lub_refgap *G, lub_refscales *d);
/* Read the case, sample the gap and compute the scales in one call (for programs that need
 * only the scales, e.g. probe -dimensionless). */
void lub_refscales_read(lub_refscales *d, const lub_case *c);

#endif
