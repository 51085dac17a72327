//! Animation export with progress and cancel: a numbered PNG sequence (the files `hadou render
//! --frames` writes, byte for byte) or an animated GIF.
//!
//! ```no_run
//! use hadou::export::{export_animation, AnimationSpec, Control};
//! use hadou::{CpuBackend, Scene};
//! let scene = Scene::load("scenes/kamehameha.toml").expect("valid scene");
//! let spec = AnimationSpec { frames: 0..48, fps: 24.0, width: Some(320), height: Some(180), samples: None };
//! let outcome = export_animation(&scene, &mut CpuBackend::new(), &spec, "fire.gif".as_ref(), &mut |p| {
//!     eprintln!("{}/{}", p.done, p.total);
//!     Control::Continue
//! })
//! .expect("exported");
//! println!("{outcome:?}");
//! ```
//!
//! Frame `f` is rendered at scene time `f as f32 / fps` (in `f32`, as `hadou render --frames`
//! computes it), with the spec's width and height overriding the scene's `[image]` size.
//!
//! What is left on disk:
//! - **GIF**: the file is written to a temporary file beside the output (`.NAME.PID.N.tmp`, a
//!   [`hadou_scene::TempFile`]) and renamed into place after the last frame, so the output path
//!   holds either its old content or the complete new animation. On cancel, on any error and on
//!   an interrupt of the process ([`output::install_interrupt_cleanup`]) the temporary file is
//!   removed and the output path is untouched.
//! - **PNG sequence**: every frame is written whole (temporary file, then rename) by
//!   [`output::write_png_banded`], exactly as `hadou render --frames` writes it. A cancel is seen
//!   between frames: the frames finished before it stay on disk, no partial file is left. An error
//!   or an interrupt part-way also keeps the frames finished before it.
//!
//! Sizes: every frame has the spec's size (the overrides, else the scene's `[image]`; tracks cannot
//! change it), checked before the first frame against the scene's image limits
//! ([`Scene::check_image_size`]) and, for a GIF, [`GIF_MAX_PIXELS`].

use crate::farm::{FramePattern, FrameStamp, OnDisk, SceneStamp};
use crate::output::{self, OutputError};
use hadou_scene::{Backend, Frame, FrameOverrides, Image, RenderError, Scene};
use std::io::{BufWriter, Write};
use std::ops::Range;
use std::path::Path;

/// The largest image edge an export accepts (the scene's `[image]` and the CLI's
/// `--width`/`--height` limit).
pub const MAX_EDGE: u32 = hadou_scene::MAX_IMAGE_EDGE;

pub use hadou_scene::{check_gif_size, gif_delay_cs, GIF_MAX_PIXELS, GIF_QUANT_SPEED};

/// How an animation is written, chosen from the output path by [`AnimationFormat::from_path`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnimationFormat {
    /// Numbered 8-bit sRGB PNGs in a directory, named by [`frame_file_name`].
    PngSequence,
    /// One looping animated GIF (at most 256 colours per frame).
    Gif,
}

impl AnimationFormat {
    /// The format for `path`: a path ending in a separator (`out/`) or naming an existing directory
    /// is a PNG sequence into that directory; a `.gif` file name (case-insensitive) is a GIF.
    /// Anything else is [`OutputError::BadPath`].
    pub fn from_path(path: &Path) -> Result<Self, OutputError> {
        let text = path.as_os_str().to_string_lossy();
        if text.chars().last().is_some_and(std::path::is_separator) || path.is_dir() {
            return Ok(AnimationFormat::PngSequence);
        }
        match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
            Some("gif") => Ok(AnimationFormat::Gif),
            _ => Err(OutputError::BadPath(format!(
                "{}: unknown animation format; use a .gif file name or a directory (ending in `/`) for \
                 a numbered PNG sequence",
                path.display()
            ))),
        }
    }
}

/// What to render: which frames, at what rate, at what size.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimationSpec {
    /// Frame numbers (end excluded); frame `f` is at scene time `f as f32 / fps`.
    pub frames: Range<u32>,
    /// Frames per second: finite and > 0.
    pub fps: f32,
    /// Image width overriding the scene's (1..=[`MAX_EDGE`]); `None` keeps the scene's.
    pub width: Option<u32>,
    /// Image height overriding the scene's (1..=[`MAX_EDGE`]); `None` keeps the scene's.
    pub height: Option<u32>,
    /// Anti-aliasing samples per pixel overriding the scene's `[image] samples` (1, 4, 9 or
    /// 16); `None` keeps the scene's.
    pub samples: Option<u32>,
}

