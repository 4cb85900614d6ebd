/* Hindered settling of a uniform suspension of DEM spheres in MPS water (unresolved MPS-DEM coupling,
   seed 002 §2.3, Model B, drag law of Eq. 26) against Richardson-Zaki: U = u_t eps^n, in a cell
   periodic along x and y over a floor (no side walls).
   Usage: run [DATA_DIR] [--tier=default|full] [--phi=F] [--t-end=S] [--t-start=S]   (the reference
   is analytic; no file is read). Default tier: phi 0.1 to T_END (about 3 min CPU); full tier: the
   three fractions 0.1, 0.2, 0.3 (0.2 and 0.3 have 2 and 3 times the particles: longer than 10 min
   together; --phi=all is the same); --phi=0.2 or 0.3 runs that one.
   Writes settling_<law>_phi<phi>.csv per run: t, v_band (mean vertical velocity of the particles in
   the measuring box, m/s), u_band (mean vertical velocity of the FLUID particles there), eps_band
   (mean porosity eps_k of the particles there), n_band, z_top (99th percentile of the particles'
   heights), z_bed (top of the bed: the highest height below which the particles' mean speed is
   under 10% of u_t, see bed_top), u_wall (the fluid within r_e of the side walls at the box's
   heights), q_total (the volume flux of fluid and solid through the whole cross-section at the
   box's heights: zero in an incompressible mixture in a closed tank), and profile_phi<phi>.csv
   (averages over the window in r0 slabs: fluid velocity, porosity of the FLUID particles and
   particle velocity in the core and within r_e of the side walls, FLUID particles per slab and the
   whole cross-section's volume flux), lateral_phi<phi>.csv (the same at the box's heights against
   the distance to the nearest side wall, r0/2 bins). */
#include "fsdem.h"
#include "common.h"

#define CASE "mpsdem_settling"
#define PI 3.14159265358979323846

/* fluid and particles: Re_t about 0.5 (see README) */
static const double rho = 1000, nu = 1e-4, rho_s = 2500, g = 9.81;
static const double r0 = 0.004, d = 0.002;
/* tank: W x W, suspension SUSP r0 high, clear water CLEAR r0 above it */
#define WIDTH 16
#define SUSP 28
#define CLEAR 6
/* measuring box: r_e (4.1 r0) from the side walls, heights [Z_LO, Z_HI] r0 */
#define Z_LO 10.0
#define Z_HI 18.0
static double T_START = 0.2; /* s: the window starts after the transient (see README); --t-start */
static double T_END = 0.4;   /* s: the cost bound (10 min for the three runs); --t-end */
#define NZ 40                /* profile slabs, r0 thick, from the floor */
#define NL 16                /* lateral bins, r0/2 wide, by the distance to the nearest side wall */
#define SAMPLE 0.01 /* s */

static double mu(void) { return rho * nu; }

static double per_volume(fsdem_drag_law law, double eps, double slip) {
    fsdem_real c = 0;
    if (fsdem_drag_coefficient(law, (fsdem_real)eps, (fsdem_real)d, (fsdem_real)slip, (fsdem_real)rho, (fsdem_real)mu(), &c, NULL,
                               NULL, 0) != FSDEM_OK)
        return NAN;
    return c;
}

/* Slip s with c(eps, d, s) s = rhs, by bisection (c s grows with s for every law here). */
static double balance(fsdem_drag_law law, double eps, double rhs) {
    double a = 0, b = 10;
    int it;
    for (it = 0; it < 200; ++it) {
        const double s = 0.5 * (a + b);
        if (per_volume(law, eps, s) * s > rhs) b = s;
        else a = s;
    }
    return 0.5 * (a + b);
}

/* Single-particle terminal velocity of the law: c(1, d, u) u = (rho_s - rho) g. */
static double terminal(fsdem_drag_law law) { return balance(law, 1.0, (rho_s - rho) * g); }

