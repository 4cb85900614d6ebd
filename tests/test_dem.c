/* DEM: neighbour search, conservation, contact laws (restitution, rolling, static overlap), contact
   history, subcycling, time-step estimates and input validation.

   Every test asserts physics that would be false if the code were wrong, against an independent
   computation (brute force, an analytical solution, a conservation law). Each tolerance is justified
   next to its check. Set FSDEM_TEST_VERBOSE=1 to print the measured values. */
#include <fenv.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fsdem_tests.h"

#define PI 3.14159265358979323846
#define G 9.81

/* ---- helpers ---------------------------------------------------------------------------------- */

/* Deterministic xorshift64* generator, so the tests do not depend on the C library's rand(). */
static unsigned long long rng_state = 1;
static void rng_seed(unsigned long long seed) { rng_state = seed ? seed : 1; }
static double urand(void) {
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}
static double urange(double lo, double hi) { return lo + (hi - lo) * urand(); }

static int verbose(void) {
    const char *v = getenv("FSDEM_TEST_VERBOSE");
    return v != NULL && v[0] != '\0' && v[0] != '0';
}
#define REPORT(...)                  \
    do {                             \
        if (verbose()) {             \
            printf("  [dem] ");      \
            printf(__VA_ARGS__);     \
            putchar('\n');           \
            fflush(stdout);          \
        }                            \
    } while (0)

