// The traced resolve's per-pixel work (twin of hadou_math::soft::lamp and ::bvh; hadou's own, issue
// 43): the lamp as seen from a receiver (lamp_frame), the hierarchy's tests (capsule_hits,
// box_may_hide, one_side) and the samples a triangle hides (occlude, into `mask`), each function
// named after its Rust twin. Reads the module's `frame` (FrameUniforms: the lamp's shape, centre,
// axis and size), `traced` (TracedUniforms: the sample layout) and the hierarchy's `nodes` and
// `tris`, which the module declares: soft_traced.wgsl as bindings, the twin tests (trace_twins.rs)
// their own way. Prepended by common.wgsl.

// Keep in sync with layout/ `TracedUniforms` (hadou_math::soft::LampPattern).
struct TracedUniforms {
    rows: u32,
    per_row: u32,
    // 1 for rows of chords of the unit disc (disc, sphere), 0 for the segment's one row.
    disc: u32,
    node_count: u32,
    // Row j's share of the lamp in weights[j / 4][j % 4].
    weights: array<vec4<f32>, 8>,
}

// Keep in sync with hadou_math::soft::BvhNode (32 bytes).
struct BvhNode {
    lo: vec3<f32>,
    skip: u32,
    hi: vec3<f32>,
    tris: u32,
}

// Keep in sync with hadou_math::soft::BvhTri (48 bytes): corners in xyz, the unit normal in the ws.
struct BvhTri {
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
}

// hadou_math::soft::MASK_WORDS, T_MIN, TRACE_BIAS.
const MASK_WORDS: u32 = 32u;
const T_MIN: f32 = 1e-5;
const TRACE_BIAS: f32 = 1e-3;
// hadou_math::soft::SEGMENT_PLANE_MARGIN.
const SEGMENT_PLANE_MARGIN: f32 = 1e-4;

// A pixel's mask of hidden samples (bit k: sample k % per_row of row k / per_row), a function
// variable of the caller's passed by pointer (MASK_WORDS words).
alias Mask = array<u32, 32>;

