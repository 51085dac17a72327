//! The `hadou` command-line tool: render, validate, probe, bench, view. `hadou view` opens its
//! window only when built with the `view` feature (on by default); without it the subcommand is
//! still listed and exits 2 saying how to get it.

use clap::{Args, Parser, Subcommand, ValueEnum};
use hadou::output;
use hadou::{Backend, CpuBackend, Frame, GpuBackend, Image, RenderError, Scene};
use std::path::PathBuf;
use std::process::ExitCode;

/// Real-time anime energy waves from formulas.
#[derive(Parser, Debug)]
#[command(name = "hadou", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene to a PNG/EXR image, or with --frames a numbered PNG sequence or a GIF.
    Render(RenderArgs),
    /// Check a scene file; exit 0 if valid (listing the animation clips and VRM expressions of its
    /// glTF objects), 2 with `file:line:col: message` if not. With --frames DIR, check a rendered
    /// sequence too: every frame complete, of this scene (or, without SCENE, of one scene), of this
    /// hadou version and of one set of settings, none missing.
    Validate(ValidateArgs),
    /// Print, as JSON, each wave's energy, the final colour and the depth at one pixel.
    Probe(ProbeArgs),
    /// Measure rendering speed in the layout of the thesis's tables.
    Bench(BenchArgs),
    /// Open a window: tune every parameter live, play the animation, save, export.
    View(ViewArgs),
}

#[derive(Args, Debug)]
#[cfg_attr(not(feature = "view"), allow(dead_code))]
struct ViewArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Drive the viewer from a script file (one command per line; see docs/viewer.md), then exit.
    #[arg(long)]
    script: Option<PathBuf>,
    /// Write the viewport (the scene's image, as `hadou render` writes it) to this PNG/EXR file
    /// once drawn (after the script, if any), and exit.
    #[arg(long)]
    screenshot: Option<PathBuf>,
    /// Start at this scene time in seconds (≥ 0).
    #[arg(long, allow_hyphen_values = true)]
    time: Option<String>,
    /// Which backend draws the viewport [default: auto: the GPU backend on a hardware GPU, the CPU
    /// backend when the only adapter is a software rasterizer].
    #[arg(long, value_enum)]
    backend: Option<ViewBackend>,
    /// Print the median frame, render and viewer-overhead times as JSON on exit.
    #[arg(long)]
    stats: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ViewBackend {
    /// The CPU reference backend (its image uploaded as a texture).
    Cpu,
    /// The GPU backend, drawing straight into the window.
    Gpu,
}

#[derive(Args, Debug)]
struct RenderArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Output file (.png or .exr), or with --frames a directory (ending in `/`) for a PNG
    /// sequence or a `.gif` file for an animated GIF.
    #[arg(short, long)]
    output: PathBuf,
    /// Scene time in seconds (≥ 0).
    #[arg(long, default_value = "0", allow_hyphen_values = true)]
    time: String,
    /// Frame range `A..B` (B excluded) or `A..=B`, rendered at times `frame / fps`.
    #[arg(long, allow_hyphen_values = true)]
    frames: Option<String>,
    /// Frames per second for --frames.
    #[arg(long, default_value = "24", allow_hyphen_values = true)]
    fps: String,
    /// Override the image width (the scene's `[image]` limits hold: 1..=16384, and at most 4096²
    /// pixels with an `[area_light]`).
    #[arg(long, allow_hyphen_values = true)]
    width: Option<u32>,
    /// Override the image height (the same limits).
    #[arg(long, allow_hyphen_values = true)]
    height: Option<u32>,
    /// Override the anti-aliasing samples per pixel (`[image] samples`, default 4): 1, 4, 9 or
    /// 16.
    #[arg(long, allow_hyphen_values = true)]
    samples: Option<u32>,
    /// Which backend renders.
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    backend: BackendChoice,
    /// How --frames reports progress: a bar on stderr, `openjd_progress: PERCENT` lines on stdout
    /// (Open Job Description), or nothing.
    #[arg(long, value_enum, default_value_t = ProgressChoice::Bar)]
    progress: ProgressChoice,
    /// With --frames into a directory: keep the frames already there that are complete and
    /// stamped with this scene file, hadou version and settings; render the rest, replacing
    /// anything else at their paths (docs/farm.md).
    #[arg(long)]
    skip_existing: bool,
    /// With --frames into a directory: the frames' file names, one run of `#` for the frame
    /// number (zero-padded to at least that many digits).
    #[arg(long, default_value = "frame_#####.png")]
    frame_name: String,
}

