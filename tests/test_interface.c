/* The coupling interface of >>doc: what the fluids report at points (fsdem_pic_sample,
   fsdem_swe_sample), the momentum sources a coupler adds (fsdem_pic_add_force, fsdem_swe_add_force,
   _clear_forces), the DEM's advance with a callback at every force evaluation
   (fsdem_dem_advance_with), and the NULL-object policy of every public function. Each expected value
   is computed here from the contract's formula, not read back from the library. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fsdem_tests.h"

#define IF_PI 3.14159265358979323846
#define IF_RHO 1000.0
#define IF_G 9.81

/* ---- PIC: a still tank ---- */

/* Still water 0.5 m deep in a closed tank of 0.1 m cells (2D: 1.0 x 0.8 m, 3D: 0.4 x 0.3 x 0.8 m),
   seeds not jittered, after `duration` s. */
static fsdem_pic *if_still_tank(int dim, double duration) {
    fsdem_pic_desc d = fsdem_pic_desc_default(dim);
    fsdem_pic *s = NULL;
    d.cell_size = (fsdem_real)0.1;
    d.jitter = 0;
    d.domain_max = dim == 2 ? fsdem_v3(1.0, 0.8, 0) : fsdem_v3(0.4, 0.3, 0.8);
    ck_assert_int_eq(fsdem_pic_create(&d, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(s, fsdem_v3(0, 0, 0), dim == 2 ? fsdem_v3(1.0, 0.5, 0) : fsdem_v3(0.4, 0.3, 0.5),
                                        fsdem_v3(0, 0, 0), NULL),
                     FSDEM_OK);
    if (duration > 0) ck_assert_int_eq(fsdem_pic_advance(s, (fsdem_real)duration, NULL), FSDEM_OK);
    return s;
}

/* The still-water bounds of test_pic.c (still_water_bounds): the hydrostatic state is exact on the
   grid, so the pressure error is the solve's, at most kappa tau sqrt(N) rho g h with
   kappa = 16 dim h^2 / (pi^2 dx^2) the condition number of the pressure matrix, tau the pressure
   tolerance and N the fluid cells; the velocity a step leaves is its gradient,
   2 kappa tau sqrt(N) g h dt / dx. A face difference (p_hi - p_lo) / dx then carries
   2 kappa tau sqrt(N) rho g h / dx, i.e. 2 kappa tau sqrt(N) h / dx of rho g (plus the rounding of
   p: 16 eps h / dx). */
static void if_still_bounds(const fsdem_pic *s, double h, double *grad_rel, double *speed) {
    const fsdem_pic_fields g = fsdem_pic_get_fields(s);
    const fsdem_pic_desc d = fsdem_pic_get_desc(s);
    const double dx = g.cell_size;
    int c, fluid = 0;
    double kt;
    for (c = 0; c < g.n[0] * g.n[1] * g.n[2]; ++c) fluid += g.cell[c] == FSDEM_STENCIL_CELL_FLUID;
    kt = 16.0 * g.dim * h * h / (IF_PI * IF_PI * dx * dx) * (double)d.pressure_tolerance * sqrt((double)fluid);
    *grad_rel = 2 * kt * h / dx + 16 * TEST_EPS * h / dx;
    *speed = 2 * kt * IF_G * h * (double)d.dt_max / dx;
}

/* fsdem_pic_sample in still water at rest: deep inside the pressure gradient is rho g (pointing down,
   against the surface), the velocity is the rest the projection leaves and the liquid fraction is 1;
   well above the surface the fraction is 0; across the surface it is the documented
   clamp(1/2 - phi/dx, 0, 1) of a plane at h = 0.5 m, interpolated between cell centres:
   0.5 + (h - y) / dx within half a cell of the surface (0.8 at y = 0.47 m). */
START_TEST(pic_sample_still_water) {
    int dim;
    for (dim = 2; dim <= 3; ++dim) {
        fsdem_pic *s = if_still_tank(dim, 0.1);
        const int up = dim - 1;
        fsdem_vec3 pts[6];
        fsdem_fluid_sample out[6];
        double grad_rel, speed, frac_tol;
        int q, a;
        if_still_bounds(s, 0.5, &grad_rel, &speed);
        /* the particles moved by at most speed x 0.1 s: that much of a cell of liquid fraction */
        frac_tol = speed * 0.1 / 0.1 + 16 * TEST_EPS;
        if (dim == 2) {
            pts[0] = fsdem_v3(0.43, 0.27, 0); /* deep, between faces and centres */
            pts[1] = fsdem_v3(0.71, 0.12, 0);
            pts[2] = fsdem_v3(0.43, 0.72, 0); /* above the surface */
            pts[3] = fsdem_v3(0.43, 0.47, 0); /* across the surface */
            pts[4] = fsdem_v3(0.66, 0.5, 0);
            pts[5] = fsdem_v3(0.43, 5.0, 0);  /* off the domain: clamped into its top cells */
        } else {
            pts[0] = fsdem_v3(0.17, 0.13, 0.27);
            pts[1] = fsdem_v3(0.29, 0.21, 0.12);
            pts[2] = fsdem_v3(0.17, 0.13, 0.72);
            pts[3] = fsdem_v3(0.17, 0.13, 0.47);
            pts[4] = fsdem_v3(0.26, 0.07, 0.5);
            pts[5] = fsdem_v3(0.17, 0.13, 5.0);
        }
        ck_assert_int_eq(fsdem_pic_sample(s, 6, pts, out), FSDEM_OK);
        for (q = 0; q < 2; ++q) {
            const double gp[3] = {out[q].pressure_gradient.x, out[q].pressure_gradient.y, out[q].pressure_gradient.z};
            TEST_REPORT("%dD point %d: grad p = (%.6g, %.6g, %.6g) Pa/m, |u| = %.2e m/s, fraction %.9g (bounds: %.2e of rho g, "
                        "%.2e m/s)",
                        dim, q, gp[0], gp[1], gp[2], sqrt(pow(out[q].velocity.x, 2) + pow(out[q].velocity.y, 2) + pow(out[q].velocity.z, 2)),
                        (double)out[q].volume_fraction, grad_rel, speed);
            /* grad p = rho g: -rho g along the vertical, 0 across */
            for (a = 0; a < dim; ++a)
                ck_assert_msg(fabs(gp[a] - (a == up ? -IF_RHO * IF_G : 0)) <= grad_rel * IF_RHO * IF_G,
                              "%dD point %d: grad p[%d] = %.9g Pa/m", dim, q, a, gp[a]);
            ck_assert_msg(fabs(out[q].velocity.x) <= speed && fabs(out[q].velocity.y) <= speed && fabs(out[q].velocity.z) <= speed,
                          "%dD point %d: velocity (%g, %g, %g)", dim, q, (double)out[q].velocity.x, (double)out[q].velocity.y,
                          (double)out[q].velocity.z);
            ck_assert_msg(fabs(out[q].volume_fraction - 1) <= frac_tol, "%dD point %d: fraction %.9g", dim, q,
                          (double)out[q].volume_fraction);
        }
        ck_assert_msg(fabs(out[2].volume_fraction) <= frac_tol, "%dD above: fraction %g", dim, (double)out[2].volume_fraction);
        ck_assert_msg(fabs(out[3].volume_fraction - 0.8) <= frac_tol + 8 * TEST_EPS, "%dD at 0.47 m: fraction %.9g, expected 0.8",
                      dim, (double)out[3].volume_fraction);
        ck_assert_msg(fabs(out[4].volume_fraction - 0.5) <= frac_tol + 8 * TEST_EPS, "%dD at the surface: fraction %.9g", dim,
                      (double)out[4].volume_fraction);
        ck_assert_msg(fabs(out[5].volume_fraction) <= frac_tol, "%dD off the domain: fraction %g", dim, (double)out[5].volume_fraction);
        /* count 0 is fine, NULL arrays are not */
        ck_assert_int_eq(fsdem_pic_sample(s, 0, NULL, NULL), FSDEM_OK);
        ck_assert_int_eq(fsdem_pic_sample(s, 2, NULL, out), FSDEM_ERR_INVALID_ARG);
        fsdem_pic_destroy(s);
    }
}
END_TEST

/* Tent weight of face position xf for a point at p, half-width hw, over the first `dim` axes. */
static double if_tent(fsdem_vec3 xf, fsdem_vec3 p, double hw, int dim) {
    const double d[3] = {(double)xf.x - p.x, (double)xf.y - p.y, (double)xf.z - p.z};
    double w = 1;
    int b;
    for (b = 0; b < dim; ++b) w *= fmax(0, 1 - fabs(d[b]) / hw);
    return w;
}

/* Checks one fsdem_pic_add_force against its contract, from the fields and the coupling arrays:
   along each axis a, the faces that received acceleration are exactly the faces with E > 0 next to
   a FLUID cell of the last step within the tent of half-width hw = max(radius, dx); each received
   force_a w_f / (W rho dx^dim) with w_f the tent weight and W their sum (so acceleration / w_f is
   the same on every face), and sum_f acceleration_f rho dx^dim = force_a (rounding: each of the n
   terms is a rounded product, the sum in double: (n + 8) eps |force_a|). */
static void if_check_spread(const fsdem_pic *s, fsdem_pic_coupling cp, fsdem_vec3 point, double radius, fsdem_vec3 force) {
    const fsdem_pic_fields g = fsdem_pic_get_fields(s);
    const double dx = g.cell_size, hw = fmax(radius, dx), cellv = pow(dx, g.dim);
    const double fa[3] = {force.x, force.y, force.z};
    int a;
    if (g.dim == 2) point.z = 0;
    for (a = 0; a < g.dim; ++a) {
        const int fn0 = g.n[0] + (a == 0), fn1 = g.n[1] + (a == 1), fn2 = g.dim == 3 ? g.n[2] + (a == 2) : 1;
        double sum = 0, ratio = 0;
        int i, j, k, faces = 0;
        /* the largest share first, to have the ratio before any tiny weight is met */
        for (k = 0; k < fn2 && fa[a] != 0; ++k)
            for (j = 0; j < fn1; ++j)
                for (i = 0; i < fn0; ++i) {
                    const int f = (k * fn1 + j) * fn0 + i;
                    const fsdem_vec3 xf = fsdem_v3((fsdem_real)(g.origin.x + dx * (i + (a == 0 ? 0 : 0.5))),
                                                   (fsdem_real)(g.origin.y + dx * (j + (a == 1 ? 0 : 0.5))),
                                                   (fsdem_real)(g.origin.z + dx * (k + (a == 2 ? 0 : 0.5))));
                    const double w = if_tent(xf, point, hw, g.dim);
                    if (cp.acceleration[a][f] != 0 && w > 0.1 && ratio == 0) ratio = cp.acceleration[a][f] / w;
                }
        for (k = 0; k < fn2; ++k)
            for (j = 0; j < fn1; ++j)
                for (i = 0; i < fn0; ++i) {
                    const int f = (k * fn1 + j) * fn0 + i, coord = a == 0 ? i : a == 1 ? j : k;
                    const int step = a == 0 ? 1 : a == 1 ? g.n[0] : g.n[0] * g.n[1];
                    const int above = coord < g.n[a] ? (k * g.n[1] + j) * g.n[0] + i : -1;
                    const int below = coord > 0 ? (k * g.n[1] + j) * g.n[0] + i - step : -1;
                    const int wet = (above >= 0 && g.cell[above] == FSDEM_STENCIL_CELL_FLUID) ||
                                    (below >= 0 && g.cell[below] == FSDEM_STENCIL_CELL_FLUID);
                    const fsdem_vec3 xf = fsdem_v3((fsdem_real)(g.origin.x + dx * (i + (a == 0 ? 0 : 0.5))),
                                                   (fsdem_real)(g.origin.y + dx * (j + (a == 1 ? 0 : 0.5))),
                                                   (fsdem_real)(g.origin.z + dx * (k + (a == 2 ? 0 : 0.5))));
                    const double w = if_tent(xf, point, hw, g.dim), acc = cp.acceleration[a][f];
                    /* a weight within rounding of 0 (a face at hw from the point) may go either way */
                    const double wtiny = 16 * TEST_EPS;
                    if (!wet || !(g.open[a][f] > 0) || w <= wtiny) {
                        ck_assert_msg(acc == 0 || (wet && g.open[a][f] > 0 && w <= wtiny && fabs(acc) <= 2 * wtiny * fabs(ratio)),
                                      "axis %d face %d: acceleration %g on a face outside the contract (weight %g)", a, f, acc, w);
                        sum += acc;
                        continue;
                    }
                    ck_assert_msg(fa[a] == 0 || acc != 0, "axis %d face %d (weight %g) next to the liquid received nothing", a, f, w);
                    if (fa[a] == 0) continue;
                    /* the weight's rounding (eps of the distances over hw) relative to w */
                    ck_assert_msg(fabs(acc / w - ratio) <= 16 * TEST_EPS / w * fabs(ratio), "axis %d face %d: acceleration %g is not the tent share",
                                  a, f, acc);
                    sum += acc;
                    faces++;
                }
        ck_assert_msg(fabs(sum * IF_RHO * cellv - fa[a]) <= (faces + 8) * TEST_EPS * fabs(fa[a]),
                      "axis %d: sum of acceleration x rho dx^dim = %.17g N, force %.17g N (%d faces)", a, sum * IF_RHO * cellv, fa[a],
                      faces);
        ck_assert_msg(fa[a] == 0 || faces > 0, "axis %d: no face took the force", a);
    }
}

/* fsdem_pic_add_force spreads the force over the faces next to the liquid with the tent kernel and
   exactly (sum of acceleration x rho dx^dim = force), in the bulk, where the kernel reaches the
   surface (part of it in air) and at a wall; a point with no such face within reach takes nothing
   and writes nothing; non-finite input is refused unchanged; fsdem_pic_clear_forces zeroes all. */
START_TEST(pic_add_force_is_exact) {
    int dim;
    for (dim = 2; dim <= 3; ++dim) {
        fsdem_pic *s = if_still_tank(dim, 0);
        fsdem_pic_coupling cp;
        fsdem_real *saved[3];
        const fsdem_vec3 force = fsdem_v3(3.5, -7.25, dim == 3 ? 1.5 : 0);
        fsdem_vec3 pts[3];
        const double radii[2] = {0, 0.23};
        int q, r, a, taken;
        ck_assert_int_eq(fsdem_pic_step(s), FSDEM_OK); /* the FLUID cells of a step */
        cp = fsdem_pic_get_coupling(s);
        if (dim == 2) {
            pts[0] = fsdem_v3(0.43, 0.22, 0);  /* bulk */
            pts[1] = fsdem_v3(0.61, 0.48, 0);  /* at the surface */
            pts[2] = fsdem_v3(0.04, 0.07, 0);  /* in a corner */
        } else {
            pts[0] = fsdem_v3(0.17, 0.13, 0.22);
            pts[1] = fsdem_v3(0.21, 0.16, 0.48);
            pts[2] = fsdem_v3(0.04, 0.27, 0.07);
        }
        for (q = 0; q < 3; ++q)
            for (r = 0; r < 2; ++r) {
                ck_assert_int_eq(fsdem_pic_clear_forces(s), FSDEM_OK);
                taken = -1;
                ck_assert_int_eq(fsdem_pic_add_force(s, pts[q], (fsdem_real)radii[r], force, &taken), FSDEM_OK);
                ck_assert_int_eq(taken, 1);
                if_check_spread(s, cp, pts[q], radii[r], force);
            }
        /* a second force adds to the first */
        ck_assert_int_eq(fsdem_pic_add_force(s, pts[0], 0, force, NULL), FSDEM_OK);
        for (a = 0; a < dim; ++a) {
            double sum = 0;
            int f;
            for (f = 0; f < cp.face_count[a]; ++f) sum += cp.acceleration[a][f];
            ck_assert_msg(fabs(sum * IF_RHO * pow(0.1, dim) - 2 * (double)(a == 0 ? force.x : a == 1 ? force.y : force.z)) <=
                              64 * TEST_EPS * 2 * fabs(a == 0 ? force.x : a == 1 ? force.y : force.z) + 1e-12,
                          "axis %d: two forces sum to %g", a, sum * IF_RHO * pow(0.1, dim));
        }
        /* nothing within reach: high in the air (no face next to a FLUID cell within a cell) */
        for (a = 0; a < dim; ++a) {
            saved[a] = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)cp.face_count[a]);
            memcpy(saved[a], cp.acceleration[a], sizeof(fsdem_real) * (size_t)cp.face_count[a]);
        }
        taken = -1;
        ck_assert_int_eq(fsdem_pic_add_force(s, dim == 2 ? fsdem_v3(0.43, 0.75, 0) : fsdem_v3(0.17, 0.13, 0.75), 0, force, &taken),
                         FSDEM_OK);
        ck_assert_int_eq(taken, 0);
        ck_assert_int_eq(fsdem_pic_add_force(s, pts[0], 0, fsdem_v3((fsdem_real)NAN, 0, 0), &taken), FSDEM_ERR_INVALID_ARG);
        ck_assert_int_eq(fsdem_pic_add_force(s, pts[0], -1, force, &taken), FSDEM_ERR_INVALID_ARG);
        for (a = 0; a < dim; ++a) {
            ck_assert_msg(memcmp(saved[a], cp.acceleration[a], sizeof(fsdem_real) * (size_t)cp.face_count[a]) == 0,
                          "axis %d: a force that was not taken changed the accelerations", a);
            free(saved[a]);
        }
        ck_assert_int_eq(fsdem_pic_clear_forces(s), FSDEM_OK);
        for (a = 0; a < dim; ++a) {
            int f;
            for (f = 0; f < cp.face_count[a]; ++f) ck_assert(cp.acceleration[a][f] == 0);
        }
        fsdem_pic_destroy(s);
    }
}
END_TEST