static fsdem_vec3 vadd(fsdem_vec3 a, fsdem_vec3 b) { return fsdem_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static fsdem_vec3 vsub(fsdem_vec3 a, fsdem_vec3 b) { return fsdem_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static fsdem_vec3 vscale(fsdem_vec3 a, double s) { return fsdem_v3(a.x * s, a.y * s, a.z * s); }
static double vdot(fsdem_vec3 a, fsdem_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static double vnorm(fsdem_vec3 a) { return sqrt(vdot(a, a)); }
static double vcomp(fsdem_vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

static fsdem_dem *dem_new(const fsdem_dem_desc *desc) {
    fsdem_dem *dem = NULL;
    char msg[256] = "";
    fsdem_result res = fsdem_dem_create(desc, &dem);
    fsdem_dem_desc_check(desc, msg, sizeof msg);
    ck_assert_msg(res == FSDEM_OK, "fsdem_dem_create: %s (%s)", fsdem_result_string(res), msg);
    ck_assert_ptr_nonnull(dem);
    return dem;
}

static int add_material(fsdem_dem *dem, double density, double young, double poisson, double restitution,
                        double friction, double alpha) {
    fsdem_dem_material m = fsdem_dem_material_default();
    int index = -1;
    fsdem_result res;
    m.density = density;
    m.young_modulus = young;
    m.poisson_ratio = poisson;
    m.restitution = restitution;
    m.friction = friction;
    m.damping_alpha = alpha;
    res = fsdem_dem_add_material(dem, &m, &index);
    ck_assert_msg(res == FSDEM_OK, "add_material: %s", fsdem_dem_last_error(dem));
    return index;
}

/* A material for tests where contact damping plays no part. Restitution 1 makes
   fsdem_dem_add_material skip the Hertz damping calibration, which costs ~60 ms (seconds under
   Valgrind) per new restitution value. */
static int add_plain_material(fsdem_dem *dem) { return add_material(dem, 2500, 1e7, 0.3, 1.0, 0.3, 0.4); }

static int add_particle(fsdem_dem *dem, fsdem_vec3 x, fsdem_vec3 v, fsdem_vec3 w, double radius, int material,
                        int fixed) {
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    int index = -1;
    fsdem_result res;
    p.position = x;
    p.velocity = v;
    p.angular_velocity = w;
    p.radius = radius;
    p.material = material;
    p.fixed = fixed;
    res = fsdem_dem_add_particle(dem, &p, &index);
    ck_assert_msg(res == FSDEM_OK, "add_particle: %s", fsdem_dem_last_error(dem));
    return index;
}

static int add_wall(fsdem_dem *dem, fsdem_dem_wall_desc w) {
    int id = -1;
    fsdem_result res = fsdem_dem_add_wall(dem, &w, &id);
    ck_assert_msg(res == FSDEM_OK, "add_wall: %s", fsdem_dem_last_error(dem));
    return id;
}

static void step_n(fsdem_dem *dem, int n) {
    int s;
    for (s = 0; s < n; ++s) {
        fsdem_result res = fsdem_dem_step(dem);
        ck_assert_msg(res == FSDEM_OK, "fsdem_dem_step: %s: %s", fsdem_result_string(res), fsdem_dem_last_error(dem));
    }
}

/* Hertz effective modulus of two bodies of one material: 1/E* = 2 (1 - nu^2) / E. */
static double hertz_estar(double young, double poisson) { return young / (2 * (1 - poisson * poisson)); }

/* Duration of an elastic Hertz impact (Johnson 1985, Sec. 11.4):
   t_c = 2.868 (m*^2 / (R* E*^2 v))^(1/5), v the normal approach speed. */
static double hertz_contact_time(double m_eff, double r_eff, double estar, double v) {
    return 2.868 * pow(m_eff * m_eff / (r_eff * estar * estar * v), 0.2);
}

/* Static Hertz overlap under a normal load F: F = (4/3) E* sqrt(R*) d^1.5. */
static double hertz_static_overlap(double load, double r_eff, double estar) {
    return pow(3 * load / (4 * estar * sqrt(r_eff)), 2.0 / 3.0);
}

static double sphere_mass(double density, double r) { return density * 4.0 / 3.0 * PI * r * r * r; }

/* ---- 1. neighbour search: cell lists + skin versus brute force -------------------------------- */

typedef struct contact_rec {
    int i, j; /* j > i for a pair; -1 - wall id for a wall */
    double overlap;
    fsdem_vec3 normal;
} contact_rec;

static int contact_rec_cmp(const void *pa, const void *pb) {
    const contact_rec *a = (const contact_rec *)pa, *b = (const contact_rec *)pb;
    if (a->i != b->i) return a->i < b->i ? -1 : 1;
    if (a->j != b->j) return a->j < b->j ? -1 : 1;
    if (a->overlap != b->overlap) return a->overlap < b->overlap ? -1 : 1;
    return 0;
}

/* The walls of the neighbour test: an axis-aligned box holding the particles and a plane cutting
   off the upper corner. */
typedef struct nb_geometry {
    int dim, box_id, plane_id;
    double offset;
    fsdem_vec3 lo, hi, plane_point, plane_normal; /* plane_normal is a unit vector */
} nb_geometry;

/* All contacts of the current positions by an O(n^2) scan, written independently of the library. */
static int brute_force_contacts(const fsdem_dem_particles *p, const nb_geometry *g, contact_rec *out) {
    int i, j, axis, count = 0;
    for (i = 0; i < p->count; ++i) {
        const fsdem_vec3 xi = p->position[i];
        const double ri = p->radius[i];
        for (j = i + 1; j < p->count; ++j) {
            const fsdem_vec3 dx = vsub(xi, p->position[j]);
            const double dist = vnorm(dx), overlap = ri + p->radius[j] + g->offset - dist;
            if (overlap <= 0) continue;
            out[count].i = i;
            out[count].j = j;
            out[count].overlap = overlap;
            out[count].normal = vscale(dx, 1 / dist);
            count++;
        }
        for (axis = 0; axis < g->dim; ++axis) {
            double e[3] = {0, 0, 0}, d_lo = vcomp(xi, axis) - vcomp(g->lo, axis), d_hi = vcomp(g->hi, axis) - vcomp(xi, axis);
            if (ri + g->offset - d_lo > 0) {
                e[axis] = 1;
                out[count].i = i;
                out[count].j = -1 - g->box_id;
                out[count].overlap = ri + g->offset - d_lo;
                out[count].normal = fsdem_v3(e[0], e[1], e[2]);
                count++;
            }
            if (ri + g->offset - d_hi > 0) {
                e[axis] = -1;
                out[count].i = i;
                out[count].j = -1 - g->box_id;
                out[count].overlap = ri + g->offset - d_hi;
                out[count].normal = fsdem_v3(e[0], e[1], e[2]);
                count++;
            }
        }
        {
            const double d = vdot(vsub(xi, g->plane_point), g->plane_normal);
            if (ri + g->offset - d > 0) {
                out[count].i = i;
                out[count].j = -1 - g->plane_id;
                out[count].overlap = ri + g->offset - d;
                out[count].normal = g->plane_normal;
                count++;
            }
        }
    }
    return count;
}

/* Compares fsdem_dem_contacts with brute force: same set of (i, j) pairs and particle-wall
   contacts, same overlaps and normals. Returns the number of contacts. */
static int compare_with_brute_force(fsdem_dem *dem, const nb_geometry *g) {
    fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    const int n = p.count, room = n * (n - 1) / 2 + n * (2 * g->dim + 1) + 1;
    fsdem_dem_contact *info;
    contact_rec *lib, *ref;
    int total, got, nref, k;
    total = fsdem_dem_contacts(dem, NULL, 0);
    ck_assert_int_ge(total, 0);
    info = (fsdem_dem_contact *)malloc(sizeof *info * (size_t)(total + 1));
    lib = (contact_rec *)malloc(sizeof *lib * (size_t)(total + 1));
    ref = (contact_rec *)malloc(sizeof *ref * (size_t)room);
    ck_assert(info && lib && ref);
    got = fsdem_dem_contacts(dem, info, total);
    ck_assert_int_eq(got, total);
    p = fsdem_dem_get_particles(dem);
    for (k = 0; k < total; ++k) {
        lib[k].i = info[k].i;
        lib[k].j = info[k].j;
        lib[k].overlap = info[k].overlap;
        lib[k].normal = info[k].normal;
    }
    nref = brute_force_contacts(&p, g, ref);
    qsort(lib, (size_t)total, sizeof *lib, contact_rec_cmp);
    qsort(ref, (size_t)nref, sizeof *ref, contact_rec_cmp);
    ck_assert_msg(total == nref, "cell lists found %d contacts, brute force %d", total, nref);
    for (k = 0; k < total; ++k) {
        ck_assert_msg(lib[k].i == ref[k].i && lib[k].j == ref[k].j, "contact %d: library (%d,%d), brute force (%d,%d)", k,
                      lib[k].i, lib[k].j, ref[k].i, ref[k].j);
        /* Both evaluate r_i + r_j + offset - |x_i - x_j| (a wall: r_i + offset - (x_i - p).n) from the
           same numbers; in double only the operation order differs, so they agree to a few ulps of
           the radius (1e-15 m here). In float the library rounds each operation to fsdem_real while
           the reference works in double: 8 eps of the largest term (the radii, or |x_i - p| for a
           wall), measured 3 eps. */
        const double scale = lib[k].j >= 0 ? p.radius[lib[k].i] + p.radius[lib[k].j] + g->offset
                                           : vnorm(vsub(p.position[lib[k].i], g->plane_point)) + p.radius[lib[k].i] + g->offset;
        ck_assert_msg(fabs(lib[k].overlap - ref[k].overlap) < TOL(1e-13, 8 * scale), "overlap %g vs %g", lib[k].overlap,
                      ref[k].overlap);
        /* unit normals from the same difference vector: rounding only (1e-9 allows for the
           1/dist of nearly coincident centres, which random placement can produce; a difference of
           two fsdem_real positions is rounded relative to itself, so float needs a few eps: 16) */
        ck_assert_msg(vnorm(vsub(lib[k].normal, ref[k].normal)) < TOL(1e-9, 16), "contact (%d,%d): normal differs by %g",
                      lib[k].i, lib[k].j, vnorm(vsub(lib[k].normal, ref[k].normal)));
    }
    free(info);
    free(lib);
    free(ref);
    return total;
}

static void neighbour_case(int dim, double offset_factor, unsigned long long seed) {
    const int n = 200, steps = 60;
    const double r0 = 0.01, L = dim == 3 ? 0.15 : 0.4, vmax = 0.1;
    fsdem_dem_desc d = fsdem_dem_desc_default(dim);
    fsdem_dem *dem;
    nb_geometry g;
    int mat, i, s, contacts0, reused = 0, min_contacts = 1 << 30, wall_seen = 0, inert_seen = 0;
    long long rebuilds0;
    fsdem_dem_stats st;
    rng_seed(seed);
    d.gravity = fsdem_v3(0, 0, 0);
    d.domain_min = fsdem_v3(-0.05, -0.05, dim == 3 ? -0.05 : -1);
    d.domain_max = fsdem_v3(L + 0.05, L + 0.05, dim == 3 ? L + 0.05 : 1);
    d.contact_offset = offset_factor * r0;
    d.dt = 1e-3;
    dem = dem_new(&d);
    /* E = 1 Pa: contact forces are negligible (accelerations below ~0.5 m/s^2, a few cm/s over the
       run), so the particles fly nearly ballistically through each other and the lists see every
       kind of relative motion. Restitution 1 skips the damping calibration (add_plain_material). */
    mat = add_material(dem, 1000, 1, 0.3, 1.0, 0.3, 0.4);
    memset(&g, 0, sizeof g);
    g.dim = dim;
    g.offset = d.contact_offset;
    g.lo = fsdem_v3(0, 0, 0);
    g.hi = fsdem_v3(L, L, dim == 3 ? L : 0);
    g.plane_point = fsdem_v3(0.8 * L, 0.8 * L, dim == 3 ? 0.8 * L : 0);
    g.plane_normal = dim == 3 ? fsdem_v3(-1 / sqrt(3.0), -1 / sqrt(3.0), -1 / sqrt(3.0))
                              : fsdem_v3(-1 / sqrt(2.0), -1 / sqrt(2.0), 0);
    g.box_id = add_wall(dem, fsdem_dem_wall_box(g.lo, fsdem_v3(L, L, L), 1, mat));
    g.plane_id = add_wall(dem, fsdem_dem_wall_plane(g.plane_point, g.plane_normal, mat));
    for (i = 0; i < n;) {
        fsdem_vec3 x = fsdem_v3(urange(0, L), urange(0, L), dim == 3 ? urange(0, L) : 0);
        fsdem_vec3 v = fsdem_v3(urange(-vmax, vmax), urange(-vmax, vmax), dim == 3 ? urange(-vmax, vmax) : 0);
        double r = r0 * urange(0.5, 1.5); /* polydisperse: radii differ by up to a factor 3 */
        if (vdot(vsub(x, g.plane_point), g.plane_normal) < 0) continue; /* keep centres on the open side */
        /* one in eight is fixed (kinematic): pairs of them are geometric contacts that exert nothing */
        add_particle(dem, x, v, fsdem_v3(0, 0, 0), r, mat, i % 8 == 0);
        ++i;
    }
    /* fresh set: the lists are built by this call */
    contacts0 = compare_with_brute_force(dem, &g);
    rebuilds0 = fsdem_dem_get_stats(dem).rebuilds;
    for (s = 0; s < steps; ++s) {
        long long before = fsdem_dem_get_stats(dem).rebuilds;
        int c, k;
        fsdem_dem_contact *info;
        step_n(dem, 1);
        c = compare_with_brute_force(dem, &g);
        st = fsdem_dem_get_stats(dem);
        if (st.rebuilds == before) reused++;
        if (c < min_contacts) min_contacts = c;
        info = (fsdem_dem_contact *)malloc(sizeof *info * (size_t)(c + 1));
        ck_assert_int_eq(fsdem_dem_contacts(dem, info, c), c);
        {
            /* The forces of the step were evaluated at these same positions, so they saw the same
               contacts but those that exert nothing: two fixed particles, a fixed one and a wall. */
            const unsigned char *fixed = fsdem_dem_get_particles(dem).fixed;
            int inert = 0;
            for (k = 0; k < c; ++k) {
                wall_seen |= info[k].j < 0 ? (info[k].j == -1 - g.plane_id ? 2 : 1) : 0;
                inert += fixed[info[k].i] && (info[k].j < 0 || fixed[info[k].j]);
                inert_seen |= info[k].j >= 0 && fixed[info[k].i] && fixed[info[k].j];
            }
            ck_assert_int_eq(st.contacts + st.wall_contacts, c - inert);
        }
        free(info);
    }
    st = fsdem_dem_get_stats(dem);
    REPORT("neighbours dim %d offset %.2f r0: %d contacts fresh, >= %d later, %lld rebuilds in %d steps, %d steps reused "
           "the lists",
           dim, offset_factor, contacts0, min_contacts, st.rebuilds - rebuilds0, steps, reused);
    /* The comparison is meaningful only if there are many contacts of both kinds, the particles
       moved far enough to need rebuilds, and most comparisons used lists that were not fresh. */
    ck_assert_int_gt(contacts0, n / 2);
    ck_assert_int_eq(wall_seen, 3);
    ck_assert_msg(inert_seen, "no pair of fixed particles touched: the case does not test them");
    ck_assert_int_ge(st.rebuilds - rebuilds0, 2);
    ck_assert_int_ge(reused, steps / 2);
    fsdem_dem_destroy(dem);
}

START_TEST(neighbour_lists_match_brute_force) {
    neighbour_case(2, 0.0, 11);
    neighbour_case(3, 0.0, 12);
    neighbour_case(2, 0.3, 13);
    neighbour_case(3, 0.3, 14);
}
END_TEST

/* Pairs that touch (d^2 < (r_i + r_j)^2) with an overlap that rounds to zero, sliding past each
   other, under each law: the contact kernel (vector lanes, padding, guarded divisors) must raise
   neither a division by zero nor an invalid operation, which would trap a user running with
   floating-point exceptions enabled. The pairs are searched for with the library's own arithmetic
   (the difference of the stored centres, squared and summed; the root subtracted from the reach). */
START_TEST(touching_pairs_raise_no_fp_exceptions) {
    const fsdem_dem_law laws[3] = {FSDEM_DEM_LAW_HERTZ_MINDLIN, FSDEM_DEM_LAW_LINEAR, FSDEM_DEM_LAW_GIC};
    const fsdem_real r = (fsdem_real)0.01, reach = r + r;
    fsdem_vec3 xa[8], xb[8];
    int law, k, m, pairs = 0, flags = 0, contacts = 0;
    for (m = 0; m < 200 && pairs < 8; ++m) {
        const double angle = 0.1 + 0.0137 * m;
        const fsdem_vec3 base = fsdem_v3((fsdem_real)(-0.8 + 0.2 * pairs), (fsdem_real)0.2, 0);
        for (k = -6; k <= 6; ++k) {
            /* steps of half an ulp of the distance, in the precision of fsdem_real */
            const fsdem_vec3 other = fsdem_v3((fsdem_real)(base.x + reach * cos(angle) * (1 + k * TEST_EPS / 2)),
                                              (fsdem_real)(base.y + reach * sin(angle)), 0);
            const fsdem_real ex = base.x - other.x, ey = base.y - other.y, d2 = ex * ex + ey * ey;
            if (d2 < reach * reach && reach - (fsdem_real)sqrt((double)d2) <= 0) {
                xa[pairs] = base; /* one pair at each base point, 0.2 m from the next */
                xb[pairs++] = other;
                break;
            }
        }
    }
    ck_assert_msg(pairs >= 2, "found %d pairs with a zero overlap", pairs);
    for (law = 0; law < 3; ++law) {
        fsdem_dem_desc d = fsdem_dem_desc_default(3);
        fsdem_dem *dem;
        int mat;
        d.gravity = fsdem_v3(0, 0, 0);
        d.law = laws[law];
        d.linear_dx = 0.001;
        d.linear_accel = 9.81;
        d.dt = 1e-6;
        dem = dem_new(&d);
        mat = add_material(dem, 2500, 1e7, 0.3, 0.5, 0.3, 0.4);
        for (k = 0; k < pairs; ++k) {
            add_particle(dem, xa[k], fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), r, mat, 0);
            add_particle(dem, xb[k], fsdem_v3(0, 0, 0.1), fsdem_v3(0, 0, 3), r, mat, 0);
        }
        feclearexcept(FE_ALL_EXCEPT);
        ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK); /* its first force evaluation is at these positions */
        flags |= fetestexcept(FE_DIVBYZERO | FE_INVALID);
        contacts += fsdem_dem_get_stats(dem).contacts;
        fsdem_dem_destroy(dem);
    }
    REPORT("%d pairs touching with a zero overlap, %d contacts after the step (3 laws); FP flags %s%s", pairs, contacts,
           flags & FE_DIVBYZERO ? "divide-by-zero " : "", flags & FE_INVALID ? "invalid" : "");
    ck_assert_msg(flags == 0, "floating-point exceptions raised: %s%s", flags & FE_DIVBYZERO ? "divide-by-zero " : "",
                  flags & FE_INVALID ? "invalid" : "");
}
END_TEST

/* ---- 2. elastic box: momentum and energy -------------------------------------------------------- */

static int key_cmp(const void *a, const void *b) {
    const long x = *(const long *)a, y = *(const long *)b;
    return x < y ? -1 : x > y;
}

START_TEST(elastic_box_conserves_momentum_and_energy) {
    const int n = 200;
    const double r0 = 0.01, rho = 2500, young = 1e7, nu = 0.3, L = 0.152, vmax = 1.0;
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem;
    fsdem_dem_particles p;
    fsdem_dem_energy en;
    fsdem_dem_contact *info;
    long *prev_keys, *cur_keys;
    int mat, box, i, j, nprev = 0, steps = 0, info_room = 8 * n;
    long collisions = 0;
    double e0, max_drift = 0, pscale = 0, tc, m0, err, imp_norm;
    fsdem_vec3 p0 = fsdem_v3(0, 0, 0), p1, impulse;
    rng_seed(2024);
    d.gravity = fsdem_v3(0, 0, 0);
    d.domain_min = fsdem_v3(-0.02, -0.02, -0.02);
    d.domain_max = fsdem_v3(L + 0.02, L + 0.02, L + 0.02);
    /* dt resolves the Hertz contact: 50 steps over the contact time of two mean spheres meeting at
       1 m/s (faster impacts, rarer, get >= 40 steps; slower ones more). */
    m0 = sphere_mass(rho, r0);
    tc = hertz_contact_time(m0 / 2, r0 / 2, hertz_estar(young, nu), 1.0);
    d.dt = tc / 50;
    dem = dem_new(&d);
    mat = add_material(dem, rho, young, nu, 1.0, 0.0, 0.4); /* elastic, frictionless */
    box = add_wall(dem, fsdem_dem_wall_box(fsdem_v3(0, 0, 0), fsdem_v3(L, L, L), 1, mat));
    for (i = 0; i < n;) {
        const double r = r0 * urange(0.8, 1.2); /* unequal masses: momentum exchange is not symmetric */
        fsdem_vec3 x = fsdem_v3(urange(r, L - r), urange(r, L - r), urange(r, L - r));
        int ok = 1;
        p = fsdem_dem_get_particles(dem);
        for (j = 0; j < p.count && ok; ++j)
            if (vnorm(vsub(x, p.position[j])) < r + p.radius[j]) ok = 0;
        if (!ok) continue;
        add_particle(dem, x, fsdem_v3(urange(-vmax, vmax), urange(-vmax, vmax), urange(-vmax, vmax)),
                     fsdem_v3(urange(-50, 50), urange(-50, 50), urange(-50, 50)), r, mat, 0);
        ++i;
    }
    p = fsdem_dem_get_particles(dem);
    for (i = 0; i < n; ++i) {
        p0 = vadd(p0, vscale(p.velocity[i], p.mass[i]));
        pscale += p.mass[i] * vnorm(p.velocity[i]);
    }
    en = fsdem_dem_get_energy(dem);
    e0 = en.kinetic + en.rotational + en.elastic;
    prev_keys = (long *)malloc(sizeof(long) * (size_t)info_room);
    cur_keys = (long *)malloc(sizeof(long) * (size_t)info_room);
    info = (fsdem_dem_contact *)malloc(sizeof *info * (size_t)info_room);
    ck_assert(prev_keys && cur_keys && info);
    /* Collisions are counted as contact starts: after every step the pairs in contact are listed
       (fsdem_dem_contacts) and a pair that was not in contact after the previous step is a new
       collision. A contact lasts >= 40 steps, so no collision starts and ends unseen between two
       listings; a counter of stats.contacts increases would miss starts that coincide with ends. */
    while (collisions < 10000 && steps < 200000) {
        int c, ncur = 0;
        long *tmp;
        step_n(dem, 1);
        steps++;
        c = fsdem_dem_contacts(dem, info, info_room);
        ck_assert_int_le(c, info_room);
        for (i = 0; i < c; ++i)
            if (info[i].j >= 0) cur_keys[ncur++] = (long)info[i].i * n + info[i].j;
        qsort(cur_keys, (size_t)ncur, sizeof(long), key_cmp);
        for (i = 0; i < ncur; ++i)
            if (!bsearch(&cur_keys[i], prev_keys, (size_t)nprev, sizeof(long), key_cmp)) collisions++;
        tmp = prev_keys;
        prev_keys = cur_keys;
        cur_keys = tmp;
        nprev = ncur;
        if (steps % 20 == 0) {
            double drift;
            en = fsdem_dem_get_energy(dem);
            drift = fabs(en.kinetic + en.rotational + en.elastic - e0) / e0;
            if (drift > max_drift) max_drift = drift;
        }
    }
    en = fsdem_dem_get_energy(dem);
    {
        double drift = fabs(en.kinetic + en.rotational + en.elastic - e0) / e0;
        if (drift > max_drift) max_drift = drift;
    }
    p = fsdem_dem_get_particles(dem);
    p1 = fsdem_v3(0, 0, 0);
    for (i = 0; i < n; ++i) p1 = vadd(p1, vscale(p.velocity[i], p.mass[i]));
    impulse = fsdem_dem_wall_impulse(dem, box);
    err = vnorm(vsub(vsub(p1, p0), impulse)) / pscale;
    imp_norm = vnorm(impulse) / pscale;
    REPORT("elastic box: %d steps of dt = %.3g s (t_c/50), %ld particle collisions, max energy drift %.3e, "
           "momentum error %.3e (wall impulse %.3e, both relative to sum m|v|)",
           steps, d.dt, collisions, max_drift, err, imp_norm);
    ck_assert_msg(collisions >= 10000, "only %ld collisions", collisions);
    /* The wall impulse is large (the walls reverse the particles' momentum many times over), so
       the bookkeeping identity below is not satisfied trivially. */
    ck_assert_msg(imp_norm > 0.01, "wall impulse %g too small for the test to mean anything", imp_norm);
    /* Momentum: every kick adds h (F_i + F_ext) / m_i to v_i, pair forces enter i and j with
       opposite signs, and the wall accumulates -h F_wall in the same kick, so
       sum m v - P0 = sum of wall impulses exactly in real arithmetic. Rounding of ~1e4 steps of
       sums of 200 terms gives ~ eps sqrt(steps) ~ 1e-14 relative; 1e-12 leaves a margin. In float
       each kick rounds each of the n velocities by eps |v|: a random walk of eps sqrt(steps n) m|v|
       against pscale = n m|v|, i.e. eps sqrt(steps / n), times 4 (float: 4e-6, measured 2.2e-7). */
    ck_assert_msg(err < TOL(1e-12, 4 * sqrt((double)steps / n)), "momentum error %g (relative)", err);
    /* Energy: velocity Verlet is symplectic; with 50 steps per Hertz contact its energy error per
       collision is O((dt/t_c)^2) ~ 1e-3 of the collision's energy and of random sign, so the sum
       over 1e4 collisions random-walks to ~1e-4 of the total. 0.5% is the required bound. */
    ck_assert_msg(max_drift < 0.005, "energy drift %g", max_drift);
    free(prev_keys);
    free(cur_keys);
    free(info);
    fsdem_dem_destroy(dem);
}
END_TEST

/* ---- 3. restitution ------------------------------------------------------------------------------ */

/* Material of the impact tests, and the approach speed of each body. */
#define IMPACT_RHO 2500.0
#define IMPACT_YOUNG 1e7
#define IMPACT_NU 0.3
#define IMPACT_SPEED 0.5
#define IMPACT_GAP 1e-4

/* Expected restitution and contact duration of a head-on impact of sphere 1 (radius r1) on
   sphere 2 (r2, both moving at IMPACT_SPEED towards each other) or on a plane (wall = 1). */
static double impact_expectation(fsdem_dem_law law, double theta_dx_over_g, double e, double alpha, double r1,
                                 double r2, int wall, double *duration) {
    const double m1 = sphere_mass(IMPACT_RHO, r1), m2 = sphere_mass(IMPACT_RHO, r2);
    const double m_eff = wall ? m1 : m1 * m2 / (m1 + m2);
    if (law == FSDEM_DEM_LAW_LINEAR) {
        /* seed 000 Eq. 10-11: k = m_ij ||g|| / (theta dx), c = 2 alpha sqrt(m_ij k), with
           m_ij = (m1 + m2)/2 for a pair and m1 for a wall. The two bodies form a damped oscillator
           of mass m_eff, so zeta = c / (2 sqrt(m_eff k)) (alpha sqrt 2 for equal spheres, alpha for
           a wall) and, as the law has no tension cut-off, the contact ends after exactly half a
           damped period with e = exp(-pi zeta / sqrt(1 - zeta^2)). */
        const double m_ij = wall ? m1 : (m1 + m2) / 2, k = m_ij / theta_dx_over_g;
        const double c = 2 * alpha * sqrt(m_ij * k), zeta = c / (2 * sqrt(m_eff * k));
        *duration = PI / (sqrt(k / m_eff) * sqrt(1 - zeta * zeta));
        return exp(-PI * zeta / sqrt(1 - zeta * zeta));
    }
    /* Hertz-Mindlin: the damping is calibrated so that e is the material's restitution; the
       impact lasts about the elastic Hertz contact time (less when strongly damped). */
    *duration = hertz_contact_time(m_eff, wall ? r1 : r1 * r2 / (r1 + r2), hertz_estar(IMPACT_YOUNG, IMPACT_NU),
                                   wall ? IMPACT_SPEED : 2 * IMPACT_SPEED);
    return e;
}

/* Runs one head-on impact without gravity in `dem` with time step dt, then removes what it added.
   Returns the measured normal restitution (rebound / impact relative normal speed). */
static double run_impact(fsdem_dem *dem, int mat, double r1, double r2, int wall, double dt, double duration) {
    const double v = IMPACT_SPEED, gap = IMPACT_GAP;
    fsdem_dem_particles p;
    int a, b = -1, s, touched = 0, wall_id = -1, max_steps;
    double v_in, v_out;
    ck_assert_int_eq(fsdem_dem_set_dt(dem, dt), FSDEM_OK);
    a = add_particle(dem, fsdem_v3(-r1 - gap, 0, 0), fsdem_v3(v, 0, 0), fsdem_v3(0, 0, 0), r1, mat, 0);
    if (wall) wall_id = add_wall(dem, fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(-1, 0, 0), mat));
    else b = add_particle(dem, fsdem_v3(r2 + gap, 0, 0), fsdem_v3(-v, 0, 0), fsdem_v3(0, 0, 0), r2, mat, 0);
    v_in = wall ? v : 2 * v;
    max_steps = (int)(10 * duration / dt + 2 * gap / (v * dt));
    for (s = 0; s < max_steps; ++s) {
        fsdem_dem_stats st;
        step_n(dem, 1);
        st = fsdem_dem_get_stats(dem);
        if (st.contacts + st.wall_contacts > 0) touched = 1;
        else if (touched) break;
    }
    ck_assert_msg(touched && s < max_steps, "the impact did not complete");
    p = fsdem_dem_get_particles(dem);
    v_out = wall ? -p.velocity[a].x : p.velocity[b].x - p.velocity[a].x;
    /* the motion stays on the x axis: no spurious tangential force or spin */
    ck_assert(fabs(p.velocity[a].y) + fabs(p.velocity[a].z) < 1e-12 * v);
    if (b >= 0) ck_assert_int_eq(fsdem_dem_remove_particle(dem, b), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_remove_particle(dem, a), FSDEM_OK);
    if (wall_id >= 0) ck_assert_int_eq(fsdem_dem_remove_wall(dem, wall_id), FSDEM_OK);
    return v_out / v_in;
}

START_TEST(hertz_restitution_matches_input) {
    const double es[3] = {0.1, 0.5, 0.9}, r = 0.01;
    int k, wall, integ;
    for (integ = 0; integ < 2; ++integ)
        for (k = 0; k < 3; ++k) {
            fsdem_dem_desc d = fsdem_dem_desc_default(3);
            fsdem_dem *dem;
            int mat;
            d.gravity = fsdem_v3(0, 0, 0);
            d.integrator = integ ? FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR : FSDEM_DEM_INTEGRATOR_VERLET;
            dem = dem_new(&d);
            /* one object per e: the sphere-sphere and the sphere-wall impact share its material */
            mat = add_material(dem, IMPACT_RHO, IMPACT_YOUNG, IMPACT_NU, es[k], 0.3, 0.4);
            for (wall = 0; wall < 2; ++wall) {
                double duration, expected = impact_expectation(FSDEM_DEM_LAW_HERTZ_MINDLIN, 0, es[k], 0, r, r, wall, &duration);
                double e = run_impact(dem, mat, r, r, wall, duration / 400, duration);
                REPORT("Hertz-Mindlin %s %s: e = %.4f measured, %.4f input (%+.2f%%)", integ ? "PC    " : "Verlet",
                       wall ? "sphere-wall  " : "sphere-sphere", e, expected, 100 * (e / expected - 1));
                /* The damping coefficient is calibrated on the exact dimensionless Hertz ODE, so the
                   only error is time integration; with 400 steps per contact it is below 0.7%
                   (measured; it is largest for e = 0.1, where the dashpot dominates). 2% is the
                   required bound. */
                ck_assert_msg(fabs(e / expected - 1) < 0.02, "e = %g, expected %g (wall %d, integrator %d)", e, expected,
                              wall, integ);
            }
            fsdem_dem_destroy(dem);
        }
}
END_TEST

START_TEST(linear_restitution_matches_damped_oscillator) {
    const double alphas[3] = {0.1, 0.3, 0.5}, theta = 0.01, dx = 0.005, r = 0.01;
    const char *names[3] = {"equal spheres  ", "unequal spheres", "sphere-wall    "};
    int k, kind, integ, mats[3];
    for (integ = 0; integ < 2; ++integ) {
        fsdem_dem_desc d = fsdem_dem_desc_default(3);
        fsdem_dem *dem;
        d.gravity = fsdem_v3(0, 0, 0);
        d.law = FSDEM_DEM_LAW_LINEAR;
        d.integrator = integ ? FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR : FSDEM_DEM_INTEGRATOR_VERLET;
        d.linear_theta = theta;
        d.linear_dx = dx;
        d.linear_accel = G; /* ||g|| of seed 000 Eq. 10; gravity itself is off for a clean impact */
        dem = dem_new(&d);
        /* restitution is not used by the linear law (alpha sets the damping) */
        for (k = 0; k < 3; ++k) mats[k] = add_material(dem, IMPACT_RHO, IMPACT_YOUNG, IMPACT_NU, 1.0, 0.3, alphas[k]);
        for (kind = 0; kind < 3; ++kind)
            for (k = 0; k < 3; ++k) {
                const double r2 = kind == 1 ? 0.7 * r : r; /* unequal: mass ratio 0.343 */
                double duration, e, expected;
                /* Velocity Verlet evaluates the dashpot with the half-step velocity, so for a damped
                   contact it is first order in dt (measured: the error falls 4x when dt does);
                   8000 steps per contact keep it below 0.4% for zeta = 0.81. The predictor-corrector
                   is second order: 400 steps give < 0.03%. */
                const double steps_per_contact = integ ? 400 : 8000;
                expected = impact_expectation(FSDEM_DEM_LAW_LINEAR, theta * dx / G, 1, alphas[k], r, r2, kind == 2, &duration);
                e = run_impact(dem, mats[k], r, r2, kind == 2, duration / steps_per_contact, duration);
                REPORT("linear %s %s alpha %.1f: e = %.4f measured, %.4f damped oscillator (%+.3f%%)",
                       integ ? "PC    " : "Verlet", names[kind], alphas[k], e, expected, 100 * (e / expected - 1));
                /* 1% is the required bound */
                ck_assert_msg(fabs(e / expected - 1) < 0.01, "e = %g, expected %g (kind %d, alpha %g, integrator %d)", e,
                              expected, kind, alphas[k], integ);
            }
        fsdem_dem_destroy(dem);
    }
}
END_TEST

/* ---- 4. rolling and sliding down an incline ------------------------------------------------------ */

#define INCLINE_RHO 2500.0
#define INCLINE_YOUNG 1e7
#define INCLINE_NU 0.3

/* A sphere (3D) or disc (2D) of material `mat` released at rest on a plane tilted by theta
   (gravity vertical) in `dem`; removes its particle and wall afterwards. Returns the acceleration
   along the slope from the velocity change between t1 and t2, and the slip speed (contact-point
   speed along the slope) at t2 relative to the centre's speed. */
static double incline_acceleration(fsdem_dem *dem, int mat, double theta, double *slip_ratio) {
    const double r = 0.01, t1 = 0.1, t2 = 0.4, dt = fsdem_dem_get_stats(dem).dt;
    fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    const int dim = p.dim;
    fsdem_vec3 n, down, axis;
    int n1, n2, wall, index;
    double m, delta, v1, v2, spin;
    if (dim == 3) {
        n = fsdem_v3(-sin(theta), 0, cos(theta));
        down = fsdem_v3(-cos(theta), 0, -sin(theta));
    } else {
        n = fsdem_v3(-sin(theta), cos(theta), 0);
        down = fsdem_v3(-cos(theta), -sin(theta), 0);
    }
    wall = add_wall(dem, fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), n, mat));
    index = add_particle(dem, fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), r, mat, 0);
    p = fsdem_dem_get_particles(dem);
    m = p.mass[index];
    /* start at the static overlap under the normal load so that the normal bounce is small */
    delta = hertz_static_overlap(m * G * cos(theta), r, hertz_estar(INCLINE_YOUNG, INCLINE_NU));
    ck_assert_int_eq(fsdem_dem_set_particle_state(dem, index, vscale(n, r - delta), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0)),
                     FSDEM_OK);
    n1 = (int)(t1 / dt + 0.5);
    n2 = (int)(t2 / dt + 0.5);
    step_n(dem, n1);
    p = fsdem_dem_get_particles(dem);
    v1 = vdot(p.velocity[index], down);
    step_n(dem, n2 - n1);
    p = fsdem_dem_get_particles(dem);
    v2 = vdot(p.velocity[index], down);
    /* rolling down the slope spins the body about n x down, at omega = v / r without slip */
    axis = fsdem_v3(n.y * down.z - n.z * down.y, n.z * down.x - n.x * down.z, n.x * down.y - n.y * down.x);
    spin = vdot(p.angular_velocity[index], axis);
    *slip_ratio = (v2 - spin * r) / v2;
    ck_assert_int_eq(fsdem_dem_get_stats(dem).wall_contacts, 1); /* still on the plane */
    ck_assert_int_eq(fsdem_dem_remove_particle(dem, index), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_remove_wall(dem, wall), FSDEM_OK);
    return (v2 - v1) / ((n2 - n1) * dt);
}

