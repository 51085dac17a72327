//! The default integrator (`integrate.rs`, SPEC.md §1.5) on eight neighbouring rays at once:
//! [`curve_energy_lanes`], what the CPU backend's wave pass runs per batch of eight pixels.
//!
//! # Method
//! Neighbouring rays walk nearly the same pieces of the [`PieceTable`](super::PieceTable), so the
//! eight rays walk the tree as one packet: the packet visits the tree's pieces in the scalar walk's
//! order (depth first, in `x` order), and at each piece every ray that the scalar walk would
//! evaluate there forms its quadratic, its chord-model estimate and, if accepted, its exact
//! integral, in lanes; the piece's line, bound and end nodes are read once for all eight. Each
//! ray keeps the scalar walk's state as lane state: a ray that accepted a piece (or found it
//! outside its range) waits until the packet leaves the piece's subtree, a ray that descends `k`
//! levels waits on the left spine until the packet reaches that level, a ray past its range is
//! done. So each ray evaluates exactly the pieces, in the order, that [`default_energy`] gives it
//! (the same evaluation count; the decisions use only `+ − × ÷ √`, rounded as the scalar code
//! rounds them), and the sums differ from it only by the lane logarithm, arctangent and power
//! (a few ulp). The end spheres and the attenuation's parts are lane arithmetic with masks.
//!
//! What stays scalar, per ray, with the scalar code itself: a leaf too coarse for a ray
//! (`leaf_walk`, rays passing within about `δ_leaf/τ` of the curve), the rays whose slab part is
//! degenerate (`x` constant along the ray, or an infinite slab span), any ray whose lane sum is
//! not finite or whose logarithm argument is not (recomputed whole by the scalar integrator), and
//! the other integrators (Simpson, the nearest-point field).
//!
//! [`default_energy`]: super::integrate::default_energy

use super::dispatch::curve_energy;
use super::integrate::{
    attenuation_split, default_generic, leaf_walk, next_piece, Acc, ChordModel, CurveSample, DEFAULT_SETTINGS,
};
use super::local_ray::{LocalFrame, LocalRay};
use super::prepare::PreparedCurve;
use super::wave::Integrator;
use crate::energy::{scaled, Falloff, FieldParams, Ray};
use crate::simd::{Lane, Outlined};

/// Rays per packet (the lane count of [`Lane`]).
pub const PACKET: usize = 8;

/// Per-lane masks as bits.
#[inline(always)]
fn bits<L: Lane>(m: L) -> u32 {
    m.bitmask()
}

/// Bits as a lane mask.
#[inline(always)]
fn mask<L: Lane>(b: u32) -> L {
    let on = f32::from_bits(u32::MAX);
    L::from_array(std::array::from_fn(|i| if b & (1 << i) != 0 { on } else { 0.0 }))
}

/// `|x|` per lane (the sign bit cleared).
#[inline(always)]
fn abs<L: Lane>(x: L) -> L {
    x & L::splat(f32::from_bits(0x7fff_ffff))
}

/// `x == y` per lane (false for NaN).
#[inline(always)]
fn eq<L: Lane>(x: L, y: L) -> L {
    x.simd_ge(y) & x.simd_le(y)
}

/// Finite lanes.
#[inline(always)]
fn finite<L: Lane>(x: L) -> L {
    !(x.is_nan() | x.is_inf())
}

/// `Real::clamp` per lane: `max(lo, min(x, hi))` with `f32`'s NaN rule (NaN gives `hi`).
#[inline(always)]
fn clamp<L: Lane>(x: L, lo: L, hi: L) -> L {
    lo.max(x.min(hi))
}

/// [`CurveReal::split`](super::local_ray::CurveReal::split) per lane: the low 12 significand bits
/// cleared.
#[inline(always)]
fn split<L: Lane>(x: L) -> L {
    x & L::splat(f32::from_bits(0xffff_f000))
}

/// `ln(1 + x)` for `x > −1` (Goldberg's form: `ln(u)·x/(u − 1)`, `u = 1 + x` rounded, exact
/// where `u = 1`): within a few ulp, as `f32::ln_1p`.
#[inline(always)]
fn ln_1p<L: Lane>(x: L) -> L {
    let u = L::splat(1.0) + x;
    let d = u - L::splat(1.0);
    let tiny = eq(d, L::splat(0.0));
    let safe_d = tiny.select(L::splat(1.0), d);
    tiny.select(x, u.ln() * x / safe_d)
}

