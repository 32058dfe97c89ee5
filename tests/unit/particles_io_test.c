/* Unit tests of src/particles/particles_io.c: particle files (HDF5) and their XDMF descriptions.
 *
 * References are independent of the writer: round trips compare every array bit for bit
 * with what was stored in memory; damaged and foreign files are made here with the HDF5 API
 * or by cutting and overwriting bytes; every rejection must be a fatal input error (status 1)
 * naming the file, leave no HDF5 object open and print nothing of HDF5's own on stderr.
 *
 * For tests/cases/particleFiles: "-writeCase DIR" writes a sample case instead (three time
 * folders, 2-D, two levels, patches, extra fields, and an empty 3-D set in DIR/empty);
 * "-read FILE" reads one file and exits with the reader's status (damaged files are fuzzed
 * there, one process each, because HDF5 1.10 itself leaks memory on some damaged headers).
 */
#include <dirent.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <hdf5.h>

#include "io/case.h"
#include "particles/particles_io.h"
#include "particles/particles.h"
#include "test.h"

static char tmpdir[LUB_PATH_MAX];
static char last_message[2048]; /* message of the last expect_rejected */

/* ---------------------------------------------------------------------------------------- */
/* Helpers                                                                                  */

/* "<dir>/<name>" into buf (LUB_PATH_MAX bytes). */
static char *join(char *buf, const char *dir, const char *name)
{
    if (snprintf(buf, LUB_PATH_MAX, "%s/%s", dir, name) >= LUB_PATH_MAX) {
        fprintf(stderr, "path too long\n");
        exit(1);
    }
    return buf;
}

static uint64_t rng_state = 88172645463325252ull;
static uint64_t rng(void) /* xorshift64 */
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}
static double urand(void)
{
    return (double)(rng() >> 11) / 9007199254740992.0;
}

/* Particles with awkward values (negative zero, subnormal, huge, non-terminating binary
 * fractions) so that any conversion or rounding shows in a bitwise comparison. */
static void make_particles(lub_particles *P, int dim, size_t n, int nlevels, int npatches,
                           int nextra)
{
    static const double special[] = {-0.0,      4.9406564584124654e-324,  1.7976931348623157e308,
                                     1.0 / 3.0, -2.2250738585072014e-308, 0.1};
    lub_particles_init(P, dim, 1); /* small: exercise growth */
    P->time = 0.0123456789012345678;
    P->step = 123456789012l;
    P->nlevels = nlevels;
    for (int k = 0; k < nlevels; k++) {
        P->levels[k].l0 = 5e-6 * (k + 1) / 3.0;
        P->levels[k].re = 3.1 * P->levels[k].l0;
        P->levels[k].n0 = 6.123456789 + k;
        P->levels[k].lambda0 = 1.0 / (7.0 + k);
    }
    char name[32];
    for (int k = 0; k < npatches; k++) {
        snprintf(name, sizeof name, "wall_%d", k);
        lub_particles_patch(P, name);
    }
    for (int e = 0; e < nextra; e++) {
        snprintf(name, sizeof name, "extra%d", e);
        lub_particles_extra(P, name);
    }
    for (size_t i = 0; i < n; i++) {
        double x[3];
        for (int d = 0; d < 3; d++) x[d] = (urand() - 0.5) * 1e-3;
        if (i < sizeof special / sizeof *special && !isinf(special[i])) x[0] = special[i];
        int kind = npatches ? (int)(rng() % 3) : LUB_FLUID;
        int patch = kind == LUB_FLUID ? 0 : (int)(rng() % (uint64_t)npatches);
        size_t k = lub_particles_add(P, x, kind, patch, (int)(rng() % (uint64_t)nlevels));
        for (int d = 0; d < 3; d++) P->u[d][k] = d < dim ? (urand() - 0.5) * 7.0 : 0.0;
        P->p[k] = i < sizeof special / sizeof *special ? special[i] : urand() * 1e6;
        P->id[k] = (rng() >> 2) + i; /* stable ids are not indices */
        for (int e = 0; e < nextra; e++) P->extra[e].v[k] = urand() - 0.25 * e;
    }
}

static int same_bits(const void *a, const void *b, size_t bytes)
{
    return bytes == 0 || memcmp(a, b, bytes) == 0;
}

/* Every stored value of A equals B's bit for bit. */
static void check_equal(const lub_particles *A, const lub_particles *B)
{
    CHECK(A->dim == B->dim);
    CHECK(A->n == B->n);
    CHECK(same_bits(&A->time, &B->time, sizeof A->time));
    CHECK(A->step == B->step);
    CHECK(A->nlevels == B->nlevels);
    CHECK(same_bits(A->levels, B->levels, sizeof A->levels[0] * (size_t)A->nlevels));
    CHECK(A->npatches == B->npatches);
    for (int k = 0; k < A->npatches && k < B->npatches; k++)
        CHECK(strcmp(A->patch_names[k], B->patch_names[k]) == 0);
    if (A->n != B->n) return;
    size_t n = A->n;
    for (int d = 0; d < 3; d++) {
        CHECK(same_bits(A->x[d], B->x[d], n * sizeof(double)));
        CHECK(same_bits(A->u[d], B->u[d], n * sizeof(double)));
    }
    CHECK(same_bits(A->p, B->p, n * sizeof(double)));
    CHECK(same_bits(A->kind, B->kind, n));
    CHECK(same_bits(A->patch, B->patch, n * sizeof(uint16_t)));
    CHECK(same_bits(A->level, B->level, n));
    CHECK(same_bits(A->id, B->id, n * sizeof(uint64_t)));
    CHECK(A->nextra == B->nextra);
    for (int e = 0; e < A->nextra; e++) {
        const double *v = lub_particles_find_extra(B, A->extra[e].name);
        CHECK(v != NULL);
        if (v) CHECK(same_bits(A->extra[e].v, v, n * sizeof(double)));
    }
}

