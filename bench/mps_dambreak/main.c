/* bench/mps_dambreak: MPS (fsdem_mps_*) wall time to a physical time, side by side with PySPH.

   Case 1, "mps_dambreak" (issue 11): the PySPH example dam_break_2d (pysph.examples.dam_break_2d,
   Gomez-Gesteira et al. 2010) in 2D MPS. Tank inside [0, 4] x [0, 4] m, open at the top (walls by
   fsdem_mps_add_box_walls: one WALL layer and the DUMMY layers of the scheme's re outside the
   box); water column [0, 1] x [0, 2] m at the left wall (fsdem_mps_fill_box: 67 x 133 = 8,911
   FLUID particles at r0 = 0.015 m). Everything else is fsdem_mps_desc_default(2): the explicit
   scheme (re = 2.8 r0, c0 = 10 sqrt(2 g H), cfl 0.35 on c0 + u_max, density diffusion 0.1,
   negative pressures kept), then seed 002's scheme with its defaults as "mps_dambreak_seed"
   (fsdem_mps_desc_default_scheme: re = 4.1 r0, gamma = 0.01, beta = 0.8, alpha = 0.9, CFL 0.2 with
   adaptive dt, min-form gradient, MIC(0)-PCG to 1e-8, negative pressures clamped); both with
   collisions at 0.8 r0, no shifting, dt_max 1e-3 s. The domain is
   [-0.1, 4.1] x [-0.1, 6] m. Simulated to t = 0.6 s in 0.1 s chunks by fsdem_mps_advance (each chunk ends exactly
   on its time, so the fronts at 0.4 and 0.6 s are at those times), single thread.
   Figures: wall_s = wall-clock seconds of the stepping (creation and filling excluded, as PySPH's
   "Run took"), steps = MPS steps to 0.6 s, particle_steps_per_s = FLUID particles x steps / wall_s,
   front_t0.4 and front_t0.6 = the largest x of a FLUID particle at t = 0.4 and 0.6 s (m).
   The required line is
     BENCH mps_dambreak wall_s=<s> steps=<n> particle_steps_per_s=<v> front_t0.4=<m> front_t0.6=<m>
   followed by detail lines (particle counts, the front every 0.1 s, dt, PCG iterations, the share
   of CPU time in the pressure equation, fluid particles found outside the tank, memory).
   The PySPH side is in pysph/ (run_pysph.sh); README.md has both and the results.

   Case 2, "mps_sun2013_3d": time per MPS step at the resolution of seed 002 Table 2 (d_p = 0.0027
   m: 1.83 s per step for the MPS part of MPS-DEM on the Sun et al. (2013) tank). The seed gives
   the container (0.2 m long, 0.1 m wide, 0.15 m high) but neither the water column nor a particle
   count; this bench ASSUMES a water column 0.05 m long x 0.1 m wide x 0.1 m high at the left
   wall (override: arguments 3 and 4) in that container (walls as in case 1, open top), 3D,
   the seed's scheme, defaults otherwise, r0 = 0.0027 m. It is a 3D dam break: one untimed step
   (list growth and first touch), then `steps_3d` timed steps from rest; time per step = wall time
   / steps.
   The particle counts of each kind are printed: compare with the count of the seed's case when
   it is known.

   Usage: mps_dambreak [t_end [steps_3d [column_length_3d column_height_3d]]]
          defaults 0.6 s, 5 steps, 0.05 m, 0.1 m; t_end 0 or steps_3d 0 skips a case.
   Build: make build/bench/mps_dambreak (or make bench). Prints BENCH lines only (no pass/fail);
   a failure prints "BENCH <case> error=<code> ..." with the time, step and fsdem_mps_last_error. */
#define _POSIX_C_SOURCE 200809L
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Largest x of a FLUID particle (m). */
static double front(fsdem_mps *mps) {
    fsdem_mps_particles p = fsdem_mps_get_particles(mps);
    double x = -1e30;
    int i;
    for (i = 0; i < p.count; ++i)
        if (p.kind[i] == FSDEM_MPS_KIND_FLUID && (double)p.position[i].x > x) x = (double)p.position[i].x;
    return x;
}

