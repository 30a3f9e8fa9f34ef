#!/usr/bin/env bash
# paprsek-mpi denoises as `paprsek render` does, once, on rank 0, after the
# merge, and writes the same bytes: the default render (16 spp, denoised with
# the albedo and normal the ranks send with their tiles) and --spp 4
# --denoise, with 1, 2 and 3 ranks and tiles of three sizes; --time passes
# denoised equal one denoised render of as many samples; --stats prints the
# denoiser's row. --denoise with weights that are not there stops the job
# before anything is rendered: status 1, one message, no file; a default
# render without them warns once and stays raw, as paprsek render.
# Skipped (77) when the weights (BUILD/weights) or oneDNN are missing.
# usage: test_mpi_denoise.sh PAPRSEK PAPRSEK_MPI MPIEXEC DATA_DIR
. "$(dirname "$0")/mpi_common.sh"

cam=(--look-from 0,1.5,5 --look-at 0,1,0)
common=(--width 48 --height 32 --threads 1 --quiet "${cam[@]}")

# --denoise without weights: rank 0 says so once, before any rendering, and
# every rank stops with status 1; neither OUT nor OUT.partial is written.
# (This needs no weights, so it runs before the skip below.)
for n in 2 3; do
  run_mpi "$n" mpi_room.obj -o "$tmp/none.png" "${common[@]}" --spp 4 --denoise --weights /nonexistent --stats \
    >"$tmp/o" 2>"$tmp/e"
  st=$?
  [ $st = 1 ] || bad "$n ranks, --denoise --weights /nonexistent: exit status $st, not 1"
  k=$(grep -c "^paprsek-mpi:" "$tmp/e")
  [ "$k" = 1 ] || { bad "$n ranks, --denoise --weights /nonexistent: $k messages, not 1"; cat "$tmp/e"; }
  grep -q "^paprsek-mpi: /nonexistent/.*no such weights file" "$tmp/e" ||
    { bad "$n ranks, --denoise --weights /nonexistent: no message naming the weights file"; cat "$tmp/e"; }
  [ -s "$tmp/o" ] && { bad "$n ranks, --denoise --weights /nonexistent: rendered (--stats printed)"; cat "$tmp/o"; }
  ls "$tmp" | grep -q "^none" && bad "$n ranks, --denoise --weights /nonexistent: wrote $(ls "$tmp" | grep "^none")"
done

# the weights where the build puts them (beside both programs), and oneDNN
weights=$(dirname "$bin")/weights
if [ ! -r "$weights/rt_hdr_alb_nrm.tza" ]; then
  [ $fail = 0 ] || exit 1
  echo "SKIP: the denoiser's weights are not in $weights (make weights fetches them)"
  exit 77
fi
if ! "$bin" render -o "$tmp/probe.pfm" --width 8 --height 8 --spp 1 --denoise --quiet 2>"$tmp/e"; then
  if grep -q "denoise:" "$tmp/e"; then
    [ $fail = 0 ] || exit 1
    echo "SKIP: the denoiser cannot run here: $(cat "$tmp/e")"
    exit 77
  fi
  bad "paprsek render --denoise: $(cat "$tmp/e")"
fi

# same SPEC...: paprsek render, then paprsek-mpi with 1, 2 and 3 ranks (tiles
# of 16, 24 and 8), the same bytes
same() {
  local what="${*:-the default render}" n t
  rm -f "$tmp/one.pfm"
  (cd "$tmp/scene" && "$bin" render mpi_room.obj -o "$tmp/one.pfm" "${common[@]}" "$@") ||
    { bad "paprsek render $what"; return; }
  for n in 1 2 3; do
    t=$(echo 16 24 8 | cut -d' ' -f"$n")
    rm -f "$tmp/many.pfm"
    if ! run_mpi "$n" mpi_room.obj -o "$tmp/many.pfm" "${common[@]}" --tile "$t" "$@" >"$tmp/o" 2>"$tmp/e"; then
      bad "$n ranks, $what: exit status $?"
      cat "$tmp/e"
      continue
    fi
    cmp -s "$tmp/one.pfm" "$tmp/many.pfm" || bad "$n ranks, tile $t, $what: the image differs from paprsek render's"
  done
}

