//! Driving a character's spring bones and eyes from the scene: the fixed-rate steps from time 0
//! (module docs of `spring`), each under the object's clip, placement and the waves' wind at the
//! step's time, the per-object cache that lets a sequence of frames continue where the last left
//! off, and the gaze of `look_at` (module docs of `look_at`) at the frame's values.

use crate::frame::WaveShape;
use crate::look_at::LookTarget;
use crate::rig::{PoseInput, Rig};
use crate::scene::{ObjectDef, Scene};
use crate::spring::{
    affine_inverse, SpringState, StepInput, StillPose, SPRING_MAX_STEPS, SPRING_RATE, SPRING_RESTART_STEPS,
};
use hadou_math::energy::Falloff;
use hadou_math::Vec3f;

/// The steps of the simulation done by scene time `time`: `⌊time · SPRING_RATE⌋` (0 before 0).
pub fn spring_steps_at(time: f32) -> u64 {
    if time.is_nan() || time <= 0.0 {
        return 0;
    }
    let n = (time as f64 * SPRING_RATE).floor();
    if n >= u64::MAX as f64 {
        u64::MAX
    } else {
        n as u64
    }
}

/// The step the simulation of step `n` starts from rest at: 0 up to [`SPRING_MAX_STEPS`], then
/// the first multiple of [`SPRING_RESTART_STEPS`] at most [`SPRING_MAX_STEPS`] before `n`.
pub fn spring_start(n: u64) -> u64 {
    match n.checked_sub(SPRING_MAX_STEPS) {
        None | Some(0) => 0,
        Some(past) => past.div_ceil(SPRING_RESTART_STEPS).saturating_mul(SPRING_RESTART_STEPS),
    }
}

/// Steps between the states kept along a simulation (one second): a frame earlier than the last
/// one asked for continues from the kept state before it, at most this many steps back.
const SPRING_MARK_STEPS: u64 = 60;

/// Least work (steps × joints) worth spreading over threads: below it one thread is quicker.
const SPRING_PARALLEL_WORK: usize = 4096;

/// One wave's wind at a step: its centre line, strength and falloff.
struct WindSource {
    line: crate::frame::LightLine,
    /// For a segment line `a..b`: `a`, `b − a` and `1/|b − a|²` (`None`: [`LightLine::nearest`](crate::frame::LightLine::nearest)).
    segment: Option<(Vec3f, Vec3f, f32)>,
    /// `wind · α·a` (the strength at least 0).
    push: f32,
    /// The core radius squared (at least `1e-4`, as `hadou_math::toon::dominance`).
    core_2: f32,
    inverse_square: bool,
}

impl WindSource {
    /// The nearest point of the centre line to `p`: [`LightLine::nearest`](crate::frame::LightLine::nearest), with a segment's
    /// division done once a step.
    #[inline]
    fn nearest(&self, p: Vec3f) -> Vec3f {
        match self.segment {
            Some((a, ab, inv)) => a + ab * ((p - a).dot(ab) * inv).clamp(0.0, 1.0),
            None => self.line.nearest(p),
        }
    }
}

impl Scene {
    /// Per object in file order, the spring joints that turn and the colliders of its VRM file
    /// (`(0, 0)` for objects without spring bones or with `spring = false`).
    pub fn object_springs(&self) -> Vec<(usize, usize)> {
        self.objects
            .iter()
            .map(|o| match o.rig.as_ref().and_then(|r| r.springs()).filter(|_| o.spring) {
                Some(s) => (s.joint_count(), s.collider_count()),
                None => (0, 0),
            })
            .collect()
    }

    /// The spring bones' local rotations of object `o` at scene time `time`: the state after
    /// [`spring_steps_at`] steps (empty when it has none or `spring = false`).
    pub(crate) fn spring_rotations(&self, o: &ObjectDef, rig: &Rig, time: f32) -> Vec<(usize, [f32; 4])> {
        let Some(springs) = rig.springs.as_ref().filter(|_| o.spring) else { return Vec::new() };
        let n = spring_steps_at(time);
        let start = spring_start(n);
        // The latest kept state of this start at or before step `n`: the last one asked for, or a
        // mark (so scrubbing back does not step again from the start).
        let kept = o.spring_cache.lock().ok().and_then(|m| {
            m.last
                .iter()
                .chain(&m.marks)
                .filter(|s| s.start == start && s.step <= n)
                .max_by_key(|s| s.step)
                .cloned()
        });
        if let Some(s) = kept.as_ref().filter(|s| s.step == n) {
            return s.rotations(springs);
        }
        // Without a clip the pose the springs hang from is the same at every step.
        let still = if o.motion.as_ref().is_none_or(|m| m.clip.is_none()) { rig.still_pose() } else { None };
        let still = still.as_ref();
        let mut state = match kept {
            Some(s) => s,
            None => {
                let Some(s) = self.with_step_input(o, start, still, |input| rig.spring_rest(start, input))
                else {
                    return Vec::new();
                };
                s
            }
        };
        let mut marks = Vec::new();
        while state.step < n {
            let to = ((state.step / SPRING_MARK_STEPS + 1) * SPRING_MARK_STEPS).min(n);
            self.spring_advance(o, rig, springs, &mut state, to, still);
            if to.is_multiple_of(SPRING_MARK_STEPS) {
                marks.push(state.clone());
            }
        }
        let out = state.rotations(springs);
        if let Ok(mut m) = o.spring_cache.lock() {
            m.marks.retain(|s| s.start == start);
            for mark in marks {
                if !m.marks.iter().any(|s| s.step == mark.step) {
                    m.marks.push(mark);
                }
            }
            m.last = Some(state);
        }
        out
    }

