/* lubkit command-line options common to all programs.
 *
 * Every program takes -case DIR, -help, -version and, where it reads time folders, the time
 * selection -time LIST, -latestTime, -noZero.  A program declares its own options in a table:
 *
 *     static const char *patch = NULL; static int dry = 0;
 *     lub_option opts[] = {
 *         {"-patch", "NAME", "wall patch to sample", LUB_OPT_STR, &patch},
 *         {"-dryRun", NULL, "print counts, write nothing", LUB_OPT_FLAG, &dry},
 *         {0}};
 *     lub_program_info info = {.name = "particleGen", .summary = "...",
 *                              .usage = "[OPTIONS]", .dictionaries = "system/particleGenDict.yaml",
 *                              .time_selection = 0, .min_args = 0, .max_args = 0};
 *     lub_args a;
 *     lub_args_parse(&a, argc, argv, &info, opts);
 *
 * Unknown options are fatal with a suggestion; -help prints usage, options, the dictionaries
 * read, and exits 0.  Option values are checked by type (-bin must be a positive real...).
 */
#ifndef LUB_CORE_ARGS_H
#define LUB_CORE_ARGS_H

#include <stddef.h>

#define LUB_MAX_POS 256

typedef enum {
    LUB_OPT_FLAG,  /* int*: set to 1 */
    LUB_OPT_STR,   /* const char**: the next argument */
    LUB_OPT_REAL,  /* double*: the next argument, a finite real */
    LUB_OPT_INT,   /* long*: the next argument, an integer */
    LUB_OPT_MULTI, /* lub_strlist*: repeatable, each value appended */
} lub_opt_type;

typedef struct {
    const char **items;
    size_t n, cap;
} lub_strlist;
void lub_strlist_push(lub_strlist *l, const char *s);
void lub_strlist_free(lub_strlist *l);

typedef struct {
    const char *name; /* "-o" */
    const char *arg;  /* value placeholder for -help ("FILE"), NULL for flags */
    const char *help;
    lub_opt_type type;
    void *dest;
} lub_option;

typedef struct {
    const char *name;         /* program name */
    const char *summary;      /* one line */
    const char *usage;        /* after the program name, e.g. "[OPTIONS] TABLE REFERENCE" */
    const char *description;  /* longer text for -help (may be NULL) */
    const char *dictionaries; /* dictionaries read, one per line (may be NULL) */
    int time_selection;       /* accepts -time, -latestTime, -noZero */
    int has_case;             /* accepts -case (most programs) */
    int min_args, max_args;   /* positional arguments (max < 0: unlimited) */
} lub_program_info;

typedef struct {
    const char *case_dir; /* "." by default */
    const char *time;     /* -time LIST, or NULL */
    int latest_time;      /* -latestTime */
    int no_zero;          /* -noZero */
    const char *pos[LUB_MAX_POS]; /* positional arguments */
    int npos;
} lub_args;

/* Parse argv; fatal (exit 1) on any bad option.  Sets the program name for messages. */
void lub_args_parse(lub_args *a, int argc, char **argv, const lub_program_info *info,
                    const lub_option *opts);

/* Parse a real / integer from text; 0 on success.  Whole string must be consumed. */
int lub_parse_real(const char *s, double *out);
int lub_parse_int(const char *s, long *out);

#endif
