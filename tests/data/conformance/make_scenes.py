#!/usr/bin/env python3
"""Writes one Cornell box in five formats for tests/render/test_conformance.c:
box.obj + box.mtl, box.json (the same OBJ, materials in JSON; box_mr.json
with glTF's metallic-roughness materials, the twin of box.gltf), box.xml
(Mitsuba: one OBJ per part), box.pbrt (pbrt-v4 trianglemeshes) and box.gltf
(glTF 2.0, buffers in a data: URI).

Every coordinate is a multiple of 1/4, exact in binary and in text, so that
every reader gets the same floats; the parts come in the same order in every
file, so the triangles are numbered alike. The camera sits at (0, 1, 3.5)
looking at (0, 1, 0), 40 degrees vertically, in the formats that carry one
(the OBJ render is given it through the API).

usage: make_scenes.py [DIR]   (default: this script's folder)
"""
import base64
import json
import os
import struct
import sys

WHITE, RED, GREEN = (0.7, 0.7, 0.7), (0.6, 0.1, 0.1), (0.1, 0.5, 0.1)
LIGHT = (10.0, 10.0, 10.0)

# (name, material, quads): each quad four corners, counter-clockwise seen
# from the side it faces.
PARTS = [
    ("floor", "white", [[(-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1)]]),
    ("ceiling", "white", [[(-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)]]),
    ("back", "white", [[(-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)]]),
    ("left", "red", [[(-1, 0, -1), (-1, 2, -1), (-1, 2, 1), (-1, 0, 1)]]),
    ("right", "green", [[(1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1)]]),
    ("block", "white", [  # a box 0.5 wide, 0.75 high, on the floor
        [(-0.5, 0.75, -0.5), (-0.5, 0.75, 0), (0, 0.75, 0), (0, 0.75, -0.5)],
        [(-0.5, 0, 0), (0, 0, 0), (0, 0.75, 0), (-0.5, 0.75, 0)],
        [(0, 0, 0), (0, 0, -0.5), (0, 0.75, -0.5), (0, 0.75, 0)],
        [(-0.5, 0, -0.5), (-0.5, 0, 0), (-0.5, 0.75, 0), (-0.5, 0.75, -0.5)],
    ]),
    ("light", "light", [[(-0.25, 1.75, -0.25), (0.25, 1.75, -0.25), (0.25, 1.75, 0.25), (-0.25, 1.75, 0.25)]]),
]


def tris(quads):
    """Vertices and triangles (0-2-1 order kept: v0 v1 v2, v0 v2 v3)."""
    verts, out = [], []
    for q in quads:
        b = len(verts)
        verts += q
        out += [(b, b + 1, b + 2), (b, b + 2, b + 3)]
    return verts, out


def num(x):
    return repr(float(x)).rstrip('0').rstrip('.') if float(x) != int(x) else str(int(x))


def write_obj(path, parts, mtllib=None):
    with open(path, "w") as f:
        if mtllib:
            f.write(f"mtllib {mtllib}\n")
        base = 1
        for name, mat, quads in parts:
            v, t = tris(quads)
            f.write(f"o {name}\nusemtl {mat}\n")
            for p in v:
                f.write("v " + " ".join(num(c) for c in p) + "\n")
            for a, b, c in t:
                f.write(f"f {a + base} {b + base} {c + base}\n")
            base += len(v)