/* ---- SWE ---- */

/* A 2D lake with a sloping surface eta = 0.6 + 0.02 x - 0.03 y over a sloping bed 0.1 + 0.05 x, flowing
   uniformly at (0.3, -0.2) m/s, with a dry bank (bed at 1 m) for x > 1.6 m; 0.1 m cells on
   [0, 2] x [0, 1]. */
static void if_lake(void *user, fsdem_real x, fsdem_real y, fsdem_swe_cell *c) {
    const double eta = 0.6 + 0.02 * x - 0.03 * y;
    (void)user;
    c->bed = (fsdem_real)(x > 1.6 ? 1.0 : 0.1 + 0.05 * x);
    c->depth = (fsdem_real)(eta > c->bed ? eta - c->bed : 0);
    c->u = 0.3;
    c->v = -0.2;
}

static void if_channel(void *user, fsdem_real x, fsdem_real y, fsdem_swe_cell *c) {
    (void)user;
    (void)y;
    c->bed = (fsdem_real)(0.1 + 0.05 * x);
    c->depth = (fsdem_real)(0.6 + 0.02 * x - c->bed);
    c->u = 0.3;
    c->v = 0;
}

/* fsdem_swe_sample: in the water column (bed <= z <= eta) the depth-averaged velocity, the
   hydrostatic gradient rho g (deta/dx, deta/dy, -1) and fraction 1; above the surface, below the bed,
   over a dry cell and off the grid everything is 0. The fields are linear where sampled, so the
   bilinear sampling and the one-cell surface difference are exact; rounding: the surface (~0.7 m) is
   rounded to eps at each cell, and the slope is a difference over dx = 0.1 m: 64 eps x 0.7 / 0.1 of
   rho g, 16 eps of the velocities. Also 1D (y ignored). */
