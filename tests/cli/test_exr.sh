#!/usr/bin/env bash
# OpenEXR output and --exposure from the program: -o OUT.exr (any case)
# writes an OpenEXR file (magic 76 2f 31 01) whose data window is the
# render's size; --exposure out of range or not a number is a usage error
# (exit 2, one message, at once, nothing written); --exposure changes PNG
# output only (an .exr is the same file with or without it, with a warning);
# SIGINT during a render to OUT.exr leaves OUT.partial.exr, an OpenEXR file.
# usage: test_exr.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
export LC_ALL=C
bin=$1
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL $*"; fail=1; }
ok() { echo "ok   $*"; }

# exr_size FILE: "WIDTH HEIGHT" from the dataWindow attribute of an OpenEXR
# file (name, "box2i", 4-byte size 16, then xmin ymin xmax ymax, int32 LE),
# or nothing when FILE does not start with the OpenEXR magic number.
exr_size() {
  [ "$(head -c 4 "$1" | od -An -tx1 | tr -d ' \n')" = 762f3101 ] || return
  local off
  off=$(grep -obUa 'dataWindow' "$1" | head -n 1 | cut -d: -f1)
  [ -n "$off" ] || return
  od -An -td4 -j $((off + 21)) -N16 "$1" | awk '{ print $3 - $1 + 1, $4 - $2 + 1 }'
}

# 1. a tiny render to .exr, and to .EXR
for name in out.exr OUT.EXR; do
  "$bin" render -o "$tmp/$name" --width 24 --height 16 --light-samples 2 -q >"$tmp/stdout" 2>"$tmp/stderr"
  rc=$?
  if [ $rc -ne 0 ]; then bad "render -o $name: exit $rc: $(cat "$tmp/stderr")"
  elif [ -s "$tmp/stderr" ]; then bad "render -o $name printed: $(cat "$tmp/stderr")"
  elif [ "$(exr_size "$tmp/$name")" != "24 16" ]; then
    bad "$name: not a 24x16 OpenEXR file: $(head -c 4 "$tmp/$name" | od -An -tx1) size '$(exr_size "$tmp/$name")'"
  else ok "render -o $name: OpenEXR, 24x16, $(wc -c <"$tmp/$name") bytes"; fi
done
grep -qa 'compression' "$tmp/out.exr" && grep -qa 'channels' "$tmp/out.exr" \
  && ok "out.exr has the channels and compression attributes" || bad "out.exr lacks required attributes"

# 2. --exposure out of range or not a number: exit 2 before any work (the
# scene is missing and the render would take hours), nothing written
slow=(--width 2048 --height 2048 --spp 65536)
for ev in 21 -20.5 nan inf -inf abc 1x "" 1e3; do
  t0=$SECONDS
  timeout 60 "$bin" render "$tmp/missing.obj" -o "$tmp/e.png" --exposure "$ev" "${slow[@]}" \
    >"$tmp/stdout" 2>"$tmp/stderr"
  rc=$?
  want="paprsek: --exposure: '$ev' must be a number of stops in -20..20"
  if [ $rc -ne 2 ]; then bad "--exposure '$ev': exit $rc, wanted 2: $(cat "$tmp/stderr")"
  elif [ "$(cat "$tmp/stderr")" != "$want" ]; then bad "--exposure '$ev': stderr '$(cat "$tmp/stderr")'"
  elif [ $((SECONDS - t0)) -gt 5 ]; then bad "--exposure '$ev': took $((SECONDS - t0)) s"
  elif [ -e "$tmp/e.png" ]; then bad "--exposure '$ev': wrote $tmp/e.png"
  else ok "--exposure '$ev' refused: $want"; fi
done
"$bin" render -o "$tmp/e.png" --exposure >/dev/null 2>"$tmp/stderr"
rc=$?
[ $rc -eq 2 ] && ok "--exposure without a value: exit 2" || bad "--exposure without a value: exit $rc"

# 3. --exposure in range: PNG changes, .exr does not (but is warned about)
small=(--width 16 --height 16 --light-samples 2 -q)
"$bin" render -o "$tmp/p0.png" "${small[@]}" && "$bin" render -o "$tmp/pz.png" --exposure 0 "${small[@]}" &&
  "$bin" render -o "$tmp/pm.png" --exposure=-20 "${small[@]}" && "$bin" render -o "$tmp/pp.png" --exposure 2.5 "${small[@]}" ||
  bad "renders with --exposure failed"
cmp -s "$tmp/p0.png" "$tmp/pz.png" && ok "--exposure 0 is the default" || bad "--exposure 0 changes the PNG"
! cmp -s "$tmp/p0.png" "$tmp/pm.png" && ! cmp -s "$tmp/p0.png" "$tmp/pp.png" && ok "--exposure -20 and 2.5 change the PNG" \
  || bad "--exposure does not change the PNG"
"$bin" render -o "$tmp/x1.exr" --width 16 --height 16 --light-samples 2 --exposure 1 >/dev/null 2>"$tmp/stderr"
rc=$?
"$bin" render -o "$tmp/x0.exr" "${small[@]}"
if [ $rc -ne 0 ]; then bad "--exposure 1 -o .exr: exit $rc"
elif ! cmp -s "$tmp/x0.exr" "$tmp/x1.exr"; then bad "--exposure changes the .exr"
elif ! grep -q 'exposure applies to PNG only' "$tmp/stderr"; then bad "no warning for --exposure with .exr: $(cat "$tmp/stderr")"
else ok "--exposure leaves .exr unscaled, with a warning"; fi

# 4. SIGINT: the finished tiles go to OUT.partial.exr
"$bin" render -o "$tmp/int.exr" --width 2048 --height 2048 --spp 4096 --threads 1 -q >"$tmp/stdout" 2>"$tmp/stderr" &
pid=$!
n=0
while [ $n -lt 600 ]; do # until its SIGINT handler is installed (bit 2 of SigCgt)
  mask=$(awk '/^SigCgt:/ { print $2 }' "/proc/$pid/status" 2>/dev/null)
  [ -n "$mask" ] && (((16#$mask >> 1) & 1)) && break
  [ -r "/proc/$pid/status" ] || { sleep 1; break; }
  sleep 0.1
  n=$((n + 1))
done
sleep 0.5
kill -s INT "$pid"
n=0
while kill -0 "$pid" 2>/dev/null && [ $n -lt 300 ]; do sleep 0.1; n=$((n + 1)); done
kill -0 "$pid" 2>/dev/null && { kill -9 "$pid"; bad "still rendering 30 s after SIGINT"; }
wait "$pid"
rc=$?
if [ $rc -ne 130 ]; then bad "SIGINT: exit $rc, wanted 130: $(cat "$tmp/stderr")"
elif [ -e "$tmp/int.exr" ]; then bad "SIGINT: int.exr was written"
elif [ "$(exr_size "$tmp/int.partial.exr")" != "2048 2048" ]; then bad "SIGINT: int.partial.exr is not a 2048x2048 OpenEXR file"
else ok "SIGINT: int.partial.exr written ($(wc -c <"$tmp/int.partial.exr") bytes), exit 130"; fi
left=$(find "$tmp" -name '*.tmp.*')
[ -z "$left" ] && ok "no temporary file left" || bad "temporary files left: $left"

# 5. the formats are in --help
"$bin" render --help | grep -q '\.exr  OpenEXR' && "$bin" --help | grep -q '\.exr' &&
  "$bin" render --help | grep -q -- '--exposure EV' && ok "--help lists .exr and --exposure" || bad "--help lacks .exr or --exposure"

exit $fail
