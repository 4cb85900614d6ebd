/* What every coupler shares (>>couple): the claims on the solvers' coupling arrays, and couplers of
   one fluid stepped together (one PIC carrying a Granule-In-Cell sand bed and a resolved body). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "fsdem_tests.h"

#define RHO 1000.0
#define G 9.81

static double norm3(fsdem_vec3 v) { return sqrt((double)v.x * v.x + (double)v.y * v.y + (double)v.z * v.z); }

/* A 2D PIC box [0, L]^2 of cells dx with still water up to `depth`. */
static fsdem_pic *still_water(double L, double dx, double depth) {
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_pic *pic = NULL;
    pd.cell_size = (fsdem_real)dx;
    pd.jitter = 0;
    pd.domain_max = fsdem_v3((fsdem_real)L, (fsdem_real)L, 0);
    pd.gravity = fsdem_v3(0, (fsdem_real)-G, 0);
    pd.dt_max = (fsdem_real)1e-3;
    pd.viscosity = (fsdem_real)1e-6;
    pd.pressure_tolerance = (fsdem_real)TOL(1e-8, 1e3);
    ck_assert_int_eq(fsdem_pic_create(&pd, &pic), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)L, (fsdem_real)depth, 0), fsdem_v3(0, 0, 0), NULL),
                     FSDEM_OK);
    return pic;
}

/* A 2D DEM over the PIC's box, one material of density rho_s (the GIC contact law for sand). */
static fsdem_dem *dem_over(const fsdem_pic *pic, double rho_s, int sand) {
    const fsdem_pic_desc pd = fsdem_pic_get_desc(pic);
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem *dem = NULL;
    dd.domain_min = pd.domain_min;
    dd.domain_max = pd.domain_max;
    dd.gravity = pd.gravity;
    dd.dt = (fsdem_real)1e-4;
    if (sand) {
        dd.law = FSDEM_DEM_LAW_GIC;
        dd.rotation = 0;
        m.young_modulus = (fsdem_real)1e6;
    } else dd.integrator = FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR;
    m.density = (fsdem_real)rho_s;
    ck_assert_int_eq(fsdem_dem_create(&dd, &dem), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_OK);
    return dem;
}

static void add_disc(fsdem_dem *dem, double x, double y, double r, int fixed) {
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    p.position = fsdem_v3((fsdem_real)x, (fsdem_real)y, 0);
    p.radius = (fsdem_real)r;
    p.fixed = fixed;
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
}

/* A fixed bed of granules (radius 2 mm, 5 mm apart) filling [0, L] x [0, top]. */
static void add_bed(fsdem_dem *dem, double L, double top) {
    double x, y;
    for (y = 0.0025; y < top; y += 0.005)
        for (x = 0.0025; x < L; x += 0.005) add_disc(dem, x, y, 0.002, 1);
}

static fsdem_gic *gic_on(fsdem_pic *pic, fsdem_dem *dem) {
    fsdem_gic_desc d = fsdem_gic_desc_default();
    fsdem_gic *c = NULL;
    d.pic = pic;
    d.dem = dem;
    ck_assert_int_eq(fsdem_gic_create(&d, &c), FSDEM_OK);
    return c;
}

static fsdem_pic_dem *pic_dem_on(fsdem_pic *pic, fsdem_dem *dem) {
    fsdem_pic_dem_desc d = fsdem_pic_dem_desc_default();
    fsdem_pic_dem *c = NULL;
    d.pic = pic;
    d.dem = dem;
    ck_assert_int_eq(fsdem_pic_dem_create(&d, &c), FSDEM_OK);
    return c;
}

/* The registry: a second claim of a held array is refused naming the holder and the array, nothing
   is claimed then; the holder may claim again; a release frees the owner's arrays only; a bit the
   solver does not have is refused. */
