/* Cross-compiler determinism: each solver (DEM, PIC, SWE, MPS) and each coupler (SWE-DEM, MPS-DEM,
   PIC-DEM) runs a small scene and prints a hash of its complete saved state (fsdem_X_save_memory; a
   coupler's holds its solvers' states). `make determinism` builds this program with gcc and clang at -O0,
   -O2, -O2 -march=native and -O2 -DFSDEM_NO_SIMD and checks every build prints the pinned hashes of
   tests/determinism.expected: the results do not depend on the compiler, the optimisation level or
   the SIMD lane width (the DEM contact kernel runs 1, 2, 4 or 8 contacts per instruction).
   Usage: determinism            print "<solver> <hash>" lines */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <stdio.h>
#include <stdlib.h>

/* 64-bit FNV-1a of a buffer. */
static unsigned long long hash_bytes(const unsigned char *p, size_t n) {
    unsigned long long h = 1469598103934665603ULL;
    size_t k;
    for (k = 0; k < n; ++k) h = (h ^ p[k]) * 1099511628211ULL;
    return h;
}

typedef fsdem_result (*save_fn)(const void *object, void *buffer, size_t capacity, size_t *size);

static fsdem_result save_dem(const void *o, void *b, size_t c, size_t *s) { return fsdem_dem_save_memory((const fsdem_dem *)o, b, c, s); }
static fsdem_result save_pic(const void *o, void *b, size_t c, size_t *s) { return fsdem_pic_save_memory((const fsdem_pic *)o, b, c, s); }
static fsdem_result save_swe(const void *o, void *b, size_t c, size_t *s) { return fsdem_swe_save_memory((const fsdem_swe *)o, b, c, s); }
static fsdem_result save_mps(const void *o, void *b, size_t c, size_t *s) { return fsdem_mps_save_memory((const fsdem_mps *)o, b, c, s); }
static fsdem_result save_swe_dem(const void *o, void *b, size_t c, size_t *s) {
    return fsdem_swe_dem_save_memory((const fsdem_swe_dem *)o, b, c, s);
}
static fsdem_result save_mps_dem(const void *o, void *b, size_t c, size_t *s) {
    return fsdem_mps_dem_save_memory((const fsdem_mps_dem *)o, b, c, s);
}
static fsdem_result save_pic_dem(const void *o, void *b, size_t c, size_t *s) {
    return fsdem_pic_dem_save_memory((const fsdem_pic_dem *)o, b, c, s);
}

static fsdem_result save_gic(const void *o, void *b, size_t c, size_t *s) { return fsdem_gic_save_memory((const fsdem_gic *)o, b, c, s); }

static int print_hash(const char *name, const void *object, save_fn save) {
    size_t size = 0;
    unsigned char *buf;
    if (save(object, NULL, 0, &size) != FSDEM_OK) return 1;
    buf = (unsigned char *)malloc(size);
    if (!buf || save(object, buf, size, &size) != FSDEM_OK) return 1;
    printf("%s %016llx\n", name, hash_bytes(buf, size));
    free(buf);
    return 0;
}

