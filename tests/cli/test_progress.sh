#!/usr/bin/env bash
# The progress bar: on a terminal (a pty from `script`) stderr shows a bar
# redrawn in place ('\r', percentage, elapsed time, ETA) and then one line
# "wrote OUT (WxH, N spp[, denoised], T)"; stdout (--stats) holds none of it; a pipe or a file
# gets neither, and --quiet silences both.
# usage: test_progress.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
command -v script >/dev/null || { echo "SKIP: no script (util-linux) to run paprsek on a terminal"; exit 77; }
script -qec true /dev/null </dev/null >/dev/null 2>&1 || { echo "SKIP: script cannot open a pty here"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL $*"; fail=1; }

# on_tty COMMAND: runs the shell COMMAND with stdin, stdout and stderr on a
# pty; what it wrote there goes to $tmp/tty.
on_tty() {
  script -qec "$1" /dev/null </dev/null >"$tmp/tty" 2>&1
}

# A render of about a second on two threads: several reports (4 a second)
# and the last one.
args="--width 256 --height 256 --spp 16 --light-samples 8 --threads 2"
on_tty "'$bin' render -o '$tmp/a.png' $args --stats >'$tmp/stdout'"
rc=$?
tty=$(tr '\r' '\n' <"$tmp/tty") # one line per redraw
bars=$(grep -cE '^\[[#.]+\] +[0-9]+%  [0-9.:]+ s?, (ETA|done)' <<<"$tty")
if [ $rc -ne 0 ]; then
  bad "on a terminal: exit $rc: $(cat "$tmp/tty")"
elif ! grep -q $'\r' "$tmp/tty"; then
  bad "on a terminal: no '\\r' (the bar is not redrawn in place): $(cat "$tmp/tty")"
elif [ "$bars" -lt 2 ]; then
  bad "on a terminal: $bars bar(s), wanted the first and at least the last: $tty"
elif ! grep -qE '^\[#+\] 100%  .*, done' <<<"$tty"; then
  bad "on a terminal: no full bar at 100%: $tty"
elif ! grep -qE "^wrote $tmp/a.png \(256x256, [0-9]+ spp(, denoised)?, [0-9.:]+( s)?\)$" <<<"$tty"; then
  bad "on a terminal: no 'wrote $tmp/a.png (256x256, ...)' line: $tty"
else
  echo "ok   on a terminal: $bars redraws of the bar, then '$(grep '^wrote' <<<"$tty")'"
fi
grep -q ETA <<<"$tty" || echo "note: no intermediate report with an ETA (a fast machine): $tty"
# the statistics on stdout are untouched by the bar
if grep -q $'\r\|wrote\|%' "$tmp/stdout" || ! grep -q '^Mrays/s' "$tmp/stdout"; then
  bad "on a terminal: stdout is not the statistics table alone: $(cat "$tmp/stdout")"
else
  echo "ok   on a terminal: stdout holds the statistics table alone"
fi

# the bar is erased before a message: the interrupted render's line starts clean
on_tty "'$bin' render -o '$tmp/i.png' --width 512 --height 512 --spp 4096 --threads 2 & p=\$!; sleep 1.5; kill -INT \$p; wait \$p; echo rc=\$?"
if grep -q "rc=130" "$tmp/tty" && tr '\r' '\n' <"$tmp/tty" | grep -q "^paprsek: interrupted; finished tiles written to $tmp/i.partial.png *$"; then
  echo "ok   on a terminal: the bar is erased before 'interrupted'"
else
  bad "interrupted on a terminal: $(cat -A "$tmp/tty")"
fi

# --quiet on a terminal: nothing at all
on_tty "'$bin' render -o '$tmp/q.png' $args --quiet"
rc=$?
if [ $rc -ne 0 ] || [ -s "$tmp/tty" ] || [ ! -s "$tmp/q.png" ]; then
  bad "--quiet on a terminal: exit $rc, printed '$(cat -A "$tmp/tty")'"
else
  echo "ok   --quiet on a terminal: nothing printed"
fi

# stderr a file or a pipe: no bar, no 'wrote' line
"$bin" render -o "$tmp/f.png" $args 2>"$tmp/stderr" >/dev/null
rc=$?
[ $rc -eq 0 ] && [ ! -s "$tmp/stderr" ] && echo "ok   stderr a file: nothing printed" ||
  bad "stderr a file: exit $rc, printed '$(cat -A "$tmp/stderr")'"
piped=$("$bin" render -o "$tmp/p.png" $args 2>&1 >/dev/null | cat)
[ -z "$piped" ] && [ -s "$tmp/p.png" ] && echo "ok   stderr a pipe: nothing printed" ||
  bad "stderr a pipe: printed '$piped'"
exit $fail
