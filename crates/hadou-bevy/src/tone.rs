//! hadou's colour mapping on a Bevy view: a full-screen pass of Bevy's `Core3d` schedule that
//! maps the view's HDR image with hadou-gpu's own `map_faithful` / `map_filmic` (its
//! `common.wgsl`, the WGSL twins of `hadou_math::shade`) where Bevy's tone mapping would run:
//! after bloom, before `tonemapping` (which the camera then skips, its `Tonemapping` being
//! `None`).

use crate::camera::{HadouCamera, ViewMapping};
use bevy::asset::uuid_handle;
use bevy::core_pipeline::fullscreen_material::FullscreenMaterial;
use bevy::core_pipeline::tonemapping::{tonemapping, Tonemapping};
use bevy::core_pipeline::Core3dSystems;
use bevy::ecs::schedule::ScheduleConfigs;
use bevy::ecs::system::BoxedSystem;
use bevy::post_process::bloom::bloom;
use bevy::prelude::*;
use bevy::render::extract_component::ExtractComponent;
use bevy::render::render_resource::ShaderType;
use bevy::shader::ShaderRef;
use hadou_scene::ToneMode;

/// The shader of [`ToneMapPass`], composed at start-up (see [`shader_source`]).
pub(crate) const SHADER: Handle<Shader> = uuid_handle!("6f1f3c52-7d0e-4d8b-9a51-3b2a4c1e8d07");

/// `ToneMapPass::mode` of hadou's faithful mapping; the same code as hadou-gpu's `TONE_FAITHFUL`.
const MODE_FAITHFUL: u32 = hadou_gpu::layout::TONE_FAITHFUL;
/// `ToneMapPass::mode` of hadou's filmic mapping; the same code as hadou-gpu's `TONE_FILMIC`.
const MODE_FILMIC: u32 = hadou_gpu::layout::TONE_FILMIC;

/// The fragment stage of the pass: the view's HDR colour, texel for texel, through the mapping of
/// `settings.mode` (`TONE_FAITHFUL`, `TONE_FILMIC`, `map_faithful` and `map_filmic` come from
/// hadou-gpu's `common.wgsl`, prepended by [`shader_source`]).
const PASS: &str = r"
@group(0) @binding(0) var screen_texture: texture_2d<f32>;
@group(0) @binding(1) var screen_sampler: sampler;
struct ToneMapPass {
    mode: u32,
}
@group(0) @binding(2) var<uniform> settings: ToneMapPass;

@fragment
fn fragment(in: FullscreenVertexOutput) -> @location(0) vec4<f32> {
    let c = textureLoad(screen_texture, vec2<i32>(floor(in.position.xy)), 0);
    var rgb = map_filmic(c.rgb);
    if (settings.mode == TONE_FAITHFUL) {
        rgb = map_faithful(c.rgb);
    }
    return vec4<f32>(rgb, c.a);
}
";

/// The WGSL of the pass: Bevy's full-screen vertex output, hadou-gpu's `common.wgsl` (the
/// mappings, 002 §3.3 and SPEC.md §1.1), then [`PASS`].
pub(crate) fn shader_source() -> String {
    format!(
        "#import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput\n{}\n{PASS}",
        hadou_gpu::shaders::COMMON
    )
}

/// On a camera whose [`HadouCamera::mapping`] is hadou's: the mode of its colour mapping pass.
#[derive(Component, ExtractComponent, Clone, Copy, Debug, Default, PartialEq, ShaderType)]
pub(crate) struct ToneMapPass {
    mode: u32,
}

impl FullscreenMaterial for ToneMapPass {
    fn fragment_shader() -> ShaderRef {
        ShaderRef::Handle(SHADER)
    }

    fn schedule_configs(system: ScheduleConfigs<BoxedSystem>) -> ScheduleConfigs<BoxedSystem> {
        system.in_set(Core3dSystems::PostProcess).after(bloom).before(tonemapping)
    }
}

fn pass_of(mapping: ViewMapping) -> Option<ToneMapPass> {
    match mapping {
        ViewMapping::Bevy => None,
        ViewMapping::Hadou(ToneMode::Faithful) => Some(ToneMapPass { mode: MODE_FAITHFUL }),
        ViewMapping::Hadou(ToneMode::Filmic) => Some(ToneMapPass { mode: MODE_FILMIC }),
    }
}

/// A changed [`HadouCamera`] with its mapping pass and Bevy tone mapping, if any.
type ChangedCamera<'a> = (Entity, &'a HadouCamera, Option<&'a ToneMapPass>, Option<&'a mut Tonemapping>);

/// Gives every camera whose [`HadouCamera::mapping`] is hadou's its mapping pass and turns Bevy's
/// tone mapping off on it (`Tonemapping::None`); takes the pass off a camera set back to Bevy's.
pub(crate) fn apply_mapping(mut commands: Commands, mut cameras: Query<ChangedCamera, Changed<HadouCamera>>) {
    for (entity, camera, current, tonemapping) in &mut cameras {
        let wanted = pass_of(camera.mapping);
        if wanted.as_ref() != current {
            match wanted {
                Some(pass) => commands.entity(entity).insert(pass),
                None => commands.entity(entity).remove::<ToneMapPass>(),
            };
        }
        if wanted.is_some() {
            match tonemapping {
                Some(mut t) if *t != Tonemapping::None => *t = Tonemapping::None,
                Some(_) => {}
                None => {
                    commands.entity(entity).insert(Tonemapping::None);
                }
            }
        }
    }
}

/// A camera that loses its [`HadouCamera`] loses its mapping pass too.
pub(crate) fn remove_mapping(removed: On<Remove, HadouCamera>, mut commands: Commands) {
    if let Ok(mut entity) = commands.get_entity(removed.entity) {
        entity.try_remove::<ToneMapPass>();
    }
}
