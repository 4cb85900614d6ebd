/* DEM contact options (issue 23 §2), each against a hand calculation of a two-sphere contact:
   tangential damping on and off, Coulomb's limit on the spring plus dashpot or the spring alone,
   the tangential spring's history incremental or total, material-pair tables with their mixing
   rule, simplified-JKR cohesion, and seed 002's linear stiffness (Eq. 19-24).

   The probe: sphere j fixed at the origin, sphere i free, no gravity, no spin (desc.rotation = 0).
   i starts just apart from j, so the first force evaluation of a Verlet step finds no contact and
   the half kick leaves v = v0 exactly; after the drift x1 = x0 + h v0 the spheres overlap by delta
   and the step's contact force is the law at (x1, v0) with a zero spring (first touch) plus
   v0_t h. The reduced mass is m_i (j is fixed) and R* = R/2. Forces are compared relative to the
   largest term, at rounding (1e-10: a few hundred roundings of the geometry; in float 1e5 eps:
   the overlap of 5e-7 m, a difference of positions of 0.02 m, is known to 1e-9 m, 2e-3 of it). */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "fsdem_tests.h"

#define PI 3.14159265358979323846
#define R 0.01      /* m, both spheres */
#define H 1e-5      /* s, the step */
#define DELTA 5e-7  /* m, overlap after the step: less than H |v_n|, so the spheres start apart */
#define VN 0.1      /* m/s, approach speed */
#define VT 0.05     /* m/s, tangential speed along +y */
#define YOUNG 1e7   /* Pa */
#define NU 0.3

typedef struct probe {
    fsdem_dem *dem;
    int mat[2];
    double m_i; /* kg */
} probe;

/* A DEM with the options of `d` (gravity and spin off) and materials a, b (b may be NULL). */
static probe probe_new(fsdem_dem_desc d, const fsdem_dem_material *a, const fsdem_dem_material *b) {
    probe p;
    d.gravity = fsdem_v3(0, 0, 0);
    d.rotation = 0;
    d.dt = (fsdem_real)H;
    d.domain_min = fsdem_v3(-1, -1, -1);
    d.domain_max = fsdem_v3(1, 1, 1);
    ck_assert_int_eq(fsdem_dem_create(&d, &p.dem), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(p.dem, a, &p.mat[0]), FSDEM_OK);
    p.mat[1] = p.mat[0];
    if (b) ck_assert_int_eq(fsdem_dem_add_material(p.dem, b, &p.mat[1]), FSDEM_OK);
    p.m_i = a->density * (d.dim == 3 ? 4.0 / 3.0 * PI * R * R * R : PI * R * R * d.disc_length);
    return p;
}

/* j (material mat[1]) fixed at the origin; i (material mat[0]) placed so that one step of v0 =
   (-VN, VT, 0) ends with the centres DISTANCE apart along x: the contact normal is +x. */
static void probe_place(probe *p, double distance) {
    fsdem_dem_particle_desc q = fsdem_dem_particle_desc_default();
    q.radius = (fsdem_real)R;
    q.material = p->mat[1];
    q.fixed = 1;
    ck_assert_int_eq(fsdem_dem_add_particle(p->dem, &q, NULL), FSDEM_OK);
    q.material = p->mat[0];
    q.fixed = 0;
    q.position = fsdem_v3((fsdem_real)(distance + H * VN), (fsdem_real)(-H * VT), 0);
    q.velocity = fsdem_v3((fsdem_real)-VN, (fsdem_real)VT, 0);
    ck_assert_int_eq(fsdem_dem_add_particle(p->dem, &q, NULL), FSDEM_OK);
}

/* The contact force on i after one step from probe_place(2R - DELTA). */
static fsdem_vec3 probe_force(probe *p) {
    probe_place(p, 2 * R - DELTA);
    ck_assert_int_eq(fsdem_dem_step(p->dem), FSDEM_OK);
    return fsdem_dem_get_particles(p->dem).force[1];
}

