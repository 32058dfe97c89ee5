/* lubkit MPS: the walls' checks, shared by every formulation of the fluid over the solver's
 * state (models/fluid.h): a particle with a non-finite value or outside the domain box, a fluid
 * particle through a wall (lub_mps_check), a given particle buried behind one
 * (lub_mps_buried); and the largest speed (see mps.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "mps/mps.h"

static const char *kind_name(int k)
{
    return k == LUB_FLUID ? "fluid" : k == LUB_WALL ? "wall" : "dummy";
}

/* Through a wall.  Walls are one layer of wall particles on the surface with dummy layers
 * l0, 2 l0 ... behind it (particleGen: along the normal for planes and polylines, filling the
 * corners on the lattice; arcs, rings and spheres sample every layer with its own spacing of
 * about l0, so that a dummy is in general not straight behind a wall particle).  Walls move
 * and deform (movingWalls, elasticWall), so the test is made on the particles, not on the
 * geometry.  A fluid particle i went through a wall in the step when, relative to the wall
 * particles around it, it moved from in front of the wall layer to behind it.  With the wall
 * and dummy particles of one patch among i's neighbours (within re):
 *
 *   n     the wall's normal at i, into the fluid: normal to the least-squares line (plane in
 *         3-D) through the wall particles, oriented from the centroid of the dummy particles
 *         to that of the wall particles;
 *   w     the wall particle nearest to the line through i along n: it must be within
 *         0.55 l0 of that line (0.75 l0 in 3-D), and the wall layer must go on at least
 *         l0/4 beyond i on both sides (across n; in 3-D in both tangent directions);
 *   t     the depth of i behind the wall layer, n.(r_w - r_i): t1 now, and t0 = t1 -
 *         dt n.(u_w - u_i) before the step (each particle moved by u dt in it: wall and
 *         dummy particles in step 3, fluid particles in steps 3 and 8 and in the collision);
 *
 * i went through the wall of the patch when t0 <= l0/4 < t1.  The distances, in l0, for a
 * wall layer of spacing s <= l0 (elasticWall stretches it by far less than 1%):
 *   - fluid sliding along the wall sits ~1 in front of the wall layer (t ~ -1), ~2 from the
 *     first dummy layer; a particle pushed against the wall layer by the collision model is
 *     still in front of it (t <= 0, the line through the centres of the wall particles) and
 *     is never flagged; t1 > 1/4 is a quarter spacing into the wall, where the nearest dummy
 *     is at most sqrt(0.55^2 + 0.75^2) = 0.93 away (1.06 in 3-D);
 *   - n is exact on a plane (the adjugate of the wall particles' covariance, of rank d - 1
 *     there, is a multiple of n n^T) and within about l0 / (2 R) radians of it on an arc of
 *     radius R; the centroids alone would tilt it by up to 20 degrees (27 at re = 1.5 l0),
 *     as the layers are cut off at re at different places.  Across n the wall particles
 *     are at most s apart, so one is within s/2 (s/sqrt(2) on a square lattice) of the
 *     line through i: the bounds 0.55 and 0.75 leave 10% for rings sampled slightly wider
 *     than l0;
 *   - the test looks at the motion, not only at the position, because the oil can reach
 *     the dummy particles without crossing the wall layer: round the open end of a wall,
 *     where its dummy layers end (a wall with a range; an arc that does not close over a
 *     periodic seam).  In the soft-EHL tutorial (tutorials/softEHL/cylinderFlatReduced)
 *     with the period [-0.5, 0.4] mm of its versions before 2026-11-28, from step 360 on
 *     particles flowed round the end of the cylinder's arc at x = 0.4 mm into its dummy
 *     layers, up to 3 l0 deep and 0.04 l0 from a dummy particle, and on into the cylinder
 *     (157 by 0.3 ms; tests/cases/softEHL now checks that none is there).  They were not
 *     flagged: beside the end of the wall layer the line or the both-sides test fails, and
 *     once behind it they kept t >= 0.64 (measured over the 1,200 steps), clear of l0/4.  A
 *     test on the position alone (i nearer a dummy than any wall particle, say) stopped
 *     that tutorial at step 364.
 * Not seen: a particle that goes through all the layers within one step (the box check stops
 * the run when it leaves the domain, as in the wedge at Courant 1: tutorials/README.md),
 * one within l0/4 of the open end of a wall, and one where two patches meet, since each
 * patch is looked at alone.
 *
 * Cost.  The search starts from the dummy particles: only a fluid particle closer than
 * 1.2 l0 to one is tested, over its own list.  In a sound run there is none (the first dummy
 * layer is ~2 from the fluid; measured in every test and tutorial but the soft-EHL one:
 * 1.1 l0 at the closest), so the check costs a sweep over the lists of the dummy particles.
 * No list is built for it: the lists are those of the last update (at r*, or before the
 * collision step); since then only fluid particles have moved, by their pressure correction
 * (and collision) delta, and every pair closer than re was listed, so every pair now closer
 * than 1.2 l0 is, as long as delta < re - 1.2 l0 (1.9 l0 at the default re = 3.1 l0).  The
 * distances are taken at the current positions (lub_neighbours_r).  A particle moving
 * further in one step (a run already diverging) is seen with the next step's lists if it is
 * still near a dummy particle. */
