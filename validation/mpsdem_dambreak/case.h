/* validation/mpsdem_dambreak/case.h - the liquid-solid dam break of seed 002 §3.2 (after Sun, Sakai
   and Yamada 2013), built with fsdem.h: shared by validation/mpsdem_dambreak and
   bench/mpsdem_dambreak. Not part of fsdem.h. Include after fsdem.h (with its implementation).

   Geometry (README.md says which numbers come from where; the column and bed sizes are ASSUMED,
   the paper's were not found):
     tank        inside [0, 0.2] x [0, 0.1] x [0, 0.15] m, open at the top (seed 002 §3.2);
     water       a column [0, 0.05] x [0, 0.1] x [0, 0.1] m against the left wall (x = 0);
     sediment    spheres of diameter 0.0027 m (radius 0.00135 m, seed 002 Table 1), 2500 kg/m^3,
                 on a simple cubic lattice filling [0, 0.05] x [0, 0.1] x [0, 0.03] m at the bottom of
                 the column (18 x 36 x 11 = 7128 spheres), inside the water;
     released at t = 0 (no gate).
   The MPS spacing r0 is the seed's d_p (0.003, 0.0027, 0.002 m); the spheres keep their size at
   every r0, as in the seed (Table 1 gives one radius). Inside the bed the water is placed on a
   coarser lattice, r0 / eps_bed^(1/3) per particle on average, eps_bed the bed's porosity: in the
   coupler each MPS particle holds the fluid mass rho r0^3 and stands for r0^3 / eps of mixture,
   so the number density of Eq. 7 (sum of w / eps_j) starts at n0 in the bed as well. Above the
   bed the water is on the r0 lattice of fsdem_mps_fill_box. The water column is 0.1 m of mixture,
   so the water volume with sediment is 0.05 x 0.1 x (0.07 + 0.03 eps_bed) m^3; the clear-water
   run fills the whole column with water (0.05 x 0.1 x 0.1 m^3).

   Solvers: MPS with the seed's semi-implicit scheme, fsdem_mps_desc_default(3) otherwise (seed
   002 §2.1 values: re = 4.1 r0, gamma 0.01, beta 0.8, alpha 0.9, CFL 0.2, rho 1000, nu 1e-6) with
   model A or B; DEM Hertz-Mindlin with
   the sediment of Table 1 (E = 1e8 Pa, nu = 0.2, e = 0.9, mu = 0.2), velocity Verlet, dt = the
   Rayleigh rule of seed 002 Eq. 38 times 0.2 (the library default safety fraction); walls: a box
   [0, 0.2] x [0, 0.1] x [0, 0.29] m (the DEM needs a lid; it is far above the flow); coupler
   defaults (Ergun / Wen-Yu drag of Eq. 26, r_e of w_s = the MPS re). */
#ifndef FSDEM_MPSDEM_DAMBREAK_CASE_H
#define FSDEM_MPSDEM_DAMBREAK_CASE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SD_TANK_X 0.2
#define SD_TANK_Y 0.1
#define SD_TANK_Z 0.15
#define SD_COLUMN_X 0.05
#define SD_COLUMN_Z 0.1
#define SD_BED_Z 0.03
#define SD_RADIUS 0.00135
#define SD_DENSITY 2500.0

typedef struct sd_case {
    fsdem_mps *mps;
    fsdem_dem *dem;
    fsdem_mps_dem *cpl; /* NULL for clear water */
    double r0;
    int sediment;       /* 1: with the sediment bed */
    int fluid, walls, spheres;
    double bed_porosity; /* of the initial simple cubic bed (0 without sediment) */
    double dem_dt;
    char error[512];
} sd_case;

static inline void sd_destroy(sd_case *c) {
    char error[sizeof c->error];
    memcpy(error, c->error, sizeof error); /* a failed sd_create's reason stays readable */
    fsdem_mps_dem_destroy(c->cpl);
    fsdem_dem_destroy(c->dem);
    fsdem_mps_destroy(c->mps);
    memset(c, 0, sizeof *c);
    memcpy(c->error, error, sizeof error);
}

/* Builds the case at MPS spacing r0 (m), model A or B, with (sediment = 1) or without the bed.
   Returns 0, or -1 with the reason in c->error. */
