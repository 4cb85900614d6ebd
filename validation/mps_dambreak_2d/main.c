/* Collapse of a water column, MPS in 2D: the Martin & Moyce (1952) column n^2 = 2 (a = 0.05715 m,
   a x 2a, tank 8a long; checked) and the Koshizuka & Oka (1996) column (L = 0.146 m, L x 2L, tank
   4L long, as in their MPS paper; reported).
   Usage: run [DATA_DIR] [--tier=default|full] [--cells=N]   (DATA_DIR: validation/data by default;
   N particles across a: 40 in both tiers; the same column at N/2 is reported as a convergence
   figure). The library's default scheme is checked; the other one runs the checked column and is
   reported beside it.
   Reads martin_moyce_1952_front_n2_2_table_ocellaris.csv,
   martin_moyce_1952_residual_height_n2_2_table_ocellaris.csv and koshizuka_oka_1996_front_pysph.csv.
   Writes front.csv (t,x_front,h_column in m) of the checked run, front_other.csv (the other
   scheme's), front_n<N>.csv (the coarser run),
   front_ko.csv (the Koshizuka & Oka column), front_shifted.csv (front.csv delayed by the best-fit
   time shift against Martin & Moyce), density.csv (t, mean n/n0 of the inner fluid, surface
   particles) of the checked run and the tables in SI units (ref_front.csv, ref_front_ko.csv for
   a = 0.05715 m, ref_front_ko_L.csv for L = 0.146 m, ref_height.csv) for the plots.
   The front is compared with the experiments by the protocol of dambreak_protocol.h
   (db_report_front), the one the PIC dam-break cases use. */
#include "fsdem.h"
#include "common.h"
#include "dambreak_protocol.h"

#define CASE "mps_dambreak_2d"
#define KO_L 0.146       /* m, column width of Koshizuka & Oka (1996) */
#define MB_MAX_STEPS 40000 /* a run stops (as failed) after this many steps: about twice what the
                              a/40 run needs with the explicit scheme (the sound speed's Courant
                              number), 14 times the semi-implicit scheme's */

/* What a run measures besides its front series. */
typedef struct mb_extra {
    double r0;
    int fluid_start, fluid_end;    /* FLUID particles at the start and at the end */
    double nd_start, nd_end;       /* mean n/n0 of FLUID particles not on the surface: first and last step */
    double nd_max_dev;             /* max over the run of |mean n/n0 - nd_start| */
    double deep_start, deep_end;   /* the same over the FLUID particles farther than MB_DEEP r0 from
                                      every surface particle: first and last step */
    double vol_start, vol_end;     /* m^2: the explicit scheme's FLUID volume, sum r0^2 rho / rho_i,
                                      at the first step and the end (0 with the other scheme) */
    int surface_start, surface_end;
    double t_fail;                 /* s (-1: completed) */
    double u_last, dt_last;        /* m/s, s: largest FLUID speed and step at the last sample */
    long long iterations;          /* PCG iterations, all steps */
    char error[800];
} mb_extra;

/* Front: the largest x of a FLUID particle plus r0/2 (the right edge of the volume r0 x r0 that the
   particle stands for; a at t = 0). Column height: the largest y of a FLUID particle in the first
   column (x < r0) plus r0/2 (2a at t = 0); 0 when none is left there. */
