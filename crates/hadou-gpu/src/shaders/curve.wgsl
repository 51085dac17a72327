// WGSL twins of hadou_math::curve (002 §3.4, SPEC.md §1.4): shape evaluation (shape.rs), the
// closed-form pieces (closed.rs), the default integrator's chord walk over the PieceTable
// (integrate.rs), the faithful Simpson integrator (simpson.rs) and the nearest-point field
// (nearest.rs). Prepended by common.wgsl and
// energy.wgsl. The data layout (GpuCurve, curve_vec4, curve_f32) is built by
// hadou_gpu::layout::CurveBuffers; keep in sync with layout/.

// Storage buffers of the curve data. Every module that includes this file declares them at
// these bindings; keep in sync with CurveBuffers in layout/.
@group(0) @binding(5) var<storage, read> curves: array<GpuCurve>;
// PieceTable::nodes then PieceTable::lines of every curve, one vec4 each.
@group(0) @binding(6) var<storage, read> curve_vec4: array<vec4<f32>>;
// Control points (y, z pairs), trig terms, knots, PieceTable::errors and the level offsets
// (u32 bits) of every curve.
@group(0) @binding(7) var<storage, read> curve_f32: array<f32>;

// The integrators and shapes the frame's curves use (pipeline-overridable; see USE_SPHERE in
// wave.wgsl): the others are compiled out of curve_energy and curve_eval.
override USE_CHORD: bool = true;
override USE_SIMPSON: bool = true;
override USE_NEAREST: bool = true;
override USE_HELIX: bool = true;
override USE_TRIG: bool = true;
override USE_BEZIER: bool = true;
override USE_BSPLINE: bool = true;

// `dt` above this is an open (infinite) span: the GPU's stand-in for f32::INFINITY is T_OPEN.
const CURVE_INF: f32 = 1.0e38;
const F32_MAX: f32 = 3.4028234663852886e38;

// f32::is_finite.
fn curve_finite(x: f32) -> bool {
    return abs(x) <= F32_MAX;
}

// f32::ln_1p (for x > −1): the series below 1/16, else log with the rounding of 1 + x corrected.
fn curve_ln_1p(x: f32) -> f32 {
    if (abs(x) < 0.0625) {
        return ln_1p_small(x);
    }
    let u = 1.0 + x;
    return log(u) - ((u - 1.0) - x) / u;
}

// ---- shape.rs ----

// Control point / term pair `i` of curve `c`.
fn curve_pair(start: u32, i: u32) -> vec2<f32> {
    return vec2<f32>(curve_f32[start + 2u * i], curve_f32[start + 2u * i + 1u]);
}

// Mirrors shape.rs `trig_sum` (002 eq. 3.30).
fn curve_trig_sum(rate: f32, s: f32, start: u32, count: u32) -> f32 {
    var acc = 0.0;
    var n = 0.0;
    for (var k = 0u; k < count; k++) {
        n += 1.0;
        let a = n * rate * s;
        let t = curve_pair(start, k);
        acc += t.x * sin(a) + t.y * cos(a);
    }
    return acc;
}

// Mirrors shape.rs `bezier` (002 eq. 3.31–3.32, nested Bernstein form).
fn curve_bezier(c: GpuCurve, s: f32) -> vec2<f32> {
    let n = c.point_count - 1u;
    let u = 1.0 - s;
    var acc = curve_pair(c.points, 0u) * u;
    var sn = 1.0;
    var binom = 1.0;
    for (var i = 1u; i < n; i++) {
        sn *= s;
        binom = binom * f32(n + 1u - i) / f32(i);
        let w = sn * binom;
        acc = (acc + w * curve_pair(c.points, i)) * u;
    }
    let w = sn * s;
    return acc + w * curve_pair(c.points, n);
}

fn curve_knot(c: GpuCurve, i: u32) -> f32 {
    return curve_f32[c.knots + i];
}

