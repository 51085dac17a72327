//! Mutation fuzzing of viewer scripts without a window: hand-made scripts that use every command
//! (and the hostile ones that once spun or crashed the viewer: a backend switch then `quit`,
//! `resize` to the largest size, `select` of nobody, extreme numbers) are mutated at random (bytes
//! flipped, lines deleted, duplicated or swapped, numbers replaced by extreme values, words
//! swapped) and run against example scenes. Each case must parse or fail with one
//! `file:line:col:` line; every command it runs must succeed or fail with one line naming the
//! script's file and line; nothing may panic, and the viewer's frame stays finite.
//!
//! `HADOU_FUZZ_CASES=N` sets the number of cases (default 4000), `HADOU_FUZZ_SEED=S` the seed.

use hadou_math::rng::Rng;
use hadou_view::document::Document;
use hadou_view::script::{self, Command};
use hadou_view::viewer::Viewer;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

const SCRIPTS: &[&str] = &[
    "time 1\nset wave.beam.length 2.5\nkey wave.beam.length\nunkey wave.beam.length\nfire beam 0.5\nwait 3\nquit\n",
    "play\nloop on\nwait 10\npause\nloop off\ntime 0\norbit 30 -10\npan 0.1 -0.2\nzoom 1.5\nundo\nredo\n",
    "add wave sphere\nadd object box\nremove wave beam\nremove object ground\nundo\nundo\nselect none\n",
    "select beam\nprobe 10 20\nscreenshot shot.png\nexport frames/ 0..4 24\nexport out.gif 0..2 12\n",
    // Once spun: a frame in flight on the CPU when the backend changes.
    "backend cpu\nwait 1\nbackend gpu\nquit\n",
    // The largest size a script may ask for, and nothing.
    "resize 16384 16384\nwait 1\nresize 0 0\nresize 1 1\n",
    "select nobody\nfire nobody\nset wave.nobody.alpha 1\nkey camera.nothing\nremove wave nobody\n",
    "set camera.fov 179.999\nset camera.position 1e6 -1e6 1e6\nset camera.target 0 0 0\nzoom 1e-30\norbit 1e30 -1e30\n",
    "time 3.4e38\nset wave.beam.alpha_s 1e5\nfire beam 1e-30\nwait 100000\n",
    "export out.gif 0..100000 0.001\nprobe 4294967295 4294967295\npan 1e38 -1e38\n",
];

const EXTREMES: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "1e38",
    "-1e38",
    "3.5e38",
    "1e-45",
    "nan",
    "inf",
    "-inf",
    "16385",
    "4294967296",
    "1e6",
];

fn env_u64(key: &str) -> Option<u64> {
    std::env::var(key).ok().and_then(|v| v.trim().parse().ok())
}

/// One random mutation of a script's text.
fn mutate(rng: &mut Rng, text: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    if lines.is_empty() {
        lines.push(String::new());
    }
    let i = rng.below(lines.len());
    match rng.below(7) {
        0 => {
            let mut b = lines[i].clone().into_bytes();
            if !b.is_empty() {
                let k = rng.below(b.len());
                b[k] ^= 1 << rng.below(8);
            }
            lines[i] = String::from_utf8_lossy(&b).into_owned();
        }
        1 => {
            lines.remove(i);
        }
        2 => {
            let l = lines[i].clone();
            lines.insert(i, l);
        }
        3 => {
            let j = rng.below(lines.len());
            lines.swap(i, j);
        }
        4 | 5 => {
            // A word that parses as a number becomes an extreme value.
            let mut words: Vec<String> = lines[i].split(' ').map(str::to_string).collect();
            let numeric: Vec<usize> = (0..words.len()).filter(|&k| words[k].parse::<f64>().is_ok()).collect();
            if !numeric.is_empty() {
                let k = *rng.pick(&numeric);
                words[k] = rng.pick(EXTREMES).to_string();
            }
            lines[i] = words.join(" ");
        }
        _ => {
            // A word from another line of any script.
            let donor = rng.pick(SCRIPTS);
            let donor_words: Vec<&str> = donor.split_whitespace().collect();
            let mut words: Vec<String> = lines[i].split(' ').map(str::to_string).collect();
            let k = rng.below(words.len());
            words[k] = rng.pick(&donor_words).to_string();
            lines[i] = words.join(" ");
        }
    }
    lines.join("\n")
}

