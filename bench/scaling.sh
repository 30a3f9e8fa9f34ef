#!/usr/bin/env bash
# scaling.sh - how single-ray tracing scales with threads: `paprsek bench rays`
# on one workload at 1, 2, 4, ... threads, Paprsek's BVH and Embree
# interleaved in every round. Prints a markdown table of the median Mrays/s at
# each thread count, the speed-up over one thread and the efficiency (speed-up
# / threads; 1.0 is linear).
#
# usage: bench/scaling.sh [SHARED_DIR [PAPRSEK]]   (defaults: ../shared, build/paprsek)
# environment: WORKLOAD (sponza), KIND (diffuse; primary, diffuse, shadow, or
#              one of those with -any for occlusion), THREAD_COUNTS (1 2 4 ...
#              up to the cores online), ROUNDS (5), REPS (5), SIZE (1024),
#              PAPRSEK_EMBREE_QUALITY (Embree's build quality, default medium)
# The ray file is bench/run.sh's (bench/out/WORKLOAD-KIND-SIZE.rays): run it once first.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
# shellcheck disable=SC2034 # read by workloads.sh
shared=${1:-$repo/../shared}
bin=${2:-$repo/build/paprsek}
die() { echo "scaling.sh: $*" >&2; exit 1; }
# shellcheck source=workloads.sh
. "$here/workloads.sh"
wl=${WORKLOAD:-sponza}; kind=${KIND:-diffuse}
rounds=${ROUNDS:-5}; reps=${REPS:-5}; size=${SIZE:-1024}
if [ -z "${THREAD_COUNTS:-}" ]; then
    cores=$(nproc); THREAD_COUNTS=
    for ((n = 1; n < cores; n *= 2)); do THREAD_COUNTS="$THREAD_COUNTS $n"; done
    THREAD_COUNTS="$THREAD_COUNTS $cores"
fi
[ -x "$bin" ] || die "$bin is not there: build first (make build), or pass the binary as the second argument"
rays=$here/out/$wl-${kind%-any}-$size.rays
[ -f "$rays" ] || die "no $rays (run bench/run.sh first)"
scene=$(scene_of "$wl")
[ -r "$scene" ] || die "$scene is not there"
flag=; [ "$kind" != "${kind%-any}" ] && flag=--any-hit
accels="bvh"
"$bin" bench rays "$scene" "$rays" --accel embree --reps 1 --threads 1 >/dev/null 2>&1 && accels="bvh embree"

first=${THREAD_COUNTS# }; first=${first%% *}
res=$(mktemp)
trap 'rm -f "$res"' EXIT
for ((r = 1; r <= rounds; r++)); do
    for n in $THREAD_COUNTS; do
        for acc in $accels; do
            # shellcheck disable=SC2086
            v=$("$bin" bench rays "$scene" "$rays" --accel "$acc" --threads "$n" --reps "$reps" $flag 2>/dev/null |
                field mrays_per_s) || v=
            [ -n "$v" ] || die "$acc at $n threads failed"
            echo "$acc $n $v" >>"$res"
        done
    done
    echo "round $r of $rounds done" >&2
done

echo "## Thread scaling: $wl $kind ($(awk -F': ' '/^model name/ { print $2; exit }' /proc/cpuinfo 2>/dev/null), $(nproc) cores online)"
echo
echo "$rounds rounds interleaved, $reps timed passes per run, medians; speed-up over $first thread(s); efficiency = speed-up x $first / threads (1.0: linear)"
echo
echo "| threads | Paprsek Mrays/s | speed-up | efficiency | Embree Mrays/s | speed-up | efficiency | Paprsek/Embree |"
echo "|---|---|---|---|---|---|---|---|"
med() { awk -v a="$1" -v n="$2" '$1 == a && $2 == n { print $3 }' "$res" | sort -g |
        awk '{ v[NR] = $1 } END { if (NR) print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }'; }
p1=$(med bvh "$first"); e1=$(med embree "$first")
for n in $THREAD_COUNTS; do
    p=$(med bvh "$n"); e=$(med embree "$n")
    awk -v n="$n" -v f="$first" -v p="$p" -v p1="$p1" -v e="$e" -v e1="$e1" 'BEGIN {
        ps = p / p1; line = sprintf("| %d | %.2f | %.2f | %.2f |", n, p, ps, ps * f / n)
        if (e != "") { es = e / e1; line = line sprintf(" %.2f | %.2f | %.2f | %.2f |", e, es, es * f / n, p / e) }
        else line = line " - | - | - | - |"
        print line }'
done
