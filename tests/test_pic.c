/* PIC/FLIP: still water (2D, 3D), discrete incompressibility, flux through an open box with an
   obstacle, implicit viscosity, particles kept out of solids, output files, bad input. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fsdem_tests.h"

#define RHO 1000.0
#define G 9.81

/* A closed tank with still water of depth h (0.5 m) on a coarse grid. Seeds are not jittered, so the
   discrete initial state is a flat surface: any motion after 1 s is the scheme's own. */
static fsdem_pic *still_tank(int dim, fsdem_pic_transfer transfer, fsdem_pic_kernel kernel) {
    fsdem_pic_desc d = fsdem_pic_desc_default(dim);
    fsdem_pic *s = NULL;
    d.cell_size = 0.1;
    d.jitter = 0;
    d.transfer = transfer;
    d.kernel = kernel;
    if (dim == 2) {
        d.domain_max = fsdem_v3(1.0, 0.8, 0);
    } else {
        d.domain_max = fsdem_v3(0.4, 0.3, 0.8);
    }
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), dim == 2 ? fsdem_v3(1.0, 0.5, 0) : fsdem_v3(0.4, 0.3, 0.5),
                                        fsdem_v3(0, 0, 0), NULL),
                     FSDEM_OK);
    return s;
}

/* Bottom pressure averaged over the bottom cells, extrapolated from the two lowest cell centres to
   the floor. */
static double bottom_pressure(const fsdem_pic *s) {
    fsdem_pic_fields g = fsdem_pic_get_fields(s);
    int up = g.dim - 1, i, stride = up == 1 ? g.n[0] : g.n[0] * g.n[1];
    double sum = 0;
    for (i = 0; i < stride; ++i) sum += 1.5 * (double)g.pressure[i] - 0.5 * (double)g.pressure[i + stride];
    return sum / stride;
}

/* What the method guarantees for still water (depth h, flat surface, particles on their seeds).
   The hydrostatic pressure is an exact solution of the discrete equations: the ghost-fluid surface
   is exact for a plane and the linear profile is exact on the grid, so the only error is that of the
   pressure solve, stopped at a relative residual tau (pressure_tolerance: 1e-8, float 1e-5). Its
   error e obeys ||e||_2 <= kappa tau ||p||_2, kappa the condition number of the pressure matrix:
   its largest eigenvalue is at most 4 dim, its smallest that of a quarter wave over the depth
   (p = 0 at the surface, no flux through the bottom), (pi dx / (2 h))^2, so
   kappa = 16 dim h^2 / (pi^2 dx^2); and with N fluid cells, max |e| <= ||e||_2,
   ||p||_2 <= sqrt(N) rho g h:
       |p - rho g (h - y)| <= kappa tau sqrt(N) rho g h.
   The velocity a step leaves is the gradient of that error, (dt / rho) 2 |dp| / dx:
       |u| <= 2 kappa tau sqrt(N) g h dt / dx      (dt <= dt_max),
   and does not accumulate over steps: a gradient field has divergence, which the next projection
   removes. The water volume the solver sees moves with the particles, by |u| T / dx of the volume
   over a time T at most, plus the rounding of its sum over the cells (16 sqrt(cells) eps). */
typedef struct still_bounds {
    double pressure; /* relative to rho g h */
    double speed;    /* m/s */
    double volume;   /* relative */
} still_bounds;

static still_bounds still_water_bounds(const fsdem_pic *s, double h, double duration) {
    const fsdem_pic_fields g = fsdem_pic_get_fields(s);
    const fsdem_pic_desc d = fsdem_pic_get_desc(s);
    const double PI_ = 3.14159265358979323846, dx = g.cell_size;
    int c, fluid = 0, cells = g.n[0] * g.n[1] * g.n[2];
    still_bounds b;
    for (c = 0; c < cells; ++c) fluid += g.cell[c] == FSDEM_STENCIL_CELL_FLUID;
    b.pressure = 16.0 * g.dim * h * h / (PI_ * PI_ * dx * dx) * (double)d.pressure_tolerance * sqrt((double)fluid);
    b.speed = 2 * b.pressure * G * h * (double)d.dt_max / (double)g.cell_size;
    b.volume = b.speed * duration / (double)g.cell_size + 16 * sqrt((double)cells) * TEST_EPS;
    return b;
}

static void check_still(int dim, fsdem_pic_transfer transfer, fsdem_pic_kernel kernel) {
    fsdem_pic *s = still_tank(dim, transfer, kernel);
    fsdem_pic_stats st;
    still_bounds b;
    double p, ref = RHO * G * 0.5, vol;
    ck_assert_int_eq(fsdem_pic_advance(s, 1.0, NULL), FSDEM_OK);
    st = fsdem_pic_get_stats(s);
    b = still_water_bounds(s, 0.5, 1.0);
    p = bottom_pressure(s);
    vol = fabs((double)st.fluid_volume / (double)st.particle_volume - 1);
    TEST_REPORT("%dD transfer %d kernel %d: max speed %.2e m/s (bound %.2e), bottom pressure error %.2e (bound %.2e), "
                "volume %.2e (bound %.2e)",
                dim, (int)transfer, (int)kernel, (double)st.max_speed, b.speed, fabs(p - ref) / ref, b.pressure, vol, b.volume);
    ck_assert_msg(fabs((double)st.time - 1.0) < 1e-9, "time %g", (double)st.time);
    /* measured: 1.6e-9, 1.8e-10 (3D), 9.6e-9 m/s (APIC) against 5.6e-6, 9.2e-6, 5.6e-6 (the old
       figure was 1e-3); float 4.6e-7, 4.4e-7, 3.6e-5 against 5.6e-3, 9.2e-3, 5.6e-3 (tau = 1e-5) */
    ck_assert_msg(st.max_speed < b.speed, "%dD still water: max speed %g m/s after 1 s (bound %g)", dim,
                  (double)st.max_speed, b.speed);
    /* measured: 9e-9, 1.2e-8, 2e-10 against 5.7e-6, 9.4e-6, 5.7e-6 (the old figure was 1e-2); float
       9e-6, 6e-7, 3e-6 against 5.7e-3, 9.4e-3, 5.7e-3 */
    ck_assert_msg(fabs(p - ref) < b.pressure * ref, "%dD bottom pressure %g Pa vs rho g h = %g Pa", dim, p, ref);
    ck_assert_msg(vol < b.volume, "volume %g vs %g", (double)st.fluid_volume, (double)st.particle_volume);
    fsdem_pic_destroy(s);
}

START_TEST(still_water_2d_stays_still) { check_still(2, FSDEM_PIC_TRANSFER_FLIP, FSDEM_PIC_KERNEL_LINEAR); }
END_TEST

START_TEST(still_water_3d_stays_still) { check_still(3, FSDEM_PIC_TRANSFER_FLIP, FSDEM_PIC_KERNEL_LINEAR); }
END_TEST

START_TEST(still_water_apic_quadratic_stays_still) {
    check_still(2, FSDEM_PIC_TRANSFER_APIC, FSDEM_PIC_KERNEL_QUADRATIC);
}
END_TEST

