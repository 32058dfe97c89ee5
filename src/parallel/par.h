/* lubkit parallel: a run on several MPI processes (ranks), `mpirun -np N lubFoam -parallel`
 * (issue 31; the plan and its state: doc/parallel.md).
 *
 * Decomposition (system/decomposeParDict.yaml, method): slabs along one axis, or ranges of
 * a space-filling curve (sfc).  Slabs: rank r owns the particles (fluid, wall and dummy)
 * whose coordinate on the axis lies in [cut[r], cut[r+1]).  sfc: the box is divided into
 * cells of about the halo's width, each cell has its index along a Hilbert curve (its key,
 * lub_par_hilbert), and rank r owns the particles whose cell's key lies in
 * [kcut[r], kcut[r+1]): a contiguous stretch of the curve, a compact patch of the case
 * whatever its shape (a bearing's ring, a thin film), where a slab of a ring holds unequal
 * arcs and thin slabs a halo as large as themselves.  The cuts (cut or kcut) are set at the
 * start, and again when re-balancing, at the quantiles of the coordinate or key over all
 * ranks (every rank holds about N / P particles), found by a parallel selection that holds
 * no rank's copy of all N.  Each rank keeps
 * its owned particles first in its lub_particles (indices 0 .. nown-1) and, during a step,
 * copies of the other ranks' particles within `width` of its slab (the halo, appended after
 * them: nown .. nown+nhalo-1), so that every neighbour sum of an owned particle is complete.
 * An axis of fewer than a quarter of the longest's cells (a film's thickness) is left out
 * of the curve: the cells across it share a key, and the ranges are patches of the film
 * through its thickness.
 * With sfc a particle goes to the halo of every other rank owning a cell within width of it
 * (the cells within ceil(width / cell) of its own along each axis, their owners by their
 * keys, cached per cell between re-cuts; across a periodic direction with the minimum
 * image).
 *
 *     lub_par_start(&argc, &argv);              first thing in main (MPI_Init)
 *     lub_par_init(&d, axis, width, lo, hi, periodic_axis);
 *     lub_par_distribute(&d, S, place, P);      each rank's slice of the start's file S to the
 *                                               slabs' owners: P holds this rank's slab
 *     each step (mps/step.c):
 *         lub_par_migrate(&d, P);               owned particles that left the slab to their owner
 *         lub_par_halo(&d, P);                  the halo, all fields; P->n = nown + nhalo
 *         lub_par_refresh(&d, a, sizeof *a);    one field of the halo anew (after a phase)
 *         ... P->n = d.nown at the end of the step
 *     lub_par_gather(&d, P, &G);                all particles on rank 0 (output)
 *
 * A halo particle is taken from every rank whose slab lies within width of it (not only the
 * adjacent ones: slabs narrower than the width are allowed), and in a periodic direction
 * along the axis across the period, with its own coordinates: the neighbour search takes the
 * minimum image (the end slabs then end at the box, lo and lo + period).  Migration and
 * halo exchange are all-to-all (MPI_Alltoallv): fine for the tens of ranks of a workstation
 * or a small cluster; the neighbour-only exchange of the plan is for later.
 *
 * Errors: once started, a fatal error on any rank ends all (MPI_Abort with its exit status).
 * While the ranks repeat the same start-up (reading the dictionaries and the particles:
 * lub_par_startup_done not yet called), rank 0 prints the message and the other ranks wait
 * for its abort (printing theirs only if it does not come within 10 s); after it, the rank
 * that fails prints the message with its rank.  Messages (lub_message) come from rank 0 only.
 *
 * A build without MPI (make MPI=0) has the names: lub_par_available() is 0, lub_par_start
 * is a fatal input error saying so, and the rest is never called.
 */
#ifndef LUB_PARALLEL_PAR_H
#define LUB_PARALLEL_PAR_H

#include <stddef.h>
#include <stdint.h>

#include "particles/particles.h"

/* system/decomposeParDict.yaml (etc/templates/decomposeParDict.yaml):
 *
 *     numberOfSubdomains: 2          # = mpirun -np
 *     method: slabs                  # slabs | sfc (ranges of a Hilbert curve over cells)
 *     slabs: { axis: auto }          # auto (the fluid's longest) | x | y | z
 *     balance: { interval: 0, imbalance: 0.1 }   # re-cut every interval steps (0: never)
 *                                    # when the fullest rank holds > (1 + imbalance) x mean
 *     writeParticles: auto           # collective (MPI-IO, every rank its rows: a build with
 *                                    # Open MPI's HDF5) | gather (to rank 0) | auto
 *     margin: 0.2                    # a slab's room at the start beyond its particles and
 *                                    # halo, for the migration (re-sized when it fills)
 *     weights: { fluid: 1, wall: 1, dummy: 1 }   # each kind's share of the work: the cuts
 *                                    # give every rank the same sum of weights
 *
 * Read from path for a dim-D case; nranks > 0: numberOfSubdomains must equal it (an error
 * at its line naming both otherwise).  Fatal (exit 1) at file:line on bad input. */
