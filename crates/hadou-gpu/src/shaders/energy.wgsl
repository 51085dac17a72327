// WGSL twins of hadou_math::energy (thesis 002 §3.3, eq. 3.4–3.11, with SPEC.md §1.2's corrected
// asinh antiderivative and its stable single-logarithm evaluation). Each function names the Rust
// function it mirrors and follows it line by line, so the two agree to f32 rounding; read the Rust
// doc comments (crates/hadou-math/src/energy/{mod,kernel}.rs) for the derivations.
// Prepended by common.wgsl.
//
// Infinity: WGSL has no infinity literal and lets implementations assume values are finite, so
// ±T_OPEN stands for ±∞ (a ray that hits nothing in the inverse-square measure, and the unbounded
// capsule regions). Every use compares it against T_LIMIT (1e12), exactly as the Rust code treats
// infinity.

// The falloffs the frame's waves use (pipeline-overridable; see USE_SPHERE in wave.wgsl): the
// other one's integral is compiled out of rq_integral.
override USE_FAITHFUL: bool = true;
override USE_INVERSE_SQUARE: bool = true;
// Whether some product α·I of the frame can overflow f32 (energy_scaled's exponent arithmetic);
// without it every α·I of the frame is known to fit (passes/wave.rs WaveVariant::of: the analytic
// pieces are at most ENERGY_MAX, two of them summed at most twice that, and every α of an
// analytic wave at most WIDE_ALPHA there; every curve's α and the exposure at most 1), and α·I is
// one multiplication.
override USE_WIDE_SCALE: bool = true;
// Whether some beam of the frame has a head bulb (α_h ≠ 0), a muzzle bulb (α_m ≠ 0). A bulb of
// α = 0 adds nothing; a software adapter would still integrate it for every pixel under a mask.
override USE_BEAM_HEAD: bool = true;
override USE_BEAM_MUZZLE: bool = true;

const T_OPEN: f32 = 3.0e38;
// Mirrors hadou_math::energy::T_LIMIT.
const T_LIMIT: f32 = 1.0e12;
// Mirrors hadou_math::energy::H_FLOOR.
const H_FLOOR: f32 = 1.0e-24;
// Mirrors hadou_math::energy::ENERGY_MAX.
const ENERGY_MAX: f32 = 1.0e30;
// Mirrors hadou_math::energy::ENERGY_SATURATION (f32::MAX).
const ENERGY_SATURATION: f32 = 3.4028234663852886e38;

// Mirrors hadou_math::energy::saturate for the values the formulas produce: x ∈ [0, ∞) clamped
// to [0, f32::MAX]. WGSL may assume no infinity or NaN occurs, so the sums and products below are
// formed so that they never overflow (energy_add, energy_scaled) instead of relying on it.
fn energy_saturate(x: f32) -> f32 {
    return clamp(x, 0.0, ENERGY_SATURATION);
}

// (x + y) saturated at f32::MAX for x, y ∈ [0, f32::MAX], without overflowing: halves are added
// (exact for normal values) and doubled after the clamp. The Rust twin is saturate(x + y).
fn energy_add(x: f32, y: f32) -> f32 {
    return 2.0 * min(0.5 * x + 0.5 * y, 0.5 * ENERGY_SATURATION);
}

// Mirrors hadou_math::energy::scaled: α·I saturated, for I ∈ [0, ∞) and α ≥ 0 finite, without
// forming an overflowing product or dividing: with I = f·2^m and α = g·2^n (frexp, exact), the
// product is f·g·2^(m+n), and a quarter of it, ldexp(f·g, m+n−2), is finite whenever the product
// can be (m + n ≤ 129). The same rounding as I·α where that fits. (A quotient test, I ≥ MAX/α,
// fails on GPUs: compilers divide by multiplying with an approximate reciprocal that is zero or
// subnormal for α ≥ 2¹²⁶, and NVIDIA's saturated every energy of an α near f32::MAX.)
fn energy_scaled(integral: f32, alpha: f32) -> f32 {
    let i = energy_saturate(integral);
    if (!USE_WIDE_SCALE || alpha <= 1.0) {
        return i * alpha;
    }
    let a = frexp(i);
    let b = frexp(alpha);
    let e = a.exp + b.exp;
    if (e > 129) {
        return ENERGY_SATURATION;
    }
    let quarter = ldexp(a.fract * b.fract, e - 2);
    if (quarter >= 0.25 * ENERGY_SATURATION) {
        return ENERGY_SATURATION;
    }
    return 4.0 * quarter;
}

