//! Spawning a [`HadouScene`] asset: [`HadouSceneRoot`] names the scene; once it has loaded, its
//! camera, light, objects, waves and area light become entities under the root, and every frame
//! the scene's tracks at the root's clock set the waves, the object transforms, the camera and
//! the area light.

use crate::area::HadouAreaLight;
use crate::asset::HadouScene;
use crate::camera::{HadouCamera, ViewMapping};
#[cfg(feature = "gltf")]
use crate::clips::{ClipPlayback, ClipRejected, HadouClip};
use crate::material::HadouMaterial;
use crate::mesh::{bevy_mesh, outline_mesh, slot_indices_of};
use crate::outline::HadouOutline;
#[cfg(feature = "gltf")]
use crate::pose::{HadouPose, PoseBinding, PoseRejected};
use crate::shaded::HadouShaded;
use crate::shadows::{shadow_mask, HadouShadows};
use crate::wave::HadouWave;
#[cfg(feature = "gltf")]
use bevy::asset::AssetPath;
#[cfg(feature = "gltf")]
use bevy::gltf::GltfAssetLabel;
use bevy::mesh::Indices;
use bevy::prelude::*;
use bevy::render::storage::ShaderBuffer;
#[cfg(feature = "gltf")]
use bevy::world_serialization::WorldAssetRoot;
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
    /// One entity per `[[object]]` (its transform). A primitive has a child per material slot
    /// that has triangles (`Mesh3d`, `HadouMaterial`) and one per outlined slot
    /// (`HadouOutline`); a `kind = "gltf"` object is the file's scene loaded by Bevy's glTF
    /// loader (`WorldAssetRoot`, skinned and animated by Bevy) with [`crate::HadouShaded`]
    /// giving each of its meshes its slot's look, and a `HadouClip` (feature `gltf`) at the
    /// scene's clip time when it plays an `animation`, or a `HadouPose` (feature `gltf`) of
    /// hadou-scene's pose of its nodes when hadou poses it beyond a clip of its file (a VRMA
    /// `animation_file`, `expressions`, spring bones, `look_at`).
    pub objects: Vec<Entity>,
    /// Per object, the material of each slot (the object's materials in order), set from the
    /// scene every frame (tracks may change `wave_blend`, colours, the light); empty for a glTF
    /// object, whose [`crate::HadouShaded`] is set instead.
    pub materials: Vec<Vec<Handle<HadouMaterial>>>,
    /// One entity per `[[wave]]`.
    pub waves: Vec<Entity>,
    /// The `[area_light]`'s entity ([`HadouAreaLight`], its casters the entities of the
    /// light's caster objects), if the scene has one.
    pub area_light: Option<Entity>,
    /// Every object is drawn with hadou's look: true at once for a scene of primitives; a scene
    /// with glTF objects is ready once Bevy has loaded each file (or failed to, with its error
    /// logged) and each of its meshes has been switched to its slot's `HadouMaterial`. Wait for
    /// it before a screenshot.
    pub ready: bool,
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

#[cfg(feature = "gltf")]
/// The asset path of the default scene of the glTF file `file` named by the scene asset
/// `scene` (relative to the scene file's directory; hadou-scene checked that it lies inside it),
/// or `None` when the scene asset has no path.
pub fn gltf_scene_path(scene: &Handle<HadouScene>, file: &std::path::Path) -> Option<AssetPath<'static>> {
    let scene_path = scene.path()?;
    let mut path = scene_path.path().parent().map(std::path::Path::to_path_buf).unwrap_or_default();
    for part in file.components() {
        match part {
            std::path::Component::ParentDir => {
                path.pop();
            }
            std::path::Component::Normal(p) => path.push(p),
            _ => {}
        }
    }
    let file = AssetPath::from(path).with_source(scene_path.source().clone_owned());
    // hadou reads the file's default scene (`scene`, else the first): Bevy's label for it.
    Some(file.with_label(GltfAssetLabel::Scene(0).to_string()))
}

fn object_transform(object: &hadou_scene::Object) -> Transform {
    Transform::from_matrix(bevy::math::Mat4::from_cols_array_2d(&object.transform.cols))
}

