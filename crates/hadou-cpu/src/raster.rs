//! The opaque pass: a deterministic scanline-free triangle rasterizer with a depth buffer, the
//! inverted-hull outlines (000 §2.3), and surface shading (`crate::shading`: the materials and the
//! waves as lights).
//!
//! Conventions (the GPU backend's raster pass matches them): pixel `(px, py)` has its centre at
//! `(px + ½, py + ½)`, `py = 0` is the top row; projection from [`CameraBasis`]; triangles are
//! clipped at the near plane in view space, drawn double-sided, with the top-left fill rule;
//! the depth test is `z < stored z` in submission order, so ties keep the earlier triangle and
//! the result does not depend on the number of threads. Every object's triangles come first, then
//! the outline hulls, of which only the back faces are drawn.

use crate::shading::{self, FrameLights};
use crate::shadows::{FrameShadows, NO_SHADOW};
use crate::soft::SoftPoint;
use hadou_math::{Vec3, Vec3f};
use hadou_scene::ShadowMethod;
use hadou_scene::{CameraBasis, Frame};
use rayon::prelude::*;

/// Rows per parallel band.
pub(crate) const BAND: usize = 16;

/// One vertex after transform: view-space position (for clipping/projection) and world-space
/// attributes (for shading).
#[derive(Clone, Copy, Debug)]
struct Vert {
    view: Vec3f,
    world: Vec3f,
    normal: Vec3f,
    uv: [f32; 2],
    color: [f32; 4],
}

/// A projected triangle ready to rasterize.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ScreenTri {
    /// Continuous screen coordinates (x right, y down).
    sx: [f32; 3],
    sy: [f32; 3],
    /// `1 / view z` per vertex.
    inv_z: [f32; 3],
    world: [Vec3f; 3],
    normal: [Vec3f; 3],
    uv: [[f32; 2]; 3],
    color: [[f32; 4]; 3],
    object: u32,
    /// Material slot of the object.
    material: u32,
    /// An outline hull triangle: drawn only where it faces away from the eye, in the outline
    /// colour.
    hull: bool,
}

impl ScreenTri {
    /// The view depth at screen barycentrics `w`: `1 / Σ wᵢ/zᵢ` (perspective-correct).
    #[inline]
    pub(crate) fn depth_at(&self, w: [f32; 3]) -> f32 {
        1.0 / (w[0] * self.inv_z[0] + w[1] * self.inv_z[1] + w[2] * self.inv_z[2])
    }

    /// A bare triangle in screen coordinates (for rasterizing shadow maps with [`cover`]).
    pub(crate) fn flat(sx: [f32; 3], sy: [f32; 3]) -> Self {
        ScreenTri {
            sx,
            sy,
            inv_z: [1.0; 3],
            world: [Vec3f::ZERO; 3],
            normal: [Vec3f::ZERO; 3],
            uv: [[0.0; 2]; 3],
            color: [[0.0; 4]; 3],
            object: 0,
            material: 0,
            hull: false,
        }
    }
}

/// What the opaque pass leaves per pixel.
#[derive(Default)]
pub(crate) struct OpaqueBuffers {
    /// Shaded linear RGB, background where nothing is drawn.
    pub color: Vec<[f32; 3]>,
    /// Eye distance to the visible surface, `None` where nothing is drawn.
    pub surface: Vec<Option<f32>>,
    /// Index into `frame.objects` of the visible object, if any.
    pub object: Vec<Option<u32>>,
    /// Index into `frame.shadows` of the shadow the pixel takes, if any.
    pub shadow: Vec<Option<u32>>,
    /// With an `[area_light]`: each pixel's visible point for the soft shadows (`None` for the
    /// background and outline hulls); empty without one.
    pub soft: Vec<Option<SoftPoint>>,
    /// The soft-shadow visibility per pixel once resolved (empty before, and without an area
    /// light).
    pub visibility: Vec<f32>,
}

