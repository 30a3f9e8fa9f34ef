#!/usr/bin/env bash
# A pbrt-v4 scene of N instances (default 100000) of one 1,280-triangle
# sphere mesh (ObjectBegin / ObjectInstance), scattered with random
# rotations, scales and some mirrors over a ground plane, under a sky and a
# sun; 128 M triangles if flattened. Writes the scene and, given a program,
# renders it at 320x180 with --stats under /usr/bin/time -v (peak memory).
# usage: bench/instances.sh OUT.pbrt [N [PAPRSEK [more render options]]]
set -euo pipefail
out=${1:?usage: bench/instances.sh OUT.pbrt [N [PAPRSEK [options]]]}
n=${2:-100000}
bin=${3:-}
shift 3 2>/dev/null || shift $# || true
/usr/bin/python3 - "$out" "$n" <<'EOF_PY'
import math, random, sys
out, n = sys.argv[1], int(sys.argv[2])
r = random.Random(1)
S, T = 32, 21  # slices, stacks: 2 S (T - 1) = 1280 triangles
pts, nrm, idx = [], [], []
pts.append((0, 1, 0))
for j in range(1, T):
    th = math.pi * j / T
    for i in range(S):
        ph = 2 * math.pi * i / S
        pts.append((math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)))
pts.append((0, -1, 0))
last = len(pts) - 1
ring = lambda j, i: 1 + (j - 1) * S + i % S
for i in range(S):
    idx += [0, ring(1, i + 1), ring(1, i)]
    idx += [last, ring(T - 1, i), ring(T - 1, i + 1)]
for j in range(1, T - 1):
    for i in range(S):
        a, b, c, d = ring(j, i), ring(j, i + 1), ring(j + 1, i), ring(j + 1, i + 1)
        idx += [a, b, d, a, d, c]
assert len(idx) == 3 * 1280
side = math.sqrt(n) * 2.5
with open(out, "w") as f:
    f.write(f'LookAt 0 6 {-side / 2 - 4:.3f}  0 0 {-side / 2 + 40:.3f}  0 1 0\n')
    f.write('Camera "perspective" "float fov" 45\n')
    f.write('Film "rgb" "integer xresolution" 320 "integer yresolution" 180 "string filename" "instances.png"\n')
    f.write('Sampler "independent" "integer pixelsamples" 4\n')
    f.write('WorldBegin\n')
    f.write('LightSource "infinite" "rgb L" [0.4 0.45 0.5]\n')
    f.write('LightSource "distant" "point3 from" [1 3 -2] "point3 to" [0 0 0] "rgb L" [3 3 3]\n')
    f.write('ObjectBegin "ball"\nMaterial "diffuse" "rgb reflectance" [0.7 0.3 0.2]\n')
    f.write('Shape "trianglemesh" "point3 P" [' + " ".join(f"{c:.6f}" for p in pts for c in p) + ']\n')
    f.write('  "normal N" [' + " ".join(f"{c:.6f}" for p in pts for c in p) + ']\n')
    f.write('  "integer indices" [' + " ".join(map(str, idx)) + ']\nObjectEnd\n')
    for k in range(n):
        x, z = r.uniform(-side / 2, side / 2), r.uniform(-side / 2, side / 2)
        s = r.uniform(0.4, 1.1)
        mirror = "Scale -1 1 1 " if k % 7 == 0 else ""
        f.write(f'AttributeBegin Translate {x:.4f} {s:.4f} {z:.4f} Rotate {r.uniform(0, 360):.2f} '
                f'{r.uniform(-1, 1):.3f} 1 {r.uniform(-1, 1):.3f} Scale {s:.4f} {s * r.uniform(0.6, 1.4):.4f} {s:.4f} '
                f'{mirror}ObjectInstance "ball" AttributeEnd\n')
    h = side
    f.write('Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]\n')
    f.write(f'Shape "trianglemesh" "point3 P" [{-h} 0 {-h} {h} 0 {-h} {h} 0 {h} {-h} 0 {h}] "integer indices" [0 2 1 0 3 2]\n')
EOF_PY
echo "wrote $out ($n instances of a 1,280-triangle mesh: $((n * 1280)) triangles if flattened)"
if [ -n "$bin" ]; then
  /usr/bin/time -v "$bin" render "$out" -o "${out%.pbrt}.png" --stats "$@" 2>&1 |
    grep -E '^(build|render \[s\]|memory|settings|scene)|Maximum resident|Elapsed \(wall'
fi
