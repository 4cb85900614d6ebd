/* Pressure drop through a packed bed of FIXED DEM spheres moving down at U through MPS water
   (unresolved MPS-DEM coupling, seed 002 §2.3, Model B, Eq. 26) against Ergun (1952): the closed-
   tank form, kept as information (INFO lines, full tier only) since ../mpsdem_fixed_bed checks
   Ergun on a periodic bed, where no wall, face or free surface enters (README.md).
   Usage: run [DATA_DIR] [--tier=default|full] [--t-end=S] [--t-start=S]   (the reference is
   analytic; no file is read; the window is [0.2, 0.4] s in the default tier, [0.2, 0.6] s in the
   full one)
   The tank is made tall enough for the bed's travel in t_end; the average is over [t_start, t_end].
   Writes pressure.csv (t, bed bottom z, p_below, p_above, dP_dyn = p_below - p_above - rho g dz,
   dP_dyn / L_pack, the drag on the bed sum F^d_z and sum F^d_z / eps_k per cross-section area, the
   superficial velocity through the bed relative to it in the core and within r_e of the walls),
   pressure_profile.csv (the dynamic pressure along the axis and along a line r0 from a wall,
   averaged over the window), porosity.csv (z relative to the bed's bottom face, mean porosity of the
   FLUID particles in slabs r0/2 thick: over the whole cross-section and over the core r_e from the
   walls; at the end of the run) and porosity_eq31.csv (Eq. 31 with the open-kernel normaliser on a
   r0/4 grid, cross-section mean). */
#include "fsdem.h"
#include "common.h"

#define CASE "mpsdem_fixed_bed_tank"

static const double rho = 1000, nu = 1e-6, g = 9.81;
static const double r0 = 0.004, d = 0.002, U = 0.05; /* Re_p = 100: see README */
#define WIDTH 16      /* tank W = 16 r0 square */
#define BED_LAYERS 32 /* bed L = 32 d = 16 r0 (3.9 r_e) thick, simple cubic packing of spacing d */
#define BELOW_END 8   /* r0 of water below the bed at the end of the run, at least */
#define ABOVE 10      /* r0 of water above the bed */
#define GAP 6.0       /* probes GAP r0 below and above the bed's faces: r_e (4.1 r0) + the probe radius r0 + margin */
#define T_END 0.6     /* s, full tier (about 6 min CPU): dP_dyn and the drag are steady from about 0.2 s (README) */
#define T_END_DEFAULT 0.4 /* s, default tier (about 2 min CPU; README.md, "Tiers") */
#define T_START 0.2   /* s, default: the average starts here */
#define NPROF 69      /* profile points, r0/2 apart, from GAP r0 below the bed to GAP r0 above it */
#define PI 3.14159265358979323846

static double ergun(double mu, double e) {
    return 150 * mu * pow(1 - e, 2) * U / (pow(e, 3) * d * d) + 1.75 * rho * (1 - e) * U * U / (pow(e, 3) * d);
}

/* The open part of the weight's integral at (px, py) in a tank [0, W]^2 (side walls only), by a
   quadrature of w_s over the kernel: n_s less the part beyond the walls (what the coupler subtracts
   with its WALL and DUMMY particles). */
static double open_weight(double px, double py, double W, double re) {
    const int n = 24;
    const double h = 2 * re / n;
    double all = 0, open = 0;
    int a, b, c;
    for (a = 0; a < n; ++a)
        for (b = 0; b < n; ++b)
            for (c = 0; c < n; ++c) {
                const double x = -re + (a + 0.5) * h, y = -re + (b + 0.5) * h, z = -re + (c + 0.5) * h;
                const double r = sqrt(x * x + y * y + z * z) / re;
                double w;
                if (r >= 1) continue;
                w = 4 * pow(r, 5) - 5 * pow(r, 4) + 1;
                all += w;
                if (px + x > 0 && px + x < W && py + y > 0 && py + y < W) open += w;
            }
    return 10 * PI / 21 * re * re * re * open / all;
}

