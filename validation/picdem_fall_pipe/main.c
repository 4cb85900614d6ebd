/* Fall-pipe solid dumping (seed 000 section 3.3): six layers of aluminium cylinders (6 and 5
   alternately) piled in a funnel just above the still water level fall through a vertical pipe to
   the bottom of a tank full of water; a continuous and a perforated pipe. Resolved PIC-DEM
   (fsdem_pic_dem), 2D. The geometry of the seed's Fig. 11 is not given in its text: README.md states
   the one chosen here.
   Usage: run [DATA_DIR] [--tier=default|full] [--dx M] [--t-max S] [--pipe continuous|perforated] [--dry]
     DATA_DIR is ignored (no reference data exist for this case);
     --tier=full  the seed's grid, dx = 0.05 cm, with 0.1 cm holes (--seed is the same; the default
              tier: dx = 0.15 cm, holes of 2 cells = 0.3 cm, README.md "Tiers");
     --dx M   another grid (m; holes of max(0.1 cm, 2 dx));
     --t-max  end of a run when cylinders are still in the pipe (default 4 s);
     --pipe   run one pipe only (the comparison check is then skipped);
     --dry    the DEM alone with the same walls, no water (dump times for reference; the checks
              on water and the comparison are skipped).
   Writes cylinders.csv, levels.csv and cylinders_<pipe>_<t>.csv snapshots into the working
   directory. */
#include "fsdem.h"
#include "common.h"

#include <time.h>

#define CASE "picdem_fall_pipe"

/* cylinders and DEM: seed 000 section 3.1 and Table 1 (as validation/dem_cylinder_collapse) */
static const double radius = 0.005;    /* m, d = 1 cm */
static const double length = 0.099;    /* m, cylinder length (disc_length) */
static const double density = 2700;    /* kg/m^3, aluminium */
static const double theta = 0.01, alpha = 0.4, psi = 0.3, mu = 0.3, gamma_dt = 150;
static const double dx_table1 = 0.0005; /* m, the dx of Eq. 10 with which Table 1 was tuned */
static const double beta = 0.5;        /* Eq. 20, seed 000 section 3.2 */

/* water: seed 000 section 3.2 */
static const double rho_w = 1000, nu_w = 1e-6, depth = 0.12;

/* geometry (m), chosen (README.md): tank, pipe, funnel (hopper) */
static const double tank_w = 0.28, tank_h = 0.26;
static const double xc = 0.14;          /* pipe axis */
static const double pipe_w = 0.030;     /* inner width (3 cm: narrower pipes jam, README.md) */
static const double wall_t = 0.003;     /* wall thickness of pipe and funnel */
static const double pipe_bottom = 0.05; /* above the floor */
static const double pipe_top = 0.13;    /* the funnel's neck, 1 cm above the still water */
static const double funnel_w0 = 0.08;   /* inner width of the funnel's vertical part (dx <= 1 mm) */
static const double funnel_angle = 45;  /* degrees from the horizontal of the funnel's slope */
static double funnel_w, funnel_slope_top; /* the slope from the neck ends at funnel_slope_top */
static const double funnel_top = 0.24;
static const double hole_first = 0.06, hole_pitch = 0.02; /* hole centres 6, 8, 10, 12 cm */
static const int hole_count = 4;

#define DEG (3.14159265358979323846 / 180)

enum { N_CYL = 33, MAX_PIECES = 16, MAX_COLUMNS = 256 };

typedef struct options {
    double dx, hole_w, t_max;
    int pipes; /* bit 0 continuous, bit 1 perforated */
    int dry;   /* no water: the DEM alone */
} options;

typedef struct result {
    int completed, ran;
    double t_first_out, t_dump, t_end, wall_seconds;
    double level0_in, level_min_in, t_level_min_in, level_rise_after_min, t_level_max_after;
    double level0_out, level_max_out, noise;
    double volume_drift, fluid_drift, max_overlap;
    int particles0, particles_min, particles_max;
    int outside, reentered;
    long long steps;
} result;

/* The pipe's wall pieces and the funnel, the same geometry for the PIC (obstacles) and the DEM
   (walls): boxes (the pipe walls, between the holes, and the funnel's left side, the left pipe wall
   continued straight up) and one polygon (the funnel's right side: a slope from the neck up to a
   vertical part). */
