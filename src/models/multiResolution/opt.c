/* lubkit MPS: the overlapping particle technique, multi-resolution driver (see opt.h). */
#include "models/multiResolution/opt.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "geometry/discretise.h"
#include "mps/operators.h"
#include "particles/weight.h"

/* ---- particles: split, fill, merge ------------------------------------------------------ */

/* Particle i of src into slot k of dst (room reserved; extra fields in the same order; dst
 * may be src, with k <= i). */
static void put_particle(lub_particles *dst, size_t k, const lub_particles *src, size_t i)
{
    for (int d = 0; d < 3; d++) {
        dst->x[d][k] = src->x[d][i];
        dst->u[d][k] = src->u[d][i];
    }
    dst->p[k] = src->p[i];
    dst->kind[k] = src->kind[i];
    dst->patch[k] = src->patch[i];
    dst->level[k] = src->level[i];
    dst->id[k] = src->id[i];
    for (int e = 0; e < src->nextra; e++) dst->extra[e].v[k] = src->extra[e].v[i];
}

/* Append particle i of src to dst. */
static void copy_particle(lub_particles *dst, const lub_particles *src, size_t i)
{
    put_particle(dst, dst->n++, src, i);
}

/* The margins of level k: the parts of its extended region it does not own, as closed
 * intervals (a periodic one may reach past the domain's x; split by the caller). */
static int margins(const lub_levels *L, int k, double iv[4][2])
{
    const lub_level_def *v = &L->level[k];
    int n = 0;
    if (k < L->nlevels - 1) { /* past its own region, into the coarser level's */
        if (v->bounded[0]) iv[n][0] = v->ext[0], iv[n++][1] = v->region[0];
        if (v->bounded[1]) iv[n][0] = v->region[1], iv[n++][1] = v->ext[1];
    }
    if (k > 0) { /* inside the finer level's region, up to its hole */
        const lub_level_def *f = &L->level[k - 1];
        if (f->bounded[0]) iv[n][0] = f->region[0], iv[n++][1] = v->hole[0];
        if (f->bounded[1]) iv[n][0] = v->hole[1], iv[n++][1] = f->region[1];
    }
    return n;
}

/* x in the closed interval [a, b] (periodic: some image of x). */
static int in_interval(const lub_levels *L, double x, double a, double b)
{
    if (!L->periodic) return x >= a && x <= b;
    const double period = L->xmax - L->xmin;
    const double y = a + fmod(x - a, period);
    return (y >= a ? y : y + period) <= b;
}

/* Level k's particles that the geometry puts in its margins, when a margin holds none of
 * the level's particles yet (a start from particleGen's file), into G (initialised here;
 * fluid at rest).  The particles must lie in the level's extended region and outside the
 * part of x it owns. */
static void fill_margins(const lub_levels *L, const lub_geometry *g, const lub_particles *P, int k,
                         lub_particles *G)
{
    lub_particles_init(G, g->dim, 16);
    double iv[4][2];
    const int n = margins(L, k, iv);
    for (int m = 0; m < n; m++) {
        int empty = 1;
        for (size_t i = 0; i < P->n && empty; i++) {
            if (P->level[i] != k) continue;
            lub_level_where w;
            lub_levels_locate(L, P->x[0][i], &w);
            if (w.owner != k && in_interval(L, P->x[0][i], iv[m][0], iv[m][1])) empty = 0;
        }
        if (!empty) continue;
        /* the interval in the domain's x: one piece, or two across a periodic seam */
        double piece[2][2];
        int np = 0;
        const double period = L->xmax - L->xmin;
        double a = iv[m][0], b = iv[m][1];
        if (L->periodic && a < L->xmin) {
            piece[np][0] = a + period, piece[np++][1] = L->xmax;
            a = L->xmin;
        }
        if (L->periodic && b > L->xmax) {
            piece[np][0] = L->xmin, piece[np++][1] = b - period;
            b = L->xmax;
        }
        piece[np][0] = a, piece[np++][1] = b;
        for (int q = 0; q < np; q++) {
            if (!(piece[q][0] <= piece[q][1])) continue;
            lub_particles R;
            lub_geometry_discretise_range(g, k, piece[q][0], piece[q][1], &R);
            for (size_t i = 0; i < R.n; i++) {
                lub_level_where w;
                lub_levels_locate(L, R.x[0][i], &w);
                if (w.owner == k || !(w.present & (1u << k))) continue;
                double x[3] = {R.x[0][i], R.x[1][i], R.x[2][i]};
                int patch = 0;
                if (R.kind[i] != LUB_FLUID) {
                    patch = lub_particles_find_patch(P, R.patch_names[R.patch[i]]);
                    if (patch < 0)
                        lub_bug("fill_margins: no patch '%s'", R.patch_names[R.patch[i]]);
                }
                lub_particles_add(G, x, R.kind[i], patch, k);
            }
            lub_particles_free(&R);
        }
    }
}

/* The fill fraction of a level's fluid at its free surface: the PND of a half-space of the
 * regular lattice (spacing 1, rows y <= 0, every lattice point) at half a spacing above its
 * top row, over n0 (T-4).  The top row's particles represent the fluid up to there, so a
 * point where the fraction n_fluid / (n0 - n_wall) exceeds this lies inside the fluid the
 * level represents (0.601 in 2-D at re = 3.1 l0; 0.744 at 2.1, 0.558 at 4.0). */
static double surface_fraction(int dim, double re_l0)
{
    const int m = (int)ceil(re_l0) + 1, mz = dim == 3 ? m : 0;
    double n0, lambda0, s = 0.0;
    lub_mps_reference(dim, 1.0, re_l0, &n0, &lambda0);
    for (int c = -mz; c <= mz; c++)
        for (int b = -m; b <= 0; b++)
            for (int a = -m; a <= m; a++) {
                const double y = b - 0.5;
                s += lub_mps_weight(sqrt((double)a * a + y * y + (double)c * c), re_l0);
            }
    return s / n0;
}

/* The generation cells of level k (opt.h, lub_opt_transfer): the level's lattice points in
 * its generation layers, one l0 wide inside each edge of its extended region beyond which
 * another level lies (locate's `generate`), where particleGen's rules allow fluid; the walls
 * that a model moves (o->moved, lub_opt_moving_wall) are left out of those rules. */
