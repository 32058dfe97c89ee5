/* lubkit wall-clock timing, for the cost accounting every run reports (design.md,
 * "Speed-for-accuracy"): seconds per phase (neighbour search, assembly, pressure solve, ...).
 */
#ifndef LUB_CORE_TIMER_H
#define LUB_CORE_TIMER_H

#include <time.h>

/* Monotonic wall-clock seconds. */
static inline double lub_wtime(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#define LUB_MAX_PHASES 16

/* Accumulated seconds per named phase. */
typedef struct {
    int n;
    const char *name[LUB_MAX_PHASES];
    double seconds[LUB_MAX_PHASES];
    double started[LUB_MAX_PHASES];
} lub_timers;

/* Register a phase (before the time loop); returns its index. */
int lub_timers_add(lub_timers *t, const char *name);
static inline void lub_timer_start(lub_timers *t, int k)
{
    t->started[k] = lub_wtime();
}
static inline void lub_timer_stop(lub_timers *t, int k)
{
    t->seconds[k] += lub_wtime() - t->started[k];
}

/* The machine's 1-minute load average (/proc/loadavg; path: a file of its format), or -1
 * where it cannot be read; and in *runnable (may be NULL) the tasks runnable at the moment
 * of reading (R of its fourth field R/T, which counts the reader), or -1. */
double lub_load_average(const char *path, int *runnable);
/* The peak resident memory of this process in kB (VmHWM of /proc/self/status; path: a file
 * of its format, NULL: that one), or -1 where it cannot be read. */
long lub_peak_memory_kb(const char *path);
/* The load other work puts on the machine now: the 1-minute average, but no more than the
 * `others` tasks of other programs runnable at this moment (-1: unknown).  The average lags:
 * it still reads 1.5 a few seconds after a two-thread run has ended, which alone made every
 * run started right after another (a sweep, an Allrun after a build) warn of a busy machine.
 * A run still going is runnable at any moment (MPS runs do not wait for I/O).  -1 if the
 * average is unknown. */
double lub_load_now(double average, int others);

/* Whether `threads` OpenMP threads would share the `cores` cores with other work at load
 * `load` (lub_load_now, taken before the run starts): threads > 1 and load + threads > cores + 0.5.
 * Threads that wait for each other at every parallel region then wait for the other work's
 * time slices too: on this project's 2-core machine with two other runs, the reduced wedge
 * took 7.6 us per particle-step on two threads against 2.5 on one (1.9 on two, idle).
 * A load below 0 (unknown) is never oversubscribed.  The number of threads that would fit
 * (at least 1) goes to *fit. */
int lub_threads_oversubscribed(double load, int cores, int threads, int *fit);

#endif
