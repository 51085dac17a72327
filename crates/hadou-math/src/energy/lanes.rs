//! The analytic kernels eight rays at a time: the same closed forms as [`RayQuadratic`], on any
//! [`Lane`] type (the portable `wide::f32x8`, or AVX2 lanes chosen at run time through
//! [`crate::simd::dispatch`]), with every branch of the scalar kernel turned into a per-lane
//! select.
//!
//! Rays of one batch share their origin (the eye) and carry their own direction and span, as the
//! CPU backend's pixels do. Each function here agrees with its scalar twin in `f32` within a few
//! units in the last place (the logarithm and `atan2` are polynomial ones, `wide`'s or
//! [`Lane`]'s, rather than the maths library's; the AVX2 lanes fuse multiply-adds), is finite and non-negative on every ray the scalar tests cover (through
//! a centre, along an axis, far away, `r_c = 0`, empty or NaN spans), and saturates the same way
//! (`tests/analytic_lanes.rs` holds them to the scalar kernels and to the `f64` reference).
//!
//! # Distance attenuation
//! The `*_attenuated` kernels add the attenuation `(1 − t/t_far)^j` of 002 eq. 3.23 (SPEC.md
//! §1.4) with a per-lane `t_far` ([`AttenuationLanes`]), by the march of
//! [`RayQuadratic::attenuated`] run on all eight rays at once: one loop whose every pass cuts one
//! cell per lane, each lane keeping its own position, sums, cell count and active mask, with the
//! scalar march's grading (geometric towards `t_far` and away from the peak, the inner cell in
//! `ψ = asinh(Y/√H)` or `θ = atan(Y/√H)`, the ulp step), early stop and cell cap applied per
//! lane by selects; the loop ends when no lane is active ([`Lane::bitmask`]), so a batch costs
//! its slowest lane's cells (at most [`MAX_CELLS`]). Each lane takes the far tail in one
//! Gauss–Laguerre step where the scalar march does (and is then done); a pass whose lanes mix
//! the line and peak rules takes one power per node (`Quad::mean_g_mixed`). The powers are
//! products by repeated squaring for an integer `j` up to [`INTEGER_J_MAX`], else `exp(j·ln h)`;
//! they, `sinh`, `tan`, `asinh` and `atan` are the lane polynomials of [`Lane`], so each lane
//! cuts the scalar march's cells up to rounding and agrees with it to about `10⁻⁵` relative
//! (`tests/analytic_attenuation_lanes.rs`). `j = 0` (or NaN) runs the unattenuated kernels.
//!
//! [`RayQuadratic`]: super::RayQuadratic
//! [`RayQuadratic::attenuated`]: super::RayQuadratic::attenuated

use super::attenuated::{
    tail_reach, APPROACH_RATIO, FAR_GRADE, FAR_RATIO_MIN, GL_W, GL_X, INNER_CELL, LAGUERRE_W, LAGUERRE_X,
    LEAVE_GROWTH, MAX_CELLS, PEAK_RANGE, REST_TOLERANCE, TAIL_MIN_J,
};
use super::field::{BeamField, CapsuleField, CylinderField, Falloff, FieldParams, SphereField};
use super::kernel::{ENERGY_MAX, ENERGY_SATURATION, H_FLOOR, T_LIMIT};
use crate::simd::{Lane, Outlined};
use crate::Vec3;

/// Rays evaluated together.
pub const LANES: usize = 8;

/// One `f32` per ray of a batch, on the portable path ([`crate::simd::Portable`]).
pub type Lanes = crate::simd::Portable;

/// A 3-vector per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3<L = Lanes> {
    /// x of every lane.
    pub x: L,
    /// y of every lane.
    pub y: L,
    /// z of every lane.
    pub z: L,
}

impl<L: Lane> V3<L> {
    /// The same vector in every lane.
    #[inline(always)]
    pub fn splat(v: Vec3<f32>) -> Self {
        Self { x: L::splat(v.x), y: L::splat(v.y), z: L::splat(v.z) }
    }

    /// Lane `i` of each component taken from `v[i]`.
    #[inline(always)]
    pub fn from_vecs(v: &[Vec3<f32>; LANES]) -> Self {
        Self {
            x: L::from_array(v.map(|p| p.x)),
            y: L::from_array(v.map(|p| p.y)),
            z: L::from_array(v.map(|p| p.z)),
        }
    }

    #[inline(always)]
    fn dot(self, o: Self) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }

    #[inline(always)]
    fn scale(self, k: L) -> Self {
        Self { x: self.x * k, y: self.y * k, z: self.z * k }
    }

    /// `self × d` for a vector `d` shared by every lane (as [`Vec3::cross`]).
    #[inline(always)]
    fn cross_splat(self, d: Vec3<f32>) -> Self {
        self.cross(Self::splat(d))
    }
}

/// Eight rays `origin + t·dir[i]`, `t ∈ [t0[i], t1[i]]`, sharing one origin (see
/// [`super::Ray`] for what `dir` means per falloff).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayLanes<L = Lanes> {
    /// The shared origin `S`.
    pub origin: Vec3<f32>,
    /// Each ray's direction.
    pub dir: V3<L>,
    /// Each span's start.
    pub t0: L,
    /// Each span's end.
    pub t1: L,
}