START_TEST(incline_rolling_and_sliding) {
    const double theta = 30 * PI / 180;
    fsdem_dem_desc d3 = fsdem_dem_desc_default(3), d2 = fsdem_dem_desc_default(2);
    fsdem_dem *dem3, *dem2;
    int sticky3, slippery3, sticky2;
    double slip, a, ref;
    /* dt: the normal and tangential contact oscillations (periods ~5-8 ms here) get >= 100 steps */
    d3.dt = d2.dt = 5e-5;
    d2.disc_length = 0.02; /* a cylinder as long as its diameter */
    dem3 = dem_new(&d3);
    dem2 = dem_new(&d2);
    /* e = 0.5 damps the contact transients; both frictions in one object share the calibration */
    sticky3 = add_material(dem3, INCLINE_RHO, INCLINE_YOUNG, INCLINE_NU, 0.5, 0.5, 0.4);
    slippery3 = add_material(dem3, INCLINE_RHO, INCLINE_YOUNG, INCLINE_NU, 0.5, 0.1, 0.4);
    sticky2 = add_material(dem2, INCLINE_RHO, INCLINE_YOUNG, INCLINE_NU, 0.5, 0.5, 0.4);

    /* sphere, mu = 0.5 > (2/7) tan(theta) = 0.165: rolls without slipping, a = (5/7) g sin(theta) */
    a = incline_acceleration(dem3, sticky3, theta, &slip);
    ref = 5.0 / 7.0 * G * sin(theta);
    REPORT("sphere rolling: a / ((5/7) g sin theta) = %.5f, slip speed / speed = %.2e", a / ref, slip);
    /* The Mindlin spring's transient is damped out by t1 = 0.1 s (its damping time is a few ms),
       so Delta v over 0.3 s is set by the rolling dynamics; what remains is the O(dt^2)
       integration error and the tangential spring's small elastic creep, far below 1%. */
    ck_assert_msg(fabs(a / ref - 1) < 0.01, "sphere rolling a = %g, expected %g", a, ref);
    /* no slip: the contact point is at rest up to the elastic creep of the spring (~1e-3) */
    ck_assert_msg(fabs(slip) < 0.01, "sphere slips: %g", slip);

    /* disc, mu = 0.5 > (1/3) tan(theta) = 0.19: a = (2/3) g sin(theta) */
    a = incline_acceleration(dem2, sticky2, theta, &slip);
    ref = 2.0 / 3.0 * G * sin(theta);
    REPORT("disc rolling:   a / ((2/3) g sin theta) = %.5f, slip speed / speed = %.2e", a / ref, slip);
    ck_assert_msg(fabs(a / ref - 1) < 0.01, "disc rolling a = %g, expected %g", a, ref);
    ck_assert_msg(fabs(slip) < 0.01, "disc slips: %g", slip);

    /* sphere, mu = 0.1 with tan(theta) = 0.577 > 3.5 mu = 0.35: it slides all the way and
       a = g (sin theta - mu cos theta) (friction at the Coulomb limit, normal force m g cos) */
    a = incline_acceleration(dem3, slippery3, theta, &slip);
    ref = G * (sin(theta) - 0.1 * cos(theta));
    REPORT("sphere sliding: a / (g (sin theta - mu cos theta)) = %.5f, slip speed / speed = %.4f (expected %.4f)", a / ref,
           slip, 1 - 2.5 * 0.1 * cos(theta) / (sin(theta) - 0.1 * cos(theta)));
    ck_assert_msg(fabs(a / ref - 1) < 0.01, "sphere sliding a = %g, expected %g", a, ref);
    /* and it really slides: the friction torque spins it up at omega r = (5/2) mu g cos(theta) t
       while v = a t, so the slip ratio is 1 - (5/2) mu cos / (sin - mu cos) = 0.476 at all times.
       The short initial transient shifts both by ~1e-3 relative; 2% is ample. */
    ref = 1 - 2.5 * 0.1 * cos(theta) / (sin(theta) - 0.1 * cos(theta));
    ck_assert_msg(fabs(slip / ref - 1) < 0.02, "sliding sphere slip ratio %g, expected %g", slip, ref);
    fsdem_dem_destroy(dem3);
    fsdem_dem_destroy(dem2);
}
END_TEST

