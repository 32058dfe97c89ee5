/* lubkit parallel: slabs or ranges of a Hilbert curve, halo and migration on MPI (see par.h).
 * Compiled with MPI's flags when the build has MPI (Makefile: MPI=1 defines LUB_HAVE_MPI for this
 * file). */
#include "parallel/par.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/error.h"
#include "core/timer.h"
#include "io/dict.h"
#include "particles/particles_io.h"

static const char *const methods[] = {"slabs", "sfc", NULL};
static const char *const axes[] = {"auto", "x", "y", "z", NULL};
static const char *const writes[] = {"auto", "collective", "gather", NULL};

void lub_par_read_dict(lub_par_dict *pd, const char *path, int dim, int nranks)
{
    lub_dict *dd = lub_dict_read_optional(path);
    if (!dd)
        lub_fatal("-parallel: no '%s': it gives numberOfSubdomains and the method "
                  "(etc/templates/decomposeParDict.yaml)",
                  path);
    lub_node *root = lub_dict_root(dd);
    lub_node *nsub = lub_dict_get(root, "numberOfSubdomains");
    const long ns = lub_node_int(nsub, 1, 1L << 20);
    if (nranks > 0 && ns != nranks)
        lub_node_error(nsub,
                       "numberOfSubdomains %ld, but %s %d process%s (mpirun -np %d): run "
                       "mpirun -np %ld lubFoam -parallel, or set numberOfSubdomains: %d",
                       ns, lub_par_under_mpirun() ? "mpirun started" : "not under mpirun:", nranks,
                       nranks == 1 ? "" : "es", nranks, ns, nranks);
    pd->method = lub_dict_choice(root, "method", methods, LUB_PAR_SLABS);
    lub_node *sl = lub_dict_map_or(root, "slabs");
    const int ax = lub_dict_choice(sl, "axis", axes, 0);
    if (ax > dim) lub_node_error(lub_dict_find(sl, "axis"), "slabs axis z in a %d-D case", dim);
    lub_node *bl = lub_dict_map_or(root, "balance");
    pd->axis = ax - 1;
    pd->interval = lub_dict_int_or(bl, "interval", 0, 0, 1L << 40);
    pd->imbalance = lub_dict_real_or(bl, "imbalance", 0.1, LUB_NONNEGATIVE);
    pd->write = lub_dict_choice(root, "writeParticles", writes, 0);
    pd->margin = lub_dict_real_or(root, "margin", 0.2, LUB_NONNEGATIVE);
    lub_node *wt = lub_dict_map_or(root, "weights");
    static const char *const kinds[3] = {"fluid", "wall", "dummy"};
    for (int k = 0; k < 3; k++) {
        pd->weight[k] = lub_dict_real_or(wt, kinds[k], 1.0, LUB_POSITIVE);
        if (pd->weight[k] < 1e-3 || pd->weight[k] > 1e3)
            lub_node_error(lub_dict_find(wt, kinds[k]),
                           "weights %s %g: expected a weight from 0.001 to 1000 (the kinds' "
                           "shares of the work relative to each other)",
                           kinds[k], pd->weight[k]);
    }
    if (pd->write == LUB_PAR_WRITE_COLLECTIVE && !lub_particles_collective())
        lub_node_error(lub_dict_find(root, "writeParticles"),
                       "writeParticles collective, but this lubkit was built with the serial "
                       "HDF5 (the build says which: make HDF5=mpi with libhdf5-openmpi-dev "
                       "installed, bin/installDeps): use auto or gather");
    lub_dict_finish(dd);
    lub_dict_free(dd);
}

int lub_par_under_mpirun(void)
{
    return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMI_SIZE") || getenv("PMIX_RANK");
}

/* Skilling's algorithm (par.h): the cell's coordinates turned, bit level by bit level from
 * the top, into the "transposed" Hilbert index (the inverse of his TransposetoAxes: undo the
 * reflections and exchanges of the sub-cubes, then the Gray code), whose bits interleaved
 * from the top (x[0]'s, x[1]'s, ... at each level) are the index along the curve. */
uint64_t lub_par_hilbert(const uint32_t c[3], int dim, int bits)
{
    if (bits <= 0) return 0;
    if (dim < 2) return c[0];
    uint32_t x[3] = {c[0], c[1], dim > 2 ? c[2] : 0};
    const uint32_t top = 1u << (bits - 1);
    for (uint32_t q = top; q > 1; q >>= 1) {
        const uint32_t low = q - 1;
        for (int i = 0; i < dim; i++) {
            if (x[i] & q) {
                x[0] ^= low; /* a reflection of the lower bits */
            } else {
                const uint32_t t = (x[0] ^ x[i]) & low; /* an exchange of axes 0 and i */
                x[0] ^= t;
                x[i] ^= t;
            }
        }
    }
    for (int i = 1; i < dim; i++) x[i] ^= x[i - 1];
    uint32_t t = 0;
    for (uint32_t q = top; q > 1; q >>= 1)
        if (x[dim - 1] & q) t ^= q - 1;
    for (int i = 0; i < dim; i++) x[i] ^= t;
    uint64_t key = 0;
    for (int b = bits - 1; b >= 0; b--)
        for (int i = 0; i < dim; i++) key = key << 1 | ((x[i] >> b) & 1u);
    return key;
}

#ifndef LUB_HAVE_MPI

int lub_par_available(void)
{
    return 0;
}
void lub_par_start(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    lub_fatal("-parallel: this lubkit was built without MPI (make MPI=0, or no Open MPI and "
              "PETSc found: bin/installDeps, then make)");
}
int lub_par_started(void)
{
    return 0;
}
int lub_par_rank(void)
{
    return 0;
}
int lub_par_size(void)
{
    return 1;
}
void lub_par_startup_done(void) {}
void lub_par_stop(void) {}
double lub_par_sum(double v)
{
    return v;
}
double lub_par_max(double v)
{
    return v;
}
long lub_par_sum_long(long v)
{
    return v;
}
long lub_par_exscan(long v)
{
    (void)v;
    return 0;
}
void lub_par_sum_doubles(double *a, size_t n)
{
    (void)a, (void)n;
}
void lub_par_sum_longs(long *a, size_t n)
{
    (void)a, (void)n;
}
void lub_par_min_doubles(double *a, size_t n)
{
    (void)a, (void)n;
}
void lub_par_bcast_text(char *text, size_t size, int root)
{
    (void)text, (void)size, (void)root;
}
int lub_par_first(int flag)
{
    return flag ? 0 : -1;
}
void lub_par_barrier(void) {}
#define NO_MPI(f) lub_bug(f " in a build without MPI");
void lub_par_init(lub_par *d, int axis, double width, double lo, double hi, int periodic)
{
    (void)d, (void)axis, (void)width, (void)lo, (void)hi, (void)periodic;
    NO_MPI("lub_par_init")
}
void lub_par_init_sfc(lub_par *d, int dim, double cell, const double lo[3], const double hi[3],
                      const int periodic[3])
{
    (void)d, (void)dim, (void)cell, (void)lo, (void)hi, (void)periodic;
    NO_MPI("lub_par_init_sfc")
}
int lub_par_owner_of(const lub_par *d, const lub_particles *P, size_t i)
{
    (void)d, (void)P, (void)i;
    return 0;
}
void lub_par_free(lub_par *d)
{
    (void)d;
}
void lub_par_set_weights(lub_par *d, const double w[3])
{
    (void)d, (void)w;
}
int lub_par_longest_axis(const lub_particles *P)
{
    (void)P;
    NO_MPI("lub_par_longest_axis")
}
void lub_par_quantiles(const double *x, const uint64_t *w, size_t n, int parts, double *cut)
{
    (void)x, (void)w, (void)n, (void)parts, (void)cut;
    NO_MPI("lub_par_quantiles")
}
size_t lub_par_distribute(lub_par *d, const lub_particles *S, const uint64_t *place,
                          lub_particles *P, const char *path)
{
    (void)d, (void)S, (void)place, (void)P, (void)path;
    NO_MPI("lub_par_distribute")
}
size_t lub_par_halo_count(lub_par *d, const lub_particles *P)
{
    (void)d, (void)P;
    NO_MPI("lub_par_halo_count")
}
void lub_par_collect(lub_par *d, const lub_particles *P, double width, const uint8_t *want,
                     lub_particles *Q)
{
    (void)d, (void)P, (void)width, (void)want, (void)Q;
    NO_MPI("lub_par_collect")
}
void lub_par_raise(int status, const char *msg)
{
    if (msg) {
        if (status == LUB_EXIT_RUN) lub_fatal_run("%s", msg);
        lub_fatal("%s", msg);
    }
}
long lub_par_peak_memory(long kb, long *least, long *mean)
{
    *least = *mean = kb;
    return kb;
}
int lub_par_owner(const lub_par *d, double x)
{
    (void)d, (void)x;
    return 0;
}
int lub_par_rebalance(lub_par *d, const lub_particles *P, double imbalance)
{
    (void)d, (void)P, (void)imbalance;
    NO_MPI("lub_par_rebalance")
}
void lub_par_migrate(lub_par *d, lub_particles *P)
{
    (void)d, (void)P;
    NO_MPI("lub_par_migrate")
}
void lub_par_halo(lub_par *d, lub_particles *P)
{
    (void)d, (void)P;
    NO_MPI("lub_par_halo")
}
void lub_par_refresh(lub_par *d, void *a, size_t elsize)
{
    (void)d, (void)a, (void)elsize;
    NO_MPI("lub_par_refresh")
}
void lub_par_gather(lub_par *d, const lub_particles *P, lub_particles *G)
{
    (void)d, (void)P, (void)G;
    NO_MPI("lub_par_gather")
}
size_t lub_par_row_first(const lub_par *d, int q)
{
    (void)d, (void)q;
    return 0;
}
int lub_par_ids_dense(const lub_par *d, const lub_particles *P)
{
    (void)d, (void)P;
    NO_MPI("lub_par_ids_dense")
}
size_t lub_par_rows(lub_par *d, const lub_particles *P, lub_particles *R, uint64_t *place)
{
    (void)d, (void)P, (void)R, (void)place;
    NO_MPI("lub_par_rows")
}

