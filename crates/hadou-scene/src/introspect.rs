//! What a scene's parameters are, for tools that edit them (the viewer's panel, gizmos and
//! timeline): every animatable number with its place in the scene file, shape, valid range,
//! value as written and whether a track drives it. Read-only; edits go through the scene file
//! text and [`Scene::parse`], so a tool can never build a scene that `hadou render` would reject.

use crate::anim::Interpolation;
use crate::params::{Constraint, Param, ParamSet, Shape};
use crate::scene::Scene;
use crate::wave_kind::WaveKind;

/// The table of the scene file a parameter is written in.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Entity {
    /// The top level (`background`).
    Top,
    /// `[camera]`.
    Camera,
    /// `[light]`.
    Light,
    /// `[color]`.
    Color,
    /// `[area_light]`.
    AreaLight,
    /// `[bloom]`.
    Bloom,
    /// `[image]` (no animatable keys; its size is structural).
    Image,
    /// The `[[wave]]` with this name.
    Wave(String),
    /// The `[[object]]` with this name.
    Object(String),
    /// The `[[material]]` with this name.
    Material(String),
    /// The `[[shadow]]` with this name.
    Shadow(String),
}

impl Entity {
    /// The TOML table name (`"camera"`, `"wave"`, …; `""` for the top level).
    pub fn table(&self) -> &'static str {
        match self {
            Entity::Top => "",
            Entity::Camera => "camera",
            Entity::Light => "light",
            Entity::Color => "color",
            Entity::AreaLight => "area_light",
            Entity::Bloom => "bloom",
            Entity::Image => "image",
            Entity::Wave(_) => "wave",
            Entity::Object(_) => "object",
            Entity::Material(_) => "material",
            Entity::Shadow(_) => "shadow",
        }
    }

    /// The name of an array-of-tables entry (`[[wave]]` …), `None` for single tables.
    pub fn name(&self) -> Option<&str> {
        match self {
            Entity::Wave(n) | Entity::Object(n) | Entity::Material(n) | Entity::Shadow(n) => Some(n),
            _ => None,
        }
    }

    /// The track-target prefix: `"wave.beam."`, `"camera."`, `""` for the top level.
    pub fn target_prefix(&self) -> String {
        match self.name() {
            Some(n) => format!("{}.{n}.", self.table()),
            None if *self == Entity::Top => String::new(),
            None => format!("{}.", self.table()),
        }
    }

    /// How the table is headed in the file: `[camera]`, `[[wave]] "beam"`, `top level`.
    pub fn describe(&self) -> String {
        match self.name() {
            Some(n) => format!("[[{}]] \"{n}\"", self.table()),
            None if *self == Entity::Top => "top level".into(),
            None => format!("[{}]", self.table()),
        }
    }
}

/// How a parameter is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamShape {
    /// One number.
    Scalar,
    /// `[x, y, …]` with exactly this many numbers.
    Vector(usize),
    /// A list of vectors of this width (`points`, `y_terms`, …); the count is fixed by the file.
    List(usize),
}

/// The range rule a parameter obeys (`docs/scene-format.md`), as checked at load.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamRange {
    /// Any number within ±`COORD_MAX`.
    Any,
    /// `v ≥ 0`.
    NonNeg,
    /// `v > 0`.
    Positive,
    /// Inside `[lo, hi]`; open ends exclude the bound.
    Range {
        /// Lower bound.
        lo: f32,
        /// Upper bound.
        hi: f32,
        /// `lo` itself is excluded.
        lo_open: bool,
        /// `hi` itself is excluded.
        hi_open: bool,
    },
    /// A direction: not the zero vector.
    NonZero,
    /// A colour `[r, g, b, a]` with `r, g, b ≥ 0` and `a ∈ [0, 1]`.
    Rgba,
    /// A non-decreasing list (a knot vector).
    NonDecreasing,
}

impl ParamRange {
    fn of(c: Constraint) -> Self {
        match c {
            Constraint::Any => ParamRange::Any,
            Constraint::NonNeg => ParamRange::NonNeg,
            Constraint::Positive => ParamRange::Positive,
            Constraint::Range { lo, hi, lo_open, hi_open } => ParamRange::Range { lo, hi, lo_open, hi_open },
            Constraint::NonZero => ParamRange::NonZero,
            Constraint::Rgba => ParamRange::Rgba,
            Constraint::NonDecreasing => ParamRange::NonDecreasing,
        }
    }

    fn constraint(self) -> Constraint {
        match self {
            ParamRange::Any => Constraint::Any,
            ParamRange::NonNeg => Constraint::NonNeg,
            ParamRange::Positive => Constraint::Positive,
            ParamRange::Range { lo, hi, lo_open, hi_open } => Constraint::Range { lo, hi, lo_open, hi_open },
            ParamRange::NonZero => Constraint::NonZero,
            ParamRange::Rgba => Constraint::Rgba,
            ParamRange::NonDecreasing => Constraint::NonDecreasing,
        }
    }

