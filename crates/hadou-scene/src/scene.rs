//! [`Scene`]: a loaded, validated scene file with its animation tracks ([`ObjectDef`], [`WaveDef`]
//! and the other parts as read); [`Scene::at`] evaluates it into a [`Frame`]: tracks applied,
//! values clamped, then every object, wave (curves included), shadow and the area light built.
//! [`Scene::load`] and [`Scene::parse`] are in `schema.rs`.

use crate::anim::Track;
use crate::area_light_def::{build_area_light, AreaLightDef};
use crate::bloom_def::build_bloom;
use crate::frame::{
    Camera, ColorMapping, Frame, FrameOverrides, Light, Material, Mesh, Object, Ramp, ToneMode, Wave,
    WaveLight, WaveShape,
};
use crate::materials::{build_material, MaterialDef, ObjectMaterials};
use crate::params::ParamSet;
use crate::rig::{clip_time, clip_wrap, Clip, NodePose, PoseInput, Rig};
use crate::shadow_def::{build_shadow, ShadowDef};
use crate::wave_kind::{CurveKind, WaveKind};
use hadou_math::curve::{CurveFrame, CurveShape, CurveWave, Integrator, Reduction};
use hadou_math::energy::{BeamField, CapsuleField, CylinderField, Falloff, SphereField};
use hadou_math::{Mat4, Vec3, Vec3f};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A scene loaded from a TOML file: typed, range-checked, with animation tracks.
///
/// Loading does all validation; [`Scene::at`] never fails.
#[derive(Clone, Debug)]
pub struct Scene {
    pub(crate) path: PathBuf,
    pub(crate) width: u32,
    /// `[image] samples` (or [`crate::DEFAULT_SAMPLES`]).
    pub(crate) samples: u32,
    pub(crate) height: u32,
    /// Every numeric parameter as written in the file (the store tracks write into).
    pub(crate) values: Vec<f32>,
    pub(crate) camera: ParamSet,
    pub(crate) light: ParamSet,
    pub(crate) color: ParamSet,
    /// Holds `background`.
    pub(crate) globals: ParamSet,
    pub(crate) tone: ToneMode,
    pub(crate) materials: Vec<MaterialDef>,
    pub(crate) objects: Vec<ObjectDef>,
    pub(crate) waves: Vec<WaveDef>,
    pub(crate) shadows: Vec<ShadowDef>,
    pub(crate) area_light: Option<AreaLightDef>,
    /// `[bloom]`'s parameters.
    pub(crate) bloom: Option<ParamSet>,
    /// Where the `[bloom]` table is, for the messages of the limits it brings.
    pub(crate) bloom_at: Option<crate::Location>,
    pub(crate) tracks: Vec<Track>,
    /// Things that were accepted but deserve a note (a downscaled texture, textures on a mesh
    /// without texture coordinates, …).
    pub(crate) warnings: Vec<String>,
}

/// An `[[object]]`: its mesh (built once) and its animatable placement and colour.
#[derive(Clone, Debug)]
pub(crate) struct ObjectDef {
    pub name: String,
    pub mesh: Arc<Mesh>,
    pub params: ParamSet,
    pub materials: ObjectMaterials,
    /// A `kind = "plane"` primitive (a shadow may take its plane).
    pub is_plane: bool,
    /// A `kind = "gltf"` object's `path`, as written (relative to the scene file).
    pub gltf: Option<PathBuf>,
    /// The posable character of its glTF file, kept when the object is animated (`motion`).
    pub rig: Option<Arc<Rig>>,
    /// How it moves: its clip and expressions.
    pub motion: Option<Motion>,
    /// The last pose built and its key (clip time and expression weights), shared by clones.
    pub pose_cache: PoseCache,
    /// Its spring bones move (`spring`, default true; only a VRM with spring bones has any).
    pub spring: bool,
    /// The spring simulation's last state, shared by clones (`spring_scene`).
    pub spring_cache: SpringCache,
    /// What its VRM eyes follow (`look_at`).
    pub look_at: Option<crate::look_at::LookTarget>,
}