typedef struct geometry {
    int boxes;
    fsdem_vec3 lo[MAX_PIECES], hi[MAX_PIECES];
    fsdem_vec3 funnel[6];
} geometry;

static void build_geometry(geometry *g, int perforated, double hole_w) {
    const double xin[2] = {xc - pipe_w / 2 - wall_t, xc + pipe_w / 2}; /* left edge of each wall */
    /* the slope: from the neck (a, pipe_top) to (b, funnel_slope_top), wall_t thick perpendicular to
       it (tf horizontally) */
    const double a = xc + pipe_w / 2, b = xc - pipe_w / 2 + funnel_w, t = wall_t;
    const double tn = tan(funnel_angle * DEG), tf = t / sin(funnel_angle * DEG);
    int side, h;
    g->boxes = 0;
    for (side = 0; side < 2; ++side) {
        double y = pipe_bottom;
        if (perforated)
            for (h = 0; h < hole_count; ++h) {
                double yc = hole_first + h * hole_pitch;
                g->lo[g->boxes] = fsdem_v3(xin[side], y, 0);
                g->hi[g->boxes] = fsdem_v3(xin[side] + wall_t, yc - hole_w / 2, 0);
                g->boxes++;
                y = yc + hole_w / 2;
            }
        g->lo[g->boxes] = fsdem_v3(xin[side], y, 0);
        g->hi[g->boxes] = fsdem_v3(xin[side] + wall_t, pipe_top, 0);
        g->boxes++;
    }
    g->lo[g->boxes] = fsdem_v3(xin[0], pipe_top, 0);
    g->hi[g->boxes] = fsdem_v3(xin[0] + wall_t, funnel_top, 0);
    g->boxes++;
    g->funnel[0] = fsdem_v3(a, pipe_top, 0);
    g->funnel[1] = fsdem_v3(b, funnel_slope_top, 0);
    g->funnel[2] = fsdem_v3(b, funnel_top, 0);
    g->funnel[3] = fsdem_v3(b + t, funnel_top, 0);
    g->funnel[4] = fsdem_v3(b + t, pipe_top + (b + t - a - tf) * tn, 0);
    g->funnel[5] = fsdem_v3(a + tf, pipe_top, 0);
}

/* Distance from (px, py) to the segment (ax, ay)-(bx, by). */
static double segment_distance(double px, double py, double ax, double ay, double bx, double by) {
    const double ux = bx - ax, uy = by - ay;
    double f = ((px - ax) * ux + (py - ay) * uy) / (ux * ux + uy * uy);
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    return hypot(px - ax - f * ux, py - ay - f * uy);
}

/* Centre of the bottom layer's left cylinder: the gap and half a millimetre from the funnel's left
   side, as low as the right one clears the slope and the vertical part of its right side by as much
   (y < 0: does not fit; main makes the funnel wide enough). */
static fsdem_vec3 pile_origin(double s, double gap) {
    const double need = radius + gap + 0.0005, x0 = xc - pipe_w / 2 + need, xr = x0 + 5 * s;
    const double a = xc + pipe_w / 2, b = xc - pipe_w / 2 + funnel_w;
    double y;
    for (y = pipe_top; y < funnel_top; y += 1e-4)
        if ((xr - a) * tan(funnel_angle * DEG) < y - pipe_top && /* above the slope, inside */
            segment_distance(xr, y, a, pipe_top, b, funnel_slope_top) >= need &&
            segment_distance(xr, y, b, funnel_slope_top, b, funnel_top) >= need)
            return fsdem_v3(x0, y, 0);
    return fsdem_v3(x0, -1, 0);
}

/* Errors and warnings of the solvers go to stderr. */
static void log_stderr(void *user, fsdem_log_level level, const char *message) {
    (void)level;
    fprintf(stderr, "%s (%s): %s\n", CASE, (const char *)user, message);
}

static int compare_real(const void *a, const void *b) {
    const fsdem_real x = *(const fsdem_real *)a, y = *(const fsdem_real *)b;
    return x < y ? -1 : x > y;
}