static fsdem_dem_material material(double density, double restitution, double friction) {
    fsdem_dem_material m = fsdem_dem_material_default();
    m.density = (fsdem_real)density;
    m.young_modulus = (fsdem_real)YOUNG;
    m.poisson_ratio = (fsdem_real)NU;
    m.restitution = (fsdem_real)restitution;
    m.friction = (fsdem_real)friction;
    return m;
}

static void close_to(double value, double expected, double scale, const char *what) {
    ck_assert_msg(fabs(value - expected) <= TOL(1e-10, 1e5) * scale, "%s: %.15g, expected %.15g", what, value, expected);
}

/* Hertz between two equal spheres of one material: E* = E / (2 (1 - nu^2)), G* = E / (4 (2 - nu)
   (1 + nu)); elastic normal force (4/3) E* sqrt(R*) delta^1.5, tangential stiffness 8 G* sqrt(R* delta). */
static double hertz_elastic(void) { return 4.0 / 3.0 * YOUNG / (2 * (1 - NU * NU)) * sqrt(R / 2) * pow(DELTA, 1.5); }
static double hertz_tangential_stiffness(void) { return 8 * YOUNG / (4 * (2 - NU) * (1 + NU)) * sqrt(R / 2 * DELTA); }

/* ---- tangential damping ------------------------------------------------------------------------- */

/* Hertz-Mindlin, no slip (mu = 10): F_t = -S_t VT H - eta_t VT with the dashpot on, -S_t VT H
   without; eta_t = ct eta_n, ct = sqrt(4 G* / E*) = sqrt(2 (1 - nu)/(2 - nu)) (one material), and
   eta_n is read off the normal force: F_n = F_el + eta_n VN (approaching), the same in both runs. */
START_TEST(hertz_tangential_damping_on_and_off) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    const fsdem_dem_material m = material(2500, 0.5, 10);
    const double st = hertz_tangential_stiffness(), ct = sqrt(2 * (1 - NU) / (2 - NU));
    probe on, off;
    fsdem_vec3 f_on, f_off;
    double eta_n;
    on = probe_new(d, &m, NULL);
    d.tangential_damping = 0;
    off = probe_new(d, &m, NULL);
    f_on = probe_force(&on);
    f_off = probe_force(&off);
    eta_n = ((double)f_on.x - hertz_elastic()) / VN;
    ck_assert(eta_n > 0);
    close_to(f_off.x, f_on.x, f_on.x, "the normal force does not change");
    close_to(f_off.y, -st * VT * H, st * VT * H, "spring alone");
    close_to(f_on.y, -st * VT * H - ct * eta_n * VT, ct * eta_n * VT, "spring and dashpot");
    TEST_REPORT("F_n %.6g N, spring %.6g N, dashpot %.6g N", f_on.x, -st * VT * H, -ct * eta_n * VT);
    fsdem_dem_destroy(on.dem);
    fsdem_dem_destroy(off.dem);
}
END_TEST

/* Seed 000's linear law (Eq. 10-13), theta = 0.01, dx = 1 mm, ||g|| = 9.81: k_n = 9.81 / 1e-5 =
   9.81e5 s^-2 per unit of the mean mass m_ij = (m_i + m_j)/2, c_n = 2 alpha sqrt(k_n), k_t = k_n /
   (2 (1 + psi)), c_t = c_n / sqrt(2 (1 + psi)); the one-step spring F_t = -m_ij (k_t H + c_t) v_t
   (Eq. 8, 12-13); without the dashpot -m_ij k_t H v_t. F_n = m_ij (k_n delta + c_n VN). */