/// [`super::RayAxis`] per lane: `s = |u|`, `û = u/s`, or `s = 0`, `û = 0` where `|u|²` is not a
/// positive normal number.
#[derive(Clone, Copy)]
struct Axis<L> {
    s: L,
    unit: V3<L>,
}

impl<L: Lane> Axis<L> {
    #[inline(always)]
    fn new(u: V3<L>) -> Self {
        let a = u.dot(u);
        let ok = a.simd_ge(L::splat(f32::MIN_POSITIVE));
        let s = ok.select(a.sqrt(), L::splat(0.0));
        let inv = ok.select(L::splat(1.0) / s, L::splat(0.0));
        Self { s, unit: u.scale(inv) }
    }
}

/// [`super::RayQuadratic`] per lane: `|v + t·u|² + r_c² = (s·t + β)² + H`.
#[derive(Clone, Copy)]
struct Quad<L> {
    s: L,
    beta: L,
    h: L,
}

impl<L: Lane> Quad<L> {
    /// As [`super::RayQuadratic::new`].
    #[inline(always)]
    fn new(axis: &Axis<L>, v: V3<L>, rc2: f32) -> Self {
        let beta = axis.unit.dot(v);
        let c = axis.unit.cross(v);
        let d2 = axis.s.simd_gt(L::splat(0.0)).select(c.dot(c), v.dot(v));
        Self { s: axis.s, beta, h: (d2 + L::splat(rc2)).max(L::splat(H_FLOOR as f32)) }
    }

    /// Lane-wise `if m { a } else { b }`.
    #[inline(always)]
    fn select(m: L, a: &Self, b: &Self) -> Self {
        Self { s: a.s, beta: m.select(a.beta, b.beta), h: m.select(a.h, b.h) }
    }

    /// `∫ dt / sqrt(Y² + H)` over `[t0, t1]` per lane: the scalar
    /// [`super::RayQuadratic::faithful`] (002 eq. 3.8–3.9 with SPEC.md §1.2's corrected `asinh`,
    /// as `ln(P₁/P₀)` from positive terms), its sign branches as selects.
    ///
    /// The last step differs in form, not in value: with `z = s·k`, the scalar `ln(1 + z)/s` (or
    /// `ln_1p(z)/s`, or `k` as `s → 0`) is here `k · ln(u)/(u − 1)`, `u = 1 + z` (the ratio is 1
    /// where `u` rounds to 1). `ln(u)/(u − 1)` equals `ln(1 + z)/z` to a few ulp because the
    /// rounding of `u` cancels between numerator and denominator, so one formula covers every
    /// `z ≥ 0` and needs no division by `s`.
    #[inline(always)]
    fn faithful(&self, t0: L, t1: L) -> L {
        let lim = L::splat(T_LIMIT as f32);
        let t0c = t0.max(-lim);
        let t1c = t1.min(lim);
        // False for NaN ends and empty spans, before and after the clamps (as the scalar kernel).
        let live = t1.simd_gt(t0) & t1c.simd_gt(t0c);
        let (s, h) = (self.s, self.h);
        let dt = t1c - t0c;
        let y0 = s * t0c + self.beta;
        let y1 = s * t1c + self.beta;
        let r0 = (y0 * y0 + h).sqrt();
        let r1 = (y1 * y1 + h).sqrt();
        let sum = y0 + y1;
        let rs = r0 + r1;
        let one = L::splat(1.0);
        let ahead = sum.simd_ge(L::splat(0.0));
        // sum ≥ 0: P₀ = y₀ + r₀, or H/(r₀ − y₀) for y₀ < 0; else N₁ = r₁ − y₁, or H/(r₁ + y₁).
        let y0_pos = y0.simd_ge(L::splat(0.0));
        let y1_neg = y1.simd_le(L::splat(0.0));
        let a_fwd = y0_pos.select(one, r0 - y0);
        let b_fwd = y0_pos.select(y0 + r0, h);
        let a_bwd = y1_neg.select(one, r1 + y1);
        let b_bwd = y1_neg.select(r1 - y1, h);
        let num = ahead.select(rs + sum, rs - sum);
        let a = ahead.select(a_fwd, a_bwd);
        let b = ahead.select(b_fwd, b_bwd);
        let k = dt * num * a / (rs * b);
        let u = one + s * k;
        let ratio = u.simd_gt(one).select(u.ln() / (u - one), one);
        let v = k * ratio;
        // u = +∞ (k overflowed): ln(u)/(u − 1) is NaN; the integral is then beyond ENERGY_MAX.
        let v = u.is_inf().select(L::splat(f32::INFINITY), v);
        clamp_energy(live, v)
    }

    /// `∫ dt / (Y² + H)` over `[t0, t1]` per lane: the scalar
    /// [`super::RayQuadratic::inverse_square`] (one `atan2(√H·s·Δt, H + Y₀Y₁)`, `t ≥ T_LIMIT` as
    /// `±∞`), its branches as selects.
    #[inline(always)]
    fn inverse_square(&self, t0: L, t1: L) -> L {
        let lim = L::splat(T_LIMIT as f32);
        let live = t1.simd_gt(t0);
        let (s, h) = (self.s, self.h);
        let sh = h.sqrt();
        let y0 = s * t0 + self.beta;
        let y1 = s * t1 + self.beta;
        let to_inf = t1.simd_ge(lim);
        let from_inf = t0.simd_le(-lim);
        let finite = !(to_inf | from_inf);
        let dt = t1 - t0;
        let num_f = sh * s * dt;
        let den_f = h + y0 * y1;
        // Infinite ends: (√H, Y₀) to +∞, (√H, −Y₁) from −∞, (0, −1) for the whole line.
        let num_i = (to_inf & from_inf).select(L::splat(0.0), sh);
        let den_i = from_inf.select(to_inf.select(-L::splat(1.0), -y1), y0);
        let num = finite.select(num_f, num_i);
        let den = finite.select(den_f, den_i);
        let angle = num.atan2(den) / (s * sh);
        let tiny = finite & num_f.simd_le(L::splat(f32::EPSILON) * den_f);
        let v = tiny.select(dt / den_f, angle);
        clamp_energy(live, v)
    }