/* Levels (0 without water): lv[0] inside the pipe, the median of the level gauges of its cell
   columns (gauge[3 ..], n_in of them: a single column reads the top of a cylinder, a splash or an
   air pocket behind a cylinder when one passes, most columns do not), lv[1] and lv[2] outside
   (gauge[1], gauge[2]), lv[3] the gauge on the pipe's axis (gauge[0]). */
static void levels(const fsdem_pic *pic, const int *gauge, int n_in, fsdem_real *lv) {
    fsdem_real col[MAX_COLUMNS];
    int k;
    for (k = 0; k < 4; ++k) lv[k] = 0;
    if (!pic) return;
    for (k = 0; k < 3; ++k) fsdem_pic_gauge(pic, gauge[k], &lv[k == 0 ? 3 : k]);
    for (k = 0; k < n_in; ++k) fsdem_pic_gauge(pic, gauge[3 + k], &col[k]);
    qsort(col, (size_t)n_in, sizeof col[0], compare_real);
    lv[0] = n_in % 2 ? col[n_in / 2] : 0.5 * (col[n_in / 2 - 1] + col[n_in / 2]);
}

static double level_outside(const fsdem_real *lv) { return 0.5 * (lv[1] + lv[2]); }

static int run(const options *o, int perforated, result *r, FILE *cyl_csv, FILE *lev_csv) {
    const char *tag = perforated ? "perforated" : "continuous";
    const double dx = o->dx, gap = 2 * dx, s = 2 * radius + gap;
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_dem_material al = fsdem_dem_material_default();
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_pic_dem_desc cd = fsdem_pic_dem_desc_default();
    fsdem_dem *dem = NULL;
    fsdem_pic *pic = NULL;
    fsdem_pic_dem *cp = NULL;
    geometry g;
    int mat, k, layer, gauge[3 + MAX_COLUMNS], n_in = 0, failed = 0, next_snap = 0;
    double vol0, fvol0, next_row = 0, t, t_quiet = 0.0;
    fsdem_vec3 p0;
    double quiet_min = 1e30, quiet_max = -1e30;
    clock_t c0 = clock();
    fsdem_real lv[4];
    static const double snap[] = {0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.5, 2.0, 3.0, 4.0};

    memset(r, 0, sizeof *r);
    r->ran = 1;
    r->t_first_out = r->t_dump = -1;
    build_geometry(&g, perforated, o->hole_w);

    /* DEM */
    dd.domain_min = fsdem_v3(-0.05, -0.05, -1);
    dd.domain_max = fsdem_v3(tank_w + 0.05, tank_h + 0.2, 1);
    dd.law = FSDEM_DEM_LAW_LINEAR;
    dd.contact_offset = gap; /* imaginary boundaries, Eq. 19 */
    dd.linear_theta = theta;
    dd.linear_dx = dx_table1;
    dd.disc_length = length;
    dd.dt_param = gamma_dt;
    dd.integrator = FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR;
    dd.log = pd.log = cd.log = log_stderr;
    dd.log_user = pd.log_user = cd.log_user = (void *)tag;
    if (fsdem_dem_create(&dd, &dem) != FSDEM_OK) return -1;
    al.density = density;
    al.poisson_ratio = psi;
    al.friction = mu;
    al.damping_alpha = alpha;
    al.young_modulus = 70e9;
    al.restitution = 0.5;
    fsdem_dem_add_material(dem, &al, &mat);
    {
        fsdem_dem_wall_desc w[3];
        w[0] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 1, 0), mat);
        w[1] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), mat);
        w[2] = fsdem_dem_wall_plane(fsdem_v3(tank_w, 0, 0), fsdem_v3(-1, 0, 0), mat);
        for (k = 0; k < 3; ++k) fsdem_dem_add_wall(dem, &w[k], NULL);
    }
    for (k = 0; k < g.boxes; ++k) {
        fsdem_dem_wall_desc w = fsdem_dem_wall_box(g.lo[k], g.hi[k], 0, mat);
        if (fsdem_dem_add_wall(dem, &w, NULL) != FSDEM_OK) { fprintf(stderr, "%s\n", fsdem_dem_last_error(dem)); return -1; }
    }
    for (k = 0; k < 6; ++k) {
        fsdem_dem_wall_desc w = fsdem_dem_wall_segment(g.funnel[k], g.funnel[(k + 1) % 6], mat);
        if (fsdem_dem_add_wall(dem, &w, NULL) != FSDEM_OK) { fprintf(stderr, "%s\n", fsdem_dem_last_error(dem)); return -1; }
    }
    /* the pile: layers of 6 and 5, neighbours 2r + 2dx apart (imaginary boundaries touching) */
    p0 = pile_origin(s, gap);
    for (layer = 0; layer < 6; ++layer) {
        int count = layer % 2 ? 5 : 6;
        for (k = 0; k < count; ++k) {
            fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
            p.radius = radius;
            p.material = mat;
            p.position = fsdem_v3(p0.x + (k + (count == 5 ? 0.5 : 0)) * s, p0.y + layer * s * sqrt(3.0) / 2, 0);
            if (fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK) { fprintf(stderr, "%s\n", fsdem_dem_last_error(dem)); return -1; }
        }
    }
    {
        fsdem_real st = 0; /* Eq. 18 with gamma = 150 */
        if (fsdem_dem_stable_dt(dem, &st) != FSDEM_OK || fsdem_dem_set_dt(dem, st) != FSDEM_OK) {
            fprintf(stderr, "%s\n", fsdem_dem_last_error(dem));
            return -1;
        }
    }

    if (!o->dry) {
        /* PIC */
        pd.cell_size = dx;
        pd.domain_max = fsdem_v3(tank_w, tank_h, 0);
        pd.density = rho_w;
        pd.viscosity = nu_w;
        pd.dt_max = 1e-3;
        pd.cfl = 0.5; /* a cylinder entering the water next to a wall squirts water at 10 m/s */
        if (fsdem_pic_create(&pd, &pic) != FSDEM_OK) return -1;
        for (k = 0; k < g.boxes; ++k) {
            fsdem_pic_obstacle ob = fsdem_pic_obstacle_box(g.lo[k], g.hi[k]);
            if (fsdem_pic_add_obstacle(pic, &ob, NULL) != FSDEM_OK) { fprintf(stderr, "%s\n", fsdem_pic_last_error(pic)); return -1; }
        }
        {
            fsdem_pic_obstacle ob = fsdem_pic_obstacle_polygon(g.funnel, 6);
            if (fsdem_pic_add_obstacle(pic, &ob, NULL) != FSDEM_OK) { fprintf(stderr, "%s\n", fsdem_pic_last_error(pic)); return -1; }
        }
        fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3(tank_w, depth, 0), fsdem_v3(0, 0, 0), NULL);
        /* level gauges: the pipe's axis, 10 cm either side (clear of the funnel above), and every
           cell column inside the pipe */
        fsdem_pic_add_gauge(pic, FSDEM_PIC_GAUGE_KIND_LEVEL, fsdem_v3(xc, pipe_bottom + 0.01, 0), 0, &gauge[0]);
        fsdem_pic_add_gauge(pic, FSDEM_PIC_GAUGE_KIND_LEVEL, fsdem_v3(xc - 0.10, 0.01, 0), 0, &gauge[1]);
        fsdem_pic_add_gauge(pic, FSDEM_PIC_GAUGE_KIND_LEVEL, fsdem_v3(xc + 0.10, 0.01, 0), 0, &gauge[2]);
        for (k = 0;; ++k) {
            const double x = (floor((xc - pipe_w / 2) / dx + 1e-9) + k + 0.5) * dx;
            if (x > xc + pipe_w / 2 || n_in == MAX_COLUMNS) break;
            fsdem_pic_add_gauge(pic, FSDEM_PIC_GAUGE_KIND_LEVEL, fsdem_v3(x, pipe_bottom + 0.01, 0), 0, &gauge[3 + n_in]);
            n_in++;
        }

        cd.pic = pic;
        cd.dem = dem;
        cd.dissipation = beta;
        if (fsdem_pic_dem_create(&cd, &cp) != FSDEM_OK) {
            return -1;
        }
    }
    vol0 = pic ? fsdem_pic_get_stats(pic).particle_volume : 1;
    fvol0 = pic ? fsdem_pic_get_stats(pic).fluid_volume : 1;
    r->particles0 = r->particles_min = r->particles_max = pic ? fsdem_pic_get_stats(pic).particles : 0;
    vc_info(CASE, "%s%s: dx = %.3g m, holes %.3g m, %d wall pieces, funnel %.4f m wide, pile base y = %.4f m, %d water particles, DEM dt = %.3g s",
            tag, o->dry ? " (dry)" : "", dx, perforated ? o->hole_w : 0.0, g.boxes, funnel_w, p0.y,
            pic ? fsdem_pic_get_stats(pic).particles : 0, (double)fsdem_dem_get_desc(dem).dt);
    levels(pic, gauge, n_in, lv);
    r->level0_in = lv[0];
    r->level0_out = level_outside(lv);
    r->level_min_in = lv[0];
    r->level_max_out = r->level0_out;
    r->t_level_min_in = 0;

    for (;;) {
        fsdem_dem_particles P = fsdem_dem_get_particles(dem);
        int above = 0, in_pipe = 0, out = 0, i;
        double xm = 0, ym = 0, dv;
        t = cp ? fsdem_pic_dem_time(cp) : fsdem_dem_time(dem);
        for (i = 0; i < P.count; ++i) {
            const fsdem_vec3 q = P.position[i];
            xm += q.x;
            ym += q.y;
            if (q.y > pipe_bottom) above++;
            if (q.y > pipe_bottom && q.y < pipe_top && fabs(q.x - xc) < pipe_w / 2) in_pipe++;
            if (!(q.x > 0 && q.x < tank_w && q.y > 0 && q.y < tank_h)) out++;
        }
        xm /= P.count;
        ym /= P.count;
        if (out > r->outside) r->outside = out;
        if (above < N_CYL && r->t_first_out < 0) r->t_first_out = t;
        if (above == 0 && r->t_dump < 0) r->t_dump = t;
        if (above > 0 && r->t_dump >= 0) r->reentered = 1;
        if (pic) {
            const fsdem_pic_stats ps = fsdem_pic_get_stats(pic);
            dv = fabs(ps.particle_volume / vol0 - 1);
            if (dv > r->volume_drift) r->volume_drift = dv;
            dv = fabs(ps.fluid_volume / fvol0 - 1);
            if (dv > r->fluid_drift) r->fluid_drift = dv;
            if (ps.particles < r->particles_min) r->particles_min = ps.particles;
            if (ps.particles > r->particles_max) r->particles_max = ps.particles;
        }
        {
            fsdem_real ov = fsdem_dem_get_stats(dem).max_overlap;
            if (ov > r->max_overlap) r->max_overlap = ov;
        }
        levels(pic, gauge, n_in, lv);
        /* the noise of the level: its spread before the first cylinder reaches the water */
        if (r->t_first_out < 0 && t_quiet == 0) {
            int wet = 0;
            for (i = 0; i < P.count; ++i)
                if (P.position[i].y - radius - gap < depth + dx) wet = 1;
            if (wet) t_quiet = t;
            else {
                for (k = 0; k < 3; ++k) {
                    if (lv[k] < quiet_min) quiet_min = lv[k];
                    if (lv[k] > quiet_max) quiet_max = lv[k];
                }
            }
        }
        if (lv[0] < r->level_min_in) {
            r->level_min_in = lv[0];
            r->t_level_min_in = t;
            r->level_rise_after_min = 0;
        } else if (lv[0] - r->level_min_in > r->level_rise_after_min) {
            r->level_rise_after_min = lv[0] - r->level_min_in;
            r->t_level_max_after = t;
        }
        if (level_outside(lv) > r->level_max_out) r->level_max_out = level_outside(lv);
        if (t >= next_row - 1e-9) {
            fprintf(cyl_csv, "%d,%.5f,%d,%d,%.6f,%.6f\n", perforated, t, above, in_pipe, xm, ym);
            fprintf(lev_csv, "%d,%.5f,%.6f,%.6f,%.6f,%.6f\n", perforated, t, (double)lv[0], (double)lv[1], (double)lv[2], (double)lv[3]);
            next_row += 0.005;
        }
        if (next_snap < (int)(sizeof snap / sizeof snap[0]) && t >= snap[next_snap] - 1e-9) {
            char path[96];
            snprintf(path, sizeof path, "cylinders_%s_%.1f.csv", tag, snap[next_snap]);
            fsdem_dem_write_csv(dem, path);
            next_snap++;
        }
        if (t >= o->t_max - 1e-9 || (r->t_dump >= 0 && t >= r->t_dump + 0.3)) break;
        if (cp ? fsdem_pic_dem_step(cp) != FSDEM_OK : fsdem_dem_advance(dem, 1e-3, NULL) != FSDEM_OK) {
            fprintf(stderr, "%s (%s): t = %.4f s: %s\n", CASE, tag, t, cp ? fsdem_pic_dem_last_error(cp) : fsdem_dem_last_error(dem));
            failed = 1;
            break;
        }
        r->steps++;
        if (r->steps % 200 == 0) {
            fprintf(stderr, "%s: t = %.3f s, %d above the pipe bottom, %d in the pipe, level in %.4f out %.4f, %.0f s\n",
                    tag, t, above, in_pipe, (double)lv[0], level_outside(lv),
                    (double)(clock() - c0) / CLOCKS_PER_SEC);
        }
    }
    r->t_end = t;
    r->completed = !failed;
    r->noise = quiet_max > quiet_min ? quiet_max - quiet_min : 0;
    r->wall_seconds = (double)(clock() - c0) / CLOCKS_PER_SEC;
    if (cp) {
        fsdem_pic_dem_stats cs = fsdem_pic_dem_get_stats(cp);
        vc_info(CASE, "%s: %lld coupled steps to t = %.3f s, %.1f s CPU (PIC %.1f, DEM %.1f, coupling %.1f); quiet until t = %.3f s",
                tag, r->steps, t, r->wall_seconds, cs.coupling.seconds_fluid, cs.coupling.seconds_dem, cs.coupling.seconds_coupling, t_quiet);
    }
    if (cp) fsdem_pic_dem_destroy(cp);
    if (pic) fsdem_pic_destroy(pic);
    fsdem_dem_destroy(dem);
    return failed;
}

