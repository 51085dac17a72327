//! A frame's data on the GPU: the checks against the device that come before any GPU work
//! (image size, camera, meshes, shadows and their maps, the `[area_light]`, storage-buffer
//! limits), the records every pass reads (objects, waves, curves, materials, lights, shading data,
//! shadow casts, laid out by `layout/`), their buffers, and each pass's draw lists. The renderer
//! (`render.rs`) prepares a frame with these and hands each pass its own part.

use crate::layout::{
    self, CurveBuffers, FrameShadows, GpuCurve, GpuLight, GpuMaterial, GpuObject, GpuShadowCast, GpuWave,
    ShadingBuffers,
};
use crate::passes::setup::Draw;
use crate::passes::soft::check_area_light;
use crate::passes::wave::WaveVariant;
use bytemuck::Zeroable;
use hadou_scene::{Frame, LightLine, RenderError, MAX_SHADOWS};
use wgpu::util::DeviceExt;

fn other(msg: String) -> RenderError {
    RenderError::Other(msg)
}

/// Checks that a frame can be drawn at all, before any GPU work.
pub(crate) fn validate_frame(frame: &Frame) -> Result<(), RenderError> {
    if !(1..=16384).contains(&frame.width) || !(1..=16384).contains(&frame.height) {
        return Err(other(format!(
            "image size {}×{} is outside 1..=16384 in each dimension",
            frame.width, frame.height
        )));
    }
    let c = &frame.camera;
    if !(c.near > 0.0 && c.far > c.near && c.far.is_finite()) {
        return Err(other(format!(
            "camera near/far must satisfy 0 < near < far (got {}, {})",
            c.near, c.far
        )));
    }
    if !(c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0) {
        return Err(other(format!("camera fov must be in (0, 180) degrees (got {})", c.fov_y_deg)));
    }
    for o in &frame.objects {
        let m = &o.mesh;
        if m.normals.len() != m.positions.len() {
            return Err(other(format!(
                "object `{}`: {} normals for {} positions",
                o.name,
                m.normals.len(),
                m.positions.len()
            )));
        }
        if m.indices.len() % 3 != 0 {
            return Err(other(format!(
                "object `{}`: {} indices is not a triangle list",
                o.name,
                m.indices.len()
            )));
        }
        if let Some(bad) = m.indices.iter().find(|&&i| i as usize >= m.positions.len()) {
            return Err(other(format!(
                "object `{}`: index {bad} out of range ({} vertices)",
                o.name,
                m.positions.len()
            )));
        }
    }
    if frame.shadows.len() > MAX_SHADOWS {
        return Err(other(format!(
            "{} shadows; at most {MAX_SHADOWS} fit (receivers carry one bit per shadow)",
            frame.shadows.len()
        )));
    }
    let objects = frame.objects.len();
    for s in &frame.shadows {
        if let Some(bad) = s.casters.iter().chain(&s.receivers).find(|&&o| o as usize >= objects) {
            return Err(other(format!(
                "shadow \"{}\": object index {bad} out of range ({objects} objects)",
                s.name
            )));
        }
    }
    Ok(())
}

/// Checks the frame's shadow maps against the device: each map's edge within the largest 2D
/// texture, their number within the array layers of one texture.
pub(crate) fn check_maps(
    limits: &wgpu::Limits,
    frame: &Frame,
    shadows: &FrameShadows,
) -> Result<(), RenderError> {
    for (i, g) in shadows.map_casts.iter().map(|&j| &shadows.casts[j as usize]).enumerate() {
        let name = &frame.shadows[g.shadow as usize].name;
        if g.map_size > limits.max_texture_dimension_2d {
            return Err(RenderError::Device(format!(
                "shadow \"{name}\": map_size {} exceeds this adapter's largest texture ({})",
                g.map_size, limits.max_texture_dimension_2d
            )));
        }
        if i as u32 >= limits.max_texture_array_layers {
            return Err(RenderError::Device(format!(
                "shadow \"{name}\": the frame needs {} shadow maps, more than this adapter's {} texture array \
                 layers",
                shadows.map_casts.len(),
                limits.max_texture_array_layers
            )));
        }
    }
    Ok(())
}

/// The largest storage buffer binding the device allows.
fn max_binding(limits: &wgpu::Limits) -> u64 {
    limits.max_storage_buffer_binding_size.min(limits.max_buffer_size)
}

/// Checks the frame's curve buffers against the device's storage-buffer limit.
pub(crate) fn check_curves(limits: &wgpu::Limits, curve_data: &CurveBuffers) -> Result<(), RenderError> {
    let max_binding = max_binding(limits);
    let curve_bytes = [
        std::mem::size_of_val(curve_data.curves.as_slice()),
        std::mem::size_of_val(curve_data.vec4s.as_slice()),
        std::mem::size_of_val(curve_data.scalars.as_slice()),
    ];
    if let Some(&big) = curve_bytes.iter().find(|&&b| b as u64 > max_binding) {
        return Err(RenderError::Device(format!(
            "curve data of {big} bytes exceeds the device's storage buffer limit of {max_binding} bytes"
        )));
    }
    Ok(())
}