/// An object's spring-bone states (the last, and marks on the way to it).
pub(crate) type SpringCache = Arc<std::sync::Mutex<crate::spring::SpringMemo>>;

/// An object's last pose and its key (clip time and expression weights, as bits).
pub(crate) type PoseCache = Arc<std::sync::Mutex<Option<(Vec<u32>, Arc<Mesh>)>>>;

/// An object's animation as its keys give it; the times and speed are its parameters
/// (`animation_start`, `animation_speed`, `animation_time`).
#[derive(Clone, Debug)]
pub(crate) struct Motion {
    /// The clip played, if any: one of the file's, or a VRM Animation retargeted onto it.
    pub clip: Option<Arc<Clip>>,
    /// `animation_loop`.
    pub looping: bool,
    /// The clip time is `animation_time` (written in the file or animated by a track) rather than
    /// derived from the scene time.
    pub pinned: bool,
    /// It gives `expressions` (the parameter `expressions`, one weight per expression of the
    /// file, in the file's order).
    pub expressions: bool,
    /// The clip is a VRM Animation (`animation_file`) retargeted onto the file, not one of its
    /// own clips.
    pub retargeted: bool,
}

/// What poses an object at one time (`Scene::pose_parts`).
struct PoseParts<'a> {
    clip: Option<&'a Clip>,
    clip_t: f32,
    expressions: Vec<(usize, f32)>,
    rotations: Vec<(usize, [f32; 4])>,
}

impl PoseParts<'_> {
    /// The rig's input for this pose.
    fn input(&self) -> PoseInput<'_> {
        PoseInput {
            clip: self.clip,
            time: self.clip_t,
            expressions: &self.expressions,
            rotations: &self.rotations,
            skip_weights: false,
        }
    }
}

impl ObjectDef {
    /// Object → world at these values (`T·R·S`).
    pub(crate) fn transform(&self, vals: &[f32]) -> Mat4 {
        let v3 = |key: &str| Vec3f::from_array(self.params.arr::<3>(vals, key));
        Mat4::from_trs(v3("position"), v3("rotation"), v3("scale"))
    }
}

/// How a curve is integrated (the structural, non-animatable part).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum IntegratorDef {
    Default,
    /// `field = "nearest"`.
    Nearest,
    Simpson {
        m: u32,
        n: Option<u32>,
    },
}

/// A `[[wave]]`.
#[derive(Clone, Debug)]
pub(crate) struct WaveDef {
    pub name: String,
    pub kind: WaveKind,
    pub falloff: Falloff,
    pub params: ParamSet,
    /// Capsule/beam given by `M2` (else by `D` + `length`).
    pub uses_m2: bool,
    pub integrator: IntegratorDef,
    /// B-spline order.
    pub order: u32,
    /// B-spline has an explicit knot vector.
    pub has_knots: bool,
    /// `light_ramp`, if given (else derived from the wave's colour).
    pub light_ramp: Option<Ramp>,
}

impl Scene {
    /// Notes about things the loader accepted but changed or ignored (downscaled textures,
    /// Each object's animation clips (name, length in seconds), in the order of its glTF file;
    /// empty for objects without clips.
    pub fn object_clips(&self) -> Vec<Vec<(String, f32)>> {
        self.objects
            .iter()
            .map(|o| {
                o.rig.as_ref().map_or_else(Vec::new, |r| {
                    r.clips().iter().map(|c| (c.name.clone(), c.duration)).collect()
                })
            })
            .collect()
    }

    /// Each object's VRM expression names (empty for objects of other files).
    pub fn object_expressions(&self) -> Vec<Vec<String>> {
        self.objects
            .iter()
            .map(|o| {
                o.rig
                    .as_ref()
                    .map_or_else(Vec::new, |r| r.expressions().iter().map(|e| e.name.clone()).collect())
            })
            .collect()
    }

