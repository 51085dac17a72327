//! Encoders: 8-bit sRGB PNG, float EXR, numbered sequences. Every write goes to a temporary file
//! in the destination directory and is renamed into place, so a failed or interrupted write never
//! leaves a half-written output.

use hadou_math::shade::linear_to_srgb8;
use hadou_scene::Image;
use rayon::prelude::*;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

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
    check_directory(path)?;
    let probe = TempFile::create(path)?;
    drop(probe);
    Ok(format)
}

/// The checks of [`check_writable`] that create nothing: the directory exists (naming the real
/// cause when a part of the path is a file), and `path` is not a directory.
pub fn check_directory(path: &Path) -> Result<(), OutputError> {
    let dir = parent_dir(path);
    if !dir.is_dir() {
        // The nearest part of the path that exists says why: a file in the way, or nothing there.
        let blocking = dir.ancestors().find(|a| !a.as_os_str().is_empty() && a.exists());
        return Err(OutputError::BadPath(match blocking {
            Some(f) if !f.is_dir() => format!(
                "{}: `{}` is a file, not a directory; choose another output path",
                path.display(),
                f.display()
            ),
            _ => format!(
                "{}: directory `{}` does not exist; create it first or choose another output path",
                path.display(),
                dir.display()
            ),
        }));
    }
    if path.is_dir() {
        return Err(OutputError::BadPath(format!("{}: is a directory; give a file name", path.display())));
    }
    Ok(())
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
    atomic_write(path, |file| encode_png_into(image, BufWriter::new(file)))
}

/// The 8-bit sRGB PNG of `image` (what [`write_png`] writes), in memory.
pub fn encode_png(image: &Image) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    encode_png_into(image, &mut out)?;
    Ok(out)
}

