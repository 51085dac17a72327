//! `[[shadow]]`: hard shadows cast by chosen objects onto chosen receivers, from the sun
//! (001, SPEC.md §3) or from a wave (000 §2.4, SPEC.md §2.4), found on a receiver plane by
//! projection or on any receiver by an orthographic shadow map. The frame types ([`Shadow`],
//! [`ShadowCast`]) and [`Frame::shadow_casts`], the one place both backends get their projection
//! directions and map frames from.

use crate::error::hint;
use crate::frame::{Frame, LightLine, Object};
use crate::params::{Constraint, ParamSet, Shape};
use crate::toml_read::{type_name, Fallback, ParamReader, Res, Span, Table};
use hadou_math::shadow::{horizon_fade, wave_direction, MapFrame, Plane, DEFAULT_THETA_DEG};
use hadou_math::{Vec3, Vec3f};
use toml::de::DeValue;

/// Most `[[shadow]]` tables in one scene (receivers carry one bit per shadow).
pub const MAX_SHADOWS: usize = 16;
/// Largest shadow-map edge in texels (WebGPU's guaranteed `maxTextureDimension2D`).
pub const MAX_MAP_SIZE: u32 = 8192;
/// Most shadow-map texels of one frame together (every map of every shadow; 256 MiB of `f32`).
pub const MAX_MAP_TEXELS: u64 = 1 << 26;
/// Most maps of one frame (a sun shadow needs one, a wave shadow one per caster).
pub const MAX_MAPS: usize = 64;
/// A visible point counts as on a receiver plane within `ON_PLANE · (1 + eye distance)` of it.
pub const ON_PLANE: f32 = 1e-3;

/// Where a shadow's light comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowLight {
    /// Parallel rays travelling along this unit direction (001: the sun).
    Sun(Vec3f),
    /// Wave `wave` (index into [`Frame::waves`]), each caster's direction clamped to at most `theta`
    /// radians from straight down (000 §2.4).
    Wave {
        /// Index into `Frame::waves`.
        wave: u32,
        /// Longest-shadow angle `θ ∈ [0, π/2)`, radians.
        theta: f32,
    },
}

/// How a shadow finds the surface it falls on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowMethod {
    /// Projection onto a plane (the theses): shows on receiver points within [`ON_PLANE`] of it.
    Plane(Plane),
    /// An orthographic shadow map of `size²` texels per map along each projection direction: any
    /// receiver shape (hadou's answer to the uneven receivers 000 leaves open).
    Map {
        /// Edge in texels, `1..=MAX_MAP_SIZE`.
        size: u32,
    },
}

/// One `[[shadow]]` of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Shadow {
    /// Name from the scene file.
    pub name: String,
    /// The light.
    pub light: ShadowLight,
    /// Plane projection or shadow map.
    pub method: ShadowMethod,
    /// Unit normal of the receivers' lit side: `−up` is "straight down" for θ, and a light must
    /// travel against it (`k·up < 0`) to cast (the plane's normal for [`ShadowMethod::Plane`]).
    pub up: Vec3f,
    /// Casting objects (indices into [`Frame::objects`]).
    pub casters: Vec<u32>,
    /// Receiving objects (indices into [`Frame::objects`]).
    pub receivers: Vec<u32>,
    /// Linear RGB of the shadow.
    pub color: [f32; 3],
    /// Opacity in `[0, 1]`: a shadowed point becomes `(1 − o)·colour + o·shadow colour`.
    pub opacity: f32,
}

/// One projection of a frame: some casters of one shadow moved along one direction. Computed by
/// [`Frame::shadow_casts`]; a sun shadow gives one cast for all its casters, a wave shadow one per
/// caster.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowCast {
    /// Index into [`Frame::shadows`].
    pub shadow: u32,
    /// The casting objects.
    pub casters: Vec<u32>,
    /// Unit projection direction `k` (from the light towards the receiver).
    pub k: Vec3f,
    /// Effective opacity: the shadow's opacity times [`horizon_fade`], `> 0`.
    pub opacity: f32,
    /// For [`ShadowMethod::Map`]: the map's frame around the casters' bounding sphere.
    pub map: Option<MapFrame>,
}

impl Shadow {
    /// Whether object `o` receives this shadow.
    #[inline]
    pub fn receives(&self, o: u32) -> bool {
        self.receivers.contains(&o)
    }
}

