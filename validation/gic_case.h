/* Shared by the Granule-In-Cell cases (validation/gic_*): the granules' DEM with seed 004's contact
   law and material, and the coupler over a PIC and a DEM whose granules are placed. */
#ifndef FSDEM_VALIDATION_GIC_CASE_H
#define FSDEM_VALIDATION_GIC_CASE_H
#include <stdio.h>
#include "fsdem.h"

/* A DEM over the box [lo, hi] with the GIC contact law (Eq. 1a-1c, translation only) and one
   material of density rho_s with the seed's E = 1e6 Pa (§6) and the friction mu. NULL on failure. */
static fsdem_dem *gic_case_dem(int dim, fsdem_vec3 lo, fsdem_vec3 hi, double rho_s, double mu, double disc_length) {
    fsdem_dem_desc dd = fsdem_dem_desc_default(dim);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem *dem = NULL;
    dd.domain_min = lo;
    dd.domain_max = hi;
    dd.law = FSDEM_DEM_LAW_GIC;
    dd.rotation = 0;
    if (disc_length > 0) dd.disc_length = (fsdem_real)disc_length;
    m.density = (fsdem_real)rho_s;
    m.young_modulus = (fsdem_real)1e6;
    m.friction = (fsdem_real)mu;
    if (fsdem_dem_create(&dd, &dem) != FSDEM_OK) return NULL;
    if (fsdem_dem_add_material(dem, &m, NULL) != FSDEM_OK) {
        fsdem_dem_destroy(dem);
        return NULL;
    }
    return dem;
}

/* The DEM at its stable step (Eq. 32) and the coupler over it, its fractions updated. Returns 0
   and sets *out, or 1 with the reason in `error`. */
static int gic_case_couple(fsdem_pic *pic, fsdem_dem *dem, int virtual_mass, fsdem_gic **out, char *error, size_t size) {
    fsdem_gic_desc gd = fsdem_gic_desc_default();
    fsdem_real dt_dem = 0;
    *out = NULL;
    if (fsdem_dem_stable_dt(dem, &dt_dem) != FSDEM_OK || fsdem_dem_set_dt(dem, dt_dem) != FSDEM_OK) {
        snprintf(error, size, "DEM: %s", fsdem_dem_last_error(dem));
        return 1;
    }
    gd.pic = pic;
    gd.dem = dem;
    gd.virtual_mass = virtual_mass;
    if (fsdem_gic_create(&gd, out) != FSDEM_OK || fsdem_gic_update(*out) != FSDEM_OK) {
        snprintf(error, size, "GIC: %s", *out ? fsdem_gic_last_error(*out) : "create failed");
        return 1;
    }
    return 0;
}

#endif
