/* lubFoam internals shared by its source files (not part of liblub). */
#ifndef LUBFOAM_H
#define LUBFOAM_H

#include <stdio.h>

#include "geometry/geometry.h"
#include "io/case.h"
#include "io/control.h"
#include "models/model.h"
#include "particles/particles_io.h"
#include "mps/mps.h"
#include "parallel/par.h"

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
    /* The write grid: write times are write_origin + k writeInterval (steps:
     * write_origin_step + k writeInterval) from the start of the case's first run, whatever
     * the restarts between (uniform/state.yaml carries it on). */
    double write_origin;
    long write_origin_step;
    lub_particles_writer writer; /* id-order buffers for every particle the run can hold */
    lub_xdmf_series series;      /* the index of <case>/particles.xdmf */
    /* -parallel (lubFoamParallel.c): P holds this rank's slab.  The particle files: written
     * collectively (collective: every rank its rows R, in id order, place their solver's
     * places), or gathered into G on rank 0; rank 0 writes the rest of the time folders */
    int parallel;
    double cpu0; /* CPU seconds of the process when the time loop began (the cost) */
    lub_par par;
    lub_par_dict pd; /* system/decomposeParDict.yaml */
    size_t most;     /* the particles of the fullest slab at the start */
    lub_particles G;
    int collective;
    lub_particles R;
    uint64_t *place;
} lubfoam_run;

/* -parallel on the command line (MPI is started before the arguments are parsed). */
int lubfoam_wants_parallel(int argc, char **argv);
typedef struct lubfoam_functions lubfoam_functions;
/* -parallel, the start on the slabs (lubFoamParallel.c), in the order main calls them:
 *   _start       system/decomposeParDict.yaml against mpirun's process count, and the models
 *                of constant/models.yaml that are not parallel yet refused (exit 1, naming
 *                them), before anything reads the particles;
 *   _distribute  (lubfoam_read_start) this rank's slice of the start's file S (rows, their
 *                solver's places) sent to the slabs' owners: r->P holds this rank's slab;
 *   _capacity    (after lub_scene_read: the solver's configuration cfg) the formulation and
 *                solvers refused that are not parallel, the halo's width, and r->P's capacity
 *                for the slab, its halo and the margin, so that the solver built next is
 *                sized for them; the scene told of the ranks;
 *   _setup       (after the scene is built) the function objects refused that are not
 *                parallel, the decomposition said, the particle files' way chosen. */
void lubfoam_parallel_start(lubfoam_run *r, const lub_geometry *geo);
void lubfoam_parallel_distribute(lubfoam_run *r, const lub_geometry *geo, const lub_particles *S,
                                 const uint64_t *place, const char *path);
void lubfoam_parallel_capacity(lubfoam_run *r, const lub_mps_config *cfg);
void lubfoam_parallel_setup(lubfoam_run *r, const lubfoam_functions *fos);
void lubfoam_parallel_free(lubfoam_run *r);
/* A start-up check of the particles (check(r, ctx), fatal on failure): serially as it is;
 * -parallel, on this rank's slab, its failure every rank's (rank 0 prints the message of
 * the first failing rank, once). */
void lubfoam_collective_check(const lubfoam_run *r,
                              void (*check)(const lubfoam_run *r, const void *ctx),
                              const void *ctx);
/* Rank 0 writes the time folders (1 in a serial run); with r->collective every rank writes
 * its rows of the particle file. */
static inline int lubfoam_writer_rank(const lubfoam_run *r)
{
    return !r->parallel || r->par.rank == 0;
}

/* Start time folder per controlDict (startFrom), reading particles and uniform/state.yaml;
 * -parallel: each rank its rows of the particle file, then its slab (geo: the domain). */
void lubfoam_read_start(lubfoam_run *r, const lub_geometry *geo);
/* Before the time loop: the writer's buffers (for r->P's capacity), the index of
 * particles.xdmf, and the leftovers of runs killed while writing removed (temporary files
 * and folders whose process is gone: lub_case_clean). */
void lubfoam_output_init(lubfoam_run *r);
void lubfoam_output_free(lubfoam_run *r);

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
/* The name of the first function object that does not run in parallel (forces), or NULL. */
const char *lubfoam_functions_unparallel(const lubfoam_functions *f);

#endif