/* ---- 5. static overlap ----------------------------------------------------------------------------- */

/* A sphere released touching a floor settles; returns the final overlap and the expected one. */
static double resting_overlap(fsdem_dem_law law, double linear_accel, double *expected) {
    const double rho = 2500, young = 1e7, nu = 0.3, r = 0.01;
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem;
    fsdem_dem_particles p;
    fsdem_real dt;
    int mat, steps;
    double overlap, m;
    d.law = law;
    d.linear_theta = 0.01;
    d.linear_dx = 0.01;
    d.linear_accel = linear_accel;
    d.dt = 1e-5;
    dem = dem_new(&d);
    /* restitution only matters for Hertz-Mindlin (the linear law's damping is alpha) */
    mat = add_material(dem, rho, young, nu, law == FSDEM_DEM_LAW_LINEAR ? 1.0 : 0.5, 0.3, 0.4);
    add_wall(dem, fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), mat));
    add_particle(dem, fsdem_v3(0, 0, r), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), r, mat, 0);
    p = fsdem_dem_get_particles(dem);
    m = p.mass[0];
    if (law == FSDEM_DEM_LAW_LINEAR) {
        /* seed 000 Eq. 10 for a wall: m_ij = m, k = m ||g|| / (theta dx), ||g|| = linear_accel
           when set, else |gravity|. The weight m g is carried by k d: d = m g / k. */
        const double accel = linear_accel > 0 ? linear_accel : G;
        const double k = m * accel / (d.linear_theta * d.linear_dx);
        *expected = m * G / k;
        /* seed 000 Eq. 18 with gamma = 150 gives ~150 steps per undamped period */
        ck_assert_int_eq(fsdem_dem_stable_dt(dem, &dt), FSDEM_OK); /* the law's rule: Eq. 18, gamma 150 */
        ck_assert_int_eq(fsdem_dem_set_dt(dem, dt), FSDEM_OK);
        /* damping zeta = alpha = 0.4, omega = sqrt(k/m) >= 313 rad/s: after 0.3 s the transient
           is below e^-37 */
        steps = (int)(0.3 / dt);
    } else {
        /* F = (4/3) E* sqrt(R) d^1.5 = m g with R* = r for a wall, 1/E* = 2 (1 - nu^2)/E */
        *expected = hertz_static_overlap(m * G, r, hertz_estar(young, nu));
        dt = 5e-5; /* ~100 steps per period of the oscillation about the static overlap */
        ck_assert_int_eq(fsdem_dem_set_dt(dem, dt), FSDEM_OK);
        steps = (int)(0.3 / dt);
    }
    step_n(dem, steps);
    p = fsdem_dem_get_particles(dem);
    overlap = r - p.position[0].z;
    fsdem_dem_destroy(dem);
    return overlap;
}

START_TEST(resting_particle_settles_to_static_overlap) {
    double expected, overlap;
    overlap = resting_overlap(FSDEM_DEM_LAW_LINEAR, 0, &expected);
    REPORT("linear, ||g|| = |gravity|: overlap / (m g / k) = %.6f (m g / k = %.4g m = theta dx)", overlap / expected,
           expected);
    /* At rest the dashpot is idle and k d = m g holds exactly; the residual transient is < e^-37.
       1% is the required bound. */
    ck_assert_msg(fabs(overlap / expected - 1) < 0.01, "overlap %g, expected %g", overlap, expected);
    /* theta dx, the meaning of theta in seed 000 (theta and dx are fsdem_real: 4 eps of 1e-4) */
    ck_assert(fabs(expected - 0.01 * 0.01) < TOL(1e-12, 4 * 1e-4));
    overlap = resting_overlap(FSDEM_DEM_LAW_LINEAR, 2.5 * G, &expected);
    REPORT("linear, ||g|| = 2.5 |gravity|: overlap / (m g / k) = %.6f (m g / k = %.4g m = theta dx / 2.5)",
           overlap / expected, expected);
    ck_assert_msg(fabs(overlap / expected - 1) < 0.01, "overlap %g, expected %g", overlap, expected);
    overlap = resting_overlap(FSDEM_DEM_LAW_HERTZ_MINDLIN, 0, &expected);
    REPORT("Hertz: overlap / (3 m g / (4 E* sqrt R))^(2/3) = %.6f (%.4g m)", overlap / expected, expected);
    /* Hertz damping (e = 0.5) decays the oscillation within ~0.05 s; the equilibrium is exact. */
    ck_assert_msg(fabs(overlap / expected - 1) < 0.01, "overlap %g, expected %g", overlap, expected);
}
END_TEST

/* A particle resting where mesh elements meet (the shared diagonal of two coplanar triangles, the
   shared vertex of a fan of six, the joint of a 2D polyline) must be pushed once, as by a plane:
   Hertz gives the static overlap (3 m g / (4 E* sqrt R))^(2/3). Counting the shared edge once per
   element would give two (or six) springs in parallel and a smaller overlap (0.63x for two). */
