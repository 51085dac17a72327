#!/usr/bin/env python3
"""Writes mtoon-ball.vrm: three spheres (radius 0.5, 0.9 apart along x, on y = 0.5) with different
VRMC_materials_mtoon 1.0 looks, in a VRM 1.0 file (a GLB whose extensionsUsed names VRMC_vrm).

- "soft" (left): a wide step (toony 0.5) from a blue shade to a striped base texture that scrolls
  (UV animation, 0.25 per second along u), a red parametric rim (lift 0.1, fresnel power 3), an
  outline 0.006 of the image height (screen coordinates) half lit.
- "hard" (middle): a hard step (toony 0.95, shift -0.2) to a dark purple shade, a radial matcap
  texture (factor 0.8), a faint emission, an outline 0.02 units wide (world coordinates) fully lit.
- "painted" (right): a checker shade multiply texture, a shading shift texture (a gradient in u,
  scale 0.4), a rim multiply texture, and a rotating UV animation (0.5 rad/s) masked by the blue
  channel of a mask texture (half the sphere turns).

PNGs are written with zlib + struct (filter byte 0 rows). Run from this folder:
`python3 make_mtoon.py`.
"""
import json
import math
import struct
import zlib

STACKS, SLICES = 16, 24


def png(w, h, pixel):
    rows = b"".join(b"\0" + bytes(c for x in range(w) for c in pixel(x, y)) for y in range(h))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b"")


