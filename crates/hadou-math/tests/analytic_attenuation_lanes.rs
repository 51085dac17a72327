//! The attenuated eight-lane kernels (`hadou_math::energy::lanes::*_attenuated`, 002 eq. 3.23,
//! SPEC.md §1.4) against the scalar `f32` march (`hadou_math::energy::*_attenuated`): every shape
//! in both laws, for `j` = 0.5, 2, 2.7, 8, 16 and 64, on random rays (each lane with its own far
//! point) and degenerate ones (through a centre with `r_c` = 0 and tiny, along an axis, spans
//! beyond the far point, empty and NaN spans, far points at the span's start, huge, infinite,
//! zero or negative). Each lane matches the scalar value within [`REL`] relative plus [`FLOOR`]
//! times the unattenuated energy (the pixel's energy without attenuation: what a difference is
//! seen against), is finite and non-negative, and does not depend on its neighbours; `j = 0` is
//! the unattenuated lane kernels bit for bit. Every test runs on each vector path the machine
//! supports (`SimdPath::supported`).

use hadou_math::energy::lanes::{self, AttenuationLanes, RayLanes, LANES, V3};
use hadou_math::energy::{
    beam_energy, beam_energy_attenuated, capsule_energy, capsule_energy_attenuated, cylinder_energy,
    cylinder_energy_attenuated, sphere_energy, sphere_energy_attenuated, Attenuation, BeamField,
    CapsuleField, CylinderField, Falloff, FieldParams, Ray, SphereField,
};
use hadou_math::rng::Rng;
use hadou_math::simd::{dispatch, Lane, SimdPath, WithLanes};
use hadou_math::{Vec3, Vec3f};

/// Largest relative difference between a lane and the scalar march: the lanes' `exp(j·ln h)`,
/// logarithm and `atan2` differ from the maths library's by a few ulp (about `10⁻⁷·j·|ln h|`
/// for the powers), and a lane may stop one cell before or after the scalar march (each stop
/// leaves out at most [`hadou_math::energy::REST_TOLERANCE`] = `10⁻⁵` of the sum).
const REL: f64 = 1e-4;

/// Absolute allowance, as a fraction of the lane's unattenuated energy.
const FLOOR: f64 = 1e-9;

/// Exponents: integers up to `INTEGER_J_MAX` (powers by squaring) and others (`exp(j·ln h)`).
const JS: [f32; 7] = [0.5, 2.0, 2.7, 8.0, 16.0, 64.0, 96.0];
const LAWS: [Falloff; 2] = [Falloff::Faithful, Falloff::InverseSquare];

/// One ray of a batch: direction, span and far point (the origin is the batch's).
#[derive(Clone, Copy, Debug)]
struct R {
    dir: Vec3f,
    t0: f32,
    t1: f32,
    t_far: f32,
}

#[derive(Clone, Copy, Debug)]
enum Shape {
    Sphere(SphereField<f32>),
    Cylinder(CylinderField<f32>),
    Capsule(CapsuleField<f32>),
    Beam(BeamField<f32>),
}

impl Shape {
    /// The scalar march (`j = 0`: the closed form).
    fn scalar(&self, p: &FieldParams<f32>, origin: Vec3f, r: R, j: f32) -> f32 {
        let ray = Ray { origin, dir: r.dir };
        let att = Attenuation { j, t_far: r.t_far };
        match self {
            Shape::Sphere(f) => sphere_energy_attenuated(p, &ray, r.t0, r.t1, &att, f),
            Shape::Cylinder(f) => cylinder_energy_attenuated(p, &ray, r.t0, r.t1, &att, f),
            Shape::Capsule(f) => capsule_energy_attenuated(p, &ray, r.t0, r.t1, &att, f),
            Shape::Beam(f) => beam_energy_attenuated(p, &ray, r.t0, r.t1, &att, f),
        }
    }

    /// The unattenuated scalar closed form.
    fn plain(&self, p: &FieldParams<f32>, origin: Vec3f, r: R) -> f32 {
        let ray = Ray { origin, dir: r.dir };
        match self {
            Shape::Sphere(f) => sphere_energy(p, &ray, r.t0, r.t1, f),
            Shape::Cylinder(f) => cylinder_energy(p, &ray, r.t0, r.t1, f),
            Shape::Capsule(f) => capsule_energy(p, &ray, r.t0, r.t1, f),
            Shape::Beam(f) => beam_energy(p, &ray, r.t0, r.t1, f),
        }
    }

