//! The render-farm contract (docs/farm.md): the Open Job Description template run by the real
//! `openjd` CLI gives the frames of one `hadou render` process byte for byte; a frame is the same
//! bytes on every vector path and in any chunk; progress lines, one-line errors naming the frame;
//! `--skip-existing` resumes (after a kill mid-frame too) and re-renders what it cannot trust;
//! frames carry the scene's hash and the version, and `hadou validate --frames` reports strays.

mod common;

use common::Scratch;
use hadou::export::{export_sequence, AnimationSpec, Control, SequenceNote, SequenceOptions};
use hadou::farm::{FramePattern, FrameStamp, SceneStamp};
use hadou::{Backend, CpuBackend, Frame, Image, RenderError, Rgb8Image, Scene};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const KAME: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/kamehameha.toml");
const TEMPLATE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../farm/hadou-sequence.yaml");
/// Every frame here is this small: the contract does not depend on the size.
const SIZE: [&str; 4] = ["--width", "64", "--height", "36"];

fn tmpdir(name: &str) -> Scratch {
    Scratch::new("farm", name)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn hadou(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hadou")).args(args).output().expect("binary runs")
}

/// `hadou render SCENE -o DIR/ --frames FRAMES` at 64×36 on the CPU, with `extra` flags and
/// `HADOU_SIMD=simd` when given.
fn render_frames(scene: &Path, dir: &Path, frames: &str, simd: Option<&str>, extra: &[&str]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_hadou"));
    if let Some(s) = simd {
        c.env("HADOU_SIMD", s);
    }
    c.arg("render").arg(scene).arg("-o").arg(format!("{}/", dir.display())).args([
        "--frames",
        frames,
        "--backend",
        "cpu",
    ]);
    // 64×36 and no progress unless `extra` says otherwise.
    for pair in SIZE.chunks(2).chain([&["--progress", "none"][..]]) {
        if !extra.contains(&pair[0]) {
            c.args(pair);
        }
    }
    c.args(extra).output().expect("binary runs")
}

fn ok(o: &Output) {
    assert_eq!(o.status.code(), Some(0), "stderr: {}\nstdout: {}", stderr(o), stdout(o));
}

fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    names
}

fn frame_names(range: std::ops::Range<u32>) -> Vec<String> {
    range.map(|f| FramePattern::default().name(f)).collect()
}

/// Every file of `a` equals, byte for byte, the file of the same name in `b`, and both hold the
/// same names.
fn assert_same_files(a: &Path, b: &Path, what: &str) {
    assert_eq!(listing(a), listing(b), "{what}");
    for name in listing(a) {
        assert!(
            std::fs::read(a.join(&name)).unwrap() == std::fs::read(b.join(&name)).unwrap(),
            "{what}: {name} differs"
        );
    }
}

/// A copy of the example scene (with the glTF file it names) at `dir/NAME`, its text with
/// `extra` appended: the same scene file or, with `extra`, an edited one.
fn copy_scene(dir: &Path, name: &str, extra: &str) -> PathBuf {
    std::fs::create_dir_all(dir.join("assets")).unwrap();
    let glb = Path::new(KAME).with_file_name("assets/crystal.glb");
    std::fs::copy(glb, dir.join("assets/crystal.glb")).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, std::fs::read_to_string(KAME).unwrap() + extra).unwrap();
    path
}

/// The error output is one line (`error: …`), whatever went wrong.
fn one_line_error(o: &Output) -> String {
    let e = stderr(o);
    let lines: Vec<&str> = e.lines().filter(|l| !l.starts_with("note:")).collect();
    assert_eq!(lines.len(), 1, "not one line: {e}");
    assert!(lines[0].starts_with("error: "), "{e}");
    lines[0].to_string()
}

/// The one `hadou render --frames 0..24` process every other way of rendering is held to.
fn reference(dir: &Path) -> PathBuf {
    let r = dir.join("reference");
    std::fs::create_dir(&r).unwrap();
    ok(&render_frames(Path::new(KAME), &r, "0..24", None, &[]));
    assert_eq!(listing(&r), frame_names(0..24));
    // The beam moves: frames differ, so equal files below mean the right frame at the right time.
    let read = |f: u32| std::fs::read(r.join(FramePattern::default().name(f))).unwrap();
    assert_ne!(read(0), read(12));
    assert_ne!(read(12), read(23));
    r
}

