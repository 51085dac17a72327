//! The frame's uniforms (`FrameUniforms`, the tone codes), an object's record (`GpuObject`) and a
//! mesh vertex (`GpuVertex`).

use bytemuck::{Pod, Zeroable};
use hadou_math::outline;
use hadou_math::Mat4;
use hadou_scene::{CameraBasis, Frame, Object, SampleGrid, ToneMode};

/// `FrameUniforms::tone_mode` of [`ToneMode::Faithful`]. Keep in sync with `TONE_FAITHFUL`.
pub const TONE_FAITHFUL: u32 = 0;
/// `FrameUniforms::tone_mode` of [`ToneMode::Filmic`]. Keep in sync with `TONE_FILMIC`.
pub const TONE_FILMIC: u32 = 1;
/// `FrameUniforms::tone_mode` of a frame with a `[bloom]`: the wave pass writes the linear colour,
/// unmapped (bloom.wgsl maps it after the glare). Keep in sync with `TONE_LINEAR`.
pub const TONE_LINEAR: u32 = 2;

/// Per-frame, per-tile uniforms: camera basis, light, colour mapping and the tile's place in the
/// image. Keep in sync with `FrameUniforms` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniforms {
    /// Eye `S`.
    pub eye: [f32; 3],
    /// `tan(fov_y / 2)`.
    pub tan_half_fov: f32,
    /// Unit right.
    pub right: [f32; 3],
    /// Width / height.
    pub aspect: f32,
    /// Unit up.
    pub up: [f32; 3],
    /// Near plane distance.
    pub near: f32,
    /// Unit forward.
    pub forward: [f32; 3],
    /// Far plane distance.
    pub far: f32,
    /// Background linear RGB.
    pub background: [f32; 3],
    /// Wave colour multiplier.
    pub exposure: f32,
    /// Unit direction the light travels.
    pub light_dir: [f32; 3],
    /// [`TONE_FAITHFUL`] or [`TONE_FILMIC`].
    pub tone_mode: u32,
    /// Light intensity, linear RGB.
    pub light_color: [f32; 3],
    /// Number of waves in the wave buffer.
    pub wave_count: u32,
    /// Ambient term, linear RGB.
    pub ambient: [f32; 3],
    /// 1 when some wave glows (`light_glow > 0`): every surface then takes the waves' light.
    pub any_glow: u32,
    /// Whole image size in pixels.
    pub image_size: [u32; 2],
    /// Top-left pixel of the tile in the image.
    pub tile_origin: [u32; 2],
    /// Tile size in pixels.
    pub tile_size: [u32; 2],
    /// Word offset of the frame's [`GpuShadowCast`](crate::layout::GpuShadowCast) records in the shading data buffer
    /// ([`ShadingBuffers::push_shadows`](crate::layout::ShadingBuffers::push_shadows)).
    pub shadow_casts: u32,
    /// Word offset of the map casts' indices (into the cast records) in the shading data buffer.
    pub map_casts: u32,
    /// Tile NDC = image NDC · scale + offset.
    pub ndc_scale: [f32; 2],
    /// See `ndc_scale`.
    pub ndc_offset: [f32; 2],
    /// Number of shadow casts (records at `shadow_casts`); 0 = no shadows.
    pub cast_count: u32,
    /// Number of map casts (indices at `map_casts`).
    pub map_count: u32,
    /// Number of plane casts (when 0 the wave pass does not read the plane-shadow target).
    pub plane_count: u32,
    /// 1 when the frame has an `[area_light]`: the wave pass then reads each pixel's soft-shadow
    /// visibility where it later writes the eye distance, and adds the area term (soft.wgsl).
    pub area: u32,
    /// The area light's centre `L`.
    pub area_position: [f32; 3],
    /// How far the edge pass looks for outlines, in pixels (`hadou_math::outline::reach_window`
    /// of the widest outline; 0: nothing is outlined).
    pub outline_reach: u32,
    /// The area light's colour times intensity.
    pub area_color: [f32; 3],
    /// The edge of the sample grid (`Frame::grid`): 1, or with anti-aliasing these are the
    /// sample frame's uniforms and the wave pass resolves `grid × grid` samples per pixel.
    pub grid: u32,
    /// The area light's axis `P = (L − G)/|L − G|` (`AreaLight::axis`).
    pub area_axis: [f32; 3],
    /// The area light's size `l`.
    pub area_size: f32,
    /// The area light's lamp shape ([`LAMP_SEGMENT`], [`LAMP_DISC`], [`LAMP_SPHERE`]).
    pub area_shape: u32,
    /// Padding to the uniform's 16-byte alignment.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

/// `FrameUniforms::area_shape` of `LampShape::Segment`. Keep in sync with `LAMP_SEGMENT`.
pub const LAMP_SEGMENT: u32 = 0;
/// `FrameUniforms::area_shape` of `LampShape::Disc`. Keep in sync with `LAMP_DISC`.
pub const LAMP_DISC: u32 = 1;
/// `FrameUniforms::area_shape` of `LampShape::Sphere`. Keep in sync with `LAMP_SPHERE`.
pub const LAMP_SPHERE: u32 = 2;