    /// Steps `state` on to step `to`.
    fn spring_advance(
        &self,
        o: &ObjectDef,
        rig: &Rig,
        springs: &crate::spring::SpringBones,
        state: &mut SpringState,
        to: u64,
        still: Option<&StillPose>,
    ) {
        let n = to;
        let dt = (1.0 / SPRING_RATE) as f32;
        // Springs that move apart from each other are stepped on the machine's threads, each
        // thread all the steps of its run of springs (the same operations as one thread does).
        let threads = std::thread::available_parallelism().map_or(1, |t| t.get());
        let work = (n - state.step) as usize * springs.joint_count();
        if threads > 1 && work >= SPRING_PARALLEL_WORK && springs.independent(|i| rig.nodes[i].parent) {
            let runs = springs.runs(threads);
            let from = state.step;
            let mut tails: &mut [(Vec3f, Vec3f)] = &mut state.tails;
            let mut rotations: &mut [[f32; 4]] = &mut state.rotations;
            let mut jobs = Vec::new();
            for (part, joints) in runs {
                let (t, rest_t) = std::mem::take(&mut tails).split_at_mut(joints.len());
                let (r, rest_r) = std::mem::take(&mut rotations).split_at_mut(joints.len());
                (tails, rotations) = (rest_t, rest_r);
                jobs.push((part, t, r));
            }
            std::thread::scope(|scope| {
                for (part, t, r) in jobs {
                    scope.spawn(move || {
                        for k in from + 1..=n {
                            self.with_step_input(o, k, still, |input| {
                                rig.spring_step_part(part.clone(), t, r, input, dt)
                            });
                        }
                    });
                }
            });
            state.step = n;
        }
        while state.step < n {
            let k = state.step + 1;
            self.with_step_input(o, k, still, |input| rig.spring_step(state, input, dt));
        }
    }

