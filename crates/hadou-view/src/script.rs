//! `hadou view SCENE --script FILE`: drives the viewer from a text file, one command per line,
//! for tests and reproducible demos. `#` starts a comment. Commands run in order, each in its own
//! window frame; `wait N` lets `N` frames pass. The viewer exits after the last command (writing
//! `--screenshot` first, if given). A command that fails stops the run with `file:line:col: …`
//! ([`run`]); one that names a wave, object or parameter the scene does not have lists the names
//! it could be (a clip the object's file lacks: its clips).
//!
//! | command | effect |
//! |---|---|
//! | `wait N` | let `N` window frames pass (N ≤ 100000) |
//! | `time T` | set the time to `T` seconds |
//! | `play`, `pause` | start / stop the clock |
//! | `loop on` / `loop off` | wrap at the end of the animation, or stop there |
//! | `set TARGET V…` | edit a whole parameter (`wave.beam.length 3`, `camera.position 0 2 9`); keyed when it has a track |
//! | `key TARGET`, `unkey TARGET` | set / remove the key at the current time |
//! | `fire WAVE [SECONDS]` | the firing preset from the current time |
//! | `orbit YAW PITCH`, `pan DX DY`, `zoom F` | camera moves (degrees; fractions of the view; distance factor) |
//! | `undo`, `redo` | |
//! | `add wave KIND`, `add object KIND`, `remove wave NAME`, `remove object NAME` | |
//! | `select WAVE`, `select none` | whose handles show |
//! | `clip OBJECT CLIP`, `clip OBJECT` | the object plays its glTF clip `CLIP` on the scene's clock / rests (the clip chooser) |
//! | `spring OBJECT on\|off` | the object's VRM spring bones move / stay at rest (its `spring` key) |
//! | `look_at OBJECT none\|camera\|WAVE`, `look_at OBJECT X Y Z` | what the object's VRM eyes follow (its `look_at` key) |
//! | `probe X Y` | probe the pixel `(X, Y)` of the image |
//! | `backend cpu` / `backend gpu` | switch the renderer |
//! | `resize W H` | resize the window (0 0 minimises it to nothing) |
//! | `save`, `save PATH` | save the scene (to `PATH`: save as) |
//! | `screenshot PATH` | write the viewport as `hadou render` would (PNG or EXR) |
//! | `export PATH A..B FPS` | export frames `A..B` as a PNG sequence (`PATH/`) or GIF |
//! | `quit` | stop here |

use crate::document::Gaze;
use crate::viewer::{BackendKind, Request, Viewer};
use hadou_scene::escape_controls;
use std::path::{Path, PathBuf};

/// One parsed command.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// `wait N`.
    Wait(u32),
    /// `time T`.
    Time(f32),
    /// `play` (true) / `pause` (false).
    Play(bool),
    /// `loop on|off`.
    Loop(bool),
    /// `set TARGET V…`.
    Set(String, Vec<f32>),
    /// `key TARGET`.
    Key(String),
    /// `unkey TARGET`.
    Unkey(String),
    /// `fire WAVE [SECONDS]`.
    Fire(String, Option<f32>),
    /// `orbit YAW PITCH`.
    Orbit(f32, f32),
    /// `pan DX DY`.
    Pan(f32, f32),
    /// `zoom F`.
    Zoom(f32),
    /// `undo`.
    Undo,
    /// `redo`.
    Redo,
    /// `add wave KIND` (true) / `add object KIND` (false).
    Add(bool, String),
    /// `remove wave NAME` (true) / `remove object NAME` (false).
    Remove(bool, String),
    /// `select WAVE` / `select none`.
    Select(Option<String>),
    /// `clip OBJECT [CLIP]`.
    Clip(String, Option<String>),
    /// `spring OBJECT on|off`.
    Spring(String, bool),
    /// `look_at OBJECT none|camera|WAVE|X Y Z`.
    LookAt(String, Gaze),
    /// `probe X Y`.
    Probe(u32, u32),
    /// `backend cpu|gpu`.
    Backend(BackendKind),
    /// `resize W H`.
    Resize(u32, u32),
    /// `save [PATH]`.
    Save(Option<PathBuf>),
    /// `screenshot PATH`.
    Screenshot(PathBuf),
    /// `export PATH A..B FPS`.
    Export(PathBuf, std::ops::Range<u32>, f32),
    /// `quit`.
    Quit,
}

/// A command with the line it came from (1-based).
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    /// Line number.
    pub line: usize,
    /// The column (1-based, in bytes) of each word: the command's, then each argument's.
    pub cols: Vec<usize>,
    /// The command.
    pub command: Command,
}

