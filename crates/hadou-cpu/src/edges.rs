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

use crate::opaque::{expand, OpaqueBuffers, HULL, NONE};
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

/// An edge pixel of an outlined object, with what the pixels that take its outline read of it
/// (copied, so that bands can write their own rows while others still read their edges).
#[derive(Clone, Copy)]
struct Edge {
    x: u32,
    /// Its reach in pixels, squared.
    reach2: f32,
    object: u32,
    /// The material slot of its surface.
    material: u32,
    distance: f32,
    /// The unit ray through it.
    dir: Vec3f,
}

/// Rows of the image one task of the edge pass decides.
const EDGE_BAND: usize = 16;

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
    let OpaqueBuffers { color, surface, object, shadow, normal, material, reach: reaches, once, .. } = out;
    // A surface pixel's object (hulls and the background: none).
    let owner = |i: usize| match (surface[i].is_finite(), material[i] & HULL != 0) {
        (true, false) if object[i] != NONE => Some(object[i]),
        _ => None,
    };
    // Each row's edge pixels, in order of x.
    let edges: Vec<Vec<Edge>> = (0..h)
        .into_par_iter()
        .map(|r| {
            let mut row = Vec::new();
            for x in 0..w {
                let i = r * w + x;
                // (The reach tested first: it is 0 for hulls, the background and every pixel of a
                // surface without an outline or not on its edge.)
                let code = u32::from(reaches[i]);
                if code == 0 {
                    continue;
                }
                let material = material[i];
                let Some(o) = owner(i) else { continue };
                // Neighbours outside the buffers count as the same object. (Tested first: most
                // pixels of an outlined surface are not on its edge.)
                let differs = |j: usize| owner(j) != Some(o);
                let on_edge = (x > 0 && differs(i - 1))
                    || (x + 1 < w && differs(i + 1))
                    || (r > 0 && differs(i - w))
                    || (r + 1 < h && differs(i + w));
                if !on_edge {
                    continue;
                }
                let dir = unit_dir(basis, frame, x, r + first_row);
                let z = surface[i] * dir.dot(basis.forward);
                let px = hull_px(o, material, z);
                let rp = reach_pixels(px, code);
                if rp.is_nan() || rp <= 0.0 {
                    continue;
                }
                let distance = surface[i];
                row.push(Edge { x: x as u32, reach2: rp * rp, object: o, material, distance, dir });
            }
            row
        })
        .collect();
    if edges.iter().all(|r| r.is_empty()) {
        return;
    }
    // Each pixel's winning edge pixel, if any, band by band: every edge pixel within the search
    // window of the band's rows visits the pixels of its window in the band (a scatter: the
    // window's pixels far outnumber the edge pixels that reach them), in row-major order, so that
    // of equally near edge pixels the first in row-major order wins.
    let edges = &edges;
    // Pixels whose samples take their centre colour unwritten (`ShadedOnce::centred`): a band's
    // `EDGE_BAND / grid` rows of them (every band gets an empty slice where none is marked).
    let grid = once.grid.max(1);
    let pw = w / grid;
    let marks: Vec<&mut [bool]> = if once.centred.is_empty() {
        (0..h.div_ceil(EDGE_BAND)).map(|_| Default::default()).collect()
    } else {
        once.centred.chunks_mut(EDGE_BAND / grid * pw).collect()
    };
    let centre = &once.centre;
    color
        .par_chunks_mut(EDGE_BAND * w)
        .zip(surface.par_chunks(EDGE_BAND * w))
        .zip(object.par_chunks_mut(EDGE_BAND * w))
        .zip(shadow.par_chunks_mut(EDGE_BAND * w))
        .zip(normal.par_chunks(EDGE_BAND * w))
        .zip(material.par_chunks_mut(EDGE_BAND * w))
        .zip(reaches.par_chunks_mut(EDGE_BAND * w))
        .zip(marks)
        .enumerate()
        .for_each(
            |(band, (((((((color, surface), object), shadow), normal), material), reaches), marks))| {
                let y0 = band * EDGE_BAND;
                let rows = surface.len() / w;
                let owner = |i: usize| match (surface[i].is_finite(), material[i] & HULL != 0) {
                    (true, false) if object[i] != NONE => Some(object[i]),
                    _ => None,
                };
                let window =
                    || edges.iter().enumerate().take(y0 + rows + reach).skip(y0.saturating_sub(reach));
                if window().all(|(_, row)| row.is_empty()) {
                    return;
                }
                // Per pixel: the winning edge's eye distance and (row, index in its row); kept by the
                // thread from band to band (all `None` between bands: only the pixels listed in
                // `touched` are set, and reset after), since most of a band's pixels are never reached.
                let mut scratch = EDGE_SCRATCH.take();
                let (best, touched) = &mut scratch;
                best.resize(rows * w, None);
                for (rr, row) in window() {
                    // The band's rows within the window of the edge pixels of row `rr`.
                    let r_lo = rr.saturating_sub(reach).max(y0);
                    let r_hi = (rr + reach + 1).min(y0 + rows);
                    for (k, e) in row.iter().enumerate() {
                        let ex = e.x as usize;
                        let (x_lo, x_hi) = (ex.saturating_sub(reach), (ex + reach + 1).min(w));
                        for r in r_lo..r_hi {
                            let dy = r as f32 - rr as f32;
                            for x in x_lo..x_hi {
                                let dx = x as f32 - ex as f32;
                                if dx * dx + dy * dy > e.reach2 {
                                    continue;
                                }
                                let i = (r - y0) * w + x;
                                let Some(b) = owner(i) else { continue };
                                if b == e.object || best[i].is_some_and(|(d, _, _)| e.distance >= d) {
                                    continue;
                                }
                                let p_dir = unit_dir(basis, frame, x, first_row + r);
                                let p_dist = surface[i];
                                if in_front(normal[i], p_dir, p_dist, e.dir, e.distance) {
                                    if best[i].is_none() {
                                        touched.push(i as u32);
                                    }
                                    best[i] = Some((e.distance, rr as u32, k as u32));
                                }
                            }
                        }
                    }
                }
                for &i in touched.iter() {
                    let i = i as usize;
                    let Some((_, rr, k)) = best[i].take() else { continue };
                    let e = &edges[rr as usize][k as usize];
                    let mat = frame.objects[e.object as usize].material(e.material);
                    if mat.outline.is_some() {
                        // The sample's pixel's samples written first where they are not.
                        if !marks.is_empty() {
                            let (pr, px) = (i / w / grid, i % w / grid);
                            let p = pr * pw + px;
                            let rows = pr * grid * w..(pr + 1) * grid * w;
                            let c = centre[band * (EDGE_BAND / grid) * pw + p];
                            expand(
                                &mut marks[p],
                                c,
                                grid,
                                w,
                                px,
                                &mut color[rows.clone()],
                                &mut shadow[rows],
                            );
                        }
                        color[i] = mat.outline_rgb(&frame.light);
                        shadow[i] = NONE;
                        // The pixel now shows that object's outline, as a hull pixel of it would (the
                        // GPU's edge pass writes its material word | HULL_BIT): what the probe names
                        // and what the anti-aliased resolve compares.
                        object[i] = e.object;
                        (material[i], reaches[i]) = (e.material | HULL, 0);
                    }
                }
                touched.clear();
                EDGE_SCRATCH.set(scratch);
            },
        );
}