#define THROUGH_GATE  1.2  /* l0: fluid particles this close to a dummy particle are tested */
#define THROUGH_DEPTH 0.25 /* l0: t0 <= THROUGH_DEPTH < t1; also the both-sides margin */

int lub_mps_wall_plane(const lub_mps *m, size_t i, unsigned patch, double cw[3], double n[3])
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    double *const x[3] = {P->x[0], P->x[1], P->x[2]};
    const int dim = m->dim;
    const double re2 = m->re * m->re;
    /* centroids of the patch's wall and dummy neighbours, covariance of the wall particles */
    double cd[3] = {0, 0, 0}, S[3][3] = {{0}};
    int nw = 0, nd = 0;
    for (int a = 0; a < 3; a++) cw[a] = n[a] = 0;
    for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
        const size_t j = nb->j[q];
        if (P->kind[j] == LUB_FLUID || P->patch[j] != patch) continue;
        double v[3];
        if (!(lub_neighbours_r(nb, x, i, j, v) < re2)) continue;
        if (P->kind[j] == LUB_WALL) {
            for (int a = 0; a < 3; a++) {
                cw[a] += v[a];
                for (int b = 0; b < 3; b++) S[a][b] += v[a] * v[b];
            }
            nw++;
        } else {
            for (int a = 0; a < 3; a++) cd[a] += v[a];
            nd++;
        }
    }
    if (nw < 2 || !nd) return 0;
    double n0[3], C[3][3], A[3][3] = {{0}}, nn = 0, n0n = 0, tr = 0;
    for (int a = 0; a < 3; a++) {
        cw[a] /= nw;
        n0[a] = cw[a] - cd[a] / nd;
        n0n += n0[a] * n0[a];
    }
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) C[a][b] = S[a][b] / nw - cw[a] * cw[b];
    /* adjugate of the covariance: for wall particles on a line (plane in 3-D) it has rank
     * dim - 1 and the adjugate is a multiple of n n^T */
    if (dim == 2) {
        A[0][0] = C[1][1], A[1][1] = C[0][0], A[0][1] = A[1][0] = -C[0][1];
        tr = C[0][0] + C[1][1];
    } else {
        A[0][0] = C[1][1] * C[2][2] - C[1][2] * C[1][2];
        A[1][1] = C[0][0] * C[2][2] - C[0][2] * C[0][2];
        A[2][2] = C[0][0] * C[1][1] - C[0][1] * C[0][1];
        A[0][1] = A[1][0] = C[0][2] * C[1][2] - C[0][1] * C[2][2];
        A[0][2] = A[2][0] = C[0][1] * C[1][2] - C[0][2] * C[1][1];
        A[1][2] = A[2][1] = C[0][1] * C[0][2] - C[0][0] * C[1][2];
        tr = C[0][0] + C[1][1] + C[2][2];
        tr *= tr;
    }
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) n[a] += A[a][b] * n0[b];
    for (int a = 0; a < 3; a++) nn += n[a] * n[a];
    /* the wall particles all on one line (3-D) or one point: the centroids' direction */
    if (!(nn > 1e-12 * tr * tr * n0n)) {
        for (int a = 0; a < 3; a++) n[a] = n0[a];
        nn = n0n;
    }
    if (!(nn > 0)) return 0;
    const double sn = (n[0] * n0[0] + n[1] * n0[1] + n[2] * n0[2] < 0 ? -1 : 1) / sqrt(nn);
    for (int a = 0; a < 3; a++) n[a] *= sn;
    return 1;
}

