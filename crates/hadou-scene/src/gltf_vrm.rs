//! The VRM parts of a `.vrm` file that pose a character: expressions (VRM 1.0
//! `VRMC_vrm.expressions`, VRM 0.x `VRM.blendShapeMaster.blendShapeGroups`) and the humanoid bone
//! map (`VRMC_vrm.humanoid.humanBones`, VRM 0.x `VRM.humanoid.humanBones`), read from the raw JSON.
//!
//! VRM 0.x names are mapped to VRM 1.0's (`joy` → `happy`, `a` → `aa`, `blink_l` → `blinkLeft`, …),
//! its bind weights (0–100) to 0–1, and its binds' meshes to every node that instantiates that
//! mesh. A broken extension (wrong types, indices out of range) is an error naming the JSON path.

use crate::rig::{Expression, RigNode, VrmVersion};
use serde_json::Value;

/// VRM 0.x blend-shape preset names and their VRM 1.0 expression names.
const PRESETS_0X: &[(&str, &str)] = &[
    ("joy", "happy"),
    ("angry", "angry"),
    ("sorrow", "sad"),
    ("fun", "relaxed"),
    ("a", "aa"),
    ("i", "ih"),
    ("u", "ou"),
    ("e", "ee"),
    ("o", "oh"),
    ("blink", "blink"),
    ("blink_l", "blinkLeft"),
    ("blink_r", "blinkRight"),
    ("lookup", "lookUp"),
    ("lookdown", "lookDown"),
    ("lookleft", "lookLeft"),
    ("lookright", "lookRight"),
    ("neutral", "neutral"),
];

/// The file's VRM version, if it is a VRM.
pub(crate) fn vrm_version(raw: &Value) -> Option<VrmVersion> {
    let ext = raw.get("extensions")?;
    if ext.get("VRMC_vrm").is_some() {
        Some(VrmVersion::V1)
    } else if ext.get("VRM").is_some() {
        Some(VrmVersion::V0)
    } else {
        None
    }
}

fn index(v: &Value, len: usize, at: &str) -> Result<usize, String> {
    match v.as_u64() {
        Some(i) if (i as usize) < len => Ok(i as usize),
        Some(i) => Err(format!("{at} is {i}, but the file has {len} of them (0-based)")),
        None => Err(format!("{at} must be a non-negative integer")),
    }
}

fn number(v: Option<&Value>, default: f64, at: &str) -> Result<f64, String> {
    match v {
        None => Ok(default),
        Some(x) => {
            x.as_f64().filter(|f| f.is_finite()).ok_or_else(|| format!("{at} must be a finite number"))
        }
    }
}

fn object<'a>(v: &'a Value, at: &str) -> Result<&'a serde_json::Map<String, Value>, String> {
    v.as_object().ok_or_else(|| format!("{at} must be an object"))
}

fn array<'a>(v: &'a Value, at: &str) -> Result<&'a [Value], String> {
    v.as_array().map(|a| a.as_slice()).ok_or_else(|| format!("{at} must be an array"))
}

