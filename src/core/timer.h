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
static inline void lub_timer_start(lub_timers *t, int k) { t->started[k] = lub_wtime(); }
static inline void lub_timer_stop(lub_timers *t, int k)
{
    t->seconds[k] += lub_wtime() - t->started[k];
}

#endif