def main(d):
    os.makedirs(d, exist_ok=True)
    # OBJ + MTL
    write_obj(f"{d}/box.obj", PARTS, "box.mtl")
    with open(f"{d}/box.mtl", "w") as f:
        for name, c in (("white", WHITE), ("red", RED), ("green", GREEN)):
            f.write(f"newmtl {name}\nKd {c[0]} {c[1]} {c[2]}\nKs 0 0 0\nillum 1\n\n")
        f.write(f"newmtl light\nKd 0 0 0\nKs 0 0 0\nKe {LIGHT[0]} {LIGHT[1]} {LIGHT[2]}\nillum 1\n")
    # JSON: the same OBJ, its materials named in JSON (the MTL is not read)
    write_obj(f"{d}/box_nomtl.obj", PARTS)
    scene = {
        "camera": {"look_from": [0, 1, 3.5], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov": 40},
        "materials": {"white": {"type": "diffuse", "albedo": list(WHITE)},
                      "red": {"type": "diffuse", "albedo": list(RED)},
                      "green": {"type": "diffuse", "albedo": list(GREEN)},
                      "light": {"type": "emitter", "radiance": list(LIGHT)}},
        "meshes": [{"obj": "box_nomtl.obj"}],
        "environment": "none",
    }
    with open(f"{d}/box.json", "w") as f:
        json.dump(scene, f, indent=1)
    # JSON with glTF's material model, the twin of box.gltf
    scene["materials"] = {n: {"type": "metallic_roughness", "base_color": list(c), "metallic": 0, "roughness": 1}
                          for n, c in (("white", WHITE), ("red", RED), ("green", GREEN))}
    scene["materials"]["light"] = {"type": "emitter", "radiance": list(LIGHT),
                                   "bsdf": {"type": "metallic_roughness", "base_color": [0, 0, 0], "metallic": 0,
                                            "roughness": 1}}
    with open(f"{d}/box_mr.json", "w") as f:
        json.dump(scene, f, indent=1)
    # Mitsuba: one OBJ per part
    xml = ['<scene version="3.0.0">',
           ' <sensor type="perspective"><float name="fov" value="40"/><string name="fov_axis" value="y"/>',
           '  <transform name="to_world"><lookat origin="0, 1, 3.5" target="0, 1, 0" up="0, 1, 0"/></transform>',
           ' </sensor>']
    cols = {"white": WHITE, "red": RED, "green": GREEN}
    for name, mat, quads in PARTS:
        write_obj(f"{d}/part_{name}.obj", [(name, mat, quads)])
        xml.append(f' <shape type="obj"><string name="filename" value="part_{name}.obj"/>')
        if mat == "light":
            xml.append('  <bsdf type="diffuse"><rgb name="reflectance" value="0, 0, 0"/></bsdf>')
            xml.append(f'  <emitter type="area"><rgb name="radiance" value="{LIGHT[0]}, {LIGHT[1]}, {LIGHT[2]}"/></emitter>')
        else:
            c = cols[mat]
            xml.append(f'  <bsdf type="diffuse"><rgb name="reflectance" value="{c[0]}, {c[1]}, {c[2]}"/></bsdf>')
        xml.append(' </shape>')
    xml.append('</scene>')
    with open(f"{d}/box.xml", "w") as f:
        f.write("\n".join(xml) + "\n")
    # pbrt-v4
    # pbrt's camera space is left-handed: exporters mirror x before the
    # LookAt so that pbrt's image is the right-handed renderers' one
    pb = ['Scale -1 1 1', 'LookAt 0 1 3.5  0 1 0  0 1 0', 'Camera "perspective" "float fov" [ 40 ]', 'WorldBegin']
    for name, mat, quads in PARTS:
        v, t = tris(quads)
        pb.append('AttributeBegin')
        if mat == "light":
            pb.append(f'  AreaLightSource "diffuse" "rgb L" [ {LIGHT[0]} {LIGHT[1]} {LIGHT[2]} ]')
            pb.append('  Material "diffuse" "rgb reflectance" [ 0 0 0 ]')
        else:
            c = cols[mat]
            pb.append(f'  Material "diffuse" "rgb reflectance" [ {c[0]} {c[1]} {c[2]} ]')
        pb.append('  Shape "trianglemesh" "point3 P" [ ' + " ".join(num(c) for p in v for c in p) + ' ]')
        pb.append('    "integer indices" [ ' + " ".join(str(i) for tr in t for i in tr) + ' ]')
        pb.append('AttributeEnd')
    with open(f"{d}/box.pbrt", "w") as f:
        f.write("\n".join(pb) + "\n")
    # glTF: one mesh per part, positions float32 and indices uint16 in one buffer
    blob, views, accessors, meshes, nodes, materials = b"", [], [], [], [], []
    mat_index = {}
    for name, c in (("white", WHITE), ("red", RED), ("green", GREEN), ("light", (0, 0, 0))):
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0],
                                                     "metallicFactor": 0.0, "roughnessFactor": 1.0}}
        if name == "light":
            m["emissiveFactor"] = [1.0, 1.0, 1.0]
            m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": LIGHT[0]}}
        mat_index[name] = len(materials)
        materials.append(m)
    for name, mat, quads in PARTS:
        v, t = tris(quads)
        pos = b"".join(struct.pack("<3f", *p) for p in v)
        idx = b"".join(struct.pack("<3H", *tr) for tr in t)
        lo = [min(p[k] for p in v) for k in range(3)]
        hi = [max(p[k] for p in v) for k in range(3)]
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(pos)})
        blob += pos
        accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": len(v), "type": "VEC3",
                          "min": lo, "max": hi})
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(idx)})
        blob += idx + b"\0" * ((4 - len(idx) % 4) % 4)
        accessors.append({"bufferView": len(views) - 1, "componentType": 5123, "count": 3 * len(t), "type": "SCALAR"})
        meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                                      "indices": len(accessors) - 1, "material": mat_index[mat]}]})
        nodes.append({"mesh": len(meshes) - 1})
    nodes.append({"camera": 0, "translation": [0.0, 1.0, 3.5]})
    gltf = {
        "asset": {"version": "2.0", "generator": "paprsek tests/data/conformance/make_scenes.py"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes, "meshes": meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.6981317007977318, "aspectRatio": 1.0,
                                                             "znear": 0.01}}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": views, "accessors": accessors,
    }
    with open(f"{d}/box.gltf", "w") as f:
        json.dump(gltf, f, indent=1)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__)))
