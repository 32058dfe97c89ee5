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
/* fsync a directory (after a rename into it: the rename is durable only then).  0 on
 * success, else -1 with errno. */
int lub_fsync_dir(const char *dir);
/* Remove a directory tree.  0 on success. */
int lub_rm_rf(const char *path);

/* Atomic time folder: begin creates "<root>/.<name>.tmp<pid>" and returns its path in dir;
 * files are written inside (each flushed to disk); commit flushes the folder and its
 * sub-folders, renames it to "<root>/<name>" (replacing an existing folder of that name only
 * after the new one is complete) and flushes the case directory.  Fatal (exit 2) on I/O
 * errors. */
void lub_timedir_begin(const lub_case *c, const char *name, char *dir);
void lub_timedir_commit(const lub_case *c, const char *name, const char *dir);

/* Remove what a program killed while writing (kill -9, a full disk) left in the case: the
 * temporary names of lub_timedir_begin/commit, lub_atomic_open and lub_particles_write,
 * which carry the writer's pid: hidden ".<time>.tmp<pid>" folders, "<file>.tmp<pid>" files
 * in the case, in its time folders (and their uniform/) and under postProcessing/.  A
 * ".<time>.old<pid>" folder is the previous copy of a time that was being replaced: it is
 * put back when the time folder is missing, else removed.  Only names whose process is gone
 * are touched (another program may be writing).  Each is reported (lub_message); returns
 * the count. */
size_t lub_case_clean(const lub_case *c);

/* Atomic file: open writes "<path>.tmp<pid>", close flushes, fsyncs and renames over path
 * (and fsyncs its directory).  A path that exists and is not a regular file (/dev/null, a
 * FIFO) is written in place: a rename would replace the device.  lub_atomic_close returns
 * 0 on success; on failure removes the temporary and returns -1 with errno. */
typedef struct {
    FILE *fp;
    char path[LUB_PATH_MAX], tmp[LUB_PATH_MAX];
    int sync_dir; /* 1 (set by open): fsync the directory after the rename; 0 for a file in
                     a temporary time folder, whose directories lub_timedir_commit syncs */
} lub_atomic_file;
FILE *lub_atomic_open(lub_atomic_file *f, const char *path); /* NULL on failure (errno) */
int lub_atomic_close(lub_atomic_file *f);
void lub_atomic_abort(lub_atomic_file *f);

/* "postProcessing/<name>/<timeName>/" under the case, created; path of <file> into buf. */
char *lub_postproc_path(const lub_case *c, const char *name, const char *time_name,
                        const char *file, char *buf);

#endif
