#!/usr/bin/env python3
"""Writes the animated test characters (deterministically; python3 stdlib only):

- brace.glb: a skinned character (about 1.8 units tall, standing on y = 0, facing +z) with 19
  joints (hips -> spine -> chest -> neck -> head; shoulders -> upper arms -> lower arms -> hands;
  upper legs -> lower legs -> feet). The mesh is stored in a T-pose bind pose; at rest the upper
  arms are turned 60 degrees down. Vertices between two joints of a chain blend the two (u8
  normalised WEIGHTS_0, u8 JOINTS_0). The head is a mesh of its own with the morph targets
  `blink` and `aa` (POSITION and NORMAL deltas, names in `mesh.extras.targetNames`, default
  `weights` [0, 0.25]); a rigid headband hangs on a node under the head joint. The skinned body
  node carries a translation of (0, 3, 0) that the glTF spec says to ignore. Clips:
  `brace` (LINEAR, 0-2 s: the torso turns towards +x, the forearms rise in front of the face, the
  knees bend and the hips drop; two consecutive hips keys are stored with opposite quaternion
  signs; the headband's `scale` pulses), `step` (STEP), `cubic` (CUBICSPLINE on translation,
  rotation and scale with non-zero tangents) and `blink` (LINEAR morph `weights`).
- dancer.glb: the bench character, about 50 000 triangles, 65 joints (the body, three joints per
  finger and a 16-joint braid), up to 4 weights per vertex (u16 normalised, u16 JOINTS_0) and one
  looping LINEAR clip `dance` (2 s) that animates every joint.
- brace.vrm: brace.glb's geometry as a VRM 1.0 avatar (`VRMC_vrm` humanoid, meta, expressions
  bound to the head's morph targets; `VRMC_materials_mtoon` on every material), T-pose at rest.
- brace0.vrm: the same as a VRM 0.x avatar (the `VRM` extension: humanoid bone list, blend shape
  groups, MToon `materialProperties`), turned 180 degrees about y (VRM 0.x faces -z).
- blast.vrm: brace.vrm with twelve hair strands (nine joints each) down the back of the head and a
  skirt of sixteen strands (seven joints each) round the hips, every strand a VRMC_springBone
  spring (the last joint of each only its tail: 192 joints turn), with sphere and capsule colliders
  on the head, chest and upper legs; what a wave's wind blows (scenes/light-blast.toml).
- showcase.vrm: blast.vrm with sixteen golden hair strands (ten joints each, down to the shoulders)
  and a longer skirt of twenty strands (eight joints each): the character of scenes/showcase.toml
  (u16 joint indices: 339 joints).
- brace.vrma: a `VRMC_vrm_animation` 1.0 clip `brace` on a humanoid skeleton of nodes whose upper
  arms rest 10 degrees lower than brace.vrm's, with a bone the avatars lack (leftThumbProximal) and
  a `blink` expression track (the expression node's translation x).
- showcase.vrma: the same clip without leftThumbProximal (every bone it names, the avatars have).

Run from this folder: `python3 make_brace.py`.
"""
import json
import math
import struct
import zlib

# ---------------------------------------------------------------------------------------------
# Small maths on tuples: quaternions are (x, y, z, w) as in glTF.


def norm(v):
    l = math.sqrt(sum(c * c for c in v)) or 1.0
    return tuple(c / l for c in v)


def q_axis(axis, deg):
    h = math.radians(deg) / 2
    s = math.sin(h)
    return {"x": (s, 0.0, 0.0, math.cos(h)), "y": (0.0, s, 0.0, math.cos(h)), "z": (0.0, 0.0, s, math.cos(h))}[axis]


def q_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def q_rot(*pairs):
    """The product of axis rotations, applied right to left."""
    q = (0.0, 0.0, 0.0, 1.0)
    for axis, deg in pairs:
        q = q_mul(q, q_axis(axis, deg))
    return q


def mirror_q(q):
    """The rotation mirrored through the x = 0 plane (for the right side)."""
    return (q[0], -q[1], -q[2], q[3])


def neg(q):
    return tuple(-c for c in q)


def r4(v):
    """Values written to JSON are rounded, so the text does not depend on the last bits of libm."""
    return [round(c, 7) + 0.0 for c in v]


# ---------------------------------------------------------------------------------------------
# Skeletons.

class Skeleton:
    def __init__(self):
        self.names, self.parent, self.pos = [], [], []

    def add(self, name, parent, pos):
        self.names.append(name)
        self.parent.append(parent)
        self.pos.append(tuple(pos))
        return len(self.names) - 1

    def index(self, name):
        return self.names.index(name)


def body_skeleton(fingers=False, braid=0):
    s = Skeleton()
    hips = s.add("hips", None, (0.0, 0.95, 0.0))
    spine = s.add("spine", hips, (0.0, 1.08, 0.0))
    chest = s.add("chest", spine, (0.0, 1.25, 0.0))
    neck = s.add("neck", chest, (0.0, 1.45, 0.0))
    s.add("head", neck, (0.0, 1.53, 0.0))
    for side, tag in ((1.0, "L"), (-1.0, "R")):
        sh = s.add("shoulder." + tag, chest, (side * 0.05, 1.40, 0.0))
        ua = s.add("upperArm." + tag, sh, (side * 0.18, 1.40, 0.0))
        la = s.add("lowerArm." + tag, ua, (side * 0.45, 1.40, 0.0))
        s.add("hand." + tag, la, (side * 0.70, 1.40, 0.0))
    for side, tag in ((1.0, "L"), (-1.0, "R")):
        ul = s.add("upperLeg." + tag, hips, (side * 0.1, 0.90, 0.0))
        ll = s.add("lowerLeg." + tag, ul, (side * 0.1, 0.50, 0.0))
        s.add("foot." + tag, ll, (side * 0.1, 0.08, 0.0))
    if fingers:
        for side, tag in ((1.0, "L"), (-1.0, "R")):
            hand = s.index("hand." + tag)
            for f, z in enumerate((0.045, 0.022, 0.0, -0.022, -0.044)):
                x0 = 0.74 if f == 0 else 0.79
                p = hand
                for k in range(3):
                    p = s.add("finger%d.%d.%s" % (f, k, tag), p, (side * (x0 + 0.03 * k), 1.40 - (0.02 if f == 0 else 0.0), z))
    if braid:
        p = s.index("head")
        for k in range(braid):
            p = s.add("braid.%d" % k, p, (0.0, 1.62 - 0.06 * k, -0.15 - 0.004 * k))
    return s


# ---------------------------------------------------------------------------------------------
# Geometry: parts of vertices with skin influences.

class Part:
    def __init__(self):
        self.pos, self.nrm, self.uv, self.infl, self.tris = [], [], [], [], []

    def vert(self, p, n, uv, infl):
        self.pos.append(tuple(p))
        self.nrm.append(tuple(n))
        self.uv.append(tuple(uv))
        self.infl.append(infl)
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


