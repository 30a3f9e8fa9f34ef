#!/usr/bin/env bash
# gpu_render.sh - the path tracer on the GPU (--device cuda) against the CPU
# (all cores, --accel bvh and embree) on CornellBox-Original, Sponza with an
# area light and Bitterli's Cornell box: samples per second (camera samples,
# each a whole path) at WIDTH x HEIGHT. Prints a markdown table.
#
# usage: bench/gpu_render.sh [SHARED_DIR [PAPRSEK]]
# environment: WIDTH, HEIGHT (1024), GPU_SPP (1024), CPU_SPP (16), OUT (images, default bench/out/gpu)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
shared=${1:-$repo/../shared}
bin=${2:-$repo/build/paprsek}
w=${WIDTH:-1024}; h=${HEIGHT:-1024}
gspp=${GPU_SPP:-1024}; cspp=${CPU_SPP:-16}
out=${OUT:-$here/out/gpu}
mkdir -p "$out"
field() { sed -n "s/.*\"$1\": *\([0-9.e+-]*\).*/\1/p" | head -1; }
echo "| scene | GPU samples/s | GPU time (spp) | CPU bvh samples/s | CPU embree samples/s | GPU / CPU bvh |"
echo "|---|---|---|---|---|---|"
for sc in "$shared/scenes/cornell/CornellBox-Original.obj" "$repo/bench/sponza-area-light.json" \
          "$shared/scenes/bitterli/cornell-box/scene_v3.xml"; do
    name=$(basename "$(dirname "$sc")")-$(basename "$sc" | sed 's/\.[a-z]*$//')
    g=$("$bin" render "$sc" --device cuda --width "$w" --height "$h" --spp "$gspp" --stats-json - -o "$out/$name-gpu.png" 2>"$out/$name-gpu.err") || g=
    c=$("$bin" render "$sc" --accel bvh --width "$w" --height "$h" --spp "$cspp" --stats-json - -o "$out/$name-cpu.png" 2>/dev/null) || c=
    e=$("$bin" render "$sc" --accel embree --width "$w" --height "$h" --spp "$cspp" --stats-json - -o "$out/$name-emb.png" 2>/dev/null) || e=
    gs=$(echo "$g" | field samples_per_s); gt=$(echo "$g" | field render_s)
    cs=$(echo "$c" | field samples_per_s); es=$(echo "$e" | field samples_per_s)
    awk -v n="$name" -v gs="$gs" -v gt="$gt" -v sp="$gspp" -v cs="$cs" -v es="$es" -v err="$(head -1 "$out/$name-gpu.err")" 'BEGIN {
        printf "| %s | %s | %s | %s | %s | %s |\n", n, gs == "" ? "fail: " err : sprintf("%.0f M", gs / 1e6),
            gt == "" ? "-" : sprintf("%.2f s (%d)", gt, sp), cs == "" ? "n/a" : sprintf("%.1f M", cs / 1e6),
            es == "" ? "n/a" : sprintf("%.1f M", es / 1e6), (gs == "" || cs == "") ? "-" : sprintf("%.0fx", gs / cs) }'
done
