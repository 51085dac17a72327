//! Hard shadows (`[[shadow]]`): the frame's projections ([`hadou_scene::Frame::shadow_casts`]),
//! their shadow maps, the plane casts' projected casters (which the opaque pass covers), and the
//! per-pixel choice of the shadow a receiver pixel takes ([`ShadowCasts`]). The GPU
//! backend mirrors this module: `shadow_raster.wgsl` (the plane-shadow pass and the map pass) and
//! `shadow_lookup.wgsl` (the choice per pixel, in the wave pass).
//!
//! A receiver pixel (visible, not an outline hull, its object among the shadow's receivers) takes
//! the cast of largest effective opacity among
//! - plane casts (001, 000 §2.4) whose projected casters cover the pixel centre with `t ≥ 0` while
//!   the visible point lies on the cast's plane (within [`ON_PLANE`]`·(1 + eye distance)`), and
//! - map casts whose orthographic map holds a caster nearer the light than the point by more than
//!   [`MapFrame::bias`],
//!
//! ties going to the earlier cast; its colour becomes `c + (shadow colour − c)·opacity`. Several
//! casters of one shadow therefore darken an overlap once, and a shadow shows only on its
//! receivers.

use crate::raster::{nearest_depths, Chunked, ScreenProjection, ScreenTri, Tris, Vert};
use hadou_math::shadow::MapFrame;
use hadou_math::{Vec3, Vec3f};
use hadou_scene::{CameraBasis, Frame, LightLine, ShadowCast, ShadowMethod, ON_PLANE};
use rayon::prelude::*;

/// A pixel's chosen cast: `(effective opacity, cast index)`.
pub(crate) type Choice = (f32, u32);
/// No shadow.
pub(crate) const NO_SHADOW: Choice = (0.0, u32::MAX);

/// An orthographic depth map of one map cast: `size²` depths in `[0, 1]`, 1 where no caster is.
pub(crate) struct DepthMap {
    frame: MapFrame,
    size: u32,
    depth: Vec<f32>,
}

/// The frame's shadow casts and the maps of its map casts.
pub(crate) struct ShadowCasts {
    /// In [`Frame::shadow_casts`] order.
    pub casts: Vec<ShadowCast>,
    /// One per cast (`None` for plane casts).
    maps: Vec<Option<DepthMap>>,
}

impl ShadowCasts {
    /// Computes the casts from the waves' light `lines` and renders every map.
    pub(crate) fn new(frame: &Frame, lines: &[LightLine]) -> Self {
        let casts = if frame.shadows.is_empty() { Vec::new() } else { frame.shadow_casts(lines) };
        let maps = casts
            .par_iter()
            .map(|c| match (c.map, frame.shadows[c.shadow as usize].method) {
                (Some(m), ShadowMethod::Map { size }) => Some(render_map(frame, c, m, size)),
                _ => None,
            })
            .collect();
        ShadowCasts { casts, maps }
    }

    /// Whether the frame casts any hard shadow.
    pub(crate) fn any(&self) -> bool {
        !self.casts.is_empty()
    }

    /// Whether any cast projects onto a plane.
    pub(crate) fn any_plane(&self) -> bool {
        self.maps.iter().any(Option::is_none)
    }

