//! A glTF character that can be posed: its node hierarchy with the rest transforms, its skins, its
//! primitives in mesh space with their joint influences and morph targets, and its animation clips
//! (glTF 2.0 §3.5 nodes, §3.7.2.2 morph targets, §3.7.3 skins, §3.11 animations). The loader
//! (`gltf_load`) builds one next to the rest-pose [`Mesh`] of a file that has skins, morph targets
//! or animations; [`Rig::pose`] turns a clip time into a posed mesh with the rest mesh's vertex
//! order, triangles, texture coordinates and materials, so every backend draws, outlines and
//! shadows the posed character exactly as it draws a still one.
//!
//! Posing a vertex `p` with normal `n` (glTF 2.0 §3.7.2.2, §3.7.3.3):
//! 1. morph targets: `p' = p + Σ wᵢ·δpᵢ`, `n' = n + Σ wᵢ·δnᵢ` with the weights of the animation
//!    (else the node's `weights`, else the mesh's, else 0), plus VRM expression binds;
//! 2. skinning: `M = Σ_k w_k · G(joint_k) · IBM_k` (weights normalised to sum 1; the skinned mesh
//!    node's own transform is ignored), `p'' = M·p'`, `n'' = cof(M)·n'` normalised; a vertex
//!    without skin influences takes its node's global transform `G(node)`;
//! 3. `G(node) = G(parent) · L(node)` with `L = T·R·S` of the sampled channels (a channel that is
//!    absent keeps the node's rest value).

use crate::frame::Mesh;
use crate::limits::COORD_MAX;
use hadou_math::keyframes::{sample, trs_matrix, Sampling};
use hadou_math::{Mat4, Vec3f};

/// A node's rest transform: a matrix (such a node cannot be animated) or translation, rotation
/// (unit quaternion `[x, y, z, w]`) and scale.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum RestLocal {
    Matrix(Mat4),
    Trs { t: [f32; 3], r: [f32; 4], s: [f32; 3] },
}

/// A node of the character's hierarchy.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct RigNode {
    pub parent: Option<usize>,
    pub rest: RestLocal,
    /// The default morph weights of the node's mesh (`node.weights`, else `mesh.weights`, else
    /// zeros); empty when its mesh has no morph targets.
    pub weights: Vec<f32>,
}

/// A skin: its joint nodes and their inverse bind matrices.
#[derive(Clone, Debug)]
pub(crate) struct RigSkin {
    pub joints: Vec<usize>,
    pub ibms: Vec<Mat4>,
}

/// One morph target of a primitive: position offsets and (possibly empty) normal offsets.
#[derive(Clone, Debug, Default)]
pub(crate) struct MorphTarget {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
}

/// One primitive instance of the loaded mesh, in its mesh's own space.
#[derive(Clone, Debug)]
pub(crate) struct Part {
    /// The node that instantiates it.
    pub node: usize,
    /// The skin that places it, if it has one and skin attributes.
    pub skin: Option<usize>,
    /// Its first vertex in the loaded mesh.
    pub first: usize,
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    /// Per vertex, up to four (joint, weight) pairs with weights summing to 1, or all weights 0 (the
    /// vertex follows its node); empty for a rigid part.
    pub influences: Vec<[(u16, f32); 4]>,
    pub targets: Vec<MorphTarget>,
}

/// What an animation channel drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ChannelPath {
    Translation,
    Rotation,
    Scale,
    Weights,
    /// A VRM expression's weight (from a VRM Animation): `node` is the expression's index.
    Expression,
}

/// One channel: a node property sampled from keys.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Channel {
    pub node: usize,
    pub path: ChannelPath,
    pub sampling: Sampling,
    pub times: Vec<f32>,
    pub values: Vec<f32>,
    /// Floats per key value (3, 4, or the node's number of morph targets).
    pub width: usize,
}

/// A named animation clip of a glTF file.
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    /// The animation's `name` (or `animation N` for an unnamed one).
    pub name: String,
    /// Its length in seconds: the latest key time of its channels.
    pub duration: f32,
    pub(crate) channels: Vec<Channel>,
}

/// Which VRM a file is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VrmVersion {
    /// `VRMC_vrm` (VRM 1.0): the model faces +z.
    V1,
    /// The `VRM` extension (VRM 0.x): the model faces −z.
    V0,
}

/// A VRM expression (blend shape group): morph-target binds `(node, target, weight)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Expression {
    /// The preset or custom name (`happy`, `blink`, `aa`, …).
    pub name: String,
    pub(crate) binds: Vec<(usize, usize, f32)>,
}

