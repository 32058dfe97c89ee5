/* lubkit text-preserving YAML edits (see yamledit.h).
 *
 * The text is parsed with libyaml's event API into a small tree that records, for every
 * node, its byte span in the text.  libyaml marks count characters (a CRLF counts two, a BOM
 * none), so a table maps character index -> byte offset.  Spans:
 *   - scalar: start..end mark of its event (anchor/tag and quotes included); block scalars
 *     ("|", ">") are trimmed of the trailing line breaks libyaml includes in them;
 *   - flow collection: from '[' / '{' to the end mark of the closing bracket;
 *   - block collection: from its first entry to the end of its last descendant (libyaml's
 *     end mark of a block collection is where the next token starts, after comments).
 * An edit splices the new text into the span; the result is parsed again and compared, in a
 * canonical form that ignores layout, with the old document in which the edited entry has
 * been replaced by the new value.  Only when both agree is the edit kept.
 */
#define _XOPEN_SOURCE 700 /* realpath */
#include "io/yamledit.h"

#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <yaml.h>

#include "core/error.h"
#include "io/case.h"
#include "io/dict.h"

enum { YK_SCALAR, YK_SEQ, YK_MAP, YK_ALIAS };
#define YAML_MAX_DEPTH 256

typedef struct ynode {
    int kind;
    int flow;          /* collection written in flow style */
    int plain;         /* scalar in plain style (its type is resolved from the text) */
    char *value;       /* scalar value, alias name */
    char *tag;         /* explicit tag, or NULL */
    size_t start, end; /* byte span in the text */
    size_t content;    /* start of the content after the anchor and tag, if any */
    int line, col;     /* 1-based, of the start */
    size_t n, nk, cap;
    struct ynode **keys, **items; /* mapping keys / values, or sequence items */
} ynode;

typedef struct {
    ynode *root; /* NULL for an empty document */
    size_t *off; /* character index -> byte offset */
    size_t nchar;
    int ok, eline, ecol; /* syntax error location (1-based) when !ok */
    char problem[512];
} ytree;

/* ---- growing strings ------------------------------------------------------------------ */

typedef struct {
    char *s;
    size_t n, cap;
} sbuf;

