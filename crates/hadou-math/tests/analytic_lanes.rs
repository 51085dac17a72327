//! The eight-lane kernels (`hadou_math::energy::lanes`) against the scalar `f32` kernels and the
//! `f64` reference: on random rays they are as accurate as the scalar ones, and on the degenerate
//! rays the scalar tests cover (through a centre, along and parallel to an axis, `D·Q = 0`,
//! zero-length capsules, far away, `r_c = 0`, empty, NaN and infinite spans) they are finite,
//! non-negative and equal to the scalar value — each lane on its own, whatever its neighbours.
//! Every test runs on each vector path the machine supports (`SimdPath::supported`: the portable
//! lanes everywhere, AVX2 + FMA and AVX-512 where the CPU has them).

use hadou_math::energy::lanes::{self, RayLanes, LANES, V3};
use hadou_math::energy::{
    beam_energy, capsule_energy, cylinder_energy, sphere_energy, BeamField, CapsuleField, CylinderField,
    Falloff, FieldParams, Ray, SphereField,
};
use hadou_math::rng::Rng;
use hadou_math::simd::{dispatch, Lane, SimdPath, WithLanes};
use hadou_math::{Vec3, Vec3f};

/// One ray of a batch: direction and span (the origin is the batch's).
#[derive(Clone, Copy, Debug)]
struct R {
    dir: Vec3f,
    t0: f32,
    t1: f32,
}

/// The shapes under test, each as (scalar f32, scalar f64, lanes).
#[derive(Clone, Copy, Debug)]
enum Shape {
    Sphere(SphereField<f32>),
    Cylinder(CylinderField<f32>),
    Capsule(CapsuleField<f32>),
    Beam(BeamField<f32>),
}

fn f64v(v: Vec3f) -> Vec3<f64> {
    v.as_f64()
}

fn capsule64(c: &CapsuleField<f32>) -> CapsuleField<f64> {
    CapsuleField {
        m: f64v(c.m),
        d: f64v(c.d),
        length: c.length as f64,
        alpha_s: c.alpha_s as f64,
        alpha_c: c.alpha_c as f64,
    }
}

impl Shape {
    fn scalar(&self, p: &FieldParams<f32>, origin: Vec3f, r: R) -> f32 {
        let ray = Ray { origin, dir: r.dir };
        match self {
            Shape::Sphere(f) => sphere_energy(p, &ray, r.t0, r.t1, f),
            Shape::Cylinder(f) => cylinder_energy(p, &ray, r.t0, r.t1, f),
            Shape::Capsule(f) => capsule_energy(p, &ray, r.t0, r.t1, f),
            Shape::Beam(f) => beam_energy(p, &ray, r.t0, r.t1, f),
        }
    }

    fn reference(&self, p: &FieldParams<f32>, origin: Vec3f, r: R) -> f64 {
        let p = FieldParams { falloff: p.falloff, core_radius: p.core_radius as f64 };
        let ray = Ray { origin: f64v(origin), dir: f64v(r.dir) };
        let (t0, t1) = (r.t0 as f64, r.t1 as f64);
        match self {
            Shape::Sphere(f) => sphere_energy(
                &p,
                &ray,
                t0,
                t1,
                &SphereField { center: f64v(f.center), alpha: f.alpha as f64 },
            ),
            Shape::Cylinder(f) => cylinder_energy(
                &p,
                &ray,
                t0,
                t1,
                &CylinderField { point: f64v(f.point), dir: f64v(f.dir), alpha: f.alpha as f64 },
            ),
            Shape::Capsule(f) => capsule_energy(&p, &ray, t0, t1, &capsule64(f)),
            Shape::Beam(f) => beam_energy(
                &p,
                &ray,
                t0,
                t1,
                &BeamField {
                    capsule: capsule64(&f.capsule),
                    head_alpha: f.head_alpha as f64,
                    muzzle_alpha: f.muzzle_alpha as f64,
                },
            ),
        }
    }

    fn lanes(&self, path: SimdPath, p: &FieldParams<f32>, origin: Vec3f, rays: &[R; LANES]) -> [f32; LANES] {
        dispatch(path, Kernel { shape: self, p, origin, rays })
    }
}

/// One shape's kernel on eight rays, on a path's lanes.
struct Kernel<'a> {
    shape: &'a Shape,
    p: &'a FieldParams<f32>,
    origin: Vec3f,
    rays: &'a [R; LANES],
}