int main(int argc, char **argv) {
    const double W = WIDTH * r0, L = BED_LAYERS * d, mu = rho * nu, pad = 6 * r0, re = 4.1 * r0, A = W * W;
    const double eps_pack = 1 - PI / 6, V = PI / 6 * d * d * d;
    double t_end, t_start, z_bed0;
    int below;
    fsdem_mps_desc md = fsdem_mps_desc_default_scheme(3, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_dem_material mat = fsdem_dem_material_default();
    fsdem_mps_dem_desc cd = fsdem_mps_dem_desc_default();
    fsdem_mps *mps = NULL;
    fsdem_dem *dem = NULL;
    fsdem_mps_dem *cpl = NULL;
    fsdem_vec3 *pos;
    fsdem_csv csv;
    int i, j, k, nf = 0, material, bed_fluid_layers, failed = 0, nsamp = 0, nprof = 0;
    double z, top, sum = 0, sum2 = 0, T = 0, next = 0, next_prof = 0, eps_core = 0;
    double s_drag = 0, s_drag_eps = 0, s_us_core = 0, s_us_wall = 0, s_eps_bed = 0;
    double prof_axis[NPROF] = {0}, prof_wall[NPROF] = {0};
    vc_begin(CASE, argc, argv, NULL);
    t_end = vc_option_num("--t-end", vc_full() ? T_END : T_END_DEFAULT);
    t_start = vc_option_num("--t-start", T_START);
    if (!(t_end > 0 && t_start >= 0 && t_start < t_end)) {
        fprintf(stderr, "usage: run [DATA_DIR] [--tier=default|full] [--t-end=S] [--t-start=S] (0 <= t_start < t_end)\n");
        return 2;
    }
    vc_tier("r0 %g m, bed of %d layers of d = %g m, window %g-%g s", r0, BED_LAYERS, d, t_start, t_end);
    if (!vc_full() && !vc_option("--t-end")) {
        vc_info(CASE, "information only, run in the full tier (or with --t-end): the Ergun lines are ../mpsdem_fixed_bed's");
        return 0;
    }
    /* the bed travels U t_end: start it high enough to keep BELOW_END r0 of water under it */
    below = BELOW_END + (int)ceil(U * t_end / r0);
    z_bed0 = below * r0;
    md.r0 = (fsdem_real)r0;
    md.model = FSDEM_MPS_MODEL_B;
    md.viscosity = (fsdem_real)nu;
    md.density = (fsdem_real)rho;
    md.domain_min = fsdem_v3((fsdem_real)-pad, (fsdem_real)-pad, (fsdem_real)-pad);
    md.domain_max = fsdem_v3((fsdem_real)(W + pad), (fsdem_real)(W + pad), (fsdem_real)((below + ABOVE + 30) * r0 + L + pad));
    if (fsdem_mps_create(&md, &mps) != FSDEM_OK) return 1;
    /* water on the r0 lattice below and above the bed; inside it, layers about r0 / eps_pack apart
       (each MPS particle stands for r0^3 / eps of mixture) */
    bed_fluid_layers = (int)floor(L * eps_pack / r0 + 0.5);
    pos = (fsdem_vec3 *)malloc(sizeof *pos * (size_t)(WIDTH * WIDTH * (below + ABOVE + bed_fluid_layers)));
    for (k = 0; k < below + bed_fluid_layers + ABOVE; ++k) {
        if (k < below) z = (k + 0.5) * r0;
        else if (k < below + bed_fluid_layers) z = z_bed0 + (k - below + 0.5) * L / bed_fluid_layers;
        else z = z_bed0 + L + (k - below - bed_fluid_layers + 0.5) * r0;
        for (j = 0; j < WIDTH; ++j)
            for (i = 0; i < WIDTH; ++i) pos[nf++] = fsdem_v3((fsdem_real)((i + 0.5) * r0), (fsdem_real)((j + 0.5) * r0), (fsdem_real)z);
    }
    top = z_bed0 + L + ABOVE * r0;
    fsdem_mps_add_box_walls(mps, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)W, (fsdem_real)W, (fsdem_real)(top + 6 * r0)), 1u << FSDEM_SIDE_ZMAX, NULL);
    if (fsdem_mps_add_particles(mps, FSDEM_MPS_KIND_FLUID, nf, pos, NULL) != FSDEM_OK) {
        printf("%s\n", fsdem_mps_last_error(mps));
        return 1;
    }
    free(pos);
    dd.domain_min = md.domain_min;
    dd.domain_max = md.domain_max;
    if (fsdem_dem_create(&dd, &dem) != FSDEM_OK) return 1;
    mat.friction = 0.3f;
    fsdem_dem_add_material(dem, &mat, &material);
    for (k = 0; k < BED_LAYERS; ++k)
        for (j = 0; j < (int)(W / d + 0.5); ++j)
            for (i = 0; i < (int)(W / d + 0.5); ++i) {
                fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
                p.position = fsdem_v3((fsdem_real)((i + 0.5) * d), (fsdem_real)((j + 0.5) * d), (fsdem_real)(z_bed0 + (k + 0.5) * d));
                p.velocity = fsdem_v3(0, 0, (fsdem_real)-U);
                p.radius = (fsdem_real)(0.5 * d);
                p.material = material;
                p.fixed = 1;
                fsdem_dem_add_particle(dem, &p, NULL);
            }
    fsdem_dem_set_dt(dem, 1e-3f); /* fixed particles only: no contact to resolve */
    cd.mps = mps;
    cd.dem = dem;
    cd.drag = FSDEM_DRAG_LAW_ERGUN_WEN_YU;
    if (fsdem_mps_dem_create(&cd, &cpl) != FSDEM_OK) return 1;
    {
        const double Re = rho * U * d / mu, visc = 150 * mu * pow(1 - eps_pack, 2) * U / (pow(eps_pack, 3) * d * d),
                     inert = 1.75 * rho * (1 - eps_pack) * U * U / (pow(eps_pack, 3) * d);
        vc_info(CASE, "d %g m, r0 %g m, bed %d x %d x %d fixed spheres (L %.4f m = %.1f r0 = %.2f r_e), eps_pack %.4f, U %g m/s, Re_p %.1f; "
                      "Ergun: viscous %.0f Pa/m, inertial %.0f Pa/m, sum %.0f Pa/m (%.3f rho g); run to %.2f s, averages over [%.2f, %.2f] s, "
                      "bed bottom starts %d r0 above the floor",
                d, r0, (int)(W / d + 0.5), (int)(W / d + 0.5), BED_LAYERS, L, L / r0, L / re, eps_pack, U, Re, visc, inert,
                visc + inert, (visc + inert) / (rho * g), t_end, t_start, t_end, below);
    }
    fsdem_csv_open(&csv, "pressure.csv", "t,z_bed,p_below,p_above,dP_dyn,dP_dyn_per_L,drag_per_A,drag_over_eps_per_A,Us_core,Us_wall");
    while (fsdem_mps_dem_time(cpl) < t_end - 1e-9) {
        fsdem_result r = fsdem_mps_dem_step(cpl);
        const double t = fsdem_mps_dem_time(cpl), zb = z_bed0 - U * t;
        if (r != FSDEM_OK) {
            vc_info(CASE, "step failed at t = %.4f s: %s", t, fsdem_mps_dem_last_error(cpl));
            failed = 1;
            break;
        }
        {
            const fsdem_vec3 below_pt = fsdem_v3((fsdem_real)(W / 2), (fsdem_real)(W / 2), (fsdem_real)(zb - GAP * r0));
            const fsdem_vec3 above_pt = fsdem_v3((fsdem_real)(W / 2), (fsdem_real)(W / 2), (fsdem_real)(zb + L + GAP * r0));
            const double dt = fsdem_mps_dem_get_stats(cpl).coupling.dt;
            fsdem_real pb, pa, row[10];
            double dp;
            fsdem_mps_probe_pressure(mps, below_pt, (fsdem_real)r0, &pb);
            fsdem_mps_probe_pressure(mps, above_pt, (fsdem_real)r0, &pa);
            dp = pb - pa - rho * g * (L + 2 * GAP * r0);
            if (t >= t_start - 1e-9) {
                sum += dt * dp;
                sum2 += dt * dp * dp;
                T += dt;
            }
            if (t >= next - 1e-9) {
                /* the drag on the bed (sum F^d_z; Model B gives the fluid F^d / eps_k + the buoyancy, so
                   in steady state sum F^d_z / eps_k = A dP_dyn), and the superficial velocity relative to
                   the bed, U_s = q + eps U with q the fluid's volume flux (r0^3 per MPS particle) in the
                   bed r_e from its faces: in the core and within r_e of the side walls */
                const fsdem_mps_particles mv = fsdem_mps_get_particles(mps);
                const int nd = fsdem_dem_get_particles(dem).count;
                double drag = 0, drag_eps = 0, qc = 0, qw = 0, us_core, us_wall;
                const double h_slab = L - 2 * re, a_core = (W - 2 * re) * (W - 2 * re);
                for (k = 0; k < nd; ++k) {
                    fsdem_mps_dem_force f;
                    if (fsdem_mps_dem_get_force(cpl, k, &f) != FSDEM_OK || !f.wet) continue;
                    drag += f.drag.z;
                    drag_eps += f.drag.z / f.porosity;
                }
                for (i = 0; i < mv.count; ++i) {
                    const fsdem_vec3 x = mv.position[i];
                    const int core = x.x > re && x.x < W - re && x.y > re && x.y < W - re;
                    if (mv.kind[i] != FSDEM_MPS_KIND_FLUID || x.z < zb + re || x.z > zb + L - re) continue;
                    if (core) qc += r0 * r0 * r0 * mv.velocity[i].z;
                    else qw += r0 * r0 * r0 * mv.velocity[i].z;
                }
                us_core = qc / (a_core * h_slab) + eps_pack * U;
                us_wall = qw / ((A - a_core) * h_slab) + eps_pack * U;
                if (t >= t_start - 1e-9) {
                    s_drag += drag / A, s_drag_eps += drag_eps / A, s_us_core += us_core, s_us_wall += us_wall;
                    nsamp++;
                }
                next += 0.005;
                row[0] = (fsdem_real)t, row[1] = (fsdem_real)zb, row[2] = pb, row[3] = pa, row[4] = (fsdem_real)dp, row[5] = (fsdem_real)(dp / L);
                row[6] = (fsdem_real)(drag / A), row[7] = (fsdem_real)(drag_eps / A), row[8] = (fsdem_real)us_core, row[9] = (fsdem_real)us_wall;
                fsdem_csv_row(&csv, row, 10);
            }
            if (t >= t_start - 1e-9 && t >= next_prof - 1e-9) {
                /* dynamic pressure p + rho g z relative to the top probe, on the axis and r0 from a wall */
                for (k = 0; k < NPROF; ++k) {
                    const double zz = zb - GAP * r0 + 0.5 * r0 * k;
                    fsdem_real p1, p2;
                    fsdem_mps_probe_pressure(mps, fsdem_v3((fsdem_real)(W / 2), (fsdem_real)(W / 2), (fsdem_real)zz), (fsdem_real)r0, &p1);
                    fsdem_mps_probe_pressure(mps, fsdem_v3((fsdem_real)(W / 2), (fsdem_real)r0, (fsdem_real)zz), (fsdem_real)r0, &p2);
                    prof_axis[k] += p1 + rho * g * (zz - (zb + L + GAP * r0)) - pa;
                    prof_wall[k] += p2 + rho * g * (zz - (zb + L + GAP * r0)) - pa;
                }
                next_prof = t + 0.01;
                ++nprof;
            }
        }
    }
    fsdem_csv_close(&csv);
    {
        /* porosity profile of the FLUID particles relative to the bed's bottom face, and the Ergun
           integral over it: int Ergun(eps(z), U) dz (U_s = U at every height, README) */
        enum { NS = 200 };
        double se[NS] = {0}, sc[NS] = {0}, ne[NS] = {0}, nc[NS] = {0}, integral = 0, zb = z_bed0 - U * fsdem_mps_dem_time(cpl);
        double eb = 0, eps_bed_all = 0, eq31_bed = 0;
        int n_bed = 0, n_eq31 = 0;
        const fsdem_mps_particles mv = fsdem_mps_get_particles(mps);
        const double h = 0.5 * r0, z0 = -(GAP + 2) * r0;
        double ec = 0;
        int n_core = 0;
        for (i = 0; i < mv.count; ++i) {
            const fsdem_vec3 x = mv.position[i];
            const int s = (int)floor((x.z - zb - z0) / h);
            const int core = x.x > re && x.x < W - re && x.y > re && x.y < W - re;
            if (mv.kind[i] != FSDEM_MPS_KIND_FLUID || s < 0 || s >= NS) continue;
            se[s] += mv.porosity[i], ne[s] += 1;
            if (core) sc[s] += mv.porosity[i], nc[s] += 1;
            if (core && x.z > zb + re && x.z < zb + L - re) ec += mv.porosity[i], n_core++;
            if (x.z > zb + re && x.z < zb + L - re) eb += mv.porosity[i], n_bed++;
        }
        eps_core = n_core ? ec / n_core : NAN;
        eps_bed_all = n_bed ? eb / n_bed : NAN;
        (void)s_eps_bed;
        fsdem_csv_open(&csv, "porosity.csv", "z_rel,eps_all,eps_core");
        for (k = 0; k < NS; ++k) {
            fsdem_real row[3];
            if (!ne[k]) continue;
            row[0] = (fsdem_real)(z0 + (k + 0.5) * h);
            row[1] = (fsdem_real)(se[k] / ne[k]);
            row[2] = (fsdem_real)(nc[k] ? sc[k] / nc[k] : NAN);
            fsdem_csv_row(&csv, row, 3);
        }
        fsdem_csv_close(&csv);
        /* Eq. 31 with the open-kernel normaliser (as the coupler since 6aede37) evaluated on a fine
           vertical grid (r0/4), averaged over 8 x 8 points of the cross-section, and Ergun
           integrated over it between the probes */
        {
            const fsdem_dem_particles dv = fsdem_dem_get_particles(dem);
            const double hz = 0.25 * r0;
            double zz, ns_open[8][8];
            int a, b;
            for (a = 0; a < 8; ++a)
                for (b = 0; b < 8; ++b) ns_open[a][b] = open_weight((a + 0.5) * W / 8, (b + 0.5) * W / 8, W, re);
            fsdem_csv_open(&csv, "porosity_eq31.csv", "z_rel,eps");
            for (zz = -GAP * r0 + 0.5 * hz; zz < L + GAP * r0; zz += hz) {
                double e = 0;
                int q;
                fsdem_real row[2];
                for (a = 0; a < 8; ++a)
                    for (b = 0; b < 8; ++b) {
                        const double px = (a + 0.5) * W / 8, py = (b + 0.5) * W / 8, pz = zb + zz;
                        double solid = 0;
                        for (q = 0; q < dv.count; ++q) {
                            const double dx = dv.position[q].x - px, dy = dv.position[q].y - py, dz = dv.position[q].z - pz;
                            const double r = sqrt(dx * dx + dy * dy + dz * dz) / re;
                            if (r < 1) solid += (4 * pow(r, 5) - 5 * pow(r, 4) + 1) * V;
                        }
                        e += 1 - solid / ns_open[a][b];
                    }
                e /= 64;
                if (zz > re && zz < L - re) eq31_bed += e, n_eq31++;
                row[0] = (fsdem_real)zz, row[1] = (fsdem_real)e;
                fsdem_csv_row(&csv, row, 2);
                integral += hz * (150 * mu * pow(1 - e, 2) * U / (pow(e, 3) * d * d) + 1.75 * rho * (1 - e) * U * U / (pow(e, 3) * d));
            }
        }
        fsdem_csv_close(&csv);
        {
            const fsdem_mps_dem_stats st = fsdem_mps_dem_get_stats(cpl);
            const double mean = T > 0 ? sum / T : NAN, rms = T > 0 ? sqrt(fmax(sum2 / T - mean * mean, 0)) : NAN;
            const double ergun_pack = ergun(mu, eps_pack), ergun_core = ergun(mu, eps_core);
            const double m_drag = nsamp ? s_drag / nsamp : NAN, m_drag_eps = nsamp ? s_drag_eps / nsamp : NAN;
            /* Ergun's drag on the whole bed from the law: per unit volume beta w = eps^2 dP/dx at the
               slip w = U / eps, i.e. sum F^d_z = A L eps Ergun(eps) */
            vc_info(CASE, "%lld coupled steps (mean dt %.2e s), %d MPS particles, %.1f s CPU (MPS %.1f s)%s", st.coupling.steps,
                    st.coupling.steps ? st.coupling.time / (double)st.coupling.steps : 0, mv.count, st.coupling.seconds_fluid + (st.coupling.seconds_dem + st.coupling.seconds_coupling), st.coupling.seconds_fluid,
                    failed ? "; FAILED" : "");
            vc_info(CASE, "dP_dyn over [%.2f, %.2f] s: mean %.1f Pa, RMS of its fluctuation %.1f Pa (%.1f%%); per packing length %.0f Pa/m",
                    t_start, t_end, mean, rms, 100 * rms / mean, mean / L);
            vc_info(CASE, "porosity in the bed r_e from its faces: FLUID particles r_e from the walls %.4f, all FLUID particles %.4f, "
                          "Eq. 31 (open-kernel normaliser) cross-section mean %.4f (packing %.4f); Ergun at the core's %.0f Pa/m; "
                          "Ergun integrated over the Eq. 31 profile between the probes: %.1f Pa (measured %+.1f%%)",
                    eps_core, eps_bed_all, n_eq31 ? eq31_bed / n_eq31 : NAN, eps_pack, ergun_core, integral, 100 * (mean / integral - 1));
            vc_info(CASE, "balance over [%.2f, %.2f] s (%d samples): drag on the bed sum F^d_z / A %.1f Pa (Ergun eps L Ergun(eps) %.1f), "
                          "sum F^d_z / eps_k / A %.1f Pa vs dP_dyn %.1f Pa (%+.1f%%); superficial velocity relative to the bed: "
                          "core %.4f m/s, within r_e of the walls %.4f m/s (U %.4f)",
                    t_start, t_end, nsamp, m_drag, eps_pack * L * ergun_pack, m_drag_eps, mean, 100 * (mean / m_drag_eps - 1),
                    nsamp ? s_us_core / nsamp : NAN, nsamp ? s_us_wall / nsamp : NAN, U);
            fsdem_csv_open(&csv, "pressure_profile.csv", "z_rel,p_dyn_axis,p_dyn_wall");
            for (k = 0; k < NPROF && nprof; ++k) {
                fsdem_real row[3];
                row[0] = (fsdem_real)(-GAP * r0 + 0.5 * r0 * k), row[1] = (fsdem_real)(prof_axis[k] / nprof), row[2] = (fsdem_real)(prof_wall[k] / nprof);
                fsdem_csv_row(&csv, row, 3);
            }
            fsdem_csv_close(&csv);
            /* 5%: the line */
            vc_info(CASE, "dP_per_L_pack_vs_ergun_eps_pack_Pa_per_m value=%.6g ref=%.6g (%+.1f%%)", mean / L, ergun_pack,
                    100 * (mean / L / ergun_pack - 1));
            vc_info(CASE, "dP_per_L_pack_vs_ergun_eps_core_Pa_per_m value=%.6g ref=%.6g (%+.1f%%)", mean / L, ergun_core,
                    100 * (mean / L / ergun_core - 1));
        }
    }
    fsdem_mps_dem_destroy(cpl);
    fsdem_dem_destroy(dem);
    fsdem_mps_destroy(mps);
    return vc_exit_code();
}
