//! The one integral every analytic shape reduces to: `∫ dt / (Y² + H)^{1/2}` (faithful) or
//! `∫ dt / (Y² + H)` (inverse square) with `Y(t) = s·t + β` — see the module docs of
//! [`crate::energy`] for the derivation and why each form is the stable one.

use super::field::Falloff;
use crate::{Real, Vec3};

/// Floor on `H` (a squared length): keeps rays exactly through a centre or along an axis with
/// `r_c = 0` finite. The same value in `f32` and `f64`; `max(H, H_FLOOR)` is continuous.
pub const H_FLOOR: f64 = 1e-24;

/// Largest value one closed-form piece returns (reached only where the true integral diverges or
/// exceeds it: a ray along an infinite cylinder's axis to infinity, a ray through a centre with
/// `r_c = 0`). Several pieces times any sane `α` stay finite in `f32`.
pub const ENERGY_MAX: f64 = 1e30;

/// The largest energy any function of this crate returns, in either precision: `f32::MAX`
/// (SPEC.md §1.1 leaves overflow open; hadou saturates). An energy whose true value exceeds it —
/// `α·I` overflowing `f32` on a ray through a centre or along an axis with a huge `α` — is
/// reported as this value, so the pixel renders at full brightness, never as 0.
pub const ENERGY_SATURATION: f64 = f32::MAX as f64;

/// `x` saturated to `[0, f32::MAX]` ([`ENERGY_SATURATION`]): `+∞` and values above become
/// `f32::MAX`, negative values 0. A NaN can only come from an overflow here (every formula is a
/// sum of non-negative, finite-capped pieces times `α ≥ 0`, see [`scaled`]), so it saturates too.
#[inline(always)]
pub fn saturate<R: Real>(x: R) -> R {
    let max = R::from_f64(ENERGY_SATURATION);
    if x >= R::ZERO {
        x.min(max)
    } else if x < R::ZERO {
        R::ZERO
    } else {
        max
    }
}

/// `α·I` saturated ([`saturate`]): `I` is first saturated, so it is finite and `α = 0` gives 0,
/// never `0·∞ = NaN` ("no contribution" stays 0); an overflowing product gives `f32::MAX`.
#[inline(always)]
pub fn scaled<R: Real>(integral: R, alpha: R) -> R {
    saturate(saturate(integral) * alpha)
}

/// `|t|` from which an end of the interval counts as infinite: [`Falloff::InverseSquare`]
/// integrates to infinity in closed form (the tail beyond is below `10⁻¹²/s²` absolute),
/// [`Falloff::Faithful`] clamps there (its `1/r` integral diverges at infinity). Keeps `Y²` finite
/// in `f32`.
pub const T_LIMIT: f64 = 1e12;

/// A unit direction `û = u/|u|` and `s = |u|`, or `s = 0`, `û = 0` where `|u|²` is not a
/// positive normal number (the ray is parallel to a cylinder's axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayAxis<R> {
    /// `s = |u|`.
    pub s: R,
    /// `û = u/|u|` (zero when `s = 0`).
    pub unit: Vec3<R>,
}

impl<R: Real> RayAxis<R> {
    /// Splits `u` into length and direction.
    #[inline(always)]
    pub fn new(u: Vec3<R>) -> Self {
        let a = u.length_squared();
        if a >= R::MIN_POSITIVE {
            let s = a.sqrt();
            Self { s, unit: u * (R::ONE / s) }
        } else {
            Self { s: R::ZERO, unit: Vec3::ZERO }
        }
    }
}

/// The regularised squared distance along a ray in completed-square form:
/// `|v + t·u|² + r_c² = Y(t)² + H`, `Y(t) = s·t + β`, `s = |u|`, `β = û·v`, `H = |û × v|² + r_c²`.
///
/// With `u = Q`, `v = S − M` this is the sphere's `U(t) + r_c²` (002 eq. 3.6, `A = s²`,
/// `B = sβ`, `AC − B² = s²H`); with `u = Q × D`, `v = (S − M) × D` the cylinder's
/// `W(t) + r_c²` (002 eq. 3.7, `D' = s²`). `H` comes from a cross product, never from
/// `AC − B²`, so it does not cancel (SPEC.md §1.2 numerics).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayQuadratic<R> {
    /// `s = |u| ≥ 0` (`√A`, or `√D'` for a cylinder).
    pub s: R,
    /// `β = û·v` (`B/√A`).
    pub beta: R,
    /// `H = |û × v|² + r_c² ≥ H_FLOOR` (`(AC − B²)/A`: the squared closest distance plus `r_c²`).
    pub h: R,
}

impl<R: Real> RayQuadratic<R> {
    /// The quadratic of `|v + t·u|² + rc2` for `u` already split into `axis`.
    #[inline(always)]
    pub fn new(axis: &RayAxis<R>, v: Vec3<R>, rc2: R) -> Self {
        let beta = axis.unit.dot(v);
        // s = 0: Y ≡ β = 0 and H must be the whole |v|².
        let d2 = if axis.s > R::ZERO { axis.unit.cross(v).length_squared() } else { v.length_squared() };
        Self { s: axis.s, beta, h: (d2 + rc2).max(R::from_f64(H_FLOOR)) }
    }

