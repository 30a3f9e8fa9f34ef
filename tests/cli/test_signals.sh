#!/usr/bin/env bash
# SIGINT and SIGTERM during a render: the render stops within seconds, exit
# status 128 + the signal (130 for SIGINT, 143 for SIGTERM, as a shell
# reports a process the signal ended), the finished tiles go to OUT with
# ".partial" before the extension, an existing OUT is left untouched (and a missing one is not
# created), and no temporary file is left behind.
# usage: test_signals.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL $*"; fail=1; }

# png_size FILE: prints "WIDTH HEIGHT" of a PNG, or nothing when FILE is not one.
png_size() {
  [ "$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || return
  od -An -tu1 -j16 -N8 "$1" | awk '{ print $1*16777216 + $2*65536 + $3*256 + $4, $5*16777216 + $6*65536 + $7*256 + $8 }'
}

# start_render ARGS...: starts paprsek render ARGS in the background (pid in
# $pid) and returns once it has its signal handlers, that is, once it renders.
start_render() {
  "$bin" render "$@" >"$tmp/stdout" 2>"$tmp/stderr" &
  pid=$!
  # Before its handler is installed SIGTERM would kill paprsek and SIGINT,
  # which a shell's background job ignores, would be lost. Without /proc, a
  # second's wait.
  local n=0 mask
  if [ -r "/proc/$pid/status" ]; then
    while [ $n -lt 600 ]; do
      mask=$(awk '/^SigCgt:/ { print $2 }' "/proc/$pid/status" 2>/dev/null)
      [ -n "$mask" ] && (((16#$mask >> 1) & 1)) && (((16#$mask >> 14) & 1)) && return
      sleep 0.1
      n=$((n + 1))
    done
  else
    sleep 1
  fi
}

# stop SIGNAL NAME: sends SIGNAL to $pid, waits up to 30 s for it to end and
# sets $rc (empty when it had to be killed) and $waited (tenths of a second).
stop() {
  kill -s "$1" "$pid"
  waited=0
  while kill -0 "$pid" 2>/dev/null && [ $waited -lt 300 ]; do
    sleep 0.1
    waited=$((waited + 1))
  done
  if kill -0 "$pid" 2>/dev/null; then
    kill -9 "$pid"
    wait "$pid"
    bad "$2: still rendering 30 s after the signal"
    rc=
    return
  fi
  wait "$pid"
  rc=$?
}

# interrupt SIGNAL EXISTING: renders the built-in Cornell box for what would
# be hours (65536 samples per pixel), sends SIGNAL once the render runs and
# checks the outcome; EXISTING=1 puts a file at OUT first.
interrupt() {
  local sig=$1 existing=$2 name="SIG$1" want_rc
  case $sig in INT) want_rc=130 ;; TERM) want_rc=143 ;; esac
  rm -rf "$tmp"/*
  if [ "$existing" = 1 ]; then
    printf 'an earlier image\n' >"$tmp/out.png"
    name="$name over an existing image"
  fi
  start_render -o "$tmp/out.png" --width 96 --height 64 --spp 65536 --threads 2
  sleep 0.2
  stop "$sig" "$name"
  [ -n "$rc" ] || return
  local want="paprsek: interrupted; finished tiles written to $tmp/out.partial.png"
  [ "$rc" -eq "$want_rc" ] || bad "$name: exit $rc, wanted $want_rc"
  [ "$(cat "$tmp/stderr")" = "$want" ] || bad "$name: stderr is '$(cat "$tmp/stderr")', wanted '$want'"
  if [ "$existing" = 1 ]; then
    [ "$(cat "$tmp/out.png")" = "an earlier image" ] || bad "$name: the existing OUT was changed"
  else
    [ ! -e "$tmp/out.png" ] || bad "$name: OUT was created"
  fi
  [ "$(png_size "$tmp/out.partial.png")" = "96 64" ] || bad "$name: out.partial.png is not a 96x64 PNG"
  local left
  left=$(ls "$tmp" | grep -F '.tmp.')
  [ -z "$left" ] || bad "$name: temporary files left: $left"
  [ $fail -ne 0 ] || echo "ok   $name: exit $rc after $((waited / 10)).$((waited % 10)) s, $(cat "$tmp/stderr")"
}

interrupt INT 1
interrupt TERM 1
interrupt INT 0
interrupt TERM 0

# The .partial image holds the tiles finished before the signal, and the
# others black: a PFM (raw floats) of 1024x1024 at 64 samples (minutes of
# work) interrupted after a few seconds has both lit and black pixels. How
# long the first tile takes depends on the build (sanitizers make it several
# times slower) and on what else the machine runs: when no tile had finished
# yet, the render is tried again with twice the wait, up to 32 s.
wait_s=2
while :; do
  rm -rf "$tmp"/*
  start_render -o "$tmp/out.pfm" --width 1024 --height 1024 --spp 64 --threads 2
  sleep $wait_s
  stop INT "finished tiles"
  [ -n "$rc" ] || break
  part="$tmp/out.partial.pfm"
  header=$(head -c 18 "$part" 2>/dev/null | tr '\n' ' ')
  body=$((1024 * 1024 * 12))
  lit=$(tail -c "$body" "$part" 2>/dev/null | tr -d '\000' | wc -c)
  size=$(($(wc -c <"$part" 2>/dev/null || echo 0) - 18))
  if [ "$rc" -ne 130 ] || [ "$header" != "PF 1024 1024 -1.0 " ] || [ "$size" -ne "$body" ]; then
    bad "finished tiles: exit $rc, .partial header '$header', $size bytes of pixels"
  elif [ "$lit" -eq 0 ] && [ $wait_s -lt 32 ]; then
    echo "note no tile finished in $wait_s s; trying again with $((wait_s * 2)) s"
    wait_s=$((wait_s * 2))
    continue
  elif [ "$lit" -eq 0 ] || [ "$lit" -gt $((body / 2)) ]; then
    bad "finished tiles: $lit of $body bytes of pixels are not zero after $wait_s s; wanted some, and many black"
  else
    echo "ok   finished tiles: $lit of $body pixel bytes of out.partial.pfm are not zero after $wait_s s (a tile has 3072)"
  fi
  [ ! -e "$tmp/out.pfm" ] || bad "finished tiles: OUT was created"
  break
done

# A render that is not interrupted replaces OUT with the complete image.
rm -rf "$tmp"/*
printf 'an earlier image\n' >"$tmp/out.png"
"$bin" render -o "$tmp/out.png" --width 24 --height 16 --light-samples 1 2>"$tmp/stderr" ||
  bad "plain render: exit $?: $(cat "$tmp/stderr")"
[ "$(png_size "$tmp/out.png")" = "24 16" ] || bad "plain render: OUT is not the new 24x16 PNG"
[ ! -e "$tmp/out.partial.png" ] || bad "plain render: a .partial image was written"
exit $fail
