/* lubkit rigid bodies: the mechanics of one body (see body.h). */
#include "models/rigidBodies/body.h"

#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <string.h>

#include "core/error.h"

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

/* ---- contact between two bodies ---------------------------------------------------------- */

/* 1/M of the translation and R^2/I of the rotation; 0 for a held body (infinitely heavy) */
static double inverse_mass(const lub_body *b)
{
    int held = b->hold[0] && b->hold[1] && (b->dim == 2 || b->hold[2]);
    return held ? 0.0 : 1.0 / b->mass;
}

static double inverse_rotary(const lub_body *b)
{
    double I =
        b->dim == 2 ? b->inertia[2] : fmin(b->inertia[0], fmin(b->inertia[1], b->inertia[2]));
    return b->hold[3] ? 0.0 : b->radius * b->radius / I;
}

void lub_body_pair_damping(lub_body_pair *p, const lub_body *b, double zeta)
{
    const lub_body *A = &b[p->a], *B = &b[p->b];
    const double in = inverse_mass(A) + inverse_mass(B);
    const double it = in + inverse_rotary(A) + inverse_rotary(B);
    p->cn = in > 0 ? 2.0 * zeta * sqrt(p->kn / in) : 0.0;
    p->ct = it > 0 ? 2.0 * zeta * sqrt(p->kt / it) : 0.0;
}

double lub_body_pair_dt_limit(const lub_body_pair *p, const lub_body *b, double steps)
{
    const lub_body *A = &b[p->a], *B = &b[p->b];
    const double in = inverse_mass(A) + inverse_mass(B);
    const double it = in + inverse_rotary(A) + inverse_rotary(B);
    double tn = in > 0 ? 2.0 * M_PI / sqrt(p->kn * in) : INFINITY;
    double tt = it > 0 && p->kt > 0 ? 2.0 * M_PI / sqrt(p->kt * it) : INFINITY;
    return fmin(tn, tt) / steps;
}

/* the pair's contact at states s: force f on b, torques, the tangential relative velocity vt
 * of the contact points and the normal n; 1 while touching */
static int pair_contact(const lub_body_pair *p, const lub_body *b, const lub_body_state *s,
                        const double xi[3], double f[3], double ta[3], double tb[3], double vt[3],
                        double n[3], double *delta)
{
    const lub_body *A = &b[p->a], *B = &b[p->b];
    const lub_body_state *sa = &s[p->a], *sb = &s[p->b];
    double d[3], ra[3], rb[3], va[3], vb[3], v[3];
    for (int k = 0; k < 3; k++) d[k] = sb->x[k] - sa->x[k], f[k] = ta[k] = tb[k] = vt[k] = 0.0;
    const double dist = sqrt(dot3(d, d));
    for (int k = 0; k < 3; k++) n[k] = dist > 0 ? d[k] / dist : 0.0;
    *delta = A->radius + B->radius + p->distance - dist;
    /* touching from delta = 0 on: an impact that begins at a step's start begins there */
    if (*delta < 0 || dist == 0) return 0;
    for (int k = 0; k < 3; k++) ra[k] = A->radius * n[k], rb[k] = -B->radius * n[k];
    lub_body_point_velocity(A, sa, ra, va);
    lub_body_point_velocity(B, sb, rb, vb);
    for (int k = 0; k < 3; k++) v[k] = vb[k] - va[k];
    const double vn = dot3(v, n);
    for (int k = 0; k < 3; k++) vt[k] = v[k] - vn * n[k];
    const double fn = fmax(0.0, p->kn * *delta - p->cn * vn);
    double ft[3], ftn = 0;
    const double xin = dot3(xi, n);
    for (int k = 0; k < 3; k++) {
        ft[k] = -p->kt * (xi[k] - xin * n[k]) - p->ct * vt[k];
        ftn += ft[k] * ft[k];
    }
    ftn = sqrt(ftn);
    const double cap = p->mu * fn, scale = ftn > cap ? cap / ftn : 1.0;
    double fa[3];
    for (int k = 0; k < 3; k++) f[k] = fn * n[k] + scale * ft[k], fa[k] = -f[k];
    cross(rb, f, tb);
    cross(ra, fa, ta);
    return 1;
}

int lub_body_pair_contact(const lub_body_pair *p, const lub_body *b, const lub_body_state *s,
                          const double xi[3], double f[3], double ta[3], double tb[3],
                          double *delta)
{
    double vt[3], n[3];
    return pair_contact(p, b, s, xi, f, ta, tb, vt, n, delta);
}

/* ---- the step ------------------------------------------------------------------------------ */

