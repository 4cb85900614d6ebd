#!/bin/sh
# Builds a header that is fsdem.h plus the work-in-progress sections in wip/:
#   wip/<module>_api.h  is inserted before the public ">>io" banner,
#   wip/<module>_impl.h is inserted before the ">>impl_io" banner,
# modules in the alphabetical order of their api files (the impl files follow the same order).
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
  /^\/\* ===== >>io : / { emit(apis) }
  /^\/\* ===== >>impl_io : / { emit(impls) }
  { print }
' "$here/../fsdem.h" > "$out"