static ssize_t open_objects(void)
{
    (void)test_last_error; /* (CHECK_FATAL keeps the message there) */
    return H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL);
}

static char *subdir(char *buf, const char *name)
{
    join(buf, tmpdir, name);
    lub_rm_rf(buf);
    CHECK(lub_mkdir_p(buf) == 0);
    return buf;
}

static char *read_text(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) return NULL;
    fseek(fp, 0, SEEK_END);
    long size = ftell(fp);
    rewind(fp);
    char *s = malloc((size_t)size + 1);
    size_t got = fread(s, 1, (size_t)size, fp);
    s[got] = '\0';
    fclose(fp);
    return s;
}

static void copy_file(const char *from, const char *to, long max_bytes)
{
    FILE *in = fopen(from, "rb"), *out = fopen(to, "wb");
    CHECK(in && out);
    if (!in || !out) return;
    char buf[4096];
    long total = 0;
    size_t got;
    while ((got = fread(buf, 1, sizeof buf, in)) > 0) {
        if (max_bytes >= 0 && total + (long)got > max_bytes) got = (size_t)(max_bytes - total);
        fwrite(buf, 1, got, out);
        total += (long)got;
        if (max_bytes >= 0 && total >= max_bytes) break;
    }
    fclose(in);
    fclose(out);
}

static long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

/* Read path expecting a fatal input error whose message names the file and contains sub;
 * P must hold nothing afterwards, no HDF5 object may stay open and HDF5 must not have
 * written to stderr. */
static void expect_rejected(const char *path, const char *sub)
{
    char errpath[LUB_PATH_MAX];
    join(errpath, tmpdir, "stderr.txt");
    fflush(stderr);
    int saved = dup(2), fd = open(errpath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 2);
    close(fd);

    lub_particles P;
    lub_catcher c;
    int raised = 0;
    if (lub_error_catch(&c) == 0) {
        lub_particles_read(&P, path);
        lub_error_uncatch();
    } else
        raised = 1;

    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    CHECK(raised);
    if (!raised) {
        printf("  %s: accepted, expected an error containing '%s'\n", path, sub);
        lub_particles_free(&P);
        return;
    }
    memcpy(last_message, c.message, sizeof last_message);
    CHECK(c.status == LUB_EXIT_INPUT);
    CHECK_STR(c.message, path);
    CHECK_STR(c.message, sub);
    CHECK(P.x[0] == NULL && P.n == 0 && P.nextra == 0);
    CHECK(open_objects() == 0);
    CHECK(file_size(errpath) == 0);
}

/* A valid file to damage: 2-D, 50 particles, 2 patches, 2 levels, one extra field. */
static void write_valid(const char *dir, lub_particles *P)
{
    lub_particles_free(P); /* callers start from a zeroed struct */
    rng_state = 12345;
    make_particles(P, 2, 50, 2, 2, 1);
    lub_particles_write(P, dir);
}

/* Open dir/particles.h5 for editing with the HDF5 API (independent of the reader). */
static hid_t edit_open(const char *dir)
{
    char path[LUB_PATH_MAX];
    join(path, dir, "particles.h5");
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    CHECK(f >= 0);
    return f;
}

static void replace_dataset(hid_t f, const char *name, hid_t type, int rank, hsize_t d0, hsize_t d1,
                            const void *data)
{
    hsize_t dims[2] = {d0, d1};
    if (H5Lexists(f, name, H5P_DEFAULT) > 0) H5Ldelete(f, name, H5P_DEFAULT);
    hid_t s = H5Screate_simple(rank, dims, NULL);
    hid_t d = H5Dcreate2(f, name, type, s, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    CHECK(d >= 0);
    if (data) CHECK(H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0);
    H5Dclose(d);
    H5Sclose(s);
}

/* ---------------------------------------------------------------------------------------- */
/* Round trips                                                                              */

static void roundtrip(int dim, size_t n, int nlevels, int npatches, int nextra)
{
    char dir[LUB_PATH_MAX], path[LUB_PATH_MAX];
    char name[64];
    snprintf(name, sizeof name, "rt_%dd_%zu_%d_%d_%d", dim, n, nlevels, npatches, nextra);
    subdir(dir, name);
    lub_particles A, B;
    make_particles(&A, dim, n, nlevels, npatches, nextra);
    lub_particles_write(&A, dir);
    join(path, dir, "particles.h5");
    lub_particles_read(&B, path);
    check_equal(&A, &B);
    CHECK(B.cap >= B.n);
    CHECK(open_objects() == 0);

    lub_particles_info info;
    lub_particles_read_info(path, &info);
    CHECK(info.dim == dim && info.n == n && info.nextra == nextra);
    CHECK(info.nlevels == nlevels && info.npatches == npatches);
    CHECK(info.step == A.step && info.time == A.time);
    CHECK(info.conn_bytes == 4);
    for (int e = 0; e < nextra; e++)
        CHECK(strcmp(info.extra[e], A.extra[e].name) == 0 ||
              lub_particles_find_extra(&A, info.extra[e]));

    /* The folder holds exactly the two files: no temporary left behind. */
    int entries = 0, h5 = 0, xdmf = 0;
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d))) {
        if (e->d_name[0] == '.') continue;
        entries++;
        h5 += strcmp(e->d_name, "particles.h5") == 0;
        xdmf += strcmp(e->d_name, "particles.xdmf") == 0;
    }
    if (d) closedir(d);
    CHECK(entries == 2 && h5 == 1 && xdmf == 1);

    /* Writing over an existing file replaces it (restart writes the same time again). */
    B.p[0] = n ? 99.0 : 0.0;
    lub_particles_write(&B, dir);
    lub_particles C;
    lub_particles_read(&C, path);
    check_equal(&B, &C);
    lub_particles_free(&A);
    lub_particles_free(&B);
    lub_particles_free(&C);
}

