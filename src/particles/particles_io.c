/* lubkit particle files: HDF5 particles.h5 and XDMF descriptions (see particles_io.h).
 *
 * Error handling.  HDF5's automatic error printing is switched off around every use of the
 * library, and a failure is reported in our own words with the innermost HDF5 reason.  The
 * fatal error is raised only after every HDF5 handle and buffer has been released, because
 * lub_fatal may longjmp (unit tests) and the next test must find a clean library.  To make
 * that simple every helper closes what it opened before returning, and files are opened with
 * H5F_CLOSE_STRONG so that closing the file also closes anything a path forgot.
 */
#include "particles/particles_io.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <hdf5.h>

#include "core/error.h"

static const char *const standard_fields[] = {"position", "velocity", "pressure", "kind",
                                              "patch",    "level",    "id"};
enum { N_STANDARD = sizeof standard_fields / sizeof *standard_fields };

/* ------------------------------------------------------------------------------------------ */
/* Error context                                                                              */

typedef struct {
    char msg[1024]; /* first failure, our words (+ HDF5 reason) */
    int failed;
    H5E_auto2_t old_func; /* HDF5 automatic error printing, restored on exit */
    void *old_data;
    void *buf;     /* scratch buffer, freed on every exit when owned */
    int own_buf;   /* buf was allocated for this call (a writer's buffers are kept) */
    hid_t fapl;    /* file access property list */
    hid_t file;    /* the open file */
    int have_data; /* P holds storage that must be freed on failure */
    int mpi;       /* the file is open on every rank of MPI_COMM_WORLD (MPI-IO driver):
                      collective creation, this rank's rows by hyperslab */
    int sliced;    /* reading rows first .. first + count - 1 only (lub_particles_read_rows) */
    size_t first, count;
} h5ctx;