static void generation_cells(lub_opt *o, const lub_geometry *g, int k)
{
    const lub_levels *L = &o->L;
    const lub_level_def *v = &L->level[k];
    const double l0 = v->l0, eps = 1e-6 * l0;
    double iv[4][2];
    int n = 0;
    if (k < L->nlevels - 1) {
        if (v->bounded[0]) iv[n][0] = v->ext[0], iv[n++][1] = v->ext[0] + l0 - eps;
        if (v->bounded[1]) iv[n][0] = v->ext[1] - l0 + eps, iv[n++][1] = v->ext[1];
    }
    if (k > 0 && v->has_hole) {
        if (isfinite(v->hole[0])) iv[n][0] = v->hole[0] - l0 + eps, iv[n++][1] = v->hole[0];
        if (isfinite(v->hole[1])) iv[n][0] = v->hole[1], iv[n++][1] = v->hole[1] + l0 - eps;
    }
    /* the geometry with one fluid region, the whole domain: fluid wherever it may be */
    lub_geometry any = *g;
    lub_region box;
    memset(&box, 0, sizeof box);
    box.type = LUB_REGION_BOX;
    for (int d = 0; d < 3; d++) box.min[d] = g->dmin[d], box.max[d] = g->dmax[d];
    any.nregions = 1;
    any.regions = &box;
    lub_wall walls[LUB_MAX_PATCHES];
    any.nwalls = 0;
    any.walls = walls;
    for (int i = 0; i < g->nwalls && any.nwalls < LUB_MAX_PATCHES; i++) {
        int p = lub_particles_find_patch(&o->P[k], g->walls[i].name);
        if (p < 0 || !o->moved[p]) walls[any.nwalls++] = g->walls[i];
    }
    size_t cap = 0;
    for (int m = 0; m < n; m++) {
        lub_particles R;
        lub_geometry_discretise_range(&any, k, iv[m][0], iv[m][1], &R);
        for (size_t i = 0; i < R.n; i++) {
            if (R.kind[i] != LUB_FLUID) continue;
            if (o->ngen[k] == cap) {
                cap = cap ? 2 * cap : 64;
                o->gen[k] = lub_realloc(o->gen[k], 3 * cap * sizeof(double));
            }
            for (int d = 0; d < 3; d++) o->gen[k][3 * o->ngen[k] + d] = R.x[d][i];
            o->ngen[k]++;
        }
        lub_particles_free(&R);
    }
    const size_t m = o->ngen[k] ? o->ngen[k] : 1;
    o->gen_ok[k] = lub_calloc(m, 1);
    o->gen_val[k] = lub_calloc(7 * m, sizeof(double));
}

/* Every moving wall must be a plane sliding along itself, or moved by a model that keeps x
 * (opt.h, Walls). */
static void check_walls(const lub_particles *P, const lub_mps_config *c, const lub_geometry *g)
{
    for (int p = 0; p < P->npatches; p++) {
        const double *v = c->patch_velocity[p];
        const lub_wall *w = NULL;
        for (int i = 0; i < g->nwalls; i++)
            if (strcmp(g->walls[i].name, P->patch_names[p]) == 0) w = &g->walls[i];
        /* a wall moved by a model keeps its particles' x (elasticWall: vertically only;
         * mps.h still_walls), so each level's part of it stays in the level's part of x */
        if (c->patch_moved[p]) continue;
        const double s = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (!(s > 0)) continue;
        double vn = 0;
        if (w)
            for (int d = 0; d < 3; d++) vn += v[d] * w->normal[d];
        if (!w || w->type != LUB_WALL_PLANE || w->has_range || fabs(vn) > 1e-9 * s) {
            const char *why = !w                          ? "is not a wall of the geometry"
                              : w->type != LUB_WALL_PLANE ? "is not a plane"
                              : w->has_range              ? "is a plane with a range in x"
                                                          : "moves across its normal";
            if (w)
                lub_node_error(w->node,
                               "multiResolution: the wall '%s' moves (movingWalls velocity %g, "
                               "%g) but %s: in a multi-resolution run the wall particles keep "
                               "their positions and only carry the velocity, which is right "
                               "for a plane without ends sliding along itself only",
                               P->patch_names[p], v[0], v[1], why);
            lub_fatal("multiResolution: the moving wall '%s' %s", P->patch_names[p], why);
        }
    }
}

void lub_opt_init(lub_opt *o, const lub_levels *L, const lub_particles *P, const lub_mps_config *c,
                  const lub_geometry *g, double headroom)
{
    memset(o, 0, sizeof *o);
    o->L = *L;
    o->nlevels = L->nlevels;
    o->dim = P->dim;
    if (P->nlevels != L->nlevels)
        lub_bug("lub_opt_init: particles with %d levels, %d in the levels", P->nlevels, L->nlevels);
    check_walls(P, c, g);
    uint64_t next = 0;
    for (size_t i = 0; i < P->n; i++)
        if (P->id[i] >= next) next = P->id[i] + 1;

    for (int k = 0; k < o->nlevels - 1; k++) {
        const lub_level_def *v = &L->level[k];
        if (L->periodic && (v->ext[0] < L->xmin || v->ext[1] > L->xmax))
            lub_fatal("multiResolution: level %d's extended region [%g, %g] (its region and the "
                      "overlap margins) reaches across the periodic seam of x [%g, %g]: shift "
                      "the domain (or the region) so that it lies inside",
                      k, v->ext[0], v->ext[1], L->xmin, L->xmax);
    }

    lub_mps_config cfg = *c;
    cfg.fixed_flags = 1;
    cfg.still_walls = 1;
    for (int k = 0; k < o->nlevels; k++) {
        lub_particles G;
        fill_margins(L, g, P, k, &G);
        generation_cells(o, g, k);
        o->fill[k] = surface_fraction(o->dim, c->re_l0);
        size_t cnt = 0;
        for (size_t i = 0; i < P->n; i++) cnt += P->level[i] == k;
        /* room for the particles generated later: headroom, and 4 per generation cell (a
         * level that starts nearly empty and fills up through its generation layers) */
        const size_t total = cnt + G.n + 4 * o->ngen[k];
        lub_particles *Q = &o->P[k];
        lub_particles_init(Q, P->dim, (size_t)((double)total * (1.0 + headroom)) + 16);
        Q->time = P->time;
        Q->step = P->step;
        Q->nlevels = 1;
        Q->levels[0] = P->levels[k];
        Q->npatches = P->npatches;
        memcpy(Q->patch_names, P->patch_names, sizeof Q->patch_names);
        for (int e = 0; e < P->nextra; e++) lub_particles_extra(Q, P->extra[e].name);
        for (size_t i = 0; i < P->n; i++)
            if (P->level[i] == k) copy_particle(Q, P, i);
        for (size_t i = 0; i < G.n; i++) {
            const size_t j = Q->n++;
            for (int d = 0; d < 3; d++) Q->x[d][j] = G.x[d][i], Q->u[d][j] = 0.0;
            Q->p[j] = 0.0;
            Q->kind[j] = G.kind[i];
            Q->patch[j] = G.patch[i];
            Q->level[j] = (uint8_t)k;
            Q->id[j] = next++;
            for (int e = 0; e < Q->nextra; e++) Q->extra[e].v[j] = 0.0;
        }
        o->filled[k] = G.n;
        lub_particles_free(&G);
        if (cnt == 0)
            lub_fatal("multiResolution: level %d (l0 %g) has no particles in the particle file", k,
                      P->levels[k].l0);
        lub_mps_init(&o->m[k], Q, &cfg, g->dmin, g->dmax, g->periodic);
        /* the neighbour search's particle arrays sized once for the capacity */
        lub_neighbours_bin(&o->m[k].nb, Q->cap, Q->x);

        /* cell list of the level as a source, sized once for its capacity */
        lub_neighbours_init(&o->src[k], o->dim, o->m[k].re, 0.0, g->dmin, g->dmax, g->periodic);
        lub_neighbours_bin(&o->src[k], Q->cap, Q->x);
        lub_lsq_options *s = &o->lsq[k];
        *s = lub_lsq_defaults(o->dim, o->m[k].l0, o->m[k].re);
        s->order = 2;
        for (int d = 0; d < o->dim; d++)
            s->period[d] = g->periodic[d] ? g->dmax[d] - g->dmin[d] : 0.0;
        if (Q->cap > o->cap_cand) o->cap_cand = Q->cap;
        o->drop[k] = lub_calloc(Q->cap, 1);
    }
    /* each level's step count (the reorder schedule of lub_mps_step) in its own steps: the
     * particle file counts the finest level's */
    for (int k = 0; k < o->nlevels; k++) o->m[k].steps = P->step / L->level[k].dt_factor;
    /* finest steps per step of the coarsest level: the product of the Nr (1: commonDeltaT) */
    o->nr = L->common_dt ? 1 : (int)L->level[o->nlevels - 1].dt_factor;
    if (o->nr > 1)
        for (int k = 1; k < o->nlevels; k++) { /* state K of every coarser level, sized once */
            lub_opt_saved *K = &o->K[k];
            const lub_particles *C = &o->P[k];
            lub_particles_init(&K->P, o->dim, C->cap);
            K->fixed = lub_calloc(C->cap, 1);
            lub_neighbours_init(&K->cells, o->dim, o->m[k].re, 0.0, g->dmin, g->dmax, g->periodic);
            lub_neighbours_bin(&K->cells, C->cap, K->P.x);
        }
    o->next_id = next;
    o->nthreads = omp_get_max_threads();
    o->cand = lub_malloc((size_t)o->nthreads * o->cap_cand * sizeof *o->cand);
    o->rho = c->rho;
    lub_opt_mass m0;
    lub_opt_mass_count(o, &m0);
    o->mass0 = m0.mass;
}

