//! The traced resolve's per-pixel count of hidden lamp samples from the outline of what a
//! receiver sees (hadou's own, issue 43), for one tile's candidate triangles: see
//! [`hadou_math::soft::Topology`] for the weights and the winding number this counts with.
//!
//! For a pixel with receiver `p` and lamp frame `f` ([`LampFrame`]):
//! 1. every candidate triangle gets its weight `w` from the side `p` is on (fixed for the whole
//!    tile when the tile's ball lies on one side of its plane);
//! 2. a counted triangle wholly between the lamp's plane and the receiver (every corner's height
//!    `h` over the plane in `(0, (1 − T_MIN)·hₚ)`) is counted through its edges; one reaching
//!    past either plane is clipped and set in the sample mask on its own
//!    ([`hadou_math::soft::occlude`]) and left out of the edges;
//! 3. every edge whose weight `c = w₁ + σ·w₂` is not zero (the outline, in practice) is
//!    projected from `p` onto the lamp's plane; where it crosses a row of samples
//!    (half-open in height, so a corner shared by two edges counts once), `±c` is added at the
//!    first sample to its right (`+` going up);
//! 4. along each row the running sum is the winding number of the sample; a sample is hidden
//!    where it is not zero or its mask bit is set, and the visibility is the rows' weighted share
//!    of clear samples ([`LampPattern::row_weight`]).
//!
//! The answer is the one [`hadou_math::soft::occlude`] gives triangle by triangle (the union of
//! the projected triangles), up to samples lying exactly on a projected edge; only the outline's
//! few edges are projected, which is what makes a detailed caster cheap.

use hadou_math::soft::{
    occlude, row_offset, Bvh, Capsule, LampFrame, LampPattern, Topology, MASK_WORDS, NO_TRI, T_MIN,
};
use hadou_math::Vec3f;
use std::collections::HashMap;

/// No local triangle.
const NONE: u32 = u32::MAX;

/// A candidate triangle of the tile.
#[derive(Clone, Copy)]
struct LocalTri {
    /// Local corners.
    v: [u32; 3],
    /// First corner and unit normal (the side test).
    a: Vec3f,
    n: Vec3f,
    /// Local edges (`a b`, `b c`, `c a`).
    e: [u32; 3],
    /// The weight over the whole tile, when the tile's ball lies on one side of the plane.
    fixed: Option<i8>,
    /// Global index.
    global: u32,
    /// A ball around it (centre, radius).
    ball: (Vec3f, f32),
}

/// An edge that can carry weight somewhere in the tile.
#[derive(Clone, Copy)]
struct LocalEdge {
    a: u32,
    b: u32,
    t1: u32,
    t2: u32,
    sigma: i8,
}

/// One tile's candidate triangles, their corners and the edges that may be outline, with the
/// per-pixel scratch; reused from tile to tile.
#[derive(Default)]
pub(crate) struct TileCasters {
    verts: Vec<Vec3f>,
    tris: Vec<LocalTri>,
    /// Every edge of the candidates.
    edges: Vec<LocalEdge>,
    /// The edges that can carry weight somewhere in the tile when both their triangles are
    /// counted through their edges (the others are only needed beside a triangle that is
    /// clipped or beyond the planes, which then carries them itself).
    live: Vec<u32>,
    vert_of: HashMap<u32, u32>,
    edge_of: HashMap<u32, u32>,
    edge_stamp: Vec<u32>,
    // Per pixel.
    h: Vec<f32>,
    xy: Vec<(f32, f32)>,
    projected: Vec<u32>,
    stamp: u32,
    w: Vec<i8>,
    /// Counted triangles clipped or beyond the planes (this pixel's).
    spill: Vec<u32>,
    diff: Vec<i32>,
}

