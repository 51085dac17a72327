// WGSL twins of hadou_math::curve (002 §3.4, SPEC.md §1.4): shape evaluation (shape.rs), the
// closed-form pieces (closed.rs), the default integrator's chord walk over the PieceTable
// (integrate.rs) and the faithful Simpson integrator (simpson.rs). Prepended by common.wgsl and
// energy.wgsl. The data layout (GpuCurve, curve_vec4, curve_f32) is built by
// hadou_gpu::layout::CurveBuffers; keep in sync with layout.rs.

// Storage buffers of the curve data. Every module that includes this file declares them at
// these bindings; keep in sync with CurveBuffers in layout.rs.
@group(0) @binding(5) var<storage, read> curves: array<GpuCurve>;
// PieceTable::nodes then PieceTable::lines of every curve, one vec4 each.
@group(0) @binding(6) var<storage, read> curve_vec4: array<vec4<f32>>;
// Control points (y, z pairs), trig terms, knots, PieceTable::errors and the level offsets
// (u32 bits) of every curve.
@group(0) @binding(7) var<storage, read> curve_f32: array<f32>;

// `dt` above this is an open (infinite) span: the GPU's stand-in for f32::INFINITY is T_OPEN.
const CURVE_INF: f32 = 1.0e38;
const F32_MAX: f32 = 3.4028235e38;

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

// Mirrors closed.rs `ln1p_over`: ln(1 + x)/x, 1 at x = 0.
fn curve_ln1p_over(x: f32) -> f32 {
    if (abs(x) < 1.0e-3) {
        return 1.0 - x * (0.5 - x / 3.0);
    }
    return curve_ln_1p(x) / x;
}

// Mirrors closed.rs `sinh` (x ≥ 0).
fn curve_sinh(x: f32) -> f32 {
    if (x < 0.1) {
        let x2 = x * x;
        return x * (1.0 + x2 / 6.0 * (1.0 + x2 / 20.0));
    }
    return (exp(x) - exp(-x)) * 0.5;
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
    switch c.shape {
        case SHAPE_HELIX: {
            let a = c.rate * s + c.phase;
            return vec2<f32>(c.radius * sin(a), c.radius * cos(a));
        }
        case SHAPE_TRIG: {
            let zs = c.points + 2u * c.y_terms;
            return vec2<f32>(curve_trig_sum(c.rate, s, c.points, c.y_terms), curve_trig_sum(c.rate, s, zs, c.z_terms));
        }
        case SHAPE_BEZIER: {
            return curve_bezier(c, s);
        }
        default: {
            let tau = c.lo + clamp(s, 0.0, 1.0) * (c.hi - c.lo);
            return curve_bspline(c, tau);
        }
    }
}

// ---- integrate.rs: LocalRay ----

// Mirrors integrate.rs `LocalRay`.
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
    let o = vec3<f32>(dot(w, c.axis_d), dot(w, c.axis_y), dot(w, c.axis_z));
    let q = vec3<f32>(dot(ray.dir, c.axis_d), dot(ray.dir, c.axis_y), dot(ray.dir, c.axis_z));
    return LocalRay(o, q, t0, t1, t_far, j, rc * rc, falloff, c.alpha, c.x_head);
}

// Mirrors `LocalRay::attenuation`: (1 − t/t_far)^j (002 eq. 3.23), 0 beyond the far point.
fn curve_attenuation(r: LocalRay, t: f32) -> f32 {
    if (r.j == 0.0) {
        return 1.0;
    }
    let u = 1.0 - t / r.t_far;
    if (u <= 0.0) {
        return 0.0;
    }
    return pow(u, r.j);
}

// ---- closed.rs: Segment ----

// Mirrors closed.rs `Segment`.
struct Segment {
    value: f32,
    falloff: u32,
    dt: f32,
    y0: f32,
    y1: f32,
    flipped: bool,
    e: f32,
    delta: f32,
}

