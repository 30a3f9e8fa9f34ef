#!/usr/bin/env bash
# SIGINT and SIGTERM during a render: the render stops within seconds, exit
# status 130, the finished tiles go to OUT with ".partial" before the
# extension, an existing OUT is left untouched (and a missing one is not
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

# interrupt SIGNAL EXISTING: renders the built-in Cornell box for what would
# be hours (65536 samples per pixel), sends SIGNAL after a second and checks
# the outcome; EXISTING=1 puts a file at OUT first.
interrupt() {
  local sig=$1 existing=$2 name="SIG$1"
  rm -rf "$tmp"/*
  if [ "$existing" = 1 ]; then
    printf 'an earlier image\n' >"$tmp/out.png"
    name="$name over an existing image"
  fi
  "$bin" render -o "$tmp/out.png" --width 96 --height 64 --spp 65536 --threads 2 >"$tmp/stdout" 2>"$tmp/stderr" &
  local pid=$!
  sleep 1
  kill -s "$sig" "$pid"
  local waited=0
  while kill -0 "$pid" 2>/dev/null && [ $waited -lt 300 ]; do
    sleep 0.1
    waited=$((waited + 1))
  done
  if kill -0 "$pid" 2>/dev/null; then
    kill -9 "$pid"
    wait "$pid"
    bad "$name: still rendering 30 s after the signal"
    return
  fi
  wait "$pid"
  local rc=$?
  local want="paprsek: interrupted; finished tiles written to $tmp/out.partial.png"
  [ "$rc" -eq 130 ] || bad "$name: exit $rc, wanted 130"
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
  [ $fail -ne 0 ] || echo "ok   $name: exit 130 after $((waited / 10)).$((waited % 10)) s, $(cat "$tmp/stderr")"
}

interrupt INT 1
interrupt TERM 1
interrupt INT 0

# A render that is not interrupted replaces OUT with the complete image.
rm -rf "$tmp"/*
printf 'an earlier image\n' >"$tmp/out.png"
"$bin" render -o "$tmp/out.png" --width 24 --height 16 --light-samples 1 2>"$tmp/stderr" ||
  bad "plain render: exit $?: $(cat "$tmp/stderr")"
[ "$(png_size "$tmp/out.png")" = "24 16" ] || bad "plain render: OUT is not the new 24x16 PNG"
[ ! -e "$tmp/out.partial.png" ] || bad "plain render: a .partial image was written"
exit $fail
