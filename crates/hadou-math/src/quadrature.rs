//! Numerical quadrature: the converged references that tests and the curve integrators compare
//! against.
//!
//! - [`integrate_adaptive`] / [`integrate_adaptive_breaks`]: globally adaptive Gauss–Kronrod 7–15
//!   in `f64` with error control. The interval with the largest error estimate is bisected until
//!   the summed estimate meets `max(abs_tol, rel_tol·|value|)`, so near-singular peaks are resolved
//!   by repeated bisection where they are; known kinks, jumps or peaks can be given as break points
//!   so that they fall on interval ends. Infinite ends are mapped to finite ones by the substitution
//!   `t = p + x/(1 − x)` (or its mirror), which keeps integrands that decay like `1/t²` smooth.
//! - [`composite_simpson`]: the thesis's fixed-step rule (002 §3.4.4, "分点数" `m`).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// The outcome of an adaptive integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadrature {
    /// The integral's estimate.
    pub value: f64,
    /// An estimate of `|value − exact|` (conservative: Kronrod minus Gauss, scaled as in QUADPACK's
    /// QK rules, summed over the final intervals).
    pub error_estimate: f64,
    /// How many times the integrand was evaluated.
    pub evaluations: u32,
    /// Whether the requested tolerance was met (false: the interval budget ran out, an interval
    /// could not be bisected further, or the integrand returned a non-finite value).
    pub converged: bool,
}

/// Upper bound on the number of intervals one integration may create (each costs 15 evaluations).
pub const MAX_INTERVALS: usize = 20_000;

/// Gauss–Kronrod 15-point abscissae on `[-1, 1]`, positive half, largest first; the odd-indexed
/// ones (and 0) are the 7-point Gauss nodes.
#[allow(clippy::excessive_precision)] // The published 33-digit tables, kept verbatim.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_639_206_854_697_526_329,
    0.949_107_912_342_758_524_526_189_684_047_851,
    0.864_864_423_359_769_072_789_712_788_640_926,
    0.741_531_185_599_394_439_863_864_773_280_788,
    0.586_087_235_467_691_130_294_144_845_693_013,
    0.405_845_151_377_397_166_906_606_412_076_961,
    0.207_784_955_007_898_467_600_689_403_773_245,
    0.0,
];
/// Kronrod weights matching [`XGK`].
#[allow(clippy::excessive_precision)] // The published 33-digit tables, kept verbatim.
const WGK: [f64; 8] = [
    0.022_935_322_010_529_224_963_732_008_058_970,
    0.063_092_092_629_978_553_290_700_663_189_204,
    0.104_790_010_322_250_183_839_876_322_541_518,
    0.140_653_259_715_525_918_745_189_590_510_238,
    0.169_004_726_639_267_902_826_583_426_598_550,
    0.190_350_578_064_785_409_913_256_402_421_014,
    0.204_432_940_075_298_892_414_161_999_234_649,
    0.209_482_141_084_727_828_012_999_174_891_714,
];
/// 7-point Gauss weights for the nodes `XGK[1], XGK[3], XGK[5], XGK[7]`.
#[allow(clippy::excessive_precision)] // The published 33-digit tables, kept verbatim.
const WG: [f64; 4] = [
    0.129_484_966_168_869_693_270_611_432_679_082,
    0.279_705_391_489_276_667_901_467_771_423_780,
    0.381_830_050_505_118_944_950_369_775_488_975,
    0.417_959_183_673_469_387_755_102_040_816_327,
];

/// One Gauss–Kronrod 7–15 panel on a finite `[a, b]`: `(kronrod value, error estimate)`.
///
/// The error estimate is `|K₁₅ − G₇|`, rescaled with the integrand's variation over the panel
/// (`ρ·min(1, (200·|K − G|/ρ)^{3/2})`, `ρ = ∫|f − mean|`) and floored at `50·ε·∫|f|`, the
/// heuristics of QUADPACK's QK15 (Piessens et al. 1983): it tracks the true error of the Kronrod
/// value closely once the panel resolves `f`, and is never below what rounding allows.
pub fn gauss_kronrod_15(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut k = fc * WGK[7];
    let mut g = fc * WG[3];
    let mut abs_k = fc.abs() * WGK[7];
    let mut fv = [(0.0, 0.0); 7];
    for (j, &x) in XGK[..7].iter().enumerate() {
        let f1 = f(c - h * x);
        let f2 = f(c + h * x);
        fv[j] = (f1, f2);
        k += WGK[j] * (f1 + f2);
        abs_k += WGK[j] * (f1.abs() + f2.abs());
        if j % 2 == 1 {
            g += WG[j / 2] * (f1 + f2);
        }
    }
    let mean = 0.5 * k;
    let mut asc = WGK[7] * (fc - mean).abs();
    for (j, &(f1, f2)) in fv.iter().enumerate() {
        asc += WGK[j] * ((f1 - mean).abs() + (f2 - mean).abs());
    }
    let ha = h.abs();
    let value = k * h;
    let abs_k = abs_k * ha;
    let asc = asc * ha;
    let mut err = ((k - g) * h).abs();
    if asc != 0.0 && err != 0.0 {
        err = asc * (200.0 * err / asc).powf(1.5).min(1.0);
    }
    if abs_k > f64::MIN_POSITIVE / (50.0 * f64::EPSILON) {
        err = err.max(50.0 * f64::EPSILON * abs_k);
    }
    (value, err)
}