impl TileCasters {
    /// Takes the candidates `ids` (global triangle indices, ascending) of a tile whose receivers
    /// lie in the ball `(tc, tr)`.
    pub(crate) fn set(&mut self, bvh: &Bvh, topo: &Topology, ids: &[u32], tc: Vec3f, tr: f32) {
        self.verts.clear();
        self.tris.clear();
        self.edges.clear();
        self.live.clear();
        self.vert_of.clear();
        self.edge_of.clear();
        let local = |g: u32| -> u32 {
            if g == NO_TRI {
                return NONE;
            }
            ids.binary_search(&g).map_or(NONE, |i| i as u32)
        };
        for &g in ids {
            let gv = topo.tri_verts[g as usize];
            let v = gv.map(|i| {
                *self.vert_of.entry(i).or_insert_with(|| {
                    self.verts.push(topo.verts[i as usize]);
                    self.verts.len() as u32 - 1
                })
            });
            let t = &bvh.tris[g as usize];
            let (a, n) = (topo.verts[gv[0] as usize], t.normal());
            let d = n.dot(tc - a);
            let fixed = if d > tr {
                Some(1)
            } else if d < -tr {
                Some(-1)
            } else {
                None
            };
            let corners = t.corners();
            let centre = (corners[0] + corners[1] + corners[2]) * (1.0 / 3.0);
            let radius = corners.iter().map(|c| (*c - centre).length()).fold(0.0f32, f32::max);
            self.tris.push(LocalTri { v, a, n, e: [0; 3], fixed, global: g, ball: (centre, radius) });
        }
        for (lt, &g) in ids.iter().enumerate() {
            for k in 0..3 {
                let ge = topo.tri_edges[g as usize][k];
                let next = self.edges.len() as u32;
                let le = *self.edge_of.entry(ge).or_insert(next);
                self.tris[lt].e[k] = le;
                if le != next {
                    continue;
                }
                let te = topo.edges[ge as usize];
                let (t1, t2) = (local(te.t1), local(te.t2));
                // `t1` may lie outside the candidates while `t2` is in: turn the edge round so
                // that `t1` is a candidate.
                let (a, b, t1, t2, sigma) = if t1 == NONE {
                    if te.sigma == -1 {
                        (te.b, te.a, t2, NONE, 0)
                    } else {
                        (te.a, te.b, t2, NONE, 0)
                    }
                } else {
                    (te.a, te.b, t1, t2, te.sigma)
                };
                self.edges.push(LocalEdge { a: self.vert_of[&a], b: self.vert_of[&b], t1, t2, sigma });
                let fixed_of = |t: u32| if t == NONE { Some(0) } else { self.tris[t as usize].fixed };
                let dead =
                    matches!((fixed_of(t1), fixed_of(t2)), (Some(w1), Some(w2)) if w1 + sigma * w2 == 0);
                if !dead {
                    self.live.push(next);
                }
            }
        }
        let nv = self.verts.len();
        self.projected.clear();
        self.projected.resize(nv, 0);
        self.h.resize(nv, 0.0);
        self.xy.resize(nv, (0.0, 0.0));
        self.edge_stamp.clear();
        self.edge_stamp.resize(self.edges.len(), 0);
        self.stamp = 0;
        self.w.clear();
        self.w.resize(self.tris.len(), 0);
    }