// f32::EPSILON and f32::MIN_POSITIVE.
const F32_EPSILON: f32 = 1.1920929e-7;
const F32_MIN_POSITIVE: f32 = 1.17549435e-38;

// Mirrors hadou_math::energy::FieldParams<f32>.
struct FieldParams {
    falloff: u32,
    core_radius: f32,
}

// Mirrors hadou_math::energy::Ray<f32>.
struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

// Mirrors hadou_math::energy::RayAxis<f32>.
struct RayAxis {
    s: f32,
    unit: vec3<f32>,
}

// Mirrors hadou_math::energy::RayQuadratic<f32>: |v + t·u|² + r_c² = Y(t)² + H, Y = s·t + β.
struct RayQuadratic {
    s: f32,
    beta: f32,
    h: f32,
}

// Mirrors RayAxis::new.
fn ray_axis(u: vec3<f32>) -> RayAxis {
    let a = dot3(u, u);
    if (a >= F32_MIN_POSITIVE) {
        let s = sqrt(a);
        return RayAxis(s, u * (1.0 / s));
    }
    return RayAxis(0.0, vec3<f32>(0.0));
}

// Mirrors RayQuadratic::new.
fn ray_quadratic(axis: RayAxis, v: vec3<f32>, rc2: f32) -> RayQuadratic {
    let beta = dot3(axis.unit, v);
    var d2 = dot3(v, v);
    if (axis.s > 0.0) {
        let c = cross3(axis.unit, v);
        d2 = dot3(c, c);
    }
    return RayQuadratic(axis.s, beta, max(d2 + rc2, H_FLOOR));
}

// f32::ln_1p for EPSILON < z < 1/16, where RayQuadratic::faithful uses it (WGSL has no log1p):
// the alternating series to z⁸, relative error below z⁸/9 < 3e-11.
fn ln_1p_small(z: f32) -> f32 {
    return z * (1.0 - z * (0.5 - z * (1.0 / 3.0 - z * (0.25 - z * (0.2 - z * (1.0 / 6.0 - z * (1.0 / 7.0 - z * 0.125)))))));
}

// Mirrors RayQuadratic::faithful: ∫ dt / sqrt(Y² + H) as one logarithm (002 eq. 3.8–3.9,
// corrected asinh antiderivative; the stable single-log form of the Rust doc comment).
fn rq_faithful(q: RayQuadratic, t0_in: f32, t1_in: f32) -> f32 {
    if (!(t1_in > t0_in)) {
        return 0.0;
    }
    let t0 = max(t0_in, -T_LIMIT);
    let t1 = min(t1_in, T_LIMIT);
    if (t1 <= t0) {
        return 0.0;
    }
    let s = q.s;
    let h = q.h;
    let dt = t1 - t0;
    let y0 = s * t0 + q.beta;
    let y1 = s * t1 + q.beta;
    let r0 = sqrt(y0 * y0 + h);
    let r1 = sqrt(y1 * y1 + h);
    let sum = y0 + y1;
    let rs = r0 + r1;
    // k = Δt·(1 ± q)/P with q = sum/rs, as one division: P₀ = y₀ + r₀ = H/(r₀ − y₀),
    // N₁ = r₁ − y₁ = H/(r₁ + y₁).
    var num = 0.0;
    var a = 1.0;
    var b = 0.0;
    if (sum >= 0.0) {
        if (y0 >= 0.0) {
            b = y0 + r0;
        } else {
            a = r0 - y0;
            b = h;
        }
        num = rs + sum;
    } else {
        if (y1 <= 0.0) {
            b = r1 - y1;
        } else {
            a = r1 + y1;
            b = h;
        }
        num = rs - sum;
    }
    let k = dt * num * a / (rs * b);
    let z = s * k;
    // ln(1 + z)/s, by the series for small z: both forms share one division.
    let ln_1p = select(ln_1p_small(z), log(1.0 + z), z >= 0.0625);
    let v = select(k, ln_1p / s, z > F32_EPSILON);
    return min(max(v, 0.0), ENERGY_MAX);
}

