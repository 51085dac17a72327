//! hadou in the browser: `hadou view`'s viewer as a static web page (docs/web.md).
//!
//! The page runs the same viewer state and UI as the native window (`hadou_view::viewer` and
//! `hadou_view::ui`), inside eframe's web runner on a canvas. Where the browser has WebGPU the
//! GPU backend draws the viewport (`hadou_gpu::GpuBackend::render_to_texture`, no read-back);
//! on WebGL2, which has no compute shaders, the CPU backend compiled to WebAssembly draws and
//! WebGL2 shows its image and the UI. Files come from memory: the presets are every example
//! scene embedded at build time ([`presets`]), dropped or opened scenes come with the files they
//! name ([`dropped`]); both are mounted as a `hadou_scene::MemoryFiles` set, so the loader, its
//! limits and its messages are `hadou render`'s. Screenshots, scene text and GIF exports leave
//! as downloads.
//!
//! The parts that do not need a browser ([`params`], [`presets`], [`dropped`], [`export`]) build
//! and are tested on any target; the page itself (`page`) exists only on `wasm32`.

pub mod dropped;
pub mod export;
pub mod params;
pub mod presets;

#[cfg(target_arch = "wasm32")]
mod page;
