/* lubDict: read or edit entries of a dictionary from the shell, keeping comments and layout.
 *
 *     lubDict constant/transportProperties.yaml nu
 *     lubDict constant/models.yaml -set 'elasticWall.E=2e7' -set 'gravity.g=[0, -1.62]'
 *     lubDict system/controlDict.yaml                  every value: "key.path = value" lines
 *
 * Edits go through src/io/yamledit (only the value's text changes, each edit re-parsed and
 * checked) and the file is replaced atomically once all of them succeeded.
 *
 * The edited dictionary is checked by the readers of the programs that read it, before it is
 * written: the types, ranges and choices of its entries are known in one place only, the
 * reader of each dictionary (src/io/control.c, src/geometry, src/models, src/mps/config.c,
 * src/reynolds/refcase.c), and a second, hand-written schema here would drift from them.
 * The readers run on the edited text (lub_dict_substitute) in a child process, so that their
 * fatal errors, allocations and messages stay there; the child reports whether an error lies
 * in the edited file or elsewhere (the edit cannot be checked: said, and written); an error
 * about an edited entry refuses the edit (check_edit).
 */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/args.h"
#include "core/error.h"
#include "geometry/discretise.h"
#include "geometry/geometry.h"
#include "io/case.h"
#include "io/control.h"
#include "io/dict.h"
#include "io/yamledit.h"
#include "models/transport.h"
#include "models/model.h"
#include "mps/mps.h"
#include "parallel/par.h"
#include "reynolds/refcase.h"

static const char *description =
    "  FILE                 print every value, one 'key.path = value' line each (a list of\n"
    "                       numbers on one line, '[0, -9.81]')\n"
    "  FILE KEY...          print the value of each KEY, one per line: a scalar as its value,\n"
    "                       a mapping or sequence as its source text\n"
    "  FILE -set KEY=VALUE  replace values in place (repeatable); the rest of the file stays\n"
    "                       byte-for-byte the same (comments, layout, flow style)\n"
    "  FILE -add KEY=VALUE  add entries that do not exist yet (repeatable)\n"
    "  FILE -remove KEY     take entries out (repeatable): their lines go, with the comment\n"
    "                       after the value and its aligned continuation lines\n"
    "  FILE -keys [KEY]     list the keys of the mapping at KEY (the top level by default)\n"
    "\n"
    "KEY is a dot path through mappings; integers index sequences: 'nu',\n"
    "'elasticWall.E', 'multiResolution.levels.0.l0', 'fluid.1.thickness'.\n"
    "VALUE is YAML text on one line: 4.5e-4, crankNicolson, '[0, -9.81]', '{l0: 5e-6}'.\n"
    "All -add, then all -set, then all -remove edits are applied in the order given; each\n"
    "must give valid YAML that reads back as intended, else nothing is written.  FILE is\n"
    "replaced atomically (or -o FILE is written instead).  A relative FILE is taken relative\n"
    "to the -case directory.  A missing key is an error that suggests the closest key.\n"
    "\n"
    "Checks: before an edited case dictionary is written, the readers of the programs\n"
    "that use it read it; they know every entry's type, range and choices (etc/templates/\n"
    "documents them).  An error about an edited entry (its type, range or choices, an\n"
    "unknown key added, a required key removed) refuses the edit with the reader's\n"
    "file:line message, exit 1: 'lubDict constant/transportProperties.yaml -set nu=abc'.\n"
    "Another error (a check of several entries together, e.g. stopAt: nSteps needs\n"
    "nSteps, which the next edit may add; an error the file had before) is a warning, and\n"
    "the file is written.  Checked, known by their place in a case:\n"
    "system/controlDict.yaml, particleGenDict.yaml, schemes.yaml, solution.yaml,\n"
    "reynoldsRefDict.yaml, decomposeParDict.yaml, constant/transportProperties.yaml,\n"
    "models.yaml (schemes, solution, models, reynoldsRefDict and decomposeParDict are\n"
    "read with the case's other dictionaries, as the programs read them).  Not checked, and said "
    "so on standard error: the function\n"
    "objects of controlDict (lubFoam -dryRun checks them), system/probeDict.yaml (probe\n"
    "checks it), any other file, an edit whose case has another dictionary the readers\n"
    "cannot read.  Values that need the particles or several dictionaries together (a\n"
    "Courant number) are checked by lubFoam -dryRun.  -noCheck writes without the readers.";

