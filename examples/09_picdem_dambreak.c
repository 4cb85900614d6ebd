/* 09_picdem_dambreak: a 2D dam break through a pile of cylinders, PIC/FLIP water coupled with DEM
   discs that the water sees at their true shape (the resolved cut-cell PIC-DEM coupler of seed 000),
   written for ParaView.

   Six layers of aluminium cylinders (d = 1 cm, 6 and 5 per layer, the 5-layers in the grooves) are
   piled against the left wall of a tank 0.286 m long, with water behind a plate up to 0.12 m
   (the wet collapse of seed 000 §3.2). At t = 0 the plate is gone: the water bursts out through
   and over the pile and carries the cylinders to the right wall.

   Each cylinder is a moving cut-cell solid of the water's grid (fsdem_pic_dem): the pressure and
   the cylinders' velocities are solved together, and the fluid force and torque go to the DEM,
   which takes as many substeps per water step as its contacts need. The DEM contacts start 2 dx
   before the surfaces meet (contact_offset, seed 000 Eq. 19), so a gap of open cells always stays
   between cylinders; the water in the contact areas is slowed by beta = 0.5 (Eq. 20).

   Every 0.01 s: water_NNNN.vtp (PIC particles: velocity) listed in water.pvd and
   cylinders_NNNN.vtp (DEM discs: radius, velocity, forces) listed in cylinders.pvd; walls.vtp once.
   ParaView: open both .pvd files and walls.vtp; cylinders: Glyph, Sphere, scale by "radius",
   factor 2; water: Points, colour by velocity.

   Run:  make examples && cd build/examples && ./09_picdem_dambreak      (about 10 s of CPU; 18 MB)
   Build by hand: cc -std=c99 -O2 -I. examples/09_picdem_dambreak.c -o picdem_dambreak -lm */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <math.h>
#include <stdio.h>

#define DX 0.002       /* m, water grid (seed 000 uses 0.0005) */
#define RADIUS 0.005   /* m */
#define TANK 0.286     /* m */
#define WATER 0.12     /* m, water depth behind the plate */
#define LAYERS 6

