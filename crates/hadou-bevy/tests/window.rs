//! Split screen on a window: the two cameras of `tests/viewports.rs` (`common/split.rs`), the
//! scene's in the left half of the primary window and a second one, from another side, in the
//! right half, each drawing its waves against its own depth into the window's surface; a
//! screenshot of the window holds each half to hadou-cpu's render of its camera (mean ≤ 2). The
//! app runs as a game runs, under winit's event loop (on the test's thread; one event loop a
//! process, so this file holds one test). Needs a display: without `DISPLAY` it skips with a
//! message, unless `HADOU_REQUIRE_WINDOW=1` (CI runs it under `xvfb-run` with that set) makes that
//! a failure; without an adapter it skips unless `HADOU_REQUIRE_GPU=1`.

mod common;

use bevy::image::Image;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::render::RenderPlugin;
use bevy::window::WindowResolution;
use bevy::winit::WinitPlugin;
use common::adapter_or_skip;
use common::picture::scenes;
use common::split::{check, halves, split, Split};
use hadou_bevy::{HadouPlugin, HadouSceneRoot, SceneClock, SpawnedScene};
use std::sync::{Arc, Mutex};

/// The screenshot once taken, and the spawned scene's root.
#[derive(Resource)]
struct Shot(Arc<Mutex<Option<Image>>>, Entity);

/// Frames the scene has been drawn after it spawned.
#[derive(Resource, Default)]
struct Drawn(u32);

/// Five frames after the scene is ready, asks for a screenshot of the window; exits once it is
/// back (or after `FRAME_LIMIT` frames, leaving the test to fail on the missing picture).
fn screenshot(
    mut commands: Commands,
    shot: Res<Shot>,
    spawned: Query<&SpawnedScene>,
    mut drawn: ResMut<Drawn>,
    mut frames: Local<u32>,
    mut exit: MessageWriter<AppExit>,
) {
    *frames += 1;
    if spawned.get(shot.1).is_ok_and(|s| s.ready) {
        drawn.0 += 1;
    }
    if drawn.0 == 5 {
        let taken = shot.0.clone();
        commands.spawn(Screenshot::primary_window()).observe(
            move |captured: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
                *taken.lock().unwrap() = Some(captured.image.clone());
                exit.write(AppExit::Success);
            },
        );
    }
    if *frames > FRAME_LIMIT {
        exit.write(AppExit::error());
    }
}

/// Frames after which the app gives up.
const FRAME_LIMIT: u32 = 2000;

#[test]
fn two_viewports_on_one_window_each_draw_their_own_cameras_waves() {
    let test = "two_viewports_on_one_window_each_draw_their_own_cameras_waves";
    if std::env::var_os("DISPLAY").is_none() {
        if std::env::var("HADOU_REQUIRE_WINDOW").is_ok_and(|v| v == "1") {
            panic!("{test}: HADOU_REQUIRE_WINDOW=1 but no display (DISPLAY is not set)");
        }
        eprintln!("SKIPPED {test}: no display (DISPLAY); set HADOU_REQUIRE_WINDOW=1 to make this a failure");
        return;
    }
    if !adapter_or_skip(test) {
        return;
    }
    let root = scenes().canonicalize().unwrap();
    let halves = halves(&root);
    let (w, h) = (halves.left.width, halves.left.height);
    let window = Window {
        title: test.into(),
        resolution: WindowResolution::new(2 * w, h).with_scale_factor_override(1.0),
        resizable: false,
        ..default()
    };
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(WindowPlugin { primary_window: Some(window), ..default() })
            .set(WinitPlugin { run_on_any_thread: true })
            .set(AssetPlugin { file_path: root.display().to_string(), ..default() })
            .set(RenderPlugin { synchronous_pipeline_compilation: true, ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: root.clone() });
    let scene = app.world().resource::<AssetServer>().load(halves.file.to_string());
    let scene_root =
        app.world_mut().spawn(HadouSceneRoot { scene, clock: SceneClock::Frozen(halves.time) }).id();
    let taken: Arc<Mutex<Option<Image>>> = Arc::default();
    app.insert_resource(Split::new(None, &halves))
        .insert_resource(Shot(taken.clone(), scene_root))
        .init_resource::<Drawn>()
        .add_systems(Update, (split, screenshot));
    let exit = app.run();
    let shot = taken.lock().unwrap().take();
    let shot = shot.unwrap_or_else(|| panic!("{test}: no screenshot of the window came back ({exit:?})"));
    check("one window", &halves, shot);
}
