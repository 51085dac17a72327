//! The reader of a VRM's spring bones: VRM 1.0 `VRMC_springBone` (`colliders`, `colliderGroups`,
//! `springs` with their `joints` and `center`) and VRM 0.x `VRM.secondaryAnimation` (`boneGroups`
//! and `colliderGroups`), the latter converted to the former as the VRM 1.0 migration does:
//!
//! - each bone group's `bones` and all their descendants become joints, in chains that follow a
//!   node's first child (a node's other children start chains of their own); a chain's last bone
//!   gets a tail 0.07 units along its parent-to-bone direction (VRM 0.x's end tail);
//! - `stiffiness` (sic) → `stiffness`, `dragForce`, `gravityPower`, `gravityDir` and `hitRadius`
//!   are the group's, for every joint; `center = -1` is none;
//! - colliders are spheres; VRM 0.x stores their `offset` and the `gravityDir` with z opposite to
//!   the glTF file's (the Unity space 0.x writes), so z is negated.
//!
//! Everything is checked: indices in range, a joint node in one spring only and each joint the
//! child of the one before (so no cycles), a `center` that is an ancestor of its spring's first
//! joint, finite numbers, radii ≥ 0, stiffness, drag and gravity power ≥ 0 (drag ≤ 1), and the
//! limits of `spring`. A problem is an error naming the JSON path.

use crate::limits::{MAX_SPRING_COLLIDERS, MAX_SPRING_COLLISION_PAIRS, MAX_SPRING_JOINTS};
use crate::rig::{RestLocal, RigNode};
use crate::spring_bones::{Collider, ColliderShape, Joint, Spring, SpringBones};
use hadou_math::keyframes::trs_matrix;
use hadou_math::{Mat4, Vec3f};
use serde_json::Value;

/// VRM 0.x's tail past a chain's last bone, in metres (scene units).
const TAIL_0X: f32 = 0.07;

fn index(v: Option<&Value>, len: usize, at: &str) -> Result<usize, String> {
    match v.and_then(Value::as_u64) {
        Some(i) if (i as usize) < len => Ok(i as usize),
        Some(i) => Err(format!("{at} is {i}, but the file has {len} of them (0-based)")),
        None => Err(format!("{at} must be a non-negative integer")),
    }
}

/// A finite number at `v` (or `default` when absent), at least `lo`.
fn number(v: Option<&Value>, default: f32, lo: f32, at: &str) -> Result<f32, String> {
    let Some(v) = v else { return Ok(default) };
    let x = v.as_f64().ok_or_else(|| format!("{at} must be a number"))?;
    if !x.is_finite() || x.abs() > f32::MAX as f64 {
        return Err(format!("{at} must be a finite number"));
    }
    if (x as f32) < lo {
        return Err(format!("{at} is {x}, but it must be at least {lo}"));
    }
    Ok(x as f32)
}

/// A vector `[x, y, z]` (1.0) or `{x, y, z}` (0.x) at `v`, or `default` when absent.
fn vector(v: Option<&Value>, default: Vec3f, at: &str) -> Result<Vec3f, String> {
    let Some(v) = v else { return Ok(default) };
    let c = |k: usize, name: &str| -> Result<f32, String> {
        let x = match v {
            Value::Array(a) if a.len() == 3 => a.get(k),
            Value::Object(o) => Some(o.get(name).unwrap_or(&Value::Null)).filter(|x| !x.is_null()),
            _ => return Err(format!("{at} must be three numbers")),
        };
        number(x, 0.0, f32::MIN, &format!("{at}.{name}"))
    };
    Ok(Vec3f::new(c(0, "x")?, c(1, "y")?, c(2, "z")?))
}

fn unit(v: Vec3f, at: &str) -> Result<Vec3f, String> {
    v.try_normalize().filter(|u| u.is_finite()).ok_or_else(|| format!("{at} must not be zero"))
}

