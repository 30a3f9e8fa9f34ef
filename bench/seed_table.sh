#!/usr/bin/env bash
# The seed's statistics table: CornellBox-Original and CornellBox-Sphere (with
# and without Fresnel) rendered with each accelerator, one line per run.
# usage: bench/seed_table.sh [SHARED_DIR] [PAPRSEK] [SIZE] [ACCELS]
set -euo pipefail
shared=${1:-../shared}
bin=${2:-build/paprsek}
size=${3:-256}
accels=${4:-"none midpoint bvh"}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores"
echo "settings: ${size}x${size}, 1 spp, 32 light samples, max depth 8, all cores"
echo
echo "| scene | fresnel | accel | build [µs] | render [s] | rays | intersection tests | nodes traversed | tests/ray | nodes/ray | traversal time/ray [µs] | Mrays/s |"
echo "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
for scene in Original Sphere; do
  for fresnel in on off; do
    [ "$scene" = Original ] && [ "$fresnel" = off ] && continue  # no dielectrics: identical
    for accel in $accels; do
      "$bin" render "$shared/scenes/cornell/CornellBox-$scene.obj" -o "$tmp/img.png" --quiet --integrator whitted \
        --width "$size" --height "$size" --light-samples 32 --accel "$accel" --fresnel "$fresnel" \
        --stats-json "$tmp/s.json" >/dev/null
      python3 - "$tmp/s.json" "$scene" "$fresnel" "$accel" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); r = max(s["rays"], 1)
print(f"| CornellBox-{sys.argv[2]} | {sys.argv[3]} | {sys.argv[4]} | {s['build_us']:.0f} | {s['render_s']:.3f} | "
      f"{s['rays']} | {s['intersection_tests']} | {s['nodes_visited']} | {s['intersection_tests']/r:.1f} | "
      f"{s['nodes_visited']/r:.1f} | {s['render_s']*s['threads']/r*1e6:.3f} | {s['mrays_per_s']:.2f} |")
PY
    done
  done
done