void lub_opt_set_mass0(lub_opt *o, double mass0)
{
    o->mass0 = mass0;
}

void lub_opt_free(lub_opt *o)
{
    for (int k = 0; k < o->nlevels; k++) {
        lub_mps_free(&o->m[k]);
        lub_neighbours_free(&o->src[k]);
        lub_particles_free(&o->P[k]);
    }
    for (int k = 0; k < LUB_MAX_LEVELS; k++) {
        free(o->gen[k]);
        free(o->gen_ok[k]);
        free(o->gen_val[k]);
        free(o->drop[k]);
    }
    if (o->nr > 1)
        for (int k = 1; k < o->nlevels; k++) {
            lub_particles_free(&o->K[k].P);
            free(o->K[k].fixed);
            lub_neighbours_free(&o->K[k].cells);
        }
    free(o->cand);
    memset(o, 0, sizeof *o);
}

void lub_opt_moving_wall(lub_opt *o, const lub_geometry *g, int patch)
{
    if (patch < 0 || patch >= LUB_MAX_PATCHES) lub_bug("lub_opt_moving_wall: patch %d", patch);
    if (o->moved[patch]) return;
    o->moved[patch] = 1;
    for (int k = 0; k < o->nlevels; k++) {
        free(o->gen[k]);
        free(o->gen_ok[k]);
        free(o->gen_val[k]);
        o->gen[k] = NULL;
        o->ngen[k] = 0;
        generation_cells(o, g, k);
    }
}

size_t lub_opt_capacity(const lub_opt *o)
{
    size_t c = 0;
    for (int k = 0; k < o->nlevels; k++) c += o->P[k].cap;
    return c;
}

void lub_opt_merge(const lub_opt *o, lub_particles *P)
{
    size_t n = 0;
    for (int k = 0; k < o->nlevels; k++) n += o->P[k].n;
    lub_particles_reserve(P, n);
    P->npatches = o->P[0].npatches;
    memcpy(P->patch_names, o->P[0].patch_names, sizeof P->patch_names);
    P->nlevels = o->nlevels;
    P->n = 0;
    for (int k = 0; k < o->nlevels; k++) {
        const lub_particles *Q = &o->P[k];
        P->levels[k] = Q->levels[0];
        double *ev[LUB_MAX_EXTRA];
        for (int e = 0; e < Q->nextra; e++) ev[e] = lub_particles_extra(P, Q->extra[e].name);
        const size_t base = P->n;
        for (int d = 0; d < 3; d++) {
            memcpy(P->x[d] + base, Q->x[d], Q->n * sizeof(double));
            memcpy(P->u[d] + base, Q->u[d], Q->n * sizeof(double));
        }
        memcpy(P->p + base, Q->p, Q->n * sizeof *P->p);
        memcpy(P->kind + base, Q->kind, Q->n * sizeof *P->kind);
        memcpy(P->patch + base, Q->patch, Q->n * sizeof *P->patch);
        memcpy(P->level + base, Q->level, Q->n * sizeof *P->level);
        memcpy(P->id + base, Q->id, Q->n * sizeof *P->id);
        for (int e = 0; e < Q->nextra; e++)
            memcpy(ev[e] + base, Q->extra[e].v, Q->n * sizeof(double));
        P->n += Q->n;
    }
}

/* ---- the coupling: fixed bands by least squares ------------------------------------------ */

/* Mark the particles of level k whose values are given this step: fluid and wall particles
 * in a fixed band (T-25, T-26) or outside the level's extended region. */
static size_t mark_fixed(lub_opt *o, int k)
{
    lub_particles *P = &o->P[k];
    uint8_t *fix = o->m[k].fixed;
    const unsigned bit = 1u << k;
    size_t nfix = 0;
#pragma omp parallel for schedule(static) reduction(+ : nfix)
    for (size_t i = 0; i < P->n; i++) {
        uint8_t f = 0;
        if (P->kind[i] != LUB_DUMMY) {
            lub_level_where w;
            lub_levels_locate(&o->L, P->x[0][i], &w);
            f = (w.fixed & bit) || !(w.present & bit);
        }
        fix[i] = f;
        nfix += f;
    }
    return nfix;
}

/* The level whose particles give the values of a particle of level k at x: the other level
 * of the overlap x lies in, else the neighbouring level on the side of the level owning x
 * (k - 1 where a finer level owns x, k + 1 where a coarser one does), else a neighbouring
 * level.  Always k - 1 or k + 1: the levels are coupled only at their boundaries. */
