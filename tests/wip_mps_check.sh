#!/bin/sh
# Builds and runs the "mps" suite against the header merged with wip/ (sh wip/merge.sh), until the
# MPS module is merged into fsdem.h: compile checks (gcc and clang, C99, double and float,
# -Werror; g++ and clang++), the map check of the merged header, then the suite in double and in
# float. Usage: sh tests/wip_mps_check.sh   (from the repository root; FSDEM_TEST_VERBOSE=1 prints
# the measured figures)
set -eu
B=build/wip_mps
mkdir -p $B
sh wip/merge.sh build/merged/fsdem.h
WARN="-Wall -Wextra -Wpedantic -Werror"
for c in gcc clang; do
  command -v $c >/dev/null || continue
  for v in "" "-DFSDEM_USE_FLOAT" "-DFSDEM_NO_SIMD"; do
    $c -std=c99 $WARN -O2 $v -Ibuild/merged -c tests/fsdem_impl.c -o $B/impl_check.o
  done
done
for c in g++ clang++; do
  command -v $c >/dev/null || continue
  $c $WARN -O2 -Ibuild/merged -c tests/compile_cpp.cpp -o $B/compile_cpp.o
done
sh tests/map_check.sh build/merged/fsdem.h
cat > $B/main.c <<'MAIN'
/* Runs the mps suite only. */
#include <stdlib.h>
#include "fsdem_tests.h"
Suite *mps_suite(void);
int main(void) {
    SRunner *runner = srunner_create(mps_suite());
    int failed;
    srunner_run_all(runner, CK_NORMAL);
    failed = srunner_ntests_failed(runner);
    srunner_free(runner);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
MAIN
CHECK_CFLAGS=$(pkg-config --cflags check 2>/dev/null || true)
CHECK_LIBS=$(pkg-config --libs check 2>/dev/null || echo -lcheck -lsubunit -lrt -lpthread -lm)
for v in "" "-DFSDEM_USE_FLOAT"; do
  gcc -std=c99 -Wall -Wextra -Wpedantic -O2 -g $v $CHECK_CFLAGS -Ibuild/merged -Itests \
    tests/test_mps.c $B/main.c tests/fsdem_impl.c -o $B/check_mps $CHECK_LIBS -lm
  echo "mps suite ${v:-(double)}:"
  $B/check_mps
done
