/* lubkit MPS: resolution levels of the overlapping particle technique (OPT, multi-resolution;
 * methods.md §3, thesis §2-2, §4-3-1).
 *
 * The levels themselves (l0 and the x-interval each level owns) are those particleGen
 * generated the particles with: the `levels` list of system/particleGenDict.yaml,
 *
 *     levels:
 *       - { l0: 5.0e-6, region: [-0.0036, 0.0030] }   # level 0 (finest) owns [a1, a2]
 *       - { l0: 4.0e-5 }                               # the last level owns the rest
 *
 * and constant/models.yaml adds how the levels are coupled:
 *
 *     multiResolution:
 *       levels: [ {l0: 5e-6}, {l0: 4e-5} ]  # optional: restates particleGenDict's levels
 *                                           #   (l0, region: checked to agree); fixedBand
 *                                           #   may be overridden per level here
 *       fineRegion: [-0.0036, 0.0030]       # optional: level 0's region (checked)
 *       Nr:           8                     # sub-steps: dt_{k+1} = Nr dt_k (T-19); one value
 *                                           #   for every pair or a list of nlevels-1;
 *                                           #   default the l0 ratio (an integer)
 *       commonDeltaT: false                 # true: every level takes the same dt (T-60)
 *       overlap:   { coarse: 6, fine: 12 }  # L = 6 l0_coarse + 12 l0_fine (T-24; T-23: 6+6)
 *       fixedBand: 4                        # L_fix = 4 l0 of each level (T-25, T-26)
 *       massCorrection: { cMax: 0.24, cMin: 0.048, relax: 10, threshold: 0.002 }  # T-27..29
 *
 * Ownership (as particleGen's): x belongs to the first level whose region [a1, a2] contains
 * it, else to the last level.  The regions must be nested: each level's region strictly
 * inside the next coarser one's (the last level: inside the domain), so every level but the
 * finest owns a ring (two intervals, one in a periodic domain for the last level), and every
 * boundary separates two consecutive levels k (fine) and k+1 (coarse).
 *
 * Overlap at a boundary a (T-23, T-24: L = L_margin,Coarse + L_margin,Fine).  a is the
 * thesis' a1 or a2, "the boundary position between fine and coarse particles for
 * visualization" (Shibata's OPT): it lies inside the overlap.  Each level reaches past a
 * into the other's owned region by its margin,
 *
 *     m_fine   = overlap.fine   l0_fine     (default 12 l0_fine: fine particles outside [a1, a2])
 *     m_coarse = overlap.coarse l0_coarse   (default  6 l0_coarse: coarse particles inside)
 *
 * so the overlap is [a - m_coarse, a + m_fine] at a2 (fine on the left) and
 * [a - m_fine, a + m_coarse] at a1, of length L = m_coarse + m_fine.  The extended region of a
 * level (where its particles exist) is its owned region plus its margins; particles that leave
 * it are deleted.  At each edge of an extended region that lies inside the domain:
 *   - the fixed-velocity band, fixedBand l0 wide (T-25, T-26), inside the extended region:
 *     there the level's temporary velocity (and the pressure used as a boundary value) is
 *     interpolated from the other level (mps/lsq.h), not computed;
 *   - the generation layer, one cell (l0 of the level) wide at the edge, where a particle is
 *     created in every cell that the other level's fluid fills and this level's does not.
 * The two bands of an overlap must not meet (fixedBand l0_fine + fixedBand l0_coarse < L),
 * so each band lies where the other level is computed freely; the overlaps of two boundaries
 * must not meet either (an overlap longer than a level region), and in a non-periodic domain
 * an overlap must not reach past the domain.
 *
 * Any number of levels from 2 up (LUB_MAX_LEVELS; the thesis uses 2 and proposes 3-4 for
 * 3-D), e.g. three:
 *
 *     levels:                                              # particleGenDict.yaml
 *       - { l0: 0.001, region: [0.1, 0.136] }              # level 0 owns [0.1, 0.136]
 *       - { l0: 0.002, region: [0.056, 0.18] }             # level 1 the ring around it
 *       - { l0: 0.004 }                                    # level 2 the rest
 *     multiResolution: { Nr: [2, 2] }                      # models.yaml: Nr_0, Nr_1
 *
 * Sub-stepping (T-19..T-22): level k+1 advances Nr_k steps of level k at once, dt_{k+1} =
 * Nr_k dt_k (dt_factor of level k: the product of the finer levels' Nr); with a Courant
 * number fixed on every level Nr equals the l0 ratio (the thesis' wedge), which is the
 * default and must then be an integer.  commonDeltaT (soft EHL, T-60)
 * gives every level the finest dt.  While level k takes its sub-steps b = 0 .. Nr-1 after the
 * coarser level's step K, the coarser values are interpolated linearly in time
 * (lub_levels_time_weight): T-20 as printed weights the old value by b/Nr, which is 0 at
 * b = 0 where the value must be the level-K one; the weights used are (Nr - b)/Nr for K and
 * b/Nr for K + 1.
 *
 * Mass correction (T-27..T-29; T-61 without cMin): when |M^k - M^0| > threshold M^0, the
 * particles of the overlaps get the x-velocity correction B sgn(M^k - M^0) (sign chosen by the
 * solver to drive the mass back, per boundary), B = max(min(|M^k - M^0| / (rho A C_relax dt),
 * cMax), cMin); models/multiResolution/opt.h.
 *
 * Errors are fatal with file:line of the entry (models.yaml, or particleGenDict.yaml for the
 * regions it owns); the reader asks for every key it knows, so lub_dict_finish() on
 * models.yaml reports unknown keys in multiResolution.
 */
