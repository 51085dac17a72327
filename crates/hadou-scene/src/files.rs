//! Reading untrusted files: only regular files, never more than a cap. A FIFO would block
//! forever and `/dev/zero` never ends, so the type is checked before opening and again on the
//! opened handle, and the read itself stops one byte past the cap (a file that grows while it is
//! read is caught too). [`SceneDir`] is the scene file's directory tree, which every file a scene
//! names (textures, glTF files) must lie in.
//!
//! Where there is no file system (a web page) or a program holds the files itself, a
//! [`MemoryFiles`] set is mounted on the thread ([`mount_memory_files`]): while it is, every
//! file the loader reads on that thread (scene files, glTF files and their buffers, textures,
//! VRMA clips) comes from the set, under the same size caps and the same rule that a scene's files
//! lie inside its directory, and a path the set lacks is "not among the files given"
//! ([`MemoryFiles::missing_note`]).

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::Read;
use std::path::{Component, Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;

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
    if let Some(set) = mounted() {
        return set.read(path, cap);
    }
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
        let r = canonicalize(&self.path).map_err(|e| {
            format!("cannot resolve the scene file's directory {}: {e}", crate::error::show_path(&self.path))
        })?;
        self.root = Some(r.clone());
        Ok(r)
    }
}

/// Files held in memory under absolute paths (`/scenes/kamehameha.toml`), standing in for the
/// file system while mounted (see the module documentation). Directories are implied by the
/// files' paths.
#[derive(Clone, Debug)]
pub struct MemoryFiles {
    files: BTreeMap<PathBuf, Arc<[u8]>>,
    /// Why a path the set lacks cannot be read (the end of "cannot read PATH: …").
    pub missing_note: String,
    /// The paths asked for that the set lacks, in order ([`MemoryFiles::take_missed`]).
    missed: RefCell<Vec<PathBuf>>,
}

impl Default for MemoryFiles {
    fn default() -> Self {
        Self::new()
    }
}

impl MemoryFiles {
    /// An empty set whose missing files are "not among the files given".
    pub fn new() -> MemoryFiles {
        MemoryFiles {
            files: BTreeMap::new(),
            missing_note: "it is not among the files given".into(),
            missed: RefCell::new(Vec::new()),
        }
    }

    /// Adds (or replaces) the file at `path`, made absolute and normalised (`.` and `..`
    /// resolved by name).
    pub fn insert(&mut self, path: impl AsRef<Path>, bytes: impl Into<Arc<[u8]>>) {
        self.files.insert(normalise(path.as_ref()), bytes.into());
    }

    /// The file at `path` (normalised as by [`MemoryFiles::insert`]), if the set has it.
    pub fn get(&self, path: impl AsRef<Path>) -> Option<&Arc<[u8]>> {
        self.files.get(&normalise(path.as_ref()))
    }

    /// Every file's path, in order.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.files.keys().map(PathBuf::as_path)
    }

    /// The paths the loader asked for that the set lacks, since the last call (a page can offer
    /// a dropped file of the same name there).
    pub fn take_missed(&self) -> Vec<PathBuf> {
        std::mem::take(&mut *self.missed.borrow_mut())
    }

    fn miss(&self, p: PathBuf) {
        self.missed.borrow_mut().push(p);
    }

    /// Whether the set has no files.
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    fn is_dir(&self, p: &Path) -> bool {
        self.files.range(p.to_path_buf()..).next().is_some_and(|(k, _)| k != p && k.starts_with(p))
    }

    /// The canonical form of `path` in the set: the normalised path of a file or directory it
    /// has.
    fn canonicalize(&self, path: &Path) -> std::io::Result<PathBuf> {
        let p = normalise(path);
        if self.files.contains_key(&p) || self.is_dir(&p) {
            Ok(p)
        } else {
            self.miss(p);
            Err(std::io::Error::new(std::io::ErrorKind::NotFound, self.missing_note.clone()))
        }
    }

    fn read(&self, path: &Path, cap: u64) -> Result<Vec<u8>, String> {
        let p = normalise(path);
        match self.files.get(&p) {
            Some(bytes) if bytes.len() as u64 > cap => {
                Err(format!("it is {} bytes, more than the limit of {}", bytes.len(), describe_bytes(cap)))
            }
            Some(bytes) => Ok(bytes.to_vec()),
            None if self.is_dir(&p) => Err("it is a directory, not a regular file".into()),
            None => {
                self.miss(p);
                Err(self.missing_note.clone())
            }
        }
    }
}

