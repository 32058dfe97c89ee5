/* lubkit Reynolds equation: the 1-D finite-difference reference (methods.md 5, thesis 3-2).
 *
 * Steady (or quasi-steady) 1-D Reynolds equation for an incompressible film between a lower
 * surface sliding at U1 and an upper surface sliding at U2, with the upper surface moving
 * normal to the film (squeeze), in the conservative flux form
 *
 *     d/dx ( h^3 / (12 mu) dp/dx ) = (U1 + U2)/2 dh/dx + dh/dt          (T-32 divided by 12)
 *
 * (T-33 is the case U2 = 0, dh/dt = 0.)  It is the balance of the volume flux
 * q = (U1 + U2)/2 h - h^3/(12 mu) dp/dx with dq/dx = -dh/dt.
 *
 * Discretisation: a uniform grid of n cells between the inlet xa and the outlet xb, nodes
 * x_i = xa + i (xb - xa)/n, i = 0..n; p at nodes.  The flux is evaluated at the faces
 * (midpoints) with h_{i+1/2} from the caller or the mean of the two nodes, which makes the
 * scheme second order and conservative.  The solver knows nothing of geometry: the caller
 * passes h as arrays, so a soft-EHL iteration can call it repeatedly with a deformed gap.
 *
 * Boundary conditions (p = 0 at the inlet in all of them):
 *   LUB_REYNOLDS_BC_REYNOLDS        Reynolds / Swift-Stieber (T-34..T-36): p >= 0, and at the
 *       free exit p = 0 and dp/dx = 0.  Solved as the linear complementarity problem
 *       p >= 0, w = M p + f >= 0, p w = 0 (M = minus the discrete operator, an M-matrix):
 *       a projected Thomas sweep (Brennan-Schwartz) gives the exact discrete solution when
 *       the film ruptures once downstream (the usual case) and the primal-dual active-set
 *       method then confirms it in one tridiagonal solve.  When the film ruptures and
 *       reforms, the active-set method (finite convergence for M-matrices) starts from the
 *       solution on a grid of half the cells, recursively, so that the work stays O(n log n)
 *       at worst rather than O(n^2).  No SOR sweeps.
 *   LUB_REYNOLDS_BC_HALF_SOMMERFELD Guembel: p = 0 at both ends, negative pressures set to 0.
 *   LUB_REYNOLDS_BC_FULL_SOMMERFELD p = 0 at both ends, negative pressures kept.
 *   LUB_REYNOLDS_BC_GIVEN_EXIT      p = 0 at the inlet and at a given exit x (between two
 *       nodes in general: a Shortley-Weller cut cell keeps second order), p = 0 beyond.
 */
#ifndef LUB_REYNOLDS_REYNOLDS_H
#define LUB_REYNOLDS_REYNOLDS_H

typedef enum {
    LUB_REYNOLDS_BC_REYNOLDS = 0,
    LUB_REYNOLDS_BC_HALF_SOMMERFELD,
    LUB_REYNOLDS_BC_FULL_SOMMERFELD,
    LUB_REYNOLDS_BC_GIVEN_EXIT
} lub_reynolds_bc;

/* Dictionary words of the boundary conditions, in enum order, NULL-terminated. */
extern const char *const lub_reynolds_bc_names[];

/* Status of a solve. */
typedef enum {
    LUB_REYNOLDS_OK = 0,
    LUB_REYNOLDS_BAD_INPUT,     /* n < 2, xb <= xa, mu <= 0, non-finite data, bad exit */
    LUB_REYNOLDS_BAD_GAP,       /* h <= 0 (or non-finite) at a node or face */
    LUB_REYNOLDS_NOT_CONVERGED, /* active set still changing after maxIterations */
    LUB_REYNOLDS_SINGULAR       /* zero pivot in the tridiagonal solve */
} lub_reynolds_status;

const char *lub_reynolds_status_string(lub_reynolds_status s);