    /// The closed form of `falloff` over `[t0, t1]` per lane ([`Lane::outlined_if_unoptimized`]:
    /// a frame of its own in an unoptimized build).
    #[inline(always)]
    fn integral(&self, falloff: Falloff, t0: L, t1: L) -> L {
        L::outlined_if_unoptimized(Integral { quad: *self, falloff, t0, t1 })
    }
}

/// [`Quad::integral`] as a body for [`Lane::outlined_if_unoptimized`].
struct Integral<L> {
    quad: Quad<L>,
    falloff: Falloff,
    t0: L,
    t1: L,
}

impl<L: Lane> Outlined<L> for Integral<L> {
    type Output = L;
    #[inline(always)]
    fn run(self) -> L {
        match self.falloff {
            Falloff::Faithful => self.quad.faithful(self.t0, self.t1),
            Falloff::InverseSquare => self.quad.inverse_square(self.t0, self.t1),
        }
    }
}

impl<L: Lane> Quad<L> {
    /// The scalar [`super::RayQuadratic::attenuated`] on eight rays: `∫_{t0}^{min(t1, t_far)}
    /// (1 − t/t_far)^j w(t) dt` (002 eq. 3.23, SPEC.md §1.4) by 8-point Gauss–Legendre on graded
    /// cells weighted by the closed form, as one masked loop (see the [module docs](self)). Each
    /// lane cuts the scalar march's cells: the same grading, ulp step, early stop
    /// ([`REST_TOLERANCE`](super::REST_TOLERANCE)) and cap ([`MAX_CELLS`](super::MAX_CELLS));
    /// lanes whose span is empty, NaN, beyond `t_far`, or whose `t_far` is not positive and
    /// finite, give 0 and take no pass. `j = 0` (or NaN) is [`Self::integral`].
    ///
    /// The march runs in a function of its own ([`Lane::outlined`], [`March`]): inlined, each of
    /// a beam's five pieces would add the march's lane temporaries to the dispatched body's frame,
    /// which in an unoptimized build (a slot per temporary) outgrows a thread's stack.
    ///
    /// Mirrors `RayQuadratic::attenuated` (keep in sync).
    #[inline(always)]
    fn attenuated(&self, falloff: Falloff, t0: L, t1: L, att: &AttenuationLanes<L>) -> L {
        if !att.is_active() {
            return self.integral(falloff, t0, t1);
        }
        L::outlined(March { quad: *self, falloff, t0, t1, att: *att })
    }

