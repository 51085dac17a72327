//! What a render farm needs of a frame on disk (docs/farm.md): each frame carries a stamp — the
//! BLAKE3 hash of the scene file's bytes, the hadou version, the frame number and the settings it
//! was drawn with — in its PNG `tEXt` chunks (an EXR's header text attribute); a frame file is
//! *complete* when it decodes to its last chunk at the expected size, and *the job's own* when its
//! stamp is the expected one. `hadou render --skip-existing` keeps exactly the frames that are
//! both and renders the rest; `hadou validate --frames DIR` reports frames of another scene,
//! version or settings, unreadable files and gaps.
//!
//! Frame names come from a [`FramePattern`] (`frame_#####.png`: the run of `#` is the frame
//! number, zero-padded to at least that many digits).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The `tEXt` keyword of the scene file's BLAKE3 hash, 64 hex digits (in an EXR, a line
/// `KEY=VALUE` of the header's text attribute [`crate::output::EXR_TEXT_ATTRIBUTE`], as the
/// others).
pub const KEY_SCENE: &str = "hadou-scene-blake3";
/// The `tEXt` keyword of the hadou version that drew the frame.
pub const KEY_VERSION: &str = "hadou-version";
/// The `tEXt` keyword of the frame number (absent on a single image rendered at `--time`).
pub const KEY_FRAME: &str = "hadou-frame";
/// The `tEXt` keyword of the settings the frame was drawn with ([`frame_settings`]).
pub const KEY_SETTINGS: &str = "hadou-settings";

/// This hadou's version, as frames record it.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Which scene file, read by which hadou: what every frame of one job shares.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneStamp {
    /// BLAKE3 of the scene file's bytes as they were parsed, lowercase hex.
    pub scene_hash: String,
    /// The hadou version ([`VERSION`] for frames drawn now).
    pub version: String,
}

impl SceneStamp {
    /// The stamp of a scene read from `text` ([`hadou_scene::Scene::read_text`]) by this hadou.
    pub fn of_text(text: &str) -> SceneStamp {
        SceneStamp { scene_hash: blake3::hash(text.as_bytes()).to_hex().to_string(), version: VERSION.into() }
    }

    /// The first 12 hex digits of the hash, for messages.
    pub fn short_hash(&self) -> &str {
        self.scene_hash.get(..12).unwrap_or(&self.scene_hash)
    }
}

/// Everything a frame file records about how it was made.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrameStamp {
    /// The scene file and the hadou version.
    pub scene: SceneStamp,
    /// The frame number of a sequence's frame; `None` for an image rendered at `--time`.
    pub frame: Option<u32>,
    /// The settings ([`frame_settings`]).
    pub settings: String,
}

impl FrameStamp {
    /// The stamp as `(keyword, text)` pairs, in the order they are written.
    pub fn text_chunks(&self) -> Vec<(String, String)> {
        let mut out = vec![
            (KEY_SCENE.to_string(), self.scene.scene_hash.clone()),
            (KEY_VERSION.to_string(), self.scene.version.clone()),
        ];
        if let Some(f) = self.frame {
            out.push((KEY_FRAME.to_string(), f.to_string()));
        }
        out.push((KEY_SETTINGS.to_string(), self.settings.clone()));
        out
    }

    /// The stamp read back from `(keyword, text)` pairs; `None` without a scene hash and a version
    /// (a file hadou did not stamp).
    pub fn from_text_chunks<'a>(chunks: impl IntoIterator<Item = (&'a str, &'a str)>) -> Option<FrameStamp> {
        let map: BTreeMap<&str, &str> = chunks.into_iter().collect();
        Some(FrameStamp {
            scene: SceneStamp {
                scene_hash: map.get(KEY_SCENE)?.to_string(),
                version: map.get(KEY_VERSION)?.to_string(),
            },
            frame: map.get(KEY_FRAME).and_then(|f| f.parse().ok()),
            settings: map.get(KEY_SETTINGS).map_or_else(String::new, |s| s.to_string()),
        })
    }
}

/// The settings a frame records beside its scene: size, samples per pixel, the time (a frame
/// number and its fps, or a time in seconds) and the backend that drew it. Frames of one job
/// share everything but the frame number; two backends draw different bytes, so a job whose nodes
/// differ there (`--backend auto` on a mixed farm) is caught by `hadou validate --frames`.
pub fn frame_settings(frame: &hadou_scene::Frame, when: &str, backend: &str) -> String {
    format!(
        "{}x{}, {} samples, {when}, {backend} backend",
        frame.width,
        frame.height,
        frame.sample_grid().count()
    )
}