/// `openjd`, where it is installed: `HADOU_OPENJD` names it, else `openjd` on PATH. `None` skips
/// the template's test, unless `HADOU_REQUIRE_OPENJD=1` (set by `.ci/run`) makes that a failure.
fn openjd() -> Option<PathBuf> {
    let exe = std::env::var_os("HADOU_OPENJD").map_or_else(|| PathBuf::from("openjd"), PathBuf::from);
    let found = Command::new(&exe).arg("--version").output().is_ok_and(|o| o.status.success());
    if found {
        return Some(exe);
    }
    assert!(
        std::env::var("HADOU_REQUIRE_OPENJD").as_deref() != Ok("1"),
        "HADOU_REQUIRE_OPENJD=1 but `{}` does not run; install it with `pip install openjd-cli`",
        exe.display()
    );
    eprintln!(
        "SKIPPED: no `openjd` (pip install openjd-cli) on PATH; set HADOU_REQUIRE_OPENJD=1 to fail instead"
    );
    None
}

/// `openjd run` of the template with the test's parameters and `params` over them.
fn openjd_run(openjd: &Path, scene: &Path, out: &Path, params: &[&str]) -> Output {
    let mut c = Command::new(openjd);
    c.args(["run", TEMPLATE, "--extensions", "TASK_CHUNKING"])
        .arg("-p")
        .arg(format!("SceneFile={}", scene.display()))
        .arg("-p")
        .arg(format!("OutputDir={}", out.display()))
        .arg("-p")
        .arg(format!("Hadou={}", env!("CARGO_BIN_EXE_hadou")));
    for p in ["FrameEnd=23", "ChunkSize=5", "Width=64", "Height=36", "Backend=cpu"] {
        c.args(["-p", p]);
    }
    for p in params {
        c.args(["-p", p]);
    }
    c.output().expect("openjd runs")
}

/// The template, run for real by `openjd run`: five chunks of 5, 5, 5, 5 and 4 frames, each a
/// `hadou render` process, write the 24 frames of one `hadou render --frames 0..24` process, byte
/// for byte; a task's progress comes through as Open Job Description reads it. Parameters out of
/// range and a scene that fails to load fail the job, leaving nothing written.
#[test]
fn the_template_run_by_openjd_gives_the_frames_of_one_process() {
    let Some(openjd) = openjd() else { return };
    let dir = tmpdir("openjd");
    let reference = reference(&dir);
    let out = dir.join("farm");
    std::fs::create_dir(&out).unwrap();
    let o = openjd_run(&openjd, Path::new(KAME), &out, &[]);
    let log = format!("{}{}", stdout(&o), stderr(&o));
    assert!(o.status.success(), "{log}");
    assert_same_files(&out, &reference, "openjd run of farm/hadou-sequence.yaml");
    // One hadou process per chunk: each reports its own progress up to 100 %.
    for chunk in ["0-4", "5-9", "10-14", "15-19", "20-23"] {
        assert!(log.contains(&format!("Frames(CHUNK[INT]) = {chunk}\n")), "no task for chunk {chunk}: {log}");
    }
    assert_eq!(log.matches("openjd_progress: 100.0").count(), 5, "{log}");
    assert!(log.contains("openjd_progress: 20.0") && log.contains("openjd_progress: 25.0"), "{log}");

    // Run again: every task keeps its frames (--skip-existing), the files are untouched.
    let o = openjd_run(&openjd, Path::new(KAME), &out, &[]);
    let log = format!("{}{}", stdout(&o), stderr(&o));
    assert!(o.status.success(), "{log}");
    assert_eq!(log.matches("wrote 0 frames").count(), 5, "{log}");
    assert_same_files(&out, &reference, "openjd run again");

    // Bad parameters: refused before any task runs.
    let empty = dir.join("empty");
    std::fs::create_dir(&empty).unwrap();
    for (params, needle) in [
        (&["FrameStart=10", "FrameEnd=5"][..], "descending range"),
        (&["ChunkSize=0"][..], "ChunkSize must be at least 1"),
        (&["Width=-64"][..], "Width must be at least 1"),
        (&["Samples=3"][..], "Samples"),
        (&["Backend=auto"][..], "Backend"),
    ] {
        let o = openjd_run(&openjd, Path::new(KAME), &empty, params);
        let log = format!("{}{}", stdout(&o), stderr(&o));
        assert!(!o.status.success(), "{params:?}: {log}");
        assert!(log.contains(needle), "{params:?}: {log}");
        assert!(listing(&empty).is_empty(), "{params:?}");
    }
    // A scene that fails to load on the node: the task fails with hadou's one line, exit 2.
    let broken = dir.join("broken.toml");
    std::fs::write(&broken, "[image]\nwidth = 0\n").unwrap();
    let o = openjd_run(&openjd, &broken, &empty, &[]);
    let log = format!("{}{}", stdout(&o), stderr(&o));
    assert!(!o.status.success(), "{log}");
    assert!(log.contains("broken.toml:2:") && log.contains("exited with code: 2"), "{log}");
    assert!(listing(&empty).is_empty());
    // A missing output folder, the same.
    let o = openjd_run(&openjd, Path::new(KAME), &dir.join("missing"), &[]);
    let log = format!("{}{}", stdout(&o), stderr(&o));
    assert!(!o.status.success() && log.contains("does not exist"), "{log}");
    assert!(!dir.join("missing").exists());
}

