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
//! for `j` beyond a few, so [`RayQuadratic::attenuated`] integrates by 4-point Gauss–Legendre on
//! graded cells in the variable `u = −ln h`, `h = 1 − t/t_far`, in which the attenuation is an
//! exponential: `g dt = t_far·e^{−(j+1)u} du`. On a cell `[x, y]` with `span = t_far − x` and
//! `Δu = −ln(1 − (y − x)/span)`, `∫ g w dt = g(x)·span·Δu·∫_0^1 e^{−(j+1)Δu·ξ} w(t(ξ)) dξ`,
//! `t(ξ) = x − span·expm1(−ξΔu)`, so the rule's nodes and weights need one `ln_1p` per cell and
//! exponentials of known arguments, no power of `h` at a node, and `g(x)` is carried from cell
//! to cell; `w` is sampled at the nodes and `∫ w dt` (what the early stop counts) comes from the
//! same nodes:
//!
//! - cells shrink geometrically towards `t_far`: each spans at most `Δu = FAR_STEP/(j + 1)`
//!   ([`FAR_STEP`]), so the weight `e^{−(j+1)Δu·ξ}` varies by at most `e^{−FAR_STEP}` on a cell
//!   (4 nodes integrate it to `5.6·10⁻¹⁰·FAR_STEP⁸`), and `g`'s branch point is at `u = ∞`.
//!   Such a cell's nodes and weights depend only on `j`: the eight-lane march takes them once
//!   per wave (on the benchmark's sphere rays, 40 % of its passes have every lane on one);
//! - cells grow geometrically away from the peak, so that `w`'s complex poles `t_c ± iε` stay a
//!   cell length away in the rule's variable (Bernstein ellipse `ρ ≥ 3 + √8`): approaching,
//!   `t_c − t` halves per cell (in `u` the cell is then no longer than in `t` relative to its
//!   distance to the pole, `ln` being concave); leaving, a cell at distance `m = max(t − t_c, ε)`
//!   spans `Δu ≤ ln(1 + m/span)`, the pole's distance in `u` (`t_far − y ≥ span²/(span + m)`);
//!   the `t`-rule's doubling (`y = x + m`) gives up to 1.7× longer cells in `u` than their
//!   distance, and raised the worst `f64` error of `tests/analytic_attenuation.rs` to `8.6·10⁻⁵`;
//! - the inner cell `|t − t_c| ≤ ε` is integrated in the variable in which `w dt` is uniform,
//!   `ψ = asinh(Y/√H)` (faithful) or `θ = atan(Y/√H)` (inverse square; `|θ| ≤ π/4` keeps the
//!   poles of `t(θ) ∝ tan θ` twice the cell's half-width away), so the peak itself needs no
//!   refinement however narrow it is (`H` down to `H_FLOOR`); its weight `∫w` is the closed form
//!   and the rule only averages `g` against it (`I_cell·ḡ_cell`). A peak narrower than the
//!   spacing of `t`'s floating-point values is approached by halving down to that spacing, its
//!   mass then taken by the closed form over one step of it; so is every cell shorter than
//!   [`RESOLVED_CELL`] steps of `t` (whose nodes would round onto such a peak), the capped last
//!   cell and a cell that reaches `t_far`;
//! - the march stops once the rest cannot add more than `10⁻⁵` of the sum: `g` falls along the
//!   ray, so the rest is at most `g(x)·(I − Σ ∫_cell w)`, `I` the unattenuated integral;
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
//! The 4-point rule on a cell whose nearest singularity is a cell length away (Bernstein ellipse
//! `ρ = 3 + √8`) errs by about `ρ⁻⁸ ≈ 10⁻⁶` relative; the weight `e^{−(j+1)Δu·ξ}` grows on that
//! ellipse by up to `e^{FAR_STEP·(ρ + 1/ρ)/4}`, which is why `FAR_STEP` stays near 1 (at 1.3 the
//! worst error of the inverse square rose from `1.9·10⁻⁵` to `3.8·10⁻⁵`, at 2 to `7.9·10⁻⁵`);
//! `tests/analytic_attenuation.rs` holds the result to an `f64` adaptive quadrature of the
//! densities written from their definitions
//! (p99 relative error ≤ 10⁻³ in `f32` over random rays and degenerate ones). A ray through a
//! centre with `r_c = 0` needs about `2·log₂(span/ε)` cells; the march is capped at
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

