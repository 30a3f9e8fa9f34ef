#!/usr/bin/env bash
# Choosing lights by power or through the light tree (--light-tree 0 / 1),
# on a floor under K small lamps of random size, height and brightness, for
# several K. For each: the relative noise of one render (two seeds, the
# whole image, bench/imgstat.py noise2) at a fixed sample count, and the
# instructions a smaller render of the same (80x60, 4 spp, one thread) takes
# under callgrind: a count that the other loads of a shared machine do not
# change. Efficiency = 1 / (noise^2 x instructions); the last column is the
# tree's over power's (> 1: the tree reaches a given noise in less work).
# usage: bench/light_tree.sh [PAPRSEK [K...]]
set -euo pipefail
bin=${1:-build/paprsek}
shift 1 2>/dev/null || true
counts=${*:-1 2 4 8 16 64 256}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
command -v valgrind >/dev/null || { echo "valgrind is not installed"; exit 0; }
echo "| lamps | noise power | noise tree | instructions power | instructions tree | efficiency tree / power |"
echo "|---|---|---|---|---|---|"
for k in $counts; do
  /usr/bin/python3 - "$k" "$tmp" <<'EOF_PY'
import random, sys
k, d = int(sys.argv[1]), sys.argv[2]
r = random.Random(k)
with open(f"{d}/lamps.obj", "w") as f:
    f.write("")
    for i in range(k):
        x, z, y, s = r.uniform(-8, 8), r.uniform(-8, 8), r.uniform(0.5, 3), r.uniform(0.05, 0.4)
        f.write(f"v {x} {y} {z}\nv {x + s} {y} {z}\nv {x} {y} {z + s}\nusemtl lamp{i % 4}\nf {3*i+1} {3*i+2} {3*i+3}\n")
mats = ", ".join(f'"lamp{j}": {{"type": "emitter", "radiance": [{20 * 3 ** j}, {20 * 3 ** j}, {20 * 3 ** j}]}}' for j in range(4))
with open(f"{d}/scene.json", "w") as f:
    f.write('{"materials": {%s, "floor": {"kd": [0.5, 0.5, 0.5]}},'
            ' "camera": {"look_from": [0, 9, 9], "look_at": [0, 0, 0], "fov": 60},'
            ' "meshes": [{"obj": "lamps.obj"}],'
            ' "spheres": [{"center": [0, -1000, 0], "radius": 1000, "material": "floor"}],'
            ' "environment": "none"}' % mats)
EOF_PY
  declare -A noise instr
  for mode in 0 1; do
    for seed in 1 2; do
      "$bin" render "$tmp/scene.json" -o "$tmp/i$mode$seed.pfm" \
        --quiet --width 160 --height 120 --spp 16 --seed "$seed" --light-tree "$mode" >/dev/null
    done
    noise[$mode]=$(/usr/bin/python3 "$here/imgstat.py" noise2 "$tmp/i${mode}1.pfm" "$tmp/i${mode}2.pfm" 0 1 0 1)
    valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bin" render "$tmp/scene.json" -o "$tmp/c.pfm" \
      --quiet --width 80 --height 60 --spp 4 --threads 1 --light-tree "$mode" >/dev/null 2>"$tmp/cg"
    instr[$mode]=$(awk '/Collected/ { print $4 }' "$tmp/cg")
  done
  awk -v k="$k" -v n0="${noise[0]}" -v n1="${noise[1]}" -v i0="${instr[0]}" -v i1="${instr[1]}" 'BEGIN {
    printf "| %d | %.4f | %.4f | %.3g | %.3g | %.2f |\n", k, n0, n1, i0, i1, (n0 * n0 * i0) / (n1 * n1 * i1) }'
done
