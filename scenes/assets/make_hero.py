#!/usr/bin/env python3
"""Writes hero.glb: a small skinned character (about 1.8 units tall, standing on y = 0, facing +z).

Parts: legs and torso ("suit", with a striped baseColorTexture), arms and hands ("skin"), a head
("face": skin colour plus hadou's feature texture, a face drawn here, in the material's
`extras.hadou.featureTexture`) and a hair cap ("hair", VRMC_materials_mtoon toon shading).

The mesh is stored in a T-pose bind pose and skinned to four joints: hips (root), neck, and two
shoulders. At rest the shoulders are turned 75 degrees down, so the arms hang; the skinned mesh's
own node carries a translation of (0, 3, 0) that the glTF spec says to ignore. A loader that skips
the skin draws the figure floating 3 units up in a T-pose; one that applies it draws it standing
with hanging arms. PNGs are written with zlib + struct (filter byte 0 rows).
Run from this folder: `python3 make_hero.py`.
"""
import json
import math
import struct
import zlib

SUIT, SKIN, FACE, HAIR = range(4)
HIPS, NECK, L_SHOULDER, R_SHOULDER = range(4)
# Bind-pose (T-pose) joint positions; the bind pose has no rotations.
JOINT_POS = [(0.0, 0.9, 0.0), (0.0, 1.45, 0.0), (0.2, 1.4, 0.0), (-0.2, 1.4, 0.0)]
ARM_DROP_DEG = 75.0


class Part:
    def __init__(self):
        self.pos, self.nrm, self.uv, self.joint, self.tris = [], [], [], [], []

    def vert(self, p, n, uv, joint):
        self.pos.append(p)
        self.nrm.append(n)
        self.uv.append(uv)
        self.joint.append(joint)
        return len(self.pos) - 1

    def tri(self, a, b, c):
        # Counter-clockwise seen from outside: the face normal agrees with the vertex normals.
        pa, pb, pc = self.pos[a], self.pos[b], self.pos[c]
        e1 = [pb[i] - pa[i] for i in range(3)]
        e2 = [pc[i] - pa[i] for i in range(3)]
        fn = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
        ns = [self.nrm[a][i] + self.nrm[b][i] + self.nrm[c][i] for i in range(3)]
        if sum(fn[i] * ns[i] for i in range(3)) < 0:
            b, c = c, b
        if sum(f * f for f in fn) > 1e-14:
            self.tris.append((a, b, c))


def norm(v):
    l = math.sqrt(sum(c * c for c in v)) or 1.0
    return tuple(c / l for c in v)


def ellipse_tube(part, center, axis, rx, rz, y0, y1, seg, joint, caps=True):
    """A capped tube along `axis` ('y' or 'x') with an elliptic cross-section."""
    def place(a, s, r1, r2):
        (c0, c1, c2) = center
        if axis == "y":
            return (c0 + r1 * math.sin(a), s, c2 + r2 * math.cos(a)), norm((math.sin(a) / r1, 0, math.cos(a) / r2))
        return (s, c1 + r1 * math.sin(a), c2 + r2 * math.cos(a)), norm((0, math.sin(a) / r1, math.cos(a) / r2))

    rows = []
    for s in (y0, y1):
        row = []
        for j in range(seg + 1):
            a = 2 * math.pi * j / seg
            p, n = place(a, s, rx, rz)
            row.append(part.vert(p, n, (j / seg, 0.0 if s == y0 else 1.0), joint))
        rows.append(row)
    for j in range(seg):
        a, b, c, d = rows[0][j], rows[0][j + 1], rows[1][j + 1], rows[1][j]
        part.tri(a, b, c)
        part.tri(a, c, d)
    if caps:
        for s, sign in ((y0, -1.0), (y1, 1.0)):
            n = (0.0, sign, 0.0) if axis == "y" else (sign, 0.0, 0.0)
            mid_p = (center[0], s, center[2]) if axis == "y" else (s, center[1], center[2])
            mid = part.vert(mid_p, n, (0.5, 0.5), joint)
            ring = [part.vert(place(2 * math.pi * j / seg, s, rx, rz)[0], n, (0.5, 0.5), joint) for j in range(seg)]
            for j in range(seg):
                part.tri(mid, ring[j], ring[(j + 1) % seg])


