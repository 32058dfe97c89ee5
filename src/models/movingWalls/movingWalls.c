/* lubkit model movingWalls: walls moving with a given velocity or motion history (methods.md
 * §2, step 8; methods.md §5.5: squeeze films).
 *
 *     movingWalls: { lowerWall: { velocity: [1.2, 0] } }     # m/s, per wall of the geometry
 *     movingWalls: { plate: { motion: sinusoidal, amplitude: [0, 2e-4], frequency: 1,
 *                             phase: 0 } }
 *     movingWalls: { plate: { motion: table, table: [[0, 0, 0], [0.5, 0, -2e-4]] } }
 *
 * The motions and their formulas: models/models.h (lub_wall_motion).
 *
 * A constant motion (the default): the wall and dummy particles of a listed patch carry its
 * velocity in every step (mps.h patch_velocity): the viscous step sees it, and they move with
 * it (a multi-resolution run keeps them in place: every moving wall must then be a plane
 * sliding along itself).
 *
 * A motion history (sinusoidal, table): the patch is one a model moves (mps.h patch_moved).
 * Its particles sit at x0 + d(t) after every step, x0 their place at t = 0 (the particle
 * fields wallOriginX, wallOriginY (wallOriginZ), written with the time folders): no drift
 * from integrating a velocity, and a restart at any time is exact.  In the step from t to
 * t + dt they carry d'(t + dt/2), the velocity of the step's midpoint (second order, as the
 * Crank-Nicolson viscous step, and the step's temporary positions off x0 + d(t + dt) by
 * O(dt^3) only); the written fields carry d'(t) of the time folder's t.
 *
 * At start-up: the largest wall speed over the motion goes into the Courant number (lubFoam
 * reads patch_velocity, set to a velocity of that speed), and a moving wall that comes
 * within l0 of another wall (wall particles l0 apart: no fluid particle fits between them)
 * before the end time is an error naming the time. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/spell.h"
#include "models/model.h"
#include "models/models.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

const char *const lub_motion_names[] = {"constant", "sinusoidal", "table", NULL};

/* The table's displacement D(t) (held beyond the ends) and the index of the row interval
 * [k, k+1] holding t (-1 before the first row, nrows - 1 after the last). */
static int table_at(const lub_wall_motion *m, double t, double D[3])
{
    const int n = m->nrows;
    if (t < m->time[0]) {
        memcpy(D, m->disp[0], 3 * sizeof *D);
        return -1;
    }
    if (t >= m->time[n - 1]) {
        memcpy(D, m->disp[n - 1], 3 * sizeof *D);
        return n - 1;
    }
    int lo = 0, hi = n - 1; /* time[lo] <= t < time[hi] */
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (m->time[mid] <= t)
            lo = mid;
        else
            hi = mid;
    }
    double f = (t - m->time[lo]) / (m->time[hi] - m->time[lo]);
    for (int d = 0; d < 3; d++) D[d] = m->disp[lo][d] + f * (m->disp[hi][d] - m->disp[lo][d]);
    return lo;
}

void lub_wall_motion_displacement(const lub_wall_motion *m, double t, double d[3])
{
    switch (m->kind) {
    case LUB_MOTION_SINUSOIDAL: {
        double s = sin(2.0 * M_PI * m->frequency * t + m->phase) - sin(m->phase);
        for (int k = 0; k < 3; k++) d[k] = m->amplitude[k] * s;
        return;
    }
    case LUB_MOTION_TABLE:
        table_at(m, t, d);
        for (int k = 0; k < 3; k++) d[k] -= m->d0[k];
        return;
    default:
        for (int k = 0; k < 3; k++) d[k] = m->velocity[k] * t;
    }
}

void lub_wall_motion_velocity(const lub_wall_motion *m, double t, double v[3])
{
    switch (m->kind) {
    case LUB_MOTION_SINUSOIDAL: {
        double w = 2.0 * M_PI * m->frequency, c = w * cos(w * t + m->phase);
        for (int k = 0; k < 3; k++) v[k] = m->amplitude[k] * c;
        return;
    }
    case LUB_MOTION_TABLE: {
        double D[3];
        int k = table_at(m, t, D);
        for (int d = 0; d < 3; d++)
            v[d] = k < 0 || k >= m->nrows - 1
                       ? 0.0
                       : (m->disp[k + 1][d] - m->disp[k][d]) / (m->time[k + 1] - m->time[k]);
        return;
    }
    default:
        memcpy(v, m->velocity, 3 * sizeof *v);
    }
}

static double norm3(const double *v)
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

