#!/usr/bin/env bash
# OpenVDB .vdb media through the library's OpenVDB module (paprsek_openvdb.so,
# which `make build` puts beside the program where libopenvdb-dev is
# installed, and `make demo` does not build): with the module a .vdb scene
# renders; without it (--config openvdb.module naming a file that is not
# there, or a program with no module beside it) or without OpenVDB (a module
# whose library is gone) the render fails with exit status 1 and one line
# naming OpenVDB's package.
# usage: test_vdb.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
data=$3/media
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
cp "$data/grid.vdb" "$tmp/"
cat >"$tmp/smoke.json" <<'JSON'
{"spheres": [{"center": [0, 0, 0], "radius": 1}],
 "media": [{"name": "smoke", "type": "grid", "file": "grid.vdb", "grid": "density", "sigma_t": 0.01}],
 "medium": "smoke"}
JSON
# render PROGRAM [OPTION...]
render() {
  local b=$1
  shift
  "$b" render "$tmp/smoke.json" -q --width 16 --height 16 --spp 1 -o "$tmp/out.png" "$@"
}

# refused: exit 1, one line: "paprsek: smoke.json:2: media[0].file: PATH: MESSAGE"
expect_refused() {
  local what=$1 pattern=$2
  shift 2
  rm -f "$tmp/out.png"
  "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  if [ "$rc" != 1 ]; then
    echo "FAIL $what: exit status $rc, expected 1: $(head -3 "$tmp/err")"; fail=1
  elif [ "$(wc -l <"$tmp/err")" != 1 ]; then
    echo "FAIL $what: expected one line on stderr: $(cat "$tmp/err")"; fail=1
  elif ! grep -Eq "^paprsek: .*smoke.json:2: media\[0\]\.file: .*grid.vdb: $pattern" "$tmp/err"; then
    echo "FAIL $what: message '$(cat "$tmp/err")' does not say '$pattern'"; fail=1
  elif [ -e "$tmp/out.png" ]; then
    echo "FAIL $what: an image was written"; fail=1
  else
    echo "ok: $what: $(cat "$tmp/err")"
  fi
}

missing='\.vdb files are read by the OpenVDB module, which is not here \(.*paprsek_openvdb\.so is not (there|in .*)\): install OpenVDB \(Debian: libopenvdb-dev\) and build the module \(make build\)$'
expect_refused "openvdb.module not there" "$missing" \
  render "$bin" --config "openvdb.module=$tmp/no-such-dir/paprsek_openvdb.so"
printf 'not a shared object' >"$tmp/fake.so"
expect_refused "openvdb.module not a module" \
  'the OpenVDB module does not load: .*fake\.so.*; is OpenVDB installed\? \(Debian: libopenvdb-dev\)$' \
  render "$bin" --config "openvdb.module=$tmp/fake.so"

# a module whose OpenVDB is not installed (here: a module that needs a
# library which is gone), as after removing libopenvdb: the loader's reason
if command -v cc >/dev/null 2>&1; then
  echo 'int pk_nothing(void) { return 0; }' >"$tmp/d.c"
  if cc -shared -fPIC -o "$tmp/libopenvdb_gone.so" "$tmp/d.c" &&
     cc -shared -fPIC -o "$tmp/paprsek_openvdb.so" "$tmp/d.c" -L"$tmp" -Wl,--no-as-needed -lopenvdb_gone; then
    rm -f "$tmp/libopenvdb_gone.so"
    expect_refused "OpenVDB not installed" \
      'the OpenVDB module does not load: .*paprsek_openvdb\.so could not be loaded \(libopenvdb_gone\.so: cannot open shared object file.*\); is OpenVDB installed\? \(Debian: libopenvdb-dev\)$' \
      render "$bin" --config "openvdb.module=$tmp/paprsek_openvdb.so"
  else
    echo "FAIL cc could not build the stand-in module"; fail=1
  fi
else
  echo "skipped: OpenVDB not installed (no C compiler to build a stand-in module)"
fi

# the program alone in a folder (as `make demo` leaves it: no module beside it)
mkdir -p "$tmp/alone"
cp "$bin" "$tmp/alone/paprsek"
if [ -e /usr/local/lib/paprsek/paprsek_openvdb.so ]; then
  echo "skipped: a program without a module beside it (one is installed in /usr/local/lib/paprsek)"
else
  expect_refused "no module beside the program" "$missing" render "$tmp/alone/paprsek"
fi

# the module the build made, found beside the program
if [ -e "$(dirname "$bin")/paprsek_openvdb.so" ]; then
  if render "$bin" 2>"$tmp/err" && [ -s "$tmp/out.png" ]; then
    echo "ok: the module beside the program reads grid.vdb"
  else
    echo "FAIL the module beside the program: $(cat "$tmp/err")"; fail=1
  fi
else
  echo "note: this build made no OpenVDB module (libopenvdb-dev missing): only the refusals are checked"
fi
[ $fail -eq 0 ] && echo "ok"
exit $fail
