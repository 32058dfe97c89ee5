/* postErr: compare a table with a reference table (e.g. probe output with reynoldsRef).
 *
 *     postErr postProcessing/probe/0.03/p.dat postProcessing/reynoldsRef/0/p.dat -max relL2=0.1
 *
 * Both tables are sorted by x and read as piecewise-linear functions.  The comparison grid is
 * the table's own x points inside the common range [xmin, xmax] plus the two range ends; the
 * reference is interpolated linearly onto it.  L1 and L2 norms are trapezoid integrals over
 * that grid; integrals and peaks use each table's own points clipped to the range.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/args.h"
#include "core/error.h"
#include "io/case.h"
#include "io/dict.h"
#include "io/table.h"

static const char *description =
    "Reads two tables ('# name ...' header, whitespace-separated rows; '-' is standard\n"
    "input) and compares column Y of TABLE with column YREF of REFERENCE as functions of x.\n"
    "\n"
    "Method: each table is sorted by x (rows with the same x must have the same value) and\n"
    "read as a piecewise-linear function.  The common range is the overlap of the two x\n"
    "ranges, cut to -range when given.  The comparison grid is TABLE's x points inside the\n"
    "range plus the range ends (TABLE interpolated there); REFERENCE is interpolated\n"
    "linearly onto that grid.  With d = y - yref on the grid:\n"
    "  relL1   = int|d| / int|yref|, relL2 = sqrt(int d^2 / int yref^2)  (trapezoid rule)\n"
    "  relLinf = max|d| / max|yref|\n"
    "  peak, xPeak: largest value of each table in the range and its x (own points and the\n"
    "  interpolated range ends); peakErr = (peak - peakRef) / |peakRef|;\n"
    "  xPeakErr = xPeak - xPeakRef, xPeakErrRel = xPeakErr / (xmax - xmin);\n"
    "  integral: trapezoid rule on each table's own points in the range, interpolated at the\n"
    "  ends; integralErr = (integral - integralRef) / |integralRef|.\n"
    "The signed errors (peakErr, xPeakErr, xPeakErrRel, integralErr) are nan when their\n"
    "reference is 0.  Output: one 'name value' line each for xmin xmax n relL1 relL2 relLinf\n"
    "peak peakRef peakErr xPeak xPeakRef xPeakErr xPeakErrRel integral integralRef\n"
    "integralErr (n: points of the comparison grid), then a comment line '# relative\n"
    "error: L2 3.71%, ...' that says the same in per cent for a reader.\n"
    "\n"
    "-max NORM=VALUE fails (exit 1, after printing) when |NORM| > VALUE; NORM is one of\n"
    "relL1 relL2 relLinf peakErr xPeakErr xPeakErrRel integralErr.  Errors (exit 1): no\n"
    "overlap, a missing column (the columns are listed), a table with fewer than 2 rows, a\n"
    "reference that is zero over the whole range (relative errors undefined), bad -range.\n"
    "A relative file name is taken relative to the -case directory.";

typedef struct {
    const char *source;
    size_t n;
    double *x, *y;
} curve;

typedef struct {
    double x, y;
    size_t row;
} point;

static int point_cmp(const void *pa, const void *pb)
{
    const point *a = pa, *b = pb;
    if (a->x != b->x) return a->x < b->x ? -1 : 1;
    return a->row < b->row ? -1 : a->row > b->row; /* stable: keep the file's order */
}

/* A ratio in per cent for the summary line, "3.71%" ("+3.71%" signed; "undefined" for nan),
 * in one of six buffers so that one printf can take several. */
static const char *percent(double v, int sign, int slot)
{
    static char buf[6][32];
    if (isnan(v))
        snprintf(buf[slot], sizeof buf[slot], "undefined (zero reference)");
    else
        snprintf(buf[slot], sizeof buf[slot], sign ? "%+.3g%%" : "%.3g%%", 100 * v);
    return buf[slot];
}

