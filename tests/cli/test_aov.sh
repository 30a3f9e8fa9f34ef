#!/usr/bin/env bash
# --aov: the outputs beside OUT as NAME.AOV.EXT for PNG and PFM, layers of an
# .exr OUT; an unknown
# name is a usage error (exit 2) and nothing is written.
# usage: test_aov.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
ok() { echo "ok   $1"; }
bad() { echo "FAIL $1"; fail=1; }

"$bin" render -o "$tmp/c.png" --width 24 --height 16 --aov albedo,normal,depth,heatmap 2>"$tmp/err"
rc=$?
[ $rc -eq 0 ] && ok "render with four AOVs" || bad "render with four AOVs: exit $rc: $(cat "$tmp/err")"
for a in albedo normal depth heatmap; do
  [ "$(head -c 8 "$tmp/c.$a.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] && ok "c.$a.png is a PNG" ||
    bad "c.$a.png missing or not a PNG"
done
grep -q "^heatmap: blue [0-9.e+]* to red [0-9.e+]* nodes visited" "$tmp/err" && ok "the heatmap's range is printed" ||
  bad "no heatmap range: $(cat "$tmp/err")"
"$bin" render -o "$tmp/d.pfm" --width 24 --height 16 --aov depth --quiet
[ "$(head -c 2 "$tmp/d.depth.pfm")" = PF ] && ok "d.depth.pfm is a colour PFM" || bad "d.depth.pfm"
[ ! -e "$tmp/d.albedo.pfm" ] && ok "only the AOVs asked for" || bad "an AOV not asked for was written"
"$bin" render -o "$tmp/x.exr" --width 24 --height 16 --aov depth,albedo --quiet
[ -s "$tmp/x.exr" ] && [ ! -e "$tmp/x.depth.exr" ] && grep -aq 'depth\.R' "$tmp/x.exr" && grep -aq 'albedo\.B' "$tmp/x.exr" &&
  ok "an .exr holds the AOVs as layers" || bad "AOV layers in .exr"
"$bin" render -o "$tmp/e.png" --aov depth,colour 2>"$tmp/err"
rc=$?
[ $rc -eq 2 ] && grep -q "unknown output 'colour'" "$tmp/err" && [ ! -e "$tmp/e.png" ] &&
  ok "unknown AOV refused (exit 2)" || bad "unknown AOV: exit $rc: $(cat "$tmp/err")"
exit $fail
