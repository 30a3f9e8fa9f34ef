#!/usr/bin/env bash
# paprsek-mpi with 1, 2 and 3 ranks writes the image `paprsek render` writes,
# byte for byte, for the path tracer and the Whitted integrator, an OBJ+MTL
# scene, an OBJ+MTL+texture scene and a JSON scene with OBJ meshes, tiles of three sizes, an
# environment map (--env FILE); the scene's files exist only in rank 0's
# folder. --time passes of 1 spp equal one
# render of as many samples. --aov: the AOVs as EXR layers and as files beside
# a PNG. --stats reports every rank.
# usage: test_mpi_identical.sh PAPRSEK PAPRSEK_MPI MPIEXEC DATA_DIR
. "$(dirname "$0")/mpi_common.sh"

cam=(--look-from 0,1.5,5 --look-at 0,1,0)
common=(--width 48 --height 32 --threads 1 --quiet)

# the other ranks' folder really lacks the scene
(cd "$tmp/empty" && "$bin" render mpi_room.obj -o "$tmp/x.pfm" --quiet 2>/dev/null) &&
  bad "the scene can be read from the other ranks' folder"

for integ in path whitted; do
  for scene in mpi_room.obj mpi_tex.obj json_example.json; do
    extra=()
    [ "$scene" != json_example.json ] && extra=("${cam[@]}")
    (cd "$tmp/scene" && "$bin" render "$scene" -o "$tmp/one.pfm" "${common[@]}" --spp 3 --integrator "$integ" \
      "${extra[@]}") || { bad "paprsek render $scene --integrator $integ"; continue; }
    # one tile size per number of ranks: 16, 24 (tiles cut by the image's edge), 8
    for n in 1 2 3; do
      for t in $(echo 16 24 8 | cut -d' ' -f"$n"); do
        [ "$scene" != mpi_room.obj ] && [ "$n" = 1 ] && continue
        rm -f "$tmp/many.pfm"
        if ! run_mpi "$n" "$scene" -o "$tmp/many.pfm" "${common[@]}" --spp 3 --integrator "$integ" --tile "$t" \
          "${extra[@]}" >"$tmp/out" 2>"$tmp/err"; then
          bad "$n ranks, $scene, $integ, tile $t: exit status $?"
          cat "$tmp/err"
          continue
        fi
        cmp -s "$tmp/one.pfm" "$tmp/many.pfm" || bad "$n ranks, $scene, $integ, tile $t: the image differs"
      done
    done
  done
done

# --env FILE: the environment map is a file too, read while applying the
# command line; it exists only beside the scene (a 4x2 PFM: RGB 1, 0.5, 2)
{ printf 'PF\n4 2\n-1.0\n'; for i in 1 2 3 4 5 6 7 8; do printf '\000\000\200\077\000\000\000\077\000\000\000\100'; done; } \
  >"$tmp/scene/sky.pfm"
(cd "$tmp/scene" && "$bin" render mpi_room.obj -o "$tmp/one.pfm" "${common[@]}" --spp 2 --env sky.pfm "${cam[@]}") ||
  bad "paprsek render --env sky.pfm"
rm -f "$tmp/many.pfm"
run_mpi 2 mpi_room.obj -o "$tmp/many.pfm" "${common[@]}" --spp 2 --env sky.pfm --tile 16 "${cam[@]}" >"$tmp/out" 2>"$tmp/err" ||
  { bad "2 ranks with --env sky.pfm"; cat "$tmp/err"; }
cmp -s "$tmp/one.pfm" "$tmp/many.pfm" || bad "2 ranks with --env sky.pfm: the image differs"

# PNG and --stats: every rank listed, tiles adding up to the image's
(cd "$tmp/scene" && "$bin" render mpi_room.obj -o "$tmp/one.png" "${common[@]}" --spp 2 "${cam[@]}") ||
  bad "paprsek render to PNG"
run_mpi 3 mpi_room.obj -o "$tmp/many.png" "${common[@]}" --spp 2 --tile 8 --stats "${cam[@]}" >"$tmp/stats" 2>"$tmp/err" ||
  { bad "3 ranks with --stats"; cat "$tmp/err"; }