static void test_roundtrip_2d(void)
{
    roundtrip(2, 200, 1, 1, 0);
}
static void test_roundtrip_3d(void)
{
    roundtrip(3, 300, 1, 3, 0);
}
static void test_roundtrip_extras_levels(void)
{
    roundtrip(2, 1000, 3, 4, 3);
    roundtrip(3, 517, LUB_MAX_LEVELS, 5, LUB_MAX_EXTRA);
}
static void test_roundtrip_fluid_only(void)
{
    roundtrip(2, 64, 1, 0, 1);
}
/* N = 0 is a valid (empty) particle set: it round-trips with its header. */
static void test_roundtrip_empty(void)
{
    roundtrip(3, 0, 2, 2, 2);
}

/* The sidecar XDMF names every dataset with its shape (checked as text here; the case test
 * checks it against h5dump and xmllint). */
static void test_sidecar(void)
{
    char dir[LUB_PATH_MAX], path[LUB_PATH_MAX];
    subdir(dir, "sidecar");
    lub_particles P;
    rng_state = 777;
    make_particles(&P, 2, 37, 2, 2, 2);
    lub_particles_write(&P, dir);
    join(path, dir, "particles.xdmf");
    char *x = read_text(path);
    CHECK(x != NULL);
    if (x) {
        CHECK_STR(x, "<Xdmf");
        CHECK_STR(x, "Version=\"3.0\"");
        /* no <Time> in a lone grid: meshio.read refuses one ("Unknown section 'Time'"); the
         * time is the file's attribute, and the case's collection carries it */
        CHECK(strstr(x, "<Time") == NULL);
        CHECK_STR(x, "<Attribute Name=\"position\" AttributeType=\"Vector\" Center=\"Node\">");
        CHECK_STR(x, "TopologyType=\"Polyvertex\" NumberOfElements=\"37\"");
        CHECK_STR(x, "<DataItem Dimensions=\"37\" NumberType=\"UInt\" Precision=\"4\" "
                     "Format=\"HDF\">particles.h5:/xdmf/connectivity</DataItem>");
        CHECK_STR(x, "<Geometry GeometryType=\"XYZ\">");
        CHECK_STR(x, "<DataItem Dimensions=\"37 3\" NumberType=\"Float\" Precision=\"8\" "
                     "Format=\"HDF\">particles.h5:/fields/position</DataItem>");
        CHECK_STR(x, "<Attribute Name=\"velocity\" AttributeType=\"Vector\" Center=\"Node\">");
        CHECK_STR(x, "<DataItem Dimensions=\"37 3\" NumberType=\"Float\" Precision=\"8\" "
                     "Format=\"HDF\">particles.h5:/fields/velocity</DataItem>");
        CHECK_STR(x, "Dimensions=\"37\" NumberType=\"Float\" Precision=\"8\" "
                     "Format=\"HDF\">particles.h5:/fields/pressure<");
        CHECK_STR(x, "Dimensions=\"37\" NumberType=\"UChar\" Precision=\"1\" "
                     "Format=\"HDF\">particles.h5:/fields/kind<");
        CHECK_STR(x, "Dimensions=\"37\" NumberType=\"UInt\" Precision=\"2\" "
                     "Format=\"HDF\">particles.h5:/fields/patch<");
        CHECK_STR(x, "Dimensions=\"37\" NumberType=\"UChar\" Precision=\"1\" "
                     "Format=\"HDF\">particles.h5:/fields/level<");
        CHECK_STR(x, "Dimensions=\"37\" NumberType=\"Int\" Precision=\"8\" "
                     "Format=\"HDF\">particles.h5:/fields/id<");
        CHECK_STR(x, "<Attribute Name=\"extra1\" AttributeType=\"Scalar\" Center=\"Node\">");
        CHECK_STR(x, "particles.h5:/fields/extra1<");
        free(x);
    }
    lub_particles_free(&P);
}

/* ---------------------------------------------------------------------------------------- */
/* Rejected files                                                                           */

static void test_missing_file(void)
{
    char path[LUB_PATH_MAX];
    join(path, tmpdir, "no/such/particles.h5");
    expect_rejected(path, "No such file");
    expect_rejected(tmpdir, "not a regular file");
}

static void test_not_hdf5(void)
{
    char dir[LUB_PATH_MAX], path[LUB_PATH_MAX];
    subdir(dir, "random");
    join(path, dir, "particles.h5");
    FILE *fp = fopen(path, "wb");
    rng_state = 99;
    for (int i = 0; i < 5000; i++) fputc((int)(rng() & 255), fp);
    fclose(fp);
    expect_rejected(path, "not an HDF5 file");

    /* HDF5's signature followed by garbage: looks like HDF5, is not readable. */
    fp = fopen(path, "wb");
    fwrite("\211HDF\r\n\032\n", 1, 8, fp);
    for (int i = 0; i < 3000; i++) fputc((int)(rng() & 255), fp);
    fclose(fp);
    expect_rejected(path, "HDF5");

    fp = fopen(path, "wb"); /* empty file */
    fclose(fp);
    expect_rejected(path, "not an HDF5 file");
}

