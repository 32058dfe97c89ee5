/* Unit tests of models/rigidBodies/body.h: a rigid body without fluid against closed forms
 * (methods.md §7): mass properties of the shapes, free fall, a spring's period, the
 * torque-free symmetric top, and the soft contact: a cylinder rolling down a slope without
 * slip, (2/3) g sin(slope), and sliding when the friction cannot hold it, g (sin - mu cos). */
#include <math.h>
#include <string.h>

#include "models/rigidBodies/body.h"
#include "test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static void test_mass_properties(void)
{
    lub_body b = {.dim = 2};
    lub_body_circle(&b, 7850, 0.0125);
    /* seed 003's roller (methods.md §7): 5 mm thick, M = 19.3 g, I = M R^2 / 2 */
    CHECK_REL(b.mass * 0.005, 0.019265, 1e-4);
    CHECK_REL(b.inertia[2], 0.5 * b.mass * 0.0125 * 0.0125, 1e-14);
    /* a 2 x 1 rectangle at (3, 1), clockwise: M = 2 rho, I = M (4 + 1)/12 about (4, 1.5) */
    const double rect[] = {3, 1, 3, 2, 5, 2, 5, 1};
    double c[2];
    lub_body_polygon(&b, 10, rect, 4, c);
    CHECK_REL(fabs(b.mass), 20, 1e-14);
    CHECK_NEAR(c[0], 4, 1e-13);
    CHECK_NEAR(c[1], 1.5, 1e-13);
    CHECK_REL(fabs(b.inertia[2]), 20 * 5.0 / 12.0, 1e-12);
    /* the same counter-clockwise: positive */
    const double ccw[] = {3, 1, 5, 1, 5, 2, 3, 2};
    lub_body_polygon(&b, 10, ccw, 4, c);
    CHECK_REL(b.mass, 20, 1e-14);
    CHECK_REL(b.inertia[2], 20 * 5.0 / 12.0, 1e-12);
    /* a right triangle (0,0), (1,0), (0,1): centroid (1/3, 1/3); polar moment about the
     * origin 2 int x^2 dA = 1/6, about the centroid 1/6 - A |c|^2 = 1/6 - 1/9 = 1/18 */
    const double tri[] = {0, 0, 1, 0, 0, 1};
    lub_body_polygon(&b, 1, tri, 3, c);
    CHECK_REL(b.mass, 0.5, 1e-14);
    CHECK_NEAR(c[0], 1.0 / 3.0, 1e-14);
    CHECK_REL(b.inertia[2], 1.0 / 18.0, 1e-12);
    lub_body s3 = {.dim = 3};
    lub_body_sphere(&s3, 1000, 0.1);
    CHECK_REL(s3.mass, 1000 * 4.0 / 3.0 * M_PI * 1e-3, 1e-14);
    CHECK_REL(s3.inertia[0], 0.4 * s3.mass * 0.01, 1e-14);
}

/* RK4 integrates a constant force exactly (to round-off) */
static void test_free_fall(void)
{
    lub_body b = {.dim = 2, .g = {0, -9.81, 0}};
    lub_body_circle(&b, 1000, 0.01);
    lub_body_state s = {.x = {0, 1, 0}, .V = {0.5, 0, 0}, .q = {1, 0, 0, 0}};
    const double F[3] = {0.1 * b.mass, 0, 0}, T[3] = {0, 0, 2 * b.inertia[2]};
    for (int k = 0; k < 100; k++) lub_body_step(&b, &s, F, T, 1e-3);
    const double t = 0.1;
    CHECK_NEAR(s.x[1], 1 - 0.5 * 9.81 * t * t, 1e-14);
    CHECK_NEAR(s.x[0], 0.5 * t + 0.5 * 0.1 * t * t, 1e-14);
    CHECK_NEAR(s.omega[2], 2 * t, 1e-14);
    CHECK_NEAR(s.angle, t * t, 1e-14);
    CHECK_NEAR(s.q[3], sin(0.5 * s.angle), 1e-15);
    /* held directions keep their velocity */
    lub_body h = b;
    h.hold[1] = h.hold[3] = 1;
    lub_body_state u = {.x = {0, 1, 0}, .V = {0, 0.2, 0}, .q = {1, 0, 0, 0}, .omega = {0, 0, 3}};
    for (int k = 0; k < 100; k++) lub_body_step(&h, &u, F, T, 1e-3);
    CHECK_NEAR(u.V[1], 0.2, 1e-15);
    CHECK_NEAR(u.omega[2], 3, 1e-15);
    CHECK_NEAR(u.x[1], 1.02, 1e-14);
    CHECK_NEAR(u.angle, 0.3, 1e-14);
}

