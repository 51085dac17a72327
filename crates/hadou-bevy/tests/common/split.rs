//! Split screen: a scene's camera in the left half of a target and a second camera, looking at
//! the same scene from another side, in the right half (its viewport away from the target's
//! corner), each held to hadou-cpu's render of the frame from its own camera. Shared by
//! `tests/viewports.rs` (the target an image) and `tests/window.rs` (the target a window).

use super::picture::difference;
use bevy::camera::{RenderTarget, Viewport};
use bevy::image::Image;
use bevy::prelude::*;
use hadou_bevy::HadouCamera;
use hadou_math::Vec3f;

/// The largest mean absolute difference of the 8-bit RGB values accepted in each half (the
/// parity bound of `tests/parity.rs`).
pub const MAX_MEAN: f64 = 2.0;

/// The scene, time and the two frames the halves are held to.
pub struct Halves {
    pub file: &'static str,
    pub time: f32,
    pub left: hadou_scene::Frame,
    pub right: hadou_scene::Frame,
}

/// `kamehameha.toml` at 1.5 s, one sample, no glare, from its camera and from its eye turned 35°
/// about the vertical through its target.
pub fn halves(root: &std::path::Path) -> Halves {
    let (file, time) = ("kamehameha.toml", 1.5);
    let mut left = hadou_scene::Scene::load(root.join(file)).unwrap().at(time);
    left.samples = 1;
    left.bloom = None;
    let c = &left.camera;
    let (t, p) = (c.target, c.position);
    let (s, co) = 35f32.to_radians().sin_cos();
    let (dx, dz) = (p.x - t.x, p.z - t.z);
    let eye = Vec3f::new(t.x + co * dx + s * dz, p.y, t.z - s * dx + co * dz);
    let mut right = left.clone();
    right.camera.position = eye;
    right.camera.up = Vec3f::new(0.0, 1.0, 0.0);
    left.camera.up = Vec3f::new(0.0, 1.0, 0.0);
    Halves { file, time, left, right }
}

/// What both cameras draw into (`None`: the primary window), the size of each half, and the
/// second camera's eye and target.
#[derive(Resource)]
pub struct Split {
    pub image: Option<Handle<Image>>,
    pub half: UVec2,
    pub eye: Vec3,
    pub target: Vec3,
}

impl Split {
    /// Each half `halves`' frame size, the second camera at the right frame's eye.
    pub fn new(image: Option<Handle<Image>>, halves: &Halves) -> Split {
        let v = |p: Vec3f| Vec3::new(p.x, p.y, p.z);
        let c = &halves.right.camera;
        Split {
            image,
            half: UVec2::new(halves.left.width, halves.left.height),
            eye: v(c.position),
            target: v(c.target),
        }
    }
}

/// Marks the second camera.
#[derive(Component)]
pub struct Second;

/// What [`split`] reads of the spawned scene camera.
type SceneCamera = (Entity, &'static mut Camera, &'static HadouCamera, &'static Projection);

/// Puts the spawned scene camera into the left half and a second camera of the same settings
/// into the right half.
pub fn split(
    mut commands: Commands,
    mut cameras: Query<SceneCamera, (Added<HadouCamera>, Without<Second>)>,
    split: Res<Split>,
) {
    for (entity, mut camera, settings, projection) in &mut cameras {
        camera.viewport = Some(Viewport { physical_size: split.half, ..default() });
        let mut second = commands.spawn((
            Second,
            Camera3d::default(),
            Camera {
                order: 1,
                viewport: Some(Viewport {
                    physical_position: UVec2::new(split.half.x, 0),
                    physical_size: split.half,
                    ..default()
                }),
                clear_color: ClearColorConfig::None,
                ..default()
            },
            bevy::camera::Hdr,
            bevy::render::view::Msaa::Off,
            bevy::camera::Exposure { ev100: 0.0 },
            bevy::core_pipeline::tonemapping::Tonemapping::None,
            *settings,
            projection.clone(),
            Transform::from_translation(split.eye).looking_at(split.target, Vec3::Y),
        ));
        if let Some(image) = &split.image {
            second.insert(RenderTarget::Image(image.clone().into()));
            commands.entity(entity).insert(RenderTarget::Image(image.clone().into()));
        }
    }
}

/// The `rows × (width · 4)` bytes of the `width`-wide half of `image` (4 bytes a pixel, `2 · width`
/// wide) starting at column `x0`.
fn half(image: &[u8], width: usize, x0: usize) -> Vec<u8> {
    image.chunks_exact(8 * width).flat_map(|row| row[4 * x0..4 * (x0 + width)].iter().copied()).collect()
}

/// Holds each half of `shot` (8-bit sRGB, RGBA or BGRA, `2·w × h`) to hadou-cpu's render of its camera (mean ≤
/// [`MAX_MEAN`]) and the right half apart from the left camera's picture; `what` names the target.
pub fn check(what: &str, halves: &Halves, shot: Image) {
    let (w, h) = (halves.left.width, halves.left.height);
    assert_eq!((shot.width(), shot.height()), (2 * w, h), "{what}: the screenshot's size");
    // RGBA bytes whatever the target's format (a window's surface is often BGRA).
    let bytes = shot.try_into_dynamic().expect("an 8-bit colour screenshot").to_rgba8().into_raw();
    let (lref, rref) = (hadou_cpu::render(&halves.left), hadou_cpu::render(&halves.right));
    let (lb, rb) = (half(&bytes, w as usize, 0), half(&bytes, w as usize, w as usize));
    let (lm, lmax) = difference(&lb, &lref);
    let (rm, rmax) = difference(&rb, &rref);
    let (file, time) = (halves.file, halves.time);
    eprintln!(
        "{what}: {file} at t = {time}, {w}×{h} each: left mean {lm:.3} (largest {lmax}), right mean {rm:.3} (largest {rmax})"
    );
    assert!(lm <= MAX_MEAN, "{what}, left viewport: mean {lm:.3} > {MAX_MEAN} (largest {lmax})");
    assert!(rm <= MAX_MEAN, "{what}, right viewport: mean {rm:.3} > {MAX_MEAN} (largest {rmax})");
    // The two cameras see different pictures, and each half is its own camera's.
    let (cross, _) = difference(&rb, &lref);
    assert!(cross > 2.0 * MAX_MEAN, "{what}: the right half is the left camera's picture (mean {cross:.3})");
}
