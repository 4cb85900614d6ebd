#!/bin/sh
# Builds a header that is fsdem.h plus the work-in-progress sections in wip/:
#   wip/<module>_api.h  is inserted before the public ">>restart" banner (after >>couple_swe),
#   wip/<module>_impl.h is inserted before the ">>impl_restart" banner,
# modules in the alphabetical order of their api files (the impl files follow the same order).
# The float build's symbol block of >>config (FSDEM__SYMBOLS_BEGIN .. _END) is then regenerated
# with tests/map_check.sh --symbols, so the new FSDEM_API functions get their "_f" names.
# Usage: sh wip/merge.sh OUT   (e.g. build/merged/fsdem.h; compile tests with -Ibuild/merged first)
set -eu
out=${1:?usage: merge.sh OUT}
here=$(dirname "$0")
mkdir -p "$(dirname "$out")"
apis=$(ls "$here"/*_api.h 2>/dev/null || true)
impls=""
for f in $apis; do impls="$impls ${f%_api.h}_impl.h"; done
awk -v apis="$apis" -v impls="$impls" '
  function emit(list,   n, i, parts, l) {
    n = split(list, parts, /[ \n]+/)
    for (i = 1; i <= n; i++) if (parts[i] != "") { while ((getline l < parts[i]) > 0) print l; close(parts[i]); print "" }
  }
  /^\/\* ===== >>restart : / { emit(apis) }
  /^\/\* ===== >>impl_restart : / { emit(impls) }
  { print }
' "$here/../fsdem.h" > "$out.tmp"
sh "$here/../tests/map_check.sh" --symbols "$out.tmp" > "$out.symbols"
awk -v symfile="$out.symbols" '
  /FSDEM__SYMBOLS_BEGIN/ { armed = 1 }
  armed && /^#ifdef FSDEM_USE_FLOAT$/ { armed = 0; skip = 1; while ((getline l < symfile) > 0) print l; next }
  skip && /^#endif$/ { skip = 0; next }
  skip { next }
  { print }
' "$out.tmp" > "$out"
rm -f "$out.tmp" "$out.symbols"
