/* lubkit particles: structure-of-arrays storage (see particles.h).
 *
 * Every per-particle array, the extra fields included, has the same capacity P->cap, so
 * growing is one place (lub_particles_reserve).  lub_particles_add doubles the capacity when
 * full, which is fine while particles are generated; the solver reserves what it needs before
 * its time loop, so the loop itself never allocates.
 */
#include "particles/particles.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* Names of the standard datasets in /fields of a particle file: an extra field must not take
 * one of them. */
static const char *const standard_fields[] = {"position", "velocity", "pressure", "kind",
                                              "patch",    "level",    "id"};

static void check_name(const char *what, const char *name)
{
    size_t len = strlen(name);
    if (len == 0) lub_fatal("empty %s name", what);
    if (len >= LUB_NAME_MAX)
        lub_fatal("%s name '%s' is too long (%zu characters, at most %d)", what, name, len,
                  LUB_NAME_MAX - 1);
    /* Names become HDF5 link names and XML attribute values. */
    for (const char *c = name; *c; c++)
        if (*c == '/' || *c == '<' || *c == '>' || *c == '&' || *c == '"' || *c == '\'' ||
            (unsigned char)*c < 32)
            lub_fatal("%s name '%s' contains the character '%c' (not allowed in names)", what, name,
                      *c);
    if (strcmp(name, ".") == 0 || strcmp(name, "..") == 0)
        lub_fatal("'%s' is not a valid %s name", name, what);
}

void lub_particles_init(lub_particles *P, int dim, size_t cap)
{
    if (dim != 2 && dim != 3) lub_bug("dimension %d (expected 2 or 3)", dim);
    memset(P, 0, sizeof *P);
    P->dim = dim;
    P->nlevels = 1;
    lub_particles_reserve(P, cap ? cap : 16);
}

void lub_particles_free(lub_particles *P)
{
    for (int d = 0; d < 3; d++) {
        free(P->x[d]);
        free(P->u[d]);
    }
    free(P->p);
    free(P->kind);
    free(P->patch);
    free(P->level);
    free(P->id);
    for (int e = 0; e < P->nextra; e++) free(P->extra[e].v);
    memset(P, 0, sizeof *P);
}

void lub_particles_reserve(lub_particles *P, size_t cap)
{
    if (cap <= P->cap) return;
    size_t old = P->cap;
    for (int d = 0; d < 3; d++) {
        P->x[d] = lub_regrow(P->x[d], old, cap, sizeof(double));
        P->u[d] = lub_regrow(P->u[d], old, cap, sizeof(double));
    }
    P->p = lub_regrow(P->p, old, cap, sizeof(double));
    P->kind = lub_regrow(P->kind, old, cap, sizeof(uint8_t));
    P->patch = lub_regrow(P->patch, old, cap, sizeof(uint16_t));
    P->level = lub_regrow(P->level, old, cap, sizeof(uint8_t));
    P->id = lub_regrow(P->id, old, cap, sizeof(uint64_t));
    for (int e = 0; e < P->nextra; e++)
        P->extra[e].v = lub_regrow(P->extra[e].v, old, cap, sizeof(double));
    P->cap = cap;
}

size_t lub_particles_add(lub_particles *P, const double *x, int kind, int patch, int level)
{
    if (kind < LUB_FLUID || kind > LUB_DUMMY) lub_bug("particle kind %d", kind);
    if (patch < 0 || patch >= LUB_MAX_PATCHES) lub_bug("patch index %d", patch);
    if (level < 0 || level >= LUB_MAX_LEVELS) lub_bug("level %d", level);
    if (P->n == P->cap) lub_particles_reserve(P, P->cap ? 2 * P->cap : 16);
    size_t i = P->n++;
    for (int d = 0; d < 3; d++) {
        P->x[d][i] = d < P->dim ? x[d] : 0.0; /* z = 0 in 2-D */
        P->u[d][i] = 0.0;
    }
    P->p[i] = 0.0;
    P->kind[i] = (uint8_t)kind;
    P->patch[i] = (uint16_t)patch;
    P->level[i] = (uint8_t)level;
    P->id[i] = (uint64_t)i;
    for (int e = 0; e < P->nextra; e++) P->extra[e].v[i] = 0.0;
    return i;
}

int lub_particles_find_patch(const lub_particles *P, const char *name)
{
    for (int k = 0; k < P->npatches; k++)
        if (strcmp(P->patch_names[k], name) == 0) return k;
    return -1;
}

int lub_particles_patch(lub_particles *P, const char *name)
{
    int k = lub_particles_find_patch(P, name);
    if (k >= 0) return k;
    check_name("patch", name);
    if (P->npatches >= LUB_MAX_PATCHES)
        lub_fatal("too many patches: '%s' would be number %d (at most %d)", name, P->npatches + 1,
                  LUB_MAX_PATCHES);
    k = P->npatches++;
    strcpy(P->patch_names[k], name); /* length checked above */
    return k;
}

double *lub_particles_find_extra(const lub_particles *P, const char *name)
{
    for (int e = 0; e < P->nextra; e++)
        if (strcmp(P->extra[e].name, name) == 0) return P->extra[e].v;
    return NULL;
}

double *lub_particles_extra(lub_particles *P, const char *name)
{
    double *v = lub_particles_find_extra(P, name);
    if (v) return v;
    check_name("extra field", name);
    for (size_t k = 0; k < sizeof standard_fields / sizeof *standard_fields; k++)
        if (strcmp(name, standard_fields[k]) == 0)
            lub_fatal("extra field name '%s' is a standard particle field", name);
    if (P->nextra >= LUB_MAX_EXTRA)
        lub_fatal("too many extra particle fields: '%s' would be number %d (at most %d)", name,
                  P->nextra + 1, LUB_MAX_EXTRA);
    lub_extra_field *f = &P->extra[P->nextra++];
    strcpy(f->name, name);
    f->v = lub_calloc(P->cap ? P->cap : 1, sizeof(double));
    return f->v;
}