#[derive(Args, Debug)]
struct ValidateArgs {
    /// The scene file (TOML).
    #[arg(required_unless_present = "frames")]
    scene: Option<PathBuf>,
    /// A directory of frames written by `hadou render --frames` to check (docs/farm.md).
    #[arg(long)]
    frames: Option<PathBuf>,
    /// The frames' file names, as given to `hadou render --frame-name`.
    #[arg(long, default_value = "frame_#####.png")]
    frame_name: String,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ProgressChoice {
    /// A progress bar on stderr.
    Bar,
    /// `openjd_progress: PERCENT` lines on stdout, as Open Job Description reads them.
    Openjd,
    /// Nothing until the summary line.
    None,
}

#[derive(Args, Debug)]
struct ProbeArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// The pixel `X,Y` (0,0 is the top-left).
    #[arg(long, allow_hyphen_values = true)]
    pixel: String,
    /// Scene time in seconds (≥ 0).
    #[arg(long, default_value = "0", allow_hyphen_values = true)]
    time: String,
    /// Override the image width (the scene's `[image]` limits hold: 1..=16384, and at most 4096²
    /// pixels with an `[area_light]`).
    #[arg(long, allow_hyphen_values = true)]
    width: Option<u32>,
    /// Override the image height (the same limits).
    #[arg(long, allow_hyphen_values = true)]
    height: Option<u32>,
    /// Which backend evaluates the pixel (the CPU also counts integrand evaluations).
    #[arg(long, value_enum, default_value_t = BackendChoice::Cpu)]
    backend: BackendChoice,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum BenchTable {
    /// Sphere, capsule, sphere+capsule and bulged beam, with and without occlusion.
    Analytic,
    /// Helix, trig sum, Bézier and B-spline: faithful Simpson against the default integrator.
    Curves,
    /// The toon scene (character, props, ground, wave light, outlines, textures), full and plain.
    Toon,
    /// Soft shadows (003): faithful N = 1, 3, 5, 10, exact and PCSS against a true disc light.
    Shadows,
}

#[derive(Args, Debug)]
struct BenchArgs {
    /// Which table to measure.
    #[arg(value_enum, default_value_t = BenchTable::Analytic)]
    table: BenchTable,
    /// Directory holding the example scenes (for the curve and toon tables).
    #[arg(long, default_value = "scenes")]
    scenes: PathBuf,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Image sizes (square), comma-separated [default: 512,1024,2048 for analytic, 512 for curves,
    /// 256,512,1024 for toon].
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    sizes: Vec<u32>,
    /// Timed repetitions per cell (after one warm-up) [default: 5 for analytic and toon, 1 for
    /// curves].
    #[arg(long, allow_hyphen_values = true)]
    iterations: Option<u32>,
    /// Which backend to measure.
    #[arg(long, value_enum, default_value_t = BackendChoice::Cpu)]
    backend: BackendChoice,
    /// shadows only: the ground truth's (and PCSS's) disc radius in scene units [default: the
    /// radius whose penumbra matches the two maps' band, docs/soft-shadows.md].
    #[arg(long, allow_hyphen_values = true)]
    disc_radius: Option<f32>,
    /// shadows only: the scene file (in --scenes) to measure, at t = 0 [default:
    /// soft-gradient.toml]. Its [area_light] gives the traced rows' sample count.
    #[arg(long)]
    scene: Option<String>,
    /// shadows only: measure only the traced rows, their references and the whole frames (not
    /// the two-map resolves, PCSS and their disc truth).
    #[arg(long)]
    traced_only: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum BackendChoice {
    /// A hardware GPU if there is one, otherwise the CPU reference (faster than a software GPU).
    Auto,
    /// The CPU reference backend.
    Cpu,
    /// The wgpu backend (any adapter, including software Vulkan).
    Gpu,
}

/// A failure with the exit code it maps to: 2 for bad input, 1 for everything else.
struct Failure {
    code: u8,
    message: String,
}

impl Failure {
    fn input(message: impl Into<String>) -> Self {
        Failure { code: 2, message: message.into() }
    }
    fn runtime(message: impl Into<String>) -> Self {
        Failure { code: 1, message: message.into() }
    }
}

impl From<hadou::SceneError> for Failure {
    fn from(e: hadou::SceneError) -> Self {
        Failure::input(e.to_string())
    }
}

impl From<output::OutputError> for Failure {
    fn from(e: output::OutputError) -> Self {
        match e {
            output::OutputError::BadPath(m) => Failure::input(m),
            output::OutputError::Io(m) => Failure::runtime(m),
        }
    }
}

impl From<RenderError> for Failure {
    fn from(e: RenderError) -> Self {
        // Memory the machine lacks for a frame within the limits is a size to lower: exit 2, as
        // a size over the limits is.
        if let RenderError::Memory(_) = e {
            return Failure::input(format!("render failed: {e}; nothing was written (a smaller --width/--height or fewer --samples fits)"));
        }
        Failure::runtime(format!("render failed: {e}"))
    }
}

fn main() -> ExitCode {
    // Mesa's Vulkan device-selection layer connects to a Wayland/X11 display to rank GPUs and
    // prints "XDG_RUNTIME_DIR is invalid" on headless machines; hadou renders off-screen and ranks
    // adapters itself, so the layer is switched off (unless the user set the variable). Set before
    // any thread starts.
    if std::env::var_os("NODEVICE_SELECT").is_none() {
        std::env::set_var("NODEVICE_SELECT", "1");
    }
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return flag_error(e),
    };
    // A vector path the CPU lacks is refused here, before anything renders (the library would
    // fall back to the widest path with a warning; it never runs instructions the CPU lacks).
    if let Err(e) = hadou_math::simd::SimdPath::from_env() {
        eprintln!("error: {}: {e}", hadou_math::simd::SIMD_ENV);
        return ExitCode::from(2);
    }
    let result = match cli.command {
        Command::Render(a) => render(a),
        Command::Validate(a) => validate(a),
        Command::Probe(a) => probe(a),
        Command::Bench(a) => bench(a),
        Command::View(a) => view(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            // One line whatever a message quotes (a path, a file's text): control characters
            // escaped here, for every error.
            eprintln!("error: {}", hadou_scene::escape_controls(&f.message));
            ExitCode::from(f.code)
        }
    }
}

/// `render --frames A..B -o DIR/ | OUT.gif`: a PNG sequence or an animated GIF through
/// `hadou::export` (every path checked before the first frame), with a progress bar.
fn render_animation(a: &RenderArgs, range: std::ops::Range<u32>, fps: f32) -> Result<(), Failure> {
    use hadou::export::{export_animation, AnimationSpec, Control, ExportError, ExportOutcome};
    let sequence =
        hadou::export::AnimationFormat::from_path(&a.output)? == hadou::export::AnimationFormat::PngSequence;
    let pattern = hadou::farm::FramePattern::parse(&a.frame_name).map_err(Failure::input)?;
    if !sequence && (a.skip_existing || pattern != hadou::farm::FramePattern::default()) {
        let flag = if a.skip_existing { "--skip-existing" } else { "--frame-name" };
        return Err(Failure::input(format!(
            "{flag}: applies to a PNG sequence (-o DIR/ with --frames), not to {}",
            a.output.display()
        )));
    }
    let spec =
        AnimationSpec { frames: range.clone(), fps, width: a.width, height: a.height, samples: a.samples };
    spec.validate().map_err(|e| Failure::input(e.to_string()))?;
    if hadou::export::AnimationFormat::from_path(&a.output)? == hadou::export::AnimationFormat::Gif {
        output::check_directory(&a.output)?;
    }
    let (scene, stamp) = load_scene_stamped(&a.scene)?;
    let (w, h) = check_image_size(&scene, &a.scene, a.width, a.height)?;
    check_samples_work(&scene, a.samples)?;
    if hadou::export::AnimationFormat::from_path(&a.output)? == hadou::export::AnimationFormat::Gif {
        hadou::export::check_gif_size(w, h).map_err(|m| {
            Failure::input(format!("{}: {m}", size_origin(&scene, &a.scene, a.width, a.height)))
        })?;
    }
    let mut backend = make_backend(a.backend)?;
    let bar = match a.progress {
        ProgressChoice::Bar => indicatif::ProgressBar::new(range.len() as u64),
        ProgressChoice::Openjd | ProgressChoice::None => indicatif::ProgressBar::hidden(),
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} frames, {per_sec}, eta {eta}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let openjd = a.progress == ProgressChoice::Openjd;
    let mut report = |p: hadou::export::Progress| {
        bar.set_position(u64::from(p.done));
        if openjd {
            // Open Job Description reads a task's progress from these stdout lines (a percentage).
            use std::io::Write;
            let mut out = std::io::stdout().lock();
            let _ = writeln!(
                out,
                "openjd_progress: {:.1}",
                100.0 * f64::from(p.done) / f64::from(p.total.max(1))
            );
            let _ = out.flush();
        }
        Control::Continue
    };
    let (mut kept, mut replaced) = (0u32, 0u32);
    let outcome = if sequence {
        let options =
            hadou::export::SequenceOptions { pattern, stamp: Some(stamp), skip_existing: a.skip_existing };
        let mut notes = |n: hadou::export::SequenceNote| match n {
            hadou::export::SequenceNote::Kept(_) => kept += 1,
            hadou::export::SequenceNote::Replacing(f, why) => {
                replaced += 1;
                bar.suspend(|| {
                    eprintln!("note: frame {f}: rendering it again: {}", hadou_scene::escape_controls(&why))
                });
            }
        };
        hadou::export::export_sequence(
            &scene,
            backend.as_mut(),
            &spec,
            &a.output,
            &options,
            &mut report,
            &mut notes,
        )
    } else {
        export_animation(&scene, backend.as_mut(), &spec, &a.output, &mut report)
            .map_err(|error| hadou::export::SequenceError { frame: None, error })
    };
    bar.finish_and_clear();
    match outcome {
        Ok(ExportOutcome::Finished { frames }) | Ok(ExportOutcome::Cancelled { frames_written: frames }) => {
            let resumed = if a.skip_existing {
                format!(", {kept} kept as they were, {replaced} replaced")
            } else {
                String::new()
            };
            eprintln!(
                "wrote {} frames to {} ({} backend{resumed})",
                frames.saturating_sub(kept),
                a.output.display(),
                backend.name()
            );
            Ok(())
        }
        Err(e) => {
            let at = e.frame.map_or_else(String::new, |f| format!("frame {f}: "));
            Err(match e.error {
                ExportError::Spec(m) => Failure::input(format!("{at}{m}")),
                ExportError::Output(o) => {
                    let f: Failure = o.into();
                    Failure { message: format!("{at}{}", f.message), ..f }
                }
                ExportError::Render(r) => {
                    let f: Failure = r.into();
                    Failure { message: format!("{at}{}", f.message), ..f }
                }
            })
        }
    }
}

#[cfg(feature = "view")]
fn view(a: ViewArgs) -> Result<(), Failure> {
    // Ctrl-C, SIGTERM and SIGHUP remove the temporary files of screenshots, exports and saves.
    output::install_interrupt_cleanup().map_err(Failure::runtime)?;
    let time = a.time.as_deref().map(|t| parse_time("--time", t)).transpose()?;
    let opts = hadou::view::ViewOptions {
        scene: a.scene,
        script: a.script,
        screenshot: a.screenshot,
        time,
        backend: a.backend.map(|b| match b {
            ViewBackend::Cpu => hadou_view::viewer::BackendKind::Cpu,
            ViewBackend::Gpu => hadou_view::viewer::BackendKind::Gpu,
        }),
        stats: a.stats,
    };
    hadou::view::run(opts).map_err(|e| Failure { code: e.code, message: e.message })
}

/// Without the `view` feature there is no window to open.
#[cfg(not(feature = "view"))]
fn view(_: ViewArgs) -> Result<(), Failure> {
    Err(Failure::input(
        "hadou view: this hadou was built without its window (the `view` cargo feature, on by \
         default); build it with the feature, e.g. `cargo build --release -p hadou --features view`. \
         Without a window, `hadou render SCENE -o out.png` writes the same image and `hadou probe` \
         reads single pixels",
    ))
}

fn size_override(w: Option<u32>, h: Option<u32>) -> Result<(), Failure> {
    for (name, v) in [("--width", w), ("--height", h)] {
        if let Some(v) = v {
            check_size(name, v)?;
        }
    }
    Ok(())
}

/// Image edges are 1..=[`hadou::MAX_IMAGE_EDGE`] pixels; `flag` names the option the value came
/// from. Checked before the scene is loaded; [`check_image_size`] checks the whole size after.
fn check_size(flag: &str, v: u32) -> Result<(), Failure> {
    let max = hadou::MAX_IMAGE_EDGE;
    if v == 0 || v > max {
        return Err(Failure::input(format!("{flag} {v}: image size must be in 1..={max}")));
    }
    Ok(())
}

/// The image size `--width`/`--height` give `scene` (each flag overriding its edge of the scene's
/// `[image]`), checked against the limits of the scene's `[image]` ([`Scene::check_image_size`]:
/// edges, and the pixel count of a scene with an `[area_light]`) before anything is rendered or
/// written; the message names the flags.
fn check_image_size(
    scene: &Scene,
    path: &std::path::Path,
    w: Option<u32>,
    h: Option<u32>,
) -> Result<(u32, u32), Failure> {
    let (width, height) = (w.unwrap_or(scene.width()), h.unwrap_or(scene.height()));
    scene
        .check_image_size(width, height)
        .map_err(|m| Failure::input(format!("{}: {m}", size_origin(scene, path, w, h))))?;
    Ok((width, height))
}

/// `--samples n`'s cost per pixel with the scene's waves ([`Scene::check_pixel_work`]).
fn check_samples_work(scene: &Scene, samples: Option<u32>) -> Result<(), Failure> {
    match samples {
        Some(n) => scene.check_pixel_work(n).map_err(|(_, m)| Failure::input(format!("--samples {n}: {m}"))),
        None => Ok(()),
    }
}

/// Where an image size came from, for a message: the flags as given, with the edge the scene
/// file gave when only one flag is, or the scene's `[image]` when neither is.
fn size_origin(scene: &Scene, path: &std::path::Path, w: Option<u32>, h: Option<u32>) -> String {
    match (w, h) {
        (Some(w), Some(h)) => format!("--width {w} --height {h}"),
        (Some(w), None) => format!("--width {w} (height {} from the scene's [image])", scene.height()),
        (None, Some(h)) => format!("--height {h} (width {} from the scene's [image])", scene.width()),
        (None, None) => format!("{}: [image] {}×{}", path.display(), scene.width(), scene.height()),
    }
}

/// What each numeric flag that the argument parser reads accepts, for its one-line message.
fn flag_accepts(flag: &str) -> Option<&'static str> {
    Some(match flag {
        "--width" | "--height" => "must be a whole number of pixels, 1 to 16384",
        "--samples" => "must be one of 1, 4, 9, 16 (a k × k grid of samples per pixel)",
        "--sizes" => "must be whole numbers of pixels separated by commas, e.g. 512,1024",
        "--iterations" => "must be a whole number of repetitions, 1 or more",
        _ => return None,
    })
}

/// A command line the argument parser refused: help and version are printed as asked (exit 0);
/// anything else is one line on stderr naming the flag, the value as typed and what the flag
/// accepts, exit 2 (the parser's own message is three lines, with a usage hint).
fn flag_error(e: clap::Error) -> ExitCode {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
        let _ = e.print();
        return ExitCode::SUCCESS;
    }
    if matches!(e.kind(), ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand) {
        let _ = e.print();
        return ExitCode::from(2);
    }
    let text = |kind| match e.get(kind) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        _ => None,
    };
    let line = match (e.kind(), text(ContextKind::InvalidArg), text(ContextKind::InvalidValue)) {
        // The missing arguments are on the parser's second line: named here, on the one line.
        (ErrorKind::MissingRequiredArgument, _, _) => match e.get(ContextKind::InvalidArg) {
            Some(ContextValue::Strings(missing)) => {
                format!("missing {}", missing.join(", "))
            }
            _ => "a required argument is missing".to_string(),
        },
        (ErrorKind::InvalidValue | ErrorKind::ValueValidation, Some(arg), Some(value)) => {
            // The argument as clap names it: `--samples <SAMPLES>`; the flag is its first word.
            let flag = arg.split_whitespace().next().unwrap_or(&arg).to_string();
            let value = hadou_scene::escape_controls(&value).into_owned();
            match flag_accepts(&flag) {
                Some(accepts) => format!("{flag} {value}: {accepts}"),
                None => {
                    let first = e.to_string();
                    let first = first.lines().next().unwrap_or("").trim_start_matches("error: ").to_string();
                    format!("{flag} {value}: {first}")
                }
            }
        }
        _ => {
            let first = e.to_string();
            first.lines().next().unwrap_or("").trim_start_matches("error: ").to_string()
        }
    };
    eprintln!("error: {} (see hadou --help)", hadou_scene::escape_controls(&line));
    ExitCode::from(2)
}

