//! Triangulated primitives for `[[object]]`: box, UV sphere and plane quad, with texture
//! coordinates. Every mesh has counter-clockwise front faces seen from outside and outward unit
//! normals. Also the mesh operations the glTF loader uses ([`smooth_normals`], [`transform_mesh`],
//! [`append_mesh`]) and the outline normals of the inverted hull ([`with_outline_normals`]).

use crate::frame::Mesh;
use hadou_math::{Mat4, Vec3f};
use std::f32::consts::PI;

/// An axis-aligned box centred on the origin with edge lengths `size` (x, y, z): 24 vertices
/// (flat normals per face), 12 triangles.
pub fn box_mesh(size: [f32; 3]) -> Mesh {
    let h = size.map(|s| 0.5 * s);
    let mut m = Mesh::default();
    // Each face: outward normal n and two in-face axes u, v with u × v = n, so the quad
    // (−u−v, +u−v, +u+v, −u+v) runs counter-clockwise seen from outside.
    let faces: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
    ];
    for (n, u, v) in faces {
        let base = m.positions.len() as u32;
        for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let p: [f32; 3] = std::array::from_fn(|i| (n[i] + su * u[i] + sv * v[i]) * h[i]);
            m.positions.push(p);
            m.normals.push(n);
            m.uvs.push([0.5 * (su + 1.0), 0.5 * (1.0 - sv)]);
        }
        m.indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    m
}

/// The triangles and vertices of [`sphere_mesh`] with `segments`, without building it.
pub fn sphere_size(segments: u32) -> (u64, u64) {
    let slices = u64::from(segments.max(3));
    let stacks = u64::from((segments / 2).max(2));
    (2 * slices * (stacks - 1), (stacks + 1) * (slices + 1))
}

/// A UV sphere of `radius` around the origin with `segments` slices around the y axis and
/// `max(2, segments / 2)` stacks; the pole caps are triangles.
pub fn sphere_mesh(radius: f32, segments: u32) -> Mesh {
    let slices = segments.max(3);
    let stacks = (segments / 2).max(2);
    let mut m = Mesh::default();
    for i in 0..=stacks {
        let theta = PI * i as f32 / stacks as f32; // from +y down
        let (st, ct) = theta.sin_cos();
        for j in 0..=slices {
            let phi = 2.0 * PI * j as f32 / slices as f32;
            let (sp, cp) = phi.sin_cos();
            // Exact poles (sin π is not exactly 0 in f32).
            let st = if i == 0 || i == stacks { 0.0 } else { st };
            let n = [st * sp, ct, st * cp];
            m.positions.push(n.map(|c| c * radius));
            m.normals.push(n);
            m.uvs.push([j as f32 / slices as f32, i as f32 / stacks as f32]);
        }
    }
    let row = slices + 1;
    for i in 0..stacks {
        for j in 0..slices {
            let a = i * row + j;
            let b = a + row;
            // Seen from outside with phi increasing towards +x from +z, (a, b, b+1) is CCW.
            if i != 0 {
                m.indices.extend_from_slice(&[a, b, a + 1]);
            }
            if i != stacks - 1 {
                m.indices.extend_from_slice(&[a + 1, b, b + 1]);
            }
        }
    }
    m
}

/// A finite plane in xz centred on the origin, `size = [x, z]`, normal +y: 4 vertices,
/// 2 triangles.
pub fn plane_mesh(size: [f32; 2]) -> Mesh {
    let (hx, hz) = (0.5 * size[0], 0.5 * size[1]);
    Mesh {
        positions: vec![[-hx, 0.0, -hz], [-hx, 0.0, hz], [hx, 0.0, hz], [hx, 0.0, -hz]],
        normals: vec![[0.0, 1.0, 0.0]; 4],
        indices: vec![0, 1, 2, 0, 2, 3],
        uvs: vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]],
        ..Mesh::default()
    }
}

