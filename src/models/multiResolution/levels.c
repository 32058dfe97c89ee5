/* lubkit MPS: resolution levels of the overlapping particle technique (see levels.h). */
#include "models/multiResolution/levels.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "geometry/discretise.h"

#define NR_MAX        1024L
#define DT_FACTOR_MAX (1L << 30)

/* "file:line" of a node, for messages that point at a second file. */
static const char *where(const lub_node *n, char *buf, size_t size)
{
    if (!n) return "system/particleGenDict.yaml";
    snprintf(buf, size, "%s:%d", lub_node_file(n), lub_node_line(n));
    return buf;
}

static int same_real(double a, double b, double scale)
{
    return fabs(a - b) <= 1e-9 * scale;
}

/* The level regions of particleGenDict: nested, each strictly inside the next coarser one. */
static void take_regions(lub_levels *L, const lub_geometry *g, double tol)
{
    const int n = L->nlevels;
    char wb[600];
    for (int k = 0; k < n; k++) {
        const lub_level_spec *s = &g->levels[k];
        lub_level_def *v = &L->level[k];
        v->l0 = s->l0;
        if (k == n - 1) {
            if (s->has_region && !(s->xmin <= L->xmin + tol && s->xmax >= L->xmax - tol))
                lub_node_error(s->node,
                               "multiResolution: levels are not nested: the last level's region "
                               "[%g, %g] must cover the domain's x [%g, %g] (or drop it: the "
                               "last level owns the rest)",
                               s->xmin, s->xmax, L->xmin, L->xmax);
            v->region[0] = L->xmin;
            v->region[1] = L->xmax;
            continue;
        }
        v->region[0] = s->xmin;
        v->region[1] = s->xmax;
        if (L->periodic && !(s->xmin > L->xmin + tol && s->xmax < L->xmax - tol))
            lub_node_error(s->node,
                           "multiResolution: level %d's region [%g, %g] reaches the periodic "
                           "ends of x [%g, %g]: an overlap across the periodic seam is not "
                           "supported; shift the domain so that the region lies inside it",
                           k, s->xmin, s->xmax, L->xmin, L->xmax);
        v->bounded[0] = s->xmin > L->xmin + tol;
        v->bounded[1] = s->xmax < L->xmax - tol;
        if (!v->bounded[0] && !v->bounded[1])
            lub_node_error(s->node,
                           "multiResolution: level %d's region [%g, %g] covers the domain's x "
                           "[%g, %g]: the coarser levels would own nothing",
                           k, s->xmin, s->xmax, L->xmin, L->xmax);
    }
    /* nesting: region k-1 strictly inside region k where k-1 has a boundary, and reaching the
     * same domain end where it has none */
    for (int k = 1; k < n - 1; k++) {
        const lub_level_def *f = &L->level[k - 1], *c = &L->level[k];
        int ok0 = f->bounded[0] ? c->region[0] < f->region[0] - tol : !c->bounded[0];
        int ok1 = f->bounded[1] ? c->region[1] > f->region[1] + tol : !c->bounded[1];
        if (!ok0 || !ok1)
            lub_node_error(g->levels[k].node,
                           "multiResolution: levels are not nested: level %d's region [%g, %g] "
                           "must contain level %d's region [%g, %g] (%s) with room on each "
                           "side where that one ends inside the domain: every level owns a "
                           "ring around the finer one",
                           k, c->region[0], c->region[1], k - 1, f->region[0], f->region[1],
                           where(g->levels[k - 1].node, wb, sizeof wb));
    }
}

