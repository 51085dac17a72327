//! The thesis's faithful integrator (002 §3.4.4): composite Simpson over the ray parameter with a
//! fixed number of subintervals `m`, optionally reduced to `m/n` outside a bounding cylinder.
//!
//! Kept deliberately as printed, so that its banding (002 Figs. 4.15–4.17) can be reproduced and
//! compared: the exact curve is evaluated at every sample (002 eq. 3.17–3.21, with the
//! cross-section pairing of SPEC.md §1.4 and the round ends of eq. 3.24).

use super::local_ray::{CurveReal, LocalRay};
use super::prepare::PreparedCurve;
use super::wave::{Reduction, MAX_SIMPSON_M};
use crate::energy::{scaled, Falloff};

/// The exact density at ray parameter `t`, without `α`: `w(|P(t) − C(t)|)·(1 − t/t_far)^j`
/// (002 eq. 3.17, 3.23), `C(t)` the curve point paired with `P(t)` by cross-section, clamped to
/// the existing part `[0, k·s_end]` (eq. 3.24).
#[inline]
pub(crate) fn density<R: CurveReal>(c: &PreparedCurve, r: &LocalRay<R>, t: R) -> R {
    let p = r.at(t);
    let xc = p.x.clamp(R::ZERO, r.x_head);
    let s = (xc / R::from_f64(f64::from(c.wave.gamma))).min(R::from_f64(c.s_head));
    let cs = R::shape(c).eval(s);
    let (dx, dy, dz) = (p.x - xc, p.y - cs[0], p.z - cs[1]);
    let q = dx * dx + dy * dy + dz * dz + r.rc2;
    let w = match r.falloff {
        Falloff::Faithful => R::ONE / q.sqrt(),
        Falloff::InverseSquare => R::ONE / q,
    };
    w * r.attenuation(t)
}

/// Composite Simpson with `m` (even) subintervals over `[a, b]`: `(sum, evaluations)`.
#[inline]
fn composite<R: CurveReal>(c: &PreparedCurve, r: &LocalRay<R>, a: R, b: R, m: u32) -> (R, u32) {
    if !(b > a) {
        return (R::ZERO, 0);
    }
    let h = (b - a) / R::from_f64(f64::from(m));
    let mut odd = R::ZERO;
    let mut even = R::ZERO;
    for i in 1..m {
        let v = density(c, r, a + h * R::from_f64(f64::from(i)));
        if i % 2 == 1 {
            odd += v;
        } else {
            even += v;
        }
    }
    let four = R::from_f64(4.0);
    let sum = (density(c, r, a) + four * odd + R::TWO * even + density(c, r, b)) * h / R::from_f64(3.0);
    (sum, m + 1)
}

/// `m/n` rounded up to an even count of at least 2 (002 §3.4.4: outside the cylinder).
pub fn reduced_m(m: u32, n: u32) -> u32 {
    let k = (m / n.max(1)).max(2);
    k + (k & 1)
}

/// The faithful Simpson integrator over the resolved span of `r`, generic over the precision:
/// `(α·∫, evaluations)`.
///
/// The span `[t0, min(t1, t_far)]` (the thesis integrates from the eye to the far point, `u ∈
/// [0, 1]`, and here stops early at the visible surface) gets `m` subintervals. With a reduction,
/// the ray's entry and exit `u₁ < u₂` of the infinite cylinder of radius `R + ε` around the axis
/// (002 eq. 3.22) split it into three regions: inside `m`, each outside part `m/n`; without two
/// real roots the whole span uses `m/n`. Empty regions are skipped. Beyond the far point
/// (inverse square, no attenuation, `t1 > t_far`) the thesis has no rule; [`curve_energy`]
/// adds that tail by the default integrator and counts it.
///
/// [`curve_energy`]: super::curve_energy
pub(crate) fn simpson_generic<R: CurveReal>(
    c: &PreparedCurve,
    r: &LocalRay<R>,
    m: u32,
    reduction: Option<Reduction>,
) -> (R, u32) {
    let m = {
        let m = m.clamp(2, MAX_SIMPSON_M);
        m + (m & 1)
    };
    let te = r.t1.min(r.t_far);
    let mut sum = R::ZERO;
    let mut evals = 0;
    let mut add = |(s, e): (R, u32)| {
        sum += s;
        evals += e;
    };
    match reduction {
        None => add(composite(c, r, r.t0, te, m)),
        Some(red) => {
            let mo = reduced_m(m, red.n);
            let rad = R::from_f64(c.bound + f64::from(red.epsilon));
            // |P_⊥(u)|² = (R + ε)²: a u² + 2 b u + k = 0 (002 eq. 3.22).
            let a = r.q.y * r.q.y + r.q.z * r.q.z;
            let b = r.o.y * r.q.y + r.o.z * r.q.z;
            let k = r.o.y * r.o.y + r.o.z * r.o.z - rad * rad;
            let disc = b * b - a * k;
            if a > R::ZERO && disc > R::ZERO {
                let sq = disc.sqrt();
                let u1 = ((-b - sq) / a).clamp(r.t0, te);
                let u2 = ((-b + sq) / a).clamp(r.t0, te);
                add(composite(c, r, r.t0, u1, mo));
                add(composite(c, r, u1, u2, m));
                add(composite(c, r, u2, te, mo));
            } else {
                add(composite(c, r, r.t0, te, mo));
            }
        }
    }
    (scaled(sum, r.alpha), evals)
}