static void ctx_begin(h5ctx *c)
{
    /* No library shutdown at exit: after a damaged file HDF5 1.10 may fail to release its
     * internal state and print "infinite loop closing library" when the program exits.  Our
     * files are always closed explicitly, so the shutdown has nothing to flush.  Effective
     * only before the library is first used (else a harmless error, not reported). */
    static int once = 0;
    if (!once) {
        once = 1;
        H5dont_atexit();
    }
    memset(c, 0, sizeof *c);
    c->fapl = c->file = H5I_INVALID_HID;
    H5Eget_auto2(H5E_DEFAULT, &c->old_func, &c->old_data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

static int fail_h5(h5ctx *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Release everything; returns whether a failure was recorded. */
static int ctx_end(h5ctx *c)
{
    errno = 0;
    if (c->file >= 0 && H5Fclose(c->file) < 0 && !c->failed) {
        /* closing flushes what HDF5 held back: a full disk shows here; say why */
        const int e = errno;
        fail_h5(c, "cannot close the file%s%s", e ? ": " : "", e ? strerror(e) : "");
    }
    c->file = H5I_INVALID_HID;
    if (c->fapl >= 0) H5Pclose(c->fapl);
    c->fapl = H5I_INVALID_HID;
    if (c->own_buf) free(c->buf);
    c->buf = NULL;
    H5Eclear2(H5E_DEFAULT);
    H5Eset_auto2(H5E_DEFAULT, c->old_func, c->old_data);
    return c->failed;
}

typedef struct {
    char *buf;
    size_t size;
    int found;
} reason_walk;

/* H5Ewalk2 upward starts at the most specific entry: keep that one. */
static herr_t reason_cb(unsigned n, const H5E_error2_t *e, void *data)
{
    reason_walk *r = data;
    (void)n;
    if (!r->found && e->desc && e->desc[0]) {
        snprintf(r->buf, r->size, "%s", e->desc);
        for (char *q = r->buf; *q; q++) /* one line (HDF5's ctime() ends in a newline) */
            if (*q == '\n') *q = ' ';
        r->found = 1;
    }
    return 0;
}

static int vfail(h5ctx *c, int with_reason, const char *fmt, va_list ap)
{
    if (c->failed) return -1; /* keep the first failure */
    c->failed = 1;
    int n = vsnprintf(c->msg, sizeof c->msg, fmt, ap);
    if (n < 0) n = 0;
    if (n >= (int)sizeof c->msg) n = (int)sizeof c->msg - 1;
    if (with_reason) {
        char reason[512] = "";
        reason_walk r = {reason, sizeof reason, 0};
        H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, reason_cb, &r);
        H5Eclear2(H5E_DEFAULT);
        if (r.found) snprintf(c->msg + n, sizeof c->msg - (size_t)n, " (HDF5: %s)", reason);
    }
    return -1;
}

/* A failure of our own checks. */
static int fail(h5ctx *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int fail(h5ctx *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vfail(c, 0, fmt, ap);
    va_end(ap);
    return -1;
}

/* A failure of an HDF5 call: the message gets HDF5's innermost reason. */
static int fail_h5(h5ctx *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int fail_h5(h5ctx *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vfail(c, 1, fmt, ap);
    va_end(ap);
    return -1;
}

static void close_id(hid_t *id, herr_t (*closer)(hid_t))
{
    if (*id >= 0) closer(*id);
    *id = H5I_INVALID_HID;
}

/* File access: closing the file closes every object in it; files are written in the HDF5
 * 1.8 format, whose superblock and object headers carry checksums, so damaged metadata is
 * detected when read instead of being decoded (HDF5 1.10 can crash decoding corrupted
 * version-1 object headers).  Readable by every HDF5 since 1.8, ParaView's included. */
static hid_t file_access_plist(int writing)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (fapl < 0) return fapl;
    if (H5Pset_fclose_degree(fapl, H5F_CLOSE_STRONG) < 0 ||
        (writing && H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_V18) < 0)) {
        H5Pclose(fapl);
        return H5I_INVALID_HID;
    }
    return fapl;
}

/* ------------------------------------------------------------------------------------------ */
/* Writing                                                                                    */

static int write_attr(h5ctx *c, hid_t loc, const char *name, hid_t filetype, hid_t memtype,
                      const void *value)
{
    hid_t s = H5Screate(H5S_SCALAR), a = H5I_INVALID_HID;
    int rc = -1;
    if (s < 0) {
        fail_h5(c, "cannot create a dataspace");
        goto out;
    }
    a = H5Acreate2(loc, name, filetype, s, H5P_DEFAULT, H5P_DEFAULT);
    if (a < 0 || H5Awrite(a, memtype, value) < 0) {
        fail_h5(c, "cannot write attribute '%s'", name);
        goto out;
    }
    rc = 0;
out:
    close_id(&a, H5Aclose);
    close_id(&s, H5Sclose);
    return rc;
}

static int write_attr_string(h5ctx *c, hid_t loc, const char *name, const char *value)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    int rc = -1;
    if (t < 0 || H5Tset_size(t, strlen(value) + 1) < 0 || H5Tset_strpad(t, H5T_STR_NULLTERM) < 0)
        fail_h5(c, "cannot make a string type");
    else
        rc = write_attr(c, loc, name, t, t, value);
    close_id(&t, H5Tclose);
    return rc;
}

/* Rows per chunk of a dataset: HDF5's Fletcher32 checksum filter works on chunked
 * datasets only; 65536 rows (1.5 MB of positions) keep the chunk index small and a
 * chunk's checksum cheap. */
enum { CHUNK_ROWS = 65536 };

/* One dataset of n rows and ncols columns (ncols 1: rank 1), of which this process writes
 * rows first .. first + count - 1 from data (all of them serially; in a collective write,
 * c->mpi, every rank its own rows, possibly none, by a hyperslab).  Chunked with HDF5's
 * Fletcher32 checksum filter, so that a damaged byte in the data (a flipped bit on a disk,
 * a copy cut short) is found when it is read, not computed with: HDF5 verifies every
 * chunk's checksum on reading.  An empty dataset cannot be chunked and holds nothing to
 * check: contiguous. */
static int write_rows(h5ctx *c, hid_t g, const char *name, hid_t filetype, hid_t memtype, size_t n,
                      int ncols, size_t first, size_t count, const void *data)
{
    hsize_t dims[2] = {(hsize_t)n, (hsize_t)ncols};
    hsize_t chunk[2] = {(hsize_t)(n < CHUNK_ROWS ? n : CHUNK_ROWS), (hsize_t)ncols};
    hid_t s = H5Screate_simple(ncols > 1 ? 2 : 1, dims, NULL), d = H5I_INVALID_HID;
    hid_t dcpl = H5I_INVALID_HID, ms = H5I_INVALID_HID, dxpl = H5P_DEFAULT;
    int rc = -1;
    if (s < 0) {
        fail_h5(c, "cannot create the dataspace of '%s'", name);
        goto out;
    }
    if ((dcpl = H5Pcreate(H5P_DATASET_CREATE)) < 0 ||
        (n > 0 &&
         (H5Pset_chunk(dcpl, ncols > 1 ? 2 : 1, chunk) < 0 || H5Pset_fletcher32(dcpl) < 0))) {
        fail_h5(c, "cannot set up the checksum of dataset '%s'", name);
        goto out;
    }
    d = H5Dcreate2(g, name, filetype, s, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (d < 0) {
        fail_h5(c, "cannot create dataset '%s'", name);
        goto out;
    }
    if (n > 0 && c->mpi) {
#ifdef H5_HAVE_PARALLEL
        /* every rank takes part in the write (HDF5 writes filtered datasets collectively
         * only), each with its rows */
        hsize_t start[2] = {(hsize_t)first, 0}, cnt[2] = {(hsize_t)count, (hsize_t)ncols};
        const int rank = ncols > 1 ? 2 : 1;
        herr_t sel = -1;
        if ((ms = H5Screate_simple(rank, cnt, NULL)) >= 0)
            sel = count > 0 ? H5Sselect_hyperslab(s, H5S_SELECT_SET, start, NULL, cnt, NULL)
                  : H5Sselect_none(s) < 0 ? -1
                                          : H5Sselect_none(ms);
        if (sel < 0 || (dxpl = H5Pcreate(H5P_DATASET_XFER)) < 0 ||
            H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE) < 0 ||
            H5Dwrite(d, memtype, ms, s, dxpl, data) < 0) {
            fail_h5(c, "cannot write dataset '%s'", name);
            goto out;
        }
#else
        (void)first, (void)count;
        lub_bug("a collective write in a build with the serial HDF5");
#endif
    } else if (n > 0 && H5Dwrite(d, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
        fail_h5(c, "cannot write dataset '%s'", name);
        goto out;
    }
    rc = 0;
out:
    if (dxpl != H5P_DEFAULT) H5Pclose(dxpl);
    close_id(&ms, H5Sclose);
    close_id(&dcpl, H5Pclose);
    close_id(&d, H5Dclose);
    close_id(&s, H5Sclose);
    return rc;
}

/* The rows of this process: first .. first + count - 1 of n (serially all of them). */
typedef struct {
    size_t first, count, n;
    const uint64_t *place; /* collective: the solver's place of each row's particle (the
                              gathered order a parallel run's /solver/order names) */
    int write_order;       /* /solver/order is written (the solver's order is not the id's) */
} rows_t;

/* A per-particle dataset: this process's rows. */
static int write_dataset(h5ctx *c, hid_t g, const char *name, hid_t filetype, hid_t memtype,
                         const rows_t *rw, int ncols, const void *data)
{
    return write_rows(c, g, name, filetype, memtype, rw->n, ncols, rw->first, rw->count, data);
}

static hid_t make_group(h5ctx *c, hid_t loc, const char *name)
{
    hid_t g = H5Gcreate2(loc, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0) fail_h5(c, "cannot create group '%s'", name);
    return g;
}

/* The rows of a file are the particles in id order (rank[r].index is the particle of row
 * r): a reader that is not ours (meshio's time series, a script pairing two times row by
 * row) finds the same particle in the same row at every time where the set is the same,
 * whatever order the solver keeps them in. */
static void gather3(double *buf, double *const comp[3], const lub_particles_rank *rank, size_t n)
{
    for (size_t r = 0; r < n; r++)
        for (int d = 0; d < 3; d++) buf[3 * r + d] = comp[d][rank[r].index];
}

static void gather_f64(double *buf, const double *v, const lub_particles_rank *rank, size_t n)
{
    for (size_t r = 0; r < n; r++) buf[r] = v[rank[r].index];
}

static void gather_u8(uint8_t *buf, const uint8_t *v, const lub_particles_rank *rank, size_t n)
{
    for (size_t r = 0; r < n; r++) buf[r] = v[rank[r].index];
}

static void gather_u16(uint16_t *buf, const uint16_t *v, const lub_particles_rank *rank, size_t n)
{
    for (size_t r = 0; r < n; r++) buf[r] = v[rank[r].index];
}

static void gather_u64(uint64_t *buf, const uint64_t *v, const lub_particles_rank *rank, size_t n)
{
    for (size_t r = 0; r < n; r++) buf[r] = v[rank[r].index];
}

/* Every rank of a collective write makes the same calls (HDF5 creates objects and writes
 * attributes collectively, with the same values on every rank). */
static int write_contents(h5ctx *c, const lub_particles *P, const lub_particles_rank *rank,
                          const rows_t *rw)
{
    hid_t f = c->file, g = H5I_INVALID_HID, t = H5I_INVALID_HID;
    int64_t step = P->step;
    int rc = -1;
    if (write_attr_string(c, f, "format", LUB_PARTICLES_FORMAT) ||
        write_attr(c, f, "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &P->time) ||
        write_attr(c, f, "step", H5T_STD_I64LE, H5T_NATIVE_INT64, &step) ||
        write_attr(c, f, "dimension", H5T_STD_I32LE, H5T_NATIVE_INT, &P->dim) ||
        write_attr(c, f, "nLevels", H5T_STD_I32LE, H5T_NATIVE_INT, &P->nlevels))
        goto out;

    for (int k = 0; k < P->nlevels; k++) {
        char name[32];
        const lub_level *L = &P->levels[k];
        snprintf(name, sizeof name, "level%d", k);
        if ((g = make_group(c, f, name)) < 0 ||
            write_attr(c, g, "l0", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &L->l0) ||
            write_attr(c, g, "re", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &L->re) ||
            write_attr(c, g, "n0", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &L->n0) ||
            write_attr(c, g, "lambda0", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &L->lambda0))
            goto out;
        close_id(&g, H5Gclose);
    }

    /* Patch names: fixed-length strings, simple to read back and to validate. */
    t = H5Tcopy(H5T_C_S1);
    if (t < 0 || H5Tset_size(t, LUB_NAME_MAX) < 0 || H5Tset_strpad(t, H5T_STR_NULLTERM) < 0) {
        fail_h5(c, "cannot make a string type");
        goto out;
    }
    /* (a collective write: rank 0's copy, the same on every rank) */
    const size_t np = (size_t)P->npatches;
    if (write_rows(c, f, "patches", t, t, np, 1, 0, c->mpi && rw->first > 0 ? 0 : np,
                   P->patch_names))
        goto out;

    if ((g = make_group(c, f, "fields")) < 0) goto out;
    const size_t n = rw->count;
    double *buf = c->buf;
    gather3(buf, P->x, rank, n);
    if (write_dataset(c, g, "position", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, rw, 3, buf)) goto out;
    gather3(buf, P->u, rank, n);
    if (write_dataset(c, g, "velocity", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, rw, 3, buf)) goto out;
    gather_f64(buf, P->p, rank, n);
    if (write_dataset(c, g, "pressure", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, rw, 1, buf)) goto out;
    gather_u8(c->buf, P->kind, rank, n);
    if (write_dataset(c, g, "kind", H5T_STD_U8LE, H5T_NATIVE_UINT8, rw, 1, c->buf)) goto out;
    gather_u16(c->buf, P->patch, rank, n);
    if (write_dataset(c, g, "patch", H5T_STD_U16LE, H5T_NATIVE_UINT16, rw, 1, c->buf)) goto out;
    gather_u8(c->buf, P->level, rank, n);
    if (write_dataset(c, g, "level", H5T_STD_U8LE, H5T_NATIVE_UINT8, rw, 1, c->buf)) goto out;
    gather_u64(c->buf, P->id, rank, n);
    if (write_dataset(c, g, "id", H5T_STD_U64LE, H5T_NATIVE_UINT64, rw, 1, c->buf)) goto out;
    for (int e = 0; e < P->nextra; e++) {
        gather_f64(buf, P->extra[e].v, rank, n);
        if (write_dataset(c, g, P->extra[e].name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, rw, 1, buf))
            goto out;
    }
    close_id(&g, H5Gclose);

    /* The solver's own order, when it is not the id order: /solver/order[r] is the place in
     * the solver's arrays of the particle of row r.  The reader puts every particle back in
     * its place, so a restart continues with the very arrays the run had (its sums in the
     * same order: bit-identical to the run that was not stopped). */
    if (rw->write_order) {
        if ((g = make_group(c, f, "solver")) < 0) goto out;
        if (rw->n <= UINT32_MAX) {
            uint32_t *v = c->buf;
            for (size_t r = 0; r < n; r++)
                v[r] = (uint32_t)(rw->place ? rw->place[r] : rank[r].index);
            if (write_dataset(c, g, "order", H5T_STD_U32LE, H5T_NATIVE_UINT32, rw, 1, v)) goto out;
        } else {
            uint64_t *v = c->buf;
            for (size_t r = 0; r < n; r++) v[r] = rw->place ? rw->place[r] : rank[r].index;
            if (write_dataset(c, g, "order", H5T_STD_U64LE, H5T_NATIVE_UINT64, rw, 1, v)) goto out;
        }
        close_id(&g, H5Gclose);
    }

    /* Vertex connectivity 0 .. N-1 for the XDMF Polyvertex topology: ParaView's Xdmf3
     * readers make no cells without it, and points without cells do not show in the Points
     * representation.  4 bytes per particle (8 beyond 2^32 particles). */
    if ((g = make_group(c, f, "xdmf")) < 0) goto out;
    if (rw->n <= UINT32_MAX) {
        uint32_t *v = c->buf;
        for (size_t i = 0; i < n; i++) v[i] = (uint32_t)(rw->first + i);
        if (write_dataset(c, g, "connectivity", H5T_STD_U32LE, H5T_NATIVE_UINT32, rw, 1, v))
            goto out;
    } else {
        int64_t *v = c->buf;
        for (size_t i = 0; i < n; i++) v[i] = (int64_t)(rw->first + i);
        if (write_dataset(c, g, "connectivity", H5T_STD_I64LE, H5T_NATIVE_INT64, rw, 1, v))
            goto out;
    }
    rc = 0;
out:
    close_id(&t, H5Tclose);
    close_id(&g, H5Gclose);
    return rc;
}

static void check_writable(const lub_particles *P)
{
    if (P->dim != 2 && P->dim != 3) lub_bug("dimension %d", P->dim);
    if (P->nlevels < 1 || P->nlevels > LUB_MAX_LEVELS) lub_bug("nlevels %d", P->nlevels);
    if (P->npatches < 0 || P->npatches > LUB_MAX_PATCHES) lub_bug("npatches %d", P->npatches);
    if (P->nextra < 0 || P->nextra > LUB_MAX_EXTRA) lub_bug("nextra %d", P->nextra);
    if (P->n > P->cap) lub_bug("n %zu > capacity %zu", P->n, P->cap);
    if (!(P->time >= 0) || !isfinite(P->time)) lub_bug("time %g", P->time);
    /* What the reader rejects is never written: a bad kind, patch or level is a bug; a
     * non-finite value is a failed run (the caller writes the last good state). */
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] > LUB_DUMMY) lub_bug("particle %zu has kind %d", i, P->kind[i]);
        if (P->level[i] >= P->nlevels)
            lub_bug("particle %zu has level %d, nlevels %d", i, P->level[i], P->nlevels);
        if (P->patch[i] >= P->npatches && !(P->kind[i] == LUB_FLUID && P->patch[i] == 0))
            lub_bug("particle %zu has patch %d, npatches %d", i, P->patch[i], P->npatches);
        int finite = isfinite(P->p[i]);
        for (int d = 0; d < 3; d++) finite = finite && isfinite(P->x[d][i]) && isfinite(P->u[d][i]);
        for (int e = 0; e < P->nextra; e++) finite = finite && isfinite(P->extra[e].v[i]);
        if (!finite)
            lub_fatal_run("particle %zu (id %llu) has a non-finite position, velocity, pressure "
                          "or %s; particles at time %g not written",
                          i, (unsigned long long)P->id[i], P->nextra ? "extra field" : "field",
                          P->time);
        if (P->dim == 2 && P->x[2][i] != 0.0)
            lub_bug("particle %zu has z = %g in 2-D", i, P->x[2][i]);
    }
}

