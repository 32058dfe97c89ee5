/* lubkit dictionaries on libyaml (see dict.h).
 *
 * The YAML document is loaded with libyaml's composer (yaml_parser_load) and copied into a
 * small tree of lub_node that keeps each node's line and column, its path for messages, and,
 * for mappings, the keys the program asked for (the "known" keys used by lub_dict_finish).
 */
#include "io/dict.h"

#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <yaml.h>

#include "core/args.h"
#include "core/error.h"

struct lub_node {
    lub_node_type type;
    const lub_dict *dict;
    lub_node *parent;
    int line, col;
    char *text;           /* scalar text; for mapping entries the key is in keys[] */
    size_t n;             /* items (sequence) or entries (mapping) */
    lub_node **items;     /* sequence items, or mapping values */
    lub_node **keys;      /* mapping keys (scalar nodes) */
    char *label;          /* this node's name in its parent: key text or item index */
    char *path;           /* dotted path, built on demand */
    int opened;           /* a lookup was made in this mapping */
    unsigned char *known; /* per entry: the program asked for this key */
    char **asked;         /* keys asked for (also absent ones), for suggestions */
    size_t nasked, capasked;
};

struct lub_dict {
    char *path;
    lub_node *root;
    unsigned char *text; /* file contents while parsing (owned) */
};

/* ---- building the tree ---------------------------------------------------------------- */

static lub_node *node_new(const lub_dict *d, lub_node *parent, lub_node_type type,
                          const yaml_node_t *y)
{
    lub_node *n = lub_calloc(1, sizeof *n);
    n->type = type;
    n->dict = d;
    n->parent = parent;
    n->line = y ? (int)y->start_mark.line + 1 : 1;
    n->col = y ? (int)y->start_mark.column + 1 : 1;
    return n;
}

static void node_free(lub_node *n)
{
    if (!n) return;
    for (size_t i = 0; i < n->n; i++) {
        node_free(n->items[i]);
        if (n->keys) node_free(n->keys[i]);
    }
    for (size_t i = 0; i < n->nasked; i++) free(n->asked[i]);
    free(n->asked);
    free(n->items);
    free(n->keys);
    free(n->known);
    free(n->text);
    free(n->label);
    free(n->path);
    free(n);
}

