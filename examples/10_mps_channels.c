/* 10_mps_channels: MPS boundaries that are not walls: a periodic channel and an open one.

   1. Plane Poiseuille flow. A 2D channel 0.3 m high between two particle walls, periodic along x
      (desc.periodic[0]: what leaves at x = 0.16 m comes back at x = 0), full of a viscous liquid
      (nu = 0.01 m^2/s) pushed along x by a body force of 0.1 m/s^2 from rest. The walls hold the
      liquid by the no-slip ghost velocities of desc.wall_viscosity. The liquid has no free surface,
      so its pressure is only known up to a constant (the solver sets the lowest to 0). Every 1.8 s
      the centre speed is printed against the parabola's, and poiseuille.csv holds the final
      profile (y, u_x of each particle, the parabola).
   2. An open channel. Water enters at x = 0 at 0.1 m/s from an inflow buffer
      (fsdem_mps_add_inflow) and leaves through an outflow plane at x = 0.3 m
      (fsdem_mps_add_outflow), between walls 0.1 m apart, without gravity; the particles that
      entered and left and the water between the planes are printed every 0.5 s.

   Run:  make examples && cd build/examples && ./10_mps_channels      (a few seconds)
   Build by hand: cc -std=c99 -O2 -I. examples/10_mps_channels.c -o mps_channels -lm */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <stdio.h>

/* Prints the solver's message and frees it; returns 1 for main. */
static int fail(fsdem_mps *mps) {
    fprintf(stderr, "%s\n", fsdem_mps_last_error(mps));
    fsdem_mps_destroy(mps);
    return 1;
}

static int poiseuille(void) {
    const double r0 = 0.01, H = 0.3, L = 0.16, nu = 0.01, g = 0.1;
    const double u_centre = g * H * H / (8 * nu); /* the parabola u = g/(2 nu) y (H - y) */
    /* the seed's scheme: an enclosed liquid, its pressure from the equation */
    fsdem_mps_desc desc = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_mps *mps;
    fsdem_mps_particles p;
    fsdem_csv csv;
    int k, i;
    desc.r0 = (fsdem_real)r0;
    desc.viscosity = (fsdem_real)nu;
    desc.gravity = fsdem_v3((fsdem_real)g, 0, 0); /* the body force drives the flow along x */
    desc.dt_max = 1;
    desc.periodic[0] = 1; /* period domain_max.x - domain_min.x = 16 r0 */
    desc.domain_min = fsdem_v3(0, -0.06, 0);
    desc.domain_max = fsdem_v3((fsdem_real)L, (fsdem_real)(H + 0.06), 0);
    if (fsdem_mps_create(&desc, &mps) != FSDEM_OK) return 1;
    /* walls below and above; the sides along x are open, so the walls meet across the seam */
    if (fsdem_mps_add_box_walls(mps, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)L, (fsdem_real)H, 0),
                                (1u << FSDEM_SIDE_XMIN) | (1u << FSDEM_SIDE_XMAX), NULL) != FSDEM_OK ||
        fsdem_mps_fill_box(mps, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)L, (fsdem_real)H, 0), fsdem_v3(0, 0, 0), NULL) != FSDEM_OK)
        return fail(mps);
    printf("periodic channel: Poiseuille flow from rest, centre speed against the parabola's %.4f m/s\n", u_centre);
    for (k = 1; k <= 5; ++k) {
        double centre = 0;
        int n = 0;
        if (fsdem_mps_advance(mps, 1.8f, NULL) != FSDEM_OK) return fail(mps);
        p = fsdem_mps_get_particles(mps);
        for (i = 0; i < p.count; ++i)
            if (p.kind[i] == FSDEM_MPS_KIND_FLUID && p.position[i].y > H / 2 - r0 && p.position[i].y < H / 2 + r0) {
                centre += p.velocity[i].x;
                ++n;
            }
        printf("  t = %4.1f s  centre %.4f m/s (%.1f %% of the parabola's)\n", fsdem_mps_time(mps), centre / n,
               100 * centre / n / u_centre);
    }
    if (fsdem_csv_open(&csv, "poiseuille.csv", "y,u_x,u_parabola") == FSDEM_OK) {
        p = fsdem_mps_get_particles(mps);
        for (i = 0; i < p.count; ++i)
            if (p.kind[i] == FSDEM_MPS_KIND_FLUID) {
                const double y = p.position[i].y;
                fsdem_real row[3];
                row[0] = (fsdem_real)y;
                row[1] = p.velocity[i].x;
                row[2] = (fsdem_real)(g / (2 * nu) * y * (H - y));
                fsdem_csv_row(&csv, row, 3);
            }
        fsdem_csv_close(&csv);
    }
    fsdem_mps_destroy(mps);
    return 0;
}

