/* What a hostile user found at main 25f1947 (issue 23 §5): frees of the wrong size and silent
   out-of-memory results, values that were accepted and came back later as NaN or nonsense, a drag
   law that turned NaN at a finite Reynolds number, and messages naming the wrong function. Each test
   failed before its fix. (Restoring from a directory: test_restart.c.) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fsdem_tests.h"

/* ---- an allocator that fails on demand and checks every free's size -------------------------- */

/* Each block carries the size it was allocated with in a header; a free with another size is
   counted (a pool allocator keyed by size would corrupt), and so is every block still live. The
   allocation numbered `fail_at` (counted from 1 after arming) returns NULL, and with `lasting` every
   one after it too (the memory is gone, not just one request refused). */
typedef struct sized {
    long count, fail_at, bad_frees, live;
    int lasting;
} sized;

#define SIZED_HEADER 16 /* keeps the blocks aligned for any fsdem type */

static void *sized_alloc(void *user, size_t size) {
    sized *h = (sized *)user;
    size_t *block;
    if (++h->count == h->fail_at || (h->lasting && h->count > h->fail_at)) return NULL;
    block = (size_t *)malloc(size + SIZED_HEADER);
    if (!block) return NULL;
    block[0] = size;
    h->live++;
    return (char *)block + SIZED_HEADER;
}

static void sized_free(void *user, void *ptr, size_t size) {
    sized *h = (sized *)user;
    size_t *block = (size_t *)(void *)((char *)ptr - SIZED_HEADER);
    if (block[0] != size) h->bad_frees++;
    h->live--;
    free(block);
}

static fsdem_allocator sized_allocator(sized *h) {
    fsdem_allocator a;
    a.alloc = sized_alloc;
    a.free = sized_free;
    a.user = h;
    return a;
}

/* Fails the allocation `n` counted from now. */
static void arm(sized *h, long n) { h->fail_at = h->count + n; }

/* After a run that failed its allocation `armed`: every free had the size allocated and nothing
   leaked; a run that met the failure said so in a message. Returns 0 once a run no longer reaches
   the failing allocation (the loops below stop there). */
static int audited(const sized *h, fsdem_result res, const char *message, const char *what) {
    ck_assert_msg(h->bad_frees == 0, "%s (allocation %ld failed): %ld frees of another size", what, h->fail_at, h->bad_frees);
    ck_assert_msg(h->live == 0, "%s (allocation %ld failed): %ld blocks leaked", what, h->fail_at, h->live);
    if (res == FSDEM_ERR_OUT_OF_MEMORY) ck_assert_msg(strstr(message, "out of memory") != NULL, "%s: no message (\"%s\")", what, message);
    return h->count >= h->fail_at;
}

typedef struct log_capture {
    char last[512];
} log_capture;

static void capture(void *user, fsdem_log_level level, const char *message) {
    (void)level;
    snprintf(((log_capture *)user)->last, sizeof((log_capture *)user)->last, "%s", message);
}

/* ---- frees of the wrong size -------------------------------------------------------------------- */

/* The gauges keep three arrays of one capacity; the first grew and the second failed, so the first
   was later freed with the old capacity's size. Every failure point of forty gauges, MPS and PIC. */
static int gauges_run(int pic, long n) {
    sized h = {0, 0, 0, 0, 0};
    fsdem_result res = FSDEM_OK;
    char message[512];
    int k;
    if (pic) {
        fsdem_pic_desc d = fsdem_pic_desc_default(2);
        fsdem_pic *s = NULL;
        d.cell_size = (fsdem_real)0.1;
        d.allocator = sized_allocator(&h);
        ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
        arm(&h, n);
        for (k = 0; k < 40 && res == FSDEM_OK; ++k) res = fsdem_pic_add_gauge(s, FSDEM_PIC_GAUGE_KIND_LEVEL, fsdem_v3(0.5, 0.5, 0), 0, NULL);
        snprintf(message, sizeof message, "%s", fsdem_pic_last_error(s));
        fsdem_pic_destroy(s);
    } else {
        fsdem_mps_desc d = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
        fsdem_mps *s = NULL;
        d.allocator = sized_allocator(&h);
        ck_assert_int_eq(fsdem_mps_create(&d, &s), FSDEM_OK);
        arm(&h, n);
        for (k = 0; k < 40 && res == FSDEM_OK; ++k) res = fsdem_mps_add_gauge(s, FSDEM_MPS_GAUGE_KIND_LEVEL, fsdem_v3(0.5, 0.5, 0), 0, NULL);
        snprintf(message, sizeof message, "%s", fsdem_mps_last_error(s));
        fsdem_mps_destroy(s);
    }
    return audited(&h, res, message, pic ? "fsdem_pic_add_gauge" : "fsdem_mps_add_gauge");
}

START_TEST(gauge_growth_failure_frees_at_the_size_allocated) {
    long n;
    for (n = 1; gauges_run(0, n); ++n) {
    }
    for (n = 1; gauges_run(1, n); ++n) {
    }
}
END_TEST

