/* Chung & Ooi (2011) DEM benchmark, tests 1-4, with the Hertz-Mindlin law of fsdem.h.
   Usage: run [DATA_DIR] [--tier=default|full]   (validation/data by default; both tiers run the same
   impacts; writes test1.csv .. test4.csv and ref_*.csv into the working directory)
   See README.md next to this file for the physics, the references, the metrics and the tolerances. */
#include "fsdem.h"
#include "common.h"

#define CASE "dem_chung_ooi"
#define PI 3.14159265358979323846

typedef struct material {
    char name[64];
    double E, nu, rho, R, v, mu, e;
} material;

/* One impact: a sphere on a rigid plane z = 0 (two = 0) or two identical spheres head-on along x
   (two = 1). Inputs above the blank line, results below. */
typedef struct impact {
    material m;
    double restitution; /* input e of the contact */
    double vn, vt;      /* m/s, approach speed normal to the plane (or of each sphere) and tangential */
    double dt;          /* s */
    int steps;          /* > 0: record exactly this many steps; 0: stop shortly after separation */
    double *rec_f, *rec_d; /* optional: force (N) and overlap (m) of each recorded step */

    double f_max, d_max, t_contact; /* N, m, s */
    fsdem_vec3 v_after, w_after;    /* of sphere 0 */
    int ok;
} impact;

/* Hertz elastic impact: reduced quantities and the closed-form peak overlap and contact time. */
static double hertz_contact_time(const material *m, int two, double v_rel) {
    double e_star = 1 / ((two ? 2 : 1) * (1 - m->nu * m->nu) / m->E);
    double r_star = two ? m->R / 2 : m->R;
    double mass = m->rho * 4.0 / 3.0 * PI * m->R * m->R * m->R, m_star = two ? mass / 2 : mass;
    double d_max = pow(15 * m_star * v_rel * v_rel / (16 * e_star * sqrt(r_star)), 0.4);
    return 2.94328 * d_max / v_rel;
}

static void run_impact(impact *im, int two) {
    fsdem_dem_desc desc = fsdem_dem_desc_default(3);
    fsdem_dem_material mat = fsdem_dem_material_default(), rigid;
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_dem_particles view;
    fsdem_dem *dem = NULL;
    double R = im->m.R, d_prev = 0, t_prev = 0, t_end = -1;
    int sphere, plane_mat, step, after = 0;
    im->ok = 0;
    im->f_max = im->d_max = 0;
    im->t_contact = NAN;
    desc.gravity = fsdem_v3(0, 0, 0); /* the benchmark has no gravity */
    desc.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    desc.dt = im->dt;
    desc.domain_min = fsdem_v3(-1, -1, -1);
    desc.domain_max = fsdem_v3(1, 1, 1);
    if (fsdem_dem_create(&desc, &dem) != FSDEM_OK) return;
    mat.density = im->m.rho;
    mat.young_modulus = im->m.E;
    mat.poisson_ratio = im->m.nu;
    mat.restitution = im->restitution;
    mat.friction = im->m.mu;
    rigid = mat;
    rigid.young_modulus = 1000 * mat.young_modulus; /* a rigid plane, as the yade scripts make it */
    if (fsdem_dem_add_material(dem, &mat, &sphere) != FSDEM_OK ||
        (!two && fsdem_dem_add_material(dem, &rigid, &plane_mat) != FSDEM_OK)) {
        vc_info(CASE, "%s: %s", im->m.name, fsdem_dem_last_error(dem)); /* the impact's checks then fail */
        fsdem_dem_destroy(dem);
        return;
    }
    p.radius = R;
    p.material = sphere;
    if (two) { /* touching at t = 0, closing at 2 vn */
        p.position = fsdem_v3(-R, 0, 0);
        p.velocity = fsdem_v3(im->vn, 0, 0);
        fsdem_dem_add_particle(dem, &p, NULL);
        p.position = fsdem_v3(R, 0, 0);
        p.velocity = fsdem_v3(-im->vn, 0, 0);
        fsdem_dem_add_particle(dem, &p, NULL);
    } else { /* touching the plane at t = 0 */
        fsdem_dem_wall_desc floor = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), plane_mat);
        if (fsdem_dem_add_wall(dem, &floor, NULL) != FSDEM_OK) { fsdem_dem_destroy(dem); return; }
        p.position = fsdem_v3(0, 0, R);
        p.velocity = fsdem_v3(im->vt, 0, -im->vn);
        fsdem_dem_add_particle(dem, &p, NULL);
    }
    for (step = 0; im->steps ? step < im->steps : step < 100000000; ++step) {
        double d, f, t;
        if (fsdem_dem_step(dem) != FSDEM_OK) {
            fprintf(stderr, "%s: step failed: %s\n", CASE, fsdem_dem_last_error(dem));
            fsdem_dem_destroy(dem);
            return;
        }
        view = fsdem_dem_get_particles(dem);
        t = fsdem_dem_time(dem);
        if (two) d = 2 * R - (view.position[1].x - view.position[0].x);
        else d = R - view.position[0].z;
        f = sqrt(view.force[0].x * view.force[0].x + view.force[0].y * view.force[0].y +
                 view.force[0].z * view.force[0].z);
        if (f > im->f_max) im->f_max = f;
        if (d > im->d_max) im->d_max = d;
        if (im->rec_f) im->rec_f[step] = f;
        if (im->rec_d) im->rec_d[step] = d > 0 ? d : 0;
        if (t_end < 0 && step > 0 && d <= 0 && d_prev > 0)
            t_end = t_prev + (t - t_prev) * d_prev / (d_prev - d); /* contact began at t = 0 */
        if (t_end >= 0 && !im->steps && ++after > 10) break;
        d_prev = d;
        t_prev = t;
    }
    view = fsdem_dem_get_particles(dem);
    im->v_after = view.velocity[0];
    im->w_after = view.angular_velocity[0];
    im->t_contact = t_end;
    im->ok = t_end > 0;
    fsdem_dem_destroy(dem);
}

