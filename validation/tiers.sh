#!/bin/sh
# validation/tiers.sh - runs validation cases in a tier, records what each run was run on, and renders
# the reports (validation/README.md describes the whole scheme). The Makefile calls it; by hand:
#
#   sh validation/tiers.sh run TIER CASE OUT_ROOT DATA_DIR
#       runs build/validation/CASE/run --tier=TIER in OUT_ROOT/CASE/ (emptied first): stdout to
#       checks.txt, stderr to log.txt, then the plots (validation/CASE/plot.gp, when gnuplot is
#       installed) and meta.txt (tier, commit, fingerprints, CPU and wall time, exit status).
#       Writes nothing outside OUT_ROOT. Prints a summary of the case; exits 0 whatever the result.
#   sh validation/tiers.sh publish TIER OUT_ROOT
#       copies the record of every case run in OUT_ROOT (checks.txt, meta.txt, the plots) and its
#       run.txt into validation/report-TIER/ (the committed record of the tier), replacing those
#       cases' earlier records only.
#   sh validation/tiers.sh render TIER SRC_ROOT OUT_MD [IMG_PREFIX]
#       writes the Markdown report OUT_MD from the cases in SRC_ROOT/*/meta.txt; plots are linked as
#       IMG_PREFIX<case>/<png> (IMG_PREFIX: the path from OUT_MD's folder to SRC_ROOT, with a slash).
#   sh validation/tiers.sh verdict OUT_ROOT CASE...
#       one line of totals for the cases named; exits 1 when one of them failed (a CHECK FAIL, a crash,
#       or no result).
#   sh validation/tiers.sh status
#       every case of both committed reports: current, or stale (and why) against the working tree
#       and against HEAD.
#   sh validation/tiers.sh fingerprint CASE [FSDEM_H]
#       prints `solver=<hash> case=<hash>`: the hash (cksum) of the fsdem.h chapters the case
#       depends on (validation/CASE/DEPENDS: >>tags; each tag's public chapter and its >>impl_tag
#       chapter, plus the >>impl preamble) and of the case's own code (its .c and .h files, the
#       validation headers they include, and DEPENDS).
#   sh validation/tiers.sh order TIER CASE...
#       the cases, longest first by the wall time of their last run in validation/report-TIER/
#       (cases without one first, in the order given): the order `make -j2` starts them in.
#
# Run it from the top of the repository (the Makefile does).
set -u
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/.." && pwd)

die() { echo "tiers.sh: $*" >&2; exit 2; }
scratch=$(mktemp -d "${TMPDIR:-/tmp}/tiers.XXXXXX") || die "cannot make a scratch folder"
trap 'rm -rf "$scratch"' EXIT

# ---- fingerprints ----

