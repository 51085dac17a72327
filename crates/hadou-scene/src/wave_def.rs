//! The reader of `[[wave]]` tables: a wave's kind (from the kinds' table, `wave_kind.rs`), its
//! keys with their ranges and defaults, a curve's shape and integrator, and the rules across a
//! curve's keys, checked on the file's values and at every key time of its tracks (`schema.rs`).

use crate::limits::ATTENUATION_MAX;
use crate::materials::parse_ramp;
use crate::params::{Constraint, ParamSet, Shape, ALPHA, ANY, NONNEG, POSITIVE, S, V3};
use crate::scene::{up_is_usable, IntegratorDef, Scene, WaveDef};
use crate::toml_read::{Fallback, ParamReader, Res, Table};
use crate::wave_kind::{CurveKind, WaveKind, WAVE_KINDS};
use hadou_math::energy::Falloff;
use hadou_math::Vec3f;

/// Default base colour of a wave: the yellow of 002 Fig. 4.1.
pub(crate) const DEFAULT_RGBA: [f32; 4] = [0.8, 0.8, 0.2, 1.0];
/// Default core radius (world units): small against the shapes of the thesis figures.
pub(crate) const DEFAULT_CORE_RADIUS: f32 = 0.02;

pub(crate) fn parse_wave(t: &Table<'_, '_>, name: String, rd: &mut ParamReader<'_>) -> Res<WaveDef> {
    let kind_s = t.choice("kind", WAVE_KINDS, None)?;
    let Some(kind) = WaveKind::from_name(kind_s) else {
        return Err(t.src.value_err(&t.key_span("kind"), format!("unknown wave kind \"{kind_s}\"")));
    };
    let is_curve = kind.is_curve();
    t.check_keys(&kind.keys())?;

    let falloff = match t.choice("falloff", &["faithful", "inverse-square"], Some("inverse-square"))? {
        "faithful" => Falloff::Faithful,
        _ => Falloff::InverseSquare,
    };
    let mut p = ParamSet::default();
    rd.add(t, &mut p, "rgba", Shape::Vector(4), Constraint::Rgba, Fallback::Value(&DEFAULT_RGBA), false)?;
    rd.add(t, &mut p, "core_radius", S, NONNEG, Fallback::Value(&[DEFAULT_CORE_RADIUS]), false)?;
    rd.add(t, &mut p, "light_glow", S, NONNEG, Fallback::Value(&[0.0]), false)?;
    // The push on VRM spring bones (`spring` module docs): 0 = none.
    rd.add(t, &mut p, "wind", S, NONNEG, Fallback::Value(&[0.0]), false)?;
    if !is_curve {
        // The distance attenuation (1 − u)^j of 002 eq. 3.23 (SPEC.md §1.4); curves read theirs
        // in parse_curve.
        let j_rule = Constraint::Range { lo: 0.0, hi: ATTENUATION_MAX, lo_open: false, hi_open: false };
        rd.add(t, &mut p, "j", S, j_rule, Fallback::Value(&[0.0]), false)?;
    }
    let light_ramp = parse_ramp(t, "light_ramp")?;
    let dir = Constraint::NonZero;
    let mut def = WaveDef {
        name,
        kind,
        falloff,
        params: ParamSet::default(),
        uses_m2: false,
        integrator: IntegratorDef::Default,
        order: 0,
        has_knots: false,
        light_ramp,
    };
    match kind {
        WaveKind::Sphere => {
            rd.add(t, &mut p, "M", V3, ANY, Fallback::Required("the centre"), false)?;
            rd.add(t, &mut p, "alpha_s", S, ALPHA, Fallback::Required("the strength α_s"), false)?;
        }
        WaveKind::Cylinder => {
            rd.add(t, &mut p, "M", V3, ANY, Fallback::Required("a point on the axis"), false)?;
            rd.add(t, &mut p, "D", V3, dir, Fallback::Required("the axis direction"), false)?;
            rd.add(t, &mut p, "alpha_c", S, ALPHA, Fallback::Required("the strength α_c"), false)?;
        }
        WaveKind::Capsule | WaveKind::Beam => {
            rd.add(t, &mut p, "M", V3, ANY, Fallback::Required("the muzzle end"), false)?;
            def.uses_m2 = t.get("M2").is_some();
            if def.uses_m2 {
                for other in ["D", "length"] {
                    if t.get(other).is_some() {
                        return Err(t.src.value_err(
                            &t.key_span(other),
                            format!("{} gives `M2`; give either `M2` or `D` + `length`, not both", t.what),
                        ));
                    }
                }
                rd.add(t, &mut p, "M2", V3, ANY, Fallback::Required("the head end"), false)?;
            } else {
                let need =
                    "the direction from M to the head; or give the head `M2` instead of `D` + `length`";
                rd.add(t, &mut p, "D", V3, dir, Fallback::Required(need), false)?;
                rd.add(
                    t,
                    &mut p,
                    "length",
                    S,
                    NONNEG,
                    Fallback::Required("the distance from M to the head"),
                    false,
                )?;
            }
            rd.add(
                t,
                &mut p,
                "alpha_s",
                S,
                ALPHA,
                Fallback::Required("the strength of the end spheres α_s"),
                false,
            )?;
            rd.add(
                t,
                &mut p,
                "alpha_c",
                S,
                ALPHA,
                Fallback::Required("the strength of the cylinder α_c"),
                false,
            )?;
            if kind == WaveKind::Beam {
                rd.add(t, &mut p, "head_alpha", S, ALPHA, Fallback::Value(&[0.0]), false)?;
                rd.add(t, &mut p, "muzzle_alpha", S, ALPHA, Fallback::Value(&[0.0]), false)?;
            }
        }
        WaveKind::Curve(kind) => parse_curve(t, &mut def, kind, &mut p, rd)?,
    }
    def.params = p;
    Ok(def)
}

