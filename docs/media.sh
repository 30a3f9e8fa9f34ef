#!/usr/bin/env bash
# media.sh - the README's picture of participating media, docs/media.png: the
# Stanford bunny as jade (a dielectric of index 1.3 around a scattering,
# green-absorbing interior: subsurface scattering) in a room filled with thin
# fog, lit by a spot light whose cone shows in the fog, and a dim point
# light. 512x384, 256 samples per pixel, denoised.
#
# usage: bash docs/media.sh [SHARED_DIR [PAPRSEK [SPP]]]   (defaults: ../shared, build/paprsek, 256)
# needs: the denoiser's weights (make weights), SHARED_DIR/scenes/bench/stanford-bunny.obj
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
shared=${1:-$repo/../shared}
bin=${2:-$repo/build/paprsek}
spp=${3:-256}
[ -x "$bin" ] || { echo "media.sh: $bin is not there: build first (make build)" >&2; exit 1; }
bunny=$shared/scenes/bench/stanford-bunny.obj
[ -f "$bunny" ] || { echo "media.sh: $bunny is not there" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
/usr/bin/python3 - "$tmp" "$repo/bench" "$bunny" <<'EOF_PY'
import sys
sys.path.insert(0, sys.argv[2])
from media_scenes import box, quad  # noqa: E402
d, obj = sys.argv[1], sys.argv[3]
with open(obj) as src, open(f"{d}/bunny.obj", "w") as f:
    f.write("usemtl jade\n")
    f.write(src.read())
with open(f"{d}/room.obj", "w") as f:
    f.write("usemtl wall\n")
    quad(f, (-2, 0, -2), (-2, 0, 2), (2, 0, 2), (2, 0, -2))  # the floor
    quad(f, (-2, 0, -2), (2, 0, -2), (2, 3, -2), (-2, 3, -2))  # the back wall
    f.write("usemtl fogbox\n")
    box(f, (-1.999, 0.001, -1.999), (1.999, 3.0, 1.5))  # where the fog is
with open(f"{d}/media.json", "w") as f:
    f.write('''{"camera": {"look_from": [0, 1.1, 4.2], "look_at": [0, 0.65, 0], "fov": 34},
 "environment": "none",
 "media": [{"name": "fog", "type": "homogeneous", "sigma_a": 0.01, "sigma_s": 0.12, "g": 0.5},
           {"name": "jade", "type": "homogeneous", "sigma_s": 24, "sigma_a": [0.8, 0.08, 0.4], "g": 0.3}],
 "materials": {"jade": {"type": "dielectric", "ior": 1.3, "interior": "jade", "exterior": "fog"},
    "wall": {"type": "diffuse", "albedo": [0.55, 0.55, 0.55]},
    "fogbox": {"type": "interface", "interior": "fog", "exterior": null}},
 "lights": [{"type": "spot", "position": [-1.3, 2.9, 0.6], "direction": [1.3, -2.6, -0.6],
             "intensity": [60, 52, 40], "outer_angle": 20, "inner_angle": 14},
            {"type": "point", "position": [1.5, 2.5, 1.2], "intensity": [1.0, 1.2, 1.6]}],
 "meshes": [{"obj": "room.obj"},
   {"obj": "bunny.obj", "transform": {"translate": [0.135, -0.264, 0], "scale": 8}}]}
''')
EOF_PY
"$bin" render "$tmp/media.json" -o "$here/media.png" --width 512 --height 384 --spp "$spp" --denoise --quiet
echo "wrote $here/media.png" >&2
