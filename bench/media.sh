#!/usr/bin/env bash
# Participating media: what they cost and how fast their noise falls, and
# what they cost the path tracer on scenes without them.
#
#  1. Samples/s (--stats-json samples_per_s, median of ROUNDS interleaved
#     runs, SIZE x SIZE, SPP samples per pixel, all cores) and instructions
#     per sample under callgrind (one thread, 32x32; the difference between
#     a 20 and a 4 spp run over the 16 x 32 x 32 samples between them, so that
#     reading the scene and building it do not count: a figure that the
#     other loads of a shared machine do not change) of the scenes of
#     bench/media_scenes.py, written to a temporary folder: a Cornell-style
#     room filled with homogeneous fog, a procedural 256^3 smoke plume (a
#     .vol grid) in the same room, the same plume replaced by a homogeneous
#     medium of the grid's mean extinction (the cost of a heterogeneous
#     medium against a homogeneous one), and a subsurface bunny (a
#     dielectric of index 1.3 around a scattering interior; needs
#     SHARED/scenes/bench/stanford-bunny.obj, skipped without it).
#  2. Noise at equal time: relMSE (bench/imgstat.py) of --time T renders of
#     1-spp passes against a REF_SPP reference of the same scene, for each T
#     of TIMES.
#  3. With a second program BASE (e.g. one built before media existed): the
#     path tracer on scenes without media, CornellBox-Original and Sponza
#     with a light (SHARED/scenes; skipped without them), BASE and PAPRSEK
#     alternated in each round: medians of samples/s, the median of the
#     per-round ratios, instructions per sample under callgrind (as in 1,
#     64x64, 2 and 6 spp) and whether the two images are byte-identical.
#
# No figure is asserted: the script fails only when a render fails.
# usage: bench/media.sh [PAPRSEK [BASE [SHARED]]]
# environment: ROUNDS (5), SIZE (128), SPP (16), TIMES ("2 8"; 0: skip part 2), REF_SPP (1024),
# GRID (256: the smoke grid's resolution), CALLGRIND (1; 0: skip callgrind),
# KEEP (a folder: keep the scenes and images there instead of a temporary one)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
bin=${1:-$repo/build/paprsek}
base=${2:-}
shared=${3:-$repo/../shared}
rounds=${ROUNDS:-5}; size=${SIZE:-128}; spp=${SPP:-16}; times=${TIMES:-2 8}; ref_spp=${REF_SPP:-1024}
grid=${GRID:-256}; callgrind=${CALLGRIND:-1}
die() { echo "media.sh: $*" >&2; exit 1; }
[ -x "$bin" ] || die "no program at $bin"
[ -z "$base" ] || [ -x "$base" ] || die "no program at $base"
if [ -n "${KEEP:-}" ]; then tmp=$KEEP; mkdir -p "$tmp"; else
    tmp=$(mktemp -d)
    trap 'rm -rf "$tmp"' EXIT
fi
if [ "$callgrind" = 1 ] && ! command -v valgrind >/dev/null; then
    echo "valgrind is not installed: no instruction counts"
    callgrind=0
fi
field() { /usr/bin/python3 -c 'import json, sys; print(json.load(sys.stdin)[sys.argv[1]])' "$1"; }
median() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
range() { tr ' ' '\n' | grep . | sort -g | awk 'NR == 1 { lo = $1 } { hi = $1 } END { printf "%.3g-%.3g", lo, hi }'; }
# samples/s of one render: PROGRAM SCENE OUT [options]
rate() {
    local p=$1 s=$2 o=$3
    shift 3
    "$p" render "$s" -o "$o" --quiet --no-denoise --stats-json "$tmp/stats.json" "$@" >/dev/null 2>"$tmp/err" ||
        die "$p render $s $* failed: $(cat "$tmp/err")"
    field samples_per_s <"$tmp/stats.json"
}
# instructions per sample under callgrind: PROGRAM SCENE W H SPP_LO SPP_HI [options]
instr() {
    local p=$1 s=$2 w=$3 h=$4 lo=$5 hi=$6 n
    shift 6
    local i=()
    for n in "$lo" "$hi"; do
        valgrind --tool=callgrind --callgrind-out-file=/dev/null "$p" render "$s" -o "$tmp/cg.pfm" --quiet \
            --no-denoise --width "$w" --height "$h" --spp "$n" --threads 1 "$@" >/dev/null 2>"$tmp/cg" ||
            die "callgrind $p render $s $* failed: $(tail -3 "$tmp/cg")"
        i+=("$(awk '/Collected/ { print $4 }' "$tmp/cg")")
    done
    awk -v a="${i[0]}" -v b="${i[1]}" -v n=$((w * h * (hi - lo))) 'BEGIN { printf "%.0f", (b - a) / n }'
}

