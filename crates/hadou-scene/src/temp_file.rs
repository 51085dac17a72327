//! The one way the workspace writes a file: to a [`TempFile`] beside the destination, registered
//! for clean-up before it exists, renamed into place when complete. Images, animations and saved
//! scene files all go through it, so an interrupt handler that calls [`remove_pending_temp_files`]
//! leaves no partial file of any writer behind.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// Temporary files that may exist right now. A path is added, under the lock, before its file is
/// created, and removed, under the same lock, after the file is renamed into place or deleted; so
/// [`remove_pending_temp_files`] sees every temporary file from before its first byte to its
/// rename, and never a half-renamed state.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Distinguishes the temporary files of writes running at once in one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Attempts at a fresh name when a stale file (of an earlier process with the same id) is in the
/// way.
const NAME_ATTEMPTS: u32 = 64;

fn pending() -> MutexGuard<'static, Vec<PathBuf>> {
    PENDING.lock().unwrap_or_else(|p| p.into_inner())
}

/// Deletes every temporary file being written and returns how many there were. For an interrupt
/// handler that ends the process next: it keeps the lock, so no temporary file can be created or
/// renamed into place afterwards.
pub fn remove_pending_temp_files() -> usize {
    let mut files = pending();
    let mut removed = 0;
    for f in files.iter() {
        if std::fs::remove_file(f).is_ok() {
            removed += 1;
        }
    }
    files.clear();
    std::mem::forget(files); // keep the lock held until the process exits
    removed
}

/// A temporary file `.NAME.PID.N.tmp` in the directory of an output path `NAME`: registered for
/// [`remove_pending_temp_files`] before it is created, deleted on drop unless
/// [`TempFile::commit`] renamed it over the output.
#[derive(Debug)]
pub struct TempFile {
    tmp: PathBuf,
}

impl TempFile {
    /// Creates a new temporary file for `path` (never replacing an existing file) and returns it
    /// with the open file to write into. Fails as creating a file in `path`'s directory fails.
    pub fn create(path: &Path) -> std::io::Result<(TempFile, File)> {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let mut attempt = 0;
        loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let tmp = dir.join(format!(".{name}.{}.{n}.tmp", std::process::id()));
            let mut list = pending();
            list.push(tmp.clone());
            match File::options().write(true).create_new(true).open(&tmp) {
                Ok(file) => return Ok((TempFile { tmp }, file)),
                Err(e) => {
                    list.retain(|p| p != &tmp);
                    attempt += 1;
                    if e.kind() != std::io::ErrorKind::AlreadyExists || attempt == NAME_ATTEMPTS {
                        return Err(e);
                    }
                }
            }
        }
    }

    /// The temporary file's path.
    pub fn path(&self) -> &Path {
        &self.tmp
    }

    /// Renames the finished temporary file over `path` (close its file first). On failure the
    /// temporary file is deleted.
    pub fn commit(mut self, path: &Path) -> std::io::Result<()> {
        let mut list = pending();
        std::fs::rename(&self.tmp, path)?;
        list.retain(|p| p != &self.tmp);
        self.tmp = PathBuf::new();
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if self.tmp.as_os_str().is_empty() {
            return;
        }
        let mut list = pending();
        let _ = std::fs::remove_file(&self.tmp);
        list.retain(|p| p != &self.tmp);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn registered(p: &Path) -> bool {
        pending().iter().any(|q| q == p)
    }

    #[test]
    fn a_temp_file_is_registered_until_committed_or_dropped() {
        let dir = std::env::temp_dir().join(format!("hadou-temp-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("out.txt");
        let (a, file) = TempFile::create(&out).unwrap();
        drop(file);
        let a_path = a.path().to_path_buf();
        assert!(a_path.exists() && registered(&a_path));
        let (b, _) = TempFile::create(&out).unwrap();
        assert_ne!(a.path(), b.path(), "two writes at once share a temporary file");
        let b_path = b.path().to_path_buf();
        a.commit(&out).unwrap();
        assert!(out.exists() && !a_path.exists() && !registered(&a_path));
        drop(b);
        assert!(!b_path.exists() && !registered(&b_path));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