START_TEST(linear_tangential_damping_on_and_off) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    const fsdem_dem_material m = material(2500, 0.5, 10);
    const double alpha = 0.4, kn = 9.81 / (0.01 * 1e-3), cn = 2 * alpha * sqrt(kn), kt = kn / (2 * (1 + NU));
    const double ct = cn / sqrt(2 * (1 + NU)), m_mean = 2500 * 4.0 / 3.0 * PI * R * R * R;
    probe on, off;
    fsdem_vec3 f_on, f_off;
    d.law = FSDEM_DEM_LAW_LINEAR;
    d.linear_dx = (fsdem_real)1e-3;
    d.linear_accel = (fsdem_real)9.81;
    on = probe_new(d, &m, NULL);
    d.tangential_damping = 0;
    off = probe_new(d, &m, NULL);
    f_on = probe_force(&on);
    f_off = probe_force(&off);
    close_to(f_on.x, m_mean * (kn * DELTA + cn * VN), f_on.x, "normal force, Eq. 7");
    close_to(f_off.x, f_on.x, f_on.x, "the normal force does not change");
    close_to(f_on.y, -m_mean * (kt * H + ct) * VT, m_mean * ct * VT, "Eq. 8 with the dashpot");
    close_to(f_off.y, -m_mean * kt * H * VT, m_mean * kt * H * VT, "Eq. 8 without it");
    fsdem_dem_destroy(on.dem);
    fsdem_dem_destroy(off.dem);
}
END_TEST

/* ---- Coulomb's limit ---------------------------------------------------------------------------- */

/* Hertz-Mindlin sliding (mu = 0.001; the spring force S_t VT H is about twice mu F_n): on the
   total, |F_t| = mu F_n; on the spring alone, |F_t| = mu F_n + eta_t VT, the dashpot riding on the
   capped spring. */
START_TEST(coulomb_limit_on_total_or_spring) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    const fsdem_dem_material m = material(2500, 0.5, 0.001);
    const double ct = sqrt(2 * (1 - NU) / (2 - NU));
    probe total, spring;
    fsdem_vec3 ft, fs;
    double eta_n;
    total = probe_new(d, &m, NULL);
    d.coulomb_limit = FSDEM_DEM_COULOMB_LIMIT_SPRING;
    spring = probe_new(d, &m, NULL);
    ft = probe_force(&total);
    fs = probe_force(&spring);
    ck_assert(hertz_tangential_stiffness() * VT * H > 0.001 * ft.x); /* the spring alone slides */
    eta_n = ((double)ft.x - hertz_elastic()) / VN;
    close_to(ft.y, -0.001 * ft.x, ft.x, "total capped");
    close_to(fs.x, ft.x, ft.x, "the normal force does not change");
    close_to(fs.y, -0.001 * fs.x - ct * eta_n * VT, fs.x, "spring capped, dashpot added");
    ck_assert(fabs(ft.z) < 1e-12 * ft.x && fabs(fs.z) < 1e-12 * fs.x);
    fsdem_dem_destroy(total.dem);
    fsdem_dem_destroy(spring.dem);
}
END_TEST

/* ---- tangential history ------------------------------------------------------------------------- */

/* A spring built by one step (S = VT H along +y, no slip), then i turned by 60 degrees about j at the
   same distance and brought to rest (density 1e12 kg/m^3: the force of the next step moves it by
   1e-20 m and 1e-15 m/s). The new normal (cos 60, sin 60, 0) takes a part sin 60 of the spring: the
   incremental spring is turned into the new tangent plane with its length kept, |F_t| = S_t S; the
   total one is projected, |F_t| = S_t S cos 60. Either way F_t lies in the tangent plane. */
static fsdem_vec3 turned_spring_force(fsdem_dem_tangential_history history, fsdem_vec3 *normal) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    const fsdem_dem_material m = material(1e12, 1, 10); /* e = 1: no dashpot */
    const double dist = 2 * R - DELTA, c = cos(PI / 3), s = sin(PI / 3);
    probe p;
    fsdem_vec3 f;
    d.tangential_history = history;
    p = probe_new(d, &m, NULL);
    probe_force(&p);
    ck_assert_int_eq(fsdem_dem_set_particle_state(p.dem, 1, fsdem_v3((fsdem_real)(dist * c), (fsdem_real)(dist * s), 0),
                                                  fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0)),
                     FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_step(p.dem), FSDEM_OK);
    f = fsdem_dem_get_particles(p.dem).force[1];
    *normal = fsdem_v3((fsdem_real)c, (fsdem_real)s, 0);
    fsdem_dem_destroy(p.dem);
    return f;
}

