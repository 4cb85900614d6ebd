/* validation/picdem_floating: DEM bodies floating in PIC water (resolved cut-cell PIC-DEM,
   fsdem_pic_dem, seed 000 §2). A disc (2D) and a sphere (3D) of density 500 kg/m^3 are released at
   rest with their lowest point on the still surface of a closed tank and settle at the Archimedes
   draft; a neutrally buoyant body (1000 kg/m^3) released at rest at mid-depth stays where it is.
   Reference: analytical. The submerged segment (2D) or cap (3D) of the body holds the water mass
   m / rho_f; the water it displaces raises the level of the closed tank. Nothing is read from
   validation/data.
   Usage: run [DATA_DIR] [--tier=default|full] [--quick] [--pic] [--only=TAGS]   (both tiers have the
   same grids; the default tier runs the floating bodies for 1.5 s and averages over the last 0.5 s,
   the full tier for 4 s (2D) and 3 s (3D), averaging over 1.5 s and 1 s; --quick: the short runs in
   either tier; the checks keep their tolerances; --pic: the PIC transfer instead of FLIP; --only: the
   runs named, of floating_2d, neutral_2d, floating_3d, neutral_3d, comma-separated)
   Writes floating_2d.csv, floating_3d.csv, neutral_2d.csv, neutral_3d.csv: t, centre height, vertical
   velocity, pressure and viscous force, body volume the faces see, particle volume. See README.md. */
#include "fsdem.h"
#include "common.h"

#include <time.h>

#define CASE "picdem_floating"
#define PI 3.14159265358979323846

static const double rho_f = 1000, g = 9.81;

typedef struct setup {
    int dim;
    double width;     /* m; tank side (x, and y in 3D) */
    double height;    /* m; tank height */
    double depth;     /* m; still water depth before the body is added */
    double radius;    /* m */
    double dx;        /* m */
    double rho_s;     /* kg/m^3 */
    double release;   /* m; initial centre height */
    double t_end;     /* s */
    double dt_max;    /* s; the PIC's largest step */
    fsdem_pic_transfer transfer;
    double t_avg;     /* s; the final centre height is averaged over [t_end - t_avg, t_end] */
    const char *tag;
} setup;

typedef struct outcome {
    double mean_height;   /* time-averaged centre height over the last t_avg */
    double max_drift;     /* max |centre - release| (neutral runs) */
    double volume_drift;  /* max |V_particles / V_0 - 1| over the run */
    double water_volume;  /* particle volume after the coupler's creation (m^3, m^2 in 2D) */
    double faces_volume;  /* body volume the faces see, time-averaged like mean_height */
    double fp_up, fv_up;  /* time-averaged vertical pressure and viscous force (N) */
    double cpu;           /* s */
    long long steps, substeps;
    double dt_dem;
    int failed;
} outcome;

static double up(fsdem_vec3 v, int dim) { return dim == 2 ? (double)v.y : (double)v.z; }

/* Submerged area (2D, per metre) or volume (3D) of a body of radius R whose lowest point is s below
   the surface (0 <= s <= 2R). */
static double submerged(int dim, double R, double s) {
    if (s <= 0) return 0;
    if (s >= 2 * R) return dim == 2 ? PI * R * R : 4.0 / 3.0 * PI * R * R * R;
    if (dim == 2) return R * R * acos((R - s) / R) - (R - s) * sqrt(2 * R * s - s * s);
    return PI * s * s * (3 * R - s) / 3;
}

/* The floating equilibrium: draft s with submerged(s) = (rho_s / rho_f) x body volume (bisection),
   and the water level of a closed tank of cross-section `area` (m in 2D, m^2 in 3D) holding
   `water` (m^2 or m^3) besides the body. Returns the centre height. */
static double equilibrium(int dim, double R, double rho_s, double water, double area, double *level, double *draft) {
    const double target = rho_s / rho_f * submerged(dim, R, 2 * R);
    double a = 0, b = 2 * R;
    int it;
    for (it = 0; it < 200; ++it) {
        const double s = 0.5 * (a + b);
        if (submerged(dim, R, s) < target) a = s;
        else b = s;
    }
    *draft = 0.5 * (a + b);
    *level = (water + target) / area;
    return *level - *draft + R;
}

