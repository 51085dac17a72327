//! VRM Animation (`.vrma`, `VRMC_vrm_animation` 1.0) clips retargeted onto a VRM character by
//! humanoid bone names.
//!
//! A VRMA file is a glTF file whose nodes form a humanoid skeleton (`humanoid.humanBones` maps
//! bone names to nodes) at its own rest pose, with animations on those nodes, and expression nodes
//! whose translation `x` is the expression's weight. Retargeting, as the VRMA specification
//! describes it, carries each bone's motion *relative to the file's rest pose* onto the
//! character's bone relative to *its* rest pose, in world axes:
//! - rotation: the key `q` of bone `B` becomes the world-axis delta `d = P_a · q · W_a⁻¹` (`P_a`,
//!   `W_a`: the rest world rotations of the VRMA bone's parent and of the bone; `d = 1` at the
//!   VRMA rest pose), and the character's bone takes the local rotation
//!   `P_t⁻¹ · d · P_t · R_t` (`P_t`: its parent's rest world rotation, `R_t`: its rest local
//!   rotation), so `d = 1` leaves it at its own rest;
//! - translation (the hips only): the key's world position `G_a(parent) · τ`, scaled by the ratio
//!   of the character's hips height to the file's, expressed in the character's hips parent
//!   (`G_t(parent)⁻¹ · …`);
//! - expressions: the translation `x` of an expression node is that expression's weight.
//!
//! CUBICSPLINE tangents go through the same linear maps (without the translation part). Bones and
//! expressions the character lacks are skipped with one warning; channels on other nodes are
//! ignored.

use crate::files::{parent_dir, read_regular_file, GLTF_MAX_BYTES};
use crate::gltf_anim::read_clips;
use crate::gltf_load::{open, read_buffers, Opened};
use crate::guard::guarded;
use crate::rig::{Channel, ChannelPath, Clip, RestLocal, Rig, RigNode};
use hadou_math::keyframes::{normalize_quat, quat_conjugate, quat_mul, rotation_of, Sampling};
use hadou_math::{Mat4, Vec3f};
use serde_json::Value;
use std::path::Path;

/// Loads the VRM Animation file `path` (its buffers inside its own directory) and retargets its clip
/// `name` (or its first clip) onto `rig`; returns the clip and the load's warnings.
pub fn load_vrma_clip(path: &Path, rig: &Rig, name: Option<&str>) -> Result<(Clip, Vec<String>), String> {
    let mut warnings = Vec::new();
    let root =
        crate::files::canonicalize(parent_dir(path)).map_err(|e| format!("cannot read the file: {e}"))?;
    let clip = load_vrma(path, &root, rig, name, &mut warnings)?;
    Ok((clip, warnings))
}

