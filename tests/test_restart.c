/* Checkpoint and restart: for every solver (DEM, PIC, SWE, MPS) and the couplers, a run continued from a restored state is
   the uninterrupted run to the last byte of the state (fixed and adaptive dt); bad data (truncated,
   corrupted, other version, precision, dimension, kind, grid or desc) are refused with a message and
   leave the object exactly as it was, as does running out of memory. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fsdem_tests.h"

/* Saves of each object into malloc'd buffers (size first, then the bytes). */
#define DEFINE_SAVE(X)                                                                              \
    static unsigned char *save_##X(const fsdem_##X *o, size_t *size) {                              \
        size_t need = 0;                                                                            \
        unsigned char *b;                                                                           \
        ck_assert_int_eq(fsdem_##X##_save_memory(o, NULL, 0, &need), FSDEM_OK);                     \
        b = (unsigned char *)malloc(need);                                                          \
        ck_assert_ptr_nonnull(b);                                                                   \
        ck_assert_int_eq(fsdem_##X##_save_memory(o, b, need, size), FSDEM_OK);                      \
        ck_assert_uint_eq(*size, need);                                                             \
        return b;                                                                                   \
    }
DEFINE_SAVE(dem)
DEFINE_SAVE(pic)
DEFINE_SAVE(swe)
DEFINE_SAVE(swe_dem)
DEFINE_SAVE(mps)
DEFINE_SAVE(mps_dem)
DEFINE_SAVE(pic_dem)

/* Two saves are the same bytes; on failure the first differing byte is named. */
static void same_bytes(const unsigned char *a, size_t na, const unsigned char *b, size_t nb, const char *what) {
    size_t k = 0;
    ck_assert_msg(na == nb, "%s: %lu bytes vs %lu", what, (unsigned long)na, (unsigned long)nb);
    while (k < na && a[k] == b[k]) ++k;
    ck_assert_msg(k == na, "%s: the saves differ from byte %lu of %lu", what, (unsigned long)k, (unsigned long)na);
}

/* An allocator that fails once its budget of allocations is spent. */
typedef struct budget {
    long left;
} budget;

static void *budget_alloc(void *user, size_t size) {
    budget *b = (budget *)user;
    if (b->left <= 0) return NULL;
    b->left--;
    return malloc(size);
}

static void budget_free(void *user, void *p, size_t size) {
    (void)user;
    (void)size;
    free(p);
}

/* ---- DEM ---- */

/* Floor as a callback (an SDF wall). */
static fsdem_real floor_sdf(void *user, fsdem_vec3 p, fsdem_vec3 *normal) {
    (void)user;
    *normal = fsdem_v3(0, 0, 1);
    return p.z;
}

/* 3D Hertz-Mindlin scene: 64 spheres (r = 2 mm) on a lattice 0.1 mm apart with random velocities
   of 0.3 m/s in a box that moves sideways, on an SDF floor, with friction (tangential springs),
   rolling resistance and an external load on one sphere: contacts come and go, springs are held
   across steps, and the neighbour lists are rebuilt every hundred steps or so. */
static fsdem_dem_desc dem_desc(fsdem_dem_integrator integrator) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    d.domain_min = fsdem_v3(-0.05, -0.05, -0.01);
    d.domain_max = fsdem_v3(0.05, 0.05, 0.1);
    d.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    d.integrator = integrator;
    d.dt = 1e-5;
    return d;
}

/* The walls and materials of the scene (what a user's setup adds again before restoring: the SDF
   floor must be there, the rest is replaced by the restore). */