/* a spring: x = A cos(w t), w = sqrt(k/M); RK4's phase error (w dt)^4 t w / 120 */
static void test_spring(void)
{
    lub_body b = {.dim = 2, .spring_k = 400.0};
    lub_body_circle(&b, 1000, 0.01);
    const double w = sqrt(b.spring_k / b.mass), dt = 2 * M_PI / w / 200;
    lub_body_state s = {.x = {0.01, 0, 0}, .q = {1, 0, 0, 0}};
    const double zero[3] = {0, 0, 0};
    for (int k = 0; k < 1000; k++) lub_body_step(&b, &s, zero, zero, dt);
    CHECK_NEAR(s.x[0], 0.01, 1e-8); /* five periods */
    CHECK_NEAR(s.V[0], 0.0, 1e-8 * w);
}

/* torque-free symmetric top (I1 = I2): omega_b precesses about the symmetry axis at
 * (I3 - I1) omega3 / I1 in the body frame, |omega| and the energy stay, q stays unit */
static void test_symmetric_top(void)
{
    lub_body b = {.dim = 3, .mass = 1, .inertia = {1, 1, 2}};
    lub_body_state s = {.q = {1, 0, 0, 0}, .omega = {0.3, 0, 1.0}};
    const double zero[3] = {0, 0, 0}, dt = 1e-3;
    for (int k = 0; k < 5000; k++) lub_body_step(&b, &s, zero, zero, dt);
    const double W = (2.0 - 1.0) / 1.0 * 1.0, t = 5.0;
    /* I1 w1' = (I1 - I3) w2 w3 -> w1 = 0.3 cos(W t), w2 = 0.3 sin(W t) */
    CHECK_NEAR(s.omega[0], 0.3 * cos(W * t), 1e-10);
    CHECK_NEAR(s.omega[1], 0.3 * sin(W * t), 1e-10);
    CHECK_NEAR(s.omega[2], 1.0, 1e-14);
    const double nq = s.q[0] * s.q[0] + s.q[1] * s.q[1] + s.q[2] * s.q[2] + s.q[3] * s.q[3];
    CHECK_NEAR(nq, 1.0, 1e-15);
    /* the angular momentum in the world frame is constant: R I omega_b = (0.3, 0, 2) at 0 */
    double R[3][3], L[3];
    lub_body_rotation(&b, &s, R);
    for (int a = 0; a < 3; a++)
        L[a] = R[a][0] * 1 * s.omega[0] + R[a][1] * 1 * s.omega[1] + R[a][2] * 2 * s.omega[2];
    CHECK_NEAR(L[0], 0.3, 1e-9);
    CHECK_NEAR(L[1], 0.0, 1e-9);
    CHECK_NEAR(L[2], 2.0, 1e-9);
    /* a spin about z in 3-D turns like the 2-D angle */
    lub_body_state z = {.q = {1, 0, 0, 0}, .omega = {0, 0, 2.0}};
    for (int k = 0; k < 1000; k++) lub_body_step(&b, &z, zero, zero, dt);
    CHECK_NEAR(z.q[0], cos(1.0), 1e-12);
    CHECK_NEAR(z.q[3], sin(1.0), 1e-12);
}

/* A solid cylinder (seed 003's roller, per unit depth) on a plate tilted by `slope`: gravity
 * (g sin, -g cos), the plate y = 0.  Returns the mean acceleration along the plate between
 * 0.05 s and 0.25 s, after the normal contact has settled. */
static double roll(double slope, double mu, double *slip)
{
    const double g = 9.81, R = 0.0125;
    lub_body b = {.dim = 2, .g = {g * sin(slope), -g * cos(slope), 0}};
    lub_body_circle(&b, 7850, R);
    b.nplanes = 1;
    b.plane[0] = (lub_body_plane){.point = {0, 0, 0}, .normal = {0, 1, 0}};
    b.kn = 1e6; /* N/m per m depth: the static overlap M g / k = 38 um */
    b.kt = 2.0 / 7.0 * b.kn;
    b.mu = mu;
    lub_body_contact_damping(&b, 0.3);
    const double dt = 1e-4;
    CHECK(dt <= lub_body_dt_limit(&b, 20)); /* the model's start-up check */
    lub_body_state s = {.x = {0, R - b.mass * g * cos(slope) / b.kn, 0}, .q = {1, 0, 0, 0}};
    const double zero[3] = {0, 0, 0};
    double v0 = 0;
    for (int k = 1; k <= 2500; k++) {
        lub_body_step(&b, &s, zero, zero, dt);
        if (k == 500) v0 = s.V[0];
    }
    *slip = s.V[0] + s.omega[2] * R; /* the contact point's velocity along the plate */
    return (s.V[0] - v0) / 0.2;
}