/// The file names of a sequence's frames: a name with one run of `#` (`frame_#####.png`), which
/// becomes the frame number zero-padded to at least that many digits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FramePattern {
    prefix: String,
    digits: usize,
    suffix: String,
}

impl Default for FramePattern {
    /// `frame_#####.png`, the names `hadou render --frames` has always written.
    fn default() -> Self {
        FramePattern { prefix: "frame_".into(), digits: 5, suffix: ".png".into() }
    }
}

impl FramePattern {
    /// Parses a pattern: a plain file name (no directory part) ending in `.png`, with exactly one
    /// run of `#` of 1 to 10 characters.
    pub fn parse(text: &str) -> Result<FramePattern, String> {
        let bad = |why: &str| {
            format!(
                "--frame-name {text}: {why}; expected a file name ending in .png with one run of `#` for \
                 the frame number, e.g. shot_####.png"
            )
        };
        if text.chars().any(|c| std::path::is_separator(c) || c.is_control()) {
            return Err(bad("must be a file name, without a directory or control characters"));
        }
        if !text.to_ascii_lowercase().ends_with(".png") {
            return Err(bad("must end in .png"));
        }
        let start = text.find('#').ok_or_else(|| bad("has no `#`"))?;
        let digits = text[start..].chars().take_while(|&c| c == '#').count();
        let suffix = &text[start + digits..];
        if suffix.contains('#') {
            return Err(bad("has more than one run of `#`"));
        }
        if digits > 10 {
            return Err(bad("has more than 10 `#`"));
        }
        if text[..start].starts_with('.') {
            return Err(bad("must not start with `.` (hidden files are hadou's temporary files)"));
        }
        Ok(FramePattern { prefix: text[..start].into(), digits, suffix: suffix.into() })
    }

    /// The file name of frame `f`.
    pub fn name(&self, f: u32) -> String {
        format!("{}{f:0width$}{}", self.prefix, self.suffix, width = self.digits)
    }

    /// The frame number a file name of this pattern holds, if it is one (`name(f) == file`).
    pub fn frame_of(&self, file: &str) -> Option<u32> {
        let digits = file.strip_prefix(&self.prefix)?.strip_suffix(&self.suffix)?;
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let f: u32 = digits.parse().ok()?;
        (self.name(f) == file).then_some(f)
    }
}

impl std::fmt::Display for FramePattern {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}{}{}", self.prefix, "#".repeat(self.digits), self.suffix)
    }
}

/// A PNG frame file read whole: its size and stamp.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrameFile {
    /// Width and height in pixels.
    pub size: (u32, u32),
    /// The stamp, `None` when the file has none (not written by hadou, or by a hadou before
    /// stamps).
    pub stamp: Option<FrameStamp>,
}

/// Reads the PNG at `path` to its last chunk (so a truncated or corrupt file is an error) and
/// returns its size and stamp. A frame written by hadou is renamed into place whole, so an error
/// here means a file from elsewhere or damaged since.
pub fn read_png_frame(path: &Path) -> Result<FrameFile, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("cannot open: {e}"))?;
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .map_err(|e| format!("not a readable PNG ({e})"))?;
    let size = (reader.info().width, reader.info().height);
    // One row at a time: memory follows a row, not the image.
    while reader.next_row().map_err(|e| format!("truncated or corrupt PNG ({e})"))?.is_some() {}
    reader.finish().map_err(|e| format!("truncated or corrupt PNG ({e})"))?;
    let info = reader.info();
    let stamp = FrameStamp::from_text_chunks(
        info.uncompressed_latin1_text.iter().map(|c| (c.keyword.as_str(), c.text.as_str())),
    );
    Ok(FrameFile { size, stamp })
}

/// What `--skip-existing` makes of the file at a frame's path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OnDisk {
    /// Nothing there: render the frame.
    Missing,
    /// A complete frame with the expected size and stamp: keep it.
    Complete,
    /// Something else (truncated, another scene, version or settings, not a hadou frame): render
    /// the frame again, replacing it; the text says why.
    Replace(String),
}

/// Decides [`OnDisk`] for the file at `path`, expected to be a `width × height` frame stamped
/// `expected`.
pub fn check_frame_file(path: &Path, expected: &FrameStamp, size: (u32, u32)) -> OnDisk {
    match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return OnDisk::Missing,
        Err(e) => return OnDisk::Replace(format!("cannot read it ({e})")),
        Ok(m) if !m.is_file() => return OnDisk::Replace("not a regular file".into()),
        Ok(_) => {}
    }
    let file = match read_png_frame(path) {
        Ok(f) => f,
        Err(e) => return OnDisk::Replace(e),
    };
    if file.size != size {
        return OnDisk::Replace(format!("{}x{}, not {}x{}", file.size.0, file.size.1, size.0, size.1));
    }
    match file.stamp {
        None => OnDisk::Replace("no hadou stamp (not a frame hadou wrote)".into()),
        Some(s) if s == *expected => OnDisk::Complete,
        Some(s) => OnDisk::Replace(stamp_difference(&s, expected)),
    }
}

