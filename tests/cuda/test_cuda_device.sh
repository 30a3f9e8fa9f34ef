#!/usr/bin/env bash
# test_cuda_device.sh - the GPU against the CPU on the same rays: `bench rays
# --accel cuda` and `--accel bvh` on primary, diffuse and shadow rays of the
# Cornell sphere box (or of a small scene in tests/data when ../shared is
# absent), closest and any hit; the hit files must agree (`bench compare`,
# the rule of the ray benchmark spec) and the output line must carry the
# device's keys. Skipped (77) where there is no CUDA driver or device.
# Usage: test_cuda_device.sh PAPRSEK SHARED_DIR TEST_DATA_DIR HAVE_CUDA
set -u
bin=$1
shared=$2
data=$3
have_cuda=$4
[ "$have_cuda" = 1 ] || { echo "SKIP: built without CUDA (nvcc not found)"; exit 77; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

scene="$shared/scenes/cornell/CornellBox-Sphere.obj"
cam=(--look-from 0,1,3.9 --look-at 0,1,0 --fov 39.3)
if [ ! -r "$scene" ]; then
    echo "note: $scene is not there (../shared is absent): using $data/json_floor.obj"
    scene="$data/json_floor.obj"
    cam=(--look-from 0.1,1,0.2 --look-at 0,0,0 --fov 60)
fi
"$bin" bench gen-rays "$scene" "${cam[@]}" --size 256 -o "$tmp/p.rays" 2>/dev/null || fail "gen-rays primary"
"$bin" bench gen-rays "$scene" "${cam[@]}" --size 256 --kind diffuse -o "$tmp/d.rays" 2>/dev/null ||
    fail "gen-rays diffuse"
kinds="p d"
if "$bin" bench gen-rays "$scene" "${cam[@]}" --size 256 --kind shadow -o "$tmp/s.rays" 2>/dev/null; then
    kinds="p d s"
fi

# is there a device at all?
if ! "$bin" bench rays "$scene" "$tmp/p.rays" --accel cuda --reps 1 >"$tmp/out" 2>"$tmp/err"; then
    if grep -Eq "no CUDA driver|no CUDA device" "$tmp/err"; then
        echo "SKIP: $(cat "$tmp/err")"
        exit 77
    fi
    fail "bench rays --accel cuda: $(cat "$tmp/err")"
    exit 1
fi
line=$(cat "$tmp/out")
echo "$line"
for key in rays accel=cuda build_ms time_s mrays_per_s hits device upload_ms structure_bytes device_bytes \
    rays_upload_ms kernel_ms download_ms kernel_mrays_per_s; do
    echo "$line" | grep -Eq "(^| )$key" || fail "no $key in '$line'"
done

for k in $kinds; do
    for mode in closest any; do
        extra=()
        [ "$mode" = any ] && extra=(--any-hit)
        "$bin" bench rays "$scene" "$tmp/$k.rays" --accel bvh --reps 1 --hits "$tmp/cpu.hits" "${extra[@]}" >/dev/null ||
            fail "$k $mode: bvh"
        "$bin" bench rays "$scene" "$tmp/$k.rays" --accel cuda --reps 3 --hits "$tmp/gpu.hits" "${extra[@]}" \
            >"$tmp/out" || fail "$k $mode: cuda"
        if "$bin" bench compare "$tmp/cpu.hits" "$tmp/gpu.hits" --rays "$tmp/$k.rays" "${extra[@]}" >"$tmp/cmp" 2>&1; then
            echo "ok: $k $mode: $(tail -1 "$tmp/cmp")"
        else
            fail "$k $mode: the GPU's hits disagree with the CPU's: $(cat "$tmp/cmp")"
        fi
        # closest hits are the same bit for bit
        if [ "$mode" = closest ] && ! cmp -s "$tmp/cpu.hits" "$tmp/gpu.hits"; then
            fail "$k closest: hit files are not identical"
        fi
    done
done
[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "all ok"