/// Gauss–Legendre nodes on `[0, 1]` (4 points).
pub(super) const GL_X: [f64; 4] =
    [0.069_431_844_202_973_71, 0.330_009_478_207_571_9, 0.669_990_521_792_428_1, 0.930_568_155_797_026_3];
/// Gauss–Legendre weights on `[0, 1]` (sum 1).
pub(super) const GL_W: [f64; 4] =
    [0.173_927_422_568_726_93, 0.326_072_577_431_273_07, 0.326_072_577_431_273_07, 0.173_927_422_568_726_93];

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

/// A cell spans at most `FAR_STEP/(j + 1)` in `u = −ln(1 − t/t_far)` (the grading towards
/// `t_far`; see this module's documentation): on it the rule's weight `e^{−(j+1)u}` (002 eq.
/// 3.23, SPEC.md §1.4) varies by at most `e^{−FAR_STEP}`. At `j = 8` the cells are those of the
/// earlier grading in `t` (`t_far − t` falling by `e^{−1/j}`).
pub const FAR_STEP: f64 = 1.125;

/// A cell shorter than `RESOLVED_CELL·ε·|x|` (`ε` the type's epsilon) is weighted by the closed
/// form, as the inner cell is: its nodes are not resolved well enough in `t` to sample a density
/// whose peak may sit one rounding step away.
pub const RESOLVED_CELL: f64 = 4096.0;

/// Most cells one piece is cut into; the rest of the span is then one last cell.
pub const MAX_CELLS: u32 = 192;

/// The march stops once the rest is at most this fraction of the sum so far.
pub const REST_TOLERANCE: f64 = 1e-5;

/// A peak is graded only where `|t_c|` and `ε` are below this (`s` is not vanishingly small).
pub const PEAK_RANGE: f64 = 1e20;

/// Half-width of the inner cell around the peak, in units of the peak's half-width `ε = √H/s`.
pub const INNER_CELL: f64 = 1.0;