static const char *in_case(const lub_args *a, const char *path, char *buf)
{
    if (path[0] == '/' || strcmp(a->case_dir, ".") == 0) return path;
    lub_case c;
    lub_case_open(&c, a->case_dir);
    return lub_case_path(&c, buf, path);
}

/* ---- checks by the readers ----------------------------------------------------------- */

/* The particles' levels and patches as particleGen would make them, without particles (the
 * solver's dictionaries name patches and levels): particleGen's lattice over an empty
 * x-range left of the domain. */
static void empty_particles(const lub_geometry *g, lub_particles *P)
{
    double x = g->dmin[0] - 1.0 - 2.0 * (g->dmax[0] - g->dmin[0]);
    lub_geometry_discretise_range(g, 0, x, x, P);
}

static void read_control(const char *file, const char *root)
{
    (void)root;
    lub_control c;
    lub_control_read(&c, file);
    /* the function objects are lubFoam's (functionObjects.c): their names are taken as
     * they are, their contents are not looked into */
    for (size_t i = 0; c.functions && lub_node_type_of(c.functions) == LUB_NODE_MAPPING &&
                       i < lub_node_size(c.functions);
         i++)
        lub_node_key_at(c.functions, i);
    lub_dict_finish(c.dict);
    lub_control_free(&c);
}

static void read_geometry(const char *file, const char *root)
{
    (void)root;
    lub_geometry g;
    lub_geometry_read(&g, file);
    lub_geometry_free(&g);
}

static void read_transport(const char *file, const char *root)
{
    (void)root;
    double rho, nu;
    lub_transport_read(file, &rho, &nu);
}

/* schemes.yaml, solution.yaml, models.yaml: lubFoam's readers of the fluid's dictionaries
 * and of the models the scene lists (src/models/model.h: lub_scene_read), as lubFoam reads
 * them */
static void read_solver(const char *file, const char *root)
{
    (void)file;
    char path[LUB_PATH_MAX];
    lub_case c;
    lub_case_open(&c, root);
    lub_geometry g;
    lub_geometry_read(&g, lub_case_path(&c, path, "system/particleGenDict.yaml"));
    lub_particles P;
    empty_particles(&g, &P);
    lub_mps_config cfg;
    lub_scene scene;
    lub_scene_read(&scene, &c, &P, &g, &cfg);
    lub_scene_free(&scene);
    lub_particles_free(&P);
    lub_geometry_free(&g);
}

static void read_reference(const char *file, const char *root)
{
    (void)file;
    lub_case c;
    lub_case_open(&c, root);
    lub_refcase rc;
    lub_refcase_read(&rc, &c);
    lub_refcase_free(&rc);
}

static void read_decompose(const char *file, const char *root)
{
    char path[LUB_PATH_MAX];
    lub_case c;
    lub_case_open(&c, root);
    lub_geometry g;
    lub_geometry_read(&g, lub_case_path(&c, path, "system/particleGenDict.yaml"));
    lub_par_dict pd;
    lub_par_read_dict(&pd, file, g.dim, 0);
    lub_geometry_free(&g);
}

typedef struct {
    const char *rel;                                  /* place in a case */
    void (*read)(const char *file, const char *root); /* NULL: not checked here */
    const char *why;                                  /* not checked: who checks it */
} known_dict;

