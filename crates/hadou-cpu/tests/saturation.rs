//! An energy too large for `f32` (a ray through a sphere's centre or along a cylinder's axis with
//! `core_radius = 0` and a huge strength; frames built by hand, since scene files cap `α`)
//! renders at full brightness: the energy saturates at `f32::MAX` and the colour maps to the
//! wave's saturated colour (faithful) or white (filmic), for every wave kind and both falloffs —
//! never to 0 (black) or NaN. A strength of 0 still gives exactly 0.

use hadou_cpu::{probe, render};
use hadou_math::curve::{CurveFrame, CurveShape, CurveWave, Integrator};
use hadou_math::energy::{BeamField, CapsuleField, CylinderField, Falloff, SphereField};
use hadou_math::Vec3;
use hadou_scene::{ColorMapping, Frame, ToneMode, Wave, WaveShape};

mod common;

/// Every kind (default curve integrator; [`bezier`] adds Simpson), on the axis `x = y = 0` along which the centre pixel's ray runs, with strength `a`.
fn shapes(a: f32) -> Vec<WaveShape> {
    let z = Vec3::new(0.0, 0.0, 1.0);
    let capsule = CapsuleField { m: Vec3::new(0.0, 0.0, -1.0), d: z, length: 2.0, alpha_s: a, alpha_c: a };
    let curve = |shape: CurveShape, gamma: f32| {
        WaveShape::Curve(CurveWave {
            frame: CurveFrame { origin: Vec3::new(0.0, 0.0, -2.0), axis: z, up: Vec3::Y },
            shape,
            gamma,
            extension: 1.0,
            attenuation: 0.0,
            alpha: a,
            integrator: Integrator::Default,
        })
    };
    let line = vec![[0.0, 0.0]; 3];
    vec![
        WaveShape::Sphere(SphereField { center: Vec3::ZERO, alpha: a }),
        WaveShape::Cylinder(CylinderField { point: Vec3::ZERO, dir: z, alpha: a }),
        WaveShape::Capsule(capsule),
        WaveShape::Beam(BeamField { capsule, head_alpha: a, muzzle_alpha: a }),
        curve(CurveShape::Helix { radius: 0.0, rate: 1.0, phase: 0.0, length: 4.0 }, 1.0),
        curve(
            CurveShape::TrigSum { rate: 1.0, y_terms: vec![[0.0, 0.0]], z_terms: vec![], length: 4.0 },
            1.0,
        ),
        curve(CurveShape::Bezier { points: line.clone() }, 4.0),
        curve(CurveShape::BSpline { points: line, order: 2, knots: None }, 4.0),
    ]
}

fn bezier(a: f32) -> CurveWave {
    CurveWave {
        frame: CurveFrame { origin: Vec3::new(0.0, 0.0, -2.0), axis: Vec3::new(0.0, 0.0, 1.0), up: Vec3::Y },
        shape: CurveShape::Bezier { points: vec![[0.0, 0.0]; 2] },
        gamma: 4.0,
        extension: 1.0,
        attenuation: 0.0,
        alpha: a,
        integrator: Integrator::Simpson { m: 100, reduction: None },
    }
}

/// A 3×3 frame (the centre pixel looks exactly along −z) with two copies of the wave, so the
/// sum of two saturated energies is exercised too.
fn frame(shape: WaveShape, falloff: Falloff, mode: ToneMode) -> Frame {
    let wave = Wave::new("w", [1.0, 0.5, 0.0, 1.0], falloff, 0.0, shape);
    let camera = common::camera(Vec3::new(0.0, 0.0, 10.0), 45.0);
    Frame {
        color_mapping: ColorMapping { mode, exposure: 1.0 },
        ..common::frame(3, 3, camera, vec![], vec![wave.clone(), wave])
    }
}

#[test]
fn an_overflowing_energy_is_full_brightness_for_every_kind() {
    let mut shapes_all = shapes(f32::MAX);
    shapes_all.push(WaveShape::Curve(bezier(f32::MAX)));
    for shape in shapes_all {
        for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
            for (mode, want) in [(ToneMode::Faithful, [1.0, 1.0, 0.0]), (ToneMode::Filmic, [1.0, 1.0, 1.0])] {
                let frame = frame(shape.clone(), falloff, mode);
                let p = probe(&frame, 1, 1).expect("centre pixel");
                // Saturated, or (faithful 1/r, whose integral through a centre grows only
                // logarithmically) just below it.
                for w in &p.waves {
                    assert!(w.energy.is_finite() && w.energy >= 1e38, "{shape:?} {falloff:?}: {}", w.energy);
                }
                for (c, w) in p.color.iter().zip(want) {
                    assert!((c - w).abs() < 1e-6, "{shape:?} {falloff:?} {mode:?}: {:?}", p.color);
                }
                let img = render(&frame);
                assert!(img.color.iter().flatten().all(|v| v.is_finite()), "{shape:?}: colour");
                assert!(img.energy.iter().all(|v| v.is_finite() && *v >= 0.0), "{shape:?}: energy");
                // Two such energies add up to more than f32 holds: the sum saturates too.
                assert_eq!(img.energy[4], f32::MAX, "{shape:?} {falloff:?}: summed energy");
            }
        }
    }
}

#[test]
fn a_zero_strength_on_a_divergent_ray_is_exactly_zero() {
    let mut shapes_all = shapes(0.0);
    shapes_all.push(WaveShape::Curve(bezier(0.0)));
    for shape in shapes_all {
        for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
            let frame = frame(shape.clone(), falloff, ToneMode::Filmic);
            let p = probe(&frame, 1, 1).expect("centre pixel");
            for w in &p.waves {
                assert_eq!(w.energy, 0.0, "{shape:?} {falloff:?}");
            }
        }
    }
}
