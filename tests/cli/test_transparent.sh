#!/usr/bin/env bash
# --transparent, --tonemap and --camera-orbit from the command line:
#   - a sphere against a bright constant environment: the PNG is RGBA, alpha
#     255 inside the sphere, 0 outside, fractional at the edge; where alpha is
#     255 the colour is byte for byte that of the render without
#     --transparent (the environment still lights the sphere);
#   - the .exr has a channel A; a .pfm with --transparent is a usage error;
#   - --tonemap: each curve writes, an unknown one is a usage error, an HDR
#     output is warned about; --camera-orbit: a bad value is a usage error,
#     an orbit at the same place as --look-from renders the same bytes.
# usage: test_transparent.sh PAPRSEK [SHARED_DIR DATA_DIR]
set -u
bin=$1
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL $*"; fail=1; }
ok() { echo "ok   $*"; }

printf '%s\n' '{"spheres":[{"center":[0,0,0],"radius":1,"material":"m"}],"materials":{"m":{"kd":[0.5,0.5,0.5]}},' \
  '"camera":{"look_from":[0,0,4],"look_at":[0,0,0],"fov":45}}' >"$tmp/s.json"
common=(--width 32 --height 32 --spp 16 --env 2 --quiet)
"$bin" render "$tmp/s.json" -o "$tmp/a.png" "${common[@]}" || bad "render without --transparent"
"$bin" render "$tmp/s.json" -o "$tmp/t.png" "${common[@]}" --transparent || bad "render --transparent (png)"
"$bin" render "$tmp/s.json" -o "$tmp/t.exr" "${common[@]}" --transparent || bad "render --transparent (exr)"

# the PNGs decoded here (8-bit RGB or RGBA, the five row filters), standard library only
python3 - "$tmp/a.png" "$tmp/t.png" "$tmp/t.exr" <<'PY' || fail=1
import struct, sys, zlib
def png(path):
    d = open(path, 'rb').read()
    assert d[:8] == b'\x89PNG\r\n\x1a\n'
    pos, idat = 8, b''
    while pos < len(d):
        n, = struct.unpack('>I', d[pos:pos + 4]); t = d[pos + 4:pos + 8]; c = d[pos + 8:pos + 8 + n]
        if t == b'IHDR': w, h, depth, ct = struct.unpack('>IIBB', c[:10])
        if t == b'IDAT': idat += c
        pos += 12 + n
    bpp = {2: 3, 6: 4}[ct]
    raw, rows, prev = zlib.decompress(idat), [], bytearray(w * bpp)
    for y in range(h):
        f = raw[y * (w * bpp + 1)]; line = bytearray(raw[y * (w * bpp + 1) + 1:(y + 1) * (w * bpp + 1)])
        for i in range(len(line)):
            a = line[i - bpp] if i >= bpp else 0; b = prev[i]; c = prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line); prev = line
    return w, h, ct, rows
w, h, ct_a, A = png(sys.argv[1])
w2, h2, ct_t, T = png(sys.argv[2])
bad = []
if ct_a != 2: bad.append('plain render is not RGB (colour type %d)' % ct_a)
if ct_t != 6: bad.append('--transparent PNG is not RGBA (colour type %d)' % ct_t)
alpha = [[T[y][4 * x + 3] for x in range(w)] for y in range(h)]
if alpha[h // 2][w // 2] != 255: bad.append('centre alpha %d' % alpha[h // 2][w // 2])
if alpha[0][0] != 0 or alpha[h - 1][w - 1] != 0: bad.append('corner alpha %d %d' % (alpha[0][0], alpha[h - 1][w - 1]))
frac = sum(1 for r in alpha for a in r if 0 < a < 255)
full = sum(1 for r in alpha for a in r if a == 255)
if frac < 8: bad.append('only %d fractional edge pixels' % frac)
same = sum(1 for y in range(h) for x in range(w) if alpha[y][x] == 255 and T[y][4 * x:4 * x + 3] == A[y][3 * x:3 * x + 3])
if same != full: bad.append('%d of %d covered pixels differ from the render without --transparent' % (full - same, full))
if A[0][0:3] == bytearray(3): bad.append('the plain render does not show the environment')
exr = open(sys.argv[3], 'rb').read(4096)
i = exr.find(b'channels\x00chlist\x00')
names = []
if i >= 0:
    p = i + len(b'channels\x00chlist\x00') + 4
    while exr[p] != 0:
        e = exr.index(b'\x00', p); names.append(exr[p:e].decode()); p = e + 1 + 16
if names != ['A', 'B', 'G', 'R']: bad.append('EXR channels %s' % names)
for b in bad: print('FAIL', b)
print('ok   alpha: %d covered, %d fractional, %d covered pixels as without --transparent; EXR channels %s' % (full, frac, same, names))
sys.exit(1 if bad else 0)
PY

# usage errors (exit 2) and warnings
expect2() {
  local name=$1; shift
  "$@" >"$tmp/out" 2>"$tmp/err"; local rc=$?
  if [ $rc -eq 2 ] && [ -s "$tmp/err" ]; then ok "$name: $(head -1 "$tmp/err")"; else bad "$name: exit $rc: $(cat "$tmp/err")"; fi
}
expect2 "--transparent with .pfm" "$bin" render "$tmp/s.json" -o "$tmp/t.pfm" --transparent
expect2 "--tonemap unknown" "$bin" render "$tmp/s.json" -o "$tmp/x.png" --tonemap filmic
expect2 "--camera-orbit bad" "$bin" render "$tmp/s.json" -o "$tmp/x.png" --camera-orbit 0,90
expect2 "--camera-orbit radius 0" "$bin" render "$tmp/s.json" -o "$tmp/x.png" --camera-orbit 0,90,0
[ ! -e "$tmp/t.pfm" ] && [ ! -e "$tmp/x.png" ] || bad "a refused render left a file"
"$bin" render "$tmp/s.json" -o "$tmp/w.exr" --width 32 --height 32 --spp 4 --env 2 --tonemap aces 2>"$tmp/err" >/dev/null
grep -q -- '--tonemap applies to PNG only' "$tmp/err" && ok "--tonemap with .exr warns" || bad "no --tonemap warning: $(cat "$tmp/err")"
for c in clamp agx pbr-neutral aces; do
  "$bin" render "$tmp/s.json" -o "$tmp/c-$c.png" "${common[@]}" --tonemap $c || bad "--tonemap $c"
done
cmp -s "$tmp/c-clamp.png" "$tmp/a.png" && ok "--tonemap clamp is the default's bytes" || bad "--tonemap clamp differs from the default"
for c in agx pbr-neutral aces; do
  cmp -s "$tmp/c-$c.png" "$tmp/a.png" && bad "--tonemap $c changes nothing" || ok "--tonemap $c differs from clamp"
done
# theta 0, phi 90, radius 4 about the centre (0,0,0) is look_from (0,0,4)
"$bin" render "$tmp/s.json" -o "$tmp/o.png" "${common[@]}" --camera-orbit 0,90,4 || bad "--camera-orbit"
cmp -s "$tmp/o.png" "$tmp/a.png" && ok "--camera-orbit 0,90,4 is the scene's camera" || bad "--camera-orbit 0,90,4 differs"
"$bin" render "$tmp/s.json" -o "$tmp/o2.png" "${common[@]}" --camera-orbit 30,60,auto || bad "--camera-orbit auto"
exit $fail
