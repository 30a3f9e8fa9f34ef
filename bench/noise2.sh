#!/usr/bin/env bash
# Raw noise against time, measured the honest way: for each T, two renders of
# CornellBox-Original at 512x512 with --time T and different seeds; the
# relative noise of one render in the back-wall patch (x 0.55-0.70, y
# 0.28-0.55 of the image) is sqrt(mean((a - b)^2) / 2) / mean((a + b) / 2)
# of the luminance (bench/imgstat.py noise2). Unlike bench/noise.sh's
# neighbour differences it stays right for filtered images (--denoise: set
# EXTRA=--denoise).
# usage: bench/noise2.sh [SHARED_DIR [PAPRSEK [SECONDS...]]]
set -euo pipefail
shared=${1:-../shared}
bin=${2:-build/paprsek}
shift 2 2>/dev/null || true
times=${*:-1 2 4 6 8}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene="$shared/scenes/cornell/CornellBox-Original.obj"
[ -f "$scene" ] || { echo "no $scene (../shared is absent)"; exit 0; }
echo "| --time [s] | samples per pixel | relative noise |"
echo "|---|---|---|"
for t in $times; do
  for seed in 1 2; do
    "$bin" render "$scene" -o "$tmp/n$seed.pfm" --quiet --width 512 --height 512 --time "$t" --seed "$seed" \
      --look-from 0,1,3.9 --look-at 0,1,0 --fov 39.3 ${EXTRA:-} --stats-json "$tmp/s$seed.json" >/dev/null
  done
  spp=$(/usr/bin/python3 -c "import json,sys; s=json.load(open(sys.argv[1])); print(round(s['samples_per_s']*s['render_s']/(512*512)))" "$tmp/s1.json")
  n=$(/usr/bin/python3 "$here/imgstat.py" noise2 "$tmp/n1.pfm" "$tmp/n2.pfm")
  printf '| %g | %s | %.2f %% |\n' "$t" "$spp" "$(awk "BEGIN { print 100 * $n }")"
done
