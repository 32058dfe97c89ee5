/* The two-potential surface tension (src/models/surfaceTension/, doc/methods.md §9) with the
 * MPH fluid, against closed forms:
 *
 *   - the model's flat interface on the lattice pulls sigma (the calibration of a to the
 *     force), in 2-D and 3-D; its energy is within 5% of sigma;
 *   - a 2-D drop without walls or gravity keeps its momentum (the fluid pair forces are
 *     antisymmetric) and, annealed, holds the Laplace pressure sigma / R in its mechanical
 *     (virial) pressure within 3% (a static drop is a jammed particle packing: from the
 *     lattice disc 0.92 of it, doc/methods.md §9);
 *   - its mode-2 oscillation has Rayleigh's period;
 *   - (K-8) is the gradient of (K-7b), walls included;
 *   - a liquid bridge's pressure is Laplace's for its meniscus;
 *   - sessile drops reach the contact angle asked (60, 90, 120 degrees) within 5 degrees;
 *
 * The model is driven here as a scene drives it (models/model.h): read from a dictionary
 * text, init, and its particle_forces attached to the solver's hook. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include <unistd.h>

#include "geometry/discretise.h"
#include "geometry/geometry.h"
#include "io/dict.h"
#include "models/fluid/mph.h"
#include "models/model.h"
#include "mps/mps.h"
#include "test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

extern const lub_model_type lub_model_surfaceTension;
extern const lub_fluid_type lub_fluid_mps, lub_fluid_mph;
static int use_mps; /* the MPS fluid instead of MPH */

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

/* the model from "surfaceTension: { ... }" text on particles P, before the solver */
static void model_read(driver *d, lub_particles *P, const char *text, lub_mps_config *c)
{
    memset(d, 0, sizeof *d);
    d->dict = lub_dict_parse("constant/models.yaml", text);
    d->scene.P = P;
    d->scene.dict = d->dict;
    d->scene.fluid = use_mps ? &lub_fluid_mps : &lub_fluid_mph;
    d->model.type = &lub_model_surfaceTension;
    d->model.entry = lub_dict_find(lub_dict_root(d->dict), "surfaceTension");
    d->model.state = lub_calloc(1, d->model.type->size);
    d->model.type->read(&d->model, &d->scene);
    d->model.type->check(&d->model, &d->scene);
    d->model.type->configure(&d->model, &d->scene, c);
}

static void model_attach(driver *d, lub_mps *m)
{
    d->scene.nlevels = 1;
    d->scene.level[0] = m;
    d->model.type->init(&d->model, &d->scene);
    m->hooks.ctx = d;
    m->hooks.particle_forces = hook;
}

static void model_free(driver *d)
{
    d->model.type->free(&d->model);
    free(d->model.state);
    lub_dict_free(d->dict);
}

static int run(lub_mps *m, double dt, long nsteps)
{
    char msg[512];
    long bad;
    for (long k = 0; k < nsteps; k++) {
        lub_step_status s = use_mps ? lub_mps_step(m, dt, &bad, msg, sizeof msg)
                                    : lub_mph_step(m, dt, &bad, msg, sizeof msg);
        if (s != LUB_STEP_OK) {
            printf("  step %ld failed: %s\n", k, msg);
            return -1;
        }
    }
    return 0;
}

/* A 2-D drop of the lattice points within radius R0 l0 of the origin, l0 = 0.1 mm. */
static void drop(lub_particles *P, double l0, int R0)
{
    lub_particles_init(P, 2, 1);
    P->nlevels = 1;
    P->levels[0].l0 = l0;
    for (int a = -R0; a <= R0; a++)
        for (int b = -R0; b <= R0; b++)
            if (a * a + b * b < R0 * R0) {
                const double x[3] = {a * l0, b * l0, 0};
                lub_particles_add(P, x, LUB_FLUID, 0, 0);
            }
}

static void config(lub_mps_config *c, double rho, double nu, double lambda, double kappa)
{
    lub_mps_config_defaults(c);
    c->rho = rho;
    c->nu = nu;
    c->bulk_viscosity = lambda;
    c->bulk_modulus = kappa;
    c->list_l0 = LUB_MPH_HV;
    c->predictor = 0;
    c->clip_negative = LUB_NEGATIVE_KEEP;
    c->viscosity = LUB_VISCOSITY_CN;
    c->v_solver.kind = LUB_LINSOLVER_PCG;
    c->v_solver.pcg.precond = LUB_PRECOND_JACOBI;
    c->v_solver.pcg.tolerance = 1e-10;
}

/* Laplace: a drop of N particles, R = l0 sqrt(N / pi) (its area), sigma = 0.03 N/m; the
 * inside pressure is the mean P of the particles within R/2 of the centroid once the drop
 * has settled (viscous time R^2/nu = 10 ms; 3000 steps of 2e-5 s = 60 ms).  Returns
 * dp / (sigma / R). */
