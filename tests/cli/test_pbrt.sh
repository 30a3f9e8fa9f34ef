#!/usr/bin/env bash
# pbrt-v4 scenes on the command line: a scene split over included files
# renders at its Film's size; bad scenes give exactly one line naming the
# file and line, exit status 1 and no image; Bitterli's Cornell box in
# pbrt-v4 form renders when ../shared is there; spectrum files and gzip files
# are read.
# usage: test_pbrt.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
shared=$2
data=$3/pbrt
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

expect "includes render" 0 "" render "$data/include_main.pbrt" -o "$tmp/out.png" --spp 1 -q
# the Film's 64 x 48 (PNG header: width and height at bytes 16..23)
size=$(od -An -tu1 -j16 -N8 "$tmp/out.png" 2>/dev/null | tr -s ' ')
if [ "$size" != " 0 0 0 64 0 0 0 48" ]; then echo "FAIL film size: PNG header says$size"; fail=1; else echo "ok   film size"; fi
expect "include cycle" 1 "$data/cycle_b.pbrt:2: Include \"cycle_a.pbrt\": the file includes itself (a cycle)" \
  render "$data/cycle_a.pbrt" -o "$tmp/out.png"
expect "missing mesh" 1 "missing_ply.pbrt:3: plymesh: $data/no_such_mesh.ply: cannot open: No such file or directory" \
  render "$data/missing_ply.pbrt" -o "$tmp/out.png"
printf 'WorldBegin\n\nShape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 7]\n' > "$tmp/bad.pbrt"
expect "index out of range" 1 "bad.pbrt:3: trianglemesh: index 7 (number 2) is out of range (3 vertices)" \
  render "$tmp/bad.pbrt" -o "$tmp/out.png"

# spectrum files (pbrt-v4's .spd): read relative to the scene, the same
# image as the same samples given inline (and not the image of the 1 that
# stands in for a file that cannot be read); bad files are one warning
mkdir -p "$tmp/spd/spds"
printf '# gold (test values)\n400 1.66\n500 0.97 # a comment\n600 0.25\n700 0.16\n' > "$tmp/spd/spds/eta.spd"
printf '400 1.95  500 1.87\r\n600 2.98  700 3.96\n' > "$tmp/spd/spds/k.spd"
printf '400 1 500\n' > "$tmp/spd/spds/odd.spd"
spd_scene() {
  printf 'LookAt 0 0 5  0 0 0  0 1 0\nCamera "perspective" "float fov" 30\n'
  printf 'Film "rgb" "integer xresolution" 24 "integer yresolution" 24 "string filename" "x.exr"\nWorldBegin\n'
  printf 'LightSource "infinite" "rgb L" [1 1 1]\nMaterial "conductor" %s "float roughness" 0.2\n' "$1"
  printf 'Shape "sphere" "float radius" 1\n'
}
spd_scene '"spectrum eta" "spds/eta.spd" "spectrum k" "spds/k.spd"' > "$tmp/spd/file.pbrt"
spd_scene '"spectrum eta" [400 1.66 500 0.97 600 0.25 700 0.16] "spectrum k" [400 1.95 500 1.87 600 2.98 700 3.96]' \
  > "$tmp/spd/inline.pbrt"
spd_scene '"spectrum eta" "spds/none.spd" "spectrum k" "spds/k.spd"' > "$tmp/spd/missing.pbrt"
spd_scene '"spectrum eta" "spds/odd.spd" "spectrum k" "spds/k.spd"' > "$tmp/spd/odd.pbrt"
for v in file inline missing odd; do
  "$bin" render "$tmp/spd/$v.pbrt" -o "$tmp/spd/$v.pfm" --spp 2 2>"$tmp/spd/$v.err" >/dev/null ||
    { echo "FAIL spectrum file: $v did not render: $(cat "$tmp/spd/$v.err")"; fail=1; }
done
if [ -s "$tmp/spd/file.err" ] || ! cmp -s "$tmp/spd/file.pfm" "$tmp/spd/inline.pfm"; then
  echo "FAIL spectrum file: not the image of the same samples inline ($(cat "$tmp/spd/file.err"))"; fail=1
elif cmp -s "$tmp/spd/file.pfm" "$tmp/spd/missing.pfm"; then
  echo "FAIL spectrum file: the file's values made no difference"; fail=1
else
  echo "ok   spectrum file"
