//! VRM look-at: the eyes of a VRM character turned towards a point (the scene's `look_at` key: a
//! wave's head, the camera or a point). VRM 1.0 `VRMC_vrm.lookAt` (`offsetFromHeadBone`, `type`
//! `bone` or `expression`, the range maps `rangeMapHorizontalInner`, `rangeMapHorizontalOuter`,
//! `rangeMapVerticalDown`, `rangeMapVerticalUp`); VRM 0.x `firstPerson` (`firstPersonBoneOffset`,
//! `lookAtTypeName` `Bone` or `BlendShape`, `lookAtHorizontalInner/Outer`, `lookAtVerticalDown/Up`
//! with `xRange` → `inputMaxValue` and `yRange` → `outputScale`, the curve read as linear, as the
//! VRM 1.0 migration does).
//!
//! As the VRM 1.0 specification describes: the target `p` in the head bone's space, less the offset,
//! `d = G(head)⁻¹·p − offset` (for VRM 0.x, which faces −z, turned half a turn about y), gives
//! `yaw = atan2(d.x, d.z)` and `pitch = atan2(d.y, √(d.x² + d.z²))` in degrees. A range map turns an
//! angle `a` into `min(|a|, inputMaxValue) / inputMaxValue · outputScale`. Bone type: each eye turns
//! by the mapped yaw about y and pitch about x (the left eye takes the outer map when looking to the
//! character's left, +x, the inner one to its right; the right eye the opposite; up takes the up
//! map, down the down map). Expression type: `lookLeft`/`lookRight` take the outer map of the yaw,
//! `lookUp`/`lookDown` the maps of the pitch, as weights.

use crate::spring_bones::affine_inverse;
use hadou_math::{Mat4, Vec3f};
use serde_json::Value;

/// A range map: an angle (degrees) to an eye angle (degrees) or expression weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RangeMap {
    pub input_max: f32,
    pub output_scale: f32,
}

impl RangeMap {
    /// `min(|a|, inputMaxValue) / inputMaxValue · outputScale` (0 for a non-positive input range).
    pub(crate) fn map(&self, a: f32) -> f32 {
        if self.input_max.is_nan() || self.input_max <= 0.0 || !a.is_finite() {
            return 0.0;
        }
        a.abs().min(self.input_max) / self.input_max * self.output_scale
    }
}

/// How the eyes turn.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum LookAtKind {
    /// The `leftEye` and `rightEye` humanoid bones turn (either may be missing).
    Bone { left: Option<usize>, right: Option<usize> },
    /// The `lookLeft`, `lookRight`, `lookUp`, `lookDown` expressions are weighted.
    Expression,
}

/// A VRM's look-at.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct LookAt {
    pub head: usize,
    pub offset: Vec3f,
    pub kind: LookAtKind,
    pub inner: RangeMap,
    pub outer: RangeMap,
    pub down: RangeMap,
    pub up: RangeMap,
    /// VRM 0.x (faces −z in the file).
    pub v0: bool,
}

fn number(v: Option<&Value>, default: f32, at: &str) -> Result<f32, String> {
    match v {
        None => Ok(default),
        Some(x) => match x.as_f64() {
            Some(f) if f.is_finite() && f.abs() <= 1e6 => Ok(f as f32),
            _ => Err(format!("{at} must be a finite number within ±1e6")),
        },
    }
}

/// The look-at of a VRM file (`None` without a head bone, or for type bone without eye bones).
pub(crate) fn read_look_at(raw: &Value, humanoid: &[(String, usize)]) -> Result<Option<LookAt>, String> {
    let bone = |name: &str| humanoid.iter().find(|(n, _)| n == name).map(|b| b.1);
    let Some(head) = bone("head") else { return Ok(None) };
    let (left, right) = (bone("leftEye"), bone("rightEye"));
    let ext = raw.get("extensions");
    let v1 = ext.and_then(|e| e.get("VRMC_vrm"));
    let v0 = ext.and_then(|e| e.get("VRM"));
    let look = match (v1, v0) {
        (Some(v1), _) => {
            let Some(l) = v1.get("lookAt") else {
                return Ok(None);
            };
            let at = "VRMC_vrm.lookAt";
            let expression = match l.get("type").and_then(Value::as_str) {
                None | Some("bone") => false,
                Some("expression") => true,
                Some(other) => {
                    return Err(format!("{at}.type is \"{other}\"; it must be \"bone\" or \"expression\""))
                }
            };
            let scale = if expression { 1.0 } else { 10.0 };
            let map = |key: &str| -> Result<RangeMap, String> {
                let m = l.get(key);
                Ok(RangeMap {
                    input_max: number(
                        m.and_then(|m| m.get("inputMaxValue")),
                        90.0,
                        &format!("{at}.{key}.inputMaxValue"),
                    )?,
                    output_scale: number(
                        m.and_then(|m| m.get("outputScale")),
                        scale,
                        &format!("{at}.{key}.outputScale"),
                    )?,
                })
            };
            let offset = match l.get("offsetFromHeadBone") {
                None => Vec3f::ZERO,
                Some(Value::Array(a)) if a.len() == 3 => {
                    let c = |k: usize| number(a.get(k), 0.0, &format!("{at}.offsetFromHeadBone[{k}]"));
                    Vec3f::new(c(0)?, c(1)?, c(2)?)
                }
                Some(_) => return Err(format!("{at}.offsetFromHeadBone must be three numbers")),
            };
            LookAt {
                head,
                offset,
                kind: if expression { LookAtKind::Expression } else { LookAtKind::Bone { left, right } },
                inner: map("rangeMapHorizontalInner")?,
                outer: map("rangeMapHorizontalOuter")?,
                down: map("rangeMapVerticalDown")?,
                up: map("rangeMapVerticalUp")?,
                v0: false,
            }
        }
        (None, Some(v0)) => {
            let Some(fp) = v0.get("firstPerson") else {
                return Ok(None);
            };
            let at = "VRM.firstPerson";
            let expression = match fp.get("lookAtTypeName").and_then(Value::as_str) {
                None | Some("Bone") => false,
                Some("BlendShape") => true,
                Some(other) => {
                    return Err(format!(
                        "{at}.lookAtTypeName is \"{other}\"; it must be \"Bone\" or \"BlendShape\""
                    ))
                }
            };
            let scale = if expression { 1.0 } else { 10.0 };
            let map = |key: &str| -> Result<RangeMap, String> {
                let m = fp.get(key);
                Ok(RangeMap {
                    input_max: number(m.and_then(|m| m.get("xRange")), 90.0, &format!("{at}.{key}.xRange"))?,
                    output_scale: number(
                        m.and_then(|m| m.get("yRange")),
                        scale,
                        &format!("{at}.{key}.yRange"),
                    )?,
                })
            };
            let o = fp.get("firstPersonBoneOffset");
            let c =
                |k: &str| number(o.and_then(|o| o.get(k)), 0.0, &format!("{at}.firstPersonBoneOffset.{k}"));
            LookAt {
                head,
                // VRM 0.x stores the offset with z opposite to the file's (its Unity space).
                offset: Vec3f::new(c("x")?, c("y")?, -c("z")?),
                kind: if expression { LookAtKind::Expression } else { LookAtKind::Bone { left, right } },
                inner: map("lookAtHorizontalInner")?,
                outer: map("lookAtHorizontalOuter")?,
                down: map("lookAtVerticalDown")?,
                up: map("lookAtVerticalUp")?,
                v0: true,
            }
        }
        (None, None) => return Ok(None),
    };
    if matches!(look.kind, LookAtKind::Bone { left: None, right: None }) {
        return Ok(None);
    }
    Ok(Some(look))
}

