//! Which files a scene may name, by extension, and the most bytes each kind may have: what a page
//! checks a dropped file against before reading it.

use crate::files::{GLTF_MAX_BYTES, SCENE_MAX_BYTES};
use crate::texture::TEXTURE_MAX_BYTES;
use std::path::Path;

/// The largest file the loader reads under the name `name`, from its extension: scene files
/// ([`SCENE_MAX_BYTES`]), glTF files, their buffers and VRMA clips ([`GLTF_MAX_BYTES`]) and
/// textures ([`TEXTURE_MAX_BYTES`]), with what kind of file that is; `None` for a name no
/// scene reads. A page checks a dropped file's size against it before reading the file.
pub fn file_size_limit(name: &str) -> Option<(u64, &'static str)> {
    let ext = Path::new(name).extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "toml" => Some((SCENE_MAX_BYTES, "a scene file")),
        "gltf" | "glb" | "vrm" | "vrma" | "bin" => Some((GLTF_MAX_BYTES, "a glTF file or buffer")),
        "png" | "jpg" | "jpeg" => Some((TEXTURE_MAX_BYTES, "a texture")),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn size_limits_follow_the_extension() {
        assert_eq!(file_size_limit("a/b.TOML").map(|l| l.0), Some(SCENE_MAX_BYTES));
        assert_eq!(file_size_limit("hero.vrm").map(|l| l.0), Some(GLTF_MAX_BYTES));
        assert_eq!(file_size_limit("face.jpeg").map(|l| l.0), Some(TEXTURE_MAX_BYTES));
        assert_eq!(file_size_limit("notes.txt"), None);
        assert_eq!(file_size_limit("noext"), None);
    }
}