/// `∫_a^b f(t) dt` by globally adaptive Gauss–Kronrod 7–15 to `max(abs_tol, rel_tol·|value|)`.
///
/// `a` and `b` may be infinite (`t = a + x/(1 − x)`, `x ∈ [0, 1)`, for `[a, ∞)`, its mirror for
/// `(−∞, b]`, and a split at 0 for the whole line); `b < a` gives minus the integral over
/// `[b, a]`. Equivalent to [`integrate_adaptive_breaks`] with `&[a, b]`.
pub fn integrate_adaptive(f: impl Fn(f64) -> f64, a: f64, b: f64, rel_tol: f64, abs_tol: f64) -> Quadrature {
    if b < a {
        let q = integrate_adaptive_breaks(&f, &[b, a], rel_tol, abs_tol);
        return Quadrature { value: -q.value, ..q };
    }
    integrate_adaptive_breaks(&f, &[a, b], rel_tol, abs_tol)
}

/// An interval awaiting refinement, ordered by its error estimate (largest first in the heap).
#[derive(Clone, Copy, Debug)]
struct Panel {
    /// Interval start (in the mapped variable).
    a: f64,
    /// Interval end (in the mapped variable).
    b: f64,
    /// Which mapping the interval lives in (index into the mapped integrands).
    map: usize,
    value: f64,
    err: f64,
}

