//! The analytic shapes' energies with the distance attenuation `(1 − t/t_far)^j` of 002 eq. 3.23
//! (SPEC.md §1.4): the thesis defines it for curved waves only (SPEC.md §1.6 lists "the analytic
//! shapes cannot be attenuated with distance" among its limits); here every analytic shape has it.
//!
//! # Method
//! Each shape reduces to [`RayQuadratic`] pieces, so one integral is needed:
//! `A = ∫_{t0}^{min(t1, t_far)} g(t)·w(t) dt`, `g = (1 − t/t_far)^j`, `w = 1/sqrt(Y² + H)`
//! (faithful) or `1/(Y² + H)` (inverse square), `Y = s·t + β`. `w` has one peak, at
//! `t_c = −β/s` with half-width `ε = √H/s`; `g` falls from 1 to 0 at `t_far`, steeply for large
//! `j`, with a branch point there for non-integer `j`. No closed form covers real `j`, and the
//! polynomial expansion of `(1 − t/t_far)^j` for integer `j` cancels catastrophically in `f32`
//! for `j` beyond a few, so [`RayQuadratic::attenuated`] integrates by 8-point Gauss–Legendre on
//! graded cells, each cell's weight `∫w` taken from the exact closed form and the rule only
//! averaging `g` against it (`A = Σ_cells I_cell·ḡ_cell`; exact wherever `g` is constant):
//!
//! - cells shrink geometrically towards `t_far`: `t_far − t` falls by `q = max(e^{−4/j}, ¼)` per
//!   cell ([`FAR_GRADE`], [`FAR_RATIO_MIN`]), so `g` changes by at most a factor `e⁴` on one and
//!   its branch point stays a third of a cell length away;
//! - cells grow geometrically away from the peak: a cell leaving it at distance `d > ε` from
//!   `t_c` spans at most `4·d` ([`LEAVE_GROWTH`]), one approaching it ends at a fifth of the
//!   distance left ([`APPROACH_RATIO`]), so `w`'s complex poles `t_c ± iε` stay a quarter of a
//!   cell length away. On such a cell `g` is averaged with the weights `W_i·w(t_i)` at nodes
//!   uniform in `t`;
//! - the inner cell `|t − t_c| ≤ ε` is integrated in the variable in which `w dt` is uniform,
//!   `ψ = asinh(Y/√H)` (faithful) or `θ = atan(Y/√H)` (inverse square; `|θ| ≤ π/4` keeps the
//!   poles of `t(θ) ∝ tan θ` twice the cell's half-width away), so the peak itself needs no
//!   refinement however narrow it is (`H` down to `H_FLOOR`). A peak narrower than the spacing
//!   of `t`'s floating-point values is approached by halving down to that spacing, its mass then
//!   taken by the closed form over one step of it;
//! - the march stops once the rest cannot add more than `10⁻⁵` of the sum: `g` falls along the
//!   ray, so the rest is at most `g(x)·(I − Σ I_cell)`, `I` the unattenuated integral;
//! - the far tail `[x, t_far]` is one step as soon as the peak is far from it: with
//!   `h = 1 − t/t_far` and `u = (j + 1)·ln(h(x)/h(t))`, the attenuation times the measure is
//!   exactly `(t_far − x)·g(x)/(j + 1)·e^{−u} du` (`g dt = −t_far h^j dh`), so
//!   `∫_x^{t_far} g w dt = (t_far − x)·g(x)/(j + 1)·∫_0^∞ e^{−u} w(t(u)) du`,
//!   `t(u) = t_far − (t_far − x)·e^{−u/(j+1)}`, which 8-point Gauss–Laguerre integrates from
//!   eight densities (no power per node: `e^{−u_i/(j+1)}` is one set per call). The branch point
//!   of `g` at `t_far` is in the weight, not the integrand; what is left, `w(t(u)) =
//!   F(e^{−u/(j+1)})` with `F(ζ) = w(t_far − (t_far − x)ζ)`, has its singularities (the peak's
//!   `t_c ± iε`) at `|ζ| = |t_far − t_c ∓ iε|/(t_far − x)`. Expanding `F` in powers of `ζ`, the
//!   rule errs by about `Σ_k |ζ|^{−k}·E(k/(j + 1))`, `E(λ)` its error on `e^{−λu}`; taking the
//!   step once `|ζ| ≥ reach(j) = max(1 + 2·j^{−2/3}, 1.25)` ([`TAIL_REACH`]) keeps that near
//!   `10⁻⁶` for every `j ≥ 1` ([`TAIL_MIN_J`]; smaller `j` marches to the end); the inverse
//!   square's two nearly coincident poles make it up to `1.2·10⁻⁵` at `j = 1`
//!   (`tests/analytic_attenuation.rs`, `far_tail_step_is_accurate_at_the_edge_of_its_reach`). An end `b`
//!   before `t_far` (an occluder) takes `∫_x^{t_far} − ∫_b^{t_far}` where the second is at most
//!   half the first (else the march goes on).
//!
//! The 8-point rule on a cell whose nearest singularity is a quarter of a cell length away
//! (Bernstein ellipse `ρ = 1.5 + √1.25 ≈ 2.6`) errs by about `ρ⁻¹⁶ ≈ 2·10⁻⁷` relative, times
//! what `g` grows by on that ellipse (at most `e⁴` more); the grading of the 4-point rule it
//! replaced (ratio 2 from the peak, `e` per cell towards `t_far`) took about twice as many cells
//! for the same error (docs/benchmarks.md, "Eight nodes on longer cells").
//! `tests/analytic_attenuation.rs` holds the result to an `f64` adaptive quadrature of the
//! densities written from their definitions (p99 relative error ≤ 10⁻³ in `f32` over random
//! rays and degenerate ones). A ray through a
//! centre with `r_c = 0` needs about `2·log₅(span/ε)` cells; the march is capped at
//! [`MAX_CELLS`] (the rest is then one last cell).
//!
//! `j = 0` calls the unattenuated kernels themselves, so it is bit-identical to them and as fast.
//! The eight-lane kernels (`lanes.rs`) have the same march in lanes (`lanes::*_attenuated`, a
//! masked loop in which each lane grades, stops, caps its own cells and takes the far tail by the
//! rules here), which
//! the CPU backend uses; these functions are what they are tested against.