/* FLUID particles outside the tank's inside [lo, hi] (open top: no upper bound on the last axis). */
static int outside_tank(fsdem_mps *mps, fsdem_vec3 lo, fsdem_vec3 hi) {
    fsdem_mps_particles p = fsdem_mps_get_particles(mps);
    int i, n = 0;
    for (i = 0; i < p.count; ++i) {
        fsdem_vec3 r = p.position[i];
        if (p.kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        if (r.x < lo.x || r.x > hi.x || r.y < lo.y) ++n;
        else if (p.dim == 2 ? 0 : (r.y > hi.y || r.z < lo.z)) ++n;
    }
    return n;
}

/* The split of the steps' CPU time (since `before`, when given) and the pairs of the last search. */
static void print_split(const char *name, const fsdem_mps_stats *st, const fsdem_mps_stats *before) {
    const double total = st->seconds_total - (before ? before->seconds_total : 0);
    const double search = st->seconds_search - (before ? before->seconds_search : 0);
    const double assembly = st->seconds_assembly - (before ? before->seconds_assembly : 0);
    const double solve = st->seconds_solve - (before ? before->seconds_solve : 0);
    if (!(total > 0)) return;
    printf("BENCH %s split search=%.1f%% operators=%.1f%% assembly=%.1f%% solve=%.1f%%\n", name, 100 * search / total,
           100 * (total - search - assembly - solve) / total, 100 * assembly / total, 100 * solve / total);
    printf("BENCH %s pairs candidates=%lld kept=%lld (%.1f%%)\n", name, st->candidate_pairs, st->neighbours,
           st->candidate_pairs > 0 ? 100.0 * (double)st->neighbours / (double)st->candidate_pairs : 0.0);
}

static void report_error(const char *name, fsdem_mps *mps, const char *what, fsdem_result r) {
    if (mps) {
        fsdem_mps_stats st = fsdem_mps_get_stats(mps);
        printf("BENCH %s error=%d at=%s t=%.6f step=%lld dt=%.3g max_speed=%.4g message=\"%s\"\n", name,
               (int)r, what, st.time, st.steps, (double)st.dt, (double)st.max_speed, fsdem_mps_last_error(mps));
    } else {
        printf("BENCH %s error=%d at=%s\n", name, (int)r, what);
    }
    fflush(stdout);
}

/* Case 1: the PySPH dam_break_2d case to t_end with `scheme`, its lines named `name`. */
static void bench_2d(double t_end, fsdem_mps_scheme scheme, const char *name) {
    const fsdem_vec3 tank_lo = fsdem_v3(0, 0, 0), tank_hi = fsdem_v3(4, 4, 0);
    fsdem_mps_desc d = fsdem_mps_desc_default_scheme(2, scheme);
    fsdem_mps *mps = NULL;
    fsdem_mps_stats st;
    fsdem_result r;
    struct rusage usage;
    double wall = 0, f04 = -1, f06 = -1, fronts[64], times[64], t0;
    long long steps = 0;
    int added_fluid = 0, added_walls = 0, nf = 0, k;

    d.r0 = (fsdem_real)0.015;
    d.domain_min = fsdem_v3(-0.1, -0.1, 0);
    d.domain_max = fsdem_v3(4.1, 6, 0);
    r = fsdem_mps_create(&d, &mps);
    if (r != FSDEM_OK) {
        report_error(name, NULL, "create", r);
        return;
    }
    r = fsdem_mps_fill_box(mps, fsdem_v3(0, 0, 0), fsdem_v3(1, 2, 0), fsdem_v3(0, 0, 0), &added_fluid);
    if (r != FSDEM_OK) {
        report_error(name, mps, "fill_box", r);
        fsdem_mps_destroy(mps);
        return;
    }
    r = fsdem_mps_add_box_walls(mps, tank_lo, tank_hi, 1u << FSDEM_SIDE_YMAX, &added_walls);
    if (r != FSDEM_OK) {
        report_error(name, mps, "add_box_walls", r);
        fsdem_mps_destroy(mps);
        return;
    }

    t0 = now();
    for (k = 1;; ++k) {
        double target = (double)k * 0.1 < t_end ? (double)k * 0.1 : t_end;
        long long n = 0;
        r = fsdem_mps_advance(mps, (fsdem_real)(target - fsdem_mps_time(mps)), &n);
        steps += n;
        if (r != FSDEM_OK) break;
        if (nf < 64) {
            times[nf] = fsdem_mps_time(mps);
            fronts[nf++] = front(mps);
        }
        if (target >= t_end) break;
    }
    wall = now() - t0;
    st = fsdem_mps_get_stats(mps);
    for (k = 0; k < nf; ++k) {
        if (times[k] > 0.4 - 1e-9 && times[k] < 0.4 + 1e-9) f04 = fronts[k];
        if (times[k] > 0.6 - 1e-9 && times[k] < 0.6 + 1e-9) f06 = fronts[k];
    }
    if (r != FSDEM_OK) {
        report_error(name, mps, "advance", r);
        printf("BENCH %s partial wall_s=%.3f steps=%lld front=%.4f m\n", name, wall, st.steps, front(mps));
    } else {
        printf("BENCH %s wall_s=%.3f steps=%lld particle_steps_per_s=%.4g front_t0.4=%.4f front_t0.6=%.4f\n", name,
               wall, st.steps, (double)st.fluid * (double)st.steps / wall, f04, f06);
    }
    printf("BENCH %s particles fluid=%d wall=%d dummy=%d\n", name, st.fluid, st.wall, st.dummy);
    for (k = 0; k < nf; ++k) printf("BENCH %s front t=%.3f x=%.4f m\n", name, times[k], fronts[k]);
    printf("BENCH %s simulated_time=%.4f s\n", name, st.time);
    printf("BENCH %s mean_dt=%.4g s\n", name, st.steps > 0 ? st.time / (double)st.steps : 0.0);
    printf("BENCH %s step_time=%.4g s\n", name, st.steps > 0 ? wall / (double)st.steps : 0.0);
    printf("BENCH %s pressure_iterations_mean=%.2f 1\n", name,
           st.steps > 0 ? (double)st.pressure_iterations_total / (double)st.steps : 0.0);
    printf("BENCH %s pressure_share=%.1f %%\n", name,
           st.seconds_total > 0 ? 100 * st.seconds_pressure / st.seconds_total : 0.0);
    print_split(name, &st, NULL);
    printf("BENCH %s max_speed=%.4g m/s\n", name, (double)st.max_speed);
    printf("BENCH %s fluid_outside_tank=%d 1\n", name, outside_tank(mps, tank_lo, tank_hi));
    printf("BENCH %s memory_bytes=%zu B\n", name, st.memory_bytes);
    getrusage(RUSAGE_SELF, &usage);
    printf("BENCH %s peak_rss=%ld KiB\n", name, (long)usage.ru_maxrss);
    fflush(stdout);
    fsdem_mps_destroy(mps);
}

/* Case 2: time per step of a 3D dam break in the Sun (2013) container at d_p = 0.0027 m. */
static void bench_3d(int steps, double column_length, double column_height) {
    const char *name = "mps_sun2013_3d";
    const fsdem_vec3 tank_lo = fsdem_v3(0, 0, 0), tank_hi = fsdem_v3(0.2, 0.1, 0.15);
    fsdem_mps_desc d = fsdem_mps_desc_default_scheme(3, FSDEM_MPS_SCHEME_SEMI_IMPLICIT); /* Table 2 is the seed's */
    fsdem_mps *mps = NULL;
    fsdem_mps_stats st0, st;
    fsdem_result r;
    struct rusage usage;
    double t0, wall;
    int added_fluid = 0, added_walls = 0, k;

    d.r0 = (fsdem_real)0.0027;
    d.domain_min = fsdem_v3(-0.02, -0.02, -0.02);
    d.domain_max = fsdem_v3(0.22, 0.12, 0.3);
    r = fsdem_mps_create(&d, &mps);
    if (r != FSDEM_OK) {
        report_error(name, NULL, "create", r);
        return;
    }
    r = fsdem_mps_fill_box(mps, fsdem_v3(0, 0, 0), fsdem_v3(column_length, 0.1, column_height), fsdem_v3(0, 0, 0),
                           &added_fluid);
    if (r != FSDEM_OK) {
        report_error(name, mps, "fill_box", r);
        fsdem_mps_destroy(mps);
        return;
    }
    r = fsdem_mps_add_box_walls(mps, tank_lo, tank_hi, 1u << FSDEM_SIDE_ZMAX, &added_walls);
    if (r != FSDEM_OK) {
        report_error(name, mps, "add_box_walls", r);
        fsdem_mps_destroy(mps);
        return;
    }
    /* one untimed step: the neighbour list and matrix reach their size, pages are touched */
    r = fsdem_mps_step(mps);
    if (r != FSDEM_OK) {
        report_error(name, mps, "first step", r);
        fsdem_mps_destroy(mps);
        return;
    }
    st0 = fsdem_mps_get_stats(mps);
    t0 = now();
    for (k = 0; k < steps; ++k) {
        r = fsdem_mps_step(mps);
        if (r != FSDEM_OK) break;
    }
    wall = now() - t0;
    st = fsdem_mps_get_stats(mps);
    if (r != FSDEM_OK) report_error(name, mps, "step", r);
    printf("BENCH %s column=%.4gx0.1x%.4g m r0=0.0027 m\n", name, column_length, column_height);
    printf("BENCH %s particles fluid=%d wall=%d dummy=%d total=%d\n", name, st.fluid, st.wall, st.dummy,
           st.fluid + st.wall + st.dummy);
    printf("BENCH %s pressure_unknowns=%d 1\n", name, st.unknowns);
    printf("BENCH %s neighbour_pairs=%lld 1\n", name, st.neighbours);
    printf("BENCH %s steps=%d 1\n", name, k);
    printf("BENCH %s step_time=%.4g s\n", name, k > 0 ? wall / k : 0.0);
    printf("BENCH %s seed002_table2_mps_step_time=1.83128 s\n", name);
    printf("BENCH %s pressure_iterations_mean=%.2f 1\n", name,
           k > 0 ? (double)(st.pressure_iterations_total - st0.pressure_iterations_total) / k : 0.0);
    printf("BENCH %s pressure_share=%.1f %%\n", name,
           st.seconds_total > st0.seconds_total
               ? 100 * (st.seconds_pressure - st0.seconds_pressure) / (st.seconds_total - st0.seconds_total)
               : 0.0);
    print_split(name, &st, &st0);
    printf("BENCH %s memory_bytes=%zu B\n", name, st.memory_bytes);
    getrusage(RUSAGE_SELF, &usage);
    printf("BENCH %s peak_rss=%ld KiB\n", name, (long)usage.ru_maxrss);
    (void)tank_lo;
    fflush(stdout);
    fsdem_mps_destroy(mps);
}

int main(int argc, char **argv) {
    double t_end = argc > 1 ? atof(argv[1]) : 0.6;
    int steps3 = argc > 2 ? atoi(argv[2]) : 5;
    double cl = argc > 3 ? atof(argv[3]) : 0.05, ch = argc > 4 ? atof(argv[4]) : 0.1;
    fsdem_set_threads(1); /* one thread, as the figures in README.md (the threaded benches print speedup_2t) */
    printf("BENCH mps_dambreak threads=%d ranks=1\n", fsdem_threads());
    if (t_end > 0) {
        bench_2d(t_end, fsdem_mps_desc_default(2).scheme, "mps_dambreak");    /* the default: the explicit scheme */
        bench_2d(t_end, FSDEM_MPS_SCHEME_SEMI_IMPLICIT, "mps_dambreak_seed"); /* seed 002's, beside it */
    }
    if (steps3 > 0) bench_3d(steps3, cl, ch);
    return 0;
}