/* Richardson-Zaki exponent, Rowe (1987). */
static double rz_exponent(double Re) {
    const double r = pow(Re, 0.75);
    return (4.7 + 0.41 * r) / (1 + 0.175 * r);
}

/* Steady settling speed that the law itself predicts in a closed vessel with Model B (README):
   c(eps, s) s = eps (rho_s - rho) g for the slip s, and by continuity |v| = eps s. */
static double law_prediction(fsdem_drag_law law, double eps) { return eps * balance(law, eps, eps * (rho_s - rho) * g); }

static unsigned long long rng_state = 88172645463325252ULL;
static double urand(void) { /* xorshift64, uniform in [0, 1) */
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}

typedef struct outcome {
    double phi, eps_nominal;   /* solid fraction of the packing, 1 - phi */
    double v, v_rms;           /* m/s: mean settling speed (positive down) in the window, RMS of the samples */
    double u_fluid;            /* m/s: mean vertical velocity of the fluid in the box (positive up) */
    double u_wall;             /* m/s: the same for the fluid within r_e of the side walls, at T_END */
    double eps_k;              /* mean porosity the coupler measures at the particles in the box */
    double flux;               /* m/s: eps u + (1 - eps) v (zero in a closed tank) */
    double top_end, bed_end;   /* m: top front and bed top at T_END */
    int particles, fluid, mps_total, steps, failed;
    double cpu, cpu_mps, dt_mean, substeps;
    char error[1024];
} outcome;

/* Top of the bed: the lowest 1 r0 slab (from the floor up) whose particles' mean |v_z| exceeds
   0.1 u_t marks the first layer still settling; its bottom is the bed's top. */
static double bed_top(const fsdem_dem_particles *dv, double ut) {
    int slab;
    for (slab = 0; slab < SUSP; ++slab) {
        double s = 0;
        int n = 0, k;
        for (k = 0; k < dv->count; ++k) {
            const double z = dv->position[k].z;
            if (z >= slab * r0 && z < (slab + 1) * r0) s += fabs(dv->velocity[k].z), n++;
        }
        if (n && s / n > 0.1 * ut) return slab * r0;
    }
    return SUSP * r0;
}