use super::field::{
    Attenuation, BeamField, CapsuleField, CylinderField, Falloff, FieldParams, Ray, SphereField,
};
use super::integral::{capsule_parts, cylinder_quadratic, sphere_quadratic};
use super::kernel::{saturate, scaled, RayQuadratic, ENERGY_MAX, T_LIMIT};
use crate::Real;

/// Gauss–Legendre nodes on `[0, 1]` (8 points).
pub(super) const GL_X: [f64; 8] = [
    0.019_855_071_751_231_884,
    0.101_666_761_293_186_64,
    0.237_233_795_041_835_5,
    0.408_282_678_752_175_1,
    0.591_717_321_247_825,
    0.762_766_204_958_164_5,
    0.898_333_238_706_813_4,
    0.980_144_928_248_768_1,
];
/// Gauss–Legendre weights on `[0, 1]` (8 points, sum 1).
pub(super) const GL_W: [f64; 8] = [
    0.050_614_268_145_188_13,
    0.111_190_517_226_687_24,
    0.156_853_322_938_943_63,
    0.181_341_891_689_181,
    0.181_341_891_689_181,
    0.156_853_322_938_943_63,
    0.111_190_517_226_687_24,
    0.050_614_268_145_188_13,
];

/// Cells towards `t_far` shrink `t_far − t` by `e^{−FAR_GRADE/j}`: `g` changes by at most
/// `e^{FAR_GRADE}` on one.
pub const FAR_GRADE: f64 = 4.0;