static void mb_measure(fsdem_mps *s, double r0, double *front, double *hcol) {
    fsdem_mps_particles p = fsdem_mps_get_particles(s);
    int i;
    *front = 0;
    *hcol = 0;
    for (i = 0; i < p.count; ++i) {
        if (p.kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        if (p.position[i].x + 0.5 * r0 > *front) *front = p.position[i].x + 0.5 * r0;
        if (p.position[i].x < r0 && p.position[i].y + 0.5 * r0 > *hcol) *hcol = p.position[i].y + 0.5 * r0;
    }
}

/* Mean number density over n0 of the FLUID particles that are not on the surface (the number
   density and the surface flags of the last step, i.e. at the positions of its start). */
static double mb_inner_density(fsdem_mps *s, int *surface) {
    fsdem_mps_particles p = fsdem_mps_get_particles(s);
    double n0 = (double)fsdem_mps_get_stats(s).n0, sum = 0;
    int i, k = 0;
    *surface = 0;
    for (i = 0; i < p.count; ++i) {
        if (p.kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        if (p.surface[i]) {
            (*surface)++;
            continue;
        }
        sum += (double)p.number_density[i];
        k++;
    }
    return k ? sum / k / n0 : NAN;
}

/* Depth in r0 from which a particle's neighbourhood is whole: 4.1 r0, the larger of the two
   schemes' interaction radii (2.8 and 4.1 r0). */
#define MB_DEEP 4.1

/* Mean number density over n0 of the FLUID particles farther than MB_DEEP r0 from every surface
   particle: the liquid's own compression, without the particles whose neighbourhood the surface
   cuts (their n is below n0 by geometry, and their share grows with the surface's length). */
static double mb_deep_density(fsdem_mps *s, double r0) {
    fsdem_mps_particles p = fsdem_mps_get_particles(s);
    const double n0 = (double)fsdem_mps_get_stats(s).n0, reach2 = MB_DEEP * MB_DEEP * r0 * r0;
    double sum = 0;
    int i, j, k = 0;
    for (i = 0; i < p.count; ++i) {
        int deep = p.kind[i] == FSDEM_MPS_KIND_FLUID && !p.surface[i];
        for (j = 0; j < p.count && deep; ++j)
            if (p.kind[j] == FSDEM_MPS_KIND_FLUID && p.surface[j]) {
                const double dx = (double)(p.position[j].x - p.position[i].x), dy = (double)(p.position[j].y - p.position[i].y);
                deep = dx * dx + dy * dy >= reach2;
            }
        if (!deep) continue;
        sum += (double)p.number_density[i];
        k++;
    }
    return k ? sum / k / n0 : NAN;
}

/* The explicit scheme's volume of the FLUID particles, sum r0^2 rho / rho_i (m^2; 0 when the
   particles carry no density: the semi-implicit scheme). */
static double mb_volume(fsdem_mps *s, double r0) {
    fsdem_mps_particles p = fsdem_mps_get_particles(s);
    double v = 0;
    int i;
    for (i = 0; i < p.count; ++i)
        if (p.kind[i] == FSDEM_MPS_KIND_FLUID && p.density[i] > 0) v += r0 * r0 * 1000 / (double)p.density[i];
    return v;
}

/* A column a wide and 2a high against the left wall of a tank `length` a long (walls 4a high, open
   at the top), n particles across a, until t_end or the front's arrival at the far wall plus
   `after_wall` s. Writes `csv_name` (t,x_front,h_column) and, when not NULL, `density_csv`. */
static void mb_run(fsdem_mps_scheme scheme, double a, double length, int n, double t_end, double after_wall,
                   const char *csv_name, const char *density_csv, db_series *out, mb_extra *ex) {
    fsdem_mps_desc d = fsdem_mps_desc_default_scheme(2, scheme);
    fsdem_mps *s = NULL;
    fsdem_csv csv, dcsv;
    fsdem_mps_stats st;
    double r0 = a / n, L = length * a, H = 4 * a, margin = 6 * r0;
    memset(out, 0, sizeof *out);
    memset(ex, 0, sizeof *ex);
    out->a = a;
    out->t_wall = -1;
    ex->r0 = r0;
    ex->t_fail = -1;
    d.r0 = (fsdem_real)r0;
    d.domain_min = fsdem_v3((fsdem_real)-margin, (fsdem_real)-margin, 0);
    d.domain_max = fsdem_v3((fsdem_real)(L + margin), (fsdem_real)(3 * H), 0);
    if (fsdem_mps_create(&d, &s) != FSDEM_OK) {
        char why[256];
        fsdem_mps_desc_check(&d, why, sizeof why);
        snprintf(ex->error, sizeof ex->error, "fsdem_mps_create: %s", why);
        out->failed = 1;
        return;
    }
    if (fsdem_mps_add_box_walls(s, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)L, (fsdem_real)H, 0), 1u << FSDEM_SIDE_YMAX,
                                NULL) != FSDEM_OK ||
        fsdem_mps_fill_box(s, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)a, (fsdem_real)(2 * a), 0), fsdem_v3(0, 0, 0),
                           &ex->fluid_start) != FSDEM_OK) {
        snprintf(ex->error, sizeof ex->error, "%s", fsdem_mps_last_error(s));
        out->failed = 1;
        fsdem_mps_destroy(s);
        return;
    }
    fsdem_csv_open(&csv, csv_name, "t,x_front,h_column");
    if (density_csv) fsdem_csv_open(&dcsv, density_csv, "t,inner_density_over_n0,surface");
    for (;;) {
        double fr, hc, t = fsdem_mps_time(s);
        fsdem_real row[3];
        mb_measure(s, r0, &fr, &hc);
        if (out->n < DB_MAX_SAMPLES) {
            out->t[out->n] = t;
            out->x[out->n] = fr;
            out->h[out->n] = hc;
            out->n++;
        }
        row[0] = (fsdem_real)t;
        row[1] = (fsdem_real)fr;
        row[2] = (fsdem_real)hc;
        fsdem_csv_row(&csv, row, 3);
        if (out->t_wall < 0 && fr >= L - 0.5 * r0) out->t_wall = t;
        if (t > 0) { /* the number density of the step just taken */
            int surf;
            double nd = mb_inner_density(s, &surf);
            if (fsdem_mps_get_stats(s).steps == 1) {
                ex->nd_start = nd;
                ex->surface_start = surf;
                ex->vol_start = mb_volume(s, r0);
                ex->deep_start = mb_deep_density(s, r0);
            }
            if (fabs(nd - ex->nd_start) > ex->nd_max_dev) ex->nd_max_dev = fabs(nd - ex->nd_start);
            ex->nd_end = nd;
            ex->surface_end = surf;
            if (density_csv) {
                row[1] = (fsdem_real)nd;
                row[2] = (fsdem_real)surf;
                fsdem_csv_row(&dcsv, row, 3);
            }
        }
        ex->u_last = (double)fsdem_mps_get_stats(s).max_speed;
        ex->dt_last = (double)fsdem_mps_get_stats(s).dt;
        if (t >= t_end - 1e-12 || (out->t_wall >= 0 && t >= out->t_wall + after_wall)) break;
        if (fsdem_mps_get_stats(s).steps >= MB_MAX_STEPS) {
            ex->t_fail = t;
            snprintf(ex->error, sizeof ex->error, "stopped after %d steps at t = %.4f s (last dt %.3g s, largest speed "
                     "%.3g m/s)", MB_MAX_STEPS, t, ex->dt_last, ex->u_last);
            out->failed = 1;
            break;
        }
        if (fsdem_mps_step(s) != FSDEM_OK) {
            ex->t_fail = fsdem_mps_time(s);
            snprintf(ex->error, sizeof ex->error, "step %lld failed at t = %.4f s (T = %.2f; before it dt %.3g s, "
                     "largest speed %.3g m/s): %s", fsdem_mps_get_stats(s).steps, ex->t_fail,
                     ex->t_fail * sqrt(2 * DB_G / a), ex->dt_last, ex->u_last, fsdem_mps_last_error(s));
            fprintf(stderr, "%s\n", ex->error);
            out->failed = 1;
            break;
        }
    }
    fsdem_csv_close(&csv);
    if (density_csv) fsdem_csv_close(&dcsv);
    st = fsdem_mps_get_stats(s);
    ex->fluid_end = st.fluid;
    ex->vol_end = mb_volume(s, r0);
    ex->deep_end = mb_deep_density(s, r0);
    ex->iterations = st.pressure_iterations_total;
    out->steps = (int)st.steps;
    out->particles = st.fluid + st.wall + st.dummy;
    out->cpu = st.seconds_total;
    out->cpu_pressure = st.seconds_pressure;
    out->volume_drift = fabs((double)ex->fluid_end / ex->fluid_start - 1);
    fsdem_mps_destroy(s);
}