    /// Whether `vals` (a whole parameter) obeys the rule; `Err` has the loader's message.
    pub fn check(self, vals: &[f32]) -> Result<(), String> {
        self.constraint().check(vals, 0, true).map_err(|(_, m)| m)
    }

    /// Moves `vals` (a whole parameter) into the rule, as the scene does for animated values.
    pub fn clamp(self, vals: &mut [f32]) {
        let fallback = vals.iter().map(|v| if v.is_finite() { *v } else { 0.0 }).collect::<Vec<_>>();
        self.constraint().clamp(vals, &fallback);
    }

    /// The bounds of component `i`'s values (`None` where unbounded): what a slider may span.
    pub fn bounds(self, i: usize) -> (Option<f32>, Option<f32>) {
        match self {
            ParamRange::NonNeg | ParamRange::Positive => (Some(0.0), None),
            ParamRange::Range { lo, hi, .. } => (Some(lo), Some(hi)),
            ParamRange::Rgba if i == 3 => (Some(0.0), Some(1.0)),
            ParamRange::Rgba => (Some(0.0), None),
            ParamRange::Any | ParamRange::NonZero | ParamRange::NonDecreasing => (None, None),
        }
    }
}

/// One animatable parameter of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamInfo {
    /// The table it is written in.
    pub entity: Entity,
    /// Its key in that table (`"M2"`, `"fov"`, …).
    pub key: &'static str,
    /// Its whole-parameter track target (`"wave.beam.M2"`, `"camera.fov"`, `"background"`).
    pub target: String,
    /// How it is written.
    pub shape: ParamShape,
    /// Its range rule.
    pub range: ParamRange,
    /// The value as written in the file (or its default when the file leaves it out).
    pub value: Vec<f32>,
    /// A plain number may stand for every component (`scale = 2`).
    pub broadcast: bool,
}

/// What a `kind = "gltf"` object's `look_at` key names, for tools that edit it.
#[derive(Clone, Debug, PartialEq)]
pub enum LookAtTarget {
    /// `"camera"`: the camera's position.
    Camera,
    /// A wave's name: its head.
    Wave(String),
    /// A point `[x, y, z]` (the animatable parameter `object.NAME.look_at`).
    Point,
}

/// The spring-bone and look-at keys of a `kind = "gltf"` object whose VRM file has spring bones
/// or look-at (`spring`, `look_at`; `docs/scene-format.md`), for tools that edit them.
#[derive(Clone, Debug, PartialEq)]
pub struct CharacterInfo {
    /// The object's name.
    pub object: String,
    /// Its file has spring bones, so `spring` may be given.
    pub has_springs: bool,
    /// Its springs move (`spring`, default true); `false` where the file has none.
    pub spring: bool,
    /// Its file has VRM look-at, so `look_at` may be given.
    pub has_look_at: bool,
    /// What `look_at` names (`None`: no key, the eyes stay at rest).
    pub look_at: Option<LookAtTarget>,
}

/// A track, as the timeline shows it.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackInfo {
    /// Its target as written (`"wave.beam.M2.z"`).
    pub target: String,
    /// Its interpolation.
    pub interpolation: Interpolation,
    /// Key times in seconds, increasing.
    pub times: Vec<f32>,
    /// Floats per key value.
    pub len: usize,
    /// Key values, `len` floats per key.
    pub values: Vec<f32>,
}

impl Scene {
    /// Every animatable parameter, grouped by table in the order of `docs/scene-format.md`
    /// (camera, light, colour, top level, objects, materials, waves, shadows, area light, bloom), each
    /// table's keys in the order the loader declares them.
    pub fn parameters(&self) -> Vec<ParamInfo> {
        let mut out = Vec::new();
        let mut push = |entity: Entity, set: &ParamSet| {
            for p in &set.params {
                out.push(self.info(entity.clone(), p));
            }
        };
        push(Entity::Camera, &self.camera);
        push(Entity::Light, &self.light);
        push(Entity::Color, &self.color);
        push(Entity::Top, &self.globals);
        for o in &self.objects {
            push(Entity::Object(o.name.clone()), &o.params);
        }
        for m in &self.materials {
            push(Entity::Material(m.name.clone()), &m.params);
        }
        for w in &self.waves {
            push(Entity::Wave(w.name.clone()), &w.params);
        }
        for s in &self.shadows {
            push(Entity::Shadow(s.name.clone()), &s.params);
        }
        if let Some(a) = &self.area_light {
            push(Entity::AreaLight, &a.params);
        }
        if let Some(b) = &self.bloom {
            push(Entity::Bloom, b);
        }
        out
    }

