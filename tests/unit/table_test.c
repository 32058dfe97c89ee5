/* Unit tests of src/io/table.c: the table format every utility reads and writes. */
#include <dirent.h>
#include <float.h>
#include <stdlib.h>
#include <unistd.h>

#include "io/table.h"
#include "test.h"

static char dir[256];

/* Write text to <dir>/<name>; returns the path (static buffer, one at a time). */
static const char *put(const char *name, const char *text)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *fp = fopen(path, "w");
    fputs(text, fp);
    fclose(fp);
    return path;
}

static void test_roundtrip_exact(void)
{
    /* values whose shortest decimal form is long, extremes and a subnormal: %.17g must give
     * back the same bits */
    const double v[] = {0.1,
                        1.0 / 3.0,
                        -2.0 / 7.0,
                        1e-300,
                        DBL_MAX,
                        -DBL_MAX,
                        DBL_MIN,
                        5e-324,
                        0.0,
                        -0.0,
                        123456789012345678.0,
                        3.14159265358979323846,
                        -1e-17,
                        6.02214076e23,
                        1.0 - DBL_EPSILON,
                        4.9406564584124654e-324};
    const size_t n = sizeof v / sizeof v[0];
    char path[512];
    snprintf(path, sizeof path, "%s/rt.dat", dir);
    lub_output o;
    lub_output_open(&o, path);
    lub_table_write_header(o.fp, "i v[Pa] w");
    for (size_t i = 0; i < n; i++) {
        double row[3] = {(double)i, v[i], -v[i]};
        lub_table_write_row(o.fp, row, 3);
    }
    lub_output_close(&o);

    lub_table t;
    lub_table_read(&t, path);
    CHECK(t.ncol == 3 && t.nrow == n);
    CHECK_STR(t.names[1], "v[Pa]");
    int bad = 0;
    for (size_t i = 0; i < n && t.nrow == n; i++) {
        double a = lub_table_at(&t, i, 1), b = lub_table_at(&t, i, 2);
        if (memcmp(&a, &v[i], sizeof a) != 0) bad++;
        double mv = -v[i];
        if (memcmp(&b, &mv, sizeof b) != 0) bad++;
        if (lub_table_at(&t, i, 0) != (double)i) bad++;
    }
    CHECK(bad == 0);
    lub_table_free(&t);

    /* the atomic output left no temporary file behind */
    DIR *d = opendir(dir);
    int tmp = 0;
    for (struct dirent *e; (e = readdir(d));)
        if (strstr(e->d_name, ".tmp")) tmp++;
    closedir(d);
    CHECK(tmp == 0);
}

static void test_lookup_units(void)
{
    lub_table t;
    lub_table_read(&t, put("u.dat", "# x[m] p[Pa]  h\n0 1 2\n"));
    CHECK(lub_table_find(&t, "x") == 0);
    CHECK(lub_table_find(&t, "x[m]") == 0);
    CHECK(lub_table_find(&t, "p") == 1);
    CHECK(lub_table_find(&t, "p[Pa]") == 1);
    CHECK(lub_table_find(&t, "p[bar]") == -1); /* a unit asked for must match */
    CHECK(lub_table_find(&t, "h") == 2);
    CHECK(lub_table_find(&t, "H") == -1);
    CHECK(lub_table_find(&t, "") == -1);
    CHECK(lub_table_col(&t, "h") == 2);
    CHECK_FATAL(lub_table_col(&t, "pp"), "no column 'pp' (did you mean 'p'?)");
    CHECK_STR(test_last_error, "x[m] p[Pa] h");
    CHECK_STR(test_last_error, "u.dat");
    CHECK_FATAL(lub_table_col(&t, "velocity"), "the columns are: x[m] p[Pa] h");
    lub_table_free(&t);
}

static void test_comments_blanks(void)
{
    lub_table t;
    lub_table_read(&t, put("c.dat", "\n  \n#x y\n# a comment\n1 2\n\n  # indented comment\n"
                                    "\t3\t4  \r\n5e-3 -6.5E+2\n"));
    CHECK(t.ncol == 2 && t.nrow == 3);
    CHECK_STR(t.names[0], "x");
    if (t.nrow == 3) {
        CHECK(lub_table_at(&t, 1, 0) == 3.0 && lub_table_at(&t, 1, 1) == 4.0);
        CHECK(lub_table_at(&t, 2, 0) == 5e-3 && lub_table_at(&t, 2, 1) == -650.0);
    }
    lub_table_free(&t);

    lub_table_read(&t, put("h.dat", "# a b c\n"));
    CHECK(t.ncol == 3 && t.nrow == 0);
    lub_table_free(&t);
}

