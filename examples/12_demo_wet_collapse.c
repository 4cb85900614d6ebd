/* 12_demo_wet_collapse.c - the `make demo` program: a water dam breaking through a pile of cylinders.

   The wet collapse of seed 000 §3.2 (Fig. 8, after Zhang et al. 2009): six layers of aluminium
   cylinders (d = 1 cm, 9.9 cm long, 2700 kg/m^3, 6 and 5 a layer) piled against the left wall of a
   tank 0.286 m long stand in water 0.12 m deep held by a plate. At t = 0 the plate is gone: the water
   bursts through and over the pile and carries cylinders to the right wall. Each cylinder is a moving
   cut-cell solid of the PIC/FLIP water, solved with the pressure (fsdem_pic_dem); the DEM has the
   seed's linear law (Table 1), predictor-corrector, gap of 2 dx (Eq. 19) and beta = 0.5 (Eq. 20).

   Every 0.02 s, into the folder of the first argument (default "."; it must exist): frame_NNNN.png
   for any image viewer (water dots, deeper blue where slower; cylinders grey), water_NNNN.vtp and
   cylinders_NNNN.vtp in the ParaView series water.pvd and cylinders.pvd, and walls.vtp once
   (ParaView: Glyph on the cylinders, Sphere, scale by "radius", factor 2). One line per frame.

   Run:  make demo    (build/examples/12_demo_wet_collapse into build/demo: about 50 s of CPU on one
                       core; 26 frames of 739 x 524 pixels, 40 MB in all)
   By hand: cc -std=c99 -O2 -I. examples/12_demo_wet_collapse.c -o demo -lm && ./demo out */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"
#include "png_writer.h"
#include <math.h>
#include <stdio.h>
#include <time.h>

#define DX 0.001     /* m, water grid: the gap between cylinders is 2 dx (seed 000: dx = 0.0005) */
#define RADIUS 0.005 /* m */
#define TANK 0.286   /* m, length of the tank */
#define HEIGHT 0.2   /* m, height of the water's grid (its lid) */
#define WATER 0.12   /* m, water depth behind the plate */
#define SCALE 2500   /* pixels per metre */
#define MARGIN 12    /* pixels round the tank, the walls drawn in them */

/* On a failed call, print the object's message (the library never prints) and leave through the
   clean-up with status 1. The call is made before its message is read. */
#define TRY(call, message)                                                                              \
    do {                                                                                                \
        fsdem_result result_ = (call);                                                                  \
        if (result_ != FSDEM_OK) {                                                                      \
            fprintf(stderr, "error: %s (%s)\n", message, fsdem_result_string(result_));                 \
            goto done;                                                                                  \
        }                                                                                               \
    } while (0)

/* The PNG picture: water dots coloured by speed, cylinders with a rim, the walls, the time. */
static void draw_frame(rgb_image *image, fsdem_pic *pic, const fsdem_dem *dem, double t) {
    static const unsigned char background[3] = {248, 248, 250}, wall[3] = {80, 80, 88}, ink[3] = {40, 40, 48},
                               slow[3] = {20, 70, 180}, fast[3] = {160, 215, 255}, rim[3] = {60, 60, 70},
                               metal[3] = {200, 200, 208};
    const int floor_y = image->height - MARGIN, right_x = MARGIN + (int)(TANK * SCALE + 0.5);
    const fsdem_pic_particles water = fsdem_pic_get_particles(pic);
    const fsdem_dem_particles cylinders = fsdem_dem_get_particles(dem);
    char label[32];
    int i, c;
    rgb_image_fill_rect(image, 0, 0, image->width, image->height, background);
    for (i = 0; i < water.count; ++i) { /* dots of 1 pixel radius, 1.25 pixels apart */
        const fsdem_vec3 p = water.position[i], v = water.velocity[i];
        double speed = sqrt((double)(v.x * v.x + v.y * v.y)) / 1.5; /* 1.5 m/s: about sqrt(2 g h) */
        unsigned char colour[3];
        if (speed > 1) speed = 1;
        for (c = 0; c < 3; ++c) colour[c] = (unsigned char)(slow[c] + speed * (fast[c] - slow[c]));
        rgb_image_fill_disc(image, MARGIN + p.x * SCALE, floor_y - p.y * SCALE, 1, colour);
    }
    for (i = 0; i < cylinders.count; ++i) {
        const double x = MARGIN + cylinders.position[i].x * SCALE, y = floor_y - cylinders.position[i].y * SCALE;
        rgb_image_fill_disc(image, x, y, cylinders.radius[i] * SCALE, rim);
        rgb_image_fill_disc(image, x, y, cylinders.radius[i] * SCALE - 1.5, metal);
    }
    rgb_image_fill_rect(image, MARGIN - 6, MARGIN, MARGIN, floor_y + 6, wall);       /* left wall */
    rgb_image_fill_rect(image, right_x, MARGIN, right_x + 6, floor_y + 6, wall);     /* right wall */
    rgb_image_fill_rect(image, MARGIN - 6, floor_y, right_x + 6, floor_y + 6, wall); /* floor */
    snprintf(label, sizeof label, "t = %.2f s", t);
    rgb_image_text(image, MARGIN + 12, MARGIN + 12, 4, label, ink);
}