    /// The visibility of the lamp `f` (layout `pat`, first-row offset `o`) from its origin, the
    /// tile's candidates being every triangle that can hide part of it; `lamp_centre` and
    /// `lamp_size` give the ball that holds the lamp, which a clipped triangle must come near
    /// ([`hadou_math::soft::capsule_hits`], [`hadou_math::soft::BvhTri::one_side`]) before it is projected.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn visibility(
        &mut self,
        bvh: &Bvh,
        f: &LampFrame,
        pat: &LampPattern,
        o: f32,
        lamp_centre: Vec3f,
        lamp_size: f32,
    ) -> f32 {
        let TileCasters {
            verts, tris, edges, live, h, xy, projected, stamp, edge_stamp, w, spill, diff, ..
        } = self;
        let p = f.origin;
        let top = f.height * (1.0 - T_MIN);
        *stamp = stamp.wrapping_add(1);
        if *stamp == 0 {
            projected.iter_mut().for_each(|s| *s = 0);
            edge_stamp.iter_mut().for_each(|s| *s = 0);
            *stamp = 1;
        }
        let stamp = *stamp;
        for (h, v) in h.iter_mut().zip(verts.iter()) {
            *h = f.n.dot(*v - f.centre);
        }
        let mut mask = [0u32; MASK_WORDS];
        let mut masked = false;
        spill.clear();
        let capsule = Capsule::new(p, 0.0, lamp_centre, lamp_size);
        for (i, (t, w)) in tris.iter().zip(w.iter_mut()).enumerate() {
            let i = i as u32;
            let s = match t.fixed {
                Some(fw) => fw,
                None => {
                    let d = t.n.dot(p - t.a);
                    (d > 0.0) as i8 - (d < 0.0) as i8
                }
            };
            *w = 0;
            if s == 0 {
                continue;
            }
            let hs = t.v.map(|i| h[i as usize]);
            if hs.iter().all(|&h| h > 0.0 && h < top) {
                *w = s;
                continue;
            }
            // Its edges with counted neighbours are outline now, even where the tile dropped them.
            spill.push(i);
            let corners = t.v.map(|v| verts[v as usize]);
            let near = |c: Vec3f, rc: f32| capsule.hits(c, rc);
            if hs.iter().any(|&h| h > 0.0)
                && hs.iter().any(|&h| h < top)
                && (!bvh.tris[t.global as usize].one_side(p, 0.0, lamp_centre, lamp_size)
                    && near(t.ball.0, t.ball.1))
            {
                occlude(f, pat, o, &corners, &mut mask);
                masked = true;
            }
        }
        let (rows, m) = (pat.rows as usize, pat.per_row as usize);
        let stride = m + 1;
        // Rows some edge crosses (bit j).
        let mut touched = 0u32;
        let mut cleared = false;
        let inv_r = 1.0 / f.radius;
        let extra = spill.iter().flat_map(|&t| tris[t as usize].e);
        for ei in live.iter().copied().chain(extra) {
            if edge_stamp[ei as usize] == stamp {
                continue;
            }
            edge_stamp[ei as usize] = stamp;
            let e = edges[ei as usize];
            let w2 = if e.t2 == NONE { 0 } else { w[e.t2 as usize] };
            let c = i32::from(w[e.t1 as usize] + e.sigma * w2);
            if c == 0 {
                continue;
            }
            let mut at = |i: u32| -> (f32, f32) {
                let i = i as usize;
                if projected[i] != stamp {
                    projected[i] = stamp;
                    let s = f.height / (f.height - h[i]);
                    let y = p + (verts[i] - p) * s - f.centre;
                    xy[i] = (f.u.dot(y) * inv_r, f.v.dot(y) * inv_r);
                }
                xy[i]
            };
            let (pa, pb) = (at(e.a), at(e.b));
            if pa.1 == pb.1 {
                continue;
            }
            let (lo, hi, dir) = if pa.1 < pb.1 { (pa, pb, c) } else { (pb, pa, -c) };
            let (j0, j1) = pat.rows_within(lo.1, hi.1);
            for j in j0..=j1 {
                let (yj, cj) = pat.row(j);
                if !(lo.1 <= yj && yj < hi.1) || cj <= 0.0 {
                    continue;
                }
                if !cleared {
                    cleared = true;
                    diff.clear();
                    diff.resize(rows * stride, 0);
                }
                let x = lo.0 + (yj - lo.1) * (hi.0 - lo.0) / (hi.1 - lo.1);
                let q = ((x + cj) * (m as f32 / (2.0 * cj)) - row_offset(o, j)).clamp(-2.0, m as f32 + 1.0);
                let k = (q.floor() as i32 + 1).clamp(0, m as i32) as usize;
                diff[j as usize * stride + k] += dir;
                touched |= 1 << j;
            }
        }
        if touched == 0 && !masked {
            return 1.0;
        }
        let mut v = 0.0f32;
        for j in 0..rows {
            let clear = if touched >> j & 1 == 0 {
                if masked {
                    m as u32 - count_row(&mask, j * m, m)
                } else {
                    m as u32
                }
            } else {
                let mut wind = 0i32;
                let mut clear = 0u32;
                for (i, d) in diff[j * stride..j * stride + m].iter().enumerate() {
                    wind += d;
                    let bit = j * m + i;
                    let hidden = wind != 0 || (masked && mask[bit / 32] >> (bit % 32) & 1 == 1);
                    clear += u32::from(!hidden);
                }
                clear
            };
            v += pat.weights[j] * clear as f32 / m as f32;
        }
        v.clamp(0.0, 1.0)
    }
}