static void test_rolling(void)
{
    const double th = 5 * M_PI / 180, g = 9.81;
    double slip;
    /* rolling without slip: a = (2/3) g sin (I = M R^2/2), omega = -V/R; mu = 0.3 holds it
     * (needs mu >= tan / 3 = 0.029) */
    double a = roll(th, 0.3, &slip);
    CHECK_REL(a, 2.0 / 3.0 * g * sin(th), 1e-4); /* measured 2.3e-6 */
    printf("  rolling: a %.9g m/s^2, (2/3) g sin %.9g, slip velocity %.3g m/s\n", a,
           2.0 / 3.0 * g * sin(th), slip);
    CHECK(fabs(slip) < 1e-3 * 0.25 * a);
    /* sliding: mu = 0.01 < tan/3: a = g (sin - mu cos) */
    a = roll(th, 0.01, &slip);
    CHECK_REL(a, g * (sin(th) - 0.01 * cos(th)), 0.02);
    CHECK(slip > 0.01);
}

/* the contact's normal spring: the static overlap M g / k_n, and the period check */
static void test_contact_limits(void)
{
    lub_body b = {.dim = 2};
    lub_body_circle(&b, 7850, 0.0125);
    b.nplanes = 1;
    b.kn = 1e6, b.kt = 0;
    CHECK_REL(lub_body_dt_limit(&b, 20), 2 * M_PI * sqrt(b.mass / 1e6) / 20, 1e-14);
    b.kt = 2.0 / 7.0 * b.kn;
    const double mt = 1.0 / (1.0 / b.mass + b.radius * b.radius / b.inertia[2]);
    /* the shorter of the two periods: here the normal one (m_t = M/3, k_t = 2/7 k_n) */
    CHECK_REL(lub_body_dt_limit(&b, 20),
              fmin(2 * M_PI * sqrt(mt / b.kt), 2 * M_PI * sqrt(b.mass / b.kn)) / 20, 1e-14);
    b.kt = 10 * b.kn;
    CHECK_REL(lub_body_dt_limit(&b, 20), 2 * M_PI * sqrt(mt / b.kt) / 20, 1e-14);
    b.nplanes = 0;
    CHECK(isinf(lub_body_dt_limit(&b, 20)));
}

/* Two dry discs meeting head-on (no gravity, no friction needed): RK4 over both with the pair
 * force at every stage.  Momentum M_a V_a + M_b V_b constant to round-off at every step; the
 * relative speed after the impact e times the one before, e from the spring-dashpot with the
 * force cut off at zero (body.h): w_d t = pi - atan(2 z sqrt(1 - z^2)/(1 - 2 z^2)),
 * e = exp(-z w_n t) (z/sqrt(1 - z^2) sin(w_d t) - cos(w_d t)); the kinetic energy of the
 * relative motion falls by e^2.  Unequal masses (steel and aluminium-like) so that m_n
 * matters.  They start touching (delta = 0): the damping force c_n v the touch switches on
 * then begins with a step (inside one, RK4 would be first order in dt); the cut-off's kink
 * remains, 1.3e-6 at 1000 steps per period 2 pi/w_n, 7e-8 at 2000. */
static double collide(double zeta, int per, double *dp)
{
    lub_body b[2] = {{.dim = 2}, {.dim = 2}};
    lub_body_circle(&b[0], 7850, 0.01);
    lub_body_circle(&b[1], 2700, 0.015);
    lub_body_pair p = {.a = 0, .b = 1, .kn = 1e6, .kt = 2e5, .mu = 0.3};
    lub_body_pair_damping(&p, b, zeta);
    const double mn = 1.0 / (1.0 / b[0].mass + 1.0 / b[1].mass);
    CHECK_REL(p.cn, 2 * zeta * sqrt(p.kn * mn), 1e-14);
    lub_body_state s[2] = {
        {.x = {0, 0, 0}, .V = {0.3, 0, 0}, .q = {1, 0, 0, 0}},
        {.x = {b[0].radius + b[1].radius, 0, 0}, .V = {-0.2, 0, 0}, .q = {1, 0, 0, 0}}};
    const double zero[2][3] = {{0, 0, 0}, {0, 0, 0}};
    double xi[1][3] = {{0, 0, 0}};
    const double P0 = b[0].mass * s[0].V[0] + b[1].mass * s[1].V[0];
    const double wn = sqrt(p.kn / mn), dt = 2 * M_PI / wn / per;
    *dp = 0;
    for (int k = 0; k < 2 * per; k++) {
        lub_bodies_step(2, b, s, zero, zero, 1, &p, xi, dt);
        *dp = fmax(*dp, fabs(b[0].mass * s[0].V[0] + b[1].mass * s[1].V[0] - P0) / fabs(P0));
    }
    double f[3], ta[3], tb[3], del;
    CHECK(!lub_body_pair_contact(&p, b, s, xi[0], f, ta, tb, &del)); /* apart again */
    CHECK(fabs(s[0].V[1]) + fabs(s[1].V[1]) + fabs(s[0].omega[2]) + fabs(s[1].omega[2]) < 1e-15);
    return (s[1].V[0] - s[0].V[0]) / 0.5; /* relative speed after over before */
}