/// How `found` differs from `expected`, in words.
pub fn stamp_difference(found: &FrameStamp, expected: &FrameStamp) -> String {
    let mut why = Vec::new();
    if found.scene.scene_hash != expected.scene.scene_hash {
        why.push(format!(
            "another scene file (blake3 {}…, this one's {}…)",
            found.scene.short_hash(),
            expected.scene.short_hash()
        ));
    }
    if found.scene.version != expected.scene.version {
        why.push(format!("hadou {}, not {}", found.scene.version, expected.scene.version));
    }
    if found.frame != expected.frame {
        let n = |f: Option<u32>| f.map_or_else(|| "none".to_string(), |f| f.to_string());
        why.push(format!("frame number {}, not {}", n(found.frame), n(expected.frame)));
    }
    if found.settings != expected.settings {
        why.push(format!("settings \"{}\", not \"{}\"", found.settings, expected.settings));
    }
    format!("drawn from {}", why.join(", "))
}

/// One problem `hadou validate --frames` reports.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrameProblem {
    /// The file (or, for a gap, the directory).
    pub path: PathBuf,
    /// The frame number, when the problem is one frame's.
    pub frame: Option<u32>,
    /// What is wrong.
    pub message: String,
}

/// What `hadou validate --frames` found in a directory.
#[derive(Clone, Debug, Default)]
pub struct FramesReport {
    /// The frames found, by number, with their stamps (`None`: unreadable or unstamped).
    pub frames: BTreeMap<u32, Option<FrameStamp>>,
    /// Every problem found, in frame order.
    pub problems: Vec<FrameProblem>,
}

/// Checks the frames named by `pattern` in `dir`: each must be a complete PNG stamped by this
/// hadou ([`VERSION`]) from the scene `expected` (when given; otherwise from the scene most of the
/// frames share), with the settings most of them share and its own frame number; the numbers
/// from the lowest to the highest must all be there. Stray temporary files of a killed writer
/// (`.NAME.PID.N.tmp`) are reported too.
pub fn check_frames_dir(
    dir: &Path,
    pattern: &FramePattern,
    expected: Option<&SceneStamp>,
) -> Result<FramesReport, String> {
    if !dir.is_dir() {
        let what = if dir.exists() { "is not a directory" } else { "does not exist" };
        return Err(format!("--frames {}: {what}", dir.display()));
    }
    let listing =
        std::fs::read_dir(dir).map_err(|e| format!("--frames {}: cannot list it: {e}", dir.display()))?;
    let mut found: BTreeMap<u32, PathBuf> = BTreeMap::new();
    let mut stray = Vec::new();
    for entry in listing.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        if let Some(f) = pattern.frame_of(name) {
            found.insert(f, entry.path());
        } else if name.starts_with('.') && name.ends_with(".tmp") {
            // `.frame_00042.png.PID.N.tmp`: a frame's temporary file.
            let inner = name[1..].split(".png.").next().map(|n| format!("{n}.png"));
            if inner.is_some_and(|n| pattern.frame_of(&n).is_some()) {
                stray.push(entry.path());
            }
        }
    }
    if found.is_empty() {
        return Err(format!("--frames {}: no frames named {pattern} in it", dir.display()));
    }
    let mut report = FramesReport::default();
    let mut problems: Vec<(u32, FrameProblem)> = Vec::new();
    for (&f, path) in &found {
        let problem = |message: String| (f, FrameProblem { path: path.clone(), frame: Some(f), message });
        match read_png_frame(path) {
            Err(e) => {
                problems.push(problem(e));
                report.frames.insert(f, None);
            }
            Ok(FrameFile { stamp: None, .. }) => {
                problems.push(problem("no hadou stamp (not a frame hadou wrote)".into()));
                report.frames.insert(f, None);
            }
            Ok(FrameFile { stamp: Some(s), size }) => {
                let s = FrameStamp { settings: format!("{}; {}x{} file", s.settings, size.0, size.1), ..s };
                report.frames.insert(f, Some(s));
            }
        }
    }
    // What most frames share stands for the job where no scene was given.
    let most = |key: &dyn Fn(&FrameStamp) -> String| -> Option<String> {
        let mut counts: BTreeMap<String, usize> = BTreeMap::new();
        for s in report.frames.values().flatten() {
            *counts.entry(key(s)).or_default() += 1;
        }
        counts.into_iter().max_by_key(|(_, n)| *n).map(|(k, _)| k)
    };
    let scene_hash = expected.map(|e| e.scene_hash.clone()).or_else(|| most(&|s| s.scene.scene_hash.clone()));
    let settings = most(&|s| strip_time(&s.settings));
    for (&f, stamp) in &report.frames {
        let Some(s) = stamp else { continue };
        let path = found[&f].clone();
        let mut why = Vec::new();
        if scene_hash.as_deref().is_some_and(|h| h != s.scene.scene_hash) {
            let whose = if expected.is_some() { "the scene file's" } else { "most frames'" };
            why.push(format!(
                "from another scene file (blake3 {}…, {whose} {}…)",
                s.scene.short_hash(),
                scene_hash.as_deref().map_or("", |h| h.get(..12).unwrap_or(h))
            ));
        }
        if s.scene.version != VERSION {
            why.push(format!("drawn by hadou {}, this is hadou {VERSION}", s.scene.version));
        }
        if s.frame != Some(f) {
            let n = s.frame.map_or_else(|| "none".to_string(), |n| n.to_string());
            why.push(format!("its stamp says frame {n}"));
        }
        if settings.as_deref().is_some_and(|m| m != strip_time(&s.settings)) {
            why.push(format!(
                "other settings ({}; most frames: {})",
                s.settings,
                settings.as_deref().unwrap_or("")
            ));
        }
        if !why.is_empty() {
            problems.push((f, FrameProblem { path, frame: Some(f), message: why.join("; ") }));
        }
    }
    let (lo, hi) = (*found.keys().next().unwrap_or(&0), *found.keys().last().unwrap_or(&0));
    let mut gap: Option<(u32, u32)> = None;
    let mut gaps = Vec::new();
    for f in lo..=hi {
        if found.contains_key(&f) {
            if let Some(g) = gap.take() {
                gaps.push(g);
            }
        } else {
            gap = Some(gap.map_or((f, f), |(a, _)| (a, f)));
        }
    }
    for (a, b) in gaps {
        let which = if a == b { format!("frame {a} is") } else { format!("frames {a}..={b} are") };
        problems.push((
            a,
            FrameProblem {
                path: dir.to_path_buf(),
                frame: Some(a),
                message: format!("{which} missing (the sequence has frames {lo}..={hi})"),
            },
        ));
    }
    for path in stray {
        problems.push((
            u32::MAX,
            FrameProblem {
                path,
                frame: None,
                message: "a partial frame left by a writer that was killed (safe to delete once no hadou writes here)"
                    .into(),
            },
        ));
    }
    problems.sort_by_key(|(f, _)| *f);
    report.problems = problems.into_iter().map(|(_, p)| p).collect();
    Ok(report)
}