/* the derivatives of all bodies and pair springs at states y, springs xi */
static void derivatives(int n, const lub_body *b, const lub_body_state *y, const double (*F)[3],
                        const double (*T)[3], int np, const lub_body_pair *p, const double (*xi)[3],
                        lub_body_state *k, double (*kxi)[3])
{
    double fx[LUB_BODY_MAX_BODIES][3], tx[LUB_BODY_MAX_BODIES][3];
    for (int i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) fx[i][d] = F[i][d], tx[i][d] = T[i][d];
    for (int q = 0; q < np; q++) {
        double f[3], ta[3], tb[3], nn[3], del;
        pair_contact(&p[q], b, y, xi[q], f, ta, tb, kxi[q], nn, &del);
        for (int d = 0; d < 3; d++) {
            fx[p[q].a][d] -= f[d], tx[p[q].a][d] += ta[d];
            fx[p[q].b][d] += f[d], tx[p[q].b][d] += tb[d];
        }
    }
    for (int i = 0; i < n; i++) derivative(&b[i], &y[i], fx[i], tx[i], &k[i]);
}

/* after the step: q renormalised, the springs of the planes and pairs kept tangential, zero
 * without contact and at most mu F_n / k_t while sliding */
static void finish(const lub_body *b, lub_body_state *s)
{
    if (b->dim == 3) {
        const double nq = sqrt(dot3(s->q + 1, s->q + 1) + s->q[0] * s->q[0]);
        for (int a = 0; a < 4; a++) s->q[a] /= nq;
    } else {
        s->q[0] = cos(0.5 * s->angle), s->q[1] = s->q[2] = 0.0, s->q[3] = sin(0.5 * s->angle);
    }
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

static void finish_pair(const lub_body_pair *p, const lub_body *b, const lub_body_state *s,
                        double xi[3])
{
    double f[3], ta[3], tb[3], vt[3], n[3], del;
    const double zero[3] = {0, 0, 0};
    if (!pair_contact(p, b, s, zero, f, ta, tb, vt, n, &del)) {
        xi[0] = xi[1] = xi[2] = 0.0;
        return;
    }
    const double xin = dot3(xi, n);
    for (int d = 0; d < 3; d++) xi[d] -= xin * n[d];
    const double fn = fmax(0.0, dot3(f, n)); /* with xi = 0: the normal force alone */
    const double xm = sqrt(dot3(xi, xi)), lim = p->kt > 0 ? p->mu * fn / p->kt : 0.0;
    if (xm > lim)
        for (int d = 0; d < 3; d++) xi[d] = xm > 0 ? xi[d] * lim / xm : 0.0;
}

void lub_bodies_step(int n, const lub_body *b, lub_body_state *s, const double (*F)[3],
                     const double (*T)[3], int np, const lub_body_pair *p, double (*xi)[3],
                     double dt)
{
    if (n > LUB_BODY_MAX_BODIES || np > LUB_BODY_MAX_PAIRS)
        lub_bug("lub_bodies_step: %d bodies, %d pairs (at most %d, %d)", n, np, LUB_BODY_MAX_BODIES,
                LUB_BODY_MAX_PAIRS);
    lub_body_state k[4][LUB_BODY_MAX_BODIES], y[LUB_BODY_MAX_BODIES];
    double kx[4][LUB_BODY_MAX_PAIRS][3], yx[LUB_BODY_MAX_PAIRS][3];
    static const double h[4] = {0.0, 0.5, 0.5, 1.0};
    for (int stage = 0; stage < 4; stage++) {
        for (int i = 0; i < n; i++)
            if (stage == 0)
                y[i] = s[i];
            else
                axpy(&y[i], &s[i], h[stage] * dt, &k[stage - 1][i]);
        for (int q = 0; q < np; q++)
            for (int d = 0; d < 3; d++)
                yx[q][d] = xi[q][d] + (stage ? h[stage] * dt * kx[stage - 1][q][d] : 0.0);
        derivatives(n, b, y, F, T, np, p, (const double(*)[3])yx, k[stage], kx[stage]);
    }
    for (int i = 0; i < n; i++) {
        double *ps = (double *)&s[i];
        const double *p1 = (double *)&k[0][i], *p2 = (double *)&k[1][i], *p3 = (double *)&k[2][i],
                     *p4 = (double *)&k[3][i];
        for (size_t j = 0; j < sizeof s[i] / sizeof(double); j++)
            ps[j] += dt / 6.0 * (p1[j] + 2.0 * p2[j] + 2.0 * p3[j] + p4[j]);
    }
    for (int q = 0; q < np; q++)
        for (int d = 0; d < 3; d++)
            xi[q][d] +=
                dt / 6.0 * (kx[0][q][d] + 2.0 * kx[1][q][d] + 2.0 * kx[2][q][d] + kx[3][q][d]);
    for (int i = 0; i < n; i++) finish(&b[i], &s[i]);
    for (int q = 0; q < np; q++) finish_pair(&p[q], b, s, xi[q]);
}

void lub_body_step(const lub_body *b, lub_body_state *s, const double F[3], const double T[3],
                   double dt)
{
    lub_bodies_step(1, b, s, (const double(*)[3])F, (const double(*)[3])T, 0, NULL, NULL, dt);
}
