#!/usr/bin/env python3
"""Writes the fuzzers' seed corpus (tests/fuzz/corpus/<target>/), small files
made here from scratch: valid glTF/GLB/OBJ scenes and ray files that reach
deep into each parser, plus a few near-misses. Deterministic; run it again
after changing it and commit the output."""
import base64
import json
import os
import struct
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")


def put(target, name, data):
    d = os.path.join(ROOT, target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


def pad4(b, fill=b"\0"):
    return b + fill * (-len(b) % 4)


def gltf_doc(positions, indices=None, index_type=5123, mode=None, nodes=None, extra_buffer_uri=None):
    pos = b"".join(struct.pack("<3f", *p) for p in positions)
    fmt = {5121: "B", 5123: "H", 5125: "I"}[index_type]
    idx = pad4(b"".join(struct.pack("<" + fmt, i) for i in indices)) if indices else b""
    blob = pos + idx
    lo = [min(p[k] for p in positions) for k in range(3)]
    hi = [max(p[k] for p in positions) for k in range(3)]
    accessors = [{"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
                  "min": lo, "max": hi}]
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos), "target": 34962}]
    prim = {"attributes": {"POSITION": 0}}
    if indices:
        views.append({"buffer": 0, "byteOffset": len(pos), "byteLength": len(indices) * struct.calcsize(fmt),
                      "target": 34963})
        accessors.append({"bufferView": 1, "componentType": index_type, "count": len(indices), "type": "SCALAR"})
        prim["indices"] = 1
    if mode is not None:
        prim["mode"] = mode
    doc = {"asset": {"version": "2.0"}, "scene": 0, "buffers": [{"byteLength": len(blob)}],
           "bufferViews": views, "accessors": accessors, "meshes": [{"primitives": [prim]}],
           "nodes": nodes if nodes is not None else [{"mesh": 0}],
           "scenes": [{"nodes": [0]}]}
    if extra_buffer_uri:
        doc["buffers"][0]["uri"] = extra_buffer_uri
    return doc, blob


def as_gltf(doc, blob):
    doc = json.loads(json.dumps(doc))
    if "uri" not in doc["buffers"][0]:
        doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode()
    return json.dumps(doc, separators=(",", ":"))


def as_glb(doc, blob):
    js = pad4(json.dumps(doc, separators=(",", ":")).encode(), b" ")
    bin_ = pad4(blob)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(bin_), 0x004E4942) + bin_
    return struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body


def gltf_seeds():
    tri = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
    quad = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
    cube = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    cube_idx = [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3]
    seeds = {
        "triangle": gltf_doc(tri),
        "quad_u16": gltf_doc(quad, [0, 1, 2, 0, 2, 3]),
        "cube_u8": gltf_doc(cube, cube_idx, 5121),
        "cube_u32": gltf_doc(cube, cube_idx, 5125),
        "strip": gltf_doc(quad, [0, 1, 3, 2], mode=5),
        "fan": gltf_doc(quad, [0, 1, 2, 3], mode=6),
        "lines": gltf_doc(quad, [0, 1, 1, 2], mode=1),
        "hierarchy": gltf_doc(tri, nodes=[
            {"children": [1], "translation": [1, 2, 3], "rotation": [0, 0, 0.7071068, 0.7071068], "scale": [2, 2, 2]},
            {"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1]}]),
        "instanced": gltf_doc(tri, nodes=[{"children": [1, 2]}, {"mesh": 0}, {"mesh": 0, "translation": [3, 0, 0]}]),
    }
    for name, (doc, blob) in seeds.items():
        put("gltf", name + ".gltf", as_gltf(doc, blob))
        put("gltf", name + ".glb", as_glb(doc, blob))
    # A camera and a light (KHR_lights_punctual), as the loader reads them.
    doc, blob = gltf_doc(tri, nodes=[{"mesh": 0}, {"camera": 0, "translation": [0, 0, 5]},
                                     {"extensions": {"KHR_lights_punctual": {"light": 0}}}])
    doc["scenes"][0]["nodes"] = [0, 1, 2]
    doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5}}]
    doc["extensionsUsed"] = ["KHR_lights_punctual"]
    doc["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 10}]}}
    put("gltf", "camera_light.gltf", as_gltf(doc, blob))
    # Byte stride and an offset accessor.
    doc, blob = gltf_doc(tri)
    doc["bufferViews"][0]["byteStride"] = 12
    put("gltf", "stride.gltf", as_gltf(doc, blob))
    # An external buffer that does not exist next to the file.
    doc, blob = gltf_doc(tri, extra_buffer_uri="missing.bin")
    put("gltf", "external_missing.gltf", json.dumps(doc))


def obj_seeds():
    put("obj", "triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    put("obj", "quad_negative.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n")
    put("obj", "cube_vt_vn.obj",
        "# cube\no cube\ng side\n" +
        "".join(f"v {x} {y} {z}\n" for x in (0, 1) for y in (0, 1) for z in (0, 1)) +
        "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 1 0\n" +
        "f 1/1/1 2/2/1 4/3/1\nf 1//2 4//2 3//2\nf 5/1 6/2 8/3 7/1\nf 1 5 6 2\nusemtl none\ns 1\nf 3 4 8 7\n")
    put("obj", "polygon.obj", "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 2 2 0\nv 0 2 0\nv -1 1 0\nf 1 2 3 4 5 6\n")
    put("obj", "lines_points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\np 3\nf 1 2 3\n")
    put("obj", "mtllib_missing.obj", "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n")
    put("obj", "continuation.obj", "v 0 0 \\\n 0\nv 1e3 0 0\nv 0 1e-3 0\nf 1 2 3\n")


def ray_seeds():
    def header(magic, count):
        return magic + struct.pack("<IQ", 1, count)
    rays = [(0, 0, -1, 0, 0, 0, 1, 1e30), (0.5, 0.25, 2, 0.001, -0.0, 0.0, -1, 10)]
    put("ray_file", "rays2.rays", header(b"RAYS", 2) + b"".join(struct.pack("<8f", *r) for r in rays))
    put("ray_file", "rays0.rays", header(b"RAYS", 0))
    put("ray_file", "hits2.hits", header(b"HITS", 2) + struct.pack("<If", 3, 1.5) + struct.pack("<If", 0xFFFFFFFF, 1e30))
    put("ray_file", "occl3.occl", header(b"OCCL", 3) + bytes([0, 1, 1]))
    put("ray_file", "rays_short.rays", header(b"RAYS", 2) + struct.pack("<8f", *rays[0]))


def main():
    gltf_seeds()
    obj_seeds()
    ray_seeds()
    return 0


if __name__ == "__main__":
    sys.exit(main())