/// The least ratio of `t_far − t` from one cell's start to its end (small `j`), so that `t_far`,
/// a branch point of `g` for non-integer `j`, stays a third of a cell length away.
pub const FAR_RATIO_MIN: f64 = 0.25;

/// A cell approaching the peak ends at this fraction of its distance `t_c − x` from the peak.
pub const APPROACH_RATIO: f64 = 0.2;

/// A cell leaving the peak at distance `d` spans at most `LEAVE_GROWTH·d`.
pub const LEAVE_GROWTH: f64 = 4.0;

/// Gauss–Laguerre nodes (8 points, weight `e^{−u}` on `[0, ∞)`): the far tail's rule.
pub(super) const LAGUERRE_X: [f64; 8] = [
    0.170_279_632_305_100_93,
    0.903_701_776_799_38,
    2.251_086_629_866_131,
    4.266_700_170_287_659,
    7.045_905_402_393_465_5,
    10.758_516_010_180_996,
    15.740_678_641_278_004,
    22.863_131_736_889_265,
];
/// Gauss–Laguerre weights (8 points, sum 1).
pub(super) const LAGUERRE_W: [f64; 8] = [
    0.369_188_589_341_634_95,
    0.418_786_780_814_344_7,
    0.175_794_986_637_172_55,
    0.033_343_492_261_215_794,
    0.002_794_536_235_225_683_4,
    9.076_508_773_358_139e-5,
    8.485_746_716_272_57e-7,
    1.048_001_174_871_515_3e-9,
];

/// The far tail `[x, t_far]` is taken in one Gauss–Laguerre step once the peak's complex
/// singularities `t_c ± iε` are at least `reach(j) = max(1 + TAIL_REACH·j^{−2/3}, TAIL_REACH_MIN)`
/// times `t_far − x` from `t_far` (the rule's error is then about `10⁻⁶` relative, up to
/// `1.2·10⁻⁵` for the inverse square at `j = 1`; see this module's documentation).
pub const TAIL_REACH: f64 = 2.0;

/// The least reach of the far tail's rule (large `j`).
pub const TAIL_REACH_MIN: f64 = 1.25;

/// `reach(j)` of [`TAIL_REACH`].
#[inline(always)]
pub(super) fn tail_reach<R: Real>(j: R) -> R {
    (R::ONE + R::from_f64(TAIL_REACH) * j.powf(R::from_f64(-2.0 / 3.0))).max(R::from_f64(TAIL_REACH_MIN))
}

/// The far tail's rule is used only for `j` at least this (below, `e^{−u/(j+1)}` is too far from
/// a low-degree polynomial in `u` for 8 nodes).
pub const TAIL_MIN_J: f64 = 1.0;

/// Most cells one piece is cut into; the rest of the span is then one last cell.
pub const MAX_CELLS: u32 = 192;

/// The march stops once the rest is at most this fraction of the sum so far.
pub const REST_TOLERANCE: f64 = 1e-5;

/// A peak is graded only where `|t_c|` and `ε` are below this (`s` is not vanishingly small).
pub const PEAK_RANGE: f64 = 1e20;

/// Half-width of the inner cell around the peak, in units of the peak's half-width `ε = √H/s`.
pub const INNER_CELL: f64 = 1.0;

/// `(Y² + H)^{-1/2}` or `(Y² + H)^{-1}`.
#[inline(always)]
fn density<R: Real>(falloff: Falloff, y: R, h: R) -> R {
    let r2 = y * y + h;
    match falloff {
        Falloff::Faithful => R::ONE / r2.sqrt(),
        Falloff::InverseSquare => R::ONE / r2,
    }
}

