#!/usr/bin/env bash
# montage.sh - renders the public scenes of ../shared (the four Mitsuba XML
# scenes, the Stanford bunny and Sponza, both without lights of their own)
# and puts them side by side in docs/montage.png, labelled.
#
# usage: bash docs/montage.sh [SHARED_DIR [PAPRSEK]]   (defaults: ../shared, build/paprsek)
# environment: SECONDS_EACH (20: --time of each render), SIZE (400x300)
# needs: ImageMagick's montage (Debian package imagemagick, installed when missing, as root)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
shared=${1:-$repo/../shared}
bin=${2:-$repo/build/paprsek}
secs=${SECONDS_EACH:-20}
size=${SIZE:-400x300}
w=${size%x*}
h=${size#*x}
[ -x "$bin" ] || { echo "montage.sh: $bin is not there: build first (make build)" >&2; exit 1; }
[ -d "$shared/scenes" ] || { echo "montage.sh: $shared/scenes is not there" >&2; exit 1; }
if ! command -v montage >/dev/null; then
    [ "$(id -u)" = 0 ] || { echo "montage.sh: install imagemagick (montage)" >&2; exit 1; }
    apt-get install -y imagemagick >/dev/null || { apt-get update >/dev/null && apt-get install -y imagemagick >/dev/null; }
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
s=$shared/scenes
# name | scene | options
while IFS='|' read -r name scene opts; do
    echo "rendering $name" >&2
    # shellcheck disable=SC2086
    "$bin" render "$s/$scene" -o "$tmp/$name.png" --width "$w" --height "$h" --spp 1 --time "$secs" --quiet $opts
done <<EOF
cornell-box|bitterli/cornell-box/scene_v3.xml|
veach-mis|bitterli/veach-mis/scene.xml|
classroom|bitterli/classroom/scene_v0.6.xml|
veach-door|mitsuba/veach-door/scene.xml|
bunny|bench/stanford-bunny.obj|
sponza|bench/dabrovic-sponza/sponza.obj|--look-from -10,2,0 --look-at 10,5,0 --fov 60
EOF
montage -label '%t' -pointsize 14 -geometry +2+2 -tile 3x \
    "$tmp/cornell-box.png" "$tmp/veach-mis.png" "$tmp/classroom.png" \
    "$tmp/veach-door.png" "$tmp/bunny.png" "$tmp/sponza.png" "$here/montage.png"
echo "wrote $here/montage.png" >&2
