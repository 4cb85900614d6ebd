/* One granule settling in still water (Granule-In-Cell, seed 004): its velocity against the terminal
   velocity of its drag law, with and without virtual mass. The granule (d smaller than a cell)
   starts at rest under water in a closed box; the seed's quadratic law (Eq. 5b) with the
   pressure-gradient force (Eq. 5a) gives
       u_t = sqrt((rho_s - rho) g d / (18 C rho)),   C = 0.44,
   and from rest w(t) = u_t tanh(t / tau) with tau = u_t / a0, a0 = (rho_s - rho) g / (rho_s + C_a rho)
   (C_a = 1/2 with virtual mass, Eq. 14; 0 without): the 63 % time 0.745 tau is longer with virtual
   mass by (rho_s + rho / 2) / rho_s = 1.2.
   Usage: run [DATA_DIR] [--tier=default|full] [--ratio=R] [--t-end=S]   (R = dx / d; the reference is
   analytic, no file is read). Default tier: R = 8; full tier: R = 4, 8 and 16; each with and
   without virtual mass.
   Writes settling_R<R>_vm<0|1>.csv: t, z (m), w (m/s, the granule's vertical velocity), w_fluid
   (the water's vertical velocity sampled at the granule, m/s). */
#include "fsdem.h"
#include "common.h"
#include "gic_case.h"

#define CASE "gic_settling"
#define PI 3.14159265358979323846

static const double rho = 1000, rho_s = 2500, g = 9.81, d = 7.8e-4, C = 0.44;
static double T_END = 1.5;          /* s */
static const double WINDOW = 0.5;   /* s: the mean is taken over [WINDOW, T_END] */
static const double FINE = 0.03, FINE_DT = 2.5e-4; /* s: steps of FINE_DT up to FINE resolve the start */

typedef struct outcome {
    double w_mean, slip_mean, w_fluid_mean, tau63; /* m/s, s */
    int steps;
    double cpu;
    char error[512];
} outcome;

static outcome run(double ratio, double ut, int vm) {
    const double dx = ratio * d, W = 16 * dx, H = 24 * dx, depth = 22 * dx;
    fsdem_pic_desc pd = fsdem_pic_desc_default(3);
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_pic *pic = NULL;
    fsdem_dem *dem = NULL;
    fsdem_gic *gic = NULL;
    fsdem_csv csv;
    char name[64];
    outcome o;
    double sw = 0, ss = 0, sf = 0, n = 0;
    clock_t t0 = clock();
    memset(&o, 0, sizeof o);
    o.tau63 = NAN;
    pd.cell_size = (fsdem_real)dx;
    pd.domain_max = fsdem_v3((fsdem_real)W, (fsdem_real)W, (fsdem_real)H);
    pd.jitter = 0;
    pd.dt_max = (fsdem_real)5e-3;
    if (fsdem_pic_create(&pd, &pic) != FSDEM_OK ||
        fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)W, (fsdem_real)W, (fsdem_real)depth), fsdem_v3(0, 0, 0), NULL) !=
            FSDEM_OK) {
        snprintf(o.error, sizeof o.error, "PIC: %s", pic ? fsdem_pic_last_error(pic) : "create failed");
        fsdem_pic_destroy(pic);
        return o;
    }
    p.radius = (fsdem_real)(d / 2);
    /* off the grid's planes: a centre on a face or a node would sample the symmetric case only */
    p.position = fsdem_v3((fsdem_real)(0.5 * W + 0.31 * dx), (fsdem_real)(0.5 * W + 0.17 * dx), (fsdem_real)(depth - 3.4 * dx));
    dem = gic_case_dem(3, fsdem_v3(0, 0, 0), pd.domain_max, rho_s, fsdem_dem_material_default().friction, 0);
    if (!dem || fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK) {
        snprintf(o.error, sizeof o.error, "DEM: %s", dem ? fsdem_dem_last_error(dem) : "create failed");
        goto done;
    }
    if (gic_case_couple(pic, dem, vm, &gic, o.error, sizeof o.error)) goto done;
    snprintf(name, sizeof name, "settling_R%g_vm%d.csv", ratio, vm);
    if (fsdem_csv_open(&csv, name, "t,z,w,w_fluid") != FSDEM_OK) {
        snprintf(o.error, sizeof o.error, "cannot write %s", name);
        goto done;
    }
    while (fsdem_gic_time(gic) < T_END - 1e-9) {
        fsdem_gic_force rec;
        fsdem_dem_particles P;
        double t, w, wf;
        const double t_prev = fsdem_gic_time(gic), w_prev = -fsdem_dem_get_particles(dem).velocity[0].z;
        if ((t_prev < FINE ? fsdem_gic_step_dt(gic, (fsdem_real)FINE_DT) : fsdem_gic_step(gic)) != FSDEM_OK) {
            snprintf(o.error, sizeof o.error, "step %d: %s", o.steps, fsdem_gic_last_error(gic));
            break;
        }
        o.steps++;
        P = fsdem_dem_get_particles(dem);
        fsdem_gic_get_force(gic, 0, &rec);
        t = fsdem_gic_time(gic);
        w = -P.velocity[0].z;
        wf = -rec.fluid_velocity.z;
        {
            const fsdem_real row[4] = {(fsdem_real)t, P.position[0].z, (fsdem_real)-w, (fsdem_real)-wf};
            fsdem_csv_row(&csv, row, 4);
        }
        if (isnan(o.tau63) && w >= (1 - exp(-1.0)) * ut) /* between the two samples */
            o.tau63 = t_prev + (t - t_prev) * ((1 - exp(-1.0)) * ut - w_prev) / (w - w_prev);
        if (t >= WINDOW) {
            sw += w;
            ss += w - wf;
            sf += wf;
            n += 1;
        }
    }
    fsdem_csv_close(&csv);
    o.w_mean = n > 0 ? sw / n : NAN;
    o.slip_mean = n > 0 ? ss / n : NAN;
    o.w_fluid_mean = n > 0 ? sf / n : NAN;
