//! An independent f64 implementation of glTF 2.0 posing, written from the glTF 2.0
//! specification for tests (it shares no code with the loader): GLB container (§4.4), accessors
//! (§3.6.2, normalised integers per §3.11), animation samplers (§3.11 and Appendix C: STEP,
//! LINEAR with shortest-arc slerp for rotations, CUBICSPLINE Hermite splines with tangents scaled
//! by the key interval), node transforms `T · R · S` (§3.5.3), morph targets (§3.7.2.2:
//! `base + Σ wᵢ · δᵢ`, weights from the animation, else `node.weights`, else `mesh.weights`),
//! skinning (§3.7.3: `Σ wₖ · global(jointₖ) · inverseBindₖ · p`, weights normalised, the skinned
//! node's own transform ignored) and rigid meshes placed by their node's global matrix.
//!
//! Vertex order: the default scene's root nodes walked depth-first (children in listed order),
//! each mesh's primitives in order, each primitive's vertices in accessor order.
#![allow(dead_code)]

use serde_json::Value;
use std::path::Path;

pub type V3 = [f64; 3];
pub type Q = [f64; 4];
/// Column-major 4×4 matrix, as glTF stores them.
pub type M4 = [f64; 16];

pub const IDENTITY: M4 = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];

/// A parsed GLB: its JSON chunk and its BIN chunk.
pub struct Gltf {
    pub json: Value,
    pub bin: Vec<u8>,
}

fn u32_at(b: &[u8], o: usize) -> u32 {
    u32::from_le_bytes(b[o..o + 4].try_into().unwrap())
}

fn idx(v: &Value) -> usize {
    v.as_u64().unwrap_or_else(|| panic!("not an index: {v}")) as usize
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().unwrap_or_else(|| panic!("not an array: {v}")).iter().map(num).collect()
}

/// The interpolated value of one sampler at a clip time.
#[derive(Clone, Debug)]
pub enum Sampled {
    Translation(V3),
    Rotation(Q),
    Scale(V3),
    Weights(Vec<f64>),
}

impl Gltf {
    /// Reads a GLB file: 12-byte header (magic `glTF`, version 2, length), then chunks of
    /// (length, type, data): JSON first, BIN optional.
    pub fn open(path: &Path) -> Gltf {
        let b = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        Gltf::from_glb(&b)
    }

    pub fn from_glb(b: &[u8]) -> Gltf {
        assert_eq!(&b[0..4], b"glTF", "not a GLB");
        assert_eq!(u32_at(b, 4), 2, "GLB version");
        assert_eq!(u32_at(b, 8) as usize, b.len(), "GLB length");
        let (mut json, mut bin) = (None, Vec::new());
        let mut o = 12;
        while o + 8 <= b.len() {
            let (len, kind) = (u32_at(b, o) as usize, u32_at(b, o + 4));
            let data = &b[o + 8..o + 8 + len];
            match kind {
                0x4E4F_534A => json = Some(serde_json::from_slice(data).expect("JSON chunk")),
                0x004E_4942 => bin = data.to_vec(),
                _ => {}
            }
            o += 8 + len;
        }
        Gltf { json: json.expect("no JSON chunk"), bin }
    }

    fn arr(&self, key: &str) -> &[Value] {
        self.json[key].as_array().map(Vec::as_slice).unwrap_or(&[])
    }

