#!/bin/sh
# The map of fsdem.h is exact: `grep -n '>>' fsdem.h` is the table of contents, so this check (run by
# `make test`) fails when
#   - a >>tag banner is defined twice;
#   - a header chapter has no implementation chapter >>impl_<tag>, or the implementation chapters
#     are not in the order of the header chapters;
#   - a >>tag named anywhere (a reference such as "(>>dem_law)") names no banner;
#   - the table of contents of >>doc does not list every chapter of the header half;
#   - an implementation chapter does not open with a contents comment naming its subsections;
#   - a subsection (or a chapter without subsections) runs over MAX_LINES lines;
#   - the float build's precision-suffixed symbol list (>>config) differs from the FSDEM_API functions;
#   - a public enum value breaks FSDEM_<ENUM>_<VALUE> (fsdem_result's codes excepted, as >>doc says);
#   - the objects of the verb table in >>doc ("ONE DIALECT FOR EVERY SOLVER") are not exactly those
#     with a create and a step, or one of them lacks a verb of the table (couplers: and get_force);
#   - a stable_dt takes a non-const object;
#   - the coupling chapter or a coupler (>>impl_couple, >>impl_couple_*) calls a private helper of
#     the DEM, PIC, MPS or SWE or reads a field of a solver object: couplers speak to the solvers
#     through their public calls;
# and, where the header is generated from src/ (src/pack.sh beside it), when
#   - the header differs from what `make fsdem.h` writes from src/;
#   - a file of src/ is not packed (not listed in src/pack.sh), runs over MAX_FILE_LINES lines, or
#     does not open with its >>tag banner.
# Usage: sh tests/map_check.sh [fsdem.h]          check
#        sh tests/map_check.sh --symbols [fsdem.h] print the symbol block for >>config
set -u
mode=check
if [ "${1:-}" = "--symbols" ]; then mode=symbols; shift; fi
file=${1:-fsdem.h}
[ -r "$file" ] || { echo "map_check: cannot read $file"; exit 1; }
MAX_FILE_LINES=1500

# the source in rooms: the header is src/ packed, every file of src/ is packed, short, and opens with
# its banner (the documentation block has its banner on its fourth line)
src=$(dirname "$file")/src
if [ "$mode" = check ] && [ -r "$src/pack.sh" ]; then
    if ! sh "$src/pack.sh" | cmp -s - "$file"; then
        echo "map_check: $file differs from what src/ packs into (edit src/, then run: make fsdem.h)"
        sh "$src/pack.sh" | diff "$file" - | head -20 | sed 's/^/  /'
        exit 1
    fi
    for f in $(cd "$src" && find . -name '*.[ch]' | sed 's|^\./||' | LC_ALL=C sort); do
        grep -qE "(^|[ \"])$f( |\"|$)" "$src/pack.sh" || { echo "map_check: src/$f is not packed (list it in src/pack.sh)"; exit 1; }
        lines=$(wc -l < "$src/$f")
        [ "$lines" -le $MAX_FILE_LINES ] || { echo "map_check: src/$f has $lines lines, more than $MAX_FILE_LINES: split it by concept"; exit 1; }
        head -4 "$src/$f" | grep -qE '^(/\*|  ) *(=====|----) >>[a-z_]+ :' ||
            { echo "map_check: src/$f does not open with its >>tag banner"; exit 1; }
    done
fi

