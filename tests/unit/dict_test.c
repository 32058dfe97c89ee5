/* Unit tests of the dictionary layer (src/io/dict.c): valid files and every error class,
 * each with the exact file:line:column in the message. */
#include <stdlib.h>
#include <unistd.h>

#include "io/dict.h"
#include "test.h"

static const char *controlDict = "# run control\n"                  /* 1 */
                                 "application: lubFoam\n"           /* 2 */
                                 "endTime:     0.03\n"              /* 3 */
                                 "deltaT:      1.0e-6\n"            /* 4 */
                                 "nSteps:      100\n"               /* 5 */
                                 "adjustTimeStep: false\n"          /* 6 */
                                 "gravity:     { g: [0, -9.81] }\n" /* 7 */
                                 "walls:\n"                         /* 8 */
                                 "  lowerWall:\n"                   /* 9 */
                                 "    velocity: [1.2, 0]\n"         /* 10 */
                                 "  cylinder: { radius: 0.04 }\n"   /* 11 */
                                 "levels:\n"                        /* 12 */
                                 "  - { l0: 5e-6 }\n"               /* 13 */
                                 "  - { l0: 4e-5 }\n";              /* 14 */

static void test_valid(void)
{
    lub_dict *d = lub_dict_parse("system/controlDict.yaml", controlDict);
    lub_node *r = lub_dict_root(d);
    CHECK(strcmp(lub_dict_str(r, "application"), "lubFoam") == 0);
    CHECK_NEAR(lub_dict_real(r, "endTime", LUB_POSITIVE), 0.03, 0);
    CHECK_NEAR(lub_dict_real(r, "deltaT", LUB_POSITIVE), 1e-6, 0);
    CHECK(lub_dict_int(r, "nSteps", 0, 1000000) == 100);
    CHECK(lub_dict_bool_or(r, "adjustTimeStep", 1) == 0);
    CHECK_NEAR(lub_dict_real_or(r, "maxCourant", 0.24, LUB_POSITIVE), 0.24, 0); /* default */
    CHECK(lub_dict_int_or(r, "purgeWrite", 7, 0, 100) == 7);
    CHECK(strcmp(lub_dict_str_or(r, "startFrom", "latestTime"), "latestTime") == 0);
    double g[3] = {0, 0, 0};
    CHECK(lub_dict_vec(lub_dict_map(r, "gravity"), "g", g, 2, 3, LUB_ANY) == 2);
    CHECK_NEAR(g[1], -9.81, 0);
    lub_node *walls = lub_dict_map(r, "walls");
    CHECK(lub_node_size(walls) == 2);
    CHECK(strcmp(lub_node_key_at(walls, 1), "cylinder") == 0);
    lub_node *cyl = lub_node_value_at(walls, 1);
    CHECK_NEAR(lub_dict_real(cyl, "radius", LUB_POSITIVE), 0.04, 0);
    CHECK(strcmp(lub_node_path(lub_dict_get(cyl, "radius")), "walls.cylinder.radius") == 0);
    lub_node *lw = lub_node_value_at(walls, 0);
    double v[3];
    CHECK(lub_dict_vec(lw, "velocity", v, 2, 3, LUB_ANY) == 2 && v[0] == 1.2);
    CHECK(lub_node_line(lub_dict_get(lw, "velocity")) == 10);
    lub_node *lev = lub_dict_seq(r, "levels");
    CHECK(lub_node_size(lev) == 2);
    lub_node *l1 = lub_node_expect_map(lub_node_item(lev, 1));
    CHECK_NEAR(lub_dict_real(l1, "l0", LUB_POSITIVE), 4e-5, 0);
    CHECK(strcmp(lub_node_path(lub_dict_get(l1, "l0")), "levels.1.l0") == 0);
    lub_dict_real(lub_node_expect_map(lub_node_item(lev, 0)), "l0", LUB_POSITIVE);
    lub_dict_finish(d); /* every key asked for: no error */
    lub_dict_free(d);
}

static void test_choice_and_bool(void)
{
    lub_dict *d = lub_dict_parse("s.yaml", "scheme: crankNicolson\nflag: yes\n");
    lub_node *r = lub_dict_root(d);
    const char *ch[] = {"explicit", "crankNicolson", NULL};
    CHECK(lub_dict_choice(r, "scheme", ch, -1) == 1);
    CHECK(lub_dict_choice(r, "absent", ch, 0) == 0);
    CHECK(lub_dict_bool_or(r, "flag", 0) == 1);
    lub_dict_finish(d);
    lub_dict_free(d);
}

