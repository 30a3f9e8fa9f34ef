#!/usr/bin/env bash
# A glTF asset rendered the way the Khronos Render Fidelity project
# (google/model-viewer, packages/render-fidelity-tools) renders its
# scenarios, so that Paprsek's image can be put beside the project's
# published ones (test/goldens/NAME/*-golden.png there):
#   - an orbit camera about a target (by default the centre of the asset's
#     bounds), theta degrees around +y from +z, phi degrees down from +y,
#     at a radius (or auto: the bounding sphere just fills the view), as
#     model-viewer's camera-orbit and three.js's setFromSphericalCoords;
#   - a 45 degree vertical field of view, 768x768 pixels (the project's
#     defaults; a scenario of its config.json may say otherwise: pass
#     --width/--height/--fov/--look-at after OUT);
#   - the scenario's environment image lights the asset, and is not seen:
#     a transparent background (PNG with alpha);
#   - Khronos PBR Neutral as the tone curve (model-viewer's default), into
#     8-bit sRGB.
# The environment's orientation is Paprsek's lat-long convention
# (docs/scene-format.md); it has not been checked against three.js's.
#
# usage: bench/render_fidelity.sh ASSET ENV ORBIT OUT.png [paprsek render options...]
#   ASSET  a .gltf or .glb
#   ENV    a .hdr or .exr environment (or a grey value, e.g. 1)
#   ORBIT  THETA,PHI,RADIUS (degrees, degrees, scene units), THETA,PHI,auto,
#          or auto (0,90,auto: the project's default orbit, from the front)
#   OUT    the 8-bit PNG to write
# environment: PAPRSEK (default build/paprsek), SPP (default 256),
#   TONEMAP (default pbr-neutral), SIZE (default 768)
set -euo pipefail
if [ $# -lt 4 ]; then
  sed -n '2,/^set -e/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
  exit 2
fi
asset=$1 env=$2 orbit=$3 out=$4
shift 4
bin=${PAPRSEK:-build/paprsek}
[ "$orbit" = auto ] && orbit=0,90,auto
case $out in *.png|*.PNG) ;; *) echo "render_fidelity.sh: OUT must be a .png" >&2; exit 2 ;; esac
exec "$bin" render "$asset" -o "$out" --env "$env" --camera-orbit "$orbit" --fov 45 \
  --width "${SIZE:-768}" --height "${SIZE:-768}" --spp "${SPP:-256}" \
  --transparent --tonemap "${TONEMAP:-pbr-neutral}" "$@"
