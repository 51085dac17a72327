//! hadou meshes as Bevy meshes: the whole mesh, one material slot's triangles, and the outline
//! hull of a slot (000 §2.3).

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;

/// A Bevy mesh with the positions, normals, indices, texture coordinates and vertex colours of
/// a hadou mesh.
pub fn bevy_mesh(mesh: &hadou_scene::Mesh) -> Mesh {
    let mut out = Mesh::new(PrimitiveTopology::TriangleList, RenderAssetUsages::default());
    out.insert_attribute(Mesh::ATTRIBUTE_POSITION, mesh.positions.clone());
    out.insert_attribute(Mesh::ATTRIBUTE_NORMAL, mesh.normals.clone());
    if mesh.uvs.len() == mesh.positions.len() {
        out.insert_attribute(Mesh::ATTRIBUTE_UV_0, mesh.uvs.clone());
    }
    if mesh.colors.len() == mesh.positions.len() {
        out.insert_attribute(Mesh::ATTRIBUTE_COLOR, mesh.colors.clone());
    }
    out.insert_indices(Indices::U32(mesh.indices.clone()));
    out
}

/// The slot a triangle of `mesh` is drawn with, of `slots` (its first vertex's, clamped as
/// `Object::material` clamps it).
fn triangle_slot(mesh: &hadou_scene::Mesh, first: u32, slots: usize) -> u32 {
    mesh.material_of(first as usize).min(slots.saturating_sub(1) as u32)
}

/// The indices of `mesh`'s triangles drawn with material slot `slot` of `slots` (see
/// `Object::material`: a slot past the last is the last).
pub fn slot_indices_of(mesh: &hadou_scene::Mesh, slot: u32, slots: usize) -> Vec<u32> {
    mesh.indices
        .chunks_exact(3)
        .filter(|t| triangle_slot(mesh, t[0], slots) == slot)
        .flatten()
        .copied()
        .collect()
}

pub(crate) fn slot_indices(mesh: &hadou_scene::Mesh, slot: u32) -> Vec<u32> {
    slot_indices_of(mesh, slot, mesh.materials.len().max(1))
}

/// [`bevy_mesh`] with only the triangles of material slot `slot` of `slots`.
pub fn bevy_slot_mesh(mesh: &hadou_scene::Mesh, slot: u32, slots: usize) -> Mesh {
    let mut out = bevy_mesh(mesh);
    out.insert_indices(Indices::U32(slot_indices_of(mesh, slot, slots)));
    out
}

/// The hull mesh of `mesh`'s material slot `slot`: its positions, its outline normals (or its
/// normals when it has none) as `NORMAL`, and the triangles of that slot.
pub fn outline_mesh(mesh: &hadou_scene::Mesh, slot: u32) -> Mesh {
    let normals = if mesh.outline_normals.len() == mesh.positions.len() {
        mesh.outline_normals.clone()
    } else {
        mesh.normals.clone()
    };
    let mut out =
        Mesh::new(bevy::mesh::PrimitiveTopology::TriangleList, bevy::asset::RenderAssetUsages::default());
    out.insert_attribute(Mesh::ATTRIBUTE_POSITION, mesh.positions.clone());
    out.insert_attribute(Mesh::ATTRIBUTE_NORMAL, normals);
    out.insert_indices(Indices::U32(slot_indices(mesh, slot)));
    out
}