/// Parses a time in seconds as typed after `flag`: a finite number ≥ 0. Messages echo the text
/// as typed, never a reformatted value.
fn parse_time(flag: &str, text: &str) -> Result<f32, Failure> {
    let t: f64 = text
        .trim()
        .parse()
        .map_err(|_| Failure::input(format!("{flag} {text}: must be a number of seconds, e.g. 1.5")))?;
    if !t.is_finite() {
        return Err(Failure::input(format!("{flag} {text}: must be a finite number of seconds")));
    }
    if t.abs() > f64::from(f32::MAX) {
        return Err(Failure::input(format!(
            "{flag} {text}: is past the largest time a frame can hold ({:e} s, a 32-bit float)",
            f32::MAX
        )));
    }
    if t < 0.0 {
        return Err(Failure::input(format!("{flag} {text}: times are ≥ 0 seconds")));
    }
    Ok(t as f32)
}

/// Parses `--fps` as typed: a finite number > 0 such that every frame of `range` has a finite time.
fn parse_fps(text: &str, range: &std::ops::Range<u32>) -> Result<f32, Failure> {
    let bad =
        || Failure::input(format!("--fps {text}: must be a positive number of frames per second, e.g. 24"));
    let fps: f64 = text.trim().parse().map_err(|_| bad())?;
    if !(fps.is_finite() && fps > 0.0 && fps <= f64::from(f32::MAX)) || (fps as f32) <= 0.0 {
        return Err(bad());
    }
    let last = range.end.saturating_sub(1);
    let t = f64::from(last) / f64::from(fps as f32);
    if t.is_nan() || t > f64::from(f32::MAX) {
        return Err(Failure::input(format!(
            "--fps {text}: too small; frame {last} would be at {t:.3e} s, beyond the largest time hadou \
             can represent (3.4e38 s)"
        )));
    }
    Ok(fps as f32)
}

