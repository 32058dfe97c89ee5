/* lubFoam: start-up checks of a multi-resolution case's fine/coarse boundaries (methods.md §3,
 * thesis §2-2 and case 7 of §3), printed after the Courant and diffusion numbers.  They warn
 * (stderr, "lubFoam: warning: ...") and never stop the run: a boundary in a bad place gives
 * poor results, not a failure.  For every boundary a (a1, a2 of models/multiResolution/levels.h):
 *
 *   1. the film across x = a, in coarse particles: the clearance between the walls there (or,
 *      without an upper wall, the depth of the fluid particleGen fills; lub_levels_gap)
 *      divided by the coarse level's l0.  Fewer than 4 is a warning (between two walls only at
 *      an inlet boundary, where the moving walls drag the oil into the fine region: a1 for
 *      walls moving in +x): the
 *      thesis lost the inlet film with too few coarse particles across the gap at a1
 *      (Nr = 16) and asks for 4-5; at an outlet it is a note (past the rupture the gap is
 *      not full).
 *
 *   2. the Reynolds pressure there, when the case has system/reynoldsRefDict.yaml: the rigid
 *      reference is solved as reynoldsRef solves it (milliseconds), and a boundary between
 *      the inflection points of p(x) on each side of its peak (where the pressure is high)
 *      is a warning: the thesis puts a1 upstream of the inflection point.  Without the
 *      dictionary one line says that the check is skipped; a dictionary reynoldsRef would
 *      reject, or a failed solve, is a warning naming the problem, and the run goes on.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/error.h"
#include "core/timer.h"
#include "geometry/geometry.h"
#include "lubFoam.h"
#include "models/multiResolution/levels.h"
#include "reynolds/refcase.h"
#include "reynolds/reynolds.h"

/* The thesis' rule: at least 4-5 coarse particles across the gap at a1 (methods.md §3). */
#define MIN_ACROSS 4.0

/* "a1" / "a2" (with more than two levels: "a1 of level k"). */
static void boundary_name(const lub_levels *L, const lub_level_boundary *b, char *buf, size_t size)
{
    if (L->nlevels == 2)
        snprintf(buf, size, "a%d", b->side + 1);
    else
        snprintf(buf, size, "a%d of level %d", b->side + 1, b->fine);
}

/* 1. coarse particles across the film at each boundary.  Between two walls the rule is the
 * inlet's: where the walls drag the oil into the fine region the film fills the gap; at the
 * outlet, past the film's rupture, the gap is mostly empty and the count only informs.  A
 * film without an upper wall is checked at both ends.  inlet_side: the side
 * (0 a1, 1 a2) of the inlet boundaries, from the mean x-velocity of the moving walls, or -1
 * (no moving wall: every boundary is checked). */
static void check_gaps(const lub_levels *L, const lub_geometry *g, int inlet_side)
{
    for (int i = 0; i < L->nboundaries; i++) {
        const lub_level_boundary *b = &L->boundary[i];
        const double l0 = L->level[b->coarse].l0;
        char name[64];
        boundary_name(L, b, name, sizeof name);
        lub_level_gap gp;
        lub_levels_gap(g, b->x, 0.25 * L->level[0].l0, &gp);
        if (gp.kind == LUB_GAP_NONE) {
            lub_message("multiResolution: no fluid at %s = %g m in system/particleGenDict.yaml: "
                        "the film across it is not checked",
                        name, b->x);
            continue;
        }
        const double across = gp.h / l0;
        char what[256];
        if (gp.kind == LUB_GAP_WALLS)
            snprintf(what, sizeof what, "the gap (between '%s' and '%s')",
                     g->walls[gp.wall_lo].name, g->walls[gp.wall_hi].name);
        else
            snprintf(what, sizeof what, "the fluid depth (no %s wall there)",
                     gp.wall_hi < 0 ? "upper" : "lower");
        char fix[96] = "";
        if (gp.kind == LUB_GAP_WALLS) snprintf(fix, sizeof fix, "move %s outward or ", name);
        if (across < MIN_ACROSS * (1 - 1e-9) && gp.kind == LUB_GAP_WALLS && inlet_side >= 0 &&
            b->side != inlet_side)
            lub_message("multiResolution: at the outlet boundary %s = %g m %s is %.3g m, %.2f "
                        "coarse particles across (l0 %g): fewer than the 4-5 the thesis asks "
                        "for at the inlet, where the film fills the gap; past the film's "
                        "rupture the gap is not full",
                        name, b->x, what, gp.h, across, l0);
        else if (across < MIN_ACROSS * (1 - 1e-9))
            lub_warning("multiResolution: at the boundary %s = %g m %s is %.3g m, %.2f coarse "
                        "particles across (l0 %g); the thesis needs at least 4-5 (methods.md 3): "
                        "%slower Nr",
                        name, b->x, what, gp.h, across, l0, fix);
        else
            lub_message("multiResolution: at %s = %g m %s is %.3g m: %.2f coarse particles "
                        "across (l0 %g; at least 4-5 needed, methods.md 3)",
                        name, b->x, what, gp.h, across, l0);
    }
}

