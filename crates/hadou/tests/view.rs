//! `hadou view` end to end: the viewer opens a window under Xvfb on the software adapter, runs a
//! script (edits, camera moves, a minimise, a backend switch, a save) and writes a screenshot,
//! which must equal what `hadou render` writes for the saved scene at the same time and size.
//!
//! Tolerance: with the CPU backend (the automatic choice on a software adapter) the screenshot is
//! the same renderer's output, so every 8-bit code must match exactly. With the GPU backend it is
//! the CPU↔GPU differential tolerance of the backends' own tests in 8-bit terms: at least 99.5 %
//! of the channel values within 2 codes and none more than 40 codes apart (edges where a
//! triangle's coverage flips between the rasterizers).
//!
//! Needs `xvfb-run` (`apt-get install xvfb`); without it the tests skip with a message, and
//! fail under `HADOU_REQUIRE_GPU=1` (CI).
mod common;

use common::Scratch;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn hadou() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hadou"))
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> Scratch {
    Scratch::new("view-e2e", name)
}

/// One Xvfb at a time: `xvfb-run -a` picks a free display number by looking for lock files, and
/// two started at once can pick the same one. The lock holds across processes too (an advisory
/// lock on a file in the temporary folder), since CI runs this binary on Vulkan and on OpenGL at
/// the same time.
struct XvfbLock {
    _file: Option<std::fs::File>,
    _guard: std::sync::MutexGuard<'static, ()>,
}

fn xvfb_lock() -> XvfbLock {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let guard = LOCK.lock().unwrap_or_else(|p| p.into_inner());
    let file = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(std::env::temp_dir().join("hadou-view-tests-xvfb.lock"))
        .ok()
        .filter(|f| f.lock().is_ok());
    XvfbLock { _file: file, _guard: guard }
}

/// `xvfb-run` when present; `None` (skip) otherwise, a failure in CI.
fn xvfb(test: &str) -> Option<Command> {
    xvfb_with(test, &[])
}

/// [`xvfb`] with `hadou` run through `wrapper` (a command line that ends by running its last
/// argument, `hadou`, with the arguments the caller adds).
fn xvfb_with(test: &str, wrapper: &[&str]) -> Option<Command> {
    let found =
        Command::new("sh").args(["-c", "command -v xvfb-run"]).output().is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var("HADOU_REQUIRE_GPU").map_or(true, |v| v != "1"),
            "{test}: xvfb-run is missing (apt-get install xvfb)"
        );
        eprintln!("SKIPPED {test}: xvfb-run is missing (apt-get install xvfb)");
        return None;
    }
    let mut c = Command::new("xvfb-run");
    c.args(["-a", "-s", "-screen 0 1600x1200x24"]).args(wrapper).arg(env!("CARGO_BIN_EXE_hadou"));
    Some(c)
}

fn run(mut c: Command) -> Output {
    let out = c.output().expect("runs");
    eprintln!("{}", String::from_utf8_lossy(&out.stderr));
    out
}

fn decode(path: &Path) -> (u32, u32, Vec<u8>) {
    let d = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut r = d.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size().unwrap()];
    let info = r.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// (max difference, fraction of values within 2 codes).
fn compare(a: &Path, b: &Path) -> (u8, f64) {
    let (wa, ha, pa) = decode(a);
    let (wb, hb, pb) = decode(b);
    assert_eq!((wa, ha), (wb, hb), "sizes differ");
    assert_eq!(pa.len(), pb.len());
    let diffs: Vec<u8> = pa.iter().zip(&pb).map(|(x, y)| x.abs_diff(*y)).collect();
    let max = diffs.iter().copied().max().unwrap_or(0);
    let close = diffs.iter().filter(|&&d| d <= 2).count() as f64 / diffs.len().max(1) as f64;
    (max, close)
}

fn render(scene: &Path, time: &str, out: &Path) {
    let o = run({
        let mut c = hadou();
        c.args(["render", "--backend", "cpu", "--time", time, "-o"]).arg(out).arg(scene);
        c
    });
    assert!(o.status.success());
}

