/* Free-surface validation report (not a test; make bench runs it): the collapse of a water
 * column twice as high as it is wide (Martin & Moyce 1952), against the measured surge front
 * (tutorials/damBreakMartinMoyce/martinMoyce1952.dat: Z = x_front / a against
 * T = t sqrt(2 g / a), two experiment series).
 *
 * The front of the particle column is the largest x of the fluid particles within 2 l0 of
 * the floor, plus l0/2 (particles are the centres of cells of size l0).  It reports, for
 * 1 <= T <= 3, how far the front is from the band spanned by the two experiment series
 * (each interpolated linearly in T), in Z, and how often that is more than the scatter
 * between them there (issue 4 asks for "within the scatter between the two experimental
 * series up to T = 3").  The distance is given in Z, not in units of the scatter: where the
 * two series cross, their scatter is near 0 and the ratio says nothing.
 *
 * Finding (a = 0.1 m, 20 and 40 particles across the column, same result within 1%; the
 * tutorial tutorials/damBreakMartinMoyce, a = 0.146 m, 16 and 40 across, likewise): the
 * front moves at the measured speed but leads the data by 0.19-0.28 in Z from the series'
 * first point (T = 0.83) on, as if it had started dT = 0.2-0.24 earlier; unchanged with the
 * standard gradient, without the collision model or without the pressure predictor.  The
 * start of the collapse and its energy agree with references independent of the
 * experiments (tests/cases/martinMoyce, tutorials/README.md).
 *
 *     build/bench/martinMoyce_bench [particles across the column, default 20]
 */
#include <math.h>
#include <stdlib.h>
#include <unistd.h>

#include "geometry/discretise.h"
#include "geometry/geometry.h"
#include "io/case.h"
#include "io/table.h"
#include "models/collision/collision.h"
#include "mps/mps.h"
#include <stdio.h>
#include <string.h>

/* Linear interpolation of Z(T) in one experiment series (rows with that column width). */
static int series_at(const lub_table *t, double width_in, double T, double *Z)
{
    int cT = lub_table_col(t, "T"), cZ = lub_table_col(t, "Z"), ca = lub_table_col(t, "a_in");
    double T0 = NAN, Z0 = NAN;
    for (size_t r = 0; r < t->nrow; r++) {
        if (lub_table_at(t, r, (size_t)ca) != width_in) continue;
        double T1 = lub_table_at(t, r, (size_t)cT), Z1 = lub_table_at(t, r, (size_t)cZ);
        if (!isnan(T0) && T0 <= T && T <= T1) {
            *Z = Z0 + (Z1 - Z0) * (T - T0) / (T1 - T0);
            return 1;
        }
        T0 = T1, Z0 = Z1;
    }
    return 0;
}

static int report(double across)
{
    const double a = 0.1, l0 = a / across, g = 9.81;
    char dict[1024];
    snprintf(dict, sizeof dict,
             "dimension: 2\n"
             "l0: %g\n"
             "domain: { min: [-0.02, -0.02], max: [%g, %g] }\n"
             "walls:\n"
             "  tank: { type: box, min: [0, 0], max: [%g, %g], fluid: inside }\n"
             "fluid:\n"
             "  - { type: box, min: [0, 0], max: [%g, %g] }\n",
             l0, 4 * a + 0.02, 3 * a + 0.02, 4 * a, 3 * a, a, 2 * a);
    char path[] = "/tmp/lubdamXXXXXX";
    int fd = mkstemp(path);
    if (fd < 0 || write(fd, dict, strlen(dict)) != (ssize_t)strlen(dict)) abort();
    close(fd);
    lub_geometry geo;
    lub_geometry_read(&geo, path);
    unlink(path);
    lub_particles P = {0};
    lub_geometry_discretise(&geo, &P, 0, NULL);

    lub_mps_config c;
    lub_mps_config_defaults(&c);
    c.rho = 1000;
    c.nu = 1e-6;
    c.viscosity = LUB_VISCOSITY_CN;
    c.gravity = 1;
    c.g[1] = -g;
    lub_mps m;
    lub_mps_init(&m, &P, &c, geo.dmin, geo.dmax, geo.periodic);
    const lub_collision col = lub_collision_defaults();
    lub_collision_attach(&m, &col);

    char data[LUB_PATH_MAX];
    const char *top = getenv("LUB_TOP");
    snprintf(data, sizeof data, "%s/tutorials/damBreakMartinMoyce/martinMoyce1952.dat",
             top ? top : ".");
    lub_table t;
    lub_table_read(&t, data);

    const double dt = 5e-4, tscale = sqrt(2 * g / a);
    int ok = 1, checked = 0, outside = 0;
    double worst = 0, worst_scatter = 0, worst_T = 0; /* largest distance from the band */
    char msg[512];
    long bad;
    for (int k = 1; ok && k * dt * tscale <= 3.0 + 1e-9; k++) {
        if (lub_mps_step(&m, dt, &bad, msg, sizeof msg) != LUB_STEP_OK) {
            printf("  step %d failed: %s\n", k, msg);
            ok = 0;
            break;
        }
        double T = k * dt * tscale, xf = 0;
        for (size_t i = 0; i < P.n; i++)
            if (P.kind[i] == LUB_FLUID && P.x[1][i] < 2 * l0 && P.x[0][i] > xf) xf = P.x[0][i];
        double Z = (xf + 0.5 * l0) / a, Z1, Z2;
        if (T < 1.0 || !series_at(&t, 1.125, T, &Z1) || !series_at(&t, 2.25, T, &Z2)) continue;
        double lo = fmin(Z1, Z2), hi = fmax(Z1, Z2), scatter = hi - lo;
        double dev = Z < lo ? lo - Z : Z > hi ? Z - hi : 0; /* outside the band */
        if (dev > worst) worst = dev, worst_scatter = scatter, worst_T = T;
        if (dev > scatter) outside++;
        checked++;
        if (k % 20 == 0) printf("  %8.3f %8.3f %8.3f %8.3f\n", T, Z, Z1, Z2);
    }
    printf("# Martin & Moyce: %d times compared for 1 <= T <= 3, %d outside the band widened "
           "by the scatter; largest distance from the band %.3f in Z (at T = %.2f, where the "
           "series differ by %.3f)\n",
           checked, outside, worst, worst_T, worst_scatter);
    lub_table_free(&t);
    lub_mps_free(&m);
    lub_particles_free(&P);
    lub_geometry_free(&geo);
    return ok ? 0 : 2;
}

int main(int argc, char **argv)
{
    double across = argc > 1 ? atof(argv[1]) : 20;
    printf("# collapse of a water column (a = 0.1 m, %g particles across) against Martin & "
           "Moyce (1952)\n#        T        Z  Z(1.125in) Z(2.25in)\n",
           across);
    return report(across);
}
