/* What a user meets on the first day (issue 10): the defects found by probing the API from outside,
   each with a test that failed before its fix; the DEM dt warning; SWE buildings (blocked cells)
   and gauges at exact output times; PIC gauges. Tolerances are justified next to each check. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fsdem_tests.h"

#define G 9.81

/* A log sink that keeps the last message of each level. */
typedef struct log_capture {
    char last[3][512];
    int count[3];
} log_capture;

static void capture(void *user, fsdem_log_level level, const char *message) {
    log_capture *c = (log_capture *)user;
    snprintf(c->last[level], sizeof c->last[level], "%s", message);
    c->count[level]++;
}

/* An allocator that fails every call (out of memory from the first byte). */
static void *no_alloc(void *user, size_t size) {
    (void)user;
    (void)size;
    return NULL;
}
static void no_free(void *user, void *ptr, size_t size) {
    (void)user;
    (void)ptr;
    (void)size;
}

static fsdem_dem *make_dem(const fsdem_dem_desc *d) {
    fsdem_dem *dem = NULL;
    ck_assert_int_eq(fsdem_dem_create(d, &dem), FSDEM_OK);
    return dem;
}

static int add_sphere(fsdem_dem *dem, int mat, fsdem_vec3 x, fsdem_vec3 v, double r) {
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    int index = -1;
    p.position = x;
    p.velocity = v;
    p.radius = (fsdem_real)r;
    p.material = mat;
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, &index), FSDEM_OK);
    return index;
}

/* ---- defects 1-3: a lone sphere, huge domains, heavy damping ----------------------------------- */

/* One sphere and no pair: the pair search has nothing to copy (it called memcpy from NULL, which
   UBSan reports under `make sanitize`). Free fall is exact under velocity Verlet (constant force):
   z = z0 - g t^2 / 2 to rounding. */
START_TEST(lone_sphere_falls_freely) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem;
    fsdem_dem_material m = fsdem_dem_material_default();
    int mat, k;
    double t, z;
    d.dt = 1e-4;
    dem = make_dem(&d);
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat), FSDEM_OK);
    add_sphere(dem, mat, fsdem_v3(0, 0, 0.9), fsdem_v3(0, 0, 0), 0.01);
    for (k = 0; k < 100; ++k) ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_advance(dem, 0.01, NULL), FSDEM_OK);
    t = fsdem_dem_time(dem);
    z = fsdem_dem_get_particles(dem).position[0].z;
    /* 200 steps of rounding on numbers of order 1: 1e-12 m in double (a few hundred eps), 1e-4 m in float */
    ck_assert_msg(fabs(z - (0.9 - 0.5 * G * t * t)) < (sizeof(fsdem_real) == 4 ? 1e-4 : 1e-12), "z %g, exact %g", z,
                  0.9 - 0.5 * G * t * t);
    fsdem_dem_destroy(dem);
}
END_TEST

/* A domain of +-1e308 overflows its extent to infinity: the cell grid enlarged its cells forever. */
START_TEST(infinite_extents_are_refused) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_cellgrid g;
    fsdem_vec3 pts[2] = {{0, 0, 0}, {0.5, 0.5, 0.5}};
    char msg[256];
    d.domain_min = fsdem_v3((fsdem_real)-1e308, -1, -1);
    d.domain_max = fsdem_v3((fsdem_real)1e308, 1, 1);
    if (sizeof(fsdem_real) == 8) { /* (in float 1e308 is already infinite and refused as such) */
        ck_assert_int_eq(fsdem_dem_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
        ck_assert_ptr_nonnull(strstr(msg, "finite extent"));
    }
    memset(&g, 0, sizeof g);
    ck_assert_int_eq(fsdem_cellgrid_build(&g, pts, 2), FSDEM_ERR_INVALID_ARG); /* before any setup */
    ck_assert_int_eq(fsdem_cellgrid_setup(&g, NULL, 3, d.domain_min, d.domain_max, 0.1, 0), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_cellgrid_setup(&g, NULL, 3, fsdem_v3(0, 0, 0), fsdem_v3(1, 1, 1), 0.1, 0), FSDEM_OK);
    ck_assert_int_eq(fsdem_cellgrid_build(&g, pts, -5), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_cellgrid_build(&g, pts, 2), FSDEM_OK);
    ck_assert_int_eq(g.cell_start[g.cell_count], 2);
    fsdem_cellgrid_free(&g);
}
END_TEST