def chain2(joints, centres):
    """Influences along a chain: linear between consecutive bone centres (two joints blend),
    clamped to the first and last joint beyond the ends."""
    def f(t):
        if t <= centres[0]:
            return [(joints[0], 1.0)]
        for i in range(len(centres) - 1):
            if t <= centres[i + 1]:
                u = (t - centres[i]) / (centres[i + 1] - centres[i])
                return [(joints[i], 1.0 - u), (joints[i + 1], u)]
        return [(joints[-1], 1.0)]
    return f


def chain4(joints, centres, radius):
    """Influences along a chain: hat functions of `radius` around the bone centres, the four
    largest kept (a braid bends smoothly over several joints)."""
    def f(t):
        t = min(max(t, centres[0]), centres[-1])
        w = [(j, max(0.0, 1.0 - abs(t - c) / radius)) for j, c in zip(joints, centres)]
        w = sorted((x for x in w if x[1] > 0.0), key=lambda x: -x[1])[:4]
        return w
    return f


def const(j):
    return lambda t: [(j, 1.0)]


def tube(part, centre, axis, rx, rz, s0, s1, seg, rings, infl, caps=True, t_sign=1.0):
    """A tube along `axis` ('x' or 'y') from s0 to s1 with an elliptic cross-section, `rings`
    rows of vertices; `infl(t)` gives the skin influences at t = t_sign * s."""
    def place(a, s):
        c0, c1, c2 = centre
        if axis == "y":
            return (c0 + rx * math.sin(a), s, c2 + rz * math.cos(a)), norm((math.sin(a) / rx, 0, math.cos(a) / rz))
        return (s, c1 + rx * math.sin(a), c2 + rz * math.cos(a)), norm((0, math.sin(a) / rx, math.cos(a) / rz))

    rows = []
    for i in range(rings + 1):
        s = s0 + (s1 - s0) * i / rings
        w = infl(t_sign * s)
        row = []
        for j in range(seg + 1):
            a = 2 * math.pi * j / seg
            p, n = place(a, s)
            row.append(part.vert(p, n, (j / seg, i / rings), w))
        rows.append(row)
    for i in range(rings):
        for j in range(seg):
            a, b, c, d = rows[i][j], rows[i][j + 1], rows[i + 1][j + 1], rows[i + 1][j]
            part.tri(a, b, c)
            part.tri(a, c, d)
    if caps:
        for s, sign in ((s0, -1.0), (s1, 1.0)):
            n = (0.0, sign, 0.0) if axis == "y" else (sign, 0.0, 0.0)
            w = infl(t_sign * s)
            mid_p = (centre[0], s, centre[2]) if axis == "y" else (s, centre[1], centre[2])
            mid = part.vert(mid_p, n, (0.5, 0.5), w)
            ring = [part.vert(place(2 * math.pi * j / seg, s)[0], n, (0.5, 0.5), w) for j in range(seg)]
            for j in range(seg):
                part.tri(mid, ring[j], ring[(j + 1) % seg])


def sphere(part, centre, r, slices, stacks, infl, theta_max=math.pi, scale=(1.0, 1.0, 1.0)):
    """A UV sphere (or a cap down to `theta_max`), phi = 0 towards +z, v = theta / pi from the top;
    `infl(d)` gives the influences for the unit direction d. Returns the vertex ids by row."""
    rows = []
    for i in range(stacks + 1):
        t = theta_max * i / stacks
        row = []
        for j in range(slices + 1):
            phi = -math.pi + 2 * math.pi * j / slices
            d = (math.sin(t) * math.sin(phi), math.cos(t), math.sin(t) * math.cos(phi))
            p = tuple(centre[k] + r * scale[k] * d[k] for k in range(3))
            n = norm(tuple(d[k] / scale[k] for k in range(3)))
            row.append(part.vert(p, n, (0.5 + phi / (2 * math.pi), t / math.pi), infl(d)))
        rows.append(row)
    for i in range(stacks):
        for j in range(slices):
            a, b, c, d = rows[i][j], rows[i][j + 1], rows[i + 1][j + 1], rows[i + 1][j]
            part.tri(a, b, c)
            part.tri(a, c, d)
    return rows


def torus(part, R, r, seg, sides):
    """A ring around the y axis at the origin (a rigid part: no influences)."""
    rows = []
    for i in range(seg + 1):
        a = 2 * math.pi * i / seg
        row = []
        for j in range(sides + 1):
            b = 2 * math.pi * j / sides
            n = (math.cos(b) * math.sin(a), math.sin(b), math.cos(b) * math.cos(a))
            p = ((R + r * math.cos(b)) * math.sin(a), r * math.sin(b), (R + r * math.cos(b)) * math.cos(a))
            row.append(part.vert(p, n, (i / seg, j / sides), []))
        rows.append(row)
    for i in range(seg):
        for j in range(sides):
            a, b, c, d = rows[i][j], rows[i + 1][j], rows[i + 1][j + 1], rows[i][j + 1]
            part.tri(a, b, c)
            part.tri(a, c, d)


SUIT, SKIN, HAIR, FACE, BAND = range(5)
MATERIAL_NAMES = ["suit", "skin", "hair", "face", "band"]


def build_body(sk, res, fingers=False, braid=0, wide=False):
    """Parts SUIT, SKIN, HAIR (the body mesh), FACE (the head mesh, with its morph deltas) and
    BAND (the rigid headband, in its node's space). `res` scales every tessellation; `wide`
    blends up to four joints along every chain (hats 1.6 bone spacings wide) instead of two."""
    J = sk.index

    def chain(joints, centres):
        if not wide:
            return chain2(joints, centres)
        return chain4(joints, centres, 1.6 * max(b - a for a, b in zip(centres, centres[1:])))
    parts = [Part() for _ in range(5)]
    R = lambda n: max(3, int(round(n * res)))
    # Torso: hips -> spine -> chest -> neck.
    tj = [J("hips"), J("spine"), J("chest"), J("neck")]
    tube(parts[SUIT], (0.0, 0.0, 0.0), "y", 0.17, 0.1, 0.86, 1.47, R(20), R(14),
         chain(tj, [0.98, 1.16, 1.35, 1.49]))
    # Neck: chest -> neck -> head.
    tube(parts[SKIN], (0.0, 0.0, 0.0), "y", 0.05, 0.05, 1.43, 1.56, R(12), R(4),
         chain([J("chest"), J("neck"), J("head")], [1.42, 1.49, 1.56]))
    for side, tag in ((1.0, "L"), (-1.0, "R")):
        # Legs: along t = -y, hips -> upper leg -> lower leg -> foot.
        lj = [J("hips"), J("upperLeg." + tag), J("lowerLeg." + tag), J("foot." + tag)]
        tube(parts[SUIT], (side * 0.1, 0.0, 0.0), "y", 0.075, 0.08, 0.0, 0.9, R(14), R(22),
             chain(lj, [-0.95, -0.7, -0.29, -0.04]), t_sign=-1.0)
        # Arms: along t = side * x, shoulder -> upper arm -> lower arm -> hand.
        aj = [J("shoulder." + tag), J("upperArm." + tag), J("lowerArm." + tag), J("hand." + tag)]
        x0, x1 = sorted((side * 0.12, side * 0.72))
        tube(parts[SKIN], (0.0, 1.4, 0.0), "x", 0.045, 0.045, x0, x1, R(12), R(16),
             chain(aj, [0.115, 0.315, 0.575, 0.74]), t_sign=side)
        sphere(parts[SKIN], (side * 0.75, 1.4, 0.0), 0.055, R(12), R(6), const(J("hand." + tag)))
        if fingers:
            for f in range(5):
                fj = [J("hand." + tag)] + [J("finger%d.%d.%s" % (f, k, tag)) for k in range(3)]
                base = sk.pos[fj[1]]
                centres = [0.74, 0.79, 0.82, 0.85] if f else [0.72, 0.755, 0.785, 0.815]
                xa, xb = sorted((side * (base[0] * side - 0.01), side * (base[0] * side + 0.095)))
                tube(parts[SKIN], (0.0, base[1], base[2]), "x", 0.009, 0.009, xa, xb, R(8), R(8),
                     chain(fj, centres), t_sign=side)
    # Head mesh (the face material, morph targets) and a hair cap, on the head joint.
    head = J("head")
    rows = sphere(parts[FACE], (0.0, 1.64, 0.0), 0.13, R(24), R(14), const(head), scale=(0.95, 1.1, 1.0))
    sphere(parts[HAIR], (0.0, 1.655, -0.01), 0.14, R(24), R(8), const(head), theta_max=math.radians(80),
           scale=(0.95, 1.1, 1.0))
    if braid:
        bj = [J("braid.%d" % k) for k in range(braid)]
        ys = [sk.pos[j][1] for j in bj]
        centres = [-(y - 0.03) for y in ys]
        tube(parts[HAIR], (0.0, 0.0, -0.17), "y", 0.025, 0.025, ys[-1] - 0.06, ys[0], R(16), R(3 * braid),
             chain4(bj, centres, 0.12), t_sign=-1.0)
    torus(parts[BAND], 0.14, 0.012, R(24), R(8))
    return parts