#ifndef LUB_MODELS_LEVELS_H
#define LUB_MODELS_LEVELS_H

#include "geometry/geometry.h"
#include "io/dict.h"
#include "particles/particles.h"

#define LUB_LEVELS_MAX_BOUNDARIES (2 * (LUB_MAX_LEVELS - 1))

typedef struct {
    double l0;        /* particle spacing [m] */
    double region[2]; /* particleGen's region [a1, a2] (the last level: the domain's x) */
    int bounded[2];   /* region end 0 / 1 is a boundary with the next coarser level (not the
                         domain end, not the last level) */
    double ext[2];    /* outer bounds of the extended region: region -+ this level's margin
                         toward the coarser level at bounded ends (last level: domain) */
    int has_hole;     /* level > 0: the finer level's region minus this level's margins */
    double hole[2];   /* open interval where this level has no particles */
    double band;      /* fixed-velocity band width [m] (T-25, T-26) */
    int nr;           /* sub-steps of this level per step of the next coarser level (last: 1) */
    long dt_factor;   /* dt of this level / dt of level 0: product of the finer levels' nr */
} lub_level_def;

typedef struct {
    double x;         /* boundary position: a1 (side 0) or a2 (side 1) of level `fine` */
    int fine, coarse; /* the two levels (coarse = fine + 1) */
    int side;         /* 0: the fine level owns x > a (a1); 1: it owns x < a (a2) */
    double lo, hi;    /* the overlap [lo, hi], hi - lo = L */
} lub_level_boundary;

typedef struct lub_levels {
    int dim;
    int nlevels;
    lub_level_def level[LUB_MAX_LEVELS];
    int nboundaries; /* sorted by x */
    lub_level_boundary boundary[LUB_LEVELS_MAX_BOUNDARIES];
    double xmin, xmax; /* domain in x */
    int periodic;      /* periodic in x */

    double overlap_coarse, overlap_fine; /* L = overlap_coarse l0_coarse + overlap_fine l0_fine */
    int common_dt;                       /* commonDeltaT: every level takes dt of level 0 */

    int mass_correction; /* massCorrection given */
    double c_max, c_min; /* [m/s] (c_min 0: no lower limit, T-61) */
    double relax;        /* C_relax of T-28 */
    double threshold;    /* M' / M^0 of T-27 */

    /* where multiResolution is, for later messages (start-up checks of the solver) */
    char file[512];
    int line, col;
} lub_levels;

/* Read and check the multiResolution entry mr (its node in models.yaml) against the levels
 * of the geometry g (system/particleGenDict.yaml, read by lub_geometry_read).  Fatal (exit 1)
 * with file:line on any bad input: fewer than 2 levels, levels not nested, a restated l0 or
 * region that differs from particleGenDict, a non-integer l0 ratio where Nr defaults to it,
 * Nr < 1, Nr with commonDeltaT, bands that do not fit in an overlap, an overlap longer than
 * a level region or reaching past a non-periodic domain, cMin > cMax.  L keeps no pointer
 * into g or the dictionaries. */
void lub_levels_read(lub_levels *L, lub_node *mr, const lub_geometry *g);

/* For a solver: read system/particleGenDict.yaml (geometry_path), then lub_levels_read, and
 * check that the particles P (may be NULL) carry the same levels (count and l0). */
void lub_levels_read_case(lub_levels *L, lub_node *mr, const char *geometry_path,
                          const lub_particles *P);

