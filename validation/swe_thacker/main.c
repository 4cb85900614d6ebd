/* validation/swe_thacker: Thacker's (1981) planar surface in a paraboloid, 2D, frictionless. A disc of
   water with a tilted plane surface rotates around the bowl without changing shape, so its shoreline
   moves over dry ground all the time, and the exact solution is known at every point and time.
   Bed z(r) = -h0 (1 - r^2/a^2), r from the bowl centre (L/2, L/2); with X, Y measured from the centre
   and omega = sqrt(2 g h0)/a:
       h = (h0/a^2) [a^2 - (X - eta cos wt)^2 - (Y - eta sin wt)^2]  where positive, else 0,
       u = -eta omega sin(wt),  v = eta omega cos(wt)  (uniform in the wet disc).
   Parameters of the SWASHES 2D planar case: a = 1 m, h0 = 0.1 m, eta = 0.5 m, L = 4 m.
   Runs the default scheme on 100^2 and 200^2 cells for three periods; checks the L1 error of h after
   one and three periods on 200^2, and that it decreases under refinement.
   Usage: run [DATA_DIR] [--tier=default|full]   (the reference is analytic; both tiers run the same;
   writes thacker.csv and profile_T*.csv)
   See README.md next to this file. */
#include "fsdem.h"
#include "common.h"

#define CASE "swe_thacker"
#define PI 3.14159265358979323846

static const double A = 1.0, H0 = 0.1, ETA = 0.5, L = 4.0, G = 9.81;

static double omega(void) { return sqrt(2 * G * H0) / A; }

static double exact_h(double x, double y, double t) {
    double X = x - L / 2, Y = y - L / 2, w = omega() * t;
    double dx = X - ETA * cos(w), dy = Y - ETA * sin(w);
    double h = H0 / (A * A) * (A * A - dx * dx - dy * dy);
    return h > 0 ? h : 0;
}

static void initial(void *user, fsdem_real x, fsdem_real y, fsdem_swe_cell *c) {
    double X = x - L / 2, Y = y - L / 2;
    (void)user;
    c->bed = -H0 * (1 - (X * X + Y * Y) / (A * A));
    c->depth = exact_h(x, y, 0);
    c->u = 0;
    c->v = c->depth > 0 ? ETA * omega() : 0;
}

typedef struct result {
    double l1[2];      /* m^3, sum |h - h_exact| dA after one and three periods */
    double rel[2];     /* L1 / exact volume */
    double cx_err[2];  /* m, centre-of-mass x error */
    double vol_change; /* relative, after three periods */
    double hmin;
    long long steps;
} result;