    /// Calls `f` with what drives step `k` of object `o`: its clip time and the wind at time
    /// `k / SPRING_RATE`, and `still`, the pose of a character without a clip.
    fn with_step_input<R>(
        &self,
        o: &ObjectDef,
        k: u64,
        still: Option<&StillPose>,
        f: impl FnOnce(&StepInput<'_>) -> R,
    ) -> R {
        let time = (k as f64 / SPRING_RATE) as f32;
        let vals = self.values_at(time);
        let clip = o.motion.as_ref().and_then(|m| m.clip.as_deref());
        let clip_time = self.clip_time_of(o, &vals, time).unwrap_or(0.0);
        let sources: Vec<WindSource> = self
            .waves
            .iter()
            .filter(|w| w.params.f(&vals, "wind") > 0.0)
            .map(|w| {
                let wave = self.build_wave(w, &vals);
                let line = wave.light_line(None);
                let segment = match line {
                    crate::frame::LightLine::Segment(a, b) => {
                        let ab = b - a;
                        let l2 = ab.length_squared();
                        (l2 > 0.0 && l2.is_finite()).then(|| (a, ab, 1.0 / l2))
                    }
                    _ => None,
                };
                WindSource {
                    line,
                    segment,
                    push: w.params.f(&vals, "wind") * wave.light_strength().max(0.0),
                    core_2: wave.core_radius.max(1e-4) * wave.core_radius.max(1e-4),
                    inverse_square: wave.falloff == Falloff::InverseSquare,
                }
            })
            .collect();
        let to_world = o.transform(&vals);
        let placed = to_world != hadou_math::Mat4::IDENTITY;
        let to_rig = if placed && !sources.is_empty() { affine_inverse(&to_world) } else { to_world };
        let windy = !sources.is_empty();
        let wind = move |p: Vec3f| -> Vec3f {
            if sources.is_empty() {
                return Vec3f::ZERO;
            }
            let pw = if placed { to_world.transform_point(p) } else { p };
            let mut f = Vec3f::ZERO;
            for s in &sources {
                let away = pw - s.nearest(pw);
                let d2 = away.length_squared();
                if d2.is_nan() || d2 <= 0.0 {
                    continue;
                }
                // `wind · ρ(d) / d` with `ρ` of `hadou_math::toon::dominance` (`α·a / q` inverse
                // square, `α·a / √q` faithful, `q = d² + r_c²`), in one division and one square
                // root (faithful: `√q · d = √(q·d²)`).
                let q = d2 + s.core_2;
                let k = s.push / if s.inverse_square { q * d2.sqrt() } else { (q * d2).sqrt() };
                if k.is_nan() {
                    continue;
                }
                f += away * k.min(f32::MAX);
            }
            let f = if placed { to_rig.transform_vector(f) } else { f };
            if f.is_finite() {
                f
            } else {
                Vec3f::ZERO
            }
        };
        f(&StepInput { clip, clip_time, wind: &wind, windy, still })
    }
}

impl Scene {
    /// Adds object `o`'s gaze (`look_at`) to the pose: its eye bones' rotations to `rotations`,
    /// its look expressions to `expressions`. The target is found at these values, in world space,
    /// and carried into the character's space; the head is where the clip and the spring bones put
    /// it.
    pub(crate) fn add_gaze(
        &self,
        o: &ObjectDef,
        rig: &Rig,
        vals: &[f32],
        clip_time: f32,
        rotations: &mut Vec<(usize, [f32; 4])>,
        expressions: &mut Vec<(usize, f32)>,
    ) {
        let Some(look) = rig.look_at.as_ref() else { return };
        let Some(world) = self.gaze_target(o, vals) else { return };
        let target = affine_inverse(&o.transform(vals)).transform_point(world);
        if !target.is_finite() {
            return;
        }
        let clip = o.motion.as_ref().and_then(|m| m.clip.as_deref());
        let globals = rig.node_globals(&PoseInput { clip, time: clip_time, rotations, ..Default::default() });
        let rest = |n: usize| match rig.nodes.get(n).map(|n| &n.rest) {
            Some(crate::rig::RestLocal::Trs { r, .. }) => *r,
            _ => [0.0, 0.0, 0.0, 1.0],
        };
        let gaze = look.gaze(&globals, target, rest);
        rotations.extend(gaze.rotations);
        for (name, w) in gaze.expressions {
            if let Some(e) = rig.expressions.iter().position(|x| x.name == name) {
                if w > 0.0 {
                    expressions.push((e, w));
                }
            }
        }
    }

    /// Where object `o`'s eyes look at these values, in world space (module docs of `look_at`):
    /// the camera's position, a wave's head or the object's `look_at` point; `None` without
    /// `look_at`.
    fn gaze_target(&self, o: &ObjectDef, vals: &[f32]) -> Option<Vec3f> {
        Some(match o.look_at.as_ref()? {
            LookTarget::Camera => Vec3f::from_array(self.camera.arr::<3>(vals, "position")),
            LookTarget::Point => Vec3f::from_array(o.params.arr::<3>(vals, "look_at")),
            LookTarget::WaveName(..) => return None,
            LookTarget::Wave(i) => match self.build_wave(self.waves.get(*i)?, vals).shape {
                WaveShape::Sphere(f) => f.center,
                WaveShape::Cylinder(f) => f.point,
                WaveShape::Capsule(f) => f.m2(),
                WaveShape::Beam(f) => f.capsule.m2(),
                WaveShape::Curve(c) => *hadou_math::curve::prepare(&c).light_polyline().last()?,
            },
        })
    }

    /// Where the eyes of the object named `object` look at scene time `time` (world space): the
    /// point its `look_at` names there; `None` for an object without `look_at`.
    pub fn look_at_point(&self, object: &str, time: f32) -> Option<[f32; 3]> {
        let o = self.objects.iter().find(|o| o.name == object)?;
        let time = if time.is_finite() { time } else { 0.0 };
        self.gaze_target(o, &self.values_at(time)).map(Vec3f::to_array)
    }
}

impl Scene {
    /// Takes over `old`'s spring-bone states for the objects whose springs `old` drives with the
    /// same inputs: the same VRM skeleton and springs, clip, placement and timing parameters and
    /// their tracks, and the same waves (unless no wave of either scene ever blows: `wind` 0 and
    /// not animated). A scene parsed again after an edit that does not touch them (the camera, a
    /// light, a material, …) then continues from where `old` was instead of stepping again from
    /// time 0. The states are a function of those inputs alone, so the frames are the same bits
    /// either way.
    pub fn keep_spring_states(&mut self, old: &Scene) {
        let waves_same = (self.windless() && old.windless()) || self.waves_same_as(old);
        let kept: Vec<(usize, crate::scene::SpringCache)> = self
            .objects
            .iter()
            .enumerate()
            .filter_map(|(i, o)| {
                let was = old.objects.iter().find(|x| x.name == o.name)?;
                let same = o.spring
                    && was.spring
                    && waves_same
                    && same_springs(o, was)
                    && same_params(self, &o.params, old, &was.params);
                same.then(|| (i, was.spring_cache.clone()))
            })
            .collect();
        for (i, cache) in kept {
            self.objects[i].spring_cache = cache;
        }
    }

