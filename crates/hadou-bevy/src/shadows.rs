//! The `[[shadow]]`s of a hadou frame on [`HadouMaterial`]s: the wave's stylized shadows (000
//! §2.4, SPEC.md §2.4: each caster's own direction from the wave's centre line, clamped to θ from
//! straight down, the horizon fade) and the sun's (001, SPEC.md §3), found on receivers by
//! hadou-gpu's orthographic shadow maps, drawn on Bevy's device into [`SHADOW_MAPS`] once a frame
//! (`GpuBackend::encode_shadow_maps_into`) and looked up per fragment by hadou-gpu's
//! `apply_shadows` (shadow_lookup.wgsl). A shadow of `method = "plane"` is drawn with a map of
//! [`PLANE_MAP_SIZE`]² texels along the same direction (Bevy has no screen-space plane pass):
//! the same shadow up to a texel at its edge.

use crate::material::{HadouMaterial, SHADOW_DATA, SHADOW_MAPS};
use crate::render::HadouRenderer;
use bevy::asset::RenderAssetUsages;
use bevy::image::Image;
use bevy::prelude::*;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::{
    Extent3d, TextureDimension, TextureFormat, TextureUsages, TextureViewDescriptor, TextureViewDimension,
};
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::storage::ShaderBuffer;
use bevy::render::texture::GpuImage;
use bevy::render::Extract;
use hadou_gpu::layout::FrameShadows;
use hadou_scene::{Frame, ShadowMethod};

/// The map edge a `method = "plane"` shadow is drawn with in Bevy.
pub const PLANE_MAP_SIZE: u32 = 2048;

/// Words before the records in [`SHADOW_DATA`].
const HEADER: usize = 4;

/// The frame whose `[[shadow]]`s are drawn: its objects (casters and receivers by index, their
/// transforms and meshes), waves (a wave shadow's light) and shadows. A spawned scene sets it
/// every frame; a game may set it itself (`None`: no shadows). Receivers are the entities whose
/// [`HadouMaterial`]s have the shadow's bit in `shadow_mask` ([`HadouMaterial::with_shadow_mask`]).
#[derive(Resource, Default, Clone)]
pub struct HadouShadows {
    /// The frame.
    pub frame: Option<Frame>,
}

/// The frame as Bevy draws its shadows: plane shadows as maps (see the module's notes).
pub fn shadow_frame(frame: &Frame) -> Frame {
    let mut out = frame.clone();
    for s in &mut out.shadows {
        if matches!(s.method, ShadowMethod::Plane(_)) {
            s.method = ShadowMethod::Map { size: PLANE_MAP_SIZE };
        }
    }
    out
}

/// Bit `s` set when object `object` of `frame` receives `frame.shadows[s]` (hadou-gpu's
/// `GpuMaterial::shadow_mask`).
pub fn shadow_mask(frame: &Frame, object: u32) -> u32 {
    frame
        .shadows
        .iter()
        .take(32)
        .enumerate()
        .filter(|(_, s)| s.receives(object))
        .fold(0, |m, (s, _)| m | 1 << s)
}

/// The records of `frame`'s shadows: the words of [`SHADOW_DATA`] and the maps' edge and layers.
pub fn shadow_records(frame: &Frame) -> (Vec<u32>, u32, u32) {
    let lines: Vec<_> = frame.waves.iter().map(|w| w.light_line(None)).collect();
    let casts = frame.shadow_casts(&lines);
    let shadows = FrameShadows::new(frame, &casts);
    let mut words = vec![0u32; HEADER];
    words[0] = shadows.casts.len() as u32;
    words[1] = shadows.map_casts.len() as u32;
    words[2] = HEADER as u32;
    words.extend_from_slice(bytemuck::cast_slice(&shadows.casts));
    words[3] = words.len() as u32;
    words.extend_from_slice(&shadows.map_casts);
    (words, shadows.map_size.max(1), shadows.map_layers.max(2))
}

fn map_image(size: u32, layers: u32) -> Image {
    let mut image = Image::new_uninit(
        Extent3d { width: size, height: size, depth_or_array_layers: layers },
        TextureDimension::D2,
        TextureFormat::Depth32Float,
        RenderAssetUsages::RENDER_WORLD,
    );
    image.texture_descriptor.usage = TextureUsages::TEXTURE_BINDING | TextureUsages::RENDER_ATTACHMENT;
    image.texture_view_descriptor =
        Some(TextureViewDescriptor { dimension: Some(TextureViewDimension::D2Array), ..default() });
    image
}

