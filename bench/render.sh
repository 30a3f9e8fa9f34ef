#!/usr/bin/env bash
# render.sh - whole renders with Paprsek's BVH (--accel bvh) against Embree
# (--accel embree), interleaved: the wall-clock time of each `paprsek render`
# command (scene loading, the acceleration build and the render), median over
# rounds, and the ratio Embree time / BVH time (above 1: the BVH is faster).
# Without --stats, so that neither accelerator counts anything.
#
# usage: bench/render.sh [SHARED_DIR [PAPRSEK]]
# environment: THREADS (2), ROUNDS (5), SIZE (1024: image side), OUT (images,
# default bench/out/render)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
shared=${1:-$repo/../shared}
bin=${2:-$repo/build/paprsek}
threads=${THREADS:-2}; rounds=${ROUNDS:-5}; size=${SIZE:-1024}
out=${OUT:-$here/out/render}
mkdir -p "$out"
die() { echo "render.sh: $*" >&2; exit 1; }
[ -x "$bin" ] || die "no program at $bin (make build)"
cornell=$shared/scenes/cornell
[ -d "$cornell" ] || die "no scenes at $cornell"
"$bin" render --accel embree --width 8 --height 8 -o "$out/probe.png" >/dev/null 2>&1 ||
    die "this build has no Embree (--accel embree)"

# name | scene | options: both integrators on CornellBox-Sphere, CornellBox-Original
# (the standard camera) and Sponza with an area light; Whitted at 1 sample
# per pixel and 32 light samples, the path tracer at 4 (Sponza: 2)
cases() {
    local cam="--look-from 0,1,3.9 --look-at 0,1,0 --fov 39.3"
    local whitted="--integrator whitted --light-samples 32 --spp 1"
    echo "whitted-cornell-sphere|$cornell/CornellBox-Sphere.obj|$whitted $cam"
    echo "whitted-cornell-original|$cornell/CornellBox-Original.obj|$whitted $cam"
    echo "whitted-sponza-area-light|$here/sponza-area-light.json|$whitted"
    echo "path-cornell-sphere|$cornell/CornellBox-Sphere.obj|--integrator path --spp 4 $cam"
    echo "path-cornell-original|$cornell/CornellBox-Original.obj|--integrator path --spp 4 $cam"
    echo "path-sponza-area-light|$here/sponza-area-light.json|--integrator path --spp 2"
}

res=$out/times-$(date +%Y%m%d-%H%M%S).txt
: >"$res"
echo "- machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores; threads: $threads; $rounds rounds; ${size}x${size}"
echo "- commit: $(git -C "$repo" rev-parse --short HEAD 2>/dev/null || echo unknown)"
for ((r = 1; r <= rounds; r++)); do
    while IFS='|' read -r name scene opts; do
        # alternate which accelerator goes first
        if ((r % 2)); then order="bvh embree"; else order="embree bvh"; fi
        for acc in $order; do
            t0=$(date +%s.%N)
            # shellcheck disable=SC2086
            "$bin" render "$scene" --accel "$acc" --threads "$threads" --width "$size" --height "$size" $opts \
                -o "$out/$name-$acc.png" >/dev/null 2>>"$out/stderr.log" || die "$name --accel $acc failed (see $out/stderr.log)"
            t1=$(date +%s.%N)
            echo "$name $acc $r $(echo "$t1 - $t0" | bc -l)" >>"$res"
        done
    done < <(cases)
done

echo
echo "| render | bvh s (median) | embree s (median) | embree / bvh | per round |"
echo "|---|---|---|---|---|"
while IFS='|' read -r name _ _; do
    awk -v n="$name" '
        function median(a, k,   i, j, t, b) { for (i = 1; i <= k; i++) b[i] = a[i]
            for (i = 2; i <= k; i++) { t = b[i]; for (j = i - 1; j >= 1 && b[j] > t; j--) b[j + 1] = b[j]; b[j + 1] = t }
            return k % 2 ? b[(k + 1) / 2] : (b[k / 2] + b[k / 2 + 1]) / 2 }
        $1 == n && $2 == "bvh" { b[$3] = $4; nb++ }
        $1 == n && $2 == "embree" { e[$3] = $4; ne++ }
        END { per = ""; for (i = 1; i <= nb; i++) per = per sprintf("%s%.2f", i > 1 ? " " : "", e[i] / b[i])
              mb = median(b, nb); me = median(e, ne)
              printf "| %s | %.2f | %.2f | %.2f | %s |\n", n, mb, me, me / mb, per }' "$res"
done < <(cases)
echo
echo "(raw times: $res)"