fi
want="paprsek: warning: missing.pbrt:6: spectrum \"spds/none.spd\" is neither a named spectrum nor a file that can be read ($tmp/spd/spds/none.spd: cannot open: No such file or directory); using 1"
[ "$(cat "$tmp/spd/missing.err")" = "$want" ] && echo "ok   spectrum file missing" ||
  { echo "FAIL spectrum file missing: $(cat "$tmp/spd/missing.err")"; fail=1; }
want="paprsek: warning: odd.pbrt:6: spectrum file \"spds/odd.spd\" holds an odd count of numbers (wavelength and value pairs were expected); using 1"
[ "$(cat "$tmp/spd/odd.err")" = "$want" ] && echo "ok   spectrum file odd" ||
  { echo "FAIL spectrum file odd: $(cat "$tmp/spd/odd.err")"; fail=1; }

# gzip files by name (a .ply.gz mesh, an included .pbrt.gz, two members
# joined by cat): the bytes of the same files uncompressed
mkdir -p "$tmp/gz"
cp "$data/../fuzz_seed_mesh.ply" "$tmp/gz/mesh.ply"
gzip -c "$tmp/gz/mesh.ply" > "$tmp/gz/mesh.ply.gz"
printf 'LightSource "infinite" "rgb L" [ 1 1 1 ]\nTranslate 0 0 3\n' > "$tmp/gz/light.pbrt"
{ head -c 20 "$tmp/gz/light.pbrt" | gzip -c; tail -c +21 "$tmp/gz/light.pbrt" | gzip -c; } > "$tmp/gz/light.pbrt.gz"
printf 'Camera "perspective"\nFilm "rgb" "integer xresolution" 24 "integer yresolution" 24\nWorldBegin\nInclude "light.pbrt%s"\nShape "plymesh" "string filename" "mesh.ply%s"\n' "" "" > "$tmp/gz/plain.pbrt"
printf 'Camera "perspective"\nFilm "rgb" "integer xresolution" 24 "integer yresolution" 24\nWorldBegin\nInclude "light.pbrt%s"\nShape "plymesh" "string filename" "mesh.ply%s"\n' ".gz" ".gz" > "$tmp/gz/gz.pbrt"
"$bin" render "$tmp/gz/plain.pbrt" -o "$tmp/gz/plain.pfm" --spp 2 -q 2>"$tmp/gz/plain.err"
"$bin" render "$tmp/gz/gz.pbrt" -o "$tmp/gz/gz.pfm" --spp 2 -q 2>"$tmp/gz/gz.err"
head -n 4 "$tmp/gz/plain.pbrt" > "$tmp/gz/nomesh.pbrt"
"$bin" render "$tmp/gz/nomesh.pbrt" -o "$tmp/gz/nomesh.pfm" --spp 2 -q 2>/dev/null
if [ -s "$tmp/gz/gz.err" ] || ! cmp -s "$tmp/gz/plain.pfm" "$tmp/gz/gz.pfm"; then
  echo "FAIL gzip files: not the image of the files uncompressed ($(cat "$tmp/gz/gz.err"))"; fail=1
elif cmp -s "$tmp/gz/gz.pfm" "$tmp/gz/nomesh.pfm"; then
  echo "FAIL gzip files: the mesh is not in the image"; fail=1
else
  echo "ok   gzip files"
fi
head -c 60 "$tmp/gz/mesh.ply.gz" > "$tmp/gz/cut.ply.gz"
printf 'WorldBegin\nShape "plymesh" "string filename" "cut.ply.gz"\n' > "$tmp/gz/cut.pbrt"
expect "gzip cut short" 1 "cut.pbrt:2: plymesh: $tmp/gz/cut.ply.gz: the gzip data ends early" \
  render "$tmp/gz/cut.pbrt" -o "$tmp/out.png"
cp "$tmp/gz/mesh.ply" "$tmp/gz/plain.ply.gz"
printf 'WorldBegin\nShape "plymesh" "string filename" "plain.ply.gz"\n' > "$tmp/gz/notgz.pbrt"
expect "not gzip" 1 "notgz.pbrt:2: plymesh: $tmp/gz/plain.ply.gz: not a gzip file" \
  render "$tmp/gz/notgz.pbrt" -o "$tmp/out.png"

if [ -r "$shared/scenes/pbrt-v4/cornell-box/scene-v4.pbrt" ]; then
  expect "cornell box" 0 "" render "$shared/scenes/pbrt-v4/cornell-box/scene-v4.pbrt" -o "$tmp/out.png" \
    --spp 1 --width 32 --height 32 -q
else
  echo "skip cornell box: $shared/scenes/pbrt-v4 is not there"
fi
exit $fail