/* The rigid Reynolds reference of the case, as reynoldsRef solves it. */
typedef struct {
    lub_refcase rc;
    lub_refgap G;
    double *p;
    lub_reynolds_result res;
    lub_reynolds_status st;
} reference;

static void reference_solve(reference *f, const lub_case *c)
{
    lub_refcase_read(&f->rc, c);
    if (f->rc.ehl) return; /* lubFoam refuses elasticWall with multiResolution */
    lub_refgap_sample(&f->G, &f->rc);
    f->p = lub_malloc((size_t)(f->G.n + 1) * sizeof *f->p);
    f->st = lub_refcase_solve(&f->rc, &f->G, f->p, &f->res);
}

static void reference_free(reference *f)
{
    free(f->p);
    lub_refgap_free(&f->G);
    lub_refcase_free(&f->rc);
    free(f);
}

/* p at x by linear interpolation on the reference's grid (x inside it). */
static double reference_p(const reference *f, double x)
{
    const lub_refgap *G = &f->G;
    double s = (x - G->xa) / G->dx;
    int i = (int)floor(s);
    if (i < 0) i = 0;
    if (i > G->n - 1) i = G->n - 1;
    s -= i;
    return (1 - s) * f->p[i] + s * f->p[i + 1];
}

/* 2. the boundaries against the Reynolds pressure's inflection points */
static void check_reynolds(const lub_levels *L, const lub_case *c)
{
    char path[LUB_PATH_MAX];
    struct stat st;
    if (stat(lub_case_path(c, path, "system/reynoldsRefDict.yaml"), &st) != 0) {
        lub_message("multiResolution: no system/reynoldsRefDict.yaml: the boundaries are not "
                    "checked against the Reynolds pressure (a1 upstream of its inflection "
                    "point, methods.md 3)");
        return;
    }
    /* errors of the reference's dictionaries become a warning; what they allocated before
     * the error is freed with the reference (f is zeroed: the frees take a partial one) */
    reference *f = lub_calloc(1, sizeof *f);
    double t0 = lub_wtime();
    lub_catcher catcher;
    if (lub_error_catch(&catcher) == 0) {
        reference_solve(f, c);
        lub_error_uncatch();
    } else {
        lub_warning("multiResolution: the boundaries are not checked against the Reynolds "
                    "pressure: its reference cannot be built (reynoldsRef would stop): %s",
                    catcher.message);
        reference_free(f);
        return;
    }
    t0 = lub_wtime() - t0;
    if (f->rc.ehl) {
        lub_message("multiResolution: the Reynolds reference is soft EHL: the boundaries are "
                    "not checked against its pressure");
    } else if (f->st != LUB_REYNOLDS_OK) {
        lub_warning("multiResolution: the boundaries are not checked against the Reynolds "
                    "pressure: the solve of system/reynoldsRefDict.yaml failed: %s (%d cells "
                    "on [%g, %g] m, %s)",
                    lub_reynolds_status_string(f->st), f->G.n, f->G.xa, f->G.xb,
                    lub_reynolds_bc_names[f->rc.s.bc]);
    } else {
        double xl, xr;
        int found = lub_reynolds_inflections(f->G.n, f->G.xa, f->G.xb, f->p, &xl, &xr);
        /* for the messages: round-off about x = 0 printed as 0 */
        const double tiny = 1e-9 * (f->G.xb - f->G.xa);
        if (fabs(xl) < tiny) xl = 0.0;
        if (fabs(xr) < tiny) xr = 0.0;
        if (found < 0) {
            lub_warning("multiResolution: the boundaries are not checked against the Reynolds "
                        "pressure: it is nowhere positive (system/reynoldsRefDict.yaml, %d cells "
                        "on [%g, %g] m)",
                        f->G.n, f->G.xa, f->G.xb);
        } else {
            char sl[96], sr[96];
            snprintf(sl, sizeof sl, "%.4g m%s", xl,
                     found & 1 ? "" : " (none on this side: the end of the film)");
            snprintf(sr, sizeof sr, "%.4g m%s", xr,
                     found & 2 ? "" : " (none on this side: the end of the film)");
            lub_message("multiResolution: Reynolds reference (system/reynoldsRefDict.yaml, %d "
                        "cells on [%g, %g] m, %s; %.3g s): peak %.4g Pa at x = %.4g m, "
                        "inflection points of p(x) at x = %s and %s",
                        f->G.n, f->G.xa, f->G.xb, lub_reynolds_bc_names[f->rc.s.bc], t0,
                        f->res.p_max, f->res.x_max, sl, sr);
            for (int i = 0; i < L->nboundaries; i++) {
                const lub_level_boundary *b = &L->boundary[i];
                char name[64];
                boundary_name(L, b, name, sizeof name);
                if (b->x < f->G.xa || b->x > f->G.xb) {
                    lub_message("multiResolution: %s = %g m lies outside the reference's [%g, "
                                "%g] m, away from its pressure",
                                name, b->x, f->G.xa, f->G.xb);
                    continue;
                }
                const double pc = 100.0 * reference_p(f, b->x) / f->res.p_max;
                if (b->x > xl && b->x < xr)
                    lub_warning("multiResolution: the boundary %s = %g m lies where the "
                                "Reynolds pressure is high, between the inflection points "
                                "x = %.4g and %.4g m on each side of its peak (%.4g Pa at "
                                "x = %.4g m; system/reynoldsRefDict.yaml): p there is %.1f%% of "
                                "the peak; the thesis puts a1 upstream of the inflection point "
                                "(methods.md 3): move %s outward",
                                name, b->x, xl, xr, f->res.p_max, f->res.x_max, pc, name);
                else
                    lub_message("multiResolution: %s = %g m lies outside the high-pressure "
                                "zone between the inflection points: p there is %.1f%% of the "
                                "peak",
                                name, b->x, pc);
            }
        }
    }
    reference_free(f);
}