echo "- machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores;" \
    "load average at the start: $(cut -d' ' -f1-3 /proc/loadavg)"
commit() { git -C "$(dirname "$1")" rev-parse --short HEAD 2>/dev/null || echo "commit unknown"; }
echo "- program: $bin ($(commit "$bin"); the HEAD of the git tree it lies in)${base:+; base: $base ($(commit "$base"))}"
bunny_obj=$shared/scenes/bench/stanford-bunny.obj
if [ -f "$bunny_obj" ]; then
    stats=$(/usr/bin/python3 "$here/media_scenes.py" "$tmp" "$grid" "$bunny_obj")
    scenes="fog smoke smoke_hom bunny"
else
    echo "- no $bunny_obj: the subsurface bunny is skipped"
    stats=$(/usr/bin/python3 "$here/media_scenes.py" "$tmp" "$grid")
    scenes="fog smoke smoke_hom"
fi
read -r mean peak <<<"$stats"
echo "- smoke grid: ${grid}^3, mean density $mean over its box, greatest $peak"
label() {
    case $1 in
    fog) echo "fog box (homogeneous)" ;;
    smoke) echo "smoke plume (${grid}^3 grid)" ;;
    smoke_hom) echo "the plume's box, homogeneous of the mean density" ;;
    bunny) echo "subsurface bunny" ;;
    esac
}

# 1. samples/s and instructions per sample
declare -A rates ins
for ((r = 1; r <= rounds; r++)); do
    for s in $scenes; do
        rates[$s]+=" $(rate "$bin" "$tmp/$s.json" "$tmp/$s.pfm" --width "$size" --height "$size" --spp "$spp" --seed "$r")"
    done
done
if [ "$callgrind" = 1 ]; then
    for s in $scenes; do ins[$s]=$(instr "$bin" "$tmp/$s.json" 32 32 4 20); done
fi
echo
echo "| scene | samples/s (median, ${size}x${size}, $spp spp, $rounds runs) | range | instructions/sample (callgrind) |"
echo "|---|---:|---|---:|"
declare -A med
for s in $scenes; do
    med[$s]=$(echo "${rates[$s]}" | median)
    printf "| %s | %.0f | %s | %s |\n" "$(label "$s")" "${med[$s]}" "$(echo "${rates[$s]}" | range)" "${ins[$s]:--}"
done
awk -v g="${med[smoke]}" -v h="${med[smoke_hom]}" -v ig="${ins[smoke]:-0}" -v ih="${ins[smoke_hom]:-0}" 'BEGIN {
    printf "\ncost per sample, grid / homogeneous of the same mean: %.2f by time", h / g
    if (ih > 0) printf ", %.2f by instructions", ig / ih
    printf "\n" }'