static void test_unknown_key(void)
{
    lub_dict *d = lub_dict_parse("system/schemes.yaml", "laplacian: standard\n"
                                                        "viscosity: implicit\n"
                                                        "gradiant: lsmps\n");
    lub_node *r = lub_dict_root(d);
    lub_dict_str_or(r, "laplacian", "standard");
    lub_dict_str_or(r, "gradient", "lsmps");
    lub_dict_str_or(r, "viscosity", "implicit");
    CHECK_FATAL(lub_dict_finish(d),
                "system/schemes.yaml:3:1: unknown key 'gradiant' (did you mean 'gradient'?)");
    lub_dict_free(d);

    /* nested, with no close candidate: the valid keys are listed */
    d = lub_dict_parse("m.yaml", "gravity:\n  g: [0, -9.81]\n  zzzzzz: 1\n");
    lub_node *gr = lub_dict_map(lub_dict_root(d), "gravity");
    double g[3];
    lub_dict_vec(gr, "g", g, 2, 3, LUB_ANY);
    CHECK_FATAL(lub_dict_finish(d),
                "m.yaml:3:3: unknown key 'zzzzzz' in 'gravity' (valid keys: g)");
    lub_dict_free(d);

    /* a mapping nobody looked into is not judged; its parent key must be known */
    d = lub_dict_parse("m.yaml", "gravity: { g: 1 }\nviscosity: { anything: 1 }\n");
    lub_dict_find(lub_dict_root(d), "gravity");
    lub_dict_find(lub_dict_root(d), "viscosity");
    lub_dict_finish(d);
    lub_dict_free(d);
}

static void test_wrong_type(void)
{
    lub_dict *d = lub_dict_parse("system/controlDict.yaml",
                                 "endTime: abc\nnSteps: 1.5\ng: 3\nwalls: [1, 2]\nflag: maybe\n"
                                 "name: { a: 1 }\n");
    lub_node *r = lub_dict_root(d);
    CHECK_FATAL(lub_dict_real(r, "endTime", LUB_POSITIVE),
                "system/controlDict.yaml:1:10: 'endTime' expects a real number, found 'abc'");
    CHECK_FATAL(lub_dict_int(r, "nSteps", 0, 10),
                "controlDict.yaml:2:9: 'nSteps' expects an integer, found '1.5'");
    double v[3];
    CHECK_FATAL(lub_dict_vec(r, "g", v, 2, 3, LUB_ANY),
                "controlDict.yaml:3:4: 'g' expects a list of 2 to 3 numbers");
    CHECK_FATAL(lub_dict_map(r, "walls"), "controlDict.yaml:4:8: 'walls' expects a mapping");
    CHECK_FATAL(lub_dict_bool_or(r, "flag", 0),
                "controlDict.yaml:5:7: 'flag' expects true or false, found 'maybe'");
    CHECK_FATAL(lub_dict_str(r, "name"),
                "controlDict.yaml:6:7: 'name' expects a single value, found a mapping");
    lub_dict_free(d);
}

static void test_out_of_range(void)
{
    lub_dict *d = lub_dict_parse("system/controlDict.yaml",
                                 "deltaT: -1e-6\nnSteps: 1000\ng: [0, 1, 2, 3]\nalpha: 1.5\n"
                                 "scheme: crankNicholson\n");
    lub_node *r = lub_dict_root(d);
    CHECK_FATAL(lub_dict_real(r, "deltaT", LUB_POSITIVE),
                "system/controlDict.yaml:1:9: 'deltaT' must be > 0, found '-1e-6'");
    CHECK_FATAL(lub_dict_int(r, "nSteps", 0, 10),
                "controlDict.yaml:2:9: 'nSteps' must be between 0 and 10, found '1000'");
    double v[4];
    CHECK_FATAL(lub_dict_vec(r, "g", v, 2, 3, LUB_ANY),
                "controlDict.yaml:3:4: 'g' expects 2 to 3 numbers, found 4");
    CHECK_FATAL(lub_dict_real(r, "alpha", LUB_UNIT),
                "controlDict.yaml:4:8: 'alpha' must be >= 0 and <= 1, found '1.5'");
    const char *ch[] = {"explicit", "crankNicolson", NULL};
    CHECK_FATAL(lub_dict_choice(r, "scheme", ch, -1),
                "controlDict.yaml:5:9: 'scheme' must be one of: explicit, crankNicolson; found "
                "'crankNicholson' (did you mean 'crankNicolson'?)");
    lub_dict_free(d);
}

