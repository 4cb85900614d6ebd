/* 04_pic_dambreak: a 2D dam break with the PIC/FLIP solver, written for ParaView.

   A water column 0.2 m x 0.4 m collapses in a 1 m x 0.5 m tank with a submerged disc. Every 0.02 s
   the particles (particles_NNNN.vtp) and the grid (grid_NNNN.vti: pressure, phi, velocity, cell
   type) are written, listed in particles.pvd and grid.pvd (File > Open the .pvd in ParaView, then
   play; the series are valid while the run goes on); the last frame is the final state at t = 1 s, also written as final_particles.csv
   (x,y,z,vx,vy,vz). timeseries.csv holds t, fluid volume, kinetic energy and the pressure
   iterations. Progress (time, steps, front position, kinetic energy, CPU time) is printed every
   0.1 s. The time step is the solver's adaptive one (fsdem_pic_advance: CFL 1 by default).
   The VTK files are binary (appended raw data): exact, smaller and faster to write than ASCII;
   pass FSDEM_VTK_FORMAT_ASCII to read them in an editor.

   Run:  make examples && cd build/examples && ./04_pic_dambreak      (about 15 s; ~70 MB of ASCII files)
   Build by hand: cc -std=c99 -O2 -I. examples/04_pic_dambreak.c -o dambreak -lm */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <stdio.h>

/* Writes one frame (particles and grid) and lists it in the two series. */
static void write_frame(fsdem_pic *pic, fsdem_pvd *particles, fsdem_pvd *grid, int frame) {
    char name[64];
    double t = fsdem_pic_time(pic);
    snprintf(name, sizeof name, "particles_%04d.vtp", frame);
    if (fsdem_pic_write_particles_vtp(pic, name, FSDEM_VTK_FORMAT_APPENDED) == FSDEM_OK) fsdem_pvd_add(particles, t, name);
    snprintf(name, sizeof name, "grid_%04d.vti", frame);
    if (fsdem_pic_write_grid_vti(pic, name, FSDEM_VTK_FORMAT_APPENDED) == FSDEM_OK) fsdem_pvd_add(grid, t, name);
}

/* Surge front: the largest x of a particle lying within the lowest 2 cm of the tank. */
static double front(fsdem_pic *pic) {
    fsdem_pic_particles p = fsdem_pic_get_particles(pic);
    double x = 0;
    int i;
    for (i = 0; i < p.count; ++i)
        if (p.position[i].y < 0.02 && p.position[i].x > x) x = p.position[i].x;
    return x;
}

int main(void) {
    const double t_end = 1.0, frame_every = 0.02;
    fsdem_pic_desc desc = fsdem_pic_desc_default(2); /* x-y plane, gravity -y */
    fsdem_pic *pic;
    fsdem_pic_obstacle disc = fsdem_pic_obstacle_sphere(fsdem_v3(0.6, 0.08, 0), 0.06);
    fsdem_pvd particles, grid;
    fsdem_csv series;
    fsdem_pic_stats st;
    int frame = 0, status = 0;

    desc.domain_max = fsdem_v3(1.0, 0.5, 0);
    desc.cell_size = 0.005; /* 200 x 100 cells */
    if (fsdem_pic_create(&desc, &pic) != FSDEM_OK) {
        char why[256];
        fsdem_pic_desc_check(&desc, why, sizeof why);
        fprintf(stderr, "%s\n", why);
        return 1;
    }
    if (fsdem_pic_add_obstacle(pic, &disc, NULL) != FSDEM_OK ||
        fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3(0.2, 0.4, 0), fsdem_v3(0, 0, 0), NULL) != FSDEM_OK) {
        fprintf(stderr, "%s\n", fsdem_pic_last_error(pic));
        fsdem_pic_destroy(pic);
        return 1;
    }
    if (fsdem_pvd_open(&particles, "particles.pvd") != FSDEM_OK || fsdem_pvd_open(&grid, "grid.pvd") != FSDEM_OK ||
        fsdem_csv_open(&series, "timeseries.csv", "t,fluid_volume,kinetic_energy,pressure_iterations") != FSDEM_OK) {
        fprintf(stderr, "cannot write the output files in this folder\n");
        fsdem_pic_destroy(pic);
        return 1;
    }
    printf("2D dam break, %d particles on 200 x 100 cells, to t = %.1f s\n", fsdem_pic_get_stats(pic).particles, t_end);
    printf("%6s %7s %9s %12s %9s\n", "t (s)", "steps", "front (m)", "KE (J/m)", "CPU (s)");
    for (;;) {
        fsdem_real row[4];
        st = fsdem_pic_get_stats(pic);
        row[0] = (fsdem_real)st.time;
        row[1] = st.fluid_volume;
        row[2] = st.kinetic_energy;
        row[3] = (fsdem_real)st.pressure_iterations;
        fsdem_csv_row(&series, row, 4);
        write_frame(pic, &particles, &grid, frame);
        if (frame % 5 == 0)
            printf("%6.2f %7lld %9.3f %12.4g %9.1f\n", st.time, st.steps, front(pic), (double)st.kinetic_energy,
                   st.seconds_total);
        fflush(stdout);
        if (frame * frame_every >= t_end - 1e-9) break; /* the final state is written */
        frame++;
        /* adaptive steps (CFL 1) up to the next frame, the last one shortened to land on it */
        if (fsdem_pic_advance(pic, (fsdem_real)frame_every, NULL) != FSDEM_OK) {
            fprintf(stderr, "step failed at t = %.4f s: %s\n", fsdem_pic_time(pic), fsdem_pic_last_error(pic));
            status = 1;
            break;
        }
    }
    if (fsdem_pic_write_particles_csv(pic, "final_particles.csv") != FSDEM_OK) status = 1;
    st = fsdem_pic_get_stats(pic);
    printf("%d frames, %lld steps, %d particles, volume %.5f m^2 (particles %.5f m^2), %.1f s CPU\n", frame + 1,
           st.steps, st.particles, (double)st.fluid_volume, (double)st.particle_volume, st.seconds_total);
    printf("wrote particles.pvd, grid.pvd (ParaView), timeseries.csv, final_particles.csv\n");
    fsdem_csv_close(&series);
    fsdem_pvd_close(&particles);
    fsdem_pvd_close(&grid);
    fsdem_pic_destroy(pic);
    return status;
}