double lub_wall_motion_max_speed(const lub_wall_motion *m, double t0, double t1, double v[3])
{
    double best = -1.0, vb[3] = {0, 0, 0}, u[3];
    if (m->kind == LUB_MOTION_SINUSOIDAL) {
        /* |d'| is largest where cos(w t + phi) = +-1: the first such time from t0 on, else
         * the ends */
        double w = 2.0 * M_PI * m->frequency;
        double k = ceil((w * t0 + m->phase) / M_PI), tk = (k * M_PI - m->phase) / w;
        double ts[3] = {t0, t1, tk};
        for (int i = 0; i < 3; i++) {
            if (ts[i] < t0 || ts[i] > t1) continue;
            lub_wall_motion_velocity(m, ts[i], u);
            if (norm3(u) > best) best = norm3(u), memcpy(vb, u, sizeof vb);
        }
    } else if (m->kind == LUB_MOTION_TABLE) {
        /* the slopes of the row intervals that overlap [t0, t1] (0 beyond the ends) */
        for (int k = -1; k < m->nrows; k++) {
            double a = k < 0 ? -INFINITY : m->time[k];
            double b = k + 1 < m->nrows ? m->time[k + 1] : INFINITY;
            if (b <= t0 || a > t1) continue;
            lub_wall_motion_velocity(m, k < 0 ? b - 1.0 : a, u);
            if (k < 0 || k + 1 >= m->nrows) u[0] = u[1] = u[2] = 0.0;
            if (norm3(u) > best) best = norm3(u), memcpy(vb, u, sizeof vb);
        }
    } else {
        memcpy(vb, m->velocity, sizeof vb);
        best = norm3(vb);
    }
    if (best < 0) best = 0;
    if (v) memcpy(v, vb, sizeof vb);
    return best;
}

int lub_wall_motion_is_history(const lub_wall_motion *m)
{
    return m->kind != LUB_MOTION_CONSTANT;
}

static size_t vec_text(char *buf, size_t size, const double *v, int dim)
{
    size_t len = (size_t)snprintf(buf, size, "(%g", v[0]);
    for (int d = 1; d < dim && len < size; d++)
        len += (size_t)snprintf(buf + len, size - len, ", %g", v[d]);
    if (len < size) len += (size_t)snprintf(buf + len, size - len, ")");
    return len;
}

void lub_wall_motion_describe(const lub_wall_motion *m, int dim, char *buf, size_t size)
{
    char v[160];
    switch (m->kind) {
    case LUB_MOTION_SINUSOIDAL:
        vec_text(v, sizeof v, m->amplitude, dim);
        snprintf(buf, size, "sinusoidal, amplitude %s m, %g Hz, phase %g rad", v, m->frequency,
                 m->phase);
        return;
    case LUB_MOTION_TABLE:
        snprintf(buf, size, "table of %d rows, t = %g .. %g s", m->nrows, m->time[0],
                 m->time[m->nrows - 1]);
        return;
    default:
        vec_text(v, sizeof v, m->velocity, dim);
        snprintf(buf, size, "%s m/s", v);
    }
}

int lub_wall_motion_breaks(const lub_wall_motion *m, double t0, double t1, double *out, int max)
{
    int n = 0;
    if (m->kind == LUB_MOTION_SINUSOIDAL) {
        /* d' = 0 where w t + phi = pi/2 + k pi */
        double w = 2.0 * M_PI * m->frequency;
        for (double k = ceil((w * t0 + m->phase - 0.5 * M_PI) / M_PI); n < max; k++) {
            double t = ((k + 0.5) * M_PI - m->phase) / w;
            if (t >= t1) break;
            if (t > t0) out[n++] = t;
        }
    } else if (m->kind == LUB_MOTION_TABLE) {
        for (int k = 0; k < m->nrows && n < max; k++)
            if (m->time[k] > t0 && m->time[k] < t1) out[n++] = m->time[k];
    }
    return n;
}