static void sb_add(sbuf *b, const char *s, size_t n)
{
    if (b->n + n + 1 > b->cap) {
        b->cap = 2 * (b->n + n + 1) + 64;
        b->s = lub_realloc(b->s, b->cap);
    }
    memcpy(b->s + b->n, s, n);
    b->n += n;
    b->s[b->n] = '\0';
}
static void sb_str(sbuf *b, const char *s)
{
    sb_add(b, s, strlen(s));
}
static void sb_fmt(sbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void sb_fmt(sbuf *b, const char *fmt, ...)
{
    char tmp[64];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    sb_add(b, tmp, (size_t)n < sizeof tmp ? (size_t)n : sizeof tmp - 1);
}
static char *sb_take(sbuf *b)
{
    if (!b->s) sb_add(b, "", 0);
    char *s = b->s;
    b->s = NULL;
    b->n = b->cap = 0;
    return s;
}

/* ---- the tree ------------------------------------------------------------------------- */

static void node_free(ynode *n)
{
    if (!n) return;
    for (size_t i = 0; i < n->n; i++) node_free(n->items[i]);
    for (size_t i = 0; i < n->nk; i++) node_free(n->keys[i]);
    free(n->items);
    free(n->keys);
    free(n->value);
    free(n->tag);
    free(n);
}

static void tree_free(ytree *t)
{
    node_free(t->root);
    free(t->off);
    t->root = NULL;
    t->off = NULL;
}

static size_t byte_at(const ytree *t, size_t index)
{
    return t->off[index <= t->nchar ? index : t->nchar];
}

static void push_child(ynode *parent, ynode *n)
{
    if (parent->kind == YK_MAP && parent->nk == parent->n) { /* a key */
        if (parent->nk == parent->cap) {
            parent->cap = parent->cap ? 2 * parent->cap : 4;
            parent->keys = lub_realloc(parent->keys, parent->cap * sizeof *parent->keys);
            parent->items = lub_realloc(parent->items, parent->cap * sizeof *parent->items);
        }
        parent->keys[parent->nk++] = n;
        return;
    }
    if (parent->n == parent->cap) {
        parent->cap = parent->cap ? 2 * parent->cap : 4;
        parent->items = lub_realloc(parent->items, parent->cap * sizeof *parent->items);
        if (parent->kind == YK_MAP)
            parent->keys = lub_realloc(parent->keys, parent->cap * sizeof *parent->keys);
    }
    parent->items[parent->n++] = n;
}

/* Parse text into t.  Returns 1 on success; on a syntax error fills t->problem/eline/ecol
 * and returns 0 (the tree is freed). */
static int tree_parse(ytree *t, const char *text, size_t len)
{
    memset(t, 0, sizeof *t);
    t->ok = 1;
    size_t bom = (len >= 3 && memcmp(text, "\xef\xbb\xbf", 3) == 0) ? 3 : 0;
    t->off = lub_malloc((len + 1) * sizeof *t->off);
    size_t k = 0;
    for (size_t i = bom; i < len; i++) /* UTF-8: a character starts at every non-continuation */
        if (((unsigned char)text[i] & 0xC0) != 0x80) t->off[k++] = i;
    t->off[k] = len;
    t->nchar = k;

    yaml_parser_t p;
    if (!yaml_parser_initialize(&p)) lub_fatal_run("cannot initialise the YAML parser");
    yaml_parser_set_input_string(&p, (const unsigned char *)text, len);
    ynode *stack[YAML_MAX_DEPTH];
    int depth = 0, ndoc = 0;
    sbuf anchors = {0}; /* "\nname\n" of every anchor defined so far */
    for (int done = 0; !done;) {
        yaml_event_t e;
        if (!yaml_parser_parse(&p, &e)) {
            t->ok = 0;
            t->eline = (int)p.problem_mark.line + 1;
            t->ecol = (int)p.problem_mark.column + 1;
            snprintf(t->problem, sizeof t->problem, "%s%s%s", p.problem ? p.problem : "error",
                     p.context ? " " : "", p.context ? p.context : "");
            break;
        }
        ynode *n = NULL;
        switch (e.type) {
        case YAML_STREAM_END_EVENT:
            done = 1;
            break;
        case YAML_DOCUMENT_START_EVENT:
            if (++ndoc > 1) {
                t->ok = 0;
                t->eline = (int)e.start_mark.line + 1;
                t->ecol = (int)e.start_mark.column + 1;
                snprintf(t->problem, sizeof t->problem,
                         "a dictionary holds one YAML document, found a second one");
                done = 1;
            }
            break;
        case YAML_SCALAR_EVENT:
        case YAML_ALIAS_EVENT:
        case YAML_SEQUENCE_START_EVENT:
        case YAML_MAPPING_START_EVENT:
            n = lub_calloc(1, sizeof *n);
            n->start = byte_at(t, e.start_mark.index);
            n->end = byte_at(t, e.end_mark.index);
            n->line = (int)e.start_mark.line + 1;
            n->col = (int)e.start_mark.column + 1;
            const yaml_char_t *anchor =
                e.type == YAML_SCALAR_EVENT           ? e.data.scalar.anchor
                : e.type == YAML_SEQUENCE_START_EVENT ? e.data.sequence_start.anchor
                : e.type == YAML_MAPPING_START_EVENT  ? e.data.mapping_start.anchor
                                                      : NULL;
            if (anchor) sb_str(&anchors, "\n"), sb_str(&anchors, (const char *)anchor);
            if (anchor) sb_str(&anchors, "\n");
            if (e.type == YAML_ALIAS_EVENT) {
                /* as libyaml's loader does: an alias must name an anchor defined before it */
                char want[1024];
                snprintf(want, sizeof want, "\n%s\n", (const char *)e.data.alias.anchor);
                if (!anchors.s || !strstr(anchors.s, want)) {
                    t->ok = 0;
                    t->eline = n->line;
                    t->ecol = n->col;
                    snprintf(t->problem, sizeof t->problem, "found undefined alias '*%.400s'",
                             (const char *)e.data.alias.anchor);
                    done = 1;
                }
            }
            if (e.type == YAML_SCALAR_EVENT) {
                n->kind = YK_SCALAR;
                n->value = lub_malloc(e.data.scalar.length + 1);
                memcpy(n->value, e.data.scalar.value, e.data.scalar.length);
                n->value[e.data.scalar.length] = '\0';
                n->plain = e.data.scalar.style == YAML_PLAIN_SCALAR_STYLE;
                if (e.data.scalar.tag) n->tag = lub_strdup((const char *)e.data.scalar.tag);
                if (e.data.scalar.style == YAML_LITERAL_SCALAR_STYLE ||
                    e.data.scalar.style == YAML_FOLDED_SCALAR_STYLE)
                    while (n->end > n->start && strchr(" \t\r\n", text[n->end - 1])) n->end--;
            } else if (e.type == YAML_ALIAS_EVENT) {
                n->kind = YK_ALIAS;
                n->value = lub_strdup((const char *)e.data.alias.anchor);
            } else if (e.type == YAML_SEQUENCE_START_EVENT) {
                n->kind = YK_SEQ;
                n->flow = e.data.sequence_start.style == YAML_FLOW_SEQUENCE_STYLE;
                if (e.data.sequence_start.tag)
                    n->tag = lub_strdup((const char *)e.data.sequence_start.tag);
                n->end = n->start;
            } else {
                n->kind = YK_MAP;
                n->flow = e.data.mapping_start.style == YAML_FLOW_MAPPING_STYLE;
                if (e.data.mapping_start.tag)
                    n->tag = lub_strdup((const char *)e.data.mapping_start.tag);
                n->end = n->start;
            }
            if (depth == 0)
                t->root = n;
            else
                push_child(stack[depth - 1], n);
            if (n->kind == YK_SEQ || n->kind == YK_MAP) {
                if (depth == YAML_MAX_DEPTH) {
                    t->ok = 0;
                    t->eline = n->line;
                    t->ecol = n->col;
                    snprintf(t->problem, sizeof t->problem, "nested more than %d levels deep",
                             YAML_MAX_DEPTH);
                    done = 1;
                    break;
                }
                stack[depth++] = n;
                n = NULL; /* complete at its end event */
            }
            break;
        case YAML_SEQUENCE_END_EVENT:
        case YAML_MAPPING_END_EVENT:
            n = stack[--depth];
            if (n->flow) n->end = byte_at(t, e.end_mark.index);
            break;
        default:
            break;
        }
        /* the content starts after the node's properties (&anchor, !tag) */
        if (n) {
            n->content = n->start;
            while (n->content < n->end && (text[n->content] == '&' || text[n->content] == '!')) {
                while (n->content < n->end && !strchr(" \t\r\n", text[n->content])) n->content++;
                while (n->content < n->end && strchr(" \t\r\n", text[n->content])) n->content++;
            }
        }
        /* a completed node extends its (block) parent's span */
        if (n && depth > 0 && stack[depth - 1]->end < n->end) stack[depth - 1]->end = n->end;
        yaml_event_delete(&e);
    }
    yaml_parser_delete(&p);
    free(anchors.s);
    if (!t->ok) {
        node_free(t->root);
        t->root = NULL;
    }
    return t->ok;
}

/* ---- canonical form: the document's content without its layout -------------------------
 * Scalars keep whether they were plain (a plain "1" is a number, a quoted "1" a string). */

typedef struct {
    const ynode *target; /* replaced by repl */
    const char *repl;
    const ynode *addmap; /* gets add appended after its entries */
    const char *add;
    const ynode *dropin; /* loses its entry or item drop */
    size_t drop;
} canon_edit;

static void canon(sbuf *b, const ynode *n, const canon_edit *ed)
{
    if (n->tag) sb_fmt(b, "!%zu:", strlen(n->tag)), sb_str(b, n->tag);
    if (ed && n == ed->target) { /* an edit keeps the node's properties (tag, anchor) */
        sb_str(b, ed->repl);
        return;
    }
    switch (n->kind) {
    case YK_SCALAR:
        sb_fmt(b, "S%c%zu:", n->plain ? 'p' : 'q', strlen(n->value));
        sb_str(b, n->value);
        break;
    case YK_ALIAS:
        sb_fmt(b, "*%zu:", strlen(n->value));
        sb_str(b, n->value);
        break;
    case YK_SEQ:
        sb_str(b, "[");
        for (size_t i = 0; i < n->n; i++)
            if (!ed || n != ed->dropin || i != ed->drop) canon(b, n->items[i], ed);
        sb_str(b, "]");
        break;
    default:
        sb_str(b, "{");
        for (size_t i = 0; i < n->n; i++)
            if (!ed || n != ed->dropin || i != ed->drop)
                canon(b, n->keys[i], ed), canon(b, n->items[i], ed);
        if (ed && n == ed->addmap) sb_str(b, ed->add);
        sb_str(b, "}");
        break;
    }
}

static char *canon_of(const ynode *root, const canon_edit *ed)
{
    sbuf b = {0};
    if (root) canon(&b, root, ed);
    return sb_take(&b);
}

/* ---- texts ---------------------------------------------------------------------------- */

static _Noreturn void syntax_fatal(const char *name, const ytree *t)
{
    lub_fatal_at(name, t->eline, t->ecol, "YAML syntax error: %s", t->problem);
}

/* Take ownership of text (len bytes, NUL-terminated) after checking it; frees it when fatal. */
static void text_adopt(lub_yaml_text *y, const char *name, char *text, size_t len)
{
    memset(y, 0, sizeof *y);
    snprintf(y->name, sizeof y->name, "%s", name);
    const unsigned char *u = (const unsigned char *)text;
    if (len >= 2 && ((u[0] == 0xFE && u[1] == 0xFF) || (u[0] == 0xFF && u[1] == 0xFE))) {
        free(text);
        lub_fatal_at(name, 0, 0, "the file is UTF-16; dictionaries must be UTF-8");
    }
    if (strlen(text) != len) {
        size_t at = strlen(text);
        int line = 1, col = 1;
        for (size_t i = 0; i < at; i++)
            line += text[i] == '\n', col = text[i] == '\n' ? 1 : col + 1;
        free(text);
        lub_fatal_at(name, line, col, "NUL byte in the file: not a YAML text");
    }
    ytree t;
    if (!tree_parse(&t, text, len)) {
        free(text);
        tree_free(&t);
        syntax_fatal(name, &t);
    }
    tree_free(&t);
    /* the file as every program reads it (dict.c): an edit must not be the only thing that
     * accepts a file the programs reject (a duplicate key, a second document, an alias
     * bomb) */
    lub_catcher c;
    if (lub_error_catch(&c) == 0) {
        lub_dict_free(lub_dict_parse(name, text));
        lub_error_uncatch();
    } else {
        free(text);
        lub_fatal_at(NULL, 0, 0, "%s", c.message);
    }
    y->text = text;
    y->len = len;
}

void lub_yaml_text_init(lub_yaml_text *y, const char *name, const char *text)
{
    text_adopt(y, name, lub_strdup(text), strlen(text));
}

void lub_yaml_text_read(lub_yaml_text *y, const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) lub_fatal("cannot read '%s': %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(fp), &st) == 0 && S_ISDIR(st.st_mode)) {
        fclose(fp);
        lub_fatal("cannot read '%s': it is a directory", path);
    }
    sbuf b = {0};
    char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, fp)) > 0) sb_add(&b, buf, n);
    int err = ferror(fp);
    fclose(fp);
    if (err) {
        free(b.s);
        lub_fatal("error reading '%s'", path);
    }
    size_t len = b.n;
    text_adopt(y, path, sb_take(&b), len);
}