/// Runs the opaque pass over the frame's rows `rows` (0 = top); the buffers hold those rows only.
/// Every pixel is decided by the triangles covering it alone, so a pixel's result does not depend
/// on which rows are drawn with it.
///
/// Shadows (`[[shadow]]`) darken the shaded colour of receiver pixels here, before the waves:
/// [`FrameShadows::resolve`] picks, per pixel, the cast of largest opacity among the plane casts
/// whose projected casters cover the pixel and the map casts whose map shadows it.
pub(crate) fn draw_opaque(
    frame: &Frame,
    basis: &CameraBasis,
    lights: &FrameLights,
    shadows: &FrameShadows,
    rows: std::ops::Range<usize>,
) -> OpaqueBuffers {
    let mut out = OpaqueBuffers::default();
    draw_opaque_into(frame, basis, lights, shadows, rows, &mut out);
    out
}

/// Resizes `v` to `n` copies of `x`, reusing its allocation (every element is rewritten, so a
/// reused buffer costs a fill, not fresh pages).
fn refill<T: Clone>(v: &mut Vec<T>, n: usize, x: T) {
    v.clear();
    v.resize(n, x);
}

/// [`draw_opaque`] into `out`, reusing its buffers' allocations from an earlier frame. Bands of
/// rows that no triangle or shadow touches are filled with the background without further work.
pub(crate) fn draw_opaque_into(
    frame: &Frame,
    basis: &CameraBasis,
    lights: &FrameLights,
    shadows: &FrameShadows,
    rows: std::ops::Range<usize>,
    out: &mut OpaqueBuffers,
) {
    let (w, h) = (frame.width as usize, rows.len());
    let tris = project_all(frame, basis);
    let shadow_tris = if shadows.any_plane() { project_shadows(frame, basis, shadows) } else { Vec::new() };
    let far = frame.camera.far;
    let bins = bin_rows(&tris, frame.height as usize, &rows);
    let shadow_bins = bin_rows(&shadow_tris, frame.height as usize, &rows);
    let OpaqueBuffers { color, surface, object, shadow, soft, visibility } = out;
    // Every element is written below: the fills only size the buffers.
    refill(color, w * h, [0.0f32; 3]);
    refill(surface, w * h, None);
    refill(object, w * h, None);
    refill(shadow, w * h, None);
    visibility.clear();
    let area = frame.area_light.as_ref();
    refill(soft, if area.is_some() { w * h } else { 0 }, None);
    if w * h == 0 {
        return;
    }
    // Without an area light every band gets an empty slice.
    let soft_chunks: Vec<&mut [Option<SoftPoint>]> = if area.is_some() {
        soft.chunks_mut(BAND * w).collect()
    } else {
        (0..h.div_ceil(BAND)).map(|_| Default::default()).collect()
    };
    color
        .par_chunks_mut(BAND * w)
        .zip(surface.par_chunks_mut(BAND * w))
        .zip(object.par_chunks_mut(BAND * w))
        .zip(shadow.par_chunks_mut(BAND * w))
        .zip(soft_chunks.into_par_iter())
        .enumerate()
        .for_each(|(b, ((((col, surf), obj), shad), soft))| {
            let y_start = rows.start + b * BAND;
            let rows = col.len() / w;
            if bins[b].is_empty() && shadow_bins[b].is_empty() {
                // Nothing drawn here (the refills left surface, object, shadow and soft empty).
                col.fill(frame.background);
                return;
            }
            let mut zbuf = vec![f32::INFINITY; rows * w];
            let mut tri_id = vec![u32::MAX; rows * w];
            for &ti in &bins[b] {
                raster_tri(&tris[ti as usize], ti, y_start, rows, w, far, &mut zbuf, &mut tri_id);
            }
            // The visible surface of every pixel.
            let mut visible: Vec<Option<shading::Surface>> = vec![None; rows * w];
            for r in 0..rows {
                for x in 0..w {
                    let i = r * w + x;
                    if tri_id[i] == u32::MAX {
                        continue;
                    }
                    let py = (y_start + r) as f32;
                    let s = interpolate(&tris[tri_id[i] as usize], x as f32 + 0.5, py + 0.5);
                    let d = (s.world - basis.eye).length();
                    surf[i] = Some(if d.is_finite() { d } else { 0.0 });
                    obj[i] = Some(tris[tri_id[i] as usize].object);
                    visible[i] = Some(s);
                }
            }
            // Shadows: the receiver pixels each cast darkens, the largest opacity winning.
            let mut best = vec![NO_SHADOW; rows * w];
            let receiver = |i: usize| {
                let t = tris.get(tri_id[i] as usize)?;
                (!t.hull).then_some(t.object)
            };
            for &si in &shadow_bins[b] {
                let st = &shadow_tris[si as usize];
                cover(st, y_start, rows, w, |i, bary| {
                    let (Some(o), Some(s)) = (receiver(i), visible[i].as_ref()) else { return };
                    let t = perspective(st, bary, |k| st.uv[k][0]);
                    shadows.plane_candidate(
                        frame,
                        st.object,
                        o,
                        t,
                        s.world,
                        surf[i].unwrap_or(0.0),
                        &mut best[i],
                    );
                });
            }
            for r in 0..rows {
                for x in 0..w {
                    let i = r * w + x;
                    let Some(s) = visible[i].as_ref() else {
                        col[i] = frame.background;
                        continue;
                    };
                    let t = &tris[tri_id[i] as usize];
                    let material = frame.objects[t.object as usize].material(t.material);
                    let c = match (t.hull, material.outline) {
                        (true, Some(o)) => o.color,
                        _ => shading::shade(frame, lights, material, s),
                    };
                    if t.hull {
                        col[i] = c;
                    } else {
                        (col[i], shad[i]) = shadows.resolve(frame, t.object, s.world, best[i], c);
                        if let Some(al) = area {
                            soft[i] = Some(SoftPoint {
                                world: s.world,
                                normal: s.normal.normalize_or(Vec3f::ZERO),
                                term: shading::area_term(al, material, s),
                            });
                        }
                    }
                }
            }
        });
}