static _Noreturn void fatal_node_raw(const lub_dict *d, int line, int col, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static _Noreturn void fatal_node_raw(const lub_dict *d, int line, int col, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    lub_vfatal_at(LUB_EXIT_INPUT, d->path, line, col, fmt, ap);
}

/* Conversion can fail (duplicate key, non-scalar key); the partly built tree is then owned
 * by the caller through *root so nothing leaks when a test catches the error. */
typedef struct {
    lub_dict *d;
    yaml_document_t *doc;
    unsigned char *seen; /* per document node: converted once already (a later visit is an alias) */
    size_t expanded;     /* nodes built by repeated visits: the expansion of aliases */
} build_ctx;

/* libyaml's composer keeps an alias as a reference to its anchored node; the tree built here
 * copies it at every use, so nested aliases multiply (9 lines of "&a [*b, *b, ...]" make
 * 10^9 nodes, all the memory there is).  libyaml leaves the limit to the application: a
 * dictionary repeats a setting or a few with aliases, so the copies are capped. */
#define LUB_DICT_MAX_ALIAS_NODES 10000

static lub_node *convert(build_ctx *ctx, yaml_node_t *y, lub_node *parent, int depth,
                         lub_node **slot)
{
    const lub_dict *d = ctx->d;
    if (depth > 64)
        fatal_node_raw(d, (int)y->start_mark.line + 1, (int)y->start_mark.column + 1,
                       "nesting deeper than 64 levels (recursive alias?)");
    const size_t id = (size_t)(y - ctx->doc->nodes.start);
    if (ctx->seen[id] && ++ctx->expanded > LUB_DICT_MAX_ALIAS_NODES)
        fatal_node_raw(d, (int)y->start_mark.line + 1, (int)y->start_mark.column + 1,
                       "YAML aliases (*name) expand to more than %d values: an alias repeats "
                       "its anchored part (&name) at every use, and nested ones multiply",
                       LUB_DICT_MAX_ALIAS_NODES);
    ctx->seen[id] = 1;
    switch (y->type) {
    case YAML_SCALAR_NODE: {
        lub_node *n = node_new(d, parent, LUB_NODE_SCALAR, y);
        *slot = n;
        n->text = lub_malloc(y->data.scalar.length + 1);
        memcpy(n->text, y->data.scalar.value, y->data.scalar.length);
        n->text[y->data.scalar.length] = '\0';
        return n;
    }
    case YAML_SEQUENCE_NODE: {
        lub_node *n = node_new(d, parent, LUB_NODE_SEQUENCE, y);
        *slot = n;
        size_t cnt = (size_t)(y->data.sequence.items.top - y->data.sequence.items.start);
        n->items = lub_calloc(cnt ? cnt : 1, sizeof *n->items);
        for (size_t i = 0; i < cnt; i++) {
            yaml_node_t *c = yaml_document_get_node(ctx->doc, y->data.sequence.items.start[i]);
            n->n = i + 1;
            lub_node *item = convert(ctx, c, n, depth + 1, &n->items[i]);
            char buf[32];
            snprintf(buf, sizeof buf, "%zu", i);
            item->label = lub_strdup(buf);
        }
        return n;
    }
    case YAML_MAPPING_NODE: {
        lub_node *n = node_new(d, parent, LUB_NODE_MAPPING, y);
        *slot = n;
        size_t cnt = (size_t)(y->data.mapping.pairs.top - y->data.mapping.pairs.start);
        n->items = lub_calloc(cnt ? cnt : 1, sizeof *n->items);
        n->keys = lub_calloc(cnt ? cnt : 1, sizeof *n->keys);
        n->known = lub_calloc(cnt ? cnt : 1, 1);
        for (size_t i = 0; i < cnt; i++) {
            yaml_node_pair_t *pr = &y->data.mapping.pairs.start[i];
            yaml_node_t *k = yaml_document_get_node(ctx->doc, pr->key);
            yaml_node_t *v = yaml_document_get_node(ctx->doc, pr->value);
            if (k->type != YAML_SCALAR_NODE)
                fatal_node_raw(d, (int)k->start_mark.line + 1, (int)k->start_mark.column + 1,
                               "a key must be a plain word, found a %s",
                               k->type == YAML_MAPPING_NODE ? "mapping" : "sequence");
            n->n = i + 1;
            convert(ctx, k, n, depth + 1, &n->keys[i]);
            for (size_t j = 0; j < i; j++)
                if (strcmp(n->keys[j]->text, n->keys[i]->text) == 0)
                    fatal_node_raw(d, n->keys[i]->line, n->keys[i]->col,
                                   "duplicate key '%s' (first given at line %d)", n->keys[i]->text,
                                   n->keys[j]->line);
            lub_node *val = convert(ctx, v, n, depth + 1, &n->items[i]);
            val->label = lub_strdup(n->keys[i]->text);
        }
        return n;
    }
    default:
        fatal_node_raw(d, (int)y->start_mark.line + 1, (int)y->start_mark.column + 1,
                       "unsupported YAML node");
    }
}

static const char *yaml_error_name(yaml_error_type_t e)
{
    switch (e) {
    case YAML_MEMORY_ERROR:
        return "out of memory";
    case YAML_READER_ERROR:
        return "unreadable text";
    case YAML_SCANNER_ERROR:
    case YAML_PARSER_ERROR:
    case YAML_COMPOSER_ERROR:
        return "YAML syntax error";
    default:
        return "YAML error";
    }
}

/* Line and column (1-based) of a byte offset into the text. */
static void offset_position(const unsigned char *text, size_t len, size_t offset, int *line,
                            int *col)
{
    *line = 1;
    *col = 1;
    for (size_t i = 0; i < offset && i < len; i++) {
        if (text[i] == '\n') {
            ++*line;
            *col = 1;
        } else if ((text[i] & 0xC0) != 0x80) { /* a character, not a UTF-8 continuation */
            ++*col;
        }
    }
}

/* Fatal error for a failed yaml_parser_load, after releasing the parser. */
static _Noreturn void load_error(lub_dict *d, yaml_parser_t *parser, const unsigned char *text,
                                 size_t len)
{
    char msg[1024];
    int line = (int)parser->problem_mark.line + 1, col = (int)parser->problem_mark.column + 1;
    /* libyaml's reader (bad UTF-8, a control character such as NUL) gives the position as
     * a byte offset and leaves the mark at the start */
    if (parser->error == YAML_READER_ERROR)
        offset_position(text, len, parser->problem_offset, &line, &col);
    if (parser->error == YAML_READER_ERROR && parser->problem_value >= 0)
        snprintf(msg, sizeof msg, "%s: %s (byte 0x%02x)", yaml_error_name(parser->error),
                 parser->problem ? parser->problem : "?", (unsigned)parser->problem_value);
    else
        snprintf(msg, sizeof msg, "%s: %s%s%s", yaml_error_name(parser->error),
                 parser->problem ? parser->problem : "?", parser->context ? " " : "",
                 parser->context ? parser->context : "");
    yaml_parser_delete(parser);
    fatal_node_raw(d, line, col, "%s", msg);
}

/* Parse text of given length into d->root.  Errors are fatal; resources are released first. */
static void parse_into(lub_dict *d, const unsigned char *text, size_t len)
{
    yaml_parser_t parser;
    yaml_document_t doc;
    if (!yaml_parser_initialize(&parser)) lub_fatal_run("libyaml: cannot initialise parser");
    yaml_parser_set_input_string(&parser, text, len);
    if (!yaml_parser_load(&parser, &doc)) load_error(d, &parser, text, len);
    /* A dictionary is one document: keys after a second '---' would be silently ignored. */
    yaml_document_t next;
    if (!yaml_parser_load(&parser, &next)) {
        yaml_document_delete(&doc);
        load_error(d, &parser, text, len);
    }
    if (yaml_document_get_root_node(&next)) {
        int line = (int)next.start_mark.line + 1, col = (int)next.start_mark.column + 1;
        yaml_document_delete(&next);
        yaml_document_delete(&doc);
        yaml_parser_delete(&parser);
        fatal_node_raw(d, line, col,
                       "a second YAML document begins here ('---'): a dictionary is one "
                       "document, whose entries all belong to the first one");
    }
    yaml_document_delete(&next);
    yaml_parser_delete(&parser);

    yaml_node_t *top = yaml_document_get_root_node(&doc);
    if (!top) { /* empty document: an empty mapping */
        yaml_document_delete(&doc);
        d->root = node_new(d, NULL, LUB_NODE_MAPPING, NULL);
        d->root->known = lub_calloc(1, 1);
        return;
    }
    if (top->type != YAML_MAPPING_NODE) {
        int line = (int)top->start_mark.line + 1, col = (int)top->start_mark.column + 1;
        yaml_document_delete(&doc);
        fatal_node_raw(d, line, col, "expected a mapping of 'key: value' entries at the top");
    }
    /* A catcher makes sure the document is released if conversion fails. */
    lub_catcher c;
    build_ctx ctx = {d, &doc, NULL, 0};
    ctx.seen = lub_calloc((size_t)(doc.nodes.top - doc.nodes.start) + 1, 1);
    if (lub_error_catch(&c) == 0) {
        convert(&ctx, top, NULL, 0, &d->root);
        lub_error_uncatch();
        free(ctx.seen);
        yaml_document_delete(&doc);
    } else {
        free(ctx.seen);
        yaml_document_delete(&doc);
        node_free(d->root);
        d->root = NULL;
        lub_fatal_at(NULL, 0, 0, "%s", c.message); /* message already carries file:line */
    }
}

static lub_dict *dict_new(const char *path)
{
    lub_dict *d = lub_calloc(1, sizeof *d);
    d->path = lub_strdup(path);
    return d;
}

/* Parse, releasing d itself when parsing fails (so a caught error leaks nothing). */
static lub_dict *dict_parse_owned(lub_dict *d, const unsigned char *text, size_t len)
{
    lub_catcher c;
    if (lub_error_catch(&c) == 0) {
        parse_into(d, text, len);
        lub_error_uncatch();
        return d;
    }
    free(d->text);
    free(d->path);
    free(d);
    lub_fatal_at(NULL, 0, 0, "%s", c.message);
}

/* lub_dict_substitute: the file (device, inode) whose reads parse `text`, named `name`. */
static struct {
    int on;
    dev_t dev;
    ino_t ino;
    char *name, *text;
} subst;

void lub_dict_substitute(const char *path, const char *name, const char *text)
{
    free(subst.name);
    free(subst.text);
    memset(&subst, 0, sizeof subst);
    struct stat st;
    if (!path || stat(path, &st) != 0) return;
    subst.on = 1;
    subst.dev = st.st_dev;
    subst.ino = st.st_ino;
    subst.name = lub_strdup(name ? name : path);
    subst.text = lub_strdup(text);
}

static lub_dict *read_file(const char *path, int optional)
{
    struct stat st;
    if (subst.on && stat(path, &st) == 0 && st.st_dev == subst.dev && st.st_ino == subst.ino)
        return dict_parse_owned(dict_new(subst.name), (const unsigned char *)subst.text,
                                strlen(subst.text));
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        if (optional && errno == ENOENT) return NULL;
        lub_fatal("cannot open dictionary '%s': %s", path, strerror(errno));
    }
    size_t cap = 4096, len = 0;
    unsigned char *buf = lub_malloc(cap);
    size_t got;
    while ((got = fread(buf + len, 1, cap - len, fp)) > 0) {
        len += got;
        if (len == cap) buf = lub_realloc(buf, cap *= 2);
    }
    int err = ferror(fp);
    fclose(fp);
    if (err) {
        free(buf);
        lub_fatal("cannot read dictionary '%s'", path);
    }
    lub_dict *d = dict_new(path);
    d->text = buf; /* released with d if parsing fails */
    dict_parse_owned(d, buf, len);
    free(d->text);
    d->text = NULL;
    return d;
}