fn array<'a>(v: Option<&'a Value>, at: &str) -> Result<&'a [Value], String> {
    match v {
        None => Ok(&[]),
        Some(v) => v.as_array().map(Vec::as_slice).ok_or_else(|| format!("{at} must be an array")),
    }
}

/// A node's rest translation (a matrix node: its matrix's).
fn rest_translation(n: &RigNode) -> Vec3f {
    match &n.rest {
        RestLocal::Trs { t, .. } => Vec3f::from_array(*t),
        RestLocal::Matrix(m) => Vec3f::new(m.cols[3][0], m.cols[3][1], m.cols[3][2]),
    }
}

/// Every node's rest global matrix (file space), parents before children as `order` lists them.
fn rest_globals(nodes: &[RigNode], order: &[usize]) -> Vec<Mat4> {
    let mut g = vec![Mat4::IDENTITY; nodes.len()];
    for &i in order {
        let local = match &nodes[i].rest {
            RestLocal::Trs { t, r, s } => trs_matrix(*t, *r, *s),
            RestLocal::Matrix(m) => *m,
        };
        g[i] = nodes[i].parent.map_or(local, |p| g[p] * local);
    }
    g
}

/// The spring bones of a VRM file (`None` when it has none).
pub(crate) fn read_springs(
    raw: &Value,
    nodes: &[RigNode],
    order: &[usize],
) -> Result<Option<SpringBones>, String> {
    let Some(ext) = raw.get("extensions") else { return Ok(None) };
    let sb = if let Some(s) = ext.get("VRMC_springBone") {
        read_1(s, nodes)?
    } else if let Some(s) = ext.get("VRM").and_then(|v| v.get("secondaryAnimation")) {
        read_0(s, nodes, order)?
    } else {
        return Ok(None);
    };
    if sb.springs.iter().all(|s| s.joints.is_empty()) {
        return Ok(None);
    }
    let mut sb = sb;
    let mut moving = vec![false; nodes.len()];
    for j in sb.springs.iter().flat_map(|s| &s.joints) {
        moving[j.node] = true;
    }
    for &i in order {
        if let Some(p) = nodes[i].parent {
            moving[i] |= moving[p];
        }
    }
    sb.moving = moving;
    let pairs: usize = sb.springs.iter().map(|s| s.joints.len() * s.colliders.len()).sum();
    if pairs > MAX_SPRING_COLLISION_PAIRS {
        return Err(format!(
            "the spring bones have {pairs} joint-collider pairs (each spring's joints times its colliders), \
             over the limit of {MAX_SPRING_COLLISION_PAIRS}"
        ));
    }
    Ok(Some(sb))
}

/// Checks that no node is a joint twice and the joint count is within the limit.
fn check_joints(springs: &[Spring], at: &str) -> Result<(), String> {
    let n: usize = springs.iter().map(|s| s.joints.len()).sum();
    if n > MAX_SPRING_JOINTS {
        return Err(format!("{at} has {n} joints, over the limit of {MAX_SPRING_JOINTS}"));
    }
    let mut seen = std::collections::HashMap::new();
    for (i, s) in springs.iter().enumerate() {
        for (k, j) in s.joints.iter().enumerate() {
            if let Some((a, b)) = seen.insert(j.node, (i, k)) {
                return Err(format!(
                    "{at}: node {} is a joint twice (springs[{a}].joints[{b}] and springs[{i}].joints[{k}])",
                    j.node
                ));
            }
        }
    }
    Ok(())
}

/// Checks that `center` is an ancestor of `first`.
fn check_center(nodes: &[RigNode], center: usize, first: usize, at: &str) -> Result<(), String> {
    let mut n = first;
    for _ in 0..nodes.len() {
        match nodes[n].parent {
            Some(p) if p == center => return Ok(()),
            Some(p) => n = p,
            None => break,
        }
    }
    Err(format!("{at} is node {center}, which is not an ancestor of the spring's first joint (node {first})"))
}

