#!/usr/bin/env bash
# What real OBJ/MTL/JSON files contain that a strict reader would reject:
# each file RENDERS (exit 0, a PNG of the asked size written) and prints
# exactly the warnings listed, or none. Fixtures: tests/data/odd_*.
# usage: test_oddities.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
data=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

# png_size FILE: prints "WIDTH HEIGHT" of a PNG, or nothing when FILE is not one.
png_size() {
  [ "$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || return
  od -An -tu1 -j16 -N8 "$1" | awk '{ print $1*16777216 + $2*65536 + $3*256 + $4, $5*16777216 + $6*65536 + $7*256 + $8 }'
}

# renders FILE [WARNING...]: FILE (in the data folder) renders at 20x12 with
# exactly these lines on stderr ("paprsek: warning: " is added to each;
# @nolight stands for the warning about a scene without any light).
renders() {
  local file=$1
  shift
  local want=""
  for w in "$@"; do
    # @nolight: the warning every scene without any light gets
    [ "$w" = @nolight ] && w="${file}: the scene has no light; lighting it with a uniform white environment of radiance 1 (--env none for black, --env r,g,b or --env FILE for another)"
    want+="paprsek: warning: $w"$'\n'
  done
  rm -f "$tmp/out.png"
  "$bin" render "$data/$file" -o "$tmp/out.png" --width 20 --height 12 --light-samples 2 >"$tmp/stdout" 2>"$tmp/stderr"
  local rc=$?
  local got
  got=$(cat "$tmp/stderr")
  if [ $rc -ne 0 ]; then
    echo "FAIL $file: exit $rc: $got"; fail=1
  elif [ "$(png_size "$tmp/out.png")" != "20 12" ]; then
    echo "FAIL $file: no 20x12 PNG written"; fail=1
  elif [ "$got" != "${want%$'\n'}" ]; then
    echo "FAIL $file: stderr differs"
    diff <(printf '%s' "$want") <(printf '%s\n' "$got") | sed 's/^/     /'
    fail=1
  else
    echo "ok   $file ($# warning(s))"
  fi
}

renders odd_crlf.obj
renders odd_tabs.obj @nolight
renders odd_no_newline.obj @nolight
renders odd_continuation.obj @nolight
renders odd_bom.obj @nolight
renders odd_bom.json @nolight
renders odd_colours.obj @nolight
renders odd_space.obj
renders odd_w.obj @nolight
renders odd_ngon.obj @nolight
renders odd_unknown.obj \
  "odd_unknown.obj:6: unknown statement 'vp' ignored (further ones not reported)" \
  "odd_unknown.obj:7: unknown statement 'l' ignored (further ones not reported)" \
  "odd_unknown.obj:9: unknown statement 'cstype' ignored (further ones not reported)" \
  "odd_unknown.obj:10: unknown statement 'p' ignored (further ones not reported)" \
  @nolight
renders odd_maps.obj \
  "odd_maps.mtl:5: texture 'paint.png' not used ($data/paint.png: cannot open: No such file or directory); Kd is used alone" \
  "odd_maps.mtl:6: texture 'paint2.png' not used ($data/paint2.png: cannot open: No such file or directory); Kd is used alone" \
  "odd_maps.mtl:7: texture 'paint_bump.png' not used ($data/paint_bump.png: cannot open: No such file or directory); the surface is not bumped" \
  "odd_maps.mtl:8: 'Tf spectral' is not supported, statement ignored (further ones not reported)" \
  @nolight
renders odd_missing_mtl.obj \
  "odd_missing_mtl.obj:2: cannot read material library 'odd_nonexistent.mtl' ($data/odd_nonexistent.mtl: cannot open: No such file or directory); its materials are not defined" \
  "odd_missing_mtl.obj:6: material 'red' is not defined; its faces use the default material" \
  @nolight
renders odd_undefined.obj \
  "odd_undefined.obj:9: material 'nosuch' is not defined; its faces use the default material"
renders odd_degenerate.obj \
  "odd_degenerate.obj: 2 degenerate triangles (zero area) dropped" \
  @nolight

# --quiet silences every warning, and the image is still written
rm -f "$tmp/out.png"
"$bin" render "$data/odd_unknown.obj" -o "$tmp/out.png" --width 20 --height 12 --quiet 2>"$tmp/stderr" &&
  [ ! -s "$tmp/stderr" ] && [ "$(png_size "$tmp/out.png")" = "20 12" ] &&
  echo "ok   --quiet" || { echo "FAIL --quiet: $(cat "$tmp/stderr")"; fail=1; }
exit $fail