/// The `FrameUniforms::area_shape` of `shape`.
pub fn lamp_shape(shape: hadou_scene::LampShape) -> u32 {
    match shape {
        hadou_scene::LampShape::Segment => LAMP_SEGMENT,
        hadou_scene::LampShape::Disc => LAMP_DISC,
        hadou_scene::LampShape::Sphere => LAMP_SPHERE,
    }
}

/// How far the edge pass looks (pixels): the widest outline's hull width on screen, rounded up
/// and capped (`hadou_math::outline::reach_window`, as hadou-cpu's `edges::frame_reach`).
fn outline_reach(frame: &Frame) -> u32 {
    outline::reach_window(hadou_scene::widest_outline_pixels(frame))
}

impl FrameUniforms {
    /// Uniforms of the tile at `origin` with `size` pixels, for `frame` seen through `basis`;
    /// `grid` is the sample grid of the image `frame`'s pixels resolve into (`frame` itself is
    /// the sample frame with anti-aliasing, so its own `samples` is 1).
    pub fn new(
        frame: &Frame,
        basis: &CameraBasis,
        origin: [u32; 2],
        size: [u32; 2],
        grid: SampleGrid,
    ) -> Self {
        let (w, h) = (frame.width as f32, frame.height as f32);
        let (tw, th) = (size[0] as f32, size[1] as f32);
        let (ox, oy) = (origin[0] as f32, origin[1] as f32);
        Self {
            eye: basis.eye.to_array(),
            tan_half_fov: basis.tan_half_fov,
            right: basis.right.to_array(),
            aspect: basis.aspect,
            up: basis.up.to_array(),
            near: frame.camera.near,
            forward: basis.forward.to_array(),
            far: frame.camera.far,
            background: frame.background,
            exposure: frame.color_mapping.exposure,
            light_dir: frame.light.direction.to_array(),
            tone_mode: match frame.color_mapping.mode {
                ToneMode::Faithful => TONE_FAITHFUL,
                ToneMode::Filmic => TONE_FILMIC,
            },
            light_color: frame.light.color,
            wave_count: frame.waves.len() as u32,
            ambient: frame.light.ambient,
            any_glow: u32::from(frame.waves.iter().any(|w| w.light.glow > 0.0)),
            image_size: [frame.width, frame.height],
            tile_origin: origin,
            tile_size: size,
            shadow_casts: 0,
            map_casts: 0,
            // Image NDC x_g = 2(px + ½)/W − 1; tile NDC x_t = 2(px − ox + ½)/tw − 1
            // = x_g·W/tw + (W − 2·ox − tw)/tw. For y (downwards rows) the same with a sign flip.
            ndc_scale: [w / tw, h / th],
            ndc_offset: [(w - 2.0 * ox - tw) / tw, (th - h + 2.0 * oy) / th],
            cast_count: 0,
            map_count: 0,
            plane_count: 0,
            area: u32::from(frame.area_light.is_some()),
            area_position: frame.area_light.as_ref().map_or([0.0; 3], |a| a.position.to_array()),
            outline_reach: outline_reach(frame),
            area_color: frame.area_light.as_ref().map_or([0.0; 3], |a| a.color),
            grid: grid.edge(),
            area_axis: frame.area_light.as_ref().map_or([0.0; 3], |a| a.axis().to_array()),
            area_size: frame.area_light.as_ref().map_or(0.0, |a| a.size),
            area_shape: frame.area_light.as_ref().map_or(LAMP_SEGMENT, |a| lamp_shape(a.shape)),
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        }
    }
}

/// One object's transforms and where its materials start. Keep in sync with `GpuObject` in
/// common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuObject {
    /// Object → world, column-major.
    pub model: [[f32; 4]; 4],
    /// [`Mat4::normal_matrix`] of `model`.
    pub normal_matrix: [[f32; 4]; 4],
    /// Index of the object's first material in the frame's material buffer.
    pub material_base: u32,
    /// Number of its materials (≥ 1); a vertex's slot is clamped to `count − 1`.
    pub material_count: u32,
    /// Padding.
    pub _pad: [u32; 2],
}

impl GpuObject {
    /// The GPU form of `object`, whose materials start at `material_base`.
    pub fn new(object: &Object, material_base: u32) -> Self {
        let m: Mat4 = object.transform;
        Self {
            model: m.cols,
            normal_matrix: m.normal_matrix().cols,
            material_base,
            material_count: object.materials.len().max(1) as u32,
            _pad: [0; 2],
        }
    }
}

/// One mesh vertex as the raster pass reads it (`VertexIn` in raster.wgsl, locations 0–5).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuVertex {
    /// Object-space position.
    pub position: [f32; 3],
    /// Object-space normal.
    pub normal: [f32; 3],
    /// Object-space outline direction ([`hadou_scene::Mesh::outline_normals`]).
    pub outline_normal: [f32; 3],
    /// Texture coordinates.
    pub uv: [f32; 2],
    /// Linear RGBA vertex colour.
    pub color: [f32; 4],
    /// Material slot of the object.
    pub material: u32,
}
