/* lubFoam: the semi-implicit MPS solver (methods.md §1-2).
 *
 * Reads the case's dictionaries and the particles of the start time, checks the stability
 * limits (and, multi-resolution, the fine/coarse boundaries: lubFoamChecks.c), then advances
 * in time, writing time folders and function-object tables, and reports what the run cost.
 */
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "core/args.h"
#include "core/error.h"
#include "core/timer.h"
#include "geometry/geometry.h"
#include "particles/particles_io.h"
#include "io/table.h"
#include "lubFoam.h"

static volatile sig_atomic_t stop_signal = 0, write_signal = 0;
static void on_signal(int sig)
{
    if (sig == SIGUSR1)
        write_signal = sig;
    else
        stop_signal = sig;
}

/* As OpenFOAM's solvers: SIGINT, SIGTERM, SIGHUP (the terminal closed) and SIGQUIT ask for
 * the current state to be written and the run to stop; SIGUSR1 asks for a time folder now,
 * and the run goes on.  Installed first thing in main, so that a signal in the first
 * milliseconds (while the dictionaries are read) does not kill the run: it stops before
 * its first step, having written nothing.  The handler stays installed (sigaction without
 * SA_RESETHAND): with -std=c11 glibc's signal() has System V semantics, so a second signal
 * before the state was written (lubSweep signals the run's process group as well as its
 * own children; a second Ctrl-C) used to kill the run and lose the state.  SA_RESTART:
 * system calls of the writers are resumed, not failed. */
static void install_signal_handlers(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    const int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1};
    sigset_t set;
    sigemptyset(&set);
    for (size_t k = 0; k < sizeof sigs / sizeof *sigs; k++) {
        sigaction(sigs[k], &sa, NULL);
        sigaddset(&set, sigs[k]);
    }
    /* a parent that blocked them (a shell's trap, a job script) would hide them from the run
     * for ever: unblocked, a signal already pending is taken now, at the start */
    sigprocmask(SIG_UNBLOCK, &set, NULL);
}

static const char *signal_name(int sig)
{
    switch (sig) {
    case SIGINT:
        return "SIGINT";
    case SIGTERM:
        return "SIGTERM";
    case SIGHUP:
        return "SIGHUP";
    case SIGQUIT:
        return "SIGQUIT";
    case SIGUSR1:
        return "SIGUSR1";
    default:
        return "signal";
    }
}