/// The set bits `start..start + len` of `mask`.
fn count_row(mask: &[u32; MASK_WORDS], start: usize, len: usize) -> u32 {
    (start..start + len).filter(|&b| mask[b / 32] >> (b % 32) & 1 == 1).count() as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use hadou_math::soft::{lamp_frame, mask_visibility, pixel_offset, LampShape};

    fn rng(seed: u64) -> impl FnMut() -> f32 {
        let mut s = seed | 1;
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// The 12 triangles of the box `lo..hi`, wound outward.
    fn box_tris(lo: Vec3f, hi: Vec3f) -> Vec<[Vec3f; 3]> {
        let c = |i: usize| {
            Vec3f::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let quads = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];
        quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]].map(|t| t.map(c))).collect()
    }

    /// Every sample the winding count hides is one some triangle hides ([`occlude`], one by one),
    /// and the other way round, for boxes, loose triangles and receivers beside the casters, on
    /// their faces and inside them, for every lamp shape.
    #[test]
    fn the_winding_count_equals_the_union_of_the_triangles() {
        let mut r = rng(9);
        let mut worst = 0.0f32;
        for case in 0..2000 {
            let mut tris = box_tris(Vec3f::new(-0.5, 0.0, -0.5), Vec3f::new(0.5, 1.6, 0.5));
            tris.extend(box_tris(Vec3f::new(0.8, 0.2, 0.3), Vec3f::new(1.1, 0.5, 0.9)));
            for _ in 0..6 {
                let c = Vec3f::new(r() * 3.0 - 1.5, r() * 2.0, r() * 3.0 - 1.5);
                tris.push([0, 1, 2].map(|_| c + Vec3f::new(r() - 0.5, r() - 0.5, r() - 0.5) * 0.8));
            }
            let bvh = Bvh::build(&tris);
            let topo = Topology::of(&bvh);
            let shape = [LampShape::Segment, LampShape::Disc, LampShape::Sphere][case % 3];
            let l = Vec3f::new(2.2 + r(), 3.0 + r(), 0.8 + r());
            let axis = (l - Vec3f::new(0.0, 0.8, 0.0)).normalize_or(Vec3f::Y);
            let size = 0.2 + r() * 0.6;
            let p = if case % 4 == 0 {
                // On a face of the first box (its top), just above it.
                Vec3f::new(r() - 0.5, 1.6 + 1e-3, r() - 0.5)
            } else {
                Vec3f::new(r() * 4.0 - 2.0, r() * 0.3, r() * 4.0 - 2.0)
            };
            let Some(f) = lamp_frame(shape, l, axis, size, p) else { continue };
            let pat = LampPattern::new(shape, 256);
            let o = pixel_offset(case as u32, 7);
            let ids: Vec<u32> = (0..bvh.tris.len() as u32).collect();
            let mut casters = TileCasters::default();
            // The tile's ball: the receiver alone (every side fixed), or a wider one around it.
            let tile =
                if case % 2 == 0 { (p, 0.0) } else { (p + Vec3f::new(r() - 0.5, 0.0, r() - 0.5) * 0.2, 0.3) };
            casters.set(&bvh, &topo, &ids, tile.0, tile.1);
            let got = casters.visibility(&bvh, &f, &pat, o, l, size);
            let mut mask = [0u32; MASK_WORDS];
            for t in &bvh.tris {
                occlude(&f, &pat, o, &t.corners(), &mut mask);
            }
            let want = mask_visibility(&mask, &pat);
            worst = worst.max((got - want).abs());
            assert!((got - want).abs() <= 2.0 / pat.per_row as f32, "case {case} {shape:?}: {got} vs {want}");
        }
        eprintln!("largest difference {worst}");
    }
}
