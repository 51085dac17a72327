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
//! sharp, so it is integrated against that weight by substitution: with `W(τ) = ∫₀^τ w` the
//! integral is `∫₀^{W(Δt)} g(τ(W)) dW`, and Gauss–Legendre nodes are placed uniformly in `W`
//! (in `ψ = asinh(y/√e)` or `θ = atan(y/√e)`, which are proportional to `W`). The rule is exact
//! for attenuation linear in `W` and needs no moments.

use crate::energy::Falloff;
use crate::{Real, Vec3};

/// Gauss–Legendre nodes on `[0, 1]` and their weights (summing to 1), for 1, 2 and 3 points.
pub(crate) fn gauss_legendre(n: usize) -> (&'static [f64], &'static [f64]) {
    const X1: [f64; 1] = [0.5];
    const W1: [f64; 1] = [1.0];
    const X2: [f64; 2] = [0.211_324_865_405_187_1, 0.788_675_134_594_812_9];
    const W2: [f64; 2] = [0.5, 0.5];
    const X3: [f64; 3] = [0.112_701_665_379_258_3, 0.5, 0.887_298_334_620_741_7];
    const W3: [f64; 3] = [5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0];
    match n {
        0 | 1 => (&X1, &W1),
        2 => (&X2, &W2),
        _ => (&X3, &W3),
    }
}

/// `ln(1 + x)/x`, 1 at `x = 0`.
#[inline]
fn ln1p_over<R: Real>(x: R) -> R {
    if x.abs() < R::from_f64(1e-3) {
        R::ONE - x * (R::HALF - x / R::from_f64(3.0))
    } else {
        x.ln_1p() / x
    }
}

/// `sinh(x)` for `x ≥ 0`, accurate for small `x`.
#[inline]
fn sinh<R: Real>(x: R) -> R {
    if x < R::from_f64(0.1) {
        let x2 = x * x;
        x * (R::ONE + x2 / R::from_f64(6.0) * (R::ONE + x2 / R::from_f64(20.0)))
    } else {
        (x.exp() - (-x).exp()) * R::HALF
    }
}

/// One straight piece's integral and what its attenuation nodes need.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Segment<R> {
    /// `∫₀^{Δt} w(τ) dτ`.
    pub value: R,
    falloff: Falloff,
    dt: R,
    /// `y₀`, `y₁` after the mirroring (faithful) that makes `y₀ + y₁ ≥ 0`.
    y0: R,
    y1: R,
    /// Whether `y` was mirrored.
    flipped: bool,
    e: R,
    /// `Δψ = ψ₁ − ψ₀` (faithful) or `Δθ = θ₁ − θ₀` (inverse square).
    delta: R,
}

impl<R: Real> Segment<R> {
    /// The integral of `w = (|p + vτ|² + rc2)^{-1/2}` (faithful) or `^{-1}` (inverse square) over
    /// `τ ∈ [0, dt]`. `rc2 > 0`; `dt ≥ 0` may be `+∞` for the inverse square (then `v ≠ 0`).
    #[inline]
    pub(crate) fn new(falloff: Falloff, p: Vec3<R>, v: Vec3<R>, dt: R, rc2: R) -> Self {
        Self::with_dots(falloff, p, v, v.dot(v), p.dot(v), dt, rc2)
    }

