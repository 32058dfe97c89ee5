/* lubkit post-processing: sampling particle fields (design.md, probe).
 *
 * Everything here works on a lub_particles in memory, so that the probe utility (which reads
 * time folders) and the solver's function objects (which see the particles of the running
 * step) share one implementation and write the same numbers:
 *
 *   fields   a list like "p,U" resolved against the particles: p (pressure), U (velocity:
 *            columns Ux Uy [Uz]), Ux, Uy, Uz, and the optional fields of the file (pMean...);
 *   accum    sums and sample counts per row (a bin or a point), kept over several times so
 *            that a time-window average is the pooled mean sum / count;
 *   bins     uniform bins of width dx on a closed interval [from, to];
 *   sample   particles of one kind (and patch) into bins of x, or of any coordinate (arc
 *            length); a kernel-weighted mean at a point; totals (mass, momentum, energy).
 *
 * Functions check their inputs and return a status where the input can be wrong (with a
 * message for the caller to report at the location of the input, a command-line option or a
 * dictionary entry).
 */
#ifndef LUB_POST_SAMPLE_H
#define LUB_POST_SAMPLE_H

#include <stddef.h>

#include "geometry/geometry.h"
#include "particles/particles.h"

/* ---- fields --------------------------------------------------------------------------- */

#define LUB_POST_MAX_COLS 32

typedef enum { LUB_POST_PRESSURE, LUB_POST_VELOCITY, LUB_POST_EXTRA } lub_post_source;

/* One scalar column: the pressure, a velocity component or an optional field. */
typedef struct {
    lub_post_source src;
    int comp;                      /* velocity component 0..2 */
    char field[LUB_NAME_MAX];      /* optional field name (src == LUB_POST_EXTRA) */
    char column[LUB_NAME_MAX + 8]; /* table header name: "p[Pa]", "Ux[m/s]", "pMean" */
} lub_post_column;

typedef struct {
    int n;
    lub_post_column col[LUB_POST_MAX_COLS];
} lub_post_fields;

/* Resolve a comma-separated list ("p,U", "pMean") against the fields of P: p (alias
 * pressure), U (aliases u, velocity; expands to Ux Uy, and Uz in 3-D), Ux Uy Uz (aliases ux
 * uy uz; Uz only in 3-D), or the name of an optional field of P (which wins over an alias of
 * the same name).  Returns 0, or -1 with a message in err (an unknown name, with a
 * suggestion and the list of the fields P offers; a repeated or empty name; too many
 * columns) for the caller to report with the location of the list. */
int lub_post_fields_parse(lub_post_fields *f, const char *list, const lub_particles *P, char *err,
                          size_t errsize);

/* "p U Ux Uy pMean pnd": the field names P offers (for messages), into buf. */
char *lub_post_fields_available(const lub_particles *P, char *buf, size_t size);

/* The value array of every column in P (vals[c], P->n entries).  Returns 0, or -1 when an
 * optional field is missing from P (a later time folder without it), with its name in err. */
int lub_post_fields_arrays(const lub_post_fields *f, const lub_particles *P, const double **vals,
                           char *err, size_t errsize);

/* ---- accumulators --------------------------------------------------------------------- */

/* nrows x ncols sums and a sample count per row. */
typedef struct {
    int nrows, ncols;
    double *sum;   /* sum[r * ncols + c] */
    double *count; /* samples of row r */
} lub_accum;

void lub_accum_init(lub_accum *a, int nrows, int ncols);
void lub_accum_clear(lub_accum *a);
void lub_accum_free(lub_accum *a);
/* Add one sample v[0..ncols-1] to row r. */
static inline void lub_accum_add(lub_accum *a, int r, const double *v)
{
    double *s = a->sum + (size_t)r * (size_t)a->ncols;
    for (int c = 0; c < a->ncols; c++) s[c] += v[c];
    a->count[r] += 1.0;
}
/* Mean of column c of row r (count must be > 0). */
static inline double lub_accum_mean(const lub_accum *a, int r, int c)
{
    return a->sum[(size_t)r * (size_t)a->ncols + (size_t)c] / a->count[r];
}

/* ---- bins ----------------------------------------------------------------------------- */

#define LUB_BINS_MAX 10000000

/* Bins of width dx from `from`: [from + k dx, from + (k+1) dx), k = 0 .. nbins-1, the last one
 * closed and cut at `to` (so a partial last bin is narrower). */
