//! The page's presets: every example scene of `scenes/` with the asset files the scenes name,
//! embedded at build time (`build.rs`) and served to the loader as a [`MemoryFiles`] set under
//! [`PRESET_DIR`], so a preset loads exactly as `hadou render scenes/NAME.toml` loads it.

use hadou_scene::MemoryFiles;
use std::path::PathBuf;

include!(concat!(env!("OUT_DIR"), "/presets.rs"));

/// Where the presets lie in the page's file set.
pub const PRESET_DIR: &str = "/scenes";

/// The scene files' names without `.toml`, sorted (`fig4-1-beam`, …, `spiral-drill`).
pub fn names() -> Vec<&'static str> {
    let mut v: Vec<&str> =
        FILES.iter().filter_map(|(rel, _)| rel.strip_suffix(".toml")).filter(|n| !n.contains('/')).collect();
    v.sort_unstable();
    v
}

/// The scene file of preset `name`, or an error naming the presets there are.
pub fn scene_path(name: &str) -> Result<PathBuf, String> {
    let all = names();
    if all.contains(&name) {
        Ok(PathBuf::from(format!("{PRESET_DIR}/{name}.toml")))
    } else {
        Err(format!(
            "there is no preset scene `{}`; the presets are {}",
            hadou_scene::escape_controls(name),
            all.join(", ")
        ))
    }
}

/// Every embedded file under [`PRESET_DIR`].
pub fn files() -> MemoryFiles {
    let mut set = MemoryFiles::new();
    for (rel, bytes) in FILES {
        set.insert(format!("{PRESET_DIR}/{rel}"), *bytes);
    }
    set
}

/// The embedded files' total size in bytes.
pub fn total_bytes() -> usize {
    FILES.iter().map(|(_, b)| b.len()).sum()
}
