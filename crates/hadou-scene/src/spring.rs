//! VRM spring bones (`VRMC_springBone` 1.0; VRM 0.x `secondaryAnimation` converted to it by
//! `spring_def`): hair, skirts and tails that swing behind a character and that a wave's wind
//! blows. The simulation follows the reference implementation of the VRMC_springBone-1.0
//! specification ("Reference implementation"): per joint, in the order of the spring's chain, with
//! the joint's tail position kept from the last two steps,
//!
//! ```text
//! head      = G(parent) · L₀ · 0                         (L₀: the joint's local transform with its
//!                                                          rest rotation, animated translation/scale)
//! restDir   = normalize(G(parent) · L₀ · tail − head)     (tail: the tail's rest offset in the joint)
//! length    = |G(parent) · L₀ · tail − head|
//! next      = current + (current − previous)·(1 − dragForce)
//!           + restDir · stiffness · Δt
//!           + gravityDir · gravityPower · Δt
//!           + wind(current) · Δt                          (the waves' push, `wind` below)
//! next      = head + normalize(next − head) · length
//! collisions: for each collider of the spring's collider groups, a sphere (centre c, radius r) or
//!   a capsule (the point c of its segment nearest `next`): if |next − c| < r + hitRadius then
//!   next = c + normalize(next − c)·(r + hitRadius), and again next = head + normalize(next − head)·length
//! previous  = current; current = next
//! rotation  = R₀ · fromTo(normalize(tail), normalize((G(parent) · L₀)⁻¹ · next))
//! ```
//!
//! With a `center` node the tail positions are kept in that node's space (so the spring follows it
//! without lag). The last joint of a 1.0 spring is only a tail and does not rotate; a VRM 0.x chain's
//! last bone gets a tail 0.07 units along its parent-to-bone direction, as VRM 0.x does.
//!
//! **Determinism.** The simulation runs at a fixed [`SPRING_RATE`] from scene time 0: the pose at
//! time `t` is the state after `n = ⌊t·SPRING_RATE⌋` steps, each step `k` driven by the animation
//! and waves at time `k/SPRING_RATE`. A frame is thus a pure function of its time, whether it is
//! rendered alone, in a sequence or in chunks; a per-object cache continues from the last state
//! when a later time is asked for, and from the state it kept every 60 steps on the way when an
//! earlier one is ([`SpringMemo`]), which gives the same bits. Springs that do not move each other
//! (`SpringBones::independent`) may be stepped on several threads, each spring by the same
//! operations, so again the same bits. Past [`SPRING_MAX_STEPS`] steps the
//! simulation starts from rest at the first multiple of [`SPRING_RESTART_STEPS`] at most
//! [`SPRING_MAX_STEPS`] steps before `n` (`spring_scene::spring_start`; a damped spring has long
//! forgotten its start by then), so no frame costs more, and the frames between two such starts
//! continue one state.
//!
//! **Wind.** A wave with `wind = w > 0` pushes each joint's tail `p` (world space) away from its
//! centre line: `wind(p) = Σ w · ρ(|p − E|) · (p − E)/|p − E|`, `E` the nearest point of the
//! wave's centre line ([`crate::LightLine::nearest`]: a curve's polyline) and `ρ` the energy density
//! the shading weighs waves by ([`hadou_math::toon::dominance`] with the wave's core radius,
//! strength `α·a` and falloff). The force is carried into the character's space, and gravity
//! plus wind is shortened to at most [`SPRING_FORCE_MAX`].

pub use crate::limits::{
    MAX_SPRING_COLLIDERS, MAX_SPRING_COLLISION_PAIRS, MAX_SPRING_JOINTS, SPRING_FORCE_MAX, SPRING_MAX_STEPS,
    SPRING_RATE, SPRING_RESTART_STEPS,
};
use crate::rig::{Clip, PoseInput, Rig};
pub(crate) use crate::spring_bones::{affine_inverse, ColliderShape, SpringBones};
use hadou_math::keyframes::quat_mul;
use hadou_math::{Mat4, Vec3f};

/// What drives one step: the animation at the step's time and the wind there.
pub(crate) struct StepInput<'a> {
    /// The clip and its time at the step.
    pub clip: Option<&'a Clip>,
    pub clip_time: f32,
    /// The external force on a point of the character's space (rig space), per second.
    pub wind: &'a dyn Fn(Vec3f) -> Vec3f,
    /// Whether any wave blows at this step (else `wind` is zero everywhere and is not called).
    pub windy: bool,
    /// The nodes' pose when it is the same at every step (no clip): worked out once for all the
    /// steps instead of at each ([`Rig::still_pose`]).
    pub still: Option<&'a StillPose>,
}