START_TEST(tangential_history_incremental_or_total) {
    /* the 1e-15 m/s of the step; in float the overlap's 2e-3 (close_to) */
    const double spring = hertz_tangential_stiffness() * VT * H, tol = TOL(1e-6, 1e5);
    fsdem_vec3 n, fi = turned_spring_force(FSDEM_DEM_TANGENTIAL_HISTORY_INCREMENTAL, &n);
    fsdem_vec3 ft = turned_spring_force(FSDEM_DEM_TANGENTIAL_HISTORY_TOTAL, &n);
    const double fni = fi.x * n.x + fi.y * n.y, fnt = ft.x * n.x + ft.y * n.y;
    const double ti = hypot(fi.x - fni * n.x, fi.y - fni * n.y), tt = hypot(ft.x - fnt * n.x, ft.y - fnt * n.y);
    ck_assert_msg(fabs(ti / spring - 1) < tol, "incremental: |F_t| = %.10g, S_t S = %.10g", ti, spring);
    ck_assert_msg(fabs(tt / (spring * cos(PI / 3)) - 1) < tol, "total: |F_t| = %.10g, S_t S cos 60 = %.10g", tt, spring / 2);
    close_to(fni, hertz_elastic(), hertz_elastic(), "the normal force is Hertz's");
    close_to(fnt, hertz_elastic(), hertz_elastic(), "the normal force is Hertz's");
    ck_assert(fabs(fi.z) < 1e-12 * spring && fabs(ft.z) < 1e-12 * spring);
}
END_TEST

/* ---- material-pair tables ----------------------------------------------------------------------- */

/* Relative speed after a head-on collision of two equal free Hertz spheres of materials a and b,
   over the speed before (1 m/s), the contact resolved in about 500 steps. */
static double head_on_restitution(fsdem_dem *dem, int a, int b) {
    fsdem_dem_particle_desc q = fsdem_dem_particle_desc_default();
    fsdem_dem_particles v;
    int k;
    q.radius = (fsdem_real)R;
    q.material = a;
    q.position = fsdem_v3((fsdem_real)(-R - 1e-4), 0, 0);
    q.velocity = fsdem_v3((fsdem_real)0.5, 0, 0);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &q, NULL), FSDEM_OK);
    q.material = b;
    q.position = fsdem_v3((fsdem_real)(R + 1e-4), 0, 0);
    q.velocity = fsdem_v3((fsdem_real)-0.5, 0, 0);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &q, NULL), FSDEM_OK);
    for (k = 0; k < 20000; ++k) ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK);
    v = fsdem_dem_get_particles(dem);
    ck_assert(v.position[1].x - v.position[0].x > 2 * R); /* apart again */
    return (v.velocity[1].x - v.velocity[0].x) / 1.0;
}

/* Unset pairs take the arithmetic means (LIGGGHTS wants the full peratomtypepair matrices; we mix
   what was given per material); a set pair replaces them for that pair alone, both orders: a
   sliding contact of A on B takes B-A's friction, A on A its own; a head-on A-B collision takes
   the pair's restitution (Hertz damping calibrated exactly; 500 steps per contact: 2e-3). */
