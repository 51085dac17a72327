//! Exact line integrals over one straight piece, and the attenuation rule built on them.
//!
//! On a piece the paired distance is `d(τ) = p + v·τ`, `τ ∈ [0, Δt]` (a 3-D vector; inside the
//! slab its axial component is 0). Write `|v| = s`, `v̂ = v/s`, `y(τ) = d(τ)·v̂ = y₀ + sτ` and
//! `e = |p × v̂|² + r_c²` (a cross product, so it never cancels), so that
//! `|d|² + r_c² = y² + e` — the same completed square as the analytic fields (SPEC.md §1.2):
//!
//! - Faithful (002 eq. 3.9, corrected): `∫ dτ/√(y² + e) = [asinh(y/√e)]/s`, evaluated as
//!   `ln(g₁/g₀)/s`, `g = y + √(y² + e)`, through `ln_1p` of the exact difference
//!   `g₁ − g₀ = sΔt·(1 + (y₀+y₁)/(√Q₀+√Q₁))`, after mirroring `y → −y` so that `y₀ + y₁ ≥ 0`: no
//!   difference of two large `asinh` values, and the limit `s → 0` is the constant integrand.
//! - Inverse square: `∫ dτ/(y² + e) = [atan(y/√e)]/(s√e) = atan2(sΔt√e, e + y₀y₁)/(s√e)`
//!   (the difference of the two `atan`s folded into one `atan2`), `→ Δt/(e + y₀²)` as `s → 0`.
//!
//! Attenuation `(1 − t/t_far)^j` (002 eq. 3.23) is smooth where the piece's weight `w(τ)` is
//! sharp, so it is integrated against that weight by its moments: with the weight's centroid `t̄`
//! and variance `σ²` (both closed forms), `∫w·g = ∫w·[g(t̄) + ½g''(t̄)σ²] + R₃`, where `R₃`
//! involves the third central moment and `g'''`. For `j ∈ {1, 2}` the rule is exact; otherwise
//! the caller keeps `Δu/(1 − u)` small enough that `R₃` is below its tolerance (see
//! `integrate.rs`). One power per piece: `g''/g = j(j−1)/((1−ū)·t_far)²`.
//!
//! Every function here has a WGSL twin of the same name in snake case in
//! `crates/hadou-gpu/src/shaders/curve.wgsl` (`Quad` → `quad_*` on a `vec4`, `Segment` methods →
//! `segment_*`); keep them in sync (the GPU twin tests compare them).

use crate::energy::Falloff;
use crate::{Real, Vec3};

/// The quadratic `|p + vτ|² + r_c²` of one piece, by its dot products: `pp = p·p`, `vv = v·v`,
/// `pv = p·v` and `E = |p × v|² + r_c²·vv` (`= vv·e`; a cross product, so it never cancels).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Quad<R> {
    pub pp: R,
    pub vv: R,
    pub pv: R,
    pub big_e: R,
}

impl<R: Real> Quad<R> {
    /// The quadratic of `d(τ) = p + vτ` in 3-D.
    #[inline]
    pub(crate) fn new(p: Vec3<R>, v: Vec3<R>, rc2: R) -> Self {
        let vv = v.dot(v);
        Quad { pp: p.dot(p), vv, pv: p.dot(v), big_e: p.cross(v).length_squared() + rc2 * vv }
    }

    /// `|d(τ)|²` at `τ = dt`.
    #[inline]
    pub(crate) fn end_squared(&self, dt: R) -> R {
        (self.pp + dt * (R::TWO * self.pv + self.vv * dt)).max(R::ZERO)
    }

    /// `1/D²`, `D²` the quadratic's minimum over `τ ∈ [0, dt]` (with `r_c²`): at an end, or
    /// inside at `E/vv` (one division either way).
    #[inline]
    pub(crate) fn inv_closest(&self, dt: R, rc2: R) -> R {
        if self.pv >= R::ZERO {
            R::ONE / (self.pp + rc2)
        } else if self.pv + self.vv * dt <= R::ZERO {
            R::ONE / (self.end_squared(dt) + rc2)
        } else {
            self.vv / self.big_e
        }
    }

