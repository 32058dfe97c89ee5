/* lubkit rigid bodies: the mechanics of one body, without the fluid (methods.md §7).
 *
 * A body has a centre of mass x_G, a velocity V, an orientation and an angular velocity.  In
 * 3-D the orientation is the unit quaternion q = (w, x, y, z) and the angular velocity is
 * kept in the body frame, omega_b; the equations are (methods.md §7, [L])
 *
 *     M dV/dt = F + M g,   dx_G/dt = V,
 *     I_b domega_b/dt + omega_b x (I_b omega_b) = T_b = R(q)^T T,   dq/dt = q (x) (0, omega_b) / 2,
 *
 * I_b the principal moments (a sphere's, or those given).  In 2-D there is an angle theta
 * (counter-clockwise, accumulated, not wrapped) and I dOmega/dt = T_z, everything per unit
 * depth (M in kg/m, I in kg m, F in N/m, T in N).  lub_body_step integrates one step with the
 * classical 4-stage Runge-Kutta scheme; the fluid's force and torque are frozen over the
 * step (explicit coupling: they come from the fluid's last step), while gravity, the applied
 * load, the spring and the contact are evaluated at every stage from the stage's state (the
 * contact is stiff: its period must be resolved, lub_body_check_dt); q is renormalised at the
 * end of the step.
 *
 * Constraints: a held direction (hold: x, y, z; rotation) keeps its velocity (its
 * derivative is zero): a body held in every direction is fixed and only measures the force; a
 * held rotation with an initial omega is a prescribed rotation; a held translation with a
 * free rotation is a fixed axis.  A spring pulls the centre towards an anchor (stiffness k,
 * damping c: F = -k (x_G - anchor) - c V); a load is a constant applied force and torque.
 *
 * Contact (a circle or sphere of radius R against plane walls, the soft-sphere model of
 * discrete-element codes, Cundall and Strack, Geotechnique 29 (1979) 47).  With n the plane's
 * unit normal into the fluid and p a point of it, the overlap is
 *
 *     delta = R + d_c - (x_G - p).n            (d_c: the contact distance, a film kept open)
 *
 * and while delta > 0 the contact point x_G - R n carries
 *
 *     F_n = max(0, k_n delta - c_n v_n),                                 normal, no adhesion
 *     F_t = -k_t xi - c_t v_t,  |F_t| <= mu F_n  (sliding: F_t scaled back to mu F_n),
 *
 * v the contact point's velocity V + omega x (-R n), v_n = v.n, v_t its tangential part, xi
 * the tangential spring: the integral of v_t since the contact began (part of the state,
 * integrated with the body, zeroed when the contact opens, and shortened after a step to
 * |k_t xi| = mu F_n while sliding).  The damping coefficients come from a damping ratio zeta:
 * c_n = 2 zeta sqrt(k_n M), c_t = 2 zeta sqrt(k_t m_t), m_t = 1 / (1/M + R^2/I) the mass a
 * tangential force at the contact point accelerates.  The tangential spring makes a rolling
 * body stick (rolling without slip, the acceleration (2/3) g sin(slope) of a solid cylinder)
 * instead of creeping as a purely viscous friction would.
 *
 * Contact between two bodies a and b (circles or spheres, lub_body_pair): the same law with
 * n = (x_b - x_a)/|x_b - x_a|, delta = R_a + R_b + d_c - |x_b - x_a|, the contact points
 * x_a + R_a n and x_b - R_b n, v the relative velocity of b's point against a's; b gets
 * F_n n + F_t, a the opposite (so the pair conserves momentum, and angular momentum about
 * any point when F_t = 0); the damping from the pair's masses: c_n = 2 zeta sqrt(k_n m_n),
 * m_n = 1/(1/M_a + 1/M_b), c_t = 2 zeta sqrt(k_t m_t), 1/m_t = 1/M_a + R_a^2/I_a + 1/M_b +
 * R_b^2/I_b (a body held in every direction counts as infinitely heavy).  With F_n cut off
 * at zero (no adhesion), a head-on impact ends when k_n delta + c_n d(delta)/dt = 0, at
 * w_d t = pi - atan(2 zeta sqrt(1 - zeta^2)/(1 - 2 zeta^2)) (zeta < 1/sqrt 2), and the
 * coefficient of restitution is e = exp(-zeta w_n t) (zeta/sqrt(1 - zeta^2) sin(w_d t) -
 * cos(w_d t)) (w_n^2 = k_n/m_n, w_d = w_n sqrt(1 - zeta^2); Schwager and Poeschel, Granular
 * Matter 9 (2007) 465, on the cut-off). */
#ifndef LUB_MODELS_RIGIDBODIES_BODY_H
#define LUB_MODELS_RIGIDBODIES_BODY_H

#define LUB_BODY_MAX_PLANES 8
#define LUB_BODY_MAX_BODIES 8 /* in one lub_bodies_step */
#define LUB_BODY_MAX_PAIRS  28

