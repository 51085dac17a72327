//! The GPU-visible structs: one Rust definition each, `bytemuck::Pod` with explicit padding.
//!
//! Keep in sync with `src/shaders/common.wgsl` (same names, same field order, same padding);
//! `shaders::tests::gpu_structs_match_their_rust_definitions` checks every member offset and
//! struct size against the layout naga computes for the WGSL side.

use bytemuck::{Pod, Zeroable};
use hadou_math::energy::Falloff;
use hadou_math::{Mat4, Vec3f};
use hadou_scene::{CameraBasis, Frame, Object, ToneMode, Wave, WaveShape};

/// `GpuWave::kind` of a sphere field. Keep in sync with `WAVE_SPHERE` in common.wgsl.
pub const WAVE_SPHERE: u32 = 0;
/// `GpuWave::kind` of an infinite cylinder field. Keep in sync with `WAVE_CYLINDER`.
pub const WAVE_CYLINDER: u32 = 1;
/// `GpuWave::kind` of a capsule field. Keep in sync with `WAVE_CAPSULE`.
pub const WAVE_CAPSULE: u32 = 2;
/// `GpuWave::kind` of a bulged beam. Keep in sync with `WAVE_BEAM`.
pub const WAVE_BEAM: u32 = 3;
/// `GpuWave::falloff` of [`Falloff::Faithful`]. Keep in sync with `FALLOFF_FAITHFUL`.
pub const FALLOFF_FAITHFUL: u32 = 0;
/// `GpuWave::falloff` of [`Falloff::InverseSquare`]. Keep in sync with `FALLOFF_INVERSE_SQUARE`.
pub const FALLOFF_INVERSE_SQUARE: u32 = 1;
/// `FrameUniforms::tone_mode` of [`ToneMode::Faithful`]. Keep in sync with `TONE_FAITHFUL`.
pub const TONE_FAITHFUL: u32 = 0;
/// `FrameUniforms::tone_mode` of [`ToneMode::Filmic`]. Keep in sync with `TONE_FILMIC`.
pub const TONE_FILMIC: u32 = 1;

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
    /// Padding.
    pub _pad0: u32,
    /// Whole image size in pixels.
    pub image_size: [u32; 2],
    /// Top-left pixel of the tile in the image.
    pub tile_origin: [u32; 2],
    /// Tile size in pixels.
    pub tile_size: [u32; 2],
    /// Padding.
    pub _pad1: [u32; 2],
    /// Tile NDC = image NDC · scale + offset.
    pub ndc_scale: [f32; 2],
    /// See `ndc_scale`.
    pub ndc_offset: [f32; 2],
}

impl FrameUniforms {
    /// Uniforms of the tile at `origin` with `size` pixels, for `frame` seen through `basis`.
    pub fn new(frame: &Frame, basis: &CameraBasis, origin: [u32; 2], size: [u32; 2]) -> Self {
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
            _pad0: 0,
            image_size: [frame.width, frame.height],
            tile_origin: origin,
            tile_size: size,
            _pad1: [0; 2],
            // Image NDC x_g = 2(px + ½)/W − 1; tile NDC x_t = 2(px − ox + ½)/tw − 1
            // = x_g·W/tw + (W − 2·ox − tw)/tw. For y (downwards rows) the same with a sign flip.
            ndc_scale: [w / tw, h / th],
            ndc_offset: [(w - 2.0 * ox - tw) / tw, (th - h + 2.0 * oy) / th],
        }
    }
}

/// One object's transforms and albedo. Keep in sync with `GpuObject` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuObject {
    /// Object → world, column-major.
    pub model: [[f32; 4]; 4],
    /// [`Mat4::normal_matrix`] of `model`.
    pub normal_matrix: [[f32; 4]; 4],
    /// Linear RGB albedo.
    pub color: [f32; 3],
    /// Padding.
    pub _pad: f32,
}

impl GpuObject {
    /// The GPU form of `object`.
    pub fn new(object: &Object) -> Self {
        let m: Mat4 = object.transform;
        Self { model: m.cols, normal_matrix: m.normal_matrix().cols, color: object.color, _pad: 0.0 }
    }
}

/// One analytic wave. Keep in sync with `GpuWave` in common.wgsl.
///
/// | kind | `p0` | `p1` | `p2` |
/// |---|---|---|---|
/// | sphere | centre `M`, `α_s` | — | — |
/// | cylinder | point `M`, `α_c` | unit axis `D`, — | — |
/// | capsule | `M`, `α_s` | `D`, `α_c` | `length`, —, — |
/// | beam | `M`, `α_s` | `D`, `α_c` | `length`, `head_alpha`, `muzzle_alpha` |
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuWave {
    /// Base colour `(r, g, b, a)`.
    pub color: [f32; 4],
    /// One of the `WAVE_*` codes.
    pub kind: u32,
    /// [`FALLOFF_FAITHFUL`] or [`FALLOFF_INVERSE_SQUARE`].
    pub falloff: u32,
    /// Core radius `r_c`.
    pub core_radius: f32,
    /// Padding.
    pub _pad: u32,
    /// See the table above.
    pub p0: [f32; 4],
    /// See the table above.
    pub p1: [f32; 4],
    /// See the table above.
    pub p2: [f32; 4],
}

fn v4(v: Vec3f, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

impl GpuWave {
    /// The GPU form of an analytic wave, or `None` for a curved wave (no WGSL twin yet).
    pub fn new(wave: &Wave) -> Option<Self> {
        let mut g = Self {
            color: wave.color,
            kind: 0,
            falloff: match wave.falloff {
                Falloff::Faithful => FALLOFF_FAITHFUL,
                Falloff::InverseSquare => FALLOFF_INVERSE_SQUARE,
            },
            core_radius: wave.core_radius,
            _pad: 0,
            p0: [0.0; 4],
            p1: [0.0; 4],
            p2: [0.0; 4],
        };
        match &wave.shape {
            WaveShape::Sphere(s) => {
                g.kind = WAVE_SPHERE;
                g.p0 = v4(s.center, s.alpha);
            }
            WaveShape::Cylinder(c) => {
                g.kind = WAVE_CYLINDER;
                g.p0 = v4(c.point, c.alpha);
                g.p1 = v4(c.dir, 0.0);
            }
            WaveShape::Capsule(c) => {
                g.kind = WAVE_CAPSULE;
                g.p0 = v4(c.m, c.alpha_s);
                g.p1 = v4(c.d, c.alpha_c);
                g.p2 = [c.length, 0.0, 0.0, 0.0];
            }
            WaveShape::Beam(b) => {
                let c = &b.capsule;
                g.kind = WAVE_BEAM;
                g.p0 = v4(c.m, c.alpha_s);
                g.p1 = v4(c.d, c.alpha_c);
                g.p2 = [c.length, b.head_alpha, b.muzzle_alpha, 0.0];
            }
            // GAP(curves): curved waves need a WGSL port of hadou_math::curve's integrator.
            WaveShape::Curve(_) => return None,
        }
        Some(g)
    }
}

/// One mesh vertex as the raster pass reads it (locations 0 and 1 of `VertexIn` in raster.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuVertex {
    /// Object-space position.
    pub position: [f32; 3],
    /// Object-space normal.
    pub normal: [f32; 3],
}
