/* Dam break through layers of aluminium cylinders (seed 000 section 3.2, after Zhang et al. 2009),
   resolved PIC-DEM in 2D: 6, 8, 10 and 12 layers, each with the gap treatment of Eq. 20 (beta = 0.5)
   and without it (beta = 1). The set-up is case.h's (README.md).
   Usage: run [DATA_DIR] [--tier=default|full] [--dx M] [--t-end S] [--layers N] [--beta B]
     DATA_DIR  ignored (no reference file is read: no digitised data exist, see README.md)
     --tier=full  the seed's grid, dx = 0.05 cm, 0.6 s per run (--seed is the same); the default
               tier: dx = 0.125 cm, 0.4 s per run (README.md, "Tiers")
     --dx M    another cell size (m)
     --t-end S simulated time per run (default 0.6 s)
     --layers N only the runs with N layers (the checks that compare layer counts are then skipped)
     --beta B  only the runs with beta = B (0.5 or 1; the checks that compare betas are then skipped)
   Writes, per run, cylinders_<layers>_b<beta>.csv (t, x_ave, z_ave, x_max, water front, volume
   drift) and, for 6 and 12 layers, snapshots at t = 0, 0.1, 0.2, 0.3, 0.4 s: water_<layers>_b<beta>
   _<t>.csv / .vtp (PIC particles) and cylinders_<layers>_b<beta>_<t>.csv / .vtp (DEM particles). */
#include "fsdem.h"
#include "common.h"
#include "picdem_cylinder_dambreak/case.h"

#include <time.h>

#define CASE "picdem_cylinder_dambreak"
#define NSNAP 5
#define DEFAULT_DX 0.00125 /* m, the default tier's grid (README.md, "Tiers") */
#define DEFAULT_T_END 0.4  /* s per run in the default tier: after every arrival (README.md, "Tiers") */

static const double snap_times[NSNAP] = {0, 0.1, 0.2, 0.3, 0.4};
static const double front_times[3] = {0.1, 0.2, 0.3};

typedef struct result {
    int layers;
    double beta;
    int failed, outside;
    double arrival;           /* s; first contact of a cylinder with the right wall; -1: none */
    double front_arrival;     /* s; water front at the right wall; -1: none */
    double front[3];          /* m; water front at front_times */
    double x_ave_end, z_ave_end;
    double drift;             /* largest |V/V0 - 1| of the particle volume */
    double max_overlap;       /* m; largest DEM overlap seen after a coupled step */
    long long steps, substeps;
    double cpu, cpu_pic, cpu_dem, cpu_coupling;
    int water_particles, cylinders;
} result;

static void snapshot(const wd_case *c, const char *tag, double t) {
    char path[160];
    snprintf(path, sizeof path, "water_%s_%.2f.csv", tag, t);
    fsdem_pic_write_particles_csv(c->pic, path);
    snprintf(path, sizeof path, "water_%s_%.2f.vtp", tag, t);
    fsdem_pic_write_particles_vtp(c->pic, path, FSDEM_VTK_FORMAT_APPENDED);
    snprintf(path, sizeof path, "cylinders_%s_%.2f.csv", tag, t);
    fsdem_dem_write_csv(c->dem, path);
    snprintf(path, sizeof path, "cylinders_%s_%.2f.vtp", tag, t);
    fsdem_dem_write_vtp(c->dem, path, FSDEM_VTK_FORMAT_APPENDED);
}

