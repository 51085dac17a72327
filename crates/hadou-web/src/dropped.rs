//! Scenes a user drops on the page (or opens with its file button): the dropped files become a
//! [`MemoryFiles`] set under [`DROP_DIR`], the one scene file among them is loaded, and a file the
//! scene names that was dropped without its folder (`assets/hero.glb` dropped as `hero.glb`) is
//! found by its name.

use hadou_scene::MemoryFiles;
use hadou_view::document::Document;
use std::path::{Path, PathBuf};

/// Where dropped files lie in the page's file set.
pub const DROP_DIR: &str = "/dropped";

/// One batch of dropped files: their names and bytes, and the files refused by size before they
/// were read (with the reason).
#[derive(Clone, Debug, Default)]
pub struct DropBatch {
    /// Name and bytes of each file read.
    pub files: Vec<(String, Vec<u8>)>,
    /// Files not read, with why.
    pub refused: Vec<String>,
}

/// Why a file of `size` bytes named `name` is not read, or `None` when it may be: too large for
/// its kind ([`hadou_scene::file_size_limit`], the limits of docs/scene-format.md), or of a kind
/// no scene names.
pub fn refuse_by_size(name: &str, size: f64) -> Option<String> {
    let shown = hadou_scene::escape_controls(name);
    match hadou_scene::file_size_limit(name) {
        None => Some(format!(
            "{shown}: not read: a scene names only .toml scene files, glTF files (.gltf .glb .vrm .vrma .bin) and \
             textures (.png .jpg .jpeg)"
        )),
        Some((cap, what)) if size.is_nan() || size > cap as f64 => Some(format!(
            "{shown}: not read: it is {size} bytes, more than the {cap} bytes {what} may have (docs/scene-format.md)"
        )),
        Some(_) => None,
    }
}

/// Loads the batch's scene with `base` (the files already in the page: the presets) and the
/// dropped files mounted, and leaves them mounted (the document's edits load the scene again);
/// or returns the loader's message (`file:line:col: …`) and mounts the set mounted before again.
/// Fails without a scene file or with more than one.
pub fn load(batch: &DropBatch, base: &MemoryFiles) -> Result<Document, String> {
    let scenes: Vec<&(String, Vec<u8>)> = batch.files.iter().filter(|(n, _)| is_scene(n)).collect();
    let scene = match scenes.as_slice() {
        [one] => one,
        [] => return Err("no scene file (.toml) among the dropped files: drop the scene file together with the files it names".into()),
        many => {
            let names: Vec<String> = many.iter().map(|(n, _)| hadou_scene::escape_controls(n).into_owned()).collect();
            return Err(format!("drop one scene file at a time (these are {})", names.join(", ")));
        }
    };
    let mut set = base.clone();
    set.missing_note = "it was not dropped with the scene: drop it together with the scene file".into();
    for (name, bytes) in &batch.files {
        set.insert(Path::new(DROP_DIR).join(file_name(name)), bytes.clone());
    }
    let path = Path::new(DROP_DIR).join(file_name(&scene.0));
    let previous = hadou_scene::mount_memory_files(Some(set));
    let mut outcome = Document::open(&path);
    // A file named by a path below the scene's folder but dropped on its own (`assets/hero.glb`
    // dropped as `hero.glb`): put it where the scene looks for it and load again, at most once
    // per dropped file.
    for _ in 0..batch.files.len() {
        if outcome.is_ok() {
            break;
        }
        let mut set = hadou_scene::mount_memory_files(None).expect("mounted above");
        let found: Vec<(PathBuf, Vec<u8>)> = set
            .take_missed()
            .into_iter()
            .filter_map(|p| dropped_by_name(batch, &p).map(|b| (p, b.to_vec())))
            .collect();
        let retry = !found.is_empty();
        for (p, b) in found {
            set.insert(p, b);
        }
        hadou_scene::mount_memory_files(Some(set));
        if !retry {
            break;
        }
        outcome = Document::open(&path);
    }
    match outcome {
        Ok(doc) => Ok(doc),
        Err(e) => {
            hadou_scene::mount_memory_files(previous);
            Err(e.to_string())
        }
    }
}

fn is_scene(name: &str) -> bool {
    Path::new(name).extension().is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

/// The last component of a dropped file's name (browsers give bare names; a path is cut).
fn file_name(name: &str) -> PathBuf {
    PathBuf::from(name.rsplit(['/', '\\']).next().unwrap_or(name))
}

/// The bytes of a dropped file whose name is `wanted`'s file name, when `wanted` lies below the
/// drop folder and is not itself one of the dropped paths.
fn dropped_by_name<'a>(batch: &'a DropBatch, wanted: &Path) -> Option<&'a [u8]> {
    if !wanted.starts_with(DROP_DIR) || wanted.parent() == Some(Path::new(DROP_DIR)) {
        return None;
    }
    let name = wanted.file_name()?.to_str()?;
    batch.files.iter().find(|(n, _)| file_name(n).to_str() == Some(name)).map(|(_, b)| b.as_slice())
}
