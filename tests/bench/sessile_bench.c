/* The contact angle of a 2-D sessile drop against the wall factor c of the two-potential
 * surface tension (src/models/surfaceTension/, doc/methods.md §9), for the table c(theta)
 * of doc/methods.md §9 (not part of make test: about a minute per value of c).
 *
 * A drop of 16 x 8 particles (l0 = 0.1 mm, water-like, nu = 1e-4 m^2/s, sigma = 0.03 N/m,
 * no gravity) is set on a plane wall (a wall layer and 3 dummy layers, the fluid's first row
 * l0 above it) and relaxes for 0.1 s with the MPH fluid.  Its cap: height h above the wall's
 * surface (half-way between the wall layer and the first fluid row: the top particle's
 * height above the wall layer, the half spacings cancelling) and half-base a (the first
 * row's half-width plus l0/2); the angle of the circular cap through them,
 * tan(theta/2) = h/a.
 *
 *     build/bench/sessile_bench [c ...]          (default: c = (1 + cos theta)/2 for theta
 *                                                 = 30, 60, 90, 120 degrees)
 *     build/bench/sessile_bench -angle 30 60 ... through contactAngle (the model's table)
 *     LUB_STEPS=N build/bench/sessile_bench ...  N steps of 2e-5 s instead of 5000
 *     LUB_SCALE=s build/bench/sessile_bench ...  a drop of 16 s x 8 s particles
 * The angle is printed every 2500 steps (0.05 s).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"
#include "geometry/discretise.h"
#include "geometry/geometry.h"
#include "io/dict.h"
#include "models/fluid/mph.h"
#include "models/model.h"
#include "mps/mps.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

extern const lub_model_type lub_model_surfaceTension;

typedef struct {
    lub_model model;
    lub_scene scene;
    lub_dict *dict;
} driver;

static int hook(void *ctx, const lub_mps *m, double *const acc[3])
{
    driver *d = ctx;
    return d->model.type->particle_forces(&d->model, m, acc);
}

static double angle_for(double c, double want)
{
    /* LUB_SCALE = s: a drop of 16 s x 8 s particles (the resolution study) */
    const double sc = getenv("LUB_SCALE") ? atof(getenv("LUB_SCALE")) : 1.0;
    char geo[1024];
    snprintf(geo, sizeof geo,
             "dimension: 2\n"
             "l0: 1.0e-4\n"
             "domain: { min: [%g, -0.0006], max: [%g, %g] }\n"
             "dummyLayers: 3\n"
             "walls:\n"
             "  wall: { type: plane, point: [0, 0], normal: [0, 1] }\n"
             "fluid:\n"
             "  - { type: box, min: [%g, 0], max: [%g, %g] }\n",
             -0.005 * sc, 0.005 * sc, 0.003 * sc, -0.0008 * sc, 0.0008 * sc, 0.0008 * sc);
    char path[] = "/tmp/sessileXXXXXX";
    int fd = mkstemp(path);
    if (fd < 0 || write(fd, geo, strlen(geo)) != (ssize_t)strlen(geo)) abort();
    close(fd);
    lub_geometry g;
    lub_geometry_read(&g, path);
    unlink(path);
    lub_particles P = {0};
    lub_geometry_discretise(&g, &P, 0, NULL);
    /* the Young-Dupre angle of c, (1 + cos theta)/2 = c, for comparison */
    const double theta = acos(fmax(-1.0, fmin(1.0, 2 * c - 1))) * 180 / M_PI;
    char text[256];
    if (want > 0) /* the model's own mapping of the angle */
        snprintf(text, sizeof text,
                 "surfaceTension: { sigma: 0.03, contactAngle: { wall: %.12g } }\n", want);
    else
        snprintf(text, sizeof text,
                 "surfaceTension: { sigma: 0.03, wallFactor: { wall: %.12g } }\n", c);
    lub_mps_config cf;
    lub_mps_config_defaults(&cf);
    cf.rho = 1000, cf.nu = 1e-4, cf.bulk_viscosity = 1.0, cf.bulk_modulus = 3e3;
    cf.list_l0 = LUB_MPH_HV, cf.predictor = 0, cf.clip_negative = LUB_NEGATIVE_KEEP;
    cf.v_solver.pcg.precond = LUB_PRECOND_JACOBI;
    cf.v_solver.pcg.tolerance = 1e-10;
    driver d;
    memset(&d, 0, sizeof d);
    d.dict = lub_dict_parse("constant/models.yaml", text);
    d.scene.P = &P;
    d.scene.dict = d.dict;
    d.model.type = &lub_model_surfaceTension;
    d.model.entry = lub_dict_find(lub_dict_root(d.dict), "surfaceTension");
    d.model.state = lub_calloc(1, d.model.type->size);
    d.model.type->read(&d.model, &d.scene);
    d.model.type->configure(&d.model, &d.scene, &cf);
    lub_mps m;
    lub_mps_init(&m, &P, &cf, g.dmin, g.dmax, g.periodic);
    d.scene.nlevels = 1, d.scene.level[0] = &m;
    d.model.type->init(&d.model, &d.scene);
    m.hooks.ctx = &d, m.hooks.particle_forces = hook;
    const double l0 = 1e-4, dt = 2e-5;
    char msg[512];
    long bad;
    const char *ns = getenv("LUB_STEPS");
    const int nsteps = ns ? atoi(ns) : 5000;
    double meas = NAN;
    for (int k = 1; k <= nsteps; k++) {
        if (lub_mph_step(&m, dt, &bad, msg, sizeof msg) != LUB_STEP_OK) {
            printf("c %.4f: step %d failed: %s\n", c, k, msg);
            return NAN;
        }
        if (k % 2500 && k != nsteps) continue;
        double top = -INFINITY, xl = INFINITY, xr = -INFINITY;
        for (size_t i = 0; i < P.n; i++) {
            if (P.kind[i] != LUB_FLUID) continue;
            top = fmax(top, P.x[1][i]);
            if (P.x[1][i] < 1.5 * l0) xl = fmin(xl, P.x[0][i]), xr = fmax(xr, P.x[0][i]);
        }
        const double h = top, a = 0.5 * (xr - xl) + 0.5 * l0;
        meas = 2 * atan(h / a) * 180 / M_PI;
        if (want > 0)
            printf("contactAngle %g, t %.2f s: h %.2f l0, a %.2f l0, contact angle %.1f deg\n",
                   want, k * dt, h / l0, a / l0, meas);
        else
            printf("c %.4f (Young-Dupre angle %5.1f deg), t %.2f s: h %.2f l0, a %.2f l0, contact "
                   "angle %.1f deg\n",
                   c, theta, k * dt, h / l0, a / l0, meas);
        fflush(stdout);
    }
    fflush(stdout);
    lub_mps_free(&m);
    d.model.type->free(&d.model);
    free(d.model.state);
    lub_dict_free(d.dict);
    lub_particles_free(&P);
    lub_geometry_free(&g);
    return meas;
}

int main(int argc, char **argv)
{
    if (argc > 1) {
        if (strcmp(argv[1], "-angle") == 0)
            for (int k = 2; k < argc; k++) angle_for(NAN, atof(argv[k]));
        else
            for (int k = 1; k < argc; k++) angle_for(atof(argv[k]), 0);
        return 0;
    }
    const double th[] = {30, 60, 90, 120};
    for (int k = 0; k < 4; k++) angle_for(0.5 * (1 + cos(th[k] * M_PI / 180)), 0);
    return 0;
}
