/* lubFoam internals shared by its source files (not part of liblub). */
#ifndef LUBFOAM_H
#define LUBFOAM_H

#include <stdio.h>

#include "geometry/geometry.h"
#include "io/case.h"
#include "io/control.h"
#include "models/model.h"
#include "mps/mps.h"
#include "mps/opt.h"

/* Run state the writers need. */
typedef struct {
    lub_case cs;
    lub_control ctl;
    lub_mps mps;       /* single resolution: the solver */
    lub_opt *opt;      /* multi-resolution (constant/models.yaml multiResolution): the levels and
                          their solvers (mps/opt.h), else NULL; mps is then unused */
    lub_particles P;   /* the particles (multi-resolution: all levels, merged after every step) */
    lub_scene scene;   /* the models of constant/models.yaml */
    double mass0;      /* multi-resolution: the fluid mass M^0 of the run's first start (T-27) */
    int has_opt_state; /* the start folder's uniform/state.yaml has multiResolution: */
    unsigned long long next_id; /*   the next particle id, */
    double state_mass0;         /*   and M^0 (an exact restart continues both) */
    double t, dt;
    long step;
    double start_time;
    char start_name[64];
    /* time folders written by this run, oldest first (for purgeWrite) */
    char (*written)[64];
    size_t nwritten, capwritten;
} lubfoam_run;

/* The solver of the finest level (the only one in a single-resolution run): its l0,
 * configuration and domain. */
static inline const lub_mps *lubfoam_mps0(const lubfoam_run *r)
{
    return r->opt ? &r->opt->m[0] : &r->mps;
}

/* Start time folder per controlDict (startFrom), reading particles and uniform/state.yaml. */
void lubfoam_read_start(lubfoam_run *r);
/* Write the current state as a time folder (atomic), update particles.xdmf, purge. */
void lubfoam_write(lubfoam_run *r);

/* Multi-resolution start-up checks (lubFoamChecks.c; nothing without r->opt): for every
 * fine/coarse boundary, the coarse particles across the film there (at least 4-5) and its
 * place against the inflection points of the Reynolds pressure of
 * system/reynoldsRefDict.yaml.  Warnings only. */
void lubfoam_check_levels(const lubfoam_run *r, const lub_geometry *geo);

/* Function objects (controlDict `functions`): _read checks their dictionaries, _start opens
 * their tables under postProcessing/ (a run with no step to take writes none), _execute
 * after every step, _write at every write time and at the end. */
typedef struct lubfoam_functions lubfoam_functions;
lubfoam_functions *lubfoam_functions_read(lubfoam_run *r);
void lubfoam_functions_start(lubfoam_functions *f, lubfoam_run *r);
void lubfoam_functions_execute(lubfoam_functions *f, lubfoam_run *r);
void lubfoam_functions_write(lubfoam_functions *f, lubfoam_run *r);
void lubfoam_functions_free(lubfoam_functions *f);

#endif
