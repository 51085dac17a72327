//! # hadou-scene
//!
//! Scene files (TOML) → typed, validated [`Scene`] with animation tracks → [`Frame`] at any time.
//! Also the [`Image`] every backend returns and the [`Backend`] trait.
//!
//! ```text
//! scene.toml ──Scene::load──▶ Scene ──scene.at(t)──▶ Frame ──Backend::render──▶ Image
//! ```
//!
//! All validation happens in [`Scene::load`]/[`Scene::parse`]; errors are [`SceneError`]s whose
//! `Display` is `path:line:col: message`. [`Scene::at`] never fails. A backend that cannot render
//! says why with a [`RenderError`]. The file format is described key by key in
//! `docs/scene-format.md`.
//!
//! The files form layers; each uses only files of its own layer or the layers below (no import
//! circles):
//! 1. the frame's plain values (`frame.rs`, with `shadow.rs` and `area_light.rs`; `image.rs`) and
//!    the helpers everything uses (`error.rs`, `limits.rs`, `files.rs`, `guard.rs`, `params.rs`,
//!    `anim.rs`, `toml_read.rs`) and `temp_file.rs` (how every writer of the workspace writes);
//! 2. a frame's geometry and assets: `bounds.rs`, `mesh.rs`, `texture.rs`, `gltf_uri.rs`,
//!    `gltf_material.rs`, `gltf_load.rs`; `backend.rs`; `gif_timing.rs` (what GIF writers share); and `file_kinds.rs` (the files a scene may
//!    name, by extension, with their size limits);
//! 3. each feature read from the scene file and built at one set of values (`materials.rs`,
//!    `shadow_def.rs`, `area_light_def.rs`), and `shadow_casts.rs` (`Frame::shadow_casts`);
//! 4. `scene.rs`: [`Scene`] and [`Scene::at`];
//! 5. `track_def.rs` (`[[track]]` targets resolved against a [`Scene`]) and `introspect.rs`;
//! 6. `schema.rs`: [`Scene::load`], [`Scene::parse`].
//!
//! This file only declares the modules and re-exports the public items.

mod anim;
mod area_light;
mod area_light_def;
mod backend;
mod bloom_def;
mod bounds;
mod camera_def;
mod error;
mod file_kinds;
mod files;
mod frame;
mod gif_timing;
mod gltf_accessor;
mod gltf_anim;
mod gltf_load;
mod gltf_material;
mod gltf_mtoon;
mod gltf_uri;
mod gltf_vrm;
mod gltf_vrma;
mod guard;
mod image;
mod introspect;
mod light_def;
mod limits;
mod look_at;
mod materials;
pub mod mesh;
mod object_def;
mod params;
mod rig;
mod scene;
mod schema;
mod shadow;
mod shadow_casts;
mod shadow_def;
mod spring;
mod spring_bones;
mod spring_def;
mod spring_scene;
#[cfg(test)]
mod spring_tests;
mod temp_file;
mod texture;
mod toml_read;
mod track_def;
mod wave_check;
mod wave_def;
mod wave_kind;

pub use anim::Interpolation;
pub use area_light::{
    AreaLight, LampShape, Penumbra, SoftResolve, DEFAULT_TRACE_SAMPLES, MAX_GRID, MAX_TRACE_SAMPLES,
    SOFT_MAX_PIXELS,
};
pub use backend::{Backend, RenderError};
pub use bloom_def::{BLOOM_MAX_STREAK_LENGTH, BLOOM_MAX_THRESHOLD, BLOOM_MAX_WEIGHT};
pub use bounds::{caster_box, caster_triangles, object_bounds, object_center, widest_outline_pixels};
pub use error::{escape_controls, Location, SceneError};
pub use file_kinds::file_size_limit;
pub use files::{
    mount_memory_files, read_regular_file, MemoryFiles, GLTF_MAX_BYTES, GLTF_MAX_JSON_BYTES,
    GLTF_MAX_JSON_OBJECTS, GLTF_MAX_JSON_VALUES, SCENE_MAX_BYTES,
};
pub use frame::*;
pub use gif_timing::{check_gif_size, gif_delay_cs, GIF_MAX_PIXELS, GIF_QUANT_SPEED};
pub use gltf_anim::MAX_ANIMATION_VALUES;
pub use gltf_load::{
    check_gltf_materials, gltf_from_bytes, gltf_from_bytes_with_warnings, load_gltf, load_gltf_rig,
    MAX_MORPH_DELTAS, MAX_MORPH_TARGETS,
};
pub use gltf_vrma::load_vrma_clip;
pub use image::{Image, Rgb8Image};
pub use introspect::{CharacterInfo, Entity, LookAtTarget, ParamInfo, ParamRange, ParamShape, TrackInfo};
pub use limits::{
    check_image_size, check_image_size_with, check_trace_memory, glare_band_rows, ALPHA_MAX,
    ANALYTIC_RAY_WORK, ATTENUATION_MAX, GLARE_BAND_BYTES_PER_PIXEL, GLARE_BYTES_PER_PIXEL, GLARE_MAX_BYTES,
    GLARE_MAX_PIXELS, MAX_IMAGE_EDGE, MAX_KEY_CHECKS, MAX_MATERIAL_SLOTS, MAX_SKINNED_NODES, MAX_SKIN_JOINTS,
    MAX_TRIANGLES, MAX_VERTICES, PIXEL_WORK_MAX, TRACE_MAX_BYTES,
};
pub use rig::{clip_time, clip_wrap, Clip, Expression, NodePose, PoseInput, Rig, Trs, VrmVersion};
pub use scene::Scene;
pub use shadow::{
    Shadow, ShadowCast, ShadowLight, ShadowMethod, MAX_MAPS, MAX_MAP_SIZE, MAX_MAP_TEXELS, MAX_SHADOWS,
    MAX_SHADOW_CASTERS, MAX_SHADOW_TRIANGLES, ON_PLANE,
};
pub use spring::{
    MAX_SPRING_COLLIDERS, MAX_SPRING_COLLISION_PAIRS, MAX_SPRING_JOINTS, SPRING_FORCE_MAX, SPRING_MAX_STEPS,
    SPRING_RATE, SPRING_RESTART_STEPS,
};
pub use spring_bones::SpringBones;
pub use spring_scene::{spring_start, spring_steps_at};
pub use temp_file::{remove_pending_temp_files, TempFile};
pub use texture::{
    decode_texture, encode_png, MAX_SCENE_TEXELS, TEXTURE_DOWNSCALE_EDGE, TEXTURE_MAX_BYTES,
    TEXTURE_MAX_EDGE, TEXTURE_MAX_TEXELS,
};
pub use wave_check::WaveError;
pub use wave_kind::{CurveKind, Growth, StarterValue, WaveKind, WAVE_KINDS};
