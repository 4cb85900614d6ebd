/* validation/mpsdem_dambreak: the liquid-solid dam break of seed 002 §3.2 (after Sun et al. 2013)
   with the unresolved MPS-DEM coupler, Models A and B, at d_p = r0 = 0.003, 0.0027 and 0.002 m, and
   the same column of clear water. Geometry and solver settings: case.h; sources and choices:
   README.md.

   Runs (each to T_END, fronts sampled every 0.005 s; README.md has the measured costs):
     --tier=default  B and clear water at 0.004 m (the resolution lines are the full tier's: INFO
                     (full tier) without a value);
     --tier=full     B and clear water at 0.003 and 0.0027 m, B at 0.002 m and A at all three
                     (--all is the same);
     --only M:R      one run (model M = A, B or W for clear water, r0 = R m), for timing.
   Usage: run [data_dir] [--tier=default|full] [--only B:0.002]   (data_dir is unused: this case has
   no reference data; `make validate` passes it).

   Output: fronts.csv (long form: run,model,r0,sediment,t,water_front,sediment_front,water_q,
   sediment_q), fronts_<run>.csv per run (t,water_front,sediment_front,water_q,sediment_q), CHECK
   and INFO lines. Fronts (m, from the wall behind the column): the leading fronts, the largest x
   of a water particle plus r0/2 and of a sphere plus its radius (both 0.05 m at t = 0), and the x
   beyond which 0.5 % of the phase's particles lie (_q), less sensitive to one particle thrown ahead.

   Checks:
     <run>_completed                       every step returned FSDEM_OK
     <model>_water_front_resolution_<r0>   max over the window of |x(t) - x_fine(t)| / travel <= 5 %
     <model>_sediment_front_resolution_<r0> the same for the sediment, against the finest run of the
                                           model; travel = the fine run's front at the window's end
                                           minus 0.05 m; the window ends at T_END or when the fine
                                           run's water front reaches 0.19 m (the far wall is at 0.2)
     water_front_slowed_by_sediment_<r0>    t(water front reaches 0.15 m) with sediment (Model B) /
                                           the same for clear water, in [1, 5] (with T_END
                                           for a front that never gets there: a lower bound)                      */
#define _POSIX_C_SOURCE 200809L
#include "fsdem.h"

#include "common.h"
#include "mpsdem_dambreak/case.h"

#include <time.h>

#define CASE "mpsdem_dambreak"
#define T_END 0.2
#define DT_SAMPLE 0.005
#define MAX_SAMPLES 128
#define MAX_RUNS 12
#define QUANTILE 0.005

typedef struct run {
    char model;  /* 'A', 'B' or 'W' (clear water, no sediment) */
    double r0;
    int done, completed, n;
    double t[MAX_SAMPLES], water[MAX_SAMPLES], sediment[MAX_SAMPLES], water_q[MAX_SAMPLES], sediment_q[MAX_SAMPLES];
    long long steps, substeps;
    double cpu_mps, cpu_dem, wall;
    int fluid, walls, spheres;
    char error[512];
} run;

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void run_name(const run *r, char *buf, size_t size) {
    snprintf(buf, size, "%c_%.4f", r->model, r->r0);
}

