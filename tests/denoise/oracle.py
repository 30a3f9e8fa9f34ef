#!/usr/bin/python3
"""An independent NumPy implementation of the denoiser (Open Image Denoise's
U-Net, its input and output transforms and the tiling), in float64, checked
against what denoise_dump wrote: every layer, the network's output, and the
whole pipeline tiled and untiled. Written from OIDN's published model
description (training/model.py, color.py) and the tza format, not from the
C code.   usage: oracle.py WEIGHTS.tza DUMPDIR"""
import struct
import sys

import numpy as np

TOL = 1e-4  # relative to the largest magnitude of the reference tensor


def read_tza(path):
    data = open(path, 'rb').read()
    magic, major, _minor, table = struct.unpack_from('<HBBQ', data, 0)
    assert magic == 0x41D7 and major == 2, 'not a tza v2 file'
    (count,) = struct.unpack_from('<I', data, table)
    p = table + 4
    tensors = {}
    for _ in range(count):
        (n,) = struct.unpack_from('<H', data, p)
        p += 2
        name = data[p:p + n].decode()
        p += n
        nd = data[p]
        p += 1
        shape = struct.unpack_from('<%dI' % nd, data, p)
        p += 4 * nd
        p += nd  # layout
        dtype = {'h': np.float16, 'f': np.float32}[chr(data[p])]
        p += 1
        (off,) = struct.unpack_from('<Q', data, p)
        p += 8
        count_el = int(np.prod(shape))
        tensors[name] = np.frombuffer(data, dtype=dtype, count=count_el, offset=off).reshape(shape).astype(np.float64)
    return tensors


def conv(x, w, b, relu):
    c, h, wd = x.shape
    xp = np.zeros((c, h + 2, wd + 2))
    xp[:, 1:-1, 1:-1] = x
    out = np.zeros((w.shape[0], h, wd))
    for ky in range(3):
        for kx in range(3):
            out += np.tensordot(w[:, :, ky, kx], xp[:, ky:ky + h, kx:kx + wd], axes=(1, 0))
    out += b[:, None, None]
    return np.maximum(out, 0.0) if relu else out