/* Check a restated level list / fineRegion of models.yaml against particleGenDict. */
static void check_restated(lub_levels *L, lub_node *lv, lub_node *mr, const lub_geometry *g,
                           double bands[LUB_MAX_LEVELS], int *band_override)
{
    const double dx = L->xmax - L->xmin;
    char wb[600];
    int region0_given = 0;
    if (lv) {
        size_t n = lub_node_size(lv);
        if (n < 2)
            lub_node_error(lv, "multiResolution: 'levels' must list at least 2 levels, found %zu",
                           n);
        if ((int)n != g->nlevels)
            lub_node_error(lv,
                           "multiResolution: 'levels' lists %zu levels but %s lists %d: the "
                           "particles are generated with particleGenDict's levels (drop "
                           "'levels' here, or make both agree)",
                           n, where(g->levels[0].node, wb, sizeof wb), g->nlevels);
        for (size_t k = 0; k < n; k++) {
            lub_node *m = lub_node_expect_map(lub_node_item(lv, k));
            const lub_level_spec *s = &g->levels[k];
            lub_node *l0n = lub_dict_find(m, "l0");
            if (l0n) {
                double l0 = lub_node_real(l0n, LUB_POSITIVE);
                if (!same_real(l0, s->l0, s->l0))
                    lub_node_error(l0n,
                                   "multiResolution: level %zu has l0 = %g here but l0 = %g in "
                                   "%s, which generated the particles: change both (or drop "
                                   "'l0' here)",
                                   k, l0, s->l0, where(s->node, wb, sizeof wb));
            }
            double r[2];
            if (lub_dict_vec_or(m, "region", r, 2, 2, LUB_ANY)) {
                lub_node *rn = lub_dict_get(m, "region");
                if (!s->has_region)
                    lub_node_error(rn,
                                   "multiResolution: level %zu has no region in %s (it owns "
                                   "the rest of the domain): drop 'region' here",
                                   k, where(s->node, wb, sizeof wb));
                if (!same_real(r[0], s->xmin, dx) || !same_real(r[1], s->xmax, dx))
                    lub_node_error(rn,
                                   "multiResolution: level %zu's region [%g, %g] differs from "
                                   "[%g, %g] in %s, which generated the particles",
                                   k, r[0], r[1], s->xmin, s->xmax, where(s->node, wb, sizeof wb));
                if (k == 0) region0_given = 1;
            }
            if (lub_dict_has(m, "fixedBand")) *band_override = 1;
            bands[k] = lub_dict_real_or(m, "fixedBand", bands[k], LUB_BETWEEN(1.0, 1000.0));
        }
    }
    double fr[2];
    if (lub_dict_vec_or(mr, "fineRegion", fr, 2, 2, LUB_ANY)) {
        lub_node *fn = lub_dict_get(mr, "fineRegion");
        const lub_level_spec *s = &g->levels[0];
        if (region0_given)
            lub_node_error(fn, "multiResolution: give level 0's region either as 'fineRegion' "
                               "or in 'levels', not both");
        if (!same_real(fr[0], s->xmin, dx) || !same_real(fr[1], s->xmax, dx))
            lub_node_error(fn,
                           "multiResolution: 'fineRegion' [%g, %g] differs from level 0's "
                           "region [%g, %g] in %s, which generated the particles",
                           fr[0], fr[1], s->xmin, s->xmax, where(s->node, wb, sizeof wb));
    }
}