    /// The attenuated lane kernel (`attenuated`) or the unattenuated one on `path`.
    fn lanes(
        &self,
        path: SimdPath,
        p: &FieldParams<f32>,
        origin: Vec3f,
        rays: &[R; LANES],
        j: f32,
        attenuated: bool,
    ) -> [f32; LANES] {
        dispatch(path, Kernel { shape: self, p, origin, rays, j, attenuated })
    }
}

/// One shape's kernel on eight rays, on a path's lanes.
struct Kernel<'a> {
    shape: &'a Shape,
    p: &'a FieldParams<f32>,
    origin: Vec3f,
    rays: &'a [R; LANES],
    j: f32,
    attenuated: bool,
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
        let att = AttenuationLanes::new(self.j, L::from_array(self.rays.map(|r| r.t_far)));
        let p = self.p;
        let e = if self.attenuated {
            match self.shape {
                Shape::Sphere(f) => lanes::sphere_energy_attenuated(p, &batch, &att, f),
                Shape::Cylinder(f) => lanes::cylinder_energy_attenuated(p, &batch, &att, f),
                Shape::Capsule(f) => lanes::capsule_energy_attenuated(p, &batch, &att, f),
                Shape::Beam(f) => lanes::beam_energy_attenuated(p, &batch, &att, f),
            }
        } else {
            match self.shape {
                Shape::Sphere(f) => lanes::sphere_energy(p, &batch, f),
                Shape::Cylinder(f) => lanes::cylinder_energy(p, &batch, f),
                Shape::Capsule(f) => lanes::capsule_energy(p, &batch, f),
                Shape::Beam(f) => lanes::beam_energy(p, &batch, f),
            }
        };
        e.to_array()
    }
}

/// The largest difference seen, relative to `max(scalar, FLOOR·unattenuated)`.
#[derive(Default)]
struct Worst {
    rel: f64,
    checked: usize,
}

/// Every lane against the scalar march on every path: finite, non-negative, within
/// `REL·|scalar| + FLOOR·unattenuated`.
fn check(shape: &Shape, p: &FieldParams<f32>, origin: Vec3f, rays: &[R; LANES], j: f32, worst: &mut Worst) {
    for path in SimdPath::supported() {
        let got = shape.lanes(path, p, origin, rays, j, true);
        for (i, r) in rays.iter().enumerate() {
            let s = f64::from(shape.scalar(p, origin, *r, j));
            let e0 = f64::from(shape.plain(p, origin, *r));
            let g = f64::from(got[i]);
            let law = p.falloff;
            assert!(g.is_finite() && g >= 0.0, "{path} {shape:?} {law:?} j {j} lane {i} {r:?}: {g}");
            let diff = (g - s).abs();
            let tol = REL * s + FLOOR * e0 + 1e-30;
            assert!(
                diff <= tol,
                "{path} {shape:?} {law:?} core {} j {j} lane {i} {r:?} from {origin:?}: lanes {g:e}, \
                 scalar {s:e} (rel {:e}), unattenuated {e0:e}",
                p.core_radius,
                diff / s
            );
            worst.rel = worst.rel.max(diff / s.max(FLOOR * e0).max(1e-30));
            worst.checked += 1;
        }
    }
}

