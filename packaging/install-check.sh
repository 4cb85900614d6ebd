#!/bin/sh
# `make install-check`: installs fsdem into a temporary prefix and builds a small program against
# the installed tree, once with `pkg-config --cflags --libs fsdem` and once with CMake's
# find_package(fsdem CONFIG REQUIRED), then runs both. Also checks a staged install (DESTDIR).
# Environment: MAKE, CC (default cc), CMAKE (default cmake), PKG_CONFIG (default pkg-config).
set -eu
cd "$(dirname "$0")/.."
MAKE=${MAKE:-make}
CC=${CC:-cc}
CMAKE=${CMAKE:-cmake}
PKG_CONFIG=${PKG_CONFIG:-pkg-config}
for tool in "$CC" "$CMAKE" "$PKG_CONFIG"; do
  command -v "$tool" >/dev/null || { echo "install-check: $tool is missing (sudo apt-get install -y cmake pkg-config)"; exit 1; }
done
version=$(sed -n 's/^#define FSDEM_VERSION_STRING "\(.*\)"$/\1/p' fsdem.h)
[ -n "$version" ] || { echo "install-check: no FSDEM_VERSION_STRING in fsdem.h"; exit 1; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/fsdem-install-check.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
prefix=$tmp/prefix

# 1. install into the prefix; a staged install (DESTDIR) puts the same files under the stage
"$MAKE" --no-print-directory -s install PREFIX="$prefix" DESTDIR=
"$MAKE" --no-print-directory -s install PREFIX=/opt/fsdem DESTDIR="$tmp/stage"
for f in include/fsdem.h lib/pkgconfig/fsdem.pc lib/cmake/fsdem/fsdemConfig.cmake lib/cmake/fsdem/fsdemConfigVersion.cmake; do
  [ -f "$prefix/$f" ] || { echo "install-check: $prefix/$f was not installed"; exit 1; }
  [ -f "$tmp/stage/opt/fsdem/$f" ] || { echo "install-check: DESTDIR install lacks /opt/fsdem/$f"; exit 1; }
done
grep -q '^prefix=/opt/fsdem$' "$tmp/stage/opt/fsdem/lib/pkgconfig/fsdem.pc" ||
  { echo "install-check: a DESTDIR install must name the final prefix in fsdem.pc"; exit 1; }
cmp -s fsdem.h "$prefix/include/fsdem.h" || { echo "install-check: installed fsdem.h differs"; exit 1; }

# 2. pkg-config (built at -O0: the header's implementation takes ~15 s to compile at -O2)
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
got=$("$PKG_CONFIG" --modversion fsdem)
[ "$got" = "$version" ] || { echo "install-check: pkg-config reports $got, fsdem.h says $version"; exit 1; }
flags=$("$PKG_CONFIG" --cflags --libs fsdem)
echo "install-check: pkg-config --cflags --libs fsdem: $flags"
# shellcheck disable=SC2086 # the flags are words
"$CC" -std=c99 -Wall -Wextra -Wpedantic -Werror -O0 -DEXPECTED_VERSION="\"$version\"" -DHOW='"pkg-config"' \
  packaging/install-check/main.c -o "$tmp/hello_pkgconfig" $flags

# 3. CMake: find_package(fsdem CONFIG REQUIRED) with CMAKE_PREFIX_PATH
"$CMAKE" -S packaging/install-check -B "$tmp/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_C_COMPILER="$CC" -DEXPECTED_VERSION="$version" >"$tmp/cmake.log" 2>&1 ||
  { cat "$tmp/cmake.log"; echo "install-check: CMake configuration failed"; exit 1; }
"$CMAKE" --build "$tmp/cmake-build" >"$tmp/build.log" 2>&1 ||
  { cat "$tmp/build.log"; echo "install-check: CMake build failed"; exit 1; }

# 4. run both
"$tmp/hello_pkgconfig"
"$tmp/cmake-build/hello_cmake"
echo "install-check: fsdem $version installs and is found by pkg-config and CMake"
