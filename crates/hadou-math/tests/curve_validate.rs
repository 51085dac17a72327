//! Validation errors name their scene-file key; degenerate but legal shapes and degenerate rays
//! give finite energies with every integrator; invalid input never panics.

#[allow(dead_code)]
#[path = "curve_common/mod.rs"]
mod support;

use hadou_math::curve::{
    curve_energy, curve_energy_reference, prepare, CurveShape, CurveWave, Integrator, Reduction,
    MAX_SIMPSON_M, MAX_SLOPE, MAX_TURNS,
};
use hadou_math::energy::{Falloff, FieldParams, Ray};
use hadou_math::Vec3;
use support::*;

/// An edit that makes a valid wave invalid.
type Edit = Box<dyn Fn(&mut CurveWave)>;

fn field_of(w: &CurveWave) -> Option<&'static str> {
    w.validate().err().map(|e| {
        assert!(!e.message.is_empty());
        e.field
    })
}

#[test]
fn every_invalid_parameter_names_its_field() {
    let base = helix();
    assert_eq!(field_of(&base), None);
    let cases: Vec<(&str, Edit)> = vec![
        ("axis", Box::new(|w| w.frame.axis = Vec3::ZERO)),
        ("axis", Box::new(|w| w.frame.axis = Vec3::new(f32::NAN, 0.0, 0.0))),
        ("up", Box::new(|w| w.frame.up = Vec3::new(-3.0, 0.0, 0.0))),
        ("origin", Box::new(|w| w.frame.origin = Vec3::new(0.0, f32::INFINITY, 0.0))),
        ("gamma", Box::new(|w| w.gamma = 0.0)),
        ("gamma", Box::new(|w| w.gamma = -1.0)),
        ("extension", Box::new(|w| w.extension = 0.0)),
        ("extension", Box::new(|w| w.extension = 1.5)),
        ("attenuation", Box::new(|w| w.attenuation = -0.5)),
        ("alpha", Box::new(|w| w.alpha = f32::NAN)),
        (
            "radius",
            Box::new(|w| w.shape = CurveShape::Helix { radius: -1.0, rate: 1.0, phase: 0.0, length: 1.0 }),
        ),
        (
            "length",
            Box::new(|w| w.shape = CurveShape::Helix { radius: 1.0, rate: 1.0, phase: 0.0, length: 0.0 }),
        ),
        (
            "rate",
            Box::new(|w| {
                w.shape = CurveShape::Helix { radius: 1.0, rate: f32::NAN, phase: 0.0, length: 1.0 }
            }),
        ),
        ("points", Box::new(|w| w.shape = CurveShape::Bezier { points: vec![[0.0, 0.0]] })),
        ("points", Box::new(|w| w.shape = CurveShape::Bezier { points: vec![[0.0, 0.0], [f32::NAN, 1.0]] })),
        (
            "y_terms",
            Box::new(|w| {
                w.shape = CurveShape::TrigSum {
                    rate: 1.0,
                    y_terms: vec![[f32::INFINITY, 0.0]],
                    z_terms: vec![],
                    length: 1.0,
                }
            }),
        ),
        (
            "order",
            Box::new(|w| {
                w.shape = CurveShape::BSpline { points: vec![[0.0, 0.0]; 4], order: 1, knots: None }
            }),
        ),
        (
            "order",
            Box::new(|w| {
                w.shape = CurveShape::BSpline { points: vec![[0.0, 0.0]; 40], order: 17, knots: None }
            }),
        ),
        (
            "points",
            Box::new(|w| {
                w.shape = CurveShape::BSpline { points: vec![[0.0, 0.0]; 3], order: 4, knots: None }
            }),
        ),
        (
            "knots",
            Box::new(|w| {
                w.shape =
                    CurveShape::BSpline { points: vec![[0.0, 0.0]; 4], order: 3, knots: Some(vec![0.0; 6]) }
            }),
        ),
        (
            "knots",
            Box::new(|w| {
                w.shape = CurveShape::BSpline {
                    points: vec![[0.0, 0.0]; 4],
                    order: 2,
                    knots: Some(vec![0.0, 0.0, 0.5, 0.4, 1.0, 1.0, 1.0]),
                }
            }),
        ),
        (
            "knots",
            Box::new(|w| {
                w.shape = CurveShape::BSpline {
                    points: vec![[0.0, 0.0]; 4],
                    order: 2,
                    knots: Some(vec![0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0]),
                }
            }),
        ),
        // The bounds on a ray's work (cost.rs).
        (
            "rate",
            Box::new(|w| w.shape = CurveShape::Helix { radius: 0.8, rate: -1e6, phase: 0.0, length: 11.0 }),
        ),
        (
            "rate",
            Box::new(|w| {
                w.shape = CurveShape::TrigSum {
                    rate: 1.0,
                    y_terms: vec![[1.0, 0.0]; 64],
                    z_terms: vec![],
                    length: 13.0,
                }
            }),
        ),
        (
            "y_terms",
            Box::new(|w| {
                w.shape = CurveShape::TrigSum {
                    rate: 1e-3,
                    y_terms: vec![[1.0, 0.0]; 65],
                    z_terms: vec![],
                    length: 1.0,
                }
            }),
        ),
        (
            "points",
            Box::new(|w| {
                w.shape = CurveShape::BSpline { points: vec![[0.0, 0.0]; 513], order: 4, knots: None }
            }),
        ),
        (
            "gamma",
            Box::new(|w| {
                w.shape = CurveShape::Helix { radius: 1e3, rate: 1.0, phase: 0.0, length: 1.0 };
                w.gamma = 1e-3;
            }),
        ),
        (
            "gamma",
            Box::new(|w| {
                w.shape = CurveShape::Bezier { points: vec![[1e6, 0.0], [-1e6, 0.0], [1e6, 1e6]] };
                w.gamma = 1.0;
            }),
        ),
        (
            "knots",
            Box::new(|w| {
                w.shape = CurveShape::BSpline {
                    points: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [1.0, 0.0]],
                    order: 2,
                    knots: Some(vec![0.0, 0.0, 0.5, 0.500_000_1, 1.0, 1.0]),
                }
            }),
        ),
        (
            "knots",
            Box::new(|w| {
                w.shape = CurveShape::BSpline {
                    points: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [1.0, 0.0]],
                    order: 2,
                    knots: Some(vec![0.0, 0.0, 0.5, 0.5, 1.0, 1.0]),
                }
            }),
        ),
        (
            "m",
            Box::new(|w| {
                w.shape = CurveShape::Bezier { points: vec![[0.0, 1.0]; 64] };
                w.integrator = Integrator::Simpson { m: 5000, reduction: None };
            }),
        ),
        ("m", Box::new(|w| w.integrator = Integrator::Simpson { m: 0, reduction: None })),
        ("m", Box::new(|w| w.integrator = Integrator::Simpson { m: 101, reduction: None })),
        ("m", Box::new(|w| w.integrator = Integrator::Simpson { m: 100_002, reduction: None })),
        (
            "n",
            Box::new(|w| {
                w.integrator =
                    Integrator::Simpson { m: 100, reduction: Some(Reduction { n: 0, epsilon: 0.1 }) }
            }),
        ),
        (
            "epsilon",
            Box::new(|w| {
                w.integrator =
                    Integrator::Simpson { m: 100, reduction: Some(Reduction { n: 2, epsilon: -0.1 }) }
            }),
        ),
    ];
    for (field, edit) in &cases {
        let mut w = base.clone();
        edit(&mut w);
        assert_eq!(field_of(&w), Some(*field), "{w:?}");
        // Invalid input is sanitized, never a panic, and renders finitely; what is prepared keeps
        // the bounds on a ray's work.
        let c = prepare(&w);
        assert!(c.wave.turns().is_none_or(|t| t <= MAX_TURNS), "{field}: {:?}", c.wave.turns());
        assert!(c.wave.steepness() <= MAX_SLOPE, "{field}: {}", c.wave.steepness());
        if let Integrator::Simpson { m, .. } = c.wave.integrator {
            assert!(f64::from(m) * c.wave.point_cost() <= f64::from(MAX_SIMPSON_M), "{field}: m = {m}");
        }
        let r = pixel_ray(256.0, 256.0, Falloff::Faithful);
        let s = curve_energy(&c, &params32(&params(Falloff::Faithful)), &r.ray32(), 0.0, 1.0, 1.0);
        assert!(s.energy.is_finite());
    }
    // Valid waves are prepared unchanged, so the integrator's arithmetic for them is untouched.
    for (name, w) in shapes() {
        assert_eq!(prepare(&w).wave, w, "{name}");
    }
    // Legal edge values.
    let mut w = base.clone();
    w.extension = 1.0;
    w.attenuation = 0.0;
    w.integrator = Integrator::Simpson { m: 100_000, reduction: Some(Reduction { n: 1, epsilon: 0.0 }) };
    assert_eq!(field_of(&w), None);
}