static inline int sd_create(sd_case *c, double r0, fsdem_mps_model model, int sediment) {
    fsdem_mps_desc md = fsdem_mps_desc_default_scheme(3, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_dem_desc dd = fsdem_dem_desc_default(3);
    fsdem_dem_material mat = fsdem_dem_material_default();
    fsdem_mps_dem_desc cd = fsdem_mps_dem_desc_default();
    fsdem_dem_wall_desc box;
    int material = 0, added = 0;
    fsdem_result r;
    memset(c, 0, sizeof *c);
    c->r0 = r0;
    c->sediment = sediment;
    md.r0 = (fsdem_real)r0;
    md.model = model;
    md.domain_min = fsdem_v3(-0.02, -0.02, -0.02);
    md.domain_max = fsdem_v3(0.22, 0.12, 0.3);
    if ((r = fsdem_mps_create(&md, &c->mps)) != FSDEM_OK) {
        fsdem_mps_desc_check(&md, c->error, sizeof c->error);
        return -1;
    }
    if (fsdem_mps_add_box_walls(c->mps, fsdem_v3(0, 0, 0), fsdem_v3(SD_TANK_X, SD_TANK_Y, SD_TANK_Z), 1u << FSDEM_SIDE_ZMAX,
                                &c->walls) != FSDEM_OK)
        goto mps_error;
    if (!sediment) {
        if (fsdem_mps_fill_box(c->mps, fsdem_v3(0, 0, 0), fsdem_v3(SD_COLUMN_X, SD_TANK_Y, SD_COLUMN_Z), fsdem_v3(0, 0, 0),
                               &c->fluid) != FSDEM_OK)
            goto mps_error;
        return 0;
    }

    /* the bed: a simple cubic lattice of spheres, as many as fit at 1.01 d per axis */
    {
        const double d = 2 * SD_RADIUS, pitch = 1.01 * d;
        const int nx = (int)(SD_COLUMN_X / pitch), ny = (int)(SD_TANK_Y / pitch), nz = (int)(SD_BED_Z / pitch);
        const double sx = SD_COLUMN_X / nx, sy = SD_TANK_Y / ny, sz = SD_BED_Z / nz;
        int i, j, k;
        dd.domain_min = md.domain_min;
        dd.domain_max = md.domain_max;
        dd.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
        dd.dt_rule = FSDEM_DEM_DT_RULE_RAYLEIGH;
        if ((r = fsdem_dem_create(&dd, &c->dem)) != FSDEM_OK) {
            snprintf(c->error, sizeof c->error, "fsdem_dem_create: %s", fsdem_result_string(r));
            sd_destroy(c);
            return -1;
        }
        mat.density = (fsdem_real)SD_DENSITY;
        mat.young_modulus = (fsdem_real)1e8;
        mat.poisson_ratio = (fsdem_real)0.2;
        mat.restitution = (fsdem_real)0.9;
        mat.friction = (fsdem_real)0.2;
        if (fsdem_dem_add_material(c->dem, &mat, &material) != FSDEM_OK) goto dem_error;
        box = fsdem_dem_wall_box(fsdem_v3(0, 0, 0), fsdem_v3(SD_TANK_X, SD_TANK_Y, 0.29), 1, material);
        if (fsdem_dem_add_wall(c->dem, &box, NULL) != FSDEM_OK) goto dem_error;
        for (k = 0; k < nz; ++k)
            for (j = 0; j < ny; ++j)
                for (i = 0; i < nx; ++i) {
                    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
                    p.position = fsdem_v3((fsdem_real)((i + 0.5) * sx), (fsdem_real)((j + 0.5) * sy), (fsdem_real)((k + 0.5) * sz));
                    p.radius = (fsdem_real)SD_RADIUS;
                    p.material = material;
                    if (fsdem_dem_add_particle(c->dem, &p, NULL) != FSDEM_OK) goto dem_error;
                }
        c->spheres = nx * ny * nz;
        c->bed_porosity = 1 - (3.14159265358979323846 / 6) * d * d * d / (sx * sy * sz);
        {
            fsdem_real dt = 0;
            if (fsdem_dem_stable_dt(c->dem, &dt) != FSDEM_OK || fsdem_dem_set_dt(c->dem, dt) != FSDEM_OK) goto dem_error;
            c->dem_dt = (double)dt;
        }
    }
    /* water in the bed: a lattice of r0 / eps^(1/3) on average, fitted to the bed per axis */
    {
        const double s = r0 / cbrt(c->bed_porosity);
        const int nx = (int)floor(SD_COLUMN_X / s + 0.5), ny = (int)floor(SD_TANK_Y / s + 0.5), nz = (int)floor(SD_BED_Z / s + 0.5);
        const double sx = SD_COLUMN_X / nx, sy = SD_TANK_Y / ny, sz = SD_BED_Z / nz;
        const int n = nx * ny * nz;
        fsdem_vec3 *x = (fsdem_vec3 *)malloc((size_t)n * sizeof *x);
        int i, j, k, m = 0;
        if (!x) {
            snprintf(c->error, sizeof c->error, "out of memory");
            sd_destroy(c);
            return -1;
        }
        for (k = 0; k < nz; ++k)
            for (j = 0; j < ny; ++j)
                for (i = 0; i < nx; ++i)
                    x[m++] = fsdem_v3((fsdem_real)((i + 0.5) * sx), (fsdem_real)((j + 0.5) * sy), (fsdem_real)((k + 0.5) * sz));
        r = fsdem_mps_add_particles(c->mps, FSDEM_MPS_KIND_FLUID, n, x, NULL);
        free(x);
        if (r != FSDEM_OK) goto mps_error;
        c->fluid = n;
    }
    if (fsdem_mps_fill_box(c->mps, fsdem_v3(0, 0, (fsdem_real)SD_BED_Z), fsdem_v3(SD_COLUMN_X, SD_TANK_Y, SD_COLUMN_Z),
                           fsdem_v3(0, 0, 0), &added) != FSDEM_OK)
        goto mps_error;
    c->fluid += added;
    cd.mps = c->mps;
    cd.dem = c->dem;
    if ((r = fsdem_mps_dem_create(&cd, &c->cpl)) != FSDEM_OK) {
        fsdem_mps_dem_desc_check(&cd, c->error, sizeof c->error);
        sd_destroy(c);
        return -1;
    }
    return 0;
mps_error:
    snprintf(c->error, sizeof c->error, "%s", fsdem_mps_last_error(c->mps));
    sd_destroy(c);
    return -1;
dem_error:
    snprintf(c->error, sizeof c->error, "%s", fsdem_dem_last_error(c->dem));
    sd_destroy(c);
    return -1;
}

/* One step: coupled, or the MPS alone for clear water. */
static inline fsdem_result sd_step(sd_case *c) { return c->cpl ? fsdem_mps_dem_step(c->cpl) : fsdem_mps_step(c->mps); }

/* Steps until exactly `duration` later; the number goes to *steps. */
static inline fsdem_result sd_advance(sd_case *c, double duration, long long *steps) {
    return c->cpl ? fsdem_mps_dem_advance(c->cpl, (fsdem_real)duration, steps) : fsdem_mps_advance(c->mps, (fsdem_real)duration, steps);
}

static inline const char *sd_last_error(const sd_case *c) {
    if (c->cpl && fsdem_mps_dem_last_error(c->cpl)[0]) return fsdem_mps_dem_last_error(c->cpl);
    return fsdem_mps_last_error(c->mps);
}

/* Leading fronts (m, from the wall behind the column): the largest x of a FLUID particle plus r0/2
   (the edge of the volume it stands for, so the front starts at 0.05 m) and of a sphere plus its
   radius (0.05 m at t = 0 too); and, less sensitive to a lone particle thrown ahead, the x beyond
   which `fraction` of the phase's particles lie (of its volume: all particles of a phase are alike),
   with the same half spacing or radius added. The sediment fronts are 0 without sediment. */
typedef struct sd_fronts {
    double water_max, water_q, sediment_max, sediment_q;
} sd_fronts;

static inline int sd__cmp_desc(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? 1 : x > y ? -1 : 0;
}

/* The k-th largest of n values (k >= 0), by sorting a copy. */
static inline double sd__kth_largest(double *v, int n, int k) {
    qsort(v, (size_t)n, sizeof *v, sd__cmp_desc);
    return v[k < n ? k : n - 1];
}

static inline sd_fronts sd_measure(const sd_case *c, double fraction) {
    sd_fronts f;
    fsdem_mps_particles mp = fsdem_mps_get_particles(c->mps);
    double *v = (double *)malloc((size_t)(mp.count + 1) * sizeof *v);
    int i, n = 0;
    memset(&f, 0, sizeof f);
    if (!v) return f;
    for (i = 0; i < mp.count; ++i)
        if (mp.kind[i] == FSDEM_MPS_KIND_FLUID) v[n++] = (double)mp.position[i].x;
    if (n > 0) {
        f.water_q = sd__kth_largest(v, n, (int)(fraction * n)) + c->r0 / 2;
        f.water_max = v[0] + c->r0 / 2;
    }
    free(v);
    if (c->dem) {
        fsdem_dem_particles dp = fsdem_dem_get_particles(c->dem);
        v = (double *)malloc((size_t)(dp.count + 1) * sizeof *v);
        if (!v) return f;
        for (i = 0; i < dp.count; ++i) v[i] = (double)dp.position[i].x;
        if (dp.count > 0) {
            f.sediment_q = sd__kth_largest(v, dp.count, (int)(fraction * dp.count)) + SD_RADIUS;
            f.sediment_max = v[0] + SD_RADIUS;
        }
        free(v);
    }
    return f;
}

#endif
