//! Encoders: 8-bit sRGB PNG, float EXR, numbered sequences. Every write goes to a temporary file
//! in the destination directory and is renamed into place, so a failed or interrupted write never
//! leaves a half-written output.

use hadou_math::shade::linear_to_srgb;
use hadou_scene::Image;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Why an output could not be written.
#[derive(Debug)]
pub enum OutputError {
    /// The path is unusable (missing directory, unknown extension, no permission); a user error.
    BadPath(String),
    /// Encoding or I/O failed while writing.
    Io(String),
}

impl std::fmt::Display for OutputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OutputError::BadPath(m) | OutputError::Io(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for OutputError {}

/// Output formats, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// 8-bit sRGB PNG.
    Png,
    /// 32-bit float OpenEXR with linear R, G, B, A, `energy` and `depth` channels.
    Exr,
}

impl Format {
    /// The format for `path`'s extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Format, OutputError> {
        match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
            Some("png") => Ok(Format::Png),
            Some("exr") => Ok(Format::Exr),
            _ => Err(OutputError::BadPath(format!(
                "{}: unknown output format; use a .png (8-bit sRGB) or .exr (float) file name",
                path.display()
            ))),
        }
    }
}

/// Checks, before any rendering, that `path` can be written: its directory exists, is a
/// directory, and accepts a new file. Returns the format.
pub fn check_writable(path: &Path) -> Result<Format, OutputError> {
    let format = Format::from_path(path)?;
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(OutputError::BadPath(format!(
            "{}: directory `{}` does not exist; create it first or choose another output path",
            path.display(),
            dir.display()
        )));
    }
    if path.is_dir() {
        return Err(OutputError::BadPath(format!("{}: is a directory; give a file name", path.display())));
    }
    let probe = temp_path(path);
    match File::create(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(format)
        }
        Err(e) => Err(OutputError::BadPath(format!(
            "{}: cannot create files in `{}` ({e}); check its permissions or choose another output path",
            path.display(),
            dir.display()
        ))),
    }
}

/// Writes `image` to `path` in the format its extension names.
pub fn write(image: &Image, path: &Path) -> Result<(), OutputError> {
    match Format::from_path(path)? {
        Format::Png => write_png(image, path),
        Format::Exr => write_exr(image, path),
    }
}

/// Writes an 8-bit sRGB PNG (colour only).
pub fn write_png(image: &Image, path: &Path) -> Result<(), OutputError> {
    atomic_write(path, |file| {
        let mut enc = png::Encoder::new(BufWriter::new(file), image.width, image.height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        let mut w = enc.write_header().map_err(|e| e.to_string())?;
        w.write_image_data(&srgb8(image)).map_err(|e| e.to_string())?;
        w.finish().map_err(|e| e.to_string())
    })
}

/// The image's colour as packed 8-bit sRGB triples.
pub fn srgb8(image: &Image) -> Vec<u8> {
    let mut data = Vec::with_capacity(image.color.len() * 3);
    for c in &image.color {
        for &v in &c[..3] {
            data.push((linear_to_srgb(v) * 255.0 + 0.5) as u8);
        }
    }
    data
}

/// Writes a float EXR with channels `R, G, B, A` (linear colour after mapping), `energy` and
/// `depth`.
pub fn write_exr(image: &Image, path: &Path) -> Result<(), OutputError> {
    use exr::prelude::*;
    let ch = |name: &str, v: Vec<f32>| AnyChannel::new(name, FlatSamples::F32(v));
    let comp = |k: usize| image.color.iter().map(|c| c[k]).collect::<Vec<f32>>();
    let channels = AnyChannels::sort(SmallVec::from_vec(vec![
        ch("R", comp(0)),
        ch("G", comp(1)),
        ch("B", comp(2)),
        ch("A", comp(3)),
        ch("energy", image.energy.clone()),
        ch("depth", image.depth.clone()),
    ]));
    let size = (image.width as usize, image.height as usize);
    let layer = Layer::new(size, LayerAttributes::named("hadou"), Encoding::FAST_LOSSLESS, channels);
    let img = exr::image::Image::from_layer(layer);
    atomic_write(path, |file| {
        let mut w = BufWriter::new(file);
        img.write().to_buffered(&mut w).map_err(|e| e.to_string())?;
        w.flush().map_err(|e| e.to_string())
    })
}

fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    parent_dir(path).join(format!(".{name}.{}.tmp", std::process::id()))
}

/// Runs `write` on a temporary file beside `path`, then renames it into place; on any failure the
/// temporary file is removed and `path` is untouched.
fn atomic_write(path: &Path, write: impl FnOnce(File) -> Result<(), String>) -> Result<(), OutputError> {
    let tmp = temp_path(path);
    let file = File::create(&tmp).map_err(|e| {
        OutputError::BadPath(format!(
            "{}: cannot create `{}` ({e}); check that the directory exists and is writable",
            path.display(),
            tmp.display()
        ))
    })?;
    let result = write(file).and_then(|_| std::fs::rename(&tmp, path).map_err(|e| e.to_string()));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(OutputError::Io(format!("{}: write failed: {e}", path.display())));
    }
    Ok(())
}