def pool(x):
    c, h, w = x.shape
    return x.reshape(c, h // 2, 2, w // 2, 2).max(axis=(2, 4))


def up(x):
    return x.repeat(2, axis=1).repeat(2, axis=2)


def unet(t, x, layers=None):
    def cv(name, v, relu=True):
        r = conv(v, t[name + '.weight'], t[name + '.bias'], relu)
        if layers is not None:
            layers[name] = r
        return r
    inp = x
    x = cv('enc_conv0', x)
    x = p1 = pool(cv('enc_conv1', x))
    x = p2 = pool(cv('enc_conv2', x))
    x = p3 = pool(cv('enc_conv3', x))
    x = pool(cv('enc_conv4', x))
    x = cv('enc_conv5b', cv('enc_conv5a', x))
    x = cv('dec_conv4b', cv('dec_conv4a', np.concatenate([up(x), p3])))
    x = cv('dec_conv3b', cv('dec_conv3a', np.concatenate([up(x), p2])))
    x = cv('dec_conv2b', cv('dec_conv2a', np.concatenate([up(x), p1])))
    x = cv('dec_conv1b', cv('dec_conv1a', np.concatenate([up(x), inp])))
    return cv('dec_conv0', x, relu=False)


# OIDN's PU transfer curve (color.py)
PU = dict(a=1.41283765e+03, b=1.64593172e+00, c=4.31384981e-01, d=-2.94139609e-03, e=1.92653254e-01,
          f=6.26026094e-03, g=9.98620152e-01, y0=1.57945760e-06, y1=3.22087631e-02, x0=2.23151711e-03,
          x1=3.70974749e-01)


def pu_fwd(y):
    with np.errstate(all='ignore'):
        return np.where(y <= PU['y0'], PU['a'] * y,
                        np.where(y <= PU['y1'], PU['b'] * np.power(np.maximum(y, 0), PU['c']) + PU['d'],
                                 PU['e'] * np.log(y + PU['f']) + PU['g']))


def pu_inv(x):
    with np.errstate(all='ignore'):
        return np.where(x <= PU['x0'], x / PU['a'],
                        np.where(x <= PU['x1'], np.power(np.maximum((x - PU['d']) / PU['b'], 0), 1 / PU['c']),
                                 np.exp((x - PU['g']) / PU['e']) - PU['f']))


NORM = 1.0 / pu_fwd(np.float64(65504.0))


def clean(v, lo, hi):
    v = np.where(np.isfinite(v), v, 0.0)
    return np.clip(v, lo, hi)


def autoexposure(rgb):
    h, w, _ = rgb.shape
    c = clean(rgb.astype(np.float64), 0, np.finfo(np.float32).max)
    lum = 0.212671 * c[..., 0] + 0.715160 * c[..., 1] + 0.072169 * c[..., 2]
    bh, bw = -(-h // 16), -(-w // 16)
    logs = []
    for i in range(bh):
        for j in range(bw):
            blk = lum[i * h // bh:(i + 1) * h // bh, j * w // bw:(j + 1) * w // bw]
            m = blk.mean()
            if m > 1e-8:
                logs.append(np.log2(m))
    return 0.18 / np.exp2(np.mean(logs)) if logs else 1.0


def spans(n, t, ov):
    if n <= t:
        return [(0, n, 0, n)]
    out, k, prev = [], 0, 0
    while True:
        s = k * (t - 2 * ov)
        last = s + t >= n
        if last:
            s = n - t
        e = n if last else s + t - ov
        out.append((s, t, prev, e))
        prev = e
        if last:
            return out
        k += 1


def pipeline(t, color, alb, nrm, scale, tile, ov):
    h, w, _ = color.shape
    out = np.zeros_like(color, dtype=np.float64)
    c = clean(color.astype(np.float64) * np.float32(scale), 0, np.finfo(np.float32).max)
    feats = [pu_fwd(c) * NORM, clean(alb.astype(np.float64), 0, 1), clean(nrm.astype(np.float64), -1, 1) * 0.5 + 0.5]
    img = np.concatenate(feats, axis=2)[..., :t['enc_conv0.weight'].shape[1]]
    for (ys, ysz, yo0, yo1) in spans(h, tile, ov):
        for (xs, xsz, xo0, xo1) in spans(w, tile, ov):
            ph, pw = -(-ysz // 16) * 16, -(-xsz // 16) * 16
            x = np.zeros((img.shape[2], ph, pw))
            x[:, :ysz, :xsz] = img[ys:ys + ysz, xs:xs + xsz].transpose(2, 0, 1)
            y = unet(t, x)
            y = pu_inv(clean(y, 0, np.inf) / NORM) / np.float32(scale)
            out[yo0:yo1, xo0:xo1] = np.maximum(y[:, yo0 - ys:yo1 - ys, xo0 - xs:xo1 - xs].transpose(1, 2, 0), 0)
    return out


def compare(what, got, ref):
    err = np.abs(got - ref).max() / max(np.abs(ref).max(), 1e-30)
    ok = err <= TOL and np.all(np.isfinite(got))
    print('%-22s max |C - NumPy| / max |NumPy| = %.2e %s' % (what, err, 'ok' if ok else 'FAIL'))
    return ok


def main():
    weights, d = sys.argv[1], sys.argv[2]
    t = read_tza(weights)

    def load(name, shape):
        return np.fromfile('%s/%s.bin' % (d, name), dtype=np.float32).reshape(shape).astype(np.float64)
    ic = t['enc_conv0.weight'].shape[1]
    H, W = 48, 32
    x = load('net_in', (ic, H, W))
    layers = {}
    ref = unet(t, x, layers)
    ok = True
    for name, r in layers.items():
        ok &= compare(name, load('layer_' + name, r.shape), r)
    ok &= compare('network output', load('net_out', (3, H, W)), ref)

    IH, IW = 110, 150
    color, alb, nrm = (np.fromfile('%s/img_%s.bin' % (d, k), dtype=np.float32).reshape(IH, IW, 3)
                       for k in ('color', 'albedo', 'normal'))
    scale = autoexposure(color)
    c_scale = float(np.fromfile('%s/img_scale.bin' % d, dtype=np.float32)[0])
    ok &= compare('exposure', np.array([c_scale]), np.array([scale]))
    for name, tile, ov in (('img_tiled', 64, 16), ('img_whole', 1024, 96)):
        ok &= compare(name, load(name, (IH, IW, 3)), pipeline(t, color, alb, nrm, c_scale, tile, ov))
    sys.exit(0 if ok else 1)


if __name__ == '__main__':
    main()