fn one_line(what: &str, msg: &str, script: &Path) -> Result<(), String> {
    if msg.chars().any(char::is_control) {
        return Err(format!("{what} is not one line of text: {msg:?}"));
    }
    if !msg.starts_with(&format!("{}:", script.display())) {
        return Err(format!("{what} does not start with the script's path: {msg:?}"));
    }
    Ok(())
}

/// Runs one script against a fresh viewer of `scene`; `Err` says what went wrong.
fn run_case(scene: &(PathBuf, String), text: &str, script_path: &Path) -> Result<(), String> {
    let lines = match script::parse(text, script_path) {
        Ok(lines) => lines,
        Err(e) => return one_line("parse error", &e, script_path),
    };
    let doc = Document::from_text(&scene.1, &scene.0).map_err(|e| format!("scene failed to load: {e}"))?;
    let mut viewer = Viewer::new(doc);
    for line in &lines {
        // Saving writes where the (mutated) script says; the save paths have tests of their own.
        if matches!(line.command, Command::Save(_)) {
            continue;
        }
        if let Err(e) = script::run(&mut viewer, line, script_path) {
            one_line("command error", &e, script_path)?;
        }
        viewer.tick(1.0 / 60.0);
        let frame = viewer.frame();
        let c = &frame.camera;
        let finite = c.position.is_finite() && c.target.is_finite() && c.fov_y_deg.is_finite();
        if !finite || !viewer.timeline.time.is_finite() {
            return Err(format!("line {}: the viewer's camera or time is not finite: {c:?}", line.line));
        }
    }
    Ok(())
}

#[test]
fn mutated_scripts_run_or_fail_cleanly() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let dir = std::env::temp_dir().join(format!("hadou-script-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("assets")).unwrap();
    std::fs::copy(root.join("assets/crystal.glb"), dir.join("assets/crystal.glb")).unwrap();
    // Copies of example scenes (kamehameha's crystal beside it), so saving and hot reload never
    // touch scenes/.
    let scenes: Vec<(PathBuf, String)> = ["kamehameha.toml", "fig4-2-helix.toml", "soft-overlap.toml"]
        .iter()
        .map(|n| {
            let text = std::fs::read_to_string(root.join(n)).unwrap();
            (dir.join(n), text)
        })
        .collect();
    let script_path = dir.join("script.txt");

    let cases = env_u64("HADOU_FUZZ_CASES").unwrap_or(4000);
    let seed = env_u64("HADOU_FUZZ_SEED").unwrap_or(0x5343_5249_5054);
    println!("script fuzz: {cases} cases, HADOU_FUZZ_SEED={seed}");
    let mut failures = Vec::new();
    for case in 0..cases {
        let case_seed = seed ^ case.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let mut rng = Rng(case_seed);
        let scene = rng.pick(&scenes);
        let mut text = rng.pick(SCRIPTS).to_string();
        // The hand-made scripts run as written first.
        if case >= SCRIPTS.len() as u64 {
            for _ in 0..1 + rng.below(4) {
                text = mutate(&mut rng, &text);
            }
        } else {
            text = SCRIPTS[case as usize].to_string();
        }
        let outcome = catch_unwind(AssertUnwindSafe(|| run_case(scene, &text, &script_path)));
        let why = match outcome {
            Ok(Ok(())) => continue,
            Ok(Err(why)) => why,
            Err(_) => "panicked".to_string(),
        };
        failures.push(format!(
            "case {case} (case seed {case_seed}, run seed {seed}) on {}: {why}\n--- script ---\n{text}",
            scene.0.display()
        ));
        if failures.len() >= 5 {
            break;
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(failures.is_empty(), "{} failure(s):\n\n{}", failures.len(), failures.join("\n\n"));
}
