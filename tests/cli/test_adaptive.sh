#!/usr/bin/env bash
# paprsek render --noise (adaptive sampling): the statistics report the
# target, the estimated noise and how many samples went where (also in
# --stats-json); --spp caps the samples of a pixel; --time still stops the
# render; the same image at 1 and 2 threads; and the usage errors (exit 2,
# nothing written): a target that is not a positive number, --min-spp
# without --noise, a bad --min-spp.
# usage: test_adaptive.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL $*"; fail=1; }
ok() { echo "ok   $*"; }
run() {
  timeout 120 "$bin" "$@" >"$tmp/stdout" 2>"$tmp/stderr" </dev/null
  rc=$?
  out=$(cat "$tmp/stdout")
  err=$(cat "$tmp/stderr")
}
# field NAME: a number of the "adaptive" object of $tmp/s.json
field() { /usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['adaptive'][sys.argv[2]])" "$tmp/s.json" "$1"; }

run render -o "$tmp/a.pfm" --width 64 --height 48 --noise 0.1 --no-denoise --stats --stats-json "$tmp/s.json" -q
if [ $rc -eq 0 ] && [[ "$out" == *"adaptive: estimated noise"*"(target 0.1000)"*"adaptive: samples per pixel"* ]]; then
  ok "--noise: the statistics say how it went"
else
  bad "--noise: exit $rc: $err $out"
fi
if [ -s "$tmp/s.json" ] && [ "$(field tiles)" = 12 ] && [ "$(field min_spp)" -ge 16 ] &&
  [ "$(field max_spp)" -le 1024 ] && /usr/bin/python3 -c "import sys; sys.exit(not (0 < float(sys.argv[1]) <= 0.1))" "$(field noise)"; then
  ok "--stats-json: the adaptive object (12 tiles, $(field min_spp)..$(field max_spp) spp, noise $(field noise))"
else
  bad "--stats-json: $(cat "$tmp/s.json" 2>/dev/null)"
fi
cp "$tmp/a.pfm" "$tmp/a2.pfm"
run render -o "$tmp/b.pfm" --width 64 --height 48 --noise 0.1 --no-denoise --threads 1 -q
if [ $rc -eq 0 ] && cmp -s "$tmp/a2.pfm" "$tmp/b.pfm"; then ok "the same image at 1 thread"; else bad "threads: exit $rc, or the images differ"; fi

# --spp caps it
run render -o "$tmp/c.pfm" --width 64 --height 48 --noise 0.001 --spp 24 --min-spp 8 --no-denoise --stats-json "$tmp/s.json" -q
if [ $rc -eq 0 ] && [ "$(field max_spp)" -le 24 ] && [ "$(field min_spp)" -ge 8 ]; then
  ok "--spp 24 caps a pixel's samples ($(field min_spp)..$(field max_spp))"
else
  bad "--spp with --noise: exit $rc: $err"
fi
# --time stops it
start=$(date +%s)
run render -o "$tmp/d.pfm" --width 128 --height 128 --noise 0.0001 --spp 65536 --time 1 --no-denoise -q
if [ $rc -eq 0 ] && [ $(( $(date +%s) - start )) -lt 20 ] && [ -s "$tmp/d.pfm" ]; then ok "--time stops it"; else bad "--time: exit $rc: $err"; fi

# usage errors
for args in "--noise 0" "--noise -1" "--noise abc" "--min-spp 8" "--noise 0.1 --min-spp 0"; do
  # shellcheck disable=SC2086
  run render -o "$tmp/e.png" --width 8 --height 8 $args
  if [ $rc -eq 2 ] && [ -n "$err" ] && [ ! -e "$tmp/e.png" ]; then ok "$args: refused"; else bad "$args: exit $rc: $err"; fi
done
exit $fail
