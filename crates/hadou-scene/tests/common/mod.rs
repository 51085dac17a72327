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

/// Standard base64 (with `=` padding), for `data:` URIs in hand-built glTF files.
pub fn base64(data: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let v = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for i in 0..4 {
            s.push(if i <= c.len() { A[(v >> (18 - 6 * i) & 63) as usize] as char } else { '=' });
        }
    }
    s
}