static int cmp_rank(const void *a, const void *b)
{
    const lub_particles_rank *x = a, *y = b;
    return (x->id > y->id) - (x->id < y->id);
}

void lub_particles_writer_init(lub_particles_writer *w, size_t cap)
{
    w->cap = cap;
    w->buf = lub_malloc(3 * (cap ? cap : 1) * sizeof *w->buf);
    w->rank = lub_malloc((cap ? cap : 1) * sizeof *w->rank);
    w->sync_dir = 1;
}

void lub_particles_writer_free(lub_particles_writer *w)
{
    free(w->buf);
    free(w->rank);
    w->buf = NULL;
    w->rank = NULL;
    w->cap = 0;
}

/* Flush the directory holding path: a rename is durable only once its directory is. */
static int sync_parent(const char *path)
{
    char dir[LUB_PATH_MAX];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash == dir)
        dir[1] = '\0';
    else if (slash)
        *slash = '\0';
    else
        strcpy(dir, ".");
    return lub_fsync_dir(dir);
}

/* The written file tmp made visible as path: flushed to disk before the rename, and the
 * folder after it (sync_dir); a failure is recorded in c. */
static void publish(h5ctx *c, const char *tmp, const char *path, int sync_dir)
{
    int fd = open(tmp, O_RDONLY);
    if (fd < 0 || fsync(fd) != 0) fail(c, "cannot sync '%s': %s", tmp, strerror(errno));
    if (fd >= 0) close(fd);
    if (!c->failed && rename(tmp, path) != 0)
        fail(c, "cannot rename '%s': %s", tmp, strerror(errno));
    if (!c->failed && sync_dir && sync_parent(path) != 0)
        fail(c, "cannot sync the folder of '%s': %s", path, strerror(errno));
}

static void write_sidecar(const lub_particles *P, size_t n, const char *dir, int sync_dir);

void lub_particles_writer_write(lub_particles_writer *w, const lub_particles *P, const char *dir)
{
    char path[LUB_PATH_MAX], tmp[LUB_PATH_MAX];
    if (snprintf(path, sizeof path, "%s/particles.h5", dir) >= (int)sizeof path ||
        snprintf(tmp, sizeof tmp, "%s/particles.h5.tmp%ld", dir, (long)getpid()) >= (int)sizeof tmp)
        lub_fatal_run("path too long: '%s/particles.h5'", dir);
    check_writable(P);
    if (P->n > w->cap) lub_bug("%zu particles, the writer has room for %zu", P->n, w->cap);
    /* id order (see gather3): a sort of (id, index) pairs in the writer's buffer */
    for (size_t i = 0; i < P->n; i++) {
        w->rank[i].id = P->id[i];
        w->rank[i].index = i;
    }
    qsort(w->rank, P->n, sizeof *w->rank, cmp_rank);
    for (size_t r = 1; r < P->n; r++)
        if (w->rank[r].id == w->rank[r - 1].id)
            lub_bug("particles %zu and %zu have the same id %llu", w->rank[r - 1].index,
                    w->rank[r].index, (unsigned long long)w->rank[r].id);

    rows_t rw = {0, P->n, P->n, NULL, 0};
    for (size_t r = 0; r < P->n && !rw.write_order; r++) rw.write_order = w->rank[r].index != r;

    h5ctx c;
    ctx_begin(&c);
    c.buf = w->buf;
    if ((c.fapl = file_access_plist(1)) < 0)
        fail_h5(&c, "cannot make a file access property list");
    else if ((c.file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, c.fapl)) < 0)
        fail_h5(&c, "cannot create '%s'", tmp);
    else
        write_contents(&c, P, w->rank, &rw);
    if (!ctx_end(&c)) {
        publish(&c, tmp, path, w->sync_dir);
    }
    if (c.failed) {
        unlink(tmp);
        lub_fatal_run("%s: cannot write particle file: %s", path, c.msg);
    }
    write_sidecar(P, P->n, dir, w->sync_dir);
}

