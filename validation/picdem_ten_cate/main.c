/* validation/picdem_ten_cate: a sphere settling in silicone oil onto the floor of a closed box,
   ten Cate et al. (2002) experiment E1 (Re = 1.5), with the resolved cut-cell PIC-DEM coupling
   (fsdem_pic_dem, seed 000 §2): sphere d = 15 mm, rho_s = 1120 kg/m^3, oil rho_f = 970 kg/m^3,
   mu_f = 0.373 Pa s, box 100 x 100 x 160 mm full of oil, released at rest with its bottom 120 mm
   above the floor, centred.
   Reference: the sphere's velocity and gap against time measured by ten Cate et al. (2002)
   (validation/data/ten_cate2002_E1_Re1.5_velocity.csv and _gap.csv; sources in their headers).
   Usage: run [DATA_DIR] [--tier=default|full] [--cells=N] [--t-end=S]
     --tier=default: dx = 20 mm / 8 (6 cells per diameter, to landing; README.md, "Tiers");
     --tier=full: dx = 20 mm / 18 (13.5 cells per diameter, 90 x 90 x 144 cells; --fine is the same);
     --cells=N: dx = 20 mm / N; --t-end=S: stop at S seconds (default 4 s, or once the sphere rests);
     --ppc=N particles per cell (default 1), --vfrac=F viscous_dt_fraction (default 1),
     --tol=T pressure and viscous solver tolerance (default 1e-6).
   Writes sphere.csv (t, gap, w) and forces.csv (t, pressure and viscous force, body volume). */
#include "fsdem.h"
#include "common.h"

#include <time.h>

#define CASE "picdem_ten_cate"
#define PI 3.14159265358979323846

/* experiment E1 (see the reference files' headers) */
static const double D = 0.015, rho_s = 1120, rho_f = 970, mu_f = 0.373;
static const double box_x = 0.10, box_y = 0.10, box_z = 0.16, release_gap = 0.120;
static const double u_inf = 0.038; /* m/s; terminal velocity measured by ten Cate et al. (2002) */
/* the plateau over which the terminal velocity is averaged (the measured curve is within 3% of
   u_inf there) */
static const double plateau_lo = 1.0, plateau_hi = 2.5;
#define CELLS_DEFAULT 8 /* the default tier's cells per 20 mm (README.md, "Tiers") */

#define MAX_SAMPLES 200000
static double st[MAX_SAMPLES], sgap[MAX_SAMPLES], sw[MAX_SAMPLES];
static int ns = 0;

/* Simulated w at time t (linear interpolation between samples; clamped at the ends). */
static double w_at(double t) {
    int a = 0, b = ns - 1;
    if (ns == 0) return NAN;
    if (t <= st[0]) return sw[0];
    if (t >= st[ns - 1]) return sw[ns - 1];
    while (b - a > 1) {
        const int m = (a + b) / 2;
        if (st[m] <= t) a = m;
        else b = m;
    }
    return sw[a] + (sw[b] - sw[a]) * (t - st[a]) / (st[b] - st[a]);
}

static double gap_at(double t) {
    int a = 0, b = ns - 1;
    if (ns == 0) return NAN;
    if (t <= st[0]) return sgap[0];
    if (t >= st[ns - 1]) return sgap[ns - 1];
    while (b - a > 1) {
        const int m = (a + b) / 2;
        if (st[m] <= t) a = m;
        else b = m;
    }
    return sgap[a] + (sgap[b] - sgap[a]) * (t - st[a]) / (st[b] - st[a]);
}

