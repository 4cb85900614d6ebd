/* 08_mpsdem_dambreak: a 3D dam break of water carrying sediment, MPS water coupled with DEM
   spheres (the unresolved MPS-DEM coupler, Model B of seed 002), written for ParaView.

   A water column 0.05 m long, 0.05 m wide and 0.1 m high stands against the left wall of a tank
   0.2 m long (a slice of the liquid-solid dam break of seed 002 §3.2, half as wide); the bottom
   0.02 m of the column is a bed of 400 glass spheres (5 mm, 2500 kg/m^3) in a simple cubic
   packing, with the water in its pores. At t = 0 the column is released: the water runs ahead and
   drags the sediment along the floor.

   The water is MPS particles 5 mm apart (the walls are particles too: one WALL layer and DUMMY
   layers behind it), the sediment DEM spheres (Hertz-Mindlin, E = 1e8 Pa, e = 0.9, friction 0.2).
   The coupler (fsdem_mps_dem) gives each MPS particle the porosity of the spheres around it and
   each sphere the drag and buoyancy of the water around it (seed 002 Eq. 25-36); every coupled
   step is one MPS step and as many DEM substeps as the spheres need. Each MPS particle holds the
   water of an r0 cube and stands for r0^3 / eps of mixture, so inside the bed the water is placed
   on a coarser lattice (r0 / eps^(1/3) apart).

   Every 0.01 s: water_NNNN.vtp (MPS particles: kind, pressure, velocity, porosity) listed in
   water.pvd, sediment_NNNN.vtp (DEM spheres: radius, velocity, forces) listed in sediment.pvd, and a
   row of fronts.csv (t, the leading water front: the largest x of a water particle, and the
   sediment front: the largest x of a sphere plus its radius). ParaView: open both .pvd files;
   water: Threshold on "kind" = 0; sediment: Glyph, sphere, scale by "radius", factor 2.

   Run:  make examples && cd build/examples && ./08_mpsdem_dambreak      (about 45 s of CPU; ~80 MB)
   Build by hand: cc -std=c99 -O2 -I. examples/08_mpsdem_dambreak.c -o mpsdem_dambreak -lm */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define R0 0.005          /* m, MPS spacing */
#define RADIUS 0.0025     /* m, sphere radius */
#define TANK_X 0.2        /* m */
#define TANK_Y 0.05
#define TANK_Z 0.15
#define COLUMN_X 0.05
#define COLUMN_Z 0.1
#define BED_Z 0.02

/* Largest x of a FLUID particle (m). */
static double water_front(fsdem_mps *mps) {
    fsdem_mps_particles p = fsdem_mps_get_particles(mps);
    double x = 0;
    int i;
    for (i = 0; i < p.count; ++i)
        if (p.kind[i] == FSDEM_MPS_KIND_FLUID && p.position[i].x > x) x = p.position[i].x;
    return x;
}

/* Largest x of a sphere's surface (m). */
static double sediment_front(const fsdem_dem *dem) {
    fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    double x = 0;
    int i;
    for (i = 0; i < p.count; ++i)
        if (p.position[i].x + p.radius[i] > x) x = p.position[i].x + p.radius[i];
    return x;
}