    /// [`Self::attenuated`]'s march (`j > 0`) in place: what [`March`] runs.
    #[inline(always)]
    fn march(&self, falloff: Falloff, t0: L, t1: L, att: &AttenuationLanes<L>) -> L {
        let k = L::splat;
        let zero = k(0.0);
        let tf = att.t_far;
        let a = t0.max(k(-T_LIMIT as f32));
        let b = t1.min(tf);
        // False for NaN ends, empty spans and spans beyond the far point.
        let live = b.simd_gt(a) & tf.simd_gt(zero) & tf.simd_lt(k(f32::INFINITY));
        let (a, b) = (live.select(a, zero), live.select(b, zero));
        let total = self.integral(falloff, a, b);
        let mut active = live & total.simd_gt(zero);
        if active.bitmask() == 0 {
            return zero;
        }
        let (s, h) = (self.s, self.h);
        let sh = h.sqrt();
        // A peak only where t_c = −β/s and ε = √H/s stay far below overflow.
        let range = s * k(PEAK_RANGE as f32);
        let has_peak = s.simd_gt(zero) & sh.simd_le(range) & self.beta.max(-self.beta).simd_le(range);
        let tc = has_peak.select(-self.beta / s, zero);
        let dmin = has_peak.select(k(INNER_CELL as f32) * (sh / s), zero);
        // The same ratio as the scalar march (taken once with the attenuation: `MarchConstants`).
        let q = k(att.march.q);
        let approach = k(APPROACH_RATIO as f32);
        let leave = k(LEAVE_GROWTH as f32);
        let last_cell = k((MAX_CELLS - 1) as f32);
        let tolerance = k(REST_TOLERANCE as f32);
        // The far tail (the scalar march's): where the peak's singularities are far from t_far.
        let tail_on = att.j >= TAIL_MIN_J as f32;
        let (tail_reach, beyond, nodes) = if tail_on {
            let dc = tf - tc;
            let eps = sh / s;
            let far = (dc * dc + eps * eps).sqrt() / k(att.march.reach);
            let nodes = att.march.nodes.map(k);
            (has_peak.select(far, k(f32::INFINITY)), (tf - b) * att.factor(b), nodes)
        } else {
            (zero, zero, [zero; 8])
        };
        let mut x = a;
        let mut acc = zero;
        let mut used = zero;
        let mut cells = zero;
        while active.bitmask() != 0 {
            if tail_on {
                let near = (tf - x).simd_le(tail_reach);
                if (active & near).bitmask() != 0 {
                    // ∫_x^{t_far} − ∫_b^{t_far}, the second at most half the first.
                    let within = (tf - x) * att.factor(x);
                    let now = active & near & beyond.simd_le(k(0.5) * within);
                    if now.bitmask() != 0 {
                        let mut tail = self.tail(falloff, tf, tf - x, within, att.j, &nodes);
                        if (now & beyond.simd_gt(zero)).bitmask() != 0 {
                            let past = self.tail(falloff, tf, tf - b, beyond, att.j, &nodes);
                            tail = tail - beyond.simd_gt(zero).select(past, zero);
                        }
                        acc += now.select(tail.max(zero), zero);
                        active = active & !now;
                        if active.bitmask() == 0 {
                            break;
                        }
                    }
                }
            }
            let graded = b.min(tf - q * (tf - x));
            let capped = cells.simd_ge(last_cell);
            // Approaching the peak: a fifth of the distance left, down to the inner cell; inside
            // it: to its end; leaving it: the distance times five.
            let before = x.simd_lt(tc - dmin);
            let within = x.simd_lt(tc + dmin);
            let y_before = graded.min((tc - (tc - x) * approach).min(tc - dmin));
            let y_within = graded.min(tc + dmin);
            let y_after = graded.min(x + leave * (x - tc).max(dmin));
            let y_peak = before.select(y_before, within.select(y_within, y_after));
            let y = capped.select(b, has_peak.select(y_peak, graded));
            let inner = has_peak & !capped & !before & within;
            // The grading rounded away (a peak narrower than one ulp of t): about two ulps.
            let step = (x.max(-x) * k(2.0 * f32::EPSILON)).max(k(f32::MIN_POSITIVE));
            let nudged = (x + step).min(b);
            let nudged = nudged.simd_gt(x).select(nudged, b);
            let y = y.simd_gt(x).select(y, nudged);
            let i0 = self.integral(falloff, x, y);
            let any_line = (active & !inner).bitmask() != 0;
            let any_inner = (active & inner).bitmask() != 0;
            let gbar = if any_line && any_inner {
                self.mean_g_mixed(falloff, x, y, att, inner)
            } else if any_inner {
                self.mean_g_peak(falloff, x, y, att)
            } else {
                self.mean_g_line(falloff, x, y, att)
            };
            acc += active.select(i0 * gbar, zero);
            used += active.select(i0, zero);
            cells += active.select(k(1.0), zero);
            x = active.select(y, x);
            let rest = (total - used).max(zero);
            let done = (att.factor(x) * rest).simd_le(tolerance * acc);
            active = active & x.simd_lt(b) & !done;
        }
        clamp_energy(live, acc)
    }

    /// The far tail `∫_x^{t_far} g w dt` by 8-point Gauss–Laguerre for `span = t_far − x` and
    /// `weight = span·g(x)`, `nodes` the factors `e^{−u_i/(j+1)}` (the scalar `tail`).
    #[inline(always)]
    fn tail(&self, falloff: Falloff, tf: L, span: L, weight: L, j: f32, nodes: &[L; 8]) -> L {
        let k = L::splat;
        let mut sum = k(0.0);
        for (e, &wu) in nodes.iter().zip(LAGUERRE_W.iter()) {
            let t = tf - span * *e;
            let yv = self.s * t + self.beta;
            let r2 = yv * yv + self.h;
            let density = match falloff {
                Falloff::Faithful => k(1.0) / r2.sqrt(),
                Falloff::InverseSquare => k(1.0) / r2,
            };
            sum += k(wu as f32) * density;
        }
        weight / k(j + 1.0) * sum
    }

    /// `g` averaged over `[x, y]` against `w` with 8 Gauss–Legendre nodes uniform in `t`, the
    /// plain mean of `g` where the weights underflow (the scalar `mean_g_line`).
    #[inline(always)]
    fn mean_g_line(&self, falloff: Falloff, x: L, y: L, att: &AttenuationLanes<L>) -> L {
        let k = L::splat;
        let dt = y - x;
        let mut num = k(0.0);
        let mut den = k(0.0);
        let mut plain = k(0.0);
        for (&xi, &wi) in GL_X.iter().zip(GL_W.iter()) {
            let wi = k(wi as f32);
            let t = x + k(xi as f32) * dt;
            let g = att.factor(t);
            let yv = self.s * t + self.beta;
            let r2 = yv * yv + self.h;
            let density = match falloff {
                Falloff::Faithful => k(1.0) / r2.sqrt(),
                Falloff::InverseSquare => k(1.0) / r2,
            };
            let w = wi * density;
            num += w * g;
            den += w;
            plain += wi * g;
        }
        let ok = den.simd_gt(k(0.0)) & finite(den) & finite(num);
        ok.select(num / den, plain)
    }

