/* reynoldsRef: the parts shared by the rigid reference (reynoldsRef.c) and the soft-EHL mode
 * (reynoldsRefEHL.c). */
#ifndef REYNOLDSREF_H
#define REYNOLDSREF_H

#include "io/case.h"
#include "reynolds/refcase.h"

/* The table "# x p h [X P H]" (h the film at the nodes of G's grid) to out_file, or to
 * postProcessing/reynoldsRef/<tname>/p.dat; d is NULL without -dimensionless.  The path
 * written goes to written (LUB_PATH_MAX). */
void reynoldsRef_table_write(const lub_case *c, const char *out_file, const char *tname,
                             const lub_refgap *G, const double *h, const double *p,
                             const lub_refscales *d, char *written);

/* Soft EHL (rc->ehl): solve the Reynolds equation, the elastic deformation and the load
 * balance on G's grid (src/reynolds/ehl.h), write the table and print the report.  A failed
 * solve is fatal with exit 2 (nothing written). */
void reynoldsRef_soft_ehl(const lub_case *c, const lub_refcase *rc, const lub_refgap *G,
                          const char *out_file, const char *tname, int dimensionless,
                          double t_start);

#endif