/* Columns xname, yname of t as a function sorted by x. */
static void curve_make(curve *c, const lub_table *t, const char *xname, const char *yname)
{
    int cx = lub_table_col(t, xname), cy = lub_table_col(t, yname);
    if (t->nrow < 2)
        lub_fatal_at(t->source, 0, 0, "needs at least 2 rows to interpolate, found %zu", t->nrow);
    point *p = lub_malloc(t->nrow * sizeof *p);
    for (size_t r = 0; r < t->nrow; r++)
        p[r] = (point){lub_table_at(t, r, (size_t)cx), lub_table_at(t, r, (size_t)cy), r};
    qsort(p, t->nrow, sizeof *p, point_cmp);
    c->source = t->source;
    c->x = lub_malloc(t->nrow * sizeof *c->x);
    c->y = lub_malloc(t->nrow * sizeof *c->y);
    c->n = 0;
    for (size_t r = 0; r < t->nrow; r++) {
        if (c->n > 0 && p[r].x == c->x[c->n - 1]) {
            /* a repeated row is harmless; two values at one x make the function ambiguous */
            if (p[r].y == c->y[c->n - 1]) continue;
            double x = p[r].x, y0 = c->y[c->n - 1], y1 = p[r].y;
            size_t r0 = p[r - 1].row + 1, r1 = p[r].row + 1;
            free(p);
            free(c->x);
            free(c->y);
            lub_fatal_at(t->source, 0, 0,
                         "%s = %.17g appears in data rows %zu and %zu with different %s (%.17g "
                         "and %.17g); a table must be a function of %s",
                         t->names[cx], x, r0, r1, t->names[cy], y0, y1, t->names[cx]);
        }
        c->x[c->n] = p[r].x;
        c->y[c->n] = p[r].y;
        c->n++;
    }
    free(p);
    if (c->n < 2)
        lub_fatal_at(t->source, 0, 0, "needs at least 2 distinct %s values, found 1", t->names[cx]);
}

static void curve_free(curve *c)
{
    free(c->x);
    free(c->y);
}

/* Linear interpolation at xq, c->x[0] <= xq <= c->x[n-1]; exact at the points. */
static double curve_at(const curve *c, double xq)
{
    size_t lo = 0, hi = c->n - 1;
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (c->x[mid] <= xq)
            lo = mid;
        else
            hi = mid;
    }
    double t = (xq - c->x[lo]) / (c->x[hi] - c->x[lo]);
    return (1.0 - t) * c->y[lo] + t * c->y[hi];
}

/* The curve restricted to [a, b]: the ends (interpolated) and the points strictly inside.
 * xs, ys have room for c->n + 2.  Returns the count. */
static size_t curve_clip(const curve *c, double a, double b, double *xs, double *ys)
{
    size_t m = 0;
    xs[m] = a, ys[m++] = curve_at(c, a);
    for (size_t i = 0; i < c->n; i++)
        if (c->x[i] > a && c->x[i] < b) xs[m] = c->x[i], ys[m++] = c->y[i];
    xs[m] = b, ys[m++] = curve_at(c, b);
    return m;
}

static double trapezoid(const double *x, const double *f, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i + 1 < n; i++) s += 0.5 * (f[i] + f[i + 1]) * (x[i + 1] - x[i]);
    return s;
}

/* Index of the largest value (the first one when several are equal). */
static size_t argmax(const double *f, size_t n)
{
    size_t k = 0;
    for (size_t i = 1; i < n; i++)
        if (f[i] > f[k]) k = i;
    return k;
}

static double rel(double v, double ref)
{
    return ref != 0.0 ? (v - ref) / fabs(ref) : NAN;
}

/* "X0:X1" with either side empty (open). */
static void parse_range(const char *s, double *x0, double *x1)
{
    const char *colon = strchr(s, ':');
    if (!colon) lub_fatal("-range '%s': expected X0:X1, e.g. -range -0.002:0.003", s);
    char left[128], right[128];
    size_t ll = (size_t)(colon - s);
    if (ll >= sizeof left || strlen(colon + 1) >= sizeof right)
        lub_fatal("-range '%s': too long", s);
    memcpy(left, s, ll);
    left[ll] = '\0';
    strcpy(right, colon + 1);
    *x0 = -INFINITY;
    *x1 = INFINITY;
    if (*left && lub_parse_real(left, x0)) lub_fatal("-range '%s': '%s' is not a number", s, left);
    if (*right && lub_parse_real(right, x1))
        lub_fatal("-range '%s': '%s' is not a number", s, right);
    if (!(*x0 < *x1)) lub_fatal("-range '%s': X0 must be less than X1", s);
}

static const char *const NORMS[] = {"relL1",    "relL2",       "relLinf",    "peakErr",
                                    "xPeakErr", "xPeakErrRel", "integralErr"};
#define NNORMS (sizeof NORMS / sizeof NORMS[0])

typedef struct {
    int norm;
    double limit;
    const char *text;
} limit;

