#!/usr/bin/env bash
# paprsek convert on the shared scenes (../shared): Bitterli's and Mitsuba's
# XML scenes, pbrt-v4's, the glTF samples and the Cornell OBJ files convert
# to JSON scenes that render the same bytes as the originals (image and AOVs,
# path tracer and Whitted). Skipped (77) without the shared folder.
# usage: test_convert_shared.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
shared=$2
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
if [ ! -d "$shared/scenes" ]; then echo "SKIP: no shared scenes at $shared/scenes"; exit 77; fi
# shellcheck source=convert_same.sh
. "$here/convert_same.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scenes=()
for f in "$shared"/scenes/cornell/*.obj; do
  case $f in */water.obj) continue ;; esac
  scenes+=("$f")
done
for f in bitterli/cornell-box/scene_v3.xml bitterli/veach-mis/scene.xml bitterli/classroom/scene_v0.6.xml \
         mitsuba/veach-door/scene.xml pbrt-v4/cornell-box/scene-v4.pbrt pbrt-v4/material-testball/scene-v4.pbrt; do
  [ -f "$shared/scenes/$f" ] && scenes+=("$shared/scenes/$f")
done
for f in "$shared"/scenes/gltf/*/*.gltf "$shared"/scenes/gltf/*/*.glb; do
  [ -f "$f" ] && scenes+=("$f")
done
SIZE=${SIZE:-32} SPP=${SPP:-1} convert_same "$bin" "$tmp" "${scenes[@]}"
bad=$?
[ $bad -eq 0 ] && echo "ok"
exit $((bad > 0))