lub_dict *lub_dict_read(const char *path)
{
    return read_file(path, 0);
}
lub_dict *lub_dict_read_optional(const char *path)
{
    return read_file(path, 1);
}

lub_dict *lub_dict_parse(const char *name, const char *text)
{
    return dict_parse_owned(dict_new(name), (const unsigned char *)text, strlen(text));
}

void lub_dict_free(lub_dict *d)
{
    if (!d) return;
    node_free(d->root);
    free(d->path);
    free(d);
}

lub_node *lub_dict_root(const lub_dict *d)
{
    return d->root;
}
const char *lub_dict_path(const lub_dict *d)
{
    return d->path;
}

/* ---- nodes ---------------------------------------------------------------------------- */

lub_node_type lub_node_type_of(const lub_node *n)
{
    return n->type;
}
int lub_node_line(const lub_node *n)
{
    return n->line;
}
int lub_node_col(const lub_node *n)
{
    return n->col;
}
const char *lub_node_file(const lub_node *n)
{
    return n->dict->path;
}
size_t lub_node_size(const lub_node *n)
{
    return n->type == LUB_NODE_SCALAR ? 0 : n->n;
}

static const char *type_name(lub_node_type t)
{
    return t == LUB_NODE_SCALAR     ? "a single value"
           : t == LUB_NODE_SEQUENCE ? "a list"
                                    : "a mapping";
}

