/* lubFoam internals shared by its source files (not part of liblub). */
#ifndef LUBFOAM_H
#define LUBFOAM_H

#include <stdio.h>

#include "geometry/geometry.h"
#include "io/case.h"
#include "io/control.h"
#include "io/particles_io.h"
#include "mps/elastic_wall.h"
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
    double mass0;      /* multi-resolution: the fluid mass M^0 of the run's first start (T-27) */
    int has_opt_state; /* the start folder's uniform/state.yaml has multiResolution: */
    unsigned long long next_id; /*   the next particle id, */
    double state_mass0;         /*   and M^0 (an exact restart continues both) */
    int has_elastic;            /* constant/models.yaml has elasticWall */
    lub_mps_elastic elastic;    /* its state */
    double t, dt;
    long step;
    double start_time;
    char start_name[64];
    /* time folders written by this run, oldest first (for purgeWrite) */
    char (*written)[64];
    size_t nwritten, capwritten;
    /* The write grid: write times are write_origin + k writeInterval (steps:
     * write_origin_step + k writeInterval) from the start of the case's first run, whatever
     * the restarts between (uniform/state.yaml carries it on). */
    double write_origin;
    long write_origin_step;
    lub_particles_writer writer; /* id-order buffers for every particle the run can hold */
    lub_xdmf_series series;      /* the index of <case>/particles.xdmf */
} lubfoam_run;

/* The solver of the finest level (the only one in a single-resolution run): its l0,
 * configuration and domain. */
static inline const lub_mps *lubfoam_mps0(const lubfoam_run *r)
{
    return r->opt ? &r->opt->m[0] : &r->mps;
}

/* Start time folder per controlDict (startFrom), reading particles and uniform/state.yaml. */
void lubfoam_read_start(lubfoam_run *r);
/* The elasticWall model of constant/models.yaml, if any (after lub_mps_init, or lub_opt_init:
 * then on every level): its restart state from the start folder's uniform/state.yaml, the
 * ramp checked against endTime. */
void lubfoam_read_elastic(lubfoam_run *r, const lub_geometry *geo);
/* Before the time loop: the writer's buffers (for r->P's capacity), the index of
 * particles.xdmf, and the leftovers of runs killed while writing removed (temporary files
 * and folders whose process is gone: lub_case_clean). */
void lubfoam_output_init(lubfoam_run *r);
void lubfoam_output_free(lubfoam_run *r);

typedef struct lubfoam_functions lubfoam_functions;
/* Write the current state as a time folder (atomic: the particles, uniform/state.yaml and
 * the function objects' running state in uniform/, then one rename), update
 * particles.xdmf, purge. */
void lubfoam_write(lubfoam_run *r, lubfoam_functions *fos);

/* The start folder's particles against system/particleGenDict.yaml: dimension, l0 and
 * every particle inside the domain (fatal, exit 1, naming the file). */
void lubfoam_check_particles(const lubfoam_run *r, const lub_geometry *geo);

/* Multi-resolution start-up checks (lubFoamChecks.c; nothing without r->opt): for every
 * fine/coarse boundary, the coarse particles across the film there (at least 4-5) and its
 * place against the inflection points of the Reynolds pressure of
 * system/reynoldsRefDict.yaml.  Warnings only. */
void lubfoam_check_levels(const lubfoam_run *r, const lub_geometry *geo);

/* Function objects (controlDict `functions`): _read checks their dictionaries, _start opens
 * their tables under postProcessing/ (a run with no step to take writes none), _execute
 * after every step, _write at every write time and at the end. */
lubfoam_functions *lubfoam_functions_read(lubfoam_run *r);
void lubfoam_functions_start(lubfoam_functions *f, lubfoam_run *r);
void lubfoam_functions_execute(lubfoam_functions *f, lubfoam_run *r);
void lubfoam_functions_write(lubfoam_functions *f, lubfoam_run *r);
/* The running state of the function objects (a wallPressure's sums) into the time folder
 * being written (dir, before it is renamed): a restart from any written time continues
 * it exactly. */
void lubfoam_functions_write_state(lubfoam_functions *f, const lubfoam_run *r, const char *dir);
void lubfoam_functions_free(lubfoam_functions *f);

#endif