/// The rotation (unit quaternion) of `deg` degrees about unit axis `(x, y, z)`.
fn axis_angle(x: f32, y: f32, z: f32, deg: f32) -> [f32; 4] {
    let h = deg.to_radians() * 0.5;
    let s = h.sin();
    [x * s, y * s, z * s, h.cos()]
}

/// What looking at a point gives: eye-bone local rotations replacing theirs, and expression
/// weights by name.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Gaze {
    pub rotations: Vec<(usize, [f32; 4])>,
    pub expressions: Vec<(&'static str, f32)>,
}

impl LookAt {
    /// The yaw and pitch (degrees) of rig-space point `target` seen from the head (`globals`: the
    /// nodes' global matrices of the pose).
    pub(crate) fn angles(&self, globals: &[Mat4], target: Vec3f) -> Option<(f32, f32)> {
        let g = globals.get(self.head)?;
        let mut d = affine_inverse(g).transform_point(target) - self.offset;
        if self.v0 {
            d = Vec3f::new(-d.x, d.y, -d.z);
        }
        if !d.is_finite() || d.length_squared() == 0.0 {
            return None;
        }
        let yaw = d.x.atan2(d.z).to_degrees();
        let pitch = d.y.atan2(d.x.hypot(d.z)).to_degrees();
        Some((yaw, pitch))
    }

    /// The gaze at rig-space point `target`; `rest` gives a node's rest rotation.
    pub(crate) fn gaze(&self, globals: &[Mat4], target: Vec3f, rest: impl Fn(usize) -> [f32; 4]) -> Gaze {
        let Some((yaw, pitch)) = self.angles(globals, target) else { return Gaze::default() };
        let vertical = if pitch > 0.0 { self.up.map(pitch) } else { -self.down.map(pitch) };
        match self.kind {
            LookAtKind::Expression => Gaze {
                rotations: Vec::new(),
                expressions: vec![
                    ("lookLeft", if yaw > 0.0 { self.outer.map(yaw) } else { 0.0 }),
                    ("lookRight", if yaw < 0.0 { self.outer.map(yaw) } else { 0.0 }),
                    ("lookUp", vertical.max(0.0)),
                    ("lookDown", (-vertical).max(0.0)),
                ],
            },
            LookAtKind::Bone { left, right } => {
                let mut rotations = Vec::new();
                for (eye, is_left) in [(left, true), (right, false)] {
                    let Some(eye) = eye else { continue };
                    // Towards +x (the character's left) the left eye turns outwards.
                    let outwards = (yaw > 0.0) == is_left;
                    let h = if outwards { self.outer.map(yaw) } else { self.inner.map(yaw) };
                    let h = h.copysign(yaw);
                    // Up turns +z towards +y: a negative turn about x.
                    let mut q = hadou_math::keyframes::quat_mul(
                        axis_angle(0.0, 1.0, 0.0, h),
                        axis_angle(1.0, 0.0, 0.0, -vertical),
                    );
                    if self.v0 {
                        // Half a turn about y: the file's axes x and z are the other way round.
                        q = [-q[0], q[1], -q[2], q[3]];
                    }
                    let r =
                        hadou_math::keyframes::normalize_quat(hadou_math::keyframes::quat_mul(rest(eye), q));
                    rotations.push((eye, r));
                }
                Gaze { rotations, expressions: Vec::new() }
            }
        }
    }
}

/// What an object's `look_at` key names.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum LookTarget {
    /// The camera's position.
    Camera,
    /// The head of wave `i` (scene order): a sphere's centre, a cylinder's point `M`, a capsule's
    /// or beam's end `M + D·length`, a curve's last point.
    Wave(usize),
    /// A wave name as written, until the waves are read (`schema` resolves it).
    WaveName(String, crate::toml_read::Span),
    /// The object's animatable `look_at` point (world space).
    Point,
}