def face_targets(part):
    """Morph deltas of the head: `blink` closes the eye band on the front, `aa` opens the mouth."""
    cy = 1.64
    blink_p, blink_n, aa_p, aa_n = [], [], [], []
    for p in part.pos:
        dy = (p[1] - cy) / 0.143
        front = max(0.0, p[2] / 0.13)
        eye = front * max(0.0, 1.0 - abs(dy - 0.1) / 0.25) * max(0.0, 1.0 - abs(abs(p[0]) - 0.05) / 0.06)
        mouth = front * max(0.0, 1.0 - abs(dy + 0.35) / 0.25) * max(0.0, 1.0 - abs(p[0]) / 0.06)
        blink_p.append((0.0, -0.012 * eye, 0.004 * eye))
        blink_n.append((0.0, 0.2 * eye, 0.0))
        aa_p.append((0.0, -0.02 * mouth, 0.006 * mouth))
        aa_n.append((0.0, -0.15 * mouth, 0.05 * mouth))
    return [(blink_p, blink_n), (aa_p, aa_n)]


# ---------------------------------------------------------------------------------------------
# Images (PNG via zlib + struct, filter byte 0 rows).

def png(w, h, pixel):
    rows = b"".join(b"\0" + bytes(c for x in range(w) for c in pixel(x, y)) for y in range(h))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    ihdr = struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b"")


def stripes(x, y):
    return (255, 255, 255, 255) if (y // 4) % 2 == 0 else (200, 200, 215, 255)


FW = FH = 64


def face_img(x, y):
    u, v = (x + 0.5) / FW, (y + 0.5) / FH
    for eu in (0.5 - 0.07, 0.5 + 0.07):
        if ((u - eu) / 0.035) ** 2 + ((v - 0.45) / 0.05) ** 2 < 1.0:
            return (20, 20, 30, 255)
    if abs(u - 0.5) < 0.045 and abs(v - 0.6) < 0.012:
        return (90, 20, 20, 255)
    return (255, 255, 255, 255)


def matcap_img(x, y):
    u, v = (x + 0.5) / 16 * 2 - 1, (y + 0.5) / 16 * 2 - 1
    g = max(0.0, 1.0 - (u * u + v * v))
    c = int(round(40 + 200 * g))
    return (c, c, c, 255)


def mask_img(x, y):
    c = int(round(255 * (x + 0.5) / 8))
    return (c, c, c, 255)


# ---------------------------------------------------------------------------------------------
# GLB writer.

class Doc:
    def __init__(self):
        self.blob = bytearray()
        self.views, self.accessors = [], []
        self.cache = {}

    def view(self, data, target=None):
        while len(self.blob) % 4:
            self.blob.append(0)
        v = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target:
            v["target"] = target
        self.blob.extend(data)
        self.views.append(v)
        return len(self.views) - 1

    def acc(self, data, ctype, count, typ, target=None, **extra):
        key = (bytes(data), ctype, count, typ, target, json.dumps(extra, sort_keys=True))
        if key in self.cache:  # the same data is stored once (sampler inputs, repeated keys)
            return self.cache[key]
        self.accessors.append(dict({"bufferView": self.view(data, target), "componentType": ctype, "count": count,
                                    "type": typ}, **extra))
        self.cache[key] = len(self.accessors) - 1
        return self.cache[key]

    def floats(self, vals, typ, target=None, minmax=False):
        width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}[typ]
        flat = [float(c) for v in vals for c in (v if width > 1 else (v,))]
        data = struct.pack("<%df" % len(flat), *flat)
        extra = {}
        if minmax:
            f32 = struct.unpack("<%df" % len(flat), data)
            extra = {"min": [min(f32[i::width]) for i in range(width)], "max": [max(f32[i::width]) for i in range(width)]}
        return self.acc(data, 5126, len(vals), typ, target, **extra)

    def write(self, path, doc):
        while len(self.blob) % 4:
            self.blob.append(0)
        doc["buffers"] = [{"byteLength": len(self.blob)}]
        doc["bufferViews"] = self.views
        doc["accessors"] = self.accessors
        js = json.dumps(doc, separators=(",", ":")).encode()
        js += b" " * (-len(js) % 4)
        body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(self.blob), 0x004E4942) + bytes(self.blob)
        with open(path, "wb") as f:
            f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
        return 12 + len(body)


def quantise(infl, scale):
    """Four (joint, weight) pairs, weights as integers summing to `scale` exactly."""
    infl = sorted(infl, key=lambda x: -x[1])[:4]
    total = sum(w for _, w in infl)
    q = [int(round(w / total * scale)) for _, w in infl]
    q[0] += scale - sum(q)
    js = [j for j, _ in infl] + [0] * (4 - len(infl))
    return js, q + [0] * (4 - len(q))