/* Raise a caught fatal error again, with its status. */
static _Noreturn void fatal_status(int status, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static _Noreturn void fatal_status(int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    lub_vfatal_at(status, NULL, 0, 0, fmt, ap);
}

void lub_particles_write(const lub_particles *P, const char *dir)
{
    lub_particles_writer w;
    lub_particles_writer_init(&w, P->n); /* before HDF5 is used: lub_malloc may be fatal */
    lub_catcher c;
    if (lub_error_catch(&c) == 0) {
        lub_particles_writer_write(&w, P, dir);
        lub_error_uncatch();
        lub_particles_writer_free(&w);
    } else {
        lub_particles_writer_free(&w);
        fatal_status(c.status, "%s", c.message);
    }
}

/* ---- collective: every rank its rows (lubFoam -parallel, a build with Open MPI's HDF5) -- */

#ifdef H5_HAVE_PARALLEL

int lub_particles_collective(void)
{
    return 1;
}

void lub_particles_writer_write_rows(lub_particles_writer *w, const lub_particles *P,
                                     const uint64_t *place, size_t first, size_t n, const char *dir)
{
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    /* one temporary name for all ranks: rank 0's pid */
    long pid = (long)getpid();
    MPI_Bcast(&pid, 1, MPI_LONG, 0, MPI_COMM_WORLD);
    char path[LUB_PATH_MAX], tmp[LUB_PATH_MAX];
    if (snprintf(path, sizeof path, "%s/particles.h5", dir) >= (int)sizeof path ||
        snprintf(tmp, sizeof tmp, "%s/particles.h5.tmp%ld", dir, pid) >= (int)sizeof tmp)
        lub_fatal_run("path too long: '%s/particles.h5'", dir);
    check_writable(P);
    if (P->n > w->cap) lub_bug("%zu rows, the writer has room for %zu", P->n, w->cap);
    if (first + P->n > n) lub_bug("rows %zu + %zu of %zu", first, P->n, n);
    /* the rows are in id order already: the writer's map is the identity */
    int same = 1;
    for (size_t r = 0; r < P->n; r++) {
        if (r > 0 && P->id[r] <= P->id[r - 1])
            lub_bug("row %zu: id %llu after id %llu (rows not in id order)", first + r,
                    (unsigned long long)P->id[r], (unsigned long long)P->id[r - 1]);
        w->rank[r].id = P->id[r];
        w->rank[r].index = r;
        same = same && place[r] == first + r;
    }
    int all_same = same;
    MPI_Allreduce(&same, &all_same, 1, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
    rows_t rw = {first, P->n, n, place, !all_same};

    h5ctx c;
    ctx_begin(&c);
    c.buf = w->buf;
    c.mpi = 1;
    if ((c.fapl = file_access_plist(1)) < 0 ||
        H5Pset_fapl_mpio(c.fapl, MPI_COMM_WORLD, MPI_INFO_NULL) < 0)
        fail_h5(&c, "cannot make a file access property list for MPI-IO");
    else if ((c.file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, c.fapl)) < 0)
        fail_h5(&c, "cannot create '%s'", tmp);
    else
        write_contents(&c, P, w->rank, &rw);
    ctx_end(&c); /* the collective close: every rank's rows are in the file after it */
    int failed = c.failed, any = failed;
    MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (rank == 0 && !any) publish(&c, tmp, path, w->sync_dir);
    if (any && rank == 0) unlink(tmp);
    if (c.failed) lub_fatal_run("%s: cannot write particle file: %s", path, c.msg);
    if (any) /* the failing rank's message ends the run: this one waits for it */
        lub_fatal_run("%s: cannot write particle file: another rank failed (its message "
                      "names the reason)",
                      path);
    if (rank == 0) write_sidecar(P, n, dir, w->sync_dir);
}

#else

int lub_particles_collective(void)
{
    return 0;
}

void lub_particles_writer_write_rows(lub_particles_writer *w, const lub_particles *P,
                                     const uint64_t *place, size_t first, size_t n, const char *dir)
{
    (void)w, (void)P, (void)place, (void)first, (void)n, (void)dir;
    lub_bug("a collective write in a build with the serial HDF5 (make HDF5=mpi)");
}

#endif

/* ------------------------------------------------------------------------------------------ */
/* Reading                                                                                    */

/* Read a scalar numeric attribute of object objname (for messages) into memtype. */
static int read_attr_num(h5ctx *c, hid_t loc, const char *objname, const char *name, hid_t memtype,
                         int integer_only, void *value)
{
    hid_t a = H5I_INVALID_HID, s = H5I_INVALID_HID, t = H5I_INVALID_HID;
    int rc = -1;
    htri_t ex = H5Aexists(loc, name);
    if (ex < 0) {
        fail_h5(c, "cannot read the attributes of %s", objname);
        goto out;
    }
    if (ex == 0) {
        fail(c, "attribute '%s' missing in %s", name, objname);
        goto out;
    }
    if ((a = H5Aopen(loc, name, H5P_DEFAULT)) < 0 || (s = H5Aget_space(a)) < 0 ||
        (t = H5Aget_type(a)) < 0) {
        fail_h5(c, "cannot open attribute '%s' of %s", name, objname);
        goto out;
    }
    H5T_class_t cls = H5Tget_class(t);
    if (H5Sget_simple_extent_npoints(s) != 1) {
        fail(c, "attribute '%s' of %s must be a single value", name, objname);
        goto out;
    }
    if (cls != H5T_INTEGER && (integer_only || cls != H5T_FLOAT)) {
        fail(c, "attribute '%s' of %s must be %s", name, objname,
             integer_only ? "an integer" : "a number");
        goto out;
    }
    if (H5Aread(a, memtype, value) < 0) {
        fail_h5(c, "cannot read attribute '%s' of %s", name, objname);
        goto out;
    }
    rc = 0;
out:
    close_id(&t, H5Tclose);
    close_id(&s, H5Sclose);
    close_id(&a, H5Aclose);
    return rc;
}

static int read_attr_double(h5ctx *c, hid_t loc, const char *objname, const char *name, double *v)
{
    if (read_attr_num(c, loc, objname, name, H5T_NATIVE_DOUBLE, 0, v)) return -1;
    if (!isfinite(*v)) return fail(c, "attribute '%s' of %s is not finite", name, objname);
    return 0;
}

/* The format attribute: returns 0 when it is ours.  A file without it, or with another
 * value, is "not a lubkit particle file". */
static int check_format(h5ctx *c, hid_t f)
{
    hid_t a = H5I_INVALID_HID, t = H5I_INVALID_HID, m = H5I_INVALID_HID;
    hid_t s = H5I_INVALID_HID;
    char value[128] = "";
    int rc = -1;
    htri_t ex = H5Aexists(f, "format");
    if (ex < 0) {
        fail_h5(c, "cannot read the root attributes");
        goto out;
    }
    if (ex == 0) {
        fail(c, "not a lubkit particle file (format attribute missing)");
        goto out;
    }
    if ((a = H5Aopen(f, "format", H5P_DEFAULT)) < 0 || (t = H5Aget_type(a)) < 0 ||
        (s = H5Aget_space(a)) < 0) {
        fail_h5(c, "cannot open the format attribute");
        goto out;
    }
    if (H5Tget_class(t) != H5T_STRING || H5Sget_simple_extent_npoints(s) != 1) {
        fail(c, "not a lubkit particle file (format attribute is not a string)");
        goto out;
    }
    if (H5Tis_variable_str(t) > 0) {
        char *v = NULL;
        if ((m = H5Tcopy(H5T_C_S1)) < 0 || H5Tset_size(m, H5T_VARIABLE) < 0 ||
            H5Aread(a, m, &v) < 0) {
            fail_h5(c, "cannot read the format attribute");
            goto out;
        }
        snprintf(value, sizeof value, "%s", v ? v : "");
        H5free_memory(v);
    } else {
        size_t size = H5Tget_size(t);
        if (size == 0 || size >= sizeof value) {
            fail(c, "not a lubkit particle file (format attribute of %zu characters)", size);
            goto out;
        }
        /* One byte more than stored, null-terminated: whatever the file's padding. */
        if ((m = H5Tcopy(H5T_C_S1)) < 0 || H5Tset_size(m, size + 1) < 0 ||
            H5Tset_strpad(m, H5T_STR_NULLTERM) < 0 || H5Aread(a, m, value) < 0) {
            fail_h5(c, "cannot read the format attribute");
            goto out;
        }
    }
    if (strcmp(value, LUB_PARTICLES_FORMAT) != 0) {
        fail(c, "not a lubkit particle file (format attribute is '%.64s', expected '%s')", value,
             LUB_PARTICLES_FORMAT);
        goto out;
    }
    rc = 0;
out:
    close_id(&m, H5Tclose);
    close_id(&s, H5Sclose);
    close_id(&t, H5Tclose);
    close_id(&a, H5Aclose);
    return rc;
}

/* 1 if the dataset's storage may hold less than its values (a compression filter). */
static int compressed(hid_t d)
{
    hid_t dcpl = H5Dget_create_plist(d);
    if (dcpl < 0) return 1;
    int nf = H5Pget_nfilters(dcpl), packed = 0;
    for (int k = 0; k < nf; k++) {
        unsigned flags, conf;
        size_t nv = 0;
        H5Z_filter_t id = H5Pget_filter2(dcpl, (unsigned)k, &flags, &nv, NULL, 0, NULL, &conf);
        if (id != H5Z_FILTER_FLETCHER32 && id != H5Z_FILTER_SHUFFLE) packed = 1;
    }
    H5Pclose(dcpl);
    return packed;
}

/* The bytes the dataset declares must be in the file: its allocated storage (at least the
 * values, uncompressed), within the file's size. */
static int check_storage(h5ctx *c, hid_t d, hid_t t, const char *gname, const char *name,
                         const hsize_t *dims, int rank)
{
    double values = 1;
    for (int k = 0; k < rank; k++) values *= (double)dims[k];
    const double need = values * (double)H5Tget_size(t);
    const double have = (double)H5Dget_storage_size(d);
    /* deflate packs at most about 1000 to 1 */
    const double room = compressed(d) ? 1100 * have : have;
    if (need > room)
        return fail(c,
                    "%s/%s declares %.0f values (%.4g bytes) but the file holds %.4g bytes of "
                    "it: damaged or cut short",
                    gname, name, values, need, have);
    return 0;
}

/* Open dataset <gname>/<name>, check its class and shape (n_expected rows, or any when
 * *n is (size_t)-1 on entry, then set; ncols 1 for rank 1).  Returns the open dataset. */
static hid_t open_dataset(h5ctx *c, hid_t g, const char *gname, const char *name, int ncols,
                          size_t *n, int want_float, int want_int)
{
    hid_t d = H5I_INVALID_HID, s = H5I_INVALID_HID, t = H5I_INVALID_HID;
    htri_t ex = H5Lexists(g, name, H5P_DEFAULT);
    if (ex < 0) {
        fail_h5(c, "cannot look up %s/%s", gname, name);
        goto bad;
    }
    if (ex == 0) {
        fail(c, "dataset %s/%s missing", gname, name);
        goto bad;
    }
    if ((d = H5Dopen2(g, name, H5P_DEFAULT)) < 0) {
        fail_h5(c, "%s/%s is not a readable dataset", gname, name);
        goto bad;
    }
    if ((s = H5Dget_space(d)) < 0 || (t = H5Dget_type(d)) < 0) {
        fail_h5(c, "cannot read the shape of %s/%s", gname, name);
        goto bad;
    }
    int rank = H5Sget_simple_extent_ndims(s);
    hsize_t dims[H5S_MAX_RANK];
    if (rank < 0 || H5Sget_simple_extent_dims(s, dims, NULL) < 0) {
        fail_h5(c, "cannot read the shape of %s/%s", gname, name);
        goto bad;
    }
    int want_rank = ncols > 1 ? 2 : 1;
    if (rank != want_rank || (ncols > 1 && dims[1] != (hsize_t)ncols)) {
        char shape[128] = "", *q = shape;
        for (int k = 0; k < rank && q < shape + sizeof shape - 24; k++)
            q += sprintf(q, "%s%llu", k ? " x " : "", (unsigned long long)dims[k]);
        if (rank == 0) strcpy(shape, "scalar");
        if (ncols > 1)
            fail(c, "%s/%s has shape %s, expected N x %d", gname, name, shape, ncols);
        else
            fail(c, "%s/%s has shape %s, expected N (one value per particle)", gname, name, shape);
        goto bad;
    }
    if (*n == (size_t)-1)
        *n = (size_t)dims[0];
    else if (dims[0] != (hsize_t)*n) {
        fail(c, "%s/%s has %llu rows, expected %zu (the number of particles in position)", gname,
             name, (unsigned long long)dims[0], *n);
        goto bad;
    }
    /* Sizes against the file before anything is allocated for them: a damaged or forged
     * header may declare 10^10 rows that the file does not hold. */
    if (check_storage(c, d, t, gname, name, dims, rank)) goto bad;
    H5T_class_t cls = H5Tget_class(t);
    int ok = (want_float && cls == H5T_FLOAT) || (want_int && cls == H5T_INTEGER);
    if (!ok) {
        fail(c, "%s/%s must hold %s", gname, name,
             want_float && want_int ? "numbers"
             : want_float           ? "floating-point numbers"
                                    : "integers");
        goto bad;
    }
    close_id(&t, H5Tclose);
    close_id(&s, H5Sclose);
    return d;
bad:
    close_id(&t, H5Tclose);
    close_id(&s, H5Sclose);
    close_id(&d, H5Dclose);
    return H5I_INVALID_HID;
}

/* Read a whole checked dataset into buf with memory type memtype. */
static int read_dataset(h5ctx *c, hid_t g, const char *gname, const char *name, int ncols, size_t n,
                        int want_float, int want_int, hid_t memtype, void *buf)
{
    size_t rows = n;
    hid_t d = open_dataset(c, g, gname, name, ncols, &rows, want_float, want_int);
    if (d < 0) return -1;
    int rc = 0;
    if (c->sliced) { /* this process's rows: a hyperslab of the file's */
        hid_t fs = H5Dget_space(d), ms = H5I_INVALID_HID;
        hsize_t start[2] = {(hsize_t)c->first, 0}, cnt[2] = {(hsize_t)c->count, (hsize_t)ncols};
        if (c->count > 0 && (fs < 0 || (ms = H5Screate_simple(ncols > 1 ? 2 : 1, cnt, NULL)) < 0 ||
                             H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, cnt, NULL) < 0 ||
                             H5Dread(d, memtype, ms, fs, H5P_DEFAULT, buf) < 0))
            rc = fail_h5(c, "cannot read %s/%s: the file is damaged or unreadable", gname, name);
        close_id(&ms, H5Sclose);
        close_id(&fs, H5Sclose);
    } else if (n > 0 && H5Dread(d, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0)
        rc = fail_h5(c, "cannot read %s/%s: the file is damaged or unreadable", gname, name);
    H5Dclose(d);
    return rc;
}

static int is_standard(const char *name)
{
    for (int k = 0; k < N_STANDARD; k++)
        if (strcmp(name, standard_fields[k]) == 0) return 1;
    return 0;
}

/* A name that lub_particles_extra accepts and that is safe in XML attributes. */
static int name_ok(const char *s)
{
    size_t len = strlen(s);
    if (len == 0 || len >= LUB_NAME_MAX) return 0;
    for (; *s; s++)
        if (*s == '/' || *s == '<' || *s == '>' || *s == '&' || *s == '"' || *s == '\'' ||
            (unsigned char)*s < 32)
            return 0;
    return 1;
}

/* Header: format, root attributes, levels and patches (into P, not yet initialised). */
static int read_header(h5ctx *c, hid_t f, lub_particles *P)
{
    int64_t step;
    if (check_format(c, f) || read_attr_double(c, f, "/", "time", &P->time) ||
        read_attr_num(c, f, "/", "step", H5T_NATIVE_INT64, 1, &step) ||
        read_attr_num(c, f, "/", "dimension", H5T_NATIVE_INT, 1, &P->dim) ||
        read_attr_num(c, f, "/", "nLevels", H5T_NATIVE_INT, 1, &P->nlevels))
        return -1;
    P->step = (long)step;
    if (step < 0) return fail(c, "attribute 'step' is %lld, expected >= 0", (long long)step);
    /* a negative time would name the time folders -0.98, ... */
    if (P->time < 0) return fail(c, "attribute 'time' is %g, expected >= 0", P->time);
    if (P->dim != 2 && P->dim != 3)
        return fail(c, "attribute 'dimension' is %d, expected 2 or 3", P->dim);
    if (P->nlevels < 1 || P->nlevels > LUB_MAX_LEVELS)
        return fail(c, "attribute 'nLevels' is %d, expected 1 to %d", P->nlevels, LUB_MAX_LEVELS);
    for (int k = 0; k < P->nlevels; k++) {
        char name[32], objname[40];
        lub_level *L = &P->levels[k];
        snprintf(name, sizeof name, "level%d", k);
        snprintf(objname, sizeof objname, "/%s", name);
        htri_t ex = H5Lexists(f, name, H5P_DEFAULT);
        if (ex <= 0) return fail(c, "group %s missing (nLevels is %d)", objname, P->nlevels);
        hid_t g = H5Gopen2(f, name, H5P_DEFAULT);
        if (g < 0) return fail_h5(c, "cannot open group %s", objname);
        int rc = read_attr_double(c, g, objname, "l0", &L->l0) ||
                 read_attr_double(c, g, objname, "re", &L->re) ||
                 read_attr_double(c, g, objname, "n0", &L->n0) ||
                 read_attr_double(c, g, objname, "lambda0", &L->lambda0);
        H5Gclose(g);
        if (rc) return -1;
        /* lengths and the reference values of T-4, T-5 are positive: a zero l0 divides */
        const char *names[4] = {"l0", "re", "n0", "lambda0"};
        const double vals[4] = {L->l0, L->re, L->n0, L->lambda0};
        for (int a = 0; a < 4; a++)
            if (!(vals[a] > 0))
                return fail(c, "attribute '%s' of %s is %g, expected > 0", names[a], objname,
                            vals[a]);
    }

    /* /patches: 1-D strings, fixed or variable length. */
    htri_t ex = H5Lexists(f, "patches", H5P_DEFAULT);
    if (ex < 0) return fail_h5(c, "cannot look up /patches");
    if (ex == 0) return fail(c, "dataset /patches missing");
    hid_t d = H5Dopen2(f, "patches", H5P_DEFAULT);
    if (d < 0) return fail_h5(c, "/patches is not a readable dataset");
    hid_t t = H5Dget_type(d), s = H5Dget_space(d), m = H5I_INVALID_HID;
    hsize_t dims[H5S_MAX_RANK];
    int rc = -1;
    char **vnames = NULL;
    char *fnames = NULL;
    if (t < 0 || s < 0) {
        fail_h5(c, "cannot read the type of /patches");
        goto out;
    }
    if (H5Tget_class(t) != H5T_STRING) {
        fail(c, "/patches must hold strings (the patch names)");
        goto out;
    }
    if (H5Sget_simple_extent_ndims(s) != 1 || H5Sget_simple_extent_dims(s, dims, NULL) < 0) {
        fail(c, "/patches must be a 1-D list of names");
        goto out;
    }
    if (dims[0] > LUB_MAX_PATCHES) {
        fail(c, "/patches holds %llu names, at most %d are supported", (unsigned long long)dims[0],
             LUB_MAX_PATCHES);
        goto out;
    }
    P->npatches = (int)dims[0];
    if (P->npatches > 0) {
        if (H5Tis_variable_str(t) > 0) {
            vnames = calloc((size_t)P->npatches, sizeof *vnames);
            if (!vnames || (m = H5Tcopy(H5T_C_S1)) < 0 || H5Tset_size(m, H5T_VARIABLE) < 0 ||
                H5Dread(d, m, H5S_ALL, H5S_ALL, H5P_DEFAULT, vnames) < 0) {
                fail_h5(c, "cannot read /patches");
                goto out;
            }
        } else {
            size_t size = H5Tget_size(t) + 1;
            fnames = calloc((size_t)P->npatches, size);
            if (!fnames || (m = H5Tcopy(H5T_C_S1)) < 0 || H5Tset_size(m, size) < 0 ||
                H5Tset_strpad(m, H5T_STR_NULLTERM) < 0 ||
                H5Dread(d, m, H5S_ALL, H5S_ALL, H5P_DEFAULT, fnames) < 0) {
                fail_h5(c, "cannot read /patches");
                goto out;
            }
            for (int k = 0; k < P->npatches; k++) {
                const char *name = fnames + (size_t)k * size;
                if (strlen(name) >= LUB_NAME_MAX) {
                    fail(c, "/patches[%d] '%.64s...' is longer than %d characters", k, name,
                         LUB_NAME_MAX - 1);
                    goto out;
                }
                strcpy(P->patch_names[k], name);
            }
        }
        for (int k = 0; vnames && k < P->npatches; k++) {
            const char *name = vnames[k] ? vnames[k] : "";
            if (strlen(name) >= LUB_NAME_MAX) {
                fail(c, "/patches[%d] '%.64s...' is longer than %d characters", k, name,
                     LUB_NAME_MAX - 1);
                goto out;
            }
            strcpy(P->patch_names[k], name);
        }
        for (int k = 0; k < P->npatches; k++) {
            if (!name_ok(P->patch_names[k])) {
                fail(c, "/patches[%d] '%s' is not a valid patch name", k, P->patch_names[k]);
                goto out;
            }
            for (int j = 0; j < k; j++)
                if (strcmp(P->patch_names[j], P->patch_names[k]) == 0) {
                    fail(c, "/patches lists '%s' twice", P->patch_names[k]);
                    goto out;
                }
        }
    }
    rc = 0;
out:
    if (vnames) {
        if (m >= 0 && s >= 0) H5Dvlen_reclaim(m, s, H5P_DEFAULT, vnames);
        free(vnames);
    }
    free(fnames);
    close_id(&m, H5Tclose);
    close_id(&s, H5Sclose);
    close_id(&t, H5Tclose);
    H5Dclose(d);
    return rc;
}

/* Shape of /fields: N from position, and the extra fields (names checked, shapes N). */
static int read_shape(h5ctx *c, hid_t g, size_t *n, int *nextra,
                      char extra[LUB_MAX_EXTRA][LUB_NAME_MAX])
{
    *n = (size_t)-1;
    hid_t d = open_dataset(c, g, "/fields", "position", 3, n, 1, 0);
    if (d < 0) return -1;
    H5Dclose(d);

    H5G_info_t info;
    if (H5Gget_info(g, &info) < 0) return fail_h5(c, "cannot list /fields");
    *nextra = 0;
    for (hsize_t k = 0; k < info.nlinks; k++) {
        char name[LUB_NAME_MAX + 8];
        ssize_t len = H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, k, name, sizeof name,
                                         H5P_DEFAULT);
        if (len < 0) return fail_h5(c, "cannot list /fields");
        if ((size_t)len >= LUB_NAME_MAX)
            return fail(c, "/fields/%s...: field name longer than %d characters", name,
                        LUB_NAME_MAX - 1);
        if (is_standard(name)) continue;
        if (!name_ok(name)) return fail(c, "/fields/%s: not a valid field name", name);
        if (*nextra >= LUB_MAX_EXTRA)
            return fail(c, "/fields holds more than %d extra fields", LUB_MAX_EXTRA);
        size_t rows = *n;
        d = open_dataset(c, g, "/fields", name, 1, &rows, 1, 1);
        if (d < 0) return -1;
        H5Dclose(d);
        strcpy(extra[(*nextra)++], name);
    }
    return 0;
}