static void test_truncated(void)
{
    char dir[LUB_PATH_MAX], good[LUB_PATH_MAX], path[LUB_PATH_MAX];
    lub_particles P;
    memset(&P, 0, sizeof P);
    subdir(dir, "truncated");
    write_valid(dir, &P);
    lub_particles_free(&P);
    join(good, dir, "particles.h5");
    join(path, dir, "cut.h5");
    long size = file_size(good);
    CHECK(size > 2000);
    long cuts[] = {8, 100, 512, 1000, size / 2, size - 100, size - 1};
    for (size_t k = 0; k < sizeof cuts / sizeof *cuts; k++) {
        copy_file(good, path, cuts[k]);
        CHECK(file_size(path) == cuts[k]);
        expect_rejected(path, "HDF5"); /* "not an HDF5 file" or "(HDF5: reason)" */
    }
}

static void test_foreign_hdf5(void)
{
    char dir[LUB_PATH_MAX], path[LUB_PATH_MAX];
    subdir(dir, "foreign");
    join(path, dir, "other.h5");
    /* an HDF5 file of someone else: a dataset, no format attribute */
    hid_t f = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    double v[4] = {1, 2, 3, 4};
    replace_dataset(f, "data", H5T_NATIVE_DOUBLE, 1, 4, 0, v);
    H5Fclose(f);
    expect_rejected(path, "not a lubkit particle file (format attribute missing)");

    /* a format attribute with another value */
    f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t t = H5Tcopy(H5T_C_S1), s = H5Screate(H5S_SCALAR);
    H5Tset_size(t, 3);
    hid_t a = H5Acreate2(f, "format", t, s, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, t, "xyz");
    H5Aclose(a);
    H5Sclose(s);
    H5Tclose(t);
    H5Fclose(f);
    expect_rejected(path, "not a lubkit particle file (format attribute is 'xyz'");

    /* the right format as a variable-length string (as h5py writes it), nothing else */
    f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    H5Adelete(f, "format");
    t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, H5T_VARIABLE);
    s = H5Screate(H5S_SCALAR);
    a = H5Acreate2(f, "format", t, s, H5P_DEFAULT, H5P_DEFAULT);
    const char *fmt = LUB_PARTICLES_FORMAT;
    H5Awrite(a, t, &fmt);
    H5Aclose(a);
    H5Sclose(s);
    H5Tclose(t);
    H5Fclose(f);
    expect_rejected(path, "attribute 'time' missing in /");
    CHECK(open_objects() == 0);
}

static void test_bad_contents(void)
{
    char dir[LUB_PATH_MAX], path[LUB_PATH_MAX];
    lub_particles P;
    memset(&P, 0, sizeof P);
    subdir(dir, "contents");
    join(path, dir, "particles.h5");
    hid_t f;
    size_t n = 50;

    /* position N x 2 */
    write_valid(dir, &P);
    double *buf = calloc(3 * n, sizeof *buf);
    f = edit_open(dir);
    replace_dataset(f, "fields/position", H5T_NATIVE_DOUBLE, 2, n, 2, buf);
    H5Fclose(f);
    expect_rejected(path, "/fields/position has shape 50 x 2, expected N x 3");

    /* pressure with one row too few */
    write_valid(dir, &P);
    f = edit_open(dir);
    replace_dataset(f, "fields/pressure", H5T_NATIVE_DOUBLE, 1, n - 1, 0, buf);
    H5Fclose(f);
    expect_rejected(path, "/fields/pressure has 49 rows, expected 50");

    /* velocity missing */
    write_valid(dir, &P);
    f = edit_open(dir);
    H5Ldelete(f, "fields/velocity", H5P_DEFAULT);
    H5Fclose(f);
    expect_rejected(path, "dataset /fields/velocity missing");

    /* kind = 7 */
    write_valid(dir, &P);
    uint8_t kind[50];
    memcpy(kind, P.kind, n);
    kind[3] = 7;
    f = edit_open(dir);
    replace_dataset(f, "fields/kind", H5T_NATIVE_UINT8, 1, n, 0, kind);
    H5Fclose(f);
    expect_rejected(path, "/fields/kind[3] = 7");

    /* kind stored as floating point */
    write_valid(dir, &P);
    f = edit_open(dir);
    replace_dataset(f, "fields/kind", H5T_NATIVE_DOUBLE, 1, n, 0, buf);
    H5Fclose(f);
    expect_rejected(path, "/fields/kind must hold integers");

    /* a wall particle's patch beyond /patches (2 names) */
    write_valid(dir, &P);
    size_t wall = 0;
    while (wall < n && P.kind[wall] == LUB_FLUID) wall++;
    CHECK(wall < n);
    uint16_t patch[50];
    memcpy(patch, P.patch, sizeof patch);
    patch[wall] = 2;
    f = edit_open(dir);
    replace_dataset(f, "fields/patch", H5T_NATIVE_UINT16, 1, n, 0, patch);
    H5Fclose(f);
    char expected[128];
    snprintf(expected, sizeof expected, "/fields/patch[%zu] = 2, but /patches lists 2 names", wall);
    expect_rejected(path, expected);

    /* level beyond nLevels (2) */
    write_valid(dir, &P);
    uint8_t level[50] = {0};
    level[10] = 2;
    f = edit_open(dir);
    replace_dataset(f, "fields/level", H5T_NATIVE_UINT8, 1, n, 0, level);
    H5Fclose(f);
    expect_rejected(path, "/fields/level[10] = 2");

    /* a non-finite position, and z != 0 in a 2-D file */
    for (int k = 0; k < 2; k++) {
        write_valid(dir, &P);
        double *pos = calloc(3 * n, sizeof *pos);
        if (k == 0) pos[3 * 5 + 1] = NAN;
        if (k == 1) pos[3 * 6 + 2] = 1e-9;
        f = edit_open(dir);
        replace_dataset(f, "fields/position", H5T_NATIVE_DOUBLE, 2, n, 3, pos);
        H5Fclose(f);
        free(pos);
        expect_rejected(path, k == 0 ? "/fields/position[5][1] is not finite"
                                     : "/fields/position[6] has z = 1e-09 in a 2-D file");
    }

    /* an extra field of the wrong length */
    write_valid(dir, &P);
    f = edit_open(dir);
    replace_dataset(f, "fields/extra0", H5T_NATIVE_DOUBLE, 1, n + 1, 0, NULL);
    H5Fclose(f);
    expect_rejected(path, "/fields/extra0 has 51 rows, expected 50");

    /* header: dimension 4, nLevels 0, a missing level group, /patches missing */
    write_valid(dir, &P);
    f = edit_open(dir);
    int four = 4;
    hid_t a = H5Aopen(f, "dimension", H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_INT, &four);
    H5Aclose(a);
    H5Fclose(f);
    expect_rejected(path, "attribute 'dimension' is 4, expected 2 or 3");

    write_valid(dir, &P);
    f = edit_open(dir);
    H5Ldelete(f, "level1", H5P_DEFAULT);
    H5Fclose(f);
    expect_rejected(path, "group /level1 missing (nLevels is 2)");

    write_valid(dir, &P);
    f = edit_open(dir);
    H5Ldelete(f, "patches", H5P_DEFAULT);
    H5Fclose(f);
    expect_rejected(path, "dataset /patches missing");

    write_valid(dir, &P);
    f = edit_open(dir);
    H5Ldelete(f, "fields", H5P_DEFAULT);
    H5Fclose(f);
    expect_rejected(path, "group /fields missing");

    lub_particles_free(&P);
    free(buf);

    /* after all these failures the library is clean and a valid file reads */
    memset(&P, 0, sizeof P);
    write_valid(dir, &P);
    lub_particles Q;
    lub_particles_read(&Q, path);
    check_equal(&P, &Q);
    lub_particles_free(&P);
    lub_particles_free(&Q);
    CHECK(open_objects() == 0);
}