same                    # the default render: 16 spp, denoised
cp "$tmp/one.pfm" "$tmp/default.pfm"
same --spp 4 --denoise
same --spp 4 --denoise --denoise-quality fast
# the default render was denoised at all (else the above proves little)
(cd "$tmp/scene" && "$bin" render mpi_room.obj -o "$tmp/raw.pfm" "${common[@]}" --no-denoise) ||
  bad "paprsek render --no-denoise"
cmp -s "$tmp/raw.pfm" "$tmp/default.pfm" && bad "the default render equals the --no-denoise one: nothing was denoised"
rm -f "$tmp/many.pfm"
run_mpi 2 mpi_room.obj -o "$tmp/many.pfm" "${common[@]}" --no-denoise >"$tmp/o" 2>"$tmp/e" ||
  { bad "2 ranks, --no-denoise"; cat "$tmp/e"; }
cmp -s "$tmp/raw.pfm" "$tmp/many.pfm" || bad "2 ranks, --no-denoise: the image differs from paprsek render's"

# a default render without weights: one warning, the raw image
rm -f "$tmp/many.pfm"
run_mpi 3 mpi_room.obj -o "$tmp/many.pfm" --width 48 --height 32 --threads 1 "${cam[@]}" --weights /nonexistent \
  >"$tmp/o" 2>"$tmp/e" || { bad "3 ranks, default render, --weights /nonexistent: exit status $?"; cat "$tmp/e"; }
k=$(grep -c "^paprsek-mpi: warning: the image is not denoised" "$tmp/e")
[ "$k" = 1 ] || { bad "3 ranks, default render, --weights /nonexistent: $k warnings, not 1"; cat "$tmp/e"; }
cmp -s "$tmp/raw.pfm" "$tmp/many.pfm" || bad "3 ranks, default render, --weights /nonexistent: not the raw image"

# PNG and --stats: the denoiser's row, as paprsek render prints it
(cd "$tmp/scene" && "$bin" render mpi_room.obj -o "$tmp/one.png" "${common[@]}") || bad "paprsek render to PNG"
run_mpi 2 mpi_room.obj -o "$tmp/many.png" "${common[@]}" --tile 16 --stats >"$tmp/stats" 2>"$tmp/e" ||
  { bad "2 ranks with --stats"; cat "$tmp/e"; }
cmp -s "$tmp/one.png" "$tmp/many.png" || bad "2 ranks: the denoised PNG differs"
grep -Eq '^denoise +[0-9.]+ s, [0-9.]+ MiB, [0-9.]+ GFLOP/s \(high-quality network\)$' "$tmp/stats" ||
  { bad "--stats: no 'denoise' row"; cat "$tmp/stats"; }
grep -q '^ranks  *2$' "$tmp/stats" || bad "--stats: no 'ranks 2' line"

# --time --denoise: passes of 1 spp, denoised, equal one denoised render of as many samples
if run_mpi 2 mpi_room.obj -o "$tmp/timed.pfm" "${common[@]}" --spp 1 --time 0.3 --denoise --stats \
  >"$tmp/stats" 2>"$tmp/e"; then
  passes=$(awk '$1 == "passes" { print $2 }' "$tmp/stats")
  if [ -n "$passes" ] && [ "$passes" -ge 1 ]; then
    (cd "$tmp/scene" && "$bin" render mpi_room.obj -o "$tmp/one.pfm" "${common[@]}" --spp "$passes" --denoise) ||
      bad "paprsek render --spp $passes --denoise"
    cmp -s "$tmp/one.pfm" "$tmp/timed.pfm" ||
      bad "--time --denoise: $passes passes of 1 spp differ from one denoised render of $passes spp"
  else
    bad "--time --denoise: no 'passes' line in --stats"
  fi
else
  bad "2 ranks with --time --denoise"
  cat "$tmp/e"
fi
[ $fail = 0 ] && echo "test_mpi_denoise: ok"
exit $fail