START_TEST(material_pairs_mix_and_override) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    const fsdem_dem_material a = material(2500, 0.5, 0.2), b = material(2500, 0.9, 0.6);
    fsdem_dem_material_pair v;
    probe p, same;
    fsdem_vec3 f;
    fsdem_real dt;
    double e;
    p = probe_new(d, &a, &b);
    v = fsdem_dem_get_material_pair(p.dem, p.mat[0], p.mat[1]);
    ck_assert(fabs(v.friction - 0.4) < TOL(1e-15, 4) && fabs(v.restitution - 0.7) < TOL(1e-15, 4) && v.cohesion == 0);
    v.friction = (fsdem_real)0.05;
    ck_assert_int_eq(fsdem_dem_set_material_pair(p.dem, p.mat[1], p.mat[0], &v), FSDEM_OK);
    ck_assert(fsdem_dem_get_material_pair(p.dem, p.mat[0], p.mat[1]).friction == v.friction);
    f = probe_force(&p);
    close_to(f.y, -0.05 * f.x, f.x, "the pair's friction");
    same = probe_new(d, &a, NULL);
    f = probe_force(&same);
    close_to(f.y, -0.2 * f.x, f.x, "A on A keeps its own");
    /* refused values change nothing */
    v.restitution = 2;
    ck_assert_int_eq(fsdem_dem_set_material_pair(p.dem, p.mat[0], p.mat[1], &v), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(fsdem_dem_last_error(p.dem), "restitution"));
    ck_assert_int_eq(fsdem_dem_set_material_pair(p.dem, 0, 7, &v), FSDEM_ERR_NOT_FOUND);
    ck_assert(fsdem_dem_get_material_pair(p.dem, p.mat[0], p.mat[1]).restitution == (fsdem_real)0.7);
    fsdem_dem_destroy(p.dem);
    fsdem_dem_destroy(same.dem);
    /* restitution of the pair */
    d.gravity = fsdem_v3(0, 0, 0);
    d.domain_min = fsdem_v3(-1, -1, -1);
    d.domain_max = fsdem_v3(1, 1, 1);
    d.rotation = 0;
    ck_assert_int_eq(fsdem_dem_create(&d, &p.dem), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(p.dem, &a, &p.mat[0]), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(p.dem, &b, &p.mat[1]), FSDEM_OK);
    v = fsdem_dem_get_material_pair(p.dem, p.mat[0], p.mat[1]);
    v.restitution = (fsdem_real)0.3;
    ck_assert_int_eq(fsdem_dem_set_material_pair(p.dem, p.mat[0], p.mat[1], &v), FSDEM_OK);
    {
        /* contact time of Hertz at 1 m/s between two free spheres (m* = m/2): 2.87 (m*^2 / (R* E*^2
           v))^(1/5), resolved in ~500 steps */
        const double ms = 2500 * 4.0 / 3.0 * PI * R * R * R / 2, es = YOUNG / (2 * (1 - NU * NU));
        dt = (fsdem_real)(2.87 * pow(ms * ms / (R / 2 * es * es * 1.0), 0.2) / 500);
        ck_assert_int_eq(fsdem_dem_set_dt(p.dem, dt), FSDEM_OK);
    }
    e = head_on_restitution(p.dem, p.mat[0], p.mat[1]);
    ck_assert_msg(fabs(e - 0.3) < 2e-3, "restitution %.6f, the pair's 0.3", e);
    fsdem_dem_destroy(p.dem);
}
END_TEST

/* ---- cohesion ----------------------------------------------------------------------------------- */

/* Two equal spheres at rest overlapping by DELTA (e = 1, no slip, density 1e12: the force of a step
   moves them by 1e-20 m): F_n = F_el - k pi a^2, a^2 = R^2 - (d/2)^2 the radius of the circle where
   they intersect, d = 2R - DELTA; on a plane wall a^2 = DELTA (2R - DELTA); in 2D the area is the
   chord 2a times the disc length (0.1 m). k = 1e5 J/m^3. */