static void run(double dx, int layers, double beta, double t_end, result *res) {
    wd_case c;
    fsdem_csv csv;
    char tag[64], path[128];
    double next_row = 0, every = 1e-3;
    int next_snap = 0, next_front = 0, snaps = layers == 6 || layers == 12;
    clock_t t0 = clock();
    memset(res, 0, sizeof *res);
    res->layers = layers;
    res->beta = beta;
    res->arrival = res->front_arrival = -1;
    if (wd_create(&c, dx, layers, beta) != 0) {
        fprintf(stderr, "%s: %d layers, beta %g: %s\n", CASE, layers, beta, c.error);
        res->failed = 1;
        return;
    }
    res->water_particles = c.water_particles;
    res->cylinders = c.cylinders;
    snprintf(tag, sizeof tag, "%d_b%.1f", layers, beta);
    vc_info(CASE, "L%d beta %.1f: %d cylinders, %d water particles, plate at x = %.4f m, dx = %g m, gap %g m, DEM dt %.3g s", layers,
            beta, c.cylinders, c.water_particles, c.plate, dx, c.gap, c.dem_dt);
    snprintf(path, sizeof path, "cylinders_%s.csv", tag);
    fsdem_csv_open(&csv, path, "t,x_ave,z_ave,x_max,water_front,volume_drift");
    for (;;) {
        const double t = fsdem_pic_dem_time(c.cpl);
        const fsdem_pic_stats ps = fsdem_pic_get_stats(c.pic);
        const double drift = (double)ps.particle_volume / c.volume0 - 1;
        const double overlap = (double)fsdem_dem_get_stats(c.dem).max_overlap;
        const double front = wd_front(&c);
        double target = t_end;
        int k;
        fsdem_result r;
        if (fabs(drift) > res->drift) res->drift = fabs(drift);
        if (overlap > res->max_overlap) res->max_overlap = overlap;
        if ((k = wd_outside(&c)) > res->outside) res->outside = k;
        if (res->arrival < 0 && wd_at_right_wall(&c)) res->arrival = t;
        if (res->front_arrival < 0 && front >= WD_TANK - 0.5 * dx) res->front_arrival = t;
        while (next_front < 3 && t >= front_times[next_front] - 1e-9) res->front[next_front++] = front;
        if (t >= next_row - 1e-9 || t >= t_end - 1e-9) {
            fsdem_real row[6];
            double xa, za, xm;
            wd_centres(&c, &xa, &za, &xm);
            row[0] = (fsdem_real)t;
            row[1] = (fsdem_real)xa;
            row[2] = (fsdem_real)za;
            row[3] = (fsdem_real)xm;
            row[4] = (fsdem_real)front;
            row[5] = (fsdem_real)drift;
            fsdem_csv_row(&csv, row, 6);
            while (next_row <= t + 1e-9) next_row += every;
        }
        if (next_snap < NSNAP && t >= snap_times[next_snap] - 1e-9) {
            if (snaps) snapshot(&c, tag, snap_times[next_snap]);
            next_snap++;
        }
        if (t >= t_end - 1e-9) break;
        if (next_snap < NSNAP && snap_times[next_snap] < target) target = snap_times[next_snap];
        if ((r = wd_step_until(&c, target)) != FSDEM_OK) {
            fprintf(stderr, "%s: %d layers, beta %g, t = %.4f s: %s\n", CASE, layers, beta, fsdem_pic_dem_time(c.cpl), wd_last_error(&c));
            res->failed = 1;
            break;
        }
    }
    fsdem_csv_close(&csv);
    wd_centres(&c, &res->x_ave_end, &res->z_ave_end, &next_row);
    {
        fsdem_pic_dem_stats s = fsdem_pic_dem_get_stats(c.cpl);
        res->steps = s.coupling.steps;
        res->substeps = s.coupling.substeps_total;
        res->cpu_pic = s.coupling.seconds_fluid;
        res->cpu_dem = s.coupling.seconds_dem;
        res->cpu_coupling = s.coupling.seconds_coupling;
    }
    res->cpu = (double)(clock() - t0) / CLOCKS_PER_SEC;
    wd_destroy(&c);
}

