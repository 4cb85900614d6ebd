/* validation/swe_debris_dambreak: seed 003's dam-break flume with one floating debris piece.
   35.5 m x 1 m flume (1D SWE, width 1 m), gate at x_g = 15 m, upstream/downstream depths 0.2/0,
   0.2/0.1 and 0.3/0.1 m; one debris piece (a sphere, r = 4 cm, 600 kg/m^3) 0.75 m downstream of the
   gate, resting on the bed (dry case) or floating. Checks that the debris starts moving when the wave
   front reaches it, and that the depth at the gate matches the exact (Ritter/Stoker) dam-break value
   before reflections. Usage: run [DATA_DIR] [--tier=default|full] (no data file is read; both tiers
   run the same). Writes gauges_<case>.csv and debris_<case>.csv. See README.md. */
#include "fsdem.h"
#include "common.h"

#define CASE "swe_debris_dambreak"
#define G 9.81

static const double length = 35.5, x_gate = 15, debris_offset = 0.75, r = 0.04, rho_s = 600;
static const int nx = 710; /* 5 cm cells */

/* Exact depth at the gate (x = x0) of a dam break h_L | h_R, and the front (dry) or shock (wet)
   speed: Ritter for h_R = 0; Stoker otherwise, c_m the root of
   c^6 - 9 c_R^2 c^4 + 16 c_L c_R^2 c^3 - c_R^2 (c_R^2 + 8 c_L^2) c^2 + c_R^6 = 0 in (c_R, c_L)
   (validation/data/README.md, "Ritter and Stoker"). The gate lies in the rarefaction (h = 4/9 h_L)
   when 2 c_L - 3 c_m > 0. */
static void dambreak_exact(double hl, double hr, double *h_gate, double *front_speed) {
    double cl = sqrt(G * hl), cr = sqrt(G * hr), lo = cr, hi = cl, cm, hm, um;
    int it;
    if (hr == 0) {
        *h_gate = 4.0 / 9.0 * hl;
        *front_speed = 2 * cl;
        return;
    }
    for (it = 0; it < 200; ++it) {
        double c = 0.5 * (lo + hi), c2 = c * c;
        double f = c2 * c2 * c2 - 9 * cr * cr * c2 * c2 + 16 * cl * cr * cr * c2 * c - cr * cr * (cr * cr + 8 * cl * cl) * c2 +
                   cr * cr * cr * cr * cr * cr;
        /* f < 0 between c_R and the root (checked numerically for these cases) */
        if (f < 0) lo = c;
        else hi = c;
    }
    cm = 0.5 * (lo + hi);
    hm = cm * cm / G;
    um = 2 * (cl - cm);
    *h_gate = 2 * cl - 3 * cm > 0 ? 4.0 / 9.0 * hl : hm;
    *front_speed = hm * um / (hm - hr);
}

/* Runs one case with the given slope limiter; checks it when `checked`, otherwise only reports it.
   Returns 0 on success, 2 when a create or step fails. */
