//! Degenerate rays (through a centre, along or parallel to an axis, in a splitting plane,
//! `D·Q = 0`, zero-length capsules) give finite values that are continuous with their neighbours;
//! the capsule's energy is continuous across its planes when `α_s = α_c`; and the closed forms
//! respect the configuration's symmetries (002 eq. 3.6–3.11, SPEC.md §1.2).

mod analytic_common;

use analytic_common::*;
use hadou_math::energy::{
    beam_energy, capsule_energy, cylinder_energy, sphere_energy, BeamField, CapsuleField, CylinderField,
    Falloff, FieldParams, Ray, SphereField, ENERGY_MAX,
};
use hadou_math::{Vec3, Vec3d};

const LAWS: [Falloff; 2] = [Falloff::Faithful, Falloff::InverseSquare];

fn params(falloff: Falloff, core: f64) -> FieldParams<f64> {
    FieldParams { falloff, core_radius: core }
}

/// A finite interval suiting the law: `t ∈ [0, 1]` with `|Q| = 20` (faithful) or `[0, 20]` along a
/// unit direction (inverse square); and the direction to use.
fn interval(falloff: Falloff, n: Vec3d) -> (Vec3d, f64, f64) {
    match falloff {
        Falloff::Faithful => (n * 20.0, 0.0, 1.0),
        Falloff::InverseSquare => (n, 0.0, 20.0),
    }
}

fn capsule() -> CapsuleField<f64> {
    CapsuleField {
        m: Vec3::new(0.3, -0.2, 0.1),
        d: Vec3::new(1.0, 2.0, -0.5).normalize_or(Vec3::X),
        length: 3.0,
        alpha_s: 1.3,
        alpha_c: 1.3,
    }
}

#[test]
fn ray_through_a_centre_is_finite_and_continuous() {
    let m = Vec3::new(0.5, 1.0, -2.0);
    let eye = Vec3::new(-4.0, 3.0, 5.0);
    let n = (m - eye).normalize_or(Vec3::X);
    let side = Vec3::new(n.y, -n.x, 0.0).normalize_or(Vec3::Y);
    let sphere = SphereField { center: m, alpha: 1.0 };
    for law in LAWS {
        let (q, t0, t1) = interval(law, n);
        for t1 in [t1, f64::INFINITY] {
            if law == Falloff::Faithful && t1.is_infinite() {
                continue;
            }
            let at = |off: f64, core: f64| {
                let ray = Ray { origin: eye + side * off, dir: q };
                sphere_energy(&params(law, core), &ray, t0, t1, &sphere)
            };
            // With a core radius the energy is an even, smooth function of the offset.
            for core in [1e-2, 1e-4] {
                let e0 = at(0.0, core);
                assert!(e0.is_finite() && e0 > 0.0);
                for off in [1e-12, 1e-9, 1e-7] {
                    let e = at(off, core);
                    let bound = 4.0 * (off / core).powi(2) + 1e-13;
                    assert!(rel(e, e0) <= bound, "{law:?} core {core} offset {off}: {e} vs {e0}");
                    assert!(rel(at(-off, core), e) <= 1e-12);
                }
            }
            // Without one the true integral diverges: the value saturates at the H floor, is
            // finite, and grows monotonically towards it.
            let e0 = at(0.0, 0.0);
            assert!(e0.is_finite() && e0 > 0.0 && e0 <= ENERGY_MAX, "{law:?}: {e0}");
            assert_eq!(at(1e-14, 0.0), e0, "{law:?}: below the floor the value is flat");
            let mut prev = e0;
            for off in [1e-11, 1e-9, 1e-6, 1e-3] {
                let e = at(off, 0.0);
                assert!(e.is_finite() && e < prev, "{law:?} offset {off}: {e} !< {prev}");
                prev = e;
            }
            // And the same in f32.
            let ray32 = Ray { origin: eye.as_f32(), dir: q.as_f32() };
            let p32 = FieldParams { falloff: law, core_radius: 0.0f32 };
            let s32 = SphereField { center: m.as_f32(), alpha: 1.0f32 };
            let e32 = sphere_energy(&p32, &ray32, t0 as f32, t1 as f32, &s32);
            assert!(e32.is_finite() && e32 > 0.0, "{law:?} f32: {e32}");
        }
    }
}