/* Sub-step ratios Nr (T-19), or commonDeltaT (T-60). */
static void read_substeps(lub_levels *L, lub_node *mr, const lub_geometry *g)
{
    const int n = L->nlevels;
    lub_node *nrn = lub_dict_find(mr, "Nr");
    L->common_dt = lub_dict_bool_or(mr, "commonDeltaT", 0);
    char wb[600];
    if (nrn && L->common_dt)
        lub_node_error(nrn, "multiResolution: give either 'Nr' or 'commonDeltaT: true', not both");
    for (int k = 0; k < n - 1; k++) {
        if (L->common_dt) {
            L->level[k].nr = 1;
        } else if (nrn && lub_node_type_of(nrn) == LUB_NODE_SCALAR) {
            L->level[k].nr = (int)lub_node_int(nrn, 1, NR_MAX);
        } else if (nrn && lub_node_type_of(nrn) == LUB_NODE_SEQUENCE) {
            size_t m = lub_node_size(nrn);
            if ((int)m != n - 1)
                lub_node_error(nrn,
                               "multiResolution: 'Nr' lists %zu values; %d levels need %d (one "
                               "per pair of consecutive levels, fine to coarse) or a single "
                               "value",
                               m, n, n - 1);
            L->level[k].nr = (int)lub_node_int(lub_node_item(nrn, (size_t)k), 1, NR_MAX);
        } else if (nrn) {
            lub_node_error(nrn, "multiResolution: 'Nr' expects an integer or a list of integers");
        } else {
            /* default: the l0 ratio, which keeps the Courant number of every level (T-19) */
            const double q = L->level[k + 1].l0 / L->level[k].l0, r = nearbyint(q);
            if (!(fabs(q - r) <= 1e-9 * q) || r > NR_MAX)
                lub_node_error(mr,
                               "multiResolution: level %d's l0 (%g, %s) is %.10g times level "
                               "%d's (%g): not an integer, so the sub-step ratio Nr = dt_%d / "
                               "dt_%d (T-19) cannot default to it; give 'Nr' (an integer) or "
                               "'commonDeltaT: true', or make the l0 ratio an integer",
                               k + 1, L->level[k + 1].l0,
                               where(g->levels[k + 1].node, wb, sizeof wb), q, k, L->level[k].l0,
                               k + 1, k);
            L->level[k].nr = (int)r;
        }
    }
    L->level[n - 1].nr = 1;
    long f = 1;
    for (int k = 0; k < n; k++) {
        L->level[k].dt_factor = f;
        if (k < n - 1) {
            f *= L->level[k].nr;
            if (f > DT_FACTOR_MAX)
                lub_node_error(nrn ? nrn : mr,
                               "multiResolution: the coarsest level would take steps more than "
                               "%ld times the finest dt (product of Nr)",
                               DT_FACTOR_MAX);
        }
    }
}

/* Extended regions, holes, boundaries and their overlaps. */
static void build_regions(lub_levels *L)
{
    const int n = L->nlevels;
    for (int k = 0; k < n; k++) {
        lub_level_def *v = &L->level[k];
        if (k == n - 1) {
            v->ext[0] = L->xmin;
            v->ext[1] = L->xmax;
        } else {
            const double mf = L->overlap_fine * v->l0; /* reach into level k+1 */
            v->ext[0] = v->bounded[0] ? v->region[0] - mf : L->xmin;
            v->ext[1] = v->bounded[1] ? v->region[1] + mf : L->xmax;
        }
        if (k > 0) {
            const lub_level_def *f = &L->level[k - 1];
            const double mc = L->overlap_coarse * v->l0; /* reach into level k-1 */
            v->has_hole = 1;
            v->hole[0] = f->bounded[0] ? f->region[0] + mc : -INFINITY;
            v->hole[1] = f->bounded[1] ? f->region[1] - mc : INFINITY;
        }
    }
    L->nboundaries = 0;
    for (int k = 0; k < n - 1; k++)
        for (int s = 0; s < 2; s++) {
            const lub_level_def *v = &L->level[k];
            if (!v->bounded[s]) continue;
            lub_level_boundary *b = &L->boundary[L->nboundaries++];
            const double mf = L->overlap_fine * v->l0, mc = L->overlap_coarse * L->level[k + 1].l0;
            b->x = v->region[s];
            b->fine = k;
            b->coarse = k + 1;
            b->side = s;
            b->lo = s == 0 ? b->x - mf : b->x - mc;
            b->hi = s == 0 ? b->x + mc : b->x + mf;
        }
    /* sort by x (at most 14) */
    for (int i = 1; i < L->nboundaries; i++)
        for (int j = i; j > 0 && L->boundary[j].x < L->boundary[j - 1].x; j--) {
            lub_level_boundary t = L->boundary[j];
            L->boundary[j] = L->boundary[j - 1];
            L->boundary[j - 1] = t;
        }
}

