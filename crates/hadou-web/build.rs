//! Embeds every example scene and the asset files they name (`scenes/*.toml`, `scenes/assets/*`
//! but the scripts that make them) into the page as presets: writes `presets.rs` into `OUT_DIR`
//! with one `include_bytes!` per file.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn main() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    println!("cargo:rerun-if-changed={}", scenes.display());
    let mut files = Vec::new();
    collect(&scenes, &scenes, &mut files);
    files.sort();
    let mut out = String::from(
        "/// Every file of `scenes/` the page embeds: its path under `scenes/` and its bytes.\n",
    );
    out.push_str("pub(crate) static FILES: &[(&str, &[u8])] = &[\n");
    for (rel, abs) in &files {
        writeln!(out, "    ({rel:?}, include_bytes!({:?})),", abs.display().to_string()).unwrap();
    }
    out.push_str("];\n");
    let dest = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("presets.rs");
    std::fs::write(dest, out).expect("writing presets.rs");
}

fn collect(root: &Path, dir: &Path, out: &mut Vec<(String, PathBuf)>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let path = e.path();
        println!("cargo:rerun-if-changed={}", path.display());
        if path.is_dir() {
            collect(root, &path, out);
            continue;
        }
        let ext = path.extension().and_then(|x| x.to_str()).unwrap_or("");
        // The scripts that make the assets are not assets.
        if ext == "py" || ext.is_empty() {
            continue;
        }
        let rel = path.strip_prefix(root).expect("under the root").to_string_lossy().replace('\\', "/");
        let abs = path.canonicalize().expect("an existing file");
        out.push((rel, abs));
    }
}