/// The nodes' local transforms under no clip, and the global matrices of the nodes no joint
/// moves: what every step of a character without a clip starts from.
pub(crate) struct StillPose {
    locals: Vec<Trs>,
    /// Per node, its global matrix (`None` for a node a joint moves).
    globals: Vec<Option<Mat4>>,
    /// Per joint (springs in order), its local matrix at its rest rotation, `T·R₀·S`.
    rest: Vec<Mat4>,
}

/// The state of a character's springs after some steps.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SpringState {
    /// Steps done since the state was made at rest.
    pub step: u64,
    /// The step it was made at rest at.
    pub start: u64,
    /// Per joint (springs in order), the previous and current tail, in the spring's center space.
    pub(crate) tails: Vec<(Vec3f, Vec3f)>,
    /// Per joint, its local rotation now.
    pub(crate) rotations: Vec<[f32; 4]>,
}

/// An object's spring-bone states: the last one asked for, and the states every 60 steps on the
/// way to it (of its start), kept by `spring_scene`.
#[derive(Debug, Default)]
pub(crate) struct SpringMemo {
    pub(crate) last: Option<SpringState>,
    pub(crate) marks: Vec<SpringState>,
}

/// A node's translation, rotation and scale (a matrix node: `None`).
type Trs = Option<([f32; 3], [f32; 4], [f32; 3])>;

impl SpringState {
    /// The joints' local rotations `(node, quaternion)`, for [`PoseInput::rotations`].
    pub(crate) fn rotations(&self, springs: &SpringBones) -> Vec<(usize, [f32; 4])> {
        springs
            .springs
            .iter()
            .flat_map(|s| s.joints.iter().map(|j| j.node))
            .zip(self.rotations.iter().copied())
            .collect()
    }
}

impl Rig {
    /// The state of the springs at rest at step `start`, under the animation `input` gives.
    pub(crate) fn spring_rest(&self, start: u64, input: &StepInput<'_>) -> Option<SpringState> {
        let sb = self.springs.as_ref()?;
        let locals = self.step_locals(input);
        let mut tails = Vec::with_capacity(sb.joint_count());
        let mut rotations = Vec::with_capacity(sb.joint_count());
        for s in &sb.springs {
            let center = s.center.map_or(Mat4::IDENTITY, |c| self.global_of(c, &locals));
            let to_center = affine_inverse(&center);
            for j in &s.joints {
                let g = self.global_of(j.node, &locals);
                let tail = to_center.transform_point(g.transform_point(j.tail));
                let tail = if tail.is_finite() { tail } else { Vec3f::ZERO };
                tails.push((tail, tail));
                rotations.push(j.rest);
            }
        }
        Some(SpringState { step: start, start, tails, rotations })
    }

    /// The pose of the steps of a character without a clip ([`StillPose`]).
    pub(crate) fn still_pose(&self) -> Option<StillPose> {
        let sb = self.springs.as_ref()?;
        let wind = |_: Vec3f| Vec3f::ZERO;
        let input = StepInput { clip: None, clip_time: 0.0, wind: &wind, windy: false, still: None };
        let locals = self.step_locals(&input);
        let globals = (0..self.nodes.len())
            .map(|n| (!sb.moving.get(n).copied().unwrap_or(true)).then(|| self.global_of(n, &locals)))
            .collect();
        let rest = (sb.springs.iter().flat_map(|s| &s.joints))
            .map(|j| match locals.get(j.node).copied().flatten() {
                Some((t, _, sc)) => unit_trs(t, j.rest, sc),
                None => Mat4::IDENTITY,
            })
            .collect();
        Some(StillPose { locals, globals, rest })
    }

    /// The nodes' local transforms for `input`'s clip time (no spring rotations).
    fn step_locals(&self, input: &StepInput<'_>) -> Vec<Trs> {
        if let Some(still) = input.still {
            return still.locals.clone();
        }
        let pose =
            PoseInput { clip: input.clip, time: input.clip_time, skip_weights: true, ..Default::default() };
        self.sample_locals(&pose).0
    }

    /// Node `node`'s global matrix from local transforms `locals` (walking up its ancestors).
    fn global_of(&self, node: usize, locals: &[Trs]) -> Mat4 {
        let mut m = self.local_matrix(node, locals[node]);
        let mut at = node;
        let mut guard = self.nodes.len();
        while let Some(p) = self.nodes[at].parent {
            if guard == 0 {
                break;
            }
            guard -= 1;
            m = self.local_matrix(p, locals[p]) * m;
            at = p;
        }
        self.base * m
    }

