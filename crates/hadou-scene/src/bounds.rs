//! Where a frame's objects are: the world-space bounding box of an object's mesh
//! ([`object_bounds`]) and its centre `B` ([`object_center`]), as shadows and the area light use
//! them.

use crate::frame::{Frame, Mesh, Object};
use hadou_math::soft::CasterBox;
use hadou_math::{Vec3, Vec3f};

/// World-space axis-aligned bounds of an object's mesh: the 8 transformed corners of its local
/// bounds. `None` for an empty mesh.
pub fn object_bounds(o: &Object) -> Option<(Vec3f, Vec3f)> {
    let (lo, hi) = local_bounds(o)?;
    let mut w_lo = Vec3::splat(f32::INFINITY);
    let mut w_hi = Vec3::splat(f32::NEG_INFINITY);
    for c in box_corners(lo, hi) {
        let w = o.transform.transform_point(c);
        w_lo = w_lo.min(w);
        w_hi = w_hi.max(w);
    }
    Some((w_lo, w_hi))
}

/// The box a caster's mesh lies in, placed in the world (its local bounds under its transform, a
/// parallelepiped), as the area light's map fit tests it ([`CasterBox::blocks`]). A side of the
/// local bounds shorter than `10⁻⁶` of the longest (a flat mesh) is widened by that much on both
/// ends so that the box spans a volume; a transform that flattens it falls back to the
/// world-space bounds ([`object_bounds`]) so widened. `None` for an empty mesh or bounds that are not finite.
pub fn caster_box(o: &Object) -> Option<CasterBox> {
    let widen = |(lo, hi): (Vec3f, Vec3f)| {
        let e = hi - lo;
        let m = e.x.max(e.y).max(e.z);
        let pad = |x: f32| if x > 1e-6 * m { 0.0 } else { 1e-6 * m.max(1e-3) };
        let pad = Vec3::new(pad(e.x), pad(e.y), pad(e.z));
        (lo - pad, hi + pad)
    };
    let (lo, hi) = widen(local_bounds(o)?);
    let m = &o.transform;
    let e = hi - lo;
    let edges = [Vec3::new(e.x, 0.0, 0.0), Vec3::new(0.0, e.y, 0.0), Vec3::new(0.0, 0.0, e.z)];
    CasterBox::from_edges(m.transform_point(lo), edges.map(|v| m.transform_vector(v))).or_else(|| {
        let (lo, hi) = widen(object_bounds(o)?);
        let e = hi - lo;
        CasterBox::from_edges(
            lo,
            [Vec3::new(e.x, 0.0, 0.0), Vec3::new(0.0, e.y, 0.0), Vec3::new(0.0, 0.0, e.z)],
        )
    })
}

/// The centre `B` of a caster (000 §2.4's "model's centre"): the centre of its mesh's local
/// bounding box, placed in the world. `None` for an empty mesh.
pub fn object_center(o: &Object) -> Option<Vec3f> {
    let (lo, hi) = local_bounds(o)?;
    Some(o.transform.transform_point((lo + hi) * 0.5))
}

/// The 8 corners of the box `lo..hi`; corner `i` takes `hi` on the axes whose bit is set in `i`
/// (x: 1, y: 2, z: 4).
pub(crate) fn box_corners(lo: Vec3f, hi: Vec3f) -> [Vec3f; 8] {
    std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// The centre of a mesh's bounding box in its own space (`None` when it has no vertices).
pub(crate) fn mesh_center(mesh: &Mesh) -> Option<Vec3f> {
    let (lo, hi) = mesh_bounds(mesh)?;
    Some((lo + hi) * 0.5)
}

/// The object-space bounding box of an object's mesh (`None` when it has no vertices).
fn local_bounds(o: &Object) -> Option<(Vec3f, Vec3f)> {
    mesh_bounds(&o.mesh)
}

fn mesh_bounds(mesh: &Mesh) -> Option<(Vec3f, Vec3f)> {
    let mut it = mesh.positions.iter().map(|p| Vec3f::from_array(*p));
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

/// The widest outline hull on screen, in pixels, which the edge pass of both backends searches
/// around each pixel ([`crate::Material::hull_pixels`] of every outlined material; an MToon outline in
/// world units at the nearest view depth its object's surface can have, its bounding box's
/// nearest corner, at least the near plane).
pub fn widest_outline_pixels(frame: &Frame) -> f32 {
    let basis = frame.camera.basis(frame.width, frame.height);
    let mut widest = 0.0f32;
    for o in &frame.objects {
        for m in o.materials.iter().filter(|m| m.outline.is_some()) {
            let z = if m.outline_in_world_units() {
                let near = object_bounds(o).map_or(frame.camera.near, |(lo, hi)| {
                    (0..8)
                        .map(|k| {
                            let c = Vec3::new(
                                if k & 1 == 0 { lo.x } else { hi.x },
                                if k & 2 == 0 { lo.y } else { hi.y },
                                if k & 4 == 0 { lo.z } else { hi.z },
                            );
                            basis.to_view(c).z
                        })
                        .fold(f32::INFINITY, f32::min)
                });
                near.max(frame.camera.near)
            } else {
                1.0
            };
            widest = widest.max(m.hull_pixels(z, basis.tan_half_fov, frame.height));
        }
    }
    widest
}

/// The world-space triangles of the objects `casters` of `frame` (their meshes under their
/// transforms, indices out of range skipped): what an `[area_light]`'s traced resolve builds its
/// hierarchy over (`hadou_math::soft::Bvh`), on both backends.
pub fn caster_triangles(frame: &Frame, casters: &[u32]) -> Vec<[Vec3f; 3]> {
    let mut out = Vec::new();
    for obj in casters.iter().filter_map(|&c| frame.objects.get(c as usize)) {
        let world: Vec<Vec3f> =
            obj.mesh.positions.iter().map(|p| obj.transform.transform_point(Vec3::from_array(*p))).collect();
        for tri in obj.mesh.indices.chunks_exact(3) {
            let v = [tri[0], tri[1], tri[2]].map(|i| world.get(i as usize).copied());
            if let [Some(a), Some(b), Some(c)] = v {
                out.push([a, b, c]);
            }
        }
    }
    out
}