/// The frame's curve buffers uploaded (bindings 5–7 of the wave pass and the wave overlay).
pub(crate) fn upload_curves(d: &wgpu::Device, curves: &CurveBuffers) -> [wgpu::Buffer; 3] {
    [
        storage(d, "curves", or_zeroed(&curves.curves, &[GpuCurve::zeroed()])),
        storage(d, "curve vec4s", bytemuck::cast_slice(&curves.vec4s)),
        storage(d, "curve scalars", bytemuck::cast_slice(&curves.scalars)),
    ]
}

/// A storage buffer holding `bytes` (one zeroed 16-byte element when empty: storage bindings may
/// not be empty).
pub(crate) fn storage(d: &wgpu::Device, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: if bytes.is_empty() { &[0u8; 16] } else { bytes },
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// The shadow fields of `layout::FrameUniforms` for one frame.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ShadowFields {
    pub(crate) shadow_casts: u32,
    pub(crate) map_casts: u32,
    pub(crate) cast_count: u32,
    pub(crate) map_count: u32,
    pub(crate) plane_count: u32,
}

impl ShadowFields {
    /// Writes these fields into `uniforms`.
    pub(crate) fn apply(&self, uniforms: &mut layout::FrameUniforms) {
        uniforms.shadow_casts = self.shadow_casts;
        uniforms.map_casts = self.map_casts;
        uniforms.cast_count = self.cast_count;
        uniforms.map_count = self.map_count;
        uniforms.plane_count = self.plane_count;
    }
}

/// A frame's records as the passes read them, built on the CPU and checked against the device's
/// limits before anything is uploaded.
pub(crate) struct FrameData {
    pub(crate) waves: Vec<GpuWave>,
    pub(crate) curves: CurveBuffers,
    pub(crate) shading: ShadingBuffers,
    pub(crate) shadows: FrameShadows,
    pub(crate) objects: Vec<GpuObject>,
    /// `(cast, object)` per shadow draw: the plane casts' draws first, then each map cast's.
    pub(crate) draw_pairs: Vec<[u32; 2]>,
    /// The plane casts' draws in cast order (instance = index into `draw_pairs`).
    pub(crate) plane_draws: Vec<Draw>,
    /// Each map cast's draws (instance = index into `draw_pairs`), by layer.
    pub(crate) map_draws: Vec<Vec<Draw>>,
    pub(crate) shadow_fields: ShadowFields,
}

impl FrameData {
    /// The records of `frame` (which `validate_frame` accepted); errors where the frame's curves,
    /// shadow maps, `[area_light]` or textures exceed the device's `limits`.
    pub(crate) fn new(limits: &wgpu::Limits, frame: &Frame) -> Result<Self, RenderError> {
        let (waves, curve_data, prepared_curves) = layout::frame_waves(frame).map_err(other)?;
        let mut shading = ShadingBuffers::new(frame, &prepared_curves);
        // The waves' light lines, as the shading buffers hold them: the wave shadows' lights.
        let lines: Vec<LightLine> =
            frame.waves.iter().zip(&prepared_curves).map(|(w, c)| w.light_line(c.as_ref())).collect();
        let shadow_casts = frame.shadow_casts(&lines);
        let shadows = FrameShadows::new(frame, &shadow_casts);
        check_maps(limits, frame, &shadows)?;
        check_area_light(limits, frame)?;
        let (cast_offset, map_offset) = shading.push_shadows(&shadows);
        // Draws of the shadow passes: (cast, object) pairs, the plane casts' first, then each map
        // cast's; casters without triangles draw nothing.
        let mut draw_pairs: Vec<[u32; 2]> = Vec::new();
        let mut plane_draws = Vec::new();
        let mut map_draws: Vec<Vec<Draw>> = vec![Vec::new(); shadows.map_casts.len()];
        let caster_draws = |j: usize| {
            shadow_casts[j].casters.iter().filter_map(|&o| {
                let count = frame.objects[o as usize].mesh.indices.len() as u32;
                (count > 0).then_some((o as usize, count))
            })
        };
        for (j, g) in shadows.casts.iter().enumerate() {
            if g.map_size == layout::CAST_PLANE {
                for (object, index_count) in caster_draws(j) {
                    plane_draws.push(Draw { object, index_count, instance: draw_pairs.len() as u32 });
                    draw_pairs.push([j as u32, object as u32]);
                }
            }
        }
        for (layer, &j) in shadows.map_casts.iter().enumerate() {
            for (object, index_count) in caster_draws(j as usize) {
                map_draws[layer].push(Draw { object, index_count, instance: draw_pairs.len() as u32 });
                draw_pairs.push([j, object as u32]);
            }
        }
        let shadow_fields = ShadowFields {
            shadow_casts: cast_offset,
            map_casts: map_offset,
            cast_count: shadows.casts.len() as u32,
            map_count: shadows.map_casts.len() as u32,
            plane_count: shadows.casts.len() as u32 - shadows.map_casts.len() as u32,
        };
        let objects: Vec<GpuObject> = frame
            .objects
            .iter()
            .zip(&shading.material_base)
            .map(|(o, &base)| GpuObject::new(o, base))
            .collect();
        check_curves(limits, &curve_data)?;
        // The raster pass keeps a material index in the low bits of a word (layout::MATERIAL_MASK).
        if shading.materials.len() > crate::layout::MATERIAL_MASK as usize + 1 {
            return Err(RenderError::Device(format!(
                "the frame has {} material slots, more than the {} the GPU backend can tell apart",
                shading.materials.len(),
                crate::layout::MATERIAL_MASK as usize + 1
            )));
        }
        let max_binding = max_binding(limits);
        let data_bytes = std::mem::size_of_val(shading.data.as_slice()) as u64;
        if data_bytes > max_binding {
            return Err(RenderError::Device(format!(
                "the frame's textures take {data_bytes} bytes, more than the device's storage buffer limit of \
                 {max_binding} bytes; use smaller textures"
            )));
        }
        Ok(Self {
            waves,
            curves: curve_data,
            shading,
            shadows,
            objects,
            draw_pairs,
            plane_draws,
            map_draws,
            shadow_fields,
        })
    }

