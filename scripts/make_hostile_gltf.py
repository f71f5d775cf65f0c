#!/usr/bin/env python3
"""Writes the hostile glTF files of tests/regressions/ (run from the repository root).

Each file is a small valid skinned glTF (one triangle, two joints, inverse binds, a clip)
with one thing broken, the way a malformed or malicious download breaks it. The test
`untrusted::each_hostile_file_is_refused_at_its_place` holds the error each must give.
Only the standard library: `python3 scripts/make_hostile_gltf.py`.
"""

import copy
import json
import math
import os
import struct

OUT = os.path.join("tests", "regressions")

FLOAT, UBYTE, USHORT, UINT = 5126, 5121, 5123, 5125


def base():
    """A valid file: its JSON (a dict) and its binary buffer (bytearray)."""
    bin_ = bytearray()
    views, accessors = [], []

    def add(data, component, count, kind, stride=None):
        while len(bin_) % 4:
            bin_.append(0)
        view = {"buffer": 0, "byteOffset": len(bin_), "byteLength": len(data)}
        if stride:
            view["byteStride"] = stride
        bin_.extend(data)
        views.append(view)
        accessors.append({"bufferView": len(views) - 1, "componentType": component, "count": count, "type": kind})
        return len(accessors) - 1

    positions = add(struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0), FLOAT, 3, "VEC3")
    accessors[positions]["min"], accessors[positions]["max"] = [0, 0, 0], [1, 1, 0]
    indices = add(struct.pack("<3H", 0, 1, 2) + b"\0\0", USHORT, 3, "SCALAR")
    views[-1]["byteLength"] = 6
    joints = add(struct.pack("<12B", 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0), UBYTE, 3, "VEC4")
    weights = add(struct.pack("<12f", 1, 0, 0, 0, 0.5, 0.5, 0, 0, 1, 0, 0, 0), FLOAT, 3, "VEC4")
    identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    second = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1]
    ibm = add(struct.pack("<32f", *identity, *second), FLOAT, 2, "MAT4")
    times = add(struct.pack("<2f", 0, 1), FLOAT, 2, "SCALAR")
    s = math.sqrt(0.5)
    rotations = add(struct.pack("<8f", 0, 0, 0, 1, 0, 0, s, s), FLOAT, 2, "VEC4")
    translations = add(struct.pack("<6f", 0, 1, 0, 0, 1, 0), FLOAT, 2, "VEC3")
    doc = {
        "asset": {"version": "2.0", "generator": "make_hostile_gltf.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"name": "mesh", "mesh": 0, "skin": 0},
            {"name": "root", "children": [2]},
            {"name": "tip", "translation": [0, 1, 0]},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": positions, "JOINTS_0": joints, "WEIGHTS_0": weights},
                                    "indices": indices}]}],
        "skins": [{"joints": [1, 2], "inverseBindMatrices": ibm}],
        "animations": [{"name": "bend",
                        "samplers": [{"input": times, "output": rotations}, {"input": times, "output": translations}],
                        "channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}},
                                     {"sampler": 1, "target": {"node": 2, "path": "translation"}}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(bin_)}],
    }
    return doc, bin_


def glb(doc, bin_, length=None):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    bin_ = bytes(bin_) + b"\0" * (-len(bin_) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(bin_), 0x004E4942) + bin_
    total = 12 + len(body) if length is None else length
    return struct.pack("<4sII", b"glTF", 2, total) + body


def put_floats(doc, bin_, accessor, index, values):
    """Overwrites element `index` of a float accessor in the buffer."""
    a = doc["accessors"][accessor]
    view = doc["bufferViews"][a["bufferView"]]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}[a["type"]]
    at = view["byteOffset"] + a.get("byteOffset", 0) + 4 * width * index
    bin_[at:at + 4 * len(values)] = struct.pack(f"<{len(values)}f", *values)


# name -> change of (doc, bin); accessors: 0 POSITION, 1 indices, 2 JOINTS_0, 3 WEIGHTS_0,
# 4 inverse binds, 5 key times, 6 rotations, 7 translations.
def acc(i, **fields):
    return lambda d, b: d["accessors"][i].update(fields)


