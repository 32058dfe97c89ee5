/* lubkit core: messages, errors and exit status (see error.h). */
#include "core/error.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *program_name = "lubkit";
static int quiet = 0;
static lub_catcher *catcher = NULL;
static lub_fatal_hook fatal_hook = NULL;
static const char *warning_prefix = "";

void lub_set_program(const char *name)
{
    program_name = name;
}
const char *lub_program(void)
{
    return program_name;
}
void lub_set_quiet(int q)
{
    quiet = q;
}
void lub_set_fatal_hook(lub_fatal_hook hook)
{
    fatal_hook = hook;
}
void lub_set_warning_prefix(const char *prefix)
{
    warning_prefix = prefix;
}

void lub_message(const char *fmt, ...)
{
    if (quiet) return;
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stdout, fmt, ap);
    va_end(ap);
    fputc('\n', stdout);
}

void lub_warning(const char *fmt, ...)
{
    if (!warning_prefix) return;
    va_list ap;
    fflush(stdout);
    fprintf(stderr, "%s: %swarning: ", program_name, warning_prefix);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

void lub_error_push(lub_catcher *c)
{
    c->prev = catcher;
    c->message[0] = '\0';
    c->status = 0;
    catcher = c;
}

void lub_error_uncatch(void)
{
    if (catcher) catcher = catcher->prev;
}

_Noreturn void lub_vfatal_at(int status, const char *file, int line, int col, const char *fmt,
                             va_list ap)
{
    char msg[2048];
    size_t n = 0;
    if (file) {
        if (line > 0 && col > 0)
            n = (size_t)snprintf(msg, sizeof msg, "%s:%d:%d: ", file, line, col);
        else if (line > 0)
            n = (size_t)snprintf(msg, sizeof msg, "%s:%d: ", file, line);
        else
            n = (size_t)snprintf(msg, sizeof msg, "%s: ", file);
        if (n >= sizeof msg) n = sizeof msg - 1;
    }
    vsnprintf(msg + n, sizeof msg - n, fmt, ap);
    if (catcher) {
        lub_catcher *c = catcher;
        catcher = c->prev;
        memcpy(c->message, msg, sizeof c->message);
        c->message[sizeof c->message - 1] = '\0';
        c->status = status;
        longjmp(c->env, 1);
    }
    if (fatal_hook) fatal_hook(status, msg); /* does not return (lub_set_fatal_hook) */
    fflush(stdout);
    fprintf(stderr, "%s: error: %s\n", program_name, msg);
    exit(status);
}

_Noreturn void lub_fatal_at(const char *file, int line, int col, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    lub_vfatal_at(LUB_EXIT_INPUT, file, line, col, fmt, ap);
}

_Noreturn void lub_fatal(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    lub_vfatal_at(LUB_EXIT_INPUT, NULL, 0, 0, fmt, ap);
}

_Noreturn void lub_fatal_run(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    lub_vfatal_at(LUB_EXIT_RUN, NULL, 0, 0, fmt, ap);
}

_Noreturn void lub_bug_at(const char *file, const char *func, int line, const char *fmt, ...)
{
    va_list ap;
    fflush(stdout);
    fprintf(stderr, "%s: internal error in %s() at %s:%d: ", program_name, func, file, line);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    abort();
}

void *lub_malloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p) lub_fatal_run("out of memory allocating %zu bytes", n);
    return p;
}

void *lub_calloc(size_t n, size_t size)
{
    void *p = calloc(n ? n : 1, size ? size : 1);
    if (!p) lub_fatal_run("out of memory allocating %zu x %zu bytes", n, size);
    return p;
}

void *lub_realloc(void *p, size_t n)
{
    void *q = realloc(p, n ? n : 1);
    if (!q) lub_fatal_run("out of memory allocating %zu bytes", n);
    return q;
}

void *lub_regrow(void *p, size_t old, size_t cap, size_t size)
{
    char *q = lub_realloc(p, cap * size);
    if (cap > old) memset(q + old * size, 0, (cap - old) * size);
    return q;
}

char *lub_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = lub_malloc(n);
    memcpy(d, s, n);
    return d;
}