void lub_yaml_text_free(lub_yaml_text *y)
{
    free(y->text);
    y->text = NULL;
    y->len = 0;
}

void lub_yaml_text_write(const lub_yaml_text *y, const char *path)
{
    /* write through a symbolic link to its target, not over the link */
    char real[PATH_MAX];
    const char *target = realpath(path, real) ? real : path;
    struct stat st;
    int have = stat(target, &st) == 0;
    lub_atomic_file f;
    if (!lub_atomic_open(&f, target)) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
    if (have) fchmod(fileno(f.fp), st.st_mode & 07777);
    if (fwrite(y->text, 1, y->len, f.fp) != y->len) {
        int e = errno;
        lub_atomic_abort(&f);
        lub_fatal_run("error writing '%s': %s", path, strerror(e));
    }
    if (lub_atomic_close(&f) != 0) lub_fatal_run("error writing '%s': %s", path, strerror(errno));
}

/* ---- dot paths ------------------------------------------------------------------------ */

typedef struct {
    char **seg;
    size_t nseg;
    char *buf;
} ypath;

static void path_split(ypath *p, const char *name, const char *key)
{
    memset(p, 0, sizeof *p);
    if (!key || !*key) return;
    p->buf = lub_strdup(key);
    p->seg = lub_calloc(strlen(key) + 1, sizeof *p->seg);
    for (char *s = p->buf;;) {
        char *dot = strchr(s, '.');
        if (dot) *dot = '\0';
        if (!*s) {
            free(p->buf);
            free(p->seg);
            lub_fatal_at(name, 0, 0, "bad key '%s': empty part in the dot path", key);
        }
        p->seg[p->nseg++] = s;
        if (!dot) break;
        s = dot + 1;
    }
}

