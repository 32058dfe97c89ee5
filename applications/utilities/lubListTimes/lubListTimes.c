/* lubListTimes: the time folders of a case in numeric order, as OpenFOAM's foamListTimes.
 *
 *     lubListTimes                 every time folder, one name per line, oldest first
 *     lubListTimes -latestTime     the newest one
 *     lubListTimes -time 0.01: -rm remove the time folders from 0.01 on
 *
 * `ls` sorts names as text (5e-05 after 0.03); this sorts by value, with the folder rules of
 * every other program (src/io/case.c: a directory whose whole name is a number).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/args.h"
#include "core/error.h"
#include "io/case.h"
#include "particles/particles_io.h"

static const char *description =
    "  Prints the names of the case's time folders (directories whose whole name is a\n"
    "  number), one per line, in increasing time: 5e-05 comes before 0.0001, unlike in\n"
    "  `ls`.  -time, -latestTime and -noZero select as in the other programs; a selection\n"
    "  that matches nothing prints nothing (exit 0), so that a script can loop over it:\n"
    "      for t in $(lubListTimes -noZero); do probe totals -time $t; done\n"
    "  -rm removes the selected time folders instead of printing them (time 0, the\n"
    "  initial particles, is never removed: lubClean -withZero does that) and rewrites\n"
    "  particles.xdmf for the times that remain.";

int main(int argc, char **argv)
{
    int rm = 0;
    lub_option opts[] = {{"-rm", NULL,
                          "remove the selected time folders (never 0) and print their names",
                          LUB_OPT_FLAG, &rm},
                         {0}};
    lub_program_info info = {.name = "lubListTimes",
                             .summary = "list the time folders of a case in numeric order",
                             .usage = "[OPTIONS]",
                             .description = description,
                             .time_selection = 1,
                             .has_case = 1,
                             .min_args = 0,
                             .max_args = 0};
    lub_args a;
    lub_args_parse(&a, argc, argv, &info, opts);
    lub_case c;
    lub_case_open(&c, a.case_dir);
    lub_time *t;
    size_t n = lub_case_filter_times(&c, a.time, a.latest_time, a.no_zero, &t);
    size_t removed = 0;
    for (size_t i = 0; i < n; i++) {
        if (rm) {
            if (t[i].value == 0.0) continue;
            char path[LUB_PATH_MAX];
            if (lub_rm_rf(lub_case_path(&c, path, t[i].name)) != 0)
                lub_fatal_run("cannot remove '%s': %s", path, strerror(errno));
            removed++;
        }
        printf("%s\n", t[i].name);
    }
    free(t);
    if (removed) lub_case_xdmf_write(&c);
    if (fflush(stdout) != 0 || ferror(stdout)) lub_fatal_run("error writing standard output");
    return 0;
}
