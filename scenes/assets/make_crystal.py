#!/usr/bin/env python3
"""Writes crystal.glb: a small two-node glTF 2.0 asset used by scenes/kamehameha.toml.

A stretched octahedron (the parent node, scaled 1 x 2 x 1) with a smaller, tilted octahedron as a
child node offset to its side: it exercises node transforms, u16 indices and normals computed by
the loader (the file stores none). Run from this folder: `python3 make_crystal.py`.
"""
import json
import struct

POS = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
# Counter-clockwise seen from outside.
TRIS = [
    (0, 2, 4), (4, 2, 1), (1, 2, 5), (5, 2, 0),
    (4, 3, 0), (1, 3, 4), (5, 3, 1), (0, 3, 5),
]
# Flat shading: unshared vertices per face.
positions = [POS[i] for t in TRIS for i in t]
indices = list(range(len(positions)))

pos_bytes = b"".join(struct.pack("<3f", *p) for p in positions)
idx_bytes = b"".join(struct.pack("<H", i) for i in indices)
idx_bytes += b"\0" * (-len(idx_bytes) % 4)
blob = pos_bytes + idx_bytes

doc = {
    "asset": {"version": "2.0", "generator": "hadou make_crystal.py"},
    "scene": 0,
    "scenes": [{"nodes": [0]}],
    "nodes": [
        {"mesh": 0, "scale": [1.0, 2.0, 1.0], "children": [1]},
        {"mesh": 0, "translation": [1.4, -0.5, 0.3], "scale": [0.45, 0.45, 0.45],
         "rotation": [0.0, 0.0, 0.3826834, 0.9238795]},
    ],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}]}],
    "buffers": [{"byteLength": len(blob)}],
    "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": len(pos_bytes), "target": 34962},
        {"buffer": 0, "byteOffset": len(pos_bytes), "byteLength": len(indices) * 2, "target": 34963},
    ],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
         "min": [-1, -1, -1], "max": [1, 1, 1]},
        {"bufferView": 1, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
    ],
}
js = json.dumps(doc, separators=(",", ":")).encode()
js += b" " * (-len(js) % 4)
body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(blob), 0x004E4942) + blob
with open("crystal.glb", "wb") as f:
    f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