// Mirrors `Segment::new`: ∫₀^dt of (|p + vτ|² + rc2)^{-1/2} or ^{-1} in closed form (002 eq.
// 3.9, corrected single-log / atan2 forms of SPEC.md §1.2). dt > CURVE_INF is an open end.
fn segment_new(falloff: u32, p: vec3<f32>, v: vec3<f32>, dt: f32, rc2: f32) -> Segment {
    let s = length(v);
    var y0 = 0.0;
    var e = dot(p, p) + rc2;
    if (s > 0.0) {
        let vh = v / s;
        let cr = cross(p, vh);
        y0 = dot(p, vh);
        e = dot(cr, cr) + rc2;
    }
    var seg = Segment(0.0, falloff, dt, y0, y0, false, e, 0.0);
    if (!(dt > 0.0)) {
        return seg;
    }
    if (falloff == FALLOFF_FAITHFUL) {
        var dtf = dt;
        if (dt > CURVE_INF) {
            dtf = 0.0;
        }
        var a0 = y0;
        var a1 = y0 + s * dtf;
        if (a0 + a1 < 0.0) {
            let tmp = a0;
            a0 = -a1;
            a1 = -tmp;
            seg.flipped = true;
        }
        let q0 = sqrt(a0 * a0 + e);
        let q1 = sqrt(a1 * a1 + e);
        var g0 = e / (q0 - a0);
        if (a0 >= 0.0) {
            g0 = a0 + q0;
        }
        let f = 1.0 + (a0 + a1) / (q0 + q1);
        let a = dtf * f / g0;
        let x = s * a;
        seg.value = a * curve_ln1p_over(x);
        seg.delta = curve_ln_1p(x);
        seg.y0 = a0;
        seg.y1 = a1;
    } else {
        let se = sqrt(e);
        if (dt <= CURVE_INF) {
            let y1 = y0 + s * dt;
            let z = s * dt * se;
            let k = e + y0 * y1;
            let th = atan2(z, k);
            if (k > 0.0 && z < 1.0e-4 * k) {
                let r = z / k;
                seg.value = dt / k * (1.0 - r * r / 3.0);
            } else {
                seg.value = th / (s * se);
            }
            seg.delta = th;
            seg.y1 = y1;
        } else if (s > 0.0) {
            let th = atan2(se, y0);
            seg.value = th / (s * se);
            seg.delta = th;
            seg.y1 = T_OPEN;
        }
    }
    return seg;
}

// Mirrors `Segment::fraction_at`.
fn segment_fraction_at(seg: Segment, mu: f32) -> f32 {
    let y0 = seg.y0;
    let e = seg.e;
    let span = seg.y1 - y0;
    if (!(span > F32_EPSILON * (abs(y0) + sqrt(e)))) {
        return mu;
    }
    var lambda = 1.0;
    if (seg.falloff == FALLOFF_FAITHFUL) {
        var m = mu;
        if (seg.flipped) {
            m = 1.0 - mu;
        }
        let phi = m * seg.delta;
        let q0 = sqrt(y0 * y0 + e);
        let sh = curve_sinh(phi);
        var num = 0.0;
        if (y0 >= 0.0) {
            let h = curve_sinh(phi * 0.5);
            num = y0 * 2.0 * h * h + q0 * sh;
        } else {
            let g0 = e / (q0 - y0);
            var ome = 1.0 - exp(-phi);
            if (phi < 1.0e-3) {
                ome = phi * (1.0 - phi * 0.5);
            }
            num = -y0 * ome + g0 * sh;
        }
        let l = num / span;
        lambda = l;
        if (seg.flipped) {
            lambda = 1.0 - l;
        }
    } else {
        let phi = mu * seg.delta;
        let sp = sin(phi);
        let cp = cos(phi);
        let den = sqrt(e) * cp - y0 * sp;
        if (den > 0.0) {
            lambda = (y0 * y0 + e) * sp / (den * span);
        }
    }
    if (curve_finite(lambda)) {
        return clamp(lambda, 0.0, 1.0);
    }
    return mu;
}

