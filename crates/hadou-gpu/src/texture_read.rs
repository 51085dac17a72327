//! Reading a texture back without waiting: what a web page does with the frame
//! [`crate::GpuBackend::render_to_texture`] drew (its screenshots, its animation export, its test
//! mode), where nothing may block. The copy into a staging buffer is submitted at once and the
//! buffer mapped asynchronously; the caller asks [`TextureRead::try_take`] on later frames until
//! the bytes are there. Natively the same path serves tests (`tests/present.rs`).

use hadou_scene::RenderError;
use std::sync::{Arc, Mutex};

/// What the map callback reported: nothing yet, or the outcome.
type MapSlot = Arc<Mutex<Option<Result<(), wgpu::BufferAsyncError>>>>;

/// A texture's RGBA8 pixels on their way back from the GPU (see the module documentation).
pub struct TextureRead {
    buffer: wgpu::Buffer,
    size: [u32; 2],
    padded_row: u32,
    slot: MapSlot,
    taken: bool,
}

impl TextureRead {
    /// Copies all of `texture` (4 bytes a texel, `size` its width and height) into a new staging
    /// buffer, submits the copy on `queue` and starts mapping the buffer.
    pub(crate) fn start(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        texture: &wgpu::Texture,
        size: [u32; 2],
    ) -> TextureRead {
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let padded_row = (4 * size[0]).div_ceil(align) * align;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("texture read-back"),
            size: u64::from(padded_row) * u64::from(size[1].max(1)),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("read-back") });
        enc.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row),
                    rows_per_image: Some(size[1]),
                },
            },
            wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
        );
        queue.submit([enc.finish()]);
        let slot: MapSlot = Arc::new(Mutex::new(None));
        let s = slot.clone();
        buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            *s.lock().unwrap_or_else(|p| p.into_inner()) = Some(r);
        });
        TextureRead { buffer, size, padded_row, slot, taken: false }
    }

    /// The texture's width and height.
    pub fn size(&self) -> [u32; 2] {
        self.size
    }

    /// The pixels, `4 · width · height` bytes row after row, once the GPU has finished the copy;
    /// `None` while it has not (ask again on a later frame). Never waits: natively it polls
    /// `device` once; in a browser the mapping completes between the page's frames. After the
    /// bytes (or an error) have been returned once, `None` forever.
    pub fn try_take(&mut self, device: &wgpu::Device) -> Option<Result<Vec<u8>, RenderError>> {
        if self.taken {
            return None;
        }
        let _ = device.poll(wgpu::PollType::Poll);
        let outcome = self.slot.lock().unwrap_or_else(|p| p.into_inner()).take()?;
        self.taken = true;
        if let Err(e) = outcome {
            return Some(Err(RenderError::Device(format!("reading the frame back failed: {e}"))));
        }
        let row = 4 * self.size[0] as usize;
        let mut out = Vec::with_capacity(row * self.size[1] as usize);
        {
            let mapped = self.buffer.slice(..).get_mapped_range();
            for r in mapped.chunks(self.padded_row as usize).take(self.size[1] as usize) {
                out.extend_from_slice(&r[..row]);
            }
        }
        self.buffer.unmap();
        Some(Ok(out))
    }
}
