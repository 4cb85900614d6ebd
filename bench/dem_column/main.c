/* bench/dem_column: DEM throughput on a 3D granular column collapse, the case of the LIGGGHTS
   reference run in bench/liggghts/ (README.md there has its figures).

   20 x 20 x 50 = 20,000 spheres, d = 2 mm, rho = 2500 kg/m^3, on a simple cubic lattice of spacing
   2.1 mm (first centre 1.05 mm from each wall) filling the corner column 0.042 x 0.042 x 0.105 m,
   each coordinate jittered by a uniform +-0.05 mm (splitmix64, fixed seed). Channel 0.168 x 0.042 m:
   plane walls x = 0, x = 0.168, y = 0, y = 0.042 and the floor z = 0, open top (the domain, which
   fsdem needs closed, reaches z = 0.2 m without a wall). Hertz-Mindlin, E = 1e8 Pa, nu = 0.3,
   e = 0.9, mu = 0.3 for particles and walls, g = 9.81 m/s^2 along -z, dt = 5e-6 s, 30,000 steps
   (0.15 s), skin 0.4 mm, velocity Verlet (fsdem_dem_advance, 1000 steps a call), on one thread and
   then on two (speedup_2t; the second run needs a build with OpenMP, as `make bench` builds it).

   Usage: dem_column [steps [trace_interval]]
     steps           number of steps (default 30000) for quick runs
     trace_interval  if > 0, print "TRACE step ketr kerot xmax ncont" every that many steps, like the
                     LIGGGHTS thermo output (outside the timed region)

   Prints BENCH lines only (throughput, wall time, final physics, memory); no pass/fail. */
#define _POSIX_C_SOURCE 200809L
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>

#define NX 20
#define NY 20
#define NZ 50
#define SPACING 2.1e-3
#define FIRST 1.05e-3
#define JITTER 0.05e-3
#define RADIUS 1.0e-3
#define BOX_X 0.168
#define BOX_Y 0.042
#define BOX_TOP 0.2
#define DT 5e-6
#define STEPS 30000
#define SEED 12345u

