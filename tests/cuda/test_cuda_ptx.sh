#!/usr/bin/env bash
# test_cuda_ptx.sh - the kernels as nvcc compiles them with the build's
# flags round like the CPU: no fused multiply-add (fma) and no approximate
# division or square root in the PTX of src/accel/cuda/trace.cu, whose
# float operations must be those of geom.h's triangle test one for one.
# Compiling it with fused multiply-adds allowed must show some, or the
# check would prove nothing.
# Usage: test_cuda_ptx.sh NVCC SOURCE_DIR FLAGS...
set -u
nvcc=$1
src=$2
shift 2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

ptx() { # OUT FLAGS...
    local out=$1
    shift
    "$nvcc" -ptx -arch=compute_90 "$@" -I"$src/src" -I"$src/include" -o "$out" "$src/src/accel/cuda/trace.cu"
}
ptx "$tmp/build.ptx" "$@" || { echo "FAIL: nvcc"; exit 1; }
n_fma=$(grep -c 'fma\.' "$tmp/build.ptx")
n_approx=$(grep -Ec '(div|sqrt|rcp)\.(approx|full)' "$tmp/build.ptx")
n_rn=$(grep -Ec '(mul|add|sub)\.rn\.f32' "$tmp/build.ptx")
[ "$n_fma" = 0 ] || fail "$n_fma fused multiply-adds in the kernels' PTX"
[ "$n_approx" = 0 ] || fail "$n_approx approximate divisions or square roots in the kernels' PTX"
[ "$n_rn" -gt 100 ] || fail "only $n_rn rounded float operations: is this the traversal?"
# every kernel version that src/accel/cuda.c can ask for is there
versions=$(sed -n 's/^static const char \*const kernel_names\[\] = {\(.*\)};$/\1/p' "$src/src/accel/cuda.c" | tr -d '"' | tr ',' ' ')
[ -n "$versions" ] || fail "no kernel_names in src/accel/cuda.c"
for v in $versions; do
    for k in closest any; do
        grep -q "^\.visible \.entry pk_trace_${k}_$v(" "$tmp/build.ptx" || fail "no kernel pk_trace_${k}_$v in the PTX"
    done
done
# the same source with contraction allowed (nvcc's default) does fuse
ptx "$tmp/fused.ptx" -O3 -std=c++17 -fmad=true || fail "nvcc -fmad=true"
n_fused=$(grep -c 'fma\.' "$tmp/fused.ptx")
[ "$n_fused" -gt 0 ] || fail "no fma even with -fmad=true: the check proves nothing"
echo "PTX: $n_rn rounded float operations, $n_fma fma, $n_approx approximate (with -fmad=true: $n_fused fma)"
[ "$fails" = 0 ] || exit 1
echo "all ok"
