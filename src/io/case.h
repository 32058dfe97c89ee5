/* lubkit case directory: paths, time folders, atomic output.
 *
 * Time folder names are the time printed with "%.*g" and timePrecision digits (default 6),
 * as OpenFOAM does.  Folders are written under a temporary name and renamed when complete.
 */
#ifndef LUB_IO_CASE_H
#define LUB_IO_CASE_H

#include <stdio.h>
#include <stddef.h>

#define LUB_PATH_MAX 4096

typedef struct {
    char root[LUB_PATH_MAX]; /* case directory as given (-case), without trailing slash */
} lub_case;

/* Open a case: fatal (exit 1) if the directory does not exist. */
void lub_case_open(lub_case *c, const char *dir);
/* "<root>/<rel>" into buf (size LUB_PATH_MAX); returns buf. */
char *lub_case_path(const lub_case *c, char *buf, const char *rel);
/* Same with printf-style relative path. */
char *lub_case_pathf(const lub_case *c, char *buf, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Time folder name: "%.*g" with precision digits. */
char *lub_time_name(double t, int precision, char *buf, size_t size);

/* A time folder found on disk. */
typedef struct {
    double value;
    char name[64];
} lub_time;

/* List the time folders of a case (directories whose whole name is a number), sorted by
 * value.  Returns the count; *times is allocated (free with free()). */
size_t lub_case_times(const lub_case *c, lub_time **times);

/* The time folders a selection keeps (see lub_case_select_times), possibly none; fatal
 * (exit 1) only when the list is malformed.  *times is allocated (free with free()). */
size_t lub_case_filter_times(const lub_case *c, const char *list, int latest, int no_zero,
                             lub_time **times);

/* Select times: list "0.01,0.02:0.03,0.05" (values and inclusive ranges, ":0.03" and
 * "0.02:" open), latest (only the last), no_zero (drop time 0).  Fatal (exit 1) when the
 * list is malformed or the selection is empty (the message lists what is available). */
size_t lub_case_select_times(const lub_case *c, const char *list, int latest, int no_zero,
                             lub_time **times);

/* Create directories along a path (mkdir -p).  0 on success. */
int lub_mkdir_p(const char *path);
/* Remove a directory tree.  0 on success. */
int lub_rm_rf(const char *path);

/* Atomic time folder: begin creates "<root>/.<name>.tmp<pid>" and returns its path in dir;
 * files are written inside; commit renames it to "<root>/<name>" (replacing an existing
 * folder of that name only after the new one is complete).  Fatal (exit 2) on I/O errors. */
void lub_timedir_begin(const lub_case *c, const char *name, char *dir);
void lub_timedir_commit(const lub_case *c, const char *name, const char *dir);

/* Atomic file: open writes "<path>.tmp<pid>", close flushes, fsyncs and renames over path.
 * lub_atomic_close returns 0 on success; on failure removes the temporary and returns -1. */
typedef struct {
    FILE *fp;
    char path[LUB_PATH_MAX], tmp[LUB_PATH_MAX];
} lub_atomic_file;
FILE *lub_atomic_open(lub_atomic_file *f, const char *path); /* NULL on failure (errno) */
int lub_atomic_close(lub_atomic_file *f);
void lub_atomic_abort(lub_atomic_file *f);

/* "postProcessing/<name>/<timeName>/" under the case, created; path of <file> into buf. */
char *lub_postproc_path(const lub_case *c, const char *name, const char *time_name,
                        const char *file, char *buf);

#endif