enum { LUB_PAR_SLABS, LUB_PAR_SFC };
typedef struct {
    int method;       /* LUB_PAR_SLABS, LUB_PAR_SFC */
    int axis;         /* 0, 1, 2; -1: auto */
    long interval;    /* balance.interval (0: never) */
    double imbalance; /* balance.imbalance */
    int write;        /* writeParticles: LUB_PAR_WRITE_* */
    double margin;    /* margin */
    double weight[3]; /* weights of LUB_FLUID, LUB_WALL, LUB_DUMMY */
} lub_par_dict;
enum { LUB_PAR_WRITE_AUTO, LUB_PAR_WRITE_COLLECTIVE, LUB_PAR_WRITE_GATHER };
void lub_par_read_dict(lub_par_dict *pd, const char *path, int dim, int nranks);

/* 1 when this build has MPI. */
int lub_par_available(void);
/* 1 when the process looks started by mpirun (Open MPI's or MPICH's environment). */
int lub_par_under_mpirun(void);
/* MPI_Init (and the fatal-error hook, rank 0's messages); fatal without MPI. */
void lub_par_start(int *argc, char ***argv);
/* 1 after lub_par_start */
int lub_par_started(void);
int lub_par_rank(void);
int lub_par_size(void);
/* Collective: when some rank has a message (msg != NULL), every rank ends with the first such
 * rank's (status LUB_EXIT_INPUT or LUB_EXIT_RUN; rank 0 prints it during the start-up): a
 * start-up check made on each rank's slab fails on all ranks together, its message once. */
void lub_par_raise(int status, const char *msg);
/* The peak resident memory over the ranks (kb: this rank's, lub_peak_memory_kb), the least
 * and the mean (collective). */
long lub_par_peak_memory(long kb, long *least, long *mean);
/* The ranks' start-up (same work on the same input) is over: from now on a fatal error is
 * the failing rank's own and it prints it ("rank k: ..."), and warnings come from every
 * rank, prefixed. */
void lub_par_startup_done(void);
/* MPI_Finalize (at the normal end; a fatal error aborts instead). */
void lub_par_stop(void);

/* Collectives over all ranks (the value itself without MPI or before lub_par_start). */
double lub_par_sum(double v);
double lub_par_max(double v);
long lub_par_sum_long(long v);
/* Element-wise sums over the ranks, in place: a[k] becomes the sum of every rank's a[k]
 * (function objects: their bins and totals over the owned particles of every rank). */
void lub_par_sum_doubles(double *a, size_t n);
void lub_par_sum_longs(long *a, size_t n);
/* Element-wise minima over the ranks, in place. */
void lub_par_min_doubles(double *a, size_t n);
/* The sum of v over the ranks below this one. */
long lub_par_exscan(long v);
/* Rank 0's text to every rank (size bytes, NUL-terminated). */
void lub_par_bcast_text(char *text, size_t size, int root);
/* The smallest rank with flag != 0, or -1 when no rank has it. */
int lub_par_first(int flag);
void lub_par_barrier(void);