    /// One step of `state` (module docs), driven by `input`; `dt` is the step in seconds.
    pub(crate) fn spring_step(&self, state: &mut SpringState, input: &StepInput<'_>, dt: f32) {
        let Some(sb) = self.springs.as_ref() else { return };
        self.spring_step_part(0..sb.springs.len(), &mut state.tails, &mut state.rotations, input, dt);
        state.step += 1;
    }

    /// One step of springs `part` alone, whose joints' tails and rotations are `tails` and
    /// `rotations` (a run of [`SpringState`]'s): what [`Rig::spring_step`] does for them when no
    /// other spring moves what they hang from, centre on or collide with
    /// ([`SpringBones::independent`]).
    pub(crate) fn spring_step_part(
        &self,
        part: std::ops::Range<usize>,
        tails: &mut [(Vec3f, Vec3f)],
        rotations: &mut [[f32; 4]],
        input: &StepInput<'_>,
        dt: f32,
    ) {
        let Some(sb) = self.springs.as_ref() else { return };
        let Some(springs) = sb.springs.get(part.clone()) else { return };
        // The index of the part's first joint among all the springs' joints.
        let first: usize = sb.springs[..part.start].iter().map(|s| s.joints.len()).sum();
        let mut locals = self.step_locals(input);
        // The last step's rotations, so colliders and springs below other springs see them.
        for (j, r) in springs.iter().flat_map(|s| &s.joints).zip(rotations.iter()) {
            if let Some((_, rot, _)) = locals[j.node].as_mut() {
                *rot = *r;
            }
        }
        // Globals of the nodes no joint moves, worked out once this step (once for all steps
        // without a clip).
        let mut memo: Vec<Option<Mat4>> = match input.still {
            Some(_) => Vec::new(),
            None => vec![None; self.nodes.len()],
        };
        let mut global = |node: usize, locals: &[Trs]| -> Mat4 {
            if sb.moving.get(node).copied().unwrap_or(true) {
                return self.global_of(node, locals);
            }
            if let Some(still) = input.still {
                return still
                    .globals
                    .get(node)
                    .copied()
                    .flatten()
                    .unwrap_or_else(|| self.global_of(node, locals));
            }
            // Up to the nearest known ancestor, then down.
            let mut path = Vec::new();
            let mut at = Some(node);
            let mut m = self.base;
            while let Some(n) = at {
                if let Some(g) = memo[n] {
                    m = g;
                    break;
                }
                path.push(n);
                at = self.nodes[n].parent;
                if path.len() > self.nodes.len() {
                    break;
                }
            }
            for &n in path.iter().rev() {
                m = m * self.local_matrix(n, locals[n]);
                memo[n] = Some(m);
            }
            m
        };
        // Each collider this step: a segment `a..b` (a sphere's is a point), its radius, and the
        // sphere around it all: the segment's middle and the radius plus half its length.
        let colliders: Vec<(Vec3f, Vec3f, f32, Vec3f, f32)> = sb
            .colliders
            .iter()
            .map(|c| {
                let g = global(c.node, &locals);
                let (a, b, radius) = match c.shape {
                    ColliderShape::Sphere { offset, radius } => {
                        let p = g.transform_point(offset);
                        (p, p, radius)
                    }
                    ColliderShape::Capsule { offset, tail, radius } => {
                        (g.transform_point(offset), g.transform_point(tail), radius)
                    }
                };
                // A non-finite bound tests every joint, as without it.
                let bound = radius + 0.5 * (b - a).length();
                let bound = if bound.is_finite() { bound } else { f32::INFINITY };
                (a, b, radius, (a + b) * 0.5, bound)
            })
            .collect();
        let mut k = 0;
        for s in springs {
            let center = s.center.map(|c| global(c, &locals));
            let to_center = center.as_ref().map(affine_inverse);
            let mut parent = match s.joints.first().and_then(|j| self.nodes[j.node].parent) {
                Some(p) => global(p, &locals),
                None => self.base,
            };
            for j in &s.joints {
                let idx = k;
                k += 1;
                let (Some((t, _, sc)), Some(axis)) = (locals[j.node], j.axis) else {
                    parent = parent * self.local_matrix(j.node, locals[j.node]);
                    continue;
                };
                let rest_r = &j.rest;
                let rest_local = match input.still.and_then(|p| p.rest.get(first + idx)) {
                    Some(m) => *m,
                    None => unit_trs(t, *rest_r, sc),
                };
                let m0 = affine_mul(&parent, &rest_local);
                let head = Vec3f::new(m0.cols[3][0], m0.cols[3][1], m0.cols[3][2]);
                let span = m0.transform_vector(j.tail);
                let rest_tail = head + span;
                let length = span.length();
                if !(length > 0.0 && length.is_finite()) {
                    parent = m0;
                    continue;
                }
                let rest_dir = span * (1.0 / length);
                let Some(&(prev, cur)) = tails.get(idx) else { return };
                let (prev, cur) = match &center {
                    Some(c) => (c.transform_point(prev), c.transform_point(cur)),
                    None => (prev, cur),
                };
                let mut force = j.gravity_dir * j.gravity_power;
                if input.windy {
                    force += (input.wind)(cur);
                }
                // The length is taken only for a force past the bound (compared squared).
                let f2 = force.length_squared();
                if f2.is_nan() || f2 > SPRING_FORCE_MAX * SPRING_FORCE_MAX {
                    let f = f2.sqrt();
                    force = if f.is_finite() { force * (SPRING_FORCE_MAX / f) } else { Vec3f::ZERO };
                }
                let next = cur + (cur - prev) * (1.0 - j.drag) + rest_dir * (j.stiffness * dt) + force * dt;
                let mut next = head + scaled_to(next - head, length).unwrap_or(rest_dir * length);
                for &c in &s.colliders {
                    let Some(&(a, b, radius, centre, bound)) = colliders.get(c) else { continue };
                    let reach = radius + j.hit_radius;
                    // Outside the collider's bounding sphere grown by the hit radius: no contact,
                    // and no nearest point to find.
                    let far = bound + j.hit_radius;
                    if (next - centre).length_squared() >= far * far {
                        continue;
                    }
                    let at = nearest_on_segment(next, a, b);
                    let d = next - at;
                    // Compared squared: the square root only for a contact.
                    if d.length_squared() < reach * reach {
                        if let Some(out) = scaled_to(d, reach) {
                            next = head + scaled_to(at + out - head, length).unwrap_or(rest_dir * length);
                        }
                    }
                }
                if !next.is_finite() {
                    next = rest_tail;
                }
                let back = match &to_center {
                    Some(c) => {
                        let b = c.transform_point(next);
                        if b.is_finite() {
                            b
                        } else {
                            c.transform_point(rest_tail)
                        }
                    }
                    None => next,
                };
                let Some(slot) = tails.get_mut(idx) else { return };
                *slot = (slot.1, back);
                let turn = turn_to(axis, local_direction(&m0, next - head));
                // Both of unit length, so is their product (to rounding; each step starts again
                // from the rest rotation, so nothing accumulates).
                let r = quat_mul(*rest_r, turn);
                if let Some(slot) = rotations.get_mut(idx) {
                    *slot = r;
                }
                if let Some((_, rot, _)) = locals[j.node].as_mut() {
                    *rot = r;
                }
                parent = if sc[0] == sc[1] && sc[1] == sc[2] {
                    // A uniform scale commutes with the turn: `G·T·R₀·S·turn`, `m0` turned.
                    turned(&m0, turn)
                } else {
                    affine_mul(&parent, &unit_trs(t, r, sc))
                };
            }
        }
    }
}