fn parse_curve(
    t: &Table<'_, '_>,
    def: &mut WaveDef,
    kind: CurveKind,
    p: &mut ParamSet,
    rd: &mut ParamReader<'_>,
) -> Res<()> {
    let k_rule = Constraint::Range { lo: 0.0, hi: 1.0, lo_open: true, hi_open: false };
    rd.add(t, p, "O", V3, ANY, Fallback::Required("the launch point"), false)?;
    rd.add(t, p, "D", V3, Constraint::NonZero, Fallback::Required("the travel axis"), false)?;
    rd.add(t, p, "up", V3, Constraint::NonZero, Fallback::Value(&[0.0, 1.0, 0.0]), false)?;
    rd.add(t, p, "alpha", S, ALPHA, Fallback::Required("the strength α"), false)?;
    rd.add(t, p, "gamma", S, POSITIVE, Fallback::Value(&[1.0]), false)?;
    rd.add(t, p, "k", S, k_rule, Fallback::Value(&[1.0]), false)?;
    rd.add(t, p, "j", S, NONNEG, Fallback::Value(&[0.0]), false)?;
    match kind {
        CurveKind::Helix => {
            rd.add(t, p, "radius", S, NONNEG, Fallback::Required("the helix radius r"), false)?;
            rd.add(
                t,
                p,
                "rate",
                S,
                ANY,
                Fallback::Required("the angular rate θ in radians per unit s"),
                false,
            )?;
            rd.add(t, p, "phase", S, ANY, Fallback::Value(&[0.0]), false)?;
            rd.add(t, p, "length", S, POSITIVE, Fallback::Required("the parameter range s_end"), false)?;
        }
        CurveKind::Trig => {
            rd.add(t, p, "rate", S, ANY, Fallback::Required("the base angular rate θ"), false)?;
            rd.add(t, p, "y_terms", Shape::List(2), ANY, Fallback::Value(&[]), false)?;
            rd.add(t, p, "z_terms", Shape::List(2), ANY, Fallback::Value(&[]), false)?;
            rd.add(t, p, "length", S, POSITIVE, Fallback::Required("the parameter range s_end"), false)?;
        }
        CurveKind::Bezier | CurveKind::BSpline => {
            let meaning = "control points [[y, z], …] across the axis";
            rd.add(t, p, "points", Shape::List(2), ANY, Fallback::Required(meaning), false)?;
            let n_points = p.find("points").map_or(0, |q| q.len / 2);
            if n_points < 2 {
                let span = t.get("points").map_or(t.span.clone(), |v| v.span());
                return Err(t.src.value_err(
                    &span,
                    format!("`points` in {} needs at least 2 control points, got {n_points}", t.what),
                ));
            }
            if kind == CurveKind::BSpline {
                let order = t.opt_int("order", 2, n_points as i64)?.map_or(n_points.min(4), |v| v.0 as usize);
                def.order = order as u32;
                if let Some(v) = t.get("knots") {
                    rd.add(
                        t,
                        p,
                        "knots",
                        Shape::List(1),
                        Constraint::NonDecreasing,
                        Fallback::Value(&[]),
                        false,
                    )?;
                    let want = n_points + order;
                    let got = p.find("knots").map_or(0, |q| q.len);
                    if got != want {
                        return Err(t.src.value_err(
                            &v.span(),
                            format!(
                                "`knots` in {} needs {want} values ({n_points} points + order {order}), got {got}",
                                t.what
                            ),
                        ));
                    }
                    def.has_knots = true;
                }
            }
        }
    }
    // Distance field and integrator.
    let nearest = t.choice("field", &["section", "nearest"], Some("section"))? == "nearest";
    if nearest && t.get("integrator").is_some() {
        return Err(t.src.value_err(
            &t.key_span("integrator"),
            format!(
                "`integrator` in {} applies only with field = \"section\" (the nearest field has its own)",
                t.what
            ),
        ));
    }
    let simpson = t.choice("integrator", &["default", "simpson"], Some("default"))? == "simpson";
    let m = t.opt_int("m", 2, 100_000)?;
    let n = t.opt_int("n", 1, 100_000)?;
    if !simpson {
        if let Some(key) = ["m", "n", "epsilon"].into_iter().find(|k| t.get(k).is_some()) {
            return Err(t.src.value_err(
                &t.key_span(key),
                format!("`{key}` in {} applies only with integrator = \"simpson\"", t.what),
            ));
        }
    }
    if let Some((m, span)) = &m {
        if m % 2 != 0 {
            return Err(t.src.value_err(
                span,
                format!("`m` in {} must be even (composite Simpson), got {m}; try {}", t.what, m + 1),
            ));
        }
    }
    if n.is_none() && t.get("epsilon").is_some() {
        return Err(t.src.value_err(
            &t.key_span("epsilon"),
            format!("`epsilon` in {} applies only with the reduction `n`", t.what),
        ));
    }
    rd.add(t, p, "epsilon", S, NONNEG, Fallback::Value(&[0.0]), false)?;
    if simpson {
        def.integrator =
            IntegratorDef::Simpson { m: m.map_or(100, |v| v.0 as u32), n: n.map(|v| v.0 as u32) };
    } else if nearest {
        def.integrator = IntegratorDef::Nearest;
    }
    if let Err((key, msg)) = check_curve(def, p, rd.values) {
        return Err(t.src.value_err(&t.key_span(key), format!("{msg} in {}", t.what)));
    }
    Ok(())
}