static void path_free(ypath *p)
{
    free(p->buf);
    free(p->seg);
}

/* "a.b.c" from the first n segments, into b. */
static void path_join(sbuf *b, const ypath *p, size_t from, size_t to)
{
    for (size_t i = from; i < to; i++) {
        if (i > from) sb_str(b, ".");
        sb_str(b, p->seg[i]);
    }
}

static int parse_index(const char *s, size_t *out)
{
    if (!*s) return -1;
    for (const char *c = s; *c; c++)
        if (*c < '0' || *c > '9') return -1;
    errno = 0;
    unsigned long long v = strtoull(s, NULL, 10);
    if (errno) return -1;
    *out = (size_t)v;
    return 0;
}

enum { FOUND, NO_KEY, NO_ITEM, NOT_INDEX, IN_SCALAR, IN_ALIAS, EMPTY_DOC };

typedef struct {
    int why;
    ynode *node; /* found node, or the node in which segment k failed */
    size_t k;    /* failing segment */
} ylookup;

static ylookup lookup(ynode *root, const ypath *p)
{
    ylookup r = {FOUND, root, 0};
    if (!root) {
        r.why = p->nseg ? EMPTY_DOC : FOUND;
        return r;
    }
    for (size_t k = 0; k < p->nseg; k++) {
        ynode *n = r.node;
        r.k = k;
        if (n->kind == YK_MAP) {
            ynode *next = NULL;
            for (size_t i = 0; i < n->n && !next; i++)
                if (n->keys[i]->kind == YK_SCALAR && strcmp(n->keys[i]->value, p->seg[k]) == 0)
                    next = n->items[i];
            if (!next) return (ylookup){NO_KEY, n, k};
            r.node = next;
        } else if (n->kind == YK_SEQ) {
            size_t i;
            if (parse_index(p->seg[k], &i) != 0) return (ylookup){NOT_INDEX, n, k};
            if (i >= n->n) return (ylookup){NO_ITEM, n, k};
            r.node = n->items[i];
        } else {
            return (ylookup){n->kind == YK_ALIAS ? IN_ALIAS : IN_SCALAR, n, k};
        }
    }
    return r;
}