impl PartialEq for Panel {
    fn eq(&self, o: &Self) -> bool {
        self.err.total_cmp(&o.err) == Ordering::Equal
    }
}
impl Eq for Panel {}
impl PartialOrd for Panel {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Panel {
    fn cmp(&self, o: &Self) -> Ordering {
        self.err.total_cmp(&o.err)
    }
}

/// How an interval's variable maps to `t`.
#[derive(Clone, Copy, Debug)]
enum Map {
    /// `t = x`.
    Identity,
    /// `t = p + x/(1 − x)`, `x ∈ [0, 1)`.
    Upper(f64),
    /// `t = p − x/(1 − x)`, `x ∈ [0, 1)` (integrated as `∫_0^1`, the orientation flip and the
    /// Jacobian's sign cancel).
    Lower(f64),
}

impl Map {
    /// The integrand in the mapped variable, `f(t(x))·|dt/dx|`; 0 at the infinite end itself.
    #[inline]
    fn eval(self, f: &impl Fn(f64) -> f64, x: f64) -> f64 {
        match self {
            Map::Identity => f(x),
            Map::Upper(p) | Map::Lower(p) => {
                let r = 1.0 - x;
                if r <= 0.0 {
                    return 0.0;
                }
                let s = x / r;
                let t = if matches!(self, Map::Upper(_)) { p + s } else { p - s };
                f(t) / (r * r)
            }
        }
    }
}

/// `∫` of `f` over `[breaks[0], breaks[last]]`, with interval ends at every break point.
///
/// Break points must be non-decreasing; the first may be `−∞` and the last `+∞`. Putting the
/// location of a peak, kink or jump of `f` into `breaks` lets the quadrature converge quickly
/// there. Fewer than two break points, or unordered or NaN ones, give a non-converged 0.
pub fn integrate_adaptive_breaks(
    f: impl Fn(f64) -> f64,
    breaks: &[f64],
    rel_tol: f64,
    abs_tol: f64,
) -> Quadrature {
    let fail = Quadrature { value: 0.0, error_estimate: f64::INFINITY, evaluations: 0, converged: false };
    if breaks.len() < 2 || breaks.windows(2).any(|w| w[0].is_nan() || w[1].is_nan() || w[1] < w[0]) {
        return fail;
    }
    let n = breaks.len();
    // Finite break points; the infinite ends become mapped intervals attached to the nearest one.
    let finite: Vec<f64> = breaks.iter().copied().filter(|x| x.is_finite()).collect();
    let lower_inf = breaks[0] == f64::NEG_INFINITY;
    let upper_inf = breaks[n - 1] == f64::INFINITY;
    let mut maps: Vec<Map> = vec![Map::Identity];
    let mut initial: Vec<(f64, f64, usize)> = Vec::new();
    if finite.is_empty() {
        // (−∞, ∞) with no finite point: split at 0; (−∞, −∞) or (∞, ∞): empty.
        if lower_inf && upper_inf {
            maps.push(Map::Lower(0.0));
            maps.push(Map::Upper(0.0));
            initial.push((0.0, 1.0, 1));
            initial.push((0.0, 1.0, 2));
        }
    } else {
        if lower_inf {
            maps.push(Map::Lower(finite[0]));
            initial.push((0.0, 1.0, maps.len() - 1));
        }
        for w in finite.windows(2) {
            if w[1] > w[0] {
                initial.push((w[0], w[1], 0));
            }
        }
        if upper_inf {
            maps.push(Map::Upper(finite[finite.len() - 1]));
            initial.push((0.0, 1.0, maps.len() - 1));
        }
    }

    let mut evaluations = 0u32;
    let mut heap = BinaryHeap::new();
    let mut done: Vec<Panel> = Vec::new();
    let mut total = 0.0;
    let mut total_err = 0.0;
    let mut finite_values = true;
    let panel = |a: f64, b: f64, map: usize, evaluations: &mut u32| {
        let m = maps[map];
        let (value, err) = gauss_kronrod_15(&|x| m.eval(&f, x), a, b);
        *evaluations += 15;
        Panel { a, b, map, value, err }
    };
    for &(a, b, m) in &initial {
        let p = panel(a, b, m, &mut evaluations);
        total += p.value;
        total_err += p.err;
        heap.push(p);
    }
    let mut intervals = heap.len();
    let mut converged = false;
    loop {
        if !(total.is_finite() && total_err.is_finite()) {
            finite_values = false;
            break;
        }
        if total_err <= abs_tol.max(rel_tol * total.abs()) {
            // Re-add from scratch to drop the running sums' drift before accepting.
            let (v, e) = heap.iter().chain(done.iter()).fold((0.0, 0.0), |s, p| (s.0 + p.value, s.1 + p.err));
            total = v;
            total_err = e;
            if total_err <= abs_tol.max(rel_tol * total.abs()) {
                converged = true;
                break;
            }
        }
        let Some(worst) = heap.pop() else { break };
        let mid = 0.5 * (worst.a + worst.b);
        if intervals >= MAX_INTERVALS || !(mid > worst.a && mid < worst.b) {
            done.push(worst);
            if intervals >= MAX_INTERVALS {
                break;
            }
            continue;
        }
        let left = panel(worst.a, mid, worst.map, &mut evaluations);
        let right = panel(mid, worst.b, worst.map, &mut evaluations);
        total += left.value + right.value - worst.value;
        total_err += left.err + right.err - worst.err;
        heap.push(left);
        heap.push(right);
        intervals += 1;
    }
    let (value, error_estimate) =
        heap.iter().chain(done.iter()).fold((0.0, 0.0), |s, p| (s.0 + p.value, s.1 + p.err));
    Quadrature { value, error_estimate, evaluations, converged: converged && finite_values }
}

/// Composite Simpson's rule over `[a, b]` with `m` subintervals (002 §3.4.4, the thesis's "分点数";
/// it measured `m = 100, 300, 500`): `h/3·(f₀ + 4f₁ + 2f₂ + … + 4f_{m−1} + f_m)`, `h = (b − a)/m`.
///
/// Simpson's rule needs an even `m`: an odd `m` is rounded up, and `m < 2` is taken as 2. Uses
/// `m + 1` evaluations.
pub fn composite_simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, m: u32) -> f64 {
    let m = m.max(2);
    let m = m + (m & 1);
    let h = (b - a) / f64::from(m);
    let mut odd = 0.0;
    let mut even = 0.0;
    for i in 1..m {
        let x = a + h * f64::from(i);
        if i % 2 == 1 {
            odd += f(x);
        } else {
            even += f(x);
        }
    }
    h / 3.0 * (f(a) + 4.0 * odd + 2.0 * even + f(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kronrod_weights_integrate_polynomials_exactly() {
        // K15 is exact to degree 22, G7 to degree 13; on [-1, 1], ∫x^k = 2/(k+1) for even k.
        for k in 0..=22 {
            let exact = if k % 2 == 0 { 2.0 / (k as f64 + 1.0) } else { 0.0 };
            let mut kv = WGK[7] * if k == 0 { 1.0 } else { 0.0 };
            let mut gv = WG[3] * if k == 0 { 1.0 } else { 0.0 };
            for j in 0..7 {
                let p = XGK[j].powi(k) + (-XGK[j]).powi(k);
                kv += WGK[j] * p;
                if j % 2 == 1 {
                    gv += WG[j / 2] * p;
                }
            }
            assert!((kv - exact).abs() < 1e-15, "K15 degree {k}: {kv} vs {exact}");
            if k <= 13 {
                assert!((gv - exact).abs() < 1e-15, "G7 degree {k}: {gv} vs {exact}");
            }
        }
    }

    #[test]
    fn gauss_nodes_are_legendre_roots() {
        // P7(x) = (429x^7 − 693x^5 + 315x^3 − 35x)/16.
        for j in [1, 3, 5, 7] {
            let x: f64 = XGK[j];
            let p = (429.0 * x.powi(7) - 693.0 * x.powi(5) + 315.0 * x.powi(3) - 35.0 * x) / 16.0;
            assert!(p.abs() < 1e-14, "node {x}: P7 = {p}");
        }
    }

    #[test]
    fn adaptive_resolves_a_narrow_peak() {
        let e: f64 = 1e-5;
        let q = integrate_adaptive(|t| 1.0 / (t * t + e * e), -1.0, 2.0, 1e-12, 0.0);
        let exact = ((2.0 / e).atan() + (1.0 / e).atan()) / e;
        assert!(q.converged);
        assert!(((q.value - exact) / exact).abs() < 1e-11, "{} vs {exact}", q.value);
        assert!(q.error_estimate >= (q.value - exact).abs());
    }

    #[test]
    fn adaptive_semi_infinite_and_whole_line() {
        let q = integrate_adaptive(|t| 1.0 / (1.0 + t * t), 0.0, f64::INFINITY, 1e-13, 0.0);
        assert!((q.value - std::f64::consts::FRAC_PI_2).abs() < 1e-12, "{}", q.value);
        let q = integrate_adaptive(|t| (-t * t).exp(), f64::NEG_INFINITY, f64::INFINITY, 1e-13, 0.0);
        assert!((q.value - std::f64::consts::PI.sqrt()).abs() < 1e-12, "{}", q.value);
        let q = integrate_adaptive(|t| (t * 0.5).exp(), f64::NEG_INFINITY, 1.0, 1e-13, 0.0);
        assert!((q.value - 2.0 * 0.5f64.exp()).abs() < 1e-12, "{}", q.value);
    }

    #[test]
    fn reversed_limits_negate_and_breaks_handle_jumps() {
        let q1 = integrate_adaptive(|t| t.sin(), 0.0, 2.0, 1e-13, 0.0);
        let q2 = integrate_adaptive(|t| t.sin(), 2.0, 0.0, 1e-13, 0.0);
        assert!((q1.value + q2.value).abs() < 1e-15);
        assert!((q1.value - (1.0 - 2f64.cos())).abs() < 1e-13);
        let step = |t: f64| if t < 0.3 { 1.0 } else { 5.0 };
        let q = integrate_adaptive_breaks(step, &[0.0, 0.3, 1.0], 1e-13, 0.0);
        assert!(q.converged);
        assert!((q.value - (0.3 + 3.5)).abs() < 1e-13, "{}", q.value);
        // Without the break point bisection still converges, more slowly.
        let q2 = integrate_adaptive(step, 0.0, 1.0, 1e-10, 0.0);
        assert!((q2.value - 3.8).abs() < 1e-9, "{}", q2.value);
        assert!(q2.evaluations > q.evaluations);
    }

    #[test]
    fn bad_breaks_and_non_finite_integrands_do_not_converge() {
        assert!(!integrate_adaptive_breaks(|t| t, &[1.0, 0.0], 1e-10, 0.0).converged);
        assert!(!integrate_adaptive_breaks(|t| t, &[f64::NAN, 1.0], 1e-10, 0.0).converged);
        assert!(!integrate_adaptive(|t| 1.0 / t, 0.0, 1.0, 1e-10, 0.0).converged);
    }

    #[test]
    fn simpson_is_exact_for_cubics_and_fourth_order() {
        let f = |t: f64| 3.0 * t * t * t - t + 2.0;
        let exact = 0.75 * 16.0 - 2.0 + 4.0 - (0.75 - 0.5 - 2.0);
        assert!((composite_simpson(f, -1.0, 2.0, 2) - exact).abs() < 1e-12);
        // Odd m is rounded up to even; error of exp falls ~16× per doubling of m.
        let e1 = (composite_simpson(f64::exp, 0.0, 1.0, 10) - (1f64.exp() - 1.0)).abs();
        let e2 = (composite_simpson(f64::exp, 0.0, 1.0, 20) - (1f64.exp() - 1.0)).abs();
        assert!((14.0..18.0).contains(&(e1 / e2)), "{}", e1 / e2);
        assert_eq!(composite_simpson(f64::exp, 0.0, 1.0, 9), composite_simpson(f64::exp, 0.0, 1.0, 10));
    }
}