/// A frame is a pure function of the scene file and its number: rendered in chunks whose
/// boundaries fall anywhere, in any order, by a process on any CPU vector path, each frame is the
/// bytes of the one-process reference.
#[test]
fn every_vector_path_and_every_chunking_gives_the_same_bytes() {
    let dir = tmpdir("pure");
    let reference = reference(&dir);
    let supported = hadou_math::simd::SimdPath::supported();
    eprintln!("vector paths: {supported:?}");
    let chunkings: [&[&str]; 3] = [&["0..24"], &["20..24", "7..20", "0..7"], &["0..=0", "1-13", "14..24"]];
    for path in &supported {
        for (k, chunks) in chunkings.iter().enumerate() {
            let out = dir.join(format!("{}-{k}", path.name()));
            std::fs::create_dir(&out).unwrap();
            for chunk in chunks.iter() {
                ok(&render_frames(Path::new(KAME), &out, chunk, Some(path.name()), &[]));
            }
            assert_same_files(&out, &reference, &format!("{path}, chunks {chunks:?}"));
        }
    }
    // Nor does the number of threads a node gives the process change a byte.
    for threads in ["1", "3"] {
        let out = dir.join(format!("threads-{threads}"));
        std::fs::create_dir(&out).unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_hadou"))
            .env("RAYON_NUM_THREADS", threads)
            .arg("render")
            .arg(KAME)
            .arg("-o")
            .arg(format!("{}/", out.display()))
            .args(["--frames", "5..24", "--backend", "cpu", "--progress", "none"])
            .args(SIZE)
            .output()
            .unwrap();
        ok(&o);
        ok(&render_frames(Path::new(KAME), &out, "0..5", None, &[]));
        assert_same_files(&out, &reference, &format!("{threads} threads"));
    }
}