/// `e^v − 1` without the cancellation of `exp(v) − 1` near 0 (Kahan's `(u − 1)·v/ln u`, `u = e^v`).
#[inline(always)]
fn exp_m1<R: Real>(v: R) -> R {
    let u = v.exp();
    if u == R::ONE {
        v
    } else if (u - R::ONE).abs() < R::from_f64(0.5) {
        (u - R::ONE) * v / u.ln()
    } else {
        u - R::ONE
    }
}

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
    /// of 002 eq. 3.23 (SPEC.md §1.4), 0 from the far point on. Graded 4-point Gauss–Legendre
    /// cells uniform in `u = −ln(1 − t/t_far)` (the inner cell around the peak weighted by the
    /// closed form), then one 8-point Gauss–Laguerre step over the far tail
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
        // A far-graded cell spans FAR_STEP/(j + 1) in u = −ln(1 − t/t_far): t_far − t falls by q.
        let q = (-R::from_f64(FAR_STEP) / (att.j + R::ONE)).exp();
        let half = R::from_f64(0.5);
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
        // g(x), carried from cell to cell.
        let mut g = att.factor(a);
        let mut acc = R::ZERO;
        let mut used = R::ZERO;
        let mut cells = 0;
        while x < b {
            let span = tf - x;
            if tail_on && span <= tail_reach {
                // ∫_x^{t_far} − ∫_b^{t_far}, the second at most half the first (else march on).
                let within = span * g;
                if beyond <= half * within {
                    let mut tail = self.tail(falloff, tf, span, within, att.j);
                    if beyond > R::ZERO {
                        tail -= self.tail(falloff, tf, tf - b, beyond, att.j);
                    }
                    acc += tail.max(R::ZERO);
                    break;
                }
            }
            let graded = b.min(tf - q * span);
            let mut y = graded;
            let mut inner = false;
            let mut whole = false;
            if cells + 1 >= MAX_CELLS {
                y = b;
                whole = true;
            } else if has_peak {
                if x < tc - dmin {
                    // Approaching the peak: halve the distance, down to the inner cell.
                    y = y.min((tc - (tc - x) * half).min(tc - dmin));
                } else if x < tc + dmin {
                    y = y.min(tc + dmin);
                    inner = true;
                } else {
                    // Leaving it: at most the distance m to the peak, in u (t_far − y ≥
                    // span²/(span + m)).
                    let m = (x - tc).max(dmin);
                    y = y.min(x + span * m / (span + m));
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
                whole = true;
            }
            // h(y)/h(x) = e^{−Δu}, in (0, 1) on a cell of the u rule.
            // (false where it is not, or NaN).
            let in_range = (tf - y) / span > R::ZERO;
            // A cell too short for its nodes to be told apart from its ends (next to a peak
            // narrower than the rounding of t) takes its mass from the closed form.
            let fine = y - x <= R::from_f64(RESOLVED_CELL) * R::EPSILON * x.abs();
            if inner || whole || fine || !in_range {
                let i0 = self.integral(falloff, x, y);
                let gbar = if inner {
                    self.mean_g_peak(falloff, x, y, att)
                } else {
                    self.mean_g_line(falloff, x, y, att)
                };
                acc += i0 * gbar;
                used += i0;
                g = att.factor(y);
            } else {
                let (piece, mass) = self.cell_u(falloff, x, y, span, att.j);
                acc += g * piece;
                used += mass;
                g = att.factor(y);
            }
            cells += 1;
            x = y;
            if x < b {
                let rest = (total - used).max(R::ZERO);
                if g * rest <= R::from_f64(REST_TOLERANCE) * acc {
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

    /// One cell `[x, y]` of the u rule, `span = t_far − x`, `Δu = −ln_1p(−(y − x)/span)`:
    /// `(∫ g w dt / g(x), ∫ w dt)` by 4 Gauss–Legendre nodes uniform in `u = −ln(1 − t/t_far)`,
    /// in which `g dt = g(x)·span·e^{−(j+1)(u − u_x)} du` exactly (002 eq. 3.23, SPEC.md §1.4):
    /// the nodes are `t_i = x − span·expm1(−ξ_iΔu)` (no cancellation however short the cell),
    /// the weights `W_i·Δu·span·e^{−(j+1)ξ_iΔu}` (and `e^{−ξ_iΔu}` for the unattenuated mass), so
    /// no power of `h` is taken at a node.
    #[inline(always)]
    fn cell_u(&self, falloff: Falloff, x: R, y: R, span: R, j: R) -> (R, R) {
        let lr = (-(y - x) / span).ln_1p(); // −Δu
        let j1 = j + R::ONE;
        let mut num = R::ZERO;
        let mut den = R::ZERO;
        for (&xi, &wi) in GL_X.iter().zip(GL_W.iter()) {
            let em1 = exp_m1(R::from_f64(xi) * lr);
            let e = R::ONE + em1;
            let t = x - span * em1;
            let w = R::from_f64(wi) * density(falloff, self.s * t + self.beta, self.h);
            num += w * (j1 * R::from_f64(xi) * lr).exp();
            den += w * e;
        }
        let scale = -lr * span;
        (scale * num, scale * den)
    }

    /// `g` averaged over `[x, y]` against `w`, with 4 Gauss–Legendre nodes uniform in `t`
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

    /// `g` averaged over `[x, y]` against `w` on the inner cell around the peak (`s > 0`), with 4
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