/* Reads the material rows of test `test` from the parameter file. */
static int read_materials(const vc_table *t, int test, material *out, int max) {
    int row, n = 0, c_test = vc_table_col(t, "test"), c_mat = vc_table_col(t, "material");
    int c_e = vc_table_col(t, "E_Pa"), c_nu = vc_table_col(t, "nu"), c_rho = vc_table_col(t, "rho_kg_m3");
    int c_r = vc_table_col(t, "R_m"), c_v = vc_table_col(t, "v_m_s"), c_mu = vc_table_col(t, "mu"),
        c_res = vc_table_col(t, "e");
    for (row = 0; row < t->rows && n < max; ++row) {
        material *m = &out[n];
        if ((int)vc_table_num(t, row, c_test) != test) continue;
        snprintf(m->name, sizeof m->name, "%s", vc_table_str(t, row, c_mat));
        m->E = vc_table_num(t, row, c_e);
        m->nu = vc_table_num(t, row, c_nu);
        m->rho = vc_table_num(t, row, c_rho);
        m->R = vc_table_num(t, row, c_r);
        m->v = vc_table_num(t, row, c_v);
        m->mu = vc_table_num(t, row, c_mu);
        m->e = vc_table_num(t, row, c_res);
        n++;
    }
    return n;
}

/* "aluminium oxide" -> "aluminium_oxide" for metric names. */
static const char *slug(const char *name, char *buf, size_t size) {
    size_t k;
    for (k = 0; name[k] && k + 1 < size; ++k) buf[k] = name[k] == ' ' ? '_' : name[k];
    buf[k] = '\0';
    return buf;
}

/* Tests 1 and 2: elastic impacts of both materials; checks against the Hertz reference values and
   writes force and overlap of both materials on one time axis. */
