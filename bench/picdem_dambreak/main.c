/* bench/picdem_dambreak: the resolved PIC-DEM dam break through six layers of cylinders (seed 000
   §3.2) at the seed's grid, dx = 0.05 cm, for 0.5 s of physical time, one thread.

   The case is validation/picdem_cylinder_dambreak's (case.h: tank 0.286 m, PIC domain 0.286 x
   0.26 m = 572 x 520 cells, 33 cylinders of 1 cm, water 0.12 m deep behind the pile, beta = 0.5,
   DEM linear law of Table 1 with dt from Eq. 18). The goal is under 2 minutes of wall time.
   Figures (CPU seconds from the solvers' statistics, clock(): the process's CPU time, so other jobs
   on the machine do not inflate them; wall_s is the elapsed time and does include them):
     wall_s          elapsed seconds of the coupled steps (creation excluded)
     fluid_steps     coupled steps (one PIC step each)
     dem_substeps    DEM substeps, total
     cells           PIC grid cells
     particles       water particles at the end
   then the split of the CPU time:
     pressure_s      PIC pressure setup + solve, the coupler's implicit body term included
                     (fsdem_pic_stats.seconds_pressure)
     density_s       the density projection's setup + solve (seconds_density)
     transfers_s     the rest of the PIC steps: P2G/G2P, advection, viscosity, level set,
                     extrapolation, reseeding (seconds_total - pressure - density)
     dem_s           DEM substeps (fsdem_pic_dem_stats.seconds_dem)
     coupling_s      faces, solid velocities, J, fluid forces, Eq. 20, particle exclusion
                     (seconds_coupling)
   The required line is
     BENCH picdem_dambreak wall_s=<s> fluid_steps=<n> dem_substeps=<n> cells=<n> particles=<n>

   Usage: picdem_dambreak [t_end [dx [layers [beta]]]]   defaults 0.5, 0.0005, 6, 0.5
   Build: make build/bench/picdem_dambreak (or make bench). Prints BENCH lines only (no pass/fail);
   a failure prints "BENCH picdem_dambreak error=<code> ..." with the coupler's message. */
#define _POSIX_C_SOURCE 200809L
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include "../../validation/picdem_cylinder_dambreak/case.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv) {
    const double t_end = argc > 1 ? atof(argv[1]) : 0.5, dx = argc > 2 ? atof(argv[2]) : WD_SEED_DX;
    const int layers = argc > 3 ? atoi(argv[3]) : 6;
    const double beta = argc > 4 ? atof(argv[4]) : 0.5;
    wd_case c;
    fsdem_pic_stats ps;
    fsdem_pic_dem_stats cs;
    fsdem_pic_fields g;
    struct rusage usage;
    fsdem_result res = FSDEM_OK;
    double t0, wall, arrival = -1, cpu, transfers;
    long long iterations = 0;
    fsdem_set_threads(1); /* one thread, as the figures in README.md (the threaded benches print speedup_2t) */
    printf("BENCH picdem_dambreak threads=%d ranks=1\n", fsdem_threads());
    if (wd_create(&c, dx, layers, beta) != 0) {
        printf("BENCH picdem_dambreak error=create message=\"%s\"\n", c.error);
        return 1;
    }
    g = fsdem_pic_get_fields(c.pic);
    t0 = now();
    while (fsdem_pic_dem_time(c.cpl) < t_end - 1e-9) {
        if ((res = wd_step_until(&c, t_end)) != FSDEM_OK) break;
        iterations += fsdem_pic_get_stats(c.pic).pressure_iterations;
        if (arrival < 0 && wd_at_right_wall(&c)) arrival = fsdem_pic_dem_time(c.cpl);
    }
    wall = now() - t0;
    ps = fsdem_pic_get_stats(c.pic);
    cs = fsdem_pic_dem_get_stats(c.cpl);
    if (res != FSDEM_OK)
        printf("BENCH picdem_dambreak error=%d t=%.5f step=%lld message=\"%s\"\n", (int)res, cs.coupling.time, cs.coupling.steps, wd_last_error(&c));
    transfers = ps.seconds_total - ps.seconds_pressure - ps.seconds_density;
    cpu = ps.seconds_total + cs.coupling.seconds_dem + cs.coupling.seconds_coupling;
    printf("BENCH picdem_dambreak wall_s=%.2f fluid_steps=%lld dem_substeps=%lld cells=%d particles=%d\n", wall, cs.coupling.steps,
           cs.coupling.substeps_total, g.n[0] * g.n[1], ps.particles);
    printf("BENCH picdem_dambreak split cpu_s=%.2f pressure_s=%.2f density_s=%.2f transfers_s=%.2f dem_s=%.2f coupling_s=%.2f\n", cpu,
           ps.seconds_pressure, ps.seconds_density, transfers, cs.coupling.seconds_dem, cs.coupling.seconds_coupling);
    printf("BENCH picdem_dambreak share pressure=%.1f %% density=%.1f %% transfers=%.1f %% dem=%.1f %% coupling=%.1f %%\n",
           100 * ps.seconds_pressure / cpu, 100 * ps.seconds_density / cpu, 100 * transfers / cpu, 100 * cs.coupling.seconds_dem / cpu,
           100 * cs.coupling.seconds_coupling / cpu);
    printf("BENCH picdem_dambreak t_end=%.4g s dx=%.4g m layers=%d cylinders=%d beta=%.2g mean_dt=%.4g s dem_dt=%.4g s "
           "substeps_per_step=%.1f pressure_iterations_mean=%.1f\n",
           cs.coupling.time, dx, layers, c.cylinders, beta, cs.coupling.steps ? cs.coupling.time / (double)cs.coupling.steps : 0.0, c.dem_dt,
           cs.coupling.steps ? (double)cs.coupling.substeps_total / (double)cs.coupling.steps : 0.0, cs.coupling.steps ? (double)iterations / (double)cs.coupling.steps : 0.0);
    printf("BENCH picdem_dambreak arrival_s=%.4f goal_wall_s=120 %s\n", arrival, wall <= 120 ? "met" : "not_met");
    printf("BENCH picdem_dambreak pic_memory_bytes=%zu\n", ps.memory_bytes);
    getrusage(RUSAGE_SELF, &usage);
    printf("BENCH picdem_dambreak peak_rss=%ld KiB\n", (long)usage.ru_maxrss);
    fflush(stdout);
    wd_destroy(&c);
    return res == FSDEM_OK ? 0 : 1;
}