/* A wall's entry: velocity, or motion with its keys (fatal with file:line on bad input). */
static void motion_read(lub_node *entry, const char *name, lub_wall_motion *m)
{
    memset(m, 0, sizeof *m);
    lub_node_expect_map(entry);
    m->kind = lub_dict_choice(entry, "motion", lub_motion_names, LUB_MOTION_CONSTANT);
    static const char *const keys[3][3] = {
        {"velocity", NULL, NULL}, {"amplitude", "frequency", "phase"}, {"table", NULL, NULL}};
    /* a key of another motion: say which motion it belongs to */
    static const char *const all[] = {"velocity", "amplitude", "frequency", "phase", "table"};
    static const int owner[] = {LUB_MOTION_CONSTANT, LUB_MOTION_SINUSOIDAL, LUB_MOTION_SINUSOIDAL,
                                LUB_MOTION_SINUSOIDAL, LUB_MOTION_TABLE};
    for (int k = 0; k < 5; k++) {
        lub_node *n = lub_dict_find(entry, all[k]);
        if (n && owner[k] != m->kind)
            lub_node_error(n,
                           "movingWalls: '%s' belongs to 'motion: %s', but wall '%s' has "
                           "'motion: %s' (its keys: %s%s%s%s%s)",
                           all[k], lub_motion_names[owner[k]], name, lub_motion_names[m->kind],
                           keys[m->kind][0], keys[m->kind][1] ? ", " : "",
                           keys[m->kind][1] ? keys[m->kind][1] : "", keys[m->kind][2] ? ", " : "",
                           keys[m->kind][2] ? keys[m->kind][2] : "");
    }
    switch (m->kind) {
    case LUB_MOTION_SINUSOIDAL:
        lub_dict_vec(entry, "amplitude", m->amplitude, 2, 3, LUB_ANY);
        m->frequency = lub_dict_real(entry, "frequency", LUB_POSITIVE);
        m->phase = lub_dict_real_or(entry, "phase", 0.0, LUB_ANY);
        break;
    case LUB_MOTION_TABLE: {
        lub_node *tab = lub_dict_seq(entry, "table");
        size_t n = lub_node_size(tab);
        if (n < 2)
            lub_node_error(tab,
                           "movingWalls: the table of wall '%s' needs at least 2 rows [t, dx, "
                           "dy], found %zu",
                           name, n);
        m->nrows = (int)n;
        m->time = lub_malloc(n * sizeof *m->time);
        m->disp = lub_calloc(n, sizeof *m->disp);
        int width = 0;
        for (size_t i = 0; i < n; i++) {
            lub_node *row = lub_node_item(tab, i);
            size_t w = lub_node_type_of(row) == LUB_NODE_SEQUENCE ? lub_node_size(row) : 0;
            if (w < 3 || w > 4 || (width && (int)w != width))
                lub_node_error(row,
                               "movingWalls: row %zu of the table of wall '%s' must be [t, dx, "
                               "dy] (2-D) or [t, dx, dy, dz] (3-D)%s, found %s of %zu",
                               i + 1, name, width ? ", as wide as the first row" : "",
                               lub_node_type_of(row) == LUB_NODE_SEQUENCE ? "a list" : "an entry",
                               w);
            width = (int)w;
            m->time[i] = lub_node_real(lub_node_item(row, 0), LUB_ANY);
            for (size_t d = 1; d < w; d++)
                m->disp[i][d - 1] = lub_node_real(lub_node_item(row, d), LUB_ANY);
            if (i > 0 && !(m->time[i] > m->time[i - 1]))
                lub_node_error(lub_node_item(row, 0),
                               "movingWalls: the times of the table of wall '%s' must increase: "
                               "row %zu has t = %g after t = %g",
                               name, i + 1, m->time[i], m->time[i - 1]);
        }
        table_at(m, 0.0, m->d0);
        break;
    }
    default:
        lub_dict_vec(entry, "velocity", m->velocity, 2, 3, LUB_ANY);
    }
}

int lub_moving_walls_read(lub_node *root, const lub_geometry *g, lub_wall_motion *motion,
                          int *moving)
{
    for (int w = 0; w < g->nwalls; w++) {
        memset(&motion[w], 0, sizeof motion[w]);
        moving[w] = 0;
    }
    lub_node *mw = lub_dict_map_or(root, "movingWalls");
    if (!mw) return 0;
    size_t n = lub_node_size(mw);
    for (size_t i = 0; i < n; i++) {
        const char *name = lub_node_key_at(mw, i);
        lub_node *entry = lub_node_value_at(mw, i);
        int w = lub_geometry_find_wall(g, name);
        if (w < 0) {
            char list[1024] = "";
            size_t len = 0;
            const char *names[256] = {0};
            int nn = g->nwalls < 256 ? g->nwalls : 256;
            for (int k = 0; k < nn; k++) {
                names[k] = g->walls[k].name;
                if (len < sizeof list)
                    len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", k ? ", " : "",
                                            g->walls[k].name);
            }
            const char *near = lub_closest(name, names, (size_t)nn);
            lub_moving_walls_free(motion, g->nwalls);
            if (near)
                lub_node_error(entry,
                               "movingWalls: '%s' is not a wall of the geometry (did you mean "
                               "'%s'? walls: %s)",
                               name, near, list);
            lub_node_error(entry, "movingWalls: '%s' is not a wall of the geometry (walls: %s)",
                           name, nn ? list : "none");
        }
        motion_read(entry, name, &motion[w]);
        moving[w] = 1;
    }
    return (int)n;
}

