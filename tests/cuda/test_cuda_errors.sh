#!/usr/bin/env bash
# test_cuda_errors.sh - `--accel cuda` fails cleanly where it cannot run: no
# driver, no kernels' module, no device, a driver too old for the kernels, too little device
# memory, a kernel that fails, and rendering on the GPU. Each is exit
# status 1, one line on stderr ("paprsek: ..." saying what is wrong),
# nothing on stdout and no hit file. The driver is replaced by a stub
# (cuda_stub.c, through PAPRSEK_CUDA_LIBRARY, which the program passes on as
# the library's config key cuda.library, or --config cuda.library=...) that
# plays each failure, so this runs on machines without a GPU.
# Usage: test_cuda_errors.sh PAPRSEK TEST_DATA_DIR HAVE_CUDA STUB_LIBRARY
set -u
bin=$1
have_cuda=$3
stub=${4:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# two triangles, no materials (nothing to warn about)
scene="$tmp/quad.obj"
printf 'v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 2 3\nf 1 3 4\n' >"$scene"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

"$bin" bench gen-rays "$scene" --look-from 0.1,1,0.2 --look-at 0,0,0 --fov 60 --size 16 -o "$tmp/r.rays" 2>/dev/null ||
    fail "gen-rays"

# expect_failure WHAT PATTERN command...: exit 1, one stderr line matching PATTERN, empty stdout
expect_failure() {
    local what=$1 pattern=$2
    shift 2
    rm -f "$tmp/h.hits"
    "$@" >"$tmp/out" 2>"$tmp/err"
    local rc=$?
    local lines
    lines=$(wc -l <"$tmp/err")
    if [ "$rc" != 1 ]; then
        fail "$what: exit status $rc, expected 1 ($(head -3 "$tmp/err"))"
    elif [ "$lines" != 1 ]; then
        fail "$what: $lines lines on stderr, expected 1: $(cat "$tmp/err")"
    elif ! grep -Eq "^paprsek: .*$pattern" "$tmp/err"; then
        fail "$what: message '$(cat "$tmp/err")' does not say '$pattern'"
    elif [ -s "$tmp/out" ]; then
        fail "$what: something on stdout: $(head -2 "$tmp/out")"
    elif [ -e "$tmp/h.hits" ]; then
        fail "$what: a hit file was written"
    else
        echo "ok: $what: $(cat "$tmp/err")"
    fi
}

rays=("$bin" bench rays "$scene" "$tmp/r.rays" --accel cuda --reps 1 --hits "$tmp/h.hits")

if [ "$have_cuda" != 1 ]; then
    expect_failure "not built in" "not available in this build" "${rays[@]}"
    [ "$fails" = 0 ] || exit 1
    exit 0
fi

PAPRSEK_CUDA_LIBRARY="$tmp/no-such-dir/libcuda.so.1" \
    expect_failure "no driver" "no CUDA driver \(.*libcuda.so.1" "${rays[@]}"
if [ -z "$stub" ] || [ ! -r "$stub" ]; then
    echo "SKIP: the stub driver ($stub) is not there"
    exit 77
fi
export PAPRSEK_CUDA_LIBRARY="$stub"
PK_CUDA_STUB=nodevice expect_failure "cuInit: no device" "no CUDA device$" "${rays[@]}"
PK_CUDA_STUB=zero expect_failure "no device counted" "no CUDA device$" "${rays[@]}"
PK_CUDA_STUB=oldptx expect_failure "driver too old" "built with CUDA [0-9.]+, do not run on Stub GPU \(compute capability 9.0\) with driver 11.4 \(.*\): they need a driver for CUDA [0-9.]+ or newer$" "${rays[@]}"
PK_CUDA_STUB=nomem expect_failure "too little memory" "not enough device memory for the BVH: [0-9]+ bytes needed, 64 bytes free of 16384.0 MiB$" \
    "${rays[@]}"
PK_CUDA_STUB=kernelfail expect_failure "kernel failure" "the traversal kernel failed: unspecified launch failure" \
    "${rays[@]}"
PK_CUDA_STUB=kernelfail expect_failure "kernel failure, any-hit" "the traversal kernel failed" "${rays[@]}" --any-hit
# the driver named by --config instead of the environment (which the program
# passes on as cuda.library); --config wins
PAPRSEK_CUDA_LIBRARY="$tmp/no-such-dir/libcuda.so.1" PK_CUDA_STUB=kernelfail \
    expect_failure "driver from --config" "the traversal kernel failed" "${rays[@]}" --config "cuda.library=$stub"
# the kernels' module (paprsek_cuda.so, which `make build` puts beside the
# program and `make demo` does not build) named where it is not
PK_CUDA_STUB=kernelfail expect_failure "no kernels' module" \
    "the CUDA kernels' module is not there \(.*/no-such-dir/paprsek_cuda.so is not there\): .make build. builds it where nvcc is found \(.make demo. does not\)$" \
    "${rays[@]}" --config "cuda.module=$tmp/no-such-dir/paprsek_cuda.so"
# the kernel versions measured once are gone: their key is unknown (a usage error, 2)
"${rays[@]}" --config cuda.kernel=v6 >"$tmp/out" 2>"$tmp/err"
rc=$?
if [ "$rc" != 2 ] || ! grep -q "^paprsek: --config: unknown key 'cuda.kernel'" "$tmp/err"; then
    fail "unknown config key: exit status $rc: $(cat "$tmp/err")"
else
    echo "ok: unknown config key: $(cat "$tmp/err")"
fi
# rendering on the GPU: the same messages, and no image written
PK_CUDA_STUB=kernelfail expect_failure "render, kernel failure" "the kernel pk_path_[a-z]+ failed: unspecified launch failure$" \
    "$bin" render "$scene" -o "$tmp/h.hits.png" --device cuda --env 1 --width 8 --height 8
[ -e "$tmp/h.hits.png" ] && fail "render: an image was written"
PK_CUDA_STUB=nomem expect_failure "render, too little memory" "not enough device memory for the BVH: [0-9]+ bytes needed, 64 bytes free of 16384.0 MiB$" \
    "$bin" render "$scene" -o "$tmp/h.hits.png" --device cuda --env 1 --width 8 --height 8
[ -e "$tmp/h.hits.png" ] && fail "render: an image was written"
PK_CUDA_STUB=nodevice expect_failure "render, no device" "no CUDA device$" \
    "$bin" render "$scene" -o "$tmp/h.hits.png" --device cuda --env 1 --width 8 --height 8
expect_failure "render, Whitted" "the GPU renders with the path tracer only, not the Whitted integrator$" \
    "$bin" render "$scene" -o "$tmp/h.hits.png" --device cuda --integrator whitted --env 1 --width 8 --height 8
# --accel cuda is the older spelling of --device cuda for a render
PK_CUDA_STUB=kernelfail expect_failure "render, --accel cuda" "the kernel pk_path_[a-z]+ failed: unspecified launch failure$" \
    "$bin" render "$scene" -o "$tmp/h.hits.png" --accel cuda --env 1 --width 8 --height 8
[ -e "$tmp/h.hits.png" ] && fail "render: an image was written"

[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "all ok"