    /// The plane casts' projected casters (001's flattened copies, 000 §2.4's shadow models): every
    /// caster vertex `P` moved to `G = P + t·k` on the cast's plane
    /// ([`hadou_math::shadow::project`]), with `t` carried in `uv[0]` for the per-pixel `t ≥ 0` test
    /// (interpolated perspective-correctly, exact because `t` is affine on the projected triangle) and
    /// the cast's index in `object`. Drawn double-sided.
    pub(crate) fn plane_tris(&self, frame: &Frame, basis: &CameraBasis) -> Tris {
        let screen = ScreenProjection::new(frame, basis);
        let mut out = Tris::default();
        for (ci, cast) in self.casts.iter().enumerate() {
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
                            outline: Vec3f::ZERO,
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

    /// Plane cast `cast` covers a pixel whose visible object is `object`, point `world` at eye
    /// distance `dist`, with interpolated projection parameter `t`: updates `best` if the pixel
    /// receives it and it is more opaque (casts arrive in increasing order, so ties keep the
    /// earlier cast).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn plane_candidate(
        &self,
        frame: &Frame,
        cast: u32,
        object: u32,
        t: f32,
        world: Vec3f,
        dist: f32,
        best: &mut Choice,
    ) {
        let c = &self.casts[cast as usize];
        let s = &frame.shadows[c.shadow as usize];
        let ShadowMethod::Plane(plane) = s.method else { return };
        // `t ≥ 0` is false for a NaN too.
        let in_front = t >= 0.0;
        if !in_front || c.opacity <= best.0 || !s.receives(object) {
            return;
        }
        if plane.distance(world).abs() <= ON_PLANE * (1.0 + dist) {
            *best = (c.opacity, cast);
        }
    }

    /// The colour of a receiver pixel and the shadow it takes (an index into `frame.shadows`):
    /// the map casts are tested against `best` (the plane casts' choice), and the winner's colour
    /// is blended over `c`.
    pub(crate) fn resolve(
        &self,
        frame: &Frame,
        object: u32,
        world: Vec3f,
        mut best: Choice,
        c: [f32; 3],
    ) -> ([f32; 3], Option<u32>) {
        for (j, (cast, map)) in self.casts.iter().zip(&self.maps).enumerate() {
            let Some(map) = map else { continue };
            let j = j as u32;
            if cast.opacity < best.0 || (cast.opacity == best.0 && j > best.1) {
                continue;
            }
            if frame.shadows[cast.shadow as usize].receives(object) && map.shadows(world) {
                best = (cast.opacity, j);
            }
        }
        if best.1 == u32::MAX {
            return (c, None);
        }
        let si = self.casts[best.1 as usize].shadow;
        let s = &frame.shadows[si as usize];
        (std::array::from_fn(|k| c[k] + (s.color[k] - c[k]) * best.0), Some(si))
    }
}

impl DepthMap {
    /// Whether a caster lies between `p` and the light: the texel under `p` holds a depth below
    /// 1 (a caster) and `p` is deeper by more than [`MapFrame::bias`].
    #[inline]
    fn shadows(&self, p: Vec3f) -> bool {
        let [s, t, d] = self.frame.to_map(p);
        let n = self.size as f32;
        // `⌊v⌋` lies in `0..n` exactly when `v` does (`n` whole; NaN in neither), so the texel is
        // the truncation's (without a call to `floorf` on targets without SSE4.1).
        let (x, y) = (s * n, (1.0 - t) * n);
        if !(x >= 0.0 && y >= 0.0 && x < n && y < n) {
            return false;
        }
        let m = self.depth[y as usize * self.size as usize + x as usize];
        m < 1.0 && d > m + MapFrame::bias(self.size)
    }
}

/// Renders cast `c`'s casters into an orthographic depth map along `c.k`: texel `(x, y)` covers
/// `s ∈ [x/n, (x+1)/n)`, `1 − t ∈ [y/n, (y+1)/n)` (the GPU's viewport convention, row 0 at
/// `t = 1`), depth interpolated linearly, the nearest kept, double-sided, top-left rule.
fn render_map(frame: &Frame, c: &ShadowCast, m: MapFrame, size: u32) -> DepthMap {
    let n = size as usize;
    let nf = size as f32;
    let mut tris = Tris::default();
    let mut depths: Chunked<[f32; 3]> = Chunked::default();
    for &o in &c.casters {
        let obj = &frame.objects[o as usize];
        let pts: Vec<[f32; 3]> = obj
            .mesh
            .positions
            .iter()
            .map(|p| {
                let [s, t, d] = m.to_map(obj.transform.transform_point(Vec3::from_array(*p)));
                [s * nf, (1.0 - t) * nf, d]
            })
            .collect();
        for tri in obj.mesh.indices.chunks_exact(3) {
            let v = [tri[0], tri[1], tri[2]].map(|i| pts.get(i as usize).copied());
            let [Some(a), Some(b), Some(cc)] = v else { continue };
            tris.push(ScreenTri::flat([a[0], b[0], cc[0]], [a[1], b[1], cc[1]]));
            depths.push([a[2], b[2], cc[2]]);
        }
    }
    let depth = nearest_depths(&tris, n, 1.0, |ti, w| {
        let dz = depths[ti];
        w[0] * dz[0] + w[1] * dz[1] + w[2] * dz[2]
    });
    DepthMap { frame: m, size, depth }
}
