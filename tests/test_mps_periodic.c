/* MPS boundaries: periodic axes (desc.periodic), inflow and outflow planes, the no-slip ghost
   velocities of the walls (desc.wall_viscosity) and the pressure of a liquid without a free
   surface. */
#include "fsdem_tests.h"

#define TEST_PI 3.14159265358979323846

/* A channel periodic along x (and z in 3D), `cells` spacings r0 per period, between walls at y = 0
   and y = rows r0, full of liquid at rest, with the body force (gx, 0, 0) and viscosity nu. */
static fsdem_mps *test_channel(int dim, double r0, int rows, int cells, double gx, double nu, fsdem_mps_wall_viscosity walls) {
    const double H = rows * r0, L = cells * r0;
    fsdem_mps_desc d = fsdem_mps_desc_default_scheme(dim, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_mps *m = NULL;
    unsigned open = (1u << FSDEM_SIDE_XMIN) | (1u << FSDEM_SIDE_XMAX);
    d.r0 = (fsdem_real)r0;
    d.viscosity = (fsdem_real)nu;
    d.wall_viscosity = walls;
    d.gravity = fsdem_v3((fsdem_real)gx, 0, 0);
    d.dt_max = 1;
    d.domain_min = fsdem_v3(0, (fsdem_real)(-6 * r0), 0);
    d.domain_max = fsdem_v3((fsdem_real)L, (fsdem_real)(H + 6 * r0), (fsdem_real)(dim == 3 ? L : 0));
    d.periodic[0] = 1;
    if (dim == 3) {
        d.periodic[2] = 1;
        open |= (1u << FSDEM_SIDE_ZMIN) | (1u << FSDEM_SIDE_ZMAX);
    }
    ck_assert_int_eq(fsdem_mps_create(&d, &m), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_add_box_walls(m, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)L, (fsdem_real)H, (fsdem_real)(dim == 3 ? L : 0)),
                                             open, NULL),
                     FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_fill_box(m, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)L, (fsdem_real)H, (fsdem_real)(dim == 3 ? L : 0)),
                                        fsdem_v3(0, 0, 0), NULL),
                     FSDEM_OK);
    return m;
}

/* Runs the channel to t = 0.6 H^2/nu and returns the largest |u_x - u_exact| of a FLUID particle
   over u_max = gx H^2 / (8 nu), the parabola u = gx/(2 nu) y (H - y) with no slip at the box faces;
   *cross gets the largest |u_y| / u_max, *spread the pressure range / (rho u_max^2). */