static void mb_info(const char *tag, const db_series *s, const mb_extra *ex) {
    vc_info(CASE, "%s: r0 = a/%.0f = %.3g m, %d fluid particles (%d in all), %d steps, %.1f s CPU (pressure %.1f s), "
                  "%.1f PCG iterations per step; %s%s",
            tag, db_width(s) / ex->r0, ex->r0, ex->fluid_start, s->particles, s->steps, s->cpu, s->cpu_pressure,
            s->steps ? (double)ex->iterations / s->steps : 0.0, s->failed ? "FAILED: " : "completed",
            s->failed ? ex->error : "");
    vc_info(CASE, "%s: mean n/n0 of the inner fluid (FLUID, not surface) %.5f at the first step, %.5f at the end "
                  "(%+.3f%%), largest deviation during the run %.3f%%; surface particles %d -> %d",
            tag, ex->nd_start, ex->nd_end, 100 * (ex->nd_end / ex->nd_start - 1), 100 * ex->nd_max_dev / ex->nd_start,
            ex->surface_start, ex->surface_end);
    vc_info(CASE, "%s: mean n/n0 of the FLUID particles farther than %.1f r0 from every surface particle %.5f at the first "
                  "step, %.5f at the end (%+.3f%%)",
            tag, MB_DEEP, ex->deep_start, ex->deep_end, 100 * (ex->deep_end / ex->deep_start - 1));
    if (ex->vol_start > 0)
        vc_info(CASE, "%s: FLUID volume by the explicit scheme's densities (sum r0^2 rho / rho_i) %.6g m^2 at the first step, "
                      "%.6g m^2 at the end (%+.3f%%)",
                tag, ex->vol_start, ex->vol_end, 100 * (ex->vol_end / ex->vol_start - 1));
}

