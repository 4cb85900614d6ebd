/* validation/pic_dambreak.h - the Martin & Moyce (1952) dam break shared by pic_dambreak_2d and
   pic_dambreak_3d: set-up, front and column-height measurement, comparison with the tables.
   Not part of fsdem.h. Include after fsdem.h and common.h. */
#ifndef FSDEM_VALIDATION_PIC_DAMBREAK_H
#define FSDEM_VALIDATION_PIC_DAMBREAK_H

#define DB_A 0.05715     /* m, column width a (2.25 in) */
#define DB_G 9.81        /* m/s^2 */
#define DB_LENGTH 8.0    /* tank length in a */
#define DB_HEIGHT 3.0    /* tank height in a */
#define DB_MAX_SAMPLES 20000

/* Time series of one run: t (s), front x (m, from the wall behind the column), column height (m). */
typedef struct db_series {
    int n;
    double t[DB_MAX_SAMPLES], x[DB_MAX_SAMPLES], h[DB_MAX_SAMPLES];
    double t_wall;       /* s, first time the front reached the far wall (-1: never) */
    double volume_drift; /* max |V(t)/V(0) - 1| */
    int steps, particles;
    double cpu, cpu_pressure;
    int failed;
} db_series;

/* Front and column height from the solver's own surface: the rightmost fluid cell of the bottom row
   (of the middle slice in 3D) plus the interface fraction of the ghost-fluid method, and the
   topmost fluid cell of the first column likewise. */
static void db_measure(const fsdem_pic *s, double *front, double *hcol) {
    fsdem_pic_fields g = fsdem_pic_get_fields(s);
    int up = g.dim - 1, i, j, nx = g.n[0], mid = g.dim == 3 ? g.n[1] / 2 : 0;
    int sx = 1, sup = up == 1 ? nx : nx * g.n[1], base = g.dim == 3 ? mid * nx : 0, nup = g.n[up];
    double dx = g.cell_size;
    *front = 0;
    *hcol = 0;
    for (i = nx - 1; i >= 0; --i) {
        int c = base + i * sx;
        if (g.cell[c] == FSDEM_STENCIL_CELL_FLUID) {
            double th = 0.5;
            if (i + 1 < nx) {
                double p0 = g.phi[c], p1 = g.phi[c + sx];
                th = p0 < p1 ? p0 / (p0 - p1) : 1;
            }
            *front = (i + 0.5 + th) * dx;
            break;
        }
    }
    for (j = nup - 1; j >= 0; --j) {
        int c = base + j * sup;
        if (g.cell[c] == FSDEM_STENCIL_CELL_FLUID) {
            double th = 0.5;
            if (j + 1 < nup) {
                double p0 = g.phi[c], p1 = g.phi[c + sup];
                th = p0 < p1 ? p0 / (p0 - p1) : 1;
            }
            *hcol = (j + 0.5 + th) * dx;
            break;
        }
    }
}

/* Runs the column collapse: n cells across a, width w (m; 3D only), until t_end, with or without
   the density projection. Writes `csv_name` (t,x_front,h_column) when not NULL. */
static void db_run_opt(int dim, int n, double width, double t_end, const char *csv_name, int density_projection,
                       db_series *out) {
    fsdem_pic_desc d = fsdem_pic_desc_default(dim);
    fsdem_pic *s;
    fsdem_csv csv;
    fsdem_pic_stats st;
    double dx = DB_A / n, v0, L = DB_LENGTH * DB_A, H = DB_HEIGHT * DB_A, t;
    memset(out, 0, sizeof *out);
    out->t_wall = -1;
    d.cell_size = (fsdem_real)dx;
    d.density_projection = density_projection;
    d.domain_max = dim == 2 ? fsdem_v3((fsdem_real)L, (fsdem_real)H, 0) : fsdem_v3((fsdem_real)L, (fsdem_real)width, (fsdem_real)H);
    if (fsdem_pic_create(&d, &s) != FSDEM_OK) {
        out->failed = 1;
        return;
    }
    if (fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0),
                           dim == 2 ? fsdem_v3((fsdem_real)DB_A, (fsdem_real)(2 * DB_A), 0)
                                    : fsdem_v3((fsdem_real)DB_A, (fsdem_real)(2 * width), (fsdem_real)(2 * DB_A)),
                           fsdem_v3(0, 0, 0), NULL) != FSDEM_OK) {
        out->failed = 1;
        fsdem_pic_destroy(s);
        return;
    }
    v0 = (double)fsdem_pic_get_stats(s).fluid_volume;
    if (csv_name) fsdem_csv_open(&csv, csv_name, "t,x_front,h_column");
    for (;;) {
        double fr, hc;
        fsdem_real row[3];
        db_measure(s, &fr, &hc);
        t = (double)fsdem_pic_time(s);
        st = fsdem_pic_get_stats(s);
        if (fabs(st.fluid_volume / v0 - 1) > out->volume_drift) out->volume_drift = fabs(st.fluid_volume / v0 - 1);
        if (out->n < DB_MAX_SAMPLES) {
            out->t[out->n] = t;
            out->x[out->n] = fr;
            out->h[out->n] = hc;
            out->n++;
        }
        if (out->t_wall < 0 && fr >= L - 0.5 * dx) out->t_wall = t;
        row[0] = (fsdem_real)t;
        row[1] = (fsdem_real)fr;
        row[2] = (fsdem_real)hc;
        if (csv_name) fsdem_csv_row(&csv, row, 3);
        if (t >= t_end - 1e-12) break;
        if (fsdem_pic_step(s) != FSDEM_OK) {
            fprintf(stderr, "dam break %dD n=%d: %s\n", dim, n, fsdem_pic_last_error(s));
            out->failed = 1;
            break;
        }
    }
    if (csv_name) fsdem_csv_close(&csv);
    st = fsdem_pic_get_stats(s);
    out->steps = (int)st.steps;
    out->particles = st.particles;
    out->cpu = st.seconds_total;
    out->cpu_pressure = st.seconds_pressure;
    fsdem_pic_destroy(s);
}