/* 150 Hertz-Mindlin spheres of two sizes poured into a box: contacts with history, walls, rebuilds. */
static int dem_scene(void) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_wall_desc w;
    fsdem_dem *dem;
    int mat, i, bad;
    d.domain_min = fsdem_v3(-0.06, -0.06, -0.01);
    d.domain_max = fsdem_v3(0.06, 0.06, 0.3);
    d.dt = 2e-5;
    if (fsdem_dem_create(&d, &dem) != FSDEM_OK) return 1;
    m.friction = (fsdem_real)0.4;
    m.rolling_friction = (fsdem_real)0.02;
    fsdem_dem_add_material(dem, &m, &mat);
    w = fsdem_dem_wall_box(fsdem_v3(-0.05, -0.05, 0), fsdem_v3(0.05, 0.05, 0.25), 1, mat);
    fsdem_dem_add_wall(dem, &w, NULL);
    for (i = 0; i < 150; ++i) {
        fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
        p.radius = (fsdem_real)(i % 2 ? 0.006 : 0.0045);
        p.position = fsdem_v3((fsdem_real)(-0.035 + 0.014 * (i % 6)), (fsdem_real)(-0.035 + 0.014 * (i / 6 % 6)),
                              (fsdem_real)(0.01 + 0.014 * (i / 36)));
        p.velocity = fsdem_v3((fsdem_real)(0.1 * ((i * 37) % 11 - 5)), (fsdem_real)(0.1 * ((i * 53) % 7 - 3)), 0);
        p.material = mat;
        fsdem_dem_add_particle(dem, &p, NULL);
    }
    bad = fsdem_dem_advance(dem, 0.05, NULL) != FSDEM_OK || print_hash("dem", dem, save_dem);
    fsdem_dem_destroy(dem);
    return bad;
}

/* 8,000 spheres of two materials settling in a box, enough pairs for the threaded contact kernels
   (their batches evaluated in parallel, the forces added by each particle's owner) and the threaded
   Verlet passes. */
static int dem_bulk_scene(void) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_wall_desc w;
    fsdem_dem *dem;
    int mat[2], i, bad;
    d.domain_min = fsdem_v3(-0.01, -0.01, -0.01);
    d.domain_max = fsdem_v3(0.05, 0.05, 0.08);
    d.dt = 5e-6;
    if (fsdem_dem_create(&d, &dem) != FSDEM_OK) return 1;
    m.friction = (fsdem_real)0.4;
    m.rolling_friction = (fsdem_real)0.02;
    fsdem_dem_add_material(dem, &m, &mat[0]);
    m.young_modulus *= 2;
    m.friction = (fsdem_real)0.2;
    fsdem_dem_add_material(dem, &m, &mat[1]);
    w = fsdem_dem_wall_box(fsdem_v3(0, 0, 0), fsdem_v3(0.042, 0.042, 0.07), 1, mat[0]);
    fsdem_dem_add_wall(dem, &w, NULL);
    for (i = 0; i < 8000; ++i) {
        fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
        const unsigned u = (unsigned)i * 2654435761u;
        p.radius = (fsdem_real)(i % 3 ? 0.001 : 0.0009);
        p.position = fsdem_v3((fsdem_real)(0.00105 + 0.0021 * (i % 20) + 1e-5 * (u % 7)),
                              (fsdem_real)(0.00105 + 0.0021 * (i / 20 % 20) + 1e-5 * (u / 7 % 7)),
                              (fsdem_real)(0.00105 + 0.0021 * (i / 400)));
        p.velocity = fsdem_v3((fsdem_real)(0.01 * ((u >> 8) % 11) - 0.05), 0, (fsdem_real)-0.3);
        p.material = mat[i % 2];
        fsdem_dem_add_particle(dem, &p, NULL);
    }
    bad = fsdem_dem_advance(dem, 0.003, NULL) != FSDEM_OK || print_hash("dem_bulk", dem, save_dem);
    fsdem_dem_destroy(dem);
    return bad;
}

/* A 2D FLIP dam break with an obstacle: transfers, reseeding (random draws), projections. */
static int pic_scene(void) {
    fsdem_pic_desc d = fsdem_pic_desc_default(2);
    fsdem_pic_obstacle ob = fsdem_pic_obstacle_box(fsdem_v3(0.6, 0, 0), fsdem_v3(0.7, 0.15, 0));
    fsdem_pic *pic;
    int k, bad = 0;
    d.cell_size = (fsdem_real)(1.0 / 48);
    if (fsdem_pic_create(&d, &pic) != FSDEM_OK) return 1;
    fsdem_pic_add_obstacle(pic, &ob, NULL);
    fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3(0.3, 0.6, 0), fsdem_v3(0, 0, 0), NULL);
    for (k = 0; k < 40 && !bad; ++k) bad = fsdem_pic_step(pic) != FSDEM_OK;
    bad = bad || print_hash("pic", pic, save_pic);
    fsdem_pic_destroy(pic);
    return bad;
}

