#!/usr/bin/env bash
# denoise.sh - the same wall time, raw and denoised: each scene rendered raw
# with --time T, and with --time (T - the denoiser's time) --denoise, so that
# both whole renders take about T; side by side in docs/denoise.png.
#
# usage: bash docs/denoise.sh [SHARED_DIR [PAPRSEK]]   (defaults: ../shared, build/paprsek)
# environment: SECONDS_EACH (4), SIZE (400x300)
# needs: ImageMagick's montage (Debian package imagemagick, installed when missing, as root)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
shared=${1:-$repo/../shared}
bin=${2:-$repo/build/paprsek}
secs=${SECONDS_EACH:-4}
size=${SIZE:-400x300}
w=${size%x*}
h=${size#*x}
[ -x "$bin" ] || { echo "denoise.sh: $bin is not there: build first (make build)" >&2; exit 1; }
[ -d "$shared/scenes" ] || { echo "denoise.sh: $shared/scenes is not there" >&2; exit 1; }
if ! command -v montage >/dev/null; then
    [ "$(id -u)" = 0 ] || { echo "denoise.sh: install imagemagick (montage)" >&2; exit 1; }
    apt-get install -y imagemagick >/dev/null || { apt-get update >/dev/null && apt-get install -y imagemagick >/dev/null; }
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
s=$shared/scenes
files=()
while IFS='|' read -r name scene opts; do
    echo "rendering $name" >&2
    # the denoiser's time at this size, measured on this machine
    # shellcheck disable=SC2086
    "$bin" render "$s/$scene" -o "$tmp/probe.exr" --width "$w" --height "$h" --spp 1 --aov albedo,normal --quiet $opts
    dn=$("$bin" denoise "$tmp/probe.exr" -o "$tmp/probe.pfm" --quiet --stats | awk '/^denoise \[s\]/ { print $3 }')
    td=$(awk "BEGIN { t = $secs - $dn; print (t > 0.1 ? t : 0.1) }")
    # shellcheck disable=SC2086
    "$bin" render "$s/$scene" -o "$tmp/$name-raw.png" --width "$w" --height "$h" --spp 1 --time "$secs" --quiet $opts
    # shellcheck disable=SC2086
    "$bin" render "$s/$scene" -o "$tmp/$name-dn.png" --width "$w" --height "$h" --spp 1 --time "$td" --denoise --quiet $opts
    files+=(-label "$name: raw, ${secs} s" "$tmp/$name-raw.png" -label "$name: denoised, ${secs} s" "$tmp/$name-dn.png")
done <<SCENES
cornell-box|cornell/CornellBox-Original.obj|--look-from 0,1,3.9 --look-at 0,1,0 --fov 39.3
classroom|bitterli/classroom/scene_v0.6.xml|
veach-door|mitsuba/veach-door/scene.xml|
SCENES
montage -pointsize 14 -geometry +2+2 -tile 2x "${files[@]}" "$here/denoise.png"
echo "wrote $here/denoise.png" >&2