/* Still water with the library's defaults (issue 38: a user's tank with the seeding of the day,
   jitter 0.5, reached 3.7 cm/s at 0.07 s and 0.9 mm/s at 1 s, faster than fine sand settles): the
   default seeds lie on the sub-cell lattice, so the surface is flat and the tank stays at rest, at
   most 1 mm/s at every step to 1 s (the line; the bound of check_still is far below it).
   The jittered seeding is reported beside it, not checked. */
static double still_default_peak(int dim, double jitter) {
    fsdem_pic_desc d = fsdem_pic_desc_default(dim);
    fsdem_pic *s = NULL;
    double peak = 0;
    d.cell_size = (fsdem_real)0.02;
    d.domain_max = dim == 2 ? fsdem_v3((fsdem_real)0.4, (fsdem_real)0.3, 0) : fsdem_v3((fsdem_real)0.2, (fsdem_real)0.2, (fsdem_real)0.3);
    if (jitter >= 0) d.jitter = (fsdem_real)jitter;
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), dim == 2 ? fsdem_v3((fsdem_real)0.4, (fsdem_real)0.2, 0) : fsdem_v3((fsdem_real)0.2, (fsdem_real)0.2, (fsdem_real)0.2),
                                        fsdem_v3(0, 0, 0), NULL),
                     FSDEM_OK);
    while (fsdem_pic_time(s) < 1) {
        fsdem_pic_particles p;
        int i;
        ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK);
        p = fsdem_pic_get_particles(s);
        for (i = 0; i < p.count; ++i) {
            const double v = sqrt((double)(p.velocity[i].x * p.velocity[i].x + p.velocity[i].y * p.velocity[i].y + p.velocity[i].z * p.velocity[i].z));
            if (v > peak) peak = v;
        }
    }
    fsdem_pic_destroy(s);
    return peak;
}

START_TEST(still_water_with_the_default_seeding_stays_still) {
    int dim;
    for (dim = 2; dim <= 3; ++dim) {
        const double peak = still_default_peak(dim, -1), jittered = still_default_peak(dim, 0.5);
        TEST_REPORT("%dD, defaults (jitter %g): peak particle speed %.3g m/s to 1 s; seeds jittered by 0.5: %.3g m/s", dim,
                    (double)fsdem_pic_desc_default(dim).jitter, peak, jittered);
        ck_assert_msg(peak <= 1e-3, "%dD: still water with the defaults reached %g m/s", dim, peak);
    }
}
END_TEST

/* Still water around submerged obstacles (2D: a disc and a wedge polygon; 3D: a sphere and a
   horizontal cylinder) stays still: the cut-cell fractions E, the solid fluxes and the fluid
   fraction next to solids are consistent with the hydrostatic state. */
START_TEST(still_water_around_obstacles_stays_still) {
    int dim;
    for (dim = 2; dim <= 3; ++dim) {
        fsdem_pic_desc d = fsdem_pic_desc_default(dim);
        fsdem_pic *s;
        fsdem_pic_obstacle o1, o2;
        fsdem_vec3 tri[3];
        fsdem_pic_stats st;
        fsdem_pic_fields g;
        double err = 0, ref = RHO * G * 0.5;
        still_bounds b;
        int c;
        d.cell_size = dim == 2 ? 0.05 : 0.1;
        d.jitter = 0;
        d.domain_max = dim == 2 ? fsdem_v3(1.0, 0.8, 0) : fsdem_v3(0.8, 0.4, 0.8);
        ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
        if (dim == 2) {
            tri[0] = fsdem_v3(0.7, 0, 0);
            tri[1] = fsdem_v3(0.95, 0, 0);
            tri[2] = fsdem_v3(0.95, 0.3, 0);
            o1 = fsdem_pic_obstacle_sphere(fsdem_v3(0.43, 0.21, 0), 0.13);
            o2 = fsdem_pic_obstacle_polygon(tri, 3);
        } else {
            o1 = fsdem_pic_obstacle_sphere(fsdem_v3(0.25, 0.2, 0.22), 0.13);
            o2 = fsdem_pic_obstacle_cylinder(fsdem_v3(0.6, -0.1, 0.15), fsdem_v3(0.6, 0.5, 0.15), 0.09);
        }
        ck_assert_int_eq(fsdem_pic_add_obstacle(s, &o1, NULL), FSDEM_OK);
        ck_assert_int_eq(fsdem_pic_add_obstacle(s, &o2, NULL), FSDEM_OK);
        ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), dim == 2 ? fsdem_v3(1, 0.5, 0) : fsdem_v3(1, 1, 0.5),
                                            fsdem_v3(0, 0, 0), NULL),
                         FSDEM_OK);
        ck_assert_int_eq(fsdem_pic_advance(s, 1.0, NULL), FSDEM_OK);
        st = fsdem_pic_get_stats(s);
        b = still_water_bounds(s, 0.5, 1.0);
        g = fsdem_pic_get_fields(s);
        for (c = 0; c < g.n[0] * g.n[1] * g.n[2]; ++c) {
            int up = dim == 2 ? c / g.n[0] : c / (g.n[0] * g.n[1]);
            double y = (up + 0.5) * (double)g.cell_size;
            if (g.cell[c] != FSDEM_STENCIL_CELL_FLUID) continue;
            if (fabs((double)g.pressure[c] - RHO * G * (0.5 - y)) > err) err = fabs((double)g.pressure[c] - RHO * G * (0.5 - y));
        }
        TEST_REPORT("%dD: max speed %.2e m/s (bound %.2e), pressure error %.2e (bound %.2e)", dim, (double)st.max_speed, b.speed,
                    err / ref, b.pressure);
        /* the bounds of still_water_bounds: the cut cells, solid fluxes and fractions next to solids
           are exact for the hydrostatic state too. Measured 3e-10 and 8e-11 m/s against 8.6e-5 and
           1.5e-5 (float 4e-6, 2.7e-6 against 8.6e-2, 1.5e-2); pressure 5.9e-9, 6.6e-9 against 4.4e-5
           and 1.5e-5 (float 2.2e-6, 5.8e-6 against 4.4e-2, 1.5e-2) */
        ck_assert_msg(st.max_speed < b.speed, "%dD: max speed %g m/s after 1 s (bound %g)", dim, (double)st.max_speed, b.speed);
        ck_assert_msg(err < b.pressure * ref, "%dD: pressure off the hydrostatic one by %g Pa", dim, err);
        fsdem_pic_destroy(s);
    }
}
END_TEST

/* Divergence of the face fluxes over the cells the projection solved for, computed here from the
   fields alone (not the library's own figure): the flux through face f of axis a is E u + (1 - E) us
   (open fraction, face velocity, velocity of the solid part; domain walls are faces with E = 0), and
   div_c = sum_a (flux(upper face) - flux(lower face)) / dx.
   Which cells: fields.cell is the classification of the particles' final positions (made at the end
   of the step for diagnostics), while the face velocities come from the projection, which used the
   classification at the start of the step; a cell the front entered during the step is FLUID in the
   view but its faces carry extrapolated velocities. The cells of the projection are those where the
   pressure solution is not 0 (it is 0 in air and solid cells, >>linalg; an exact 0 in a fluid cell
   is a measure-zero event), so those are the cells checked; *checked gets their number and *fluid
   the number of FLUID cells of the view. Returns the largest |div_c| (1/s) and writes the largest
   |flux| / dx to *scale (the size of the terms, for rounding bounds). */
