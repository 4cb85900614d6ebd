/* validation/picdem_cylinder_dambreak/case.h - the dam break through layers of aluminium cylinders of
   seed 000 §3.2 (after Zhang et al. 2009), resolved PIC-DEM (fsdem_pic_dem) in 2D, built with
   fsdem.h: shared by validation/picdem_cylinder_dambreak, bench/picdem_dambreak and
   examples/09_picdem_dambreak.c. Not part of fsdem.h. Include after fsdem.h (with its
   implementation).

   Geometry (README.md of the validation case says which numbers come from where):
     tank        x in [0, 0.286] m (the 26 cm tank enlarged by 1.1, as the dry case of seed 000
                 §3.1), floor y = 0; the PIC domain is [0, 0.286] x [0, 0.26] m with slip sides;
     cylinders   d = 1 cm, length 0.099 m, 2700 kg/m^3; `layers` layers of 6 and 5 alternately, the
                 5-layers in the grooves, neighbours 2r + gap apart (gap = 2 dx, seed 000 Eq. 19) so
                 the imaginary boundaries just touch, the lowest-left one r + gap from the floor and
                 the left wall: the validation/dem_cylinder_collapse pile;
     water       from the left wall to the plate (the right side of the pile's widest layer,
                 x = 2 (r + gap) + 5 (2r + gap)) and 0.12 m high; the particles inside the cylinders
                 are removed by the coupler;
     released at t = 0 (the plate is not simulated).
   DEM: linear law of seed 000 Table 1 (alpha 0.4, psi 0.3, mu 0.3, theta 1 % of linear_dx =
   0.05 cm, the seed's grid, whatever the PIC's dx, so the contact law is the seed's at every
   resolution), dt of Eq. 18 with gamma 150, the predictor-corrector of Eq. 21-24, contact_offset
   = 2 dx; walls: floor, left wall, right wall (index WD_RIGHT_WALL). PIC: defaults (FLIP 0.97, 4
   particles per cell, density projection, multigrid PCG) with rho = 1000 kg/m^3, nu = 1e-6 m^2/s,
   dt_max = 1 ms (from rest the first coupled step would otherwise be sqrt(dx/g) and trip the PIC's
   CFL check) and cfl_max = 10 (the PIC refuses a step after the fact when the projected grid
   velocity moved more than cfl_max cells; in the 2-cell gaps between moving cylinders a face with
   a small open fraction can carry a one-step spike, 10.9 m/s beside particles at 1.07 m/s, and the
   refusal ends the coupled run: README.md, Problems). Coupler: beta = `beta` (1 switches the gap treatment off), contact area 4 dx. */
#ifndef FSDEM_PICDEM_CYLINDER_DAMBREAK_CASE_H
#define FSDEM_PICDEM_CYLINDER_DAMBREAK_CASE_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#define WD_RADIUS 0.005       /* m, d = 1 cm */
#define WD_LENGTH 0.099       /* m, cylinder length (disc_length) */
#define WD_DENSITY 2700.0     /* kg/m^3, aluminium */
#define WD_TANK 0.286         /* m, 0.26 m x 1.1 */
#define WD_HEIGHT 0.26        /* m, PIC domain height */
#define WD_WATER 0.12         /* m, water depth behind the plate */
#define WD_SEED_DX 0.0005     /* m, the seed's grid (and the DEM's linear_dx) */
#define WD_RIGHT_WALL 2       /* index of the right wall among the DEM walls */

typedef struct wd_case {
    fsdem_pic *pic;
    fsdem_dem *dem;
    fsdem_pic_dem *cpl;
    double dx, gap, beta;
    double plate;         /* m, x of the plate: the water's right side at t = 0 */
    int layers, cylinders, water_particles;
    double dem_dt;        /* s */
    double volume0;       /* m^2, particle volume after the coupler removed the water in the cylinders */
    char error[512];
} wd_case;

static inline void wd_destroy(wd_case *c) {
    fsdem_pic_dem_destroy(c->cpl);
    fsdem_pic_destroy(c->pic);
    fsdem_dem_destroy(c->dem);
    c->cpl = NULL;
    c->pic = NULL;
    c->dem = NULL;
}

static inline const char *wd_last_error(const wd_case *c) {
    return c->cpl ? fsdem_pic_dem_last_error(c->cpl) : c->error;
}

