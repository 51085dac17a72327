//! The edge pass: closed outlines where objects meet. After the opaque pass (and the area light's
//! term), every drawn pixel of a surface takes the outline colour of another object whose visible
//! edge lies within that object's outline width and in front of the pixel's surface
//! (`hadou_math::outline`, 000 §2.3): so the outline of a box standing on the ground, whose hull
//! is buried in the ground along its base, runs round the base at the width the hull has against
//! the sky. The hull keeps the silhouette against the background; the two are unioned.
//!
//! A pixel `p` (a surface, not a hull) takes the outline of pixel `q` when `q` shows another
//! object's surface with an outline, `q` is on that object's edge (a 4-neighbour in the image
//! shows something else), `|p − q|² ≤ r²` with `r` the hull's on-screen reach at `q`
//! (`reach_pixels`), and `q`'s point lies in front of the plane of `p`'s surface (`in_front`);
//! of several, the nearest `q` to the eye wins, ties to the first in row-major order. The GPU's
//! `shaders/edges.wgsl` is the twin.

use crate::opaque::{EdgeTexel, OpaqueBuffers};
use hadou_math::outline::{in_front, reach_pixels, reach_window};
use hadou_math::Vec3f;
use hadou_scene::{CameraBasis, Frame};
use rayon::prelude::*;

/// How far (in pixels) the edge pass looks for the frame's outlines: the widest outlined
/// material's hull width on screen, rounded up and capped (`reach_window`); 0 when nothing is
/// outlined.
pub(crate) fn frame_reach(frame: &Frame) -> u32 {
    reach_window(hadou_scene::widest_outline_pixels(frame))
}

/// The unit ray direction of pixel `(x, y)`.
fn unit_dir(basis: &CameraBasis, frame: &Frame, x: usize, y: usize) -> Vec3f {
    let d = basis.pixel_dir(x as f32, y as f32, frame.width, frame.height);
    d / d.length()
}

/// An edge pixel of an outlined object.
#[derive(Clone, Copy)]
struct Edge {
    x: u32,
    /// Its reach in pixels, squared.
    reach2: f32,
    object: u32,
    distance: f32,
    /// Index of its pixel in the buffers.
    index: usize,
}