static double fluid_divergence(const fsdem_pic_fields *g, double *scale, int *checked, int *fluid) {
    const int n0 = g->n[0], n1 = g->n[1], n2 = g->n[2];
    double worst = 0, big = 0;
    int i, j, k, a;
    *checked = *fluid = 0;
    for (k = 0; k < n2; ++k)
        for (j = 0; j < n1; ++j)
            for (i = 0; i < n0; ++i) {
                const int c = (k * n1 + j) * n0 + i;
                double div = 0;
                *fluid += g->cell[c] == FSDEM_STENCIL_CELL_FLUID;
                if (g->pressure[c] == 0) continue;
                ++*checked;
                for (a = 0; a < g->dim; ++a) {
                    /* lower face of the cell along a, and the stride to the upper one */
                    const int lo = a == 0 ? (k * n1 + j) * (n0 + 1) + i : a == 1 ? (k * (n1 + 1) + j) * n0 + i : (k * n1 + j) * n0 + i;
                    const int up = lo + (a == 0 ? 1 : a == 1 ? n0 : n0 * n1);
                    const double e0 = g->open[a][lo], e1 = g->open[a][up];
                    const double f0 = e0 * g->velocity[a][lo] + (1 - e0) * g->solid_velocity[a][lo];
                    const double f1 = e1 * g->velocity[a][up] + (1 - e1) * g->solid_velocity[a][up];
                    div += (f1 - f0) / g->cell_size;
                    big = fmax(big, fmax(fabs(f0), fabs(f1)) / g->cell_size);
                }
                worst = fmax(worst, fabs(div));
            }
    *scale = big;
    return worst;
}

/* A small 2D dam break around a disc: after each step the projected velocity's divergence (with the
   cut-cell fluxes), computed here from the face velocities, open fractions and solid velocities, is
   zero in every fluid cell to the solver tolerance: the pressure equation's residual is the
   divergence left, so max |div| <= ||div||_2 after <= tol ||div u*||_2 (divergence_before, the one
   figure taken from the library; a factor 2 for rounding). In float the fields themselves carry
   eps |flux| / dx per term: 8 eps of the largest term (TOL). A solve that ignored the cut-cell
   fractions or the solid fluxes would leave O(u / dx) here. */
START_TEST(projection_is_discretely_divergence_free) {
    fsdem_pic_desc d = fsdem_pic_desc_default(2);
    fsdem_pic *s;
    fsdem_pic_obstacle disc = fsdem_pic_obstacle_sphere(fsdem_v3(0.55, 0.12, 0), 0.08);
    int k;
    d.cell_size = 0.04;
    d.domain_max = fsdem_v3(1.0, 0.6, 0);
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_add_obstacle(s, &disc, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), fsdem_v3(0.3, 0.5, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
    for (k = 0; k < 25; ++k) {
        fsdem_pic_stats st;
        fsdem_pic_fields g;
        double div, scale;
        int checked, fluid;
        ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK);
        st = fsdem_pic_get_stats(s);
        g = fsdem_pic_get_fields(s);
        div = fluid_divergence(&g, &scale, &checked, &fluid);
        ck_assert_int_gt(st.fluid_cells, 0);
        ck_assert_msg(checked >= 0.8 * fluid, "step %d: %d cells checked of %d fluid", k, checked, fluid);
        ck_assert_msg(st.divergence_before > 0, "nothing to project");
        ck_assert_msg(div <= fmax(2 * d.pressure_tolerance * st.divergence_before, 8 * TEST_EPS * scale),
                      "step %d: max |div| %g 1/s (library: %g), before %g 1/s", k, div, (double)st.max_divergence,
                      (double)st.divergence_before);
        if (k == 24)
            TEST_REPORT("max |div| %.3g 1/s (library %.3g) against 2 tol div_before = %.3g, flux scale %.3g 1/s", div,
                        (double)st.max_divergence, 2 * d.pressure_tolerance * st.divergence_before, scale);
    }
    ck_assert_msg(fsdem_pic_get_stats(s).max_speed > 0.5, "the column should be collapsing");
    fsdem_pic_destroy(s);
}
END_TEST

/* A 1 m x H open box completely filled with water (no free surface), 0.025 m cells, no gravity:
   inflow U on -x, outflow on +x, slip walls. The particles are the caller's to add. */
static fsdem_pic *open_channel(double U, double H) {
    fsdem_pic_desc d = fsdem_pic_desc_default(2);
    fsdem_pic *s;
    d.cell_size = 0.025;
    d.domain_max = fsdem_v3(1.0, H, 0);
    d.gravity = fsdem_v3(0, 0, 0);
    d.free_surface = 0;
    d.boundary[0] = FSDEM_PIC_BC_INFLOW;
    d.boundary_velocity[0] = fsdem_v3(U, 0, 0);
    d.boundary[1] = FSDEM_PIC_BC_OUTFLOW;
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    return s;
}

/* Flux through an open box: inflow U on -x, outflow on +x, slip walls, a disc in the middle, the
   box completely filled (no free surface). Every section x = const carries U H. */
START_TEST(open_box_conserves_flux_past_obstacle) {
    fsdem_pic *s;
    fsdem_pic_obstacle disc = fsdem_pic_obstacle_sphere(fsdem_v3(0.5, 0.25, 0), 0.1);
    fsdem_pic_fields g;
    double U = 1.0, H = 0.5, vmax = 0;
    int k, i, j;
    s = open_channel(U, H);
    ck_assert_int_eq(fsdem_pic_add_obstacle(s, &disc, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), fsdem_v3(1.0, H, 0), fsdem_v3(U, 0, 0), NULL), FSDEM_OK);
    for (k = 0; k < 10; ++k) ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK);
    g = fsdem_pic_get_fields(s);
    for (i = 0; i <= g.n[0]; ++i) {
        double flux = 0;
        for (j = 0; j < g.n[1]; ++j) {
            int f = j * (g.n[0] + 1) + i;
            double e = (double)g.open[0][f];
            flux += (e * (double)g.velocity[0][f] + (1 - e) * (double)g.solid_velocity[0][f]) * (double)g.cell_size;
            if (fabs((double)g.velocity[0][f]) > vmax) vmax = fabs((double)g.velocity[0][f]);
        }
        ck_assert_msg(fabs(flux - U * H) < 1e-6 * U * H, "section %d: flux %.9g vs %.9g", i, flux, U * H);
    }
    ck_assert_msg(vmax > 1.2 * U, "the flow should accelerate past the disc (max u %g)", vmax);
    ck_assert_int_gt(fsdem_pic_get_stats(s).particles, 0);
    fsdem_pic_destroy(s);
}
END_TEST

/* Every option combination (PIC, FLIP, APIC; linear and quadratic kernels; RK2 and RK3; with and
   without density projection) runs a short 3D dam break without error, divergence-free (checked as
   in projection_is_discretely_divergence_free, from the fields), with the particles inside the tank
   and no volume lost beyond 2 %. */