/* splitmix64: small, deterministic, good enough for a jitter */
static uint64_t rng_next(uint64_t *state) {
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* uniform in [lo, hi) */
static double rng_uniform(uint64_t *state, double lo, double hi) {
    double u = (double)(rng_next(state) >> 11) * (1.0 / 9007199254740992.0);
    return lo + (hi - lo) * u;
}

static double now_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double front_x(fsdem_dem *dem) {
    fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    double xmax = -HUGE_VAL;
    int i;
    for (i = 0; i < p.count; ++i)
        if (p.position[i].x > xmax) xmax = p.position[i].x;
    return xmax;
}

static int fail(fsdem_dem *dem, const char *what, fsdem_result res) {
    fprintf(stderr, "dem_column: %s: %s (%s)\n", what, fsdem_result_string(res),
            dem ? fsdem_dem_last_error(dem) : "");
    fsdem_dem_destroy(dem);
    return 1;
}

/* The column on `threads` threads (fsdem_set_threads; one without OpenMP); its BENCH lines, and the
   throughput into *rate. */
static int run_column(long steps, long trace, int threads, double *rate) {
    fsdem_dem_desc desc = fsdem_dem_desc_default(3);
    fsdem_dem_material mat = fsdem_dem_material_default();
    fsdem_dem *dem = NULL;
    fsdem_result res;
    fsdem_dem_energy energy;
    fsdem_dem_stats stats;
    struct rusage usage;
    uint64_t rng = SEED;
    double loop_time = 0, t0;
    long s;
    int material, i, j, k;

    fsdem_set_threads(threads);
    if (steps < 0) steps = 0;
    desc.domain_min = fsdem_v3(0, 0, 0);
    desc.domain_max = fsdem_v3(BOX_X, BOX_Y, BOX_TOP);
    desc.gravity = fsdem_v3(0, 0, -9.81);
    desc.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    desc.integrator = FSDEM_DEM_INTEGRATOR_VERLET;
    desc.dt = DT;
    desc.skin = 0.4e-3;
    desc.capacity = NX * NY * NZ;
    res = fsdem_dem_create(&desc, &dem);
    if (res != FSDEM_OK) return fail(NULL, "fsdem_dem_create", res);

    mat.density = 2500;
    mat.young_modulus = 1e8;
    mat.poisson_ratio = 0.3;
    mat.restitution = 0.9;
    mat.friction = 0.3;
    mat.rolling_friction = 0;
    res = fsdem_dem_add_material(dem, &mat, &material);
    if (res != FSDEM_OK) return fail(dem, "fsdem_dem_add_material", res);

    {
        fsdem_dem_wall_desc walls[5];
        walls[0] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), material);
        walls[1] = fsdem_dem_wall_plane(fsdem_v3(BOX_X, 0, 0), fsdem_v3(-1, 0, 0), material);
        walls[2] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 1, 0), material);
        walls[3] = fsdem_dem_wall_plane(fsdem_v3(0, BOX_Y, 0), fsdem_v3(0, -1, 0), material);
        walls[4] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), material);
        for (i = 0; i < 5; ++i) {
            res = fsdem_dem_add_wall(dem, &walls[i], NULL);
            if (res != FSDEM_OK) return fail(dem, "fsdem_dem_add_wall", res);
        }
    }

    /* lattice in the order of make_column_data.py: z slowest, x fastest; jitter drawn x, y, z */
    for (k = 0; k < NZ; ++k)
        for (j = 0; j < NY; ++j)
            for (i = 0; i < NX; ++i) {
                fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
                double x = FIRST + i * SPACING + rng_uniform(&rng, -JITTER, JITTER);
                double y = FIRST + j * SPACING + rng_uniform(&rng, -JITTER, JITTER);
                double z = FIRST + k * SPACING + rng_uniform(&rng, -JITTER, JITTER);
                p.position = fsdem_v3(x, y, z);
                p.radius = RADIUS;
                p.material = material;
                res = fsdem_dem_add_particle(dem, &p, NULL);
                if (res != FSDEM_OK) return fail(dem, "fsdem_dem_add_particle", res);
            }

    /* runs of `chunk` steps through fsdem_dem_advance (the API for many steps: its Verlet substeps
       are fused into one pass over the particles each), with the trace between them */
    if (trace > 0) printf("TRACE step ketr kerot xmax ncont\n");
    t0 = now_seconds();
    for (s = 0; s < steps;) {
        long chunk = trace > 0 ? trace : 1000;
        if (chunk > steps - s) chunk = steps - s;
        res = fsdem_dem_advance(dem, (fsdem_real)(chunk * DT), NULL);
        if (res != FSDEM_OK) return fail(dem, "fsdem_dem_advance", res);
        s += chunk;
        if (trace > 0) {
            loop_time += now_seconds() - t0;
            energy = fsdem_dem_get_energy(dem);
            stats = fsdem_dem_get_stats(dem);
            printf("TRACE %ld %.9g %.9g %.9g %d\n", s, (double)energy.kinetic, (double)energy.rotational,
                   front_x(dem), stats.contacts);
            fflush(stdout);
            t0 = now_seconds();
        }
    }
    loop_time += now_seconds() - t0;

    energy = fsdem_dem_get_energy(dem);
    stats = fsdem_dem_get_stats(dem);
    getrusage(RUSAGE_SELF, &usage);
    *rate = loop_time > 0 ? (double)fsdem_dem_get_particles(dem).count * (double)steps / loop_time : 0.0;
    printf("BENCH dem_column threads=%d ranks=1\n", fsdem_threads());
    printf("BENCH dem_column particles=%d 1\n", fsdem_dem_get_particles(dem).count);
    printf("BENCH dem_column steps=%ld 1\n", steps);
    printf("BENCH dem_column particle_steps_per_s=%.4g 1/s\n",
           loop_time > 0 ? (double)fsdem_dem_get_particles(dem).count * (double)steps / loop_time : 0.0);
    printf("BENCH dem_column wall_time=%.3f s\n", loop_time);
    printf("BENCH dem_column kinetic_energy=%.9g J\n", (double)energy.kinetic);
    printf("BENCH dem_column rotational_energy=%.9g J\n", (double)energy.rotational);
    printf("BENCH dem_column front_x=%.9g m\n", front_x(dem));
    printf("BENCH dem_column contacts=%d 1\n", stats.contacts);
    printf("BENCH dem_column wall_contacts=%d 1\n", stats.wall_contacts);
    printf("BENCH dem_column neighbour_rebuilds=%lld 1\n", stats.rebuilds);
    printf("BENCH dem_column memory_bytes=%zu B\n", stats.memory_bytes);
    printf("BENCH dem_column peak_rss=%ld KiB\n", (long)usage.ru_maxrss);
    fsdem_dem_destroy(dem);
    return 0;
}

/* The column on one thread, then on two (a build with OpenMP): the same results bit for bit
   (>>doc THREADS), and the speed-up. */
int main(int argc, char **argv) {
    const long steps = argc > 1 ? strtol(argv[1], NULL, 10) : STEPS, trace = argc > 2 ? strtol(argv[2], NULL, 10) : 0;
    double one = 0, two = 0;
    if (run_column(steps, trace, 1, &one)) return 1;
    fsdem_set_threads(2);
    if (fsdem_threads() < 2) {
        printf("BENCH dem_column speedup_2t=n/a (built without OpenMP)\n");
        return 0;
    }
    if (run_column(steps, 0, 2, &two)) return 1;
    printf("BENCH dem_column speedup_2t=%.2f (particle steps per second, 2 threads over 1)\n", one > 0 ? two / one : 0.0);
    return 0;
}
