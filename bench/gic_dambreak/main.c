/* bench/gic_dambreak: the Granule-In-Cell dam break of seed 004 (Fig. 15, Table 1 "Dam Breaking")
   scaled to this machine, one thread: the throughput in water-particle steps per second against
   Table 1's.

   Table 1's run: a 192 x 192 x 128 grid, 2.2e5 granules, 9.7e6 water particles, 10.94 s per fluid
   step on 80 cores (AMD EPYC 9K84), i.e. 9.7e6 / 10.94 / 80 = 1.1e4 water-particle steps per
   second per core (the Big Ball's figure too). The goal (issue 38) is at least 20 times that per
   core. The seed gives neither the tank's size nor the dam's: this bench ASSUMES a grid a quarter of
   Table 1's along every axis, 48 x 48 x 32 cells of dx = 1 cm (1/64 of its cells), a water wall
   0.16 m long, 0.24 m high and the tank's width at x = 0, 8 particles per cell (1/64 of Table 1's
   water: 1.47e5 particles), and a sand dam 0.08 m long and 0.06 m high across the tank from
   x = 0.28 m, granules of radius 4 mm on a cubic lattice of spacing 2.1 r (3,990 granules, 1/55 of
   Table 1's), seed 004's contact law and material (E = 1e6 Pa, 2500 kg/m^3, friction 0.5) at the
   DEM's stable step, and the library's defaults otherwise (quadratic drag Eq. 5b, density
   projection). The fluid steps are the coupler's stable ones to t_end.
   Figures (CPU seconds from the solvers' statistics, clock(); wall_s elapsed):
     s_per_step        wall seconds per coupled (fluid) step
     water_particles   PIC particles at the end
     granules          DEM particles
     cells             PIC grid cells
     sand_substeps     DEM substeps per coupled step, mean
     particle_steps_per_s_per_core  water particles x steps / wall seconds (one core)
     table1_ratio      that over Table 1's 1.1e4 (the goal: >= 20)
   then the split of the CPU time: sand (the DEM substeps with their force evaluations), density
   projection (fsdem_pic_stats.seconds_density), pressure (seconds_pressure), the rest of the PIC
   step and the coupler's own work (fractions, limits).
   The required line is
     BENCH gic_dambreak s_per_step=<s> water_particles=<n> granules=<n> cells=<n> sand_substeps=<n>

   Usage: gic_dambreak [t_end]   default 0.25 s (the water reaches the dam at about 0.2 s)
   Build: make build/bench/gic_dambreak (or make bench). Prints BENCH lines only (no pass/fail); a
   failure prints "BENCH gic_dambreak error=<code> ..." with the coupler's message. */
#define _POSIX_C_SOURCE 200809L
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>

