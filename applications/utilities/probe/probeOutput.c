/* probe: tables and where they go (see probe.h).
 *
 * Files are written atomically (a temporary name renamed when complete, lub_output); if probe
 * stops on an error while a file is open, the temporary is removed at exit, so a failed run
 * never leaves a partial table behind.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"
#include "probe.h"

/* ---- blocks --------------------------------------------------------------------------- */

void probe_block_begin(probe_block *b, const char *header, int ncols)
{
    snprintf(b->header, sizeof b->header, "%s", header);
    b->comments[0] = '\0';
    b->ncols = ncols;
    b->nrows = 0;
}

void probe_block_row(probe_block *b, const double *row)
{
    if (b->nrows == b->cap) {
        b->cap = b->cap ? 2 * b->cap : 256;
        b->data = lub_realloc(b->data, b->cap * (size_t)b->ncols * sizeof *b->data);
    }
    memcpy(b->data + b->nrows * (size_t)b->ncols, row, (size_t)b->ncols * sizeof *row);
    b->nrows++;
}

void probe_block_comment(probe_block *b, const char *fmt, ...)
{
    size_t len = strlen(b->comments);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(b->comments + len, sizeof b->comments - len, fmt, ap);
    va_end(ap);
    len = strlen(b->comments);
    if (len + 1 < sizeof b->comments) strcat(b->comments, "\n");
}

void probe_block_free(probe_block *b)
{
    free(b->data);
    memset(b, 0, sizeof *b);
}

/* ---- sinks ---------------------------------------------------------------------------- */

/* The sink whose atomic file is open, for the exit handler. */
static probe_sink *pending = NULL;

static void remove_pending(void)
{
    if (!pending || !pending->open || !pending->out.atomic || !pending->out.fp) return;
    fclose(pending->out.fp);
    pending->out.fp = NULL;
    unlink(pending->out.tmp);
}

void probe_sink_init(probe_sink *k, const lub_case *c, const char *path, int per_time,
                     const char *name)
{
    static int registered = 0;
    if (!registered) atexit(remove_pending), registered = 1;
    memset(k, 0, sizeof *k);
    k->c = c;
    k->path = path;
    k->per_time = per_time;
    k->name = name;
}

static void write_comments(FILE *fp, const probe_block *b, const char *prefix)
{
    const char *s = b->comments;
    while (*s) {
        const char *e = strchr(s, '\n');
        size_t len = e ? (size_t)(e - s) : strlen(s);
        fprintf(fp, "# %s%.*s\n", prefix, (int)len, s);
        s += len + (e ? 1 : 0);
    }
}

static void write_rows(FILE *fp, const probe_block *b, int tcol, double t)
{
    double row[1 + 64];
    for (size_t r = 0; r < b->nrows; r++) {
        const double *v = b->data + r * (size_t)b->ncols;
        if (!tcol) {
            lub_table_write_row(fp, v, (size_t)b->ncols);
            continue;
        }
        row[0] = t;
        memcpy(row + 1, v, (size_t)b->ncols * sizeof *v);
        lub_table_write_row(fp, row, (size_t)b->ncols + 1);
    }
}

void probe_sink_write(probe_sink *k, const probe_block *b, const char *time_name, double t)
{
    if (b->ncols > 64) lub_bug("%d columns", b->ncols);
    if (k->per_time) {
        char file[96], path[LUB_PATH_MAX];
        snprintf(file, sizeof file, "%s.dat", k->name);
        lub_postproc_path(k->c, "probe", time_name, file, path);
        lub_output_open(&k->out, path);
        k->open = 1;
        pending = k;
        lub_table_write_header(k->out.fp, b->header);
        write_comments(k->out.fp, b, "");
        write_rows(k->out.fp, b, 0, 0.0);
        lub_output_close(&k->out);
        k->open = 0;
        pending = NULL;
        k->files++;
        snprintf(k->last_path, sizeof k->last_path, "postProcessing/probe/%s/%s", time_name, file);
        return;
    }
    if (!k->open) {
        lub_output_open(&k->out, k->path);
        k->open = 1;
        pending = k;
    }
    if (!k->header_done) {
        char h[sizeof b->header + 8];
        snprintf(h, sizeof h, "%s%s", k->tcol ? "t[s] " : "", b->header);
        lub_table_write_header(k->out.fp, h);
        k->header_done = 1;
    }
    char prefix[64] = "";
    if (k->tcol) snprintf(prefix, sizeof prefix, "t = %s: ", time_name);
    write_comments(k->out.fp, b, prefix);
    write_rows(k->out.fp, b, k->tcol, t);
}

void probe_sink_close(probe_sink *k)
{
    if (!k->open) return;
    lub_output_close(&k->out);
    k->open = 0;
    if (pending == k) pending = NULL;
}