/* Damaged files of issue 28, each with the message the reader gives (also written by
 * -writeDamaged for tests/cases/particleFiles, which reads them in a real process). */
static const struct {
    const char *name, *message;
} damages[] = {
    {"flippedPosition", "cannot read /fields/position: the file is damaged or unreadable (HDF5: "
                        "data error detected by Fletcher32 checksum)"},
    {"negativeTime", "attribute 'time' is -1, expected >= 0"},
    {"zeroL0", "attribute 'l0' of /level1 is 0, expected > 0"},
    {"negativeL0", "attribute 'l0' of /level1 is -5e-06, expected > 0"},
    {"nanPressure", "/fields/pressure[17] is not finite (nan)"},
    {"infVelocity", "/fields/velocity[4][1] is not finite (-inf)"},
    {"nanExtra", "/fields/extra0[9] is not finite (nan)"},
    {"hugeRows", "/fields/position declares 30000000000 values (2.4e+11 bytes) but the file "
                 "holds 0 bytes of it"},
    {"badOrder", "/solver/order[20] = 3: not a place of 0 .. 49, each once"},
};
enum { N_DAMAGES = sizeof damages / sizeof *damages };

/* dir/particles.h5: the valid file of write_valid, damaged as damages[k] says. */
static void damage(const char *dir, int k)
{
    char path[LUB_PATH_MAX];
    join(path, dir, "particles.h5");
    lub_particles P;
    memset(&P, 0, sizeof P);
    write_valid(dir, &P);
    const size_t n = P.n;
    lub_particles_free(&P);
    const char *what = damages[k].name;
    double v[150] = {0};
    hid_t f = edit_open(dir);
    if (strcmp(what, "flippedPosition") == 0) {
        /* a byte of the position data flipped where it lies in the file */
        hid_t d = H5Dopen2(f, "fields/position", H5P_DEFAULT), sp = H5Dget_space(d);
        haddr_t addr = HADDR_UNDEF;
        hsize_t size = 0, off[2];
        unsigned mask;
        CHECK(H5Dget_chunk_info(d, sp, 0, off, &mask, &addr, &size) >= 0);
        H5Sclose(sp);
        H5Dclose(d);
        H5Fclose(f);
        CHECK(addr != HADDR_UNDEF && size == 3 * n * sizeof(double) + 4);
        FILE *fp = fopen(path, "r+b");
        CHECK(fp != NULL);
        if (fp) {
            long at = (long)addr + 8 * 3 * 7 + 3; /* particle 7's x, its fourth byte */
            fseek(fp, at, SEEK_SET);
            int byte = fgetc(fp);
            fseek(fp, at, SEEK_SET);
            fputc(byte ^ 0x10, fp);
            fclose(fp);
        }
        return;
    }
    if (strcmp(what, "negativeTime") == 0) {
        double minus1 = -1;
        hid_t a = H5Aopen(f, "time", H5P_DEFAULT);
        CHECK(H5Awrite(a, H5T_NATIVE_DOUBLE, &minus1) >= 0);
        H5Aclose(a);
    } else if (strcmp(what, "zeroL0") == 0 || strcmp(what, "negativeL0") == 0) {
        double l0 = what[0] == 'z' ? 0 : -5e-6;
        hid_t g = H5Gopen2(f, "level1", H5P_DEFAULT), a = H5Aopen(g, "l0", H5P_DEFAULT);
        CHECK(H5Awrite(a, H5T_NATIVE_DOUBLE, &l0) >= 0);
        H5Aclose(a);
        H5Gclose(g);
    } else if (strcmp(what, "nanPressure") == 0) {
        v[17] = NAN;
        replace_dataset(f, "fields/pressure", H5T_NATIVE_DOUBLE, 1, n, 0, v);
    } else if (strcmp(what, "infVelocity") == 0) {
        v[3 * 4 + 1] = -INFINITY;
        replace_dataset(f, "fields/velocity", H5T_NATIVE_DOUBLE, 2, n, 3, v);
    } else if (strcmp(what, "nanExtra") == 0) {
        v[9] = NAN;
        replace_dataset(f, "fields/extra0", H5T_NATIVE_DOUBLE, 1, n, 0, v);
    } else if (strcmp(what, "hugeRows") == 0) {
        /* 10^10 rows declared, none stored: refused before anything is allocated */
        replace_dataset(f, "fields/position", H5T_NATIVE_DOUBLE, 2, 10000000000ull, 3, NULL);
    } else if (strcmp(what, "badOrder") == 0) {
        uint32_t bad[50];
        for (size_t r = 0; r < n; r++) bad[r] = (uint32_t)r;
        bad[20] = 3;
        replace_dataset(f, "solver/order", H5T_NATIVE_UINT32, 1, n, 0, bad);
    }
    H5Fclose(f);
}