// Mirrors RayQuadratic::inverse_square: ∫ dt / (Y² + H) as one atan2; t1 ≥ T_LIMIT means +∞.
fn rq_inverse_square(q: RayQuadratic, t0: f32, t1: f32) -> f32 {
    if (!(t1 > t0)) {
        return 0.0;
    }
    let s = q.s;
    let h = q.h;
    let sh = sqrt(h);
    let y0 = s * t0 + q.beta;
    var v = 0.0;
    if (t1 < T_LIMIT && t0 > -T_LIMIT) {
        let y1 = s * t1 + q.beta;
        let dt = t1 - t0;
        let num = sh * s * dt;
        let den = h + y0 * y1;
        if (num <= F32_EPSILON * den) {
            v = dt / den;
        } else {
            v = atan2(num, den) / (s * sh);
        }
    } else {
        var num = 0.0;
        var den = -1.0;
        if (t0 > -T_LIMIT) {
            num = sh;
            den = y0;
        } else if (t1 < T_LIMIT) {
            num = sh;
            den = -(s * t1 + q.beta);
        }
        v = atan2(num, den) / (s * sh);
    }
    return min(max(v, 0.0), ENERGY_MAX);
}

// Mirrors RayQuadratic::integral.
fn rq_integral(q: RayQuadratic, falloff: u32, t0: f32, t1: f32) -> f32 {
    if (falloff == FALLOFF_FAITHFUL) {
        if (USE_FAITHFUL) {
            return rq_faithful(q, t0, t1);
        }
        return 0.0;
    }
    if (USE_INVERSE_SQUARE) {
        return rq_inverse_square(q, t0, t1);
    }
    return 0.0;
}

// Mirrors hadou_math::energy::Attenuation<f32>: the factor (1 − t/t_far)^j of 002 eq. 3.23
// (SPEC.md §1.4); j = 0 is none.
struct Attenuation {
    j: f32,
    t_far: f32,
}

// Mirrors Attenuation::none.
fn att_none() -> Attenuation {
    return Attenuation(0.0, 1.0);
}

// #if ATTENUATION
// Mirrors Attenuation::factor: (1 − t/t_far)^j, 0 from the far point on.
fn att_factor(att: Attenuation, t: f32) -> f32 {
    let h = 1.0 - t / att.t_far;
    if (h > 0.0) {
        return pow(h, att.j);
    }
    return 0.0;
}

// Mirrors attenuated.rs GL_X and GL_W: 8-point Gauss–Legendre on [0, 1].
const ATT_GL_X = array<f32, 8>(0.019855071751231884, 0.10166676129318664, 0.2372337950418355,
    0.4082826787521751, 0.591717321247825, 0.7627662049581645, 0.8983332387068134, 0.9801449282487681);
const ATT_GL_W = array<f32, 8>(0.05061426814518813, 0.11119051722668724, 0.15685332293894363,
    0.181341891689181, 0.181341891689181, 0.15685332293894363, 0.11119051722668724, 0.05061426814518813);
// Mirrors hadou_math::energy::FAR_GRADE, FAR_RATIO_MIN, APPROACH_RATIO and LEAVE_GROWTH.
const ATT_FAR_GRADE: f32 = 4.0;
const ATT_FAR_RATIO_MIN: f32 = 0.25;
const ATT_APPROACH_RATIO: f32 = 0.2;
const ATT_LEAVE_GROWTH: f32 = 4.0;
// Mirrors hadou_math::energy::MAX_CELLS, REST_TOLERANCE and INNER_CELL.
const ATT_MAX_CELLS: u32 = 192u;
const ATT_REST_TOLERANCE: f32 = 1.0e-5;
const ATT_INNER_CELL: f32 = 1.0;
// Mirrors hadou_math::energy::PEAK_RANGE.
const ATT_PEAK_RANGE: f32 = 1.0e20;

// The density (Y² + H)^{-1/2} or (Y² + H)^{-1} (attenuated.rs `density`).
fn att_density(falloff: u32, y: f32, h: f32) -> f32 {
    let r2 = y * y + h;
    if (falloff == FALLOFF_FAITHFUL) {
        return 1.0 / sqrt(r2);
    }
    return 1.0 / r2;
}