int main(void) {
    const double t_end = 0.4, frame_every = 0.01, gap = 2 * DX;
    const double a = RADIUS + gap, s = 2 * RADIUS + gap; /* first centre from the walls; spacing */
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_pic_dem_desc cd = fsdem_pic_dem_desc_default();
    fsdem_dem_material al = fsdem_dem_material_default();
    fsdem_dem_wall_desc w[3];
    fsdem_dem *dem = NULL;
    fsdem_pic *pic = NULL;
    fsdem_pic_dem *cpl = NULL;
    fsdem_pvd water_series, cylinder_series;
    fsdem_real dem_dt = 0;
    int material = 0, frame = 0, status = 1, layer, k;

    /* the cylinders: the linear law of seed 000 Table 1 with the seed's predictor-corrector */
    dd.domain_min = fsdem_v3(-0.05, -0.05, -1);
    dd.domain_max = fsdem_v3(TANK + 0.05, 0.5, 1);
    dd.law = FSDEM_DEM_LAW_LINEAR;
    dd.linear_theta = 0.01;      /* one weight compresses a contact by 1 % of linear_dx */
    dd.linear_dx = 0.0005;
    dd.dt_param = 150;           /* gamma of the stable-step rule (seed 000 Eq. 18) */
    dd.integrator = FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR;
    dd.contact_offset = gap;     /* imaginary boundaries: the gap (Eq. 19) */
    dd.disc_length = 0.099;      /* m: each disc is a cylinder 9.9 cm long (mass and forces) */
    al.density = 2700;
    al.poisson_ratio = 0.3;
    al.friction = 0.3;
    al.damping_alpha = 0.4;
    if (fsdem_dem_create(&dd, &dem) != FSDEM_OK || fsdem_dem_add_material(dem, &al, &material) != FSDEM_OK) {
        fprintf(stderr, "cannot create the DEM\n");
        goto done;
    }
    w[0] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 1, 0), material);    /* floor */
    w[1] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), material);    /* left wall */
    w[2] = fsdem_dem_wall_plane(fsdem_v3(TANK, 0, 0), fsdem_v3(-1, 0, 0), material); /* right wall */
    for (k = 0; k < 3; ++k)
        if (fsdem_dem_add_wall(dem, &w[k], NULL) != FSDEM_OK) goto done;
    for (layer = 0; layer < LAYERS; ++layer)
        for (k = 0; k < (layer % 2 ? 5 : 6); ++k) {
            fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
            p.radius = RADIUS;
            p.material = material;
            p.position = fsdem_v3((fsdem_real)(a + s * k + (layer % 2 ? s / 2 : 0)), (fsdem_real)(a + layer * s * sqrt(3.0) / 2), 0);
            if (fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK) {
                fprintf(stderr, "%s\n", fsdem_dem_last_error(dem));
                goto done;
            }
        }
    if (fsdem_dem_stable_dt(dem, &dem_dt) != FSDEM_OK || fsdem_dem_set_dt(dem, dem_dt) != FSDEM_OK) goto done;

    /* the water: PIC/FLIP on the tank (slip sides), water from the left wall to the plate */
    pd.cell_size = DX;
    pd.domain_max = fsdem_v3(TANK, 0.26, 0);
    pd.viscosity = 1e-6;
    pd.dt_max = 1e-3;            /* from rest the first step would be sqrt(dx/g) */
    if (fsdem_pic_create(&pd, &pic) != FSDEM_OK ||
        fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)(2 * a + 5 * s), WATER, 0), fsdem_v3(0, 0, 0), NULL) != FSDEM_OK) {
        fprintf(stderr, "cannot create the water\n");
        goto done;
    }

    /* the coupler removes the water inside the cylinders; beta = 0.5 in the contact areas */
    cd.pic = pic;
    cd.dem = dem;
    cd.dissipation = 0.5;
    if (fsdem_pic_dem_create(&cd, &cpl) != FSDEM_OK) {
        char why[256];
        fsdem_pic_dem_desc_check(&cd, why, sizeof why);
        fprintf(stderr, "coupler: %s\n", why);
        goto done;
    }
    if (fsdem_pvd_open(&water_series, "water.pvd") != FSDEM_OK) goto done;
    if (fsdem_pvd_open(&cylinder_series, "cylinders.pvd") != FSDEM_OK) {
        fsdem_pvd_close(&water_series);
        goto done;
    }
    fsdem_dem_write_walls_vtp(dem, "walls.vtp", FSDEM_VTK_FORMAT_APPENDED);
    printf("2D PIC-DEM dam break: %d water particles (dx = %g m), %d cylinders (DEM dt %.3g s), beta %.1f, to t = %.1f s\n",
           fsdem_pic_get_stats(pic).particles, DX, fsdem_dem_get_particles(dem).count, (double)dem_dt, (double)cd.dissipation, t_end);
    printf("%6s %6s %9s %9s %9s %8s %8s %8s\n", "t (s)", "steps", "x_ave(m)", "x_max(m)", "contacts", "PIC (s)", "DEM (s)", "cpl (s)");
    status = 0;
    for (;;) {
        const fsdem_pic_dem_stats st = fsdem_pic_dem_get_stats(cpl);
        const fsdem_dem_particles P = fsdem_dem_get_particles(dem);
        const double t = fsdem_pic_dem_time(cpl);
        double x_ave = 0, x_max = 0;
        char name[64];
        int i;
        for (i = 0; i < P.count; ++i) {
            x_ave += P.position[i].x / P.count;
            if (P.position[i].x > x_max) x_max = P.position[i].x;
        }
        snprintf(name, sizeof name, "water_%04d.vtp", frame);
        if (fsdem_pic_write_particles_vtp(pic, name, FSDEM_VTK_FORMAT_APPENDED) == FSDEM_OK) fsdem_pvd_add(&water_series, t, name);
        snprintf(name, sizeof name, "cylinders_%04d.vtp", frame);
        if (fsdem_dem_write_vtp(dem, name, FSDEM_VTK_FORMAT_APPENDED) == FSDEM_OK) fsdem_pvd_add(&cylinder_series, t, name);
        if (frame % 5 == 0)
            printf("%6.2f %6lld %9.4f %9.4f %9d %8.1f %8.1f %8.1f\n", t, st.coupling.steps, x_ave, x_max, st.contacts, st.coupling.seconds_fluid,
                   st.coupling.seconds_dem, st.coupling.seconds_coupling);
        fflush(stdout);
        if (frame * frame_every >= t_end - 1e-9) break;
        frame++;
        /* coupled steps to the next frame, the last one shortened to land on it */
        if (fsdem_pic_dem_advance(cpl, (fsdem_real)frame_every, NULL) != FSDEM_OK) {
            fprintf(stderr, "step failed at t = %.4f s: %s\n", fsdem_pic_dem_time(cpl), fsdem_pic_dem_last_error(cpl));
            status = 1;
            break;
        }
    }
    {
        const fsdem_pic_dem_stats st = fsdem_pic_dem_get_stats(cpl);
        printf("%d frames, %lld coupled steps, %lld DEM substeps; %lld particle velocities damped in contact areas\n", frame + 1,
               st.coupling.steps, st.coupling.substeps_total, st.dissipated);
    }
    printf("wrote water.pvd and cylinders.pvd (ParaView) with water_*.vtp, cylinders_*.vtp, and walls.vtp\n");
    fsdem_pvd_close(&water_series);
    fsdem_pvd_close(&cylinder_series);
done:
    fsdem_pic_dem_destroy(cpl);
    fsdem_pic_destroy(pic);
    fsdem_dem_destroy(dem);
    return status;
}
