/* bench/pic_dambreak: PIC/FLIP throughput on a dam break.
   2D: 512 x 256 cells (tank 4 m x 2 m, dx = 1/128 m), water column 1.6 m x 1.6 m, 4 particles per cell.
   3D: 128 x 64 x 64 cells (tank 4 x 2 x 2 m, dx = 1/32 m), column 1.6 m long across the full width,
   1.6 m high, 8 particles per cell. FLIP 0.97, linear kernel, RK2, density projection, multigrid PCG
   (tolerance 1e-8 relative), adaptive dt at CFL 1; on one thread, then on two (speedup_2t: only the
   pressure solves are threaded so far). The shares are of CPU time, which two threads both count.
   Usage: pic_dambreak [steps_2d [steps_3d]]   (defaults 200 and 40; 0 skips a case)
   Prints BENCH lines only (no pass/fail): particle-steps per second over the timed steps, the share
   of CPU time in the pressure solve (setup + iterations) and in the density projection's solve,
   memory held and peak RSS. */
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

/* The dam break on `threads` threads; returns particle steps per second. */
static double bench(int dim, int steps, int threads) {
    const char *name = dim == 2 ? (threads > 1 ? "pic_dambreak_2d_2t" : "pic_dambreak_2d") : (threads > 1 ? "pic_dambreak_3d_2t" : "pic_dambreak_3d");
    fsdem_pic_desc d = fsdem_pic_desc_default(dim);
    fsdem_pic *s;
    fsdem_pic_stats st0, st;
    struct rusage usage;
    double t0, wall, particle_steps = 0, cpu_p0, cpu_d0;
    long long iters = 0;
    int k, added;
    fsdem_set_threads(threads);
    d.cell_size = dim == 2 ? (fsdem_real)(1.0 / 128) : (fsdem_real)(1.0 / 32);
    d.domain_max = dim == 2 ? fsdem_v3(4, 2, 0) : fsdem_v3(4, 2, 2);
    if (fsdem_pic_create(&d, &s) != FSDEM_OK) {
        printf("BENCH %s create_failed=1 1\n", name);
        return 0;
    }
    fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), dim == 2 ? fsdem_v3(1.6, 1.6, 0) : fsdem_v3(1.6, 2, 1.6), fsdem_v3(0, 0, 0), &added);
    /* one untimed step: first-touch of the grid arrays */
    fsdem_pic_step(s);
    st0 = fsdem_pic_get_stats(s);
    cpu_p0 = st0.seconds_pressure;
    cpu_d0 = st0.seconds_density;
    t0 = now();
    for (k = 0; k < steps; ++k) {
        int np = fsdem_pic_get_stats(s).particles;
        fsdem_result r = fsdem_pic_step(s);
        particle_steps += np;
        iters += fsdem_pic_get_stats(s).pressure_iterations;
        if (r != FSDEM_OK) {
            printf("BENCH %s step_error=%d 1\n", name, (int)r);
            break;
        }
    }
    wall = now() - t0;
    st = fsdem_pic_get_stats(s);
    getrusage(RUSAGE_SELF, &usage);
    printf("BENCH %s threads=%d ranks=1\n", name, fsdem_threads());
    printf("BENCH %s cells=%d 1\n", name, dim == 2 ? 512 * 256 : 128 * 64 * 64);
    printf("BENCH %s particles=%d 1\n", name, st.particles);
    printf("BENCH %s steps=%d 1\n", name, k);
    printf("BENCH %s simulated_time=%.4g s\n", name, (double)(st.time - st0.time));
    printf("BENCH %s wall_time=%.3f s\n", name, wall);
    printf("BENCH %s particle_steps_per_s=%.4g 1/s\n", name, particle_steps / wall);
    printf("BENCH %s step_time=%.4g s\n", name, wall / (k > 0 ? k : 1));
    printf("BENCH %s pressure_share=%.1f %%\n", name,
           100 * (st.seconds_pressure - cpu_p0) / (st.seconds_total - st0.seconds_total));
    printf("BENCH %s density_projection_share=%.1f %%\n", name,
           100 * (st.seconds_density - cpu_d0) / (st.seconds_total - st0.seconds_total));
    printf("BENCH %s pressure_iterations_mean=%.2f 1\n", name, (double)iters / (k > 0 ? k : 1));
    printf("BENCH %s memory_bytes=%zu B\n", name, st.memory_bytes);
    printf("BENCH %s peak_rss=%ld KiB\n", name, (long)usage.ru_maxrss);
    fflush(stdout);
    fsdem_pic_destroy(s);
    return particle_steps / wall;
}

/* Each case on one thread, then on two (a build with OpenMP): speedup_2t. */
static void bench_both(int dim, int steps) {
    const char *name = dim == 2 ? "pic_dambreak_2d" : "pic_dambreak_3d";
    const double one = bench(dim, steps, 1);
    fsdem_set_threads(2);
    if (fsdem_threads() < 2) printf("BENCH %s speedup_2t=n/a (built without OpenMP)\n", name);
    else printf("BENCH %s speedup_2t=%.2f (particle steps per second, 2 threads over 1)\n", name, bench(dim, steps, 2) / one);
}

int main(int argc, char **argv) {
    int steps2 = argc > 1 ? atoi(argv[1]) : 200, steps3 = argc > 2 ? atoi(argv[2]) : 40;
    if (steps2 > 0) bench_both(2, steps2);
    if (steps3 > 0) bench_both(3, steps3);
    return 0;
}