// Mirrors shape.rs `find_span`.
fn curve_find_span(c: GpuCurve, tau: f32) -> u32 {
    let order = c.order;
    let n = c.point_count - 1u;
    var lo = order - 1u;
    var hi = n;
    if (tau >= curve_knot(c, n + 1u)) {
        var m = n;
        while (m > order - 1u && curve_knot(c, m) >= curve_knot(c, n + 1u)) {
            m -= 1u;
        }
        return m;
    }
    if (tau <= curve_knot(c, lo)) {
        var m = lo;
        while (m < n && curve_knot(c, m + 1u) <= curve_knot(c, lo)) {
            m += 1u;
        }
        return m;
    }
    while (hi > lo) {
        let mid = (lo + hi + 1u) / 2u;
        if (curve_knot(c, mid) <= tau) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    return lo;
}

// Mirrors shape.rs `bspline` with `basis_funs` (002 eq. 3.33–3.34, Cox–de Boor triangle).
fn curve_bspline(c: GpuCurve, tau: f32) -> vec2<f32> {
    let span = curve_find_span(c, tau);
    var nb: array<f32, 16>;
    var left: array<f32, 16>;
    var right: array<f32, 16>;
    nb[0] = 1.0;
    for (var d = 1u; d < c.order; d++) {
        left[d] = tau - curve_knot(c, span + 1u - d);
        right[d] = curve_knot(c, span + d) - tau;
        var saved = 0.0;
        for (var r = 0u; r < d; r++) {
            let denom = right[r + 1u] + left[d - r];
            var temp = 0.0;
            if (denom > 0.0) {
                temp = nb[r] / denom;
            }
            nb[r] = saved + right[r + 1u] * temp;
            saved = left[d - r] * temp;
        }
        nb[d] = saved;
    }
    var acc = vec2<f32>(0.0);
    for (var r = 0u; r < c.order; r++) {
        acc += nb[r] * curve_pair(c.points, span + 1u + r - c.order);
    }
    return acc;
}

// Mirrors shape.rs `ShapeEval::eval`: the cross-section point (y(s), z(s)).
fn curve_eval(c: GpuCurve, s: f32) -> vec2<f32> {
    // Each shape is compiled in only when the frame has it (USE_HELIX … USE_BSPLINE).
    switch c.shape {
        case SHAPE_HELIX: {
            if (USE_HELIX) {
                let a = c.rate * s + c.phase;
                return vec2<f32>(c.radius * sin(a), c.radius * cos(a));
            }
        }
        case SHAPE_TRIG: {
            if (USE_TRIG) {
                let zs = c.points + 2u * c.y_terms;
                return vec2<f32>(curve_trig_sum(c.rate, s, c.points, c.y_terms), curve_trig_sum(c.rate, s, zs, c.z_terms));
            }
        }
        case SHAPE_BEZIER: {
            if (USE_BEZIER) {
                return curve_bezier(c, s);
            }
        }
        case SHAPE_BSPLINE: {
            if (USE_BSPLINE) {
                let tau = c.lo + clamp(s, 0.0, 1.0) * (c.hi - c.lo);
                return curve_bspline(c, tau);
            }
        }
        // No other shape is made (layout/ CurveBuffers::push); one without its case has no
        // kernel (passes/wave.rs every_wave_kind_has_a_kernel).
        default: {}
    }
    return vec2<f32>(0.0);
}

// ---- local_ray.rs: LocalRay ----

// Mirrors local_ray.rs `LocalRay`.
struct LocalRay {
    o: vec3<f32>,
    q: vec3<f32>,
    t0: f32,
    t1: f32,
    t_far: f32,
    j: f32,
    rc2: f32,
    falloff: u32,
    alpha: f32,
    x_head: f32,
}

// Mirrors `LocalRay::new`; `ok` is false where Rust returns None. An open end is t1 ≥ T_OPEN.
fn curve_local_ray(c: GpuCurve, falloff: u32, core_radius: f32, ray: Ray, t0: f32, t1_in: f32, t_far_in: f32, ok: ptr<function, bool>) -> LocalRay {
    var t_far = 1.0;
    if (curve_finite(t_far_in) && t_far_in > 0.0) {
        t_far = t_far_in;
    }
    let j = c.attenuation;
    var t1 = t1_in;
    if (falloff == FALLOFF_FAITHFUL && t1 >= T_OPEN) {
        t1 = t_far;
    }
    if (j > 0.0) {
        t1 = min(t1, t_far);
    }
    *ok = curve_finite(t0) && t1 > t0 && all(abs(ray.origin) <= vec3<f32>(F32_MAX)) && all(abs(ray.dir) <= vec3<f32>(F32_MAX));
    var rc = c.core_floor;
    if (curve_finite(core_radius)) {
        rc = max(abs(core_radius), c.core_floor);
    }
    let w = ray.origin - c.origin;
    let o = vec3<f32>(dot3(w, c.axis_d), dot3(w, c.axis_y), dot3(w, c.axis_z));
    let q = vec3<f32>(dot3(ray.dir, c.axis_d), dot3(ray.dir, c.axis_y), dot3(ray.dir, c.axis_z));
    return LocalRay(o, q, t0, t1, t_far, j, rc * rc, falloff, c.alpha, c.x_head);
}

// Mirrors `LocalRay::attenuation`: (1 − t/t_far)^j (002 eq. 3.23), 0 beyond the far point.
fn curve_attenuation(r: LocalRay, t: f32) -> f32 {
// #if ATTENUATION
    if (r.j == 0.0) {
        return 1.0;
    }
    let u = 1.0 - t / r.t_far;
    if (u <= 0.0) {
        return 0.0;
    }
    return pow(u, r.j);
// #else
    return 1.0;
// #endif
}

// ---- closed.rs: Segment ----

// Mirrors closed.rs `Segment`.
struct Segment {
    value: f32,
    falloff: u32,
    dt: f32,
    y0: f32,
    y1: f32,
    span: f32,
    flipped: bool,
    e: f32,
    delta: f32,
}

// Mirrors closed.rs `Quad`: (pp, vv, pv, E) of |p + vτ|² + rc2, E = |p × v|² + rc2·vv.
fn quad_new(p: vec3<f32>, v: vec3<f32>, rc2: f32) -> vec4<f32> {
    let vv = dot3(v, v);
    let cr = cross3(p, v);
    return vec4<f32>(dot3(p, p), vv, dot3(p, v), dot3(cr, cr) + rc2 * vv);
}

// Mirrors `Quad::end_squared`.
fn quad_end_squared(q: vec4<f32>, dt: f32) -> f32 {
    return max(q.x + dt * (2.0 * q.z + q.y * dt), 0.0);
}

// Mirrors `Quad::shifted`.
fn quad_shifted(q: vec4<f32>, off: f32) -> vec4<f32> {
    return vec4<f32>(quad_end_squared(q, off), q.y, q.z + q.y * off, q.w);
}

// Mirrors `Segment::from_quad`: ∫₀^dt of (|p + vτ|² + rc2)^{-1/2} or ^{-1} in closed form (002
// eq. 3.9, corrected single-log / atan2 forms of SPEC.md §1.2), in s-scaled quantities Y = s·y,
// E = s²e. dt > CURVE_INF is an open end.
fn segment_new(falloff: u32, q: vec4<f32>, dt: f32, rc2: f32) -> Segment {
    let vv = q.y;
    let pv = q.z;
    let big_e = q.w;
    var seg = Segment(0.0, falloff, dt, 0.0, 0.0, 0.0, false, rc2, 0.0);
    if (!(vv > 0.0)) {
        let e0 = q.x + rc2;
        seg.e = e0;
        if (dt > 0.0 && dt <= CURVE_INF) {
            if (falloff == FALLOFF_FAITHFUL) {
                seg.value = dt / sqrt(e0);
            } else {
                seg.value = dt / e0;
            }
        }
        return seg;
    }
    let inv_s = 1.0 / sqrt(vv);
    seg.e = big_e * inv_s * inv_s;
    seg.y0 = pv * inv_s;
    seg.y1 = seg.y0;
    if (!(dt > 0.0)) {
        return seg;
    }
    if (falloff == FALLOFF_FAITHFUL) {
        var dtf = dt;
        if (dt > CURVE_INF) {
            dtf = 0.0;
        }
        let span = vv * dtf;
        seg.span = span * inv_s;
        var a0 = pv;
        var a1 = pv + span;
        if (a0 + a1 < 0.0) {
            let tmp = a0;
            a0 = -a1;
            a1 = -tmp;
            seg.flipped = true;
        }
        let r0 = sqrt(a0 * a0 + big_e);
        let r1 = sqrt(a1 * a1 + big_e);
        let rs = r0 + r1;
        var x = span * (rs + a0 + a1) * (r0 - a0) / (rs * big_e);
        if (a0 >= 0.0) {
            x = span * (rs + a0 + a1) / (rs * (a0 + r0));
        }
        var delta = curve_ln_1p(x);
        if (x >= 0.0625) {
            delta = log(1.0 + x);
        }
        seg.value = delta * inv_s;
        seg.delta = delta;
        seg.y0 = a0 * inv_s;
        seg.y1 = a1 * inv_s;
    } else {
        let se = sqrt(big_e);
        if (dt <= CURVE_INF) {
            let span = vv * dt;
            seg.span = span * inv_s;
            let z = span * se;
            let k = big_e + pv * (pv + span);
            let th = atan2(z, k);
            if (k > 0.0 && z < 1.0e-4 * k) {
                let r = z / k;
                seg.value = span / k * (1.0 - r * r / 3.0);
            } else {
                seg.value = th / se;
            }
            seg.delta = th;
            seg.y1 = (pv + span) * inv_s;
        } else {
            let th = atan2(se, pv);
            seg.value = th / se;
            seg.delta = th;
            seg.y1 = T_OPEN;
        }
    }
    return seg;
}

// #if ATTENUATION
// Mirrors `Segment::fitted_variance`: the variance of the weight's quadratic interpolant.
fn segment_fitted_variance(seg: Segment, uniform: f32) -> f32 {
    let y0 = seg.y0;
    let e = seg.e;
    let span = seg.span;
    let ym = y0 + span * 0.5;
    let y1 = y0 + span;
    var w0 = 1.0 / (y0 * y0 + e);
    var wm = 1.0 / (ym * ym + e);
    var w1 = 1.0 / (y1 * y1 + e);
    if (seg.falloff == FALLOFF_FAITHFUL) {
        w0 = 1.0 / sqrt(y0 * y0 + e);
        wm = 1.0 / sqrt(ym * ym + e);
        w1 = 1.0 / sqrt(y1 * y1 + e);
    }
    let gamma = 2.0 * (w1 - 2.0 * wm + w0) / wm;
    let beta = (w1 - w0) / wm - gamma;
    let a = w0 / wm;
    let m0 = a + beta * 0.5 + gamma / 3.0;
    let m1 = a * 0.5 + beta / 3.0 + gamma * 0.25;
    let m2 = a / 3.0 + beta * 0.25 + gamma / 5.0;
    let c1 = m1 / m0;
    let c2 = m2 / m0;
    let v = clamp(c2 - c1 * c1, 0.0, 0.25) * seg.dt * seg.dt;
    if (curve_finite(v)) {
        return v;
    }
    return uniform;
}

// Mirrors `Segment::moments`: (centroid τ̄, variance σ²) of the weight over the piece.
fn segment_moments(seg: Segment) -> vec2<f32> {
    let y0 = seg.y0;
    let y1 = seg.y1;
    let e = seg.e;
    let dt = seg.dt;
    let span = seg.span;
    let mid = dt * 0.5;
    let uniform = dt * dt / 12.0;
    let q0 = y0 * y0 + e;
    let nu = span * (max(abs(y0), abs(y1)) + span);
    if (!(seg.value > 0.0) || !(nu > 1.0e-4 * q0)) {
        return vec2<f32>(mid, uniform);
    }
    var m0 = 0.0;
    var m1 = 0.0;
    var s2 = 0.0;
    if (seg.falloff == FALLOFF_FAITHFUL) {
        let r0 = sqrt(q0);
        let r1 = sqrt(y1 * y1 + e);
        m0 = seg.delta;
        m1 = span * (y0 + y1) / (r0 + r1);
        s2 = 0.5 * (y1 * r1 - y0 * r0) - 2.0 * y0 * m1 + (y0 * y0 - 0.5 * e) * m0;
    } else {
        m0 = seg.delta / sqrt(e);
        m1 = 0.5 * curve_ln_1p(span * (y0 + y1) / q0);
        s2 = span - 2.0 * y0 * m1 + (y0 * y0 - e) * m0;
    }
    let mu = m1 / m0 - y0;
    let scale = dt / span;
    var tbar = mu * scale;
    if (seg.flipped) {
        tbar = dt - tbar;
    }
    if (curve_finite(tbar)) {
        tbar = clamp(tbar, 0.0, dt);
    } else {
        tbar = mid;
    }
    if (!(nu > 0.1 * q0)) {
        return vec2<f32>(tbar, segment_fitted_variance(seg, uniform));
    }
    let v = clamp(s2 / m0 - mu * mu, 0.0, span * span * 0.25) * scale * scale;
    if (curve_finite(v)) {
        return vec2<f32>(tbar, v);
    }
    return vec2<f32>(tbar, uniform);
}

// Mirrors `Segment::attenuated`: second order about the weight's centroid.
fn segment_attenuated(seg: Segment, t_start: f32, t_far: f32, j: f32) -> f32 {
    if (!(seg.value > 0.0)) {
        return 0.0;
    }
    let mv = segment_moments(seg);
    let h = 1.0 - (t_start + mv.x) / t_far;
    if (!(h > 0.0)) {
        return 0.0;
    }
    let ht = h * t_far;
    let z = min(mv.y / (ht * ht), 1.0);
    let factor = max(1.0 + 0.5 * j * (j - 1.0) * z, 0.0);
    return seg.value * pow(h, j) * factor;
}

// #endif

// ---- integrate.rs: the default integrator ----

// Mirrors integrate.rs `Acc::piece_quad`: adds the piece d(τ) = p + vτ, τ ∈ [0, dt], from ray
// parameter ts; with j > 0 (curve_piece_attenuated) cut into parts whose 1 − u shrinks by att_q,
// down to att_floor.
fn curve_piece(c: GpuCurve, r: LocalRay, ts: f32, q: vec4<f32>, dt: f32, acc: ptr<function, f32>) {
// #if ATTENUATION
    if (r.j != 0.0) {
        curve_piece_attenuated(c, r, ts, q, dt, acc);
        return;
    }
// #endif
    *acc += segment_new(r.falloff, q, dt, r.rc2).value;
}

// #if ATTENUATION
// curve_piece where j > 0.
fn curve_piece_attenuated(c: GpuCurve, r: LocalRay, ts: f32, q: vec4<f32>, dt: f32, acc: ptr<function, f32>) {
    let te = ts + dt;
    var a = ts;
    for (var i = 0u; i < CURVE_MAX_PARTS; i++) {
        let ha = 1.0 - a / r.t_far;
        var b = te;
        if (!(ha <= c.att_floor) && i + 1u < CURVE_MAX_PARTS) {
            b = min(te, r.t_far * (1.0 - ha * c.att_q));
        }
        let seg = segment_new(r.falloff, quad_shifted(q, a - ts), b - a, r.rc2);
        *acc += segment_attenuated(seg, a, r.t_far, r.j);
        if (!(b < te)) {
            break;
        }
        a = b;
    }
}
// #endif

// Mirrors hadou_math::curve::MAX_ATTENUATION_PARTS (checked by shaders.rs `constants_match`).
const CURVE_MAX_PARTS: u32 = 64u;

// Mirrors integrate.rs `ChordModel::new(falloff)`: (first, saturation, partial, second).
fn chord_model(falloff: u32) -> vec4<f32> {
    if (falloff == FALLOFF_FAITHFUL) {
        return vec4<f32>(3.0 / 16.0, 1.0, 1.25, 1.0);
    }
    return vec4<f32>(0.75, 1.0, 2.5, 3.0);
}

// Mirrors `ChordModel::terms` then `ChordModel::refinement`: 0 to accept, else levels to descend.
fn chord_refinement(m: vec4<f32>, err: f32, q: vec4<f32>, dt: f32, rc2: f32, uncovered: f32, tol: f32, level: u32) -> u32 {
    var inv = q.y / q.w;
    if (q.z >= 0.0) {
        inv = 1.0 / (q.x + rc2);
    } else if (q.z + q.y * dt <= 0.0) {
        inv = 1.0 / (quad_end_squared(q, dt) + rc2);
    }
    let x2 = err * err * inv;
    let a = min(m.x * q.y * dt * dt * inv, m.y) + m.z * uncovered;
    let b = tol - m.w * x2;
    if (b >= 0.0 && x2 * a * a <= b * b) {
        return 0u;
    }
    var ratio = (sqrt(x2) * a + m.w * x2) / (tol * 8.0);
    var k = 1u;
    while (k < level && ratio > 8.0) {
        ratio = ratio / 8.0;
        k += 1u;
    }
    return k;
}

// PieceTable::nodes[i] as (x, y, z).
fn curve_node(c: GpuCurve, i: u32) -> vec3<f32> {
    return curve_vec4[c.nodes + i].xyz;
}

// PieceTable::level_offsets[l].
fn curve_level_offset(c: GpuCurve, l: u32) -> u32 {
    return bitcast<u32>(curve_f32[c.level_offsets + l]);
}

// Mirrors integrate.rs `leaf_of`.
fn curve_leaf_of(c: GpuCurve, x: f32) -> u32 {
    var lo = 0u;
    var hi = c.node_count - 2u;
    while (hi > lo) {
        let mid = (lo + hi + 1u) / 2u;
        if (curve_node(c, mid).x <= x) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    return lo;
}

// Mirrors the `t_of` closure of integrate.rs `walk`: the ray parameter at axial coordinate x.
fn curve_t_of(x: f32, lo: f32, hi: f32, t_lo: f32, t_hi: f32, inv_qx: f32) -> f32 {
    if (x == lo) {
        return t_lo;
    } else if (x == hi) {
        return t_hi;
    }
    return t_lo + (x - lo) * inv_qx;
}

// Mirrors integrate.rs `curve_at`: the exact cross-section point at axial coordinate x.
fn curve_at(c: GpuCurve, x: f32) -> vec2<f32> {
    return curve_eval(c, clamp(x / c.gamma, 0.0, c.s_head));
}

// Mirrors local_ray.rs `CurveReal::split` for f32: the lower 12 of 24 significand bits cleared,
// so that products of such values with each other or with a remainder x − split(x) are exact.
fn curve_split(x: f32) -> f32 {
    return bitcast<f32>(bitcast<u32>(x) & 0xfffff000u);
}

// Mirrors integrate.rs `two_sum`: (s, e) with s = a + b rounded and s + e = a + b exactly
// (additions only, so no fused multiply-add can change it).
fn curve_two_sum(a: f32, b: f32) -> vec2<f32> {
    let s = a + b;
    let bb = s - a;
    return vec2<f32>(s, (a - (s - bb)) + (b - bb));
}

// Mirrors integrate.rs `anchored`: o + q·t − l for an anchor t = curve_split(·), good to the
// rounding of the small result (q·t split into two exact products, the cancelling sums two-sums).
fn curve_anchored(o: f32, q: f32, l: f32, t: f32) -> f32 {
    let h = curve_two_sum(o, -l);
    let qh = curve_split(q);
    let s = curve_two_sum(h.x, qh * t);
    return s.x + (s.y + h.y + (q - qh) * t);
}

// Mirrors integrate.rs `line_quad`: the quadratic of the line (ly, lz) + (x − xm)·(my, mz) along
// the ray from ts on, over [0, dt]; p·p and p·v at ts, E = |p × v|² + rc2·vv from the relative
// position at the anchor nearest the ray (a cross product of small, locally formed numbers) where
// the ray passes within about 2.4e-3 of the coordinates' size, else from p at ts.
fn curve_line_quad(r: LocalRay, ly: f32, lz: f32, my: f32, mz: f32, xm: f32, ts: f32, dt: f32) -> vec4<f32> {
    let xs = r.o.x + r.q.x * ts - xm;
    let py = r.o.y + r.q.y * ts - (ly + xs * my);
    let pz = r.o.z + r.q.z * ts - (lz + xs * mz);
    let vy = r.q.y - r.q.x * my;
    let vz = r.q.z - r.q.x * mz;
    let vv = vy * vy + vz * vz;
    let pv = py * vy + pz * vz;
    var cr = py * vz - pz * vy;
    let ats = abs(ts);
    let size = abs(r.o.y) + abs(r.o.z) + (abs(r.q.y) + abs(r.q.z)) * ats + (abs(r.o.x) + abs(r.q.x) * ats) * (abs(my) + abs(mz));
    let bound = F32_EPSILON * 2e4 * size;
    if (!(cr * cr > bound * bound * vv)) {
        var tau = -pv / vv;
        if (!(tau > 0.0)) {
            tau = 0.0;
        }
        if (tau > dt) {
            tau = dt;
        }
        let ta = curve_split(ts + tau);
        let xa = curve_anchored(r.o.x, r.q.x, xm, ta);
        let ay = curve_anchored(r.o.y, r.q.y, ly, ta) - xa * my;
        let az = curve_anchored(r.o.z, r.q.z, lz, ta) - xa * mz;
        cr = ay * vz - az * vy;
    }
    return vec4<f32>(py * py + pz * pz, vv, pv, cr * cr + r.rc2 * vv);
}

// Mirrors hadou_math::curve::integrate::MAX_SUB_LEVELS.
const CURVE_SUB_LEVELS: u32 = 16u;

// Mirrors integrate.rs `leaf_walk`: the chord walk below leaf i over [x0, x1], bisecting on the
// exact curve; each sub-piece's line is its chord shifted by ⅔ of the midpoint deviation d, with
// the bound |d|. Right halves wait on a fixed stack (x_a, y_a, z_a, depth) + (x_b, y_b, z_b).
fn curve_leaf_walk(c: GpuCurve, r: LocalRay, i: u32, x0: f32, x1: f32, lo: f32, hi: f32, t_lo: f32, t_hi: f32, inv_qx: f32, model: vec4<f32>, acc: ptr<function, f32>) {
    var stack_a: array<vec4<f32>, CURVE_SUB_LEVELS>;
    var stack_b: array<vec3<f32>, CURVE_SUB_LEVELS>;
    var top = 0u;
    let na = curve_node(c, i);
    let nb = curve_node(c, i + 1u);
    var xa = na.x;
    var pa = na.yz;
    var xb = nb.x;
    var pb = nb.yz;
    var depth = 0u;
    let noise = F32_EPSILON * 0.5;
    // Each sub-piece is visited once: at most 2^(levels+1) − 1; the bound only guards the loop.
    for (var step = 0u; step < 4096u; step++) {
        if (xb > x0 && xa < x1) {
            let w = xb - xa;
            let xm = (xa + xb) * 0.5;
            let cm = curve_at(c, xm);
            let mid = (pa + pb) * 0.5;
            let d = cm - mid;
            let err = sqrt(d.x * d.x + d.y * d.y);
            let ly = mid.x + d.x * (2.0 / 3.0);
            let lz = mid.y + d.y * (2.0 / 3.0);
            let my = (pb.x - pa.x) / w;
            let mz = (pb.y - pa.y) / w;
            let px0 = max(x0, xa);
            let px1 = min(x1, xb);
            let tx0 = curve_t_of(px0, lo, hi, t_lo, t_hi, inv_qx);
            let tx1 = curve_t_of(px1, lo, hi, t_lo, t_hi, inv_qx);
            let ts = select(tx1, tx0, tx0 <= tx1);
            let te = select(tx0, tx1, tx0 <= tx1);
            let dt = te - ts;
            let quad = curve_line_quad(r, ly, lz, my, mz, xm, ts, dt);
            var uncovered = 0.0;
            if (px0 > xa || px1 < xb) {
                uncovered = 1.0 - (px1 - px0) / w;
            }
            var split = depth < CURVE_SUB_LEVELS && xm > xa && xm < xb && err > noise * (abs(cm.x) + abs(cm.y) + abs(xm));
            if (split) {
                split = chord_refinement(model, err, quad, dt, r.rc2, uncovered, c.tolerance, 1u) > 0u;
            }
            if (split) {
                depth += 1u;
                stack_a[top] = vec4<f32>(xm, cm.x, cm.y, f32(depth));
                stack_b[top] = vec3<f32>(xb, pb.x, pb.y);
                top += 1u;
                xb = xm;
                pb = cm;
                continue;
            }
            curve_piece(c, r, ts, quad, dt, acc);
        }
        if (top == 0u) {
            return;
        }
        top -= 1u;
        let sa = stack_a[top];
        let sb = stack_b[top];
        xa = sa.x;
        pa = sa.yz;
        depth = u32(sa.w);
        xb = sb.x;
        pb = sb.yz;
    }
}

// Mirrors integrate.rs `walk`: the stackless chord walk over the slab part [ta, tb].
fn curve_walk(c: GpuCurve, r: LocalRay, ta: f32, tb: f32, acc: ptr<function, f32>) {
    let n = c.node_count - 1u;
    let levels = c.levels;
    let xh = r.x_head;
    let xa = clamp(r.o.x + r.q.x * ta, 0.0, xh);
    let xb = clamp(r.o.x + r.q.x * tb, 0.0, xh);
    var lo = xa;
    var hi = xb;
    var t_lo = ta;
    var t_hi = tb;
    if (!(xa <= xb)) {
        lo = xb;
        hi = xa;
        t_lo = tb;
        t_hi = ta;
    }
    if (!(hi - lo > xh * (F32_EPSILON * 8.0)) || tb - ta > CURVE_INF) {
        let cm = curve_at(c, (lo + hi) * 0.5);
        let py = r.o.y + r.q.y * ta;
        let pz = r.o.z + r.q.z * ta;
        let p = vec3<f32>(0.0, py - cm.x, pz - cm.y);
        curve_piece(c, r, ta, quad_new(p, vec3<f32>(0.0, r.q.y, r.q.z), r.rc2), tb - ta, acc);
        return;
    }
    let model = chord_model(r.falloff);
    let inv_qx = 1.0 / r.q.x;
    var l = levels - 1u;
    var j = 0u;
    let max_steps = 4u * (curve_level_offset(c, levels) + levels);
    for (var step = 0u; step < max_steps; step++) {
        let ia = j << l;
        let ib = min((j + 1u) << l, n);
        let na = curve_node(c, ia);
        let nb = curve_node(c, ib);
        if (na.x >= hi) {
            break;
        }
        var descend = 0u;
        if (nb.x > lo) {
            let x0 = max(lo, na.x);
            let x1 = min(hi, nb.x);
            let tx0 = curve_t_of(x0, lo, hi, t_lo, t_hi, inv_qx);
            let tx1 = curve_t_of(x1, lo, hi, t_lo, t_hi, inv_qx);
            let ts = select(tx1, tx0, tx0 <= tx1);
            let te = select(tx0, tx1, tx0 <= tx1);
            let idx = curve_level_offset(c, l) + j;
            let ln = curve_vec4[c.lines + idx];
            let dt = te - ts;
            let quad = curve_line_quad(r, ln.x, ln.y, ln.z, ln.w, (na.x + nb.x) * 0.5, ts, dt);
            let err = curve_f32[c.errors + idx];
            var uncovered = 0.0;
            if (x0 > na.x || x1 < nb.x) {
                uncovered = 1.0 - (x1 - x0) / (nb.x - na.x);
            }
            let refine = chord_refinement(model, err, quad, dt, r.rc2, uncovered, c.tolerance, l);
            if (refine == 0u) {
                curve_piece(c, r, ts, quad, dt, acc);
            } else if (l == 0u) {
                curve_leaf_walk(c, r, j, x0, x1, lo, hi, t_lo, t_hi, inv_qx, model, acc);
            } else {
                descend = refine;
            }
        }
        if (descend > 0u) {
            l -= descend;
            j = j << descend;
            continue;
        }
        loop {
            if (l + 1u >= levels) {
                return;
            }
            if ((j & 1u) == 0u && ((j + 1u) << l) < n) {
                j += 1u;
                break;
            }
            j >>= 1u;
            l += 1u;
        }
    }
}

// The end point c(0) (head = false) or c(k·s_end) (head = true) in local coordinates.
fn curve_end_point(c: GpuCurve, r: LocalRay, head: bool) -> vec3<f32> {
    if (head) {
        let nd = curve_node(c, c.node_count - 1u);
        return vec3<f32>(r.x_head, nd.y, nd.z);
    }
    let nd = curve_node(c, 0u);
    return vec3<f32>(0.0, nd.y, nd.z);
}

// The exact sphere piece against an end point over [a, b] (`sphere` in integrate_span).
fn curve_end_piece(c: GpuCurve, r: LocalRay, head: bool, a: f32, b: f32, acc: ptr<function, f32>) {
    if (b > a) {
        curve_piece(c, r, a, quad_new(r.o + r.q * a - curve_end_point(c, r, head), r.q, r.rc2), b - a, acc);
    }
}

// Mirrors integrate.rs `integrate_span`: the tail's end piece, the walk over the slab, the head's
// end piece, in ray order. Written as one pass over the three parts with one call of each (the
// parts a ray parallel to the slab (q.x = 0) does not meet are empty), because a software adapter
// inlines every call site: each extra call of the walk would be compiled again.
fn curve_integrate_span(c: GpuCurve, r: LocalRay, ta: f32, tb: f32, acc: ptr<function, f32>) {
    let qx = r.q.x;
    // The three parts' ranges: [ta, first_end) beside the first end point, [a, b) in the slab,
    // [second_start, tb) beside the second end point.
    var head_first = false;
    var first_end = ta;
    var a = ta;
    var b = ta;
    var second_start = tb;
    var walk = false;
    if (qx == 0.0) {
        if (r.o.x < 0.0) {
            first_end = tb;
        } else if (r.o.x > r.x_head) {
            head_first = true;
            first_end = tb;
        } else {
            // As integrate.rs: the walk runs even on an empty range here.
            b = tb;
            walk = true;
        }
    } else {
        let t_a = -r.o.x / qx;
        let t_b = (r.x_head - r.o.x) / qx;
        var tin = t_a;
        var tout = t_b;
        if (!(qx > 0.0)) {
            tin = t_b;
            tout = t_a;
            head_first = true;
        }
        first_end = min(tb, tin);
        a = max(ta, tin);
        b = min(tb, tout);
        second_start = max(ta, tout);
        walk = b > a;
    }
    for (var part = 0u; part < 3u; part++) {
        if (part == 1u) {
            if (walk) {
                curve_walk(c, r, a, b, acc);
            }
            continue;
        }
        var head = head_first;
        var lo = ta;
        var hi = first_end;
        if (part == 2u) {
            head = !head_first;
            lo = second_start;
            hi = tb;
        }
        curve_end_piece(c, r, head, lo, hi, acc);
    }
}

// Mirrors integrate.rs `default_energy` (f32) at DEFAULT_SETTINGS: `LocalRay::new`, then
// `default_generic`.
fn curve_default(c: GpuCurve, falloff: u32, core_radius: f32, ray: Ray, t0: f32, t1: f32, t_far: f32) -> f32 {
    var ok = false;
    let r = curve_local_ray(c, falloff, core_radius, ray, t0, t1, t_far, &ok);
    if (!ok) {
        return 0.0;
    }
    var acc = 0.0;
    curve_integrate_span(c, r, r.t0, r.t1, &acc);
    return energy_scaled(acc, r.alpha);
}

// ---- simpson.rs ----

// Mirrors simpson.rs `density`: w(|P(t) − C(t)|)·(1 − t/t_far)^j (002 eq. 3.17, 3.23, 3.24).
fn curve_density(c: GpuCurve, r: LocalRay, t: f32) -> f32 {
    let p = r.o + r.q * t;
    let xc = clamp(p.x, 0.0, r.x_head);
    let s = min(xc / c.gamma, c.s_head);
    let cs = curve_eval(c, s);
    let dx = p.x - xc;
    let dy = p.y - cs.x;
    let dz = p.z - cs.y;
    let q = dx * dx + dy * dy + dz * dz + r.rc2;
    var w = 1.0 / q;
    if (r.falloff == FALLOFF_FAITHFUL) {
        w = 1.0 / sqrt(q);
    }
    return w * curve_attenuation(r, t);
}

// Mirrors simpson.rs `composite`: composite Simpson with m (even) subintervals over [a, b]. The
// end points are evaluated in the loop (one call site of the density: a software adapter inlines
// every call), and summed as simpson.rs sums them.
fn curve_composite(c: GpuCurve, r: LocalRay, a: f32, b: f32, m: u32) -> f32 {
    if (!(b > a)) {
        return 0.0;
    }
    let h = (b - a) / f32(m);
    var odd = 0.0;
    var even = 0.0;
    var fa = 0.0;
    var fb = 0.0;
    for (var i = 0u; i <= m; i++) {
        var t = a + h * f32(i);
        if (i == 0u) {
            t = a;
        } else if (i == m) {
            t = b;
        }
        let v = curve_density(c, r, t);
        if (i == 0u) {
            fa = v;
        } else if (i == m) {
            fb = v;
        } else if ((i & 1u) == 1u) {
            odd += v;
        } else {
            even += v;
        }
    }
    return (fa + 4.0 * odd + 2.0 * even + fb) * h / 3.0;
}

// What curve_simpson leaves to the default integrator: the tail [t0, t1] past the far point
// (none when t1 ≤ t0), after the Simpson part's energy.
struct SimpsonPart {
    energy: f32,
    tail_t0: f32,
    tail_t1: f32,
}

// Mirrors the Simpson arm of dispatch.rs `curve_energy_generic` (f32): simpson.rs `simpson_generic`
// (m subintervals, m/n outside the bounding cylinder of radius R + ε, 002 §3.4.4, eq. 3.22); the
// default integrator for any tail past the far point is curve_energy's (one call site for both
// integrators). The one, two or three composite rules run from one call site too: a software
// adapter inlines every call.
fn curve_simpson(c: GpuCurve, falloff: u32, core_radius: f32, ray: Ray, t0: f32, t1: f32, t_far: f32) -> SimpsonPart {
    var out = SimpsonPart(0.0, 0.0, 0.0);
    var ok = false;
    let r = curve_local_ray(c, falloff, core_radius, ray, t0, t1, t_far, &ok);
    if (!ok) {
        return out;
    }
    let m = c.m;
    let te = min(r.t1, r.t_far);
    // The spans [bounds[k], bounds[k + 1]] with ms[k] subintervals, k < spans.
    var bounds = array<f32, 4>(r.t0, te, te, te);
    var ms = array<u32, 3>(m, m, m);
    var spans = 1u;
    if (c.reduce != 0u) {
        let mo = c.m_reduced;
        let rad = c.cylinder_radius;
        let a = r.q.y * r.q.y + r.q.z * r.q.z;
        let b = r.o.y * r.q.y + r.o.z * r.q.z;
        let k = r.o.y * r.o.y + r.o.z * r.o.z - rad * rad;
        let disc = b * b - a * k;
        if (a > 0.0 && disc > 0.0) {
            let sq = sqrt(disc);
            bounds[1] = clamp((-b - sq) / a, r.t0, te);
            bounds[2] = clamp((-b + sq) / a, r.t0, te);
            ms = array<u32, 3>(mo, m, mo);
            spans = 3u;
        } else {
            ms[0] = mo;
        }
    }
    var sum = 0.0;
    for (var k = 0u; k < spans; k++) {
        sum += curve_composite(c, r, bounds[k], bounds[k + 1u], ms[k]);
    }
    out.energy = energy_scaled(sum, r.alpha);
    if (r.t1 > r.t_far) {
        out.tail_t0 = r.t_far;
        out.tail_t1 = r.t1;
    }
    return out;
}

// ---- nearest.rs ----

// Mirrors nearest.rs NEAREST_STEP, MAX_NEAREST_STEPS, MAX_NEAREST_VISITS, NEAREST_PRUNE,
// TAIL_RADII; keep in sync.
const NEAREST_STEP: f32 = 0.25;
const MAX_NEAREST_STEPS: u32 = 180u;
const MAX_NEAREST_VISITS: u32 = 2048u;
const NEAREST_PRUNE: f32 = 1e-4;
const TAIL_RADII: f32 = 64.0;
const NEAREST_STACK: u32 = 32u;
// Mirrors nearest.rs REFINE_STEPS.
const REFINE_STEPS: u32 = 1u;

// Mirrors nearest.rs `segment`: (squared distance from p to the segment a..b, parameter of the
// nearest point).
fn curve_segment(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>) -> vec2<f32> {
    let d = b - a;
    let dd = dot3(d, d);
    var f = 0.0;
    if (dd > 0.0) {
        f = clamp(dot3(p - a, d) / dd, 0.0, 1.0);
    }
    let e = p - (a + d * f);
    return vec2<f32>(dot3(e, e), f);
}

// The exact curve point c(s) in local coordinates (the `point` closure of nearest.rs
// `nearest_point`).
fn curve_nearest_foot(c: GpuCurve, s: f32) -> vec3<f32> {
    let cs = curve_eval(c, s);
    return vec3<f32>(c.gamma * s, cs.x, cs.y);
}

// Mirrors nearest.rs `Nearest`: the nearest exact curve point found for one query.
struct NearestHit {
    d2: f32,
    s: f32,
    foot: vec3<f32>,
}

// Mirrors nearest.rs `nearest_point`: branch and bound over the piece table from the hint (the
// previous query's exact point, `s` and `c(s)`), the winning leaf refined by one parabolic step
// on the exact curve.
fn curve_nearest_point(c: GpuCurve, p: vec3<f32>, hint: NearestHit) -> NearestHit {
    let n = c.node_count - 1u;
    let e0 = p - hint.foot;
    var out = NearestHit(dot3(e0, e0), hint.s, hint.foot);
    var best2 = out.d2;
    var best = sqrt(best2);
    let keep = 1.0 - NEAREST_PRUNE;
    var found = false;
    var leaf = 0u;
    var leaf_f = 0.0;
    // Entries: level << 24 | piece index.
    var stack: array<u32, NEAREST_STACK>;
    stack[0] = (c.levels - 1u) << 24u;
    var top = 1u;
    var visits = 0u;
    while (top > 0u && visits < MAX_NEAREST_VISITS) {
        top -= 1u;
        let l = stack[top] >> 24u;
        let j = stack[top] & 0xffffffu;
        visits += 1u;
        let a = j << l;
        let b = min((j + 1u) << l, n);
        let na = curve_node(c, a);
        let nb = curve_node(c, b);
        if (l == 0u) {
            let sd = curve_segment(p, na, nb);
            if (sd.x < best2) {
                best2 = sd.x;
                best = sqrt(best2);
                found = true;
                leaf = a;
                leaf_f = sd.y;
            }
            continue;
        }
        let k = curve_level_offset(c, l) + j;
        let ln = curve_vec4[c.lines + k];
        let delta = curve_f32[c.errors + k];
        let xm = 0.5 * (na.x + nb.x);
        let ea = vec3<f32>(na.x, ln.x + (na.x - xm) * ln.z, ln.y + (na.x - xm) * ln.w);
        let eb = vec3<f32>(nb.x, ln.x + (nb.x - xm) * ln.z, ln.y + (nb.x - xm) * ln.w);
        let sd = curve_segment(p, ea, eb);
        let reach = best * keep + delta;
        if (!(sd.x < reach * reach)) {
            continue;
        }
        let left = ((l - 1u) << 24u) | (2u * j);
        let right_start = (2u * j + 1u) << (l - 1u);
        if (right_start >= n) {
            stack[top] = left;
            top += 1u;
            continue;
        }
        let right = left + 1u;
        var first = right;
        var second = left;
        if (p.x < curve_node(c, right_start).x) {
            first = left;
            second = right;
        }
        if (top + 2u <= NEAREST_STACK) {
            stack[top] = second;
            stack[top + 1u] = first;
            top += 2u;
        }
    }
    if (found) {
        let sa = curve_vec4[c.nodes + leaf].w;
        let sb = curve_vec4[c.nodes + leaf + 1u].w;
        let w = sb - sa;
        let lo = max(sa - w * 0.5, 0.0);
        let hi = min(sb + w * 0.5, c.s_head);
        var s0 = sa + w * leaf_f;
        var h = w * 0.25;
        for (var it = 0u; it < REFINE_STEPS; it++) {
            let x1 = max(s0 - h, lo);
            let x3 = min(s0 + h, hi);
            let c1 = curve_nearest_foot(c, x1);
            let c2 = curve_nearest_foot(c, s0);
            let c3 = curve_nearest_foot(c, x3);
            let g1 = dot3(p - c1, p - c1);
            let g2 = dot3(p - c2, p - c2);
            let g3 = dot3(p - c3, p - c3);
            if (g1 < out.d2) {
                out = NearestHit(g1, x1, c1);
            }
            if (g2 < out.d2) {
                out = NearestHit(g2, s0, c2);
            }
            if (g3 < out.d2) {
                out = NearestHit(g3, x3, c3);
            }
            if (!(x1 < s0 && s0 < x3)) {
                break;
            }
            // Mirrors nearest.rs `parabola_vertex`.
            let pa = s0 - x1;
            let pb = s0 - x3;
            let num = pa * pa * (g2 - g3) - pb * pb * (g2 - g1);
            let den = pa * (g2 - g3) - pb * (g2 - g1);
            let chord = g1 + (g3 - g1) * (s0 - x1) / (x3 - x1);
            if (!(den < 0.0) && !(den > 0.0)) {
                break;
            }
            let v = s0 - 0.5 * num / den;
            if (!(curve_finite(v) && g2 <= chord)) {
                break;
            }
            let vc = clamp(v, lo, hi);
            h = min(max(abs(vc - s0) * 2.0, w * (1.0 / 64.0)), h);
            s0 = vc;
        }
        let cv = curve_nearest_foot(c, s0);
        let gv = dot3(p - cv, p - cv);
        if (gv < out.d2) {
            out = NearestHit(gv, s0, cv);
        }
    }
    return out;
}

// Mirrors nearest.rs `weight`: w(D) without the attenuation.
fn curve_nearest_weight(falloff: u32, d2: f32, rc2: f32) -> f32 {
    let q = d2 + rc2;
    if (falloff == FALLOFF_FAITHFUL) {
        return 1.0 / sqrt(q);
    }
    return 1.0 / q;
}

// Mirrors dispatch.rs with Integrator::Nearest: `LocalRay::new`, then nearest.rs
// `nearest_generic` (the walk whose steps follow the distance, Simpson on each interval, the
// closed tail of an open span).
fn curve_nearest(c: GpuCurve, falloff: u32, core_radius: f32, ray: Ray, t0: f32, t1: f32, t_far: f32) -> f32 {
    var ok = false;
    let r = curve_local_ray(c, falloff, core_radius, ray, t0, t1, t_far, &ok);
    if (!ok) {
        return 0.0;
    }
    let qn = sqrt(dot3(r.q, r.q));
    if (!(qn > 0.0) || !curve_finite(qn)) {
        return 0.0;
    }
    var end = r.t1;
    let open = !(r.t1 < T_OPEN);
    if (open) {
        let centre = vec3<f32>(0.5 * r.x_head, 0.0, 0.0);
        let rb = c.tail_radius;
        let big = TAIL_RADII * rb;
        let tc = dot3(centre - r.o, r.q) / (qn * qn);
        let e = r.o + r.q * tc - centre;
        let reach = sqrt(max(big * big - dot3(e, e), 0.0)) / qn;
        end = max(r.t0, tc + reach);
    }
    // Simpson's rule on steps [a, b] with midpoint m, the nearest point found at a, m, b in turn
    // from the one before (the hint). Each point is evaluated by the one call below (phase 0: the
    // start; 1: a step's midpoint; 2: its end), because a software adapter inlines every call.
    var a = r.t0;
    var b = a;
    var na = NearestHit(0.0, 0.0, curve_nearest_foot(c, 0.0));
    var fa = 0.0;
    var fm = 0.0;
    var sum = 0.0;
    let floor = 1e-3 * r.t_far;
    var steps = 0u;
    var phase = 0u;
    var x = a;
    var hint = na;
    loop {
        let n = curve_nearest_point(c, r.o + r.q * x, hint);
        let f = curve_nearest_weight(r.falloff, n.d2, r.rc2) * curve_attenuation(r, x);
        if (phase == 1u) {
            fm = f;
            phase = 2u;
            x = b;
            hint = n;
            continue;
        }
        if (phase == 2u) {
            sum += (b - a) / 6.0 * (fa + 4.0 * fm + f);
            a = b;
        }
        na = n;
        fa = f;
        if (!(a < end)) {
            break;
        }
        steps += 1u;
        let d = sqrt(na.d2 + r.rc2);
        var h = NEAREST_STEP * d / qn;
// #if ATTENUATION
        if (r.j > 0.0) {
            h = min(h, max(NEAREST_STEP * (r.t_far - a), floor));
        }
// #endif
        b = a + h;
        if (steps >= MAX_NEAREST_STEPS || !(a + h < end)) {
            b = end;
        }
        phase = 1u;
        x = 0.5 * (a + b);
        hint = na;
    }
    if (open) {
        let quad = quad_new(r.o + r.q * end - na.foot, r.q, r.rc2);
        sum += segment_new(r.falloff, quad, T_OPEN, r.rc2).value;
    }
    return energy_scaled(sum, r.alpha);
}

// Mirrors hadou_math::curve::curve_energy: dispatch on the wave's integrator. The default
// integrator, which the Simpson rule also calls for the tail past the far point, has one call
// site (a software adapter inlines every call).
fn curve_energy(c: GpuCurve, falloff: u32, core_radius: f32, ray: Ray, t0: f32, t1: f32, t_far: f32) -> f32 {
    // Each integrator is compiled in only when the frame's curves use it.
    if (c.integrator == INTEGRATOR_NEAREST) {
        if (USE_NEAREST) {
            return curve_nearest(c, falloff, core_radius, ray, t0, t1, t_far);
        }
        return 0.0;
    }
    var simpson = false;
    var head = 0.0;
    var ta = t0;
    var tb = t1;
    var tf = t_far;
    if (c.integrator == INTEGRATOR_SIMPSON) {
        if (!USE_SIMPSON) {
            return 0.0;
        }
        let part = curve_simpson(c, falloff, core_radius, ray, t0, t1, t_far);
        if (!(part.tail_t1 > part.tail_t0)) {
            return part.energy;
        }
        simpson = true;
        head = part.energy;
        ta = part.tail_t0;
        tb = part.tail_t1;
        tf = part.tail_t0;
    } else if (!USE_CHORD) {
        return 0.0;
    }
    let e = curve_default(c, falloff, core_radius, ray, ta, tb, tf);
    if (simpson) {
        return energy_add(head, e);
    }
    return e;
}