/* Builds the case at PIC cell size dx (m) with `layers` layers and beta (Eq. 20). Returns 0, or -1
   with the reason in c->error. */
static inline int wd_create(wd_case *c, double dx, int layers, double beta) {
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_dem_material al = fsdem_dem_material_default();
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_pic_dem_desc cd = fsdem_pic_dem_desc_default();
    const double gap = 2 * dx, a = WD_RADIUS + gap, s = 2 * WD_RADIUS + gap;
    fsdem_dem_wall_desc w[3];
    fsdem_result r;
    fsdem_real dt = 0;
    int mat = 0, layer, k, added = 0;
    memset(c, 0, sizeof *c);
    c->dx = dx;
    c->gap = gap;
    c->beta = beta;
    c->layers = layers;
    c->plate = 2 * a + 5 * s;

    dd.domain_min = fsdem_v3(-0.05, -0.05, -1);
    dd.domain_max = fsdem_v3(WD_TANK + 0.05, WD_HEIGHT + 0.2, 1);
    dd.law = FSDEM_DEM_LAW_LINEAR;
    dd.contact_offset = (fsdem_real)gap; /* imaginary boundaries, seed 000 Eq. 19 */
    dd.linear_theta = (fsdem_real)0.01;
    dd.linear_dx = (fsdem_real)WD_SEED_DX;
    dd.disc_length = (fsdem_real)WD_LENGTH;
    dd.dt_param = 150; /* Eq. 18 gamma */
    dd.integrator = FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR;
    if ((r = fsdem_dem_create(&dd, &c->dem)) != FSDEM_OK) {
        fsdem_dem_desc_check(&dd, c->error, sizeof c->error);
        return -1;
    }
    al.density = (fsdem_real)WD_DENSITY;
    al.poisson_ratio = (fsdem_real)0.3;
    al.friction = (fsdem_real)0.3;
    al.damping_alpha = (fsdem_real)0.4;
    if (fsdem_dem_add_material(c->dem, &al, &mat) != FSDEM_OK) goto dem_error;
    w[0] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 1, 0), mat);                 /* floor */
    w[1] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(1, 0, 0), mat);                 /* left wall */
    w[2] = fsdem_dem_wall_plane(fsdem_v3((fsdem_real)WD_TANK, 0, 0), fsdem_v3(-1, 0, 0), mat); /* right wall */
    for (k = 0; k < 3; ++k)
        if (fsdem_dem_add_wall(c->dem, &w[k], NULL) != FSDEM_OK) goto dem_error;
    for (layer = 0; layer < layers; ++layer) {
        const int count = layer % 2 ? 5 : 6;
        for (k = 0; k < count; ++k) {
            fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
            p.radius = (fsdem_real)WD_RADIUS;
            p.material = mat;
            p.position = fsdem_v3((fsdem_real)(a + s * k + (layer % 2 ? s / 2 : 0)), (fsdem_real)(a + layer * s * sqrt(3.0) / 2), 0);
            if (fsdem_dem_add_particle(c->dem, &p, NULL) != FSDEM_OK) goto dem_error;
            c->cylinders++;
        }
    }
    if (fsdem_dem_stable_dt(c->dem, &dt) != FSDEM_OK || fsdem_dem_set_dt(c->dem, dt) != FSDEM_OK) goto dem_error;
    c->dem_dt = (double)dt;

    pd.cell_size = (fsdem_real)dx;
    pd.domain_max = fsdem_v3((fsdem_real)WD_TANK, (fsdem_real)WD_HEIGHT, 0);
    pd.density = 1000;
    pd.viscosity = (fsdem_real)1e-6;
    pd.dt_max = (fsdem_real)1e-3;
    pd.cfl_max = 10;
    if ((r = fsdem_pic_create(&pd, &c->pic)) != FSDEM_OK) {
        fsdem_pic_desc_check(&pd, c->error, sizeof c->error);
        wd_destroy(c);
        return -1;
    }
    if (fsdem_pic_fill_box(c->pic, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)c->plate, (fsdem_real)WD_WATER, 0), fsdem_v3(0, 0, 0),
                           &added) != FSDEM_OK) {
        snprintf(c->error, sizeof c->error, "fsdem_pic_fill_box: %.400s", fsdem_pic_last_error(c->pic));
        wd_destroy(c);
        return -1;
    }
    cd.pic = c->pic;
    cd.dem = c->dem;
    cd.dissipation = (fsdem_real)beta;
    if ((r = fsdem_pic_dem_create(&cd, &c->cpl)) != FSDEM_OK) {
        fsdem_pic_dem_desc_check(&cd, c->error, sizeof c->error);
        if (!c->error[0]) snprintf(c->error, sizeof c->error, "fsdem_pic_dem_create: %.400s", fsdem_result_string(r));
        wd_destroy(c);
        return -1;
    }
    c->water_particles = fsdem_pic_get_stats(c->pic).particles;
    c->volume0 = (double)fsdem_pic_get_stats(c->pic).particle_volume;
    return 0;