/* Fatal "no entry" message for a failed lookup. */
static _Noreturn void lookup_fatal(const char *name, ytree *t, ypath *p, const char *key, ylookup r)
{
    sbuf where = {0}, msg = {0};
    path_join(&where, p, 0, r.k);
    if (!where.s) sb_str(&where, "(the top level)");
    const char *w = where.s;
    sb_fmt(&msg, "%s", "");
    switch (r.why) {
    case NO_KEY: {
        ynode *m = r.node;
        const char **cand = lub_calloc(m->n + 1, sizeof *cand);
        size_t nc = 0;
        for (size_t i = 0; i < m->n; i++)
            if (m->keys[i]->kind == YK_SCALAR) cand[nc++] = m->keys[i]->value;
        const char *near = lub_closest(p->seg[r.k], cand, nc);
        if (near) {
            sbuf s = {0};
            path_join(&s, p, 0, r.k);
            if (r.k) sb_str(&s, ".");
            sb_str(&s, near);
            if (r.k + 1 < p->nseg) sb_str(&s, "."), path_join(&s, p, r.k + 1, p->nseg);
            sb_str(&msg, " (did you mean '");
            sb_str(&msg, s.s);
            sb_str(&msg, "'?)");
            free(s.s);
        } else {
            sb_str(&msg, r.k ? " ('" : " (the keys are: ");
            if (r.k) sb_str(&msg, w), sb_str(&msg, "' has keys: ");
            for (size_t i = 0; i < nc; i++) sb_str(&msg, i ? ", " : ""), sb_str(&msg, cand[i]);
            if (!nc) sb_str(&msg, "none");
            sb_str(&msg, ")");
        }
        free(cand);
        break;
    }
    case NO_ITEM:
        sb_fmt(&msg, " ('%s' has %zu items", w, r.node->n), sb_str(&msg, ")");
        break;
    case NOT_INDEX:
        sb_str(&msg, " ('");
        sb_str(&msg, w);
        sb_str(&msg, "' is a sequence: use an item number 0, 1, ...)");
        break;
    case IN_SCALAR:
        sb_str(&msg, " ('"), sb_str(&msg, w), sb_str(&msg, "' is a scalar)");
        break;
    case IN_ALIAS:
        sb_str(&msg, " ('"), sb_str(&msg, w),
            sb_str(&msg, "' is an alias; aliases are not followed)");
        break;
    default:
        sb_str(&msg, " (the file is empty)");
        break;
    }
    char text[2048];
    snprintf(text, sizeof text, "no entry '%s'%s", key, msg.s);
    free(where.s);
    free(msg.s);
    path_free(p);
    tree_free(t);
    lub_fatal_at(name, 0, 0, "%s", text);
}

/* Parse y's text (valid by construction) and find key; fatal when absent. */
static ynode *find(const lub_yaml_text *y, ytree *t, ypath *p, const char *key)
{
    path_split(p, y->name, key);
    if (!tree_parse(t, y->text, y->len)) {
        path_free(p);
        tree_free(t);
        syntax_fatal(y->name, t);
    }
    ylookup r = lookup(t->root, p);
    if (r.why != FOUND) lookup_fatal(y->name, t, p, key, r);
    return r.node;
}

/* ---- reading -------------------------------------------------------------------------- */

int lub_yaml_has(const lub_yaml_text *y, const char *key)
{
    ypath p;
    path_split(&p, y->name, key);
    ytree t;
    if (!tree_parse(&t, y->text, y->len)) {
        path_free(&p);
        tree_free(&t);
        syntax_fatal(y->name, &t);
    }
    int found = lookup(t.root, &p).why == FOUND && (t.root || p.nseg);
    path_free(&p);
    tree_free(&t);
    return found;
}

/* Source text of a node; lines after the first lose the node's own indentation. */
static char *source_text(const lub_yaml_text *y, const ynode *n)
{
    sbuf b = {0};
    size_t indent = (size_t)(n->col - 1);
    for (size_t i = n->start; i < n->end; i++) {
        sb_add(&b, y->text + i, 1);
        if (y->text[i] == '\n')
            for (size_t k = 0; k < indent && i + 1 < n->end && y->text[i + 1] == ' '; k++) i++;
    }
    return sb_take(&b);
}

char *lub_yaml_get(const lub_yaml_text *y, const char *key)
{
    ytree t;
    ypath p;
    ynode *n = find(y, &t, &p, key);
    char *out = !n                     ? lub_strdup("")
                : n->kind == YK_SCALAR ? lub_strdup(n->value)
                                       : source_text(y, n);
    path_free(&p);
    tree_free(&t);
    return out;
}

size_t lub_yaml_keys(const lub_yaml_text *y, const char *key, char ***keys)
{
    ytree t;
    ypath p;
    ynode *n = find(y, &t, &p, key);
    size_t count = 0;
    *keys = NULL;
    if (n && (n->kind == YK_SCALAR || n->kind == YK_ALIAS)) {
        const char *what = n->kind == YK_SCALAR ? "a scalar" : "an alias";
        path_free(&p);
        tree_free(&t);
        lub_fatal_at(y->name, 0, 0, "'%s' is %s; it has no keys", key, what);
    }
    if (n) {
        *keys = lub_calloc(n->n + 1, sizeof **keys);
        for (size_t i = 0; i < n->n; i++) {
            if (n->kind == YK_SEQ) {
                char num[32];
                snprintf(num, sizeof num, "%zu", i);
                (*keys)[count++] = lub_strdup(num);
            } else {
                ynode *k = n->keys[i];
                (*keys)[count++] = k->kind == YK_SCALAR ? lub_strdup(k->value) : source_text(y, k);
            }
        }
    }
    path_free(&p);
    tree_free(&t);
    return count;
}

void lub_yaml_keys_free(char **keys, size_t n)
{
    for (size_t i = 0; i < n; i++) free(keys[i]);
    free(keys);
}

/* ---- editing -------------------------------------------------------------------------- */

void lub_yaml_split_assignment(const char *arg, const char *what, char **key, char **value)
{
    /* spaces around the '=' and at the ends are layout, not part of key or value */
    const char *eq = strchr(arg, '=');
    if (!eq) lub_fatal("%s '%s': expected KEY=VALUE, e.g. %s 'nu=4.5e-4'", what, arg, what);
    const char *k0 = arg, *k1 = eq, *v0 = eq + 1, *v1 = eq + strlen(eq);
    while (k0 < k1 && strchr(" \t", *k0)) k0++;
    while (k1 > k0 && strchr(" \t", k1[-1])) k1--;
    while (v0 < v1 && strchr(" \t", *v0)) v0++;
    while (v1 > v0 && strchr(" \t", v1[-1])) v1--;
    if (k0 == k1) lub_fatal("%s '%s': the key before '=' is empty", what, arg);
    *key = lub_malloc((size_t)(k1 - k0) + 1);
    memcpy(*key, k0, (size_t)(k1 - k0));
    (*key)[k1 - k0] = '\0';
    *value = lub_malloc((size_t)(v1 - v0) + 1);
    memcpy(*value, v0, (size_t)(v1 - v0));
    (*value)[v1 - v0] = '\0';
}

