//! [`Frame`]: the plain values a backend draws — one instant of a scene, nothing animated, nothing
//! to parse. Produced by `Scene::at`, consumed by every backend. The camera and its basis
//! ([`CameraBasis`]), the light, objects with their meshes, materials and textures, the waves and
//! the colour mapping are here; the frame's shadows ([`Shadow`]) are in `shadow.rs` and its area
//! light ([`AreaLight`]) in `area_light.rs`.

use crate::area_light::AreaLight;
use crate::shadow::Shadow;
pub use hadou_math::bloom::BloomParams;
use hadou_math::curve::{CurveWave, PreparedCurve};
use hadou_math::energy::{Attenuation, BeamField, CapsuleField, CylinderField, Falloff, Ray, SphereField};
pub use hadou_math::toon::{Filter, Ramp, RampKind, Wrap};
use hadou_math::{Mat4, Vec3, Vec3f};
use std::sync::Arc;

/// One instant of a scene, ready to draw.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Image width in pixels, `1..=16384`.
    pub width: u32,
    /// Image height in pixels, `1..=16384`.
    pub height: u32,
    /// Scene time in seconds this frame was evaluated at.
    pub time: f32,
    /// The camera.
    pub camera: Camera,
    /// Linear RGB of pixels where nothing is drawn.
    pub background: [f32; 3],
    /// The simple diffuse light of the opaque scene.
    pub light: Light,
    /// Opaque geometry, already triangulated.
    pub objects: Vec<Object>,
    /// Energy waves, added in this order.
    pub waves: Vec<Wave>,
    /// How summed wave colour becomes the output colour.
    pub color_mapping: ColorMapping,
    /// Hard shadows (`[[shadow]]`), applied to the receivers' shaded colour before the waves.
    pub shadows: Vec<Shadow>,
    /// The `[area_light]` (003's soft shadows), if any.
    pub area_light: Option<AreaLight>,
    /// The `[bloom]` (glare on the linear colour before the colour mapping), if any.
    pub bloom: Option<BloomParams>,
    /// Anti-aliasing samples per pixel (`[image] samples`): 1, 4, 9 or 16, a `k × k` grid
    /// ([`Frame::sample_grid`]). Every surface is drawn, shaded and shadowed once per sample; the waves'
    /// integrals once per pixel where its samples see one surface ([`Frame::sample_frame`]).
    pub samples: u32,
}

/// Samples per pixel a scene gets without `[image] samples`.
pub const DEFAULT_SAMPLES: u32 = 4;
/// How far apart in eye distance (relative to the nearest) the samples of one pixel may be and
/// still count as one surface, whose waves both backends integrate once, along the ray through the
/// pixel's centre clipped at the samples' mean distance ([`Frame::sample_frame`]).
pub const SAMPLE_DEPTH_SPREAD: f32 = 0.01;
/// Largest `samples` (a 4 × 4 grid).
pub const MAX_SAMPLES: u32 = 16;

/// Checks an anti-aliasing sample count: 1, 4, 9 or 16 (a `k × k` grid, `k ≤ 4`).
pub fn check_samples(samples: u32) -> Result<(), String> {
    if matches!(samples, 1 | 4 | 9 | 16) {
        Ok(())
    } else {
        Err(format!(
            "samples {samples} is not one of 1, 4, 9, 16 (a k × k grid of samples per pixel, at most {MAX_SAMPLES})"
        ))
    }
}

/// A frame's sample grid: `edge × edge` samples per image pixel, decided once per frame by
/// [`Frame::sample_grid`] (from `[image] samples` and the `[area_light]`'s budget). Every
/// consumer, both backends, the CLI's band sizes and the GPU's uniforms, reads it from there;
/// the sample frame ([`Frame::sample_frame`]) is a frame of one sample per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleGrid {
    edge: u32,
}

impl SampleGrid {
    /// One sample per pixel.
    pub const SINGLE: SampleGrid = SampleGrid { edge: 1 };

    /// The grid's edge `k`: 1 to 4.
    pub fn edge(self) -> u32 {
        self.edge
    }

    /// Samples per pixel, `k²`.
    pub fn count(self) -> u32 {
        self.edge * self.edge
    }

    /// Whether a pixel is one sample (no anti-aliasing).
    pub fn is_single(self) -> bool {
        self.edge == 1
    }
}

