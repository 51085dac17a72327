//! The `f32` render path on the rays of a 2048-wide image with a far plane at 1e4 (faithful law,
//! 002 eq. 3.8–3.11 with SPEC.md §1.2's stable forms): every pixel finite and within `1e-3` of the
//! `f64` value of the same inputs. The thesis's single-logarithm form
//! `ln((At₁ + B + sqrt(A·U(t₁))) / (At₀ + B + sqrt(A·U(t₀))))/sqrt(A)`, kept below as a test
//! helper, fails the same check: for rays passing close to a centre far ahead its denominator
//! cancels to nothing (or to exactly 0, giving infinity).

mod analytic_common;

use analytic_common::rel;
use hadou_math::energy::{
    beam_energy, sphere_energy, BeamField, CapsuleField, Falloff, FieldParams, Ray, SphereField,
};
use hadou_math::{Vec3, Vec3f};

const WIDTH: u32 = 2048;
const HEIGHT: u32 = 1152;
const FAR: f32 = 1e4;

/// The faithful ray of pixel `(px, py)`: eye at the origin looking down `−z` with a 60° horizontal
/// field of view, `Q` reaching the far plane `z = −FAR`.
fn pixel_ray(px: u32, py: u32) -> Ray<f32> {
    let half = (30.0f32).to_radians().tan();
    let x = ((px as f32 + 0.5) / WIDTH as f32 * 2.0 - 1.0) * half;
    let y = (1.0 - (py as f32 + 0.5) / HEIGHT as f32 * 2.0) * half * HEIGHT as f32 / WIDTH as f32;
    Ray { origin: Vec3::ZERO, dir: Vec3::new(x, y, -1.0) * FAR }
}

/// How one energy function fared on a set of pixels.
#[derive(Debug)]
struct RowStats {
    /// Largest relative error among finite results.
    worst: f64,
    /// Pixels off by more than `1e-3` or not finite.
    failures: usize,
    /// Pixels whose result was not finite.
    non_finite: usize,
    /// The first failure, described.
    first: Option<String>,
}

/// Checks one energy function on `rows` of the image against `reference`.
fn check_rows(
    energy: impl Fn(&Ray<f32>) -> f32,
    reference: impl Fn(&Ray<f64>) -> f64,
    rows: std::ops::Range<u32>,
) -> RowStats {
    let mut st = RowStats { worst: 0.0, failures: 0, non_finite: 0, first: None };
    for py in rows {
        for px in 0..WIDTH {
            let ray = pixel_ray(px, py);
            let e = energy(&ray);
            let r = reference(&Ray { origin: ray.origin.as_f64(), dir: ray.dir.as_f64() });
            let err = rel(f64::from(e), r);
            if !e.is_finite() {
                st.non_finite += 1;
            } else {
                st.worst = st.worst.max(err);
            }
            if !e.is_finite() || err > 1e-3 {
                st.failures += 1;
                st.first.get_or_insert_with(|| format!("pixel ({px}, {py}): {e:e} vs {r:e}"));
            }
        }
    }
    st
}

/// The thesis's form as one naive logarithm, without the mirrored branch (what not to do).
fn naive_single_log(p: &FieldParams<f32>, ray: &Ray<f32>, t0: f32, t1: f32, f: &SphereField<f32>) -> f32 {
    let w = ray.origin - f.center;
    let a = ray.dir.length_squared();
    let b = ray.dir.dot(w);
    let c = w.length_squared() + p.core_radius * p.core_radius;
    let u = |t: f32| a * t * t + 2.0 * b * t + c;
    let num = a * t1 + b + (a * u(t1)).sqrt();
    let den = a * t0 + b + (a * u(t0)).sqrt();
    f.alpha * (num / den).ln() / a.sqrt()
}

fn sphere_at(z: f32) -> SphereField<f32> {
    // Centred on the pixel grid's corner so no ray hits it exactly.
    SphereField { center: Vec3f::new(0.0, 0.0, z), alpha: 1.0 }
}

fn sphere64(s: &SphereField<f32>) -> SphereField<f64> {
    SphereField { center: s.center.as_f64(), alpha: f64::from(s.alpha) }
}