static void run_case(run *r) {
    sd_case c;
    char name[64], path[96];
    fsdem_csv csv;
    double t0 = now();
    clock_t c0 = clock();
    int k;
    run_name(r, name, sizeof name);
    r->done = 1;
    if (sd_create(&c, r->r0, r->model == 'A' ? FSDEM_MPS_MODEL_A : FSDEM_MPS_MODEL_B, r->model != 'W') != 0) {
        snprintf(r->error, sizeof r->error, "%s", c.error);
        return;
    }
    r->fluid = c.fluid;
    r->walls = c.walls;
    r->spheres = c.spheres;
    snprintf(path, sizeof path, "fronts_%s.csv", name);
    fsdem_csv_open(&csv, path, "t,water_front,sediment_front,water_q,sediment_q");
    r->completed = 1;
    for (k = 0;; ++k) {
        sd_fronts f = sd_measure(&c, QUANTILE);
        fsdem_real row[5];
        long long steps = 0;
        fsdem_result res;
        r->t[r->n] = fsdem_mps_time(c.mps);
        r->water[r->n] = f.water_max;
        r->sediment[r->n] = f.sediment_max;
        r->water_q[r->n] = f.water_q;
        r->sediment_q[r->n] = f.sediment_q;
        row[0] = (fsdem_real)r->t[r->n];
        row[1] = (fsdem_real)f.water_max;
        row[2] = (fsdem_real)f.sediment_max;
        row[3] = (fsdem_real)f.water_q;
        row[4] = (fsdem_real)f.sediment_q;
        fsdem_csv_row(&csv, row, 5);
        r->n++;
        if (k % 10 == 0) {
            printf("  %s t=%.3f s water %.4f m sediment %.4f m (%.0f s)\n", name, r->t[r->n - 1], f.water_max, f.sediment_max,
                   now() - t0);
            fflush(stdout);
        }
        if ((k + 1) * DT_SAMPLE > T_END + 1e-9 || r->n >= MAX_SAMPLES) break;
        res = sd_advance(&c, (k + 1) * DT_SAMPLE - fsdem_mps_time(c.mps), &steps);
        if (res != FSDEM_OK) {
            snprintf(r->error, sizeof r->error, "t = %.4f s: %.400s", fsdem_mps_time(c.mps), sd_last_error(&c));
            r->completed = 0;
            break;
        }
    }
    fsdem_csv_close(&csv);
    if (c.cpl) {
        fsdem_mps_dem_stats st = fsdem_mps_dem_get_stats(c.cpl);
        r->steps = st.coupling.steps;
        r->substeps = st.coupling.substeps_total;
        r->cpu_mps = st.coupling.seconds_fluid;
        r->cpu_dem = (st.coupling.seconds_dem + st.coupling.seconds_coupling);
    } else {
        fsdem_mps_stats st = fsdem_mps_get_stats(c.mps);
        r->steps = st.steps;
        r->cpu_mps = st.seconds_total;
    }
    r->wall = now() - t0;
    (void)c0;
    sd_destroy(&c);
}

/* Linear interpolation of a series at t (clamped). */
static double at(const run *r, const double *x, double t) {
    int i;
    if (r->n == 0) return NAN;
    if (t <= r->t[0]) return x[0];
    for (i = 1; i < r->n; ++i)
        if (r->t[i] >= t) return x[i - 1] + (x[i] - x[i - 1]) * (t - r->t[i - 1]) / (r->t[i] - r->t[i - 1]);
    return x[r->n - 1];
}

/* First time the series reaches x (interpolated), or -1. */
static double reach(const run *r, const double *x, double level) {
    int i;
    for (i = 1; i < r->n; ++i)
        if (x[i] >= level) return r->t[i - 1] + (r->t[i] - r->t[i - 1]) * (level - x[i - 1]) / (x[i] - x[i - 1]);
    return -1;
}

static run *find(run *runs, int n, char model, double r0) {
    int i;
    for (i = 0; i < n; ++i)
        if (runs[i].model == model && fabs(runs[i].r0 - r0) < 1e-9 && runs[i].done && runs[i].completed) return &runs[i];
    return NULL;
}

typedef struct spec {
    char model; /* as run.model */
    double r0;  /* m */
} spec;

/* The full tier's resolution lines of one model, for the default tier, which runs one spacing per
   model: INFO (full tier) lines without a value (they compare the seed's spacings). */