/// `h^j` for `h > 0` (002 eq. 3.23's attenuation): `h`, `h²`, `√h` exactly for `j = 1, 2, ½`,
/// else `2^{j·log₂h}` by the lane logarithm and cephes' `exp2f` polynomial on the fraction
/// (relative error about `10⁻⁷·|j·log₂h|`); `h` below the normal range counts as `2⁻¹²⁶`.
#[inline(always)]
fn powf<L: Lane>(h: L, j: f32) -> L {
    if j == 1.0 {
        return h;
    }
    if j == 2.0 {
        return h * h;
    }
    if j == 0.5 {
        return h.sqrt();
    }
    let k = L::splat;
    let h = h.max(k(f32::MIN_POSITIVE));
    let y = (k(j * std::f32::consts::LOG2_E) * h.ln()).max(k(-126.0)).min(k(126.0));
    // Round to nearest by the 1.5·2²³ shift (|y| ≤ 126).
    let n = (y + k(12_582_912.0)) - k(12_582_912.0);
    let f = y - n;
    let mut p = k(1.535_336_2e-4);
    for c in [1.339_887_4e-3, 9.618_437e-3, 5.550_332_5e-2, 2.402_264_8e-1, 6.931_472e-1] {
        p = p * f + k(c);
    }
    let frac = p * f + k(1.0);
    let pos = n.simd_gt(k(0.0));
    let scale = pos.select((n - k(126.0)).exp2_int() * k(f32::from_bits(253 << 23)), n.exp2_int());
    frac * scale
}

