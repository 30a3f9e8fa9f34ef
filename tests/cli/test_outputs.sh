#!/usr/bin/env bash
# Outputs are checked before any work: a missing folder, a folder given as
# OUT, a path through a regular file and a folder this user cannot write in
# fail at once (exit 1, one message naming the problem), before the scene is
# even read, and leave nothing behind. The same for --stats-json FILE and
# for the files of `paprsek bench`.
# usage: test_outputs.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
tmp=$(mktemp -d)  # what paprsek may write in
logs=$(mktemp -d) # its stdout and stderr
trap 'rm -rf "$tmp" "$logs"' EXIT
fail=0
bad() { echo "FAIL $*"; fail=1; }

mkdir "$tmp/work" "$tmp/folder.png" "$tmp/folder.json"
printf 'not a folder\n' >"$tmp/file.txt"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$tmp/tri.obj"
listing() { (cd "$tmp" && find . | sort); }
before=$(listing)

# refuse NAME MESSAGE COMMAND...: COMMAND (paprsek ...) must exit 1 within seconds with
# stderr "paprsek: MESSAGE" and change nothing under $tmp. The scene named
# is missing and the render would take hours: only a check made before
# loading and rendering answers with MESSAGE at once.
refuse() {
  local name=$1 want="paprsek: $2"
  shift 2
  local t0=$SECONDS
  timeout 60 "$@" >"$logs/stdout" 2>"$logs/stderr" </dev/null
  local rc=$? got
  got=$(cat "$logs/stderr")
  if [ $rc -ne 1 ]; then bad "$name: exit $rc, wanted 1; stderr: $got"
  elif [ "$got" != "$want" ]; then bad "$name: stderr is '$got', wanted '$want'"
  elif [ $((SECONDS - t0)) -gt 5 ]; then bad "$name: took $((SECONDS - t0)) s"
  elif [ "$(listing)" != "$before" ]; then bad "$name: files changed: $(diff <(echo "$before") <(listing) | tail -n +2)"
  else echo "ok   $name: $got"; fi
}

slow=(--width 2048 --height 2048 --spp 65536)
refuse "missing folder" "$tmp/no/such/out.png: folder '$tmp/no/such' does not exist" \
  "$bin" render "$tmp/missing.obj" -o "$tmp/no/such/out.png" "${slow[@]}"
refuse "folder given as OUT" "$tmp/folder.png: is a folder; name a file in it" \
  "$bin" render "$tmp/missing.obj" -o "$tmp/folder.png" "${slow[@]}"
refuse "folder given as OUT, with a slash" "$tmp/folder.png/: is a folder; name a file in it" \
  "$bin" render "$tmp/missing.obj" -o "$tmp/folder.png/" "${slow[@]}"
refuse "OUT under a regular file" "$tmp/file.txt/out.png: '$tmp/file.txt' is not a folder" \
  "$bin" render "$tmp/missing.obj" -o "$tmp/file.txt/out.png" "${slow[@]}"
refuse "OUT deeper under a regular file" \
  "$tmp/file.txt/sub/out.png: folder '$tmp/file.txt/sub' does not exist (part of its path is a file)" \
  "$bin" render "$tmp/missing.obj" -o "$tmp/file.txt/sub/out.png" "${slow[@]}"
refuse "statistics into a missing folder" "$tmp/no/stats.json: folder '$tmp/no' does not exist" \
  "$bin" render "$tmp/missing.obj" -o "$tmp/work/out.png" --stats-json "$tmp/no/stats.json" "${slow[@]}"
refuse "statistics into a folder" "$tmp/folder.json: is a folder; name a file in it" \
  "$bin" render "$tmp/missing.obj" -o "$tmp/work/out.png" --stats-json "$tmp/folder.json" "${slow[@]}"
refuse "statistics under a regular file" "$tmp/file.txt/stats.json: '$tmp/file.txt' is not a folder" \
  "$bin" render "$tmp/missing.obj" -o "$tmp/work/out.png" --stats-json="$tmp/file.txt/stats.json" "${slow[@]}"
refuse "bench hits into a missing folder" "$tmp/no/x.hits: folder '$tmp/no' does not exist" \
  "$bin" bench rays "$tmp/tri.obj" "$tmp/missing.rays" --hits "$tmp/no/x.hits"
refuse "bench rays into a folder" "$tmp/folder.png: is a folder; name a file in it" \
  "$bin" bench gen-rays "$tmp/tri.obj" --look-from 0,0,3 --look-at 0,0,0 --fov 40 -o "$tmp/folder.png"

# A folder this user may not write in. root may write anywhere, so the case
# runs as an unprivileged user (setpriv or runuser), when there is one that
# can run the program.
mkdir "$tmp/readonly" "$tmp/open"
chmod 755 "$tmp" "$tmp/readonly"
chmod 777 "$tmp/open"
before=$(listing)
as_user=()
if [ "$(id -u)" = 0 ]; then
  user=$(id -un nobody 2>/dev/null)
  group=$(id -gn nobody 2>/dev/null)
  if [ -n "$user" ] && command -v setpriv >/dev/null; then
    as_user=(setpriv --reuid="$user" --regid="$group" --clear-groups)
  elif [ -n "$user" ] && command -v runuser >/dev/null; then
    as_user=(runuser -u "$user" --)
  fi
  if [ ${#as_user[@]} -gt 0 ] && ! "${as_user[@]}" "$bin" --version >/dev/null 2>&1; then
    echo "skip unwritable folder: user nobody cannot run $bin (its folders are not readable to others)"
    as_user=()
  elif [ ${#as_user[@]} -eq 0 ]; then
    echo "skip unwritable folder: no user nobody, or neither setpriv nor runuser"
  fi
else
  chmod 555 "$tmp/readonly" # an ordinary user is refused by the mode itself
  as_user=(env)
fi
if [ ${#as_user[@]} -gt 0 ]; then
  before=$(listing)
  refuse "unwritable folder" "$tmp/readonly/out.png: cannot write in folder '$tmp/readonly': Permission denied" \
    "${as_user[@]}" "$bin" render "$tmp/missing.obj" -o "$tmp/readonly/out.png" "${slow[@]}"
  refuse "statistics into an unwritable folder" \
    "$tmp/readonly/s.json: cannot write in folder '$tmp/readonly': Permission denied" \
    "${as_user[@]}" "$bin" render "$tmp/missing.obj" -o "$tmp/open/out.png" --stats-json "$tmp/readonly/s.json" "${slow[@]}"
fi

# A good render still writes both files.
"$bin" render "$tmp/tri.obj" -o "$tmp/work/out.png" --width 8 --height 8 --stats-json "$tmp/work/s.json" --quiet ||
  bad "good render: exit $?"
[ -s "$tmp/work/out.png" ] && [ -s "$tmp/work/s.json" ] && echo "ok   a good render writes OUT and the statistics" ||
  bad "good render: OUT or the statistics missing"
exit $fail
