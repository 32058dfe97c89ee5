/* Set-up and checks shared by the flow tests (mps_flow_test.c: one level; opt_test.c: two
 * levels coupled by the overlapping particle technique): particles from particleGenDict text,
 * the analytic Couette and Poiseuille profiles, and the binned velocity profile's relative L2
 * error against them.  Header-only (static inline), so that each test program includes it.
 */
#ifndef LUB_TEST_FLOW_H
#define LUB_TEST_FLOW_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "geometry/discretise.h"
#include "geometry/geometry.h"
#include "particles/particles.h"

/* Generate particles from particleGenDict text (as particleGen does). */
static inline void generate(const char *text, lub_particles *P, lub_geometry *g)
{
    char path[] = "/tmp/lubflowXXXXXX";
    int fd = mkstemp(path);
    if (fd < 0 || write(fd, text, strlen(text)) != (ssize_t)strlen(text)) abort();
    close(fd);
    lub_geometry_read(g, path);
    unlink(path);
    lub_geometry_discretise(g, P, 0, NULL);
}

typedef struct {
    double U, H, f, nu;
} flow;

/* Lower wall sliding at U, upper wall at rest, gap H. */
static inline double couette(double y, void *c)
{
    flow *f = c;
    return f->U * (f->H - y) / f->H;
}

/* Body force f along x between walls at rest, gap H. */
static inline double poiseuille(double y, void *c)
{
    flow *f = c;
    return f->f / (2 * f->nu) * y * (f->H - y);
}

/* Mean x-velocity of the fluid particles (those with skip[i] == 0 when skip is given, and x
 * in [xlo, xhi]) in bins of height `bin` along axis ax (bin b centred at b bin); relative L2
 * of the bin means against u_ref(y) at the bins' mean y.  LUB_PROFILE in the environment
 * prints the bins. */
static inline double profile_error_sel(const lub_particles *P, int ax, double bin,
                                       const uint8_t *skip, double xlo, double xhi,
                                       double (*uref)(double, void *), void *ctx)
{
    enum { NB = 64 };
    double sum[NB] = {0}, ysum[NB] = {0};
    int cnt[NB] = {0};
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_FLUID || (skip && skip[i])) continue;
        if (P->x[0][i] < xlo || P->x[0][i] > xhi) continue;
        int b = (int)floor(P->x[ax][i] / bin + 0.5);
        if (b < 0 || b >= NB) continue;
        sum[b] += P->u[0][i];
        ysum[b] += P->x[ax][i];
        cnt[b]++;
    }
    double e2 = 0, r2 = 0;
    for (int b = 0; b < NB; b++) {
        if (!cnt[b]) continue;
        double y = ysum[b] / cnt[b], u = sum[b] / cnt[b], r = uref(y, ctx);
        if (getenv("LUB_PROFILE")) printf("    y %.5f u %.6g ref %.6g n %d\n", y, u, r, cnt[b]);
        e2 += (u - r) * (u - r);
        r2 += r * r;
    }
    return sqrt(e2 / r2);
}

/* The same over all fluid particles, in bins of l0 (level 0). */
static inline double profile_error(const lub_particles *P, int ax, double (*uref)(double, void *),
                                   void *ctx)
{
    return profile_error_sel(P, ax, P->levels[0].l0, NULL, -INFINITY, INFINITY, uref, ctx);
}

#endif