void lub_moving_walls_free(lub_wall_motion *motion, int n)
{
    for (int w = 0; w < n; w++) {
        free(motion[w].time);
        free(motion[w].disp);
        motion[w].time = NULL;
        motion[w].disp = NULL;
    }
}

static const char *const origin_fields[3] = {"wallOriginX", "wallOriginY", "wallOriginZ"};

typedef struct {
    int npatches;
    lub_wall_motion motion[LUB_MAX_PATCHES]; /* per patch of the particles */
    lub_node *node[LUB_MAX_PATCHES];         /* its entry (NULL: not listed) */
    int history;                             /* some patch has a motion history */
    double t_meet;       /* the first time a moving wall comes within l0 of another (INFINITY) */
    char meet_what[256]; /* which walls */
} moving_walls;

static void moving_walls_read(lub_model *m, lub_scene *s)
{
    moving_walls *mw = m->state;
    const lub_particles *P = s->P;
    /* the names are patches of the particle file: present them as walls */
    lub_geometry geo = {0};
    lub_wall walls[LUB_MAX_PATCHES];
    memset(walls, 0, sizeof walls);
    geo.dim = P->dim;
    geo.nwalls = P->npatches;
    geo.walls = walls;
    for (int k = 0; k < P->npatches; k++)
        snprintf(walls[k].name, sizeof walls[k].name, "%s", P->patch_names[k]);
    int moving[LUB_MAX_PATCHES];
    mw->npatches = P->npatches;
    lub_moving_walls_read(lub_dict_root(s->dict), &geo, mw->motion, moving);
    for (int k = 0; k < P->npatches; k++) {
        mw->node[k] = moving[k] ? lub_dict_find(m->entry, P->patch_names[k]) : NULL;
        mw->history |= lub_wall_motion_is_history(&mw->motion[k]);
    }
    mw->t_meet = INFINITY;
}

/* A motion history places the particles itself, on one level: the multi-resolution levels
 * keep their wall particles in place (mps.h still_walls). */
static void moving_walls_check(lub_model *m, lub_scene *s)
{
    const moving_walls *mw = m->state;
    if (!mw->history) return;
    for (int k = 0; k < s->nmodels; k++) {
        if (strcmp(s->model[k].type->name, "multiResolution") != 0) continue;
        for (int p = 0; p < mw->npatches; p++)
            if (lub_wall_motion_is_history(&mw->motion[p]))
                lub_node_error(mw->node[p],
                               "movingWalls: wall '%s' has 'motion: %s', which a "
                               "multi-resolution run (multiResolution) does not support: its "
                               "levels keep the wall particles in place (only a plane sliding "
                               "along itself at a constant velocity may move there)",
                               s->P->patch_names[p], lub_motion_names[mw->motion[p].kind]);
    }
}

/* The whole motion's largest speed: a constant one's, a sinusoid's 2 pi f |A|, the table's
 * steepest row interval. */
static double full_max_speed(const lub_wall_motion *mo, double v[3])
{
    if (mo->kind == LUB_MOTION_SINUSOIDAL)
        return lub_wall_motion_max_speed(mo, 0.0, 1.0 / mo->frequency, v);
    if (mo->kind == LUB_MOTION_TABLE)
        return lub_wall_motion_max_speed(mo, mo->time[0], mo->time[mo->nrows - 1], v);
    return lub_wall_motion_max_speed(mo, 0.0, 0.0, v);
}

static void moving_walls_configure(lub_model *m, lub_scene *s, lub_mps_config *c)
{
    const moving_walls *mw = m->state;
    for (int k = 0; k < s->P->npatches; k++) {
        const lub_wall_motion *mo = &mw->motion[k];
        if (!lub_wall_motion_is_history(mo)) {
            memcpy(c->patch_velocity[k], mo->velocity, sizeof mo->velocity);
            continue;
        }
        /* the model places the particles (before and after every step); patch_velocity:
         * a velocity of the largest speed, for the Courant number of lubFoam's start-up */
        c->patch_moved[k] = 1;
        full_max_speed(mo, c->patch_velocity[k]);
    }
}

