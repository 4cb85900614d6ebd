/* validation/swe_dambreak: the four exact 1D dam breaks of
   validation/data/swe_dambreak_ritter_stoker_worked_examples.csv (Ritter on a dry bed, Stoker on a
   wet bed, h_L = 1 m at t = 1 s, and the two SWASHES cases with h_L = 5 mm at t = 6 s), with
   MUSCL-Hancock, HLL, CFL 0.5 and the MC limiter (checked); the library's default minmod limiter is
   run beside it and reported (INFO).
   Usage: run [DATA_DIR] [--tier=default|full]   (validation/data by default; both tiers run the
   same; writes profile_<case>.csv and
   profile_<case>_minmod.csv into the working directory)
   See README.md next to this file for the physics, the reference, the metrics and the tolerances. */
#include "fsdem.h"
#include "common.h"

#define CASE "swe_dambreak"

typedef struct dambreak {
    char name[64];
    double hl, hr, g, t, x0, cl, cm, hm, um, s, xa, xb, xc;
} dambreak;

/* What one run measures. */
typedef struct result {
    long long steps;
    double dx, l1, hmin;
    double x5, x3;     /* Ritter: the 0.05 h_L and 1e-3 h_L contours (m) */
    double xs, hp;     /* Stoker: the shock (mid-level contour, m) and the plateau depth (m) */
    double hdam;       /* Ritter: depth at the dam (m) */
} result;

/* Exact depth and velocity from the reference parameters (validation/data/README.md, SWE formulas). */
static void exact(const dambreak *c, double x, double *h, double *u) {
    double xi = (x - c->x0) / c->t;
    if (xi <= -c->cl) {
        *h = c->hl;
        *u = 0;
    } else if (xi <= 2 * c->cl - 3 * c->cm) {
        *h = 4 / (9 * c->g) * (c->cl - xi / 2) * (c->cl - xi / 2);
        *u = 2.0 / 3.0 * (xi + c->cl);
    } else if (c->hr > 0 && xi <= c->s) {
        *h = c->hm;
        *u = c->um;
    } else {
        *h = c->hr;
        *u = 0;
    }
}

/* Exact position of the depth level `level` in the Ritter fan: h = (4/9g)(c_L - xi/2)^2 = level gives
   xi = 2 c_L - 3 sqrt(g level). */
static double ritter_level_position(const dambreak *c, double level) {
    return c->x0 + (2 * c->cl - 3 * sqrt(c->g * level)) * c->t;
}

/* Position of the last downstream crossing of the level `level` by the cell-centre profile, by linear
   interpolation between centres. */
static double contour(const fsdem_real *h, int n, double x_min, double dx, double level) {
    int i, last = -1;
    for (i = 0; i < n - 1; ++i)
        if (h[i] > level && h[i + 1] <= level) last = i;
    if (last < 0) return NAN;
    return x_min + (last + 0.5) * dx + dx * (h[last] - level) / (h[last] - h[last + 1]);
}

/* Cells: 1000 on [-5, 8] m for the h_L = 1 m cases; 2000 on SWASHES's [0, 10] m, so that the Ritter
   travel 2 c_L t = 2.66 m spans 531 cells, as the 6.26 m of case A span 482 (README.md, "Grids"). */
static int cells(const dambreak *c) { return strstr(c->name, "swashes") ? 2000 : 1000; }

/* One run to c->t with the given limiter and cell count; writes `csv` (x,h,u,h_exact,u_exact). The dry
   threshold is 1e-6 h_L (the library's default 1e-6 m for h_L = 1 m), so the SWASHES cases (h_L = 5 mm)
   are the h_L = 1 m problems scaled, not 5 um contours next to a 1 um threshold. */
