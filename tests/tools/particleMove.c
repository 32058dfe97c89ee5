/* particleMove [-u] DIR ID X Y [Z] [ID X Y [Z] ...]: put the particles of the given ids of
 * DIR/particles.h5 at the given positions (velocity and pressure kept), or with -u give them
 * the given velocities (position and pressure kept), rewriting the file: a test's way to
 * build a state particleGen does not make (tests/cases/parallel: a group of particles
 * squeezed together across a slab boundary, two particles thrown at each other across it).
 * Exit 1 on a bad argument or an id not in the file. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "particles/particles_io.h"

int main(int argc, char **argv)
{
    lub_set_program("particleMove");
    int vel = 0;
    if (argc > 1 && strcmp(argv[1], "-u") == 0) vel = 1, argc--, argv++;
    if (argc < 2) lub_fatal("usage: particleMove [-u] DIR ID X Y [Z] [ID X Y [Z] ...]");
    char path[4096];
    snprintf(path, sizeof path, "%s/particles.h5", argv[1]);
    lub_particles P;
    lub_particles_read(&P, path);
    const int per = 1 + P.dim;
    if ((argc - 2) % per != 0 || argc == 2)
        lub_fatal("give ID and %d coordinates per particle", P.dim);
    for (int a = 2; a < argc; a += per) {
        const unsigned long long id = strtoull(argv[a], NULL, 10);
        size_t i = 0;
        while (i < P.n && P.id[i] != id) i++;
        if (i == P.n) lub_fatal("no particle with id %llu in '%s'", id, path);
        for (int d = 0; d < P.dim; d++) (vel ? P.u : P.x)[d][i] = strtod(argv[a + 1 + d], NULL);
    }
    lub_particles_write(&P, argv[1]);
    lub_particles_free(&P);
    return 0;
}
