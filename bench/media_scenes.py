#!/usr/bin/python3
"""The scenes of bench/media.sh, written into a folder (JSON scenes and
their OBJ files; nothing is read from the repository):

  fog.json        a Cornell-style room (2 units a side, open toward the
                  camera, an area light under the ceiling, a block and a
                  sphere) filled with homogeneous fog, bounded by an
                  index-matched box just inside the walls
  smoke.json      the same room, empty, with a smoke plume: a 256^3 grid
                  (smoke.vol, written here: a few octaves of value noise
                  masked by a rising, widening, wandering column) inside an
                  index-matched box
  smoke_hom.json  the same, the grid replaced by a homogeneous medium of
                  the grid's mean extinction over the same box
  bunny.json      (with a bunny OBJ) a subsurface bunny: a dielectric of
                  index 1.3 around a scattering jade-green interior, on a
                  floor, lit by an area light

usage: media_scenes.py DIR [GRID_RES [BUNNY.obj]]
Prints the smoke grid's mean and greatest density.
"""
import struct
import sys

import numpy as np


def quad(f, a, b, c, d):
    """a quad with vertices a, b, c, d counter-clockwise seen from the side its normal faces"""
    for v in (a, b, c, d):
        f.write("v %g %g %g\n" % v)
    f.write("f -4 -3 -2 -1\n")