#[test]
fn ray_parallel_to_the_axis_integrates_the_constant_density() {
    let d = Vec3::new(0.0, 0.6, 0.8);
    let cyl = CylinderField { point: Vec3::new(1.0, -1.0, 0.5), dir: d, alpha: 2.0 };
    let perp = Vec3::new(1.0, 0.0, 0.0);
    for law in LAWS {
        for (rho, core) in [(0.7, 0.0), (0.7, 0.1), (0.0, 0.1)] {
            let (q, t0, t1) = interval(law, d);
            let ray = Ray { origin: cyl.point + perp * rho - d * 3.0, dir: q };
            let e = cylinder_energy(&params(law, core), &ray, t0, t1, &cyl);
            let r2 = rho * rho + core * core;
            let density = match law {
                Falloff::Faithful => 1.0 / r2.sqrt(),
                Falloff::InverseSquare => 1.0 / r2,
            };
            let exact = 2.0 * (t1 - t0) * density;
            assert!(rel(e, exact) < 1e-12, "{law:?} rho {rho}: {e} vs {exact}");
            // Tilting by tiny angles changes the value continuously (the a → 0 limit).
            let mut prev_err = 0.0;
            for tilt in [1e-15, 1e-12, 1e-9, 1e-6, 1e-4] {
                let q2 = (d + perp * tilt).normalize_or(d) * q.length();
                let case_ray = Ray { origin: ray.origin, dir: q2 };
                let et = cylinder_energy(&params(law, core), &case_ray, t0, t1, &cyl);
                let err = rel(et, exact);
                assert!(err <= 50.0 * tilt + 1e-12, "{law:?} tilt {tilt}: {et} vs {exact}");
                assert!(err >= prev_err * 0.5 - 1e-13, "{law:?}: not monotone in the tilt");
                prev_err = err;
            }
            // f32 agrees.
            let e32 = cylinder_energy(
                &FieldParams { falloff: law, core_radius: core as f32 },
                &Ray { origin: ray.origin.as_f32(), dir: q.as_f32() },
                t0 as f32,
                t1 as f32,
                &CylinderField { point: cyl.point.as_f32(), dir: d.as_f32(), alpha: 2.0f32 },
            );
            assert!(rel(f64::from(e32), exact) < 1e-5, "{law:?} f32: {e32} vs {exact}");
        }
    }
    // Along the axis to infinity with the inverse-square law the integral diverges: finite cap.
    let ray = Ray { origin: cyl.point, dir: d };
    let e = cylinder_energy(&params(Falloff::InverseSquare, 0.0), &ray, 0.0, f64::INFINITY, &cyl);
    assert!(e.is_finite() && e >= ENERGY_MAX, "{e}");
    let e32 = cylinder_energy(
        &FieldParams { falloff: Falloff::InverseSquare, core_radius: 0.0f32 },
        &Ray { origin: cyl.point.as_f32(), dir: d.as_f32() },
        0.0,
        f32::INFINITY,
        &CylinderField { point: cyl.point.as_f32(), dir: d.as_f32(), alpha: 2.0f32 },
    );
    assert!(e32.is_finite(), "{e32}");
}