/* Canonical form of a value given as YAML text, or NULL with a message in err when it is
 * not one valid value on one line. */
static char *value_canon(const char *what, const char *key, const char *value, char *err,
                         size_t errsz)
{
    if (strpbrk(value, "\r\n")) {
        snprintf(err, errsz, "%s '%s=...': the value must be on one line", what, key);
        return NULL;
    }
    ytree v;
    if (!tree_parse(&v, value, strlen(value))) {
        snprintf(err, errsz, "%s '%s=%s': the value is not valid YAML (%s at column %d)", what, key,
                 value, v.problem, v.ecol);
        tree_free(&v);
        return NULL;
    }
    if (v.root && (v.root->kind == YK_SEQ || v.root->kind == YK_MAP) && !v.root->flow) {
        snprintf(err, errsz,
                 "%s '%s=%s': write mappings and sequences in flow style, e.g. {a: 1} or [1, 2]",
                 what, key, value);
        tree_free(&v);
        return NULL;
    }
    /* an empty value is the empty plain scalar, as "key:" reads */
    char *c = v.root ? canon_of(v.root, NULL) : lub_strdup("Sp0:");
    tree_free(&v);
    return c;
}

/* Splice ins into y at [start, end), then check that the result parses and reads as
 * `expect` in canonical form.  Returns 0 and updates y, or -1 with a message in err and y
 * unchanged. */
static int splice_checked(lub_yaml_text *y, size_t start, size_t end, const char *ins,
                          const char *expect, const char *what, const char *key, const char *value,
                          char *err, size_t errsz)
{
    size_t li = strlen(ins), len = y->len - (end - start) + li;
    char *text = lub_malloc(len + 1);
    memcpy(text, y->text, start);
    memcpy(text + start, ins, li);
    memcpy(text + start + li, y->text + end, y->len - end + 1);
    ytree t;
    if (!tree_parse(&t, text, len)) {
        snprintf(err, errsz,
                 "%s '%s%s%s' would make the file invalid YAML (line %d, column %d: %s); the "
                 "file is left unchanged",
                 what, key, value ? "=" : "", value ? value : "", t.eline, t.ecol, t.problem);
        tree_free(&t);
        free(text);
        return -1;
    }
    char *got = canon_of(t.root, NULL);
    int same = strcmp(got, expect) == 0;
    free(got);
    tree_free(&t);
    if (!same && !value) {
        snprintf(err, errsz,
                 "%s '%s': the entry cannot be taken out of this layout without changing "
                 "other entries; the file is left unchanged",
                 what, key);
        free(text);
        return -1;
    }
    if (!same) {
        snprintf(err, errsz,
                 "%s '%s=%s': the value does not fit in place (it would change other entries; "
                 "quote it or write it in flow style); the file is left unchanged",
                 what, key, value);
        free(text);
        return -1;
    }
    free(y->text);
    y->text = text;
    y->len = len;
    return 0;
}

void lub_yaml_set(lub_yaml_text *y, const char *key, const char *value)
{
    if (!key || !*key) lub_fatal_at(y->name, 0, 0, "-set: empty key");
    char err[2048];
    ytree t;
    ypath p;
    ynode *n = find(y, &t, &p, key); /* fatal (freeing its own) when absent */
    char *vc = value_canon("-set", key, value, err, sizeof err);
    if (!vc) {
        path_free(&p);
        tree_free(&t);
        lub_fatal_at(y->name, 0, 0, "%s", err);
    }
    canon_edit ed = {.target = n, .repl = vc};
    char *expect = canon_of(t.root, &ed);
    /* an empty value ("key:") sits right after the ':'; keep a space before the new text */
    sbuf ins = {0};
    if (n->content == n->end && n->content > 0 && !strchr(" \t\n", y->text[n->content - 1]) &&
        *value)
        sb_str(&ins, " ");
    sb_str(&ins, value);
    char *s = sb_take(&ins);
    int rc = splice_checked(y, n->content, n->end, s, expect, "-set", key, value, err, sizeof err);
    /* A block collection may start at its key's indentation ("g:\n- 1\n- 2"), where a flow
     * value is not allowed: then put the value after the ':' instead ("g: [3]"). */
    size_t back = n->content;
    while (back > 0 && strchr(" \t\r\n", y->text[back - 1])) back--;
    if (rc && back < n->content && memchr(y->text + back, '\n', n->content - back) && back > 0 &&
        strchr(":-", y->text[back - 1]) && n->start == n->content) {
        char err2[2048];
        sbuf alt = {0};
        sb_str(&alt, " ");
        sb_str(&alt, value);
        char *s2 = sb_take(&alt);
        if (splice_checked(y, back, n->end, s2, expect, "-set", key, value, err2, sizeof err2) == 0)
            rc = 0;
        free(s2);
    }
    path_free(&p);
    tree_free(&t);
    free(vc);
    free(s);
    free(expect);
    if (rc) lub_fatal_at(y->name, 0, 0, "%s", err);
}

