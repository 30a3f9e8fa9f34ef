#!/usr/bin/env bash
# Adaptive sampling against uniform sampling at equal time: CornellBox-Original
# at 512x512 (the camera of bench/noise2.sh). For each target X, two renders
# with --noise X and different seeds; then two uniform renders with --time
# equal to the adaptive render's time. Reported: render time, mean samples
# per pixel, the two-seed relative error over the whole image
# (imgstat.py twoseed, what --noise aims at), that of the worst tiles
# (tiles95: the 95th percentile over 16x16 tiles) and the back wall's relative
# noise (imgstat.py noise2, the patch of bench/noise2.sh), and the image
# means (no bias: they must agree).
# usage: bench/adaptive.sh [SHARED_DIR [PAPRSEK [TARGETS...]]]
set -euo pipefail
shared=${1:-../shared}
bin=${2:-build/paprsek}
shift 2 2>/dev/null || true
targets=${*:-0.06 0.05 0.04}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene="$shared/scenes/cornell/CornellBox-Original.obj"
[ -f "$scene" ] || { echo "no $scene (../shared is absent)"; exit 0; }
cam=(--width 512 --height 512 --look-from 0,1,3.9 --look-at 0,1,0 --fov 39.3 --no-denoise --quiet)
py=/usr/bin/python3
json() { $py -c "import json,sys; s=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }
mean() { $py -c "import sys; sys.path.insert(0, sys.argv[1]); import imgstat; print('%.5f' % imgstat.read_pfm(sys.argv[2]).mean())" "$here" "$1"; }
echo "| mode | render [s] | mean spp | two-seed error (image) | worst tiles (95th pct) | back-wall noise | image mean |"
echo "|---|---|---|---|---|---|---|"
for x in $targets; do
  for seed in 1 2; do
    "$bin" render "$scene" -o "$tmp/a$seed.pfm" "${cam[@]}" --noise "$x" --seed "$seed" --stats-json "$tmp/a$seed.json" >/dev/null
  done
  t=$(json "$tmp/a1.json" "round(s['render_s'], 2)")
  spp=$(json "$tmp/a1.json" "round(s['adaptive']['mean_spp'], 1)")
  printf '| --noise %s | %s | %s | %.4f | %.4f | %.2f %% | %s |\n' "$x" "$t" "$spp" \
    "$($py "$here/imgstat.py" twoseed "$tmp/a1.pfm" "$tmp/a2.pfm")" "$($py "$here/imgstat.py" tiles95 "$tmp/a1.pfm" "$tmp/a2.pfm")" \
    "$(awk "BEGIN { print 100 * $($py "$here/imgstat.py" noise2 "$tmp/a1.pfm" "$tmp/a2.pfm") }")" "$(mean "$tmp/a1.pfm")"
  for seed in 1 2; do
    "$bin" render "$scene" -o "$tmp/u$seed.pfm" "${cam[@]}" --spp 1 --time "$t" --seed "$seed" --stats-json "$tmp/u$seed.json" >/dev/null
  done
  ut=$(json "$tmp/u1.json" "round(s['render_s'], 2)")
  uspp=$(json "$tmp/u1.json" "round(s['samples_per_s'] * s['render_s'] / (512 * 512), 1)")
  printf '| uniform, --time %s | %s | %s | %.4f | %.4f | %.2f %% | %s |\n' "$t" "$ut" "$uspp" \
    "$($py "$here/imgstat.py" twoseed "$tmp/u1.pfm" "$tmp/u2.pfm")" "$($py "$here/imgstat.py" tiles95 "$tmp/u1.pfm" "$tmp/u2.pfm")" \
    "$(awk "BEGIN { print 100 * $($py "$here/imgstat.py" noise2 "$tmp/u1.pfm" "$tmp/u2.pfm") }")" "$(mean "$tmp/u1.pfm")"
done