/* Place the particles of the history patches at x0 + d(t), with velocity u (NULL: d'(t)). */
static void place(const moving_walls *mw, lub_mps *f, double t, const double (*u)[3])
{
    lub_particles *P = f->P;
    const int dim = P->dim;
    double *x0[3] = {NULL, NULL, NULL};
    for (int d = 0; d < dim; d++) x0[d] = lub_particles_find_extra(P, origin_fields[d]);
    double disp[LUB_MAX_PATCHES][3], vel[LUB_MAX_PATCHES][3];
    for (int p = 0; p < mw->npatches; p++) {
        if (!lub_wall_motion_is_history(&mw->motion[p])) continue;
        lub_wall_motion_displacement(&mw->motion[p], t, disp[p]);
        if (u)
            memcpy(vel[p], u[p], sizeof vel[p]);
        else
            lub_wall_motion_velocity(&mw->motion[p], t, vel[p]);
    }
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] == LUB_FLUID) continue;
        const int p = P->patch[i];
        if (p >= mw->npatches || !lub_wall_motion_is_history(&mw->motion[p])) continue;
        for (int d = 0; d < dim; d++) {
            double x = x0[d][i] + disp[p][d];
            if (f->periodic[d]) { /* as the step wraps the fluid (step.c wrap) */
                const double lo = f->lo[d], L = f->hi[d] - f->lo[d];
                if (x < lo || x >= lo + L) {
                    x = lo + fmod(x - lo, L);
                    if (x < lo) x += L;
                    if (x >= lo + L) x -= L;
                }
            }
            P->x[d][i] = x;
            P->u[d][i] = vel[p][d];
        }
    }
}

/* The relative displacement of patch a against patch b from time ts to t, without the
 * periodic directions (a wall moving along a periodic direction meets itself there again,
 * and its images: the check takes the nearest image of every pair and the motion across). */
