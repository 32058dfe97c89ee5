/* Unit tests of src/io/yamledit.c: text-preserving YAML edits.  Every expected text below is
 * written out by hand: the edit must change the value's span and nothing else. */
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/yamledit.h"
#include "test.h"

/* the models.yaml example of design.md, with comments and odd spacing */
static const char *MODELS = "# physics models of this scene\n"
                            "gravity:        { g: [0, -9.81] }   # m/s^2\n"
                            "movingWalls:    { lowerWall: { velocity: [1.2, 0] } }\n"
                            "viscosity:      { scheme: crankNicolson }\n"
                            "elasticWall:    { patch: cylinder, E: 1.966e7, load: 1000, "
                            "rampTime: 2e-3,\n"
                            "                  relaxation: 5e-6, averageSteps: 1000 }\n"
                            "multiResolution: { levels: [ {l0: 5e-6}, {l0: 4e-5} ], "
                            "fineRegion: [-0.0036, 0.0030],\n"
                            "                   massCorrection: { cMax: 0.24, cMin: 0.048, "
                            "relax: 10 } }\n";

static const char *BLOCK = "application:   lubFoam   # the solver\n"
                           "endTime:       0.03\n"
                           "\n"
                           "# output\n"
                           "writeInterval: 0.001\n"
                           "fluid:\n"
                           "  - name: oil\n"
                           "    thickness: 4e-5  # m\n"
                           "  - name: air\n"
                           "    thickness: 1e-4\n"
                           "note: \"caf\xc3\xa9 \xe2\x82\xac\"   # UTF-8 before later spans\n"
                           "empty:\n"
                           "text: |\n"
                           "  line one\n"
                           "  line two\n"
                           "\n"
                           "functions:\n"
                           "  probe1:\n"
                           "    type: probe   # comment\n"
                           "    every: 10\n"
                           "last: end\n";

/* Apply one set and compare the whole text with the expected one. */
static void set_expect(const char *in, const char *key, const char *value, const char *want)
{
    lub_yaml_text y;
    lub_yaml_text_init(&y, "t.yaml", in);
    lub_yaml_set(&y, key, value);
    CHECK(y.len == strlen(y.text));
    if (strcmp(y.text, want) != 0) {
        printf("  set %s=%s gave:\n%s\n  expected:\n%s\n", key, value, y.text, want);
        CHECK(0);
    }
    lub_yaml_text_free(&y);
}

static char *get(const char *text, const char *key)
{
    lub_yaml_text y;
    lub_yaml_text_init(&y, "t.yaml", text);
    char *v = lub_yaml_get(&y, key);
    lub_yaml_text_free(&y);
    return v;
}

#define CHECK_GET(text, key, want)                                                                 \
    do {                                                                                           \
        char *v_ = get(text, key);                                                                 \
        if (strcmp(v_, want) != 0) {                                                               \
            printf("  %s:%d: get %s = '%s', expected '%s'\n", __FILE__, __LINE__, key, v_, want);  \
            test_failed_checks_++;                                                                 \
        }                                                                                          \
        free(v_);                                                                                  \
    } while (0)