static int simulate(const dambreak *c, int nx, fsdem_swe_limiter limiter, const char *csv, result *r) {
    fsdem_swe_desc d = fsdem_swe_desc_default(1);
    fsdem_swe *s = NULL;
    fsdem_real *h = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)nx);
    fsdem_real *u = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)nx);
    int swashes = strstr(c->name, "swashes") != NULL, i;
    double x_min = swashes ? 0 : -5, x_max = swashes ? 10 : 8, dx = (x_max - x_min) / nx, vol = 0;
    FILE *fp;
    memset(r, 0, sizeof *r);
    r->dx = dx;
    r->hmin = 1e300;
    d.nx = nx;
    d.x_min = x_min;
    d.x_max = x_max;
    d.gravity = fsdem_v3(0, 0, (fsdem_real)-c->g);
    d.limiter = limiter;
    d.dry_depth = (fsdem_real)(1e-6 * c->hl);
    d.boundary[FSDEM_SIDE_XMIN].type = FSDEM_SWE_BC_TRANSMISSIVE;
    d.boundary[FSDEM_SIDE_XMAX].type = FSDEM_SWE_BC_TRANSMISSIVE;
    for (i = 0; i < nx; ++i) h[i] = x_min + (i + 0.5) * dx < c->x0 ? c->hl : c->hr;
    d.depth = h;
    if (fsdem_swe_create(&d, &s) != FSDEM_OK || fsdem_swe_advance(s, c->t, &r->steps) != FSDEM_OK) {
        fprintf(stderr, "%s: simulation failed: %s\n", c->name, s ? fsdem_swe_last_error(s) : "create");
        free(h);
        free(u);
        return 1;
    }
    fsdem_swe_copy_field(s, FSDEM_SWE_FIELD_DEPTH, h);
    fsdem_swe_copy_field(s, FSDEM_SWE_FIELD_U, u);
    fp = csv ? fopen(csv, "w") : NULL;
    if (fp) fprintf(fp, "x,h,u,h_exact,u_exact\n");
    for (i = 0; i < nx; ++i) {
        double x = x_min + (i + 0.5) * dx, he, ue;
        exact(c, x, &he, &ue);
        r->l1 += fabs(h[i] - he);
        vol += he;
        if (h[i] < r->hmin) r->hmin = h[i];
        if (fp) fprintf(fp, "%.8g,%.10g,%.10g,%.10g,%.10g\n", x, (double)h[i], (double)u[i], he, ue);
    }
    if (fp) fclose(fp);
    r->l1 /= vol;
    if (c->hr > 0) {
        r->xs = contour(h, nx, x_min, dx, 0.5 * (c->hm + c->hr));
        r->hp = h[(int)((0.5 * (c->xb + c->xc) - x_min) / dx)];
    } else {
        int i0 = (int)((c->x0 - x_min) / dx);
        r->x5 = contour(h, nx, x_min, dx, 0.05 * c->hl);
        r->x3 = contour(h, nx, x_min, dx, 1e-3 * c->hl);
        r->hdam = 0.5 * (h[i0 - 1] + h[i0]);
    }
    fsdem_swe_destroy(s);
    free(h);
    free(u);
    return 0;
}

/* Tolerance of the relative L1 error: between the second-order values (MC and minmod) and the
   first-order value on the same grid, so a loss of second order fails (README.md, "Tolerances"). */
static double l1_tolerance(const char *name) {
    if (name[0] == 'A' || name[0] == 'B') return 3e-3;
    if (name[0] == 'C') return 1e-3;
    return 7.5e-4;
}