/* The bands fit in each overlap; the overlaps neither meet nor leave the domain. */
static void check_overlaps(const lub_levels *L, lub_node *mr, lub_node *ovn, lub_node *bandn,
                           const lub_geometry *g)
{
    lub_node *at = ovn ? ovn : mr;
    char wb[600];
    const double tol = 1e-9 * (L->xmax - L->xmin);
    for (int i = 0; i < L->nboundaries; i++) {
        const lub_level_boundary *b = &L->boundary[i];
        const double bf = L->level[b->fine].band, bc = L->level[b->coarse].band;
        if (!(bf + bc < b->hi - b->lo - tol))
            lub_node_error(bandn ? bandn : at,
                           "multiResolution: the fixed-velocity bands of levels %d and %d "
                           "(%g + %g m) do not fit in their overlap at x = %g (L = %g m): they "
                           "must leave a gap where both levels are computed; narrow "
                           "'fixedBand' or lengthen 'overlap'",
                           b->fine, b->coarse, bf, bc, b->x, b->hi - b->lo);
    }
    for (int i = 0; i + 1 < L->nboundaries; i++) {
        const lub_level_boundary *a = &L->boundary[i], *b = &L->boundary[i + 1];
        if (a->hi < b->lo) continue;
        lub_level_where w;
        lub_levels_locate(L, 0.5 * (a->x + b->x), &w);
        lub_node_error(at,
                       "multiResolution: an overlap is longer than a level region: the overlaps "
                       "at x = %g ([%g, %g]) and x = %g ([%g, %g]) meet inside level %d's region "
                       "between them (%g m long, %s); enlarge that region or shorten 'overlap' "
                       "(L = %g l0_coarse + %g l0_fine)",
                       a->x, a->lo, a->hi, b->x, b->lo, b->hi, w.owner, b->x - a->x,
                       where(g->levels[w.owner].node, wb, sizeof wb), L->overlap_coarse,
                       L->overlap_fine);
    }
    if (L->nboundaries == 0) return;
    const lub_level_boundary *first = &L->boundary[0], *last = &L->boundary[L->nboundaries - 1];
    if (L->periodic) {
        const double period = L->xmax - L->xmin;
        if (!(last->hi < first->lo + period))
            lub_node_error(at,
                           "multiResolution: an overlap is longer than a level region: the "
                           "overlaps at x = %g ([%g, %g]) and x = %g ([%g, %g]) meet across the "
                           "periodic seam inside level %d's region (%g m long); enlarge the "
                           "domain or shorten 'overlap' (L = %g l0_coarse + %g l0_fine)",
                           last->x, last->lo, last->hi, first->x, first->lo, first->hi,
                           last->coarse, first->x + period - last->x, L->overlap_coarse,
                           L->overlap_fine);
    } else {
        const lub_level_boundary *b = !(first->lo > L->xmin)  ? first
                                      : !(last->hi < L->xmax) ? last
                                                              : NULL;
        if (b)
            lub_node_error(at,
                           "multiResolution: the overlap at x = %g ([%g, %g]) reaches past the "
                           "domain's x [%g, %g]: level %d's region beyond it is shorter than "
                           "the overlap; move the boundary or shorten 'overlap'",
                           b->x, b->lo, b->hi, L->xmin, L->xmax, b->coarse);
    }
}