static void test_get(void)
{
    CHECK_GET(BLOCK, "application", "lubFoam");
    CHECK_GET(BLOCK, "endTime", "0.03");
    CHECK_GET(BLOCK, "fluid.1.thickness", "1e-4");
    CHECK_GET(BLOCK, "fluid.0.name", "oil");
    CHECK_GET(BLOCK, "note", "caf\xc3\xa9 \xe2\x82\xac"); /* quotes resolved */
    CHECK_GET(BLOCK, "empty", "");
    CHECK_GET(BLOCK, "text", "line one\nline two\n");
    CHECK_GET(BLOCK, "functions.probe1", "type: probe   # comment\nevery: 10");
    CHECK_GET(BLOCK, "fluid.1", "name: air\nthickness: 1e-4");
    CHECK_GET(MODELS, "gravity", "{ g: [0, -9.81] }");
    CHECK_GET(MODELS, "gravity.g", "[0, -9.81]");
    CHECK_GET(MODELS, "gravity.g.1", "-9.81");
    CHECK_GET(MODELS, "movingWalls.lowerWall.velocity", "[1.2, 0]");
    CHECK_GET(MODELS, "multiResolution.levels.1.l0", "4e-5");
    CHECK_GET(MODELS, "multiResolution.massCorrection.relax", "10");
    CHECK_GET(MODELS, "elasticWall.averageSteps", "1000");

    lub_yaml_text y;
    lub_yaml_text_init(&y, "t.yaml", BLOCK);
    CHECK(lub_yaml_has(&y, "fluid.0.thickness"));
    CHECK(!lub_yaml_has(&y, "fluid.2.thickness"));
    CHECK(!lub_yaml_has(&y, "endTime.x"));
    char **k;
    size_t n = lub_yaml_keys(&y, "", &k);
    CHECK(n == 9);
    if (n == 9) CHECK(strcmp(k[0], "application") == 0 && strcmp(k[8], "last") == 0);
    lub_yaml_keys_free(k, n);
    n = lub_yaml_keys(&y, "fluid", &k);
    CHECK(n == 2 && strcmp(k[1], "1") == 0);
    lub_yaml_keys_free(k, n);
    n = lub_yaml_keys(&y, "fluid.0", &k);
    CHECK(n == 2 && strcmp(k[0], "name") == 0 && strcmp(k[1], "thickness") == 0);
    lub_yaml_keys_free(k, n);
    CHECK_FATAL(lub_yaml_keys(&y, "endTime", &k), "'endTime' is a scalar");
    lub_yaml_text_free(&y);
}

static void test_missing(void)
{
    lub_yaml_text y;
    lub_yaml_text_init(&y, "constant/models.yaml", MODELS);
    CHECK_FATAL(free(lub_yaml_get(&y, "elasticWall.EE")),
                "constant/models.yaml: no entry 'elasticWall.EE' (did you mean 'elasticWall.E'?)");
    CHECK_FATAL(free(lub_yaml_get(&y, "gravty.g")),
                "no entry 'gravty.g' (did you mean 'gravity.g'?)");
    CHECK_FATAL(free(lub_yaml_get(&y, "viscosity.xyzzy")),
                "no entry 'viscosity.xyzzy' ('viscosity' has keys: scheme)");
    CHECK_FATAL(free(lub_yaml_get(&y, "multiResolution.levels.2.l0")),
                "no entry 'multiResolution.levels.2.l0' ('multiResolution.levels' has 2 items)");
    CHECK_FATAL(free(lub_yaml_get(&y, "gravity.g.x")), "is a sequence: use an item number");
    CHECK_FATAL(free(lub_yaml_get(&y, "viscosity.scheme.order")),
                "('viscosity.scheme' is a scalar)");
    CHECK_FATAL(free(lub_yaml_get(&y, "gravity..g")), "empty part");
    CHECK_FATAL(lub_yaml_set(&y, "elasticWall.load.x", "1"), "no entry 'elasticWall.load.x'");
    CHECK(strcmp(y.text, MODELS) == 0);
    lub_yaml_text_free(&y);

    lub_yaml_text_init(&y, "e.yaml", "# only a comment\n");
    CHECK_FATAL(free(lub_yaml_get(&y, "a")), "e.yaml: no entry 'a' (the file is empty)");
    lub_yaml_text_free(&y);
}

