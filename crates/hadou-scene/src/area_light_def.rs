//! `[area_light]` as the scene file writes it: [`AreaLightDef`] (read by [`parse_area_light`],
//! checked by [`check_area_light`]) and [`build_area_light`], the frame's [`AreaLight`] at one set
//! of values: `G` from an object or a point, and the two map frames around every caster.

use crate::area_light::{
    AreaLight, LampShape, Penumbra, SoftResolve, DEFAULT_TRACE_SAMPLES, MAX_GRID, MAX_TRACE_SAMPLES,
};
use crate::bounds::{box_corners, caster_box, object_bounds, object_center};
use crate::frame::Object;
use crate::limits::fmt_f32;
use crate::params::{Constraint, ParamSet, Shape};
use crate::shadow::MAX_MAP_SIZE;
use crate::toml_read::{type_name, Fallback, ParamReader, Res, Table};
use hadou_math::soft::{light_pair, SpotMap};
use hadou_math::Vec3f;
use toml::de::DeValue;

pub(crate) const AREA_LIGHT_KEYS: &[&str] = &[
    "position",
    "size",
    "target",
    "color",
    "intensity",
    "map_size",
    "resolve",
    "n",
    "depth_aware",
    "casters",
    "penumbra",
    "shape",
    "samples",
];

/// Where `G` comes from.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Target {
    /// The centre of this object's bounding box.
    Object(usize),
    /// The animatable point `target`.
    Point,
}

/// The `[area_light]` as read.
#[derive(Clone, Debug)]
pub(crate) struct AreaLightDef {
    pub target: Target,
    pub casters: Vec<u32>,
    pub map_size: u32,
    pub resolve: SoftResolve,
    pub depth_aware: bool,
    pub penumbra: Penumbra,
    pub shape: LampShape,
    pub params: ParamSet,
}

/// Parses `[area_light]`; `objects_with_kind` are the scene's objects (name, is a `plane`
/// primitive).
pub(crate) fn parse_area_light(
    t: &Table<'_, '_>,
    objects_with_kind: &[(&str, bool)],
    rd: &mut ParamReader<'_>,
) -> Res<AreaLightDef> {
    t.check_keys(AREA_LIGHT_KEYS)?;
    let names: Vec<&str> = objects_with_kind.iter().map(|o| o.0).collect();
    let objects = names.as_slice();
    // Casters: as listed, or every object that is not a `kind = "plane"` primitive.
    let casters = if t.get("casters").is_some() {
        t.object_list("casters", objects_with_kind)?
    } else {
        (0..objects_with_kind.len() as u32).filter(|&i| !objects_with_kind[i as usize].1).collect()
    };
    let mut params = ParamSet::default();
    rd.add(
        t,
        &mut params,
        "position",
        Shape::Vector(3),
        Constraint::Any,
        Fallback::Required("the light centre L"),
        false,
    )?;
    rd.add(
        t,
        &mut params,
        "size",
        Shape::Scalar,
        Constraint::Positive,
        Fallback::Required("the size parameter l > 0: the maps sit at L ± l·P"),
        false,
    )?;
    let target = match t.get("target").map(|v| (v, v.get_ref())) {
        Some((v, DeValue::String(s))) => {
            let name: &str = s.as_ref();
            match objects.iter().position(|n| *n == name) {
                Some(i) => Target::Object(i),
                None => {
                    return Err(t.src.value_err(
                        &v.span(),
                        format!(
                            "`target` in {}: no [[object]] is named \"{name}\"{}",
                            t.what,
                            crate::error::hint(name, objects, "names")
                        ),
                    ))
                }
            }
        }
        Some((_, DeValue::Array(_))) => {
            rd.add(
                t,
                &mut params,
                "target",
                Shape::Vector(3),
                Constraint::Any,
                Fallback::Required(""),
                false,
            )?;
            Target::Point
        }
        Some((v, other)) => {
            return Err(t.src.type_err(
                &v.span(),
                format!(
                    "`target` in {} must be an object name or a point [x, y, z], got {}",
                    t.what,
                    type_name(other)
                ),
            ))
        }
        None => {
            return Err(t.src.missing(
                &t.span,
                format!("{} needs `target` (the point of interest G: an object name or a point)", t.what),
            ))
        }
    };
    rd.add(t, &mut params, "color", Shape::Vector(3), Constraint::NonNeg, Fallback::Value(&[1.0; 3]), false)?;
    rd.add(t, &mut params, "intensity", Shape::Scalar, Constraint::NonNeg, Fallback::Value(&[1.0]), false)?;
    let map_size = t.opt_int("map_size", 1, i64::from(MAX_MAP_SIZE))?.map_or(1024, |v| v.0 as u32);
    let shape = match t.choice("shape", &["segment", "disc", "sphere"], Some("segment"))? {
        "disc" => LampShape::Disc,
        "sphere" => LampShape::Sphere,
        _ => LampShape::Segment,
    };
    let resolve_name = t.choice("resolve", &["exact", "faithful", "traced"], Some("exact"))?;
    // A key that belongs to another resolve than the one chosen.
    let not_here = |key: &str, why: &str| -> Res<()> {
        if t.get(key).is_some() {
            return Err(t.src.value_err(&t.key_span(key), format!("`{key}` in {} {why}", t.what)));
        }
        Ok(())
    };
    if resolve_name != "traced" {
        not_here("samples", "applies to `resolve = \"traced\"` (the two-map resolves take no lamp samples)")?;
    }
    let resolve = match resolve_name {
        "faithful" => {
            SoftResolve::Faithful { n: t.opt_int("n", 1, i64::from(MAX_GRID))?.map_or(3, |v| v.0 as u32) }
        }
        "traced" => {
            not_here("n", "applies to `resolve = \"faithful\"` (the traced resolve needs no grid)")?;
            not_here(
                "penumbra",
                "applies to the two-map resolves (the traced resolve counts the lamp samples each pixel sees)",
            )?;
            if let Some(v) = t.get("samples").filter(|v| !matches!(v.get_ref(), DeValue::Integer(_))) {
                return Err(t.src.type_err(
                    &v.span(),
                    format!(
                        "`samples` in {} must be an integer in 1..={MAX_TRACE_SAMPLES} (lamp samples a pixel), got {}",
                        t.what,
                        type_name(v.get_ref())
                    ),
                ));
            }
            let samples = t
                .opt_int("samples", 1, i64::from(MAX_TRACE_SAMPLES))?
                .map_or(DEFAULT_TRACE_SAMPLES, |v| v.0 as u32);
            SoftResolve::Traced { samples }
        }
        _ => {
            not_here("n", "applies to `resolve = \"faithful\"` (the exact resolve needs no grid)")?;
            SoftResolve::Exact
        }
    };
    let depth_aware = t.opt_bool("depth_aware")?.unwrap_or(true);
    let default_penumbra = if resolve == SoftResolve::Exact { "segment" } else { "linear" };
    let penumbra = match t.choice("penumbra", &["segment", "linear"], Some(default_penumbra))? {
        "linear" => Penumbra::Linear,
        _ => Penumbra::Segment,
    };
    Ok(AreaLightDef { target, casters, map_size, resolve, depth_aware, penumbra, shape, params })
}