impl AnimationSpec {
    /// Checks the spec: a non-empty frame range, a finite `fps > 0` that gives every frame a finite
    /// time, and size overrides in 1..=[`MAX_EDGE`].
    pub fn validate(&self) -> Result<(), ExportError> {
        let Range { start, end } = self.frames;
        if end <= start {
            return Err(ExportError::Spec(format!("frames {start}..{end}: the range is empty")));
        }
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(ExportError::Spec(format!(
                "fps {}: must be a finite number of frames per second > 0, e.g. 24",
                self.fps
            )));
        }
        let last = end - 1;
        if !self.time_of(last).is_finite() {
            return Err(ExportError::Spec(format!(
                "fps {}: too small; frame {last} would be at {:.3e} s, beyond the largest time hadou can \
                 represent (3.4e38 s)",
                self.fps,
                f64::from(last) / f64::from(self.fps)
            )));
        }
        if let Some(s) = self.samples {
            hadou_scene::check_samples(s).map_err(ExportError::Spec)?;
        }
        for (name, v) in [("width", self.width), ("height", self.height)] {
            if let Some(v) = v {
                if v == 0 || v > MAX_EDGE {
                    return Err(ExportError::Spec(format!(
                        "{name} {v}: image size must be in 1..={MAX_EDGE}"
                    )));
                }
            }
        }
        Ok(())
    }

    /// The scene time of frame `f`: `f as f32 / fps`, as `hadou render --frames` computes it.
    pub fn time_of(&self, f: u32) -> f32 {
        f as f32 / self.fps
    }

    /// The size of every frame: the spec's overrides, else the scene's `[image]` size (no track can
    /// change it).
    pub fn size(&self, scene: &Scene) -> (u32, u32) {
        (self.width.unwrap_or(scene.width()), self.height.unwrap_or(scene.height()))
    }

    /// The scene at frame `f` with the spec's size and sample overrides applied.
    pub fn frame(&self, scene: &Scene, f: u32) -> Frame {
        let overrides = FrameOverrides { width: self.width, height: self.height, samples: self.samples };
        scene.at_with(self.time_of(f), &overrides)
    }
}

/// Where an export stands, passed to the progress callback.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Frames finished so far.
    pub done: u32,
    /// Frames in the export.
    pub total: u32,
}

/// The progress callback's answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// Go on with the next frame.
    Continue,
    /// Stop now; see [`ExportOutcome::Cancelled`] for what stays on disk. The answer to the call
    /// after the last frame is ignored: the export is complete and ends
    /// [`ExportOutcome::Finished`].
    Cancel,
}

/// How an export ended (errors aside).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExportOutcome {
    /// Every frame was written.
    Finished {
        /// Frames written.
        frames: u32,
    },
    /// The progress callback returned [`Control::Cancel`].
    Cancelled {
        /// Complete frame files left on disk: the PNG frames finished before the cancel; always 0
        /// for a GIF, whose temporary file is removed and whose output path is left untouched.
        frames_written: u32,
    },
}

/// Why an export failed.
#[derive(Debug)]
pub enum ExportError {
    /// The [`AnimationSpec`] is invalid (empty range, bad fps, bad size); a user error.
    Spec(String),
    /// The output path is unusable ([`OutputError::BadPath`], a user error) or writing failed
    /// ([`OutputError::Io`]).
    Output(OutputError),
    /// The backend failed, or produced a non-finite value.
    Render(RenderError),
}

impl std::fmt::Display for ExportError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ExportError::Spec(m) => f.write_str(m),
            ExportError::Output(e) => write!(f, "{e}"),
            ExportError::Render(e) => write!(f, "render failed: {e}"),
        }
    }
}

impl std::error::Error for ExportError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ExportError::Spec(_) => None,
            ExportError::Output(e) => Some(e),
            ExportError::Render(e) => Some(e),
        }
    }
}

impl From<OutputError> for ExportError {
    fn from(e: OutputError) -> Self {
        ExportError::Output(e)
    }
}

impl From<RenderError> for ExportError {
    fn from(e: RenderError) -> Self {
        ExportError::Render(e)
    }
}

/// The file name of frame `f` in a PNG sequence: `frame_00042.png` (at least five digits), the
/// name `hadou render --frames` gives it ([`FramePattern::default`]).
pub fn frame_file_name(f: u32) -> String {
    FramePattern::default().name(f)
}