/// Rays with `D·Q = 0` lie in one region; their energy is that region's closed form and is
/// continuous with slightly tilted rays and across the planes.
#[test]
fn rays_parallel_to_the_splitting_planes() {
    let c = capsule();
    let u = Vec3::new(2.0, -1.0, 0.0).normalize_or(Vec3::X);
    let u = (u - c.d * u.dot(c.d)).normalize_or(Vec3::X); // ⟂ D
    let v = c.d.cross(u);
    let m2 = c.m2();
    for law in LAWS {
        let p = params(law, 0.05);
        let (q, t0, t1) = interval(law, u);
        for z in [-1.0, 0.0, 1.2, 3.0, 4.5] {
            let ray = Ray { origin: c.m + c.d * z + v * 0.4 - u * 6.0, dir: q };
            let e = capsule_energy(&p, &ray, t0, t1, &c);
            let expect = if z < 0.0 {
                sphere_energy(&p, &ray, t0, t1, &SphereField { center: c.m, alpha: c.alpha_s })
            } else if z > c.length {
                sphere_energy(&p, &ray, t0, t1, &SphereField { center: m2, alpha: c.alpha_s })
            } else {
                cylinder_energy(&p, &ray, t0, t1, &CylinderField { point: c.m, dir: c.d, alpha: c.alpha_c })
            };
            assert!(rel(e, expect) < 1e-14, "{law:?} z {z}: {e} vs {expect}");
            // Tilting out of the plane by tiny angles: continuous.
            for tilt in [1e-14, 1e-10, 1e-7] {
                let rt = Ray { origin: ray.origin, dir: (q + c.d * (tilt * q.length())) };
                let et = capsule_energy(&p, &rt, t0, t1, &c);
                assert!(rel(et, e) < 1e3 * tilt + 1e-13, "{law:?} z {z} tilt {tilt}: {et} vs {e}");
            }
        }
        // In the planes themselves (z = 0, z = length) and just beside them: continuous.
        for z in [0.0, c.length] {
            let on = Ray { origin: c.m + c.d * z + v * 0.4 - u * 6.0, dir: q };
            let e = capsule_energy(&p, &on, t0, t1, &c);
            for dz in [1e-12, 1e-9, 1e-6] {
                for sign in [-1.0, 1.0] {
                    let off = Ray { origin: on.origin + c.d * (sign * dz), dir: q };
                    let eo = capsule_energy(&p, &off, t0, t1, &c);
                    assert!(
                        rel(eo, e) < 10.0 * dz + 1e-13,
                        "{law:?} plane {z} dz {}: {eo} vs {e}",
                        sign * dz
                    );
                }
            }
        }
    }
}

/// Energies along a family of rays sweeping across a splitting plane change smoothly when
/// `α_s = α_c`, and show the jump when they differ (so the check can fail).
#[test]
fn capsule_energy_is_continuous_across_its_planes() {
    let base = capsule();
    let u =
        (Vec3::new(0.3, -1.0, 2.0) - base.d * Vec3::new(0.3, -1.0, 2.0).dot(base.d)).normalize_or(Vec3::X);
    let v = base.d.cross(u);
    // Largest step between neighbouring rays (1e-5 apart) relative to the mean energy: about
    // 1e-4 for a smooth family, the size of the α jump for a discontinuous one.
    let roughness = |c: &CapsuleField<f64>, law: Falloff, tilted: bool| {
        let p = params(law, 0.02);
        let dir = if tilted { (u + base.d * 0.3).normalize_or(u) } else { u };
        let (q, t0, t1) = interval(law, dir);
        let es: Vec<f64> = (-100..=100)
            .map(|k| {
                let z = k as f64 * 1e-5;
                let o = c.m + c.d * z + v * 0.15 - dir * 8.0;
                capsule_energy(&p, &Ray { origin: o, dir: q }, t0, t1, c)
            })
            .collect();
        let mean = es.iter().sum::<f64>() / es.len() as f64;
        es.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max) / mean
    };
    for law in LAWS {
        for tilted in [false, true] {
            let r = roughness(&base, law, tilted);
            assert!(r < 1e-3, "{law:?} tilted {tilted}: neighbour step {r} of the energy");
        }
        let jumpy = CapsuleField { alpha_c: base.alpha_s * 1.5, ..base };
        let r = roughness(&jumpy, law, false);
        assert!(r > 1e-2, "{law:?}: the α_s ≠ α_c jump must be visible, step {r}");
    }
}