static void test_pair_impact(void)
{
    for (int c = 0; c < 3; c++) {
        const double z = (double[]){0.0, 0.1, 0.3}[c];
        const double wt = M_PI - atan(2 * z * sqrt(1 - z * z) / (1 - 2 * z * z));
        const double e = exp(-z * wt / sqrt(1 - z * z)) * (z / sqrt(1 - z * z) * sin(wt) - cos(wt));
        double dp, dp2;
        const double em = collide(z, 1000, &dp), em2 = collide(z, 2000, &dp2);
        printf("  head-on impact, zeta %.1f: e %.9f (1000 steps per period), %.9f (2000), closed "
               "form %.9f; momentum to %.2g\n",
               z, em, em2, e, fmax(dp, dp2));
        CHECK_REL(em, e, 1e-5);
        CHECK(fabs(em2 - e) <= 0.6 * fabs(em - e) + 1e-12);
        dp = fmax(dp, dp2);
        CHECK(dp < 1e-14);
    }
}

/* A disc resting on a fixed disc (held in every direction) under gravity, with damping: it
 * settles where the normal spring carries its weight, delta = M g / k_n, straight above (the
 * tangential spring and friction keep it there against a slight offset: it comes to rest
 * with the contact force balancing gravity, no slip beyond mu) */
static void test_pair_resting(void)
{
    lub_body b[2] = {{.dim = 2, .hold = {1, 1, 0, 1}}, {.dim = 2, .g = {0, -9.81, 0}}};
    lub_body_circle(&b[0], 7850, 0.02);
    lub_body_circle(&b[1], 7850, 0.01);
    lub_body_pair p = {.a = 0, .b = 1, .kn = 1e6, .kt = 2e5, .mu = 0.3};
    lub_body_pair_damping(&p, b, 0.5);
    /* the held disc is infinitely heavy: m_n = M_b, m_t = 1/(1/M_b + R_b^2/I_b) = M_b/3 */
    CHECK_REL(p.cn, 2 * 0.5 * sqrt(p.kn * b[1].mass), 1e-14);
    CHECK_REL(lub_body_pair_dt_limit(&p, b, 20),
              fmin(2 * M_PI * sqrt(b[1].mass / p.kn), 2 * M_PI * sqrt(b[1].mass / 3 / p.kt)) / 20,
              1e-14);
    lub_body_state s[2] = {{.q = {1, 0, 0, 0}}, {.x = {0, 0.03, 0}, .q = {1, 0, 0, 0}}};
    const double zero[2][3] = {{0, 0, 0}, {0, 0, 0}};
    double xi[1][3] = {{0, 0, 0}};
    const double dt = lub_body_pair_dt_limit(&p, b, 40);
    for (int k = 0; k < 40 * 200; k++) lub_bodies_step(2, b, s, zero, zero, 1, &p, xi, dt);
    const double del = b[1].mass * 9.81 / p.kn;
    CHECK_REL(0.03 - s[1].x[1], del, 1e-6);
    CHECK(fabs(s[1].V[1]) < 1e-9 && fabs(s[1].x[0]) < 1e-15 && s[0].x[1] == 0);
    double f[3], ta[3], tb[3], d;
    CHECK(lub_body_pair_contact(&p, b, s, xi[0], f, ta, tb, &d));
    CHECK_REL(f[1], b[1].mass * 9.81, 1e-6);
}

int main(void)
{
    RUN(test_mass_properties);
    RUN(test_free_fall);
    RUN(test_spring);
    RUN(test_symmetric_top);
    RUN(test_rolling);
    RUN(test_contact_limits);
    RUN(test_pair_impact);
    RUN(test_pair_resting);
    return test_summary();
}