static double settle_on_mesh(int dim, const fsdem_dem_wall_desc *walls, int nwalls, fsdem_vec3 at, double *expected) {
    const double rho = 2500, young = 1e7, nu = 0.3, r = 0.01;
    fsdem_dem_desc d = fsdem_dem_desc_default(dim);
    fsdem_dem *dem;
    fsdem_dem_particles p;
    int mat, k;
    double overlap, height;
    d.dt = 5e-5; /* ~100 steps per period of the oscillation about the static overlap */
    dem = dem_new(&d);
    mat = add_material(dem, rho, young, nu, 0.5, 0.3, 0.4);
    for (k = 0; k < nwalls; ++k) {
        fsdem_dem_wall_desc w = walls[k];
        w.material = mat;
        add_wall(dem, w);
    }
    add_particle(dem, at, fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), r, mat, 0);
    p = fsdem_dem_get_particles(dem);
    *expected = hertz_static_overlap(p.mass[0] * G, r, hertz_estar(young, nu));
    step_n(dem, 6000); /* 0.3 s: e = 0.5 damps the bounce within ~0.05 s */
    p = fsdem_dem_get_particles(dem);
    height = dim == 2 ? p.position[0].y : p.position[0].z;
    overlap = r - height;
    fsdem_dem_destroy(dem);
    return overlap;
}

START_TEST(mesh_edges_and_vertices_push_once) {
    const double r = 0.01;
    fsdem_dem_wall_desc w[6];
    double expected, overlap;
    int k;
    /* two triangles sharing the diagonal (-1,-1)-(1,1); sphere on the diagonal, then near it */
    w[0] = fsdem_dem_wall_triangle(fsdem_v3(-1, -1, 0), fsdem_v3(1, -1, 0), fsdem_v3(1, 1, 0), 0);
    w[1] = fsdem_dem_wall_triangle(fsdem_v3(-1, -1, 0), fsdem_v3(1, 1, 0), fsdem_v3(-1, 1, 0), 0);
    overlap = settle_on_mesh(3, w, 2, fsdem_v3(0, 0, r), &expected);
    REPORT("sphere on a shared triangle edge: overlap / Hertz = %.6f", overlap / expected);
    /* Hertz equilibrium is exact once the bounce has decayed (< 1e-6 relative after 0.3 s); 1% as
       for the plane. Two contacts would give (1/2)^(2/3) = 0.63. */
    ck_assert_msg(fabs(overlap / expected - 1) < 0.01, "overlap %g, expected %g", overlap, expected);
    overlap = settle_on_mesh(3, w, 2, fsdem_v3(0.2 * r, -0.1 * r, r), &expected);
    REPORT("sphere beside a shared triangle edge: overlap / Hertz = %.6f", overlap / expected);
    ck_assert_msg(fabs(overlap / expected - 1) < 0.01, "overlap %g, expected %g", overlap, expected);
    /* a fan of six triangles around the origin; sphere on the common vertex */
    for (k = 0; k < 6; ++k) {
        double a0 = k * PI / 3, a1 = (k + 1) * PI / 3;
        w[k] = fsdem_dem_wall_triangle(fsdem_v3(0, 0, 0), fsdem_v3(cos(a0), sin(a0), 0), fsdem_v3(cos(a1), sin(a1), 0), 0);
    }
    overlap = settle_on_mesh(3, w, 6, fsdem_v3(0, 0, r), &expected);
    REPORT("sphere on a vertex shared by six triangles: overlap / Hertz = %.6f", overlap / expected);
    ck_assert_msg(fabs(overlap / expected - 1) < 0.01, "overlap %g, expected %g", overlap, expected);
    /* 2D: a disc on the joint of a two-segment polyline */
    w[0] = fsdem_dem_wall_segment(fsdem_v3(-1, 0, 0), fsdem_v3(0, 0, 0), 0);
    w[1] = fsdem_dem_wall_segment(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), 0);
    overlap = settle_on_mesh(2, w, 2, fsdem_v3(0, r, 0), &expected);
    REPORT("disc on a polyline joint: overlap / Hertz = %.6f", overlap / expected);
    ck_assert_msg(fabs(overlap / expected - 1) < 0.01, "overlap %g, expected %g", overlap, expected);
}
END_TEST

/* A wall moved by its own callback (an SDF plane z = *height) must reach particles that were far from
   it at the last neighbour-list build: fsdem_dem_wall_moved tells the search. Without it the plane
   would rise through a resting particle (measured: it does, the particle stays at z = 0.05). */
static fsdem_real sdf_rising_floor(void *user, fsdem_vec3 p, fsdem_vec3 *normal) {
    *normal = fsdem_v3(0, 0, 1);
    return p.z - *(const fsdem_real *)user;
}

START_TEST(moving_sdf_wall_reaches_resting_particles) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem;
    fsdem_real height = 0;
    int mat, wall, s;
    d.gravity = fsdem_v3(0, 0, 0);
    d.dt = 1e-5;
    dem = dem_new(&d);
    mat = add_plain_material(dem);
    wall = add_wall(dem, fsdem_dem_wall_sdf(sdf_rising_floor, &height, mat));
    add_particle(dem, fsdem_v3(0, 0, 0.05), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), 0.01, mat, 0);
    for (s = 0; s < 10000; ++s) { /* the floor rises 0.1 m at 1 m/s */
        height += 1e-5;
        ck_assert_int_eq(fsdem_dem_wall_moved(dem, wall, 1e-5), FSDEM_OK);
        step_n(dem, 1);
    }
    /* the particle rides on the floor: centre at least r minus a Hertz overlap (< 1 mm here) above it */
    ck_assert_msg(fsdem_dem_get_particles(dem).position[0].z > height + 0.01 - 1e-3, "particle at %g, floor at %g",
                  (double)fsdem_dem_get_particles(dem).position[0].z, (double)height);
    ck_assert_int_eq(fsdem_dem_wall_moved(dem, wall, -1), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_dem_wall_moved(dem, 7, 1), FSDEM_ERR_NOT_FOUND);
    fsdem_dem_destroy(dem);
}
END_TEST

/* ---- 6. input validation ------------------------------------------------------------------------- */

typedef struct log_capture {
    char message[512];
    int count;
} log_capture;

static void capture_log(void *user, fsdem_log_level level, const char *message) {
    log_capture *c = (log_capture *)user;
    (void)level;
    snprintf(c->message, sizeof c->message, "%s", message);
    c->count++;
}

/* fsdem_dem_create rejects `bad` with FSDEM_ERR_INVALID_ARG, leaves *out NULL, and both the log
   and fsdem_dem_desc_check name `culprit`. */
static void expect_bad_desc(fsdem_dem_desc bad, const char *culprit) {
    log_capture cap;
    char msg[256] = "";
    fsdem_dem *dem = (fsdem_dem *)&cap; /* must be overwritten with NULL */
    memset(&cap, 0, sizeof cap);
    bad.log = capture_log;
    bad.log_user = &cap;
    ck_assert_int_eq(fsdem_dem_desc_check(&bad, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert_msg(strstr(msg, culprit) != NULL, "desc_check message \"%s\" does not name %s", msg, culprit);
    ck_assert_int_eq(fsdem_dem_create(&bad, &dem), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_null(dem);
    ck_assert_int_eq(cap.count, 1);
    ck_assert_msg(strstr(cap.message, culprit) != NULL, "create log \"%s\" does not name %s", cap.message, culprit);
}

/* `res` is `code` and the object's message names `culprit`. */
static void expect_error(fsdem_dem *dem, fsdem_result res, fsdem_result code, const char *culprit) {
    ck_assert_msg(res == code, "got %s, expected %s (%s)", fsdem_result_string(res), fsdem_result_string(code),
                  fsdem_dem_last_error(dem));
    ck_assert_msg(strstr(fsdem_dem_last_error(dem), culprit) != NULL, "message \"%s\" does not name %s",
                  fsdem_dem_last_error(dem), culprit);
}

/* The object still works: a valid particle can be added and a step succeeds. */
static void expect_usable(fsdem_dem *dem, int material) {
    fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    const int before = p.count;
    int index = -1;
    fsdem_dem_particle_desc pd = fsdem_dem_particle_desc_default();
    pd.position = fsdem_v3(0.5 * (before % 3) - 0.5, 0.5, 0); /* distinct, inside [-1, 1]^3 */
    pd.radius = 0.01;
    pd.material = material;
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &pd, &index), FSDEM_OK);
    ck_assert_int_eq(index, before);
    ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK);
    ck_assert_str_eq(fsdem_dem_last_error(dem), "");
}

START_TEST(invalid_desc_is_rejected) {
    fsdem_dem_desc base = fsdem_dem_desc_default(3), bad;
    fsdem_dem *dem;
    bad = base; bad.dim = 4; expect_bad_desc(bad, "fsdem_dem_desc.dim");
    bad = base; bad.dt = 0; expect_bad_desc(bad, "fsdem_dem_desc.dt");
    bad = base; bad.dt = -1e-5; expect_bad_desc(bad, "fsdem_dem_desc.dt");
    bad = base; bad.dt = NAN; expect_bad_desc(bad, "fsdem_dem_desc.dt");
    bad = base; bad.domain_max.y = bad.domain_min.y; expect_bad_desc(bad, "fsdem_dem_desc.domain_max");
    bad = base; bad.domain_max.x = -2; expect_bad_desc(bad, "fsdem_dem_desc.domain_max");
    bad = base; bad.gravity.z = NAN; expect_bad_desc(bad, "fsdem_dem_desc.gravity");
    bad = base; bad.contact_offset = -1e-3; expect_bad_desc(bad, "fsdem_dem_desc.contact_offset");
    bad = base; bad.law = FSDEM_DEM_LAW_LINEAR; expect_bad_desc(bad, "fsdem_dem_desc.linear_dx"); /* linear_dx left at 0 */
    bad = base; bad.law = FSDEM_DEM_LAW_LINEAR; bad.linear_dx = 0.01; bad.gravity = fsdem_v3(0, 0, 0);
    expect_bad_desc(bad, "fsdem_dem_desc.linear_accel");
    /* the same desc with linear_accel set is valid: zero gravity is fine then */
    bad.linear_accel = G;
    dem = dem_new(&bad);
    fsdem_dem_destroy(dem);
    /* and the valid base desc still creates an object */
    dem = dem_new(&base);
    expect_usable(dem, add_plain_material(dem));
    fsdem_dem_destroy(dem);
}
END_TEST

START_TEST(invalid_material_and_particle_are_rejected) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem;
    fsdem_dem_material good = fsdem_dem_material_default(), bad;
    fsdem_dem_particle_desc pd = fsdem_dem_particle_desc_default(), pbad;
    int index = -7, mat;
    d.gravity = fsdem_v3(0, 0, 0);
    dem = dem_new(&d);
    mat = add_plain_material(dem);
    good.restitution = 1; /* see add_plain_material */
    bad = good; bad.density = 0;
    expect_error(dem, fsdem_dem_add_material(dem, &bad, &index), FSDEM_ERR_INVALID_ARG, "fsdem_dem_material.density");
    bad = good; bad.density = -2500;
    expect_error(dem, fsdem_dem_add_material(dem, &bad, &index), FSDEM_ERR_INVALID_ARG, "fsdem_dem_material.density");
    bad = good; bad.restitution = 0;
    expect_error(dem, fsdem_dem_add_material(dem, &bad, &index), FSDEM_ERR_INVALID_ARG, "fsdem_dem_material.restitution");
    bad = good; bad.restitution = 1.5;
    expect_error(dem, fsdem_dem_add_material(dem, &bad, &index), FSDEM_ERR_INVALID_ARG, "fsdem_dem_material.restitution");
    bad = good; bad.friction = -0.1;
    expect_error(dem, fsdem_dem_add_material(dem, &bad, &index), FSDEM_ERR_INVALID_ARG, "fsdem_dem_material.friction");
    bad = good; bad.poisson_ratio = 0.6;
    expect_error(dem, fsdem_dem_add_material(dem, &bad, &index), FSDEM_ERR_INVALID_ARG, "fsdem_dem_material.poisson_ratio");
    ck_assert_int_eq(index, -7); /* untouched on failure */
    /* none of the rejected materials was added: the next one gets index 1 */
    ck_assert_int_eq(fsdem_dem_add_material(dem, &good, &index), FSDEM_OK);
    ck_assert_int_eq(index, 1);
    pd.position = fsdem_v3(0, 0, 0);
    pd.radius = 0.01;
    pd.material = mat;
    pbad = pd; pbad.radius = -0.01;
    expect_error(dem, fsdem_dem_add_particle(dem, &pbad, &index), FSDEM_ERR_INVALID_ARG, "fsdem_dem_particle_desc.radius");
    pbad = pd; pbad.radius = 0;
    expect_error(dem, fsdem_dem_add_particle(dem, &pbad, &index), FSDEM_ERR_INVALID_ARG, "fsdem_dem_particle_desc.radius");
    pbad = pd; pbad.position.y = NAN;
    expect_error(dem, fsdem_dem_add_particle(dem, &pbad, &index), FSDEM_ERR_INVALID_ARG, "position");
    pbad = pd; pbad.position.x = 1.5; /* domain is [-1, 1]^3 */
    expect_error(dem, fsdem_dem_add_particle(dem, &pbad, &index), FSDEM_ERR_OUT_OF_DOMAIN, "position");
    pbad = pd; pbad.material = 2; /* two materials exist */
    expect_error(dem, fsdem_dem_add_particle(dem, &pbad, &index), FSDEM_ERR_INVALID_ARG, "fsdem_dem_particle_desc.material");
    pbad = pd; pbad.material = -1;
    expect_error(dem, fsdem_dem_add_particle(dem, &pbad, &index), FSDEM_ERR_INVALID_ARG, "fsdem_dem_particle_desc.material");
    ck_assert_int_eq(fsdem_dem_get_particles(dem).count, 0);
    expect_usable(dem, mat);
    expect_usable(dem, 1);
    fsdem_dem_destroy(dem);
}
END_TEST