#else

#include <mpi.h>

static int started = 0, startup = 1, rank_ = 0, size_ = 1;
static char rank_prefix[32];

int lub_par_available(void)
{
    return 1;
}

/* The fatal-error hook (core/error.h): every rank's fatal error ends the job. */
static void fatal_hook(int status, const char *msg)
{
    fflush(stdout);
    if (startup && rank_ != 0) {
        /* rank 0 does the same work on the same input and meets the same error: its
         * MPI_Abort ends this process; only if it does not come is this rank's own */
        const struct timespec ts = {0, 100000000};
        for (int k = 0; k < 100; k++) nanosleep(&ts, NULL);
    }
    if ((startup && rank_ == 0) || size_ == 1)
        fprintf(stderr, "%s: error: %s\n", lub_program(), msg);
    else
        fprintf(stderr, "%s: error: rank %d: %s\n", lub_program(), rank_, msg);
    fflush(stderr);
    if (size_ == 1) exit(status); /* no other rank to end (MPI is finalised at exit) */
    MPI_Abort(MPI_COMM_WORLD, status);
    exit(status);
}

static void stop_at_exit(void)
{
    int fin = 0;
    MPI_Finalized(&fin);
    if (!fin) MPI_Finalize();
}

void lub_par_start(int *argc, char ***argv)
{
    if (started) return;
    if (MPI_Init(argc, argv) != MPI_SUCCESS) lub_fatal("-parallel: MPI_Init failed");
    started = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    lub_set_fatal_hook(fatal_hook);
    if (rank_ != 0) {
        lub_set_quiet(1);
        lub_set_warning_prefix(NULL);
    }
    /* PETSc, started later on MPI_COMM_WORLD, finalises at exit too (registered after this,
     * so it runs first) */
    atexit(stop_at_exit);
}

int lub_par_started(void)
{
    return started;
}
int lub_par_rank(void)
{
    return rank_;
}
int lub_par_size(void)
{
    return size_;
}

void lub_par_startup_done(void)
{
    if (!started) return;
    startup = 0;
    snprintf(rank_prefix, sizeof rank_prefix, "rank %d: ", rank_);
    if (size_ > 1) lub_set_warning_prefix(rank_prefix);
}

void lub_par_stop(void)
{
    if (started) stop_at_exit();
}

