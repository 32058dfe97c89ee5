/* lubkit core: "did you mean": the known word nearest to a misspelt one, for the messages of
 * the dictionaries (io/dict.h) and the command-line options (core/args.h). */
#ifndef LUB_CORE_SPELL_H
#define LUB_CORE_SPELL_H

#include <stddef.h>

/* Levenshtein distance, and the closest candidate within a reasonable distance (or NULL): one
 * edit for words of up to 4 letters, two up to 8, three beyond; a word differing in letter
 * case only counts as one edit. */
int lub_edit_distance(const char *a, const char *b);
const char *lub_closest(const char *word, const char *const *candidates, size_t n);

#endif