    /// The quadratic of the same line from `τ = off` on.
    #[inline]
    pub(crate) fn shifted(&self, off: R) -> Self {
        Quad { pp: self.end_squared(off), vv: self.vv, pv: self.pv + self.vv * off, big_e: self.big_e }
    }
}

/// One straight piece's integral and what its attenuation rule needs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Segment<R> {
    /// `∫₀^{Δt} w(τ) dτ`.
    pub value: R,
    falloff: Falloff,
    dt: R,
    /// `y₀`, `y₁` after the mirroring (faithful) that makes `y₀ + y₁ ≥ 0`.
    y0: R,
    y1: R,
    /// `y₁ − y₀ = sΔt`, formed directly (not as a difference of the rounded `y₀`, `y₁`).
    span: R,
    /// Whether `y` was mirrored.
    flipped: bool,
    e: R,
    /// `Δψ = ψ₁ − ψ₀` (faithful) or `Δθ = θ₁ − θ₀` (inverse square).
    delta: R,
}

impl<R: Real> Segment<R> {
    /// The integral of `w = (|p + vτ|² + rc2)^{-1/2}` (faithful) or `^{-1}` (inverse square) over
    /// `τ ∈ [0, dt]`. `rc2 > 0`; `dt ≥ 0` may be `+∞` for the inverse square (then `v ≠ 0`).
    #[cfg(test)]
    pub(crate) fn new(falloff: Falloff, p: Vec3<R>, v: Vec3<R>, dt: R, rc2: R) -> Self {
        Self::from_quad(falloff, &Quad::new(p, v, rc2), dt, rc2)
    }

    /// [`new`](Self::new) from the piece's [`Quad`] (the chord walk has it from its acceptance
    /// test).
    ///
    /// Computed in `s`-scaled quantities (`s = |v|`): `Y = s·y` (`Y₀ = p·v`, `Y₁ = Y₀ + s²Δt`),
    /// `E = s²e = |p × v|² + r_c²s²`, `R = s·√Q = √(Y² + E)`, so that no division by `s` sits
    /// between the square roots and the logarithm: the faithful argument is
    /// `x = s²Δt·f/G₀` with `f = 1 + (Y₀+Y₁)/(R₀+R₁)` and `G₀ = s·g₀` (one division), and the
    /// inverse-square angle is `atan2(s²Δt√E, E + Y₀Y₁)` over `√E`, with no `s` at all. `1/s`
    /// is formed beside them, off the critical path.
    #[inline]
    pub(crate) fn from_quad(falloff: Falloff, q: &Quad<R>, dt: R, rc2: R) -> Self {
        let (vv, pv, big_e) = (q.vv, q.pv, q.big_e);
        let mut seg = Segment {
            value: R::ZERO,
            falloff,
            dt,
            y0: R::ZERO,
            y1: R::ZERO,
            span: R::ZERO,
            flipped: false,
            e: rc2,
            delta: R::ZERO,
        };
        if !(vv > R::ZERO) {
            // Constant integrand.
            let e = q.pp + rc2;
            seg.e = e;
            if dt > R::ZERO && dt.is_finite() {
                seg.value = match falloff {
                    Falloff::Faithful => dt / e.sqrt(),
                    Falloff::InverseSquare => dt / e,
                };
            }
            return seg;
        }
        let inv_s = R::ONE / vv.sqrt();
        seg.e = big_e * inv_s * inv_s;
        seg.y0 = pv * inv_s;
        seg.y1 = seg.y0;
        if !(dt > R::ZERO) {
            return seg;
        }
        match falloff {
            Falloff::Faithful => {
                let dt = if dt.is_finite() { dt } else { R::ZERO };
                let span = vv * dt;
                seg.span = span * inv_s;
                let (mut y0, mut y1) = (pv, pv + span);
                if y0 + y1 < R::ZERO {
                    (y0, y1) = (-y1, -y0);
                    seg.flipped = true;
                }
                let r0 = (y0 * y0 + big_e).sqrt();
                let r1 = (y1 * y1 + big_e).sqrt();
                let rs = r0 + r1;
                // x = s²Δt·(R₀+R₁+Y₀+Y₁)/((R₀+R₁)·G₀), G₀ = Y₀ + R₀ = E/(R₀ − Y₀).
                let x = if y0 >= R::ZERO {
                    span * (rs + y0 + y1) / (rs * (y0 + r0))
                } else {
                    span * (rs + y0 + y1) * (r0 - y0) / (rs * big_e)
                };
                // One logarithm: Δψ = ln(1 + x), by ln(1 + x) once x ≥ 1/16 (the rounding of
                // 1 + x then costs at most ε/2 against a value ≥ 0.06, and logf is much cheaper
                // than log1pf), by ln_1p below; the value is Δψ/s.
                let delta = if x >= R::from_f64(0.0625) { (R::ONE + x).ln() } else { x.ln_1p() };
                seg.value = delta * inv_s;
                seg.delta = delta;
                seg.y0 = y0 * inv_s;
                seg.y1 = y1 * inv_s;
            }
            Falloff::InverseSquare => {
                let se = big_e.sqrt();
                if dt.is_finite() {
                    let span = vv * dt;
                    seg.span = span * inv_s;
                    let z = span * se;
                    let k = big_e + pv * (pv + span);
                    let th = z.atan2(k);
                    seg.value = if k > R::ZERO && z < R::from_f64(1e-4) * k {
                        let r = z / k;
                        span / k * (R::ONE - r * r / R::from_f64(3.0))
                    } else {
                        th / se
                    };
                    seg.delta = th;
                    seg.y1 = (pv + span) * inv_s;
                } else {
                    let th = se.atan2(pv);
                    seg.value = th / se;
                    seg.delta = th;
                    seg.y1 = R::INFINITY;
                }
            }
        }
        seg
    }

