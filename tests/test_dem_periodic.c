/* Periodic DEM boundaries (issue 23 §3, LIGGGHTS `boundary p p f`): contacts across the seam found
   as a brute-force minimum-image search finds them, momentum conserved to rounding in a periodic
   shear box, a contact's tangential history kept as it crosses the seam, a packing invariant under
   a shift by one period (and by a third of one), positions wrapped, restart bit for bit. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fsdem_tests.h"

static unsigned long long rng = 88172645463325252ULL;
static double urand(void) {
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static double nearest(double e, double L) { return L > 0 ? e - L * floor(e / L + 0.5) : e; }

/* A fully periodic 3D box of side L (0.1 m) with n Hertz spheres (radius 3-4 mm, friction 0.5)
   placed without overlap, velocities of a shear u_x = rate (z - L/2) plus noise; no gravity. */
static fsdem_dem *shear_box(int n, double rate) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem *dem;
    const double L = 0.1;
    int k, placed = 0;
    fsdem_vec3 *x = (fsdem_vec3 *)malloc(sizeof(fsdem_vec3) * (size_t)n);
    double *r = (double *)malloc(sizeof(double) * (size_t)n);
    d.domain_min = fsdem_v3(0, 0, 0);
    d.domain_max = fsdem_v3((fsdem_real)L, (fsdem_real)L, (fsdem_real)L);
    d.periodic[0] = d.periodic[1] = d.periodic[2] = 1;
    d.gravity = fsdem_v3(0, 0, 0);
    d.dt = (fsdem_real)2e-5;
    ck_assert_int_eq(fsdem_dem_create(&d, &dem), FSDEM_OK);
    m.friction = (fsdem_real)0.5;
    m.young_modulus = (fsdem_real)1e7;
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_OK);
    while (placed < n) {
        const fsdem_vec3 p = fsdem_v3((fsdem_real)(L * urand()), (fsdem_real)(L * urand()), (fsdem_real)(L * urand()));
        const double radius = 0.003 + 0.001 * urand();
        fsdem_dem_particle_desc q = fsdem_dem_particle_desc_default();
        int free_of_others = 1;
        for (k = 0; k < placed && free_of_others; ++k) {
            const double ex = nearest(p.x - x[k].x, L), ey = nearest(p.y - x[k].y, L), ez = nearest(p.z - x[k].z, L);
            free_of_others = ex * ex + ey * ey + ez * ez > (radius + r[k]) * (radius + r[k]);
        }
        if (!free_of_others) continue;
        x[placed] = p;
        r[placed++] = radius;
        q.position = p;
        q.radius = (fsdem_real)radius;
        q.velocity = fsdem_v3((fsdem_real)(rate * (p.z - L / 2) + 0.05 * (urand() - 0.5)), (fsdem_real)(0.05 * (urand() - 0.5)),
                              (fsdem_real)(0.05 * (urand() - 0.5)));
        ck_assert_int_eq(fsdem_dem_add_particle(dem, &q, NULL), FSDEM_OK);
    }
    free(x);
    free(r);
    return dem;
}

/* Touching pairs by brute force over all pairs with minimum images, against the library's. */
static int brute_force_touching(const fsdem_dem *dem, double L) {
    const fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    int i, j, count = 0;
    for (i = 0; i < p.count; ++i)
        for (j = i + 1; j < p.count; ++j) {
            const double ex = nearest(p.position[i].x - p.position[j].x, L), ey = nearest(p.position[i].y - p.position[j].y, L);
            const double ez = nearest(p.position[i].z - p.position[j].z, L), reach = p.radius[i] + p.radius[j];
            count += ex * ex + ey * ey + ez * ez < reach * reach;
        }
    return count;
}

/* Momentum sum m v over all particles, and the sum of m |v| (its scale). */
static fsdem_vec3 momentum(const fsdem_dem *dem, double *scale) {
    const fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    double s[3] = {0, 0, 0};
    int i;
    *scale = 0;
    for (i = 0; i < p.count; ++i) {
        s[0] += p.mass[i] * p.velocity[i].x;
        s[1] += p.mass[i] * p.velocity[i].y;
        s[2] += p.mass[i] * p.velocity[i].z;
        *scale += p.mass[i] * sqrt((double)p.velocity[i].x * p.velocity[i].x + (double)p.velocity[i].y * p.velocity[i].y +
                                   (double)p.velocity[i].z * p.velocity[i].z);
    }
    return fsdem_v3((fsdem_real)s[0], (fsdem_real)s[1], (fsdem_real)s[2]);
}