impl Line {
    /// The column of argument `k` (the command's own when there is no such argument).
    pub fn arg_col(&self, k: usize) -> usize {
        self.cols.get(k.saturating_add(1)).or(self.cols.first()).copied().unwrap_or(1)
    }
}

/// Parses a script; errors read `file:line:col: message`. Paths in the script are relative to
/// the script's directory.
pub fn parse(text: &str, path: &Path) -> Result<Vec<Line>, String> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("");
        let words: Vec<(usize, &str)> = words(line);
        let Some(&(col, name)) = words.first() else { continue };
        let at = |col: usize, m: String| {
            let place = format!("{}:{}:{}", path.display(), i + 1, col + 1);
            format!("{}: {}", escape_controls(&place), escape_controls(&m))
        };
        let args = &words[1..];
        let command = parse_command(name, args, dir).map_err(|(c, m)| at(c.unwrap_or(col), m))?;
        let cols = words.iter().map(|&(c, _)| c + 1).collect();
        out.push(Line { line: i + 1, cols, command });
    }
    Ok(out)
}

/// Words with their byte columns.
fn words(line: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in line.char_indices() {
        match (c.is_whitespace(), start) {
            (true, Some(s)) => {
                out.push((s, &line[s..i]));
                start = None;
            }
            (false, None) => start = Some(i),
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, &line[s..]));
    }
    out
}

type Fail = (Option<usize>, String);