/// World-space axis-aligned bounds of an object's mesh: the 8 transformed corners of its local
/// bounds. `None` for an empty mesh.
pub fn object_bounds(o: &Object) -> Option<(Vec3f, Vec3f)> {
    let (lo, hi) = local_bounds(o)?;
    let mut w_lo = Vec3::splat(f32::INFINITY);
    let mut w_hi = Vec3::splat(f32::NEG_INFINITY);
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let w = o.transform.transform_point(c);
        w_lo = w_lo.min(w);
        w_hi = w_hi.max(w);
    }
    Some((w_lo, w_hi))
}

/// The centre `B` of a caster (000 §2.4's "model's centre"): the centre of its mesh's local
/// bounding box, placed in the world. `None` for an empty mesh.
pub fn object_center(o: &Object) -> Option<Vec3f> {
    let (lo, hi) = local_bounds(o)?;
    Some(o.transform.transform_point((lo + hi) * 0.5))
}

/// The object-space bounding box of an object's mesh (`None` when it has no vertices).
fn local_bounds(o: &Object) -> Option<(Vec3f, Vec3f)> {
    let mut it = o.mesh.positions.iter().map(|p| Vec3f::from_array(*p));
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

impl Frame {
    /// Every projection this frame's shadows make, in shadow order, then caster order: each with
    /// its direction `k` (the sun's direction, or [`wave_direction`] from the nearest point of the
    /// wave's light line `lines[wave]` to the caster's centre), its effective opacity, and for a
    /// map its frame. Casts that cannot show (opacity 0, a light at or below the receivers'
    /// horizon, a wave with no strength, casters without triangles) are left out.
    pub fn shadow_casts(&self, lines: &[LightLine]) -> Vec<ShadowCast> {
        let mut out = Vec::new();
        for (si, s) in self.shadows.iter().enumerate() {
            if s.opacity <= 0.0 {
                continue;
            }
            let mut push = |casters: Vec<u32>, k: Vec3f| {
                let opacity = s.opacity * horizon_fade(k, s.up);
                if opacity <= 0.0 || casters.is_empty() {
                    return;
                }
                let map = match s.method {
                    ShadowMethod::Plane(_) => None,
                    ShadowMethod::Map { .. } => {
                        let mut lo = Vec3::splat(f32::INFINITY);
                        let mut hi = Vec3::splat(f32::NEG_INFINITY);
                        for &c in &casters {
                            if let Some((a, b)) = object_bounds(&self.objects[c as usize]) {
                                lo = lo.min(a);
                                hi = hi.max(b);
                            }
                        }
                        if !(lo.is_finite() && hi.is_finite()) {
                            return;
                        }
                        Some(MapFrame::new(k, (lo + hi) * 0.5, (hi - lo).length() * 0.5))
                    }
                };
                out.push(ShadowCast { shadow: si as u32, casters, k, opacity, map });
            };
            match s.light {
                ShadowLight::Sun(l) => {
                    let casters = s
                        .casters
                        .iter()
                        .copied()
                        .filter(|&c| object_center(&self.objects[c as usize]).is_some());
                    push(casters.collect(), l);
                }
                ShadowLight::Wave { wave, theta } => {
                    let (Some(w), Some(line)) = (self.waves.get(wave as usize), lines.get(wave as usize))
                    else {
                        continue;
                    };
                    if w.light_strength() <= 0.0 {
                        continue;
                    }
                    for &c in &s.casters {
                        let Some(b) = object_center(&self.objects[c as usize]) else { continue };
                        let k = wave_direction(b, line.nearest(b), s.up, theta);
                        push(vec![c], k);
                    }
                }
            }
        }
        out
    }
}

// ---------------------------------------------------------------------------------------------
// The scene-file side.

pub(crate) const SHADOW_KEYS: &[&str] = &[
    "name",
    "kind",
    "method",
    "casters",
    "receivers",
    "direction",
    "wave",
    "theta",
    "plane_point",
    "plane_normal",
    "plane_points",
    "up",
    "map_size",
    "color",
    "opacity",
];

/// Which plane a plane-method shadow uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum PlaneSource {
    /// `plane_point` + `plane_normal`.
    PointNormal,
    /// `plane_points = [I, J, K]`.
    ThreePoints,
    /// The receiver, a `kind = "plane"` object (index): its origin and +y.
    Object(usize),
}

