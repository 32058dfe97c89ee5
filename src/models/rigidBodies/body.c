/* lubkit rigid bodies: the mechanics of one body (see body.h). */
#include "models/rigidBodies/body.h"

#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <string.h>

void lub_body_circle(lub_body *b, double rho, double R)
{
    b->mass = rho * M_PI * R * R;
    b->inertia[0] = b->inertia[1] = 0.0;
    b->inertia[2] = 0.5 * b->mass * R * R;
    b->radius = R;
}

void lub_body_sphere(lub_body *b, double rho, double R)
{
    b->mass = rho * 4.0 / 3.0 * M_PI * R * R * R;
    b->inertia[0] = b->inertia[1] = b->inertia[2] = 0.4 * b->mass * R * R;
    b->radius = R;
}

void lub_body_polygon(lub_body *b, double rho, const double *xy, int n, double centre[2])
{
    /* the triangles (0, p_i, p_i+1): area a_i = cross_i / 2, first moments (p_i + p_i+1)
     * cross_i / 6, polar moment about 0 cross_i (|p_i|^2 + p_i.p_i+1 + |p_i+1|^2) / 12 */
    double A = 0, cx = 0, cy = 0, J = 0;
    for (int k = 0; k < n; k++) {
        const double *p = xy + 2 * k, *r = xy + 2 * ((k + 1) % n);
        const double c = p[0] * r[1] - r[0] * p[1];
        A += 0.5 * c;
        cx += (p[0] + r[0]) * c / 6.0;
        cy += (p[1] + r[1]) * c / 6.0;
        J += c *
             (p[0] * p[0] + p[0] * r[0] + r[0] * r[0] + p[1] * p[1] + p[1] * r[1] + r[1] * r[1]) /
             12.0;
    }
    centre[0] = cx / A;
    centre[1] = cy / A;
    b->mass = rho * A;
    b->inertia[0] = b->inertia[1] = 0.0;
    b->inertia[2] = rho * (J - A * (centre[0] * centre[0] + centre[1] * centre[1]));
    b->radius = 0.0;
}

/* the mass a tangential force at the contact point accelerates: 1/M + R^2/I */
static double tangential_mass(const lub_body *b)
{
    double I =
        b->dim == 2 ? b->inertia[2] : fmin(b->inertia[0], fmin(b->inertia[1], b->inertia[2]));
    return 1.0 / (1.0 / b->mass + b->radius * b->radius / I);
}

void lub_body_contact_damping(lub_body *b, double zeta)
{
    b->cn = 2.0 * zeta * sqrt(b->kn * b->mass);
    b->ct = 2.0 * zeta * sqrt(b->kt * tangential_mass(b));
}

double lub_body_dt_limit(const lub_body *b, double steps)
{
    if (b->nplanes == 0) return INFINITY;
    double tn = 2.0 * M_PI * sqrt(b->mass / b->kn);
    double tt = b->kt > 0 ? 2.0 * M_PI * sqrt(tangential_mass(b) / b->kt) : INFINITY;
    return fmin(tn, tt) / steps;
}

static void quat_rotation(const double *q, double R[3][3])
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    R[0][0] = 1 - 2 * (y * y + z * z), R[0][1] = 2 * (x * y - w * z), R[0][2] = 2 * (x * z + w * y);
    R[1][0] = 2 * (x * y + w * z), R[1][1] = 1 - 2 * (x * x + z * z), R[1][2] = 2 * (y * z - w * x);
    R[2][0] = 2 * (x * z - w * y), R[2][1] = 2 * (y * z + w * x), R[2][2] = 1 - 2 * (x * x + y * y);
}

void lub_body_rotation(const lub_body *b, const lub_body_state *s, double R[3][3])
{
    if (b->dim == 3) {
        quat_rotation(s->q, R);
        return;
    }
    const double c = cos(s->angle), sn = sin(s->angle);
    memset(R, 0, 9 * sizeof(double));
    R[0][0] = c, R[0][1] = -sn, R[1][0] = sn, R[1][1] = c, R[2][2] = 1.0;
}

