//! A flattened bounding volume hierarchy over the casters' world-space triangles, for the traced
//! resolve of the `[area_light]` (hadou's own). Plain `#[repr(C)]` arrays of `f32`/`u32`, no
//! pointers, so the GPU uploads and walks the very same bytes:
//!
//! - [`BvhNode`] (32 bytes): the node's box `lo`/`hi`, `skip` (the index of the first node after
//!   its subtree: nodes are stored in depth-first pre-order, a node's first child right after it)
//!   and `tris` (`first << 4 | count`: `count > 0` for a leaf holding the triangles
//!   `first..first + count`, `0` for an inner node).
//! - [`BvhTri`] (48 bytes): a triangle's three corners, each padded to four floats (`w = 0`).
//!
//! The walk is stackless ([`Bvh::walk`]): at node `i`, if the query meets its box, a leaf's
//! triangles are visited and an inner node continues at `i + 1` (its first child); otherwise, or
//! after a leaf, it continues at `skip`. It ends at `skip = nodes.len()`.
//!
//! The build is a median split on the longest axis of the centroids' box (ties by index), at most
//! [`LEAF_MAX`] triangles a leaf: it always terminates (each split halves the count, whatever the
//! coordinates), zero-area and non-finite triangles are dropped (they hide no light), and every
//! kept triangle ends in exactly one leaf.

use crate::Vec3f;

/// Most triangles of a leaf.
pub const LEAF_MAX: u32 = 4;

/// Bytes of one [`BvhNode`].
pub const BVH_NODE_BYTES: u64 = 32;
/// Bytes of one [`BvhTri`].
pub const BVH_TRI_BYTES: u64 = 48;

/// One node of the flattened hierarchy (32 bytes, WGSL
/// `struct BvhNode { lo: vec3<f32>, skip: u32, hi: vec3<f32>, tris: u32 }`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhNode {
    /// Smallest corner of the box of every triangle below.
    pub lo: [f32; 3],
    /// Index of the next node once this subtree is done (skipped or walked).
    pub skip: u32,
    /// Largest corner.
    pub hi: [f32; 3],
    /// `first << 4 | count`: a leaf's triangles `first..first + count` (`count ≥ 1`), `0` for an
    /// inner node.
    pub tris: u32,
}

impl BvhNode {
    /// A leaf's triangle range, `None` for an inner node.
    #[inline]
    pub fn leaf(&self) -> Option<std::ops::Range<usize>> {
        let count = (self.tris & 15) as usize;
        (count > 0).then(|| {
            let first = (self.tris >> 4) as usize;
            first..first + count
        })
    }

    /// The centre of the node's box and the radius of the ball around it that holds the box.
    #[inline]
    pub fn ball(&self) -> (Vec3f, f32) {
        let (lo, hi) = (Vec3f::from_array(self.lo), Vec3f::from_array(self.hi));
        ((lo + hi) * 0.5, (hi - lo).length() * 0.5)
    }
}

/// One triangle (48 bytes, WGSL `struct BvhTri { a: vec4<f32>, b: vec4<f32>, c: vec4<f32> }`): the
/// corners in `xyz` and, in the `w`s, the unit normal: `(a.w, b.w, c.w)` = unit `(b − a) × (c − a)`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhTri {
    /// First corner, `w` = the normal's `x`.
    pub a: [f32; 4],
    /// Second corner, `w` = the normal's `y`.
    pub b: [f32; 4],
    /// Third corner, `w` = the normal's `z`.
    pub c: [f32; 4],
}

impl BvhTri {
    /// The triangle `a b c` and its unit normal (zero for a degenerate one).
    pub fn new(a: Vec3f, b: Vec3f, c: Vec3f) -> Self {
        let n = (b - a).cross(c - a).normalize_or(Vec3f::ZERO);
        BvhTri { a: [a.x, a.y, a.z, n.x], b: [b.x, b.y, b.z, n.y], c: [c.x, c.y, c.z, n.z] }
    }

    /// The three corners.
    #[inline]
    pub fn corners(&self) -> [Vec3f; 3] {
        [self.a, self.b, self.c].map(|v| Vec3f::new(v[0], v[1], v[2]))
    }

    /// The unit normal.
    #[inline]
    pub fn normal(&self) -> Vec3f {
        Vec3f::new(self.a[3], self.b[3], self.c[3])
    }