/* The rows read: all n, or the slice's. */
static size_t rows_read(const h5ctx *c, size_t n)
{
    return c->sliced ? c->count : n;
}

/* The file's row of the i-th row read. */
static size_t file_row(const h5ctx *c, size_t i)
{
    return c->sliced ? c->first + i : i;
}

static int read_int_field(h5ctx *c, hid_t g, const char *name, size_t n, int64_t *tmp,
                          int64_t limit, const char *expected)
{
    if (read_dataset(c, g, "/fields", name, 1, n, 0, 1, H5T_NATIVE_INT64, tmp)) return -1;
    for (size_t i = 0; i < rows_read(c, n); i++)
        if (tmp[i] < 0 || tmp[i] >= limit)
            return fail(c, "/fields/%s[%zu] = %lld, expected %s", name, file_row(c, i),
                        (long long)tmp[i], expected);
    return 0;
}

static int check_finite(h5ctx *c, const char *name, const double *v, size_t n)
{
    for (size_t i = 0; i < rows_read(c, n); i++)
        if (!isfinite(v[i]))
            return fail(c, "/fields/%s[%zu] is not finite (%g)", name, file_row(c, i), v[i]);
    return 0;
}

/* A slice's places (lub_particles_read_rows): /solver/order's rows, or the rows themselves
 * when the file has none (the solver's order was the id order), each below n. */