static double resting_normal_force(int dim, int wall) {
    fsdem_dem_desc d = fsdem_dem_desc_default(dim);
    fsdem_dem_material m = material(1e12, 1, 10);
    fsdem_dem_particle_desc q = fsdem_dem_particle_desc_default();
    fsdem_dem *dem;
    double f;
    m.cohesion = (fsdem_real)1e5;
    d.gravity = fsdem_v3(0, 0, 0);
    d.disc_length = (fsdem_real)0.1;
    ck_assert_int_eq(fsdem_dem_create(&d, &dem), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_OK);
    q.radius = (fsdem_real)R;
    if (wall) {
        fsdem_dem_wall_desc w = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), 0);
        ck_assert_int_eq(fsdem_dem_add_wall(dem, &w, NULL), FSDEM_OK);
    } else {
        q.fixed = 1;
        ck_assert_int_eq(fsdem_dem_add_particle(dem, &q, NULL), FSDEM_OK);
        q.fixed = 0;
    }
    q.position = fsdem_v3((fsdem_real)((wall ? 1 : 2) * R - DELTA), 0, 0);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &q, NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK);
    f = fsdem_dem_get_particles(dem).force[wall ? 0 : 1].x;
    fsdem_dem_destroy(dem);
    return f;
}

START_TEST(cohesion_pulls_by_the_contact_area) {
    const double k = 1e5, dist = 2 * R - DELTA, a2 = R * R - dist * dist / 4, a2w = DELTA * (2 * R - DELTA);
    const double es = YOUNG / (2 * (1 - NU * NU)), el = hertz_elastic(), elw = 4.0 / 3.0 * es * sqrt(R) * pow(DELTA, 1.5);
    /* 2D Hertz in this library is the 3D formula per disc (R* of the discs): the same elastic part */
    close_to(resting_normal_force(3, 0), el - k * PI * a2, k * PI * a2, "3D pair");
    close_to(resting_normal_force(3, 1), elw - k * PI * a2w, k * PI * a2w, "3D wall");
    close_to(resting_normal_force(2, 0), el - k * 2 * sqrt(a2) * 0.1, k * 2 * sqrt(a2) * 0.1, "2D pair");
    TEST_REPORT("3D pair: elastic %.6g N, cohesion %.6g N", el, k * PI * a2);
}
END_TEST

/* ---- seed 002's linear stiffness ---------------------------------------------------------------- */

/* Eq. 21 as printed for two equal spheres, chi^n = (sqrt 2 / 3) E sqrt(R) / (1 - nu^2) (in SI:
   2.59e4 here); Eq. 22 chi^t = chi^n / (2 + nu); Eq. 23-24 eta = -2 ln(e) sqrt(chi m* / (ln^2 e +
   pi^2)) with m* = m_i (j fixed). F_n = chi^n DELTA + eta^n VN (Eq. 19); first touch, no slip:
   F_t = -(chi^t H + eta^t) VT (Eq. 20 with the spring VT H). */
START_TEST(seed002_linear_stiffness_is_eq_21_to_24) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    const fsdem_dem_material m = material(2500, 0.5, 10);
    const double chin = sqrt(2.0) / 3 * YOUNG * sqrt(R) / (1 - NU * NU), chit = chin / (2 + NU);
    const double ms = 2500 * 4.0 / 3.0 * PI * R * R * R, le = log(0.5);
    const double etan = -2 * le * sqrt(chin * ms / (le * le + PI * PI)), etat = -2 * le * sqrt(chit * ms / (le * le + PI * PI));
    probe p;
    fsdem_vec3 f;
    fsdem_real dt;
    d.law = FSDEM_DEM_LAW_LINEAR;
    d.linear_stiffness = FSDEM_DEM_LINEAR_STIFFNESS_SEED002;
    p = probe_new(d, &m, NULL);
    f = probe_force(&p);
    close_to(f.x, chin * DELTA + etan * VN, etan * VN, "Eq. 19 with Eq. 21, 23");
    close_to(f.y, -(chit * H + etat) * VT, etat * VT, "Eq. 20 with Eq. 22, 24");
    ck_assert_int_eq(fsdem_dem_stable_dt(p.dem, &dt), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_get_desc(p.dem).dt_rule, FSDEM_DEM_DT_RULE_RAYLEIGH);
    fsdem_dem_destroy(p.dem);
}
END_TEST