    /// The clip object `index` plays and its clip time at scene time `time`, if it plays one.
    pub fn object_clip_at(&self, index: usize, time: f32) -> Option<(String, f32)> {
        let o = self.objects.get(index)?;
        let clip = o.motion.as_ref()?.clip.as_deref()?;
        let vals = self.values_at(time);
        Some((clip.name.clone(), self.clip_time_of(o, &vals, time)?))
    }

    /// What loading found and worked around (textures downscaled to fit, textures on meshes
    /// without texture coordinates, animation keys for bones a character lacks, …), one line each,
    /// every control character of a file's text escaped ([`crate::escape_controls`]); the CLI
    /// prints them.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Anti-aliasing samples per pixel (`[image] samples`, default [`crate::DEFAULT_SAMPLES`]).
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Checks a size for this scene's images (from a flag or the viewer) against the rules its
    /// `[image]` follows: [`crate::check_image_size`].
    pub fn check_image_size(&self, width: u32, height: u32) -> Result<(), String> {
        crate::limits::check_image_size_with(width, height, self.area_light.is_some(), self.bloom_at.as_ref())
    }

    /// Time of the last key of any track in seconds, or the end of the longest clip an object
    /// plays once more (its `animation_start` plus its length over its speed, as the file writes
    /// them) if that is later; 0 for a static scene.
    pub fn duration(&self) -> f32 {
        let tracks = self.tracks.iter().map(Track::end).fold(0.0, f32::max);
        let clips = self
            .objects
            .iter()
            .filter_map(|o| {
                let motion = o.motion.as_ref()?;
                let clip = motion.clip.as_ref()?;
                if motion.pinned {
                    return None;
                }
                let p = &o.params;
                let speed = p.f(&self.values, "animation_speed").abs();
                (speed > 0.0).then(|| p.f(&self.values, "animation_start") + clip.duration / speed)
            })
            .fold(0.0, f32::max);
        tracks.max(clips).min(crate::limits::COORD_MAX)
    }

    /// Each wave's most work on one ray, in integrand evaluations (scene order):
    /// [`crate::ANALYTIC_RAY_WORK`] for the closed-form shapes, the integrator's bound for a curve
    /// ([`hadou_math::curve::Integrator::ray_work_bound`]).
    pub fn ray_work(&self) -> Vec<u64> {
        use hadou_math::curve::{Integrator, Reduction};
        self.waves
            .iter()
            .map(|w| match w.kind {
                WaveKind::Sphere | WaveKind::Cylinder | WaveKind::Capsule | WaveKind::Beam => {
                    crate::ANALYTIC_RAY_WORK
                }
                WaveKind::Curve(_) => match w.integrator {
                    IntegratorDef::Default => Integrator::Default.ray_work_bound(),
                    IntegratorDef::Nearest => Integrator::Nearest.ray_work_bound(),
                    IntegratorDef::Simpson { m, n } => {
                        let reduction = n.map(|n| Reduction { n, epsilon: 0.0 });
                        Integrator::Simpson { m, reduction }.ray_work_bound()
                    }
                },
            })
            .collect()
    }