    /// [`Self::mean_g_peak`] on the `inner` lanes and [`Self::mean_g_line`] on the others, with
    /// one power per node: each lane's node positions are chosen first, then `g` is taken once
    /// at them (a pass in which the lanes disagree would otherwise pay for both rules' powers).
    #[inline(always)]
    fn mean_g_mixed(&self, falloff: Falloff, x: L, y: L, att: &AttenuationLanes<L>, inner: L) -> L {
        let k = L::splat;
        let sh = self.h.sqrt();
        let (yx, yy) = ((self.s * x + self.beta) / sh, (self.s * y + self.beta) / sh);
        let (px, py) = match falloff {
            Falloff::Faithful => (yx.asinh(), yy.asinh()),
            Falloff::InverseSquare => (yx.atan(), yy.atan()),
        };
        let dt = y - x;
        let mut num = k(0.0);
        let mut den = k(0.0);
        let mut plain = k(0.0);
        for (&xi, &wi) in GL_X.iter().zip(GL_W.iter()) {
            let wi = k(wi as f32);
            // The line rule's node and weight.
            let t_line = x + k(xi as f32) * dt;
            let yv = self.s * t_line + self.beta;
            let r2 = yv * yv + self.h;
            let density = match falloff {
                Falloff::Faithful => k(1.0) / r2.sqrt(),
                Falloff::InverseSquare => k(1.0) / r2,
            };
            // The peak rule's node.
            let p = px + k(xi as f32) * (py - px);
            let v = match falloff {
                Falloff::Faithful => {
                    let e = p.exp();
                    k(0.5) * (e - k(1.0) / e)
                }
                Falloff::InverseSquare => p.tan(),
            };
            let t_peak = ((v * sh - self.beta) / self.s).max(x).min(y);
            let g = att.factor(inner.select(t_peak, t_line));
            let w = wi * density;
            num += w * g;
            den += w;
            plain += wi * g;
        }
        let ok = den.simd_gt(k(0.0)) & finite(den) & finite(num);
        // The peak rule's mean is the plain one at its nodes.
        inner.select(plain, ok.select(num / den, plain))
    }

    /// `g` averaged over `[x, y]` against `w` on the inner cell around the peak, with 4
    /// Gauss–Legendre nodes uniform in `ψ = asinh(Y/√H)` (faithful; `Y/√H = sinh ψ` from
    /// [`Lane::exp`]) or `θ = atan(Y/√H)` (inverse square; `Y/√H = tan θ`, [`Lane::tan`]): the
    /// scalar `mean_g_peak`. Lanes without a peak (`s = 0`) give garbage, which the caller
    /// selects away; node positions are clamped to `[x, y]` (a NaN one to `x`).
    #[inline(always)]
    fn mean_g_peak(&self, falloff: Falloff, x: L, y: L, att: &AttenuationLanes<L>) -> L {
        let k = L::splat;
        let sh = self.h.sqrt();
        let (yx, yy) = ((self.s * x + self.beta) / sh, (self.s * y + self.beta) / sh);
        let (px, py) = match falloff {
            Falloff::Faithful => (yx.asinh(), yy.asinh()),
            Falloff::InverseSquare => (yx.atan(), yy.atan()),
        };
        let mut sum = k(0.0);
        for (&xi, &wi) in GL_X.iter().zip(GL_W.iter()) {
            let p = px + k(xi as f32) * (py - px);
            let v = match falloff {
                Falloff::Faithful => {
                    let e = p.exp();
                    k(0.5) * (e - k(1.0) / e)
                }
                Falloff::InverseSquare => p.tan(),
            };
            let t = ((v * sh - self.beta) / self.s).max(x).min(y);
            sum += k(wi as f32) * att.factor(t);
        }
        sum
    }
}

/// [`Quad::attenuated`]'s march as a body for [`Lane::outlined`].
struct March<L> {
    quad: Quad<L>,
    falloff: Falloff,
    t0: L,
    t1: L,
    att: AttenuationLanes<L>,
}

impl<L: Lane> Outlined<L> for March<L> {
    type Output = L;
    #[inline(always)]
    fn run(self) -> L {
        self.quad.march(self.falloff, self.t0, self.t1, &self.att)
    }
}

/// The largest integer exponent [`AttenuationLanes::factor`] takes by repeated squaring.
pub const INTEGER_J_MAX: f32 = 64.0;

/// The distance attenuation `(1 − t/t_far)^j` of 002 eq. 3.23 (SPEC.md §1.4) on eight rays:
/// [`super::Attenuation`] with one exponent for the batch (a wave's) and each ray's own far point
/// (`t_far` is 1 for every faithful ray, the far point's distance along each inverse-square ray).
/// Built by [`Self::new`], which also takes the march's constants that depend on `j` alone (its
/// ratio towards `t_far`, the far tail's reach and nodes: about ten `exp` that each of a bulged
/// beam's five pieces would otherwise take again).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttenuationLanes<L = Lanes> {
    /// Exponent `j ≥ 0` (0: none), shared by the lanes.
    j: f32,
    /// Each ray's far-point parameter (`> 0`).
    pub t_far: L,
    /// What the march takes from `j` alone.
    march: MarchConstants,
}

/// The constants of [`Quad::march`] that depend on `j` alone, formed as the scalar march forms
/// them (so each lane still cuts the scalar march's cells).
#[derive(Clone, Copy, Debug, PartialEq)]
struct MarchConstants {
    /// `t_far − t` falls by this per cell graded towards `t_far`.
    q: f32,
    /// The far tail's `reach(j)`.
    reach: f32,
    /// The far tail's nodes `e^{−u_i/(j+1)}` (zero below [`TAIL_MIN_J`]).
    nodes: [f32; 8],
}