static double laplace(int R0, double *mom, double *scale)
{
    const double l0 = 1e-4, rho = 1000, sigma = 0.03, dt = 2e-5;
    lub_particles P;
    drop(&P, l0, R0);
    lub_mps_config c;
    config(&c, rho, 1e-4, 1.0, 3e3); /* dt sqrt(kappa/rho0)/l0 = 0.35 */
    if (use_mps) { /* semi-implicit MPS, its defaults (free surface: p = 0), implicit viscosity */
        lub_mps_config_defaults(&c);
        c.rho = rho, c.nu = 1e-4, c.viscosity = LUB_VISCOSITY_CN;
    }
    driver d;
    model_read(&d, &P, "surfaceTension: { sigma: 0.03 }\n", &c);
    const double L = (R0 + 8) * l0, lo[3] = {-L, -L, -L}, hi[3] = {L, L, L};
    const int periodic[3] = {0, 0, 0};
    lub_mps m;
    lub_mps_init(&m, &P, &c, lo, hi, periodic);
    model_attach(&d, &m);
    const double mass = rho * l0 * l0;
    /* the inside pressure averaged over the last third of the run */
    const double R = l0 * sqrt(P.n / M_PI);
    double sp = 0;
    long n = 0;
    for (int k = 0; k < 3000; k++) {
        if (run(&m, dt, 1)) {
            if (use_mps) {
                double pmax = 0;
                for (size_t i = 0; i < P.n; i++) pmax = fmax(pmax, m.pnd[i] / m.n0);
                printf("  MPS: stopped at step %d, the largest PND %.4f n0 (surface "
                       "particles: %zu)\n",
                       k, pmax, m.st.nsurface);
            } else
                CHECK(0);
            break;
        }
        if (k < 2000) continue;
        double cx = 0, cy = 0;
        for (size_t i = 0; i < P.n; i++) cx += P.x[0][i] / P.n, cy += P.x[1][i] / P.n;
        for (size_t i = 0; i < P.n; i++)
            if (hypot(P.x[0][i] - cx, P.x[1][i] - cy) < 0.5 * R) sp += P.p[i], n++;
        if (getenv("LUB_PROFILE") && k % 100 == 0) printf("    step %d P %.5g\n", k, sp / n);
    }
    double px = 0, py = 0, sc = 0;
    for (size_t i = 0; i < P.n; i++) {
        px += mass * P.u[0][i], py += mass * P.u[1][i];
        sc += mass * hypot(P.u[0][i], P.u[1][i]);
    }
    *mom = hypot(px, py), *scale = sc;
    const double ratio = sp / n / (sigma / R);
    printf("  drop of %zu particles, R = %.2f l0: inside P %.4g Pa, sigma/R %.4g Pa, ratio "
           "%.4f\n",
           P.n, R / l0, sp / n, sigma / R, ratio);
    lub_mps_free(&m);
    model_free(&d);
    lub_particles_free(&P);
    return ratio;
}

/* ---- the drop's inside pressure as the virial of its pair forces --------------------------- */

/* w^a and its r-derivative in metres (methods.md §9): (r/h)(1 - r/h)^2 / (S_a h^2), S_a = pi /
 * (15 l0^2) */
static double wa_m(double l0, double h, double r)
{
    if (!(r < h)) return 0.0;
    const double q = r / h;
    return q * (1 - q) * (1 - q) * (l0 / h) * (l0 / h) * 15.0 / M_PI;
}
static double dwa_m(double l0, double h, double r)
{
    if (!(r < h)) return 0.0;
    const double q = r / h;
    return (1 - q) * (1 - 3 * q) / h * (l0 / h) * (l0 / h) * 15.0 / M_PI;
}

/* The virial of the pair forces on each particle of a 2-D particle set at rest (l0 = 1e-4 m;
 * x periodic over Lx if Lx > 0; the wall factor cwall between fluid and wall or dummy
 * particles, 1 between particles of one kind): wt[i] = -(1/2) sum_j r_ij . f_ij and wx[i] =
 * -(1/2) sum_j (r_ij)_x (f_ij)_x, f_ij the pair force on i from j, every pair force written
 * out again here from methods.md §8-9: the fluid's pressure pairs dV (P_i + P_j) e_ij
 * w_p'(r_ij) of (K-6) (P of each particle as given) and the CPP and DGP pairs of (K-8) (the
 * viscous pairs vanish at rest). */
static void pair_virial(const lub_particles *P, double a, double cwall, double Lx, double *wt,
                        double *wx)
{
    const double l0 = 1e-4, hs = 3.5 * l0, hp = LUB_MPH_HP * l0, k = 0.350778153;
    const double ch = hs / (hs * hs / 10), dA = l0 * l0, ak2 = a * k * k * ch;
    const size_t n = P->n;
    double n0a = 0;
    for (int x = -4; x <= 4; x++)
        for (int y = -4; y <= 4; y++)
            if (x || y) n0a += wa_m(l0, hs, l0 * sqrt((double)(x * x + y * y)));
    double *N = lub_calloc(n, sizeof(double)), *chi[2];
    for (int q = 0; q < 2; q++) chi[q] = lub_calloc(n, sizeof(double));
#define SEPARATION(i, j, r_)                                                                       \
    double r_[2] = {P->x[0][j] - P->x[0][i], P->x[1][j] - P->x[1][i]};                             \
    if (Lx > 0) r_[0] -= Lx * round(r_[0] / Lx);
#define FACTOR(i, j) ((P->kind[i] == LUB_FLUID) == (P->kind[j] == LUB_FLUID) ? 1.0 : cwall)
    for (size_t i = 0; i < n; i++) {
        for (size_t j = 0; j < n; j++) {
            SEPARATION(i, j, r_)
            const double r = hypot(r_[0], r_[1]);
            if (j == i || !(r < hs)) continue;
            const double c = FACTOR(i, j);
            N[i] += c * wa_m(l0, hs, r);
            const double wg = c * lub_mph_w(2, l0, hs, r);
            chi[0][i] += ch * r_[0] * wg, chi[1][i] += ch * r_[1] * wg;
        }
        N[i] = fmin(N[i] - n0a, 0.0);
    }
    for (size_t i = 0; i < n; i++) {
        wt[i] = wx[i] = 0;
        for (size_t j = 0; j < n; j++) {
            SEPARATION(i, j, r_)
            const double r = hypot(r_[0], r_[1]);
            if (j == i || !(r < hs)) continue;
            const double e[2] = {r_[0] / r, r_[1] / r};
            const double v[2] = {chi[0][j] - chi[0][i], chi[1][j] - chi[1][i]};
            const double vr = v[0] * r_[0] + v[1] * r_[1];
            const double c = FACTOR(i, j), cpp = c * a * (N[i] + N[j]) * dwa_m(l0, hs, r);
            const double pp = r < hp ? (P->p[i] + P->p[j]) * lub_mph_dw(2, l0, hp, r) : 0.0;
            const double wg = c * lub_mph_w(2, l0, hs, r), dwg = c * lub_mph_dw(2, l0, hs, r);
            for (int q = 0; q < 2; q++) {
                const double rf =
                    r_[q] * dA * ((cpp + pp) * e[q] - ak2 * (wg * v[q] + vr * e[q] * dwg));
                wt[i] -= 0.5 * rf;
                if (q == 0) wx[i] -= 0.5 * rf;
            }
        }
    }
#undef SEPARATION
#undef FACTOR
    free(N), free(chi[0]), free(chi[1]);
}