static int write_damaged(const char *root)
{
    lub_mkdir_p(root);
    for (int k = 0; k < N_DAMAGES; k++) {
        char dir[LUB_PATH_MAX];
        join(dir, root, damages[k].name);
        lub_mkdir_p(dir);
        damage(dir, k);
        printf("%s|%s\n", damages[k].name, damages[k].message);
    }
    return test_failed_checks_ ? 1 : 0;
}

/* The rows of a file in id order (what readers that are not ours need), the solver's order
 * kept in /solver/order and restored on reading; a checksum on every dataset (a flipped
 * byte in the positions is found); the header checks of issue 28: a negative time, l0 = 0,
 * a NaN pressure or velocity, a dataset declaring more rows than the file holds, a damaged
 * /solver/order. */
static void test_order_and_checks(void)
{
    char dir[LUB_PATH_MAX], path[LUB_PATH_MAX];
    lub_particles P;
    memset(&P, 0, sizeof P);
    subdir(dir, "order");
    join(path, dir, "particles.h5");
    write_valid(dir, &P); /* random ids: P's order is not the id order */
    size_t n = P.n;
    hid_t f = edit_open(dir);
    uint64_t ids[50];
    hid_t d = H5Dopen2(f, "fields/id", H5P_DEFAULT);
    CHECK(H5Dread(d, H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, ids) >= 0);
    hid_t dcpl = H5Dget_create_plist(d);
    CHECK(H5Pget_nfilters(dcpl) == 1);
    unsigned flags, conf;
    size_t nv = 0;
    CHECK(H5Pget_filter2(dcpl, 0, &flags, &nv, NULL, 0, NULL, &conf) == H5Z_FILTER_FLETCHER32);
    H5Pclose(dcpl);
    H5Dclose(d);
    int sorted = 1;
    for (size_t r = 1; r < n; r++) sorted = sorted && ids[r] > ids[r - 1];
    CHECK(sorted);
    /* row r is P's particle order[r] */
    uint64_t order[50];
    d = H5Dopen2(f, "solver/order", H5P_DEFAULT);
    CHECK(d >= 0 && H5Dread(d, H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, order) >= 0);
    H5Dclose(d);
    for (size_t r = 0; r < n; r++) CHECK(order[r] < n && P.id[order[r]] == ids[r]);

    H5Fclose(f);
    for (int k = 0; k < N_DAMAGES; k++) {
        damage(dir, k);
        expect_rejected(path, damages[k].message);
    }
    lub_particles_free(&P);
    CHECK(open_objects() == 0);
}

/* Slice ra[i] of S (its row first + i) equals F's particle at place[i], bit for bit. */
static int slice_row_is(const lub_particles *S, size_t i, const lub_particles *F, size_t k)
{
    int same = S->kind[i] == F->kind[k] && S->patch[i] == F->patch[k] &&
               S->level[i] == F->level[k] && S->id[i] == F->id[k] &&
               same_bits(&S->p[i], &F->p[k], sizeof(double)) && S->nextra == F->nextra;
    for (int d = 0; d < 3; d++)
        same = same && same_bits(&S->x[d][i], &F->x[d][k], sizeof(double)) &&
               same_bits(&S->u[d][i], &F->u[d][k], sizeof(double));
    for (int e = 0; e < S->nextra && same; e++) {
        const double *v = lub_particles_find_extra(F, S->extra[e].name);
        same = v && same_bits(&S->extra[e].v[i], &v[k], sizeof(double));
    }
    return same;
}

/* The rank-slice read of a parallel restart (lub_particles_read_rows): the slices of a file
 * put at their places give the whole file's particles in the solver's order (the reference:
 * lub_particles_read, whose order is checked above), their rows in id order; a file without
 * /solver/order gives the rows as places; rows beyond the file, and a bad value in a slice
 * (named by its row of the file), are input errors. */