static void test_missing_key(void)
{
    lub_dict *d = lub_dict_parse("constant/transportProperties.yaml", "rho: 850\nsub:\n  a: 1\n");
    lub_node *r = lub_dict_root(d);
    CHECK_FATAL(lub_dict_real(r, "nu", LUB_POSITIVE),
                "constant/transportProperties.yaml:1:1: missing required key 'nu'");
    CHECK_FATAL(lub_dict_real(lub_dict_map(r, "sub"), "b", LUB_ANY),
                "transportProperties.yaml:3:3: missing required key 'b' in 'sub'");
    lub_dict_free(d);
}

static void test_malformed(void)
{
    CHECK_FATAL(lub_dict_parse("system/bad.yaml", "a: 1\nb: [1, 2\nc: 3\n"), "system/bad.yaml:");
    CHECK_STR(test_last_error, "YAML syntax error");
    CHECK_FATAL(lub_dict_parse("system/bad.yaml", "a: 1\n  b: 2\n"), "system/bad.yaml:2:");
    CHECK_FATAL(lub_dict_parse("system/list.yaml", "- 1\n- 2\n"),
                "system/list.yaml:1:1: expected a mapping");
    CHECK_FATAL(lub_dict_parse("system/dup.yaml", "a: 1\nb: 2\na: 3\n"),
                "system/dup.yaml:3:1: duplicate key 'a' (first given at line 1)");
    CHECK_FATAL(lub_dict_parse("x.yaml", "a: 1\n\tb: 2\n"), "x.yaml:2:");
    /* an empty file is an empty mapping */
    lub_dict *d = lub_dict_parse("empty.yaml", "# nothing\n");
    CHECK(lub_node_size(lub_dict_root(d)) == 0);
    lub_dict_free(d);
}

/* What libyaml accepts but a dictionary must not: keys after a second '---' (they would be
 * ignored), an alias bomb (nested aliases multiplying to 10^9 nodes), a NUL byte (libyaml
 * reports it by byte offset: the message must give its line, not 1:1). */
static void test_yaml_limits(void)
{
    CHECK_FATAL(lub_dict_parse("system/two.yaml", "a: 1\nb: 2\n---\nc: 3\n"),
                "system/two.yaml:3:1: a second YAML document begins here");
    CHECK_FATAL(lub_dict_parse("system/two.yaml", "a: 1\n...\n---\n"), "two.yaml:3:1: a second");
    /* one document, explicitly started and ended, is fine */
    lub_dict *d = lub_dict_parse("one.yaml", "---\na: 1\n...\n");
    CHECK(lub_dict_int(lub_dict_root(d), "a", 0, 9) == 1);
    lub_dict_free(d);

    const char *bomb = "a: &a [x, x, x, x, x, x, x, x, x]\n"
                       "b: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
                       "c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]\n"
                       "d: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c]\n"
                       "e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d]\n"
                       "f: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e]\n"
                       "g: &g [*f, *f, *f, *f, *f, *f, *f, *f, *f]\n"
                       "h: &h [*g, *g, *g, *g, *g, *g, *g, *g, *g]\n"
                       "i: &i [*h, *h, *h, *h, *h, *h, *h, *h, *h]\n";
    CHECK_FATAL(lub_dict_parse("system/bomb.yaml", bomb), "system/bomb.yaml:");
    CHECK_STR(test_last_error, "aliases (*name) expand to more than 10000 values");
    /* aliases that repeat a setting are fine */
    d = lub_dict_parse("alias.yaml", "base: &w { l0: 1e-5 }\nfine: *w\ncoarse: *w\n");
    CHECK_NEAR(lub_dict_real(lub_dict_map(lub_dict_root(d), "coarse"), "l0", LUB_POSITIVE), 1e-5,
               0);
    lub_dict_free(d);

    static const char nul[] = "a: 1\nb: 2\nc: x\0y\n";
    lub_dict *dn = NULL;
    char path[] = "/tmp/lubdictnulXXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0 && write(fd, nul, sizeof nul - 1) == (ssize_t)(sizeof nul - 1));
    close(fd);
    CHECK_FATAL(dn = lub_dict_read(path),
                ":3:5: unreadable text: control characters are not allowed");
    CHECK_STR(test_last_error, "(byte 0x00)");
    (void)dn;
    unlink(path);

    /* a list of a fixed length asked for with a scalar names the length once */
    d = lub_dict_parse("m.yaml", "g: down\n");
    double g[2];
    CHECK_FATAL(
        lub_dict_vec(lub_dict_root(d), "g", g, 2, 2, LUB_ANY),
        "m.yaml:1:4: 'g' expects a list of 2 numbers like [0, 1], found a single value 'down'");
    lub_dict_free(d);
}