    /// The weight's centroid `τ̄ = ∫τw/∫w` in `[0, Δt]` and its variance
    /// `σ² = ∫(τ − τ̄)²w/∫w`, in closed form, for the attenuation's second-order rule. Finite
    /// pieces only.
    ///
    /// From the moments in `y` (`τ = (y − y₀)/s`; mirroring flips the centroid and leaves the
    /// variance): with `m₀ = ∫w dy`, `m₁ = ∫y w dy`, `S₂ = ∫(y − y₀)²w dy`,
    /// - faithful: `m₀ = Δψ`, `m₁ = √Q₁ − √Q₀ = Δy(y₀+y₁)/(√Q₀+√Q₁)`,
    ///   `S₂ = ½(y₁√Q₁ − y₀√Q₀) − 2y₀m₁ + (y₀² − ½e)m₀`;
    /// - inverse square: `m₀ = Δθ/√e`, `m₁ = ½ln(Q₁/Q₀)` (through `ln_1p`),
    ///   `S₂ = Δy − 2y₀m₁ + (y₀² − e)m₀`;
    ///
    /// the centroid is `μ = m₁/m₀ − y₀` (as `τ̄ = μΔt/Δy`) and `σ_y² = S₂/m₀ − μ²`, clamped to
    /// `[0, Δy²/4]` (the most any weight on the interval allows) so that rounding can never make
    /// it negative, `σ² = σ_y²(Δt/Δy)²`. Where the weight is constant to `10⁻⁴` over the piece
    /// (`ν = Δy(|y|max + Δy)/Q₀`) the centroid is the midpoint and the variance `Δt²/12`; where
    /// it changes by less than 10 % the variance is that of its quadratic interpolant
    /// ([`fitted_variance`](Self::fitted_variance)): `S₂` is a small difference of terms of size
    /// `y²Δy` there, and in `f32` a far piece at `ν ≈ 0.01` came out 3× too large.
    #[inline]
    pub(crate) fn moments(&self) -> (R, R) {
        let (y0, y1, e, dt, span) = (self.y0, self.y1, self.e, self.dt, self.span);
        let (mid, uniform) = (dt * R::HALF, dt * dt / R::from_f64(12.0));
        let q0 = y0 * y0 + e;
        let nu = span * (y0.abs().max(y1.abs()) + span);
        if !(self.value > R::ZERO) || !(nu > R::from_f64(1e-4) * q0) {
            return (mid, uniform);
        }
        let (m0, m1, s2) = match self.falloff {
            Falloff::Faithful => {
                let (r0, r1) = (q0.sqrt(), (y1 * y1 + e).sqrt());
                let m0 = self.delta;
                let m1 = span * (y0 + y1) / (r0 + r1);
                (m0, m1, R::HALF * (y1 * r1 - y0 * r0) - R::TWO * y0 * m1 + (y0 * y0 - R::HALF * e) * m0)
            }
            Falloff::InverseSquare => {
                let m0 = self.delta / e.sqrt();
                let m1 = R::HALF * (span * (y0 + y1) / q0).ln_1p();
                (m0, m1, span - R::TWO * y0 * m1 + (y0 * y0 - e) * m0)
            }
        };
        let mu = m1 / m0 - y0;
        let scale = dt / span;
        let tbar = mu * scale;
        let tbar = if self.flipped { dt - tbar } else { tbar };
        let tbar = if tbar.is_finite() { tbar.clamp(R::ZERO, dt) } else { mid };
        if !(nu > R::from_f64(0.1) * q0) {
            return (tbar, self.fitted_variance(uniform));
        }
        let var = (s2 / m0 - mu * mu).clamp(R::ZERO, span * span * R::from_f64(0.25)) * scale * scale;
        (tbar, if var.is_finite() { var } else { uniform })
    }

