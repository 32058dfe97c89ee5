/* lubkit core: the near misses of a word (see spell.h). */
#include "core/spell.h"

#include <string.h>
#include <strings.h>

int lub_edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > 255 || lb > 255) return (int)(la > lb ? la : lb);
    int prev[256], cur[256];
    for (size_t j = 0; j <= lb; j++) prev[j] = (int)j;
    for (size_t i = 1; i <= la; i++) {
        cur[0] = (int)i;
        for (size_t j = 1; j <= lb; j++) {
            int sub = prev[j - 1] + (a[i - 1] != b[j - 1]);
            int del = prev[j] + 1, ins = cur[j - 1] + 1;
            cur[j] = sub < del ? (sub < ins ? sub : ins) : (del < ins ? del : ins);
        }
        memcpy(prev, cur, (lb + 1) * sizeof *prev);
    }
    return prev[lb];
}

const char *lub_closest(const char *word, const char *const *cand, size_t n)
{
    const char *best = NULL;
    int bestd = 1 << 30;
    size_t lw = strlen(word);
    int limit = lw <= 4 ? 1 : lw <= 8 ? 2 : 3;
    for (size_t i = 0; i < n; i++) {
        int dist = lub_edit_distance(word, cand[i]);
        /* a differing letter case only (Deltat for deltaT) counts as a near miss */
        if (dist > 0 && strcasecmp(word, cand[i]) == 0) dist = 1;
        if (dist < bestd) {
            bestd = dist;
            best = cand[i];
        }
    }
    return bestd <= limit ? best : NULL;
}