static outcome run(const setup *S) {
    const int dim = S->dim;
    const double W = S->width, R = S->radius, dx = S->dx;
    fsdem_pic_desc pd = fsdem_pic_desc_default(dim);
    fsdem_dem_desc dd = fsdem_dem_desc_default(dim);
    fsdem_pic_dem_desc cd = fsdem_pic_dem_desc_default();
    fsdem_dem_material mat = fsdem_dem_material_default();
    fsdem_dem_particle_desc body = fsdem_dem_particle_desc_default();
    fsdem_pic *pic = NULL;
    fsdem_dem *dem = NULL;
    fsdem_pic_dem *cpl = NULL;
    fsdem_csv csv;
    fsdem_real dt_dem = 0;
    outcome o;
    double v0, t0 = S->t_end - S->t_avg, wsum = 0;
    clock_t c0 = clock();
    char path[64];
    int m, k;
    memset(&o, 0, sizeof o);

    /* water: the tank [0, W] x [0, H] (x [0, W] y [0, W] z [0, H] in 3D), closed slip sides */
    pd.cell_size = (fsdem_real)dx;
    pd.density = (fsdem_real)rho_f;
    pd.domain_max = dim == 2 ? fsdem_v3((fsdem_real)W, (fsdem_real)S->height, 0) : fsdem_v3((fsdem_real)W, (fsdem_real)W, (fsdem_real)S->height);
    pd.dt_max = (fsdem_real)S->dt_max;
    pd.jitter = 0; /* a flat initial surface: still water is still (pic_hydrostatic) */
    pd.transfer = S->transfer;
    if (fsdem_pic_create(&pd, &pic) != FSDEM_OK) {
        fprintf(stderr, "%s: PIC creation failed\n", S->tag);
        o.failed = 1;
        return o;
    }
    if (fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0),
                           dim == 2 ? fsdem_v3((fsdem_real)W, (fsdem_real)S->depth, 0) : fsdem_v3((fsdem_real)W, (fsdem_real)W, (fsdem_real)S->depth),
                           fsdem_v3(0, 0, 0), NULL) != FSDEM_OK) {
        fprintf(stderr, "%s: fill failed: %s\n", S->tag, fsdem_pic_last_error(pic));
        o.failed = 1;
        fsdem_pic_destroy(pic);
        return o;
    }

    /* the body: one DEM disc or sphere; walls at the tank's sides and floor */
    dd.domain_min = fsdem_v3(-0.1f, -0.1f, dim == 2 ? 0 : -0.1f);
    dd.domain_max = dim == 2 ? fsdem_v3((fsdem_real)(W + 0.1), (fsdem_real)(S->height + 0.1), 0)
                             : fsdem_v3((fsdem_real)(W + 0.1), (fsdem_real)(W + 0.1), (fsdem_real)(S->height + 0.1));
    dd.integrator = FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR;
    dd.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    dd.contact_offset = (fsdem_real)(2 * dx); /* seed 000 Eq. 19 */
    if (fsdem_dem_create(&dd, &dem) != FSDEM_OK) {
        o.failed = 1;
        fsdem_pic_destroy(pic);
        return o;
    }
    mat.density = (fsdem_real)S->rho_s;
    mat.young_modulus = 1e8;
    mat.restitution = 0.5;
    fsdem_dem_add_material(dem, &mat, &m);
    {
        fsdem_dem_wall_desc w;
        w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), dim == 2 ? fsdem_v3(0, 1, 0) : fsdem_v3(0, 0, 1), m);
        fsdem_dem_add_wall(dem, &w, NULL);
        w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), m);
        fsdem_dem_add_wall(dem, &w, NULL);
        w = fsdem_dem_wall_plane(fsdem_v3((fsdem_real)W, 0, 0), fsdem_v3(-1, 0, 0), m);
        fsdem_dem_add_wall(dem, &w, NULL);
        if (dim == 3) {
            w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 1, 0), m);
            fsdem_dem_add_wall(dem, &w, NULL);
            w = fsdem_dem_wall_plane(fsdem_v3(0, (fsdem_real)W, 0), fsdem_v3(0, -1, 0), m);
            fsdem_dem_add_wall(dem, &w, NULL);
        }
    }
    body.position = dim == 2 ? fsdem_v3((fsdem_real)(W / 2), (fsdem_real)S->release, 0)
                             : fsdem_v3((fsdem_real)(W / 2), (fsdem_real)(W / 2), (fsdem_real)S->release);
    body.radius = (fsdem_real)R;
    body.material = m;
    if (fsdem_dem_add_particle(dem, &body, NULL) != FSDEM_OK) {
        o.failed = 1;
        goto done;
    }
    fsdem_dem_stable_dt(dem, &dt_dem);
    fsdem_dem_set_dt(dem, dt_dem);
    o.dt_dem = (double)dt_dem;

    cd.pic = pic;
    cd.dem = dem;
    if (fsdem_pic_dem_create(&cd, &cpl) != FSDEM_OK) {
        fprintf(stderr, "%s: coupler creation failed\n", S->tag);
        o.failed = 1;
        goto done;
    }
    v0 = (double)fsdem_pic_get_stats(pic).particle_volume; /* after the bodies' water was removed */
    o.water_volume = v0;

    snprintf(path, sizeof path, "%s.csv", S->tag);
    fsdem_csv_open(&csv, path, "t,height,w,pressure_force,viscous_force,faces_volume,particle_volume");
    for (k = 0; fsdem_pic_dem_time(cpl) < S->t_end - 1e-9; ++k) {
        fsdem_dem_particles P;
        fsdem_pic_dem_force B;
        fsdem_real row[7];
        double t_before = fsdem_pic_dem_time(cpl), t, dtk, h, vol;
        fsdem_result r = fsdem_pic_dem_step(cpl);
        if (r != FSDEM_OK) {
            fprintf(stderr, "%s: t = %g s: %s\n", S->tag, t_before, fsdem_pic_dem_last_error(cpl));
            o.failed = 1;
            break;
        }
        t = fsdem_pic_dem_time(cpl);
        dtk = t - t_before;
        P = fsdem_dem_get_particles(dem);
        fsdem_pic_dem_get_force(cpl, 0, &B);
        h = up(P.position[0], dim);
        vol = (double)fsdem_pic_get_stats(pic).particle_volume;
        if (fabs(vol / v0 - 1) > o.volume_drift) o.volume_drift = fabs(vol / v0 - 1);
        if (fabs(h - S->release) > o.max_drift) o.max_drift = fabs(h - S->release);
        if (t > t0) {
            const double w = t - (t_before > t0 ? t_before : t0);
            o.mean_height += w * h;
            o.faces_volume += w * (double)B.volume;
            o.fp_up += w * up(B.pressure_force, dim);
            o.fv_up += w * up(B.viscous_force, dim);
            wsum += w;
        }
        row[0] = (fsdem_real)t;
        row[1] = (fsdem_real)h;
        row[2] = (fsdem_real)up(P.velocity[0], dim);
        row[3] = (fsdem_real)up(B.pressure_force, dim);
        row[4] = (fsdem_real)up(B.viscous_force, dim);
        row[5] = B.volume;
        row[6] = (fsdem_real)vol;
        fsdem_csv_row(&csv, row, 7);
        (void)dtk;
    }
    fsdem_csv_close(&csv);
    if (wsum > 0) {
        o.mean_height /= wsum;
        o.faces_volume /= wsum;
        o.fp_up /= wsum;
        o.fv_up /= wsum;
    }
    {
        fsdem_pic_dem_stats st = fsdem_pic_dem_get_stats(cpl);
        o.steps = st.coupling.steps;
        o.substeps = st.coupling.substeps_total;
    }