_Noreturn void lub_node_error(const lub_node *n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    lub_vfatal_at(LUB_EXIT_INPUT, n->dict->path, n->line, n->col, fmt, ap);
}

const char *lub_node_path(const lub_node *n)
{
    lub_node *m = (lub_node *)n;
    if (m->path) return m->path;
    if (!m->parent || !m->label) {
        m->path = lub_strdup(m->label ? m->label : "");
        return m->path;
    }
    const char *pp = lub_node_path(m->parent);
    size_t len = strlen(pp) + strlen(m->label) + 2;
    m->path = lub_malloc(len);
    if (*pp)
        snprintf(m->path, len, "%s.%s", pp, m->label);
    else
        snprintf(m->path, len, "%s", m->label);
    return m->path;
}

const char *lub_node_text(const lub_node *n)
{
    if (n->type != LUB_NODE_SCALAR)
        lub_node_error(n, "'%s' expects a single value, found %s", lub_node_path(n),
                       type_name(n->type));
    return n->text;
}

lub_node *lub_node_item(const lub_node *seq, size_t i)
{
    if (seq->type != LUB_NODE_SEQUENCE || i >= seq->n) lub_bug("bad sequence access");
    return seq->items[i];
}

const char *lub_node_key_at(const lub_node *map, size_t i)
{
    if (map->type != LUB_NODE_MAPPING || i >= map->n) lub_bug("bad mapping access");
    lub_node *m = (lub_node *)map;
    m->opened = 1;
    m->known[i] = 1;
    return map->keys[i]->text;
}