/* The mechanical pressure inside a 2-D drop at rest: the mean over the particles within rc
 * of centre of their virial per volume, wt / (d dV).  The drop's particles exert no force on
 * anything else, so sum_i x_i . F_i = 0 at rest (the virial theorem): this interior pressure
 * times the area balances the surface layer's tension times its length, P = f / R in 2-D. */
static double virial_pressure(const lub_particles *P, double a, const double c[2], double rc)
{
    const double dV = 1e-8;
    double *wt = lub_calloc(P->n, sizeof(double)), *wx = lub_calloc(P->n, sizeof(double));
    pair_virial(P, a, 1.0, 0.0, wt, wx);
    double sum = 0;
    size_t cnt = 0;
    for (size_t i = 0; i < P->n; i++)
        if (hypot(P->x[0][i] - c[0], P->x[1][i] - c[1]) <= rc) sum += wt[i] / (2 * dV), cnt++;
    free(wt), free(wx);
    return cnt ? sum / cnt : 0.0;
}

/* The mechanical tension of the model's flat interface on the lattice: a slab 16 rows thick,
 * x periodic over 10 l0, at rest with P = 0 (the bulk rows carry no stress: N = 0, chi = 0);
 * the force across a cut normal to it, per surface, -sum_i wx_i / Lx / 2, for the coefficient
 * a.  The model's a makes it sigma (methods.md §9); Kondo's [KC] would make this interface's
 * energy 1.011 sigma and its force 1.037 sigma. */
static double lattice_tension(double a)
{
    const double l0 = 1e-4;
    lub_particles P;
    lub_particles_init(&P, 2, 1);
    for (int a = 0; a < 10; a++)
        for (int b = 0; b < 16; b++) {
            const double x[3] = {a * l0, b * l0, 0};
            lub_particles_add(&P, x, LUB_FLUID, 0, 0);
        }
    double *wt = lub_calloc(P.n, sizeof(double)), *wx = lub_calloc(P.n, sizeof(double));
    pair_virial(&P, a, 1.0, 10 * l0, wt, wx);
    double sum = 0;
    for (size_t i = 0; i < P.n; i++) sum += wx[i];
    free(wt), free(wx);
    lub_particles_free(&P);
    return -sum / (10 * l0) / 2;
}

/* The test's own coefficient a for sigma: the flat lattice interface pulls sigma
 * (lattice_tension per unit a, formed over all pairs here; the model's calibration,
 * methods.md §9, forms it by rows), so that the forces written out here are the model's. */
static double coef(double sigma)
{
    static double t1 = 0;
    if (t1 == 0) t1 = lattice_tension(1.0);
    return sigma / t1;
}

/* A normal deviate (Box-Muller) from a 64-bit linear congruential generator: the same kicks
 * on every platform. */
static double gauss(uint64_t *s)
{
    double u[2];
    for (int q = 0; q < 2; q++) {
        *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
        u[q] = ((*s >> 11) + 0.5) / 9007199254740992.0; /* in (0, 1) */
    }
    return sqrt(-2 * log(u[0])) * cos(2 * M_PI * u[1]);
}

/* The Laplace pressure of a 2-D drop against the drop's mechanical inside pressure
 * (virial_pressure, within max(R - 2 h_s, R/2) of the centroid: the surface forces reach
 * 2 h_s inwards).  By the virial theorem that pressure is f/R, f the tension of the drop's
 * surface layer; the model's flat interface on the lattice has f = sigma (lattice_tension,
 * with the test's own a: coef).  A static MPH drop is
 * a jammed particle packing: its surface layer keeps the particles it started with, and it
 * holds the tension of a fluid's only where it holds as many particles as a fluid's would
 * (at the least surface energy: f = gamma + dgamma/dGamma dGamma/deps = gamma).  The
 * lattice disc puts 4/pi times that into its outer layer (the staircase), which closes into
 * a hoop-compressed ring: f = 0.92 sigma (doc/methods.md §9).  So the drop is annealed
 * first: 2500 steps (0.05 s) of random velocity kicks of standard deviation 0.02 m/s falling
 * linearly to 0 (their mean and rigid rotation removed: the momentum stays 0, and a spinning
 * drop's centrifugal pressure would lower the inside one), then 2500 steps at rest; the
 * virial averaged over the last 1000.  Asserted: within 3% of f/R = sigma/R (measured
 * 1.010).  LUB_ANNEAL=0 leaves the annealing out (the lattice disc: 0.92 of sigma/R, and it
 * fails), LUB_R0 sets R0 (12). */
