//! The texture formats of the passes' targets, in one place: the passes create and bind them, and
//! the adapter check (`device.rs`) requires each to be renderable and readable before a device is
//! opened.

/// The raster pass's two G-buffer targets (raster.wgsl `fs_main`): target 0 holds the unit normal
/// and the Euclidean eye distance of the visible surface, target 1 the texture coordinates, the
/// 8-bit vertex colour and the material index (with `layout::HULL_BIT` on outline-hull
/// fragments), each as the bit patterns of four 32-bit words (`bitcast` in raster.wgsl and the
/// passes that read them). An integer format because `Rgba32Uint` is colour-renderable on every
/// adapter wgpu offers (GLES 3.0 and WebGL2 included), while `Rgba32Float` and `R32Float` targets
/// need optional extensions on GL; the bits pass through unchanged, so the readers get exactly the
/// `f32`s the fragment shader wrote. A cleared texel is all zero bits, i.e. distance 0: nothing
/// drawn (a drawn surface is at least `near` > 0 away).
pub(crate) const SCENE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;
/// Depth buffer of the raster pass and of the plane-shadow pass (renderable on every adapter).
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Target of the plane-shadow pass (shadow_raster.wgsl): `j + 1` of the kept plane cast, 0 = none.
/// Colour-renderable and readable on every adapter, GLES 3.0 included.
pub(crate) const PLANE_SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// The shadow maps: a depth array texture rendered by the map pass and read (as unfilterable
/// float) by the wave pass. Also the depth buffer of the `[area_light]`'s map pass.
pub(crate) const MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Target of the `[area_light]`'s map pass (soft_map.wgsl): the f32 bits of the view depth.
pub(crate) const SPOT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// The format of the texture [`crate::GpuBackend::render_to_texture`] draws into: 8-bit sRGB
/// with alpha, the format egui and most window surfaces use for colour images.
pub const PRESENT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The usages of that texture: sampled by the window's renderer, drawn by the present pass,
/// copied from (screenshots, tests), written by the queue (a frame with a `[bloom]`, whose glare
/// is drawn over the whole image before it is uploaded).
pub const PRESENT_USAGE: wgpu::TextureUsages = wgpu::TextureUsages::TEXTURE_BINDING
    .union(wgpu::TextureUsages::RENDER_ATTACHMENT)
    .union(wgpu::TextureUsages::COPY_SRC)
    .union(wgpu::TextureUsages::COPY_DST);
