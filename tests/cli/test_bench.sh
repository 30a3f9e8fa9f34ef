#!/usr/bin/env bash
# test_bench.sh - `paprsek bench gen-rays|rays|compare` end to end on small ray
# files for CornellBox-Sphere: every accelerator answers the same rays alike,
# the output line has the keys of spec/ray-benchmark.md, and bad input fails
# with a message. Usage: test_bench.sh PAPRSEK SHARED_DIR TEST_DATA_DIR
set -u
bin=$1
shared=$2
scene="$shared/scenes/cornell/CornellBox-Sphere.obj"
[ -r "$scene" ] || { echo "SKIP: $scene is not there (../shared is absent)"; exit 77; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# runs a command that must fail: non-zero exit and a "paprsek: " message
expect_error() {
    local what=$1
    shift
    if "$@" >"$tmp/out" 2>"$tmp/err"; then
        fail "$what: exit status 0"
    elif ! grep -q '^paprsek: ' "$tmp/err"; then
        fail "$what: no message on stderr"
    else
        echo "ok: $what: $(head -1 "$tmp/err")"
    fi
}

cam=(--look-from 0,1,3.9 --look-at 0,1,0 --fov 39.3)
"$bin" bench gen-rays "$scene" "${cam[@]}" --size 64 -o "$tmp/p.rays" 2>/dev/null || fail "gen-rays primary"
"$bin" bench gen-rays "$scene" "${cam[@]}" --size 64 --kind diffuse --seed 7 -o "$tmp/d.rays" 2>/dev/null ||
    fail "gen-rays diffuse"
[ "$(stat -c %s "$tmp/p.rays")" = $((64 * 64 * 32)) ] || fail "primary: expected 4096 rays"
d_size=$(stat -c %s "$tmp/d.rays" 2>/dev/null || echo 0)
[ "$d_size" -gt 0 ] && [ $((d_size % 32)) = 0 ] || fail "diffuse: bad size $d_size"

# the same seed gives the same file; --workload is the same camera
"$bin" bench gen-rays "$scene" "${cam[@]}" --size 64 --kind diffuse --seed 7 -o "$tmp/d2.rays" 2>/dev/null
cmp -s "$tmp/d.rays" "$tmp/d2.rays" || fail "diffuse rays differ between two runs with one seed"
"$bin" bench gen-rays --workload cornell-sphere --shared "$shared" --size 64 -o "$tmp/w.rays" 2>/dev/null
cmp -s "$tmp/p.rays" "$tmp/w.rays" || fail "--workload cornell-sphere is not the spec's camera"

accels="none midpoint bvh"
"$bin" bench rays "$scene" "$tmp/p.rays" --accel embree --reps 1 >/dev/null 2>&1 && accels="$accels embree"
for kind in p d; do
    for a in $accels; do
        for mode in "" --packets; do
            tag=$kind.$a${mode:+.pk}
            if ! "$bin" bench rays "$scene" "$tmp/$kind.rays" --accel $a --threads 2 --reps 2 $mode \
                --hits "$tmp/$tag.hits" --stats >"$tmp/$tag.out" 2>"$tmp/err"; then
                fail "bench rays $tag: $(cat "$tmp/err")"
                continue
            fi
            line=$(cat "$tmp/$tag.out")
            [ "$(wc -l <"$tmp/$tag.out")" = 1 ] || fail "$tag: not exactly one line"
            for key in rays accel threads build_ms time_s mrays_per_s hits nodes_per_ray; do
                echo "$line" | grep -Eq "(^| )$key=[^ ]+" || fail "$tag: no $key= in: $line"
            done
            echo "$line" | grep -q " accel=$a " || fail "$tag: wrong accel in: $line"
            echo "$line" | grep -q " threads=2 " || fail "$tag: wrong threads in: $line"
            hits=$(echo "$line" | sed -n 's/.* hits=\([0-9]*\).*/\1/p')
            [ "${hits:-0}" -gt 0 ] || fail "$tag: no hits"
            if [ "$tag" != "$kind.none" ]; then
                if ! "$bin" bench compare "$tmp/$kind.none.hits" "$tmp/$tag.hits" --rays "$tmp/$kind.rays" \
                    >"$tmp/cmp" 2>&1; then
                    fail "$tag disagrees with none: $(cat "$tmp/cmp")"
                fi
            fi
            echo "ok: $line"
        done
    done
done
nrays=$(sed -n 's/^rays=\([0-9]*\).*/\1/p' "$tmp/p.none.out")
[ "$nrays" = 4096 ] || fail "rays=$nrays, expected 4096"
[ "$(stat -c %s "$tmp/p.none.hits")" = $((4096 * 16)) ] || fail "hits file size"

# compare notices a disagreement (every ray a hit at t = 0 on triangle 0)
head -c $((4096 * 16)) /dev/zero >"$tmp/zero.hits"
expect_error "compare against a different file" "$bin" bench compare "$tmp/p.none.hits" "$tmp/zero.hits"
cmp_line=$(cat "$tmp/out")
echo "$cmp_line" | grep -q "agree=no" || fail "compare did not print agree=no: $cmp_line"

# bad input: malformed, missing, bad options
head -c 100 "$tmp/p.rays" >"$tmp/bad.rays"
: >"$tmp/empty.rays"
expect_error "malformed ray file" "$bin" bench rays "$scene" "$tmp/bad.rays"
expect_error "empty ray file" "$bin" bench rays "$scene" "$tmp/empty.rays"
expect_error "missing ray file" "$bin" bench rays "$scene" "$tmp/nope.rays"
expect_error "missing scene" "$bin" bench rays "$tmp/nope.obj" "$tmp/p.rays"
expect_error "unknown accel" "$bin" bench rays "$scene" "$tmp/p.rays" --accel warp
expect_error "bad --reps" "$bin" bench rays "$scene" "$tmp/p.rays" --reps 0
expect_error "unknown option" "$bin" bench rays "$scene" "$tmp/p.rays" --fast
expect_error "missing arguments" "$bin" bench rays "$scene"
expect_error "malformed hit file" "$bin" bench compare "$tmp/p.none.hits" "$tmp/bad.rays"
expect_error "gen-rays without -o" "$bin" bench gen-rays "$scene" "${cam[@]}"
expect_error "gen-rays bad --kind" "$bin" bench gen-rays "$scene" "${cam[@]}" --kind glossy -o "$tmp/x.rays"
expect_error "gen-rays missing scene" "$bin" bench gen-rays "$tmp/nope.obj" "${cam[@]}" -o "$tmp/x.rays"
expect_error "unknown subcommand" "$bin" bench fly
grep -q "bench" "$tmp/err" || fail "unknown subcommand: no usage"
expect_error "hits into a missing folder" "$bin" bench rays "$scene" "$tmp/p.rays" --reps 1 \
    --hits "$tmp/no/such/dir/x.hits"

if [ $fails -ne 0 ]; then
    echo "test_bench: $fails failure(s)"
    exit 1
fi
echo "test_bench: ok"