static int source_level(const lub_opt *o, int k, double x)
{
    lub_level_where w;
    lub_levels_locate(&o->L, x, &w);
    if (w.boundary >= 0) {
        const lub_level_boundary *b = &o->L.boundary[w.boundary];
        if (b->fine == k) return b->coarse;
        if (b->coarse == k) return b->fine;
    }
    if (w.owner < k) return k - 1;
    if (w.owner > k) return k + 1;
    return k > 0 ? k - 1 : k + 1;
}

/* Cell coordinate of x in direction d of a cell list (clamped; as neighbours.c). */
static int cell_of(const lub_neighbours *nb, int d, double x)
{
    if (nb->periodic[d]) {
        x = nb->lo[d] + fmod(x - nb->lo[d], nb->period[d]);
        if (x < nb->lo[d]) x += nb->period[d];
    }
    const double t = (x - nb->lo[d]) * nb->inv_h[d];
    if (!(t >= 0)) return 0;
    if (t >= nb->nc[d]) return nb->nc[d] - 1;
    return (int)t;
}

/* The cells of a cell list around x: cells[d][0 .. nc[d]) in direction d, up to
 * 2 reach + 1 (fewer at a non-periodic end, or when a period holds fewer). */
#define CELLS_AROUND (2 * LUB_NEIGHBOURS_MAX_REACH + 1)
static void cells_around(const lub_neighbours *nb, int dim, const double x[3],
                         int cells[3][CELLS_AROUND], int nc[3])
{
    for (int d = 0; d < 3; d++) {
        nc[d] = 0;
        if (d >= dim) {
            cells[d][nc[d]++] = 0;
            continue;
        }
        const int c = cell_of(nb, d, x[d]);
        for (int off = -nb->reach; off <= nb->reach; off++) {
            int cc = c + off;
            if (nb->periodic[d])
                cc = (cc + nb->nc[d]) % nb->nc[d];
            else if (cc < 0 || cc >= nb->nc[d])
                continue;
            int seen = 0;
            for (int q = 0; q < nc[d]; q++) seen |= cells[d][q] == cc;
            if (!seen) cells[d][nc[d]++] = cc;
        }
    }
}

/* Index of cell (a, b, e) of a cell list (as neighbours.c: x fastest). */
static inline size_t cell_index(const lub_neighbours *nb, int a, int b, int e)
{
    return (size_t)a + (size_t)nb->nc[0] * ((size_t)b + (size_t)nb->nc[1] * (size_t)e);
}

/* Every particle of a cell list in the cells around x, in cell order, into out (so every
 * particle within the list's radius of x); returns the count. */
static size_t cells_collect(const lub_neighbours *nb, int dim, const double x[3], size_t *out)
{
    int cells[3][CELLS_AROUND], nc[3];
    cells_around(nb, dim, x, cells, nc);
    size_t n = 0;
    for (int a = 0; a < nc[0]; a++)
        for (int b = 0; b < nc[1]; b++)
            for (int e = 0; e < nc[2]; e++) {
                const size_t cell = cell_index(nb, cells[0][a], cells[1][b], cells[2][e]);
                for (size_t q = nb->cell_start[cell]; q < nb->cell_start[cell + 1]; q++)
                    out[n++] = nb->perm[q];
            }
    return n;
}

/* A source of interpolated values: a level's particles now, or (sub-stepping) a coarser
 * level as it was at the start of its step, state K of T-20..T-22 (o->K). */
typedef struct {
    const lub_particles *P;
    const uint8_t *fixed;
    const lub_neighbours *cells; /* binned at P's positions */
    const lub_lsq_options *lsq;
    double re, n0, fill;
} source;

static source source_now(const lub_opt *o, int k)
{
    source s = {&o->P[k],   o->m[k].fixed, &o->src[k], &o->lsq[k],
                o->m[k].re, o->m[k].n0,    o->fill[k]};
    return s;
}

/* Values at a time between the states old (K) and now (K + 1) of the source level:
 * w old + (1 - w) now, w the weight of T-20..T-22 (corrected; lub_levels_time_weight);
 * old NULL: now alone. */
typedef struct {
    const source *old, *now;
    double w;
} blend;

/* The blend table of level A: for each source level B (A - 1 or A + 1, source_level) the
 * states its values come from.  The finer level A - 1 is taken as it is now (at the start of
 * A's step, or at its end after A's sub-steps); the coarser level A + 1, when old (its saved
 * states K, sub-stepping) is given, in time between its state K and now (K + 1) with the
 * weight w of state K (`moment`); without old, now alone. */
static void blend_table(const lub_opt *o, int A, const source *now, const source *old,
                        double moment, blend *tab)
{
    for (int B = 0; B < o->nlevels; B++) {
        tab[B].old = NULL;
        tab[B].now = &now[B];
        tab[B].w = 0.0;
    }
    if (old && A + 1 < o->nlevels) {
        tab[A + 1].old = &old[A + 1];
        tab[A + 1].w = moment;
    }
}

/* The source particles in the cells around x (the cells are at least re wide, so every
 * particle within re is among them): fluid and wall particles, without those given
 * themselves when skip_fixed. */
static size_t gather(const lub_opt *o, const source *S, const double x[3], int skip_fixed,
                     size_t *out)
{
    const lub_particles *P = S->P;
    const uint8_t *fix = S->fixed;
    const size_t all = cells_collect(S->cells, o->dim, x, out);
    size_t n = 0;
    for (size_t q = 0; q < all; q++) {
        const size_t j = out[q];
        if (P->kind[j] != LUB_DUMMY && !(skip_fixed && fix[j])) out[n++] = j;
    }
    return n;
}

/* Least-squares fit (lsq.h) at x of the velocity (when fluid) and pressure of one source:
 * v = {u (dim), p}, grad (may be NULL) their gradients.
 *
 * Limiter.  Where x lies beyond the source's particles (a band particle above the other
 * level's free surface, which is lower by up to half a coarse spacing, or past its wall
 * layer) the fit extrapolates, and a second-order fit can overshoot by far (measured: 2.7 m/s
 * in a film on a wall sliding at 1 m/s, on a coarse level of four rows).  Each value is
 * therefore kept within the range of the neighbours' values (within re), widened by a quarter
 * of that range on each side: a smooth field inside the neighbourhood (the peak of a
 * Poiseuille profile between two rows) is not clipped, an extrapolation is. */