/// For each band of `BAND` rows of `rows`, the triangles that may cover it, in submission order.
pub(crate) fn bin_rows(tris: &[ScreenTri], height: usize, rows: &std::ops::Range<usize>) -> Vec<Vec<u32>> {
    let h = rows.len();
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); h.div_ceil(BAND)];
    for (i, t) in tris.iter().enumerate() {
        let (y0, y1) = y_range(t, height);
        let (y0, y1) = (y0.max(rows.start), y1.min(rows.end.saturating_sub(1)));
        if y0 > y1 || h == 0 {
            continue;
        }
        for bin in &mut bins[((y0 - rows.start) / BAND)..=((y1 - rows.start) / BAND)] {
            bin.push(i as u32);
        }
    }
    bins
}

fn project_all(frame: &Frame, basis: &CameraBasis) -> Vec<ScreenTri> {
    let screen = ScreenProjection::new(frame, basis);
    let mut out = Vec::new();
    for (oi, obj) in frame.objects.iter().enumerate() {
        let nm = obj.transform.normal_matrix();
        let mesh = &obj.mesh;
        let verts: Vec<Vert> = (0..mesh.positions.len())
            .map(|i| {
                let world = obj.transform.transform_point(Vec3::from_array(mesh.positions[i]));
                let normal =
                    nm.transform_vector(Vec3::from_array(mesh.normals.get(i).copied().unwrap_or([0.0; 3])));
                Vert {
                    view: basis.to_view(world),
                    world,
                    normal,
                    uv: mesh.uvs.get(i).copied().unwrap_or([0.0; 2]),
                    color: mesh.colors.get(i).copied().unwrap_or([1.0; 4]),
                }
            })
            .collect();
        // The outline hull (000 §2.3): each vertex pushed along its world-space outline normal
        // by `d·|z|` (`z` its view depth), which is `R' = R + d·|R_z|·U` in view space.
        let outlined = obj.materials.iter().any(|m| m.outline.is_some_and(|o| o.width > 0.0));
        let hull: Vec<Vert> = if outlined {
            verts
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    let width = obj.material(mesh.material_of(i)).outline.map_or(0.0, |o| o.width);
                    let dir =
                        mesh.outline_normals.get(i).or(mesh.normals.get(i)).copied().unwrap_or([0.0; 3]);
                    let u = nm.transform_vector(Vec3::from_array(dir)).normalize_or(Vec3f::ZERO);
                    let world = v.world + u * (width * v.view.z.abs());
                    Vert { view: basis.to_view(world), world, ..*v }
                })
                .collect()
        } else {
            Vec::new()
        };
        let passes: &[(&[Vert], bool)] =
            if outlined { &[(&verts, false), (&hull, true)] } else { &[(&verts, false)] };
        for &(verts, is_hull) in passes {
            for tri in mesh.indices.chunks_exact(3) {
                let v = [tri[0], tri[1], tri[2]].map(|i| verts.get(i as usize).copied());
                let [Some(a), Some(b), Some(c)] = v else { continue };
                let material = mesh.material_of(tri[0] as usize);
                if is_hull
                    && obj.material(material).outline.is_none_or(|o| o.width.is_nan() || o.width <= 0.0)
                {
                    continue;
                }
                screen.push([a, b, c], oi as u32, material, is_hull, &mut out);
            }
        }
    }
    out
}

