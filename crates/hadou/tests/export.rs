//! `hadou::export`: a PNG sequence equals what `hadou render` writes, a GIF decodes to the right
//! frames, size, delays and colours, cancel and errors leave nothing half-written.

mod common;

use common::Scratch;
use hadou::export::{
    export_animation, export_sequence, frame_file_name, gif_delay_cs, AnimationFormat, AnimationSpec,
    Control, ExportError, ExportOutcome, Progress, SequenceOptions,
};
use hadou::farm::SceneStamp;
use hadou::output::{self, OutputError};
use hadou::{Backend, CpuBackend, Scene};
use std::path::{Path, PathBuf};

const SCENE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/kamehameha.toml");
const W: u32 = 64;
const H: u32 = 36;

fn scene() -> Scene {
    Scene::load(SCENE).expect("the example scene loads")
}

fn spec(frames: std::ops::Range<u32>, fps: f32) -> AnimationSpec {
    AnimationSpec { frames, fps, width: Some(W), height: Some(H), samples: None }
}

fn tmpdir(name: &str) -> Scratch {
    Scratch::new("export", name)
}

fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    names
}

/// Decodes an 8-bit RGB PNG into its size and pixel bytes.
fn decode_png(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.color_type, info.bit_depth), (png::ColorType::Rgb, png::BitDepth::Eight));
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// The PNG `output::write` writes for frame `f` of `spec`, rendered whole on the CPU, decoded.
fn reference_png(scene: &Scene, spec: &AnimationSpec, f: u32, dir: &Path) -> (u32, u32, Vec<u8>) {
    let mut frame = scene.at(f as f32 / spec.fps);
    frame.width = W;
    frame.height = H;
    let image = CpuBackend::new().render(&frame).unwrap();
    let path = dir.join(format!("reference_{f}.png"));
    output::write(&image, &path).unwrap();
    let decoded = decode_png(&std::fs::read(&path).unwrap());
    std::fs::remove_file(&path).unwrap();
    decoded
}

/// A progress callback that records every call and cancels once `done` reaches `cancel_at`.
fn recorder(calls: &mut Vec<Progress>, cancel_at: Option<u32>) -> impl FnMut(Progress) -> Control + '_ {
    move |p| {
        calls.push(p);
        if Some(p.done) == cancel_at {
            Control::Cancel
        } else {
            Control::Continue
        }
    }
}

#[test]
fn formats_come_from_the_path() {
    let dir = tmpdir("formats");
    let f = |p: &Path| AnimationFormat::from_path(p);
    assert_eq!(f(&dir).unwrap(), AnimationFormat::PngSequence);
    assert_eq!(f(Path::new("not-yet-there/")).unwrap(), AnimationFormat::PngSequence);
    assert_eq!(f(Path::new("out/fire.gif")).unwrap(), AnimationFormat::Gif);
    assert_eq!(f(Path::new("FIRE.GIF")).unwrap(), AnimationFormat::Gif);
    // An existing directory is a sequence whatever its name.
    let gif_named_dir = dir.join("looks.gif");
    std::fs::create_dir(&gif_named_dir).unwrap();
    assert_eq!(f(&gif_named_dir).unwrap(), AnimationFormat::PngSequence);
    for bad in ["fire.png", "fire.mp4", "fire"] {
        match f(Path::new(bad)) {
            Err(OutputError::BadPath(m)) => assert!(m.contains(bad) && m.contains(".gif"), "{m}"),
            other => panic!("{bad}: {other:?}"),
        }
    }
    assert_eq!(frame_file_name(7), "frame_00007.png");
    assert_eq!(frame_file_name(123456), "frame_123456.png");
}

#[test]
fn gif_delays_keep_the_average_rate() {
    // 24 fps: frame k shows from round(100k/24) cs; 6 frames take exactly 25 cs.
    let d: Vec<u16> = (0..12).map(|k| gif_delay_cs(24.0, k)).collect();
    assert_eq!(d, [4, 4, 5, 4, 4, 4, 4, 4, 5, 4, 4, 4]);
    assert_eq!((0..24).map(|k| u32::from(gif_delay_cs(24.0, k))).sum::<u32>(), 100);
    assert!((0..30).all(|k| gif_delay_cs(10.0, k) == 10));
    assert!((0..30).all(|k| gif_delay_cs(25.0, k) == 4));
    // Faster than 50 fps plays at 50 fps (browsers slow 0–1 cs delays down to 10 cs).
    assert!((0..30).all(|k| gif_delay_cs(60.0, k) == 2 && gif_delay_cs(50.0, k) == 2));
    assert_eq!(gif_delay_cs(1e-4, 0), u16::MAX);
}

