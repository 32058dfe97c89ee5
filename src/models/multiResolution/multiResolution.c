/* lubkit model multiResolution: the overlapping particle technique (OPT; methods.md §3,
 * thesis §2-2): one MPS solver per resolution level, coupled in the overlaps (opt.h), the
 * levels and their regions as levels.h reads them.
 *
 *     multiResolution: { Nr: 8, overlap: { coarse: 6, fine: 12 }, fixedBand: 4,
 *                        massCorrection: { cMax: 0.24, cMin: 0.048 } }
 *
 * The driver of the scene (models/model.h): it builds the levels' solvers (build) and takes
 * their coupled step (advance: lub_opt_step), merges the levels into the scene's particles
 * after every step (after_step), says which level owns a point (owner: T-27's ownership, for
 * the function objects), and keeps the next particle id and the mass M^0 of
 * the run's first start in uniform/state.yaml (an exact restart continues both). */
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "models/model.h"
#include "models/multiResolution/levels.h"
#include "models/multiResolution/opt.h"

typedef struct {
    lub_levels L; /* the entry, checked against particleGenDict's levels */
    lub_opt o;
    int built;
    double mass0;    /* M^0 of the run's first start (T-27) */
    int warned_full; /* a level's arrays were full (warned once) */
} multires;

static void mr_read(lub_model *m, lub_scene *s)
{
    multires *r = m->state;
    char geometry[LUB_PATH_MAX];
    lub_case_path(s->cs, geometry, "system/particleGenDict.yaml");
    lub_levels_read_case(&r->L, m->entry, geometry, s->P);
    s->levels = &r->L;
}

/* The levels take steps of semi-implicit MPS (lub_opt_step: lub_mps_step on each level). */
static void mr_check(lub_model *m, lub_scene *s)
{
    if (s->fluid->step != lub_mps_step)
        lub_node_error(m->entry,
                       "model 'multiResolution' couples levels of the fluid 'mps' (semi-implicit "
                       "MPS), not of '%s' (the fluid entry of constant/models.yaml)",
                       s->fluid->name);
}

static void mr_build(lub_model *m, lub_scene *s, const lub_mps_config *c)
{
    /* one solver per level; the scene's particles keep all levels, merged back after every
     * step for the function objects and the time folders */
    multires *r = m->state;
    lub_opt *o = &r->o;
    lub_opt_init(o, &r->L, s->P, c, s->geo, 0.5);
    r->built = 1;
    s->nlevels = o->nlevels;
    for (int k = 0; k < o->nlevels; k++) {
        s->level[k] = &o->m[k];
        s->dt_factor[k] = o->L.level[k].dt_factor;
    }
    s->levels = &o->L;
    /* multi-resolution with sub-stepping: one step of the scene is one step of the coarsest
     * level, nr steps of deltaT on the finest level (nr: the product of the Nr) */
    s->nr = o->nr;
}

/* After the other models' init (registry order): the walls they move, the merged particles
 * and the restart state. */
static void mr_init(lub_model *m, lub_scene *s)
{
    multires *r = m->state;
    lub_opt *o = &r->o;
    /* walls a model moves leave the place where the geometry puts them (elasticWall) */
    for (int p = 0; p < o->P[0].npatches; p++)
        if (o->m[0].c.patch_moved[p]) lub_opt_moving_wall(o, s->geo, p);
    lub_particles_reserve(s->P, lub_opt_capacity(o));
    lub_opt_merge(o, s->P);
    lub_opt_mass m0;
    lub_opt_mass_count(o, &m0);
    r->mass0 = m0.mass;
    lub_node *st = lub_dict_map_or(s->state, "multiResolution");
    if (st) { /* a restart: the ids and M^0 of the run it continues */
        const unsigned long long next = (unsigned long long)lub_dict_int(st, "nextId", 0, 1L << 62);
        const double mass0 = lub_dict_real(st, "mass0", LUB_NONNEGATIVE);
        if (next > o->next_id) o->next_id = next;
        if (mass0 > 0) r->mass0 = mass0;
    }
    lub_opt_set_mass0(o, r->mass0);
}

static void mr_header_levels(const lub_model *m, const lub_scene *s)
{
    (void)s;
    const lub_opt *o = &((const multires *)m->state)->o;
    char desc[1024];
    lub_levels_describe(&o->L, desc, sizeof desc);
    lub_message("multiResolution: %s", desc);
    for (int k = 0; k < o->nlevels; k++) {
        const lub_mps *q = &o->m[k];
        size_t c[3] = {0, 0, 0};
        for (size_t i = 0; i < o->P[k].n; i++) c[o->P[k].kind[i] < 3 ? o->P[k].kind[i] : 0]++;
        lub_message("MPS level %d: l0 %g m, re %g m (%g l0), n0 %.10g, lambda0 %.10g m^2; "
                    "%zu particles (fluid %zu, wall %zu, dummy %zu), %zu added in its "
                    "overlap margins; %zu generation cells, room for %zu particles",
                    k, q->l0, q->re, q->c.re_l0, q->n0, q->lambda0, o->P[k].n, c[0], c[1], c[2],
                    o->filled[k], o->ngen[k], o->P[k].cap);
    }
}

