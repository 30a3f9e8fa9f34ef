#!/usr/bin/env python3
"""gltf_transmission.py - writes gltf_transmission.gltf, the glTF asset of
docs/images/gltf_transmission.png: four spheres of KHR_materials_transmission
in front of a checkered wall, left to right

  1. transmission 1, roughness 0, KHR_materials_volume (thickness 1): a glass
     ball that refracts (the wall seen upside down through it)
  2. the same with roughness 0.3: frosted glass
  3. the same as 1 with attenuationColor (0.9, 0.35, 0.2) at attenuationDistance
     0.6: tinted by the length light travels inside
  4. transmission 1, roughness 0, no volume: a thin sheet, the wall seen
     through it unbent

lit by a directional light. Render (from the repository root):

  python3 docs/images/gltf_transmission.py
  paprsek render docs/images/gltf_transmission.gltf --width 480 --height 160 --spp 256 \\
      --env 0.4,0.4,0.4 -o docs/images/gltf_transmission.png
"""
import base64
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def sphere(nu=48, nv=24):
    pos, nrm, idx = [], [], []
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu + 1):
            ph = 2 * math.pi * i / nu
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            pos += n
            nrm += n
    for j in range(nv):
        for i in range(nu):
            a, b = j * (nu + 1) + i, (j + 1) * (nu + 1) + i
            if j > 0:
                idx += [a, a + 1, b]
            if j < nv - 1:
                idx += [a + 1, b + 1, b]
    return pos, nrm, idx


def main():
    data = bytearray()
    views, acc = [], []

    def add(raw, count, typ, ctype=5126):
        while len(data) % 4:
            data.append(0)
        views.append({"buffer": 0, "byteOffset": len(data), "byteLength": len(raw)})
        data.extend(raw)
        acc.append({"bufferView": len(views) - 1, "componentType": ctype, "count": count, "type": typ})
        return len(acc) - 1

    pos, nrm, idx = sphere()
    nv = len(pos) // 3
    sp = add(struct.pack("<%df" % len(pos), *pos), nv, "VEC3")
    acc[sp]["min"], acc[sp]["max"] = [-1, -1, -1], [1, 1, 1]
    sn = add(struct.pack("<%df" % len(nrm), *nrm), nv, "VEC3")
    si = add(struct.pack("<%dI" % len(idx), *idx), len(idx), "SCALAR", 5125)
    wp = add(struct.pack("<12f", -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0), 4, "VEC3")
    acc[wp]["min"], acc[wp]["max"] = [-1, -1, 0], [1, 1, 0]
    wn = add(struct.pack("<12f", *([0, 0, 1] * 4)), 4, "VEC3")
    wt = add(struct.pack("<8f", 0, 1, 3, 1, 3, 0, 0, 0), 4, "VEC2")
    wi = add(struct.pack("<6I", 0, 1, 2, 0, 2, 3), 6, "SCALAR", 5125)

    def glass(rough, volume=None):
        m = {"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": rough},
             "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}}}
        if volume is not None:
            m["extensions"]["KHR_materials_volume"] = volume
        return m

    vol = {"thicknessFactor": 1}
    tinted = {"thicknessFactor": 1, "attenuationColor": [0.9, 0.35, 0.2], "attenuationDistance": 0.6}
    mats = [glass(0, vol), glass(0.3, vol), glass(0, tinted), glass(0),
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0, "roughnessFactor": 0.8}}]
    meshes = [{"primitives": [{"attributes": {"POSITION": sp, "NORMAL": sn}, "indices": si, "material": k}]}
              for k in range(4)]
    meshes.append({"primitives": [{"attributes": {"POSITION": wp, "NORMAL": wn, "TEXCOORD_0": wt}, "indices": wi,
                                   "material": 4}]})
    nodes = [{"mesh": k, "translation": [-3.3 + 2.2 * k, 0, 0]} for k in range(4)]
    nodes += [{"mesh": 4, "translation": [0, 0, -3], "scale": [12, 4, 1]},
              {"camera": 0, "translation": [0, 0, 9.5]},
              {"rotation": [-0.3826834, 0.2, 0, 0.9016]}]
    nodes[-1]["extensions"] = {"KHR_lights_punctual": {"light": 0}}
    doc = {"asset": {"version": "2.0", "generator": "paprsek docs/images/gltf_transmission.py"},
           "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume", "KHR_lights_punctual"],
           "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 5}]}},
           "buffers": [{"byteLength": len(data),
                        "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(data)).decode()}],
           "bufferViews": views, "accessors": acc,
           "images": [{"uri": "../../tests/data/tex_checker.png"}], "textures": [{"source": 0}],
           "materials": mats, "meshes": meshes,
           "cameras": [{"type": "perspective", "perspective": {"yfov": 0.42, "aspectRatio": 3, "znear": 0.1}}],
           "nodes": nodes, "scenes": [{"nodes": list(range(len(nodes)))}]}
    with open(os.path.join(HERE, "gltf_transmission.gltf"), "w") as f:
        json.dump(doc, f, indent=1)


if __name__ == "__main__":
    main()