static void test_laplace_2d(void)
{
    const char *e = getenv("LUB_R0"), *an = getenv("LUB_ANNEAL");
    const int R0 = e ? atoi(e) : 12;
    const long nanneal = an ? atol(an) : 2500, nsettle = 2500;
    const double l0 = 1e-4, rho = 1000, sigma = 0.03, dt = 2e-5, noise = 0.02;
    lub_particles P;
    drop(&P, l0, R0);
    lub_mps_config c;
    config(&c, rho, 1e-4, 1.0, 3e3); /* dt sqrt(kappa/rho0)/l0 = 0.35 */
    driver d;
    model_read(&d, &P, "surfaceTension: { sigma: 0.03 }\n", &c);
    const double L = (R0 + 8) * l0, lo[3] = {-L, -L, -L}, hi[3] = {L, L, L};
    const int periodic[3] = {0, 0, 0};
    lub_mps m;
    lub_mps_init(&m, &P, &c, lo, hi, periodic);
    model_attach(&d, &m);
    const double R = l0 * sqrt(P.n / M_PI), rin = fmax(R - 7 * l0, 0.5 * R);
    uint64_t seed = 12345;
    double sv = 0, sp = 0, kicks = 0;
    long nv = 0, np = 0;
    for (long k = 0; k < nanneal + nsettle; k++) {
        if (k < nanneal) { /* the kicks, without their mean and their rigid rotation */
            const double s = noise * (1.0 - (double)k / nanneal);
            double um[2] = {0, 0}, cx[2] = {0, 0}, Lz = 0, I = 0;
            for (size_t i = 0; i < P.n; i++)
                for (int q = 0; q < 2; q++) {
                    const double g = s * gauss(&seed);
                    P.u[q][i] += g, um[q] += g / P.n, kicks += rho * l0 * l0 * fabs(g);
                }
            for (size_t i = 0; i < P.n; i++) {
                P.u[0][i] -= um[0], P.u[1][i] -= um[1];
                cx[0] += P.x[0][i] / P.n, cx[1] += P.x[1][i] / P.n;
            }
            for (size_t i = 0; i < P.n; i++) {
                const double x = P.x[0][i] - cx[0], y = P.x[1][i] - cx[1];
                Lz += x * P.u[1][i] - y * P.u[0][i], I += x * x + y * y;
            }
            for (size_t i = 0; i < P.n; i++) {
                P.u[0][i] += Lz / I * (P.x[1][i] - cx[1]);
                P.u[1][i] -= Lz / I * (P.x[0][i] - cx[0]);
            }
        }
        if (run(&m, dt, 1)) {
            CHECK(0);
            break;
        }
        if (k < nanneal + nsettle - 1000 || (k + 1) % 100) continue;
        double cx[2] = {0, 0};
        for (size_t i = 0; i < P.n; i++) cx[0] += P.x[0][i] / P.n, cx[1] += P.x[1][i] / P.n;
        sv += virial_pressure(&P, coef(sigma), cx, rin), nv++;
        for (size_t i = 0; i < P.n; i++)
            if (hypot(P.x[0][i] - cx[0], P.x[1][i] - cx[1]) < rin) sp += P.p[i], np++;
    }
    const double mass = rho * l0 * l0, dp = sigma / R;
    double px = 0, py = 0, scale = 0;
    for (size_t i = 0; i < P.n; i++) {
        px += mass * P.u[0][i], py += mass * P.u[1][i];
        scale += mass * hypot(P.u[0][i], P.u[1][i]);
    }
    const double f = lattice_tension(coef(sigma)), ratio = sv / nv / (f / R);
    printf("  drop of %zu particles, R = %.2f l0, annealed %ld steps: inside pressure (virial) "
           "%.4g Pa: %.4f of f/R (f = %.4f sigma, the lattice interface's tension), %.4f of "
           "sigma/R (the mean P %.4f); momentum %.3g (sum m|u| %.3g, of the kicks %.3g)\n",
           P.n, R / l0, nanneal, sv / nv, ratio, f / sigma, sv / nv / dp, sp / np / dp,
           hypot(px, py), scale, kicks);
    CHECK(hypot(px, py) < 1e-9 * (scale + kicks) + 1e-18);
    CHECK(fabs(ratio - 1) < 0.03);
    lub_mps_free(&m);
    model_free(&d);
    lub_particles_free(&P);
}

/* The same drop with the MPS fluid: a measurement for doc/methods.md §9, run only with
 * LUB_ST_MPS=1 in the environment (it fails, as documented there: MPS holds p = 0 on its
 * free-surface particles, inside the layer h_s = 3.5 l0 deep where the cohesive forces act,
 * so no Laplace jump builds; the drop contracts until no particle is on the surface and the
 * pressure equation, with alpha = 0, has no Dirichlet condition left). */
static void test_laplace_mps(void)
{
    if (!getenv("LUB_ST_MPS")) return;
    double mom, scale;
    use_mps = 1;
    const double r = laplace(10, &mom, &scale);
    use_mps = 0;
    printf("  MPS: inside pressure %.3f of sigma/R\n", r);
}

/* The mode-2 oscillation of a free 2-D drop (no walls, no gravity) against Rayleigh's
 * omega^2 = n (n^2 - 1) sigma / (rho R^3), n = 2 (Rayleigh 1879): the lattice disc of radius
 * 10 l0 (R = 9.85 l0 from its area) settles for 0.03 s (nu 1e-4 m^2/s, lambda 1 Pa s: three
 * viscous times R^2/nu), then is set moving with the potential flow of the mode at its
 * equilibrium crossing, u = eps omega (x, -y) about the centroid, eps = 0.05, with nu =
 * 1e-5 m^2/s (Lamb's decay rate 4 nu / R^2 = 41 1/s, a tenth of omega) and a bulk viscosity
 * of 0.01 Pa s (the particles' divergence of the incompressible mode is not zero: with
 * lambda = 1 Pa s, 100 mu, the period comes out 17% long).  The period from the zero
 * crossings of <x^2> - <y^2> on fixed axes (two full periods); tolerance 1.5 (l0/2) / R =
 * 7.6%: T goes as R^(3/2), and the surface of a particle drop is defined to about half a
 * spacing.  Measured 1.040 (doc/methods.md §9).  The amplitude's decay rate is printed, not
 * asserted (50 against Lamb's 41 1/s). */
