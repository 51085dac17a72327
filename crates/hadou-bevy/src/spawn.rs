//! Spawning a [`HadouScene`] asset: [`HadouSceneRoot`] names the scene; once it has loaded, its
//! camera, light, objects and waves become entities under the root, and every frame the scene's
//! tracks at the root's clock set the waves, the object transforms and the camera.

use crate::asset::HadouScene;
use crate::camera::{HadouCamera, ViewMapping};
use crate::material::HadouMaterial;
use crate::wave::HadouWave;
use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;
use hadou_scene::Frame;

/// Spawns the scene `scene` under this entity once it has loaded (nothing, with the loader's
/// error logged by Bevy's asset server, if it fails to load).
#[derive(Component, Clone, Debug)]
#[require(Transform, Visibility)]
pub struct HadouSceneRoot {
    /// The scene asset.
    pub scene: Handle<HadouScene>,
    /// Its clock.
    pub clock: SceneClock,
}

/// Which time of a scene's tracks a [`HadouSceneRoot`] shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneClock {
    /// Seconds since the scene was spawned, from 0, starting again after its last key.
    Running,
    /// Always this time, in seconds.
    Frozen(f32),
}

/// What a spawned scene made, in the scene's order; on the root.
#[derive(Component, Debug)]
pub struct SpawnedScene {
    /// Scene seconds since spawning (what [`SceneClock::Running`] shows).
    pub elapsed: f32,
    /// The camera.
    pub camera: Entity,
    /// The directional light.
    pub light: Entity,
    /// One entity per `[[object]]`.
    pub objects: Vec<Entity>,
    /// One entity per `[[wave]]`.
    pub waves: Vec<Entity>,
}

fn linear(c: [f32; 3]) -> Color {
    Color::linear_rgb(c[0], c[1], c[2])
}

fn vec3(v: hadou_math::Vec3f) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

/// Bevy's directional light "illuminance" giving about hadou's Lambert term
/// `light · max(0, N·(−L))` (`hadou_math::shade::diffuse`) on a rough, non-metallic
/// `StandardMaterial` under a camera of `Exposure { ev100: 0.0 }` (Bevy's diffuse lobe is about
/// `1/π` and that exposure scales by `1/1.2`), for a game's own meshes added to a spawned scene;
/// the scene's objects are shaded by [`HadouMaterial`] with the scene's light itself.
const ILLUMINANCE: f32 = std::f32::consts::PI * 1.2;
/// Bevy's ambient brightness giving hadou's `albedo · ambient` under that exposure.
const AMBIENT_BRIGHTNESS: f32 = 1.2;

/// A Bevy mesh with the positions, normals, indices, texture coordinates and vertex colours of
/// a hadou mesh.
pub fn bevy_mesh(mesh: &hadou_scene::Mesh) -> Mesh {
    let mut out = Mesh::new(PrimitiveTopology::TriangleList, RenderAssetUsages::default());
    out.insert_attribute(Mesh::ATTRIBUTE_POSITION, mesh.positions.clone());
    out.insert_attribute(Mesh::ATTRIBUTE_NORMAL, mesh.normals.clone());
    if mesh.uvs.len() == mesh.positions.len() {
        out.insert_attribute(Mesh::ATTRIBUTE_UV_0, mesh.uvs.clone());
    }
    if mesh.colors.len() == mesh.positions.len() {
        out.insert_attribute(Mesh::ATTRIBUTE_COLOR, mesh.colors.clone());
    }
    out.insert_indices(Indices::U32(mesh.indices.clone()));
    out
}

fn camera_transform(frame: &Frame) -> Transform {
    let c = &frame.camera;
    Transform::from_translation(vec3(c.position)).looking_at(vec3(c.target), vec3(c.up))
}

fn camera_projection(frame: &Frame) -> Projection {
    let c = &frame.camera;
    Projection::Perspective(PerspectiveProjection {
        fov: c.fov_y_deg.to_radians(),
        near: c.near,
        far: c.far,
        ..default()
    })
}

fn light_transform(frame: &Frame) -> Transform {
    let d = vec3(frame.light.direction);
    let up = if d.cross(Vec3::Y).length_squared() > 1e-6 { Vec3::Y } else { Vec3::X };
    Transform::default().looking_to(d, up)
}

fn object_transform(object: &hadou_scene::Object) -> Transform {
    Transform::from_matrix(bevy::math::Mat4::from_cols_array_2d(&object.transform.cols))
}

/// What a frame uses that the plugin does not draw yet, one line each (empty when nothing):
/// logged as one warning when a scene is spawned.
pub fn unsupported(frame: &Frame) -> Vec<String> {
    let mut out = Vec::new();
    if !frame.shadows.is_empty() {
        out.push(format!("{} [[shadow]] (wave and sun shadows)", frame.shadows.len()));
    }
    if frame.area_light.is_some() {
        out.push("the [area_light] (soft shadows)".into());
    }
    for object in &frame.objects {
        let mut what = Vec::new();
        let materials = &object.materials;
        if materials.len() > 1 {
            what.push(format!("{} material slots (the first is used)", materials.len()));
        }
        if materials.iter().any(|m| m.wave_blend > 0.0) {
            what.push("wave_blend (the wave as a light)".into());
        }
        if materials.iter().any(|m| m.base_texture.is_some() || m.feature_texture.is_some()) {
            what.push("textures".into());
        }
        if materials.iter().any(|m| m.outline.is_some()) {
            what.push("outlines".into());
        }
        if !what.is_empty() {
            out.push(format!("object \"{}\": {}", object.name, what.join(", ")));
        }
    }
    out
}

