#!/usr/bin/env bash
# The denoiser from the command line: the default render (no --spp, --time or
# scene sample count) is denoised; an explicit --spp stays raw unless
# --denoise; `paprsek render --denoise` equals `paprsek denoise` of the same
# render's EXR (colour + albedo + normal layers) bit for bit; missing,
# foreign or damaged weights are one message, exit 1, no image (or, for the
# default render, a warning and the raw image); bad pixels are warned about.
# usage: test_denoise.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1 shared=${2:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
ok() { echo "ok   $1"; }
bad() { echo "FAIL $1"; fail=1; }
weights=$(dirname "$bin")/weights
if [ ! -f "$weights/rt_hdr_alb_nrm.tza" ]; then echo "SKIP: no weights in $weights (make weights)"; exit 77; fi
if ! "$bin" render -o "$tmp/probe.pfm" --width 4 --height 4 --spp 1 --denoise --quiet 2>"$tmp/err"; then
  grep -q "oneDNN\|no denoiser" "$tmp/err" && { echo "SKIP: $(cat "$tmp/err")"; exit 77; }
fi
sz=(--width 48 --height 40)

# 1. defaults: the default render is denoised; --spp N is raw
"$bin" render -o "$tmp/def.pfm" "${sz[@]}" --stats >"$tmp/stats" 2>"$tmp/err"
rc=$?
[ $rc -eq 0 ] && grep -q "16 spp" "$tmp/stats" && grep -q "^denoise .*GFLOP/s" "$tmp/stats" &&
  ok "the default render takes 16 spp and is denoised" || bad "default render: exit $rc: $(cat "$tmp/err" "$tmp/stats")"
"$bin" render -o "$tmp/raw16.pfm" "${sz[@]}" --spp 16 --quiet
"$bin" render -o "$tmp/nod.pfm" "${sz[@]}" --no-denoise --quiet
cmp -s "$tmp/raw16.pfm" "$tmp/nod.pfm" && ok "--no-denoise gives the raw 16-spp image" || bad "--no-denoise differs from --spp 16"
! cmp -s "$tmp/raw16.pfm" "$tmp/def.pfm" && ok "the denoised image differs from the raw one" || bad "default image is raw"
"$bin" render -o "$tmp/raw4.pfm" "${sz[@]}" --spp 4 --stats --stats-json "$tmp/raw.json" >"$tmp/stats" 2>/dev/null
! grep -q "^denoise" "$tmp/stats" && ok "an explicit --spp stays raw" || bad "--spp 4 was denoised"
/usr/bin/python3 -c 'import json, sys; sys.exit(json.load(open(sys.argv[1]))["denoise"] is not None)' "$tmp/raw.json" &&
  ok "--stats-json: denoise null when raw" || bad "--stats-json of a raw render: $(cat "$tmp/raw.json")"
"$bin" render -o "$tmp/dn.pfm" "${sz[@]}" --spp 2 --denoise --denoise-quality fast --stats-json "$tmp/dn.json" 2>/dev/null &&
  /usr/bin/python3 -c 'import json, sys; d = json.load(open(sys.argv[1]))["denoise"]; sys.exit(not (d["network"] == "fast" and d["seconds"] > 0 and d["bytes"] > 0 and d["gflop_per_s"] > 0))' "$tmp/dn.json" &&
  ok "--stats-json: the denoiser's network, time, memory and GFLOP/s" || bad "--stats-json of a denoised render: $(cat "$tmp/dn.json")"

# 2. render --denoise = denoise of the same render's EXR
"$bin" render -o "$tmp/r.exr" "${sz[@]}" --spp 4 --aov albedo,normal --quiet
"$bin" denoise "$tmp/r.exr" -o "$tmp/d1.pfm" --quiet
"$bin" render -o "$tmp/d2.pfm" "${sz[@]}" --spp 4 --denoise --quiet
cmp -s "$tmp/d1.pfm" "$tmp/d2.pfm" && ok "render --denoise equals paprsek denoise of its EXR" ||
  bad "render --denoise and paprsek denoise differ"
