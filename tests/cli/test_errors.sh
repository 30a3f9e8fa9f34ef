#!/usr/bin/env bash
# Every class of bad input: exactly one line on stderr, the one given here
# (file and line named where there are some), the given exit status (1: the
# input is bad, 2: the command line is), no image and no temporary file
# written, and no crash.
# usage: test_errors.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
data=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

# expect NAME STATUS MESSAGE ARGS... : runs paprsek with ARGS and wants exit
# STATUS, stderr exactly "paprsek: MESSAGE", and nothing written at $tmp/out.*
# (for STATUS 0, a warning that is not fatal, the image written).
expect() {
  local name=$1 want=$2 msg="paprsek: $3"
  shift 3
  rm -f "$tmp"/out.*
  timeout 120 "$bin" "$@" >"$tmp/stdout" 2>"$tmp/stderr" </dev/null
  local rc=$?
  local got
  got=$(cat "$tmp/stderr")
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
    echo "ok   $name: $got"
  fi
}

put() { printf "%b" "$2" >"$tmp/$1"; }
# render NAME STATUS MESSAGE SCENE [ARGS...]: renders $tmp/SCENE at 8x8.
render() { expect "$1" "$2" "$3" render "$tmp/$4" -o "$tmp/out.png" --width 8 --height 8 "${@:5}"; }

put tri.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n'

# ---- scene files that cannot be read
expect "missing scene file" 1 "$tmp/no-such.obj: cannot open: No such file or directory" \
  render "$tmp/no-such.obj" -o "$tmp/out.png"
mkdir "$tmp/dir.obj"
expect "scene is a folder" 1 "$tmp/dir.obj: not a regular file" render "$tmp/dir.obj" -o "$tmp/out.png"
if mkfifo "$tmp/fifo.obj" 2>/dev/null; then # opening it must not wait for a writer
  expect "scene is a FIFO" 1 "$tmp/fifo.obj: not a regular file" render "$tmp/fifo.obj" -o "$tmp/out.png"
fi
put scene.txt 'v 0 0 0\n'
expect "unknown scene type" 1 "$tmp/scene.txt: unknown scene format (expected .obj, .json, .xml, .pbrt, .gltf or .glb)" \
  render "$tmp/scene.txt" -o "$tmp/out.png"
put bad.xml '<scene version="3.0.0">\n<shape type="cube">\n</scene>\n'
expect "malformed XML" 1 "bad.xml:3: malformed XML: mismatched tag" render "$tmp/bad.xml" -o "$tmp/out.png"
put param.xml '<scene version="3.0.0">\n<shape type="$kind"/><emitter type="point"><point name="position" x="0" y="0" z="5"/></emitter>\n</scene>\n'
expect "undefined XML parameter" 1 'param.xml:2: type="...$kind...": no <default name="kind"> defines $kind' \
  render "$tmp/param.xml" -o "$tmp/out.png"
expect "-D without a value" 2 "-D kind: expected NAME=VALUE" render "$tmp/param.xml" -D kind -o "$tmp/out.png"
rm -f "$tmp"/out.*
if "$bin" render "$tmp/param.xml" -D kind=cube -o "$tmp/out.png" --spp 1 --width 4 --height 4 2>"$tmp/stderr" &&
  [ -s "$tmp/out.png" ] && [ ! -s "$tmp/stderr" ]; then
  echo "ok   -D sets a parameter"
else
  echo "FAIL -D sets a parameter: $(cat "$tmp/stderr")"; fail=1
fi
if truncate -s 2049M "$tmp/huge.obj" 2>/dev/null; then # sparse: takes no disk space
  render "scene file too large" 1 "$tmp/huge.obj: file is larger than 2147483648 bytes" huge.obj
  rm -f "$tmp/huge.obj"
fi