/* 1200 spheres (a solid fraction of 0.2) sheared at 20/s for 0.1 s: half of them cross a seam
   (shear speed up to 1 m/s over a 0.1 m period). Contacts act in pairs, equal and opposite: the
   total momentum changes by rounding only, 1e-12 of sum m |v| over 5000 steps (about sqrt(5000 x
   contacts) roundings), and every touching pair a brute-force minimum-image search finds is in the
   lists. */
START_TEST(periodic_shear_box_conserves_momentum) {
    fsdem_dem *dem = shear_box(1200, 20);
    double scale0, scale1;
    const fsdem_vec3 p0 = momentum(dem, &scale0);
    fsdem_vec3 p1;
    fsdem_dem_particles v;
    int k, i, contacts = 0, across = 0;
    for (k = 0; k < 50; ++k) {
        ck_assert_int_eq(fsdem_dem_advance(dem, (fsdem_real)2e-3, NULL), FSDEM_OK);
        contacts += fsdem_dem_get_stats(dem).contacts;
        ck_assert_int_eq(fsdem_dem_contacts(dem, NULL, 0), brute_force_touching(dem, 0.1));
    }
    p1 = momentum(dem, &scale1);
    v = fsdem_dem_get_particles(dem);
    for (i = 0; i < v.count; ++i) { /* wrapped positions */
        ck_assert(v.position[i].x >= 0 && v.position[i].x < 0.1 && v.position[i].y >= 0 && v.position[i].y < 0.1);
        ck_assert(v.position[i].z >= 0 && v.position[i].z < 0.1);
        across += fabs(v.velocity[i].x) * 0.1 > 0.05; /* moved over half a period at least */
    }
    TEST_REPORT("momentum change (%.3g, %.3g, %.3g) of scale %.3g; %d contact-steps sampled; %d fast particles", p1.x - p0.x,
                p1.y - p0.y, p1.z - p0.z, scale0, contacts, across);
    ck_assert(contacts > 100 && across > 100);
    ck_assert(fabs(p1.x - p0.x) < TOL(1e-12, 1e3) * scale0 && fabs(p1.y - p0.y) < TOL(1e-12, 1e3) * scale0 &&
              fabs(p1.z - p0.z) < TOL(1e-12, 1e3) * scale0);
    fsdem_dem_destroy(dem);
}
END_TEST

/* Sphere i rests (gravity -z) on sphere j, which is kinematic and slides along x at 0.5 m/s; i
   starts 0.01 m/s faster, so the tangential spring builds and holds i (mu = 1). Started at x0 =
   0.04 m the pair stays inside the 0.1 m period for the 0.04 s of the run; at x0 = 0.09 m it
   crosses the seam at 0.02 s. The force on i is the same in both runs at every step (to rounding
   of the positions, 1e-9 of it): the spring crossed the seam intact. */
static void slide_run(double x0, double *fx, double *fz, int steps) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_particle_desc q = fsdem_dem_particle_desc_default();
    fsdem_dem *dem;
    int k;
    d.domain_min = fsdem_v3(0, (fsdem_real)-0.05, (fsdem_real)-0.05);
    d.domain_max = fsdem_v3((fsdem_real)0.1, (fsdem_real)0.05, (fsdem_real)0.05);
    d.periodic[0] = 1;
    d.dt = (fsdem_real)1e-5;
    ck_assert_int_eq(fsdem_dem_create(&d, &dem), FSDEM_OK);
    m.friction = 1;
    m.restitution = (fsdem_real)0.1;
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_OK);
    q.radius = (fsdem_real)0.005;
    q.fixed = 1;
    q.position = fsdem_v3((fsdem_real)x0, 0, 0);
    q.velocity = fsdem_v3((fsdem_real)0.5, 0, 0);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &q, NULL), FSDEM_OK);
    q.fixed = 0;
    {
        /* resting at Hertz's static overlap under its weight: (3 m g / (4 E* sqrt(R*)))^(2/3) */
        const double weight = 2500 * 4.0 / 3.0 * 3.14159265358979 * 1.25e-7 * 9.81, es = 1e8 / (2 * (1 - 0.09));
        q.position = fsdem_v3((fsdem_real)x0, 0, (fsdem_real)(0.01 - pow(3 * weight / (4 * es * sqrt(0.0025)), 2.0 / 3.0)));
    }
    q.velocity = fsdem_v3((fsdem_real)0.51, 0, 0);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &q, NULL), FSDEM_OK);
    for (k = 0; k < steps; ++k) {
        ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK);
        fx[k] = fsdem_dem_get_particles(dem).force[1].x;
        fz[k] = fsdem_dem_get_particles(dem).force[1].z;
        ck_assert_int_eq(fsdem_dem_get_stats(dem).contacts, 1);
    }
    /* wrapped: x0 + 0.5 t back into [0, 0.1), after 4000 drifts of 5 um */
    ck_assert(fabs(fsdem_dem_get_particles(dem).position[0].x - fmod(x0 + 0.5 * steps * 1e-5, 0.1)) < TOL(1e-10, 1e5));
    fsdem_dem_destroy(dem);
}