static void cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void lub_body_omega_world(const lub_body *b, const lub_body_state *s, double w[3])
{
    if (b->dim == 2) {
        w[0] = w[1] = 0.0, w[2] = s->omega[2];
        return;
    }
    double R[3][3];
    quat_rotation(s->q, R);
    for (int a = 0; a < 3; a++) w[a] = dot3(R[a], s->omega);
}

void lub_body_point_velocity(const lub_body *b, const lub_body_state *s, const double r[3],
                             double u[3])
{
    double w[3], c[3];
    lub_body_omega_world(b, s, w);
    cross(w, r, c);
    for (int d = 0; d < 3; d++) u[d] = s->V[d] + c[d];
}

/* The contact with plane k at state s: 1 if touching, its force f and torque t; the
 * tangential velocity of the contact point in vt. */
static int plane_contact(const lub_body *b, const lub_body_state *s, int k, double f[3],
                         double t[3], double vt[3])
{
    const lub_body_plane *pl = &b->plane[k];
    double rel[3], r[3], v[3];
    for (int d = 0; d < 3; d++) rel[d] = s->x[d] - pl->point[d];
    const double delta = b->radius + b->distance - dot3(rel, pl->normal);
    f[0] = f[1] = f[2] = t[0] = t[1] = t[2] = vt[0] = vt[1] = vt[2] = 0.0;
    if (delta <= 0) return 0;
    for (int d = 0; d < 3; d++) r[d] = -b->radius * pl->normal[d];
    lub_body_point_velocity(b, s, r, v);
    const double vn = dot3(v, pl->normal);
    for (int d = 0; d < 3; d++) vt[d] = v[d] - vn * pl->normal[d];
    const double fn = fmax(0.0, b->kn * delta - b->cn * vn);
    double ft[3], xi[3], ftn = 0;
    const double xin = dot3(s->xi[k], pl->normal);
    for (int d = 0; d < 3; d++) {
        xi[d] = s->xi[k][d] - xin * pl->normal[d];
        ft[d] = -b->kt * xi[d] - b->ct * vt[d];
        ftn += ft[d] * ft[d];
    }
    ftn = sqrt(ftn);
    const double cap = b->mu * fn;
    const double scale = ftn > cap ? cap / ftn : 1.0;
    for (int d = 0; d < 3; d++) f[d] = fn * pl->normal[d] + scale * ft[d];
    cross(r, f, t);
    return 1;
}

void lub_body_contact(const lub_body *b, const lub_body_state *s, lub_body_contact_sum *c)
{
    memset(c, 0, sizeof *c);
    for (int k = 0; k < b->nplanes; k++) {
        double f[3], t[3], vt[3];
        if (!plane_contact(b, s, k, f, t, vt)) continue;
        c->ncontacts++;
        for (int d = 0; d < 3; d++) c->F[d] += f[d], c->T[d] += t[d];
    }
}

