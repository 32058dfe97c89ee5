/* core/timer: the phase timers, the load (average and tasks running now) and the oversubscription
 * test that lubFoam warns with at start-up. */
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "core/timer.h"
#include "test.h"

static void test_timers(void)
{
    lub_timers t = {0};
    int a = lub_timers_add(&t, "a"), b = lub_timers_add(&t, "b");
    CHECK(a == 0 && b == 1 && t.n == 2);
    lub_timer_start(&t, a);
    double w0 = lub_wtime();
    while (lub_wtime() - w0 < 0.01) {
    }
    lub_timer_stop(&t, a);
    /* at least the span waited for (no upper bound: a timed assertion would depend on the
     * machine's load) */
    CHECK(t.seconds[a] >= 0.01 && isfinite(t.seconds[a]));
    CHECK(t.seconds[b] == 0.0);
}

static void test_load_average(void)
{
    char path[] = "/tmp/lub_loadavg_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    FILE *f = fdopen(fd, "w");
    fputs("1.52 0.80 0.40 3/120 4567\n", f);
    fclose(f);
    int running = 0;
    CHECK_NEAR(lub_load_average(path, &running), 1.52, 1e-15);
    CHECK(running == 3);
    CHECK_NEAR(lub_load_average(path, NULL), 1.52, 1e-15); /* runnable may be NULL */
    f = fopen(path, "w");
    fputs("garbage\n", f);
    fclose(f);
    CHECK(lub_load_average(path, &running) == -1.0 && running == -1);
    f = fopen(path, "w");
    fputs("0.90 1.27 1.35\n", f); /* no R/T field */
    fclose(f);
    CHECK_NEAR(lub_load_average(path, &running), 0.90, 1e-15);
    CHECK(running == -1);
    remove(path);
    CHECK(lub_load_average(path, &running) == -1.0 && running == -1); /* missing file */
    /* the machine's own file: when it reads, it counts at least this reader */
    const double avg = lub_load_average(NULL, &running);
    CHECK(avg == -1.0 || running >= 1);
}

/* VmHWM of /proc/self/status: parsed from a file of its format, and on the real one it
 * grows by at least what the process touches beyond its peak (64 MB written) */
static void test_peak_memory(void)
{
    char path[] = "/tmp/lub_status_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    FILE *f = fdopen(fd, "w");
    fputs("Name:\tlubFoam\nVmPeak:\t  900000 kB\nVmHWM:\t  295012 kB\nVmRSS:\t  1000 kB\n", f);
    fclose(f);
    CHECK(lub_peak_memory_kb(path) == 295012);
    f = fopen(path, "w");
    fputs("Name:\tx\n", f);
    fclose(f);
    CHECK(lub_peak_memory_kb(path) == -1);
    remove(path);
    CHECK(lub_peak_memory_kb(path) == -1);
    const long before = lub_peak_memory_kb(NULL);
    if (before < 0) return; /* no /proc here */
    const size_t bytes = ((size_t)before + 65536) * 1024;
    volatile char *b = malloc(bytes);
    CHECK(b != NULL);
    for (size_t i = 0; i < bytes; i += 4096) b[i] = 1;
    CHECK(lub_peak_memory_kb(NULL) >= before + 65536);
    free((void *)b);
}

static void test_load_now(void)
{
    /* a two-thread run ended seconds ago: the average still reads 1.5, nothing runs now */
    CHECK(lub_load_now(1.5, 0) == 0.0);
    CHECK(!lub_threads_oversubscribed(lub_load_now(1.5, 0), 2, 2, NULL));
    /* a two-thread run going for minutes: average and count agree */
    CHECK(lub_load_now(1.95, 2) == 1.95);
    CHECK(lub_threads_oversubscribed(lub_load_now(1.95, 2), 2, 2, NULL));
    /* one just started: the average has not caught up, it is taken as it is */
    CHECK(lub_load_now(0.3, 2) == 0.3);
    /* unknown count: the average; unknown average: unknown */
    CHECK(lub_load_now(1.2, -1) == 1.2);
    CHECK(lub_load_now(-1.0, 3) == -1.0);
}

static void test_oversubscribed(void)
{
    int fit = 0;
    /* 2 cores, idle: 2 threads fit */
    CHECK(!lub_threads_oversubscribed(0.05, 2, 2, &fit) && fit == 2);
    /* one other run: 1 fits, 2 threads share a core */
    CHECK(lub_threads_oversubscribed(1.0, 2, 2, &fit) && fit == 1);
    /* two other runs: still at least 1 */
    CHECK(lub_threads_oversubscribed(2.0, 2, 2, &fit) && fit == 1);
    /* one thread is never oversubscribed in this sense (nothing waits for it) */
    CHECK(!lub_threads_oversubscribed(3.0, 2, 1, &fit) && fit == 1);
    /* unknown load */
    CHECK(!lub_threads_oversubscribed(-1.0, 2, 2, &fit) && fit == 2);
    /* 8 cores, load 3: 5 threads fit, 6 do not */
    CHECK(!lub_threads_oversubscribed(3.0, 8, 5, &fit) && fit == 5);
    CHECK(lub_threads_oversubscribed(3.0, 8, 6, &fit) && fit == 5);
    CHECK(lub_threads_oversubscribed(1.0, 2, 2, NULL)); /* fit may be NULL */
}

int main(void)
{
    RUN(test_timers);
    RUN(test_load_average);
    RUN(test_peak_memory);
    RUN(test_oversubscribed);
    RUN(test_load_now);
    return test_summary();
}
