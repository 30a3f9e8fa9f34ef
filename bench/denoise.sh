#!/usr/bin/env bash
# The denoiser's targets (docs/performance.md, "Denoising"): for each scene,
# raw renders at SPP samples per pixel against denoised renders at SPP/16,
# both as whole processes (load, render, denoise, write), interleaved over
# ROUNDS rounds; the error of each against a converged reference (relMSE =
# mean (x - r)^2 / (r^2 + 0.01)) and the ratio of wall times (medians).
# References are rendered once into bench/out/ref/ (REF_SPP samples, a seed
# of their own; delete them to remake) and never enter git.
#
# usage: bench/denoise.sh [SHARED_DIR [PAPRSEK]]
#   SPP=256 REF_SPP=4096 ROUNDS=3 SCENES="cornell sphere classroom" \
#   SWEEP="1 2 4 8 16" (CornellBox-Original at 512x512: denoised at each
#   spp against raw 1024 spp; REF512_SPP=4096)
set -euo pipefail
shared=${1:-../shared}
bin=${2:-build/paprsek}
SPP=${SPP:-256}
REF_SPP=${REF_SPP:-4096}
ROUNDS=${ROUNDS:-3}
SCENES=${SCENES:-cornell sphere classroom}
SWEEP=${SWEEP-1 2 4 8 16}
REF512_SPP=${REF512_SPP:-4096}
here=$(cd "$(dirname "$0")" && pwd)
out=$here/out
stat="/usr/bin/python3 $here/imgstat.py"
mkdir -p "$out/ref" "$out/denoise"
cb=(--look-from 0,1,3.9 --look-at 0,1,0 --fov 39.3)

scene_args() { # name -> scene file and size
  case $1 in
    cornell) echo "$shared/scenes/cornell/CornellBox-Original.obj --width 256 --height 256 ${cb[*]}" ;;
    sphere) echo "$shared/scenes/cornell/CornellBox-Sphere.obj --width 256 --height 256 ${cb[*]}" ;;
    classroom) echo "$shared/scenes/bitterli/classroom/scene_v0.6.xml --width 160 --height 90" ;;
    cornell512) echo "$shared/scenes/cornell/CornellBox-Original.obj --width 512 --height 512 ${cb[*]}" ;;
  esac
}

# wall seconds of one whole process
timed() {
  local s e
  s=$(date +%s.%N)
  "$@" >/dev/null 2>&1
  e=$(date +%s.%N)
  awk "BEGIN { print $e - $s }"
}

median() { sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }

reference() { # name spp -> path
  local ref="$out/ref/$1-$2.pfm"
  if [ ! -f "$ref" ]; then
    echo "rendering the reference of $1 ($2 spp, once) ..." >&2
    # shellcheck disable=SC2046
    "$bin" render $(scene_args "$1") --spp "$2" --seed 7777 --quiet -o "$ref"
  fi
  echo "$ref"
}

[ -x "$bin" ] || { echo "no program $bin"; exit 1; }
[ -d "$shared/scenes" ] || { echo "no $shared/scenes (../shared is absent)"; exit 0; }
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) threads; commit $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo ?)"
echo
dn=$((SPP / 16))
echo "| scene | raw spp | raw wall [s] | raw relMSE | denoised spp | denoised wall [s] | denoised relMSE | wall ratio | closer? | faster than 1/8? |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for s in $SCENES; do
  ref=$(reference "$s" "$REF_SPP")
  read -r -a args <<<"$(scene_args "$s")"
  tr=() td=()
  for r in $(seq "$ROUNDS"); do
    tr+=("$(timed "$bin" render "${args[@]}" --spp "$SPP" --seed "$r" -o "$out/denoise/$s-raw.pfm")")
    td+=("$(timed "$bin" render "${args[@]}" --spp "$dn" --seed "$r" --denoise -o "$out/denoise/$s-dn.pfm")")
  done
  er=$($stat relmse "$out/denoise/$s-raw.pfm" "$ref")
  ed=$($stat relmse "$out/denoise/$s-dn.pfm" "$ref")
  mr=$(printf '%s\n' "${tr[@]}" | median)
  md=$(printf '%s\n' "${td[@]}" | median)
  ratio=$(echo "$md / $mr" | bc -l)
  closer=$(echo "$ed <= $er" | bc -l)
  fast=$(echo "$ratio <= 0.125" | bc -l)
  printf '| %s | %d | %.2f | %.3g | %d | %.2f | %.3g | 1/%.1f | %s | %s |\n' "$s" "$SPP" "$mr" "$er" "$dn" "$md" "$ed" \
    "$(echo "1 / $ratio" | bc -l)" "$([ "$closer" = 1 ] && echo yes || echo no)" "$([ "$fast" = 1 ] && echo yes || echo no)"
done

if [ -n "$SWEEP" ]; then
  echo
  ref=$(reference cornell512 "$REF512_SPP")
  read -r -a args <<<"$(scene_args cornell512)"
  "$bin" render "${args[@]}" --spp 1024 --seed 1 --quiet -o "$out/denoise/c512-raw1024.pfm"
  e1024=$($stat relmse "$out/denoise/c512-raw1024.pfm" "$ref")
  echo "CornellBox-Original 512x512: raw 1024 spp relMSE $e1024 (reference $REF512_SPP spp)"
  echo
  echo "| denoised spp | wall [s] (median of $ROUNDS) | relMSE | better than raw 1024 spp? |"
  echo "|---|---|---|---|"
  for n in $SWEEP; do
    t=()
    for r in $(seq "$ROUNDS"); do
      t+=("$(timed "$bin" render "${args[@]}" --spp "$n" --seed "$r" --denoise -o "$out/denoise/c512-dn$n.pfm")")
    done
    e=$($stat relmse "$out/denoise/c512-dn$n.pfm" "$ref")
    printf '| %d | %.2f | %.3g | %s |\n' "$n" "$(printf '%s\n' "${t[@]}" | median)" "$e" \
      "$([ "$(echo "$e <= $e1024" | bc -l)" = 1 ] && echo yes || echo no)"
  done
fi