def box(f, lo, hi, outward=True):
    """the six faces of an axis-aligned box, normals outward (or inward)"""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    faces = [
        ((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),  # -x
        ((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)),  # +x
        ((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),  # -y
        ((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)),  # +y
        ((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)),  # -z
        ((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),  # +z
    ]
    for q in faces:
        quad(f, *(q if outward else q[::-1]))


def room(d):
    """the Cornell-style room: [-1, 1] x [0, 2] x [-1, 1], open toward +z"""
    with open(f"{d}/room.obj", "w") as f:
        f.write("usemtl white\n")
        quad(f, (-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1))  # floor, up
        quad(f, (-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1))  # ceiling, down
        quad(f, (-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1))  # back, +z
        f.write("usemtl red\n")
        quad(f, (-1, 0, -1), (-1, 2, -1), (-1, 2, 1), (-1, 0, 1))  # left, +x
        f.write("usemtl green\n")
        quad(f, (1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1))  # right, -x
        f.write("usemtl light\n")
        quad(f, (-0.25, 1.98, -0.25), (0.25, 1.98, -0.25), (0.25, 1.98, 0.25), (-0.25, 1.98, 0.25))  # down


ROOM_MATERIALS = """
    "white": {"type": "diffuse", "albedo": [0.73, 0.73, 0.73]},
    "red": {"type": "diffuse", "albedo": [0.63, 0.065, 0.05]},
    "green": {"type": "diffuse", "albedo": [0.14, 0.45, 0.091]},
    "light": {"type": "emitter", "radiance": [17, 12, 4]}"""
CAMERA = '"camera": {"look_from": [0, 1, 3.8], "look_at": [0, 1, 0], "fov": 40}'


def fog(d):
    with open(f"{d}/fog_box.obj", "w") as f:
        f.write("usemtl fogbox\n")
        box(f, (-0.999, 0.001, -0.999), (0.999, 1.999, 1.0))
    with open(f"{d}/block.obj", "w") as f:
        f.write("usemtl white\n")
        box(f, (-0.7, 0.0, -0.6), (-0.15, 1.2, -0.05))
    with open(f"{d}/fog.json", "w") as f:
        f.write('{%s, "environment": "none",\n' % CAMERA)
        f.write(' "media": [{"name": "fog", "type": "homogeneous", "sigma_a": 0.05, "sigma_s": 0.3, "g": 0.3}],\n')
        f.write(' "materials": {%s,\n    "fogbox": {"type": "interface", "interior": "fog", "exterior": null}},\n'
                % ROOM_MATERIALS)
        f.write(' "meshes": [{"obj": "room.obj"}, {"obj": "block.obj"}, {"obj": "fog_box.obj"}],\n')
        f.write(' "spheres": [{"center": [0.45, 0.35, 0.3], "radius": 0.35, "material": "white"}]}\n')


def smoke_grid(n):
    """a smoke plume: value-noise fBm (4 octaves) masked by a column that
    rises along y, wanders, widens and fades toward the top; z, y, x order"""
    rng = np.random.default_rng(7)
    c = (np.arange(n, dtype=np.float32) + 0.5) / n

    def value_noise(fr):
        lat = rng.random((fr + 1, fr + 1, fr + 1), dtype=np.float32)
        u = c * fr
        i = np.minimum(u.astype(np.int32), fr - 1)
        t = u - i
        t = t * t * (3 - 2 * t)
        a = lat[i] * (1 - t)[:, None, None] + lat[i + 1] * t[:, None, None]
        a = a[:, i] * (1 - t)[None, :, None] + a[:, i + 1] * t[None, :, None]
        return a[:, :, i] * (1 - t)[None, None, :] + a[:, :, i + 1] * t[None, None, :]

    fbm = np.zeros((n, n, n), np.float32)
    amp, tot = 1.0, 0.0
    for fr in (4, 8, 16, 32):
        fbm += amp * value_noise(fr)
        tot += amp
        amp *= 0.5
    fbm /= tot
    z, y, x = c[:, None, None], c[None, :, None], c[None, None, :]
    cx = 0.5 + 0.08 * np.sin(7.0 * y + 1.0)
    cz = 0.5 + 0.06 * np.cos(5.0 * y)
    d = np.sqrt((x - cx) ** 2 + (z - cz) ** 2) / (0.06 + 0.3 * y)
    mask = np.clip(1.0 - d, 0, 1) ** 1.5 * np.clip(y / 0.04, 0, 1) * np.clip((1.0 - y) / 0.25, 0, 1)
    return (mask * np.clip(2.2 * fbm - 0.6, 0, None)).astype(np.float32)


SMOKE_LO, SMOKE_HI = (-0.6, 0.002, -0.7), (0.6, 1.9, 0.5)
SMOKE_SIGMA_T, SMOKE_ALBEDO = 60.0, 0.9


def smoke(d, n):
    g = smoke_grid(n)
    with open(f"{d}/smoke.vol", "wb") as f:
        f.write(b"VOL\x03" + struct.pack("<5i", 1, n, n, n, 1) + struct.pack("<6f", 0, 0, 0, 1, 1, 1))
        f.write(g.tobytes())
    mean = float(g.astype(np.float64).mean())
    with open(f"{d}/smoke_box.obj", "w") as f:
        f.write("usemtl smokebox\n")
        box(f, SMOKE_LO, SMOKE_HI)
    lo, hi = list(SMOKE_LO), list(SMOKE_HI)
    for name, med in (
            ("smoke", '{"name": "smoke", "type": "grid", "file": "smoke.vol", "sigma_t": %g, "albedo": %g, '
                      '"bounds": {"min": %s, "max": %s}}' % (SMOKE_SIGMA_T, SMOKE_ALBEDO, lo, hi)),
            ("smoke_hom", '{"name": "smoke", "type": "homogeneous", "sigma_t": %.6g, "albedo": %g}'
                          % (SMOKE_SIGMA_T * mean, SMOKE_ALBEDO))):
        with open(f"{d}/{name}.json", "w") as f:
            f.write('{%s, "environment": "none",\n "media": [%s],\n' % (CAMERA, med))
            f.write(' "materials": {%s,\n    "smokebox": {"type": "interface", "interior": "smoke", "exterior": null}},\n'
                    % ROOM_MATERIALS)
            f.write(' "meshes": [{"obj": "room.obj"}, {"obj": "smoke_box.obj"}]}\n')
    print("%.6g %.6g" % (mean, float(g.max())))


def bunny(d, obj):
    with open(obj) as src, open(f"{d}/bunny.obj", "w") as f:
        f.write("usemtl jade\n")
        f.write(src.read())
    with open(f"{d}/floor.obj", "w") as f:
        f.write("usemtl floor\n")
        quad(f, (-4, 0, -4), (-4, 0, 4), (4, 0, 4), (4, 0, -4))
        f.write("usemtl lamp\n")
        quad(f, (-0.6, 2.5, -1.6), (0.6, 2.5, -1.6), (0.6, 3.0, -0.4), (-0.6, 3.0, -0.4))
    # the Stanford bunny spans about 0.155 x 0.154 x 0.121 from y = 0.033:
    # scaled by 8 it stands 1.23 units tall on the floor
    with open(f"{d}/bunny.json", "w") as f:
        f.write('{"camera": {"look_from": [0, 0.9, 3.2], "look_at": [0, 0.6, 0], "fov": 32},\n')
        f.write(' "environment": {"radiance": [0.08, 0.09, 0.1]},\n')
        f.write(' "media": [{"name": "jade", "type": "homogeneous", "sigma_s": 24, '
                '"sigma_a": [1.2, 0.15, 0.6], "g": 0.3}],\n')
        f.write(' "materials": {"jade": {"type": "dielectric", "ior": 1.3, "interior": "jade", "exterior": null},\n'
                '    "floor": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},\n'
                '    "lamp": {"type": "emitter", "radiance": [12, 11, 10]}},\n')
        f.write(' "meshes": [{"obj": "floor.obj"},\n'
                '   {"obj": "bunny.obj", "transform": {"translate": [0.15, -0.264, 0], "scale": 8}}]}\n')


def main():
    d = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 256
    room(d)
    fog(d)
    smoke(d, n)
    if len(sys.argv) > 3:
        bunny(d, sys.argv[3])


if __name__ == "__main__":
    main()