static int run_case(const dambreak *c) {
    result r, rm;
    char path[256], metric[128];
    int nx = cells(c);
    double travel = 2 * c->cl * c->t; /* Ritter: from the dam to the wet front x0 + 2 c_L t */
    snprintf(path, sizeof path, "profile_%s.csv", c->name);
    if (simulate(c, nx, FSDEM_SWE_LIMITER_MC, path, &r)) return 1;
    snprintf(path, sizeof path, "profile_%s_minmod.csv", c->name);
    if (simulate(c, nx, FSDEM_SWE_LIMITER_MINMOD, path, &rm)) return 1;
    vc_info(CASE, "%s: %d cells of %.4g m, MC limiter, %lld steps to t = %g s (minmod: %lld steps)", c->name, nx, r.dx,
            r.steps, c->t, rm.steps);

    /* 1. relative L1 error of h over the domain (see README for the tolerances) */
    snprintf(metric, sizeof metric, "%s_L1_h_relative", c->name);
    vc_check(CASE, metric, r.l1, 0, l1_tolerance(c->name));
    /* 2. no negative depth anywhere */
    snprintf(metric, sizeof metric, "%s_min_depth_m", c->name);
    vc_check(CASE, metric, r.hmin >= 0 ? 0 : r.hmin, 0, 0);
    if (c->hr > 0) {
        /* 3. Stoker: shock at the mid level between h_m and h_R, within 2 cells of x_C */
        snprintf(metric, sizeof metric, "%s_shock_position_m", c->name);
        vc_check(CASE, metric, r.xs, c->xc, 2 * r.dx);
        /* 4. plateau depth h_m in the middle of the plateau, within 1% */
        snprintf(metric, sizeof metric, "%s_plateau_depth_m", c->name);
        vc_check(CASE, metric, r.hp, c->hm, 0.01 * c->hm);
        vc_info(CASE, "%s with minmod (information): L1 %.3g, shock %+.2f cells, plateau %.3g relative", c->name, rm.l1,
                (rm.xs - c->xc) / rm.dx, rm.hp / c->hm - 1);
    } else {
        double x3e = ritter_level_position(c, 1e-3 * c->hl), xw = c->x0 + travel;
        /* 3. the front, as the h = 1e-3 h_L contour, against the exact solution's 1e-3 h_L contour,
              within 2% of the travel 2 c_L t (issue 9, amended line) */
        snprintf(metric, sizeof metric, "%s_front_1e-3_contour_error_of_travel", c->name);
        vc_check(CASE, metric, (r.x3 - x3e) / travel, 0, 0.02);
        /* 4. the 0.05 h_L contour, within 2 cells of its exact position */
        snprintf(metric, sizeof metric, "%s_front_5pct_position_m", c->name);
        vc_check(CASE, metric, r.x5, ritter_level_position(c, 0.05 * c->hl), 2 * r.dx);
        /* 5. depth at the dam 4/9 h_L (cell-centre average of the two cells around x0), within 1% */
        snprintf(metric, sizeof metric, "%s_depth_at_dam_m", c->name);
        vc_check(CASE, metric, r.hdam, 4.0 / 9.0 * c->hl, 0.01 * 4.0 / 9.0 * c->hl);
        vc_info(CASE, "%s: h = 1e-3 h_L contour at %.4f m, exact %.4f m (%+.1f cells, %+.2f%% of the travel %.4f m)",
                c->name, r.x3, x3e, (r.x3 - x3e) / r.dx, 100 * (r.x3 - x3e) / travel, travel);
        vc_info(CASE, "%s: former literal figure, the 1e-3 h_L contour against the wet front x0 + 2 c_L t = %.4f m "
                      "(information; bound 2%%, the exact solution's own contour lies %.2f%% of the travel behind it): %+.2f%%",
                c->name, xw, 100 * (xw - x3e) / travel, 100 * (r.x3 - xw) / travel);
        vc_info(CASE, "%s with minmod (information): L1 %.3g; 1e-3 h_L contour %+.2f%% of the travel from the exact one "
                      "(bound 2%%: %s); 0.05 h_L contour %+.2f cells; depth at the dam %.3g relative",
                c->name, rm.l1, 100 * (rm.x3 - x3e) / travel, fabs(rm.x3 - x3e) <= 0.02 * travel ? "met" : "not met",
                (rm.x5 - ritter_level_position(c, 0.05 * c->hl)) / rm.dx, rm.hdam / (4.0 / 9.0 * c->hl) - 1);
        if (nx != 1000) {
            result r1, rm1;
            if (simulate(c, 1000, FSDEM_SWE_LIMITER_MC, NULL, &r1) == 0 &&
                simulate(c, 1000, FSDEM_SWE_LIMITER_MINMOD, NULL, &rm1) == 0)
                vc_info(CASE, "%s on 1000 cells (information: %d cells across the travel): 1e-3 h_L contour %+.2f%% "
                              "(MC), %+.2f%% (minmod) of the travel from the exact one",
                        c->name, (int)(travel / r1.dx), 100 * (r1.x3 - x3e) / travel, 100 * (rm1.x3 - x3e) / travel);
        }
    }
    return 0;
}

int main(int argc, char **argv) {
    vc_table t;
    char path[512];
    int r, bad = 0;
    vc_begin(CASE, argc, argv, NULL);
    vc_tier("1000 cells (Ritter, Stoker), 2000 (SWASHES)");
    if (vc_table_load(&t, vc_path(path, sizeof path, vc_data_dir(),
                                  "swe_dambreak_ritter_stoker_worked_examples.csv")) != 0) {
        vc_check(CASE, "reference_loaded", 0, 1, 0);
        return vc_exit_code();
    }
    for (r = 0; r < t.rows; ++r) {
        dambreak c;
        memset(&c, 0, sizeof c);
        snprintf(c.name, sizeof c.name, "%s", vc_table_str(&t, r, vc_table_col(&t, "case")));
        c.hl = vc_table_num(&t, r, vc_table_col(&t, "h_L_m"));
        c.hr = vc_table_num(&t, r, vc_table_col(&t, "h_R_m"));
        c.g = vc_table_num(&t, r, vc_table_col(&t, "g"));
        c.t = vc_table_num(&t, r, vc_table_col(&t, "t_s"));
        c.x0 = vc_table_num(&t, r, vc_table_col(&t, "x0_m"));
        c.cl = vc_table_num(&t, r, vc_table_col(&t, "c_L"));
        c.cm = vc_table_num(&t, r, vc_table_col(&t, "c_m"));
        c.hm = vc_table_num(&t, r, vc_table_col(&t, "h_m"));
        c.um = vc_table_num(&t, r, vc_table_col(&t, "u_m"));
        c.s = vc_table_num(&t, r, vc_table_col(&t, "s_shock"));
        c.xa = vc_table_num(&t, r, vc_table_col(&t, "x_A"));
        c.xb = vc_table_num(&t, r, vc_table_col(&t, "x_B"));
        c.xc = vc_table_num(&t, r, vc_table_col(&t, "x_C"));
        bad |= run_case(&c);
    }
    vc_table_free(&t);
    return bad ? 1 : vc_exit_code();
}
