/* ===== >>config : version, configuration macros, precision-suffixed symbols ======================== */

#include <stddef.h>

#define FSDEM_VERSION_MAJOR 0
#define FSDEM_VERSION_MINOR 9
#define FSDEM_VERSION_PATCH 0
#define FSDEM_VERSION_STRING "0.9.0"

/* Precision-suffixed symbols: with FSDEM_USE_FLOAT every public function X is named X_f, so a float
   and a double build of the library cannot be linked together by mistake. src/pack.sh writes the
   list here from the FSDEM_API declarations; tests/map_check.sh checks it. */
/* FSDEM__SYMBOLS */

#ifndef FSDEM_API
#define FSDEM_API extern
#endif
