#!/usr/bin/env bash
# run.sh - Paprsek's default BVH against Embree 3 on the standard workloads of
# spec/ray-benchmark.md (primary and diffuse rays, closest hit; diffuse rays
# and shadow rays toward the area lights, any hit), timed interleaved in one
# run on this machine, with a check that both find the same hits. Prints the
# machine and a markdown table; raw numbers stay in bench/out/.
#
# usage: bench/run.sh [SHARED_DIR [PAPRSEK]]   (defaults: ../shared, build/paprsek)
# environment: ROUNDS (5), THREADS (2), REPS (5 timed passes per run),
#              SIZE (1024, image side of the ray files), WORKLOADS ("cornell-sphere bunny sponza")
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
shared=${1:-$repo/../shared}
bin=${2:-$repo/build/paprsek}
rounds=${ROUNDS:-5}
threads=${THREADS:-2}
reps=${REPS:-5}
size=${SIZE:-1024}
workloads=${WORKLOADS:-cornell-sphere bunny sponza}
out=$here/out

die() { echo "run.sh: $*" >&2; exit 1; }
[ -x "$bin" ] || die "$bin is not there: build first (make build), or pass the binary as the second argument"
[ -d "$shared/scenes" ] || die "$shared/scenes is not there: pass the shared folder as the first argument"
mkdir -p "$out"

. "$here/workloads.sh"

# ---- machine -----------------------------------------------------------------
cpu=$(awk -F': ' '/^model name/ { print $2; exit }' /proc/cpuinfo 2>/dev/null || true)
embree_version=$(dpkg-query -W -f='${Version}' libembree-dev 2>/dev/null || echo unknown)
echo "## Ray tracing: Paprsek vs Embree"
echo
echo "- machine: ${cpu:-unknown CPU}, $(nproc) cores online, $(uname -srm)"
echo "- paprsek: $(git -C "$repo" rev-parse --short HEAD 2>/dev/null || echo unknown), $bin"
echo "- embree: $embree_version (libembree-dev)"
echo "- $threads threads, $rounds rounds interleaved, $reps timed passes per run (median), ${size}x${size} ray files"
echo "- started $(date -u '+%Y-%m-%d %H:%M UTC')"
echo

# ---- ray files (made once) ----------------------------------------------------
for wl in $workloads; do
    scene=$(scene_of "$wl")
    [ -r "$scene" ] || die "$scene is not there"
    for kind in primary diffuse shadow; do
        rays=$out/$wl-$kind-$size.rays
        if [ ! -s "$rays" ] && [ ! -e "$rays.none" ]; then
            echo "making $rays" >&2
            if ! "$bin" bench gen-rays "$scene" --workload "$wl" --shared "$shared" --size "$size" --kind "$kind" \
                --seed 1 --threads "$threads" -o "$rays" 2>"$out/gen.err"; then
                # shadow rays need area lights: a scene without them has none
                [ "$kind" = shadow ] && grep -q "no area light" "$out/gen.err" && : >"$rays.none" && continue
                cat "$out/gen.err" >&2
                die "gen-rays $wl $kind failed"
            fi
        fi
    done
done

# the kinds of a workload: closest hit on primary and diffuse rays; any hit
# (occlusion) on diffuse rays and, where the scene has area lights, on shadow rays
kinds_for() {
    echo primary diffuse diffuse-any
    [ -s "$out/$1-shadow-$size.rays" ] && echo shadow-any
    return 0
}
rays_of() { echo "$out/$1-${2%-any}-$size.rays"; }
anyhit_of() { case $1 in *-any) echo --any-hit ;; esac; }

# ---- is Embree built in? -------------------------------------------------------
first=${workloads%% *}
have_embree=1
if ! "$bin" bench rays "$(scene_of "$first")" "$out/$first-primary-$size.rays" --accel embree --reps 1 \
    --threads "$threads" >/dev/null 2>"$out/embree-check.err"; then
    have_embree=0
    echo "(Embree is not available: $(head -1 "$out/embree-check.err"))"
    echo
fi

# configurations: name accel quality flags
configs_for() {
    echo "bvh bvh - -"
    [ $have_embree = 1 ] && echo "emb_m embree medium -" && echo "emb_h embree high -"
    if [ "$1" = primary ]; then
        echo "bvh_pk bvh - --packets"
        [ $have_embree = 1 ] && echo "emb_m_pk embree medium --packets" && echo "emb_h_pk embree high --packets"
    fi
    return 0
}

