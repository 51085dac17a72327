//! The viewport's textures: the CPU path's image texture and its upload, and the binding of a
//! wgpu texture (the CPU path's, or the one the GPU backend renders into) as an egui texture.

use hadou_gpu::wgpu;

/// The texture the CPU path's image is uploaded into: `size`, `Rgba8UnormSrgb` (the bytes are
/// sRGB codes; sampling gives linear colour back), sampled and written.
pub fn viewport_texture(device: &wgpu::Device, size: [u32; 2]) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("hadou view CPU image"),
        size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// Writes 8-bit RGBA rows (`4 · size[0]` bytes each) into the whole of `texture`.
pub fn upload_rgba(queue: &wgpu::Queue, texture: &wgpu::Texture, rgba: &[u8], size: [u32; 2]) {
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        rgba,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(4 * size[0]),
            rows_per_image: Some(size[1]),
        },
        wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
    );
}

/// Shows `view` as the egui texture `id` (its binding replaced), or as a new egui texture when
/// there is none yet; returns its id.
pub(super) fn bind_native(
    renderer: &mut egui_wgpu::Renderer,
    device: &wgpu::Device,
    view: &wgpu::TextureView,
    id: Option<egui::TextureId>,
) -> egui::TextureId {
    match id {
        Some(id) => {
            renderer.update_egui_texture_from_wgpu_texture(device, view, wgpu::FilterMode::Linear, id);
            id
        }
        None => renderer.register_native_texture(device, view, wgpu::FilterMode::Linear),
    }
}