#[test]
fn scripted_session_matches_render() {
    let _x = xvfb_lock();
    let Some(mut view) = xvfb("scripted_session_matches_render") else { return };
    let dir = tmp("script");
    let scene = dir.join("scene.toml");
    std::fs::copy(repo().join("scenes/fig4-2-bezier.toml"), &scene).unwrap();
    let script = dir.join("session.txt");
    std::fs::write(
        &script,
        "# an editing session\n\
         wait 2\n\
         time 0.4\n\
         set wave.bezier.alpha 0.08\n\
         orbit 15 5\n\
         zoom 0.9\n\
         wait 2\n\
         probe 100 100\n\
         resize 0 0\n\
         wait 3\n\
         resize 900 700\n\
         wait 2\n\
         backend gpu\n\
         wait 2\n\
         screenshot gpu.png\n\
         backend cpu\n\
         undo\n\
         redo\n\
         save edited.toml\n\
         export anim.gif 0..3 12\n\
         wait 2\n",
    )
    .unwrap();
    let shot = dir.join("shot.png");
    let o = run({
        view.arg("view")
            .arg(&scene)
            .arg("--script")
            .arg(&script)
            .arg("--screenshot")
            .arg(&shot)
            .arg("--stats");
        view
    });
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let saved = dir.join("edited.toml");
    let text = std::fs::read_to_string(&saved).unwrap();
    assert!(text.contains("alpha = 0.08"), "{text}");
    // The original file's comments survive.
    let original = std::fs::read_to_string(&scene).unwrap();
    let first_comment = original.lines().find(|l| l.starts_with('#')).unwrap();
    assert!(text.contains(first_comment));
    let reference = dir.join("reference.png");
    render(&saved, "0.4", &reference);
    let (max, _) = compare(&shot, &reference);
    assert_eq!(max, 0, "the CPU-backend screenshot must equal `hadou render` exactly");
    let (max, close) = compare(&dir.join("gpu.png"), &reference);
    assert!(close >= 0.995 && max <= 40, "GPU screenshot vs render: max {max}, within 2 codes {close}");
    // The export ran to the end before the script went on: three frames, no temporary file.
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut gif = options.read_info(std::fs::File::open(dir.join("anim.gif")).unwrap()).unwrap();
    let mut frames = 0;
    while gif.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    assert_eq!(frames, 3);
    let stray: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(stray.is_empty(), "{stray:?}");
    // --stats printed the figures.
    let stats = String::from_utf8_lossy(&o.stdout);
    assert!(stats.contains("\"median_image_overhead_ms\""), "{stats}");
}

#[test]
fn time_and_screenshot_without_script() {
    let _x = xvfb_lock();
    let Some(mut view) = xvfb("time_and_screenshot_without_script") else { return };
    let dir = tmp("time");
    let shot = dir.join("shot.png");
    let scene = repo().join("scenes/fig4-13-extension.toml");
    let o = run({
        view.arg("view").arg(&scene).args(["--time", "0.7", "--screenshot"]).arg(&shot);
        view
    });
    assert!(o.status.success());
    let reference = dir.join("reference.png");
    render(&scene, "0.7", &reference);
    assert_eq!(compare(&shot, &reference).0, 0);
    // A different time gives a different picture (the comparison can fail).
    let other = dir.join("other.png");
    render(&scene, "0", &other);
    assert!(compare(&shot, &other).0 > 0);
}

