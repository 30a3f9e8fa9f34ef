#!/usr/bin/env bash
# mpi_scaling.sh - paprsek-mpi's scaling on this machine: paprsek render with
# one thread, then paprsek-mpi with each number of ranks of one thread each
# (oversubscribed beyond the cores), the same image every time (checked with
# cmp). Prints a Markdown table: wall time of the render (the job's, from the
# first tile dealt to the last merged), speed-up and parallel efficiency
# against the one-thread process, each rank's share of the tiles, and the
# bytes rank 1 sent; and the CPU time (user + system) of all ranks together
# against the one process's, which other work on the machine disturbs far
# less than the wall clock. Each is run REPEAT times (default 3),
# interleaved, and the fastest run counts (the machine may be shared).
# usage: [REPEAT=3] bench/mpi_scaling.sh [SCENE] [WxH] [SPP] [RANKS...]
#   defaults: bench/sponza-light.json 640x360 8 1 2 3 4 (needs ../shared)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
build=${BUILD:-$here/../build}
scene=${1:-$here/sponza-light.json}
size=${2:-640x360}
spp=${3:-8}
shift $(($# < 3 ? $# : 3))
ranks=${*:-1 2 3 4}
w=${size%x*} h=${size#*x}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
opts=(--width "$w" --height "$h" --spp "$spp" --threads 1 --quiet --stats)
cd "$(dirname "$scene")"
s=$(basename "$scene")
repeat=${REPEAT:-3}
# best FILE VALUE: keeps the smaller of FILE's number and VALUE in FILE
best() { if [ ! -s "$1" ] || awk -v a="$2" -v b="$(cat "$1")" 'BEGIN { exit !(a < b) }'; then echo "$2" >"$1"; fi; }
for k in $(seq "$repeat"); do
  /usr/bin/time -f "%U %S" -o "$tmp/cpu1" "$build/paprsek" render "$s" -o "$tmp/one.pfm" "${opts[@]}" >"$tmp/one.txt"
  best "$tmp/t1" "$(awk '$1 == "render" && $2 == "[s]" { print $3 }' "$tmp/one.txt")"
  best "$tmp/c1" "$(awk '{ print $1 + $2 }' "$tmp/cpu1")"
  for n in $ranks; do
    mpiexec --oversubscribe --bind-to none -np "$n" "$build/paprsek-mpi" render "$s" -o "$tmp/many.pfm" \
      "${opts[@]}" >"$tmp/many.txt"
    cmp -s "$tmp/one.pfm" "$tmp/many.pfm" || echo "(the image of $n ranks differs!)"
    tn=$(awk '$1 == "job" && $2 == "render" { print $4 }' "$tmp/many.txt")
    best "$tmp/t$n.best" "$tn"
    best "$tmp/c$n.best" "$(awk '$1 == "rank" { for (i = 1; i <= NF; i++) if ($i == "cpu") s += $(i + 1) } END { print s }' "$tmp/many.txt")"
    if [ "$(cat "$tmp/t$n.best")" = "$tn" ]; then cp "$tmp/many.txt" "$tmp/many$n.txt"; fi
  done
done
t1=$(cat "$tmp/t1")
echo "scene $scene, ${w}x${h}, $spp spp, path tracer, tiles of 64 pixels, one thread per rank, $(nproc) cores,"
echo "fastest of $repeat runs"
echo
c1=$(cat "$tmp/c1")
echo "| ranks | render [s] | speed-up | efficiency | tiles per rank | bytes sent by rank 1 | CPU [s], all ranks | CPU efficiency |"
echo "|---:|---:|---:|---:|---|---:|---:|---:|"
echo "| paprsek render, 1 thread | $t1 | 1.00 | 1.00 | | | $c1 | 1.00 |"
for n in $ranks; do
  tn=$(cat "$tmp/t$n.best")
  tiles=$(awk '$1 == "rank" { for (i = 1; i <= NF; i++) if ($i == "tiles") printf "%s%s", sep, $(i - 1); sep = " / " }' "$tmp/many$n.txt")
  sent=$(awk '$1 == "rank" && $2 == 1 { for (i = 1; i <= NF; i++) if ($i == "sent") print $(i + 1) }' "$tmp/many$n.txt")
  cn=$(cat "$tmp/c$n.best")
  awk -v n="$n" -v t1="$t1" -v tn="$tn" -v tiles="$tiles" -v sent="${sent:--}" -v c1="$c1" -v cn="$cn" \
    'BEGIN { printf "| %d | %.3f | %.2f | %.2f | %s | %s | %.2f | %.2f |\n", n, tn, t1 / tn, t1 / tn / n, tiles, sent, cn, c1 / cn }'
done