static void db_run(int dim, int n, double width, double t_end, const char *csv_name, db_series *out) {
    db_run_opt(dim, n, width, t_end, csv_name, 1, out);
}

/* Linear interpolation of a series column at time t (clamped). */
static double db_at(const db_series *s, const double *col, double t) {
    int lo = 0, hi = s->n - 1;
    if (s->n == 0) return NAN;
    if (t <= s->t[0]) return col[0];
    if (t >= s->t[hi]) return col[hi];
    while (hi - lo > 1) {
        int m = (lo + hi) / 2;
        if (s->t[m] <= t) lo = m;
        else hi = m;
    }
    return col[lo] + (col[hi] - col[lo]) * (t - s->t[lo]) / (s->t[hi] - s->t[lo]);
}

/* Reference tables: front Z(T), T = t sqrt(2g/a); residual height eta(tau), tau = t sqrt(g/a). */
typedef struct db_ref {
    int nz, ne;
    double T[64], Z[64], tau[64], eta[64];
} db_ref;

static int db_load_ref(const char *dir, db_ref *r) {
    vc_table t;
    char path[512];
    int i, c0, c1;
    memset(r, 0, sizeof *r);
    if (vc_table_load(&t, vc_path(path, sizeof path, dir, "martin_moyce_1952_front_n2_2_table_ocellaris.csv")) != 0) return -1;
    c0 = vc_table_col(&t, "T");
    c1 = vc_table_col(&t, "Z");
    for (i = 0; i < t.rows && i < 64 && c0 >= 0 && c1 >= 0; ++i) {
        r->T[i] = vc_table_num(&t, i, c0);
        r->Z[i] = vc_table_num(&t, i, c1);
        r->nz++;
    }
    vc_table_free(&t);
    if (vc_table_load(&t, vc_path(path, sizeof path, dir, "martin_moyce_1952_residual_height_n2_2_table_ocellaris.csv")) != 0)
        return -1;
    c0 = vc_table_col(&t, "tau");
    c1 = vc_table_col(&t, "eta");
    for (i = 0; i < t.rows && i < 64 && c0 >= 0 && c1 >= 0; ++i) {
        r->tau[i] = vc_table_num(&t, i, c0);
        r->eta[i] = vc_table_num(&t, i, c1);
        r->ne++;
    }
    vc_table_free(&t);
    return r->nz > 0 && r->ne > 0 ? 0 : -1;
}

/* Writes the front table as ref_front.csv (t in s, x_front in m) for the plots. */
static void db_write_ref_front(const db_ref *r) {
    fsdem_csv rf;
    int i;
    fsdem_csv_open(&rf, "ref_front.csv", "t,x_front");
    for (i = 0; i < r->nz; ++i) {
        fsdem_real row[2];
        row[0] = (fsdem_real)(r->T[i] * sqrt(DB_A / (2 * DB_G)));
        row[1] = (fsdem_real)(r->Z[i] * DB_A);
        fsdem_csv_row(&rf, row, 2);
    }
    fsdem_csv_close(&rf);
}

/* RMS of Z_sim(T + shift) - Z over the front table (shift in units of T). */
static double db_rms_front(const db_series *s, const db_ref *r, double shift) {
    double sum = 0, k = sqrt(DB_A / (2 * DB_G));
    int i;
    for (i = 0; i < r->nz; ++i) {
        double z = db_at(s, s->x, (r->T[i] + shift) * k) / DB_A - r->Z[i];
        sum += z * z;
    }
    return sqrt(sum / r->nz);
}

/* RMS of eta_sim(tau) - eta over the residual-height table entries up to the run's end. */
static double db_rms_height(const db_series *s, const db_ref *r) {
    double sum = 0, k = sqrt(DB_A / DB_G);
    int i, n = 0;
    for (i = 0; i < r->ne; ++i) {
        double e;
        if (s->n == 0 || r->tau[i] * k > s->t[s->n - 1] + 1e-9) continue;
        e = db_at(s, s->h, r->tau[i] * k) / (2 * DB_A) - r->eta[i];
        sum += e * e;
        n++;
    }
    return n ? sqrt(sum / n) : NAN;
}

/* The time shift (in T) that minimises the front RMS, searched on [-1, 1] by steps of 0.005. */
static double db_best_shift(const db_series *s, const db_ref *r, double *rms) {
    double best = 0, b = 1e30, sh;
    for (sh = -1; sh <= 1 + 1e-9; sh += 0.005) {
        double e = db_rms_front(s, r, sh);
        if (e < b) {
            b = e;
            best = sh;
        }
    }
    *rms = b;
    return best;
}

#endif