/// World vector `v` in the space of `m` (its 3×3 block inverted as `Mᵀ` with each row divided by
/// that column's squared length: exact for a rotation times a scale, which a joint's global matrix
/// is unless a parent scales unevenly under a turn; with the three columns of one length, `Mᵀ·v`,
/// the same direction). Only its direction is used.
#[inline]
fn local_direction(m: &Mat4, v: Vec3f) -> Vec3f {
    let c = |k: usize| Vec3f::new(m.cols[k][0], m.cols[k][1], m.cols[k][2]);
    let (c0, c1, c2) = (c(0), c(1), c(2));
    let l = [c0.length_squared(), c1.length_squared(), c2.length_squared()];
    let dots = Vec3f::new(c0.dot(v), c1.dot(v), c2.dot(v));
    let (lo, hi) = (l[0].min(l[1]).min(l[2]), l[0].max(l[1]).max(l[2]));
    // Columns of one length (a uniform scale, to rounding): the common divisor does not change
    // the direction, so `Mᵀ·v` is it.
    if lo > 0.0 && hi - lo <= 1e-6 * lo {
        return dots;
    }
    let row = |d: f32, l2: f32| if l2 > 0.0 { d / l2 } else { 0.0 };
    Vec3f::new(row(dots.x, l[0]), row(dots.y, l[1]), row(dots.z, l[2]))
}

