//! The README stays true: its first command renders the picture it opens with.

mod common;

use std::path::Path;
use std::process::Command;

/// The README's first `cargo run --release -- render …` line, as the arguments after `--`.
fn first_render_command(readme: &str) -> Vec<String> {
    let line = readme
        .lines()
        .find(|l| l.trim_start().starts_with("cargo run --release -- render "))
        .expect("the README gives a render command");
    line.split_once(" -- ").unwrap().1.split_whitespace().map(str::to_string).collect()
}

/// The first picture the README shows (`![…](path)`, possibly over several lines).
fn first_picture(readme: &str) -> String {
    let start = readme.find("![").expect("the README shows a picture");
    let rest = &readme[start..];
    let open = rest.find("](").unwrap() + 2;
    rest[open..open + rest[open..].find(')').unwrap()].to_string()
}

#[test]
fn the_readmes_first_command_renders_its_first_picture() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let args = first_render_command(&readme);
    assert_eq!(args[0], "render");
    let picture = root.join(first_picture(&readme));
    let dir = common::Scratch::new("readme", "first-command");
    // The same command, its output in the scratch directory, on the CPU reference (what `auto`
    // picks on a machine without a GPU, and what the picture was rendered with).
    let mut args: Vec<String> = args;
    let out = args.iter().position(|a| a == "-o").expect("the command names its output") + 1;
    let name = args[out].clone();
    args[out] = dir.join(&name).display().to_string();
    let status = Command::new(env!("CARGO_BIN_EXE_hadou"))
        .current_dir(&root)
        .args(&args)
        .args(["--backend", "cpu"])
        .output()
        .expect("binary runs");
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    let (w, h, ours) = common::decode_png(&dir.join(&name));
    let (pw, ph, theirs) = common::decode_png(&picture);
    assert_eq!((w, h), (pw, ph), "{} has the command's size", picture.display());
    let diff: u64 = ours.iter().zip(&theirs).map(|(a, b)| u64::from(a.abs_diff(*b))).sum();
    let mean = diff as f64 / ours.len() as f64;
    // The CPU backend is deterministic: a picture taken from an older scene or renderer differs
    // by far more than this.
    assert!(mean <= 0.5, "{} is {mean:.3} from what the README's command renders now", picture.display());
}