static void report(const options *o, const result *r, const char *tag) {
    char m[96];
    /* a drop of the inside level counts when it exceeds the noise by far: the larger of half a cell
       and three times the spread of the gauges before the first cylinder reaches the water */
    const double threshold = fmax(0.5 * o->dx, 3 * r->noise);
    snprintf(m, sizeof m, "%s_run_completed", tag);
    vc_check(CASE, m, r->completed, 1, 0);
    snprintf(m, sizeof m, "%s_cylinders_outside_domain", tag);
    vc_check(CASE, m, r->outside, 0, 0);
    snprintf(m, sizeof m, "%s_all_cylinders_left_pipe", tag);
    vc_check(CASE, m, r->t_dump >= 0, 1, 0);
    if (!o->dry) {
        snprintf(m, sizeof m, "%s_volume_drift", tag);
        vc_check(CASE, m, r->volume_drift, 0, 0.005);
    }
    if (r->t_dump >= 0)
        vc_info(CASE, "%s: first cylinder below the pipe bottom at t = %.3f s, all at t = %.3f s (dump time)%s", tag,
                r->t_first_out, r->t_dump, r->reentered ? "; one came back above it later" : "");
    else
        vc_info(CASE, "%s: first cylinder below the pipe bottom at t = %.3f s; not all by t = %.3f s", tag, r->t_first_out,
                r->t_end);
    if (o->dry) return;
    vc_info(CASE, "%s: level inside the pipe %.4f m at t = 0, lowest %.4f m at t = %.3f s (drop %.2f mm), then up by %.2f mm (to t = %.3f s); outside %.4f m at t = 0, highest %.4f m (+%.2f mm)",
            tag, r->level0_in, r->level_min_in, r->t_level_min_in, 1e3 * (r->level0_in - r->level_min_in),
            1e3 * r->level_rise_after_min, r->t_level_max_after, r->level0_out, r->level_max_out,
            1e3 * (r->level_max_out - r->level0_out));
    vc_info(CASE, "%s: water particles %d at t = 0, between %d and %d during the run; the grid's liquid volume (fsdem_pic_stats.fluid_volume, cut cells by their open volume) drifts by up to %.3g %%",
            tag, r->particles0, r->particles_min, r->particles_max, 100 * r->fluid_drift);
    vc_info(CASE, "%s: level noise before the cylinders reach the water %.3f mm, threshold %.3f mm; largest overlap %.3g m",
            tag, 1e3 * r->noise, 1e3 * threshold, r->max_overlap);
}

