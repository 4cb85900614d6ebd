/* packaging/install-check/main.c: the program `make install-check` builds against an installed
   fsdem (once through pkg-config, once through CMake's find_package). It includes the installed
   header (this folder has no fsdem.h), compiles the implementation here, creates a DEM, takes a
   step and destroys it, and checks the header's version against the one the package reported. */
#define FSDEM_IMPLEMENTATION
#include <fsdem.h>

#include <stdio.h>
#include <string.h>

#ifndef EXPECTED_VERSION
#error "build with -DEXPECTED_VERSION=\"x.y.z\" (the version the package reports)"
#endif
#ifndef HOW
#define HOW "?"
#endif

int main(void) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem *dem;
    int mat;
    if (strcmp(FSDEM_VERSION_STRING, EXPECTED_VERSION) != 0) {
        fprintf(stderr, "install-check (%s): header %s, package %s\n", HOW, FSDEM_VERSION_STRING, EXPECTED_VERSION);
        return 1;
    }
    if (fsdem_dem_create(&d, &dem) != FSDEM_OK) return 1;
    p.radius = 0.01;
    if (fsdem_dem_add_material(dem, &m, &mat) != FSDEM_OK || fsdem_dem_add_particle(dem, &p, NULL) != FSDEM_OK ||
        fsdem_dem_step(dem) != FSDEM_OK) {
        fprintf(stderr, "install-check (%s): %s\n", HOW, fsdem_dem_last_error(dem));
        fsdem_dem_destroy(dem);
        return 1;
    }
    printf("install-check (%s): fsdem %s, a DEM created, stepped to t = %g s and destroyed\n", HOW,
           FSDEM_VERSION_STRING, fsdem_dem_time(dem));
    fsdem_dem_destroy(dem);
    return 0;
}
