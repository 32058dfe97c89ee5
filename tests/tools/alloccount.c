/* lubkit test tool: counts a process's heap allocations.
 *
 *     LD_PRELOAD=<build>/tests/liballoccount.so LUB_ALLOC_COUNT_FILE=count lubFoam ...
 *
 * Every call of malloc, calloc, realloc, reallocarray, posix_memalign, aligned_alloc,
 * memalign and valloc is counted and passed on to glibc's own allocator (__libc_malloc and
 * friends); at exit two numbers are written to $LUB_ALLOC_COUNT_FILE on one line: the
 * allocations of the program and its libraries, and those of the OpenMP runtime.
 * tests/cases/allocation runs a case for N and for 2N steps: the difference of the first
 * numbers is what steps N+1 .. 2N allocated, which the time loop must not do (issue 4: no
 * allocation in the time loop).
 *
 * The OpenMP runtime's allocations (the caller's address inside libgomp) are counted
 * apart: libgomp allocates a team for every parallel region that runs on one thread (all
 * of them with OMP_NUM_THREADS=1, and those an if clause serialises, such as the small
 * matrices of the AMG's coarse levels) and frees it at the region's end.  That is the
 * runtime's bookkeeping, not the program's.
 *
 * To find an allocation: LUB_ALLOC_TRACE=K prints the call stack (addresses, for addr2line)
 * of every counted allocation after the K-th to standard error.
 *
 * Only for glibc, and not for the AddressSanitizer build (it replaces the allocator). */
#define _GNU_SOURCE
#include <errno.h>
#include <execinfo.h>
#include <fcntl.h>
#include <link.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

extern void *__libc_malloc(size_t size);
extern void *__libc_calloc(size_t n, size_t size);
extern void *__libc_realloc(void *p, size_t size);
extern void *__libc_memalign(size_t align, size_t size);
extern void __libc_free(void *p);

static atomic_ulong calls, omp_calls;
static unsigned long trace_after = (unsigned long)-1;
static _Thread_local int in_trace;
/* the address ranges of libgomp's loaded segments */
#define MAX_RANGES 8
static uintptr_t omp_lo[MAX_RANGES], omp_hi[MAX_RANGES];
static int omp_ranges;

static int find_omp(struct dl_phdr_info *info, size_t size, void *data)
{
    (void)size, (void)data;
    if (!info->dlpi_name || !strstr(info->dlpi_name, "libgomp")) return 0;
    for (int h = 0; h < info->dlpi_phnum && omp_ranges < MAX_RANGES; h++)
        if (info->dlpi_phdr[h].p_type == PT_LOAD) {
            omp_lo[omp_ranges] = info->dlpi_addr + info->dlpi_phdr[h].p_vaddr;
            omp_hi[omp_ranges] = omp_lo[omp_ranges] + info->dlpi_phdr[h].p_memsz;
            omp_ranges++;
        }
    return 1;
}

static int from_omp(const void *caller)
{
    const uintptr_t a = (uintptr_t)caller;
    for (int r = 0; r < omp_ranges; r++)
        if (a >= omp_lo[r] && a < omp_hi[r]) return 1;
    return 0;
}

#define count() count_from(__builtin_return_address(0))
static void count_from(const void *caller)
{
    if (from_omp(caller)) {
        atomic_fetch_add_explicit(&omp_calls, 1, memory_order_relaxed);
        return;
    }
    unsigned long k = atomic_fetch_add_explicit(&calls, 1, memory_order_relaxed) + 1;
    if (k > trace_after && !in_trace) {
        in_trace = 1;
        void *stack[16];
        int depth = backtrace(stack, 16);
        char line[48];
        int len = snprintf(line, sizeof line, "allocation %lu:\n", k);
        if (write(2, line, (size_t)len) < 0) { /* nothing to do */
        }
        backtrace_symbols_fd(stack, depth, 2);
        in_trace = 0;
    }
}

/* backtrace() loads libgcc (which allocates) on its first call: done here, before tracing */
__attribute__((constructor)) static void setup(void)
{
    dl_iterate_phdr(find_omp, NULL);
    const char *t = getenv("LUB_ALLOC_TRACE");
    if (!t || !*t) return;
    void *stack[2];
    backtrace(stack, 2);
    trace_after = strtoul(t, NULL, 10);
}

void *malloc(size_t size)
{
    count();
    return __libc_malloc(size);
}

void *calloc(size_t n, size_t size)
{
    count();
    return __libc_calloc(n, size);
}

void *realloc(void *p, size_t size)
{
    count();
    return __libc_realloc(p, size);
}

void *reallocarray(void *p, size_t n, size_t size)
{
    count();
    if (size && n > (size_t)-1 / size) {
        errno = ENOMEM;
        return NULL;
    }
    return __libc_realloc(p, n * size);
}

void free(void *p)
{
    __libc_free(p);
}

void *memalign(size_t align, size_t size)
{
    count();
    return __libc_memalign(align, size);
}

void *aligned_alloc(size_t align, size_t size)
{
    count();
    return __libc_memalign(align, size);
}

void *valloc(size_t size)
{
    count();
    return __libc_memalign((size_t)sysconf(_SC_PAGESIZE), size);
}

int posix_memalign(void **out, size_t align, size_t size)
{
    count();
    if (align < sizeof(void *) || (align & (align - 1)) != 0) return EINVAL;
    void *p = __libc_memalign(align, size);
    if (!p && size) return ENOMEM;
    *out = p;
    return 0;
}

/* written with write(2) from a stack buffer: nothing here allocates */
__attribute__((destructor)) static void report(void)
{
    const char *file = getenv("LUB_ALLOC_COUNT_FILE");
    if (!file || !*file) return;
    char line[48];
    int len =
        snprintf(line, sizeof line, "%lu %lu\n", atomic_load(&calls), atomic_load(&omp_calls));
    int fd = open(file, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) return;
    if (write(fd, line, (size_t)len) != len) { /* the test sees a missing or short count */
    }
    close(fd);
}