impl<R: Real> RayQuadratic<R> {
    /// `∫_{t0}^{min(t1, t_far)} (1 − t/t_far)^j dt / sqrt(Y² + H)` (faithful) or `/(Y² + H)`
    /// (inverse square): the piece integral of [`Self::integral`] with the distance attenuation
    /// of 002 eq. 3.23 (SPEC.md §1.4), 0 from the far point on. Graded 8-point Gauss–Legendre
    /// cells weighted by the closed form, then one 8-point Gauss–Laguerre step over the far tail
    /// once the peak is far enough from the far point (see this module's documentation,
    /// `energy/attenuated.rs`); `j = 0` (or NaN) is
    /// [`Self::integral`] itself. Finite and in `[0, ENERGY_MAX]` for finite inputs; empty or
    /// NaN spans give 0.
    ///
    /// Mirrored by `rq_attenuated` in the GPU crate's `energy.wgsl` and eight rays at a time by
    /// `lanes::Quad::attenuated` (keep all three in sync).
    pub fn attenuated(&self, falloff: Falloff, t0: R, t1: R, att: &Attenuation<R>) -> R {
        if !att.is_active() {
            return self.integral(falloff, t0, t1);
        }
        let tf = att.t_far;
        let a = t0.max(-R::from_f64(T_LIMIT));
        let b = t1.min(tf);
        // False for NaN ends, empty spans and spans beyond the far point.
        if !(b > a && tf > R::ZERO && tf.is_finite()) {
            return R::ZERO;
        }
        let total = self.integral(falloff, a, b);
        let positive = total > R::ZERO; // false for NaN too
        if !positive {
            return R::ZERO;
        }
        let (s, h) = (self.s, self.h);
        let sh = h.sqrt();
        // A peak only where t_c = −β/s and ε = √H/s stay far below overflow.
        let range = R::from_f64(PEAK_RANGE);
        let has_peak = s > R::ZERO && sh <= s * range && self.beta.abs() <= s * range;
        let (tc, dmin) =
            if has_peak { (-self.beta / s, R::from_f64(INNER_CELL) * (sh / s)) } else { (R::ZERO, R::ZERO) };
        let q = (-R::from_f64(FAR_GRADE) / att.j).exp().max(R::from_f64(FAR_RATIO_MIN));
        let half = R::from_f64(0.5);
        let approach = R::from_f64(APPROACH_RATIO);
        let leave = R::from_f64(LEAVE_GROWTH);
        // The far tail: where the peak's singularities are far from t_far (or there is no peak).
        let tail_on = att.j >= R::from_f64(TAIL_MIN_J);
        let tail_reach = if has_peak {
            let dc = tf - tc;
            (dc * dc + (sh / s) * (sh / s)).sqrt() / tail_reach(att.j)
        } else {
            R::INFINITY
        };
        // (t_far − b)·g(b): what the tail beyond an end before t_far weighs (0 at t_far).
        let beyond = (tf - b) * att.factor(b);
        let mut x = a;
        let mut acc = R::ZERO;
        let mut used = R::ZERO;
        let mut cells = 0;
        while x < b {
            if tail_on && tf - x <= tail_reach {
                // ∫_x^{t_far} − ∫_b^{t_far}, the second at most half the first (else march on).
                let within = (tf - x) * att.factor(x);
                if beyond <= half * within {
                    let mut tail = self.tail(falloff, tf, tf - x, within, att.j);
                    if beyond > R::ZERO {
                        tail -= self.tail(falloff, tf, tf - b, beyond, att.j);
                    }
                    acc += tail.max(R::ZERO);
                    break;
                }
            }
            let graded = b.min(tf - q * (tf - x));
            let mut y = graded;
            let mut inner = false;
            if cells + 1 >= MAX_CELLS {
                y = b;
            } else if has_peak {
                if x < tc - dmin {
                    // Approaching the peak: a fifth of the distance left, down to the inner cell.
                    y = y.min((tc - (tc - x) * approach).min(tc - dmin));
                } else if x < tc + dmin {
                    y = y.min(tc + dmin);
                    inner = true;
                } else {
                    // Leaving it: the distance times five.
                    y = y.min(x + leave * (x - tc).max(dmin));
                }
            }
            let advances = y > x; // false for NaN too
            if !advances {
                // The grading rounded away (a peak narrower than one ulp of t): a step of about
                // two ulps, which holds the peak's mass and from which the cells double again.
                let step = x.abs() * R::from_f64(2.0) * R::EPSILON;
                y = (x + step.max(R::MIN_POSITIVE)).min(b);
                if y <= x {
                    y = b;
                }
            }
            let i0 = self.integral(falloff, x, y);
            let gbar = if inner {
                self.mean_g_peak(falloff, x, y, att)
            } else {
                self.mean_g_line(falloff, x, y, att)
            };
            acc += i0 * gbar;
            used += i0;
            cells += 1;
            x = y;
            if x < b {
                let rest = (total - used).max(R::ZERO);
                if att.factor(x) * rest <= R::from_f64(REST_TOLERANCE) * acc {
                    break;
                }
            }
        }
        acc.max(R::ZERO).min(R::from_f64(ENERGY_MAX))
    }

