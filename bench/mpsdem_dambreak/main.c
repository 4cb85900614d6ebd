/* bench/mpsdem_dambreak: seconds per coupled step of the MPS-DEM liquid-solid dam break of seed 002
   §3.2 at d_p = 0.0027 m, against the seed's Table 2 (Model B: 1.83128 s for the MPS part and
   3.25171 s for the DEM and coupling parts per MPS step at d_p = 0.0027 m).

   The case is validation/mpsdem_dambreak's (case.h: tank 0.2 x 0.1 x 0.15 m, water column 0.05 x
   0.1 x 0.1 m, a bed of 7128 spheres of 2.7 mm at the bottom of the column; the column and bed sizes
   are assumptions, README.md), Model B, MPS spacing r0 = d_p = 0.0027 m, one thread. `warmup`
   coupled steps are taken first (lists and matrices reach their size, pages are touched; the
   flow starts), then `steps` timed ones. The figures are CPU seconds from fsdem_mps_dem_get_stats
   (clock(): the process's CPU time, so other jobs on the machine do not inflate them):
     mps_s_per_step             seconds_mps / step: MPS steps (neighbours, predictor, pressure
                                equation, corrector, collisions)
     dem_coupling_s_per_step    seconds_dem / step: porosity, averages and forces of the coupler,
                                and the DEM substeps
     particles                  MPS particles of all kinds (FLUID + WALL + DUMMY)
     dem                        DEM particles
   The required line is
     BENCH mpsdem_dambreak mps_s_per_step=<s> dem_coupling_s_per_step=<s> particles=<n> dem=<n>
   followed by detail lines: the split of the particles, dt and DEM substeps per step, PCG
   iterations, the share of the MPS time in its pressure equation, wall time per step, the ratios to
   Table 2 and the goal (each part at least 20 times faster than Table 2).

   Usage: mpsdem_dambreak [steps [warmup [r0]]]   defaults 30, 5, 0.0027
   Build: make build/bench/mpsdem_dambreak (or make bench). Prints BENCH lines only (no pass/fail);
   a failure prints "BENCH mpsdem_dambreak error=<code> ..." with fsdem_mps_dem_last_error. */
#define _POSIX_C_SOURCE 200809L
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include "../../validation/mpsdem_dambreak/case.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>

#define TABLE2_MPS 1.83128
#define TABLE2_DEM 3.25171

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv) {
    const int steps = argc > 1 ? atoi(argv[1]) : 30, warmup = argc > 2 ? atoi(argv[2]) : 5;
    const double r0 = argc > 3 ? atof(argv[3]) : 0.0027;
    sd_case c;
    fsdem_mps_dem_stats s0, s1;
    fsdem_mps_stats m0, m1;
    fsdem_result res = FSDEM_OK;
    struct rusage usage;
    double t0, wall, mps, dem;
    int k, done = 0;
    fsdem_set_threads(1); /* one thread, as the figures in README.md (the threaded benches print speedup_2t) */
    printf("BENCH mpsdem_dambreak threads=%d ranks=1\n", fsdem_threads());
    if (sd_create(&c, r0, FSDEM_MPS_MODEL_B, 1) != 0) {
        printf("BENCH mpsdem_dambreak error=create message=\"%s\"\n", c.error);
        return 1;
    }
    for (k = 0; k < warmup && res == FSDEM_OK; ++k) res = fsdem_mps_dem_step(c.cpl);
    s0 = fsdem_mps_dem_get_stats(c.cpl);
    m0 = fsdem_mps_get_stats(c.mps);
    t0 = now();
    for (k = 0; k < steps && res == FSDEM_OK; ++k)
        if ((res = fsdem_mps_dem_step(c.cpl)) == FSDEM_OK) done++;
    wall = now() - t0;
    s1 = fsdem_mps_dem_get_stats(c.cpl);
    m1 = fsdem_mps_get_stats(c.mps);
    if (res != FSDEM_OK) {
        printf("BENCH mpsdem_dambreak error=%d t=%.5f step=%lld message=\"%s\"\n", (int)res, s1.coupling.time, s1.coupling.steps, sd_last_error(&c));
        if (done == 0) {
            sd_destroy(&c);
            return 1;
        }
    }
    mps = (s1.coupling.seconds_fluid - s0.coupling.seconds_fluid) / done;
    dem = (s1.coupling.seconds_dem + s1.coupling.seconds_coupling - s0.coupling.seconds_dem - s0.coupling.seconds_coupling) / done;
    printf("BENCH mpsdem_dambreak mps_s_per_step=%.4g dem_coupling_s_per_step=%.4g particles=%d dem=%d\n", mps, dem,
           m1.fluid + m1.wall + m1.dummy, c.spheres);
    printf("BENCH mpsdem_dambreak r0=%.4g m model=B warmup_steps=%d timed_steps=%d t_start=%.5f s t_end=%.5f s\n", r0, warmup, done,
           s0.coupling.time, s1.coupling.time);
    printf("BENCH mpsdem_dambreak particles fluid=%d wall=%d dummy=%d spheres=%d\n", m1.fluid, m1.wall, m1.dummy, c.spheres);
    printf("BENCH mpsdem_dambreak mean_dt=%.4g s dem_dt=%.4g s substeps_per_step=%.1f dem_mps_pairs=%lld\n",
           (s1.coupling.time - s0.coupling.time) / done, c.dem_dt, (double)(s1.coupling.substeps_total - s0.coupling.substeps_total) / done, s1.pairs);
    printf("BENCH mpsdem_dambreak pressure_iterations_mean=%.1f pressure_share_of_mps=%.1f %% neighbour_pairs=%lld\n",
           (double)(m1.pressure_iterations_total - m0.pressure_iterations_total) / done,
           m1.seconds_total > m0.seconds_total
               ? 100 * (m1.seconds_pressure - m0.seconds_pressure) / (m1.seconds_total - m0.seconds_total)
               : 0.0,
           m1.neighbours);
    printf("BENCH mpsdem_dambreak wall_s_per_step=%.4g cpu_s_per_step=%.4g\n", wall / done, mps + dem);
    printf("BENCH mpsdem_dambreak table2_mps_s_per_step=%.5f speedup_mps=%.1f goal=20 %s\n", TABLE2_MPS, TABLE2_MPS / mps,
           TABLE2_MPS / mps >= 20 ? "met" : "not_met");
    printf("BENCH mpsdem_dambreak table2_dem_coupling_s_per_step=%.5f speedup_dem_coupling=%.1f goal=20 %s\n", TABLE2_DEM,
           TABLE2_DEM / dem, TABLE2_DEM / dem >= 20 ? "met" : "not_met");
    printf("BENCH mpsdem_dambreak mps_memory_bytes=%zu\n", m1.memory_bytes);
    getrusage(RUSAGE_SELF, &usage);
    printf("BENCH mpsdem_dambreak peak_rss=%ld KiB\n", (long)usage.ru_maxrss);
    fflush(stdout);
    sd_destroy(&c);
    return 0;
}
