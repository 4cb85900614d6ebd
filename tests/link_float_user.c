/* A translation unit built with FSDEM_USE_FLOAT, to be linked against an implementation built
   without it: the link must fail (every public function is fsdem_..._f here), never run with
   mismatched types. `make compile-checks` checks that it does. */
#define FSDEM_USE_FLOAT
#include "fsdem.h"

int main(void) {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    fsdem_dem *dem = 0;
    if (fsdem_dem_create(&d, &dem) != FSDEM_OK) return 1;
    fsdem_dem_destroy(dem);
    return 0;
}
