//! The per-ray entry points [`curve_energy`] and [`curve_energy_f64`]: the ray's span is resolved
//! in the curve's frame once ([`LocalRay::new`]) and integrated by the wave's [`Integrator`] —
//! the thesis's Simpson rule (`simpson.rs`) or hadou's default integrator (`integrate.rs`), which
//! do not depend on each other (002 §3.4).

use super::integrate::{default_generic, CurveSample, DEFAULT_SETTINGS};
use super::local_ray::{CurveReal, LocalRay};
use super::nearest::nearest_generic;
use super::prepare::PreparedCurve;
use super::simpson::simpson_generic;
use super::wave::Integrator;
use crate::energy::{saturate, FieldParams, Ray};

/// The energy of one ray through a prepared curve, by the wave's integrator (002 §3.4).
///
/// `ray`, `t0`, `t1`, `t_far` come from the scene's wave-ray construction: for
/// [`Falloff::Faithful`] `ray.dir = Q = E − S` and `t_far = 1`; for [`Falloff::InverseSquare`]
/// `ray.dir` is a unit vector, `t_far` the far point's distance, and `t1` may be `+∞`.
/// `[t0, t1]` is the span clipped at the visible surface (002 §3.3.5). Non-finite or empty input
/// gives 0; the result is always finite.
///
/// [`Falloff::Faithful`]: crate::energy::Falloff::Faithful
/// [`Falloff::InverseSquare`]: crate::energy::Falloff::InverseSquare
pub fn curve_energy(
    c: &PreparedCurve,
    p: &FieldParams<f32>,
    ray: &Ray<f32>,
    t0: f32,
    t1: f32,
    t_far: f32,
) -> CurveSample {
    let (e, n) = curve_energy_generic(c, p, ray, t0, t1, t_far);
    CurveSample { energy: e, evaluations: n }
}

/// [`curve_energy`] in `f64`: the same algorithm, for tests that separate its own error from
/// `f32` rounding.
pub fn curve_energy_f64(
    c: &PreparedCurve,
    p: &FieldParams<f64>,
    ray: &Ray<f64>,
    t0: f64,
    t1: f64,
    t_far: f64,
) -> (f64, u32) {
    curve_energy_generic(c, p, ray, t0, t1, t_far)
}

/// The wave's integrator over the resolved span, generic over the precision: `(α·∫, evaluations)`,
/// `(0, 0)` for an empty span or input that is not finite.
///
/// [`Integrator::Simpson`] covers the span up to the far point; beyond it (inverse square without
/// attenuation, `t1 > t_far`) the thesis has no rule, so the default integrator adds that tail
/// and its evaluations are counted.
fn curve_energy_generic<R: CurveReal>(
    c: &PreparedCurve,
    p: &FieldParams<R>,
    ray: &Ray<R>,
    t0: R,
    t1: R,
    t_far: R,
) -> (R, u32) {
    let Some(r) = LocalRay::new(c, p, ray, t0, t1, t_far) else {
        return (R::ZERO, 0);
    };
    match c.wave.integrator {
        Integrator::Simpson { m, reduction } => {
            let (e, n) = simpson_generic(c, &r, m, reduction);
            if r.t1 > r.t_far {
                // The same resolved ray from the far point on.
                let (tail, tail_n) = default_generic(c, &LocalRay { t0: r.t_far, ..r }, &DEFAULT_SETTINGS);
                return (saturate(e + tail), n + tail_n);
            }
            (e, n)
        }
        Integrator::Default => default_generic(c, &r, &DEFAULT_SETTINGS),
        Integrator::Nearest => nearest_generic(c, &r),
    }
}