// Mirrors `Segment::centroid`.
fn segment_centroid(seg: Segment) -> f32 {
    let y0 = seg.y0;
    let y1 = seg.y1;
    let e = seg.e;
    let dt = seg.dt;
    let span = y1 - y0;
    let q0 = y0 * y0 + e;
    if (!(seg.value > 0.0) || !(span * (max(abs(y0), abs(y1)) + span) > 1.0e-4 * q0)) {
        return dt * 0.5;
    }
    var n1 = 0.0;
    if (seg.falloff == FALLOFF_FAITHFUL) {
        let q1 = y1 * y1 + e;
        n1 = dt * (y0 + y1) / (sqrt(q0) + sqrt(q1));
    } else {
        let x = span * (y0 + y1) / q0;
        n1 = dt * (y0 + y1) / (2.0 * q0) * curve_ln1p_over(x);
    }
    let s = span / dt;
    var tbar = (n1 / seg.value - y0) / s;
    if (seg.flipped) {
        tbar = dt - tbar;
    }
    if (curve_finite(tbar)) {
        return clamp(tbar, 0.0, dt);
    }
    return dt * 0.5;
}

// Mirrors closed.rs `gauss_legendre`: node k of the n-point rule on [0, 1] as (x, w).
fn gauss_legendre(n: u32, k: u32) -> vec2<f32> {
    if (n <= 1u) {
        return vec2<f32>(0.5, 1.0);
    }
    if (n == 2u) {
        return select(vec2<f32>(0.21132487, 0.5), vec2<f32>(0.7886751, 0.5), k == 1u);
    }
    if (k == 0u) {
        return vec2<f32>(0.11270167, 5.0 / 18.0);
    }
    if (k == 1u) {
        return vec2<f32>(0.5, 8.0 / 18.0);
    }
    return vec2<f32>(0.8872983, 5.0 / 18.0);
}

// Mirrors `Segment::attenuated`, with g = `LocalRay::attenuation`.
fn segment_attenuated(seg: Segment, r: LocalRay, t_start: f32, nodes: u32, ga: f32, gb: f32) -> f32 {
    if (!(seg.value > 0.0)) {
        return 0.0;
    }
    let tbar = segment_centroid(seg);
    var lam0 = 0.5;
    if (seg.dt > 0.0) {
        lam0 = tbar / seg.dt;
    }
    var acc = ga + (gb - ga) * lam0;
    for (var k = 0u; k < nodes; k++) {
        let xw = gauss_legendre(nodes, k);
        let lam = segment_fraction_at(seg, xw.x);
        acc += xw.y * (curve_attenuation(r, t_start + lam * seg.dt) - (ga + (gb - ga) * lam));
    }
    return acc * seg.value;
}

// ---- integrate.rs: the default integrator ----

