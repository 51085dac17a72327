//! # hadou
//!
//! Real-time anime-style energy waves from formulas. This crate is the facade over the workspace:
//! load a [`Scene`], evaluate it at a time into a [`Frame`], render it with a [`Backend`], and
//! write the [`Image`].
//!
//! ```no_run
//! use hadou::{Backend, CpuBackend, Scene};
//! let scene = Scene::load("scenes/kamehameha.toml").expect("valid scene");
//! let frame = scene.at(1.0);
//! let image = CpuBackend::new().render(&frame).expect("render");
//! hadou::output::write_png(&image, "kamehameha.png".as_ref()).expect("written");
//! ```
//!
//! Modules: [`output`] writes images (PNG, EXR), [`export`] animations with progress and cancel,
//! [`farm`] the frame stamps, names and checks a render farm relies on,
//! [`bench`](mod@bench) measures the thesis's tables, and `view` is the window of `hadou view`.
//!
//! ## Features
//!
//! - `view` (on by default): the `view` module and `hadou view`'s window, with what only they
//!   build: winit, egui, egui-wgpu, egui-winit and `hadou-view`. A program that only renders
//!   depends on hadou with `default-features = false` and builds none of them.

pub mod bench;
pub mod export;
pub mod farm;
pub mod output;
#[cfg(feature = "view")]
pub mod view;

pub use hadou_cpu::{probe, CpuBackend, Probe, WaveProbe};
pub use hadou_gpu as gpu;
pub use hadou_gpu::GpuBackend;
pub use hadou_math as math;
pub use hadou_scene::*;

/// The package's README (what crates.io shows): its examples compile as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
