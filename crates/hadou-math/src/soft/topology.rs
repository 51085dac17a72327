//! How the casters' triangles of a [`Bvh`] hang together (hadou's own, issue 43): their corners
//! welded and their edges shared. The CPU's traced resolve uses it to count a lamp's hidden
//! samples from the outline of what a receiver sees instead of from every triangle
//! (`hadou_cpu::traced`, its module notes):
//!
//! - **Weights.** Seen from a receiver `p`, a triangle's side is `s = sign(n·(p − a))`; a triangle
//!   hides light whichever side faces `p`, so it counts with weight `w = s` (a back face counted
//!   turned over). (Counting only a closed solid's front faces would halve the work, but it is
//!   wrong for a receiver inside a solid or within the blocker tolerance of one — where two
//!   pieces of a figure meet — so every face counts.)
//! - **Winding.** Projected from `p` onto the lamp's plane, every triangle turns the same way once
//!   weighted, so the sum of their weighted indicators (the winding number of the weighted edges)
//!   counts the layers over a lamp point, and the point is hidden where it is not zero. An edge
//!   shared by two triangles carries `w₁ + σ·w₂` (`σ = −1` when the second runs it the other way,
//!   as in a consistently wound surface): zero between two front or two back faces, so only the
//!   outline (the folds between front and back faces, and the borders) is ever projected.
//!
//! Corners are welded when their coordinates are equal bit for bit (`−0.0` as `0.0`); an edge
//! met by more than two triangles is kept once per extra triangle, as a border of its own.

use super::bvh::Bvh;
use crate::Vec3f;
use std::collections::HashMap;

/// No triangle (an edge's second side on a border).
pub const NO_TRI: u32 = u32::MAX;

/// An edge between welded corners `a` and `b`, as the triangle `t1` runs it (`a → b`), and the
/// triangle `t2` on its other side ([`NO_TRI`] on a border) with `sigma = −1` when `t2` runs it
/// `b → a`, `+1` when `t2` runs it `a → b` too.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TopoEdge {
    /// First corner (welded index).
    pub a: u32,
    /// Second corner.
    pub b: u32,
    /// The triangle that runs it `a → b`.
    pub t1: u32,
    /// The triangle on its other side, or [`NO_TRI`].
    pub t2: u32,
    /// `−1` or `+1`, see above (`0` without `t2`).
    pub sigma: i8,
}

/// The welded corners and the shared edges of a hierarchy's triangles, in
/// the order of [`Bvh::tris`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Topology {
    /// Welded corners.
    pub verts: Vec<Vec3f>,
    /// Each triangle's corners (indices into `verts`, in the triangle's order `a b c`).
    pub tri_verts: Vec<[u32; 3]>,
    /// Each triangle's edges (indices into `edges`: `a b`, `b c`, `c a`).
    pub tri_edges: Vec<[u32; 3]>,
    /// The edges, each once (an edge met by more than two triangles: once per extra triangle, as
    /// a border of its own).
    pub edges: Vec<TopoEdge>,
}

fn key(v: Vec3f) -> [u32; 3] {
    // `+ 0.0` turns −0.0 into 0.0, so both weld.
    [(v.x + 0.0).to_bits(), (v.y + 0.0).to_bits(), (v.z + 0.0).to_bits()]
}

impl Topology {
    /// The topology of `bvh`'s triangles.
    pub fn of(bvh: &Bvh) -> Topology {
        let n = bvh.tris.len();
        let mut weld: HashMap<[u32; 3], u32> = HashMap::with_capacity(n);
        let mut verts = Vec::new();
        let tri_verts: Vec<[u32; 3]> = bvh
            .tris
            .iter()
            .map(|t| {
                t.corners().map(|v| {
                    *weld.entry(key(v)).or_insert_with(|| {
                        verts.push(v);
                        verts.len() as u32 - 1
                    })
                })
            })
            .collect();
        drop(weld);
        // Undirected edge → its entry in `edges`.
        let mut by_pair: HashMap<(u32, u32), u32> = HashMap::with_capacity(n * 3 / 2 + 1);
        let mut edges: Vec<TopoEdge> = Vec::with_capacity(n * 3 / 2 + 1);
        let mut tri_edges = vec![[0u32; 3]; n];
        for (t, vs) in tri_verts.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (vs[k], vs[(k + 1) % 3]);
                let pair = (a.min(b), a.max(b));
                let slot = match by_pair.get(&pair) {
                    Some(&e) if edges[e as usize].t2 == NO_TRI && a != b => {
                        let edge = &mut edges[e as usize];
                        edge.t2 = t as u32;
                        edge.sigma = if edge.a == a { 1 } else { -1 };
                        e
                    }
                    _ => {
                        // New, or a third (fourth …) triangle on it: a border of its own.
                        edges.push(TopoEdge { a, b, t1: t as u32, t2: NO_TRI, sigma: 0 });
                        let e = edges.len() as u32 - 1;
                        by_pair.entry(pair).or_insert(e);
                        e
                    }
                };
                tri_edges[t][k] = slot;
            }
        }
        Topology { verts, tri_verts, tri_edges, edges }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::soft::Bvh;

    /// The 12 triangles of the box `lo..hi`, wound outward (or inward when `flip`).
    fn box_tris(lo: Vec3f, hi: Vec3f, flip: bool) -> Vec<[Vec3f; 3]> {
        let c = |i: usize| {
            Vec3f::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        };
        // Faces as corner quads, counter-clockwise seen from outside.
        let quads = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];
        let mut out = Vec::new();
        for q in quads {
            for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                let mut tri = t.map(c);
                if flip {
                    tri.swap(1, 2);
                }
                out.push(tri);
            }
        }
        out
    }

    #[test]
    fn a_box_shares_every_edge_between_two_faces_wound_against_each_other() {
        for flip in [false, true] {
            let topo = Topology::of(&Bvh::build(&box_tris(Vec3f::ZERO, Vec3f::new(1.0, 2.0, 3.0), flip)));
            assert_eq!(topo.verts.len(), 8);
            assert_eq!(topo.edges.len(), 18);
            assert!(topo.edges.iter().all(|e| e.t2 != NO_TRI && e.sigma == -1));
            for (t, es) in topo.tri_edges.iter().enumerate() {
                assert!(es
                    .iter()
                    .all(|&e| [topo.edges[e as usize].t1, topo.edges[e as usize].t2].contains(&(t as u32))));
            }
        }
    }

    #[test]
    fn borders_flipped_faces_and_folds_of_three_are_kept_apart() {
        let mut tris = box_tris(Vec3f::ZERO, Vec3f::splat(1.0), false);
        tris.pop();
        let topo = Topology::of(&Bvh::build(&tris));
        assert_eq!(topo.edges.iter().filter(|e| e.t2 == NO_TRI).count(), 3);
        let mut tris = box_tris(Vec3f::ZERO, Vec3f::splat(1.0), false);
        tris[3].swap(1, 2);
        let topo = Topology::of(&Bvh::build(&tris));
        assert_eq!(topo.edges.iter().filter(|e| e.sigma == 1).count(), 3);
        // Three triangles on one edge: the third keeps it as a border of its own.
        let (a, b) = (Vec3f::ZERO, Vec3f::X);
        let fan = [[a, b, Vec3f::Y], [b, a, Vec3f::Z], [a, b, -Vec3f::Y]];
        let topo = Topology::of(&Bvh::build(&fan));
        assert_eq!(topo.edges.len(), 3 * 3 - 1);
        assert_eq!(topo.edges.iter().filter(|e| e.t2 != NO_TRI).count(), 1);
    }
}
