#!/usr/bin/env python3
"""make_gltf.py - writes the small glTF 2.0 assets of the tests and the fuzz
seeds (tests/data/gltf, tests/fuzz/corpus/gltf), so that every one can be
made again: python3 tests/data/gltf/make_gltf.py

  cube.glb          a cube (normals, uvs, unsigned short indices) with a base
                    colour texture held in a buffer view, a perspective camera,
                    a point light and a spot light (KHR_lights_punctual)
  external.gltf     a quad whose buffer is the file "quad data.bin" (a URI
                    with a percent escape), a texture file next to it, MASK
  instanced.gltf    one mesh placed by three nodes (matrix and T R S), an
                    orthographic camera, a directional light, a strip and a fan
  uv_sets.gltf      two quads whose textures read different TEXCOORD sets:
                    base colour TEXCOORD_0, emission and a normal map
                    TEXCOORD_1 (the map turned by a quarter; the second placed
                    twice, the second time out of view), a camera and a light
  bad_*.gltf/.glb   hostile assets: an accessor past its view, an index out
                    of range, a malformed data: URI, a lying GLB length, a node
                    cycle
"""
import base64
import json
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
SEEDS = os.path.join(HERE, "..", "..", "fuzz", "corpus", "gltf")


class Buf:
    def __init__(self):
        self.data = bytearray()
        self.views = []

    def view(self, raw, stride=None):
        while len(self.data) % 4:
            self.data.append(0)
        v = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(raw)}
        if stride:
            v["byteStride"] = stride
        self.data += raw
        self.views.append(v)
        return len(self.views) - 1


def floats(vals):
    return struct.pack("<%df" % len(vals), *vals)


def cube():
    """24 vertices (4 a face), outward normals, uvs, 36 indices."""
    faces = [((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
             ((0, 1, 0), (1, 0, 0), (0, 0, -1)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
             ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (-1, 0, 0), (0, 1, 0))]
    pos, nrm, uv, idx = [], [], [], []
    for n, u, v in faces:
        base = len(pos) // 3
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            pos += [0.5 * (n[k] + su * u[k] + sv * v[k]) for k in range(3)]
            nrm += list(n)
            uv += [(su + 1) / 2, 1 - (sv + 1) / 2]
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return pos, nrm, uv, idx


def write_glb(path, doc, binary, lie=None):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    binary = bytes(binary) + b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(js) + 8 + len(binary)
    out = struct.pack("<4sII", b"glTF", 2, lie if lie else total)
    out += struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(binary), 0x004E4942) + binary
    with open(path, "wb") as f:
        f.write(out)
    return out


def write_json(path, doc):
    text = json.dumps(doc, indent=1).encode()
    with open(path, "wb") as f:
        f.write(text)
    return text


def asset(**kw):
    d = {"asset": {"version": "2.0", "generator": "paprsek tests/data/gltf/make_gltf.py"}}
    d.update(kw)
    return d


def make_cube():
    pos, nrm, uv, idx = cube()
    b = Buf()
    vp = b.view(floats(pos))
    vn = b.view(floats(nrm))
    vt = b.view(floats(uv))
    vi = b.view(struct.pack("<%dH" % len(idx), *idx))
    with open(os.path.join(HERE, "..", "tex_checker.png"), "rb") as f:
        vimg = b.view(f.read())
    doc = asset(
        extensionsUsed=["KHR_lights_punctual"],
        extensions={"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 0.9, 0.8], "intensity": 4000},
            {"type": "spot", "intensity": 8000, "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.5}}]}},
        buffers=[{"byteLength": len(b.data)}],
        bufferViews=b.views,
        accessors=[
            {"bufferView": vp, "componentType": 5126, "count": 24, "type": "VEC3",
             "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
            {"bufferView": vn, "componentType": 5126, "count": 24, "type": "VEC3"},
            {"bufferView": vt, "componentType": 5126, "count": 24, "type": "VEC2"},
            {"bufferView": vi, "componentType": 5123, "count": 36, "type": "SCALAR"}],
        images=[{"bufferView": vimg, "mimeType": "image/png"}],
        samplers=[{"wrapS": 10497, "wrapT": 10497}],
        textures=[{"source": 0, "sampler": 0}],
        materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0,
                                             "roughnessFactor": 0.6}},
                   {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0}}],
        meshes=[{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3,
                                 "material": 0}]},
                {"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 3, "material": 1}]}],
        cameras=[{"type": "perspective", "perspective": {"yfov": 0.7, "aspectRatio": 1.5, "znear": 0.1}}],
        nodes=[{"mesh": 0, "rotation": [0, 0.3826834, 0, 0.9238795]},
               {"mesh": 1, "translation": [0, -0.75, 0], "scale": [6, 0.5, 6]},
               {"camera": 0, "translation": [0, 1.2, 3.5], "rotation": [-0.1736482, 0, 0, 0.9848078]},
               {"translation": [2, 3, 2], "extensions": {"KHR_lights_punctual": {"light": 0}}},
               {"translation": [0, 4, 0], "rotation": [-0.7071068, 0, 0, 0.7071068],
                "extensions": {"KHR_lights_punctual": {"light": 1}}}],
        scenes=[{"nodes": [0, 1, 2, 3, 4]}], scene=0)
    return write_glb(os.path.join(HERE, "cube.glb"), doc, b.data), doc, b.data


