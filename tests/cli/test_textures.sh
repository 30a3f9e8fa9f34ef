#!/usr/bin/env bash
# Textures end to end: the textured scene of tests/data (checker floor, a
# fence with map_d holes, bump, normal and colour panels) renders the same
# with every accelerator (holes included) for both integrators: bit for bit
# with Paprsek's own, within float rounding with Embree (whose triangle test
# is its own: the Cornell box differs by rounding too, nowhere by more than
# 1e-3 relative, which a hole taken for a surface would exceed); --stats
# reports the texture memory; the albedo AOV shows the texture; a texture
# that cannot be read is one warning and the render goes on.
# usage: test_textures.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
data=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
ok() { echo "ok   $1"; }
bad() { echo "FAIL $1"; fail=1; }

# Samples of two PFM files of the same size that differ by more than 1e-3 relative.
differing() {
  paste <(od -An -tf4 -v -j "$(head -n 3 "$1" | wc -c)" "$1" | tr -s ' ' '\n' | grep -v '^$') \
        <(od -An -tf4 -v -j "$(head -n 3 "$2" | wc -c)" "$2" | tr -s ' ' '\n' | grep -v '^$') |
    awk '{ d = $1 - $2; if (d < 0) d = -d; a = $1 < 0 ? -$1 : $1; if (!(d <= 1e-3 * (a + 1e-3))) n++ } END { print n + 0 }'
}

view=(--width 48 --height 36 --look-from 0,2.2,5 --look-at 0,0.7,0 --threads 2)
accels="none bvh midpoint"
"$bin" render -o "$tmp/probe.pfm" --accel embree --width 4 --height 4 --quiet 2>/dev/null && accels="$accels embree"
for integ in path whitted; do
  for a in $accels; do
    "$bin" render "$data/tex_scene.obj" -o "$tmp/$integ-$a.pfm" "${view[@]}" --spp 2 --integrator $integ --accel $a \
      --quiet 2>"$tmp/err" || bad "$integ $a: $(cat "$tmp/err")"
    [ -s "$tmp/err" ] && bad "$integ $a warned: $(cat "$tmp/err")"
  done
  for a in $accels; do
    if [ $a = embree ]; then
      # Embree's own triangle test rounds t, u, v differently (its AVX2 and
      # AVX-512 kernels differ too): a ray through a cut-out may land on the
      # other side of a texel edge. At most 0.5 % of the 5184 samples.
      n=$(differing "$tmp/$integ-none.pfm" "$tmp/$integ-$a.pfm")
      [ "$n" -le 25 ] && ok "$integ: embree gives the image of none within rounding ($n samples differ)" ||
        bad "$integ: embree differs from none in $n samples"
    else
      cmp -s "$tmp/$integ-none.pfm" "$tmp/$integ-$a.pfm" && ok "$integ: $a gives the image of none" ||
        bad "$integ: $a differs from none"
    fi
  done
done

"$bin" render "$data/tex_scene.obj" -o "$tmp/s.png" "${view[@]}" --stats >"$tmp/out" 2>&1
grep -Eq '^textures +6 images, [0-9.]+ MiB \(mipmaps included\)$' "$tmp/out" && ok "--stats reports 6 textures" ||
  bad "--stats: $(grep textures "$tmp/out")"
"$bin" render "$data/tex_scene.obj" -o "$tmp/j.pfm" "${view[@]}" --stats-json - --quiet >"$tmp/json"
grep -Eq '"texture_bytes": [1-9][0-9]*' "$tmp/json" && ok "--stats-json has texture_bytes" || bad "stats json: $(cat "$tmp/json")"

# the quad's albedo AOV is its texture: red, green, blue, white quarters
"$bin" render "$data/tex_quad.obj" -o "$tmp/q.pfm" --width 8 --height 8 --look-from 0,0,2.7474774 --look-at 0,0,0 \
  --fov 40 --aov albedo --quiet --integrator whitted --spp 1
# pixel (2, 2) from the top left (file row 5: PFM rows run bottom to top) is 1/8 of a texel
# right of and below the red texel's centre: bilinear weights 49/64 red, 7/64 green, 7/64
# blue, 1/64 white give (0.78125, 0.125, 0.125)
px=$(od -An -tf4 -v -j $(( $(head -n 3 "$tmp/q.albedo.pfm" | wc -c) + (5 * 8 + 2) * 12 )) -N 12 "$tmp/q.albedo.pfm")
echo "$px" | awk '{ d1 = $1 - 0.78125; d2 = $2 - 0.125; d3 = $3 - 0.125
  exit !(d1 * d1 < 1e-6 && d2 * d2 < 1e-6 && d3 * d3 < 1e-6) }' &&
  ok "the albedo AOV shows the bilinear texture ($px)" || bad "albedo AOV pixel: $px"

# a missing texture: one warning naming the MTL line and the file, the render goes on
mkdir "$tmp/m"
printf 'newmtl m\nKd 0.5 0.5 0.5\nmap_Kd nothere.png\n' >"$tmp/m/m.mtl"
printf 'mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n' >"$tmp/m/m.obj"
"$bin" render "$tmp/m/m.obj" -o "$tmp/m.png" --width 8 --height 8 2>"$tmp/err"
rc=$?
[ $rc -eq 0 ] && ok "a missing texture does not stop the render" || bad "missing texture: exit $rc"
n=$(grep -c "m.mtl:3: texture 'nothere.png' not used ($tmp/m/nothere.png: cannot open: No such file or directory); Kd is used alone" "$tmp/err")
[ "$n" = 1 ] && ok "one warning for the missing texture" || bad "missing texture warning: $(cat "$tmp/err")"
exit $fail