# "tag hash" for every chapter tag of fsdem.h (the hash of the text of >>tag and >>impl_tag; for
# "impl", of the >>impl preamble alone), computed once per fsdem.h into the scratch folder.
hash_chapters() { # fsdem_h
    out="$scratch/hashes.$(echo "$1" | cksum | cut -d' ' -f1)"
    if [ ! -f "$out" ]; then
        mkdir -p "$scratch/chapters"
        rm -f "$scratch/chapters"/*
        awk -v dir="$scratch/chapters" '
            /===== >>[a-z_]+ :/ {
                if (file != "") close(file)
                match($0, />>[a-z_]+/); tag = substr($0, RSTART + 2, RLENGTH - 2)
                base = tag; if (tag != "impl") sub(/^impl_/, "", base)
                file = dir "/" base
            }
            file != "" { print >> file }' "$1"
        for f in "$scratch/chapters"/*; do
            echo "$(basename "$f") $(cksum <"$f" | awk '{ print $1 "-" $2 }')"
        done >"$out"
    fi
    echo "$out"
}

# "tag:hash" for the >>impl preamble and each tag of DEPENDS, comma-separated.
chapter_hashes() { # deps_file fsdem_h
    awk -v tags="impl $(cat "$1")" 'NR == FNR { h[$1] = $2; next }
        END { n = split(tags, t, " "); for (i = 1; i <= n; i++) printf "%s%s:%s", (i > 1 ? "," : ""), t[i], h[t[i]]; print "" }' \
        "$(hash_chapters "$2")" /dev/null
}

# The case's code: its .c and .h files and, transitively, the validation headers they include.
case_files() { # case
    todo=$(ls "$here/$1"/*.c "$here/$1"/*.h 2>/dev/null)
    seen=""
    while [ -n "$todo" ]; do
        set -- $todo
        f=$1
        shift
        todo="$*"
        case " $seen " in *" $f "*) continue ;; esac
        seen="$seen $f"
        for inc in $(sed -n 's/^#include "\(.*\)"/\1/p' "$f"); do
            for cand in "$(dirname "$f")/$inc" "$here/$inc"; do
                if [ -f "$cand" ]; then
                    todo="$todo $(cd "$(dirname "$cand")" && pwd)/$(basename "$cand")"
                    break
                fi
            done
        done
    done
    for f in $seen; do echo "$f"; done | sort
}

fingerprint() { # case [fsdem_h]
    deps="$here/$1/DEPENDS"
    [ -f "$deps" ] || die "validation/$1/DEPENDS is missing (the >>tags of fsdem.h the case depends on)"
    chapters=$(chapter_hashes "$deps" "${2:-$top/fsdem.h}")
    solver=$(echo "$chapters" | cksum | awk '{ print $1 "-" $2 }')
    code=$( (for f in $(case_files "$1"); do cat "$f"; done; cat "$deps") | cksum | awk '{ print $1 "-" $2 }')
    echo "solver=$solver case=$code chapters=$chapters"
}

# value of key in a meta.txt
meta() { sed -n "s/^$2=//p" "$1" | head -n 1; }

# a file with the recorded "tag:hash" entries of a meta.txt, one a line (for grep -f)
meta_list() {
    meta "$1" chapters_fp | tr , '\n' >"$scratch/recorded"
    echo "$scratch/recorded"
}

# ---- run one case ----

run_case() { # tier case out_root data_dir
    tier=$1 name=$2 out="$3/$2" data=$4
    bin="$top/build/validation/$name/run"
    [ -x "$bin" ] || die "$bin is not built (make $bin)"
    mkdir -p "$out"
    # a fresh folder, but the default tier's holds the program itself
    find "$out" -maxdepth 1 -type f ! -name run ! -name '*.o' -exec rm -f {} +
    commit=$(cd "$top" && git rev-parse --short HEAD 2>/dev/null || echo unknown)
    dirty=0
    if [ "$commit" != unknown ] && [ -n "$(cd "$top" && git status --porcelain -- . ':(exclude)validation/report-default' \
        ':(exclude)validation/report-full' ':(exclude)validation/REPORT-default.md' ':(exclude)validation/REPORT-full.md' \
        2>/dev/null)" ]; then dirty=1; fi
    fp=$(fingerprint "$name")
    echo "== $name: started ($tier tier)"
    start=$(date +%s.%N)
    (cd "$out" && "$bin" "$data" --tier="$tier" >checks.txt 2>log.txt)
    rc=$?
    end=$(date +%s.%N)
    plots=""
    if [ -f "$here/$name/plot.gp" ]; then
        if command -v gnuplot >/dev/null 2>&1; then
            (cd "$out" && gnuplot "$here/$name/plot.gp") >"$out/plot.log" 2>&1 || plots="gnuplot failed (plot.log)"
        else plots="gnuplot is not installed: no plots (sudo apt-get install -y gnuplot-nox)"; fi
    fi
    {
        echo "case=$name"
        echo "tier=$tier"
        echo "commit=$commit"
        echo "dirty=$dirty"
        echo "date=$(date -u +%Y-%m-%dT%H:%MZ)"
        echo "rc=$rc"
        awk -v s="$start" -v e="$end" 'BEGIN { printf "wall_s=%.1f\n", e - s }'
        sed -n 's/^TIME [^ ]* cpu_s=\([^ ]*\).*/cpu_s=\1/p' "$out/checks.txt" | tail -n 1
        sed -n 's/^TIER [^ ]* tier=[^ ]* resolution=/resolution=/p' "$out/checks.txt" | head -n 1
        echo "depends=$(cat "$here/$name/DEPENDS")"
        for kv in $fp; do echo "${kv%%=*}_fp=${kv#*=}"; done
        echo "cores=$(nproc 2>/dev/null || echo unknown)"
        [ -n "$plots" ] && echo "plots=$plots"
    } >"$out/meta.txt"
    awk -v name="$name" -v rc="$rc" -v wall="$(meta "$out/meta.txt" wall_s)" -v cpu="$(meta "$out/meta.txt" cpu_s)" '
        $1 == "CHECK" { n++; if ($NF != "PASS") { bad++; fails = fails "   " $0 "\n" } }
        $1 == "INFO" && / \(full tier\)$/ { full++ }
        END {
            printf "== %s: %d of %d checks pass%s, %d full-tier lines; wall %s s, CPU %s s%s\n", name, n - bad, n,
                   bad ? " (" bad " FAIL)" : "", full, wall, cpu == "" ? "?" : cpu, rc == 0 ? "" : ", exit status " rc
            printf "%s", fails
        }' "$out/checks.txt"
    return 0
}