/// The time a root shows at `elapsed` seconds since spawning, for a scene of `duration` seconds.
pub fn scene_time(clock: SceneClock, elapsed: f32, duration: f32) -> f32 {
    match clock {
        SceneClock::Frozen(t) => t,
        SceneClock::Running if duration > 0.0 => elapsed % duration,
        SceneClock::Running => 0.0,
    }
}

pub(crate) fn spawn_scenes(
    mut commands: Commands,
    roots: Query<(Entity, &HadouSceneRoot), Without<SpawnedScene>>,
    scenes: Res<Assets<HadouScene>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<HadouMaterial>>,
) {
    for (root, spawn) in &roots {
        let Some(HadouScene(scene)) = scenes.get(&spawn.scene) else { continue };
        let frame = scene.at(scene_time(spawn.clock, 0.0, scene.duration()));
        let missing = unsupported(&frame);
        if !missing.is_empty() {
            warn!(
                "{}: not drawn in Bevy yet (see docs/bevy.md): {}",
                scene.path().display(),
                missing.join("; ")
            );
        }
        let camera = commands
            .spawn((
                Name::new("camera"),
                Camera3d::default(),
                Camera { clear_color: ClearColorConfig::Custom(linear(frame.background)), ..default() },
                bevy::camera::Hdr,
                bevy::render::view::Msaa::Off,
                bevy::camera::Exposure { ev100: 0.0 },
                AmbientLight {
                    color: linear(frame.light.ambient),
                    brightness: AMBIENT_BRIGHTNESS,
                    ..default()
                },
                camera_transform(&frame),
                camera_projection(&frame),
                bevy::core_pipeline::tonemapping::Tonemapping::None,
                HadouCamera {
                    exposure: frame.color_mapping.exposure,
                    far: frame.camera.far,
                    mapping: ViewMapping::Hadou(frame.color_mapping.mode),
                },
                ChildOf(root),
            ))
            .id();
        let light = commands
            .spawn((
                Name::new("light"),
                DirectionalLight { color: linear(frame.light.color), illuminance: ILLUMINANCE, ..default() },
                light_transform(&frame),
                ChildOf(root),
            ))
            .id();
        let objects = frame
            .objects
            .iter()
            .map(|object| {
                commands
                    .spawn((
                        Name::new(object.name.clone()),
                        Mesh3d(meshes.add(bevy_mesh(&object.mesh))),
                        MeshMaterial3d(materials.add(HadouMaterial::new(object.material(0), &frame.light))),
                        object_transform(object),
                        ChildOf(root),
                    ))
                    .id()
            })
            .collect();
        let waves = frame
            .waves
            .iter()
            .map(|wave| {
                commands
                    .spawn((Name::new(wave.name.clone()), HadouWave::new(wave.clone()), ChildOf(root)))
                    .id()
            })
            .collect();
        commands.entity(root).insert(SpawnedScene { elapsed: 0.0, camera, light, objects, waves });
    }
}

pub(crate) fn animate_scenes(
    time: Res<Time>,
    mut roots: Query<(&HadouSceneRoot, &mut SpawnedScene)>,
    scenes: Res<Assets<HadouScene>>,
    mut transforms: Query<&mut Transform, Without<HadouSceneRoot>>,
    mut cameras: Query<(&mut Projection, &mut HadouCamera)>,
    mut waves: Query<&mut HadouWave>,
) {
    for (root, mut spawned) in &mut roots {
        let Some(HadouScene(scene)) = scenes.get(&root.scene) else { continue };
        spawned.elapsed += time.delta_secs();
        let frame = scene.at(scene_time(root.clock, spawned.elapsed, scene.duration()));
        if let Ok(mut t) = transforms.get_mut(spawned.camera) {
            *t = camera_transform(&frame);
        }
        if let Ok((mut projection, mut settings)) = cameras.get_mut(spawned.camera) {
            *projection = camera_projection(&frame);
            settings.exposure = frame.color_mapping.exposure;
            settings.far = frame.camera.far;
        }
        if let Ok(mut t) = transforms.get_mut(spawned.light) {
            *t = light_transform(&frame);
        }
        for (&entity, object) in spawned.objects.iter().zip(&frame.objects) {
            if let Ok(mut t) = transforms.get_mut(entity) {
                *t = object_transform(object);
            }
        }
        for (&entity, wave) in spawned.waves.iter().zip(&frame.waves) {
            if let Ok(mut w) = waves.get_mut(entity) {
                w.wave = wave.clone();
            }
        }
    }
}