/// Area-weighted smooth vertex normals of an indexed mesh; vertices touching only degenerate
/// triangles get `+y`.
pub fn smooth_normals(positions: &[[f32; 3]], indices: &[u32]) -> Vec<[f32; 3]> {
    let mut acc = vec![Vec3f::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let idx = [t[0] as usize, t[1] as usize, t[2] as usize];
        if idx.iter().any(|&i| i >= positions.len()) {
            continue;
        }
        let [a, b, c] = idx.map(|i| Vec3f::from_array(positions[i]));
        let n = (b - a).cross(c - a);
        if n.is_finite() {
            for i in idx {
                acc[i] += n;
            }
        }
    }
    acc.into_iter().map(|n| n.normalize_or(Vec3f::Y).to_array()).collect()
}

/// `mesh` with `m` applied to positions, normals and outline normals (normals by the inverse
/// transpose, then renormalised); every other attribute is kept. A mirroring transform (negative determinant) reverses the winding so front
/// faces stay counter-clockwise.
pub fn transform_mesh(mesh: &Mesh, m: &Mat4) -> Mesh {
    let nm = m.normal_matrix();
    let positions =
        mesh.positions.iter().map(|&p| m.transform_point(Vec3f::from_array(p)).to_array()).collect();
    let normal = |&n: &[f32; 3]| {
        let n0 = Vec3f::from_array(n);
        nm.transform_vector(n0).normalize_or(n0.normalize_or(Vec3f::Y)).to_array()
    };
    let normals = mesh.normals.iter().map(normal).collect();
    let outline_normals = mesh.outline_normals.iter().map(normal).collect();
    let x = m.transform_vector(Vec3f::X);
    let y = m.transform_vector(Vec3f::Y);
    let z = m.transform_vector(Vec3f::Z);
    let mut indices = mesh.indices.clone();
    if x.cross(y).dot(z) < 0.0 {
        for t in indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
    }
    Mesh { positions, normals, indices, outline_normals, ..mesh.clone() }
}

/// Appends `other`'s geometry and per-vertex attributes to `mesh` (an attribute only one side
/// has is filled with its neutral value on the other: uv 0, white, material 0, the normal);
/// material ids are taken as they are (callers keep one material list).
pub fn append_mesh(mesh: &mut Mesh, other: &Mesh) {
    let base = mesh.positions.len();
    let n = other.positions.len();
    fn extend<T: Clone>(dst: &mut Vec<T>, base: usize, src: &[T], n: usize, fill: T) {
        if dst.is_empty() && src.is_empty() {
            return;
        }
        dst.resize(base, fill.clone());
        if src.is_empty() {
            dst.resize(base + n, fill);
        } else {
            dst.extend_from_slice(src);
        }
    }
    extend(&mut mesh.uvs, base, &other.uvs, n, [0.0; 2]);
    extend(&mut mesh.colors, base, &other.colors, n, [1.0; 4]);
    extend(&mut mesh.material_ids, base, &other.material_ids, n, 0);
    if !mesh.outline_normals.is_empty() || !other.outline_normals.is_empty() {
        let mut on = std::mem::take(&mut mesh.outline_normals);
        if on.is_empty() {
            on = mesh.normals.clone();
        }
        on.extend_from_slice(if other.outline_normals.is_empty() {
            &other.normals
        } else {
            &other.outline_normals
        });
        mesh.outline_normals = on;
    }
    mesh.positions.extend_from_slice(&other.positions);
    mesh.normals.extend_from_slice(&other.normals);
    mesh.indices.extend(other.indices.iter().map(|i| i + base as u32));
}

/// `mesh` with [`Mesh::outline_normals`] filled: for every group of vertices at exactly the same
/// position, the normalised sum of their normals (so the hard edges of a box, whose corners carry
/// three face normals, get one shared direction and the pushed-out hull stays closed). A group
/// whose normals cancel keeps each vertex's own normal. Where a vertex's material is MToon with an
/// `outlineWidthMultiplyTexture`, the direction is scaled by that texture's green channel at the
/// vertex's texture coordinates ([`outline_scale`]): backends push the hull by the direction's
/// length times the outline width.
pub fn with_outline_normals(mut mesh: Mesh) -> Mesh {
    let mut groups: std::collections::HashMap<[u32; 3], Vec3f> = std::collections::HashMap::new();
    let key = |p: &[f32; 3]| p.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        *groups.entry(key(p)).or_insert(Vec3f::ZERO) += Vec3f::from_array(*n);
    }
    let outline_normals = mesh
        .positions
        .iter()
        .zip(&mesh.normals)
        .enumerate()
        .map(|(i, (p, n))| {
            let own = Vec3f::from_array(*n);
            (groups[&key(p)].try_normalize().unwrap_or(own) * outline_scale(&mesh, i)).to_array()
        })
        .collect();
    mesh.outline_normals = outline_normals;
    mesh
}

