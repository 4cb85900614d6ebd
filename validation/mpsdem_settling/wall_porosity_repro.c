/* Reproduction: WALL particles' Eq. 31 porosity inflates the MPS number density of the fluid next to
   a wall (fsdem.h couple_mps step 1 writes eps to WALL particles; Eq. 7 / the PPE divide by eps_j,
   but WALL particles sit on the full r0 lattice). Fixed spheres (phi 0.065) fill a closed tank of
   still water at the right particle count; the water must stay at rest (Model B, hydrostatic p).
   Mode 0: fsdem_mps_dem_update + fsdem_mps_step_dt (= fsdem_mps_dem_step for fixed spheres).
   Mode 1: the same with the porosity of WALL and DUMMY particles set back to 1 before the MPS step.
   From the repository root: cc -std=c99 -O2 -I. validation/mpsdem_settling/wall_porosity_repro.c -o repro -lm && ./repro
   (2 runs of 40 steps, about 5 s CPU; run(mode, 2) packs spheres at phi 0.524, but its water layers
   are then 2 r0 apart and the column is not at rest in either mode) */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"
#include <stdio.h>

static void run(int mode, int per) {
    const double r0 = 0.004, d = 0.002, W = 8 * r0, HS = 16 * r0, rho = 1000, g = 9.81;
    const double eps = 1 - per * per * per * 3.14159265358979 / 6 * d * d * d / (r0 * r0 * r0); /* spheres on the r0/per lattice */
    const int layers = (int)(HS / r0 * eps + 0.5), clear = 4;
    const double hs = layers * r0 / eps; /* suspension height at eps exactly */
    fsdem_mps_desc md = fsdem_mps_desc_default(3);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_dem_material mat = fsdem_dem_material_default();
    fsdem_mps_dem_desc cd = fsdem_mps_dem_desc_default();
    fsdem_mps *mps;
    fsdem_dem *dem;
    fsdem_mps_dem *cpl;
    fsdem_vec3 pos[64 * 60];
    int i, j, k, n = 0, m, step, nz = (int)(hs / r0 * per + 1e-9);
    md.r0 = (fsdem_real)r0, md.model = FSDEM_MPS_MODEL_B, md.viscosity = 1e-6f, md.density = (fsdem_real)rho;
    md.domain_min = fsdem_v3(-0.03f, -0.03f, -0.03f), md.domain_max = fsdem_v3(0.07f, 0.07f, 0.15f);
    fsdem_mps_create(&md, &mps);
    fsdem_mps_add_box_walls(mps, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)W, (fsdem_real)W, 0.12f), 1u << FSDEM_SIDE_ZMAX, NULL);
    for (k = 0; k < layers + clear; ++k)
        for (j = 0; j < 8; ++j)
            for (i = 0; i < 8; ++i)
                pos[n++] = fsdem_v3((fsdem_real)((i + 0.5) * r0), (fsdem_real)((j + 0.5) * r0),
                                    (fsdem_real)(k < layers ? (k + 0.5) * r0 / eps : hs + (k - layers + 0.5) * r0));
    fsdem_mps_add_particles(mps, FSDEM_MPS_FLUID, n, pos, NULL);
    dd.domain_min = md.domain_min, dd.domain_max = md.domain_max;
    fsdem_dem_create(&dd, &dem);
    fsdem_dem_add_material(dem, &mat, &m);
    for (k = 0; k < nz; ++k)
        for (j = 0; j < 8 * per; ++j)
            for (i = 0; i < 8 * per; ++i) {
                fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
                p.position = fsdem_v3((fsdem_real)((i + 0.5) * r0 / per), (fsdem_real)((j + 0.5) * r0 / per), (fsdem_real)((k + 0.5) * hs / nz));
                p.radius = (fsdem_real)(d / 2), p.material = m, p.fixed = 1;
                fsdem_dem_add_particle(dem, &p, NULL);
            }
    cd.mps = mps, cd.dem = dem;
    fsdem_mps_dem_create(&cd, &cpl);
    for (step = 1; step <= 40; ++step) {
        fsdem_mps_particles v;
        double u = 0, nd_in = 0, nd_wall = 0, ew = 0, gz = 0;
        int c = 0, cin = 0, cw = 0, nw = 0;
        fsdem_mps_dem_update(cpl);
        v = fsdem_mps_get_particles(mps);
        for (i = 0; i < v.count; ++i)
            if (v.kind[i] == FSDEM_MPS_WALL && v.position[i].z < 0 && v.position[i].x > 0 && v.position[i].x < W && v.position[i].y > 0 && v.position[i].y < W)
                ew += v.porosity[i], nw++;
        if (mode == 1)
            for (i = 0; i < v.count; ++i)
                if (v.kind[i] != FSDEM_MPS_FLUID) v.porosity[i] = 1;
        fsdem_mps_step_dt(mps, 1e-3f);
        v = fsdem_mps_get_particles(mps);
        for (i = 0; i < v.count; ++i) {
            const fsdem_vec3 x = v.position[i];
            if (v.kind[i] != FSDEM_MPS_FLUID || x.z > hs) continue;
            u += v.velocity[i].z, c++;
            if (x.z > 4.1 * r0 && x.z < hs - 4.1 * r0 && x.x > 3 * r0 && x.x < W - 3 * r0 && x.y > 3 * r0 && x.y < W - 3 * r0)
                nd_in += v.number_density[i], gz += v.pressure_gradient[i].z, cin++;
            else if (x.z < 1.0 * r0) nd_wall += v.number_density[i], cw++;
        }
        if (step % 20 == 0) {
            fsdem_real pa, pb;
            fsdem_mps_probe_pressure(mps, fsdem_v3((fsdem_real)(W / 2), (fsdem_real)(W / 2), (fsdem_real)(4 * r0)), (fsdem_real)r0, &pb);
            fsdem_mps_probe_pressure(mps, fsdem_v3((fsdem_real)(W / 2), (fsdem_real)(W / 2), (fsdem_real)(12 * r0)), (fsdem_real)r0, &pa);
            printf("mode %d (%s) t %.3f s: floor WALL eps %.4f, fluid in the suspension mean u_z %+.5f m/s, n_i first row %.2f vs interior %.2f, "
                   "dp/dz between z = 4 and 12 r0: %.3f rho g, the corrector's grad p in the middle %.3f rho g (eps %.4f; to the fluid %.4f of N V rho g)\n",
                   mode, mode ? "WALL/DUMMY eps reset to 1" : "as the coupler writes", step * 1e-3, nw ? ew / nw : 1, u / c, cw ? nd_wall / cw : 0,
                   cin ? nd_in / cin : 0, (pb - pa) / (8 * r0) / (rho * g), cin ? -gz / cin / (rho * g) : 0, eps,
                   -fsdem_mps_dem_get_stats(cpl).to_fluid.z / (fsdem_dem_get_particles(dem).count * 3.14159265358979 / 6 * d * d * d * rho * g));
        }
    }
    fsdem_mps_dem_destroy(cpl);
    fsdem_dem_destroy(dem);
    fsdem_mps_destroy(mps);
}

int main(void) {
    run(0, 1);
    run(1, 1);
    return 0;
}