fn frame_at(scene: &Scene, t: f32, width: Option<u32>, height: Option<u32>, samples: Option<u32>) -> Frame {
    scene.at_with(t, &hadou::FrameOverrides { width, height, samples })
}

fn make_backend(choice: BackendChoice) -> Result<Box<dyn Backend>, Failure> {
    match choice {
        BackendChoice::Cpu => Ok(Box::new(CpuBackend::new())),
        BackendChoice::Gpu => Ok(Box::new(GpuBackend::new()?)),
        // Decided from the adapter's description alone (no device, no shader compilation), so a
        // declined GPU costs little and says one line.
        BackendChoice::Auto => Ok(match hadou::gpu::find_adapter() {
            Ok(info) if info.device_type != hadou::gpu::wgpu::DeviceType::Cpu => match GpuBackend::new() {
                Ok(g) => Box::new(g),
                Err(e) => {
                    eprintln!(
                        "note: using the CPU backend; the GPU adapter {} failed to start: {e}",
                        info.name
                    );
                    Box::new(CpuBackend::new())
                }
            },
            Ok(info) => {
                eprintln!(
                    "note: using the CPU backend; the only GPU adapter, {}, is a software rasterizer (slower here)",
                    info.name
                );
                Box::new(CpuBackend::new())
            }
            Err(e) => {
                eprintln!("note: using the CPU backend ({e})");
                Box::new(CpuBackend::new())
            }
        }),
    }
}