/// VRM 1.0 `VRMC_springBone`.
fn read_1(s: &Value, nodes: &[RigNode]) -> Result<SpringBones, String> {
    let root = "VRMC_springBone";
    let cols = array(s.get("colliders"), &format!("{root}.colliders"))?;
    if cols.len() > MAX_SPRING_COLLIDERS {
        return Err(format!(
            "{root}.colliders has {} colliders, over the limit of {MAX_SPRING_COLLIDERS}",
            cols.len()
        ));
    }
    let mut colliders = Vec::new();
    for (i, c) in cols.iter().enumerate() {
        let at = format!("{root}.colliders[{i}]");
        let node = index(c.get("node"), nodes.len(), &format!("{at}.node"))?;
        let shape = c.get("shape").ok_or_else(|| format!("{at}.shape is missing"))?;
        let shape = if let Some(sp) = shape.get("sphere") {
            let sat = format!("{at}.shape.sphere");
            ColliderShape::Sphere {
                offset: vector(sp.get("offset"), Vec3f::ZERO, &format!("{sat}.offset"))?,
                radius: number(sp.get("radius"), 0.0, 0.0, &format!("{sat}.radius"))?,
            }
        } else if let Some(cp) = shape.get("capsule") {
            let cat = format!("{at}.shape.capsule");
            ColliderShape::Capsule {
                offset: vector(cp.get("offset"), Vec3f::ZERO, &format!("{cat}.offset"))?,
                tail: vector(cp.get("tail"), Vec3f::ZERO, &format!("{cat}.tail"))?,
                radius: number(cp.get("radius"), 0.0, 0.0, &format!("{cat}.radius"))?,
            }
        } else {
            return Err(format!("{at}.shape must have `sphere` or `capsule`"));
        };
        colliders.push(Collider { node, shape });
    }
    let mut groups = Vec::new();
    for (i, g) in array(s.get("colliderGroups"), &format!("{root}.colliderGroups"))?.iter().enumerate() {
        let at = format!("{root}.colliderGroups[{i}].colliders");
        let list = array(g.get("colliders"), &at)?;
        let mut members = Vec::new();
        for (k, c) in list.iter().enumerate() {
            members.push(index(Some(c), colliders.len(), &format!("{at}[{k}]"))?);
        }
        groups.push(members);
    }
    let mut springs = Vec::new();
    for (i, sp) in array(s.get("springs"), &format!("{root}.springs"))?.iter().enumerate() {
        let at = format!("{root}.springs[{i}]");
        let joints = array(sp.get("joints"), &format!("{at}.joints"))?;
        if joints.len() > MAX_SPRING_JOINTS {
            return Err(format!(
                "{at}.joints has {} joints, over the limit of {MAX_SPRING_JOINTS}",
                joints.len()
            ));
        }
        let mut js: Vec<(usize, Joint)> = Vec::new();
        for (k, j) in joints.iter().enumerate() {
            let jat = format!("{at}.joints[{k}]");
            let node = index(j.get("node"), nodes.len(), &format!("{jat}.node"))?;
            if let Some((prev, _)) = js.last() {
                if nodes[node].parent != Some(*prev) {
                    return Err(format!(
                        "{jat}.node is node {node}, which is not a child of the joint before it (node {prev})"
                    ));
                }
            }
            let joint = Joint {
                node,
                tail: Vec3f::ZERO,
                rest: [0.0, 0.0, 0.0, 1.0],
                axis: None,
                hit_radius: number(j.get("hitRadius"), 0.0, 0.0, &format!("{jat}.hitRadius"))?,
                stiffness: number(j.get("stiffness"), 1.0, 0.0, &format!("{jat}.stiffness"))?,
                gravity_power: number(j.get("gravityPower"), 0.0, 0.0, &format!("{jat}.gravityPower"))?,
                gravity_dir: unit(
                    vector(j.get("gravityDir"), Vec3f::new(0.0, -1.0, 0.0), &format!("{jat}.gravityDir"))?,
                    &format!("{jat}.gravityDir"),
                )?,
                drag: number(j.get("dragForce"), 0.5, 0.0, &format!("{jat}.dragForce"))?.min(1.0),
            };
            js.push((node, joint));
        }
        // Each joint's tail is the next joint; the last is only a tail.
        let mut chain = Vec::new();
        for w in js.windows(2) {
            let mut j = w[0].1.clone();
            j.tail = rest_translation(&nodes[w[1].0]);
            chain.push(finish(j, nodes));
        }
        let mut members = Vec::new();
        for (k, g) in array(sp.get("colliderGroups"), &format!("{at}.colliderGroups"))?.iter().enumerate() {
            let gi = index(Some(g), groups.len(), &format!("{at}.colliderGroups[{k}]"))?;
            for &c in &groups[gi] {
                if !members.contains(&c) {
                    members.push(c);
                }
            }
        }
        let center = match sp.get("center") {
            None => None,
            Some(c) => {
                let c = index(Some(c), nodes.len(), &format!("{at}.center"))?;
                if let Some((first, _)) = js.first() {
                    check_center(nodes, c, *first, &format!("{at}.center"))?;
                }
                Some(c)
            }
        };
        springs.push(Spring { joints: chain, colliders: members, center });
    }
    check_joints(&springs, &format!("{root}.springs"))?;
    Ok(SpringBones { springs, colliders, moving: Vec::new() })
}

