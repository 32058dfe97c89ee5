/* lubDict: read or edit entries of a dictionary from the shell, keeping comments and layout.
 *
 *     lubDict constant/transportProperties.yaml nu
 *     lubDict constant/models.yaml -set 'elasticWall.E=2e7' -set 'gravity.g=[0, -1.62]'
 *
 * Edits go through src/io/yamledit (only the value's text changes, each edit re-parsed and
 * checked) and the file is replaced atomically once all of them succeeded.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/args.h"
#include "core/error.h"
#include "io/case.h"
#include "io/yamledit.h"

static const char *description =
    "  FILE KEY...          print the value of each KEY, one per line: a scalar as its value,\n"
    "                       a mapping or sequence as its source text\n"
    "  FILE -set KEY=VALUE  replace values in place (repeatable); the rest of the file stays\n"
    "                       byte-for-byte the same (comments, layout, flow style)\n"
    "  FILE -add KEY=VALUE  add entries that do not exist yet (repeatable)\n"
    "  FILE -keys [KEY]     list the keys of the mapping at KEY (the top level by default)\n"
    "\n"
    "KEY is a dot path through mappings; integers index sequences: 'nu',\n"
    "'elasticWall.E', 'multiResolution.levels.0.l0', 'fluid.1.thickness'.\n"
    "VALUE is YAML text on one line: 4.5e-4, crankNicolson, '[0, -9.81]', '{l0: 5e-6}'.\n"
    "All -add, then all -set edits are applied in the order given; each must give valid\n"
    "YAML that reads back as the value, else nothing is written.  FILE is replaced\n"
    "atomically (or -o FILE is written instead).  A relative FILE is taken relative to\n"
    "the -case directory.  A missing key is an error that suggests the closest key.";

static const char *in_case(const lub_args *a, const char *path, char *buf)
{
    if (path[0] == '/' || strcmp(a->case_dir, ".") == 0) return path;
    lub_case c;
    lub_case_open(&c, a->case_dir);
    return lub_case_path(&c, buf, path);
}

int main(int argc, char **argv)
{
    lub_strlist sets = {0}, adds = {0};
    int keys = 0;
    const char *out = NULL;
    lub_option opts[] = {
        {"-set", "KEY=VALUE", "replace the value of KEY (repeatable)", LUB_OPT_MULTI, &sets},
        {"-add", "KEY=VALUE", "add the entry KEY (repeatable)", LUB_OPT_MULTI, &adds},
        {"-keys", NULL, "list the keys of the mapping at KEY (or the top level)", LUB_OPT_FLAG,
         &keys},
        {"-o", "FILE", "write the edited dictionary to FILE instead of editing in place",
         LUB_OPT_STR, &out},
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
    int edit = sets.n > 0 || adds.n > 0;
    if (edit && (keys || a.npos > 1))
        lub_fatal("-set/-add edit the file; print values in a separate call (found '%s')",
                  keys ? "-keys" : a.pos[1]);
    if (!edit && !keys && a.npos < 2)
        lub_fatal("nothing to do: give a KEY to print, -set KEY=VALUE, -add or -keys; see "
                  "lubDict -help");
    if (keys && a.npos > 2) lub_fatal("-keys takes at most one KEY, found '%s'", a.pos[2]);
    if (out && !edit) lub_fatal("-o is for edits (-set, -add)");

    lub_yaml_text y;
    lub_yaml_text_read(&y, file);
    if (keys) {
        char **k;
        size_t n = lub_yaml_keys(&y, a.npos > 1 ? a.pos[1] : "", &k);
        for (size_t i = 0; i < n; i++) printf("%s\n", k[i]);
        lub_yaml_keys_free(k, n);
    } else if (!edit) {
        for (int i = 1; i < a.npos; i++) {
            char *v = lub_yaml_get(&y, a.pos[i]);
            size_t n = strlen(v);
            /* a block scalar ("|") ends with its own line break */
            printf(n && v[n - 1] == '\n' ? "%s" : "%s\n", v);
            free(v);
        }
    } else {
        for (size_t i = 0; i < adds.n; i++) {
            char *key, *value;
            lub_yaml_split_assignment(adds.items[i], "-add", &key, &value);
            lub_yaml_add(&y, key, value);
            free(key);
            free(value);
        }
        for (size_t i = 0; i < sets.n; i++) {
            char *key, *value;
            lub_yaml_split_assignment(sets.items[i], "-set", &key, &value);
            lub_yaml_set(&y, key, value);
            free(key);
            free(value);
        }
        lub_yaml_text_write(&y, out ? in_case(&a, out, obuf) : file);
    }
    lub_yaml_text_free(&y);
    lub_strlist_free(&sets);
    lub_strlist_free(&adds);
    if (fflush(stdout) != 0 || ferror(stdout)) lub_fatal_run("error writing standard output");
    return 0;
}
