#!/usr/bin/env bash
# Emission maps (MTL map_Ke, JSON emitter "radiance" textures, pbrt-v4
# AreaLightSource "filename", glTF emissiveTexture): an emitter whose map is
# black on its left half and 2 on its right half must light the scene as an
# untextured emitter of radiance 2 that covers the right half only. Both are
# rendered with two seeds; in each of five vertical bands of the image the
# means must agree within 4 standard deviations, the deviation measured from
# the two seeds' per-pixel differences. The same scene drawn with the map's
# mean (uniform radiance 1 over the whole emitter, what a renderer without
# emission maps draws) must differ by more than 10 of them in the left band,
# so the comparison can tell. The same map through pbrt-v4 is checked too.
# usage: test_emission_map.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
command -v python3 >/dev/null || { echo "SKIP: python3 is not installed"; exit 77; }

# a 64 x 1 linear map: 0 on the left half, 2 on the right
python3 - "$tmp/half.pfm" <<'PY'
import struct, sys
w = 64
with open(sys.argv[1], 'wb') as f:
    f.write(b'PF\n%d 1\n-1\n' % w)
    for x in range(w):
        v = 0.0 if x < w // 2 else 2.0
        f.write(struct.pack('<3f', v, v, v))
PY
# floor y = 0 (white), emitter at y = 1 facing down, x from x0 to 1, z from -1 to 1
scene() { # name x0 mtl-lines
  cat >"$tmp/$1.mtl" <<M
newmtl floor
Kd 0.8 0.8 0.8
newmtl light
Kd 0 0 0
$3
M
  cat >"$tmp/$1.obj" <<O
mtllib $1.mtl
v -3 0 -3
v 3 0 -3
v 3 0 3
v -3 0 3
v $2 1 -1
v 1 1 -1
v 1 1 1
v $2 1 1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl floor
f 4 3 2 1
usemtl light
f 5/1 6/2 7/3 8/4
O
}
scene tex -1 $'Ke 1 1 1\nmap_Ke -clamp on half.pfm'
scene half 0 'Ke 2 2 2'
scene mean -1 'Ke 1 1 1'
view=(--width 60 --height 40 --look-from 0,0.5,4.5 --look-at 0,0.4,0 --fov 50 --spp ${PBRT_SPP:-64} --threads 2 --max-depth 2)
for s in tex half mean; do
  for seed in 1 2; do
    "$bin" render "$tmp/$s.obj" -o "$tmp/$s-$seed.pfm" "${view[@]}" --seed $seed 2>"$tmp/err" ||
      { echo "FAIL render $s: $(cat "$tmp/err")"; exit 1; }
    [ -s "$tmp/err" ] && { echo "FAIL $s warned: $(cat "$tmp/err")"; fail=1; }
  done
done
# the same emitter in pbrt-v4: its uv (0,0) .. (1,1) over the quad, the image as the radiance
cat >"$tmp/tex.pbrt" <<P
LookAt 0 0.5 4.5  0 0.4 0  0 1 0
Camera "perspective" "float fov" 50
Film "rgb" "integer xresolution" 60 "integer yresolution" 40
WorldBegin
Material "diffuse" "rgb reflectance" [0.8 0.8 0.8]
Shape "trianglemesh" "point3 P" [-3 0 -3 3 0 -3 3 0 3 -3 0 3] "integer indices" [0 3 2 0 2 1]
AttributeBegin
Material "diffuse" "rgb reflectance" [0 0 0]
AreaLightSource "diffuse" "string filename" "half.pfm"
Shape "trianglemesh" "point3 P" [-1 1 -1 1 1 -1 1 1 1 -1 1 1] "point2 uv" [0 0 1 0 1 1 0 1] "integer indices" [0 1 2 0 2 3]
AttributeEnd
P
python3 - "$tmp" <<'PY'
import math, struct, sys
d = sys.argv[1]
def pfm(path):
    with open(path, 'rb') as f:
        assert f.readline().strip() == b'PF'
        w, h = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        v = struct.unpack(('<' if scale < 0 else '>') + '%df' % (3 * w * h), f.read(12 * w * h))
    return w, h, v