/* Fluid particle i and the wall of patch `patch`: the depths t0, t1 (m) and whether i went
 * through the wall layer in the step (dt). */
static int through(const lub_mps *m, double dt, size_t i, unsigned patch, double *t0, double *t1)
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    double *const x[3] = {P->x[0], P->x[1], P->x[2]};
    const int dim = m->dim;
    const double re2 = m->re * m->re, l0 = m->l0;
    double cw[3], n[3];
    if (!lub_mps_wall_plane(m, i, patch, cw, n)) return 0;
    /* tangent directions e[0] (2-D); e[0], e[1] (3-D: e[0] = n x the axis least aligned
     * with n, e[1] = n x e[0]) */
    double e[2][3] = {{-n[1], n[0], 0}, {0, 0, 0}};
    if (dim == 3) {
        const int k = fabs(n[0]) <= fabs(n[1]) && fabs(n[0]) <= fabs(n[2]) ? 0
                      : fabs(n[1]) <= fabs(n[2])                           ? 1
                                                                           : 2;
        double ax[3] = {0, 0, 0}, ee = 0;
        ax[k] = 1;
        e[0][0] = n[1] * ax[2] - n[2] * ax[1];
        e[0][1] = n[2] * ax[0] - n[0] * ax[2];
        e[0][2] = n[0] * ax[1] - n[1] * ax[0];
        for (int a = 0; a < 3; a++) ee += e[0][a] * e[0][a];
        for (int a = 0; a < 3; a++) e[0][a] /= sqrt(ee);
        e[1][0] = n[1] * e[0][2] - n[2] * e[0][1];
        e[1][1] = n[2] * e[0][0] - n[0] * e[0][2];
        e[1][2] = n[0] * e[0][1] - n[1] * e[0][0];
    }
    /* w: the wall particle nearest to the line through i along n; the wall layer on both
     * sides */
    const int nt = dim - 1, all = (1 << (2 * nt)) - 1;
    const double side = THROUGH_DEPTH * l0, band = (dim == 3 ? 0.75 : 0.55) * l0;
    int sides = 0;
    size_t w = i;
    double lw2 = INFINITY, tw = 0;
    for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
        const size_t j = nb->j[q];
        if (P->kind[j] != LUB_WALL || P->patch[j] != patch) continue;
        double v[3];
        const double r2 = lub_neighbours_r(nb, x, i, j, v);
        if (!(r2 < re2)) continue;
        const double t = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
        if (r2 - t * t < lw2) lw2 = r2 - t * t, w = j, tw = t;
        for (int k = 0; k < nt; k++) {
            const double p = v[0] * e[k][0] + v[1] * e[k][1] + v[2] * e[k][2];
            if (p >= side) sides |= 1 << (2 * k);
            if (p <= -side) sides |= 1 << (2 * k + 1);
        }
    }
    if (w == i || sides != all || !(lw2 <= band * band)) return 0;
    double du = 0;
    for (int a = 0; a < dim; a++) du += n[a] * (P->u[a][w] - P->u[a][i]);
    *t1 = tw;
    *t0 = tw - dt * du;
    return *t0 <= THROUGH_DEPTH * l0 && *t1 > THROUGH_DEPTH * l0;
}

/* The first (lowest index) fluid particle that went through a wall in the step, or -1; the
 * patch and depths of its crossing. */
static long through_wall(const lub_mps *m, double dt, unsigned *patch, double *t0, double *t1)
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    double *const x[3] = {P->x[0], P->x[1], P->x[2]};
    const double g2 = THROUGH_GATE * THROUGH_GATE * m->l0 * m->l0;
    const long none = (long)P->n;
    long first = none;
    /* from the fluid side (the dummies have no lists of their own): each fluid particle near
     * a dummy of a patch, tested against that patch */