/// What a frame uses that the plugin does not draw yet, one line each (empty when nothing):
/// logged as one warning when a scene is spawned.
pub fn unsupported(frame: &Frame) -> Vec<String> {
    let mut out = Vec::new();
    if frame.bloom.is_some() {
        out.push("the [bloom] (glare)".into());
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

/// The asset collections [`spawn_object`] adds to.
pub struct ObjectAssets<'a> {
    /// Meshes.
    pub meshes: &'a mut Assets<Mesh>,
    /// Shaded materials.
    pub materials: &'a mut Assets<HadouMaterial>,
    /// Outline materials.
    pub outlines: &'a mut Assets<HadouOutline>,
    /// Texture buffers.
    pub buffers: &'a mut Assets<ShaderBuffer>,
}

/// Spawns a hadou `[[object]]` under `light`, receiving the shadows of `shadow_mask` (see
/// [`HadouMaterial::with_shadow_mask`]): an entity with its name and transform, with a child
/// per material slot that has triangles (`Mesh3d`, a [`HadouMaterial`] with the slot's textures)
/// and one per outlined slot ([`HadouOutline`] over [`crate::outline_mesh`]). Returns the entity
/// and the material of every slot (the object's materials in order), e.g. to change `wave_blend`.
pub fn spawn_object(
    commands: &mut Commands,
    assets: &mut ObjectAssets,
    object: &hadou_scene::Object,
    light: &hadou_scene::Light,
    shadow_mask: u32,
) -> (Entity, Vec<Handle<HadouMaterial>>) {
    let entity = commands
        .spawn((Name::new(object.name.clone()), object_transform(object), Visibility::default()))
        .id();
    let slots = object.materials.len().max(1);
    let mut handles = Vec::with_capacity(slots);
    for slot in 0..slots as u32 {
        let material = object.material(slot);
        let shaded =
            HadouMaterial::with_textures(material, light, assets.buffers).with_shadow_mask(shadow_mask);
        let handle = assets.materials.add(shaded);
        handles.push(handle.clone());
        let indices = slot_indices_of(&object.mesh, slot, slots);
        if indices.is_empty() {
            continue;
        }
        let mut mesh = bevy_mesh(&object.mesh);
        mesh.insert_indices(Indices::U32(indices));
        commands.spawn((
            Name::new(format!("{} slot {slot}", object.name)),
            Mesh3d(assets.meshes.add(mesh)),
            MeshMaterial3d(handle),
            ChildOf(entity),
        ));
        if let Some(hull) = HadouOutline::of(material, light) {
            // The hull, and its closing hull where the outline meets another surface.
            let mesh = assets.meshes.add(outline_mesh(&object.mesh, slot));
            for (name, hull) in [("outline closing", hull.closing()), ("outline", hull)] {
                commands.spawn((
                    Name::new(format!("{} slot {slot} {name}", object.name)),
                    Mesh3d(mesh.clone()),
                    MeshMaterial3d(assets.outlines.add(hull)),
                    ChildOf(entity),
                ));
            }
        }
    }
    (entity, handles)
}

#[cfg_attr(not(feature = "gltf"), allow(unused_variables))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn spawn_scenes(
    mut commands: Commands,
    roots: Query<(Entity, &HadouSceneRoot), Without<SpawnedScene>>,
    scenes: Res<Assets<HadouScene>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<HadouMaterial>>,
    mut outlines: ResMut<Assets<HadouOutline>>,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
    asset_server: Res<AssetServer>,
    #[cfg(feature = "gltf")] gltf_loader: Option<Res<Assets<bevy::gltf::Gltf>>>,
) {
    for (root, spawn) in &roots {
        let Some(HadouScene(scene)) = scenes.get(&spawn.scene) else { continue };
        #[cfg(feature = "gltf")]
        let files = scene.object_files();
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
                // The prepass depth and normals close the outlines where objects meet
                // (`HadouOutline::closing`).
                bevy::core_pipeline::prepass::DepthPrepass,
                bevy::core_pipeline::prepass::NormalPrepass,
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
        let mut objects = Vec::with_capacity(frame.objects.len());
        let mut object_materials = Vec::with_capacity(frame.objects.len());
        let mut assets = ObjectAssets {
            meshes: &mut meshes,
            materials: &mut materials,
            outlines: &mut outlines,
            buffers: &mut buffers,
        };
        for (i, object) in frame.objects.iter().enumerate() {
            let mask = shadow_mask(&frame, i as u32);
            #[cfg(feature = "gltf")]
            // Through Bevy's glTF loader when the app has it (its plugin adds `Assets<Gltf>`).
            let gltf = files
                .get(i)
                .copied()
                .flatten()
                .filter(|_| gltf_loader.is_some())
                .and_then(|file| gltf_scene_path(&spawn.scene, file));
            #[cfg(not(feature = "gltf"))]
            let gltf: Option<()> = None;
            let (entity, handles) = match gltf {
                #[cfg(feature = "gltf")]
                Some(path) => {
                    let shaded = HadouShaded {
                        slots: object.materials.clone(),
                        time: frame.time,
                        ..HadouShaded::new(object.material(0).clone(), frame.light, mask)
                    };
                    let entity = commands
                        .spawn((
                            Name::new(object.name.clone()),
                            object_transform(object),
                            WorldAssetRoot(asset_server.load(path)),
                            shaded,
                        ))
                        .id();
                    if scene.object_posed_by_hadou(i) {
                        // Posed by hadou-scene (a VRMA clip, expressions, spring bones, a gaze):
                        // its nodes are set from the pose, and no clip of the file is played.
                        let pose = scene.object_node_pose_at(i, frame.time).unwrap_or_default();
                        commands.entity(entity).insert(HadouPose(pose));
                    } else if let Some((name, time)) = scene.object_clip_at(i, frame.time) {
                        commands.entity(entity).insert(HadouClip { name, time });
                    }
                    (entity, Vec::new())
                }
                _ => spawn_object(&mut commands, &mut assets, object, &frame.light, mask),
            };
            commands.entity(entity).insert(ChildOf(root));
            objects.push(entity);
            object_materials.push(handles);
        }
        let waves = frame
            .waves
            .iter()
            .map(|wave| {
                commands
                    .spawn((Name::new(wave.name.clone()), HadouWave::new(wave.clone()), ChildOf(root)))
                    .id()
            })
            .collect();
        let area_light = frame.area_light.as_ref().map(|light| {
            let casters = light.casters.iter().filter_map(|&c| objects.get(c as usize).copied()).collect();
            commands
                .spawn((Name::new("area_light"), HadouAreaLight::from_scene(light, casters), ChildOf(root)))
                .id()
        });
        let ready = object_materials.iter().all(|m| !m.is_empty());
        commands.entity(root).insert(SpawnedScene {
            ready,
            elapsed: 0.0,
            camera,
            light,
            objects,
            materials: object_materials,
            waves,
            area_light,
        });
    }
}

