//! # hadou-scene
//!
//! Scene files (TOML) → typed, validated [`Scene`] with animation tracks → [`Frame`] at any time.
//! Also the [`Image`] every backend returns and the [`Backend`] trait.

mod backend;
mod frame;
mod image;

pub use backend::{Backend, RenderError};
pub use frame::*;
pub use image::Image;