START_TEST(swe_sample_sloping_lake) {
    int dim;
    for (dim = 1; dim <= 2; ++dim) {
        fsdem_swe_desc d = fsdem_swe_desc_default(dim);
        fsdem_swe *s;
        fsdem_vec3 pts[7];
        fsdem_fluid_sample out[7];
        const double x = 0.73, y = dim == 2 ? 0.41 : 0, bed = 0.1 + 0.05 * x, eta = 0.6 + 0.02 * x - (dim == 2 ? 0.03 * y : 0);
        const double rg = IF_RHO * IF_G, gtol = 64 * TEST_EPS * 0.7 / 0.1 * rg, vtol = 16 * TEST_EPS;
        int q;
        d.nx = 20;
        d.ny = dim == 2 ? 10 : 1;
        d.x_max = 2;
        ck_assert_int_eq(fsdem_swe_create(&d, &s), FSDEM_OK);
        ck_assert_int_eq(fsdem_swe_set_cells(s, dim == 2 ? if_lake : if_channel, NULL), FSDEM_OK);
        pts[0] = fsdem_v3((fsdem_real)x, (fsdem_real)y, (fsdem_real)(bed + 0.5 * (eta - bed))); /* mid column */
        pts[1] = fsdem_v3((fsdem_real)x, (fsdem_real)y, (fsdem_real)(bed + 0.01));              /* just above the bed */
        pts[2] = fsdem_v3((fsdem_real)x, (fsdem_real)y, (fsdem_real)(eta + 0.02));              /* above the surface */
        pts[3] = fsdem_v3((fsdem_real)x, (fsdem_real)y, (fsdem_real)(bed - 0.02));              /* below the bed */
        pts[4] = fsdem_v3(2.5, (fsdem_real)y, 0.3);                                            /* off the grid */
        pts[5] = dim == 2 ? fsdem_v3(0.5, -0.2, 0.3) : fsdem_v3(-0.1, 0, 0.3);
        pts[6] = dim == 2 ? fsdem_v3(1.85, 0.5, 1.02) : fsdem_v3(1.23, 7, 0.5); /* 2D: over the dry bank; 1D: y ignored */
        ck_assert_int_eq(fsdem_swe_sample(s, 7, pts, out), FSDEM_OK);
        for (q = 0; q < 2; ++q) {
            TEST_REPORT("%dD: u = (%.9g, %.9g, %.9g) m/s, grad p = (%.9g, %.9g, %.9g) Pa/m, fraction %g", dim, (double)out[q].velocity.x,
                        (double)out[q].velocity.y, (double)out[q].velocity.z, (double)out[q].pressure_gradient.x,
                        (double)out[q].pressure_gradient.y, (double)out[q].pressure_gradient.z, (double)out[q].volume_fraction);
            ck_assert_double_eq_tol(out[q].velocity.x, 0.3, vtol);
            ck_assert_double_eq_tol(out[q].velocity.y, dim == 2 ? -0.2 : 0, vtol);
            ck_assert(out[q].velocity.z == 0);
            ck_assert_double_eq_tol(out[q].pressure_gradient.x, rg * 0.02, gtol);
            ck_assert_double_eq_tol(out[q].pressure_gradient.y, dim == 2 ? rg * -0.03 : 0, gtol);
            ck_assert_double_eq_tol(out[q].pressure_gradient.z, -rg, 8 * TEST_EPS * rg);
            ck_assert(out[q].volume_fraction == 1);
        }
        for (q = 2; q < 7; ++q) {
            if (dim == 1 && q == 6) {
                /* 1D: y is ignored, so (1.23, 7) is in the channel */
                ck_assert(out[q].volume_fraction == 1);
                ck_assert_double_eq_tol(out[q].pressure_gradient.x, rg * 0.02, gtol);
                continue;
            }
            ck_assert_msg(out[q].volume_fraction == 0 && out[q].velocity.x == 0 && out[q].velocity.y == 0 && out[q].velocity.z == 0 &&
                              out[q].pressure_gradient.x == 0 && out[q].pressure_gradient.y == 0 && out[q].pressure_gradient.z == 0,
                          "%dD point %d: fraction %g, velocity %g, gradient %g", dim, q, (double)out[q].volume_fraction,
                          (double)out[q].velocity.x, (double)out[q].pressure_gradient.z);
        }
        /* inside the outermost half-cells (corner (0.02, 0.02), and (1.98, ...) in 1D), where the samples
           are clamped to the last centres: the slope of the nearest pair of centres, exact for this plane */
        pts[0] = fsdem_v3(dim == 2 ? 0.02 : 1.98, dim == 2 ? 0.02 : 0, 0.3);
        ck_assert_int_eq(fsdem_swe_sample(s, 1, pts, out), FSDEM_OK);
        ck_assert(out[0].volume_fraction == 1);
        ck_assert_double_eq_tol(out[0].pressure_gradient.x, rg * 0.02, gtol);
        ck_assert_double_eq_tol(out[0].pressure_gradient.y, dim == 2 ? rg * -0.03 : 0, gtol);
        ck_assert_int_eq(fsdem_swe_sample(s, 1, pts, NULL), FSDEM_ERR_INVALID_ARG);
        fsdem_swe_destroy(s);
    }
}
END_TEST

/* Half-wet basin: 10 x 10 cells of 0.1 m, 0.2 m of water for x < 0.5 m, dry beyond (flat bed). */
static void if_half_wet(void *user, fsdem_real x, fsdem_real y, fsdem_swe_cell *c) {
    (void)user;
    (void)y;
    c->bed = 0;
    c->depth = x < 0.5 ? 0.2 : 0;
    c->u = c->v = 0;
}

/* Overlap length of [a0, a1] with [b0, b1]. */
static double if_overlap(double a0, double a1, double b0, double b1) { return fmax(0, fmin(a1, b1) - fmax(a0, b0)); }

/* Shares of the cells of an n x m grid of 0.1 m cells (m = 1: 1D) under the footprint of (x, y) and r
   as fsdem_real holds them, wet cells (x < 0.5) only, in proportion to the overlap. */
static void if_footprint_shares(double *share, int n, int m, double x, double y, double r) {
    const double X = (fsdem_real)x, Y = (fsdem_real)y, Rr = (fsdem_real)r;
    double total = 0;
    int k;
    for (k = 0; k < n * m; ++k) {
        const int i = k % n, j = k / n;
        share[k] = 0.1 * i < 0.5 ? if_overlap(X - Rr, X + Rr, 0.1 * i, 0.1 * (i + 1)) *
                                       (m > 1 ? if_overlap(Y - Rr, Y + Rr, 0.1 * j, 0.1 * (j + 1)) : 1)
                                 : 0;
        total += share[k];
    }
    for (k = 0; k < n * m; ++k) share[k] /= total;
}

/* Adds `f` at p with radius r to a cleared coupling and checks the sources against `share`
   (the fraction of the force each cell must receive, computed by the caller from the contract):
   source_k rho A = share_k force in x and y, and sum_k source_k rho A = force (rounding: 16 eps). */
static void if_check_swe_shares(fsdem_swe *s, fsdem_vec3 p, double r, fsdem_vec3 f, const double *share) {
    const fsdem_swe_grid g = fsdem_swe_get_grid(s);
    const fsdem_swe_coupling cp = fsdem_swe_get_coupling(s);
    double sx = 0, sy = 0;
    int k, taken = -1;
    ck_assert_int_eq(fsdem_swe_clear_forces(s), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_add_force(s, p, (fsdem_real)r, f, &taken), FSDEM_OK);
    ck_assert_int_eq(taken, 1);
    for (k = 0; k < g.nx * g.ny; ++k) {
        const double fx = (double)cp.source_x[k] * IF_RHO * g.cell_area, fy = (double)cp.source_y[k] * IF_RHO * g.cell_area;
        ck_assert_msg(fabs(fx - share[k] * f.x) <= 16 * TEST_EPS * fabs(f.x), "cell %d: %.9g N of %g, expected %.9g", k, fx,
                      (double)f.x, share[k] * f.x);
        if (g.dim == 2)
            ck_assert_msg(fabs(fy - share[k] * f.y) <= 16 * TEST_EPS * fabs(f.y), "cell %d: %.9g N of %g, expected %.9g", k, fy,
                          (double)f.y, share[k] * f.y);
        sx += fx;
        sy += fy;
    }
    ck_assert_msg(fabs(sx - f.x) <= 16 * TEST_EPS * fabs(f.x), "x: the sources add up to %.17g N, force %g N", sx, (double)f.x);
    if (g.dim == 2) ck_assert_msg(fabs(sy - f.y) <= 16 * TEST_EPS * fabs(f.y), "y: the sources add up to %.17g N", sy);
}

/* fsdem_swe_add_force with a footprint: shares in proportion to the overlap of each wet cell with
   the square [x - r, x + r] x [y - r, y + r], all of the force (sum of source x rho x cell area =
   force); a footprint half on dry cells gives everything to its wet part; a footprint on dry cells
   only goes, in equal shares, to the wet cells of the footprint grown by one cell; in an all-dry
   neighbourhood it is not taken (taken = 0) and nothing changes; off the grid and non-finite input
   are refused unchanged; clear_forces zeroes everything. Also 1D, where the cell area is dx width. */