static void test_set_block(void)
{
    set_expect(BLOCK, "endTime", "0.05",
               "application:   lubFoam   # the solver\n"
               "endTime:       0.05\n"
               "\n"
               "# output\n"
               "writeInterval: 0.001\n"
               "fluid:\n"
               "  - name: oil\n"
               "    thickness: 4e-5  # m\n"
               "  - name: air\n"
               "    thickness: 1e-4\n"
               "note: \"caf\xc3\xa9 \xe2\x82\xac\"   # UTF-8 before later spans\n"
               "empty:\n"
               "text: |\n"
               "  line one\n"
               "  line two\n"
               "\n"
               "functions:\n"
               "  probe1:\n"
               "    type: probe   # comment\n"
               "    every: 10\n"
               "last: end\n");
    /* comment right after the value is kept */
    set_expect("a: 1 # one\nb: 2\n", "a", "1.5e-3", "a: 1.5e-3 # one\nb: 2\n");
    set_expect(BLOCK, "fluid.0.thickness", "3e-5",
               "application:   lubFoam   # the solver\n"
               "endTime:       0.03\n"
               "\n"
               "# output\n"
               "writeInterval: 0.001\n"
               "fluid:\n"
               "  - name: oil\n"
               "    thickness: 3e-5  # m\n"
               "  - name: air\n"
               "    thickness: 1e-4\n"
               "note: \"caf\xc3\xa9 \xe2\x82\xac\"   # UTF-8 before later spans\n"
               "empty:\n"
               "text: |\n"
               "  line one\n"
               "  line two\n"
               "\n"
               "functions:\n"
               "  probe1:\n"
               "    type: probe   # comment\n"
               "    every: 10\n"
               "last: end\n");
    /* spans after multi-byte characters: the byte offsets must not drift */
    set_expect("n: \"\xc3\xa9\xc3\xa9\xc3\xa9\"\nm: \xe2\x82\xac\xe2\x82\xac\nk: 7 # x\n", "k", "8",
               "n: \"\xc3\xa9\xc3\xa9\xc3\xa9\"\nm: \xe2\x82\xac\xe2\x82\xac\nk: 8 # x\n");
    set_expect("\xef\xbb\xbf"
               "a: \xc3\xa9\nb: 2\n",
               "b", "3",
               "\xef\xbb\xbf"
               "a: \xc3\xa9\nb: 3\n");
    /* CRLF line ends */
    set_expect("a: 1\r\nb: 2\r\nc: 3\r\n", "c", "4", "a: 1\r\nb: 2\r\nc: 4\r\n");
    /* an empty value gets a space after the ':' */
    set_expect("empty:\nx: 1\n", "empty", "[1, 2]", "empty: [1, 2]\nx: 1\n");
    /* a block scalar is replaced without eating the blank line after it */
    set_expect("text: |\n  line one\n  line two\n\nlast: end\n", "text", "short",
               "text: short\n\nlast: end\n");
    /* a block mapping replaced by a flow mapping, the comment before the next key kept */
    set_expect("functions:\n  probe1:\n    type: probe\n# next\nlast: end\n", "functions", "{}",
               "functions:\n  {}\n# next\nlast: end\n");
    /* quoted values and words */
    set_expect("a: 1\n", "a", "\"1\"", "a: \"1\"\n");
    set_expect("s: crankNicolson\n", "s", "explicit", "s: explicit\n");
    /* an indentless block sequence: the flow value goes after the ':' */
    set_expect("g:\n- 1\n- 2\nh: 0\n", "g", "[3]", "g: [3]\nh: 0\n");
    /* anchors and tags stay; an alias elsewhere then reads the new value */
    set_expect("a: &x 5\nb: *x\nc: !!str 7\n", "a", "6", "a: &x 6\nb: *x\nc: !!str 7\n");
    set_expect("a: &x 5\nb: *x\nc: !!str 7\n", "c", "8", "a: &x 5\nb: *x\nc: !!str 8\n");
    /* a block scalar followed by a comment line */
    set_expect("a: |\n  text\n# c\nb: 1\n", "a", "x", "a: x\n# c\nb: 1\n");
    /* no trailing newline at the end of the file */
    set_expect("a: 1\nb: 2", "b", "20", "a: 1\nb: 20");
}