/// The posable character of one glTF file.
#[derive(Clone, Debug)]
pub struct Rig {
    pub(crate) nodes: Vec<RigNode>,
    /// Every node, parents before their children.
    pub(crate) order: Vec<usize>,
    pub(crate) skins: Vec<Option<RigSkin>>,
    pub(crate) parts: Vec<Part>,
    pub(crate) clips: Vec<Clip>,
    pub(crate) expressions: Vec<Expression>,
    /// A VRM's humanoid bones: `(bone name, node)`.
    pub(crate) humanoid: Vec<(String, usize)>,
    /// Which VRM the file is, if it is one.
    pub(crate) vrm: Option<VrmVersion>,
    /// The transform above the file's root nodes (a half turn about y for VRM 0.x, which faces −z).
    pub(crate) base: Mat4,
    /// Per vertex of the loaded mesh, the group of vertices at the same rest position (their
    /// outline normals are the normalised sum of their normals).
    pub(crate) groups: Vec<u32>,
    pub(crate) group_count: usize,
    /// A VRM's spring bones (`VRMC_springBone`, VRM 0.x `secondaryAnimation`), if it has any.
    pub(crate) springs: Option<crate::spring_bones::SpringBones>,
    /// A VRM's look-at (`VRMC_vrm.lookAt`, VRM 0.x `firstPerson`), if it has one with a head.
    pub(crate) look_at: Option<crate::look_at::LookAt>,
}

/// The pose of a character's glTF nodes ([`Rig::node_locals`], [`crate::Scene::object_node_pose_at`]):
/// per node of the file (the file's node order), its local transform and the morph weights of
/// its mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodePose {
    /// Per node, its local translation, rotation (unit quaternion `[x, y, z, w]`) and scale
    /// (glTF 2.0 §3.5.3: `L = T·R·S`); `None` for a node given by a `matrix`, which keeps it.
    pub locals: Vec<Option<Trs>>,
    /// Per node, the morph weights of its mesh (glTF 2.0 §3.7.2.2, expressions added); empty for
    /// a node without morph targets.
    pub weights: Vec<Vec<f32>>,
}

/// What to pose: a clip at a time, and expression weights.
#[derive(Clone, Copy, Debug, Default)]
pub struct PoseInput<'a> {
    /// The clip (one of [`Rig::clips`] or a retargeted VRM Animation), or the rest pose.
    pub clip: Option<&'a Clip>,
    /// Seconds into the clip (held at its ends).
    pub time: f32,
    /// `(expression index, weight in [0, 1])`.
    pub expressions: &'a [(usize, f32)],
    /// `(node, unit quaternion)`: local rotations that replace the clip's and the rest's (the
    /// spring bones' turns).
    pub rotations: &'a [(usize, [f32; 4])],
    /// Only the nodes' transforms are wanted (the spring simulation): no morph weights.
    pub skip_weights: bool,
}

impl Rig {
    /// The file's animation clips.
    pub fn clips(&self) -> &[Clip] {
        &self.clips
    }

    /// The index of the clip called `name`.
    pub fn clip(&self, name: &str) -> Option<usize> {
        self.clips.iter().position(|c| c.name == name)
    }

    /// The file's VRM expressions.
    pub fn expressions(&self) -> &[Expression] {
        &self.expressions
    }

    /// A VRM's humanoid bones: `(bone name, node)` (empty for other files).
    pub fn humanoid(&self) -> &[(String, usize)] {
        &self.humanoid
    }

    /// Which VRM the file is, if it is one.
    pub fn vrm(&self) -> Option<VrmVersion> {
        self.vrm
    }

    /// Every node's global matrix under `input` (the scene space of the loaded mesh).
    pub fn node_globals(&self, input: &PoseInput<'_>) -> Vec<Mat4> {
        self.node_pose(input).0
    }

    /// Whether posing can change anything (a clip, a skin, morph targets or expressions).
    pub fn is_posable(&self) -> bool {
        !self.clips.is_empty()
            || !self.expressions.is_empty()
            || self.parts.iter().any(|p| !p.targets.is_empty())
    }

    /// The file's spring bones, if it has any.
    pub fn springs(&self) -> Option<&crate::spring_bones::SpringBones> {
        self.springs.as_ref()
    }