/// Hot reload: a root whose scene asset changed (Bevy's asset server reloads a watched file, or a
/// system replaced the asset) loses what it spawned and spawns the new scene; its clock starts
/// again. A reload that fails leaves the last good scene in place (the asset server logs the
/// loader's `file:line:col` message).
pub(crate) fn reload_scenes(
    mut commands: Commands,
    mut events: MessageReader<AssetEvent<HadouScene>>,
    roots: Query<(Entity, &HadouSceneRoot), With<SpawnedScene>>,
    scenes: Res<Assets<HadouScene>>,
) {
    let modified: Vec<AssetId<HadouScene>> = events
        .read()
        .filter_map(|e| match e {
            AssetEvent::Modified { id } => Some(*id),
            _ => None,
        })
        .collect();
    if modified.is_empty() {
        return;
    }
    for (root, spawn) in &roots {
        if modified.contains(&spawn.scene.id()) {
            if let Some(HadouScene(scene)) = scenes.get(&spawn.scene) {
                info!("{}: changed; spawning it again", scene.path().display());
            }
            commands.entity(root).despawn_related::<Children>().remove::<SpawnedScene>();
        }
    }
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn animate_scenes(
    time: Res<Time>,
    mut roots: Query<(&HadouSceneRoot, &mut SpawnedScene)>,
    scenes: Res<Assets<HadouScene>>,
    mut transforms: Query<&mut Transform, Without<HadouSceneRoot>>,
    mut shaded: Query<&mut HadouShaded>,
    mut cameras: Query<(&mut Projection, &mut HadouCamera)>,
    mut waves: Query<&mut HadouWave>,
    mut materials: ResMut<Assets<HadouMaterial>>,
    mut shadows: ResMut<HadouShadows>,
    mut area_lights: Query<&mut HadouAreaLight>,
    #[cfg(feature = "gltf")] mut clips: Query<&mut HadouClip>,
    #[cfg(feature = "gltf")] mut poses: Query<&mut HadouPose>,
) {
    for (root, mut spawned) in &mut roots {
        let Some(HadouScene(scene)) = scenes.get(&root.scene) else { continue };
        spawned.elapsed += time.delta_secs();
        let frame = scene.at(scene_time(root.clock, spawned.elapsed, scene.duration()));
        #[cfg(feature = "gltf")]
        for (i, &entity) in spawned.objects.iter().enumerate() {
            // The clip time of hadou-scene's rule (`animation_start`, `animation_speed`,
            // `animation_loop`, `animation_time`), written only when it changes.
            if let (Ok(mut clip), Some((_, t))) = (clips.get_mut(entity), scene.object_clip_at(i, frame.time))
            {
                if clip.time != t {
                    clip.time = t;
                }
            }
            // hadou-scene's pose of the nodes at this time, written only when it changes.
            if let Ok(mut pose) = poses.get_mut(entity) {
                if let Some(next) = scene.object_node_pose_at(i, frame.time) {
                    if pose.0 != next {
                        pose.0 = next;
                    }
                }
            }
        }
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
        for ((&entity, handles), object) in spawned.objects.iter().zip(&spawned.materials).zip(&frame.objects)
        {
            if let Ok(mut t) = transforms.get_mut(entity) {
                *t = object_transform(object);
            }
            if let Ok(mut s) = shaded.get_mut(entity) {
                // Only a changed look marks the component changed (its materials are updated).
                let moves = s.time != frame.time && object.materials.iter().any(|m| m.mtoon.is_some());
                if s.slots != object.materials || s.light != frame.light || moves {
                    s.slots.clone_from(&object.materials);
                    s.light = frame.light;
                    s.time = frame.time;
                }
            }
            for (slot, handle) in handles.iter().enumerate() {
                let material = object.material(slot as u32);
                // Only a material whose uniform changes is marked changed (and uploaded again).
                let changed = materials.get(handle).is_some_and(|m| {
                    let mut next = m.clone();
                    next.update(material, &frame.light) | next.set_time(frame.time)
                });
                if changed {
                    if let Some(mut m) = materials.get_mut(handle) {
                        m.update(material, &frame.light);
                        m.set_time(frame.time);
                    }
                }
            }
        }
        for (&entity, wave) in spawned.waves.iter().zip(&frame.waves) {
            if let Ok(mut w) = waves.get_mut(entity) {
                w.wave = wave.clone();
            }
        }
        if let (Some(light), Some(Ok(mut drawn))) =
            (&frame.area_light, spawned.area_light.map(|e| area_lights.get_mut(e)))
        {
            // Only a moved or changed lamp marks the component changed (and is checked again).
            let next = HadouAreaLight {
                enabled: drawn.enabled,
                ..HadouAreaLight::from_scene(light, drawn.casters.clone())
            };
            if next != *drawn {
                *drawn = next;
            }
        }
        if !frame.shadows.is_empty() {
            shadows.frame = Some(frame);
        }
    }
}

/// Sets [`SpawnedScene::ready`] once every glTF object's file has loaded (or failed to) and each
/// of its meshes has its slot's [`HadouMaterial`].
#[cfg(feature = "gltf")]
#[allow(clippy::too_many_arguments)]
pub(crate) fn mark_ready(
    mut roots: Query<&mut SpawnedScene>,
    models: Query<&WorldAssetRoot, With<HadouShaded>>,
    children: Query<&Children>,
    standard: Query<(), With<MeshMaterial3d<StandardMaterial>>>,
    shaded: Query<(), With<MeshMaterial3d<HadouMaterial>>>,
    asset_server: Res<AssetServer>,
    clips: Query<(Option<&ClipPlayback>, Has<ClipRejected>), With<HadouClip>>,
    animation: Option<Res<Assets<bevy::animation::graph::AnimationGraph>>>,
    poses: Query<(Option<&PoseBinding>, Has<PoseRejected>), With<HadouPose>>,
) {
    for mut spawned in roots.iter_mut().filter(|s| !s.ready) {
        let ready = spawned.objects.iter().all(|&object| {
            let Ok(model) = models.get(object) else { return true };
            if asset_server.load_state(&model.0).is_failed() {
                return true;
            }
            // A clip is bound to its player (or rejected) before the first posed frame.
            if let Ok((playback, rejected)) = clips.get(object) {
                if animation.is_some() && !rejected && !playback.is_some_and(ClipPlayback::is_bound) {
                    return false;
                }
            }
            // hadou's pose is bound to the nodes (or rejected) before the first posed frame.
            if let Ok((binding, rejected)) = poses.get(object) {
                if !rejected && !binding.is_some_and(PoseBinding::is_bound) {
                    return false;
                }
            }
            let (mut switched, mut left) = (0, 0);
            for e in children.iter_descendants(object) {
                switched += usize::from(shaded.contains(e));
                left += usize::from(standard.contains(e));
            }
            switched > 0 && left == 0
        });
        if ready {
            spawned.ready = true;
        }
    }
}
