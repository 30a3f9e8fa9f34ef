#!/usr/bin/env bash
# test_cuda_ptx.sh - the kernels as nvcc compiles them with the build's
# flags round like the CPU: no approximate division or square root in the
# PTX of src/accel/cuda/trace.cu, and no fused multiply-add (fma) but the
# ones the box tests ask for (gpu_fma): the triangle test's float operations
# must be those of geom.h's one for one. The reference kernels, without
# those box tests (pk_trace_*_ref), must have none at all; with the box
# tests kept out of line (PK_GPU_BOX_NOINLINE) no kernel may have any
# outside them. Compiling with fused multiply-adds allowed must show more,
# or the check would prove nothing.
# (The path tracer, src/render/cuda/path.cu, is not checked: its shading
# calls sinf, expf and friends, whose library code uses fma on purpose; its
# traversal is the same code compiled with the same flags.)
# Usage: test_cuda_ptx.sh NVCC SOURCE_DIR REPORT_DIR FLAGS...
# (REPORT_DIR: the build's cuda/, where the build keeps ptxas's reports)
set -u
nvcc=$1
src=$2
reports=$3
shift 3
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
ptx "$tmp/apart.ptx" "$@" -DPK_GPU_BOX_NOINLINE || { echo "FAIL: nvcc -DPK_GPU_BOX_NOINLINE"; exit 1; }
# fma count per function: "NAME COUNT" for entries and functions
fma_by_function() {
    awk '/^\.(visible|func|entry)/ { name = $0; sub(/\($/, "", name); n = split(name, a, /[ )]/); name = a[n]; c[name] += 0 }
         /fma\./ { c[name]++ } END { for (k in c) print k, c[k] }' "$1"
}
n_fma=$(grep -c 'fma\.' "$tmp/build.ptx")
n_approx=$(grep -Ec '(div|sqrt|rcp)\.(approx|full)' "$tmp/build.ptx")
n_rn=$(grep -Ec '(mul|add|sub)\.rn\.f32' "$tmp/build.ptx")
bad=$(fma_by_function "$tmp/build.ptx" | awk '$1 ~ /^pk_trace_[a-z]+_ref$/ && $2 > 0')
[ -z "$bad" ] || fail "fused multiply-adds in kernels without fma box tests: $bad"
bad=$(fma_by_function "$tmp/apart.ptx" | awk '$1 !~ /(gpu_node_hits_fma|gpu_node_hits_wide)/ && $2 > 0')
[ -z "$bad" ] || fail "fused multiply-adds outside the box tests: $bad"
n_box=$(fma_by_function "$tmp/apart.ptx" | awk '$1 ~ /(gpu_node_hits_fma|gpu_node_hits_wide)/ && $2 > 0' | wc -l)
# the default kernels' GPU_TEST_WIDE, and GPU_TEST_FMA for the rays it leaves to it
[ "$n_box" = 2 ] || fail "the box tests' fused multiply-adds are not where expected ($n_box functions)"
[ "$n_approx" = 0 ] || fail "$n_approx approximate divisions or square roots in the kernels' PTX"
[ "$n_rn" -gt 100 ] || fail "only $n_rn rounded float operations: is this the traversal?"
# every kernel that src/accel/cuda.c asks for is there
kernels=$(grep -o '"pk_trace_[a-z_]*"' "$src/src/accel/cuda.c" | tr -d '"' | sort -u)
[ -n "$kernels" ] || fail "no kernel names in src/accel/cuda.c"
for k in $kernels; do
    grep -q "^\.visible \.entry $k(" "$tmp/build.ptx" || fail "no kernel $k in the PTX"
done
# the same source with contraction allowed (nvcc's default) does fuse
ptx "$tmp/fused.ptx" -O3 -std=c++17 -fmad=true || fail "nvcc -fmad=true"
n_fused=$(grep -c 'fma\.' "$tmp/fused.ptx")
[ "$n_fused" -gt "$n_fma" ] || fail "no more fma with -fmad=true: the check proves nothing"
echo "PTX: $n_rn rounded float operations, $n_fma fma (box tests), $n_approx approximate (with -fmad=true: $n_fused fma)"

# Resources per kernel as ptxas reported them for sm_90 (the H100) when the
# build compiled the kernels (cmake/nvcc_report.sh keeps the report in
# REPORT_DIR/NAME.ptxas.txt; compiling path.cu again here took minutes):
# registers, stack frame, spills. Written to cuda_resources.txt in the
# working directory (the build's tests/), the table docs/gpu.md reads; the
# traversal kernels must not spill, and the ordered traversal's stack frame
# must be its 64 entries, half the sorted one's.
resources() { # REPORT -> lines "kernel registers stack spill_stores spill_loads" (sm_90)
    [ -r "$1" ] || { echo "FAIL: no ptxas report $1 (is the build complete?)" >&2; return 1; }
    awk '/Compiling entry function/ { k = ""; if ($0 ~ /for .sm_90.$/) { k = $0; sub(/.*function .?/, "", k); sub(/.? for .*/, "", k) } }
         /bytes stack frame/ && k != "" { st = $1; ss = $5; sl = $9 }
         /Used [0-9]+ registers/ && k != "" { r = $0; sub(/.*Used /, "", r); sub(/ registers.*/, "", r);
                                              print k, r, st + 0, ss + 0, sl + 0; k = "" }' "$1"
}
flags=("$@")
{
    resources "$reports/trace.ptxas.txt" || fails=$((fails + 1))
    resources "$reports/path.ptxas.txt" || fails=$((fails + 1))
} > "$tmp/res.txt"
{
    echo "# kernel registers stack_bytes spill_store_bytes spill_load_bytes (ptxas, sm_90, flags: ${flags[*]})"
    cat "$tmp/res.txt"
} > cuda_resources.txt
cat cuda_resources.txt
res() { awk -v k="$1" -v f="$2" '$1 == k { print $f }' "$tmp/res.txt"; }
for k in $kernels pk_path_render pk_path_render_camera; do
    [ -n "$(res "$k" 2)" ] || fail "ptxas reported nothing for kernel $k"
done
for k in $kernels; do
    [ "$(res "$k" 4)" = 0 ] && [ "$(res "$k" 5)" = 0 ] || fail "kernel $k spills ($(res "$k" 4) bytes stored)"
done
so=$(res pk_trace_closest_ordered 3)
ss=$(res pk_trace_closest 3)
if [ -n "$so" ] && [ -n "$ss" ]; then
    ostack=$(awk '/#define GPU_OSTACK/ { print $3 }' "$src/src/accel/bvh_gpu.h")
    [ "$so" -le $((8 * ostack + 64)) ] && [ "$so" -lt "$ss" ] ||
        fail "the ordered kernel's stack frame is $so bytes (sorted: $ss, entries: $((8 * ostack)))"
fi
[ "$fails" = 0 ] || exit 1
echo "all ok"