    /// The variance of the weight's quadratic interpolant through `y₀`, the midpoint and `y₁`,
    /// `w ∝ 1 + βλ + γλ²` on `λ ∈ [0, 1]`: `M_k = ∫λ^k w` are `1 + β/2 + γ/3`, `½ + β/3 + γ/4`,
    /// `⅓ + β/4 + γ/5`, and `σ² = (M₂/M₀ − (M₁/M₀)²)·Δt²` (`uniform = Δt²/12` at `β = γ = 0`).
    /// Used where the weight changes by less than 10 % over the piece: the interpolant is then
    /// good to `O(ν³)`, and nothing cancels worse than `1/12` against `1/3`.
    #[inline]
    fn fitted_variance(&self, uniform: R) -> R {
        let (y0, e, span) = (self.y0, self.e, self.span);
        let w = |y: R| match self.falloff {
            Falloff::Faithful => R::ONE / (y * y + e).sqrt(),
            Falloff::InverseSquare => R::ONE / (y * y + e),
        };
        let (w0, wm, w1) = (w(y0), w(y0 + span * R::HALF), w(y0 + span));
        let gamma = R::TWO * (w1 - R::TWO * wm + w0) / wm;
        let beta = (w1 - w0) / wm - gamma;
        let a = w0 / wm;
        let m0 = a + beta * R::HALF + gamma / R::from_f64(3.0);
        let m1 = a * R::HALF + beta / R::from_f64(3.0) + gamma * R::from_f64(0.25);
        let m2 = a / R::from_f64(3.0) + beta * R::from_f64(0.25) + gamma / R::from_f64(5.0);
        let (c1, c2) = (m1 / m0, m2 / m0);
        let v = (c2 - c1 * c1).clamp(R::ZERO, R::from_f64(0.25)) * self.dt * self.dt;
        if v.is_finite() {
            v
        } else {
            uniform
        }
    }

    /// The centroid alone (see [`moments`](Self::moments)).
    #[cfg(test)]
    pub(crate) fn centroid(&self) -> R {
        self.moments().0
    }

    /// The variance alone (see [`moments`](Self::moments)).
    #[cfg(test)]
    pub(crate) fn variance(&self) -> R {
        self.moments().1
    }

