/* 07_mps_dambreak: a 2D dam break with the MPS particle solver, written for ParaView.

   A water column 0.1 m wide and 0.2 m high collapses in a tank 0.4 m long (the walls are particles
   too: one WALL layer whose pressure is solved with the water's, and DUMMY layers behind it). Every
   0.01 s the particles are written (mps_NNNN.vtp: kind, pressure, velocity, number density, surface
   flag) and listed in mps.pvd: open mps.pvd in ParaView, apply Threshold on "kind" (0 = water) and
   press play; the series is valid while the run goes on. front.csv holds t, the surge front (the
   largest x of a water particle) and the water level at the left wall (fsdem_mps_probe_height).
   Progress (time, steps, front, largest speed, PCG iterations, CPU time) is printed every 0.05 s.
   The time step is the solver's adaptive one (fsdem_mps_advance; Courant number desc.cfl on the
   sound speed of the default, weakly compressible scheme). The run stops at t = 0.5 s, after the
   surge has run up the far wall and come back. The run-up throws single particles high (one
   passes 0.6 m, three times the column, at t = 0.44 s), so the domain reaches 1 m; a particle
   leaving it fails the step, which is reported with the solver's message.

   Run:  make examples && cd build/examples && ./07_mps_dambreak      (about 7 s; ~8 MB of files)
   Build by hand: cc -std=c99 -O2 -I. examples/07_mps_dambreak.c -o mps_dambreak -lm */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <stdio.h>

/* Writes the particles of this frame and lists the file in the series. */
static void write_frame(fsdem_mps *mps, fsdem_pvd *series, int frame) {
    char name[64];
    snprintf(name, sizeof name, "mps_%04d.vtp", frame);
    if (fsdem_mps_write_vtp(mps, name, FSDEM_VTK_FORMAT_APPENDED) == FSDEM_OK) fsdem_pvd_add(series, fsdem_mps_time(mps), name);
}

/* Surge front: the largest x of a water particle. */
static double front(fsdem_mps *mps) {
    fsdem_mps_particles p = fsdem_mps_get_particles(mps);
    double x = 0;
    int i;
    for (i = 0; i < p.count; ++i)
        if (p.kind[i] == FSDEM_MPS_KIND_FLUID && p.position[i].x > x) x = p.position[i].x;
    return x;
}

int main(void) {
    const double t_end = 0.5, frame_every = 0.01;
    const double r0 = 0.005;                       /* particle spacing: 20 x 40 water particles */
    fsdem_mps_desc desc = fsdem_mps_desc_default(2); /* x-y plane, gravity -y, water */
    fsdem_mps *mps;
    fsdem_pvd series;
    fsdem_csv csv;
    fsdem_mps_stats st;
    int frame = 0, status = 0, walls = 0, water = 0;

    desc.r0 = (fsdem_real)r0;
    /* every particle must stay inside the domain: the walls are 3 particles thick (1 WALL + 2
       DUMMY layers for the default re = 2.8 r0) and the splash rises above the tank */
    desc.domain_min = fsdem_v3(-0.05, -0.05, 0);
    desc.domain_max = fsdem_v3(0.45, 1.0, 0);
    if (fsdem_mps_create(&desc, &mps) != FSDEM_OK) {
        char why[256];
        fsdem_mps_desc_check(&desc, why, sizeof why);
        fprintf(stderr, "%s\n", why);
        return 1;
    }
    /* tank [0, 0.4] x [0, 0.3], open at the top; then the water column on the same lattice */
    if (fsdem_mps_add_box_walls(mps, fsdem_v3(0, 0, 0), fsdem_v3(0.4, 0.3, 0), 1u << FSDEM_SIDE_YMAX, &walls) != FSDEM_OK ||
        fsdem_mps_fill_box(mps, fsdem_v3(0, 0, 0), fsdem_v3(0.1, 0.2, 0), fsdem_v3(0, 0, 0), &water) != FSDEM_OK) {
        fprintf(stderr, "%s\n", fsdem_mps_last_error(mps));
        fsdem_mps_destroy(mps);
        return 1;
    }
    if (fsdem_pvd_open(&series, "mps.pvd") != FSDEM_OK ||
        fsdem_csv_open(&csv, "front.csv", "t,x_front,level_at_left_wall") != FSDEM_OK) {
        fprintf(stderr, "cannot write the output files in this folder\n");
        fsdem_mps_destroy(mps);
        return 1;
    }
    printf("2D MPS dam break: %d water and %d wall particles, r0 = %g m, to t = %.1f s\n", water, walls, r0, t_end);
    printf("%6s %7s %9s %9s %5s %8s\n", "t (s)", "steps", "front (m)", "u_max", "PCG", "CPU (s)");
    for (;;) {
        fsdem_real row[3], level = 0;
        st = fsdem_mps_get_stats(mps);
        /* water level on the vertical line one spacing from the left wall */
        fsdem_mps_probe_height(mps, fsdem_v3((fsdem_real)r0, 0, 0), &level);
        row[0] = (fsdem_real)st.time;
        row[1] = (fsdem_real)front(mps);
        row[2] = level;
        fsdem_csv_row(&csv, row, 3);
        write_frame(mps, &series, frame);
        if (frame % 5 == 0)
            printf("%6.2f %7lld %9.3f %9.3f %5d %8.1f\n", st.time, st.steps, (double)row[1], (double)st.max_speed,
                   st.pressure_iterations, st.seconds_total);
        fflush(stdout);
        if (frame * frame_every >= t_end - 1e-9) break; /* the final state is written */
        frame++;
        /* adaptive steps up to the next frame, the last one shortened to land on it */
        if (fsdem_mps_advance(mps, (fsdem_real)frame_every, NULL) != FSDEM_OK) {
            fprintf(stderr, "step failed at t = %.4f s: %s\n", fsdem_mps_time(mps), fsdem_mps_last_error(mps));
            status = 1;
            break;
        }
    }
    st = fsdem_mps_get_stats(mps);
    printf("%d frames, %lld steps, %.1f PCG iterations per step, %.1f s CPU\n", frame + 1, st.steps,
           st.steps ? (double)st.pressure_iterations_total / (double)st.steps : 0.0, st.seconds_total);
    printf("wrote mps.pvd (ParaView) with mps_*.vtp, and front.csv\n");
    fsdem_csv_close(&csv);
    fsdem_pvd_close(&series);
    fsdem_mps_destroy(mps);
    return status;
}