static void relative(const moving_walls *mw, int a, int b, double ts, double t, const int *periodic,
                     double r[3])
{
    double da[3], da0[3], db[3], db0[3];
    lub_wall_motion_displacement(&mw->motion[a], t, da);
    lub_wall_motion_displacement(&mw->motion[a], ts, da0);
    lub_wall_motion_displacement(&mw->motion[b], t, db);
    lub_wall_motion_displacement(&mw->motion[b], ts, db0);
    for (int d = 0; d < 3; d++) r[d] = periodic[d] ? 0.0 : (da[d] - da0[d]) - (db[d] - db0[d]);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The smallest distance |D_k + r| over the candidate pair differences D (n of them). */
static double min_dist(const double (*D)[3], size_t n, const double r[3], size_t *which)
{
    double best = INFINITY;
    for (size_t k = 0; k < n; k++) {
        double e0 = D[k][0] + r[0], e1 = D[k][1] + r[1], e2 = D[k][2] + r[2];
        double q = e0 * e0 + e1 * e1 + e2 * e2;
        if (q < best) best = q, *which = k;
    }
    return sqrt(best);
}

/* The samples t (*nt of them, allocated) of the relative path of patch a against patch b
 * over [ts, te]: 2000, then fine enough that it moves by l0/20 at most between samples, with
 * the motions' turning points; lo, hi: the path's box.  0 (nothing allocated) when the two
 * move together, or only along the periodic directions. */
static int pair_path(const moving_walls *mw, int a, int b, double ts, double te, const int *per,
                     double l0, double **tp, long *ntp, double lo[3], double hi[3])
{
    int n0 = 2000;
    double len = 0, r[3], rp[3];
    relative(mw, a, b, ts, ts, per, rp);
    for (int k = 1; k <= n0; k++) {
        relative(mw, a, b, ts, ts + (te - ts) * k / n0, per, r);
        len += sqrt((r[0] - rp[0]) * (r[0] - rp[0]) + (r[1] - rp[1]) * (r[1] - rp[1]) +
                    (r[2] - rp[2]) * (r[2] - rp[2]));
        memcpy(rp, r, sizeof r);
    }
    if (len == 0.0) return 0; /* they move together, or only along periodic x */
    long n = (long)ceil(len / (0.05 * l0));
    n = n < n0 ? n0 : n > 200000 ? 200000 : n;
    double *t = lub_malloc((size_t)(n + 1 + 2 * 4096) * sizeof *t);
    long nt = 0;
    for (long k = 0; k <= n; k++) t[nt++] = ts + (te - ts) * (double)k / (double)n;
    nt += lub_wall_motion_breaks(&mw->motion[a], ts, te, t + nt, 4096);
    nt += lub_wall_motion_breaks(&mw->motion[b], ts, te, t + nt, 4096);
    qsort(t, (size_t)nt, sizeof *t, cmp_double);
    for (int d = 0; d < 3; d++) lo[d] = INFINITY, hi[d] = -INFINITY;
    for (long k = 0; k < nt; k++) {
        relative(mw, a, b, ts, t[k], per, r);
        for (int d = 0; d < 3; d++) lo[d] = fmin(lo[d], r[d]), hi[d] = fmax(hi[d], r[d]);
    }
    *tp = t;
    *ntp = nt;
    return 1;
}

/* The pairs check_meeting looks at: a moves, and b either rests or comes later (each pair
 * once), both with wall particles (counts: over all ranks). */
static int pair_checked(const moving_walls *mw, const long *count, int a, int b)
{
    if (a == b || count[a] == 0 || count[b] == 0) return 0;
    const int ma = mw->node[a] != NULL, mb = mw->node[b] != NULL;
    return ma && !(mb && b < a);
}

/* The first time in (ts, te] at which a wall particle of a moving patch comes within l0 of
 * one of another patch (moving otherwise): the walls meet, no fluid particle fits between
 * them (wall particles l0 apart).  Pairs already closer than 2 l0 at ts (patches meeting at a
 * corner) count when they come within half their distance at ts.  Sets mw->t_meet and
 * mw->meet_what.
 *
 * On several ranks (f->par) each rank holds its slab's particles: it takes the pairs of its
 * own wall particles of a with the wall particles of b of every rank within reach (its own,
 * and the other ranks' within the paths' extent along the slabs' axis and 2 l0 of its slab,
 * or with the curve's ranges within the paths' reach in space and 2 l0 of the box of its
 * wall particles: lub_par_collect), the smallest distance at ts of each pair of patches over all
 * ranks, and the earliest meeting of all ranks with its rank's message: the serial check's pairs,
 * each on the rank of its a particle. */
static void check_meeting(moving_walls *mw, const lub_mps *f, double ts, double te)
{
    const lub_particles *P = f->P;
    lub_par *par = f->par;
    const double l0 = f->l0;
    const int dim = P->dim, np = mw->npatches;
    int per[3] = {0, 0, 0};
    double Lp[3] = {0, 0, 0};
    for (int d = 0; d < dim; d++)
        if (f->periodic[d]) per[d] = 1, Lp[d] = f->hi[d] - f->lo[d];
    long count[LUB_MAX_PATCHES] = {0}; /* wall particles per patch, all ranks' */
    for (size_t i = 0; i < P->n; i++)
        if (P->kind[i] == LUB_WALL && P->patch[i] < np) count[P->patch[i]]++;
    if (par) lub_par_sum_longs(count, (size_t)np);
    /* the paths of the pairs checked (the same on every rank: the motions alone) */
    double(*plo)[3] = lub_calloc((size_t)(np * np) + 1, sizeof *plo);
    double(*phi)[3] = lub_calloc((size_t)(np * np) + 1, sizeof *phi);
    double reach = 0;
    int *moves = lub_calloc((size_t)(np * np) + 1, sizeof *moves);
    for (int a = 0; a < np; a++)
        for (int b = 0; b < np; b++) {
            double *t = NULL;
            long nt = 0;
            if (!pair_checked(mw, count, a, b)) continue;
            moves[a * np + b] =
                pair_path(mw, a, b, ts, te, per, l0, &t, &nt, plo[a * np + b], phi[a * np + b]);
            free(t);
            if (par && moves[a * np + b] && par->method == LUB_PAR_SFC) {
                /* the curve's ranges are patches, not slabs: the paths' reach in space */
                double r2 = 0;
                for (int d = 0; d < dim; d++) {
                    const double e = fmax(fabs(plo[a * np + b][d]), fabs(phi[a * np + b][d]));
                    r2 += e * e;
                }
                reach = fmax(reach, sqrt(r2));
            } else if (par && moves[a * np + b]) {
                reach = fmax(reach, fmax(fabs(plo[a * np + b][par->axis]),
                                         fabs(phi[a * np + b][par->axis])));
            }
        }
    /* the wall particles of each patch: this rank's (own), then on several ranks the other
     * ranks' within reach of its slab */
    lub_particles Q = {0};
    if (par) {
        uint8_t *want = lub_calloc(P->n + 1, 1);
        for (size_t i = 0; i < P->n; i++) want[i] = P->kind[i] == LUB_WALL;
        lub_par_collect(par, P, reach + 2.0 * l0 * (1 + 1e-9), want, &Q);
        free(want);
    }
    const size_t nall = P->n + Q.n;
    double(*wx)[3] = lub_malloc((nall + 1) * sizeof *wx);
    uint8_t *own = lub_malloc(nall + 1);
    size_t start[LUB_MAX_PATCHES + 1], nw = 0;
    for (int p = 0; p < np; p++) {
        start[p] = nw;
        for (int q = 0; q < 2; q++) {
            const lub_particles *W = q ? &Q : P;
            for (size_t i = 0; i < W->n; i++)
                if (W->kind[i] == LUB_WALL && W->patch[i] == p) {
                    for (int d = 0; d < 3; d++) wx[nw][d] = d < dim ? W->x[d][i] : 0.0;
                    own[nw++] = q == 0;
                }
        }
    }
    start[np] = nw;
    if (par) lub_particles_free(&Q);
    /* the smallest distance of each pair of patches at ts, over all ranks */
    double *dmin = lub_malloc(((size_t)(np * np) + 1) * sizeof *dmin);
    for (int k = 0; k < np * np; k++) dmin[k] = INFINITY;
    for (int a = 0; a < np; a++)
        for (int b = 0; b < np; b++) {
            if (!moves[a * np + b]) continue;
            double q2 = INFINITY;
            for (size_t i = start[a]; i < start[a + 1]; i++) {
                if (!own[i]) continue;
                for (size_t j = start[b]; j < start[b + 1]; j++) {
                    double q = 0;
                    for (int d = 0; d < dim; d++) {
                        double e = wx[i][d] - wx[j][d];
                        if (per[d]) e -= Lp[d] * nearbyint(e / Lp[d]);
                        q += e * e;
                    }
                    q2 = fmin(q2, q);
                }
            }
            dmin[a * np + b] = sqrt(q2);
        }
    if (par) lub_par_min_doubles(dmin, (size_t)(np * np));
    for (int a = 0; a < np; a++) {
        for (int b = 0; b < np; b++) {
            if (!moves[a * np + b]) continue;
            double *t = NULL, lo[3], hi[3], r[3];
            long nt = 0;
            pair_path(mw, a, b, ts, te, per, l0, &t, &nt, lo, hi);
            /* the pair differences D = x_a - x_b (nearest image) that come within 2 l0 of a
             * point of the path's box */
            size_t nc = 0, cap = 1024;
            double(*D)[3] = lub_malloc(cap * sizeof *D);
            for (size_t i = start[a]; i < start[a + 1]; i++) {
                if (!own[i]) continue;
                for (size_t j = start[b]; j < start[b + 1]; j++) {
                    double e[3] = {0, 0, 0}, qb = 0;
                    for (int d = 0; d < dim; d++) {
                        e[d] = wx[i][d] - wx[j][d];
                        if (per[d]) e[d] -= Lp[d] * nearbyint(e[d] / Lp[d]);
                        double c = e[d] + fmin(fmax(-e[d], lo[d]), hi[d]);
                        qb += c * c;
                    }
                    if (qb >= 4.0 * l0 * l0) continue;
                    if (nc == cap) D = lub_realloc(D, (cap *= 2) * sizeof *D);
                    memcpy(D[nc++], e, sizeof e);
                }
            }
            const double dmin0 = dmin[a * np + b];
            const double thr = dmin0 < 2.0 * l0 ? 0.5 * dmin0 : l0;
            size_t which = 0;
            for (long k = 1; k < nt && nc > 0; k++) {
                relative(mw, a, b, ts, t[k], per, r);
                if (!(min_dist(D, nc, r, &which) < thr)) continue;
                /* bisection between the last sample apart and this one */
                double ta = t[k - 1], tb = t[k];
                for (int it = 0; it < 100 && tb - ta > 1e-14 * fmax(1.0, fabs(tb)); it++) {
                    double tm = 0.5 * (ta + tb);
                    relative(mw, a, b, ts, tm, per, r);
                    if (min_dist(D, nc, r, &which) < thr)
                        tb = tm;
                    else
                        ta = tm;
                }
                if (tb < mw->t_meet) {
                    mw->t_meet = tb;
                    snprintf(mw->meet_what, sizeof mw->meet_what,
                             "'%s' comes within %.3g m of '%s' (%s)", P->patch_names[a], thr,
                             P->patch_names[b],
                             thr < l0 ? "half their distance at the start: they meet at a "
                                        "corner"
                                      : "l0: no fluid particle fits between their wall particles");
                }
                break;
            }
            free(D);
            free(t);
        }
    }
    free(dmin), free(wx), free(own), free(moves), free(plo), free(phi);
    if (par) { /* the earliest of all ranks, with its rank's message */
        const double first = -lub_par_max(-mw->t_meet);
        const int who = lub_par_first(mw->t_meet == first && first < INFINITY);
        if (who >= 0) lub_par_bcast_text(mw->meet_what, sizeof mw->meet_what, who);
        mw->t_meet = first;
    }
}

static void moving_walls_init(lub_model *m, lub_scene *s)
{
    moving_walls *mw = m->state;
    lub_mps *f = s->level[0];
    lub_particles *P = f->P;
    const double ts = P->time;
    if (mw->history) {
        /* x0: from the fields of a restart, else x - d(ts) (x itself at ts = 0: d(0) = 0) */
        int have = 1;
        for (int d = 0; d < P->dim; d++)
            have &= lub_particles_find_extra(P, origin_fields[d]) != NULL;
        for (int d = 0; d < P->dim; d++) {
            double *x0 = lub_particles_extra(P, origin_fields[d]);
            if (have) continue;
            for (size_t i = 0; i < P->n; i++) {
                const int p = P->patch[i];
                double disp[3] = {0, 0, 0};
                if (P->kind[i] != LUB_FLUID && p < mw->npatches &&
                    lub_wall_motion_is_history(&mw->motion[p]))
                    lub_wall_motion_displacement(&mw->motion[p], ts, disp);
                x0[i] = P->kind[i] == LUB_FLUID ? 0.0 : P->x[d][i] - disp[d];
            }
        }
        place(mw, f, ts, NULL);
    }
    if (s->end_time > ts) {
        check_meeting(mw, f, ts, s->end_time);
        if (mw->t_meet <= s->end_time)
            lub_node_error(m->entry,
                           "movingWalls: the walls meet at t = %.6g s, before the %s (%g s): "
                           "%s; shorten the run or change the motion",
                           mw->t_meet, s->end_what[0] ? s->end_what : "end time", s->end_time,
                           mw->meet_what);
    }
}

static lub_step_status moving_walls_before_step(lub_model *m, lub_scene *s, double t, double dt,
                                                char *msg, size_t msgsize)
{
    (void)msg, (void)msgsize;
    const moving_walls *mw = m->state;
    if (!mw->history) return LUB_STEP_OK;
    /* the step's velocity: d' at its midpoint; the particles stay at x0 + d(t) */
    double u[LUB_MAX_PATCHES][3];
    for (int p = 0; p < mw->npatches; p++)
        lub_wall_motion_velocity(&mw->motion[p], t + 0.5 * dt, u[p]);
    place(mw, s->level[0], t, (const double(*)[3])u);
    return LUB_STEP_OK;
}

static void moving_walls_after_step(lub_model *m, lub_scene *s, double t)
{
    const moving_walls *mw = m->state;
    if (mw->history) place(mw, s->level[0], t, NULL);
}

/* "movingWalls lowerWall (1.2, 0) m/s, plate sinusoidal ...": the walls that move (nothing
 * when all rest) */
static void moving_walls_describe(const lub_model *m, const lub_scene *s, char *buf, size_t size)
{
    const moving_walls *mw = m->state;
    const lub_particles *P = s->P;
    size_t len = 0;
    buf[0] = '\0';
    for (int k = 0; k < P->npatches && len < size; k++) {
        const lub_wall_motion *mo = &mw->motion[k];
        if (!lub_wall_motion_is_history(mo) && norm3(mo->velocity) == 0) continue;
        char one[256];
        lub_wall_motion_describe(mo, P->dim, one, sizeof one);
        len += (size_t)snprintf(buf + len, size - len, "%s%s %s", len ? ", " : "movingWalls ",
                                P->patch_names[k], one);
    }
}

/* One line per listed wall: its motion, displacement, largest speed; and when the walls meet. */
static void moving_walls_header(const lub_model *m, const lub_scene *s)
{
    const moving_walls *mw = m->state;
    const lub_particles *P = s->P;
    for (int k = 0; k < P->npatches; k++) {
        if (!mw->node[k]) continue;
        const lub_wall_motion *mo = &mw->motion[k];
        char one[256];
        lub_wall_motion_describe(mo, P->dim, one, sizeof one);
        double vmax = full_max_speed(mo, NULL);
        switch (mo->kind) {
        case LUB_MOTION_SINUSOIDAL:
            lub_message("movingWalls: %s %s: at x0 + A (sin(2 pi f t + phase) - sin(phase)), "
                        "velocity its derivative, up to %g m/s",
                        P->patch_names[k], one, vmax);
            break;
        case LUB_MOTION_TABLE:
            lub_message("movingWalls: %s %s: at x0 + D(t) - D(0), D linear between the rows "
                        "(held beyond them), velocity the rows' slope, up to %g m/s",
                        P->patch_names[k], one, vmax);
            break;
        default:
            lub_message("movingWalls: %s at constant velocity %s", P->patch_names[k], one);
        }
    }
    if (s->end_time > 0) {
        if (isfinite(mw->t_meet))
            lub_message("movingWalls: the walls meet at t = %g s: %s", mw->t_meet, mw->meet_what);
        else
            lub_message("movingWalls: no moving wall comes within l0 of another before the %s",
                        s->end_what[0] ? s->end_what : "end time");
    }
}

static void moving_walls_free(lub_model *m)
{
    moving_walls *mw = m->state;
    lub_moving_walls_free(mw->motion, mw->npatches);
}

const lub_model_type lub_model_movingWalls = {
    .name = "movingWalls",
    .size = sizeof(moving_walls),
    .read = moving_walls_read,
    .check = moving_walls_check,
    .configure = moving_walls_configure,
    .init = moving_walls_init,
    .describe = moving_walls_describe,
    .header = moving_walls_header,
    .before_step = moving_walls_before_step,
    .after_step = moving_walls_after_step,
    .free = moving_walls_free,
};