    fn info(&self, entity: Entity, p: &Param) -> ParamInfo {
        let shape = match p.shape {
            Shape::Scalar => ParamShape::Scalar,
            Shape::Vector(n) => ParamShape::Vector(n),
            Shape::List(w) => ParamShape::List(w),
        };
        ParamInfo {
            target: format!("{}{}", entity.target_prefix(), p.key),
            entity,
            key: p.key,
            shape,
            range: ParamRange::of(p.rule),
            value: self.values.get(p.offset..p.offset + p.len).map(<[f32]>::to_vec).unwrap_or_default(),
            broadcast: p.broadcast,
        }
    }

    /// The value of the whole parameter `target` (as [`ParamInfo::target`]) at `time`, with
    /// tracks applied and clamped as [`Scene::at`] uses it; `None` for an unknown target.
    pub fn value_at(&self, target: &str, time: f32) -> Option<Vec<f32>> {
        let (offset, len) = self.locate(target)?;
        let time = if time.is_finite() { time } else { 0.0 };
        self.values_at(time).get(offset..offset + len).map(<[f32]>::to_vec)
    }

    /// The tracks in file order.
    pub fn tracks(&self) -> Vec<TrackInfo> {
        self.tracks
            .iter()
            .map(|t| TrackInfo {
                target: t.target.clone(),
                interpolation: t.interpolation,
                times: t.times.clone(),
                len: t.len,
                values: t.values.clone(),
            })
            .collect()
    }

    /// Whether any track writes part of the whole parameter `target`.
    pub fn is_animated(&self, target: &str) -> bool {
        let Some((offset, len)) = self.locate(target) else { return false };
        self.tracks.iter().any(|t| t.offset < offset + len && offset < t.offset + t.len)
    }

    /// The objects whose VRM file has spring bones or look-at, in file order, with what their
    /// `spring` and `look_at` keys say.
    pub fn characters(&self) -> Vec<CharacterInfo> {
        use crate::look_at::LookTarget;
        self.objects
            .iter()
            .filter_map(|o| {
                let rig = o.rig.as_ref()?;
                let has_springs = rig.springs.is_some();
                let has_look_at = rig.look_at.is_some();
                if !(has_springs || has_look_at) {
                    return None;
                }
                let look_at = o.look_at.as_ref().map(|t| match t {
                    LookTarget::Camera => LookAtTarget::Camera,
                    LookTarget::Point => LookAtTarget::Point,
                    LookTarget::WaveName(n, _) => LookAtTarget::Wave(n.clone()),
                    LookTarget::Wave(i) => {
                        LookAtTarget::Wave(self.waves.get(*i).map_or_else(String::new, |w| w.name.clone()))
                    }
                });
                Some(CharacterInfo {
                    object: o.name.clone(),
                    has_springs,
                    spring: has_springs && o.spring,
                    has_look_at,
                    look_at,
                })
            })
            .collect()
    }

    /// The kind of the wave named `name`.
    pub fn wave_kind(&self, name: &str) -> Option<WaveKind> {
        self.waves.iter().find(|w| w.name == name).map(|w| w.kind)
    }

    /// Material names in file order.
    pub fn material_names(&self) -> Vec<&str> {
        self.materials.iter().map(|m| m.name.as_str()).collect()
    }

    /// Shadow names in file order.
    pub fn shadow_names(&self) -> Vec<&str> {
        self.shadows.iter().map(|s| s.name.as_str()).collect()
    }

    /// Where the whole parameter `target` lives in the value store.
    fn locate(&self, target: &str) -> Option<(usize, usize)> {
        let (entity, key) = match target.split_once('.') {
            None => (Entity::Top, target),
            Some((head, rest)) => match head {
                "camera" => (Entity::Camera, rest),
                "light" => (Entity::Light, rest),
                "color" => (Entity::Color, rest),
                "area_light" => (Entity::AreaLight, rest),
                "bloom" => (Entity::Bloom, rest),
                _ => {
                    let (name, key) = rest.split_once('.')?;
                    let name = name.to_string();
                    let e = match head {
                        "wave" => Entity::Wave(name),
                        "object" => Entity::Object(name),
                        "material" => Entity::Material(name),
                        "shadow" => Entity::Shadow(name),
                        _ => return None,
                    };
                    (e, key)
                }
            },
        };
        let set = match &entity {
            Entity::Top => &self.globals,
            Entity::Camera => &self.camera,
            Entity::Light => &self.light,
            Entity::Color => &self.color,
            Entity::AreaLight => &self.area_light.as_ref()?.params,
            Entity::Bloom => self.bloom.as_ref()?,
            Entity::Image => return None,
            Entity::Wave(n) => &self.waves.iter().find(|w| &w.name == n)?.params,
            Entity::Object(n) => &self.objects.iter().find(|o| &o.name == n)?.params,
            Entity::Material(n) => &self.materials.iter().find(|m| &m.name == n)?.params,
            Entity::Shadow(n) => &self.shadows.iter().find(|s| &s.name == n)?.params,
        };
        let p = set.find(key)?;
        Some((p.offset, p.len))
    }
}
