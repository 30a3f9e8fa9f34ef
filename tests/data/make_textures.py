#!/usr/bin/env python3
"""make_textures.py - writes the small texture images of the tests and the
fuzz seeds (PNG with zlib, PFM and Radiance HDR by hand), so that every
image in tests/ can be made again: python3 tests/data/make_textures.py"""
import math
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
SEEDS = os.path.join(HERE, "..", "fuzz", "corpus", "image")


def png(path, w, h, channels, pixels):
    """pixels: rows (top first) of w tuples of `channels` bytes."""
    colour = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    raw = b"".join(b"\0" + bytes(v for px in row for v in px) for row in pixels)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", w, h, 8, colour, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def pfm(path, w, h, rgb):
    """rgb: rows top first of w (r, g, b) floats; written bottom first, little-endian."""
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        for row in reversed(rgb):
            for px in row:
                f.write(struct.pack("<3f", *px))


def hdr_flat(path, w, h, rgbe):
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w))
        for row in rgbe:
            for px in row:
                f.write(bytes(px))


def hdr_rle(path, w, h, rgbe):
    """Adaptive run-length encoding (w >= 8): each channel a run or literals."""
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w))
        for row in rgbe:
            f.write(bytes([2, 2, w >> 8, w & 255]))
            for c in range(4):
                vals = [px[c] for px in row]
                i = 0
                while i < w:
                    run = 1
                    while i + run < w and run < 127 and vals[i + run] == vals[i]:
                        run += 1
                    if run >= 3:
                        f.write(bytes([128 + run, vals[i]]))
                        i += run
                    else:
                        n = min(128, w - i)
                        f.write(bytes([n]) + bytes(vals[i:i + n]))
                        i += n


def main():
    # 2x2 sRGB: red, green / blue, white (linear mean 0.5 per channel)
    png(os.path.join(HERE, "tex_rgbw.png"), 2, 2, 3, [[(255, 0, 0), (0, 255, 0)], [(0, 0, 255), (255, 255, 255)]])
    # 2x2 white (a lossless textured albedo in the furnace tests)
    png(os.path.join(HERE, "tex_white.png"), 2, 2, 3, [[(255, 255, 255)] * 2] * 2)
    # 64x64 checker of 8x8 blocks
    png(os.path.join(HERE, "tex_checker.png"), 64, 64, 3,
        [[(230, 200, 60) if (x // 8 + y // 8) % 2 else (40, 60, 150) for x in range(64)] for y in range(64)])
    # 32x32 RGBA: round holes (alpha 0) in a green sheet
    holes = []
    for y in range(32):
        row = []
        for x in range(32):
            dx, dy = (x % 16) - 7.5, (y % 16) - 7.5
            row.append((40, 170, 60, 0 if dx * dx + dy * dy < 30 else 255))
        holes.append(row)
    png(os.path.join(HERE, "tex_holes.png"), 32, 32, 4, holes)
    # 64x64 grey heights: rings
    png(os.path.join(HERE, "tex_bump.png"), 64, 64, 1,
        [[(int(127.5 + 127.5 * math.sin(math.hypot(x - 32, y - 32) * 0.6)),) for x in range(64)] for y in range(64)])
    # 16x16 tangent-space normal map: a pyramid
    nm = []
    for y in range(16):
        row = []
        for x in range(16):
            dx, dy = x - 7.5, 7.5 - y
            n = (0.5 if abs(dx) > abs(dy) else 0.0) * (1 if dx > 0 else -1), (0.5 if abs(dy) >= abs(dx) else 0.0) * (1 if dy > 0 else -1), 1.0
            l = math.sqrt(sum(c * c for c in n))
            row.append(tuple(int(round((c / l * 0.5 + 0.5) * 255)) for c in n))
        nm.append(row)
    png(os.path.join(HERE, "tex_normal.png"), 16, 16, 3, nm)
    # the fuzz seeds: one of each format
    os.makedirs(SEEDS, exist_ok=True)
    png(os.path.join(SEEDS, "seed_grey.png"), 3, 2, 1, [[(0,), (128,), (255,)], [(9,), (99,), (199,)]])
    png(os.path.join(SEEDS, "seed_ga.png"), 2, 2, 2, [[(0, 0), (50, 255)], [(100, 128), (255, 255)]])
    png(os.path.join(SEEDS, "seed_rgba.png"), 4, 1, 4, [[(1, 2, 3, 4), (50, 60, 70, 0), (255, 0, 0, 255), (9, 9, 9, 9)]])
    pfm(os.path.join(SEEDS, "seed.pfm"), 3, 2, [[(0.5, 1.0, 2.0), (0, 0, 0), (1e3, -1, 0.25)], [(1, 1, 1), (2, 2, 2), (3, 3, 3)]])
    hdr_flat(os.path.join(SEEDS, "seed_flat.hdr"), 3, 2, [[(128, 64, 32, 129), (10, 20, 30, 128), (1, 1, 1, 2)],
                                                          [(0, 0, 0, 0), (255, 255, 255, 130), (1, 2, 3, 127)]])
    hdr_rle(os.path.join(SEEDS, "seed_rle.hdr"), 10, 2, [[(50, i, 7, 128) for i in range(10)], [(i * 20, 3, 3, 129) for i in range(10)]])


if __name__ == "__main__":
    main()
