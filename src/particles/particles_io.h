/* lubkit particle files: <time>/particles.h5 (HDF5) and the XDMF files ParaView opens.
 *
 * Layout of particles.h5 (design.md "Particle files"):
 *
 *     /  attributes: format = "lubkit-particles-1" (string), time (float64), step (int64),
 *                   dimension (int32), nLevels (int32)
 *     /level<k>      attributes l0, re, n0, lambda0 (float64), k = 0 .. nLevels-1
 *     /patches       npatches fixed-length strings (64 bytes, null-terminated)
 *     /fields/position  N x 3 float64 (z = 0 in 2-D)      /fields/velocity  N x 3 float64
 *     /fields/pressure  N float64                          /fields/kind      N uint8
 *     /fields/patch     N uint16                           /fields/level     N uint8
 *     /fields/id        N uint64                           /fields/<extra>   N float64
 *     /xdmf/connectivity  N uint32: 0 .. N-1, the Polyvertex cells of the XDMF description
 *                       (ParaView's Xdmf3 readers make no cells without it); not read back
 *
 * A fluid particle's patch index is meaningless and written as 0 (allowed even when there
 * are no patches); a wall or dummy particle's patch index must name one of /patches.
 *
 * particles.xdmf next to each particles.h5 describes the same datasets for one time (paths
 * relative to the folder); <case>/particles.xdmf is the temporal collection over all time
 * folders.  Both are XDMF 3 and open in ParaView's Xdmf3 readers without plugins.
 */
#ifndef LUB_PARTICLES_PARTICLES_IO_H
#define LUB_PARTICLES_PARTICLES_IO_H

#include <stddef.h>
#include <stdint.h>

#include "io/case.h"
#include "particles/particles.h"

#define LUB_PARTICLES_FORMAT "lubkit-particles-1"

/* Write <dir>/particles.h5 and its sidecar <dir>/particles.xdmf, each through a temporary
 * name renamed when complete (dir is normally the temporary folder of lub_timedir_begin).
 * Only particles 0 .. P->n-1 are written, in id order (the rows of every time are then the
 * same particles wherever the set is the same), every dataset with HDF5's Fletcher32
 * checksum; the order P holds them in is kept in /solver/order when it is not the id
 * order, and lub_particles_read restores it.  Fatal run error (exit 2) naming the file and
 * the HDF5 reason when writing fails.  A non-finite value is a failed run (exit 2). */
void lub_particles_write(const lub_particles *P, const char *dir);

/* A row of the id order: the particle's id and its index in P. */
typedef struct {
    uint64_t id;
    size_t index;
} lub_particles_rank;

/* The buffers of lub_particles_write allocated once, for a time loop that writes without
 * allocating: room for cap particles (more is a bug: reserve the capacity the particles
 * can reach). */
typedef struct {
    size_t cap;
    double *buf;              /* 3 cap values: one field's rows */
    lub_particles_rank *rank; /* cap rows: the sort by id */
    int sync_dir;             /* 1 (init): fsync dir after the renames; 0 when dir is a
                                 temporary time folder, which lub_timedir_commit syncs */
} lub_particles_writer;
void lub_particles_writer_init(lub_particles_writer *w, size_t cap);
void lub_particles_writer_free(lub_particles_writer *w);
/* lub_particles_write with w's buffers. */
void lub_particles_writer_write(lub_particles_writer *w, const lub_particles *P, const char *dir);

/* 1 when this build's HDF5 is Open MPI's (make HDF5=mpi): lubFoam -parallel writes its
 * particle files collectively. */
