/* 02_hello_sphere.c - the hello world of fsdem.h's documentation block.

   What it shows: the smallest complete program. A sphere (r = 1 cm, default material: 2500 kg/m^3,
   E = 1e8 Pa, restitution 0.5) is dropped from 0.5 m onto a floor plane and bounces with the
   Hertz-Mindlin law; its height is printed every 0.1 s, together with what a rigid-body estimate
   predicts for the first impact (free fall) and the first rebound (restitution 0.5).

   Run:  make examples && ./build/examples/02_hello_sphere */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <math.h>
#include <stdio.h>

int main(void) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    d.domain_min = fsdem_v3(-1, -1, 0);
    d.domain_max = fsdem_v3(1, 1, 2);
    d.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    d.dt = 1e-5;
    fsdem_dem *dem;
    if (fsdem_dem_create(&d, &dem) != FSDEM_OK) return 1;
    fsdem_dem_material mat = fsdem_dem_material_default();
    int steel;
    fsdem_dem_add_material(dem, &mat, &steel);
    fsdem_dem_wall_desc floor = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), steel);
    fsdem_dem_add_wall(dem, &floor, NULL);
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    p.position = fsdem_v3(0, 0, 0.5);
    p.radius = 0.01;
    p.material = steel;
    fsdem_dem_add_particle(dem, &p, NULL);

    /* rigid-body estimate: free fall of 0.49 m, rebound at e times the impact speed */
    double g = 9.81, fall = 0.5 - p.radius, v_impact = sqrt(2 * g * fall);
    double v_rebound = mat.restitution * v_impact;
    printf("first impact expected at t = %.3f s, rebound to %.3f m\n", sqrt(2 * fall / g),
           p.radius + v_rebound * v_rebound / (2 * g));
    printf("%6s %10s %10s\n", "t [s]", "z [m]", "vz [m/s]");
    double peak = 0; /* highest point after the first rebound */
    int bounced = 0;
    for (int s = 0; s <= 100000; ++s) {
        fsdem_dem_particles now = fsdem_dem_get_particles(dem);
        if (now.velocity[0].z > 0) bounced = 1;
        if (bounced && bounced < 2 && now.position[0].z > peak) peak = now.position[0].z;
        if (bounced && now.velocity[0].z < 0 && peak > 0) bounced = 2; /* falling again: first peak done */
        if (s % 10000 == 0) {
            fsdem_dem_particles view = fsdem_dem_get_particles(dem);
            printf("%6.2f %10.4f %10.4f\n", (double)fsdem_dem_time(dem), (double)view.position[0].z,
                   (double)view.velocity[0].z);
        }
        if (s < 100000 && fsdem_dem_step(dem) != FSDEM_OK) {
            puts(fsdem_dem_last_error(dem));
            break;
        }
    }
    printf("first rebound reached %.4f m\n", peak);
    fsdem_dem_destroy(dem);
    return 0;
}
