/* lubkit tables (see table.h).
 *
 * Reading is strict because a table is usually the last step before an accuracy verdict: a
 * cell that is not a finite number, a short row or a missing header would otherwise turn into
 * a silently wrong error norm.  Every such problem is fatal and names file:line.
 */
#include "io/table.h"

#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "io/case.h"
#include "io/dict.h"

static const char *const SPACE = " \t\r\n\v\f";

/* Reading state, so that a fatal error can release everything first (unit tests catch the
 * error and go on). */
typedef struct {
    lub_table *t;
    FILE *fp;
    int is_stdin;
    char *line;
} reader;

static _Noreturn void read_fail(reader *r, int lineno, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static _Noreturn void read_fail(reader *r, int lineno, const char *fmt, ...)
{
    char msg[1536];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    free(r->line);
    r->line = NULL;
    if (r->fp && !r->is_stdin) fclose(r->fp);
    r->fp = NULL;
    lub_table_free(r->t);
    lub_fatal_at(r->t->source, lineno, 0, "%s", msg);
}

/* First non-space character of a line, or NULL for a blank line. */
static char *skip_space(char *s)
{
    s += strspn(s, SPACE);
    return *s ? s : NULL;
}

/* Length of a column name without its unit: "p[Pa]" -> 1. */
static size_t base_len(const char *name)
{
    const char *b = strchr(name, '[');
    return b ? (size_t)(b - name) : strlen(name);
}

static int same_base(const char *a, const char *b)
{
    size_t la = base_len(a), lb = base_len(b);
    return la == lb && strncmp(a, b, la) == 0;
}

static void push_name(reader *r, size_t *cap, const char *tok, int line)
{
    lub_table *t = r->t;
    for (size_t c = 0; c < t->ncol; c++)
        if (same_base(t->names[c], tok))
            read_fail(r, line, "duplicate column '%.*s' in the header", (int)base_len(tok), tok);
    if (base_len(tok) == 0) read_fail(r, line, "column name '%s' has no name before its unit", tok);
    if (t->ncol == *cap) {
        *cap = *cap ? 2 * *cap : 8;
        t->names = lub_realloc(t->names, *cap * sizeof *t->names);
    }
    t->names[t->ncol++] = lub_strdup(tok);
}

/* Parse "# name1 name2 ..." (line is modified). */
static void parse_header(reader *r, char *s, int lineno)
{
    if (*s != '#') {
        s[strcspn(s, "\r\n")] = '\0';
        read_fail(r, lineno, "missing header line '# name ...' (found '%.40s')", s);
    }
    size_t cap = 0;
    char *save = NULL;
    for (char *tok = strtok_r(s + 1, SPACE, &save); tok; tok = strtok_r(NULL, SPACE, &save))
        push_name(r, &cap, tok, lineno);
    if (r->t->ncol == 0) read_fail(r, lineno, "missing header line '# name ...' (no column names)");
}

static void parse_row(reader *r, char *line, int lineno, size_t *cap)
{
    lub_table *t = r->t;
    if (t->nrow == *cap) {
        *cap = *cap ? 2 * *cap : 64;
        t->data = lub_realloc(t->data, *cap * t->ncol * sizeof *t->data);
    }
    double *row = t->data + t->nrow * t->ncol;
    size_t c = 0;
    char *save = NULL;
    for (char *tok = strtok_r(line, SPACE, &save); tok; tok = strtok_r(NULL, SPACE, &save), c++) {
        if (c >= t->ncol) {
            size_t found = c + 1;
            while (strtok_r(NULL, SPACE, &save)) found++;
            read_fail(r, lineno, "expected %zu values, found %zu", t->ncol, found);
        }
        char *end;
        errno = 0;
        double v = strtod(tok, &end);
        if (end == tok || *end)
            read_fail(r, lineno, "'%s' is not a number (column %zu, '%s')", tok, c + 1,
                      t->names[c]);
        /* nan/inf are never valid table data; an overflow to inf is reported the same way.
         * (ERANGE on underflow is accepted: the value is a correctly rounded tiny number.) */
        if (!isfinite(v))
            read_fail(r, lineno, "'%s' is not a finite number (column %zu, '%s')", tok, c + 1,
                      t->names[c]);
        row[c] = v;
    }
    if (c != t->ncol) read_fail(r, lineno, "expected %zu values, found %zu", t->ncol, c);
    t->nrow++;
}

void lub_table_read(lub_table *t, const char *path)
{
    memset(t, 0, sizeof *t);
    reader r = {.t = t, .is_stdin = strcmp(path, "-") == 0};
    snprintf(t->source, sizeof t->source, "%s", r.is_stdin ? "<stdin>" : path);
    r.fp = r.is_stdin ? stdin : fopen(path, "r");
    if (!r.fp) lub_fatal("cannot open table '%s': %s", path, strerror(errno));
    struct stat st;
    if (!r.is_stdin && fstat(fileno(r.fp), &st) == 0 && S_ISDIR(st.st_mode))
        read_fail(&r, 0, "cannot read a table: this is a directory");

    size_t linecap = 0, rowcap = 0;
    int lineno = 0, have_header = 0;
    ssize_t len;
    while ((len = getline(&r.line, &linecap, r.fp)) >= 0) {
        lineno++;
        if (strlen(r.line) != (size_t)len) read_fail(&r, lineno, "NUL byte in a table (binary?)");
        char *s = skip_space(r.line);
        if (!have_header) {
            /* blank lines before the header are tolerated; the first text must be it */
            if (!s) continue;
            parse_header(&r, s, lineno);
            have_header = 1;
            continue;
        }
        if (!s || *s == '#') continue;
        parse_row(&r, s, lineno, &rowcap);
    }
    if (ferror(r.fp)) read_fail(&r, 0, "read error: %s", strerror(errno));
    if (!have_header)
        read_fail(&r, lineno > 0 ? lineno : 1,
                  "missing header line '# name ...' (the table is empty)");
    free(r.line);
    if (!r.is_stdin) fclose(r.fp);
}

void lub_table_free(lub_table *t)
{
    for (size_t c = 0; c < t->ncol; c++) free(t->names[c]);
    free(t->names);
    free(t->data);
    t->names = NULL;
    t->data = NULL;
    t->ncol = t->nrow = 0;
}

int lub_table_find(const lub_table *t, const char *name)
{
    /* an exact match (unit included) wins, then the name without unit */
    for (size_t c = 0; c < t->ncol; c++)
        if (strcmp(t->names[c], name) == 0) return (int)c;
    if (strchr(name, '[')) return -1; /* a unit was asked for and it differs */
    for (size_t c = 0; c < t->ncol; c++)
        if (same_base(t->names[c], name)) return (int)c;
    return -1;
}

int lub_table_col(const lub_table *t, const char *name)
{
    int c = lub_table_find(t, name);
    if (c >= 0) return c;
    char list[1024] = "";
    size_t len = 0;
    for (size_t k = 0; k < t->ncol && len < sizeof list; k++)
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", k ? " " : "", t->names[k]);
    /* suggest among the names without units */
    char **bases = lub_calloc(t->ncol, sizeof *bases);
    for (size_t k = 0; k < t->ncol; k++) {
        size_t bl = base_len(t->names[k]);
        bases[k] = lub_malloc(bl + 1);
        memcpy(bases[k], t->names[k], bl);
        bases[k][bl] = '\0';
    }
    const char *near = lub_closest(name, (const char *const *)bases, t->ncol);
    char hint[300] = "";
    if (near) snprintf(hint, sizeof hint, " (did you mean '%s'?)", near);
    for (size_t k = 0; k < t->ncol; k++) free(bases[k]);
    free(bases);
    lub_fatal_at(t->source, 0, 0, "no column '%s'%s; the columns are: %s", name, hint, list);
}

void lub_table_write_header(FILE *fp, const char *names)
{
    fprintf(fp, "# %s\n", names);
}

void lub_table_write_row(FILE *fp, const double *values, size_t n)
{
    for (size_t i = 0; i < n; i++) fprintf(fp, i ? " %.17g" : "%.17g", values[i]);
    fputc('\n', fp);
}

void lub_output_open(lub_output *o, const char *path)
{
    memset(o, 0, sizeof *o);
    if (!path || strcmp(path, "-") == 0) {
        o->fp = stdout;
        snprintf(o->path, sizeof o->path, "<stdout>");
        return;
    }
    lub_atomic_file f;
    /* a write that cannot happen (a read-only or full file system) is a failed run, exit 2,
     * as when lubFoam cannot write its tables */
    if (!lub_atomic_open(&f, path)) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
    o->fp = f.fp;
    o->atomic = 1;
    snprintf(o->path, sizeof o->path, "%s", f.path);
    snprintf(o->tmp, sizeof o->tmp, "%s", f.tmp);
}

void lub_output_close(lub_output *o)
{
    if (!o->fp) return;
    if (!o->atomic) {
        /* a full disk or a closed pipe shows up here, not at the fprintf calls */
        int bad = fflush(o->fp) != 0 || ferror(o->fp);
        o->fp = NULL;
        if (bad) lub_fatal_run("error writing to standard output: %s", strerror(errno));
        return;
    }
    lub_atomic_file f;
    f.fp = o->fp;
    snprintf(f.path, sizeof f.path, "%s", o->path);
    snprintf(f.tmp, sizeof f.tmp, "%s", o->tmp);
    f.sync_dir = 1;
    o->fp = NULL;
    if (lub_atomic_close(&f) != 0)
        lub_fatal_run("error writing '%s': %s", o->path, strerror(errno));
}