/// Runs the edge pass over `out`, which holds the rows from `first_row` on. Rows within
/// [`frame_reach`]` + 1` of either end of the buffers (unless at the image's edge) see only part
/// of their neighbourhood: draw that many more rows than are kept.
pub(crate) fn close_outlines(frame: &Frame, basis: &CameraBasis, first_row: usize, out: &mut OpaqueBuffers) {
    let reach = frame_reach(frame) as usize;
    let w = frame.width as usize;
    if reach == 0 || w == 0 || out.surface.is_empty() {
        return;
    }
    let h = out.surface.len() / w;
    // The hull's width on screen at an edge pixel at view depth `z` (`Material::hull_pixels`).
    let hull_px = |o: u32, m: u32, z: f32| {
        frame.objects[o as usize].material(m).hull_pixels(z, basis.tan_half_fov, frame.height)
    };
    let OpaqueBuffers { color, surface, object, shadow, edge, .. } = out;
    // A surface pixel's object (hulls and the background: none).
    let owner = |i: usize| match (surface[i], edge[i].hull) {
        (Some(_), false) => object[i],
        _ => None,
    };
    // Each row's edge pixels, in order of x.
    let edges: Vec<Vec<Edge>> = (0..h)
        .into_par_iter()
        .map(|r| {
            let mut row = Vec::new();
            for x in 0..w {
                let i = r * w + x;
                let EdgeTexel { material, reach: code, .. } = edge[i];
                let Some(o) = owner(i) else { continue };
                if code == 0 {
                    continue;
                }
                let z =
                    surface[i].unwrap_or(0.0) * unit_dir(basis, frame, x, r + first_row).dot(basis.forward);
                let px = hull_px(o, material, z);
                let rp = reach_pixels(px, code);
                if rp.is_nan() || rp <= 0.0 {
                    continue;
                }
                // Neighbours outside the buffers count as the same object.
                let differs = |j: usize| owner(j) != Some(o);
                let on_edge = (x > 0 && differs(i - 1))
                    || (x + 1 < w && differs(i + 1))
                    || (r > 0 && differs(i - w))
                    || (r + 1 < h && differs(i + w));
                if on_edge {
                    let distance = surface[i].unwrap_or(0.0);
                    row.push(Edge { x: x as u32, reach2: rp * rp, object: o, distance, index: i });
                }
            }
            row
        })
        .collect();
    if edges.iter().all(|r| r.is_empty()) {
        return;
    }
    // Each pixel's winning edge pixel, if any: row by row, only the pixels within the search
    // window of some edge pixel searched (a difference array over the window's rows marks them).
    // Per row of edge pixels, the one object they all belong to (`None`: several, or none): a
    // pixel of that object skips the row, whose edges can only be its own.
    let sole: Vec<Option<u32>> = edges
        .iter()
        .map(|row| {
            let first = row.first()?.object;
            row.iter().all(|e| e.object == first).then_some(first)
        })
        .collect();
    let (surface_ro, edge_ro, edges_ro, sole) = (&*surface, &*edge, &edges, &sole);
    let owner = &owner;
    let wins: Vec<Option<usize>> = (0..h)
        .into_par_iter()
        .flat_map_iter(|r| {
            let (surface, edge, edges) = (surface_ro, edge_ro, edges_ro);
            let lo = r.saturating_sub(reach);
            let hi = (r + reach + 1).min(h);
            let mut near = vec![0i32; w + 1];
            for row in &edges[lo..hi] {
                for e in row {
                    near[(e.x as usize).saturating_sub(reach)] += 1;
                    near[(e.x as usize + reach + 1).min(w)] -= 1;
                }
            }
            let mut count = 0;
            let near: Vec<bool> = near[..w]
                .iter()
                .map(|d| {
                    count += d;
                    count > 0
                })
                .collect();
            (0..w).map(move |x| {
                let i = r * w + x;
                if !near[x] {
                    return None;
                }
                let b = owner(i)?;
                let y = first_row + r;
                let p_dir = unit_dir(basis, frame, x, y);
                let p_dist = surface[i].unwrap_or(0.0);
                let p_normal = edge[i].normal;
                let mut best: Option<(f32, usize)> = None;
                for (rr, row) in edges.iter().enumerate().take(hi).skip(lo) {
                    if sole[rr] == Some(b) {
                        continue;
                    }
                    let dy = rr as f32 - r as f32;
                    let start = row.partition_point(|e| (e.x as usize) + reach < x);
                    for e in &row[start..] {
                        if e.x as usize > x + reach {
                            break;
                        }
                        if e.object == b {
                            continue;
                        }
                        let dx = e.x as f32 - x as f32;
                        if dx * dx + dy * dy > e.reach2 {
                            continue;
                        }
                        if best.is_some_and(|(d, _)| e.distance >= d) {
                            continue;
                        }
                        let q_dir = unit_dir(basis, frame, e.x as usize, first_row + rr);
                        if in_front(p_normal, p_dir, p_dist, q_dir, e.distance) {
                            best = Some((e.distance, e.index));
                        }
                    }
                }
                best.map(|(_, q)| q)
            })
        })
        .collect();
    for (i, win) in wins.into_iter().enumerate() {
        let Some(q) = win else { continue };
        let (Some(o), m) = (object[q], edge[q].material) else { continue };
        let mat = frame.objects[o as usize].material(m);
        if mat.outline.is_some() {
            color[i] = mat.outline_rgb(&frame.light);
            shadow[i] = None;
            // The pixel now shows that object's outline, as a hull pixel of it would (the GPU's
            // edge pass writes its material word | HULL_BIT): what the probe names and what
            // the anti-aliased resolve compares.
            object[i] = Some(o);
            edge[i] = EdgeTexel { material: m, hull: true, reach: 0, ..edge[i] };
        }
    }
}