static int read_places(h5ctx *c, size_t n, uint64_t *place)
{
    htri_t ex = H5Lexists(c->file, "solver", H5P_DEFAULT);
    if (ex < 0) return fail_h5(c, "cannot look up /solver");
    if (ex == 0) {
        for (size_t i = 0; i < c->count; i++) place[i] = c->first + i;
        return 0;
    }
    ex = H5Lexists(c->file, "solver/order", H5P_DEFAULT);
    if (ex <= 0) return fail(c, "group /solver holds no dataset 'order'");
    hid_t g = H5Gopen2(c->file, "solver", H5P_DEFAULT);
    if (g < 0) return fail_h5(c, "cannot open group /solver");
    int rc = read_dataset(c, g, "/solver", "order", 1, n, 0, 1, H5T_NATIVE_UINT64, place);
    H5Gclose(g);
    for (size_t i = 0; rc == 0 && i < c->count; i++)
        if (place[i] >= n)
            rc = fail(c, "/solver/order[%zu] = %llu: not a place of 0 .. %zu", c->first + i,
                      (unsigned long long)place[i], n - 1);
    return rc;
}

/* Put every particle back where the solver had it (/solver/order, written when that order
 * is not the id order of the rows); the rows stay in file order without it.  c->buf (3 n
 * values) is the scratch space of the moves. */
static int restore_order(h5ctx *c, lub_particles *P, size_t n)
{
    htri_t ex = H5Lexists(c->file, "solver", H5P_DEFAULT);
    if (ex < 0) return fail_h5(c, "cannot look up /solver");
    if (ex == 0 || n == 0) return 0;
    ex = H5Lexists(c->file, "solver/order", H5P_DEFAULT);
    if (ex <= 0) return fail(c, "group /solver holds no dataset 'order'");
    hid_t g = H5Gopen2(c->file, "solver", H5P_DEFAULT);
    if (g < 0) return fail_h5(c, "cannot open group /solver");
    uint64_t *order = malloc(n * sizeof *order);
    unsigned char *seen = calloc(n, 1);
    int rc = -1;
    if (!order || !seen) {
        fail(c, "out of memory reading /solver/order of %zu particles", n);
        goto out;
    }
    if (read_dataset(c, g, "/solver", "order", 1, n, 0, 1, H5T_NATIVE_UINT64, order)) goto out;
    for (size_t r = 0; r < n; r++) {
        if (order[r] >= n || seen[order[r]]) {
            fail(c, "/solver/order[%zu] = %llu: not a place of 0 .. %zu, each once", r,
                 (unsigned long long)order[r], n - 1);
            goto out;
        }
        seen[order[r]] = 1;
    }
    double *tmp = c->buf;
#define LUB_PLACE(arr, type)                                                                       \
    do {                                                                                           \
        type *t_ = (type *)(void *)tmp;                                                            \
        memcpy(t_, (arr), n * sizeof(type));                                                       \
        for (size_t r = 0; r < n; r++) (arr)[order[r]] = t_[r];                                    \
    } while (0)
    for (int d = 0; d < 3; d++) {
        LUB_PLACE(P->x[d], double);
        LUB_PLACE(P->u[d], double);
    }
    LUB_PLACE(P->p, double);
    LUB_PLACE(P->kind, uint8_t);
    LUB_PLACE(P->patch, uint16_t);
    LUB_PLACE(P->level, uint8_t);
    LUB_PLACE(P->id, uint64_t);
    for (int e = 0; e < P->nextra; e++) LUB_PLACE(P->extra[e].v, double);
#undef LUB_PLACE
    rc = 0;
out:
    free(order);
    free(seen);
    H5Gclose(g);
    return rc;
}

/* The whole file, or (c->sliced) rows first .. first + count - 1 of it with their places
 * (place: count entries) instead of the solver's order restored. */