#[test]
fn bad_input_exits_2_with_positions() {
    let dir = tmp("bad");
    let scene = dir.join("bad.toml");
    std::fs::write(&scene, "[camera]\nfov = 500.0\n").unwrap();
    let o = run({
        let mut c = hadou();
        c.arg("view").arg(&scene);
        c
    });
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bad.toml:2:7:"), "{err}");
    // A bad script line: file:line:col, before any window opens.
    let script = dir.join("s.txt");
    std::fs::write(&script, "wait 1\nzoom -2\n").unwrap();
    let o = run({
        let mut c = hadou();
        c.arg("view").arg(repo().join("scenes/fig4-1-sphere.toml")).arg("--script").arg(&script);
        c
    });
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("s.txt:2:6: the zoom factor must be > 0"), "{err}");
    // A bad --time.
    let o = run({
        let mut c = hadou();
        c.arg("view").arg(repo().join("scenes/fig4-1-sphere.toml")).args(["--time", "-1"]);
        c
    });
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn no_display_names_the_variables_and_the_alternatives() {
    let o = run({
        let mut c = hadou();
        c.arg("view")
            .arg(repo().join("scenes/fig4-1-sphere.toml"))
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY");
        c
    });
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    for needle in ["DISPLAY", "WAYLAND_DISPLAY", "xvfb-run", "hadou render"] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
}

#[test]
fn a_failing_script_command_is_an_error() {
    let _x = xvfb_lock();
    if xvfb("a_failing_script_command_is_an_error").is_none() {
        return;
    }
    let dir = tmp("failing");
    // (script, what the message must name): an edit the loader refuses, and requests the window
    // carries out later (a screenshot to an unknown format, an export into a missing directory, a
    // screenshot asked for while minimised) must all stop the run with the line that asked.
    let cases = [
        ("wait 1\nset camera.fov 900\n", "s.txt:2:", "fov"),
        ("wait 1\nscreenshot shot.txt\nwait 2\n", "s.txt:2:", "shot.txt"),
        ("export missing/anim.gif 0..2 10\nwait 2\n", "s.txt:1:", "missing"),
        ("resize 0 0\nscreenshot shot.bmp\n", "s.txt:2:", "shot.bmp"),
        // A command naming a wave the scene lacks, whatever the command (`select` used to pass).
        ("wait 1\nselect nobody\n", "s.txt:2:8:", "no wave is named \"nobody\"; the waves are `sphere`"),
        ("fire nobody\n", "s.txt:1:6:", "no wave is named \"nobody\"; the waves are `sphere`"),
        ("set wave.nobody.alpha_s 1\n", "s.txt:1:5:", "`wave.nobody` is none of the scene's tables"),
    ];
    for (text, line, needle) in cases {
        let script = dir.join("s.txt");
        std::fs::write(&script, text).unwrap();
        let mut view = xvfb("a_failing_script_command_is_an_error").unwrap();
        let o = run({
            view.arg("view").arg(repo().join("scenes/fig4-1-sphere.toml")).arg("--script").arg(&script);
            view
        });
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{text}: {err}");
        assert!(err.contains(line) && err.contains(needle), "{text}: {err}");
    }
    // A screenshot asked for while minimised is still written before the run ends.
    let script = dir.join("s.txt");
    std::fs::write(&script, "resize 0 0\nscreenshot min.png\n").unwrap();
    let mut view = xvfb("a_failing_script_command_is_an_error").unwrap();
    let o = run({
        view.arg("view").arg(repo().join("scenes/fig4-1-sphere.toml")).arg("--script").arg(&script);
        view
    });
    assert!(o.status.success());
    assert!(dir.join("min.png").is_file());
    // A script that is not UTF-8 text: exit 2 naming the byte, before any window.
    std::fs::write(&script, b"wait 1\n\xff\n").unwrap();
    let o = run({
        let mut c = hadou();
        c.arg("view").arg(repo().join("scenes/fig4-1-sphere.toml")).arg("--script").arg(&script);
        c
    });
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("s.txt: the script is not UTF-8 text (byte 7)"));
}

/// The longest a scripted run that must end may take (a hang is killed and fails the test).
const HANG_LIMIT_S: &str = "180";