def make_external():
    b = Buf()
    vp = b.view(floats([-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0]))
    vt = b.view(floats([0, 1, 1, 1, 1, 0, 0, 0]))
    vi = b.view(bytes([0, 1, 2, 0, 2, 3]))
    with open(os.path.join(HERE, "quad data.bin"), "wb") as f:
        f.write(b.data)
    doc = asset(
        buffers=[{"byteLength": len(b.data), "uri": "quad%20data.bin"}],
        bufferViews=b.views,
        accessors=[{"bufferView": vp, "componentType": 5126, "count": 4, "type": "VEC3"},
                   {"bufferView": vt, "componentType": 5126, "count": 4, "type": "VEC2"},
                   {"bufferView": vi, "componentType": 5121, "count": 6, "type": "SCALAR"}],
        images=[{"uri": "../tex_holes.png"}],
        textures=[{"source": 0}],
        materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0},
                    "alphaMode": "MASK", "doubleSided": True}],
        meshes=[{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        nodes=[{"mesh": 0}], scenes=[{"nodes": [0]}])
    return write_json(os.path.join(HERE, "external.gltf"), doc)


def data_uri(raw):
    return "data:application/octet-stream;base64," + base64.b64encode(bytes(raw)).decode()


def make_instanced():
    b = Buf()
    pos, nrm, uv, idx = cube()
    vp = b.view(floats(pos))
    vi = b.view(struct.pack("<%dI" % len(idx), *idx))
    # a strip and a fan: a ground of 2 triangles each
    vs = b.view(floats([-3, 0, -3, -3, 0, 3, 0, 0, -3, 0, 0, 3]))
    vf = b.view(floats([0, 0, 0, 0, 0, -3, 3, 0, -3, 3, 0, 3, 0, 0, 3]))
    doc = asset(
        extensionsUsed=["KHR_lights_punctual"],
        extensions={"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 1500}]}},
        buffers=[{"byteLength": len(b.data), "uri": data_uri(b.data)}],
        bufferViews=b.views,
        accessors=[{"bufferView": vp, "componentType": 5126, "count": 24, "type": "VEC3"},
                   {"bufferView": vi, "componentType": 5125, "count": 36, "type": "SCALAR"},
                   {"bufferView": vs, "componentType": 5126, "count": 4, "type": "VEC3"},
                   {"bufferView": vf, "componentType": 5126, "count": 5, "type": "VEC3"}],
        materials=[{"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.3, 0.2, 1], "metallicFactor": 0,
                                             "roughnessFactor": 0.4}},
                   {"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.9, 1], "metallicFactor": 1,
                                             "roughnessFactor": 0.2}}],
        meshes=[{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]},
                {"primitives": [{"attributes": {"POSITION": 2}, "mode": 5, "material": 1},
                                {"attributes": {"POSITION": 3}, "mode": 6, "material": 1}]}],
        cameras=[{"type": "orthographic", "orthographic": {"xmag": 4, "ymag": 3, "znear": 0.1, "zfar": 50}}],
        nodes=[{"children": [1, 2, 3]},
               {"mesh": 0, "translation": [-1.5, 0.5, 0]},
               {"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0.5, 0, 1]},
               {"mesh": 0, "translation": [1.5, 0.5, 0], "rotation": [0, 0.3826834, 0, 0.9238795],
                "scale": [1, 0.5, 1]},
               {"mesh": 1},
               {"camera": 0, "translation": [0, 8, 8], "rotation": [-0.3826834, 0, 0, 0.9238795]},
               {"rotation": [-0.5, 0.5, 0.2, 0.6782330], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
        scenes=[{"nodes": [0, 4, 5, 6]}])
    return write_json(os.path.join(HERE, "instanced.gltf"), doc)


def make_uv_sets():
    b = Buf()
    vp = b.view(floats([-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0]))
    vn = b.view(floats([0, 0, 1] * 4))
    uv0 = [0, 1, 1, 1, 1, 0, 0, 0]
    vt0 = b.view(floats(uv0))
    vt1 = b.view(floats(uv0[2:] + uv0[:2]))  # each vertex takes the next one's: a quarter turn
    vi = b.view(bytes([0, 1, 2, 0, 2, 3]))
    doc = asset(
        extensionsUsed=["KHR_lights_punctual"],
        extensions={"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 400}]}},
        buffers=[{"byteLength": len(b.data), "uri": data_uri(b.data)}],
        bufferViews=b.views,
        accessors=[{"bufferView": vp, "componentType": 5126, "count": 4, "type": "VEC3"},
                   {"bufferView": vn, "componentType": 5126, "count": 4, "type": "VEC3"},
                   {"bufferView": vt0, "componentType": 5126, "count": 4, "type": "VEC2"},
                   {"bufferView": vt1, "componentType": 5126, "count": 4, "type": "VEC2"},
                   {"bufferView": vi, "componentType": 5121, "count": 6, "type": "SCALAR"}],
        images=[{"uri": "../tex_checker.png"}, {"uri": "../tex_rgbw.png"}],
        textures=[{"source": 0}, {"source": 1}],
        materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0},
                    "emissiveTexture": {"index": 1, "texCoord": 1}, "emissiveFactor": [0.5, 0.5, 0.5]},
                   {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0},
                    "normalTexture": {"index": 1, "texCoord": 1}}],
        meshes=[{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TEXCOORD_1": 3},
                                 "indices": 4, "material": 0}]},
                {"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TEXCOORD_1": 3},
                                 "indices": 4, "material": 1}]}],
        cameras=[{"type": "perspective", "perspective": {"yfov": 0.9, "aspectRatio": 2, "znear": 0.1}}],
        nodes=[{"mesh": 0, "translation": [-1.1, 0, 0]}, {"mesh": 1, "translation": [1.1, 0, 0]},
               {"camera": 0, "translation": [0, 0, 3.2]},
               {"translation": [0, 1, 2], "extensions": {"KHR_lights_punctual": {"light": 0}}},
               {"mesh": 1, "translation": [1.1, -3, 0]}],
        scenes=[{"nodes": [0, 1, 2, 3, 4]}])
    return write_json(os.path.join(HERE, "uv_sets.gltf"), doc)


