//! Shadows cast by the pose Bevy draws: every frame, the mesh of each object of
//! [`HadouShadows`]' frame that is a model Bevy spawned (an entity with [`HadouShaded`] whose
//! `Name` is the object's name, as a spawned scene names its `kind = "gltf"` objects) is replaced
//! by the world-space triangles of the meshes Bevy draws under it (each `Mesh3d` under its
//! `GlobalTransform`, a skinned one posed by its joints as Bevy's skinning poses it: area.rs's
//! gathering, the one the area light's hierarchy is built from), with an identity transform. So
//! the wave shadows (000 §2.4), the sun's plane and map shadows (001, SPEC.md §3) and their maps
//! follow the clip Bevy plays, or a joint a game turns, rather than hadou's own reading of the
//! file.

use crate::area::{caster_triangles, CasterScene};
use crate::shaded::HadouShaded;
use crate::shadows::HadouShadows;
use bevy::prelude::*;
use hadou_math::Vec3f;
use std::sync::Arc;

/// A hadou mesh of the world-space triangles `tris` (three vertices each, flat normals, one
/// material): what the shadow passes draw in place of an object's own mesh. Triangles with a
/// coordinate that is not finite are left out.
pub fn triangles_mesh(tris: &[[Vec3f; 3]]) -> hadou_scene::Mesh {
    let mut mesh = hadou_scene::Mesh::default();
    for t in tris.iter().filter(|t| t.iter().all(|v| v.x.is_finite() && v.y.is_finite() && v.z.is_finite())) {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).try_normalize().unwrap_or(Vec3f::Y);
        for v in t {
            mesh.indices.push(mesh.positions.len() as u32);
            mesh.positions.push([v.x, v.y, v.z]);
            mesh.normals.push([n.x, n.y, n.z]);
        }
    }
    mesh
}

/// Puts the drawn pose of every Bevy-spawned model into [`HadouShadows`]' frame (see the
/// module's notes); a model none of whose meshes has loaded keeps the frame's mesh. `PostUpdate`,
/// after Bevy's animation, skinning joints and transform propagation, before the shadows'
/// records are written.
pub(crate) fn shadows_from_drawn_poses(
    mut shadows: ResMut<HadouShadows>,
    models: Query<(Entity, &Name), With<HadouShaded>>,
    scene: CasterScene,
) {
    if models.is_empty() || shadows.frame.is_none() {
        return;
    }
    let mut models: Vec<_> = models.iter().collect();
    models.sort_by_key(|(e, _)| *e);
    let Some(frame) = shadows.frame.as_mut() else { return };
    for object in &mut frame.objects {
        let Some(&(entity, _)) = models.iter().find(|(_, name)| name.as_str() == object.name) else {
            continue;
        };
        let mut tris = Vec::new();
        caster_triangles(entity, &scene, &mut tris);
        let mesh = triangles_mesh(&tris);
        if !mesh.positions.is_empty() {
            object.mesh = Arc::new(mesh);
            object.transform = hadou_math::Mat4::IDENTITY;
        }
    }
}