static int cmp_double(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* window averages of the profiles: [0] fluid velocity, [1] FLUID porosity, [2] their count (core),
   [3]-[5] the same within r_e of the side walls, [6] particle velocity core, [7] count, [8] particle
   velocity wall, [9] count, [10] the whole cross-section's volume flux (fluid + solid), [11] free-
   surface FLUID particles, [12], [13] number density n_i of Eq. 7 core, wall, [14] pressure core */
enum { PF_U, PF_E, PF_N, PF_UW, PF_EW, PF_NW, PF_V, PF_NV, PF_VW, PF_NVW, PF_Q, PF_S, PF_ND, PF_NDW, PF_P, PF_COUNT };
/* lateral: [0] fluid velocity, [1] FLUID porosity, [2] count, [3] particle velocity, [4] count */
enum { PL_U, PL_E, PL_N, PL_V, PL_NV, PL_COUNT };

static outcome run(double phi, fsdem_drag_law law, double ut, const char *csv_name, const char *profile_name, const char *lateral_name) {
    double prof[NZ][PF_COUNT], lat[NL][PL_COUNT];
    const double W = WIDTH * r0, pad = 6 * r0, V = PI / 6 * d * d * d;
    double eps0 = 1 - phi;
    const double re = 4.1 * r0, x_lo = re, x_hi = W - re;
    fsdem_mps_desc md = fsdem_mps_desc_default_scheme(3, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_dem_material mat = fsdem_dem_material_default();
    fsdem_mps_dem_desc cd = fsdem_mps_dem_desc_default();
    fsdem_mps *mps = NULL;
    fsdem_dem *dem = NULL;
    fsdem_mps_dem *cpl = NULL;
    fsdem_vec3 *pos = NULL;
    double *heights = NULL;
    outcome o;
    fsdem_csv csv;
    int i, j, k, nf = 0, layers, nx, nz, material;
    double z_susp, a, ax, az, next = 0, sv = 0, sv2 = 0, su = 0, se = 0, sn = 0;
    memset(&o, 0, sizeof o);
    memset(prof, 0, sizeof prof);
    memset(lat, 0, sizeof lat);
    o.phi = phi;
    md.r0 = (fsdem_real)r0;
    md.model = FSDEM_MPS_MODEL_B;
    md.viscosity = (fsdem_real)nu;
    md.density = (fsdem_real)rho;
    /* laterally periodic (the set-up: no side walls, so no back-flow along them), one floor */
    md.domain_min = fsdem_v3(0, 0, (fsdem_real)-pad);
    md.domain_max = fsdem_v3((fsdem_real)W, (fsdem_real)W, (fsdem_real)((SUSP + CLEAR + 10) * r0 + pad));
    md.periodic[0] = md.periodic[1] = 1;
    if (fsdem_mps_create(&md, &mps) != FSDEM_OK) {
        snprintf(o.error, sizeof o.error, "fsdem_mps_create failed");
        o.failed = 1;
        return o;
    }
    fsdem_mps_add_box_walls(mps, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)W, (fsdem_real)W, (fsdem_real)((SUSP + CLEAR + 4) * r0)),
                            1u << FSDEM_SIDE_ZMAX, NULL);
    /* water: in the suspension the layers are r0 / eps0 apart (each MPS particle stands for a volume
       of mixture r0^3 / eps, Eq. 7 with 1/eps_j), r0 above it, with eps0 the porosity of the
       particle lattice itself, not the nominal 1 - phi: a lattice of nx^2 nz cells of the
       suspension's height z_susp = layers r0 / eps0 has phi = nx^2 nz V / (W^2 z_susp), so
       phi = c (1 - phi) with c = nx^2 nz V / (W^2 layers r0). (The nominal eps0 left the water
       0.8% short of n0 at phi 0.1, 0.9 against the lattice's 0.908, and the column sank.) */
    layers = (int)floor(SUSP * eps0 + 1e-9);
    a = d * cbrt(PI / (6 * phi));
    nx = (int)floor(W / a);
    nz = (int)floor(layers * r0 / eps0 / a);
    {
        const double c = nx * nx * nz * V / (W * W * layers * r0);
        eps0 = 1 - c / (1 + c);
    }
    z_susp = layers * r0 / eps0;
    pos = (fsdem_vec3 *)malloc(sizeof *pos * (size_t)(WIDTH * WIDTH * (layers + CLEAR)));
    for (k = 0; k < layers + CLEAR; ++k)
        for (j = 0; j < WIDTH; ++j)
            for (i = 0; i < WIDTH; ++i) {
                const double z = k < layers ? (k + 0.5) * r0 / eps0 : z_susp + (k - layers + 0.5) * r0;
                pos[nf++] = fsdem_v3((fsdem_real)((i + 0.5) * r0), (fsdem_real)((j + 0.5) * r0), (fsdem_real)z);
            }
    if (fsdem_mps_add_particles(mps, FSDEM_MPS_KIND_FLUID, nf, pos, NULL) != FSDEM_OK) {
        snprintf(o.error, sizeof o.error, "%s", fsdem_mps_last_error(mps));
        o.failed = 1;
        goto done;
    }
    o.fluid = nf;
    /* particles: a jittered cubic lattice of spacing a = d (pi / (6 phi))^(1/3) filling the suspension */
    dd.domain_min = md.domain_min;
    dd.domain_max = md.domain_max;
    dd.periodic[0] = dd.periodic[1] = 1;
    dd.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    if (fsdem_dem_create(&dd, &dem) != FSDEM_OK) {
        snprintf(o.error, sizeof o.error, "fsdem_dem_create failed");
        o.failed = 1;
        goto done;
    }
    mat.density = (fsdem_real)rho_s;
    mat.young_modulus = 1e6f; /* soft: few contacts in a suspension; the DEM step is then not the cost */
    mat.friction = 0.3f;
    mat.restitution = 0.5f;
    fsdem_dem_add_material(dem, &mat, &material);
    {
        fsdem_dem_wall_desc floor = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), material);
        fsdem_dem_add_wall(dem, &floor, NULL);
    }
    ax = W / nx;
    az = z_susp / nz;
    for (k = 0; k < nz; ++k)
        for (j = 0; j < nx; ++j)
            for (i = 0; i < nx; ++i) {
                fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
                const double jx = 0.5 * (ax - d) * 0.98, jz = 0.5 * (az - d) * 0.98;
                p.position = fsdem_v3((fsdem_real)((i + 0.5) * ax + jx * (2 * urand() - 1)), (fsdem_real)((j + 0.5) * ax + jx * (2 * urand() - 1)),
                                      (fsdem_real)((k + 0.5) * az + jz * (2 * urand() - 1)));
                p.radius = (fsdem_real)(0.5 * d);
                p.material = material;
                fsdem_dem_add_particle(dem, &p, NULL);
            }
    o.particles = nx * nx * nz;
    o.phi = o.particles * (PI / 6 * d * d * d) / (W * W * z_susp);
    o.eps_nominal = 1 - o.phi;
    {
        fsdem_real sdt = (fsdem_real)1e-5;
        fsdem_dem_stable_dt(dem, &sdt);
        fsdem_dem_set_dt(dem, sdt);
    }
    cd.mps = mps;
    cd.dem = dem;
    cd.drag = law;
    if (fsdem_mps_dem_create(&cd, &cpl) != FSDEM_OK) {
        snprintf(o.error, sizeof o.error, "fsdem_mps_dem_create failed");
        o.failed = 1;
        goto done;
    }
    heights = (double *)malloc(sizeof *heights * (size_t)o.particles);
    fsdem_csv_open(&csv, csv_name, "t,v_band,u_band,eps_band,n_band,z_top,z_bed,u_wall,q_total");
    while (fsdem_mps_dem_time(cpl) < T_END - 1e-9) {
        fsdem_result r = fsdem_mps_dem_step(cpl);
        double t = fsdem_mps_dem_time(cpl);
        if (r != FSDEM_OK) {
            snprintf(o.error, sizeof o.error, "step failed at t = %.4f s: %s", t, fsdem_mps_dem_last_error(cpl));
            o.failed = 1;
            break;
        }
        if (t >= next - 1e-9) {
            const fsdem_dem_particles dv = fsdem_dem_get_particles(dem);
            const fsdem_mps_particles mv = fsdem_mps_get_particles(mps);
            const double vol = W * W * r0;
            const int win = t >= T_START - 1e-9;
            double v = 0, u = 0, e = 0, uw = 0, q = 0, row[9];
            int n = 0, m = 0, mw = 0;
            next += SAMPLE;
            for (k = 0; k < dv.count; ++k) {
                const fsdem_vec3 x = dv.position[k];
                const int s = (int)floor(x.z / r0), wall = x.x < x_lo || x.x > x_hi || x.y < x_lo || x.y > x_hi;
                const double dw = fmin(fmin(x.x, W - x.x), fmin(x.y, W - x.y));
                const int b = (int)floor(dw / (0.5 * r0));
                if (x.z > Z_LO * r0 && x.z < Z_HI * r0) q += V * dv.velocity[k].z;
                if (!win) continue;
                if (s >= 0 && s < NZ) {
                    prof[s][wall ? PF_VW : PF_V] += dv.velocity[k].z, prof[s][wall ? PF_NVW : PF_NV] += 1;
                    prof[s][PF_Q] += V * dv.velocity[k].z / vol;
                }
                if (x.z > Z_LO * r0 && x.z < Z_HI * r0 && b >= 0 && b < NL) lat[b][PL_V] += dv.velocity[k].z, lat[b][PL_NV] += 1;
            }
            for (i = 0; i < mv.count; ++i) {
                const fsdem_vec3 x = mv.position[i];
                const int s = (int)floor(x.z / r0), wall = x.x < x_lo || x.x > x_hi || x.y < x_lo || x.y > x_hi;
                const double dw = fmin(fmin(x.x, W - x.x), fmin(x.y, W - x.y));
                const int b = (int)floor(dw / (0.5 * r0));
                if (mv.kind[i] != FSDEM_MPS_KIND_FLUID) continue;
                if (x.z > Z_LO * r0 && x.z < Z_HI * r0) q += r0 * r0 * r0 * mv.velocity[i].z;
                if (!win) continue;
                if (s >= 0 && s < NZ) {
                    prof[s][wall ? PF_UW : PF_U] += mv.velocity[i].z, prof[s][wall ? PF_EW : PF_E] += mv.porosity[i];
                    prof[s][wall ? PF_NW : PF_N] += 1;
                    prof[s][PF_S] += mv.surface[i];
                    prof[s][wall ? PF_NDW : PF_ND] += mv.number_density[i];
                    if (!wall) prof[s][PF_P] += mv.pressure[i];
                    prof[s][PF_Q] += r0 * r0 * r0 * mv.velocity[i].z / vol;
                }
                if (x.z > Z_LO * r0 && x.z < Z_HI * r0 && b >= 0 && b < NL)
                    lat[b][PL_U] += mv.velocity[i].z, lat[b][PL_E] += mv.porosity[i], lat[b][PL_N] += 1;
            }
            q /= W * W * (Z_HI - Z_LO) * r0;
            for (k = 0; k < dv.count; ++k) {
                const fsdem_vec3 x = dv.position[k];
                fsdem_mps_dem_force f;
                heights[k] = x.z;
                if (x.x < x_lo || x.x > x_hi || x.y < x_lo || x.y > x_hi || x.z < Z_LO * r0 || x.z > Z_HI * r0) continue;
                fsdem_mps_dem_get_force(cpl, k, &f);
                v += -dv.velocity[k].z;
                e += f.porosity;
                n++;
            }
            for (i = 0; i < mv.count; ++i) {
                const fsdem_vec3 x = mv.position[i];
                if (mv.kind[i] == FSDEM_MPS_KIND_FLUID && x.z > Z_LO * r0 && x.z < Z_HI * r0 &&
                    (x.x < x_lo || x.x > x_hi || x.y < x_lo || x.y > x_hi))
                    uw += mv.velocity[i].z, mw++;
                if (mv.kind[i] != FSDEM_MPS_KIND_FLUID || x.x < x_lo || x.x > x_hi || x.y < x_lo || x.y > x_hi || x.z < Z_LO * r0 ||
                    x.z > Z_HI * r0)
                    continue;
                u += mv.velocity[i].z;
                m++;
            }
            v = n ? v / n : NAN;
            e = n ? e / n : NAN;
            u = m ? u / m : NAN;
            qsort(heights, (size_t)dv.count, sizeof *heights, cmp_double);
            row[0] = (fsdem_real)t;
            row[1] = (fsdem_real)v;
            row[2] = (fsdem_real)u;
            row[3] = (fsdem_real)e;
            row[4] = (fsdem_real)n;
            row[5] = (fsdem_real)heights[(int)(0.99 * (dv.count - 1))];
            row[6] = (fsdem_real)bed_top(&dv, ut);
            row[7] = (fsdem_real)(mw ? uw / mw : NAN);
            row[8] = (fsdem_real)q;
            fsdem_csv_row(&csv, row, 9);
            o.u_wall = row[7];
            o.top_end = row[5];
            o.bed_end = row[6];
            if (t >= T_START - 1e-9) {
                sv += v;
                sv2 += v * v;
                su += u;
                se += e;
                sn += 1;
            }
        }
    }
    fsdem_csv_close(&csv);
    fsdem_csv_open(&csv, profile_name, "z,u_core,eps_core,n_fluid_core,u_wall,eps_wall,n_fluid_wall,v_core,v_wall,q_total,surface,nd_core,nd_wall,p_core");
    for (k = 0; k < NZ && sn > 0; ++k) {
        const double *P = prof[k];
        fsdem_real row[14];
        row[0] = (k + 0.5) * r0;
        row[1] = P[PF_N] ? P[PF_U] / P[PF_N] : NAN, row[2] = P[PF_N] ? P[PF_E] / P[PF_N] : NAN, row[3] = P[PF_N] / sn;
        row[4] = P[PF_NW] ? P[PF_UW] / P[PF_NW] : NAN, row[5] = P[PF_NW] ? P[PF_EW] / P[PF_NW] : NAN, row[6] = P[PF_NW] / sn;
        row[7] = P[PF_NV] ? P[PF_V] / P[PF_NV] : NAN, row[8] = P[PF_NVW] ? P[PF_VW] / P[PF_NVW] : NAN, row[9] = P[PF_Q] / sn;
        row[10] = P[PF_S] / sn, row[11] = P[PF_N] ? P[PF_ND] / P[PF_N] : NAN, row[12] = P[PF_NW] ? P[PF_NDW] / P[PF_NW] : NAN;
        row[13] = P[PF_N] ? P[PF_P] / P[PF_N] : NAN;
        fsdem_csv_row(&csv, row, 14);
    }
    fsdem_csv_close(&csv);
    fsdem_csv_open(&csv, lateral_name, "dist_wall,u,eps,n_fluid,v,n_particles");
    for (k = 0; k < NL && sn > 0; ++k) {
        const double *P = lat[k];
        fsdem_real row[6];
        row[0] = (k + 0.5) * 0.5 * r0;
        row[1] = P[PL_N] ? P[PL_U] / P[PL_N] : NAN, row[2] = P[PL_N] ? P[PL_E] / P[PL_N] : NAN, row[3] = P[PL_N] / sn;
        row[4] = P[PL_NV] ? P[PL_V] / P[PL_NV] : NAN, row[5] = P[PL_NV] / sn;
        fsdem_csv_row(&csv, row, 6);
    }
    fsdem_csv_close(&csv);
    if (sn > 0) {
        o.v = sv / sn;
        o.v_rms = sqrt(fmax(sv2 / sn - o.v * o.v, 0));
        o.u_fluid = su / sn;
        o.eps_k = se / sn;
        o.flux = o.eps_k * o.u_fluid - (1 - o.eps_k) * o.v;
    }
    {
        const fsdem_mps_dem_stats st = fsdem_mps_dem_get_stats(cpl);
        o.steps = (int)st.coupling.steps;
        o.cpu = st.coupling.seconds_fluid + (st.coupling.seconds_dem + st.coupling.seconds_coupling);
        o.cpu_mps = st.coupling.seconds_fluid;
        o.substeps = st.coupling.steps ? (double)st.coupling.substeps_total / (double)st.coupling.steps : 0;
        o.dt_mean = st.coupling.steps ? st.coupling.time / (double)st.coupling.steps : 0;
        o.mps_total = fsdem_mps_get_particles(mps).count;
    }