/// `G` of the light at these values.
fn interest(def: &AreaLightDef, vals: &[f32], objects: &[Object]) -> Vec3f {
    interest_at(def, vals, |o| {
        object_center(&objects[o]).unwrap_or(objects[o].transform.transform_point(Vec3f::ZERO))
    })
}

/// `G` of the light at these values, `centre(o)` giving the centre of object `o` (its mesh's
/// bounding box centre placed in the world, its origin for an empty mesh).
pub(crate) fn interest_at(def: &AreaLightDef, vals: &[f32], centre: impl FnOnce(usize) -> Vec3f) -> Vec3f {
    match def.target {
        Target::Object(o) => centre(o),
        Target::Point => Vec3f::from_array(def.params.arr(vals, "target")),
    }
}

/// Cross-key rule at one set of values, `g` being `G` there ([`interest_at`]): `G ≠ L` and
/// `l < |L − G|` (else `L₂` would sit at or beyond `G`). The error names the key to change.
pub(crate) fn check_area_light(
    def: &AreaLightDef,
    vals: &[f32],
    g: Vec3f,
) -> Result<(), (&'static str, String)> {
    let l = Vec3f::from_array(def.params.arr(vals, "position"));
    let d = (l - g).length();
    let key = if def.target == Target::Point { "target" } else { "position" };
    if d.is_nan() || d <= 1e-6 {
        return Err((
            key,
            "the point of interest `target` coincides with the light's `position`: G must differ from L"
                .into(),
        ));
    }
    let size = def.params.f(vals, "size");
    if size >= d {
        return Err((
            "size",
            format!(
                "`size` ({}) must be less than the distance from `position` to `target` ({}): the nearer map L − l·P \
                 would sit at or beyond the point of interest",
                fmt_f32(size),
                fmt_f32(d)
            ),
        ));
    }
    Ok(())
}

/// The frame's area light at these values (never fails: an animated `G = L` falls back to the
/// file's values, and `l` is kept below `|L − G|`).
pub(crate) fn build_area_light(
    def: &AreaLightDef,
    vals: &[f32],
    base: &[f32],
    objects: &[Object],
) -> AreaLight {
    let p = &def.params;
    let at = |vals: &[f32]| (Vec3f::from_array(p.arr(vals, "position")), interest(def, vals, objects));
    let (mut l, mut g) = at(vals);
    if (l - g).length().is_nan() || (l - g).length() <= 1e-6 {
        (l, g) = at(base);
    }
    if (l - g).length().is_nan() || (l - g).length() <= 1e-6 {
        g = l - Vec3f::Y;
    }
    let d = (l - g).length();
    let size = p.f(vals, "size").clamp(1e-6 * d, 0.99 * d);
    let (l1, l2) = light_pair(l, g, size).unwrap_or((l + Vec3f::Y * size, l - Vec3f::Y * size));
    let mut corners = Vec::with_capacity(def.casters.len() * 8);
    for o in def.casters.iter().map(|&c| &objects[c as usize]) {
        if let Some((lo, hi)) = object_bounds(o) {
            corners.extend(box_corners(lo, hi));
        }
    }
    let intensity = p.f(vals, "intensity");
    let color: [f32; 3] = p.arr(vals, "color");
    AreaLight {
        position: l,
        size,
        shape: def.shape,
        interest: g,
        color: color.map(|c| hadou_math::energy::saturate(c * intensity)),
        map_size: def.map_size,
        resolve: def.resolve,
        depth_aware: def.depth_aware,
        penumbra: def.penumbra,
        casters: def.casters.clone(),
        maps: [SpotMap::look(l1, g, &corners), SpotMap::look(l2, g, &corners)],
        caster_boxes: def.casters.iter().filter_map(|&c| caster_box(&objects[c as usize])).collect(),
    }
}