# ---- publish ----

# The records of the cases run in out_root into the committed report of the tier.
publish() { # tier out_root
    tier=$1 root=$2
    for m in "$root"/*/meta.txt; do
        [ -f "$m" ] || continue
        out=$(dirname "$m")
        rec="$here/report-$tier/$(basename "$out")"
        rm -rf "$rec"
        mkdir -p "$rec"
        cp "$out/checks.txt" "$out/meta.txt" "$rec/"
        # the plots, in 32 colours when ImageMagick is there (a third of the size: they are committed)
        for p in "$out"/*.png; do
            [ -f "$p" ] || continue
            if command -v convert >/dev/null 2>&1; then convert "$p" -strip -colors 32 "PNG8:$rec/$(basename "$p")" 2>/dev/null; fi
            [ -s "$rec/$(basename "$p")" ] || cp "$p" "$rec/"
        done
        echo "published $(basename "$out") into validation/report-$tier/"
    done
    [ ! -f "$root/run.txt" ] || cp "$root/run.txt" "$here/report-$tier/run.txt"
}

# ---- verdict ----

verdict() { # out_root case...
    root=$1
    shift
    bad=0 n=0 checks=0 fails=0
    for c in "$@"; do
        n=$((n + 1))
        m="$root/$c/meta.txt"
        if [ ! -f "$m" ]; then
            echo "   $c: no result"
            bad=1
            continue
        fi
        [ "$(meta "$m" rc)" = 0 ] || bad=1
        checks=$((checks + $(grep -c '^CHECK ' "$root/$c/checks.txt")))
        fails=$((fails + $(grep '^CHECK ' "$root/$c/checks.txt" | grep -vc ' PASS$')))
    done
    echo "$n cases, $checks checks, $fails FAIL"
    return $bad
}

# ---- staleness ----

# "current", or why the record in a case folder is stale (computed once per record and call)
staleness() { # case_dir
    cache="$scratch/stale.$(echo "$1" | cksum | cut -d' ' -f1)"
    [ -f "$cache" ] || staleness_of "$1" >"$cache"
    cat "$cache"
}

# Why the fingerprints of a record differ from those of the tree under `root` (fsdem.h and
# validation/ there), or nothing when they agree.
changes_in() { # meta root name
    now=$(here="$2/validation"; top="$2"; fingerprint "$3")
    why=""
    if [ "solver=$(meta "$1" solver_fp)" != "$(echo "$now" | cut -d' ' -f1)" ]; then
        # name the chapters that changed (or, when the list of chapters changed, all of them)
        changed=$(echo "$now" | cut -d' ' -f3 | sed 's/^chapters=//' | tr , '\n' | grep -vxF -f "$(meta_list "$1")" |
            sed 's/:.*//; s/^/>>/' | paste -s -d' ' -)
        why="fsdem.h changed (${changed:-the chapters of DEPENDS})"
    fi
    [ "case=$(meta "$1" case_fp)" = "$(echo "$now" | cut -d' ' -f2)" ] || why="${why:+$why; }the case's code changed"
    echo "$why"
}