def stripes(x, y):
    return (255, 240, 200, 255) if (x // 2) % 2 == 0 else (200, 120, 90, 255)


def checker(x, y):
    return (255, 255, 255, 255) if (x // 2 + y // 2) % 2 == 0 else (110, 140, 255, 255)


def gradient(x, y):
    v = int(255 * x / 15)
    return (v, v, v, 255)


def matcap(x, y):
    # A bright spot up and to the left of the centre, dark at the rim.
    u, v = (x + 0.5) / 16 * 2 - 1, (y + 0.5) / 16 * 2 - 1
    d = math.sqrt((u + 0.35) ** 2 + (v + 0.35) ** 2)
    c = max(0.0, 1.0 - d) ** 2
    return (int(255 * c), int(255 * c), int(230 * c + 25), 255)


def rim_mask(x, y):
    return (255, 255, 255, 255) if y < 10 else (60, 60, 60, 255)


def uv_mask(x, y):
    return (0, 0, 255 if x < 8 else 0, 255)


images = [png(16, 16, f) for f in (stripes, checker, gradient, matcap, rim_mask, uv_mask)]
STRIPES, CHECKER, GRADIENT, MATCAP, RIM, MASK = range(6)

blob = bytearray()
views, accessors = [], []


def add_view(data, target=None):
    while len(blob) % 4:
        blob.append(0)
    v = {"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)}
    if target:
        v["target"] = target
    blob.extend(data)
    views.append(v)
    return len(views) - 1


def add_acc(data, ctype, count, typ, target=None, **extra):
    accessors.append(dict({"bufferView": add_view(data, target), "componentType": ctype, "count": count,
                           "type": typ}, **extra))
    return len(accessors) - 1


def sphere(cx):
    pos, nrm, uv = [], [], []
    for i in range(STACKS + 1):
        th = math.pi * i / STACKS
        for j in range(SLICES + 1):
            ph = 2 * math.pi * j / SLICES
            n = (math.sin(th) * math.sin(ph), math.cos(th), math.sin(th) * math.cos(ph))
            nrm.append(n)
            pos.append((cx + 0.5 * n[0], 0.5 + 0.5 * n[1], 0.5 * n[2]))
            uv.append((j / SLICES, i / STACKS))
    idx = []
    for i in range(STACKS):
        for j in range(SLICES):
            a, b = i * (SLICES + 1) + j, (i + 1) * (SLICES + 1) + j
            # Counter-clockwise seen from outside.
            idx += [a, b, a + 1, a + 1, b, b + 1]
    return pos, nrm, uv, idx


primitives = []
for m, cx in enumerate((-0.9, 0.0, 0.9)):
    pos, nrm, uv, idx = sphere(cx)
    n = len(pos)
    lo = [min(p[i] for p in pos) for i in range(3)]
    hi = [max(p[i] for p in pos) for i in range(3)]
    attrs = {
        "POSITION": add_acc(b"".join(struct.pack("<3f", *p) for p in pos), 5126, n, "VEC3", 34962, min=lo, max=hi),
        "NORMAL": add_acc(b"".join(struct.pack("<3f", *v) for v in nrm), 5126, n, "VEC3", 34962),
        "TEXCOORD_0": add_acc(b"".join(struct.pack("<2f", *t) for t in uv), 5126, n, "VEC2", 34962),
    }
    ind = add_acc(b"".join(struct.pack("<H", i) for i in idx), 5123, len(idx), "SCALAR", 34963)
    primitives.append({"attributes": attrs, "indices": ind, "material": m, "mode": 4})

image_views = [add_view(img) for img in images]

doc = {
    "asset": {"version": "2.0", "generator": "hadou make_mtoon.py"},
    "extensionsUsed": ["VRMC_vrm", "VRMC_materials_mtoon"],
    "extensions": {"VRMC_vrm": {
        "specVersion": "1.0",
        "meta": {"name": "mtoon-ball", "version": "1", "authors": ["hadou"],
                 "licenseUrl": "https://vrm.dev/licenses/1.0/"},
        "humanoid": {"humanBones": {"hips": {"node": 0}}},
    }},
    "scene": 0,
    "scenes": [{"nodes": [0]}],
    "nodes": [{"name": "balls", "mesh": 0}],
    "meshes": [{"name": "balls", "primitives": primitives}],
    "materials": [
        {"name": "soft", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                                                  "baseColorTexture": {"index": STRIPES}},
         "extensions": {"VRMC_materials_mtoon": {
             "specVersion": "1.0", "shadeColorFactor": [0.15, 0.2, 0.45], "shadingToonyFactor": 0.5,
             "parametricRimColorFactor": [0.9, 0.15, 0.1], "parametricRimLiftFactor": 0.1,
             "parametricRimFresnelPowerFactor": 3.0, "rimLightingMixFactor": 0.5,
             "uvAnimationScrollXSpeedFactor": 0.25, "outlineWidthMode": "screenCoordinates",
             "outlineWidthFactor": 0.006, "outlineColorFactor": [0.1, 0.05, 0.3], "outlineLightingMixFactor": 0.5}}},
        {"name": "hard", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.75, 0.55, 1.0]},
         "emissiveFactor": [0.03, 0.01, 0.0],
         "extensions": {"VRMC_materials_mtoon": {
             "specVersion": "1.0", "shadeColorFactor": [0.2, 0.08, 0.25], "shadingToonyFactor": 0.95,
             "shadingShiftFactor": -0.2, "matcapFactor": [0.8, 0.8, 0.8], "matcapTexture": {"index": MATCAP},
             "rimLightingMixFactor": 1.0, "outlineWidthMode": "worldCoordinates", "outlineWidthFactor": 0.02,
             "outlineColorFactor": [0.25, 0.05, 0.1], "outlineLightingMixFactor": 1.0}}},
        {"name": "painted", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.85, 1.0]},
         "extensions": {"VRMC_materials_mtoon": {
             "specVersion": "1.0", "shadeColorFactor": [0.45, 0.35, 0.5],
             "shadeMultiplyTexture": {"index": CHECKER}, "shadingToonyFactor": 0.8,
             "shadingShiftTexture": {"index": GRADIENT, "scale": 0.4}, "shadingShiftFactor": -0.2,
             "parametricRimColorFactor": [0.1, 0.3, 0.45], "parametricRimFresnelPowerFactor": 4.0,
             "rimMultiplyTexture": {"index": RIM}, "rimLightingMixFactor": 0.0,
             "uvAnimationMaskTexture": {"index": MASK}, "uvAnimationRotationSpeedFactor": 0.5}}},
    ],
    "samplers": [{"magFilter": 9728, "wrapS": 10497, "wrapT": 10497},
                 {"magFilter": 9729, "wrapS": 33071, "wrapT": 33071}],
    "textures": [{"source": i, "sampler": 1 if i in (MATCAP, GRADIENT) else 0} for i in range(len(images))],
    "images": [{"bufferView": v, "mimeType": "image/png"} for v in image_views],
    "buffers": [{"byteLength": 0}],
    "bufferViews": views,
    "accessors": accessors,
}
while len(blob) % 4:
    blob.append(0)
doc["buffers"][0]["byteLength"] = len(blob)
js = json.dumps(doc, separators=(",", ":")).encode()
js += b" " * (-len(js) % 4)
body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(blob), 0x004E4942) + bytes(blob)
with open("mtoon-ball.vrm", "wb") as f:
    f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
print("mtoon-ball.vrm:", 12 + len(body), "bytes,", sum(len(p["attributes"]) for p in primitives), "attributes")