static const char *mb_scheme_name(fsdem_mps_scheme scheme) {
    return scheme == FSDEM_MPS_SCHEME_EXPLICIT ? "explicit" : "semi-implicit (seed 002)";
}

static db_series mm, mm_coarse, ko, mm_other;

int main(int argc, char **argv) {
    db_ref ref;
    mb_extra ex, ex_coarse, ex_ko, ex_other;
    const fsdem_mps_scheme scheme = fsdem_mps_desc_default(2).scheme;
    const fsdem_mps_scheme other = scheme == FSDEM_MPS_SCHEME_EXPLICIT ? FSDEM_MPS_SCHEME_SEMI_IMPLICIT : FSDEM_MPS_SCHEME_EXPLICIT;
    const char *dir;
    int n, i;
    double t_end;
    vc_begin(CASE, argc, argv, NULL);
    n = vc_option_int("--cells", 40);
    vc_tier("r0 = a/%d (and a/%d reported), Koshizuka & Oka column at L/%d; %s scheme checked, the other reported", n, n / 2, n,
            scheme == FSDEM_MPS_SCHEME_EXPLICIT ? "explicit" : "semi-implicit");
    dir = vc_data_dir();
    char name[64];
    if (db_load_ref(dir, &ref) != 0) {
        vc_check(CASE, "reference_loaded", 0, 1, 0);
        return vc_exit_code();
    }
    t_end = db_end_time(&ref);
    db_write_ref_front(&ref);
    db_write_front_table(&ref.ko, KO_L, "ref_front_ko_L.csv");

    /* ---- Martin & Moyce, a/n: the checks ---- */
    mb_run(scheme, DB_A, DB_LENGTH, n, t_end, 1e30, "front.csv", "density.csv", &mm, &ex);
    vc_info(CASE, "MM: the %s scheme (the library's default)", mb_scheme_name(scheme));
    mb_info("MM", &mm, &ex);
    vc_check(CASE, "run_completed", mm.failed ? 0 : 1, 1, 0);
    {
        db_front_cmp c = db_report_front(CASE, "", &mm, &ref.mm, 1);
        db_write_shifted(&mm, c.dT, "front_shifted.csv");
    }
    vc_check(CASE, "residual_height_rms_eta", db_rms_height(&mm, &ref), 0, 0.05);
    { /* what the figures cover when the run stopped early */
        int covered_h = 0, covered_z = 0;
        double t_last = mm.n ? mm.t[mm.n - 1] : 0;
        for (i = 0; i < ref.ne; ++i) covered_h += ref.tau[i] * sqrt(DB_A / DB_G) <= t_last + 1e-9;
        for (i = 0; i < ref.mm.n; ++i) covered_z += ref.mm.T[i] * sqrt(DB_A / (2 * DB_G)) <= t_last + 1e-9;
        vc_info(CASE, "MM: the run covers t <= %.4f s (T = %.2f, tau = %.2f): %d of the %d front entries and %d of the %d "
                      "height entries (the residual height RMS is over those; beyond its end a series is held at its "
                      "last value by the front comparison); volume and number density are at its last step",
                t_last, t_last * sqrt(2 * DB_G / DB_A), t_last * sqrt(DB_G / DB_A), covered_z, ref.mm.n, covered_h, ref.ne);
    }
    /* volume = particle count x r0^2: no particle is created or removed (one leaving the domain
       stops the run), so this is book-keeping; the number density is the volume figure of the
       semi-implicit scheme, whose pressure equation drives n back to n0. The explicit scheme's
       particles carry their volume, mass / rho_i, so its volume figure is their sum; its mean n/n0
       over the particles off the surface also counts those within re of it, whose neighbourhood
       the surface cuts (n below n0 by geometry, more of them as the surface lengthens; the deep
       figure, reported, leaves them out), and moves with the order of the particles (the weight of
       Eq. 6 is steep near r = 0) */
    vc_check(CASE, "volume_particle_count_change", (double)(ex.fluid_end - ex.fluid_start) * ex.r0 * ex.r0, 0, 0);
    vc_check(CASE, "inner_number_density_drift", ex.nd_end / ex.nd_start - 1, 0, 0.01);
    if (ex.vol_start > 0) vc_check(CASE, "fluid_volume_drift_by_density", ex.vol_end / ex.vol_start - 1, 0, 0.01);
    vc_check(CASE, "front_reached_far_wall", mm.t_wall >= 0 ? 1 : 0, 1, 0);
    if (mm.t_wall >= 0) vc_info(CASE, "MM: front at the far wall at T = %.2f", mm.t_wall * sqrt(2 * DB_G / DB_A));
    /* Koshizuka & Oka's table against the same n^2 = 2 column, as the PIC cases do (information) */
    db_report_front(CASE, "MM_column", &mm, &ref.ko, 0);

    /* ---- the Koshizuka & Oka column (L = 0.146 m, tank 4L) against their front: reported ---- */
    mb_run(scheme, KO_L, 4.0, n, ref.ko.T[ref.ko.n - 1] * sqrt(KO_L / (2 * DB_G)) + 0.03, 0.0, "front_ko.csv", NULL, &ko, &ex_ko);
    mb_info("KO", &ko, &ex_ko);
    db_report_front(CASE, "KO_column", &ko, &ref.ko, 0);

    /* ---- convergence: the same Martin & Moyce column at half the resolution ---- */
    snprintf(name, sizeof name, "front_n%d.csv", n / 2);
    mb_run(scheme, DB_A, DB_LENGTH, n / 2, t_end, 1e30, name, NULL, &mm_coarse, &ex_coarse);
    snprintf(name, sizeof name, "MM_a/%d", n / 2);
    mb_info(name, &mm_coarse, &ex_coarse);
    {
        db_front_cmp c = db_compare_front(&mm_coarse, &ref.mm);
        double d1 = 0, k = sqrt(DB_A / (2 * DB_G));
        for (i = 0; i < ref.mm.n; ++i) {
            double t = ref.mm.T[i] * k, z0 = db_at(&mm, mm.x, t), z1 = db_at(&mm_coarse, mm_coarse.x, t);
            d1 += (z1 - z0) * (z1 - z0);
        }
        vc_info(CASE, "%s against Martin & Moyce: dT = %.3f, RMS(Z) after it %.3f, slope %.3f (table %.3f), height "
                      "RMS(eta) %.3f; RMS front change a/%d -> a/%d at the table's times %.3f a",
                name, c.dT, c.rms_shifted, c.slope_sim, c.slope_table, db_rms_height(&mm_coarse, &ref), n / 2, n,
                sqrt(d1 / ref.mm.n) / DB_A);
    }

    /* ---- the other scheme on the checked column: reported beside it ---- */
    mb_run(other, DB_A, DB_LENGTH, n, t_end, 1e30, "front_other.csv", NULL, &mm_other, &ex_other);
    vc_info(CASE, "MM_other: the %s scheme on the same column (reported)", mb_scheme_name(other));
    mb_info("MM_other", &mm_other, &ex_other);
    {
        const db_front_cmp c = db_compare_front(&mm_other, &ref.mm);
        vc_info(CASE, "MM_other against Martin & Moyce: dT = %.3f, RMS(Z) after it %.3f, slope %.3f (table %.3f), height RMS(eta) "
                      "%.3f, inner n/n0 drift %+.3f%%%s",
                c.dT, c.rms_shifted, c.slope_sim, c.slope_table, db_rms_height(&mm_other, &ref),
                100 * (ex_other.nd_end / ex_other.nd_start - 1), mm_other.t_wall >= 0 ? "" : ", front did not reach the far wall");
    }
    return vc_exit_code();
}