static const known_dict known[] = {
    {"system/controlDict.yaml", read_control, NULL},
    {"system/particleGenDict.yaml", read_geometry, NULL},
    {"constant/transportProperties.yaml", read_transport, NULL},
    {"system/schemes.yaml", read_solver, NULL},
    {"system/solution.yaml", read_solver, NULL},
    {"constant/models.yaml", read_solver, NULL},
    {"system/reynoldsRefDict.yaml", read_reference, NULL},
    {"system/decomposeParDict.yaml", read_decompose, NULL},
    {"system/probeDict.yaml", NULL, "probe reads its sampling sets when it runs: run probe"},
};

/* The dictionary a path is, by its last two components, and the case root before them. */
static const known_dict *known_of(const char *file, char *root)
{
    size_t n = strlen(file);
    for (size_t k = 0; k < sizeof known / sizeof known[0]; k++) {
        size_t m = strlen(known[k].rel);
        if (n < m || strcmp(file + n - m, known[k].rel) != 0) continue;
        if (n > m && file[n - m - 1] != '/') continue;
        if (n == m)
            strcpy(root, ".");
        else if (n - m - 1 == 0)
            strcpy(root, "/");
        else
            snprintf(root, LUB_PATH_MAX, "%.*s", (int)(n - m - 1), file);
        return &known[k];
    }
    return NULL;
}

enum { CHECK_OK = 0, CHECK_BAD = 1, CHECK_ELSEWHERE = 3 };

/* Run the readers of dictionary k on text in place of file (in a child process).  Returns
 * CHECK_OK, CHECK_BAD (an error in file: the reader's message in msg) or CHECK_ELSEWHERE (an
 * error in another file, or none could be run: msg says why). */
static int check_text(const known_dict *k, const char *file, const char *root, const char *text,
                      char *msg, size_t size)
{
    int fd[2];
    msg[0] = '\0';
    fflush(NULL);
    if (pipe(fd) != 0) {
        snprintf(msg, size, "cannot run the check: %s", strerror(errno));
        return CHECK_ELSEWHERE;
    }
    pid_t pid = fork();
    if (pid < 0) {
        close(fd[0]);
        close(fd[1]);
        snprintf(msg, size, "cannot run the check: %s", strerror(errno));
        return CHECK_ELSEWHERE;
    }
    if (pid == 0) {
        close(fd[0]);
        /* the readers' warnings and messages are about a run, not an edit */
        int nul = open("/dev/null", O_WRONLY);
        if (nul >= 0) dup2(nul, STDOUT_FILENO), dup2(nul, STDERR_FILENO);
        lub_set_quiet(1);
        lub_dict_substitute(file, file, text);
        lub_catcher c;
        int status = CHECK_OK;
        if (lub_error_catch(&c) == 0) {
            k->read(file, root);
            lub_error_uncatch();
        } else {
            size_t n = strlen(file);
            status = strncmp(c.message, file, n) == 0 && c.message[n] == ':' ? CHECK_BAD
                                                                             : CHECK_ELSEWHERE;
            ssize_t w = write(fd[1], c.message, strlen(c.message));
            (void)w;
        }
        close(fd[1]);
        _exit(status); /* the readers' allocations end with the child */
    }
    close(fd[1]);
    size_t len = 0;
    ssize_t got;
    while ((got = read(fd[0], msg + len, size - 1 - len)) > 0 && len + 1 < size) len += (size_t)got;
    msg[len] = '\0';
    close(fd[0]);
    int st;
    while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
    }
    if (!WIFEXITED(st) || (WEXITSTATUS(st) != CHECK_OK && WEXITSTATUS(st) != CHECK_BAD &&
                           WEXITSTATUS(st) != CHECK_ELSEWHERE)) {
        if (!msg[0]) snprintf(msg, size, "the readers stopped (status %d)", st);
        return CHECK_ELSEWHERE;
    }
    return WEXITSTATUS(st);
}

/* The entry a reader's message is about, from the forms of src/io/dict.c: "'a.b' expects
 * ...", "'a.b' must be ...", "unknown key 'b' in 'a'", "missing required key 'b' in 'a'"
 * (after "<file>:<line>:<col>: ").  Empty when the message has another form (a reader's
 * own check, which may involve several entries: "stopAt: nSteps needs 'nSteps' >= 1"). */
