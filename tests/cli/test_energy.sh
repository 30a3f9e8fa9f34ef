#!/usr/bin/env bash
# --energy-compensation: a glTF asset renders with it on by default (the
# same bytes as --energy-compensation on, others with off), an OBJ scene
# with it off; the JSON that `paprsek convert` writes of the asset keeps it
# on (the same bytes again), and an OBJ scene with it on differs from off
# only where a rough microfacet lobe is (a diffuse scene: the same bytes).
# usage: test_energy.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
data=$3
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL $*"; fail=1; }
ok() { echo "ok   $*"; }
r() { timeout 120 "$bin" render "$@" --width 24 --height 24 --spp 2 --threads 2 -q || bad "render $*: exit $?"; }

asset="$data/conformance/box.gltf"
r "$asset" -o "$tmp/default.pfm"
r "$asset" -o "$tmp/on.pfm" --energy-compensation on
r "$asset" -o "$tmp/off.pfm" --energy-compensation off
if cmp -s "$tmp/default.pfm" "$tmp/on.pfm"; then ok "glTF: on by default"; else bad "glTF: the default is not on"; fi
if cmp -s "$tmp/default.pfm" "$tmp/off.pfm"; then bad "glTF: off renders as on"; else ok "glTF: off differs"; fi
timeout 120 "$bin" convert "$asset" -o "$tmp/box.json" >/dev/null 2>&1 || bad "convert: exit $?"
grep -q '"energy_compensation": *true' "$tmp/box.json" && ok "convert writes the setting" ||
  bad "convert: no energy_compensation in the JSON"
r "$tmp/box.json" -o "$tmp/conv.pfm"
if cmp -s "$tmp/default.pfm" "$tmp/conv.pfm"; then ok "converted: the same bytes"; else bad "converted: the image differs"; fi

# OBJ: off by default; a rough metal changes with on, a diffuse scene does not
printf 'newmtl m\nKd 0.5 0.5 0.5\n' >"$tmp/d.mtl"
printf 'mtllib d.mtl\nusemtl m\nv -1 0 -1\nv 1 0 -1\nv 0 1.5 -1\nf 1 2 3\n' >"$tmp/d.obj"
r "$tmp/d.obj" -o "$tmp/d0.pfm" --env 1,1,1
r "$tmp/d.obj" -o "$tmp/d1.pfm" --env 1,1,1 --energy-compensation on
r "$tmp/d.obj" -o "$tmp/d2.pfm" --env 1,1,1 --energy-compensation off
if cmp -s "$tmp/d0.pfm" "$tmp/d1.pfm" && cmp -s "$tmp/d0.pfm" "$tmp/d2.pfm"; then ok "diffuse OBJ: the same bytes"; else
  bad "diffuse OBJ: compensation changed the image"; fi
cat >"$tmp/m.json" <<JSON
{"materials": {"metal": {"type": "conductor", "specular": [0.9, 0.8, 0.6], "roughness": 0.8}},
 "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0], "fov": 30},
 "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "metal"}], "environment": [1, 1, 1]}
JSON
r "$tmp/m.json" -o "$tmp/m0.pfm"
r "$tmp/m.json" -o "$tmp/m2.pfm" --energy-compensation off
r "$tmp/m.json" -o "$tmp/m1.pfm" --energy-compensation on
if cmp -s "$tmp/m0.pfm" "$tmp/m2.pfm"; then ok "JSON: off by default"; else bad "JSON: the default is not off"; fi
if cmp -s "$tmp/m0.pfm" "$tmp/m1.pfm"; then bad "rough metal: on renders as off"; else ok "rough metal: on differs"; fi
sed 's/"environment"/"render": {"energy_compensation": true}, "environment"/' "$tmp/m.json" >"$tmp/m_on.json"
r "$tmp/m_on.json" -o "$tmp/m3.pfm"
if cmp -s "$tmp/m1.pfm" "$tmp/m3.pfm"; then ok "JSON render.energy_compensation"; else bad "JSON render.energy_compensation: differs from --energy-compensation on"; fi
exit $fail
