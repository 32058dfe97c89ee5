/* lubkit wall-clock timing (see timer.h). */
#include "core/timer.h"

#include <math.h>
#include <stdio.h>

#include "core/error.h"

int lub_timers_add(lub_timers *t, const char *name)
{
    if (t->n >= LUB_MAX_PHASES) lub_bug("more than %d timed phases", LUB_MAX_PHASES);
    t->name[t->n] = name;
    t->seconds[t->n] = 0.0;
    t->started[t->n] = 0.0;
    return t->n++;
}

double lub_load_average(const char *path, int *runnable)
{
    if (runnable) *runnable = -1;
    FILE *f = fopen(path ? path : "/proc/loadavg", "r");
    if (!f) return -1.0;
    double load = -1.0;
    int running = -1;
    if (fscanf(f, "%lf", &load) != 1 || !(load >= 0))
        load = -1.0;
    else if (fscanf(f, "%*f %*f %d/%*d", &running) != 1 || running < 0)
        running = -1;
    if (runnable) *runnable = running;
    fclose(f);
    return load;
}

long lub_peak_memory_kb(const char *path)
{
    FILE *f = fopen(path ? path : "/proc/self/status", "r");
    if (!f) return -1;
    char line[256];
    long kb = -1;
    while (kb < 0 && fgets(line, sizeof line, f))
        if (sscanf(line, "VmHWM: %ld kB", &kb) != 1) kb = -1;
    fclose(f);
    return kb;
}

double lub_load_now(double average, int others)
{
    if (!(average >= 0)) return -1.0;
    return others >= 0 && others < average ? (double)others : average;
}

int lub_threads_oversubscribed(double load, int cores, int threads, int *fit)
{
    int free_cores = load >= 0 ? (int)floor(cores - load + 0.5) : cores;
    if (fit) *fit = free_cores < 1 ? 1 : free_cores > threads ? threads : free_cores;
    return threads > 1 && load >= 0 && load + threads > cores + 0.5;
}