/* A 2D water tank with one disc; `late`: then a step, two more discs added to the DEM, and the
   step that cuts them is the one that fails. The coupler's face and J arrays grew one by one (frees
   of the wrong size), and the body records' failure left the step's result without a message. The
   refused step leaves the run as it was (issue 34), at every allocation that fails, and when
   (`lasting`) no allocation succeeds after it: the put-back allocates nothing. */
static int pic_dem_run(int late, int lasting, long n) {
    sized h = {0, 0, 0, 0, 0};
    log_capture log;
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_pic_dem_desc cd = fsdem_pic_dem_desc_default();
    fsdem_pic *pic = NULL;
    fsdem_dem *dem = NULL;
    fsdem_pic_dem *c = NULL;
    fsdem_result res;
    test_kept before, after;
    char message[512];
    log.last[0] = '\0';
    pd.cell_size = (fsdem_real)0.02;
    pd.domain_max = fsdem_v3(0.4f, 0.4f, 0);
    pd.dt_max = (fsdem_real)1e-3;
    pd.allocator = sized_allocator(&h);
    ck_assert_int_eq(fsdem_pic_create(&pd, &pic), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3(0.4f, 0.3f, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
    dd.domain_min = fsdem_v3(0, 0, 0);
    dd.domain_max = pd.domain_max;
    dd.dt = (fsdem_real)1e-4;
    dd.allocator = sized_allocator(&h);
    ck_assert_int_eq(fsdem_dem_create(&dd, &dem), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_OK);
    p.radius = (fsdem_real)0.05;
    p.position = fsdem_v3(0.2f, 0.15f, 0);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
    cd.pic = pic;
    cd.dem = dem;
    cd.log = capture;
    cd.log_user = &log;
    if (!late) {
        arm(&h, n);
        res = fsdem_pic_dem_create(&cd, &c);
        snprintf(message, sizeof message, "%s", log.last);
    } else {
        ck_assert_int_eq(fsdem_pic_dem_create(&cd, &c), FSDEM_OK);
        ck_assert_int_eq(fsdem_pic_dem_step(c), FSDEM_OK);
        p.radius = (fsdem_real)0.03;
        p.position = fsdem_v3(0.1f, 0.15f, 0);
        ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
        p.position = fsdem_v3(0.3f, 0.15f, 0);
        ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
        TEST_KEEP(fsdem_pic_dem_save_memory, c, fsdem_pic_dem_get_stats(c).coupling, &before);
        arm(&h, n);
        h.lasting = lasting;
        res = fsdem_pic_dem_step(c);
        h.lasting = 0;
        snprintf(message, sizeof message, "%s", fsdem_pic_dem_last_error(c));
        TEST_KEEP(fsdem_pic_dem_save_memory, c, fsdem_pic_dem_get_stats(c).coupling, &after);
        if (res == FSDEM_OK) { /* taken */
            free(before.bytes);
            free(after.bytes);
        } else /* a refused step changes nothing (>>couple_step), the put-back allocating nothing */
            test_kept_same(&before, &after, "fsdem_pic_dem_step out of memory");
    }
    fsdem_pic_dem_destroy(c);
    fsdem_dem_destroy(dem);
    fsdem_pic_destroy(pic);
    return audited(&h, res, message, late ? "fsdem_pic_dem_step after late bodies" : "fsdem_pic_dem_create");
}

START_TEST(pic_dem_out_of_memory_frees_at_size_and_says_so) {
    long n;
    for (n = 1; pic_dem_run(0, 0, n); ++n) {
    }
    for (n = 1; pic_dem_run(1, 0, n); ++n) {
    }
    for (n = 1; pic_dem_run(1, 1, n); ++n) {
    }
}
END_TEST

/* Issue 34: a coupled step refused out of memory leaves coupler, fluid and DEM byte for byte as they
   were, at every allocation that fails and when none succeeds after it (`lasting`: the put-back
   allocates nothing). MPS-DEM: a water tank with a disc, sixteen discs added since its last step
   (the force records grow in the step's update); SWE-DEM: a channel with a floating sphere and one
   added since its last step (its force and reaction arrays grow in the step). */
static int coupled_oom_run(int mps, int lasting, long n) {
    sized h = {0, 0, 0, 0, 0};
    fsdem_dem_desc dd = fsdem_dem_desc_default(mps ? 2 : 3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_mps *water = NULL;
    fsdem_swe *channel = NULL;
    fsdem_dem *dem = NULL;
    fsdem_mps_dem *md = NULL;
    fsdem_swe_dem *sd = NULL;
    fsdem_result res;
    test_kept before, after;
    char message[512];
    int k;
    dd.allocator = sized_allocator(&h);
    if (mps) {
        fsdem_mps_desc d = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
        d.domain_min = fsdem_v3(-0.06f, -0.06f, 0);
        d.domain_max = fsdem_v3(0.26f, 0.26f, 0);
        d.allocator = sized_allocator(&h);
        ck_assert_int_eq(fsdem_mps_create(&d, &water), FSDEM_OK);
        ck_assert_int_eq(fsdem_mps_add_box_walls(water, fsdem_v3(0, 0, 0), fsdem_v3(0.2f, 0.2f, 0), 1u << FSDEM_SIDE_YMAX, NULL), FSDEM_OK);
        ck_assert_int_eq(fsdem_mps_fill_box(water, fsdem_v3(0, 0, 0), fsdem_v3(0.2f, 0.1f, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
        dd.domain_min = fsdem_v3(-0.06f, -0.06f, -1);
        dd.domain_max = fsdem_v3(0.26f, 0.26f, 1);
        p.radius = 0.004f;
        p.position = fsdem_v3(0.1f, 0.05f, 0);
    } else {
        fsdem_swe_desc d = fsdem_swe_desc_default(1);
        fsdem_real depth[100];
        for (k = 0; k < 100; ++k) depth[k] = 1;
        d.nx = 100;
        d.x_max = 10;
        d.depth = depth;
        d.allocator = sized_allocator(&h);
        ck_assert_int_eq(fsdem_swe_create(&d, &channel), FSDEM_OK);
        dd.domain_min = fsdem_v3(0, -1, -1);
        dd.domain_max = fsdem_v3(10, 1, 2);
        dd.dt = (fsdem_real)1e-4;
        m.density = 500;
        p.radius = 0.2f;
        p.position = fsdem_v3(3, 0, 1);
    }
    ck_assert_int_eq(fsdem_dem_create(&dd, &dem), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
    if (mps) {
        fsdem_mps_dem_desc cd = fsdem_mps_dem_desc_default();
        cd.mps = water;
        cd.dem = dem;
        ck_assert_int_eq(fsdem_mps_dem_create(&cd, &md), FSDEM_OK);
        ck_assert_int_eq(fsdem_mps_dem_step(md), FSDEM_OK);
        for (k = 0; k < 16; ++k) {
            p.position = fsdem_v3((fsdem_real)(0.02 + 0.01 * k), 0.08f, 0);
            ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
        }
        TEST_KEEP(fsdem_mps_dem_save_memory, md, fsdem_mps_dem_get_stats(md).coupling, &before);
    } else {
        fsdem_swe_dem_desc cd = fsdem_swe_dem_desc_default();
        cd.swe = channel;
        cd.dem = dem;
        ck_assert_int_eq(fsdem_swe_dem_create(&cd, &sd), FSDEM_OK);
        ck_assert_int_eq(fsdem_swe_dem_step(sd), FSDEM_OK);
        p.position = fsdem_v3(6, 0, 1);
        ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
        TEST_KEEP(fsdem_swe_dem_save_memory, sd, fsdem_swe_dem_get_stats(sd).coupling, &before);
    }
    arm(&h, n);
    h.lasting = lasting;
    res = mps ? fsdem_mps_dem_step(md) : fsdem_swe_dem_step(sd);
    h.lasting = 0;
    snprintf(message, sizeof message, "%s", mps ? fsdem_mps_dem_last_error(md) : fsdem_swe_dem_last_error(sd));
    if (mps) TEST_KEEP(fsdem_mps_dem_save_memory, md, fsdem_mps_dem_get_stats(md).coupling, &after);
    else TEST_KEEP(fsdem_swe_dem_save_memory, sd, fsdem_swe_dem_get_stats(sd).coupling, &after);
    if (res == FSDEM_OK) {
        free(before.bytes);
        free(after.bytes);
    } else
        test_kept_same(&before, &after, mps ? "fsdem_mps_dem_step out of memory" : "fsdem_swe_dem_step out of memory");
    fsdem_mps_dem_destroy(md);
    fsdem_swe_dem_destroy(sd);
    fsdem_dem_destroy(dem);
    fsdem_mps_destroy(water);
    fsdem_swe_destroy(channel);
    return audited(&h, res, message, mps ? "fsdem_mps_dem_step" : "fsdem_swe_dem_step");
}

START_TEST(coupled_step_out_of_memory_changes_nothing) {
    int mps, lasting;
    long n;
    for (mps = 0; mps < 2; ++mps)
        for (lasting = 0; lasting < 2; ++lasting)
            for (n = 1; coupled_oom_run(mps, lasting, n); ++n) {
            }
}
END_TEST

/* fsdem_swe_create returned FSDEM_ERR_OUT_OF_MEMORY without a message when it could not copy a
   boundary's series (its third and fourth allocations). */
static int swe_run(long n) {
    static const fsdem_real t[2] = {0, 1}, q[2] = {0.1f, 0.2f};
    sized h = {0, 0, 0, 0, 0};
    log_capture log;
    fsdem_swe_desc d = fsdem_swe_desc_default(1);
    fsdem_swe *s = NULL;
    fsdem_result res;
    log.last[0] = '\0';
    d.allocator = sized_allocator(&h);
    d.log = capture;
    d.log_user = &log;
    d.boundary[FSDEM_SIDE_XMIN].type = FSDEM_SWE_BC_DISCHARGE;
    d.boundary[FSDEM_SIDE_XMIN].series_time = t;
    d.boundary[FSDEM_SIDE_XMIN].series_value = q;
    d.boundary[FSDEM_SIDE_XMIN].series_count = 2;
    arm(&h, n);
    res = fsdem_swe_create(&d, &s);
    ck_assert(res == FSDEM_OK || res == FSDEM_ERR_OUT_OF_MEMORY);
    ck_assert((res == FSDEM_OK) == (s != NULL));
    fsdem_swe_destroy(s);
    return audited(&h, res, log.last, "fsdem_swe_create");
}

START_TEST(swe_create_out_of_memory_is_logged) {
    long n;
    for (n = 1; swe_run(n); ++n) {
    }
}
END_TEST

/* ---- values that cannot be right are refused at the call ----------------------------------------- */

/* The call returned FSDEM_ERR_INVALID_ARG and its message names `word`. */
#define REFUSED(call, message, word)                                                                                     \
    do {                                                                                                                 \
        ck_assert_int_eq((call), FSDEM_ERR_INVALID_ARG);                                                                 \
        ck_assert_msg(strstr((message), (word)) != NULL, "message \"%s\" does not name %s", (message), (word));          \
    } while (0)

START_TEST(implausible_mps_input_is_refused) {
    fsdem_mps_desc d = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_mps *s = NULL;
    char msg[512];
    const fsdem_vec3 x = {0.5f, 0.5f, 0}, fast = {(fsdem_real)1e20, 0, 0};
    d.gravity = fsdem_v3(0, (fsdem_real)-9.81, 1);
    REFUSED(fsdem_mps_desc_check(&d, msg, sizeof msg), msg, "gravity.z");
    d = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    d.gravity = fsdem_v3(0, (fsdem_real)-1e20, 0);
    REFUSED(fsdem_mps_desc_check(&d, msg, sizeof msg), msg, "FSDEM_MAX_ACCELERATION");
    d = fsdem_mps_desc_default(2);
    d.r0 = 5; /* the domain is 1 m wide */
    REFUSED(fsdem_mps_desc_check(&d, msg, sizeof msg), msg, "r0");
    d = fsdem_mps_desc_default(2);
    d.dt_max = (fsdem_real)1e20; /* g dt_max would be 1e21 m/s */
    REFUSED(fsdem_mps_desc_check(&d, msg, sizeof msg), msg, "dt_max");
    d.dt_max = 1; /* 9.81 m/s of free fall in a step is plausible, if not stable: the CFL limit takes over */
    ck_assert_int_eq(fsdem_mps_desc_check(&d, msg, sizeof msg), FSDEM_OK);
    d = fsdem_mps_desc_default(2);
    d.scheme = (fsdem_mps_scheme)2;
    REFUSED(fsdem_mps_desc_check(&d, msg, sizeof msg), msg, "scheme");
    d.scheme = FSDEM_MPS_SCHEME_EXPLICIT;
    d.sound_speed = -1;
    REFUSED(fsdem_mps_desc_check(&d, msg, sizeof msg), msg, "sound_speed");
    d.sound_speed = 0;
    d.density_diffusion = 2;
    REFUSED(fsdem_mps_desc_check(&d, msg, sizeof msg), msg, "density_diffusion");
    d.density_diffusion = (fsdem_real)0.1;
    d.re = 2 * d.r0; /* inside the explicit gradient's support */
    REFUSED(fsdem_mps_desc_check(&d, msg, sizeof msg), msg, "re");
    d = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    ck_assert_int_eq(fsdem_mps_create(&d, &s), FSDEM_OK);
    REFUSED(fsdem_mps_add_particles(s, FSDEM_MPS_KIND_FLUID, 1, &x, &fast), fsdem_mps_last_error(s), "FSDEM_MAX_SPEED");
    REFUSED(fsdem_mps_fill_box(s, fsdem_v3(0.1f, 0.1f, 0), fsdem_v3(0.2f, 0.2f, 0), fast, NULL), fsdem_mps_last_error(s),
            "FSDEM_MAX_SPEED");
    REFUSED(fsdem_mps_add_box_walls(s, fsdem_v3(0.1f, 0.1f, 0), fsdem_v3(0.3f, 0.3f, 0), 1u << 4, NULL), fsdem_mps_last_error(s),
            "open_sides");
    ck_assert_int_eq(fsdem_mps_get_particles(s).count, 0);
    fsdem_mps_destroy(s);
}
END_TEST

START_TEST(implausible_dem_input_is_refused) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_dem_contact c[2];
    fsdem_dem *dem = NULL, *unit = NULL;
    fsdem_dem_wall_desc w;
    char msg[512];
    int mat;
    d.dim = 2;
    d.gravity = fsdem_v3(0, (fsdem_real)-9.81, (fsdem_real)-1);
    REFUSED(fsdem_dem_desc_check(&d, msg, sizeof msg), msg, "gravity.z");
    d = fsdem_dem_desc_default(3);
    ck_assert_int_eq(fsdem_dem_create(&d, &dem), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_create(&d, &unit), FSDEM_OK);
    m.young_modulus = (fsdem_real)INFINITY; /* two such materials met in an infinite contact stiffness */
    REFUSED(fsdem_dem_add_material(dem, &m, NULL), fsdem_dem_last_error(dem), "young_modulus");
    m.young_modulus = (fsdem_real)1e20; /* finite but no material: beyond FSDEM_MAX_MODULUS */
    REFUSED(fsdem_dem_add_material(dem, &m, NULL), fsdem_dem_last_error(dem), "young_modulus");
    m = fsdem_dem_material_default();
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(unit, &m, NULL), FSDEM_OK);
    m.young_modulus = (fsdem_real)1.2e15; /* a wall a thousand times stiffer than diamond is allowed */
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_OK);
    m = fsdem_dem_material_default();
    p.radius = (fsdem_real)0.1;
    p.velocity = fsdem_v3((fsdem_real)1e20, 0, 0);
    REFUSED(fsdem_dem_add_particle(dem, &p, NULL), fsdem_dem_last_error(dem), "FSDEM_MAX_SPEED");
    p.velocity = fsdem_v3(0, 0, 0);
    p.angular_velocity = fsdem_v3(0, 0, (fsdem_real)1e6); /* its surface would move at 1e5 m/s */
    REFUSED(fsdem_dem_add_particle(dem, &p, NULL), fsdem_dem_last_error(dem), "FSDEM_MAX_SPEED");
    ck_assert_int_eq(fsdem_dem_get_particles(dem).count, 0);
    /* a plane normal of (0, 0, 1e30) is the plane of normal (0, 0, 1): the same contact */
    w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, (fsdem_real)1e30), mat);
    ck_assert_int_eq(fsdem_dem_add_wall(dem, &w, NULL), FSDEM_OK);
    w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), mat);
    ck_assert_int_eq(fsdem_dem_add_wall(unit, &w, NULL), FSDEM_OK);
    p.angular_velocity = fsdem_v3(0, 0, 0);
    p.position = fsdem_v3(0, 0, (fsdem_real)0.09);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_particle(unit, &p, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_contacts(dem, c, 1), 1);
    ck_assert_int_eq(fsdem_dem_contacts(unit, c + 1, 1), 1);
    ck_assert(c[0].normal.z == c[1].normal.z && c[0].overlap == c[1].overlap);
    w.velocity = fsdem_v3(0, (fsdem_real)1e20, 0);
    REFUSED(fsdem_dem_add_wall(dem, &w, NULL), fsdem_dem_last_error(dem), "FSDEM_MAX_SPEED");
    REFUSED(fsdem_dem_set_wall_velocity(dem, 0, fsdem_v3((fsdem_real)1e20, 0, 0)), fsdem_dem_last_error(dem), "FSDEM_MAX_SPEED");
    fsdem_dem_destroy(dem);
    fsdem_dem_destroy(unit);
}
END_TEST