def tri_doc(accessor_count=3, indices=None, uri=None):
    b = Buf()
    vp = b.view(floats([0, 0, 0, 1, 0, 0, 0, 1, 0]))
    acc = [{"bufferView": vp, "componentType": 5126, "count": accessor_count, "type": "VEC3"}]
    prim = {"attributes": {"POSITION": 0}}
    if indices:
        vi = b.view(struct.pack("<%dH" % len(indices), *indices))
        acc.append({"bufferView": vi, "componentType": 5123, "count": len(indices), "type": "SCALAR"})
        prim["indices"] = 1
    return asset(buffers=[{"byteLength": len(b.data), "uri": uri or data_uri(b.data)}], bufferViews=b.views,
                 accessors=acc, meshes=[{"primitives": [prim]}], nodes=[{"mesh": 0}], scenes=[{"nodes": [0]}])


def main():
    os.makedirs(SEEDS, exist_ok=True)
    seeds = {}
    glb, cube_doc, cube_bin = make_cube()
    seeds["cube.glb"] = glb
    seeds["external.gltf"] = make_external()
    seeds["instanced.gltf"] = make_instanced()
    seeds["uv_sets.gltf"] = make_uv_sets()
    seeds["bad_accessor.gltf"] = write_json(os.path.join(HERE, "bad_accessor.gltf"), tri_doc(accessor_count=100))
    seeds["bad_index.gltf"] = write_json(os.path.join(HERE, "bad_index.gltf"), tri_doc(indices=[0, 1, 9]))
    seeds["bad_uri.gltf"] = write_json(os.path.join(HERE, "bad_uri.gltf"),
                                       tri_doc(uri="data:application/octet-stream;base64,AAAA=AAA"))
    cyc = asset(nodes=[{"children": [1]}, {"children": [0]}], scenes=[{"nodes": [0]}])
    seeds["bad_cycle.gltf"] = write_json(os.path.join(HERE, "bad_cycle.gltf"), cyc)
    seeds["bad_length.glb"] = write_glb(os.path.join(HERE, "bad_length.glb"), cube_doc, cube_bin, lie=1 << 20)
    for name, data in seeds.items():
        with open(os.path.join(SEEDS, "seed-" + name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
