//! hadou's energy waves in Bevy.
//!
//! [`HadouPlugin`] draws every [`HadouWave`] into every camera with a [`HadouCamera`], through
//! hadou-gpu's own wave pass on Bevy's `RenderDevice` (`GpuBackend::encode_wave_overlay`): per
//! pixel the waves' light along the view ray, clipped at the camera's depth buffer (002 §3.3.5),
//! added into the view's HDR target after Bevy's main passes and before bloom and tone mapping.
//! A camera's [`HadouCamera::mapping`] picks Bevy's tone mapping or hadou's own colour mapping
//! ([`ViewMapping::Hadou`]: hadou-gpu's `map_faithful` / `map_filmic` on the HDR image, after
//! bloom, in place of Bevy's tone mapping). [`HadouMaterial`] shades a mesh with hadou's Lambert
//! or toon model under a hadou light, and a [`HadouAreaLight`] adds a lamp's light and soft
//! shadows (the share of the lamp each fragment sees past the casters' meshes). A hadou scene file (`.toml`) is a Bevy asset
//! ([`HadouScene`]); a [`HadouSceneRoot`] spawns it (camera with the scene's colour mapping,
//! light, objects with [`HadouMaterial`]s, waves, area light) and plays its tracks.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use hadou_bevy::{HadouPlugin, HadouSceneRoot, SceneClock};
//!
//! fn main() {
//!     App::new()
//!         .add_plugins((DefaultPlugins, HadouPlugin::default()))
//!         .add_systems(Startup, |mut commands: Commands, assets: Res<AssetServer>| {
//!             let scene = assets.load("kamehameha.toml");
//!             commands.spawn(HadouSceneRoot { scene, clock: SceneClock::Running });
//!         })
//!         .run();
//! }
//! ```

mod area;
mod asset;
mod camera;
#[cfg(feature = "gltf")]
mod clips;
mod drawn_pose;
mod material;
mod mesh;
mod outline;
#[cfg(feature = "gltf")]
mod pose;
mod render;
mod shaded;
mod shadows;
mod spawn;
mod tone;
#[cfg(feature = "gltf")]
mod vrm;
mod wave;

pub use area::{
    area_rejection_message, check_area_light, fragment_loop_bound, AreaLightError, AreaLightRejected,
    HadouAreaLight, AREA_COORD_MAX, LLVMPIPE_LOOP_BUDGET,
};
pub use asset::{parse_scene, HadouScene, HadouSceneLoadError, HadouSceneLoader};
pub use camera::{
    camera_rejection_message, check_camera, frame_camera, frame_view, CameraError, CameraRejected,
    HadouCamera, ViewMapping, EXPOSURE_MAX,
};
#[cfg(feature = "gltf")]
pub use clips::{clip_rejection_message, ClipRejected, HadouClip};
pub use drawn_pose::triangles_mesh;
pub use material::{
    light_records, prepared_light_records, HadouMaterial, HadouRamp, HadouSurface, AREA_DATA, AREA_NODES,
    AREA_TRIS, MAX_WAVE_LIGHTS, NO_TEXTURES, SHADOW_DATA, SHADOW_MAPS, WAVE_LIGHTS, WAVE_LIGHT_DATA,
};
pub use mesh::{bevy_mesh, bevy_slot_mesh, outline_mesh, slot_indices_of};
pub use outline::{HadouOutline, HadouOutlineUniform};
#[cfg(feature = "gltf")]
pub use pose::{pose_rejection_message, HadouPose, PoseRejected};
pub use shaded::{hadou_texture, HadouShaded};
pub use shadows::{shadow_frame, shadow_mask, shadow_records, HadouShadows, PLANE_MAP_SIZE};
pub use spawn::{
    scene_time, spawn_object, unsupported, HadouSceneRoot, ObjectAssets, SceneClock, SpawnedScene,
};
#[cfg(feature = "gltf")]
pub use vrm::VrmLoader;
pub use wave::{check_wave, rejection_message, HadouWave, WaveError, WaveRejected};

use bevy::asset::io::file::FileAssetReader;
use bevy::core_pipeline::fullscreen_material::FullscreenMaterialPlugin;
use bevy::core_pipeline::schedule::{Core3d, Core3dSystems};
use bevy::pbr::MaterialPlugin;
use bevy::prelude::*;
use bevy::render::extract_component::ExtractComponentPlugin;
use bevy::render::storage::ShaderBuffer;
use bevy::render::{ExtractSchedule, Render, RenderApp, RenderStartup, RenderSystems};
use std::path::PathBuf;

/// Bevy plugin: hadou's waves in every [`HadouCamera`]'s view, hadou scene files as assets.
/// Works without a renderer too (e.g. under `MinimalPlugins`): waves are then only checked.
pub struct HadouPlugin {
    /// The directory asset paths are relative to (Bevy's `AssetPlugin::file_path` resolved), from
    /// which a scene's glTF models and textures are read. Default: `assets` under Bevy's base
    /// path (`BEVY_ASSET_ROOT`, else `CARGO_MANIFEST_DIR`, else the executable's directory).
    pub asset_root: PathBuf,
}

impl Default for HadouPlugin {
    fn default() -> Self {
        HadouPlugin { asset_root: FileAssetReader::get_base_path().join("assets") }
    }
}

/// The main-world systems of [`HadouPlugin`], for ordering against them.
#[derive(SystemSet, Clone, Debug, PartialEq, Eq, Hash)]
pub enum HadouSystems {
    /// Spawning loaded scenes and setting their entities from the tracks (`Update`).
    Scenes,
    /// Checking changed waves and area lights (`PostUpdate`).
    CheckWaves,
    /// Writing the waves as lights, the shadows and the area light for the [`HadouMaterial`]s
    /// (`PostUpdate`, after [`HadouSystems::CheckWaves`]).
    Lights,
}