static void swe_initial(void *user, fsdem_real x, fsdem_real y, fsdem_swe_cell *c) {
    (void)user;
    c->bed = (fsdem_real)(0.05 * y * y);
    c->depth = x < 0.4 ? 1 : (fsdem_real)0.1;
    c->u = c->v = 0;
}

/* A 2D shallow-water dam break over an uneven bed with friction and a building. */
static int swe_scene(void) {
    fsdem_swe_desc d = fsdem_swe_desc_default(2);
    fsdem_swe *swe;
    int bad;
    d.nx = 64;
    d.ny = 32;
    d.y_max = (fsdem_real)0.5;
    d.manning = (fsdem_real)0.02;
    d.limiter = FSDEM_SWE_LIMITER_MC;
    if (fsdem_swe_create(&d, &swe) != FSDEM_OK) return 1;
    fsdem_swe_set_cells(swe, swe_initial, NULL);
    fsdem_swe_block_box(swe, (fsdem_real)0.6, (fsdem_real)0.2, (fsdem_real)0.7, (fsdem_real)0.3);
    bad = fsdem_swe_advance(swe, 0.5, NULL) != FSDEM_OK || print_hash("swe", swe, save_swe);
    fsdem_swe_destroy(swe);
    return bad;
}

/* A 2D MPS dam break (Model A): a column of 10 x 20 spacings in a walled tank of 40 x 30, 0.1 s:
   the pressure solve (MIC(0)-PCG), collisions, surface detection. */
static int mps_scene(void) {
    fsdem_mps_desc d = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_mps *mps;
    int bad;
    d.domain_min = fsdem_v3(-0.05, -0.05, 0);
    d.domain_max = fsdem_v3(0.45, 0.4, 0);
    if (fsdem_mps_create(&d, &mps) != FSDEM_OK) return 1;
    bad = fsdem_mps_add_box_walls(mps, fsdem_v3(0, 0, 0), fsdem_v3(0.4, 0.3, 0), 1u << FSDEM_SIDE_YMAX, NULL) != FSDEM_OK ||
          fsdem_mps_fill_box(mps, fsdem_v3(0, 0, 0), fsdem_v3(0.1, 0.2, 0), fsdem_v3(0, 0, 0), NULL) != FSDEM_OK ||
          fsdem_mps_advance(mps, 0.1, NULL) != FSDEM_OK || print_hash("mps", mps, save_mps);
    fsdem_mps_destroy(mps);
    return bad;
}

/* Adds `count` particles of radius r and material 0 in a row from `first` along `step`. */
static int add_row(fsdem_dem *dem, int count, fsdem_real r, fsdem_vec3 first, fsdem_vec3 step, fsdem_vec3 velocity) {
    int i;
    for (i = 0; i < count; ++i) {
        fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
        p.radius = r;
        p.position = fsdem_v3(first.x + i * step.x, first.y + i * step.y, first.z + i * step.z);
        p.velocity = velocity;
        if (fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK) return 1;
    }
    return 0;
}

/* Six light spheres carried by a 2D shallow-water dam break (Manning friction), 0.3 s: buoyancy
   refreshed in the substeps, hydrostatic and dynamic pressure, the reactions on the water. */
