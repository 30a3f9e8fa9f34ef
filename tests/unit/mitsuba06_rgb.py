#!/usr/bin/env python3
# mitsuba06_rgb.py - the numbers test_spectra.c checks spectra_mitsuba06_rgb
# against, computed here independently (NumPy, double): Mitsuba 0.5/0.6's
# RGB-mode Spectrum::fromContinuousSpectrum of a <spectrum value="l:v, ...">
# (scenehandler.cpp: InterpolatedSpectrum, zeroExtend, fromContinuousSpectrum):
#   X = average over 360..830 nm of s.eval(l) * CIE_X_interp.eval(l), same for Y, Z
#   divided by CIE_Y_interp.average(360, 830) (trapezoids), Rec. 709 matrix,
#   negatives clamped,
# where eval is InterpolatedSpectrum::eval as released (0.5.0, 0.6.0): between
# samples a and b it returns lerp(t, f_b, f_a), the segment mirrored (fixed
# upstream on 2020-01-31, commit cfeb776). Mitsuba integrates the product by
# adaptive Gauss-Lobatto (rel. 1e-4); here exactly: on each piece between
# whole nanometres and samples the product is quadratic, Simpson is exact.
# usage: mitsuba06_rgb.py [path to src/scene/cie1931.inc]
import os, re, sys
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
inc = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, '..', '..', 'src', 'scene', 'cie1931.inc')
text = open(inc).read().split('cie1931_xyz[471][3] = {')[1].split('};')[0]
T = np.array([float(v.rstrip('f')) for v in re.findall(r'[-+]?[0-9.]+(?:e[-+]?[0-9]+)?f?', re.sub(r'/\*.*?\*/', '', text))]).reshape(471, 3)
W = np.arange(360.0, 831.0)
M = np.array([[3.240479, -1.537150, -0.498535], [-0.969256, 1.875991, 0.041556], [0.055648, -0.204043, 1.057311]])

def seg(x, f, l, mirrored):
    """the table (x, f) on the segment containing the open piece around l"""
    if l < x[0] or l > x[-1]:
        return 0.0
    i = np.searchsorted(x, l) - 1
    t = (l - x[i]) / (x[i + 1] - x[i])
    return (1 - t) * f[i + 1] + t * f[i] if mirrored else (1 - t) * f[i] + t * f[i + 1]

def rgb(nm, val, mirrored=True):
    x, f = list(map(float, nm)), list(map(float, val))
    sp = (x[-1] - x[0]) / (len(x) - 1)
    if f[0] != 0: x, f = [x[0] - sp] + x, [0.0] + f
    if f[-1] != 0: x, f = x + [x[-1] + sp], f + [0.0]
    x, f = np.array(x), np.array(f)
    cuts = sorted(set(W) | {v for v in x if 360 < v < 830})
    acc = np.zeros(3)
    for a, b in zip(cuts[:-1], cuts[1:]):
        m = 0.5 * (a + b)
        # each factor's segment is fixed by the piece's midpoint; evaluate its formula at a, m, b
        def at(l):
            i = int(np.floor(m)) - 360
            t = l - W[i]
            c = (1 - t) * T[i + 1] + t * T[i] if mirrored else (1 - t) * T[i] + t * T[i + 1]
            j = np.searchsorted(x, m) - 1
            if m < x[0] or m > x[-1]:
                return np.zeros(3)
            u = (l - x[j]) / (x[j + 1] - x[j])
            s = (1 - u) * f[j + 1] + u * f[j] if mirrored else (1 - u) * f[j] + u * f[j + 1]
            return s * c
        acc += (b - a) / 6 * (at(a) + 4 * at(m) + at(b))
    ynorm = np.sum(0.5 * (T[:-1, 1] + T[1:, 1]))
    return np.maximum(M @ (acc / ynorm), 0)

if __name__ == '__main__':
    for name, nm, val in [('door light', [400, 500, 600, 700], [0, 16, 31.2, 36.8]),
                          ('flat 400..700', [400, 700], [1, 1])]:
        print('%-14s Mitsuba 0.5/0.6 %s   straight interpolation %s' % (
            name, ' '.join('%.9g' % v for v in rgb(nm, val)), ' '.join('%.9g' % v for v in rgb(nm, val, False))))
