#!/usr/bin/env bash
# Light from the surroundings, from the program: a scene without lights is
# lit by a white environment (one warning) and renders non-black; --env none
# gives black (and the warning that says so); --env V equals --env V,V,V;
# --env FILE reads a lat-long image (a missing or corrupt one is an error,
# exit 1, nothing written); a JSON "environment" with a sky and no sun
# direction is refused at its line.
# usage: test_env.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
export LC_ALL=C
bin=$1
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL $*"; fail=1; }
ok() { echo "ok   $*"; }

# a triangle facing the camera, no light, no material library
printf 'v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n' >"$tmp/tri.obj"
run() { "$bin" render "$tmp/tri.obj" --width 8 --height 8 --spp 4 "$@" >"$tmp/stdout" 2>"$tmp/stderr"; rc=$?; }

# nonzero_pfm FILE: whether any float of the PFM's pixels is non-zero
nonzero_pfm() {
  tail -c +$(($(head -c 64 "$1" | awk 'NR<=3 { n += length($0) + 1 } END { print n }') + 1)) "$1" |
    od -An -tx1 -v | tr -d ' \n' | grep -q '[1-9a-f]'
}

run -o "$tmp/default.pfm"
if [ $rc -eq 0 ] && grep -q "uniform white environment of radiance 1" "$tmp/stderr" && nonzero_pfm "$tmp/default.pfm"; then
  ok "no light: the white environment, with a warning"
else
  bad "no light: exit $rc, $(cat "$tmp/stderr")"
fi

run -o "$tmp/none.pfm" --env none
if [ $rc -eq 0 ] && grep -q "the image will be black" "$tmp/stderr" && ! nonzero_pfm "$tmp/none.pfm"; then
  ok "--env none: black, with a warning"
else
  bad "--env none: exit $rc, $(cat "$tmp/stderr")"
fi

run -o "$tmp/grey1.pfm" --env 0.5
run -o "$tmp/grey3.pfm" --env 0.5,0.5,0.5
if [ $rc -eq 0 ] && cmp -s "$tmp/grey1.pfm" "$tmp/grey3.pfm" && ! grep -q "white environment" "$tmp/stderr"; then
  ok "--env 0.5 is --env 0.5,0.5,0.5"
else
  bad "--env 0.5 and 0.5,0.5,0.5 differ or warn: $(cat "$tmp/stderr")"
fi
if ! cmp -s "$tmp/grey1.pfm" "$tmp/default.pfm"; then ok "--env 0.5 differs from the default"; else bad "--env 0.5 = default"; fi

# a 2x1 PFM map of radiance 0.5 everywhere (0.5 = 00 00 00 3f)
{ printf 'PF\n2 1\n-1.0\n'; for _ in 1 2 3 4 5 6; do printf '\x00\x00\x00\x3f'; done; } >"$tmp/half.pfm"
run -o "$tmp/map.pfm" --env "$tmp/half.pfm"
if [ $rc -eq 0 ] && nonzero_pfm "$tmp/map.pfm"; then ok "--env FILE renders"; else bad "--env FILE: exit $rc, $(cat "$tmp/stderr")"; fi

run -o "$tmp/missing.png" --env "$tmp/nowhere.hdr"
if [ $rc -eq 1 ] && grep -q "nowhere.hdr" "$tmp/stderr" && [ ! -e "$tmp/missing.png" ]; then
  ok "--env missing file: exit 1, $(head -n 1 "$tmp/stderr")"
else
  bad "--env missing file: exit $rc, $(cat "$tmp/stderr")"
fi
printf 'PF\n2 1\n-1.0\nshort' >"$tmp/cut.pfm"
run -o "$tmp/cut.png" --env "$tmp/cut.pfm"
if [ $rc -eq 1 ] && grep -q "cut.pfm" "$tmp/stderr" && [ ! -e "$tmp/cut.png" ]; then
  ok "--env truncated image: exit 1, $(head -n 1 "$tmp/stderr")"
else
  bad "--env truncated image: exit $rc, $(cat "$tmp/stderr")"
fi

# JSON: an environment map relative to the scene, and a refused sky
mkdir -p "$tmp/scene"
cp "$tmp/half.pfm" "$tmp/scene/sky.pfm"
cp "$tmp/tri.obj" "$tmp/scene/tri.obj"
printf '{ "meshes": [ { "obj": "tri.obj" } ],\n  "environment": { "map": "sky.pfm", "scale": 2 } }\n' >"$tmp/scene/map.json"
"$bin" render "$tmp/scene/map.json" -o "$tmp/json.pfm" --width 8 --height 8 --spp 4 2>"$tmp/stderr"
rc=$?
if [ $rc -eq 0 ] && nonzero_pfm "$tmp/json.pfm" && [ ! -s "$tmp/stderr" ]; then ok "JSON environment map"; else
  bad "JSON environment map: exit $rc, $(cat "$tmp/stderr")"; fi
printf '{ "meshes": [ { "obj": "tri.obj" } ],\n  "environment": { "map": "nowhere.hdr" } }\n' >"$tmp/scene/nomap.json"
"$bin" render "$tmp/scene/nomap.json" -o "$tmp/nomap.png" --width 8 --height 8 2>"$tmp/stderr"
rc=$?
if [ $rc -eq 1 ] && grep -q "^paprsek: nomap.json:2: environment.map: .*nowhere.hdr" "$tmp/stderr"; then
  ok "JSON missing map: $(cat "$tmp/stderr")"
else
  bad "JSON missing map: exit $rc, $(cat "$tmp/stderr")"
fi
printf '{ "meshes": [ { "obj": "tri.obj" } ],\n  "environment": {\n "sky": { "turbidity": 3 } } }\n' >"$tmp/scene/sky.json"
"$bin" render "$tmp/scene/sky.json" -o "$tmp/sky.png" --width 8 --height 8 2>"$tmp/stderr"
rc=$?
want="paprsek: sky.json:3: environment.sky: needs the sun's direction: an environment.sun or a \"sun_direction\""
if [ $rc -eq 1 ] && [ "$(cat "$tmp/stderr")" = "$want" ]; then ok "JSON sky without a sun: $want"; else
  bad "JSON sky without a sun: exit $rc, $(cat "$tmp/stderr")"; fi

exit $fail