    /// Every glTF node's local transform and morph weights under `input` (steps 1 and 3 of the
    /// module's notes before the product `G(node) = G(parent) · L(node)`): what a renderer that
    /// keeps the file's own node hierarchy (Bevy's glTF scene) sets on its nodes so that its
    /// skinning draws the pose [`Rig::pose`] gives. The rig's `base` (VRM 0.x's half turn above
    /// the root nodes) is not in it.
    pub fn node_locals(&self, input: &PoseInput<'_>) -> NodePose {
        let (locals, weights) = self.sample_locals(input);
        NodePose { locals, weights }
    }

    /// Every node's global matrix and morph weights for `input`.
    fn node_pose(&self, input: &PoseInput<'_>) -> (Vec<Mat4>, Vec<Vec<f32>>) {
        let n = self.nodes.len();
        let (trs, weights) = self.sample_locals(input);
        let mut globals = vec![Mat4::IDENTITY; n];
        for &i in &self.order {
            let local = self.local_matrix(i, trs[i]);
            globals[i] = match self.nodes[i].parent {
                Some(p) => globals[p] * local,
                None => self.base * local,
            };
        }
        (globals, weights)
    }

    /// Node `i`'s local matrix from its sampled transform (`None`: its rest matrix).
    pub(crate) fn local_matrix(&self, i: usize, trs: Option<Trs>) -> Mat4 {
        match (&self.nodes[i].rest, trs) {
            (_, Some((t, r, s))) => trs_matrix(t, r, s),
            (RestLocal::Matrix(m), None) => *m,
            (RestLocal::Trs { .. }, None) => Mat4::IDENTITY,
        }
    }

    /// Every node's local transform (`None` for a matrix node) and morph weights for `input`.
    pub(crate) fn sample_locals(&self, input: &PoseInput<'_>) -> (Vec<Option<Trs>>, Vec<Vec<f32>>) {
        let mut trs: Vec<Option<Trs>> = self
            .nodes
            .iter()
            .map(|node| match node.rest {
                RestLocal::Trs { t, r, s } => Some((t, r, s)),
                RestLocal::Matrix(_) => None,
            })
            .collect();
        let mut weights: Vec<Vec<f32>> = if input.skip_weights {
            Vec::new()
        } else {
            self.nodes.iter().map(|node| node.weights.clone()).collect()
        };
        let mut clip_expressions: Vec<(usize, f32)> = Vec::new();
        if let Some(clip) = input.clip {
            let mut buf = [0.0f32; 4];
            for ch in &clip.channels {
                if ch.path == ChannelPath::Expression {
                    sample(ch.sampling, &ch.times, &ch.values, 1, false, input.time, &mut buf);
                    clip_expressions.push((ch.node, buf[0]));
                    continue;
                }
                let rotation = ch.path == ChannelPath::Rotation;
                if ch.path == ChannelPath::Weights {
                    let Some(w) = weights.get_mut(ch.node) else { continue };
                    if w.len() == ch.width {
                        sample(ch.sampling, &ch.times, &ch.values, ch.width, false, input.time, w);
                    }
                    continue;
                }
                let Some((t, r, s)) = trs[ch.node].as_mut() else { continue };
                sample(ch.sampling, &ch.times, &ch.values, ch.width, rotation, input.time, &mut buf);
                match ch.path {
                    ChannelPath::Translation => t.copy_from_slice(&buf[..3]),
                    ChannelPath::Rotation => r.copy_from_slice(&buf),
                    ChannelPath::Scale => s.copy_from_slice(&buf[..3]),
                    ChannelPath::Weights | ChannelPath::Expression => {}
                }
            }
        }
        for &(e, value) in input.expressions.iter().chain(&clip_expressions) {
            let Some(ex) = self.expressions.get(e) else { continue };
            let value = if value.is_finite() { value.clamp(0.0, 1.0) } else { 0.0 };
            for &(node, target, w) in &ex.binds {
                if let Some(x) = weights.get_mut(node).and_then(|ws| ws.get_mut(target)) {
                    *x += value * w;
                }
            }
        }
        for &(node, r) in input.rotations {
            if let Some((_, rot, _)) = trs.get_mut(node).and_then(|x| x.as_mut()) {
                *rot = r;
            }
        }
        (trs, weights)
    }