/// A bench timer for the chosen backend, its name and how it measures.
fn make_timer(choice: BackendChoice) -> Result<(Box<hadou::bench::Timer<'static>>, String, String), Failure> {
    let gpu = match choice {
        BackendChoice::Cpu => None,
        BackendChoice::Gpu => Some(GpuBackend::new()?),
        BackendChoice::Auto => match hadou::gpu::find_adapter() {
            Ok(info) if info.device_type != hadou::gpu::wgpu::DeviceType::Cpu => GpuBackend::new().ok(),
            _ => None,
        },
    };
    if let Some(mut gpu) = gpu {
        let name = format!("gpu ({})", gpu.adapter_name());
        let method = if gpu.has_timestamps() {
            "GPU timestamp queries, excluding read-back"
        } else {
            "submit-and-wait wall clock (no timestamp queries on this adapter), excluding read-back"
        };
        let timer = move |f: &Frame, n: u32| {
            let t = gpu.time_frame(f, n)?;
            let mut parts: Vec<(String, f64)> =
                t.passes.iter().map(|p| (p.name.clone(), p.median_ms)).collect();
            // The PNG's rows as `hadou render` gets them (drawn, read back, 8-bit sRGB), by wall
            // clock after a warm-up; less the GPU's time, what the read-back adds.
            let mut image = gpu.render_rows_rgb8(f, 0..f.height)?;
            let mut wall = Vec::with_capacity(n.max(1) as usize);
            for _ in 0..n.max(1) {
                let start = std::time::Instant::now();
                image = gpu.render_rows_rgb8(f, 0..f.height)?;
                wall.push(start.elapsed().as_secs_f64() * 1e3);
            }
            parts.push(("read-back".into(), (hadou::bench::median(wall) - t.median_ms).max(0.0)));
            let output =
                (0..n.max(1)).map(|_| hadou::bench::rgb8_output_ms(&image)).collect::<Result<Vec<_>, _>>()?;
            parts.push(("output".into(), hadou::bench::median(output)));
            Ok(hadou::bench::Timing { ms: t.median_ms, parts })
        };
        return Ok((Box::new(timer), name, method.into()));
    }
    let timer = hadou::bench::time_cpu;
    let threads = rayon::current_num_threads();
    Ok((Box::new(timer), format!("cpu ({threads} threads)"), "wall clock, whole render".into()))
}

/// Parses `A..B` (B excluded) or `A..=B`, or an Open Job Description range of contiguous frames
/// (a task chunk's value): `A-B` (B included) or a single frame `N`.
fn parse_frames(s: &str) -> Result<std::ops::Range<u32>, Failure> {
    let bad = || {
        Failure::input(format!(
            "--frames {s}: expected a range of non-negative frame numbers like `0..48` (48 excluded), \
             `0..=47` or `0-47`"
        ))
    };
    let (a, b, inclusive) = if let Some((a, b)) = s.split_once("..=") {
        (a, b, true)
    } else if let Some((a, b)) = s.split_once("..") {
        (a, b, false)
    } else if let Some((a, b)) = s.trim().split_once('-').filter(|(a, _)| !a.is_empty()) {
        (a, b, true)
    } else if s.trim().bytes().all(|c| c.is_ascii_digit()) && !s.trim().is_empty() {
        (s, s, true)
    } else {
        return Err(bad());
    };
    let a: u32 = a.trim().parse().map_err(|_| bad())?;
    let b: u32 = b.trim().parse().map_err(|_| bad())?;
    let too_large =
        || Failure::input(format!("--frames {s}: frame numbers go up to 4294967294 (`A..=4294967294`)"));
    let end = if inclusive { b.checked_add(1).ok_or_else(too_large)? } else { b };
    if end <= a {
        return Err(Failure::input(format!("--frames {s}: the range is empty")));
    }
    Ok(a..end)
}