int main(int argc, char **argv) {
    options o;
    result res[2];
    FILE *cyl, *lev;
    int p;
    const char *pipe;
    vc_begin(CASE, argc, argv, "--seed");
    o.dx = vc_option_num("--dx", vc_full() ? 0.0005 : 0.0015);
    o.hole_w = -1;
    o.t_max = vc_option_num("--t-max", 4.0);
    o.pipes = 3;
    if ((pipe = vc_option("--pipe")) != NULL) {
        o.pipes = !strcmp(pipe, "continuous") ? 1 : !strcmp(pipe, "perforated") ? 2 : 0;
        if (!o.pipes) { fprintf(stderr, "--pipe continuous|perforated\n"); return 2; }
    }
    o.dry = vc_flag("--dry");
    if (!(o.dx > 0 && o.dx <= 0.002)) { fprintf(stderr, "--dx must be in (0, 0.002] m\n"); return 2; }
    /* the funnel holds the bottom layer (6 cylinders 2r + 2 dx apart) with a gap to spare: 8 cm for
       dx <= 1 mm, wider on coarser (development) grids */
    funnel_w = fmax(funnel_w0, 5 * (2 * radius + 2 * o.dx) + 2 * (radius + 2 * o.dx) + 0.002);
    funnel_slope_top = pipe_top + (funnel_w - pipe_w) * tan(funnel_angle * DEG);
    o.hole_w = fmax(0.001, 2 * o.dx);
    vc_tier("dx = %g mm, holes %g mm, runs to %g s at most%s", 1e3 * o.dx, 1e3 * o.hole_w, o.t_max, o.dry ? ", dry" : "");
    cyl = fopen("cylinders.csv", "w");
    lev = fopen("levels.csv", "w");
    if (!cyl || !lev) { fprintf(stderr, "%s: cannot write the CSV files\n", CASE); return 1; }
    fprintf(cyl, "perforated,t,above_pipe_bottom,in_pipe,x_mean,y_mean\n");
    fprintf(lev, "perforated,t,level_inside,level_left,level_right,level_axis\n");
    memset(res, 0, sizeof res);
    for (p = 0; p < 2; ++p) {
        if (!(o.pipes & (1 << p))) continue;
        if (run(&o, p, &res[p], cyl, lev) < 0) { fprintf(stderr, "%s: set-up failed\n", CASE); return 1; }
        fflush(cyl);
        fflush(lev);
    }
    fclose(cyl);
    fclose(lev);
    for (p = 0; p < 2; ++p)
        if (res[p].ran) report(&o, &res[p], p ? "perforated" : "continuous");
    if (res[0].ran && !o.dry) {
        const result *r = &res[0];
        const double threshold = fmax(0.5 * o.dx, 3 * r->noise);
        /* seed 000 Fig. 12 A1-A5: the level inside the continuous pipe drops, then recovers */
        vc_check(CASE, "continuous_level_drop_beyond_noise", r->level0_in - r->level_min_in > threshold, 1, 0);
        vc_check(CASE, "continuous_level_rise_after_minimum", r->level_rise_after_min > threshold, 1, 0);
    }
    if (res[0].ran && res[1].ran && !o.dry) {
        /* seed 000 section 3.3: the perforated pipe dumps without delay */
        const int both = res[0].t_dump >= 0 && res[1].t_dump >= 0;
        vc_check(CASE, "perforated_dumps_faster", both && res[1].t_dump < res[0].t_dump, 1, 0);
        if (both)
            vc_info(CASE, "dump time continuous %.3f s, perforated %.3f s (ratio %.3f)", res[0].t_dump, res[1].t_dump,
                    res[1].t_dump / res[0].t_dump);
    }
    return vc_exit_code();
}