"$bin" denoise "$tmp/r.exr" -o "$tmp/d3.pfm" --threads 1 --quiet
cmp -s "$tmp/d1.pfm" "$tmp/d3.pfm" && ok "1 thread gives the same image" || bad "--threads 1 differs"
"$bin" denoise "$tmp/r.exr" -o "$tmp/fast.pfm" --quality fast --quiet && ! cmp -s "$tmp/d1.pfm" "$tmp/fast.pfm" &&
  ok "--quality fast runs the small network" || bad "--quality fast"
"$bin" denoise "$tmp/r.exr" -o "$tmp/c.pfm" --no-aux --stats >"$tmp/stats" 2>/dev/null &&
  grep -q "colour alone" "$tmp/stats" && ok "--no-aux: the colour-only network" || bad "--no-aux: $(cat "$tmp/stats")"
"$bin" denoise "$tmp/raw4.pfm" -o "$tmp/c2.png" --quiet && [ "$(head -c 4 "$tmp/c2.png" | od -An -c | tr -d ' ')" = "211PNG" ] &&
  ok "a PFM without layers denoises to PNG" || bad "PFM to PNG"
"$bin" render -o "$tmp/one.pfm" --width 1 --height 1 --denoise --quiet && ok "a 1x1 render denoises" || bad "1x1"

# 3. bad input
"$bin" denoise "$tmp/r.exr" -o "$tmp/x.pfm" --weights "$tmp/none" 2>"$tmp/err"
rc=$?
[ $rc -eq 1 ] && grep -q "no such weights file" "$tmp/err" && grep -q "make weights" "$tmp/err" && [ ! -e "$tmp/x.pfm" ] &&
  [ "$(wc -l <"$tmp/err")" -eq 1 ] && ok "missing weights: one message, exit 1, no image" || bad "missing weights: exit $rc: $(cat "$tmp/err")"
"$bin" render -o "$tmp/y.pfm" "${sz[@]}" --spp 2 --denoise --weights "$tmp/none" 2>"$tmp/err"
rc=$?
[ $rc -eq 1 ] && [ ! -e "$tmp/y.pfm" ] && ok "render --denoise without weights fails before rendering" ||
  bad "render --denoise without weights: exit $rc: $(cat "$tmp/err")"
"$bin" render -o "$tmp/z.pfm" "${sz[@]}" --weights "$tmp/none" 2>"$tmp/err"
rc=$?
[ $rc -eq 0 ] && grep -q "warning: the image is not denoised" "$tmp/err" && cmp -s "$tmp/z.pfm" "$tmp/raw16.pfm" &&
  ok "default render without weights: a warning and the raw image" || bad "default without weights: exit $rc: $(cat "$tmp/err")"
mkdir -p "$tmp/w"
head -c 100000 "$weights/rt_hdr_alb_nrm.tza" >"$tmp/w/rt_hdr_alb_nrm.tza"
"$bin" denoise "$tmp/r.exr" -o "$tmp/x.pfm" --weights "$tmp/w" 2>"$tmp/err"
rc=$?
[ $rc -eq 1 ] && grep -q "not one of Open Image Denoise 2.3's weights files" "$tmp/err" && [ ! -e "$tmp/x.pfm" ] &&
  ok "truncated weights refused by their hash" || bad "truncated weights: exit $rc: $(cat "$tmp/err")"
cp "$weights/rt_hdr_alb_nrm.tza" "$tmp/w/rt_hdr_alb_nrm.tza"
printf '\x01' | dd of="$tmp/w/rt_hdr_alb_nrm.tza" bs=1 seek=5000 conv=notrunc 2>/dev/null
"$bin" denoise "$tmp/r.exr" -o "$tmp/x.pfm" --weights "$tmp/w" 2>"$tmp/err"
rc=$?
[ $rc -eq 1 ] && grep -q "SHA-256" "$tmp/err" && [ ! -e "$tmp/x.pfm" ] && ok "a changed byte is refused" ||
  bad "corrupt weights: exit $rc: $(cat "$tmp/err")"