/// Every lane finite and in `[0, unattenuated]` (up to rounding) on every path.
fn check_bounded(shape: &Shape, p: &FieldParams<f32>, origin: Vec3f, rays: &[R; LANES], j: f32) {
    for path in SimdPath::supported() {
        let got = shape.lanes(path, p, origin, rays, j, true);
        for (i, r) in rays.iter().enumerate() {
            let e0 = shape.plain(p, origin, *r);
            let g = got[i];
            assert!(
                g.is_finite() && g >= 0.0 && g <= e0 * (1.0 + 1e-5),
                "{path} {shape:?} {:?} j {j} lane {i} {r:?}: {g}, unattenuated {e0}",
                p.falloff
            );
        }
    }
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

/// A ray suiting the law, as the CPU backend makes them: faithful `Q = 60·n` over `[0, g]`,
/// `g = min(clip/60, 1)`, `t_far = 1`; inverse square a unit direction over `[0, clip]` or
/// `[0, ∞)` with the far point at `far`.
fn ray_for(law: Falloff, dir: Vec3f, clip: Option<f32>, far: f32) -> R {
    let n = dir.normalize_or(Vec3::Z);
    match law {
        Falloff::Faithful => {
            R { dir: n * 60.0, t0: 0.0, t1: clip.map_or(1.0, |d| (d / 60.0).min(1.0)), t_far: 1.0 }
        }
        Falloff::InverseSquare => R { dir: n, t0: 0.0, t1: clip.unwrap_or(f32::INFINITY), t_far: far },
    }
}

#[test]
fn random_rays_match_the_scalar_march() {
    let mut rng = Rng(0x5eed_a77e);
    let mut worst = Worst::default();
    for _ in 0..60 {
        for law in LAWS {
            let p = FieldParams { falloff: law, core_radius: rng.range_f32(0.0, 0.1) };
            let origin = rng.in_cube_f32(20.0);
            let rays: [R; LANES] = std::array::from_fn(|_| {
                let target = rng.in_cube_f32(6.0);
                let clip = if rng.unit_f32() < 0.3 { Some(rng.range_f32(1.0, 50.0)) } else { None };
                // Far points around the target's distance (the grading meets the peak there),
                // well beyond it, or short of it.
                let dist = (target - origin).length();
                let far = match rng.below(3) {
                    0 => dist * rng.range_f32(0.9, 1.5),
                    1 => rng.log_range(1.0, 1e4) as f32,
                    _ => rng.range_f32(0.5, 60.0),
                };
                ray_for(law, target - origin, clip, far)
            });
            for shape in shapes(&mut rng) {
                for j in JS {
                    check(&shape, &p, origin, &rays, j, &mut worst);
                }
            }
        }
    }
    println!("random rays: {} lanes, worst relative difference {:.2e}", worst.checked, worst.rel);
}

#[test]
fn degenerate_rays_match_the_scalar_march() {
    let eye = Vec3::new(-4.0, 3.0, 25.0);
    let m = Vec3::new(0.5, 1.0, -2.0);
    let d = Vec3::X;
    let to_m = m - eye;
    let dist = to_m.length();
    let capsule = |length: f32| CapsuleField { m, d, length, alpha_s: 1.5, alpha_c: 1.5 };
    let mut worst = Worst::default();
    for law in LAWS {
        for core in [0.0, 1e-6, 1e-3, 0.05] {
            let p = FieldParams { falloff: law, core_radius: core };
            let through = ray_for(law, to_m, None, dist * 1.2);
            let rays: [R; LANES] = [
                // Through the centre M, the far point just past it, at it and far beyond.
                through,
                R { t_far: dist, ..through },
                R { t_far: 1e30, ..through },
                // The span beyond the far point, starting at it, empty, NaN.
                R { t0: 0.7, t1: 0.9, t_far: 0.5, ..through },
                R { t0: through.t_far, ..through },
                R { t1: f32::NAN, ..through },
                // Far away, and clipped short of the centre.
                ray_for(law, Vec3::new(1e6, 1.0, -3.0) - eye, None, 40.0),
                ray_for(law, to_m, Some(dist * 0.3), 45.0),
            ];
            // Odd far points: zero, negative, infinite, NaN, a clip beyond a short far point.
            let odd: [R; LANES] = [
                R { t_far: 0.0, ..through },
                R { t_far: -3.0, ..through },
                R { t_far: f32::INFINITY, ..through },
                R { t_far: f32::NAN, ..through },
                ray_for(law, to_m, Some(dist + 3.0), dist * 0.5),
                ray_for(law, to_m, Some(dist * 0.5), dist * 2.0),
                R { t0: f32::NAN, ..through },
                R { t0: -1e13, ..through },
            ];
            let sphere = Shape::Sphere(SphereField { center: m, alpha: 1.0 });
            let cyl = Shape::Cylinder(CylinderField { point: m, dir: d, alpha: 1.0 });
            let caps = Shape::Capsule(capsule(4.0));
            let zero = Shape::Capsule(capsule(0.0));
            let beam = Shape::Beam(BeamField { capsule: capsule(4.0), head_alpha: 2.0, muzzle_alpha: 0.5 });
            for shape in [sphere, cyl, caps, zero, beam] {
                for j in JS {
                    check(&shape, &p, eye, &rays, j, &mut worst);
                    check(&shape, &p, eye, &odd, j, &mut worst);
                }
            }
            // Nearly parallel to the cylinder's axis: the peak's inner cell is far wider than the
            // span, which then lies within a few ulp of ψ or θ, so the scalar march's nodes
            // (t from sinh ψ or tan θ, divided by a tiny s) are rounding noise and so are the
            // lanes'; both are only held to [0, unattenuated].
            let parallel: [R; LANES] = std::array::from_fn(|i| {
                let tilt = [1e-7, 1e-6, 1e-5, 1e-4][i % 4];
                ray_for(law, Vec3::new(1.0, tilt, 0.0), Some(30.0 + i as f32), 45.0)
            });
            for j in JS {
                check_bounded(&cyl, &p, eye, &parallel, j);
            }
            // Along the axis from an eye on it (the cylinder's s = 0), and parallel to it.
            let on_axis = m - d * 10.0;
            let along: [R; LANES] = std::array::from_fn(|i| {
                let clip = if i % 2 == 0 { None } else { Some(6.0 + i as f32) };
                ray_for(law, if i < 4 { d } else { -d }, clip, 8.0 + 3.0 * i as f32)
            });
            for shape in [cyl, caps, zero, beam] {
                for j in JS {
                    check(&shape, &p, on_axis, &along, j, &mut worst);
                    check(&shape, &p, on_axis + Vec3::new(0.0, 0.3, 0.0), &along, j, &mut worst);
                }
            }
        }
    }
    println!("degenerate rays: {} lanes, worst relative difference {:.2e}", worst.checked, worst.rel);
}

#[test]
fn zero_exponent_is_the_unattenuated_lane_kernels_bit_for_bit() {
    let mut rng = Rng(41);
    for _ in 0..40 {
        for law in LAWS {
            let p = FieldParams { falloff: law, core_radius: rng.range_f32(0.0, 0.1) };
            let origin = rng.in_cube_f32(20.0);
            let rays: [R; LANES] = std::array::from_fn(|_| {
                let far = rng.range_f32(0.5, 60.0);
                ray_for(law, rng.in_cube_f32(6.0) - origin, None, far)
            });
            for shape in shapes(&mut rng) {
                for path in SimdPath::supported() {
                    let plain = shape.lanes(path, &p, origin, &rays, 0.0, false);
                    for j in [0.0, -0.0, f32::NAN] {
                        let got = shape.lanes(path, &p, origin, &rays, j, true);
                        assert_eq!(
                            got.map(f32::to_bits),
                            plain.map(f32::to_bits),
                            "{path} {shape:?} {law:?} j {j}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn lanes_do_not_depend_on_their_neighbours() {
    // The same ray gives the same value in every lane, whatever the other lanes hold (a lane
    // that needs many cells, NaN spans, the far point before the span).
    let eye = Vec3::new(0.0, 6.0, 40.0);
    let c =
        CapsuleField { m: Vec3::new(-10.0, 0.0, 0.0), d: Vec3::X, length: 20.0, alpha_s: 2.0, alpha_c: 2.0 };
    let beam = Shape::Beam(BeamField { capsule: c, head_alpha: 4.0, muzzle_alpha: 1.0 });
    for law in LAWS {
        let p = FieldParams { falloff: law, core_radius: 0.0 };
        let probe = ray_for(law, Vec3::new(3.0, 0.2, 0.0) - eye, None, 45.0);
        let odd = [
            R { t1: f32::NAN, ..probe },
            ray_for(law, Vec3::new(-10.0, 0.0, 0.0) - eye, None, 50.0),
            R { t0: 2.0, t_far: 1.0, ..probe },
        ];
        for path in SimdPath::supported() {
            for j in [0.5, 8.0] {
                let alone = beam.lanes(path, &p, eye, &[probe; LANES], j, true)[0];
                for lane in 0..LANES {
                    let rays: [R; LANES] =
                        std::array::from_fn(|i| if i == lane { probe } else { odd[i % odd.len()] });
                    let got = beam.lanes(path, &p, eye, &rays, j, true)[lane];
                    assert_eq!(got.to_bits(), alone.to_bits(), "{path} {law:?} j {j} lane {lane}");
                }
            }
        }
    }
}

#[test]
fn huge_strengths_saturate_and_stay_finite() {
    // α near f32::MAX on rays through a centre with r_c = 0: saturated, never ∞ or NaN.
    let eye = Vec3::new(0.0, 0.0, 10.0);
    let m = Vec3::ZERO;
    let c = CapsuleField { m, d: Vec3::X, length: 3.0, alpha_s: 3e38, alpha_c: 3e38 };
    let shapes = [
        Shape::Sphere(SphereField { center: m, alpha: 3e38 }),
        Shape::Cylinder(CylinderField { point: m, dir: Vec3::Y, alpha: 3e38 }),
        Shape::Capsule(c),
        Shape::Beam(BeamField { capsule: c, head_alpha: 3e38, muzzle_alpha: 3e38 }),
    ];
    let mut worst = Worst::default();
    for law in LAWS {
        let p = FieldParams { falloff: law, core_radius: 0.0 };
        let rays: [R; LANES] = std::array::from_fn(|i| {
            ray_for(law, m - eye + Vec3::new(1e-3 * i as f32, 0.0, 0.0), None, 10.0 + i as f32)
        });
        for shape in &shapes {
            for j in JS {
                check(shape, &p, eye, &rays, j, &mut worst);
            }
        }
    }
}
