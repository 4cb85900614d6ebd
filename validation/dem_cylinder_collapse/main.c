/* Collapse of six layers of aluminium cylinders (seed 000 section 3.1, after Zhang et al. 2009), 2D,
   with the linear law of seed 000 (Table 1) and, as a second run, with Hertz-Mindlin.
   Usage: run [DATA_DIR] [--tier=default|full]   (no reference file is read: no digitised data exist,
   see README.md; both tiers run the same)
   Writes mass_centre.csv, mass_centre_hertz.csv, energy.csv, energy_hertz.csv and particle snapshots
   particles_<t>.csv / particles_hertz_<t>.csv into the working directory. */
#include "fsdem.h"
#include "common.h"

#define CASE "dem_cylinder_collapse"

/* seed 000 section 3.1 and Table 1 */
static const double radius = 0.005;      /* m, d = 1 cm */
static const double length = 0.099;      /* m, cylinder length (disc_length) */
static const double density = 2700;      /* kg/m^3, aluminium */
static const double dx = 0.0005;         /* m, background grid of the PIC model */
static const double tank = 0.26 * 1.1;   /* m, 26 cm tank enlarged by 1.1 */
static const double theta = 0.01, alpha = 0.4, psi = 0.3, mu = 0.3, gamma_dt = 150;
static const double t_end = 1.0;         /* s */

typedef struct result {
    double t_snap[6], x_snap[6], z_snap[6];
    double ke_peak, t_ke_peak, t_ke_1pc;
} result;

static void mass_centre(fsdem_dem *dem, double *x_ave, double *z_ave) {
    fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    double sx = 0, sz = 0;
    int i;
    for (i = 0; i < p.count; ++i) {
        sx += p.position[i].x;
        sz += p.position[i].y; /* z of the paper is the vertical, y in fsdem 2D */
    }
    *x_ave = sx / p.count;
    *z_ave = sz / p.count;
}

/* Particles whose centre is outside the tank (x in [0, tank], y in [0, tank]). */
static int outside_tank(fsdem_dem *dem) {
    fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    int i, n = 0;
    for (i = 0; i < p.count; ++i)
        if (!(p.position[i].x > 0 && p.position[i].x < tank && p.position[i].y > 0 && p.position[i].y < tank)) n++;
    return n;
}