/// The triangles of the objects `casters` (not the outline hulls) as seen from one of 003's soft-shadow maps:
/// clipped at the map's near plane and projected to texel coordinates of a `size²` map (texel
/// `(x, y)` covers `[x, x+1) × [y, y+1)`, row 0 at the frustum's top), `1/z` per vertex for the
/// perspective-correct depth ([`ScreenTri::inv_z_at`]).
pub(crate) fn spot_tris(
    frame: &Frame,
    casters: &[u32],
    map: &hadou_math::soft::SpotMap,
    size: u32,
) -> Vec<ScreenTri> {
    let n = size as f32;
    let scale = 1.0 / map.tan_half;
    let mut out = Vec::new();
    for obj in casters.iter().filter_map(|&c| frame.objects.get(c as usize)) {
        let verts: Vec<Vert> = obj
            .mesh
            .positions
            .iter()
            .map(|p| {
                let world = obj.transform.transform_point(Vec3::from_array(*p));
                Vert { view: map.to_view(world), world, normal: Vec3f::ZERO, uv: [0.0; 2], color: [0.0; 4] }
            })
            .collect();
        for tri in obj.mesh.indices.chunks_exact(3) {
            let v = [tri[0], tri[1], tri[2]].map(|i| verts.get(i as usize).copied());
            let [Some(a), Some(b), Some(c)] = v else { continue };
            let mut poly = [a; 4];
            let k = clip_near([a, b, c], map.near, &mut poly);
            for j in 1..k.saturating_sub(1) {
                let pv = [poly[0], poly[j], poly[j + 1]];
                let mut t = ScreenTri::flat([0.0; 3], [0.0; 3]);
                let mut ok = true;
                for (m, v) in pv.iter().enumerate() {
                    let iz = 1.0 / v.view.z;
                    t.inv_z[m] = iz;
                    t.sx[m] = (v.view.x * iz * scale + 1.0) * 0.5 * n;
                    t.sy[m] = (1.0 - v.view.y * iz * scale) * 0.5 * n;
                    ok &= t.sx[m].is_finite() && t.sy[m].is_finite() && iz.is_finite();
                }
                if ok {
                    out.push(t);
                }
            }
        }
    }
    out
}

/// The camera projection of view-space triangles to [`ScreenTri`]s, clipped at the near plane.
struct ScreenProjection {
    near: f32,
    w: f32,
    h: f32,
    sx_scale: f32,
    sy_scale: f32,
}

impl ScreenProjection {
    fn new(frame: &Frame, basis: &CameraBasis) -> Self {
        ScreenProjection {
            near: frame.camera.near,
            w: frame.width as f32,
            h: frame.height as f32,
            sx_scale: 1.0 / (basis.tan_half_fov * basis.aspect),
            sy_scale: 1.0 / basis.tan_half_fov,
        }
    }