static int read_contents(h5ctx *c, lub_particles *P, uint64_t *place)
{
    hid_t f = c->file;
    lub_particles H;
    memset(&H, 0, sizeof H);
    if (read_header(c, f, &H)) return -1;

    hid_t g = H5I_INVALID_HID;
    int rc = -1;
    htri_t ex = H5Lexists(f, "fields", H5P_DEFAULT);
    if (ex <= 0) {
        fail(c, "group /fields missing");
        goto out;
    }
    if ((g = H5Gopen2(f, "fields", H5P_DEFAULT)) < 0) {
        fail_h5(c, "cannot open group /fields");
        goto out;
    }
    size_t n;
    int nextra;
    char extra[LUB_MAX_EXTRA][LUB_NAME_MAX];
    if (read_shape(c, g, &n, &nextra, extra)) goto out;
    if (n > ((size_t)-1) / (3 * sizeof(double)) - 1) {
        fail(c, "/fields/position claims %zu particles", n);
        goto out;
    }
    if (c->sliced && (c->first > n || c->count > n - c->first)) {
        fail(c, "rows %zu .. %zu asked of a file of %zu particles", c->first, c->first + c->count,
             n);
        goto out;
    }
    const size_t m = rows_read(c, n); /* the rows read */

    /* The header is sound: set up storage (m exactly) and read the data. */
    lub_particles_init(P, H.dim, m ? m : 1);
    c->have_data = 1;
    P->time = H.time;
    P->step = H.step;
    P->nlevels = H.nlevels;
    memcpy(P->levels, H.levels, sizeof P->levels);
    P->npatches = H.npatches;
    memcpy(P->patch_names, H.patch_names, sizeof P->patch_names);
    P->n = m;
    for (int e = 0; e < nextra; e++) lub_particles_extra(P, extra[e]); /* names checked */

    c->buf = malloc(3 * (m ? m : 1) * sizeof(double));
    c->own_buf = 1;
    if (!c->buf) {
        fail(c, "out of memory reading %zu particles", m);
        goto out;
    }
    double *buf = c->buf;
    int64_t *tmp = c->buf;

    if (read_dataset(c, g, "/fields", "position", 3, n, 1, 0, H5T_NATIVE_DOUBLE, buf)) goto out;
    for (size_t i = 0; i < m; i++)
        for (int d = 0; d < 3; d++) {
            double v = buf[3 * i + d];
            if (!isfinite(v)) {
                fail(c, "/fields/position[%zu][%d] is not finite (%g)", file_row(c, i), d, v);
                goto out;
            }
            if (d == 2 && P->dim == 2 && v != 0.0) {
                fail(c, "/fields/position[%zu] has z = %g in a 2-D file (expected 0)",
                     file_row(c, i), v);
                goto out;
            }
            P->x[d][i] = v;
        }
    if (read_dataset(c, g, "/fields", "velocity", 3, n, 1, 0, H5T_NATIVE_DOUBLE, buf)) goto out;
    for (size_t i = 0; i < m; i++)
        for (int d = 0; d < 3; d++) {
            double v = buf[3 * i + d];
            if (!isfinite(v)) {
                fail(c, "/fields/velocity[%zu][%d] is not finite (%g)", file_row(c, i), d, v);
                goto out;
            }
            P->u[d][i] = v;
        }
    if (read_dataset(c, g, "/fields", "pressure", 1, n, 1, 0, H5T_NATIVE_DOUBLE, P->p) ||
        check_finite(c, "pressure", P->p, n) ||
        read_dataset(c, g, "/fields", "id", 1, n, 0, 1, H5T_NATIVE_UINT64, P->id))
        goto out;
    for (int e = 0; e < P->nextra; e++)
        if (read_dataset(c, g, "/fields", P->extra[e].name, 1, n, 1, 1, H5T_NATIVE_DOUBLE,
                         P->extra[e].v) ||
            check_finite(c, P->extra[e].name, P->extra[e].v, n))
            goto out;

    if (read_int_field(c, g, "kind", n, tmp, 3, "0 (fluid), 1 (wall) or 2 (dummy)")) goto out;
    for (size_t i = 0; i < m; i++) P->kind[i] = (uint8_t)tmp[i];
    char expected[96];
    snprintf(expected, sizeof expected, "a level below nLevels = %d", P->nlevels);
    if (read_int_field(c, g, "level", n, tmp, P->nlevels, expected)) goto out;
    for (size_t i = 0; i < m; i++) P->level[i] = (uint8_t)tmp[i];
    /* Fluid particles carry patch 0, meaningless; walls and dummies name a patch. */
    if (read_int_field(c, g, "patch", n, tmp, 65536, "0 to 65535")) goto out;
    for (size_t i = 0; i < m; i++) {
        if (tmp[i] >= P->npatches && !(P->kind[i] == LUB_FLUID && tmp[i] == 0)) {
            fail(c, "/fields/patch[%zu] = %lld, but /patches lists %d name%s", file_row(c, i),
                 (long long)tmp[i], P->npatches, P->npatches == 1 ? "" : "s");
            goto out;
        }
        P->patch[i] = (uint16_t)tmp[i];
    }
    if (c->sliced ? read_places(c, n, place) : restore_order(c, P, n)) goto out;
    rc = 0;
out:
    close_id(&g, H5Gclose);
    return rc;
}

/* Common opening of a file for reading; returns 0 with c->file open. */
static int open_for_reading(h5ctx *c, const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) return fail(c, "cannot read particle file: %s", strerror(errno));
    if (!S_ISREG(st.st_mode)) return fail(c, "not a regular file");
    htri_t is = H5Fis_hdf5(path);
    if (is == 0) return fail(c, "not an HDF5 file (a lubkit particle file is HDF5)");
    if (is < 0) return fail_h5(c, "not a readable HDF5 file");
    if ((c->fapl = file_access_plist(0)) < 0)
        return fail_h5(c, "cannot make a file access property list");
    if ((c->file = H5Fopen(path, H5F_ACC_RDONLY, c->fapl)) < 0)
        return fail_h5(c, "damaged or unreadable HDF5 file");
    return 0;
}

void lub_particles_read(lub_particles *P, const char *path)
{
    h5ctx c;
    memset(P, 0, sizeof *P);
    ctx_begin(&c);
    if (open_for_reading(&c, path) == 0) read_contents(&c, P, NULL);
    int have_data = c.have_data;
    if (ctx_end(&c)) {
        if (have_data) lub_particles_free(P);
        lub_fatal("%s: %s", path, c.msg);
    }
}

void lub_particles_read_rows(lub_particles *P, const char *path, size_t first, size_t count,
                             uint64_t *place)
{
    h5ctx c;
    memset(P, 0, sizeof *P);
    ctx_begin(&c);
    c.sliced = 1;
    c.first = first;
    c.count = count;
    if (open_for_reading(&c, path) == 0) read_contents(&c, P, place);
    int have_data = c.have_data;
    if (ctx_end(&c)) {
        if (have_data) lub_particles_free(P);
        lub_fatal("%s: %s", path, c.msg);
    }
}

/* Size of the entries of /xdmf/connectivity when it is a list of n integers, else 0 (the
 * XDMF then has no connectivity: fine for the Xdmf2 reader, points only for Xdmf3). */
static int connectivity_bytes(hid_t f, size_t n)
{
    int bytes = 0;
    if (H5Lexists(f, "xdmf", H5P_DEFAULT) <= 0 ||
        H5Lexists(f, "xdmf/connectivity", H5P_DEFAULT) <= 0)
        return 0;
    hid_t d = H5Dopen2(f, "xdmf/connectivity", H5P_DEFAULT);
    if (d < 0) return 0;
    hid_t s = H5Dget_space(d), t = H5Dget_type(d);
    hsize_t dims[H5S_MAX_RANK];
    if (s >= 0 && t >= 0 && H5Sget_simple_extent_ndims(s) == 1 &&
        H5Sget_simple_extent_dims(s, dims, NULL) == 1 && dims[0] == (hsize_t)n &&
        H5Tget_class(t) == H5T_INTEGER) {
        size_t size = H5Tget_size(t);
        H5T_sign_t sign = H5Tget_sign(t);
        if (size == 4 && sign == H5T_SGN_NONE) bytes = 4;
        if (size == 8 && sign == H5T_SGN_2) bytes = 8;
    }
    close_id(&t, H5Tclose);
    close_id(&s, H5Sclose);
    H5Dclose(d);
    H5Eclear2(H5E_DEFAULT);
    return bytes;
}

/* Header and shapes of a file; 0, or -1 with the reason in msg. */
static int read_info(const char *path, lub_particles_info *info, char *msg, size_t size)
{
    h5ctx c;
    lub_particles H;
    memset(&H, 0, sizeof H);
    memset(info, 0, sizeof *info);
    ctx_begin(&c);
    if (open_for_reading(&c, path) == 0 && read_header(&c, c.file, &H) == 0) {
        hid_t g = H5I_INVALID_HID;
        if (H5Lexists(c.file, "fields", H5P_DEFAULT) <= 0)
            fail(&c, "group /fields missing");
        else if ((g = H5Gopen2(c.file, "fields", H5P_DEFAULT)) < 0)
            fail_h5(&c, "cannot open group /fields");
        else if (read_shape(&c, g, &info->n, &info->nextra, info->extra) == 0)
            info->conn_bytes = connectivity_bytes(c.file, info->n);
        close_id(&g, H5Gclose);
    }
    if (ctx_end(&c)) {
        snprintf(msg, size, "%s: %s", path, c.msg);
        return -1;
    }
    info->dim = H.dim;
    info->time = H.time;
    info->step = H.step;
    info->nlevels = H.nlevels;
    info->npatches = H.npatches;
    return 0;
}

void lub_particles_read_info(const char *path, lub_particles_info *info)
{
    char msg[LUB_PATH_MAX + 1100];
    if (read_info(path, info, msg, sizeof msg)) lub_fatal("%s", msg);
}

/* ------------------------------------------------------------------------------------------ */
/* XDMF                                                                                       */

/* Indentation is a number of spaces (printed as "%*s" of ""). */

/* One DataItem referring to <prefix>particles.h5:/fields/<name>. */
static void xdmf_item(FILE *fp, int indent, const char *prefix, const char *name, size_t n,
                      int ncols, const char *numtype, int precision)
{
    char dims[64];
    if (ncols > 1)
        snprintf(dims, sizeof dims, "%zu %d", n, ncols);
    else
        snprintf(dims, sizeof dims, "%zu", n);
    fprintf(fp,
            "%*s<DataItem Dimensions=\"%s\" NumberType=\"%s\" Precision=\"%d\" "
            "Format=\"HDF\">%sparticles.h5:/fields/%s</DataItem>\n",
            indent, "", dims, numtype, precision, prefix, name);
}

static void xdmf_attribute(FILE *fp, int indent, const char *prefix, const char *name, size_t n,
                           int ncols, const char *numtype, int precision)
{
    fprintf(fp, "%*s<Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n", indent, "",
            name, ncols > 1 ? "Vector" : "Scalar");
    xdmf_item(fp, indent + 2, prefix, name, n, ncols, numtype, precision);
    fprintf(fp, "%*s</Attribute>\n", indent, "");
}

