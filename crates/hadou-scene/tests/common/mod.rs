//! Helpers shared by the scene crate's error tests.
#![allow(dead_code)]

use hadou_scene::{Scene, SceneError};
use std::path::Path;

/// The error `text` must produce (as if read from `scenes/x.toml`).
pub fn err(text: &str) -> SceneError {
    match Scene::parse(text, Path::new("scenes/x.toml")) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    }
}

/// The 1-based line and column an error points at.
pub fn at(e: &SceneError) -> (usize, usize) {
    let l = e.location().unwrap_or_else(|| panic!("no location: {e}"));
    (l.line, l.col)
}