fn degenerate_waves() -> Vec<CurveWave> {
    vec![
        wave(CurveShape::Helix { radius: 0.0, rate: 1.0, phase: 0.0, length: 20.0 }, 1.0),
        wave(CurveShape::Bezier { points: vec![[1.0, 1.0]; 5] }, 20.0),
        wave(CurveShape::BSpline { points: vec![[0.0, 0.0]; 6], order: 3, knots: None }, 20.0),
        wave(CurveShape::TrigSum { rate: 1.0, y_terms: vec![], z_terms: vec![], length: 20.0 }, 1.0),
        wave(CurveShape::Helix { radius: 2.0, rate: 1e3, phase: 0.0, length: 20.0 }, 1.0),
        wave(CurveShape::Helix { radius: 2.0, rate: 1.0, phase: 0.0, length: 1e-3 }, 1e-3),
    ]
}

/// Rays through the curve, along the axis, perpendicular to it in a cross-section, starting on
/// the curve, and to infinity.
fn degenerate_rays() -> Vec<(Ray<f64>, f64)> {
    let x = Vec3::X;
    vec![
        (Ray { origin: Vec3::new(-20.0, 0.0, 0.0), dir: x }, 1.0), // along the axis
        (Ray { origin: Vec3::new(0.0, 0.0, 40.0), dir: Vec3::new(0.0, 0.0, -1.0) }, 1.0), // perpendicular, through it
        (Ray { origin: Vec3::new(-10.0, 1.0, 1.0), dir: Vec3::new(0.0, 0.0, 1.0) }, 1.0), // in the start plane
        (Ray { origin: Vec3::new(-10.0, 0.0, 0.0), dir: Vec3::new(0.6, 0.8, 0.0) }, 1.0), // from the launch point
        (Ray { origin: Vec3::new(5.0, 0.3, -7.0), dir: Vec3::new(1e-9, 0.0, 1.0) }, 1.0), // almost perpendicular
    ]
}

