//! Encoders: 8-bit sRGB PNG, float EXR, numbered sequences. Every write goes to a
//! [`hadou_scene::TempFile`] in the destination directory (registered for the interrupt handler's
//! clean-up before its first byte) and is renamed into place, so a failed or interrupted write
//! never leaves a half-written output. Both formats can be written band by band
//! ([`write_png_banded`], [`write_exr_banded`]): memory follows the band, not the image.

use hadou_math::shade::linear_to_srgb8;
use hadou_scene::{Image, Rgb8Image, TempFile};
use rayon::prelude::*;
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
    check_directory(path)?;
    drop(create_temp(path)?);
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

/// Writes a `width × height` image to `path` in the format its extension names, band by band
/// ([`write_png_banded`], [`write_exr_banded`]): memory follows the band, not the image.
/// `rows_per_band` is the band's height, [`frame_band_rows`] of the frame.
pub fn write_banded<E: From<OutputError>>(
    path: &Path,
    width: u32,
    height: u32,
    rows_per_band: u32,
    band: impl FnMut(std::ops::Range<u32>) -> Result<Image, E>,
) -> Result<(), E> {
    write_banded_with_text(path, width, height, rows_per_band, &[], band)
}

/// [`write_banded`] with `text` in the file's metadata: PNG `tEXt` chunks or EXR header text
/// attributes ([`write_png_banded_with_text`], [`write_exr_banded_with_text`]).
pub fn write_banded_with_text<E: From<OutputError>>(
    path: &Path,
    width: u32,
    height: u32,
    rows_per_band: u32,
    text: &[(String, String)],
    band: impl FnMut(std::ops::Range<u32>) -> Result<Image, E>,
) -> Result<(), E> {
    match Format::from_path(path)? {
        Format::Png => {
            let mut band = band;
            write_png_banded_with_text(path, width, height, rows_per_band, text, |rows| {
                let image = band(rows)?;
                Rgb8Image::from_image(&image).ok_or_else(|| {
                    E::from(OutputError::Io(format!(
                        "{}: internal error: the renderer produced a non-finite value; nothing was written",
                        path.display()
                    )))
                })
            })
        }
        Format::Exr => write_exr_banded_with_text(path, width, height, rows_per_band, text, band),
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

/// The PNG of 8-bit sRGB rows, in memory.
pub fn encode_png_rgb8(image: &Rgb8Image) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    encode_rgb8_into(image.width, image.height, &image.rgb, &mut out)?;
    Ok(out)
}

fn encode_png_into(image: &Image, sink: impl Write) -> Result<(), String> {
    encode_rgb8_into(image.width, image.height, &srgb8(image), sink)
}

fn encode_rgb8_into(width: u32, height: u32, rgb: &[u8], sink: impl Write) -> Result<(), String> {
    let mut enc = png::Encoder::new(sink, width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    // fdeflate's PNG-tuned compressor: several times faster than the default level.
    enc.set_compression(png::Compression::Fast);
    let mut w = enc.write_header().map_err(|e| e.to_string())?;
    w.write_image_data(rgb).map_err(|e| e.to_string())?;
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
/// `depth` ([`write_exr_banded`] over the image's rows).
pub fn write_exr(image: &Image, path: &Path) -> Result<(), OutputError> {
    write_exr_banded(path, image.width, image.height, 1, |rows| Ok::<_, OutputError>(image.crop_rows(rows)))
}

fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Deletes every temporary output file being written and returns how many it deleted. Called by
/// the interrupt handler; no temporary file can be created or renamed into place afterwards
/// ([`hadou_scene::remove_pending_temp_files`]).
pub fn remove_pending() -> usize {
    hadou_scene::remove_pending_temp_files()
}

/// Makes Ctrl-C, SIGTERM and SIGHUP remove partial outputs: the handler deletes every pending
/// temporary file (of any writer: images, animations, saved scenes), says how many on stderr and
/// exits with status 130. Outputs finished before the interrupt (earlier frames of a sequence)
/// stay.
pub fn install_interrupt_cleanup() -> Result<(), String> {
    ctrlc::set_handler(|| {
        let n = remove_pending();
        // Never `eprintln!`: on a closed stderr it panics, and this thread would then never
        // exit, leaving the process blocked on the temporary-file lock it keeps.
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "\ninterrupted: removed {n} partial output file(s)");
        std::process::exit(130);
    })
    .map_err(|e| format!("cannot install the interrupt handler: {e}"))
}

/// A new [`TempFile`] beside `path`, with the open file to write into; a failure to create it is
/// the path's fault ([`OutputError::BadPath`]).
pub(crate) fn create_temp(path: &Path) -> Result<(TempFile, File), OutputError> {
    TempFile::create(path).map_err(|e| {
        OutputError::BadPath(format!(
            "{}: cannot create files in `{}` ({e}); check its permissions or choose another output path",
            path.display(),
            parent_dir(path).display()
        ))
    })
}

/// Runs `write` on a temporary file beside `path`, then renames it into place; on any failure the
/// temporary file is removed and `path` is untouched.
fn atomic_write(path: &Path, write: impl FnOnce(File) -> Result<(), String>) -> Result<(), OutputError> {
    let (tmp, file) = create_temp(path)?;
    write(file)
        .and_then(|_| tmp.commit(path).map_err(|e| e.to_string()))
        .map_err(|e| OutputError::Io(format!("{}: write failed: {e}", path.display())))
}

/// Rows per band of [`write_png_banded`] for an image `width` pixels wide drawn at `samples` per
/// pixel (`SampleGrid::count`): about `BAND_PIXELS` samples (at least one row), so a band costs a few
/// hundred MB at most on any backend whatever the image size and anti-aliasing.
pub fn band_rows(width: u32, samples: u32) -> u32 {
    (u64::from(BAND_PIXELS) / (u64::from(width.max(1)) * u64::from(samples.max(1)))).max(1) as u32
}

/// Rows per band of a written `frame`: [`band_rows`] for its samples per pixel, or with a
/// `[bloom]` the most rows whose band fits beside the glare's whole-image planes
/// ([`hadou_scene::glare_band_rows`]: every band of such a frame draws the whole linear image
/// again, so its bands are as tall as memory allows; an image up to about 6 340² is one band).
pub fn frame_band_rows(frame: &hadou_scene::Frame) -> u32 {
    if frame.bloom.is_some() {
        hadou_scene::glare_band_rows(frame.width, frame.height)
    } else {
        band_rows(frame.width, frame.sample_grid().count())
    }
}

/// Pixels per band of a streamed PNG (4 Mi: about 100 MB of float image per band).
pub const BAND_PIXELS: u32 = 1 << 22;

/// The start of every banded write: `path`'s format and directory checked, and its temporary
/// file created (registered for interrupt clean-up) before the first band is asked for.
fn begin_banded(path: &Path) -> Result<(TempFile, File), OutputError> {
    Format::from_path(path)?;
    check_directory(path)?;
    create_temp(path)
}

/// An I/O failure while writing `path`.
fn write_failed(path: &Path, e: impl std::fmt::Display) -> OutputError {
    OutputError::Io(format!("{}: write failed: {e}", path.display()))
}

/// A band of rows as the writers receive it.
trait BandSize {
    fn size(&self) -> (u32, u32);
}

impl BandSize for Image {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
}

impl BandSize for Rgb8Image {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
}

/// The band of rows `rows` from `band`, refused unless it is `width × rows.len()`.
fn next_band<E: From<OutputError>, B: BandSize>(
    band: &mut impl FnMut(std::ops::Range<u32>) -> Result<B, E>,
    rows: std::ops::Range<u32>,
    width: u32,
    path: &Path,
) -> Result<B, E> {
    let image = band(rows.clone())?;
    let (w, h) = image.size();
    if w != width || h != rows.len() as u32 {
        let got = format!("a band of rows {}..{} came back {w}×{h}", rows.start, rows.end);
        return Err(write_failed(path, got).into());
    }
    Ok(image)
}

/// Writes a `width × height` 8-bit sRGB PNG to `path`, asking `band` for the image rows
/// `y0..y1` in turn as 8-bit sRGB ([`hadou_scene::Backend::render_rows_rgb8`]) (each at most `rows_per_band` rows: [`frame_band_rows`]) and streaming them into the encoder, so
/// memory follows the band, not the image. The file is created (and registered for interrupt
/// clean-up) before the first band is requested, and renamed into place after the last; on any
/// error nothing is left behind.
pub fn write_png_banded<E: From<OutputError>>(
    path: &Path,
    width: u32,
    height: u32,
    rows_per_band: u32,
    band: impl FnMut(std::ops::Range<u32>) -> Result<Rgb8Image, E>,
) -> Result<(), E> {
    write_png_banded_with_text(path, width, height, rows_per_band, &[], band)
}

/// [`write_png_banded`] with `text` written as `tEXt` chunks (keyword, Latin-1 text) before the
/// image data: the frame stamp of [`crate::farm::FrameStamp::text_chunks`].
pub fn write_png_banded_with_text<E: From<OutputError>>(
    path: &Path,
    width: u32,
    height: u32,
    rows_per_band: u32,
    text: &[(String, String)],
    mut band: impl FnMut(std::ops::Range<u32>) -> Result<Rgb8Image, E>,
) -> Result<(), E> {
    let (tmp, file) = begin_banded(path)?;
    let io = |e: String| write_failed(path, e);
    let mut enc = png::Encoder::new(BufWriter::new(file), width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    // fdeflate's PNG-tuned compressor: several times faster than the default level.
    enc.set_compression(png::Compression::Fast);
    for (keyword, value) in text {
        enc.add_text_chunk(keyword.clone(), value.clone()).map_err(|e| io(e.to_string()))?;
    }
    let mut w = enc.write_header().map_err(|e| io(e.to_string()))?;
    {
        let mut stream = w.stream_writer().map_err(|e| io(e.to_string()))?;
        let step = rows_per_band.max(1);
        let mut y = 0;
        while y < height {
            let rows = y..(y + step).min(height);
            let image = next_band(&mut band, rows.clone(), width, path)?;
            stream.write_all(&image.rgb).map_err(|e| io(e.to_string()))?;
            y = rows.end;
        }
        stream.finish().map_err(|e| io(e.to_string()))?;
    }
    w.finish().map_err(|e| io(e.to_string()))?;
    tmp.commit(path).map_err(|e| io(e.to_string()))?;
    Ok(())
}

/// Reads one EXR channel's value of pixel `i` from an image.
type ExrSample = fn(&Image, usize) -> f32;

/// The EXR's channels in the order the file stores them (sorted by name, as OpenEXR requires),
/// each with the pixel value it holds.
const EXR_CHANNELS: [(&str, ExrSample); 6] = [
    ("A", |im, i| im.color[i][3]),
    ("B", |im, i| im.color[i][2]),
    ("G", |im, i| im.color[i][1]),
    ("R", |im, i| im.color[i][0]),
    ("depth", |im, i| im.depth[i]),
    ("energy", |im, i| im.energy[i]),
];

/// Writes a `width × height` float EXR (channels `R, G, B, A`: linear colour after mapping,
/// `energy` and `depth`; RLE-compressed scan lines, layer `hadou`) to `path`, asking `band` for
/// the image rows `y0..y1` in turn (each at most `rows_per_band` rows: [`frame_band_rows`]) and writing each band's
/// lines before asking for the next, so memory follows the band, not the image. The file is
/// created (and registered for interrupt clean-up) before the first band is requested, and
/// renamed into place after the last; on any error nothing is left behind.
pub fn write_exr_banded<E: From<OutputError>>(
    path: &Path,
    width: u32,
    height: u32,
    rows_per_band: u32,
    band: impl FnMut(std::ops::Range<u32>) -> Result<Image, E>,
) -> Result<(), E> {
    write_exr_banded_with_text(path, width, height, rows_per_band, &[], band)
}

/// The EXR header's text attribute that holds [`write_exr_banded_with_text`]'s pairs, one
/// `KEY=VALUE` a line.
pub const EXR_TEXT_ATTRIBUTE: &str = "hadou";

/// [`write_exr_banded`] with `text` written into the layer's header: one text attribute,
/// [`EXR_TEXT_ATTRIBUTE`], of `KEY=VALUE` lines (the frame stamp of
/// [`crate::farm::FrameStamp::text_chunks`]).
pub fn write_exr_banded_with_text<E: From<OutputError>>(
    path: &Path,
    width: u32,
    height: u32,
    rows_per_band: u32,
    text: &[(String, String)],
    mut band: impl FnMut(std::ops::Range<u32>) -> Result<Image, E>,
) -> Result<(), E> {
    use exr::block::writer::ChunksWriter;
    use exr::block::{BlockIndex, UncompressedBlock};
    use exr::meta::attribute::{ChannelDescription, SampleType};
    use exr::meta::header::Header;
    use exr::meta::BlockDescription;
    use exr::prelude::*;
    let (tmp, file) = begin_banded(path)?;
    let io = |e: String| write_failed(path, e);
    let channels = EXR_CHANNELS.iter().map(|&(n, _)| ChannelDescription::named(n, SampleType::F32)).collect();
    let mut header = Header::new("hadou".into(), (width as usize, height as usize), channels).with_encoding(
        Compression::RLE,
        BlockDescription::ScanLines,
        LineOrder::Increasing,
    );
    // One attribute holding every pair: the header's attributes are a hash map, written in an
    // order that changes from run to run, and the same frame must be the same bytes.
    if !text.is_empty() {
        let joined: Vec<String> = text.iter().map(|(k, v)| format!("{k}={v}")).collect();
        header.own_attributes.other.insert(
            exr::meta::attribute::Text::from(EXR_TEXT_ATTRIBUTE),
            exr::meta::attribute::AttributeValue::Text(exr::meta::attribute::Text::from(
                joined.join("\n").as_str(),
            )),
        );
    }
    // RLE compresses one scan line per block, so block `y` is line `y`.
    debug_assert_eq!(header.compression.scan_lines_per_block(), 1);
    // An error of `band` (or a band of the wrong size) stops the writer; it is kept here.
    let mut failure: Option<E> = None;
    let written =
        exr::block::write(BufWriter::new(file), SmallVec::from_vec(vec![header]), true, |meta, chunks| {
            let step = rows_per_band.max(1);
            let mut y = 0;
            while y < height {
                let rows = y..(y + step).min(height);
                let image = match next_band(&mut band, rows.clone(), width, path) {
                    Ok(image) => image,
                    Err(e) => {
                        failure = Some(e);
                        return Err(exr::error::Error::Aborted);
                    }
                };
                let w = width as usize;
                let compressed: Vec<_> = (0..rows.len())
                    .into_par_iter()
                    .map(|r| {
                        let line = r * w..(r + 1) * w;
                        let mut data = Vec::with_capacity(w * 4 * EXR_CHANNELS.len());
                        for (_, sample) in EXR_CHANNELS {
                            for i in line.clone() {
                                data.extend_from_slice(&sample(&image, i).to_ne_bytes());
                            }
                        }
                        let index = BlockIndex {
                            layer: 0,
                            pixel_position: Vec2(0, rows.start as usize + r),
                            pixel_size: Vec2(w, 1),
                            level: Vec2(0, 0),
                        };
                        UncompressedBlock { index, data }.compress_to_chunk(&meta.headers)
                    })
                    .collect();
                for (r, chunk) in compressed.into_iter().enumerate() {
                    chunks.write_chunk(rows.start as usize + r, chunk?)?;
                }
                y = rows.end;
            }
            Ok(())
        });
    if let Some(e) = failure {
        return Err(e);
    }
    written.map_err(|e| io(e.to_string()))?;
    tmp.commit(path).map_err(|e| io(e.to_string()))?;
    Ok(())
}