impl Frame {
    /// The frame's `k × k` sample grid: `k = √samples` (1 for a count that is not 4, 9 or 16),
    /// made smaller where an `[area_light]` would otherwise shade more than
    /// [`crate::SOFT_MAX_PIXELS`] samples (its penumbra search works on every sample of the image
    /// at once).
    pub fn sample_grid(&self) -> SampleGrid {
        let mut k = match self.samples {
            4 => 2,
            9 => 3,
            16 => 4,
            _ => 1,
        };
        if self.area_light.is_some() {
            let px = u64::from(self.width) * u64::from(self.height);
            while k > 1 && px * u64::from(k * k) > crate::SOFT_MAX_PIXELS {
                k -= 1;
            }
        }
        SampleGrid { edge: k }
    }

    /// The frame whose pixels are this frame's samples: `k` times as wide and as high
    /// ([`Frame::sample_grid`]), one sample each, without the `[bloom]` (which works on the resolved
    /// image). Sample `(i, j)` of pixel `(x, y)` is the sample frame's pixel `(k·x + i, k·y + j)`,
    /// centred at `x + (i + ½)/k`: an ordered grid. Both backends draw the surfaces of this frame
    /// and resolve each pixel by the box filter over its samples; the camera, and so every ray
    /// through a pixel's centre, is the same in both frames.
    pub fn sample_frame(&self) -> Frame {
        let k = self.sample_grid().edge();
        Frame { width: self.width * k, height: self.height * k, samples: 1, bloom: None, ..self.clone() }
    }
}

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position `S`.
    pub position: Vec3f,
    /// Point looked at.
    pub target: Vec3f,
    /// Up vector (not parallel to the view direction).
    pub up: Vec3f,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_deg: f32,
    /// Near plane distance, `> 0`.
    pub near: f32,
    /// Far plane distance, `> near`.
    pub far: f32,
}

/// The camera's orthonormal basis, which both backends project and build their rays from, and the
/// scalar per-pixel ray construction ([`CameraBasis::pixel_dir`], [`CameraBasis::wave_ray`]) their
/// batched and WGSL ray builders mirror.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraBasis {
    /// Eye.
    pub eye: Vec3f,
    /// Unit forward (towards the target).
    pub forward: Vec3f,
    /// Unit right.
    pub right: Vec3f,
    /// Unit up (perpendicular to forward and right).
    pub up: Vec3f,
    /// `tan(fov_y / 2)`.
    pub tan_half_fov: f32,
    /// Width / height.
    pub aspect: f32,
}

impl Camera {
    /// The camera's basis for an image of `width × height`.
    pub fn basis(&self, width: u32, height: u32) -> CameraBasis {
        let forward = (self.target - self.position).normalize_or(Vec3::new(0.0, 0.0, -1.0));
        let right = forward.cross(self.up).normalize_or(forward.orthonormal_basis().0);
        let up = right.cross(forward);
        CameraBasis {
            eye: self.position,
            forward,
            right,
            up,
            tan_half_fov: (self.fov_y_deg.to_radians() * 0.5).tan(),
            aspect: width as f32 / height as f32,
        }
    }
}

impl CameraBasis {
    /// Direction through the centre of pixel `(px, py)` (`py = 0` is the top row), scaled so its
    /// component along `forward` is exactly 1: the point at view depth `z` is `eye + z·dir`.
    /// `hadou-cpu`'s wave pass builds the same directions eight at a time with the same
    /// operations (`waves::WavePass::rays`), `hadou-gpu` per pixel in `shaders/common.wgsl`'s
    /// `pixel_dir`; keep in sync.
    #[inline]
    pub fn pixel_dir(&self, px: f32, py: f32, width: u32, height: u32) -> Vec3f {
        let ndc_x = 2.0 * (px + 0.5) / width as f32 - 1.0;
        let ndc_y = 1.0 - 2.0 * (py + 0.5) / height as f32;
        self.forward
            + self.right * (ndc_x * self.tan_half_fov * self.aspect)
            + self.up * (ndc_y * self.tan_half_fov)
    }