static void tests_1_2(int test, const material *mats, const vc_table *ref) {
    int c_test = vc_table_col(ref, "test"), c_mat = vc_table_col(ref, "material");
    int c_d = vc_table_col(ref, "delta_max_m"), c_f = vc_table_col(ref, "F_max_N"), c_t = vc_table_col(ref, "t_contact_s");
    int two = test == 1, k, row, steps;
    double tc[2], dt;
    impact im[2];
    char path[64], name[64], metric[128];
    fsdem_csv csv;
    for (k = 0; k < 2; ++k) tc[k] = hertz_contact_time(&mats[k], two, two ? 2 * mats[k].v : mats[k].v);
    dt = (tc[0] < tc[1] ? tc[0] : tc[1]) / 1000; /* one step for both, so the series share t */
    steps = (int)(1.1 * (tc[0] > tc[1] ? tc[0] : tc[1]) / dt);
    for (k = 0; k < 2; ++k) {
        memset(&im[k], 0, sizeof im[k]);
        im[k].m = mats[k];
        im[k].restitution = 1; /* elastic */
        im[k].vn = mats[k].v;
        im[k].dt = dt;
        im[k].steps = steps;
        im[k].rec_f = (double *)calloc((size_t)steps, sizeof(double));
        im[k].rec_d = (double *)calloc((size_t)steps, sizeof(double));
        run_impact(&im[k], two);
        for (row = 0; row < ref->rows; ++row)
            if ((int)vc_table_num(ref, row, c_test) == test && strcmp(vc_table_str(ref, row, c_mat), mats[k].name) == 0)
                break;
        slug(mats[k].name, name, sizeof name);
        snprintf(metric, sizeof metric, "test%d_%s_peak_force_N", test, name);
        vc_check_rel(CASE, metric, im[k].f_max, vc_table_num(ref, row, c_f), 0.01);
        snprintf(metric, sizeof metric, "test%d_%s_peak_overlap_m", test, name);
        vc_check_rel(CASE, metric, im[k].d_max, vc_table_num(ref, row, c_d), 0.01);
        snprintf(metric, sizeof metric, "test%d_%s_contact_time_s", test, name);
        vc_check_rel(CASE, metric, im[k].t_contact, vc_table_num(ref, row, c_t), 0.01);
    }
    snprintf(path, sizeof path, "test%d.csv", test);
    {
        char header[320], n0[64], n1[64];
        slug(mats[0].name, n0, sizeof n0);
        slug(mats[1].name, n1, sizeof n1);
        snprintf(header, sizeof header, "t,force_%s,overlap_%s,force_%s,overlap_%s", n0, n0, n1, n1);
        if (fsdem_csv_open(&csv, path, header) == FSDEM_OK) {
            for (k = 0; k < steps; ++k) {
                fsdem_real r[5];
                r[0] = (k + 1) * dt;
                r[1] = im[0].rec_f[k];
                r[2] = im[0].rec_d[k];
                r[3] = im[1].rec_f[k];
                r[4] = im[1].rec_d[k];
                fsdem_csv_row(&csv, r, 5);
            }
            fsdem_csv_close(&csv);
        }
    }
    for (k = 0; k < 2; ++k) {
        free(im[k].rec_f);
        free(im[k].rec_d);
    }
}

/* Copies the digitised test 1-2 curves in SI units (s or m, N) for the plots. */
static void write_curves(const vc_table *t) {
    int c_test = vc_table_col(t, "test"), c_q = vc_table_col(t, "quantity"), c_x = vc_table_col(t, "x"),
        c_y = vc_table_col(t, "y"), row, test;
    for (test = 1; test <= 2; ++test) {
        FILE *ft, *fo;
        char pt[64], po[64];
        snprintf(pt, sizeof pt, "ref_test%d_force_time.csv", test);
        snprintf(po, sizeof po, "ref_test%d_force_overlap.csv", test);
        ft = fopen(pt, "w");
        fo = fopen(po, "w");
        if (!ft || !fo) {
            if (ft) fclose(ft);
            if (fo) fclose(fo);
            return;
        }
        fprintf(ft, "t,force\n");
        fprintf(fo, "overlap,force\n");
        for (row = 0; row < t->rows; ++row) {
            if ((int)vc_table_num(t, row, c_test) != test) continue;
            /* the curves are in micrometres or microseconds and kilonewtons */
            fprintf(strcmp(vc_table_str(t, row, c_q), "force_vs_time") == 0 ? ft : fo, "%.8g,%.8g\n",
                    vc_table_num(t, row, c_x) * 1e-6, vc_table_num(t, row, c_y) * 1e3);
        }
        fclose(ft);
        fclose(fo);
    }
}