static void resolution_lines_of_full_tier(const spec *full, int nf, char model) {
    double fine = 1;
    int i;
    char metric[96];
    for (i = 0; i < nf; ++i)
        if (full[i].model == model && full[i].r0 < fine) fine = full[i].r0;
    for (i = 0; i < nf; ++i) {
        if (full[i].model != model || full[i].r0 == fine) continue;
        snprintf(metric, sizeof metric, "%c_water_front_resolution_%.4f_vs_%.4f", model, full[i].r0, fine);
        vc_check_full(CASE, metric, NAN, 0.025, 0.025);
        snprintf(metric, sizeof metric, "%c_sediment_front_resolution_%.4f_vs_%.4f", model, full[i].r0, fine);
        vc_check_full(CASE, metric, NAN, 0.025, 0.025);
    }
}

/* Resolution checks of one model: every completed run against the finest completed one. */
static void check_resolution(run *runs, int n, char model) {
    run *fine = NULL;
    double t_win, travel_w, travel_s;
    int i, j;
    for (i = 0; i < n; ++i)
        if (runs[i].model == model && runs[i].done && runs[i].completed && (!fine || runs[i].r0 < fine->r0)) fine = &runs[i];
    if (!fine) return;
    t_win = reach(fine, fine->water, 0.19);
    if (t_win < 0 || t_win > fine->t[fine->n - 1]) t_win = fine->t[fine->n - 1];
    travel_w = at(fine, fine->water, t_win) - SD_COLUMN_X;
    travel_s = at(fine, fine->sediment, t_win) - SD_COLUMN_X;
    vc_info(CASE, "model %c: finest run r0 = %.4f m; window 0..%.3f s; travel water %.4f m, sediment %.4f m", model, fine->r0, t_win,
            travel_w, travel_s);
    for (i = 0; i < n; ++i) {
        run *r = &runs[i];
        double ew = 0, es = 0, ewq = 0, esq = 0;
        char metric[96];
        if (r->model != model || !r->done || !r->completed || r == fine) continue;
        for (j = 0; j < fine->n && fine->t[j] <= t_win + 1e-9; ++j) {
            const double t = fine->t[j];
            ew = fmax(ew, fabs(at(r, r->water, t) - fine->water[j]));
            es = fmax(es, fabs(at(r, r->sediment, t) - fine->sediment[j]));
            ewq = fmax(ewq, fabs(at(r, r->water_q, t) - fine->water_q[j]));
            esq = fmax(esq, fabs(at(r, r->sediment_q, t) - fine->sediment_q[j]));
        }
        snprintf(metric, sizeof metric, "%c_water_front_resolution_%.4f_vs_%.4f", model, r->r0, fine->r0);
        vc_check(CASE, metric, ew / travel_w, 0.025, 0.025);
        snprintf(metric, sizeof metric, "%c_sediment_front_resolution_%.4f_vs_%.4f", model, r->r0, fine->r0);
        vc_check(CASE, metric, es / travel_s, 0.025, 0.025);
        vc_info(CASE, "model %c r0 %.4f vs %.4f: max |dx| / travel of the 0.5%% fronts: water %.4f, sediment %.4f", model, r->r0,
                fine->r0, ewq / travel_w, esq / travel_s);
    }
}

