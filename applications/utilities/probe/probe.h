/* probe: sampling sets, their output, and the shared state of one probe run.
 *
 * A sampling set (a subcommand with its options, or an entry of system/probeDict.yaml) is a
 * probe_spec; probe_run() selects its times, samples every time folder with src/post and
 * hands each table to a probe_sink, which writes standard output, -o FILE, or
 * postProcessing/probe/<time>/<name>.dat.
 */
#ifndef PROBE_H
#define PROBE_H

#include <stddef.h>

#include "core/args.h"
#include "geometry/geometry.h"
#include "io/case.h"
#include "io/dict.h"
#include "io/table.h"
#include "models/elastic.h"
#include "models/multiResolution/levels.h"
#include "reynolds/refcase.h"

typedef enum {
    PROBE_WALL,
    PROBE_LINE,
    PROBE_POINTS,
    PROBE_FILM,
    PROBE_TOTALS,
    PROBE_SHAPE,
    PROBE_FRONT,
    PROBE_PARTICLES,
    PROBE_NKINDS
} probe_kind;

extern const char *const probe_kind_names[]; /* "wallPressure", ..., NULL */

/* One sampling set.  Reals that were not given are NAN. */
typedef struct {
    probe_kind kind;
    char name[64];     /* set name (file name of its output), or the subcommand */
    const char *patch; /* wallPressure, wallShape; totals: the load on this patch */
    char fields[1024]; /* comma-separated field list (default "p") */
    double from, to, bin;
    int arc;    /* wallPressure: against arc length */
    int facing; /* wallPressure: -1 (+1) only the wall particles facing down (up), 0 all */
    int has_z;  /* wallPressure, line, film (3-D): only the particles with z in [z0, z1] */
    double z0, z1;
    double *pts; /* points: npts x 3 (z = 0 in 2-D), owned */
    size_t npts;
    int pts_dim; /* coordinates given per point */
    int history; /* points: one point, one row per time '# t p n' */
    int average; /* average over [t0, t1] */
    double t0, t1;
    int dimensionless;
    /* where each setting came from, for messages: a dictionary entry, or NULL for options */
    const lub_node *node, *patch_node, *field_node, *at_node, *average_node, *history_node, *z_node;
} probe_spec;

void probe_spec_init(probe_spec *s, probe_kind kind, const char *name);
void probe_spec_free(probe_spec *s);

/* "x y; x y" (or "x,y;x,y"; 3 coordinates per point in 3-D) into s->pts; 0, or -1 with a
 * message in err. */
int probe_parse_points(probe_spec *s, const char *text, char *err, size_t errsize);
/* "T0:T1" with T0 <= T1; 0, or -1. */
int probe_parse_window(const char *text, double *t0, double *t1);

/* ---- output --------------------------------------------------------------------------- */

/* One table: a header, comment lines and rows, for one time (or a time average). */
typedef struct {
    char header[2048];
    char comments[1024]; /* lines without '#', separated by '\n' */
    int ncols;
    size_t nrows, cap;
    double *data;
} probe_block;

void probe_block_begin(probe_block *b, const char *header, int ncols);
void probe_block_row(probe_block *b, const double *row);
void probe_block_comment(probe_block *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
void probe_block_free(probe_block *b);

/* Where tables go. */
typedef struct {
    const lub_case *c;
    const char *path; /* -o FILE (NULL or "-": standard output); NULL with per_time */
    int per_time;     /* postProcessing/probe/<time>/<name>.dat, one file per block */
    int tcol;         /* single stream with several times: a leading t column */
    const char *name; /* set name (per_time) */
    lub_output out;
    int open, header_done;
    size_t files; /* files written (per_time) */
    char last_path[LUB_PATH_MAX];
} probe_sink;

void probe_sink_init(probe_sink *k, const lub_case *c, const char *path, int per_time,
                     const char *name);
/* Write a block for the time folder time_name (value t). */
void probe_sink_write(probe_sink *k, const probe_block *b, const char *time_name, double t);
void probe_sink_close(probe_sink *k);

/* ---- running -------------------------------------------------------------------------- */

/* State shared by the sets of one run: the case and lazily read dictionaries. */
typedef struct {
    lub_case c;
    const lub_args *a;
    int have_scales;
    lub_refscales scales;
    int geom_state; /* 0 not read, 1 read, -1 no particleGenDict.yaml */
    lub_geometry geom;
    int have_rho;
    double rho;
    int ew_state;     /* constant/models.yaml elasticWall: 0 not read, 1 read, -1 none */
    lub_dict *models; /* owns ew's nodes */
    lub_elastic_wall ew;
    int levels_state; /* constant/models.yaml multiResolution: 0 not read, 1 read, -1 none */
    lub_levels levels;
} probe_ctx;

void probe_ctx_free(probe_ctx *x);

/* Run one set: select its times, sample them, write through the sink (fatal on bad input). */
void probe_run(probe_ctx *x, probe_spec *s, probe_sink *k);

/* Fatal error about a setting: at its dictionary entry when it came from probeDict.yaml, else
 * a plain message naming the option. */
_Noreturn void probe_error(const lub_node *node, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* ---- system/probeDict.yaml ------------------------------------------------------------ */

typedef struct {
    lub_dict *dict;
    int n;
    probe_spec *sets;
} probe_sets;

/* Read every set strictly (lub_dict_finish); fatal when the file is missing. */
void probe_sets_read(probe_sets *S, const lub_case *c);
void probe_sets_free(probe_sets *S);
/* Index of a set by name; fatal listing the sets (with a suggestion) when absent. */
int probe_sets_find(const probe_sets *S, const char *name);

#endif
