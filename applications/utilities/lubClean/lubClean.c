/* lubClean: remove what the programs wrote into a case, keeping its input (OpenFOAM's
 * cleanCase / foamCleanTutorials).
 *
 *     lubClean                     time folders after 0, postProcessing/, log.*, temporaries
 *     lubClean -withZero           0/ as well (particleGen writes it again)
 *     lubClean -dryRun             print what would be removed
 *
 * Kept: system/, constant/, 0/ (the initial particles) and every file the programs do not
 * write.  The temporaries are those of src/io/case.c's atomic writes, which carry the pid of
 * their writer and stay behind after a kill -9 or a full disk: ".<time>.tmp<pid>/" and
 * ".<time>.old<pid>/" folders, "<file>.tmp<pid>" files (particles.xdmf, the dictionaries
 * lubDict edits, 0/particles.h5 being written).
 */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/args.h"
#include "core/error.h"
#include "io/case.h"
#include "particles/particles_io.h"

static const char *description =
    "  Removes from the case directory what lubkit's programs write:\n"
    "    the time folders other than 0 (with -withZero, 0 too; negative times included),\n"
    "    postProcessing/, log.* (runApplication's logs), particles.xdmf (rewritten for 0/\n"
    "    when 0/ stays), and the temporary files and folders of interrupted writes\n"
    "    (.<time>.tmp<pid>/, .<time>.old<pid>/, <file>.tmp<pid> in the case, 0/,\n"
    "    system/ and constant/).\n"
    "  Keeps system/, constant/, 0/ and every other file (plots, notes, scripts).  Refuses\n"
    "  a directory without system/ (not a case).  Do not clean a case while a program\n"
    "  runs in it.  A tutorial's Allclean calls it (RunFunctions' cleanCase).";

typedef struct {
    int dry;
    size_t folders, files, temps;
} cleaner;

/* "<anything>.tmp<digits>", or ".<anything>.old<digits>": a temporary of src/io/case.c. */
static int is_temporary(const char *name)
{
    static const char *const tags[] = {".tmp", ".old"};
    for (int k = 0; k < 2; k++) {
        const char *p = NULL;
        for (const char *s = strstr(name, tags[k]); s; s = strstr(s + 1, tags[k])) p = s;
        if (!p || p == name || !p[4]) continue;
        const char *d = p + 4;
        while (*d >= '0' && *d <= '9') d++;
        if (*d) continue;
        if (k == 1 && name[0] != '.') continue;
        return 1;
    }
    return 0;
}

static void remove_path(cleaner *cl, const char *path, size_t *count)
{
    struct stat st;
    if (lstat(path, &st) != 0) return;
    if (cl->dry)
        printf("%s%s\n", path, S_ISDIR(st.st_mode) ? "/" : "");
    else if (lub_rm_rf(path) != 0)
        lub_fatal_run("cannot remove '%s': %s", path, strerror(errno));
    (*count)++;
}

/* The temporaries directly inside folder rel of the case ("" for the case itself). */
static void remove_temporaries(cleaner *cl, const lub_case *c, const char *rel)
{
    char dir[LUB_PATH_MAX];
    if (*rel)
        lub_case_path(c, dir, rel);
    else
        snprintf(dir, sizeof dir, "%s", c->root);
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (!is_temporary(e->d_name)) continue;
        char path[LUB_PATH_MAX];
        if (snprintf(path, sizeof path, "%s/%s", dir, e->d_name) >= (int)sizeof path) continue;
        remove_path(cl, path, &cl->temps);
    }
    closedir(d);
}

int main(int argc, char **argv)
{
    cleaner cl = {0};
    int with_zero = 0;
    lub_option opts[] = {
        {"-withZero", NULL, "remove 0/ as well (the initial particles; particleGen writes them)",
         LUB_OPT_FLAG, &with_zero},
        {"-dryRun", NULL, "print what would be removed, remove nothing", LUB_OPT_FLAG, &cl.dry},
        {0}};
    lub_program_info info = {.name = "lubClean",
                             .summary = "remove the results of a case, keep its input",
                             .usage = "[OPTIONS]",
                             .description = description,
                             .has_case = 1,
                             .min_args = 0,
                             .max_args = 0};
    lub_args a;
    lub_args_parse(&a, argc, argv, &info, opts);
    lub_case c;
    lub_case_open(&c, a.case_dir);
    char path[LUB_PATH_MAX];
    struct stat st;
    if (stat(lub_case_path(&c, path, "system"), &st) != 0 || !S_ISDIR(st.st_mode))
        lub_fatal("'%s' is not a lubkit case (no system/ folder): nothing removed", c.root);

    /* the temporaries first: a ".0.tmp<pid>" folder is not a time folder */
    remove_temporaries(&cl, &c, "");
    lub_time *t;
    size_t n = lub_case_times(&c, &t);
    int zero_kept = 0;
    char zero_name[sizeof t->name] = "0";
    for (size_t i = 0; i < n; i++) {
        if (t[i].value == 0.0 && !with_zero) {
            zero_kept = 1;
            memcpy(zero_name, t[i].name, sizeof zero_name);
            continue;
        }
        remove_path(&cl, lub_case_path(&c, path, t[i].name), &cl.folders);
    }
    free(t);
    if (zero_kept) remove_temporaries(&cl, &c, zero_name);
    remove_temporaries(&cl, &c, "system");
    remove_temporaries(&cl, &c, "constant");
    remove_path(&cl, lub_case_path(&c, path, "postProcessing"), &cl.folders);

    DIR *d = opendir(c.root);
    if (!d) lub_fatal("cannot list '%s': %s", c.root, strerror(errno));
    struct dirent *e;
    while ((e = readdir(d)))
        if (strncmp(e->d_name, "log.", 4) == 0) {
            lub_case_path(&c, path, e->d_name);
            if (lstat(path, &st) == 0 && !S_ISDIR(st.st_mode)) remove_path(&cl, path, &cl.files);
        }
    closedir(d);

    /* particles.xdmf: the collection of what remains (0/), none when nothing does */
    lub_case_path(&c, path, "particles.xdmf");
    if (cl.dry) {
        if (lstat(path, &st) == 0) printf("%s%s\n", path, zero_kept ? " (rewritten for 0/)" : "");
    } else if (zero_kept) {
        lub_case_xdmf_write(&c);
    } else if (lstat(path, &st) == 0) {
        remove_path(&cl, path, &cl.files);
    }
    if (!cl.dry)
        lub_message("lubClean: %s: removed %zu folders, %zu files, %zu temporaries%s", c.root,
                    cl.folders, cl.files, cl.temps, zero_kept ? "; kept 0/" : "");
    if (fflush(stdout) != 0 || ferror(stdout)) lub_fatal_run("error writing standard output");
    return 0;
}