/// The expressions of a VRM file (empty for other files). Binds to targets a node's mesh lacks are
/// errors; expression weights are 0–1.
pub(crate) fn read_expressions(
    raw: &Value,
    nodes: &[RigNode],
    mesh_of: &[Option<usize>],
) -> Result<Vec<Expression>, String> {
    let ext = match raw.get("extensions") {
        Some(e) => e,
        None => return Ok(Vec::new()),
    };
    let mut out: Vec<Expression> = Vec::new();
    let check_target = |node: usize, target: usize, at: &str| -> Result<(), String> {
        let n = nodes[node].weights.len();
        if target >= n {
            return Err(format!(
                "{at}: morph target {target} of node {node}, whose mesh has {n} morph targets"
            ));
        }
        Ok(())
    };
    if let Some(vrm) = ext.get("VRMC_vrm") {
        let Some(exprs) = vrm.get("expressions") else { return Ok(out) };
        let exprs = object(exprs, "VRMC_vrm.expressions")?;
        for group in ["preset", "custom"] {
            let Some(set) = exprs.get(group) else { continue };
            for (name, e) in object(set, &format!("VRMC_vrm.expressions.{group}"))? {
                let at = format!("VRMC_vrm.expressions.{group}.{name}");
                let mut binds = Vec::new();
                if let Some(b) = object(e, &at)?.get("morphTargetBinds") {
                    for (k, bind) in array(b, &format!("{at}.morphTargetBinds"))?.iter().enumerate() {
                        let bat = format!("{at}.morphTargetBinds[{k}]");
                        let node = index(
                            bind.get("node").unwrap_or(&Value::Null),
                            nodes.len(),
                            &format!("{bat}.node"),
                        )?;
                        let target = index(
                            bind.get("index").unwrap_or(&Value::Null),
                            usize::MAX,
                            &format!("{bat}.index"),
                        )?;
                        check_target(node, target, &bat)?;
                        let w = number(bind.get("weight"), 1.0, &format!("{bat}.weight"))?.clamp(0.0, 1.0);
                        binds.push((node, target, w as f32));
                    }
                }
                out.push(Expression { name: name.clone(), binds });
            }
        }
    } else if let Some(vrm) = ext.get("VRM") {
        let Some(groups) = vrm.get("blendShapeMaster").and_then(|b| b.get("blendShapeGroups")) else {
            return Ok(out);
        };
        for (g, group) in array(groups, "VRM.blendShapeMaster.blendShapeGroups")?.iter().enumerate() {
            let at = format!("VRM.blendShapeMaster.blendShapeGroups[{g}]");
            let group = object(group, &at)?;
            let preset = group.get("presetName").and_then(Value::as_str).unwrap_or("unknown");
            let name = match PRESETS_0X.iter().find(|(p, _)| *p == preset) {
                Some((_, n)) => n.to_string(),
                None => group.get("name").and_then(Value::as_str).unwrap_or(preset).to_string(),
            };
            let mut binds = Vec::new();
            if let Some(b) = group.get("binds") {
                for (k, bind) in array(b, &format!("{at}.binds"))?.iter().enumerate() {
                    let bat = format!("{at}.binds[{k}]");
                    let mesh =
                        index(bind.get("mesh").unwrap_or(&Value::Null), usize::MAX, &format!("{bat}.mesh"))?;
                    let target = index(
                        bind.get("index").unwrap_or(&Value::Null),
                        usize::MAX,
                        &format!("{bat}.index"),
                    )?;
                    let w = (number(bind.get("weight"), 100.0, &format!("{bat}.weight"))? / 100.0)
                        .clamp(0.0, 1.0);
                    let users: Vec<usize> = (0..nodes.len())
                        .filter(|&n| mesh_of.get(n).copied().flatten() == Some(mesh))
                        .collect();
                    if users.is_empty() {
                        return Err(format!("{bat}.mesh is {mesh}, which no node of the file instantiates"));
                    }
                    for node in users {
                        check_target(node, target, &bat)?;
                        binds.push((node, target, w as f32));
                    }
                }
            }
            if out.iter().any(|e| e.name == name) {
                continue;
            }
            out.push(Expression { name, binds });
        }
    }
    Ok(out)
}

/// A VRM 0.x humanoid bone name as VRM 1.0 names that bone: 0.x counts the thumb's segments from
/// the proximal one (`thumbProximal`, `thumbIntermediate`, `thumbDistal`), 1.0 from the metacarpal
/// (`thumbMetacarpal`, `thumbProximal`, `thumbDistal`), as the VRM 1.0 migration maps them. Every
/// other name is the same in both.
pub(crate) fn thumb_1(name: &str) -> &str {
    match name {
        "leftThumbProximal" => "leftThumbMetacarpal",
        "leftThumbIntermediate" => "leftThumbProximal",
        "rightThumbProximal" => "rightThumbMetacarpal",
        "rightThumbIntermediate" => "rightThumbProximal",
        other => other,
    }
}

/// The humanoid bone map of a VRM file: `(bone name, node)` pairs (empty for other files), VRM 0.x
/// thumb names mapped to VRM 1.0's ([`thumb_1`]).
pub(crate) fn read_humanoid(raw: &Value, n_nodes: usize) -> Result<Vec<(String, usize)>, String> {
    let Some(ext) = raw.get("extensions") else { return Ok(Vec::new()) };
    let mut out = Vec::new();
    if let Some(vrm) = ext.get("VRMC_vrm") {
        let Some(bones) = vrm.get("humanoid").and_then(|h| h.get("humanBones")) else { return Ok(out) };
        for (name, b) in object(bones, "VRMC_vrm.humanoid.humanBones")? {
            let at = format!("VRMC_vrm.humanoid.humanBones.{name}.node");
            out.push((name.clone(), index(b.get("node").unwrap_or(&Value::Null), n_nodes, &at)?));
        }
    } else if let Some(vrm) = ext.get("VRM") {
        let Some(bones) = vrm.get("humanoid").and_then(|h| h.get("humanBones")) else { return Ok(out) };
        for (k, b) in array(bones, "VRM.humanoid.humanBones")?.iter().enumerate() {
            let at = format!("VRM.humanoid.humanBones[{k}]");
            let name =
                b.get("bone").and_then(Value::as_str).ok_or_else(|| format!("{at}.bone must be a string"))?;
            out.push((
                thumb_1(name).to_string(),
                index(b.get("node").unwrap_or(&Value::Null), n_nodes, &format!("{at}.node"))?,
            ));
        }
    }
    Ok(out)
}