#[test]
fn zero_length_capsule_is_the_sphere() {
    let mut rng = Rng(77);
    for law in LAWS {
        for _ in 0..500 {
            let case = random_case(&mut rng, RayClass::Generic, law);
            let mut c = case.beam.capsule;
            c.length = 0.0;
            let s = SphereField { center: c.m, alpha: c.alpha_s };
            let e = capsule_energy(&case.p, &case.ray, case.t0, case.t1, &c);
            let es = sphere_energy(&case.p, &case.ray, case.t0, case.t1, &s);
            assert!(rel(e, es) < 1e-12, "{law:?}: {e} vs {es}");
            c.length = 1e-9;
            let e9 = capsule_energy(&case.p, &case.ray, case.t0, case.t1, &c);
            assert!(rel(e9, es) < 1e-6, "{law:?}: length 1e-9 {e9} vs {es}");
            let e32 = capsule_energy(
                &case.to_f32().p,
                &case.to_f32().ray,
                case.t0 as f32,
                case.t1 as f32,
                &CapsuleField { length: 0.0, ..case.to_f32().beam.capsule },
            );
            assert!(e32.is_finite());
        }
    }
}

/// A rotation about `axis` (unit) by `angle` (Rodrigues).
fn rotate(x: Vec3d, axis: Vec3d, angle: f64) -> Vec3d {
    let (s, c) = angle.sin_cos();
    x * c + axis.cross(x) * s + axis * (axis.dot(x) * (1.0 - c))
}

#[test]
fn symmetries_of_the_configuration() {
    let mut rng = Rng(99);
    for law in LAWS {
        for i in 0..1000 {
            let case = random_case(&mut rng, RayClass::Generic, law);
            let (p, ray, t0, t1) = (case.p, case.ray, case.t0, case.t1);
            let c = case.beam.capsule;
            let e = capsule_energy(&p, &ray, t0, t1, &c);
            let eb = beam_energy(&p, &ray, t0, t1, &case.beam);
            // Swapping the ends: M' = M₂, D' = −D.
            let swapped = CapsuleField { m: c.m2(), d: -c.d, ..c };
            let es = capsule_energy(&p, &ray, t0, t1, &swapped);
            assert!(rel(es, e) < 1e-10, "{law:?} #{i} swap: {es} vs {e}");
            let bswap = BeamField {
                capsule: swapped,
                head_alpha: case.beam.muzzle_alpha,
                muzzle_alpha: case.beam.head_alpha,
            };
            assert!(rel(beam_energy(&p, &ray, t0, t1, &bswap), eb) < 1e-10, "{law:?} #{i} beam swap");
            // Mirroring the ray about the mid-plane (normal D through the capsule's middle).
            let mid = c.m + c.d * (0.5 * c.length);
            let mirror = |x: Vec3d| x - c.d * (2.0 * x.dot(c.d));
            let mray = Ray { origin: mid + mirror(ray.origin - mid), dir: mirror(ray.dir) };
            let em = capsule_energy(&p, &mray, t0, t1, &c);
            assert!(rel(em, e) < 1e-10, "{law:?} #{i} mirror: {em} vs {e}");
            // Rotating and translating everything.
            let axis = rng.unit_vec();
            let angle = rng.range(0.0, std::f64::consts::TAU);
            let shift = rng.in_cube(5.0);
            let tf = |x: Vec3d| rotate(x, axis, angle) + shift;
            let rray = Ray { origin: tf(ray.origin), dir: rotate(ray.dir, axis, angle) };
            let rc = CapsuleField { m: tf(c.m), d: rotate(c.d, axis, angle), ..c };
            let er = capsule_energy(&p, &rray, t0, t1, &rc);
            assert!(rel(er, e) < 1e-9, "{law:?} #{i} rotate: {er} vs {e}");
            // Running the ray backwards over the same segment (finite ends only).
            if t1.is_finite() {
                let back = Ray { origin: ray.origin + ray.dir * t1, dir: -ray.dir };
                let eback = beam_energy(&p, &back, 0.0, t1 - t0, &case.beam);
                assert!(rel(eback, eb) < 1e-9, "{law:?} #{i} reversed: {eback} vs {eb}");
            }
            // Faithful: scaling Q by k and the interval by 1/k scales the energy by 1/k.
            if law == Falloff::Faithful {
                let k = rng.log_range(0.1, 10.0);
                let sray = Ray { origin: ray.origin, dir: ray.dir * k };
                let ek = beam_energy(&p, &sray, t0 / k, t1 / k, &case.beam);
                assert!(rel(ek * k, eb) < 1e-10, "{law:?} #{i} scale: {} vs {eb}", ek * k);
            }
        }
    }
}

