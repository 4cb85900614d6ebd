/* 01_cylinder_collapse.c - the `make demo` program: collapse of six layers of aluminium cylinders.

   What it shows: a 2D DEM run of seed 000 section 3.1 (after Zhang et al. 2009). 33 cylinders
   (d = 1 cm, 9.9 cm long, 2700 kg/m^3) stacked in layers of 6 and 5 against the left wall of a tank
   collapse when the retaining plate is removed at t = 0. It uses the seed's linear spring-dashpot law
   (Eq. 7-18, Table 1: alpha = 0.4, psi = 0.3, mu = 0.3, theta = 1%), its imaginary-boundary gap of
   2 dx (Eq. 19), its predictor-corrector (Eq. 21-24) and the time step of Eq. 18 with gamma = 150.

   Run:  make demo          (builds build/examples/01_cylinder_collapse and runs it in build/examples)
   Prints t, the mean centre x_ave and height z_ave (Eq. 26), the kinetic energy and the contact
   count every 0.05 s, and writes collapse_NNN.csv and VTK XML snapshots: the cylinders
   (collapse_NNN.vtp) and their contacts (contacts_NNN.vtp, lines with the contact force), listed in
   collapse.pvd and contacts.pvd, and the tank's walls (walls.vtp). In ParaView open the two .pvd
   series and walls.vtp; on collapse.pvd apply a Glyph filter (sphere, scale by "radius", factor 2).
   Takes well under a second. */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <math.h>
#include <stdio.h>

int main(void) {
    const double r = 0.005, dx = 0.0005, gap = 2 * dx, tank = 0.26 * 1.1, t_end = 1.0, every = 0.05;
    const double a = r + gap, s = 2 * r + gap; /* first centre, centre spacing: boundaries just touch */
    fsdem_dem_desc desc = fsdem_dem_desc_default(2);
    fsdem_dem_material al = fsdem_dem_material_default();
    fsdem_dem *dem;
    fsdem_pvd particles, contacts;
    fsdem_real dt;
    int mat, layer, k, frame = 0;
    long step, steps;

    desc.domain_min = fsdem_v3(-0.05, -0.05, -1);
    desc.domain_max = fsdem_v3(tank + 0.05, tank + 0.2, 1);
    desc.law = FSDEM_DEM_LAW_LINEAR;
    desc.integrator = FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR;
    desc.contact_offset = gap;
    desc.linear_theta = 0.01;
    desc.linear_dx = dx;
    desc.disc_length = 0.099; /* discs with the cylinders' real mass */
    if (fsdem_dem_create(&desc, &dem) != FSDEM_OK) return 1;

    al.density = 2700;
    al.poisson_ratio = 0.3;
    al.friction = 0.3;
    al.damping_alpha = 0.4;
    fsdem_dem_add_material(dem, &al, &mat);
    {
        fsdem_dem_wall_desc floor = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 1, 0), mat);
        fsdem_dem_wall_desc left = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), mat);
        fsdem_dem_wall_desc right = fsdem_dem_wall_plane(fsdem_v3(tank, 0, 0), fsdem_v3(-1, 0, 0), mat);
        fsdem_dem_add_wall(dem, &floor, NULL);
        fsdem_dem_add_wall(dem, &left, NULL);
        fsdem_dem_add_wall(dem, &right, NULL);
    }
    for (layer = 0; layer < 6; ++layer) /* 6, 5, 6, 5, 6, 5; the 5-layers sit in the grooves */
        for (k = 0; k < (layer % 2 ? 5 : 6); ++k) {
            fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
            p.radius = r;
            p.material = mat;
            p.position = fsdem_v3(a + s * k + (layer % 2 ? s / 2 : 0), a + layer * s * sqrt(3.0) / 2, 0);
            if (fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK) {
                printf("%s\n", fsdem_dem_last_error(dem));
                return 1;
            }
        }
    fsdem_dem_stable_dt(dem, &dt); /* the linear law's rule: seed 000 Eq. 18, gamma = 150 */
    fsdem_dem_set_dt(dem, dt);
    steps = (long)ceil(t_end / dt);
    printf("cylinder collapse: %d cylinders, dt = %.3g s, %ld steps\n", fsdem_dem_get_particles(dem).count, (double)dt,
           steps);
    printf("%6s %9s %9s %12s %8s\n", "t [s]", "x_ave [m]", "z_ave [m]", "E_kin [J]", "contacts");
    /* binary (appended raw) output: exact and compact; the series stay valid after every entry */
    if (fsdem_dem_write_walls_vtp(dem, "walls.vtp", FSDEM_VTK_FORMAT_APPENDED) != FSDEM_OK ||
        fsdem_pvd_open(&particles, "collapse.pvd") != FSDEM_OK || fsdem_pvd_open(&contacts, "contacts.pvd") != FSDEM_OK) {
        printf("cannot write the output files here\n");
        fsdem_dem_destroy(dem);
        return 1;
    }

    for (step = 0; step <= steps; ++step) {
        double t = fsdem_dem_time(dem);
        if (t >= frame * every - dt / 2) { /* progress line and snapshot every 0.05 s */
            fsdem_dem_particles p = fsdem_dem_get_particles(dem);
            fsdem_dem_energy e = fsdem_dem_get_energy(dem);
            fsdem_dem_stats st = fsdem_dem_get_stats(dem);
            double xs = 0, zs = 0;
            char path[64];
            int i;
            for (i = 0; i < p.count; ++i) {
                xs += p.position[i].x;
                zs += p.position[i].y; /* the paper's z is the vertical, y in fsdem 2D */
            }
            printf("%6.2f %9.4f %9.4f %12.4e %8d\n", t, xs / p.count, zs / p.count,
                   (double)(e.kinetic + e.rotational), st.contacts + st.wall_contacts);
            snprintf(path, sizeof path, "collapse_%03d.csv", frame);
            fsdem_dem_write_csv(dem, path);
            snprintf(path, sizeof path, "collapse_%03d.vtp", frame);
            fsdem_dem_write_vtp(dem, path, FSDEM_VTK_FORMAT_APPENDED);
            fsdem_pvd_add(&particles, t, path);
            snprintf(path, sizeof path, "contacts_%03d.vtp", frame);
            fsdem_dem_write_contacts_vtp(dem, path, FSDEM_VTK_FORMAT_APPENDED);
            fsdem_pvd_add(&contacts, t, path);
            frame++;
        }
        if (step < steps && fsdem_dem_step(dem) != FSDEM_OK) {
            printf("step failed: %s\n", fsdem_dem_last_error(dem));
            fsdem_pvd_close(&particles);
            fsdem_pvd_close(&contacts);
            fsdem_dem_destroy(dem);
            return 1;
        }
    }
    printf("wrote %d snapshots: collapse_000.csv/.vtp .. collapse_%03d.csv/.vtp, contacts_NNN.vtp, walls.vtp; "
           "series collapse.pvd, contacts.pvd\n",
           frame, frame - 1);
    fsdem_pvd_close(&particles);
    fsdem_pvd_close(&contacts);
    fsdem_dem_destroy(dem);
    return 0;
}