void lub_levels_read(lub_levels *L, lub_node *mr, const lub_geometry *g)
{
    memset(L, 0, sizeof *L);
    lub_node_expect_map(mr);
    snprintf(L->file, sizeof L->file, "%s", lub_node_file(mr) ? lub_node_file(mr) : "");
    L->line = lub_node_line(mr);
    L->col = lub_node_col(mr);
    L->dim = g->dim;
    L->xmin = g->dmin[0];
    L->xmax = g->dmax[0];
    L->periodic = g->periodic[0];

    /* every key first, so that a misspelt one is reported by lub_dict_finish */
    lub_node *lv = lub_dict_seq_or(mr, "levels");
    lub_dict_find(mr, "fineRegion");
    lub_node *ovn = lub_dict_map_or(mr, "overlap");
    L->overlap_coarse = lub_dict_real_or(ovn, "coarse", 6.0, LUB_BETWEEN(0.0, 1000.0));
    L->overlap_fine = lub_dict_real_or(ovn, "fine", 12.0, LUB_BETWEEN(0.0, 1000.0));
    lub_node *bandn = lub_dict_find(mr, "fixedBand");
    const double band = lub_dict_real_or(mr, "fixedBand", 4.0, LUB_BETWEEN(1.0, 1000.0));
    lub_node *mc = lub_dict_map_or(mr, "massCorrection");
    L->mass_correction = mc != NULL;
    if (mc) {
        L->c_max = lub_dict_real(mc, "cMax", LUB_POSITIVE);
        L->c_min = lub_dict_real_or(mc, "cMin", 0.0, LUB_NONNEGATIVE);
        L->relax = lub_dict_real_or(mc, "relax", 10.0, LUB_POSITIVE);
        L->threshold = lub_dict_real_or(mc, "threshold", 0.002, (lub_range){0.0, 1.0, 0, 1});
        if (L->c_min > L->c_max)
            lub_node_error(lub_dict_get(mc, "cMin"),
                           "multiResolution: massCorrection.cMin (%g) must not exceed cMax (%g)",
                           L->c_min, L->c_max);
    }

    char wb[600];
    if (g->nlevels < 2)
        lub_node_error(mr,
                       "multiResolution needs at least 2 resolution levels, but %s gives a "
                       "single l0: list the levels there ('levels: [ {l0: ..., region: [a1, "
                       "a2]}, {l0: ...} ]')",
                       where(g->levels[0].node, wb, sizeof wb));
    L->nlevels = g->nlevels;
    double bands[LUB_MAX_LEVELS];
    for (int k = 0; k < L->nlevels; k++) bands[k] = band;
    int band_override = 0;
    check_restated(L, lv, mr, g, bands, &band_override);
    take_regions(L, g, 1e-9 * (L->xmax - L->xmin));
    for (int k = 0; k < L->nlevels; k++) L->level[k].band = bands[k] * L->level[k].l0;
    read_substeps(L, mr, g);
    build_regions(L);
    check_overlaps(L, mr, ovn, band_override ? NULL : bandn, g);
}

void lub_levels_read_case(lub_levels *L, lub_node *mr, const char *geometry_path,
                          const lub_particles *P)
{
    lub_geometry g;
    lub_geometry_read(&g, geometry_path);
    lub_levels_read(L, mr, &g);
    lub_geometry_free(&g);
    if (!P) return;
    if (P->nlevels != L->nlevels)
        lub_node_error(mr,
                       "multiResolution: the particles have %d resolution level%s but %s lists "
                       "%d: run particleGen again",
                       P->nlevels, P->nlevels == 1 ? "" : "s", geometry_path, L->nlevels);
    for (int k = 0; k < L->nlevels; k++)
        if (!same_real(P->levels[k].l0, L->level[k].l0, L->level[k].l0))
            lub_node_error(mr,
                           "multiResolution: the particles' level %d has l0 = %g but %s says "
                           "%g: run particleGen again",
                           k, P->levels[k].l0, geometry_path, L->level[k].l0);
}

double lub_levels_overlap(const lub_levels *L, int k)
{
    if (k < 0 || k >= L->nlevels - 1) lub_bug("no boundary between levels %d and %d", k, k + 1);
    return L->overlap_coarse * L->level[k + 1].l0 + L->overlap_fine * L->level[k].l0;
}

void lub_levels_locate(const lub_levels *L, double x, lub_level_where *w)
{
    if (L->periodic) {
        const double period = L->xmax - L->xmin;
        x = L->xmin + fmod(x - L->xmin, period);
        if (x < L->xmin) x += period;
    }
    memset(w, 0, sizeof *w);
    w->owner = L->nlevels - 1;
    for (int k = 0; k < L->nlevels - 1; k++)
        if (x >= L->level[k].region[0] && x <= L->level[k].region[1]) {
            w->owner = k;
            break;
        }
    for (int k = 0; k < L->nlevels; k++) {
        const lub_level_def *v = &L->level[k];
        if (x < v->ext[0] || x > v->ext[1]) continue;
        if (v->has_hole && x > v->hole[0] && x < v->hole[1]) continue;
        const unsigned bit = 1u << k;
        w->present |= bit;
        /* distance to the nearest edge of the extended region that another level lies beyond */
        double d = INFINITY;
        if (v->bounded[0]) d = fmin(d, x - v->ext[0]);
        if (v->bounded[1]) d = fmin(d, v->ext[1] - x);
        if (v->has_hole) {
            if (isfinite(v->hole[0])) d = fmin(d, v->hole[0] - x >= 0 ? v->hole[0] - x : INFINITY);
            if (isfinite(v->hole[1])) d = fmin(d, x - v->hole[1] >= 0 ? x - v->hole[1] : INFINITY);
        }
        if (d <= v->band) w->fixed |= bit;
        if (d <= v->l0) w->generate |= bit;
    }
    w->boundary = -1;
    for (int i = 0; i < L->nboundaries; i++)
        if (x >= L->boundary[i].lo && x <= L->boundary[i].hi) {
            w->boundary = i;
            break;
        }
}