int main(void) {
    const double t_end = 0.4, frame_every = 0.01, pi = 3.14159265358979323846;
    fsdem_mps_desc md = fsdem_mps_desc_default_scheme(3, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_dem_material glass = fsdem_dem_material_default();
    fsdem_mps_dem_desc cd = fsdem_mps_dem_desc_default();
    fsdem_dem_wall_desc box;
    fsdem_mps *mps = NULL;
    fsdem_dem *dem = NULL;
    fsdem_mps_dem *cpl = NULL;
    fsdem_pvd water_series, sediment_series;
    fsdem_csv csv;
    fsdem_real dem_dt = 0;
    double bed_porosity;
    int material = 0, walls = 0, water = 0, above = 0, spheres = 0, frame = 0, status = 1, i, j, k;

    /* the water: MPS defaults (seed 002 §2.1: re = 4.1 r0, gamma 0.01, CFL 0.2) with Model B */
    md.r0 = (fsdem_real)R0;
    md.model = FSDEM_MPS_MODEL_B;
    md.domain_min = fsdem_v3(-0.03, -0.03, -0.03);
    md.domain_max = fsdem_v3(0.23, 0.08, 0.3);
    /* the sediment: Hertz-Mindlin spheres, dt by the Rayleigh rule (seed 002 Eq. 38) */
    dd.domain_min = md.domain_min;
    dd.domain_max = md.domain_max;
    dd.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    dd.dt_rule = FSDEM_DEM_DT_RULE_RAYLEIGH;
    glass.density = 2500;
    glass.young_modulus = 1e8;
    glass.poisson_ratio = 0.2;
    glass.restitution = 0.9;
    glass.friction = 0.2;
    if (fsdem_mps_create(&md, &mps) != FSDEM_OK || fsdem_dem_create(&dd, &dem) != FSDEM_OK ||
        fsdem_dem_add_material(dem, &glass, &material) != FSDEM_OK) {
        fprintf(stderr, "cannot create the solvers\n");
        goto done;
    }
    /* tank [0, 0.2] x [0, 0.05] x [0, 0.15], open at the top: MPS wall particles, and for the DEM a
       box wall (with a lid far above the flow) */
    box = fsdem_dem_wall_box(fsdem_v3(0, 0, 0), fsdem_v3(TANK_X, TANK_Y, 0.28), 1, material);
    if (fsdem_mps_add_box_walls(mps, fsdem_v3(0, 0, 0), fsdem_v3(TANK_X, TANK_Y, TANK_Z), 1u << FSDEM_SIDE_ZMAX, &walls) != FSDEM_OK ||
        fsdem_dem_add_wall(dem, &box, NULL) != FSDEM_OK) {
        fprintf(stderr, "walls: %s %s\n", fsdem_mps_last_error(mps), fsdem_dem_last_error(dem));
        goto done;
    }
    /* the bed: spheres one diameter apart (touching) on a simple cubic lattice over [0, 0.05]^2 x [0, 0.02] */
    {
        const int nx = (int)(COLUMN_X / (2 * RADIUS) + 1e-6), ny = (int)(TANK_Y / (2 * RADIUS) + 1e-6),
                  nz = (int)(BED_Z / (2 * RADIUS) + 1e-6);
        const double sx = COLUMN_X / nx, sy = TANK_Y / ny, sz = BED_Z / nz;
        for (k = 0; k < nz; ++k)
            for (j = 0; j < ny; ++j)
                for (i = 0; i < nx; ++i) {
                    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
                    p.position = fsdem_v3((fsdem_real)((i + 0.5) * sx), (fsdem_real)((j + 0.5) * sy), (fsdem_real)((k + 0.5) * sz));
                    p.radius = (fsdem_real)RADIUS;
                    p.material = material;
                    if (fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK) {
                        fprintf(stderr, "%s\n", fsdem_dem_last_error(dem));
                        goto done;
                    }
                    spheres++;
                }
        bed_porosity = 1 - (4.0 / 3.0) * pi * RADIUS * RADIUS * RADIUS / (sx * sy * sz);
    }
    if (fsdem_dem_stable_dt(dem, &dem_dt) != FSDEM_OK || fsdem_dem_set_dt(dem, dem_dt) != FSDEM_OK) goto done;
    /* water in the pores: a lattice r0 / eps^(1/3) apart on average, fitted to the bed per axis */
    {
        const double s = R0 / cbrt(bed_porosity);
        const int nx = (int)floor(COLUMN_X / s + 0.5), ny = (int)floor(TANK_Y / s + 0.5), nz = (int)floor(BED_Z / s + 0.5);
        const double sx = COLUMN_X / nx, sy = TANK_Y / ny, sz = BED_Z / nz;
        fsdem_vec3 *x = (fsdem_vec3 *)malloc((size_t)(nx * ny * nz) * sizeof *x);
        if (!x) goto done;
        for (k = 0; k < nz; ++k)
            for (j = 0; j < ny; ++j)
                for (i = 0; i < nx; ++i)
                    x[water++] = fsdem_v3((fsdem_real)((i + 0.5) * sx), (fsdem_real)((j + 0.5) * sy), (fsdem_real)((k + 0.5) * sz));
        k = fsdem_mps_add_particles(mps, FSDEM_MPS_KIND_FLUID, water, x, NULL);
        free(x);
        if (k != FSDEM_OK) goto done;
    }
    /* clear water above the bed, on the r0 lattice */
    if (fsdem_mps_fill_box(mps, fsdem_v3(0, 0, BED_Z), fsdem_v3(COLUMN_X, TANK_Y, COLUMN_Z), fsdem_v3(0, 0, 0), &above) != FSDEM_OK) {
        fprintf(stderr, "%s\n", fsdem_mps_last_error(mps));
        goto done;
    }
    water += above;
    cd.mps = mps;
    cd.dem = dem;
    if (fsdem_mps_dem_create(&cd, &cpl) != FSDEM_OK) {
        char why[256];
        fsdem_mps_dem_desc_check(&cd, why, sizeof why);
        fprintf(stderr, "%s\n", why);
        goto done;
    }
    if (fsdem_pvd_open(&water_series, "water.pvd") != FSDEM_OK) goto done;
    if (fsdem_pvd_open(&sediment_series, "sediment.pvd") != FSDEM_OK) {
        fsdem_pvd_close(&water_series);
        goto done;
    }
    if (fsdem_csv_open(&csv, "fronts.csv", "t,water_front,sediment_front") != FSDEM_OK) {
        fsdem_pvd_close(&water_series);
        fsdem_pvd_close(&sediment_series);
        goto done;
    }
    printf("3D MPS-DEM dam break: %d water, %d wall particles (r0 = %g m), %d spheres (d = %g m, bed porosity %.3f),\n"
           "DEM dt %.3g s, Model B, to t = %.1f s\n",
           water, walls, R0, spheres, 2 * RADIUS, bed_porosity, (double)dem_dt, t_end);
    printf("%6s %6s %10s %10s %8s %8s %8s\n", "t (s)", "steps", "water (m)", "sed. (m)", "u_max", "MPS (s)", "DEM (s)");
    status = 0;
    for (;;) {
        fsdem_mps_dem_stats st = fsdem_mps_dem_get_stats(cpl);
        fsdem_real row[3];
        char name[64];
        row[0] = (fsdem_real)fsdem_mps_dem_time(cpl);
        row[1] = (fsdem_real)(water_front(mps) + R0 / 2);
        row[2] = (fsdem_real)sediment_front(dem);
        fsdem_csv_row(&csv, row, 3);
        snprintf(name, sizeof name, "water_%04d.vtp", frame);
        if (fsdem_mps_write_vtp(mps, name, FSDEM_VTK_FORMAT_APPENDED) == FSDEM_OK) fsdem_pvd_add(&water_series, row[0], name);
        snprintf(name, sizeof name, "sediment_%04d.vtp", frame);
        if (fsdem_dem_write_vtp(dem, name, FSDEM_VTK_FORMAT_APPENDED) == FSDEM_OK) fsdem_pvd_add(&sediment_series, row[0], name);
        if (frame % 5 == 0)
            printf("%6.2f %6lld %10.4f %10.4f %8.3f %8.1f %8.1f\n", (double)row[0], st.coupling.steps, (double)row[1], (double)row[2],
                   (double)fsdem_mps_get_stats(mps).max_speed, st.coupling.seconds_fluid, (st.coupling.seconds_dem + st.coupling.seconds_coupling));
        fflush(stdout);
        if (frame * frame_every >= t_end - 1e-9) break;
        frame++;
        /* coupled steps up to the next frame, the last one shortened to land on it */
        if (fsdem_mps_dem_advance(cpl, (fsdem_real)frame_every, NULL) != FSDEM_OK) {
            fprintf(stderr, "step failed at t = %.4f s: %s\n", fsdem_mps_dem_time(cpl), fsdem_mps_dem_last_error(cpl));
            status = 1;
            break;
        }
    }
    {
        fsdem_mps_dem_stats st = fsdem_mps_dem_get_stats(cpl);
        printf("%d frames, %lld coupled steps, %lld DEM substeps; CPU %.1f s MPS, %.1f s DEM and coupling\n", frame + 1, st.coupling.steps,
               st.coupling.substeps_total, st.coupling.seconds_fluid, (st.coupling.seconds_dem + st.coupling.seconds_coupling));
    }
    printf("wrote water.pvd and sediment.pvd (ParaView) with water_*.vtp, sediment_*.vtp, and fronts.csv\n");
    fsdem_csv_close(&csv);
    fsdem_pvd_close(&water_series);
    fsdem_pvd_close(&sediment_series);
done:
    fsdem_mps_dem_destroy(cpl);
    fsdem_dem_destroy(dem);
    fsdem_mps_destroy(mps);
    return status;
}