static void test_read_rows(void)
{
    char dir[LUB_PATH_MAX], path[LUB_PATH_MAX];
    lub_particles P, F, S;
    memset(&P, 0, sizeof P);
    subdir(dir, "rows");
    join(path, dir, "particles.h5");
    write_valid(dir, &P); /* random ids: /solver/order is written */
    lub_particles_read(&F, path);
    const size_t n = F.n, cuts[] = {0, 17, 17, 50}; /* an empty slice among them */
    int seen[50] = {0}, ok = 1;
    uint64_t place[50], last_id = 0;
    for (int k = 0; k + 1 < 4; k++) {
        const size_t first = cuts[k], count = cuts[k + 1] - cuts[k];
        lub_particles_read_rows(&S, path, first, count, place);
        CHECK(S.n == count && S.dim == F.dim && S.time == F.time && S.step == F.step);
        CHECK(S.npatches == F.npatches && S.nlevels == F.nlevels && S.nextra == F.nextra);
        for (size_t i = 0; i < count; i++) {
            ok = ok && place[i] < n && !seen[place[i]] && slice_row_is(&S, i, &F, place[i]);
            ok = ok && (first + i == 0 || S.id[i] > last_id); /* id order */
            if (place[i] < n) seen[place[i]] = 1;
            last_id = S.id[i];
        }
        lub_particles_free(&S);
    }
    CHECK(ok);
    for (size_t k = 0; k < n; k++) CHECK(seen[k]);

    /* ids 0 .. n-1 in order (particleGen's): no /solver/order, the places are the rows */
    lub_particles_free(&P);
    rng_state = 7;
    make_particles(&P, 3, 20, 1, 1, 0);
    for (size_t i = 0; i < P.n; i++) P.id[i] = i;
    lub_particles_write(&P, dir);
    lub_particles_read_rows(&S, path, 5, 10, place);
    ok = S.n == 10;
    for (size_t i = 0; i < S.n && ok; i++) ok = place[i] == 5 + i && slice_row_is(&S, i, &P, 5 + i);
    CHECK(ok);
    lub_particles_free(&S);

    CHECK_FATAL(lub_particles_read_rows(&S, path, 15, 10, place),
                "rows 15 .. 25 asked of a file of 20 particles");
    /* a bad kind in row 12: found by the slice holding it, named by its row */
    hid_t f = edit_open(dir);
    hid_t d = H5Dopen2(f, "fields/kind", H5P_DEFAULT), fs = H5Dget_space(d);
    hsize_t at = 12, one = 1;
    hid_t ms = H5Screate_simple(1, &one, NULL);
    uint8_t bad = 7;
    H5Sselect_hyperslab(fs, H5S_SELECT_SET, &at, NULL, &one, NULL);
    CHECK(H5Dwrite(d, H5T_NATIVE_UINT8, ms, fs, H5P_DEFAULT, &bad) >= 0);
    H5Sclose(ms), H5Sclose(fs), H5Dclose(d), H5Fclose(f);
    CHECK_FATAL(lub_particles_read_rows(&S, path, 10, 5, place), "/fields/kind[12] = 7");
    CHECK(S.x[0] == NULL && S.n == 0);
    lub_particles_read_rows(&S, path, 0, 12, place); /* the rows before it */
    CHECK(S.n == 12);
    lub_particles_free(&S);
    lub_particles_free(&P);
    lub_particles_free(&F);
    CHECK(open_objects() == 0);
}

/* A write that cannot happen is a run failure (exit 2) naming the file and the reason. */
static void test_write_failure(void)
{
    char dir[LUB_PATH_MAX];
    join(dir, tmpdir, "does/not/exist");
    lub_particles P;
    rng_state = 5;
    make_particles(&P, 2, 10, 1, 1, 0);
    lub_catcher c;
    if (lub_error_catch(&c) == 0) {
        lub_particles_write(&P, dir);
        lub_error_uncatch();
        CHECK(!"write into a missing folder succeeded");
    } else {
        CHECK(c.status == LUB_EXIT_RUN);
        CHECK_STR(c.message, "does/not/exist/particles.h5: cannot write particle file");
        CHECK_STR(c.message, "HDF5:");
    }
    CHECK(open_objects() == 0);

    /* a non-finite position is a failed run: nothing is written */
    char ok_dir[LUB_PATH_MAX];
    subdir(ok_dir, "nonfinite");
    P.x[1][3] = INFINITY;
    if (lub_error_catch(&c) == 0) {
        lub_particles_write(&P, ok_dir);
        lub_error_uncatch();
        CHECK(!"a non-finite position was written");
    } else {
        CHECK(c.status == LUB_EXIT_RUN);
        CHECK_STR(c.message, "particle 3 (id ");
        CHECK_STR(c.message, "non-finite position");
    }
    char h5[LUB_PATH_MAX];
    CHECK(file_size(join(h5, ok_dir, "particles.h5")) < 0);
    lub_particles_free(&P);
}

/* ---------------------------------------------------------------------------------------- */
/* Case collection                                                                          */

static void write_time(const lub_case *c, double t, size_t n, int nextra)
{
    char name[64], dir[LUB_PATH_MAX];
    lub_particles P;
    make_particles(&P, 2, n, 2, 2, nextra);
    P.time = t;
    lub_time_name(t, 6, name, sizeof name);
    lub_timedir_begin(c, name, dir);
    lub_particles_write(&P, dir);
    lub_timedir_commit(c, name, dir);
    lub_particles_free(&P);
}