#define DX 0.01      /* m, cells */
#define RADIUS 0.004 /* m, granules */
#define TABLE1_RATE 1.1e4 /* water-particle steps per second per core of seed 004 Table 1 */

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv) {
    const double t_end = argc > 1 ? atof(argv[1]) : 0.25, s = 2.1 * RADIUS;
    const fsdem_vec3 lo = fsdem_v3(0, 0, 0), hi = fsdem_v3((fsdem_real)(48 * DX), (fsdem_real)(48 * DX), (fsdem_real)(32 * DX));
    fsdem_pic_desc pd = fsdem_pic_desc_default(3);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_gic_desc gd = fsdem_gic_desc_default();
    fsdem_dem_material sand = fsdem_dem_material_default();
    fsdem_pic *pic = NULL;
    fsdem_dem *dem = NULL;
    fsdem_gic *gic = NULL;
    fsdem_gic_stats gs;
    fsdem_pic_stats ps;
    fsdem_real dem_dt = 0;
    fsdem_result res = FSDEM_OK;
    struct rusage usage;
    double t0, wall, cpu, rest, rate;
    long long steps;
    int i, j, k, status = 1;
    fsdem_set_threads(1); /* one thread, as the figures in README.md */
    printf("BENCH gic_dambreak threads=%d ranks=1\n", fsdem_threads());

    dd.domain_min = lo;
    dd.domain_max = hi;
    dd.law = FSDEM_DEM_LAW_GIC;
    dd.rotation = 0;
    sand.density = 2500;
    sand.young_modulus = 1e6;
    sand.friction = (fsdem_real)0.5;
    if (fsdem_dem_create(&dd, &dem) != FSDEM_OK || fsdem_dem_add_material(dem, &sand, NULL) != FSDEM_OK) goto failed_create;
    {
        const fsdem_dem_wall_desc box = fsdem_dem_wall_box(lo, hi, 1, 0);
        if (fsdem_dem_add_wall(dem, &box, NULL) != FSDEM_OK) goto failed_create;
    }
    for (k = 0; (k + 0.5) * s < 0.06; ++k)
        for (j = 0; (j + 1) * s < (double)hi.y; ++j)
            for (i = 0; (i + 0.5) * s < 0.08; ++i) {
                fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
                p.radius = (fsdem_real)RADIUS;
                p.position = fsdem_v3((fsdem_real)(0.28 + (i + 0.5) * s), (fsdem_real)((j + 1) * s), (fsdem_real)((k + 0.5) * s));
                if (fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK) goto failed_create;
            }
    if (fsdem_dem_stable_dt(dem, &dem_dt) != FSDEM_OK || fsdem_dem_set_dt(dem, dem_dt) != FSDEM_OK) goto failed_create;

    pd.cell_size = (fsdem_real)DX;
    pd.domain_max = hi;
    if (fsdem_pic_create(&pd, &pic) != FSDEM_OK ||
        fsdem_pic_fill_box(pic, lo, fsdem_v3((fsdem_real)0.16, hi.y, (fsdem_real)0.24), fsdem_v3(0, 0, 0), NULL) != FSDEM_OK)
        goto failed_create;
    gd.pic = pic;
    gd.dem = dem;
    if (fsdem_gic_create(&gd, &gic) != FSDEM_OK || fsdem_gic_update(gic) != FSDEM_OK) goto failed_create;

    t0 = now();
    res = fsdem_gic_advance(gic, (fsdem_real)t_end, NULL);
    wall = now() - t0;
    gs = fsdem_gic_get_stats(gic);
    ps = fsdem_pic_get_stats(pic);
    steps = gs.coupling.steps;
    if (res != FSDEM_OK)
        printf("BENCH gic_dambreak error=%d t=%.5f step=%lld message=\"%s\"\n", (int)res, gs.coupling.time, steps, fsdem_gic_last_error(gic));
    rate = wall > 0 ? (double)ps.particles * (double)steps / wall : 0;
    printf("BENCH gic_dambreak s_per_step=%.4f water_particles=%d granules=%d cells=%d sand_substeps=%.1f\n", steps ? wall / (double)steps : 0.0,
           ps.particles, fsdem_dem_get_particles(dem).count, 48 * 48 * 32, steps ? (double)gs.coupling.substeps_total / (double)steps : 0.0);
    printf("BENCH gic_dambreak particle_steps_per_s_per_core=%.4g table1_ratio=%.1f goal_ratio=20 %s\n", rate, rate / TABLE1_RATE,
           rate >= 20 * TABLE1_RATE ? "met" : "not_met");
    cpu = gs.coupling.seconds_fluid + gs.coupling.seconds_dem + gs.coupling.seconds_coupling;
    rest = gs.coupling.seconds_fluid - ps.seconds_density - ps.seconds_pressure;
    printf("BENCH gic_dambreak split cpu_s=%.2f sand_s=%.2f density_s=%.2f pressure_s=%.2f pic_rest_s=%.2f coupling_s=%.2f\n", cpu,
           gs.coupling.seconds_dem, ps.seconds_density, ps.seconds_pressure, rest, gs.coupling.seconds_coupling);
    if (cpu > 0)
        printf("BENCH gic_dambreak share sand=%.1f %% density=%.1f %% pressure=%.1f %% pic_rest=%.1f %% coupling=%.1f %%\n",
               100 * gs.coupling.seconds_dem / cpu, 100 * ps.seconds_density / cpu, 100 * ps.seconds_pressure / cpu, 100 * rest / cpu,
               100 * gs.coupling.seconds_coupling / cpu);
    printf("BENCH gic_dambreak t_end=%.4g s steps=%lld mean_dt=%.4g s dem_dt=%.4g s max_solid_fraction=%.3f fluid_volume=%.6g m3\n",
           gs.coupling.time, steps, steps ? gs.coupling.time / (double)steps : 0.0, (double)dem_dt, (double)gs.max_solid_fraction,
           (double)ps.fluid_volume);
    getrusage(RUSAGE_SELF, &usage);
    printf("BENCH gic_dambreak peak_rss=%ld KiB\n", (long)usage.ru_maxrss);
    status = res == FSDEM_OK ? 0 : 1;
    goto done;
failed_create:
    printf("BENCH gic_dambreak error=create message=\"%s\"\n",
           gic ? fsdem_gic_last_error(gic) : pic ? fsdem_pic_last_error(pic) : dem ? fsdem_dem_last_error(dem) : "create failed");
done:
    fsdem_gic_destroy(gic);
    fsdem_pic_destroy(pic);
    fsdem_dem_destroy(dem);
    return status;
}
