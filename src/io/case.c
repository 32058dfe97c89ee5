/* lubkit case directory: paths, time folders, atomic output (see case.h). */
#include "io/case.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <math.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/args.h"
#include "core/error.h"

static void copy_path(char *dst, const char *src)
{
    size_t n = strlen(src);
    if (n >= LUB_PATH_MAX) lub_fatal("path too long: '%.80s...'", src);
    memcpy(dst, src, n + 1);
}

void lub_case_open(lub_case *c, const char *dir)
{
    struct stat st;
    if (dir && !*dir) lub_fatal("empty case directory name (the current directory is '.')");
    copy_path(c->root, dir ? dir : ".");
    size_t n = strlen(c->root);
    while (n > 1 && c->root[n - 1] == '/') c->root[--n] = '\0';
    if (stat(c->root, &st) != 0)
        lub_fatal("case directory '%s' does not exist (%s)", c->root, strerror(errno));
    if (!S_ISDIR(st.st_mode)) lub_fatal("case '%s' is not a directory", c->root);
}

char *lub_case_path(const lub_case *c, char *buf, const char *rel)
{
    int n = snprintf(buf, LUB_PATH_MAX, "%s/%s", c->root, rel);
    if (n < 0 || n >= LUB_PATH_MAX) lub_fatal("path too long under case '%s'", c->root);
    return buf;
}

char *lub_case_pathf(const lub_case *c, char *buf, const char *fmt, ...)
{
    char rel[LUB_PATH_MAX];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(rel, sizeof rel, fmt, ap);
    va_end(ap);
    if (n < 0 || n >= (int)sizeof rel) lub_fatal("path too long under case '%s'", c->root);
    return lub_case_path(c, buf, rel);
}

char *lub_time_name(double t, int precision, char *buf, size_t size)
{
    if (t == 0.0) t = 0.0; /* no "-0" folder */
    snprintf(buf, size, "%.*g", precision, t);
    return buf;
}

static int cmp_time(const void *a, const void *b)
{
    double x = ((const lub_time *)a)->value, y = ((const lub_time *)b)->value;
    return (x > y) - (x < y);
}

size_t lub_case_times(const lub_case *c, lub_time **times)
{
    DIR *d = opendir(c->root);
    if (!d) lub_fatal("cannot list case directory '%s': %s", c->root, strerror(errno));
    size_t n = 0, cap = 16;
    lub_time *t = lub_malloc(cap * sizeof *t);
    struct dirent *e;
    while ((e = readdir(d))) {
        double v;
        if (e->d_name[0] == '.' || lub_parse_real(e->d_name, &v)) continue;
        if (strlen(e->d_name) >= sizeof t->name) continue;
        char path[LUB_PATH_MAX];
        struct stat st;
        lub_case_path(c, path, e->d_name);
        if (stat(path, &st) != 0 || !S_ISDIR(st.st_mode)) continue;
        if (n == cap) t = lub_realloc(t, (cap *= 2) * sizeof *t);
        t[n].value = v;
        strcpy(t[n].name, e->d_name);
        n++;
    }
    closedir(d);
    qsort(t, n, sizeof *t, cmp_time);
    *times = t;
    return n;
}

/* Does value v match one item of a -time list?  Items: "a", "a:b", "a:", ":b".
 * A single value matches the folder whose value is equal within a relative 1e-9 (folder
 * names are rounded by timePrecision), ranges are inclusive with the same slack. */
static int parse_item(const char *item, double *lo, double *hi)
{
    char buf[128];
    if (strlen(item) >= sizeof buf) return -1;
    strcpy(buf, item);
    char *colon = strchr(buf, ':');
    if (!colon) {
        if (lub_parse_real(buf, lo)) return -1;
        *hi = *lo;
        return 0;
    }
    *colon = '\0';
    *lo = -INFINITY;
    *hi = INFINITY;
    if (*buf && lub_parse_real(buf, lo)) return -1;
    if (colon[1] && lub_parse_real(colon + 1, hi)) return -1;
    return 0;
}