typedef struct {
    double from, to, dx;
    int nbins;
} lub_bins;

/* 0 on success; -1 when dx <= 0, to <= from, a value is not finite, or the count exceeds
 * LUB_BINS_MAX (the caller reports which). */
int lub_bins_init(lub_bins *b, double from, double to, double dx);
/* Bin of coordinate x, or -1 outside [from, to]. */
int lub_bins_find(const lub_bins *b, double x);
/* Centre of bin k (of its part inside [from, to]). */
double lub_bins_centre(const lub_bins *b, int k);
/* Lower and upper edge of bin k. */
double lub_bins_lower(const lub_bins *b, int k);
double lub_bins_upper(const lub_bins *b, int k);

/* ---- sampling ------------------------------------------------------------------------- */

/* Add the particles of the given kind (LUB_FLUID, LUB_WALL, LUB_DUMMY), and of the given
 * patch when patch >= 0, to the bins of their coordinate coord[i] (NULL: x): one sample of
 * vals[0..a->ncols-1][i] per particle into row lub_bins_find(coord).  Particles outside
 * [from, to] are left out.  a->nrows must be b->nbins.  Returns the samples added. */
size_t lub_sample_bins(lub_accum *a, const lub_bins *b, const lub_particles *P, int kind, int patch,
                       const double *coord, const double *const *vals);

/* The wall particles of `patch` whose surface faces down (dir < 0) or up (dir > 0): on[i] = 1
 * when the outward normal at i, from the centroid of the patch's dummy particles of i's level
 * within 1.5 l0 to i (the dummy layers lie behind the surface), is within 60 degrees of -y
 * (+y), else 0 (every other particle 0).  A closed body (a polygon, a whole circle) has wall
 * particles on all its faces: facing down are those of its lower face, the one a film under
 * it wets, and the bottom corners; the faces steeper than 60 degrees and the top are left out,
 * so that wall pressure binned in x takes each x once.  Works on the particles, so a moving or
 * deforming wall is followed.  Returns the number of particles marked. */
size_t lub_wall_facing(const lub_particles *P, int patch, int dir, unsigned char *on);

/* Kernel-weighted (Shepard) mean at point xq over the fluid and wall particles (not the
 * dummies) within the effective radius re of the level of the particle nearest to xq:
 *
 *     f(xq) = sum_j w(|x_j - xq|) f_j / sum_j w(|x_j - xq|),   w = MPS weight (T-6)
 *
 * for each column (vals[c]), into out[0..ncols-1].  w(0) = 1, so a point on a particle is
 * weighted most by it; a linear field is reproduced exactly where the neighbourhood is
 * symmetric (inside a regular lattice), and a constant field everywhere.  Returns the number
 * of particles used, 0 when none lies within re (out untouched); *re_used (may be NULL)
 * receives re.  Cost: two passes over the particles. */
size_t lub_sample_point(const lub_particles *P, const double *xq, const double *const *vals,
                        int ncols, double *out, double *re_used);

/* Totals over the fluid particles: particle mass m = rho l0^dim with the l0 of its level (per
 * unit depth in 2-D), mass = sum m, momentum = sum m u, kinetic = sum m |u|^2 / 2. */
typedef struct {
    double mass, momentum[3], kinetic;
    size_t nfluid;
} lub_totals;
void lub_totals_compute(lub_totals *t, const lub_particles *P, double rho);

/* Arc length along a 2-D wall of the point x (a particle of the wall), the coordinate of
 * probe wallPressure -arc:
 *   cylinder  s = R theta, theta the angle from the lowest point of the circle, positive
 *             towards +x (so s has the sign of x - x_centre on the lower half), in (-pi R, pi R];
 *   plane     s = (x - point) . t, t the unit tangent with t_x > 0 (t_y > 0 if vertical);
 *   segment   s = (x - from) . t, t the unit vector from `from` to `to`;
 *   polyline  s = the length along the polyline from its first point to the projection of x
 *             on the nearest piece;
 *   polygon   the same along the closed boundary from its first vertex, counter-clockwise
 *             (geometry.h: the vertices as stored).
 * Returns 0, or -1 for other walls (box, sphere) and in 3-D. */
int lub_wall_arc(const lub_wall *w, int dim, const double *x, double *s);

#endif
