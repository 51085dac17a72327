//! # hadou-cpu
//!
//! The CPU reference backend: renders a [`Frame`](hadou_scene::Frame) to an
//! [`Image`](hadou_scene::Image) with the exact closed forms of `hadou-math`, multi-threaded with
//! rayon and deterministic (the same picture for any number of threads). It is the oracle the GPU
//! backend is tested against, and the fall-back where no GPU adapter exists.
//!
//! Passes, in order, after the per-frame set-up (`setup`): opaque geometry and its outline hulls
//! (`opaque`, drawn with the triangle rasterizer `raster`), shaded with the materials and the waves
//! as lights (`shading`) and darkened by the hard shadows (`shadows`), lit by the area light
//! through its soft shadows (`soft`), outlines closed where objects meet (`edges`), then the
//! energy integrals clipped at the visible surface and the colour mapping (`waves`), with a
//! `[bloom]` the glare on the linear colour before the mapping (`bloom`). `render` runs them for a
//! frame, `probe` for one pixel.

mod bloom;
mod edges;
mod opaque;
mod probe;
mod raster;
mod render;
mod setup;
mod shading;
mod shadows;
pub mod soft;
pub mod traced;
mod waves;
mod winding;

pub use probe::{probe, Probe, WaveProbe};
pub use render::{
    render, render_every_sample_shaded, render_rows, render_rows_glare_chunked, render_timed, CpuBackend,
    PassTimes,
};