// Twin of hadou_math::soft::lamp's hash32 (Chris Wellons's lowbias32).
fn hash32(x0: u32) -> u32 {
    var x = x0;
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

// Twin of hadou_math::soft::pixel_offset.
fn pixel_offset(x: u32, y: u32) -> f32 {
    return f32(hash32((x * 0x9e3779b1u) ^ hash32(y)) >> 8u) * (1.0 / 16777216.0);
}

// Twin of hadou_math::soft::lamp's floor_small and ceil_small (x already clamped to a small range).
fn floor_small(x: f32) -> f32 {
    let i = f32(i32(x));
    return select(i, i - 1.0, i > x);
}

fn ceil_small(x: f32) -> f32 {
    let i = f32(i32(x));
    return select(i, i + 1.0, i < x);
}

// Twin of hadou_math::soft::row_offset.
fn row_offset(o: f32, j: u32) -> f32 {
    let x = o + f32(j) * 0.618034;
    return x - floor_small(x);
}

// Twin of hadou_math::Vec3::orthonormal_basis (Duff et al.), the sign from z's sign bit as
// `1.copysign(z)`.
fn orthonormal_u(n: vec3<f32>) -> vec3<f32> {
    let sign = select(1.0, -1.0, (bitcast<u32>(n.z) & 0x80000000u) != 0u);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
}

fn orthonormal_v(n: vec3<f32>) -> vec3<f32> {
    let sign = select(1.0, -1.0, (bitcast<u32>(n.z) & 0x80000000u) != 0u);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(b, sign + n.y * n.y * a, -n.y);
}

fn finite_f32(v: f32) -> bool {
    return (bitcast<u32>(v) & 0x7f800000u) != 0x7f800000u;
}

// Twin of hadou_math::soft::LampFrame.
struct LampFrame {
    origin: vec3<f32>,
    centre: vec3<f32>,
    u: vec3<f32>,
    v: vec3<f32>,
    n: vec3<f32>,
    radius: f32,
    height: f32,
    // false: the receiver sees the lamp edge-on or from inside (it sees all of it).
    ok: bool,
}

// Twin of hadou_math::soft::lamp_frame for the frame's lamp seen from p.
fn lamp_frame(p: vec3<f32>) -> LampFrame {
    var f: LampFrame;
    f.ok = false;
    let l = frame.area_position;
    let axis = frame.area_axis;
    let size = frame.area_size;
    let r = p - l;
    if (frame.area_shape == LAMP_SEGMENT) {
        let side = r - axis * dot3(r, axis);
        let len = length3(side);
        if (!(len > 0.0 && finite_f32(len))) {
            return f;
        }
        let n = side / len;
        f.centre = l;
        f.u = axis;
        f.v = cross3(n, axis);
        f.n = n;
        f.radius = size;
    } else if (frame.area_shape == LAMP_DISC) {
        f.n = select(axis, -axis, dot3(r, axis) < 0.0);
        f.centre = l;
        f.u = orthonormal_u(axis);
        f.v = orthonormal_v(axis);
        f.radius = size;
    } else {
        let d = length3(r);
        if (d <= size || !finite_f32(d)) {
            return f;
        }
        let w = r / d;
        f.centre = l + w * (size * size / d);
        f.u = orthonormal_u(w);
        f.v = orthonormal_v(w);
        f.n = w;
        f.radius = size * sqrt((d - size) * (d + size)) / d;
    }
    f.origin = p;
    f.height = dot3(f.n, p - f.centre);
    f.ok = f.height > 0.0 && finite_f32(f.height) && f.radius > 0.0;
    return f;
}

// Twin of hadou_math::soft::capsule_hits: whether the ball (c, rc) meets the tapered capsule from
// the ball (a, ra) to the ball (b, rb); true where not finite.
fn capsule_hits(a: vec3<f32>, ra: f32, b: vec3<f32>, rb: f32, c: vec3<f32>, rc: f32) -> bool {
    let x = c - a;
    let d = b - a;
    let dl = length3(d);
    let rp = rb - ra;
    if (dl <= abs(rp) || dl <= 0.0) {
        var e = a;
        var r = ra;
        if (rb >= ra) {
            e = b;
            r = rb;
        }
        let gap = length3(c - e);
        return !(gap == gap) || !(rc == rc) || gap <= r + rc;
    }
    let axis = d / dl;
    let along = dot3(x, axis);
    let h = sqrt(max(dot3(x, x) - along * along, 0.0));
    let t = clamp(along / dl + rp * h / (dl * sqrt((dl - rp) * (dl + rp))), 0.0, 1.0);
    let f = length3(x - d * t) - ra - t * rp;
    return !(f == f) || !(rc == rc) || f <= rc;
}

// One corner `c` of box_may_hide's box: its projection from the origin onto the lamp's plane, in
// units of the radius, folded into the extent `e` (x0, x1, y0, y1); `state.x` counts the corners
// beyond the plane, `state.y` is 1 once a corner is at or behind the origin's parallel plane (or
// NaN).
fn box_corner(f: LampFrame, c: vec3<f32>, e: ptr<function, vec4<f32>>, state: ptr<function, vec2<u32>>) {
    let top = f.height * (1.0 - T_MIN);
    let h = dot3(f.n, c - f.centre);
    if (!(h == h) || h >= top) {
        (*state).y = 1u;
    }
    if (h < 0.0) {
        (*state).x += 1u;
    }
    let s = f.height / (f.height - h);
    let y = f.origin + (c - f.origin) * s - f.centre;
    let inv_r = 1.0 / f.radius;
    let px = dot3(f.u, y) * inv_r;
    let py = dot3(f.v, y) * inv_r;
    *e = vec4<f32>(min((*e).x, px), max((*e).y, px), min((*e).z, py), max((*e).w, py));
}

// Twin of hadou_math::soft::LampFrame::box_may_hide: the eight corners straight, with no loop
// (each node of the walk would spend eight of llvmpipe's loop iterations, see pixel_visibility).
fn box_may_hide(f: LampFrame, lo: vec3<f32>, hi: vec3<f32>, disc: bool) -> bool {
    var e = vec4<f32>(3.4028234663852886e38, -3.4028234663852886e38, 3.4028234663852886e38, -3.4028234663852886e38);
    var state = vec2<u32>(0u, 0u);
    box_corner(f, vec3<f32>(lo.x, lo.y, lo.z), &e, &state);
    box_corner(f, vec3<f32>(hi.x, lo.y, lo.z), &e, &state);
    box_corner(f, vec3<f32>(lo.x, hi.y, lo.z), &e, &state);
    box_corner(f, vec3<f32>(hi.x, hi.y, lo.z), &e, &state);
    box_corner(f, vec3<f32>(lo.x, lo.y, hi.z), &e, &state);
    box_corner(f, vec3<f32>(hi.x, lo.y, hi.z), &e, &state);
    box_corner(f, vec3<f32>(lo.x, hi.y, hi.z), &e, &state);
    box_corner(f, vec3<f32>(hi.x, hi.y, hi.z), &e, &state);
    let ylim = select(0.0, 1.0, disc);
    return state.y != 0u || (state.x < 8u && !(e.x > 1.0 || e.y < -1.0 || e.z > ylim || e.w < -ylim));
}

// Twin of hadou_math::soft::segment_plane_margin for the receiver p, `extent` the largest
// coordinate magnitude of the hierarchy's root box.
fn segment_plane_margin(p: vec3<f32>, extent: f32) -> f32 {
    return SEGMENT_PLANE_MARGIN * (max(max(abs(p.x), abs(p.y)), abs(p.z)) + extent);
}

// Twin of hadou_math::soft::LampFrame::box_beside_segment_plane: the box lo..hi wholly beyond
// `margin` on one side of the plane through the receiver and the segment.
fn box_beside_segment_plane(f: LampFrame, lo: vec3<f32>, hi: vec3<f32>, margin: f32) -> bool {
    let c = (lo + hi) * 0.5;
    let e = (hi - lo) * 0.5;
    let reach = e.x * abs(f.v.x) + e.y * abs(f.v.y) + e.z * abs(f.v.z);
    return abs(dot3(f.v, c - f.origin)) > reach + margin;
}

// Twin of hadou_math::soft::LampFrame::beside_segment_plane for a triangle's three corners.
fn tri_beside_segment_plane(f: LampFrame, t: BvhTri, margin: f32) -> bool {
    let da = dot3(f.v, t.a.xyz - f.origin);
    let db = dot3(f.v, t.b.xyz - f.origin);
    let dc = dot3(f.v, t.c.xyz - f.origin);
    return min(min(da, db), dc) > margin || max(max(da, db), dc) < -margin;
}

// Twin of hadou_math::soft::BvhTri::one_side with a receiver ball of radius 0 at p and the lamp's
// ball (l, rl).
fn one_side(t: BvhTri, p: vec3<f32>, l: vec3<f32>, rl: f32) -> bool {
    let n = vec3<f32>(t.a.w, t.b.w, t.c.w);
    let dp = dot3(n, p - t.a.xyz);
    let dl = dot3(n, l - t.a.xyz);
    return (dp > 0.0 && dl > rl) || (dp < 0.0 && dl < -rl);
}

// Twin of hadou_math::soft::LampPattern::row: row j's height and the half-length of its chord.
fn pattern_row(j: u32) -> vec2<f32> {
    if (traced.disc == 0u) {
        return vec2<f32>(0.0, 1.0);
    }
    let y = -1.0 + f32(2u * j + 1u) / f32(traced.rows);
    return vec2<f32>(y, sqrt(max(1.0 - y * y, 0.0)));
}

fn samples() -> u32 {
    return traced.rows * traced.per_row;
}

// The bits k..k+n (within one word) as a word mask.
fn word_bits(bit: u32, n: u32) -> u32 {
    return select(((1u << n) - 1u) << bit, 0xffffffffu, n == 32u);
}

// Twin of hadou_math::soft::lamp's set_bits: sets the bits a..b of the mask; returns how many were
// clear (the caller keeps the count of hidden samples, so that no loop asks whether the mask is
// full: see pixel_visibility).
fn set_bits(mask: ptr<function, Mask>, a: u32, b: u32) -> u32 {
    var i = a;
    var added = 0u;
    while (i < b) {
        let w = i / 32u;
        let bit = i % 32u;
        let n = min(32u - bit, b - i);
        let bits = word_bits(bit, n);
        added += countOneBits(bits & ~(*mask)[w]);
        (*mask)[w] |= bits;
        i += n;
    }
    return added;
}

// Twin of hadou_math::soft::lamp's count_bits: the set bits a..b of the mask.
fn count_bits(mask: ptr<function, Mask>, a: u32, b: u32) -> u32 {
    var i = a;
    var c = 0u;
    while (i < b) {
        let w = i / 32u;
        let bit = i % 32u;
        let n = min(32u - bit, b - i);
        c += countOneBits((*mask)[w] & word_bits(bit, n));
        i += n;
    }
    return c;
}

// Twin of hadou_math::soft::mask_visibility.
fn mask_visibility(mask: ptr<function, Mask>) -> f32 {
    var v = 0.0;
    let m = traced.per_row;
    for (var j = 0u; j < traced.rows; j++) {
        let hidden = count_bits(mask, j * m, (j + 1u) * m);
        v += traced.weights[j / 4u][j % 4u] * f32(m - hidden) / f32(m);
    }
    return clamp(v, 0.0, 1.0);
}

// Twin of hadou_math::soft::occlude: sets the samples of the lamp `f` (first-row offset `o`) that
// the triangle `t` hides from f.origin.
fn occlude(f: LampFrame, o: f32, t: BvhTri, mask: ptr<function, Mask>) -> u32 {
    let hp = f.height;
    let top = hp * (1.0 - T_MIN);
    var a: array<vec3<f32>, 5>;
    var ha: array<f32, 5>;
    a[0] = t.a.xyz;
    a[1] = t.b.xyz;
    a[2] = t.c.xyz;
    var na = 3u;
    for (var i = 0u; i < 3u; i++) {
        ha[i] = dot3(f.n, a[i] - f.centre);
    }
    var b: array<vec3<f32>, 5>;
    var hb: array<f32, 5>;
    var nb = 0u;
    // Clip against h ≥ 0. Loops of a constant count (the corners at most), which the compiler
    // unrolls: they spend none of llvmpipe's loop iterations (see pixel_visibility).
    for (var i = 0u; i < 3u; i++) {
        let k = (i + 1u) % 3u;
        let p = a[i];
        let q = a[k];
        let h0 = ha[i];
        let hq = ha[k];
        if (h0 >= 0.0) {
            b[nb] = p;
            hb[nb] = h0;
            nb += 1u;
        }
        if ((h0 >= 0.0) != (hq >= 0.0)) {
            let s = h0 / (h0 - hq);
            b[nb] = p + (q - p) * s;
            hb[nb] = 0.0;
            nb += 1u;
        }
    }
    // Then against h ≤ top.
    na = 0u;
    for (var i = 0u; i < 4u; i++) {
        if (i >= nb) {
            break;
        }
        let k = (i + 1u) % nb;
        let p = b[i];
        let q = b[k];
        let h0 = hb[i];
        let hq = hb[k];
        if (h0 <= top) {
            a[na] = p;
            ha[na] = h0;
            na += 1u;
        }
        if ((h0 <= top) != (hq <= top)) {
            let s = (h0 - top) / (h0 - hq);
            a[na] = p + (q - p) * s;
            ha[na] = top;
            na += 1u;
        }
    }
    // Each step only where the last leaves something to do.
    var added = 0u;
    if (na >= 3u) {
        added = occlude_polygon(f, o, a, ha, na, mask);
    }
    return added;
}

// occlude's second half: the clipped polygon `a` (heights `ha`, `na` corners) projected onto the
// lamp's plane and its samples set.
fn occlude_polygon(f: LampFrame, o: f32, a: array<vec3<f32>, 5>, ha: array<f32, 5>, na: u32, mask: ptr<function, Mask>) -> u32 {
    let hp = f.height;
    // Project from the origin onto the plane, in units of the radius.
    var xy: array<vec2<f32>, 5>;
    let inv_r = 1.0 / f.radius;
    var x0 = 3.4028234663852886e38;
    var x1 = -3.4028234663852886e38;
    var y0 = 3.4028234663852886e38;
    var y1 = -3.4028234663852886e38;
    for (var i = 0u; i < 5u; i++) {
        if (i >= na) {
            break;
        }
        let s = hp / max(hp - ha[i], hp * T_MIN);
        let y = f.origin + (a[i] - f.origin) * s - f.centre;
        xy[i] = vec2<f32>(dot3(f.u, y) * inv_r, dot3(f.v, y) * inv_r);
        x0 = min(x0, xy[i].x);
        x1 = max(x1, xy[i].x);
        y0 = min(y0, xy[i].y);
        y1 = max(y1, xy[i].y);
    }
    let disc = traced.disc != 0u;
    let ylim = select(0.0, 1.0, disc);
    var added = 0u;
    if (x0 > 1.0 || x1 < -1.0 || y0 > ylim || y1 < -ylim || !(x0 == x0) || !(y0 == y0)) {
        // It misses the lamp's box.
    } else {
        added = occlude_rows(f, o, xy, na, x0, x1, y0, y1, mask);
    }
    return added;
}

// occlude's last part: the projected polygon `xy` (`na` corners, extent x0..x1, y0..y1, meeting
// the lamp's box) into the samples of every row it crosses.
fn occlude_rows(f: LampFrame, o: f32, xy: array<vec2<f32>, 5>, na: u32, x0: f32, x1: f32, y0: f32, y1: f32, mask: ptr<function, Mask>) -> u32 {
    let disc = traced.disc != 0u;
    let ylim = select(0.0, 1.0, disc);
    // A polygon holding the lamp's box hides every sample. Only a polygon whose extent covers the
    // box can (the test's loops are skipped for the others: every loop iteration counts against
    // llvmpipe's budget, see pixel_visibility).
    var all_hidden = false;
    var added = 0u;
    var area = 0.0;
    let covers = x0 <= -1.0 && x1 >= 1.0 && y0 <= -ylim && y1 >= ylim;
    for (var i = 0u; i < 5u; i++) {
        if (i < na && covers) {
            let k = (i + 1u) % na;
            area += xy[i].x * xy[k].y - xy[k].x * xy[i].y;
        }
    }
    if (covers && area != 0.0) {
        var holds = true;
        for (var c = 0u; c < 4u; c++) {
            let px = select(-1.0, 1.0, (c & 1u) != 0u);
            let py = select(-ylim, ylim, (c & 2u) != 0u);
            for (var i = 0u; i < 5u; i++) {
                let k = (i + 1u) % na;
                let e = xy[i];
                let g = xy[k];
                if (i < na && !(((g.x - e.x) * (py - e.y) - (g.y - e.y) * (px - e.x)) * area >= 0.0)) {
                    holds = false;
                }
            }
        }
        if (holds) {
            added = set_bits(mask, 0u, samples());
        }
        all_hidden = holds;
    }
    // The rows whose height lies in [y0, y1].
    var j0 = 0u;
    var j1 = 0u;
    if (disc) {
        let r = f32(traced.rows);
        let k0 = (clamp(y0, -1.0, 1.0) + 1.0) * 0.5 * r - 0.5;
        let k1 = (clamp(y1, -1.0, 1.0) + 1.0) * 0.5 * r - 0.5;
        j0 = u32(max(ceil_small(k0), 0.0));
        j1 = u32(clamp(floor_small(k1), 0.0, r - 1.0));
    }
    let m = f32(traced.per_row);
    for (var j = j0; j <= j1 && !all_hidden; j++) {
        let row = pattern_row(j);
        let yj = row.x;
        let c = row.y;
        var lo = 3.4028234663852886e38;
        var hi = -3.4028234663852886e38;
        var any = false;
        for (var i = 0u; i < 5u; i++) {
            if (i >= na) {
                break;
            }
            let k = (i + 1u) % na;
            let p = xy[i];
            let q = xy[k];
            if ((p.y - yj) * (q.y - yj) > 0.0) {
                // The edge does not cross the row.
            } else if (p.y == q.y) {
                lo = min(lo, min(p.x, q.x));
                hi = max(hi, max(p.x, q.x));
            } else {
                let x = p.x + (yj - p.y) * (q.x - p.x) / (q.y - p.y);
                lo = min(lo, x);
                hi = max(hi, x);
            }
            any = any || !((p.y - yj) * (q.y - yj) > 0.0);
        }
        let oj = row_offset(o, j);
        let scale = m / (2.0 * c);
        let i0 = max(ceil_small(clamp((lo + c) * scale - oj, -1.0, m + 1.0)), 0.0);
        let i1 = min(floor_small(clamp((hi + c) * scale - oj, -1.0, m + 1.0)), m - 1.0);
        if (any && lo == lo && hi == hi && lo <= hi && c > 0.0 && i0 <= i1) {
            let base = j * traced.per_row;
            added += set_bits(mask, base + u32(i0), base + u32(i1) + 1u);
        }
    }
    return added;
}

// Twin of hadou-cpu's traced::pixel (the walk without a tile's triangles): the visibility of the
// receiver `r` at global pixel (x, y).
fn pixel_visibility(r: vec3<f32>, x: u32, y: u32) -> f32 {
    let f = lamp_frame(r);
    if (!f.ok) {
        return 1.0;
    }
    let o = pixel_offset(x, y);
    var mask: Mask;
    for (var w = 0u; w < MASK_WORDS; w++) {
        mask[w] = 0u;
    }
    let l = frame.area_position;
    let size = frame.area_size;
    let disc = traced.disc != 0u;
    // llvmpipe (lavapipe, Mesa's GL) stops every loop of a shader invocation once all its loops
    // together have run 65,535 iterations (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS, one counter
    // shared by every loop): past it, the walk would end early and mask_visibility count row 0
    // alone. So the work spends as few loop iterations as it can: the count of hidden samples
    // kept as bits are set (no loop asks whether the mask is full), the box test straight, the
    // loops over a polygon's corners of a constant count (unrolled), the containment test skipped
    // where it cannot hold (trace_twins.rs wgsl_trace_walk_matches_the_cpu holds the walk to the
    // CPU's). The walk itself, one iteration a node, and the rows a triangle crosses remain.
    // The segment: what lies wholly on one side of the plane through r and the segment hides
    // nothing (hadou-cpu's traced::pixel, the same test first).
    let segment = frame.area_shape == LAMP_SEGMENT;
    var extent = 0.0;
    if (traced.node_count > 0u) {
        let root = nodes[0];
        let m = max(abs(root.lo), abs(root.hi));
        extent = max(max(m.x, m.y), m.z);
    }
    let margin = segment_plane_margin(r, extent);
    var i = 0u;
    var full = false;
    var hidden = 0u;
    let all = samples();
    while (i < traced.node_count && !full) {
        let node = nodes[i];
        let centre = (node.lo + node.hi) * 0.5;
        let radius = length3(node.hi - node.lo) * 0.5;
        let count = node.tris & 15u;
        if ((segment && box_beside_segment_plane(f, node.lo, node.hi, margin))
            || !(capsule_hits(r, 0.0, l, size, centre, radius) && box_may_hide(f, node.lo, node.hi, disc))) {
            i = node.skip;
        } else if (count == 0u) {
            i += 1u;
        } else {
            let first = node.tris >> 4u;
            var k = first;
            while (k < first + count && !full) {
                let t = tris[k];
                if (!(segment && tri_beside_segment_plane(f, t, margin)) && !one_side(t, r, l, size)) {
                    hidden += occlude(f, o, t, &mask);
                    full = hidden >= all;
                }
                k += 1u;
            }
            i = node.skip;
        }
    }
    return mask_visibility(&mask);
}