/* Where a point is (x only: the levels are x-intervals). */
typedef struct {
    int owner;         /* the level that owns x (particleGen's choice; mass count of T-27) */
    unsigned present;  /* bit k: x is in the extended region of level k */
    unsigned fixed;    /* bit k: x is in a fixed-velocity band of level k (T-25, T-26) */
    unsigned generate; /* bit k: x is in a generation layer of level k */
    int boundary;      /* index of the boundary whose overlap contains x, or -1 */
} lub_level_where;

/* Locate x (wrapped into the period when x is periodic).  Intervals are closed, except the
 * holes (a level exists on the edge of its hole). */
void lub_levels_locate(const lub_levels *L, double x, lub_level_where *w);

/* The part of a level-k particle's cell, the interval [x - l0_k/2, x + l0_k/2] of x it
 * represents, that lies in the part of x level k owns (particleGen's ownership: region k
 * minus the finer level's region; the last level owns the rest of the domain, its ends
 * included), as a fraction in [0, 1].  The mass of T-27 counts every point of space on one
 * level: each fluid particle with rho l0^d times this fraction.  Counting the particles
 * whose centre is owned instead would make M jump by a whole column of particles whenever
 * one crosses a boundary (1-2% of a short film's mass); with the fraction a column crossing
 * a boundary moves M continuously, and a fine and a coarse particle straddling it share the
 * space between them. */
double lub_levels_owned_fraction(const lub_levels *L, int k, double x);

/* The sums of T-27 over the fluid particles of a particle set whose particles carry their
 * level (P->level), each weighted by the owned part f of its cell (lub_levels_owned_fraction):
 * per level the fluid particles, those whose x the level owns, and the sums of f, f u and
 * f |u|^2.  Added to s (zero it first); serial, in the particles' order, so that the sums do
 * not depend on the number of threads (the mass correction acts on them).  The one place
 * where T-27 is summed: the mass correction (multiResolution/opt.c), lubFoam's totals and
 * probe totals. */
typedef struct {
    size_t fluid[LUB_MAX_LEVELS], owned[LUB_MAX_LEVELS];
    double f[LUB_MAX_LEVELS], fu[LUB_MAX_LEVELS][3], fu2[LUB_MAX_LEVELS];
} lub_levels_sums;
void lub_levels_sum(const lub_levels *L, const lub_particles *P, lub_levels_sums *s);
/* The mass of T-27, M = sum_k m_k f_k (m: the particle mass rho l0_k^d of each level). */
double lub_levels_mass(const lub_levels_sums *s, int nlevels, const double *m);

/* Overlap length of the boundary between levels k and k + 1 [m]. */
double lub_levels_overlap(const lub_levels *L, int k);

/* Time interpolation of a coarser level's value while the finer level takes sub-step b
 * (0 <= b < nr) after the coarser step K (T-20..T-22, corrected): the weight of the level-K
 * value; the value at K + 1 gets 1 minus it.  At b = 0 it is 1. */
static inline double lub_levels_time_weight(int b, int nr)
{
    return (double)(nr - b) / (double)nr;
}

/* The film across a boundary, for the solver's start-up check of the coarse resolution
 * (methods.md §3, §6.1: at least 4-5 coarse particles across the gap at a1, thesis case 7).
 *
 * Along the vertical line through x (in 3-D at z = 0, or the domain's middle z when 0 is
 * outside it), between the domain's y-limits, the open space (behind no wall, sampled every
 * dy and its ends found by bisection) that holds the most fluid of the geometry
 * (lub_geometry_fluid_at: the fluid regions of particleGenDict.yaml, no wallGap) is the
 * film.  When walls bound it below and above, h is the clearance between them (a cylinder of
 * radius R over a plane: R - sqrt(R^2 - x^2) + h0 = h0 + x^2/(2R) + ...); when one side is
 * the domain's edge (no upper wall at x: a free surface), h is the depth of the fluid in it,
 * from its lowest to its highest point (the layer particleGen fills). */
typedef enum {
    LUB_GAP_NONE,  /* no fluid on the line */
    LUB_GAP_WALLS, /* the clearance between two walls */
    LUB_GAP_FLUID  /* no wall on one side: the fluid depth */
} lub_gap_kind;

typedef struct {
    lub_gap_kind kind;
    double h;             /* the clearance or the fluid depth [m] */
    double ylo, yhi;      /* the open space's ends */
    int wall_lo, wall_hi; /* walls (indices into the geometry) there, -1: the domain's edge */
} lub_level_gap;

void lub_levels_gap(const lub_geometry *g, double x, double dy, lub_level_gap *gap);

/* One-line summary ("2 levels: l0 5e-06 [-0.0036, 0.003], 4e-05; Nr 8; overlap 0.0003 m"). */
void lub_levels_describe(const lub_levels *L, char *buf, size_t size);

#endif