void lub_yaml_add(lub_yaml_text *y, const char *key, const char *value)
{
    if (!key || !*key) lub_fatal_at(y->name, 0, 0, "-add: empty key");
    char err[2048];
    ypath p;
    path_split(&p, y->name, key);
    ytree t;
    if (!tree_parse(&t, y->text, y->len)) {
        path_free(&p);
        tree_free(&t);
        syntax_fatal(y->name, &t);
    }
    ylookup r = lookup(t.root, &p);
    if (r.why == FOUND) {
        path_free(&p);
        tree_free(&t);
        lub_fatal_at(y->name, 0, 0, "-add '%s=%s': the entry exists already (use -set)", key,
                     value);
    }
    ynode *map = r.why == NO_KEY ? r.node : NULL;
    if (r.why != NO_KEY && !(r.why == EMPTY_DOC))
        lookup_fatal(y->name, &t, &p, key, r); /* not in a mapping: say why */
    if (r.why == EMPTY_DOC) r.k = 0;

    /* the new entry: "seg_k: {seg_k+1: {...: value}}" */
    sbuf v = {0};
    for (size_t i = r.k + 1; i < p.nseg; i++)
        sb_str(&v, "{"), sb_str(&v, p.seg[i]), sb_str(&v, ": ");
    sb_str(&v, value);
    for (size_t i = r.k + 1; i < p.nseg; i++) sb_str(&v, "}");
    char *vtext = sb_take(&v);
    char *vc = value_canon("-add", key, vtext, err, sizeof err);
    if (!vc) {
        free(vtext);
        path_free(&p);
        tree_free(&t);
        lub_fatal_at(y->name, 0, 0, "%s", err);
    }
    sbuf kc = {0};
    sb_fmt(&kc, "Sp%zu:", strlen(p.seg[r.k]));
    sb_str(&kc, p.seg[r.k]);
    sb_str(&kc, vc);
    char *addc = sb_take(&kc);

    sbuf ins = {0};
    size_t at;
    char *expect;
    if (!map) { /* empty document: the entry becomes its first line */
        at = y->len;
        if (at > 0 && y->text[at - 1] != '\n') sb_str(&ins, "\n");
        sb_str(&ins, p.seg[r.k]), sb_str(&ins, ": "), sb_str(&ins, vtext), sb_str(&ins, "\n");
        sbuf e = {0};
        sb_str(&e, "{"), sb_str(&e, addc), sb_str(&e, "}");
        expect = sb_take(&e);
    } else {
        canon_edit ed = {.addmap = map, .add = addc};
        expect = canon_of(t.root, &ed);
        if (map->flow) {
            /* after the last value, or just inside the '}' of an empty mapping */
            at = map->n ? map->items[map->n - 1]->end : map->end - 1;
            if (map->n) sb_str(&ins, ", ");
        } else {
            /* a new line after the mapping's last line, at the indentation of its keys */
            at = map->end;
            while (at < y->len && y->text[at] != '\n') at++;
            int crlf = at > 0 && at < y->len && y->text[at - 1] == '\r';
            if (crlf) at--;
            sb_str(&ins, crlf ? "\r\n" : "\n");
            for (int i = 1; i < map->keys[0]->col; i++) sb_str(&ins, " ");
        }
        sb_str(&ins, p.seg[r.k]), sb_str(&ins, ": "), sb_str(&ins, vtext);
    }
    char *s = sb_take(&ins);
    int rc = splice_checked(y, at, at, s, expect, "-add", key, value, err, sizeof err);
    free(s);
    free(expect);
    free(addc);
    free(vc);
    free(vtext);
    path_free(&p);
    tree_free(&t);
    if (rc) lub_fatal_at(y->name, 0, 0, "%s", err);
}

/* ---- removing ------------------------------------------------------------------------- */

static size_t line_start(const lub_yaml_text *y, size_t pos)
{
    while (pos > 0 && y->text[pos - 1] != '\n') pos--;
    return pos;
}

/* Just after the line break that ends the line holding pos (or the end of the text). */
static size_t line_after(const lub_yaml_text *y, size_t pos)
{
    while (pos < y->len && y->text[pos] != '\n') pos++;
    return pos < y->len ? pos + 1 : pos;
}

/* The text of [from, to) is blanks, with one '-' among them when dash (a block item). */
static int blank_before(const lub_yaml_text *y, size_t from, size_t to, int dash)
{
    int dashes = 0;
    for (size_t i = from; i < to; i++) {
        if (y->text[i] == '-' && dash && !dashes++) continue;
        if (y->text[i] != ' ' && y->text[i] != '\t') return 0;
    }
    return !dash || dashes == 1;
}

/* Column (0-based) of a comment after pos on its line, or -1. */
static long trailing_comment(const lub_yaml_text *y, size_t pos)
{
    size_t ls = line_start(y, pos);
    for (size_t i = pos; i < y->len && y->text[i] != '\n'; i++)
        if (y->text[i] == '#' && (i == 0 || strchr(" \t", y->text[i - 1]))) return (long)(i - ls);
    return -1;
}