/* Test 3: normal impacts on the rigid plane with input restitution 0.2 .. 1.0. */
static void test_3(const material *mats) {
    fsdem_csv csv;
    int k, i;
    double worst[2] = {0, 0};
    if (fsdem_csv_open(&csv, "test3.csv", "e_input,ratio_aluminium_oxide,ratio_cast_iron") != FSDEM_OK) return;
    for (i = 2; i <= 10; ++i) {
        fsdem_real row[3];
        row[0] = i / 10.0;
        for (k = 0; k < 2; ++k) {
            impact im;
            char metric[128], name[64];
            memset(&im, 0, sizeof im);
            im.m = mats[k];
            im.restitution = i / 10.0;
            im.vn = mats[k].v;
            im.dt = hertz_contact_time(&mats[k], 0, mats[k].v) / 1000;
            run_impact(&im, 0);
            row[1 + k] = im.v_after.z / im.vn;
            snprintf(metric, sizeof metric, "test3_%s_restitution_e%.1f", slug(mats[k].name, name, sizeof name),
                     i / 10.0);
            vc_check_rel(CASE, metric, row[1 + k], i / 10.0, 0.02);
            if (fabs(row[1 + k] / (i / 10.0) - 1) > worst[k]) worst[k] = fabs(row[1 + k] / (i / 10.0) - 1);
        }
        fsdem_csv_row(&csv, row, 3);
    }
    fsdem_csv_close(&csv);
    vc_info(CASE, "test3 largest relative restitution error: %s %.2e, %s %.2e", mats[0].name, worst[0], mats[1].name,
            worst[1]);
}

/* Test 4 quantities of one oblique impact at `angle_deg` from the normal. The spin is reported in the
   reference's sign convention: positive omega adds to the contact point's tangential velocity,
   V_cp = V_t + omega R, so forward rolling (our omega_y > 0 for motion along +x on a floor with
   normal +z) is negative. */
static void oblique(const material *m, double angle_deg, double out[3]) {
    impact im;
    double a = angle_deg * PI / 180, vn = m->v * cos(a), vt = m->v * sin(a), omega;
    memset(&im, 0, sizeof im);
    im.m = *m;
    im.restitution = m->e;
    im.vn = vn;
    im.vt = vt;
    im.dt = hertz_contact_time(m, 0, vn) / 1000;
    run_impact(&im, 0);
    omega = -im.w_after.y;
    out[0] = im.v_after.x / vt;
    out[1] = omega;
    out[2] = atan((im.v_after.x + omega * m->R) / im.v_after.z) * 180 / PI;
}