#[test]
fn empty_and_non_finite_intervals_give_zero_and_splitting_the_interval_adds_up() {
    let mut rng = Rng(5);
    for law in LAWS {
        for _ in 0..300 {
            let case = random_case(&mut rng, RayClass::Generic, law);
            let (p, ray) = (case.p, case.ray);
            let b = &case.beam;
            assert_eq!(beam_energy(&p, &ray, case.t0, case.t0, b), 0.0);
            assert_eq!(beam_energy(&p, &ray, case.t0 + 1.0, case.t0, b), 0.0);
            assert_eq!(beam_energy(&p, &ray, f64::NAN, case.t1, b), 0.0);
            assert_eq!(beam_energy(&p, &ray, case.t0, f64::NAN, b), 0.0);
            // Additivity over a split point (exercises all branches of the stable forms).
            let tm =
                if case.t1.is_finite() { case.t0 + rng.unit() * (case.t1 - case.t0) } else { case.t0 + 3.0 };
            let whole = beam_energy(&p, &ray, case.t0, case.t1, b);
            let parts = beam_energy(&p, &ray, case.t0, tm, b) + beam_energy(&p, &ray, tm, case.t1, b);
            assert!(rel(parts, whole) < 1e-11, "{law:?}: {parts} vs {whole}");
        }
    }
    // A zero direction (eye = far point) is a constant density over the interval.
    let s = SphereField { center: Vec3::new(0.0, 3.0, 4.0), alpha: 1.0 };
    let ray = Ray { origin: Vec3::ZERO, dir: Vec3::ZERO };
    let e = sphere_energy(&params(Falloff::Faithful, 0.0), &ray, 0.0, 1.0, &s);
    assert!(rel(e, 0.2) < 1e-15, "{e}");
    let e = sphere_energy(&params(Falloff::InverseSquare, 0.0), &ray, 0.0, f64::INFINITY, &s);
    assert!(e.is_finite(), "{e}");
}

#[test]
fn huge_and_tiny_parameters_stay_finite_in_f32() {
    let c = CapsuleField {
        m: Vec3::new(0.0f32, 0.0, -10.0),
        d: Vec3::new(1.0, 0.0, 0.0),
        length: 5.0,
        alpha_s: 1.0,
        alpha_c: 1.0,
    };
    let beam = BeamField { capsule: c, head_alpha: 2.0, muzzle_alpha: 1.0 };
    let dirs = [
        Vec3::new(0.0f32, 0.0, -1.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::new(0.0, 1e-30, -1.0),
        Vec3::new(1e-20, 0.0, -1.0),
    ];
    for law in LAWS {
        for core in [0.0f32, 1e-20, 1e-3, 1e3] {
            let p = FieldParams { falloff: law, core_radius: core };
            for dir in dirs {
                for origin in [Vec3::ZERO, Vec3::new(0.0, 0.0, -10.0), Vec3::new(2.5, 0.0, -10.0), c.m2()] {
                    for scale in [1.0f32, 1e4, 1e-4] {
                        let ray = Ray { origin, dir: dir * scale };
                        for (t0, t1) in [(0.0f32, 1.0f32), (0.0, 1e30), (-1e30, 1e30), (0.0, f32::INFINITY)] {
                            let e = beam_energy(&p, &ray, t0, t1, &beam);
                            assert!(
                                e.is_finite() && e >= 0.0,
                                "{law:?} {core} {dir:?} {origin:?} {scale} {t1}: {e}"
                            );
                        }
                    }
                }
            }
        }
    }
}