fn render(a: RenderArgs) -> Result<(), Failure> {
    size_override(a.width, a.height)?;
    if let Some(n) = a.samples {
        hadou_scene::check_samples(n).map_err(|m| Failure::input(format!("--samples {n}: {m}")))?;
    }
    // Ctrl-C, SIGTERM and SIGHUP remove the temporary file of an output being written.
    output::install_interrupt_cleanup().map_err(Failure::runtime)?;
    let Some(frames) = &a.frames else {
        if a.skip_existing {
            return Err(Failure::input("--skip-existing: applies to a PNG sequence (-o DIR/ with --frames)"));
        }
        if a.frame_name != "frame_#####.png" {
            return Err(Failure::input("--frame-name: applies to a PNG sequence (-o DIR/ with --frames)"));
        }
        let time = parse_time("--time", &a.time)?;
        output::Format::from_path(&a.output)?;
        output::check_directory(&a.output)?;
        let (scene, stamp) = load_scene_stamped(&a.scene)?;
        check_image_size(&scene, &a.scene, a.width, a.height)?;
        check_samples_work(&scene, a.samples)?;
        let frame = frame_at(&scene, time, a.width, a.height, a.samples);
        let mut backend = make_backend(a.backend)?;
        backend.check_frame(&frame).map_err(|m| {
            let at = scene.bloom_location().map_or_else(|| a.scene.display().to_string(), |l| l.to_string());
            Failure::input(format!("{at}: {m}"))
        })?;
        // Both formats are rendered and encoded band by band: memory follows the band, not the
        // image.
        let (w, h, band_rows) = (frame.width, frame.height, output::frame_band_rows(&frame));
        // The image's stamp (docs/farm.md): the scene file's hash, the version, the settings.
        let stamp = hadou::farm::FrameStamp {
            scene: stamp,
            frame: None,
            settings: hadou::farm::frame_settings(&frame, &format!("t={} s", a.time.trim()), backend.name()),
        }
        .text_chunks();
        match output::Format::from_path(&a.output)? {
            // A PNG's bands come as 8-bit sRGB straight from the renderer (the CPU backend's colour
            // stage writes no float buffers for them).
            output::Format::Png => {
                output::write_png_banded_with_text(&a.output, w, h, band_rows, &stamp, |rows| {
                    Ok::<_, Failure>(backend.render_rows_rgb8(&frame, rows)?)
                })?
            }
            output::Format::Exr => {
                output::write_banded_with_text(&a.output, w, h, band_rows, &stamp, |rows| {
                    let band = backend.render_rows(&frame, rows)?;
                    check_finite(&band)?;
                    Ok::<_, Failure>(band)
                })?
            }
        }
        eprintln!(
            "wrote {} ({}×{}, {} backend)",
            a.output.display(),
            frame.width,
            frame.height,
            backend.name()
        );
        return Ok(());
    };
    let range = parse_frames(frames)?;
    let fps = parse_fps(&a.fps, &range)?;
    render_animation(&a, range, fps)
}

/// The last line of defence of the invariant that no NaN or infinity reaches an image.
fn check_finite(image: &Image) -> Result<(), Failure> {
    if output::is_finite(image) {
        Ok(())
    } else {
        Err(Failure::runtime("internal error: the renderer produced a non-finite value; nothing was written"))
    }
}

/// A number for JSON output: never `null` (serde_json's rendering of NaN and ±∞). Energies
/// saturate at the largest finite `f32`, so ±∞ becomes ±`f32::MAX`; a NaN (none should reach here)
/// becomes 0.
fn json_number(v: f32) -> f32 {
    if v.is_nan() {
        0.0
    } else {
        v.clamp(-f32::MAX, f32::MAX)
    }
}

fn parse_pixel(s: &str) -> Result<(u32, u32), Failure> {
    let bad = || {
        Failure::input(format!(
            "--pixel {s}: expected `X,Y` with non-negative integers inside the image, e.g. 256,128"
        ))
    };
    let (x, y) = s.split_once(',').ok_or_else(bad)?;
    Ok((x.trim().parse().map_err(|_| bad())?, y.trim().parse().map_err(|_| bad())?))
}

fn probe(a: ProbeArgs) -> Result<(), Failure> {
    size_override(a.width, a.height)?;
    let (x, y) = parse_pixel(&a.pixel)?;
    let time = parse_time("--time", &a.time)?;
    let scene = load_scene(&a.scene)?;
    check_image_size(&scene, &a.scene, a.width, a.height)?;
    // The pixel's centre, at one sample (docs/scene-format.md, `[image] samples`).
    let frame = frame_at(&scene, time, a.width, a.height, Some(1));
    let outside = || {
        Failure::input(format!(
            "--pixel {x},{y}: outside the {}×{} image (x < {}, y < {})",
            frame.width, frame.height, frame.width, frame.height
        ))
    };
    let mut backend = make_backend(a.backend)?;
    let p = if backend.name() == "cpu" {
        hadou::probe(&frame, x, y).ok_or_else(outside)?
    } else {
        if x >= frame.width || y >= frame.height {
            return Err(outside());
        }
        gpu_probe(&mut *backend, &frame, x, y)?
    };
    let waves: Vec<_> = p
        .waves
        .iter()
        .map(|w| {
            serde_json::json!({"name": w.name, "energy": json_number(w.energy), "evaluations": w.evaluations})
        })
        .collect();
    let j = serde_json::json!({
        "scene": a.scene.display().to_string(),
        "time": time,
        "pixel": [x, y],
        "size": [frame.width, frame.height],
        "waves": waves,
        "energy": json_number(p.waves.iter().map(|w| w.energy).sum::<f32>()),
        "color": p.color.map(json_number),
        "depth": json_number(p.depth),
        "object": p.object,
        "backend": backend.name(),
    });
    // The shadow the pixel takes, present only where there is one.
    let mut j = j;
    if let (Some(shadow), Some(map)) = (p.shadow, j.as_object_mut()) {
        map.insert("shadow".into(), serde_json::Value::String(shadow));
    }
    // The area light's soft-shadow visibility, present only with an [area_light].
    if let (Some(v), Some(map)) = (p.soft, j.as_object_mut()) {
        map.insert("soft_visibility".into(), serde_json::json!(json_number(v)));
    }
    println!("{}", serde_json::to_string_pretty(&j).unwrap_or_default());
    Ok(())
}