def primitive(d, part, material, weight_bits, targets=None):
    n = len(part.pos)
    attrs = {
        "POSITION": d.floats(part.pos, "VEC3", 34962, minmax=True),
        "NORMAL": d.floats(part.nrm, "VEC3", 34962),
        "TEXCOORD_0": d.floats(part.uv, "VEC2", 34962),
    }
    if part.infl and part.infl[0]:
        if weight_bits == 8:
            jq = [quantise(i, 255) for i in part.infl]
            attrs["JOINTS_0"] = d.acc(b"".join(struct.pack("<4B", *j) for j, _ in jq), 5121, n, "VEC4", 34962)
            attrs["WEIGHTS_0"] = d.acc(b"".join(struct.pack("<4B", *w) for _, w in jq), 5121, n, "VEC4", 34962,
                                       normalized=True)
        else:
            jq = [quantise(i, 65535) for i in part.infl]
            attrs["JOINTS_0"] = d.acc(b"".join(struct.pack("<4H", *j) for j, _ in jq), 5123, n, "VEC4", 34962)
            attrs["WEIGHTS_0"] = d.acc(b"".join(struct.pack("<4H", *w) for _, w in jq), 5123, n, "VEC4", 34962,
                                       normalized=True)
    idx = [i for t in part.tris for i in t]
    assert n < 65536
    ind = d.acc(struct.pack("<%dH" % len(idx), *idx), 5123, len(idx), "SCALAR", 34963)
    p = {"attributes": attrs, "indices": ind, "material": material, "mode": 4}
    if targets:
        p["targets"] = [{"POSITION": d.floats(dp, "VEC3", minmax=True), "NORMAL": d.floats(dn, "VEC3")}
                        for dp, dn in targets]
    return p


def add_images(d, doc, imgs):
    doc["images"] = [{"bufferView": d.view(img), "mimeType": "image/png"} for img in imgs]
    doc["samplers"] = [{"magFilter": 9729, "wrapS": 10497, "wrapT": 10497},
                       {"magFilter": 9729, "wrapS": 33071, "wrapT": 33071}]
    doc["textures"] = [{"source": i, "sampler": 0 if i == 0 else 1} for i in range(len(imgs))]


TEX_STRIPES, TEX_FACE, TEX_MATCAP, TEX_MASK = range(4)
BASE_COLOURS = {"suit": [0.12, 0.16, 0.55, 1.0], "skin": [0.9, 0.6, 0.45, 1.0], "hair": [0.08, 0.04, 0.02, 1.0],
                "face": [0.9, 0.6, 0.45, 1.0], "band": [0.85, 0.1, 0.12, 1.0]}
SHADE_COLOURS = {"suit": [0.05, 0.06, 0.25], "skin": [0.7, 0.4, 0.35], "hair": [0.04, 0.02, 0.01],
                 "face": [0.7, 0.4, 0.35], "band": [0.4, 0.03, 0.05]}


def materials(full_mtoon):
    out = []
    for name in MATERIAL_NAMES:
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": BASE_COLOURS[name]}}
        if name == "suit":
            m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": TEX_STRIPES}
        if name == "face":
            m["extras"] = {"hadou": {"featureTexture": {"index": TEX_FACE}}}
        if full_mtoon:
            m["extensions"] = {"VRMC_materials_mtoon": mtoon(name)}
        elif name == "hair":
            m["extensions"] = {"VRMC_materials_mtoon": {"specVersion": "1.0", "shadeColorFactor": SHADE_COLOURS[name],
                                                        "shadingShiftFactor": 0.0, "shadingToonyFactor": 0.9}}
        out.append(m)
    return out


def mtoon(name):
    """A VRMC_materials_mtoon 1.0 object with every property set."""
    return {
        "specVersion": "1.0",
        "transparentWithZWrite": False,
        "renderQueueOffsetNumber": 0,
        "shadeColorFactor": SHADE_COLOURS[name],
        "shadeMultiplyTexture": {"index": TEX_STRIPES if name == "suit" else TEX_MASK, "texCoord": 0},
        "shadingShiftFactor": -0.1,
        "shadingShiftTexture": {"index": TEX_MASK, "texCoord": 0, "scale": 0.5},
        "shadingToonyFactor": 0.9,
        "giEqualizationFactor": 0.9,
        "matcapFactor": [0.2, 0.2, 0.25],
        "matcapTexture": {"index": TEX_MATCAP, "texCoord": 0},
        "parametricRimColorFactor": [0.6, 0.7, 1.0],
        "rimMultiplyTexture": {"index": TEX_MASK, "texCoord": 0},
        "rimLightingMixFactor": 0.5,
        "parametricRimFresnelPowerFactor": 4.0,
        "parametricRimLiftFactor": 0.1,
        "outlineWidthMode": "worldCoordinates",
        "outlineWidthFactor": 0.004,
        "outlineWidthMultiplyTexture": {"index": TEX_MASK, "texCoord": 0},
        "outlineColorFactor": [0.05, 0.03, 0.08],
        "outlineLightingMixFactor": 1.0,
        "uvAnimationMaskTexture": {"index": TEX_MASK, "texCoord": 0},
        "uvAnimationScrollXSpeedFactor": 0.1 if name == "band" else 0.0,
        "uvAnimationScrollYSpeedFactor": 0.0,
        "uvAnimationRotationSpeedFactor": 0.0,
    }


def mtoon0(name):
    """The VRM 0.x MToon material of the same look."""
    b, s = BASE_COLOURS[name], SHADE_COLOURS[name]
    return {
        "name": name, "shader": "VRM/MToon", "renderQueue": 2000,
        "floatProperties": {"_Cutoff": 0.5, "_BumpScale": 1.0, "_ReceiveShadowRate": 1.0, "_ShadingGradeRate": 1.0,
                            "_ShadeShift": -0.1, "_ShadeToony": 0.9, "_LightColorAttenuation": 0.0,
                            "_IndirectLightIntensity": 0.1, "_RimLightingMix": 0.5, "_RimFresnelPower": 4.0,
                            "_RimLift": 0.1, "_OutlineWidth": 0.4, "_OutlineScaledMaxDistance": 1.0,
                            "_OutlineLightingMix": 1.0, "_UvAnimScrollX": 0.1 if name == "band" else 0.0,
                            "_UvAnimScrollY": 0.0, "_UvAnimRotation": 0.0, "_MToonVersion": 38.0,
                            "_DebugMode": 0.0, "_BlendMode": 0.0, "_OutlineWidthMode": 1.0,
                            "_OutlineColorMode": 1.0, "_CullMode": 2.0, "_OutlineCullMode": 1.0, "_SrcBlend": 1.0,
                            "_DstBlend": 0.0, "_ZWrite": 1.0},
        "vectorProperties": {"_Color": b, "_ShadeColor": s + [1.0], "_RimColor": [0.6, 0.7, 1.0, 1.0],
                             "_OutlineColor": [0.05, 0.03, 0.08, 1.0], "_EmissionColor": [0.0, 0.0, 0.0, 1.0],
                             "_MainTex": [0.0, 0.0, 1.0, 1.0], "_ShadeTexture": [0.0, 0.0, 1.0, 1.0]},
        "textureProperties": dict({"_ShadeTexture": TEX_MASK, "_SphereAdd": TEX_MATCAP,
                                   "_OutlineWidthTexture": TEX_MASK, "_RimTexture": TEX_MASK},
                                  **({"_MainTex": TEX_STRIPES} if name == "suit" else {})),
        "keywordMap": {"MTOON_OUTLINE_WIDTH_WORLD": True, "MTOON_OUTLINE_COLOR_MIXED": True},
        "tagMap": {"RenderType": "Opaque"},
    }


# ---------------------------------------------------------------------------------------------
# Animation.

