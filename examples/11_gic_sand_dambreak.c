/* 11_gic_sand_dambreak: a 2D dam break onto a pile of sand, PIC/FLIP water coupled with DEM granules
   smaller than a cell through volume fractions (the Granule-In-Cell coupler of seed 004), written
   for ParaView.

   A water column 0.1 m wide and 0.2 m high stands at the left wall of a tank 0.4 m long; a block of
   sand (granules of radius 1.25 mm, 2500 kg/m^3) 0.1 m wide and 0.05 m high lies on the floor
   further on. At t = 0 the water is released, runs into the sand, soaks through it (the density
   projection keeps the water out of the space the granules take) and pushes it along.

   Every 0.02 s: water_NNNN.vtp (PIC particles: velocity) listed in water.pvd and sand_NNNN.vtp (DEM
   granules: radius, velocity, forces) listed in sand.pvd. ParaView: open both .pvd files; sand:
   Glyph, Sphere, scale by "radius", factor 2; water: Points, colour by velocity.

   Run:  make examples && cd build/examples && ./11_gic_sand_dambreak      (about 30 s of CPU; 6,600 steps:
         the drag limit of >>couple_gic holds dt near 0.1 ms while the water soaks the sand)
   Build by hand: cc -std=c99 -O2 -I. examples/11_gic_sand_dambreak.c -o gic_sand_dambreak -lm */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <stdio.h>

#define DX 0.005     /* m, water grid */
#define RADIUS 0.00125 /* m, granules */
#define TANK 0.4     /* m */

int main(void) {
    const double t_end = 1.0, frame_every = 0.02, s = 2.1 * RADIUS;
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_gic_desc gd = fsdem_gic_desc_default();
    fsdem_dem_material sand = fsdem_dem_material_default();
    fsdem_dem *dem = NULL;
    fsdem_pic *pic = NULL;
    fsdem_gic *gic = NULL;
    fsdem_pvd water_series, sand_series;
    fsdem_real dem_dt = 0;
    int frame = 0, status = 1, i, j;

    /* the sand: seed 004's contact law (Eq. 1a-1c), E = 1e6 Pa, translation only; discs as heavy
       as spheres of the same radius (disc_length 2 r) */
    dd.domain_min = fsdem_v3(0, 0, 0); /* the water's tank: the DEM's walls are its sides */
    dd.domain_max = fsdem_v3(TANK, 0.3, 0);
    dd.law = FSDEM_DEM_LAW_GIC;
    dd.rotation = 0;
    dd.disc_length = 2 * RADIUS;
    sand.density = 2500;
    sand.young_modulus = 1e6;
    sand.friction = 0.5;
    if (fsdem_dem_create(&dd, &dem) != FSDEM_OK || fsdem_dem_add_material(dem, &sand, NULL) != FSDEM_OK) {
        fprintf(stderr, "cannot create the DEM\n");
        goto done;
    }
    {
        const fsdem_dem_wall_desc box = fsdem_dem_wall_box(dd.domain_min, dd.domain_max, 1, 0);
        if (fsdem_dem_add_wall(dem, &box, NULL) != FSDEM_OK) goto done;
    }
    for (j = 0; (j + 0.5) * s < 0.05; ++j)
        for (i = 0; (i + 0.5) * s < 0.1; ++i) {
            fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
            p.radius = RADIUS;
            p.position = fsdem_v3((fsdem_real)(0.2 + (i + 0.5) * s), (fsdem_real)((j + 0.5) * s), 0);
            if (fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK) {
                fprintf(stderr, "%s\n", fsdem_dem_last_error(dem));
                goto done;
            }
        }
    if (fsdem_dem_stable_dt(dem, &dem_dt) != FSDEM_OK || fsdem_dem_set_dt(dem, dem_dt) != FSDEM_OK) goto done;

    /* the water: PIC/FLIP on the tank, a column at the left wall */
    pd.cell_size = DX;
    pd.domain_max = fsdem_v3(TANK, 0.3, 0);
    pd.dt_max = 2e-3;
    if (fsdem_pic_create(&pd, &pic) != FSDEM_OK ||
        fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3(0.1f, 0.2f, 0), fsdem_v3(0, 0, 0), NULL) != FSDEM_OK) {
        fprintf(stderr, "cannot create the water\n");
        goto done;
    }

    /* the coupler: the seed's quadratic drag (Eq. 5b) and pressure-gradient force (Eq. 5a) */
    gd.pic = pic;
    gd.dem = dem;
    if (fsdem_gic_create(&gd, &gic) != FSDEM_OK || fsdem_gic_update(gic) != FSDEM_OK) {
        char why[256];
        fsdem_gic_desc_check(&gd, why, sizeof why);
        fprintf(stderr, "coupler: %s\n", gic ? fsdem_gic_last_error(gic) : why);
        goto done;
    }
    if (fsdem_pvd_open(&water_series, "water.pvd") != FSDEM_OK) goto done;
    if (fsdem_pvd_open(&sand_series, "sand.pvd") != FSDEM_OK) {
        fsdem_pvd_close(&water_series);
        goto done;
    }
    printf("2D sand dam break (Granule-In-Cell): %d water particles (dx = %g m), %d granules (DEM dt %.3g s), to t = %.1f s\n",
           fsdem_pic_get_stats(pic).particles, DX, fsdem_dem_get_particles(dem).count, (double)dem_dt, t_end);
    printf("%6s %6s %11s %12s %10s %8s %8s\n", "t (s)", "steps", "sand x(m)", "water vol", "max a_s", "PIC (s)", "DEM (s)");
    status = 0;
    for (;;) {
        const fsdem_gic_stats st = fsdem_gic_get_stats(gic);
        const fsdem_dem_particles P = fsdem_dem_get_particles(dem);
        const double t = fsdem_gic_time(gic);
        double x_ave = 0;
        char name[64];
        for (i = 0; i < P.count; ++i) x_ave += P.position[i].x / P.count;
        snprintf(name, sizeof name, "water_%04d.vtp", frame);
        if (fsdem_pic_write_particles_vtp(pic, name, FSDEM_VTK_FORMAT_APPENDED) == FSDEM_OK) fsdem_pvd_add(&water_series, t, name);
        snprintf(name, sizeof name, "sand_%04d.vtp", frame);
        if (fsdem_dem_write_vtp(dem, name, FSDEM_VTK_FORMAT_APPENDED) == FSDEM_OK) fsdem_pvd_add(&sand_series, t, name);
        if (frame % 5 == 0)
            printf("%6.2f %6lld %11.4f %12.5g %10.3f %8.1f %8.1f\n", t, st.coupling.steps, x_ave, (double)fsdem_pic_get_stats(pic).fluid_volume,
                   (double)st.max_solid_fraction, st.coupling.seconds_fluid, (st.coupling.seconds_dem + st.coupling.seconds_coupling));
        fflush(stdout);
        if (frame * frame_every >= t_end - 1e-9) break;
        frame++;
        if (fsdem_gic_advance(gic, (fsdem_real)frame_every, NULL) != FSDEM_OK) {
            fprintf(stderr, "step failed at t = %.4f s: %s\n", fsdem_gic_time(gic), fsdem_gic_last_error(gic));
            status = 1;
            break;
        }
    }
    fsdem_pvd_close(&water_series);
    fsdem_pvd_close(&sand_series);
done:
    fsdem_gic_destroy(gic);
    fsdem_pic_destroy(pic);
    fsdem_dem_destroy(dem);
    return status;
}