    /// Clips `tri` at the near plane and appends the projected pieces to `out`.
    fn push(&self, tri: [Vert; 3], object: u32, material: u32, hull: bool, out: &mut Vec<ScreenTri>) {
        let mut poly = [tri[0]; 4];
        let n = clip_near(tri, self.near, &mut poly);
        for k in 1..n.saturating_sub(1) {
            let pv = [poly[0], poly[k], poly[k + 1]];
            let mut t = ScreenTri {
                sx: [0.0; 3],
                sy: [0.0; 3],
                inv_z: [0.0; 3],
                world: pv.map(|v| v.world),
                normal: pv.map(|v| v.normal),
                uv: pv.map(|v| v.uv),
                color: pv.map(|v| v.color),
                object,
                material,
                hull,
            };
            let mut ok = true;
            for (j, v) in pv.iter().enumerate() {
                let iz = 1.0 / v.view.z;
                t.inv_z[j] = iz;
                t.sx[j] = (v.view.x * iz * self.sx_scale + 1.0) * 0.5 * self.w;
                t.sy[j] = (1.0 - v.view.y * iz * self.sy_scale) * 0.5 * self.h;
                ok &= t.sx[j].is_finite() && t.sy[j].is_finite() && iz.is_finite();
            }
            if ok {
                out.push(t);
            }
        }
    }
}

/// The plane casts' projected casters (001's flattened copies, 000 §2.4's shadow models): every
/// caster vertex `P` moved to `G = P + t·k` on the cast's plane
/// ([`hadou_math::shadow::project`]), with `t` carried in `uv[0]` for the per-pixel `t ≥ 0` test
/// (interpolated perspective-correctly, exact because `t` is affine on the projected triangle) and
/// the cast's index in `object`. Drawn double-sided.
fn project_shadows(frame: &Frame, basis: &CameraBasis, shadows: &FrameShadows) -> Vec<ScreenTri> {
    let screen = ScreenProjection::new(frame, basis);
    let mut out = Vec::new();
    for (ci, cast) in shadows.casts.iter().enumerate() {
        let ShadowMethod::Plane(plane) = frame.shadows[cast.shadow as usize].method else { continue };
        for &o in &cast.casters {
            let obj = &frame.objects[o as usize];
            let mesh = &obj.mesh;
            let verts: Vec<Vert> = mesh
                .positions
                .iter()
                .map(|p| {
                    let world = obj.transform.transform_point(Vec3::from_array(*p));
                    let (g, t) = hadou_math::shadow::project(world, cast.k, &plane);
                    Vert {
                        view: basis.to_view(g),
                        world: g,
                        normal: Vec3f::ZERO,
                        uv: [t, 0.0],
                        color: [0.0; 4],
                    }
                })
                .collect();
            for tri in mesh.indices.chunks_exact(3) {
                let v = [tri[0], tri[1], tri[2]].map(|i| verts.get(i as usize).copied());
                let [Some(a), Some(b), Some(c)] = v else { continue };
                screen.push([a, b, c], ci as u32, 0, false, &mut out);
            }
        }
    }
    out
}

/// Sutherland–Hodgman against the plane `z = near` (keeping `z ≥ near`). Returns the vertex count
/// (0, 3 or 4) written to `out`.
fn clip_near(tri: [Vert; 3], near: f32, out: &mut [Vert; 4]) -> usize {
    let mut n = 0;
    for i in 0..3 {
        let a = tri[i];
        let b = tri[(i + 1) % 3];
        let ina = a.view.z >= near;
        let inb = b.view.z >= near;
        if ina {
            out[n] = a;
            n += 1;
        }
        if ina != inb {
            let s = (near - a.view.z) / (b.view.z - a.view.z);
            let lerp = |p: Vec3f, q: Vec3f| p + (q - p) * s;
            let mix = |p: f32, q: f32| p + (q - p) * s;
            let mut v = Vert {
                view: lerp(a.view, b.view),
                world: lerp(a.world, b.world),
                normal: lerp(a.normal, b.normal),
                uv: std::array::from_fn(|k| mix(a.uv[k], b.uv[k])),
                color: std::array::from_fn(|k| mix(a.color[k], b.color[k])),
            };
            v.view.z = near;
            if n < 4 {
                out[n] = v;
                n += 1;
            }
        }
    }
    n
}