#[test]
fn a_png_sequence_is_what_hadou_render_writes() {
    let dir = tmpdir("pngseq");
    let out = dir.join("frames");
    std::fs::create_dir(&out).unwrap();
    let scene = scene();
    let spec = spec(3..6, 12.0);
    let mut calls = Vec::new();
    let outcome =
        export_animation(&scene, &mut CpuBackend::new(), &spec, &out, &mut recorder(&mut calls, None))
            .unwrap();
    assert_eq!(outcome, ExportOutcome::Finished { frames: 3 });
    let expected: Vec<Progress> = (0..=3).map(|done| Progress { done, total: 3 }).collect();
    assert_eq!(calls, expected);
    assert_eq!(listing(&out), ["frame_00003.png", "frame_00004.png", "frame_00005.png"]);
    for f in 3..6 {
        let got = decode_png(&std::fs::read(out.join(frame_file_name(f))).unwrap());
        assert_eq!(got, reference_png(&scene, &spec, f, &dir), "frame {f}");
    }
    // The frames differ (the beam moves), so the times really are f / fps.
    assert_ne!(
        std::fs::read(out.join("frame_00003.png")).unwrap(),
        std::fs::read(out.join("frame_00005.png")).unwrap()
    );

    // Byte for byte what `hadou render --frames` writes.
    let cli = dir.join("cli");
    std::fs::create_dir(&cli).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_hadou"))
        .args(["render", SCENE, "-o", cli.to_str().unwrap(), "--frames", "3..6", "--fps", "12"])
        .args(["--width", "64", "--height", "36", "--backend", "cpu"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(listing(&cli), listing(&out));
    // The CLI stamps its frames (docs/farm.md); `export_sequence` with the same stamp writes its
    // files byte for byte, and the pixels are `export_animation`'s.
    let stamped = dir.join("stamped");
    std::fs::create_dir(&stamped).unwrap();
    let options = SequenceOptions {
        stamp: Some(SceneStamp::of_text(&std::fs::read_to_string(SCENE).unwrap())),
        ..SequenceOptions::default()
    };
    export_sequence(
        &scene,
        &mut CpuBackend::new(),
        &spec,
        &stamped,
        &options,
        &mut |_| Control::Continue,
        &mut |_| {},
    )
    .unwrap();
    for name in listing(&out) {
        assert_eq!(
            std::fs::read(cli.join(&name)).unwrap(),
            std::fs::read(stamped.join(&name)).unwrap(),
            "{name}"
        );
        assert_eq!(common::decode_png(&cli.join(&name)), common::decode_png(&out.join(&name)), "{name}");
    }
}

/// A decoded GIF.
struct DecodedGif {
    size: (u16, u16),
    repeat: gif::Repeat,
    /// Each frame's delay (cs) and RGBA pixels.
    frames: Vec<(u16, Vec<u8>)>,
}

fn decode_gif(path: &Path) -> DecodedGif {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options.read_info(std::fs::File::open(path).unwrap()).unwrap();
    let size = (decoder.width(), decoder.height());
    let mut frames = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert_eq!((frame.left, frame.top, frame.width, frame.height), (0, 0, size.0, size.1));
        frames.push((frame.delay, frame.buffer.to_vec()));
    }
    DecodedGif { size, repeat: decoder.repeat(), frames }
}

#[test]
fn a_gif_has_the_frames_size_delays_and_colours() {
    let dir = tmpdir("gif");
    let path = dir.join("fire.gif");
    std::fs::write(&path, b"an older file, replaced whole").unwrap();
    let scene = scene();
    let spec = spec(0..5, 24.0);
    let mut calls = Vec::new();
    let outcome =
        export_animation(&scene, &mut CpuBackend::new(), &spec, &path, &mut recorder(&mut calls, None))
            .unwrap();
    assert_eq!(outcome, ExportOutcome::Finished { frames: 5 });
    assert_eq!(calls.len(), 6);
    assert_eq!(listing(&dir), ["fire.gif"], "no temporary file is left");

    let DecodedGif { size, repeat, frames } = decode_gif(&path);
    assert_eq!(size, (W as u16, H as u16));
    assert_eq!(repeat, gif::Repeat::Infinite);
    assert_eq!(frames.len(), 5);
    let delays: Vec<u16> = frames.iter().map(|f| f.0).collect();
    assert_eq!(delays, [4, 4, 5, 4, 4]);

    // Colours: every frame against the 8-bit sRGB PNG of the same frame. Quantisation to 256
    // colours per frame (NeuQuant at speed 10, deterministic) moves a channel by under 1.5 codes on
    // average, fewer than 8 % of the pixels by more than 12 codes in any channel, and none by more
    // than 48 (measured here: mean 0.83–0.87, about 4 % beyond 12, worst 35); alpha is opaque.
    for (k, (_, rgba)) in frames.iter().enumerate() {
        let (_, _, rgb) = reference_png(&scene, &spec, k as u32, &dir);
        assert_eq!(rgba.len(), rgb.len() / 3 * 4);
        let (mut max, mut sum, mut far) = (0u8, 0u64, 0usize);
        for (g, p) in rgba.chunks_exact(4).zip(rgb.chunks_exact(3)) {
            assert_eq!(g[3], 255);
            let d = (0..3).map(|c| g[c].abs_diff(p[c])).max().unwrap_or(0);
            far += usize::from(d > 12);
            for c in 0..3 {
                let d = g[c].abs_diff(p[c]);
                max = max.max(d);
                sum += u64::from(d);
            }
        }
        let mean = sum as f64 / rgb.len() as f64;
        eprintln!(
            "frame {k}: max {max}, mean {mean:.3}, pixels off by more than 12: {far} of {}",
            rgb.len() / 3
        );
        assert!(
            max <= 48 && mean < 1.5 && far * 100 < rgb.len() / 3 * 8,
            "frame {k}: max {max}, mean {mean}, far {far}"
        );
    }
}

#[test]
fn a_cancelled_gif_leaves_nothing() {
    let dir = tmpdir("cancel-gif");
    let scene = scene();
    let mut calls = Vec::new();
    let path = dir.join("fire.gif");
    let outcome = export_animation(
        &scene,
        &mut CpuBackend::new(),
        &spec(0..6, 24.0),
        &path,
        &mut recorder(&mut calls, Some(2)),
    )
    .unwrap();
    assert_eq!(outcome, ExportOutcome::Cancelled { frames_written: 0 });
    assert_eq!(calls.last(), Some(&Progress { done: 2, total: 6 }));
    assert_eq!(calls.len(), 3, "no frame is rendered after the cancel");
    assert!(listing(&dir).is_empty(), "{:?}", listing(&dir));

    // An existing GIF at the path is left as it was.
    std::fs::write(&path, b"keep me").unwrap();
    let outcome =
        export_animation(&scene, &mut CpuBackend::new(), &spec(0..6, 24.0), &path, &mut |_| Control::Cancel)
            .unwrap();
    assert_eq!(outcome, ExportOutcome::Cancelled { frames_written: 0 });
    assert_eq!(listing(&dir), ["fire.gif"]);
    assert_eq!(std::fs::read(&path).unwrap(), b"keep me");
}

#[test]
fn a_cancelled_png_sequence_keeps_the_finished_frames() {
    let dir = tmpdir("cancel-png");
    let mut calls = Vec::new();
    let outcome = export_animation(
        &scene(),
        &mut CpuBackend::new(),
        &spec(10..16, 24.0),
        &dir,
        &mut recorder(&mut calls, Some(2)),
    )
    .unwrap();
    assert_eq!(outcome, ExportOutcome::Cancelled { frames_written: 2 });
    assert_eq!(listing(&dir), ["frame_00010.png", "frame_00011.png"]);
    // A cancel answered after the last frame changes nothing: the export is complete.
    let outcome = export_animation(
        &scene(),
        &mut CpuBackend::new(),
        &spec(0..2, 24.0),
        &dir,
        &mut recorder(&mut Vec::new(), Some(2)),
    )
    .unwrap();
    assert_eq!(outcome, ExportOutcome::Finished { frames: 2 });
}

#[test]
fn bad_specs_are_errors_and_write_nothing() {
    let dir = tmpdir("spec");
    let scene = scene();
    let cases = [
        (spec(5..5, 24.0), "range is empty"),
        (spec(std::ops::Range { start: 6, end: 2 }, 24.0), "range is empty"),
        (spec(0..3, 0.0), "fps 0"),
        (spec(0..3, -24.0), "fps -24"),
        (spec(0..3, f32::NAN), "fps NaN"),
        (spec(0..3, f32::INFINITY), "fps inf"),
        (spec(0..u32::MAX, 1e-38), "too small"),
        (AnimationSpec { width: Some(0), ..spec(0..3, 24.0) }, "width 0"),
        (AnimationSpec { height: Some(20000), ..spec(0..3, 24.0) }, "height 20000"),
    ];
    for (s, needle) in cases {
        for path in [dir.join("a.gif"), dir.to_path_buf()] {
            let mut called = false;
            let r = export_animation(&scene, &mut CpuBackend::new(), &s, &path, &mut |_| {
                called = true;
                Control::Continue
            });
            match r {
                Err(e @ ExportError::Spec(_)) => {
                    assert!(e.to_string().contains(needle), "{e} lacks {needle}")
                }
                other => panic!("{s:?}: {other:?}"),
            }
            assert!(!called);
        }
    }
    assert!(listing(&dir).is_empty(), "{:?}", listing(&dir));
}

#[test]
fn sizes_past_the_scenes_limits_are_spec_errors_and_write_nothing() {
    let dir = tmpdir("sizes");
    let soft = Scene::load(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/soft-gradient.toml")).unwrap();
    let big = AnimationSpec { width: Some(4097), height: Some(4096), ..spec(0..2, 24.0) };
    let cases = [
        // An [area_light]'s image limit holds for sizes from the spec, on both formats.
        (&soft, big.clone(), dir.join("a.gif"), "at most 16777216 pixels"),
        (&soft, big.clone(), dir.to_path_buf(), "at most 16777216 pixels"),
        // A GIF frame's limit holds without one.
        (&scene(), big, dir.join("a.gif"), "a GIF frame is at most 16777216 pixels"),
    ];
    for (scene, s, path, needle) in cases {
        let mut called = false;
        let r = export_animation(scene, &mut CpuBackend::new(), &s, &path, &mut |_| {
            called = true;
            Control::Continue
        });
        match r {
            Err(e @ ExportError::Spec(_)) => assert!(e.to_string().contains(needle), "{e} lacks {needle}"),
            other => panic!("{}: {other:?}", path.display()),
        }
        assert!(!called, "{}: progress was called", path.display());
    }
    assert!(listing(&dir).is_empty(), "{:?}", listing(&dir));
}

#[test]
fn bad_paths_are_bad_path_errors_and_create_nothing() {
    let dir = tmpdir("paths");
    let scene = scene();
    let missing = dir.join("missing");
    let file = dir.join("a-file");
    std::fs::write(&file, b"x").unwrap();
    let cases = [
        (missing.join("fire.gif"), "does not exist"),
        (missing.join("deeper/"), "does not exist"),
        (PathBuf::from(format!("{}/", missing.display())), "does not exist"),
        (file.join("fire.gif"), "is a file"),
        (dir.join("fire.webm"), "unknown animation format"),
    ];
    for (path, needle) in cases {
        let r = export_animation(&scene, &mut CpuBackend::new(), &spec(0..2, 24.0), &path, &mut |_| {
            Control::Continue
        });
        match r {
            Err(ExportError::Output(OutputError::BadPath(m))) => {
                assert!(m.contains(needle), "{m} lacks {needle}")
            }
            other => panic!("{}: {other:?}", path.display()),
        }
    }
    assert!(!missing.exists());
    assert_eq!(listing(&dir), ["a-file"]);
}

#[test]
fn hadou_render_writes_a_gif_with_frames() {
    let dir = tmpdir("cli-gif");
    let out = dir.join("fire.gif");
    let scene_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/kamehameha.toml");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_hadou"))
        .args([
            "render",
            "--backend",
            "cpu",
            "--frames",
            "0..4",
            "--fps",
            "10",
            "--width",
            "48",
            "--height",
            "27",
            "-o",
        ])
        .arg(&out)
        .arg(&scene_path)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let g = decode_gif(&out);
    assert_eq!(g.frames.len(), 4);
    assert_eq!(g.size, (48, 27));
    assert_eq!(g.repeat, gif::Repeat::Infinite);
    assert_eq!(listing(&dir), vec!["fire.gif".to_string()], "no temporary file is left");
    // A GIF in a missing directory: exit 2, nothing created.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_hadou"))
        .args(["render", "--frames", "0..2", "-o"])
        .arg(dir.join("missing/fire.gif"))
        .arg(&scene_path)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(!dir.join("missing").exists());
}