START_TEST(swe_add_force_footprint) {
    fsdem_swe_desc d = fsdem_swe_desc_default(2);
    fsdem_swe *s;
    fsdem_swe_coupling cp;
    double share[100];
    fsdem_real save_x[100], save_y[100];
    const fsdem_vec3 f = fsdem_v3(12.5, -4.75, 99);
    int j, k, taken;
    d.nx = d.ny = 10;
    ck_assert_int_eq(fsdem_swe_create(&d, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_set_cells(s, if_half_wet, NULL), FSDEM_OK);
    cp = fsdem_swe_get_coupling(s);
    /* (a) wholly wet footprint [0.11, 0.35] x [0.35, 0.59]: overlap areas */
    if_footprint_shares(share, 10, 10, 0.23, 0.47, 0.12);
    if_check_swe_shares(s, fsdem_v3(0.23, 0.47, 0), 0.12, f, share);
    /* (b) footprint [0.42, 0.52] x [0.45, 0.55] over the wet/dry line x = 0.5: the wet column i = 4 takes
       it all, half in row 4 and half in row 5 */
    memset(share, 0, sizeof share);
    share[4 + 10 * 4] = share[4 + 10 * 5] = 0.5;
    if_check_swe_shares(s, fsdem_v3(0.47, 0.5, 0), 0.05, f, share);
    /* (c) footprint [0.52, 0.58] x [0.49, 0.55] on dry cells (column 5, rows 4 and 5): grown by one
       cell, columns 4 to 6 and rows 3 to 6, whose wet cells are (4, 3..6): a quarter each */
    memset(share, 0, sizeof share);
    for (j = 3; j <= 6; ++j) share[4 + 10 * j] = 0.25;
    if_check_swe_shares(s, fsdem_v3(0.55, 0.52, 0), 0.03, f, share);
    /* (d) all dry within the grown footprint: not taken, nothing written */
    memcpy(save_x, cp.source_x, sizeof save_x);
    memcpy(save_y, cp.source_y, sizeof save_y);
    taken = -1;
    ck_assert_int_eq(fsdem_swe_add_force(s, fsdem_v3(0.85, 0.5, 0), 0.03, f, &taken), FSDEM_OK);
    ck_assert_int_eq(taken, 0);
    /* (e) refused */
    ck_assert_int_eq(fsdem_swe_add_force(s, fsdem_v3(1.5, 0.5, 0), 0, f, &taken), FSDEM_ERR_OUT_OF_DOMAIN);
    ck_assert_int_eq(fsdem_swe_add_force(s, fsdem_v3(0.2, 0.5, 0), -0.1, f, &taken), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_swe_add_force(s, fsdem_v3(0.2, 0.5, 0), 0, fsdem_v3((fsdem_real)INFINITY, 0, 0), &taken),
                     FSDEM_ERR_INVALID_ARG);
    ck_assert(memcmp(save_x, cp.source_x, sizeof save_x) == 0 && memcmp(save_y, cp.source_y, sizeof save_y) == 0);
    /* radius 0: the wet cell holding the point */
    memset(share, 0, sizeof share);
    share[2 + 10 * 4] = 1;
    if_check_swe_shares(s, fsdem_v3(0.23, 0.47, 0), 0, f, share);
    ck_assert_int_eq(fsdem_swe_clear_forces(s), FSDEM_OK);
    for (k = 0; k < 100; ++k) ck_assert(cp.source_x[k] == 0 && cp.source_y[k] == 0);
    fsdem_swe_destroy(s);

    /* 1D, width 2 m: footprint [0.31, 0.55] over 0.1 m cells, all wet */
    d = fsdem_swe_desc_default(1);
    d.nx = 10;
    d.width = 2;
    ck_assert_int_eq(fsdem_swe_create(&d, &s), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_set_cells(s, if_half_wet, NULL), FSDEM_OK);
    ck_assert_double_eq_tol(fsdem_swe_get_grid(s).cell_area, 0.2, 4 * TEST_EPS);
    if_footprint_shares(share, 10, 1, 0.43, 0, 0.12);
    if_check_swe_shares(s, fsdem_v3(0.43, 0, 0), 0.12, f, share);
    fsdem_swe_destroy(s);
}
END_TEST

/* ---- DEM: the advance with a substep callback ---- */

typedef struct if_calls {
    int count, fail_at;           /* calls so far; the call (1-based) that returns `code` (0: none) */
    fsdem_result code;
    double time[64];
    fsdem_vec3 position[64];      /* particle 0 as the callback sees it */
    int loads;                    /* 1: write the constant loads below at every call */
    fsdem_vec3 force[4], torque[4];
} if_calls;

static fsdem_result if_callback(void *user, fsdem_dem *dem, double time) {
    if_calls *c = (if_calls *)user;
    if (c->count < 64) {
        c->time[c->count] = time;
        c->position[c->count] = fsdem_dem_get_particles(dem).position[0];
    }
    c->count++;
    if (c->loads) {
        fsdem_dem_coupling cp = fsdem_dem_get_coupling(dem);
        int i;
        for (i = 0; i < cp.count && i < 4; ++i) {
            cp.force[i] = c->force[i];
            cp.torque[i] = c->torque[i];
        }
    }
    return c->fail_at && c->count == c->fail_at ? c->code : FSDEM_OK;
}

/* Four spheres: one falling freely (particle 0, far from the rest), one on a floor, one on top of it
   and one beside it, all touching by 10 um to 0.1 mm (Hertz forces of a fraction of their weight, so
   the contacts last), spinning; dt = 1e-4 s. */
static fsdem_dem *if_dem(fsdem_dem_integrator integrator) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem;
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_dem_wall_desc w;
    int mat;
    d.dt = 1e-4;
    d.integrator = integrator;
    ck_assert_int_eq(fsdem_dem_create(&d, &dem), FSDEM_OK);
    m.young_modulus = 1e7;
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat), FSDEM_OK);
    w = fsdem_dem_wall_plane(fsdem_v3(0, 0, -0.5), fsdem_v3(0, 0, 1), mat);
    ck_assert_int_eq(fsdem_dem_add_wall(dem, &w, NULL), FSDEM_OK);
    p.radius = 0.01;
    p.material = mat;
    p.position = fsdem_v3(0.5, 0.5, 0.5);
    p.velocity = fsdem_v3(0.2, 0, 0.1);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
    p.velocity = fsdem_v3(0, 0, 0);
    p.position = fsdem_v3(0, 0, -0.49001);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
    p.position = fsdem_v3(0.001, 0, -0.47003);
    p.angular_velocity = fsdem_v3(0, 3, 5);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
    p.position = fsdem_v3(0.0199, 0, -0.49001);
    p.angular_velocity = fsdem_v3(2, 0, -5);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
    return dem;
}

/* fsdem_dem_advance_with (velocity Verlet): the callback runs once before the first substep and once
   after each substep's drift, at times t0, t0 + h, ..., t0 + K h, and sees the positions of that time
   (particle 0 falls freely: Verlet is exact for a constant force, so its position at call k is
   x0 + v0 t + g t^2 / 2 to rounding); writing a constant load in the callback gives the state of
   fsdem_dem_advance with the load preset (the same arithmetic: equal to rounding); a callback that
   fails stops the advance at once with its code, after complete substeps. The predictor-corrector
   calls it at the start of each substep. */