static void test_errors(void)
{
    lub_table t;
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "# x p h\n1 2 3\n\n# c\n4 5 6\n7 8 9\n1 2\n")),
                "p.dat:7: expected 3 values, found 2");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "# x p h\n1 2 3 4 5\n")),
                "p.dat:2: expected 3 values, found 5");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "# x p\n1 2\n1 abc\n")),
                "p.dat:3: 'abc' is not a number (column 2, 'p')");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "# x p\n1 2x\n")),
                "p.dat:2: '2x' is not a number (column 2, 'p')");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "# x p[Pa]\n1 2 # trailing comment\n")),
                "p.dat:2: expected 2 values, found 5");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "# x p[Pa]\nnan 2\n")),
                "p.dat:2: 'nan' is not a finite number (column 1, 'x')");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "# x p[Pa]\n1 -inf\n")),
                "p.dat:2: '-inf' is not a finite number (column 2, 'p[Pa]')");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "# x p[Pa]\n1 1e999\n")),
                "p.dat:2: '1e999' is not a finite number");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "x p\n1 2\n")),
                "p.dat:1: missing header line '# name ...'");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "1 2\n")),
                "p.dat:1: missing header line '# name ...'");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "#\n1 2\n")),
                "p.dat:1: missing header line '# name ...' (no column names)");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "")), "p.dat:1: missing header line");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "# x p x[m]\n")), "p.dat:1: duplicate column 'x'");
    CHECK_FATAL(lub_table_read(&t, put("p.dat", "# x [m]\n")), "p.dat:1: column name '[m]'");
    char missing[512];
    snprintf(missing, sizeof missing, "%s/nonexistent.dat", dir);
    CHECK_FATAL(lub_table_read(&t, missing), "nonexistent.dat");
    CHECK_STR(test_last_error, "No such file");
    CHECK_FATAL(lub_table_read(&t, dir), "directory");
    /* underflow is not an error: the value is the correctly rounded tiny number */
    lub_table_read(&t, put("p.dat", "# x\n1e-320\n"));
    CHECK(t.nrow == 1 && lub_table_at(&t, 0, 0) > 0 && lub_table_at(&t, 0, 0) < 1e-319);
    lub_table_free(&t);
}

static void test_output_errors(void)
{
    lub_output o;
    char bad[512];
    snprintf(bad, sizeof bad, "%s/no/such/dir/out.dat", dir);
    CHECK_FATAL(lub_output_open(&o, bad), "no/such/dir/out.dat");

    /* -o over an existing file replaces it only at close */
    const char *p = put("o.dat", "old\n");
    char path[512];
    snprintf(path, sizeof path, "%s", p);
    lub_output_open(&o, path);
    lub_table_write_header(o.fp, "a");
    FILE *fp = fopen(path, "r");
    char buf[64] = "";
    CHECK(fgets(buf, sizeof buf, fp) && strcmp(buf, "old\n") == 0);
    fclose(fp);
    lub_output_close(&o);
    fp = fopen(path, "r");
    CHECK(fgets(buf, sizeof buf, fp) && strcmp(buf, "# a\n") == 0);
    fclose(fp);

    /* a write error (full device) is reported at close */
    if (access("/dev/full", W_OK) == 0) {
        lub_output f = {0};
        FILE *full = fopen("/dev/full", "w");
        f.fp = full;
        f.atomic = 0;
        for (int i = 0; i < 10000; i++) fprintf(f.fp, "0123456789\n");
        CHECK_FATAL(lub_output_close(&f), "error writing");
        fclose(full);
    }
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/lub_table_test.XXXXXX");
    if (!mkdtemp(dir)) return 1;
    RUN(test_roundtrip_exact);
    RUN(test_lookup_units);
    RUN(test_comments_blanks);
    RUN(test_errors);
    RUN(test_output_errors);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) printf("cannot remove %s\n", dir);
    return test_summary();
}