/* Length of [a, b] inside [lo, hi], with the images of [a, b] one period either side when
 * x is periodic. */
static double covered(const lub_levels *L, double a, double b, double lo, double hi)
{
    double len = 0;
    const double period = L->xmax - L->xmin;
    for (int s = L->periodic ? -1 : 0; s <= (L->periodic ? 1 : 0); s++) {
        const double l = fmin(b + s * period, hi) - fmax(a + s * period, lo);
        if (l > 0) len += l;
    }
    return len;
}

double lub_levels_owned_fraction(const lub_levels *L, int k, double x)
{
    if (L->periodic) {
        const double period = L->xmax - L->xmin;
        x = L->xmin + fmod(x - L->xmin, period);
        if (x < L->xmin) x += period;
    }
    const double l0 = L->level[k].l0, a = x - 0.5 * l0, b = x + 0.5 * l0;
    const double in_k =
        k == L->nlevels - 1 ? l0 : covered(L, a, b, L->level[k].region[0], L->level[k].region[1]);
    const double in_finer =
        k == 0 ? 0 : covered(L, a, b, L->level[k - 1].region[0], L->level[k - 1].region[1]);
    const double f = (in_k - in_finer) / l0;
    return f < 0 ? 0 : f > 1 ? 1 : f;
}

void lub_levels_sum(const lub_levels *L, const lub_particles *P, lub_levels_sums *s)
{
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_FLUID) continue;
        const int k = P->level[i];
        lub_level_where w;
        lub_levels_locate(L, P->x[0][i], &w);
        s->fluid[k]++;
        if (w.owner == k) s->owned[k]++;
        const double f = lub_levels_owned_fraction(L, k, P->x[0][i]);
        s->f[k] += f;
        for (int d = 0; d < P->dim; d++) {
            s->fu[k][d] += f * P->u[d][i];
            s->fu2[k] += f * P->u[d][i] * P->u[d][i];
        }
    }
}

double lub_levels_mass(const lub_levels_sums *s, int nlevels, const double *m)
{
    double mass = 0.0;
    for (int k = 0; k < nlevels; k++) mass += m[k] * s->f[k]; /* T-27 */
    return mass;
}

void lub_levels_describe(const lub_levels *L, char *buf, size_t size)
{
    size_t len = 0;
#define PUT(...)                                                                                   \
    do {                                                                                           \
        if (len < size) len += (size_t)snprintf(buf + len, size - len, __VA_ARGS__);               \
    } while (0)
    PUT("%d levels: l0", L->nlevels);
    for (int k = 0; k < L->nlevels; k++) {
        PUT(" %g", L->level[k].l0);
        if (k < L->nlevels - 1) PUT(" in [%g, %g],", L->level[k].region[0], L->level[k].region[1]);
    }
    if (L->common_dt) {
        PUT("; common dt");
    } else {
        PUT("; Nr");
        for (int k = 0; k < L->nlevels - 1; k++) PUT("%s%d", k ? "," : " ", L->level[k].nr);
    }
    PUT("; overlap");
    for (int k = 0; k < L->nlevels - 1; k++) PUT("%s%g", k ? "," : " ", lub_levels_overlap(L, k));
    PUT(" m; bands");
    for (int k = 0; k < L->nlevels; k++) PUT("%s%g", k ? "," : " ", L->level[k].band);
    PUT(" m");
    if (L->mass_correction)
        PUT("; mass correction cMax %g, cMin %g, relax %g, threshold %g", L->c_max, L->c_min,
            L->relax, L->threshold);
    else
        PUT("; no mass correction");
#undef PUT
}

/* ---- the film across a boundary (start-up check) ---------------------------------------- */