    /// `base` (this rig's rest mesh) posed by `input`: positions, normals and outline normals
    /// replaced, everything else shared in value. Non-finite results fall back to the rest
    /// vertex, and coordinates are clamped to `±COORD_MAX`, so any pose renders.
    pub fn pose(&self, base: &Mesh, input: &PoseInput<'_>) -> Mesh {
        let (globals, weights) = self.node_pose(input);
        let nv = base.positions.len();
        let mut positions = base.positions.clone();
        let mut normals = base.normals.clone();
        // Each skin's joint matrices `G(joint_k) · IBM_k`, once per pose.
        let skin_mats: Vec<Vec<Mat4>> = self
            .skins
            .iter()
            .enumerate()
            .map(|(i, skin)| match skin {
                Some(skin) if self.parts.iter().any(|p| p.skin == Some(i)) => {
                    skin.joints.iter().zip(&skin.ibms).map(|(&j, ibm)| globals[j] * *ibm).collect()
                }
                _ => Vec::new(),
            })
            .collect();
        // What every part shares: its joint matrices, its node's matrices, its active targets.
        let empty: Vec<Mat4> = Vec::new();
        let setups: Vec<PartSetup<'_>> = self
            .parts
            .iter()
            .map(|part| {
                let node = globals[part.node];
                PartSetup {
                    joints: part.skin.and_then(|s| skin_mats.get(s)).unwrap_or(&empty),
                    node,
                    node_normals: node.normal_matrix(),
                    active: weights[part.node]
                        .iter()
                        .copied()
                        .enumerate()
                        .filter(|&(i, x)| x != 0.0 && i < part.targets.len())
                        .collect(),
                }
            })
            .collect();
        // Work in chunks of vertices, spread over the machine's threads for a large mesh.
        const CHUNK: usize = 4096;
        let tasks: Vec<(usize, usize, usize)> = self
            .parts
            .iter()
            .enumerate()
            .filter(|(_, p)| p.first + p.positions.len() <= nv)
            .flat_map(|(i, p)| {
                (0..p.positions.len())
                    .step_by(CHUNK)
                    .map(move |v0| (i, v0, (v0 + CHUNK).min(p.positions.len())))
            })
            .collect();
        let run = |&(i, v0, v1): &(usize, usize, usize)| {
            let part = &self.parts[i];
            pose_range(part, &setups[i], v0..v1, &base.positions[part.first..], &base.normals[part.first..])
        };
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(tasks.len());
        let results: Vec<(usize, PosedRange)> = if threads <= 1 || nv < 2 * CHUNK {
            tasks.iter().enumerate().map(|(k, t)| (k, run(t))).collect()
        } else {
            let next = std::sync::atomic::AtomicUsize::new(0);
            std::thread::scope(|scope| {
                let workers: Vec<_> = (0..threads)
                    .map(|_| {
                        scope.spawn(|| {
                            let mut done = Vec::new();
                            loop {
                                let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                                let Some(t) = tasks.get(k) else { break };
                                done.push((k, run(t)));
                            }
                            done
                        })
                    })
                    .collect();
                workers.into_iter().flat_map(|w| w.join().unwrap_or_default()).collect()
            })
        };
        for (k, (pos, nrm)) in results {
            let (i, v0, _) = tasks[k];
            let first = self.parts[i].first + v0;
            positions[first..first + pos.len()].copy_from_slice(&pos);
            normals[first..first + nrm.len()].copy_from_slice(&nrm);
        }
        let outline_normals = if base.outline_normals.is_empty() || self.groups.len() != nv {
            Vec::new()
        } else {
            let mut sums = vec![Vec3f::ZERO; self.group_count];
            for (g, n) in self.groups.iter().zip(&normals) {
                sums[*g as usize] += Vec3f::from_array(*n);
            }
            // Each rest outline direction's length is its width multiplier (`mesh::outline_scale`).
            self.groups
                .iter()
                .zip(&normals)
                .zip(&base.outline_normals)
                .map(|((g, n), rest)| {
                    let scale = Vec3f::from_array(*rest).length();
                    (sums[*g as usize].try_normalize().unwrap_or(Vec3f::from_array(*n)) * scale).to_array()
                })
                .collect()
        };
        Mesh {
            positions,
            normals,
            outline_normals,
            indices: base.indices.clone(),
            uvs: base.uvs.clone(),
            colors: base.colors.clone(),
            material_ids: base.material_ids.clone(),
            materials: base.materials.clone(),
        }
    }
}

/// A node's translation, rotation (unit quaternion `[x, y, z, w]`) and scale (glTF 2.0 §3.5.3).
pub type Trs = ([f32; 3], [f32; 4], [f32; 3]);

/// What posing every vertex of one part shares.
struct PartSetup<'a> {
    /// Its skin's joint matrices (empty for a rigid part).
    joints: &'a [Mat4],
    /// Its node's global matrix and that matrix's normal matrix.
    node: Mat4,
    node_normals: Mat4,
    /// The morph targets with a non-zero weight: (target, weight).
    active: Vec<(usize, f32)>,
}

