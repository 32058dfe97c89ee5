/* probe: sampling sets (probe_spec), their text forms, and system/probeDict.yaml.
 *
 *     pWall:  { type: wallPressure, patch: cylinder, bin: 2.5e-5, average: [0.024, 0.030] }
 *     pFilm:  { type: line, field: p, from: -0.004, to: 0.003, bin: 2.5e-5 }
 *     probes: { type: points, field: [p, U], at: [[0, 2.0e-5], [1.0e-4, 2.0e-5]] }
 *     film:   { type: film, bin: 2.0e-5 }
 *     totals: { type: totals }                            # patch: adds its load
 *     shape:  { type: wallShape, patch: cylinder }        # the elastic wall's deformation
 *     near:   { type: particles, from: -0.01, to: 0.03 }  # every particle there, one row each
 *
 * Template with every key: etc/templates/probeDict.yaml.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "probe.h"

const char *const probe_kind_names[] = {"wallPressure", "line",  "points",    "film", "totals",
                                        "wallShape",    "front", "particles", NULL};

void probe_spec_init(probe_spec *s, probe_kind kind, const char *name)
{
    memset(s, 0, sizeof *s);
    s->kind = kind;
    snprintf(s->name, sizeof s->name, "%s", name);
    snprintf(s->fields, sizeof s->fields, "p");
    s->from = s->to = s->bin = NAN;
    s->t0 = s->t1 = NAN;
}

void probe_spec_free(probe_spec *s)
{
    free(s->pts);
    s->pts = NULL;
    s->npts = 0;
}

_Noreturn void probe_error(const lub_node *node, const char *fmt, ...)
{
    char msg[1536];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (node) lub_node_error(node, "%s", msg);
    lub_fatal("%s", msg);
}

/* ---- text forms ----------------------------------------------------------------------- */

static void push_point(probe_spec *s, const double *x)
{
    s->pts = lub_realloc(s->pts, (s->npts + 1) * 3 * sizeof *s->pts);
    memcpy(s->pts + 3 * s->npts, x, 3 * sizeof *x);
    s->npts++;
}

int probe_parse_points(probe_spec *s, const char *text, char *err, size_t errsize)
{
    char buf[4096];
    if (strlen(text) >= sizeof buf) {
        snprintf(err, errsize, "the point list is too long");
        return -1;
    }
    strcpy(buf, text);
    s->npts = 0;
    s->pts_dim = 0;
    int k = 0;
    char *save = NULL;
    for (char *pt = strtok_r(buf, ";", &save); pt; pt = strtok_r(NULL, ";", &save)) {
        k++;
        double x[3] = {0.0, 0.0, 0.0};
        int nc = 0;
        char *save2 = NULL;
        for (char *tok = strtok_r(pt, " \t,", &save2); tok; tok = strtok_r(NULL, " \t,", &save2)) {
            if (nc == 3) {
                snprintf(err, errsize, "point %d has more than 3 coordinates", k);
                return -1;
            }
            if (lub_parse_real(tok, &x[nc])) {
                snprintf(err, errsize, "point %d: '%s' is not a number", k, tok);
                return -1;
            }
            nc++;
        }
        if (nc == 0) {
            snprintf(err, errsize, "point %d is empty", k);
            return -1;
        }
        if (nc == 1) {
            snprintf(err, errsize, "point %d has 1 coordinate; give 'x y' (2-D) or 'x y z'", k);
            return -1;
        }
        if (s->pts_dim && nc != s->pts_dim) {
            snprintf(err, errsize, "point %d has %d coordinates, point 1 has %d", k, nc,
                     s->pts_dim);
            return -1;
        }
        s->pts_dim = nc;
        push_point(s, x);
    }
    if (s->npts == 0) {
        snprintf(err, errsize, "no point given");
        return -1;
    }
    return 0;
}

int probe_parse_window(const char *text, double *t0, double *t1)
{
    const char *colon = strchr(text, ':');
    char left[128];
    if (!colon || (size_t)(colon - text) >= sizeof left) return -1;
    memcpy(left, text, (size_t)(colon - text));
    left[colon - text] = '\0';
    if (lub_parse_real(left, t0) || lub_parse_real(colon + 1, t1)) return -1;
    return *t0 <= *t1 ? 0 : -1;
}

/* ---- system/probeDict.yaml ------------------------------------------------------------ */

#define DICT "system/probeDict.yaml"

