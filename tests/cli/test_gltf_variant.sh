#!/usr/bin/env bash
# --variant on the command line: a glTF asset's material variant
# (KHR_materials_variants) is drawn; a variant that maps the primitive to
# a material equal to its default renders the same bytes as no --variant,
# one that maps it to another colour does not; an unknown name is one line
# listing the asset's variants (exit 1, no image); --variant is refused for
# scenes that are not glTF.
# usage: test_gltf_variant.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
# a square of two triangles facing +z (the default camera looks at it)
buf="data:application/octet-stream;base64,AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAACAPwAAgD8AAAAAAACAvwAAgD8AAAAAAACAvwAAgL8AAAAAAACAPwAAgD8AAAAA"
cat >"$tmp/v.gltf" <<JSON
{"asset":{"version":"2.0"},"extensionsUsed":["KHR_materials_variants"],
 "extensions":{"KHR_materials_variants":{"variants":[{"name":"same"},{"name":"red"}]}},
 "buffers":[{"byteLength":72,"uri":"$buf"}],
 "bufferViews":[{"buffer":0,"byteLength":72}],
 "accessors":[{"bufferView":0,"componentType":5126,"count":6,"type":"VEC3","min":[-1,-1,0],"max":[1,1,0]}],
 "materials":[{"name":"grey","emissiveFactor":[0.5,0.5,0.5]},{"name":"grey too","emissiveFactor":[0.5,0.5,0.5]},
              {"name":"red","emissiveFactor":[1,0,0]}],
 "meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0,
   "extensions":{"KHR_materials_variants":{"mappings":[{"material":1,"variants":[0]},{"material":2,"variants":[1]}]}}}]}],
 "cameras":[{"type":"perspective","perspective":{"yfov":0.8,"znear":0.1}}],
 "nodes":[{"mesh":0},{"camera":0,"translation":[0,0,3]}],"scenes":[{"nodes":[0,1]}],"scene":0}
JSON
r() { timeout 120 "$bin" render "$tmp/v.gltf" -o "$1" --spp 1 --width 16 --height 16 -q "${@:2}"; }
r "$tmp/default.pfm" || { echo "FAIL default render"; fail=1; }
r "$tmp/same.pfm" --variant same || { echo "FAIL variant same"; fail=1; }
r "$tmp/red.pfm" --variant red || { echo "FAIL variant red"; fail=1; }
if cmp -s "$tmp/default.pfm" "$tmp/same.pfm"; then echo "ok   variant of an equal material: the same bytes"
else echo "FAIL variant 'same' differs from the default"; fail=1; fi
if ! cmp -s "$tmp/default.pfm" "$tmp/red.pfm"; then echo "ok   variant red: another image"
else echo "FAIL variant 'red' renders the default"; fail=1; fi
rm -f "$tmp/out.png"
got=$("$bin" render "$tmp/v.gltf" -o "$tmp/out.png" --variant blue 2>&1 >/dev/null); rc=$?
want="paprsek: v.gltf: variant 'blue' is not one of the asset's: 'same', 'red'"
if [ $rc -eq 1 ] && [ "$got" = "$want" ] && [ ! -e "$tmp/out.png" ]; then echo "ok   unknown variant"
else echo "FAIL unknown variant: exit $rc, '$got'"; fail=1; fi
got=$("$bin" render "$3/obj_pentagon.obj" -o "$tmp/out.png" --variant red 2>&1 >/dev/null); rc=$?
want="paprsek: --variant: picks a material variant of a glTF asset (.gltf, .glb); '$3/obj_pentagon.obj' is not one"
if [ $rc -eq 2 ] && [ "$got" = "$want" ]; then echo "ok   variant of an obj refused"
else echo "FAIL variant of an obj: exit $rc, '$got'"; fail=1; fi
exit $fail
