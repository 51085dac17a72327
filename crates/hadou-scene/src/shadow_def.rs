//! `[[shadow]]` as the scene file writes it: [`ShadowDef`] (read and checked by [`parse_shadow`],
//! [`check_shadow`] and [`check_map_budget`]) and [`build_shadow`], the frame's [`Shadow`] at one
//! set of values.

use crate::error::hint;
use crate::frame::Object;
use crate::params::{Constraint, ParamSet, Shape};
use crate::shadow::{Shadow, ShadowLight, ShadowMethod, MAX_MAPS, MAX_MAP_SIZE, MAX_MAP_TEXELS};
use crate::toml_read::{type_name, Fallback, ParamReader, Res, Table};
use hadou_math::shadow::{Plane, DEFAULT_THETA_DEG};
use hadou_math::Vec3f;
use toml::de::DeValue;

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
    /// Ascending ([`Shadow::receives`] searches them).
    pub receivers: Vec<u32>,
    pub params: ParamSet,
}

const UNIT: Constraint = Constraint::Range { lo: 0.0, hi: 1.0, lo_open: false, hi_open: false };
const THETA: Constraint = Constraint::Range { lo: 0.0, hi: 90.0, lo_open: false, hi_open: true };
const V3: Shape = Shape::Vector(3);

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
    let casters = t.object_list("casters", objects)?;
    let mut receivers = t.object_list("receivers", objects)?;
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
    receivers.sort_unstable();
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