static int run(fsdem_dem_law law, const char *tag, result *res) {
    static const double snap[6] = {0, 0.1, 0.2, 0.3, 0.5, 1.0};
    fsdem_dem_desc desc = fsdem_dem_desc_default(2);
    fsdem_dem_material al = fsdem_dem_material_default();
    fsdem_dem *dem;
    fsdem_csv mc, en;
    fsdem_dem_energy e;
    double gap = 2 * dx, a = radius + gap, s = 2 * radius + gap, dt, pe0, e_min, rise = 0, max_overlap = 0, settled_overlap = 0;
    double e_total, ke;
    int mat, layer, k, outside = 0, next_snap = 0, every, failed = 0;
    long step, steps;
    char path[128], metric[128];
    const char *suffix = law == FSDEM_DEM_LAW_LINEAR ? "" : "_hertz";

    desc.domain_min = fsdem_v3(-0.05, -0.05, -1);
    desc.domain_max = fsdem_v3(tank + 0.05, tank + 0.2, 1);
    desc.law = law;
    desc.contact_offset = gap;  /* imaginary boundaries, seed 000 Eq. 19 */
    desc.linear_theta = theta;
    desc.linear_dx = dx;
    desc.disc_length = length;
    desc.dt_param = law == FSDEM_DEM_LAW_LINEAR ? gamma_dt : 0.2; /* Eq. 18 gamma; Rayleigh fraction */
    /* the seed's predictor-corrector (Eq. 21-24) for the seed's law; velocity Verlet for Hertz */
    desc.integrator = law == FSDEM_DEM_LAW_LINEAR ? FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR : FSDEM_DEM_INTEGRATOR_VERLET;
    if (fsdem_dem_create(&desc, &dem) != FSDEM_OK) return -1;
    al.density = density;
    al.poisson_ratio = psi;
    al.friction = mu;
    al.damping_alpha = alpha;
    al.young_modulus = 70e9;
    al.restitution = 0.5;
    fsdem_dem_add_material(dem, &al, &mat);
    {
        fsdem_dem_wall_desc w[3];
        w[0] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 1, 0), mat);     /* floor */
        w[1] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), mat);     /* left wall */
        w[2] = fsdem_dem_wall_plane(fsdem_v3(tank, 0, 0), fsdem_v3(-1, 0, 0), mat); /* right wall */
        for (k = 0; k < 3; ++k) fsdem_dem_add_wall(dem, &w[k], NULL);
    }
    /* six layers, 6 and 5 alternately, the 5-layers in the grooves; neighbours 2r + 2dx apart so the
       imaginary boundaries just touch; the plate is removed at t = 0 */
    for (layer = 0; layer < 6; ++layer) {
        int count = layer % 2 ? 5 : 6;
        for (k = 0; k < count; ++k) {
            fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
            p.radius = radius;
            p.material = mat;
            p.position = fsdem_v3(a + s * k + (layer % 2 ? s / 2 : 0), a + layer * s * sqrt(3.0) / 2, 0);
            if (fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK) return -1;
        }
    }
    {
        fsdem_real stable;
        fsdem_dem_stable_dt(dem, &stable);
        dt = stable;
    }
    fsdem_dem_set_dt(dem, (fsdem_real)dt);
    steps = (long)ceil(t_end / dt - 1e-9);
    every = (int)(1e-3 / dt + 0.5);
    if (every < 1) every = 1;
    vc_info(CASE, "%s: %d cylinders, dt = %.4g s, %ld steps", tag, fsdem_dem_get_particles(dem).count, dt, steps);

    snprintf(path, sizeof path, "mass_centre%s.csv", suffix);
    fsdem_csv_open(&mc, path, "t,x_ave,z_ave");
    snprintf(path, sizeof path, "energy%s.csv", suffix);
    fsdem_csv_open(&en, path, "t,kinetic,rotational,potential,elastic,total");
    e = fsdem_dem_get_energy(dem);
    pe0 = e.potential; /* from the floor: -m g.x with the floor at y = 0 */
    e_min = e.kinetic + e.rotational + e.potential + e.elastic;
    res->ke_peak = 0;
    res->t_ke_1pc = -1;
    for (step = 0;; ++step) {
        double t = fsdem_dem_time(dem);
        fsdem_dem_stats st = fsdem_dem_get_stats(dem);
        e = fsdem_dem_get_energy(dem);
        e_total = e.kinetic + e.rotational + e.potential + e.elastic;
        ke = e.kinetic + e.rotational;
        if (e_total - e_min > rise) rise = e_total - e_min; /* rise above the lowest energy so far */
        if (e_total < e_min) e_min = e_total;
        if (st.max_overlap > max_overlap) max_overlap = st.max_overlap;
        k = outside_tank(dem);
        if (k > outside) outside = k;
        if (ke > res->ke_peak) {
            res->ke_peak = ke;
            res->t_ke_peak = t;
            res->t_ke_1pc = -1;
        } else if (res->t_ke_1pc < 0 && ke < 0.01 * res->ke_peak) {
            res->t_ke_1pc = t;
        }
        if (step % every == 0 || step == steps) {
            fsdem_real row[6];
            double xa, za;
            mass_centre(dem, &xa, &za);
            row[0] = t;
            row[1] = xa;
            row[2] = za;
            fsdem_csv_row(&mc, row, 3);
            row[1] = e.kinetic;
            row[2] = e.rotational;
            row[3] = e.potential;
            row[4] = e.elastic;
            row[5] = e_total;
            fsdem_csv_row(&en, row, 6);
        }
        if (next_snap < 6 && t >= snap[next_snap] - dt / 2) {
            snprintf(path, sizeof path, "particles%s_%.2f.csv", suffix, snap[next_snap]);
            fsdem_dem_write_csv(dem, path);
            res->t_snap[next_snap] = t;
            mass_centre(dem, &res->x_snap[next_snap], &res->z_snap[next_snap]);
            next_snap++;
        }
        if (step == steps) break;
        if (fsdem_dem_step(dem) != FSDEM_OK) {
            fprintf(stderr, "%s (%s): %s\n", CASE, tag, fsdem_dem_last_error(dem));
            failed = 1;
            break;
        }
    }
    fsdem_csv_close(&mc);
    fsdem_csv_close(&en);
    {
        fsdem_dem_contact c[512];
        int n = fsdem_dem_contacts(dem, c, 512);
        for (k = 0; k < n && k < 512; ++k)
            if (c[k].overlap > settled_overlap) settled_overlap = c[k].overlap;
    }

    snprintf(metric, sizeof metric, "%s_run_completed", tag);
    vc_check(CASE, metric, failed ? 0 : 1, 1, 0);
    snprintf(metric, sizeof metric, "%s_particles_outside_tank", tag);
    vc_check(CASE, metric, outside, 0, 0);
    /* overlap of the imaginary boundaries (issue 9, amended line): during the run it must stay below
       the 2 dx gap (the real surfaces never touch, seed 000 section 2.2.2); in the settled pile it is
       set by theta (Eq. 10: one weight compresses a contact by theta dx), so it must stay below
       10 theta dx. Impacts exceed theta dx (README), so the former literal bound over the whole run,
       10 theta dx, is printed as information only. */
    snprintf(metric, sizeof metric, "%s_max_overlap_m", tag);
    vc_check(CASE, metric, max_overlap, 0, gap);
    snprintf(metric, sizeof metric, "%s_settled_max_overlap_m", tag);
    vc_check(CASE, metric, settled_overlap, 0, 10 * theta * dx);
    vc_info(CASE, "%s: former check max_overlap_theta_dx (largest overlap during the run in theta dx, tol 10): %.4g "
                  "(information: impacts, not the static sag, set it)", tag, max_overlap / (theta * dx));
    snprintf(metric, sizeof metric, "%s_energy_rise_J", tag);
    vc_check(CASE, metric, rise, 0, 1e-3 * pe0);
    vc_info(CASE, "%s: largest overlap %.3g theta dx (%.3g of the gap) during the run, %.3g theta dx at t = %.2f s", tag,
            max_overlap / (theta * dx), max_overlap / gap, settled_overlap / (theta * dx), t_end);
    vc_info(CASE, "%s: initial potential energy %.5g J, largest energy rise %.3g of it", tag, pe0, rise / pe0);
    for (k = 0; k < next_snap; ++k)
        vc_info(CASE, "%s: t = %.2f s  x_ave = %.4f m  z_ave = %.4f m", tag, res->t_snap[k], res->x_snap[k],
                res->z_snap[k]);
    if (res->t_ke_1pc >= 0)
        vc_info(CASE, "%s: kinetic energy peaks at %.4g J (t = %.3f s), below 1%% of the peak from t = %.3f s", tag,
                res->ke_peak, res->t_ke_peak, res->t_ke_1pc);
    else
        vc_info(CASE, "%s: kinetic energy peaks at %.4g J (t = %.3f s), still above 1%% of the peak at t = %.2f s",
                tag, res->ke_peak, res->t_ke_peak, t_end);
    fsdem_dem_destroy(dem);
    return failed;
}

int main(int argc, char **argv) {
    result lin, hertz;
    vc_begin(CASE, argc, argv, NULL);
    vc_tier("33 cylinders, 1 s, linear and Hertz");
    memset(&lin, 0, sizeof lin);
    memset(&hertz, 0, sizeof hertz);
    run(FSDEM_DEM_LAW_LINEAR, "linear", &lin);
    run(FSDEM_DEM_LAW_HERTZ_MINDLIN, "hertz", &hertz);
    return vc_exit_code();
}
