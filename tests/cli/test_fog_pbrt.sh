#!/usr/bin/env bash
# The fog scene in pbrt-v4's format (tests/data/media/fog.pbrt) renders to
# the very image of its JSON version (fog.json): the same media, surfaces,
# camera and settings make the same samples. Skipped (77) while fog.json is
# not there.
# usage: test_fog_pbrt.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
data=$3/media
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
[ -r "$data/fog.json" ] || { echo "SKIP: $data/fog.json is not there"; exit 77; }
fail=0
for f in fog.pbrt fog.json; do
  if ! timeout 300 "$bin" render "$data/$f" -o "$tmp/$f.png" --spp 4 --width 64 --seed 7 >/dev/null 2>"$tmp/err"; then
    echo "FAIL $f does not render: $(cat "$tmp/err")"; fail=1
  elif [ -s "$tmp/err" ]; then
    echo "FAIL $f: warnings: $(cat "$tmp/err")"; fail=1
  fi
done
if [ $fail -eq 0 ] && ! cmp -s "$tmp/fog.pbrt.png" "$tmp/fog.json.png"; then
  echo "FAIL fog.pbrt and fog.json render different images"; fail=1
fi
[ $fail -eq 0 ] && echo "ok"
exit $fail