double lub_par_sum(double v)
{
    double r = v;
    if (started) MPI_Allreduce(&v, &r, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    return r;
}
double lub_par_max(double v)
{
    double r = v;
    if (started) MPI_Allreduce(&v, &r, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return r;
}
long lub_par_sum_long(long v)
{
    long r = v;
    if (started) MPI_Allreduce(&v, &r, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
    return r;
}
void lub_par_sum_doubles(double *a, size_t n)
{
    if (started && n > 0)
        MPI_Allreduce(MPI_IN_PLACE, a, (int)n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
}
void lub_par_sum_longs(long *a, size_t n)
{
    if (started && n > 0) MPI_Allreduce(MPI_IN_PLACE, a, (int)n, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
}
void lub_par_min_doubles(double *a, size_t n)
{
    if (started && n > 0)
        MPI_Allreduce(MPI_IN_PLACE, a, (int)n, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
}
long lub_par_exscan(long v)
{
    long r = 0;
    if (started) MPI_Exscan(&v, &r, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
    return rank_ == 0 ? 0 : r;
}
void lub_par_bcast_text(char *text, size_t size, int root)
{
    if (started) MPI_Bcast(text, (int)size, MPI_CHAR, root, MPI_COMM_WORLD);
    text[size - 1] = '\0';
}
int lub_par_first(int flag)
{
    int r = flag ? rank_ : size_, m = r;
    if (started) MPI_Allreduce(&r, &m, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return m < size_ ? m : -1;
}
void lub_par_barrier(void)
{
    if (started) MPI_Barrier(MPI_COMM_WORLD);
}

/* ---- the decomposition ------------------------------------------------------------------ */

void lub_par_init(lub_par *d, int axis, double width, double lo, double hi, int periodic)
{
    memset(d, 0, sizeof *d);
    d->axis = axis;
    d->width = width;
    d->lo = lo;
    d->periodic = periodic;
    d->period = periodic ? hi - lo : 0.0;
    d->rank = rank_;
    d->size = size_;
    d->wkind[0] = d->wkind[1] = d->wkind[2] = 1;
    d->cut = lub_calloc((size_t)size_ + 1, sizeof *d->cut);
    d->sel = lub_calloc(3 * ((size_t)size_ + 1), sizeof *d->sel);
    int **a[] = {&d->scount, &d->sdispl,  &d->rcount, &d->rdispl,
                 &d->mcount, &d->mrcount, &d->mdispl, &d->mrdispl};
    for (size_t k = 0; k < sizeof a / sizeof *a; k++)
        *a[k] = lub_calloc((size_t)size_, sizeof(int));
}

void lub_par_init_sfc(lub_par *d, int dim, double cell, const double lo[3], const double hi[3],
                      const int periodic[3])
{
    lub_par_init(d, 0, 0.0, lo[0], hi[0], 0);
    d->method = LUB_PAR_SFC;
    d->dim = dim;
    d->kcut = lub_calloc((size_t)size_ + 1, sizeof *d->kcut);
    d->mark = lub_calloc((size_t)size_, sizeof *d->mark);
    /* the cells: a whole number of them along each axis (a period holds whole cells), each
     * at least `cell` wide, at most 2^bits along an axis for the key's 63 bits */
    const int maxbits = dim == 3 ? 21 : 30;
    int most = 1;
    for (int k = 0; k < 3; k++) {
        const double len = k < dim ? hi[k] - lo[k] : 0.0;
        double n = cell > 0 && len > 0 ? floor(len / cell) : 1.0;
        if (n < 1) n = 1;
        if (n > (double)(1L << maxbits)) n = (double)(1L << maxbits);
        d->ncell[k] = (int)n;
        d->clo[k] = k < dim ? lo[k] : 0.0;
        d->csize[k] = len > 0 ? len / n : (cell > 0 ? cell : 1.0);
        d->cper[k] = k < dim && periodic[k];
        d->cperiod[k] = d->cper[k] ? len : 0.0;
        if (d->ncell[k] > most) most = d->ncell[k];
    }
    while ((1L << d->bits) < most) d->bits++;
    /* the curve's axes: an axis of a few cells against the longest (a film's thickness:
     * fewer than a quarter as many) is left out, its cells across the film one key, so that
     * the ranges are patches of the film's area through its thickness; a curve through the
     * cube of the longest side would wander out of the film and back, and its ranges would
     * be scattered pieces (the 3-D roller at h0/2, 36 x 3 x 16 cells on 4 ranks: a halo of
     * 43% of the owned particles with the 3-D curve, against 22% of slabs: measured) */
    for (int k = 0; k < dim; k++)
        if (4 * d->ncell[k] > most) d->curve[d->ncurve++] = k;
    d->kcut[d->size] = UINT64_MAX;
}

void lub_par_free(lub_par *d)
{
    free(d->cut);
    free(d->scount), free(d->sdispl), free(d->rcount), free(d->rdispl);
    free(d->mcount), free(d->mrcount), free(d->mdispl), free(d->mrdispl);
    free(d->sidx);
    free(d->sbuf);
    free(d->rbuf);
    free(d->keys);
    free(d->cw);
    free(d->wts);
    free(d->sel);
    free(d->kcut), free(d->mark), free(d->pairs);
    free(d->nb_owner), free(d->nb_tag);
    memset(d, 0, sizeof *d);
}

int lub_par_longest_axis(const lub_particles *P)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < P->n; i++) {
        if (P->kind[i] != LUB_FLUID) continue;
        for (int k = 0; k < P->dim; k++) {
            lo[k] = fmin(lo[k], P->x[k][i]);
            hi[k] = fmax(hi[k], P->x[k][i]);
        }
    }
    MPI_Allreduce(MPI_IN_PLACE, lo, 3, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, hi, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    int axis = 0;
    for (int k = 1; k < P->dim; k++)
        if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
    return axis;
}

int lub_par_owner(const lub_par *d, double x)
{
    int a = 0, b = d->size; /* the largest r with cut[r] <= x, cut[0] = -inf */
    while (b - a > 1) {
        const int m = (a + b) / 2;
        if (d->cut[m] <= x)
            a = m;
        else
            b = m;
    }
    return a;
}

/* ---- the curve's cells and keys ---------------------------------------------------------- */

/* The cell of coordinate x along axis k: wrapped along a periodic axis, else the end cells
 * take what lies beyond the box (their boxes reach to infinity: sfc_axis_distance). */
static int cell_index(const lub_par *d, int k, double x)
{
    const int n = d->ncell[k];
    const double s = floor((x - d->clo[k]) / d->csize[k]);
    if (isnan(s)) return 0;
    if (d->cper[k]) {
        double m = fmod(s, (double)n);
        if (m < 0) m += n;
        return m >= n ? n - 1 : (int)m;
    }
    return s < 0 ? 0 : s >= n ? n - 1 : (int)s;
}

static uint64_t cell_key(const lub_par *d, const int c[3])
{
    uint32_t u[3] = {0, 0, 0};
    for (int j = 0; j < d->ncurve; j++) u[j] = (uint32_t)c[d->curve[j]];
    return lub_par_hilbert(u, d->ncurve, d->bits);
}

static uint64_t particle_key(const lub_par *d, const lub_particles *P, size_t i)
{
    int c[3] = {0, 0, 0};
    for (int k = 0; k < d->dim; k++) c[k] = cell_index(d, k, P->x[k][i]);
    return cell_key(d, c);
}

/* The rank whose range of keys holds key k: the largest r with kcut[r] <= k. */
static int key_owner(const lub_par *d, uint64_t k)
{
    int a = 0, b = d->size;
    while (b - a > 1) {
        const int m = (a + b) / 2;
        if (d->kcut[m] <= k)
            a = m;
        else
            b = m;
    }
    return a;
}

int lub_par_owner_of(const lub_par *d, const lub_particles *P, size_t i)
{
    if (d->method == LUB_PAR_SFC) return key_owner(d, particle_key(d, P, i));
    return lub_par_owner(d, P->x[d->axis][i]);
}

/* Move particle i to k (k <= i) in every array of P. */
static void move_particle(lub_particles *P, size_t k, size_t i)
{
    if (k == i) return;
    for (int c = 0; c < 3; c++) {
        P->x[c][k] = P->x[c][i];
        P->u[c][k] = P->u[c][i];
    }
    P->p[k] = P->p[i];
    P->kind[k] = P->kind[i];
    P->patch[k] = P->patch[i];
    P->level[k] = P->level[i];
    P->id[k] = P->id[i];
    for (int e = 0; e < P->nextra; e++) P->extra[e].v[k] = P->extra[e].v[i];
}

/* The weights in units of 1/1000 (a weight 0.001-1000 a particle, exact integer sums: 16 M
 * particles of weight 1000 sum to 1.6e13, far below 2^64). */
void lub_par_set_weights(lub_par *d, const double w[3])
{
    for (int k = 0; k < 3; k++) d->wkind[k] = (uint64_t)llround(1000.0 * w[k]);
    d->weighted = d->wkind[0] != d->wkind[1] || d->wkind[0] != d->wkind[2];
    if (!d->weighted) d->wkind[0] = d->wkind[1] = d->wkind[2] = 1;
}

/* ---- the cuts: quantiles by a parallel selection ----------------------------------------- */

/* A double as an unsigned integer of the same order (IEEE 754: a positive number with its
 * sign bit set, a negative one with every bit flipped), so that the selection below bisects
 * integers: x < y exactly when key(x) < key(y). */
static uint64_t order_key(double x)
{
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b >> 63 ? ~b : b | (1ULL << 63);
}

static double key_value(uint64_t k)
{
    const uint64_t b = k >> 63 ? k & ~(1ULL << 63) : ~k;
    double x;
    memcpy(&x, &b, sizeof x);
    return x;
}

static int cmp_key(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* How many of the n sorted keys are <= v. */
static uint64_t count_upto(const uint64_t *keys, size_t n, uint64_t v)
{
    size_t a = 0, b = n; /* the first key > v */
    while (a < b) {
        const size_t m = a + (b - a) / 2;
        if (keys[m] <= v)
            a = m + 1;
        else
            b = m;
    }
    return a;
}

/* The exact selection over all ranks' keys (this rank's n, sorted), with the caller's
 * buffer sel (3 (parts + 1)): sel[r] (r = 1 .. parts - 1) becomes the floor(r N / parts)-th
 * smallest key of all ranks (from 0; weighted, cw given, the running sums of the sorted keys'
 * weights: the smallest key whose keys up to it weigh more than floor(r W / parts), W the
 * total weight), found by bisecting the keys' 64 bits: at each of at
 * most 64 rounds every rank counts its keys up to the middle of each cut's interval (a
 * binary search in its sorted keys) and one MPI_Allreduce sums the counts of all cuts, so
 * the memory is this rank's keys and O(parts), never all N.  The result is the whole
 * sort's (the all-gather this replaced), equal keys (a lattice's column, a cell of the
 * curve) together on the rank of the first.  Returns N or W (0: sel untouched). */
static uint64_t select_keys(const uint64_t *keys, const uint64_t *cw, size_t n, int parts,
                            uint64_t *sel)
{
    const uint64_t mine = cw ? (n ? cw[n - 1] : 0) : n;
    uint64_t total = 0;
    MPI_Allreduce(&mine, &total, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    if (total == 0) return 0;
    uint64_t range[2] = {n ? keys[0] : UINT64_MAX, n ? ~keys[n - 1] : UINT64_MAX};
    MPI_Allreduce(MPI_IN_PLACE, range, 2, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD);
    uint64_t *lo = sel, *hi = sel + parts + 1, *cnt = sel + 2 * (parts + 1);
    for (int r = 1; r < parts; r++) lo[r] = range[0], hi[r] = ~range[1];
    for (;;) {
        int busy = 0;
        for (int r = 1; r < parts; r++) {
            cnt[r] = 0;
            if (lo[r] < hi[r]) {
                const uint64_t a = count_upto(keys, n, lo[r] + (hi[r] - lo[r]) / 2);
                cnt[r] = cw ? (a ? cw[a - 1] : 0) : a; /* the weight of the keys up to it */
                busy = 1;
            }
        }
        if (!busy) break; /* every rank sees the same intervals: all stop together */
        MPI_Allreduce(MPI_IN_PLACE, cnt + 1, parts - 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
        for (int r = 1; r < parts; r++) {
            if (lo[r] >= hi[r]) continue;
            const uint64_t want = (uint64_t)((double)r * (double)total / parts);
            const uint64_t mid = lo[r] + (hi[r] - lo[r]) / 2;
            if (cnt[r] > (want < total ? want : total - 1))
                hi[r] = mid;
            else
                lo[r] = mid + 1;
        }
    }
    return total;
}

/* Slabs' cuts from this rank's n sorted keys of the coordinates (cw: their weights' running
 * sums, NULL: counts), selected exactly over all ranks (select_keys), sel its buffer. */
static void slab_cuts(const uint64_t *keys, const uint64_t *cw, size_t n, int parts, double *cut,
                      uint64_t *sel)
{
    cut[0] = -INFINITY;
    cut[parts] = INFINITY;
    if (select_keys(keys, cw, n, parts, sel) == 0) {
        for (int r = 1; r < parts; r++) cut[r] = 0.0;
        return;
    }
    for (int r = 1; r < parts; r++) {
        cut[r] = key_value(sel[r]);
        if (cut[r] < cut[r - 1]) cut[r] = cut[r - 1];
    }
}

static void *grow_buf(unsigned char **b, size_t *cap, size_t bytes);
static long displs(const int *count, int *displ, int size);

/* n keys with their weights w (NULL: unweighted), sorted by key in keys; returns the running
 * sums of the weights in key order in the buffer *kwb (NULL when unweighted).  The (key,
 * weight) pairs are sorted in the buffer (by the key, the pair's first word), then the sums
 * written over them from the front: sum i lands on word i, which belongs to pair i/2 <= i,
 * read already. */
static const uint64_t *sort_weighted(uint64_t *keys, const uint64_t *w, size_t n,
                                     unsigned char **kwb, size_t *cap)
{
    if (!w) {
        qsort(keys, n, sizeof *keys, cmp_key);
        return NULL;
    }
    uint64_t *kw = grow_buf(kwb, cap, 2 * (n ? n : 1) * sizeof(uint64_t));
    for (size_t i = 0; i < n; i++) kw[2 * i] = keys[i], kw[2 * i + 1] = w[i];
    qsort(kw, n, 2 * sizeof *kw, cmp_key);
    uint64_t sum = 0;
    for (size_t i = 0; i < n; i++) {
        keys[i] = kw[2 * i];
        sum += kw[2 * i + 1];
        kw[i] = sum;
    }
    return kw;
}

void lub_par_quantiles(const double *x, const uint64_t *w, size_t n, int parts, double *cut)
{
    uint64_t *keys = lub_malloc((n ? n : 1) * sizeof *keys);
    uint64_t *sel = lub_malloc(3 * ((size_t)parts + 1) * sizeof *sel);
    unsigned char *kwb = NULL;
    size_t cap = 0;
    for (size_t i = 0; i < n; i++) keys[i] = order_key(x[i]);
    slab_cuts(keys, sort_weighted(keys, w, n, &kwb, &cap), n, parts, cut, sel);
    free(keys);
    free(sel);
    free(kwb);
}

/* The cuts of d at the quantiles of P's first n particles over all ranks (weighted: of their
 * weights), with d's buffers: slabs, of their coordinate on the axis; sfc, of their cells'
 * keys (the ranges of the curve: each rank about N / P particles, or 1 / P of the weight, a
 * cell never divided).  A new cut empties the cache of the cells' neighbour owners. */
static void cut_at_quantiles(lub_par *d, const lub_particles *P, size_t n)
{
    uint64_t *keys = grow_buf(&d->keys, &d->keys_cap, (n ? n : 1) * sizeof(uint64_t));
    const int slabs = d->method != LUB_PAR_SFC;
    for (size_t i = 0; i < n; i++)
        keys[i] = slabs ? order_key(P->x[d->axis][i]) : particle_key(d, P, i);
    uint64_t *w = NULL; /* weighted: the particles' weights, then their running sums */
    if (d->weighted) {
        w = grow_buf(&d->wts, &d->wts_cap, (n ? n : 1) * sizeof(uint64_t));
        for (size_t i = 0; i < n; i++) w[i] = d->wkind[P->kind[i]];
    }
    const uint64_t *cw = sort_weighted(keys, w, n, &d->cw, &d->cw_cap);
    if (slabs) {
        slab_cuts(keys, cw, n, d->size, d->cut, d->sel);
        return;
    }
    const int size = d->size;
    d->kcut[0] = 0;
    d->kcut[size] = UINT64_MAX;
    const int any = select_keys(keys, cw, n, size, d->sel) > 0;
    for (int r = 1; r < size; r++) {
        d->kcut[r] = any ? d->sel[r] : 0;
        if (d->kcut[r] < d->kcut[r - 1]) d->kcut[r] = d->kcut[r - 1];
    }
    if (d->nb_tag) memset(d->nb_tag, 0, d->ncache * sizeof *d->nb_tag);
}

/* This rank's owned weight (weighted cuts) or count. */
static double owned_load(const lub_par *d, const lub_particles *P)
{
    if (!d->weighted) return (double)d->nown;
    uint64_t w = 0;
    for (size_t i = 0; i < d->nown; i++) w += d->wkind[P->kind[i]];
    return (double)w;
}

int lub_par_rebalance(lub_par *d, const lub_particles *P, double imbalance)
{
    const double t0 = lub_wtime();
    const double load = owned_load(d, P);
    const double most = lub_par_max(load), mean = lub_par_sum(load) / d->size;
    int recut = 0;
    if (most > (1 + imbalance) * mean) {
        const long total = lub_par_sum_long((long)d->nown);
        if ((size_t)total != d->ntotal)
            lub_bug("re-balancing: %ld particles on the ranks, %zu at the start", total, d->ntotal);
        cut_at_quantiles(d, P, d->nown);
        d->nbalanced++;
        recut = 1;
    }
    d->seconds += lub_wtime() - t0;
    return recut;
}

/* ---- packing ---------------------------------------------------------------------------- */

/* A particle as doubles: position, velocity, pressure, kind, patch, level, id (its bits),
 * the extra fields. */
static size_t record_doubles(const lub_particles *P)
{
    return 11 + (size_t)P->nextra;
}

static void pack(const lub_particles *P, size_t i, double *r)
{
    for (int c = 0; c < 3; c++) r[c] = P->x[c][i], r[3 + c] = P->u[c][i];
    r[6] = P->p[i];
    r[7] = P->kind[i];
    r[8] = P->patch[i];
    r[9] = P->level[i];
    memcpy(&r[10], &P->id[i], sizeof(double));
    for (int e = 0; e < P->nextra; e++) r[11 + e] = P->extra[e].v[i];
}

static void unpack(lub_particles *P, size_t i, const double *r)
{
    for (int c = 0; c < 3; c++) P->x[c][i] = r[c], P->u[c][i] = r[3 + c];
    P->p[i] = r[6];
    P->kind[i] = (uint8_t)r[7];
    P->patch[i] = (uint16_t)r[8];
    P->level[i] = (uint8_t)r[9];
    memcpy(&P->id[i], &r[10], sizeof(double));
    for (int e = 0; e < P->nextra; e++) P->extra[e].v[i] = r[11 + e];
}

static void *grow_buf(unsigned char **b, size_t *cap, size_t bytes)
{
    if (bytes > *cap) {
        free(*b);
        *cap = bytes + bytes / 2 + 64;
        *b = lub_malloc(*cap);
    }
    return *b;
}

/* displacements from counts; returns the total */
static long displs(const int *count, int *displ, int size)
{
    long t = 0;
    for (int r = 0; r < size; r++) {
        displ[r] = (int)t;
        t += count[r];
    }
    return t;
}

/* Room for n particles in P: beyond its capacity the owner's grow (lubFoam: the particles
 * and the solver's arrays re-sized, once, between steps), else a run failure. */
static void need_capacity(lub_par *d, lub_particles *P, size_t n, const char *what)
{
    if (n <= P->cap) return;
    if (d->grow) {
        d->grow(d->grow_ctx, n, what);
        d->nresized++;
    }
    if (n > P->cap)
        lub_fatal_run("%s: %zu particles on this rank exceed its capacity %zu", what, n, P->cap);
}

/* An MPI datatype of `size` bytes, contiguous (counts in particles, records of any size). */
static MPI_Datatype record_type(size_t bytes)
{
    MPI_Datatype t;
    MPI_Type_contiguous((int)bytes, MPI_BYTE, &t);
    MPI_Type_commit(&t);
    return t;
}

/* Send each rank the particle records packed for it in sb (scount, sdispl: per rank, in
 * records), receive theirs (rcount, rdispl set here) and unpack them into P from index at
 * on; returns the number received.  what names the exchange in a capacity error. */
static long exchange(lub_par *d, lub_particles *P, const double *sb, const int *scount,
                     const int *sdispl, int *rcount, int *rdispl, size_t at, const char *what)
{
    const size_t nr = record_doubles(P);
    MPI_Alltoall(scount, 1, MPI_INT, rcount, 1, MPI_INT, MPI_COMM_WORLD);
    const long nin = displs(rcount, rdispl, d->size);
    need_capacity(d, P, at + (size_t)nin, what);
    double *rb = grow_buf(&d->rbuf, &d->rbuf_cap, (nin ? (size_t)nin : 1) * nr * sizeof(double));
    MPI_Datatype t = record_type(nr * sizeof(double));
    MPI_Alltoallv(sb, scount, sdispl, t, rb, rcount, rdispl, t, MPI_COMM_WORLD);
    MPI_Type_free(&t);
    for (long q = 0; q < nin; q++) unpack(P, at + (size_t)q, rb + (size_t)q * nr);
    return nin;
}

void lub_par_migrate(lub_par *d, lub_particles *P)
{
    const double t0 = lub_wtime();
    const int size = d->size;
    const size_t nr = record_doubles(P), n = d->nown;
    P->n = n;
    memset(d->mcount, 0, (size_t)size * sizeof *d->mcount);
    size_t nout = 0;
    for (size_t i = 0; i < n; i++) {
        const int o = lub_par_owner_of(d, P, i);
        if (o != d->rank) d->mcount[o]++, nout++;
    }
    displs(d->mcount, d->mdispl, size);
    double *sb = grow_buf(&d->sbuf, &d->sbuf_cap, (nout ? nout : 1) * nr * sizeof(double));
    /* pack the leavers by owner, keep the others in order */
    int *fill = d->scount; /* free until the halo */
    memset(fill, 0, (size_t)size * sizeof *fill);
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        const int o = lub_par_owner_of(d, P, i);
        if (o != d->rank) {
            pack(P, i, sb + (size_t)(d->mdispl[o] + fill[o]++) * nr);
        } else {
            move_particle(P, k++, i);
        }
    }
    const long nin =
        exchange(d, P, sb, d->mcount, d->mdispl, d->mrcount, d->mrdispl, k, "migration");
    d->nown = k + (size_t)nin;
    d->nmigrated += nout;
    P->n = d->nown;
    d->seconds += lub_wtime() - t0;
}

/* Distance along the axis from x to slab r (0 inside), the period taken into account.  A
 * periodic axis: the end slabs end at the box, [lo, cut[1]) and [cut[size-1], lo + period)
 * (cut[0] and cut[size] are infinite for the owner's search; taken as the slab's ends, a
 * slab reached every particle of the other end slab across the period, and the halo held
 * the whole case). */
static double slab_distance(const lub_par *d, int r, double x)
{
    double a = d->cut[r], b = d->cut[r + 1];
    if (d->periodic) {
        if (r == 0) a = d->lo;
        if (r == d->size - 1) b = d->lo + d->period;
    }
    double best = INFINITY;
    const int shifts = d->periodic ? 1 : 0;
    for (int s = -shifts; s <= shifts; s++) {
        const double y = x + s * d->period;
        const double dist = y < a ? a - y : (y >= b ? y - b : 0.0);
        if (dist < best) best = dist;
    }
    return best;
}

/* ---- the halo of the curve's ranges ------------------------------------------------------ */

enum { SFC_CACHE = 2048 }; /* cells whose neighbours' owners are kept (a power of 2) */

/* The cells the halo reaches each way along each axis, ceil(width / cell) (at most all of
 * a periodic axis' cells, or the box's), and the cache of the cells' neighbour owners sized
 * for it: allocated when the width changes (at the start), not in the steps. */
static void sfc_reach(lub_par *d)
{
    int reach[3] = {0, 0, 0}, nnb = 1;
    for (int k = 0; k < d->dim; k++) {
        const double r = d->width > 0 ? ceil(d->width / d->csize[k]) : 0.0;
        const int most = d->cper[k] ? d->ncell[k] / 2 : d->ncell[k] - 1;
        reach[k] = r < most ? (int)r : most;
        nnb *= 2 * reach[k] + 1;
    }
    if (d->nb_owner && nnb == d->nnb && memcmp(reach, d->reach, sizeof reach) == 0) return;
    memcpy(d->reach, reach, sizeof reach);
    d->nnb = nnb;
    free(d->nb_owner), free(d->nb_tag);
    d->ncache = SFC_CACHE;
    d->nb_owner = lub_malloc(d->ncache * (size_t)nnb * sizeof *d->nb_owner);
    d->nb_tag = lub_calloc(d->ncache, sizeof *d->nb_tag);
}

/* Neighbour q of a cell: its offsets along the axes (q counts x fastest). */
static void sfc_offset(const lub_par *d, int q, int o[3])
{
    for (int k = 0; k < 3; k++) {
        const int w = 2 * d->reach[k] + 1;
        o[k] = q % w - d->reach[k];
        q /= w;
    }
}

/* The owners of cell c's neighbours (nnb of them, -1 beyond a box's side), from the cache
 * or computed into it. */
static const int *sfc_neighbours(lub_par *d, const int c[3])
{
    const uint64_t tag =
        1 + (uint64_t)c[0] +
        (uint64_t)d->ncell[0] * ((uint64_t)c[1] + (uint64_t)d->ncell[1] * (uint64_t)c[2]);
    const size_t e = (size_t)((tag * 0x9E3779B97F4A7C15ULL) >> 53) & (d->ncache - 1);
    int *own = d->nb_owner + e * (size_t)d->nnb;
    if (d->nb_tag[e] == tag) return own;
    d->nb_tag[e] = tag;
    for (int q = 0; q < d->nnb; q++) {
        int o[3], cc[3] = {0, 0, 0}, inside = 1;
        sfc_offset(d, q, o);
        for (int k = 0; k < d->dim; k++) {
            int v = c[k] + o[k];
            const int n = d->ncell[k];
            if (d->cper[k])
                v = ((v % n) + n) % n;
            else if (v < 0 || v >= n)
                inside = 0;
            cc[k] = v;
        }
        own[q] = inside ? key_owner(d, cell_key(d, cc)) : -1;
    }
    return own;
}

/* The distance along axis k from x to the cell of index v (not wrapped: a neighbour's, next
 * to x's cell), the box's end cells reaching to infinity, the period taken into account. */
static double sfc_axis_distance(const lub_par *d, int k, int v, double x)
{
    double a = d->clo[k] + v * d->csize[k], b = a + d->csize[k];
    if (!d->cper[k]) {
        if (v <= 0) a = -INFINITY;
        if (v >= d->ncell[k] - 1) b = INFINITY;
    }
    double best = INFINITY;
    const int shifts = d->cper[k] ? 1 : 0;
    for (int s = -shifts; s <= shifts; s++) {
        const double y = x + s * d->cperiod[k];
        const double dist = y < a ? a - y : (y >= b ? y - b : 0.0);
        if (dist < best) best = dist;
    }
    return best;
}

/* The halo's lists of the curve's ranges: each owned particle goes to every other rank
 * owning a cell within width of it (its distance to the cell's box: a rank's halo holds
 * every particle within width of its cells, so of its particles, which lie in them).
 * Fills d->scount, sdispl and sidx (by rank, each in the particles' order); returns the
 * number sent (a particle sent to several ranks counted for each). */
static long sfc_halo_lists(lub_par *d, const lub_particles *P)
{
    const int size = d->size, dim = d->dim;
    const double w2 = d->width * d->width;
    sfc_reach(d);
    memset(d->scount, 0, (size_t)size * sizeof *d->scount);
    memset(d->mark, 0, (size_t)size * sizeof *d->mark);
    size_t np = 0;
    for (size_t i = 0; i < d->nown; i++) {
        int c[3] = {0, 0, 0};
        for (int k = 0; k < dim; k++) c[k] = cell_index(d, k, P->x[k][i]);
        const int *own = sfc_neighbours(d, c);
        for (int q = 0; q < d->nnb; q++) {
            const int r = own[q];
            if (r < 0 || r == d->rank || d->mark[r] == i + 1) continue;
            int o[3];
            sfc_offset(d, q, o);
            double d2 = 0;
            for (int k = 0; k < dim && d2 < w2; k++) {
                const double e = sfc_axis_distance(d, k, c[k] + o[k], P->x[k][i]);
                d2 += e * e;
            }
            if (d2 >= w2) continue;
            d->mark[r] = i + 1;
            if (np == d->pairs_cap) {
                d->pairs_cap = 2 * d->pairs_cap + 1024;
                uint64_t *p = lub_malloc(d->pairs_cap * sizeof *p);
                if (np) memcpy(p, d->pairs, np * sizeof *p);
                free(d->pairs);
                d->pairs = p;
            }
            d->pairs[np++] = (uint64_t)r << 32 | (uint64_t)i;
            d->scount[r]++;
        }
    }
    const long nsend = displs(d->scount, d->sdispl, size);
    if ((size_t)nsend > d->sidx_cap) {
        free(d->sidx);
        d->sidx_cap = (size_t)nsend + (size_t)nsend / 2 + 16;
        d->sidx = lub_malloc(d->sidx_cap * sizeof *d->sidx);
    }
    int *fill = d->mcount; /* free after the migration */
    memset(fill, 0, (size_t)size * sizeof *fill);
    for (size_t k = 0; k < np; k++) {
        const int r = (int)(d->pairs[k] >> 32);
        d->sidx[d->sdispl[r] + fill[r]++] = (uint32_t)(d->pairs[k] & 0xffffffffu);
    }
    return nsend;
}

/* Which owned particles (P's first nown) each other rank's halo needs: d->scount, sdispl
 * (sfc: and the lists, d->sidx); returns their number (a particle sent to several ranks
 * counted for each). */
static long halo_counts(lub_par *d, const lub_particles *P)
{
    if (d->method == LUB_PAR_SFC) return sfc_halo_lists(d, P);
    const int a = d->axis, size = d->size;
    memset(d->scount, 0, (size_t)size * sizeof *d->scount);
    for (size_t i = 0; i < d->nown; i++)
        for (int r = 0; r < size; r++)
            if (r != d->rank && slab_distance(d, r, P->x[a][i]) < d->width) d->scount[r]++;
    return displs(d->scount, d->sdispl, size);
}

size_t lub_par_halo_count(lub_par *d, const lub_particles *P)
{
    halo_counts(d, P);
    MPI_Alltoall(d->scount, 1, MPI_INT, d->rcount, 1, MPI_INT, MPI_COMM_WORLD);
    return (size_t)displs(d->rcount, d->rdispl, d->size);
}

void lub_par_halo(lub_par *d, lub_particles *P)
{
    const double t0 = lub_wtime();
    const int a = d->axis, size = d->size;
    const size_t n = d->nown, nr = record_doubles(P);
    P->n = n;
    /* which owned particles each other rank needs: two passes (count, then list by rank;
     * the curve's ranges list them in the first) */
    const long nsend = halo_counts(d, P);
    if (d->method != LUB_PAR_SFC && (size_t)nsend > d->sidx_cap) {
        free(d->sidx);
        d->sidx_cap = (size_t)nsend + (size_t)nsend / 2 + 16;
        d->sidx = lub_malloc(d->sidx_cap * sizeof *d->sidx);
    }
    int *fill = d->mcount; /* free after the migration */
    memset(fill, 0, (size_t)size * sizeof *fill);
    for (size_t i = 0; i < n && d->method != LUB_PAR_SFC; i++)
        for (int r = 0; r < size; r++)
            if (r != d->rank && slab_distance(d, r, P->x[a][i]) < d->width)
                d->sidx[d->sdispl[r] + fill[r]++] = (uint32_t)i;
    double *sb =
        grow_buf(&d->sbuf, &d->sbuf_cap, (nsend ? (size_t)nsend : 1) * nr * sizeof(double));
    for (long q = 0; q < nsend; q++) pack(P, d->sidx[q], sb + (size_t)q * nr);
    const long nin = exchange(d, P, sb, d->scount, d->sdispl, d->rcount, d->rdispl, n, "halo");
    d->nhalo = (size_t)nin;
    d->halo_sum += (double)nin;
    d->owned_sum += (double)n;
    P->n = n + (size_t)nin;
    d->seconds += lub_wtime() - t0;
}

void lub_par_refresh(lub_par *d, void *a, size_t elsize)
{
    const double t0 = lub_wtime();
    const long nsend = (long)d->sdispl[d->size - 1] + d->scount[d->size - 1];
    unsigned char *sb = grow_buf(&d->sbuf, &d->sbuf_cap, (nsend ? (size_t)nsend : 1) * elsize);
    const unsigned char *src = a;
    for (long q = 0; q < nsend; q++)
        memcpy(sb + (size_t)q * elsize, src + d->sidx[q] * elsize, elsize);
    MPI_Datatype t = record_type(elsize);
    /* straight into the halo's part of the array: the receive displacements are its order */
    MPI_Alltoallv(sb, d->scount, d->sdispl, t, (unsigned char *)a + d->nown * elsize, d->rcount,
                  d->rdispl, t, MPI_COMM_WORLD);
    MPI_Type_free(&t);
    d->seconds += lub_wtime() - t0;
}

/* What a set of particles carries besides its particles (dimension, time, step, levels,
 * patches, extra fields), from P into D, which receives P's records (gather, rows). */
static void copy_header(lub_particles *D, const lub_particles *P, const char *what)
{
    D->dim = P->dim;
    D->time = P->time;
    D->step = P->step;
    D->nlevels = P->nlevels;
    memcpy(D->levels, P->levels, sizeof D->levels);
    D->npatches = P->npatches;
    memcpy(D->patch_names, P->patch_names, sizeof D->patch_names);
    for (int e = 0; e < P->nextra; e++) lub_particles_extra(D, P->extra[e].name);
    if (D->nextra != P->nextra) lub_bug("%s: %d extra fields into %d", what, P->nextra, D->nextra);
}

void lub_par_gather(lub_par *d, const lub_particles *P, lub_particles *G)
{
    const double t0 = lub_wtime();
    const size_t nr = record_doubles(P), n = d->nown;
    const int size = d->size;
    int cnt = (int)n;
    MPI_Gather(&cnt, 1, MPI_INT, d->mrcount, 1, MPI_INT, 0, MPI_COMM_WORLD);
    long total = 0;
    if (d->rank == 0) total = displs(d->mrcount, d->mrdispl, size);
    double *sb = grow_buf(&d->sbuf, &d->sbuf_cap, (n ? n : 1) * nr * sizeof(double));
    for (size_t i = 0; i < n; i++) pack(P, i, sb + i * nr);
    double *rb = NULL;
    if (d->rank == 0)
        rb = grow_buf(&d->rbuf, &d->rbuf_cap, (total ? (size_t)total : 1) * nr * sizeof(double));
    MPI_Datatype t = record_type(nr * sizeof(double));
    MPI_Gatherv(sb, cnt, t, rb, d->mrcount, d->mrdispl, t, 0, MPI_COMM_WORLD);
    MPI_Type_free(&t);
    if (d->rank == 0) {
        if (G->cap < (size_t)total) lub_particles_reserve(G, (size_t)total);
        copy_header(G, P, "gather");
        for (long q = 0; q < total; q++) unpack(G, (size_t)q, rb + (size_t)q * nr);
        G->n = (size_t)total;
    }
    d->seconds += lub_wtime() - t0;
}

/* ---- the rows of the output -------------------------------------------------------------- */

size_t lub_par_row_first(const lub_par *d, int q)
{
    return (size_t)((unsigned long long)q * d->ntotal / (unsigned long long)d->size);
}

int lub_par_ids_dense(const lub_par *d, const lub_particles *P)
{
    double most = -1;
    for (size_t i = 0; i < d->nown; i++)
        if ((double)P->id[i] > most) most = (double)P->id[i];
    most = lub_par_max(most);
    return most + 1 == (double)d->ntotal;
}

/* The rank whose rows hold row r. */
static int row_owner(const lub_par *d, uint64_t r)
{
    int q = (int)((unsigned long long)r * (unsigned long long)d->size / d->ntotal);
    if (q >= d->size) q = d->size - 1;
    while (q > 0 && lub_par_row_first(d, q) > r) q--;
    while (q + 1 < d->size && lub_par_row_first(d, q + 1) <= r) q++;
    return q;
}

size_t lub_par_rows(lub_par *d, const lub_particles *P, lub_particles *R, uint64_t *place)
{
    const double t0 = lub_wtime();
    const int size = d->size;
    const size_t n = d->nown, nr = record_doubles(P) + 1; /* + the place */
    const size_t first = lub_par_row_first(d, d->rank);
    const size_t count = lub_par_row_first(d, d->rank + 1) - first;
    const long offset = lub_par_exscan((long)n); /* this rank's first place */
    memset(d->mcount, 0, (size_t)size * sizeof *d->mcount);
    for (size_t i = 0; i < n; i++) {
        if (P->id[i] >= d->ntotal)
            lub_bug("particle id %llu of %zu particles: the ids are not 0 .. N-1",
                    (unsigned long long)P->id[i], d->ntotal);
        d->mcount[row_owner(d, P->id[i])]++;
    }
    displs(d->mcount, d->mdispl, size);
    double *sb = grow_buf(&d->sbuf, &d->sbuf_cap, (n ? n : 1) * nr * sizeof(double));
    int *fill = d->scount; /* free outside the step (P->n = nown) */
    memset(fill, 0, (size_t)size * sizeof *fill);
    for (size_t i = 0; i < n; i++) {
        const int o = row_owner(d, P->id[i]);
        double *rec = sb + (size_t)(d->mdispl[o] + fill[o]++) * nr;
        pack(P, i, rec);
        const uint64_t at = (uint64_t)offset + i;
        memcpy(&rec[nr - 1], &at, sizeof at);
    }
    MPI_Alltoall(d->mcount, 1, MPI_INT, d->mrcount, 1, MPI_INT, MPI_COMM_WORLD);
    const long nin = displs(d->mrcount, d->mrdispl, size);
    if ((size_t)nin != count)
        lub_bug("rows %zu .. %zu: %ld particles received", first, first + count, nin);
    if (R->cap < count) lub_bug("rows: %zu rows, room for %zu", count, R->cap);
    double *rb = grow_buf(&d->rbuf, &d->rbuf_cap, (nin ? (size_t)nin : 1) * nr * sizeof(double));
    MPI_Datatype t = record_type(nr * sizeof(double));
    MPI_Alltoallv(sb, d->mcount, d->mdispl, t, rb, d->mrcount, d->mrdispl, t, MPI_COMM_WORLD);
    MPI_Type_free(&t);
    copy_header(R, P, "rows");
    R->n = count;
    for (size_t r = 0; r < count; r++) R->id[r] = UINT64_MAX;
    for (long q = 0; q < nin; q++) {
        const double *rec = rb + (size_t)q * nr;
        uint64_t id;
        memcpy(&id, &rec[10], sizeof id);
        const size_t r = (size_t)(id - first);
        unpack(R, r, rec);
        memcpy(&place[r], &rec[nr - 1], sizeof place[r]);
    }
    for (size_t r = 0; r < count; r++)
        if (R->id[r] != first + r)
            lub_bug("row %zu holds no particle (ids not unique?)", first + r);
    d->seconds += lub_wtime() - t0;
    return first;
}

/* ---- the start on the slabs ----------------------------------------------------------- */

/* Every place of 0 .. total - 1 once over the ranks' slices (as the whole-file reader
 * checks): each place is sent to the rank holding that range of places, which marks them;
 * the first place out of range or twice, or -1 (collective). */
static long long duplicate_place(lub_par *d, const uint64_t *place, size_t n)
{
    const int size = d->size;
    const size_t total = d->ntotal;
    long long bad = -1;
    memset(d->mcount, 0, (size_t)size * sizeof *d->mcount);
    for (size_t i = 0; i < n && bad < 0; i++)
        if (place[i] >= total) bad = (long long)place[i];
    for (size_t i = 0; i < n; i++)
        if (place[i] < total) d->mcount[row_owner(d, place[i])]++;
    displs(d->mcount, d->mdispl, size);
    uint64_t *sb = lub_malloc((n ? n : 1) * sizeof *sb);
    int *fill = d->scount;
    memset(fill, 0, (size_t)size * sizeof *fill);
    for (size_t i = 0; i < n; i++)
        if (place[i] < total) {
            const int o = row_owner(d, place[i]);
            sb[d->mdispl[o] + fill[o]++] = place[i];
        }
    MPI_Alltoall(d->mcount, 1, MPI_INT, d->mrcount, 1, MPI_INT, MPI_COMM_WORLD);
    const long nin = displs(d->mrcount, d->mrdispl, size);
    uint64_t *rb = lub_malloc((nin ? (size_t)nin : 1) * sizeof *rb);
    MPI_Alltoallv(sb, d->mcount, d->mdispl, MPI_UINT64_T, rb, d->mrcount, d->mrdispl, MPI_UINT64_T,
                  MPI_COMM_WORLD);
    const size_t first = lub_par_row_first(d, d->rank);
    const size_t count = lub_par_row_first(d, d->rank + 1) - first;
    unsigned char *seen = lub_calloc(count ? count : 1, 1);
    for (long q = 0; q < nin && bad < 0; q++) {
        if (seen[rb[q] - first]) bad = (long long)rb[q];
        seen[rb[q] - first] = 1;
    }
    free(seen), free(rb), free(sb);
    long long most = bad;
    MPI_Allreduce(&bad, &most, 1, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
    return most;
}

typedef struct {
    uint64_t place;
    size_t at;
} placed;

static int cmp_placed(const void *a, const void *b)
{
    const placed *x = a, *y = b;
    if (x->place != y->place) return (x->place > y->place) - (x->place < y->place);
    return (x->at > y->at) - (x->at < y->at);
}

size_t lub_par_distribute(lub_par *d, const lub_particles *S, const uint64_t *place,
                          lub_particles *P, const char *path)
{
    const double t0 = lub_wtime();
    const int size = d->size;
    const size_t nr = record_doubles(S) + 1, n = S->n; /* + the place */
    d->ntotal = (size_t)lub_par_sum_long((long)n);
    const long long bad = duplicate_place(d, place, n);
    if (bad >= 0)
        lub_fatal("%s: /solver/order holds %llu twice or beyond the %zu particles: not a place "
                  "of 0 .. %zu, each once",
                  path, bad, d->ntotal, d->ntotal ? d->ntotal - 1 : 0);
    cut_at_quantiles(d, S, n);
    /* every particle of the slice to its slab's owner, with its place */
    memset(d->mcount, 0, (size_t)size * sizeof *d->mcount);
    for (size_t i = 0; i < n; i++) d->mcount[lub_par_owner_of(d, S, i)]++;
    displs(d->mcount, d->mdispl, size);
    /* (the buffers are the start's own, freed after it: the exchanges' buffers of the run,
     * kept from step to step, stay the size of a halo) */
    double *sb = lub_malloc((n ? n : 1) * nr * sizeof(double));
    int *fill = d->scount;
    memset(fill, 0, (size_t)size * sizeof *fill);
    for (size_t i = 0; i < n; i++) {
        const int o = lub_par_owner_of(d, S, i);
        double *rec = sb + (size_t)(d->mdispl[o] + fill[o]++) * nr;
        pack(S, i, rec);
        memcpy(&rec[nr - 1], &place[i], sizeof place[i]);
    }
    MPI_Alltoall(d->mcount, 1, MPI_INT, d->mrcount, 1, MPI_INT, MPI_COMM_WORLD);
    const long nin = displs(d->mrcount, d->mrdispl, size);
    double *rb = lub_malloc((nin ? (size_t)nin : 1) * nr * sizeof(double));
    MPI_Datatype t = record_type(nr * sizeof(double));
    MPI_Alltoallv(sb, d->mcount, d->mdispl, t, rb, d->mrcount, d->mrdispl, t, MPI_COMM_WORLD);
    MPI_Type_free(&t);
    free(sb);
    /* the slab's particles in the solver's order (their places), as a serial run holds them */
    placed *order = lub_malloc((nin ? (size_t)nin : 1) * sizeof *order);
    for (long q = 0; q < nin; q++) {
        memcpy(&order[q].place, rb + (size_t)q * nr + nr - 1, sizeof order[q].place);
        order[q].at = (size_t)q;
    }
    qsort(order, (size_t)nin, sizeof *order, cmp_placed);
    lub_particles_init(P, S->dim, nin ? (size_t)nin : 1);
    copy_header(P, S, "distribute");
    for (long q = 0; q < nin; q++) unpack(P, (size_t)q, rb + order[q].at * nr);
    free(order);
    free(rb);
    P->n = (size_t)nin;
    d->nown = (size_t)nin;
    d->nhalo = 0;
    d->seconds += lub_wtime() - t0;
    return (size_t)lub_par_max((double)nin);
}

/* The distance from particle i of P to rank r's box (box: [size][6], lower corner then
 * upper), the period taken into account (sfc's collection). */
static double box_distance(const lub_par *d, const double *box, int r, const lub_particles *P,
                           size_t i)
{
    double d2 = 0;
    for (int k = 0; k < d->dim; k++) {
        const double a = box[6 * r + k], b = box[6 * r + 3 + k];
        double best = INFINITY;
        const int shifts = d->cper[k] ? 1 : 0;
        for (int s = -shifts; s <= shifts; s++) {
            const double y = P->x[k][i] + s * d->cperiod[k];
            const double e = y < a ? a - y : (y > b ? y - b : 0.0);
            if (e < best) best = e;
        }
        d2 += best * best;
    }
    return sqrt(d2);
}

/* Whether the wanted particle i of P goes to rank r's collection. */
static int collected(const lub_par *d, const double *box, int r, const lub_particles *P, size_t i,
                     double width)
{
    if (r == d->rank) return 0;
    if (d->method == LUB_PAR_SFC) return box_distance(d, box, r, P, i) < width;
    return slab_distance(d, r, P->x[d->axis][i]) < width;
}

void lub_par_collect(lub_par *d, const lub_particles *P, double width, const uint8_t *want,
                     lub_particles *Q)
{
    const int size = d->size;
    const size_t nr = record_doubles(P);
    const double w0 = d->width;
    d->width = width; /* slab_distance against the given width */
    /* the curve's ranges: a rank's region is cells along the curve, not an interval; the
     * bounding box of its wanted particles (all ranks': one all-gather of 6 numbers each)
     * holds them, so that every pair within width is collected (and some farther) */
    double *box = NULL;
    if (d->method == LUB_PAR_SFC) {
        box = lub_malloc(6 * (size_t)size * sizeof *box);
        double mine[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < d->nown; i++)
            for (int k = 0; k < d->dim && want[i]; k++) {
                mine[k] = fmin(mine[k], P->x[k][i]);
                mine[3 + k] = fmax(mine[3 + k], P->x[k][i]);
            }
        MPI_Allgather(mine, 6, MPI_DOUBLE, box, 6, MPI_DOUBLE, MPI_COMM_WORLD);
    }
    memset(d->mcount, 0, (size_t)size * sizeof *d->mcount);
    for (size_t i = 0; i < d->nown; i++)
        for (int r = 0; r < size && want[i]; r++)
            if (collected(d, box, r, P, i, width)) d->mcount[r]++;
    const long nsend = displs(d->mcount, d->mdispl, size);
    double *sb = lub_malloc((nsend ? (size_t)nsend : 1) * nr * sizeof(double));
    int *fill = d->scount;
    memset(fill, 0, (size_t)size * sizeof *fill);
    for (size_t i = 0; i < d->nown; i++)
        for (int r = 0; r < size && want[i]; r++)
            if (collected(d, box, r, P, i, width))
                pack(P, i, sb + (size_t)(d->mdispl[r] + fill[r]++) * nr);
    d->width = w0;
    free(box);
    MPI_Alltoall(d->mcount, 1, MPI_INT, d->mrcount, 1, MPI_INT, MPI_COMM_WORLD);
    const long nin = displs(d->mrcount, d->mrdispl, size);
    double *rb = lub_malloc((nin ? (size_t)nin : 1) * nr * sizeof(double));
    MPI_Datatype t = record_type(nr * sizeof(double));
    MPI_Alltoallv(sb, d->mcount, d->mdispl, t, rb, d->mrcount, d->mrdispl, t, MPI_COMM_WORLD);
    MPI_Type_free(&t);
    lub_particles_init(Q, P->dim, nin ? (size_t)nin : 1);
    copy_header(Q, P, "collect");
    for (long q = 0; q < nin; q++) unpack(Q, (size_t)q, rb + (size_t)q * nr);
    Q->n = (size_t)nin;
    free(sb), free(rb);
}

void lub_par_raise(int status, const char *msg)
{
    const int who = lub_par_first(msg != NULL);
    if (who < 0) return;
    char text[2048];
    snprintf(text, sizeof text, "%d %s", status, msg ? msg : "");
    lub_par_bcast_text(text, sizeof text, who);
    char *rest = NULL;
    const int st = (int)strtol(text, &rest, 10);
    const char *m = rest && *rest == ' ' ? rest + 1 : text;
    if (st == LUB_EXIT_RUN) lub_fatal_run("%s", m);
    lub_fatal("%s", m);
}

long lub_par_peak_memory(long kb, long *least, long *mean)
{
    long v[3] = {kb, -kb, kb};
    MPI_Allreduce(MPI_IN_PLACE, v, 2, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, v + 2, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
    *least = -v[1];
    *mean = v[2] / size_;
    return v[0];
}

#endif
