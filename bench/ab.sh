#!/usr/bin/env bash
# ab.sh - two builds of paprsek against each other (and Embree), interleaved:
# for each round, each workload runs `bench rays` with build A, build B (both
# --accel bvh) and Embree (through build A, build quality high). Prints the
# median Mrays/s of each and the median, least and greatest per-round ratio
# B/A, and the median B/Embree. For judging a change to the kernels on a noisy
# machine: only the per-round ratios mean much.
#
# usage: bench/ab.sh A B [WORKLOAD:KIND ...]
#   A, B: paprsek programs (or scripts that run one, e.g. with PAPRSEK_CPU_ISA=avx2)
#   KIND: primary, diffuse, shadow, or one of those with -any (traced with --any-hit)
# environment: SHARED (../shared), THREADS (2), ROUNDS (5), REPS (5), SIZE (1024)
# The ray files are bench/run.sh's (bench/out/WORKLOAD-KIND-SIZE.rays): run it once first.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck disable=SC2034 # read by workloads.sh
shared=${SHARED:-$here/../../shared}
die() { echo "ab.sh: $*" >&2; exit 1; }
# shellcheck source=workloads.sh
. "$here/workloads.sh"
[ $# -ge 2 ] || die "usage: bench/ab.sh A B [WORKLOAD:KIND ...]"
a=$1; b=$2; shift 2
items=${*:-"cornell-sphere:primary cornell-sphere:diffuse cornell-sphere:diffuse-any cornell-sphere:shadow-any
bunny:primary bunny:diffuse bunny:diffuse-any sponza:primary sponza:diffuse sponza:diffuse-any"}
threads=${THREADS:-2}; rounds=${ROUNDS:-5}; reps=${REPS:-5}; size=${SIZE:-1024}
res=$(mktemp)
trap 'rm -f "$res"' EXIT
for item in $items; do
    wl=${item%%:*}; kind=${item#*:}
    [ -f "$here/out/$wl-${kind%-any}-$size.rays" ] || die "no $here/out/$wl-${kind%-any}-$size.rays (run bench/run.sh first)"
done
for ((r = 1; r <= rounds; r++)); do
    for item in $items; do
        wl=${item%%:*}; kind=${item#*:}; rays=$here/out/$wl-${kind%-any}-$size.rays
        flag=; [ "$kind" != "${kind%-any}" ] && flag=--any-hit
        for c in A B E; do
            case $c in A) bin=$a acc=bvh ;; B) bin=$b acc=bvh ;; E) bin=$a acc=embree ;; esac
            # shellcheck disable=SC2086
            v=$(PAPRSEK_EMBREE_QUALITY=high "$bin" bench rays "$(scene_of "$wl")" "$rays" --accel $acc \
                --threads "$threads" --reps "$reps" $flag 2>/dev/null | field mrays_per_s) || v=
            [ -n "$v" ] || die "$item: $c ($bin --accel $acc) failed"
            echo "$item $c $r $v" >>"$res"
        done
    done
done
echo "| workload | A Mrays/s | B Mrays/s | Embree Mrays/s | B/A median [least, greatest] | B/Embree |"
echo "|---|---|---|---|---|---|"
for item in $items; do
    awk -v it="$item" '
        function median(x, n,   i, j, t) { for (i = 2; i <= n; i++) { t = x[i]; for (j = i - 1; j >= 1 && x[j] > t; j--) x[j + 1] = x[j]; x[j + 1] = t }
            return n % 2 ? x[(n + 1) / 2] : (x[n / 2] + x[n / 2 + 1]) / 2 }
        $1 == it { v[$2, $3] = $4; if ($3 > n) n = $3 }
        END { for (r = 1; r <= n; r++) { A[r] = v["A", r]; B[r] = v["B", r]; E[r] = v["E", r]; q[r] = v["B", r] / v["A", r]; e[r] = v["B", r] / v["E", r] }
              lo = q[1]; hi = q[1]; for (r = 2; r <= n; r++) { if (q[r] < lo) lo = q[r]; if (q[r] > hi) hi = q[r] }
              printf "| %s | %.2f | %.2f | %.2f | %.3f [%.3f, %.3f] | %.3f |\n", it, median(A, n), median(B, n), median(E, n), median(q, n), lo, hi, median(e, n) }' "$res"
done