/// `Vec3::dot` per lane.
#[inline(always)]
fn dot<L: Lane>(a: [L; 3], b: [L; 3]) -> L {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Lane `i` from `f(&items[i])`.
#[inline(always)]
fn gather<L: Lane, T>(items: &[T; PACKET], f: impl Fn(&T) -> f32) -> L {
    L::from_array(std::array::from_fn(|i| f(&items[i])))
}

/// [`Quad`](super::closed::Quad) per lane.
#[derive(Clone, Copy)]
struct QuadL<L> {
    pp: L,
    vv: L,
    pv: L,
    big_e: L,
}

impl<L: Lane> QuadL<L> {
    /// `Quad::new` of `d(τ) = p + vτ` in 3-D.
    #[inline(always)]
    fn new(p: [L; 3], v: [L; 3], rc2: L) -> Self {
        let vv = dot(v, v);
        let cx = p[1] * v[2] - p[2] * v[1];
        let cy = p[2] * v[0] - p[0] * v[2];
        let cz = p[0] * v[1] - p[1] * v[0];
        let cc = cx * cx + cy * cy + cz * cz;
        QuadL { pp: dot(p, p), vv, pv: dot(p, v), big_e: cc + rc2 * vv }
    }

    /// `Quad::end_squared`.
    #[inline(always)]
    fn end_squared(&self, dt: L) -> L {
        (self.pp + dt * (L::splat(2.0) * self.pv + self.vv * dt)).max(L::splat(0.0))
    }

    /// `Quad::inv_closest`.
    #[inline(always)]
    fn inv_closest(&self, dt: L, rc2: L) -> L {
        // One division: the numerator and denominator of the case each lane is in.
        let one = L::splat(1.0);
        let start = self.pv.simd_ge(L::splat(0.0));
        let end = (self.pv + self.vv * dt).simd_le(L::splat(0.0));
        let num = (start | end).select(one, self.vv);
        let den = start.select(self.pp + rc2, end.select(self.end_squared(dt) + rc2, self.big_e));
        num / den
    }

    /// `Quad::shifted`.
    #[inline(always)]
    fn shifted(&self, off: L) -> Self {
        QuadL { pp: self.end_squared(off), vv: self.vv, pv: self.pv + self.vv * off, big_e: self.big_e }
    }
}

/// [`Segment`](super::closed::Segment) per lane: one piece's exact integral (002 eq. 3.9,
/// SPEC.md §1.2, `closed.rs`) and what the attenuation rule needs.
#[derive(Clone, Copy)]
struct SegL<L> {
    value: L,
    dt: L,
    y0: L,
    y1: L,
    span: L,
    flipped: L,
    e: L,
    delta: L,
    /// Lanes whose logarithm argument was not finite (recomputed by the scalar code).
    bad: L,
}

impl<L: Lane> SegL<L> {
    /// `Segment::from_quad`, both branches of every test formed and selected per lane.
    #[inline(always)]
    fn from_quad(falloff: Falloff, q: &QuadL<L>, dt: L, rc2: L) -> Self {
        let k = L::splat;
        let zero = k(0.0);
        let one = k(1.0);
        let (vv, pv, big_e) = (q.vv, q.pv, q.big_e);
        let constant = !vv.simd_gt(zero);
        let dt_pos = dt.simd_gt(zero);
        let dt_fin = finite(dt);
        let ec = q.pp + rc2;
        // The constant integrand (v = 0) is rare: formed only where a lane has it.
        let cval = if bits(constant) != 0 {
            (dt_pos & dt_fin).select(
                match falloff {
                    Falloff::Faithful => dt / ec.sqrt(),
                    Falloff::InverseSquare => dt / ec,
                },
                zero,
            )
        } else {
            zero
        };
        let inv_s = one / vv.sqrt();
        let e = big_e * inv_s * inv_s;
        let ys = pv * inv_s;
        let (value, y0, y1, span, flipped, delta, bad) = match falloff {
            Falloff::Faithful => {
                let dtf = dt_fin.select(dt, zero);
                let span = vv * dtf;
                let sspan = span * inv_s;
                let (y0, y1) = (pv, pv + span);
                let flip = (y0 + y1).simd_lt(zero);
                let (y0, y1) = (flip.select(-y1, y0), flip.select(-y0, y1));
                let r0 = (y0 * y0 + big_e).sqrt();
                let r1 = (y1 * y1 + big_e).sqrt();
                let rs = r0 + r1;
                // x = num/den of the lane's case, in one division.
                let pos = y0.simd_ge(zero);
                let t = span * (rs + y0 + y1);
                let x = pos.select(t, t * (r0 - y0)) / pos.select(rs * (y0 + r0), rs * big_e);
                let big = x.simd_ge(k(0.0625));
                let bad = dt_pos & !finite(x);
                let arg = finite(x).select(x, zero);
                // ln(1 + x) where x ≥ 1/16, ln_1p below, from one logarithm of u = 1 + x.
                let u = one + arg;
                let lnu = u.ln();
                let d = u - one;
                let tiny = eq(d, zero);
                let small = tiny.select(arg, lnu * arg / tiny.select(one, d));
                let delta = big.select(lnu, small);
                let value = dt_pos.select(delta * inv_s, zero);
                (value, y0 * inv_s, y1 * inv_s, sspan, flip, delta, bad)
            }
            Falloff::InverseSquare => {
                let se = big_e.sqrt();
                let span = vv * dt;
                let sspan = span * inv_s;
                let z = span * se;
                let kk = big_e + pv * (pv + span);
                let th = z.atan2(kk);
                let small = kk.simd_gt(zero) & z.simd_lt(k(1e-4) * kk);
                let r = z / kk;
                let vfin = small.select(span / kk * (one - r * r / k(3.0)), th / se);
                let thi = se.atan2(pv);
                let vinf = thi / se;
                let value = dt_pos.select(dt_fin.select(vfin, vinf), zero);
                let delta = dt_fin.select(th, thi);
                let y1 = dt_fin.select((pv + span) * inv_s, k(f32::INFINITY));
                (value, ys, y1, dt_fin.select(sspan, zero), zero, delta, zero)
            }
        };
        // Lanes without a positive span keep the scalar code's fields (they take no moments).
        let y0 = dt_pos.select(y0, ys);
        SegL {
            value: constant.select(cval, value),
            dt,
            y0: constant.select(zero, y0),
            y1: constant.select(zero, y1),
            span: constant.select(zero, span),
            flipped: constant.select(zero, flipped),
            e: constant.select(ec, e),
            delta: constant.select(zero, delta),
            bad: !constant & bad,
        }
    }

    /// `Segment::moments`: the weight's centroid and variance (closed forms, `closed.rs`).
    #[inline(always)]
    fn moments(&self, falloff: Falloff) -> (L, L) {
        let k = L::splat;
        let zero = k(0.0);
        let (y0, y1, e, dt, span) = (self.y0, self.y1, self.e, self.dt, self.span);
        let (mid, uniform) = (dt * k(0.5), dt * dt / k(12.0));
        let q0 = y0 * y0 + e;
        let nu = span * (abs(y0).max(abs(y1)) + span);
        let early = !self.value.simd_gt(zero) | !nu.simd_gt(k(1e-4) * q0);
        let (m0, m1, s2) = match falloff {
            Falloff::Faithful => {
                let (r0, r1) = (q0.sqrt(), (y1 * y1 + e).sqrt());
                let m0 = self.delta;
                let m1 = span * (y0 + y1) / (r0 + r1);
                (m0, m1, k(0.5) * (y1 * r1 - y0 * r0) - k(2.0) * y0 * m1 + (y0 * y0 - k(0.5) * e) * m0)
            }
            Falloff::InverseSquare => {
                let m0 = self.delta / e.sqrt();
                let arg = span * (y0 + y1) / q0;
                let valid = finite(arg) & arg.simd_gt(k(-1.0));
                let m1 = valid.select(k(0.5) * ln_1p(valid.select(arg, zero)), k(f32::NAN));
                (m0, m1, span - k(2.0) * y0 * m1 + (y0 * y0 - e) * m0)
            }
        };
        let mu = m1 / m0 - y0;
        let scale = dt / span;
        let tbar = mu * scale;
        let tbar = self.flipped.select(dt - tbar, tbar);
        let tbar = finite(tbar).select(clamp(tbar, zero, dt), mid);
        let fitted = !nu.simd_gt(k(0.1) * q0);
        let var = clamp(s2 / m0 - mu * mu, zero, span * span * k(0.25)) * scale * scale;
        let var = finite(var).select(var, uniform);
        let var = fitted.select(self.fitted_variance(falloff, uniform), var);
        (early.select(mid, tbar), early.select(uniform, var))
    }

    /// `Segment::fitted_variance`: the variance of the weight's quadratic interpolant.
    #[inline(always)]
    fn fitted_variance(&self, falloff: Falloff, uniform: L) -> L {
        let k = L::splat;
        let (y0, e, span) = (self.y0, self.e, self.span);
        let (ya, ym, yb) = (y0, y0 + span * k(0.5), y0 + span);
        let (qa, qm, qb) = (ya * ya + e, ym * ym + e, yb * yb + e);
        let (w0, wm, w1) = match falloff {
            Falloff::Faithful => (k(1.0) / qa.sqrt(), k(1.0) / qm.sqrt(), k(1.0) / qb.sqrt()),
            Falloff::InverseSquare => (k(1.0) / qa, k(1.0) / qm, k(1.0) / qb),
        };
        let gamma = k(2.0) * (w1 - k(2.0) * wm + w0) / wm;
        let beta = (w1 - w0) / wm - gamma;
        let a = w0 / wm;
        let m0 = a + beta * k(0.5) + gamma / k(3.0);
        let m1 = a * k(0.5) + beta / k(3.0) + gamma * k(0.25);
        let m2 = a / k(3.0) + beta * k(0.25) + gamma / k(5.0);
        let (c1, c2) = (m1 / m0, m2 / m0);
        let v = clamp(c2 - c1 * c1, k(0.0), k(0.25)) * self.dt * self.dt;
        finite(v).select(v, uniform)
    }

    /// `Segment::attenuated`: `∫w·(1 − t/t_far)^j` to second order about the centroid
    /// (002 eq. 3.23).
    #[inline(always)]
    fn attenuated(&self, falloff: Falloff, t_start: L, t_far: L, j: f32) -> L {
        let k = L::splat;
        let zero = k(0.0);
        let (tbar, var) = self.moments(falloff);
        let h = k(1.0) - (t_start + tbar) / t_far;
        let live = self.value.simd_gt(zero) & h.simd_gt(zero);
        let ht = h * t_far;
        let z = (var / (ht * ht)).min(k(1.0));
        let factor = (k(1.0) + k(0.5) * k(j) * k(j - 1.0) * z).max(zero);
        let hs = live.select(h, k(1.0));
        live.select(self.value * powf(hs, j) * factor, zero)
    }
}

/// The packet's rays in the curve's frame (`LocalRay` per lane) and what is uniform over them.
struct Packet<L> {
    o: [L; 3],
    q: [L; 3],
    t_far: L,
    rc2: L,
    falloff: Falloff,
    j: f32,
    /// [`attenuation_split`]'s `q` and `h_floor`.
    part_q: L,
    h_floor: L,
    /// The same as scalars.
    part_scalars: (f32, f32),
}

/// Lane sums and per-ray evaluation counts.
struct Sums<L> {
    sum: L,
    evals: [u32; PACKET],
    bad: L,
}

impl<L: Lane> Packet<L> {
    /// An end sphere (`integrate_span`'s `sphere`) on the lanes of `m` where `b > a`: the piece
    /// `p = P(a) − end point`, `v = q` in 3-D, from `a` to `b`; `head` picks the head's end point
    /// (`ends`: the first and last node), else `c(0)`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn sphere(&self, ends: ([f32; 4], [f32; 4]), xh: f32, head: L, a: L, b: L, m: u32, acc: &mut Sums<L>) {
        let m = m & bits(b.simd_gt(a));
        if m == 0 {
            return;
        }
        let k = L::splat;
        let (n0, n1) = ends;
        let e =
            [head.select(k(xh), k(0.0)), head.select(k(n1[1]), k(n0[1])), head.select(k(n1[2]), k(n0[2]))];
        let [ox, oy, oz] = self.o;
        let p = [ox + self.q[0] * a - e[0], oy + self.q[1] * a - e[1], oz + self.q[2] * a - e[2]];
        self.piece(m, a, &QuadL::new(p, self.q, self.rc2), b - a, acc);
    }

    /// `Acc::piece_quad` on the lanes of `m`: the piece from `ts` on over `τ ∈ [0, dt]`, cut into
    /// attenuation parts as the scalar rule cuts it (each part counts 1). A frame of its own in an
    /// unoptimized build ([`Lane::outlined_if_unoptimized`]).
    #[inline(always)]
    fn piece(&self, m: u32, ts: L, q: &QuadL<L>, dt: L, acc: &mut Sums<L>) {
        L::outlined_if_unoptimized(Piece { pk: self, m, ts, q, dt, acc })
    }

    /// [`Packet::piece`] in place.
    #[inline(always)]
    fn piece_here(&self, m: u32, ts: L, q: &QuadL<L>, dt: L, acc: &mut Sums<L>) {
        let zero = L::splat(0.0);
        if self.j == 0.0 {
            let seg = SegL::from_quad(self.falloff, q, dt, self.rc2);
            let mk = mask::<L>(m);
            acc.sum += mk.select(seg.value, zero);
            acc.bad = acc.bad | (mk & seg.bad);
            count(&mut acc.evals, m);
            return;
        }
        let one = L::splat(1.0);
        let te = ts + dt;
        let mut a = ts;
        let mut live = m;
        for i in 0..super::integrate::MAX_ATTENUATION_PARTS {
            if live == 0 {
                break;
            }
            let ha = one - a / self.t_far;
            let last = ha.simd_le(self.h_floor)
                | mask(if i + 1 == super::integrate::MAX_ATTENUATION_PARTS { u32::MAX } else { 0 });
            let b = last.select(te, te.min(self.t_far * (one - ha * self.part_q)));
            let seg = SegL::from_quad(self.falloff, &q.shifted(a - ts), b - a, self.rc2);
            let v = seg.attenuated(self.falloff, a, self.t_far, self.j);
            let mk = mask::<L>(live);
            acc.sum += mk.select(v, zero);
            acc.bad = acc.bad | (mk & seg.bad);
            count(&mut acc.evals, live);
            let more = b.simd_lt(te);
            live &= bits(more);
            a = more.select(b, a);
        }
    }

    /// `line_quad` per lane: the quadratic of the line `[ȳ, z̄, m_y, m_z]` centred at `xm` along
    /// each ray from `ts` on, its cross product formed again at the anchor where the ray passes
    /// within about `2.4·10⁻³` of the coordinates' size (see `integrate.rs`).
    #[inline(always)]
    fn line_quad(&self, line: [f32; 4], xm: f32, ts: L, dt: L) -> QuadL<L> {
        let k = L::splat;
        let [ly, lz, my, mz] = line.map(k);
        let xm = k(xm);
        let [ox, oy, oz] = self.o;
        let [qx, qy, qz] = self.q;
        let xs = ox + qx * ts - xm;
        let py = oy + qy * ts - (ly + xs * my);
        let pz = oz + qz * ts - (lz + xs * mz);
        let vy = qy - qx * my;
        let vz = qz - qx * mz;
        let vv = vy * vy + vz * vz;
        let pv = py * vy + pz * vz;
        let mut cr = py * vz - pz * vy;
        let ats = abs(ts);
        let size =
            abs(oy) + abs(oz) + (abs(qy) + abs(qz)) * ats + (abs(ox) + abs(qx) * ats) * (abs(my) + abs(mz));
        let bound = k(f32::EPSILON * 2e4) * size;
        let near = !(cr * cr).simd_gt(bound * bound * vv);
        if bits(near) != 0 {
            let zero = k(0.0);
            let tau = -pv / vv;
            let tau = tau.simd_gt(zero).select(tau, zero);
            let tau = tau.simd_gt(dt).select(dt, tau);
            let ta = split(ts + tau);
            let xa = anchored(ox, qx, xm, ta);
            let ay = anchored(oy, qy, ly, ta) - xa * my;
            let az = anchored(oz, qz, lz, ta) - xa * mz;
            cr = near.select(ay * vz - az * vy, cr);
        }
        QuadL { pp: py * py + pz * pz, vv, pv, big_e: cr * cr + self.rc2 * vv }
    }
}