    /// Whether the triangle's plane leaves the ball `(p, rp)` (a receiver or a tile of them) and
    /// the ball `(l, rl)` (the lamp) wholly on one side, so that no segment between them crosses
    /// the triangle (hadou's own): `n·(p − a)` and `n·(l − a)` of the same sign and each farther
    /// from the plane than its ball's radius. `false` where unsure (a zero normal, NaN).
    #[inline]
    pub fn one_side(&self, p: Vec3f, rp: f32, l: Vec3f, rl: f32) -> bool {
        let (n, a) = (self.normal(), Vec3f::new(self.a[0], self.a[1], self.a[2]));
        let (dp, dl) = (n.dot(p - a), n.dot(l - a));
        (dp > rp && dl > rl) || (dp < -rp && dl < -rl)
    }
}

/// A flattened hierarchy: [`BvhNode`]s in pre-order and the [`BvhTri`]s in leaf order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bvh {
    /// Nodes, the root first (empty without triangles).
    pub nodes: Vec<BvhNode>,
    /// Triangles, each leaf's contiguous.
    pub tris: Vec<BvhTri>,
}

/// Bytes a hierarchy over `triangles` triangles can take at most: every triangle kept, and fewer
/// than `2n` nodes (a full binary tree with at most `n` leaves).
pub fn bvh_bytes_bound(triangles: u64) -> u64 {
    triangles * BVH_TRI_BYTES + triangles.saturating_mul(2) * BVH_NODE_BYTES
}

/// Whether a triangle can hide light: finite corners and a non-zero area.
fn usable(t: &[Vec3f; 3]) -> bool {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    t.iter().all(|v| v.is_finite()) && n.length_squared() > 0.0 && n.is_finite()
}