/// Probes a pixel with a whole-frame backend: one render of the pixel's row for colour and depth,
/// then one per wave alone for its energy (a row, not the image, so memory stays small at any
/// size). Integrand evaluations are not counted there (reported as 0).
fn gpu_probe(backend: &mut dyn Backend, frame: &Frame, x: u32, y: u32) -> Result<hadou::Probe, Failure> {
    let img = backend.render_rows(frame, y..y + 1)?;
    let i = img.index(x, 0);
    let mut waves = Vec::new();
    for w in &frame.waves {
        let mut single = frame.clone();
        single.waves = vec![w.clone()];
        let e = backend.render_rows(&single, y..y + 1)?.energy[i];
        waves.push(hadou::WaveProbe { name: w.name.clone(), energy: e, evaluations: 0 });
    }
    let (object, shadow, soft) =
        hadou::probe(frame, x, y).map_or((None, None, None), |p| (p.object, p.shadow, p.soft));
    Ok(hadou::Probe { x, y, waves, color: img.color[i], depth: img.depth[i], object, shadow, soft })
}

fn bench(a: BenchArgs) -> Result<(), Failure> {
    let curves = a.table == BenchTable::Curves;
    let toon = a.table == BenchTable::Toon;
    let shadows = a.table == BenchTable::Shadows;
    let sizes = match (a.sizes.is_empty(), a.table) {
        (false, _) => a.sizes.clone(),
        (true, BenchTable::Analytic) => vec![512, 1024, 2048],
        (true, BenchTable::Curves) => vec![512],
        (true, BenchTable::Toon) => vec![256, 512, 1024],
        (true, BenchTable::Shadows) => vec![512, 1024],
    };
    for &s in &sizes {
        check_size("--sizes", s)?;
    }
    let iterations = a.iterations.unwrap_or(if curves { 1 } else { 5 });
    match a.disc_radius {
        Some(r) if a.table != BenchTable::Shadows => {
            return Err(Failure::input(format!("--disc-radius {r}: applies to `hadou bench shadows` only")));
        }
        Some(r) if !(r.is_finite() && (0.0..=1e6).contains(&r)) => {
            return Err(Failure::input(format!("--disc-radius {r}: must be a number in [0, 1e6]")));
        }
        _ => {}
    }
    if let Some(f) = a.scene.as_ref().filter(|_| a.table != BenchTable::Shadows) {
        return Err(Failure::input(format!("--scene {f}: applies to `hadou bench shadows` only")));
    }
    if a.traced_only && a.table != BenchTable::Shadows {
        return Err(Failure::input("--traced-only: applies to `hadou bench shadows` only"));
    }
    if iterations == 0 {
        return Err(Failure::input("--iterations 0: need at least one timed repetition"));
    }
    if (curves || toon || shadows) && !a.scenes.is_dir() {
        return Err(Failure::input(format!(
            "--scenes {}: not a directory; run from the repository root or pass --scenes DIR",
            a.scenes.display()
        )));
    }
    if curves {
        // Every scene the curve table needs must be there and valid before anything is timed.
        let files = hadou::bench::CURVE_SCENES
            .iter()
            .map(|&(_, f)| f)
            .chain(hadou::bench::ACCEPTANCE_SCENES.iter().map(|&(_, f, _)| f));
        for file in files {
            Scene::load(a.scenes.join(file)).map_err(|e| {
                Failure::input(format!(
                    "--scenes {}: the curve bench needs the example scenes (scenes/ of the repository): {e}",
                    a.scenes.display()
                ))
            })?;
        }
    }
    if toon || shadows {
        let file = if toon {
            hadou::bench::TOON_SCENE.0
        } else {
            a.scene.as_deref().unwrap_or(hadou::bench::SOFT_SCENE.0)
        };
        let scene = Scene::load(a.scenes.join(file)).map_err(|e| {
            Failure::input(format!(
                "--scenes {}: this bench needs the example scenes (scenes/ of the repository): {e}",
                a.scenes.display()
            ))
        })?;
        for &s in &sizes {
            scene.check_image_size(s, s).map_err(|m| Failure::input(format!("--sizes {s}: {m} ({file})")))?;
        }
    }
    let (mut timer, name, method) = make_timer(a.backend)?;
    let bar = indicatif::ProgressBar::new_spinner();
    let mut progress = |m: &str| bar.set_message(m.to_string());
    let (text, json) = if shadows {
        let t = hadou::bench::soft_table(
            &mut *timer,
            &a.scenes,
            &sizes,
            iterations,
            &name,
            hadou::bench::SoftOptions {
                scene: a.scene.as_deref(),
                traced_only: a.traced_only,
                disc_radius: a.disc_radius,
            },
            &mut progress,
        )?;
        (t.to_text(), t.to_json())
    } else if toon {
        let t = hadou::bench::toon_table(&mut *timer, &a.scenes, &sizes, iterations, &name, &method)?;
        (t.to_text(), t.to_json())
    } else if curves {
        let t = hadou::bench::curve_table(
            &mut *timer,
            &a.scenes,
            &sizes,
            iterations,
            &name,
            &method,
            &mut progress,
        )?;
        (t.to_text(), t.to_json())
    } else {
        let t = hadou::bench::analytic_table(&mut *timer, &sizes, iterations, &name, &method)?;
        let (mut text, mut json) = (t.to_text(), t.to_json());
        if name.starts_with("cpu") {
            // The distance to the machine's limit, at the largest size, in the same run.
            let largest = sizes.iter().copied().max().unwrap_or(1024);
            let l = hadou::bench::limit_table(largest, iterations)?;
            text += &l.to_text();
            json["limit"] = l.to_json();
        }
        (text, json)
    };
    bar.finish_and_clear();
    if !a.json {
        print!("{text}");
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&json).unwrap_or_default());
    }
    Ok(())
}