done:
    o.cpu = (double)(clock() - t0) / CLOCKS_PER_SEC;
    fsdem_gic_destroy(gic);
    fsdem_dem_destroy(dem);
    fsdem_pic_destroy(pic);
    return o;
}

int main(int argc, char **argv) {
    static const double full_ratios[3] = {4, 8, 16};
    const double ut = sqrt((rho_s - rho) * g * d / (18 * C * rho)), inertia = (rho_s + 0.5 * rho) / rho_s;
    double ratio;
    int k, count;
    vc_begin(CASE, argc, argv, NULL);
    ratio = vc_option_num("--ratio", 0);
    T_END = vc_option_num("--t-end", T_END);
    count = ratio > 0 || !vc_full() ? 1 : 3;
    vc_tier("dx/d %s, %g s, with and without virtual mass", ratio > 0 ? "as given" : vc_full() ? "4, 8, 16" : "8", T_END);
    vc_info(CASE, "d %g m, rho_s %g, rho %g kg/m^3, the GIC law (Eq. 5b, C %g): u_t %.5f m/s, Re_t %.1f (nu 1e-6); 63 %% times "
            "0.745 u_t / a0: %.5f s without, %.5f s with virtual mass", d, rho_s, rho, C, ut, ut * d / 1e-6,
            atanh(1 - exp(-1.0)) * ut * rho_s / ((rho_s - rho) * g), atanh(1 - exp(-1.0)) * ut * (rho_s + 0.5 * rho) / ((rho_s - rho) * g));
    for (k = 0; k < count; ++k) {
        const double r = ratio > 0 ? ratio : vc_full() ? full_ratios[k] : 8;
        double tau[2] = {NAN, NAN};
        int vm;
        for (vm = 0; vm <= 1; ++vm) {
            const outcome o = run(r, ut, vm);
            char metric[64];
            snprintf(metric, sizeof metric, "terminal_velocity_R%g%s", r, vm ? "_vm" : "");
            if (o.error[0]) {
                vc_info(CASE, "dx/d %g, virtual mass %d: FAILED: %s", r, vm, o.error);
                vc_check(CASE, metric, NAN, ut, 0.03 * ut);
                continue;
            }
            tau[vm] = o.tau63;
            vc_info(CASE,
                    "dx/d %g, virtual mass %d: %d steps, %.1f s CPU; mean over [%g, %g] s: settling %.5f m/s (%+.2f %% of u_t), water "
                    "at the granule %.5f m/s down, slip %.5f m/s (%+.2f %%); 63 %% of u_t at %.5f s",
                    r, vm, o.steps, o.cpu, WINDOW, T_END, o.w_mean, 100 * (o.w_mean / ut - 1), o.w_fluid_mean, o.slip_mean,
                    100 * (o.slip_mean / ut - 1), o.tau63);
            /* the line: the granule's own velocity within 3 % of u_t */
            vc_check_rel(CASE, metric, o.w_mean, ut, 0.03);
            /* the force balance: the slip against the water sampled at the granule, within 3 % too */
            snprintf(metric, sizeof metric, "terminal_slip_R%g%s", r, vm ? "_vm" : "");
            vc_check_rel(CASE, metric, o.slip_mean, ut, 0.03);
        }
        {
            char metric[64];
            snprintf(metric, sizeof metric, "approach_time_ratio_R%g", r);
            /* the line: the 63 % time longer by the added-mass ratio, within 10 % */
            vc_check_rel(CASE, metric, tau[1] / tau[0], inertia, 0.10);
        }
    }
    return vc_exit_code();
}