    /// The integration ray of pixel `(px, py)` for a wave with the given falloff (002 §3.3.3 and
    /// §3.3.5, eq. 3.12–3.13): the eye `S`, the far point `E` on the far plane, and the span
    /// clipped at the visible surface. `surface` is the eye distance of the visible opaque surface,
    /// or `None` where nothing is drawn.
    ///
    /// - [`Falloff::Faithful`]: `dir = Q = E − S`, `t ∈ [0, g]`, `g = d / |E − S|` (eq. 3.12),
    ///   `t_far = 1`.
    /// - [`Falloff::InverseSquare`]: `dir` unit, `t ∈ [0, d]` (or `[0, ∞)` with nothing drawn),
    ///   `t_far = |E − S|` (used only by attenuation).
    ///
    /// This is the scalar reference; no render path calls it. The backends mirror it:
    /// `hadou-cpu`'s wave pass with the same operations, eight pixels at a time
    /// (`waves::WavePass::rays`), and `hadou-gpu` per pixel in `shaders/wave.wgsl`'s `wave_ray`;
    /// keep the three in sync. `hadou-cpu`'s `tests/lanes.rs` checks its batched pass against the
    /// scalar kernels along these rays (pixels where nothing is drawn); the GPU is checked against
    /// the CPU. `hadou bench` (its curve-accuracy samples and the kernel-only rows of its limit
    /// table) builds its rays here too.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn wave_ray(
        &self,
        falloff: Falloff,
        far: f32,
        px: f32,
        py: f32,
        width: u32,
        height: u32,
        surface: Option<f32>,
    ) -> WaveRay {
        let dir = self.pixel_dir(px, py, width, height);
        let len = dir.length();
        let far_dist = far * len;
        match falloff {
            Falloff::Faithful => {
                let g = surface.map_or(1.0, |d| (d / far_dist).min(1.0));
                WaveRay { ray: Ray { origin: self.eye, dir: dir * far }, t0: 0.0, t1: g, t_far: 1.0 }
            }
            Falloff::InverseSquare => {
                let t1 = surface.unwrap_or(f32::INFINITY);
                WaveRay { ray: Ray { origin: self.eye, dir: dir / len }, t0: 0.0, t1, t_far: far_dist }
            }
        }
    }

    /// World → view space: `(x right, y up, z forward depth)`.
    #[inline]
    pub fn to_view(&self, p: Vec3f) -> Vec3f {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }
}

/// A pixel's wave-integration ray and span; see [`CameraBasis::wave_ray`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaveRay {
    /// The ray `S + t·dir`.
    pub ray: Ray<f32>,
    /// Start of the span (the eye).
    pub t0: f32,
    /// End of the span: the visible surface, the far point, or `+∞`.
    pub t1: f32,
    /// Parameter of the far point (normalises attenuation).
    pub t_far: f32,
}

/// The scene's directional light for the simple diffuse shading of opaque objects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Unit direction the light travels (from the light towards the scene).
    pub direction: Vec3f,
    /// Linear RGB intensity.
    pub color: [f32; 3],
    /// Ambient term added to every lit surface, linear RGB.
    pub ambient: [f32; 3],
}

/// An indexed triangle mesh in object space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Unit vertex normals, one per position.
    pub normals: Vec<[f32; 3]>,
    /// Triangle list, counter-clockwise front faces.
    pub indices: Vec<u32>,
    /// Texture coordinates, one per position, or empty (no textures can be sampled).
    pub uvs: Vec<[f32; 2]>,
    /// Linear RGBA vertex colours, one per position, or empty (white).
    pub colors: Vec<[f32; 4]>,
    /// Index into [`Mesh::materials`] per vertex (the three vertices of a triangle agree), or
    /// empty (material 0 everywhere).
    pub material_ids: Vec<u32>,
    /// The materials the mesh came with (a glTF file's), or empty (one default material).
    pub materials: Vec<Material>,
    /// Outline directions, one per position: unit normals averaged over every vertex at the same
    /// position, so an inverted hull pushed along them stays closed at hard edges (000 §2.3).
    /// Empty until [`crate::mesh::with_outline_normals`] fills them; backends then fall back to
    /// `normals`.
    pub outline_normals: Vec<[f32; 3]>,
}

impl Mesh {
    /// Material slot of vertex `v` (0 when the mesh has no per-vertex ids).
    #[inline]
    pub fn material_of(&self, v: usize) -> u32 {
        self.material_ids.get(v).copied().unwrap_or(0)
    }
}

