/* Still water in a closed tank, 2D and 3D: hydrostatic pressure, spurious velocity, volume drift.
   Usage: run [DATA_DIR] [--tier=default|full]   (the reference is analytic: p = rho g (h - y); no
   file is read; both tiers run the same)
   Writes hydrostatic_2d.csv / hydrostatic_3d.csv (time series) and profile_2d.csv / profile_3d.csv
   (pressure of the middle column against rho g (h - y)) into the working directory. */
#include "fsdem.h"
#include "common.h"

#define CASE "pic_hydrostatic"

static const double rho = 1000, g = 9.81, depth = 0.5, t_end = 2.0;

typedef struct outcome {
    double p_err;      /* max |p - rho g (h - y)| / (rho g h) over fluid cells at t_end */
    double u_max;      /* largest particle speed over [1 s, t_end] */
    double drift;      /* max |V(t)/V(0) - 1| */
    int failed;
} outcome;

/* Tank 1 m x 0.8 m (2D) or 0.4 x 0.32 x 0.8 m (3D), water 0.5 m deep, closed slip walls. */
static outcome run(int dim, double dx, double jitter, const char *tag) {
    fsdem_pic_desc d = fsdem_pic_desc_default(dim);
    fsdem_pic *s;
    fsdem_csv ts, pf;
    fsdem_pic_stats st;
    fsdem_pic_fields gr;
    outcome o = {0, 0, 0, 0};
    double v0, ref = rho * g * depth;
    int up = dim - 1, i, j, k, c, steps = 0;
    char path[64];
    d.cell_size = (fsdem_real)dx;
    d.jitter = (fsdem_real)jitter;
    d.density = (fsdem_real)rho;
    d.domain_max = dim == 2 ? fsdem_v3(1.0, 0.8, 0) : fsdem_v3(0.4, 0.32, 0.8);
    if (fsdem_pic_create(&d, &s) != FSDEM_OK) {
        o.failed = 1;
        return o;
    }
    if (fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), dim == 2 ? fsdem_v3(1.0, (fsdem_real)depth, 0) : fsdem_v3(0.4, 0.32, (fsdem_real)depth),
                           fsdem_v3(0, 0, 0), NULL) != FSDEM_OK) {
        o.failed = 1;
        fsdem_pic_destroy(s);
        return o;
    }
    v0 = (double)fsdem_pic_get_stats(s).fluid_volume;
    snprintf(path, sizeof path, "hydrostatic_%s.csv", tag);
    fsdem_csv_open(&ts, path, "t,max_speed,fluid_volume,kinetic_energy,pressure_iterations");
    while (fsdem_pic_time(s) < t_end - 1e-9) {
        fsdem_real row[5];
        fsdem_result r = fsdem_pic_advance(s, (fsdem_real)0.02, NULL);
        if (r != FSDEM_OK) {
            fprintf(stderr, "%s: %s\n", tag, fsdem_pic_last_error(s));
            o.failed = 1;
            break;
        }
        steps++;
        st = fsdem_pic_get_stats(s);
        if (st.time > 1.0 - 1e-9 && st.max_speed > o.u_max) o.u_max = st.max_speed;
        if (fabs(st.fluid_volume / v0 - 1) > o.drift) o.drift = fabs(st.fluid_volume / v0 - 1);
        row[0] = st.time;
        row[1] = st.max_speed;
        row[2] = st.fluid_volume;
        row[3] = st.kinetic_energy;
        row[4] = (fsdem_real)st.pressure_iterations;
        fsdem_csv_row(&ts, row, 5);
    }
    fsdem_csv_close(&ts);
    gr = fsdem_pic_get_fields(s);
    snprintf(path, sizeof path, "profile_%s.csv", tag);
    fsdem_csv_open(&pf, path, "y,p,p_ref");
    for (k = 0; k < gr.n[2]; ++k)
        for (j = 0; j < gr.n[1]; ++j)
            for (i = 0; i < gr.n[0]; ++i) {
                double y, pref;
                int h = up == 1 ? j : k;
                c = (k * gr.n[1] + j) * gr.n[0] + i;
                if (gr.cell[c] != FSDEM_STENCIL_CELL_FLUID) continue;
                y = (h + 0.5) * gr.cell_size;
                pref = rho * g * (depth - y);
                if (fabs(gr.pressure[c] - pref) / ref > o.p_err) o.p_err = fabs(gr.pressure[c] - pref) / ref;
                if (i == gr.n[0] / 2 && (dim == 2 || j == gr.n[1] / 2)) {
                    fsdem_real row[3];
                    row[0] = (fsdem_real)y;
                    row[1] = gr.pressure[c];
                    row[2] = (fsdem_real)pref;
                    fsdem_csv_row(&pf, row, 3);
                }
            }
    fsdem_csv_close(&pf);
    st = fsdem_pic_get_stats(s);
    vc_info(CASE, "%s: dx %g m, %d particles, %lld steps, %.2f s CPU (pressure %.2f s), jitter %g", tag, dx, st.particles,
            st.steps, st.seconds_total, st.seconds_pressure, jitter);
    (void)steps;
    fsdem_pic_destroy(s);
    return o;
}

int main(int argc, char **argv) {
    int dim;
    vc_begin(CASE, argc, argv, NULL);
    vc_tier("dx 0.02 m (2D), 0.04 m (3D), 2 s");
    for (dim = 2; dim <= 3; ++dim) {
        const char *tag = dim == 2 ? "2d" : "3d";
        char metric[64];
        outcome o = run(dim, dim == 2 ? 0.02 : 0.04, 0.0, tag), oj;
        snprintf(metric, sizeof metric, "%s_run_completed", tag);
        vc_check(CASE, metric, o.failed ? 0 : 1, 1, 0);
        snprintf(metric, sizeof metric, "%s_pressure_max_rel_error", tag);
        vc_check(CASE, metric, o.p_err, 0, 0.01);
        snprintf(metric, sizeof metric, "%s_spurious_velocity_m_s", tag);
        vc_check(CASE, metric, o.u_max, 0, 1e-3);
        snprintf(metric, sizeof metric, "%s_volume_drift", tag);
        vc_check(CASE, metric, o.drift, 0, 1e-3);
        /* seeds jittered by half their spacing (the default until issue 38; now 0): the reconstructed
           surface is then rough at the scale of a cell and relaxes as small waves; reported, not checked */
        oj = run(dim, dim == 2 ? 0.02 : 0.04, 0.5, dim == 2 ? "2d_jitter" : "3d_jitter");
        vc_info(CASE, "%s with jittered seeding (jitter 0.5): pressure error %.4f of rho g h, speed %.3g m/s, volume drift %.2e",
                tag, oj.p_err, oj.u_max, oj.drift);
    }
    return vc_exit_code();
}