static int swe_dem_scene(void) {
    fsdem_swe_desc sd = fsdem_swe_desc_default(2);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_swe_dem_desc cd = fsdem_swe_dem_desc_default();
    fsdem_swe *swe = NULL;
    fsdem_dem *dem = NULL;
    fsdem_swe_dem *c = NULL;
    int bad;
    sd.nx = 48;
    sd.ny = 16;
    sd.x_max = 3;
    sd.manning = (fsdem_real)0.01;
    dd.domain_min = fsdem_v3(0, 0, -1);
    dd.domain_max = fsdem_v3(3, 1, 2);
    dd.dt = 1e-4;
    m.density = 400;
    cd.heave_damping = (fsdem_real)0.5;
    bad = fsdem_swe_create(&sd, &swe) != FSDEM_OK || fsdem_dem_create(&dd, &dem) != FSDEM_OK;
    if (!bad) {
        fsdem_swe_set_cells(swe, swe_initial, NULL);
        cd.swe = swe;
        cd.dem = dem;
        bad = fsdem_dem_add_material(dem, &m, NULL) != FSDEM_OK ||
              add_row(dem, 6, (fsdem_real)0.04, fsdem_v3(0.15, 0.2, 0.5), fsdem_v3(0.05, 0.12, 0.2), fsdem_v3(0.3, 0, 0)) ||
              fsdem_swe_dem_create(&cd, &c) != FSDEM_OK || fsdem_swe_dem_advance(c, 0.3, NULL) != FSDEM_OK ||
              print_hash("swe_dem", c, save_swe_dem);
    }
    fsdem_swe_dem_destroy(c);
    fsdem_dem_destroy(dem);
    fsdem_swe_destroy(swe);
    return bad;
}

/* Twelve sand discs falling into a 2D MPS tank (Model B, Ergun/Wen-Yu drag), 0.04 s: porosity,
   drag, the reactions (Eq. 36), DEM substeps and wall contacts. */
static int mps_dem_scene(void) {
    fsdem_mps_desc md = fsdem_mps_desc_default_scheme(2, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_wall_desc w;
    fsdem_mps_dem_desc cd = fsdem_mps_dem_desc_default();
    fsdem_mps *mps = NULL;
    fsdem_dem *dem = NULL;
    fsdem_mps_dem *c = NULL;
    int bad, mat = 0;
    md.model = FSDEM_MPS_MODEL_B;
    md.domain_min = fsdem_v3(-0.05, -0.05, 0);
    md.domain_max = fsdem_v3(0.2, 0.25, 0);
    dd.domain_min = fsdem_v3(-0.05, -0.05, -1);
    dd.domain_max = fsdem_v3(0.2, 0.25, 1);
    dd.dt = 5e-5;
    m.density = 2600;
    m.friction = (fsdem_real)0.5;
    bad = fsdem_mps_create(&md, &mps) != FSDEM_OK || fsdem_dem_create(&dd, &dem) != FSDEM_OK;
    if (!bad) {
        w = fsdem_dem_wall_box(fsdem_v3(0, 0, -1), fsdem_v3(0.15, 0.3, 1), 1, 0);
        cd.mps = mps;
        cd.dem = dem;
        bad = fsdem_mps_add_box_walls(mps, fsdem_v3(0, 0, 0), fsdem_v3(0.15, 0.2, 0), 1u << FSDEM_SIDE_YMAX, NULL) != FSDEM_OK ||
              fsdem_mps_fill_box(mps, fsdem_v3(0, 0, 0), fsdem_v3(0.15, 0.1, 0), fsdem_v3(0, 0, 0), NULL) != FSDEM_OK ||
              fsdem_dem_add_material(dem, &m, &mat) != FSDEM_OK || fsdem_dem_add_wall(dem, &w, NULL) != FSDEM_OK ||
              add_row(dem, 6, (fsdem_real)0.003, fsdem_v3(0.03, 0.12, 0), fsdem_v3(0.017, 0.002, 0), fsdem_v3(0, -0.5, 0)) ||
              add_row(dem, 6, (fsdem_real)0.002, fsdem_v3(0.04, 0.09, 0), fsdem_v3(0.015, -0.001, 0), fsdem_v3(0.1, 0, 0)) ||
              fsdem_mps_dem_create(&cd, &c) != FSDEM_OK || fsdem_mps_dem_advance(c, 0.04, NULL) != FSDEM_OK ||
              print_hash("mps_dem", c, save_mps_dem);
    }
    fsdem_mps_dem_destroy(c);
    fsdem_dem_destroy(dem);
    fsdem_mps_destroy(mps);
    return bad;
}

/* Two discs, one heavy and one light, in a 2D FLIP tank of 1/32 m cells, 25 steps of 2 ms: cut
   faces, the implicit solid velocity in the pressure solve, forces, particle exclusion, a contact
   with the gap dissipation of Eq. 20. */
static int pic_dem_scene(void) {
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_pic_dem_desc cd = fsdem_pic_dem_desc_default();
    fsdem_pic *pic = NULL;
    fsdem_dem *dem = NULL;
    fsdem_pic_dem *c = NULL;
    int k, bad;
    pd.cell_size = (fsdem_real)(1.0 / 32);
    pd.dt_max = (fsdem_real)2e-3;
    pd.viscosity = (fsdem_real)1e-3;
    dd.domain_max = fsdem_v3(1, 1, 0);
    dd.integrator = FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR;
    dd.contact_offset = 2 * pd.cell_size;
    dd.dt = 1e-4;
    m.density = 1500;
    bad = fsdem_pic_create(&pd, &pic) != FSDEM_OK || fsdem_dem_create(&dd, &dem) != FSDEM_OK;
    if (!bad) {
        cd.pic = pic;
        cd.dem = dem;
        bad = fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3(1, 0.4, 0), fsdem_v3(0, 0, 0), NULL) != FSDEM_OK ||
              fsdem_dem_add_material(dem, &m, NULL) != FSDEM_OK ||
              add_row(dem, 2, (fsdem_real)0.08, fsdem_v3(0.4, 0.3, 0), fsdem_v3(0.2, 0.05, 0), fsdem_v3(0.3, -0.5, 0)) ||
              fsdem_pic_dem_create(&cd, &c) != FSDEM_OK;
        for (k = 0; k < 25 && !bad; ++k) bad = fsdem_pic_dem_step_dt(c, (fsdem_real)2e-3) != FSDEM_OK;
        bad = bad || print_hash("pic_dem", c, save_pic_dem);
    }
    fsdem_pic_dem_destroy(c);
    fsdem_dem_destroy(dem);
    fsdem_pic_destroy(pic);
    return bad;
}