/// Curve rules across keys: `up` not parallel to `D`; a B-spline knot vector with a non-empty
/// valid range.
fn check_curve(w: &WaveDef, p: &ParamSet, vals: &[f32]) -> Result<(), (&'static str, String)> {
    let axis = Vec3f::from_array(p.arr(vals, "D"));
    let Some(axis) = axis.try_normalize() else {
        return Err(("D", "`D` must not be the zero vector".into()));
    };
    if !up_is_usable(Vec3f::from_array(p.arr(vals, "up")), axis) {
        return Err(("up", "`up` must not be parallel to `D` (it fixes the cross-section axes)".into()));
    }
    if w.has_knots {
        let k = p.raw(vals, "knots");
        let n_points = p.raw(vals, "points").len() / 2;
        let lo = w.order as usize - 1;
        if k.get(lo) >= k.get(n_points) {
            return Err((
                "knots",
                format!(
                    "`knots` must increase somewhere between entries {lo} and {n_points} (the curve's range)"
                ),
            ));
        }
    }
    Ok(())
}

/// [`hadou_math::curve::CurveWave::validate`] on the curve built from `vals` (a no-op for analytic
/// waves); the error names the scene-file key.
pub(crate) fn validate_curve(scene: &Scene, w: &WaveDef, vals: &[f32]) -> Result<(), (&'static str, String)> {
    let kind = match w.kind {
        WaveKind::Sphere | WaveKind::Cylinder | WaveKind::Capsule | WaveKind::Beam => return Ok(()),
        WaveKind::Curve(kind) => kind,
    };
    scene.build_curve(w, kind, vals).validate().map_err(|e| {
        let key = match e.field {
            "origin" => "O",
            "axis" => "D",
            "extension" => "k",
            "attenuation" => "j",
            other => other,
        };
        (key, e.message)
    })
}

/// A wave's rules across keys on `vals`: a closed-form shape's `D` non-zero; a curve's rules
/// ([`check_curve`]) and its validation as built ([`validate_curve`]). The error names the key and
/// the wave.
pub(crate) fn check_wave_rules(scene: &Scene, w: &WaveDef, vals: &[f32]) -> Result<(), String> {
    let what = format!("[[wave]] \"{}\"", w.name);
    match w.kind {
        WaveKind::Sphere => Ok(()),
        WaveKind::Cylinder | WaveKind::Capsule | WaveKind::Beam => {
            if w.params.find("D").is_some()
                && Vec3f::from_array(w.params.arr(vals, "D")).try_normalize().is_none()
            {
                return Err(format!("`D` in {what} must not be the zero vector"));
            }
            Ok(())
        }
        WaveKind::Curve(_) => {
            check_curve(w, &w.params, vals).map_err(|e| format!("{} in {what}", e.1))?;
            validate_curve(scene, w, vals).map_err(|(key, msg)| format!("`{key}` in {what} {msg}"))
        }
    }
}