impl Bvh {
    /// Builds the hierarchy over `tris` (world-space corners); see the module notes.
    pub fn build(tris: &[[Vec3f; 3]]) -> Bvh {
        let kept: Vec<[Vec3f; 3]> = tris.iter().filter(|t| usable(t)).copied().collect();
        if kept.is_empty() {
            return Bvh::default();
        }
        let centroid: Vec<Vec3f> = kept.iter().map(|t| (t[0] + t[1] + t[2]) * (1.0 / 3.0)).collect();
        let mut order: Vec<u32> = (0..kept.len() as u32).collect();
        let mut bvh = Bvh { nodes: Vec::with_capacity(2 * kept.len()), tris: Vec::with_capacity(kept.len()) };
        // The ranges still to build, the next one on top (pre-order: a node, then its left subtree,
        // then its right one).
        struct Job {
            start: usize,
            end: usize,
        }
        let mut stack = vec![Job { start: 0, end: kept.len() }];
        // The inner nodes whose subtree is not finished (a chain from the root), with the end of
        // their triangle range: each gets `skip` = the first node built past that end.
        let mut pending: Vec<(usize, usize)> = Vec::new(); // (node, subtree end in triangles)
        while let Some(Job { start, end }) = stack.pop() {
            let me = bvh.nodes.len();
            // Every pending node whose subtree ended before this range starts gets `skip = me`.
            while let Some(&(node, sub_end)) = pending.last() {
                if sub_end <= start {
                    bvh.nodes[node].skip = me as u32;
                    pending.pop();
                } else {
                    break;
                }
            }
            let (mut lo, mut hi) = (Vec3f::splat(f32::INFINITY), Vec3f::splat(f32::NEG_INFINITY));
            let (mut clo, mut chi) = (lo, hi);
            for &i in &order[start..end] {
                for v in kept[i as usize] {
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
                clo = clo.min(centroid[i as usize]);
                chi = chi.max(centroid[i as usize]);
            }
            let n = end - start;
            if n as u32 <= LEAF_MAX {
                let first = bvh.tris.len() as u32;
                for &i in &order[start..end] {
                    let [a, b, c] = kept[i as usize];
                    bvh.tris.push(BvhTri::new(a, b, c));
                }
                bvh.nodes.push(BvhNode {
                    lo: lo.to_array(),
                    skip: me as u32 + 1,
                    hi: hi.to_array(),
                    tris: first << 4 | n as u32,
                });
                continue;
            }
            bvh.nodes.push(BvhNode { lo: lo.to_array(), skip: 0, hi: hi.to_array(), tris: 0 });
            pending.push((me, end));
            let ext = chi - clo;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let key = |i: u32| centroid[i as usize].to_array()[axis];
            let mid = start + n / 2;
            order[start..end]
                .select_nth_unstable_by(n / 2, |&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
            // Left child first in pre-order: push the right one below it.
            stack.push(Job { start: mid, end });
            stack.push(Job { start, end: mid });
        }
        let total = bvh.nodes.len() as u32;
        for (node, _) in pending {
            bvh.nodes[node].skip = total;
        }
        bvh
    }

    /// Bytes of the node and triangle arrays.
    pub fn bytes(&self) -> u64 {
        self.nodes.len() as u64 * BVH_NODE_BYTES + self.tris.len() as u64 * BVH_TRI_BYTES
    }

    /// The stackless walk: calls `leaf(index, tri)` for every triangle of every leaf that `hits`,
    /// every ancestor hitting too, in pre-order (so in increasing `index`); `leaf` returns `false`
    /// to stop the walk early.
    #[inline]
    pub fn walk(&self, mut hits: impl FnMut(&BvhNode) -> bool, mut leaf: impl FnMut(usize, &BvhTri) -> bool) {
        let mut i = 0usize;
        while i < self.nodes.len() {
            let node = &self.nodes[i];
            if !hits(node) {
                i = node.skip as usize;
                continue;
            }
            match node.leaf() {
                None => i += 1,
                Some(range) => {
                    for t in range {
                        if !leaf(t, &self.tris[t]) {
                            return;
                        }
                    }
                    i = node.skip as usize;
                }
            }
        }
    }
}

/// Whether the ball `(c, rc)` meets the tapered capsule swept from the ball `(a, ra)` to the ball
/// `(b, rb)` (the union over `t ∈ [0, 1]` of the balls of centre `a + t·(b − a)` and radius
/// `ra + t·(rb − ra)`; hadou's own). That capsule holds every segment from a point of the first
/// ball to a point of the second (a Minkowski combination of the two), so it holds the shadow
/// volume between a receiver (or a tile of receivers, `ra > 0`) and a lamp inside the second ball:
/// a caster outside it cannot hide any part of the lamp. Exact for the capsule: the distance
/// `f(t) = |X − t·D| − ra − t·R'` (`X = c − a`, `D = b − a`, `R' = rb − ra`) is convex, its
/// minimum at `t = t₀ + R'·h / (|D|·√(|D|² − R'²))`, `t₀` the projection of `c` on the axis and
/// `h` the distance from it, clamped to `[0, 1]`; when one end ball holds the other (`|D| ≤ |R'|`)
/// the larger ball is the capsule. Conservative where not finite (the ball counts as met).
#[inline]
pub fn capsule_hits(a: Vec3f, ra: f32, b: Vec3f, rb: f32, c: Vec3f, rc: f32) -> bool {
    Capsule::new(a, ra, b, rb).hits(c, rc)
}

/// The tapered capsule of [`capsule_hits`] with what depends on it alone taken once (its axis,
/// length and taper), for the many balls one receiver or tile tests: [`Capsule::hits`] gives
/// [`capsule_hits`]'s answer bit for bit with one or two square roots instead of four.
#[derive(Clone, Copy, Debug)]
pub struct Capsule {
    a: Vec3f,
    ra: f32,
    d: Vec3f,
    dl: f32,
    rp: f32,
    axis: Vec3f,
    /// `|D|·√(|D|² − R'²)`.
    den: f32,
    /// One end ball holds the other: that ball (centre, radius) is the capsule.
    ball: Option<(Vec3f, f32)>,
}

impl Capsule {
    /// The capsule swept from the ball `(a, ra)` to the ball `(b, rb)`.
    #[inline]
    pub fn new(a: Vec3f, ra: f32, b: Vec3f, rb: f32) -> Capsule {
        let d = b - a;
        let dl = d.length();
        let rp = rb - ra;
        let ball = (dl <= rp.abs() || dl <= 0.0).then_some(if rb >= ra { (b, rb) } else { (a, ra) });
        let axis = d / dl;
        let den = dl * ((dl - rp) * (dl + rp)).sqrt();
        Capsule { a, ra, d, dl, rp, axis, den, ball }
    }

    /// Whether the ball `(c, rc)` meets the capsule ([`capsule_hits`]).
    #[inline]
    pub fn hits(&self, c: Vec3f, rc: f32) -> bool {
        if let Some((e, r)) = self.ball {
            let gap = (c - e).length();
            return gap.is_nan() || rc.is_nan() || gap <= r + rc;
        }
        let x = c - self.a;
        let along = x.dot(self.axis);
        let h = (x.length_squared() - along * along).max(0.0).sqrt();
        let t = (along / self.dl + self.rp * h / self.den).clamp(0.0, 1.0);
        let f = (x - self.d * t).length() - self.ra - t * self.rp;
        f.is_nan() || rc.is_nan() || f <= rc
    }
}

/// The closest point of the triangle `t` to `p` (Ericson, *Real-Time Collision Detection* §5.1.5:
/// the Voronoi regions of the corners, edges and face in turn).
#[inline]
pub fn closest_on_triangle(p: Vec3f, t: &[Vec3f; 3]) -> Vec3f {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// The least distance between the segments `p₁q₁` and `p₂q₂` (Ericson §5.1.9, degenerate
/// segments included).
#[inline]
pub fn segment_distance(p1: Vec3f, q1: Vec3f, p2: Vec3f, q2: Vec3f) -> f32 {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    let eps = 1e-12;
    let (s, t) = if a <= eps && e <= eps {
        (0.0, 0.0)
    } else if a <= eps {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= eps {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s = if denom > 0.0 { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p1 + d1 * s) - (p2 + d2 * t)).length()
}

/// The least distance between the segment `pq` and the triangle `t` (0 where they cross): the
/// smaller of the ends' distances to the triangle and the segment's to its three edges, unless
/// the segment pierces the face. NaN where an input is (callers count that as near).
#[inline]
pub fn segment_triangle_distance(p: Vec3f, q: Vec3f, t: &[Vec3f; 3]) -> f32 {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let (dp, dq) = (n.dot(p - t[0]), n.dot(q - t[0]));
    if (dp <= 0.0) != (dq <= 0.0) {
        // The segment crosses the plane: inside the triangle there?
        let x = p + (q - p) * (dp / (dp - dq));
        let inside = (0..3).all(|k| n.dot((t[(k + 1) % 3] - t[k]).cross(x - t[k])) >= 0.0);
        if inside {
            return 0.0;
        }
    }
    let mut d = (closest_on_triangle(p, t) - p).length().min((closest_on_triangle(q, t) - q).length());
    for k in 0..3 {
        d = d.min(segment_distance(p, q, t[k], t[(k + 1) % 3]));
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rng(seed: u64) -> impl FnMut() -> f32 {
        let mut s = seed | 1;
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    fn random_tris(n: usize, seed: u64) -> Vec<[Vec3f; 3]> {
        let mut r = rng(seed);
        (0..n)
            .map(|_| {
                let c = Vec3f::new(r() * 10.0 - 5.0, r() * 10.0 - 5.0, r() * 10.0 - 5.0);
                [0, 1, 2].map(|_| c + Vec3f::new(r() - 0.5, r() - 0.5, r() - 0.5))
            })
            .collect()
    }

    /// Every kept triangle in exactly one leaf, every box holding its subtree, `skip` past it.
    fn check(bvh: &Bvh, n: usize) {
        assert_eq!(bvh.tris.len(), n);
        let mut seen = vec![0u32; n];
        fn visit(bvh: &Bvh, i: usize, seen: &mut [u32]) -> usize {
            let node = bvh.nodes[i];
            let (lo, hi) = (Vec3f::from_array(node.lo), Vec3f::from_array(node.hi));
            match node.leaf() {
                Some(r) => {
                    for t in r.clone() {
                        seen[t] += 1;
                        for v in bvh.tris[t].corners() {
                            assert!(v.x >= lo.x && v.y >= lo.y && v.z >= lo.z);
                            assert!(v.x <= hi.x && v.y <= hi.y && v.z <= hi.z);
                        }
                    }
                    assert_eq!(node.skip as usize, i + 1);
                    i + 1
                }
                None => {
                    let left_end = visit(bvh, i + 1, seen);
                    let end = visit(bvh, left_end, seen);
                    for c in [i + 1, left_end] {
                        let k = bvh.nodes[c];
                        assert!(k.lo.iter().zip(node.lo).all(|(a, b)| *a >= b));
                        assert!(k.hi.iter().zip(node.hi).all(|(a, b)| *a <= b));
                    }
                    assert_eq!(node.skip as usize, end, "node {i}");
                    end
                }
            }
        }
        if n > 0 {
            assert_eq!(visit(bvh, 0, &mut seen), bvh.nodes.len());
        }
        assert!(seen.iter().all(|&s| s == 1));
        assert!(bvh.bytes() <= bvh_bytes_bound(n as u64));
    }

    #[test]
    fn build_keeps_every_triangle_once_in_boxes_that_hold_them() {
        for n in [0usize, 1, 3, 4, 5, 17, 100, 1000] {
            check(&Bvh::build(&random_tris(n, n as u64 + 7)), n);
        }
    }

    #[test]
    fn degenerate_input_neither_hangs_nor_keeps_what_hides_nothing() {
        let p = Vec3f::new(1.0, 2.0, 3.0);
        // Zero-area triangles are dropped; coincident centroids still split.
        let flat = vec![[p, p, p]; 50];
        assert!(Bvh::build(&flat).nodes.is_empty());
        let same = vec![[p, p + Vec3f::X, p + Vec3f::Y]; 5000];
        check(&Bvh::build(&same), 5000);
        // Huge, finite coordinates.
        let huge = 1e12f32;
        let big: Vec<[Vec3f; 3]> = (0..300)
            .map(|i| {
                let o = Vec3f::new(huge * (i % 7) as f32 / 7.0, -huge, huge * 0.5);
                [o, o + Vec3f::new(huge * 0.1, 0.0, 0.0), o + Vec3f::new(0.0, huge * 0.1, 1.0)]
            })
            .collect();
        check(&Bvh::build(&big), 300);
        let nan = [Vec3f::new(f32::NAN, 0.0, 0.0), Vec3f::X, Vec3f::Y];
        assert!(Bvh::build(&[nan]).tris.is_empty());
    }

    #[test]
    fn walk_finds_what_a_brute_force_finds() {
        let tris = random_tris(500, 3);
        let bvh = Bvh::build(&tris);
        let mut r = rng(11);
        for _ in 0..200 {
            let a = Vec3f::new(r() * 12.0 - 6.0, r() * 12.0 - 6.0, r() * 12.0 - 6.0);
            let b = Vec3f::new(r() * 12.0 - 6.0, r() * 12.0 - 6.0, r() * 12.0 - 6.0);
            let (ra, rb) = (r() * 0.5, r() * 1.5);
            let mut found = Vec::new();
            bvh.walk(
                |node| {
                    let (c, rc) = node.ball();
                    capsule_hits(a, ra, b, rb, c, rc)
                },
                |_, t| {
                    found.push(*t);
                    true
                },
            );
            for t in &bvh.tris {
                let ([p, q, s], hit) = (t.corners(), found.contains(t));
                for v in [p, q, s] {
                    // A corner inside the capsule (sampled densely) must be walked to.
                    let inside = (0..=64).any(|k| {
                        let t = k as f32 / 64.0;
                        (v - a.lerp(b, t)).length() <= ra + t * (rb - ra)
                    });
                    assert!(!inside || hit, "a corner inside the capsule was not walked to");
                }
            }
        }
    }

    #[test]
    fn capsule_test_is_exact_against_sampling() {
        let mut r = rng(5);
        for _ in 0..2000 {
            let a = Vec3f::new(r(), r(), r()) * 4.0;
            let b = Vec3f::new(r(), r(), r()) * 4.0;
            let c = Vec3f::new(r(), r(), r()) * 4.0;
            let (ra, rb, rc) = (r() * 0.6, r() * 0.6, r() * 0.3);
            let dist = (0..=4000)
                .map(|k| {
                    let t = k as f32 / 4000.0;
                    (c - a.lerp(b, t)).length() - (ra + t * (rb - ra))
                })
                .fold(f32::INFINITY, f32::min);
            let hit = capsule_hits(a, ra, b, rb, c, rc);
            if dist < rc - 1e-3 {
                assert!(hit, "missed: {dist} < {rc}");
            }
            if dist > rc + 1e-2 {
                assert!(!hit, "false hit: {dist} > {rc}");
            }
        }
        assert!(capsule_hits(Vec3f::ZERO, 0.0, Vec3f::X, 1.0, Vec3f::splat(f32::NAN), 0.0));
    }

    #[test]
    fn segment_triangle_distance_matches_sampling() {
        let mut r = rng(21);
        for _ in 0..3000 {
            let v = |r: &mut dyn FnMut() -> f32| Vec3f::new(r(), r(), r()) * 4.0;
            let t = [v(&mut r), v(&mut r), v(&mut r)];
            let (p, q) = (v(&mut r), v(&mut r));
            let d = segment_triangle_distance(p, q, &t);
            // Sampled: points of the segment against points of the triangle.
            let mut best = f32::INFINITY;
            for i in 0..=60 {
                let x = p.lerp(q, i as f32 / 60.0);
                best = best.min((closest_on_triangle(x, &t) - x).length());
            }
            assert!(d <= best + 1e-4, "{d} > sampled {best}");
            assert!(d >= best - 0.15, "{d} far below sampled {best}");
        }
        let t = [Vec3f::ZERO, Vec3f::X, Vec3f::Y];
        let d = segment_triangle_distance(Vec3f::new(0.2, 0.2, -1.0), Vec3f::new(0.2, 0.2, 1.0), &t);
        assert_eq!(d, 0.0);
        let d = segment_triangle_distance(Vec3f::new(2.0, 0.0, 1.0), Vec3f::new(2.0, 0.0, -1.0), &t);
        assert!((d - 1.0).abs() < 1e-6);
    }
}