impl Plugin for HadouPlugin {
    fn build(&self, app: &mut App) {
        let renders = app.get_sub_app(RenderApp).is_some();
        if app.is_plugin_added::<AssetPlugin>() {
            app.init_asset::<HadouScene>()
                .register_asset_loader(HadouSceneLoader { root: self.asset_root.clone() });
            if renders {
                app.add_plugins((
                    MaterialPlugin::<HadouMaterial>::default(),
                    MaterialPlugin::<HadouOutline>::default(),
                ));
            } else {
                app.init_asset::<HadouMaterial>().init_asset::<HadouOutline>();
            }
            if !app.world().contains_resource::<Assets<ShaderBuffer>>() {
                app.init_asset::<ShaderBuffer>();
            }
            material::insert_buffers(&mut app.world_mut().resource_mut::<Assets<ShaderBuffer>>());
            area::insert_buffers(&mut app.world_mut().resource_mut::<Assets<ShaderBuffer>>());
            if !app.world().contains_resource::<Assets<Image>>() {
                app.init_asset::<Image>();
            }
            app.init_resource::<HadouShadows>();
            app.world_mut().resource_scope(|world, mut images: Mut<Assets<Image>>| {
                shadows::insert_assets(&mut images, &mut world.resource_mut::<Assets<ShaderBuffer>>());
            });
            app.add_systems(PostUpdate, shadows::update_shadows.in_set(HadouSystems::Lights));
            if app.world().contains_resource::<Assets<Mesh>>() {
                app.add_systems(
                    PostUpdate,
                    area::update_area_light
                        .in_set(HadouSystems::Lights)
                        .after(HadouSystems::CheckWaves)
                        .after(bevy::transform::TransformSystems::Propagate),
                );
            }
            if app.world().contains_resource::<Assets<StandardMaterial>>() {
                app.add_systems(Update, shaded::shade_models);
            }
            if app.world().contains_resource::<Assets<Mesh>>() {
                app.add_systems(
                    PostUpdate,
                    drawn_pose::shadows_from_drawn_poses
                        .in_set(HadouSystems::Lights)
                        .after(bevy::transform::TransformSystems::Propagate)
                        .before(shadows::update_shadows),
                );
            }
            #[cfg(feature = "gltf")]
            app.add_systems(Update, clips::play_clips.after(HadouSystems::Scenes));
            #[cfg(feature = "gltf")]
            app.add_systems(Update, pose::apply_poses.after(HadouSystems::Scenes));
            app.add_systems(
                PostUpdate,
                material::update_wave_lights.in_set(HadouSystems::Lights).after(HadouSystems::CheckWaves),
            );
            if app.world().contains_resource::<Assets<Mesh>>() {
                app.add_systems(
                    Update,
                    (spawn::reload_scenes, spawn::spawn_scenes, spawn::animate_scenes)
                        .chain()
                        .in_set(HadouSystems::Scenes),
                );
                #[cfg(feature = "gltf")]
                if app.world().contains_resource::<Assets<StandardMaterial>>() {
                    app.add_systems(
                        Update,
                        spawn::mark_ready.after(HadouSystems::Scenes).after(shaded::shade_models),
                    );
                }
            }
        }
        app.init_resource::<wave::DrawnWaves>();
        app.add_systems(
            PostUpdate,
            (wave::check_changed_waves, area::check_changed_area_lights).in_set(HadouSystems::CheckWaves),
        )
        .add_systems(
            PostUpdate,
            wave::prepare_drawn_waves.after(HadouSystems::CheckWaves).before(HadouSystems::Lights),
        )
        .add_systems(PostUpdate, (camera::bind_depth, camera::check_cameras, tone::apply_mapping))
        .add_observer(tone::remove_mapping);
        if !renders {
            return;
        }
        if let Some(mut shaders) = app.world_mut().get_resource_mut::<Assets<Shader>>() {
            shaders
                .insert(&tone::SHADER, Shader::from_wgsl(tone::shader_source(), "hadou_bevy/tone_map.wgsl"))
                .expect("a shader under a fixed handle can be inserted");
            shaders
                .insert(
                    &material::SHADER,
                    Shader::from_wgsl(material::shader_source(), "hadou_bevy/material.wgsl"),
                )
                .expect("a shader under a fixed handle can be inserted");
            shaders
                .insert(
                    &outline::SHADER,
                    Shader::from_wgsl(outline::shader_source(), "hadou_bevy/outline.wgsl"),
                )
                .expect("a shader under a fixed handle can be inserted");
        }
        app.add_plugins((
            ExtractComponentPlugin::<HadouCamera>::default(),
            FullscreenMaterialPlugin::<tone::ToneMapPass>::default(),
        ));
        let render_app = app.sub_app_mut(RenderApp);
        render_app
            .init_resource::<render::ExtractedWaves>()
            .init_resource::<render::Warned>()
            .init_resource::<shadows::ExtractedShadows>()
            .add_systems(ExtractSchedule, shadows::extract_shadows)
            .add_systems(Render, shadows::draw_shadow_maps.in_set(RenderSystems::PrepareResources))
            .add_systems(RenderStartup, render::init_renderer)
            .add_systems(ExtractSchedule, render::extract_waves)
            .add_systems(
                Core3d,
                render::wave_pass.after(Core3dSystems::MainPass).before(Core3dSystems::EarlyPostProcess),
            );
    }

    fn finish(&self, app: &mut App) {
        // After the glTF plugin's `finish`, which makes the loader's settings.
        #[cfg(feature = "gltf")]
        if app.is_plugin_added::<AssetPlugin>() {
            vrm::register(app);
        }
    }
}

/// The package's README (what crates.io shows): its examples compile as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