/// Rows (inclusive) whose pixel centres the triangle may cover, clamped to the image.
fn y_range(t: &ScreenTri, h: usize) -> (usize, usize) {
    let lo = t.sy[0].min(t.sy[1]).min(t.sy[2]);
    let hi = t.sy[0].max(t.sy[1]).max(t.sy[2]);
    if hi < 0.0 || lo > h as f32 {
        return (1, 0);
    }
    let y0 = (lo - 0.5).ceil().max(0.0) as usize;
    let y1 = ((hi - 0.5).floor().min(h as f32 - 1.0)).max(0.0) as usize;
    (y0, y1)
}

/// Twice the signed area of `(a, b, p)`.
#[inline(always)]
fn edge(ax: f32, ay: f32, bx: f32, by: f32, px: f32, py: f32) -> f32 {
    (bx - ax) * (py - ay) - (by - ay) * (px - ax)
}

/// Whether an edge owns pixel centres lying exactly on it (the top-left rule, for the triangle
/// orientation given by `sign`).
#[inline(always)]
fn owns_boundary(ax: f32, ay: f32, bx: f32, by: f32, sign: f32) -> bool {
    let (dx, dy) = ((bx - ax) * sign, (by - ay) * sign);
    // With y down and positive orientation: a top edge is horizontal going right... expressed
    // for the normalised (positive) orientation.
    (dy == 0.0 && dx > 0.0) || dy < 0.0
}

#[allow(clippy::too_many_arguments)] // a hot inner routine: plain slices beat a bundling struct
fn raster_tri(
    t: &ScreenTri,
    id: u32,
    y_start: usize,
    rows: usize,
    w: usize,
    far: f32,
    zbuf: &mut [f32],
    tri_id: &mut [u32],
) {
    // With y down, a triangle counter-clockwise seen from the eye (a front face) has area < 0;
    // a hull shows only its back faces.
    if t.hull && edge(t.sx[0], t.sy[0], t.sx[1], t.sy[1], t.sx[2], t.sy[2]) < 0.0 {
        return;
    }
    cover(t, y_start, rows, w, |i, b| {
        let iz = b[0] * t.inv_z[0] + b[1] * t.inv_z[1] + b[2] * t.inv_z[2];
        let z = 1.0 / iz;
        if z < zbuf[i] && z <= far {
            zbuf[i] = z;
            tri_id[i] = id;
        }
    });
}