impl WithLanes for Kernel<'_> {
    type Output = [f32; LANES];
    #[inline(always)]
    fn run<L: Lane>(self) -> [f32; LANES] {
        let batch = RayLanes {
            origin: self.origin,
            dir: V3::<L>::from_vecs(&self.rays.map(|r| r.dir)),
            t0: L::from_array(self.rays.map(|r| r.t0)),
            t1: L::from_array(self.rays.map(|r| r.t1)),
        };
        let p = self.p;
        let e = match self.shape {
            Shape::Sphere(f) => lanes::sphere_energy(p, &batch, f),
            Shape::Cylinder(f) => lanes::cylinder_energy(p, &batch, f),
            Shape::Capsule(f) => lanes::capsule_energy(p, &batch, f),
            Shape::Beam(f) => lanes::beam_energy(p, &batch, f),
        };
        e.to_array()
    }
}

fn capsule(m: Vec3f, d: Vec3f, length: f32) -> CapsuleField<f32> {
    CapsuleField { m, d: d.normalize_or(Vec3::X), length, alpha_s: 1.5, alpha_c: 1.5 }
}

fn shapes(rng: &mut Rng) -> Vec<Shape> {
    let m = rng.in_cube_f32(3.0);
    let d = rng.in_cube_f32(1.0).normalize_or(Vec3::X);
    let c = CapsuleField { m, d, length: rng.range_f32(0.5, 8.0), alpha_s: 1.2, alpha_c: 0.7 };
    vec![
        Shape::Sphere(SphereField { center: m, alpha: 2.0 }),
        Shape::Cylinder(CylinderField { point: m, dir: d, alpha: 0.8 }),
        Shape::Capsule(c),
        Shape::Beam(BeamField { capsule: c, head_alpha: 3.0, muzzle_alpha: 0.5 }),
    ]
}

/// A ray suiting the law: faithful `|Q| = 60` over `[0, g]`, inverse square a unit direction over
/// `[0, d]` or `[0, ∞)`.
fn ray_for(law: Falloff, dir: Vec3f, clip: Option<f32>) -> R {
    let n = dir.normalize_or(Vec3::Z);
    match law {
        Falloff::Faithful => R { dir: n * 60.0, t0: 0.0, t1: clip.map_or(1.0, |d| (d / 60.0).min(1.0)) },
        Falloff::InverseSquare => R { dir: n, t0: 0.0, t1: clip.unwrap_or(f32::INFINITY) },
    }
}

#[test]
fn random_rays_are_as_accurate_as_the_scalar_kernels() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut worst = 0.0f64;
    for _ in 0..300 {
        for law in [Falloff::Faithful, Falloff::InverseSquare] {
            let p = FieldParams { falloff: law, core_radius: rng.range_f32(0.0, 0.1) };
            let origin = rng.in_cube_f32(20.0);
            let rays: [R; LANES] = std::array::from_fn(|_| {
                let target = rng.in_cube_f32(6.0);
                let clip = if rng.unit_f32() < 0.3 { Some(rng.range_f32(1.0, 50.0)) } else { None };
                ray_for(law, target - origin, clip)
            });
            for shape in shapes(&mut rng) {
                for path in SimdPath::supported() {
                    let got = shape.lanes(path, &p, origin, &rays);
                    for (i, r) in rays.iter().enumerate() {
                        let s32 = shape.scalar(&p, origin, *r) as f64;
                        let s64 = shape.reference(&p, origin, *r);
                        let g = got[i] as f64;
                        assert!(g.is_finite() && g >= 0.0, "{path} {shape:?} {law:?} lane {i}: {g}");
                        // As accurate as the scalar f32 kernel, up to a few ulp of the value.
                        let bound = 4.0 * (s32 - s64).abs() + 2e-6 * s64.abs() + 1e-30;
                        assert!(
                            (g - s64).abs() <= bound,
                            "{path} {shape:?} {law:?} {r:?}: lanes {g}, f32 {s32}, f64 {s64}"
                        );
                        worst = worst.max((g - s32).abs() / s64.abs().max(1e-30));
                    }
                }
            }
        }
    }
    assert!(worst < 1e-4, "lanes and scalar f32 differ by {worst} relative");
}

/// Every lane equals the scalar kernel on the same ray (relative `tol`, or both saturated), is
/// finite and non-negative.
fn assert_matches_scalar(shape: &Shape, p: &FieldParams<f32>, origin: Vec3f, rays: &[R; LANES], tol: f32) {
    for path in SimdPath::supported() {
        let got = shape.lanes(path, p, origin, rays);
        for (i, r) in rays.iter().enumerate() {
            let s = shape.scalar(p, origin, *r);
            let g = got[i];
            assert!(g.is_finite() && g >= 0.0, "{path} {shape:?} {:?} lane {i} {r:?}: {g}", p.falloff);
            let diff = (g - s).abs();
            assert!(
                diff <= tol * s.abs().max(g.abs()) + 1e-30,
                "{path} {shape:?} {:?} lane {i} {r:?}: lanes {g}, scalar {s}",
                p.falloff
            );
        }
    }
}