typedef struct {
    int method;        /* LUB_PAR_SLABS, LUB_PAR_SFC */
    int axis;          /* 0, 1, 2 (slabs) */
    double width;      /* halo: particles within width of another rank's slab or cells */
    int periodic;      /* the axis is periodic (period = hi - lo) */
    double lo, period; /* the box along the axis */
    int rank, size;
    double *cut;   /* [size + 1]: slab r = [cut[r], cut[r+1]) */
    size_t nown;   /* owned particles: P's first nown */
    size_t nhalo;  /* halo particles after them (during a step) */
    size_t ntotal; /* all ranks' particles (at the decomposition; migration keeps it) */
    int *scount, *sdispl, *rcount, *rdispl; /* [size] the halo's counts, in particles */
    uint32_t *sidx;                         /* owned particles sent to the halos, by rank */
    size_t sidx_cap;
    unsigned char *sbuf, *rbuf; /* packing buffers */
    size_t sbuf_cap, rbuf_cap;
    int *mcount, *mrcount, *mdispl, *mrdispl; /* migration counts */
    double seconds;                           /* in communication (exchanges, gathers) */
    size_t nmigrated;                         /* particles this rank sent away so far */
    double halo_sum, owned_sum; /* the halo's and the owned counts summed over the halos built */
    long interval;              /* re-balance every interval steps (0: never; set by the caller) */
    double imbalance;           /* when the fullest rank holds > (1 + imbalance) x the mean */
    unsigned char *keys;        /* the selection's sorted coordinates (this rank's) */
    size_t keys_cap;
    uint64_t *sel;  /* [3 (size + 1)] the selection's intervals and counts */
    long nbalanced; /* re-cuts so far */
    /* When a migration or a halo would exceed P's capacity: grow(grow_ctx, n, what) makes
     * room for n particles (lubFoam: lub_mps_resize, the particles and the solver's arrays
     * re-sized between steps); NULL: a run failure (exit 2). */
    void (*grow)(void *ctx, size_t n, const char *what);
    void *grow_ctx;
    double margin; /* the room a re-size leaves beyond n (decomposeParDict margin) */
    /* The cuts' weights per kind (LUB_FLUID, LUB_WALL, LUB_DUMMY), in integer units (exact
     * sums over the ranks); all equal: the cuts count particles.  lub_par_set_weights. */
    uint64_t wkind[3];
    int weighted;
    unsigned char *cw; /* the selection's (key, weight) pairs, then the running sums of the
                        * weights in key order (this rank's) */
    size_t cw_cap;
    unsigned char *wts; /* the particles' weights for the selection */
    size_t wts_cap;
    long nresized; /* re-sizes so far */
    /* sfc: the cells of the curve and the ranges of keys */
    int dim;
    int ncell[3];            /* cells along each axis */
    int cper[3];             /* the axis is periodic */
    double clo[3], csize[3]; /* the box's lower corner, the cells' size (at least the cell asked) */
    double cperiod[3];       /* the period along a periodic axis */
    int bits;                /* of the curve along each axis: 2^bits >= ncell */
    int ncurve, curve[3];    /* the curve's axes (a film's few cells across left out) */
    uint64_t *kcut;          /* [size + 1]: rank r owns the keys [kcut[r], kcut[r+1]) */
    int reach[3];            /* the halo's cells each way: ceil(width / csize) */
    int nnb;                 /* neighbour cells per cell, prod (2 reach + 1) */
    int *nb_owner;           /* the cache: [ncache][nnb] owners of a cell's neighbours (-1: none) */
    uint64_t *nb_tag;        /* [ncache] the cell (its linear index + 1) an entry holds, 0: none */
    size_t ncache;
    uint64_t *pairs; /* the halo's (rank, particle) pairs before their order by rank */
    size_t pairs_cap;
    size_t *mark; /* [size] the last particle (+ 1) sent to each rank's halo */
} lub_par;

/* Slabs of the axis (0, 1, 2) of the box [lo, hi] (periodic: the axis is periodic), halo
 * width (the neighbour search's radius re (1 + skin) and a margin). */
void lub_par_init(lub_par *d, int axis, double width, double lo, double hi, int periodic);
/* Ranges of a Hilbert curve over the cells of the dim-D box [lo, hi] (periodic[k]: axis k
 * periodic), each cell at least `cell` wide (the halo's width, known or foreseen: the halo
 * reaches as many cells as it needs when d->width is set otherwise). */
void lub_par_init_sfc(lub_par *d, int dim, double cell, const double lo[3], const double hi[3],
                      const int periodic[3]);
void lub_par_free(lub_par *d);
/* The cuts' weights of the fluid, wall and dummy particles (decomposeParDict weights; > 0):
 * every rank's slab or range then holds about the same sum of weights, and the re-balancing
 * compares the ranks' sums.  Equal weights (the default): particle counts. */
void lub_par_set_weights(lub_par *d, const double w[3]);
/* The index along the Hilbert curve of the cell c (dim 2 or 3, each coordinate below
 * 2^bits, dim x bits <= 63): the curve visits every cell of the 2^bits cube once, each step
 * to a cell sharing a face (J. Skilling, Programming the Hilbert curve, AIP Conf. Proc. 707,
 * 2004: the transposed index, its bits then interleaved). */
uint64_t lub_par_hilbert(const uint32_t c[3], int dim, int bits);
/* The rank owning particle i of P (its slab, or its cell's range of keys). */
int lub_par_owner_of(const lub_par *d, const lub_particles *P, size_t i);
/* The longest axis of the fluid particles' bounding box over all ranks' particles P.
 * Collective. */