/* Runs n x n cells for three periods; writes the time series and profiles when `out` is set. */
static int run(int n, int out, result *res) {
    fsdem_swe_desc d = fsdem_swe_desc_default(2);
    fsdem_swe *s = NULL;
    fsdem_real *h = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)(n * n));
    double period = 2 * PI / omega(), t_out = period / 40, v0, dxy = L / n;
    int k, frame, nframes = 120, period_frames[2] = {40, 120}, which = 0;
    fsdem_csv csv;
    d.nx = d.ny = n;
    d.x_min = d.y_min = 0;
    d.x_max = d.y_max = L;
    d.gravity = fsdem_v3(0, 0, (fsdem_real)-G);
    if (fsdem_swe_create(&d, &s) != FSDEM_OK || fsdem_swe_set_cells(s, initial, NULL) != FSDEM_OK) return 1;
    v0 = fsdem_swe_volume(s);
    res->hmin = 1e300;
    res->steps = 0;
    if (out) fsdem_csv_open(&csv, "thacker.csv", "t,l1_h,l1_h_relative,volume,x_mass,y_mass,x_mass_exact,y_mass_exact");
    for (frame = 0; frame <= nframes; ++frame) {
        double l1 = 0, vol_e = 0, mx = 0, my = 0, m = 0, t, w;
        long long steps = 0;
        if (frame > 0) {
            if (fsdem_swe_advance(s, t_out, &steps) != FSDEM_OK) {
                fprintf(stderr, "step failed: %s\n", fsdem_swe_last_error(s));
                return 1;
            }
            res->steps += steps;
        }
        t = fsdem_swe_time(s);
        w = omega() * t;
        fsdem_swe_copy_field(s, FSDEM_SWE_FIELD_DEPTH, h);
        for (k = 0; k < n * n; ++k) {
            double x = (k % n + 0.5) * dxy, y = (k / n + 0.5) * dxy, he = exact_h(x, y, t);
            l1 += fabs(h[k] - he);
            vol_e += he;
            mx += h[k] * x;
            my += h[k] * y;
            m += h[k];
            if (h[k] < res->hmin) res->hmin = h[k];
        }
        if (out) {
            /* exact centre of mass: the depth is a paraboloid of revolution over the wet disc, so
               the centre of mass is the disc centre (L/2 + eta cos wt, L/2 + eta sin wt) */
            fsdem_real row[8];
            row[0] = (fsdem_real)t;
            row[1] = (fsdem_real)(l1 * dxy * dxy);
            row[2] = (fsdem_real)(l1 / vol_e);
            row[3] = (fsdem_real)(m * dxy * dxy);
            row[4] = (fsdem_real)(mx / m);
            row[5] = (fsdem_real)(my / m);
            row[6] = (fsdem_real)(L / 2 + ETA * cos(w));
            row[7] = (fsdem_real)(L / 2 + ETA * sin(w));
            fsdem_csv_row(&csv, row, 8);
        }
        if (which < 2 && frame == period_frames[which]) {
            res->l1[which] = l1 * dxy * dxy;
            res->rel[which] = l1 / vol_e;
            res->cx_err[which] = mx / m - (L / 2 + ETA * cos(w));
            if (out) {
                char path[64];
                FILE *fp;
                snprintf(path, sizeof path, "profile_T%d.csv", which == 0 ? 1 : 3);
                fp = fopen(path, "w");
                if (fp) {
                    int i, j = n / 2;
                    fprintf(fp, "x,h,h_exact,eta,eta_exact,bed\n");
                    for (i = 0; i < n; ++i) {
                        double x = (i + 0.5) * dxy, y = (j + 0.5) * dxy, X = x - L / 2, Y = y - L / 2;
                        double bed = -H0 * (1 - (X * X + Y * Y) / (A * A)), he = exact_h(x, y, t);
                        fprintf(fp, "%.6g,%.10g,%.10g,%.10g,%.10g,%.10g\n", x, (double)h[i + n * j], he,
                                bed + (double)h[i + n * j], bed + he, bed);
                    }
                    fclose(fp);
                }
            }
            which++;
        }
    }
    if (out) fsdem_csv_close(&csv);
    res->vol_change = (fsdem_swe_volume(s) - v0) / v0;
    fsdem_swe_destroy(s);
    free(h);
    return 0;
}

int main(int argc, char **argv) {
    result coarse, fine;
    double period = 2 * PI / omega();
    vc_begin(CASE, argc, argv, NULL);
    vc_tier("100^2 and 200^2 cells, 3 periods");
    if (run(100, 0, &coarse) != 0 || run(200, 1, &fine) != 0) return 1;
    vc_info(CASE, "period T = %.5f s; 200^2 cells: %lld steps for 3 T; 100^2: %lld steps", period, fine.steps,
            coarse.steps);
    vc_info(CASE, "L1(h) relative to the volume: 100^2: %.4g (T), %.4g (3T); 200^2: %.4g (T), %.4g (3T)",
            coarse.rel[0], coarse.rel[1], fine.rel[0], fine.rel[1]);
    vc_info(CASE, "observed order 100^2 -> 200^2: %.2f (T), %.2f (3T)", log2(coarse.l1[0] / fine.l1[0]),
            log2(coarse.l1[1] / fine.l1[1]));
    vc_info(CASE, "centre-of-mass x error on 200^2: %.3g m (T), %.3g m (3T)", fine.cx_err[0], fine.cx_err[1]);
    vc_info(CASE, "L1(h) on 200^2: %.4g m^3 (T), %.4g m^3 (3T) of a %.4f m^3 volume", fine.l1[0], fine.l1[1],
            PI * H0 * A * A / 2);
    /* tolerances: README.md ("Metrics and tolerances") */
    vc_check(CASE, "L1_h_relative_after_1_period", fine.rel[0], 0, 0.015);
    vc_check(CASE, "L1_h_relative_after_3_periods", fine.rel[1], 0, 0.035);
    vc_check(CASE, "observed_order_100_to_200_after_3_periods", log2(coarse.l1[1] / fine.l1[1]), 2.0, 0.8);
    vc_check(CASE, "relative_volume_change", fine.vol_change, 0, 1e-12);
    vc_check(CASE, "min_depth_m", fine.hmin >= 0 ? 0 : fine.hmin, 0, 0);
    return vc_exit_code();
}