#[test]
fn degenerate_rays_are_finite_and_match_the_scalar_kernels() {
    let eye = Vec3::new(-4.0, 3.0, 25.0);
    let m = Vec3::new(0.5, 1.0, -2.0);
    let d = Vec3::new(1.0, 0.0, 0.0);
    let to_m = m - eye;
    for law in [Falloff::Faithful, Falloff::InverseSquare] {
        for core in [0.0, 1e-4, 0.05] {
            let p = FieldParams { falloff: law, core_radius: core };
            let through = ray_for(law, to_m, None);
            let rays: [R; LANES] = [
                // Through the centre M, with a clip beyond it and before it.
                through,
                ray_for(law, to_m, Some(to_m.length() + 3.0)),
                ray_for(law, to_m, Some(to_m.length() * 0.5)),
                // Empty, NaN and reversed spans.
                R { t1: through.t0, ..through },
                R { t1: f32::NAN, ..through },
                R { t0: f32::NAN, ..through },
                // Far away and nearly parallel to the axis.
                ray_for(law, Vec3::new(1e6, 1.0, -3.0) - eye, None),
                ray_for(law, Vec3::new(1.0, 1e-7, 0.0), None),
            ];
            let sphere = Shape::Sphere(SphereField { center: m, alpha: 1.0 });
            let cyl = Shape::Cylinder(CylinderField { point: m, dir: d, alpha: 1.0 });
            let caps = Shape::Capsule(capsule(m, d, 4.0));
            let zero = Shape::Capsule(capsule(m, d, 0.0));
            let beam =
                Shape::Beam(BeamField { capsule: capsule(m, d, 4.0), head_alpha: 2.0, muzzle_alpha: 0.5 });
            for shape in [sphere, cyl, caps, zero, beam] {
                assert_matches_scalar(&shape, &p, eye, &rays, 2e-5);
            }
            // Along the axis (through both ends, s = 0 for the cylinder) from an eye on it, and
            // parallel to it; D·Q = 0 (the ray in a splitting plane) inside and outside the slab.
            let on_axis = m - d * 10.0;
            let along: [R; LANES] = std::array::from_fn(|i| {
                let clip = if i % 2 == 0 { None } else { Some(6.0 + i as f32) };
                ray_for(law, if i < 4 { d } else { -d }, clip)
            });
            for shape in [cyl, caps, zero, beam] {
                assert_matches_scalar(&shape, &p, on_axis, &along, 2e-5);
                assert_matches_scalar(&shape, &p, on_axis + Vec3::new(0.0, 0.3, 0.0), &along, 2e-5);
            }
            let across: [R; LANES] = std::array::from_fn(|i| {
                ray_for(law, Vec3::new(0.0, -1.0 + 0.3 * i as f32, -1.0), Some(20.0 + i as f32))
            });
            for origin in
                [m + Vec3::new(2.0, 3.0, 8.0), m + Vec3::new(-2.0, 3.0, 8.0), m + Vec3::new(6.0, 3.0, 8.0)]
            {
                for shape in [caps, zero, beam] {
                    assert_matches_scalar(&shape, &p, origin, &across, 2e-5);
                }
            }
        }
    }
}

#[test]
fn lanes_do_not_depend_on_their_neighbours() {
    // The same ray gives the same value in every lane, whatever the other lanes hold.
    let eye = Vec3::new(0.0, 6.0, 40.0);
    let beam = Shape::Beam(BeamField {
        capsule: capsule(Vec3::new(-10.0, 0.0, 0.0), Vec3::X, 20.0),
        head_alpha: 4.0,
        muzzle_alpha: 1.0,
    });
    for law in [Falloff::Faithful, Falloff::InverseSquare] {
        let p = FieldParams { falloff: law, core_radius: 0.0 };
        let probe = ray_for(law, Vec3::new(3.0, 0.2, 0.0) - eye, None);
        let odd = [
            R { t1: f32::NAN, ..probe },
            ray_for(law, Vec3::new(-10.0, 0.0, 0.0) - eye, None),
            ray_for(law, Vec3::X, None),
        ];
        for path in SimdPath::supported() {
            let alone = beam.lanes(path, &p, eye, &[probe; LANES])[0];
            for lane in 0..LANES {
                let rays: [R; LANES] =
                    std::array::from_fn(|i| if i == lane { probe } else { odd[i % odd.len()] });
                assert_eq!(beam.lanes(path, &p, eye, &rays)[lane], alone, "{path} {law:?} lane {lane}");
            }
        }
    }
}

