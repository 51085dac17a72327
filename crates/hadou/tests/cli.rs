//! The `hadou` binary end to end: every bad-input class exits 2 with a `file:line:col` message and
//! writes nothing; good input renders, probes and validates.

mod common;

use common::Scratch;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn hadou(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hadou")).args(args).output().expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn tmpdir(name: &str) -> Scratch {
    Scratch::new("cli", name)
}

const GOOD: &str = r#"[image]
width = 64
height = 48

[camera]
position = [0.0, 0.0, 40.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 45.0
near = 0.1
far = 100.0

[[object]]
name = "cube"
kind = "box"
size = [6.0, 6.0, 6.0]
position = [0.0, 0.0, -20.0]

[[wave]]
name = "beam"
kind = "beam"
M = [-10.0, 0.0, 0.0]
M2 = [10.0, 0.0, 0.0]
alpha_s = 2.0
alpha_c = 2.0
head_alpha = 4.0
muzzle_alpha = 1.0
rgba = [0.8, 0.8, 0.2, 1.0]
"#;

fn write_scene(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("scene.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// Runs `validate` and `render` on a broken scene: both exit 2 with `scene.toml:LINE:COL:` and
/// a message containing `needle`; no output file appears.
fn assert_rejected(name: &str, text: &str, line: usize, needle: &str) {
    let dir = tmpdir(name);
    let scene = write_scene(&dir, text);
    let s = scene.to_str().unwrap();
    let out = dir.join("out.png");
    for o in [hadou(&["validate", s]), hadou(&["render", s, "-o", out.to_str().unwrap()])] {
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{name}: {e}");
        let loc = format!("scene.toml:{line}:");
        assert!(e.contains(&loc), "{name}: expected {loc} in: {e}");
        assert!(e.contains(needle), "{name}: expected `{needle}` in: {e}");
        assert!(!e.contains("panicked"), "{e}");
    }
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "{name}: output written");
}

#[test]
fn the_good_scene_validates_renders_png_and_exr_and_probes() {
    let dir = tmpdir("good");
    let scene = write_scene(&dir, GOOD);
    let s = scene.to_str().unwrap();
    assert_eq!(hadou(&["validate", s]).status.code(), Some(0));

    let png = dir.join("a.png");
    let o = hadou(&["render", s, "-o", png.to_str().unwrap(), "--width", "40", "--height", "30"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let reader = decoder.read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (40, 30));

    let exr = dir.join("a.exr");
    let o = hadou(&["render", s, "-o", exr.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let img = exr::prelude::read_all_flat_layers_from_file(&exr).unwrap();
    let names: Vec<String> = img.layer_data[0].channel_data.list.iter().map(|c| c.name.to_string()).collect();
    for n in ["R", "G", "B", "A", "energy", "depth"] {
        assert!(names.iter().any(|m| m == n), "{names:?}");
    }
    // No temporary files are left behind.
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left.len(), 3, "{left:?}");

    // Probe the beam's centre: positive energy from the one wave, the cube behind it.
    let o = hadou(&["probe", s, "--pixel", "32,24"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["waves"][0]["name"], "beam");
    assert!(j["waves"][0]["energy"].as_f64().unwrap() > 0.0);
    assert_eq!(j["color"].as_array().unwrap().len(), 4);
    assert_eq!(j["object"], "cube");
    let depth = j["depth"].as_f64().unwrap();
    assert!((depth - 57.0).abs() < 0.1, "{depth}");
}

#[test]
fn a_frame_sequence_writes_numbered_pngs() {
    let dir = tmpdir("seq");
    let scene = write_scene(&dir, GOOD);
    let outdir = dir.join("frames");
    std::fs::create_dir(&outdir).unwrap();
    let o = hadou(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        outdir.to_str().unwrap(),
        "--frames",
        "2..=4",
        "--fps",
        "12",
        "--width",
        "16",
        "--height",
        "16",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let mut names: Vec<String> =
        std::fs::read_dir(&outdir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    assert_eq!(names, ["frame_00002.png", "frame_00003.png", "frame_00004.png"]);
}

#[test]
fn malformed_toml_is_located() {
    assert_rejected("malformed", &GOOD.replace("fov = 45.0", "fov = = 45.0"), 9, "");
}

#[test]
fn unknown_keys_suggest_the_nearest() {
    assert_rejected("unknown", &GOOD.replace("alpha_c = 2.0", "alpah_c = 2.0"), 25, "alpha_c");
}

#[test]
fn wrong_types_are_located() {
    assert_rejected("type", &GOOD.replace("alpha_s = 2.0", "alpha_s = \"big\""), 24, "alpha_s");
}

#[test]
fn non_finite_and_negative_values_are_rejected() {
    assert_rejected("nan", &GOOD.replace("alpha_s = 2.0", "alpha_s = nan"), 24, "alpha_s");
    assert_rejected("inf", &GOOD.replace("M2 = [10.0, 0.0, 0.0]", "M2 = [inf, 0.0, 0.0]"), 23, "M2");
    assert_rejected("negative", &GOOD.replace("head_alpha = 4.0", "head_alpha = -4.0"), 26, "head_alpha");
}

#[test]
fn zero_length_vectors_are_rejected() {
    assert_rejected("zero-up", &GOOD.replace("up = [0.0, 1.0, 0.0]", "up = [0.0, 0.0, 0.0]"), 8, "up");
}

#[test]
fn bad_shadows_are_exit_2_with_their_line() {
    // GOOD has 28 lines; the `[[shadow]]` header is line 30.
    let shadow = |body: &str| format!("{GOOD}\n[[shadow]]\nname = \"s\"\n{body}");
    let cases = [
        ("collinear", "kind = \"sun\"\ncasters = \"cube\"\nreceivers = \"cube\"\nplane_points = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]\n", 35, "one line"),
        ("zero-normal", "kind = \"sun\"\ncasters = \"cube\"\nreceivers = \"cube\"\nplane_point = [0, 0, 0]\nplane_normal = [0, 0, 0]\n", 36, "zero vector"),
        ("theta", "kind = \"wave\"\ncasters = \"cube\"\nreceivers = \"cube\"\nmethod = \"map\"\ntheta = 95\n", 36, "[0, 90)"),
        ("zero-direction", "kind = \"sun\"\ndirection = [0, 0, 0]\ncasters = \"cube\"\nreceivers = \"cube\"\nmethod = \"map\"\n", 33, "zero vector"),
        ("unknown-caster", "kind = \"sun\"\ncasters = \"cub\"\nreceivers = \"cube\"\n", 33, "did you mean `cube`"),
        ("map-size", "kind = \"sun\"\nmethod = \"map\"\nmap_size = 0\ncasters = \"cube\"\nreceivers = \"cube\"\n", 34, "1..=8192"),
    ];
    for (name, body, line, needle) in cases {
        assert_rejected(name, &shadow(body), line, needle);
    }
}

#[test]
fn camera_ranges_are_checked() {
    assert_rejected("fov0", &GOOD.replace("fov = 45.0", "fov = 0.0"), 9, "fov");
    assert_rejected("fov180", &GOOD.replace("fov = 45.0", "fov = 180.0"), 9, "fov");
    assert_rejected("nearfar", &GOOD.replace("near = 0.1", "near = 200.0"), 11, "near");
}

#[test]
fn image_sizes_are_checked() {
    assert_rejected("w0", &GOOD.replace("width = 64", "width = 0"), 2, "width");
    assert_rejected("wbig", &GOOD.replace("width = 64", "width = 16385"), 2, "width");
}

#[test]
fn a_missing_gltf_file_names_the_scene_line() {
    let text = format!("{GOOD}\n[[object]]\nname = \"m\"\nkind = \"gltf\"\npath = \"nope.glb\"\n");
    assert_rejected("gltf", &text, 33, "nope.glb");
}

#[test]
fn a_missing_scene_file_is_exit_2() {
    let o = hadou(&["validate", "/nonexistent/scene.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("/nonexistent/scene.toml"), "{}", stderr(&o));
}

#[test]
fn bad_output_paths_are_exit_2_and_write_nothing() {
    let dir = tmpdir("paths");
    let scene = write_scene(&dir, GOOD);
    let s = scene.to_str().unwrap();
    for (out, needle) in [
        (dir.join("missing/out.png"), "does not exist"),
        (dir.join("out.jpg"), "unknown output format"),
        (scene.join("out.png"), "is a file, not a directory"),
        (PathBuf::from("/proc/hadou-out.png"), "cannot create"),
    ] {
        let o = hadou(&["render", s, "-o", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{}: {}", out.display(), stderr(&o));
        assert!(stderr(&o).contains(needle), "{}: {}", out.display(), stderr(&o));
        assert!(!out.exists());
    }
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
}

#[test]
fn bad_flags_are_exit_2() {
    let dir = tmpdir("flags");
    let scene = write_scene(&dir, GOOD);
    let s = scene.to_str().unwrap();
    let out = dir.join("o.png");
    let o = out.to_str().unwrap();
    for args in [
        vec!["render", s, "-o", o, "--width", "0"],
        vec!["render", s, "-o", o, "--height", "99999"],
        vec!["render", s, "-o", o, "--time", "nan"],
        vec!["render", s, "-o", o, "--frames", "5..2"],
        vec!["render", s, "-o", o, "--frames", "abc"],
        vec!["render", s, "-o", o, "--samples", "0"],
        vec!["render", s, "-o", o, "--samples", "2"],
        vec!["render", s, "-o", o, "--samples", "25"],
        vec!["render", s, "-o", o, "--samples", "-4"],
        vec!["render", s, "-o", o, "--samples", "99999999999"],
        vec!["render", s, "-o", o, "--frames", "0..2", "--samples", "3"],
        vec!["probe", s, "--pixel", "64,0"],
        vec!["probe", s, "--pixel", "1;2"],
        vec!["bench", "--sizes", "0"],
    ] {
        let r = hadou(&args);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {}", stderr(&r));
        assert!(!stderr(&r).contains("panicked"));
    }
    assert!(!out.exists());
}

/// Issue 41, point 3: whatever an error or warning quotes (a path given, a file's text) reaches
/// the terminal as one line with its control characters escaped: a scene path holding an escape
/// sequence, and a scene whose texture path holds one, exit 2 with no control byte on stderr.
#[test]
fn issue_41_messages_escape_the_control_characters_they_quote() {
    let dir = tmpdir("escape");
    let clean = |o: &Output| {
        let e = stderr(o);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(!e.trim_end().contains('\n'), "one line: {e:?}");
        assert!(!e.trim_end().chars().any(|c| c.is_control()), "a control character reached stderr: {e:?}");
        e
    };
    let missing = dir.join("a\u{1b}[2Jb.toml");
    let e = clean(&hadou(&["validate", missing.to_str().unwrap()]));
    assert!(e.contains("\\u{1b}[2Jb"), "{e}");
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        "[camera]\nposition = [0, 0, 5]\ntarget = [0, 0, 0]\n\n[[material]]\nname = \"m\"\nmodel = \"toon\"\n\
         base_texture = \"t\\u001b]0;x\\u0007.png\"\n\n[[object]]\nname = \"b\"\nkind = \"box\"\nmaterial = \"m\"\n",
    )
    .unwrap();
    let e = clean(&hadou(&["validate", scene.to_str().unwrap()]));
    assert!(e.contains("\\u{1b}]0;x\\u{7}"), "{e}");
}

/// Every flag's bad value, whether the argument parser or hadou refuses it, is one line naming the
/// flag, the value as typed and what the flag accepts (issue 41: the parser's own error was three
/// lines), exit 2; a time past f32 says so rather than "not finite".
#[test]
fn issue_41_every_bad_flag_value_is_one_line_naming_the_flag() {
    let dir = tmpdir("flag-lines");
    let scene = write_scene(&dir, GOOD);
    let s = scene.to_str().unwrap();
    let out = dir.join("o.png");
    let o = out.to_str().unwrap();
    for (args, needles) in [
        (vec!["render", s, "-o", o, "--samples", "-1"], vec!["--samples -1", "1, 4, 9, 16"]),
        (vec!["render", s, "-o", o, "--samples", "4.0"], vec!["--samples 4.0", "1, 4, 9, 16"]),
        (vec!["render", s, "-o", o, "--samples", "nan"], vec!["--samples nan", "1, 4, 9, 16"]),
        (vec!["render", s, "-o", o, "--samples", "1e30"], vec!["--samples 1e30", "1, 4, 9, 16"]),
        (vec!["render", s, "-o", o, "--samples", "2"], vec!["--samples 2", "1, 4, 9, 16"]),
        (vec!["render", s, "-o", o, "--width", "wide"], vec!["--width wide", "pixels"]),
        (vec!["render", s, "-o", o, "--height", "-3"], vec!["--height -3", "pixels"]),
        (vec!["bench", "--sizes", "a,b"], vec!["--sizes a", "commas"]),
        (vec!["bench", "--iterations", "-2"], vec!["--iterations -2", "1 or more"]),
        (vec!["render", s, "-o", o, "--backend", "tpu"], vec!["--backend tpu"]),
        (vec!["render", s, "-o", o, "--samples", "4\x1b[2J"], vec!["--samples 4\\u{1b}[2J"]),
        (vec!["render", s, "-o", o, "--time", "3.5e38"], vec!["--time 3.5e38", "32-bit float"]),
    ] {
        let r = hadou(&args);
        let e = stderr(&r);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {e}");
        assert_eq!(e.trim_end().lines().count(), 1, "{args:?}: not one line: {e}");
        for n in needles {
            assert!(e.contains(n), "{args:?}: {e:?} lacks {n:?}");
        }
        assert!(!e.contains('\x1b'), "{args:?}: a raw escape reached the terminal");
    }
    assert!(!out.exists());
}

#[test]
fn every_example_scene_validates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut n = 0;
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            let o = hadou(&["validate", p.to_str().unwrap()]);
            assert_eq!(o.status.code(), Some(0), "{}: {}", p.display(), stderr(&o));
            n += 1;
        }
    }
    assert!(n >= 6, "only {n} example scenes");
}

#[test]
fn probe_reports_curve_energy_and_evaluations() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/spiral-drill.toml");
    let o = hadou(&["probe", scene.to_str().unwrap(), "--pixel", "300,180", "--time", "1.0"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let waves = j["waves"].as_array().unwrap();
    assert!(waves.len() >= 2, "{j}");
    // Every wave reports its energy; curved waves report how many integrand evaluations it took.
    for w in waves {
        assert!(w["energy"].as_f64().unwrap() >= 0.0);
        assert!(w["evaluations"].as_u64().unwrap() >= 1, "{w}");
    }
    let total: f64 = waves.iter().map(|w| w["energy"].as_f64().unwrap()).sum();
    assert!((total - j["energy"].as_f64().unwrap()).abs() <= 1e-6 * total.max(1.0));
}

/// Whether a usable GPU adapter exists (found without compiling anything); in CI
/// (`HADOU_REQUIRE_GPU=1`) its absence is a failure.
fn gpu_available() -> bool {
    match hadou::gpu::find_adapter() {
        Ok(_) => true,
        Err(e) => {
            assert!(std::env::var("HADOU_REQUIRE_GPU").is_err(), "HADOU_REQUIRE_GPU is set but: {e}");
            eprintln!("SKIPPED: no GPU adapter ({e}); set HADOU_REQUIRE_GPU=1 to make this a failure");
            false
        }
    }
}

#[test]
fn probe_and_render_agree_across_backends() {
    if !gpu_available() {
        return;
    }
    let dir = tmpdir("backends");
    let scene = write_scene(&dir, GOOD);
    let s = scene.to_str().unwrap();
    let run = |backend: &str| {
        let o = hadou(&["probe", s, "--pixel", "20,24", "--backend", backend]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap()
    };
    let (cpu, gpu) = (run("cpu"), run("gpu"));
    assert_eq!(gpu["backend"], "gpu");
    let (ec, eg) = (cpu["energy"].as_f64().unwrap(), gpu["energy"].as_f64().unwrap());
    assert!(ec > 0.0 && (ec - eg).abs() <= 1e-3 * ec, "cpu {ec} gpu {eg}");
    let out = dir.join("g.png");
    let o = hadou(&["render", s, "-o", out.to_str().unwrap(), "--backend", "gpu"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(out.exists());
}

/// Runs `hadou args…`, expects exit 2, a message containing every needle, and no panic.
fn assert_exit_2(args: &[&str], needles: &[&str]) {
    let o = hadou(args);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    for n in needles {
        assert!(e.contains(n), "{args:?}: expected `{n}` in: {e}");
    }
    assert!(!e.contains("panicked"), "{e}");
}

#[test]
fn negative_numbers_are_values_not_flags() {
    let dir = tmpdir("negative");
    let s = write_scene(&dir, GOOD);
    let s = s.to_str().unwrap();
    let o = dir.join("o.png");
    let o = o.to_str().unwrap();
    assert_exit_2(&["render", s, "-o", o, "--time", "-1"], &["--time -1", "times are ≥ 0"]);
    assert_exit_2(&["probe", s, "--pixel", "-1,0"], &["--pixel -1,0", "non-negative"]);
    assert_exit_2(&["render", s, "-o", o, "--frames", "-1..3"], &["--frames -1..3", "non-negative"]);
    assert_exit_2(&["render", s, "-o", o, "--width", "-5"], &["--width", "-5"]);
    assert_exit_2(
        &["render", s, "-o", o, "--frames", "0..=4294967295"],
        &["--frames", "go up to 4294967294"],
    );
    assert!(!Path::new(o).exists());
}

#[test]
fn numbers_are_echoed_as_typed() {
    let dir = tmpdir("echo");
    let s = write_scene(&dir, GOOD);
    let s = s.to_str().unwrap();
    let o = dir.join("o.png");
    let o = o.to_str().unwrap();
    for (args, typed) in [
        (vec!["render", s, "-o", o, "--time", "1e400"], "--time 1e400:"),
        (vec!["render", s, "-o", o, "--time", "3.4e39"], "--time 3.4e39:"),
        (vec!["probe", s, "--pixel", "1,2", "--time", "-1e30"], "--time -1e30:"),
    ] {
        let r = hadou(&args);
        let e = stderr(&r);
        assert_eq!(r.status.code(), Some(2), "{e}");
        assert!(e.contains(typed), "expected `{typed}` in: {e}");
        // No number is written out digit by digit.
        assert!(!e.contains("0000000000"), "{e}");
    }
}

#[test]
fn a_tiny_fps_is_blamed_on_fps_not_on_the_time() {
    let dir = tmpdir("fps");
    let s = write_scene(&dir, GOOD);
    let s = s.to_str().unwrap();
    let d = format!("{}/", dir.display());
    let r = hadou(&["render", s, "-o", &d, "--frames", "0..3", "--fps", "1e-45"]);
    let e = stderr(&r);
    assert_eq!(r.status.code(), Some(2), "{e}");
    assert!(e.contains("--fps 1e-45") && !e.contains("--time"), "{e}");
    assert_exit_2(&["render", s, "-o", &d, "--frames", "0..3", "--fps", "0"], &["--fps 0", "positive"]);
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "nothing written");
}

#[test]
fn bench_sizes_are_blamed_on_sizes() {
    assert_exit_2(&["bench", "--sizes", "0"], &["--sizes 0"]);
    assert_exit_2(&["bench", "--sizes", "512,-1"], &["--sizes"]);
}

#[test]
fn bench_curves_without_the_example_scenes_is_exit_2() {
    let dir = tmpdir("bench-scenes");
    assert_exit_2(
        &["bench", "curves", "--scenes", dir.to_str().unwrap(), "--sizes", "16"],
        &["--scenes", "needs the example scenes"],
    );
}

#[test]
fn frames_check_every_output_path_before_rendering() {
    let dir = tmpdir("frames-blocked");
    let s = write_scene(&dir, GOOD);
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("frame_00001.png")).unwrap();
    let d = format!("{}/", out.display());
    let r = hadou(&["render", s.to_str().unwrap(), "-o", &d, "--frames", "0..3"]);
    let e = stderr(&r);
    assert_eq!(r.status.code(), Some(2), "{e}");
    assert!(e.contains("frame_00001.png") && e.contains("is a directory"), "{e}");
    assert!(!out.join("frame_00000.png").exists(), "frame 0 was rendered before the check");
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 1, "only the blocking directory");
    // A directory far along a huge range is found at once, without listing every frame's path.
    std::fs::create_dir_all(out.join("frame_4000000000.png")).unwrap();
    std::fs::remove_dir(out.join("frame_00001.png")).unwrap();
    let start = std::time::Instant::now();
    let r = hadou(&["render", s.to_str().unwrap(), "-o", &d, "--frames", "0..=4294967294"]);
    let e = stderr(&r);
    assert_eq!(r.status.code(), Some(2), "{e}");
    assert!(e.contains("frame_4000000000.png") && e.contains("is a directory"), "{e}");
    assert!(start.elapsed().as_secs() < 10, "took {:?}", start.elapsed());
}

#[test]
fn probe_never_prints_null() {
    // Two spheres hit through their centres with no core: the largest energies a scene can
    // hold; whatever they come to (saturated or huge), the JSON has a number for each. (Within
    // the scene bounds they stay finite; the mapping of ±∞ and NaN itself is unit-tested in
    // main.rs, `json_numbers_are_never_null`.)
    let dir = tmpdir("probe-json");
    let text = GOOD.replace(
        "[[wave]]",
        "[[wave]]\nname = \"s1\"\nkind = \"sphere\"\nM = [0.0, 0.0, 0.0]\nalpha_s = 1e5\ncore_radius = 0.0\n\n\
         [[wave]]\nname = \"s2\"\nkind = \"sphere\"\nM = [0.0, 0.0, 0.0]\nalpha_s = 1e5\ncore_radius = 0.0\n\n[[wave]]",
    );
    let s = write_scene(&dir, &text);
    let o = hadou(&["probe", s.to_str().unwrap(), "--pixel", "32,24", "--width", "65", "--height", "49"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!out.contains("null"), "{out}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(j["energy"].as_f64().unwrap() > 1e10, "{j}");
}

#[test]
fn probe_names_the_shadow_a_pixel_takes() {
    // Seen from straight above, a box stands on the ground in a low sun from −x: the ground just
    // to its +x side is in the shadow "sun", the ground on its −x side is lit.
    let dir = tmpdir("probe-shadow");
    let text = "[image]\nwidth = 200\nheight = 200\n[camera]\nposition = [0, 12, 0]\ntarget = [0, 0, 0]\n\
                up = [0, 0, -1]\nfov = 45\n[[object]]\nname = \"ground\"\nkind = \"plane\"\nsize = [12, 12]\n\
                [[object]]\nname = \"box\"\nkind = \"box\"\nsize = [0.6, 2, 0.6]\n\
                [[shadow]]\nname = \"sun\"\nkind = \"sun\"\ndirection = [1, -1, 0]\ncasters = \"box\"\n\
                receivers = \"ground\"\n";
    let s = write_scene(&dir, text);
    let probe = |px: &str| {
        let o = hadou(&["probe", s.to_str().unwrap(), "--pixel", px, "--backend", "cpu"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap()
    };
    let shadowed = probe("118,100"); // the ground at x ≈ 0.9
    assert_eq!((shadowed["object"].as_str(), shadowed["shadow"].as_str()), (Some("ground"), Some("sun")));
    let lit = probe("82,100"); // x ≈ −0.9
    assert_eq!((lit["object"].as_str(), lit.get("shadow")), (Some("ground"), None));
}

#[test]
fn a_png_rendered_in_bands_equals_the_whole_frame() {
    use hadou::Backend;
    let dir = tmpdir("bands");
    let scene = write_scene(&dir, GOOD);
    // 8192 wide: 512 rows a band, so 1100 rows take three bands, the last one partial.
    let (w, h) = (8192u32, 1100u32);
    assert!(hadou::output::band_rows(w, 1) < h / 2);
    let out = dir.join("b.png");
    let (ws, hs) = (w.to_string(), h.to_string());
    let o = hadou(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        &ws,
        "--height",
        &hs,
        "--backend",
        "cpu",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let mut frame = hadou::Scene::load(&scene).unwrap().at(0.0);
    frame.width = w;
    frame.height = h;
    let whole = hadou::CpuBackend::new().render(&frame).unwrap();
    let (pw, ph, pixels) = common::decode_png(&out);
    assert_eq!((pw, ph), (w, h));
    assert!(pixels == hadou::output::srgb8(&whole), "banded PNG differs from the whole-frame render");
}

/// Runs `hadou ARGS` (stdout discarded, stderr kept in `dir/stderr.txt`) and polls its peak
/// resident memory from /proc until it exits (Linux only): its exit status, the peak in KiB and
/// what it printed on stderr (for the failure message). Stderr goes to a file, not a pipe, so a
/// chatty child can never block on a full pipe nobody reads.
fn run_measuring_peak(args: &[&str], dir: &Path) -> (std::process::ExitStatus, u64, String) {
    let err_path = dir.join("stderr.txt");
    let mut child = Command::new(env!("CARGO_BIN_EXE_hadou"))
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::fs::File::create(&err_path).unwrap())
        .spawn()
        .unwrap();
    let status_file = format!("/proc/{}/status", child.id());
    let mut peak = 0;
    let status = loop {
        if let Ok(text) = std::fs::read_to_string(&status_file) {
            if let Some(line) = text.lines().find(|l| l.starts_with("VmHWM:")) {
                let kib: u64 = line.split_whitespace().nth(1).and_then(|v| v.parse().ok()).unwrap_or(0);
                peak = peak.max(kib);
            }
        }
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    };
    (status, peak, std::fs::read_to_string(&err_path).unwrap_or_default())
}

#[test]
fn png_memory_follows_the_band_not_the_image() {
    if !Path::new("/proc/self/status").exists() {
        eprintln!("SKIPPED: no /proc to read peak memory from");
        return;
    }
    let dir = tmpdir("memory");
    // An 8192² frame: 1.6 GB as one float image, about 100 MB per band.
    let scene = write_scene(&dir, &GOOD.replace("width = 64\nheight = 48", "width = 8192\nheight = 8192"));
    let out = dir.join("big.png");
    let args = ["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--backend", "cpu"];
    let (status, peak, err) = run_measuring_peak(&args, &dir);
    assert!(status.success(), "{status}: {err}");
    assert!(out.exists());
    // The bound: a few bands of float image and opaque buffers (~55 bytes a pixel each), never
    // the image (8192² × 24 bytes = 1.6 GB for its floats alone).
    assert!(peak > 0 && peak < 600 * 1024, "peak resident memory {peak} KiB");
    eprintln!("8192² PNG: peak resident memory {} MiB", peak / 1024);
}

/// Sends `signal` (`-TERM`, `-INT`, `-HUP`) to `hadou render ARGS` once a temporary file exists
/// in `dir`, and returns its exit status and stderr.
#[cfg(unix)]
fn interrupt_once_writing(args: &[&str], dir: &Path, signal: &str) -> (Option<i32>, String) {
    use std::io::Read;
    let mut child = Command::new(env!("CARGO_BIN_EXE_hadou"))
        .args(args)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let tmp_exists = || {
        std::fs::read_dir(dir).unwrap().any(|e| e.unwrap().file_name().to_string_lossy().ends_with(".tmp"))
    };
    // A file seen twice 100 ms apart: the writer's, not the instant probe of a writable directory.
    let writing =
        || tmp_exists() && (std::thread::sleep(std::time::Duration::from_millis(100)), tmp_exists()).1;
    let start = std::time::Instant::now();
    while !writing() && start.elapsed().as_secs() < 30 {
        assert!(child.try_wait().unwrap().is_none(), "{args:?}: ended before a temporary file appeared");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert!(tmp_exists(), "{args:?}: no temporary file appeared");
    let kill = Command::new("kill").args([signal, &child.id().to_string()]).status().unwrap();
    assert!(kill.success());
    let status = child.wait().unwrap();
    let mut err = String::new();
    child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    (status.code(), err)
}

/// Every writer (PNG, EXR, a PNG sequence, a GIF) stopped by each signal the handler catches,
/// once its temporary file exists: the file is removed, the message counts it, and the output
/// directory is left empty.
#[cfg(unix)]
#[test]
fn an_interrupted_writer_leaves_nothing_for_every_signal() {
    let dir = tmpdir("interrupt");
    // 4096² on the CPU takes seconds; each run is stopped as soon as its file appears.
    let scene = write_scene(&dir, &GOOD.replace("width = 64\nheight = 48", "width = 4096\nheight = 4096"));
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    let s = scene.to_str().unwrap();
    let (png, exr, gif) = (out.join("a.png"), out.join("a.exr"), out.join("a.gif"));
    let seq = format!("{}/", out.display());
    let writers: [(&str, Vec<&str>); 4] = [
        ("png", vec!["render", s, "-o", png.to_str().unwrap()]),
        ("exr", vec!["render", s, "-o", exr.to_str().unwrap()]),
        ("sequence", vec!["render", s, "-o", &seq, "--frames", "0..3"]),
        ("gif", vec!["render", s, "-o", gif.to_str().unwrap(), "--frames", "0..3"]),
    ];
    for (what, args) in &writers {
        for signal in ["-TERM", "-INT", "-HUP"] {
            let args: Vec<&str> = args.iter().copied().chain(["--backend", "cpu"]).collect();
            let (code, err) = interrupt_once_writing(&args, &out, signal);
            assert_eq!(code, Some(130), "{what} {signal}: {err}");
            assert!(err.contains("interrupted: removed 1 partial output file(s)"), "{what} {signal}: {err}");
            let left: Vec<_> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name()).collect();
            assert!(left.is_empty(), "{what} {signal}: left {left:?}");
        }
    }
}

/// Issue 41 (no temp file under any timing): `hadou render` writing a GIF and a PNG is sent
/// SIGTERM at timings from 0 to 3 s (before the handler is installed, while the scene loads,
/// while frames render, while the encoder writes) with both cores kept busy by other threads;
/// whenever it stops, no temporary file is left: it exited 130 with its file removed, or was
/// stopped before its handler was installed (no file yet), or finished with its output whole.
#[cfg(unix)]
#[test]
fn issue_41_no_temp_file_under_any_signal_timing() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let dir = tmpdir("signal-timing");
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let kame = scenes.join("kamehameha.toml");
    let k = kame.to_str().unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let load: Vec<_> = (0..2)
        .map(|_| {
            let stop = stop.clone();
            std::thread::spawn(move || {
                let mut x = 0u64;
                while !stop.load(Ordering::Relaxed) {
                    x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
                }
            })
        })
        .collect();
    for (i, ms) in
        [0u64, 1, 3, 7, 15, 30, 60, 100, 160, 250, 400, 600, 900, 1300, 1900, 3000].into_iter().enumerate()
    {
        let out = dir.join(format!("t{i}"));
        std::fs::create_dir(&out).unwrap();
        let (gif, png) = (out.join("out.gif"), out.join("out.png"));
        // Both writers at once, signalled at the same moment.
        let runs: Vec<_> = [
            ("gif", &gif, &["--frames", "0..240"][..]),
            ("png", &png, &["--width", "2048", "--height", "1536"][..]),
        ]
        .into_iter()
        .map(|(what, target, extra)| {
            let mut args = vec!["render", k, "-o", target.to_str().unwrap(), "--backend", "cpu"];
            if what == "gif" {
                args.extend(["--width", "512", "--height", "384"]);
            }
            args.extend(extra);
            let child = Command::new(env!("CARGO_BIN_EXE_hadou"))
                .args(&args)
                .stderr(std::process::Stdio::null())
                .stdout(std::process::Stdio::null())
                .spawn()
                .unwrap();
            (what, target, child)
        })
        .collect();
        std::thread::sleep(std::time::Duration::from_millis(ms));
        for (_, _, child) in &runs {
            let _ = Command::new("kill").args(["-TERM", &child.id().to_string()]).status();
        }
        let ended: Vec<_> =
            runs.into_iter().map(|(what, target, mut c)| (what, target, c.wait().unwrap())).collect();
        let left: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect();
        assert!(left.is_empty(), "at {ms} ms ({ended:?}): left {left:?}");
        for (what, target, status) in ended {
            use std::os::unix::process::ExitStatusExt;
            assert!(
                matches!((status.code(), status.signal()), (Some(130 | 0), _) | (_, Some(15))),
                "{what} at {ms} ms: unexpected end {status}"
            );
            // An output there is whole: it was renamed into place before the signal came.
            if target.exists() {
                let bytes = std::fs::read(target).unwrap();
                let whole = if what == "gif" {
                    bytes.starts_with(b"GIF89a") && bytes.last() == Some(&0x3B)
                } else {
                    png::Decoder::new(std::io::Cursor::new(&bytes)).read_info().is_ok_and(|mut r| {
                        let mut buf = vec![0; r.output_buffer_size().unwrap_or(0)];
                        r.next_frame(&mut buf).is_ok()
                    })
                };
                assert!(whole, "{what} at {ms} ms ({status}): a partial output");
            }
        }
    }
    stop.store(true, Ordering::Relaxed);
    for t in load {
        t.join().unwrap();
    }
}

/// The scene `GOOD` with an `[area_light]` (whose images are at most 4096² pixels) and an
/// `[image]` of `w×h`.
fn area_light_scene(w: u32, h: u32) -> String {
    let light = "\n[[object]]\nname = \"floor\"\nkind = \"plane\"\nsize = [80.0, 80.0]\nposition = [0.0, -3.0, -20.0]\n\n[area_light]\nposition = [0.0, 20.0, -20.0]\nsize = 1.0\ntarget = \"cube\"\n";
    format!("{GOOD}{light}").replace("width = 64\nheight = 48", &format!("width = {w}\nheight = {h}"))
}

#[test]
fn sizes_from_flags_obey_the_area_light_pixel_limit_on_every_path() {
    let dir = tmpdir("flag-sizes");
    let scene = write_scene(&dir, &area_light_scene(64, 4096));
    let s = scene.to_str().unwrap();
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    let (png, exr, gif) = (out.join("a.png"), out.join("a.exr"), out.join("a.gif"));
    let seq = format!("{}/", out.display());
    let both = ["--width", "4097", "--height", "4096"];
    let cases: [Vec<&str>; 5] = [
        vec!["render", s, "-o", png.to_str().unwrap()],
        vec!["render", s, "-o", exr.to_str().unwrap()],
        vec!["render", s, "-o", &seq, "--frames", "0..2"],
        vec!["render", s, "-o", gif.to_str().unwrap(), "--frames", "0..2"],
        vec!["probe", s, "--pixel", "0,0"],
    ];
    for args in &cases {
        for backend in ["cpu", "gpu"] {
            let full: Vec<&str> = args.iter().chain(&both).copied().chain(["--backend", backend]).collect();
            assert_exit_2(&full, &["--width 4097 --height 4096", "at most 16777216 pixels", "[area_light]"]);
        }
        // One flag with the other edge from the file: both are named.
        let one: Vec<&str> = args.iter().copied().chain(["--width", "4097"]).collect();
        assert_exit_2(
            &one,
            &["--width 4097 (height 4096 from the scene's [image])", "4097×4096 is 16781312 pixels"],
        );
    }
    // The soft-shadow bench's sizes obey its scene's limit too.
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    assert_exit_2(
        &["bench", "shadows", "--sizes", "4097", "--scenes", scenes.to_str().unwrap()],
        &["--sizes 4097", "at most 16777216 pixels"],
    );
    // Within the limit it renders.
    let o = hadou(&["probe", s, "--pixel", "0,0", "--width", "4096", "--height", "4096"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let left: Vec<_> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "written: {left:?}");
}

/// Issue 41 (glare within the memory promise): an image with a `[bloom]` past the glare's
/// 8192² pixels is refused before anything is allocated or written, on every output path and
/// backend, naming the flags, the `[bloom]`'s place and the limit; within it, a render's bands
/// are sized to fit beside the glare (`output::frame_band_rows`).
#[test]
fn issue_41_a_bloom_past_its_pixel_limit_exits_2_and_writes_nothing() {
    let dir = tmpdir("bloom-size");
    let text = format!("{GOOD}\n[bloom]\nintensity = 0.5\n");
    let line = text.lines().position(|l| l == "[bloom]").unwrap() + 1;
    let scene = write_scene(&dir, &text);
    let s = scene.to_str().unwrap();
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    let (png, exr) = (out.join("a.png"), out.join("a.exr"));
    let seq = format!("{}/", out.display());
    let at = format!("{}:{line}:1", scene.display());
    for args in [
        vec!["render", s, "-o", png.to_str().unwrap()],
        vec!["render", s, "-o", exr.to_str().unwrap()],
        vec!["render", s, "-o", &seq, "--frames", "0..2"],
    ] {
        for backend in ["cpu", "gpu"] {
            let full: Vec<&str> = args
                .iter()
                .copied()
                .chain(["--width", "16384", "--height", "4097", "--backend", backend])
                .collect();
            assert_exit_2(&full, &["--width 16384 --height 4097", &at, "at most 67108864 pixels", "GB"]);
        }
    }
    let left: Vec<_> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "written: {left:?}");
    let frame = hadou::Scene::load(&scene).unwrap().at(0.0);
    let sized = |w: u32, h: u32| hadou::Frame { width: w, height: h, ..frame.clone() };
    assert_eq!(hadou::output::frame_band_rows(&sized(4096, 4096)), 4096, "one band: the glare is drawn once");
    assert!(hadou::output::frame_band_rows(&sized(8192, 8192)) >= 1024);
}

/// Issue 41 (a bounded cost per frame): `--samples` is checked against the work a pixel may cost
/// with the scene's waves, before anything is rendered or written, naming the flag and the wave.
#[test]
fn issue_41_samples_past_the_pixels_work_exit_2() {
    let dir = tmpdir("pixel-work");
    let helices: String = (0..12)
        .map(|i| {
            format!(
                "[[wave]]\nname = \"h{i}\"\nkind = \"helix\"\nO = [-0.5, {i}, 0]\nD = [1, 0, 0]\nalpha = 1\n\
                 radius = 1\nrate = 6\nlength = 1\nfield = \"nearest\"\n\n"
            )
        })
        .collect();
    let scene = write_scene(&dir, &format!("[image]\nwidth = 8\nheight = 8\nsamples = 4\n\n{helices}"));
    let s = scene.to_str().unwrap();
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    let (png, gif) = (out.join("a.png"), out.join("a.gif"));
    assert_exit_2(
        &["render", s, "-o", png.to_str().unwrap(), "--samples", "16"],
        &["--samples 16:", "[[wave]] \"h11\""],
    );
    assert_exit_2(
        &["render", s, "-o", gif.to_str().unwrap(), "--samples", "16", "--frames", "0..2"],
        &["--samples 16:", "[[wave]] \"h11\""],
    );
    let left: Vec<_> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "written: {left:?}");
    let o = hadou(&["render", s, "-o", png.to_str().unwrap(), "--samples", "9", "--backend", "cpu"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn a_gif_frame_past_its_pixel_limit_exits_2() {
    let dir = tmpdir("gif-size");
    let out = dir.join("a.gif");
    let o = out.to_str().unwrap();
    // From the flags, and from a scene file's [image] (valid: no [area_light]).
    let s = write_scene(&dir, GOOD);
    assert_exit_2(
        &["render", s.to_str().unwrap(), "-o", o, "--frames", "0..2", "--width", "4097", "--height", "4096"],
        &["--width 4097 --height 4096", "a GIF frame is at most 16777216 pixels", "PNG sequence"],
    );
    let s = write_scene(&dir, &GOOD.replace("width = 64\nheight = 48", "width = 16384\nheight = 16384"));
    assert_exit_2(
        &["render", s.to_str().unwrap(), "-o", o, "--frames", "0..2"],
        &["scene.toml: [image] 16384×16384", "a GIF frame is at most 16777216 pixels"],
    );
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "output written");
}

#[test]
fn an_exr_rendered_in_bands_equals_the_whole_frame() {
    let dir = tmpdir("exr-bands");
    let scene = write_scene(&dir, GOOD);
    // 4096 wide: 1024 rows a band, so 2100 rows take three bands, the last one partial.
    let (w, h) = (4096u32, 2100u32);
    assert!(hadou::output::band_rows(w, 1) < h / 2);
    let out = dir.join("b.exr");
    let (ws, hs) = (w.to_string(), h.to_string());
    let args =
        ["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--width", &ws, "--height", &hs];
    let o = hadou(&[&args[..], &["--backend", "cpu"]].concat());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    use hadou::Backend;
    let mut frame = hadou::Scene::load(&scene).unwrap().at(0.0);
    frame.width = w;
    frame.height = h;
    let whole = hadou::CpuBackend::new().render(&frame).unwrap();
    let img = exr::prelude::read_all_flat_layers_from_file(&out).unwrap();
    let layer = &img.layer_data[0];
    assert_eq!((layer.size.0, layer.size.1), (w as usize, h as usize));
    assert_eq!(layer.attributes.layer_name.as_ref().map(|n| n.to_string()).as_deref(), Some("hadou"));
    let channel = |name: &str| -> Vec<f32> {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap_or_else(|| panic!("no {name}"));
        c.sample_data.values_as_f32().collect()
    };
    for (k, name) in ["R", "G", "B", "A"].iter().enumerate() {
        assert!(channel(name) == whole.color.iter().map(|c| c[k]).collect::<Vec<_>>(), "{name} differs");
    }
    assert!(channel("energy") == whole.energy, "energy differs");
    assert!(channel("depth") == whole.depth, "depth differs");
}

#[test]
fn a_gpu_probe_renders_one_row_at_the_largest_size() {
    if !gpu_available() || !Path::new("/proc/self/status").exists() {
        return;
    }
    let dir = tmpdir("gpu-probe-size");
    let scene = write_scene(&dir, GOOD);
    // The whole 16384² image would take 6 GiB of floats; the pixel's row takes 1.5 MiB.
    let args = ["probe", scene.to_str().unwrap(), "--pixel", "8192,8192", "--backend", "gpu"];
    let (status, peak, err) =
        run_measuring_peak(&[&args[..], &["--width", "16384", "--height", "16384"]].concat(), &dir);
    assert!(status.success(), "{status}: {err}");
    assert!(peak > 0 && peak < 1024 * 1024, "peak resident memory {peak} KiB");
}

#[test]
fn exr_memory_follows_the_band_not_the_image() {
    if !Path::new("/proc/self/status").exists() {
        eprintln!("SKIPPED: no /proc to read peak memory from");
        return;
    }
    let dir = tmpdir("exr-memory");
    // An 8192² frame: 1.6 GB as one float image (and as much again for the old channel copies).
    let scene = write_scene(&dir, &GOOD.replace("width = 64\nheight = 48", "width = 8192\nheight = 8192"));
    let out = dir.join("big.exr");
    let args = ["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--backend", "cpu"];
    let (status, peak, err) = run_measuring_peak(&args, &dir);
    assert!(status.success(), "{status}: {err}");
    let img = exr::prelude::read_first_flat_layer_from_file(&out).unwrap();
    assert_eq!((img.layer_data.size.0, img.layer_data.size.1), (8192, 8192));
    assert!(peak > 0 && peak < 600 * 1024, "peak resident memory {peak} KiB");
    eprintln!("8192² EXR: peak resident memory {} MiB", peak / 1024);
}

#[test]
fn bench_shadows_prints_every_method_with_its_error() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let o = hadou(&[
        "bench",
        "shadows",
        "--sizes",
        "48",
        "--iterations",
        "1",
        "--json",
        "--backend",
        "cpu",
        "--scenes",
        scenes.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    let rows = j["rows"].as_array().expect("rows");
    for m in ["faithful-n1", "faithful-n3", "faithful-n5", "faithful-n10", "exact-linear", "exact", "pcss"] {
        let r = rows.iter().find(|r| r["method"] == m).unwrap_or_else(|| panic!("no {m} row: {j}"));
        assert_eq!(r["size"], 48);
        assert!(r["ms"].as_f64().is_some_and(|v| v > 0.0), "{r}");
        for k in ["mean_error", "p99_error"] {
            assert!(r[k].as_f64().is_some_and(|v| (0.0..=1.0).contains(&v)), "{m} {k}: {r}");
        }
    }
    // The exact resolve with 003's linear brightness and the search at N = 1 are the same answer;
    // the segment brightness (the exact resolve's default) is another.
    let err = |m: &str| rows.iter().find(|r| r["method"] == m).unwrap()["mean_error"].as_f64().unwrap();
    assert_eq!(err("exact-linear"), err("faithful-n1"));
    assert_ne!(err("exact"), err("exact-linear"));
    // The traced rows, each against its own lamp's brute-force reference (issue 43's bounds), the
    // two maps against the same references, the references' own rows, the traced frames.
    for shape in ["segment", "disc", "sphere"] {
        let row = |m: String| rows.iter().find(|r| r["method"] == m.as_str()).cloned();
        let t = row(format!("traced-{shape}")).unwrap_or_else(|| panic!("no traced-{shape} row: {j}"));
        assert!(t["ms"].as_f64().is_some_and(|v| v > 0.0), "{t}");
        assert!(t["pixels"].as_u64().is_some_and(|n| n > 0), "{t}");
        assert!(t["mean_error"].as_f64().is_some_and(|v| v <= 0.02), "{t}");
        assert!(t["p99_error"].as_f64().is_some_and(|v| v <= 0.08), "{t}");
        let e = row(format!("exact-vs-{shape}")).unwrap_or_else(|| panic!("no exact-vs-{shape} row"));
        assert!(e["mean_error"].as_f64().is_some_and(|v| v > t["mean_error"].as_f64().unwrap()), "{e}");
        assert!(
            row(format!("reference-{shape}")).is_some_and(|r| r["pixels"].as_u64().is_some_and(|n| n > 0))
        );
        assert!(
            row(format!("frame-traced-{shape}")).is_some_and(|r| r["ms"].as_f64().is_some_and(|v| v > 0.0))
        );
    }
    // --traced-only drops the two-map rows; --scene picks the scene; both are shadows-only.
    let o = hadou(&[
        "bench",
        "shadows",
        "--sizes",
        "32",
        "--iterations",
        "1",
        "--json",
        "--backend",
        "cpu",
        "--traced-only",
        "--scene",
        "soft-overlap.toml",
        "--scenes",
        scenes.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    assert_eq!(j["scene"], "soft-overlap.toml");
    let rows = j["rows"].as_array().expect("rows");
    assert!(rows.iter().any(|r| r["method"] == "traced-disc") && !rows.iter().any(|r| r["method"] == "pcss"));
    assert_exit_2(
        &["bench", "analytic", "--traced-only"],
        &["--traced-only: applies to `hadou bench shadows` only"],
    );
    assert_exit_2(
        &["bench", "toon", "--scene", "x.toml"],
        &["--scene x.toml: applies to `hadou bench shadows` only"],
    );
}

/// A traced frame renders on both backends, and their pictures agree (mean 8-bit difference
/// under one level).
#[test]
fn a_traced_area_light_renders_on_both_backends_alike() {
    let dir = tmpdir("traced");
    let light = "\n[[object]]\nname = \"floor\"\nkind = \"plane\"\nsize = [80.0, 80.0]\nposition = [0.0, -3.0, -20.0]\n\n[area_light]\nposition = [0.0, 20.0, -20.0]\nsize = 1.0\ntarget = \"cube\"\nshape = \"disc\"\nresolve = \"traced\"\nsamples = 64\n";
    let s = write_scene(&dir, &format!("{GOOD}{light}"));
    let out = dir.join("o.png");
    let o = hadou(&["render", s.to_str().unwrap(), "-o", out.to_str().unwrap(), "--backend", "cpu"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
    let gpu = dir.join("g.png");
    let o = hadou(&["render", s.to_str().unwrap(), "-o", gpu.to_str().unwrap(), "--backend", "gpu"]);
    let e = stderr(&o);
    if e.contains("no usable device") {
        eprintln!("no GPU adapter: the GPU's picture is not checked here");
    } else {
        assert!(o.status.success(), "{e}");
        let (c, g) = (common::decode_png(&out), common::decode_png(&gpu));
        assert_eq!((c.0, c.1), (g.0, g.1));
        let diff: u64 = c.2.iter().zip(&g.2).map(|(a, b)| u64::from(a.abs_diff(*b))).sum();
        let mean = diff as f64 / c.2.len() as f64;
        assert!(mean < 1.0, "mean 8-bit difference {mean}");
    }
    // A bad sample count is an input error at its position.
    let bad = write_scene(&dir, &format!("{GOOD}{light}").replace("samples = 64", "samples = 0"));
    let line = format!("{GOOD}{light}").lines().position(|l| l == "samples = 64").unwrap() + 1;
    assert_exit_2(
        &["render", bad.to_str().unwrap(), "-o", out.to_str().unwrap()],
        &[&format!(":{line}:11:"), "1..=1024, got 0"],
    );
}

#[test]
fn area_light_probes_its_visibility_and_bad_ones_exit_2() {
    let dir = tmpdir("area");
    let light = "\n[[object]]\nname = \"floor\"\nkind = \"plane\"\nsize = [80.0, 80.0]\nposition = [0.0, -3.0, -20.0]\n\n[area_light]\nposition = [0.0, 20.0, -20.0]\nsize = 1.0\ntarget = \"cube\"\n";
    let s = write_scene(&dir, &format!("{GOOD}{light}"));
    let o = hadou(&["probe", s.to_str().unwrap(), "--pixel", "32,24"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    assert!(j["soft_visibility"].as_f64().is_some_and(|v| (0.0..=1.0).contains(&v)), "{j}");
    let bad = write_scene(&dir, &format!("{GOOD}{light}").replace("size = 1.0", "size = 0.0"));
    let out = dir.join("o.png");
    let lines = format!("{GOOD}{light}").lines().position(|l| l == "size = 1.0").unwrap() + 1;
    assert_exit_2(
        &["render", bad.to_str().unwrap(), "-o", out.to_str().unwrap()],
        &[&format!(":{lines}:8:"), "`size` in [area_light]"],
    );
    assert!(!out.exists());
}

/// The same frame written twice is the same file, byte for byte, in every format (an EXR's
/// blocks once went to disk in whichever order its compression threads finished).
#[test]
fn outputs_are_byte_identical_from_run_to_run() {
    let dir = tmpdir("deterministic-files");
    let scene = write_scene(&dir, GOOD);
    for ext in ["exr", "png"] {
        let bytes: Vec<Vec<u8>> = (0..3)
            .map(|i| {
                let out = dir.join(format!("f{i}.{ext}"));
                let args = ["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--width", "300"];
                let o = hadou(&[&args[..], &["--height", "200", "--backend", "cpu"]].concat());
                assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
                std::fs::read(&out).unwrap()
            })
            .collect();
        assert!(bytes.windows(2).all(|w| w[0] == w[1]), "{ext}: the files differ between runs");
    }
}

#[test]
fn validate_lists_the_clips_and_expressions_of_gltf_objects() {
    let dir = tmpdir("validate-clips");
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/assets");
    for f in ["brace.glb", "brace.vrm", "brace.vrma"] {
        std::fs::copy(assets.join(f), dir.join(f)).unwrap();
    }
    let text = "[camera]\nposition = [0.0, 1.0, 6.0]\ntarget = [0.0, 0.9, 0.0]\n\n\
                [[object]]\nname = \"hero\"\nkind = \"gltf\"\npath = \"brace.glb\"\nanimation = \"brace\"\n\n\
                [[object]]\nname = \"idle\"\nkind = \"gltf\"\npath = \"brace.glb\"\nposition = [2.0, 0.0, 0.0]\n\n\
                [[object]]\nname = \"avatar\"\nkind = \"gltf\"\npath = \"brace.vrm\"\nposition = [-2.0, 0.0, 0.0]\n\n\
                [[object]]\nname = \"dancer\"\nkind = \"gltf\"\npath = \"brace.vrm\"\nanimation_file = \"brace.vrma\"\n\n\
                [[object]]\nname = \"floor\"\nkind = \"plane\"\n";
    let scene = write_scene(&dir, text);
    let o = hadou(&["validate", scene.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    let lines: Vec<&str> = out.lines().collect();
    let clips = "clips brace (2 s), step (1.5 s), cubic (1.2 s), blink (1 s)";
    assert_eq!(lines.len(), 4, "one line per glTF object with clips or expressions: {out}");
    assert_eq!(lines[0], format!("object \"hero\": {clips}; plays \"brace\""));
    assert_eq!(lines[1], format!("object \"idle\": {clips}; rests"));
    assert!(lines[2].starts_with("object \"avatar\": expressions ") && lines[2].contains("blink"), "{out}");
    // A VRM Animation clip is named as played; the avatar's file has no clips of its own.
    assert!(lines[3].starts_with("object \"dancer\": plays \"brace\"; expressions "), "{out}");
    assert!(!out.contains("floor"), "{out}");
}

/// `HADOU_SIMD` picks a vector path by name; an unknown name, or a path this CPU lacks, is exit 2
/// with what the CPU runs, before anything is written (never an illegal instruction).
#[test]
fn a_forced_vector_path_is_checked_against_the_cpu() {
    let dir = tmpdir("simd");
    let scene = write_scene(&dir, GOOD);
    let s = scene.to_str().unwrap();
    let run = |value: &str, out: &Path| {
        Command::new(env!("CARGO_BIN_EXE_hadou"))
            .env("HADOU_SIMD", value)
            .args(["render", s, "-o", out.to_str().unwrap(), "--width", "24", "--height", "16"])
            .output()
            .expect("binary runs")
    };
    let supported = hadou_math::simd::SimdPath::supported();
    let mut pngs = Vec::new();
    for path in &supported {
        let png = dir.join(format!("{}.png", path.name()));
        let o = run(path.name(), &png);
        assert_eq!(o.status.code(), Some(0), "{path}: {}", stderr(&o));
        pngs.push(png);
    }
    for name in ["avx2", "avx512"] {
        if !supported.iter().any(|p| p.name() == name) {
            let png = dir.join("lacking.png");
            let o = run(name, &png);
            assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
            let e = stderr(&o);
            assert!(
                e.contains("HADOU_SIMD") && e.contains("this CPU cannot run") && e.contains("portable"),
                "{e}"
            );
            assert!(!png.exists());
        }
    }
    let png = dir.join("unknown.png");
    let o = run("avx9000", &png);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("unknown vector path `avx9000`"), "{}", stderr(&o));
    assert!(!png.exists());
}

/// The CPU analytic bench's kernel-limit table has a whole-render, wave-pass and kernel row for
/// every vector path the CPU supports, then the scalar kernel and the plain loop.
#[test]
fn the_kernel_limit_table_has_a_row_per_vector_path() {
    let o = hadou(&["bench", "analytic", "--backend", "cpu", "--sizes", "24", "--iterations", "1", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = j["limit"]["rows"].as_array().unwrap_or_else(|| panic!("{j}"));
    let supported = hadou_math::simd::SimdPath::supported();
    assert_eq!(rows.len(), 3 * supported.len() + 2, "{rows:?}");
    for (k, path) in supported.iter().enumerate() {
        for (i, what) in ["whole render", "wave pass", "kernel only, 8 lanes"].iter().enumerate() {
            let row = &rows[3 * k + i];
            assert_eq!(row["path"], path.name(), "{row}");
            assert_eq!(row["what"], format!("{what} ({path})"), "{row}");
            assert!(row["ms"].as_f64().unwrap() > 0.0, "{row}");
        }
    }
    assert_eq!(rows[rows.len() - 1]["what"], "plain scalar loop");
    let names: Vec<&str> = supported.iter().map(|p| p.name()).collect();
    assert_eq!(j["limit"]["paths"], names.join(","));
}