/// VRM 0.x `secondaryAnimation`, converted (module docs).
fn read_0(s: &Value, nodes: &[RigNode], order: &[usize]) -> Result<SpringBones, String> {
    let root = "VRM.secondaryAnimation";
    let flip = |v: Vec3f| Vec3f::new(v.x, v.y, -v.z);
    let mut colliders = Vec::new();
    let mut groups = Vec::new();
    for (i, g) in array(s.get("colliderGroups"), &format!("{root}.colliderGroups"))?.iter().enumerate() {
        let at = format!("{root}.colliderGroups[{i}]");
        let node = index(g.get("node"), nodes.len(), &format!("{at}.node"))?;
        let mut members = Vec::new();
        for (k, c) in array(g.get("colliders"), &format!("{at}.colliders"))?.iter().enumerate() {
            let cat = format!("{at}.colliders[{k}]");
            if colliders.len() >= MAX_SPRING_COLLIDERS {
                return Err(format!("{cat}: over the limit of {MAX_SPRING_COLLIDERS} colliders"));
            }
            let offset = flip(vector(c.get("offset"), Vec3f::ZERO, &format!("{cat}.offset"))?);
            let radius = number(c.get("radius"), 0.0, 0.0, &format!("{cat}.radius"))?;
            members.push(colliders.len());
            colliders.push(Collider { node, shape: ColliderShape::Sphere { offset, radius } });
        }
        groups.push(members);
    }
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); nodes.len()];
    for &i in order {
        if let Some(p) = nodes[i].parent {
            children[p].push(i);
        }
    }
    // `order` lists parents before children but not children in file order; keep file order.
    children.iter_mut().for_each(|c| c.sort_unstable());
    let globals = rest_globals(nodes, order);
    let mut springs = Vec::new();
    let mut total = 0usize;
    // A bone listed twice (or inside another listed bone's tree) is a joint once, of its first group.
    let mut seen = vec![false; nodes.len()];
    for (i, g) in array(s.get("boneGroups"), &format!("{root}.boneGroups"))?.iter().enumerate() {
        let at = format!("{root}.boneGroups[{i}]");
        let template = Joint {
            node: 0,
            tail: Vec3f::ZERO,
            rest: [0.0, 0.0, 0.0, 1.0],
            axis: None,
            hit_radius: number(g.get("hitRadius"), 0.02, 0.0, &format!("{at}.hitRadius"))?,
            stiffness: number(g.get("stiffiness"), 1.0, 0.0, &format!("{at}.stiffiness"))?,
            gravity_power: number(g.get("gravityPower"), 0.0, 0.0, &format!("{at}.gravityPower"))?,
            gravity_dir: unit(
                flip(vector(g.get("gravityDir"), Vec3f::new(0.0, -1.0, 0.0), &format!("{at}.gravityDir"))?),
                &format!("{at}.gravityDir"),
            )?,
            drag: number(g.get("dragForce"), 0.4, 0.0, &format!("{at}.dragForce"))?.min(1.0),
        };
        let center = match g.get("center").and_then(Value::as_i64) {
            Some(c) if c < 0 => None,
            _ => match g.get("center") {
                None | Some(Value::Null) => None,
                c => Some(index(c, nodes.len(), &format!("{at}.center"))?),
            },
        };
        let mut members = Vec::new();
        for (k, c) in array(g.get("colliderGroups"), &format!("{at}.colliderGroups"))?.iter().enumerate() {
            let gi = index(Some(c), groups.len(), &format!("{at}.colliderGroups[{k}]"))?;
            for &c in &groups[gi] {
                if !members.contains(&c) {
                    members.push(c);
                }
            }
        }
        for (k, b) in array(g.get("bones"), &format!("{at}.bones"))?.iter().enumerate() {
            let bat = format!("{at}.bones[{k}]");
            let first = index(Some(b), nodes.len(), &bat)?;
            if let Some(c) = center {
                check_center(nodes, c, first, &format!("{at}.center"))?;
            }
            // Chains along first children; other children start new chains.
            let mut starts = vec![first];
            while let Some(start) = starts.pop() {
                let mut chain = Vec::new();
                let mut n = start;
                loop {
                    if seen[n] {
                        break;
                    }
                    seen[n] = true;
                    total += 1;
                    if total > MAX_SPRING_JOINTS {
                        return Err(format!(
                            "{bat}: its bones bring the joints past the limit of {MAX_SPRING_JOINTS}"
                        ));
                    }
                    let kids = &children[n];
                    let tail = match kids.first() {
                        Some(&c) => rest_translation(&nodes[c]),
                        None => leaf_tail(nodes, &globals, n),
                    };
                    chain.push(finish(Joint { node: n, tail, ..template.clone() }, nodes));
                    starts.extend(kids.iter().skip(1).rev());
                    match kids.first() {
                        Some(&c) => n = c,
                        None => break,
                    }
                }
                if !chain.is_empty() {
                    springs.push(Spring { joints: chain, colliders: members.clone(), center });
                }
            }
        }
    }
    check_joints(&springs, &format!("{root}.boneGroups"))?;
    Ok(SpringBones { springs, colliders, moving: Vec::new() })
}

/// `j` with its node's unit rest rotation and its unit tail direction (none for a matrix node or a
/// zero tail: the joint stays at rest).
fn finish(mut j: Joint, nodes: &[RigNode]) -> Joint {
    match &nodes[j.node].rest {
        RestLocal::Trs { r, .. } => {
            j.rest = hadou_math::keyframes::normalize_quat(*r);
            j.axis = j.tail.try_normalize().filter(|a| a.is_finite());
        }
        RestLocal::Matrix(_) => j.axis = None,
    }
    j
}

/// A VRM 0.x leaf's tail in its local space: 0.07 units past it along its parent-to-it direction.
fn leaf_tail(nodes: &[RigNode], globals: &[Mat4], n: usize) -> Vec3f {
    let at = globals[n].transform_point(Vec3f::ZERO);
    let from = nodes[n].parent.map_or(Vec3f::ZERO, |p| globals[p].transform_point(Vec3f::ZERO));
    let dir = (at - from).try_normalize().unwrap_or(Vec3f::Y);
    let world = at + dir * TAIL_0X;
    crate::spring::affine_inverse(&globals[n]).transform_point(world)
}