cmp -s "$tmp/one.png" "$tmp/many.png" || bad "3 ranks: the PNG differs"
for r in 0 1 2; do grep -q "^rank $r " "$tmp/stats" || bad "--stats does not list rank $r"; done
tiles=$(awk '/^rank [0-9]+ / { for (i = 1; i <= NF; i++) if ($i == "tiles") s += $(i - 1) } END { print s + 0 }' "$tmp/stats")
[ "$tiles" = 24 ] || bad "--stats: the ranks' tiles add up to $tiles, not 24 (48x32 in tiles of 8)"
grep -q '^ranks  *3$' "$tmp/stats" || bad "--stats: no 'ranks 3' line"
samples=$(awk '/^rank [0-9]+ / { for (i = 1; i <= NF; i++) if ($i == "samples,") s += $(i - 1) } END { print s + 0 }' "$tmp/stats")
[ "$samples" = $((48 * 32 * 2)) ] || bad "--stats: the ranks' samples add up to $samples, not $((48 * 32 * 2))"

# --aov: the AOVs' sums travel with the tiles; as layers of an OpenEXR file
# and as files beside a PNG, the same bytes as paprsek render's
(cd "$tmp/scene" && "$bin" render mpi_room.obj -o "$tmp/one.exr" "${common[@]}" --spp 3 "${cam[@]}" \
  --aov albedo,normal,depth,heatmap) || bad "paprsek render --aov to EXR"
run_mpi 3 mpi_room.obj -o "$tmp/many.exr" "${common[@]}" --spp 3 --tile 8 "${cam[@]}" --aov albedo,normal,depth,heatmap \
  >"$tmp/out" 2>"$tmp/err" || { bad "3 ranks with --aov to EXR"; cat "$tmp/err"; }
cmp -s "$tmp/one.exr" "$tmp/many.exr" || bad "3 ranks, --aov albedo,normal,depth,heatmap: the EXR differs"
mkdir -p "$tmp/one" "$tmp/many"
(cd "$tmp/scene" && "$bin" render mpi_room.obj -o "$tmp/one/a.png" "${common[@]}" --spp 2 "${cam[@]}" \
  --aov albedo,depth,heatmap) || bad "paprsek render --aov to PNG"
run_mpi 2 mpi_room.obj -o "$tmp/many/a.png" "${common[@]}" --spp 2 --tile 24 "${cam[@]}" --aov albedo,depth,heatmap \
  >"$tmp/out" 2>"$tmp/err" || { bad "2 ranks with --aov to PNG"; cat "$tmp/err"; }
for f in a.png a.albedo.png a.depth.png a.heatmap.png; do
  [ -e "$tmp/one/$f" ] || bad "paprsek render --aov did not write $f"
  cmp -s "$tmp/one/$f" "$tmp/many/$f" || bad "2 ranks, --aov albedo,depth,heatmap: $f differs"
done

# --time: passes of 1 spp; the same number of samples in one render
if run_mpi 2 mpi_room.obj -o "$tmp/timed.pfm" "${common[@]}" --spp 1 --time 0.4 --stats "${cam[@]}" \
  >"$tmp/stats" 2>"$tmp/err"; then
  passes=$(awk '$1 == "passes" { print $2 }' "$tmp/stats")
  if [ -n "$passes" ] && [ "$passes" -ge 1 ]; then
    (cd "$tmp/scene" && "$bin" render mpi_room.obj -o "$tmp/one.pfm" "${common[@]}" --spp "$passes" "${cam[@]}") ||
      bad "paprsek render --spp $passes"
    cmp -s "$tmp/one.pfm" "$tmp/timed.pfm" || bad "--time: $passes passes of 1 spp differ from one render of $passes spp"
  else
    bad "--time: no 'passes' line in --stats"
  fi
else
  bad "2 ranks with --time"
  cat "$tmp/err"
fi
[ $fail = 0 ] && echo "test_mpi_identical: ok"
exit $fail
