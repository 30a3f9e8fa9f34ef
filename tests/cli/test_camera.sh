#!/usr/bin/env bash
# The camera options: --lens-radius, --focus-distance, --orthographic WIDTH
# and --perspective are in --help, change the image as they should (a lens of
# radius 0 and a focus distance without a lens change nothing, byte for
# byte), override a scene's camera, and bad values are refused with exit 2
# and one line.
# usage: test_camera.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL $*"; fail=1; }
ok() { echo "ok   $*"; }

# run ARGS...: runs paprsek, sets $rc and $err (stderr).
run() {
  timeout 120 "$bin" "$@" >"$tmp/stdout" 2>"$tmp/stderr" </dev/null
  rc=$?
  err=$(cat "$tmp/stderr")
}
# img NAME ARGS...: renders the built-in Cornell box to $tmp/NAME.pfm, small.
img() {
  local name=$1
  shift
  run render -o "$tmp/$name.pfm" --width 24 --height 16 --spp 4 --threads 2 --no-denoise -q "$@"
  [ $rc -eq 0 ] || bad "$name: exit $rc: $err"
}
same() { if cmp -s "$tmp/$1.pfm" "$tmp/$2.pfm"; then ok "$3"; else bad "$3: the images differ"; fi; }
differ() { if cmp -s "$tmp/$1.pfm" "$tmp/$2.pfm"; then bad "$3: the same image"; else ok "$3"; fi; }

# ---- --help
run render --help
help=$(cat "$tmp/stdout")
for o in "--lens-radius R" "--focus-distance D" "--orthographic WIDTH" "--perspective"; do
  case "$help" in *"$o"*) ok "--help lists $o" ;; *) bad "--help lacks $o" ;; esac
done

# ---- what the options do
img pin
img lens0 --lens-radius 0
same pin lens0 "--lens-radius 0 is the pinhole, byte for byte"
img focus --focus-distance 3
same pin focus "--focus-distance without a lens changes nothing"
img persp --perspective
same pin persp "--perspective on a perspective scene changes nothing"
img lens --lens-radius 0.05 --focus-distance 0.9
differ pin lens "--lens-radius 0.05 blurs"
img lens2 --lens-radius=0.05 --focus-distance=0.9
same lens lens2 "--lens-radius=R is --lens-radius R"
img lensf --lens-radius 0.05 --focus-distance 1.5
differ lens lensf "--focus-distance moves the plane in focus"
img ortho --orthographic 0.6
differ pin ortho "--orthographic renders another image"
img ortho0 --orthographic 0
differ ortho ortho0 "--orthographic 0 takes the perspective view's width"

# a scene's orthographic camera, and --perspective over it
cat >"$tmp/o.json" <<'EOF'
{"camera": {"look_from": [0, 0, 3], "look_at": [0, 0, 0], "fov": 40, "projection": "orthographic", "ortho_width": 2.5},
 "spheres": [{"center": [0, 0, 0], "radius": 1}]}
EOF
cat >"$tmp/p.json" <<'EOF'
{"camera": {"look_from": [0, 0, 3], "look_at": [0, 0, 0], "fov": 40},
 "spheres": [{"center": [0, 0, 0], "radius": 1}]}
EOF
img scene_o "$tmp/o.json"
img scene_p "$tmp/p.json"
img scene_op "$tmp/o.json" --perspective
img scene_po "$tmp/p.json" --orthographic 2.5
differ scene_o scene_p "the JSON scene's orthographic camera"
same scene_op scene_p "--perspective over a scene's orthographic camera"
same scene_po scene_o "--orthographic WIDTH over a scene's perspective camera"

# ---- refused: exit 2, one line, nothing written
expect() {
  local name=$1 msg="paprsek: $2"
  shift 2
  rm -f "$tmp/out.png"
  run render -o "$tmp/out.png" --width 8 --height 8 "$@"
  if [ $rc -ne 2 ]; then bad "$name: exit $rc, wanted 2: $err"
  elif [ "$err" != "$msg" ]; then bad "$name: stderr '$err', wanted '$msg'"
  elif [ -e "$tmp/out.png" ]; then bad "$name: an image was written"
  else ok "$name: $err"; fi
}
expect "negative lens" "--lens-radius: '-1' must be a number of scene units, 0 or more" --lens-radius -1
expect "lens not a number" "--lens-radius: 'wide' must be a number of scene units, 0 or more" --lens-radius wide
expect "focus inf" "--focus-distance: 'inf' must be a number of scene units, 0 or more" --focus-distance inf
expect "ortho nan" "--orthographic: 'nan' must be a number of scene units, 0 or more" --orthographic nan
expect "ortho negative" "--orthographic: '-2' must be a number of scene units, 0 or more" --orthographic=-2
expect "ortho and perspective" "--orthographic and --perspective exclude each other" --orthographic 1 --perspective
expect "perspective and ortho" "--orthographic and --perspective exclude each other" --perspective --orthographic 1

exit $fail