"$bin" denoise "$tmp/r.exr" -o "$tmp/x.pfm" --normal "$tmp/r.exr" --no-aux 2>"$tmp/err"
[ $? -eq 2 ] && ok "--normal without an albedo is a usage error" || bad "--normal alone: $(cat "$tmp/err")"
"$bin" denoise "$tmp/nothing.exr" -o "$tmp/x.pfm" 2>"$tmp/err"
[ $? -eq 1 ] && [ ! -e "$tmp/x.pfm" ] && ok "a missing input: exit 1" || bad "missing input: $(cat "$tmp/err")"
# NaN, infinity and negative pixels: warned about, never in the result
printf 'PF\n2 2\n-1.0\n' >"$tmp/nan.pfm"
printf '\x00\x00\xc0\x7f\x00\x00\x80\x7f\x00\x00\x80\xbf\x00\x00\x00\x3f\x00\x00\x00\x3f\x00\x00\x00\x3f\x00\x00\x00\x3f\x00\x00\x00\x3f\x00\x00\x00\x3f\x00\x00\x00\x3f\x00\x00\x00\x3f\x00\x00\x00\x3f' >>"$tmp/nan.pfm"
"$bin" denoise "$tmp/nan.pfm" -o "$tmp/nan_out.pfm" 2>"$tmp/err"
rc=$?
if [ $rc -eq 0 ] && od -An -tf4 -j 12 "$tmp/nan_out.pfm" | tr -s ' ' '\n' | grep -qiE 'nan|inf|^-'; then
  bad "a bad pixel reached the result"
elif [ $rc -eq 0 ]; then
  ok "bad pixels are not propagated ($(tr '\n' ' ' <"$tmp/err"))"
else
  bad "bad pixels: exit $rc: $(cat "$tmp/err")"
fi
# 4. every output format holds the same denoised pixels, at 1 and 2 threads:
# EXR and PFM bit for bit, PNG their sRGB encoding, every value finite, as
# read by tests/cli/imgcheck.py (its own decoders, not the program's). Among
# them the 64x64 render of CornellBox-Original whose first ZIP chunk once
# compressed to exactly its raw size and was stored as garbage.
check=$(dirname "$0")/imgcheck.py
cases=("builtin|--width 48 --height 40 --spp 4" "builtin|--width 64 --height 64 --spp 8" "builtin|--width 100 --height 37 --spp 3")
[ -f "$shared/scenes/cornell/CornellBox-Original.obj" ] &&
  cases+=("$shared/scenes/cornell/CornellBox-Original.obj|--width 64 --height 64 --spp 8 --look-from 0,1,3.9 --look-at 0,1,0 --fov 39.3")
n=0
for c in "${cases[@]}"; do
  scene=${c%%|*} args=${c#*|} n=$((n + 1))
  [ "$scene" = builtin ] && scene=
  outs=()
  for t in 1 2; do
    for f in pfm exr png; do
      # shellcheck disable=SC2086
      "$bin" render $scene $args --denoise --threads $t -o "$tmp/f$n-$t.$f" --quiet && outs+=("$tmp/f$n-$t.$f")
    done
    # shellcheck disable=SC2086
    "$bin" render $scene $args --aov albedo,normal --threads $t -o "$tmp/f$n-$t-raw.exr" --quiet
    for f in exr pfm png; do
      "$bin" denoise "$tmp/f$n-$t-raw.exr" --threads $t -o "$tmp/f$n-$t-dn.$f" --quiet && outs+=("$tmp/f$n-$t-dn.$f")
    done
  done
  if [ ${#outs[@]} -ne 12 ]; then
    bad "formats, ${scene:-built-in} $args: only ${#outs[@]} of 12 images were written"
  elif msg=$(/usr/bin/python3 "$check" "$tmp/f$n-1.pfm" "${outs[@]:1}" 2>&1); then
    ok "formats, ${scene:+$(basename "$scene") }$args: render --denoise and denoise to PFM, EXR and PNG, 1 and 2 threads, the same finite pixels"
  else
    bad "formats, ${scene:-built-in} $args: $msg"
  fi
done
exit $fail