# public functions: the name before "(" on each FSDEM_API declaration
api=$(awk '/^FSDEM_API / { line = $0; while (line !~ /\(/) { getline nxt; line = line " " nxt }
            sub(/\(.*/, "", line); n = split(line, w, /[ *]+/); print w[n] }' "$file" | sort)
if [ "$mode" = symbols ]; then
    echo "#ifdef FSDEM_USE_FLOAT"
    for f in $api; do echo "#define $f ${f}_f"; done
    echo "#endif"
    exit 0
fi

awk -v MAX_LINES=600 -v api="$api" '
function fail(msg) { print "map_check: " msg; bad = 1 }
/^(\/\*|  ) *(=====|----) >>[a-z_]+ :/ {
    match($0, />>[a-z_]+/); tag = substr($0, RSTART + 2, RLENGTH - 2)
    if (tag in line_of) fail("tag >>" tag " defined twice (lines " line_of[tag] " and " NR ")")
    line_of[tag] = NR
    chapter_banner = ($0 ~ /=====/)
    # length of the previous section
    if (prev_tag != "" && NR - prev_line > MAX_LINES && !(prev_tag in has_sub))
        fail("section >>" prev_tag " (line " prev_line ") runs " NR - prev_line " lines, more than " MAX_LINES)
    if (chapter_banner) {
        if (tag == "impl") in_impl = 1
        else if (!in_impl) { header[++nh] = tag }
        else if (tag ~ /^impl_/) { impl[++ni] = substr(tag, 6); cur_impl = tag; contents[tag] = "" }
        else cur_impl = ""
        collecting = (tag ~ /^impl_/)
    } else {
        if (cur_impl != "") { sub_of[tag] = cur_impl; has_sub[cur_impl] = 1 }
        collecting = 0
    }
    prev_tag = tag; prev_line = NR
    next
}
# the table of contents of >>doc: its entries "     >>tag   what"
/TABLE OF CONTENTS/ { in_toc = 1 }
in_toc && /CONFIGURATION MACROS/ { in_toc = 0 }
in_toc && /^     >>[a-z_]+ / { match($0, />>[a-z_]+/); toc[substr($0, RSTART + 2, RLENGTH - 2)] = NR }
# the opening comment of an implementation chapter, up to its first code or subsection
collecting && /^[^\/ #]/ { collecting = 0 }
collecting { contents[cur_impl] = contents[cur_impl] " " $0 }
{
    # references: every >>tag in the file
    s = $0
    while (match(s, />>[a-z_]+/)) { ref[substr(s, RSTART + 2, RLENGTH - 2)] = NR; s = substr(s, RSTART + RLENGTH) }
}
END {
    for (r in ref) if (!(r in line_of)) fail("reference >>" r " (line " ref[r] ") names no banner")
    for (h = 1; h <= nh; ++h) if (!(header[h] in toc)) fail("the table of contents of >>doc does not list >>" header[h])
    k = 0
    for (h = 1; h <= nh; ++h) {
        t = header[h]
        if (t == "doc" || t == "config" || t == "licence") continue
        ++k
        if (!(("impl_" t) in line_of)) { fail("header chapter >>" t " has no >>impl_" t); continue }
        if (impl[k] != t) fail("implementation chapter " k " is >>impl_" impl[k] ", the header order wants >>impl_" t)
    }
    for (i = 1; i <= ni; ++i) {
        c = "impl_" impl[i]
        if (contents[c] !~ /Contents/) fail(">>" c " does not open with a contents comment")
    }
    for (t in sub_of) {
        c = sub_of[t]
        if (index(contents[c], ">>" t) == 0) fail("the contents of >>" c " do not list >>" t)
    }
    if (bad) exit 1
}' "$file" || exit 1

# the symbol block of >>config against the public functions
listed=$(awk '/FSDEM__SYMBOLS_BEGIN/ { on = 1 } /FSDEM__SYMBOLS_END/ { on = 0 }
              on && /^#define fsdem_/ { print $2 }' "$file" | sort)
if [ "$listed" != "$api" ]; then
    echo "map_check: the symbol block of >>config differs from the FSDEM_API functions:"
    printf '%s\n' "$api" > /tmp/map_check_api.$$
    printf '%s\n' "$listed" > /tmp/map_check_listed.$$
    diff /tmp/map_check_api.$$ /tmp/map_check_listed.$$ | sed 's/^/  /'
    rm -f /tmp/map_check_api.$$ /tmp/map_check_listed.$$
    echo "  regenerate it with: sh tests/map_check.sh --symbols"
    exit 1
fi
# enum values: FSDEM_<ENUM>_<VALUE> for every public enum but fsdem_result
awk '
function fail(msg) { print "map_check: " msg; bad = 1 }
/^typedef enum fsdem_[a-z][a-z0-9_]* \{/ { name = $3; inenum = (name != "fsdem_result"); prefix = toupper(name) "_"; next }
inenum && /^\}/ { inenum = 0; next }
inenum && /^ *FSDEM_[A-Z0-9_]+ *(= *-?[0-9]+)? *,? *(\/\*.*)?$/ {
    match($0, /FSDEM_[A-Z0-9_]+/); v = substr($0, RSTART, RLENGTH)
    if (index(v, prefix) != 1) fail("enum " name ": value " v " is not " prefix "<VALUE>")
}
END { if (bad) exit 1 }' "$file" || exit 1

# the verb table: its object list against the objects that have a create and a step, and its verbs
listed_objects=$(awk '/Each solver \(fsdem_/ { on = 1 } on { text = text " " $0 } on && /speaks these verbs/ { on = 0 }
                      END { while (match(text, /fsdem_[a-z_]+/)) { print substr(text, RSTART, RLENGTH); text = substr(text, RSTART + RLENGTH) } }' "$file" | sort -u)
stepping=$(for f in $api; do case $f in *_create) o=${f%_create}; echo "$api" | grep -qx "${o}_step" && echo "$o";; esac; done | sort -u)
if [ "$listed_objects" != "$stepping" ]; then
    echo "map_check: the verb table of >>doc lists [$(echo $listed_objects)], the objects with create and step are [$(echo $stepping)]"
    exit 1
fi
verbs="desc_default desc_check create destroy last_error get_desc step step_dt advance stable_dt time get_stats save restore save_memory restore_memory"
for o in $stepping; do
    need=$verbs
    case $o in fsdem_?*_dem | fsdem_gic) need="$need get_force update coupler write_csv";; esac
    for v in $need; do
        echo "$api" | grep -qx "${o}_$v" || { echo "map_check: ${o}_$v is missing (the verb table of >>doc promises it)"; exit 1; }
    done
    echo "$api" | grep -qE "^${o}_write_([a-z]+_)?csv\$" || { echo "map_check: ${o} writes no CSV (${o}_write_csv or _write_<what>_csv)"; exit 1; }
done

# couplers speak to the solvers through their public calls: in the >>impl_couple chapter and the
# >>impl_couple_ chapters (comments aside) no private helper of the DEM, PIC, MPS or SWE
# (fsdem__dem_, fsdem__pic_, fsdem__mps_, fsdem__swe_ other than a coupler's own fsdem__<fluid>_dem_)
# and no field of a solver object (through a pointer declared as fsdem_pic/mps/swe/dem *, or
# desc.<solver>->)
awk '
function fail(msg) { print "map_check: " msg; bad = 1 }
/^\/\* ===== >>impl_/ { coupler = ($0 ~ />>impl_couple[_ ]/); delete ptr; incomment = (index($0, "*/") == 0); next }
!coupler { next }
{
    line = $0
    # comments: drop /* ... */ spans, carrying an open one to the next lines
    if (incomment) { if (match(line, /\*\//)) { line = substr(line, RSTART + 2); incomment = 0 } else next }
    while (match(line, /\/\*/)) {
        rest = substr(line, RSTART + 2)
        if (match(rest, /\*\//)) line = substr(line, 1, index(line, "/*") - 1) " " substr(rest, RSTART + 2)
        else { line = substr(line, 1, index(line, "/*") - 1); incomment = 1 }
    }
    gsub(/"([^"\\]|\\.)*"/, "\"\"", line)   # string literals
    s = line
    while (match(s, /fsdem__(dem|pic|mps|swe)_[a-z0-9_]*/)) {
        name = substr(s, RSTART, RLENGTH); s = substr(s, RSTART + RLENGTH)
        if (name !~ /^fsdem__(pic|mps|swe)_dem_/) fail("line " NR ": a coupler calls the solver-private " name)
    }
    s = line
    while (match(s, /fsdem_(pic|mps|swe|dem) \*(const )?[a-z_][a-z0-9_]*/)) {
        decl = substr(s, RSTART, RLENGTH); s = substr(s, RSTART + RLENGTH)
        n = split(decl, w, /[ *]+/); ptr[w[n]] = 1
    }
    if (match(line, /desc(\.|->)(pic|mps|swe|dem)->/)) fail("line " NR ": a coupler reads a solver field: " substr(line, RSTART, RLENGTH + 12))
    for (v in ptr) if (match(line, "(^|[^a-z0-9_.>])" v "->")) fail("line " NR ": a coupler reads a field of solver object " v ": " substr(line, RSTART, RLENGTH + 12))
}
END { if (bad) exit 1 }' "$file" || exit 1

# queries take a const object: every stable_dt (the state is read, never written; only the message)
# (a list of couplers, fsdem_coupled_stable_dt, is passed as the other verbs of a list take it)
nonconst=$(awk '/^FSDEM_API fsdem_result fsdem_[a-z_]+_stable_dt\(/ && !/_stable_dt\(const / && !/\*const \*/ { print }' "$file")
if [ -n "$nonconst" ]; then echo "map_check: a stable_dt that takes a non-const object: $nonconst"; exit 1; fi

echo "map check: $(grep -c '>>' "$file") map lines, banners unique, order and references resolve, contents listed, symbols complete, enum names and verb table hold, couplers use public calls"