def add_clip(d, name, channels):
    """`channels`: (node, path, interpolation, times, values) with values already flattened per
    key (CUBICSPLINE: in-tangent, value, out-tangent per key; weights: every target per key)."""
    samplers, chans = [], []
    for node, path, interp, times, values in channels:
        typ = {"translation": "VEC3", "scale": "VEC3", "rotation": "VEC4", "weights": "SCALAR"}[path]
        inp = d.floats(times, "SCALAR", minmax=True)
        out = d.floats(values, typ)
        samplers.append({"input": inp, "output": out, "interpolation": interp})
        chans.append({"sampler": len(samplers) - 1, "target": {"node": node, "path": path}})
    return {"name": name, "channels": chans, "samplers": samplers}


def v3(a, b):
    return tuple(a[i] + b[i] for i in range(3))


def brace_clips(sk, nodes_rest, band_node, head_mesh_node, arm_rest):
    """The four clips of brace.glb (node indices equal joint indices)."""
    J = sk.index
    T = [0.0, 0.5, 1.0, 1.5, 2.0]
    hips_t = nodes_rest[J("hips")]["translation"]
    drop = [(0, 0, 0), (0, -0.04, 0), (-0.03, -0.12, 0), (-0.04, -0.15, 0.01), (-0.04, -0.15, 0.01)]
    hips_r = [q_rot(), q_rot(("y", 10)), q_rot(("y", 20)), neg(q_rot(("y", 25), ("x", 3))), q_rot(("y", 25), ("z", 2))]
    spine = [q_rot(("y", 10 * k)) for k in (0, 0.6, 1, 1.2, 1.2)]
    chest = [q_rot(("y", 15 * k), ("x", -8 * k)) for k in (0, 0.5, 1, 1.1, 1.1)]
    head = [q_rot(("y", -12 * k), ("x", 6 * k)) for k in (0, 0.4, 1, 1, 1)]
    ua = [q_rot(("y", -75 * k), ("z", -ARM_DROP + 35 * k)) for k in (0, 0.4, 0.9, 1, 1)]
    la = [q_rot(("z", 105 * k)) for k in (0, 0.3, 0.9, 1, 1)]
    ul = [q_rot(("x", -40 * k)) for k in (0, 0.4, 1, 1, 1)]
    ll = [q_rot(("x", 75 * k)) for k in (0, 0.4, 1, 1, 1)]
    ft = [q_rot(("x", -35 * k)) for k in (0, 0.4, 1, 1, 1)]
    ch = [(J("hips"), "translation", "LINEAR", T, [v3(hips_t, dd) for dd in drop]),
          (J("hips"), "rotation", "LINEAR", T, hips_r),
          (J("spine"), "rotation", "LINEAR", T, spine),
          (J("chest"), "rotation", "LINEAR", T, chest),
          (J("head"), "rotation", "LINEAR", T, head)]
    for tag, mir in (("L", lambda q: q), ("R", mirror_q)):
        ch += [(J("upperArm." + tag), "rotation", "LINEAR", T, [mir(q) for q in ua]),
               (J("lowerArm." + tag), "rotation", "LINEAR", T, [mir(q) for q in la]),
               (J("upperLeg." + tag), "rotation", "LINEAR", T, [mir(q) for q in ul]),
               (J("lowerLeg." + tag), "rotation", "LINEAR", T, [mir(q) for q in ll]),
               (J("foot." + tag), "rotation", "LINEAR", T, [mir(q) for q in ft])]
    ch.append((band_node, "scale", "LINEAR", T, [(1, 1, 1), (1.1, 0.9, 1.1), (1, 1, 1), (1.15, 1.0, 1.15), (1, 1, 1)]))
    brace = ch

    TS = [0.0, 0.5, 1.0, 1.5]
    step = [(J("hips"), "translation", "STEP", TS, [v3(hips_t, dd) for dd in [(0, 0, 0), (0, -0.05, 0.05), (0.05, 0, 0.1), (0, 0, 0)]]),
            (J("chest"), "rotation", "STEP", TS, [q_rot(), q_rot(("y", 30)), q_rot(("y", -30), ("x", 10)), q_rot()]),
            (J("head"), "rotation", "STEP", TS, [q_rot(), q_rot(("x", 15)), q_rot(("x", -10), ("z", 8)), q_rot()]),
            (J("upperArm.L"), "rotation", "STEP", TS, [arm_rest, q_rot(("z", 20)), q_rot(("y", -40)), arm_rest])]

    TC = [0.0, 0.6, 1.2]
    def cub(vals, tans):
        out = []
        for v, (ti, to) in zip(vals, tans):
            out += [ti, v, to]
        return out
    tr = [v3(hips_t, dd) for dd in [(0, 0, 0), (0.05, -0.08, 0.02), (0, 0, 0)]]
    tr_t = [((0, 0, 0), (0.1, -0.2, 0.05)), ((0.05, 0.0, -0.1), (-0.1, 0.15, 0.0)), ((-0.2, 0.1, 0.0), (0, 0, 0))]
    rq = [q_rot(), q_rot(("y", 35), ("x", -10)), q_rot(("y", -10))]
    rq_t = [((0, 0, 0, 0), (0.0, 0.4, 0.0, -0.05)), ((0.1, 0.2, 0.0, -0.1), (-0.1, -0.3, 0.05, 0.0)),
            ((0.0, -0.2, 0.1, 0.05), (0, 0, 0, 0))]
    sc = [(1, 1, 1), (1.08, 0.94, 1.08), (1, 1, 1)]
    sc_t = [((0, 0, 0), (0.2, -0.1, 0.2)), ((0.1, 0.0, 0.1), (-0.1, 0.05, -0.1)), ((-0.2, 0.1, -0.2), (0, 0, 0))]
    ua_t = [((0, 0, 0, 0), (0.0, 0.0, 0.5, 0.0)), ((0.0, 0.2, 0.2, 0.0), (0.0, -0.2, 0.3, 0.0)),
            ((0.0, 0.0, -0.4, 0.1), (0, 0, 0, 0))]
    cubic = [(J("hips"), "translation", "CUBICSPLINE", TC, cub(tr, tr_t)),
             (J("chest"), "rotation", "CUBICSPLINE", TC, cub(rq, rq_t)),
             (J("chest"), "scale", "CUBICSPLINE", TC, cub(sc, sc_t)),
             (J("upperArm.R"), "rotation", "CUBICSPLINE", TC,
              cub([mirror_q(arm_rest), q_rot(("z", 40)), mirror_q(arm_rest)], ua_t))]

    TB = [0.0, 0.1, 0.2, 0.6, 0.8, 1.0]
    wts = [(0.0, 0.25), (1.0, 0.3), (0.0, 0.25), (0.0, 0.25), (0.3, 0.9), (0.0, 0.25)]
    blink = [(head_mesh_node, "weights", "LINEAR", TB, [w for pair in wts for w in pair])]
    return [("brace", brace), ("step", step), ("cubic", cubic), ("blink", blink)]


# ---------------------------------------------------------------------------------------------
# brace.glb / brace.vrm / brace0.vrm


def rot_y180_point(p):
    return (-p[0], p[1], -p[2])


