#!/usr/bin/python3
"""imgcheck.py REFERENCE.pfm OTHER...: each OTHER (.pfm, .exr, .png) holds the
reference's pixels: PFM and EXR bit for bit, PNG as the reference's sRGB
encoding (within one code: the program rounds in float, this in double);
every value of every file finite. Exit 1 with one line per difference.

The files are decoded here from the formats' published descriptions (the
Portable FloatMap, OpenEXR's file layout for scanline files of FLOAT
channels with NONE, ZIPS or ZIP compression, PNG's 8-bit RGB with its five
row filters), with the standard library only, so that a writer's mistake is
not hidden by a reader that shares its code."""
import math
import struct
import sys
import zlib


def read_pfm(path):
    with open(path, 'rb') as f:
        kind = f.readline().strip()
        w, h = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        data = f.read()
    if kind != b'PF':
        raise ValueError('%s: not an RGB PFM' % path)
    fmt = '<' if scale < 0 else '>'
    vals = struct.unpack(fmt + '%df' % (3 * w * h), data[:12 * w * h])
    rows = [vals[(h - 1 - y) * 3 * w:(h - y) * 3 * w] for y in range(h)]  # bottom row first
    return w, h, [list(r) for r in rows]


def read_exr(path):
    b = open(path, 'rb').read()
    if b[:4] != b'\x76\x2f\x31\x01':
        raise ValueError('%s: not OpenEXR' % path)
    if struct.unpack_from('<I', b, 4)[0] & 0x200:
        raise ValueError('%s: tiled files are not read here' % path)
    p, attrs = 8, {}
    while b[p] != 0:
        e = b.index(b'\0', p)
        name = b[p:e].decode()
        p = e + 1
        e = b.index(b'\0', p)
        p = e + 1
        n = struct.unpack_from('<i', b, p)[0]
        attrs[name] = b[p + 4:p + 4 + n]
        p += 4 + n
    p += 1
    chans, q, cl = [], 0, attrs['channels']
    while cl[q] != 0:
        e = cl.index(b'\0', q)
        chans.append((cl[q:e].decode(), struct.unpack_from('<i', cl, e + 1)[0]))
        q = e + 1 + 16
    x0, y0, x1, y1 = struct.unpack('<4i', attrs['dataWindow'])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    lines = {0: 1, 2: 1, 3: 16}[attrs['compression'][0]]
    offsets = struct.unpack_from('<%dQ' % ((h + lines - 1) // lines), b, p)
    planes = {c: [None] * h for c, _ in chans}
    for off in offsets:
        y, n = struct.unpack_from('<2i', b, off)
        data = b[off + 8:off + 8 + n]
        rows = min(lines, h - (y - y0))
        raw = rows * w * 4 * len(chans)
        if n < raw:  # compressed: zlib, then the predictor and the interleave undone
            t = bytearray(zlib.decompress(data))
            for i in range(1, len(t)):
                t[i] = (t[i - 1] + t[i] - 128) & 255
            half = (len(t) + 1) // 2
            d = bytearray(len(t))
            d[0::2], d[1::2] = t[:half], t[half:]
            data = bytes(d)
        elif n != raw:
            raise ValueError('%s: chunk at line %d holds %d bytes, more than raw' % (path, y, n))
        k = 0
        for r in range(rows):
            for c, kind in chans:
                if kind != 2:
                    raise ValueError('%s: channel %s is not FLOAT' % (path, c))
                planes[c][y - y0 + r] = struct.unpack_from('<%df' % w, data, k)
                k += 4 * w
    rows = []
    for y in range(h):
        row = []
        for x in range(w):
            row += [planes['R'][y][x], planes['G'][y][x], planes['B'][y][x]]
        rows.append(row)
    return w, h, rows


def read_png(path):
    b = open(path, 'rb').read()
    if b[:8] != b'\x89PNG\r\n\x1a\n':
        raise ValueError('%s: not PNG' % path)
    p, idat = 8, b''
    while p < len(b):
        n, kind = struct.unpack_from('>I4s', b, p)
        body = b[p + 8:p + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype, _, _, interlace = struct.unpack('>2I5B', body)
            if (depth, ctype, interlace) != (8, 2, 0):
                raise ValueError('%s: not 8-bit RGB' % path)
        elif kind == b'IDAT':
            idat += body
        p += 12 + n
    raw, stride, prev, rows = zlib.decompress(idat), 3 * w, bytearray(3 * w), []
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - 3] if i >= 3 else 0
            c = prev[i - 3] if i >= 3 else 0
            up = prev[i]
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + up) & 255
            elif f == 3:
                line[i] = (line[i] + (a + up) // 2) & 255
            elif f == 4:
                pa, pb, pc = abs(up - c), abs(a - c), abs(a + up - 2 * c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else up if pb <= pc else c)) & 255
        rows.append(list(line))
        prev = line
    return w, h, rows


def srgb(v):
    if not v > 0:
        return 0
    if v >= 1:
        return 255
    s = 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
    return int(s * 255 + 0.5)


def bits(v):
    return struct.pack('<f', v)


def main():
    ref_path, others = sys.argv[1], sys.argv[2:]
    w, h, ref = read_pfm(ref_path)
    bad = []
    if not all(math.isfinite(v) for row in ref for v in row):
        bad.append('%s: a value that is not finite' % ref_path)
    for path in others:
        reader = {'pfm': read_pfm, 'exr': read_exr, 'png': read_png}[path.rsplit('.', 1)[-1].lower()]
        ow, oh, img = reader(path)
        if (ow, oh) != (w, h):
            bad.append('%s: %dx%d, the reference %dx%d' % (path, ow, oh, w, h))
            continue
        if reader is read_png:
            diff = [(y, i) for y in range(h) for i in range(3 * w) if abs(img[y][i] - srgb(ref[y][i])) > 1]
        else:
            if not all(math.isfinite(v) for row in img for v in row):
                bad.append('%s: a value that is not finite' % path)
            diff = [(y, i) for y in range(h) for i in range(3 * w) if bits(img[y][i]) != bits(ref[y][i])]
        if diff:
            rows = sorted({y for y, _ in diff})
            bad.append('%s: %d values differ from %s (rows %d..%d)' % (path, len(diff), ref_path, rows[0], rows[-1]))
    for line in bad:
        print(line)
    sys.exit(1 if bad else 0)


if __name__ == '__main__':
    main()
