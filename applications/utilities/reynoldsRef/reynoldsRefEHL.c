/* reynoldsRef, soft-EHL mode (methods.md 4, 5; thesis 4-2-3): the elastic cylinder of the
 * elasticWall model floating on the film under its load.  The program only gathers the input
 * and writes the output; the coupled solve is src/reynolds/ehl.c. */
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/timer.h"
#include "reynolds/ehl.h"
#include "reynolds/refcase.h"
#include "reynolds/reynolds.h"
#include "reynoldsRef.h"

/* The lower wall's height below its height at x_c, at the nodes and faces (the extra
 * undeformed gap of a lower wall that is not a plane parallel to x), or 0 when it is one. */
static int lower_shape(const lub_refcase *rc, const lub_refgap *G, double *shape,
                       double *shape_face)
{
    const lub_wall *w = rc->lower;
    if (w->type == LUB_WALL_PLANE && fabs(w->normal[0]) < 1e-12) return 0;
    double yc;
    if (!lub_wall_height(w, rc->ew.x_centre, 0, &yc))
        lub_node_error(rc->s.lower_node,
                       "soft EHL: the lower wall '%s' has no surface under the lowest point of "
                       "the cylinder (x = %g m)",
                       rc->s.lower, rc->ew.x_centre);
    for (int i = 0; i <= 2 * G->n; i++) {
        double x = G->xa + 0.5 * i * G->dx, y = yc;
        lub_wall_height(w, x, 0, &y); /* spans [inlet, outlet]: checked when G was sampled */
        if (i % 2 == 0)
            shape[i / 2] = yc - y;
        else
            shape_face[i / 2] = yc - y;
    }
    return 1;
}

void reynoldsRef_soft_ehl(const lub_case *c, const lub_refcase *rc, const lub_refgap *G,
                          const char *out_file, const char *tname, int dimensionless,
                          double t_start)
{
    const lub_refcase_settings *s = &rc->s;
    const lub_elastic_wall *ew = &rc->ew;
    int n = G->n;
    size_t nn = (size_t)n + 1;
    double *shape = lub_malloc(nn * sizeof *shape), *shape_face = lub_malloc(nn * sizeof *shape);
    int shaped = lower_shape(rc, G, shape, shape_face);

    lub_ehl_problem pb;
    lub_ehl_problem_init(&pb);
    pb.n = n;
    pb.xa = G->xa;
    pb.xb = G->xb;
    pb.u1 = rc->u1;
    pb.u2 = rc->u2;
    pb.mu = rc->mu;
    pb.radius = ew->radius;
    pb.x_centre = ew->x_centre;
    pb.shape = shaped ? shape : NULL;
    pb.shape_face = shaped ? shape_face : NULL;
    pb.E = ew->E;
    pb.load = ew->load;
    pb.b = ew->b;
    pb.tolerance = s->ehl_tolerance;
    pb.max_iterations = (int)s->ehl_max_iterations;
    pb.lcp_tolerance = s->tolerance;
    double *p = lub_malloc(nn * sizeof *p), *h = lub_malloc(nn * sizeof *h);
    lub_ehl_result res = {.p = p, .h = h};
    double t_solve = lub_wtime();
    lub_ehl_status st = lub_ehl_solve(&pb, &res);
    t_solve = lub_wtime() - t_solve;
    if (st != LUB_EHL_OK) {
        free(shape), free(shape_face), free(p), free(h); /* nothing left for LeakSanitizer */
        lub_fatal_run("the soft-EHL solve failed: %s after %d Newton iterations in %d "
                      "continuation stages (%d cells on [%g, %g]; last change of the film %.3g, "
                      "load error %.3g; softEHL maxIterations %ld, tolerance %g)",
                      lub_ehl_status_string(st), res.iterations, res.stages, n, G->xa, G->xb,
                      res.change, res.load_error, s->ehl_max_iterations, s->ehl_tolerance);
    }

    lub_refscales d;
    if (dimensionless) lub_refcase_scales(rc, G, &d);
    char written[LUB_PATH_MAX];
    reynoldsRef_table_write(c, out_file, tname, G, h, p, dimensionless ? &d : NULL, written);

    lub_message("grid        %d cells on [%g, %g] m, dx = %.4g m", n, G->xa, G->xb, G->dx);
    lub_message("walls       lower '%s' U1 = %g m/s%s, upper '%s' elastic (at rest)", s->lower,
                rc->u1, shaped ? " (not flat)" : "", s->upper);
    lub_message("oil         rho = %g kg/m^3, nu = %g m^2/s, mu = %g Pa s", rc->rho, rc->nu,
                rc->mu);
    lub_message("elastic     E = %g Pa, W = %g N/m, R = %g m: b = %.6g m, p_H = %.6g Pa "
                "(T-49, T-55)",
                ew->E, ew->load, ew->radius, ew->b, ew->p_hertz);
    lub_message("condition   reynolds (p >= 0; p = dp/dx = 0 at the free exit), %d cavitated "
                "nodes",
                res.n_cavitated);
    lub_message("iterations  %d Newton in %d continuation stages; last change of the film "
                "%.2g, of h_min %.2g (relative)",
                res.iterations, res.stages, res.change, res.hmin_change);
    lub_message("film        h_min = %.6g m at x = %.6g m, h(0) = %.6g m at x_c = %g m", res.h_min,
                res.x_min, res.h_centre, ew->x_centre);
    lub_message("position    h0 = %.6g m (T-50: y = h0 + x^2/(2R) + v; a rigid cylinder "
                "would float at %.6g m)",
                res.h0, res.h0_rigid);
    lub_message("exit        x = %.6g m%s", res.x_exit,
                res.x_exit >= G->xb ? " (the outlet: the film is full up to it)" : "");
    lub_message("peak        p = %.6g Pa at x = %.6g m", res.p_max, res.x_max);
    lub_message("load        W = %.10g N/m, error %.2g (relative to %g)", res.load, res.load_error,
                ew->load);
    lub_message("check       max |p - p_LCP(h)| / p_max = %.2g (exact complementarity solve "
                "on the final gap)",
                res.lcp_diff);
    if (dimensionless) {
        lub_message("scales      X = x/b, P = p/p_H, H = h R/b^2 (T-54..T-58)");
        lub_message("film        H_min = %.6f at X = %.5f, H(0) = %.6f", res.h_min / d.h0,
                    res.x_min / d.sx, res.h_centre / d.h0);
        lub_message("peak        P = %.5f at X = %.5f", res.p_max * d.sp, res.x_max / d.sx);
        lub_message("exit        X = %.5f", res.x_exit / d.sx);
    }
    lub_message("written     %s", written);
    lub_message("time        solve %.3g s, total %.3g s", t_solve, lub_wtime() - t_start);
    free(shape);
    free(shape_face);
    free(p);
    free(h);
}