START_TEST(option_matrix_runs_clean) {
    int transfer, kernel, order, dp;
    for (transfer = 0; transfer < 3; ++transfer)
        for (kernel = 0; kernel < 2; ++kernel)
            for (order = 2; order <= 3; ++order)
                for (dp = 0; dp <= 1; ++dp) {
                    fsdem_pic_desc d = fsdem_pic_desc_default(3);
                    fsdem_pic *s;
                    fsdem_pic_stats st;
                    fsdem_pic_particles p;
                    double v0;
                    int k, i;
                    d.cell_size = 0.1;
                    d.domain_max = fsdem_v3(0.8, 0.3, 0.5);
                    d.transfer = (fsdem_pic_transfer)transfer;
                    d.kernel = (fsdem_pic_kernel)kernel;
                    d.advection_order = order;
                    d.density_projection = dp;
                    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
                    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), fsdem_v3(0.3, 0.3, 0.4), fsdem_v3(0, 0, 0), NULL),
                                     FSDEM_OK);
                    v0 = (double)fsdem_pic_get_stats(s).fluid_volume;
                    for (k = 0; k < 8; ++k) {
                        fsdem_pic_fields g;
                        double div, scale;
                        int checked, fluid;
                        ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK);
                        st = fsdem_pic_get_stats(s);
                        g = fsdem_pic_get_fields(s);
                        div = fluid_divergence(&g, &scale, &checked, &fluid);
                        ck_assert_msg(checked >= 0.8 * fluid, "%d cells checked of %d fluid", checked, fluid);
                        ck_assert_msg(div <= fmax(2 * d.pressure_tolerance * st.divergence_before, 8 * TEST_EPS * scale) + 1e-12,
                                      "transfer %d kernel %d order %d: div %g (library %g)", transfer, kernel, order, div,
                                      (double)st.max_divergence);
                    }
                    ck_assert_msg(st.max_speed > 0.3, "the column should be collapsing (%g m/s)", (double)st.max_speed);
                    ck_assert_msg(fabs((double)st.fluid_volume / v0 - 1) < 0.02, "volume %g -> %g", v0, (double)st.fluid_volume);
                    p = fsdem_pic_get_particles(s);
                    for (i = 0; i < p.count; ++i)
                        ck_assert(p.position[i].x > 0 && p.position[i].x < 0.8 && p.position[i].y > 0 && p.position[i].y < 0.3 &&
                                  p.position[i].z > 0 && p.position[i].z < 0.5);
                    fsdem_pic_destroy(s);
                }
}
END_TEST

/* Particles never stay inside a solid or outside the walls, and reseeding keeps every cell at or
   below max_particles_per_cell. */
START_TEST(particles_stay_out_of_solids) {
    fsdem_pic_desc d = fsdem_pic_desc_default(2);
    fsdem_pic *s;
    fsdem_vec3 tri[3];
    fsdem_pic_obstacle wedge;
    fsdem_pic_particles p;
    fsdem_pic_fields g;
    int k, i, *count;
    tri[0] = fsdem_v3(0.45, 0.0, 0);
    tri[1] = fsdem_v3(0.9, 0.0, 0);
    tri[2] = fsdem_v3(0.9, 0.25, 0);
    wedge = fsdem_pic_obstacle_polygon(tri, 3);
    d.cell_size = 0.04;
    d.domain_max = fsdem_v3(1.0, 0.6, 0);
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_add_obstacle(s, &wedge, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), fsdem_v3(0.3, 0.5, 0), fsdem_v3(1, 0, 0), NULL), FSDEM_OK);
    for (k = 0; k < 30; ++k) ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK);
    p = fsdem_pic_get_particles(s);
    g = fsdem_pic_get_fields(s);
    count = (int *)calloc((size_t)(g.n[0] * g.n[1]), sizeof(int));
    for (i = 0; i < p.count; ++i) {
        fsdem_vec3 x = p.position[i];
        int ci = (int)(x.x / g.cell_size), cj = (int)(x.y / g.cell_size);
        ck_assert_msg(fsdem_pic_solid_distance(s, x, NULL) > 0, "particle %d at (%g, %g) is inside a solid", i, (double)x.x,
                      (double)x.y);
        count[cj * g.n[0] + ci]++;
    }
    for (i = 0; i < g.n[0] * g.n[1]; ++i) ck_assert_int_le(count[i], d.max_particles_per_cell);
    free(count);
    for (i = 0; i < p.count; ++i)
        ck_assert_msg(test_finite3(p.position[i]) && test_finite3(p.velocity[i]), "particle %d is not finite", i);
    fsdem_pic_destroy(s);
}
END_TEST

/* ---- implicit viscosity: the exact decay of a discrete Stokes mode ----

   In a box of nx x ny cells (edge dx) with free-slip walls, take the stream function on the cell
   corners psi(i, j) = sin(a pi i / nx) sin(b pi j / ny) and the face velocities
       u(i, j) = (psi(i, j+1) - psi(i, j)) / dx      (x-face at corner column i, cell row j)
       v(i, j) = -(psi(i+1, j) - psi(i, j)) / dx     (y-face at cell column i, corner row j).
   Its discrete divergence is 0 exactly, and each component is an eigenvector of the viscous
   operator of >>pic_viscosity (Dirichlet 0 on the wall faces normal to it, sin in that direction;
   zero gradient along slip walls, cos across): L phi = -lambda phi with
       lambda dx^2 = 4 sin^2(a pi / (2 nx)) + 4 sin^2(b pi / (2 ny)),
   the same for u and v. Backward Euler, (I - nu dt L) u = u*, multiplies its amplitude by exactly
   1 / (1 + nu dt lambda). The transfers make the grid velocity only approximately the mode, but the
   amplitude of the mode in it, A = <u, phi> / <phi, phi>, still obeys the exact law when one step
   is compared with the same step without viscosity: the viscous operator is symmetric, so the part
   of u* orthogonal to phi stays orthogonal, and the projection removes a gradient, which is
   orthogonal to the divergence-free phi (so the pressure solve's error does not touch A either).
   Hence A(nu) / A(0) = 1 / (1 + nu dt lambda), both sides. The viscous solve stops at a relative
   residual tau (viscosity_tolerance), which moves A by at most tau ||u*|| / (A ||phi||) relative:
   ~tau, since u* is mostly the mode; the check allows 20 tau (2e-7; float 2e-4). Measured 3e-12
   to 5e-11 (float 1e-7 to 5e-7); a no-slip treatment of the walls or a lambda off by the discrete
   correction (continuous (k dx)^2 instead of 4 sin^2(k dx / 2): 0.3% for mode (2, 3)) fails. */
static double pic_mode_amplitude(const fsdem_pic_fields *g, int ma, int mb) {
    const int nx = g->n[0], ny = g->n[1];
    const double PI_ = 3.14159265358979323846;
    double up = 0, pp = 0;
    int i, j;
#define PSI(i_, j_) (sin(ma * PI_ * (i_) / nx) * sin(mb * PI_ * (j_) / ny))
    for (j = 0; j < ny; ++j)
        for (i = 0; i <= nx; ++i) {
            const double phi = PSI(i, j + 1) - PSI(i, j);
            up += phi * g->velocity[0][j * (nx + 1) + i];
            pp += phi * phi;
        }
    for (j = 0; j <= ny; ++j)
        for (i = 0; i < nx; ++i) {
            const double phi = -(PSI(i + 1, j) - PSI(i, j));
            up += phi * g->velocity[1][j * nx + i];
            pp += phi * phi;
        }
#undef PSI
    return up / pp;
}