// Mirrors RayQuadratic::mean_g_line: g averaged over [x, y] against w, 8 Gauss–Legendre nodes
// uniform in t.
fn att_mean_line(q: RayQuadratic, falloff: u32, x: f32, y: f32, att: Attenuation) -> f32 {
    var xs = ATT_GL_X;
    var ws = ATT_GL_W;
    let dt = y - x;
    var num = 0.0;
    var den = 0.0;
    var plain = 0.0;
    for (var i = 0; i < 8; i++) {
        let t = x + xs[i] * dt;
        let g = att_factor(att, t);
        let w = ws[i] * att_density(falloff, q.s * t + q.beta, q.h);
        num += w * g;
        den += w;
        plain += ws[i] * g;
    }
    if (den > 0.0) {
        return num / den;
    }
    return plain;
}

// Mirrors RayQuadratic::mean_g_peak: g averaged over the inner cell [x, y] around the peak (s > 0),
// 8 Gauss–Legendre nodes uniform in ψ = asinh(Y/√H) (faithful) or θ = atan(Y/√H).
fn att_mean_peak(q: RayQuadratic, falloff: u32, x: f32, y: f32, att: Attenuation) -> f32 {
    var xs = ATT_GL_X;
    var ws = ATT_GL_W;
    let sh = sqrt(q.h);
    let yx = (q.s * x + q.beta) / sh;
    let yy = (q.s * y + q.beta) / sh;
    var px = atan(yx);
    var py = atan(yy);
    if (falloff == FALLOFF_FAITHFUL) {
        px = asinh(yx);
        py = asinh(yy);
    }
    var sum = 0.0;
    for (var i = 0; i < 8; i++) {
        let p = px + xs[i] * (py - px);
        var v = tan(p);
        if (falloff == FALLOFF_FAITHFUL) {
            let e = exp(p);
            v = 0.5 * (e - 1.0 / e);
        }
        let t = clamp((v * sh - q.beta) / q.s, x, y);
        sum += ws[i] * att_factor(att, t);
    }
    return sum;
}

// Mirrors hadou_math::energy::TAIL_MIN_J, TAIL_REACH and TAIL_REACH_MIN.
const ATT_TAIL_MIN_J: f32 = 1.0;
const ATT_TAIL_REACH: f32 = 2.0;
const ATT_TAIL_REACH_MIN: f32 = 1.25;

// Mirrors RayQuadratic::tail: ∫_x^{t_far} g w dt by 8-point Gauss–Laguerre for span = t_far − x and
// weight = span·g(x) (the density sampled at t = t_far − span·e^{−u/(j+1)}).
fn att_tail(q: RayQuadratic, falloff: u32, tf: f32, span: f32, weight: f32, j: f32) -> f32 {
    var us = array<f32, 8>(0.17027963230510093, 0.90370177679938, 2.251086629866131, 4.266700170287659,
        7.0459054023934655, 10.758516010180996, 15.740678641278004, 22.863131736889265);
    var ws = array<f32, 8>(0.36918858934163495, 0.4187867808143447, 0.17579498663717255,
        0.033343492261215794, 0.0027945362352256834, 9.076508773358139e-5, 8.48574671627257e-7,
        1.0480011748715153e-9);
    let j1 = j + 1.0;
    var sum = 0.0;
    for (var i = 0; i < 8; i++) {
        let t = tf - span * exp(-us[i] / j1);
        sum += ws[i] * att_density(falloff, q.s * t + q.beta, q.h);
    }
    return weight / j1 * sum;
}