/// An RGBA8 image for texturing: colour channels sRGB-encoded (as PNG and JPEG store them), alpha
/// linear, rows from the top. `Eq`, so comparing two `Arc`s of one image is a pointer test.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Texture {
    /// Where it came from, for messages.
    pub name: String,
    /// Width in texels, `≥ 1`.
    pub width: u32,
    /// Height in texels, `≥ 1`.
    pub height: u32,
    /// `width × height` texels.
    pub texels: Vec<[u8; 4]>,
}

/// A texture as a material uses it: the image and how it is sampled
/// ([`hadou_math::toon::sample`]: level 0, bilinear or nearest, per-axis wrapping).
#[derive(Clone, Debug, PartialEq)]
pub struct TextureRef {
    /// The image (shared between materials and frames).
    pub image: Arc<Texture>,
    /// Wrapping along u and v.
    pub wrap: [Wrap; 2],
    /// Filtering.
    pub filter: Filter,
}

impl TextureRef {
    /// Samples the texture at `uv` (linear RGBA).
    #[inline]
    pub fn sample(&self, uv: [f32; 2]) -> [f32; 4] {
        let t = &self.image;
        hadou_math::toon::sample(&t.texels, t.width, t.height, self.wrap, self.filter, uv)
    }
}

/// How a material responds to the scene's directional light (its look without the wave).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ShadingModel {
    /// `albedo · (ambient + light · max(0, N·(−L)))` (`hadou_math::shade::diffuse`).
    #[default]
    Diffuse,
    /// `albedo · ramp(N·(−L))`: the ramp's colours multiply the albedo (toon shading).
    Toon,
    /// `albedo`, unaffected by lights (glTF `KHR_materials_unlit`).
    Unlit,
}

/// The inverted-hull outline of a material (000 §2.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outline {
    /// Width `d`: the hull's vertices move `d · |view depth|` along their outline normal, so the
    /// outline is about `d / (2·tan(fov/2)) · image height` pixels wide at any distance.
    pub width: f32,
    /// Flat linear RGB colour.
    pub color: [f32; 3],
}

/// How a surface is shaded: its own look and its response to the waves' light.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name (from the scene file or the glTF file), for messages.
    pub name: String,
    /// Response to the scene light.
    pub model: ShadingModel,
    /// Linear RGB base colour; multiplied by the base texture and the vertex colour.
    pub base_color: [f32; 3],
    /// Base-colour texture (glTF `baseColorTexture`).
    pub base_texture: Option<TextureRef>,
    /// Feature texture `T` of 000 §2.2: multiplies the shaded colour, `H = S · T`.
    pub feature_texture: Option<TextureRef>,
    /// The toon ramp of [`ShadingModel::Toon`] (multipliers of the albedo).
    pub ramp: Ramp,
    /// `β ∈ [0, 1]`: 0 = the material's own look, 1 = the wave's look (000 §2.1: "the object's
    /// own colour is ignored under the wave's light"); the shaded colour is
    /// `(1 − β)·own + β·wave`.
    pub wave_blend: f32,
    /// Inverted-hull outline, if any.
    pub outline: Option<Outline>,
    /// The MToon look (VRM's `VRMC_materials_mtoon`, or VRM 0.x's `VRM/MToon` converted), which
    /// both backends draw in place of [`Material::model`] when present: `model` stays
    /// [`ShadingModel::Toon`] with `ramp` the two-band approximation of the MToon step, for
    /// renderers that do not draw MToon (hadou-bevy's material).
    pub mtoon: Option<Arc<Mtoon>>,
}

/// How an MToon outline's width is measured (`outlineWidthMode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum OutlineWidthMode {
    /// No outline.
    #[default]
    None,
    /// `outlineWidthFactor` in world units (metres).
    World,
    /// `outlineWidthFactor` as a fraction of the screen height.
    Screen,
}