static void test_oscillation_2d(void)
{
    const double l0 = 1e-4, rho = 1000, sigma = 0.03, dt = 2e-5, eps = 0.05;
    lub_particles P;
    drop(&P, l0, 10);
    lub_mps_config c;
    config(&c, rho, 1e-4, 1.0, 3e3);
    driver d;
    model_read(&d, &P, "surfaceTension: { sigma: 0.03 }\n", &c);
    const double L = 24 * l0, lo[3] = {-L, -L, -L}, hi[3] = {L, L, L};
    const int periodic[3] = {0, 0, 0};
    lub_mps m;
    lub_mps_init(&m, &P, &c, lo, hi, periodic);
    model_attach(&d, &m);
    CHECK(run(&m, dt, 1500) == 0);
    m.c.nu = 1e-5, m.c.bulk_viscosity = 0.01; /* read by every step */
    const double R = l0 * sqrt(P.n / M_PI);
    const double omega = sqrt(6 * sigma / (rho * R * R * R)), T = 2 * M_PI / omega;
    double c0[2] = {0, 0};
    for (size_t i = 0; i < P.n; i++) c0[0] += P.x[0][i] / P.n, c0[1] += P.x[1][i] / P.n;
    for (size_t i = 0; i < P.n; i++) {
        P.u[0][i] = eps * omega * (P.x[0][i] - c0[0]);
        P.u[1][i] = -eps * omega * (P.x[1][i] - c0[1]);
    }
    double t[8], ext[8], Dprev = 0, dext = 0;
    int nc = 0;
    for (long k = 1; nc < 5 && k < (long)(4 * T / dt); k++) {
        if (run(&m, dt, 1)) break;
        double cx = 0, cy = 0, sx = 0, sy = 0;
        for (size_t i = 0; i < P.n; i++) cx += P.x[0][i] / P.n, cy += P.x[1][i] / P.n;
        for (size_t i = 0; i < P.n; i++)
            sx += (P.x[0][i] - cx) * (P.x[0][i] - cx), sy += (P.x[1][i] - cy) * (P.x[1][i] - cy);
        const double D = (sx - sy) / P.n;
        if (fabs(D) > fabs(dext)) dext = D;
        if (k > 1 && (D > 0) != (Dprev > 0)) {
            t[nc] = (k - 1 + Dprev / (Dprev - D)) * dt;
            ext[nc++] = fabs(dext), dext = 0;
        }
        Dprev = D;
    }
    CHECK(nc == 5);
    if (nc == 5) {
        const double Tm2 = 0.5 * (t[4] - t[0]);
        const double rate = log(ext[1] / ext[4]) / (0.5 * (t[4] + t[3]) - 0.5 * (t[1] + t[0]));
        printf("  drop of %zu particles, R = %.2f l0: period %.5g s (two periods from the "
               "crossings), Rayleigh %.5g s: ratio %.4f; decay rate %.3g 1/s, Lamb %.3g 1/s\n",
               P.n, R / l0, Tm2, T, Tm2 / T, rate, 4 * 1e-5 / (R * R));
        CHECK(fabs(Tm2 / T - 1) < 1.5 * 0.5 * l0 / R);
    }
    lub_mps_free(&m);
    model_free(&d);
    lub_particles_free(&P);
}

/* A 2-D sessile drop (16 x 8 particles set on a plane wall, no gravity; methods.md §9): the
 * contact angle it reaches with contactAngle: theta, through the model's table, against
 * theta within 5 degrees.  The angle of the circular cap through the drop's height h above
 * the wall's surface and its half-base a, tan(theta/2) = h/a, h the top
 * particle's height above the wall layer, a the first row's half-width plus l0/2, as
 * tests/bench/sessile_bench.c measured the table.  One spacing of h or a is 3-5 degrees
 * here. */
static double sessile(double theta, int nsteps)
{
    lub_particles P = {0};
    const char *geo = "dimension: 2\n"
                      "l0: 1.0e-4\n"
                      "domain: { min: [-0.002, -0.0006], max: [0.002, 0.002] }\n"
                      "dummyLayers: 3\n"
                      "walls:\n"
                      "  wall: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                      "fluid:\n"
                      "  - { type: box, min: [-0.0008, 0], max: [0.0008, 0.0008] }\n";
    char path[] = "/tmp/stsessileXXXXXX";
    int fd = mkstemp(path);
    if (fd < 0 || write(fd, geo, strlen(geo)) != (ssize_t)strlen(geo)) abort();
    close(fd);
    lub_geometry g;
    lub_geometry_read(&g, path);
    unlink(path);
    lub_geometry_discretise(&g, &P, 0, NULL);
    lub_mps_config c;
    config(&c, 1000, 1e-4, 1.0, 3e3);
    char text[128];
    snprintf(text, sizeof text, "surfaceTension: { sigma: 0.03, contactAngle: { wall: %g } }\n",
             theta);
    driver d;
    model_read(&d, &P, text, &c);
    lub_mps m;
    lub_mps_init(&m, &P, &c, g.dmin, g.dmax, g.periodic);
    model_attach(&d, &m);
    const double l0 = 1e-4;
    double meas = NAN;
    if (run(&m, 2e-5, nsteps) == 0) {
        double top = -INFINITY, xl = INFINITY, xr = -INFINITY;
        for (size_t i = 0; i < P.n; i++) {
            if (P.kind[i] != LUB_FLUID) continue;
            top = fmax(top, P.x[1][i]);
            if (P.x[1][i] < 1.5 * l0) xl = fmin(xl, P.x[0][i]), xr = fmax(xr, P.x[0][i]);
        }
        const double h = top, a = 0.5 * (xr - xl) + 0.5 * l0;
        meas = 2 * atan(h / a) * 180 / M_PI;
        printf("  contactAngle %g after %.2f s: h %.2f l0, a %.2f l0, the cap's angle %.1f deg\n",
               theta, nsteps * 2e-5, h / l0, a / l0, meas);
    }
    lub_mps_free(&m);
    model_free(&d);
    lub_particles_free(&P);
    lub_geometry_free(&g);
    return meas;
}

/* 60, 90 and 120 degrees; 30 degrees needs 0.3 s (the contact line creeps below 60 degrees:
 * 41.8, 36.4, 33.3, 31.0 degrees at 0.05, 0.1, 0.2, 0.3 s), measured by
 * tests/bench/sessile_bench -angle 30 (doc/methods.md §9), not here. */
static void test_sessile(void)
{
    const double th[] = {60, 90, 120};
    const int steps[] = {5000, 2500, 2500};
    for (int k = 0; k < 3; k++) CHECK(fabs(sessile(th[k], steps[k]) - th[k]) < 5);
}

/* ---- the force against the potential, by finite differences ---------------------------- */

/* the kernels written out again (l0 = 1 units scaled by the caller) */
static double k_wa(double r, double h)
{
    if (r >= h) return 0;
    const double q = r / h;
    return q * (1 - q) * (1 - q) / (M_PI / 15 * h * h);
}
static double k_wg(double r, double h)
{
    if (r >= h) return 0;
    return (1 - r / h) * (1 - r / h) / (M_PI / 6 * h * h);
}