fn encode_png_into(image: &Image, sink: impl Write) -> Result<(), String> {
    let mut enc = png::Encoder::new(sink, image.width, image.height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    // fdeflate's PNG-tuned compressor: several times faster than the default level.
    enc.set_compression(png::Compression::Fast);
    let mut w = enc.write_header().map_err(|e| e.to_string())?;
    w.write_image_data(&srgb8(image)).map_err(|e| e.to_string())?;
    w.finish().map_err(|e| e.to_string())
}

/// Whether every colour, energy and depth value of `image` is finite (the invariant that no NaN
/// or infinity reaches an image, checked before writing).
pub fn is_finite(image: &Image) -> bool {
    image.color.iter().all(|c| c.iter().all(|v| v.is_finite()))
        && image.energy.iter().all(|v| v.is_finite())
        && image.depth.iter().all(|v| v.is_finite())
}

/// The image's colour as packed 8-bit sRGB triples ([`linear_to_srgb8`]), rows in parallel.
pub fn srgb8(image: &Image) -> Vec<u8> {
    let mut data = vec![0u8; image.color.len() * 3];
    data.par_chunks_mut(3 * 4096).zip(image.color.par_chunks(4096)).for_each(|(out, colors)| {
        for (o, c) in out.chunks_exact_mut(3).zip(colors) {
            o[0] = linear_to_srgb8(c[0]);
            o[1] = linear_to_srgb8(c[1]);
            o[2] = linear_to_srgb8(c[2]);
        }
    });
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

/// Temporary files that exist right now; [`remove_pending`] deletes them when the process is
/// interrupted. An entry is added when a [`TempFile`] is created and removed, under the same lock,
/// when it is renamed into place or deleted, so an interrupt sees either the temporary file or
/// the finished output, never a half-renamed state.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn pending() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    PENDING.lock().unwrap_or_else(|p| p.into_inner())
}

/// Deletes every temporary output file being written and returns how many there were. Called by
/// the interrupt handler; it keeps the lock, so no rename can start afterwards.
pub fn remove_pending() -> usize {
    let mut files = pending();
    for f in files.iter() {
        let _ = std::fs::remove_file(f);
    }
    let n = files.len();
    files.clear();
    std::mem::forget(files); // keep the lock held until the process exits
    n
}

/// Makes Ctrl-C, SIGTERM and SIGHUP remove partial outputs: the handler deletes every pending
/// temporary file, says so on stderr and exits with status 130.
pub fn install_interrupt_cleanup() -> Result<(), String> {
    ctrlc::set_handler(|| {
        let n = remove_pending();
        eprintln!("\ninterrupted: removed {n} partial output file(s); nothing was written");
        std::process::exit(130);
    })
    .map_err(|e| format!("cannot install the interrupt handler: {e}"))
}

/// A temporary file beside an output path, registered in [`PENDING`]; removed on drop unless
/// [`TempFile::commit`] renamed it into place.
struct TempFile {
    tmp: PathBuf,
    file: Option<File>,
}

impl TempFile {
    fn create(path: &Path) -> Result<TempFile, OutputError> {
        let tmp = temp_path(path);
        let mut list = pending();
        let file = File::create(&tmp).map_err(|e| {
            OutputError::BadPath(format!(
                "{}: cannot create files in `{}` ({e}); check its permissions or choose another output path",
                path.display(),
                parent_dir(path).display()
            ))
        })?;
        list.push(tmp.clone());
        Ok(TempFile { tmp, file: Some(file) })
    }

    /// Renames the finished file to `path`.
    fn commit(mut self, path: &Path) -> Result<(), String> {
        drop(self.file.take());
        let mut list = pending();
        std::fs::rename(&self.tmp, path).map_err(|e| e.to_string())?;
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
        drop(self.file.take());
        let mut list = pending();
        let _ = std::fs::remove_file(&self.tmp);
        list.retain(|p| p != &self.tmp);
    }
}

/// Runs `write` on a temporary file beside `path`, then renames it into place; on any failure the
/// temporary file is removed and `path` is untouched.
fn atomic_write(path: &Path, write: impl FnOnce(File) -> Result<(), String>) -> Result<(), OutputError> {
    let mut tmp = TempFile::create(path)?;
    let file = tmp.file.take().expect("a new temp file is open");
    write(file)
        .and_then(|_| tmp.commit(path))
        .map_err(|e| OutputError::Io(format!("{}: write failed: {e}", path.display())))
}

/// Rows per band of [`write_png_banded`]: about `BAND_PIXELS` pixels (at least one row), so a band
/// costs a few hundred MB at most on any backend whatever the image size.
pub fn band_rows(width: u32) -> u32 {
    (BAND_PIXELS / width.max(1)).max(1)
}

/// Pixels per band of a streamed PNG (4 Mi: about 100 MB of float image per band).
pub const BAND_PIXELS: u32 = 1 << 22;

/// Writes a `width × height` 8-bit sRGB PNG to `path`, asking `band` for the image rows
/// `y0..y1` in turn (each at most [`band_rows`] rows) and streaming them into the encoder, so
/// memory follows the band, not the image. The file is created (and registered for interrupt
/// clean-up) before the first band is requested, and renamed into place after the last; on any
/// error nothing is left behind.
pub fn write_png_banded<E: From<OutputError>>(
    path: &Path,
    width: u32,
    height: u32,
    mut band: impl FnMut(std::ops::Range<u32>) -> Result<Image, E>,
) -> Result<(), E> {
    Format::from_path(path)?;
    check_directory(path)?;
    let mut tmp = TempFile::create(path)?;
    let io = |e: String| OutputError::Io(format!("{}: write failed: {e}", path.display()));
    let file = tmp.file.take().expect("a new temp file is open");
    let mut enc = png::Encoder::new(BufWriter::new(file), width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    // fdeflate's PNG-tuned compressor: several times faster than the default level.
    enc.set_compression(png::Compression::Fast);
    let mut w = enc.write_header().map_err(|e| io(e.to_string()))?;
    {
        let mut stream = w.stream_writer().map_err(|e| io(e.to_string()))?;
        let step = band_rows(width);
        let mut y = 0;
        while y < height {
            let rows = y..(y + step).min(height);
            let image = band(rows.clone())?;
            if image.width != width || image.height != rows.len() as u32 {
                return Err(io(format!(
                    "a band of rows {}..{} came back {}×{}",
                    rows.start, rows.end, image.width, image.height
                ))
                .into());
            }
            stream.write_all(&srgb8(&image)).map_err(|e| io(e.to_string()))?;
            y = rows.end;
        }
        stream.finish().map_err(|e| io(e.to_string()))?;
    }
    w.finish().map_err(|e| io(e.to_string()))?;
    tmp.commit(path).map_err(io)?;
    Ok(())
}
