//! # hadou-view
//!
//! The viewer's state and UI, without any window code: the [`document::Document`] (the scene file
//! as a format-preserving TOML tree, kept in step with the parsed scene; edits, keys, the firing
//! preset, undo/redo, save and hot reload), the [`viewer::Viewer`] (timeline, camera moves, the
//! edit rules for animated parameters), [`script`] (the `--script` language) and [`ui`] (the egui
//! panels, gizmos and timeline). The window (winit, wgpu surface, render threads, export) is
//! `hadou::view`, behind the `hadou` crate's `view` feature; this crate builds for
//! `wasm32-unknown-unknown`.

pub mod document;
pub mod script;
pub mod ui;
pub mod viewer;