/// Renders `spec`'s frames of `scene` with `backend` and writes them to `path` in the format
/// [`AnimationFormat::from_path`] picks, calling `progress` before the first frame (`done` = 0)
/// and after each finished frame; it returns [`Control::Cancel`] to stop. Cancel is seen between
/// frames. See the [module docs](self) for what stays on disk after a cancel or an error.
///
/// Everything about the path is checked before the first frame is rendered: the spec
/// ([`AnimationSpec::validate`], as [`ExportError::Spec`]), the frame size against the scene's
/// image limits ([`Scene::check_image_size`]) and a GIF's ([`check_gif_size`]), both as
/// [`ExportError::Spec`], the format, and that the directory
/// exists and accepts new files ([`OutputError::BadPath`]; a PNG sequence's directory must exist
/// already, as with `hadou render --frames`). Nothing is created on a failed check.
pub fn export_animation(
    scene: &Scene,
    backend: &mut dyn Backend,
    spec: &AnimationSpec,
    path: &Path,
    progress: &mut dyn FnMut(Progress) -> Control,
) -> Result<ExportOutcome, ExportError> {
    spec.validate()?;
    let (w, h) = spec.size(scene);
    scene.check_image_size(w, h).map_err(ExportError::Spec)?;
    if let Some(n) = spec.samples {
        scene.check_pixel_work(n).map_err(|(_, m)| ExportError::Spec(format!("samples {n}: {m}")))?;
    }
    // What the backend cannot draw (a GPU's bloom halo past its storage binding), refused
    // before anything is written for the first frame, and before each later frame is drawn (the
    // radius is animatable).
    check_frame(scene, backend, &spec.frame(scene, spec.frames.start), spec.frames.start)?;
    match AnimationFormat::from_path(path)? {
        AnimationFormat::PngSequence => export_png_sequence(
            scene,
            backend,
            spec,
            path,
            &SequenceOptions::default(),
            progress,
            &mut |_| {},
        )
        .map_err(|e| e.error),
        AnimationFormat::Gif => export_gif(scene, backend, spec, path, progress),
    }
}

/// How [`export_sequence`] names, stamps and resumes a PNG sequence's frames (docs/farm.md).
#[derive(Clone, Debug, Default)]
pub struct SequenceOptions {
    /// The frames' file names (`frame_#####.png` by default).
    pub pattern: FramePattern,
    /// The scene file and hadou version every frame's stamp names
    /// ([`crate::farm::FrameStamp`]); `None` writes unstamped frames (as [`export_animation`]
    /// does: its scene may be an edited one that no file holds).
    pub stamp: Option<SceneStamp>,
    /// Keep the frames already on disk that are complete and carry this job's stamp
    /// ([`crate::farm::check_frame_file`]); anything else at a frame's path is rendered again
    /// and replaced. Needs `stamp`.
    pub skip_existing: bool,
}

/// A sequence that failed, with the frame it failed at (`None`: before the first frame).
#[derive(Debug)]
pub struct SequenceError {
    /// The frame being checked, rendered or written when it failed.
    pub frame: Option<u32>,
    /// What failed.
    pub error: ExportError,
}

impl std::fmt::Display for SequenceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.frame {
            Some(n) => write!(f, "frame {n}: {}", self.error),
            None => write!(f, "{}", self.error),
        }
    }
}

impl std::error::Error for SequenceError {}

impl<E: Into<ExportError>> From<E> for SequenceError {
    fn from(e: E) -> Self {
        SequenceError { frame: None, error: e.into() }
    }
}

/// What [`export_sequence`] did with a frame already on disk, with `skip_existing`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SequenceNote {
    /// The frame was complete and this job's: kept, not rendered.
    Kept(u32),
    /// Something else was at the frame's path (the text says what); the frame is rendered and
    /// replaces it.
    Replacing(u32, String),
}

/// The stamp frame `f` of `spec` gets when drawn by `backend_name`.
pub fn frame_stamp(
    scene: &SceneStamp,
    spec: &AnimationSpec,
    frame: &Frame,
    f: u32,
    backend_name: &str,
) -> FrameStamp {
    FrameStamp {
        scene: scene.clone(),
        frame: Some(f),
        settings: crate::farm::frame_settings(frame, &format!("t={f}/{}", spec.fps), backend_name),
    }
}