#[test]
fn degenerate_shapes_and_rays_are_finite_and_continuous() {
    let integrators = [
        Integrator::Default,
        Integrator::Simpson { m: 100, reduction: None },
        Integrator::Simpson { m: 100, reduction: Some(Reduction { n: 4, epsilon: 0.0 }) },
    ];
    for mut w in degenerate_waves().into_iter().chain(shapes().into_iter().map(|s| s.1)) {
        for j in [0.0, 0.7] {
            w.attenuation = j;
            for integ in integrators {
                w.integrator = integ;
                let c = prepare(&w);
                for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
                    let p = FieldParams { falloff, core_radius: 0.0 };
                    let p32 = params32(&p);
                    for (ray, _) in degenerate_rays() {
                        let (dir, t1, t_far) = match falloff {
                            Falloff::Faithful => (ray.dir * 60.0, 1.0, 1.0),
                            Falloff::InverseSquare => (ray.dir.try_normalize().unwrap(), f64::INFINITY, 60.0),
                        };
                        let r64 = Ray { origin: ray.origin, dir };
                        let r32 = Ray { origin: ray.origin.as_f32(), dir: dir.as_f32() };
                        let s = curve_energy(&c, &p32, &r32, 0.0, t1 as f32, t_far as f32);
                        assert!(s.energy.is_finite() && s.energy >= 0.0, "{w:?} {ray:?}: {}", s.energy);
                        let reference = curve_energy_reference(&c, &p, &r64, 0.0, t1, t_far, 1e-8);
                        assert!(reference.is_finite() && reference >= 0.0);
                        // A slightly moved ray gives a nearby value (continuity), for the
                        // default integrator against its own neighbour.
                        if integ == Integrator::Default && falloff == Falloff::InverseSquare {
                            let r2 = Ray { origin: r32.origin + Vec3::new(1e-3, 1e-3, 0.0), dir: r32.dir };
                            let s2 = curve_energy(&c, &p32, &r2, 0.0, t1 as f32, t_far as f32);
                            assert!(s2.energy.is_finite());
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn non_finite_or_empty_spans_give_zero() {
    let c = prepare(&helix());
    let p = params32(&params(Falloff::InverseSquare));
    let r = pixel_ray(200.0, 200.0, Falloff::InverseSquare).ray32();
    for (t0, t1) in [(f32::NAN, 1.0), (0.0, f32::NAN), (5.0, 5.0), (5.0, 1.0), (f32::INFINITY, f32::INFINITY)]
    {
        assert_eq!(curve_energy(&c, &p, &r, t0, t1, 100.0).energy, 0.0, "{t0} {t1}");
    }
    let bad = Ray { origin: Vec3::new(f32::NAN, 0.0, 0.0), dir: Vec3::X };
    assert_eq!(curve_energy(&c, &p, &bad, 0.0, 1.0, 1.0).energy, 0.0);
}