fn parse_command(name: &str, args: &[(usize, &str)], dir: &Path) -> Result<Command, Fail> {
    let count = |n: std::ops::RangeInclusive<usize>, usage: &str| -> Result<(), Fail> {
        if n.contains(&args.len()) {
            Ok(())
        } else {
            Err((None, format!("`{name}` takes {usage}")))
        }
    };
    let num = |k: usize| -> Result<f32, Fail> {
        let (c, w) = args[k];
        match w.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err((Some(c), format!("`{w}` is not a finite number"))),
        }
    };
    let int = |k: usize, max: u32| -> Result<u32, Fail> {
        let (c, w) = args[k];
        match w.parse::<u32>() {
            Ok(v) if v <= max => Ok(v),
            _ => Err((Some(c), format!("`{w}` is not a whole number in 0..={max}"))),
        }
    };
    let path = |k: usize| dir.join(args[k].1);
    let kind = |k: usize| -> Result<bool, Fail> {
        match args[k].1 {
            "wave" => Ok(true),
            "object" => Ok(false),
            w => Err((Some(args[k].0), format!("expected `wave` or `object`, got `{w}`"))),
        }
    };
    Ok(match name {
        "wait" => {
            count(1..=1, "one number of frames")?;
            Command::Wait(int(0, 100_000)?)
        }
        "time" => {
            count(1..=1, "one time in seconds")?;
            let t = num(0)?;
            if t < 0.0 {
                return Err((Some(args[0].0), "times are ≥ 0 seconds".into()));
            }
            Command::Time(t)
        }
        "play" | "pause" => {
            count(0..=0, "no arguments")?;
            Command::Play(name == "play")
        }
        "loop" => {
            count(1..=1, "`on` or `off`")?;
            match args[0].1 {
                "on" => Command::Loop(true),
                "off" => Command::Loop(false),
                w => return Err((Some(args[0].0), format!("expected `on` or `off`, got `{w}`"))),
            }
        }
        "set" => {
            count(2..=4096, "a target and its value's numbers")?;
            let v = (1..args.len()).map(num).collect::<Result<Vec<_>, _>>()?;
            Command::Set(args[0].1.to_string(), v)
        }
        "key" | "unkey" => {
            count(1..=1, "one target")?;
            let t = args[0].1.to_string();
            if name == "key" {
                Command::Key(t)
            } else {
                Command::Unkey(t)
            }
        }
        "fire" => {
            count(1..=2, "a wave name and optionally a duration in seconds")?;
            let d = if args.len() == 2 { Some(num(1)?) } else { None };
            Command::Fire(args[0].1.to_string(), d)
        }
        "orbit" | "pan" => {
            count(2..=2, "two numbers")?;
            let (a, b) = (num(0)?, num(1)?);
            if name == "orbit" {
                Command::Orbit(a, b)
            } else {
                Command::Pan(a, b)
            }
        }
        "zoom" => {
            count(1..=1, "one factor > 0")?;
            let f = num(0)?;
            if f <= 0.0 {
                return Err((Some(args[0].0), "the zoom factor must be > 0".into()));
            }
            Command::Zoom(f)
        }
        "undo" | "redo" | "quit" => {
            count(0..=0, "no arguments")?;
            match name {
                "undo" => Command::Undo,
                "redo" => Command::Redo,
                _ => Command::Quit,
            }
        }
        "add" | "remove" => {
            count(2..=2, "`wave` or `object` and a kind or name")?;
            let wave = kind(0)?;
            let w = args[1].1.to_string();
            if name == "add" {
                Command::Add(wave, w)
            } else {
                Command::Remove(wave, w)
            }
        }
        "select" => {
            count(1..=1, "a wave name or `none`")?;
            Command::Select((args[0].1 != "none").then(|| args[0].1.to_string()))
        }
        "clip" => {
            count(1..=2, "an object name and optionally one of its clips (none: the rest pose)")?;
            Command::Clip(args[0].1.to_string(), args.get(1).map(|a| a.1.to_string()))
        }
        "spring" => {
            count(2..=2, "an object name and `on` or `off`")?;
            let on = match args[1].1 {
                "on" => true,
                "off" => false,
                w => return Err((Some(args[1].0), format!("expected `on` or `off`, got `{w}`"))),
            };
            Command::Spring(args[0].1.to_string(), on)
        }
        "look_at" => {
            let usage = "an object name and `none`, `camera`, a wave's name or a point X Y Z";
            if !matches!(args.len(), 2 | 4) {
                return Err((None, format!("`{name}` takes {usage}")));
            }
            let gaze = match (args.len(), args[1].1) {
                (4, _) => Gaze::Point([num(1)?, num(2)?, num(3)?]),
                (_, "none") => Gaze::None,
                (_, "camera") => Gaze::Camera,
                (_, w) => Gaze::Wave(w.to_string()),
            };
            Command::LookAt(args[0].1.to_string(), gaze)
        }
        "probe" => {
            count(2..=2, "pixel coordinates X Y")?;
            Command::Probe(int(0, 16383)?, int(1, 16383)?)
        }
        "backend" => {
            count(1..=1, "`cpu` or `gpu`")?;
            match args[0].1 {
                "cpu" => Command::Backend(BackendKind::Cpu),
                "gpu" => Command::Backend(BackendKind::Gpu),
                w => return Err((Some(args[0].0), format!("expected `cpu` or `gpu`, got `{w}`"))),
            }
        }
        "resize" => {
            count(2..=2, "a width and a height in pixels")?;
            Command::Resize(int(0, 16384)?, int(1, 16384)?)
        }
        "save" => {
            count(0..=1, "optionally a path")?;
            Command::Save(args.first().map(|_| path(0)))
        }
        "screenshot" => {
            count(1..=1, "an output path (.png or .exr)")?;
            Command::Screenshot(path(0))
        }
        "export" => {
            count(3..=3, "a path, a frame range A..B and the frames per second")?;
            let (c, r) = args[1];
            let bad = || (Some(c), format!("`{r}` is not a frame range like 0..24"));
            let (a, b) = r.split_once("..").ok_or_else(bad)?;
            let (a, b) = (a.parse::<u32>().map_err(|_| bad())?, b.parse::<u32>().map_err(|_| bad())?);
            if a >= b {
                return Err(bad());
            }
            let fps = num(2)?;
            if fps <= 0.0 {
                return Err((Some(args[2].0), "frames per second must be > 0".into()));
            }
            Command::Export(path(0), a..b, fps)
        }
        other => {
            return Err((
                None,
                format!(
                    "unknown command `{other}`; commands: wait, time, play, pause, loop, set, key, unkey, fire, \
                     orbit, pan, zoom, undo, redo, add, remove, select, clip, spring, look_at, probe, backend, resize, save, screenshot, \
                     export, quit"
                ),
            ))
        }
    })
}

/// What the window must do for a command the viewer state cannot carry out itself.
#[derive(Clone, Debug, PartialEq)]
pub enum WindowOp {
    /// Nothing: the state took it.
    None,
    /// Let this many frames pass.
    Wait(u32),
    /// Resize the window's inner size.
    Resize(u32, u32),
    /// Stop running the script and exit.
    Quit,
}

