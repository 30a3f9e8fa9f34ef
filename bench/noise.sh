#!/usr/bin/env bash
# Noise against time for the path tracer: CornellBox-Original at 512x512
# (camera 0,1,3.9 -> 0,1,0, fov 39.3), all cores, rendered with --time T for
# each T given; prints the relative noise of the back-wall patch x 0.55-0.70,
# y 0.28-0.55 (fractions of the image, y from the top): the standard
# deviation of horizontal neighbour differences / sqrt 2, over the patch mean,
# on the linear image.
# usage: bench/noise.sh [SHARED_DIR [PAPRSEK [SECONDS...]]]
set -euo pipefail
shared=${1:-../shared}
bin=${2:-build/paprsek}
shift 2 2>/dev/null || true
times=${*:-1 2 3 5}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene="$shared/scenes/cornell/CornellBox-Original.obj"
[ -f "$scene" ] || { echo "no $scene (../shared is absent)"; exit 0; }
echo "| --time [s] | wall [s] | passes (1 spp) | relative noise |"
echo "|---|---|---|---|"
for t in $times; do
  start=$(date +%s.%N)
  "$bin" render "$scene" -o "$tmp/n.pfm" --quiet --width 512 --height 512 --time "$t" \
    --look-from 0,1,3.9 --look-at 0,1,0 --fov 39.3 --stats-json "$tmp/s.json" >/dev/null
  end=$(date +%s.%N)
  python3 - "$tmp/n.pfm" "$tmp/s.json" "$t" "$start" "$end" <<'PY'
import json, math, struct, sys
path, stats, t, start, end = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
with open(path, 'rb') as f:
    assert f.readline().strip() == b'PF'
    w, h = map(int, f.readline().split())
    scale = float(f.readline())
    data = f.read()
fmt = ('<' if scale < 0 else '>') + 'f' * (3 * w * h)
px = struct.unpack(fmt, data)
def lum(x, y):  # PFM rows run bottom to top
    i = 3 * ((h - 1 - y) * w + x)
    return 0.2126 * px[i] + 0.7152 * px[i + 1] + 0.0722 * px[i + 2]
x0, x1, y0, y1 = int(0.55 * w), int(0.70 * w), int(0.28 * h), int(0.55 * h)
vals = [lum(x, y) for y in range(y0, y1) for x in range(x0, x1)]
mean = sum(vals) / len(vals)
d = [lum(x + 1, y) - lum(x, y) for y in range(y0, y1) for x in range(x0, x1 - 1)]
md = sum(d) / len(d)
sd = math.sqrt(sum((v - md) ** 2 for v in d) / (len(d) - 1)) / math.sqrt(2)
s = json.load(open(stats))
passes = round(s["samples_per_s"] * s["render_s"] / (w * h)) if s["render_s"] > 0 else 0
print(f"| {t:g} | {end - start:.2f} | {passes} | {100 * sd / mean:.2f} % |")
PY
done