/// A `[[shadow]]` as read.
#[derive(Clone, Debug)]
pub(crate) struct ShadowDef {
    pub name: String,
    pub wave: Option<usize>,
    /// The sun shadow gives its own `direction` (else `[light] direction`).
    pub own_direction: bool,
    /// `None`: shadow map.
    pub plane: Option<PlaneSource>,
    pub map_size: u32,
    pub casters: Vec<u32>,
    pub receivers: Vec<u32>,
    pub params: ParamSet,
}

const UNIT: Constraint = Constraint::Range { lo: 0.0, hi: 1.0, lo_open: false, hi_open: false };
const THETA: Constraint = Constraint::Range { lo: 0.0, hi: 90.0, lo_open: false, hi_open: true };
const V3: Shape = Shape::Vector(3);

/// Reads a list of object names (`"a"` or `["a", "b"]`) into object indices.
pub(crate) fn object_list(t: &Table<'_, '_>, key: &str, objects: &[(&str, bool)]) -> Res<Vec<u32>> {
    let v = t.get(key).ok_or_else(|| {
        t.src.missing(&t.span, format!("{} needs `{key}` (an object name or a list of them)", t.what))
    })?;
    let items: Vec<(&str, Span)> = match v.get_ref() {
        DeValue::String(s) => vec![(s.as_ref(), v.span())],
        DeValue::Array(a) => {
            let mut out = Vec::new();
            for item in a.iter() {
                let DeValue::String(s) = item.get_ref() else {
                    return Err(t.src.type_err(
                        &item.span(),
                        format!(
                            "`{key}` in {} must list object names, got {}",
                            t.what,
                            type_name(item.get_ref())
                        ),
                    ));
                };
                out.push((s.as_ref(), item.span()));
            }
            out
        }
        other => {
            return Err(t.src.type_err(
                &v.span(),
                format!(
                    "`{key}` in {} must be an object name or a list of them, got {}",
                    t.what,
                    type_name(other)
                ),
            ))
        }
    };
    if items.is_empty() {
        return Err(t
            .src
            .value_err(&v.span(), format!("`{key}` in {} must name at least one object", t.what)));
    }
    let names: Vec<&str> = objects.iter().map(|o| o.0).collect();
    let mut out: Vec<u32> = Vec::new();
    for (name, span) in items {
        let Some(i) = names.iter().position(|n| *n == name) else {
            return Err(t.src.value_err(
                &span,
                format!(
                    "`{key}` in {}: no [[object]] is named \"{name}\"{}",
                    t.what,
                    hint(name, &names, "names")
                ),
            ));
        };
        if out.contains(&(i as u32)) {
            return Err(t.src.duplicate(&span, format!("`{key}` in {} names \"{name}\" twice", t.what)));
        }
        out.push(i as u32);
    }
    Ok(out)
}