static void test_set_flow(void)
{
    lub_yaml_text y;
    lub_yaml_text_init(&y, "m.yaml", MODELS);
    lub_yaml_set(&y, "movingWalls.lowerWall.velocity", "[2.4, 0]");
    lub_yaml_set(&y, "gravity.g.1", "-1.62");
    lub_yaml_set(&y, "multiResolution.levels.1.l0", "8e-5");
    lub_yaml_set(&y, "elasticWall.relaxation", "1e-5");
    lub_yaml_set(&y, "viscosity", "{ scheme: explicit }");
    const char *want = "# physics models of this scene\n"
                       "gravity:        { g: [0, -1.62] }   # m/s^2\n"
                       "movingWalls:    { lowerWall: { velocity: [2.4, 0] } }\n"
                       "viscosity:      { scheme: explicit }\n"
                       "elasticWall:    { patch: cylinder, E: 1.966e7, load: 1000, "
                       "rampTime: 2e-3,\n"
                       "                  relaxation: 1e-5, averageSteps: 1000 }\n"
                       "multiResolution: { levels: [ {l0: 5e-6}, {l0: 8e-5} ], "
                       "fineRegion: [-0.0036, 0.0030],\n"
                       "                   massCorrection: { cMax: 0.24, cMin: 0.048, "
                       "relax: 10 } }\n";
    CHECK(strcmp(y.text, want) == 0);
    if (strcmp(y.text, want) != 0) printf("%s", y.text);
    /* and the values read back */
    char *v = lub_yaml_get(&y, "gravity.g.1");
    CHECK(strcmp(v, "-1.62") == 0);
    free(v);
    v = lub_yaml_get(&y, "movingWalls.lowerWall.velocity.0");
    CHECK(strcmp(v, "2.4") == 0);
    free(v);
    lub_yaml_text_free(&y);
}

static void test_set_rejected(void)
{
    lub_yaml_text y;
    lub_yaml_text_init(&y, "m.yaml", MODELS);
    /* the comment would swallow the closing brackets */
    CHECK_FATAL(lub_yaml_set(&y, "viscosity.scheme", "explicit # c"),
                "would make the file invalid YAML");
    CHECK_STR(test_last_error, "left unchanged");
    /* valid YAML, but "x, y" would become two items of the sequence */
    CHECK_FATAL(lub_yaml_set(&y, "gravity.g.0", "x, y"), "does not fit in place");
    CHECK_FATAL(lub_yaml_set(&y, "gravity.g", "[1, 2"), "is not valid YAML");
    CHECK_FATAL(lub_yaml_set(&y, "gravity", "a: 1"), "flow style");
    CHECK_FATAL(lub_yaml_set(&y, "gravity", "a\nb"), "one line");
    CHECK(strcmp(y.text, MODELS) == 0);
    lub_yaml_text_free(&y);

    lub_yaml_text_init(&y, "b.yaml", "a: 1\nb: 2\n");
    CHECK_FATAL(lub_yaml_set(&y, "a", "- 1"), "flow style");
    CHECK_FATAL(lub_yaml_set(&y, "a", "x: y"), "flow style");
    CHECK_FATAL(lub_yaml_set(&y, "a", "'open"), "not valid YAML");
    CHECK_FATAL(lub_yaml_set(&y, "a", "*nowhere"), "undefined alias");
    CHECK(strcmp(y.text, "a: 1\nb: 2\n") == 0);
    lub_yaml_text_free(&y);
}

