#!/usr/bin/env bash
# gpu.sh - the GPU accelerator (--accel cuda) against the CPU (--accel bvh and
# Embree, all cores) on the standard workloads of spec/ray-benchmark.md at
# SIZE x SIZE rays (default 4096: 16.7 M rays per file), closest hit on
# primary and diffuse rays and any hit on diffuse and shadow rays. Checks that
# the GPU's hits agree with the CPU's. Prints a markdown table; raw lines stay
# in bench/out/.
#
# usage: bench/gpu.sh [SHARED_DIR [PAPRSEK]]   (defaults: ../shared, build/paprsek)
# environment: SIZE (4096), REPS (5), THREADS (0 = all cores), WORKLOADS
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
shared=${1:-$repo/../shared}
bin=${2:-$repo/build/paprsek}
size=${SIZE:-4096}
reps=${REPS:-5}
threads=${THREADS:-0}
workloads=${WORKLOADS:-cornell-sphere bunny sponza}
out=$here/out/gpu
mkdir -p "$out"
die() { echo "gpu.sh: $*" >&2; exit 1; }
[ -x "$bin" ] || die "$bin is not there"

. "$here/workloads.sh"

echo "## GPU traversal: --accel cuda against the CPU"
echo
echo "- GPU: $(nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader 2>/dev/null || echo unknown)"
echo "- CPU: $(awk -F': ' '/^model name/ { print $2; exit }' /proc/cpuinfo), $(nproc) cores; ${size}x${size} rays, $reps passes (median)"
echo
echo "| workload | rays | GPU kernel Grays/s | GPU end to end Mrays/s | CPU bvh Mrays/s | Embree Mrays/s | kernel / Embree | hits agree (GPU vs bvh) |"
echo "|---|---|---|---|---|---|---|---|"
for wl in $workloads; do
    scene=$(scene_of "$wl")
    for kind in primary diffuse diffuse-any shadow-any; do
        base=${kind%-any}
        rays=$out/$wl-$base-$size.rays
        any=; [ "$kind" != "$base" ] && any=--any-hit
        if [ ! -s "$rays" ]; then
            "$bin" bench gen-rays --workload "$wl" --shared "$shared" --size "$size" --kind "$base" --seed 1 \
                --threads "$threads" -o "$rays" 2>"$out/gen.err" || { echo "| $wl $kind | (no rays: $(head -1 "$out/gen.err")) |"; continue; }
        fi
        g=$("$bin" bench rays "$scene" "$rays" --accel cuda --reps "$reps" $any --hits "$out/gpu.hits" 2>>"$out/err.log") || g=
        c=$("$bin" bench rays "$scene" "$rays" --accel bvh --threads "$threads" --reps "$reps" $any --hits "$out/cpu.hits" 2>>"$out/err.log") || c=
        e=$(PAPRSEK_EMBREE_QUALITY=high "$bin" bench rays "$scene" "$rays" --accel embree --threads "$threads" --reps "$reps" $any 2>>"$out/err.log") || e=
        echo "$wl $kind GPU $g" >>"$out/raw.txt"; echo "$wl $kind CPU $c" >>"$out/raw.txt"; echo "$wl $kind EMB $e" >>"$out/raw.txt"
        cmp=$("$bin" bench compare "$out/cpu.hits" "$out/gpu.hits" $any --rays "$rays" 2>&1 || true)
        n=$(echo "$g" | field rays)
        kg=$(echo "$g" | field kernel_mrays_per_s); eg=$(echo "$g" | field mrays_per_s)
        cm=$(echo "$c" | field mrays_per_s); em=$(echo "$e" | field mrays_per_s)
        awk -v wl="$wl" -v kind="$kind" -v n="$n" -v kg="$kg" -v eg="$eg" -v cm="$cm" -v em="$em" \
            -v ag="$(echo "$cmp" | field agree) ($(echo "$cmp" | field mismatches) differ)" 'BEGIN {
            printf "| %s %s | %s | %s | %s | %s | %s | %s | %s |\n", wl, kind, n,
                kg == "" ? "fail" : sprintf("%.2f", kg / 1000), eg == "" ? "fail" : sprintf("%.0f", eg),
                cm == "" ? "n/a" : sprintf("%.1f", cm), em == "" ? "n/a" : sprintf("%.1f", em),
                (kg == "" || em == "") ? "-" : sprintf("%.0fx", kg / em), ag }'
        rm -f "$out/gpu.hits" "$out/cpu.hits"
    done
    rm -f "$out/$wl"-*.rays
done
echo
echo "Grays/s: 10^9 rays per second of kernel time (CUDA events; the BVH already on the GPU, rays"
echo "uploaded and hits downloaded outside it). End to end: the whole pk_accel_trace call."