def bands(name):
    w, h, a = pfm('%s/%s-1.pfm' % (d, name))
    _, _, b = pfm('%s/%s-2.pfm' % (d, name))
    out = []
    for k in range(5):
        s = []
        for y in range(h):
            for x in range(k * w // 5, (k + 1) * w // 5):
                i = 3 * (y * w + x)
                s.append((sum(a[i:i + 3]) / 3, sum(b[i:i + 3]) / 3))
        n = len(s)
        mean = sum(p + q for p, q in s) / (2 * n)
        dm = sum(p - q for p, q in s) / n
        var = sum((p - q - dm) ** 2 for p, q in s) / (n - 1)  # Var(p - q) = 2 Var(pixel)
        out.append((mean, var / 2 / (2 * n)))  # variance of the two-seed mean
    return out
tex, half, mean = bands('tex'), bands('half'), bands('mean')
bad = 0
for k in range(5):
    sd = math.sqrt(tex[k][1] + half[k][1])
    z = abs(tex[k][0] - half[k][0]) / sd if sd > 0 else (0 if tex[k][0] == half[k][0] else 1e9)
    print('band %d: map %.5f  right half %.5f  (%.1f sd)' % (k, tex[k][0], half[k][0], z))
    if not z < 4: bad = 1
sd = math.sqrt(tex[0][1] + mean[0][1])
z = abs(tex[0][0] - mean[0][0]) / sd
print('left band against the uniform mean: %.1f sd' % z)
if not z > 10: bad = 1
sys.exit(bad)
PY
[ $? = 0 ] && echo "ok   map_Ke lights as the emitter it describes" || { echo "FAIL map_Ke"; fail=1; }
for seed in 1 2; do
  "$bin" render "$tmp/tex.pbrt" -o "$tmp/pbrt-$seed.pfm" --spp ${PBRT_SPP:-64} --threads 2 --max-depth 2 --seed $seed 2>"$tmp/err" ||
    { echo "FAIL pbrt render: $(cat "$tmp/err")"; exit 1; }
  [ -s "$tmp/err" ] && { echo "FAIL pbrt warned: $(cat "$tmp/err")"; fail=1; }
done
# JSON: an emitter's radiance given as a texture; `paprsek convert` keeps it
cat >"$tmp/tex.json" <<J
{"camera": {"look_from": [0, 0.5, 4.5], "look_at": [0, 0.4, 0], "fov": 50},
 "materials": {"floor": {"type": "diffuse", "albedo": [0.8, 0.8, 0.8]},
               "light": {"type": "emitter", "radiance": {"texture": "half.pfm", "clamp": true}}},
 "meshes": [{"obj": "tex.obj"}]}
J
for seed in 1 2; do
  "$bin" render "$tmp/tex.json" -o "$tmp/json-$seed.pfm" --width 60 --height 40 --spp ${PBRT_SPP:-64} --threads 2 \
    --max-depth 2 --seed $seed 2>"$tmp/err" || { echo "FAIL json render: $(cat "$tmp/err")"; exit 1; }
done
"$bin" convert "$tmp/tex.json" -o "$tmp/conv.json" 2>"$tmp/err" &&
  "$bin" render "$tmp/conv.json" -o "$tmp/conv.pfm" --width 60 --height 40 --spp ${PBRT_SPP:-64} --threads 2 \
    --max-depth 2 --seed 1 2>>"$tmp/err" && cmp -s "$tmp/conv.pfm" "$tmp/json-1.pfm" && ! [ -s "$tmp/err" ] &&
  echo "ok   paprsek convert keeps an emission map" || { echo "FAIL convert: $(cat "$tmp/err")"; fail=1; }
# pbrt's camera sees the world mirrored (its image's right is world -x here):
# its bands are the OBJ scene's in reverse order
python3 - "$tmp" <<'PY'
import math, struct, sys
d = sys.argv[1]
def pfm(path):
    with open(path, 'rb') as f:
        assert f.readline().strip() == b'PF'
        w, h = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        v = struct.unpack(('<' if scale < 0 else '>') + '%df' % (3 * w * h), f.read(12 * w * h))
    return w, h, v
def bands(name):
    w, h, a = pfm('%s/%s-1.pfm' % (d, name))
    _, _, b = pfm('%s/%s-2.pfm' % (d, name))
    out = []
    for k in range(5):
        s = [(sum(a[3 * (y * w + x):3 * (y * w + x) + 3]) / 3, sum(b[3 * (y * w + x):3 * (y * w + x) + 3]) / 3)
             for y in range(h) for x in range(k * w // 5, (k + 1) * w // 5)]
        n = len(s)
        dm = sum(p - q for p, q in s) / n
        var = sum((p - q - dm) ** 2 for p, q in s) / (n - 1)
        out.append((sum(p + q for p, q in s) / (2 * n), var / 2 / (2 * n)))
    return out
obj, pb, js = bands('tex'), bands('pbrt'), bands('json')
bad = 0
for k in range(5):
    o, p, j = obj[4 - k], pb[k], js[4 - k]
    z = abs(o[0] - p[0]) / math.sqrt(o[1] + p[1])
    zj = abs(o[0] - j[0]) / math.sqrt(o[1] + j[1])
    print('pbrt band %d: %.5f  json %.5f  obj band %d: %.5f  (%.1f sd, %.1f sd)' % (k, p[0], j[0], 4 - k, o[0], z, zj))
    if not (z < 4 and zj < 4): bad = 1
sys.exit(bad)
PY
[ $? = 0 ] && echo "ok   pbrt-v4 AreaLightSource filename and JSON radiance textures" || { echo "FAIL pbrt-v4 / JSON emission maps"; fail=1; }
exit $fail