/* One step of dt of a filled, gravity-free slip box (0.5 m x 0.4 m, 0.05 m cells) whose particles
   carry the continuous mode u = d psi / dy, v = -d psi / dx; returns the mode's amplitude after it. */
static double pic_mode_step(double nu, double dt, int ma, int mb) {
    const double PI_ = 3.14159265358979323846, Lx = 0.5, Ly = 0.4;
    fsdem_pic_desc d = fsdem_pic_desc_default(2);
    fsdem_pic *s;
    fsdem_pic_particles p;
    fsdem_pic_fields g;
    double amp;
    int i;
    d.cell_size = 0.05;
    d.domain_max = fsdem_v3((fsdem_real)Lx, (fsdem_real)Ly, 0);
    d.gravity = fsdem_v3(0, 0, 0);
    d.viscosity = (fsdem_real)nu;
    d.free_surface = 0;
    d.transfer = FSDEM_PIC_TRANSFER_PIC;
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)Lx, (fsdem_real)Ly, 0), fsdem_v3(0, 0, 0), NULL),
                     FSDEM_OK);
    p = fsdem_pic_get_particles(s);
    for (i = 0; i < p.count; ++i) {
        const double x = p.position[i].x, y = p.position[i].y, kx = ma * PI_ / Lx, ky = mb * PI_ / Ly;
        p.velocity[i] = fsdem_v3((fsdem_real)(sin(kx * x) * ky * cos(ky * y)), (fsdem_real)(-kx * cos(kx * x) * sin(ky * y)), 0);
    }
    ck_assert_int_eq(fsdem_pic_step_dt(s, (fsdem_real)dt), FSDEM_OK);
    if (nu > 0) ck_assert_int_gt(fsdem_pic_get_stats(s).viscosity_iterations, 0);
    g = fsdem_pic_get_fields(s);
    ck_assert_int_eq(g.n[0], 10);
    ck_assert_int_eq(g.n[1], 8);
    amp = pic_mode_amplitude(&g, ma, mb);
    fsdem_pic_destroy(s);
    return amp;
}

/* nu dt / dx^2 = 10 (explicit diffusion needs <= 1/4) and 0.5, modes (1, 1) and (2, 3): the amplitude
   after a viscous step is that of the same step without viscosity divided by 1 + nu dt lambda. */
START_TEST(implicit_viscosity_decays_a_mode_exactly) {
    const double PI_ = 3.14159265358979323846, dx = 0.05, dt = 0.01, tau = fsdem_pic_desc_default(2).viscosity_tolerance;
    static const int modes[2][2] = {{1, 1}, {2, 3}};
    static const double knu[2] = {10, 0.5}; /* nu dt / dx^2 */
    int m, q;
    for (m = 0; m < 2; ++m) {
        const int ma = modes[m][0], mb = modes[m][1];
        const double lambda = (4 * pow(sin(ma * PI_ / 20), 2) + 4 * pow(sin(mb * PI_ / 16), 2)) / (dx * dx);
        const double a0 = pic_mode_step(0, dt, ma, mb);
        ck_assert_msg(fabs(a0) > 0.5, "mode (%d, %d): amplitude %g without viscosity", ma, mb, a0);
        for (q = 0; q < 2; ++q) {
            const double nu = knu[q] * dx * dx / dt, exact = 1 / (1 + nu * dt * lambda);
            const double ratio = pic_mode_step(nu, dt, ma, mb) / a0;
            TEST_REPORT("mode (%d, %d), nu dt / dx^2 = %g: amplitude ratio %.9f, exact 1 / (1 + nu dt lambda) = %.9f "
                        "(relative error %.2e)",
                        ma, mb, knu[q], ratio, exact, ratio / exact - 1);
            ck_assert_msg(fabs(ratio / exact - 1) < 20 * tau, "mode (%d, %d), nu dt / dx^2 = %g: ratio %.9g, exact %.9g", ma, mb,
                          knu[q], ratio, exact);
        }
    }
}
END_TEST

/* Implicit viscosity is unconditionally stable: with nu dt / dx^2 = 10 (explicit diffusion needs
   <= 1/4) a shear flow sin(2 pi y / L) in a closed no-slip box decays every step (backward Euler
   keeps 1/(1 + nu dt k^2) ~ 0.2 of the velocity of this mode, kinetic energy ~ 0.04) instead of
   blowing up. PIC transfer, so the particles carry exactly the grid velocity. The exact decay, from
   both sides, is implicit_viscosity_decays_a_mode_exactly. */
START_TEST(implicit_viscosity_is_stable) {
    fsdem_pic_desc d = fsdem_pic_desc_default(2);
    fsdem_pic *s;
    fsdem_pic_particles p;
    double ke, last, first;
    int k, i;
    d.cell_size = 0.05;
    d.domain_max = fsdem_v3(0.5, 0.5, 0);
    d.gravity = fsdem_v3(0, 0, 0);
    d.viscosity = 2.5;
    d.free_surface = 0;
    d.transfer = FSDEM_PIC_TRANSFER_PIC;
    for (k = 0; k < 4; ++k) d.boundary[k] = FSDEM_PIC_BC_NO_SLIP;
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), fsdem_v3(0.5, 0.5, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
    p = fsdem_pic_get_particles(s);
    for (i = 0; i < p.count; ++i) p.velocity[i] = fsdem_v3((fsdem_real)sin(2 * 3.14159265358979 * p.position[i].y / 0.5), 0, 0);
    first = last = (double)fsdem_pic_get_stats(s).kinetic_energy;
    for (k = 0; k < 5; ++k) {
        ck_assert_int_eq(fsdem_pic_step_dt(s, 0.01), FSDEM_OK);
        ck_assert_int_gt(fsdem_pic_get_stats(s).viscosity_iterations, 0);
        ke = (double)fsdem_pic_get_stats(s).kinetic_energy;
        ck_assert_msg(ke < 0.1 * last, "step %d: kinetic energy went from %g to %g J/m", k, last, ke);
        last = ke;
    }
    ck_assert_msg(last < 1e-6 * first, "kinetic energy %g J/m of %g J/m left", last, first);
    fsdem_pic_destroy(s);
}
END_TEST

static int file_starts_with(const char *path, const char *text) {
    char buf[256];
    FILE *fp = fopen(path, "r");
    size_t n;
    if (!fp) return 0;
    n = fread(buf, 1, sizeof buf - 1, fp);
    buf[n] = '\0';
    fclose(fp);
    return strncmp(buf, text, strlen(text)) == 0;
}