#pragma omp parallel for schedule(static) reduction(min : first)
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_FLUID || (long)i >= first) continue;
        if (m->fixed && m->fixed[i]) continue; /* given: lub_mps_buried */
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            const size_t d = nb->j[q];
            if (P->kind[d] != LUB_DUMMY) continue;
            if (!(lub_neighbours_r(nb, x, d, i, NULL) < g2)) continue;
            double a, b;
            if (through(m, dt, i, P->patch[d], &a, &b)) {
                first = (long)i;
                break;
            }
        }
    }
    if (first == none) return -1;
    /* the patch of the crossing (the first in patch order when several) */
    for (unsigned k = 0; k < (unsigned)P->npatches; k++)
        if (through(m, dt, (size_t)first, k, t0, t1)) {
            *patch = k;
            break;
        }
    return first;
}

size_t lub_mps_buried(const lub_mps *m, double dt, uint8_t *flag)
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    double *const x[3] = {P->x[0], P->x[1], P->x[2]};
    const double g2 = THROUGH_GATE * THROUGH_GATE * m->l0 * m->l0;
    memset(flag, 0, P->n);
    if (!m->fixed) return 0;
    size_t n = 0;
    /* from the fluid side (the dummies have no lists of their own) */
#pragma omp parallel for schedule(static) reduction(+ : n)
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_FLUID || !m->fixed[i]) continue;
        for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
            const size_t d = nb->j[q];
            if (P->kind[d] != LUB_DUMMY) continue;
            if (!(lub_neighbours_r(nb, x, d, i, NULL) < g2)) continue;
            double a = 0, b = 0;
            through(m, dt, i, P->patch[d], &a, &b);
            if (b > THROUGH_DEPTH * m->l0) {
                flag[i] = 1, n++;
                break;
            }
        }
    }
    return n;
}

lub_step_status lub_mps_check(lub_mps *m, double dt, long *bad, char *msg, size_t msgsize)
{
    lub_particles *P = m->P;
    *bad = -1;
    msg[0] = '\0';
    for (size_t i = 0; i < P->n; i++) {
        int finite = isfinite(P->p[i]);
        for (int d = 0; d < m->dim; d++) finite &= isfinite(P->x[d][i]) && isfinite(P->u[d][i]);
        if (!finite) {
            *bad = (long)i;
            snprintf(msg, msgsize,
                     "non-finite value at %s particle id %llu: position (%g, %g), velocity "
                     "(%g, %g), pressure %g",
                     kind_name(P->kind[i]), (unsigned long long)P->id[i], P->x[0][i], P->x[1][i],
                     P->u[0][i], P->u[1][i], P->p[i]);
            return LUB_STEP_NONFINITE;
        }
        for (int d = 0; d < m->dim; d++) {
            if (m->periodic[d]) continue;
            if (P->x[d][i] < m->lo[d] || P->x[d][i] > m->hi[d]) {
                *bad = (long)i;
                snprintf(msg, msgsize,
                         "%s particle id %llu left the domain: %c = %g outside [%g, %g] "
                         "(velocity %g, %g)",
                         kind_name(P->kind[i]), (unsigned long long)P->id[i], "xyz"[d],
                         P -> x[d][i], m -> lo[d], m -> hi[d], P -> u[0][i], P -> u[1][i]);
                return LUB_STEP_ESCAPED;
            }
        }
    }
    unsigned patch = 0;
    double t0 = 0, t1 = 0;
    long b = through_wall(m, dt, &patch, &t0, &t1);
    if (b >= 0) {
        const size_t i = (size_t)b;
        char pos[96], vel[96];
        if (m->dim == 3) {
            snprintf(pos, sizeof pos, "%g, %g, %g", P->x[0][i], P->x[1][i], P->x[2][i]);
            snprintf(vel, sizeof vel, "%g, %g, %g", P->u[0][i], P->u[1][i], P->u[2][i]);
        } else {
            snprintf(pos, sizeof pos, "%g, %g", P->x[0][i], P->x[1][i]);
            snprintf(vel, sizeof vel, "%g, %g", P->u[0][i], P->u[1][i]);
        }
        *bad = b;
        snprintf(msg, msgsize,
                 "fluid particle id %llu went through the wall '%s': position (%s), velocity "
                 "(%s), %.2g l0 behind its wall layer (%.2g l0 %s it before the step)",
                 (unsigned long long)P->id[i],
                 patch < (unsigned)P->npatches ? P->patch_names[patch] : "?", pos, vel, t1 / m->l0,
                 fabs(t0) / m->l0, t0 <= 0 ? "in front of" : "behind");
        return LUB_STEP_ESCAPED;
    }
    return LUB_STEP_OK;
}

