#!/usr/bin/env bash
# The denoiser's network layer by layer against the CPU's own FMA peak
# (docs/performance.md, "Denoising"): bench/fma_peak.c measures the peak of
# 256- and 512-bit FMAs at 1 and THREADS threads; build/tests/denoise_layers
# times each convolution of the default network (or NET) at SIZE x SIZE
# over REPS passes after a first pass that also plans, and prints a
# markdown table with each layer's share of the peak of the vector width
# the denoiser uses on this CPU (512 with AVX-512, else 256).
#   bash bench/denoise_layers.sh [BUILD]      SIZE=512 THREADS=2 REPS=5 NET=rt_hdr_alb_nrm
set -euo pipefail
build=${1:-build}
SIZE=${SIZE:-512}
THREADS=${THREADS:-$(nproc)}
REPS=${REPS:-5}
NET=${NET:-rt_hdr_alb_nrm}
here=$(cd "$(dirname "$0")" && pwd)
peakbin=$(mktemp)
trap 'rm -f "$peakbin"' EXIT
${CC:-gcc} -O2 -fopenmp "$here/fma_peak.c" -o "$peakbin"
echo "CPU: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //'), family $(grep -m1 'cpu family' /proc/cpuinfo | awk '{print $4}') model $(grep -m1 '^model\s' /proc/cpuinfo | awk '{print $3}'), $(nproc) cores"
peaks=$("$peakbin" "$THREADS")
echo "$peaks"
width=256
grep -q avx512f /proc/cpuinfo && width=512
peak=$(echo "$peaks" | awk -v w=$width -v t="$THREADS" '$1 == w && $2 == t {print $3}')
echo "peak of ${width}-bit FMAs at $THREADS threads: $peak GFLOP/s"
"$build/tests/denoise_layers" "$build/weights/$NET.tza" "$SIZE" "$SIZE" "$THREADS" "$REPS" "$peak"