/// The multiplier of vertex `v`'s outline width: the green channel of its MToon material's
/// `outlineWidthMultiplyTexture` at its texture coordinates, as stored (a data texture:
/// `hadou_math::mtoon::data_texel`), clamped to [0, 1]; else 1.
pub fn outline_scale(mesh: &Mesh, v: usize) -> f32 {
    let slot = mesh.material_of(v) as usize;
    let texture = mesh
        .materials
        .get(slot)
        .and_then(|m| m.mtoon.as_ref())
        .and_then(|m| m.outline_width_texture.as_ref());
    match (texture, mesh.uvs.get(v)) {
        (Some(t), Some(uv)) => {
            let g = hadou_math::mtoon::data_texel(t.sample(*uv)[1], 1);
            if g.is_finite() {
                g.clamp(0.0, 1.0)
            } else {
                1.0
            }
        }
        _ => 1.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_outward(m: &Mesh) {
        for t in m.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3f::from_array(m.positions[i as usize]));
            let face = (b - a).cross(c - a);
            let centroid = (a + b + c) / 3.0;
            assert!(face.length() > 0.0, "degenerate triangle {t:?}");
            assert!(face.dot(centroid) > 0.0, "inward triangle {t:?}");
        }
    }

    #[test]
    fn sphere_is_closed_and_outward() {
        for s in [3, 4, 5, 16, 1024] {
            let m = sphere_mesh(1.0, s);
            assert_eq!(sphere_size(s), ((m.indices.len() / 3) as u64, m.positions.len() as u64), "{s}");
        }
        let m = sphere_mesh(2.0, 16);
        check_outward(&m);
        for p in &m.positions {
            assert!((Vec3f::from_array(*p).length() - 2.0).abs() < 1e-5);
        }
    }

    #[test]
    fn plane_faces_up() {
        let m = plane_mesh([2.0, 4.0]);
        let t = &m.indices;
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3f::from_array(m.positions[i as usize]));
        assert!((b - a).cross(c - a).y > 0.0);
        assert_eq!(m.positions[2], [1.0, 0.0, 2.0]);
    }

    #[test]
    fn outline_normals_close_hard_edges() {
        let m = with_outline_normals(box_mesh([2.0, 2.0, 2.0]));
        let k = 1.0 / 3f32.sqrt();
        for (p, n) in m.positions.iter().zip(&m.outline_normals) {
            // Every box corner points diagonally out of the box.
            let want = p.map(|c| c.signum() * k);
            for i in 0..3 {
                assert!((n[i] - want[i]).abs() < 1e-6, "{p:?} {n:?}");
            }
        }
        let mut a = plane_mesh([1.0, 1.0]);
        a.uvs.clear();
        append_mesh(&mut a, &plane_mesh([1.0, 1.0]));
        assert_eq!(a.uvs.len(), 8);
        assert_eq!(a.uvs[0], [0.0, 0.0]);
        assert_eq!(a.uvs[5], [0.0, 1.0]);
        assert!(a.colors.is_empty() && a.material_ids.is_empty());
    }

    #[test]
    fn mirroring_keeps_winding_outward() {
        let m = transform_mesh(&box_mesh([1.0, 2.0, 3.0]), &Mat4::scale(Vec3f::new(-1.0, 1.0, 1.0)));
        check_outward(&m);
        let n = smooth_normals(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]], &[0, 1, 2]);
        assert!((n[0][1] - 1.0).abs() < 1e-6, "{n:?}");
    }
}