/* With the reduced mass in Eq. 23 the normal restitution of a head-on collision of two free equal
   spheres is e (the damped oscillator's exp(-zeta pi / sqrt(1 - zeta^2)) = e, the contact ending
   where the overlap does: no cut-off); 1000 steps over the contact: 2e-3. */
START_TEST(seed002_linear_restitution_is_e) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    const fsdem_dem_material m = material(2500, 0.6, 0.3);
    const double chin = sqrt(2.0) / 3 * YOUNG * sqrt(R) / (1 - NU * NU), ms = 2500 * 4.0 / 3.0 * PI * R * R * R / 2;
    fsdem_dem *dem;
    double e;
    d.law = FSDEM_DEM_LAW_LINEAR;
    d.linear_stiffness = FSDEM_DEM_LINEAR_STIFFNESS_SEED002;
    d.gravity = fsdem_v3(0, 0, 0);
    d.rotation = 0;
    d.dt = (fsdem_real)(PI * sqrt(ms / chin) / 1000); /* half a period of the undamped spring / 1000 */
    ck_assert_int_eq(fsdem_dem_create(&d, &dem), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_OK);
    e = head_on_restitution(dem, 0, 0);
    ck_assert_msg(fabs(e - 0.6) < 2e-3, "restitution %.6f, e = 0.6", e);
    fsdem_dem_destroy(dem);
}
END_TEST

START_TEST(contact_options_are_validated) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem *dem = NULL;
    char msg[256];
    d.tangential_damping = 2;
    ck_assert_int_eq(fsdem_dem_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(msg, "tangential_damping"));
    d = fsdem_dem_desc_default(3);
    d.tangential_history = (fsdem_dem_tangential_history)5;
    ck_assert_int_eq(fsdem_dem_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    d = fsdem_dem_desc_default(3);
    d.coulomb_limit = (fsdem_dem_coulomb_limit)-1;
    ck_assert_int_eq(fsdem_dem_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    d = fsdem_dem_desc_default(3);
    d.law = FSDEM_DEM_LAW_LINEAR;
    ck_assert_int_eq(fsdem_dem_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG); /* seed 000 needs dx */
    d.linear_stiffness = FSDEM_DEM_LINEAR_STIFFNESS_SEED002;
    ck_assert_int_eq(fsdem_dem_desc_check(&d, msg, sizeof msg), FSDEM_OK); /* seed 002 does not */
    d.dt_rule = FSDEM_DEM_DT_RULE_LINEAR_SEED000;
    ck_assert_int_eq(fsdem_dem_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    d = fsdem_dem_desc_default(3);
    ck_assert_int_eq(fsdem_dem_create(&d, &dem), FSDEM_OK);
    m.cohesion = -1;
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(fsdem_dem_last_error(dem), "cohesion"));
    fsdem_dem_destroy(dem);
}
END_TEST

Suite *dem_contact_suite(void) {
    Suite *s = suite_create("dem_contact");
    TCase *tc = tcase_create("dem_contact");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, hertz_tangential_damping_on_and_off);
    tcase_add_test(tc, linear_tangential_damping_on_and_off);
    tcase_add_test(tc, coulomb_limit_on_total_or_spring);
    tcase_add_test(tc, tangential_history_incremental_or_total);
    tcase_add_test(tc, material_pairs_mix_and_override);
    tcase_add_test(tc, cohesion_pulls_by_the_contact_area);
    tcase_add_test(tc, seed002_linear_stiffness_is_eq_21_to_24);
    tcase_add_test(tc, seed002_linear_restitution_is_e);
    tcase_add_test(tc, contact_options_are_validated);
    suite_add_tcase(s, tc);
    return s;
}