static lub_lsq_result fit_one(const lub_opt *o, const source *S, const double x[3], int fluid,
                              int skip_fixed, size_t *cand, double v[4], double (*grad)[3])
{
    const size_t n = gather(o, S, x, skip_fixed, cand);
    const double *const xs[3] = {S->P->x[0], S->P->x[1], S->P->x[2]};
    const double *f[4];
    int nf = 0;
    if (fluid)
        for (int d = 0; d < o->dim; d++) f[nf++] = S->P->u[d];
    f[nf++] = S->P->p;
    lub_lsq_result r = lub_lsq_interpolate(S->lsq, x, xs, n, cand, nf, f, v, grad, NULL);
    if (r.status == LUB_LSQ_EMPTY) return r;
    double lo[4], hi[4];
    for (int k = 0; k < nf; k++) lo[k] = INFINITY, hi[k] = -INFINITY;
    const double re2 = S->re * S->re;
    for (size_t q = 0; q < n; q++) {
        const size_t j = cand[q];
        double r2 = 0;
        for (int d = 0; d < o->dim; d++) {
            const double c = lub_min_image(xs[d][j] - x[d], S->lsq->period[d]);
            r2 += c * c;
        }
        if (!(r2 < re2)) continue;
        for (int k = 0; k < nf; k++) {
            lo[k] = fmin(lo[k], f[k][j]);
            hi[k] = fmax(hi[k], f[k][j]);
        }
    }
    for (int k = 0; k < nf; k++) {
        const double m = 0.25 * (hi[k] - lo[k]);
        v[k] = fmin(fmax(v[k], lo[k] - m), hi[k] + m);
    }
    return r;
}

/* The same in time between two states (blend); the order is the lower of the two fits, the
 * status EMPTY when either is. */
static lub_lsq_result fit(const lub_opt *o, const blend *b, const double x[3], int fluid,
                          int skip_fixed, size_t *cand, double v[4], double (*grad)[3])
{
    const source *only = !b->old || b->w <= 0 ? b->now : b->w >= 1 ? b->old : NULL;
    if (only) return fit_one(o, only, x, fluid, skip_fixed, cand, v, grad);
    double v0[4], g0[4][3];
    lub_lsq_result r0 = fit_one(o, b->old, x, fluid, skip_fixed, cand, v0, g0);
    lub_lsq_result r1 = fit_one(o, b->now, x, fluid, skip_fixed, cand, v, grad);
    if (r0.status == LUB_LSQ_EMPTY) return r0;
    if (r1.status == LUB_LSQ_EMPTY) return r1;
    const int nf = fluid ? o->dim + 1 : 1;
    for (int k = 0; k < nf; k++) {
        v[k] = b->w * v0[k] + (1 - b->w) * v[k];
        if (grad)
            for (int d = 0; d < 3; d++) grad[k][d] = b->w * g0[k][d] + (1 - b->w) * grad[k][d];
    }
    if (r0.order < r1.order) r1.order = r0.order;
    return r1;
}

/* The blend level A's values at x come from: its source level's entry in the table. */
static blend blend_for(const lub_opt *o, int A, double x, const blend *tab)
{
    return tab[source_level(o, A, x)];
}

/* Free surface in the overlaps (opt.h): mark the computed fluid and wall particles of level A
 * in an overlap where the other level's particles (every kind, as the PND of T-11) fill the
 * neighbourhood, their PND at the particle's position at least beta n0 of that level. */
static void mark_inside(lub_opt *o, int A, const blend *tab)
{
    lub_particles *P = &o->P[A];
    const uint8_t *fix = o->m[A].fixed;
    uint8_t *in = o->m[A].inside;
    const int dim = o->dim;
    size_t nin = 0;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : nin)
    for (size_t i = 0; i < P->n; i++) {
        in[i] = 0;
        if (P->kind[i] == LUB_DUMMY || fix[i]) continue;
        lub_level_where w;
        lub_levels_locate(&o->L, P->x[0][i], &w);
        if (w.boundary < 0) continue;
        const lub_level_boundary *b = &o->L.boundary[w.boundary];
        if (b->fine != A && b->coarse != A) continue;
        const int B = b->fine == A ? b->coarse : b->fine;
        const source *S = tab[B].now;
        const double xt[3] = {P->x[0][i], P->x[1][i], P->x[2][i]};
        size_t *cand = o->cand + (size_t)omp_get_thread_num() * o->cap_cand;
        const size_t nc = cells_collect(S->cells, dim, xt, cand);
        const lub_particles *Q = S->P;
        const double *L = S->cells->period;
        const int *per = S->cells->periodic;
        const double re2 = S->re * S->re;
        double pnd = 0.0;
        for (size_t q = 0; q < nc; q++) {
            const size_t j = cand[q];
            double r2 = 0.0;
            for (int d = 0; d < dim; d++) {
                const double v = lub_min_image(Q->x[d][j] - xt[d], per[d] ? L[d] : 0.0);
                r2 += v * v;
            }
            if (r2 < re2) pnd += lub_mps_weight(sqrt(r2), S->re);
        }
        in[i] = pnd >= o->m[B].c.beta * S->n0;
        nin += in[i];
    }
    o->st.ninside[A] = nin;
}

/* Interpolate the fixed particles of level A (marked) from their source levels (tab:
 * blend_table), and mark its particles inside the other level's fluid (mark_inside). */
static void couple_level(lub_opt *o, int A, const blend *tab)
{
    mark_inside(o, A, tab);
    lub_particles *P = &o->P[A];
    const uint8_t *fix = o->m[A].fixed;
    const int dim = o->dim;
    size_t nlower = 0, nempty = 0;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : nlower, nempty)
    for (size_t i = 0; i < P->n; i++) {
        if (!fix[i]) continue;
        size_t *cand = o->cand + (size_t)omp_get_thread_num() * o->cap_cand;
        const double xt[3] = {P->x[0][i], P->x[1][i], P->x[2][i]};
        const blend b = blend_for(o, A, xt[0], tab);
        /* fluid: velocity and pressure; wall: pressure (its velocity is its patch's) */
        const int fluid = P->kind[i] == LUB_FLUID;
        double v[4];
        lub_lsq_result r = fit(o, &b, xt, fluid, 1, cand, v, NULL);
        if (r.status == LUB_LSQ_EMPTY) {
            nempty++;
            continue;
        }
        if (r.order < 2) nlower++;
        int nf = 0;
        if (fluid)
            for (int d = 0; d < dim; d++) P->u[d][i] = v[nf++];
        P->p[i] = v[nf];
    }
    o->st.nlower += nlower;
    o->st.nempty += nempty;
}

void lub_opt_couple(lub_opt *o)
{
    o->st.nlower = o->st.nempty = 0;
    for (int k = 0; k < o->nlevels; k++) o->st.nfixed[k] = mark_fixed(o, k);
    for (int k = 0; k < o->nlevels; k++) lub_neighbours_bin(&o->src[k], o->P[k].n, o->P[k].x);
    source now[LUB_MAX_LEVELS];
    blend tab[LUB_MAX_LEVELS];
    for (int k = 0; k < o->nlevels; k++) now[k] = source_now(o, k);
    blend_table(o, 0, now, NULL, 0.0, tab);
    for (int k = 0; k < o->nlevels; k++) couple_level(o, k, tab);
}

/* ---- particle transfer ------------------------------------------------------------------- */