/* V of (K-7b) over every particle, formed here over all pairs (2-D, l0 = 1e-4 m) */
static double potential(const lub_particles *P, double a, const double *cpatch)
{
    const double l0 = 1e-4, h = 3.5, k = 0.350778153, R2 = h * h / 10;
    double n0 = 0;
    for (int x = -4; x <= 4; x++)
        for (int y = -4; y <= 4; y++)
            if (x || y) n0 += k_wa(sqrt(x * x + y * y), h);
    double V = 0;
    for (size_t i = 0; i < P->n; i++) {
        double n = 0, chi[2] = {0, 0};
        for (size_t j = 0; j < P->n; j++) {
            if (j == i) continue;
            const double dx = (P->x[0][j] - P->x[0][i]) / l0, dy = (P->x[1][j] - P->x[1][i]) / l0;
            const double r = sqrt(dx * dx + dy * dy);
            if (r >= h) continue;
            const int fi = P->kind[i] == LUB_FLUID, fj = P->kind[j] == LUB_FLUID;
            const double c = fi == fj ? 1.0 : cpatch[fi ? P->patch[j] : P->patch[i]];
            n += c * k_wa(r, h);
            chi[0] += c * dx * k_wg(r, h), chi[1] += c * dy * k_wg(r, h);
        }
        const double N = fmin(n - n0, 0.0);
        /* chi = (h_s / R2) sum r w in metres: the l0 factors cancel (r / R2 ~ 1 / l0) */
        const double cx = h / R2 * chi[0], cy = h / R2 * chi[1];
        V += 0.5 * a * (N * N + k * k * (cx * cx + cy * cy)) * l0 * l0;
    }
    return V;
}

/* A jittered puddle on a plate (wall layer and 3 dummy layers), the plate's wall factor 0.6:
 * the model's acceleration of a few fluid particles times their mass against -dV/dx formed
 * here by central differences of V (steps of 1e-6 l0).  Checks the derivation of (K-8)
 * from (K-7b), the walls' part included. */
