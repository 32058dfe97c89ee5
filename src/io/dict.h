/* lubkit dictionaries: strict, typed access to YAML case files (libyaml).
 *
 * A dictionary is one YAML file whose root is a block mapping.  Every lookup names the key;
 * every error names file:line:column, what was expected and what was found:
 *
 *     system/schemes.yaml:4:3: unknown key 'gradiant' (did you mean 'gradient'?)
 *     system/controlDict.yaml:6:10: 'deltaT' must be > 0, found '-1e-6'
 *
 * Strictness: each mapping remembers the keys the program asked for (whether present or
 * not).  lub_dict_finish() walks every mapping the program looked into and reports the
 * first key nobody asked for, suggesting the closest known key.  A reader therefore asks for
 * all the keys it understands (getters with defaults count), then calls lub_dict_finish().
 *
 * Errors are fatal (lub_fatal_at, exit 1); unit tests catch them with lub_error_catch.
 * Nodes belong to their dictionary and live until lub_dict_free().
 */
#ifndef LUB_IO_DICT_H
#define LUB_IO_DICT_H

#include <math.h>
#include <stddef.h>

#include "core/spell.h" /* lub_closest: the readers' "did you mean" */

typedef struct lub_dict lub_dict;
typedef struct lub_node lub_node;

typedef enum { LUB_NODE_SCALAR, LUB_NODE_SEQUENCE, LUB_NODE_MAPPING } lub_node_type;

/* Valid range of a real value.  lo_open/hi_open make the bound strict. */
typedef struct {
    double lo, hi;
    int lo_open, hi_open;
} lub_range;
#define LUB_ANY ((lub_range){-INFINITY, INFINITY, 0, 0})
#define LUB_POSITIVE ((lub_range){0.0, INFINITY, 1, 0})
#define LUB_NONNEGATIVE ((lub_range){0.0, INFINITY, 0, 0})
#define LUB_UNIT ((lub_range){0.0, 1.0, 0, 0})
#define LUB_BETWEEN(a, b) ((lub_range){(a), (b), 0, 0})

/* ---- files ---------------------------------------------------------------------------- */

/* Read and parse a dictionary.  A missing file, a YAML syntax error or a root that is not a
 * mapping is fatal (names the file, and the line for syntax errors).  An empty file is an
 * empty mapping. */
lub_dict *lub_dict_read(const char *path);
/* As lub_dict_read, but returns NULL when the file does not exist. */
lub_dict *lub_dict_read_optional(const char *path);
/* Parse text held in memory; name is used in messages (tests, -set values). */
lub_dict *lub_dict_parse(const char *name, const char *text);
void lub_dict_free(lub_dict *d);

/* Check an edit with the readers before it is written (lubDict): until called again with
 * path NULL, every lub_dict_read / lub_dict_read_optional of the file at `path` (the same
 * file under any name: device and inode) parses `text` instead, and its messages name the
 * file `name`.  A path that does not exist substitutes nothing. */
void lub_dict_substitute(const char *path, const char *name, const char *text);

lub_node *lub_dict_root(const lub_dict *d);
const char *lub_dict_path(const lub_dict *d);

/* Report the first unknown key in every mapping that was looked into (fatal). */
void lub_dict_finish(const lub_dict *d);

/* ---- nodes ---------------------------------------------------------------------------- */

lub_node_type lub_node_type_of(const lub_node *n);
int lub_node_line(const lub_node *n); /* 1-based */
int lub_node_col(const lub_node *n);  /* 1-based */
const char *lub_node_file(const lub_node *n);
/* Scalar text (fatal if n is not a scalar). */
const char *lub_node_text(const lub_node *n);
/* Number of items of a sequence or entries of a mapping (0 for a scalar). */
size_t lub_node_size(const lub_node *n);
/* Item i of a sequence. */
lub_node *lub_node_item(const lub_node *seq, size_t i);
/* Entry i of a mapping: its key text and value.  Iterating marks the key as known. */
const char *lub_node_key_at(const lub_node *map, size_t i);
lub_node *lub_node_value_at(const lub_node *map, size_t i);
/* Path of a node for messages, e.g. "walls.cylinder.radius". */
const char *lub_node_path(const lub_node *n);

/* Fatal error located at a node: "<file>:<line>:<col>: <message>". */
_Noreturn void lub_node_error(const lub_node *n, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* Conversions of a scalar node (fatal with location on a wrong type). */
double lub_node_real(const lub_node *n, lub_range r);
long lub_node_int(const lub_node *n, long lo, long hi);
int lub_node_bool(const lub_node *n); /* true/false, yes/no, on/off */

/* ---- lookups in a mapping --------------------------------------------------------------
 * All of these mark `key` as known in `map`.  "_or" variants return the default when the key
 * is absent; the others are fatal when it is absent ("missing required key 'x' in ...").
 * A value of the wrong type or out of range is fatal.  map may be NULL for the "_or" and
 * "find" variants (an absent sub-dictionary): the default is returned. */

lub_node *lub_dict_find(lub_node *map, const char *key); /* NULL if absent */
lub_node *lub_dict_get(lub_node *map, const char *key);  /* required, any type */
int lub_dict_has(lub_node *map, const char *key);

double lub_dict_real(lub_node *map, const char *key, lub_range r);
double lub_dict_real_or(lub_node *map, const char *key, double def, lub_range r);
long lub_dict_int(lub_node *map, const char *key, long lo, long hi);
long lub_dict_int_or(lub_node *map, const char *key, long def, long lo, long hi);
int lub_dict_bool_or(lub_node *map, const char *key, int def);
const char *lub_dict_str(lub_node *map, const char *key);
const char *lub_dict_str_or(lub_node *map, const char *key, const char *def);

/* One of a fixed set of words; returns its index.  choices is NULL-terminated.  A value not
 * in the set is fatal and lists the choices (with a "did you mean").  def < 0: required. */
int lub_dict_choice(lub_node *map, const char *key, const char *const *choices, int def);

/* A sequence of reals ("[0, -9.81]") with nmin..nmax items, each in range r; returns the
 * count.  _or: returns 0 and leaves out untouched when absent. */
int lub_dict_vec(lub_node *map, const char *key, double *out, int nmin, int nmax, lub_range r);
int lub_dict_vec_or(lub_node *map, const char *key, double *out, int nmin, int nmax,
                    lub_range r);

/* Sub-dictionaries: a mapping / a sequence (fatal if present with another type). */
lub_node *lub_dict_map(lub_node *map, const char *key);    /* required */
lub_node *lub_dict_map_or(lub_node *map, const char *key); /* NULL if absent */
lub_node *lub_dict_seq(lub_node *map, const char *key);    /* required */
lub_node *lub_dict_seq_or(lub_node *map, const char *key); /* NULL if absent */

/* Fatal unless a node is a mapping / sequence (for list items). */
lub_node *lub_node_expect_map(lub_node *n);

#endif