def with_normals(d, b, values):
    """Gives the primitive a NORMAL accessor of these nine floats."""
    while len(b) % 4:
        b.append(0)
    d["bufferViews"].append({"buffer": 0, "byteOffset": len(b), "byteLength": 36})
    b.extend(struct.pack("<9f", *values))
    d["accessors"].append({"bufferView": len(d["bufferViews"]) - 1, "componentType": FLOAT, "count": 3, "type": "VEC3"})
    d["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = len(d["accessors"]) - 1
    d["buffers"][0]["byteLength"] = len(b)


CASES = {
    # The gltf crate panicked on these (exit 101), or its arithmetic overflowed.
    "gltf-indices-float": acc(1, componentType=FLOAT),
    "gltf-joints-float": acc(2, componentType=FLOAT),
    "gltf-weights-uint": acc(3, componentType=UINT),
    "gltf-rotation-keys-uint": acc(6, componentType=UINT),
    "gltf-position-stride-4": lambda d, b: d["bufferViews"][0].update(byteStride=4),
    "gltf-position-vec2": acc(0, type="VEC2"),
    "gltf-inverse-binds-mat3": acc(4, type="MAT3"),
    "gltf-count-zero": acc(0, count=0),
    "gltf-count-2-pow-62": acc(0, count=2**62),
    "gltf-offset-near-2-pow-64": acc(0, byteOffset=2**64 - 8),
    "gltf-sparse-count-zero": acc(0, sparse={"count": 0, "indices": {"bufferView": 1, "componentType": USHORT},
                                            "values": {"bufferView": 0}}),
    # Hangs: the nodes above a skeleton are not a tree.
    "gltf-node-cycle": lambda d, b: d["nodes"].extend([{"name": "up", "children": [1, 4]}, {"name": "upper", "children": [3]}]),
    "gltf-node-own-child": lambda d, b: d["nodes"].append({"name": "up", "children": [3, 1]}),
    # Numbers nobody can use.
    "gltf-inverse-bind-nan": lambda d, b: put_floats(d, b, 4, 1, [math.nan]),
    "gltf-inverse-bind-singular": lambda d, b: put_floats(d, b, 4, 1, [0.0] * 16),
    "gltf-position-inf": lambda d, b: put_floats(d, b, 0, 2, [math.inf]),
    "gltf-key-value-nan": lambda d, b: put_floats(d, b, 7, 1, [math.nan]),
    "gltf-key-time-inf": lambda d, b: put_floats(d, b, 5, 1, [math.inf]),
    "gltf-rotation-key-zero": lambda d, b: put_floats(d, b, 6, 1, [0, 0, 0, 0]),
    "gltf-node-scale-zero": lambda d, b: d["nodes"][2].update(scale=[1, 0, 1]),
    "gltf-node-translation-inf": lambda d, b: d["nodes"][2].update(translation=[0, 1e39, 0]),
    "gltf-node-matrix-singular": lambda d, b: d["nodes"][1].update(matrix=[0.0] * 16),
    "gltf-weight-negative": lambda d, b: put_floats(d, b, 3, 1, [1.5, -0.5]),
    "gltf-weight-nan": lambda d, b: put_floats(d, b, 3, 1, [math.nan, 1.0]),
    "gltf-normal-nan": lambda d, b: with_normals(d, b, [0, 0, 1, 0, 0, 1, 0, math.nan, 1]),
}


def write(name, data):
    with open(os.path.join(OUT, name), "wb") as f:
        f.write(data)


def main():
    for name, change in CASES.items():
        doc, bin_ = base()
        change(doc, bin_)
        write(name + ".glb", glb(doc, bin_))
    doc, bin_ = base()
    # A GLB whose header says it is 4 bytes long.
    write("gltf-header-length-4.glb", glb(doc, bin_, length=4))
    # A clip 3e38 seconds long: valid to read, refused when sampled into frames.
    big = copy.deepcopy(doc)
    long_bin = bytearray(bin_)
    put_floats(big, long_bin, 5, 1, [3e38])
    write(os.path.join("commands", "gltf-clip-3e38-seconds.glb"), glb(big, long_bin))
    # Files named by a model that lie outside its folder.
    for name, uri in [("gltf-uri-absolute", "/etc/passwd"), ("gltf-uri-dotdot", "../../../../etc/passwd")]:
        d = copy.deepcopy(doc)
        d["buffers"][0]["uri"] = uri
        write(name + ".gltf", json.dumps(d, indent=1).encode())
    print(f"wrote {len(CASES) + 4} files to {OUT}")


if __name__ == "__main__":
    main()