static void report(const result *r, double dx, double t_end) {
    char metric[128];
    const char *b = r->beta < 0.75 ? "b05" : "b1";
    snprintf(metric, sizeof metric, "L%d_%s_run_completed", r->layers, b);
    vc_check(CASE, metric, r->failed ? 0 : 1, 1, 0);
    snprintf(metric, sizeof metric, "L%d_%s_volume_drift", r->layers, b);
    vc_check(CASE, metric, r->drift, 0, 0.005);
    snprintf(metric, sizeof metric, "L%d_%s_cylinders_outside_tank", r->layers, b);
    vc_check(CASE, metric, r->outside, 0, 0);
    snprintf(metric, sizeof metric, "L%d_%s_max_overlap_m", r->layers, b);
    vc_check(CASE, metric, r->max_overlap, 0, 2 * dx);
    if (r->arrival >= 0)
        vc_info(CASE, "L%d beta %.1f: first cylinder at the right wall at t = %.4f s", r->layers, r->beta, r->arrival);
    else
        vc_info(CASE, "L%d beta %.1f: no cylinder reached the right wall by t = %.2f s", r->layers, r->beta, t_end);
    vc_info(CASE, "L%d beta %.1f: water front %.4f / %.4f / %.4f m at t = 0.1 / 0.2 / 0.3 s, at the right wall at t = %.4f s",
            r->layers, r->beta, r->front[0], r->front[1], r->front[2], r->front_arrival);
    vc_info(CASE, "L%d beta %.1f: at t = %.2f s x_ave = %.4f m, z_ave = %.4f m; largest overlap %.3g m (%.2f of the gap)", r->layers,
            r->beta, t_end, r->x_ave_end, r->z_ave_end, r->max_overlap, r->max_overlap / (2 * dx));
    vc_info(CASE, "L%d beta %.1f: %lld coupled steps, %lld DEM substeps, CPU %.1f s (PIC %.1f, DEM %.1f, coupling %.1f)", r->layers,
            r->beta, r->steps, r->substeps, r->cpu, r->cpu_pic, r->cpu_dem, r->cpu_coupling);
}

/* Arrival time for the comparisons: a run that never arrived counts as arriving after every other. */
static double arrival_key(const result *r) { return r->arrival >= 0 ? r->arrival : 1e30; }

int main(int argc, char **argv) {
    static const int layer_counts[4] = {6, 8, 10, 12};
    static const double betas[2] = {0.5, 1.0};
    result res[4][2];
    double dx, t_end;
    int only, only_beta, i, j;
    char metric[128];
    vc_begin(CASE, argc, argv, "--seed");
    dx = vc_option_num("--dx", vc_full() ? WD_SEED_DX : DEFAULT_DX);
    t_end = vc_option_num("--t-end", vc_full() ? 0.6 : DEFAULT_T_END);
    only = vc_option_int("--layers", 0);
    only_beta = vc_option("--beta") ? (vc_option_num("--beta", 1) < 0.75 ? 0 : 1) : -1;
    vc_tier("dx = %g mm, %g s per run", 1e3 * dx, t_end);
    vc_info(CASE, "dx = %g m (seed: %g m), %.2f s per run", dx, WD_SEED_DX, t_end);
    memset(res, 0, sizeof res);
    for (i = 0; i < 4; ++i)
        for (j = 0; j < 2; ++j) res[i][j].arrival = -1; /* runs left out print -1 */
    for (i = 0; i < 4; ++i) {
        if (only && layer_counts[i] != only) continue;
        for (j = 0; j < 2; ++j) {
            if (only_beta >= 0 && j != only_beta) continue;
            run(dx, layer_counts[i], betas[j], t_end, &res[i][j]);
            report(&res[i][j], dx, t_end);
        }
    }
    /* seed 000 §3.2: without the gap treatment the water flows through the gaps and pushes the
       cylinders to the right wall sooner */
    for (i = 0; i < 4 && only_beta < 0; ++i) {
        if (only && layer_counts[i] != only) continue;
        snprintf(metric, sizeof metric, "L%d_beta1_arrives_before_beta05", layer_counts[i]);
        vc_check(CASE, metric, res[i][1].arrival >= 0 && arrival_key(&res[i][1]) < arrival_key(&res[i][0]) ? 1 : 0, 1, 0);
    }
    /* seed 000 §3.2 and Fig. 10: the 12-layer dam break is less violent; its cylinders arrive later */
    if (!only)
        for (j = 0; j < 2; ++j) {
            if (only_beta >= 0 && j != only_beta) continue;
            snprintf(metric, sizeof metric, "%s_12_layers_arrive_after_6", j ? "b1" : "b05");
            vc_check(CASE, metric, res[0][j].arrival >= 0 && arrival_key(&res[3][j]) > arrival_key(&res[0][j]) ? 1 : 0, 1, 0);
        }
    vc_info(CASE, "arrival times (s; -1: not within %.2f s or not run): layers beta=0.5 beta=1", t_end);
    for (i = 0; i < 4; ++i)
        if (!only || layer_counts[i] == only)
            vc_info(CASE, "arrival L%d %.4f %.4f", layer_counts[i], res[i][0].arrival, res[i][1].arrival);
    return vc_exit_code();
}