static fsdem_real sdf_floor(void *user, fsdem_vec3 p, fsdem_vec3 *normal) {
    (void)user;
    *normal = fsdem_v3(0, 0, 1);
    return p.z + 0.9;
}

START_TEST(invalid_walls_and_calls_are_rejected) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3), d2 = fsdem_dem_desc_default(2);
    fsdem_dem *dem, *dem2;
    fsdem_dem_wall_desc w;
    int id = -7, mat, mat2, i;
    fsdem_real t0;
    fsdem_dem_particles p;
    d.gravity = fsdem_v3(0, 0, 0);
    dem = dem_new(&d);
    mat = add_plain_material(dem);
    w = fsdem_dem_wall_plane(fsdem_v3(0, 0, -0.9), fsdem_v3(0, 0, 0), mat);
    expect_error(dem, fsdem_dem_add_wall(dem, &w, &id), FSDEM_ERR_INVALID_ARG, "normal");
    w = fsdem_dem_wall_triangle(fsdem_v3(0, 0, 0), fsdem_v3(1, 1, 1), fsdem_v3(2, 2, 2), mat); /* collinear */
    expect_error(dem, fsdem_dem_add_wall(dem, &w, &id), FSDEM_ERR_INVALID_ARG, "degenerate");
    w = fsdem_dem_wall_sdf(NULL, NULL, mat);
    expect_error(dem, fsdem_dem_add_wall(dem, &w, &id), FSDEM_ERR_INVALID_ARG, "callback");
    w = fsdem_dem_wall_plane(fsdem_v3(0, 0, -0.9), fsdem_v3(0, 0, 1), 5);
    expect_error(dem, fsdem_dem_add_wall(dem, &w, &id), FSDEM_ERR_INVALID_ARG, "material");
    ck_assert_int_eq(id, -7);
    /* no wall was added: the first valid one gets id 0 */
    w = fsdem_dem_wall_sdf(sdf_floor, NULL, mat);
    ck_assert_int_eq(fsdem_dem_add_wall(dem, &w, &id), FSDEM_OK);
    ck_assert_int_eq(id, 0);

    d2.gravity = fsdem_v3(0, 0, 0);
    dem2 = dem_new(&d2);
    mat2 = add_plain_material(dem2);
    w = fsdem_dem_wall_triangle(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), fsdem_v3(0, 1, 0), mat2);
    expect_error(dem2, fsdem_dem_add_wall(dem2, &w, &id), FSDEM_ERR_INVALID_ARG, "dim");
    expect_usable(dem2, mat2);
    fsdem_dem_destroy(dem2);

    /* time step and subcycling */
    expect_usable(dem, mat);
    expect_error(dem, fsdem_dem_set_dt(dem, 0), FSDEM_ERR_INVALID_ARG, "dt must be > 0");
    expect_error(dem, fsdem_dem_set_dt(dem, -1e-5), FSDEM_ERR_INVALID_ARG, "dt must be > 0");
    ck_assert(fsdem_dem_get_stats(dem).dt == d.dt);
    ck_assert(fsdem_dem_get_desc(dem).dt == d.dt);
    t0 = fsdem_dem_time(dem);
    expect_error(dem, fsdem_dem_advance(dem, 0, NULL), FSDEM_ERR_INVALID_ARG, "duration");
    expect_error(dem, fsdem_dem_advance(dem, -1e-3, NULL), FSDEM_ERR_INVALID_ARG, "duration");
    expect_error(dem, fsdem_dem_advance(dem, 1e9, NULL), FSDEM_ERR_INVALID_ARG, "FSDEM_DEM_MAX_SUBSTEPS");
    expect_error(dem, fsdem_dem_step_dt(dem, -1), FSDEM_ERR_INVALID_ARG, "dt must be > 0");
    ck_assert(fsdem_dem_time(dem) == t0);

    /* indices */
    expect_error(dem, fsdem_dem_remove_particle(dem, -1), FSDEM_ERR_NOT_FOUND, "index");
    expect_error(dem, fsdem_dem_remove_particle(dem, 1), FSDEM_ERR_NOT_FOUND, "index"); /* one particle */
    expect_error(dem, fsdem_dem_set_particle_state(dem, 3, fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0)),
                 FSDEM_ERR_NOT_FOUND, "index");
    expect_error(dem, fsdem_dem_set_particle_state(dem, -1, fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0)),
                 FSDEM_ERR_NOT_FOUND, "index");
    p = fsdem_dem_get_particles(dem);
    {
        const fsdem_vec3 x0 = p.position[0];
        expect_error(dem, fsdem_dem_set_particle_state(dem, 0, fsdem_v3(0, 0, 0), fsdem_v3(NAN, 0, 0), fsdem_v3(0, 0, 0)),
                     FSDEM_ERR_INVALID_ARG, "velocity");
        expect_error(dem, fsdem_dem_set_particle_state(dem, 0, fsdem_v3(0, 3, 0), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0)),
                     FSDEM_ERR_OUT_OF_DOMAIN, "position");
        p = fsdem_dem_get_particles(dem);
        ck_assert(p.position[0].x == x0.x && p.position[0].y == x0.y && p.position[0].z == x0.z);
    }
    expect_usable(dem, mat);

    /* a NaN external force is a result, naming the particle; removing it lets the run go on */
    ck_assert_int_eq(fsdem_dem_get_coupling(dem).count, 2);
    fsdem_dem_get_coupling(dem).force[1].x = NAN;
    expect_error(dem, fsdem_dem_step(dem), FSDEM_ERR_NAN, "particle 1");
    ck_assert_int_eq(fsdem_dem_remove_particle(dem, 1), FSDEM_OK);
    step_n(dem, 3);
    p = fsdem_dem_get_particles(dem);
    ck_assert_int_eq(p.count, 1);
    /* every component of every particle's state, forces and loads is finite again */
    for (i = 0; i < p.count; ++i)
        ck_assert_msg(test_finite3(p.position[i]) && test_finite3(p.velocity[i]) && test_finite3(p.angular_velocity[i]) &&
                          test_finite3(p.force[i]) && test_finite3(p.torque[i]) && test_finite3(p.external_force[i]) &&
                          test_finite3(p.external_torque[i]),
                      "particle %d is not finite after the NaN one was removed", i);
    fsdem_dem_destroy(dem);
}
END_TEST

/* A particle thrown out of an open domain: the step completes, returns FSDEM_ERR_OUT_OF_DOMAIN
   and names it; after removing it the simulation goes on. */
START_TEST(particle_leaving_domain_is_reported) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem;
    fsdem_result res = FSDEM_OK;
    fsdem_dem_particles p;
    int mat, s;
    d.dt = 1e-3;
    dem = dem_new(&d);
    mat = add_plain_material(dem);
    add_particle(dem, fsdem_v3(-0.5, 0, 0), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), 0.01, mat, 0);
    add_particle(dem, fsdem_v3(0.5, 0, 0), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), 0.01, mat, 0);
    add_particle(dem, fsdem_v3(0, 0, 0), fsdem_v3(3, 0, 5), fsdem_v3(0, 0, 0), 0.01, mat, 0);
    /* the thrown particle (index 2) crosses z = 1 after ~0.27 s; the others fall 0.37 m in that
       time and stay inside */
    for (s = 0; s < 1000 && res == FSDEM_OK; ++s) res = fsdem_dem_step(dem);
    expect_error(dem, res, FSDEM_ERR_OUT_OF_DOMAIN, "particle 2");
    p = fsdem_dem_get_particles(dem);
    ck_assert(p.position[2].z > 1); /* the step completed: the particle is outside */
    ck_assert(fabs(p.position[0].z) < 1 && fabs(p.position[1].z) < 1);
    /* s steps of the dt in force (1e-3 rounded to fsdem_real), summed in double */
    ck_assert(fabs(fsdem_dem_time(dem) - s * (double)fsdem_dem_get_desc(dem).dt) < 1e-9);
    ck_assert_int_eq(fsdem_dem_remove_particle(dem, 2), FSDEM_OK);
    step_n(dem, 10);
    fsdem_dem_destroy(dem);
}
END_TEST

/* ---- 7. contact history across rebuilds and removals ---------------------------------------------- */

/* Spheres held by static friction (rotation off, so they can only stick or slide): S1 rests on a
   fixed sphere with the contact normal tilted by beta, S2 on a plane tilted by theta. Their
   tangential springs carry m g sin. A far fixed particle moves all along, so the lists are rebuilt
   every ~75 steps; then another far particle with a lower index is removed (all indices shift)
   and the moving one is teleported (two forced rebuilds). If a rebuild dropped a spring, the sphere would slide by the spring's stretch
   xi = m g sin / S_t before sticking again (and again at every rebuild). */