/// Carries out one command on the viewer. Failures of edits are errors (a script that does not
/// do what it says should not pass silently): `Err` has the message, prefixed by
/// `file:line:col:`. A command naming a wave, object or parameter the scene does not have
/// (`select`, `fire`, `set`, `key`, `unkey`, `remove`, `clip`, `spring`, `look_at`) fails before it does anything, at the
/// name's column, listing the names it could be.
pub fn run(viewer: &mut Viewer, line: &Line, path: &Path) -> Result<WindowOp, String> {
    viewer.message = None;
    let at = |k: Option<usize>, m: &str| {
        let col = match k {
            Some(k) => line.arg_col(k),
            None => line.cols.first().copied().unwrap_or(1),
        };
        let place = format!("{}:{}:{col}", path.display(), line.line);
        format!("{}: {}", escape_controls(&place), escape_controls(m))
    };
    let named = match &line.command {
        Command::Set(target, _) | Command::Key(target) => viewer.check_target(target),
        Command::Unkey(target) => viewer.check_target(target).and_then(|()| viewer.check_track(target)),
        Command::Fire(wave, _) | Command::Select(Some(wave)) => viewer.check_wave(wave),
        Command::Remove(true, name) => viewer.check_wave(name),
        Command::Remove(false, name)
        | Command::Clip(name, _)
        | Command::Spring(name, _)
        | Command::LookAt(name, _) => viewer.check_object(name),
        _ => Ok(()),
    };
    if let Err(m) = named {
        let k = if matches!(line.command, Command::Remove(..)) { 1 } else { 0 };
        return Err(at(Some(k), &m));
    }
    let ok = match &line.command {
        Command::Wait(n) => return Ok(WindowOp::Wait(*n)),
        Command::Resize(w, h) => return Ok(WindowOp::Resize(*w, *h)),
        Command::Quit => return Ok(WindowOp::Quit),
        Command::Time(t) => {
            viewer.timeline.time = *t;
            true
        }
        Command::Play(p) => {
            viewer.timeline.playing = *p;
            true
        }
        Command::Loop(l) => {
            viewer.timeline.looping = *l;
            true
        }
        Command::Set(target, v) => viewer.edit_value(target, v.clone(), None),
        Command::Key(target) => viewer.key_current(target),
        Command::Unkey(target) => viewer.unkey_current(target),
        Command::Fire(wave, d) => {
            if let Some(d) = d {
                viewer.fire_duration = *d;
            }
            viewer.fire(wave)
        }
        Command::Orbit(a, b) => viewer.orbit(*a, *b),
        Command::Pan(a, b) => viewer.pan(*a, *b),
        Command::Zoom(f) => viewer.zoom(*f),
        Command::Undo => viewer.doc.undo(),
        Command::Redo => viewer.doc.redo(),
        Command::Add(wave, kind) => {
            let frame = viewer.frame();
            let at = frame.camera.target.to_array();
            let edit = if *wave {
                crate::document::Edit::AddWave { kind: kind.clone(), at }
            } else {
                crate::document::Edit::AddObject { kind: kind.clone(), at }
            };
            viewer.apply(edit)
        }
        Command::Remove(wave, name) => viewer.apply(if *wave {
            crate::document::Edit::RemoveWave(name.clone())
        } else {
            crate::document::Edit::RemoveObject(name.clone())
        }),
        Command::Select(w) => {
            viewer.selected_wave = w.clone();
            true
        }
        Command::Clip(object, clip) => viewer.choose_clip(object, clip.as_deref()),
        Command::Spring(object, on) => viewer.set_spring(object, *on),
        Command::LookAt(object, gaze) => viewer.set_look_at(object, gaze.clone()),
        Command::Probe(x, y) => {
            viewer.requests.push(Request::Probe([*x, *y]));
            true
        }
        Command::Backend(b) => {
            viewer.requests.push(Request::Backend(*b));
            true
        }
        Command::Save(p) => match p {
            Some(p) => match viewer.doc.save_as(p) {
                Ok(()) => true,
                Err(e) => {
                    viewer.complain(e.0);
                    false
                }
            },
            None => {
                viewer.save();
                viewer.message.as_ref().is_none_or(|m| !m.1)
            }
        },
        Command::Screenshot(p) => {
            viewer.requests.push(Request::Screenshot(p.clone()));
            true
        }
        Command::Export(p, frames, fps) => {
            viewer.requests.push(Request::Export { path: p.clone(), frames: frames.clone(), fps: *fps });
            true
        }
    };
    if ok {
        Ok(WindowOp::None)
    } else {
        let why = viewer.message.as_ref().map_or("it did nothing".to_string(), |m| m.0.clone());
        // A clip the object's file lacks, a wave `look_at` cannot name: at that name.
        let k = matches!(line.command, Command::Clip(_, Some(_)) | Command::LookAt(_, Gaze::Wave(_)))
            .then_some(1);
        Err(at(k, &why))
    }
}