/* A block of 60 granules falling into a 2D FLIP tank of 1/32 m cells, 25 adaptive steps: volume
   fractions, the porous projections, granule forces and the exchange, sand substeps with contacts. */
static int gic_scene(void) {
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_gic_desc gd = fsdem_gic_desc_default();
    fsdem_pic *pic = NULL;
    fsdem_dem *dem = NULL;
    fsdem_gic *c = NULL;
    int k, bad;
    pd.cell_size = (fsdem_real)(1.0 / 32);
    pd.dt_max = (fsdem_real)2e-3;
    dd.domain_max = fsdem_v3(1, 1, 0);
    dd.law = FSDEM_DEM_LAW_GIC;
    dd.rotation = 0;
    dd.dt = 2e-5;
    m.young_modulus = 1e6;
    bad = fsdem_pic_create(&pd, &pic) != FSDEM_OK || fsdem_dem_create(&dd, &dem) != FSDEM_OK;
    if (!bad) {
        gd.pic = pic;
        gd.dem = dem;
        bad = fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3(1, 0.4, 0), fsdem_v3(0, 0, 0), NULL) != FSDEM_OK ||
              fsdem_dem_add_material(dem, &m, NULL) != FSDEM_OK;
        for (k = 0; k < 60 && !bad; ++k) {
            fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
            p.radius = (fsdem_real)0.006;
            p.position = fsdem_v3((fsdem_real)(0.4 + 0.0125 * (k % 12)), (fsdem_real)(0.38 + 0.0125 * (k / 12)), 0);
            p.velocity = fsdem_v3(0, (fsdem_real)-0.3, 0);
            bad = fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK;
        }
        bad = bad || fsdem_gic_create(&gd, &c) != FSDEM_OK || fsdem_gic_update(c) != FSDEM_OK;
        for (k = 0; k < 25 && !bad; ++k) bad = fsdem_gic_step(c) != FSDEM_OK;
        bad = bad || print_hash("gic", c, save_gic);
    }
    fsdem_gic_destroy(c);
    fsdem_dem_destroy(dem);
    fsdem_pic_destroy(pic);
    return bad;
}