/// Posed positions and normals of a range of a part's vertices.
type PosedRange = (Vec<[f32; 3]>, Vec<[f32; 3]>);

/// Vertices `range` of `part` posed (module docs: morph, then skin or node). `rest_positions` and
/// `rest_normals` are the rest mesh's from the part's first vertex on: a non-finite position keeps
/// its rest value, a degenerate normal its rest normal.
fn pose_range(
    part: &Part,
    setup: &PartSetup<'_>,
    range: std::ops::Range<usize>,
    rest_positions: &[[f32; 3]],
    rest_normals: &[[f32; 3]],
) -> PosedRange {
    let mut positions = Vec::with_capacity(range.len());
    let mut normals = Vec::with_capacity(range.len());
    for v in range {
        let mut p = Vec3f::from_array(part.positions[v]);
        let mut nrm = Vec3f::from_array(part.normals[v]);
        for &(i, x) in &setup.active {
            let t = &part.targets[i];
            if let Some(d) = t.positions.get(v) {
                p += Vec3f::from_array(*d) * x;
            }
            if let Some(d) = t.normals.get(v) {
                nrm += Vec3f::from_array(*d) * x;
            }
        }
        let (m, nm) = match part.influences.get(v) {
            Some(inf) if inf.iter().any(|&(_, x)| x > 0.0) && !setup.joints.is_empty() => {
                let mut m = Mat4 { cols: [[0.0; 4]; 4] };
                for &(j, x) in inf {
                    if x == 0.0 {
                        continue;
                    }
                    let Some(jm) = setup.joints.get(j as usize) else { continue };
                    for (c, sc) in m.cols.iter_mut().zip(&jm.cols) {
                        for (a, b) in c.iter_mut().zip(sc) {
                            *a += x * b;
                        }
                    }
                }
                (m, m.normal_matrix())
            }
            _ => (setup.node, setup.node_normals),
        };
        let q = m.transform_point(p);
        positions.push(if q.to_array().iter().all(|c| c.is_finite()) {
            q.to_array().map(|c| c.clamp(-COORD_MAX, COORD_MAX))
        } else {
            rest_positions[v]
        });
        let fallback = Vec3f::from_array(rest_normals[v]);
        normals.push(nm.transform_vector(nrm).try_normalize().unwrap_or(fallback).to_array());
    }
    (positions, normals)
}

/// The clip time of a clip of `duration` seconds at scene time `t`: `(t − start)·speed` (0 before
/// `start`), wrapped into `[0, duration)` when `looping`, else held at `[0, duration]`.
pub fn clip_time(t: f32, start: f32, speed: f32, duration: f32, looping: bool) -> f32 {
    let local = ((t - start).max(0.0) * speed) as f64;
    clip_wrap(local as f32, duration, looping)
}

/// A clip time wrapped into `[0, duration)` (`looping`) or held within `[0, duration]`.
pub fn clip_wrap(time: f32, duration: f32, looping: bool) -> f32 {
    if !time.is_finite() {
        return 0.0;
    }
    if duration.is_nan() || duration <= 0.0 {
        return 0.0;
    }
    if looping {
        (time as f64).rem_euclid(duration as f64) as f32
    } else {
        time.clamp(0.0, duration)
    }
}

/// Per vertex, the group of vertices at exactly the same position, and the number of groups
/// (what [`crate::mesh::with_outline_normals`] averages over).
pub(crate) fn position_groups(positions: &[[f32; 3]]) -> (Vec<u32>, usize) {
    let mut ids: std::collections::HashMap<[u32; 3], u32> = std::collections::HashMap::new();
    let key = |p: &[f32; 3]| p.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
    let groups = positions
        .iter()
        .map(|p| {
            let next = ids.len() as u32;
            *ids.entry(key(p)).or_insert(next)
        })
        .collect();
    (groups, ids.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_time_loops_holds_and_waits_for_its_start() {
        assert_eq!(clip_time(0.5, 1.0, 1.0, 2.0, true), 0.0);
        assert!((clip_time(3.5, 1.0, 1.0, 2.0, true) - 0.5).abs() < 1e-6);
        assert_eq!(clip_time(9.0, 0.0, 1.0, 2.0, false), 2.0);
        assert!((clip_time(1.25, 0.0, 2.0, 2.0, true) - 0.5).abs() < 1e-6);
        assert!((clip_wrap(-0.5, 2.0, true) - 1.5).abs() < 1e-6);
        assert_eq!(clip_wrap(f32::NAN, 2.0, true), 0.0);
        assert_eq!(clip_wrap(1.0, 0.0, true), 0.0);
    }
}