    /// The wave pass's variant for this frame (see [`WaveVariant::of`]).
    /// `samples`: whether the wave pass resolves each pixel from several samples.
    pub(crate) fn wave_variant(&self, frame: &Frame, samples: bool) -> WaveVariant {
        WaveVariant::of(
            &self.waves,
            &self.curves.curves,
            &self.shading.materials,
            // The lights shading.wgsl reads (MAX_LIGHTS there).
            &self.shading.lights[..self.shading.lights.len().min(256)],
            frame.waves.iter().any(|w| w.light.glow > 0.0),
            // Every object with triangles is drawn (MeshCache::upload).
            frame.objects.iter().any(|o| !o.mesh.indices.is_empty()),
            (self.shadow_fields.plane_count > 0, self.shadow_fields.map_count > 0),
            frame.area_light.is_some(),
            frame.color_mapping.mode == hadou_scene::ToneMode::Faithful,
            frame.color_mapping.exposure,
            samples,
        )
    }

    /// Whether any object has an outlined material (then the hull pipeline runs).
    pub(crate) fn outlines(&self) -> bool {
        self.shading.materials.iter().any(|m| m.outline_width.abs() > 0.0)
    }
}

/// The frame's records uploaded as storage buffers (each at least one element: storage bindings
/// may not be empty).
pub(crate) struct FrameBuffers {
    pub(crate) objects: wgpu::Buffer,
    pub(crate) waves: wgpu::Buffer,
    /// Curve buffers (bindings 5–7 of the wave pass; see `layout::CurveBuffers`).
    pub(crate) curves: [wgpu::Buffer; 3],
    /// Materials, lights and shading data (bindings 8–10; see `layout::ShadingBuffers`).
    pub(crate) materials: wgpu::Buffer,
    pub(crate) lights: wgpu::Buffer,
    pub(crate) shading_data: wgpu::Buffer,
    /// The frame's shadow casts (binding 3 of shadow_raster.wgsl).
    pub(crate) casts: wgpu::Buffer,
    /// `(cast, object)` per shadow draw (binding 4 of shadow_raster.wgsl).
    pub(crate) shadow_draws: wgpu::Buffer,
}

/// `items` as bytes, or one zeroed element when there are none.
pub(crate) fn or_zeroed<'a, T: bytemuck::Pod>(items: &'a [T], zero: &'a [T; 1]) -> &'a [u8] {
    bytemuck::cast_slice(if items.is_empty() { &zero[..] } else { items })
}

impl FrameBuffers {
    /// Uploads `data`.
    pub(crate) fn upload(d: &wgpu::Device, data: &FrameData) -> Self {
        let storage = |label: &str, bytes: &[u8]| storage(d, label, bytes);
        Self {
            objects: storage("objects", or_zeroed(&data.objects, &[GpuObject::zeroed()])),
            waves: storage("waves", or_zeroed(&data.waves, &[GpuWave::zeroed()])),
            curves: upload_curves(d, &data.curves),
            materials: storage("materials", or_zeroed(&data.shading.materials, &[GpuMaterial::zeroed()])),
            lights: storage("lights", or_zeroed(&data.shading.lights, &[GpuLight::zeroed()])),
            shading_data: storage("shading data", bytemuck::cast_slice(&data.shading.data)),
            casts: storage("shadow casts", or_zeroed(&data.shadows.casts, &[GpuShadowCast::zeroed()])),
            shadow_draws: storage("shadow draws", bytemuck::cast_slice(&data.draw_pairs)),
        }
    }
}