static void test_add(void)
{
    lub_yaml_text y;
    lub_yaml_text_init(&y, "b.yaml", "a: 1   # c\nsub:\n  x: 1\n  y: [1,\n      2]  # c2\nz: 0\n");
    lub_yaml_add(&y, "sub.w", "3");
    lub_yaml_add(&y, "new", "{k: v}");
    lub_yaml_add(&y, "sub.deep.er", "5");
    const char *want = "a: 1   # c\nsub:\n  x: 1\n  y: [1,\n      2]  # c2\n  w: 3\n"
                       "  deep: {er: 5}\nz: 0\nnew: {k: v}\n";
    CHECK(strcmp(y.text, want) == 0);
    if (strcmp(y.text, want) != 0) printf("%s", y.text);
    CHECK_FATAL(lub_yaml_add(&y, "a", "2"), "exists already");
    CHECK_FATAL(lub_yaml_add(&y, "a.b", "2"), "'a' is a scalar");
    lub_yaml_text_free(&y);

    lub_yaml_text_init(&y, "f.yaml", "m: { a: 1 }\nn: {}\nl:\n- k: 1\n");
    lub_yaml_add(&y, "m.b", "[1, 2]");
    lub_yaml_add(&y, "n.c", "x");
    lub_yaml_add(&y, "l.0.j", "2");
    want = "m: { a: 1, b: [1, 2] }\nn: {c: x}\nl:\n- k: 1\n  j: 2\n";
    CHECK(strcmp(y.text, want) == 0);
    if (strcmp(y.text, want) != 0) printf("%s", y.text);
    lub_yaml_text_free(&y);

    lub_yaml_text_init(&y, "e.yaml", "# empty so far");
    lub_yaml_add(&y, "a.b", "1");
    CHECK(strcmp(y.text, "# empty so far\na: {b: 1}\n") == 0);
    lub_yaml_text_free(&y);
}

/* Every expected text by hand: the entry's lines go (with the comment after the value and
 * its aligned continuation lines), the rest stays byte for byte. */
static void test_remove(void)
{
    lub_yaml_text y;
    lub_yaml_text_init(
        &y, "r.yaml",
        "a: 1   # c\n       # more of c\n# about sub\nsub:\n  x: 1\n  y: [1,\n      2]"
        "  # c2\nf: { p: 1, q: 2, r: 3 }\nl:\n- k: 1\n  j: 2\n- 5\nz: 0\n");
    lub_yaml_remove(&y, "a");
    lub_yaml_remove(&y, "sub.y");
    lub_yaml_remove(&y, "f.p");
    lub_yaml_remove(&y, "f.r");
    lub_yaml_remove(&y, "l.0.k");
    lub_yaml_remove(&y, "l.1");
    const char *want = "# about sub\nsub:\n  x: 1\nf: { q: 2 }\nl:\n- j: 2\nz: 0\n";
    CHECK(strcmp(y.text, want) == 0);
    if (strcmp(y.text, want) != 0) printf("%s", y.text);
    lub_yaml_remove(&y, "sub.x"); /* the last entry of a nested block mapping */
    lub_yaml_remove(&y, "f.q");   /* of a flow one */
    want = "# about sub\nsub:\n  {}\nf: {  }\nl:\n- j: 2\nz: 0\n";
    CHECK(strcmp(y.text, want) == 0);
    if (strcmp(y.text, want) != 0) printf("%s", y.text);
    CHECK_FATAL(lub_yaml_remove(&y, "zz"), "no entry 'zz' (did you mean 'z'?)");
    CHECK_FATAL(lub_yaml_remove(&y, "l.3"), "'l' has 1 items");
    CHECK(strcmp(y.text, want) == 0);
    lub_yaml_text_free(&y);

    lub_yaml_text_init(&y, "one.yaml", "# header\nonly: [1, 2]   # c\n");
    lub_yaml_remove(&y, "only");
    CHECK(strcmp(y.text, "# header\n") == 0);
    lub_yaml_text_free(&y);
}

static void test_values(void)
{
    lub_yaml_text y;
    lub_yaml_text_init(&y, "v.yaml",
                       "a: 1   # c\ns: 'q x'\nsub: { x: [1, -2.5e-3], e: {}, n: [] }\n"
                       "l:\n- k: v\n- [3, 4]\n- - 5\n  - 6\nt: |\n  one\n  two\nnul:\n");
    char *v = lub_yaml_values(&y, NULL);
    const char *want = "a = 1\ns = q x\nsub.x = [1, -2.5e-3]\nsub.e = {}\nsub.n = []\n"
                       "l.0.k = v\nl.1 = [3, 4]\nl.2 = [5, 6]\nt = one\\ntwo\\n\nnul = \n";
    CHECK(strcmp(v, want) == 0);
    if (strcmp(v, want) != 0) printf("%s", v);
    free(v);
    v = lub_yaml_values(&y, "sub");
    CHECK(strcmp(v, "sub.x = [1, -2.5e-3]\nsub.e = {}\nsub.n = []\n") == 0);
    free(v);
    v = lub_yaml_values(&y, "a");
    CHECK(strcmp(v, "a = 1\n") == 0);
    free(v);
    lub_yaml_text_free(&y);
}

