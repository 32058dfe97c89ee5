/* Unit tests of case directories, time folders and atomic output (src/io/case.c), and of
 * the option parser's number parsing (src/core/args.c). */
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/args.h"
#include "io/case.h"
#include "test.h"

static char root[64];

static int exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0;
}

static void mk(const char *rel)
{
    char p[LUB_PATH_MAX];
    snprintf(p, sizeof p, "%s/%s", root, rel);
    CHECK(lub_mkdir_p(p) == 0);
}

static void test_time_names(void)
{
    char b[64];
    CHECK(strcmp(lub_time_name(0.001, 6, b, sizeof b), "0.001") == 0);
    CHECK(strcmp(lub_time_name(0.024, 6, b, sizeof b), "0.024") == 0);
    CHECK(strcmp(lub_time_name(3 * 0.1, 6, b, sizeof b), "0.3") == 0); /* 0.30000000000000004 */
    CHECK(strcmp(lub_time_name(1e-7, 6, b, sizeof b), "1e-07") == 0);   /* as OpenFOAM prints */
    CHECK(strcmp(lub_time_name(0.0, 6, b, sizeof b), "0") == 0);
    CHECK(strcmp(lub_time_name(-0.0, 6, b, sizeof b), "0") == 0);
    CHECK(strcmp(lub_time_name(0.0123456789, 4, b, sizeof b), "0.01235") == 0);
}

static void test_times(void)
{
    lub_case c;
    lub_case_open(&c, root);
    mk("0");
    mk("0.002");
    mk("0.0005");
    mk("0.01");
    mk("system");
    mk("1e-07x"); /* not a number */
    mk(".0.003.tmp1"); /* hidden temporary */
    char p[LUB_PATH_MAX];
    FILE *fp = fopen(lub_case_path(&c, p, "0.5"), "w"); /* a file, not a folder */
    fclose(fp);
    lub_time *t;
    size_t n = lub_case_times(&c, &t);
    CHECK(n == 4);
    if (n == 4) {
        CHECK(strcmp(t[0].name, "0") == 0 && strcmp(t[1].name, "0.0005") == 0);
        CHECK(strcmp(t[2].name, "0.002") == 0 && strcmp(t[3].name, "0.01") == 0);
    }
    free(t);
    n = lub_case_select_times(&c, NULL, 0, 1, &t);
    CHECK(n == 3 && t[0].value == 0.0005);
    free(t);
    n = lub_case_select_times(&c, NULL, 1, 0, &t);
    CHECK(n == 1 && strcmp(t[0].name, "0.01") == 0);
    free(t);
    n = lub_case_select_times(&c, "0.0005:0.002", 0, 0, &t);
    CHECK(n == 2 && t[1].value == 0.002);
    free(t);
    n = lub_case_select_times(&c, "0,0.01", 0, 0, &t);
    CHECK(n == 2 && t[0].value == 0 && t[1].value == 0.01);
    free(t);
    n = lub_case_select_times(&c, "0.001:", 0, 0, &t);
    CHECK(n == 2);
    free(t);
    CHECK_FATAL(lub_case_select_times(&c, "0.3", 0, 0, &t), "matches the selection -time 0.3 (available: 0 0.0005 0.002 0.01)");
    CHECK_FATAL(lub_case_select_times(&c, "0.1:x", 0, 0, &t), "-time: '0.1:x' is not a time");
}

static void test_timedir_atomic(void)
{
    lub_case c;
    lub_case_open(&c, root);
    char dir[LUB_PATH_MAX], p[LUB_PATH_MAX];
    lub_timedir_begin(&c, "0.004", dir);
    CHECK(!exists(lub_case_path(&c, p, "0.004"))); /* invisible until committed */
    char fpath[LUB_PATH_MAX + 16];
    snprintf(fpath, sizeof fpath, "%s/f.txt", dir);
    FILE *fp = fopen(fpath, "w");
    fputs("new\n", fp);
    fclose(fp);
    lub_timedir_commit(&c, "0.004", dir);
    CHECK(exists(lub_case_path(&c, p, "0.004/f.txt")));
    CHECK(!exists(dir));
    /* replacing an existing folder */
    lub_timedir_begin(&c, "0.004", dir);
    lub_timedir_commit(&c, "0.004", dir);
    CHECK(exists(lub_case_path(&c, p, "0.004")) && !exists(lub_case_path(&c, p, "0.004/f.txt")));

    lub_atomic_file f;
    FILE *o = lub_atomic_open(&f, lub_case_path(&c, p, "a.dat"));
    CHECK(o != NULL);
    fputs("x\n", o);
    CHECK(!exists(p));
    CHECK(lub_atomic_close(&f) == 0);
    CHECK(exists(p));
    o = lub_atomic_open(&f, lub_case_path(&c, p, "b.dat"));
    lub_atomic_abort(&f);
    CHECK(!exists(p));
    lub_postproc_path(&c, "cost", "0", "cost.dat", p);
    CHECK(exists(lub_case_path(&c, dir, "postProcessing/cost/0")));
}

static void test_open_errors(void)
{
    lub_case c;
    CHECK_FATAL(lub_case_open(&c, "/nonexistent/case"), "case directory '/nonexistent/case' does not exist");
}

static void test_parse_numbers(void)
{
    double v;
    long i;
    CHECK(lub_parse_real("1.5e-6", &v) == 0 && v == 1.5e-6);
    CHECK(lub_parse_real("1.5x", &v) != 0);
    CHECK(lub_parse_real("", &v) != 0);
    CHECK(lub_parse_real("nan", &v) != 0);
    CHECK(lub_parse_real("1e999", &v) != 0);
    CHECK(lub_parse_real("1e-320", &v) == 0); /* subnormal is a number */
    CHECK(lub_parse_int("42", &i) == 0 && i == 42);
    CHECK(lub_parse_int("4.2", &i) != 0);
}

int main(void)
{
    snprintf(root, sizeof root, "/tmp/lubcase%ld", (long)getpid());
    lub_mkdir_p(root);
    RUN(test_time_names);
    RUN(test_times);
    RUN(test_timedir_atomic);
    RUN(test_open_errors);
    RUN(test_parse_numbers);
    lub_rm_rf(root);
    return test_summary();
}
