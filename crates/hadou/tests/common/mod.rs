//! Shared by the `hadou` crate's end-to-end tests: scratch directories that clean up after
//! themselves.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// Decodes an 8-bit PNG into its size and pixel bytes (RGB or RGBA, as the file holds them).
pub fn decode_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// A fresh empty directory for one test, removed when the test ends — unless it failed, so what
/// it wrote can be looked at. Some tests write files of a gigabyte and more (an 8192² EXR), which
/// would otherwise pile up in the temporary directory run after run.
pub struct Scratch(PathBuf);

impl Scratch {
    /// `<temp dir>/hadou-<suite>-<pid>-<name>`, emptied first.
    pub fn new(suite: &str, name: &str) -> Scratch {
        let d = std::env::temp_dir().join(format!("hadou-{suite}-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;

    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}