static void test_force_is_gradient(void)
{
    lub_particles P = {0};
    const char *geo = "dimension: 2\n"
                      "l0: 1.0e-4\n"
                      "domain: { min: [-0.0015, -0.0006], max: [0.0015, 0.0012] }\n"
                      "dummyLayers: 3\n"
                      "walls:\n"
                      "  plate: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                      "fluid:\n"
                      "  - { type: box, min: [-0.0005, 0], max: [0.0005, 0.0005] }\n"
                      "jitter: { amplitude: 0.3, seed: 7 }\n";
    char path[] = "/tmp/stgradXXXXXX";
    int fd = mkstemp(path);
    if (fd < 0 || write(fd, geo, strlen(geo)) != (ssize_t)strlen(geo)) abort();
    close(fd);
    lub_geometry g;
    lub_geometry_read(&g, path);
    unlink(path);
    lub_geometry_discretise(&g, &P, 0, NULL);
    lub_mps_config c;
    config(&c, 1000, 1e-4, 1.0, 3e3);
    driver d;
    model_read(&d, &P, "surfaceTension: { sigma: 0.03, wallFactor: { plate: 0.6 } }\n", &c);
    lub_mps m;
    lub_mps_init(&m, &P, &c, g.dmin, g.dmax, g.periodic);
    model_attach(&d, &m);
    double cpatch[LUB_MAX_PATCHES];
    for (int p = 0; p < LUB_MAX_PATCHES; p++) cpatch[p] = 0.6;
    double *acc[3];
    for (int k = 0; k < 3; k++) acc[k] = lub_calloc(P.n, sizeof(double));
    lub_mph_operators(&m, NULL, NULL, NULL); /* the lists at the current positions */
    CHECK(hook(&d, &m, acc) == 1);
    const double l0 = 1e-4, mass = 1000 * l0 * l0, delta = 1e-6 * l0;
    double worst = 0, scale = 0;
    int tested = 0;
    for (size_t i = 0; i < P.n && tested < 6; i++) {
        if (P.kind[i] != LUB_FLUID || i % 7) continue; /* a few, near the plate and not */
        tested++;
        for (int dd = 0; dd < 2; dd++) {
            const double x0 = P.x[dd][i];
            P.x[dd][i] = x0 + delta;
            const double vp = potential(&P, coef(0.03), cpatch);
            P.x[dd][i] = x0 - delta;
            const double vm = potential(&P, coef(0.03), cpatch);
            P.x[dd][i] = x0;
            const double f = -(vp - vm) / (2 * delta), fm = acc[dd][i] * mass;
            worst = fmax(worst, fabs(f - fm));
            scale = fmax(scale, fabs(f));
        }
    }
    printf("  %d particles: the model's force against -dV/dx: worst difference %.3g of %.3g\n",
           tested, worst, scale);
    CHECK(tested == 6);
    CHECK(worst < 1e-5 * scale);
    for (int k = 0; k < 3; k++) free(acc[k]);
    lub_mps_free(&m);
    model_free(&d);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

/* A block of the lattice, nx x ny particles (x nz, periodic along z over nz l0, in 3-D), no
 * walls, at rest: the model's surface forces on the particles beyond the middle cut x = (nx/2
 * - 1/2) l0, summed: the force that the other half exerts across the cut (the forces are sums
 * of antisymmetric pair terms), per length of it, is the pull of the block's two flat
 * interfaces (y = 0 and (ny - 1) l0); the lattice bulk carries none (N = 0, chi = 0 there),
 * and the block's ends, 2 h_s and more from the pairs that cross the cut, none.  Returns
 * that pull per interface (N/m). */
static double block_pull(int dim, int nx, int ny, int nz, double sigma)
{
    const double l0 = 1e-4, rho = 1000;
    lub_particles P;
    lub_particles_init(&P, dim, 1);
    P.nlevels = 1;
    P.levels[0].l0 = l0;
    for (int a = 0; a < nx; a++)
        for (int b = 0; b < ny; b++)
            for (int c = 0; c < (dim == 3 ? nz : 1); c++) {
                const double x[3] = {a * l0, b * l0, c * l0};
                lub_particles_add(&P, x, LUB_FLUID, 0, 0);
            }
    lub_mps_config c;
    config(&c, rho, 1e-4, 1.0, 3e3);
    driver d;
    char text[128];
    snprintf(text, sizeof text, "surfaceTension: { sigma: %.17g }\n", sigma);
    model_read(&d, &P, text, &c);
    const double lo[3] = {-8 * l0, -8 * l0, dim == 3 ? -0.5 * l0 : -8 * l0};
    const double hi[3] = {(nx + 8) * l0, (ny + 8) * l0, dim == 3 ? (nz - 0.5) * l0 : 8 * l0};
    const int periodic[3] = {0, 0, dim == 3};
    lub_mps m;
    lub_mps_init(&m, &P, &c, lo, hi, periodic);
    model_attach(&d, &m);
    double *acc[3];
    for (int k = 0; k < 3; k++) acc[k] = lub_calloc(P.n, sizeof(double));
    lub_mph_operators(&m, NULL, NULL, NULL); /* the lists at the current positions */
    CHECK(hook(&d, &m, acc) == 1);
    const double mass = rho * (dim == 2 ? l0 * l0 : l0 * l0 * l0), xc = (0.5 * nx - 0.5) * l0;
    double Fx = 0;
    for (size_t i = 0; i < P.n; i++)
        if (P.x[0][i] > xc) Fx += acc[0][i] * mass;
    for (int k = 0; k < 3; k++) free(acc[k]);
    lub_mps_free(&m);
    model_free(&d);
    lub_particles_free(&P);
    return -Fx / (2 * (dim == 3 ? nz * l0 : 1.0));
}

/* The 2-D block's surface potential (K-7b), formed here (potential), nx x ny particles */
static double block_energy(int nx, int ny, double a)
{
    const double l0 = 1e-4;
    lub_particles P;
    lub_particles_init(&P, 2, 1);
    for (int x = 0; x < nx; x++)
        for (int y = 0; y < ny; y++) {
            const double r[3] = {x * l0, y * l0, 0};
            lub_particles_add(&P, r, LUB_FLUID, 0, 0);
        }
    double cpatch[LUB_MAX_PATCHES];
    for (int p = 0; p < LUB_MAX_PATCHES; p++) cpatch[p] = 1.0;
    const double V = potential(&P, a, cpatch);
    lub_particles_free(&P);
    return V;
}

/* The calibration of a (methods.md §9): the model's flat interface on the lattice pulls sigma
 * (its mechanical tension: the force across a cut normal to it), in 2-D and 3-D, measured on
 * a block through the model's forces (block_pull), against sigma to round-off.  Its energy
 * per length (2-D: the difference of two blocks' potentials, 10 l0 apart in length, over the
 * two interfaces' 20 l0; their ends alike) is then not sigma: a particle interface is
 * solid-like, its surface stress and surface energy differ (Shuttleworth); printed with the
 * pull of Kondo's energy calibration [KC] a_E = sigma / (h_s (I_N + k^2 I_X)), and asserted
 * within 5% of sigma. */
static void test_calibration(void)
{
    const double sigma = 0.03, l0 = 1e-4, k = 0.350778153;
    const double f2 = block_pull(2, 40, 20, 1, sigma), f3 = block_pull(3, 24, 20, 10, sigma);
    const double a = coef(sigma), aE = sigma / (3.5 * l0 * (0.024679383 + k * k * 0.226126699));
    const double gamma = (block_energy(40, 20, a) - block_energy(30, 20, a)) / (20 * l0);
    printf("  the flat lattice interface's pull through the model's forces: %.10f sigma (2-D), "
           "%.10f sigma (3-D); its energy %.4f sigma (2-D); Kondo's energy calibration (a %.4g "
           "Pa, here %.4g Pa) would pull %.4f sigma, its energy %.4f sigma\n",
           f2 / sigma, f3 / sigma, gamma / sigma, aE, a, f2 / sigma * aE / a,
           gamma / sigma * aE / a);
    CHECK(fabs(f2 / sigma - 1) < 1e-9);
    CHECK(fabs(f3 / sigma - 1) < 1e-9);
    CHECK(fabs(gamma / sigma - 1) < 0.05);
}

/* N_i = min(n^a_i - n0^a, 0) of particle i, formed here (2-D, l0 = 1e-4 m, wall factor c) */
static double deficit(const lub_particles *P, size_t i, double c)
{
    const double l0 = 1e-4, h = 3.5;
    double n0 = 0, n = 0;
    for (int x = -4; x <= 4; x++)
        for (int y = -4; y <= 4; y++)
            if (x || y) n0 += k_wa(sqrt(x * x + y * y), h);
    for (size_t j = 0; j < P->n; j++) {
        if (j == i) continue;
        const double r = hypot(P->x[0][j] - P->x[0][i], P->x[1][j] - P->x[1][i]) / l0;
        const int same = (P->kind[i] == LUB_FLUID) == (P->kind[j] == LUB_FLUID);
        n += (same ? 1.0 : c) * k_wa(r, h);
    }
    return fmin(n - n0, 0.0);
}

/* A 2-D liquid bridge between plates H = 20 l0 apart (a wall layer and 3 dummy layers
 * each), contact angle 60 degrees on both, no gravity, from a rectangle of fluid; after
 * 0.06 s: the pressure in the middle of the bridge (|x| < 5 l0, within 5 l0 of mid-height),
 * P of (K-7a) plus the cohesive pressure a N (CPP in the stretched bulk, formed here; the
 * model's field pCohesive to round-off) against Laplace's -sigma / R with R the radius of
 * the meniscus (the circle through its ends, the first and last rows, and its waist),
 * within 10%, and so the middle's mechanical pressure (the virial of every pair force on its
 * particles, as for the drop; it also holds the DGP pairs' share, which P + pCohesive leaves
 * out).  The meniscus' angle at its ends is printed, not asserted: below 60 degrees the
 * contact line still creeps at 0.06 s (doc/methods.md §9: the sessile table), and the angle
 * reached then depends on round-off, 55.7 degrees with the particles unsorted and 53.5 sorted
 * (so -2 sigma cos(60) / H = -15 Pa falls short of the bridge's own curvature).  Measured
 * (methods.md §9): P + pCohesive 0.946 of -sigma/R, the virial 0.921; the meniscus at 55.9
 * degrees, -2 sigma cos(theta)/H with it 1.05, with 60 degrees 1.18. */
static void test_bridge(void)
{
    lub_particles P = {0};
    const char *geo = "dimension: 2\n"
                      "l0: 1.0e-4\n"
                      "domain: { min: [-0.003, -0.0006], max: [0.003, 0.0026] }\n"
                      "dummyLayers: 3\n"
                      "walls:\n"
                      "  lower: { type: plane, point: [0, 0], normal: [0, 1] }\n"
                      "  upper: { type: plane, point: [0, 0.002], normal: [0, -1] }\n"
                      "fluid:\n"
                      "  - { type: box, min: [-0.001, 0], max: [0.001, 0.002] }\n";
    char path[] = "/tmp/stbridgeXXXXXX";
    int fd = mkstemp(path);
    if (fd < 0 || write(fd, geo, strlen(geo)) != (ssize_t)strlen(geo)) abort();
    close(fd);
    lub_geometry g;
    lub_geometry_read(&g, path);
    unlink(path);
    lub_geometry_discretise(&g, &P, 0, NULL);
    lub_mps_config c;
    config(&c, 1000, 1e-4, 1.0, 3e3);
    driver d;
    model_read(&d, &P, "surfaceTension: { sigma: 0.03, contactAngle: { lower: 60, upper: 60 } }\n",
               &c);
    lub_mps m;
    lub_mps_init(&m, &P, &c, g.dmin, g.dmax, g.periodic);
    model_attach(&d, &m);
    const double l0 = 1e-4, H = 0.002, sigma = 0.03, a = coef(sigma);
    const char *ns = getenv("LUB_STEPS");
    const int nsteps = ns ? atoi(ns) : 3000;
    const double *pc = lub_particles_find_extra(&P, "pCohesive");
    double pin = 0, rlap = 0, theta = 0, dpc = 0, spc = 0, pvir = 0;
    for (int step = 0; step < nsteps; step += 500) {
        if (run(&m, 2e-5, 500)) break;
        double sp = 0, sn = 0, xl = INFINITY, xr = -INFINITY, bl = INFINITY, br = -INFINITY;
        int cnt = 0;
        for (size_t i = 0; i < P.n; i++) {
            if (P.kind[i] != LUB_FLUID) continue;
            if (fabs(P.x[1][i] - 0.5 * H) < 0.5 * l0)
                xl = fmin(xl, P.x[0][i]), xr = fmax(xr, P.x[0][i]);
            if (fabs(P.x[1][i] - l0) < 0.5 * l0 || fabs(P.x[1][i] - (H - l0)) < 0.5 * l0)
                bl = fmin(bl, P.x[0][i]), br = fmax(br, P.x[0][i]);
            if (fabs(P.x[0][i]) < 5 * l0 && fabs(P.x[1][i] - 0.5 * H) < 5 * l0) {
                const double an = a * deficit(&P, i, 0.6);
                sp += P.p[i], sn += an, cnt++;
                dpc = fmax(dpc, fabs(pc[i] - an)), spc = fmax(spc, fabs(an));
            }
        }
        /* the meniscus: the circle through its ends (the first and last rows) and its waist */
        const double sag = 0.5 * ((xr - xl) - (br - bl)) * -1, half = 0.5 * (H - 2 * l0);
        const double R = (half * half + sag * sag) / (2 * sag);
        if (getenv("LUB_PROFILE"))
            printf(
                "  t %.3f s: middle P %.4g Pa, a N %.4g Pa, sum %.4g Pa; -sigma/R %.4g Pa (R %.2f "
                "l0, the meniscus' angle %.1f deg); -2 sigma cos 60 / H = %.4g Pa\n",
                (step + 500) * 2e-5, sp / cnt, sn / cnt, (sp + sn) / cnt, -sigma / R, R / l0,
                acos(half / R) * 180 / M_PI, -2 * sigma * 0.5 / H);
        pin = (sp + sn) / cnt, rlap = -sigma / R, theta = acos(half / R) * 180 / M_PI;
    }
    /* the mechanical pressure of the middle: the virial of every pair force on its particles
     * (they are h_s and more from the plates: no wall pairs; their neighbours' n^a and chi
     * take the plates' particles with the wall factor of 60 degrees) */
    double *wt = lub_calloc(P.n, sizeof(double)), *wx = lub_calloc(P.n, sizeof(double));
    const double cw = 0.5 + 0.1 * (60 - 61.8) / (50.0 - 61.8); /* the model's table, 50-61.8 */
    pair_virial(&P, a, cw, 0.0, wt, wx);
    int nmid = 0;
    for (size_t i = 0; i < P.n; i++)
        if (P.kind[i] == LUB_FLUID && fabs(P.x[0][i]) < 5 * l0 &&
            fabs(P.x[1][i] - 0.5 * H) < 5 * l0)
            pvir += wt[i] / (2 * l0 * l0), nmid++;
    pvir /= nmid;
    free(wt), free(wx);
    const double young = -2 * sigma * cos(theta * M_PI / 180) / H, y60 = -2 * sigma * 0.5 / H;
    printf("  the bridge's mechanical pressure (virial) %.4g Pa against -sigma/R: ratio %.4f\n",
           pvir, pvir / rlap);
    printf("  the bridge's pressure %.4g Pa against -sigma/R %.4g Pa: ratio %.4f; the "
           "meniscus' angle %.1f deg: -2 sigma cos(theta)/H %.4g Pa (ratio %.4f), with 60 deg "
           "%.4g Pa (ratio %.4f); pCohesive against a N formed here: %.2g of %.3g Pa\n",
           pin, rlap, pin / rlap, theta, young, pin / young, y60, pin / y60, dpc, spc);
    CHECK(fabs(pin / rlap - 1) < 0.1);
    CHECK(fabs(pvir / rlap - 1) < 0.1);
    CHECK(dpc < 1e-9 * spc);
    lub_mps_free(&m);
    model_free(&d);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

int main(void)
{
    RUN(test_calibration);
    RUN(test_force_is_gradient);
    RUN(test_laplace_2d);
    RUN(test_laplace_mps);
    RUN(test_oscillation_2d);
    RUN(test_bridge);
    RUN(test_sessile);
    return test_summary();
}
