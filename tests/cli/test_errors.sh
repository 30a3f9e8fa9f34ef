#!/usr/bin/env bash
# Every class of bad input: one clear message on stderr that names the file
# and line, a non-zero exit, no image written and no crash (exit >= 128).
# usage: test_errors.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

# expect NAME STATUS PATTERN ARGS... : runs paprsek with ARGS, wants exit STATUS,
# stderr matching the extended regex PATTERN, and no $tmp/out.png.
expect() {
  local name=$1 want=$2 pat=$3
  shift 3
  rm -f "$tmp/out.png"
  "$bin" "$@" >"$tmp/stdout" 2>"$tmp/stderr"
  local rc=$?
  local msg
  msg=$(cat "$tmp/stderr")
  if [ "$rc" -ne "$want" ]; then
    echo "FAIL $name: exit $rc, wanted $want; stderr: $msg"; fail=1
  elif ! grep -Eq -- "$pat" "$tmp/stderr"; then
    echo "FAIL $name: stderr does not match /$pat/: $msg"; fail=1
  elif [ -e "$tmp/out.png" ]; then
    echo "FAIL $name: an image was written"; fail=1
  elif ls "$tmp"/out.png.tmp.* >/dev/null 2>&1; then
    echo "FAIL $name: a temporary file was left behind"; fail=1
  else
    echo "ok   $name: $(head -n 1 "$tmp/stderr")"
  fi
}

obj() { printf "%b" "$2" > "$tmp/$1"; }
render() { expect "$1" "$2" "$3" render "$tmp/$4" -o "$tmp/out.png" --width 8 --height 8 "${@:5}"; }

obj tri.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n'

expect "missing scene file" 1 "no-such\.obj: cannot open" render "$tmp/no-such.obj" -o "$tmp/out.png"
mkdir "$tmp/dir.obj"
expect "scene is a folder" 1 "dir\.obj: not a regular file" render "$tmp/dir.obj" -o "$tmp/out.png"
expect "unknown scene type" 1 "unknown scene format" render "$tmp/scene.txt" -o "$tmp/out.png"

obj badnum.obj 'v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n'
render "bad number" 1 "badnum\.obj:2: " badnum.obj
obj junk.obj 'v 0 0 0\nv 1.0abc 0 0\nv 0 1 0\nf 1 2 3\n'
render "trailing junk in a number" 1 "junk\.obj:2: " junk.obj
obj short.obj 'v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n'
render "missing coordinate" 1 "short\.obj:2: " short.obj
obj range.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n'
render "index out of range" 1 "range\.obj:4: .*(range|9)" range.obj
obj neg.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n'
render "negative index out of range" 1 "neg\.obj:4: " neg.obj
obj zero.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n'
render "zero index" 1 "zero\.obj:4: .*(zero|0)" zero.obj
obj alpha.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 b 3\n'
render "non-numeric index" 1 "alpha\.obj:4: " alpha.obj
obj two.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n'
render "face with two vertices" 1 "two\.obj:4: .*(3|three|vert)" two.obj
obj nan.obj 'v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n'
render "NaN vertex" 1 "nan\.obj:2: " nan.obj
obj inf.obj 'v 0 0 0\nv 1e99 0 0\nv 0 1 0\nf 1 2 3\n'
render "infinite vertex" 1 "inf\.obj:2: " inf.obj
obj empty.obj '# nothing here\n'
render "no geometry" 1 "empty\.obj: no renderable geometry" empty.obj
obj flat.obj 'v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n'
render "only degenerate triangles" 1 "flat\.obj: no renderable geometry" flat.obj

obj bad.json '{ "camera": { "fov": 40,\n  "look_from": [0,0,5] \n'
render "bad JSON" 1 "bad\.json:[0-9]+: " bad.json
obj types.json '{ "meshes": [ { "obj": "tri.obj" } ],\n  "camera": { "look_from": "here", "look_at": [0,0,0], "fov": 40 } }\n'
render "wrong JSON type" 1 "types\.json:[0-9]+: .*look_from" types.json
obj radius.json '{ "spheres": [ { "center": [0,0,0], "radius": -1 } ] }\n'
render "non-positive radius" 1 "radius\.json:[0-9]+: .*radius" radius.json
obj fov.json '{ "meshes": [ { "obj": "tri.obj" } ],\n  "camera": { "look_from": [0,0,5], "look_at": [0,0,0], "fov": 0 } }\n'
render "zero fov" 1 "fov\.json:[0-9]+: .*fov" fov.json
obj self.json '{ "meshes": [ { "obj": "tri.obj" } ],\n  "camera": { "look_from": [1,1,1], "look_at": [1,1,1], "fov": 40 } }\n'
render "camera looking at itself" 1 "self\.json:[0-9]+: .*(same|itself|differ)" self.json
obj nomesh.json '{ "meshes": [ { "obj": "missing.obj" } ] }\n'
render "missing mesh file" 1 "missing\.obj" nomesh.json

expect "zero fov on the command line" 2 "fov" render "$tmp/tri.obj" -o "$tmp/out.png" --fov 0
expect "camera at its target" 1 "same point" render "$tmp/tri.obj" -o "$tmp/out.png" --look-from 1,1,1 --look-at 1,1,1
expect "absurd width" 2 "width" render "$tmp/tri.obj" -o "$tmp/out.png" --width 100000000
expect "negative height" 2 "height" render "$tmp/tri.obj" -o "$tmp/out.png" --height -5
expect "non-numeric spp" 2 "spp" render "$tmp/tri.obj" -o "$tmp/out.png" --spp lots
expect "absurd spp" 2 "spp" render "$tmp/tri.obj" -o "$tmp/out.png" --spp 99999999
expect "absurd pixel count" 1 "larger than" render "$tmp/tri.obj" -o "$tmp/out.png" --width 16384 --height 16384
expect "unknown accelerator" 2 "unknown accelerator" render "$tmp/tri.obj" -o "$tmp/out.png" --accel kd
expect "unknown option" 2 "unknown option" render "$tmp/tri.obj" -o "$tmp/out.png" --bogus
expect "no output" 2 "no output" render "$tmp/tri.obj"
expect "unknown image format" 1 "unknown image format" render "$tmp/tri.obj" -o "$tmp/out.bmp" --width 8 --height 8
expect "output over the scene" 2 "refusing" render "$tmp/tri.obj" -o "$tmp/tri.obj"
expect "unwritable folder" 1 "cannot create" render "$tmp/tri.obj" -o "$tmp/no/such/dir/out.png" --width 8 --height 8

# an existing image is replaced only by a complete one
"$bin" render "$tmp/tri.obj" -o "$tmp/keep.png" --width 8 --height 8 --quiet || { echo "FAIL: good render"; fail=1; }
cp "$tmp/keep.png" "$tmp/keep.orig"
"$bin" render "$tmp/nan.obj" -o "$tmp/keep.png" --width 8 --height 8 2>/dev/null
cmp -s "$tmp/keep.png" "$tmp/keep.orig" || { echo "FAIL: a failed render touched an existing image"; fail=1; }

exit $fail