    /// Checks the most work one pixel may cost at `samples` per pixel (1, 4, 9 or 16): every
    /// wave's [`Scene::ray_work`] times `samples`, summed, at most [`crate::PIXEL_WORK_MAX`]. `Err`
    /// holds the first wave (scene order) whose sum passes it, and the message.
    pub fn check_pixel_work(&self, samples: u32) -> Result<(), (usize, String)> {
        let mut sum = 0u64;
        for (i, work) in self.ray_work().into_iter().enumerate() {
            sum += work * u64::from(samples);
            if sum > crate::PIXEL_WORK_MAX {
                return Err((
                    i,
                    format!(
                        "the waves up to [[wave]] \"{}\" may cost {sum} integrand evaluations a pixel at \
                         {samples} sample(s) (each wave's most per ray, times the samples), over the {} a pixel \
                         may cost; fewer samples, fewer waves or cheaper integrators (the default field: at \
                         most {} per ray, `field = \"nearest\"` {}) fit",
                        crate::error::escape_controls(&self.waves[i].name),
                        crate::PIXEL_WORK_MAX,
                        hadou_math::curve::DEFAULT_RAY_WORK,
                        hadou_math::curve::NEAREST_RAY_WORK
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Where the scene's `[bloom]` table is, if it has one (for messages about the limits it
    /// brings).
    pub fn bloom_location(&self) -> Option<&crate::Location> {
        self.bloom_at.as_ref()
    }

    /// The scene file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Wave names in file order.
    pub fn wave_names(&self) -> Vec<&str> {
        self.waves.iter().map(|w| w.name.as_str()).collect()
    }

    /// Object names in file order.
    pub fn object_names(&self) -> Vec<&str> {
        self.objects.iter().map(|o| o.name.as_str()).collect()
    }

    /// Per object in file order, the glTF file a `kind = "gltf"` object was read from, as its
    /// `path` key gives it (relative to the scene file's directory, checked to lie inside it);
    /// `None` for primitives. An engine with its own glTF loader (hadou-bevy) loads the file
    /// itself to skin and animate it; the frame's mesh is the file at rest.
    pub fn object_files(&self) -> Vec<Option<&Path>> {
        self.objects.iter().map(|o| o.gltf.as_deref()).collect()
    }

    /// The animated targets (`wave.beam.M2.z`, …) in file order.
    pub fn track_targets(&self) -> Vec<&str> {
        self.tracks.iter().map(|t| t.target.as_str()).collect()
    }

    /// The frame at `time` ([`Scene::at`]) with a front end's overrides applied.
    pub fn at_with(&self, time: f32, overrides: &FrameOverrides) -> Frame {
        let mut frame = self.at(time);
        overrides.apply(&mut frame);
        frame
    }

    /// The scene at `time` seconds. Never fails: animated values are clamped into their valid
    /// ranges (smooth interpolation may overshoot) and degenerate directions fall back to the
    /// values written in the file, so every frame is renderable. A non-finite `time` reads as 0.
    pub fn at(&self, time: f32) -> Frame {
        let time = if time.is_finite() { time } else { 0.0 };
        let vals = self.values_at(time);
        self.build(&vals, time)
    }

    /// The value store at `time`: tracks applied, then every parameter clamped into range.
    pub(crate) fn values_at(&self, time: f32) -> Vec<f32> {
        let mut vals = self.values.clone();
        if self.tracks.is_empty() {
            return vals;
        }
        for t in &self.tracks {
            if let Some(out) = vals.get_mut(t.offset..t.offset + t.len) {
                t.eval(time, out);
            }
        }
        let sets = [&self.camera, &self.light, &self.color, &self.globals]
            .into_iter()
            .chain(self.objects.iter().map(|o| &o.params))
            .chain(self.materials.iter().map(|m| &m.params))
            .chain(self.waves.iter().map(|w| &w.params))
            .chain(self.shadows.iter().map(|s| &s.params))
            .chain(self.area_light.iter().map(|a| &a.params))
            .chain(self.bloom.iter());
        for set in sets {
            self.clamp_params(set, &mut vals);
        }
        vals
    }

    /// Clamps the values of `set` in `vals` into their ranges, non-finite ones falling back to the
    /// file's values.
    pub(crate) fn clamp_params(&self, set: &ParamSet, vals: &mut [f32]) {
        for p in &set.params {
            let r = p.offset..p.offset + p.len;
            if let (Some(v), Some(base)) = (vals.get_mut(r.clone()), self.values.get(r)) {
                p.rule.clamp(v, base);
            }
        }
    }

    /// Builds the frame from a (valid) value store.
    pub(crate) fn build(&self, vals: &[f32], time: f32) -> Frame {
        let base = &self.values;
        let v3 = |set: &ParamSet, vals: &[f32], key: &str| Vec3f::from_array(set.arr::<3>(vals, key));
        // Direction `key`, unit; falls back to the file's value, then to `fallback`.
        let dir = |set: &ParamSet, key: &str, fallback: Vec3f| {
            v3(set, vals, key).try_normalize().unwrap_or_else(|| v3(set, base, key).normalize_or(fallback))
        };

        let c = &self.camera;
        let near = c.f(vals, "near");
        let far = c.f(vals, "far").max(near * 1.001 + 1e-6);
        let camera = Camera {
            position: v3(c, vals, "position"),
            target: v3(c, vals, "target"),
            up: v3(c, vals, "up"),
            fov_y_deg: c.f(vals, "fov"),
            near,
            far,
        };
        let l = &self.light;
        let light = Light {
            direction: dir(l, "direction", Vec3::new(0.0, -1.0, 0.0)),
            color: l.arr(vals, "color"),
            ambient: l.arr(vals, "ambient"),
        };
        let color_mapping = ColorMapping { mode: self.tone, exposure: self.color.f(vals, "exposure") };
        let objects = self.build_objects(vals, time);
        let waves = self.waves.iter().map(|w| self.build_wave(w, vals)).collect();
        let shadows =
            self.shadows.iter().map(|s| build_shadow(s, vals, base, light.direction, &objects)).collect();
        Frame {
            width: self.width,
            height: self.height,
            time,
            camera,
            background: self.globals.arr(vals, "background"),
            light,
            waves,
            color_mapping,
            shadows,
            area_light: self.area_light.as_ref().map(|a| build_area_light(a, vals, base, &objects)),
            objects,
            bloom: self.bloom.as_ref().map(|b| build_bloom(b, vals)),
            samples: self.samples,
        }
    }

    /// The frame's objects at these values.
    pub(crate) fn build_objects(&self, vals: &[f32], time: f32) -> Vec<Object> {
        self.objects
            .iter()
            .map(|o| Object {
                name: o.name.clone(),
                mesh: self.posed_mesh(o, vals, time),
                transform: o.transform(vals),
                materials: self.object_materials(o, vals),
            })
            .collect()
    }

    /// The clip time of object `o` at scene time `time` (`None` without a clip).
    pub(crate) fn clip_time_of(&self, o: &ObjectDef, vals: &[f32], time: f32) -> Option<f32> {
        let (motion, rig) = (o.motion.as_ref()?, o.rig.as_ref()?);
        let _ = rig;
        let clip = motion.clip.as_deref()?;
        let p = &o.params;
        let pinned = motion.pinned
            || p.find("animation_time").is_some_and(|a| self.tracks.iter().any(|t| t.offset == a.offset));
        Some(if pinned {
            clip_wrap(p.f(vals, "animation_time"), clip.duration, motion.looping)
        } else {
            clip_time(
                time,
                p.f(vals, "animation_start"),
                p.f(vals, "animation_speed"),
                clip.duration,
                motion.looping,
            )
        })
    }

    /// What poses object `o` at scene time `time`: its clip, the clip time, its expressions
    /// (`expressions`, the gaze's) and its nodes' replaced rotations (spring bones, gaze); `None`
    /// when nothing moves it (its rest pose).
    fn pose_parts<'a>(&self, o: &'a ObjectDef, vals: &[f32], time: f32) -> Option<PoseParts<'a>> {
        let rig = o.rig.as_ref()?;
        let springs = o.spring && rig.springs.is_some();
        if o.motion.is_none() && !springs && o.look_at.is_none() {
            return None;
        }
        let clip_t = self.clip_time_of(o, vals, time).unwrap_or(0.0);
        let mut expressions: Vec<(usize, f32)> = if o.motion.as_ref().is_some_and(|m| m.expressions) {
            o.params.raw(vals, "expressions").iter().copied().enumerate().filter(|e| e.1 != 0.0).collect()
        } else {
            Vec::new()
        };
        let mut rotations = if springs { self.spring_rotations(o, rig, time) } else { Vec::new() };
        self.add_gaze(o, rig, vals, clip_t, &mut rotations, &mut expressions);
        let clip = o.motion.as_ref().and_then(|m| m.clip.as_deref());
        Some(PoseParts { clip, clip_t, expressions, rotations })
    }

    /// Whether hadou poses object `index` with more than a clip of its own glTF file: a VRM
    /// Animation (`animation_file`), `expressions`, spring bones or a gaze (`look_at`). Such an
    /// object's pose is [`Scene::object_node_pose_at`]; a file clip alone is
    /// [`Scene::object_clip_at`].
    pub fn object_posed_by_hadou(&self, index: usize) -> bool {
        let Some(o) = self.objects.get(index) else { return false };
        let Some(rig) = o.rig.as_ref() else { return false };
        let retargeted = o.motion.as_ref().is_some_and(|m| m.retargeted);
        let expressions = o.motion.as_ref().is_some_and(|m| m.expressions);
        retargeted || expressions || (o.spring && rig.springs.is_some()) || o.look_at.is_some()
    }

    /// The pose of object `index`'s glTF nodes at scene time `time`, from the same clip, clip
    /// time, expressions and spring-bone and gaze rotations as the mesh [`Scene::at`] draws
    /// ([`crate::Rig::node_locals`]); `None` for an object without a glTF character or one that
    /// nothing moves.
    pub fn object_node_pose_at(&self, index: usize, time: f32) -> Option<NodePose> {
        let o = self.objects.get(index)?;
        let vals = self.values_at(time);
        let parts = self.pose_parts(o, &vals, time)?;
        Some(o.rig.as_ref()?.node_locals(&parts.input()))
    }

    /// Object `o`'s mesh at scene time `time`: its rest mesh, or the pose its clip and expressions
    /// give (cached for the last pose asked for).
    fn posed_mesh(&self, o: &ObjectDef, vals: &[f32], time: f32) -> Arc<Mesh> {
        let (Some(rig), Some(parts)) = (&o.rig, self.pose_parts(o, vals, time)) else {
            return o.mesh.clone();
        };
        let key: Vec<u32> = std::iter::once(parts.clip_t.to_bits())
            .chain(parts.expressions.iter().map(|e| e.1.to_bits()))
            .chain(parts.rotations.iter().flat_map(|(_, r)| r.map(f32::to_bits)))
            .collect();
        if let Ok(cache) = o.pose_cache.lock() {
            if let Some((k, m)) = cache.as_ref() {
                if *k == key {
                    return m.clone();
                }
            }
        }
        let mesh = Arc::new(rig.pose(&o.mesh, &parts.input()));
        if let Ok(mut cache) = o.pose_cache.lock() {
            *cache = Some((key, mesh.clone()));
        }
        mesh
    }

    pub(crate) fn build_wave(&self, w: &WaveDef, vals: &[f32]) -> Wave {
        let p = &w.params;
        let base = &self.values;
        let v3 = |vals: &[f32], key: &str| Vec3f::from_array(p.arr::<3>(vals, key));
        let unit =
            |key: &str| v3(vals, key).try_normalize().unwrap_or_else(|| v3(base, key).normalize_or(Vec3f::X));
        let capsule = || {
            let m = v3(vals, "M");
            let (d, length) = if w.uses_m2 {
                let span = v3(vals, "M2") - m;
                let fallback = (v3(base, "M2") - v3(base, "M")).normalize_or(Vec3f::X);
                (span.normalize_or(fallback), span.length())
            } else {
                (unit("D"), p.f(vals, "length"))
            };
            CapsuleField { m, d, length, alpha_s: p.f(vals, "alpha_s"), alpha_c: p.f(vals, "alpha_c") }
        };
        let shape = match w.kind {
            WaveKind::Sphere => {
                WaveShape::Sphere(SphereField { center: v3(vals, "M"), alpha: p.f(vals, "alpha_s") })
            }
            WaveKind::Cylinder => WaveShape::Cylinder(CylinderField {
                point: v3(vals, "M"),
                dir: unit("D"),
                alpha: p.f(vals, "alpha_c"),
            }),
            WaveKind::Capsule => WaveShape::Capsule(capsule()),
            WaveKind::Beam => WaveShape::Beam(BeamField {
                capsule: capsule(),
                head_alpha: p.f(vals, "head_alpha"),
                muzzle_alpha: p.f(vals, "muzzle_alpha"),
            }),
            WaveKind::Curve(kind) => WaveShape::Curve(self.build_curve(w, kind, vals)),
        };
        Wave {
            name: w.name.clone(),
            color: p.arr(vals, "rgba"),
            falloff: w.falloff,
            core_radius: p.f(vals, "core_radius"),
            attenuation: p.f(vals, "j"),
            shape,
            light: self.wave_light(w, vals),
        }
    }

    /// The materials of object `o` at these values.
    fn object_materials(&self, o: &ObjectDef, vals: &[f32]) -> Vec<Material> {
        o.materials
            .slots
            .iter()
            .map(|s| build_material(s, &o.mesh, &self.materials, &o.materials, &o.params, vals))
            .collect()
    }

    /// The light of wave `w` at these values.
    fn wave_light(&self, w: &WaveDef, vals: &[f32]) -> WaveLight {
        let c = w.params.arr::<4>(vals, "rgba");
        let ramp = w.light_ramp.clone().unwrap_or_else(|| Ramp::for_wave_color([c[0], c[1], c[2]]));
        WaveLight { ramp, glow: w.params.f(vals, "light_glow") }
    }

    pub(crate) fn build_curve(&self, w: &WaveDef, kind: CurveKind, vals: &[f32]) -> CurveWave {
        let p = &w.params;
        let base = &self.values;
        let v3 = |vals: &[f32], key: &str| Vec3f::from_array(p.arr::<3>(vals, key));
        let axis = v3(vals, "D").try_normalize().unwrap_or_else(|| v3(base, "D").normalize_or(Vec3f::X));
        let mut up = v3(vals, "up");
        if !up_is_usable(up, axis) {
            up = v3(base, "up");
            if !up_is_usable(up, axis) {
                up = axis.orthonormal_basis().0;
            }
        }
        let shape = match kind {
            CurveKind::Helix => CurveShape::Helix {
                radius: p.f(vals, "radius"),
                rate: p.f(vals, "rate"),
                phase: p.f(vals, "phase"),
                length: p.f(vals, "length"),
            },
            CurveKind::Trig => CurveShape::TrigSum {
                rate: p.f(vals, "rate"),
                y_terms: p.pairs(vals, "y_terms"),
                z_terms: p.pairs(vals, "z_terms"),
                length: p.f(vals, "length"),
            },
            CurveKind::Bezier => CurveShape::Bezier { points: p.pairs(vals, "points") },
            CurveKind::BSpline => {
                let knots = w.has_knots.then(|| {
                    let k = p.raw(vals, "knots").to_vec();
                    let np = p.raw(vals, "points").len() / 2;
                    let lo = w.order as usize - 1;
                    // An animated knot vector whose valid range collapsed falls back to the file's.
                    if k.get(lo) < k.get(np) {
                        k
                    } else {
                        p.raw(base, "knots").to_vec()
                    }
                });
                CurveShape::BSpline { points: p.pairs(vals, "points"), order: w.order, knots }
            }
        };
        let integrator = match w.integrator {
            IntegratorDef::Default => Integrator::Default,
            IntegratorDef::Nearest => Integrator::Nearest,
            IntegratorDef::Simpson { m, n } => Integrator::Simpson {
                m,
                reduction: n.map(|n| Reduction { n, epsilon: p.f(vals, "epsilon") }),
            },
        };
        CurveWave {
            frame: CurveFrame { origin: v3(vals, "O"), axis, up },
            shape,
            gamma: p.f(vals, "gamma"),
            extension: p.f(vals, "k"),
            attenuation: p.f(vals, "j"),
            alpha: p.f(vals, "alpha"),
            integrator,
        }
    }
}

/// Whether `up` fixes a frame around unit `axis`: not zero and not parallel to it.
pub(crate) fn up_is_usable(up: Vec3f, axis: Vec3f) -> bool {
    let l = up.length();
    l > 0.0 && l.is_finite() && up.cross(axis).length() > 1e-4 * l
}