# ---- timed runs, interleaved: every configuration once per round ---------------
raw=$out/results-$(date -u +%Y%m%d-%H%M%S).txt
: >"$raw"
for ((r = 1; r <= rounds; r++)); do
    echo "round $r/$rounds" >&2
    for wl in $workloads; do
        scene=$(scene_of "$wl")
        for kind in $(kinds_for "$wl"); do
            rays=$(rays_of "$wl" "$kind")
            any=$(anyhit_of "$kind")
            while read -r name accel quality flags; do
                hitsopt=()
                [ "$r" = 1 ] && hitsopt=(--hits "$out/$wl-$kind.$name.hits")
                flagopt=()
                [ "$flags" != - ] && flagopt=("$flags")
                if [ "$quality" != - ]; then export PAPRSEK_EMBREE_QUALITY=$quality; else unset PAPRSEK_EMBREE_QUALITY; fi
                line=$("$bin" bench rays "$scene" "$rays" --accel "$accel" --threads "$threads" --reps "$reps" \
                    $any "${flagopt[@]}" "${hitsopt[@]}" 2>>"$out/stderr.log") || die "bench rays $wl $kind $name failed (see $out/stderr.log)"
                unset PAPRSEK_EMBREE_QUALITY
                echo "$wl $kind $name $r $(echo "$line" | field rays) $(echo "$line" | field mrays_per_s) $(echo "$line" | field build_ms) $(echo "$line" | field hits)" >>"$raw"
            done < <(configs_for "$kind")
        done
    done
done

# ---- agreement of the hit files (round 1) --------------------------------------
agree_of() {
    local wl=$1 kind=$2 a=$3 b=$4 res
    [ -f "$out/$wl-$kind.$a.hits" ] && [ -f "$out/$wl-$kind.$b.hits" ] || { echo n/a; return; }
    res=$("$bin" bench compare "$out/$wl-$kind.$a.hits" "$out/$wl-$kind.$b.hits" $(anyhit_of "$kind") \
        --rays "$(rays_of "$wl" "$kind")" 2>/dev/null || true)
    local ok mis near
    ok=$(echo "$res" | field agree)
    mis=$(echo "$res" | field mismatches)
    near=$(echo "$res" | field near_origin)
    echo "${ok:-error} (${mis:-?} differ, ${near:-0} at origin)"
}

# ---- table -----------------------------------------------------------------------
echo "| workload | rays | Paprsek Mrays/s | Embree Mrays/s | Paprsek/Embree | Paprsek packets | Embree packets | packets ratio | build ms Paprsek | build ms Embree | hits agree |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for wl in $workloads; do
    for kind in $(kinds_for "$wl"); do
        if [ $have_embree = 1 ]; then
            agree=$(agree_of "$wl" "$kind" bvh emb_m)
        else
            agree=n/a
        fi
        awk -v wl="$wl" -v kind="$kind" -v agree="$agree" '
            function median(list,   a, n, i, j, t) {
                n = split(list, a, " ")
                for (i = 2; i <= n; i++) { t = a[i]; for (j = i - 1; j >= 1 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
                return n == 0 ? "" : (n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2)
            }
            $1 == wl && $2 == kind { rate[$3] = rate[$3] " " $6; build[$3] = build[$3] " " $7; rays = $5 }
            END {
                for (c in rate) { mr[c] = median(rate[c]); mb[c] = median(build[c]) }
                p = mr["bvh"]
                e = ""; eq = ""
                if ("emb_m" in mr) { e = mr["emb_m"]; eq = "emb_m" }
                if ("emb_h" in mr && mr["emb_h"] > e) { e = mr["emb_h"]; eq = "emb_h" }
                pp = ("bvh_pk" in mr) ? mr["bvh_pk"] : ""
                ep = ""
                if ("emb_m_pk" in mr) ep = mr["emb_m_pk"]
                if ("emb_h_pk" in mr && mr["emb_h_pk"] > ep) ep = mr["emb_h_pk"]
                qname = eq == "emb_h" ? "high" : "medium"
                printf "| %s %s | %d | %.2f | %s | %s | %s | %s | %s | %.1f | %s | %s |\n", wl, kind, rays, p,
                    e == "" ? "n/a" : sprintf("%.2f (%s)", e, qname),
                    e == "" ? "n/a" : sprintf("%.2f", p / e),
                    pp == "" ? "-" : sprintf("%.2f", pp),
                    ep == "" ? "-" : sprintf("%.2f", ep),
                    (pp == "" || ep == "") ? "-" : sprintf("%.2f", pp / ep),
                    mb["bvh"],
                    e == "" ? "n/a" : sprintf("%.1f", mb[eq]),
                    agree
            }' "$raw"
    done
done
echo
echo "Mrays/s: median over the rounds of each run's median pass. Embree: the better of build quality"
echo "medium and high (its build ms is that quality's). Raw numbers: ${raw#"$repo"/}"
