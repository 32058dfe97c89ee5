/* lubFoam internals shared by its source files (not part of liblub). */
#ifndef LUBFOAM_H
#define LUBFOAM_H

#include <stdio.h>

#include "geometry/geometry.h"
#include "io/case.h"
#include "io/control.h"
#include "models/model.h"
#include "mps/mps.h"

/* Run state the writers need. */
typedef struct {
    lub_case cs;
    lub_control ctl;
    lub_particles P; /* the particles (with resolution levels: all levels, merged after every
                        step by the model that solves them) */
    lub_scene scene; /* the models of constant/models.yaml and the fluid's solvers, one per
                        resolution level (scene.level) */
    double t, dt;
    long step;
    double start_time;
    char start_name[64];
    /* time folders written by this run, oldest first (for purgeWrite) */
    char (*written)[64];
    size_t nwritten, capwritten;
} lubfoam_run;

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