/* field: p | "p,U" | [p, U] */
static void read_fields(probe_spec *s, lub_node *m)
{
    lub_node *f = lub_dict_find(m, "field");
    if (!f) return;
    s->field_node = f;
    if (lub_node_type_of(f) == LUB_NODE_SCALAR) {
        const char *t = lub_node_text(f);
        if (!*t || strlen(t) >= sizeof s->fields)
            lub_node_error(f, "'%s' expects a field name or a list of them", lub_node_path(f));
        snprintf(s->fields, sizeof s->fields, "%s", t);
        return;
    }
    if (lub_node_type_of(f) != LUB_NODE_SEQUENCE || lub_node_size(f) == 0)
        lub_node_error(f, "'%s' expects a field name or a list of them, e.g. [p, U]",
                       lub_node_path(f));
    size_t len = 0;
    s->fields[0] = '\0';
    for (size_t i = 0; i < lub_node_size(f); i++) {
        lub_node *it = lub_node_item(f, i);
        if (lub_node_type_of(it) != LUB_NODE_SCALAR || !*lub_node_text(it))
            lub_node_error(it, "'%s' expects field names, e.g. [p, U]", lub_node_path(f));
        const char *t = lub_node_text(it);
        if (len + strlen(t) + 2 >= sizeof s->fields)
            lub_node_error(f, "'%s': the list is too long", lub_node_path(f));
        len += (size_t)snprintf(s->fields + len, sizeof s->fields - len, "%s%s", i ? "," : "", t);
    }
}

/* at: [[x, y], [x, y], ...] */
static void read_points(probe_spec *s, lub_node *m)
{
    lub_node *at = lub_dict_seq(m, "at");
    s->at_node = at;
    size_t n = lub_node_size(at);
    if (n == 0) lub_node_error(at, "'%s' lists no point", lub_node_path(at));
    for (size_t i = 0; i < n; i++) {
        lub_node *it = lub_node_item(at, i);
        size_t nc = lub_node_type_of(it) == LUB_NODE_SEQUENCE ? lub_node_size(it) : 0;
        if (nc < 2 || nc > 3)
            lub_node_error(it, "'%s': each point is a list [x, y] or [x, y, z]", lub_node_path(at));
        if (s->pts_dim && (int)nc != s->pts_dim)
            lub_node_error(it, "'%s': point %zu has %zu coordinates, point 1 has %d",
                           lub_node_path(at), i + 1, nc, s->pts_dim);
        s->pts_dim = (int)nc;
        double x[3] = {0.0, 0.0, 0.0};
        for (size_t d = 0; d < nc; d++) x[d] = lub_node_real(lub_node_item(it, d), LUB_ANY);
        push_point(s, x);
    }
}

/* A set name becomes a file name: postProcessing/probe/<time>/<name>.dat. */
static void check_set_name(const lub_node *m, const char *name)
{
    size_t len = strlen(name);
    if (len == 0 || len >= 64 || name[0] == '.' || strpbrk(name, "/\\ \t"))
        lub_node_error(m,
                       "set name '%s' cannot name a file: use letters, digits, '_', '-' "
                       "(at most 63, not starting with '.')",
                       name);
}