/* Delete the particles of level k with drop[i] set (stable: the others keep their order);
 * returns the count. */
static size_t compact(lub_opt *o, int k, const uint8_t *drop)
{
    lub_particles *P = &o->P[k];
    uint8_t *fix = o->m[k].fixed;
    size_t w = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (drop[i]) continue;
        if (w != i) {
            put_particle(P, w, P, i);
            fix[w] = fix[i];
        }
        w++;
    }
    const size_t deleted = P->n - w;
    P->n = w;
    return deleted;
}

/* Delete level k's fluid particles outside its extended region; returns the count. */
static size_t delete_outside(lub_opt *o, int k)
{
    const lub_particles *P = &o->P[k];
    uint8_t *drop = o->drop[k];
    const unsigned bit = 1u << k;
    size_t n = 0;
#pragma omp parallel for schedule(static) reduction(+ : n)
    for (size_t i = 0; i < P->n; i++) {
        drop[i] = 0;
        if (P->kind[i] != LUB_FLUID) continue;
        lub_level_where lw;
        lub_levels_locate(&o->L, P->x[0][i], &lw);
        drop[i] = !(lw.present & bit);
        n += drop[i];
    }
    return n ? compact(o, k, drop) : 0;
}

/* Delete level k's given (fixed-band) fluid particles that the step of length dt took behind
 * a wall layer (lub_mps_buried: their interpolated velocity carried them into a curved
 * wall); returns the count.  They lie outside the part of x the level owns, so the mass of
 * T-27 does not change. */
static size_t delete_buried(lub_opt *o, int k, double dt)
{
    const size_t n = lub_mps_buried(&o->m[k], dt, o->drop[k]);
    if (!n) return 0;
    compact(o, k, o->drop[k]);
    o->st.nburied[k] += n;
    o->total_buried[k] += n;
    lub_mps_rebuild_lists(&o->m[k]);
    return n;
}

/* Whether a particle of level A is to be created at generation cell c (see lub_opt_transfer);
 * val receives its u (3), p and grad p (3) interpolated from the other level (b). */
/* Squared distance (minimum image) from particle j of P to c. */
static double dist2(const lub_particles *P, int dim, size_t j, const double c[3],
                    const double period[3])
{
    double r2 = 0;
    for (int d = 0; d < dim; d++) {
        const double v = lub_min_image(P->x[d][j] - c[d], period[d]);
        r2 += v * v;
    }
    return r2;
}

static int decide(lub_opt *o, int A, const double c[3], double dt, const blend *bl, size_t *cand,
                  double val[7])
{
    const int dim = o->dim;
    const double l0 = o->m[A].l0;
    double period[3] = {0, 0, 0};
    for (int d = 0; d < dim; d++) period[d] = o->lsq[A].period[d];

    /* nearest particle of A: leave the cell alone while one is within half a cell; and the
     * nearest of its wall and dummy particles: a dummy of a wall a model moves puts the cell
     * behind that wall (lub_opt_moving_wall) */
    const lub_particles *PA = &o->P[A];
    double d2min = INFINITY, d2wall = INFINITY;
    size_t jwall = 0;
    size_t n = cells_collect(&o->src[A], dim, c, cand);
    for (size_t q = 0; q < n; q++) {
        const size_t j = cand[q];
        const double r2 = dist2(PA, dim, j, c, period);
        if (r2 < d2min) d2min = r2;
        if (PA->kind[j] != LUB_FLUID && r2 < d2wall) d2wall = r2, jwall = j;
    }
    if (d2min < 0.25 * l0 * l0) return 0;
    if (d2wall < INFINITY && PA->kind[jwall] == LUB_DUMMY && o->moved[PA->patch[jwall]]) return 0;

    /* the other level's fluid fills the cell: PND of its fluid against the room its walls
     * leave (T-4 sums at c), in the state nearer in time */
    const source *S = bl->old && bl->w >= 0.5 ? bl->old : bl->now;
    const lub_particles *PB = S->P;
    const double re = S->re, n0 = S->n0;
    double nf = 0, nw = 0;
    n = cells_collect(S->cells, dim, c, cand);
    for (size_t q = 0; q < n; q++) {
        const size_t j = cand[q];
        const double r2 = dist2(PB, dim, j, c, period);
        if (!(r2 < re * re)) continue;
        const double w = lub_mps_weight(sqrt(r2), re);
        if (PB->kind[j] == LUB_FLUID)
            nf += w;
        else
            nw += w;
    }
    const double room = n0 - nw;
    if (!(room > 0.1 * n0) || !(nf > S->fill * room)) return 0;

    /* velocity, pressure and pressure gradient by least squares from B */
    double v[4], grad[4][3];
    lub_lsq_result r = fit(o, bl, c, 1, 0, cand, v, grad);
    if (r.status == LUB_LSQ_EMPTY) return 0;
    double speed = 0;
    for (int d = 0; d < dim; d++) speed += v[d] * v[d];
    speed = sqrt(speed);
    /* created once the last particle is l0 - |u| dt / 2 away: spacing l0 on average */
    const double rgen = fmax(0.5 * l0, l0 - 0.5 * speed * dt);
    if (d2min < rgen * rgen) return 0;
    for (int k = 0; k < 7; k++) val[k] = 0;
    for (int d = 0; d < dim; d++) val[d] = v[d];
    val[3] = v[dim];
    for (int d = 0; d < dim; d++) val[4 + d] = grad[dim][d];
    return 1;
}

/* Generation in level A's cells (A's and its sources' cell lists binned), after its step of
 * length dt; values from the source levels as the blend table tab gives them. */
static void generate(lub_opt *o, int A, double dt, const blend *tab)
{
    static const char *const gnames[3] = {"gradPx", "gradPy", "gradPz"};
    const size_t ng = o->ngen[A];
    uint8_t *ok = o->gen_ok[A];
    double *val = o->gen_val[A];
#pragma omp parallel for schedule(dynamic, 16)
    for (size_t q = 0; q < ng; q++) {
        size_t *cand = o->cand + (size_t)omp_get_thread_num() * o->cap_cand;
        const double *c = o->gen[A] + 3 * q;
        const blend b = blend_for(o, A, c[0], tab);
        ok[q] = (uint8_t)decide(o, A, c, dt, &b, cand, val + 7 * q);
    }
    /* append in cell order (the same on any number of threads) */
    lub_particles *P = &o->P[A];
    double *gb[3];
    for (int d = 0; d < 3; d++) gb[d] = lub_particles_find_extra(P, gnames[d]);
    for (size_t q = 0; q < ng; q++) {
        if (!ok[q]) continue;
        if (P->n >= P->cap) {
            o->st.nfull++;
            continue;
        }
        const size_t j = P->n++;
        const double *v = val + 7 * q;
        for (int d = 0; d < 3; d++) {
            P->x[d][j] = o->gen[A][3 * q + d];
            P->u[d][j] = d < o->dim ? v[d] : 0.0;
        }
        P->p[j] = v[3];
        P->kind[j] = LUB_FLUID;
        P->patch[j] = 0;
        P->level[j] = (uint8_t)A;
        P->id[j] = o->next_id++;
        for (int e = 0; e < P->nextra; e++) P->extra[e].v[j] = 0.0;
        for (int d = 0; d < o->dim; d++)
            if (gb[d]) gb[d][j] = v[4 + d];
        o->m[A].fixed[j] = 1; /* it starts in the fixed band */
        o->st.ngenerated[A]++;
    }
}