static void test_files(void)
{
    char path[] = "/tmp/lubdictXXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    const char *txt = "rho: 850\nnu: 2.25e-4\n";
    CHECK(write(fd, txt, strlen(txt)) == (ssize_t)strlen(txt));
    close(fd);
    lub_dict *d = lub_dict_read(path);
    CHECK_NEAR(lub_dict_real(lub_dict_root(d), "nu", LUB_POSITIVE), 2.25e-4, 0);
    CHECK(strcmp(lub_dict_path(d), path) == 0);
    lub_dict_free(d);
    unlink(path);
    CHECK(lub_dict_read_optional("/nonexistent/dir/x.yaml") == NULL);
    CHECK_FATAL(lub_dict_read("/nonexistent/dir/x.yaml"),
                "cannot open dictionary '/nonexistent/dir/x.yaml'");
}

/* lub_dict_substitute: the same file under another name parses the given text, messages
 * name the given name; other files are read as they are; NULL ends it. */
static void test_substitute(void)
{
    char dir[] = "/tmp/lubdictsubXXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char a[128], a2[160], b[128];
    snprintf(a, sizeof a, "%s/a.yaml", dir);
    snprintf(a2, sizeof a2, "%s/./a.yaml", dir);
    snprintf(b, sizeof b, "%s/b.yaml", dir);
    FILE *fp = fopen(a, "w");
    CHECK(fp && fputs("nu: 1\n", fp) >= 0 && fclose(fp) == 0);
    fp = fopen(b, "w");
    CHECK(fp && fputs("nu: 2\n", fp) >= 0 && fclose(fp) == 0);
    lub_dict_substitute(a, "constant/a.yaml", "nu: 3\n");
    lub_dict *d = lub_dict_read(a2);
    CHECK_NEAR(lub_dict_real(lub_dict_root(d), "nu", LUB_POSITIVE), 3, 0);
    CHECK(strcmp(lub_dict_path(d), "constant/a.yaml") == 0);
    lub_dict_free(d);
    d = lub_dict_read_optional(b);
    CHECK_NEAR(lub_dict_real(lub_dict_root(d), "nu", LUB_POSITIVE), 2, 0);
    lub_dict_free(d);
    lub_dict_substitute(a, "constant/a.yaml", "nu: abc\n");
    d = lub_dict_read(a);
    CHECK_FATAL(lub_dict_real(lub_dict_root(d), "nu", LUB_POSITIVE),
                "constant/a.yaml:1:5: 'nu' expects a real number");
    lub_dict_free(d);
    lub_dict_substitute(NULL, NULL, NULL);
    d = lub_dict_read(a);
    CHECK_NEAR(lub_dict_real(lub_dict_root(d), "nu", LUB_POSITIVE), 1, 0);
    lub_dict_free(d);
    unlink(a);
    unlink(b);
    rmdir(dir);
}

static void test_closest(void)
{
    const char *c[] = {"gradient", "laplacian", "viscosity"};
    CHECK(strcmp(lub_closest("gradiant", c, 3), "gradient") == 0);
    CHECK(strcmp(lub_closest("Laplacian", c, 3), "laplacian") == 0);
    CHECK(lub_closest("xyz", c, 3) == NULL);
    CHECK(lub_edit_distance("kitten", "sitting") == 3);
    CHECK(lub_edit_distance("", "abc") == 3);
}

int main(void)
{
    RUN(test_valid);
    RUN(test_choice_and_bool);
    RUN(test_unknown_key);
    RUN(test_wrong_type);
    RUN(test_out_of_range);
    RUN(test_missing_key);
    RUN(test_malformed);
    RUN(test_yaml_limits);
    RUN(test_files);
    RUN(test_substitute);
    RUN(test_closest);
    return test_summary();
}