done:
    o.cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
    fsdem_pic_dem_destroy(cpl);
    fsdem_dem_destroy(dem);
    fsdem_pic_destroy(pic);
    return o;
}

int main(int argc, char **argv) {
    int quick, pic_transfer, dim;
    const char *only; /* --only=<tags>: the runs named (floating_2d, neutral_2d, floating_3d, neutral_3d), comma-separated */
    vc_begin(CASE, argc, argv, NULL);
    quick = vc_flag("--quick") || !vc_full();
    pic_transfer = vc_flag("--pic");
    only = vc_option("--only");
    vc_tier("R = 10 dx (2D), 5 dx (3D); floating runs %s%s", quick ? "1.5 s" : "4 s (2D), 3 s (3D)",
            pic_transfer ? "; PIC transfer" : "");
    for (dim = 2; dim <= 3; ++dim) {
        setup S;
        outcome o, n;
        double level, draft, ref, mass, tank_area;
        char metric[80];
        memset(&S, 0, sizeof S);
        S.dim = dim;
        if (dim == 2) {
            S.width = 0.4;
            S.height = 0.4;
            S.depth = 0.25;
            S.radius = 0.05;
            S.dx = S.radius / 10;
            S.dt_max = 2e-3;
        } else {
            S.width = 0.32;
            S.height = 0.32;
            S.depth = 0.2;
            S.radius = 0.04;
            S.dx = 0.008;
            S.dt_max = 5e-3;
        }
        /* FLIP (the library's default). The PIC transfer (--pic) would damp the heave and the
           sloshing that an inviscid closed tank keeps, but with it the water next to a body picks up
           a spurious velocity of about g dt / 2 in every step (see README.md) */
        S.transfer = pic_transfer ? FSDEM_PIC_TRANSFER_PIC : FSDEM_PIC_TRANSFER_FLIP;
        tank_area = dim == 2 ? S.width : S.width * S.width;
        /* floating body, density 500: released at rest with its lowest point on the surface */
        S.rho_s = 500;
        S.release = S.depth + 0.3 * S.radius;
        S.t_end = quick ? 1.5 : dim == 2 ? 4.0 : 3.0;
        S.t_avg = quick ? 0.5 : dim == 2 ? 1.5 : 1.0;
        S.tag = dim == 2 ? "floating_2d" : "floating_3d";
        if (only && !strstr(only, S.tag)) goto neutral;
        o = run(&S);
        snprintf(metric, sizeof metric, "%s_run_completed", S.tag);
        vc_check(CASE, metric, o.failed ? 0 : 1, 1, 0);
        ref = equilibrium(dim, S.radius, S.rho_s, o.water_volume, tank_area, &level, &draft);
        mass = S.rho_s * submerged(dim, S.radius, 2 * S.radius);
        vc_info(CASE, "%s: dx %g m (R/dx %.2f), dt_DEM %.3g s, %lld coupled steps, %lld DEM substeps, CPU %.1f s", S.tag, S.dx,
                S.radius / S.dx, o.dt_dem, o.steps, o.substeps, o.cpu);
        vc_info(CASE, "%s: water %.6g, level %.5f m (still %.5f m), draft %.5f m, centre %.5f m, mean centre over the last %g s %.5f m",
                S.tag, o.water_volume, level, S.depth, draft, ref, S.t_avg, o.mean_height);
        vc_info(CASE, "%s: mean vertical pressure force %.5g N (weight %.5g), viscous %.3g, faces' volume %.6g (exact %.6g)",
                S.tag, o.fp_up, mass * g, o.fv_up, o.faces_volume, submerged(dim, S.radius, 2 * S.radius));
        snprintf(metric, sizeof metric, "%s_centre_height_error_over_d", S.tag);
        vc_check(CASE, metric, (o.mean_height - ref) / (2 * S.radius), 0, 0.02);
        snprintf(metric, sizeof metric, "%s_particle_volume_drift", S.tag);
        vc_check(CASE, metric, o.volume_drift, 0, 0.005);

    neutral:
        /* neutrally buoyant body released at rest at mid-depth */
        S.rho_s = 1000;
        S.release = S.depth / 2;
        S.t_end = 2.0;
        S.t_avg = 0.5;
        S.tag = dim == 2 ? "neutral_2d" : "neutral_3d";
        if (only && !strstr(only, S.tag)) continue;
        n = run(&S);
        snprintf(metric, sizeof metric, "%s_run_completed", S.tag);
        vc_check(CASE, metric, n.failed ? 0 : 1, 1, 0);
        vc_info(CASE, "%s: %lld coupled steps, CPU %.1f s, mean vertical pressure force %.5g (weight %.5g), faces' volume %.6g (exact %.6g)",
                S.tag, n.steps, n.cpu, n.fp_up, S.rho_s * submerged(dim, S.radius, 2 * S.radius) * g, n.faces_volume,
                submerged(dim, S.radius, 2 * S.radius));
        snprintf(metric, sizeof metric, "%s_max_drift_over_d", S.tag);
        vc_check(CASE, metric, n.max_drift / (2 * S.radius), 0, 0.02);
        snprintf(metric, sizeof metric, "%s_particle_volume_drift", S.tag);
        vc_check(CASE, metric, n.volume_drift, 0, 0.005);
    }
    return vc_exit_code();
}
