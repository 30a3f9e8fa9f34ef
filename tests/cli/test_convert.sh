#!/usr/bin/env bash
# paprsek convert: the scenes of tests/data in every format (OBJ/MTL, JSON,
# Mitsuba XML, pbrt-v4, glTF, media under volpath; tests/data/convert has
# spot lights of each falloff, distant lights, sun and skies, rotated
# environment maps, thin-lens and orthographic cameras) convert to JSON scenes that
# render the same bytes (image and AOVs, path tracer and Whitted); and the
# errors: a missing input, an unwritable output, an output that is not
# .json, content the JSON format cannot hold, usage errors - each with a
# message and nothing written.
# usage: test_convert.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
data=$(cd "$3" && pwd)
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=convert_same.sh
. "$here/convert_same.sh"
tmp=$(mktemp -d)
trap 'chmod -R u+w "$tmp"; rm -rf "$tmp"' EXIT
fail=0

convert_same "$bin" "$tmp" \
  "$data/conformance/box.obj" "$data/conformance/box.json" "$data/conformance/box.xml" \
  "$data/conformance/box.pbrt" "$data/conformance/box.gltf" \
  "$data/media/fog.json|volpath" "$data/media/fog.xml|volpath" "$data/media/fog.pbrt|volpath" \
  "$data/gltf/instanced.gltf" "$data/pbrt/plymesh.pbrt" "$data/json_example.json" \
  "$data/tex_json.json" "$data/fuzz_seed_env.json" "$data/gltf/cube.glb" "$data/gltf/external.gltf" \
  "$data/conformance/box_mr.json" "$data/conformance/box_nomtl.obj" "$data/pbrt/include_main.pbrt" \
  "$data/fuzz_seed_full.json" "$data/fuzz_seed_full.xml" "$data/tex_scene.obj" "$data/obj_mat.obj" \
  "$data/convert/lights.xml" "$data/convert/lights.pbrt" "$data/convert/lights.json" "$data/convert/spot.gltf" \
  "$data/gltf/uv_sets.gltf" \
  "$data/../../bench/scenes/materials.json" "$data/../../bench/scenes/materials.xml" \
  "$data/sheets/box.pbrt" "$data/sheets/box.xml" "$data/sheets/box.json" || fail=1

# names: a material named as the default one, and two of one name (renamed NAME#N)
printf '{"materials": [{"name": "default", "kd": [0.9, 0.1, 0.1]}, {"name": "twice", "kd": [0.1, 0.9, 0.1]},
  {"name": "twice", "kd": [0.1, 0.1, 0.9]}],
  "meshes": [{"obj": "%s/json_floor.obj"}],
  "spheres": [{"center": [-1, 0.5, 0], "radius": 0.5}, {"center": [0, 0.5, 0], "radius": 0.5, "material": "default"},
  {"center": [1, 0.5, 0], "radius": 0.5, "material": "twice"}], "environment": [1, 1, 1]}' "$data" >"$tmp/names.json"
convert_same "$bin" "$tmp" "$tmp/names.json" || fail=1

# a grid medium with all three grids (density of 3 channels), emitting, in a moved box
printf '{"media": [{"name": "g", "type": "grid", "sigma_t": [2, 3, 4], "albedo": 0.8, "g": 0.4, "emission": [0.5, 0.3, 0.1],
  "density": {"size": [2, 2, 2], "channels": 3, "data": [1,0,1, 2,1,0, 0,1,1, 1,1,1, 3,2,1, 0,0,1, 1,2,3, 0.5,0.5,0.5]},
  "albedo_grid": {"size": [2, 1, 1], "channels": 1, "data": [0.2, 0.9]},
  "emission_grid": {"size": [1, 2, 1], "channels": 3, "data": [1, 0, 0, 0, 1, 1]},
  "bounds": {"min": [-1, 0, -1], "max": [1, 2, 1]}, "transform": {"rotate": [20, 0, 1, 0]}}],
  "materials": [{"name": "boundary", "type": "interface", "interior": "g", "exterior": null}],
  "meshes": [{"obj": "%s/media/fog_cube.obj"}],
  "spheres": [{"center": [0, -101, 0], "radius": 100}],
  "lights": [{"position": [0, 5, 3], "intensity": 30}], "camera": {"look_from": [0, 1, 5], "look_at": [0, 1, 0]}}' "$data" >"$tmp/grid.json"
convert_same "$bin" "$tmp" "$tmp/grid.json|volpath" || fail=1

# a converted scene (records, PLY meshes, raw pixels) converts again to the same image
mkdir -p "$tmp/again"
if "$bin" convert "$data/convert/lights.xml" -o "$tmp/again/first.json" -q 2>"$tmp/err"; then
  convert_same "$bin" "$tmp/again" "$tmp/again/first.json" || fail=1
else
  echo "FAIL converting lights.xml: $(cat "$tmp/err")"; fail=1
