#!/usr/bin/env bash
# pbrt-v4 scenes on the command line: a scene split over included files
# renders at its Film's size; bad scenes give exactly one line naming the
# file and line, exit status 1 and no image; Bitterli's Cornell box in
# pbrt-v4 form renders when ../shared is there.
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

if [ -r "$shared/scenes/pbrt-v4/cornell-box/scene-v4.pbrt" ]; then
  expect "cornell box" 0 "" render "$shared/scenes/pbrt-v4/cornell-box/scene-v4.pbrt" -o "$tmp/out.png" \
    --spp 1 --width 32 --height 32 -q
else
  echo "skip cornell box: $shared/scenes/pbrt-v4 is not there"
fi
exit $fail
