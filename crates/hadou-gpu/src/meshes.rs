//! The mesh cache: each frame object's mesh uploaded once as vertex and index buffers and kept
//! while its `Arc<Mesh>` lives, shared by every pass that draws meshes.

use crate::layout::GpuVertex;
use hadou_scene::{Frame, Mesh};
use std::collections::HashMap;
use std::sync::{Arc, Weak};
use wgpu::util::DeviceExt;

/// A mesh on the GPU, with a weak handle to the `Arc<Mesh>` it came from (so a freed mesh whose
/// address is reused is never mistaken for the cached one).
pub(crate) struct CachedMesh {
    source: Weak<Mesh>,
    pub(crate) vertices: wgpu::Buffer,
    pub(crate) indices: wgpu::Buffer,
    pub(crate) index_count: u32,
}

/// The uploaded meshes, keyed by the address of their `Arc<Mesh>`.
#[derive(Default)]
pub(crate) struct MeshCache {
    meshes: HashMap<usize, CachedMesh>,
}

fn key(mesh: &Arc<Mesh>) -> usize {
    Arc::as_ptr(mesh) as usize
}

impl MeshCache {
    /// Drops the uploads of freed meshes and uploads every mesh of `frame` with triangles that is
    /// not uploaded yet.
    pub(crate) fn upload(&mut self, device: &wgpu::Device, frame: &Frame) {
        self.meshes.retain(|_, m| m.source.strong_count() > 0);
        for o in &frame.objects {
            if o.mesh.indices.is_empty() || self.get(&o.mesh).is_some() {
                continue;
            }
            let m = &o.mesh;
            let vertices: Vec<GpuVertex> = (0..m.positions.len())
                .map(|i| GpuVertex {
                    position: m.positions[i],
                    normal: m.normals[i],
                    outline_normal: m.outline_normals.get(i).copied().unwrap_or(m.normals[i]),
                    uv: m.uvs.get(i).copied().unwrap_or([0.0; 2]),
                    color: m.colors.get(i).copied().unwrap_or([1.0; 4]),
                    material: m.material_of(i),
                })
                .collect();
            let vb = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&o.name),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            });
            let ib = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&o.name),
                contents: bytemuck::cast_slice(&m.indices),
                usage: wgpu::BufferUsages::INDEX,
            });
            self.meshes.insert(
                key(&o.mesh),
                CachedMesh {
                    source: Arc::downgrade(&o.mesh),
                    vertices: vb,
                    indices: ib,
                    index_count: m.indices.len() as u32,
                },
            );
        }
    }

    /// The upload of `mesh`, if it is cached (and is that very mesh, not a freed one at the same
    /// address).
    pub(crate) fn get(&self, mesh: &Arc<Mesh>) -> Option<&CachedMesh> {
        self.meshes.get(&key(mesh)).filter(|c| c.source.upgrade().is_some_and(|a| Arc::ptr_eq(&a, mesh)))
    }

    /// How many meshes are uploaded.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.meshes.len()
    }
}
