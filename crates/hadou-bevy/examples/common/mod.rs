//! What the timing examples (`bench`, `stress`) share: the windowless Bevy app they time, one
//! frame's wall-clock time with the GPU waited for, the statistics and the JSON strings of their
//! reports, and the parsing of their whole-number flags.

use bevy::app::PluginGroupBuilder;
use bevy::prelude::*;
use bevy::render::renderer::RenderDevice;
use bevy::render::{RenderApp, RenderPlugin};
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;
use std::time::Instant;

/// Bevy's default plugins for an app with no window that renders into images: each frame
/// rendered within its `App::update` (no pipelined rendering, so that [`FrameClock::frame_ms`]'s
/// wait follows it), pipelines compiled synchronously (no frame skips a draw while one compiles).
pub fn windowless_plugins() -> PluginGroupBuilder {
    DefaultPlugins
        .build()
        .disable::<WinitPlugin>()
        .disable::<bevy::render::pipelined_rendering::PipelinedRenderingPlugin>()
        .set(WindowPlugin { primary_window: None, exit_condition: ExitCondition::DontExit, ..default() })
        .set(RenderPlugin { synchronous_pipeline_compilation: true, ..default() })
}

/// Times frames of a finished app (`App::finish` and `App::cleanup` called): each
/// `App::update` followed by a wait for Bevy's device to go idle.
pub struct FrameClock {
    device: wgpu::Device,
}

impl FrameClock {
    /// The clock of `app`'s render device.
    pub fn new(app: &App) -> Self {
        FrameClock { device: app.sub_app(RenderApp).world().resource::<RenderDevice>().wgpu_device().clone() }
    }

    /// One frame of `app`, milliseconds of wall clock: its update and the GPU work it submitted.
    pub fn frame_ms(&self, app: &mut App) -> f64 {
        let start = Instant::now();
        app.update();
        let _ = self.device.poll(wgpu::PollType::Wait { submission_index: None, timeout: None });
        start.elapsed().as_secs_f64() * 1e3
    }
}

/// The median of `v` (NaN when empty).
pub fn median(v: &[f64]) -> f64 {
    quantile(v, 0.5)
}

/// The `q` quantile of `v` (`0 ≤ q ≤ 1`), linearly interpolated between the sorted samples
/// (NaN when empty): `q = 0.5` is the median, `0.9` the 90th percentile.
pub fn quantile(v: &[f64], q: f64) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    let x = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x.fract());
    match v.get(i + 1) {
        Some(next) => v[i] + (next - v[i]) * f,
        None => v[i],
    }
}

/// `s` as a JSON string literal.
pub fn json_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out + "\""
}

/// The value of a whole-number flag: `1..=16384`, or an error naming the flag.
pub fn whole_number(flag: &str, value: Option<String>) -> Result<u32, String> {
    let v = value.ok_or(format!("{flag} needs a value"))?;
    match v.parse::<u32>() {
        Ok(n) if (1..=16384).contains(&n) => Ok(n),
        _ => Err(format!("{flag}: `{v}` is not a whole number in 1..=16384")),
    }
}

/// The camera of `frame` as a Bevy transform and projection.
pub fn camera(frame: &hadou_scene::Frame) -> (Transform, Projection) {
    let c = &frame.camera;
    let v = |p: hadou_math::Vec3f| Vec3::new(p.x, p.y, p.z);
    let transform = Transform::from_translation(v(c.position)).looking_at(v(c.target), v(c.up));
    let projection = Projection::Perspective(PerspectiveProjection {
        fov: c.fov_y_deg.to_radians(),
        near: c.near,
        far: c.far,
        ..default()
    });
    (transform, projection)
}