    /// [`new`](Self::new) with `vv = v·v` and `pv = p·v` already formed (the chord walk has them
    /// from its acceptance test).
    ///
    /// Computed in `s`-scaled quantities (`s = |v|`): `Y = s·y` (`Y₀ = p·v`, `Y₁ = Y₀ + s²Δt`),
    /// `E = s²e = |p × v|² + r_c²s²`, `R = s·√Q = √(Y² + E)`, so that no division by `s` sits
    /// between the square roots and the logarithm: the faithful argument is
    /// `x = s²Δt·f/G₀` with `f = 1 + (Y₀+Y₁)/(R₀+R₁)` and `G₀ = s·g₀` (one division), and the
    /// inverse-square angle is `atan2(s²Δt√E, E + Y₀Y₁)` over `√E`, with no `s` at all. `1/s`
    /// is formed beside them, off the critical path.
    #[inline]
    pub(crate) fn with_dots(falloff: Falloff, p: Vec3<R>, v: Vec3<R>, vv: R, pv: R, dt: R, rc2: R) -> Self {
        let mut seg = Segment {
            value: R::ZERO,
            falloff,
            dt,
            y0: R::ZERO,
            y1: R::ZERO,
            flipped: false,
            e: rc2,
            delta: R::ZERO,
        };
        if !(vv > R::ZERO) {
            // Constant integrand.
            let e = p.length_squared() + rc2;
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
        // |p × v̂|² = |p × v|²/|v|²: a cross product, so E never cancels.
        let big_e = p.cross(v).length_squared() + rc2 * vv;
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

    /// The `τ`-fraction (in `[0, 1]` of `Δt`) at which the weight's cumulative integral reaches the
    /// fraction `mu` of the total. Finite pieces only.
    ///
    /// With `φ = μΔψ` (faithful) or `φ = μΔθ` (inverse square) the node's `y_k` follows from the
    /// addition theorems, written in the exact quantities `y₀`, `√Q₀` and `y₁ − y₀ = sΔt` so that
    /// no angle near `±π/2` (or large `ψ`) is ever converted back:
    /// - faithful: `λ·sΔt = y₀(cosh φ − 1) + √Q₀ sinh φ`, for `y₀ < 0` rearranged as
    ///   `|y₀|(1 − e^{−φ}) + g₀ sinh φ` (both terms positive);
    /// - inverse square: `λ·sΔt = Q₀ sin φ / (√e cos φ − y₀ sin φ)`.
    #[inline]
    pub(crate) fn fraction_at(&self, mu: R) -> R {
        let (y0, y1, e, d) = (self.y0, self.y1, self.e, self.delta);
        let span = y1 - y0;
        if !(span > R::EPSILON * (y0.abs() + e.sqrt())) {
            return mu;
        }
        let lambda = match self.falloff {
            Falloff::Faithful => {
                let mu = if self.flipped { R::ONE - mu } else { mu };
                let phi = mu * d;
                let q0 = (y0 * y0 + e).sqrt();
                let sh = sinh(phi);
                let num = if y0 >= R::ZERO {
                    let h = sinh(phi * R::HALF);
                    y0 * R::TWO * h * h + q0 * sh
                } else {
                    let g0 = e / (q0 - y0);
                    let one_minus_exp = if phi < R::from_f64(1e-3) {
                        phi * (R::ONE - phi * R::HALF)
                    } else {
                        R::ONE - (-phi).exp()
                    };
                    -y0 * one_minus_exp + g0 * sh
                };
                let l = num / span;
                if self.flipped {
                    R::ONE - l
                } else {
                    l
                }
            }
            Falloff::InverseSquare => {
                let phi = mu * d;
                let (sp, cp) = (phi.sin(), phi.cos());
                let den = e.sqrt() * cp - y0 * sp;
                if den > R::ZERO {
                    (y0 * y0 + e) * sp / (den * span)
                } else {
                    R::ONE
                }
            }
        };
        if lambda.is_finite() {
            lambda.clamp(R::ZERO, R::ONE)
        } else {
            mu
        }
    }

    /// The weight's centroid `τ̄ = ∫τw/∫w` in `[0, Δt]`, from the closed-form first moment
    /// `∫y w dτ` (faithful: `Δt(y₀+y₁)/(√Q₀+√Q₁)`; inverse square: `ln(Q₁/Q₀)/(2s)` through
    /// `ln_1p`) as `τ̄ = (∫yw/∫w − y₀)/s`; the midpoint where the weight is constant to `10⁻⁴`.
    /// Finite pieces only.
    #[inline]
    pub(crate) fn centroid(&self) -> R {
        let (y0, y1, e, dt) = (self.y0, self.y1, self.e, self.dt);
        let span = y1 - y0;
        let q0 = y0 * y0 + e;
        // Relative change of the weight over the piece ≈ span·|y|/Q.
        if !(self.value > R::ZERO) || !(span * (y0.abs().max(y1.abs()) + span) > R::from_f64(1e-4) * q0) {
            return dt * R::HALF;
        }
        let n1 = match self.falloff {
            Falloff::Faithful => {
                let q1 = y1 * y1 + e;
                dt * (y0 + y1) / (q0.sqrt() + q1.sqrt())
            }
            Falloff::InverseSquare => {
                let x = span * (y0 + y1) / q0;
                dt * (y0 + y1) / (R::TWO * q0) * ln1p_over(x)
            }
        };
        let s = span / dt;
        let tbar = (n1 / self.value - y0) / s;
        let tbar = if self.flipped { dt - tbar } else { tbar };
        if tbar.is_finite() {
            tbar.clamp(R::ZERO, dt)
        } else {
            dt * R::HALF
        }
    }

    /// `∫₀^{Δt} w(τ)·g(t_start + τ) dτ`: the linear interpolant of `g` between the piece's ends
    /// (`ga = g(t_start)`, `gb = g(t_start + Δt)`) exactly, by the weight's
    /// [`centroid`](Self::centroid), and the remainder `g − g_lin` by `nodes`-point
    /// Gauss–Legendre in the weight's cumulative measure (none for `nodes = 0`), which costs
    /// `nodes` evaluations of `g`. Finite pieces only.
    #[inline]
    pub(crate) fn attenuated(&self, t_start: R, nodes: usize, ga: R, gb: R, g: impl Fn(R) -> R) -> R {
        if !(self.value > R::ZERO) {
            return R::ZERO;
        }
        let lin = |lam: R| ga + (gb - ga) * lam;
        let tbar = self.centroid();
        let mut acc = lin(if self.dt > R::ZERO { tbar / self.dt } else { R::HALF });
        if nodes > 0 {
            let (xs, ws) = gauss_legendre(nodes);
            for (x, w) in xs.iter().zip(ws) {
                let lam = self.fraction_at(R::from_f64(*x));
                acc += R::from_f64(*w) * (g(t_start + lam * self.dt) - lin(lam));
            }
        }
        acc * self.value
    }

    /// `y` range and `e` (for tests of the completed square).
    #[cfg(test)]
    pub(crate) fn parts(&self) -> (R, R, R) {
        (self.y0, self.y1, self.e)
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

    #[test]
    fn weight_fractions_split_the_integral() {
        // The weight's integral over [0, λ(μ)Δt] must be μ times the total.
        for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
            for &(p, v, dt) in &[
                (Vec3::new(0.1, -2.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 4.0),
                (Vec3::new(0.1, -20.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 1.0),
                (Vec3::new(0.1, 2.0, 0.0), Vec3::new(0.0, 1e-4, 0.0), 1.0),
                (Vec3::new(0.01, -0.5, 0.0), Vec3::new(0.0, 1.0, 0.0), 1.0),
            ] {
                let seg = Segment::new(falloff, p, v, dt, 1e-4);
                for mu in [0.1, 0.5, 0.8] {
                    let lam = seg.fraction_at(mu);
                    let part = Segment::new(falloff, p, v, lam * dt, 1e-4).value;
                    assert!(
                        (part / seg.value - mu).abs() < 1e-9,
                        "{falloff:?} {p:?} μ={mu}: {}",
                        part / seg.value
                    );
                }
                let tbar = seg.centroid();
                let m1 = integrate_adaptive(
                    |t| {
                        t * ((p + v * t).length_squared() + 1e-4).powf(if falloff == Falloff::Faithful {
                            -0.5
                        } else {
                            -1.0
                        })
                    },
                    0.0,
                    dt,
                    1e-13,
                    0.0,
                )
                .value;
                assert!(
                    (tbar - m1 / seg.value).abs() < 2e-5 * dt,
                    "{falloff:?} {p:?} centroid {tbar} vs {}",
                    m1 / seg.value
                );
                let (y0, y1, e) = seg.parts();
                assert!(y0.is_finite() && y1.is_finite() && e > 0.0);
            }
        }
    }
}
