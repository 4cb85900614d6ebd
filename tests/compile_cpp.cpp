// Compile-only check: fsdem.h with its implementation builds as C++ without warnings.
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

int fsdem_cpp_smoke();
int fsdem_cpp_smoke() {
    fsdem_dem_desc d = fsdem_dem_desc_default(3);
    return fsdem_dem_desc_check(&d, nullptr, 0) == FSDEM_OK ? 0 : 1;
}
