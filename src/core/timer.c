/* lubkit wall-clock timing (see timer.h). */
#include "core/timer.h"

#include "core/error.h"

int lub_timers_add(lub_timers *t, const char *name)
{
    if (t->n >= LUB_MAX_PHASES) lub_bug("more than %d timed phases", LUB_MAX_PHASES);
    t->name[t->n] = name;
    t->seconds[t->n] = 0.0;
    t->started[t->n] = 0.0;
    return t->n++;
}