/* One uniform grid of n points: a Polyvertex topology whose connectivity (written by
 * lub_particles_write, conn_bytes per entry) is 0 .. n-1, so every particle is one vertex
 * cell; without it (conn_bytes 0, a foreign file) Xdmf3 readers show points but no cells.
 * The id (uint64 in the file) is described as Int 8 because ParaView's Xdmf3 reader has no
 * 64-bit unsigned array type and skips such arrays; HDF5 converts on reading, exact for ids
 * below 2^63.
 *
 * The position is also a point attribute: a reader of the time series that takes the
 * geometry of the first time only and the attributes of every time (meshio's
 * TimeSeriesReader) then still has each time's positions.
 *
 * with_time: a <Time> element (the grids of the temporal collection).  The grid of a
 * folder's own particles.xdmf has none: meshio.read takes a lone grid only with Topology,
 * Geometry and Attribute in it (its time is the file's `time` attribute). */
static void xdmf_grid(FILE *fp, int indent, const char *name, int with_time, double time,
                      const char *prefix, size_t n, int conn_bytes, int nextra,
                      const char extra[][LUB_NAME_MAX])
{
    const int in1 = indent + 2, in2 = indent + 4;
    fprintf(fp, "%*s<Grid Name=\"%s\" GridType=\"Uniform\">\n", indent, "", name);
    if (with_time) fprintf(fp, "%*s<Time Value=\"%.17g\"/>\n", in1, "", time);
    fprintf(fp,
            "%*s<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" "
            "NodesPerElement=\"1\"%s>\n",
            in1, "", n, conn_bytes ? "" : "/");
    if (conn_bytes) {
        fprintf(fp,
                "%*s<DataItem Dimensions=\"%zu\" NumberType=\"%s\" Precision=\"%d\" "
                "Format=\"HDF\">%sparticles.h5:/xdmf/connectivity</DataItem>\n",
                in2, "", n, conn_bytes == 4 ? "UInt" : "Int", conn_bytes, prefix);
        fprintf(fp, "%*s</Topology>\n", in1, "");
    }
    fprintf(fp, "%*s<Geometry GeometryType=\"XYZ\">\n", in1, "");
    xdmf_item(fp, in2, prefix, "position", n, 3, "Float", 8);
    fprintf(fp, "%*s</Geometry>\n", in1, "");
    xdmf_attribute(fp, in1, prefix, "position", n, 3, "Float", 8);
    xdmf_attribute(fp, in1, prefix, "velocity", n, 3, "Float", 8);
    xdmf_attribute(fp, in1, prefix, "pressure", n, 1, "Float", 8);
    xdmf_attribute(fp, in1, prefix, "kind", n, 1, "UChar", 1);
    xdmf_attribute(fp, in1, prefix, "patch", n, 1, "UInt", 2);
    xdmf_attribute(fp, in1, prefix, "level", n, 1, "UChar", 1);
    xdmf_attribute(fp, in1, prefix, "id", n, 1, "Int", 8);
    for (int e = 0; e < nextra; e++) xdmf_attribute(fp, in1, prefix, extra[e], n, 1, "Float", 8);
    fprintf(fp, "%*s</Grid>\n", indent, "");
}

static void xdmf_head(FILE *fp)
{
    fprintf(fp, "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
                "<Xdmf xmlns:xi=\"http://www.w3.org/2001/XInclude\" Version=\"3.0\">\n"
                "  <Domain>\n");
}

static void xdmf_tail(FILE *fp)
{
    fprintf(fp, "  </Domain>\n</Xdmf>\n");
}

static void write_sidecar(const lub_particles *P, size_t n, const char *dir, int sync_dir)
{
    char path[LUB_PATH_MAX];
    char extra[LUB_MAX_EXTRA][LUB_NAME_MAX];
    if (snprintf(path, sizeof path, "%s/particles.xdmf", dir) >= (int)sizeof path)
        lub_fatal_run("path too long: '%s/particles.xdmf'", dir);
    for (int e = 0; e < P->nextra; e++) strcpy(extra[e], P->extra[e].name);
    lub_atomic_file af;
    FILE *fp = lub_atomic_open(&af, path);
    if (!fp) lub_fatal_run("%s: cannot write: %s", path, strerror(errno));
    af.sync_dir = sync_dir;
    xdmf_head(fp);
    xdmf_grid(fp, 4, "particles", 0, P->time, "", n, n <= UINT32_MAX ? 4 : 8, P->nextra,
              (const char(*)[LUB_NAME_MAX])extra);
    xdmf_tail(fp);
    if (lub_atomic_close(&af) != 0) lub_fatal_run("%s: cannot write: %s", path, strerror(errno));
}

/* ---- the case's time series ---------------------------------------------------------- */

static int cmp_entry(const void *a, const void *b)
{
    double x = ((const lub_xdmf_entry *)a)->time, y = ((const lub_xdmf_entry *)b)->time;
    return (x > y) - (x < y);
}

/* Room for one more entry. */
static lub_xdmf_entry *series_slot(lub_xdmf_series *s)
{
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 16;
        s->e = lub_realloc(s->e, s->cap * sizeof *s->e);
    }
    return &s->e[s->n];
}

void lub_xdmf_series_scan(lub_xdmf_series *s, const lub_case *c)
{
    memset(s, 0, sizeof *s);
    s->c = *c;
    lub_time *times = NULL;
    size_t nt = lub_case_times(c, &times);
    for (size_t k = 0; k < nt; k++) {
        char h5[LUB_PATH_MAX];
        struct stat st;
        lub_case_pathf(c, h5, "%s/particles.h5", times[k].name);
        if (stat(h5, &st) != 0) continue;
        lub_particles_info info;
        char msg[LUB_PATH_MAX + 1100];
        if (read_info(h5, &info, msg, sizeof msg)) {
            lub_warning("%s (time %s left out of %s/particles.xdmf)", msg, times[k].name, c->root);
            continue;
        }
        lub_xdmf_entry *e = series_slot(s);
        snprintf(e->name, sizeof e->name, "%s", times[k].name);
        e->time = info.time;
        e->n = info.n;
        e->conn_bytes = info.conn_bytes;
        e->nextra = info.nextra;
        memcpy(e->extra, info.extra, sizeof e->extra);
        s->n++;
    }
    free(times);
    if (s->n > 1) qsort(s->e, s->n, sizeof *s->e, cmp_entry); /* (none: s->e is NULL) */
}

size_t lub_xdmf_series_write(const lub_xdmf_series *s)
{
    char path[LUB_PATH_MAX];
    lub_case_path(&s->c, path, "particles.xdmf");
    if (s->n == 0) {
        unlink(path); /* no particles any more: an old collection would be stale */
        return 0;
    }
    lub_atomic_file af;
    FILE *fp = lub_atomic_open(&af, path);
    if (!fp) lub_fatal_run("%s: cannot write: %s", path, strerror(errno));
    xdmf_head(fp);
    fprintf(fp, "    <Grid Name=\"particles\" GridType=\"Collection\" "
                "CollectionType=\"Temporal\">\n");
    for (size_t k = 0; k < s->n; k++) {
        const lub_xdmf_entry *e = &s->e[k];
        char prefix[80];
        snprintf(prefix, sizeof prefix, "%s/", e->name);
        xdmf_grid(fp, 6, e->name, 1, e->time, prefix, e->n, e->conn_bytes, e->nextra,
                  (const char(*)[LUB_NAME_MAX])e->extra);
    }
    fprintf(fp, "    </Grid>\n");
    xdmf_tail(fp);
    if (lub_atomic_close(&af) != 0) lub_fatal_run("%s: cannot write: %s", path, strerror(errno));
    return s->n;
}

void lub_xdmf_series_put(lub_xdmf_series *s, const char *name, const lub_particles *P)
{
    lub_xdmf_entry *e = NULL;
    for (size_t k = 0; k < s->n && !e; k++)
        if (strcmp(s->e[k].name, name) == 0) e = &s->e[k];
    if (!e) {
        e = series_slot(s);
        s->n++;
    }
    memset(e, 0, sizeof *e);
    snprintf(e->name, sizeof e->name, "%s", name);
    e->time = P->time;
    e->n = P->n;
    e->conn_bytes = P->n <= UINT32_MAX ? 4 : 8;
    e->nextra = P->nextra;
    for (int k = 0; k < P->nextra; k++) strcpy(e->extra[k], P->extra[k].name);
    qsort(s->e, s->n, sizeof *s->e, cmp_entry);
    lub_xdmf_series_write(s);
}

void lub_xdmf_series_remove(lub_xdmf_series *s, const char *name)
{
    for (size_t k = 0; k < s->n; k++)
        if (strcmp(s->e[k].name, name) == 0) {
            memmove(&s->e[k], &s->e[k + 1], (s->n - k - 1) * sizeof *s->e);
            s->n--;
            break;
        }
    lub_xdmf_series_write(s);
}

void lub_xdmf_series_free(lub_xdmf_series *s)
{
    free(s->e);
    s->e = NULL;
    s->n = s->cap = 0;
}

size_t lub_case_xdmf_write(const lub_case *c)
{
    lub_xdmf_series s;
    lub_xdmf_series_scan(&s, c);
    size_t n = lub_xdmf_series_write(&s);
    lub_xdmf_series_free(&s);
    return n;
}