size_t lub_case_filter_times(const lub_case *c, const char *list, int latest, int no_zero,
                             lub_time **times)
{
    lub_time *all;
    size_t n = lub_case_times(c, &all), m = 0;
    lub_time *sel = lub_malloc((n ? n : 1) * sizeof *sel);
    for (size_t i = 0; i < n; i++) {
        if (no_zero && all[i].value == 0.0) continue;
        int keep = 1;
        if (list) {
            keep = 0;
            char buf[1024];
            if (strlen(list) >= sizeof buf) lub_fatal("-time list too long");
            strcpy(buf, list);
            for (char *save = NULL, *it = strtok_r(buf, ",", &save); it;
                 it = strtok_r(NULL, ",", &save)) {
                double lo, hi;
                if (parse_item(it, &lo, &hi)) {
                    free(all);
                    free(sel);
                    lub_fatal("-time: '%s' is not a time or a range like 0.01:0.02", it);
                }
                double v = all[i].value, tol = 1e-9 * fmax(fabs(v), 1e-300);
                if (v >= lo - tol && v <= hi + tol) keep = 1;
            }
        }
        if (keep) sel[m++] = all[i];
    }
    if (latest && m > 1) {
        sel[0] = sel[m - 1];
        m = 1;
    }
    free(all);
    *times = sel;
    return m;
}

size_t lub_case_select_times(const lub_case *c, const char *list, int latest, int no_zero,
                             lub_time **times)
{
    lub_time *sel;
    size_t m = lub_case_filter_times(c, list, latest, no_zero, &sel);
    if (m == 0) {
        free(sel);
        lub_time *all;
        size_t n = lub_case_times(c, &all);
        char avail[512] = "";
        size_t len = 0;
        for (size_t i = 0; i < n && len < sizeof avail - 16; i++)
            len += (size_t)snprintf(avail + len, sizeof avail - len, "%s%s", i ? " " : "",
                                    all[i].name);
        free(all);
        if (n == 0) lub_fatal("no time folders in case '%s'", c->root);
        lub_fatal("no time folder of case '%s' matches the selection%s%s (available: %s)", c->root,
                  list ? " -time " : "", list ? list : "", avail);
    }
    *times = sel;
    return m;
}

int lub_mkdir_p(const char *path)
{
    char buf[LUB_PATH_MAX];
    size_t n = strlen(path);
    if (n >= sizeof buf) return -1;
    memcpy(buf, path, n + 1);
    for (char *p = buf + 1; *p; p++) {
        if (*p != '/') continue;
        *p = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
        *p = '/';
    }
    if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
    return 0;
}

int lub_fsync_dir(const char *dir)
{
    int fd = open(dir, O_RDONLY | O_DIRECTORY);
    if (fd < 0) return -1;
    int rc = fsync(fd);
    int e = errno;
    if (rc != 0 && e == EINVAL) rc = 0; /* a file system that cannot sync a directory */
    close(fd);
    errno = e;
    return rc;
}