START_TEST(claims_name_the_holder) {
    fsdem_pic *pic = still_water(0.2, 0.02, 0.1);
    fsdem_claims *claims = fsdem_pic_claims(pic);
    int a, b;
    char msg[256];
    ck_assert_ptr_null(fsdem_claimant(claims, FSDEM_PIC_ARRAYS_SOLIDS | FSDEM_PIC_ARRAYS_POROSITY | FSDEM_PIC_ARRAYS_ACCELERATION));
    ck_assert_int_eq(fsdem_claim(claims, FSDEM_PIC_ARRAYS_POROSITY, &a, "owner a", msg, sizeof msg), FSDEM_OK);
    ck_assert_int_eq(fsdem_claim(claims, FSDEM_PIC_ARRAYS_POROSITY, &a, "owner a", msg, sizeof msg), FSDEM_OK);
    ck_assert_int_eq(fsdem_claim(claims, FSDEM_PIC_ARRAYS_SOLIDS | FSDEM_PIC_ARRAYS_POROSITY, &b, "owner b", msg, sizeof msg),
                     FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(msg, "porosity") && strstr(msg, "owner a"), "%s", msg);
    ck_assert_ptr_null(fsdem_claimant(claims, FSDEM_PIC_ARRAYS_SOLIDS)); /* nothing of a refused claim */
    ck_assert_int_eq(fsdem_claim(claims, FSDEM_PIC_ARRAYS_SOLIDS, &b, "owner b", msg, sizeof msg), FSDEM_OK);
    ck_assert_str_eq(fsdem_claimant(claims, FSDEM_PIC_ARRAYS_SOLIDS), "owner b");
    fsdem_release(claims, FSDEM_PIC_ARRAYS_SOLIDS | FSDEM_PIC_ARRAYS_POROSITY, &b); /* b holds no porosity */
    ck_assert_str_eq(fsdem_claimant(claims, FSDEM_PIC_ARRAYS_POROSITY), "owner a");
    ck_assert_ptr_null(fsdem_claimant(claims, FSDEM_PIC_ARRAYS_SOLIDS));
    ck_assert_int_eq(fsdem_claim(claims, 8u, &a, "owner a", msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(msg, "0x7"), "%s", msg);
    ck_assert_int_eq(fsdem_claim(NULL, 1u, &a, "owner a", NULL, 0), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_claim(claims, 1u, NULL, "nobody", NULL, 0), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_null(fsdem_pic_claims(NULL));
    fsdem_pic_destroy(pic);
}
END_TEST

/* Couplers claim what they write: on one PIC a GIC (porosity, accelerations) and a PIC-DEM (moving
   solids) coexist, each with its DEM; a second GIC on that PIC, or a PIC-DEM on the GIC's DEM, is
   refused at creation, naming the holder, with nothing created; once the holder is destroyed the
   same desc is accepted. */
START_TEST(couplers_claim_what_they_write) {
    fsdem_pic *pic = still_water(0.2, 0.01, 0.1);
    fsdem_dem *sand = dem_over(pic, 2650, 1), *bodies = dem_over(pic, 1500, 0), *other = dem_over(pic, 2650, 1);
    fsdem_gic_desc gd = fsdem_gic_desc_default();
    fsdem_pic_dem_desc bd = fsdem_pic_dem_desc_default();
    fsdem_gic *gic = gic_on(pic, sand), *second = NULL;
    fsdem_pic_dem *body = pic_dem_on(pic, bodies), *wrong = NULL;
    char msg[512];
    gd.pic = pic;
    gd.dem = other;
    ck_assert_int_eq(fsdem_gic_desc_check(&gd, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(msg, "claimed by fsdem_gic") && strstr(msg, "fsdem_gic_desc.pic"), "%s", msg);
    ck_assert_int_eq(fsdem_gic_create(&gd, &second), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_null(second);
    bd.pic = pic;
    bd.dem = sand;
    ck_assert_int_eq(fsdem_pic_dem_desc_check(&bd, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(msg, "external loads are claimed by fsdem_gic"), "%s", msg);
    ck_assert_int_eq(fsdem_pic_dem_create(&bd, &wrong), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_null(wrong);
    ck_assert_str_eq(fsdem_claimant(fsdem_pic_claims(pic), FSDEM_PIC_ARRAYS_SOLIDS), "fsdem_pic_dem");
    ck_assert_str_eq(fsdem_claimant(fsdem_dem_claims(bodies), FSDEM_DEM_ARRAYS_LOADS), "fsdem_pic_dem");
    fsdem_gic_destroy(gic);
    ck_assert_ptr_null(fsdem_claimant(fsdem_dem_claims(sand), FSDEM_DEM_ARRAYS_LOADS));
    ck_assert_int_eq(fsdem_gic_create(&gd, &second), FSDEM_OK);
    fsdem_gic_destroy(second);
    fsdem_pic_dem_destroy(body);
    ck_assert_ptr_null(fsdem_claimant(fsdem_pic_claims(pic), FSDEM_PIC_ARRAYS_SOLIDS | FSDEM_PIC_ARRAYS_POROSITY));
    fsdem_dem_destroy(sand);
    fsdem_dem_destroy(bodies);
    fsdem_dem_destroy(other);
    fsdem_pic_destroy(pic);
}
END_TEST

/* A list of couplers steps together only if it is a list of distinct couplers of one fluid; a
   refusal names the reason in every coupler of the list and moves nothing. */
START_TEST(coupled_lists_are_checked) {
    fsdem_pic *pic = still_water(0.2, 0.01, 0.1), *elsewhere = still_water(0.2, 0.01, 0.1);
    fsdem_dem *sand = dem_over(pic, 2650, 1), *bodies = dem_over(elsewhere, 1500, 0);
    fsdem_gic *gic = gic_on(pic, sand);
    fsdem_pic_dem *body = pic_dem_on(elsewhere, bodies);
    fsdem_coupler *list[2];
    fsdem_real dt = 0;
    list[0] = fsdem_gic_coupler(gic);
    list[1] = fsdem_pic_dem_coupler(body);
    ck_assert_int_eq(fsdem_coupled_step(list, 0), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_coupled_step(NULL, 1), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_coupled_step(list, 2), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(fsdem_gic_last_error(gic), "different fluids") && strstr(fsdem_pic_dem_last_error(body), "different fluids"),
                  "%s", fsdem_gic_last_error(gic));
    list[1] = list[0];
    ck_assert_int_eq(fsdem_coupled_step_dt(list, 2, (fsdem_real)1e-3), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(fsdem_gic_last_error(gic), "listed twice"), "%s", fsdem_gic_last_error(gic));
    ck_assert_int_eq(fsdem_coupled_stable_dt(list, 1, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_coupled_stable_dt(list, 1, &dt), FSDEM_OK);
    ck_assert(dt > 0);
    ck_assert_int_eq(fsdem_coupled_advance(list, 1, -1, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert(fsdem_pic_time(pic) == 0 && fsdem_pic_time(elsewhere) == 0 && fsdem_dem_time(sand) == 0 && fsdem_dem_time(bodies) == 0);
    ck_assert_ptr_null(fsdem_gic_coupler(NULL));
    fsdem_gic_destroy(gic);
    fsdem_pic_dem_destroy(body);
    fsdem_dem_destroy(sand);
    fsdem_dem_destroy(bodies);
    fsdem_pic_destroy(pic);
    fsdem_pic_destroy(elsewhere);
}
END_TEST

/* Couplers stepped together take the step whole or not at all (>>couple_step): a sand bed (GIC) and
   a disc (PIC-DEM) on one PIC, the disc leaving its DEM's domain in the substeps after the PIC has
   stepped. Both couplers, the PIC and both DEMs are put back as they were (saved bytes and
   statistics), both couplers carry the message, and with the disc back inside the step runs. */
START_TEST(a_failed_coupled_step_puts_every_solver_back) {
    const double dt = 1e-3;
    fsdem_pic *pic = still_water(0.2, 0.01, 0.1);
    fsdem_dem *sand = dem_over(pic, 2650, 1), *bodies = dem_over(pic, 1500, 0);
    fsdem_gic *gic;
    fsdem_pic_dem *body;
    fsdem_coupler *list[2];
    test_kept sand_before, sand_after, body_before, body_after;
    add_bed(sand, 0.2, 0.02);
    add_disc(bodies, 0.1, 0.06, 0.02, 0);
    gic = gic_on(pic, sand);
    body = pic_dem_on(pic, bodies);
    list[0] = fsdem_gic_coupler(gic);
    list[1] = fsdem_pic_dem_coupler(body);
    ck_assert_int_eq(fsdem_coupled_step_dt(list, 2, (fsdem_real)dt), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_set_particle_state(bodies, 0, fsdem_v3((fsdem_real)(0.2 - 0.5 * dt), 0.06f, 0), fsdem_v3(1, 0, 0),
                                                  fsdem_v3(0, 0, 0)),
                     FSDEM_OK); /* at 1 m/s: out half-way through the step */
    TEST_KEEP(fsdem_gic_save_memory, gic, fsdem_gic_get_stats(gic).coupling, &sand_before);
    TEST_KEEP(fsdem_pic_dem_save_memory, body, fsdem_pic_dem_get_stats(body).coupling, &body_before);
    ck_assert_int_eq(fsdem_coupled_step_dt(list, 2, (fsdem_real)dt), FSDEM_ERR_OUT_OF_DOMAIN);
    ck_assert_msg(strstr(fsdem_gic_last_error(gic), "DEM substeps") && strstr(fsdem_pic_dem_last_error(body), "DEM substeps"), "%s",
                  fsdem_gic_last_error(gic));
    TEST_KEEP(fsdem_gic_save_memory, gic, fsdem_gic_get_stats(gic).coupling, &sand_after);
    TEST_KEEP(fsdem_pic_dem_save_memory, body, fsdem_pic_dem_get_stats(body).coupling, &body_after);
    test_kept_same(&sand_before, &sand_after, "the sand bed's coupler");
    test_kept_same(&body_before, &body_after, "the disc's coupler");
    ck_assert_int_eq(fsdem_dem_set_particle_state(bodies, 0, fsdem_v3(0.1f, 0.06f, 0), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0)), FSDEM_OK);
    ck_assert_msg(fsdem_coupled_step_dt(list, 2, (fsdem_real)dt) == FSDEM_OK, "%s", fsdem_gic_last_error(gic));
    fsdem_pic_dem_destroy(body);
    fsdem_gic_destroy(gic);
    fsdem_dem_destroy(sand);
    fsdem_dem_destroy(bodies);
    fsdem_pic_destroy(pic);
}
END_TEST

/* One PIC serves a sand bed and a body at once: a fixed bed of granules (GIC: the water keeps the
   porosity alpha_f' the bed leaves it) under still water, and a disc of the water's density above
   it (PIC-DEM, the well-balanced weight), stepped together. The discrete hydrostatic state is exact
   for both: the variable-coefficient projection keeps u* = g dt against grad p / rho = g face by
   face whatever the porosity, and the disc's pressure force is rho g V_g on the volume its weight is
   taken on. So after a step of 1 ms the disc moves at the pressure solve's residue (tolerance tau:
   below 10 tau g dt, as the disc alone in neutral_disc_stays_put), and over 0.3 s by the PIC's
   still-water noise only (under 1% of its diameter; measured 2.5e-13 m/s and 0.27%). Both DEMs end
   at the fluid's time (to the rounding of their substeps); the PIC holds the bed's porosity and the
   disc's cut. With the bed's granules not added (an empty GIC) the run is the PIC-DEM's alone, bit
   for bit: the shared step adds nothing but the other coupler.
   (light: run 0 over 0.15 s; the drift bound still tells the balanced weight from the DEM's m g,
   which sinks the disc by 1.4 mm in 0.15 s; the same bounds.) */
START_TEST(one_pic_serves_a_sand_bed_and_a_body) {
    const double L = 0.4, dx = 0.01, R = 0.04, dt = 1e-3, duration = test_light() ? 0.15 : 0.3;
    unsigned char *bytes[2] = {NULL, NULL};
    size_t size[2] = {0, 0};
    int run;
    for (run = 0; run < 3; ++run) {
        /* run 0: bed and disc together; run 1: an empty GIC with the disc; run 2: the disc alone */
        fsdem_pic *pic = still_water(L, dx, 0.35);
        fsdem_dem *sand = dem_over(pic, 2650, 1), *bodies = dem_over(pic, RHO, 0);
        fsdem_gic *gic = NULL;
        fsdem_pic_dem *body;
        fsdem_coupler *list[2];
        const double tau = fsdem_pic_get_desc(pic).pressure_tolerance;
        int n = 1;
        if (run == 0) add_bed(sand, L, 0.06);
        add_disc(bodies, 0.2, 0.2, R, 0);
        if (run < 2) {
            gic = gic_on(pic, sand);
            ck_assert_int_eq(fsdem_gic_update(gic), FSDEM_OK);
            list[0] = fsdem_gic_coupler(gic);
            n = 2;
        }
        body = pic_dem_on(pic, bodies);
        list[n - 1] = fsdem_pic_dem_coupler(body);
        ck_assert_int_eq(fsdem_coupled_step_dt(list, n, (fsdem_real)dt), FSDEM_OK);
        if (run == 0) {
            const double v1 = norm3(fsdem_dem_get_particles(bodies).velocity[0]);
            const fsdem_pic_coupling pc = fsdem_pic_get_coupling(pic);
            fsdem_pic_dem_force f;
            double drift;
            ck_assert_int_eq(fsdem_coupled_advance(list, n, (fsdem_real)(duration - dt), NULL), FSDEM_OK);
            drift = hypot(fsdem_dem_get_particles(bodies).position[0].x - 0.2, fsdem_dem_get_particles(bodies).position[0].y - 0.2);
            ck_assert_int_eq(fsdem_pic_dem_get_force(body, 0, &f), FSDEM_OK);
            TEST_REPORT("sand bed and neutral disc on one PIC: first step %.2e m/s (10 tau g dt = %.2e), drift after %g s %.2e m, "
                        "bed porosity %.3f, %d faces cut",
                        v1, 10 * tau * G * dt, duration, drift, (double)pc.porosity[2 * 40 + 20], f.faces);
            ck_assert_msg(v1 < 10 * tau * G * dt, "the disc starts at %g m/s", v1);
            ck_assert_msg(drift < 0.01 * 2 * R, "the disc drifted %g m", drift);
            ck_assert(pc.porosity[2 * 40 + 20] < 0.6 && pc.porosity[30 * 40 + 20] == 1); /* the bed's, the water's */
            ck_assert(f.faces > 0);
            {
                /* every DEM substep and fluid step adds one rounding of the time */
                const fsdem_coupling_stats a = fsdem_gic_get_stats(gic).coupling, b = fsdem_pic_dem_get_stats(body).coupling;
                const double t = fsdem_pic_time(pic), slack = (double)(a.substeps_total + b.substeps_total + a.steps) * TEST_EPS * t;
                ck_assert_msg(fabs(fsdem_dem_time(sand) - t) <= slack && fabs(fsdem_dem_time(bodies) - t) <= slack,
                              "times: water %.17g, sand %.17g, disc %.17g", t, fsdem_dem_time(sand), fsdem_dem_time(bodies));
            }
            ck_assert(fsdem_gic_get_stats(gic).coupling.steps == fsdem_pic_dem_get_stats(body).coupling.steps);
        } else {
            ck_assert_int_eq(fsdem_coupled_advance(list, n, (fsdem_real)0.05, NULL), FSDEM_OK);
            ck_assert_int_eq(fsdem_pic_dem_save_memory(body, NULL, 0, &size[run - 1]), FSDEM_OK);
            bytes[run - 1] = (unsigned char *)malloc(size[run - 1]);
            ck_assert_int_eq(fsdem_pic_dem_save_memory(body, bytes[run - 1], size[run - 1], &size[run - 1]), FSDEM_OK);
        }
        fsdem_pic_dem_destroy(body);
        fsdem_gic_destroy(gic);
        fsdem_dem_destroy(sand);
        fsdem_dem_destroy(bodies);
        fsdem_pic_destroy(pic);
    }
    ck_assert(size[0] == size[1] && memcmp(bytes[0], bytes[1], size[0]) == 0);
    free(bytes[0]);
    free(bytes[1]);
}
END_TEST

Suite *couple_suite(void) {
    Suite *s = suite_create("couple");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, claims_name_the_holder);
    tcase_add_test(tc, couplers_claim_what_they_write);
    tcase_add_test(tc, coupled_lists_are_checked);
    tcase_add_test(tc, a_failed_coupled_step_puts_every_solver_back);
    tcase_add_test(tc, one_pic_serves_a_sand_bed_and_a_body);
    suite_add_tcase(s, tc);
    return s;
}