static lub_step_status mr_advance(lub_model *m, lub_scene *s, double dt, long *bad, char *msg,
                                  size_t msgsize)
{
    (void)s;
    int level;
    return lub_opt_step(&((multires *)m->state)->o, dt, &level, bad, msg, msgsize);
}

static void mr_after_step(lub_model *m, lub_scene *s, double t)
{
    (void)t;
    lub_opt *o = &((multires *)m->state)->o;
    lub_timer_start(&o->m[0].tm, LUB_T_OTHER); /* the coupling is charged to level 0 */
    lub_opt_merge(o, s->P);
    lub_timer_stop(&o->m[0].tm, LUB_T_OTHER);
}

static void mr_warn(lub_model *m, lub_scene *s, long step)
{
    (void)s;
    multires *r = m->state;
    if (r->o.total_full > 0 && !r->warned_full) {
        lub_warning("step %ld: multiResolution: a level's particle arrays are full (room "
                    "allocated at the start): %zu particles could not be generated, so the "
                    "fluid flowing into that level is lost",
                    step, r->o.total_full);
        r->warned_full = 1;
    }
}

/* Viscosity iterations of a level's last step: the sum over the velocity components. */
static int viscosity_iterations(const lub_mps *m)
{
    int it = 0;
    for (int d = 0; d < m->dim; d++) it += m->st.v[d].iterations;
    return it;
}

static void mr_log_levels(const lub_model *m, const lub_scene *s, double dt, double pit, char *buf,
                          size_t size)
{
    (void)s, (void)dt;
    const multires *r = m->state;
    const lub_opt *o = &r->o;
    /* per level: pressure and viscosity iterations, surface and given (fixed-band)
     * particles; fluid particles per level and the mass (T-27) against the start's */
    lub_opt_mass mc;
    lub_opt_mass_count(o, &mc);
    /* room for every level: its part is at most about 180 characters (the counts with 20
     * digits), and the given-in-a-wall note 40 */
    char lv[256 * LUB_MAX_LEVELS];
    size_t len = 0;
    for (int k = 0; k < o->nlevels && len < sizeof lv; k++)
        len += (size_t)snprintf(
            lv + len, sizeof lv - len, "%sL%d p %d U %d surf %zu given %zu fluid %zu (+%zu -%zu)",
            k ? " | " : "", k, o->m[k].st.p.iterations, viscosity_iterations(&o->m[k]),
            o->m[k].st.nsurface, o->st.nfixed[k], mc.fluid[k], o->total_generated[k],
            o->total_deleted[k]);
    for (int k = 0; k < o->nlevels && len < sizeof lv; k++)
        if (o->total_buried[k])
            len += (size_t)snprintf(lv + len, sizeof lv - len, " | L%d given in a wall %zu", k,
                                    o->total_buried[k]);
    char corr[64] = "";
    if (o->L.mass_correction)
        snprintf(corr, sizeof corr, " (correction %+.3g m/s)", o->st.correction);
    snprintf(buf, size, "%s  mass %+.3f%%%s  (p it per step, all levels: %.1f)  ", lv,
             r->mass0 > 0 ? 100 * (mc.mass / r->mass0 - 1) : 0.0, corr, pit);
}

static int mr_owner(const lub_model *m, double x)
{
    lub_level_where w;
    lub_levels_locate(&((const multires *)m->state)->o.L, x, &w);
    return w.owner;
}

static void mr_write_state(const lub_model *m, const lub_scene *s, FILE *fp)
{
    (void)s;
    const multires *r = m->state;
    fprintf(fp,
            "multiResolution:\n"
            "  nextId: %llu   # id of the next particle generated\n"
            "  mass0:  %.17g   # fluid mass M^0 at the first start (T-27)\n",
            (unsigned long long)r->o.next_id, r->mass0);
}

static void mr_free(lub_model *m)
{
    multires *r = m->state;
    if (r->built) lub_opt_free(&r->o);
}

const lub_model_type lub_model_multiResolution = {
    .name = "multiResolution",
    .size = sizeof(multires),
    .read = mr_read,
    .check = mr_check,
    .build = mr_build,
    .init = mr_init,
    .header_levels = mr_header_levels,
    .advance = mr_advance,
    .after_step = mr_after_step,
    .warn = mr_warn,
    .log_levels = mr_log_levels,
    .owner = mr_owner,
    .write_state = mr_write_state,
    .free = mr_free,
};