/// Parses one `[[shadow]]`. `objects` are the scene's objects (name, is a `plane` primitive);
/// `waves` the wave names.
pub(crate) fn parse_shadow(
    t: &Table<'_, '_>,
    name: String,
    objects: &[(&str, bool)],
    waves: &[&str],
    rd: &mut ParamReader<'_>,
) -> Res<ShadowDef> {
    t.check_keys(SHADOW_KEYS)?;
    let kind = t.choice("kind", &["sun", "wave"], None)?;
    let method = t.choice("method", &["plane", "map"], Some("plane"))?;
    let casters = object_list(t, "casters", objects)?;
    let receivers = object_list(t, "receivers", objects)?;
    let refuse = |key: &str, why: &str| -> Res<()> {
        if t.get(key).is_some() {
            return Err(t.src.value_err(&t.key_span(key), format!("`{key}` in {} {why}", t.what)));
        }
        Ok(())
    };
    let mut params = ParamSet::default();
    let mut wave = None;
    let mut own_direction = false;
    if kind == "sun" {
        refuse("wave", "applies to `kind = \"wave\"` shadows")?;
        refuse("theta", "applies to `kind = \"wave\"` shadows (a sun shadow's length follows the sun)")?;
        if t.get("direction").is_some() {
            own_direction = true;
            rd.add(
                t,
                &mut params,
                "direction",
                V3,
                Constraint::NonZero,
                Fallback::Value(&[0.0, -1.0, 0.0]),
                false,
            )?;
        }
    } else {
        refuse(
            "direction",
            "applies to `kind = \"sun\"` shadows; a wave shadow's direction comes from the wave",
        )?;
        wave = Some(match t.opt_str("wave")? {
            Some((w, span)) => waves.iter().position(|n| *n == w).ok_or_else(|| {
                t.src.value_err(
                    &span,
                    format!("`wave` in {}: no [[wave]] is named \"{w}\"{}", t.what, hint(w, waves, "names")),
                )
            })?,
            None if waves.len() == 1 => 0,
            None => {
                return Err(t.src.missing(
                    &t.span,
                    if waves.is_empty() {
                        format!("{} is a wave shadow, but the scene has no [[wave]]", t.what)
                    } else {
                        format!(
                            "{} needs `wave` (the scene has {} waves: {})",
                            t.what,
                            waves.len(),
                            waves.join(", ")
                        )
                    },
                ))
            }
        });
        rd.add(t, &mut params, "theta", Shape::Scalar, THETA, Fallback::Value(&[DEFAULT_THETA_DEG]), false)?;
    }

    let plane = if method == "plane" {
        refuse("up", "applies to `method = \"map\"`; a plane's lit side is its normal")?;
        refuse("map_size", "applies to `method = \"map\"`")?;
        let (has_pn, has_pts) = (
            t.get("plane_point").is_some() || t.get("plane_normal").is_some(),
            t.get("plane_points").is_some(),
        );
        if has_pn && has_pts {
            return Err(t.src.value_err(
                &t.key_span("plane_points"),
                format!(
                    "{} gives both `plane_points` and `plane_point`/`plane_normal`; give one plane",
                    t.what
                ),
            ));
        }
        Some(if has_pts {
            let three = |v: &DeValue<'_>| matches!(v, DeValue::Array(a) if a.len() == 3);
            if let Some(v) = t.get("plane_points").filter(|v| !three(v.get_ref())) {
                return Err(t.src.type_err(
                    &v.span(),
                    format!(
                        "`plane_points` in {} must be three points [[x, y, z], [x, y, z], [x, y, z]] (I, J, K), got {}",
                        t.what,
                        match v.get_ref() {
                            DeValue::Array(a) => format!("{} entries", a.len()),
                            other => type_name(other).to_string(),
                        }
                    ),
                ));
            }
            rd.add(
                t,
                &mut params,
                "plane_points",
                Shape::List(3),
                Constraint::Any,
                Fallback::Required(""),
                false,
            )?;
            PlaneSource::ThreePoints
        } else if has_pn {
            rd.add(
                t,
                &mut params,
                "plane_point",
                V3,
                Constraint::Any,
                Fallback::Required("a point of the receiver plane"),
                false,
            )?;
            rd.add(
                t,
                &mut params,
                "plane_normal",
                V3,
                Constraint::NonZero,
                Fallback::Required("the normal of the plane's lit side"),
                false,
            )?;
            PlaneSource::PointNormal
        } else {
            match receivers.as_slice() {
                [r] if objects[*r as usize].1 => PlaneSource::Object(*r as usize),
                _ => {
                    return Err(t.src.missing(
                        &t.span,
                        format!(
                            "{} projects onto a plane: give `plane_point` and `plane_normal`, or `plane_points = [I, J, K]` \
                             (or make its one receiver a `kind = \"plane\"` object, or use `method = \"map\"`)",
                            t.what
                        ),
                    ))
                }
            }
        })
    } else {
        for key in ["plane_point", "plane_normal", "plane_points"] {
            refuse(
                key,
                "applies to `method = \"plane\"`; a shadow map finds the receivers' surfaces itself",
            )?;
        }
        rd.add(t, &mut params, "up", V3, Constraint::NonZero, Fallback::Value(&[0.0, 1.0, 0.0]), false)?;
        None
    };
    let map_size = t.opt_int("map_size", 1, i64::from(MAX_MAP_SIZE))?.map_or(1024, |v| v.0 as u32);
    rd.add(t, &mut params, "color", V3, Constraint::NonNeg, Fallback::Value(&[0.0; 3]), false)?;
    rd.add(t, &mut params, "opacity", Shape::Scalar, UNIT, Fallback::Value(&[0.6]), false)?;
    let def = ShadowDef { name, wave, own_direction, plane, map_size, casters, receivers, params };
    Ok(def)
}

