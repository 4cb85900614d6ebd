/* 06_floating_debris.c - floating debris carried by a 2D shallow-water dam break (SWE-DEM, seed 003).

   What it shows: the coupler fsdem_swe_dem between a 2D shallow-water solver (fsdem_swe) and a 3D DEM
   (fsdem_dem) whose spheres float on the water. A cylindrical column of water (radius 0.8 m, 0.4 m
   deep) stands in a 5 m x 4 m basin of still water 0.1 m deep; at t = 0 it collapses, and the bore
   it sends out reaches a ring of six wooden spheres (r = 6 cm, 600 kg/m^3) floating 1.4 m from the
   centre, and pushes them outwards. Each sphere feels buoyancy and the hydrostatic and dynamic
   pressure of seed 003 Eq. 3-8; the water feels the reactions (two-way coupling); the spheres touch
   the bed, the basin walls and each other through Hertz-Mindlin contacts.

   Time steps: each coupled step is one adaptive SWE step (its stable dt, CFL 0.5), during which the
   DEM runs K = INT(dt_swe / dt_dem) substeps; dt_dem is set once from fsdem_dem_stable_dt (0.2 x the
   Rayleigh time of the spheres). fsdem_swe_dem_advance takes coupled steps up to each output time.

   Prints progress every 0.5 s; writes debris_track.csv (t,id,x,y,z,vx,vy,vz, every 0.05 s) and the
   final water surface water_final.csv (x,y,bed,h,eta,u,v per cell).

   Run:  make examples && cd build/examples && ./06_floating_debris      (a few seconds) */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <math.h>
#include <stdio.h>

#define NX 100 /* 5 cm cells */
#define NY 80
#define DEBRIS 6

static const double basin_x = 5, basin_y = 4, cx = 2.5, cy = 2.0; /* m; column centre (cx, cy) */
static const double column_r = 0.8, h_column = 0.4, h_still = 0.1, ring_r = 1.4; /* m */
static const double r = 0.06, rho_wood = 600, rho_water = 1000;                    /* m, kg/m^3 */

/* Depth of a floating sphere's submerged cap: s with pi s^2 (3r - s)/3 = (rho_wood/rho_water) 4/3 pi r^3. */
static double draft(void) {
    double lo = 0, hi = 2 * r;
    int k;
    for (k = 0; k < 60; ++k) {
        double s = 0.5 * (lo + hi);
        if (s * s * (3 * r - s) < rho_wood / rho_water * 4 * r * r * r) lo = s;
        else hi = s;
    }
    return 0.5 * (lo + hi);
}

/* Mean distance of the spheres from the column centre (m). */
static double mean_radius(const fsdem_dem *dem) {
    fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    double sum = 0;
    int i;
    for (i = 0; i < p.count; ++i) sum += hypot(p.position[i].x - cx, p.position[i].y - cy);
    return p.count ? sum / p.count : 0;
}

/* Appends one row per sphere to the track and updates each sphere's farthest distance from the centre. */
static void write_track(fsdem_csv *csv, const fsdem_dem *dem, double *farthest) {
    fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    int i;
    for (i = 0; i < p.count; ++i) {
        fsdem_real row[8];
        double d = hypot(p.position[i].x - cx, p.position[i].y - cy);
        if (d > farthest[i]) farthest[i] = d;
        row[0] = (fsdem_real)fsdem_dem_time(dem);
        row[1] = (fsdem_real)p.id[i];
        row[2] = p.position[i].x; row[3] = p.position[i].y; row[4] = p.position[i].z;
        row[5] = p.velocity[i].x; row[6] = p.velocity[i].y; row[7] = p.velocity[i].z;
        fsdem_csv_row(csv, row, 8);
    }
}