/// [`Packet::piece`]'s arguments, a body for [`Lane::outlined_if_unoptimized`].
struct Piece<'a, L> {
    pk: &'a Packet<L>,
    m: u32,
    ts: L,
    q: &'a QuadL<L>,
    dt: L,
    acc: &'a mut Sums<L>,
}

impl<L: Lane> Outlined<L> for Piece<'_, L> {
    type Output = ();
    #[inline(always)]
    fn run(self) {
        self.pk.piece_here(self.m, self.ts, self.q, self.dt, self.acc)
    }
}

/// `+1` to the counts of the lanes in `m`.
#[inline(always)]
fn count(evals: &mut [u32; PACKET], m: u32) {
    for (i, e) in evals.iter_mut().enumerate() {
        *e += (m >> i) & 1;
    }
}

/// `two_sum` per lane (Knuth's: additions only).
#[inline(always)]
fn two_sum<L: Lane>(a: L, b: L) -> (L, L) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `anchored` per lane: `o + q·t − l` good to the rounding of the result.
#[inline(always)]
fn anchored<L: Lane>(o: L, q: L, l: L, t: L) -> L {
    let (h, h_err) = two_sum(o, -l);
    let qh = split(q);
    let (s, s_err) = two_sum(h, qh * t);
    s + (s_err + h_err + (q - qh) * t)
}