/* Totals of a level's transfer; its lists are built afresh when its particles changed. */
static void transfer_done(lub_opt *o, int k)
{
    o->total_deleted[k] += o->st.ndeleted[k];
    o->total_generated[k] += o->st.ngenerated[k];
    if (o->st.ndeleted[k] || o->st.ngenerated[k]) lub_mps_rebuild_lists(&o->m[k]);
}

void lub_opt_transfer(lub_opt *o, double dt)
{
    for (int k = 0; k < o->nlevels; k++) {
        o->st.ndeleted[k] = delete_outside(o, k);
        o->st.ngenerated[k] = 0;
    }
    for (int k = 0; k < o->nlevels; k++) lub_neighbours_bin(&o->src[k], o->P[k].n, o->P[k].x);
    o->st.nfull = 0;
    source now[LUB_MAX_LEVELS];
    blend tab[LUB_MAX_LEVELS];
    for (int k = 0; k < o->nlevels; k++) now[k] = source_now(o, k);
    blend_table(o, 0, now, NULL, 0.0, tab);
    for (int A = 0; A < o->nlevels; A++) generate(o, A, dt, tab);
    for (int k = 0; k < o->nlevels; k++) transfer_done(o, k);
    o->total_full += o->st.nfull;
}

/* ---- mass correction (T-27..T-29, T-61; opt.h) ------------------------------------------- */

/* The fine level's fluid cross-section of each overlap (A of T-28 is their sum): its fluid
 * particles in the overlap times l0^d over the overlap's length. */
static double overlap_area(const lub_opt *o)
{
    const lub_levels *L = &o->L;
    double area = 0;
    for (int b = 0; b < L->nboundaries; b++) {
        const lub_level_boundary *bd = &L->boundary[b];
        const lub_particles *P = &o->P[bd->fine];
        size_t n = 0;
#pragma omp parallel for schedule(static) reduction(+ : n)
        for (size_t i = 0; i < P->n; i++) {
            if (P->kind[i] != LUB_FLUID) continue;
            lub_level_where w;
            lub_levels_locate(L, P->x[0][i], &w);
            n += w.boundary == b;
        }
        area += (double)n * pow(o->m[bd->fine].l0, o->dim) / (bd->hi - bd->lo);
    }
    return area;
}

/* After a step of length dt (the coarser level's): count M, and move the coarser level's
 * fluid particles in the overlaps by the correction's displacement du dt when |M - M^0|
 * exceeds the threshold. */
static void mass_correct(lub_opt *o, double dt)
{
    const lub_levels *L = &o->L;
    lub_opt_mass mc;
    lub_opt_mass_count(o, &mc);
    o->st.mass = mc.mass;
    o->st.correction = 0;
    o->st.area = 0;
    o->st.ncorrected = 0;
    const double err = mc.mass - o->mass0;
    if (!L->mass_correction || !(o->mass0 > 0) || !(fabs(err) > L->threshold * o->mass0)) return;
    const double area = overlap_area(o);
    o->st.area = area;
    if (!(area > 0)) return;
    const double B = fmax(fmin(fabs(err) / (o->rho * area * L->relax * dt), L->c_max), L->c_min);
    const double sg = err > 0 ? 1.0 : -1.0;
    o->st.correction = B * sg;
    size_t ncor = 0;
    for (int b = 0; b < L->nboundaries; b++) {
        const lub_level_boundary *bd = &L->boundary[b];
        const int C = bd->coarse;
        lub_particles *P = &o->P[C];
        const double s = bd->side == 1 ? 1.0 : -1.0, du = -s * B * sg;
        size_t n = 0;
#pragma omp parallel for schedule(static) reduction(+ : n)
        for (size_t i = 0; i < P->n; i++) {
            if (P->kind[i] != LUB_FLUID) continue;
            lub_level_where w;
            lub_levels_locate(L, P->x[0][i], &w);
            if (w.boundary != b) continue;
            double x = P->x[0][i] + du * dt;
            if (L->periodic) {
                if (x < L->xmin) x += L->xmax - L->xmin;
                if (x >= L->xmax) x -= L->xmax - L->xmin;
            }
            P->x[0][i] = x;
            n++;
        }
        ncor += n;
    }
    o->st.ncorrected = ncor;
}

/* ---- the step ---------------------------------------------------------------------------- */

static lub_step_status step_level(lub_opt *o, int k, double dt, int *level, long *bad, char *msg,
                                  size_t msgsize)
{
    char m[1024];
    lub_step_status s = lub_mps_step(&o->m[k], dt, bad, m, sizeof m);
    o->st.piter += o->m[k].st.p.iterations;
    for (int d = 0; d < o->dim; d++) o->st.viter += o->m[k].st.v[d].iterations;
    if (s != LUB_STEP_OK) {
        *level = k;
        snprintf(msg, msgsize, "level %d (l0 %g): %s", k, o->m[k].l0, m);
        return s;
    }
    delete_buried(o, k, dt);
    return s;
}

/* Save level k's state K (the source of the finer level's sub-steps) and bin it. */
static void save_level(lub_opt *o, int k)
{
    const lub_particles *P = &o->P[k];
    lub_opt_saved *S = &o->K[k];
    lub_particles *K = &S->P;
    K->n = P->n;
    for (int d = 0; d < 3; d++) {
        memcpy(K->x[d], P->x[d], P->n * sizeof(double));
        memcpy(K->u[d], P->u[d], P->n * sizeof(double));
    }
    memcpy(K->p, P->p, P->n * sizeof(double));
    memcpy(K->kind, P->kind, P->n * sizeof *P->kind);
    memcpy(S->fixed, o->m[k].fixed, P->n);
    lub_neighbours_bin(&S->cells, K->n, K->x);
}

/* One step of level k of length dt with sub-stepping (T-19..T-22), the thesis' Fig. 3 order
 * applied recursively: level k is coupled (its band at the coarser level k + 1 from k + 1 in
 * time between its states K and K + 1 at the start of this step, the b-th of Nr_k; its band at
 * the finer level k - 1 from k - 1 now, at the start of the step), its state K saved, and it
 * takes its step; then level k - 1 takes its Nr_{k-1} sub-steps of dt / Nr_{k-1} (each
 * doing the same for the levels below it); last, level k's transfer at the end of its step
 * (the coarser level at the weight of b + 1, the finer level as the sub-steps left it).
 * now, old: the sources of every level now and (k >= 1) as saved. */