void lub_yaml_remove(lub_yaml_text *y, const char *key)
{
    if (!key || !*key) lub_fatal_at(y->name, 0, 0, "-remove: empty key");
    char err[2048];
    ytree t;
    ypath p;
    ynode *n = find(y, &t, &p, key); /* fatal (freeing its own) when absent */
    ypath pp = p;
    pp.nseg--;
    ynode *parent = lookup(t.root, &pp).node;
    size_t i = 0;
    while (i < parent->n && parent->items[i] != n) i++;
    const int map = parent->kind == YK_MAP, last = i + 1 == parent->n;
    size_t s_i = map ? parent->keys[i]->start : n->start, e_i = n->end;
    size_t next = last ? 0 : map ? parent->keys[i + 1]->start : parent->items[i + 1]->start;
    size_t a, b;
    const char *ins = "";
    if (parent->flow) {
        /* "{a: 1, b: 2}": up to the next entry, or from the end of the one before */
        a = parent->n == 1 ? s_i : last ? parent->items[i - 1]->end : s_i;
        b = parent->n == 1 || last ? e_i : next;
    } else if (blank_before(y, line_start(y, s_i), s_i, !map)) {
        if (parent->n == 1 && parent != t.root) {
            /* the last entry of a nested block collection: it becomes an empty flow one */
            a = map ? s_i : line_start(y, s_i) + strspn(y->text + line_start(y, s_i), " \t");
            b = e_i;
            ins = map ? "{}" : "[]";
        } else {
            /* whole lines: the entry's, and the continuation lines of its comment (comment
             * lines whose '#' is aligned with the one after the value) */
            a = line_start(y, s_i);
            b = line_after(y, e_i);
            long col = trailing_comment(y, e_i);
            while (col >= 0 && b < y->len) {
                size_t e = line_after(y, b), k = b;
                while (k < e && strchr(" \t", y->text[k])) k++;
                if (k >= e || y->text[k] != '#' || (long)(k - b) != col) break;
                b = e;
            }
        }
    } else if (!last) {
        /* "- a: 1\n  b: 2" without a: "- b: 2" */
        a = s_i;
        b = next;
    } else {
        a = s_i;
        b = e_i;
        ins = map ? "{}" : "[]";
    }
    canon_edit ed = {.dropin = parent, .drop = i};
    /* the only entry of a block document: the document becomes empty (comments at most) */
    char *expect = parent == t.root && parent->n == 1 && !parent->flow ? lub_strdup("")
                                                                       : canon_of(t.root, &ed);
    int rc = splice_checked(y, a, b, ins, expect, "-remove", key, NULL, err, sizeof err);
    free(expect);
    path_free(&p);
    tree_free(&t);
    if (rc) lub_fatal_at(y->name, 0, 0, "%s", err);
}

/* ---- every value ---------------------------------------------------------------------- */

static void flat_value(sbuf *b, const char *v)
{
    for (; *v; v++) {
        if (*v == '\n')
            sb_str(b, "\\n");
        else
            sb_add(b, v, 1);
    }
}

static void flat_node(const lub_yaml_text *y, sbuf *b, const ynode *n, sbuf *path)
{
    size_t mark = path->n;
    int leaf = n->kind == YK_SCALAR || n->kind == YK_ALIAS || n->n == 0;
    if (n->kind == YK_SEQ && !leaf) {
        leaf = 1; /* a list of plain values, such as a vector: on one line */
        for (size_t i = 0; i < n->n && leaf; i++) leaf = n->items[i]->kind == YK_SCALAR;
    }
    if (leaf) {
        sb_add(b, path->s ? path->s : "", path->n);
        sb_str(b, " = ");
        if (n->kind == YK_SCALAR) {
            flat_value(b, n->value);
        } else if (n->kind == YK_ALIAS) {
            sb_str(b, "*"), sb_str(b, n->value);
        } else {
            sb_str(b, n->kind == YK_SEQ ? "[" : "{");
            for (size_t i = 0; i < n->n; i++) {
                const ynode *it = n->items[i];
                if (i) sb_str(b, ", ");
                sb_add(b, y->text + it->start, it->end - it->start);
            }
            sb_str(b, n->kind == YK_SEQ ? "]" : "}");
        }
        sb_str(b, "\n");
        return;
    }
    for (size_t i = 0; i < n->n; i++) {
        if (path->n) sb_str(path, ".");
        if (n->kind == YK_SEQ)
            sb_fmt(path, "%zu", i);
        else if (n->keys[i]->kind == YK_SCALAR)
            sb_str(path, n->keys[i]->value);
        else
            sb_add(path, y->text + n->keys[i]->start, n->keys[i]->end - n->keys[i]->start);
        flat_node(y, b, n->items[i], path);
        path->n = mark;
        if (path->s) path->s[mark] = '\0';
    }
}

char *lub_yaml_values(const lub_yaml_text *y, const char *key)
{
    ytree t;
    ypath p;
    ynode *n = find(y, &t, &p, key && *key ? key : "");
    sbuf b = {0}, path = {0};
    if (key && *key) sb_str(&path, key);
    if (n) flat_node(y, &b, n, &path);
    free(path.s);
    path_free(&p);
    tree_free(&t);
    return sb_take(&b);
}
