//! [`Frame`]: the plain values a backend draws — one instant of a scene, nothing animated, nothing
//! to parse. Produced by `Scene::at`, consumed by every backend.

use hadou_math::curve::CurveWave;
use hadou_math::energy::{BeamField, CapsuleField, CylinderField, Falloff, Ray, SphereField};
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

/// The camera's orthonormal basis and per-pixel ray construction, shared by both backends.
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
    /// Both backends build their rays with exactly this construction.
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
    /// Linear RGB albedo.
    pub color: [f32; 3],
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
    /// The shape.
    pub shape: WaveShape,
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