/// The parameters of an MToon material (`VRMC_materials_mtoon` 1.0; VRM 0.x's MToon properties
/// are converted to these). Colours are linear RGB; textures are sampled at the (UV-animated)
/// texture coordinates of the material, the matcap at the view-space normal. The formulas are
/// `hadou_math::mtoon`'s.
#[derive(Clone, Debug, PartialEq)]
pub struct Mtoon {
    /// `shadeColorFactor`: the colour of the shaded side.
    pub shade_color: [f32; 3],
    /// `shadeMultiplyTexture`: multiplies `shade_color`.
    pub shade_texture: Option<TextureRef>,
    /// `shadingShiftFactor`: added to `N·L` before the step.
    pub shading_shift: f32,
    /// `shadingShiftTexture`: its red channel times `shift_texture_scale` is added to the shift.
    pub shift_texture: Option<TextureRef>,
    /// `shadingShiftTexture.scale`.
    pub shift_texture_scale: f32,
    /// `shadingToonyFactor` in [0, 1]: the step runs over `[−1 + toony, 1 − toony]`.
    pub toony: f32,
    /// `giEqualizationFactor` in [0, 1]. hadou's ambient light is uniform, so the equalised and
    /// the raw global illumination are the same; kept for completeness.
    pub gi_equalization: f32,
    /// `parametricRimColorFactor`.
    pub rim_color: [f32; 3],
    /// `parametricRimFresnelPowerFactor` (≥ 0).
    pub rim_fresnel_power: f32,
    /// `parametricRimLiftFactor`.
    pub rim_lift: f32,
    /// `rimMultiplyTexture`: multiplies the rim (parametric rim and matcap).
    pub rim_texture: Option<TextureRef>,
    /// `rimLightingMixFactor` in [0, 1]: how much the light colour tints the rim.
    pub rim_lighting_mix: f32,
    /// `matcapFactor`.
    pub matcap_color: [f32; 3],
    /// `matcapTexture`, sampled at the view-space normal; absent: no matcap term.
    pub matcap_texture: Option<TextureRef>,
    /// `outlineWidthMode`.
    pub outline_mode: OutlineWidthMode,
    /// `outlineWidthFactor` (metres, or a fraction of the screen height). The loader turns the
    /// material's [`Material::outline`] on with this width and `outline_color`; the backends draw
    /// it through [`Material::hull_push`], [`Material::hull_pixels`] and [`Material::outline_rgb`].
    pub outline_width: f32,
    /// `outlineWidthMultiplyTexture`: its green channel at a vertex multiplies the outline width
    /// there (baked into the length of the mesh's outline directions by
    /// [`crate::mesh::with_outline_normals`]; the hull and the edge pass use that length).
    pub outline_width_texture: Option<TextureRef>,
    /// `outlineColorFactor`.
    pub outline_color: [f32; 3],
    /// `outlineLightingMixFactor` in [0, 1].
    pub outline_lighting_mix: f32,
    /// `uvAnimationMaskTexture`: channel [`Mtoon::uv_mask_channel`] scales the UV animation.
    pub uv_mask_texture: Option<TextureRef>,
    /// The mask's channel: 2 (blue) in VRM 1.0, 0 (red) in VRM 0.x.
    pub uv_mask_channel: u8,
    /// `uvAnimationScrollXSpeedFactor`, `uvAnimationScrollYSpeedFactor`: UV units per second.
    pub uv_scroll: [f32; 2],
    /// `uvAnimationRotationSpeedFactor`: radians per second about UV (0.5, 0.5).
    pub uv_rotation: f32,
    /// glTF `emissiveFactor`.
    pub emissive: [f32; 3],
    /// glTF `emissiveTexture`.
    pub emissive_texture: Option<TextureRef>,
}

impl Default for Mtoon {
    /// The specification's defaults.
    fn default() -> Self {
        Mtoon {
            shade_color: [0.0; 3],
            shade_texture: None,
            shading_shift: 0.0,
            shift_texture: None,
            shift_texture_scale: 1.0,
            toony: 0.9,
            gi_equalization: 0.9,
            rim_color: [0.0; 3],
            rim_fresnel_power: 5.0,
            rim_lift: 0.0,
            rim_texture: None,
            rim_lighting_mix: 1.0,
            matcap_color: [1.0; 3],
            matcap_texture: None,
            outline_mode: OutlineWidthMode::None,
            outline_width: 0.0,
            outline_width_texture: None,
            outline_color: [0.0; 3],
            outline_lighting_mix: 1.0,
            uv_mask_texture: None,
            uv_mask_channel: 2,
            uv_scroll: [0.0; 2],
            uv_rotation: 0.0,
            emissive: [0.0; 3],
            emissive_texture: None,
        }
    }
}

impl Material {
    /// The plain diffuse material of colour `color`: not lit by waves, no outline.
    pub fn diffuse(color: [f32; 3]) -> Self {
        Material {
            name: "default".into(),
            model: ShadingModel::Diffuse,
            base_color: color,
            base_texture: None,
            feature_texture: None,
            ramp: Ramp::two_band(0.0, [0.6; 3], 0.0),
            wave_blend: 0.0,
            outline: None,
            mtoon: None,
        }
    }
}