dem_error:
    snprintf(c->error, sizeof c->error, "DEM set-up: %.400s", fsdem_dem_last_error(c->dem));
    wd_destroy(c);
    return -1;
}

/* One coupled step of the stable dt, shortened so that the time lands exactly on `until` (s). */
static inline fsdem_result wd_step_until(wd_case *c, double until) {
    const double left = until - fsdem_pic_dem_time(c->cpl);
    fsdem_real dt = 0;
    fsdem_result r = fsdem_pic_dem_stable_dt(c->cpl, &dt);
    if (r != FSDEM_OK) return r;
    if (left > 0 && (double)dt >= left) return fsdem_pic_dem_step_dt(c->cpl, (fsdem_real)left);
    if (left > 0 && 1.5 * (double)dt > left) return fsdem_pic_dem_step_dt(c->cpl, (fsdem_real)(left / 2));
    return fsdem_pic_dem_step_dt(c->cpl, dt);
}

/* Mean centre of the cylinders (seed 000 Eq. 26; z is the vertical, y in fsdem 2D) and the largest
   centre x (m). */
static inline void wd_centres(const wd_case *c, double *x_ave, double *z_ave, double *x_max) {
    fsdem_dem_particles p = fsdem_dem_get_particles(c->dem);
    double sx = 0, sz = 0, xm = -1e30;
    int i;
    for (i = 0; i < p.count; ++i) {
        sx += p.position[i].x;
        sz += p.position[i].y;
        if (p.position[i].x > xm) xm = p.position[i].x;
    }
    *x_ave = sx / p.count;
    *z_ave = sz / p.count;
    *x_max = xm;
}

/* 1 when a cylinder is in contact with the right wall: its imaginary boundary (radius + gap)
   reaches the wall, or the wall carries a force from the DEM's last evaluation. */
static inline int wd_at_right_wall(const wd_case *c) {
    fsdem_dem_particles p = fsdem_dem_get_particles(c->dem);
    fsdem_vec3 f = fsdem_dem_wall_force(c->dem, WD_RIGHT_WALL);
    int i;
    if (f.x != 0 || f.y != 0) return 1;
    for (i = 0; i < p.count; ++i)
        if (p.position[i].x + p.radius[i] + c->gap >= WD_TANK) return 1;
    return 0;
}

/* Cylinders whose centre is outside the tank ([0, WD_TANK] x [0, WD_HEIGHT]). */
static inline int wd_outside(const wd_case *c) {
    fsdem_dem_particles p = fsdem_dem_get_particles(c->dem);
    int i, n = 0;
    for (i = 0; i < p.count; ++i)
        if (!(p.position[i].x > 0 && p.position[i].x < WD_TANK && p.position[i].y > 0 && p.position[i].y < WD_HEIGHT)) n++;
    return n;
}

/* Water front (m): the right side of the rightmost FLUID cell of the bottom row, placed inside it by
   the level set as validation/pic_dambreak.h does. */
static inline double wd_front(const wd_case *c) {
    fsdem_pic_fields g = fsdem_pic_get_fields(c->pic);
    int i;
    for (i = g.n[0] - 1; i >= 0; --i)
        if (g.cell[i] == FSDEM_STENCIL_CELL_FLUID) {
            double th = 0.5;
            if (i + 1 < g.n[0]) {
                const double p0 = (double)g.phi[i], p1 = (double)g.phi[i + 1];
                th = p0 < p1 ? p0 / (p0 - p1) : 1;
                if (th < 0) th = 0;
                if (th > 1) th = 1;
            }
            return (i + 0.5 + th) * (double)g.cell_size;
        }
    return 0;
}

#endif