/* The PCG with multigrid and with Jacobi on grids large enough for the threaded kernels (blocked dot
   products, staged V-cycle): a 2D and a 3D Poisson problem with varying face coefficients, solid
   cells and air cells (Dirichlet), the solution's bits hashed. */
static int pcg_scene(void) {
    static const int dims[2] = {2, 3}, sizes[2][3] = {{300, 200, 1}, {44, 40, 36}};
    static const fsdem_precond preconds[2] = {FSDEM_PRECOND_MG, FSDEM_PRECOND_JACOBI};
    unsigned long long h = 1469598103934665603ULL;
    int g, q, bad = 0;
    for (g = 0; g < 2 && !bad; ++g) {
        const int *n = sizes[g], cells = n[0] * n[1] * n[2];
        const int faces = (n[0] + 1) * (n[1] + 1) * (n[2] + 1);
        unsigned char *cell = (unsigned char *)malloc((size_t)cells);
        fsdem_real *face = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)faces * 3), *b, *x;
        fsdem_stencil st;
        int c, a;
        b = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)cells);
        x = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)cells);
        if (!cell || !face || !b || !x) return 1;
        for (c = 0; c < cells; ++c) {
            const int i = c % n[0], j = c / n[0] % n[1];
            cell[c] = (unsigned)c * 7919u % 23u == 0 ? FSDEM_STENCIL_CELL_SOLID : j > n[1] - 3 && i % 5 ? FSDEM_STENCIL_CELL_AIR
                                                                                              : FSDEM_STENCIL_CELL_FLUID;
            b[c] = (fsdem_real)((unsigned)c * 104729u % 1000u / 1000.0 - 0.5);
        }
        for (c = 0; c < 3 * faces; ++c) face[c] = (fsdem_real)(0.5 + (unsigned)c * 31u % 17u / 16.0);
        memset(&st, 0, sizeof st);
        st.dim = dims[g];
        for (a = 0; a < 3; ++a) st.n[a] = n[a];
        st.cell = cell;
        for (a = 0; a < dims[g]; ++a) st.face[a] = face + (size_t)a * faces;
        for (q = 0; q < 2 && !bad; ++q) {
            fsdem_pcg_desc d = fsdem_pcg_desc_default();
            fsdem_pcg *s;
            d.preconditioner = preconds[q];
            d.tolerance = (fsdem_real)1e-6;
            d.max_iterations = 10000;
            memset(x, 0, sizeof(fsdem_real) * (size_t)cells);
            bad = fsdem_pcg_create(&d, &s) != FSDEM_OK || fsdem_pcg_setup_stencil(s, &st) != FSDEM_OK ||
                  fsdem_pcg_solve(s, b, x, NULL) != FSDEM_OK;
            fsdem_pcg_destroy(s);
            h = h * 31 + hash_bytes((const unsigned char *)x, sizeof(fsdem_real) * (size_t)cells);
        }
        free(cell);
        free(face);
        free(b);
        free(x);
    }
    if (!bad) printf("pcg %016llx\n", h);
    return bad;
}

int main(void) {
    const int bad = dem_scene() | dem_bulk_scene() | pic_scene() | swe_scene() | mps_scene() | swe_dem_scene() | mps_dem_scene() | pic_dem_scene() | gic_scene() | pcg_scene();
    if (bad) printf("determinism: a scene failed\n");
    return bad;
}