/// A PNG sequence into the directory `dir`, as [`export_animation`] writes one, with the frames
/// named, stamped and resumed as `options` says; `notes` hears of every frame kept or replaced.
/// Errors name the frame they happened at. The checks before the first frame are
/// [`export_animation`]'s.
pub fn export_sequence(
    scene: &Scene,
    backend: &mut dyn Backend,
    spec: &AnimationSpec,
    dir: &Path,
    options: &SequenceOptions,
    progress: &mut dyn FnMut(Progress) -> Control,
    notes: &mut dyn FnMut(SequenceNote),
) -> Result<ExportOutcome, SequenceError> {
    spec.validate()?;
    let (w, h) = spec.size(scene);
    scene.check_image_size(w, h).map_err(ExportError::Spec)?;
    if let Some(n) = spec.samples {
        scene.check_pixel_work(n).map_err(|(_, m)| ExportError::Spec(format!("samples {n}: {m}")))?;
    }
    if options.skip_existing && options.stamp.is_none() {
        return Err(ExportError::Spec(
            "skip_existing needs the scene's stamp to recognise its frames".into(),
        )
        .into());
    }
    check_frame(scene, backend, &spec.frame(scene, spec.frames.start), spec.frames.start)?;
    if AnimationFormat::from_path(dir)? != AnimationFormat::PngSequence {
        return Err(OutputError::BadPath(format!(
            "{}: a PNG sequence is written into a directory (a path ending in `/`)",
            dir.display()
        ))
        .into());
    }
    export_png_sequence(scene, backend, spec, dir, options, progress, notes)
}

/// [`Backend::check_frame`] of frame `f`, its message located at the scene's `[bloom]`.
fn check_frame(scene: &Scene, backend: &dyn Backend, frame: &Frame, f: u32) -> Result<(), ExportError> {
    backend.check_frame(frame).map_err(|m| {
        let at = scene.bloom_location().map_or_else(|| scene.path().display().to_string(), |l| l.to_string());
        ExportError::Spec(format!("{at}: frame {f}: {m}"))
    })
}

/// The last line of defence of the invariant that no NaN or infinity reaches an image.
fn check_finite(image: &Image) -> Result<(), ExportError> {
    if output::is_finite(image) {
        Ok(())
    } else {
        Err(ExportError::Render(RenderError::Other(
            "internal error: the renderer produced a non-finite value; the frame was not written".into(),
        )))
    }
}

/// The PNG sequence: the checks and the loop of `hadou render --frames`, with progress and cancel.
fn export_png_sequence(
    scene: &Scene,
    backend: &mut dyn Backend,
    spec: &AnimationSpec,
    dir: &Path,
    options: &SequenceOptions,
    progress: &mut dyn FnMut(Progress) -> Control,
    notes: &mut dyn FnMut(SequenceNote),
) -> Result<ExportOutcome, SequenceError> {
    let range = spec.frames.clone();
    let pattern = &options.pattern;
    let frame_path = |f: u32| dir.join(pattern.name(f));
    if !dir.is_dir() {
        // A file in the way is named as such; a missing directory says so.
        if dir.ancestors().any(|a| a.is_file()) {
            output::check_directory(&frame_path(range.start))?;
        }
        let what = if dir.exists() { "is not a directory" } else { "does not exist" };
        return Err(OutputError::BadPath(format!(
            "{}: {what}; a PNG sequence is written into an existing directory, create it first",
            dir.display()
        ))
        .into());
    }
    // Every frame's path is checked before the first frame is rendered: the directory accepts new
    // files, and no entry a frame would replace is a directory. Read from the directory's listing,
    // not frame by frame, so a huge range costs nothing here.
    output::check_directory(&frame_path(range.start))?;
    drop(output::create_temp(&frame_path(range.start))?);
    let listing = std::fs::read_dir(dir).map_err(|e| {
        OutputError::BadPath(format!("{}: cannot list the output directory: {e}", dir.display()))
    })?;
    for entry in listing.flatten() {
        let name = entry.file_name();
        if name.to_str().and_then(|n| pattern.frame_of(n)).is_some_and(|f| range.contains(&f)) {
            output::check_directory(&entry.path())?;
        }
    }
    let total = range.len() as u32;
    let mut done = 0;
    if progress(Progress { done, total }) == Control::Cancel {
        return Ok(ExportOutcome::Cancelled { frames_written: 0 });
    }
    for f in range {
        let in_frame = |e: ExportError| SequenceError { frame: Some(f), error: e };
        let frame = spec.frame(scene, f);
        let stamp = options.stamp.as_ref().map(|s| frame_stamp(s, spec, &frame, f, backend.name()));
        let path = frame_path(f);
        let keep = match (&stamp, options.skip_existing) {
            (Some(stamp), true) => {
                match crate::farm::check_frame_file(&path, stamp, (frame.width, frame.height)) {
                    OnDisk::Complete => true,
                    OnDisk::Missing => false,
                    OnDisk::Replace(why) => {
                        notes(SequenceNote::Replacing(f, format!("{}: {why}", path.display())));
                        false
                    }
                }
            }
            _ => false,
        };
        if keep {
            notes(SequenceNote::Kept(f));
        } else {
            check_frame(scene, backend, &frame, f).map_err(in_frame)?;
            let text = stamp.map(|s| s.text_chunks()).unwrap_or_default();
            output::write_png_banded_with_text(
                &path,
                frame.width,
                frame.height,
                output::frame_band_rows(&frame),
                &text,
                |rows| Ok::<_, ExportError>(backend.render_rows_rgb8(&frame, rows)?),
            )
            .map_err(in_frame)?;
        }
        done += 1;
        if progress(Progress { done, total }) == Control::Cancel && done < total {
            return Ok(ExportOutcome::Cancelled { frames_written: done });
        }
    }
    Ok(ExportOutcome::Finished { frames: total })
}