impl MarchConstants {
    fn new(j: f32) -> Self {
        if j.is_nan() || j <= 0.0 {
            return Self { q: 0.0, reach: 0.0, nodes: [0.0; 8] };
        }
        let j1 = j + 1.0;
        Self {
            q: (-(FAR_GRADE as f32) / j).exp().max(FAR_RATIO_MIN as f32),
            reach: tail_reach(j),
            nodes: if j >= TAIL_MIN_J as f32 {
                LAGUERRE_X.map(|u| (-(u as f32) / j1).exp())
            } else {
                [0.0; 8]
            },
        }
    }
}

impl<L: Lane> AttenuationLanes<L> {
    /// The attenuation with exponent `j` (`≥ 0`, 0: none) and each lane's far point `t_far`.
    pub fn new(j: f32, t_far: L) -> Self {
        Self { j, t_far, march: MarchConstants::new(j) }
    }

    /// No attenuation (`j = 0`).
    pub fn none() -> Self {
        Self::new(0.0, L::splat(1.0))
    }

    /// The exponent `j`.
    #[inline(always)]
    pub fn j(&self) -> f32 {
        self.j
    }

    /// Whether it changes anything (`j > 0`; false for NaN).
    #[inline(always)]
    pub fn is_active(&self) -> bool {
        self.j > 0.0
    }

    /// `(1 − t/t_far)^j` per lane, 0 from the far point on (002 eq. 3.23, SPEC.md §1.4), `h = 1 −
    /// t/t_far` formed as the scalar [`super::Attenuation::factor`] forms it. An integer `j` up
    /// to [`INTEGER_J_MAX`] is `h^j` by repeated squaring (three products for `j = 8`, relative
    /// error about `10⁻⁷·log₂ j`); any other `j` is `exp(j·ln h)` with [`Lane::ln`] and
    /// [`Lane::exp`] (relative error about `10⁻⁷·(1 + j·|ln h|)` against `powf`). Either way a
    /// power below `f32::MIN_POSITIVE` (`10⁻³⁸`) gives 0.
    #[inline(always)]
    pub fn factor(&self, t: L) -> L {
        let k = L::splat;
        let h = k(1.0) - t / self.t_far;
        let pos = h.simd_gt(k(0.0));
        let g = if self.j == self.j.trunc() && self.j <= INTEGER_J_MAX {
            let mut n = self.j as u32;
            let mut base = pos.select(h, k(0.0));
            let mut acc = k(1.0);
            loop {
                if n & 1 == 1 {
                    acc = acc * base;
                }
                n >>= 1;
                if n == 0 {
                    break;
                }
                base = base * base;
            }
            // Normal powers only, as the exponential's (no subnormal reaches the march).
            acc.simd_ge(k(f32::MIN_POSITIVE)).select(acc, k(0.0))
        } else {
            (k(self.j) * pos.select(h, k(1.0)).ln()).exp()
        };
        pos.select(g, k(0.0))
    }
}

/// How [`capsule_parts`] integrates one piece: the closed form, or the attenuated march. A trait
/// with an `#[inline(always)]` method rather than a closure, so that the lane arithmetic inlines
/// into the dispatched body (see [`Lane`]).
trait Piece<L> {
    /// `∫_{t0}^{t1}` of `q`'s density (attenuated or not).
    fn piece(&self, q: &Quad<L>, t0: L, t1: L) -> L;
}

/// The unattenuated closed form ([`Quad::integral`]).
struct Plain(Falloff);

impl<L: Lane> Piece<L> for Plain {
    #[inline(always)]
    fn piece(&self, q: &Quad<L>, t0: L, t1: L) -> L {
        q.integral(self.0, t0, t1)
    }
}

/// The attenuated march ([`Quad::attenuated`]).
struct Attenuated<'a, L> {
    falloff: Falloff,
    att: &'a AttenuationLanes<L>,
}

impl<L: Lane> Piece<L> for Attenuated<'_, L> {
    #[inline(always)]
    fn piece(&self, q: &Quad<L>, t0: L, t1: L) -> L {
        q.attenuated(self.falloff, t0, t1, self.att)
    }
}

/// The lanes that are neither NaN nor infinite.
#[inline(always)]
fn finite<L: Lane>(v: L) -> L {
    !(v.is_nan() | v.is_inf())
}

/// `v` clamped to `[0, ENERGY_MAX]` where `live`, 0 elsewhere; NaN gives 0 (as the scalar
/// `v.max(0).min(ENERGY_MAX)`).
#[inline(always)]
fn clamp_energy<L: Lane>(live: L, v: L) -> L {
    let ok = live & v.simd_ge(L::splat(0.0));
    ok.select(v.min(L::splat(ENERGY_MAX as f32)), L::splat(0.0))
}

/// [`super::saturate`] per lane: `[0, f32::MAX]`, `+∞` and NaN to `f32::MAX`, negatives to 0.
#[inline(always)]
pub fn saturate<L: Lane>(x: L) -> L {
    let max = L::splat(ENERGY_SATURATION as f32);
    let pos = x.simd_ge(L::splat(0.0));
    let neg = x.simd_lt(L::splat(0.0));
    pos.select(x.min(max), neg.select(L::splat(0.0), max))
}