    /// `∫_x^{t_far} (1 − t/t_far)^j w(t) dt` by 8-point Gauss–Laguerre, for `span = t_far − x`
    /// and `weight = span·g(x)`: with `u = (j + 1)·ln(h(x)/h(t))`, `h = 1 − t/t_far`, the
    /// attenuation times the measure is exactly `weight/(j + 1)·e^{−u} du`, so the rule only
    /// samples the density, at `t = t_far − span·e^{−u/(j+1)}` (8 nodes between `x` and `t_far`).
    #[inline(always)]
    fn tail(&self, falloff: Falloff, tf: R, span: R, weight: R, j: R) -> R {
        let j1 = j + R::ONE;
        let mut sum = R::ZERO;
        for (&u, &wu) in LAGUERRE_X.iter().zip(LAGUERRE_W.iter()) {
            let t = tf - span * (-R::from_f64(u) / j1).exp();
            sum += R::from_f64(wu) * density(falloff, self.s * t + self.beta, self.h);
        }
        weight / j1 * sum
    }

    /// `g` averaged over `[x, y]` against `w`, with 8 Gauss–Legendre nodes uniform in `t`
    /// (`Σ W_i·w(t_i)·g(t_i) / Σ W_i·w(t_i)`); the plain mean of `g` where the weights underflow.
    #[inline(always)]
    fn mean_g_line(&self, falloff: Falloff, x: R, y: R, att: &Attenuation<R>) -> R {
        let dt = y - x;
        let mut num = R::ZERO;
        let mut den = R::ZERO;
        let mut plain = R::ZERO;
        for (&xi, &wi) in GL_X.iter().zip(GL_W.iter()) {
            let t = x + R::from_f64(xi) * dt;
            let g = att.factor(t);
            let w = R::from_f64(wi) * density(falloff, self.s * t + self.beta, self.h);
            num += w * g;
            den += w;
            plain += R::from_f64(wi) * g;
        }
        if den > R::ZERO && den.is_finite() && num.is_finite() {
            num / den
        } else {
            plain
        }
    }

    /// `g` averaged over `[x, y]` against `w` on the inner cell around the peak (`s > 0`), with 8
    /// Gauss–Legendre nodes uniform in `ψ = asinh(Y/√H)` (faithful) or `θ = atan(Y/√H)`
    /// (inverse square), the variables in which `w dt` is uniform.
    #[inline(always)]
    fn mean_g_peak(&self, falloff: Falloff, x: R, y: R, att: &Attenuation<R>) -> R {
        let sh = self.h.sqrt();
        let (yx, yy) = ((self.s * x + self.beta) / sh, (self.s * y + self.beta) / sh);
        let (px, py) = match falloff {
            Falloff::Faithful => (yx.asinh(), yy.asinh()),
            Falloff::InverseSquare => (yx.atan(), yy.atan()),
        };
        let mut sum = R::ZERO;
        for (&xi, &wi) in GL_X.iter().zip(GL_W.iter()) {
            let p = px + R::from_f64(xi) * (py - px);
            // Y/√H at the node: sinh ψ or tan θ.
            let v = match falloff {
                Falloff::Faithful => {
                    let e = p.exp();
                    R::from_f64(0.5) * (e - R::ONE / e)
                }
                Falloff::InverseSquare => p.sin() / p.cos(),
            };
            let t = ((v * sh - self.beta) / self.s).clamp(x, y);
            sum += R::from_f64(wi) * att.factor(t);
        }
        sum
    }
}