// Mirrors integrate.rs `Acc::piece`: adds the piece d(τ) = p + vτ, τ ∈ [0, dt], from ray
// parameter ts, split on the attenuation grid when j > 0.
fn curve_piece(c: GpuCurve, r: LocalRay, ts: f32, p: vec3<f32>, v: vec3<f32>, dt: f32, acc: ptr<function, f32>) {
    if (r.j == 0.0) {
        *acc += segment_new(r.falloff, p, v, dt, r.rc2).value;
        return;
    }
    let te = ts + dt;
    let step = c.att_grid * r.t_far;
    var k = floor(ts / step) + 1.0;
    var a = ts;
    for (var i = 0u; i < 70u; i++) {
        let line = k * step;
        var b = te;
        if (line < te && i < 69u) {
            b = line;
        }
        let sub = b - a;
        if (sub > 0.0) {
            let seg = segment_new(r.falloff, p + v * (a - ts), v, sub, r.rc2);
            let du = sub / r.t_far;
            let nu = r.j * du / max(1.0 - b / r.t_far, du);
            var n = c.att_nodes;
            if (nu < 0.02) {
                n = 0u;
            } else if (nu < 0.2) {
                n = min(1u, c.att_nodes);
            }
            let ga = curve_attenuation(r, a);
            let gb = curve_attenuation(r, b);
            *acc += segment_attenuated(seg, r, a, n, ga, gb);
            a = b;
        }
        if (b >= te) {
            break;
        }
        k += 1.0;
    }
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
    if (!(hi - lo > xh * 1.0e-6) || tb - ta > CURVE_INF) {
        let xm = (lo + hi) * 0.5;
        let i = curve_leaf_of(c, xm);
        let a = curve_node(c, i);
        let b = curve_node(c, i + 1u);
        let f = clamp((xm - a.x) / (b.x - a.x), 0.0, 1.0);
        let py = r.o.y + r.q.y * ta;
        let pz = r.o.z + r.q.z * ta;
        let p = vec3<f32>(0.0, py - (a.y + (b.y - a.y) * f), pz - (a.z + (b.z - a.z) * f));
        curve_piece(c, r, ta, p, vec3<f32>(0.0, r.q.y, r.q.z), tb - ta, acc);
        return;
    }
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
        var descend = false;
        if (nb.x > lo) {
            let x0 = max(lo, na.x);
            let x1 = min(hi, nb.x);
            var tx0 = t_lo + (x0 - lo) / r.q.x;
            if (x0 == lo) {
                tx0 = t_lo;
            } else if (x0 == hi) {
                tx0 = t_hi;
            }
            var tx1 = t_lo + (x1 - lo) / r.q.x;
            if (x1 == lo) {
                tx1 = t_lo;
            } else if (x1 == hi) {
                tx1 = t_hi;
            }
            let ts = select(tx1, tx0, tx0 <= tx1);
            let te = select(tx0, tx1, tx0 <= tx1);
            let idx = curve_level_offset(c, l) + j;
            let ln = curve_vec4[c.lines + idx];
            let xs = r.o.x + r.q.x * ts - (na.x + nb.x) * 0.5;
            let py = r.o.y + r.q.y * ts;
            let pz = r.o.z + r.q.z * ts;
            let p = vec3<f32>(0.0, py - (ln.x + xs * ln.z), pz - (ln.y + xs * ln.w));
            let v = vec3<f32>(0.0, r.q.y - r.q.x * ln.z, r.q.z - r.q.x * ln.w);
            let dt = te - ts;
            let err = curve_f32[c.errors + idx];
            var accept = l == 0u;
            if (!accept) {
                let vv = dot(v, v);
                var tau = 0.0;
                if (vv > 0.0) {
                    tau = clamp(-dot(p, v) / vv, 0.0, dt);
                }
                let d = p + v * tau;
                let d2 = dot(d, d) + r.rc2;
                let e2 = err * err / d2;
                let ell2 = vv * dt * dt / d2;
                accept = sqrt(e2) * min(ell2, 1.0) + e2 <= c.tolerance;
            }
            if (accept) {
                curve_piece(c, r, ts, p, v, dt, acc);
            } else {
                descend = true;
            }
        }
        if (descend) {
            l -= 1u;
            j *= 2u;
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
        curve_piece(c, r, a, r.o + r.q * a - curve_end_point(c, r, head), r.q, b - a, acc);
    }
}

// Mirrors integrate.rs `integrate_span`.
fn curve_integrate_span(c: GpuCurve, r: LocalRay, ta: f32, tb: f32, acc: ptr<function, f32>) {
    let qx = r.q.x;
    if (qx == 0.0) {
        if (r.o.x < 0.0) {
            curve_end_piece(c, r, false, ta, tb, acc);
        } else if (r.o.x > r.x_head) {
            curve_end_piece(c, r, true, ta, tb, acc);
        } else {
            curve_walk(c, r, ta, tb, acc);
        }
        return;
    }
    let t_a = -r.o.x / qx;
    let t_b = (r.x_head - r.o.x) / qx;
    var tin = t_a;
    var tout = t_b;
    var head_first = false;
    if (!(qx > 0.0)) {
        tin = t_b;
        tout = t_a;
        head_first = true;
    }
    curve_end_piece(c, r, head_first, ta, min(tb, tin), acc);
    let a = max(ta, tin);
    let b = min(tb, tout);
    if (b > a) {
        curve_walk(c, r, a, b, acc);
    }
    curve_end_piece(c, r, !head_first, max(ta, tout), tb, acc);
}