/// Loads the VRMA file `path` (its buffers confined to `root`) and retargets its clip `name` (or its
/// first clip) onto `rig`.
pub(crate) fn load_vrma(
    path: &Path,
    root: &Path,
    rig: &Rig,
    name: Option<&str>,
    warnings: &mut Vec<String>,
) -> Result<Clip, String> {
    let bytes = read_regular_file(path, GLTF_MAX_BYTES).map_err(|e| format!("cannot read the file: {e}"))?;
    let mut bytes_left = GLTF_MAX_BYTES.saturating_sub(bytes.len() as u64);
    let Opened { gltf, raw, parent, blob } = open(std::borrow::Cow::Owned(bytes))?;
    let ext = raw
        .get("extensions")
        .and_then(|e| e.get("VRMC_vrm_animation"))
        .ok_or("it is not a VRM Animation: it has no VRMC_vrm_animation extension")?;
    if rig.humanoid.is_empty() {
        return Err(
            "a VRM Animation plays on a VRM character, and this object's file has no humanoid bones".into()
        );
    }
    let buffers = read_buffers(&gltf, blob, parent_dir(path), root, &mut bytes_left)?;
    let nodes: Vec<RigNode> = gltf
        .nodes()
        .map(|n| RigNode {
            parent: parent[n.index()],
            rest: match n.transform() {
                gltf::scene::Transform::Matrix { matrix } => RestLocal::Matrix(Mat4 { cols: matrix }),
                gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
                    RestLocal::Trs { t: translation, r: rotation, s: scale }
                }
            },
            weights: Vec::new(),
        })
        .collect();
    let clips = guarded("glTF", || read_clips(&gltf, &raw, &buffers, &nodes, warnings))??;
    let clip = match name {
        Some(n) => clips.iter().find(|c| c.name == n).ok_or_else(|| {
            let list: Vec<String> = clips.iter().map(|c| format!("\"{}\"", c.name)).collect();
            format!(
                "it has no clip \"{n}\"; its clips are {}",
                if list.is_empty() { "none".into() } else { list.join(", ") }
            )
        })?,
        None => clips.first().ok_or("it has no animation clips")?,
    };
    let bones = named_nodes(
        ext.get("humanoid").and_then(|h| h.get("humanBones")),
        nodes.len(),
        "humanoid.humanBones",
    )?;
    let mut exprs = Vec::new();
    if let Some(e) = ext.get("expressions") {
        for group in ["preset", "custom"] {
            exprs.extend(named_nodes(e.get(group), nodes.len(), &format!("expressions.{group}"))?);
        }
    }
    retarget(clip, &nodes, &bones, &exprs, rig, warnings)
}

/// `{name: {node}}` → `(name, node)` pairs, every node checked.
fn named_nodes(v: Option<&Value>, n: usize, at: &str) -> Result<Vec<(String, usize)>, String> {
    let Some(v) = v else { return Ok(Vec::new()) };
    let map = v.as_object().ok_or_else(|| format!("VRMC_vrm_animation.{at} must be an object"))?;
    map.iter()
        .map(|(name, b)| match b.get("node").and_then(Value::as_u64) {
            Some(i) if (i as usize) < n => Ok((name.clone(), i as usize)),
            _ => Err(format!("VRMC_vrm_animation.{at}.{name}.node must be a node index below {n}")),
        })
        .collect()
}

/// Rest world matrices of `nodes` (a forest), without recursion.
fn rest_globals(nodes: &[RigNode], base: Mat4) -> Vec<Mat4> {
    let n = nodes.len();
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, node) in nodes.iter().enumerate() {
        if let Some(p) = node.parent {
            children[p].push(i);
        }
    }
    let mut out = vec![base; n];
    let mut stack: Vec<(usize, Mat4)> =
        (0..n).filter(|&i| nodes[i].parent.is_none()).map(|i| (i, base)).collect();
    while let Some((i, up)) = stack.pop() {
        let local = match nodes[i].rest {
            RestLocal::Matrix(m) => m,
            RestLocal::Trs { t, r, s } => hadou_math::keyframes::trs_matrix(t, r, s),
        };
        out[i] = up * local;
        stack.extend(children[i].iter().map(|&c| (c, out[i])));
    }
    out
}

/// The inverse of an affine matrix (its 3×3 block inverted through the normal matrix).
fn affine_inverse(m: &Mat4) -> Mat4 {
    let mut inv = m.normal_matrix().transpose();
    inv.cols[3] = [0.0, 0.0, 0.0, 1.0];
    let t = inv.transform_vector(Vec3f::new(m.cols[3][0], m.cols[3][1], m.cols[3][2]));
    inv.cols[3] = [-t.x, -t.y, -t.z, 1.0];
    inv
}