/* CPU seconds of this process (all its threads). */
static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void format_hms(double s, char *buf, size_t size)
{
    if (!isfinite(s) || s < 0) {
        snprintf(buf, size, "--:--:--");
        return;
    }
    long t = (long)(s + 0.5);
    snprintf(buf, size, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
}

static double fraction_done(const lubfoam_run *r, long steps_done)
{
    if (r->ctl.stop_at == LUB_STOP_NSTEPS) return (double)steps_done / (double)r->ctl.n_steps;
    double span = r->ctl.end_time - r->start_time;
    return span > 0 ? (r->t - r->start_time) / span : 1.0;
}

/* Courant (T-18) and diffusion (T-30) numbers against their limits, before the first step.
 * The speed is the fastest wall (movingWalls) or particle.  At a restart (a start step > 0)
 * the particles' own speeds only warn: the uninterrupted run met them mid-run, where a
 * Courant number above the limit is a warning too, and a restart must be able to continue
 * it.  At step 0 they count like the walls (a fluid given a velocity). */
static void check_limits(lubfoam_run *r, const lub_geometry *geo)
{
    /* resolution levels: every level takes deltaT (commonDeltaT), so the finest level has the
     * largest Courant and diffusion numbers for a speed; the speed is the fastest of all */
    const lub_scene *sc = &r->scene;
    const lub_mps *m = sc->level[0];
    double ufluid = lub_mps_max_speed(m), uwall = 0;
    for (int k = 1; k < sc->nlevels; k++) ufluid = fmax(ufluid, lub_mps_max_speed(sc->level[k]));
    /* sub-stepping: a coarser level takes dt_factor deltaT; its Courant number, over the
     * finest level's, is dt_factor l0_0 / l0_k (1 when Nr is the l0 ratio, T-19) */
    double fac = 1;
    for (int k = 1; k < sc->nlevels; k++)
        fac = fmax(fac, (double)sc->dt_factor[k] * m->l0 / sc->level[k]->l0);
    if (fac > 1)
        lub_message("Levels: the sub-steps Nr exceed the l0 ratio: the coarse level's Courant "
                    "number is %g times the fine level's (checked below)",
                    fac);
    for (int k = 0; k < r->P.npatches; k++) {
        const double *v = m->c.patch_velocity[k];
        double s = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (s > uwall) uwall = s;
    }
    const int restart = r->step > 0;
    double umax = fmax(ufluid, uwall);
    double ucheck = restart && !r->ctl.adjust_time_step ? uwall : umax;
    double co = fac * umax * r->dt / m->l0;
    if (r->ctl.adjust_time_step && umax > 0) {
        double dtc = r->ctl.max_courant * m->l0 / (fac * umax);
        if (dtc < r->dt) r->dt = dtc;
        co = fac * umax * r->dt / m->l0;
    }
    double dn = m->c.nu * r->dt / (m->l0 * m->l0);
    lub_message("Stability: Courant %.4g (u_max %g m/s, dt %g s, l0 %g m; limit %g), "
                "diffusion number %.4g (nu dt / l0^2; %s viscosity%s)",
                co, umax, r->dt, m->l0, r->ctl.max_courant, dn,
                m->c.viscosity == LUB_VISCOSITY_NONE       ? "no"
                : m->c.viscosity == LUB_VISCOSITY_EXPLICIT ? "explicit"
                                                           : "implicit",
                m->c.viscosity == LUB_VISCOSITY_EXPLICIT ? ", limit maxDiffusion" : "");
    double cocheck = fac * ucheck * r->dt / m->l0;
    if (cocheck > r->ctl.max_courant * (1 + 1e-9))
        lub_fatal("Courant number %.4g (u_max %g m/s x deltaT %g s / l0 %g m) exceeds maxCourant "
                  "%g in system/controlDict.yaml: reduce deltaT to at most %.4g s or set "
                  "adjustTimeStep: true",
                  cocheck, ucheck, r->dt, m->l0, r->ctl.max_courant,
                  r->ctl.max_courant * m->l0 / ucheck);
    if (co > r->ctl.max_courant * (1 + 1e-9))
        lub_warning("restart at step %ld: the fastest particle (%g m/s) has Courant number %.4g, "
                    "above maxCourant %g (the walls: %.4g); continuing as the run did",
                    r->step, ufluid, co, r->ctl.max_courant, uwall * r->dt / m->l0);
    /* Gravity: a particle at rest reaches |g| deltaT in one step, and so moves |g| deltaT^2;
     * the Courant limit holds for that speed too (deltaT: 1e300 took a first step to an
     * infinite position).  With adjustTimeStep deltaT is the step whenever the particles are
     * slow, so it is checked as well. */
    /* the uniform body acceleration the scene's models give (gravity: models/model.h forces) */
    double acc[3] = {0, 0, 0};
    int body = 0;
    for (int k = 0; k < r->scene.nmodels; k++) {
        lub_model *md = &r->scene.model[k];
        if (md->type->forces) body |= md->type->forces(md, m, r->dt, acc);
    }
    if (body) {
        double g = 0;
        for (int d = 0; d < m->dim; d++) g += acc[d] * acc[d];
        g = sqrt(g);
        const double dtmax = fmax(r->dt, r->ctl.delta_t);
        const double cog = fac * g * dtmax * dtmax / m->l0;
        /* Fatal only when a particle at rest would fall more than l0 in one step: a
         * viscous film holds its particles far below |g| deltaT (the Poiseuille channel of
         * tutorials/convergence: |g| deltaT = 4.5 m/s at the first step, 1 m/s in the steady
         * flow, whose diffusion length sqrt(nu deltaT) spans the channel in one step), so
         * above maxCourant but below that it warns, as does a restart */
        if (g > 0 && cog > r->ctl.max_courant * (1 + 1e-9) && cog <= 1)
            lub_warning("gravity gives a particle at rest |g| deltaT = %g m/s in one step: "
                        "Courant number %.4g, above maxCourant %g (a free particle would "
                        "outrun the limit; viscosity holds a film's particles back)",
                        g * dtmax, cog, r->ctl.max_courant);
        else if (g > 0 && !(cog <= r->ctl.max_courant * (1 + 1e-9)))
            lub_fatal("gravity: a particle at rest reaches |g| deltaT = %g m/s in one step of "
                      "deltaT %g s: Courant number %.4g exceeds maxCourant %g in "
                      "system/controlDict.yaml: reduce deltaT to at most %.4g s",
                      g * dtmax, dtmax, cog, r->ctl.max_courant,
                      sqrt(r->ctl.max_courant * m->l0 / (fac * g)));
    }
    /* Implicit viscosity is stable at any nu dt / l0^2, but its matrix I + D L (T-13, D the
     * diffusion number) has a condition number of about D times the Laplacian's, and the
     * solve loses the velocity to round-off once that times the machine epsilon 2.2e-16
     * reaches the tolerance of the solve (nu: 1e300 broke the solver at step 2). */
    const double dn_implicit_max = 1e6;
    if (m->c.viscosity != LUB_VISCOSITY_NONE && m->c.viscosity != LUB_VISCOSITY_EXPLICIT &&
        !(dn <= dn_implicit_max))
        lub_fatal("diffusion number %.4g (nu %g m^2/s x deltaT %g s / l0^2) is beyond %g, where "
                  "the implicit viscous solve loses the velocity to round-off: reduce deltaT to "
                  "at most %.4g s or check nu in constant/transportProperties.yaml",
                  dn, m->c.nu, r->dt, dn_implicit_max, dn_implicit_max * m->l0 * m->l0 / m->c.nu);
    if (m->c.viscosity == LUB_VISCOSITY_EXPLICIT && dn > r->ctl.max_diffusion)
        lub_fatal("diffusion number %.4g (nu %g m^2/s x deltaT %g s / l0^2) exceeds maxDiffusion "
                  "%g with explicit viscosity: use 'viscosity: { scheme: crankNicolson }' in "
                  "constant/models.yaml or reduce deltaT to at most %.4g s",
                  dn, m->c.nu, r->dt, r->ctl.max_diffusion,
                  r->ctl.max_diffusion * m->l0 * m->l0 / m->c.nu);
    /* the formulation's own (MPH: its elastic number, compression, walls) */
    if (sc->fluid->check) sc->fluid->check(m, geo, r->dt, acc);
}

/* average, others_running: the load average and the tasks of other programs runnable when
 * lubFoam started (-1: unknown) */
static void print_header(const lubfoam_run *r, double average, int others_running)
{
    const lub_mps *m = r->scene.level[0];
    long cnt[3] = {0, 0, 0}; /* -parallel: of every rank's slab */
    for (size_t i = 0; i < r->P.n; i++) cnt[r->P.kind[i] < 3 ? r->P.kind[i] : 0]++;
    if (r->parallel) lub_par_sum_longs(cnt, 3);
    lub_message("lubFoam: case %s, start time %s (step %ld), %d-D", r->cs.root, r->start_name,
                r->step, m->dim);
    lub_message("Particles: %ld (fluid %ld, wall %ld, dummy %ld), threads %d",
                cnt[0] + cnt[1] + cnt[2], cnt[0], cnt[1], cnt[2], omp_get_max_threads());
    const double load = lub_load_now(average, others_running);
    int fit = 1;
    if (lub_threads_oversubscribed(load, omp_get_num_procs(), omp_get_max_threads(), &fit))
        lub_warning("the machine is busy (load average %.2f, %d tasks of other programs "
                    "running at start, on %d cores) and this run has %d threads: threads that "
                    "wait for each other on shared cores can make every step several times "
                    "slower; OMP_NUM_THREADS=%d may be faster",
                    average, others_running, omp_get_num_procs(), omp_get_max_threads(), fit);
    lub_scene_header_fluid(&r->scene);
    /* the models of constant/models.yaml this run has (a scene enables only those it needs) */
    char models[1024];
    lub_scene_describe(&r->scene, models, sizeof models);
    const size_t len = strlen(models);
    lub_message("Models: %s", len ? models : "none (constant/models.yaml)");
    lub_scene_header(&r->scene);
}

static void log_line(const lubfoam_run *r, long steps_done, double wall0, double pit_sum)
{
    double frac = fraction_done(r, steps_done);
    double el = lub_wtime() - wall0;
    char eta[32], ew[128], fluid[256 * LUB_MAX_LEVELS];
    format_hms(frac > 0 ? el * (1 - frac) / frac : NAN, eta, sizeof eta);
    lub_scene_log(&r->scene, ew, sizeof ew);
    lub_scene_log_fluid(&r->scene, r->dt, steps_done ? pit_sum / (double)steps_done : 0.0, fluid,
                        sizeof fluid);
    lub_message("t %-12.6g %5.1f%%  step %-8ld dt %-9.3g Co %-6.3g %sETA %s%s", r->t, 100 * frac,
                r->step, r->dt, lub_scene_courant(&r->scene, r->dt, NULL), fluid, eta, ew);
}

static void progress_bar(const lubfoam_run *r, long steps_done, double wall0)
{
    double frac = fraction_done(r, steps_done);
    double el = lub_wtime() - wall0;
    char eta[32];
    format_hms(frac > 0 ? el * (1 - frac) / frac : NAN, eta, sizeof eta);
    int w = 30, k = (int)(frac * w);
    char bar[64];
    for (int i = 0; i < w; i++) bar[i] = i < k ? '#' : '.';
    bar[w] = '\0';
    fprintf(stdout, "\r[%s] %5.1f%% t %-10.5g ETA %s ", bar, 100 * frac, r->t, eta);
    fflush(stdout);
}

/* Seconds spent in phase k (summed over the levels). */
static double phase_seconds(const lubfoam_run *r, int k)
{
    double s = 0;
    for (int l = 0; l < r->scene.nlevels; l++) s += r->scene.level[l]->tm.seconds[k];
    return s;
}

/* The timers the solver's own work outside a step (output, coupling) is charged to. */
static lub_timers *run_timers(lubfoam_run *r)
{
    return &r->scene.level[0]->tm;
}

/* Everything main allocated for the run. */
static void run_free(lubfoam_run *r, lubfoam_functions *fos)
{
    lubfoam_functions_free(fos);
    lub_scene_free(&r->scene);
    lub_particles_free(&r->P);
    lub_control_free(&r->ctl);
    free(r->written);
}

/* -parallel: the peak resident memory of the ranks (the start-up included) and what each
 * holds: its slab, not the case (doc/parallel.md, per-rank capacity).  Collective. */
static void report_memory(const lubfoam_run *r)
{
    long least, mean;
    const long peak = lub_par_peak_memory(lub_peak_memory_kb(NULL), &least, &mean);
    const double cap = lub_par_max((double)r->P.cap);
    const long resized = lub_par_sum_long(r->par.nresized);
    lub_message("Memory: peak resident (VmHWM) per rank %.1f MB on the fullest rank, %.1f MB on "
                "the least, mean %.1f MB; capacity at most %.0f particles per rank (%.1f%% of "
                "the case), re-sized %ld time%s during the run",
                peak / 1024.0, least / 1024.0, mean / 1024.0, cap,
                r->par.ntotal ? 100 * cap / (double)r->par.ntotal : 0.0, resized,
                resized == 1 ? "" : "s");
}

/* Cost summary on the log and in postProcessing/cost/<startTime>/cost.dat. */
static void write_cost(lubfoam_run *r, long steps, double wall, double pit_sum, double vit_sum)
{
    const size_t np = r->parallel ? r->par.ntotal : r->P.n;
    double ps = (double)np * (double)steps;
    double us = ps > 0 ? 1e6 * wall / ps : 0;
    lub_message("Cost: %ld steps, %zu particles, %.6g particle-steps in %.3f s wall: "
                "%.4g us per particle-step (%d threads%s)",
                steps, np, ps, wall, us, omp_get_max_threads(), r->parallel ? " per rank" : "");
    double comm = 0;
    if (r->parallel) {
        /* the exchanges' time on the rank that spent most in them, and least (the slab
         * boundaries' count differs: the end slabs of a non-periodic axis have one); the
         * solves' own messages are inside PETSc, in the phases pressureSolve and
         * viscositySolve; rank 0's phases below */
        comm = lub_par_max(r->par.seconds);
        const double least = -lub_par_max(-r->par.seconds);
        const double mig = lub_par_sum((double)r->par.nmigrated);
        const double most = lub_par_max((double)r->par.nown);
        /* on a shared machine the wall time counts the waits for a core; the CPU time of
         * the ranks counts what they ran (an MPI wait that spins included) */
        const double cpu = lub_par_sum(cpu_seconds() - r->cpu0);
        /* the halo against the owned particles, over all ranks and steps: the work on the
         * copies (their lists, PND, gradients) and the size of the exchanges */
        const double halo = lub_par_sum(r->par.halo_sum), owned = lub_par_sum(r->par.owned_sum);
        report_memory(r);
        lub_message("  %d ranks: %.4g core-us per particle-step (wall x ranks x threads / "
                    "particle-steps), %.4g by the ranks' CPU time (%.3f s); communication "
                    "(halo, migration, gathers) %.3f s, %.1f%% of the wall time on the rank "
                    "with the most (%.3f s on the least); halo %.1f%% of the owned particles "
                    "(mean over ranks and steps); %.0f particles on the fullest rank at the end "
                    "(mean %.0f); %.0f particles migrated; %ld re-balancing cuts; rank 0's "
                    "phases (the least and the most of any rank in brackets: the load's "
                    "balance):",
                    r->par.size, us * r->par.size * omp_get_max_threads(),
                    ps > 0 ? 1e6 * cpu / ps : 0.0, cpu, comm, wall > 0 ? 100 * comm / wall : 0.0,
                    least, owned > 0 ? 100 * halo / owned : 0.0, most,
                    (double)r->par.ntotal / r->par.size, mig, r->par.nbalanced);
    }
    /* each phase's spread over the ranks (collective: before the writer's return) */
    double most_t[LUB_T_COUNT], least_t[LUB_T_COUNT];
    for (int k = 0; k < LUB_T_COUNT; k++) {
        most_t[k] = least_t[k] = phase_seconds(r, k);
        if (r->parallel) {
            most_t[k] = lub_par_max(most_t[k]);
            least_t[k] = -lub_par_max(-least_t[k]);
        }
    }
    if (!lubfoam_writer_rank(r)) return;
    for (int k = 0; k < LUB_T_COUNT; k++) {
        if (r->parallel && r->par.size > 1)
            lub_message("  %-16s %10.3f s  %5.1f%%   [%.3f, %.3f s]", lub_mps_phase_names[k],
                        phase_seconds(r, k), wall > 0 ? 100 * phase_seconds(r, k) / wall : 0.0,
                        least_t[k], most_t[k]);
        else
            lub_message("  %-16s %10.3f s  %5.1f%%", lub_mps_phase_names[k], phase_seconds(r, k),
                        wall > 0 ? 100 * phase_seconds(r, k) / wall : 0.0);
    }
    char path[LUB_PATH_MAX];
    lub_postproc_path(&r->cs, "cost", r->start_name, "cost.dat", path);
    lub_atomic_file af;
    FILE *fp = lub_atomic_open(&af, path);
    if (!fp) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
    char names[512];
    size_t len = (size_t)snprintf(names, sizeof names,
                                  "wallTime[s] steps particles particleSteps "
                                  "usPerParticleStep[us] threads meanPressureIterations "
                                  "meanViscosityIterations ranks communication[s]");
    for (int k = 0; k < LUB_T_COUNT; k++) /* seconds per phase */
        len += (size_t)snprintf(names + len, sizeof names - len, " %s[s]", lub_mps_phase_names[k]);
    lub_table_write_header(fp, names);
    enum { NFIXED = 10 };
    double row[NFIXED + LUB_T_COUNT] = {wall,
                                        (double)steps,
                                        (double)np,
                                        ps,
                                        us,
                                        (double)omp_get_max_threads(),
                                        steps ? pit_sum / (double)steps : 0.0,
                                        steps ? vit_sum / (double)steps : 0.0,
                                        r->parallel ? (double)r->par.size : 1.0,
                                        comm};
    for (int k = 0; k < LUB_T_COUNT; k++) row[NFIXED + k] = phase_seconds(r, k);
    lub_table_write_row(fp, row, NFIXED + LUB_T_COUNT);
    if (lub_atomic_close(&af) != 0) lub_fatal_run("cannot write '%s': %s", path, strerror(errno));
}

int main(int argc, char **argv)
{
    install_signal_handlers();
    /* A log file (runApplication, `> log`) is followed with tail -f: one line at a time. */
    if (!isatty(STDOUT_FILENO)) setvbuf(stdout, NULL, _IOLBF, 0);
    lub_program_info info = {
        .name = "lubFoam",
        .summary = "semi-implicit MPS (or MPH) solver for thin-film lubrication",
        .usage = "[OPTIONS]",
        .description =
            "  Starts from the time folder chosen by startFrom in system/controlDict.yaml,\n"
            "  advances to endTime (to the first step at or after it: a step is never\n"
            "  shortened, the log says where the run ends) or nSteps, writes time folders\n"
            "  and the tables of the function objects, and reports its cost in\n"
            "  postProcessing/cost/<startTime>/cost.dat (a case already at its endTime:\n"
            "  nothing to run, nothing written).  SIGINT, SIGTERM, SIGHUP and SIGQUIT\n"
            "  write the current state and exit 0 (before the first step: nothing\n"
            "  written); SIGUSR1 writes a time folder at the next step and the run goes\n"
            "  on.  Write times are multiples of writeInterval from the start of the\n"
            "  case's first run, whatever the restarts between.  Temporary files and\n"
            "  folders of a run killed while writing (kill -9, a full disk) are removed at\n"
            "  the next start.  A non-finite value, a particle leaving the\n"
            "  domain or a fluid particle going through a wall stops the run with exit 2,\n"
            "  naming the particle (and the wall) and the step; the newest time folder is\n"
            "  then the last good state.\n"
            "  startFrom: startTime over the results of an earlier run overwrites each time\n"
            "  folder and table the run writes again and leaves the others (the log warns,\n"
            "  listing them): lubClean removes them first, startFrom: latestTime continues.\n"
            "  -parallel runs on the processes of 'mpirun -np N lubFoam -parallel' (a build\n"
            "  with MPI: make MPI=1, the default with PETSc): system/decomposeParDict.yaml\n"
            "  gives numberOfSubdomains (= N), the method (slabs along an axis, or sfc:\n"
            "  ranges of a Hilbert curve over cells), the re-balancing and the margin;\n"
            "  every rank reads the dictionaries and its rows of the start's particles,\n"
            "  keeps its slab or range (sized for it, its halo and the margin: no rank\n"
            "  holds the whole case; re-sized between steps if it fills) and a halo of its\n"
            "  neighbours' particles, the pressure (and implicit viscosity) is solved by\n"
            "  PETSc over all ranks (solver: petsc in system/solution.yaml); the time\n"
            "  folders are a serial run's: every rank writes its rows of particles.h5\n"
            "  (MPI-IO: a build with Open MPI's HDF5), or rank 0 the particles gathered to\n"
            "  it (the serial HDF5, or writeParticles: gather), and rank 0 the rest, the log\n"
            "  and the function objects' tables (totals, wallPressure, wallLoad: sums over\n"
            "  every rank's particles); the end of the log gives each rank's peak memory.\n"
            "  A restart reads each rank's rows of the start's particles.h5, on any number\n"
            "  of ranks.  Models\n"
            "  other than gravity, movingWalls and collision, fluid type mph, LSMPS\n"
            "  Laplacians and the function object forces are refused (exit 1).\n"
            "  -dryRun reads and checks every dictionary and the start particles, prints the\n"
            "  start-up figures (particles, schemes, models, Courant and diffusion numbers,\n"
            "  multi-resolution checks), runs nothing and writes nothing.\n"
            "  The fluid is semi-implicit MPS, or with 'fluid: { type: mph, bulkViscosity:\n"
            "  L, bulkModulus: K }' in constant/models.yaml Moving Particle Hydrodynamics\n"
            "  (methods.md 8), whose start-up figures add its elastic number and\n"
            "  hydrostatic compression and which needs walls of dummyLayers: 3.",
        .dictionaries = "system/controlDict.yaml\nsystem/particleGenDict.yaml (domain)\n"
                        "system/schemes.yaml\nsystem/solution.yaml (optional)\n"
                        "constant/transportProperties.yaml\nconstant/models.yaml\n"
                        "system/reynoldsRefDict.yaml (optional: the start-up check of "
                        "resolution levels)\nsystem/decomposeParDict.yaml (-parallel)",
        .has_case = 1,
        .min_args = 0,
        .max_args = 0,
    };
    int dry_run = 0, parallel = 0;
    lub_option opts[] = {{"-dryRun", NULL,
                          "check the case and print the start-up figures; run nothing, write "
                          "nothing",
                          LUB_OPT_FLAG, &dry_run},
                         {"-parallel", NULL,
                          "run on the processes of mpirun -np N (system/decomposeParDict.yaml)",
                          LUB_OPT_FLAG, &parallel},
                         {0}};
    /* MPI first, before anything reads the arguments (mpirun may add its own) */
    lub_set_program(info.name);
    if (lubfoam_wants_parallel(argc, argv)) lub_par_start(&argc, &argv);
    lub_args a;
    lub_args_parse(&a, argc, argv, &info, opts);
    /* the machine's load, read before this program starts its OpenMP threads: the runnable
     * tasks then count only this thread of it */
    int runnable;
    const double load_average = lub_load_average(NULL, &runnable);
    const int others_running = runnable > 0 ? runnable - 1 : -1;

    lubfoam_run r;
    memset(&r, 0, sizeof r);
    char path[LUB_PATH_MAX];
    lub_case_open(&r.cs, a.case_dir);
    if (lub_par_rank() == 0) lub_case_clean(&r.cs); /* one rank clears the leftovers */
    lub_control_read(&r.ctl, lub_case_path(&r.cs, path, "system/controlDict.yaml"));
    lub_geometry geo;
    lub_geometry_read(&geo, lub_case_path(&r.cs, path, "system/particleGenDict.yaml"));
    /* -parallel: each rank reads its slice of the start's particles and keeps its slab; the
     * start-up checks and figures over particles are then collective */
    if (parallel) lubfoam_parallel_start(&r, &geo);
    lubfoam_read_start(&r, &geo);
    lubfoam_check_particles(&r, &geo);
    /* the fluid and the models the scene lists, and the solvers they need */
    lub_mps_config cfg;
    lub_scene_read(&r.scene, &r.cs, &r.P, &geo, &cfg);
    if (parallel) lubfoam_parallel_capacity(&r, &cfg);
    char state[LUB_PATH_MAX], what[128];
    lub_case_pathf(&r.cs, state, "%s/uniform/state.yaml", r.start_name);
    snprintf(what, sizeof what, "endTime %g of system/controlDict.yaml", r.ctl.end_time);
    lub_scene_build(&r.scene, &cfg, state, r.ctl.stop_at == LUB_STOP_ENDTIME ? r.ctl.end_time : 0.0,
                    what);
    lubfoam_functions *fos = lubfoam_functions_read(&r);
    lub_dict_finish(r.ctl.dict);

    print_header(&r, load_average, others_running);
    check_limits(&r, &geo);
    lubfoam_check_levels(&r, &geo);
    if (parallel) lubfoam_parallel_setup(&r, fos);
    lub_par_startup_done(); /* from here, a rank's error is its own */
    r.scene.geo = NULL;
    lub_geometry_free(&geo);

    /* a finished run started again (an Allrun run twice): its dictionaries are checked, but
     * it writes nothing (no empty tables under postProcessing/ for this start time) */
    const int nothing_to_run = lub_control_finished(&r.ctl, r.t, 0, r.dt);
    if (nothing_to_run)
        lub_message("lubFoam: the start time %s is at or past endTime %g: nothing to run, "
                    "nothing written (raise endTime in system/controlDict.yaml to continue)",
                    r.start_name, r.ctl.end_time);
    else if (stop_signal)
        lub_message("%s during start-up: stopping before the first step, nothing written",
                    signal_name(stop_signal));
    else if (!dry_run)
        lubfoam_functions_start(fos, &r);
    if (r.parallel) stop_signal = (sig_atomic_t)lub_par_max(stop_signal); /* all stop, or none */
    const int run_loop = !nothing_to_run && !stop_signal && !dry_run;
    if (run_loop) lubfoam_output_init(&r);

    /* The last step is never shortened to land on endTime (as OpenFOAM with a fixed deltaT):
     * the pressure of a step scales as 1/dt^2 through the source of T-9, so a short last
     * step left a last time folder and the last samples of the function objects at several
     * times the pressure of the others.  The run ends at the first step at or after
     * endTime (lub_control_finished), and says so when that is not endTime itself. */
    const int nr = r.scene.nr;
    if (!nothing_to_run && r.ctl.stop_at == LUB_STOP_ENDTIME && !r.ctl.adjust_time_step) {
        const double h = nr * r.dt;
        const double k = ceil((r.ctl.end_time - 1e-3 * r.dt - r.t) / h);
        const double t_last = r.t + k * h;
        if (fabs(t_last - r.ctl.end_time) > 1e-3 * r.dt)
            lub_message("lubFoam: endTime %g is not a whole number of steps of %g s from the "
                        "start time %s: the run ends at the first step after it, t = %.9g "
                        "(%.0f steps; a step is never shortened to land on endTime)",
                        r.ctl.end_time, h, r.start_name, t_last, k * nr);
    }
    if (dry_run) {
        if (r.parallel) report_memory(&r);
        lub_message("lubFoam -dryRun: the dictionaries and the particles of time %s are valid; "
                    "nothing run, nothing written",
                    r.start_name);
        run_free(&r, fos);
        lubfoam_parallel_free(&r);
        return LUB_EXIT_OK;
    }

    /* no progress bar in a parallel run: Open MPI gives the ranks a terminal of its own
     * whatever mpirun's output is (a log file) */
    const int tty = isatty(STDOUT_FILENO) && !r.parallel;
    const double wall0 = lub_wtime();
    r.cpu0 = cpu_seconds();
    long steps = 0, last_write_step = -1;
    double pit_sum = 0, vit_sum = 0, last_bar = 0;
    int warned_courant = 0, warned_isolated = 0, status = LUB_EXIT_OK;

    /* resolution levels with sub-stepping: one pass of the loop is one step of the coarsest
     * level, nr steps of deltaT (dt below) on the finest level (nr: the product of the Nr) */
    while (run_loop && !lub_control_finished(&r.ctl, r.t, steps, r.dt)) {
        double dtc;
        if (r.ctl.adjust_time_step && lub_scene_dt_limit(&r.scene, r.ctl.max_courant, &dtc))
            r.dt = dtc < r.ctl.delta_t ? dtc : r.ctl.delta_t;
        long bad = -1;
        char msg[1024];
        lub_step_status s = lub_scene_before_step(&r.scene, r.t, r.dt, msg, sizeof msg);
        if (s != LUB_STEP_OK) {
            /* nothing has moved: the current state is good, keep it (unless it is the start
             * folder or was just written) */
            if (tty) fputc('\n', stdout);
            if (steps > 0 && r.step != last_write_step) {
                lub_timer_start(run_timers(&r), LUB_T_OUTPUT);
                lubfoam_write(&r, fos);
                lubfoam_functions_write(fos, &r);
                lub_timer_stop(run_timers(&r), LUB_T_OUTPUT);
            }
        }
        if (s == LUB_STEP_OK) s = lub_scene_advance(&r.scene, r.dt, &bad, msg, sizeof msg);
        if (s != LUB_STEP_OK) {
            if (tty) fputc('\n', stdout);
            fflush(stdout);
            if (lubfoam_writer_rank(&r)) { /* -parallel: every rank has the message */
                fprintf(stderr, "lubFoam: error: step %ld (t = %.9g s): %s\n", r.step + nr,
                        r.t + nr * r.dt, msg);
                fprintf(stderr, "lubFoam: the last good state is the newest time folder\n");
            }
            status = LUB_EXIT_RUN;
            break;
        }
        if (nr > 1) {
            r.t += nr * r.dt;
            r.step += nr;
            steps += nr;
        } else {
            r.t += r.dt;
            r.step++;
            steps++;
        }
        lub_scene_after_step(&r.scene, r.t);
        lub_scene_iterations(&r.scene, &pit_sum, &vit_sum); /* every level's every step */
        double umax, co = lub_scene_courant(&r.scene, r.dt, &umax);
        for (int k = 0; k < r.scene.nlevels && !warned_isolated; k++) {
            const lub_mps *mk = r.scene.level[k];
            if (mk->st.nisolated > 0 && lubfoam_writer_rank(&r)) { /* all ranks' count */
                lub_warning("step %ld: %zu particle(s) squeezed into groups that touch no "
                            "surface particle (first: id %llu), where the pressure equation "
                            "(alpha = 0) is singular: taken as surface particles (p = 0), "
                            "now and whenever it happens again (warned once)",
                            r.step, mk->st.nisolated, mk->st.isolated_id);
                warned_isolated = 1;
            }
        }
        if (!r.ctl.adjust_time_step && co > r.ctl.max_courant && !warned_courant &&
            lubfoam_writer_rank(&r)) {
            lub_warning("step %ld: Courant number %.3g exceeds maxCourant %g (u_max %g m/s)",
                        r.step, co, r.ctl.max_courant, umax);
            warned_courant = 1;
        }
        lub_scene_warn(&r.scene, r.step);
        lubfoam_functions_execute(fos, &r);
        int finished = lub_control_finished(&r.ctl, r.t, steps, r.dt);
        int due = 0; /* sub-stepping: a write due at any of the pass's fine steps */
        for (int j = 0; j < nr && !due; j++)
            due = lub_control_write_due(&r.ctl, r.write_origin, r.t - j * r.dt, r.write_origin_step,
                                        r.step - j, r.dt);
        if (r.parallel) { /* a signal to one rank (mpirun forwards them) is every rank's */
            stop_signal = (sig_atomic_t)lub_par_max(stop_signal);
            write_signal = (sig_atomic_t)lub_par_max(write_signal);
        }
        const int write_now = write_signal;
        if (due || finished || stop_signal || write_now) {
            lub_timer_start(run_timers(&r), LUB_T_OUTPUT);
            lubfoam_write(&r, fos);
            lubfoam_functions_write(fos, &r);
            last_write_step = r.step;
            lub_scene_rebuild_lists(&r.scene); /* exact restart from this folder */
            lub_timer_stop(run_timers(&r), LUB_T_OUTPUT);
        }
        if (steps / r.ctl.log_interval != (steps - nr) / r.ctl.log_interval || finished) {
            if (tty) fputc('\r', stdout);
            log_line(&r, steps, wall0, pit_sum);
        } else if (tty && lub_wtime() - last_bar > 0.2) {
            progress_bar(&r, steps, wall0);
            last_bar = lub_wtime();
        }
        if (write_now) {
            write_signal = 0;
            lub_message("Signal %d (%s): state written at t = %.9g, continuing", write_now,
                        signal_name(write_now), r.t);
        }
        if (stop_signal) {
            lub_message("Signal %d (%s): state written at t = %.9g, stopping", (int)stop_signal,
                        signal_name(stop_signal), r.t);
            break;
        }
    }
    if (tty && run_loop) fputc('\n', stdout);
    if (status == LUB_EXIT_OK && !stop_signal && r.ctl.adjust_time_step &&
        r.ctl.stop_at == LUB_STOP_ENDTIME && r.t > r.ctl.end_time + 1e-3 * r.dt)
        lub_message("lubFoam: the last step ended at t = %.9g, %.3g s after endTime %g (a step "
                    "is never shortened to land on endTime)",
                    r.t, r.t - r.ctl.end_time, r.ctl.end_time);
    if (run_loop) write_cost(&r, steps, lub_wtime() - wall0, pit_sum, vit_sum);
    if (run_loop) lub_scene_summary(&r.scene, r.t);
    if (run_loop) lubfoam_output_free(&r);
    run_free(&r, fos);
    lubfoam_parallel_free(&r);
    if (status == LUB_EXIT_OK) lub_message("End");
    return status;
}