int main(int argc, char **argv) {
    /* the tiers' runs (model, r0 in m); README.md, "Tiers" */
    static const spec default_runs[] = {{'B', 0.004}, {'W', 0.004}},
                      full_runs[] = {{'B', 0.003}, {'W', 0.003}, {'B', 0.0027}, {'A', 0.003},
                                     {'A', 0.0027}, {'W', 0.0027}, {'B', 0.002}, {'A', 0.002}};
    const int n_full = (int)(sizeof full_runs / sizeof full_runs[0]);
    run runs[MAX_RUNS];
    int n = 0, i;
    double wall0 = now();
    const char *only;
    char list[256] = "";
    FILE *f;
    memset(runs, 0, sizeof runs);
    vc_begin(CASE, argc, argv, "--all");
    if ((only = vc_option("--only")) != NULL) {
        runs[n].model = only[0];
        runs[n++].r0 = only[0] && only[1] == ':' ? atof(only + 2) : 0;
        if (!strchr("ABW", runs[0].model) || !(runs[0].r0 > 0)) {
            fprintf(stderr, "--only takes model:r0, e.g. --only B:0.002\n");
            return 2;
        }
    } else if (vc_full())
        for (i = 0; i < n_full; ++i) runs[n].model = full_runs[i].model, runs[n++].r0 = full_runs[i].r0;
    else
        for (i = 0; i < (int)(sizeof default_runs / sizeof default_runs[0]); ++i)
            runs[n].model = default_runs[i].model, runs[n++].r0 = default_runs[i].r0;
    for (i = 0; i < n; ++i)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%c %g", i ? ", " : "", runs[i].model, 1e3 * runs[i].r0);
    vc_tier("r0 (mm): %s; to %.2f s", list, T_END);
    for (i = 0; i < n; ++i) {
        char name[64];
        run_name(&runs[i], name, sizeof name);
        run_case(&runs[i]);
        vc_check(CASE, (snprintf(name + strlen(name), sizeof name - strlen(name), "_completed"), name), runs[i].completed, 1, 0);
        if (runs[i].error[0]) vc_info(CASE, "%c r0 %.4f failed: %s", runs[i].model, runs[i].r0, runs[i].error);
        vc_info(CASE,
                "%c r0 %.4f: %d fluid, %d wall+dummy, %d spheres; %lld steps (%.3g s mean dt), %lld DEM substeps; CPU %.1f s MPS "
                "(%.3f s/step), %.1f s DEM+coupling (%.3f s/step); wall %.1f s",
                runs[i].model, runs[i].r0, runs[i].fluid, runs[i].walls, runs[i].spheres, runs[i].steps,
                runs[i].steps ? runs[i].t[runs[i].n - 1] / (double)runs[i].steps : 0.0, runs[i].substeps, runs[i].cpu_mps,
                runs[i].steps ? runs[i].cpu_mps / (double)runs[i].steps : 0.0, runs[i].cpu_dem,
                runs[i].steps ? runs[i].cpu_dem / (double)runs[i].steps : 0.0, runs[i].wall);
    }
    /* fronts.csv: every run in long form */
    f = fopen("fronts.csv", "w");
    if (f) {
        fprintf(f, "run,model,r0,sediment,t,water_front,sediment_front,water_q,sediment_q\n");
        for (i = 0; i < n; ++i) {
            char name[64];
            int j;
            run_name(&runs[i], name, sizeof name);
            for (j = 0; j < runs[i].n; ++j)
                fprintf(f, "%s,%c,%.4f,%d,%.4f,%.6f,%.6f,%.6f,%.6f\n", name, runs[i].model, runs[i].r0, runs[i].model != 'W',
                        runs[i].t[j], runs[i].water[j], runs[i].sediment[j], runs[i].water_q[j], runs[i].sediment_q[j]);
        }
        fclose(f);
    }
    check_resolution(runs, n, 'B');
    check_resolution(runs, n, 'A');
    if (!vc_full() && !only) {
        resolution_lines_of_full_tier(full_runs, n_full, 'B');
        resolution_lines_of_full_tier(full_runs, n_full, 'A');
    }
    /* at every r0 with a clear-water run and a Model B run */
    for (i = 0; i < n; ++i) {
        run *w = &runs[i], *b = find(runs, n, 'B', w->r0);
        char metric[96];
        double tb, tw;
        if (w->model != 'W' || !w->done || !w->completed || !b) continue;
        tb = reach(b, b->water, 0.15);
        tw = reach(w, w->water, 0.15);
        vc_info(CASE, "r0 %.4f: water front at 0.15 m at t = %.4f s with sediment (B), %.4f s clear", w->r0, tb, tw);
        snprintf(metric, sizeof metric, "water_front_slowed_by_sediment_%.4f", w->r0);
        vc_check(CASE, metric, tw > 0 ? (tb > 0 ? tb : T_END) / tw : NAN, 3, 2);
    }
    vc_info(CASE, "total wall time %.0f s", now() - wall0);
    return vc_exit_code();
}