/// A script that switches from the CPU backend to the GPU backend while the CPU render thread has
/// a frame in flight ends (the worker used to stay marked busy, and the viewer spun forever).
#[test]
fn a_backend_switch_with_a_cpu_frame_in_flight_ends() {
    let _x = xvfb_lock();
    let test = "a_backend_switch_with_a_cpu_frame_in_flight_ends";
    if xvfb(test).is_none() {
        return;
    }
    let dir = tmp("switch");
    let script = dir.join("s.txt");
    for text in
        ["backend gpu\nquit\n", "backend gpu\nbackend cpu\nbackend gpu\nwait 2\n", "time 0.3\nbackend gpu\n"]
    {
        std::fs::write(&script, text).unwrap();
        let mut view = xvfb_with(test, &["timeout", "-s", "KILL", HANG_LIMIT_S]).unwrap();
        let o = run({
            view.arg("view")
                .arg(repo().join("scenes/fig4-13-extension.toml"))
                .args(["--backend", "cpu", "--stats", "--script"])
                .arg(&script);
            view
        });
        assert!(o.status.success(), "{text}: {:?} {}", o.status, String::from_utf8_lossy(&o.stderr));
        let stats: serde_json::Value = serde_json::from_slice(&o.stdout).expect("--stats prints JSON");
        assert_eq!(stats["backend"], "GPU", "{text}");
    }
}

/// `--stats` prints strict JSON when no image was timed (a static scene drawn once): a figure
/// without samples is `null`, never `NaN`.
#[test]
fn stats_without_timed_images_are_json() {
    let _x = xvfb_lock();
    let test = "stats_without_timed_images_are_json";
    let Some(mut view) = xvfb_with(test, &["timeout", "-s", "KILL", HANG_LIMIT_S]) else { return };
    let dir = tmp("stats");
    let script = dir.join("s.txt");
    std::fs::write(&script, "wait 3\n").unwrap();
    let o = run({
        view.arg("view")
            .arg(repo().join("scenes/fig4-1-sphere.toml"))
            .args(["--backend", "cpu", "--stats", "--script"])
            .arg(&script);
        view
    });
    assert!(o.status.success(), "{:?}", o.status);
    let text = String::from_utf8_lossy(&o.stdout);
    let stats: serde_json::Value =
        serde_json::from_str(text.trim()).unwrap_or_else(|e| panic!("{e}: {text}"));
    let frames = stats["frames"].as_u64().expect("frames");
    for key in ["median_frame_ms", "median_render_ms", "median_image_overhead_ms", "median_ui_ms"] {
        let v = &stats[key];
        assert!(v.is_null() || v.as_f64().is_some_and(f64::is_finite), "{key}: {text}");
        assert_eq!(v.is_null(), frames == 0, "{key}: {text}");
    }
}

/// A surface the device cannot configure (`resize 16384 16384`, the script's largest, under a
/// 4 GiB address-space cap: lavapipe's swapchain images do not fit) is reported with the script
/// line and exit 2, the surface kept at the last size that worked; it used to be configured
/// again every frame, forever, with no message. Vulkan only: OpenGL configures its surface lazily
/// and draws the huge window instead (slowly, but it ends).
#[test]
fn a_surface_that_cannot_be_configured_exits_2_with_the_line() {
    let test = "a_surface_that_cannot_be_configured_exits_2_with_the_line";
    if std::env::var("HADOU_EXPECT_BACKEND").is_ok_and(|b| b == "gl") {
        eprintln!("SKIPPED {test}: OpenGL configures surfaces lazily");
        return;
    }
    let _x = xvfb_lock();
    let wrapper =
        ["timeout", "-s", "KILL", HANG_LIMIT_S, "sh", "-c", "ulimit -v 4194304; exec \"$0\" \"$@\""];
    let Some(mut view) = xvfb_with(test, &wrapper) else { return };
    let dir = tmp("surface-oom");
    let script = dir.join("s.txt");
    std::fs::write(&script, "wait 1\nresize 16384 16384\nresize 0 0\n").unwrap();
    let o = run({
        view.arg("view").arg(repo().join("scenes/fig4-1-sphere.toml")).arg("--script").arg(&script);
        view
    });
    let err = String::from_utf8_lossy(&o.stderr);
    // Where the surface did fit after all the run ends normally; it must never hang or crash.
    if o.status.success() {
        eprintln!("{test}: the 16384² surface was configured under the cap here");
        return;
    }
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("s.txt:2:8: the window's surface cannot be configured at 16384×16384 pixels")
            && err.contains("it stays"),
        "{err}"
    );
}