lub_node *lub_node_value_at(const lub_node *map, size_t i)
{
    lub_node_key_at(map, i);
    return map->items[i];
}

lub_node *lub_node_expect_map(lub_node *n)
{
    if (n->type != LUB_NODE_MAPPING)
        lub_node_error(n, "'%s' expects a mapping of 'key: value' entries, found %s",
                       lub_node_path(n), type_name(n->type));
    n->opened = 1;
    return n;
}

double lub_node_real(const lub_node *n, lub_range r)
{
    const char *s = lub_node_text(n);
    double v;
    if (!*s) lub_node_error(n, "'%s' expects a real number, found nothing", lub_node_path(n));
    if (lub_parse_real(s, &v))
        lub_node_error(n, "'%s' expects a real number, found '%s'", lub_node_path(n), s);
    int bad_lo = r.lo_open ? !(v > r.lo) : !(v >= r.lo);
    int bad_hi = r.hi_open ? !(v < r.hi) : !(v <= r.hi);
    if (bad_lo || bad_hi) {
        char lo[64] = "", hi[64] = "";
        if (isfinite(r.lo)) snprintf(lo, sizeof lo, "%s %g", r.lo_open ? ">" : ">=", r.lo);
        if (isfinite(r.hi)) snprintf(hi, sizeof hi, "%s %g", r.hi_open ? "<" : "<=", r.hi);
        lub_node_error(n, "'%s' must be %s%s%s, found '%s'", lub_node_path(n), lo,
                       (*lo && *hi) ? " and " : "", hi, s);
    }
    return v;
}

long lub_node_int(const lub_node *n, long lo, long hi)
{
    const char *s = lub_node_text(n);
    long v;
    if (lub_parse_int(s, &v))
        lub_node_error(n, "'%s' expects an integer, found '%s'", lub_node_path(n),
                       *s ? s : "nothing");
    if (v < lo || v > hi) {
        if (hi == LONG_MAX)
            lub_node_error(n, "'%s' must be >= %ld, found '%s'", lub_node_path(n), lo, s);
        lub_node_error(n, "'%s' must be between %ld and %ld, found '%s'", lub_node_path(n), lo, hi,
                       s);
    }
    return v;
}