int main(void) {
    const double t_end = 4.0, out_every = 0.05, print_every = 0.5;
    static fsdem_real depth[NX * NY];
    fsdem_swe_desc sd = fsdem_swe_desc_default(2);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3); /* spheres, gravity (0, 0, -9.81) like the SWE's */
    fsdem_swe_dem_desc cd = fsdem_swe_dem_desc_default();
    fsdem_dem_material wood = fsdem_dem_material_default();
    fsdem_dem_particle_desc ball = fsdem_dem_particle_desc_default();
    fsdem_dem_wall_desc basin;
    fsdem_swe *swe = NULL;
    fsdem_dem *dem = NULL;
    fsdem_swe_dem *cpl = NULL;
    fsdem_csv track;
    fsdem_real dt_dem;
    double start[DEBRIS][2], farthest[DEBRIS] = {0};
    int i, j, mat, frame, status = 1;

    /* water: a column of h_column within column_r of the centre, h_still elsewhere; walls all round */
    sd.nx = NX; sd.ny = NY;
    sd.x_max = basin_x; sd.y_max = basin_y;
    sd.limiter = FSDEM_SWE_LIMITER_MC;
    for (j = 0; j < NY; ++j)
        for (i = 0; i < NX; ++i) {
            double x = (i + 0.5) * basin_x / NX, y = (j + 0.5) * basin_y / NY;
            depth[i + NX * j] = (fsdem_real)(hypot(x - cx, y - cy) < column_r ? h_column : h_still);
        }
    sd.depth = depth;
    if (fsdem_swe_create(&sd, &swe) != FSDEM_OK) {
        char why[256];
        fsdem_swe_desc_check(&sd, why, sizeof why);
        fprintf(stderr, "%s\n", why);
        return 1;
    }

    /* debris: a DEM over the basin, its walls and bed one inside box, six spheres floating at their draft */
    dd.domain_min = fsdem_v3(-0.1, -0.1, -0.1);
    dd.domain_max = fsdem_v3(basin_x + 0.1, basin_y + 0.1, 1.0);
    dd.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    if (fsdem_dem_create(&dd, &dem) != FSDEM_OK) goto done;
    wood.density = rho_wood;
    wood.young_modulus = 1e8;
    wood.restitution = 0.5;
    wood.friction = 0.3;
    basin = fsdem_dem_wall_box(fsdem_v3(0, 0, 0), fsdem_v3(basin_x, basin_y, 0.9), 1, 0);
    if (fsdem_dem_add_material(dem, &wood, &mat) != FSDEM_OK || fsdem_dem_add_wall(dem, &basin, NULL) != FSDEM_OK)
        goto dem_error;
    for (i = 0; i < DEBRIS; ++i) {
        double a = 2 * 3.14159265358979323846 * (i + 0.25) / DEBRIS;
        start[i][0] = cx + ring_r * cos(a);
        start[i][1] = cy + ring_r * sin(a);
        ball.position = fsdem_v3(start[i][0], start[i][1], h_still - draft() + r);
        ball.radius = r;
        ball.material = mat;
        if (fsdem_dem_add_particle(dem, &ball, NULL) != FSDEM_OK) goto dem_error;
    }
    if (fsdem_dem_stable_dt(dem, &dt_dem) != FSDEM_OK || fsdem_dem_set_dt(dem, dt_dem) != FSDEM_OK) goto dem_error;

    /* the coupler; bobbing is not damped by wave radiation in the SWE, so damp it (seed 003 has none) */
    cd.swe = swe;
    cd.dem = dem;
    cd.heave_damping = 0.5;
    if (fsdem_swe_dem_create(&cd, &cpl) != FSDEM_OK) {
        char why[256];
        fsdem_swe_dem_desc_check(&cd, why, sizeof why);
        fprintf(stderr, "%s\n", why);
        goto done;
    }
    if (fsdem_csv_open(&track, "debris_track.csv", "t,id,x,y,z,vx,vy,vz") != FSDEM_OK) {
        fprintf(stderr, "cannot write debris_track.csv in this folder\n");
        goto done;
    }

    printf("radial dam break on %d x %d cells, %d floating spheres; DEM dt %.3g s, water volume %.4f m^3\n", NX, NY,
           DEBRIS, (double)dt_dem, (double)fsdem_swe_volume(swe));
    printf("%6s %7s %9s %10s %14s %9s\n", "t (s)", "steps", "substeps", "dt (s)", "mean dist (m)", "in water");
    write_track(&track, dem, farthest);
    for (frame = 1; frame * out_every <= t_end + 1e-9; ++frame) {
        if (fsdem_swe_dem_advance(cpl, (fsdem_real)out_every, NULL) != FSDEM_OK) {
            fprintf(stderr, "t = %.3f s: %s\n", fsdem_swe_dem_time(cpl), fsdem_swe_dem_last_error(cpl));
            fsdem_csv_close(&track);
            goto done;
        }
        write_track(&track, dem, farthest);
        if (fmod(frame * out_every + 1e-9, print_every) < 1e-6) {
            fsdem_swe_dem_stats st = fsdem_swe_dem_get_stats(cpl);
            fsdem_real dt_next = 0;
            fsdem_swe_dem_stable_dt(cpl, &dt_next); /* the SWE's stable dt, that of the next coupled step */
            printf("%6.2f %7lld %9lld %10.3g %14.3f %9d\n", st.coupling.time, st.coupling.steps, st.coupling.substeps_total, (double)dt_next,
                   mean_radius(dem), st.wet);
            fflush(stdout);
        }
    }
    fsdem_csv_close(&track);
    {
        fsdem_dem_particles p = fsdem_dem_get_particles(dem);
        for (i = 0; i < p.count; ++i)
            printf("sphere %d: (%.2f, %.2f) -> (%.2f, %.2f) m; distance from the centre %.2f -> %.2f m, farthest %.2f m\n",
                   p.id[i], start[i][0], start[i][1], (double)p.position[i].x, (double)p.position[i].y, ring_r,
                   hypot(p.position[i].x - cx, p.position[i].y - cy), farthest[i]);
    }
    printf("water volume %.4f m^3; wrote debris_track.csv and water_final.csv\n", (double)fsdem_swe_volume(swe));
    status = fsdem_swe_write_csv(swe, "water_final.csv") == FSDEM_OK ? 0 : 1;
    goto done;
dem_error:
    fprintf(stderr, "%s\n", fsdem_dem_last_error(dem));
done:
    fsdem_swe_dem_destroy(cpl);
    fsdem_dem_destroy(dem);
    fsdem_swe_destroy(swe);
    return status;
}