/* ds/dt at state s (the fluid's F, T frozen) */
static void derivative(const lub_body *b, const lub_body_state *s, const double F[3],
                       const double T[3], lub_body_state *ds)
{
    memset(ds, 0, sizeof *ds);
    double f[3], t[3];
    for (int d = 0; d < 3; d++) {
        f[d] = F[d] + b->mass * b->g[d] + b->load[d] - b->spring_k * (s->x[d] - b->anchor[d]) -
               b->spring_c * s->V[d];
        t[d] = T[d] + b->load_torque[d];
    }
    for (int k = 0; k < b->nplanes; k++) {
        double fc[3], tc[3], vt[3];
        if (plane_contact(b, s, k, fc, tc, vt))
            for (int d = 0; d < 3; d++) f[d] += fc[d], t[d] += tc[d], ds->xi[k][d] = vt[d];
    }
    for (int d = 0; d < b->dim; d++) {
        ds->x[d] = s->V[d];
        ds->V[d] = b->hold[d] ? 0.0 : f[d] / b->mass;
    }
    if (b->dim == 2) {
        ds->angle = s->omega[2];
        ds->omega[2] = b->hold[3] ? 0.0 : t[2] / b->inertia[2];
        return;
    }
    /* Euler's equations in the body frame: I w' = R^T T - w x (I w) */
    double R[3][3], tb[3] = {0, 0, 0}, Iw[3], gyro[3];
    quat_rotation(s->q, R);
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++) tb[a] += R[c][a] * t[c];
    for (int a = 0; a < 3; a++) Iw[a] = b->inertia[a] * s->omega[a];
    cross(s->omega, Iw, gyro);
    for (int a = 0; a < 3; a++) ds->omega[a] = b->hold[3] ? 0.0 : (tb[a] - gyro[a]) / b->inertia[a];
    /* q' = q (x) (0, w) / 2 */
    const double *q = s->q, *w = s->omega;
    ds->q[0] = -0.5 * (q[1] * w[0] + q[2] * w[1] + q[3] * w[2]);
    ds->q[1] = 0.5 * (q[0] * w[0] + q[2] * w[2] - q[3] * w[1]);
    ds->q[2] = 0.5 * (q[0] * w[1] + q[3] * w[0] - q[1] * w[2]);
    ds->q[3] = 0.5 * (q[0] * w[2] + q[1] * w[1] - q[2] * w[0]);
}

/* a = s + h k, over every number of the state */
static void axpy(lub_body_state *a, const lub_body_state *s, double h, const lub_body_state *k)
{
    const double *ps = (const double *)s, *pk = (const double *)k;
    double *pa = (double *)a;
    for (size_t i = 0; i < sizeof *s / sizeof(double); i++) pa[i] = ps[i] + h * pk[i];
}

void lub_body_step(const lub_body *b, lub_body_state *s, const double F[3], const double T[3],
                   double dt)
{
    lub_body_state k1, k2, k3, k4, y;
    derivative(b, s, F, T, &k1);
    axpy(&y, s, 0.5 * dt, &k1);
    derivative(b, &y, F, T, &k2);
    axpy(&y, s, 0.5 * dt, &k2);
    derivative(b, &y, F, T, &k3);
    axpy(&y, s, dt, &k3);
    derivative(b, &y, F, T, &k4);
    double *p = (double *)s;
    const double *p1 = (double *)&k1, *p2 = (double *)&k2, *p3 = (double *)&k3, *p4 = (double *)&k4;
    for (size_t i = 0; i < sizeof *s / sizeof(double); i++)
        p[i] += dt / 6.0 * (p1[i] + 2.0 * p2[i] + 2.0 * p3[i] + p4[i]);
    if (b->dim == 3) {
        const double nq = sqrt(dot3(s->q + 1, s->q + 1) + s->q[0] * s->q[0]);
        for (int a = 0; a < 4; a++) s->q[a] /= nq;
    } else {
        s->q[0] = cos(0.5 * s->angle), s->q[1] = s->q[2] = 0.0, s->q[3] = sin(0.5 * s->angle);
    }
    /* the tangential springs: none without contact, at most mu F_n / k_t while sliding */
    for (int k = 0; k < b->nplanes; k++) {
        double f[3], t[3], vt[3];
        const double *n = b->plane[k].normal;
        const double xin = dot3(s->xi[k], n);
        for (int d = 0; d < 3; d++) s->xi[k][d] -= xin * n[d];
        if (!plane_contact(b, s, k, f, t, vt)) {
            memset(s->xi[k], 0, sizeof s->xi[k]);
            continue;
        }
        const double fn = fmax(0.0, dot3(f, n));
        const double xm = sqrt(dot3(s->xi[k], s->xi[k])), lim = b->mu * fn / b->kt;
        if (b->kt > 0 && xm > lim)
            for (int d = 0; d < 3; d++) s->xi[k][d] *= lim / xm;
    }
}
