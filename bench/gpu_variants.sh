#!/usr/bin/env bash
# gpu_variants.sh - the GPU traversal kernel on the standard workloads of
# spec/ray-benchmark.md at SIZE x SIZE rays: kernel Grays/s, and whether its
# hits agree with the CPU's (--accel bvh: closest hits bit for bit, any hits
# on hit or miss). The CPU traces each ray file once; only the GPU runs are
# repeated. Prints a markdown table; raw lines stay in bench/out/gpu_variants/.
#
# VARIANTS names the traversals to time, each TRAVERSAL/LEAF: the
# configuration cuda.traversal=TRAVERSAL,cuda.leaf=LEAF (docs/gpu.md;
# default "sorted/16 ordered/16 sorted/4 ordered/4"). With GPUREF set to the
# textbook kernel's program (../shared/tools/gpuref, built with
# nvcc -O3 -arch=sm_90), it is timed in the same rounds. Each round runs
# every variant once on a ray file (interleaved); the table gives the
# medians over ROUNDS rounds of each run's median of REPS passes.
# (Ten older kernel versions and their switches are in the history at
# commit 51a7231, with this script as it ran them.)
#
# usage: bench/gpu_variants.sh [SHARED_DIR [PAPRSEK]]   (defaults: ../shared, build/paprsek)
# environment: SIZE (4096), REPS (3), ROUNDS (3), THREADS (0 = all cores),
#              WORKLOADS (cornell-sphere bunny sponza), KINDS (primary diffuse diffuse-any),
#              VARIANTS, GPUREF
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
shared=${1:-$repo/../shared}
bin=${2:-$repo/build/paprsek}
size=${SIZE:-4096}
reps=${REPS:-3}
threads=${THREADS:-0}
rounds=${ROUNDS:-3}
variants=${VARIANTS:-sorted/16 ordered/16 sorted/4 ordered/4}
gpuref=${GPUREF:-}
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
echo "- ${size}x${size} rays, $rounds interleaved rounds of $reps passes (median kernel Grays/s)"
echo
cols=$variants; [ -n "$gpuref" ] && cols="$cols textbook"
printf '| workload |'; for v in $cols; do printf ' %s |' "$v"; done; echo
printf '|---|'; for v in $cols; do printf -- '---|'; done; echo
med() { sort -g | awk '{ a[NR] = $1 } END { if (NR) print a[int((NR + 1) / 2)] }'; }
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
        declare -A speeds=() agree=()
        for ((round = 0; round < rounds; round++)); do
            for v in $cols; do
                if [ "$v" = textbook ]; then
                    [ -n "$any" ] && continue
                    g=$("$gpuref" "$scene" "$rays" --reps "$reps" 2>>"$out/err.log") || g=
                    echo "$wl $kind textbook $g" >>"$out/raw.txt"
                    kg=$(echo "$g" | field mrays_per_s)
                    [ -n "$kg" ] && speeds[$v]="${speeds[$v]:-} $kg"
                    continue
                fi
                cfg="cuda.traversal=${v%/*},cuda.leaf=${v#*/}"
                g=$("$bin" bench rays "$scene" "$rays" --accel cuda --config "$cfg" --reps "$reps" $any \
                    --hits "$out/gpu.hits" 2>>"$out/err.log") || g=
                echo "$wl $kind $v $g" >>"$out/raw.txt"
                kg=$(echo "$g" | field kernel_mrays_per_s)
                [ -n "$kg" ] || continue
                speeds[$v]="${speeds[$v]:-} $kg"
                if [ "$round" = 0 ]; then
                    cmp=$("$bin" bench compare "$out/cpu.hits" "$out/gpu.hits" $any --rays "$rays" 2>/dev/null || true)
                    echo "$wl $kind $v compare $cmp" >>"$out/raw.txt"
                    ag=$(echo "$cmp" | field agree)
                    [ "$ag" = yes ] && agree[$v]=ok || agree[$v]="$(echo "$cmp" | field mismatches) differ"
                fi
                rm -f "$out/gpu.hits"
            done
        done
        row="| $wl $kind |"
        for v in $cols; do
            m=$(echo ${speeds[$v]:-} | tr ' ' '\n' | grep . | med || true)
            if [ -z "$m" ]; then row="$row - |"; continue; fi
            row="$row $(awk -v k="$m" 'BEGIN { printf "%.2f", k / 1000 }')"
            [ -n "${agree[$v]:-}" ] && row="$row (${agree[$v]})"
            row="$row |"
        done
        echo "$row"
        unset speeds agree
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