impl Material {
    /// How the material's outline width is measured: hadou's `d` (view-depth-scaled, constant on
    /// screen), or an MToon outline's mode ([`Mtoon::outline_mode`]).
    fn outline_mode(&self) -> OutlineWidthMode {
        self.mtoon.as_ref().map_or(OutlineWidthMode::None, |t| t.outline_mode)
    }

    /// How far the outline hull (000 §2.3) moves a vertex at view depth `z` along its unit outline
    /// normal, for a camera of `tan_half_fov = tan(fov/2)`: hadou's `d·|z|` (`Outline::width` =
    /// `d`); for an MToon outline (`VRMC_materials_mtoon` "Outline") in screen mode, whose
    /// `Outline::width` is a fraction `w` of the image height, `2·tan_half_fov·w·|z|` (`w·height`
    /// pixels on screen, [`hadou_math::outline::hull_pixels`]); in world mode `w` world units. 0
    /// without an outline or for a width that is not positive.
    pub fn hull_push(&self, z: f32, tan_half_fov: f32) -> f32 {
        let Some(o) = self.outline else { return 0.0 };
        if o.width.is_nan() || o.width <= 0.0 {
            return 0.0;
        }
        match self.outline_mode() {
            OutlineWidthMode::World => o.width,
            OutlineWidthMode::Screen => 2.0 * tan_half_fov * o.width * z.abs(),
            OutlineWidthMode::None => o.width * z.abs(),
        }
    }

    /// The hull's width on screen in pixels where the surface is at view depth `z`
    /// ([`hadou_math::outline::hull_pixels`] of the push over `|z|`; the depth matters only in
    /// MToon's world mode, whose `|z|` is taken at least [`MIN_OUTLINE_DEPTH`]). The edge pass
    /// draws contact outlines this wide.
    pub fn hull_pixels(&self, z: f32, tan_half_fov: f32, height: u32) -> f32 {
        let d = match (self.outline, self.outline_mode()) {
            (None, _) => return 0.0,
            (Some(o), OutlineWidthMode::World) => o.width / z.abs().max(MIN_OUTLINE_DEPTH),
            (Some(o), OutlineWidthMode::Screen) => 2.0 * tan_half_fov * o.width,
            (Some(o), OutlineWidthMode::None) => o.width,
        };
        hadou_math::outline::hull_pixels(d, tan_half_fov, height)
    }

    /// Whether the hull's width on screen depends on the depth (an MToon outline in world mode):
    /// the edge pass then searches its widest window.
    pub fn outline_in_world_units(&self) -> bool {
        self.outline.is_some() && self.outline_mode() == OutlineWidthMode::World
    }

    /// The colour outline pixels of this material take under `light`: `Outline::color`; for an
    /// MToon outline `outlineColor · mix(1, light + ambient, outlineLightingMix)` per channel
    /// (`VRMC_materials_mtoon` "Outline", the light reaching the surface as for the rim).
    pub fn outline_rgb(&self, light: &Light) -> [f32; 3] {
        let Some(o) = self.outline else { return [0.0; 3] };
        match &self.mtoon {
            Some(t) if t.outline_mode != OutlineWidthMode::None => {
                let mix = hadou_math::mtoon::lighting_mix(
                    std::array::from_fn(|k| light.color[k] + light.ambient[k]),
                    t.outline_lighting_mix,
                );
                std::array::from_fn(|k| o.color[k] * mix[k])
            }
            _ => o.color,
        }
    }
}

/// The nearest view depth at which an MToon world-unit outline's width on screen is taken
/// ([`Material::hull_pixels`]).
pub const MIN_OUTLINE_DEPTH: f32 = 1.0e-3;

impl Default for Material {
    fn default() -> Self {
        Material::diffuse([0.8; 3])
    }
}

/// A mesh placed in the world.
#[derive(Clone, Debug)]
pub struct Object {
    /// Name from the scene file.
    pub name: String,
    /// Geometry (shared between frames).
    pub mesh: Arc<Mesh>,
    /// Object → world.
    pub transform: Mat4,
    /// One material per slot of the mesh (`mesh.material_ids` index it), at least one.
    pub materials: Vec<Material>,
}

