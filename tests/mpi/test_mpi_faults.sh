#!/usr/bin/env bash
# paprsek-mpi's failures: a usage error (one message, status 2); a scene rank
# 0 cannot read; a rank that cannot load the scene (it is given a scene rank 0
# did not send); a rank killed while rendering; Ctrl-C on mpirun. Each stops
# the whole job with a non-zero status and a message naming the rank and the
# cause, and leaves no OUT (Ctrl-C leaves OUT.partial).
# usage: test_mpi_faults.sh PAPRSEK PAPRSEK_MPI MPIEXEC DATA_DIR
. "$(dirname "$0")/mpi_common.sh"

common=(--width 48 --height 32 --threads 1 --quiet)
out=$tmp/out.pfm

# a usage error: rank 0 alone says so
run_mpi 3 mpi_room.obj -o "$out" "${common[@]}" --spp 0 >"$tmp/o" 2>"$tmp/e"
st=$?
[ $st = 2 ] || bad "--spp 0: exit status $st, not 2"
n=$(grep -c "spp" "$tmp/e")
[ "$n" = 1 ] || { bad "--spp 0: $n messages about --spp, not 1"; cat "$tmp/e"; }

# rank 0 cannot read the scene
run_mpi 2 missing.obj -o "$out" "${common[@]}" >"$tmp/o" 2>"$tmp/e"
st=$?
[ $st = 1 ] || bad "missing scene: exit status $st, not 1"
grep -q "rank 0 on .*: missing.obj: cannot open" "$tmp/e" || { bad "missing scene: no message naming rank 0 and the file"; cat "$tmp/e"; }
[ -e "$out" ] && bad "missing scene: $out was written"

# rank 1 cannot load its scene: it asks for a file rank 0 did not send
timeout 60 "$mpiexec" --oversubscribe -np 1 -wdir "$tmp/scene" "$mpi" render mpi_room.obj -o "$out" "${common[@]}" : \
  -np 1 -wdir "$tmp/empty" "$mpi" render other.obj -o "$out" "${common[@]}" >"$tmp/o" 2>"$tmp/e"
st=$?
[ $st = 1 ] || bad "a rank without its scene: exit status $st, not 1"
grep -q "rank 1 on .*: other.obj: not among the files rank 0 sent" "$tmp/e" ||
  { bad "a rank without its scene: no message naming rank 1 and the cause"; cat "$tmp/e"; }
[ -e "$out" ] && bad "a rank without its scene: $out was written"

# start_long N: a render of --time 60 with N ranks in the background; $mpid
# is mpirun's id, $rank1 rank 1's (once it renders).
start_long() {
  "$mpiexec" --oversubscribe -np 1 -wdir "$tmp/scene" "$mpi" render mpi_room.obj -o "$out" "${common[@]}" --time 60 : \
    -np $(($1 - 1)) -wdir "$tmp/empty" "$mpi" render mpi_room.obj -o "$out" "${common[@]}" --time 60 \
    >"$tmp/o" 2>"$tmp/e" &
  mpid=$!
  rank1=
  local i c
  for i in $(seq 100); do
    for c in $(pgrep -P "$mpid"); do
      tr '\0' '\n' <"/proc/$c/environ" 2>/dev/null | grep -qx OMPI_COMM_WORLD_RANK=1 && rank1=$c
    done
    [ -n "$rank1" ] && break
    sleep 0.1
  done
  sleep 1.5 # the scene is loaded and tiles are being rendered
}

# wait_job: waits for mpirun (at most 30 s), sets $st
wait_job() {
  local i
  for i in $(seq 300); do kill -0 "$mpid" 2>/dev/null || break; sleep 0.1; done
  if kill -0 "$mpid" 2>/dev/null; then
    bad "mpirun did not stop within 30 s"
    kill -KILL "$mpid"
  fi
  wait "$mpid"
  st=$?
}

if [ -d /proc/self ]; then
  # a rank killed
  start_long 2
  if [ -z "$rank1" ]; then
    bad "rank 1 of the long render was not found"
  else
    kill -KILL "$rank1"
    wait_job
    [ $st != 0 ] || bad "a rank killed: exit status 0"
    grep -q "rank 1 .*signal 9" "$tmp/e" || { bad "a rank killed: no message naming rank 1 and the signal"; cat "$tmp/e"; }
    [ -e "$out" ] && bad "a rank killed: $out was written"
  fi
  rm -f "$tmp"/out*

  # Ctrl-C: mpirun passes SIGTERM on; rank 0 writes the finished tiles
  start_long 2
  kill -INT "$mpid"
  wait_job
  [ $st != 0 ] || bad "SIGINT: exit status 0"
  [ -e "$out" ] && bad "SIGINT: $out was written"
  partial=$tmp/out.partial.pfm
  if [ -e "$partial" ]; then
    size=$(wc -c <"$partial")
    [ "$size" -gt $((48 * 32 * 12)) ] || bad "SIGINT: $partial holds $size bytes, less than a 48x32 image"
    grep -q "finished tiles written to $partial" "$tmp/e" || bad "SIGINT: no message about $partial"
  else
    bad "SIGINT: no $partial"
    cat "$tmp/e"
  fi
else
  echo "no /proc: the killed-rank and SIGINT cases are skipped"
fi
[ -n "${PK_SHOW:-}" ] && cat "$tmp/e"
[ $fail = 0 ] && echo "test_mpi_faults: ok"
exit $fail