START_TEST(output_files_are_written) {
    fsdem_pic *s = still_tank(2, FSDEM_PIC_TRANSFER_FLIP, FSDEM_PIC_KERNEL_LINEAR);
    fsdem_pvd pvd;
    ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_write_particles_csv(s, "build/test_pic_particles.csv"), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_write_particles_vtp(s, "build/test_pic_particles.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_write_grid_csv(s, "build/test_pic_grid.csv"), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_write_grid_vti(s, "build/test_pic_grid.vti", FSDEM_VTK_FORMAT_BASE64), FSDEM_OK);
    ck_assert_int_eq(fsdem_pvd_open(&pvd, "build/test_pic.pvd"), FSDEM_OK);
    ck_assert_int_eq(fsdem_pvd_add(&pvd, fsdem_pic_time(s), "test_pic_grid.vti"), FSDEM_OK);
    ck_assert_int_eq(fsdem_pvd_close(&pvd), FSDEM_OK);
    ck_assert(file_starts_with("build/test_pic_particles.csv", "x,y,z,vx,vy,vz\n"));
    ck_assert(file_starts_with("build/test_pic_particles.vtp", "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\""));
    ck_assert(file_starts_with("build/test_pic_grid.csv", "i,j,k,x,y,z,type,p,phi,fraction,u,v,w\n"));
    ck_assert(file_starts_with("build/test_pic_grid.vti", "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\""));
    ck_assert(file_starts_with("build/test_pic.pvd", "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\""));
    ck_assert_int_eq(fsdem_pic_write_grid_vti(s, "/nonexistent-dir/x.vti", FSDEM_VTK_FORMAT_APPENDED), FSDEM_ERR_IO);
    fsdem_pic_destroy(s);
}
END_TEST

START_TEST(bad_desc_is_rejected) {
    fsdem_pic_desc d = fsdem_pic_desc_default(2);
    fsdem_pic *s = (fsdem_pic *)&d;
    char msg[256];
    d.cell_size = 0;
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_null(s);
    ck_assert_int_eq(fsdem_pic_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(msg, "cell_size") != NULL, "message: %s", msg);
    d.cell_size = -0.1;
    ck_assert_int_eq(fsdem_pic_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    d = fsdem_pic_desc_default(3);
    d.cell_size = 1e-5; /* 1e15 cells */
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_ERR_OUT_OF_MEMORY);
    ck_assert_int_eq(fsdem_pic_desc_check(&d, msg, sizeof msg), FSDEM_ERR_OUT_OF_MEMORY);
    ck_assert_msg(strstr(msg, "cells") != NULL, "message: %s", msg);
    d = fsdem_pic_desc_default(3);
    d.cell_size = 0.01;
    d.max_memory = 1000000; /* 1e6 cells do not fit in 1 MB */
    ck_assert_int_eq(fsdem_pic_desc_check(&d, msg, sizeof msg), FSDEM_ERR_OUT_OF_MEMORY);
    ck_assert_msg(strstr(msg, "max_memory") != NULL, "message: %s", msg);
    d = fsdem_pic_desc_default(2);
    d.dim = 4;
    ck_assert_int_eq(fsdem_pic_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    d = fsdem_pic_desc_default(2);
    d.cfl = 0;
    ck_assert_int_eq(fsdem_pic_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(msg, "cfl") != NULL, "message: %s", msg);
}
END_TEST

/* Bad particles, an obstacle covering everything and a CFL-violating dt are refused with a code and
   a message naming the culprit; the solver is unchanged and keeps working. */
START_TEST(bad_input_leaves_solver_usable) {
    fsdem_pic *s = still_tank(2, FSDEM_PIC_TRANSFER_FLIP, FSDEM_PIC_KERNEL_LINEAR);
    fsdem_vec3 x[3], v[3];
    fsdem_pic_obstacle all = fsdem_pic_obstacle_box(fsdem_v3(-1, -1, -1), fsdem_v3(2, 2, 2));
    fsdem_pic_obstacle bad = fsdem_pic_obstacle_sphere(fsdem_v3(0.5, 0.5, 0), -1);
    fsdem_pic_particles p;
    fsdem_vec3 first;
    int before;
    before = fsdem_pic_get_stats(s).particles;
    x[0] = fsdem_v3(0.5, 0.6, 0);
    x[1] = fsdem_v3(0.5, (fsdem_real)NAN, 0);
    x[2] = fsdem_v3(0.6, 0.6, 0);
    v[0] = v[1] = v[2] = fsdem_v3(0, 0, 0);
    ck_assert_int_eq(fsdem_pic_add_particles(s, x, v, 3), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(fsdem_pic_last_error(s), "particle 1") != NULL, "%s", fsdem_pic_last_error(s));
    x[1] = fsdem_v3(0.5, 5.0, 0);
    ck_assert_int_eq(fsdem_pic_add_particles(s, x, v, 3), FSDEM_ERR_OUT_OF_DOMAIN);
    ck_assert_msg(strstr(fsdem_pic_last_error(s), "particle 1") != NULL, "%s", fsdem_pic_last_error(s));
    ck_assert_int_eq(fsdem_pic_get_stats(s).particles, before);

    ck_assert_int_eq(fsdem_pic_add_obstacle(s, &all, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(fsdem_pic_last_error(s), "whole domain") != NULL, "%s", fsdem_pic_last_error(s));
    ck_assert_int_eq(fsdem_pic_add_obstacle(s, &bad, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(fsdem_pic_last_error(s), "radius") != NULL, "%s", fsdem_pic_last_error(s));
    ck_assert_int_eq(fsdem_pic_get_stats(s).particles, before);

    p = fsdem_pic_get_particles(s);
    p.velocity[0] = fsdem_v3(3, 0, 0);
    first = p.position[0];
    ck_assert_int_eq(fsdem_pic_step_dt(s, 1.0), FSDEM_ERR_CFL);
    ck_assert_msg(strstr(fsdem_pic_last_error(s), "particle 0") != NULL, "%s", fsdem_pic_last_error(s));
    ck_assert(p.position[0].x == first.x && p.position[0].y == first.y);
    ck_assert_int_eq(fsdem_pic_step_dt(s, 0.0), FSDEM_ERR_INVALID_ARG);
    ck_assert_double_eq(fsdem_pic_time(s), 0);
    p.velocity[0] = fsdem_v3(0, (fsdem_real)NAN, 0);
    ck_assert_int_eq(fsdem_pic_step(s), FSDEM_ERR_NAN);
    ck_assert_msg(strstr(fsdem_pic_last_error(s), "particle 0") != NULL, "%s", fsdem_pic_last_error(s));
    p.velocity[0] = fsdem_v3(0, 0, 0);

    ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK);
    ck_assert_str_eq(fsdem_pic_last_error(s), "");
    ck_assert_int_eq(fsdem_pic_add_particles(s, x, v, 1), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK);
    fsdem_pic_destroy(s);
}
END_TEST

/* Steps never allocate: a counting allocator sees no call during 20 steps of a dam break around an
   obstacle with reseeding, density projection and viscosity (all memory comes from create, fill
   and add_obstacle). */
typedef struct counting {
    long allocs, frees;
} counting;

static void *counting_alloc(void *user, size_t size) {
    ((counting *)user)->allocs++;
    return malloc(size);
}

static void counting_free(void *user, void *ptr, size_t size) {
    (void)size;
    ((counting *)user)->frees++;
    free(ptr);
}

START_TEST(steps_do_not_allocate) {
    fsdem_pic_desc d = fsdem_pic_desc_default(2);
    fsdem_pic *s;
    fsdem_pic_obstacle box = fsdem_pic_obstacle_box(fsdem_v3(0.5, 0, 0), fsdem_v3(0.6, 0.15, 0));
    counting c = {0, 0};
    long allocs;
    int k;
    d.cell_size = 0.04;
    d.domain_max = fsdem_v3(1.0, 0.6, 0);
    d.viscosity = 1e-3;
    d.allocator.alloc = counting_alloc;
    d.allocator.free = counting_free;
    d.allocator.user = &c;
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_add_obstacle(s, &box, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), fsdem_v3(0.3, 0.5, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
    allocs = c.allocs;
    ck_assert_int_gt(allocs, 0);
    for (k = 0; k < 20; ++k) ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK);
    ck_assert_msg(c.allocs == allocs, "%ld allocations during the steps", c.allocs - allocs);
    fsdem_pic_destroy(s);
    ck_assert_int_eq(c.allocs, c.frees);
}
END_TEST

/* The coupler arrays enter the projection: faces closed by a "moving solid" (open = 0) carry the
   solid's velocity as flux. A column of faces across the open box closed by a solid moving steadily
   at U (at the start and the end of every step) leaves the uniform flow U untouched: flux U H through every section, no vertical velocity. */
START_TEST(coupler_faces_carry_solid_flux) {
    fsdem_pic *s;
    fsdem_pic_coupling cp;
    fsdem_pic_fields g;
    double U = 0.5, H = 0.5;
    int k, i, j, col = 20;
    s = open_channel(U, H);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), fsdem_v3(1.0, H, 0), fsdem_v3(U, 0, 0), NULL), FSDEM_OK);
    cp = fsdem_pic_get_coupling(s);
    ck_assert_int_eq(cp.face_count[0], (cp.n[0] + 1) * cp.n[1]);
    for (j = 0; j < cp.n[1]; ++j) {
        cp.open[0][j * (cp.n[0] + 1) + col] = 0;
        cp.solid_velocity[0][j * (cp.n[0] + 1) + col] = (fsdem_real)U;
        cp.start_velocity[0][j * (cp.n[0] + 1) + col] = (fsdem_real)U; /* it moves steadily */
    }
    for (k = 0; k < 5; ++k) ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK);
    g = fsdem_pic_get_fields(s);
    for (i = 0; i <= g.n[0]; ++i) {
        double flux = 0;
        for (j = 0; j < g.n[1]; ++j) {
            int f = j * (g.n[0] + 1) + i;
            double e = (double)g.open[0][f];
            flux += (e * (double)g.velocity[0][f] + (1 - e) * (double)g.solid_velocity[0][f]) * (double)g.cell_size;
        }
        ck_assert_msg(fabs(flux - U * H) < 1e-6 * U * H, "section %d: flux %.9g vs %.9g", i, flux, U * H);
    }
    for (j = 0; j < g.n[1]; ++j) {
        int f = j * (g.n[0] + 1) + col;
        ck_assert(g.open[0][f] == 0);
    }
    for (i = 0; i < g.face_count[1]; ++i) ck_assert_msg(fabs((double)g.velocity[1][i]) < 1e-6, "v = %g", (double)g.velocity[1][i]);
    fsdem_pic_destroy(s);
}
END_TEST