static void dem_setup(fsdem_dem *d, int *mat) {
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_wall_desc box = fsdem_dem_wall_box(fsdem_v3(-0.0085, -0.0085, -0.001), fsdem_v3(0.0085, 0.0085, 0.04), 1, 0);
    fsdem_dem_wall_desc floor = fsdem_dem_wall_sdf(floor_sdf, NULL, 0);
    m.young_modulus = 1e7;
    m.friction = 0.5;
    m.rolling_friction = 0.05;
    ck_assert_int_eq(fsdem_dem_add_material(d, &m, mat), FSDEM_OK);
    box.velocity = fsdem_v3(0.2, 0, 0);
    ck_assert_int_eq(fsdem_dem_add_wall(d, &floor, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_wall(d, &box, NULL), FSDEM_OK);
}

static fsdem_dem *dem_scene(const fsdem_dem_desc *desc) {
    fsdem_dem *d = NULL;
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    unsigned seed = 12345;
    int i, j, k, mat;
    ck_assert_int_eq(fsdem_dem_create(desc, &d), FSDEM_OK);
    dem_setup(d, &mat);
    p.radius = 0.002;
    p.material = mat;
    for (k = 0; k < 4; ++k)
        for (j = 0; j < 4; ++j)
            for (i = 0; i < 4; ++i) {
                fsdem_real r[3];
                int a;
                for (a = 0; a < 3; ++a) {
                    seed = seed * 1103515245u + 12345u;
                    r[a] = (fsdem_real)((double)(seed / 65536u % 32768u) / 32768.0 - 0.5) * (fsdem_real)0.6;
                }
                p.position = fsdem_v3(-0.00615 + 0.0041 * i, -0.00615 + 0.0041 * j, 0.0021 + 0.0041 * k);
                p.velocity = fsdem_v3(r[0], r[1], r[2]);
                ck_assert_int_eq(fsdem_dem_add_particle(d, &p, NULL), FSDEM_OK);
            }
    fsdem_dem_get_coupling(d).force[5] = fsdem_v3(0, 0, 1e-3);
    return d;
}

/* `steps` steps, alternately single and fused (fsdem_dem_advance). */
static void dem_run(fsdem_dem *d, int steps) {
    int k;
    fsdem_real dt = fsdem_dem_get_desc(d).dt;
    for (k = 0; k < steps; k += 25) {
        if (k % 50 == 0) {
            int s;
            for (s = 0; s < 25; ++s) ck_assert_int_eq(fsdem_dem_step(d), FSDEM_OK);
        } else {
            long long n = 0;
            ck_assert_int_eq(fsdem_dem_advance(d, 25 * dt, &n), FSDEM_OK);
            ck_assert_int_eq((int)n, 25);
        }
    }
}

/* Runs the scene N steps, saves (memory and file), runs M more and saves (B); a fresh object
   restored from the first save (memory, file) and run M steps saves the same bytes as B. The
   restored object saves the first state back byte for byte. */
static void check_dem(fsdem_dem_integrator integrator, int remove) {
    const fsdem_dem_desc desc = dem_desc(integrator);
    const char *path = "build/test_restart_dem.bin";
    fsdem_dem *a = dem_scene(&desc), *c = NULL, *f = NULL;
    unsigned char *A, *B, *C, *F, *R;
    size_t na, nb, nc, nf, nr;
    long long rebuilds;
    int mat;
    dem_run(a, 200);
    if (remove) {
        ck_assert_int_eq(fsdem_dem_remove_particle(a, 10), FSDEM_OK); /* lists stale, history carried by old_of */
        ck_assert_int_eq(fsdem_dem_set_dt(a, 8e-6), FSDEM_OK);
    }
    ck_assert_int_gt(fsdem_dem_get_stats(a).contacts + fsdem_dem_get_stats(a).wall_contacts, 0);
    A = save_dem(a, &na);
    ck_assert_int_eq(fsdem_dem_save(a, path), FSDEM_OK);
    rebuilds = fsdem_dem_get_stats(a).rebuilds;
    dem_run(a, 300);
    ck_assert_int_gt((int)(fsdem_dem_get_stats(a).rebuilds - rebuilds), 1);
    B = save_dem(a, &nb);

    ck_assert_int_eq(fsdem_dem_create(&desc, &c), FSDEM_OK);
    dem_setup(c, &mat); /* the SDF floor is taken from here */
    ck_assert_int_eq(fsdem_dem_restore_memory(c, A, na), FSDEM_OK);
    ck_assert_str_eq(fsdem_dem_last_error(c), "");
    R = save_dem(c, &nr);
    same_bytes(A, na, R, nr, "DEM save of the restored state");
    dem_run(c, 300);
    C = save_dem(c, &nc);
    same_bytes(B, nb, C, nc, "DEM continued from memory");

    ck_assert_int_eq(fsdem_dem_create(&desc, &f), FSDEM_OK);
    dem_setup(f, &mat);
    ck_assert_int_eq(fsdem_dem_restore(f, path), FSDEM_OK);
    dem_run(f, 300);
    F = save_dem(f, &nf);
    same_bytes(B, nb, F, nf, "DEM continued from a file");
    free(A);
    free(B);
    free(C);
    free(F);
    free(R);
    fsdem_dem_destroy(a);
    fsdem_dem_destroy(c);
    fsdem_dem_destroy(f);
}

START_TEST(dem_continues_bit_exact) { check_dem(FSDEM_DEM_INTEGRATOR_VERLET, 0); }
END_TEST

START_TEST(dem_predictor_corrector_continues_bit_exact) { check_dem(FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR, 1); }
END_TEST

/* ---- PIC ---- */

/* Disc as a callback (an SDF obstacle). */
static fsdem_real disc_sdf(void *user, fsdem_vec3 p, fsdem_vec3 *normal) {
    const fsdem_real dx = p.x - (fsdem_real)0.55, dy = p.y - (fsdem_real)0.12, r = (fsdem_real)sqrt(dx * dx + dy * dy);
    (void)user;
    *normal = r > 0 ? fsdem_v3(dx / r, dy / r, 0) : fsdem_v3(0, 1, 0);
    return r - (fsdem_real)0.08;
}

/* Dam break: 2D on a 30 x 15 grid, FLIP with a wedge (polygon) or APIC with the quadratic kernel,
   viscosity and a disc (SDF); 3D on 10 x 4 x 5 cells, FLIP with a cylinder. Reseeding tops up every
   interior cell to particles_per_cell. */
static fsdem_pic_desc pic_desc(int dim, int apic, double cell) {
    fsdem_pic_desc d = fsdem_pic_desc_default(dim);
    d.domain_max = fsdem_v3(1.0, dim == 3 ? 0.4 : 0.5, dim == 3 ? 0.5 : 0);
    d.cell_size = (fsdem_real)cell;
    d.min_particles_per_cell = d.particles_per_cell;
    d.jitter = (fsdem_real)0.5; /* seeds off the lattice: the reseeding (and its random stream) then works */
    if (apic) {
        d.transfer = FSDEM_PIC_TRANSFER_APIC;
        d.kernel = FSDEM_PIC_KERNEL_QUADRATIC;
        d.viscosity = 1e-3;
    }
    return d;
}

/* The obstacles of the scene (a user's setup adds them again before restoring: the SDF disc must be
   there, a polygon is replaced by the restore). */
static void pic_setup(fsdem_pic *s, int apic) {
    fsdem_vec3 tri[3];
    fsdem_pic_obstacle o;
    tri[0] = fsdem_v3(0.6, 0, 0);
    tri[1] = fsdem_v3(0.8, 0, 0);
    tri[2] = fsdem_v3(0.8, 0.12, 0);
    o = apic ? fsdem_pic_obstacle_sdf(disc_sdf, NULL) : fsdem_pic_obstacle_polygon(tri, 3);
    if (fsdem_pic_get_fields(s).dim == 3) o = fsdem_pic_obstacle_cylinder(fsdem_v3(0.6, 0, 0.1), fsdem_v3(0.6, 0.4, 0.1), 0.08);
    ck_assert_int_eq(fsdem_pic_add_obstacle(s, &o, NULL), FSDEM_OK);
}

static fsdem_pic *pic_scene(const fsdem_pic_desc *desc, int apic) {
    fsdem_pic *s = NULL;
    ck_assert_int_eq(fsdem_pic_create(desc, &s), FSDEM_OK);
    pic_setup(s, apic);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), desc->dim == 3 ? fsdem_v3(0.3, 0.4, 0.35) : fsdem_v3(0.3, 0.35, 0),
                                        fsdem_v3(0, 0, 0), NULL),
                     FSDEM_OK);
    return s;
}

/* `steps` steps of the adaptive dt, or of a fixed 4 ms; a force on the liquid now and then, which
   the coupling arrays keep. */
static void pic_run(fsdem_pic *s, int steps, int adaptive) {
    int k;
    for (k = 0; k < steps; ++k) {
        if (k % 5 == 0) ck_assert_int_eq(fsdem_pic_add_force(s, fsdem_v3(0.2, 0.1, 0.1), 0.05, fsdem_v3(0.5, 0, 0), NULL), FSDEM_OK);
        ck_assert_int_eq(adaptive ? fsdem_pic_step(s) : fsdem_pic_step_dt(s, (fsdem_real)0.004), FSDEM_OK);
    }
}

static void check_pic(int dim, int apic, int adaptive) {
    const fsdem_pic_desc desc = pic_desc(dim, apic, dim == 3 ? 0.1 : 1.0 / 30);
    const char *path = "build/test_restart_pic.bin";
    fsdem_pic *a = pic_scene(&desc, apic), *c = NULL, *f = NULL;
    unsigned char *A, *B, *C, *F, *R;
    size_t na, nb, nc, nf, nr;
    fsdem_pic_stats st;
    pic_run(a, 12, adaptive);
    A = save_pic(a, &na);
    ck_assert_int_eq(fsdem_pic_save(a, path), FSDEM_OK);
    pic_run(a, 12, adaptive);
    st = fsdem_pic_get_stats(a);
    ck_assert_msg(st.moved + st.removed > 0, "reseeding moved %lld, removed %lld", st.moved, st.removed);
    B = save_pic(a, &nb);

    ck_assert_int_eq(fsdem_pic_create(&desc, &c), FSDEM_OK);
    pic_setup(c, apic);
    ck_assert_int_eq(fsdem_pic_restore_memory(c, A, na), FSDEM_OK);
    R = save_pic(c, &nr);
    same_bytes(A, na, R, nr, "PIC save of the restored state");
    pic_run(c, 12, adaptive);
    C = save_pic(c, &nc);
    same_bytes(B, nb, C, nc, "PIC continued from memory");

    ck_assert_int_eq(fsdem_pic_create(&desc, &f), FSDEM_OK);
    if (apic) pic_setup(f, apic); /* a polygon or cylinder needs no setup: the restore brings it */
    ck_assert_int_eq(fsdem_pic_restore(f, path), FSDEM_OK);
    pic_run(f, 12, adaptive);
    F = save_pic(f, &nf);
    same_bytes(B, nb, F, nf, "PIC continued from a file");
    free(A);
    free(B);
    free(C);
    free(F);
    free(R);
    fsdem_pic_destroy(a);
    fsdem_pic_destroy(c);
    fsdem_pic_destroy(f);
}

