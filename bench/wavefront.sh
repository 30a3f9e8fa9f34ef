#!/usr/bin/env bash
# wavefront.sh - CPU samples per second of the path tracer's loop (each
# thread traces one path to its end, then the next: what `paprsek render`
# runs) against the wavefront (a pool of paths advanced stage by stage over
# queues: src/render/wavefront.h), on CornellBox-Original and Sponza with an
# area light. Both run in one process on the same frame, interleaved, five
# times each; the median of each is printed, and the two images are
# compared bit for bit on every run (the program stops if they differ).
#
# The timing program is the test program test_wavefront (--bench) of a
# build folder; the scenes use their own cameras (the OBJ's: the default
# view of its bounding box).
#
# The wavefront's threads meet at a barrier between stages, several times
# per bounce; on a machine whose cores are busy with other work, threads
# that spin at barriers lose their time slices to it and the wavefront
# slows down many times over: there, run with OMP_WAIT_POLICY=passive (for
# both, as the environment passes it on).
#
# usage: bench/wavefront.sh [SHARED_DIR [BUILD_DIR]]
# environment: THREADS (2), SIZE (512: image side), SPP (4), POOL (0: the
# default pool, 65536 paths)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
shared=${1:-$repo/../shared}
build=${2:-$repo/build}
threads=${THREADS:-2}; size=${SIZE:-512}; spp=${SPP:-4}; pool=${POOL:-0}
bin=$build/tests/test_wavefront
die() { echo "wavefront.sh: $*" >&2; exit 1; }
[ -x "$bin" ] || die "no program at $bin (build the tests: cmake --build $build)"
[ -d "$shared/scenes" ] || die "no scenes at $shared/scenes"
echo "- machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores; threads: $threads; ${size}x${size}, $spp spp"
echo "- commit: $(git -C "$repo" rev-parse --short HEAD 2>/dev/null || echo unknown); OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-(default)}; load: $(cut -d' ' -f1-3 /proc/loadavg)"
for scene in "$shared/scenes/cornell/CornellBox-Original.obj" "$here/sponza-area-light.json"; do
    [ -r "$scene" ] || die "no scene $scene"
    "$bin" --bench "$scene" "$size" "$size" "$spp" "$threads" "$pool"
done
