//! The triangulated primitives of `[[object]]`.

use hadou_math::Vec3f;
use hadou_scene::mesh::{box_mesh, plane_mesh, sphere_mesh};
use hadou_scene::{Mesh, Scene};
use std::path::Path;

fn tri(m: &Mesh, t: &[u32]) -> [Vec3f; 3] {
    [t[0], t[1], t[2]].map(|i| Vec3f::from_array(m.positions[i as usize]))
}

#[test]
fn box_has_12_outward_triangles_and_unit_normals() {
    let m = box_mesh([2.0, 4.0, 6.0]);
    assert_eq!(m.indices.len(), 36);
    assert_eq!(m.positions.len(), m.normals.len());
    for t in m.indices.chunks_exact(3) {
        let [a, b, c] = tri(&m, t);
        let face = (b - a).cross(c - a).normalize_or(Vec3f::ZERO);
        let n = Vec3f::from_array(m.normals[t[0] as usize]);
        assert!((n.length() - 1.0).abs() < 1e-6);
        assert!((face - n).length() < 1e-6, "winding disagrees with normal: {face:?} vs {n:?}");
        // Outward: the face's centroid lies on the side the normal points to.
        assert!(((a + b + c) / 3.0).dot(n) > 0.0);
    }
    for p in &m.positions {
        assert_eq!(p.map(f32::abs), [1.0, 2.0, 3.0]);
    }
}

#[test]
fn sphere_vertices_lie_at_the_radius_with_radial_normals() {
    let m = sphere_mesh(1.5, 24);
    for (p, n) in m.positions.iter().zip(&m.normals) {
        let p = Vec3f::from_array(*p);
        assert!((p.length() - 1.5).abs() < 1e-5);
        assert!((p / 1.5 - Vec3f::from_array(*n)).length() < 1e-5);
    }
    for t in m.indices.chunks_exact(3) {
        let [a, b, c] = tri(&m, t);
        assert!((b - a).cross(c - a).dot(a + b + c) > 0.0, "inward triangle");
    }
    // 24 slices × 12 stacks, pole rows as single triangles.
    assert_eq!(m.indices.len() / 3, 24 * 2 * (12 - 1));
}

#[test]
fn plane_is_a_quad_facing_up() {
    let m = plane_mesh([4.0, 2.0]);
    assert_eq!(m.indices.len(), 6);
    for t in m.indices.chunks_exact(3) {
        let [a, b, c] = tri(&m, t);
        assert!((b - a).cross(c - a).normalize_or(Vec3f::ZERO).y > 0.999);
    }
    assert!(m.positions.iter().all(|p| p[0].abs() == 2.0 && p[1] == 0.0 && p[2].abs() == 1.0));
}

#[test]
fn scene_objects_use_their_size_and_segments() {
    let text = "[[object]]\nname = \"s\"\nkind = \"sphere\"\nradius = 3\nsegments = 8\n\
                [[object]]\nname = \"p\"\nkind = \"plane\"\nsize = [4, 2]\nposition = [0, -1, 0]\n";
    let s = Scene::parse(text, Path::new("o.toml")).unwrap_or_else(|e| panic!("{e}"));
    let f = s.at(0.0);
    assert!(f.objects[0].mesh.positions.iter().all(|p| (Vec3f::from_array(*p).length() - 3.0).abs() < 1e-5));
    assert_eq!(f.objects[1].transform.transform_point(Vec3f::ZERO), Vec3f::new(0.0, -1.0, 0.0));
    assert_eq!(f.objects[0].materials[0].base_color, [0.8; 3]);
}