# The committed tree (fsdem.h and validation/ at HEAD), unpacked once; nothing outside git.
head_tree() {
    if [ ! -e "$scratch/head.done" ]; then
        mkdir -p "$scratch/head"
        (cd "$top" && git archive HEAD fsdem.h validation 2>/dev/null) | tar -x -C "$scratch/head" 2>/dev/null
        touch "$scratch/head.done"
    fi
    [ -f "$scratch/head/fsdem.h" ] && echo "$scratch/head"
}

# A record is stale when its fingerprints differ from the working tree's (the code it would run on
# now) or from HEAD's (the code committed with it).
staleness_of() { # case_dir
    m="$1/meta.txt"
    name=$(meta "$m" case)
    if [ ! -f "$here/$name/main.c" ]; then echo "stale: the case no longer exists"; return; fi
    if [ ! -f "$here/$name/DEPENDS" ]; then echo "stale: validation/$name/DEPENDS is missing"; return; fi
    why=$(changes_in "$m" "$top" "$name")
    head=$(head_tree)
    if [ -z "$why" ] && [ -n "$head" ] && [ -f "$head/validation/$name/DEPENDS" ]; then
        why=$(changes_in "$m" "$head" "$name")
        [ -z "$why" ] || why="at HEAD: $why"
    fi
    if [ -n "$why" ]; then echo "stale: $why since $(meta "$m" commit)"; else echo current; fi
}