int lub_rm_rf(const char *path)
{
    struct stat st;
    if (lstat(path, &st) != 0) return errno == ENOENT ? 0 : -1;
    if (!S_ISDIR(st.st_mode)) return unlink(path);
    DIR *d = opendir(path);
    if (!d) return -1;
    struct dirent *e;
    int rc = 0;
    while ((e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        char sub[LUB_PATH_MAX];
        if (snprintf(sub, sizeof sub, "%s/%s", path, e->d_name) >= (int)sizeof sub) {
            rc = -1;
            continue;
        }
        if (lub_rm_rf(sub) != 0) rc = -1;
    }
    closedir(d);
    if (rmdir(path) != 0) rc = -1;
    return rc;
}

void lub_timedir_begin(const lub_case *c, const char *name, char *dir)
{
    lub_case_pathf(c, dir, ".%s.tmp%ld", name, (long)getpid());
    lub_rm_rf(dir); /* leftover of a crashed run with the same pid */
    if (lub_mkdir_p(dir) != 0)
        lub_fatal_run("cannot create time folder '%s': %s", dir, strerror(errno));
}

/* fsync a folder and every folder below it (their entries: the files are synced). */
static int fsync_dirs(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return -1;
    struct dirent *e;
    int rc = 0;
    while ((e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        char sub[LUB_PATH_MAX];
        struct stat st;
        if (snprintf(sub, sizeof sub, "%s/%s", dir, e->d_name) >= (int)sizeof sub) continue;
        if (lstat(sub, &st) == 0 && S_ISDIR(st.st_mode) && fsync_dirs(sub) != 0) rc = -1;
    }
    closedir(d);
    if (lub_fsync_dir(dir) != 0) rc = -1;
    return rc;
}

void lub_timedir_commit(const lub_case *c, const char *name, const char *dir)
{
    char final[LUB_PATH_MAX], old[LUB_PATH_MAX];
    struct stat st;
    if (fsync_dirs(dir) != 0)
        lub_fatal_run("cannot sync time folder '%s': %s", dir, strerror(errno));
    lub_case_path(c, final, name);
    if (stat(final, &st) == 0) {
        /* keep the old folder until the new one is in place */
        lub_case_pathf(c, old, ".%s.old%ld", name, (long)getpid());
        lub_rm_rf(old);
        if (rename(final, old) != 0)
            lub_fatal_run("cannot replace time folder '%s': %s", final, strerror(errno));
        if (rename(dir, final) != 0) {
            rename(old, final);
            lub_fatal_run("cannot rename '%s' to '%s': %s", dir, final, strerror(errno));
        }
        if (lub_fsync_dir(c->root) != 0)
            lub_fatal_run("cannot sync case directory '%s': %s", c->root, strerror(errno));
        lub_rm_rf(old);
        return;
    }
    if (rename(dir, final) != 0)
        lub_fatal_run("cannot rename '%s' to '%s': %s", dir, final, strerror(errno));
    /* the rename is durable once the case directory is */
    if (lub_fsync_dir(c->root) != 0)
        lub_fatal_run("cannot sync case directory '%s': %s", c->root, strerror(errno));
}

FILE *lub_atomic_open(lub_atomic_file *f, const char *path)
{
    if (strlen(path) + 32 >= LUB_PATH_MAX) {
        errno = ENAMETOOLONG;
        return NULL;
    }
    strcpy(f->path, path);
    f->sync_dir = 1;
    /* Not a regular file (/dev/null, a FIFO, a terminal): written in place.  A rename would
     * replace the device by a regular file (reynoldsRef -o /dev/null did so, and every
     * program's output sent to /dev/null afterwards filled a file). */
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)) {
        f->tmp[0] = '\0';
        f->fp = fopen(path, "w");
        return f->fp;
    }
    snprintf(f->tmp, sizeof f->tmp, "%s.tmp%ld", path, (long)getpid());
    f->fp = fopen(f->tmp, "w");
    return f->fp;
}

int lub_atomic_close(lub_atomic_file *f)
{
    if (!f->fp) return -1;
    if (!f->tmp[0]) { /* written in place (not a regular file) */
        int bad = fflush(f->fp) != 0 || ferror(f->fp);
        int e = errno;
        if (fclose(f->fp) != 0 && !bad) {
            bad = 1;
            e = errno;
        }
        f->fp = NULL;
        errno = e ? e : EIO;
        return bad ? -1 : 0;
    }
    errno = 0;
    int bad = fflush(f->fp) != 0 || ferror(f->fp);
    if (!bad && fsync(fileno(f->fp)) != 0) bad = 1;
    int e = errno;
    if (fclose(f->fp) != 0 && !bad) {
        bad = 1;
        e = errno;
    }
    f->fp = NULL;
    if (!bad && rename(f->tmp, f->path) != 0) {
        bad = 1;
        e = errno;
    }
    if (bad) {
        unlink(f->tmp);
        errno = e ? e : EIO; /* the reason for the caller's message */
        return -1;
    }
    if (!f->sync_dir) return 0;
    /* the rename is durable once the directory is */
    char dir[LUB_PATH_MAX];
    snprintf(dir, sizeof dir, "%s", f->path);
    char *slash = strrchr(dir, '/');
    if (slash == dir)
        dir[1] = '\0';
    else if (slash)
        *slash = '\0';
    else
        strcpy(dir, ".");
    return lub_fsync_dir(dir);
}

void lub_atomic_abort(lub_atomic_file *f)
{
    if (f->fp) fclose(f->fp);
    f->fp = NULL;
    if (f->tmp[0]) unlink(f->tmp);
}