fn retarget(
    clip: &Clip,
    nodes: &[RigNode],
    bones: &[(String, usize)],
    exprs: &[(String, usize)],
    rig: &Rig,
    warnings: &mut Vec<String>,
) -> Result<Clip, String> {
    let src = rest_globals(nodes, Mat4::IDENTITY);
    let dst = rest_globals(&rig.nodes, rig.base);
    let rot = |m: &Mat4| rotation_of(m);
    let parent_rot = |g: &[Mat4], ns: &[RigNode], i: usize, base: &Mat4| match ns[i].parent {
        Some(p) => rot(&g[p]),
        None => rot(base),
    };
    let hips_height = |g: &[Mat4], bones: &[(String, usize)]| {
        bones.iter().find(|b| b.0 == "hips").map(|b| g[b.1].cols[3][1])
    };
    let scale = match (hips_height(&dst, &rig.humanoid), hips_height(&src, bones)) {
        (Some(t), Some(a)) if a > 1e-6 && t > 1e-6 => t / a,
        _ => 1.0,
    };
    let mut missing: Vec<&str> = Vec::new();
    let mut channels = Vec::new();
    for ch in &clip.channels {
        if let Some((bone, _)) = bones.iter().find(|b| b.1 == ch.node) {
            let Some(&(_, t)) = rig.humanoid.iter().find(|h| &h.0 == bone) else {
                if !missing.contains(&bone.as_str()) {
                    missing.push(bone);
                }
                continue;
            };
            match ch.path {
                ChannelPath::Rotation => {
                    let RestLocal::Trs { r: rest_t, .. } = rig.nodes[t].rest else {
                        warnings.push(format!("the character's bone `{bone}` (node {t}) has a matrix and cannot be animated; skipped"));
                        continue;
                    };
                    let pa = parent_rot(&src, nodes, ch.node, &Mat4::IDENTITY);
                    let wa_inv = quat_conjugate(rot(&src[ch.node]));
                    let pt = parent_rot(&dst, &rig.nodes, t, &rig.base);
                    let pt_inv = quat_conjugate(pt);
                    let right = quat_mul(wa_inv, quat_mul(pt, normalize_quat(rest_t)));
                    let left = quat_mul(pt_inv, pa);
                    let values = ch
                        .values
                        .chunks_exact(4)
                        .flat_map(|q| quat_mul(left, quat_mul([q[0], q[1], q[2], q[3]], right)))
                        .collect();
                    channels.push(Channel { node: t, values, ..ch.clone() });
                }
                ChannelPath::Translation if bone == "hips" => {
                    let up_a = nodes[ch.node].parent.map_or(Mat4::IDENTITY, |p| src[p]);
                    let up_t = rig.nodes[t].parent.map_or(rig.base, |p| dst[p]);
                    let to_t = affine_inverse(&up_t);
                    let per_key = if ch.sampling == Sampling::CubicSpline { 3 } else { 1 };
                    let values = ch
                        .values
                        .chunks_exact(3)
                        .enumerate()
                        .flat_map(|(k, v)| {
                            let v = Vec3f::from_array([v[0], v[1], v[2]]);
                            // Tangents (in and out of a CUBICSPLINE key) are directions.
                            let tangent = per_key == 3 && k % 3 != 1;
                            let out = if tangent {
                                to_t.transform_vector(up_a.transform_vector(v) * scale)
                            } else {
                                to_t.transform_point(up_a.transform_point(v) * scale)
                            };
                            out.to_array()
                        })
                        .collect();
                    channels.push(Channel { node: t, values, ..ch.clone() });
                }
                _ => {}
            }
        } else if let Some((name, _)) = exprs.iter().find(|e| e.1 == ch.node) {
            if ch.path != ChannelPath::Translation {
                continue;
            }
            let Some(e) = rig.expressions.iter().position(|x| &x.name == name) else {
                if !missing.contains(&name.as_str()) {
                    missing.push(name);
                }
                continue;
            };
            let values = ch.values.chunks_exact(3).map(|v| v[0]).collect();
            channels.push(Channel { node: e, path: ChannelPath::Expression, width: 1, values, ..ch.clone() });
        }
    }
    if !missing.is_empty() {
        warnings.push(format!(
            "the VRM Animation names bones or expressions the character lacks ({}); their keys are skipped",
            missing.join(", ")
        ));
    }
    Ok(Clip { name: clip.name.clone(), duration: clip.duration, channels })
}