#[test]
fn saturation_matches_the_scalar_rules() {
    use hadou_math::energy::{saturate, scaled};
    let xs = [0.0, -1.0, 1.5, f32::MAX, f32::INFINITY, f32::NAN, 1e-30, -0.0];
    let got = lanes::saturate(lanes::Lanes::from(xs)).to_array();
    for (x, g) in xs.iter().zip(got) {
        assert_eq!(g.to_bits(), saturate(*x).to_bits(), "saturate({x})");
    }
    for alpha in [0.0, 1.0, 1e30, 3.5] {
        let got = lanes::scaled(lanes::Lanes::from(xs), alpha).to_array();
        for (x, g) in xs.iter().zip(got) {
            assert_eq!(g.to_bits(), scaled(*x, alpha).to_bits(), "scaled({x}, {alpha})");
        }
    }
}

#[test]
fn every_supported_path_runs_and_names_itself() {
    let paths = SimdPath::supported();
    assert_eq!(paths[0], SimdPath::PORTABLE, "the portable path is always there");
    for path in &paths {
        assert_eq!(SimdPath::from_name(path.name()), Ok(*path));
    }
    assert_eq!(SimdPath::widest(), *paths.last().unwrap());
    #[cfg(target_arch = "x86_64")]
    {
        let avx2 = std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma");
        assert_eq!(paths.iter().any(|p| p.name() == "avx2"), avx2, "{paths:?}");
    }
    // A path the CPU lacks, or a name that is none, is refused with what the CPU runs.
    for name in ["avx2", "avx512"] {
        if !paths.iter().any(|p| p.name() == name) {
            let e = SimdPath::from_name(name).unwrap_err().to_string();
            assert!(e.contains("this CPU cannot run") && e.contains("portable"), "{e}");
        }
    }
    let e = SimdPath::from_name("avx9000").unwrap_err().to_string();
    assert!(e.contains("unknown vector path `avx9000`") && e.contains("avx512"), "{e}");
}

#[test]
fn lane_logarithm_and_atan2_follow_the_maths_library() {
    // The generic polynomials (what the AVX2 lanes use) against `f32::ln` / `f32::atan2`.
    struct Fns([f32; LANES], [f32; LANES]);
    impl WithLanes for Fns {
        type Output = ([f32; LANES], [f32; LANES]);
        #[inline(always)]
        fn run<L: Lane>(self) -> Self::Output {
            let (a, b) = (L::from_array(self.0), L::from_array(self.1));
            (a.ln().to_array(), a.atan2(b).to_array())
        }
    }
    let mut rng = Rng(7);
    let specials = [0.0, -0.0, 1.0, -1.0, f32::INFINITY, -f32::INFINITY, 1e-30, 3e30];
    for path in SimdPath::supported() {
        for round in 0..4000 {
            let xs: [f32; LANES] = std::array::from_fn(|_| {
                let e = rng.range_f32(-30.0, 30.0);
                rng.range_f32(1.0, 2.0) * 2f32.powf(e)
            });
            let ys: [f32; LANES] = std::array::from_fn(|i| {
                if round % 8 == 0 {
                    specials[(i + round / 8) % specials.len()]
                } else {
                    rng.range_f32(-1.0, 1.0) * 2f32.powf(rng.range_f32(-20.0, 20.0))
                }
            });
            let xs2: [f32; LANES] = std::array::from_fn(|i| {
                if round % 8 == 0 {
                    specials[(3 * i + round / 8) % specials.len()]
                } else {
                    rng.range_f32(-1.0, 1.0) * 2f32.powf(rng.range_f32(-20.0, 20.0))
                }
            });
            let (ln, _) = dispatch(path, Fns(xs, xs));
            for (x, g) in xs.iter().zip(ln) {
                let want = x.ln();
                assert!(
                    (g - want).abs() <= 2.0 * f32::EPSILON * want.abs().max(1.0),
                    "{path} ln({x}) = {g}, not {want}"
                );
            }
            let (_, at) = dispatch(path, Fns(ys, xs2));
            for i in 0..LANES {
                let (y, x) = (ys[i], xs2[i]);
                let want = y.atan2(x);
                let g = at[i];
                let close = g == want || (g - want).abs() <= 4.0 * f32::EPSILON * want.abs();
                assert!(close, "{path} atan2({y}, {x}) = {g}, not {want}");
            }
        }
    }
}