impl Object {
    /// An object with one diffuse material of `color`.
    pub fn new(name: impl Into<String>, mesh: Arc<Mesh>, transform: Mat4, color: [f32; 3]) -> Self {
        Object { name: name.into(), mesh, transform, materials: vec![Material::diffuse(color)] }
    }

    /// The material of slot `id` (the last one for an out-of-range id).
    #[inline]
    pub fn material(&self, id: u32) -> &Material {
        let n = self.materials.len();
        &self.materials[(id as usize).min(n.saturating_sub(1))]
    }
}

/// How a wave lights surfaces (000 §2.1): the light point on its centre line, the ramp over
/// `m = N·L`, and an optional glow in the wave's own colour.
#[derive(Clone, Debug, PartialEq)]
pub struct WaveLight {
    /// The look `ramp(m)` (absolute linear RGB) the wave gives a surface.
    pub ramp: Ramp,
    /// Glow: adds `glow · rgb · a · ρ(d)` to lit surfaces (`ρ` the wave's density at the
    /// point; 0 = off, the thesis).
    pub glow: f32,
}

impl Default for WaveLight {
    /// White bands ([`Ramp::for_wave_color`] of white), no glow.
    fn default() -> Self {
        WaveLight { ramp: Ramp::for_wave_color([1.0; 3]), glow: 0.0 }
    }
}

/// Where a wave's light comes from: its centre line.
#[derive(Clone, Debug, PartialEq)]
pub enum LightLine {
    /// One point (sphere waves).
    Point(Vec3f),
    /// A segment (capsules and bulged beams: `M..M2`).
    Segment(Vec3f, Vec3f),
    /// An infinite line through a point along a unit direction (cylinder waves).
    Line(Vec3f, Vec3f),
    /// A polyline through points of the curve (curved waves).
    Polyline(Vec<Vec3f>),
}

impl LightLine {
    /// The nearest point of the line to `p` (000 §2.1, SPEC.md §2.1).
    pub fn nearest(&self, p: Vec3f) -> Vec3f {
        use hadou_math::toon::{nearest_on_line, nearest_on_polyline, nearest_on_segment};
        match self {
            LightLine::Point(c) => *c,
            LightLine::Segment(a, b) => nearest_on_segment(p, *a, *b),
            LightLine::Line(a, d) => nearest_on_line(p, *a, *d),
            LightLine::Polyline(pts) => nearest_on_polyline(p, pts),
        }
    }
}

/// One energy wave of a frame.
#[derive(Clone, Debug)]
pub struct Wave {
    /// Name from the scene file (reported by `hadou probe`).
    pub name: String,
    /// Base colour `(r, g, b, a)`; the wave adds `rgb · a · I` (002 §3.3, SPEC.md §1.1).
    pub color: [f32; 4],
    /// Density law and ray measure.
    pub falloff: Falloff,
    /// Core radius `r_c ≥ 0` (see [`hadou_math::energy::FieldParams`]).
    pub core_radius: f32,
    /// Exponent `j ∈ [0, 64]` of the distance attenuation `(1 − u)^j`, `u = t/t_far` (002 eq.
    /// 3.23, SPEC.md §1.4; 0: none), the scene file's `j`. The analytic shapes read it here
    /// ([`Wave::attenuation_on`]); a curve reads its own copy, `CurveWave::attenuation`.
    pub attenuation: f32,
    /// The shape.
    pub shape: WaveShape,
    /// Its light on surfaces.
    pub light: WaveLight,
}

/// What a front end sets over a scene's frame: the CLI's `--width`, `--height` and `--samples`,
/// an export's sizes, the web page's `width=` and `height=`. The one place they are applied
/// ([`FrameOverrides::apply`], [`crate::Scene::at_with`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameOverrides {
    /// The image width in pixels, over `[image] width`.
    pub width: Option<u32>,
    /// The image height in pixels, over `[image] height`.
    pub height: Option<u32>,
    /// Samples per pixel, over `[image] samples`.
    pub samples: Option<u32>,
}

impl FrameOverrides {
    /// Sets what is given on `frame`.
    pub fn apply(&self, frame: &mut Frame) {
        if let Some(w) = self.width {
            frame.width = w;
        }
        if let Some(h) = self.height {
            frame.height = h;
        }
        if let Some(s) = self.samples {
            frame.samples = s;
        }
    }

    /// Whether a size is given.
    pub fn sets_size(&self) -> bool {
        self.width.is_some() || self.height.is_some()
    }
}