START_TEST(implausible_pic_and_swe_input_is_refused) {
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_swe_desc sd = fsdem_swe_desc_default(1);
    fsdem_pic *pic = NULL;
    fsdem_swe *swe = NULL;
    fsdem_swe_boundary b;
    fsdem_real a[100];
    const fsdem_vec3 fast = {(fsdem_real)1e20, 0, 0};
    char msg[512];
    int k;
    pd.cell_size = (fsdem_real)0.1;
    ck_assert_int_eq(fsdem_pic_create(&pd, &pic), FSDEM_OK);
    REFUSED(fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3(0.5f, 0.5f, 0), fast, NULL), fsdem_pic_last_error(pic),
            "FSDEM_MAX_SPEED");
    REFUSED(fsdem_pic_add_force(pic, fsdem_v3(0.5f, 0.5f, 0), 0, fast, NULL), fsdem_pic_last_error(pic), "FSDEM_MAX_ACCELERATION");
    ck_assert_int_eq(fsdem_pic_get_particles(pic).count, 0);
    fsdem_pic_destroy(pic);
    sd.gravity = fsdem_v3(0, 0, (fsdem_real)-1e20);
    REFUSED(fsdem_swe_desc_check(&sd, msg, sizeof msg), msg, "gravity");
    sd = fsdem_swe_desc_default(1);
    ck_assert_int_eq(fsdem_swe_create(&sd, &swe), FSDEM_OK);
    for (k = 0; k < 100; ++k) a[k] = (fsdem_real)1e20;
    REFUSED(fsdem_swe_set_depth(swe, a), fsdem_swe_last_error(swe), "fsdem_swe_set_depth");
    REFUSED(fsdem_swe_set_velocity(swe, a, NULL), fsdem_swe_last_error(swe), "fsdem_swe_set_velocity");
    for (k = 0; k < 100; ++k) a[k] = 1;
    ck_assert_int_eq(fsdem_swe_set_depth(swe, a), FSDEM_OK);
    REFUSED(fsdem_swe_add_force(swe, fsdem_v3(0.5f, 0, 0), 0, fast, NULL), fsdem_swe_last_error(swe), "FSDEM_MAX_ACCELERATION");
    memset(&b, 0, sizeof b);
    b.type = FSDEM_SWE_BC_STAGE;
    b.value = (fsdem_real)1e20;
    REFUSED(fsdem_swe_set_boundary(swe, FSDEM_SIDE_XMIN, &b), fsdem_swe_last_error(swe), "value");
    ck_assert(fsdem_swe_get_fields(swe).eta[0] == 1); /* unchanged */
    fsdem_swe_destroy(swe);
}
END_TEST