/// Cross-key rules of a shadow at one set of values: three plane points that span a plane.
pub(crate) fn check_shadow(s: &ShadowDef, vals: &[f32]) -> Result<(), (&'static str, String)> {
    if s.plane == Some(PlaneSource::ThreePoints) {
        let p = s.params.raw(vals, "plane_points");
        let pt = |i: usize| Vec3f::new(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
        if Plane::from_points(pt(0).as_f64(), pt(1).as_f64(), pt(2).as_f64()).is_none() {
            return Err((
                "plane_points",
                "`plane_points` coincide or lie on one line; I, J and K must span a plane".into(),
            ));
        }
    }
    Ok(())
}

/// Checks the scene's shadow maps against the frame budget ([`MAX_MAPS`], [`MAX_MAP_TEXELS`]).
pub(crate) fn check_map_budget(shadows: &[ShadowDef]) -> Result<(), (usize, String)> {
    let (mut maps, mut texels) = (0usize, 0u64);
    for (i, s) in shadows.iter().enumerate() {
        if s.plane.is_some() {
            continue;
        }
        let n = if s.wave.is_some() { s.casters.len() } else { 1 };
        maps += n;
        texels += n as u64 * u64::from(s.map_size).pow(2);
        if maps > MAX_MAPS || texels > MAX_MAP_TEXELS {
            return Err((
                i,
                format!(
                    "the scene's shadow maps need {maps} maps of {} texels in all by this shadow; at most {MAX_MAPS} maps \
                     and {} texels (for example 64 maps of 1024²) fit; lower `map_size` or use fewer casters",
                    texels,
                    MAX_MAP_TEXELS
                ),
            ));
        }
    }
    Ok(())
}

/// The frame's shadow `s` at these values. `sun` is `[light] direction` (unit).
pub(crate) fn build_shadow(
    s: &ShadowDef,
    vals: &[f32],
    base: &[f32],
    sun: Vec3f,
    objects: &[Object],
) -> Shadow {
    let p = &s.params;
    let v3 = |vals: &[f32], key: &str| Vec3f::from_array(p.arr::<3>(vals, key));
    let unit = |key: &str, fallback: Vec3f| {
        v3(vals, key).try_normalize().unwrap_or_else(|| v3(base, key).normalize_or(fallback))
    };
    let light = match s.wave {
        None if s.own_direction => ShadowLight::Sun(unit("direction", -Vec3f::Y)),
        None => ShadowLight::Sun(sun),
        Some(w) => {
            ShadowLight::Wave { wave: w as u32, theta: p.f(vals, "theta").clamp(0.0, 89.99).to_radians() }
        }
    };
    let method = match s.plane {
        None => ShadowMethod::Map { size: s.map_size },
        Some(src) => {
            let plane = match src {
                PlaneSource::PointNormal => {
                    Plane::new(v3(vals, "plane_point"), unit("plane_normal", Vec3f::Y))
                }
                PlaneSource::ThreePoints => {
                    let at = |vals: &[f32]| {
                        let q = p.raw(vals, "plane_points");
                        let pt = |i: usize| Vec3f::new(q[3 * i], q[3 * i + 1], q[3 * i + 2]);
                        Plane::from_points(pt(0), pt(1), pt(2))
                    };
                    at(vals).or_else(|| at(base))
                }
                PlaneSource::Object(o) => {
                    let obj = &objects[o];
                    let n = obj.transform.normal_matrix().transform_vector(Vec3f::Y);
                    Plane::new(obj.transform.transform_point(Vec3f::ZERO), n)
                }
            };
            ShadowMethod::Plane(plane.unwrap_or(Plane { point: Vec3f::ZERO, normal: Vec3f::Y }))
        }
    };
    let up = match method {
        ShadowMethod::Plane(pl) => pl.normal,
        ShadowMethod::Map { .. } => unit("up", Vec3f::Y),
    };
    Shadow {
        name: s.name.clone(),
        light,
        method,
        up,
        casters: s.casters.clone(),
        receivers: s.receivers.clone(),
        color: p.arr(vals, "color"),
        opacity: p.f(vals, "opacity"),
    }
}