/// `path` made absolute (under `/`) with `.` and `..` resolved by name (`..` at the top stays
/// at the top).
fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::from("/");
    for c in path.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::Normal(n) => out.push(n),
            Component::CurDir | Component::RootDir | Component::Prefix(_) => {}
        }
    }
    out
}

thread_local! {
    static MOUNTED: RefCell<Option<Rc<MemoryFiles>>> = const { RefCell::new(None) };
}

/// Mounts `files` on this thread in place of the file system (`None` unmounts): every file the
/// loader reads on this thread from now on comes from the set. Returns the set mounted before.
pub fn mount_memory_files(files: Option<MemoryFiles>) -> Option<MemoryFiles> {
    let old = MOUNTED.with(|m| m.replace(files.map(Rc::new)));
    old.map(|rc| Rc::try_unwrap(rc).unwrap_or_else(|rc| (*rc).clone()))
}

fn mounted() -> Option<Rc<MemoryFiles>> {
    MOUNTED.with(|m| m.borrow().clone())
}

/// `std::fs::canonicalize`, or the mounted [`MemoryFiles`]' canonical path while a set is
/// mounted on this thread.
pub(crate) fn canonicalize(path: &Path) -> std::io::Result<PathBuf> {
    match mounted() {
        Some(set) => set.canonicalize(path),
        None => std::fs::canonicalize(path),
    }
}

#[cfg(test)]
mod memory_tests {
    use super::*;

    #[test]
    fn a_mounted_set_stands_in_for_the_file_system_with_the_same_caps() {
        let mut set = MemoryFiles::new();
        set.insert("/s/scene.toml", b"abc".to_vec());
        set.insert("s/assets/../assets/hero.glb", vec![0u8; 10]);
        assert!(set.get("/s/assets/hero.glb").is_some());
        let old = mount_memory_files(Some(set));
        assert!(old.is_none());
        assert_eq!(read_regular_file(Path::new("/s/./scene.toml"), 16).unwrap(), b"abc");
        let e = read_regular_file(Path::new("/s/assets/hero.glb"), 4).unwrap_err();
        assert!(e.contains("10 bytes") && e.contains("limit"), "{e}");
        let e = read_regular_file(Path::new("/s/missing.png"), 4).unwrap_err();
        assert!(e.contains("not among the files given"), "{e}");
        assert_eq!(mounted().unwrap().take_missed(), vec![PathBuf::from("/s/missing.png")]);
        assert!(mounted().unwrap().take_missed().is_empty());
        let e = read_regular_file(Path::new("/s/assets"), 4).unwrap_err();
        assert!(e.contains("directory"), "{e}");
        assert_eq!(
            canonicalize(Path::new("/s/assets/../scene.toml")).unwrap(),
            PathBuf::from("/s/scene.toml")
        );
        assert_eq!(canonicalize(Path::new("/s/assets")).unwrap(), PathBuf::from("/s/assets"));
        assert!(canonicalize(Path::new("/s/asset")).is_err());
        // Climbing out of the top stays at the top.
        assert_eq!(normalise(Path::new("/../../s/scene.toml")), PathBuf::from("/s/scene.toml"));
        let back = mount_memory_files(None).expect("the set mounted above");
        assert_eq!(back.paths().count(), 2);
        // Unmounted, the real file system answers again.
        assert!(read_regular_file(Path::new("/s/scene.toml"), 16).is_err());
    }
}