    /// Accessor `i` as elements of `f64` components. Integer components read as their value,
    /// or, when `normalized`, as `c / max` (unsigned) and `max(c / max, −1)` (signed).
    pub fn accessor(&self, i: usize) -> Vec<Vec<f64>> {
        let a = &self.arr("accessors")[i];
        assert!(a.get("sparse").is_none(), "sparse accessors are not used by the test assets");
        let count = idx(&a["count"]);
        let width = match a["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT2" => 4,
            "MAT3" => 9,
            "MAT4" => 16,
            t => panic!("accessor type {t}"),
        };
        let ctype = idx(&a["componentType"]);
        let size = match ctype {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            5125 | 5126 => 4,
            c => panic!("componentType {c}"),
        };
        let normalized = a["normalized"].as_bool().unwrap_or(false);
        let Some(view) = a.get("bufferView") else { return vec![vec![0.0; width]; count] };
        let v = &self.arr("bufferViews")[idx(view)];
        assert_eq!(v["buffer"].as_u64(), Some(0), "only the GLB's own buffer");
        let base =
            v["byteOffset"].as_u64().unwrap_or(0) as usize + a["byteOffset"].as_u64().unwrap_or(0) as usize;
        let stride = v["byteStride"].as_u64().map(|s| s as usize).unwrap_or(width * size);
        (0..count)
            .map(|e| {
                (0..width)
                    .map(|c| {
                        let o = base + e * stride + c * size;
                        let b = &self.bin[o..o + size];
                        match ctype {
                            5126 => f32::from_le_bytes(b.try_into().unwrap()) as f64,
                            5121 if normalized => b[0] as f64 / 255.0,
                            5121 => b[0] as f64,
                            5120 if normalized => (b[0] as i8 as f64 / 127.0).max(-1.0),
                            5120 => b[0] as i8 as f64,
                            5123 if normalized => u16::from_le_bytes([b[0], b[1]]) as f64 / 65535.0,
                            5123 => u16::from_le_bytes([b[0], b[1]]) as f64,
                            5122 if normalized => {
                                (i16::from_le_bytes([b[0], b[1]]) as f64 / 32767.0).max(-1.0)
                            }
                            5122 => i16::from_le_bytes([b[0], b[1]]) as f64,
                            _ => u32::from_le_bytes(b.try_into().unwrap()) as f64,
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// The index of the animation named `name`.
    pub fn animation(&self, name: &str) -> usize {
        self.arr("animations")
            .iter()
            .position(|a| a["name"].as_str() == Some(name))
            .unwrap_or_else(|| panic!("no animation {name}"))
    }

    /// A clip's duration: the largest key time of its samplers.
    pub fn duration(&self, anim: usize) -> f64 {
        let a = &self.arr("animations")[anim];
        a["samplers"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|s| self.accessor(idx(&s["input"])))
            .map(|k| k[0])
            .fold(0.0, f64::max)
    }

    /// Sampler `s` of animation `anim` at clip time `t` (clamped to the first and last key),
    /// for a channel of `path`.
    pub fn sample(&self, anim: usize, s: usize, path: &str, t: f64) -> Sampled {
        let smp = &self.arr("animations")[anim]["samplers"][s];
        let times: Vec<f64> = self.accessor(idx(&smp["input"])).into_iter().map(|k| k[0]).collect();
        let flat: Vec<f64> = self.accessor(idx(&smp["output"])).into_iter().flatten().collect();
        let interp = smp["interpolation"].as_str().unwrap_or("LINEAR");
        let n = times.len();
        let cubic = interp == "CUBICSPLINE";
        let per_key = flat.len() / n / if cubic { 3 } else { 1 };
        // Element `e` (0: in-tangent, 1: value, 2: out-tangent for CUBICSPLINE) of key `k`.
        let elem = |k: usize, e: usize| -> Vec<f64> {
            let o = if cubic { (3 * k + e) * per_key } else { k * per_key };
            flat[o..o + per_key].to_vec()
        };
        let value = |k: usize| elem(k, if cubic { 1 } else { 0 });
        let v: Vec<f64> = if t <= times[0] {
            value(0)
        } else if t >= times[n - 1] {
            value(n - 1)
        } else {
            let k = (0..n - 1).find(|&k| t < times[k + 1]).unwrap();
            let td = times[k + 1] - times[k];
            let u = (t - times[k]) / td;
            match interp {
                "STEP" => value(k),
                "LINEAR" if path == "rotation" => slerp(to_q(&value(k)), to_q(&value(k + 1)), u).to_vec(),
                "LINEAR" => value(k).iter().zip(value(k + 1)).map(|(a, b)| a + (b - a) * u).collect(),
                "CUBICSPLINE" => {
                    let (p0, m0) = (value(k), elem(k, 2));
                    let (p1, m1) = (value(k + 1), elem(k + 1, 0));
                    (0..per_key).map(|i| hermite(p0[i], td * m0[i], p1[i], td * m1[i], u)).collect()
                }
                other => panic!("interpolation {other}"),
            }
        };
        match path {
            "translation" => Sampled::Translation([v[0], v[1], v[2]]),
            "scale" => Sampled::Scale([v[0], v[1], v[2]]),
            "rotation" => Sampled::Rotation(normalize_q(to_q(&v))),
            "weights" => Sampled::Weights(v),
            p => panic!("path {p}"),
        }
    }

    /// Every vertex position of the default scene, posed by animation `clip` at clip time `t`
    /// (`None`: the nodes' own transforms, the rest pose).
    pub fn pose(&self, clip: Option<(&str, f64)>) -> Vec<V3> {
        self.pose_with(clip, true)
    }

    /// As [`Gltf::pose`]; `morphs = false` leaves the morph targets out (every weight 0).
    pub fn pose_with(&self, clip: Option<(&str, f64)>, morphs: bool) -> Vec<V3> {
        let nodes = self.arr("nodes");
        let (globals, weights) = self.posed_nodes(clip);
        self.place_scene(nodes, &globals, &weights, morphs)
    }

    /// Every node's global matrix (column-major) under animation `clip` at clip time `t`.
    pub fn node_globals(&self, clip: Option<(&str, f64)>) -> Vec<M4> {
        self.posed_nodes(clip).0
    }

    /// Every node's global matrix and animated morph weights.
    #[allow(clippy::type_complexity)]
    fn posed_nodes(&self, clip: Option<(&str, f64)>) -> (Vec<M4>, Vec<Option<Vec<f64>>>) {
        let nodes = self.arr("nodes");
        // Local TRS of every node, then the animated values.
        let mut trs: Vec<(V3, Q, V3, Option<M4>)> = nodes
            .iter()
            .map(|n| {
                let m = n.get("matrix").map(|m| nums(m).try_into().unwrap());
                let t = n.get("translation").map(|v| nums(v).try_into().unwrap()).unwrap_or([0.0; 3]);
                let r =
                    n.get("rotation").map(|v| nums(v).try_into().unwrap()).unwrap_or([0.0, 0.0, 0.0, 1.0]);
                let s = n.get("scale").map(|v| nums(v).try_into().unwrap()).unwrap_or([1.0; 3]);
                (t, r, s, m)
            })
            .collect();
        let mut weights: Vec<Option<Vec<f64>>> = nodes.iter().map(|n| n.get("weights").map(nums)).collect();
        if let Some((name, t)) = clip {
            let a = self.animation(name);
            for ch in self.arr("animations")[a]["channels"].as_array().unwrap() {
                let Some(node) = ch["target"].get("node") else { continue };
                let node = idx(node);
                let path = ch["target"]["path"].as_str().unwrap();
                match self.sample(a, idx(&ch["sampler"]), path, t) {
                    Sampled::Translation(v) => trs[node].0 = v,
                    Sampled::Rotation(q) => trs[node].1 = q,
                    Sampled::Scale(v) => trs[node].2 = v,
                    Sampled::Weights(w) => weights[node] = Some(w),
                }
            }
        }
        let locals: Vec<M4> =
            trs.iter().map(|(t, r, s, m)| m.unwrap_or_else(|| compose(*t, *r, *s))).collect();
        // Globals through the hierarchy.
        let mut parent = vec![None; nodes.len()];
        for (i, n) in nodes.iter().enumerate() {
            for c in n["children"].as_array().map(Vec::as_slice).unwrap_or(&[]) {
                parent[idx(c)] = Some(i);
            }
        }
        let global = |mut i: usize| -> M4 {
            let mut m = locals[i];
            while let Some(p) = parent[i] {
                m = mul(&locals[p], &m);
                i = p;
            }
            m
        };
        let globals: Vec<M4> = (0..nodes.len()).map(global).collect();
        (globals, weights)
    }

    fn place_scene(
        &self,
        nodes: &[Value],
        globals: &[M4],
        weights: &[Option<Vec<f64>>],
        morphs: bool,
    ) -> Vec<V3> {
        let scene = &self.arr("scenes")[self.json["scene"].as_u64().unwrap_or(0) as usize];
        let mut out = Vec::new();
        let mut stack: Vec<usize> = nums(&scene["nodes"]).into_iter().rev().map(|v| v as usize).collect();
        while let Some(i) = stack.pop() {
            let n = &nodes[i];
            if let Some(m) = n.get("mesh") {
                let mesh = &self.arr("meshes")[idx(m)];
                let w: Vec<f64> = if morphs {
                    weights[i].clone().or_else(|| mesh.get("weights").map(nums)).unwrap_or_default()
                } else {
                    Vec::new()
                };
                let skin = n.get("skin").map(|s| self.joint_matrices(idx(s), globals));
                for p in mesh["primitives"].as_array().unwrap() {
                    self.place_primitive(p, &w, skin.as_deref(), &globals[i], &mut out);
                }
            }
            for c in n["children"].as_array().map(Vec::as_slice).unwrap_or(&[]).iter().rev() {
                stack.push(idx(c));
            }
        }
        out
    }

    /// `global(joint_k) · inverseBind_k` for every joint of skin `s`.
    fn joint_matrices(&self, s: usize, globals: &[M4]) -> Vec<M4> {
        let skin = &self.arr("skins")[s];
        let joints: Vec<usize> = nums(&skin["joints"]).into_iter().map(|v| v as usize).collect();
        let ibm: Vec<M4> = match skin.get("inverseBindMatrices") {
            Some(a) => self.accessor(idx(a)).into_iter().map(|m| m.try_into().unwrap()).collect(),
            None => vec![IDENTITY; joints.len()],
        };
        joints.iter().zip(&ibm).map(|(&j, b)| mul(&globals[j], b)).collect()
    }

    fn place_primitive(&self, p: &Value, w: &[f64], skin: Option<&[M4]>, node: &M4, out: &mut Vec<V3>) {
        let attrs = &p["attributes"];
        let mut pos: Vec<V3> =
            self.accessor(idx(&attrs["POSITION"])).into_iter().map(|v| [v[0], v[1], v[2]]).collect();
        for (t, wt) in p["targets"].as_array().map(Vec::as_slice).unwrap_or(&[]).iter().zip(w) {
            if let Some(a) = t.get("POSITION") {
                for (v, d) in pos.iter_mut().zip(self.accessor(idx(a))) {
                    for c in 0..3 {
                        v[c] += wt * d[c];
                    }
                }
            }
        }
        match (skin, attrs.get("JOINTS_0"), attrs.get("WEIGHTS_0")) {
            (Some(mats), Some(j), Some(wa)) => {
                let (js, ws) = (self.accessor(idx(j)), self.accessor(idx(wa)));
                for ((v, j), wv) in pos.iter().zip(js).zip(ws) {
                    let sum: f64 = wv.iter().sum();
                    let mut acc = [0.0; 3];
                    for k in 0..4 {
                        if wv[k] != 0.0 {
                            let q = transform(&mats[j[k] as usize], *v);
                            for c in 0..3 {
                                acc[c] += wv[k] / sum * q[c];
                            }
                        }
                    }
                    out.push(acc);
                }
            }
            _ => out.extend(pos.iter().map(|v| transform(node, *v))),
        }
    }
}

fn to_q(v: &[f64]) -> Q {
    [v[0], v[1], v[2], v[3]]
}

pub fn normalize_q(q: Q) -> Q {
    let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    [q[0] / l, q[1] / l, q[2] / l, q[3] / l]
}

/// Spherical linear interpolation along the shorter arc: when `a · b < 0`, `−b` (the same
/// rotation) is used.
pub fn slerp(a: Q, b: Q, u: f64) -> Q {
    let mut d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    let b = if d < 0.0 {
        d = -d;
        [-b[0], -b[1], -b[2], -b[3]]
    } else {
        b
    };
    let (ka, kb) = if d > 1.0 - 1e-12 {
        (1.0 - u, u)
    } else {
        let th = d.min(1.0).acos();
        (((1.0 - u) * th).sin() / th.sin(), (u * th).sin() / th.sin())
    };
    normalize_q([0, 1, 2, 3].map(|i| ka * a[i] + kb * b[i]))
}

/// The cubic Hermite spline of glTF's CUBICSPLINE (Appendix C) at `u` in [0, 1], with the
/// tangents already multiplied by the key interval.
pub fn hermite(p0: f64, m0: f64, p1: f64, m1: f64, u: f64) -> f64 {
    let (u2, u3) = (u * u, u * u * u);
    (2.0 * u3 - 3.0 * u2 + 1.0) * p0 + (u3 - 2.0 * u2 + u) * m0 + (-2.0 * u3 + 3.0 * u2) * p1 + (u3 - u2) * m1
}

/// Column-major product `a · b`.
pub fn mul(a: &M4, b: &M4) -> M4 {
    let mut m = [0.0; 16];
    for c in 0..4 {
        for r in 0..4 {
            m[c * 4 + r] = (0..4).map(|k| a[k * 4 + r] * b[c * 4 + k]).sum();
        }
    }
    m
}

/// `T · R · S` as a column-major matrix.
pub fn compose(t: V3, q: Q, s: V3) -> M4 {
    let [x, y, z, w] = q;
    let r = [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + z * w), 2.0 * (x * z - y * w)],
        [2.0 * (x * y - z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + x * w)],
        [2.0 * (x * z + y * w), 2.0 * (y * z - x * w), 1.0 - 2.0 * (x * x + y * y)],
    ];
    let mut m = IDENTITY;
    for c in 0..3 {
        for row in 0..3 {
            m[c * 4 + row] = r[c][row] * s[c];
        }
        m[12 + c] = t[c];
    }
    m
}

/// The point `p` through `m`.
pub fn transform(m: &M4, p: V3) -> V3 {
    [0, 1, 2].map(|r| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r])
}