/* The problem.  Arrays are borrowed, not copied. */
typedef struct {
    int n;                    /* cells; n + 1 nodes */
    double xa, xb;            /* inlet and outlet, xa < xb */
    const double *h;          /* gap at the n + 1 nodes [m] */
    const double *h_face;     /* gap at the n face midpoints, or NULL: mean of the two nodes */
    double u1, u2;            /* tangential speeds of the lower and upper surface [m/s] */
    double dhdt;              /* squeeze rate dh/dt, used when dhdt_nodes is NULL [m/s] */
    const double *dhdt_nodes; /* dh/dt at the n + 1 nodes, or NULL */
    double mu;                /* dynamic viscosity rho nu [Pa s] */
    lub_reynolds_bc bc;
    double exit_x;      /* LUB_REYNOLDS_BC_GIVEN_EXIT: xa < exit_x <= xb */
    double tolerance;   /* relative complementarity tolerance (0: default 1e-12) */
    int max_iterations; /* active-set iterations (0: default n + 10) */
} lub_reynolds_problem;

/* The solution.  p is the caller's array of n + 1 values. */
typedef struct {
    double *p;       /* pressure at the nodes [Pa] (filled) */
    double x_exit;   /* end of the pressurised film [m] (see lub_reynolds_solve) */
    double p_max;    /* peak pressure [Pa] */
    double x_max;    /* position of the peak [m] */
    double load;     /* integral of p dx over [xa, xb], trapezoid rule [N/m] */
    int iterations;  /* active-set iterations (Reynolds condition), else 0 */
    int n_cavitated; /* nodes held at p = 0 by the complementarity condition */
} lub_reynolds_result;

/* Defaults for the optional fields (tolerance, iterations, no squeeze, no face gaps). */
void lub_reynolds_problem_init(lub_reynolds_problem *pb);

/* Solve.  On success fills res and returns LUB_REYNOLDS_OK; otherwise res->p is undefined.
 *
 * Derived figures: p_max is the largest nodal pressure refined by the parabola through it and
 * its neighbours (x_max the vertex).  x_exit is, for the Reynolds condition, the first point
 * downstream of the peak where dp/dx = 0, i.e. where the volume flux (carried on from the
 * peak by the discrete conservation law) equals Um h: second-order accurate, not just the
 * cell of the discrete free boundary; xb when the film is full up to the outlet.  For the
 * given-exit condition it is the given x, otherwise the first zero crossing of p downstream
 * of the peak (linear interpolation), or xb if p stays positive. */
lub_reynolds_status lub_reynolds_solve(const lub_reynolds_problem *pb, lub_reynolds_result *res);

/* The inflection points of a pressure curve nearest its peak, one on each side (the
 * multi-resolution start-up check: the thesis puts the fine/coarse boundary a1 upstream of
 * the inflection point of the Reynolds pressure, methods.md §3).  p holds n + 1 values at the
 * nodes of a uniform grid on [xa, xb]; the peak is the largest node value.  Going out from
 * the peak, the second difference p_{i-1} - 2 p_i + p_{i+1} (negative at a smooth peak) first
 * turns positive between two nodes: the inflection point is its zero there, by linear
 * interpolation.  A side where the pressure falls to p <= 0 (the inlet, the free exit, a
 * cavitated stretch) or reaches the grid's end first has none: *xl (*xr) then gets that
 * end of the pressurised film.  Returns -1 when no node has p > 0 (nothing set), else a bit
 * set: 1 when the upstream point (x < peak) was found, 2 the downstream one. */
int lub_reynolds_inflections(int n, double xa, double xb, const double *p, double *xl, double *xr);

/* Node coordinate i of the problem's grid. */
static inline double lub_reynolds_node_x(const lub_reynolds_problem *pb, int i)
{
    return pb->xa + (pb->xb - pb->xa) * (double)i / (double)pb->n;
}

#endif