/* MPS-DEM's averaging radius and PIC-DEM's contact length of 1e30 m were accepted; so was a sphere
   wider than the fluid's domain (PIC-DEM: a body that leaves no open cell). */
START_TEST(implausible_coupler_input_is_refused) {
    fsdem_mps_desc md = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_mps_dem_desc mc = fsdem_mps_dem_desc_default();
    fsdem_pic_dem_desc pc = fsdem_pic_dem_desc_default();
    fsdem_mps *mps = NULL;
    fsdem_pic *pic = NULL;
    fsdem_dem *dem = NULL;
    fsdem_mps_dem *c = NULL;
    fsdem_pic_dem *cp = NULL;
    char msg[512];
    pd.cell_size = (fsdem_real)0.05;
    ck_assert_int_eq(fsdem_mps_create(&md, &mps), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_create(&pd, &pic), FSDEM_OK);
    dd.domain_min = fsdem_v3(-10, -10, 0);
    dd.domain_max = fsdem_v3(10, 10, 0);
    ck_assert_int_eq(fsdem_dem_create(&dd, &dem), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_OK);
    mc.mps = mps;
    mc.dem = dem;
    mc.averaging_radius = (fsdem_real)1e30;
    REFUSED(fsdem_mps_dem_desc_check(&mc, msg, sizeof msg), msg, "radius");
    pc.pic = pic;
    pc.dem = dem;
    pc.contact_length = (fsdem_real)1e30;
    REFUSED(fsdem_pic_dem_desc_check(&pc, msg, sizeof msg), msg, "contact_length");
    /* a disc of 2 m diameter in the 1 m fluid domains */
    p.radius = 1;
    p.position = fsdem_v3(0.5f, 0.5f, 0);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
    pc.contact_length = 0;
    ck_assert_int_eq(fsdem_pic_dem_create(&pc, &cp), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_null(cp);
    mc.averaging_radius = 0;
    ck_assert_int_eq(fsdem_mps_dem_create(&mc, &c), FSDEM_OK);
    REFUSED(fsdem_mps_dem_update(c), fsdem_mps_dem_last_error(c), "does not fit");
    fsdem_mps_dem_destroy(c);
    fsdem_dem_destroy(dem);
    fsdem_pic_destroy(pic);
    fsdem_mps_destroy(mps);
}
END_TEST

/* Issue 34, refused at the call that is wrong: a GIC or a PIC-DEM over a DEM periodic along x with
   a PIC that has no periodic axes (accepted; the steps failed later), a viscosity preconditioner
   the viscous stencil cannot take (refused as "= 6 is not a fsdem_precond"), a granule wider than
   the PIC's domain (refused at the step, before anything moves, naming it). */
START_TEST(mismatched_coupling_input_is_refused_where_given) {
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_gic_desc gd = fsdem_gic_desc_default();
    fsdem_pic_dem_desc cd = fsdem_pic_dem_desc_default();
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_pic *pic = NULL;
    fsdem_dem *dem = NULL;
    fsdem_gic *g = NULL;
    char msg[512];
    double t0;
    pd.cell_size = (fsdem_real)0.01;
    pd.domain_max = fsdem_v3((fsdem_real)0.1, (fsdem_real)0.1, 0);
    pd.viscosity_precond = FSDEM_PRECOND_AMG;
    REFUSED(fsdem_pic_desc_check(&pd, msg, sizeof msg), msg, "AMG takes CSR matrices only");
    pd.viscosity_precond = FSDEM_PRECOND_AUTO;
    ck_assert_int_eq(fsdem_pic_create(&pd, &pic), FSDEM_OK);
    dd.domain_max = pd.domain_max;
    dd.gravity = pd.gravity;
    dd.law = FSDEM_DEM_LAW_GIC;
    dd.periodic[0] = 1;
    ck_assert_int_eq(fsdem_dem_create(&dd, &dem), FSDEM_OK);
    gd.pic = cd.pic = pic;
    gd.dem = cd.dem = dem;
    REFUSED(fsdem_gic_desc_check(&gd, msg, sizeof msg), msg, "periodic along x");
    REFUSED(fsdem_pic_dem_desc_check(&cd, msg, sizeof msg), msg, "periodic along x");
    fsdem_dem_destroy(dem);
    dd.periodic[0] = 0;
    dd.domain_min = fsdem_v3(-1, -1, 0);
    dd.domain_max = fsdem_v3(1, 1, 0);
    ck_assert_int_eq(fsdem_dem_create(&dd, &dem), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_OK);
    p.position = fsdem_v3((fsdem_real)0.05, (fsdem_real)0.05, 0);
    p.radius = (fsdem_real)0.06; /* 0.12 m across, in a 0.1 m domain */
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
    gd.dem = dem;
    ck_assert_int_eq(fsdem_gic_create(&gd, &g), FSDEM_OK);
    t0 = fsdem_dem_time(dem);
    REFUSED(fsdem_gic_step(g), fsdem_gic_last_error(g), "does not fit");
    ck_assert(fsdem_dem_time(dem) == t0 && fsdem_pic_time(pic) == 0);
    fsdem_gic_destroy(g);
    fsdem_dem_destroy(dem);
    fsdem_pic_destroy(pic);
}
END_TEST

/* Issue 34: a symmetric matrix that is not positive definite given to AMG was refused as out of
   memory; it is FSDEM_ERR_INVALID_ARG, said so, and the solver stays usable (the same object then
   takes a positive definite matrix). */
START_TEST(amg_refuses_an_indefinite_matrix_as_such) {
    static const int start[4] = {0, 2, 5, 7}, col[7] = {0, 1, 0, 1, 2, 1, 2};
    static const fsdem_real bad[7] = {2, -1, -1, -1, -1, -1, 2}, good[7] = {2, -1, -1, 2, -1, -1, 2};
    fsdem_pcg_desc d = fsdem_pcg_desc_default();
    fsdem_csr m;
    fsdem_pcg *s = NULL;
    d.preconditioner = FSDEM_PRECOND_AMG;
    ck_assert_int_eq(fsdem_pcg_create(&d, &s), FSDEM_OK);
    m.rows = 3;
    m.row_start = start;
    m.col = col;
    m.val = bad;
    REFUSED(fsdem_pcg_setup_csr(s, &m), fsdem_pcg_last_error(s), "not positive definite");
    m.val = good;
    ck_assert_int_eq(fsdem_pcg_setup_csr(s, &m), FSDEM_OK);
    fsdem_pcg_destroy(s);
}
END_TEST

/* Issue 34: fsdem_set_threads(10000) was taken on a two-core machine and the next 128^2 PIC did not
   finish in a minute. Counts below 1 or above four per processor are refused and change nothing
   (10000 is above the bound on any machine of fewer than 2,500 processors); without OpenMP there
   is no thread to set, and any count from 1 is taken as doing nothing. */
START_TEST(thread_counts_the_machine_cannot_run_are_refused) {
    const int before = fsdem_threads();
    ck_assert_int_eq(fsdem_set_threads(0), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_set_threads(-3), FSDEM_ERR_INVALID_ARG);
#if defined(_OPENMP) && !defined(FSDEM_NO_OPENMP)
    ck_assert_int_eq(fsdem_set_threads(10000), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_threads(), before);
    ck_assert_int_eq(fsdem_set_threads(before), FSDEM_OK);
#else
    ck_assert_int_eq(fsdem_set_threads(10000), FSDEM_OK);
    ck_assert_int_eq(fsdem_threads(), 1);
#endif
    ck_assert_int_eq(fsdem_threads(), before);
}
END_TEST

/* ---- drag laws over their range ------------------------------------------------------------------ */

/* Every law is finite from Re = 0 to the largest slip (FSDEM_MAX_SPEED) for grains of 1 um to
   1 m in water and in a light gas, at porosities from 0.2 to 1. Beetstra's inertial term was
   multiplied through by Re^a and turned inf / inf = NaN where Re^a overflowed; a slip beyond the
   bound is refused, naming it, and an overflow of c itself names Re (it blamed "d too small"). */
START_TEST(drag_laws_are_finite_over_their_range) {
    static const double eps[5] = {0.2, 0.4, 0.6, 0.8, 1}, d[4] = {1e-6, 1e-3, 0.1, 1}, slip[5] = {0, 1e-9, 1e-3, 1, 1e4};
    static const double fluid[2][2] = {{1000, 1e-3}, {1, 1.8e-5}}; /* density, dynamic viscosity */
    char msg[512];
    fsdem_real c;
    int law, a, b, e, f;
    for (law = FSDEM_DRAG_LAW_STOKES; law <= FSDEM_DRAG_LAW_BEETSTRA; ++law)
        for (a = 0; a < 5; ++a)
            for (b = 0; b < 4; ++b)
                for (e = 0; e < 5; ++e)
                    for (f = 0; f < 2; ++f) {
                        ck_assert_int_eq(fsdem_drag_coefficient((fsdem_drag_law)law, (fsdem_real)eps[a], (fsdem_real)d[b], (fsdem_real)slip[e],
                                                                (fsdem_real)fluid[f][0], (fsdem_real)fluid[f][1], &c, NULL, msg,
                                                                sizeof msg),
                                         FSDEM_OK);
                        ck_assert(isfinite(c) && c > 0);
                    }
    REFUSED(fsdem_drag_coefficient(FSDEM_DRAG_LAW_BEETSTRA, (fsdem_real)0.4, (fsdem_real)1e-3, (fsdem_real)1e20, 1000, (fsdem_real)1e-3, &c,
                                   NULL, msg, sizeof msg),
            msg, "slip_speed");
    if (!TEST_FLOAT) { /* a density of 1e306 overflows c (Re = 4e305) */
        ck_assert_int_eq(fsdem_drag_coefficient(FSDEM_DRAG_LAW_BEETSTRA, (fsdem_real)0.4, (fsdem_real)1e-3, 1, (fsdem_real)1e306,
                                                (fsdem_real)1e-3, &c, NULL, msg, sizeof msg),
                         FSDEM_ERR_NAN);
        ck_assert_ptr_nonnull(strstr(msg, "Re = "));
    }
}
END_TEST

/* At Re = 5e7 Beetstra's hindrance 1 + 10^(3 phi) Re^-a differs from 1 by 1e-10 (phi = 0.5, a =
   1.5), so c is the published form's large-Re limit 18 mu eps/d^2 [10 phi/eps^2 + eps^2 (1 + 1.5
   sqrt(phi)) + 0.413 (Re (1/eps + 3 phi eps) + 8.4 Re^0.657) / (24 eps^2)] to 1e-9. */
START_TEST(beetstra_reaches_its_large_reynolds_limit) {
    const double eps = 0.5, phi = 0.5, d = 0.01, mu = 1e-3, rho = 1000, slip = 1e4, re = eps * rho * d * slip / mu;
    const double limit = 18 * mu * eps / (d * d) *
                         (10 * phi / (eps * eps) + eps * eps * (1 + 1.5 * sqrt(phi)) +
                          0.413 * (re * (1 / eps + 3 * phi * eps) + 8.4 * pow(re, 0.657)) / (24 * eps * eps));
    fsdem_real c;
    ck_assert_int_eq(fsdem_drag_coefficient(FSDEM_DRAG_LAW_BEETSTRA, (fsdem_real)eps, (fsdem_real)d, (fsdem_real)slip, (fsdem_real)rho,
                                            (fsdem_real)mu, &c, NULL, NULL, 0),
                     FSDEM_OK);
    ck_assert(fabs(c / limit - 1) < TOL(1e-9, 100));
}
END_TEST

/* ---- messages name the function called ---------------------------------------------------------- */

START_TEST(dem_messages_name_the_function_called) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem = NULL;
    long long k;
    ck_assert_int_eq(fsdem_dem_create(&d, &dem), FSDEM_OK);
    REFUSED(fsdem_dem_substep_count(dem, -1, &k), fsdem_dem_last_error(dem), "fsdem_dem_substep_count:");
    REFUSED(fsdem_dem_advance_with(dem, -1, NULL, NULL, NULL), fsdem_dem_last_error(dem), "fsdem_dem_advance_with:");
    REFUSED(fsdem_dem_advance(dem, (fsdem_real)1e30, NULL), fsdem_dem_last_error(dem), "fsdem_dem_advance:");
    fsdem_dem_destroy(dem);
}
END_TEST

Suite *probing_suite(void) {
    Suite *s = suite_create("probing");
    TCase *tc = tcase_create("probing");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, gauge_growth_failure_frees_at_the_size_allocated);
    tcase_add_test(tc, pic_dem_out_of_memory_frees_at_size_and_says_so);
    tcase_add_test(tc, coupled_step_out_of_memory_changes_nothing);
    tcase_add_test(tc, swe_create_out_of_memory_is_logged);
    tcase_add_test(tc, implausible_mps_input_is_refused);
    tcase_add_test(tc, implausible_dem_input_is_refused);
    tcase_add_test(tc, implausible_pic_and_swe_input_is_refused);
    tcase_add_test(tc, implausible_coupler_input_is_refused);
    tcase_add_test(tc, mismatched_coupling_input_is_refused_where_given);
    tcase_add_test(tc, amg_refuses_an_indefinite_matrix_as_such);
    tcase_add_test(tc, thread_counts_the_machine_cannot_run_are_refused);
    tcase_add_test(tc, drag_laws_are_finite_over_their_range);
    tcase_add_test(tc, beetstra_reaches_its_large_reynolds_limit);
    tcase_add_test(tc, dem_messages_name_the_function_called);
    suite_add_tcase(s, tc);
    return s;
}
