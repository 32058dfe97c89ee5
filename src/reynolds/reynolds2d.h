/* lubkit Reynolds equation over the bearing's area: a film of finite width (issue 31, item 3;
 * doc/methods.md §5.6).
 *
 * The 2-D Reynolds equation for an incompressible film, x along the motion, z across the
 * width W (z in [-W/2, W/2]), the gap h(x) uniform in z (the walls of a 2-D geometry
 * extruded over the width) or h(x, z) varying across (h_area: a ball over a plane, the
 * point contact h = h0 + (x^2 + z^2)/(2R)):
 *
 *     d/dx(h^3/(12 mu) dp/dx) + d/dz(h^3/(12 mu) dp/dz) = (U1 + U2)/2 dh/dx + dh/dt   (5.6)
 *
 * with p = 0 at the sides z = +-W/2 and the x conditions of the 1-D solver (reynolds.h): p = 0
 * at the inlet; Reynolds (p >= 0, a free exit), half-Sommerfeld, full-Sommerfeld or a given
 * exit x (p = 0 there and beyond).  As W -> infinity the mid-plane z = 0 tends to the 1-D
 * solution; as W/L -> 0 the film tends to the short-bearing solution of Ocvirk ((5.7)).
 *
 * Discretisation: the 1-D scheme of reynolds.c in x (fluxes at the face midpoints with the
 * face gap, a Shortley-Weller cut cell at a given exit between nodes) times central
 * differences in z on a uniform (nx, nz) grid of nodes x_i = xa + i dx, z_j = -W/2 + j dz,
 * the z fluxes likewise with the gap of their face (h(x_i, z_j +- dz/2): the node's gap when
 * h is uniform in z, so that both forms give the same matrix bit for bit).
 * Each row is the balance of a control volume dx dz, so the matrix M (minus the operator) is
 * symmetric, an M-matrix, five entries a row: second order and conservative.  It is solved
 * by the linear solver chosen (src/linalg: CHOLMOD by default, or PCG with AMG).
 *
 * Reynolds condition: the complementarity problem p >= 0, w = M p + f >= 0, p w = 0 by the
 * primal-dual active-set method (Hintermueller, Ito and Kunisch 2002) as in 1-D; its start is
 * the cavitated region of the same problem on a grid of half the cells in each direction
 * (recursively, down to about 16 x 4 cells), so that the free boundary moves a cell or two
 * per level.  An active node's row becomes p_i = 0 and its column is zeroed (explicit zeros),
 * so the pattern stays and CHOLMOD refactorises without a new analysis.
 */
#ifndef LUB_REYNOLDS_REYNOLDS2D_H
#define LUB_REYNOLDS_REYNOLDS2D_H

#include "linalg/linsolve.h"
#include "reynolds/reynolds.h"

typedef struct {
    int nx, nz;           /* cells in x and z (nz even: the mid-plane is a grid line) */
    double xa, xb;        /* inlet and outlet, xa < xb */
    double width;         /* W > 0: z in [-W/2, W/2] */
    const double *h;      /* gap at the nx + 1 x nodes [m] (uniform in z) */
    const double *h_face; /* gap at the nx face midpoints, or NULL: mean of the nodes */
    /* A gap varying across, h(x, z) (a ball over a plane): when h_area is given it replaces
     * h and h_face (which may then be NULL), and dhdt_area replaces dhdt and dhdt_nodes.
     * Nodes (i, j) at index i (nz + 1) + j; the x faces (x_i + dx/2, z_j) at i (nz + 1) + j
     * (nx (nz + 1) values), the z faces (x_i, z_j + dz/2) at i nz + j ((nx + 1) nz values);
     * a NULL face array: the mean of the two nodes. */
    const double *h_area;     /* gap at the (nx + 1)(nz + 1) nodes [m], or NULL */
    const double *h_face_x;   /* gap at the x faces, or NULL */
    const double *h_face_z;   /* gap at the z faces, or NULL */
    const double *dhdt_area;  /* dh/dt at the nodes (with h_area), or NULL: dhdt */
    double u1, u2;            /* x speeds of the lower and upper surface [m/s] */
    double dhdt;              /* squeeze rate when dhdt_nodes is NULL [m/s] */
    const double *dhdt_nodes; /* dh/dt at the nx + 1 x nodes, or NULL */
    double mu;                /* dynamic viscosity [Pa s] */
    lub_reynolds_bc bc;
    double exit_x;      /* LUB_REYNOLDS_BC_GIVEN_EXIT: xa < exit_x <= xb */
    double tolerance;   /* relative complementarity tolerance (0: 1e-12, at least 100 times
                           the linear solver's tolerance when it iterates) */
    int max_iterations; /* active-set iterations per level (0: nx + nz + 10) */
    const lub_linsolver_options *solver; /* NULL: CHOLMOD */
    /* Verification only (a manufactured solution, tests/unit/reynolds2d_test.c): a term s
     * added to the right-hand side of (5.6) at the (nx + 1)(nz + 1) nodes (index
     * i (nz + 1) + j), or NULL.  reynoldsRef never sets it. */
    const double *source;
} lub_reynolds2d_problem;

typedef struct {
    double *p;        /* (nx + 1)(nz + 1) nodal pressures, p[i (nz + 1) + j] (filled) */
    double load;      /* integral of p over the area, trapezoid rule [N] */
    double p_max;     /* peak: the largest node refined by parabolas in x and z [Pa] */
    double x_max;     /* its position [m] */
    double z_max;     /* its position [m] */
    double leakage;   /* volume flow out of both sides z = +-W/2 [m^3/s] */
    double q_in;      /* volume flow into the film through the inlet [m^3/s] */
    double q_out;     /* volume flow out through the outlet (x = xb) [m^3/s] */
    double x_exit;    /* end of the pressurised film at the mid-plane [m] */
    int iterations;   /* active-set iterations (all levels; Reynolds condition), else 0 */
    int n_cavitated;  /* nodes held at p = 0 by the complementarity condition */
    int linear_iters; /* iterations of the linear solver summed over the solves (PCG) */
} lub_reynolds2d_result;

/* Defaults for the optional fields (as lub_reynolds_problem_init). */
void lub_reynolds2d_problem_init(lub_reynolds2d_problem *pb);

/* Solve.  LUB_REYNOLDS_OK and res filled, or a status (reynolds.h; SINGULAR also when the
 * linear solver fails) with res->p undefined.
 *
 * Derived figures: the flows are q_x = Um h - h^3/(12 mu) dp/dx through the inlet and the
 * outlet and -h^3/(12 mu) dp/dz through the sides, each with the one-sided second-order
 * derivative at the boundary and the trapezoid rule along it, so that q_in - q_out - leakage
 * = integral of dh/dt over the area to O(dx^2 + dz^2) where the film is full (a check of the
 * solution, not built into it).  x_exit at the mid-plane: for the Reynolds condition the zero
 * of sqrt(p), linear through the last two pressurised nodes (p ~ (x_e - x)^2 at a free exit);
 * otherwise as in 1-D. */
lub_reynolds_status lub_reynolds2d_solve(const lub_reynolds2d_problem *pb,
                                         lub_reynolds2d_result *res);

/* z of node j and the index of node (i, j). */
static inline double lub_reynolds2d_z(const lub_reynolds2d_problem *pb, int j)
{
    return -0.5 * pb->width + pb->width * (double)j / (double)pb->nz;
}
static inline int lub_reynolds2d_index(const lub_reynolds2d_problem *pb, int i, int j)
{
    return i * (pb->nz + 1) + j;
}

#endif
