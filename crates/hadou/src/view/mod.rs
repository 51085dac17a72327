//! `hadou view`: the window (only with the `hadou` crate's `view` feature, on by default). winit
//! owns the event loop, one wgpu device drives both the window's surface (egui's drawing) and,
//! when it is chosen, the GPU backend, which renders straight into a texture the viewport shows
//! ([`GpuBackend::render_to_texture`](hadou_gpu::GpuBackend::render_to_texture): no read-back).
//! The CPU backend renders on a worker thread, so the UI handles input every frame while a frame
//! renders; its finished image is converted to sRGB bytes there and uploaded into a texture of the
//! same format. The state, panels and script language are `hadou_view`'s; this module is the
//! native shell: devices, threads, screenshots, exports and probes.
//!
//! [`run`](fn@run) (`run.rs`) checks the input and runs the event loop (`event_loop.rs`) over the
//! window's state (`app.rs`); `surface.rs` opens the window, its surface and device and draws the
//! UI; `viewport.rs` keeps the viewport's image current on either backend, with the CPU render
//! thread in `cpu_worker.rs` and the textures in `texture.rs`; `requests.rs` carries out what the
//! panel and the script ask for (exports running in `export_job.rs`); `script_runner.rs` steps a
//! `--script`; `options.rs` holds the options and errors.

mod app;
mod cpu_worker;
mod event_loop;
mod export_job;
mod options;
mod requests;
mod run;
mod script_runner;
mod surface;
mod texture;
mod viewport;

pub use cpu_worker::srgba8_into;
pub use options::{no_display_message, ViewError, ViewOptions};
pub use run::run;
pub use texture::{upload_rgba, viewport_texture};