typedef struct {
    const lub_geometry *g;
    double x, z;
} column;

static void column_point(const column *c, double y, double *p)
{
    p[0] = c->x;
    p[1] = y;
    p[2] = c->z;
}

static int column_solid(const column *c, double y)
{
    double p[3];
    column_point(c, y, p);
    for (int w = 0; w < c->g->nwalls; w++)
        if (lub_wall_behind(&c->g->walls[w], p, c->g->dim, 0.0)) return w + 1;
    return 0;
}

static int column_fluid(const column *c, double y)
{
    double p[3];
    column_point(c, y, p);
    return lub_geometry_fluid_at(c->g, p, 0.0);
}

/* The edge of a property between y0 (where pred is a) and y1 (where it is !a), by bisection. */
static double column_edge(const column *c, int (*pred)(const column *, double), double y0,
                          double y1)
{
    const int a = pred(c, y0) != 0;
    for (int it = 0; it < 80 && y0 != y1; it++) {
        double m = 0.5 * (y0 + y1);
        if (m == y0 || m == y1) break;
        if ((pred(c, m) != 0) == a)
            y0 = m;
        else
            y1 = m;
    }
    return 0.5 * (y0 + y1);
}

void lub_levels_gap(const lub_geometry *g, double x, double dy, lub_level_gap *gap)
{
    memset(gap, 0, sizeof *gap);
    gap->kind = LUB_GAP_NONE;
    gap->wall_lo = gap->wall_hi = -1;
    column c = {g, x, 0.0};
    if (g->dim == 3 && !(g->dmin[2] <= 0.0 && g->dmax[2] >= 0.0))
        c.z = 0.5 * (g->dmin[2] + g->dmax[2]);
    const double ymin = g->dmin[1], ymax = g->dmax[1], span = ymax - ymin;
    if (!(span > 0.0)) return;
    double nn = dy > 0.0 ? ceil(span / dy) + 1.0 : 1001.0;
    long n = nn < 1001.0 ? 1001 : nn > 1e6 ? 1000000 : (long)nn;
    const double h = span / (double)(n - 1);
#define YAT(j) ((j) == n - 1 ? ymax : ymin + (double)(j)*h)
    /* the open run (no wall behind) holding the most fluid samples */
    long best0 = -1, best1 = -1, bestf = 0, j0 = -1, nf = 0, f0 = -1, f1 = -1, bf0 = -1, bf1 = -1;
    for (long j = 0; j <= n; j++) {
        const int open = j < n && !column_solid(&c, YAT(j));
        if (open) {
            if (j0 < 0) j0 = j, nf = 0, f0 = f1 = -1;
            if (column_fluid(&c, YAT(j))) {
                if (f0 < 0) f0 = j;
                f1 = j;
                nf++;
            }
            continue;
        }
        if (j0 >= 0 && nf > bestf) best0 = j0, best1 = j - 1, bestf = nf, bf0 = f0, bf1 = f1;
        j0 = -1;
    }
    if (bestf == 0) return;
    gap->ylo = best0 == 0 ? ymin : column_edge(&c, column_solid, YAT(best0 - 1), YAT(best0));
    gap->yhi = best1 == n - 1 ? ymax : column_edge(&c, column_solid, YAT(best1 + 1), YAT(best1));
    if (best0 > 0) gap->wall_lo = column_solid(&c, YAT(best0 - 1)) - 1;
    if (best1 < n - 1) gap->wall_hi = column_solid(&c, YAT(best1 + 1)) - 1;
    if (gap->wall_lo >= 0 && gap->wall_hi >= 0) {
        gap->kind = LUB_GAP_WALLS;
        gap->h = gap->yhi - gap->ylo;
    } else {
        /* a free surface: the fluid's extent in the open space */
        double lo = bf0 == 0 ? ymin : column_edge(&c, column_fluid, YAT(bf0), YAT(bf0 - 1));
        double hi = bf1 == n - 1 ? ymax : column_edge(&c, column_fluid, YAT(bf1), YAT(bf1 + 1));
        gap->kind = LUB_GAP_FLUID;
        gap->h = hi - lo;
    }
#undef YAT
}