START_TEST(contact_history_survives_rebuilds_and_removal) {
    const double rho = 2500, young = 1e7, nu = 0.3, r = 0.01, rb = 0.03, mu = 0.5;
    const double theta = 10 * PI / 180, beta = 12 * PI / 180;
    const double gstar = young / (4 * (2 - nu) * (1 + nu)); /* 1/G* = 2 * 2(2-nu)(1+nu)/E */
    const double estar = hertz_estar(young, nu);
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem;
    fsdem_dem_particles p;
    fsdem_vec3 n_plane = fsdem_v3(-sin(theta), 0, cos(theta)), plane_point = fsdem_v3(0, 0, -0.5);
    fsdem_vec3 big = fsdem_v3(0.3, 0, 0), s1_before, s2_before, x;
    int mat, i, i_s1, i_s2, id_s1, id_s2, i_f1;
    long long rebuilds_before;
    double m = sphere_mass(rho, r), r_eff_b = r * rb / (r + rb), delta1, delta2, xi1, xi2, disp1, disp2;
    d.dt = 5e-5;
    d.rotation = 0;
    dem = dem_new(&d);
    mat = add_material(dem, rho, young, nu, 0.5, mu, 0.4);
    add_wall(dem, fsdem_dem_wall_plane(plane_point, n_plane, mat));
    /* 0: far fixed particle, removed later */
    add_particle(dem, fsdem_v3(0.6, 0.6, 0.6), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), r, mat, 1);
    /* 1: fixed big sphere; 2: S1 on top of it, normal tilted by beta (tan beta = 0.21 < mu) */
    add_particle(dem, big, fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), rb, mat, 1);
    delta1 = hertz_static_overlap(m * G * cos(beta), r_eff_b, estar);
    x = vadd(big, vscale(fsdem_v3(sin(beta), 0, cos(beta)), rb + r - delta1));
    i_s1 = add_particle(dem, x, fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), r, mat, 0);
    /* 3: S2 on the plane (tan theta = 0.18 < mu) */
    delta2 = hertz_static_overlap(m * G * cos(theta), r, estar);
    x = vadd(vadd(plane_point, vscale(fsdem_v3(cos(theta), 0, sin(theta)), -0.3)), vscale(n_plane, r - delta2));
    i_s2 = add_particle(dem, x, fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), r, mat, 0);
    /* 4: far fixed particle moving at 1 m/s: its displacement triggers a rebuild every
       skin / (2 v dt) = 0.0075 / (2 * 5e-5) = 75 steps */
    i_f1 = add_particle(dem, fsdem_v3(-0.6, 0.6, 0.6), fsdem_v3(0, -1, 0), fsdem_v3(0, 0, 0), r, mat, 1);
    p = fsdem_dem_get_particles(dem);
    id_s1 = p.id[i_s1];
    id_s2 = p.id[i_s2];
    ck_assert_int_eq(i_f1, 4);
    /* settle: the tangential transients decay in a few ms (Tsuji damping with e = 0.5) */
    step_n(dem, 4000);
    p = fsdem_dem_get_particles(dem);
    s1_before = p.position[i_s1];
    s2_before = p.position[i_s2];
    /* at rest: the initial stick-in transient (speed ~ xi omega ~ 5e-3 m/s) has decayed by
       e^-50 or more; a sphere still creeping would move ~1e-6 m/s x 0.15 s, above the bound below.
       In float a position is known to one ulp, eps |x| (7e-8 m at |x| ~ 0.6 m), and a sphere on a
       Hertz spring of frequency omega = sqrt(1.5 g / delta) (~700 rad/s) jitters at omega eps |x|
       (measured 1.4e-4 m/s on the plane): the bound is 4 omega eps |x| there (double: 1e-6 kept;
       the displacement checks below still catch a creep). */
    {
        const double w1 = sqrt(1.5 * G * cos(beta) / delta1), w2 = sqrt(1.5 * G * cos(theta) / delta2);
        ck_assert_msg(vnorm(p.velocity[i_s1]) < TOL(1e-6, 4 * w1 * vnorm(s1_before)) &&
                          vnorm(p.velocity[i_s2]) < TOL(1e-6, 4 * w2 * vnorm(s2_before)),
                      "not at rest: %g, %g m/s", vnorm(p.velocity[i_s1]), vnorm(p.velocity[i_s2]));
    }
    rebuilds_before = fsdem_dem_get_stats(dem).rebuilds;

    ck_assert_int_eq(fsdem_dem_remove_particle(dem, 0), FSDEM_OK);
    p = fsdem_dem_get_particles(dem);
    i_s1 = i_s2 = -1;
    for (i = 0; i < p.count; ++i) {
        if (p.id[i] == id_s1) i_s1 = i;
        if (p.id[i] == id_s2) i_s2 = i;
    }
    ck_assert_int_eq(i_s1, 1); /* indices shifted down by one */
    ck_assert_int_eq(i_s2, 2);
    step_n(dem, 1500);
    p = fsdem_dem_get_particles(dem);
    ck_assert_int_eq(fsdem_dem_set_particle_state(dem, 3, fsdem_v3(-0.6, 0.5, 0.2), p.velocity[3], fsdem_v3(0, 0, 0)),
                     FSDEM_OK);
    step_n(dem, 1500);
    p = fsdem_dem_get_particles(dem);
    disp1 = vnorm(vsub(p.position[i_s1], s1_before));
    disp2 = vnorm(vsub(p.position[i_s2], s2_before));
    /* spring stretch carrying the load: S_t = 8 G* sqrt(R* d) (Mindlin, seed 002 Eq. 20) */
    xi1 = m * G * sin(beta) / (8 * gstar * sqrt(r_eff_b * delta1));
    xi2 = m * G * sin(theta) / (8 * gstar * sqrt(r * delta2));
    REPORT("history: %lld rebuilds after settling; displacement / spring stretch: %.2e (on sphere), %.2e (on plane); "
           "stretch %.2e m, %.2e m",
           fsdem_dem_get_stats(dem).rebuilds - rebuilds_before, disp1 / xi1, disp2 / xi2, xi1, xi2);
    ck_assert_int_ge(fsdem_dem_get_stats(dem).rebuilds - rebuilds_before, 10);
    ck_assert_int_eq(fsdem_dem_get_stats(dem).contacts, 1);
    ck_assert_int_eq(fsdem_dem_get_stats(dem).wall_contacts, 1);
    /* Sticking spheres are in static equilibrium: with the history kept they do not move at all
       (up to rounding); losing it once would move them by ~xi (the spring must re-stretch), so a
       tenth of xi separates the two cases by an order of magnitude. */
    ck_assert_msg(disp1 < 0.1 * xi1, "sphere on sphere moved %g m (spring stretch %g m)", disp1, xi1);
    ck_assert_msg(disp2 < 0.1 * xi2, "sphere on plane moved %g m (spring stretch %g m)", disp2, xi2);
    fsdem_dem_destroy(dem);
}
END_TEST

/* ---- 8. subcycling (seed 000 Eq. 25) ------------------------------------------------------------- */

/* Advances by dt_outer with dt; checks the substep count, the time and the state of a particle
   under a constant external force (Verlet is exact for constant forces, so any substep split must
   give v = F t / m and x = F t^2 / (2m)). */
static void advance_case(double dt, double dt_outer, int expected_k) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem;
    fsdem_dem_particles p;
    fsdem_result res;
    int mat;
    long long steps, k = -1;
    double t0, m, force = 0.5, t, dt_after, v, x;
    d.gravity = fsdem_v3(0, 0, 0);
    d.dt = dt;
    dem = dem_new(&d);
    mat = add_plain_material(dem);
    add_particle(dem, fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), 0.01, mat, 0);
    step_n(dem, 3); /* start from a non-zero time */
    p = fsdem_dem_get_particles(dem);
    m = p.mass[0];
    fsdem_dem_get_coupling(dem).force[0] = fsdem_v3(force, 0, 0);
    t0 = fsdem_dem_time(dem);
    steps = fsdem_dem_get_stats(dem).steps;
    res = fsdem_dem_advance(dem, dt_outer, &k);
    t = fsdem_dem_time(dem) - t0;
    steps = fsdem_dem_get_stats(dem).steps - steps;
    dt_after = fsdem_dem_get_stats(dem).dt;
    p = fsdem_dem_get_particles(dem);
    v = p.velocity[0].x;
    x = p.position[0].x;
    /* destroyed before the checks, so a failure does not leak under CK_FORK=no (make valgrind) */
    fsdem_dem_destroy(dem);
    REPORT("advance dt_outer = %g with dt = %g: K = %lld (expected %d), %lld steps, time advanced %.17g", dt_outer, dt, k,
           expected_k, steps, t);
    ck_assert_int_eq(res, FSDEM_OK);
    ck_assert_msg(k == expected_k, "dt_outer/dt = %g: K = %lld, expected INT(%g) = %d", dt_outer / dt, k, dt_outer / dt,
                  expected_k);
    ck_assert_int_eq(steps, expected_k);
    /* K additions of dt_outer/K to the clock: exact up to K roundings of the sum (float: the
       duration and dt_outer/K are rounded to fsdem_real, eps dt_outer each at most) */
    ck_assert_msg(fabs(t - dt_outer) <= TOL(4 * expected_k * 2.3e-16 * (t0 + dt_outer), 2 * dt_outer), "time advanced by %.17g",
                  t);
    ck_assert(dt_after == (fsdem_real)dt); /* the user's dt is kept for later steps */
    /* the external force is held over all substeps (Verlet is exact for a constant force, up to
       rounding: in float each of the K kicks and drifts rounds v and x, K eps relative, plus a few
       for F / m and the rounded substep) */
    ck_assert(fabs(v - force / m * dt_outer) < TOL(1e-12, expected_k + 4) * force / m * dt_outer);
    ck_assert(fabs(x - 0.5 * force / m * dt_outer * dt_outer) < TOL(1e-12, 2 * expected_k + 4) * force / m * dt_outer * dt_outer);
}

START_TEST(advance_subcycles_like_seed000) {
    advance_case(1e-3, 3.5e-3, 3);  /* K = INT(3.5) = 3 substeps of 3.5e-3/3 */
    advance_case(1e-3, 0.99e-3, 1); /* dt > dt_outer: one substep of dt_outer (Eq. 25) */
    advance_case(1e-3, 0.4e-3, 1);
    advance_case(2e-3, 6e-3, 3);
    advance_case(1e-3, 20e-3, 20);
    /* dt_outer an exact multiple of dt in decimal: INT(3e-4 / 1e-4) = 3; a floating-point quotient
       of 2.9999999999999996 must not turn into K = 2 (substeps 1.5 dt, beyond the stable dt) */
    advance_case(1e-4, 3e-4, 3);
}
END_TEST

/* A gravity-free box of dense, damped, frictional Hertz spheres, shaken with random velocities and
   spins: many contacts that touch, slide and separate. */
static fsdem_dem *shaken_box(int *box) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem;
    const double L = 0.05, r = 0.004;
    int mat, i, j, k;
    d.domain_min = fsdem_v3(0, 0, 0);
    d.domain_max = fsdem_v3(L, L, L);
    d.dt = 2e-6;
    dem = dem_new(&d);
    mat = add_material(dem, 2500, 1e7, 0.3, 0.7, 0.4, 0.4);
    *box = add_wall(dem, fsdem_dem_wall_box(fsdem_v3(0, 0, 0), fsdem_v3(L, L, L), 1, mat));
    rng_seed(77);
    for (k = 0; k < 5; ++k)
        for (j = 0; j < 5; ++j)
            for (i = 0; i < 5; ++i)
                add_particle(dem, fsdem_v3(0.005 + 0.0085 * i, 0.005 + 0.0085 * j, 0.005 + 0.0085 * k),
                             fsdem_v3(urange(-1, 1), urange(-1, 1), urange(-1, 1)),
                             fsdem_v3(urange(-200, 200), urange(-200, 200), urange(-200, 200)), r, mat, 0);
    return dem;
}

/* fsdem_dem_advance runs its Verlet substeps as leapfrog (one pass per substep); it must give the
   state of as many fsdem_dem_step calls. The two differ only in rounding (one kick of h instead of
   two of h/2), which the collisions amplify; 1e-9 of the scale over 600 steps is far above that
   and far below any error of the integration itself (a missed half kick changes velocities by
   g_contact h / 2, of order 1e-2 of the scale here).
   Float: the two runs part by ~0.5 eps of the scale per step (measured 6e-8 m/s per step), until a
   frictional contact reaches its Coulomb limit one step earlier in one run than in the other: from
   then on they part at the rate of a stick-slip switch (measured 2.4e-5 m/s after 400 steps, then
   1.7e-2 m/s and 10 rad/s by 600 steps), as large as the missed half kick the check must catch. So
   float brings both boxes into the wall collisions with the same 450 fsdem_dem_step calls
   (bit-identical states) and compares the next 150 steps, to where the double run ends, with 4 eps
   of the scale per step (600 eps = 7e-5; measured 74 eps of the velocity, 33 of the spin and 42 of
   the wall impulse). */