def rot_y180_q(q):
    return q_mul(q_mul((0.0, 1.0, 0.0, 0.0), q), (0.0, -1.0, 0.0, 0.0))


ARM_DROP = 60.0
HUMAN = {"hips": "hips", "spine": "spine", "chest": "chest", "neck": "neck", "head": "head"}
for _t, _s in (("L", "left"), ("R", "right")):
    HUMAN.update({"shoulder." + _t: _s + "Shoulder", "upperArm." + _t: _s + "UpperArm",
                  "lowerArm." + _t: _s + "LowerArm", "hand." + _t: _s + "Hand",
                  "upperLeg." + _t: _s + "UpperLeg", "lowerLeg." + _t: _s + "LowerLeg", "foot." + _t: _s + "Foot"})


# The strands of the avatars with spring bones: per part, (strands, joints per strand, top y, joint
# spacing, the tube's two radii). showcase.vrm's hair is longer and thicker (down to the shoulders)
# and its skirt longer, so the wind's work reads at a glance.
STRANDS = {
    "blast": {"hair": (12, 9, 1.66, 0.035, (0.014, 0.008)), "skirt": (16, 7, 1.0, 0.045, (0.03, 0.012))},
    "showcase": {"hair": (16, 10, 1.68, 0.05, (0.024, 0.01)), "skirt": (20, 8, 1.0, 0.05, (0.035, 0.012))},
}


def add_strands(sk, kind):
    """The hair strands (on the head) and skirt strands (on the hips) of blast.vrm or
    showcase.vrm: lists of joints."""
    hair, skirt = [], []
    head, hips = sk.index("head"), sk.index("hips")
    n, joints, top, step, _ = STRANDS[kind]["hair"]
    for k in range(n):
        a = math.radians(105.0 + 150.0 * k / (n - 1))
        x, z = 0.125 * math.sin(a), 0.125 * math.cos(a) - 0.01
        p, chain = head, []
        for i in range(joints):
            p = sk.add("hair.%d.%d" % (k, i), p, (x, top - step * i, z))
            chain.append(p)
        hair.append(chain)
    n, joints, top, step, _ = STRANDS[kind]["skirt"]
    for k in range(n):
        a = 2 * math.pi * (k + 0.5) / n
        x, z = 0.2 * math.sin(a), 0.13 * math.cos(a)
        p, chain = hips, []
        for i in range(joints):
            p = sk.add("skirt.%d.%d" % (k, i), p, (x, top - step * i, z))
            chain.append(p)
        skirt.append(chain)
    return hair, skirt


def strand_geometry(sk, parts, hair, skirt, kind):
    """A thin tube down every strand, each segment bent by the joint above it."""
    (_, _, _, hair_step, hair_r), (_, _, _, skirt_step, skirt_r) = STRANDS[kind]["hair"], STRANDS[kind]["skirt"]
    for chains, part, r, seg, step in ((hair, parts[HAIR], hair_r, 5, hair_step),
                                      (skirt, parts[SUIT], skirt_r, 6, skirt_step)):
        for chain in chains:
            x, y0, z = sk.pos[chain[0]]
            y1 = sk.pos[chain[-1]][1]
            centres = [-(sk.pos[j][1] - 0.5 * step) for j in chain[:-1]]
            tube(part, (x, 0.0, z), "y", r[0], r[1], y1, y0, seg, len(chain) - 1,
                 chain4(chain[:-1], centres, step), t_sign=-1.0)


def spring_bones(hair, skirt, J):
    """VRMC_springBone for blast.vrm: a spring per strand, colliders on head, chest and legs."""
    colliders = [
        {"node": J("head"), "shape": {"sphere": {"offset": [0.0, 0.11, 0.0], "radius": 0.13}}},
        {"node": J("chest"), "shape": {"capsule": {"offset": [0.0, -0.12, 0.0], "tail": [0.0, 0.12, 0.0],
                                                   "radius": 0.11}}},
        {"node": J("upperLeg.L"), "shape": {"capsule": {"offset": [0.0, 0.0, 0.0], "tail": [0.0, -0.4, 0.0],
                                                        "radius": 0.08}}},
        {"node": J("upperLeg.R"), "shape": {"capsule": {"offset": [0.0, 0.0, 0.0], "tail": [0.0, -0.4, 0.0],
                                                        "radius": 0.08}}},
    ]
    groups = [{"name": "head", "colliders": [0, 1]}, {"name": "legs", "colliders": [2, 3]}]
    springs = []
    for chains, name, group, params in ((hair, "hair", 0, (0.6, 0.4, 0.4, 0.012)),
                                         (skirt, "skirt", 1, (1.0, 0.3, 0.5, 0.02))):
        st, gp, dr, hr = params
        for k, chain in enumerate(chains):
            springs.append({"name": "%s.%d" % (name, k), "colliderGroups": [group],
                            "joints": [{"node": j, "stiffness": st, "gravityPower": gp, "gravityDir": [0.0, -1.0, 0.0],
                                        "dragForce": dr, "hitRadius": hr} for j in chain]})
    return {"specVersion": "1.0", "colliders": colliders, "colliderGroups": groups, "springs": springs}