START_TEST(contact_history_crosses_the_seam) {
    enum { STEPS = 4000 };
    static double ax[STEPS], az[STEPS], bx[STEPS], bz[STEPS];
    double worst = 0, largest = 0;
    int k;
    slide_run(0.04, ax, az, STEPS);
    slide_run(0.09, bx, bz, STEPS);
    for (k = 0; k < STEPS; ++k) {
        if (fabs(ax[k] - bx[k]) > worst) worst = fabs(ax[k] - bx[k]);
        if (fabs(ax[k]) > largest) largest = fabs(ax[k]);
        ck_assert(fabs(az[k] - bz[k]) <= TOL(1e-9, 1e6) * fabs(az[k]));
    }
    TEST_REPORT("tangential force up to %.3g N, largest difference %.3g N", largest, worst);
    ck_assert(largest > 1e-3 * fabs(az[STEPS - 1])); /* the spring did build */
    ck_assert(worst <= TOL(1e-9, 1e6) * largest);
}
END_TEST

/* 40 discs dropped on a floor in a 2D box periodic in x (period 0.1 m), for 0.05 s of falls,
   impacts and the first packing. The same run with the domain and every disc moved by one period
   (x + 0.1), and with the discs moved by a third of one within the domain (wrapped), ends with the
   same discs at the same places less the shift, to 1e-9 m: rounding of positions of 0.1-0.2 m,
   grown by the collisions of 2500 steps. */
static void drop(double domain_shift, double disc_shift, fsdem_vec3 *out) {
    fsdem_dem_desc d = fsdem_dem_desc_default(2);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_wall_desc floor_wall;
    fsdem_dem *dem;
    int k;
    rng = 2463534242ULL;
    d.domain_min = fsdem_v3((fsdem_real)domain_shift, 0, 0);
    d.domain_max = fsdem_v3((fsdem_real)(domain_shift + 0.1), (fsdem_real)0.3, 0);
    d.periodic[0] = 1;
    d.dt = (fsdem_real)2e-5;
    ck_assert_int_eq(fsdem_dem_create(&d, &dem), FSDEM_OK);
    m.friction = (fsdem_real)0.4;
    m.young_modulus = (fsdem_real)1e6;
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_OK);
    floor_wall = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 1, 0), 0);
    ck_assert_int_eq(fsdem_dem_add_wall(dem, &floor_wall, NULL), FSDEM_OK);
    for (k = 0; k < 40; ++k) {
        fsdem_dem_particle_desc q = fsdem_dem_particle_desc_default();
        const double x = 0.0125 * (k % 8) + 0.004 * urand();
        q.position = fsdem_v3((fsdem_real)(domain_shift + fmod(x + disc_shift, 0.1)), (fsdem_real)(0.01 + 0.012 * (k / 8)), 0);
        q.radius = (fsdem_real)(0.004 + 0.001 * urand());
        q.velocity = fsdem_v3((fsdem_real)(0.2 * (urand() - 0.5)), 0, 0);
        ck_assert_int_eq(fsdem_dem_add_particle(dem, &q, NULL), FSDEM_OK);
    }
    ck_assert_int_eq(fsdem_dem_advance(dem, 0.05f, NULL), FSDEM_OK);
    memcpy(out, fsdem_dem_get_particles(dem).position, sizeof(fsdem_vec3) * 40);
    fsdem_dem_destroy(dem);
}

