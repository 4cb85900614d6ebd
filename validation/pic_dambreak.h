/* validation/pic_dambreak.h - the Martin & Moyce (1952) dam break with the PIC/FLIP solver, shared
   by pic_dambreak_2d and pic_dambreak_3d: set-up, and front and column-height measurement on the
   solver's surface. The time series, the reference tables and the comparison with the experiments
   (db_compare_front, db_report_front) are in dambreak_protocol.h, shared with mps_dambreak_2d.
   Not part of fsdem.h. Include after fsdem.h and common.h. */
#ifndef FSDEM_VALIDATION_PIC_DAMBREAK_H
#define FSDEM_VALIDATION_PIC_DAMBREAK_H

#include "dambreak_protocol.h"

/* Front and column height from the solver's own surface: the rightmost fluid cell of the bottom row
   (of the middle slice in 3D) plus the interface fraction of the ghost-fluid method, and the
   topmost fluid cell of the first column likewise. */
static inline void db_measure(const fsdem_pic *s, double *front, double *hcol) {
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
static inline void db_run_opt(int dim, int n, double width, double t_end, const char *csv_name, int density_projection,
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

static inline void db_run(int dim, int n, double width, double t_end, const char *csv_name, db_series *out) {
    db_run_opt(dim, n, width, t_end, csv_name, 1, out);
}

#endif
