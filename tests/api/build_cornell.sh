#!/usr/bin/env bash
# build_cornell.sh - runs examples/build_cornell (the Cornell box built
# through the scene-building API) and checks that its image equals, byte for
# byte, the built-in box rendered with the same options (--builtin), and
# that it says nothing on the way; and that the program printed in
# docs/scene-api.md is this program.
# usage: build_cornell.sh BUILD_CORNELL SOURCE_DIR
set -euo pipefail
prog=${1:?usage: build_cornell.sh BUILD_CORNELL SOURCE_DIR}
src=${2:?usage: build_cornell.sh BUILD_CORNELL SOURCE_DIR}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
sed -n '/^```c$/,/^```$/p' "$src/docs/scene-api.md" | sed '1d;$d' > "$dir/doc.c"
cmp -s "$dir/doc.c" "$src/examples/build_cornell.c" ||
    { echo "FAIL: docs/scene-api.md's program differs from examples/build_cornell.c"; exit 1; }
"$prog" "$dir/api.pfm" 2> "$dir/api.err"
"$prog" "$dir/builtin.pfm" --builtin 2> "$dir/builtin.err"
if [ -s "$dir/api.err" ]; then echo "FAIL: the example said:"; cat "$dir/api.err"; exit 1; fi
cmp "$dir/api.pfm" "$dir/builtin.pfm" || { echo "FAIL: the API's box differs from the built-in box"; exit 1; }
[ "$(head -c 2 "$dir/api.pfm")" = PF ] || { echo "FAIL: not a PFM image"; exit 1; }
echo "ok: the box built through the API renders the built-in box's bytes ($(wc -c < "$dir/api.pfm") bytes)"