// Mirrors RayQuadratic::attenuated: ∫ (1 − t/t_far)^j w(t) dt over [t0, min(t1, t_far)] (002 eq.
// 3.23, SPEC.md §1.4) by 8-point Gauss–Legendre on graded cells, each weighted by the closed form
// (see the Rust module docs of hadou_math::energy::attenuated for the grading).
fn rq_attenuated(q: RayQuadratic, falloff: u32, t0: f32, t1: f32, att: Attenuation) -> f32 {
    let tf = att.t_far;
    let a = max(t0, -T_LIMIT);
    let b = min(t1, tf);
    if (!(b > a && tf > 0.0)) {
        return 0.0;
    }
    let total = rq_integral(q, falloff, a, b);
    if (!(total > 0.0)) {
        return 0.0;
    }
    let s = q.s;
    let sh = sqrt(q.h);
    // A peak only where t_c = −β/s and ε = √H/s stay far below overflow.
    let has_peak = s > 0.0 && sh <= s * ATT_PEAK_RANGE && abs(q.beta) <= s * ATT_PEAK_RANGE;
    var tc = 0.0;
    var dmin = 0.0;
    if (has_peak) {
        tc = -q.beta / s;
        dmin = ATT_INNER_CELL * (sh / s);
    }
    let ratio = max(exp(-ATT_FAR_GRADE / att.j), ATT_FAR_RATIO_MIN);
    // The far tail: where the peak's singularities are far from t_far (or there is no peak).
    let tail_on = att.j >= ATT_TAIL_MIN_J;
    var tail_reach = 3.0e38; // no peak: the tail from the start
    if (has_peak) {
        let dc = tf - tc;
        let eps = sh / s;
        let reach = max(1.0 + ATT_TAIL_REACH * pow(att.j, -2.0 / 3.0), ATT_TAIL_REACH_MIN);
        tail_reach = sqrt(dc * dc + eps * eps) / reach;
    }
    let beyond = (tf - b) * att_factor(att, b);
    var x = a;
    var acc = 0.0;
    var used = 0.0;
    var cells = 0u;
    loop {
        if (!(x < b)) {
            break;
        }
        if (tail_on && tf - x <= tail_reach) {
            // ∫_x^{t_far} − ∫_b^{t_far}, the second at most half the first (else march on).
            let within = (tf - x) * att_factor(att, x);
            if (beyond <= 0.5 * within) {
                var tail = att_tail(q, falloff, tf, tf - x, within, att.j);
                if (beyond > 0.0) {
                    tail -= att_tail(q, falloff, tf, tf - b, beyond, att.j);
                }
                acc += max(tail, 0.0);
                break;
            }
        }
        let graded = min(b, tf - ratio * (tf - x));
        var y = graded;
        var inner = false;
        if (cells + 1u >= ATT_MAX_CELLS) {
            y = b;
        } else if (has_peak) {
            if (x < tc - dmin) {
                y = min(y, min(tc - (tc - x) * ATT_APPROACH_RATIO, tc - dmin));
            } else if (x < tc + dmin) {
                y = min(y, tc + dmin);
                inner = true;
            } else {
                y = min(y, x + ATT_LEAVE_GROWTH * max(x - tc, dmin));
            }
        }
        if (!(y > x)) {
            // A peak narrower than one ulp of t: a step of about two ulps.
            y = min(x + max(abs(x) * 2.0 * F32_EPSILON, F32_MIN_POSITIVE), b);
            if (!(y > x)) {
                y = b;
            }
        }
        let i0 = rq_integral(q, falloff, x, y);
        var gbar = 0.0;
        if (inner) {
            gbar = att_mean_peak(q, falloff, x, y, att);
        } else {
            gbar = att_mean_line(q, falloff, x, y, att);
        }
        acc += i0 * gbar;
        used += i0;
        cells += 1u;
        x = y;
        if (x < b) {
            let rest = max(total - used, 0.0);
            if (att_factor(att, x) * rest <= ATT_REST_TOLERANCE * acc) {
                break;
            }
        }
    }
    return min(max(acc, 0.0), ENERGY_MAX);
}

// #endif

// One piece: rq_integral, or rq_attenuated where att.j > 0 (the Rust shapes' `piece`). A module
// composed without ATTENUATION (no wave of the frame has j > 0; shaders.rs `compose_with`) holds
// none of the march above.
fn rq_piece(q: RayQuadratic, falloff: u32, t0: f32, t1: f32, att: Attenuation) -> f32 {
// #if ATTENUATION
    if (att.j > 0.0) {
        return rq_attenuated(q, falloff, t0, t1, att);
    }
// #endif
    return rq_integral(q, falloff, t0, t1);
}

// The analytic kinds, bits of analytic_energy's `kinds` (a module passes the kinds its variant has
// compiled in, which the driver then folds as constants).
const KIND_BIT_SPHERE: u32 = 1u;
const KIND_BIT_CYLINDER: u32 = 2u;
const KIND_BIT_CAPSULE: u32 = 4u;
const KIND_BIT_BEAM: u32 = 8u;
const KIND_BITS_ALL: u32 = 15u;

// The pieces of a capsule (and a bulged beam) along `ray` over [t0, t1] (capsule_parts, 002 eq.
// 3.10–3.11): the sphere around the first end crossed over [c0, lo], the cylinder between the
// planes through M and M₂ with normal D over [lo, hi], the sphere around the other end over
// [hi, c1]; and the two end spheres (the beam's bulbs at M₂ and M, over the whole span).
struct CapsulePieces {
    first: RayQuadratic,
    last: RayQuadratic,
    cylinder: RayQuadratic,
    at_m: RayQuadratic,
    at_m2: RayQuadratic,
    c0: f32,
    lo: f32,
    hi: f32,
    c1: f32,
}

