#!/usr/bin/env bash
# gpu_variants.sh - the GPU traversal kernel on the standard workloads of
# spec/ray-benchmark.md at SIZE x SIZE rays: kernel Grays/s, and whether its
# hits agree with the CPU's (--accel bvh: closest hits bit for bit, any hits
# on hit or miss). The CPU traces each ray file once; only the GPU runs are
# repeated. Prints a markdown table; raw lines stay in bench/out/gpu_variants/.
#
# It used to time ten kernel versions and several GPU trees against each
# other (PAPRSEK_CUDA_KERNEL, PAPRSEK_CUDA_TREE); after those measurements
# (docs/gpu.md, docs/performance.md) the versions but the default and the
# reference one left the product, and the switches with them. They are in
# the history at commit 51a7231 (the last with them), with this script as it
# ran them: build that commit to measure them again.
#
# usage: bench/gpu_variants.sh [SHARED_DIR [PAPRSEK]]   (defaults: ../shared, build/paprsek)
# environment: SIZE (4096), REPS (3), THREADS (0 = all cores),
#              WORKLOADS (cornell-sphere bunny sponza), KINDS (primary diffuse diffuse-any)
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
shared=${1:-$repo/../shared}
bin=${2:-$repo/build/paprsek}
size=${SIZE:-4096}
reps=${REPS:-3}
threads=${THREADS:-0}
[ -z "${VARIANTS:-}" ] || [ "${VARIANTS}" = default ] ||
    { echo "gpu_variants.sh: the kernel versions were removed; build commit 51a7231 to time them" >&2; exit 2; }
variants=default
workloads=${WORKLOADS:-cornell-sphere bunny sponza}
kinds=${KINDS:-primary diffuse diffuse-any}
out=$here/out/gpu_variants
mkdir -p "$out"
rm -f "$out/err.log"
die() { echo "gpu_variants.sh: $*" >&2; exit 1; }
[ -x "$bin" ] || die "$bin is not there"

. "$here/workloads.sh"

echo "## GPU kernel: kernel Grays/s (hits agree with the CPU's: ok, or the number that differ)"
echo
echo "- GPU: $(nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader 2>/dev/null || echo unknown)"
echo "- ${size}x${size} rays, $reps passes (median kernel time)"
echo
printf '| workload |'; for v in $variants; do printf ' %s |' "$v"; done; echo
printf '|---|'; for v in $variants; do printf -- '---|'; done; echo
for wl in $workloads; do
    scene=$(scene_of "$wl")
    for kind in $kinds; do
        base=${kind%-any}
        rays=$out/$wl-$base-$size.rays
        any=; [ "$kind" != "$base" ] && any=--any-hit
        if [ ! -s "$rays" ]; then
            "$bin" bench gen-rays --workload "$wl" --shared "$shared" --size "$size" --kind "$base" --seed 1 \
                --threads "$threads" -o "$rays" 2>"$out/gen.err" || { echo "| $wl $kind | (no rays: $(head -1 "$out/gen.err")) |"; continue; }
        fi
        c=$("$bin" bench rays "$scene" "$rays" --accel bvh --threads "$threads" --reps 1 $any --hits "$out/cpu.hits" 2>>"$out/err.log") || c=
        echo "$wl $kind CPU $c" >>"$out/raw.txt"
        row="| $wl $kind |"
        for v in $variants; do
            g=$("$bin" bench rays "$scene" "$rays" --accel cuda --reps "$reps" $any --hits "$out/gpu.hits" 2>>"$out/err.log") || g=
            echo "$wl $kind $v $g" >>"$out/raw.txt"
            kg=$(echo "$g" | field kernel_mrays_per_s)
            if [ -z "$kg" ]; then
                row="$row fail |"
                continue
            fi
            cmp=$("$bin" bench compare "$out/cpu.hits" "$out/gpu.hits" $any --rays "$rays" 2>/dev/null || true)
            echo "$wl $kind $v compare $cmp" >>"$out/raw.txt"
            ag=$(echo "$cmp" | field agree)
            [ "$ag" = yes ] && ag=ok || ag="$(echo "$cmp" | field mismatches) differ"
            row="$row $(awk -v k="$kg" 'BEGIN { printf "%.2f", k / 1000 }') ($ag) |"
            rm -f "$out/gpu.hits"
        done
        echo "$row"
        rm -f "$out/cpu.hits"
    done
    rm -f "$out/$wl"-*.rays
done
echo
echo "Grays/s: 10^9 rays per second of kernel time (CUDA events). Closest hits must agree bit for bit"
echo "(t, triangle, u, v); any hits on hit or miss."
if [ -s "$out/err.log" ]; then
    echo
    echo "Messages (counted):"
    sort "$out/err.log" | uniq -c | sort -rn | head -5
fi