int lub_particles_collective(void);
/* The collective write of <dir>/particles.h5 (every rank of MPI_COMM_WORLD calls it, after
 * MPI_Init, with the same dir, n and P's header: lubFoam -parallel): the file
 * lub_particles_write writes of the particles of all ranks, through MPI-IO, this rank
 * writing rows first .. first + P->n - 1 of n from P, which holds them in id order; place[r]
 * is the solver's place of row r's particle (the order of all ranks' particles one rank
 * after the other: /solver/order when it is not the id order).  Rank 0 renames the file
 * into place after the collective close and writes particles.xdmf.  A failure on any rank
 * is a fatal run error on all (exit 2).  A bug in a build with the serial HDF5. */
void lub_particles_writer_write_rows(lub_particles_writer *w, const lub_particles *P,
                                     const uint64_t *place, size_t first, size_t n,
                                     const char *dir);
/* Read a particle file into P, which must hold no storage (never initialised, or freed);
 * P->cap == P->n afterwards (reserve more before a time loop).  Every check of the format is
 * made (attributes, dataset presence, ranks, shapes, types, kinds, patch and level indices,
 * finite positions); a foreign, damaged or inconsistent file is a fatal input error (exit 1)
 * naming the file, with P left holding no storage. */
void lub_particles_read(lub_particles *P, const char *path);

/* Rows first .. first + count - 1 of a particle file into P (which must hold no storage),
 * by hyperslabs, with the checks of lub_particles_read on those rows (messages name the
 * file's rows), and place[i] (count entries) the solver's place of row first + i's
 * particle (/solver/order, or the row itself when the file has none: the id order), each
 * below the file's particle count; the particles stay in row order.  The rank-slice read
 * of a parallel restart (every rank its rows, HDF5's default driver: no collective call).
 * Fatal input error (exit 1) as lub_particles_read, and when the rows are not in the file. */
void lub_particles_read_rows(lub_particles *P, const char *path, size_t first, size_t count,
                             uint64_t *place);
/* What a particle file holds, from its header and dataset shapes only (no particle data). */
typedef struct {
    int dim;
    size_t n;
    double time;
    long step;
    int nlevels, npatches, nextra;
    int conn_bytes; /* entry size of /xdmf/connectivity (4 or 8), 0 when absent */
    char extra[LUB_MAX_EXTRA][LUB_NAME_MAX];
} lub_particles_info;

/* Fatal input error (exit 1) naming the file when it is not a lubkit particle file. */
void lub_particles_read_info(const char *path, lub_particles_info *info);

/* <case>/particles.xdmf: the temporal collection over every time folder that holds a
 * particles.h5, each grid with the exact time of its file.  A solver keeps the index of the
 * collection (lub_xdmf_series) and rewrites the file from it after every time it writes,
 * without opening the other folders' files again (that made writing grow with the square of
 * the number of folders). */
typedef struct {
    char name[64]; /* the folder */
    double time;   /* the file's time attribute [s] */
    size_t n;
    int conn_bytes, nextra;
    char extra[LUB_MAX_EXTRA][LUB_NAME_MAX];
} lub_xdmf_entry;
typedef struct {
    lub_case c;
    lub_xdmf_entry *e; /* sorted by time */
    size_t n, cap;
} lub_xdmf_series;
/* Index every time folder's particles.h5 (headers only; a folder whose file cannot be read
 * is left out with a warning).  The file is not written. */
void lub_xdmf_series_scan(lub_xdmf_series *s, const lub_case *c);
/* Add (or replace) the folder `name` holding P's particles, and rewrite the file. */
void lub_xdmf_series_put(lub_xdmf_series *s, const char *name, const lub_particles *P);
/* Leave the folder `name` out (before deleting it), and rewrite the file. */
void lub_xdmf_series_remove(lub_xdmf_series *s, const char *name);
/* Write the file atomically (none, and an old one removed, when the index is empty);
 * returns the number of times listed. */
size_t lub_xdmf_series_write(const lub_xdmf_series *s);
void lub_xdmf_series_free(lub_xdmf_series *s);

/* Scan and write in one: particleGen, and any program that changes time folders once. */
size_t lub_case_xdmf_write(const lub_case *c);

#endif