/// [`super::scaled`] per lane: `α·I` saturated, `α = 0` giving 0.
#[inline(always)]
pub fn scaled<L: Lane>(integral: L, alpha: f32) -> L {
    saturate(saturate(integral) * L::splat(alpha))
}

/// [`super::sphere_energy`] for eight rays (002 eq. 3.4, 3.6, 3.8–3.9, SPEC.md §1.2).
#[inline(always)]
pub fn sphere_energy<L: Lane>(p: &FieldParams<f32>, ray: &RayLanes<L>, f: &SphereField<f32>) -> L {
    let axis = Axis::new(ray.dir);
    let q = Quad::new(&axis, V3::splat(ray.origin - f.center), p.core_radius * p.core_radius);
    scaled(q.integral(p.falloff, ray.t0, ray.t1), f.alpha)
}

/// [`super::cylinder_energy`] for eight rays (002 eq. 3.5, 3.7–3.9, SPEC.md §1.2).
#[inline(always)]
pub fn cylinder_energy<L: Lane>(p: &FieldParams<f32>, ray: &RayLanes<L>, f: &CylinderField<f32>) -> L {
    let axis = Axis::new(ray.dir.cross_splat(f.dir));
    let v = V3::splat((ray.origin - f.point).cross(f.dir));
    let q = Quad::new(&axis, v, p.core_radius * p.core_radius);
    scaled(q.integral(p.falloff, ray.t0, ray.t1), f.alpha)
}

/// The capsule's energy and its end spheres' quadratics (reused by the beam).
struct CapsuleParts<L> {
    at_m: Quad<L>,
    at_m2: Quad<L>,
    energy: L,
}

/// As the scalar `capsule_parts` (002 eq. 3.10–3.11, SPEC.md §1.2): the ray split at the planes
/// through `M` and `M₂`, each region its closed form (or attenuated march: `piece`), the region
/// order per lane by the sign of `D·Q`.
///
/// A frame of its own in an unoptimized build ([`Lane::outlined_if_unoptimized`]).
#[inline(always)]
fn capsule_parts<L: Lane, P: Piece<L>>(
    p: &FieldParams<f32>,
    ray: &RayLanes<L>,
    f: &CapsuleField<f32>,
    piece: &P,
) -> CapsuleParts<L> {
    L::outlined_if_unoptimized(Capsule { p, ray, f, piece })
}

/// [`capsule_parts`]' arguments, a body for [`Lane::outlined_if_unoptimized`].
struct Capsule<'a, L, P> {
    p: &'a FieldParams<f32>,
    ray: &'a RayLanes<L>,
    f: &'a CapsuleField<f32>,
    piece: &'a P,
}

impl<L: Lane, P: Piece<L>> Outlined<L> for Capsule<'_, L, P> {
    type Output = CapsuleParts<L>;
    #[inline(always)]
    fn run(self) -> CapsuleParts<L> {
        capsule_parts_here(self.p, self.ray, self.f, self.piece)
    }
}

/// [`capsule_parts`] in place.
#[inline(always)]
fn capsule_parts_here<L: Lane>(
    p: &FieldParams<f32>,
    ray: &RayLanes<L>,
    f: &CapsuleField<f32>,
    piece: &impl Piece<L>,
) -> CapsuleParts<L> {
    let live = ray.t1.simd_gt(ray.t0);
    let t0 = live.select(ray.t0, L::splat(0.0));
    let t1 = live.select(ray.t1, L::splat(0.0));
    let rc2 = p.core_radius * p.core_radius;
    let q = ray.dir;
    let w = ray.origin - f.m;
    let sphere_axis = Axis::new(q);
    let at_m = Quad::new(&sphere_axis, V3::splat(w), rc2);
    let at_m2 = Quad::new(&sphere_axis, V3::splat(w - f.d * f.length), rc2);
    let cyl_axis = Axis::new(q.cross_splat(f.d));
    let cyl = Quad::new(&cyl_axis, V3::splat(w.cross(f.d)), rc2);
    // Axial coordinate along the ray: z(t) = ds + t·dq; planes at z = 0 (M) and z = length (M₂).
    let dq = q.dot(V3::splat(f.d));
    let ds = w.dot(f.d);
    let len = L::splat(f.length);
    let inf = f32::INFINITY;
    let fwd = dq.simd_gt(L::splat(0.0));
    let bwd = dq.simd_lt(L::splat(0.0));
    let at_plane_m = L::splat(-ds) / dq;
    let at_plane_m2 = (len - L::splat(ds)) / dq;
    // dq = 0: the whole ray in one region, by the offset ds.
    let (flat_lo, flat_hi) = if ds < 0.0 {
        (inf, inf)
    } else if ds > f.length {
        (-inf, -inf)
    } else {
        (-inf, inf)
    };
    let lo = fwd.select(at_plane_m, bwd.select(at_plane_m2, L::splat(flat_lo)));
    let hi = fwd.select(at_plane_m2, bwd.select(at_plane_m, L::splat(flat_hi)));
    let lo = lo.max(t0).min(t1);
    let hi = hi.max(lo).min(t1);
    let first = Quad::select(bwd, &at_m2, &at_m);
    let last = Quad::select(bwd, &at_m, &at_m2);
    let spheres = piece.piece(&first, t0, lo) + piece.piece(&last, hi, t1);
    let energy = saturate(scaled(spheres, f.alpha_s) + scaled(piece.piece(&cyl, lo, hi), f.alpha_c));
    CapsuleParts { at_m, at_m2, energy }
}