/* The Hertz damping calibration integrated until x = 0, which heavy damping postpones without bound
   (2.6 s at e = 1e-3, minutes at 1e-5). It is now a bounded solve: each call returns in
   milliseconds (the test's own timeout would catch a hang), and the calibrated damping gives the
   restitution asked for, measured on a head-on impact at 1 m/s without gravity. */
START_TEST(heavy_damping_calibrates_quickly) {
    const double es[3] = {1e-2, 1e-4, 1e-6};
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem *dem;
    fsdem_dem_wall_desc w;
    char msg[256];
    int k, mat;
    for (k = 0; k < 3; ++k) {
        d.gravity = fsdem_v3(0, 0, 0);
        d.integrator = FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR;
        d.dt = 1e-6; /* ~500 steps across the contact of a 1 cm sphere at 1 m/s (E = 1e8 Pa: ~0.5 ms) */
        dem = make_dem(&d);
        m.restitution = (fsdem_real)es[k];
        ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat), FSDEM_OK);
        if (k == 0) {
            double v;
            w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), mat);
            ck_assert_int_eq(fsdem_dem_add_wall(dem, &w, NULL), FSDEM_OK);
            add_sphere(dem, mat, fsdem_v3(0, 0, 0.0101), fsdem_v3(0, 0, -1), 0.01);
            ck_assert_int_eq(fsdem_dem_advance(dem, 5e-3, NULL), FSDEM_OK); /* long past the separation */
            v = fsdem_dem_get_particles(dem).velocity[0].z;
            /* the predictor-corrector reproduces the calibrated restitution to ~0.1% at e >= 0.2
               (test_dem); at e = 0.01 the rebound is 1% of the impact, and 5% of it is 5e-4 m/s */
            ck_assert_msg(fabs(v / es[k] - 1) < 0.05, "e = %g: rebound %g m/s", es[k], v);
        }
        fsdem_dem_destroy(dem);
    }
    m.restitution = (fsdem_real)5e-7;
    dem = make_dem(&d);
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(fsdem_dem_last_error(dem), "restitution"));
    fsdem_dem_destroy(dem);
    (void)msg;
}
END_TEST

/* ---- defect 5: a coupled step refused before anything moves ---------------------------------- */

START_TEST(coupled_step_checks_substeps_first) {
    fsdem_swe_desc sd = fsdem_swe_desc_default(1);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_swe_dem_desc cd = fsdem_swe_dem_desc_default();
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_real depth[20];
    fsdem_swe *swe;
    fsdem_dem *dem;
    fsdem_swe_dem *cpl;
    fsdem_vec3 mom;
    int k, mat;
    double t_swe, t_dem, vol;
    for (k = 0; k < 20; ++k) depth[k] = (fsdem_real)(k < 10 ? 0.5 : 0.1);
    sd.nx = 20;
    sd.x_max = 2;
    sd.depth = depth;
    ck_assert_int_eq(fsdem_swe_create(&sd, &swe), FSDEM_OK);
    dd.domain_min = fsdem_v3(0, -1, -1);
    dd.domain_max = fsdem_v3(2, 1, 2);
    dd.dt = 1e-7; /* a fluid step of ~1e-2 s would need ~1e5 DEM substeps */
    dem = make_dem(&dd);
    m.density = 500;
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat), FSDEM_OK);
    add_sphere(dem, mat, fsdem_v3(1.5, 0, 0.1), fsdem_v3(0, 0, 0), 0.02);
    cd.swe = swe;
    cd.dem = dem;
    cd.max_substeps = 1000;
    ck_assert_int_eq(fsdem_swe_dem_create(&cd, &cpl), FSDEM_OK);
    t_swe = fsdem_swe_time(swe);
    t_dem = fsdem_dem_time(dem);
    vol = fsdem_swe_volume(swe);
    mom = fsdem_swe_momentum(swe);
    ck_assert_int_eq(fsdem_swe_dem_step(cpl), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(fsdem_swe_dem_last_error(cpl), "max_substeps"));
    /* nothing moved: the water (exactly: no step was taken) and the debris */
    ck_assert(fsdem_swe_time(swe) == t_swe && fsdem_dem_time(dem) == t_dem);
    ck_assert(fsdem_swe_volume(swe) == vol && fsdem_swe_momentum(swe).x == mom.x);
    /* with enough substeps allowed the same step goes through */
    ck_assert_int_eq(fsdem_dem_set_dt(dem, 1e-4), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_dem_step(cpl), FSDEM_OK);
    ck_assert(fsdem_swe_dem_get_stats(cpl).coupling.substeps >= 1 && fsdem_swe_dem_get_stats(cpl).coupling.substeps <= 1000);
    fsdem_swe_dem_destroy(cpl);
    fsdem_dem_destroy(dem);
    fsdem_swe_destroy(swe);
}
END_TEST