/// `v` scaled to length `len` (one square root and one division), or `None` for a zero or
/// non-finite `v`.
#[inline]
fn scaled_to(v: Vec3f, len: f32) -> Option<Vec3f> {
    let l2 = v.length_squared();
    if l2 > 0.0 && l2.is_finite() {
        Some(v * (len / l2.sqrt()))
    } else {
        None
    }
}

/// `q / |q|` in f32, or the identity for a zero or non-finite `q` (the simulation's own, cheaper than
/// `hadou_math::keyframes::normalize_quat`'s f64).
fn unit_quat(q: [f32; 4]) -> [f32; 4] {
    let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if l > 1e-30 && l.is_finite() {
        let inv = 1.0 / l;
        q.map(|c| c * inv)
    } else {
        [0.0, 0.0, 0.0, 1.0]
    }
}

/// `T·R·S` built directly from a rotation of unit length: what
/// `hadou_math::keyframes::trs_matrix` gives, without its normalisation and two matrix products.
fn unit_trs(t: [f32; 3], r: [f32; 4], s: [f32; 3]) -> Mat4 {
    let [x, y, z, w] = r;
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz, wx, wy, wz) = (x * y, x * z, y * z, w * x, w * y, w * z);
    Mat4 {
        cols: [
            [(1.0 - 2.0 * (yy + zz)) * s[0], 2.0 * (xy + wz) * s[0], 2.0 * (xz - wy) * s[0], 0.0],
            [2.0 * (xy - wz) * s[1], (1.0 - 2.0 * (xx + zz)) * s[1], 2.0 * (yz + wx) * s[1], 0.0],
            [2.0 * (xz + wy) * s[2], 2.0 * (yz - wx) * s[2], (1.0 - 2.0 * (xx + yy)) * s[2], 0.0],
            [t[0], t[1], t[2], 1.0],
        ],
    }
}

/// `m · R(q)` for an affine `m` and a unit quaternion `q` (its 3×3 block times the rotation's,
/// its translation kept): a joint's global matrix after its turn, from the one at its rest
/// rotation, when its scale is uniform.
#[inline]
fn turned(m: &Mat4, q: [f32; 4]) -> Mat4 {
    let r = unit_trs([0.0; 3], q, [1.0; 3]);
    let mut out = *m;
    for c in 0..3 {
        for row in 0..3 {
            out.cols[c][row] =
                m.cols[0][row] * r.cols[c][0] + m.cols[1][row] * r.cols[c][1] + m.cols[2][row] * r.cols[c][2];
        }
    }
    out
}

/// `a·b` for affine matrices (last rows `0 0 0 1`).
fn affine_mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut m = Mat4::IDENTITY;
    for c in 0..4 {
        for r in 0..3 {
            let mut s =
                a.cols[0][r] * b.cols[c][0] + a.cols[1][r] * b.cols[c][1] + a.cols[2][r] * b.cols[c][2];
            if c == 3 {
                s += a.cols[3][r];
            }
            m.cols[c][r] = s;
        }
    }
    m
}

/// The point of segment `a..b` nearest `p`.
fn nearest_on_segment(p: Vec3f, a: Vec3f, b: Vec3f) -> Vec3f {
    let ab = b - a;
    let l2 = ab.length_squared();
    if l2.is_nan() || l2 <= 0.0 {
        return a;
    }
    a + ab * ((p - a).dot(ab) / l2).clamp(0.0, 1.0)
}

/// The shortest rotation (unit quaternion `[x, y, z, w]`) turning unit `a` onto the direction of
/// `b`, which need not be of unit length: the half-way quaternion `[a × b, |b| + a·b]` normalised
/// (for unit `b`, `[a × b, 1 + a·b]`), so `b` is not normalised first; half a turn about an axis
/// normal to `a` when they are opposite, the identity for a zero or non-finite `b`.
#[inline]
pub(crate) fn turn_to(a: Vec3f, b: Vec3f) -> [f32; 4] {
    let lb = b.length();
    if !(lb > 0.0 && lb.is_finite()) {
        return [0.0, 0.0, 0.0, 1.0];
    }
    let d = a.dot(b);
    if d < (-1.0 + 1e-6) * lb {
        let (n, _) = a.orthonormal_basis();
        return [n.x, n.y, n.z, 0.0];
    }
    let c = a.cross(b);
    unit_quat([c.x, c.y, c.z, lb + d])
}