static double test_poiseuille_error(int dim, double r0, int rows, int cells, fsdem_mps_wall_viscosity walls, double *cross,
                                    double *spread) {
    const double H = rows * r0, nu = 1e-2, gx = 0.1, umax = gx * H * H / (8 * nu);
    fsdem_mps *m = test_channel(dim, r0, rows, cells, gx, nu, walls);
    fsdem_mps_particles p;
    double err = 0, pmin = 1e300, pmax = -1e300;
    int i;
    ck_assert_int_eq(fsdem_mps_advance(m, (fsdem_real)(0.6 * H * H / nu), NULL), FSDEM_OK);
    p = fsdem_mps_get_particles(m);
    *cross = 0;
    for (i = 0; i < p.count; ++i) {
        double y, e;
        if (p.kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        y = p.position[i].y;
        e = fabs(p.velocity[i].x - gx / (2 * nu) * y * (H - y)) / umax;
        if (e > err) err = e;
        if (fabs(p.velocity[i].y) / umax > *cross) *cross = fabs(p.velocity[i].y) / umax;
        if (p.pressure[i] < pmin) pmin = p.pressure[i];
        if (p.pressure[i] > pmax) pmax = p.pressure[i];
    }
    *spread = (pmax - pmin) / (1000 * umax * umax);
    fsdem_mps_destroy(m);
    return err;
}

/* Plane Poiseuille flow from rest in a periodic channel (issue 19: within 2 % of the parabola,
   2D and 3D). With the no-slip ghosts the discrete steady state of the lattice is 6.2 / 1.8 /
   0.6 % off the parabola at 10 / 20 / 40 rows (2D; the method's second-order wall error), and at
   t = 0.6 H^2/nu the slowest transient, exp(-pi^2 0.6) 32/pi^3 of u_max, is within 0.3 %;
   measured: 0.81 % (2D, 30 rows) and 1.15 % (3D, 24 rows), so the 2 % line holds with room. The old wall (WALL particles at rest, DUMMY
   particles out of Eq. 10) stays 24 % fast: the test tells them apart. The liquid has no free
   surface (the singular pressure equation of a closed box): nothing flows across the channel and
   the pressure stays uniform to a small fraction of rho u_max^2.
   (light: the same channels at three times the spacing, r0 = 3 cm: 10 rows in 2D, 8 in 3D; the
   wall error of the lattice is second order, 6.2 % at 10 rows, so the parabola is held to 7 % in
   2D and 10 % in 3D (measured 5.3 % and 7.7 %); the walls at rest stay 74 % off; the cross flow
   and the pressure range hold to the same bounds.) */
START_TEST(test_mps_poiseuille) {
    const int light = test_light();
    const double r0 = light ? 0.03 : 0.01;
    double cross, spread, err;
    err = test_poiseuille_error(2, r0, light ? 10 : 30, 16, FSDEM_MPS_WALL_VISCOSITY_NO_SLIP, &cross, &spread);
    ck_assert_msg(err < (light ? 0.07 : 0.02), "2D Poiseuille: %.4f of u_max off the parabola", err);
    ck_assert_msg(cross < 1e-2, "2D Poiseuille: cross flow %.2e u_max", cross);
    ck_assert_msg(spread < 0.05, "2D Poiseuille: pressure range %.3f rho u_max^2", spread);
    err = test_poiseuille_error(2, r0, light ? 10 : 30, 16, FSDEM_MPS_WALL_VISCOSITY_AT_REST, &cross, &spread);
    ck_assert_msg(err > 0.15, "2D Poiseuille with the walls at rest: %.4f of u_max off the parabola", err);
    /* 3D: 9 spacings per period, the smallest above 2 re = 8.2 r0 */
    err = test_poiseuille_error(3, r0, light ? 8 : 24, 9, FSDEM_MPS_WALL_VISCOSITY_NO_SLIP, &cross, &spread);
    ck_assert_msg(err < (light ? 0.1 : 0.02), "3D Poiseuille: %.4f of u_max off the parabola", err);
    ck_assert_msg(cross < 1e-2, "3D Poiseuille: cross flow %.2e u_max", cross);
}
END_TEST

/* A tank periodic along x, `copies` periods of 16 spacings (r0 = 1/64 m, dyadic, so lattice
   positions and their shifts by a period are exact), water 0.25 m deep over a floor, moving with
   u_y = 0.05 sin(2 pi x / P) m/s, P one period, each copy alike; the domain starts at x0. */
static fsdem_mps *test_periodic_tank(int copies, double x0) {
    const double r0 = 1.0 / 64, P = 16 * r0, depth = 0.25;
    fsdem_mps_desc d = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_mps *m = NULL;
    fsdem_mps_particles p;
    int i;
    d.r0 = (fsdem_real)r0;
    d.domain_min = fsdem_v3((fsdem_real)x0, -0.125f, 0);
    d.domain_max = fsdem_v3((fsdem_real)(x0 + copies * P), 0.5f, 0);
    d.periodic[0] = 1;
    ck_assert_int_eq(fsdem_mps_create(&d, &m), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_add_box_walls(m, fsdem_v3((fsdem_real)x0, 0, 0), fsdem_v3((fsdem_real)(x0 + copies * P), 0.375f, 0),
                                             (1u << FSDEM_SIDE_XMIN) | (1u << FSDEM_SIDE_XMAX) | (1u << FSDEM_SIDE_YMAX), NULL),
                     FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_fill_box(m, fsdem_v3((fsdem_real)x0, 0, 0), fsdem_v3((fsdem_real)(x0 + copies * P), (fsdem_real)depth, 0),
                                        fsdem_v3(0, 0, 0), NULL),
                     FSDEM_OK);
    p = fsdem_mps_get_particles(m);
    for (i = 0; i < p.count; ++i)
        if (p.kind[i] == FSDEM_MPS_KIND_FLUID)
            p.velocity[i].y = (fsdem_real)(0.05 * sin(2 * TEST_PI * (p.position[i].x - x0) / P));
    return m;
}

/* A tank of one period and one of two periods holding the same motion twice: every particle of
   either copy follows its partner of the one-period tank, whose neighbours across the seam are
   images, to rounding (1e-6 r0 after 0.1 s, 1000 eps r0 in float, allows the growth of rounding
   differences by many orders; a seam that lost or doubled a neighbour would be off by a sizeable
   part of r0). */
START_TEST(test_mps_periodic_seam) {
    const double r0 = 1.0 / 64;
    fsdem_mps *one = test_periodic_tank(1, 0), *two = test_periodic_tank(2, 0);
    fsdem_mps_particles a, b;
    double worst = 0, moved = 0;
    int i, k;
    ck_assert_int_eq(fsdem_mps_advance(one, 0.1f, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_advance(two, 0.1f, NULL), FSDEM_OK);
    a = fsdem_mps_get_particles(one);
    b = fsdem_mps_get_particles(two);
    /* the fills go row by row along x: the two-period tank's row holds each row of the other twice */
    for (i = 0; i < b.count; ++i) {
        const double x = b.position[i].x, y = b.position[i].y;
        double best = 1e300;
        if (b.kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        for (k = 0; k < a.count; ++k) {
            double dx, dy;
            if (a.kind[k] != FSDEM_MPS_KIND_FLUID) continue;
            dx = fmod(x - a.position[k].x + 2.5 * 16 * r0, 16 * r0) - 0.5 * 16 * r0;
            dy = y - a.position[k].y;
            if (dx * dx + dy * dy < best) best = dx * dx + dy * dy;
        }
        if (sqrt(best) > worst) worst = sqrt(best);
    }
    for (i = 0; i < a.count; ++i)
        if (a.kind[i] == FSDEM_MPS_KIND_FLUID && fabs(a.velocity[i].y) > moved) moved = fabs(a.velocity[i].y);
    ck_assert_msg(moved > 0.01, "the water is moving (%.3g m/s)", moved);
    ck_assert_msg(worst < TOL(1e-6, 1e3) * r0, "a particle of the two-period tank is %.3g r0 from every image of the one-period tank", worst / r0);
    fsdem_mps_destroy(one);
    fsdem_mps_destroy(two);
}
END_TEST

/* Issue 19: a periodic box of water is bitwise symmetric under a shift by one period. The same
   particles, given once at x and once at x + P (wrapped into the domain as they are added, exactly:
   dyadic positions), run identically, bit for bit; that only shows nothing keeps the image a
   particle was given. Shifted by 5 r0 instead, the seam falls between other particles: each
   particle follows its partner to rounding (1e-6 r0 after 0.1 s, as in test_mps_periodic_seam). */
START_TEST(test_mps_periodic_shift) {
    const double r0 = 1.0 / 64, P = 16 * r0;
    fsdem_mps *a = test_periodic_tank(1, 0), *b = NULL, *c = NULL;
    fsdem_mps_desc d = fsdem_mps_get_desc(a);
    fsdem_mps_particles p = fsdem_mps_get_particles(a), q;
    double worst = 0;
    int i;
    ck_assert_int_eq(fsdem_mps_create(&d, &b), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_create(&d, &c), FSDEM_OK);
    for (i = 0; i < p.count; ++i) {
        const fsdem_vec3 x = fsdem_v3((fsdem_real)(p.position[i].x + P), p.position[i].y, 0);
        const fsdem_vec3 y = fsdem_v3((fsdem_real)(p.position[i].x + 5 * r0), p.position[i].y, 0);
        ck_assert_int_eq(fsdem_mps_add_particles(b, (fsdem_mps_kind)p.kind[i], 1, &x, &p.velocity[i]), FSDEM_OK);
        ck_assert_int_eq(fsdem_mps_add_particles(c, (fsdem_mps_kind)p.kind[i], 1, &y, &p.velocity[i]), FSDEM_OK);
    }
    test_same_run(a, b, 40);
    for (i = 0; i < 40; ++i) ck_assert_int_eq(fsdem_mps_step(c), FSDEM_OK);
    p = fsdem_mps_get_particles(a);
    q = fsdem_mps_get_particles(c);
    for (i = 0; i < p.count; ++i) {
        const double dx = fmod(q.position[i].x - p.position[i].x - 5 * r0 + 2.5 * P, P) - 0.5 * P, dy = q.position[i].y - p.position[i].y;
        if (sqrt(dx * dx + dy * dy) > worst) worst = sqrt(dx * dx + dy * dy);
    }
    ck_assert_msg(worst < TOL(1e-6, 1e3) * r0, "a particle shifted by 5 r0 is %.3g r0 off its partner", worst / r0);
    fsdem_mps_destroy(a);
    fsdem_mps_destroy(b);
    fsdem_mps_destroy(c);
}
END_TEST

/* A channel 0.3 m long between walls at y = 0 and 0.1 m (r0 = 0.01 m), no gravity, liquid at
   0.1 m/s fed by an inflow at x = 0 and leaving through an outflow at x = 0.3 m. */
static fsdem_mps *test_open_channel(void) {
    const fsdem_real L = 0.3f, H = 0.1f, U = 0.1f, depth = 0.05f;
    fsdem_mps_desc d = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_mps_inflow_desc in;
    fsdem_mps_outflow_desc out;
    fsdem_mps *m = NULL;
    int added = 0;
    d.gravity = fsdem_v3(0, 0, 0);
    d.domain_min = fsdem_v3(-0.1f, -0.1f, 0);
    d.domain_max = fsdem_v3(0.4f, 0.2f, 0);
    ck_assert_int_eq(fsdem_mps_create(&d, &m), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_add_box_walls(m, fsdem_v3(-depth, 0, 0), fsdem_v3(L + depth, H, 0),
                                             (1u << FSDEM_SIDE_XMIN) | (1u << FSDEM_SIDE_XMAX), NULL),
                     FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_fill_box(m, fsdem_v3(0, 0, 0), fsdem_v3(L, H, 0), fsdem_v3(U, 0, 0), NULL), FSDEM_OK);
    in = fsdem_mps_inflow_desc_default(); /* axis 0, direction +1 */
    in.position = 0;
    in.lo = fsdem_v3(0, 0, 0);
    in.hi = fsdem_v3(0, H, 0);
    in.speed = U;
    ck_assert_int_eq(fsdem_mps_add_inflow(m, &in, &added), FSDEM_OK);
    ck_assert_int_eq(added, 5 * 10); /* ceil(4.1) = 5 layers of 10 */
    out = fsdem_mps_outflow_desc_default();
    out.position = L;
    out.hi = fsdem_v3(0, H, 0);
    ck_assert_int_eq(fsdem_mps_add_outflow(m, &out), FSDEM_OK);
    return m;
}

/* The liquid between the planes in units of the initial: each FLUID particle (buffers included) a
   slab r0 wide along x, the part of it inside [0, 0.3] m counted (so a column crossing a plane
   counts in proportion, and a plug flow keeps the sum exactly). */
static double test_open_volume(fsdem_mps *m) {
    const double r0 = 0.01, L = 0.3;
    fsdem_mps_particles p = fsdem_mps_get_particles(m);
    double v = 0;
    int i;
    for (i = 0; i < p.count; ++i) {
        double a, b;
        if (p.kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        a = p.position[i].x - r0 / 2 > 0 ? p.position[i].x - r0 / 2 : 0;
        b = p.position[i].x + r0 / 2 < L ? p.position[i].x + r0 / 2 : L;
        if (b > a) v += (b - a) / r0;
    }
    return v / 300;
}

/* Issue 19: a steady inflow/outflow channel keeps its volume within 0.5 % over 2 s. The buffer
   feeds a column of 10 particles each 0.1 s (U / r0 columns per second) and the outflow removes
   as many: 200 in, 200 - 10 x 5 out in 2 s (the first columns need 0.5 s to cross the outflow
   zone);
   the liquid keeps its speed. (With a free surface and gravity the p = 0 of the outflow plane
   drains the channel, as a free overfall: a hydrostatic outflow condition is not offered.)
   (light: 0.81 s, 15 samples instead of 37: 81 in and 81 - 50 out, checked to a column either
   way as the 2 s run's counts; the same volume and speed bounds.) */
START_TEST(test_mps_open_channel) {
    const int light = test_light();
    fsdem_mps *m = test_open_channel();
    fsdem_mps_stats st;
    fsdem_mps_particles p;
    double worst = 0, slowest = 1, fastest = 0;
    int k, i;
    for (k = 0; k < (light ? 15 : 37); ++k) { /* sampled every 0.054 s, off the lattice's period r0 / U */
        const double v = test_open_volume(m);
        if (fabs(v - 1) > worst) worst = fabs(v - 1);
        ck_assert_int_eq(fsdem_mps_advance(m, 0.054f, NULL), FSDEM_OK);
    }
    ck_assert_msg(worst < 0.005, "the channel's volume changed by %.4f", worst);
    st = fsdem_mps_get_stats(m);
    ck_assert_msg(st.inflow_particles >= (light ? 70 : 190) && st.inflow_particles <= (light ? 90 : 210), "%lld particles in",
                  st.inflow_particles);
    ck_assert_msg(st.outflow_particles >= (light ? 20 : 140) && st.outflow_particles <= (light ? 40 : 160), "%lld particles out",
                  st.outflow_particles);
    p = fsdem_mps_get_particles(m);
    for (i = 0; i < p.count; ++i)
        if (p.kind[i] == FSDEM_MPS_KIND_FLUID && p.inflow[i] < 0) {
            if (p.velocity[i].x < slowest) slowest = p.velocity[i].x;
            if (p.velocity[i].x > fastest) fastest = p.velocity[i].x;
        }
    ck_assert_msg(slowest > 0.09 && fastest < 0.11, "speeds %.4f .. %.4f m/s", slowest, fastest);
    {   /* after a step that removed particles, its matrix's rows name particles of the new
           numbering: ascending, in range, none a DUMMY, none removed (particles past the plane
           have p = 0: no row); a row list shifted along with the particles would still pass */
        const int *rows_particle = NULL;
        const long long before = st.outflow_particles;
        fsdem_csr A;
        int r, last = -1, gone = 0;
        for (k = 0; k < 1000 && fsdem_mps_get_stats(m).outflow_particles == before; ++k) ck_assert_int_eq(fsdem_mps_step(m), FSDEM_OK);
        ck_assert(fsdem_mps_get_stats(m).outflow_particles > before);
        A = fsdem_mps_pressure_matrix(m, &rows_particle);
        p = fsdem_mps_get_particles(m);
        ck_assert_int_gt(A.rows, 0);
        for (r = 0; r < A.rows; ++r) {
            if (rows_particle[r] < 0) {
                gone++;
                continue;
            }
            ck_assert_int_lt(rows_particle[r], p.count);
            ck_assert_int_gt(rows_particle[r], last);
            ck_assert_int_ne(p.kind[rows_particle[r]], FSDEM_MPS_KIND_DUMMY);
            last = rows_particle[r];
        }
        ck_assert_int_eq(gone, 0);
    }
    fsdem_mps_destroy(m);
}
END_TEST

/* A run saved and restored mid-way continues as the uninterrupted one, bit for bit, with its
   inflow buffer and outflow (removals renumber particles, so the counts and order must survive). */
START_TEST(test_mps_open_restart) {
    fsdem_mps *a = test_open_channel(), *b = NULL;
    const fsdem_mps_desc d = fsdem_mps_get_desc(a);
    size_t size = 0;
    void *buffer;
    ck_assert_int_eq(fsdem_mps_advance(a, 0.6f, NULL), FSDEM_OK);
    ck_assert_int_gt(fsdem_mps_get_stats(a).outflow_particles, 0);
    ck_assert_int_eq(fsdem_mps_save_memory(a, NULL, 0, &size), FSDEM_OK);
    buffer = malloc(size);
    ck_assert_int_eq(fsdem_mps_save_memory(a, buffer, size, &size), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_create(&d, &b), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_restore_memory(b, buffer, size), FSDEM_OK);
    test_same_run(a, b, 30);
    ck_assert_int_eq((int)fsdem_mps_get_stats(a).outflow_particles, (int)fsdem_mps_get_stats(b).outflow_particles);
    free(buffer);
    fsdem_mps_destroy(a);
    fsdem_mps_destroy(b);
}
END_TEST

/* Open planes along a periodic axis, outside the domain, with a bad direction or speed are refused
   by name, and nothing is added. */
START_TEST(test_mps_open_bad_input) {
    fsdem_mps *m = test_open_channel();
    const int n = fsdem_mps_get_particles(m).count;
    fsdem_mps_inflow_desc in;
    fsdem_mps_outflow_desc out;
    in = fsdem_mps_inflow_desc_default();
    out = fsdem_mps_outflow_desc_default();
    in.position = -0.08f; /* the buffer would reach -0.13 m < domain_min.x */
    in.hi = fsdem_v3(0, 0.1f, 0);
    in.speed = 0.1f;
    ck_assert_int_eq(fsdem_mps_add_inflow(m, &in, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(fsdem_mps_last_error(m), "fsdem_mps_inflow_desc.position"));
    in.position = 0;
    in.direction = 0;
    ck_assert_int_eq(fsdem_mps_add_inflow(m, &in, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(fsdem_mps_last_error(m), "fsdem_mps_inflow_desc.direction"));
    in.direction = 1;
    in.speed = -1;
    ck_assert_int_eq(fsdem_mps_add_inflow(m, &in, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(fsdem_mps_last_error(m), "fsdem_mps_inflow_desc.speed"));
    in.speed = 0.1f;
    in.axis = 2;
    ck_assert_int_eq(fsdem_mps_add_inflow(m, &in, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(fsdem_mps_last_error(m), "fsdem_mps_inflow_desc.axis"));
    out.axis = 0;
    out.direction = 1;
    out.hi = fsdem_v3(0, 0.1f, 0);
    out.position = 0.38f; /* its zone would end at 0.43 m > domain_max.x */
    ck_assert_int_eq(fsdem_mps_add_outflow(m, &out), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(fsdem_mps_last_error(m), "fsdem_mps_outflow_desc.position"));
    /* issue 34: an inlet of +-1e300 m overflowed the lattice count; the same plane twice, or a plane
       in the liquid, put particles on top of others; an outflow on the inflow plane or upstream of
       it removed the liquid fed in */
    in.axis = 0;
    in.lo = fsdem_v3(0, (fsdem_real)(TEST_FLOAT ? -1e30 : -1e300), 0); /* float's range ends near 3e38 */
    in.hi = fsdem_v3(0, (fsdem_real)(TEST_FLOAT ? 1e30 : 1e300), 0);
    ck_assert_int_eq(fsdem_mps_add_inflow(m, &in, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(fsdem_mps_last_error(m), "fsdem_mps_inflow_desc.lo/hi"));
    in.lo = fsdem_v3(0, 0, 0);
    in.hi = fsdem_v3(0, 0.1f, 0);
    ck_assert_int_eq(fsdem_mps_add_inflow(m, &in, NULL), FSDEM_ERR_INVALID_ARG); /* the channel's own inflow again */
    ck_assert(strstr(fsdem_mps_last_error(m), "buffer zone"));
    in.position = 0.15f; /* its buffer, 0.10 to 0.15 m, in the liquid */
    ck_assert_int_eq(fsdem_mps_add_inflow(m, &in, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(fsdem_mps_last_error(m), "buffer zone"));
    out.position = 0; /* on the inflow plane */
    ck_assert_int_eq(fsdem_mps_add_outflow(m, &out), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(fsdem_mps_last_error(m), "not downstream"));
    out.position = -0.02f; /* upstream of it */
    ck_assert_int_eq(fsdem_mps_add_outflow(m, &out), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(fsdem_mps_last_error(m), "not downstream"));
    out.position = 0.2f; /* downstream, but facing back at the inflow */
    out.direction = -1;
    ck_assert_int_eq(fsdem_mps_add_outflow(m, &out), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(fsdem_mps_last_error(m), "not downstream"));
    ck_assert_int_eq(fsdem_mps_get_particles(m).count, n);
    ck_assert_int_eq(fsdem_mps_get_stats(m).inflow_planes, 1);
    ck_assert_int_eq(fsdem_mps_get_stats(m).outflow_planes, 1);
    {   /* a coupler cannot follow the particles open planes add and remove */
        fsdem_dem_desc dd = fsdem_dem_desc_default(2);
        fsdem_mps_desc md = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
        fsdem_dem *dem = NULL;
        fsdem_mps_dem *c = NULL;
        fsdem_mps_dem_desc cd = fsdem_mps_dem_desc_default();
        char msg[256];
        dd.domain_min = fsdem_v3(-0.1f, -0.1f, 0);
        dd.domain_max = fsdem_v3(0.4f, 0.2f, 0);
        dd.gravity = fsdem_v3(0, 0, 0);
        ck_assert_int_eq(fsdem_dem_create(&dd, &dem), FSDEM_OK);
        cd.mps = m;
        cd.dem = dem;
        ck_assert_int_eq(fsdem_mps_dem_desc_check(&cd, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
        ck_assert(strstr(msg, "inflows or outflows"));
        /* ... nor can open planes be added to an MPS a coupler holds, before its first step too */
        fsdem_mps_destroy(m);
        md.gravity = dd.gravity;
        md.domain_min = dd.domain_min;
        md.domain_max = dd.domain_max;
        ck_assert_int_eq(fsdem_mps_create(&md, &m), FSDEM_OK);
        cd.mps = m;
        ck_assert_int_eq(fsdem_mps_dem_create(&cd, &c), FSDEM_OK);
        in.position = 0;
        ck_assert_int_eq(fsdem_mps_add_inflow(m, &in, NULL), FSDEM_ERR_INVALID_ARG);
        ck_assert(strstr(fsdem_mps_last_error(m), "fsdem_mps_dem"));
        out.direction = 1;
        out.position = 0.3f;
        ck_assert_int_eq(fsdem_mps_add_outflow(m, &out), FSDEM_ERR_INVALID_ARG);
        ck_assert(strstr(fsdem_mps_last_error(m), "fsdem_mps_dem"));
        fsdem_mps_dem_destroy(c);
        fsdem_dem_destroy(dem);
    }
    fsdem_mps_destroy(m);
    m = test_periodic_tank(1, 0);
    out.position = 0.125f;
    ck_assert_int_eq(fsdem_mps_add_outflow(m, &out), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(fsdem_mps_last_error(m), "periodic"));
    fsdem_mps_destroy(m);
}
END_TEST

/* Periods the lattice cannot tile or the minimum image cannot resolve are refused by name, as
   are periodic flags that are not 0/1 or name z in 2D, a wall option that does not exist, and a
   coupler over a periodic MPS (its averaging does not wrap). */
START_TEST(test_mps_periodic_bad_input) {
    fsdem_mps_desc d = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    char msg[256];
    d.domain_max = fsdem_v3(0.105f, 1, 0); /* 10.5 r0 */
    d.periodic[0] = 1;
    ck_assert_int_eq(fsdem_mps_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(msg, "fsdem_mps_desc.periodic[0]") == msg && strstr(msg, "whole number"));
    d.domain_max = fsdem_v3(0.08f, 1, 0); /* 8 r0 < 2 re = 8.2 r0 */
    ck_assert_int_eq(fsdem_mps_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(msg, "fsdem_mps_desc.periodic[0]") == msg && strstr(msg, "2 re"));
    d.domain_max = fsdem_v3(0.09f, 1, 0); /* 9 r0: accepted */
    ck_assert_int_eq(fsdem_mps_desc_check(&d, msg, sizeof msg), FSDEM_OK);
    d.periodic[0] = 2;
    ck_assert_int_eq(fsdem_mps_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(msg, "fsdem_mps_desc.periodic[0] = 2") == msg);
    d.periodic[0] = 0;
    d.periodic[2] = 1;
    ck_assert_int_eq(fsdem_mps_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(msg, "fsdem_mps_desc.periodic[2]") == msg);
    d.periodic[2] = 0;
    {   /* walls whose sides across a periodic axis are not opened get them opened */
        fsdem_mps *m = NULL;
        int open = 0, closed = 0;
        d.domain_max = fsdem_v3(0.16f, 1, 0);
        d.periodic[0] = 1;
        ck_assert_int_eq(fsdem_mps_create(&d, &m), FSDEM_OK);
        ck_assert_int_eq(fsdem_mps_add_box_walls(m, fsdem_v3(0, 0.1f, 0), fsdem_v3(0.16f, 0.3f, 0),
                                                 (1u << FSDEM_SIDE_XMIN) | (1u << FSDEM_SIDE_XMAX), &open), FSDEM_OK);
        ck_assert_int_eq(fsdem_mps_add_box_walls(m, fsdem_v3(0, 0.5f, 0), fsdem_v3(0.16f, 0.7f, 0), 0, &closed), FSDEM_OK);
        ck_assert_int_eq(open, 2 * 5 * 16);
        ck_assert_int_eq(closed, open);
        fsdem_mps_destroy(m);
        d.periodic[0] = 0;
    }
    d.wall_viscosity = (fsdem_mps_wall_viscosity)2;
    ck_assert_int_eq(fsdem_mps_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert(strstr(msg, "fsdem_mps_desc.wall_viscosity") == msg);
    {
        fsdem_mps *mps = test_periodic_tank(1, 0);
        fsdem_dem_desc dd = fsdem_dem_desc_default(2);
        fsdem_dem *dem = NULL;
        fsdem_mps_dem_desc cd = fsdem_mps_dem_desc_default();
        dd.domain_min = fsdem_v3(0, -0.125f, 0);
        dd.domain_max = fsdem_v3(0.25f, 0.5f, 0);
        dd.gravity = fsdem_mps_get_desc(mps).gravity;
        ck_assert_int_eq(fsdem_dem_create(&dd, &dem), FSDEM_OK);
        cd.mps = mps;
        cd.dem = dem;
        ck_assert_int_eq(fsdem_mps_dem_desc_check(&cd, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
        ck_assert(strstr(msg, "periodic"));
        fsdem_dem_destroy(dem);
        fsdem_mps_destroy(mps);
    }
}
END_TEST

/* The viscous limit of the explicit predictor: a step above it is refused with FSDEM_ERR_CFL, and
   fsdem_mps_stable_dt never exceeds it. */
START_TEST(test_mps_viscous_limit) {
    fsdem_mps *m = test_channel(2, 0.01, 12, 16, 0.1, 1.0, FSDEM_MPS_WALL_VISCOSITY_NO_SLIP);
    fsdem_real dt = 0;
    ck_assert_int_eq(fsdem_mps_stable_dt(m, &dt), FSDEM_OK);
    /* nothing moves, so only the viscous bound 0.8 lambda / (2 d nu) = 0.2 lambda / nu acts: lambda
       = 4.22650464703 r0^2 for re = 4.1 r0 in 2D (Eq. 11 summed by hand over the lattice), so
       8.45300929e-5 s at nu = 1 m^2/s, r0 = 0.01 m (to rounding: 100 eps) */
    ck_assert_msg(fabs(dt / 8.453009294061e-5 - 1) < TOL(1e-10, 100), "dt = %.10g s", (double)dt);
    ck_assert_int_eq(fsdem_mps_step_dt(m, dt * 2), FSDEM_ERR_CFL);
    ck_assert(strstr(fsdem_mps_last_error(m), "viscous"));
    ck_assert_int_eq(fsdem_mps_step_dt(m, dt), FSDEM_OK);
    fsdem_mps_destroy(m);
}
END_TEST

Suite *mps_periodic_suite(void) {
    Suite *s = suite_create("mps_periodic");
    TCase *tc = tcase_create("mps_periodic");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_mps_periodic_bad_input);
    tcase_add_test(tc, test_mps_viscous_limit);
    tcase_add_test(tc, test_mps_periodic_shift);
    tcase_add_test(tc, test_mps_periodic_seam);
    tcase_add_test(tc, test_mps_open_bad_input);
    tcase_add_test(tc, test_mps_open_restart);
    tcase_add_test(tc, test_mps_open_channel);
    suite_add_tcase(s, tc);
    tc = tcase_create("mps_poiseuille"); /* half a minute of stepping (light: under two seconds): a case of its own */
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_mps_poiseuille);
    suite_add_tcase(s, tc);
    return s;
}