#[test]
fn stable_form_holds_on_a_wide_image_and_the_naive_form_does_not() {
    let rows = HEIGHT / 2 - 8..HEIGHT / 2 + 8;
    for core in [0.0f32, 1e-3] {
        let p = FieldParams { falloff: Falloff::Faithful, core_radius: core };
        let p64 = FieldParams { falloff: Falloff::Faithful, core_radius: f64::from(core) };
        for z in [-10.0f32, -200.0, -5000.0] {
            let s = sphere_at(z);
            let s64 = sphere64(&s);
            let reference = |r: &Ray<f64>| sphere_energy(&p64, r, 0.0, 1.0, &s64);
            let stable = check_rows(|r| sphere_energy(&p, r, 0.0, 1.0, &s), reference, rows.clone());
            assert_eq!(stable.failures, 0, "stable form, core {core}, sphere at z {z}: {stable:?}");
            println!("core {core}, sphere at z = {z}: stable worst rel err {:.1e}", stable.worst);
            let naive = check_rows(|r| naive_single_log(&p, r, 0.0, 1.0, &s), reference, rows.clone());
            assert!(naive.failures > 0, "the naive form passed, core {core}, z {z}: {naive:?}");
            println!(
                "  naive single log: {} of {} pixels fail ({} not finite), e.g. {}",
                naive.failures,
                rows.len() as u32 * WIDTH,
                naive.non_finite,
                naive.first.unwrap_or_default()
            );
        }
    }
}

#[test]
fn naive_form_is_fine_in_f64_so_the_failure_is_f32_cancellation() {
    // The same formula in f64 agrees with the stable form on the same rays: the f32 failure above
    // is the cancellation of At₀ + B + sqrt(A·U(t₀)), not a wrong formula.
    let s = sphere_at(-10.0);
    let s64 = sphere64(&s);
    let p64 = FieldParams { falloff: Falloff::Faithful, core_radius: 0.0 };
    for px in (0..WIDTH).step_by(7) {
        let ray = pixel_ray(px, HEIGHT / 2);
        let r64 = Ray { origin: ray.origin.as_f64(), dir: ray.dir.as_f64() };
        let w = r64.origin - s64.center;
        let (a, b, c) = (r64.dir.length_squared(), r64.dir.dot(w), w.length_squared());
        let u = |t: f64| a * t * t + 2.0 * b * t + c;
        let naive = ((a + b + (a * u(1.0)).sqrt()) / (b + (a * u(0.0)).sqrt())).ln() / a.sqrt();
        let stable = sphere_energy(&p64, &r64, 0.0, 1.0, &s64);
        assert!(rel(naive, stable) < 1e-6, "pixel {px}: {naive} vs {stable}");
    }
}

#[test]
fn beam_across_a_wide_image_is_finite_and_accurate_in_f32() {
    // A beam crossing the view 10 units ahead, muzzle left of centre, head right of it.
    let beam = BeamField {
        capsule: CapsuleField {
            m: Vec3f::new(-3.0, 0.0, -10.0),
            d: Vec3f::new(0.96, 0.0, -0.28),
            length: 6.0,
            alpha_s: 0.5,
            alpha_c: 0.5,
        },
        head_alpha: 1.5,
        muzzle_alpha: 0.7,
    };
    let c = beam.capsule;
    let beam64 = BeamField {
        capsule: CapsuleField {
            m: c.m.as_f64(),
            d: c.d.as_f64(),
            length: f64::from(c.length),
            alpha_s: f64::from(c.alpha_s),
            alpha_c: f64::from(c.alpha_c),
        },
        head_alpha: f64::from(beam.head_alpha),
        muzzle_alpha: f64::from(beam.muzzle_alpha),
    };
    for core in [1e-3f32, 0.05] {
        let p = FieldParams { falloff: Falloff::Faithful, core_radius: core };
        let p64 = FieldParams { falloff: Falloff::Faithful, core_radius: f64::from(core) };
        let st = check_rows(
            |r| beam_energy(&p, r, 0.0, 1.0, &beam),
            |r| beam_energy(&p64, r, 0.0, 1.0, &beam64),
            HEIGHT / 2 - 3..HEIGHT / 2 + 3,
        );
        assert_eq!(st.failures, 0, "core {core}: {st:?}");
        println!("beam, core {core}: worst rel err {:.1e}", st.worst);
    }
}