/// A ray's slab range in `x` and the map back to `t` (as `walk` forms them).
#[derive(Clone, Copy, Default)]
struct Range {
    lo: f32,
    hi: f32,
    t_lo: f32,
    t_hi: f32,
    inv_qx: f32,
}

impl Range {
    /// `t_of` of `walk`.
    #[inline]
    fn t_of(&self, x: f32) -> f32 {
        if x == self.lo {
            self.t_lo
        } else if x == self.hi {
            self.t_hi
        } else {
            self.t_lo + (x - self.lo) * self.inv_qx
        }
    }
}

/// [`Range`] per lane.
struct RangeL<L> {
    lo: L,
    hi: L,
    t_lo: L,
    t_hi: L,
    inv_qx: L,
}

impl<L: Lane> RangeL<L> {
    /// [`Range::t_of`] per lane.
    #[inline(always)]
    fn t_of(&self, x: L) -> L {
        eq(x, self.lo)
            .select(self.t_lo, eq(x, self.hi).select(self.t_hi, self.t_lo + (x - self.lo) * self.inv_qx))
    }
}

/// The default integrator's energy (002 §3.4, SPEC.md §1.5) of up to eight neighbouring rays, as
/// [`curve_energy`] gives each (`rays`, `t0`, `t1`, `t_far` as there, one entry per ray; at most
/// [`PACKET`]): the rays walk the piece table as one packet (see the module docs). Waves with
/// another integrator, and the rays the packet leaves to the scalar code, are integrated by
/// [`curve_energy`] itself. Entries beyond `rays.len()` are zero.
///
/// Generic over the lanes for [`crate::simd::dispatch`]: call it from a body run there (it is
/// inlined into that body, as every lane function must be).
#[inline(always)]
pub fn curve_energy_lanes<L: Lane>(
    c: &PreparedCurve,
    p: &FieldParams<f32>,
    rays: &[Ray<f32>],
    t0: &[f32],
    t1: &[f32],
    t_far: &[f32],
) -> [CurveSample; PACKET] {
    L::outlined_if_unoptimized(CurvePacket { c, p, rays, t0, t1, t_far })
}