typedef struct {
    double point[3], normal[3]; /* a plane: a point of it and its unit normal into the fluid */
} lub_body_plane;

typedef struct {
    int dim;
    double mass;       /* M [kg] (2-D: kg/m) */
    double inertia[3]; /* principal moments about x_G, body frame [kg m^2] (2-D: [2], kg m) */
    double g[3];       /* gravity [m/s^2] */
    int hold[4];       /* 1: the velocity component keeps its value: x, y, z, rotation */
    double load[3], load_torque[3]; /* applied force and torque (world frame) */
    double spring_k, spring_c, anchor[3];
    /* contact */
    int nplanes;
    lub_body_plane plane[LUB_BODY_MAX_PLANES];
    double radius;   /* R of the contact (circle, sphere) */
    double distance; /* d_c [m] */
    double kn, kt, cn, ct, mu;
} lub_body;

typedef struct {
    double x[3];     /* x_G [m] */
    double V[3];     /* [m/s] */
    double q[4];     /* orientation (3-D; 2-D: the rotation by angle about z) */
    double angle;    /* 2-D: theta [rad], accumulated */
    double omega[3]; /* angular velocity, body frame (2-D: [2], the same in both frames) */
    double xi[LUB_BODY_MAX_PLANES][3]; /* tangential springs of the contacts */
} lub_body_state;

/* A contact between bodies a and b (indices into the set lub_bodies_step integrates). */
typedef struct {
    int a, b;
    double distance; /* d_c [m] */
    double kn, kt, cn, ct, mu;
} lub_body_pair;

/* What the body felt at a state (apart from the fluid): contact force and torque. */
typedef struct {
    double F[3], T[3];
    int ncontacts;
} lub_body_contact_sum;

/* Mass properties from the shape, density rho [kg/m^3]: a 2-D circle of radius R (per
 * unit depth: M = rho pi R^2, I = M R^2 / 2), a sphere (M = rho 4/3 pi R^3, I = 2/5 M R^2) and
 * a 2-D polygon of n vertices xy (counter-clockwise: area, centroid and the polar moment
 * about the centroid by the shoelace sums of its triangles). */
void lub_body_circle(lub_body *b, double rho, double R);
void lub_body_sphere(lub_body *b, double rho, double R);
void lub_body_polygon(lub_body *b, double rho, const double *xy, int n, double centre[2]);

/* The contact's damping coefficients c_n, c_t from the ratio zeta (kn, kt, radius, mass and
 * inertia set). */
void lub_body_contact_damping(lub_body *b, double zeta);
/* The largest dt that resolves the contact's normal and tangential periods 2 pi sqrt(M/k_n),
 * 2 pi sqrt(m_t/k_t) with `steps` steps each (INFINITY without contact planes). */
double lub_body_dt_limit(const lub_body *b, double steps);

/* The rotation matrix R(q) of methods.md §7 (3-D), or of the angle about z (2-D). */
void lub_body_rotation(const lub_body *b, const lub_body_state *s, double R[3][3]);
/* The angular velocity in the world frame. */
void lub_body_omega_world(const lub_body *b, const lub_body_state *s, double w[3]);
/* Velocity V + omega x r of the point at r = x - x_G. */
void lub_body_point_velocity(const lub_body *b, const lub_body_state *s, const double r[3],
                             double u[3]);

/* The contact force and torque at state s (c may be NULL: only their sum is wanted). */
void lub_body_contact(const lub_body *b, const lub_body_state *s, lub_body_contact_sum *c);

/* One step of dt from s (in place): RK4 with the fluid's force F and torque T (world frame)
 * frozen, then q renormalised and the tangential springs of the contacts updated. */
void lub_body_step(const lub_body *b, lub_body_state *s, const double F[3], const double T[3],
                   double dt);

/* The pair's damping coefficients from the ratio zeta, and the largest dt that resolves its
 * normal and tangential periods 2 pi sqrt(m_n/k_n), 2 pi sqrt(m_t/k_t) with `steps` steps. */
void lub_body_pair_damping(lub_body_pair *p, const lub_body *b, double zeta);
double lub_body_pair_dt_limit(const lub_body_pair *p, const lub_body *b, double steps);

/* The force f on body p->b (body p->a gets -f) and the torques ta, tb on both at states s;
 * the overlap in *delta; 1 while touching. */
int lub_body_pair_contact(const lub_body_pair *p, const lub_body *b, const lub_body_state *s,
                          const double xi[3], double f[3], double ta[3], double tb[3],
                          double *delta);

/* One step of n bodies b[0..n-1] together (RK4 over all their states and the pairs'
 * tangential springs xi[0..npairs-1], the pair forces evaluated at every stage), each with its
 * fluid force F[k] and torque T[k] frozen; as lub_body_step for each body. */
void lub_bodies_step(int n, const lub_body *b, lub_body_state *s, const double (*F)[3],
                     const double (*T)[3], int npairs, const lub_body_pair *p, double (*xi)[3],
                     double dt);

#endif