int main(int argc, char **argv) {
    const char *dir;
    int cells, a, ppc;
    double vfrac, tol, t_end;
    fsdem_pic_desc pd = fsdem_pic_desc_default(3);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_pic_dem_desc cd = fsdem_pic_dem_desc_default();
    fsdem_dem_material mat = fsdem_dem_material_default();
    fsdem_dem_particle_desc sph = fsdem_dem_particle_desc_default();
    fsdem_pic *pic;
    fsdem_dem *dem;
    fsdem_pic_dem *cpl;
    fsdem_csv csv, fcsv;
    fsdem_real dt_dem;
    vc_table tv, tg;
    double dx, R = D / 2, nu = mu_f / rho_f, rest_since = -1, dt_min = 1e9, dt_max_seen = 0;
    int m, k, failed = 0, landed = 0, ic_t, ic_w, ig_t, ig_g;
    char path[1024];
    clock_t c0 = clock();

    vc_begin(CASE, argc, argv, "--fine");
    cells = vc_option_int("--cells", vc_full() ? 18 : CELLS_DEFAULT);
    t_end = vc_option_num("--t-end", 4.0);
    ppc = vc_option_int("--ppc", 1);
    vfrac = vc_option_num("--vfrac", 1.0);
    tol = vc_option_num("--tol", 1e-6);
    dir = vc_data_dir();
    if (cells < 4) cells = 4;
    dx = 0.02 / cells; /* 20 mm divides both 100 mm and 160 mm */
    vc_tier("dx = 20 mm / %d (%.1f cells per diameter), to %g s or landing", cells, D / dx, t_end);

    if (vc_table_load(&tv, vc_path(path, sizeof path, dir, "ten_cate2002_E1_Re1.5_velocity.csv")) ||
        vc_table_load(&tg, vc_path(path, sizeof path, dir, "ten_cate2002_E1_Re1.5_gap.csv")))
        return 2;
    ic_t = vc_table_col(&tv, "t_s");
    ic_w = vc_table_col(&tv, "w_m_s");
    ig_t = vc_table_col(&tg, "t_s");
    ig_g = vc_table_col(&tg, "gap_over_D");
    if (ic_t < 0 || ic_w < 0 || ig_t < 0 || ig_g < 0) return 2;

    /* oil: the closed box, full (free_surface = 0), no-slip walls */
    pd.cell_size = (fsdem_real)dx;
    pd.domain_max = fsdem_v3((fsdem_real)box_x, (fsdem_real)box_y, (fsdem_real)box_z);
    pd.density = (fsdem_real)rho_f;
    pd.viscosity = (fsdem_real)nu;
    pd.free_surface = 0;
    for (a = 0; a < 6; ++a) pd.boundary[a] = FSDEM_PIC_BC_NO_SLIP;
    pd.jitter = 0;
    pd.particles_per_cell = ppc;
    pd.pressure_tolerance = (fsdem_real)tol;
    pd.viscosity_tolerance = (fsdem_real)tol;
    pd.min_particles_per_cell = ppc / 2;
    pd.max_particles_per_cell = 3 * ppc;
    pd.dt_max = (fsdem_real)5e-3;
    if (fsdem_pic_create(&pd, &pic) != FSDEM_OK) {
        char msg[256];
        fsdem_pic_desc_check(&pd, msg, sizeof msg);
        fprintf(stderr, "PIC: %s\n", msg);
        return 2;
    }
    if (fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), pd.domain_max, fsdem_v3(0, 0, 0), NULL) != FSDEM_OK) return 2;

    /* the sphere, with DEM walls at the floor and the sides */
    dd.domain_min = fsdem_v3(-0.01f, -0.01f, -0.01f);
    dd.domain_max = fsdem_v3((fsdem_real)(box_x + 0.01), (fsdem_real)(box_y + 0.01), (fsdem_real)(box_z + 0.01));
    dd.integrator = FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR;
    dd.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    dd.contact_offset = (fsdem_real)(2 * dx); /* seed 000 Eq. 19 */
    if (fsdem_dem_create(&dd, &dem) != FSDEM_OK) return 2;
    mat.density = (fsdem_real)rho_s;
    mat.young_modulus = 1e8;
    mat.restitution = 0.1;
    fsdem_dem_add_material(dem, &mat, &m);
    {
        fsdem_dem_wall_desc w;
        w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), m);
        fsdem_dem_add_wall(dem, &w, NULL);
        w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), m);
        fsdem_dem_add_wall(dem, &w, NULL);
        w = fsdem_dem_wall_plane(fsdem_v3((fsdem_real)box_x, 0, 0), fsdem_v3(-1, 0, 0), m);
        fsdem_dem_add_wall(dem, &w, NULL);
        w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 1, 0), m);
        fsdem_dem_add_wall(dem, &w, NULL);
        w = fsdem_dem_wall_plane(fsdem_v3(0, (fsdem_real)box_y, 0), fsdem_v3(0, -1, 0), m);
        fsdem_dem_add_wall(dem, &w, NULL);
    }
    sph.position = fsdem_v3((fsdem_real)(box_x / 2), (fsdem_real)(box_y / 2), (fsdem_real)(release_gap + R));
    sph.radius = (fsdem_real)R;
    sph.material = m;
    if (fsdem_dem_add_particle(dem, &sph, NULL) != FSDEM_OK) return 2;
    fsdem_dem_stable_dt(dem, &dt_dem);
    fsdem_dem_set_dt(dem, dt_dem);

    cd.pic = pic;
    cd.dem = dem;
    cd.viscous_dt_fraction = (fsdem_real)vfrac;
    if (fsdem_pic_dem_create(&cd, &cpl) != FSDEM_OK) return 2;
    vc_info(CASE, "dx %.4g mm (%.2f cells per diameter), grid %d x %d x %d, %d particles, nu %.4g m^2/s, dt_DEM %.3g s",
            dx * 1e3, D / dx, (int)(box_x / dx + 0.5), (int)(box_y / dx + 0.5), (int)(box_z / dx + 0.5),
            fsdem_pic_get_stats(pic).particles, nu, (double)dt_dem);

    fsdem_csv_open(&csv, "sphere.csv", "t,gap,w");
    fsdem_csv_open(&fcsv, "forces.csv", "t,pressure_force_z,viscous_force_z,volume,dt,substeps");
    st[0] = 0;
    sgap[0] = release_gap;
    sw[0] = 0;
    ns = 1;
    for (k = 0; fsdem_pic_dem_time(cpl) < t_end - 1e-9; ++k) {
        fsdem_dem_particles P;
        fsdem_pic_dem_force B;
        fsdem_pic_dem_stats cs;
        fsdem_real row[6];
        double t;
        fsdem_real dt = 0;
        fsdem_result r = fsdem_pic_dem_stable_dt(cpl, &dt);
        /* 0.95 of the stable step: the viscous limit is that of the last step's cut, and the next
           cut may be a little stricter (fsdem_pic_dem_step would refuse its own step then) */
        if (r == FSDEM_OK) r = fsdem_pic_dem_step_dt(cpl, (fsdem_real)0.95 * dt);
        if (r != FSDEM_OK) {
            fprintf(stderr, "t = %g s: %s\n", fsdem_pic_dem_time(cpl), fsdem_pic_dem_last_error(cpl));
            failed = 1;
            break;
        }
        t = fsdem_pic_dem_time(cpl);
        P = fsdem_dem_get_particles(dem);
        fsdem_pic_dem_get_force(cpl, 0, &B);
        cs = fsdem_pic_dem_get_stats(cpl);
        if (ns < MAX_SAMPLES) {
            st[ns] = t;
            sgap[ns] = (double)P.position[0].z - R;
            sw[ns] = (double)P.velocity[0].z;
            row[0] = (fsdem_real)t;
            row[1] = (fsdem_real)sgap[ns];
            row[2] = (fsdem_real)sw[ns];
            fsdem_csv_row(&csv, row, 3);
            ns++;
        }
        row[0] = (fsdem_real)t;
        row[1] = B.pressure_force.z;
        row[2] = B.viscous_force.z;
        row[3] = B.volume;
        row[4] = cs.coupling.dt;
        row[5] = (fsdem_real)cs.coupling.substeps;
        fsdem_csv_row(&fcsv, row, 6);
        if ((double)cs.coupling.dt < dt_min) dt_min = (double)cs.coupling.dt;
        if ((double)cs.coupling.dt > dt_max_seen) dt_max_seen = (double)cs.coupling.dt;
        if (k % 50 == 0) {
            fprintf(stderr, "t %.3f s gap %.5f m w %.5f m/s Fp %.4g Fv %.4g N dt %.3g s (viscous %.3g) CPU %.0f s\n", t,
                    sgap[ns - 1], sw[ns - 1], (double)B.pressure_force.z, (double)B.viscous_force.z, (double)cs.coupling.dt,
                    (double)cs.viscous_dt, (double)(clock() - c0) / CLOCKS_PER_SEC);
        }
        /* the sphere has landed once it touches the floor (gap within the contact offset) and has
           stayed slower than 1% of u_inf for 0.1 s */
        if (sgap[ns - 1] < 2.5 * dx && fabs(sw[ns - 1]) < 0.01 * u_inf) {
            if (rest_since < 0) rest_since = t;
            if (t - rest_since > 0.1) {
                landed = 1;
                break;
            }
        } else rest_since = -1;
    }
    fsdem_csv_close(&csv);
    fsdem_csv_close(&fcsv);

    {
        fsdem_pic_dem_stats cs = fsdem_pic_dem_get_stats(cpl);
        double plateau = 0, wsum = 0, exp_plateau = 0, ewsum = 0, rms = 0, rms_gap = 0;
        /* a run stopped by --t-end before plateau_hi averages both curves up to its end */
        const double plateau_end = landed || st[ns - 1] > plateau_hi ? plateau_hi : st[ns - 1];
        int i, n = 0, ng = 0;
        /* terminal velocity: the time average of -w over the plateau */
        for (i = 1; i < ns; ++i) {
            const double t0 = st[i - 1] > plateau_lo ? st[i - 1] : plateau_lo, t1 = st[i] < plateau_end ? st[i] : plateau_end;
            if (t1 > t0) {
                plateau += (t1 - t0) * -0.5 * (sw[i] + sw[i - 1]);
                wsum += t1 - t0;
            }
        }
        plateau = wsum > 0 ? plateau / wsum : NAN;
        for (i = 1; i < tv.rows; ++i) {
            const double ta = atof(tv.cell[(i - 1) * tv.cols + ic_t]), tb = atof(tv.cell[i * tv.cols + ic_t]);
            const double wa = atof(tv.cell[(i - 1) * tv.cols + ic_w]), wb = atof(tv.cell[i * tv.cols + ic_w]);
            const double t0 = ta > plateau_lo ? ta : plateau_lo, t1 = tb < plateau_end ? tb : plateau_end;
            if (t1 > t0 && tb > ta) {
                /* trapezoid of the linear interpolant over [t0, t1] */
                const double w0 = wa + (wb - wa) * (t0 - ta) / (tb - ta), w1 = wa + (wb - wa) * (t1 - ta) / (tb - ta);
                exp_plateau += (t1 - t0) * -0.5 * (w0 + w1);
                ewsum += t1 - t0;
            }
        }
        exp_plateau = ewsum > 0 ? exp_plateau / ewsum : NAN;
        /* the experiment's times up to the end of the run; after landing the sphere is at rest
           (w = 0); a run stopped earlier by --t-end is compared up to its end */
        for (i = 0; i < tv.rows; ++i) {
            const double t = atof(tv.cell[i * tv.cols + ic_t]), w = atof(tv.cell[i * tv.cols + ic_w]);
            double e;
            if (t > st[ns - 1] && !landed) continue;
            e = (t <= st[ns - 1] ? w_at(t) : 0) - w;
            rms += e * e;
            n++;
        }
        rms = n > 0 ? sqrt(rms / n) : NAN; /* no point compared: no pass */
        for (i = 0; i < tg.rows; ++i) {
            const double t = atof(tg.cell[i * tg.cols + ig_t]), gd = atof(tg.cell[i * tg.cols + ig_g]);
            double e;
            if (t > st[ns - 1] && !landed) continue;
            e = gap_at(t) / D - gd;
            rms_gap += e * e;
            ng++;
        }
        rms_gap = sqrt(rms_gap / (ng > 0 ? ng : 1));
        vc_info(CASE, "%lld coupled steps (dt %.3g .. %.3g s, viscous limit %.3g s), %lld DEM substeps, end t = %.3f s, CPU %.0f s "
                      "(PIC %.0f, DEM %.1f, coupling %.1f)",
                cs.coupling.steps, dt_min, dt_max_seen, (double)cs.viscous_dt, cs.coupling.substeps_total, fsdem_pic_dem_time(cpl),
                (double)(clock() - c0) / CLOCKS_PER_SEC, cs.coupling.seconds_fluid, cs.coupling.seconds_dem, cs.coupling.seconds_coupling);
        {
            const fsdem_pic_stats ps = fsdem_pic_get_stats(pic);
            vc_info(CASE, "PIC: %d particles, last step %d pressure / %d viscous iterations, CPU %.0f s in steps (pressure %.0f s)",
                    ps.particles, ps.pressure_iterations, ps.viscosity_iterations, ps.seconds_total, ps.seconds_pressure);
        }
        vc_info(CASE, "plateau %.1f-%.1f s: simulation %.5f m/s, digitised experiment %.5f m/s; gap RMS over the experiment's times %.3f D",
                plateau_lo, plateau_end, plateau, exp_plateau, rms_gap);
        vc_info(CASE, "velocity RMS over %d of the experiment's %d points (%s)", n, tv.rows,
                landed ? "the sphere landed: at rest afterwards" : "up to the end of the run");
        vc_check(CASE, "run_completed", failed ? 0 : 1, 1, 0);
        /* the resolution the coupler is validated at (README.md): the full tier's line */
        vc_check_full(CASE, "cells_per_diameter_at_least_10", D / dx >= 10 ? 1 : 0, 1, 0);
        /* the drag of the resolved sphere converges with the grid (README.md, "Tiers"): +20 % at 6
           cells per diameter, +12 % at 7.5, +4.7 % at 10.5; the full tier's line */
        vc_check_full_rel(CASE, "terminal_velocity_m_s", plateau, u_inf, 0.05);
        vc_check(CASE, "velocity_rms_over_u_inf", rms / u_inf, 0, 0.10);
    }
    vc_table_free(&tv);
    vc_table_free(&tg);
    fsdem_pic_dem_destroy(cpl);
    fsdem_dem_destroy(dem);
    fsdem_pic_destroy(pic);
    return vc_exit_code();
}
