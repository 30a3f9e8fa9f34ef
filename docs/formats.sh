#!/usr/bin/env bash
# formats.sh - scenes of the formats Paprsek reads besides OBJ and Mitsuba:
# pbrt-v4 (Bitterli's Cornell box and material test ball) and glTF 2.0
# (Khronos samples), each rendered at 64 samples per pixel and denoised,
# side by side in docs/formats.png.
#
# usage: bash docs/formats.sh [SHARED_DIR [PAPRSEK]]   (defaults: ../shared, build/paprsek)
# needs: ImageMagick's montage (Debian package imagemagick, installed when missing, as root)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
shared=${1:-$repo/../shared}
bin=${2:-$repo/build/paprsek}
[ -x "$bin" ] || { echo "formats.sh: $bin is not there: build first (make build)" >&2; exit 1; }
[ -d "$shared/scenes" ] || { echo "formats.sh: $shared/scenes is not there" >&2; exit 1; }
if ! command -v montage >/dev/null; then
    [ "$(id -u)" = 0 ] || { echo "formats.sh: install imagemagick (montage)" >&2; exit 1; }
    apt-get install -y imagemagick >/dev/null || { apt-get update >/dev/null && apt-get install -y imagemagick >/dev/null; }
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
s=$shared/scenes
files=()
while IFS='|' read -r name label scene size; do
    echo "rendering $name" >&2
    "$bin" render "$s/$scene" -o "$tmp/$name.png" --width "${size%x*}" --height "${size#*x}" --spp 64 --denoise --quiet
    files+=(-label "$label" "$tmp/$name.png")
done <<SCENES
cornell|pbrt-v4: Cornell box|pbrt-v4/cornell-box/scene-v4.pbrt|300x300
testball|pbrt-v4: material test ball|pbrt-v4/material-testball/scene-v4.pbrt|400x300
spheres|glTF: MetalRoughSpheresNoTextures|gltf/MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.gltf|300x300
transform|glTF: TextureTransformTest|gltf/TextureTransformTest/TextureTransformTest.gltf|400x300
SCENES
montage -pointsize 14 -geometry +2+2 -tile 4x "${files[@]}" "$here/formats.png"
echo "wrote $here/formats.png" >&2