START_TEST(advance_equals_steps) {
    const int warm = TEST_FLOAT ? 450 : 0, steps = TEST_FLOAT ? 150 : 600;
    const double tol = TOL(1e-9, 4.0 * steps);
    fsdem_dem *a, *b;
    fsdem_dem_particles pa, pb;
    fsdem_vec3 ja, jb;
    int box_a, box_b, i, k, contacts = 0;
    long long n;
    double dx = 0, dv = 0, dw = 0;
    a = shaken_box(&box_a);
    b = shaken_box(&box_b);
    for (k = 0; k < warm; ++k) {
        ck_assert_int_eq(fsdem_dem_step(a), FSDEM_OK);
        ck_assert_int_eq(fsdem_dem_step(b), FSDEM_OK);
    }
    ja = fsdem_dem_wall_impulse(a, box_a);
    for (k = 0; k < steps; ++k) {
        ck_assert_int_eq(fsdem_dem_step(a), FSDEM_OK);
        contacts += fsdem_dem_get_stats(a).contacts;
    }
    ck_assert_int_eq(fsdem_dem_advance(b, (fsdem_real)(steps * 2e-6), &n), FSDEM_OK);
    pa = fsdem_dem_get_particles(a);
    pb = fsdem_dem_get_particles(b);
    for (i = 0; i < pa.count; ++i) {
        dx = fmax(dx, vnorm(vsub(pa.position[i], pb.position[i])));
        dv = fmax(dv, vnorm(vsub(pa.velocity[i], pb.velocity[i])));
        dw = fmax(dw, vnorm(vsub(pa.angular_velocity[i], pb.angular_velocity[i])));
    }
    ck_assert_msg(warm == 0 || vnorm(vsub(fsdem_dem_wall_impulse(a, box_a), ja)) > 0, "no wall contact in the window");
    ja = fsdem_dem_wall_impulse(a, box_a);
    jb = fsdem_dem_wall_impulse(b, box_b);
    REPORT("advance vs steps: %lld substeps, %d contact-steps; max |dx| %.2e m, |dv| %.2e m/s, |dw| %.2e rad/s, "
           "wall impulse %.2e of %.2e N s",
           n, contacts, dx, dv, dw, vnorm(vsub(ja, jb)), vnorm(ja));
    ck_assert_int_eq(n, steps);
    /* the substep of b is the duration / steps rounded to fsdem_real: eps of the time at most */
    ck_assert(fsdem_dem_get_stats(b).steps == warm + steps &&
              fabs(fsdem_dem_time(a) - fsdem_dem_time(b)) < TOL(1e-15, 2 * fsdem_dem_time(a)));
    ck_assert_msg(contacts > steps * 10, "the test needs contacts (%d contact-steps)", contacts);
    ck_assert_msg(dx < tol * 0.05 && dv < tol * 1 && dw < tol * 200, "dx %g dv %g dw %g", dx, dv, dw);
    ck_assert(vnorm(vsub(ja, jb)) < tol * vnorm(ja));
    fsdem_dem_destroy(a);
    fsdem_dem_destroy(b);
}
END_TEST

/* A particle that leaves the domain stops fsdem_dem_advance at that substep, with the step
   complete and the particle named, as fsdem_dem_step does. */
START_TEST(advance_stops_where_a_particle_leaves) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem;
    fsdem_result res;
    int mat;
    d.gravity = fsdem_v3(0, 0, 0);
    d.domain_min = fsdem_v3(0, 0, 0);
    d.domain_max = fsdem_v3(1, 1, 1);
    d.dt = 1e-3;
    dem = dem_new(&d);
    mat = add_plain_material(dem);
    add_particle(dem, fsdem_v3(0.5, 0.5, 0.5), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), 0.01, mat, 0);
    /* 0.9455 m at 1 m/s: out after 945 or 946 steps */
    add_particle(dem, fsdem_v3(0.2, 0.2, 0.0545), fsdem_v3(0, 0, 1), fsdem_v3(0, 0, 0), 0.01, mat, 0);
    res = fsdem_dem_advance(dem, 2.0, NULL);
    REPORT("advance stopped after %lld steps: %s", fsdem_dem_get_stats(dem).steps, fsdem_dem_last_error(dem));
    ck_assert_int_eq(res, FSDEM_ERR_OUT_OF_DOMAIN);
    ck_assert(fsdem_dem_get_stats(dem).steps >= 945 && fsdem_dem_get_stats(dem).steps <= 946);
    ck_assert_ptr_nonnull(strstr(fsdem_dem_last_error(dem), "particle 1"));
    /* the step is complete: the velocity is the full-step one, unchanged by the free flight */
    ck_assert(fabs(fsdem_dem_get_particles(dem).velocity[1].z - 1) < 1e-12);
    fsdem_dem_destroy(dem);
}
END_TEST

/* ---- 9. time-step estimates ---------------------------------------------------------------------- */

/* A DEM of desc `d` with one material (density, E, nu) and particles of the given radii; the
   stable dt of its rule goes to *dt. */
static fsdem_result rule_dt(fsdem_dem_desc d, const double *radii, const int *steel, int n, fsdem_real *dt) {
    fsdem_dem *dem = dem_new(&d);
    int m1 = add_plain_material(dem), m2 = add_material(dem, 7800, 2e11, 0.28, 1.0, 0.3, 0.4), i;
    fsdem_result res;
    for (i = 0; i < n; ++i)
        add_particle(dem, fsdem_v3(-0.5 + 0.1 * i, 0, 0), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), radii[i],
                     steel && steel[i] ? m2 : m1, 0);
    res = fsdem_dem_stable_dt(dem, dt);
    fsdem_dem_destroy(dem);
    return res;
}

START_TEST(dt_estimates_follow_their_formulas) {
    const double radii[4] = {0.01, 0.005, 0.02, 0.004};
    const int steel[4] = {0, 0, 1, 1};
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    char msg[256];
    fsdem_real dt;
    int i;
    double expected, best;
    /* seed 000 Eq. 18 with Eq. 10: (2 pi / gamma) sqrt(m_ij / k) = (2 pi / gamma) sqrt(theta dx / ||g||) */
    d.law = FSDEM_DEM_LAW_LINEAR;
    d.linear_theta = 0.01;
    d.linear_dx = 0.004;
    ck_assert_int_eq(rule_dt(d, radii, NULL, 0, &dt), FSDEM_ERR_NOT_FOUND);
    ck_assert_int_eq(rule_dt(d, radii, NULL, 2, &dt), FSDEM_OK); /* AUTO: Eq. 18 with gamma = 150 */
    expected = 2 * PI / 150 * sqrt(0.01 * 0.004 / G);
    REPORT("dt LINEAR_SEED000: %.10g, expected %.10g", (double)dt, expected);
    /* closed form: rounding only (float: the library's ~8 roundings of fsdem_real inputs, 16 eps) */
    ck_assert(fabs(dt / expected - 1) < TOL(1e-12, 16));
    d.linear_accel = 4 * G; /* ||g|| of Eq. 10 set explicitly */
    d.dt_rule = FSDEM_DEM_DT_RULE_LINEAR_SEED000;
    d.dt_param = 100;
    ck_assert_int_eq(rule_dt(d, radii, NULL, 1, &dt), FSDEM_OK);
    expected = 2 * PI / 100 * sqrt(0.01 * 0.004 / (4 * G));
    ck_assert(fabs(dt / expected - 1) < TOL(1e-12, 16));

    /* Rayleigh (seed 002 Eq. 38 with the Thornton-Randall coefficient) and GIC (seed 004 Eq. 32),
       minimum over particles of two materials and several radii */
    d = fsdem_dem_desc_default(3);
    ck_assert_int_eq(rule_dt(d, radii, steel, 4, &dt), FSDEM_OK); /* AUTO for Hertz: Rayleigh x 0.2 */
    best = HUGE_VAL;
    for (i = 0; i < 4; ++i) {
        const double rho = steel[i] ? 7800 : 2500, e = steel[i] ? 2e11 : 1e7, nu = steel[i] ? 0.28 : 0.3;
        const double t = PI * radii[i] * sqrt(2 * rho * (1 + nu) / e) / (0.1631 * nu + 0.8766);
        if (t < best) best = t;
    }
    REPORT("dt RAYLEIGH(0.2): %.10g, expected %.10g", (double)dt, 0.2 * best);
    ck_assert(fabs(dt / (0.2 * best) - 1) < TOL(1e-12, 16));
    d.dt_param = 1.5;
    ck_assert_int_eq(fsdem_dem_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(msg, "dt_param"));
    d.dt_rule = FSDEM_DEM_DT_RULE_LINEAR_SEED000;
    d.dt_param = 0;
    ck_assert_int_eq(fsdem_dem_desc_check(&d, msg, sizeof msg), FSDEM_ERR_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(msg, "linear law"));
    d.dt_rule = FSDEM_DEM_DT_RULE_GIC;
    ck_assert_int_eq(rule_dt(d, radii, steel, 4, &dt), FSDEM_OK);
    best = HUGE_VAL;
    for (i = 0; i < 4; ++i) {
        const double e = steel[i] ? 2e11 : 1e7, rho = steel[i] ? 7800 : 2500;
        const double t = 0.5 * sqrt(rho * 4.0 / 3.0 * PI * pow(radii[i], 3) / (e * radii[i]));
        if (t < best) best = t;
    }
    REPORT("dt GIC: %.10g, expected %.10g", (double)dt, best);
    ck_assert(fabs(dt / best - 1) < TOL(1e-12, 16));
}
END_TEST

/* ---- 10. masses ---------------------------------------------------------------------------------- */

START_TEST(particle_masses) {
    fsdem_dem_desc d = fsdem_dem_desc_default(2);
    fsdem_dem *dem;
    fsdem_dem_particles p;
    int mat;
    d.disc_length = 0.05;
    dem = dem_new(&d);
    mat = add_material(dem, 2650, 1e7, 0.3, 1.0, 0.3, 0.4);
    add_particle(dem, fsdem_v3(0, 0, 0.3), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), 0.012, mat, 0);
    p = fsdem_dem_get_particles(dem);
    /* a disc of length disc_length: rho pi r^2 L */
    /* closed form: rounding only (float: rho, r, L and the products rounded to fsdem_real, 8 eps) */
    ck_assert(fabs(p.mass[0] / (2650 * PI * 0.012 * 0.012 * 0.05) - 1) < TOL(1e-14, 8));
    ck_assert(p.position[0].z == 0); /* 2D particles live in the x-y plane */
    fsdem_dem_destroy(dem);
    d = fsdem_dem_desc_default(3);
    dem = dem_new(&d);
    mat = add_material(dem, 2650, 1e7, 0.3, 1.0, 0.3, 0.4);
    add_particle(dem, fsdem_v3(0, 0, 0.3), fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 0), 0.012, mat, 0);
    p = fsdem_dem_get_particles(dem);
    ck_assert(fabs(p.mass[0] / (2650 * 4.0 / 3.0 * PI * 0.012 * 0.012 * 0.012) - 1) < TOL(1e-14, 8));
    fsdem_dem_destroy(dem);
}
END_TEST

Suite *dem_suite(void) {
    Suite *s = suite_create("dem");
    TCase *tc_geom = tcase_create("neighbours");
    TCase *tc_cons = tcase_create("conservation");
    TCase *tc_laws = tcase_create("contact_laws");
    TCase *tc_api = tcase_create("api");
    tcase_add_test(tc_geom, neighbour_lists_match_brute_force);
    tcase_add_test(tc_geom, touching_pairs_raise_no_fp_exceptions);
    tcase_add_test(tc_geom, contact_history_survives_rebuilds_and_removal);
    tcase_set_timeout(tc_geom, 300);
    tcase_add_test(tc_cons, elastic_box_conserves_momentum_and_energy);
    tcase_set_timeout(tc_cons, 600);
    tcase_add_test(tc_laws, hertz_restitution_matches_input);
    tcase_add_test(tc_laws, linear_restitution_matches_damped_oscillator);
    tcase_add_test(tc_laws, incline_rolling_and_sliding);
    tcase_add_test(tc_laws, resting_particle_settles_to_static_overlap);
    tcase_add_test(tc_laws, mesh_edges_and_vertices_push_once);
    tcase_add_test(tc_laws, moving_sdf_wall_reaches_resting_particles);
    tcase_set_timeout(tc_laws, 300);
    tcase_add_test(tc_api, invalid_desc_is_rejected);
    tcase_add_test(tc_api, invalid_material_and_particle_are_rejected);
    tcase_add_test(tc_api, invalid_walls_and_calls_are_rejected);
    tcase_add_test(tc_api, particle_leaving_domain_is_reported);
    tcase_add_test(tc_api, advance_subcycles_like_seed000);
    tcase_add_test(tc_api, advance_equals_steps);
    tcase_add_test(tc_api, advance_stops_where_a_particle_leaves);
    tcase_add_test(tc_api, dt_estimates_follow_their_formulas);
    tcase_add_test(tc_api, particle_masses);
    tcase_set_timeout(tc_api, 120);
    suite_add_tcase(s, tc_geom);
    suite_add_tcase(s, tc_cons);
    suite_add_tcase(s, tc_laws);
    suite_add_tcase(s, tc_api);
    return s;
}