/// [`super::capsule_energy`] for eight rays (002 eq. 3.10–3.11, SPEC.md §1.2).
#[inline(always)]
pub fn capsule_energy<L: Lane>(p: &FieldParams<f32>, ray: &RayLanes<L>, f: &CapsuleField<f32>) -> L {
    capsule_parts(p, ray, f, &Plain(p.falloff)).energy
}

/// [`super::beam_energy`] for eight rays: the capsule plus the head and muzzle spheres over the
/// whole span (002 §3.3.3, eq. 3.4 and 3.11; SPEC.md §1.2).
#[inline(always)]
pub fn beam_energy<L: Lane>(p: &FieldParams<f32>, ray: &RayLanes<L>, f: &BeamField<f32>) -> L {
    let parts = capsule_parts(p, ray, &f.capsule, &Plain(p.falloff));
    let mut e = parts.energy;
    if f.head_alpha != 0.0 {
        e = saturate(e + scaled(parts.at_m2.integral(p.falloff, ray.t0, ray.t1), f.head_alpha));
    }
    if f.muzzle_alpha != 0.0 {
        e = saturate(e + scaled(parts.at_m.integral(p.falloff, ray.t0, ray.t1), f.muzzle_alpha));
    }
    e
}

/// [`super::sphere_energy_attenuated`] for eight rays: `α_s ∫ g(t)/ρ` (faithful) or
/// `α_s ∫ g(t)/ρ²` (inverse square) over `[t0, min(t1, t_far)]`, `g = (1 − t/t_far)^j` with each
/// lane's `t_far` (002 eq. 3.4, 3.6, 3.23; SPEC.md §1.2, §1.4). `j = 0` is [`sphere_energy`]
/// exactly.
#[inline(always)]
pub fn sphere_energy_attenuated<L: Lane>(
    p: &FieldParams<f32>,
    ray: &RayLanes<L>,
    att: &AttenuationLanes<L>,
    f: &SphereField<f32>,
) -> L {
    if !att.is_active() {
        return sphere_energy(p, ray, f);
    }
    let axis = Axis::new(ray.dir);
    let q = Quad::new(&axis, V3::splat(ray.origin - f.center), p.core_radius * p.core_radius);
    scaled(q.attenuated(p.falloff, ray.t0, ray.t1, att), f.alpha)
}

/// [`super::cylinder_energy_attenuated`] for eight rays (002 eq. 3.5, 3.7, 3.23; SPEC.md §1.2,
/// §1.4). `j = 0` is [`cylinder_energy`] exactly.
#[inline(always)]
pub fn cylinder_energy_attenuated<L: Lane>(
    p: &FieldParams<f32>,
    ray: &RayLanes<L>,
    att: &AttenuationLanes<L>,
    f: &CylinderField<f32>,
) -> L {
    if !att.is_active() {
        return cylinder_energy(p, ray, f);
    }
    let axis = Axis::new(ray.dir.cross_splat(f.dir));
    let v = V3::splat((ray.origin - f.point).cross(f.dir));
    let q = Quad::new(&axis, v, p.core_radius * p.core_radius);
    scaled(q.attenuated(p.falloff, ray.t0, ray.t1, att), f.alpha)
}

/// [`super::capsule_energy_attenuated`] for eight rays (002 eq. 3.10–3.11, 3.23; SPEC.md §1.2,
/// §1.4): the same split at the planes through `M` and `M₂`, each piece attenuated in the ray's
/// own parameter. `j = 0` is [`capsule_energy`] exactly.
#[inline(always)]
pub fn capsule_energy_attenuated<L: Lane>(
    p: &FieldParams<f32>,
    ray: &RayLanes<L>,
    att: &AttenuationLanes<L>,
    f: &CapsuleField<f32>,
) -> L {
    if !att.is_active() {
        return capsule_energy(p, ray, f);
    }
    capsule_parts(p, ray, f, &Attenuated { falloff: p.falloff, att }).energy
}

/// [`super::beam_energy_attenuated`] for eight rays (002 §3.3.3, eq. 3.4, 3.11, 3.23; SPEC.md
/// §1.2, §1.4): the attenuated capsule plus the attenuated bulbs at `M₂` and `M` over the whole
/// span. `j = 0` is [`beam_energy`] exactly.
#[inline(always)]
pub fn beam_energy_attenuated<L: Lane>(
    p: &FieldParams<f32>,
    ray: &RayLanes<L>,
    att: &AttenuationLanes<L>,
    f: &BeamField<f32>,
) -> L {
    if !att.is_active() {
        return beam_energy(p, ray, f);
    }
    let piece = Attenuated { falloff: p.falloff, att };
    let parts = capsule_parts(p, ray, &f.capsule, &piece);
    let mut e = parts.energy;
    if f.head_alpha != 0.0 {
        e = saturate(e + scaled(piece.piece(&parts.at_m2, ray.t0, ray.t1), f.head_alpha));
    }
    if f.muzzle_alpha != 0.0 {
        e = saturate(e + scaled(piece.piece(&parts.at_m, ray.t0, ray.t1), f.muzzle_alpha));
    }
    e
}
