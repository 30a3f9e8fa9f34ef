#!/usr/bin/env bash
# The fog scene of tests/data/media in Mitsuba 3's format (fog.xml) and in
# pbrt-v4's (fog.pbrt) renders to the very image of its JSON version
# (fog.json), float for float: the same media (fog, milk in a glass sphere,
# a smoke grid inside an index-matched box), surfaces, camera and settings
# (the pixel filter too: each file names its format's lanczos of radius 3)
# make the same samples.
# usage: test_fog_formats.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
data=$3/media
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
for f in fog.json fog.xml fog.pbrt; do
  if ! timeout 300 "$bin" render "$data/$f" -o "$tmp/$f.pfm" --spp 4 --width 64 --seed 7 >/dev/null 2>"$tmp/err"; then
    echo "FAIL $f does not render: $(cat "$tmp/err")"; fail=1
  elif [ -s "$tmp/err" ]; then
    echo "FAIL $f: warnings: $(cat "$tmp/err")"; fail=1
  fi
done
if [ $fail -eq 0 ]; then
  for f in fog.xml fog.pbrt; do
    cmp -s "$tmp/$f.pfm" "$tmp/fog.json.pfm" || { echo "FAIL $f and fog.json render different images"; fail=1; }
  done
fi
[ $fail -eq 0 ] && echo "ok"
exit $fail