done:
    free(pos);
    free(heights);
    fsdem_mps_dem_destroy(cpl);
    fsdem_dem_destroy(dem);
    fsdem_mps_destroy(mps);
    return o;
}

int main(int argc, char **argv) {
    static const double fractions[] = {0.1, 0.2, 0.3};
    const fsdem_drag_law law = FSDEM_DRAG_LAW_ERGUN_WEN_YU;
    const double ut = terminal(law), Re_t = rho * d * ut / mu(), n = rz_exponent(Re_t);
    int f, only; /* the fraction run (index), or -1 for the three */
    const char *phi;
    vc_begin(CASE, argc, argv, NULL);
    only = vc_full() ? -1 : 0; /* default tier: phi 0.1 alone (163 s CPU); full tier: the three */
    T_END = vc_option_num("--t-end", T_END);
    T_START = vc_option_num("--t-start", T_START);
    if ((phi = vc_option("--phi")) != NULL) {
        if (!strcmp(phi, "all")) only = -1;
        else
            for (only = 0; only < 3 && fabs(fractions[only] - atof(phi)) > 1e-6; ++only) continue;
        if (only == 3) {
            fprintf(stderr, "--phi: 0.1, 0.2, 0.3 or all\n");
            return 2;
        }
    }
    if (!(T_END > 0 && T_START >= 0 && T_START < T_END)) {
        fprintf(stderr, "usage: run [DATA_DIR] [--tier=default|full] [--phi=F] [--t-end=S] [--t-start=S] (0 <= t_start < t_end)\n");
        return 2;
    }
    if (only < 0) vc_tier("r0 %g m, phi 0.1, 0.2, 0.3, window %g-%g s", r0, T_START, T_END);
    else vc_tier("r0 %g m, phi %.1f, window %g-%g s", r0, fractions[only], T_START, T_END);
    vc_info(CASE, "d %g m, r0 %g m (d = r0/%g), rho_s %g, rho %g kg/m^3, nu %g m^2/s; %s: u_t %.5f m/s (Stokes %.5f), Re_t %.3f, "
                  "Rowe's n %.4f",
            d, r0, r0 / d, rho_s, rho, nu, fsdem_drag_law_name(law), ut, (rho_s - rho) * g * d * d / (18 * mu()), Re_t, n);
    for (f = 0; f < 3; ++f) {
        char name[80], pname[80], lname[80], metric[80];
        outcome o;
        double U_rz, U_law;
        if (only >= 0 && f != only) continue;
        snprintf(name, sizeof name, "settling_%s_phi%.1f.csv", fsdem_drag_law_name(law), fractions[f]);
        snprintf(pname, sizeof pname, "profile_phi%.1f.csv", fractions[f]);
        snprintf(lname, sizeof lname, "lateral_phi%.1f.csv", fractions[f]);
        o = run(fractions[f], law, ut, name, pname, lname);
        U_rz = ut * pow(o.eps_nominal, n);
        U_law = law_prediction(law, o.eps_nominal);
        vc_info(CASE, "phi %.3f: %d particles, %d FLUID (%d MPS in all), %d coupled steps (mean dt %.2e s, %.1f DEM substeps each), %.1f s CPU (MPS %.1f s)%s%s", o.phi,
                o.particles, o.fluid, o.mps_total, o.steps, o.dt_mean, o.substeps, o.cpu, o.cpu_mps, o.failed ? "; FAILED: " : "", o.error);
        vc_info(CASE, "phi %.3f: settling %.5f m/s (RMS of samples %.2e), R-Z %.5f (%+.1f%%), the law's own closed-tank prediction %.5f "
                      "(%+.1f%%); fluid in the box %+.5f m/s; eps_k %.4f (nominal %.4f); volume flux %+.2e m/s; top %.1f r0, bed %.1f r0, "
                      "fluid within r_e of the side walls %+.5f m/s at %.2f s",
                o.phi, o.v, o.v_rms, U_rz, 100 * (o.v / U_rz - 1), U_law, 100 * (o.v / U_law - 1), o.u_fluid, o.eps_k, o.eps_nominal,
                o.flux, o.top_end / r0, o.bed_end / r0, o.u_wall, T_END);
        snprintf(metric, sizeof metric, "phi%.1f_settling_velocity_vs_RZ", fractions[f]);
        vc_check_rel(CASE, metric, o.v, U_rz, 0.10);
    }
    return vc_exit_code();
}
