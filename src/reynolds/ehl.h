/* lubkit soft elastohydrodynamic lubrication: the 1-D Reynolds reference with an elastic
 * cylinder under a given load (methods.md 4, 5; thesis 4-2-3).
 *
 * Unknowns: the pressure p at the nodes of the Reynolds grid (lub_reynolds_problem's grid:
 * n cells on [xa, xb], p = 0 at both ends) and the rigid-body position h0 of the cylinder.
 * Equations:
 *   - the Reynolds equation with the Reynolds (Swift-Stieber) condition on the gap
 *         h(x) = h0 + (x - x_c)^2 / (2R) + s(x) + v(x)                     (T-50)
 *     (s an optional extra undeformed shape, e.g. a lower wall that is not flat), discretised
 *     exactly as lub_reynolds_solve does it (flux form, gaps at the faces);
 *   - v(x) = sum_j C(x - x_j, dx) p_j: the half-space influence coefficients of T-46..T-49
 *     (src/models/elastic.h) with the pressure piecewise constant on the control volume
 *     [x_j - dx/2, x_j + dx/2] of each node, evaluated at the nodes and the faces;
 *   - the load balance  sum_j p_j dx = W  (the trapezoid rule, p vanishing at both ends).
 * h0 may well be negative: with the ln(l/b) reference of T-46 the displacement at the contact
 * is of order b^2/R, much more than the film; only h(x) > 0 is required.
 *
 * Method.  Newton's method on the whole discrete system, pressure and h0 together (the load
 * row borders the Jacobian; the direct iteration between pressure and deformation of the
 * thesis is known to need heavy under-relaxation at high loads).  The free exit is an active
 * set: the cavitated nodes (p = 0) of each Newton step are those of the exact complementarity
 * solution lub_reynolds_solve gives for the current gap, so the exit jumps to its place
 * instead of moving a node per iteration as the primal-dual rule p_i <= r_i/d_i would let it.
 * The Jacobian is dense (the deformation couples every node to every other): it is assembled
 * from the Toeplitz influence coefficients and factorised by a blocked LU with partial
 * pivoting, O(n^3): about 0.05 s per iteration at 1000 cells, 8 times more per doubling.
 * Globalisation: continuation in the compliance, E' = E / s with s from 0 (rigid, solved
 * first by a secant on h0 with lub_reynolds_solve) to 1 in geometric steps adapted to the
 * iterations each stage needs, with a predictor extrapolating in ln s, and a non-monotone
 * backtracking line search keeping the gap positive.  Converged when the last (full) Newton
 * step changed the film by less than tolerance h_min everywhere, the load error is below
 * tolerance W and the cavitated set did not change (the thesis stops its fixed-point
 * iteration when the relative change of h_min falls below 1e-6).  The final pressure is
 * checked against lub_reynolds_solve on the final gap: their difference is reported.
 */
#ifndef LUB_REYNOLDS_EHL_H
#define LUB_REYNOLDS_EHL_H

typedef enum {
    LUB_EHL_OK = 0,
    LUB_EHL_BAD_INPUT,     /* grid, speeds, viscosity, modulus, load, shape */
    LUB_EHL_NOT_CONVERGED, /* iterations exhausted or the continuation step collapsed */
    LUB_EHL_SINGULAR,      /* zero pivot in the Newton system */
    LUB_EHL_RIGID_FAILED   /* the first stage: no rigid film carries W on this grid */
} lub_ehl_status;

const char *lub_ehl_status_string(lub_ehl_status s);

/* The problem.  Arrays are borrowed. */
typedef struct {
    int n;                    /* cells; n + 1 nodes (n >= 4) */
    double xa, xb;            /* inlet and outlet, xa < xb */
    double u1, u2;            /* tangential speeds of the lower and upper surface [m/s] */
    double mu;                /* dynamic viscosity [Pa s] */
    double radius;            /* R of the undeformed cylinder [m] */
    double x_centre;          /* x_c of its lowest point [m] */
    const double *shape;      /* extra undeformed gap at the n + 1 nodes, or NULL */
    const double *shape_face; /* ... and at the n faces (required with shape) */
    double E;                 /* equivalent modulus E' of T-46 [Pa] */
    double load;              /* W [N/m] */
    double b;                 /* reference length of the ln(l/b) term; 0: Hertz b (T-49) */
    double tolerance;         /* see above (0: default 1e-8) */
    int max_iterations;       /* Newton iterations over all stages (0: default 400) */
    double lcp_tolerance;     /* tolerance of the final lub_reynolds_solve (0: 1e-12) */
} lub_ehl_problem;

/* The solution.  p, h (and v if not NULL) are the caller's arrays of n + 1 values. */
typedef struct {
    double *p;          /* pressure at the nodes [Pa] (filled) */
    double *h;          /* film thickness at the nodes [m] (filled) */
    double *v;          /* elastic displacement at the nodes [m] (filled if not NULL) */
    double h0;          /* rigid-body position of T-50 [m] (may be negative) */
    double h0_rigid;    /* the rigid cylinder's h0 (= film) for the same load [m] */
    double h_min;       /* minimum film (nodes and faces, refined by a parabola) [m] */
    double x_min;       /* its position [m] */
    double h_centre;    /* film at x_c [m] */
    double p_max;       /* peak pressure (parabola through the largest node) [Pa] */
    double x_max;       /* its position [m] */
    double x_exit;      /* free exit (lub_reynolds_solve's flux-based exit) [m] */
    double load;        /* sum p dx [N/m] */
    double load_error;  /* (load - W) / W */
    double change;      /* last Newton step: max |dh| / h_min */
    double hmin_change; /* last Newton step: |d h_min| / h_min (the thesis' criterion) */
    double lcp_diff;    /* max |p - p_LCP(h)| / p_max, p_LCP the exact solve on the final h */
    double b;           /* reference length used in ln(l/b) [m] */
    int iterations;     /* Newton iterations (= factorisations), all stages */
    int stages;         /* continuation stages (accepted) */
    int n_cavitated;    /* nodes held at p = 0 */
} lub_ehl_result;

/* Defaults for the optional fields. */
void lub_ehl_problem_init(lub_ehl_problem *pb);

/* Solve.  Allocates its work (O(n^2) for the Newton matrix) and frees it.  On failure res
 * holds the last iterate (p, h and the figures) for inspection. */
lub_ehl_status lub_ehl_solve(const lub_ehl_problem *pb, lub_ehl_result *res);

#endif