/// [`curve_energy_lanes`]'s arguments, a body for [`Lane::outlined_if_unoptimized`] (in an
/// unoptimized build the packet walk takes a frame of its own).
struct CurvePacket<'a> {
    c: &'a PreparedCurve,
    p: &'a FieldParams<f32>,
    rays: &'a [Ray<f32>],
    t0: &'a [f32],
    t1: &'a [f32],
    t_far: &'a [f32],
}

impl<L: Lane> Outlined<L> for CurvePacket<'_> {
    type Output = [CurveSample; PACKET];
    #[inline(always)]
    fn run(self) -> Self::Output {
        packet_energy::<L>(self.c, self.p, self.rays, self.t0, self.t1, self.t_far)
    }
}

/// [`curve_energy_lanes`] in place.
#[inline(always)]
fn packet_energy<L: Lane>(
    c: &PreparedCurve,
    p: &FieldParams<f32>,
    rays: &[Ray<f32>],
    t0: &[f32],
    t1: &[f32],
    t_far: &[f32],
) -> [CurveSample; PACKET] {
    let n = rays.len().min(PACKET).min(t0.len()).min(t1.len()).min(t_far.len());
    let mut out = [CurveSample { energy: 0.0, evaluations: 0 }; PACKET];
    if c.wave.integrator != Integrator::Default {
        for i in 0..n {
            out[i] = curve_energy(c, p, &rays[i], t0[i], t1[i], t_far[i]);
        }
        return out;
    }
    let settings = &DEFAULT_SETTINGS;
    let table = &c.table;
    let nn = table.nodes.len() - 1;
    let xh = c.x_head as f32;
    let frame = LocalFrame::new(c, p);
    let mut local: [Option<LocalRay<f32>>; PACKET] = [None; PACKET];
    // Lanes the packet integrates; the others are left to the scalar code (or are empty).
    let mut packet = 0u32;
    let mut scalar = 0u32;
    let mut first = None;
    for i in 0..n {
        let Some(r) = frame.ray(&rays[i], t0[i], t1[i], t_far[i]) else { continue };
        local[i] = Some(r);
        let Some((tin, tout, _)) = r.slab() else {
            scalar |= 1 << i;
            continue;
        };
        let (a, b) = (r.t0.max(tin), r.t1.min(tout));
        if b > a {
            // walk's one-piece case (x nearly constant, or an infinite slab span).
            let xa = (r.o.x + r.q.x * a).clamp(0.0, xh);
            let xb = (r.o.x + r.q.x * b).clamp(0.0, xh);
            let (lo, hi) = if xa <= xb { (xa, xb) } else { (xb, xa) };
            if !(hi - lo > xh * f32::EPSILON * 8.0) || !(b - a).is_finite() {
                scalar |= 1 << i;
                continue;
            }
        }
        packet |= 1 << i;
        first.get_or_insert(r);
    }
    let Some(r0) = first else {
        for i in 0..n {
            if scalar & (1 << i) != 0 {
                out[i] = scalar_sample(c, local[i].as_ref());
            }
        }
        return out;
    };
    // Lanes outside the packet carry a copy of its first ray (masked off).
    let lr: [LocalRay<f32>; PACKET] =
        std::array::from_fn(|i| if packet & (1 << i) != 0 { local[i].unwrap_or(r0) } else { r0 });
    let (qs, h_floor) =
        if r0.j > 0.0 { attenuation_split(f64::from(r0.j), settings.tolerance) } else { (0.5, 0.0) };
    let k = L::splat;
    let pk = Packet {
        o: [gather(&lr, |r| r.o.x), gather(&lr, |r| r.o.y), gather(&lr, |r| r.o.z)],
        q: [gather(&lr, |r| r.q.x), gather(&lr, |r| r.q.y), gather(&lr, |r| r.q.z)],
        t_far: gather(&lr, |r| r.t_far),
        rc2: k(r0.rc2),
        falloff: r0.falloff,
        j: r0.j,
        part_q: k(qs as f32),
        h_floor: k(h_floor as f32),
        part_scalars: (qs as f32, h_floor as f32),
    };
    let rt0: L = gather(&lr, |r| r.t0);
    let rt1: L = gather(&lr, |r| r.t1);
    let mut acc = Sums { sum: k(0.0), evals: [0; PACKET], bad: k(0.0) };

    // The slab crossings and the end spheres (integrate_span).
    let ox = pk.o[0];
    let qx = pk.q[0];
    let ta_ = -ox / qx;
    let tb_ = (k(xh) - ox) / qx;
    let up = qx.simd_gt(k(0.0));
    let (tin, tout) = (up.select(ta_, tb_), up.select(tb_, ta_));
    let ends = (table.nodes[0], table.nodes[nn]);
    let head_first = !up;
    pk.sphere(ends, xh, head_first, rt0, rt1.min(tin), packet, &mut acc);
    let (wa, wb) = (rt0.max(tin), rt1.min(tout));
    let walking = packet & bits(wb.simd_gt(wa));
    if walking != 0 {
        walk(c, &pk, &local, walking, wa.to_array(), wb.to_array(), &mut acc);
    }
    pk.sphere(ends, xh, !head_first, rt0.max(tout), rt1, packet, &mut acc);

    let sums = acc.sum.to_array();
    let bad = bits(acc.bad);
    for i in 0..n {
        if scalar & (1 << i) != 0 || (packet & (1 << i) != 0 && (bad & (1 << i) != 0 || !sums[i].is_finite()))
        {
            out[i] = scalar_sample(c, local[i].as_ref());
        } else if packet & (1 << i) != 0 {
            out[i] = CurveSample { energy: scaled(sums[i], r0.alpha), evaluations: acc.evals[i] };
        }
    }
    out
}