/* ---- defect 7: inputs that were accepted silently ---------------------------------------------- */

static fsdem_real nan_sdf(void *user, fsdem_vec3 p, fsdem_vec3 *normal) {
    (void)user;
    (void)p;
    *normal = fsdem_v3(0, 1, 0);
    return (fsdem_real)NAN;
}

START_TEST(silently_accepted_inputs_are_refused) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_dem_wall_desc w;
    fsdem_dem_contact c[4];
    fsdem_dem *dem = make_dem(&d);
    fsdem_swe_desc sd = fsdem_swe_desc_default(1);
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_pic_obstacle ob;
    fsdem_vec3 same[3] = {{0.5, 0.5, 0}, {0.5, 0.5, 0}, {0.5, 0.5, 0}};
    fsdem_pic *pic;
    char msg[256];
    int mat, n;
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat), FSDEM_OK);
    /* radii whose mass overflows (acts fixed) or underflows (NaN at the next step) */
    p.material = mat;
    p.radius = (fsdem_real)(sizeof(fsdem_real) == 8 ? 1e120 : 1e30);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(fsdem_dem_last_error(dem), "radius"));
    p.radius = (fsdem_real)(sizeof(fsdem_real) == 8 ? 1e-120 : 1e-30);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_dem_get_particles(dem).count, 0);
    /* a plane normal of (1e300, 1e300, 1e300) overflowed to a zero unit normal; now it is (1,1,1)/sqrt 3 */
    w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)(sizeof(fsdem_real) == 8 ? 1e300 : 1e38),
                                                        (fsdem_real)(sizeof(fsdem_real) == 8 ? 1e300 : 1e38),
                                                        (fsdem_real)(sizeof(fsdem_real) == 8 ? 1e300 : 1e38)), mat);
    ck_assert_int_eq(fsdem_dem_add_wall(dem, &w, NULL), FSDEM_OK);
    p.radius = 0.1;
    p.position = fsdem_v3(0.01, 0.01, 0.01);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
    n = fsdem_dem_contacts(dem, c, 4);
    ck_assert_int_eq(n, 1);
    /* the normal of a unit vector rebuilt from three equal components: to a few roundings */
    ck_assert(fabs(c[0].normal.x - 1 / sqrt(3.0)) < 1e-5 && fabs(c[0].normal.z - 1 / sqrt(3.0)) < 1e-5);
    /* a triangle of 1e200 coordinates overflows its area; a segment in 3D */
    if (sizeof(fsdem_real) == 8) {
        w = fsdem_dem_wall_triangle(fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)1e200, 0, 0), fsdem_v3(0, (fsdem_real)1e200, 0), mat);
        ck_assert_int_eq(fsdem_dem_add_wall(dem, &w, NULL), FSDEM_ERR_INVALID_ARG);
    }
    w = fsdem_dem_wall_segment(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), mat);
    ck_assert_int_eq(fsdem_dem_add_wall(dem, &w, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(fsdem_dem_last_error(dem), "dim = 2"));
    fsdem_dem_destroy(dem);
    /* SWE cells of an infinite or a vanishing size */
    if (sizeof(fsdem_real) == 8) {
        sd.x_min = (fsdem_real)-1e308;
        sd.x_max = (fsdem_real)1e308;
        ck_assert_int_eq(fsdem_swe_desc_check(&sd, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
        sd.x_min = 0;
        sd.x_max = (fsdem_real)1e-308;
        ck_assert_int_eq(fsdem_swe_desc_check(&sd, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
        ck_assert_ptr_nonnull(strstr(msg, "size"));
    }
    /* PIC: a cell far larger than the domain, a polygon of coincident vertices, an SDF returning NaN */
    pd.cell_size = 100;
    ck_assert_int_eq(fsdem_pic_desc_check(&pd, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(msg, "cell_size"));
    pd = fsdem_pic_desc_default(2);
    pd.cell_size = 0.1;
    ck_assert_int_eq(fsdem_pic_create(&pd, &pic), FSDEM_OK);
    ob = fsdem_pic_obstacle_polygon(same, 3);
    ck_assert_int_eq(fsdem_pic_add_obstacle(pic, &ob, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(fsdem_pic_last_error(pic), "no area"));
    ob = fsdem_pic_obstacle_sdf(nan_sdf, NULL);
    ck_assert_int_eq(fsdem_pic_add_obstacle(pic, &ob, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(fsdem_pic_last_error(pic), "callback returned"));
    ck_assert_int_eq(fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3(0.5, 0.5, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
    fsdem_pic_destroy(pic);
}
END_TEST

/* A PIC extent that is not a whole number of cells is rounded, and the rounding is logged. */
START_TEST(pic_rounding_is_logged) {
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    log_capture log;
    fsdem_pic *pic;
    memset(&log, 0, sizeof log);
    pd.domain_max = fsdem_v3((fsdem_real)3.22, 1, 0);
    pd.cell_size = 0.03; /* 107.33 cells: 107, domain_max.x 3.21 */
    pd.log = capture;
    pd.log_user = &log;
    ck_assert_int_eq(fsdem_pic_create(&pd, &pic), FSDEM_OK);
    ck_assert_int_eq(log.count[FSDEM_LOG_LEVEL_INFO], 2); /* x and y (1/0.03 = 33.3 cells) */
    ck_assert_ptr_nonnull(strstr(log.last[FSDEM_LOG_LEVEL_INFO], "rounded"));
    ck_assert(fabs(fsdem_pic_get_desc(pic).domain_max.x - 3.21) < 1e-5);
    fsdem_pic_destroy(pic);
}
END_TEST

/* ---- defect 8: out of memory at creation says so ----------------------------------------------- */

START_TEST(out_of_memory_at_creation_is_logged) {
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_swe_desc sd = fsdem_swe_desc_default(1);
    fsdem_pcg_desc gd = fsdem_pcg_desc_default();
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_allocator none;
    log_capture log;
    fsdem_dem *dem = NULL;
    fsdem_swe *swe = NULL;
    fsdem_pcg *pcg = NULL;
    fsdem_pic *pic = NULL;
    none.alloc = no_alloc;
    none.free = no_free;
    none.user = NULL;
    memset(&log, 0, sizeof log);
    dd.allocator = sd.allocator = gd.allocator = pd.allocator = none;
    dd.log = sd.log = gd.log = pd.log = capture;
    dd.log_user = sd.log_user = gd.log_user = pd.log_user = &log;
    ck_assert_int_eq(fsdem_dem_create(&dd, &dem), FSDEM_ERR_OUT_OF_MEMORY);
    ck_assert_ptr_nonnull(strstr(log.last[FSDEM_LOG_LEVEL_ERROR], "fsdem_dem_create: out of memory"));
    ck_assert_int_eq(fsdem_swe_create(&sd, &swe), FSDEM_ERR_OUT_OF_MEMORY);
    ck_assert_ptr_nonnull(strstr(log.last[FSDEM_LOG_LEVEL_ERROR], "fsdem_swe_create: out of memory"));
    ck_assert_int_eq(fsdem_pcg_create(&gd, &pcg), FSDEM_ERR_OUT_OF_MEMORY);
    ck_assert_ptr_nonnull(strstr(log.last[FSDEM_LOG_LEVEL_ERROR], "fsdem_pcg_create: out of memory"));
    ck_assert_int_eq(fsdem_pic_create(&pd, &pic), FSDEM_ERR_OUT_OF_MEMORY);
    ck_assert_ptr_nonnull(strstr(log.last[FSDEM_LOG_LEVEL_ERROR], "fsdem_pic_create: out of memory"));
    ck_assert(!dem && !swe && !pcg && !pic && log.count[FSDEM_LOG_LEVEL_ERROR] == 4);
}
END_TEST

/* ---- the DEM dt warning ------------------------------------------------------------------------ */

/* dt above the stable estimate is logged once, shown in the stats, and named when the run fails. */
START_TEST(dem_dt_above_the_estimate_is_warned) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_wall_desc w;
    fsdem_dem *dem;
    log_capture log;
    fsdem_real stable;
    fsdem_result res = FSDEM_OK;
    int mat, k;
    memset(&log, 0, sizeof log);
    d.log = capture;
    d.log_user = &log;
    d.domain_min = fsdem_v3(-0.1, -0.1, -0.1);
    d.domain_max = fsdem_v3(0.1, 0.1, 0.3);
    dem = make_dem(&d);
    m.young_modulus = 1e9;
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat), FSDEM_OK);
    w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), mat);
    ck_assert_int_eq(fsdem_dem_add_wall(dem, &w, NULL), FSDEM_OK);
    add_sphere(dem, mat, fsdem_v3(0, 0, 0.02), fsdem_v3(0, 0, -2), 0.01);
    ck_assert_int_eq(fsdem_dem_stable_dt(dem, &stable), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_set_dt(dem, 10 * stable), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK);
    ck_assert_int_eq(log.count[FSDEM_LOG_LEVEL_WARNING], 1);
    ck_assert_ptr_nonnull(strstr(log.last[FSDEM_LOG_LEVEL_WARNING], "stable dt"));
    ck_assert(fabs(fsdem_dem_get_stats(dem).dt_ratio - 10) < 1e-4);
    ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK);
    ck_assert_int_eq(log.count[FSDEM_LOG_LEVEL_WARNING], 1); /* once per change */
    /* 1e4 times the estimate: the sphere goes through the floor, and the error says why */
    ck_assert_int_eq(fsdem_dem_set_dt(dem, 1e4 * stable), FSDEM_OK);
    for (k = 0; k < 100 && res == FSDEM_OK; ++k) res = fsdem_dem_step(dem);
    ck_assert(res == FSDEM_ERR_OUT_OF_DOMAIN || res == FSDEM_ERR_NAN);
    ck_assert_ptr_nonnull(strstr(fsdem_dem_last_error(dem), "likely cause"));
    fsdem_dem_destroy(dem);
}
END_TEST

/* ---- SWE buildings and gauges ------------------------------------------------------------------ */

static fsdem_swe *swe_new(const fsdem_swe_desc *d) {
    fsdem_swe *s = NULL;
    ck_assert_int_eq(fsdem_swe_create(d, &s), FSDEM_OK);
    return s;
}

/* A channel closed by blocked cells is the same channel closed by a WALL side: the blocked faces
   reflect with the wall's Riemann problem and the reconstruction mirrors the cell as the wall's
   ghost does, so the open cells agree bit for bit (a dam break running into the closed end, in 1D
   and across the columns of a 2D grid). */
START_TEST(blocked_cells_are_walls) {
    int dim;
    for (dim = 1; dim <= 2; ++dim) {
        fsdem_swe_desc a = fsdem_swe_desc_default(dim), b;
        fsdem_real depth_a[60 * 4], depth_b[80 * 4];
        fsdem_swe *sa, *sb;
        fsdem_swe_fields fa, fb;
        int i, j, k, ny = dim == 2 ? 4 : 1;
        a.nx = 60;
        a.ny = ny;
        a.x_max = 6;
        a.y_max = 0.4;
        a.limiter = FSDEM_SWE_LIMITER_MC;
        b = a;
        b.nx = 80;
        b.x_max = 8; /* cells 60..79 blocked */
        for (j = 0; j < ny; ++j) {
            for (i = 0; i < 60; ++i) depth_a[j * 60 + i] = (fsdem_real)(i < 20 ? 1.0 : 0.2 + 0.01 * j);
            for (i = 0; i < 80; ++i) depth_b[j * 80 + i] = i < 60 ? depth_a[j * 60 + i] : 0;
        }
        a.depth = depth_a;
        b.depth = depth_b;
        sa = swe_new(&a);
        sb = swe_new(&b);
        ck_assert_int_eq(fsdem_swe_block_box(sb, 6, -1, 9, 1), FSDEM_OK);
        for (k = 0; k < 300; ++k) {
            ck_assert_int_eq(fsdem_swe_step(sa), FSDEM_OK);
            ck_assert_int_eq(fsdem_swe_step(sb), FSDEM_OK);
        }
        fa = fsdem_swe_get_fields(sa);
        fb = fsdem_swe_get_fields(sb);
        ck_assert(fsdem_swe_time(sa) == fsdem_swe_time(sb));
        for (j = 0; j < ny; ++j)
            for (i = 0; i < 60; ++i)
                ck_assert_msg(fa.eta[j * 60 + i] == fb.eta[j * 80 + i] && fa.qx[j * 60 + i] == fb.qx[j * 80 + i] &&
                                  fa.qy[j * 60 + i] == fb.qy[j * 80 + i],
                              "%dD cell (%d, %d): eta %.17g vs %.17g", dim, i, j, (double)fa.eta[j * 60 + i],
                              (double)fb.eta[j * 80 + i]);
        for (j = 0; j < ny; ++j)
            for (i = 60; i < 80; ++i) ck_assert(fb.eta[j * 80 + i] == fb.bed[j * 80 + i] && fb.blocked[j * 80 + i]);
        fsdem_swe_destroy(sa);
        fsdem_swe_destroy(sb);
    }
}
END_TEST

static void column_of_water(void *user, fsdem_real x, fsdem_real y, fsdem_swe_cell *c) {
    (void)user;
    c->bed = 0;
    c->depth = x < 1 ? 1 : (fsdem_real)0.05;
    c->u = c->v = 0;
    (void)y;
}

/* A 2D dam break against a building: volume is conserved to rounding (no mass crosses a blocked
   face), no water ever enters the building, sampling refuses points in it and interpolates without
   it, sources and gauges cannot be put in it, and blocking a wet cell books its water. */
START_TEST(dam_break_against_a_building) {
    fsdem_swe_desc d = fsdem_swe_desc_default(2);
    const fsdem_vec3 footprint[4] = {{2.0, 0.8, 0}, {2.6, 0.8, 0}, {2.6, 1.4, 0}, {2.0, 1.4, 0}};
    fsdem_swe_point_source src;
    fsdem_swe_fields f;
    fsdem_swe_cell c;
    fsdem_swe_stats st;
    fsdem_swe *s;
    double v0, v1, inside = 0;
    int k, blocked = 0, expected = 0;
    d.nx = 80;
    d.ny = 40;
    d.x_max = 4;
    d.y_max = 2;
    s = swe_new(&d);
    ck_assert_int_eq(fsdem_swe_set_cells(s, column_of_water, NULL), FSDEM_OK);
    v0 = fsdem_swe_volume(s);
    ck_assert_int_eq(fsdem_swe_block_polygon(s, footprint, 4), FSDEM_OK);
    f = fsdem_swe_get_fields(s);
    for (k = 0; k < d.nx * d.ny; ++k) {
        /* cell centres strictly inside the footprint, counted independently of the library */
        const double x = 0.025 + 0.05 * (k % d.nx), y = 0.025 + 0.05 * (k / d.nx);
        expected += x > 2.0 && x < 2.6 && y > 0.8 && y < 1.4;
        blocked += f.blocked[k];
    }
    ck_assert_int_eq(blocked, expected);
    st = fsdem_swe_get_stats(s);
    /* the building took 0.05 m of water from each of its cells: booked as a (negative) source */
    /* 144 bookings summed in fsdem_real: up to 144 roundings of the running total (< 0.018 m^3), 4 eps m^3 */
    ck_assert_msg(fabs(st.source_volume + 0.05 * expected * 0.0025) < TOL(1e-12, 4), "booked %.9g m^3 for %d cells",
                  (double)st.source_volume, expected);
    v0 += st.source_volume;
    ck_assert(fabs(fsdem_swe_volume(s) - v0) < TOL(1e-12, 4));
    ck_assert_int_eq(fsdem_swe_advance(s, 1.0, NULL), FSDEM_OK);
    f = fsdem_swe_get_fields(s);
    for (k = 0; k < d.nx * d.ny; ++k)
        if (f.blocked[k]) inside += f.eta[k] - f.bed[k];
    v1 = fsdem_swe_volume(s);
    /* finite-volume fluxes: exact in exact arithmetic, ~1e3 steps of rounding on a volume of ~1 m^3 */
    ck_assert_msg(fabs(v1 - v0) < (sizeof(fsdem_real) == 8 ? 1e-12 : 1e-4) * v0, "volume %g -> %g", v0, v1);
    ck_assert(inside == 0);
    ck_assert_int_eq(fsdem_swe_sample_state(s, 2.3, 1.1, &c), FSDEM_ERR_OUT_OF_DOMAIN);
    /* Sampling by hand (cells of 0.05 m, centres at 0.025 + 0.05 i; the building covers the
       centres of columns i >= 40, rows 16..27). At (1.96, 1.1) the four centres around the point,
       columns 38 and 39 (x = 1.925, 1.975) and rows 21 and 22 (y = 1.075, 1.125), are open: the
       bilinear weights are 0.3 and 0.7 along x, 0.5 and 0.5 along y. At (1.99, 1.1), still in the
       open column 39, the centres of column 40 (x = 2.025, weight 0.3) are blocked and leave: the
       two open ones share the weight, 0.5 each. Rounding: the four depths and weights in fsdem_real
       (8 eps of the 1 m column). */
    {
        const int row = 21 * d.nx;
        double h[4];
        int q;
        for (q = 0; q < 4; ++q) {
            const int k = row + (q & 1 ? 39 : 38) + (q & 2 ? d.nx : 0);
            h[q] = (double)f.eta[k] - (double)f.bed[k];
        }
        ck_assert_msg(h[1] > 0.01 && h[3] > 0.01, "the water reached the building (%g, %g m)", h[1], h[3]);
        ck_assert_int_eq(fsdem_swe_sample_state(s, 1.96, 1.1, &c), FSDEM_OK);
        ck_assert_msg(fabs(c.depth - (0.5 * (0.3 * h[0] + 0.7 * h[1]) + 0.5 * (0.3 * h[2] + 0.7 * h[3]))) < 8 * TEST_EPS,
                      "depth %.9g m at (1.96, 1.1)", (double)c.depth);
        ck_assert_int_eq(fsdem_swe_sample_state(s, 1.99, 1.1, &c), FSDEM_OK);
        ck_assert_msg(fabs(c.depth - 0.5 * (h[1] + h[3])) < 8 * TEST_EPS, "depth %.9g m at (1.99, 1.1), open cells %.9g, %.9g m",
                      (double)c.depth, h[1], h[3]);
    }
    memset(&src, 0, sizeof src);
    src.x = 2.3;
    src.y = 1.1;
    src.discharge = 0.1;
    ck_assert_int_eq(fsdem_swe_add_point_source(s, &src, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_swe_add_gauge(s, 2.3, 1.1, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_swe_add_gauge(s, 0.5, 1.1, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_block_box(s, 0.4, 1.0, 0.6, 1.2), FSDEM_ERR_INVALID_ARG); /* over the gauge */
    ck_assert_int_eq(fsdem_swe_set_blocked(s, NULL), FSDEM_OK);
    ck_assert_ptr_null(fsdem_swe_get_fields(s).blocked);
    fsdem_swe_destroy(s);
}
END_TEST

/* Gauge rows fall at exact multiples of the interval: in a closed lake under uniform rain the depth
   grows exactly linearly, h = h0 + rate t, so the rows interpolated within steps equal it to
   rounding at their times, which are k x interval. */
START_TEST(gauge_rows_at_exact_times) {
    fsdem_swe_desc d = fsdem_swe_desc_default(2);
    fsdem_real depth[10 * 10];
    fsdem_swe *s;
    FILE *fp;
    char line[512];
    int k, rows = 0;
    d.nx = d.ny = 10;
    d.rain_rate = 1e-3;
    for (k = 0; k < 100; ++k) depth[k] = (fsdem_real)0.5;
    d.depth = depth;
    d.dt_max = (fsdem_real)0.037; /* steps that do not divide the interval */
    s = swe_new(&d);
    ck_assert_int_eq(fsdem_swe_add_gauge(s, 0.55, 0.45, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_gauges_open(s, "build/test_gauge_rows.csv", 0.05), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_advance(s, 1.0, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_gauges_close(s), FSDEM_OK);
    fp = fopen("build/test_gauge_rows.csv", "r");
    ck_assert_ptr_nonnull(fp);
    ck_assert_ptr_nonnull(fgets(line, sizeof line, fp));
    ck_assert_str_eq(line, "t,h_0,eta_0,u_0,v_0\n");
    while (fgets(line, sizeof line, fp)) {
        double t, h;
        ck_assert_int_eq(sscanf(line, "%lf,%lf", &t, &h), 2);
        /* times printed with 10 digits; depths exact to rounding (a linear function interpolated) */
        /* the rows are multiples of the interval as stored (0.05 rounded to fsdem_real), printed with 10 digits */
        ck_assert_msg(fabs(t - (double)(fsdem_real)0.05 * rows) < 1e-9, "row %d at t = %.12g", rows, t);
        ck_assert_msg(fabs(h - (0.5 + 1e-3 * t)) < (sizeof(fsdem_real) == 8 ? 1e-9 : 1e-5), "t %g: h %.12g", t, h);
        rows++;
    }
    fclose(fp);
    /* t = 0, 0.05, ..., 1.0: the multiples of the stored interval up to the end (20 of them in float,
       where 20 x 0.05f is 1.000000015 s, past the end) */
    ck_assert_int_eq(rows, 1 + (int)floor(1.0 * (1 + 1e-12) / (double)(fsdem_real)0.05));
    fsdem_swe_destroy(s);
}
END_TEST

/* PIC gauges in still water: the level is the water height (the level set is exact for a plane
   surface, so ~1e-6 of a cell once the particles have settled), the pressure at a point is rho g
   depth, and a sensor patch averages the cells around its centre (hydrostatic: linear in depth, so
   a symmetric patch reads the centre's pressure). */
START_TEST(pic_gauges_in_still_water) {
    fsdem_pic_desc d = fsdem_pic_desc_default(2);
    fsdem_pic *s;
    fsdem_real level, p, patch;
    int lv, pp, pa, rows = 0;
    FILE *fp;
    char line[512];
    double t, row[3] = {0, 0, 0};
    d.cell_size = (fsdem_real)(1.0 / 32);
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), fsdem_v3(1, 0.5, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_add_gauge(s, FSDEM_PIC_GAUGE_KIND_LEVEL, fsdem_v3(0.3, 0, 0), 0, &lv), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_add_gauge(s, FSDEM_PIC_GAUGE_KIND_PRESSURE, fsdem_v3(0.5, 0.25, 0), 0, &pp), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_add_gauge(s, FSDEM_PIC_GAUGE_KIND_PRESSURE, fsdem_v3(0.5, 0.25, 0), (fsdem_real)0.08, &pa),
                     FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_add_gauge(s, (fsdem_pic_gauge_kind)7, fsdem_v3(0.5, 0.25, 0), 0, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pic_add_gauge(s, FSDEM_PIC_GAUGE_KIND_LEVEL, fsdem_v3(2, 0.25, 0), 0, NULL), FSDEM_ERR_OUT_OF_DOMAIN);
    ck_assert_int_eq(fsdem_pic_gauges_open(s, "build/test_pic_gauges.csv", 0.1), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_advance(s, 0.5, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_gauges_close(s), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_gauge(s, lv, &level), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_gauge(s, pp, &p), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_gauge(s, pa, &patch), FSDEM_OK);
    /* the level set of a settled plane surface: within 1% of a cell (3e-4 m) */
    ck_assert_msg(fabs(level - 0.5) < 0.01 / 32, "level %g m", (double)level);
    /* hydrostatic pressure: the solver gets it to ~1e-10 (pic_hydrostatic); 1e-3 allows the surface
       position read from the particles */
    ck_assert_msg(fabs(p / (1000 * 9.81 * 0.25) - 1) < 1e-3, "p %g Pa", (double)p);
    ck_assert_msg(fabs(patch / p - 1) < 1e-3, "patch %g Pa, point %g Pa", (double)patch, (double)p);
    ck_assert_int_eq(fsdem_pic_gauge(s, 3, &p), FSDEM_ERR_NOT_FOUND);
    /* the file: a row at every multiple of the stored interval up to the end (t = 0 ... 0.5 in double;
       in float 5 x 0.1f is past 0.5 s), the last one the state the gauges read now (the step ends at
       0.5 s, so its row is the end values, printed with 10 digits) */
    fp = fopen("build/test_pic_gauges.csv", "r");
    ck_assert_ptr_nonnull(fp);
    ck_assert_ptr_nonnull(fgets(line, sizeof line, fp));
    ck_assert_str_eq(line, "t,level_0,p_1,p_2\n");
    while (fgets(line, sizeof line, fp)) {
        ck_assert_int_eq(sscanf(line, "%lf,%lf,%lf,%lf", &t, &row[0], &row[1], &row[2]), 4);
        ck_assert_msg(fabs(t - (double)(fsdem_real)0.1 * rows) < 1e-9, "row %d at t = %.12g", rows, t);
        rows++;
    }
    fclose(fp);
    ck_assert_int_eq(rows, 1 + (int)floor(0.5 * (1 + 1e-12) / (double)(fsdem_real)0.1));
    if (sizeof(fsdem_real) == 8) {
        ck_assert_msg(fabs(row[0] - level) < 1e-9 * level && fabs(row[1] - p) < 1e-9 * p && fabs(row[2] - patch) < 1e-9 * patch,
                      "last row %.10g %.10g %.10g, gauges %.10g %.10g %.10g", row[0], row[1], row[2], (double)level,
                      (double)p, (double)patch);
    }
    fsdem_pic_destroy(s);
}
END_TEST

Suite *robustness_suite(void) {
    Suite *s = suite_create("robustness");
    TCase *tc = tcase_create("robustness");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, lone_sphere_falls_freely);
    tcase_add_test(tc, infinite_extents_are_refused);
    tcase_add_test(tc, heavy_damping_calibrates_quickly);
    tcase_add_test(tc, coupled_step_checks_substeps_first);
    tcase_add_test(tc, silently_accepted_inputs_are_refused);
    tcase_add_test(tc, pic_rounding_is_logged);
    tcase_add_test(tc, out_of_memory_at_creation_is_logged);
    tcase_add_test(tc, dem_dt_above_the_estimate_is_warned);
    tcase_add_test(tc, blocked_cells_are_walls);
    tcase_add_test(tc, dam_break_against_a_building);
    tcase_add_test(tc, gauge_rows_at_exact_times);
    tcase_add_test(tc, pic_gauges_in_still_water);
    suite_add_tcase(s, tc);
    return s;
}