def write_brace(path, kind):
    """kind: "glb" (A-pose rest, clips), "vrm" (VRM 1.0, T-pose), "vrm0" (VRM 0.x, T-pose, faces -z),
    "blast" (the VRM 1.0 avatar with spring-bone hair and skirt), "showcase" (blast with longer,
    golden hair and a longer skirt)."""
    sk = body_skeleton()
    springy = kind in STRANDS
    hair, skirt = add_strands(sk, kind) if springy else ([], [])
    parts = build_body(sk, 1.0)
    if springy:
        strand_geometry(sk, parts, hair, skirt, kind)
    targets = face_targets(parts[FACE])
    flip = kind == "vrm0"
    if flip:
        for part in parts:
            part.pos = [rot_y180_point(p) for p in part.pos]
            part.nrm = [rot_y180_point(n) for n in part.nrm]
        targets = [([rot_y180_point(v) for v in dp], [rot_y180_point(v) for v in dn]) for dp, dn in targets]
        sk.pos = [rot_y180_point(p) for p in sk.pos]
    d = Doc()
    nj = len(sk.names)
    arm_rest_l = q_rot(("z", -ARM_DROP)) if kind == "glb" else q_rot()
    nodes = []
    for j in range(nj):
        p = sk.parent[j]
        t = [sk.pos[j][i] - (sk.pos[p][i] if p is not None else 0.0) for i in range(3)]
        n = {"name": sk.names[j], "translation": r4(t)}
        if kind == "glb" and sk.names[j].startswith("upperArm."):
            n["rotation"] = r4(arm_rest_l if sk.names[j].endswith("L") else mirror_q(arm_rest_l))
        kids = [k for k in range(nj) if sk.parent[k] == j]
        if kids:
            n["children"] = kids
        nodes.append(n)
    band_node, body_node, head_node = nj, nj + 1, nj + 2
    head = sk.index("head")
    band_t = rot_y180_point((0.0, 0.14, -0.005)) if flip else (0.0, 0.14, -0.005)
    nodes[head].setdefault("children", []).append(band_node)
    nodes.append({"name": "headband", "mesh": 2, "translation": r4(band_t)})
    nodes.append({"name": "body", "mesh": 0, "skin": 0, "translation": [0.0, 3.0, 0.0]})
    nodes.append({"name": "head_mesh", "mesh": 1, "skin": 0})

    doc = {}
    add_images(d, doc, [png(8, 16, stripes), png(FW, FH, face_img), png(16, 16, matcap_img), png(8, 8, mask_img)])
    bits = 16 if nj > 256 else 8  # u8 joint indices reach 255
    body_prims = [primitive(d, parts[m], m, bits) for m in (SUIT, SKIN, HAIR)]
    head_prim = primitive(d, parts[FACE], FACE, bits, targets)
    band_prim = primitive(d, parts[BAND], BAND, bits)
    ibm = [(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -p[0], -p[1], -p[2], 1) for p in sk.pos]
    doc.update({
        "asset": {"version": "2.0", "generator": "hadou make_brace.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, body_node, head_node]}],
        "nodes": nodes,
        "skins": [{"joints": list(range(nj)), "skeleton": 0, "inverseBindMatrices": d.floats(ibm, "MAT4")}],
        "meshes": [{"name": "body", "primitives": body_prims},
                   {"name": "head", "primitives": [head_prim], "weights": [0.0, 0.25],
                    "extras": {"targetNames": ["blink", "aa"]}},
                   {"name": "headband", "primitives": [band_prim]}],
        "materials": materials(kind in ("vrm", "blast", "showcase")),
    })
    if kind == "showcase":
        hair_m = doc["materials"][MATERIAL_NAMES.index("hair")]
        hair_m["pbrMetallicRoughness"]["baseColorFactor"] = [1.0, 0.62, 0.12, 1.0]
        hair_m["extensions"]["VRMC_materials_mtoon"]["shadeColorFactor"] = [0.55, 0.16, 0.04]
    used = ["VRMC_materials_mtoon"]
    if kind == "glb":
        doc["animations"] = [add_clip(d, name, ch)
                             for name, ch in brace_clips(sk, nodes, band_node, head_node, arm_rest_l)]
    elif kind in ("vrm", "blast", "showcase"):
        used.append("VRMC_vrm")
        doc["extensions"] = {"VRMC_vrm": {
            "specVersion": "1.0",
            "meta": {"name": "brace", "version": "1", "authors": ["hadou"], "copyrightInformation": "hadou test asset",
                     "licenseUrl": "https://vrm.dev/licenses/1.0/", "avatarPermission": "everyone",
                     "allowExcessivelyViolentUsage": False, "allowExcessivelySexualUsage": False,
                     "commercialUsage": "personalNonProfit", "allowPoliticalOrReligiousUsage": False,
                     "allowAntisocialOrHateUsage": False, "creditNotation": "required", "allowRedistribution": True,
                     "modification": "allowModificationRedistribution"},
            "humanoid": {"humanBones": {HUMAN[n]: {"node": j} for j, n in enumerate(sk.names) if n in HUMAN}},
            "expressions": {"preset": {
                "happy": {"morphTargetBinds": [{"node": head_node, "index": 1, "weight": 0.4}], "isBinary": False,
                          "overrideBlink": "none", "overrideLookAt": "none", "overrideMouth": "none"},
                "blink": {"morphTargetBinds": [{"node": head_node, "index": 0, "weight": 1.0}], "isBinary": False},
                "aa": {"morphTargetBinds": [{"node": head_node, "index": 1, "weight": 1.0}], "isBinary": False},
            }},
            "lookAt": {"offsetFromHeadBone": [0.0, 0.1, 0.1], "type": "bone"},
        }}
        if springy:
            used.append("VRMC_springBone")
            doc["extensions"]["VRMC_springBone"] = spring_bones(hair, skirt, sk.index)
    else:
        used = ["VRM"]
        doc["materials"] = [{k: v for k, v in m.items() if k != "extensions"} for m in doc["materials"]]
        doc["extensions"] = {"VRM": {
            "exporterVersion": "hadou make_brace.py", "specVersion": "0.0",
            "meta": {"title": "brace", "version": "1", "author": "hadou", "contactInformation": "", "reference": "",
                     "allowedUserName": "Everyone", "violentUssageName": "Disallow", "sexualUssageName": "Disallow",
                     "commercialUssageName": "Disallow", "otherPermissionUrl": "", "licenseName": "CC0",
                     "otherLicenseUrl": ""},
            "humanoid": {"humanBones": [{"bone": HUMAN[n], "node": j, "useDefaultValues": True}
                                        for j, n in enumerate(sk.names)],
                         "armStretch": 0.05, "legStretch": 0.05, "upperArmTwist": 0.5, "lowerArmTwist": 0.5,
                         "upperLegTwist": 0.5, "lowerLegTwist": 0.5, "feetSpacing": 0.0, "hasTranslationDoF": False},
            "blendShapeMaster": {"blendShapeGroups": [
                {"name": "Joy", "presetName": "joy", "binds": [{"mesh": 1, "index": 1, "weight": 40.0}],
                 "materialValues": [], "isBinary": False},
                {"name": "Blink", "presetName": "blink", "binds": [{"mesh": 1, "index": 0, "weight": 100.0}],
                 "materialValues": [], "isBinary": False},
                {"name": "A", "presetName": "a", "binds": [{"mesh": 1, "index": 1, "weight": 100.0}],
                 "materialValues": [], "isBinary": False}]},
            "firstPerson": {"firstPersonBone": head, "firstPersonBoneOffset": {"x": 0.0, "y": 0.06, "z": 0.0},
                            "meshAnnotations": [], "lookAtTypeName": "Bone"},
            "secondaryAnimation": {"boneGroups": [], "colliderGroups": []},
            "materialProperties": [mtoon0(n) for n in MATERIAL_NAMES],
        }}
    doc["extensionsUsed"] = used
    size = d.write(path, doc)
    tris = sum(len(p.tris) for p in parts)
    print("%s: %d bytes, %d triangles, %d joints" % (path, size, tris, nj))


# ---------------------------------------------------------------------------------------------
# dancer.glb

def write_dancer(path):
    braid = 16
    sk = body_skeleton(fingers=True, braid=braid)
    parts = build_body(sk, 2.7, fingers=True, braid=braid, wide=True)
    d = Doc()
    nj = len(sk.names)
    nodes = []
    rest = []
    for j in range(nj):
        p = sk.parent[j]
        t = [sk.pos[j][i] - (sk.pos[p][i] if p is not None else 0.0) for i in range(3)]
        n = {"name": sk.names[j], "translation": r4(t)}
        kids = [k for k in range(nj) if sk.parent[k] == j]
        if kids:
            n["children"] = kids
        nodes.append(n)
        rest.append(t)
    band_node, body_node = nj, nj + 1
    nodes[sk.index("head")]["children"].append(band_node)
    nodes.append({"name": "headband", "mesh": 1, "translation": [0.0, 0.14, -0.005]})
    nodes.append({"name": "body", "mesh": 0, "skin": 0})
    doc = {}
    add_images(d, doc, [png(8, 16, stripes), png(FW, FH, face_img)])
    prims = [primitive(d, parts[m], m, 16) for m in (SUIT, SKIN, HAIR, FACE)]
    band = primitive(d, parts[BAND], BAND, 16)
    ibm = [(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -p[0], -p[1], -p[2], 1) for p in sk.pos]
    # The dance: 2 s, a key every 1/15 s, the last key equal to the first (a seamless loop).
    n_keys = 31
    times = [2.0 * k / (n_keys - 1) for k in range(n_keys)]
    chans = []
    for j in range(nj):
        name = sk.names[j]
        amp = {"hips": 8, "spine": 10, "chest": 12, "neck": 8, "head": 10}.get(name.split(".")[0], 20)
        if name.startswith("finger"):
            amp = 30
        if name.startswith("braid"):
            amp = 15
        phase = 0.37 * j
        vals = []
        for t in times:
            a = 2 * math.pi * t / 2.0
            s = math.sin(a + phase)
            c = math.cos(2 * a + phase)
            if name.startswith("finger"):
                q = q_rot(("y" if name[6] == "0" else "z", amp * (0.5 + 0.5 * s) * (1 if name.endswith("L") else -1)))
            elif name.startswith("braid"):
                q = q_rot(("x", amp * s), ("z", 0.5 * amp * c))
            elif name.startswith("upperArm"):
                side = 1 if name.endswith("L") else -1
                q = q_rot(("z", side * (-55 + 25 * s)), ("y", side * 20 * c))
            elif name.startswith("lowerLeg"):
                q = q_rot(("x", 20 + 20 * s))
            else:
                q = q_rot(("y", amp * s), ("x", 0.5 * amp * c), ("z", 0.3 * amp * s))
            vals.append(q)
        vals[-1] = vals[0]
        chans.append((j, "rotation", "LINEAR", times, vals))
    hips_t = [v3(rest[0], (0.03 * math.sin(2 * math.pi * t / 2.0), -0.03 * (1 - math.cos(4 * math.pi * t / 2.0)), 0.0))
              for t in times]
    hips_t[-1] = hips_t[0]
    chans.append((0, "translation", "LINEAR", times, hips_t))
    doc.update({
        "asset": {"version": "2.0", "generator": "hadou make_brace.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, body_node]}],
        "nodes": nodes,
        "skins": [{"joints": list(range(nj)), "skeleton": 0, "inverseBindMatrices": d.floats(ibm, "MAT4")}],
        "meshes": [{"name": "dancer", "primitives": prims}, {"name": "headband", "primitives": [band]}],
        "materials": materials(False),
        "animations": [add_clip(d, "dance", chans)],
        "extensionsUsed": ["VRMC_materials_mtoon"],
    })
    size = d.write(path, doc)
    tris = sum(len(p.tris) for p in parts)
    print("%s: %d bytes, %d triangles, %d joints" % (path, size, tris, nj))


# ---------------------------------------------------------------------------------------------
# brace.vrma

def write_vrma(path, thumb=True):
    """thumb: add leftThumbProximal, a bone the avatars lack (brace.vrma); showcase.vrma is the same
    clip without it."""
    sk = body_skeleton()
    hand_l = sk.index("hand.L")
    thumb = sk.add("thumbProximal.L", hand_l, (0.74, 1.38, 0.045)) if thumb else None
    d = Doc()
    nj = len(sk.names)
    rest_l = q_rot(("z", -10.0))  # the arms rest 10 degrees lower than brace.vrm's T-pose
    nodes, rest_q = [], []
    for j in range(nj):
        p = sk.parent[j]
        t = [sk.pos[j][i] - (sk.pos[p][i] if p is not None else 0.0) for i in range(3)]
        n = {"name": sk.names[j], "translation": r4(t)}
        q = q_rot()
        if sk.names[j].startswith("upperArm."):
            q = rest_l if sk.names[j].endswith("L") else mirror_q(rest_l)
            n["rotation"] = r4(q)
        rest_q.append(q)
        kids = [k for k in range(nj) if sk.parent[k] == j]
        if kids:
            n["children"] = kids
        nodes.append(n)
    blink_node = nj
    nodes.append({"name": "expression.blink", "translation": [0.0, 0.0, 0.0]})
    J = sk.index
    T = [0.0, 0.5, 1.0, 1.5, 2.0]
    hips = [(0.0, 0.95 + dy, 0.0) for dy in (0.0, -0.04, -0.12, -0.15, -0.15)]
    # Each bone's key is its rest rotation followed by the motion (brace.glb's, from the T-pose).
    def track(name, qs):
        return (J(name), "rotation", "LINEAR", T, [r4(q_mul(rest_q[J(name)], q)) for q in qs])
    ks = (0, 0.4, 1, 1, 1)
    ch = [(J("hips"), "translation", "LINEAR", T, hips),
          track("hips", [q_rot(("y", 25 * k)) for k in (0, 0.4, 0.8, 1, 1)]),
          track("chest", [q_rot(("y", 15 * k), ("x", -8 * k)) for k in ks]),
          track("head", [q_rot(("y", -12 * k)) for k in ks])]
    for tag, mir in (("L", lambda q: q), ("R", mirror_q)):
        ch += [track("upperArm." + tag, [mir(q_rot(("y", -75 * k), ("z", -25 * k))) for k in ks]),
               track("lowerArm." + tag, [mir(q_rot(("z", 105 * k))) for k in ks]),
               track("upperLeg." + tag, [mir(q_rot(("x", -40 * k))) for k in ks]),
               track("lowerLeg." + tag, [mir(q_rot(("x", 75 * k))) for k in ks])]
    if thumb is not None:
        ch.append(track("thumbProximal.L", [q_rot(("y", 30 * k)) for k in ks]))
    ch.append((blink_node, "translation", "LINEAR", T, [(w, 0.0, 0.0) for w in (0.0, 1.0, 0.0, 0.0, 1.0)]))
    bones = {HUMAN[n]: {"node": j} for j, n in enumerate(sk.names) if n in HUMAN}
    if thumb is not None:
        bones["leftThumbProximal"] = {"node": thumb}
    doc = {
        "asset": {"version": "2.0", "generator": "hadou make_brace.py"},
        "extensionsUsed": ["VRMC_vrm_animation"],
        "extensions": {"VRMC_vrm_animation": {
            "specVersion": "1.0",
            "humanoid": {"humanBones": bones},
            "expressions": {"preset": {"blink": {"node": blink_node}}},
        }},
        "scene": 0,
        "scenes": [{"nodes": [0, blink_node]}],
        "nodes": nodes,
        "animations": [add_clip(d, "brace", ch)],
    }
    size = d.write(path, doc)
    print("%s: %d bytes, %d nodes" % (path, size, len(nodes)))


if __name__ == "__main__":
    write_brace("brace.glb", "glb")
    write_brace("brace.vrm", "vrm")
    write_brace("brace0.vrm", "vrm0")
    write_brace("blast.vrm", "blast")
    write_vrma("brace.vrma")
    write_brace("showcase.vrm", "showcase")
    write_vrma("showcase.vrma", thumb=False)
    write_dancer("dancer.glb")
