//! The GPU-visible structs: one Rust definition each, `bytemuck::Pod` with explicit padding.
//!
//! Keep in sync with `src/shaders/common.wgsl` (same names, same field order, same padding);
//! `shaders::tests::gpu_structs_match_their_rust_definitions` checks every member offset and
//! struct size against the layout naga computes for the WGSL side.
//!
//! One file a feature: `frame.rs`, `waves.rs`, `shading.rs`, `shadows.rs`, `soft.rs`, `overlay.rs`,
//! `bloom.rs`; every item is re-exported here (`hadou_gpu::layout::GpuWave`, …).

mod bloom;
mod frame;
mod overlay;
mod shading;
mod shadows;
mod soft;
mod waves;

pub use bloom::*;
pub use frame::*;
pub use overlay::*;
pub use shading::*;
pub use shadows::*;
pub use soft::*;
pub use waves::*;
