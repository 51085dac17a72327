//! Shared by the plugin's tests that draw: the adapter check and a Bevy app without a window.
#![allow(dead_code)]

pub mod picture;
pub mod split;

use bevy::app::PluginGroupBuilder;
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;

/// Whether a GPU adapter is there to draw with; without one the test prints a skip message and
/// returns, unless `HADOU_REQUIRE_GPU=1` makes that a failure.
pub fn adapter_or_skip(test: &str) -> bool {
    match hadou_gpu::request_adapter() {
        Ok(_) => true,
        Err(e) if std::env::var("HADOU_REQUIRE_GPU").is_ok_and(|v| v == "1") => {
            panic!("{test}: HADOU_REQUIRE_GPU=1 but no usable GPU adapter ({e})")
        }
        Err(e) => {
            eprintln!("SKIPPED {test}: {e}; set HADOU_REQUIRE_GPU=1 to make this a failure");
            false
        }
    }
}

/// Bevy's default plugins without a window (the app renders into images and is stopped by the
/// test), pipelines compiled before the first frame that uses them.
pub fn windowless() -> PluginGroupBuilder {
    DefaultPlugins
        .build()
        .disable::<WinitPlugin>()
        .set(WindowPlugin { primary_window: None, exit_condition: ExitCondition::DontExit, ..default() })
        .set(RenderPlugin { synchronous_pipeline_compilation: true, ..default() })
}
