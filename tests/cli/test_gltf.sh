#!/usr/bin/env bash
# glTF 2.0 assets on the command line: a GLB renders, --camera picks a camera
# (and is refused for other scenes or a camera that is not there), hostile
# assets give exactly one line naming the JSON pointer, exit status 1 and no
# image.
# usage: test_gltf.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
data=$3/gltf
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

# expect NAME STATUS MESSAGE ARGS... : exit STATUS and stderr exactly
# "paprsek: MESSAGE" (nothing for STATUS 0), no image unless STATUS is 0.
expect() {
  local name=$1 want=$2 msg=$3
  shift 3
  rm -f "$tmp"/out.*
  timeout 120 "$bin" "$@" >"$tmp/stdout" 2>"$tmp/stderr" </dev/null
  local rc=$?
  local got
  got=$(cat "$tmp/stderr")
  [ -n "$msg" ] && msg="paprsek: $msg"
  if [ "$rc" -ne "$want" ]; then
    echo "FAIL $name: exit $rc, wanted $want; stderr: $got"; fail=1
  elif [ "$got" != "$msg" ]; then
    echo "FAIL $name: stderr differs"
    echo "     got:    $got"
    echo "     wanted: $msg"
    fail=1
  elif [ "$want" -ne 0 ] && ls "$tmp"/out.* >/dev/null 2>&1; then
    echo "FAIL $name: something was written: $(ls "$tmp"/out.*)"; fail=1
  elif [ "$want" -eq 0 ] && [ ! -s "$tmp/out.png" ]; then
    echo "FAIL $name: no image written"; fail=1
  else
    echo "ok   $name"
  fi
}

expect "glb renders" 0 "" render "$data/cube.glb" -o "$tmp/out.png" --spp 1 --width 24 --height 16 -q
expect "glb camera 0" 0 "" render "$data/cube.glb" --camera 0 -o "$tmp/out.png" --spp 1 --width 24 --height 16 -q
expect "external buffer" 0 "" render "$data/external.gltf" -o "$tmp/out.png" --spp 1 --width 16 --height 16 -q
expect "no such camera" 1 "cube.glb: camera 3: the asset has 1 camera" \
  render "$data/cube.glb" --camera 3 -o "$tmp/out.png"
expect "camera of an obj" 2 "--camera: picks a camera of a glTF asset (.gltf, .glb); '$3/obj_pentagon.obj' is not one" \
  render "$3/obj_pentagon.obj" --camera 0 -o "$tmp/out.png"
expect "camera not a number" 2 "--camera: 'x' must be a camera number (0, 1, ...)" \
  render "$data/cube.glb" --camera x -o "$tmp/out.png"
expect "accessor overflow" 1 "bad_accessor.gltf: /accessors/0: count 100 exceeds bufferView 0 (36 bytes)" \
  render "$data/bad_accessor.gltf" -o "$tmp/out.png"
expect "index out of range" 1 "bad_index.gltf: /meshes/0/primitives/0/indices: index 9 out of range (3 vertices)" \
  render "$data/bad_index.gltf" -o "$tmp/out.png"
expect "bad data uri" 1 "bad_uri.gltf: /buffers/0/uri: malformed base64 in the data: URI" \
  render "$data/bad_uri.gltf" -o "$tmp/out.png"
expect "node cycle" 1 "bad_cycle.gltf: /nodes/1/children/0: node 0 is its own ancestor (a cycle)" \
  render "$data/bad_cycle.gltf" -o "$tmp/out.png"
expect "lying glb" 1 "bad_length.glb: GLB: the header says 1048576 bytes, the file holds 2956" \
  render "$data/bad_length.glb" -o "$tmp/out.png"
exit $fail