int lub_node_bool(const lub_node *n)
{
    const char *s = lub_node_text(n);
    static const char *yes[] = {"true", "yes", "on"}, *no[] = {"false", "no", "off"};
    for (int i = 0; i < 3; i++) {
        if (strcasecmp(s, yes[i]) == 0) return 1;
        if (strcasecmp(s, no[i]) == 0) return 0;
    }
    lub_node_error(n, "'%s' expects true or false, found '%s'", lub_node_path(n),
                   *s ? s : "nothing");
}

/* ---- lookups -------------------------------------------------------------------------- */

static void ask(lub_node *map, const char *key)
{
    for (size_t i = 0; i < map->nasked; i++)
        if (strcmp(map->asked[i], key) == 0) return;
    if (map->nasked == map->capasked) {
        map->capasked = map->capasked ? 2 * map->capasked : 8;
        map->asked = lub_realloc(map->asked, map->capasked * sizeof *map->asked);
    }
    map->asked[map->nasked++] = lub_strdup(key);
}

lub_node *lub_dict_find(lub_node *map, const char *key)
{
    if (!map) return NULL;
    lub_node_expect_map(map);
    ask(map, key);
    for (size_t i = 0; i < map->n; i++)
        if (strcmp(map->keys[i]->text, key) == 0) {
            map->known[i] = 1;
            return map->items[i];
        }
    return NULL;
}

int lub_dict_has(lub_node *map, const char *key)
{
    return lub_dict_find(map, key) != NULL;
}

lub_node *lub_dict_get(lub_node *map, const char *key)
{
    lub_node *v = lub_dict_find(map, key);
    if (!v) {
        const char *p = lub_node_path(map);
        if (*p) lub_node_error(map, "missing required key '%s' in '%s'", key, p);
        lub_node_error(map, "missing required key '%s'", key);
    }
    return v;
}

double lub_dict_real(lub_node *map, const char *key, lub_range r)
{
    return lub_node_real(lub_dict_get(map, key), r);
}

double lub_dict_real_or(lub_node *map, const char *key, double def, lub_range r)
{
    lub_node *v = lub_dict_find(map, key);
    return v ? lub_node_real(v, r) : def;
}

long lub_dict_int(lub_node *map, const char *key, long lo, long hi)
{
    return lub_node_int(lub_dict_get(map, key), lo, hi);
}

long lub_dict_int_or(lub_node *map, const char *key, long def, long lo, long hi)
{
    lub_node *v = lub_dict_find(map, key);
    return v ? lub_node_int(v, lo, hi) : def;
}

int lub_dict_bool_or(lub_node *map, const char *key, int def)
{
    lub_node *v = lub_dict_find(map, key);
    return v ? lub_node_bool(v) : def;
}

const char *lub_dict_str(lub_node *map, const char *key)
{
    lub_node *v = lub_dict_get(map, key);
    const char *s = lub_node_text(v);
    if (!*s) lub_node_error(v, "'%s' expects a value, found nothing", lub_node_path(v));
    return s;
}

const char *lub_dict_str_or(lub_node *map, const char *key, const char *def)
{
    lub_node *v = lub_dict_find(map, key);
    return v ? lub_node_text(v) : def;
}

int lub_dict_choice(lub_node *map, const char *key, const char *const *choices, int def)
{
    lub_node *v = def < 0 ? lub_dict_get(map, key) : lub_dict_find(map, key);
    if (!v) return def;
    const char *s = lub_node_text(v);
    size_t nc = 0;
    for (; choices[nc]; nc++)
        if (strcmp(choices[nc], s) == 0) return (int)nc;
    char list[1024] = "";
    size_t len = 0;
    for (size_t i = 0; i < nc && len < sizeof list; i++)
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "", choices[i]);
    const char *near = lub_closest(s, choices, nc);
    if (near)
        lub_node_error(v, "'%s' must be one of: %s; found '%s' (did you mean '%s'?)",
                       lub_node_path(v), list, s, near);
    lub_node_error(v, "'%s' must be one of: %s; found '%s'", lub_node_path(v), list, s);
}