status() {
    for tier in default full; do
        echo "== validation/REPORT-$tier.md"
        found=0
        for d in "$here/report-$tier"/*/; do
            [ -f "$d/meta.txt" ] || continue
            found=1
            printf '   %-26s %s%s  %s\n' "$(meta "$d/meta.txt" case)" "$(meta "$d/meta.txt" commit)" \
                "$( [ "$(meta "$d/meta.txt" dirty)" = 1 ] && echo '+' )" "$(staleness "$d")"
        done
        [ $found = 1 ] || echo "   (no case recorded)"
    done
}

# ---- report ----

# One case of a report, from its meta.txt and checks.txt: its row of the summary table (mode=row) or
# its section (mode=block). Variables: st (staleness), tier, img (the plots' path prefix), pngs.
case_awk='
function value(line, k,   a, v) { split(line, a, " "); v = a[k]; sub(/^[a-z]+=/, "", v); return v }
FNR == NR { i = index($0, "="); if (i) m[substr($0, 1, i - 1)] = substr($0, i + 1); next }
$1 == "CHECK" { nc++; if ($NF != "PASS") f++; check[nc] = $0; next }
$1 == "INFO" && / \(full tier\)$/ { full[++nf] = $0; next }
$1 == "INFO" { sub(/^INFO [^ ]* /, ""); info[++ni] = $0 }
END {
    name = m["case"]
    if (mode == "row") {
        counts = sprintf("%d/%d%s", nc - f, nc, f ? " (**" f " FAIL**)" : "")
        if (m["rc"] != "0" && !f) counts = counts ", **exit status " m["rc"] "**"
        printf "| [%s](#%s) | %s | %s%s | %s | %s | %s | %s |\n", name, name, m["resolution"], m["commit"],
               m["dirty"] == "1" ? " +" : "", m["cpu_s"], m["wall_s"], counts, st == "current" ? "current" : "**stale**"
        exit
    }
    printf "\n## %s\n\n", name
    printf "Ran on %s%s, %s, %s tier: %s. CPU %s s, wall %s s, exit status %s. Depends on fsdem.h: %s.\n", m["commit"],
           m["dirty"] == "1" ? " (+ uncommitted changes)" : "", m["date"], m["tier"], m["resolution"], m["cpu_s"], m["wall_s"],
           m["rc"], m["depends"]
    if (st != "current") {
        i = index(st, ":")
        printf "\n**%s**:%s; re-run it (`make validate%s CASES=%s`).\n", substr(st, 1, i - 1), substr(st, i + 1),
               tier == "full" ? "-full" : "", name
    }
    if (m["plots"] != "") printf "\nPlots: %s.\n", m["plots"]
    printf "\n| metric | value | ref | tol | result |\n|---|---|---|---|---|\n"
    for (k = 1; k <= nc; k++) {
        split(check[k], a, " ")
        printf "| %s | %s | %s | %s | %s |\n", a[3], value(check[k], 4), value(check[k], 5), value(check[k], 6),
               a[7] == "PASS" ? "PASS" : "**" a[7] "**"
    }
    if (nf) printf "\nLines of the full tier, with this tier%ss figures:\n\n", "\047"
    for (k = 1; k <= nf; k++) {
        split(full[k], a, " ")
        if (value(full[k], 4) == "nan")
            printf "- `%s`: not evaluated in this tier (it needs the full tier\047s runs); ref %s, tol %s\n", a[3],
                   value(full[k], 5), value(full[k], 6)
        else printf "- `%s`: %s (ref %s, tol %s)\n", a[3], value(full[k], 4), value(full[k], 5), value(full[k], 6)
    }
    if (ni) printf "\n"
    for (k = 1; k <= ni; k++) printf "- %s\n", info[k]
    np = split(pngs, p, "\n")
    if (np) printf "\n"
    for (k = 1; k <= np; k++) printf "![%s %s](%s%s/%s)\n", name, p[k], img, name, p[k]
}'

render() { # tier src_root out_md [img_prefix]
    tier=$1 src=$2 out=$3 img=${4:-}
    tmp="$out.tmp"
    {
        echo "# fsdem.h validation report: $tier tier"
        echo
        if [ "$tier" = full ]; then
            echo "The full tier (\`make validate-full\`): every case at the seeds' resolutions and with the fine runs;"
            echo "hours of CPU, run case by case (\`make validate-full CASES=...\` replaces only those cases' blocks)."
        else
            echo "The default tier (\`make validate\`): every case at the resolution that keeps the whole tier within"
            echo "20 minutes of wall time on 2 cores (\`make -j2 validate\`). A line that needs the full tier's"
            echo "resolution is printed as \`INFO ... (full tier)\` here, never as PASS."
        fi
        echo
        echo "Each row of a CHECK table passes when |value - ref| <= tol. Case descriptions, references and the"
        echo "reasons for each tolerance and resolution: validation/<case>/README.md; the scheme: validation/README.md."
        echo "Each case's block names the commit it ran on (\"+\": with uncommitted changes). A block is **stale**"
        echo "when the fsdem.h chapters its case depends on (validation/<case>/DEPENDS) or the case's own code"
        echo "changed since that run (\`make validate-status\` lists them)."
        echo
        if [ -f "$src/run.txt" ]; then
            echo "Last complete run of the tier: $(cat "$src/run.txt")."
            echo
        fi
        missing=""
        for c in "$here"/*/main.c; do
            c=$(basename "$(dirname "$c")")
            [ -f "$src/$c/meta.txt" ] || missing="$missing${missing:+, }$c"
        done
        if ! ls "$src"/*/meta.txt >/dev/null 2>&1; then
            echo "No case has been run in this tier yet."
        else
            [ -z "$missing" ] || { echo "Not run in this tier yet: $missing."; echo; }
            echo "| case | resolution | commit | CPU s | wall s | checks | status |"
            echo "|---|---|---|---|---|---|---|"
        fi
    } >"$tmp"
    ncase=0
    for d in "$src"/*/; do
        [ -f "$d/meta.txt" ] || continue
        awk -v mode=row -v st="$(staleness "$d")" "$case_awk" "$d/meta.txt" "$d/checks.txt" >>"$tmp"
        ncase=$((ncase + 1))
    done
    [ $ncase -gt 0 ] && {
        echo
        awk -v n="$ncase" -v tier="$tier" '
            FILENAME ~ /meta.txt$/ { if (sub(/^cpu_s=/, "")) cpu += $0; else if (sub(/^wall_s=/, "")) wall += $0; next }
            $1 == "CHECK" { c++; if ($NF == "PASS") p++ }
            $1 == "INFO" && / \(full tier\)$/ { full++ }
            END { printf "**%d case%s: %d of %d checks pass**%s. CPU %.0f s, wall %.0f s (case by case, summed).\n", n, n == 1 ? "" : "s",
                          p, c, tier == "default" ? sprintf("; %d full-tier lines (INFO here)", full) : "", cpu, wall }' \
            "$src"/*/meta.txt "$src"/*/checks.txt
        fails=$(grep -h '^CHECK ' "$src"/*/checks.txt 2>/dev/null | grep -v ' PASS$')
        if [ -n "$fails" ]; then
            echo
            echo "Failing checks:"
            echo
            echo "$fails" | awk '{ v = $4; r = $5; t = $6; sub(/^value=/, "", v); sub(/^ref=/, "", r); sub(/^tol=/, "", t)
                printf "- %s `%s`: %s (ref %s, tol %s)\n", $2, $3, v, r, t }'
        fi
    } >>"$tmp"
    for d in "$src"/*/; do
        [ -f "$d/meta.txt" ] || continue
        awk -v mode=block -v st="$(staleness "$d")" -v tier="$tier" -v img="$img" \
            -v pngs="$(cd "$d" && ls *.png 2>/dev/null)" "$case_awk" "$d/meta.txt" "$d/checks.txt" >>"$tmp"
    done
    mv "$tmp" "$out"
}

# ---- order ----

order() { # tier case...
    tier=$1
    shift
    for c in "$@"; do
        m="$here/report-$tier/$c/meta.txt"
        w=1e9
        [ -f "$m" ] && w=$(meta "$m" wall_s)
        echo "$w $c"
    done | sort -s -g -r -k1,1 | awk '{ printf "%s ", $2 } END { print "" }'
}

cmd=${1:-}
[ $# -gt 0 ] && shift
case "$cmd" in
run) [ $# -eq 4 ] || die "usage: run TIER CASE OUT_ROOT DATA_DIR"; run_case "$@" ;;
publish) [ $# -eq 2 ] || die "usage: publish TIER OUT_ROOT"; publish "$@" ;;
render) [ $# -ge 3 ] || die "usage: render TIER SRC_ROOT OUT_MD [IMG_PREFIX]"; render "$@" ;;
verdict) [ $# -ge 1 ] || die "usage: verdict OUT_ROOT CASE..."; verdict "$@" ;;
status) status ;;
fingerprint) [ $# -ge 1 ] || die "usage: fingerprint CASE [FSDEM_H]"; fingerprint "$@" ;;
order) [ $# -ge 1 ] || die "usage: order TIER CASE..."; order "$@" ;;
*) die "usage: tiers.sh run|publish|render|verdict|status|fingerprint|order ... (see the comment at its top)" ;;
esac
