/* lubkit core: messages, errors and exit status.
 *
 * Two kinds of failure, as in OpenFOAM's FatalError / FatalIOError:
 *   - bad input (a dictionary, an option, a file): the user can fix it; the message names
 *     the file and line of the input, and the program exits with LUB_EXIT_INPUT (1);
 *   - a run that fails (diverged, solver failure): exit LUB_EXIT_RUN (2) after the caller
 *     has written what is needed to inspect or restart it.
 * Internal inconsistencies (a bug) go through lub_bug(), which names the source file and
 * line of the code, like SWIFT's error() macro.
 *
 * Fatal errors go through a handler so that unit tests can catch them (lub_error_catch).
 */
#ifndef LUB_CORE_ERROR_H
#define LUB_CORE_ERROR_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

enum { LUB_EXIT_OK = 0, LUB_EXIT_INPUT = 1, LUB_EXIT_RUN = 2 };

/* Name printed in front of messages ("reynoldsRef: error: ..."); set once by main. */
void lub_set_program(const char *name);
const char *lub_program(void);

/* Informational output on stdout; suppressed by lub_set_quiet(1). */
void lub_message(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void lub_set_quiet(int quiet);
/* A program run on several MPI processes (src/parallel/par.h) ends them all on a fatal error:
 * the hook, when set, takes the message (without the program prefix) and the exit status
 * instead of the print-and-exit, and must not return.  NULL: the default. */
typedef void (*lub_fatal_hook)(int status, const char *msg);
void lub_set_fatal_hook(lub_fatal_hook hook);
/* Put between "<program>: " and "warning: " ("rank 3: "; "" none, the default); NULL: no
 * warnings at all (the other ranks while they repeat rank 0's start-up). */
void lub_set_warning_prefix(const char *prefix);
/* Warnings on stderr: "<program>: warning: ...". */
void lub_warning(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* Fatal error about input: "<program>: error: <file>:<line>:<col>: <msg>".
 * file may be NULL (no location), line/col <= 0 are omitted.  Does not return. */
_Noreturn void lub_fatal_at(const char *file, int line, int col, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
_Noreturn void lub_vfatal_at(int status, const char *file, int line, int col, const char *fmt,
                             va_list ap);
/* Fatal input error without location (options, missing files named in the message). */
_Noreturn void lub_fatal(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Fatal run failure (exit 2). */
_Noreturn void lub_fatal_run(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* Internal error with the source location of the code. */
#define lub_bug(...) lub_bug_at(__FILE__, __func__, __LINE__, __VA_ARGS__)
_Noreturn void lub_bug_at(const char *file, const char *func, int line, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Test support: while a catcher is installed, fatal errors longjmp to it instead of exiting,
 * with the message (without the program prefix) and status kept for inspection.
 *
 *     lub_catcher c;
 *     if (lub_error_catch(&c) == 0) { code_that_should_fail(); lub_error_uncatch(); fail(); }
 *     else { check(strstr(c.message, "file.yaml:3:5")); }   (handler already uninstalled)
 */
typedef struct lub_catcher {
    jmp_buf env;
    char message[2048];
    int status;
    struct lub_catcher *prev;
} lub_catcher;
#define lub_error_catch(c) (lub_error_push(c), setjmp((c)->env))
void lub_error_push(lub_catcher *c);
void lub_error_uncatch(void);

/* Allocation that cannot fail silently: out of memory is a run failure naming the size. */
void *lub_malloc(size_t n);
void *lub_calloc(size_t n, size_t size);
void *lub_realloc(void *p, size_t n);
/* An array of old elements of size bytes (NULL: none yet) grown to cap elements, the new tail
 * zeroed, so that no uninitialised memory is read or written to a file. */
void *lub_regrow(void *p, size_t old, size_t cap, size_t size);
char *lub_strdup(const char *s);

#endif