int lub_par_longest_axis(const lub_particles *P);
/* The cuts at the quantiles of the coordinates x (this rank's n) over all ranks: cut[0] =
 * -inf, cut[parts] = +inf and cut[r] the floor(r N / parts)-th smallest of the N coordinates
 * (from 0; 0 when N = 0), exactly what sorting all of them gives, by a parallel selection
 * (at most 64 rounds of one MPI_Allreduce of parts - 1 counts; memory: n and O(parts)).
 * w (NULL: all 1): the coordinates' integer weights, and cut[r] the smallest coordinate
 * whose coordinates up to it weigh more than floor(r W / parts), W their total (the cuts of
 * decomposeParDict weights).  Collective. */
void lub_par_quantiles(const double *x, const uint64_t *w, size_t n, int parts, double *cut);
/* The start on the slabs: S holds this rank's slice of the start's file (any rows; the
 * slices of all ranks together every particle once), place[i] the solver's place of S's
 * particle i (/solver/order).  The cuts at the quantiles of the axis coordinate over all
 * ranks, every particle sent to its slab's owner, and P (no storage on entry; its capacity
 * the slab's particles) holds this rank's particles in the order of their places, as
 * lub_particles_read and a cut of the whole would give them.  Places out of range or twice
 * are a fatal input error naming path.  Returns the number of particles of the most loaded
 * rank.  Collective. */
size_t lub_par_distribute(lub_par *d, const lub_particles *S, const uint64_t *place,
                          lub_particles *P, const char *path);
/* The number of halo particles this rank would receive now (P->n = nown; d->width set): for
 * the capacity of the slab before the solver is built.  Collective. */
size_t lub_par_halo_count(lub_par *d, const lub_particles *P);
/* Q (no storage on entry) gets a copy of the other ranks' owned particles with want[i] set
 * that lie within width of this rank's slab (sfc: of the bounding box of its owned
 * particles; the period taken into account): a start-up check of pairs across the ranks
 * (movingWalls: the walls meeting).  Collective. */
void lub_par_collect(lub_par *d, const lub_particles *P, double width, const uint8_t *want,
                     lub_particles *Q);
/* Re-balancing (P->n = nown): when the fullest rank holds more than (1 + imbalance) times
 * the mean count, new cuts at the quantiles of all ranks' coordinates (lub_par_quantiles);
 * lub_par_migrate then moves the particles.  Returns 1 when it re-cut.  Collective. */
int lub_par_rebalance(lub_par *d, const lub_particles *P, double imbalance);
/* The rank owning a coordinate on the axis. */
int lub_par_owner(const lub_par *d, double x);
/* P->n = nown on entry: owned particles whose coordinate left the slab go to their owner
 * (every field, the extras included, appended there); nown updated.  Beyond P->cap: d->grow,
 * else fatal (exit 2). */
void lub_par_migrate(lub_par *d, lub_particles *P);
/* P->n = nown on entry: the halo (every field of the other ranks' particles within width of
 * this slab) appended; P->n = nown + nhalo.  Beyond P->cap: d->grow, else fatal (exit 2). */
void lub_par_halo(lub_par *d, lub_particles *P);
/* The halo's copy of one per-particle array a (elements of elsize bytes: 1, 2, 4 or 8), from
 * the owners' values: a[nown + k] = the owner's a[i]. */
void lub_par_refresh(lub_par *d, void *a, size_t elsize);
/* All ranks' owned particles into G on rank 0 (G's capacity is grown; its extra fields are
 * P's, by name), with P's time, step, levels and patches; other ranks: G untouched.
 * Collective. */
void lub_par_gather(lub_par *d, const lub_particles *P, lub_particles *G);

/* The rows of the output (lubFoam -parallel's collective write, doc/parallel.md): row r of
 * a particle file holds the particle of id r when the ids are 0 .. N-1 (particleGen's, and
 * kept by a parallel run: no model adds or removes particles); rank q writes rows
 * lub_par_row_first(d, q) .. lub_par_row_first(d, q + 1) - 1, about N / size of them. */
size_t lub_par_row_first(const lub_par *d, int q);
/* 1 when all ranks' ids are 0 .. ntotal - 1 (their largest is ntotal - 1; ids are unique).
 * Collective. */
int lub_par_ids_dense(const lub_par *d, const lub_particles *P);
/* Every rank's owned particles (P->n = nown) to the rank holding their rows: R gets this
 * rank's rows in row order (R's capacity: its row count; its extra fields are P's, by name;
 * P's time, step, levels and patches), place[r] the place of row r's particle in the order
 * of lub_par_gather (rank after rank, each in its own order).  Returns the first row.
 * Collective; the ids must be dense (lub_par_ids_dense). */
size_t lub_par_rows(lub_par *d, const lub_particles *P, lub_particles *R, uint64_t *place);

#endif