static void read_set(probe_spec *s, const char *name, lub_node *m)
{
    lub_node_expect_map(m);
    check_set_name(m, name);
    probe_kind kind = (probe_kind)lub_dict_choice(m, "type", probe_kind_names, -1);
    probe_spec_init(s, kind, name);
    s->node = m;
    if (kind == PROBE_WALL || kind == PROBE_SHAPE) {
        s->patch_node = lub_dict_get(m, "patch");
        s->patch = lub_dict_str(m, "patch");
    }
    if (kind == PROBE_TOTALS) {
        s->patch_node = lub_dict_find(m, "patch");
        s->patch = s->patch_node ? lub_dict_str(m, "patch") : NULL;
    }
    if (kind == PROBE_WALL) {
        s->arc = lub_dict_bool_or(m, "arc", 0);
        static const char *const facing[] = {"all", "down", "up", NULL};
        s->facing = (int[]){0, -1, 1}[lub_dict_choice(m, "facing", facing, 0)];
    }
    if (kind == PROBE_WALL || kind == PROBE_LINE || kind == PROBE_POINTS || kind == PROBE_PARTICLES)
        read_fields(s, m);
    if (kind == PROBE_WALL || kind == PROBE_LINE || kind == PROBE_FILM || kind == PROBE_SHAPE ||
        kind == PROBE_PARTICLES) {
        s->from = lub_dict_real_or(m, "from", NAN, LUB_ANY);
        s->to = lub_dict_real_or(m, "to", NAN, LUB_ANY);
        if (kind != PROBE_SHAPE && kind != PROBE_PARTICLES)
            s->bin = lub_dict_real_or(m, "bin", NAN, LUB_POSITIVE);
        if (!isnan(s->from) && !isnan(s->to) && !(s->from < s->to))
            lub_node_error(lub_dict_get(m, "to"), "'to' (%g) must be greater than 'from' (%g)",
                           s->to, s->from);
    }
    if (kind == PROBE_WALL || kind == PROBE_LINE || kind == PROBE_FILM || kind == PROBE_PARTICLES) {
        lub_node *zn = lub_dict_find(m, "z");
        if (zn) {
            double z[2];
            lub_dict_vec(m, "z", z, 2, 2, LUB_ANY);
            if (!(z[0] <= z[1]))
                lub_node_error(zn, "'%s' is a z-range [Z0, Z1] with Z0 <= Z1, found [%g, %g]",
                               lub_node_path(zn), z[0], z[1]);
            s->has_z = 1, s->z0 = z[0], s->z1 = z[1], s->z_node = zn;
        }
    }
    if (kind == PROBE_POINTS) {
        read_points(s, m);
        s->history_node = lub_dict_find(m, "history");
        s->history = lub_dict_bool_or(m, "history", 0);
    }
    lub_node *av = lub_dict_find(m, "average");
    if (av && kind == PROBE_PARTICLES)
        lub_node_error(av, "'average' does not apply to type particles (one row per particle "
                           "and time)");
    if (av) {
        double w[2];
        lub_dict_vec(m, "average", w, 2, 2, LUB_NONNEGATIVE);
        if (!(w[0] <= w[1]))
            lub_node_error(av, "'%s' is a time window [T0, T1] with T0 <= T1, found [%g, %g]",
                           lub_node_path(av), w[0], w[1]);
        s->average = 1;
        s->t0 = w[0];
        s->t1 = w[1];
        s->average_node = av;
    }
    if (kind != PROBE_TOTALS && kind != PROBE_FRONT && kind != PROBE_PARTICLES)
        s->dimensionless = lub_dict_bool_or(m, "dimensionless", 0);
}

void probe_sets_read(probe_sets *S, const lub_case *c)
{
    char path[LUB_PATH_MAX];
    memset(S, 0, sizeof *S);
    S->dict = lub_dict_read_optional(lub_case_path(c, path, DICT));
    if (!S->dict)
        lub_fatal("no subcommand given and no %s in case '%s': give a subcommand (wallPressure, "
                  "line, points, film, totals, wallShape, front, particles) or write the "
                  "dictionary; see probe "
                  "-help",
                  DICT, c->root);
    lub_node *root = lub_dict_root(S->dict);
    size_t n = lub_node_size(root);
    if (n == 0) lub_fatal("%s: no sampling set defined", path);
    S->sets = lub_calloc(n, sizeof *S->sets);
    for (size_t i = 0; i < n; i++) {
        read_set(&S->sets[i], lub_node_key_at(root, i), lub_node_value_at(root, i));
        S->n++;
    }
    lub_dict_finish(S->dict);
}

void probe_sets_free(probe_sets *S)
{
    for (int i = 0; i < S->n; i++) probe_spec_free(&S->sets[i]);
    free(S->sets);
    lub_dict_free(S->dict);
    memset(S, 0, sizeof *S);
}

int probe_sets_find(const probe_sets *S, const char *name)
{
    for (int i = 0; i < S->n; i++)
        if (strcmp(S->sets[i].name, name) == 0) return i;
    const char *names[256];
    char list[1024] = "";
    size_t len = 0;
    int nn = S->n < 256 ? S->n : 256;
    for (int i = 0; i < nn; i++) {
        names[i] = S->sets[i].name;
        if (len < sizeof list)
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", i ? " " : "", names[i]);
    }
    const char *near = lub_closest(name, names, (size_t)nn);
    char hint[128] = "";
    if (near) snprintf(hint, sizeof hint, " (did you mean '%s'?)", near);
    lub_fatal("-set: no set '%s' in %s%s; the sets are: %s", name, DICT, hint, list);
}
