//! Reading untrusted files: only regular files, never more than a cap. A FIFO would block
//! forever and `/dev/zero` never ends, so the type is checked before opening and again on the
//! opened handle, and the read itself stops one byte past the cap (a file that grows while it is
//! read is caught too). [`SceneDir`] is the scene file's directory tree, which every file a scene
//! names (textures, glTF files) must lie in.

use std::fs::{File, OpenOptions};
use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest scene file read, in bytes (16 MiB).
pub const SCENE_MAX_BYTES: u64 = 16 << 20;
/// Largest `.gltf`/`.glb` file, and the most bytes one glTF file may read in all (the file plus
/// every external buffer), in bytes (1 GiB).
pub const GLTF_MAX_BYTES: u64 = 1 << 30;
/// Largest JSON text of a glTF file (the `.gltf` file or a `.glb`'s JSON chunk), in bytes
/// (256 MiB): the JSON is parsed into two trees (its strings, data URIs included, held three
/// times with the decoded bytes), so it is bounded on its own, below what binary buffers may
/// take; [`GLTF_MAX_JSON_OBJECTS`] and [`GLTF_MAX_JSON_VALUES`] bound the structure.
pub const GLTF_MAX_JSON_BYTES: u64 = 256 << 20;
/// Most JSON objects in a glTF file's JSON (2²⁰: about 400 MiB once parsed, at most).
pub const GLTF_MAX_JSON_OBJECTS: u64 = 1 << 20;
/// Most JSON values and keys in a glTF file's JSON (2²², counted as its `{`, `[`, `,` and `:`
/// outside strings).
pub const GLTF_MAX_JSON_VALUES: u64 = 1 << 22;

/// What kind of file system entry `meta` describes, for messages.
fn kind(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
    }
    "not a regular file"
}

fn check(meta: &std::fs::Metadata, cap: u64) -> Result<(), String> {
    if !meta.is_file() {
        let k = kind(meta);
        return Err(if k == "not a regular file" {
            "it is not a regular file".into()
        } else {
            format!("it is {k}, not a regular file")
        });
    }
    if meta.len() > cap {
        return Err(format!("it is {} bytes, more than the limit of {}", meta.len(), describe_bytes(cap)));
    }
    Ok(())
}

/// `16 MiB`, `1 GiB`, or a byte count.
pub(crate) fn describe_bytes(n: u64) -> String {
    if n >= 1 << 30 && n.is_multiple_of(1 << 30) {
        format!("{} GiB", n >> 30)
    } else if n >= 1 << 20 && n.is_multiple_of(1 << 20) {
        format!("{} MiB", n >> 20)
    } else {
        format!("{n} bytes")
    }
}

fn open(path: &Path) -> std::io::Result<File> {
    let mut o = OpenOptions::new();
    o.read(true);
    // Should the path be swapped for a FIFO between the check and the open, a non-blocking open
    // returns at once instead of waiting for a writer (it changes nothing for regular files).
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::OpenOptionsExt;
        o.custom_flags(0o4000); // O_NONBLOCK
    }
    #[cfg(target_os = "macos")]
    {
        use std::os::unix::fs::OpenOptionsExt;
        o.custom_flags(0x0004); // O_NONBLOCK
    }
    o.open(path)
}

/// The bytes of the regular file at `path` (symbolic links followed), at most `cap` of them.
/// Errors are plain-language reasons without the path ("it is a FIFO, not a regular file",
/// "No such file or directory (os error 2)", …).
pub fn read_regular_file(path: &Path, cap: u64) -> Result<Vec<u8>, String> {
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    check(&meta, cap)?;
    let file = open(path).map_err(|e| e.to_string())?;
    check(&file.metadata().map_err(|e| e.to_string())?, cap)?;
    let mut out = Vec::with_capacity(meta.len().min(cap) as usize);
    file.take(cap.saturating_add(1)).read_to_end(&mut out).map_err(|e| e.to_string())?;
    if out.len() as u64 > cap {
        return Err(format!("it grew past the limit of {} while it was read", describe_bytes(cap)));
    }
    Ok(out)
}

/// The directory of `path`, `.` for a bare file name.
pub(crate) fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The scene file's directory, the tree every file a scene names must lie in, and its canonical
/// form, resolved when first needed.
pub(crate) struct SceneDir {
    /// The directory as given.
    pub path: PathBuf,
    root: Option<PathBuf>,
}

impl SceneDir {
    /// The directory `path`, not yet resolved.
    pub(crate) fn new(path: PathBuf) -> Self {
        SceneDir { path, root: None }
    }

    /// The canonical directory (symbolic links followed), resolved once.
    pub(crate) fn root(&mut self) -> Result<PathBuf, String> {
        if let Some(r) = &self.root {
            return Ok(r.clone());
        }
        let r = std::fs::canonicalize(&self.path).map_err(|e| {
            format!("cannot resolve the scene file's directory {}: {e}", crate::error::show_path(&self.path))
        })?;
        self.root = Some(r.clone());
        Ok(r)
    }
}