# 2. noise at equal time
if [ "$times" != 0 ]; then
    echo
    echo "| scene | reference | --time [s] | passes (1 spp) | relMSE | relMSE x time |"
    echo "|---|---|---:|---:|---:|---:|"
    for s in $scenes; do
        rate "$bin" "$tmp/$s.json" "$tmp/$s-ref.pfm" --width "$size" --height "$size" --spp "$ref_spp" --seed 1000 >/dev/null
        for t in $times; do
            "$bin" render "$tmp/$s.json" -o "$tmp/$s-t.pfm" --quiet --no-denoise --width "$size" --height "$size" \
                --spp 1 --time "$t" --seed 7 --stats-json "$tmp/stats.json" >/dev/null 2>"$tmp/err" ||
                die "$s --time $t failed: $(cat "$tmp/err")"
            passes=$(($(field rays_camera <"$tmp/stats.json") / (size * size)))
            e=$(/usr/bin/python3 "$here/imgstat.py" relmse "$tmp/$s-t.pfm" "$tmp/$s-ref.pfm")
            awk -v l="$(label "$s")" -v rs="$ref_spp" -v t="$t" -v p="$passes" -v e="$e" 'BEGIN {
                printf "| %s | %d spp | %g | %s | %.4g | %.4g |\n", l, rs, t, p, e, e * t }'
        done
    done
fi

# 3. the path tracer without media, before and after
[ -n "$base" ] || exit 0
cornell=$shared/scenes/cornell/CornellBox-Original.obj
sponza=$shared/scenes/bench/dabrovic-sponza/sponza.obj
if [ ! -f "$cornell" ] || [ ! -f "$sponza" ]; then
    echo "- no $cornell or $sponza: the comparison without media is skipped"
    exit 0
fi
cat >"$tmp/sponza.json" <<EOF_JSON
{"materials": {"sun": {"kd": [0, 0, 0], "ke": [60, 55, 45]}},
 "camera": {"look_from": [-10, 2, 0], "look_at": [10, 4, 0], "fov": 60},
 "meshes": [{"obj": "$sponza"}],
 "spheres": [{"center": [0, 9, 0], "radius": 0.8, "material": "sun"}]}
EOF_JSON
cam=(--look-from '0,1,3.9' --look-at '0,1,0' --fov 39.3)
declare -A pr
for ((r = 1; r <= rounds; r++)); do
    for s in cornell sponza; do
        if [ "$s" = cornell ]; then sc=$cornell opts=("${cam[@]}" --spp 8); else sc=$tmp/sponza.json opts=(--spp 4); fi
        if ((r % 2)); then order="base new"; else order="new base"; fi
        for w in $order; do
            if [ "$w" = base ]; then p=$base; else p=$bin; fi
            pr[$s-$w]+=" $(rate "$p" "$sc" "$tmp/$s-$w.pfm" --integrator path --width 512 --height 512 --seed 1 "${opts[@]}")"
        done
        pr[$s-ratio]+=" $(awk -v a="${pr[$s-new]##* }" -v b="${pr[$s-base]##* }" 'BEGIN { print a / b }')"
    done
done
echo
echo "| path, no media (512x512) | base samples/s | new samples/s | new / base (median, range of rounds) | instructions/sample base | new | new / base | same image |"
echo "|---|---:|---:|---|---:|---:|---:|---|"
for s in cornell sponza; do
    if [ "$s" = cornell ]; then sc=$cornell opts=("${cam[@]}"); name=CornellBox-Original; else
        sc=$tmp/sponza.json opts=(); name="Sponza with a light"; fi
    ib=- in=- q=-
    if [ "$callgrind" = 1 ]; then
        ib=$(instr "$base" "$sc" 64 64 2 6 --integrator path "${opts[@]}")
        in=$(instr "$bin" "$sc" 64 64 2 6 --integrator path "${opts[@]}")
        q=$(awk -v a="$in" -v b="$ib" 'BEGIN { printf "%.3f", a / b }')
    fi
    same=no
    cmp -s "$tmp/$s-base.pfm" "$tmp/$s-new.pfm" && same=yes
    printf "| %s | %.0f | %.0f | %.3f (%s) | %s | %s | %s | %s |\n" "$name" "$(echo "${pr[$s-base]}" | median)" \
        "$(echo "${pr[$s-new]}" | median)" "$(echo "${pr[$s-ratio]}" | median)" "$(echo "${pr[$s-ratio]}" | range)" \
        "$ib" "$in" "$q" "$same"
done
echo "- load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
