#!/usr/bin/env bash
# convert_same.sh - converts scenes with `paprsek convert` and renders the
# original and the converted scene with the same options (both integrators,
# volpath for media, every AOV), asserting identical PFM bytes. Sourced by
# test_convert.sh and test_convert_shared.sh; also runnable by hand:
#   tests/cli/convert_same.sh PAPRSEK OUTDIR SCENE...   (SCENE: FILE or FILE|volpath)
# environment: SIZE (48), SPP (2)
# Prints "same NAME INTEGRATOR" or "FAIL ..." per render; returns the failures.
convert_same() { # bin outdir scene...
  local bin=$1 out=$2; shift 2
  local size=${SIZE:-48} spp=${SPP:-2} bad=0 entry scene more name integ
  for entry in "$@"; do
    scene=${entry%%|*}; more=""
    [ "$entry" != "$scene" ] && more=${entry#*|}
    name=$(echo "$scene" | sed 's|^/||; s|/|_|g')
    if ! timeout 600 "$bin" convert "$scene" -o "$out/$name.json" -q 2>"$out/$name.convert.err"; then
      echo "FAIL $name: convert failed: $(cat "$out/$name.convert.err")"; bad=$((bad + 1)); continue
    fi
    for integ in path whitted $more; do
      local ok=1 a b
      for which in orig conv; do
        local src=$scene; [ $which = conv ] && src=$out/$name.json
        if ! timeout 600 "$bin" render "$src" -o "$out/$name.$which.$integ.pfm" --width "$size" --height "$size" \
             --spp "$spp" --threads 2 --seed 3 --integrator "$integ" --aov albedo,normal,depth,heatmap -q \
             >"$out/$name.$which.$integ.log" 2>&1; then
          echo "FAIL $name $integ: the $which scene does not render: $(head -n 2 "$out/$name.$which.$integ.log")"
          ok=0
        fi
      done
      if [ $ok = 1 ]; then
        for a in "$out/$name.orig.$integ".*.pfm "$out/$name.orig.$integ.pfm"; do
          b=${a/.orig./.conv.}
          cmp -s "$a" "$b" || { echo "FAIL $name $integ: $(basename "$b") differs from the original's"; ok=0; }
        done
      fi
      [ $ok = 1 ] && echo "same $name $integ" || bad=$((bad + 1))
    done
  done
  return $bad
}
if [ "${BASH_SOURCE[0]}" = "$0" ]; then
  bin=${1:?usage: convert_same.sh PAPRSEK OUTDIR SCENE...}; out=${2:?}; shift 2
  mkdir -p "$out"
  convert_same "$bin" "$out" "$@"
  exit $?
fi