def sphere(part, center, r, slices, stacks, joint, theta_max=math.pi, scale=(1.0, 1.0, 1.0)):
    """A UV sphere (or a cap down to `theta_max`): u = 0.5 + phi / 2pi with phi = 0 towards +z
    (the seam at the back), v = theta / pi from the top, so the face texture's centre is at +z."""
    rows = []
    for i in range(stacks + 1):
        t = theta_max * i / stacks
        row = []
        for j in range(slices + 1):
            phi = -math.pi + 2 * math.pi * j / slices
            d = (math.sin(t) * math.sin(phi), math.cos(t), math.sin(t) * math.cos(phi))
            p = tuple(center[k] + r * scale[k] * d[k] for k in range(3))
            n = norm(tuple(d[k] / scale[k] for k in range(3)))
            row.append(part.vert(p, n, (0.5 + phi / (2 * math.pi), t / math.pi), joint))
        rows.append(row)
    for i in range(stacks):
        for j in range(slices):
            a, b, c, d = rows[i][j], rows[i][j + 1], rows[i + 1][j + 1], rows[i + 1][j]
            part.tri(a, b, c)
            part.tri(a, c, d)


parts = [Part() for _ in range(4)]
# Legs and torso (suit), bound to the hips.
for x in (0.1, -0.1):
    ellipse_tube(parts[SUIT], (x, 0.0, 0.0), "y", 0.075, 0.08, 0.0, 0.88, 14, HIPS)
ellipse_tube(parts[SUIT], (0.0, 0.0, 0.0), "y", 0.19, 0.11, 0.85, 1.45, 20, HIPS)
# Arms along +-x in the T-pose, with hands, bound to the shoulders; the neck bound to the neck.
for side, joint in ((1.0, L_SHOULDER), (-1.0, R_SHOULDER)):
    x0, x1 = sorted((side * 0.17, side * 0.72))
    ellipse_tube(parts[SKIN], (0.0, 1.4, 0.0), "x", 0.045, 0.045, x0, x1, 12, joint)
    sphere(parts[SKIN], (side * 0.77, 1.4, 0.0), 0.06, 12, 6, joint)
ellipse_tube(parts[SKIN], (0.0, 0.0, 0.0), "y", 0.05, 0.05, 1.43, 1.52, 12, NECK)
# Head (face texture on +z) and a hair cap, bound to the neck.
sphere(parts[FACE], (0.0, 1.62, 0.0), 0.13, 24, 14, NECK, scale=(0.95, 1.1, 1.0))
sphere(parts[HAIR], (0.0, 1.635, -0.01), 0.14, 24, 8, NECK, theta_max=math.radians(80), scale=(0.95, 1.1, 1.0))


def png(w, h, pixel):
    rows = b"".join(b"\0" + bytes(c for x in range(w) for c in pixel(x, y)) for y in range(h))
    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    ihdr = struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b"")


