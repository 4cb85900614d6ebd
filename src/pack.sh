#!/bin/sh
# Writes the single-file library fsdem.h from the files of src/ (`make fsdem.h` runs it).
#
#   sh src/pack.sh [OUT]          write the header to OUT (default: standard output)
#   sh src/pack.sh --locate LINE  name the source file and line of fsdem.h's line LINE
#
# The header is: the documentation block; the public half (config first, then every module's
# declarations inside extern "C" for C++), guarded by FSDEM_H_INCLUDED; the implementation, in the
# order of the public half, inside #ifdef FSDEM_IMPLEMENTATION; the licence. Files are joined with
# one blank line. The order below is the order of the map (`grep -n '>>' fsdem.h`): a chapter may
# use only what comes before it. Adding a file to src/ means adding it here (src/README.md).
set -eu
caller=$(pwd)
cd "$(dirname "$0")"

PUBLIC="
    core/core.h geom/geom.h kernel/kernel.h grid/grid.h
    dem/dem.h linalg/linalg.h pic/pic.h swe/swe.h mps/mps.h drag/drag.h
    couple/couple.h couple/swe.h couple/mps.h couple/pic.h couple/gic.h restart/restart.h couple/step.h io/io.h"

IMPLEMENTATION="
    impl.c
    core/core.c core/gauges.c core/lane.c core/claims.c
    geom/geom.c
    kernel/kernel.c
    grid/grid.c
    dem/types.c dem/desc.c dem/law.c dem/periodic.c dem/object.c dem/wall.c dem/neighbours.c
    dem/forces.c dem/integrate.c dem/diagnostics.c
    linalg/types.c linalg/check.c linalg/object.c linalg/grid.c linalg/kernels.c linalg/mg.c
    linalg/ic.c linalg/amg.c linalg/setup.c linalg/solve.c
    pic/types.c pic/desc.c pic/geometry.c pic/particles.c pic/transfer.c pic/cells.c
    pic/extrapolate.c pic/viscosity.c pic/projection.c pic/advection.c pic/reseed.c pic/step.c
    pic/views.c pic/output.c
    swe/types.c swe/desc.c swe/object.c swe/sources.c swe/riemann.c swe/row.c swe/step.c swe/diag.c
    mps/types.c mps/desc.c mps/particles.c mps/open.c mps/neighbours.c mps/operators.c mps/explicit.c mps/step.c
    mps/views.c mps/probes.c
    drag/drag.c
    couple/head.c couple/dem.c couple/records.c couple/swe.c couple/mps.c couple/pic.c couple/gic.c
    restart/format.c restart/dem.c restart/pic.c restart/swe.c restart/mps.c restart/couplers.c restart/api.c
    restart/journal.c
    couple/step.c
    io/csv.c io/vtk.c io/pvd.c io/dem.c io/pic.c io/swe.c"

# The float build's names (>>config): "#define X X_f" for every public function X, between the
# FSDEM__SYMBOLS_BEGIN and _END comments, in place of the line "/* FSDEM__SYMBOLS */".
symbols() {
    echo "/* FSDEM__SYMBOLS_BEGIN (written by src/pack.sh) */"
    echo "#ifdef FSDEM_USE_FLOAT"
    awk '/^FSDEM_API / { line = $0; while (line !~ /\(/) { getline nxt; line = line " " nxt }
                        sub(/\(.*/, "", line); n = split(line, w, /[ *]+/); print w[n] }' $PUBLIC |
        LC_ALL=C sort | awk '{ print "#define " $0 " " $0 "_f" }'
    echo "#endif"
    echo "/* FSDEM__SYMBOLS_END */"
}

# put FILE: the file's lines; line TEXT: one line the packer writes itself. With LOCATE set, each
# line is prefixed with where it comes from ("src/dem/law.c:12", "src/pack.sh").
put() {
    [ -r "$1" ] || { echo "pack.sh: src/$1 is missing" >&2; exit 1; }
    awk -v f="src/$1" -v locate="${LOCATE:-}" '
        function out(where, text) { if (locate != "") print where "\t" text; else print text }
        $0 == "/* FSDEM__SYMBOLS */" { n = split(ENVIRON["SYMBOLS"], s, "\n"); for (i = 1; i <= n; ++i) out("src/pack.sh", s[i]); next }
        { out(f ":" FNR, $0) }' "$1"
}
line() {
    if [ -n "${LOCATE:-}" ]; then printf 'src/pack.sh\t%s\n' "$1"; else printf '%s\n' "$1"; fi
}
files() { for f in $1; do line ""; put "$f"; done; }

header() {
    put doc.h
    line "#ifndef FSDEM_H_INCLUDED"
    line "#define FSDEM_H_INCLUDED"
    line ""
    put core/config.h
    line ""
    line "#ifdef __cplusplus"
    line 'extern "C" {'
    line "#endif"
    files "$PUBLIC"
    line ""
    line "#ifdef __cplusplus"
    line "}"
    line "#endif"
    line "#endif /* FSDEM_H_INCLUDED */"
    line ""
    line "#ifdef FSDEM_IMPLEMENTATION"
    line "#ifndef FSDEM_IMPLEMENTATION_DONE"
    line "#define FSDEM_IMPLEMENTATION_DONE"
    files "$IMPLEMENTATION"
    line ""
    line "#endif /* FSDEM_IMPLEMENTATION_DONE */"
    line "#endif /* FSDEM_IMPLEMENTATION */"
    line ""
    put licence.h
}

SYMBOLS=$(symbols)
export SYMBOLS
case "${1:-}" in
--locate)
    n=${2:?usage: pack.sh --locate LINE}
    LOCATE=1 header | awk -v n="$n" 'NR == n { sub(/\t.*/, ""); print; found = 1; exit }
                                      END { if (!found) { print "pack.sh: fsdem.h has no line " n; exit 1 } }' ;;
"") header ;;
*)
    out=$1
    case $out in /*) ;; *) out="$caller/$out" ;; esac
    header > "$out.tmp" && mv "$out.tmp" "$out" ;;
esac
