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

#include "io/case.h"
#include "particles/particles.h"

#define LUB_PARTICLES_FORMAT "lubkit-particles-1"

/* Write <dir>/particles.h5 and its sidecar <dir>/particles.xdmf, each through a temporary
 * name renamed when complete (dir is normally the temporary folder of lub_timedir_begin).
 * Only particles 0 .. P->n-1 are written.  Fatal run error (exit 2) naming the file and the
 * HDF5 reason when writing fails. */
void lub_particles_write(const lub_particles *P, const char *dir);

/* Read a particle file into P, which must hold no storage (never initialised, or freed);
 * P->cap == P->n afterwards (reserve more before a time loop).  Every check of the format is
 * made (attributes, dataset presence, ranks, shapes, types, kinds, patch and level indices,
 * finite positions); a foreign, damaged or inconsistent file is a fatal input error (exit 1)
 * naming the file, with P left holding no storage. */
void lub_particles_read(lub_particles *P, const char *path);

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

/* Write <case>/particles.xdmf, the temporal collection over every time folder that holds a
 * particles.h5 (a folder whose file cannot be read is skipped with a warning), atomically.
 * Returns the number of times listed; with none, no file is written (and an old one is
 * removed).  Opens every listed file's header: call it after writing a time, not per step. */
size_t lub_case_xdmf_write(const lub_case *c);

#endif