/// The per-pixel winners of the edge pass's bands and the pixels they set.
type EdgeScratch = (Vec<Option<(f32, u32, u32)>>, Vec<u32>);

thread_local! {
    /// Each thread's [`EdgeScratch`], kept from band to band (its winners all `None` between).
    static EDGE_SCRATCH: std::cell::Cell<EdgeScratch> = const { std::cell::Cell::new((Vec::new(), Vec::new())) };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::opaque::light_from_front_drawn;
    use crate::setup::FrameSetup;

    /// Issue 44, point 1: a pixel shaded once whose samples take its centre colour unwritten
    /// (`ShadedOnce::centred`) has its samples written before the edge pass closes an outline
    /// over one of them: the closed sample shows the outline, its neighbours in the pixel the
    /// centre colour, and the pixel is no longer marked (the resolve reads its samples).
    #[test]
    fn outlines_closed_over_centred_pixels_write_their_samples() {
        let (_, sampled, mut out) = light_from_front_drawn();
        let setup = FrameSetup::new(&sampled);
        let h = sampled.height as usize;
        let (material, marked, centre) =
            (out.material.clone(), out.once.centred.clone(), out.once.centre.clone());
        assert!(marked.iter().filter(|&&m| m).count() > 1000, "few pixels centred");
        close_outlines(&sampled, &setup.basis, 0, &mut out);
        let w = sampled.width as usize;
        let pw = w / 2;
        let (mut closed, mut written) = (0, 0);
        for i in 0..w * h {
            if out.material[i] == material[i] || out.material[i] & HULL == 0 {
                continue;
            }
            let p = i / w / 2 * pw + i % w / 2;
            let o = &sampled.objects[out.object[i] as usize];
            let outline = o.material(out.material[i] & !HULL).outline_rgb(&sampled.light);
            assert_eq!(out.color[i], outline, "sample {i}: not the outline's colour");
            assert!(!out.once.centred[p], "pixel {p}: still marked after its sample {i} was closed");
            closed += 1;
            if !marked[p] {
                continue;
            }
            // Its pixel's other samples, untouched by the pass, hold the centre colour.
            let (r0, x0) = (i / w / 2 * 2, i % w / 2 * 2);
            for j in [r0 * w + x0, r0 * w + x0 + 1, (r0 + 1) * w + x0, (r0 + 1) * w + x0 + 1] {
                if out.material[j] == material[j] {
                    assert_eq!(out.color[j], centre[p], "sample {j} of pixel {p}");
                    assert_eq!(out.shadow[j], NONE, "sample {j} of pixel {p}");
                    written += 1;
                }
            }
        }
        assert!(closed > 0 && written > 0, "{closed} samples closed, {written} centred samples written");
    }
}