/// `--progress openjd` prints `openjd_progress: PERCENT` on stdout after each frame (and 0 at the
/// start), nothing else there; `none` prints nothing; the default bar never writes to stdout.
#[test]
fn progress_lines_for_open_job_description() {
    let dir = tmpdir("progress");
    let o = render_frames(Path::new(KAME), &dir, "0..4", None, &["--progress", "openjd"]);
    ok(&o);
    let lines: Vec<String> = stdout(&o).lines().map(String::from).collect();
    assert_eq!(lines, ["0.0", "25.0", "50.0", "75.0", "100.0"].map(|p| format!("openjd_progress: {p}")));
    let o = render_frames(Path::new(KAME), &dir, "0..4", None, &["--progress", "none"]);
    ok(&o);
    assert!(o.stdout.is_empty());
    assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
    let o = render_frames(Path::new(KAME), &dir, "0..4", None, &["--progress", "loud"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(one_line_error(&o).contains("--progress"), "{}", stderr(&o));
}

/// A backend that fails on one frame (by its time), as a node's device might.
struct FailingAt {
    inner: CpuBackend,
    time: f32,
}

impl Backend for FailingAt {
    fn name(&self) -> &str {
        "cpu"
    }
    fn render(&mut self, frame: &Frame) -> Result<Image, RenderError> {
        self.inner.render(frame)
    }
    fn render_rows_rgb8(
        &mut self,
        frame: &Frame,
        rows: std::ops::Range<u32>,
    ) -> Result<Rgb8Image, RenderError> {
        if frame.time == self.time {
            return Err(RenderError::Device("the device was lost".into()));
        }
        self.inner.render_rows_rgb8(frame, rows)
    }
}

/// A failure part-way through a chunk names its frame; the frames before it stay whole, the
/// failed one leaves nothing, and a run again with skip-existing completes the chunk.
#[test]
fn a_failing_frame_is_named_and_leaves_nothing_half_written() {
    let dir = tmpdir("failing");
    let scene = Scene::load(KAME).unwrap();
    let spec = AnimationSpec { frames: 2..7, fps: 24.0, width: Some(64), height: Some(36), samples: None };
    let options = SequenceOptions {
        pattern: FramePattern::default(),
        stamp: Some(SceneStamp::of_text(&std::fs::read_to_string(KAME).unwrap())),
        skip_existing: true,
    };
    let mut backend = FailingAt { inner: CpuBackend::new(), time: 4.0 / 24.0 };
    let e =
        export_sequence(&scene, &mut backend, &spec, &dir, &options, &mut |_| Control::Continue, &mut |_| {})
            .unwrap_err();
    assert_eq!(e.frame, Some(4));
    assert_eq!(e.to_string(), "frame 4: render failed: device error: the device was lost");
    assert_eq!(listing(&dir), frame_names(2..4), "no temporary or partial file");
    let mut notes = Vec::new();
    export_sequence(
        &scene,
        &mut CpuBackend::new(),
        &spec,
        &dir,
        &options,
        &mut |_| Control::Continue,
        &mut |n| notes.push(n),
    )
    .unwrap();
    assert_eq!(notes, [SequenceNote::Kept(2), SequenceNote::Kept(3)]);
    assert_eq!(listing(&dir), frame_names(2..7));
}

/// The stamp of a frame as the test reads it back.
fn stamp_of(path: &Path) -> FrameStamp {
    hadou::farm::read_png_frame(path).unwrap().stamp.expect("stamped")
}

/// Rewrites the PNG at `path` with its pixels and `text` as its only `tEXt` chunks.
fn rewrite_png(path: &Path, text: &[(String, String)]) {
    let (w, h, rgb) = common::decode_png(path);
    let mut bytes = Vec::new();
    let mut enc = png::Encoder::new(&mut bytes, w, h);
    enc.set_color(png::ColorType::Rgb);
    for (k, v) in text {
        enc.add_text_chunk(k.clone(), v.clone()).unwrap();
    }
    let mut writer = enc.write_header().unwrap();
    writer.write_image_data(&rgb).unwrap();
    writer.finish().unwrap();
    std::fs::write(path, bytes).unwrap();
}

#[cfg(unix)]
fn inode(path: &Path) -> u64 {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(path).unwrap().ino()
}

/// `--skip-existing` keeps the complete frames of this job (the same file, not rewritten) and
/// renders the rest: a missing frame, a truncated one, a PNG hadou did not stamp, a frame of
/// another scene, version or size, and a directory's worth of junk are each rendered again
/// (with a note naming the frame and why), never trusted. The result is the reference, byte for
/// byte.
#[cfg(unix)]
#[test]
fn skip_existing_keeps_complete_frames_and_replaces_the_rest() {
    let dir = tmpdir("skip");
    let reference = reference(&dir);
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    ok(&render_frames(Path::new(KAME), &out, "0..10", None, &[]));
    let path = |f: u32| out.join(FramePattern::default().name(f));
    // 1: gone. 2: truncated (as a copy by hand might leave it). 3: a PNG without a stamp.
    // 4: another version's. 5: another scene's. 6: another size's. 7: not a PNG at all.
    std::fs::remove_file(path(1)).unwrap();
    let bytes = std::fs::read(path(2)).unwrap();
    std::fs::write(path(2), &bytes[..bytes.len() / 2]).unwrap();
    rewrite_png(&path(3), &[]);
    let mut old = stamp_of(&path(4));
    old.scene.version = "0.0.1".into();
    rewrite_png(&path(4), &old.text_chunks());
    let edited = copy_scene(&dir, "edited.toml", "\n# edited\n");
    let other = dir.join("other");
    std::fs::create_dir(&other).unwrap();
    ok(&render_frames(&edited, &other, "5..6", None, &[]));
    std::fs::copy(other.join(FramePattern::default().name(5)), path(5)).unwrap();
    ok(&render_frames(Path::new(KAME), &other, "6..7", None, &["--width", "32"]));
    std::fs::copy(other.join(FramePattern::default().name(6)), path(6)).unwrap();
    std::fs::write(path(7), b"not a png").unwrap();
    let kept: Vec<u64> = [0, 8, 9].map(|f| inode(&path(f))).to_vec();

    let o = render_frames(Path::new(KAME), &out, "0..24", None, &["--skip-existing"]);
    ok(&o);
    let e = stderr(&o);
    for (f, why) in [
        (2, "truncated or corrupt PNG"),
        (3, "no hadou stamp"),
        (4, "hadou 0.0.1, not"),
        (5, "another scene file"),
        (6, "32x36, not 64x36"),
        (7, "not a readable PNG"),
    ] {
        let line =
            e.lines().find(|l| l.starts_with(&format!("note: frame {f}: "))).unwrap_or_else(|| panic!("{e}"));
        assert!(line.contains(why), "frame {f}: {line}");
    }
    assert!(!e.contains("note: frame 1:") && !e.contains("note: frame 0:"), "{e}");
    assert!(e.contains("wrote 21 frames") && e.contains("3 kept as they were, 6 replaced"), "{e}");
    assert_eq!([0, 8, 9].map(|f| inode(&path(f))).to_vec(), kept, "a kept frame was rewritten");
    assert_same_files(&out, &reference, "resumed with --skip-existing");
}

/// A chunk killed mid-frame — by SIGTERM (its handler removes the partial frame) or SIGKILL (a
/// stray temporary file stays; it is never mistaken for a frame) — and run again with
/// `--skip-existing` completes the sequence identically.
#[cfg(unix)]
#[test]
fn a_chunk_killed_mid_frame_and_run_again_completes_identically() {
    let dir = tmpdir("killed");
    // Frames large enough to be caught mid-frame.
    let big = ["--width", "1280", "--height", "720", "--samples", "16"];
    let reference = dir.join("reference");
    std::fs::create_dir(&reference).unwrap();
    ok(&render_frames(Path::new(KAME), &reference, "0..4", None, &big));
    for signal in ["-TERM", "-KILL"] {
        let out = dir.join(signal.trim_start_matches('-'));
        std::fs::create_dir(&out).unwrap();
        let mut child = Command::new(env!("CARGO_BIN_EXE_hadou"))
            .arg("render")
            .arg(KAME)
            .arg("-o")
            .arg(format!("{}/", out.display()))
            .args(["--frames", "0..4", "--backend", "cpu", "--progress", "none", "--skip-existing"])
            .args(big)
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // Once a frame is finished and the next one's temporary file has been there 100 ms.
        let state = || {
            let names = listing(&out);
            (names.iter().filter(|n| n.ends_with(".png")).count(), names.iter().any(|n| n.ends_with(".tmp")))
        };
        let start = std::time::Instant::now();
        loop {
            let (done, writing) = state();
            if done >= 1 && writing {
                std::thread::sleep(std::time::Duration::from_millis(100));
                if state().1 {
                    break;
                }
            }
            assert!(child.try_wait().unwrap().is_none(), "{signal}: finished before it could be killed");
            assert!(start.elapsed().as_secs() < 120, "{signal}: no frame after 120 s");
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        assert!(Command::new("kill").args([signal, &child.id().to_string()]).status().unwrap().success());
        child.wait().unwrap();
        let (done, stray) = state();
        assert!((1..4).contains(&done), "{signal}: {:?}", listing(&out));
        // SIGTERM's handler removes the partial frame; SIGKILL leaves it (unless it struck in the
        // instant between one frame's rename and the next one's temporary file).
        assert!(signal == "-KILL" || !stray, "{signal}: {:?}", listing(&out));
        if stray {
            // validate names the stray partial file of the killed writer (and the missing frames).
            let o = hadou(&["validate", KAME, "--frames", out.to_str().unwrap()]);
            assert_eq!(o.status.code(), Some(2), "{}", stdout(&o));
            assert!(
                stdout(&o).contains("a partial frame left by a writer that was killed"),
                "{}",
                stdout(&o)
            );
        }
        let o =
            render_frames(Path::new(KAME), &out, "0..4", None, &[&big[..], &["--skip-existing"]].concat());
        ok(&o);
        assert!(stderr(&o).contains(&format!("{done} kept as they were, 0 replaced")), "{}", stderr(&o));
        let frames: Vec<String> = listing(&out).into_iter().filter(|n| n.ends_with(".png")).collect();
        assert_eq!(frames, frame_names(0..4));
        for name in frames {
            assert!(
                std::fs::read(out.join(&name)).unwrap() == std::fs::read(reference.join(&name)).unwrap(),
                "{signal}: {name}"
            );
        }
    }
}

/// A frame that cannot be written part-way through a chunk (a directory appeared at its path
/// after the chunk started) fails the process with one line naming the frame, exit 2; the frames
/// before it are whole and no partial file is left.
#[cfg(unix)]
#[test]
fn a_frame_failing_mid_chunk_is_named_in_one_line() {
    let dir = tmpdir("mid-chunk");
    let mut child = Command::new(env!("CARGO_BIN_EXE_hadou"))
        .arg("render")
        .arg(KAME)
        .arg("-o")
        .arg(format!("{}/", dir.display()))
        .args(["--frames", "0..6", "--backend", "cpu", "--progress", "none", "--skip-existing"])
        .args(["--width", "1280", "--height", "720", "--samples", "16"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while !dir.join("frame_00000.png").exists() {
        assert!(child.try_wait().unwrap().is_none(), "finished before frame 0 was seen");
        assert!(start.elapsed().as_secs() < 120, "no frame after 120 s");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    std::fs::create_dir(dir.join("frame_00004.png")).unwrap();
    let o = child.wait_with_output().unwrap();
    // A path a frame cannot take is the user's to fix: exit 2, as the same directory found before
    // the first frame is.
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let line = one_line_error(&o);
    assert!(
        line.starts_with("error: frame 4: ")
            && line.ends_with("frame_00004.png: is a directory; give a file name"),
        "{line}"
    );
    let mut expected = frame_names(0..4);
    expected.push("frame_00004.png".into());
    assert_eq!(listing(&dir), expected, "frames 0–3 whole, nothing partial");
    assert!(dir.join("frame_00004.png").is_dir());
}

/// Every frame (a sequence's, a single PNG's, an EXR's) carries the scene file's BLAKE3 hash and
/// the hadou version; a scene edited between chunks is caught by `hadou validate --frames`, with
/// or without the scene given, and so are another version's frames, an unstamped file and a gap.
#[test]
fn frames_carry_their_scene_and_validate_catches_a_changed_scene() {
    let dir = tmpdir("validate");
    let scene = copy_scene(&dir, "shot.toml", "");
    let text = std::fs::read_to_string(KAME).unwrap();
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    ok(&render_frames(&scene, &out, "0..5", None, &[]));
    let expected = SceneStamp::of_text(&text);
    let s = stamp_of(&out.join("frame_00003.png"));
    assert_eq!(s.scene, expected);
    assert_eq!(s.scene.version, env!("CARGO_PKG_VERSION"));
    assert_eq!(s.frame, Some(3));
    assert_eq!(s.settings, "64x36, 4 samples, t=3/24, cpu backend");
    let o = hadou(&["validate", scene.to_str().unwrap(), "--frames", out.to_str().unwrap()]);
    ok(&o);
    assert!(stdout(&o).contains("5 frames (frames 0..=4), all complete"), "{}", stdout(&o));

    // The scene is edited between chunks: the next chunk's frames are of another scene.
    std::fs::write(&scene, text.replace("[image]", "# a new take\n[image]")).unwrap();
    ok(&render_frames(&scene, &out, "5..8", None, &[]));
    let o = hadou(&["validate", scene.to_str().unwrap(), "--frames", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stdout(&o));
    let report = stdout(&o);
    for f in 0..5 {
        assert!(report.contains(&format!("frame_{f:05}.png: from another scene file")), "{report}");
    }
    assert!(!report.contains("frame_00005.png"), "{report}");
    assert!(one_line_error(&o).contains("5 problem(s) in 8 frames"), "{}", stderr(&o));
    // Without the scene, the frames in the minority are named.
    let o = hadou(&["validate", "--frames", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let report = stdout(&o);
    assert!(
        report.contains("frame_00005.png: from another scene file") && report.contains("most frames'"),
        "{report}"
    );
    assert!(!report.contains("frame_00000.png"), "{report}");

    // Another version, an unstamped file, a truncated file and a gap.
    let clean = dir.join("clean");
    std::fs::create_dir(&clean).unwrap();
    ok(&render_frames(Path::new(KAME), &clean, "0..8", None, &[]));
    let mut old = stamp_of(&clean.join("frame_00001.png"));
    old.scene.version = "0.0.1".into();
    rewrite_png(&clean.join("frame_00001.png"), &old.text_chunks());
    rewrite_png(&clean.join("frame_00002.png"), &[]);
    let bytes = std::fs::read(clean.join("frame_00006.png")).unwrap();
    std::fs::write(clean.join("frame_00006.png"), &bytes[..bytes.len() - 20]).unwrap();
    std::fs::remove_file(clean.join("frame_00004.png")).unwrap();
    // The partial frame a SIGKILL leaves behind, and a stranger's hidden file, not a frame's.
    std::fs::write(clean.join(".frame_00004.png.4242.0.tmp"), b"\x89PNG").unwrap();
    std::fs::write(clean.join(".notes.tmp"), b"").unwrap();
    let o = hadou(&["validate", "--frames", clean.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let report = stdout(&o);
    let expect = [
        "frame_00001.png: drawn by hadou 0.0.1",
        "frame_00002.png: no hadou stamp",
        "frame 4 is missing (the sequence has frames 0..=7)",
        "frame_00006.png: truncated or corrupt PNG",
        ".frame_00004.png.4242.0.tmp: a partial frame left by a writer that was killed",
    ];
    for needle in expect {
        assert!(report.contains(needle), "{needle}: {report}");
    }
    assert_eq!(report.lines().count(), 5, "{report}");

    // A single PNG and an EXR carry the stamp too.
    let png_path = dir.join("one.png");
    ok(&hadou(&[
        "render",
        KAME,
        "-o",
        png_path.to_str().unwrap(),
        "--time",
        "0.5",
        "--backend",
        "cpu",
        "--width",
        "16",
        "--height",
        "9",
    ]));
    let s = stamp_of(&png_path);
    assert_eq!(
        (s.scene, s.frame, s.settings.as_str()),
        (SceneStamp::of_text(&text), None, "16x9, 4 samples, t=0.5 s, cpu backend")
    );
    let exr_path = dir.join("one.exr");
    ok(&hadou(&[
        "render",
        KAME,
        "-o",
        exr_path.to_str().unwrap(),
        "--time",
        "0.5",
        "--backend",
        "cpu",
        "--width",
        "16",
        "--height",
        "9",
    ]));
    let meta = exr::meta::MetaData::read_from_file(&exr_path, false).unwrap();
    let attrs = &meta.headers[0].own_attributes.other;
    let stamp = match attrs.get(&exr::meta::attribute::Text::from(hadou::output::EXR_TEXT_ATTRIBUTE)) {
        Some(exr::meta::attribute::AttributeValue::Text(t)) => t.to_string(),
        other => panic!("{other:?}"),
    };
    let pairs: Vec<(&str, &str)> = stamp.lines().filter_map(|l| l.split_once('=')).collect();
    let s = FrameStamp::from_text_chunks(pairs).expect("a stamp");
    assert_eq!(s.scene, SceneStamp::of_text(&text));
    assert_eq!(s.settings, "16x9, 4 samples, t=0.5 s, cpu backend");
}

/// Bad input for a farm job: each is exit 2 with one line naming the problem, and writes nothing.
#[test]
fn bad_farm_input_is_one_line_and_writes_nothing() {
    let dir = tmpdir("bad");
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    let broken = dir.join("broken.toml");
    std::fs::write(&broken, "[image]\nwidth = -64\n").unwrap();
    let missing = dir.join("missing");
    let file = dir.join("a-file");
    std::fs::write(&file, b"x").unwrap();
    let o_dir = format!("{}/", out.display());
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec!["--frames".into(), "9-3".into()], "the range is empty"),
        (vec!["--frames".into(), "5..5".into()], "the range is empty"),
        (vec!["--frames".into(), "-3..5".into()], "expected a range"),
        (vec!["--frames".into(), "0..4".into(), "--width".into(), "-64".into()], "--width -64"),
        (vec!["--frames".into(), "0..4".into(), "--width".into(), "0".into()], "--width 0"),
        (vec!["--frames".into(), "0..4".into(), "--frame-name".into(), "x/f_#.png".into()], "--frame-name"),
        (vec!["--frames".into(), "0..4".into(), "--frame-name".into(), "f.png".into()], "has no `#`"),
        (vec!["--skip-existing".into()], "applies to a PNG sequence"),
    ];
    for (extra, needle) in cases {
        let o = Command::new(env!("CARGO_BIN_EXE_hadou"))
            .args(["render", KAME, "-o", &o_dir, "--backend", "cpu"])
            .args(&extra)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(one_line_error(&o).contains(needle), "{extra:?}: {}", stderr(&o));
        assert!(listing(&out).is_empty(), "{extra:?}");
    }
    // A scene that fails to load, a missing output folder, a file in the way.
    let o = render_frames(&broken, &out, "0..4", None, &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(one_line_error(&o).contains("broken.toml:2:"), "{}", stderr(&o));
    for (target, needle) in [(missing.clone(), "does not exist"), (file.join("sub"), "is a file")] {
        let o = render_frames(Path::new(KAME), &target, "0..4", None, &[]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(one_line_error(&o).contains(needle), "{}", stderr(&o));
    }
    assert!(!missing.exists());
    // An unwritable folder (meaningless for root, who writes anywhere).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let locked = dir.join("locked");
        std::fs::create_dir(&locked).unwrap();
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
        if std::fs::write(locked.join("probe"), b"").is_err() {
            let o = render_frames(Path::new(KAME), &locked, "0..4", None, &[]);
            assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
            assert!(one_line_error(&o).contains("cannot create files"), "{}", stderr(&o));
            assert!(listing(&locked).is_empty());
        } else {
            eprintln!("this user writes into a 0555 folder (root): /sys stands for an unwritable one");
        }
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o755)).unwrap();
        // A folder no one writes into, root included (sysfs), where Linux has one.
        if Path::new("/sys/kernel").is_dir() {
            let o = render_frames(Path::new(KAME), Path::new("/sys"), "0..4", None, &[]);
            assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
            assert!(one_line_error(&o).contains("cannot create files in `/sys`"), "{}", stderr(&o));
        }
    }
    // validate with neither a scene nor frames names what is missing.
    let o = hadou(&["validate"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(one_line_error(&o).contains("missing <SCENE>"), "{}", stderr(&o));
    // validate --frames on what is not a sequence.
    for (target, needle) in
        [(missing.as_path(), "does not exist"), (out.as_path(), "no frames named frame_#####.png")]
    {
        let o = hadou(&["validate", "--frames", target.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2));
        assert!(one_line_error(&o).contains(needle), "{}", stderr(&o));
    }
}

/// `--frame-name` names the frames; `--skip-existing` and `validate` read the same names.
#[test]
fn a_frame_name_pattern_names_the_frames() {
    let dir = tmpdir("pattern");
    ok(&render_frames(Path::new(KAME), &dir, "8-11", None, &["--frame-name", "shot.###.png"]));
    assert_eq!(listing(&dir), ["shot.008.png", "shot.009.png", "shot.010.png", "shot.011.png"]);
    let o = render_frames(
        Path::new(KAME),
        &dir,
        "8..12",
        None,
        &["--frame-name", "shot.###.png", "--skip-existing"],
    );
    ok(&o);
    assert!(stderr(&o).contains("wrote 0 frames") && stderr(&o).contains("4 kept"), "{}", stderr(&o));
    let o = hadou(&["validate", "--frames", dir.to_str().unwrap(), "--frame-name", "shot.###.png"]);
    ok(&o);
    assert!(stdout(&o).contains("4 frames (frames 8..=11)"), "{}", stdout(&o));
}