static void test_case_xdmf(void)
{
    char root[LUB_PATH_MAX], path[LUB_PATH_MAX], p2[LUB_PATH_MAX];
    subdir(root, "case");
    lub_case c;
    lub_case_open(&c, root);
    CHECK(lub_case_xdmf_write(&c) == 0); /* nothing yet: no file */
    CHECK(file_size(lub_case_path(&c, path, "particles.xdmf")) < 0);

    rng_state = 31;
    write_time(&c, 0.002, 30, 1);
    write_time(&c, 0, 20, 0);
    write_time(&c, 0.01, 40, 2);
    lub_mkdir_p(lub_case_path(&c, path, "0.005"));    /* a time without particles */
    lub_mkdir_p(lub_case_path(&c, path, "constant")); /* not a time */
    lub_mkdir_p(lub_case_path(&c, path, "0.007"));    /* a damaged particle file */
    FILE *fp = fopen(lub_case_path(&c, path, "0.007/particles.h5"), "w");
    fputs("garbage", fp);
    fclose(fp);

    /* the damaged time is left out with a warning on stderr */
    fflush(stderr);
    int saved = dup(2), fd = open(lub_case_path(&c, p2, "warn.txt"), O_WRONLY | O_CREAT, 0644);
    dup2(fd, 2);
    close(fd);
    size_t listed = lub_case_xdmf_write(&c);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    CHECK(listed == 3);
    char *w = read_text(lub_case_path(&c, p2, "warn.txt"));
    CHECK_STR(w, "0.007/particles.h5: not an HDF5 file");
    free(w);

    char *x = read_text(lub_case_path(&c, path, "particles.xdmf"));
    CHECK(x != NULL);
    if (x) {
        CHECK_STR(x, "GridType=\"Collection\" CollectionType=\"Temporal\"");
        const char *a = strstr(x, "<Time Value=\"0\"/>");
        const char *b = strstr(x, "<Time Value=\"0.002\"/>");
        const char *d = strstr(x, "<Time Value=\"0.01\"/>");
        CHECK(a && b && d && a < b && b < d); /* in time order */
        CHECK_STR(x, ">0/particles.h5:/fields/position<");
        CHECK_STR(x, "<DataItem Dimensions=\"20 3\" NumberType=\"Float\" Precision=\"8\" "
                     "Format=\"HDF\">0/particles.h5:/fields/position</DataItem>");
        CHECK_STR(x, "Dimensions=\"30 3\" NumberType=\"Float\" Precision=\"8\" "
                     "Format=\"HDF\">0.002/particles.h5:/fields/velocity<");
        CHECK_STR(x, "Dimensions=\"40\" NumberType=\"UInt\" Precision=\"4\" "
                     "Format=\"HDF\">0.01/particles.h5:/xdmf/connectivity<");
        CHECK_STR(x, ">0.01/particles.h5:/fields/extra1<");
        CHECK(strstr(x, "0.005/") == NULL && strstr(x, "0.007/") == NULL);
        CHECK(strstr(x, ">0/particles.h5:/fields/extra0<") == NULL); /* time 0 has none */
        free(x);
    }

    /* all particle files gone: the collection goes too */
    lub_rm_rf(lub_case_path(&c, p2, "0"));
    lub_rm_rf(lub_case_path(&c, p2, "0.002"));
    lub_rm_rf(lub_case_path(&c, p2, "0.01"));
    lub_rm_rf(lub_case_path(&c, p2, "0.007"));
    CHECK(lub_case_xdmf_write(&c) == 0);
    CHECK(file_size(path) < 0);
}

/* ---------------------------------------------------------------------------------------- */

/* Sample case for tests/cases/particleFiles: 2-D, levels, patches, extras, three times. */
static int write_sample_case(const char *root)
{
    lub_case c;
    if (lub_mkdir_p(root) != 0) return 1;
    lub_case_open(&c, root);
    rng_state = 2024;
    write_time(&c, 0, 120, 0);
    write_time(&c, 0.001, 130, 1);
    write_time(&c, 0.002, 140, 2);
    char dir[LUB_PATH_MAX];
    lub_particles P;
    make_particles(&P, 3, 0, 1, 0, 0); /* an empty 3-D set in its own folder */
    lub_case_pathf(&c, dir, "empty");
    lub_mkdir_p(dir);
    lub_particles_write(&P, dir);
    lub_particles_free(&P);
    return lub_case_xdmf_write(&c) == 3 ? 0 : 1;
}

/* RUN only the tests whose name contains argv[1] when given (debugging). */
static const char *only = NULL;
#define RUN_SOME(fn)                                                                               \
    do {                                                                                           \
        if (!only || strstr(#fn, only)) RUN(fn);                                                   \
    } while (0)

int main(int argc, char **argv)
{
    if (argc == 2) only = argv[1];
    if (argc == 3 && strcmp(argv[1], "-writeCase") == 0) return write_sample_case(argv[2]);
    if (argc == 3 && strcmp(argv[1], "-writeDamaged") == 0) return write_damaged(argv[2]);
    if (argc == 3 && strcmp(argv[1], "-read") == 0) { /* for the case test: exit status */
        lub_particles P;
        lub_set_program("particles_io_test");
        lub_particles_read(&P, argv[2]);
        printf("read %zu particles\n", P.n);
        lub_particles_free(&P);
        return 0;
    }
    snprintf(tmpdir, sizeof tmpdir, "%s/lub_particles_io_XXXXXX",
             getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN_SOME(test_roundtrip_2d);
    RUN_SOME(test_roundtrip_3d);
    RUN_SOME(test_roundtrip_extras_levels);
    RUN_SOME(test_roundtrip_fluid_only);
    RUN_SOME(test_roundtrip_empty);
    RUN_SOME(test_sidecar);
    RUN_SOME(test_missing_file);
    RUN_SOME(test_not_hdf5);
    RUN_SOME(test_truncated);
    RUN_SOME(test_foreign_hdf5);
    RUN_SOME(test_bad_contents);
    RUN_SOME(test_order_and_checks);
    RUN_SOME(test_read_rows);
    RUN_SOME(test_write_failure);
    RUN_SOME(test_case_xdmf);
    lub_rm_rf(tmpdir);
    return test_summary();
}