static void entry_of(const char *msg, const char *file, char *path, size_t size)
{
    path[0] = '\0';
    size_t n = strlen(file);
    if (strncmp(msg, file, n) != 0 || msg[n] != ':') return;
    const char *s = msg + n + 1;
    while (*s >= '0' && *s <= '9') s++;
    if (*s == ':') s++;
    while (*s >= '0' && *s <= '9') s++;
    if (*s == ':') s++;
    while (*s == ' ') s++;
    const char *key = NULL, *in = NULL;
    if (*s == '\'')
        key = s + 1;
    else if (strncmp(s, "unknown key '", 13) == 0)
        key = s + 13;
    else if (strncmp(s, "missing required key '", 22) == 0)
        key = s + 22;
    if (!key) return;
    const char *e = strchr(key, '\'');
    if (!e) return;
    if (*s != '\'' && strncmp(e, "' in '", 6) == 0) in = e + 6;
    if (in && strchr(in, '\''))
        snprintf(path, size, "%.*s.%.*s", (int)(strchr(in, '\'') - in), in, (int)(e - key), key);
    else
        snprintf(path, size, "%.*s", (int)(e - key), key);
}

/* Check the edited text y of file, whose edits touched the entries keys: an error of the
 * readers about one of those entries (its type, range or choices, an unknown key added, a
 * required key removed) refuses the edit; another error of the file (a check that takes
 * several entries together, which the next edit may satisfy: stopAt: nSteps before nSteps
 * is added; an error the file had before) is a warning, and the file is written. */
static void check_edit(const char *file, const lub_yaml_text *y, const lub_strlist *keys,
                       int function_objects)
{
    char root[LUB_PATH_MAX], msg[4096], path[1024];
    const known_dict *k = known_of(file, root);
    if (!k) {
        fprintf(stderr,
                "lubDict: note: %s is not a dictionary of a case lubDict knows "
                "(system/*.yaml, constant/*.yaml): the edit is checked as YAML only\n",
                file);
        return;
    }
    if (!k->read) {
        fprintf(stderr, "lubDict: note: %s: the edit is checked as YAML only (%s)\n", file, k->why);
        return;
    }
    int rc = check_text(k, file, root, y->text, msg, sizeof msg);
    if (rc == CHECK_ELSEWHERE) {
        fprintf(stderr,
                "lubDict: note: %s: the edit could not be checked by the readers of the case "
                "(%s)\n",
                file, msg);
        return;
    }
    if (rc == CHECK_BAD) {
        entry_of(msg, file, path, sizeof path);
        size_t n = strlen(path);
        for (size_t i = 0; n && i < keys->n; i++) {
            size_t m = strlen(keys->items[i]);
            if (strncmp(path, keys->items[i], m) == 0 && (path[m] == '\0' || path[m] == '.'))
                lub_fatal("%s (the file is left unchanged; -noCheck writes it anyway)", msg);
        }
        lub_warning("%s (written: the edited entries pass their readers, but the file does not "
                    "as a whole; lubFoam -dryRun checks the case)",
                    msg);
        return;
    }
    if (function_objects)
        fprintf(stderr,
                "lubDict: note: %s: the function objects are checked by lubFoam (lubFoam "
                "-dryRun), not here\n",
                file);
}