/* `dir`/`name` in path (1024 bytes), or NULL when it does not fit: the writers refuse a NULL path. */
static const char *in_dir(char *path, const char *dir, const char *name) {
    const int length = snprintf(path, 1024, "%s/%s", dir, name);
    return length > 0 && length < 1024 ? path : NULL;
}

/* Closes a series if it is open; 1, with a message, when that fails. */
static int close_series(fsdem_pvd *series, const char *name) {
    if (!series->file || fsdem_pvd_close(series) == FSDEM_OK) return 0;
    fprintf(stderr, "error: cannot close %s\n", name);
    return 1;
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : ".";
    const double t_end = 0.5, frame_every = 0.02;
    const double first = RADIUS + 2 * DX, spacing = 2 * RADIUS + 2 * DX; /* imaginary boundaries touch */
    fsdem_dem_desc dd = fsdem_dem_desc_default(2);
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_pic_dem_desc cd = fsdem_pic_dem_desc_default();
    fsdem_dem_material aluminium = fsdem_dem_material_default();
    fsdem_dem *dem = NULL;
    fsdem_pic *pic = NULL;
    fsdem_pic_dem *coupler = NULL;
    fsdem_pvd water_series, cylinder_series;
    rgb_image image = {0, 0, NULL};
    fsdem_real dem_dt = 0;
    char why[256], path[1024], name[64];
    int material = 0, frame = 0, status = 1, layer, k;
    water_series.file = cylinder_series.file = NULL;

    /* the cylinders: seed 000 Table 1 (alpha 0.4, psi 0.3, mu 0.3, theta 1 %), the step of Eq. 18 */
    dd.domain_min = fsdem_v3(-0.05, -0.05, -1);
    dd.domain_max = fsdem_v3(TANK + 0.05, HEIGHT + 0.05, 1);
    dd.law = FSDEM_DEM_LAW_LINEAR;
    dd.linear_theta = 0.01;
    dd.linear_dx = 0.0005;
    dd.dt_param = 150; /* gamma of Eq. 18 */
    dd.integrator = FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR;
    dd.contact_offset = 2 * DX; /* contacts start 2 dx early, so open cells stay between cylinders */
    dd.disc_length = 0.099;     /* discs with the cylinders' real mass */
    aluminium.density = 2700;
    aluminium.poisson_ratio = 0.3;
    aluminium.friction = 0.3;
    aluminium.damping_alpha = 0.4;
    TRY(fsdem_dem_desc_check(&dd, why, sizeof why), why);
    TRY(fsdem_dem_create(&dd, &dem), "fsdem_dem_create");
    TRY(fsdem_dem_add_material(dem, &aluminium, &material), fsdem_dem_last_error(dem));
    {
        const fsdem_vec3 origin = fsdem_v3(0, 0, 0), right = fsdem_v3(TANK, 0, 0);
        const fsdem_dem_wall_desc walls[3] = {fsdem_dem_wall_plane(origin, fsdem_v3(0, 1, 0), material),   /* floor */
                                              fsdem_dem_wall_plane(origin, fsdem_v3(1, 0, 0), material),   /* left */
                                              fsdem_dem_wall_plane(right, fsdem_v3(-1, 0, 0), material)}; /* right */
        for (k = 0; k < 3; ++k) TRY(fsdem_dem_add_wall(dem, &walls[k], NULL), fsdem_dem_last_error(dem));
    }
    for (layer = 0; layer < 6; ++layer) /* 6, 5, 6, ... cylinders, each layer in the grooves of the last */
        for (k = 0; k < (layer % 2 ? 5 : 6); ++k) {
            fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
            p.radius = RADIUS;
            p.material = material;
            p.position = fsdem_v3((fsdem_real)(first + spacing * (k + (layer % 2) / 2.0)),
                                  (fsdem_real)(first + layer * spacing * sqrt(3.0) / 2), 0);
            TRY(fsdem_dem_add_particle(dem, &p, NULL), fsdem_dem_last_error(dem));
        }
    TRY(fsdem_dem_stable_dt(dem, &dem_dt), fsdem_dem_last_error(dem));
    TRY(fsdem_dem_set_dt(dem, dem_dt), fsdem_dem_last_error(dem));

    /* the water: from the left wall to the plate, one gap past the pile; slip walls, a lid on top */
    pd.cell_size = DX;
    pd.domain_max = fsdem_v3(TANK, HEIGHT, 0);
    pd.viscosity = 1e-6;
    pd.dt_max = 1e-3; /* the step estimate does not foresee the impulsive start */
    TRY(fsdem_pic_desc_check(&pd, why, sizeof why), why);
    TRY(fsdem_pic_create(&pd, &pic), "fsdem_pic_create");
    TRY(fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), fsdem_v3((fsdem_real)(2 * first + 5 * spacing), WATER, 0),
                           fsdem_v3(0, 0, 0), NULL), fsdem_pic_last_error(pic));

    /* the coupler takes the water out of the cylinders; beta = 0.5 in the contact areas */
    cd.pic = pic;
    cd.dem = dem;
    cd.dissipation = 0.5;
    TRY(fsdem_pic_dem_desc_check(&cd, why, sizeof why), why);
    TRY(fsdem_pic_dem_create(&cd, &coupler), "fsdem_pic_dem_create");

    if (!rgb_image_create(&image, (int)(TANK * SCALE + 0.5) + 2 * MARGIN, (int)(HEIGHT * SCALE + 0.5) + 2 * MARGIN)) {
        fprintf(stderr, "error: no memory for the picture\n");
        goto done;
    }
    TRY(fsdem_dem_write_walls_vtp(dem, in_dir(path, dir, "walls.vtp"), FSDEM_VTK_FORMAT_APPENDED),
        fsdem_dem_last_error(dem));
    TRY(fsdem_pvd_open(&water_series, in_dir(path, dir, "water.pvd")), "water.pvd");
    TRY(fsdem_pvd_open(&cylinder_series, in_dir(path, dir, "cylinders.pvd")), "cylinders.pvd");
    printf("wet collapse (seed 000, section 3.2): %d water particles, dx = %g m, %d cylinders, DEM dt %.3g s;"
           " to t = %.1f s, output in %s\n", fsdem_pic_get_stats(pic).particles, DX, fsdem_dem_get_particles(dem).count,
           (double)dem_dt, t_end, dir);
    printf("%6s %6s %10s %10s %8s\n", "t (s)", "steps", "x_ave (m)", "x_max (m)", "CPU (s)");
    for (;;) {
        const fsdem_dem_particles P = fsdem_dem_get_particles(dem);
        const double t = fsdem_pic_dem_time(coupler);
        double x_ave = 0, x_max = 0;
        int i;
        for (i = 0; i < P.count; ++i) {
            x_ave += P.position[i].x / P.count;
            if (P.position[i].x > x_max) x_max = P.position[i].x;
        }
        snprintf(name, sizeof name, "water_%04d.vtp", frame); /* a series names its files from its folder */
        TRY(fsdem_pic_write_particles_vtp(pic, in_dir(path, dir, name), FSDEM_VTK_FORMAT_APPENDED),
            fsdem_pic_last_error(pic));
        TRY(fsdem_pvd_add(&water_series, t, name), "water.pvd");
        snprintf(name, sizeof name, "cylinders_%04d.vtp", frame);
        TRY(fsdem_dem_write_vtp(dem, in_dir(path, dir, name), FSDEM_VTK_FORMAT_APPENDED), fsdem_dem_last_error(dem));
        TRY(fsdem_pvd_add(&cylinder_series, t, name), "cylinders.pvd");
        snprintf(name, sizeof name, "frame_%04d.png", frame);
        draw_frame(&image, pic, dem, t);
        if (!in_dir(path, dir, name) || rgb_image_write_png(&image, path) != 0) {
            fprintf(stderr, "error: cannot write %s/%s\n", dir, name);
            goto done;
        }
        printf("%6.2f %6lld %10.4f %10.4f %8.1f\n", t, fsdem_pic_dem_get_stats(coupler).coupling.steps, x_ave, x_max,
               (double)clock() / CLOCKS_PER_SEC);
        fflush(stdout);
        if (frame * frame_every >= t_end - 1e-9) break;
        frame++;
        /* coupled steps to the next frame, the last one shortened to land on it */
        TRY(fsdem_pic_dem_advance(coupler, (fsdem_real)frame_every, NULL), fsdem_pic_dem_last_error(coupler));
    }
    printf("wrote %d frames into %s: frame_NNNN.png (%d x %d); water.pvd, cylinders.pvd (ParaView), walls.vtp\n",
           frame + 1, dir, image.width, image.height);
    status = 0;
done:
    status |= close_series(&water_series, "water.pvd");
    status |= close_series(&cylinder_series, "cylinders.pvd");
    rgb_image_free(&image);
    fsdem_pic_dem_destroy(coupler);
    fsdem_pic_destroy(pic);
    fsdem_dem_destroy(dem);
    return status;
}