/// Calls `f(i, b)` for every pixel centre of the rows `y_start..y_start + rows` (`i` indexing a
/// `rows × w` buffer) that `t` covers under the top-left rule, with the screen-space barycentric
/// weights `b` of the centre. Degenerate (zero-area or non-finite) triangles cover nothing.
#[inline(always)]
pub(crate) fn cover(
    t: &ScreenTri,
    y_start: usize,
    rows: usize,
    w: usize,
    mut f: impl FnMut(usize, [f32; 3]),
) {
    let area = edge(t.sx[0], t.sy[0], t.sx[1], t.sy[1], t.sx[2], t.sy[2]);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let sign = area.signum();
    let inv_area = 1.0 / area;
    let xmin = t.sx[0].min(t.sx[1]).min(t.sx[2]);
    let xmax = t.sx[0].max(t.sx[1]).max(t.sx[2]);
    if xmax < 0.0 || xmin > w as f32 {
        return;
    }
    let x0 = (xmin - 0.5).ceil().max(0.0) as usize;
    let x1 = ((xmax - 0.5).floor()).min(w as f32 - 1.0);
    if x1 < 0.0 {
        return;
    }
    let x1 = x1 as usize;
    let ylo = t.sy[0].min(t.sy[1]).min(t.sy[2]);
    let yhi = t.sy[0].max(t.sy[1]).max(t.sy[2]);
    let own = [
        owns_boundary(t.sx[1], t.sy[1], t.sx[2], t.sy[2], sign),
        owns_boundary(t.sx[2], t.sy[2], t.sx[0], t.sy[0], sign),
        owns_boundary(t.sx[0], t.sy[0], t.sx[1], t.sy[1], sign),
    ];
    // Only the rows whose centres may lie within [ylo, yhi] (the test below still decides).
    let r0 = ((ylo - 0.5).ceil() - y_start as f32 - 1.0).max(0.0) as usize;
    let r1 = ((yhi - 0.5).floor() - y_start as f32 + 2.0).clamp(0.0, rows as f32) as usize;
    for r in r0..r1 {
        let py = (y_start + r) as f32 + 0.5;
        if py < ylo || py > yhi {
            continue;
        }
        // The row's span of the triangle, widened by a pixel against rounding: only its pixels
        // are tested (the exact edge tests below decide), so long thin triangles cost their
        // area, not their bounding box.
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let (ay, by) = (t.sy[a], t.sy[b]);
            if (ay <= py && py <= by) || (by <= py && py <= ay) {
                let x = if ay == by {
                    lo = lo.min(t.sx[a].min(t.sx[b]));
                    t.sx[a].max(t.sx[b])
                } else {
                    t.sx[a] + (py - ay) * ((t.sx[b] - t.sx[a]) / (by - ay))
                };
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
        if lo.partial_cmp(&hi) == Some(std::cmp::Ordering::Greater) || lo.is_nan() || hi.is_nan() {
            continue;
        }
        let xs = ((lo - 1.5).ceil().max(x0 as f32)) as usize;
        let xe = ((hi + 0.5).floor().min(x1 as f32)).max(-1.0);
        if xe < xs as f32 {
            continue;
        }
        for x in xs..=xe as usize {
            let px = x as f32 + 0.5;
            let e0 = edge(t.sx[1], t.sy[1], t.sx[2], t.sy[2], px, py) * sign;
            let e1 = edge(t.sx[2], t.sy[2], t.sx[0], t.sy[0], px, py) * sign;
            let e2 = edge(t.sx[0], t.sy[0], t.sx[1], t.sy[1], px, py) * sign;
            let inside = |e: f32, o: bool| e > 0.0 || (e == 0.0 && o);
            if !(inside(e0, own[0]) && inside(e1, own[1]) && inside(e2, own[2])) {
                continue;
            }
            f(r * w + x, [e0 * inv_area * sign, e1 * inv_area * sign, e2 * inv_area * sign]);
        }
    }
}

/// A per-vertex attribute at screen barycentrics `b`, interpolated perspective-correctly.
#[inline]
fn perspective(t: &ScreenTri, b: [f32; 3], attr: impl Fn(usize) -> f32) -> f32 {
    let wts = [b[0] * t.inv_z[0], b[1] * t.inv_z[1], b[2] * t.inv_z[2]];
    let s = wts[0] + wts[1] + wts[2];
    (wts[0] * attr(0) + wts[1] * attr(1) + wts[2] * attr(2)) / s
}

/// Perspective-correct surface attributes at screen point `(px, py)`.
fn interpolate(t: &ScreenTri, px: f32, py: f32) -> shading::Surface {
    let area = edge(t.sx[0], t.sy[0], t.sx[1], t.sy[1], t.sx[2], t.sy[2]);
    let b = [
        edge(t.sx[1], t.sy[1], t.sx[2], t.sy[2], px, py) / area,
        edge(t.sx[2], t.sy[2], t.sx[0], t.sy[0], px, py) / area,
        edge(t.sx[0], t.sy[0], t.sx[1], t.sy[1], px, py) / area,
    ];
    let wts = [b[0] * t.inv_z[0], b[1] * t.inv_z[1], b[2] * t.inv_z[2]];
    let s = wts[0] + wts[1] + wts[2];
    let wts = wts.map(|v| v / s);
    let world = t.world[0] * wts[0] + t.world[1] * wts[1] + t.world[2] * wts[2];
    let normal = t.normal[0] * wts[0] + t.normal[1] * wts[1] + t.normal[2] * wts[2];
    let uv = std::array::from_fn(|k| t.uv[0][k] * wts[0] + t.uv[1][k] * wts[1] + t.uv[2][k] * wts[2]);
    let color =
        std::array::from_fn(|k| t.color[0][k] * wts[0] + t.color[1][k] * wts[1] + t.color[2][k] * wts[2]);
    shading::Surface { world, normal, uv, color }
}