static void parse_max(const char *s, limit *l)
{
    const char *eq = strchr(s, '=');
    if (!eq) lub_fatal("-max '%s': expected NORM=VALUE, e.g. -max relL2=0.05", s);
    char name[64];
    size_t nl = (size_t)(eq - s);
    if (nl >= sizeof name) nl = sizeof name - 1;
    memcpy(name, s, nl);
    name[nl] = '\0';
    l->norm = -1;
    for (size_t k = 0; k < NNORMS; k++)
        if (strcmp(name, NORMS[k]) == 0) l->norm = (int)k;
    if (l->norm < 0) {
        const char *near = lub_closest(name, NORMS, NNORMS);
        char hint[100] = "";
        if (near) snprintf(hint, sizeof hint, " (did you mean '%s'?)", near);
        lub_fatal("-max '%s': unknown norm '%s'%s; the norms are relL1 relL2 relLinf peakErr "
                  "xPeakErr xPeakErrRel integralErr",
                  s, name, hint);
    }
    if (lub_parse_real(eq + 1, &l->limit) || l->limit < 0)
        lub_fatal("-max '%s': the limit must be a number >= 0, found '%s'", s, eq + 1);
    l->text = s;
}

static const char *in_case(const lub_args *a, const char *path, char *buf)
{
    if (strcmp(path, "-") == 0 || path[0] == '/' || strcmp(a->case_dir, ".") == 0) return path;
    lub_case c;
    lub_case_open(&c, a->case_dir);
    return lub_case_path(&c, buf, path);
}