fn capsule_pieces(ray: Ray, t0: f32, t1: f32, w: GpuWave, rc2: f32) -> CapsulePieces {
    let m = w.p0.xyz;
    let d = w.p1.xyz;
    let length = w.p2.x;
    // An empty or NaN interval: every piece empty (the clamps below would turn a NaN into an
    // end).
    var c0 = 0.0;
    var c1 = 0.0;
    if (t1 > t0) {
        c0 = t0;
        c1 = t1;
    }
    let q = ray.dir;
    let wm = ray.origin - m;
    let sphere_axis = ray_axis(q);
    let at_m = ray_quadratic(sphere_axis, wm, rc2);
    let at_m2 = ray_quadratic(sphere_axis, wm - d * length, rc2);
    let cyl = ray_quadratic(ray_axis(cross3(q, d)), cross3(wm, d), rc2);
    let dq = dot3(q, d);
    let ds = dot3(wm, d);
    var lo = 0.0;
    var hi = 0.0;
    var first_is_m = true;
    if (dq > 0.0) {
        lo = -ds / dq;
        hi = (length - ds) / dq;
    } else if (dq < 0.0) {
        lo = (length - ds) / dq;
        hi = -ds / dq;
        first_is_m = false;
    } else if (ds < 0.0) {
        lo = T_OPEN;
        hi = T_OPEN;
    } else if (ds > length) {
        lo = -T_OPEN;
        hi = -T_OPEN;
    } else {
        lo = -T_OPEN;
        hi = T_OPEN;
    }
    lo = clamp(lo, c0, c1);
    hi = clamp(hi, lo, c1);
    var out: CapsulePieces;
    out.first = at_m;
    out.last = at_m2;
    if (!first_is_m) {
        out.first = at_m2;
        out.last = at_m;
    }
    out.cylinder = cyl;
    out.at_m = at_m;
    out.at_m2 = at_m2;
    out.c0 = c0;
    out.lo = lo;
    out.hi = hi;
    out.c1 = c1;
    return out;
}

// The energy of one analytic wave `w` (sphere, cylinder, capsule or bulged beam) along `ray` over
// [t0, t1], its kind taken only if its bit is in `kinds` (else 0). Mirrors, by kind:
// - hadou_math::energy::sphere_energy (002 eq. 3.4, 3.6, 3.8): one piece around the centre M;
// - cylinder_energy (002 eq. 3.5, 3.7, 3.9): one piece about the axis through M along D;
// - capsule_energy (capsule_parts, 002 eq. 3.10–3.11): the sphere around the first end crossed,
//   the cylinder between the planes through M and M₂ with normal D, the sphere around the other;
// - beam_energy (SPEC.md §1.2, the bulged beam): the capsule plus bulbs at M₂ (head) and M
//   (muzzle);
// each piece with the attenuation where att.j > 0 (the *_energy_attenuated twins, 002 eq. 3.23,
// SPEC.md §1.4). The pieces are gathered first and integrated by ONE call of rq_piece in a loop:
// a driver inlines every call site, and the attenuated march is the largest code of the wave
// module, so one call site instead of ten keeps a module with every kind (the uber-shader) small
// enough to compile in seconds on a software adapter.
fn analytic_energy(p: FieldParams, ray: Ray, t0: f32, t1: f32, att: Attenuation, w: GpuWave, kinds: u32) -> f32 {
    let rc2 = p.core_radius * p.core_radius;
    let sphere = (kinds & KIND_BIT_SPHERE) != 0u && w.kind == WAVE_SPHERE;
    let cylinder = (kinds & KIND_BIT_CYLINDER) != 0u && w.kind == WAVE_CYLINDER;
    let beam = (kinds & KIND_BIT_BEAM) != 0u && w.kind == WAVE_BEAM;
    let capsule = beam || ((kinds & KIND_BIT_CAPSULE) != 0u && w.kind == WAVE_CAPSULE);
    var qs: array<RayQuadratic, 5>;
    var a = array<f32, 5>(t0, t0, t0, t0, t0);
    var b = array<f32, 5>(t1, t1, t1, t1, t1);
    var n = 0u;
    if (sphere) {
        qs[0] = ray_quadratic(ray_axis(ray.dir), ray.origin - w.p0.xyz, rc2);
        n = 1u;
    } else if (cylinder) {
        let d = w.p1.xyz;
        qs[0] = ray_quadratic(ray_axis(cross3(ray.dir, d)), cross3(ray.origin - w.p0.xyz, d), rc2);
        n = 1u;
    } else if (capsule) {
        let c = capsule_pieces(ray, t0, t1, w, rc2);
        qs[0] = c.first;
        qs[1] = c.last;
        a[0] = c.c0;
        b[0] = c.lo;
        a[1] = c.hi;
        b[1] = c.c1;
        qs[2] = c.cylinder;
        a[2] = c.lo;
        b[2] = c.hi;
        n = 3u;
        if (beam) {
            // Pieces 3 and 4: the head's bulb at M₂ and the muzzle's at M, over the whole span.
            qs[3] = c.at_m2;
            qs[4] = c.at_m;
            n = 5u;
        }
    }
    var e = array<f32, 5>(0.0, 0.0, 0.0, 0.0, 0.0);
    for (var k = 0u; k < n; k++) {
        e[k] = rq_piece(qs[k], p.falloff, a[k], b[k], att);
    }
    if (sphere || cylinder) {
        return energy_scaled(e[0], w.p0.w);
    }
    if (!capsule) {
        return 0.0;
    }
    // α_s = p0.w, α_c = p1.w; the beam's head and muzzle strengths p2.y, p2.z.
    var energy = energy_add(energy_scaled(e[0] + e[1], w.p0.w), energy_scaled(e[2], w.p1.w));
    if (beam) {
        if (USE_BEAM_HEAD && w.p2.y != 0.0) {
            energy = energy_add(energy, energy_scaled(e[3], w.p2.y));
        }
        if (USE_BEAM_MUZZLE && w.p2.z != 0.0) {
            energy = energy_add(energy, energy_scaled(e[4], w.p2.z));
        }
    }
    return energy;
}