    /// The step the spring-bone state kept for the object named `object` has reached (`None`:
    /// nothing kept, or no such object): what the next frame continues from.
    pub fn spring_state_step(&self, object: &str) -> Option<u64> {
        let o = self.objects.iter().find(|o| o.name == object)?;
        o.spring_cache.lock().ok()?.last.as_ref().map(|s| s.step)
    }

    /// The steps of the states kept on the way to the last one for the object named `object`
    /// (every 60 steps, one second): where an earlier frame continues from.
    pub fn spring_marks(&self, object: &str) -> Vec<u64> {
        let Some(o) = self.objects.iter().find(|o| o.name == object) else { return Vec::new() };
        let mut steps: Vec<u64> =
            o.spring_cache.lock().map(|m| m.marks.iter().map(|s| s.step).collect()).unwrap_or_default();
        steps.sort_unstable();
        steps
    }

    /// Whether no wave ever blows: every `wind` is 0 and no track animates one.
    fn windless(&self) -> bool {
        self.waves.iter().all(|w| match w.params.find("wind") {
            Some(p) => {
                self.values.get(p.offset).is_none_or(|&v| v == 0.0)
                    && !self.tracks.iter().any(|t| t.offset < p.offset + p.len && p.offset < t.offset + t.len)
            }
            None => true,
        })
    }

    /// Whether the waves build the same at every time in both scenes (their definitions, values
    /// and tracks).
    fn waves_same_as(&self, old: &Scene) -> bool {
        self.waves.len() == old.waves.len()
            && self.waves.iter().zip(&old.waves).all(|(a, b)| {
                a.name == b.name
                    && a.kind == b.kind
                    && a.falloff == b.falloff
                    && a.uses_m2 == b.uses_m2
                    && a.integrator == b.integrator
                    && a.order == b.order
                    && a.has_knots == b.has_knots
                    && same_params(self, &a.params, old, &b.params)
            })
    }
}

/// Whether objects `a` and `b` have the same skeleton, springs and clip (what a step reads of
/// the character besides the parameters).
fn same_springs(a: &ObjectDef, b: &ObjectDef) -> bool {
    let rigs = match (&a.rig, &b.rig) {
        (Some(x), Some(y)) => {
            std::sync::Arc::ptr_eq(x, y)
                || (x.base == y.base && x.nodes == y.nodes && x.springs == y.springs && x.springs.is_some())
        }
        _ => false,
    };
    let motions = match (&a.motion, &b.motion) {
        (None, None) => true,
        (Some(x), Some(y)) => {
            x.looping == y.looping
                && x.pinned == y.pinned
                && match (&x.clip, &y.clip) {
                    (None, None) => true,
                    (Some(c), Some(d)) => std::sync::Arc::ptr_eq(c, d) || c == d,
                    _ => false,
                }
        }
        _ => false,
    };
    rigs && motions
}

/// Whether parameter sets `a` (of scene `sa`) and `b` (of `sb`) hold the same keys, values and
/// tracks.
fn same_params(sa: &Scene, a: &crate::params::ParamSet, sb: &Scene, b: &crate::params::ParamSet) -> bool {
    fn tracks(s: &Scene, off: usize, len: usize) -> Vec<(&str, crate::anim::Interpolation, &[f32], &[f32])> {
        s.tracks
            .iter()
            .filter(|t| t.offset < off + len && off < t.offset + t.len)
            .map(|t| (t.target.as_str(), t.interpolation, t.times.as_slice(), t.values.as_slice()))
            .collect()
    }
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<u32>>();
    a.params.len() == b.params.len()
        && a.params.iter().zip(&b.params).all(|(p, q)| {
            p.key == q.key
                && p.len == q.len
                && sa.values.get(p.offset..p.offset + p.len).map(bits)
                    == sb.values.get(q.offset..q.offset + q.len).map(bits)
                && tracks(sa, p.offset, p.len) == tracks(sb, q.offset, q.len)
        })
}