static int run_case(const char *name, double hl, double hr, fsdem_swe_limiter limiter, int checked) {
    fsdem_swe_desc sd = fsdem_swe_desc_default(1);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_swe_dem_desc cd = fsdem_swe_dem_desc_default();
    fsdem_dem_material wood = fsdem_dem_material_default();
    fsdem_dem_particle_desc debris = fsdem_dem_particle_desc_default();
    fsdem_dem_wall_desc bed;
    fsdem_swe *swe;
    fsdem_dem *dem;
    fsdem_swe_dem *cpl;
    fsdem_csv gauges, track;
    fsdem_real depth[710], dt_dem = 0;
    char path[128];
    const double x_debris = x_gate + debris_offset, dx = length / nx;
    double h_gate_exact, speed, t = 0, t_front = -1, t_move = -1, t_visible = -1, gate_err_sum = 0, draft_z;
    int k, mat, gate_samples = 0;
    dambreak_exact(hl, hr, &h_gate_exact, &speed);

    sd.nx = nx;
    sd.limiter = limiter;
    sd.x_max = length;
    for (k = 0; k < nx; ++k) depth[k] = (k + 0.5) * dx < x_gate ? hl : hr;
    sd.depth = depth;
    if (fsdem_swe_create(&sd, &swe) != FSDEM_OK) return 2;

    dd.domain_min = fsdem_v3(0, -0.5, -0.5);
    dd.domain_max = fsdem_v3(length, 0.5, 1.5);
    dd.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    if (fsdem_dem_create(&dd, &dem) != FSDEM_OK) return 2;
    wood.density = rho_s;
    wood.young_modulus = 1e8;
    wood.restitution = 0.5;
    wood.friction = 0.3;
    fsdem_dem_add_material(dem, &wood, &mat);
    bed = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), mat); /* the flat flume bed */
    fsdem_dem_add_wall(dem, &bed, NULL);
    /* resting on the bed when dry; floating at its draft when wet (cap volume = 0.6 sphere volume,
       s = 0.0456 m for r = 0.04, found by bisection below) */
    draft_z = r;
    if (hr > 0) {
        double lo = 0, hi = 2 * r;
        for (k = 0; k < 100; ++k) {
            double s = 0.5 * (lo + hi);
            if (s * s * (3 * r - s) < rho_s / 1000 * 4 * r * r * r) lo = s;
            else hi = s;
        }
        draft_z = hr - 0.5 * (lo + hi) + r;
    }
    debris.position = fsdem_v3(x_debris, 0, draft_z);
    debris.radius = r;
    debris.material = mat;
    if (fsdem_dem_add_particle(dem, &debris, NULL) != FSDEM_OK || fsdem_dem_stable_dt(dem, &dt_dem) != FSDEM_OK ||
        fsdem_dem_set_dt(dem, dt_dem) != FSDEM_OK) { /* Hertz: 0.2 x the Rayleigh time */
        fprintf(stderr, "%s: %s\n", name, fsdem_dem_last_error(dem));
        return 2;
    }

    cd.swe = swe;
    cd.dem = dem;
    cd.heave_damping = 0.5; /* bobbing is not resolved by the SWE; damp it (see README) */
    if (fsdem_swe_dem_create(&cd, &cpl) != FSDEM_OK) return 2;

    snprintf(path, sizeof path, "gauges_%s%s.csv", name, checked ? "" : "_minmod");
    fsdem_csv_open(&gauges, path, "t,h_gate,h_gate_exact,h_debris,h_x20,h_x25");
    snprintf(path, sizeof path, "debris_%s%s.csv", name, checked ? "" : "_minmod");
    fsdem_csv_open(&track, path, "t,x,z,u");
    /* run until just before the first reflection: the rarefaction head (speed sqrt(g h_L)) meets the
       upstream wall at x_g / c_L, the front/shock the downstream wall at (L - x_g)/speed */
    {
        const double t_end = fmin(x_gate / sqrt(G * hl), (length - x_gate) / speed) * 0.95;
        double next_out = 0;
        while (t < t_end) {
            fsdem_swe_cell at_gate, at_back, a20, a25;
            fsdem_dem_particles p = fsdem_dem_get_particles(dem);
            fsdem_swe_sample_state(swe, x_gate, 0, &at_gate);
            fsdem_swe_sample_state(swe, x_debris - r, 0, &at_back);
            /* the front reaches the debris's back when the depth there first rises 1e-3 h_L above its
               initial value (the front threshold, on a dry or a wet bed alike) */
            if (t_front < 0 && at_back.depth > hr + 1e-3 * hl) t_front = t;
            /* Nothing but the water moves the debris sideways (its x stays exactly x_debris until then),
               so the first horizontal displacement marks the start; 1e-6 m is 1/40000 of its radius.
               The time it has moved 0.1 mm is reported too: a sphere on a dry bed starts rolling under
               the thin Ritter tongue, whose push grows like h^1.5, so a visible move comes later. */
            if (t_move < 0 && fabs(p.position[0].x - x_debris) > 1e-6) t_move = t;
            if (t_visible < 0 && fabs(p.position[0].x - x_debris) > 1e-4) t_visible = t;
            if (t >= 1.0) { /* past the start-up of the numerical fan */
                gate_err_sum += fabs(at_gate.depth - h_gate_exact) / h_gate_exact;
                gate_samples++;
            }
            if (t >= next_out) {
                fsdem_real g[6], d[4];
                fsdem_swe_sample_state(swe, 20, 0, &a20);
                fsdem_swe_sample_state(swe, 25, 0, &a25);
                g[0] = t; g[1] = at_gate.depth; g[2] = h_gate_exact; g[3] = at_back.depth; g[4] = a20.depth; g[5] = a25.depth;
                fsdem_csv_row(&gauges, g, 6);
                d[0] = t; d[1] = p.position[0].x; d[2] = p.position[0].z; d[3] = p.velocity[0].x;
                fsdem_csv_row(&track, d, 4);
                next_out += 0.02;
            }
            if (fsdem_swe_dem_step(cpl) != FSDEM_OK) {
                printf("case %s: %s\n", name, fsdem_swe_dem_last_error(cpl));
                return 2;
            }
            t += fsdem_swe_dem_get_stats(cpl).coupling.dt;
        }
    }
    fsdem_csv_close(&gauges);
    fsdem_csv_close(&track);
    vc_info(CASE, "%s (%s limiter): front at the debris t = %.3f s, debris moves from t = %.3f s (0.1 mm at %.3f s), "
                  "start delay %+.3f s, x(end) = %.3f m; exact gate depth %.4f m, front/shock speed %.3f m/s",
            name, limiter == FSDEM_SWE_LIMITER_MC ? "MC" : "minmod", t_front, t_move, t_visible, t_move - t_front,
            (double)fsdem_dem_get_particles(dem).position[0].x, h_gate_exact, speed);
    if (checked) {
        char metric[64];
        /* moving within the front's transit time over one cell, dx / speed */
        snprintf(metric, sizeof metric, "%s_start_delay_s", name);
        vc_check(CASE, metric, t_front >= 0 && t_move >= 0 ? t_move - t_front : 1e9, 0, dx / speed);
        /* mean relative depth error at the gate from 1 s to the first reflection; 5% is the issue's
           bound (a second-order scheme on 5 cm cells smears the fan edges, not its centre) */
        snprintf(metric, sizeof metric, "%s_gate_depth_rel_error", name);
        vc_check(CASE, metric, gate_samples ? gate_err_sum / gate_samples : 1e9, 0, 0.05);
    }
    fsdem_swe_dem_destroy(cpl);
    fsdem_dem_destroy(dem);
    fsdem_swe_destroy(swe);
    return 0;
}

int main(int argc, char **argv) {
    /* The checked runs use the MC limiter. A bore rises from 10% to 90% over 2 cells with either
       limiter, but minmod's foot is longer: its 1e-5 h_L precursor runs 3 cells ahead of the 1e-3 h_L
       front, against 1 cell with MC, and a floating sphere feels it. Minmod is reported (README). */
    static const struct { const char *name; double hl, hr; } cases[] = {{"h0.2_0", 0.2, 0}, {"h0.2_0.1", 0.2, 0.1},
                                                                         {"h0.3_0.1", 0.3, 0.1}};
    int k;
    vc_begin(CASE, argc, argv, NULL);
    vc_tier("%d cells of 5 cm, 3 depth pairs", nx);
    for (k = 0; k < 3; ++k)
        if (run_case(cases[k].name, cases[k].hl, cases[k].hr, FSDEM_SWE_LIMITER_MC, 1) ||
            run_case(cases[k].name, cases[k].hl, cases[k].hr, FSDEM_SWE_LIMITER_MINMOD, 0))
            return 2;
    return vc_exit_code();
}
