/* 03_hopper_3d.c - spheres draining from a 3D hopper built of triangle walls.

   What it shows: mesh-like geometry from fsdem_dem_wall_triangle. A square funnel (top 0.2 m wide at
   z = 0.3 m, outlet 0.048 m wide at z = 0.2 m, so six particle diameters) is made of four trapezoids,
   two triangles each. About a thousand glass-like spheres (r = 4 mm, Hertz-Mindlin, mu = 0.3) start
   in a loose lattice above the funnel, fall in and drain through the outlet onto the floor of a box
   (FSDEM_DEM_WALL_TYPE_BOX_INSIDE). The program prints the number of discharged spheres (centre below the
   outlet) every 0.1 s; the count grows at a nearly steady rate while the funnel drains, as Beverloo's
   law expects for a hopper, and then levels off.

   Run:  make examples && ./build/examples/03_hopper_3d      (a few seconds) */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <stdio.h>

/* Point (x, y, z) turned by `quarter` quarter turns about the vertical axis. */
static fsdem_vec3 turned(double x, double y, double z, int quarter) {
    switch (quarter & 3) {
    case 1: return fsdem_v3(-y, x, z);
    case 2: return fsdem_v3(-x, -y, z);
    case 3: return fsdem_v3(y, -x, z);
    default: return fsdem_v3(x, y, z);
    }
}

int main(void) {
    const double r = 0.004, top = 0.30, bottom = 0.20, top_half = 0.10, out_half = 0.024;
    const double t_end = 1.2, report_every = 0.1;
    fsdem_dem_desc desc = fsdem_dem_desc_default(3);
    fsdem_dem_material glass = fsdem_dem_material_default();
    fsdem_dem *dem;
    fsdem_real dt;
    unsigned seed = 12345u;
    int mat, side, i, j, k, n_report = 0;
    long step, steps;

    desc.domain_min = fsdem_v3(-0.3, -0.3, -0.05);
    desc.domain_max = fsdem_v3(0.3, 0.3, 0.8);
    desc.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    if (fsdem_dem_create(&desc, &dem) != FSDEM_OK) return 1;
    glass.density = 2500;
    glass.young_modulus = 1e7; /* softened, as usual in DEM, for a larger time step */
    glass.poisson_ratio = 0.25;
    glass.restitution = 0.5;
    glass.friction = 0.3;
    fsdem_dem_add_material(dem, &glass, &mat);

    /* the funnel: side `side` is the trapezoid facing +x turned by `side` quarter turns */
    for (side = 0; side < 4; ++side) {
        fsdem_vec3 b0 = turned(out_half, -out_half, bottom, side), b1 = turned(out_half, out_half, bottom, side);
        fsdem_vec3 t0 = turned(top_half, -top_half, top, side), t1 = turned(top_half, top_half, top, side);
        fsdem_dem_wall_desc tri0 = fsdem_dem_wall_triangle(b0, b1, t1, mat), tri1 = fsdem_dem_wall_triangle(b0, t1, t0, mat);
        if (fsdem_dem_add_wall(dem, &tri0, NULL) != FSDEM_OK || fsdem_dem_add_wall(dem, &tri1, NULL) != FSDEM_OK) {
            printf("%s\n", fsdem_dem_last_error(dem));
            return 1;
        }
    }
    {   /* the collecting box: floor at z = 0 and four side walls */
        fsdem_dem_wall_desc box = fsdem_dem_wall_box(fsdem_v3(-0.25, -0.25, 0), fsdem_v3(0.25, 0.25, 0.75), 1, mat);
        fsdem_dem_add_wall(dem, &box, NULL);
    }

    /* a loose lattice of spheres above the funnel, jittered by up to 0.5 mm so it does not stay ordered */
    for (k = 0; k < 3; ++k)
        for (j = 0; j < 18; ++j)
            for (i = 0; i < 18; ++i) {
                fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
                double jitter[3];
                int c;
                for (c = 0; c < 3; ++c) {
                    seed = seed * 1664525u + 1013904223u; /* LCG, reproducible */
                    jitter[c] = ((seed >> 8) / 16777216.0 - 0.5) * 1e-3;
                }
                p.radius = r;
                p.material = mat;
                p.position = fsdem_v3(-0.0808 + 0.0095 * i + jitter[0], -0.0808 + 0.0095 * j + jitter[1],
                                      top + 0.012 + 0.0095 * k + jitter[2]);
                if (fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK) {
                    printf("%s\n", fsdem_dem_last_error(dem));
                    return 1;
                }
            }
    fsdem_dem_stable_dt(dem, &dt); /* Hertz: 0.2 x the Rayleigh time (seed 002 Eq. 38) */
    fsdem_dem_set_dt(dem, dt);
    steps = (long)(t_end / dt + 0.5);
    printf("hopper: %d spheres, 8 triangles, dt = %.3g s, %ld steps\n", fsdem_dem_get_particles(dem).count, (double)dt,
           steps);
    printf("%6s %11s %9s\n", "t [s]", "discharged", "in hopper");

    for (step = 0; step <= steps; ++step) {
        if (fsdem_dem_time(dem) >= n_report * report_every - dt / 2) {
            fsdem_dem_particles p = fsdem_dem_get_particles(dem);
            int below = 0, in_hopper = 0;
            for (i = 0; i < p.count; ++i) {
                if (p.position[i].z < bottom - r) below++;
                else if (p.position[i].z < top) in_hopper++;
            }
            printf("%6.2f %11d %9d\n", (double)fsdem_dem_time(dem), below, in_hopper);
            n_report++;
        }
        if (step < steps && fsdem_dem_step(dem) != FSDEM_OK) {
            printf("step failed: %s\n", fsdem_dem_last_error(dem));
            break;
        }
    }
    {
        fsdem_dem_stats st = fsdem_dem_get_stats(dem);
        printf("%lld steps, %lld neighbour-list rebuilds, %d contacts at the end\n", st.steps, st.rebuilds,
               st.contacts + st.wall_contacts);
    }
    fsdem_dem_destroy(dem);
    return 0;
}