/// [`super::sphere_energy`] with the attenuation `(1 − t/t_far)^j` (002 eq. 3.4, 3.6, 3.23;
/// SPEC.md §1.2, §1.4): `α_s ∫ g(t)/ρ` (faithful) or `α_s ∫ g(t)/ρ²` (inverse square) over
/// `[t0, min(t1, t_far)]`. `j = 0` is [`super::sphere_energy`] exactly.
#[inline]
pub fn sphere_energy_attenuated<R: Real>(
    p: &FieldParams<R>,
    ray: &Ray<R>,
    t0: R,
    t1: R,
    att: &Attenuation<R>,
    f: &SphereField<R>,
) -> R {
    let q = sphere_quadratic(p, ray, f.center);
    scaled(q.attenuated(p.falloff, t0, t1, att), f.alpha)
}

/// [`super::cylinder_energy`] with the attenuation `(1 − t/t_far)^j` (002 eq. 3.5, 3.7, 3.23;
/// SPEC.md §1.2, §1.4). `j = 0` is [`super::cylinder_energy`] exactly.
#[inline]
pub fn cylinder_energy_attenuated<R: Real>(
    p: &FieldParams<R>,
    ray: &Ray<R>,
    t0: R,
    t1: R,
    att: &Attenuation<R>,
    f: &CylinderField<R>,
) -> R {
    let q = cylinder_quadratic(p, ray, f);
    scaled(q.attenuated(p.falloff, t0, t1, att), f.alpha)
}

/// [`super::capsule_energy`] with the attenuation `(1 − t/t_far)^j` (002 eq. 3.10–3.11, 3.23;
/// SPEC.md §1.2, §1.4): the same split at the planes through `M` and `M₂`, each piece attenuated
/// in the ray's own parameter. `j = 0` is [`super::capsule_energy`] exactly.
#[inline]
pub fn capsule_energy_attenuated<R: Real>(
    p: &FieldParams<R>,
    ray: &Ray<R>,
    t0: R,
    t1: R,
    att: &Attenuation<R>,
    f: &CapsuleField<R>,
) -> R {
    capsule_parts(p, ray, t0, t1, f, |q, a, b| q.attenuated(p.falloff, a, b, att)).energy
}

/// [`super::beam_energy`] with the attenuation `(1 − t/t_far)^j` (002 §3.3.3, eq. 3.4, 3.11,
/// 3.23; SPEC.md §1.2, §1.4): the attenuated capsule plus the attenuated bulbs at `M₂` and `M`.
/// `j = 0` is [`super::beam_energy`] exactly.
#[inline]
pub fn beam_energy_attenuated<R: Real>(
    p: &FieldParams<R>,
    ray: &Ray<R>,
    t0: R,
    t1: R,
    att: &Attenuation<R>,
    f: &BeamField<R>,
) -> R {
    let piece = |q: &RayQuadratic<R>, a: R, b: R| q.attenuated(p.falloff, a, b, att);
    let parts = capsule_parts(p, ray, t0, t1, &f.capsule, piece);
    let mut e = parts.energy;
    if f.head_alpha != R::ZERO {
        e = saturate(e + scaled(piece(&parts.at_m2, t0, t1), f.head_alpha));
    }
    if f.muzzle_alpha != R::ZERO {
        e = saturate(e + scaled(piece(&parts.at_m, t0, t1), f.muzzle_alpha));
    }
    e
}