    /// `∫₀^{Δt} w(τ)·g(t_start + τ) dτ` for the attenuation `g(t) = (1 − t/t_far)^j`
    /// (002 eq. 3.23), to second order about the weight's centroid `t̄`:
    /// `∫w·g(t̄)·(1 + ½j(j−1)·z)`, `z = σ²/((1 − t̄/t_far)·t_far)²` clamped to 1 (a spread
    /// beyond the distance to the far point only occurs where `g` is already below the
    /// attenuation floor). Exact for `j ∈ {1, 2}` (up to the variance's own rounding); never
    /// negative. Finite pieces only.
    #[inline]
    pub(crate) fn attenuated(&self, t_start: R, t_far: R, j: R) -> R {
        if !(self.value > R::ZERO) {
            return R::ZERO;
        }
        let (tbar, var) = self.moments();
        let h = R::ONE - (t_start + tbar) / t_far;
        if !(h > R::ZERO) {
            return R::ZERO;
        }
        let ht = h * t_far;
        let z = (var / (ht * ht)).min(R::ONE);
        let factor = (R::ONE + R::HALF * j * (j - R::ONE) * z).max(R::ZERO);
        self.value * h.powf(j) * factor
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::integrate_adaptive;

    fn numeric(falloff: Falloff, p: Vec3<f64>, v: Vec3<f64>, dt: f64, rc2: f64) -> f64 {
        let k = if falloff == Falloff::Faithful { 0.5 } else { 1.0 };
        integrate_adaptive(|t| ((p + v * t).length_squared() + rc2).powf(-k), 0.0, dt, 1e-13, 0.0).value
    }

    #[test]
    fn closed_forms_match_quadrature_in_all_regimes() {
        let cases = [
            (Vec3::new(0.3, -2.0, 0.1), Vec3::new(0.0, 1.0, 0.2), 5.0, 1e-4),
            (Vec3::new(0.0, 3.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 2.0, 1e-2), // y₀, y₁ > 0
            (Vec3::new(0.0, -9.0, 0.5), Vec3::new(0.0, 1.0, 0.0), 2.0, 1e-2), // both < 0: mirrored
            (Vec3::new(0.2, 1.0, 0.0), Vec3::new(1e-9, 0.0, 0.0), 3.0, 1e-3), // nearly constant
            (Vec3::new(0.2, 1.0, 0.0), Vec3::ZERO, 3.0, 1e-3),               // exactly constant
            (Vec3::new(0.0, -1.0, 1e-7), Vec3::new(0.0, 50.0, 0.0), 0.04, 1e-12), // through the line
        ];
        for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
            for &(p, v, dt, rc2) in &cases {
                let exact = numeric(falloff, p, v, dt, rc2);
                let got = Segment::new(falloff, p, v, dt, rc2).value;
                assert!(((got - exact) / exact).abs() < 1e-9, "{falloff:?} {p:?} {v:?}: {got} vs {exact}");
                let got32 = Segment::new(falloff, p.as_f32(), v.as_f32(), dt as f32, rc2 as f32).value;
                assert!(
                    ((f64::from(got32) - exact) / exact).abs() < 2e-4,
                    "f32 {falloff:?} {p:?}: {got32} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn inverse_square_to_infinity() {
        let p = Vec3::new(0.5, -3.0, 0.0);
        let v = Vec3::new(0.0, 1.0, 0.0);
        let got = Segment::new(Falloff::InverseSquare, p, v, f64::INFINITY, 0.01).value;
        let exact = integrate_adaptive(
            |t| 1.0 / ((p + v * t).length_squared() + 0.01),
            0.0,
            f64::INFINITY,
            1e-13,
            0.0,
        );
        assert!((got - exact.value).abs() < 1e-10 * exact.value, "{got} vs {}", exact.value);
    }

    fn moment(falloff: Falloff, p: Vec3<f64>, v: Vec3<f64>, dt: f64, k: i32, f: impl Fn(f64) -> f64) -> f64 {
        let pw = if falloff == Falloff::Faithful { -0.5 } else { -1.0 };
        integrate_adaptive(
            |t| t.powi(k) * f(t) * ((p + v * t).length_squared() + 1e-4).powf(pw),
            0.0,
            dt,
            1e-13,
            0.0,
        )
        .value
    }

    const PIECES: [(Vec3<f64>, Vec3<f64>, f64); 8] = [
        (Vec3 { x: 0.1, y: -2.0, z: 0.0 }, Vec3 { x: 0.0, y: 1.0, z: 0.0 }, 4.0), // through the closest approach
        (Vec3 { x: 0.1, y: -20.0, z: 0.0 }, Vec3 { x: 0.0, y: 1.0, z: 0.0 }, 1.0), // far, nearly uniform
        (Vec3 { x: 0.1, y: 2.0, z: 0.0 }, Vec3 { x: 0.0, y: 1e-4, z: 0.0 }, 1.0), // almost constant
        (Vec3 { x: 0.01, y: -0.5, z: 0.0 }, Vec3 { x: 0.0, y: 1.0, z: 0.0 }, 1.0), // sharp peak inside
        (Vec3 { x: 0.02, y: 0.0, z: 0.0 }, Vec3 { x: 0.0, y: 1.0, z: 0.0 }, 30.0), // peak at the start, long tail
        (Vec3 { x: 0.0, y: -300.0, z: 1.0 }, Vec3 { x: 0.0, y: 1.0, z: 0.0 }, 0.5), // far, short
        // Far and short, moving away: the centroid was half the piece off in f32 while the
        // moments took the span as y₁ − y₀ of two rounded values.
        (Vec3 { x: 0.0, y: -131.381_07, z: -0.351_25 }, Vec3 { x: 0.0, y: -0.2149, z: -0.004_37 }, 0.2911),
        // Far, the weight changing by 1 %: the variance from S₂ came out 3× too large in f32.
        (
            Vec3 { x: 0.0, y: 139.972_365, z: -1.083_002 },
            Vec3 { x: 0.0, y: 0.460_856, z: 0.028_523 },
            2.983_01,
        ),
    ];

    #[test]
    fn centroid_and_variance_match_quadrature() {
        for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
            for &(p, v, dt) in &PIECES {
                let seg = Segment::new(falloff, p, v, dt, 1e-4);
                let m0 = moment(falloff, p, v, dt, 0, |_| 1.0);
                let m1 = moment(falloff, p, v, dt, 1, |_| 1.0);
                let m2 = moment(falloff, p, v, dt, 2, |_| 1.0);
                let tbar = m1 / m0;
                let var = m2 / m0 - tbar * tbar;
                assert!((seg.value - m0).abs() < 1e-10 * m0, "{falloff:?} {p:?}: value");
                assert!(
                    (seg.centroid() - tbar).abs() < 2e-5 * dt,
                    "{falloff:?} {p:?}: centroid {} vs {tbar}",
                    seg.centroid()
                );
                let got = seg.variance();
                assert!(
                    (got - var).abs() < 1e-6 * dt * dt + 1e-4 * var,
                    "{falloff:?} {p:?}: variance {got} vs {var}"
                );
                // f32 keeps the centroid to a small fraction of the piece, also far from the
                // closest approach: the moments use the exact span sΔt, not y₁ − y₀ of two rounded
                // large values.
                let s32 = Segment::new(falloff, p.as_f32(), v.as_f32(), dt as f32, 1e-4);
                let c32 = f64::from(s32.centroid());
                assert!((c32 - tbar).abs() < 1e-2 * dt, "f32 {falloff:?} {p:?}: centroid {c32} vs {tbar}");
                // f32 keeps the variance to a fraction of the piece's squared length.
                let g32 = s32.variance();
                assert!(
                    (f64::from(g32) - var).abs() < 1e-3 * dt * dt,
                    "f32 {falloff:?} {p:?}: {g32} vs {var}"
                );
            }
        }
    }

    #[test]
    fn attenuation_by_moments() {
        let t_far = 40.0;
        for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
            for &(p, v, dt) in &PIECES {
                for (t_start, j) in [(1.0, 2.0), (5.0, 1.0), (2.0, 0.5), (3.0, 3.0), (2.0, 6.0)] {
                    let g = |t: f64| (1.0 - (t_start + t) / t_far).max(0.0).powf(j);
                    let exact = moment(falloff, p, v, dt, 0, g);
                    let got = Segment::new(falloff, p, v, dt, 1e-4).attenuated(t_start, t_far, j);
                    // Second order about the centroid: exact for j ≤ 2, else off by the third
                    // moment term, ~j³·(Δt/(t_far − t))³/100 at most.
                    let x = dt / (t_far - t_start - dt);
                    let bound = if j == 1.0 || j == 2.0 {
                        1e-6
                    } else {
                        (j * (j - 1.0) * (j - 2.0)).abs() * x * x * x / 50.0 + 1e-9
                    };
                    assert!(
                        (got - exact).abs() <= bound * exact,
                        "{falloff:?} {p:?} j={j}: {got} vs {exact} (rel {:.2e}, bound {bound:.1e})",
                        (got - exact).abs() / exact
                    );
                }
            }
        }
    }
}