START_TEST(dem_advance_with_callback) {
    fsdem_dem *a, *b;
    if_calls calls;
    fsdem_dem_particles pa, pb;
    fsdem_dem_coupling cp;
    long long steps = -1;
    double t0, h;
    int i, k;
    const int K = 10;
    /* calls and times */
    a = if_dem(FSDEM_DEM_INTEGRATOR_VERLET);
    ck_assert_int_eq(fsdem_dem_step(a), FSDEM_OK); /* from a non-zero time */
    memset(&calls, 0, sizeof calls);
    t0 = fsdem_dem_time(a);
    pa = fsdem_dem_get_particles(a);
    {
        const fsdem_vec3 x0 = pa.position[0], v0 = pa.velocity[0];
        ck_assert_int_eq(fsdem_dem_advance_with(a, (fsdem_real)(K * 1e-4), if_callback, &calls, &steps), FSDEM_OK);
        ck_assert_int_eq(steps, K);
        ck_assert_int_eq(calls.count, K + 1);
        h = (double)(fsdem_real)(K * 1e-4) / K;
        for (k = 0; k <= K; ++k) {
            const double t = k * h, z = x0.z + v0.z * t - 0.5 * IF_G * t * t, x = x0.x + v0.x * t;
            ck_assert_msg(fabs(calls.time[k] - (t0 + k * h)) <= 4 * TEST_EPS * (t0 + K * h), "call %d at t = %.17g, expected %.17g",
                          k, calls.time[k], t0 + k * h);
            if (k > 0) ck_assert(calls.time[k] > calls.time[k - 1]);
            /* rounding: k drifts of positions of 0.5 m, 4 eps each */
            ck_assert_msg(fabs(calls.position[k].z - z) <= 4 * (k + 1) * TEST_EPS * 0.5 &&
                              fabs(calls.position[k].x - x) <= 4 * (k + 1) * TEST_EPS * 0.5,
                          "call %d: particle 0 at (%.9g, %.9g), expected (%.9g, %.9g)", k, (double)calls.position[k].x,
                          (double)calls.position[k].z, x, z);
        }
        /* the last call saw the final positions (the closing half kick moves no one) */
        pa = fsdem_dem_get_particles(a);
        ck_assert(calls.position[K].x == pa.position[0].x && calls.position[K].z == pa.position[0].z);
    }
    fsdem_dem_destroy(a);

    /* a constant load written by the callback = the same load preset */
    a = if_dem(FSDEM_DEM_INTEGRATOR_VERLET);
    b = if_dem(FSDEM_DEM_INTEGRATOR_VERLET);
    memset(&calls, 0, sizeof calls);
    calls.loads = 1;
    for (i = 0; i < 4; ++i) {
        calls.force[i] = fsdem_v3(0.01 * (float)(i + 1), -0.02, 0.03 * (float)i);
        calls.torque[i] = fsdem_v3(0, 1e-5 * (float)i, -2e-5);
    }
    cp = fsdem_dem_get_coupling(a);
    for (i = 0; i < 4; ++i) {
        cp.force[i] = calls.force[i];
        cp.torque[i] = calls.torque[i];
    }
    ck_assert_int_eq(fsdem_dem_advance(a, (fsdem_real)(50 * 1e-4), NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_advance_with(b, (fsdem_real)(50 * 1e-4), if_callback, &calls, NULL), FSDEM_OK);
    ck_assert_int_eq(calls.count, 51);
    ck_assert_int_gt(fsdem_dem_get_stats(a).contacts + fsdem_dem_get_stats(a).wall_contacts, 1);
    pa = fsdem_dem_get_particles(a);
    pb = fsdem_dem_get_particles(b);
    for (i = 0; i < 4; ++i) {
        const double dx = fabs(pa.position[i].x - pb.position[i].x) + fabs(pa.position[i].y - pb.position[i].y) +
                          fabs(pa.position[i].z - pb.position[i].z);
        const double dv = fabs(pa.velocity[i].x - pb.velocity[i].x) + fabs(pa.velocity[i].y - pb.velocity[i].y) +
                          fabs(pa.velocity[i].z - pb.velocity[i].z);
        const double dw = fabs(pa.angular_velocity[i].x - pb.angular_velocity[i].x) +
                          fabs(pa.angular_velocity[i].y - pb.angular_velocity[i].y) +
                          fabs(pa.angular_velocity[i].z - pb.angular_velocity[i].z);
        TEST_REPORT("particle %d: preset vs callback loads differ by %.2e m, %.2e m/s, %.2e rad/s", i, dx, dv, dw);
        /* the same operations on the same numbers: rounding at most (4 eps of 0.5 m, 1 m/s, 10 rad/s) */
        ck_assert_msg(dx <= 4 * TEST_EPS * 0.5 && dv <= 4 * TEST_EPS && dw <= 4 * TEST_EPS * 10, "particle %d: %g m, %g m/s, %g rad/s",
                      i, dx, dv, dw);
        /* the preset loads persist through the advance; the callback's are the same numbers */
        ck_assert(pb.external_force[i].x == pa.external_force[i].x && pb.external_force[i].y == pa.external_force[i].y &&
                  pb.external_force[i].z == pa.external_force[i].z && pb.external_torque[i].y == pa.external_torque[i].y &&
                  pb.external_torque[i].z == pa.external_torque[i].z);
    }
    fsdem_dem_destroy(a);
    fsdem_dem_destroy(b);

    /* a failing callback stops the advance with its code: after its 4th call, i.e. 3 complete
       substeps (the half kick closed: particle 0's velocity is v0 + g 3h, exact for Verlet) */
    a = if_dem(FSDEM_DEM_INTEGRATOR_VERLET);
    memset(&calls, 0, sizeof calls);
    calls.fail_at = 4;
    calls.code = FSDEM_ERR_NOT_CONVERGED;
    pa = fsdem_dem_get_particles(a);
    {
        const double vz0 = pa.velocity[0].z;
        ck_assert_int_eq(fsdem_dem_advance_with(a, (fsdem_real)(K * 1e-4), if_callback, &calls, NULL), FSDEM_ERR_NOT_CONVERGED);
        ck_assert_int_eq(calls.count, 4);
        ck_assert_int_eq(fsdem_dem_get_stats(a).steps, 3);
        ck_assert_double_eq_tol(fsdem_dem_time(a), 3 * h, 4 * TEST_EPS * 3 * h);
        pa = fsdem_dem_get_particles(a);
        ck_assert_double_eq_tol(pa.velocity[0].z, vz0 - IF_G * 3 * h, 8 * TEST_EPS);
    }
    /* ... and the object goes on */
    ck_assert_int_eq(fsdem_dem_advance(a, (fsdem_real)(K * 1e-4), NULL), FSDEM_OK);
    /* failing at the first call: nothing moves */
    memset(&calls, 0, sizeof calls);
    calls.fail_at = 1;
    calls.code = FSDEM_ERR_IO;
    t0 = fsdem_dem_time(a);
    ck_assert_int_eq(fsdem_dem_advance_with(a, (fsdem_real)(K * 1e-4), if_callback, &calls, NULL), FSDEM_ERR_IO);
    ck_assert_int_eq(calls.count, 1);
    ck_assert(fsdem_dem_time(a) == t0);
    ck_assert_int_eq(fsdem_dem_advance_with(a, (fsdem_real)(K * 1e-4), NULL, NULL, NULL), FSDEM_OK); /* fn may be NULL */
    fsdem_dem_destroy(a);

    /* predictor-corrector: one call at the start of each substep */
    a = if_dem(FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR);
    memset(&calls, 0, sizeof calls);
    t0 = fsdem_dem_time(a);
    ck_assert_int_eq(fsdem_dem_advance_with(a, (fsdem_real)(K * 1e-4), if_callback, &calls, NULL), FSDEM_OK);
    ck_assert_int_eq(calls.count, K);
    for (k = 0; k < K; ++k)
        ck_assert_msg(fabs(calls.time[k] - (t0 + k * h)) <= 4 * TEST_EPS * K * h, "call %d at t = %.17g", k, calls.time[k]);
    fsdem_dem_destroy(a);
}
END_TEST

/* ---- the NULL-object policy ---- */

/* Every public function that takes an object (fsdem_dem, fsdem_pic, fsdem_swe, fsdem_mps, the
   couplers fsdem_swe_dem, fsdem_mps_dem and fsdem_pic_dem, fsdem_pcg), or the desc or output pointer of a create, refuses NULL with FSDEM_ERR_INVALID_ARG;
   getters return zeros (cell_at: -1, "outside"); last_error says which object is NULL; destroy
   accepts NULL. Wrong answers are collected and reported together (a crash stops the test at the
   call). */
typedef struct if_policy {
    char failed[4096];
    int count, calls;
} if_policy;

static void if_expect(if_policy *p, const char *name, int ok) {
    p->calls++;
    if (ok) return;
    p->count++;
    if (strlen(p->failed) + strlen(name) + 3 < sizeof p->failed) {
        if (p->failed[0]) strcat(p->failed, ", ");
        strcat(p->failed, name);
    }
}
/* mark_point: a crash is reported at the line of the call */
#define IF_TRUE(p, name, cond)                                                                     \
    do {                                                                                           \
        mark_point();                                                                              \
        if_expect((p), name, (cond));                                                              \
    } while (0)
#define IF_REFUSED(p, call)                                                                        \
    do {                                                                                           \
        mark_point();                                                                              \
        if_expect((p), #call, (call) == FSDEM_ERR_INVALID_ARG);                                    \
    } while (0)
#define IF_ZERO(p, name, value)                                                                    \
    do {                                                                                           \
        mark_point();                                                                              \
        if_expect((p), name, (value) == 0);                                                        \
    } while (0)

/* The verbs every coupler fsdem_X (X = swe_dem, mps_dem, pic_dem; its fluid pointer F in the desc)
   shares (>>doc, ONE DIALECT FOR EVERY SOLVER), called with a NULL coupler. */
#define IF_COUPLER_DIALECT(p, X, F)                                                                \
    do {                                                                                           \
        fsdem_##X##_desc d_ = fsdem_##X##_desc_default(), dd_;                                     \
        fsdem_##X *c_ = (fsdem_##X *)(p);                                                          \
        fsdem_##X##_force f_;                                                                      \
        fsdem_##X##_stats st_;                                                                     \
        fsdem_real dt_ = 1;                                                                        \
        long long steps_ = 7;                                                                      \
        char msg_[64];                                                                             \
        const char *text_;                                                                         \
        size_t size_ = 0;                                                                          \
        IF_REFUSED(p, fsdem_##X##_desc_check(NULL, msg_, sizeof msg_));                            \
        IF_REFUSED(p, fsdem_##X##_create(NULL, &c_));                                              \
        IF_TRUE(p, "fsdem_" #X "_create(NULL, &c) sets c to NULL", c_ == NULL);                    \
        IF_REFUSED(p, fsdem_##X##_create(&d_, NULL));                                              \
        mark_point();                                                                              \
        fsdem_##X##_destroy(NULL);                                                                 \
        mark_point();                                                                              \
        text_ = fsdem_##X##_last_error(NULL);                                                      \
        IF_TRUE(p, "fsdem_" #X "_last_error(NULL)", text_ && strstr(text_, "fsdem_" #X) && strstr(text_, "NULL")); \
        mark_point();                                                                              \
        dd_ = fsdem_##X##_get_desc(NULL);                                                          \
        IF_ZERO(p, "fsdem_" #X "_get_desc(NULL)", (dd_.F != NULL) + (dd_.dem != NULL) + dd_.max_substeps + (dd_.log != NULL)); \
        IF_REFUSED(p, fsdem_##X##_get_force(NULL, 0, &f_));                                        \
        IF_REFUSED(p, fsdem_##X##_step(NULL));                                                     \
        IF_REFUSED(p, fsdem_##X##_step_dt(NULL, 1e-3));                                            \
        IF_REFUSED(p, fsdem_##X##_advance(NULL, 1e-3, &steps_));                                   \
        IF_REFUSED(p, fsdem_##X##_stable_dt(NULL, &dt_));                                          \
        IF_ZERO(p, "fsdem_" #X "_time(NULL)", fsdem_##X##_time(NULL));                             \
        mark_point();                                                                              \
        st_ = fsdem_##X##_get_stats(NULL);                                                         \
        IF_ZERO(p, "fsdem_" #X "_get_stats(NULL)", st_.coupling.steps + st_.coupling.time + st_.coupling.dt + st_.coupling.substeps + st_.coupling.substeps_total); \
        IF_REFUSED(p, fsdem_##X##_write_csv(NULL, "build/never_null.csv"));                        \
        IF_REFUSED(p, fsdem_##X##_save(NULL, "build/never_null.rst"));                             \
        IF_REFUSED(p, fsdem_##X##_restore(NULL, "build/never_null.rst"));                          \
        IF_REFUSED(p, fsdem_##X##_save_memory(NULL, NULL, 0, &size_));                             \
        IF_REFUSED(p, fsdem_##X##_restore_memory(NULL, NULL, 0));                                  \
    } while (0)

static int if_zero_bytes(const void *x, size_t n) {
    const unsigned char *c = (const unsigned char *)x;
    size_t i;
    for (i = 0; i < n; ++i)
        if (c[i]) return 0;
    return 1;
}

static fsdem_real if_plane(void *user, fsdem_vec3 q, fsdem_vec3 *n) {
    (void)user;
    if (n) *n = fsdem_v3(0, 0, 1);
    return q.z;
}

static void if_cells(void *user, fsdem_real x, fsdem_real y, fsdem_swe_cell *c) {
    (void)user, (void)x, (void)y;
    c->bed = 0, c->depth = 0.1, c->u = c->v = 0;
}

START_TEST(null_objects_are_refused) {
    if_policy p;
    fsdem_vec3 v = fsdem_v3(0, 0, 0), tri[3];
    fsdem_real r[8] = {0}, dt = 1;
    long long steps = 7;
    int idx = 7, taken = 7;
    char msg[64];
    const char *text;
    memset(&p, 0, sizeof p);
    tri[0] = fsdem_v3(0, 0, 0), tri[1] = fsdem_v3(1, 0, 0), tri[2] = fsdem_v3(0, 1, 0);
    /* ---- fsdem_dem ---- */
    {
        fsdem_dem_desc d = fsdem_dem_desc_default(3);
        fsdem_dem_material m = fsdem_dem_material_default();
        fsdem_dem_material_pair pair = {1, 1, 1, 1};
        fsdem_dem_particle_desc pd = fsdem_dem_particle_desc_default();
        fsdem_dem_wall_desc w = fsdem_dem_wall_plane(v, fsdem_v3(0, 0, 1), 0);
        fsdem_dem *dem = (fsdem_dem *)&p;
        fsdem_dem_particles pp;
        fsdem_dem_coupling cc;
        fsdem_dem_desc dd;
        fsdem_dem_energy en;
        fsdem_dem_stats st;
        fsdem_vec3 f;
        IF_REFUSED(&p, fsdem_dem_desc_check(NULL, msg, sizeof msg));
        IF_REFUSED(&p, fsdem_dem_create(NULL, &dem));
        IF_TRUE(&p, "fsdem_dem_create(NULL, &dem) sets dem to NULL", dem == NULL);
        IF_REFUSED(&p, fsdem_dem_create(&d, NULL));
        mark_point();
        fsdem_dem_destroy(NULL);
        mark_point();
        text = fsdem_dem_last_error(NULL);
        IF_TRUE(&p, "fsdem_dem_last_error(NULL)", text && strstr(text, "fsdem_dem") && strstr(text, "NULL"));
        IF_REFUSED(&p, fsdem_dem_add_material(NULL, &m, &idx));
        IF_REFUSED(&p, fsdem_dem_set_material_pair(NULL, 0, 0, &pair));
        mark_point();
        pair = fsdem_dem_get_material_pair(NULL, 0, 0);
        IF_ZERO(&p, "fsdem_dem_get_material_pair(NULL, 0, 0)", fabs(pair.restitution) + fabs(pair.friction) +
                                                                   fabs(pair.rolling_friction) + fabs(pair.cohesion));
        IF_REFUSED(&p, fsdem_dem_add_particle(NULL, &pd, &idx));
        IF_REFUSED(&p, fsdem_dem_remove_particle(NULL, 0));
        IF_REFUSED(&p, fsdem_dem_set_particle_state(NULL, 0, v, v, v));
        mark_point();
        pp = fsdem_dem_get_particles(NULL);
        IF_ZERO(&p, "fsdem_dem_get_particles(NULL)", pp.count + pp.dim + (pp.position != NULL) + (pp.velocity != NULL));
        mark_point();
        cc = fsdem_dem_get_coupling(NULL);
        IF_ZERO(&p, "fsdem_dem_get_coupling(NULL)", cc.count + (cc.force != NULL) + (cc.torque != NULL));
        IF_REFUSED(&p, fsdem_dem_add_wall(NULL, &w, &idx));
        IF_REFUSED(&p, fsdem_dem_remove_wall(NULL, 0));
        IF_REFUSED(&p, fsdem_dem_set_wall_velocity(NULL, 0, v));
        IF_REFUSED(&p, fsdem_dem_wall_moved(NULL, 0, 0.1));
        mark_point();
        f = fsdem_dem_wall_force(NULL, 0);
        IF_ZERO(&p, "fsdem_dem_wall_force(NULL, 0)", fabs(f.x) + fabs(f.y) + fabs(f.z));
        mark_point();
        f = fsdem_dem_wall_impulse(NULL, 0);
        IF_ZERO(&p, "fsdem_dem_wall_impulse(NULL, 0)", fabs(f.x) + fabs(f.y) + fabs(f.z));
        IF_REFUSED(&p, fsdem_dem_step(NULL));
        IF_REFUSED(&p, fsdem_dem_step_dt(NULL, 1e-3));
        IF_REFUSED(&p, fsdem_dem_advance(NULL, 1e-3, &steps));
        IF_REFUSED(&p, fsdem_dem_substep_count(NULL, 1e-3, &steps));
        IF_REFUSED(&p, fsdem_dem_advance_with(NULL, 1e-3, if_callback, NULL, &steps));
        IF_REFUSED(&p, fsdem_dem_set_dt(NULL, 1e-3));
        IF_ZERO(&p, "fsdem_dem_time(NULL)", fsdem_dem_time(NULL));
        IF_REFUSED(&p, fsdem_dem_stable_dt(NULL, &dt));
        mark_point();
        dd = fsdem_dem_get_desc(NULL);
        IF_ZERO(&p, "fsdem_dem_get_desc(NULL)", dd.dim + fabs(dd.dt) + (dd.allocator.alloc != NULL));
        mark_point();
        en = fsdem_dem_get_energy(NULL);
        IF_TRUE(&p, "fsdem_dem_get_energy(NULL)", if_zero_bytes(&en, sizeof en));
        mark_point();
        st = fsdem_dem_get_stats(NULL);
        IF_ZERO(&p, "fsdem_dem_get_stats(NULL)", st.steps + st.time + st.dt + st.contacts + (double)st.memory_bytes);
        IF_TRUE(&p, "fsdem_dem_contacts(NULL, NULL, 0)", fsdem_dem_contacts(NULL, NULL, 0) == FSDEM_ERR_INVALID_ARG);
        IF_REFUSED(&p, fsdem_dem_write_csv(NULL, "build/never_null.csv"));
        IF_REFUSED(&p, fsdem_dem_write_vtp(NULL, "build/never_null.vtp", FSDEM_VTK_FORMAT_ASCII));
        IF_REFUSED(&p, fsdem_dem_write_walls_vtp(NULL, "build/never_null.vtp", FSDEM_VTK_FORMAT_ASCII));
        IF_REFUSED(&p, fsdem_dem_write_contacts_vtp(NULL, "build/never_null.vtp", FSDEM_VTK_FORMAT_ASCII));
        IF_REFUSED(&p, fsdem_dem_save(NULL, "build/never_null.rst"));
        IF_REFUSED(&p, fsdem_dem_restore(NULL, "build/never_null.rst"));
        IF_REFUSED(&p, fsdem_dem_save_memory(NULL, NULL, 0, NULL));
        IF_REFUSED(&p, fsdem_dem_restore_memory(NULL, NULL, 0));
    }
    /* ---- fsdem_pcg ---- */
    {
        fsdem_pcg_desc d = fsdem_pcg_desc_default();
        fsdem_pcg *pcg = (fsdem_pcg *)&p;
        fsdem_stencil st;
        fsdem_csr m;
        fsdem_pcg_info info;
        memset(&st, 0, sizeof st);
        memset(&m, 0, sizeof m);
        st.dim = 2, st.n[0] = st.n[1] = 2;
        IF_REFUSED(&p, fsdem_pcg_desc_check(NULL, msg, sizeof msg));
        IF_REFUSED(&p, fsdem_pcg_create(NULL, &pcg));
        IF_TRUE(&p, "fsdem_pcg_create(NULL, &pcg) sets pcg to NULL", pcg == NULL);
        IF_REFUSED(&p, fsdem_pcg_create(&d, NULL));
        mark_point();
        fsdem_pcg_destroy(NULL);
        mark_point();
        text = fsdem_pcg_last_error(NULL);
        IF_TRUE(&p, "fsdem_pcg_last_error(NULL)", text && strstr(text, "fsdem_pcg") && strstr(text, "NULL"));
        IF_REFUSED(&p, fsdem_pcg_set_tolerance(NULL, 1e-5, 10));
        IF_REFUSED(&p, fsdem_pcg_setup_stencil(NULL, &st));
        IF_REFUSED(&p, fsdem_pcg_setup_csr(NULL, &m));
        IF_REFUSED(&p, fsdem_pcg_solve(NULL, r, r + 4, &info));
        IF_REFUSED(&p, fsdem_stencil_check(NULL, msg, sizeof msg));
        IF_REFUSED(&p, fsdem_csr_check(NULL, msg, sizeof msg));
    }
    /* ---- fsdem_pic ---- */
    {
        fsdem_pic_desc d = fsdem_pic_desc_default(2);
        fsdem_pic *pic = (fsdem_pic *)&p;
        fsdem_pic_obstacle ob = fsdem_pic_obstacle_box(v, fsdem_v3(0.1, 0.1, 0.1));
        fsdem_pic_particles pp;
        fsdem_pic_desc dd;
        fsdem_pic_fields g;
        fsdem_pic_coupling cp;
        fsdem_pic_stats st;
        fsdem_fluid_sample out;
        IF_REFUSED(&p, fsdem_pic_desc_check(NULL, msg, sizeof msg));
        IF_REFUSED(&p, fsdem_pic_create(NULL, &pic));
        IF_TRUE(&p, "fsdem_pic_create(NULL, &pic) sets pic to NULL", pic == NULL);
        IF_REFUSED(&p, fsdem_pic_create(&d, NULL));
        mark_point();
        fsdem_pic_destroy(NULL);
        mark_point();
        text = fsdem_pic_last_error(NULL);
        IF_TRUE(&p, "fsdem_pic_last_error(NULL)", text && strstr(text, "fsdem_pic") && strstr(text, "NULL"));
        IF_REFUSED(&p, fsdem_pic_add_obstacle(NULL, &ob, &idx));
        IF_ZERO(&p, "fsdem_pic_solid_distance(NULL, ...)", fsdem_pic_solid_distance(NULL, v, &v));
        IF_REFUSED(&p, fsdem_pic_fill_box(NULL, v, fsdem_v3(1, 1, 1), v, &idx));
        IF_REFUSED(&p, fsdem_pic_fill_sdf(NULL, if_plane, NULL, v, &idx));
        IF_REFUSED(&p, fsdem_pic_add_particles(NULL, &v, NULL, 1));
        IF_REFUSED(&p, fsdem_pic_reserve(NULL, 10));
        mark_point();
        pp = fsdem_pic_get_particles(NULL);
        IF_ZERO(&p, "fsdem_pic_get_particles(NULL)", pp.count + pp.dim + (pp.position != NULL) + (pp.velocity != NULL));
        IF_REFUSED(&p, fsdem_pic_step(NULL));
        IF_REFUSED(&p, fsdem_pic_step_dt(NULL, 1e-3));
        IF_REFUSED(&p, fsdem_pic_advance(NULL, 1e-3, &steps));
        IF_REFUSED(&p, fsdem_pic_stable_dt(NULL, &dt));
        IF_ZERO(&p, "fsdem_pic_time(NULL)", fsdem_pic_time(NULL));
        mark_point();
        dd = fsdem_pic_get_desc(NULL);
        IF_ZERO(&p, "fsdem_pic_get_desc(NULL)", dd.dim + fabs(dd.cell_size));
        mark_point();
        g = fsdem_pic_get_fields(NULL);
        IF_ZERO(&p, "fsdem_pic_get_fields(NULL)", g.dim + g.n[0] + (g.cell != NULL) + (g.velocity[0] != NULL));
        mark_point();
        cp = fsdem_pic_get_coupling(NULL);
        IF_ZERO(&p, "fsdem_pic_get_coupling(NULL)", cp.dim + cp.n[0] + (cp.acceleration[0] != NULL));
        IF_REFUSED(&p, fsdem_pic_set_pressure_extra(NULL, NULL, NULL, NULL));
        IF_REFUSED(&p, fsdem_pic_sample(NULL, 1, &v, &out));
        IF_REFUSED(&p, fsdem_pic_add_force(NULL, v, 0, v, &taken));
        IF_REFUSED(&p, fsdem_pic_clear_forces(NULL));
        IF_REFUSED(&p, fsdem_pic_add_gauge(NULL, FSDEM_PIC_GAUGE_KIND_PRESSURE, v, 0, &idx));
        IF_REFUSED(&p, fsdem_pic_gauge(NULL, 0, &dt));
        IF_REFUSED(&p, fsdem_pic_gauges_open(NULL, "build/never_null.csv", 0));
        IF_REFUSED(&p, fsdem_pic_gauges_close(NULL));
        mark_point();
        st = fsdem_pic_get_stats(NULL);
        IF_ZERO(&p, "fsdem_pic_get_stats(NULL)", st.steps + st.time + st.particles + st.fluid_cells + (double)st.memory_bytes);
        IF_REFUSED(&p, fsdem_pic_write_particles_csv(NULL, "build/never_null.csv"));
        IF_REFUSED(&p, fsdem_pic_write_particles_vtp(NULL, "build/never_null.vtp", FSDEM_VTK_FORMAT_ASCII));
        IF_REFUSED(&p, fsdem_pic_write_grid_csv(NULL, "build/never_null.csv"));
        IF_REFUSED(&p, fsdem_pic_write_grid_vti(NULL, "build/never_null.vti", FSDEM_VTK_FORMAT_ASCII));
        IF_REFUSED(&p, fsdem_pic_add_gauge(NULL, FSDEM_PIC_GAUGE_KIND_LEVEL, fsdem_v3(0, 0, 0), 0, NULL));
        IF_REFUSED(&p, fsdem_pic_gauges_open(NULL, "build/never_null.csv", 0));
        IF_REFUSED(&p, fsdem_pic_gauges_close(NULL));
        IF_REFUSED(&p, fsdem_pic_exclude_particles(NULL, if_plane, NULL, 0, &idx));
        IF_REFUSED(&p, fsdem_pic_save(NULL, "build/never_null.rst"));
        IF_REFUSED(&p, fsdem_pic_restore(NULL, "build/never_null.rst"));
        IF_REFUSED(&p, fsdem_pic_save_memory(NULL, NULL, 0, NULL));
        IF_REFUSED(&p, fsdem_pic_restore_memory(NULL, NULL, 0));
    }
    /* ---- fsdem_swe ---- */
    {
        fsdem_swe_desc d = fsdem_swe_desc_default(1);
        fsdem_swe *swe = (fsdem_swe *)&p;
        fsdem_swe_boundary bc;
        fsdem_swe_point_source src;
        fsdem_swe_cell cell;
        fsdem_swe_grid gr;
        fsdem_swe_fields fl;
        fsdem_swe_coupling cp;
        fsdem_swe_desc dd;
        fsdem_swe_stats st;
        fsdem_fluid_sample out;
        fsdem_vec3 mom;
        unsigned char blocked[8] = {0};
        memset(&bc, 0, sizeof bc);
        memset(&src, 0, sizeof src);
        IF_REFUSED(&p, fsdem_swe_desc_check(NULL, msg, sizeof msg));
        IF_REFUSED(&p, fsdem_swe_create(NULL, &swe));
        IF_TRUE(&p, "fsdem_swe_create(NULL, &swe) sets swe to NULL", swe == NULL);
        IF_REFUSED(&p, fsdem_swe_create(&d, NULL));
        mark_point();
        fsdem_swe_destroy(NULL);
        mark_point();
        text = fsdem_swe_last_error(NULL);
        IF_TRUE(&p, "fsdem_swe_last_error(NULL)", text && strstr(text, "fsdem_swe") && strstr(text, "NULL"));
        mark_point();
        gr = fsdem_swe_get_grid(NULL);
        IF_ZERO(&p, "fsdem_swe_get_grid(NULL)", gr.dim + gr.nx + gr.ny + fabs(gr.dx) + fabs(gr.cell_area));
        IF_REFUSED(&p, fsdem_swe_set_bed(NULL, r));
        IF_REFUSED(&p, fsdem_swe_set_depth(NULL, r));
        IF_REFUSED(&p, fsdem_swe_set_surface(NULL, r));
        IF_REFUSED(&p, fsdem_swe_set_velocity(NULL, r, r));
        IF_REFUSED(&p, fsdem_swe_set_cells(NULL, if_cells, NULL));
        mark_point();
        fl = fsdem_swe_get_fields(NULL);
        IF_ZERO(&p, "fsdem_swe_get_fields(NULL)", fl.nx + fl.ny + (fl.eta != NULL) + (fl.bed != NULL));
        mark_point();
        cp = fsdem_swe_get_coupling(NULL);
        IF_ZERO(&p, "fsdem_swe_get_coupling(NULL)", cp.nx + cp.ny + (cp.source_x != NULL));
        IF_REFUSED(&p, fsdem_swe_copy_field(NULL, FSDEM_SWE_FIELD_DEPTH, r));
        IF_TRUE(&p, "fsdem_swe_cell_at(NULL, ...) == -1", fsdem_swe_cell_at(NULL, 0.5, 0) == -1);
        IF_REFUSED(&p, fsdem_swe_sample_state(NULL, 0.5, 0, &cell));
        IF_REFUSED(&p, fsdem_swe_sample(NULL, 1, &v, &out));
        IF_REFUSED(&p, fsdem_swe_add_force(NULL, v, 0, v, &taken));
        IF_REFUSED(&p, fsdem_swe_clear_forces(NULL));
        IF_REFUSED(&p, fsdem_swe_set_boundary(NULL, FSDEM_SIDE_XMIN, &bc));
        IF_REFUSED(&p, fsdem_swe_set_manning(NULL, NULL));
        IF_REFUSED(&p, fsdem_swe_set_rain(NULL, 0));
        IF_REFUSED(&p, fsdem_swe_set_blocked(NULL, blocked));
        IF_REFUSED(&p, fsdem_swe_block_box(NULL, 0, 0, 1, 1));
        IF_REFUSED(&p, fsdem_swe_block_polygon(NULL, tri, 3));
        IF_REFUSED(&p, fsdem_swe_add_point_source(NULL, &src, &idx));
        IF_REFUSED(&p, fsdem_swe_remove_point_source(NULL, 0));
        IF_REFUSED(&p, fsdem_swe_stable_dt(NULL, &dt));
        IF_REFUSED(&p, fsdem_swe_step(NULL));
        IF_REFUSED(&p, fsdem_swe_step_dt(NULL, 1e-3));
        IF_REFUSED(&p, fsdem_swe_advance(NULL, 1e-3, &steps));
        IF_ZERO(&p, "fsdem_swe_time(NULL)", fsdem_swe_time(NULL));
        mark_point();
        dd = fsdem_swe_get_desc(NULL);
        IF_ZERO(&p, "fsdem_swe_get_desc(NULL)", dd.dim + dd.nx + fabs(dd.cfl));
        IF_ZERO(&p, "fsdem_swe_volume(NULL)", fsdem_swe_volume(NULL));
        mark_point();
        mom = fsdem_swe_momentum(NULL);
        IF_ZERO(&p, "fsdem_swe_momentum(NULL)", fabs(mom.x) + fabs(mom.y) + fabs(mom.z));
        mark_point();
        st = fsdem_swe_get_stats(NULL);
        IF_ZERO(&p, "fsdem_swe_get_stats(NULL)", st.steps + st.time + st.wet_cells + (double)st.memory_bytes);
        IF_REFUSED(&p, fsdem_swe_write_csv(NULL, "build/never_null.csv"));
        IF_REFUSED(&p, fsdem_swe_write_vti(NULL, "build/never_null.vti", FSDEM_VTK_FORMAT_ASCII));
        IF_REFUSED(&p, fsdem_swe_set_blocked(NULL, NULL));
        IF_REFUSED(&p, fsdem_swe_block_box(NULL, 0, 0, 1, 1));
        IF_REFUSED(&p, fsdem_swe_block_polygon(NULL, NULL, 0));
        IF_REFUSED(&p, fsdem_swe_save(NULL, "build/never_null.rst"));
        IF_REFUSED(&p, fsdem_swe_restore(NULL, "build/never_null.rst"));
        IF_REFUSED(&p, fsdem_swe_save_memory(NULL, NULL, 0, NULL));
        IF_REFUSED(&p, fsdem_swe_restore_memory(NULL, NULL, 0));
        IF_REFUSED(&p, fsdem_swe_add_gauge(NULL, 0.5, 0, &idx));
        IF_REFUSED(&p, fsdem_swe_gauge(NULL, 0, &cell));
        IF_REFUSED(&p, fsdem_swe_gauges_open(NULL, "build/never_null.csv", 0));
        IF_REFUSED(&p, fsdem_swe_gauges_close(NULL));
        /* the bed callback of a DEM wall with no solver: no crash, a finite distance */
        IF_TRUE(&p, "fsdem_swe_bed_sdf(NULL, ...) is finite", isfinite(fsdem_swe_bed_sdf(NULL, v, &mom)));
    }
    /* ---- fsdem_mps ---- */
    {
        fsdem_mps_desc d = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
        fsdem_mps *mps = (fsdem_mps *)&p;
        fsdem_mps_particles pp;
        fsdem_mps_coupling cp;
        fsdem_mps_desc dd;
        fsdem_mps_stats st;
        fsdem_csr a;
        const int *rows = (const int *)&p;
        IF_REFUSED(&p, fsdem_mps_desc_check(NULL, msg, sizeof msg));
        IF_REFUSED(&p, fsdem_mps_create(NULL, &mps));
        IF_TRUE(&p, "fsdem_mps_create(NULL, &mps) sets mps to NULL", mps == NULL);
        IF_REFUSED(&p, fsdem_mps_create(&d, NULL));
        mark_point();
        fsdem_mps_destroy(NULL);
        mark_point();
        text = fsdem_mps_last_error(NULL);
        IF_TRUE(&p, "fsdem_mps_last_error(NULL)", text && strstr(text, "fsdem_mps") && strstr(text, "NULL"));
        mark_point();
        dd = fsdem_mps_get_desc(NULL);
        IF_ZERO(&p, "fsdem_mps_get_desc(NULL)", dd.dim + fabs(dd.r0) + (dd.allocator.alloc != NULL));
        IF_REFUSED(&p, fsdem_mps_add_particles(NULL, FSDEM_MPS_KIND_FLUID, 1, &v, NULL));
        IF_REFUSED(&p, fsdem_mps_fill_box(NULL, v, fsdem_v3(1, 1, 0), v, &idx));
        IF_REFUSED(&p, fsdem_mps_add_box_walls(NULL, v, fsdem_v3(1, 1, 0), 0, &idx));
        IF_REFUSED(&p, fsdem_mps_add_box_obstacle(NULL, v, fsdem_v3(1, 1, 0), &idx));
        mark_point();
        pp = fsdem_mps_get_particles(NULL);
        IF_ZERO(&p, "fsdem_mps_get_particles(NULL)", pp.count + pp.dim + (pp.position != NULL) + (pp.velocity != NULL));
        mark_point();
        cp = fsdem_mps_get_coupling(NULL);
        IF_ZERO(&p, "fsdem_mps_get_coupling(NULL)", cp.count + (cp.force != NULL) + (cp.porosity != NULL));
        IF_REFUSED(&p, fsdem_mps_gradient(NULL, r, &v));
        IF_REFUSED(&p, fsdem_mps_divergence(NULL, &v, r));
        IF_REFUSED(&p, fsdem_mps_laplacian(NULL, r, r));
        mark_point();
        a = fsdem_mps_pressure_matrix(NULL, &rows);
        IF_ZERO(&p, "fsdem_mps_pressure_matrix(NULL, &rows)", a.rows + (a.row_start != NULL) + (a.col != NULL) + (rows != NULL));
        IF_REFUSED(&p, fsdem_mps_stable_dt(NULL, &dt));
        IF_REFUSED(&p, fsdem_mps_step(NULL));
        IF_REFUSED(&p, fsdem_mps_step_dt(NULL, 1e-3));
        IF_REFUSED(&p, fsdem_mps_advance(NULL, 1e-3, &steps));
        IF_ZERO(&p, "fsdem_mps_time(NULL)", fsdem_mps_time(NULL));
        mark_point();
        st = fsdem_mps_get_stats(NULL);
        IF_ZERO(&p, "fsdem_mps_get_stats(NULL)", st.steps + st.time + st.dt);
        IF_REFUSED(&p, fsdem_mps_probe_pressure(NULL, v, 0.1, &dt));
        IF_REFUSED(&p, fsdem_mps_probe_height(NULL, v, &dt));
        IF_REFUSED(&p, fsdem_mps_add_gauge(NULL, FSDEM_MPS_GAUGE_KIND_LEVEL, v, 0, &idx));
        IF_REFUSED(&p, fsdem_mps_gauge(NULL, 0, &dt));
        IF_REFUSED(&p, fsdem_mps_gauges_open(NULL, "build/never_null.csv", 0));
        IF_REFUSED(&p, fsdem_mps_gauges_close(NULL));
        IF_REFUSED(&p, fsdem_mps_obstacle_force(NULL, 0, &v));
        IF_REFUSED(&p, fsdem_mps_write_vtp(NULL, "build/never_null.vtp", FSDEM_VTK_FORMAT_ASCII));
        IF_REFUSED(&p, fsdem_mps_write_csv(NULL, "build/never_null.csv"));
        IF_REFUSED(&p, fsdem_mps_save(NULL, "build/never_null.rst"));
        IF_REFUSED(&p, fsdem_mps_restore(NULL, "build/never_null.rst"));
        IF_REFUSED(&p, fsdem_mps_save_memory(NULL, NULL, 0, NULL));
        IF_REFUSED(&p, fsdem_mps_restore_memory(NULL, NULL, 0));
    }
    /* ---- the couplers: the verbs they share, then their own ---- */
    IF_COUPLER_DIALECT(&p, swe_dem, swe);
    IF_REFUSED(&p, fsdem_swe_dem_update(NULL));
    IF_COUPLER_DIALECT(&p, mps_dem, mps);
    IF_REFUSED(&p, fsdem_mps_dem_update(NULL));
    IF_COUPLER_DIALECT(&p, pic_dem, pic);
    IF_REFUSED(&p, fsdem_pic_dem_update(NULL));
    IF_TRUE(&p, "the couplers' fsdem_X_coupler(NULL) are NULL",
            !fsdem_swe_dem_coupler(NULL) && !fsdem_mps_dem_coupler(NULL) && !fsdem_pic_dem_coupler(NULL) && !fsdem_gic_coupler(NULL));
    IF_REFUSED(&p, fsdem_coupled_step(NULL, 1));
    TEST_REPORT("%d calls with a NULL object, %d answered wrong", p.calls, p.count);
    ck_assert_msg(p.count == 0, "%d of %d calls with a NULL object answered wrong: %s", p.count, p.calls, p.failed);
}
END_TEST

Suite *interface_suite(void) {
    Suite *s = suite_create("interface");
    TCase *pic = tcase_create("interface_pic"), *swe = tcase_create("interface_swe");
    TCase *dem = tcase_create("interface_dem"), *null = tcase_create("interface_null");
    tcase_set_timeout(pic, 120); /* generous for valgrind */
    tcase_add_test(pic, pic_sample_still_water);
    tcase_add_test(pic, pic_add_force_is_exact);
    tcase_add_test(swe, swe_sample_sloping_lake);
    tcase_add_test(swe, swe_add_force_footprint);
    tcase_add_test(dem, dem_advance_with_callback);
    tcase_add_test(null, null_objects_are_refused);
    suite_add_tcase(s, pic);
    suite_add_tcase(s, swe);
    suite_add_tcase(s, dem);
    suite_add_tcase(s, null);
    return s;
}