def stripes(x, y):
    return (255, 255, 255, 255) if (y // 4) % 2 == 0 else (200, 200, 215, 255)


FW = FH = 64


def face(x, y):
    u, v = (x + 0.5) / FW, (y + 0.5) / FH
    for eu in (0.5 - 0.07, 0.5 + 0.07):
        if ((u - eu) / 0.035) ** 2 + ((v - 0.45) / 0.05) ** 2 < 1.0:
            return (20, 20, 30, 255)
    if abs(u - 0.5) < 0.045 and abs(v - 0.6) < 0.012:
        return (90, 20, 20, 255)
    return (255, 255, 255, 255)


images = [png(8, 16, stripes), png(FW, FH, face)]

# Binary buffer: per part POSITION, NORMAL, TEXCOORD_0, JOINTS_0 (u8), WEIGHTS_0 (float), indices.
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


primitives = []
for m, part in enumerate(parts):
    n = len(part.pos)
    lo = [min(p[i] for p in part.pos) for i in range(3)]
    hi = [max(p[i] for p in part.pos) for i in range(3)]
    attrs = {
        "POSITION": add_acc(b"".join(struct.pack("<3f", *p) for p in part.pos), 5126, n, "VEC3", 34962,
                            min=lo, max=hi),
        "NORMAL": add_acc(b"".join(struct.pack("<3f", *v) for v in part.nrm), 5126, n, "VEC3", 34962),
        "TEXCOORD_0": add_acc(b"".join(struct.pack("<2f", *t) for t in part.uv), 5126, n, "VEC2", 34962),
        "JOINTS_0": add_acc(b"".join(struct.pack("<4B", j, 0, 0, 0) for j in part.joint), 5121, n, "VEC4", 34962),
        "WEIGHTS_0": add_acc(b"".join(struct.pack("<4f", 1, 0, 0, 0) for _ in part.joint), 5126, n, "VEC4", 34962),
    }
    idx = [i for t in part.tris for i in t]
    ind = add_acc(b"".join(struct.pack("<H", i) for i in idx), 5123, len(idx), "SCALAR", 34963)
    primitives.append({"attributes": attrs, "indices": ind, "material": m, "mode": 4})

image_views = [add_view(img) for img in images]
# Inverse bind matrices: the bind pose is joint translations only.
ibm = b"".join(struct.pack("<16f", 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -p[0], -p[1], -p[2], 1) for p in JOINT_POS)
ibm_acc = add_acc(ibm, 5126, len(JOINT_POS), "MAT4")


def rot_z(deg):
    h = math.radians(deg) / 2
    return [0.0, 0.0, math.sin(h), math.cos(h)]


def local(j, parent):
    return [JOINT_POS[j][i] - (JOINT_POS[parent][i] if parent is not None else 0.0) for i in range(3)]


doc = {
    "asset": {"version": "2.0", "generator": "hadou make_hero.py"},
    "extensionsUsed": ["VRMC_materials_mtoon"],
    "scene": 0,
    "scenes": [{"nodes": [0, 4]}],
    "nodes": [
        {"name": "hips", "translation": local(HIPS, None), "children": [1, 2, 3]},
        {"name": "neck", "translation": local(NECK, HIPS)},
        {"name": "shoulder.L", "translation": local(L_SHOULDER, HIPS), "rotation": rot_z(-ARM_DROP_DEG)},
        {"name": "shoulder.R", "translation": local(R_SHOULDER, HIPS), "rotation": rot_z(ARM_DROP_DEG)},
        {"name": "hero", "mesh": 0, "skin": 0, "translation": [0.0, 3.0, 0.0]},
    ],
    "skins": [{"joints": [0, 1, 2, 3], "skeleton": 0, "inverseBindMatrices": ibm_acc}],
    "meshes": [{"name": "hero", "primitives": primitives}],
    "materials": [
        {"name": "suit", "pbrMetallicRoughness": {"baseColorFactor": [0.12, 0.16, 0.55, 1.0],
                                                  "baseColorTexture": {"index": 0}}},
        {"name": "skin", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.6, 0.45, 1.0]}},
        {"name": "face", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.6, 0.45, 1.0]},
         "extras": {"hadou": {"featureTexture": {"index": 1}}}},
        {"name": "hair", "pbrMetallicRoughness": {"baseColorFactor": [0.08, 0.04, 0.02, 1.0]},
         "extensions": {"VRMC_materials_mtoon": {"specVersion": "1.0", "shadeColorFactor": [0.04, 0.02, 0.01],
                                                 "shadingShiftFactor": 0.0, "shadingToonyFactor": 0.9}}},
    ],
    "samplers": [{"magFilter": 9729, "wrapS": 10497, "wrapT": 10497},
                 {"magFilter": 9729, "wrapS": 33071, "wrapT": 33071}],
    "textures": [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 1}],
    "images": [{"bufferView": image_views[0], "mimeType": "image/png"},
               {"bufferView": image_views[1], "mimeType": "image/png"}],
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
with open("hero.glb", "wb") as f:
    f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
print("hero.glb:", 12 + len(body), "bytes,", sum(len(p.tris) for p in parts), "triangles")