    /// `∫_{t0}^{t1} dt / sqrt(Y² + H)`: 002 eq. 3.8–3.9 with SPEC.md §1.2's corrected
    /// antiderivative `asinh((At + B)/sqrt(AC − B²))/sqrt(A)`, evaluated as one logarithm
    /// (`ln(1 + z)`, or `ln_1p(z)` below `z = 1/16`) and one division.
    ///
    /// With `P(Y) = Y + sqrt(Y² + H)` the difference of `asinh`s is `ln(P₁/P₀)`; `P₁/P₀ − 1` is
    /// formed as `s·Δt·(1 + (Y₀+Y₁)/(R₀+R₁))/P₀` (`R = sqrt(Y² + H)`), which has no cancellation
    /// when `Y₀ + Y₁ ≥ 0` if `P₀` is taken as `H/(R₀ − Y₀)` for `Y₀ < 0`. When `Y₀ + Y₁ < 0` the
    /// mirrored branch `asinh(x) = −asinh(−x)` gives `s·Δt·(1 − (Y₀+Y₁)/(R₀+R₁))/N₁` with
    /// `N₁ = R₁ − Y₁` (or `H/(R₁ + Y₁)` for `Y₁ > 0`). As `s → 0` the value tends to
    /// `Δt/sqrt(Y² + H)` without dividing by `s`. Ends are clamped to `±T_LIMIT`; empty or NaN
    /// intervals give 0.
    ///
    /// Mirrored eight rays at a time by `lanes::Quad::faithful` (keep in sync).
    #[inline(always)]
    pub fn faithful(&self, t0: R, t1: R) -> R {
        let nonempty = t1 > t0; // false for NaN ends too
        if !nonempty {
            return R::ZERO;
        }
        let lim = R::from_f64(T_LIMIT);
        let t0 = t0.max(-lim);
        let t1 = t1.min(lim);
        if t1 <= t0 {
            return R::ZERO;
        }
        let (s, h) = (self.s, self.h);
        let dt = t1 - t0;
        let y0 = s * t0 + self.beta;
        let y1 = s * t1 + self.beta;
        let r0 = (y0 * y0 + h).sqrt();
        let r1 = (y1 * y1 + h).sqrt();
        let sum = y0 + y1;
        let rs = r0 + r1;
        // k = Δt·(1 ± q)/P with q = sum/rs, as one division: P₀ = y₀ + r₀ = H/(r₀ − y₀),
        // N₁ = r₁ − y₁ = H/(r₁ + y₁).
        let (num, a, b) = if sum >= R::ZERO {
            let (a, b) = if y0 >= R::ZERO { (R::ONE, y0 + r0) } else { (r0 - y0, h) };
            (rs + sum, a, b)
        } else {
            let (a, b) = if y1 <= R::ZERO { (R::ONE, r1 - y1) } else { (r1 + y1, h) };
            (rs - sum, a, b)
        };
        let k = dt * num * a / (rs * b);
        let z = s * k;
        // ln(1 + z) loses nothing that matters once z ≥ 1/16 (absolute error ε against a value
        // ≥ 0.06) and is cheaper than ln_1p.
        let v = if z >= R::from_f64(0.0625) {
            (R::ONE + z).ln() / s
        } else if z > R::EPSILON {
            z.ln_1p() / s
        } else {
            k
        };
        v.max(R::ZERO).min(R::from_f64(ENERGY_MAX))
    }

    /// `∫_{t0}^{t1} dt / (Y² + H)` (hadou's inverse-square law; the analogue of 002 eq. 3.8 with
    /// antiderivative `atan(Y/√H)/(s√H)`), as one `atan2`.
    ///
    /// `atan(Y₁/√H) − atan(Y₀/√H) = atan2(√H·s·Δt, H + Y₀Y₁)`, exact for every sign pattern because
    /// the difference lies in `[0, π)` and the first argument is never negative; neither argument
    /// cancels badly (`H + Y₀Y₁` cancels only where the angle is near `π/2`, where `atan2` is
    /// insensitive to it). When the angle is below `ε` the value is `Δt/(H + Y₀Y₁)`, the `s → 0`
    /// limit, with no division by `s`. `t1 ≥ T_LIMIT` means `+∞` (angle `atan2(√H, Y₀)`),
    /// `t0 ≤ −T_LIMIT` means `−∞`.
    ///
    /// Mirrored eight rays at a time by `lanes::Quad::inverse_square` (keep in sync).
    #[inline(always)]
    pub fn inverse_square(&self, t0: R, t1: R) -> R {
        let nonempty = t1 > t0; // false for NaN ends too
        if !nonempty {
            return R::ZERO;
        }
        let lim = R::from_f64(T_LIMIT);
        let (s, h) = (self.s, self.h);
        let sh = h.sqrt();
        let y0 = s * t0 + self.beta;
        let y1 = s * t1 + self.beta;
        let v = if t1 < lim && t0 > -lim {
            let dt = t1 - t0;
            let num = sh * s * dt;
            let den = h + y0 * y1;
            if num <= R::EPSILON * den {
                dt / den
            } else {
                num.atan2(den) / (s * sh)
            }
        } else {
            let (num, den) = if t0 > -lim {
                (sh, y0)
            } else if t1 < lim {
                (sh, -y1)
            } else {
                (R::ZERO, -R::ONE)
            };
            num.atan2(den) / (s * sh)
        };
        v.max(R::ZERO).min(R::from_f64(ENERGY_MAX))
    }

    /// The integral for `falloff` (see [`Self::faithful`], [`Self::inverse_square`]).
    #[inline(always)]
    pub fn integral(&self, falloff: Falloff, t0: R, t1: R) -> R {
        match falloff {
            Falloff::Faithful => self.faithful(t0, t1),
            Falloff::InverseSquare => self.inverse_square(t0, t1),
        }
    }
}