char *lub_postproc_path(const lub_case *c, const char *name, const char *time_name,
                        const char *file, char *buf)
{
    char dir[LUB_PATH_MAX];
    lub_case_pathf(c, dir, "postProcessing/%s/%s", name, time_name);
    if (lub_mkdir_p(dir) != 0) lub_fatal_run("cannot create '%s': %s", dir, strerror(errno));
    if (snprintf(buf, LUB_PATH_MAX, "%s/%s", dir, file) >= LUB_PATH_MAX)
        lub_fatal("path too long: '%s/%s'", dir, file);
    return buf;
}

/* name ends in <tag><pid> (".tmp123") of a process that is gone: 1, with the part before
 * the tag in base. */
static int stale_name(const char *name, const char *tag, char *base, size_t size)
{
    const char *at = NULL;
    for (const char *p = strstr(name, tag); p; p = strstr(p + 1, tag)) at = p;
    if (!at || at == name) return 0;
    const char *digits = at + strlen(tag);
    if (!*digits || strspn(digits, "0123456789") != strlen(digits) || strlen(digits) > 9) return 0;
    const long pid = atol(digits);
    if (pid <= 0) return 0;
    if (pid == (long)getpid() || kill((pid_t)pid, 0) == 0 || errno == EPERM) return 0;
    if ((size_t)(at - name) >= size) return 0;
    memcpy(base, name, (size_t)(at - name));
    base[at - name] = '\0';
    return 1;
}

/* The stale temporary files in dir (recursing depth levels into sub-folders). */
static size_t clean_files(const char *dir, int depth)
{
    DIR *d = opendir(dir);
    if (!d) return 0;
    size_t n = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        char path[LUB_PATH_MAX], base[256];
        if (snprintf(path, sizeof path, "%s/%s", dir, e->d_name) >= (int)sizeof path) continue;
        struct stat st;
        if (lstat(path, &st) != 0) continue;
        if (S_ISDIR(st.st_mode)) {
            if (depth > 0) n += clean_files(path, depth - 1);
        } else if (stale_name(e->d_name, ".tmp", base, sizeof base) && unlink(path) == 0) {
            lub_message("removed '%s', left by a run that was stopped while writing it", path);
            n++;
        }
    }
    closedir(d);
    return n;
}

size_t lub_case_clean(const lub_case *c)
{
    size_t n = 0;
    DIR *d = opendir(c->root);
    if (!d) return 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] != '.' || strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        char path[LUB_PATH_MAX], final[LUB_PATH_MAX], base[256];
        struct stat st;
        lub_case_path(c, path, e->d_name);
        if (lstat(path, &st) != 0 || !S_ISDIR(st.st_mode)) continue;
        if (stale_name(e->d_name + 1, ".tmp", base, sizeof base)) {
            /* a time folder never completed */
            if (lub_rm_rf(path) == 0) {
                lub_message("removed '%s', a time folder left incomplete by a run that was "
                            "stopped while writing it",
                            path);
                n++;
            }
        } else if (stale_name(e->d_name + 1, ".old", base, sizeof base)) {
            /* the copy of a time folder being replaced: the only one if the new one never
             * took its place */
            lub_case_path(c, final, base);
            if (stat(final, &st) != 0 && errno == ENOENT) {
                if (rename(path, final) == 0) {
                    lub_message("restored time folder '%s' from '%s' (a run was stopped while "
                                "replacing it)",
                                final, path);
                    n++;
                }
            } else if (lub_rm_rf(path) == 0) {
                lub_message("removed '%s', the old copy of '%s' left by a run that was stopped "
                            "while replacing it",
                            path, final);
                n++;
            }
        }
    }
    closedir(d);
    n += clean_files(c->root, 0); /* particles.xdmf.tmp<pid> */
    lub_time *t;
    size_t nt = lub_case_times(c, &t);
    for (size_t k = 0; k < nt; k++) {
        char dir[LUB_PATH_MAX];
        n += clean_files(lub_case_path(c, dir, t[k].name), 1);
    }
    free(t);
    char pp[LUB_PATH_MAX];
    n += clean_files(lub_case_path(c, pp, "postProcessing"), 3);
    return n;
}