double lub_mps_max_speed(const lub_mps *m)
{
    const lub_particles *P = m->P;
    double u2 = 0;
#pragma omp parallel for schedule(static) reduction(max : u2)
    for (size_t i = 0; i < P->n; i++) {
        double s = 0;
        for (int d = 0; d < m->dim; d++) s += P->u[d][i] * P->u[d][i];
        if (s > u2) u2 = s;
    }
    return m->par ? lub_par_max(sqrt(u2)) : sqrt(u2); /* several ranks: of all */
}

void lub_mps_ghost_planes_of(const lub_mps *m, size_t i, lub_mps_ghost_planes *g)
{
    const lub_particles *P = m->P;
    const lub_neighbours *nb = &m->nb;
    g->n = 0;
    for (size_t q = nb->start[i]; q < nb->end[i]; q++) {
        const size_t j = nb->j[q];
        if (P->kind[j] != LUB_DUMMY || nb->w[q] <= 0) continue;
        const unsigned p = P->patch[j];
        int k = 0;
        while (k < g->n && g->patch[k] != p) k++;
        if (k < g->n || g->n == LUB_GHOST_PLANES) continue;
        g->patch[k] = p;
        g->ok[k] = lub_mps_wall_plane(m, i, p, g->c[k], g->nrm[k]);
        g->n++;
    }
}

/* The closest a fluid particle is taken to be to the wall in the extrapolation (l0): the ratio
 * d_j / d_i stays bounded for a particle pressed against the wall layer */
#define GHOST_MIN_DEPTH 0.5

double lub_mps_ghost(const lub_mps *m, size_t i, size_t j, const lub_mps_ghost_planes *g,
                     const double kappa[3], double a[3])
{
    a[0] = a[1] = a[2] = 0.0;
    const lub_particles *P = m->P;
    const int flux = m->c.dummy_velocity == LUB_DUMMY_FLUX;
    if (P->kind[j] == LUB_WALL) {
        /* flux: a wall particle carries the slip u_s of (2.8b), the ghost's d_j = 0 */
        int k = 0;
        while (flux && g && kappa && k < g->n && g->patch[k] != P->patch[j]) k++;
        if (!flux || !g || !kappa || k == g->n || !g->ok[k]) return 1.0;
        const double *n = g->nrm[k];
        double kn = 0.0;
        for (int d = 0; d < m->dim; d++) kn += kappa[d] * n[d];
        for (int d = 0; d < m->dim; d++) a[d] = -(kappa[d] - kn * n[d]) * m->l0 * m->l0 / 12.0;
        return 1.0;
    }
    if (m->c.dummy_velocity == LUB_DUMMY_WALL) return 1.0;
    if (m->c.dummy_velocity == LUB_DUMMY_MIRROR || !g) return 2.0;
    int k = 0;
    while (k < g->n && g->patch[k] != P->patch[j]) k++;
    if (k == g->n || !g->ok[k]) return 2.0; /* no wall layer to measure from: the mirror */
    const double *c = g->c[k], *n = g->nrm[k];
    double *const x[3] = {P->x[0], P->x[1], P->x[2]};
    double v[3];
    lub_neighbours_r(&m->nb, x, i, j, v);
    /* depths along n: i in front of the wall layer, j behind it */
    double di = 0.0, dj = 0.0;
    for (int d = 0; d < m->dim; d++) di -= n[d] * c[d], dj += n[d] * (c[d] - v[d]);
    if (!(dj > 0.0)) return 2.0;
    if (di < GHOST_MIN_DEPTH * m->l0) di = GHOST_MIN_DEPTH * m->l0;
    if (kappa) {
        double kn = 0.0;
        for (int d = 0; d < m->dim; d++) kn += kappa[d] * n[d];
        /* flux: the profile continued from the wall's velocity plus the slip
         * u_s = -kappa_t l0^2/12 (methods.md (2.8b)), which enters the ghost as (1 + dj/di) u_s */
        const double s = flux ? -(1.0 + dj / di) * m->l0 * m->l0 / 12.0 : 0.0;
        for (int d = 0; d < m->dim; d++) {
            const double kt = kappa[d] - kn * n[d];
            a[d] = 0.5 * kt * dj * (di + dj) + s * kt;
        }
    }
    return 1.0 + dj / di;
}