# ---- OBJ
put badnum.obj 'v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n'
render "bad number" 1 "badnum.obj:2: bad number 'zero'" badnum.obj
put junk.obj 'v 0 0 0\nv 1.0abc 0 0\nv 0 1 0\nf 1 2 3\n'
render "trailing junk in a number" 1 "junk.obj:2: bad number '1.0abc'" junk.obj
put short.obj 'v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n'
render "missing coordinate" 1 "short.obj:2: v needs 3 coordinates, found 2" short.obj
put long.obj 'v 0 0 0\nv 1 0 0 1 2\nv 0 1 0\nf 1 2 3\n'
render "five numbers on a vertex" 1 "long.obj:2: v takes x y z, then w or r g b; found 5 numbers" long.obj
put range.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n'
render "index out of range" 1 "range.obj:4: face index 9 out of range (1..3)" range.obj
put neg.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n'
render "negative index out of range" 1 "neg.obj:4: face index -4 out of range (-3..-1)" neg.obj
put early.obj 'f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n'
render "face before its vertices" 1 "early.obj:1: face index 1 out of range (none defined yet)" early.obj
put zero.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n'
render "zero index" 1 "zero.obj:4: face index 0 is not allowed (indices start at 1)" zero.obj
put alpha.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 b 3\n'
render "non-numeric index" 1 "alpha.obj:4: bad face vertex 'b'" alpha.obj
put two.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n'
render "face with two vertices" 1 "two.obj:4: face has 2 vertices, at least 3 are needed" two.obj
put vt.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n'
render "texture index out of range" 1 "vt.obj:5: texture coordinate index 2 out of range (1..1)" vt.obj
put vn.obj 'v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n'
render "normal index out of range" 1 "vn.obj:5: normal index 2 out of range (1..1)" vn.obj
put nan.obj 'v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n'
render "NaN vertex" 1 "nan.obj:2: number 'nan' is not a finite float" nan.obj
put inf.obj 'v 0 0 0\nv 1e99 0 0\nv 0 1 0\nf 1 2 3\n'
render "infinite vertex" 1 "inf.obj:2: number '1e99' is not a finite float" inf.obj
{ printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf'; for i in $(seq 1 1366); do printf ' 1 2 3'; done; printf '\n'; } >"$tmp/ngon.obj"
render "face with too many vertices" 1 "ngon.obj:4: face has more than 4096 vertices" ngon.obj
put empty.obj '# nothing here\n'
render "no geometry" 1 "empty.obj: no renderable geometry (0 triangles, 0 degenerate, no spheres)" empty.obj
put flat.obj 'v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n'
render "only degenerate triangles" 1 "flat.obj: no renderable geometry (1 triangles, 1 degenerate, no spheres)" flat.obj --quiet

# ---- MTL (read through an OBJ)
put badmtl.obj 'mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n'
put bad.mtl 'newmtl a\nKd 1 1 1\nKd 1 2\n'
render "MTL colour with two numbers" 1 "bad.mtl:3: Kd needs 1 or 3 numbers, found 2" badmtl.obj
put bad.mtl 'newmtl a\nillum two\n'
render "MTL illumination model not a number" 1 "bad.mtl:2: bad illumination model 'two'" badmtl.obj
put bad.mtl 'newmtl\n'
render "MTL material without a name" 1 "bad.mtl:1: newmtl needs a name" badmtl.obj
rm -f "$tmp/bad.mtl"
mkfifo "$tmp/bad.mtl" 2>/dev/null &&
  render "MTL library that is a FIFO" 0 "warning: badmtl.obj:1: cannot read material library 'bad.mtl' ($tmp/bad.mtl: not a regular file); its materials are not defined
paprsek: warning: badmtl.obj: the scene has no light; lighting it with a uniform white environment of radiance 1 (--env none for black, --env r,g,b or --env FILE for another)" badmtl.obj

# ---- JSON
put bad.json '{ "camera": { "fov": 40,\n  "look_from": [0,0,5] \n'
render "JSON cut short" 1 "bad.json:2: invalid JSON: unexpected end of file" bad.json
put comma.json '{ "meshes": [ { "obj": "tri.obj" }, ] }\n'
render "JSON syntax error" 1 "comma.json:1: invalid JSON near '] }'" comma.json
put blank.json '  \n'
render "empty JSON file" 1 "blank.json:1: empty document (expected a JSON object)" blank.json
put after.json '{ "meshes": [ { "obj": "tri.obj" } ] }\n{}\n'
render "text after the JSON document" 1 "after.json:2: unexpected text after the JSON document" after.json
put array.json '[ { "obj": "tri.obj" } ]\n'
render "JSON top level not an object" 1 "array.json:1: the top level must be a JSON object" array.json
put types.json '{ "meshes": [ { "obj": "tri.obj" } ],\n  "camera": { "look_from": "here", "look_at": [0,0,0], "fov": 40 } }\n'
render "wrong JSON type" 1 "types.json:2: camera.look_from: must be an array of 3 numbers" types.json
put dup.json '{ "meshes": [ { "obj": "tri.obj", "obj": "tri.obj" } ] }\n'
render "duplicate key" 1 "dup.json:1: meshes[0].obj: duplicate key" dup.json
put radius.json '{ "spheres": [ { "center": [0,0,0],\n "radius": -1 } ] }\n'
render "non-positive radius" 1 "radius.json:2: spheres[0].radius: must be a positive number" radius.json
put fov.json '{ "meshes": [ { "obj": "tri.obj" } ],\n  "camera": { "look_from": [0,0,5], "look_at": [0,0,0], "fov": 0 } }\n'
render "zero fov" 1 "fov.json:2: camera.fov: must be between 0 and 180 degrees (exclusive)" fov.json
put self.json '{ "meshes": [ { "obj": "tri.obj" } ],\n  "camera": { "look_from": [1,1,1], "look_at": [1,1,1], "fov": 40 } }\n'
render "camera looking at itself" 1 "self.json:2: camera.look_at: must differ from look_from" self.json
put nomesh.json '{ "meshes": [ { "obj": "missing.obj" } ] }\n'
render "missing mesh file" 1 "nomesh.json:1: meshes[0].obj: $tmp/missing.obj: cannot open: No such file or directory" nomesh.json
put nomat.json '{ "spheres": [ { "center": [0,0,0], "radius": 1, "material": "gold" } ] }\n'
render "unknown material" 1 "nomat.json:1: spheres[0].material: unknown material \"gold\"" nomat.json
put singular.json '{ "meshes": [ { "obj": "tri.obj", "transform": { "scale": [1, 0, 1] } } ] }\n'
render "singular transform" 1 "singular.json:1: meshes[0].transform.scale: must not be zero" singular.json
put meshbad.json '{ "meshes": [ { "obj": "range.obj" } ] }\n'
render "error inside a mesh of a JSON scene" 1 "$tmp/range.obj:4: face index 9 out of range (1..3)" meshbad.json
put film.json '{ "spheres": [ { "center": [0,0,0], "radius": 1 } ],\n  "film": { "width": 16385, "height": 8 } }\n'
render "JSON width above the limit" 1 "film.json:2: film.width: must be an integer in 1..16384" film.json
put pixels.json '{ "spheres": [ { "center": [0,0,0], "radius": 1 } ],\n  "film": { "width": 16384, "height": 16384 } }\n'
render "JSON pixel count above the limit" 1 "pixels.json:2: film: 16384x16384 is more than 67108864 pixels" pixels.json
put spp.json '{ "spheres": [ { "center": [0,0,0], "radius": 1 } ],\n  "render": { "spp": 65537 } }\n'
render "JSON samples above the limit" 1 "spp.json:2: render.spp: must be an integer in 1..65536" spp.json
put depth.json '{ "spheres": [ { "center": [0,0,0], "radius": 1 } ],\n  "render": { "max_depth": 1025 } }\n'
render "JSON depth above the limit" 1 "depth.json:2: render.max_depth: must be an integer in -1..1024" depth.json

# ---- the command line
expect "zero fov on the command line" 2 "--fov: '0' must be a number of degrees between 0 and 180" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --fov 0
expect "camera at its target" 1 "camera: look_from and look_at are the same point" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --look-from 1,1,1 --look-at 1,1,1
expect "bad vector" 2 "--look-from: '1,2' is not x,y,z (three finite numbers)" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --look-from 1,2
expect "absurd width" 2 "--width: '100000000' is not a whole number in 1..16384" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --width 100000000
expect "negative height" 2 "--height: '-5' is not a whole number in 1..16384" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --height -5
expect "non-numeric spp" 2 "--spp: 'lots' is not a whole number in 1..65536" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --spp lots
expect "absurd spp" 2 "--spp: '99999999' is not a whole number in 1..65536" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --spp 99999999
expect "absurd depth" 2 "--max-depth: '1025' is not a whole number in -1..1024" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --max-depth 1025
expect "absurd light samples" 2 "--light-samples: '4097' is not a whole number in 0..4096" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --light-samples 4097
expect "absurd thread count" 2 "--threads: '1025' is not a whole number in 0..1024" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --threads 1025
expect "absurd pixel count" 1 "image of 16384x16384 pixels is larger than 67108864 pixels" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --width 16384 --height 16384
expect "unknown accelerator" 2 "--accel: unknown accelerator 'kd' (none, midpoint, bvh, embree)" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --accel kd
expect "bad fresnel" 2 "--fresnel: expected on or off, not 'yes'" render "$tmp/tri.obj" -o "$tmp/out.png" --fresnel yes
expect "bad energy compensation" 2 "--energy-compensation: expected on or off, not '1'" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --energy-compensation 1
expect "unknown option" 2 "render: unknown option '--bogus' (see paprsek render --help)" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --bogus
expect "option without its value" 2 "--width needs a value" render "$tmp/tri.obj" -o "$tmp/out.png" --width
expect "two scenes" 2 "render: more than one scene given ('$tmp/tri.obj' and '$tmp/flat.obj')" \
  render "$tmp/tri.obj" "$tmp/flat.obj" -o "$tmp/out.png"
expect "no output" 2 "render: no output file (-o OUT.png)" render "$tmp/tri.obj"
expect "unknown image format" 2 "$tmp/out.bmp: unknown image format (use .png, .pfm or .exr)" \
  render "$tmp/tri.obj" -o "$tmp/out.bmp" --width 8 --height 8
expect "unknown command" 2 "unknown command 'draw' (see paprsek --help)" draw
cp "$tmp/tri.obj" "$tmp/tri.orig"
ln -s tri.obj "$tmp/link.png"
expect "output over the scene" 2 "$tmp/tri.obj: unknown image format (use .png, .pfm or .exr)" \
  render "$tmp/tri.obj" -o "$tmp/tri.obj"
expect "output over the scene through a link" 2 "render: refusing to write the image over the scene file '$tmp/tri.obj'" \
  render "$tmp/tri.obj" -o "$tmp/link.png"
expect "statistics over the scene" 2 "render: refusing to write the statistics over the scene file '$tmp/tri.obj'" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --stats-json "$tmp/tri.obj"
expect "statistics over the image" 2 "render: --stats-json and -o name the same file '$tmp/out.png'" \
  render "$tmp/tri.obj" -o "$tmp/out.png" --stats-json "$tmp/out.png"
cmp -s "$tmp/tri.obj" "$tmp/tri.orig" || { echo "FAIL: the scene file was changed"; fail=1; }
rm -f "$tmp/link.png"
# checked before the scene is read: no render, so no warning about its light
expect "folder that does not exist" 1 "$tmp/no/such/dir/out.png: folder '$tmp/no/such/dir' does not exist" \
  render "$tmp/tri.obj" -o "$tmp/no/such/dir/out.png" --width 8 --height 8
ls "$tmp"/no 2>/dev/null && { echo "FAIL: a folder was created"; fail=1; }

# an existing image is replaced only by a complete one
"$bin" render "$tmp/tri.obj" -o "$tmp/keep.png" --width 8 --height 8 --quiet || { echo "FAIL: good render"; fail=1; }
cp "$tmp/keep.png" "$tmp/keep.orig"
"$bin" render "$tmp/nan.obj" -o "$tmp/keep.png" --width 8 --height 8 2>/dev/null
cmp -s "$tmp/keep.png" "$tmp/keep.orig" || { echo "FAIL: a failed render touched an existing image"; fail=1; }
left=$(ls "$tmp" | grep -F '.tmp.')
[ -z "$left" ] || { echo "FAIL: temporary files left: $left"; fail=1; }

exit $fail