/// The shape of a wave.
#[derive(Clone, Debug)]
pub enum WaveShape {
    /// A sphere field.
    Sphere(SphereField<f32>),
    /// An infinite cylinder field.
    Cylinder(CylinderField<f32>),
    /// A capsule (straight beam).
    Capsule(CapsuleField<f32>),
    /// A bulged beam (capsule plus bulbs).
    Beam(BeamField<f32>),
    /// A curved wave.
    Curve(CurveWave),
}

impl WaveShape {
    /// The curve, for a curved wave; `None` for the shapes with a closed form. Exhaustive, so a
    /// new shape must say which it is; code that treats the two groups apart asks here rather
    /// than matching with a catch-all.
    pub fn curve(&self) -> Option<&CurveWave> {
        match self {
            WaveShape::Sphere(_) | WaveShape::Cylinder(_) | WaveShape::Capsule(_) | WaveShape::Beam(_) => {
                None
            }
            WaveShape::Curve(c) => Some(c),
        }
    }
}

/// How the summed wave colour and the scene colour become the output colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColorMapping {
    /// The mapping.
    pub mode: ToneMode,
    /// Multiplier applied to the wave colour before mapping.
    pub exposure: f32,
}

/// Colour mapping modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ToneMode {
    /// The thesis: `scene + Σ rgb·a·I`, clamped to [0, 1] per channel (002 §3.3).
    Faithful,
    /// A white-core filmic mapping: dense energy saturates towards white, smoothly.
    #[default]
    Filmic,
}

impl Wave {
    /// A wave with the default light ([`Ramp::for_wave_color`], no glow).
    pub fn new(
        name: impl Into<String>,
        color: [f32; 4],
        falloff: Falloff,
        core_radius: f32,
        shape: WaveShape,
    ) -> Self {
        let light = WaveLight { ramp: Ramp::for_wave_color([color[0], color[1], color[2]]), glow: 0.0 };
        Wave { name: name.into(), color, falloff, core_radius, attenuation: 0.0, shape, light }
    }

    /// The attenuation of an analytic wave on a ray whose far point is at ray parameter `t_far`
    /// (1 for the faithful law, the far point's distance for inverse square; see
    /// [`WaveRay`]) — `j = 0` (none) for curves, which attenuate in their own
    /// integrator.
    pub fn attenuation_on(&self, t_far: f32) -> Attenuation<f32> {
        match self.shape.curve() {
            Some(_) => Attenuation::none(),
            None => Attenuation { j: self.attenuation, t_far },
        }
    }

    /// The wave's centre line as a light (000 §2.1, SPEC.md §2.1): the centre of a sphere, the
    /// segment `M..M₂` of a capsule or bulged beam, the axis of a cylinder, and for a curve the
    /// polyline of [`PreparedCurve::light_polyline`] (`prepared` is used when given, else the
    /// curve is prepared here).
    pub fn light_line(&self, prepared: Option<&PreparedCurve>) -> LightLine {
        match &self.shape {
            WaveShape::Sphere(f) => LightLine::Point(f.center),
            WaveShape::Cylinder(f) => LightLine::Line(f.point, f.dir),
            WaveShape::Capsule(f) => LightLine::Segment(f.m, f.m2()),
            WaveShape::Beam(f) => LightLine::Segment(f.capsule.m, f.capsule.m2()),
            WaveShape::Curve(c) => {
                let owned;
                let prep = match prepared {
                    Some(p) => p,
                    None => {
                        owned = hadou_math::curve::prepare(c);
                        &owned
                    }
                };
                LightLine::Polyline(prep.light_polyline())
            }
        }
    }

    /// The strength `α·a` that weighs this wave against others at a surface point
    /// ([`hadou_math::toon::dominance`]): the colour's alpha times the field's largest strength.
    pub fn light_strength(&self) -> f32 {
        let alpha = match &self.shape {
            WaveShape::Sphere(f) => f.alpha,
            WaveShape::Cylinder(f) => f.alpha,
            WaveShape::Capsule(f) => f.alpha_s.max(f.alpha_c),
            WaveShape::Beam(f) => {
                f.capsule.alpha_s.max(f.capsule.alpha_c).max(f.head_alpha).max(f.muzzle_alpha)
            }
            WaveShape::Curve(c) => c.alpha,
        };
        (self.color[3] * alpha).max(0.0)
    }
}
