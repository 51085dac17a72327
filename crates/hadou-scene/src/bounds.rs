//! Where a frame's objects are: the world-space bounding box of an object's mesh
//! ([`object_bounds`]) and its centre `B` ([`object_center`]), as shadows and the area light use
//! them.

use crate::frame::{Mesh, Object};
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
