/* lubkit command-line options (see args.h). */
#include "core/args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/spell.h"

#ifndef LUB_VERSION
#define LUB_VERSION "0.0.0"
#endif
#ifndef LUB_GITREV
#define LUB_GITREV "unknown"
#endif

void lub_strlist_push(lub_strlist *l, const char *s)
{
    if (l->n == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 4;
        l->items = lub_realloc(l->items, l->cap * sizeof *l->items);
    }
    l->items[l->n++] = s;
}

void lub_strlist_free(lub_strlist *l)
{
    free(l->items);
    l->items = NULL;
    l->n = l->cap = 0;
}

int lub_parse_real(const char *s, double *out)
{
    char *end;
    if (!s || !*s) return -1;
    errno = 0;
    double v = strtod(s, &end);
    if (*end || end == s || !isfinite(v) || errno == ERANGE) {
        /* strtod sets ERANGE on underflow to subnormal/zero too: accept those */
        if (!*end && end != s && isfinite(v) && errno == ERANGE && fabs(v) < 1.0) {
            *out = v;
            return 0;
        }
        return -1;
    }
    *out = v;
    return 0;
}

int lub_parse_int(const char *s, long *out)
{
    char *end;
    if (!s || !*s) return -1;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (*end || end == s || errno == ERANGE) return -1;
    *out = v;
    return 0;
}

/* Common options, shown in -help after the program's own. */
enum { COMMON_CASE, COMMON_TIME, COMMON_LATEST, COMMON_NOZERO, COMMON_HELP, COMMON_VERSION };
static const struct {
    const char *name, *arg, *help;
} common[] = {
    {"-case", "DIR", "case directory (default: the current directory)"},
    {"-time", "LIST", "times to process: values and ranges, e.g. '0.01,0.02:0.03' or '0.024:'"},
    {"-latestTime", NULL, "process the latest time only"},
    {"-noZero", NULL, "leave out time 0"},
    {"-help", NULL, "print this help and exit"},
    {"-version", NULL, "print the version and exit"},
};
#define NCOMMON (sizeof common / sizeof common[0])

static int common_enabled(const lub_program_info *info, int k)
{
    if (k == COMMON_CASE) return info->has_case;
    if (k == COMMON_TIME || k == COMMON_LATEST || k == COMMON_NOZERO) return info->time_selection;
    return 1;
}

static void print_opt(const char *name, const char *arg, const char *help)
{
    char head[64];
    snprintf(head, sizeof head, "%s%s%s", name, arg ? " " : "", arg ? arg : "");
    printf("  %-22s %s\n", head, help);
}

static void print_help(const lub_program_info *info, const lub_option *opts)
{
    printf("Usage: %s %s\n\n  %s\n", info->name, info->usage ? info->usage : "[OPTIONS]",
           info->summary ? info->summary : "");
    if (info->description) printf("\n%s\n", info->description);
    printf("\nOptions:\n");
    for (const lub_option *o = opts; o && o->name; o++) print_opt(o->name, o->arg, o->help);
    for (size_t k = 0; k < NCOMMON; k++)
        if (common_enabled(info, (int)k)) print_opt(common[k].name, common[k].arg, common[k].help);
    if (info->dictionaries) {
        printf("\nDictionaries read (relative to the case directory):\n");
        const char *s = info->dictionaries;
        while (*s) {
            const char *e = strchr(s, '\n');
            size_t len = e ? (size_t)(e - s) : strlen(s);
            printf("  %.*s\n", (int)len, s);
            s += len + (e ? 1 : 0);
        }
    }
    printf("\nExit status: 0 success, 1 bad input, 2 the run failed.\n");
}

static void add_pos(lub_args *a, const char *arg)
{
    if (a->npos >= LUB_MAX_POS) lub_fatal("more than %d arguments", LUB_MAX_POS);
    a->pos[a->npos++] = arg;
}