/* A user signed-distance callback gives the same cut-cell face fractions as the built-in shape it
   describes (a disc), and they are fractions: 0 inside, 1 far away, in between on the rim, with the
   open length of a face row through the centre equal to the chord outside the disc. */
static fsdem_real disc_sdf(void *user, fsdem_vec3 p, fsdem_vec3 *normal) {
    const fsdem_real *c = (const fsdem_real *)user;
    fsdem_real dx = p.x - c[0], dy = p.y - c[1], r = (fsdem_real)sqrt(dx * dx + dy * dy);
    if (normal) *normal = r > 0 ? fsdem_v3(dx / r, dy / r, 0) : fsdem_v3(1, 0, 0);
    return r - c[2];
}

START_TEST(sdf_callback_matches_builtin_obstacle) {
    fsdem_pic_desc d = fsdem_pic_desc_default(2);
    fsdem_pic *a, *b;
    fsdem_real disc[3] = {(fsdem_real)0.51, (fsdem_real)0.47, (fsdem_real)0.23};
    fsdem_pic_obstacle o1 = fsdem_pic_obstacle_sphere(fsdem_v3(disc[0], disc[1], 0), disc[2]);
    fsdem_pic_obstacle o2 = fsdem_pic_obstacle_sdf(disc_sdf, disc);
    fsdem_pic_fields ga, gb;
    int ax, f, partial = 0;
    double open = 0;
    d.cell_size = 0.05;
    ck_assert_int_eq(fsdem_pic_create(&d, &a), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_create(&d, &b), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_add_obstacle(a, &o1, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_add_obstacle(b, &o2, NULL), FSDEM_OK);
    ga = fsdem_pic_get_fields(a);
    gb = fsdem_pic_get_fields(b);
    for (ax = 0; ax < 2; ++ax)
        for (f = 0; f < ga.face_count[ax]; ++f) {
            ck_assert_msg(fabs((double)ga.open[ax][f] - (double)gb.open[ax][f]) < 1e-12, "axis %d face %d: %g vs %g", ax, f,
                          (double)ga.open[ax][f], (double)gb.open[ax][f]);
            ck_assert(ga.open[ax][f] >= 0 && ga.open[ax][f] <= 1);
            partial += ga.open[ax][f] > 0 && ga.open[ax][f] < 1;
        }
    ck_assert_int_gt(partial, 20);
    /* the vertical faces at x = 0.5 (i = 10) span y in [0, 1]: their open length is 1 minus the
       chord 2 sqrt(r^2 - 0.01^2) of the disc */
    for (f = 0; f < ga.n[1]; ++f) open += (double)ga.open[0][f * (ga.n[0] + 1) + 10] * (double)ga.cell_size;
    ck_assert_msg(fabs(open - (1 - 2 * sqrt(0.23 * 0.23 - 0.01 * 0.01))) < 5e-3, "open length %g", open);
    fsdem_pic_destroy(a);
    fsdem_pic_destroy(b);
}
END_TEST

/* Reseeding keeps the particle count of every fluid cell in [min, max] without creating volume: a
   closed, completely filled box seeded twice (8 per cell) except for an empty column of cells has,
   after one step, at least min_particles_per_cell particles in every cell and exactly as many
   particles as before (moved from the crowded neighbours). The density projection is off so that
   reseeding alone does it. */
START_TEST(reseeding_moves_particles_into_sparse_cells) {
    fsdem_pic_desc d = fsdem_pic_desc_default(2);
    fsdem_pic *s;
    fsdem_pic_particles p;
    fsdem_pic_fields g;
    int *count, i, before;
    d.cell_size = 0.1;
    d.domain_max = fsdem_v3(1.0, 0.5, 0);
    d.gravity = fsdem_v3(0, 0, 0);
    d.free_surface = 0;
    d.density_projection = 0;
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    for (i = 0; i < 2; ++i) {
        ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), fsdem_v3(0.5, 0.5, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
        ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0.6, 0, 0), fsdem_v3(1.0, 0.5, 0), fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
    }
    before = fsdem_pic_get_stats(s).particles;
    ck_assert_int_eq(before, 8 * 45);
    ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK);
    p = fsdem_pic_get_particles(s);
    g = fsdem_pic_get_fields(s);
    ck_assert_int_eq(p.count, before);
    ck_assert_int_gt((int)fsdem_pic_get_stats(s).moved, 0);
    count = (int *)calloc((size_t)(g.n[0] * g.n[1]), sizeof(int));
    for (i = 0; i < p.count; ++i) count[(int)(p.position[i].y / g.cell_size) * g.n[0] + (int)(p.position[i].x / g.cell_size)]++;
    for (i = 0; i < g.n[0] * g.n[1]; ++i) {
        ck_assert_msg(count[i] >= d.min_particles_per_cell, "cell %d has %d particles", i, count[i]);
        ck_assert_int_le(count[i], d.max_particles_per_cell);
    }
    free(count);
    fsdem_pic_destroy(s);
}
END_TEST