/// [`load_scene`], with the stamp its frames carry: the hash of the very bytes parsed.
fn load_scene_stamped(path: &std::path::Path) -> Result<(Scene, hadou::farm::SceneStamp), Failure> {
    let text = Scene::read_text(path)?;
    let scene = Scene::parse(&text, path)?;
    for w in scene.warnings() {
        eprintln!("{}: warning: {w}", hadou_scene::escape_controls(&path.display().to_string()));
    }
    Ok((scene, hadou::farm::SceneStamp::of_text(&text)))
}

/// `hadou validate [SCENE] [--frames DIR]`: the scene (its clips listed), then the frames.
fn validate(a: ValidateArgs) -> Result<(), Failure> {
    let pattern = hadou::farm::FramePattern::parse(&a.frame_name).map_err(Failure::input)?;
    let stamp = match &a.scene {
        Some(path) => {
            let (scene, stamp) = load_scene_stamped(path)?;
            for line in clip_summary(&scene) {
                println!("{line}");
            }
            Some(stamp)
        }
        None => None,
    };
    let Some(dir) = &a.frames else { return Ok(()) };
    let report = hadou::farm::check_frames_dir(dir, &pattern, stamp.as_ref()).map_err(Failure::input)?;
    let esc = |p: &std::path::Path| hadou_scene::escape_controls(&p.display().to_string()).into_owned();
    for p in &report.problems {
        println!("{}: {}", esc(&p.path), hadou_scene::escape_controls(&p.message));
    }
    let (lo, hi) = (report.frames.keys().next().copied(), report.frames.keys().last().copied());
    let range = match (lo, hi) {
        (Some(lo), Some(hi)) => format!("frames {lo}..={hi}"),
        _ => "no frames".into(),
    };
    if report.problems.is_empty() {
        let first = report.frames.values().flatten().next();
        println!(
            "{}: {} frames ({range}), all complete, of scene blake3 {}…, hadou {}",
            esc(dir),
            report.frames.len(),
            first.map_or("", |s| s.scene.short_hash()),
            hadou::farm::VERSION
        );
        Ok(())
    } else {
        Err(Failure::input(format!(
            "{}: {} problem(s) in {} frames ({range}), listed above",
            esc(dir),
            report.problems.len(),
            report.frames.len()
        )))
    }
}

/// Loads a scene and prints its warnings (downscaled textures, meshes without texture
/// coordinates, …) to stderr as `path: warning: …`.
fn load_scene(path: &std::path::Path) -> Result<Scene, Failure> {
    let scene = Scene::load(path)?;
    for w in scene.warnings() {
        eprintln!("{}: warning: {w}", hadou_scene::escape_controls(&path.display().to_string()));
    }
    Ok(scene)
}

/// One line per glTF object with animation clips, a clip it plays or VRM expressions, for
/// `validate`: `object "hero": clips brace (2 s), step (1.5 s); plays "brace"; expressions blink`
/// (`rests` when its file has clips and it plays none; the clip played may come from its
/// `animation_file`).
fn clip_summary(scene: &Scene) -> Vec<String> {
    let esc = hadou::escape_controls;
    let (clips, expressions) = (scene.object_clips(), scene.object_expressions());
    let mut out = Vec::new();
    for (i, name) in scene.object_names().into_iter().enumerate() {
        let c = clips.get(i).map_or(&[][..], Vec::as_slice);
        let e = expressions.get(i).map_or(&[][..], Vec::as_slice);
        let mut parts = Vec::new();
        if !c.is_empty() {
            let list: Vec<String> = c.iter().map(|(n, d)| format!("{} ({d} s)", esc(n))).collect();
            parts.push(format!("clips {}", list.join(", ")));
        }
        match scene.object_clip_at(i, 0.0) {
            Some((clip, _)) => parts.push(format!("plays \"{}\"", esc(&clip))),
            None if !c.is_empty() => parts.push("rests".to_string()),
            None => {}
        }
        if !e.is_empty() {
            let list: Vec<String> = e.iter().map(|n| esc(n).into_owned()).collect();
            parts.push(format!("expressions {}", list.join(", ")));
        }
        if !parts.is_empty() {
            out.push(format!("object \"{}\": {}", esc(name), parts.join("; ")));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::json_number;

    /// serde_json writes NaN and ±∞ as `null`; `probe` passes every number through
    /// `json_number` first. (A scene file cannot make an energy overflow within its bounds, so
    /// the CLI test `probe_never_prints_null` alone could not fail on this.)
    #[test]
    fn json_numbers_are_never_null() {
        let values = [f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::MAX, 1.5, -0.0];
        let json = serde_json::to_string(&values.map(json_number)).unwrap();
        assert!(!json.contains("null"), "{json}");
        assert_eq!(json_number(f32::INFINITY), f32::MAX);
        assert_eq!(json_number(f32::NEG_INFINITY), -f32::MAX);
        assert_eq!(json_number(f32::NAN), 0.0);
        assert_eq!(json_number(1.5), 1.5);
        // Without it, the same values do print null.
        assert!(serde_json::to_string(&values).unwrap().contains("null"));
    }
}