int main(int argc, char **argv)
{
    lub_strlist sets = {0}, adds = {0}, removes = {0};
    int keys = 0, no_check = 0;
    const char *out = NULL;
    lub_option opts[] = {
        {"-set", "KEY=VALUE", "replace the value of KEY (repeatable)", LUB_OPT_MULTI, &sets},
        {"-add", "KEY=VALUE", "add the entry KEY (repeatable)", LUB_OPT_MULTI, &adds},
        {"-remove", "KEY", "take the entry KEY out (repeatable)", LUB_OPT_MULTI, &removes},
        {"-keys", NULL, "list the keys of the mapping at KEY (or the top level)", LUB_OPT_FLAG,
         &keys},
        {"-o", "FILE", "write the edited dictionary to FILE instead of editing in place",
         LUB_OPT_STR, &out},
        {"-noCheck", NULL, "write an edit without the check by the dictionary's readers",
         LUB_OPT_FLAG, &no_check},
        {0}};
    lub_program_info info = {.name = "lubDict",
                             .summary = "print or edit entries of a YAML dictionary",
                             .usage = "[OPTIONS] FILE [KEY...]",
                             .description = description,
                             .has_case = 1,
                             .min_args = 1,
                             .max_args = -1};
    lub_args a;
    lub_args_parse(&a, argc, argv, &info, opts);

    char buf[LUB_PATH_MAX], obuf[LUB_PATH_MAX];
    const char *file = in_case(&a, a.pos[0], buf);
    int edit = sets.n > 0 || adds.n > 0 || removes.n > 0;
    if (edit && (keys || a.npos > 1))
        lub_fatal("-set/-add/-remove edit the file; print values in a separate call (found "
                  "'%s')",
                  keys ? "-keys" : a.pos[1]);
    if (keys && a.npos > 2) lub_fatal("-keys takes at most one KEY, found '%s'", a.pos[2]);
    if (out && !edit) lub_fatal("-o is for edits (-set, -add, -remove)");
    if (no_check && !edit) lub_fatal("-noCheck is for edits (-set, -add, -remove)");

    lub_yaml_text y;
    lub_yaml_text_read(&y, file);
    if (keys) {
        char **k;
        size_t n = lub_yaml_keys(&y, a.npos > 1 ? a.pos[1] : "", &k);
        for (size_t i = 0; i < n; i++) printf("%s\n", k[i]);
        lub_yaml_keys_free(k, n);
    } else if (!edit && a.npos == 1) {
        char *v = lub_yaml_values(&y, "");
        fputs(v, stdout);
        free(v);
    } else if (!edit) {
        for (int i = 1; i < a.npos; i++) {
            char *v = lub_yaml_get(&y, a.pos[i]);
            size_t n = strlen(v);
            /* a block scalar ("|") ends with its own line break */
            printf(n && v[n - 1] == '\n' ? "%s" : "%s\n", v);
            free(v);
        }
    } else {
        lub_strlist edited = {0}; /* the edited keys (pointers into the arguments) */
        char **owned = lub_calloc(adds.n + sets.n + 1, sizeof *owned);
        size_t nowned = 0;
        for (size_t i = 0; i < adds.n; i++) {
            char *key, *value;
            lub_yaml_split_assignment(adds.items[i], "-add", &key, &value);
            lub_yaml_add(&y, key, value);
            lub_strlist_push(&edited, owned[nowned++] = key);
            free(value);
        }
        for (size_t i = 0; i < sets.n; i++) {
            char *key, *value;
            lub_yaml_split_assignment(sets.items[i], "-set", &key, &value);
            lub_yaml_set(&y, key, value);
            lub_strlist_push(&edited, owned[nowned++] = key);
            free(value);
        }
        for (size_t i = 0; i < removes.n; i++) {
            lub_yaml_remove(&y, removes.items[i]);
            lub_strlist_push(&edited, removes.items[i]);
        }
        int fos = 0; /* an edit of controlDict's function objects */
        for (size_t i = 0; i < edited.n; i++)
            fos |= strncmp(edited.items[i], "functions", 9) == 0 &&
                   (edited.items[i][9] == '\0' || edited.items[i][9] == '.');
        if (!no_check) check_edit(file, &y, &edited, fos);
        lub_yaml_text_write(&y, out ? in_case(&a, out, obuf) : file);
        lub_strlist_free(&edited);
        for (size_t i = 0; i < nowned; i++) free(owned[i]);
        free(owned);
    }
    lub_yaml_text_free(&y);
    lub_strlist_free(&sets);
    lub_strlist_free(&adds);
    lub_strlist_free(&removes);
    if (fflush(stdout) != 0 || ferror(stdout)) lub_fatal_run("error writing standard output");
    return 0;
}