/// Renders `frame` band by band (as the PNG path does) into packed 8-bit sRGB RGBA, alpha 255.
fn render_rgba(backend: &mut dyn Backend, frame: &Frame) -> Result<Vec<u8>, ExportError> {
    let (w, h) = (frame.width, frame.height);
    let mut rgba = Vec::with_capacity(w as usize * h as usize * 4);
    let step = output::frame_band_rows(frame);
    let mut y = 0;
    while y < h {
        let rows = y..(y + step).min(h);
        let band = backend.render_rows(frame, rows.clone())?;
        if band.width != w || band.height != rows.len() as u32 {
            return Err(ExportError::Render(RenderError::Other(format!(
                "internal error: a band of rows {}..{} came back {}×{}",
                rows.start, rows.end, band.width, band.height
            ))));
        }
        check_finite(&band)?;
        for rgb in output::srgb8(&band).chunks_exact(3) {
            rgba.extend_from_slice(&[rgb[0], rgb[1], rgb[2], 255]);
        }
        y = rows.end;
    }
    Ok(rgba)
}

/// The GIF: frames quantised one by one (NeuQuant, a palette per frame), looping forever, written
/// to a temporary file and renamed into place at the end.
fn export_gif(
    scene: &Scene,
    backend: &mut dyn Backend,
    spec: &AnimationSpec,
    path: &Path,
    progress: &mut dyn FnMut(Progress) -> Control,
) -> Result<ExportOutcome, ExportError> {
    output::check_directory(path)?;
    let first = spec.frame(scene, spec.frames.start);
    let (w, h) = (first.width, first.height);
    let mut first = Some(first);
    check_gif_size(w, h).map_err(|m| ExportError::Spec(format!("{}: {m}", path.display())))?;
    let (Ok(w16), Ok(h16)) = (u16::try_from(w), u16::try_from(h)) else {
        return Err(ExportError::Spec(format!(
            "{}: {w}×{h} is too large for a GIF (65535 at most)",
            path.display()
        )));
    };
    let (temp, file) = output::create_temp(path)?;
    let io =
        |e: String| ExportError::Output(OutputError::Io(format!("{}: write failed: {e}", path.display())));
    let mut encoder =
        gif::Encoder::new(BufWriter::new(file), w16, h16, &[]).map_err(|e| io(e.to_string()))?;
    encoder.set_repeat(gif::Repeat::Infinite).map_err(|e| io(e.to_string()))?;
    let total = spec.frames.len() as u32;
    let mut done = 0;
    if progress(Progress { done, total }) == Control::Cancel {
        return Ok(ExportOutcome::Cancelled { frames_written: 0 });
    }
    for (k, f) in spec.frames.clone().enumerate() {
        let frame = first.take().unwrap_or_else(|| spec.frame(scene, f));
        check_frame(scene, backend, &frame, f)?;
        if (frame.width, frame.height) != (w, h) {
            return Err(ExportError::Render(RenderError::Other(format!(
                "frame {f} is {}×{}, the GIF's first frame {w}×{h}; a GIF's frames share one size",
                frame.width, frame.height
            ))));
        }
        let mut rgba = render_rgba(backend, &frame)?;
        let mut gif_frame = gif::Frame::from_rgba_speed(w16, h16, &mut rgba, GIF_QUANT_SPEED);
        gif_frame.delay = gif_delay_cs(spec.fps, k as u32);
        encoder.write_frame(&gif_frame).map_err(|e| io(e.to_string()))?;
        done += 1;
        if progress(Progress { done, total }) == Control::Cancel && done < total {
            return Ok(ExportOutcome::Cancelled { frames_written: 0 });
        }
    }
    let mut writer = encoder.into_inner().map_err(|e| io(e.to_string()))?;
    writer.flush().map_err(|e| io(e.to_string()))?;
    drop(writer);
    temp.commit(path).map_err(|e| io(e.to_string()))?;
    Ok(ExportOutcome::Finished { frames: total })
}