START_TEST(pic_flip_continues_bit_exact) {
    check_pic(2, 0, 1);
    check_pic(2, 0, 0);
    check_pic(3, 0, 1);
    check_pic(3, 0, 0);
}
END_TEST

START_TEST(pic_apic_continues_bit_exact) {
    check_pic(2, 1, 1);
    check_pic(2, 1, 0);
}
END_TEST

/* ---- SWE ---- */

/* 2D dam break over a sloping bed on 40 x 24 cells, with Manning friction per cell, rain, an inflow
   hydrograph on the left, a point source with a series and a gauge. */
static fsdem_swe_desc swe_desc(void) {
    fsdem_swe_desc d = fsdem_swe_desc_default(2);
    d.nx = 40;
    d.ny = 24;
    d.x_max = 4;
    d.y_max = 2.4;
    d.manning = 0.02;
    d.boundary[FSDEM_SIDE_XMAX].type = FSDEM_SWE_BC_TRANSMISSIVE;
    return d;
}

static fsdem_swe *swe_scene(const fsdem_swe_desc *desc) {
    static const fsdem_real qt[3] = {0, 0.2, 1}, qv[3] = {0, 0.3, 0.1}, st[2] = {0, 0.5}, sv[2] = {0.02, -0.01};
    fsdem_swe *s = NULL;
    fsdem_real *bed = (fsdem_real *)malloc(sizeof(fsdem_real) * 40 * 24), *h = (fsdem_real *)malloc(sizeof(fsdem_real) * 40 * 24);
    fsdem_real *n = (fsdem_real *)malloc(sizeof(fsdem_real) * 40 * 24);
    fsdem_swe_boundary in;
    fsdem_swe_point_source src;
    int i, j;
    for (j = 0; j < 24; ++j)
        for (i = 0; i < 40; ++i) {
            bed[i + 40 * j] = (fsdem_real)(0.02 * i / 40.0 + 0.01 * (j % 3));
            h[i + 40 * j] = i < 15 ? (fsdem_real)0.4 : (fsdem_real)(i > 30 ? 0 : 0.05);
            n[i + 40 * j] = (fsdem_real)(0.01 + 0.0005 * (i % 7));
        }
    ck_assert_int_eq(fsdem_swe_create(desc, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_set_bed(s, bed), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_set_depth(s, h), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_set_manning(s, n), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_set_rain(s, 1e-4), FSDEM_OK);
    memset(&in, 0, sizeof in);
    in.type = FSDEM_SWE_BC_DISCHARGE;
    in.series_time = qt;
    in.series_value = qv;
    in.series_count = 3;
    ck_assert_int_eq(fsdem_swe_set_boundary(s, FSDEM_SIDE_XMIN, &in), FSDEM_OK);
    memset(&src, 0, sizeof src);
    src.x = 2.5;
    src.y = 1.1;
    src.series_time = st;
    src.series_value = sv;
    src.series_count = 2;
    ck_assert_int_eq(fsdem_swe_add_point_source(s, &src, NULL), FSDEM_OK);
    src.x = 3.5;
    src.discharge = 0.01;
    src.series_count = 0;
    src.series_time = src.series_value = NULL;
    ck_assert_int_eq(fsdem_swe_add_point_source(s, &src, &i), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_remove_point_source(s, i), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_add_gauge(s, 1.0, 1.0, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_add_force(s, fsdem_v3(0.5, 0.5, 0), 0.2, fsdem_v3(3, 1, 0), NULL), FSDEM_OK);
    free(bed);
    free(h);
    free(n);
    return s;
}

static void swe_run(fsdem_swe *s, int steps, int adaptive) {
    int k;
    for (k = 0; k < steps; ++k) ck_assert_int_eq(adaptive ? fsdem_swe_step(s) : fsdem_swe_step_dt(s, (fsdem_real)0.008), FSDEM_OK);
}

static void check_swe(int adaptive) {
    const fsdem_swe_desc desc = swe_desc();
    const char *path = "build/test_restart_swe.bin";
    fsdem_swe *a = swe_scene(&desc), *c = NULL, *f = NULL;
    unsigned char *A, *B, *C, *F, *R;
    size_t na, nb, nc, nf, nr;
    swe_run(a, 30, adaptive);
    A = save_swe(a, &na);
    ck_assert_int_eq(fsdem_swe_save(a, path), FSDEM_OK);
    swe_run(a, 30, adaptive);
    B = save_swe(a, &nb);

    ck_assert_int_eq(fsdem_swe_create(&desc, &c), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_restore_memory(c, A, na), FSDEM_OK);
    R = save_swe(c, &nr);
    same_bytes(A, na, R, nr, "SWE save of the restored state");
    swe_run(c, 30, adaptive);
    C = save_swe(c, &nc);
    same_bytes(B, nb, C, nc, "SWE continued from memory");

    /* into the object the scene was set up in (its sources and series are replaced) */
    f = swe_scene(&desc);
    ck_assert_int_eq(fsdem_swe_restore(f, path), FSDEM_OK);
    swe_run(f, 30, adaptive);
    F = save_swe(f, &nf);
    same_bytes(B, nb, F, nf, "SWE continued from a file");
    ck_assert(fsdem_swe_volume(f) == fsdem_swe_volume(a));
    free(A);
    free(B);
    free(C);
    free(F);
    free(R);
    fsdem_swe_destroy(a);
    fsdem_swe_destroy(c);
    fsdem_swe_destroy(f);
}

START_TEST(swe_continues_bit_exact) {
    check_swe(1);
    check_swe(0);
}
END_TEST

/* ---- SWE-DEM ---- */

typedef struct world {
    fsdem_swe *swe;
    fsdem_dem *dem;
    fsdem_swe_dem *cpl;
} world;

/* A light sphere (r = 5 cm, 500 kg/m^3) dropped into a 1D channel of 0.3 m of water flowing at
   0.2 m/s, with heave damping: it bobs and drifts. `bare`: the solvers are only created (the
   restore brings their state). */
static world world_new(int bare) {
    world w;
    fsdem_swe_desc sd = fsdem_swe_desc_default(1);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_swe_dem_desc cd = fsdem_swe_dem_desc_default();
    fsdem_real h[40], v[40];
    int k, mat;
    for (k = 0; k < 40; ++k) {
        h[k] = (fsdem_real)0.3;
        v[k] = (fsdem_real)0.2;
    }
    sd.nx = 40;
    sd.x_max = 2;
    ck_assert_int_eq(fsdem_swe_create(&sd, &w.swe), FSDEM_OK);
    dd.domain_min = fsdem_v3(0, -1, -1);
    dd.domain_max = fsdem_v3(2, 1, 2);
    dd.dt = 1e-4;
    ck_assert_int_eq(fsdem_dem_create(&dd, &w.dem), FSDEM_OK);
    if (!bare) {
        fsdem_dem_material m = fsdem_dem_material_default();
        fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
        ck_assert_int_eq(fsdem_swe_set_depth(w.swe, h), FSDEM_OK);
        ck_assert_int_eq(fsdem_swe_set_velocity(w.swe, v, NULL), FSDEM_OK);
        m.density = 500;
        ck_assert_int_eq(fsdem_dem_add_material(w.dem, &m, &mat), FSDEM_OK);
        p.position = fsdem_v3(0.5, 0, 0.32);
        p.radius = 0.05;
        p.material = mat;
        ck_assert_int_eq(fsdem_dem_add_particle(w.dem, &p, NULL), FSDEM_OK);
    }
    cd.swe = w.swe;
    cd.dem = w.dem;
    cd.heave_damping = 0.1;
    ck_assert_int_eq(fsdem_swe_dem_create(&cd, &w.cpl), FSDEM_OK);
    return w;
}

static void world_free(world *w) {
    fsdem_swe_dem_destroy(w->cpl);
    fsdem_dem_destroy(w->dem);
    fsdem_swe_destroy(w->swe);
}

static void world_run(world *w, int steps, int adaptive) {
    int k;
    for (k = 0; k < steps; ++k)
        ck_assert_int_eq(adaptive ? fsdem_swe_dem_step(w->cpl) : fsdem_swe_dem_step_dt(w->cpl, (fsdem_real)0.01), FSDEM_OK);
}

static void check_swe_dem(int adaptive) {
    const char *path = "build/test_restart_swe_dem.bin";
    world a = world_new(0), c = world_new(1), f = world_new(1);
    unsigned char *A, *B, *C, *F, *R;
    size_t na, nb, nc, nf, nr;
    fsdem_swe_dem_force force;
    world_run(&a, 15, adaptive);
    ck_assert_int_eq(fsdem_swe_dem_get_force(a.cpl, 0, &force), FSDEM_OK);
    ck_assert_int_eq(force.wet, 1);
    A = save_swe_dem(a.cpl, &na);
    ck_assert_int_eq(fsdem_swe_dem_save(a.cpl, path), FSDEM_OK);
    world_run(&a, 15, adaptive);
    B = save_swe_dem(a.cpl, &nb);

    ck_assert_int_eq(fsdem_swe_dem_restore_memory(c.cpl, A, na), FSDEM_OK);
    R = save_swe_dem(c.cpl, &nr);
    same_bytes(A, na, R, nr, "SWE-DEM save of the restored state");
    world_run(&c, 15, adaptive);
    C = save_swe_dem(c.cpl, &nc);
    same_bytes(B, nb, C, nc, "SWE-DEM continued from memory");
    ck_assert(fsdem_dem_get_particles(c.dem).position[0].z == fsdem_dem_get_particles(a.dem).position[0].z);

    ck_assert_int_eq(fsdem_swe_dem_restore(f.cpl, path), FSDEM_OK);
    world_run(&f, 15, adaptive);
    F = save_swe_dem(f.cpl, &nf);
    same_bytes(B, nb, F, nf, "SWE-DEM continued from a file");
    free(A);
    free(B);
    free(C);
    free(F);
    free(R);
    world_free(&a);
    world_free(&c);
    world_free(&f);
}

START_TEST(swe_dem_continues_bit_exact) {
    check_swe_dem(1);
    check_swe_dem(0);
}
END_TEST

/* A coupler's save refused by one of its solvers (the water's grid differs) names that solver and
   leaves all three objects as they were. */
START_TEST(swe_dem_refusal_names_the_solver) {
    world a = world_new(0), c = world_new(1);
    fsdem_swe_desc sd = fsdem_swe_desc_default(1);
    fsdem_swe *coarse = NULL;
    fsdem_swe_dem *cpl = NULL;
    fsdem_swe_dem_desc cd = fsdem_swe_dem_desc_default();
    unsigned char *A, *before, *after;
    size_t na, n0, n1;
    world_run(&a, 3, 1);
    A = save_swe_dem(a.cpl, &na);
    sd.nx = 20;
    sd.x_max = 2;
    ck_assert_int_eq(fsdem_swe_create(&sd, &coarse), FSDEM_OK);
    cd.swe = coarse;
    cd.dem = c.dem;
    cd.heave_damping = 0.1;
    fsdem_swe_dem_destroy(c.cpl); /* one coupler per DEM: its claim on the DEM's loads goes with it */
    c.cpl = NULL;
    ck_assert_int_eq(fsdem_swe_dem_create(&cd, &cpl), FSDEM_OK);
    before = save_swe_dem(cpl, &n0);
    ck_assert_int_eq(fsdem_swe_dem_restore_memory(cpl, A, na), FSDEM_ERR_INVALID_ARG);
    ck_assert_str_eq(fsdem_swe_dem_last_error(cpl),
                     "fsdem_swe_dem_restore_memory: shallow water: the grid has 40 x 1 cells in the save and 20 x 1 in "
                     "the object (create the object from the desc it was saved with)");
    after = save_swe_dem(cpl, &n1);
    same_bytes(before, n0, after, n1, "coupler after a refused restore");
    free(A);
    free(before);
    free(after);
    fsdem_swe_dem_destroy(cpl);
    fsdem_swe_destroy(coarse);
    world_free(&a);
    world_free(&c);
}
END_TEST

/* ---- bad data ---- */

/* Restoring `bad` (n bytes) into d fails with `code` and a message holding `words`, and leaves d
   exactly as `before` (its save before the attempt). */
static void refused_dem(fsdem_dem *d, const unsigned char *bad, size_t n, fsdem_result code, const char *words,
                        const unsigned char *before, size_t nbefore) {
    unsigned char *after;
    size_t nafter;
    ck_assert_int_eq(fsdem_dem_restore_memory(d, bad, n), code);
    ck_assert_msg(strstr(fsdem_dem_last_error(d), words) != NULL, "message '%s' lacks '%s'", fsdem_dem_last_error(d), words);
    ck_assert_msg(strncmp(fsdem_dem_last_error(d), "fsdem_dem_restore_memory: ", 26) == 0, "message '%s'",
                  fsdem_dem_last_error(d));
    after = save_dem(d, &nafter);
    same_bytes(before, nbefore, after, nafter, words);
    free(after);
}

/* A copy of a save with the unsigned int at `offset` replaced. */
static unsigned char *patched(const unsigned char *a, size_t n, size_t offset, unsigned int value) {
    unsigned char *b = (unsigned char *)malloc(n);
    memcpy(b, a, n);
    memcpy(b + offset, &value, sizeof value);
    return b;
}

/* The FNV-1a checksum of a save recomputed after an edit (so the edit reaches the payload checks). */
static void reseal(unsigned char *a, size_t n) {
    unsigned long long h = 0xcbf29ce484222325ull;
    size_t k;
    for (k = 0; k < n; ++k)
        if (k < 56 || k >= 64) h = (h ^ a[k]) * 0x100000001b3ull;
    memcpy(a + 56, &h, 8);
}

START_TEST(bad_data_is_refused_and_changes_nothing) {
    const fsdem_dem_desc desc = dem_desc(FSDEM_DEM_INTEGRATOR_VERLET);
    fsdem_dem_desc d2 = fsdem_dem_desc_default(2), other = desc;
    const fsdem_pic_desc pd = pic_desc(2, 0, 1.0 / 30), coarse = pic_desc(2, 0, 1.0 / 15);
    fsdem_dem *d = dem_scene(&desc), *e = NULL, *bare = NULL, *flat = NULL, *hooke = NULL;
    fsdem_pic *s = pic_scene(&pd, 0), *s2 = pic_scene(&coarse, 0);
    unsigned char *A, *E, *P, *P2, *bad, small[16];
    size_t na, ne, np, np2, need = 0;
    int mat;
    dem_run(d, 50);
    A = save_dem(d, &na);
    ck_assert_int_eq(fsdem_dem_create(&desc, &e), FSDEM_OK);
    dem_setup(e, &mat);
    E = save_dem(e, &ne);

    /* truncated, one flipped byte, magic, version, precision, byte order */
    refused_dem(e, A, na - 1, FSDEM_ERR_INVALID_ARG, "truncated", E, ne);
    refused_dem(e, A, 40, FSDEM_ERR_INVALID_ARG, "header", E, ne);
    bad = (unsigned char *)malloc(na);
    memcpy(bad, A, na);
    bad[na / 2] ^= 4;
    refused_dem(e, bad, na, FSDEM_ERR_INVALID_ARG, "checksum", E, ne);
    bad[na / 2] ^= 4;
    bad[0] = 'X';
    refused_dem(e, bad, na, FSDEM_ERR_INVALID_ARG, "magic", E, ne);
    free(bad);
    bad = patched(A, na, 8, 99);
    refused_dem(e, bad, na, FSDEM_ERR_INVALID_ARG, "version", E, ne);
    free(bad);
    bad = patched(A, na, 16, sizeof(fsdem_real) == 8 ? 4 : 8);
    refused_dem(e, bad, na, FSDEM_ERR_INVALID_ARG, "precision", E, ne);
    free(bad);
    bad = patched(A, na, 12, 0x04030201u);
    refused_dem(e, bad, na, FSDEM_ERR_INVALID_ARG, "byte order", E, ne);
    free(bad);
    /* dimension: a 2D save into a 3D object, and a patched header */
    d2.domain_min = fsdem_v3(-1, -1, 0);
    ck_assert_int_eq(fsdem_dem_create(&d2, &flat), FSDEM_OK);
    bad = save_dem(flat, &need);
    refused_dem(e, bad, need, FSDEM_ERR_INVALID_ARG, "dimension", E, ne);
    free(bad);
    bad = patched(A, na, 24, 2);
    refused_dem(e, bad, na, FSDEM_ERR_INVALID_ARG, "dimension", E, ne);
    free(bad);
    /* kind: a PIC save into a DEM; a PIC save into a PIC of another grid */
    P = save_pic(s, &np);
    refused_dem(e, P, np, FSDEM_ERR_INVALID_ARG, "fsdem_pic", E, ne);
    P2 = save_pic(s2, &np2);
    ck_assert_int_eq(fsdem_pic_restore_memory(s2, P, np), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(fsdem_pic_last_error(s2), "the grid has 30 x 15 x 1 cells in the save and 15 x ") != NULL, "%s",
                  fsdem_pic_last_error(s2));
    bad = save_pic(s2, &need);
    same_bytes(P2, np2, bad, need, "PIC after a refused restore");
    free(bad);
    /* a desc that differs; data corrupted behind a valid checksum; an SDF wall missing */
    other.law = FSDEM_DEM_LAW_LINEAR;
    other.linear_dx = 0.001;
    ck_assert_int_eq(fsdem_dem_create(&other, &hooke), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_restore_memory(hooke, A, na), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(fsdem_dem_last_error(hooke), "desc.law is 1 in the save and 0 in the object") != NULL, "%s",
                  fsdem_dem_last_error(hooke));
    bad = (unsigned char *)malloc(na);
    memcpy(bad, A, na);
    bad[na - 1] ^= 1;
    reseal(bad, na);
    refused_dem(e, bad, na, FSDEM_ERR_INVALID_ARG, "section 'DEM.' expected", E, ne);
    free(bad);
    ck_assert_int_eq(fsdem_dem_create(&desc, &bare), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_restore_memory(bare, A, na), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(fsdem_dem_last_error(bare), "wall 0 is an SDF wall in the save") != NULL, "%s",
                  fsdem_dem_last_error(bare));
    /* files and buffers */
    ck_assert_int_eq(fsdem_dem_restore(e, "build/no/such/file.bin"), FSDEM_ERR_IO);
    ck_assert_ptr_nonnull(strstr(fsdem_dem_last_error(e), "cannot open"));
    ck_assert_int_eq(fsdem_dem_save(d, "build/no/such/dir/x.bin"), FSDEM_ERR_IO);
    ck_assert_int_eq(fsdem_dem_save_memory(d, small, sizeof small, &need), FSDEM_ERR_INVALID_ARG);
    ck_assert_uint_eq(need, na);
    ck_assert_int_eq(fsdem_dem_save_memory(d, NULL, 0, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_dem_restore_memory(NULL, A, na), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_dem_restore_memory(e, NULL, na), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_dem_save(d, NULL), FSDEM_ERR_INVALID_ARG);
    /* after all that, e still takes the save */
    ck_assert_int_eq(fsdem_dem_restore_memory(e, A, na), FSDEM_OK);
    bad = save_dem(e, &need);
    same_bytes(A, na, bad, need, "DEM restored after refusals");
    free(bad);
    free(A);
    free(E);
    free(P);
    free(P2);
    fsdem_dem_destroy(d);
    fsdem_dem_destroy(e);
    fsdem_dem_destroy(bare);
    fsdem_dem_destroy(flat);
    fsdem_dem_destroy(hooke);
    fsdem_pic_destroy(s);
    fsdem_pic_destroy(s2);
}
END_TEST

/* Restores `data` into `obj` with an allocation budget of 0, 1, 2, ... until it succeeds: every
   attempt that runs out of memory says so and leaves the object as it was. */
#define OOM_LOOP(X, obj, data, n)                                                                   \
    do {                                                                                            \
        int failures = 0, done = 0;                                                                 \
        while (!done && failures < 200) {                                                           \
            unsigned char *before, *after;                                                          \
            size_t n0, n1;                                                                          \
            fsdem_result r;                                                                         \
            before = save_##X(obj, &n0);                                                            \
            b.left = failures;                                                                      \
            r = fsdem_##X##_restore_memory(obj, data, n);                                           \
            b.left = 1L << 30;                                                                      \
            if (r == FSDEM_OK) done = 1;                                                            \
            else {                                                                                  \
                ck_assert_int_eq(r, FSDEM_ERR_OUT_OF_MEMORY);                                       \
                after = save_##X(obj, &n1);                                                         \
                same_bytes(before, n0, after, n1, #X " after running out of memory");               \
                free(after);                                                                        \
                failures++;                                                                         \
            }                                                                                       \
            free(before);                                                                           \
        }                                                                                           \
        ck_assert_msg(done && failures > 1, #X ": %d failures", failures);                          \
    } while (0)

/* Out of memory at any allocation of a restore (DEM, PIC, SWE) leaves the object as it was. */
START_TEST(out_of_memory_changes_nothing) {
    budget b = {1L << 30};
    fsdem_dem_desc dd = dem_desc(FSDEM_DEM_INTEGRATOR_VERLET);
    fsdem_pic_desc pd = pic_desc(2, 0, 1.0 / 30);
    fsdem_swe_desc sd = swe_desc();
    fsdem_dem *d = dem_scene(&dd), *e = NULL;
    fsdem_pic *s = pic_scene(&pd, 0), *t = NULL;
    fsdem_swe *w = swe_scene(&sd), *x = NULL;
    unsigned char *A, *P, *W, *after;
    size_t na, np, nw, n1;
    int mat;
    dem_run(d, 50);
    pic_run(s, 3, 1);
    swe_run(w, 3, 1);
    A = save_dem(d, &na);
    P = save_pic(s, &np);
    W = save_swe(w, &nw);
    dd.allocator.alloc = pd.allocator.alloc = sd.allocator.alloc = budget_alloc;
    dd.allocator.free = pd.allocator.free = sd.allocator.free = budget_free;
    dd.allocator.user = pd.allocator.user = sd.allocator.user = &b;
    ck_assert_int_eq(fsdem_dem_create(&dd, &e), FSDEM_OK);
    dem_setup(e, &mat);
    ck_assert_int_eq(fsdem_pic_create(&pd, &t), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_create(&sd, &x), FSDEM_OK);
    OOM_LOOP(dem, e, A, na);
    OOM_LOOP(pic, t, P, np);
    OOM_LOOP(swe, x, W, nw);
    after = save_swe(x, &n1);
    same_bytes(W, nw, after, n1, "SWE restored at last");
    free(after);
    free(A);
    free(P);
    free(W);
    fsdem_dem_destroy(d);
    fsdem_dem_destroy(e);
    fsdem_pic_destroy(s);
    fsdem_pic_destroy(t);
    fsdem_swe_destroy(w);
    fsdem_swe_destroy(x);
}
END_TEST

/* A gauge file open on the object blocks a restore (its columns could not follow); once closed the
   restore goes through. */
START_TEST(swe_gauge_file_blocks_restore) {
    const fsdem_swe_desc desc = swe_desc();
    fsdem_swe *s = swe_scene(&desc);
    unsigned char *A;
    size_t na;
    A = save_swe(s, &na);
    ck_assert_int_eq(fsdem_swe_gauges_open(s, "build/test_restart_gauges.csv", 0.1), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_restore_memory(s, A, na), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(fsdem_swe_last_error(s), "gauge file"));
    ck_assert_int_eq(fsdem_swe_gauges_close(s), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_restore_memory(s, A, na), FSDEM_OK);
    free(A);
    fsdem_swe_destroy(s);
}
END_TEST

/* ---- MPS ---------------------------------------------------------------------------------------- */

/* 2D dam break in a tank with a box obstacle on its floor (r0 = 1 cm, 300 fluid particles): the
   column collapses, the surface and the neighbourhoods change every step. */
static fsdem_mps_desc mps_desc(void) {
    fsdem_mps_desc d = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    d.r0 = 0.01;
    d.domain_min = fsdem_v3(-0.1, -0.1, 0);
    d.domain_max = fsdem_v3(0.5, 0.4, 0);
    return d;
}

static void mps_setup(fsdem_mps *m) {
    ck_assert_int_eq(fsdem_mps_add_box_walls(m, fsdem_v3(0, 0, 0), fsdem_v3(0.4, 0.3, 0), 1u << FSDEM_SIDE_YMAX, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_add_box_obstacle(m, fsdem_v3(0.25, 0, 0), fsdem_v3(0.3, 0.05, 0), NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_fill_box(m, fsdem_v3(0, 0, 0), fsdem_v3(0.1, 0.3, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
}

/* Both schemes (_i: fsdem_mps_scheme); the explicit one's densities and sound speed are state. */
START_TEST(mps_continues_bit_exact) {
    fsdem_mps_desc desc = mps_desc();
    const char *path = "build/test_restart_mps.bin";
    fsdem_mps *a = NULL, *c = NULL, *f = NULL, *other = NULL;
    fsdem_mps_desc od = desc;
    unsigned char *A, *B, *C, *F, *R;
    size_t na, nb, nc, nf, nr;
    desc.scheme = (fsdem_mps_scheme)_i;
    od = desc;
    ck_assert_int_eq(fsdem_mps_create(&desc, &a), FSDEM_OK);
    mps_setup(a);
    ck_assert_int_eq(fsdem_mps_advance(a, 0.03, NULL), FSDEM_OK);
    A = save_mps(a, &na);
    ck_assert_int_eq(fsdem_mps_save(a, path), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_advance(a, 0.03, NULL), FSDEM_OK);
    B = save_mps(a, &nb);

    /* into an empty object of the same desc: nothing to add again */
    ck_assert_int_eq(fsdem_mps_create(&desc, &c), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_restore_memory(c, A, na), FSDEM_OK);
    R = save_mps(c, &nr);
    same_bytes(A, na, R, nr, "MPS save of the restored state");
    ck_assert_int_eq(fsdem_mps_advance(c, 0.03, NULL), FSDEM_OK);
    C = save_mps(c, &nc);
    same_bytes(B, nb, C, nc, "MPS continued from memory");

    /* into an object that already holds particles (others are replaced) */
    ck_assert_int_eq(fsdem_mps_create(&desc, &f), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_fill_box(f, fsdem_v3(0, 0, 0), fsdem_v3(0.3, 0.3, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_restore(f, path), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_advance(f, 0.03, NULL), FSDEM_OK);
    F = save_mps(f, &nf);
    same_bytes(B, nb, F, nf, "MPS continued from a file");

    /* another desc is refused by name, and the object is unchanged */
    od.gamma = 0.02;
    ck_assert_int_eq(fsdem_mps_create(&od, &other), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_restore_memory(other, A, na), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(fsdem_mps_last_error(other), "desc.gamma"));
    ck_assert_int_eq(fsdem_mps_get_particles(other).count, 0);
    free(A);
    free(B);
    free(C);
    free(F);
    free(R);
    fsdem_mps_destroy(a);
    fsdem_mps_destroy(c);
    fsdem_mps_destroy(f);
    fsdem_mps_destroy(other);
}
END_TEST

/* ---- MPS-DEM ---- */

typedef struct mps_world {
    fsdem_mps *mps;
    fsdem_dem *dem;
    fsdem_mps_dem *cpl;
} mps_world;

/* The MPS tank of mps_continues_bit_exact (Model B) with a few sinking grains in its column;
   `bare`: the solvers are only created (the restore brings their state). */
static mps_world mps_world_new(int bare) {
    mps_world w;
    fsdem_mps_desc md = mps_desc();
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_mps_dem_desc cd = fsdem_mps_dem_desc_default();
    md.model = FSDEM_MPS_MODEL_B;
    ck_assert_int_eq(fsdem_mps_create(&md, &w.mps), FSDEM_OK);
    dd.domain_min = fsdem_v3(md.domain_min.x, md.domain_min.y, -1);
    dd.domain_max = fsdem_v3(md.domain_max.x, md.domain_max.y, 1);
    dd.gravity = md.gravity;
    dd.dt = 2e-5;
    ck_assert_int_eq(fsdem_dem_create(&dd, &w.dem), FSDEM_OK);
    if (!bare) {
        fsdem_dem_material m = fsdem_dem_material_default();
        int mat, k;
        mps_setup(w.mps);
        ck_assert_int_eq(fsdem_dem_add_material(w.dem, &m, &mat), FSDEM_OK);
        for (k = 0; k < 6; ++k) {
            fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
            p.position = fsdem_v3((fsdem_real)(0.02 + 0.012 * k), (fsdem_real)(0.2 - 0.01 * (k % 2)), 0);
            p.radius = 0.003f;
            p.material = mat;
            ck_assert_int_eq(fsdem_dem_add_particle(w.dem, &p, NULL), FSDEM_OK);
        }
    }
    cd.mps = w.mps;
    cd.dem = w.dem;
    ck_assert_int_eq(fsdem_mps_dem_create(&cd, &w.cpl), FSDEM_OK);
    return w;
}

static void mps_world_free(mps_world *w) {
    fsdem_mps_dem_destroy(w->cpl);
    fsdem_dem_destroy(w->dem);
    fsdem_mps_destroy(w->mps);
}

START_TEST(mps_dem_continues_bit_exact) {
    const char *path = "build/test_restart_mps_dem.bin";
    mps_world a = mps_world_new(0), c = mps_world_new(1), f = mps_world_new(1);
    unsigned char *A, *B, *C, *F, *R;
    size_t na, nb, nc, nf, nr;
    fsdem_mps_dem_force fa, fc;
    ck_assert_int_eq(fsdem_mps_dem_advance(a.cpl, 0.02f, NULL), FSDEM_OK);
    A = save_mps_dem(a.cpl, &na);
    ck_assert_int_eq(fsdem_mps_dem_save(a.cpl, path), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_dem_get_force(a.cpl, 3, &fa), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_dem_advance(a.cpl, 0.02f, NULL), FSDEM_OK);
    B = save_mps_dem(a.cpl, &nb);

    ck_assert_int_eq(fsdem_mps_dem_restore_memory(c.cpl, A, na), FSDEM_OK);
    R = save_mps_dem(c.cpl, &nr);
    same_bytes(A, na, R, nr, "MPS-DEM save of the restored state");
    ck_assert_int_eq(fsdem_mps_dem_get_force(c.cpl, 3, &fc), FSDEM_OK);
    ck_assert(fc.drag.y == fa.drag.y && fc.porosity == fa.porosity && fc.wet == fa.wet);
    ck_assert_int_eq(fsdem_mps_dem_advance(c.cpl, 0.02f, NULL), FSDEM_OK);
    C = save_mps_dem(c.cpl, &nc);
    same_bytes(B, nb, C, nc, "MPS-DEM continued from memory");
    ck_assert(fsdem_dem_get_particles(c.dem).position[2].y == fsdem_dem_get_particles(a.dem).position[2].y);

    ck_assert_int_eq(fsdem_mps_dem_restore(f.cpl, path), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_dem_advance(f.cpl, 0.02f, NULL), FSDEM_OK);
    F = save_mps_dem(f.cpl, &nf);
    same_bytes(B, nb, F, nf, "MPS-DEM continued from a file");
    free(A);
    free(B);
    free(C);
    free(F);
    free(R);
    mps_world_free(&a);
    mps_world_free(&c);
    mps_world_free(&f);
}
END_TEST

/* ---- PIC-DEM ---- */

typedef struct pic_world {
    fsdem_pic *pic;
    fsdem_dem *dem;
    fsdem_pic_dem *cpl;
} pic_world;

/* A water tank with two discs, a light one rising and a heavy one sinking onto the floor (contacts,
   Eq. 20); `bare`: the solvers are only created (the restore brings their state). */
static pic_world pic_world_new(int bare) {
    pic_world w;
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_pic_dem_desc cd = fsdem_pic_dem_desc_default();
    pd.cell_size = 0.01f;
    pd.domain_max = fsdem_v3(0.3f, 0.3f, 0);
    pd.viscosity = 1e-4f;
    pd.dt_max = 2e-3f;
    ck_assert_int_eq(fsdem_pic_create(&pd, &w.pic), FSDEM_OK);
    dd.domain_min = fsdem_v3(0, 0, -1);
    dd.domain_max = fsdem_v3(0.3f, 0.3f, 1);
    dd.contact_offset = 0.02f;
    dd.integrator = FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR;
    dd.dt = 1e-4f;
    ck_assert_int_eq(fsdem_dem_create(&dd, &w.dem), FSDEM_OK);
    if (!bare) {
        fsdem_dem_material light = fsdem_dem_material_default(), heavy = fsdem_dem_material_default();
        fsdem_dem_wall_desc floor = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 1, 0), 0);
        fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
        int ml, mh;
        light.density = 600;
        heavy.density = 2500;
        ck_assert_int_eq(fsdem_dem_add_material(w.dem, &light, &ml), FSDEM_OK);
        ck_assert_int_eq(fsdem_dem_add_material(w.dem, &heavy, &mh), FSDEM_OK);
        ck_assert_int_eq(fsdem_dem_add_wall(w.dem, &floor, NULL), FSDEM_OK);
        p.radius = 0.03f;
        p.material = ml;
        p.position = fsdem_v3(0.1f, 0.1f, 0);
        ck_assert_int_eq(fsdem_dem_add_particle(w.dem, &p, NULL), FSDEM_OK);
        p.material = mh;
        p.position = fsdem_v3(0.2f, 0.06f, 0);
        ck_assert_int_eq(fsdem_dem_add_particle(w.dem, &p, NULL), FSDEM_OK);
        ck_assert_int_eq(fsdem_pic_fill_box(w.pic, fsdem_v3(0, 0, 0), fsdem_v3(0.3f, 0.22f, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
    }
    cd.pic = w.pic;
    cd.dem = w.dem;
    ck_assert_int_eq(fsdem_pic_dem_create(&cd, &w.cpl), FSDEM_OK);
    return w;
}

static void pic_world_free(pic_world *w) {
    fsdem_pic_dem_destroy(w->cpl);
    fsdem_dem_destroy(w->dem);
    fsdem_pic_destroy(w->pic);
}

START_TEST(pic_dem_continues_bit_exact) {
    const char *path = "build/test_restart_pic_dem.bin";
    pic_world a = pic_world_new(0), c = pic_world_new(1), f = pic_world_new(1);
    unsigned char *A, *B, *C, *F, *R;
    size_t na, nb, nc, nf, nr;
    fsdem_pic_dem_force ba, bc;
    ck_assert_int_eq(fsdem_pic_dem_advance(a.cpl, 0.03f, NULL), FSDEM_OK);
    A = save_pic_dem(a.cpl, &na);
    ck_assert_int_eq(fsdem_pic_dem_save(a.cpl, path), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_dem_get_force(a.cpl, 1, &ba), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_dem_advance(a.cpl, 0.03f, NULL), FSDEM_OK);
    B = save_pic_dem(a.cpl, &nb);

    ck_assert_int_eq(fsdem_pic_dem_restore_memory(c.cpl, A, na), FSDEM_OK);
    R = save_pic_dem(c.cpl, &nr);
    same_bytes(A, na, R, nr, "PIC-DEM save of the restored state");
    ck_assert_int_eq(fsdem_pic_dem_get_force(c.cpl, 1, &bc), FSDEM_OK);
    ck_assert(bc.pressure_force.y == ba.pressure_force.y && bc.volume == ba.volume);
    ck_assert_int_eq(fsdem_pic_dem_advance(c.cpl, 0.03f, NULL), FSDEM_OK);
    C = save_pic_dem(c.cpl, &nc);
    same_bytes(B, nb, C, nc, "PIC-DEM continued from memory");
    ck_assert(fsdem_dem_get_particles(c.dem).position[0].y == fsdem_dem_get_particles(a.dem).position[0].y);

    ck_assert_int_eq(fsdem_pic_dem_restore(f.cpl, path), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_dem_advance(f.cpl, 0.03f, NULL), FSDEM_OK);
    F = save_pic_dem(f.cpl, &nf);
    same_bytes(B, nb, F, nf, "PIC-DEM continued from a file");
    free(A);
    free(B);
    free(C);
    free(F);
    free(R);
    pic_world_free(&a);
    pic_world_free(&c);
    pic_world_free(&f);
}
END_TEST

/* Issue 23: a directory opens and seeks on Linux, and ftell gave its "length" as LONG_MAX: every
   restore then asked the allocator for 2^63 - 1 bytes and answered FSDEM_ERR_OUT_OF_MEMORY. It is an
   I/O error naming the path, and the object is left as it was (it still saves the same bytes). */
static void refuses_directory(fsdem_result got, const char *message) {
    ck_assert_int_eq(got, FSDEM_ERR_IO);
    ck_assert_ptr_nonnull(strstr(message, "'build'"));
}

START_TEST(restore_from_a_directory_is_an_io_error) {
    fsdem_dem_desc dd = dem_desc(FSDEM_DEM_INTEGRATOR_VERLET);
    fsdem_pic_desc pd = pic_desc(2, 0, 0.05);
    fsdem_swe_desc sd = swe_desc();
    fsdem_mps_desc md = mps_desc();
    fsdem_dem *dem = dem_scene(&dd);
    fsdem_pic *pic = pic_scene(&pd, 0);
    fsdem_swe *swe = swe_scene(&sd);
    fsdem_mps *mps = NULL;
    world w = world_new(0);
    mps_world mw = mps_world_new(0);
    pic_world pw = pic_world_new(0);
    size_t before = 0, after = 0;
    unsigned char *a, *b;
    ck_assert_int_eq(fsdem_mps_create(&md, &mps), FSDEM_OK);
    mps_setup(mps);
    ck_assert_int_eq(fsdem_dem_save_memory(dem, NULL, 0, &before), FSDEM_OK);
    a = (unsigned char *)malloc(before);
    ck_assert_int_eq(fsdem_dem_save_memory(dem, a, before, &before), FSDEM_OK);
    refuses_directory(fsdem_dem_restore(dem, "build"), fsdem_dem_last_error(dem));
    ck_assert_int_eq(fsdem_dem_save_memory(dem, NULL, 0, &after), FSDEM_OK);
    b = (unsigned char *)malloc(after);
    ck_assert_int_eq(fsdem_dem_save_memory(dem, b, after, &after), FSDEM_OK);
    same_bytes(a, before, b, after, "DEM after a refused restore");
    refuses_directory(fsdem_pic_restore(pic, "build"), fsdem_pic_last_error(pic));
    refuses_directory(fsdem_swe_restore(swe, "build"), fsdem_swe_last_error(swe));
    refuses_directory(fsdem_mps_restore(mps, "build"), fsdem_mps_last_error(mps));
    refuses_directory(fsdem_swe_dem_restore(w.cpl, "build"), fsdem_swe_dem_last_error(w.cpl));
    refuses_directory(fsdem_mps_dem_restore(mw.cpl, "build"), fsdem_mps_dem_last_error(mw.cpl));
    refuses_directory(fsdem_pic_dem_restore(pw.cpl, "build"), fsdem_pic_dem_last_error(pw.cpl));
    free(a);
    free(b);
    fsdem_dem_destroy(dem);
    fsdem_pic_destroy(pic);
    fsdem_swe_destroy(swe);
    fsdem_mps_destroy(mps);
    world_free(&w);
    mps_world_free(&mw);
    pic_world_free(&pw);
}
END_TEST

Suite *restart_suite(void) {
    Suite *s = suite_create("restart");
    TCase *tc = tcase_create("restart");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, dem_continues_bit_exact);
    tcase_add_test(tc, dem_predictor_corrector_continues_bit_exact);
    tcase_add_test(tc, pic_flip_continues_bit_exact);
    tcase_add_test(tc, pic_apic_continues_bit_exact);
    tcase_add_test(tc, swe_continues_bit_exact);
    tcase_add_test(tc, swe_dem_continues_bit_exact);
    tcase_add_test(tc, swe_dem_refusal_names_the_solver);
    tcase_add_loop_test(tc, mps_continues_bit_exact, 0, 2);
    tcase_add_test(tc, mps_dem_continues_bit_exact);
    tcase_add_test(tc, pic_dem_continues_bit_exact);
    tcase_add_test(tc, bad_data_is_refused_and_changes_nothing);
    tcase_add_test(tc, out_of_memory_changes_nothing);
    tcase_add_test(tc, swe_gauge_file_blocks_restore);
    tcase_add_test(tc, restore_from_a_directory_is_an_io_error);
    suite_add_tcase(s, tc);
    return s;
}
