/* Martin & Moyce (1952) collapse of a water column extruded in 3D: the 2D case's column (a x 2a,
   a = 0.05715 m) spans the full width of a closed tank 8a long and 3a high, in a thin tank
   (width a/4) and a wide one (width a). With slip side walls the flow is two-dimensional, so the
   front must follow the 2D result (run here at the same resolution) and the table.
   Usage: run REFDATA_DIR [cells_across_a]   (default 20)
   Writes front_2d.csv, front_thin.csv, front_wide.csv (t,x_front,h_column in m) and ref_front.csv. */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"
#include "common.h"
#include "pic_dambreak.h"

#define CASE "pic_dambreak_3d"

static db_series s2, s3;

/* Largest relative deviation of the front over the table times up to the 2D run's wall arrival. */
static double max_rel_vs(const db_series *a, const db_series *b, const db_ref *r) {
    double k = sqrt(DB_A / (2 * DB_G)), worst = 0;
    int i;
    for (i = 0; i < r->nz; ++i) {
        double za = db_at(a, a->x, r->T[i] * k), zb = db_at(b, b->x, r->T[i] * k);
        if (fabs(za - zb) / zb > worst) worst = fabs(za - zb) / zb;
    }
    return worst;
}

static double max_rel_table(const db_series *a, const db_ref *r) {
    double k = sqrt(DB_A / (2 * DB_G)), worst = 0;
    int i;
    for (i = 0; i < r->nz; ++i) {
        double z = db_at(a, a->x, r->T[i] * k) / DB_A;
        if (fabs(z - r->Z[i]) / r->Z[i] > worst) worst = fabs(z - r->Z[i]) / r->Z[i];
    }
    return worst;
}

int main(int argc, char **argv) {
    db_ref ref;
    const char *dir = argc > 1 ? argv[1] : "../shared/refdata";
    int n = argc > 2 ? atoi(argv[2]) : 20, w;
    double t_end;
    if (db_load_ref(dir, &ref) != 0) {
        vc_check(CASE, "reference_loaded", 0, 1, 0);
        return vc_exit_code();
    }
    t_end = ref.T[ref.nz - 1] * sqrt(DB_A / (2 * DB_G)) + 0.01;
    db_write_ref_front(&ref);
    db_run(2, n, 0, t_end, "front_2d.csv", &s2);
    vc_info(CASE, "2D at a/%d: %d particles, %d steps, %.1f s CPU, max deviation from the table %.1f%%", n, s2.particles,
            s2.steps, s2.cpu, 100 * max_rel_table(&s2, &ref));
    for (w = 0; w < 2; ++w) {
        const char *tag = w == 0 ? "thin" : "wide";
        double width = w == 0 ? DB_A / 4 : DB_A;
        char name[32], metric[64];
        snprintf(name, sizeof name, "front_%s.csv", tag);
        db_run(3, n, width, t_end, name, &s3);
        vc_info(CASE, "%s tank (width %.4f m = %d cells): %d particles, %d steps, %.1f s CPU (pressure %.1f s), volume drift %.3f%%",
                tag, width, (int)floor(width / (DB_A / n) + 0.5), s3.particles, s3.steps, s3.cpu, s3.cpu_pressure,
                100 * s3.volume_drift);
        {
            double rs, shift = db_best_shift(&s3, &ref, &rs);
            vc_info(CASE, "%s tank: front RMS(Z) %.3f without time shift, %.3f with the best shift %.3f in T; "
                          "column height RMS(eta) %.3f over the table entries up to the run's end", tag,
                    db_rms_front(&s3, &ref, 0), rs, shift, db_rms_height(&s3, &ref));
        }
        snprintf(metric, sizeof metric, "%s_run_completed", tag);
        vc_check(CASE, metric, s3.failed ? 0 : 1, 1, 0);
        snprintf(metric, sizeof metric, "%s_front_max_rel_dev_vs_2d", tag);
        vc_check(CASE, metric, max_rel_vs(&s3, &s2, &ref), 0, 0.05);
        snprintf(metric, sizeof metric, "%s_front_max_rel_dev_vs_table", tag);
        vc_check(CASE, metric, max_rel_table(&s3, &ref), 0, 0.05);
    }
    return vc_exit_code();
}