static lub_step_status advance(lub_opt *o, int k, double dt, int b, const source *now,
                               const source *old, int *level, long *bad, char *msg, size_t msgsize)
{
    const int top = o->nlevels - 1, nr = o->L.level[k].nr;
    blend tab[LUB_MAX_LEVELS];
    lub_step_status s;
    lub_timer_start(&o->m[0].tm, LUB_T_OTHER);
    if (k == top) {
        for (int j = 0; j < o->nlevels; j++) o->st.nfixed[j] = mark_fixed(o, j);
        for (int j = 0; j < o->nlevels; j++) lub_neighbours_bin(&o->src[j], o->P[j].n, o->P[j].x);
    } else {
        o->st.nfixed[k] = mark_fixed(o, k);
        if (k > 0) { /* the finer level as its sub-steps left it: its given particles marked
                        (not sources) and binned */
            o->st.nfixed[k - 1] = mark_fixed(o, k - 1);
            lub_neighbours_bin(&o->src[k - 1], o->P[k - 1].n, o->P[k - 1].x);
        }
    }
    blend_table(o, k, now, old, lub_levels_time_weight(b, nr), tab);
    couple_level(o, k, tab);
    if (k > 0) save_level(o, k);
    lub_timer_stop(&o->m[0].tm, LUB_T_OTHER);
    if ((s = step_level(o, k, dt, level, bad, msg, msgsize)) != LUB_STEP_OK) return s;
    if (k > 0) {
        lub_neighbours_bin(&o->src[k], o->P[k].n, o->P[k].x); /* state K + 1 */
        const int nf = o->L.level[k - 1].nr;
        for (int c = 0; c < nf; c++)
            if ((s = advance(o, k - 1, dt / nf, c, now, old, level, bad, msg, msgsize)) !=
                LUB_STEP_OK)
                return s;
    }
    /* level k's transfer, at the end of its step: time K + (b + 1) / Nr_k of the coarser */
    lub_timer_start(&o->m[0].tm, LUB_T_OTHER);
    const size_t nd = delete_outside(o, k), ng = o->st.ngenerated[k];
    lub_neighbours_bin(&o->src[k], o->P[k].n, o->P[k].x);
    if (k > 0) lub_neighbours_bin(&o->src[k - 1], o->P[k - 1].n, o->P[k - 1].x);
    blend_table(o, k, now, old, lub_levels_time_weight(b + 1, nr), tab);
    generate(o, k, dt, tab);
    if (nd || o->st.ngenerated[k] != ng) lub_mps_rebuild_lists(&o->m[k]);
    o->st.ndeleted[k] += nd;
    lub_timer_stop(&o->m[0].tm, LUB_T_OTHER);
    return LUB_STEP_OK;
}

/* One step of the coarsest level (dt = the product of the Nr times the finest dt, T-19) with
 * every finer level's sub-steps (advance), then the mass count and correction. */
static lub_step_status substeps(lub_opt *o, double dt, int *level, long *bad, char *msg,
                                size_t msgsize)
{
    source now[LUB_MAX_LEVELS], old[LUB_MAX_LEVELS];
    for (int k = 0; k < o->nlevels; k++) {
        now[k] = source_now(o, k);
        old[k] = now[k];
        if (k > 0) {
            lub_opt_saved *S = &o->K[k];
            old[k].P = &S->P;
            old[k].fixed = S->fixed;
            old[k].cells = &S->cells;
        }
    }
    o->st.nlower = o->st.nempty = 0;
    o->st.nfull = 0;
    for (int k = 0; k < o->nlevels; k++) o->st.ndeleted[k] = o->st.ngenerated[k] = 0;
    lub_step_status s = advance(o, o->nlevels - 1, dt, 0, now, old, level, bad, msg, msgsize);
    if (s != LUB_STEP_OK) return s;
    lub_timer_start(&o->m[0].tm, LUB_T_OTHER);
    for (int k = 0; k < o->nlevels; k++) {
        o->total_deleted[k] += o->st.ndeleted[k];
        o->total_generated[k] += o->st.ngenerated[k];
    }
    o->total_full += o->st.nfull;
    mass_correct(o, dt);
    lub_timer_stop(&o->m[0].tm, LUB_T_OTHER);
    return LUB_STEP_OK;
}

lub_step_status lub_opt_step(lub_opt *o, double dt, int *level, long *bad, char *msg,
                             size_t msgsize)
{
    *level = -1;
    *bad = -1;
    msg[0] = '\0';
    o->st.piter = o->st.viter = 0;
    for (int k = 0; k < o->nlevels; k++) o->st.nburied[k] = 0;
    if (o->nr > 1) return substeps(o, dt, level, bad, msg, msgsize);
    lub_timer_start(&o->m[0].tm, LUB_T_OTHER); /* the coupling is charged to level 0 */
    lub_opt_couple(o);
    lub_timer_stop(&o->m[0].tm, LUB_T_OTHER);
    for (int k = 0; k < o->nlevels; k++) {
        lub_step_status s = step_level(o, k, dt, level, bad, msg, msgsize);
        if (s != LUB_STEP_OK) return s;
    }
    lub_timer_start(&o->m[0].tm, LUB_T_OTHER);
    lub_opt_transfer(o, dt);
    mass_correct(o, dt);
    lub_timer_stop(&o->m[0].tm, LUB_T_OTHER);
    return LUB_STEP_OK;
}

/* ---- reports ----------------------------------------------------------------------------- */

void lub_opt_mass_count(const lub_opt *o, lub_opt_mass *out)
{
    memset(out, 0, sizeof *out);
    /* each level's particles carry its level (the sums: serial, a few ns per particle) */
    lub_levels_sums s;
    memset(&s, 0, sizeof s);
    double m[LUB_MAX_LEVELS];
    for (int k = 0; k < o->nlevels; k++) {
        lub_levels_sum(&o->L, &o->P[k], &s);
        out->fluid[k] = s.fluid[k];
        out->owned[k] = s.owned[k];
        m[k] = o->m[k].c.rho * pow(o->m[k].l0, o->dim);
    }
    out->mass = lub_levels_mass(&s, o->nlevels, m);
}

void lub_opt_rebuild_lists(lub_opt *o)
{
    for (int k = 0; k < o->nlevels; k++) lub_mps_rebuild_lists(&o->m[k]);
}

double lub_opt_courant_per_dt(const lub_opt *o, int *level)
{
    double best = 0;
    int at = 0;
    for (int k = 0; k < o->nlevels; k++) {
        const double c = o->m[k].st.umax * (double)o->L.level[k].dt_factor / o->m[k].l0;
        if (c > best) best = c, at = k;
    }
    if (level) *level = at;
    return best;
}