/// A sequence's settings without the frame's own time, so frames of one job compare equal.
fn strip_time(settings: &str) -> String {
    settings.split(", ").filter(|part| !part.starts_with("t=")).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_name_and_read_back_frames() {
        let p = FramePattern::default();
        assert_eq!(p.name(42), "frame_00042.png");
        assert_eq!(p.name(1234567), "frame_1234567.png");
        assert_eq!(p.frame_of("frame_00042.png"), Some(42));
        assert_eq!(p.frame_of("frame_42.png"), None, "not the name frame 42 gets");
        assert_eq!(p.frame_of("frame_0004x.png"), None);
        let q = FramePattern::parse("shot_##.v1.png").unwrap();
        assert_eq!(q.name(7), "shot_07.v1.png");
        assert_eq!(q.to_string(), "shot_##.v1.png");
        for bad in ["a/#.png", "frame.png", "f_##_##.png", "f_#.exr", ".f_#.png", "f_###########.png"] {
            assert!(FramePattern::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn stamps_round_trip_and_name_their_differences() {
        let scene = SceneStamp::of_text("[image]\nwidth = 8\n");
        assert_eq!(scene.scene_hash.len(), 64);
        assert_ne!(scene, SceneStamp::of_text("[image]\nwidth = 9\n"));
        let s = FrameStamp { scene, frame: Some(3), settings: "8x8, 4 samples, t=3/24, cpu backend".into() };
        let chunks = s.text_chunks();
        let back = FrameStamp::from_text_chunks(chunks.iter().map(|(k, v)| (k.as_str(), v.as_str())));
        assert_eq!(back.as_ref(), Some(&s));
        let other = FrameStamp { scene: SceneStamp::of_text("x"), frame: Some(4), ..s.clone() };
        let d = stamp_difference(&other, &s);
        assert!(d.contains("another scene file") && d.contains("frame number 4, not 3"), "{d}");
        assert_eq!(FrameStamp::from_text_chunks([("hadou-frame", "3")]), None);
    }
}