static int open_channel(void) {
    const double r0 = 0.01, H = 0.1, L = 0.3, U = 0.1, buffer = 5 * r0; /* ceil(re/r0) = 5 layers */
    /* the seed's scheme: without gravity the explicit scheme would need desc.sound_speed */
    fsdem_mps_desc desc = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_mps_inflow_desc in;
    fsdem_mps_outflow_desc out;
    fsdem_mps *mps;
    int k, i;
    desc.r0 = (fsdem_real)r0;
    desc.gravity = fsdem_v3(0, 0, 0);
    desc.domain_min = fsdem_v3(-0.1f, -0.1f, 0);
    desc.domain_max = fsdem_v3((fsdem_real)(L + 0.1), (fsdem_real)(H + 0.1), 0);
    if (fsdem_mps_create(&desc, &mps) != FSDEM_OK) return 1;
    /* the walls run on through the inflow buffer and the outflow zone */
    if (fsdem_mps_add_box_walls(mps, fsdem_v3((fsdem_real)-buffer, 0, 0), fsdem_v3((fsdem_real)(L + buffer), (fsdem_real)H, 0),
                                (1u << FSDEM_SIDE_XMIN) | (1u << FSDEM_SIDE_XMAX), NULL) != FSDEM_OK ||
        fsdem_mps_fill_box(mps, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)L, (fsdem_real)H, 0), fsdem_v3((fsdem_real)U, 0, 0), NULL) !=
            FSDEM_OK)
        return fail(mps);
    in = fsdem_mps_inflow_desc_default(); /* along +x */
    in.position = 0;
    in.lo = fsdem_v3(0, 0, 0);
    in.hi = fsdem_v3(0, (fsdem_real)H, 0);
    in.speed = (fsdem_real)U;
    out = fsdem_mps_outflow_desc_default();
    out.position = (fsdem_real)L;
    out.lo = fsdem_v3(0, 0, 0);
    out.hi = fsdem_v3(0, (fsdem_real)H, 0);
    if (fsdem_mps_add_inflow(mps, &in, NULL) != FSDEM_OK || fsdem_mps_add_outflow(mps, &out) != FSDEM_OK) return fail(mps);
    printf("open channel: water in at x = 0, out at x = %.1f m, at %.1f m/s\n", L, U);
    for (k = 1; k <= 4; ++k) {
        fsdem_mps_particles p;
        fsdem_mps_stats st;
        int between = 0;
        if (fsdem_mps_advance(mps, 0.5f, NULL) != FSDEM_OK) return fail(mps);
        p = fsdem_mps_get_particles(mps);
        st = fsdem_mps_get_stats(mps);
        for (i = 0; i < p.count; ++i)
            between += p.kind[i] == FSDEM_MPS_KIND_FLUID && p.inflow[i] < 0 && p.position[i].x >= 0 && p.position[i].x < L;
        printf("  t = %.1f s  %lld particles in, %lld out, %d between the planes (%.0f at the start)\n", fsdem_mps_time(mps),
               st.inflow_particles, st.outflow_particles, between, L * H / (r0 * r0));
    }
    fsdem_mps_destroy(mps);
    return 0;
}

int main(void) { return poiseuille() || open_channel(); }
