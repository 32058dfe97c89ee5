/* lubkit text-preserving YAML edits (lubDict, lubSweep).
 *
 * A dictionary is edited as text: the libyaml event parser gives the byte span of the node at
 * a dot path ("models.elasticWall.E", "levels.0.l0"; integers index sequences), and only that
 * span is replaced, so comments, layout and flow style elsewhere stay byte-for-byte the same.
 * Every edit is checked by parsing the edited text again: it must be valid YAML, and the
 * document must be the old one with only the edited entry changed, reading back as the new
 * value.  An edit that fails the check is fatal and leaves the text (and the file) unchanged.
 *
 * Values are YAML text on one line: a number, a word, "[1, 2]", "{a: 1}", '"quoted"'.
 * Errors are fatal (lub_fatal_at, exit 1) and name the file:
 *
 *     constant/models.yaml: no entry 'elasticWall.EE' (did you mean 'elasticWall.E'?)
 */
#ifndef LUB_IO_YAMLEDIT_H
#define LUB_IO_YAMLEDIT_H

#include <stddef.h>

typedef struct {
    char name[4096]; /* file name for messages */
    char *text;      /* the document text, edits applied (NUL-terminated) */
    size_t len;
} lub_yaml_text;

/* Read a file (fatal if it cannot be read or is not valid UTF-8 YAML). */
void lub_yaml_text_read(lub_yaml_text *y, const char *path);
/* Take text from memory (copied); name is used in messages.  Fatal if not valid YAML. */
void lub_yaml_text_init(lub_yaml_text *y, const char *name, const char *text);
void lub_yaml_text_free(lub_yaml_text *y);
/* Write atomically to path (following a symbolic link, keeping the file's permissions).
 * Fatal (exit 2) on an I/O error; the old file is then untouched. */
void lub_yaml_text_write(const lub_yaml_text *y, const char *path);

/* 1 if the entry exists. */
int lub_yaml_has(const lub_yaml_text *y, const char *key);
/* The entry's value: a scalar's value (quotes and escapes resolved), or the source text of a
 * mapping or sequence (block collections dedented).  Newly allocated; fatal if absent. */
char *lub_yaml_get(const lub_yaml_text *y, const char *key);
/* Keys of the mapping at key ("" or NULL: the root), or the indices "0".."n-1" of a
 * sequence.  Returns the count; *keys is allocated (free with lub_yaml_keys_free). */
size_t lub_yaml_keys(const lub_yaml_text *y, const char *key, char ***keys);
void lub_yaml_keys_free(char **keys, size_t n);

/* Replace the value of an existing entry by `value` (YAML text). */
void lub_yaml_set(lub_yaml_text *y, const char *key, const char *value);
/* Add an entry that does not exist yet to its mapping (block or flow), creating missing
 * intermediate mappings as flow mappings ("a.b.c=1" with only "a" present adds
 * "b: {c: 1}" to a).  Fatal if the entry exists. */
void lub_yaml_add(lub_yaml_text *y, const char *key, const char *value);

/* Take the entry at key out of its mapping or sequence: in block style its whole lines go
 * (with the comment after its value and that comment's continuation lines, aligned under
 * it), the other lines and comments stay; the last entry of a nested block collection
 * leaves an empty flow one ("{}", "[]").  Fatal if the entry does not exist. */
void lub_yaml_remove(lub_yaml_text *y, const char *key);

/* Every value under key ("" or NULL: the whole document) as "path = value" lines, path a
 * dot path as lub_yaml_get takes it: scalars as their value (a line break as "\n"), a
 * sequence of scalars on one line as "[a, b]" (each item's source text), an empty
 * collection as "[]" or "{}", an alias as "*name".  Newly allocated. */
char *lub_yaml_values(const lub_yaml_text *y, const char *key);

/* "key=value" split at the first '=' into key and value buffers (allocated); fatal on a
 * missing '=' or an empty key.  what names the option in messages ("-set"). */
void lub_yaml_split_assignment(const char *arg, const char *what, char **key, char **value);

#endif