/// The scalar default integrator on one resolved ray.
fn scalar_sample(c: &PreparedCurve, r: Option<&LocalRay<f32>>) -> CurveSample {
    let (energy, evaluations) = r.map_or((0.0, 0), |r| default_generic(c, r, &DEFAULT_SETTINGS));
    CurveSample { energy, evaluations }
}

/// The chord walk (`walk` in `integrate.rs`) of the lanes in `walking`, each over its slab part
/// `[wa, wb]`, as one packet (see the module docs).
#[inline(always)]
fn walk<L: Lane>(
    c: &PreparedCurve,
    pk: &Packet<L>,
    local: &[Option<LocalRay<f32>>; PACKET],
    walking: u32,
    wa: [f32; PACKET],
    wb: [f32; PACKET],
    acc: &mut Sums<L>,
) {
    let table = &c.table;
    let n = table.nodes.len() - 1;
    let levels = table.levels();
    let xh = c.x_head as f32;
    let tol = DEFAULT_SETTINGS.tolerance as f32;
    let model = ChordModel::<f32>::new(pk.falloff);
    let mut rg = [Range::default(); PACKET];
    for i in 0..PACKET {
        if walking & (1 << i) == 0 {
            continue;
        }
        let r = local[i].as_ref().expect("a walking lane has a ray");
        let x_at = |t: f32| r.o.x + r.q.x * t;
        let xa = x_at(wa[i]).clamp(0.0, xh);
        let xb = x_at(wb[i]).clamp(0.0, xh);
        let (lo, hi, t_lo, t_hi) = if xa <= xb { (xa, xb, wa[i], wb[i]) } else { (xb, xa, wb[i], wa[i]) };
        rg[i] = Range { lo, hi, t_lo, t_hi, inv_qx: 1.0 / r.q.x };
    }
    let lanes: RangeL<L> = RangeL {
        lo: gather(&rg, |r| r.lo),
        hi: gather(&rg, |r| r.hi),
        t_lo: gather(&rg, |r| r.t_lo),
        t_hi: gather(&rg, |r| r.t_hi),
        inv_qx: gather(&rg, |r| r.inv_qx),
    };
    let (lo, hi) = (lanes.lo, lanes.hi);
    let k = L::splat;
    let (first, sat, partial, second) =
        (k(model.first), k(model.saturation), k(model.partial), k(model.second));

    const FREE: usize = usize::MAX;
    // Per lane: the level of the piece whose subtree it waits out (FREE: none), and the level it
    // evaluates at next (below the packet's: descending on the left spine).
    let mut gate = [FREE; PACKET];
    let mut target = [levels - 1; PACKET];
    let mut done = !walking & 0xff;
    let (mut l, mut j) = (levels - 1, 0usize);
    let max_steps = 4 * (table.errors.len() + levels);
    for _ in 0..max_steps {
        if done == 0xff {
            return;
        }
        let a = j << l;
        let b = ((j + 1) << l).min(n);
        let (na, nb) = (table.nodes[a][0], table.nodes[b][0]);
        let mut here = 0u32;
        for i in 0..PACKET {
            if done & (1 << i) != 0 || gate[i] != FREE || target[i] != l {
                continue;
            }
            if na >= rg[i].hi {
                done |= 1 << i;
            } else if nb > rg[i].lo {
                here |= 1 << i;
            } else {
                gate[i] = l;
            }
        }
        if here != 0 {
            let x0 = lo.max(k(na));
            let x1 = hi.min(k(nb));
            let (tx0, tx1) = (lanes.t_of(x0), lanes.t_of(x1));
            let ordered = tx0.simd_le(tx1);
            let (ts, te) = (ordered.select(tx0, tx1), ordered.select(tx1, tx0));
            let dt = te - ts;
            let ln = table.line(l, j);
            let quad = pk.line_quad([ln[0], ln[1], ln[2], ln[3]], (na + nb) * 0.5, ts, dt);
            let err = k(table.error(l, j));
            let part = x0.simd_gt(k(na)) | x1.simd_lt(k(nb));
            // Only at a ray's ends does it cover part of a piece.
            let uncovered =
                if bits(part) != 0 { part.select(k(1.0) - (x1 - x0) / k(nb - na), k(0.0)) } else { k(0.0) };
            // ChordModel::terms and ::refinement.
            let inv = quad.inv_closest(dt, pk.rc2);
            let x2 = err * err * inv;
            let am = (first * quad.vv * dt * dt * inv).min(sat) + partial * uncovered;
            let bb = k(tol) - second * x2;
            let ok = bb.simd_ge(k(0.0)) & (x2 * am * am).simd_le(bb * bb);
            let accept = here & bits(ok);
            if accept != 0 {
                pk.piece(accept, ts, &quad, dt, acc);
            }
            let refine = here & !accept;
            if refine != 0 {
                let est = (x2.sqrt() * am + second * x2).to_array();
                for i in 0..PACKET {
                    if refine & (1 << i) == 0 {
                        continue;
                    }
                    acc.evals[i] += 1;
                    if l == 0 {
                        let r = local[i].as_ref().expect("a walking lane has a ray");
                        let mut sums = acc.sum.to_array();
                        let (x0, x1) = (rg[i].lo.max(na), rg[i].hi.min(nb));
                        let mut sa = Acc {
                            sum: sums[i],
                            evals: acc.evals[i],
                            q: pk.part_scalars.0,
                            h_floor: pk.part_scalars.1,
                        };
                        let g = rg[i];
                        leaf_walk(c, r, j, (x0, x1), &|x| g.t_of(x), tol, &model, &mut sa);
                        sums[i] = sa.sum;
                        acc.evals[i] = sa.evals;
                        acc.sum = L::from_array(sums);
                        gate[i] = l;
                    } else {
                        let per_level = 8.0f32;
                        let mut ratio = est[i] / (tol * per_level);
                        let mut kk = 1;
                        while kk < l && ratio > per_level {
                            ratio /= per_level;
                            kk += 1;
                        }
                        target[i] = l - kk;
                    }
                }
            }
            for (i, g) in gate.iter_mut().enumerate() {
                if accept & (1 << i) != 0 {
                    *g = l;
                }
            }
        }
        // Descend to the next level a lane evaluates at on the left spine.
        let mut next = None;
        for i in 0..PACKET {
            if done & (1 << i) == 0 && gate[i] == FREE && target[i] < l {
                next = Some(next.map_or(target[i], |t: usize| t.max(target[i])));
            }
        }
        if let Some(t) = next {
            j <<= l - t;
            l = t;
            continue;
        }
        // Advance to the next piece in x order: the right sibling, or up until there is one.
        if !next_piece(&mut j, &mut l, levels, n) {
            return;
        }
        for i in 0..PACKET {
            if gate[i] != FREE && gate[i] <= l {
                gate[i] = FREE;
            }
            if gate[i] == FREE {
                target[i] = l;
            }
        }
    }
}