START_TEST(periodic_packing_is_invariant_under_a_shift) {
    fsdem_vec3 a[40], b[40], c[40];
    double worst_b = 0, worst_c = 0;
    int k;
    drop(0, 0, a);
    drop(0.1, 0, b);
    drop(0, 0.1 / 3, c);
    for (k = 0; k < 40; ++k) {
        const double eb = hypot(nearest(b[k].x - 0.1 - a[k].x, 0.1), b[k].y - a[k].y);
        const double ec = hypot(nearest(c[k].x - 0.1 / 3 - a[k].x, 0.1), c[k].y - a[k].y);
        if (eb > worst_b) worst_b = eb;
        if (ec > worst_c) worst_c = ec;
    }
    TEST_REPORT("largest displacement from the unshifted run: %.3g m (one period), %.3g m (a third)", worst_b, worst_c);
    ck_assert(worst_b < TOL(1e-9, 1e5) && worst_c < TOL(1e-9, 1e5));
    ck_assert(a[0].y < 0.05); /* it fell */
}
END_TEST

/* A period shorter than twice the neighbour reach, a periodic z in 2D, and restart of a periodic
   run (bit for bit from memory). */
START_TEST(periodic_input_and_restart) {
    fsdem_dem_desc d = fsdem_dem_desc_default(2);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_particle_desc q = fsdem_dem_particle_desc_default();
    fsdem_dem *a, *b;
    char msg[256];
    size_t n = 0, n2 = 0;
    unsigned char *buf, *buf2;
    d.periodic[2] = 1;
    ck_assert_int_eq(fsdem_dem_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(msg, "periodic[2]"));
    d.periodic[2] = 0;
    d.periodic[0] = 1; /* period 2 m */
    ck_assert_int_eq(fsdem_dem_create(&d, &a), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(a, &m, NULL), FSDEM_OK);
    q.radius = (fsdem_real)0.5; /* reach 2.125 m: two images in reach */
    ck_assert_int_eq(fsdem_dem_add_particle(a, &q, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(fsdem_dem_last_error(a), "period"));
    q.radius = (fsdem_real)0.1;
    q.position = fsdem_v3((fsdem_real)0.95, 0, 0);
    q.velocity = fsdem_v3(3, 0, 0);
    ck_assert_int_eq(fsdem_dem_add_particle(a, &q, NULL), FSDEM_OK);
    q.position = fsdem_v3((fsdem_real)-0.95, (fsdem_real)0.05, 0);
    q.velocity = fsdem_v3(-3, 0, 0);
    ck_assert_int_eq(fsdem_dem_add_particle(a, &q, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_advance(a, 0.01f, NULL), FSDEM_OK); /* they meet across the seam */
    ck_assert_int_eq(fsdem_dem_save_memory(a, NULL, 0, &n), FSDEM_OK);
    buf = (unsigned char *)malloc(n);
    ck_assert_int_eq(fsdem_dem_save_memory(a, buf, n, &n), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_create(&d, &b), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_restore_memory(b, buf, n), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_advance(a, 0.05f, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_advance(b, 0.05f, NULL), FSDEM_OK);
    ck_assert(fsdem_dem_get_particles(a).velocity[0].x < 0); /* they bounced off each other across the seam */
    ck_assert_int_eq(fsdem_dem_save_memory(a, buf, n, &n), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_save_memory(b, NULL, 0, &n2), FSDEM_OK);
    buf2 = (unsigned char *)malloc(n2);
    ck_assert_int_eq(fsdem_dem_save_memory(b, buf2, n2, &n2), FSDEM_OK);
    ck_assert(n == n2 && memcmp(buf, buf2, n) == 0);
    d.periodic[0] = 0;
    fsdem_dem_destroy(b);
    ck_assert_int_eq(fsdem_dem_create(&d, &b), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_restore_memory(b, buf, n), FSDEM_ERR_INVALID_ARG); /* the desc differs */
    ck_assert_ptr_nonnull(strstr(fsdem_dem_last_error(b), "periodic"));
    free(buf);
    free(buf2);
    fsdem_dem_destroy(a);
    fsdem_dem_destroy(b);
}
END_TEST

Suite *dem_periodic_suite(void) {
    Suite *s = suite_create("dem_periodic");
    TCase *tc = tcase_create("dem_periodic");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, periodic_shear_box_conserves_momentum);
    tcase_add_test(tc, contact_history_crosses_the_seam);
    tcase_add_test(tc, periodic_packing_is_invariant_under_a_shift);
    tcase_add_test(tc, periodic_input_and_restart);
    suite_add_tcase(s, tc);
    return s;
}