/* OpenFOAM's damBreak tank (0.584 m, water column 0.146 x 0.292 m) with a box 3 cells wide and 7 high
   on the floor at x = 0.292 m, shifted by `shift` (m) along x: with 88 (2D) or 44 (3D) cells across,
   both sides of the unshifted box lie exactly on grid faces. */
static fsdem_pic *aligned_box_tank(int dim, double shift) {
    const int n = dim == 2 ? 88 : 44;
    const double L = 0.584, dx = L / n;
    fsdem_pic_desc d = fsdem_pic_desc_default(dim);
    fsdem_pic *s = NULL;
    fsdem_pic_obstacle box;
    d.cell_size = (fsdem_real)dx;
    d.jitter = 0;
    d.pressure_tolerance = (fsdem_real)TOL(1e-8, 1e3); /* float: its rounding floor here is about 2e-5 */
    d.domain_max = dim == 2 ? fsdem_v3((fsdem_real)L, (fsdem_real)L, 0) : fsdem_v3((fsdem_real)L, (fsdem_real)(2 * dx), (fsdem_real)L);
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    box = fsdem_pic_obstacle_box(fsdem_v3((fsdem_real)(0.292 + shift), 0, 0),
                                 dim == 2 ? fsdem_v3((fsdem_real)(0.292 + shift + 3 * dx), (fsdem_real)(7 * dx), 0)
                                          : fsdem_v3((fsdem_real)(0.292 + shift + 3 * dx), 1, (fsdem_real)(7 * dx)));
    ck_assert_int_eq(fsdem_pic_add_obstacle(s, &box, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), dim == 2 ? fsdem_v3(0.146, 0.292, 0) : fsdem_v3(0.146, 1, 0.292),
                                        fsdem_v3(0, 0, 0), NULL),
                     FSDEM_OK);
    return s;
}

/* A solid side exactly on a grid face must act like one a hair off it (moving solids cross faces every
   step). The three tanks (box on the faces, shifted by +-1e-9 m) run through the impact of the surge on
   the box with fixed steps: the same pressure and density iterations every step and the same particles
   to 1e-9 m. Before the face samples were snapped to the surface, the aligned box left its interior
   cells joined by faces open by 1e-14 and the pressure solve took 31-41 multigrid iterations per step
   instead of 8.
   (light: 0.18 s instead of 0.3 s; the surge reaches the box at 0.13 s (2D) and 0.15 s (3D) and is
   running up it by 0.18 s, so the impact is still in the run; the same bounds.) */
static void check_aligned_box(int dim) {
    fsdem_pic *s[3];
    const double shift[3] = {0, 1e-9, -1e-9}, dt = dim == 2 ? 2e-3 : 4e-3, duration = test_light() ? 0.18 : 0.3;
    int k, m, p, most = 0;
    for (m = 0; m < 3; ++m) s[m] = aligned_box_tank(dim, shift[m]);
    for (k = 0; k < (int)(duration / dt); ++k) {
        fsdem_pic_stats st[3];
        for (m = 0; m < 3; ++m) {
            ck_assert_int_eq(fsdem_pic_step_dt(s[m], (fsdem_real)dt), FSDEM_OK);
            st[m] = fsdem_pic_get_stats(s[m]);
        }
        for (m = 1; m < 3; ++m) {
            ck_assert_int_eq(st[m].pressure_iterations, st[0].pressure_iterations);
            ck_assert_int_eq(st[m].density_iterations, st[0].density_iterations);
            ck_assert_int_eq(st[m].particles, st[0].particles);
        }
        if (st[0].pressure_iterations > most) most = st[0].pressure_iterations;
    }
    for (m = 1; m < 3; ++m) {
        fsdem_pic_particles a = fsdem_pic_get_particles(s[0]), b = fsdem_pic_get_particles(s[m]);
        double worst = 0;
        for (p = 0; p < a.count; ++p) {
            double e = sqrt(pow(a.position[p].x - b.position[p].x, 2) + pow(a.position[p].y - b.position[p].y, 2) + pow(a.position[p].z - b.position[p].z, 2));
            if (e > worst) worst = e;
        }
        TEST_REPORT("aligned box %dD, shift %g m: largest particle offset %.3g m, most pressure iterations %d", dim, shift[m], worst,
                    most);
        /* particles pushed out of the box land on its surface and carry the 1e-9 m (1.5e-7 cells) shift into
           the flow; a bound of 1e-5 cells leaves two orders for its growth through the surge and is a
           million times below a change of the solids' fractions. In float the shift rounds away. */
        ck_assert(worst < 1e-5 * 0.584 / (dim == 2 ? 88 : 44));
    }
    ck_assert_int_le(most, 15); /* a multigrid-PCG solve of this tank takes 7-9 */
    for (m = 0; m < 3; ++m) fsdem_pic_destroy(s[m]);
}

START_TEST(face_aligned_solid_matches_a_hair_off) {
    check_aligned_box(2);
    check_aligned_box(3);
}
END_TEST

Suite *pic_suite(void) {
    Suite *s = suite_create("pic");
    TCase *tc = tcase_create("pic");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, still_water_2d_stays_still);
    tcase_add_test(tc, still_water_3d_stays_still);
    tcase_add_test(tc, still_water_with_the_default_seeding_stays_still);
    tcase_add_test(tc, still_water_apic_quadratic_stays_still);
    tcase_add_test(tc, still_water_around_obstacles_stays_still);
    tcase_add_test(tc, projection_is_discretely_divergence_free);
    tcase_add_test(tc, open_box_conserves_flux_past_obstacle);
    tcase_add_test(tc, option_matrix_runs_clean);
    tcase_add_test(tc, particles_stay_out_of_solids);
    tcase_add_test(tc, reseeding_moves_particles_into_sparse_cells);
    tcase_add_test(tc, implicit_viscosity_is_stable);
    tcase_add_test(tc, implicit_viscosity_decays_a_mode_exactly);
    tcase_add_test(tc, output_files_are_written);
    tcase_add_test(tc, bad_desc_is_rejected);
    tcase_add_test(tc, bad_input_leaves_solver_usable);
    tcase_add_test(tc, steps_do_not_allocate);
    tcase_add_test(tc, sdf_callback_matches_builtin_obstacle);
    tcase_add_test(tc, coupler_faces_carry_solid_flux);
    tcase_add_test(tc, face_aligned_solid_matches_a_hair_off);
    suite_add_tcase(s, tc);
    return s;
}