static void test_4(const material *m, const vc_table *ref) {
    static const char *quantity[3] = {"tangential_restitution_coefficient", "post_collision_angular_velocity_rad_s",
                                      "rebound_angle_deg"};
    static const char *series[3] = {"Al. oxide", "Al. alloy", "Experiment"};
    static const char *metric[3] = {"test4_tangential_restitution_rms", "test4_rebound_omega_rms_rad_s",
                                    "test4_rebound_angle_rms_deg"};
    int c_q = vc_table_col(ref, "quantity"), c_s = vc_table_col(ref, "series"),
        c_x = vc_table_col(ref, "incident_angle_deg"), c_y = vc_table_col(ref, "value");
    int q, s, row, angle;
    FILE *fr = fopen("ref_test4.csv", "w"), *fa = fopen("test4_at_ref.csv", "w");
    fsdem_csv csv;
    if (!fr || !fa) {
        if (fr) fclose(fr);
        if (fa) fclose(fa);
        vc_check(CASE, "test4_files_written", 0, 1, 0);
        return;
    }
    /* dense sweep for the plots */
    if (fsdem_csv_open(&csv, "test4.csv", "incident_angle_deg,tangential_restitution,omega_rad_s,rebound_angle_deg") ==
        FSDEM_OK) {
        for (angle = 1; angle <= 89; ++angle) {
            double out[3];
            fsdem_real r[4];
            oblique(m, angle, out);
            r[0] = angle;
            r[1] = out[0];
            r[2] = out[1];
            r[3] = out[2];
            fsdem_csv_row(&csv, r, 4);
        }
        fsdem_csv_close(&csv);
    }
    /* the reference curves, numbered for gnuplot: quantity 1-3, series 1 Al oxide, 2 Al alloy, 3 experiment */
    fprintf(fr, "quantity,series,incident_angle_deg,value\n");
    for (row = 0; row < ref->rows; ++row)
        for (q = 0; q < 3; ++q)
            for (s = 0; s < 3; ++s)
                if (strcmp(vc_table_str(ref, row, c_q), quantity[q]) == 0 && strcmp(vc_table_str(ref, row, c_s), series[s]) == 0)
                    fprintf(fr, "%d,%d,%.8g,%.8g\n", q + 1, s + 1, vc_table_num(ref, row, c_x), vc_table_num(ref, row, c_y));
    fclose(fr);
    /* checks: the simulation at each digitised Al-oxide angle against the digitised value */
    fprintf(fa, "quantity,incident_angle_deg,simulated,reference\n");
    for (q = 0; q < 3; ++q) {
        double sum2 = 0, lo = INFINITY, hi = -INFINITY, worst = 0, worst_at = 0;
        int n = 0;
        for (row = 0; row < ref->rows; ++row) {
            double x, y, out[3];
            if (strcmp(vc_table_str(ref, row, c_q), quantity[q]) != 0 || strcmp(vc_table_str(ref, row, c_s), series[0]) != 0)
                continue;
            x = vc_table_num(ref, row, c_x);
            y = vc_table_num(ref, row, c_y);
            oblique(m, x, out);
            fprintf(fa, "%d,%.8g,%.8g,%.8g\n", q + 1, x, out[q], y);
            sum2 += (out[q] - y) * (out[q] - y);
            if (fabs(out[q] - y) > worst) {
                worst = fabs(out[q] - y);
                worst_at = x;
            }
            if (y < lo) lo = y;
            if (y > hi) hi = y;
            n++;
        }
        if (n == 0) {
            vc_check(CASE, metric[q], NAN, 0, 0);
            continue;
        }
        /* tolerance: 3% of the reference curve's range (README.md: digitisation scatter is 0.2-0.5%) */
        vc_check(CASE, metric[q], sqrt(sum2 / n), 0, 0.03 * (hi - lo));
        vc_info(CASE, "%s: %d points, RMS %.4g (%.2f%% of range %.4g), largest error %.4g at %.1f deg", metric[q], n,
                sqrt(sum2 / n), 100 * sqrt(sum2 / n) / (hi - lo), hi - lo, worst, worst_at);
    }
    fclose(fa);
}

int main(int argc, char **argv) {
    const char *refdir;
    char path[1024];
    vc_table params, hertz, curves, oblique_ref;
    material t1[2], t2[2], t3[2], t4[2];
    vc_begin(CASE, argc, argv, NULL);
    vc_tier("single impacts of tests 1-4");
    refdir = vc_data_dir();
    if (vc_table_load(&params, vc_path(path, sizeof path, refdir, "chung_ooi2011_test_parameters.csv")) ||
        vc_table_load(&hertz, vc_path(path, sizeof path, refdir, "chung_ooi2011_tests1_2_hertz_analytic.csv")) ||
        vc_table_load(&curves, vc_path(path, sizeof path, refdir, "chung_ooi2011_test1_test2_curves.csv")) ||
        vc_table_load(&oblique_ref, vc_path(path, sizeof path, refdir, "chung_ooi2011_test4_oblique_impact.csv"))) {
        vc_check(CASE, "reference_files_read", 0, 1, 0);
        return 1;
    }
    if (read_materials(&params, 1, t1, 2) != 2 || read_materials(&params, 2, t2, 2) != 2 ||
        read_materials(&params, 3, t3, 2) != 2 || read_materials(&params, 4, t4, 2) != 2) {
        vc_check(CASE, "parameters_read", 0, 1, 0);
        return 1;
    }
    tests_1_2(1, t1, &hertz);
    tests_1_2(2, t2, &hertz);
    write_curves(&curves);
    test_3(t3);
    test_4(&t4[0], &oblique_ref); /* aluminium oxide, the first test-4 row */
    vc_table_free(&params);
    vc_table_free(&hertz);
    vc_table_free(&curves);
    vc_table_free(&oblique_ref);
    return vc_exit_code();
}