static int read_vec(lub_node *v, double *out, int nmin, int nmax, lub_range r)
{
    if (v->type != LUB_NODE_SEQUENCE) {
        char count[64];
        if (nmin == nmax)
            snprintf(count, sizeof count, "%d", nmin);
        else
            snprintf(count, sizeof count, "%d to %d", nmin, nmax);
        lub_node_error(v, "'%s' expects a list of %s numbers like [0, 1], found %s '%s'",
                       lub_node_path(v), count, type_name(v->type),
                       v->type == LUB_NODE_SCALAR ? v->text : "...");
    }
    if ((int)v->n < nmin || (int)v->n > nmax) {
        if (nmin == nmax)
            lub_node_error(v, "'%s' expects %d numbers, found %zu", lub_node_path(v), nmin, v->n);
        lub_node_error(v, "'%s' expects %d to %d numbers, found %zu", lub_node_path(v), nmin, nmax,
                       v->n);
    }
    for (size_t i = 0; i < v->n; i++) out[i] = lub_node_real(v->items[i], r);
    return (int)v->n;
}

int lub_dict_vec(lub_node *map, const char *key, double *out, int nmin, int nmax, lub_range r)
{
    return read_vec(lub_dict_get(map, key), out, nmin, nmax, r);
}

int lub_dict_vec_or(lub_node *map, const char *key, double *out, int nmin, int nmax, lub_range r)
{
    lub_node *v = lub_dict_find(map, key);
    return v ? read_vec(v, out, nmin, nmax, r) : 0;
}

static lub_node *typed(lub_node *v, lub_node_type t)
{
    if (v && v->type != t) {
        if (t == LUB_NODE_MAPPING) return lub_node_expect_map(v);
        lub_node_error(v, "'%s' expects %s, found %s", lub_node_path(v), type_name(t),
                       type_name(v->type));
    }
    if (v && t == LUB_NODE_MAPPING) v->opened = 1;
    return v;
}

lub_node *lub_dict_map(lub_node *map, const char *key)
{
    return typed(lub_dict_get(map, key), LUB_NODE_MAPPING);
}
lub_node *lub_dict_map_or(lub_node *map, const char *key)
{
    return typed(lub_dict_find(map, key), LUB_NODE_MAPPING);
}
lub_node *lub_dict_seq(lub_node *map, const char *key)
{
    return typed(lub_dict_get(map, key), LUB_NODE_SEQUENCE);
}
lub_node *lub_dict_seq_or(lub_node *map, const char *key)
{
    return typed(lub_dict_find(map, key), LUB_NODE_SEQUENCE);
}

/* ---- strictness ----------------------------------------------------------------------- */

static void finish_node(const lub_node *n)
{
    if (n->type == LUB_NODE_MAPPING && n->opened) {
        for (size_t i = 0; i < n->n; i++) {
            if (n->known[i]) continue;
            const lub_node *k = n->keys[i];
            const char *near = lub_closest(k->text, (const char *const *)n->asked, n->nasked);
            const char *p = lub_node_path(n);
            char where[512] = "";
            if (*p) snprintf(where, sizeof where, " in '%s'", p);
            if (near)
                lub_node_error(k, "unknown key '%s'%s (did you mean '%s'?)", k->text, where, near);
            char list[1024] = "";
            size_t len = 0;
            for (size_t j = 0; j < n->nasked && len < sizeof list; j++)
                len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", j ? ", " : "",
                                        n->asked[j]);
            lub_node_error(k, "unknown key '%s'%s (valid keys: %s)", k->text, where, list);
        }
    }
    if (n->type != LUB_NODE_SCALAR)
        for (size_t i = 0; i < n->n; i++) finish_node(n->items[i]);
}

void lub_dict_finish(const lub_dict *d) { finish_node(d->root); }
