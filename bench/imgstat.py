#!/usr/bin/python3
"""Error measures of rendered images (PFM), for bench/denoise.sh,
bench/noise2.sh and bench/adaptive.sh.

  imgstat.py relmse IMAGE REFERENCE
      relMSE = mean over pixels and channels of (x - r)^2 / (r^2 + 0.01)
  imgstat.py noise2 A B [x0 x1 y0 y1]
      two renders of the same scene with different seeds: the relative
      noise of one render in the patch (fractions of the image, y from the
      top; default the Cornell box's back wall, x 0.55-0.70, y 0.28-0.55):
      sqrt(mean((a - b)^2) / 2) / mean((a + b) / 2) on luminance. Unlike
      neighbour differences it stays right for filtered (denoised) images.
  imgstat.py twoseed A B
      the relative error of one render over the whole image, from two
      renders with different seeds: sqrt(mean((a - b)^2 / 2 / (m^2 + 0.01)))
      over pixels and channels, m = (a + b) / 2 (what --noise aims at)
  imgstat.py tiles95 A B
      the same per 16x16 tile (the tiles of --noise): its 95th percentile
      over the tiles, the error of the worst parts of the image
"""
import struct
import sys

import numpy as np


def read_pfm(path):
    with open(path, 'rb') as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        ch = 3 if kind == b'PF' else 1
        data = np.frombuffer(f.read(), dtype='<f4' if scale < 0 else '>f4', count=w * h * ch)
    return data.reshape(h, w, ch)[::-1].astype(np.float64)  # rows top to bottom


def lum(img):
    return 0.2126 * img[..., 0] + 0.7152 * img[..., 1] + 0.0722 * img[..., 2]


def relmse(x, r):
    return float(np.mean((x - r) ** 2 / (r ** 2 + 0.01)))


def noise2(a, b, box):
    h, w = a.shape[:2]
    x0, x1, y0, y1 = box
    sl = (slice(int(y0 * h), int(y1 * h)), slice(int(x0 * w), int(x1 * w)))
    la, lb = lum(a)[sl], lum(b)[sl]
    return float(np.sqrt(np.mean((la - lb) ** 2) / 2) / np.mean((la + lb) / 2))


def twoseed(a, b):
    m = (a + b) / 2
    return float(np.sqrt(np.mean((a - b) ** 2 / 2 / (m ** 2 + 0.01))))


def tiles95(a, b):
    m = (a + b) / 2
    rv = np.mean((a - b) ** 2 / 2 / (m ** 2 + 0.01), axis=2)
    h, w = rv.shape
    t = [np.sqrt(rv[y:y + 16, x:x + 16].mean()) for y in range(0, h, 16) for x in range(0, w, 16)]
    return float(np.percentile(t, 95))


def main():
    cmd = sys.argv[1]
    if cmd == 'relmse':
        print('%.6g' % relmse(read_pfm(sys.argv[2]), read_pfm(sys.argv[3])))
    elif cmd == 'noise2':
        box = [float(v) for v in sys.argv[4:8]] if len(sys.argv) >= 8 else [0.55, 0.70, 0.28, 0.55]
        print('%.6g' % noise2(read_pfm(sys.argv[2]), read_pfm(sys.argv[3]), box))
    elif cmd == 'twoseed':
        print('%.6g' % twoseed(read_pfm(sys.argv[2]), read_pfm(sys.argv[3])))
    elif cmd == 'tiles95':
        print('%.6g' % tiles95(read_pfm(sys.argv[2]), read_pfm(sys.argv[3])))
    else:
        sys.exit(__doc__)


if __name__ == '__main__':
    main()