int main(int argc, char **argv)
{
    const char *xname = "x", *yname = "p", *xref = NULL, *yref = NULL, *range = NULL, *out = NULL;
    lub_strlist maxes = {0};
    lub_option opts[] = {
        {"-x", "NAME", "column of x (default x)", LUB_OPT_STR, &xname},
        {"-y", "NAME", "column compared (default p)", LUB_OPT_STR, &yname},
        {"-xref", "NAME", "column of x in REFERENCE (default: as -x)", LUB_OPT_STR, &xref},
        {"-yref", "NAME", "column compared in REFERENCE (default: as -y)", LUB_OPT_STR, &yref},
        {"-range", "X0:X1", "compare only on [X0, X1] (either end may be left out)", LUB_OPT_STR,
         &range},
        {"-max", "NORM=VALUE", "exit 1 when |NORM| > VALUE (repeatable)", LUB_OPT_MULTI, &maxes},
        {"-o", "FILE", "write the results to FILE instead of standard output", LUB_OPT_STR, &out},
        {0}};
    lub_program_info info = {.name = "postErr",
                             .summary = "error norms of a table against a reference table",
                             .usage = "[OPTIONS] TABLE REFERENCE",
                             .description = description,
                             .has_case = 1,
                             .min_args = 2,
                             .max_args = 2};
    lub_args a;
    lub_args_parse(&a, argc, argv, &info, opts);
    if (!xref) xref = xname;
    if (!yref) yref = yname;
    if (strcmp(a.pos[0], "-") == 0 && strcmp(a.pos[1], "-") == 0)
        lub_fatal("TABLE and REFERENCE cannot both be standard input ('-')");
    double r0 = -INFINITY, r1 = INFINITY;
    if (range) parse_range(range, &r0, &r1);
    limit *lim = lub_calloc(maxes.n, sizeof *lim);
    for (size_t i = 0; i < maxes.n; i++) parse_max(maxes.items[i], &lim[i]);

    char b0[LUB_PATH_MAX], b1[LUB_PATH_MAX], bo[LUB_PATH_MAX];
    lub_table tt, tr;
    lub_table_read(&tt, in_case(&a, a.pos[0], b0));
    lub_table_read(&tr, in_case(&a, a.pos[1], b1));
    curve ct, cr;
    curve_make(&ct, &tt, xname, yname);
    curve_make(&cr, &tr, xref, yref);

    /* common range */
    double xa = fmax(fmax(ct.x[0], cr.x[0]), r0);
    double xb = fmin(fmin(ct.x[ct.n - 1], cr.x[cr.n - 1]), r1);
    if (!(xa < xb)) {
        if (range)
            lub_fatal("no common x range: %s has x in [%g, %g], %s in [%g, %g], -range %s",
                      ct.source, ct.x[0], ct.x[ct.n - 1], cr.source, cr.x[0], cr.x[cr.n - 1],
                      range);
        lub_fatal("no overlap: %s has x in [%g, %g], %s has x in [%g, %g]", ct.source, ct.x[0],
                  ct.x[ct.n - 1], cr.source, cr.x[0], cr.x[cr.n - 1]);
    }

    /* comparison grid: the table's points in the range and the range ends */
    double *gx = lub_malloc((ct.n + 2) * sizeof *gx), *gy = lub_malloc((ct.n + 2) * sizeof *gy);
    double *gr = lub_malloc((ct.n + 2) * sizeof *gr), *w = lub_malloc((ct.n + 2) * sizeof *w);
    size_t ng = curve_clip(&ct, xa, xb, gx, gy);
    double dmax = 0.0, rmax = 0.0;
    for (size_t i = 0; i < ng; i++) {
        gr[i] = curve_at(&cr, gx[i]);
        dmax = fmax(dmax, fabs(gy[i] - gr[i]));
        rmax = fmax(rmax, fabs(gr[i]));
    }
    if (rmax == 0.0)
        lub_fatal("%s: '%s' is zero over the common range [%g, %g]: relative errors are "
                  "undefined",
                  cr.source, yref, xa, xb);
    for (size_t i = 0; i < ng; i++) w[i] = fabs(gy[i] - gr[i]);
    double l1d = trapezoid(gx, w, ng);
    for (size_t i = 0; i < ng; i++) w[i] = fabs(gr[i]);
    double l1r = trapezoid(gx, w, ng);
    for (size_t i = 0; i < ng; i++) w[i] = (gy[i] - gr[i]) * (gy[i] - gr[i]);
    double l2d = trapezoid(gx, w, ng);
    for (size_t i = 0; i < ng; i++) w[i] = gr[i] * gr[i];
    double l2r = trapezoid(gx, w, ng);

    /* peaks and integrals on each table's own points */
    size_t kt = argmax(gy, ng);
    double peak = gy[kt], xpeak = gx[kt], integral = trapezoid(gx, gy, ng);
    double *hx = lub_malloc((cr.n + 2) * sizeof *hx), *hy = lub_malloc((cr.n + 2) * sizeof *hy);
    size_t nh = curve_clip(&cr, xa, xb, hx, hy);
    size_t kr = argmax(hy, nh);
    double peakref = hy[kr], xpeakref = hx[kr], integralref = trapezoid(hx, hy, nh);

    double norm[NNORMS] = {l1d / l1r,
                           sqrt(l2d / l2r),
                           dmax / rmax,
                           rel(peak, peakref),
                           xpeak - xpeakref,
                           (xpeak - xpeakref) / (xb - xa),
                           rel(integral, integralref)};

    lub_output o;
    lub_output_open(&o, out ? in_case(&a, out, bo) : NULL);
    fprintf(o.fp, "xmin %.17g\nxmax %.17g\nn %zu\n", xa, xb, ng);
    fprintf(o.fp, "relL1 %.17g\nrelL2 %.17g\nrelLinf %.17g\n", norm[0], norm[1], norm[2]);
    fprintf(o.fp, "peak %.17g\npeakRef %.17g\npeakErr %.17g\n", peak, peakref, norm[3]);
    fprintf(o.fp, "xPeak %.17g\nxPeakRef %.17g\nxPeakErr %.17g\nxPeakErrRel %.17g\n", xpeak,
            xpeakref, norm[4], norm[5]);
    fprintf(o.fp, "integral %.17g\nintegralRef %.17g\nintegralErr %.17g\n", integral, integralref,
            norm[6]);
    /* the same for a reader: a comment line, which the scripts that read 'name value' lines
     * (lubSweep, the Allruns: awk '$1 == "relL2"') pass over */
    fprintf(o.fp,
            "# relative error: L2 %s, L1 %s, Linf %s; peak %.4g against %.4g (%s) at x = %.4g "
            "against %.4g (%s of the range); integral %s\n",
            percent(norm[1], 0, 0), percent(norm[0], 0, 1), percent(norm[2], 0, 2), peak, peakref,
            percent(norm[3], 1, 3), xpeak, xpeakref, percent(norm[5], 1, 4),
            percent(norm[6], 1, 5));
    lub_output_close(&o);

    /* accuracy assertions, after the results are out so that a log shows them */
    char msg[2048] = "";
    size_t len = 0;
    for (size_t i = 0; i < maxes.n && len < sizeof msg; i++) {
        double v = norm[lim[i].norm];
        if (isnan(v) || fabs(v) > lim[i].limit)
            len += (size_t)snprintf(msg + len, sizeof msg - len, "%s%s = %.6g %s the limit %g",
                                    len ? "; " : "", NORMS[lim[i].norm], v,
                                    isnan(v) ? "(undefined: zero reference) fails" : "exceeds",
                                    lim[i].limit);
    }
    free(gx), free(gy), free(gr), free(w), free(hx), free(hy), free(lim);
    curve_free(&ct), curve_free(&cr);
    lub_table_free(&tt), lub_table_free(&tr);
    lub_strlist_free(&maxes);
    if (len) lub_fatal("%s", msg);
    return 0;
}