static void test_syntax_errors(void)
{
    lub_yaml_text y;
    CHECK_FATAL(lub_yaml_text_init(&y, "bad.yaml", "a: 1\nb: [1, 2\nc: 3\n"), "bad.yaml:");
    CHECK_STR(test_last_error, "YAML syntax error");
    CHECK_FATAL(lub_yaml_text_init(&y, "two.yaml", "a: 1\n---\nb: 2\n"), "two.yaml:2:1:");
    CHECK_STR(test_last_error, "one YAML document");
    CHECK_FATAL(lub_yaml_text_read(&y, "/nonexistent/dir/x.yaml"), "/nonexistent/dir/x.yaml");
    CHECK_FATAL(lub_yaml_text_init(&y, "al.yaml", "a: 1\nb: *x\n"), "al.yaml:2:4:");
    CHECK_STR(test_last_error, "undefined alias '*x'");
}

static void test_write(void)
{
    char dir[] = "/tmp/lub_yamledit_test.XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    char path[256], link[256];
    snprintf(path, sizeof path, "%s/d.yaml", dir);
    snprintf(link, sizeof link, "%s/link.yaml", dir);
    FILE *fp = fopen(path, "w");
    fputs("nu: 1e-6 # m2/s\n", fp);
    fclose(fp);
    chmod(path, 0640);
    CHECK(symlink("d.yaml", link) == 0);

    lub_yaml_text y;
    lub_yaml_text_read(&y, link);
    lub_yaml_set(&y, "nu", "4.5e-4");
    lub_yaml_text_write(&y, link);
    lub_yaml_text_free(&y);

    struct stat st;
    CHECK(lstat(link, &st) == 0 && S_ISLNK(st.st_mode)); /* the link is still a link */
    CHECK(stat(path, &st) == 0 && (st.st_mode & 0777) == 0640);
    lub_yaml_text_read(&y, path);
    CHECK(strcmp(y.text, "nu: 4.5e-4 # m2/s\n") == 0);
    lub_yaml_text_free(&y);

    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
}

static void test_split(void)
{
    char *k, *v;
    lub_yaml_split_assignment("a.b=c=d", "-set", &k, &v);
    CHECK(strcmp(k, "a.b") == 0 && strcmp(v, "c=d") == 0);
    free(k);
    free(v);
    lub_yaml_split_assignment(" nu = 4.5e-4 ", "-set", &k, &v);
    CHECK(strcmp(k, "nu") == 0 && strcmp(v, "4.5e-4") == 0);
    free(k);
    free(v);
    lub_yaml_split_assignment("s=", "-set", &k, &v);
    CHECK(strcmp(k, "s") == 0 && strcmp(v, "") == 0);
    free(k);
    free(v);
    CHECK_FATAL(lub_yaml_split_assignment("a.b", "-set", &k, &v), "expected KEY=VALUE");
    CHECK_FATAL(lub_yaml_split_assignment("=1", "-set", &k, &v), "key before '=' is empty");
    CHECK_FATAL(lub_yaml_split_assignment("  =1", "-set", &k, &v), "key before '=' is empty");
}

int main(void)
{
    RUN(test_get);
    RUN(test_missing);
    RUN(test_set_block);
    RUN(test_set_flow);
    RUN(test_set_rejected);
    RUN(test_add);
    RUN(test_remove);
    RUN(test_values);
    RUN(test_syntax_errors);
    RUN(test_write);
    RUN(test_split);
    return test_summary();
}