fi

expect() { # name status message-fragment command...
  local name=$1 want=$2 msg=$3; shift 3
  "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  if [ $rc != "$want" ]; then echo "FAIL $name: exit $rc, expected $want ($(cat "$tmp/err"))"; fail=1; return; fi
  if ! grep -q -- "$msg" "$tmp/err"; then echo "FAIL $name: message '$(cat "$tmp/err")' lacks '$msg'"; fail=1; fi
}
mkdir -p "$tmp/e"
expect missing-input 1 "nothere.obj" "$bin" convert "$tmp/nothere.obj" -o "$tmp/e/x.json"
expect no-output 2 "no output" "$bin" convert "$data/conformance/box.obj"
expect not-json 2 "(.json)" "$bin" convert "$data/conformance/box.obj" -o "$tmp/e/x.xml"
expect no-folder 1 "$tmp/e/none/x.json" "$bin" convert "$data/conformance/box.obj" -o "$tmp/e/none/x.json"
expect unknown-option 2 "unknown option" "$bin" convert "$data/conformance/box.obj" -o "$tmp/e/x.json" --frobnicate
expect two-scenes 2 "more than one scene" "$bin" convert "$data/conformance/box.obj" "$data/conformance/box.obj" -o "$tmp/e/x.json"
mkdir -p "$tmp/ro" && chmod a-w "$tmp/ro"
if [ ! -w "$tmp/ro" ]; then # (root writes anywhere)
  expect unwritable 1 "$tmp/ro" "$bin" convert "$data/conformance/box.obj" -o "$tmp/ro/x.json"
fi
# instances kept as instances are written as instances ("instance" entries) and kept again
if "$bin" convert "$data/gltf/instanced.gltf" -o "$tmp/kept.json" --config scene.instances=keep -q 2>"$tmp/err"; then
  grep -q '"instance": {"mesh": 0' "$tmp/kept.json" || { echo "FAIL kept instances not written as instances"; fail=1; }
  for src in "$data/gltf/instanced.gltf" "$tmp/kept.json"; do
    "$bin" render "$src" -o "$tmp/kept.$(basename "$src").pfm" --config scene.instances=keep --width 40 --height 30 \
      --spp 2 --aov albedo,normal,depth,heatmap -q || { echo "FAIL rendering $src with kept instances"; fail=1; }
  done
  for x in "" .albedo .normal .depth .heatmap; do
    cmp -s "$tmp/kept.instanced.gltf$x.pfm" "$tmp/kept.kept.json$x.pfm" ||
      { echo "FAIL kept instances render differently (image$x)"; fail=1; }
  done
else
  echo "FAIL converting with kept instances: $(cat "$tmp/err")"; fail=1
fi
# the record forms refuse what no reader makes
printf '{"materials": [{"name": "m", "record": {"type": 99}}], "spheres": [{"center": [0, 0, 0], "radius": 1}]}' >"$tmp/badtype.json"
expect record-type 1 "badtype.json:1: materials\[0\].record: type must be in 0..13" "$bin" render "$tmp/badtype.json" -o "$tmp/e/x.pfm"
# a mix (type 9) of a material that does not come before it
printf '{"materials": [{"name": "m", "record": {"type": 9, "mix_a": 0, "mix_b": 1}}], "spheres": [{"center": [0, 0, 0], "radius": 1}]}' >"$tmp/badmix.json"
expect record-mix 1 "badmix.json:1: materials\[0\].record: mix_a and mix_b must be numbers of materials before this one" "$bin" render "$tmp/badmix.json" -o "$tmp/e/x.pfm"
printf '{"lights": [{"record": {"spot_falloff": 5}}], "spheres": [{"center": [0, 0, 0], "radius": 1}]}' >"$tmp/badlight.json"
expect record-light 1 "lights\[0\].record: spot_falloff must be 0, 1 or 2" "$bin" render "$tmp/badlight.json" -o "$tmp/e/x.pfm"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nproperty int material\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 4\n' >"$tmp/tri.ply"
printf '{"meshes": [{"ply": "tri.ply", "materials": ["default"]}]}' >"$tmp/badply.json"
expect ply-material 1 "triangle 0: material 4 is not an index" "$bin" render "$tmp/badply.json" -o "$tmp/e/x.pfm"
"$bin" convert --help | grep -q "usage: paprsek convert" || { echo "FAIL convert --help"; fail=1; }
"$bin" help convert | grep -q "usage: paprsek convert" || { echo "FAIL help convert"; fail=1; }
"$bin" --help | grep -q "convert SCENE" || { echo "FAIL paprsek --help does not list convert"; fail=1; }
# every failure above left nothing behind
if [ -n "$(ls -A "$tmp/e")" ]; then echo "FAIL files left after failures: $(ls -A "$tmp/e")"; fail=1; fi

[ $fail -eq 0 ] && echo "ok"
exit $fail
