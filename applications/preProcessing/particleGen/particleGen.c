/* particleGen: turn system/particleGenDict.yaml into the initial particles 0/particles.h5.
 *
 * Reads the geometry (walls, fluid regions, levels), discretises it on the particle lattice,
 * prints the counts per kind, patch and level and the bounding box, and (unless -dryRun)
 * writes 0/particles.h5 + 0/particles.xdmf inside an atomic time folder, then the case-level
 * particles.xdmf.  Nothing is written unless the whole generation succeeded.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/args.h"
#include "core/error.h"
#include "geometry/discretise.h"
#include "geometry/geometry.h"
#include "io/case.h"
#include "particles/particles_io.h"
#include "particles/particles.h"

static const char *const kind_names[] = {"fluid", "wall", "dummy"};

static void print_report(const lub_geometry *g, const lub_particles *P, const size_t *rc)
{
    size_t kind[3] = {0, 0, 0}, level[LUB_MAX_LEVELS][3];
    size_t patch[LUB_MAX_PATCHES][3];
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    memset(level, 0, sizeof level);
    memset(patch, 0, sizeof patch);
    for (size_t i = 0; i < P->n; i++) {
        int k = P->kind[i];
        kind[k]++;
        level[P->level[i]][k]++;
        if (k != LUB_FLUID) patch[P->patch[i]][k]++;
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], P->x[d][i]);
            hi[d] = fmax(hi[d], P->x[d][i]);
        }
    }
    lub_message("particles: %zu (fluid %zu, wall %zu, dummy %zu)", P->n, kind[LUB_FLUID],
                kind[LUB_WALL], kind[LUB_DUMMY]);
    for (int k = 0; k < P->nlevels; k++)
        lub_message("  level %d: l0 = %g, re = %g, n0 = %.10g, lambda0 = %.10g: %zu "
                    "(fluid %zu, wall %zu, dummy %zu)",
                    k, P->levels[k].l0, P->levels[k].re, P->levels[k].n0, P->levels[k].lambda0,
                    level[k][0] + level[k][1] + level[k][2], level[k][0], level[k][1], level[k][2]);
    for (int p = 0; p < P->npatches; p++)
        lub_message("  patch %s: %zu (wall %zu, dummy %zu)", P->patch_names[p],
                    patch[p][LUB_WALL] + patch[p][LUB_DUMMY], patch[p][LUB_WALL],
                    patch[p][LUB_DUMMY]);
    for (int r = 0; r < g->nregions; r++)
        lub_message("  fluid region %d (line %d): %zu", r, lub_node_line(g->regions[r].node),
                    rc[r]);
    if (P->dim == 2)
        lub_message("bounding box: [%.9g, %.9g] x [%.9g, %.9g]", lo[0], hi[0], lo[1], hi[1]);
    else
        lub_message("bounding box: [%.9g, %.9g] x [%.9g, %.9g] x [%.9g, %.9g]", lo[0], hi[0], lo[1],
                    hi[1], lo[2], hi[2]);
    (void)kind_names;
}

int main(int argc, char **argv)
{
    static int dry = 0;
    lub_option opts[] = {{"-dryRun", NULL, "print the counts and the bounding box, write nothing",
                          LUB_OPT_FLAG, &dry},
                         {0}};
    lub_program_info info = {
        .name = "particleGen",
        .summary = "generate the initial particles 0/particles.h5 from the case geometry",
        .usage = "[OPTIONS]",
        .description = "Walls get one layer of wall particles on their surface and dummyLayers "
                       "layers behind;\nfluid regions are filled on a square (cubic) lattice of "
                       "spacing l0 per level\n(with `jitter`, each fluid particle is then moved "
                       "off it by up to amplitude l0);\na cylinder or sphere with fluidLayers K "
                       "has its first K rows of fluid on the\nsurfaces R +- k l0 instead "
                       "(body-fitted).\nPrints counts per kind, patch and level.",
        .dictionaries = "system/particleGenDict.yaml",
        .time_selection = 0,
        .has_case = 1,
        .min_args = 0,
        .max_args = 0};
    lub_args a;
    lub_args_parse(&a, argc, argv, &info, opts);

    lub_case cs;
    lub_case_open(&cs, a.case_dir);
    char path[LUB_PATH_MAX];
    lub_case_path(&cs, path, "system/particleGenDict.yaml");

    lub_geometry g;
    lub_geometry_read(&g, path);
    lub_particles P;
    size_t *rc = lub_calloc(g.nregions ? (size_t)g.nregions : 1, sizeof *rc);
    lub_geometry_discretise(&g, &P, 0.0, rc);
    print_report(&g, &P, rc);

    if (!dry) {
        char dir[LUB_PATH_MAX];
        lub_timedir_begin(&cs, "0", dir);
        /* a failed write removes the temporary folder: no half-written 0/ stays behind */
        lub_catcher cat;
        if (lub_error_catch(&cat) == 0) {
            lub_particles_write(&P, dir);
            lub_error_uncatch();
        } else {
            lub_rm_rf(dir);
            fprintf(stderr, "%s: error: %s\n", lub_program(), cat.message);
            return cat.status;
        }
        lub_timedir_commit(&cs, "0", dir);
        lub_case_xdmf_write(&cs);
        lub_message("wrote %s", lub_case_path(&cs, path, "0/particles.h5"));
    } else {
        lub_message("dry run: nothing written");
    }
    free(rc);
    lub_particles_free(&P);
    lub_geometry_free(&g);
    return 0;
}