void lub_args_parse(lub_args *a, int argc, char **argv, const lub_program_info *info,
                    const lub_option *opts)
{
    lub_set_program(info->name);
    memset(a, 0, sizeof *a);
    a->case_dir = ".";

    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (arg[0] != '-' || arg[1] == '\0') { /* positional, or "-" for stdin */
            add_pos(a, arg);
            continue;
        }
        if (strcmp(arg, "--") == 0) {
            while (++i < argc) add_pos(a, argv[i]);
            break;
        }
        /* accept --name as -name */
        const char *name = (arg[1] == '-') ? arg + 1 : arg;
        int done = 0;
        for (const lub_option *o = opts; o && o->name && !done; o++) {
            if (strcmp(name, o->name) != 0) continue;
            done = 1;
            if (o->type == LUB_OPT_FLAG) {
                *(int *)o->dest = 1;
                continue;
            }
            if (i + 1 >= argc)
                lub_fatal("option '%s' expects %s", o->name, o->arg ? o->arg : "a value");
            const char *val = argv[++i];
            switch (o->type) {
            case LUB_OPT_STR:
                *(const char **)o->dest = val;
                break;
            case LUB_OPT_MULTI:
                lub_strlist_push((lub_strlist *)o->dest, val);
                break;
            case LUB_OPT_REAL:
                if (lub_parse_real(val, (double *)o->dest))
                    lub_fatal("option '%s' expects a real number, found '%s'", o->name, val);
                break;
            case LUB_OPT_INT:
                if (lub_parse_int(val, (long *)o->dest))
                    lub_fatal("option '%s' expects an integer, found '%s'", o->name, val);
                break;
            default:
                break;
            }
        }
        if (done) continue;
        if (strcmp(name, "-help") == 0 || strcmp(name, "-h") == 0) {
            print_help(info, opts);
            exit(0);
        }
        if (strcmp(name, "-version") == 0) {
            printf("%s (lubkit %s, %s)\n", info->name, LUB_VERSION, LUB_GITREV);
            exit(0);
        }
        if (info->has_case && strcmp(name, "-case") == 0) {
            if (i + 1 >= argc) lub_fatal("option '-case' expects DIR");
            a->case_dir = argv[++i];
            /* an empty name (a variable that was not set) would run the current directory */
            if (!*a->case_dir)
                lub_fatal("option '-case' expects DIR, found an empty name (the current "
                          "directory is -case .)");
            continue;
        }
        if (info->time_selection && strcmp(name, "-time") == 0) {
            if (i + 1 >= argc) lub_fatal("option '-time' expects LIST");
            a->time = argv[++i];
            continue;
        }
        if (info->time_selection && strcmp(name, "-latestTime") == 0) {
            a->latest_time = 1;
            continue;
        }
        if (info->time_selection && strcmp(name, "-noZero") == 0) {
            a->no_zero = 1;
            continue;
        }
        /* unknown: suggest the closest known option */
        const char *names[128];
        size_t n = 0;
        for (const lub_option *o = opts; o && o->name && n < 120; o++) names[n++] = o->name;
        for (size_t k = 0; k < NCOMMON; k++)
            if (common_enabled(info, (int)k)) names[n++] = common[k].name;
        const char *near = lub_closest(name, names, n);
        if (near)
            lub_fatal("unknown option '%s' (did you mean '%s'?); see %s -help", arg, near,
                      info->name);
        lub_fatal("unknown option '%s'; see %s -help", arg, info->name);
    }
    if (a->npos < info->min_args || (info->max_args >= 0 && a->npos > info->max_args)) {
        if (a->npos < info->min_args)
            lub_fatal("missing argument%s; usage: %s %s", info->min_args - a->npos > 1 ? "s" : "",
                      info->name, info->usage ? info->usage : "");
        lub_fatal("unexpected argument '%s'; usage: %s %s", a->pos[info->max_args], info->name,
                  info->usage ? info->usage : "");
    }
}
