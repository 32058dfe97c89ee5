/* lubkit tables: the whitespace-separated format every utility reads and writes.
 *
 *     # x[m] p[Pa] h[m]
 *     -0.001 12345.678901234567 4.0e-05
 *
 * First line "# name1 name2 ..." (units in brackets allowed), then one row per line written
 * with "%.17g".  Further lines starting with '#' and blank lines are ignored when reading.
 * Columns are looked up by name, ignoring the unit: "x" finds "x[m]".
 */
#ifndef LUB_IO_TABLE_H
#define LUB_IO_TABLE_H

#include <stddef.h>
#include <stdio.h>

typedef struct {
    char source[1024]; /* file name, or "<stdin>" */
    size_t ncol, nrow;
    char **names;      /* ncol names as written (with units) */
    double *data;      /* row-major: data[r * ncol + c] */
} lub_table;

/* Read a table from a file, or standard input when path is "-".  Fatal (exit 1) with
 * file:line on a missing header, a non-numeric cell or a row of the wrong length. */
void lub_table_read(lub_table *t, const char *path);
void lub_table_free(lub_table *t);
/* Index of column `name` (unit ignored), or -1. */
int lub_table_find(const lub_table *t, const char *name);
/* As find, but fatal with the list of available columns. */
int lub_table_col(const lub_table *t, const char *name);
static inline double lub_table_at(const lub_table *t, size_t r, size_t c)
{
    return t->data[r * t->ncol + c];
}

/* Writing: header from a space-separated name list, rows with %.17g. */
void lub_table_write_header(FILE *fp, const char *names);
void lub_table_write_row(FILE *fp, const double *values, size_t n);

/* Output destination of a utility: standard output, or FILE written atomically (-o FILE). */
typedef struct {
    FILE *fp;
    int atomic;
    char path[4096], tmp[4096];
} lub_output;
void lub_output_open(lub_output *o, const char *path_or_null); /* fatal on failure */
void lub_output_close(lub_output *o);                          /* fatal on failure */

#endif