/// The initial contents of [`SHADOW_MAPS`] and [`SHADOW_DATA`]: no shadows.
pub(crate) fn insert_assets(images: &mut Assets<Image>, buffers: &mut Assets<ShaderBuffer>) {
    images.insert(&SHADOW_MAPS, map_image(1, 2)).expect("an image under a fixed handle can be inserted");
    let words = vec![0u32; 256];
    buffers
        .insert(&SHADOW_DATA, ShaderBuffer::new(bytemuck::cast_slice(&words), RenderAssetUsages::default()))
        .expect("a buffer under a fixed handle can be inserted");
}

/// What [`update_shadows`] last wrote.
#[derive(Default)]
pub(crate) struct Written {
    words: Vec<u32>,
    capacity: usize,
    maps: (u32, u32),
}

/// Writes [`HadouShadows`]' records into [`SHADOW_DATA`] and sizes [`SHADOW_MAPS`] for its maps
/// when they change; a new size marks every [`HadouMaterial`] changed so that Bevy binds it.
pub(crate) fn update_shadows(
    shadows: Res<HadouShadows>,
    mut images: ResMut<Assets<Image>>,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
    mut materials: ResMut<Assets<HadouMaterial>>,
    mut written: Local<Written>,
) {
    let (words, size, layers) = match &shadows.frame {
        Some(frame) => shadow_records(&shadow_frame(frame)),
        None => (vec![0; HEADER], 1, 2),
    };
    if written.capacity != 0 && words == written.words && (size, layers) == written.maps {
        return;
    }
    let capacity = words.len().next_power_of_two().max(256).max(written.capacity);
    let mut data = words.clone();
    data.resize(capacity, 0);
    if let Some(mut b) = buffers.get_mut(&SHADOW_DATA) {
        b.data = Some(bytemuck::cast_slice(&data).to_vec());
    }
    let resized = written.capacity != 0 && capacity != written.capacity;
    let grown = (size, layers) != written.maps && (written.maps.0 < size || written.maps.1 < layers);
    if grown {
        let (s, l) = (size.max(written.maps.0), layers.max(written.maps.1));
        images.insert(&SHADOW_MAPS, map_image(s, l)).expect("an image under a fixed handle can be inserted");
        written.maps = (s, l);
    }
    if resized || grown {
        for _ in materials.iter_mut() {}
    }
    written.words = words;
    written.capacity = capacity;
}

/// The render world's copy of [`HadouShadows`].
#[derive(Resource, Default)]
pub(crate) struct ExtractedShadows(Option<Frame>);

pub(crate) fn extract_shadows(mut extracted: ResMut<ExtractedShadows>, shadows: Extract<Res<HadouShadows>>) {
    extracted.0 = shadows.frame.as_ref().filter(|f| !f.shadows.is_empty()).map(shadow_frame);
}

/// Draws the shadow maps of [`ExtractedShadows`] into [`SHADOW_MAPS`] with hadou-gpu's
/// shadow-map pass, in a submission of its own before Bevy's frame.
pub(crate) fn draw_shadow_maps(
    extracted: Res<ExtractedShadows>,
    renderer: Option<ResMut<HadouRenderer>>,
    images: Res<RenderAssets<GpuImage>>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    mut warned: Local<bool>,
) {
    let (Some(frame), Some(mut renderer)) = (&extracted.0, renderer) else { return };
    let Some(image) = images.get(&SHADOW_MAPS) else { return };
    let (_, size, layers) = shadow_records(frame);
    let t = &image.texture;
    if t.width() < size || t.height() < size || t.depth_or_array_layers() < layers {
        return; // the grown texture arrives with the next frame
    }
    let mut encoder = device.wgpu_device().create_command_encoder(&Default::default());
    match renderer.0.encode_shadow_maps_into(frame, &mut encoder, &image.texture) {
        Ok(()) => {
            queue.0.submit([encoder.finish()]);
        }
        Err(e) if !*warned => {
            *warned = true;
            error!("hadou shadows are not drawn: {e}");
        }
        Err(_) => {}
    }
}
