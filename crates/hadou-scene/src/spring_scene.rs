//! Driving a character's spring bones and eyes from the scene: the fixed-rate steps from time 0
//! (module docs of `spring`), each under the object's clip, placement and the waves' wind at the
//! step's time, the per-object cache that lets a sequence of frames continue where the last left
//! off, and the gaze of `look_at` (module docs of `look_at`) at the frame's values.

use crate::frame::WaveShape;
use crate::look_at::LookTarget;
use crate::rig::{PoseInput, Rig};
use crate::scene::{ObjectDef, Scene};
use crate::spring::{affine_inverse, StepInput, SPRING_MAX_STEPS, SPRING_RATE};
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

/// Least work (steps × joints) worth spreading over threads: below it one thread is quicker.
const SPRING_PARALLEL_WORK: usize = 4096;

/// One wave's wind at a step: its centre line, strength and falloff.
struct WindSource {
    line: crate::LightLine,
    wind: f32,
    core: f32,
    strength: f32,
    inverse_square: bool,
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
        let start = n.saturating_sub(SPRING_MAX_STEPS);
        let cached = o.spring_cache.lock().ok().and_then(|c| c.clone());
        let mut state = match cached {
            Some(s) if s.start == start && s.step <= n => s,
            _ => {
                let Some(s) = self.with_step_input(o, start, |input| rig.spring_rest(start, input)) else {
                    return Vec::new();
                };
                s
            }
        };
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
                            self.with_step_input(o, k, |input| {
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
            self.with_step_input(o, k, |input| rig.spring_step(&mut state, input, dt));
        }
        let out = state.rotations(springs);
        if let Ok(mut c) = o.spring_cache.lock() {
            *c = Some(state);
        }
        out
    }

    /// Calls `f` with what drives step `k` of object `o`: its clip time and the wind at time
    /// `k / SPRING_RATE`.
    fn with_step_input<R>(&self, o: &ObjectDef, k: u64, f: impl FnOnce(&StepInput<'_>) -> R) -> R {
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
                WindSource {
                    line: wave.light_line(None),
                    wind: w.params.f(&vals, "wind"),
                    core: wave.core_radius,
                    strength: wave.light_strength(),
                    inverse_square: wave.falloff == Falloff::InverseSquare,
                }
            })
            .collect();
        let to_world = o.transform(&vals);
        let to_rig = affine_inverse(&to_world);
        let placed = to_world != hadou_math::Mat4::IDENTITY;
        let wind = move |p: Vec3f| -> Vec3f {
            if sources.is_empty() {
                return Vec3f::ZERO;
            }
            let pw = if placed { to_world.transform_point(p) } else { p };
            let mut f = Vec3f::ZERO;
            for s in &sources {
                let away = pw - s.line.nearest(pw);
                let d2 = away.length_squared();
                if d2.is_nan() || d2 <= 0.0 {
                    continue;
                }
                let d = d2.sqrt();
                let rho = hadou_math::toon::dominance(d, s.core, s.strength, s.inverse_square);
                f += away * (s.wind * rho / d);
            }
            let f = if placed { to_rig.transform_vector(f) } else { f };
            if f.is_finite() {
                f
            } else {
                Vec3f::ZERO
            }
        };
        f(&StepInput { clip, clip_time, wind: &wind })
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