// Mirrors integrate.rs `default_generic` (f32).
fn curve_default(c: GpuCurve, falloff: u32, core_radius: f32, ray: Ray, t0: f32, t1: f32, t_far: f32) -> f32 {
    var ok = false;
    let r = curve_local_ray(c, falloff, core_radius, ray, t0, t1, t_far, &ok);
    if (!ok) {
        return 0.0;
    }
    var acc = 0.0;
    curve_integrate_span(c, r, r.t0, r.t1, &acc);
    let e = acc * r.alpha;
    return select(0.0, e, curve_finite(e));
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

// Mirrors simpson.rs `composite`: composite Simpson with m (even) subintervals over [a, b].
fn curve_composite(c: GpuCurve, r: LocalRay, a: f32, b: f32, m: u32) -> f32 {
    if (!(b > a)) {
        return 0.0;
    }
    let h = (b - a) / f32(m);
    var odd = 0.0;
    var even = 0.0;
    for (var i = 1u; i < m; i++) {
        let v = curve_density(c, r, a + h * f32(i));
        if ((i & 1u) == 1u) {
            odd += v;
        } else {
            even += v;
        }
    }
    return (curve_density(c, r, a) + 4.0 * odd + 2.0 * even + curve_density(c, r, b)) * h / 3.0;
}

// Mirrors simpson.rs `simpson_generic` (f32): m subintervals, m/n outside the bounding cylinder
// of radius R + ε (002 §3.4.4, eq. 3.22), the default integrator for any tail past the far point.
fn curve_simpson(c: GpuCurve, falloff: u32, core_radius: f32, ray: Ray, t0: f32, t1: f32, t_far: f32) -> f32 {
    var ok = false;
    let r = curve_local_ray(c, falloff, core_radius, ray, t0, t1, t_far, &ok);
    if (!ok) {
        return 0.0;
    }
    let m = c.m;
    let te = min(r.t1, r.t_far);
    var sum = 0.0;
    if (c.reduce == 0u) {
        sum += curve_composite(c, r, r.t0, te, m);
    } else {
        let mo = c.m_reduced;
        let rad = c.cylinder_radius;
        let a = r.q.y * r.q.y + r.q.z * r.q.z;
        let b = r.o.y * r.q.y + r.o.z * r.q.z;
        let k = r.o.y * r.o.y + r.o.z * r.o.z - rad * rad;
        let disc = b * b - a * k;
        if (a > 0.0 && disc > 0.0) {
            let sq = sqrt(disc);
            let u1 = clamp((-b - sq) / a, r.t0, te);
            let u2 = clamp((-b + sq) / a, r.t0, te);
            sum += curve_composite(c, r, r.t0, u1, mo);
            sum += curve_composite(c, r, u1, u2, m);
            sum += curve_composite(c, r, u2, te, mo);
        } else {
            sum += curve_composite(c, r, r.t0, te, mo);
        }
    }
    var e = sum * r.alpha;
    if (r.t1 > r.t_far) {
        e += curve_default(c, falloff, core_radius, ray, r.t_far, r.t1, r.t_far);
    }
    return select(0.0, e, curve_finite(e));
}

// Mirrors hadou_math::curve::curve_energy: dispatch on the wave's integrator.
fn curve_energy(c: GpuCurve, falloff: u32, core_radius: f32, ray: Ray, t0: f32, t1: f32, t_far: f32) -> f32 {
    if (c.integrator == INTEGRATOR_SIMPSON) {
        return curve_simpson(c, falloff, core_radius, ray, t0, t1, t_far);
    }
    return curve_default(c, falloff, core_radius, ray, t0, t1, t_far);
}