void lubfoam_check_levels(const lubfoam_run *r, const lub_geometry *geo)
{
    const lub_levels *L = r->scene.levels;
    if (!L) return;
    /* the direction the moving walls drag the oil: the mean x-velocity of the moving patches */
    const lub_mps_config *c = &r->scene.level[0]->c;
    double u = 0;
    int nm = 0;
    for (int p = 0; p < r->scene.level[0]->P->npatches; p++) {
        const double *v = c->patch_velocity[p];
        if (v[0] != 0 || v[1] != 0 || v[2] != 0) u += v[0], nm++;
    }
    const int inlet_side = nm == 0 || u == 0 ? -1 : u > 0 ? 0 : 1;
    check_gaps(L, geo, inlet_side);
    check_reynolds(L, &r->cs);
}

/* Every particle inside the domain (the periodic directions aside); -parallel: each rank its
 * slab's (lubfoam_collective_check). */
static void check_inside(const lubfoam_run *r, const void *ctx)
{
    const lub_geometry *geo = ctx;
    const lub_particles *P = &r->P;
    char file[LUB_PATH_MAX];
    lub_case_pathf(&r->cs, file, "%s/particles.h5", r->start_name);
    static const char *const kinds[] = {"fluid", "wall", "dummy"};
    for (size_t i = 0; i < P->n; i++)
        for (int d = 0; d < P->dim; d++) {
            if (geo->periodic[d]) continue;
            const double x = P->x[d][i];
            if (x >= geo->dmin[d] && x <= geo->dmax[d]) continue;
            char patch[LUB_NAME_MAX + 16] = "";
            if (P->kind[i] != LUB_FLUID && P->patch[i] < P->npatches)
                snprintf(patch, sizeof patch, " of patch '%s'", P->patch_names[P->patch[i]]);
            lub_fatal("%s: %s particle id %llu%s lies outside the domain of "
                      "system/particleGenDict.yaml: %c = %g outside [%g, %g] (particles of "
                      "another case or geometry? run particleGen)",
                      file, kinds[P->kind[i] < 3 ? P->kind[i] : 0], (unsigned long long)P->id[i],
                      patch, "xyz"[d], x, geo -> dmin[d], geo -> dmax[d]);
        }
}

/* The start folder's particles against system/particleGenDict.yaml, before the solver is set
 * up: particles of another case (or of an older geometry) were found only at step 1, as a
 * particle "leaving" a domain it was never in (exit 2, naming no file). */
void lubfoam_check_particles(const lubfoam_run *r, const lub_geometry *geo)
{
    char file[LUB_PATH_MAX];
    lub_case_pathf(&r->cs, file, "%s/particles.h5", r->start_name);
    const lub_particles *P = &r->P;
    if (P->dim != geo->dim)
        lub_fatal("%s: the particles are %d-D but system/particleGenDict.yaml says dimension %d "
                  "(particles of another case? run particleGen)",
                  file, P->dim, geo->dim);
    const double l0 = geo->levels[0].l0, l0p = P->levels[0].l0;
    if (fabs(l0p - l0) > 1e-9 * l0)
        lub_fatal("%s: the particles have l0 = %.10g m but system/particleGenDict.yaml says l0 = "
                  "%.10g m (particles of another geometry? run particleGen)",
                  file, l0p, l0);
    lubfoam_collective_check(r, check_inside, geo);
}