// analytic_energy in a module without ATTENUATION: the same pieces, each integrated where it is
// made (rq_integral is small), with no arrays indexed in a loop, which a software adapter keeps
// in memory and reads lane by lane (the faithful sphere at 512² on lavapipe took 2.8× longer
// through the arrays).
fn analytic_energy_direct(p: FieldParams, ray: Ray, t0: f32, t1: f32, w: GpuWave, kinds: u32) -> f32 {
    let rc2 = p.core_radius * p.core_radius;
    let beam = (kinds & KIND_BIT_BEAM) != 0u && w.kind == WAVE_BEAM;
    if ((kinds & KIND_BIT_SPHERE) != 0u && w.kind == WAVE_SPHERE) {
        let q = ray_quadratic(ray_axis(ray.dir), ray.origin - w.p0.xyz, rc2);
        return energy_scaled(rq_integral(q, p.falloff, t0, t1), w.p0.w);
    }
    if ((kinds & KIND_BIT_CYLINDER) != 0u && w.kind == WAVE_CYLINDER) {
        let d = w.p1.xyz;
        let q = ray_quadratic(ray_axis(cross3(ray.dir, d)), cross3(ray.origin - w.p0.xyz, d), rc2);
        return energy_scaled(rq_integral(q, p.falloff, t0, t1), w.p0.w);
    }
    if (!(beam || ((kinds & KIND_BIT_CAPSULE) != 0u && w.kind == WAVE_CAPSULE))) {
        return 0.0;
    }
    let c = capsule_pieces(ray, t0, t1, w, rc2);
    let ends = rq_integral(c.first, p.falloff, c.c0, c.lo) + rq_integral(c.last, p.falloff, c.hi, c.c1);
    var energy = energy_add(energy_scaled(ends, w.p0.w), energy_scaled(rq_integral(c.cylinder, p.falloff, c.lo, c.hi), w.p1.w));
    if (beam) {
        if (USE_BEAM_HEAD && w.p2.y != 0.0) {
            energy = energy_add(energy, energy_scaled(rq_integral(c.at_m2, p.falloff, t0, t1), w.p2.y));
        }
        if (USE_BEAM_MUZZLE && w.p2.z != 0.0) {
            energy = energy_add(energy, energy_scaled(rq_integral(c.at_m, p.falloff, t0, t1), w.p2.z));
        }
    }
    return energy;
}
