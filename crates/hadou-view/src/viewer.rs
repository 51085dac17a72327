//! The viewer's state apart from the window: the document, the timeline, the camera moves, the
//! gizmo handles, what is shown on screen and what the window should do next ([`Request`]).
//! Everything here is plain data and runs in tests without a window.

use crate::document::{DocError, Document, Edit, Gaze, Reload};
use hadou_math::Vec3f;
use hadou_scene::{CharacterInfo, Frame, ParamShape, Scene};
use std::path::PathBuf;

/// The animation clock.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timeline {
    /// Scene time shown, seconds (≥ 0).
    pub time: f32,
    /// Whether time advances.
    pub playing: bool,
    /// Whether playing wraps to 0 after the scene's duration (else it stops there).
    pub looping: bool,
    /// Seconds of scene time per second of wall time.
    pub speed: f32,
}

impl Default for Timeline {
    fn default() -> Self {
        Timeline { time: 0.0, playing: false, looping: true, speed: 1.0 }
    }
}

impl Timeline {
    /// Advances by `dt` seconds of wall time in a scene lasting `duration` seconds (a static
    /// scene, `duration = 0`, keeps time 0). Non-finite or negative `dt` does nothing.
    pub fn advance(&mut self, dt: f32, duration: f32) {
        if !(self.playing && dt.is_finite() && dt > 0.0) {
            return;
        }
        let end = if duration.is_finite() { duration.max(0.0) } else { 0.0 };
        if end == 0.0 {
            self.time = 0.0;
            return;
        }
        let t = self.time + dt * self.speed;
        if t <= end {
            self.time = t.max(0.0);
        } else if self.looping {
            self.time = t % end;
        } else {
            self.time = end;
            self.playing = false;
        }
    }
}

/// Which renderer draws the viewport.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BackendKind {
    /// The CPU reference backend, its image uploaded as a texture.
    Cpu,
    /// The GPU backend, drawing into a texture the window shows (no read-back).
    Gpu,
}

impl BackendKind {
    /// `"CPU"` or `"GPU"`.
    pub fn label(self) -> &'static str {
        match self {
            BackendKind::Cpu => "CPU",
            BackendKind::Gpu => "GPU",
        }
    }
}

/// What the window should do, asked by the panel or a script.
#[derive(Clone, Debug, PartialEq)]
pub enum Request {
    /// Write the viewport (the renderer's image at the scene's size and the current time) as
    /// PNG or EXR, as `hadou render` would.
    Screenshot(PathBuf),
    /// Export frames `frames` at `fps` as a PNG sequence (a directory path ending in `/`) or a GIF.
    Export {
        /// Where to.
        path: PathBuf,
        /// Frame numbers, end excluded.
        frames: std::ops::Range<u32>,
        /// Frames per second.
        fps: f32,
    },
    /// Stop the running export.
    CancelExport,
    /// Hand the scene's text to the user as a download named like the scene file (what Save does
    /// in the web page, [`Viewer::save_downloads`]).
    DownloadScene,
    /// Probe the pixel (image coordinates of the scene's size).
    Probe([u32; 2]),
    /// Draw with this backend.
    Backend(BackendKind),
    /// Time the GPU backend on the current frame (GPU timestamps per pass where the adapter has
    /// them, else submit-and-wait wall clock); the figures go to [`Stats`].
    MeasureGpu,
    /// Close the window.
    Quit,
}

/// Timing and identity figures shown on screen.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stats {
    /// The backend drawing now.
    pub backend: Option<BackendKind>,
    /// Why it was chosen (automatic choice) or `"chosen by you"`.
    pub backend_note: String,
    /// The GPU adapter's name (the window's device).
    pub adapter: String,
    /// Wall time between the last two window frames, ms.
    pub frame_ms: f64,
    /// The renderer's time for the last image, ms (GPU timestamps where available).
    pub render_ms: f64,
    /// How that was measured.
    pub render_method: String,
    /// The viewer's own time for the last new image on top of rendering (frame evaluation, and
    /// on the CPU path the sRGB conversion and the upload), ms.
    pub overhead_ms: f64,
    /// Building and drawing the UI in the last frame, ms.
    pub ui_ms: f64,
}

impl Stats {
    /// Takes the GPU's own time of frame `serial` (timestamps: the whole frame and each pass, in
    /// ms) as the render time shown.
    pub fn gpu_timestamps<'a>(
        &mut self,
        serial: u64,
        frame_ms: f64,
        passes: impl IntoIterator<Item = (&'a str, f64)>,
    ) {
        let passes: Vec<String> = passes.into_iter().map(|(name, ms)| format!("{name} {ms:.2} ms")).collect();
        self.render_ms = frame_ms;
        self.render_method = format!("GPU timestamps of frame {serial}: {}", passes.join(", "));
    }
}

/// A draggable point of a wave in the viewport.
#[derive(Clone, Debug, PartialEq)]
pub struct Handle {
    /// The wave.
    pub wave: String,
    /// What dragging it edits.
    pub what: HandleKind,
    /// Its position in the world at the current time.
    pub world: Vec3f,
}

/// What a [`Handle`] moves.
#[derive(Clone, Debug, PartialEq)]
pub enum HandleKind {
    /// A world point parameter (`M`, `M2`, `O`).
    Point(&'static str),
    /// A beam's head given by `D` + `length`: moving it sets both.
    Head,
    /// Control point `i` of `points` (local `[y, z]` in the curve's frame).
    Control(usize),
}

/// What the clip chooser offers for one glTF object whose file has clips.
#[derive(Clone, Debug, PartialEq)]
pub struct ClipChoice {
    /// The object's name.
    pub object: String,
    /// Its file's clips: name and length in seconds.
    pub clips: Vec<(String, f32)>,
    /// The clip it plays, if any.
    pub playing: Option<String>,
}

/// The viewer's state.
pub struct Viewer {
    /// The scene document.
    pub doc: Document,
    /// The clock.
    pub timeline: Timeline,
    /// A message for the status line and whether it is an error.
    pub message: Option<(String, bool)>,
    /// The wave whose handles show (all waves when `None`).
    pub selected_wave: Option<String>,
    /// Figures on screen.
    pub stats: Stats,
    /// The last probe's text.
    pub probe: Option<String>,
    /// The pixel the last probe was taken at (marked in the viewport).
    pub probe_at: Option<[u32; 2]>,
    /// What the window should do next; it drains this each frame.
    pub requests: Vec<Request>,
    /// A running export's progress `(done, total)`.
    pub export_progress: Option<(u32, u32)>,
    /// The firing preset's duration, seconds.
    pub fire_duration: f32,
    /// Frames per second for exports.
    pub export_fps: f32,
    /// Where screenshots and exports go (typed in the panel).
    pub export_path: String,
    /// Where a screenshot goes (typed in the panel).
    pub screenshot_path: String,
    /// What Save does: `false` (the native viewer) writes the scene file; `true` (the web page,
    /// which has no file to write) asks for a download of the text ([`Request::DownloadScene`]).
    pub save_downloads: bool,
}

impl Viewer {
    /// A viewer on `doc` at time 0, paused.
    pub fn new(doc: Document) -> Viewer {
        let stem = doc
            .path()
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into());
        Viewer {
            doc,
            timeline: Timeline::default(),
            message: None,
            selected_wave: None,
            stats: Stats::default(),
            probe: None,
            probe_at: None,
            requests: Vec::new(),
            export_progress: None,
            fire_duration: 1.0,
            export_fps: 24.0,
            export_path: format!("{stem}.gif"),
            screenshot_path: format!("{stem}.png"),
            save_downloads: false,
        }
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        self.doc.scene()
    }

    /// The frame to draw now (the scene at the timeline's time, at the scene's image size).
    pub fn frame(&self) -> Frame {
        self.doc.scene().at(self.timeline.time)
    }

    /// The scene's duration (its tracks, and the clips its objects play once) with a floor of
    /// one second, for the scrub bar.
    pub fn scrub_end(&self) -> f32 {
        self.scene().duration().max(1.0)
    }

    /// Advances the clock by `dt` seconds of wall time.
    pub fn tick(&mut self, dt: f32) {
        let d = self.scene().duration();
        self.timeline.advance(dt, d);
    }

    /// The clip choices of each object whose glTF file has clips, in file order.
    pub fn clip_objects(&self) -> Vec<ClipChoice> {
        let scene = self.scene();
        let names = scene.object_names();
        scene
            .object_clips()
            .into_iter()
            .enumerate()
            .filter(|(_, clips)| !clips.is_empty())
            .map(|(i, clips)| ClipChoice {
                object: names.get(i).map_or_else(String::new, |n| n.to_string()),
                clips,
                playing: scene.object_clip_at(i, self.timeline.time).map(|c| c.0),
            })
            .collect()
    }

    /// The clip object `object` plays and its clip time at the current time, if it plays one.
    pub fn clip_now(&self, object: &str) -> Option<(String, f32)> {
        let i = self.scene().object_names().iter().position(|n| *n == object)?;
        self.scene().object_clip_at(i, self.timeline.time)
    }

    /// Makes `object` play `clip` (its `animation` key), or rest (`None`: [`Edit::Clip`]); one
    /// undo step. A clip its file lacks is refused with the loader's list of its clips.
    pub fn choose_clip(&mut self, object: &str, clip: Option<&str>) -> bool {
        self.apply(Edit::Clip { object: object.to_string(), clip: clip.map(str::to_string) })
    }

    /// The objects whose VRM file has spring bones or look-at, with their `spring` and `look_at`.
    pub fn characters(&self) -> Vec<CharacterInfo> {
        self.scene().characters()
    }

    /// Turns `object`'s spring bones on or off (its `spring` key); one undo step.
    pub fn set_spring(&mut self, object: &str, on: bool) -> bool {
        self.apply(Edit::Spring { object: object.to_string(), on })
    }

    /// Makes `object`'s eyes follow `gaze` (its `look_at` key); one undo step. A wave the scene
    /// lacks is refused with the loader's list of the waves.
    pub fn set_look_at(&mut self, object: &str, gaze: Gaze) -> bool {
        self.apply(Edit::LookAt { object: object.to_string(), gaze })
    }

    /// The point `object`'s eyes follow now (world space), as a `look_at` point that keeps them
    /// there: where its `look_at` leads at the current time, or the camera's position when it has
    /// none.
    pub fn gaze_point(&self, object: &str) -> [f32; 3] {
        let t = self.timeline.time;
        self.scene()
            .look_at_point(object, t)
            .or_else(|| self.v3("camera.position").map(Vec3f::to_array))
            .unwrap_or([0.0; 3])
    }

    /// Shows `m` in the status line.
    pub fn say(&mut self, m: impl Into<String>) {
        self.message = Some((m.into(), false));
    }

    /// Shows `m` as an error in the status line.
    pub fn complain(&mut self, m: impl Into<String>) {
        self.message = Some((m.into(), true));
    }

    fn report(&mut self, r: Result<(), DocError>) -> bool {
        match r {
            Ok(()) => true,
            Err(e) => {
                self.complain(e.0);
                false
            }
        }
    }

    /// Applies a document edit, showing a refusal in the status line; `true` when applied.
    pub fn apply(&mut self, edit: Edit) -> bool {
        let r = self.doc.apply(&edit);
        self.report(r)
    }

    /// Edits the whole parameter `target` as it is at the current time: a parameter with a track
    /// of its own gets a key at the current time (so the edit shows, and stays); any other is
    /// set in its table. `merge` groups a drag into one undo step.
    pub fn edit_value(&mut self, target: &str, value: Vec<f32>, merge: Option<&str>) -> bool {
        let keyed = self.scene().tracks().iter().any(|t| t.target == target);
        let edit = if keyed {
            Edit::Key { target: target.to_string(), time: self.timeline.time, value }
        } else {
            Edit::Set { target: target.to_string(), value }
        };
        let r = self.doc.apply_merged(&edit, merge);
        self.report(r)
    }

    /// `Ok` when the scene has the whole parameter `target`; otherwise the message names it and
    /// lists what it could be: the parameters of its table when the table exists, else the tables.
    pub fn check_target(&self, target: &str) -> Result<(), String> {
        let params = self.scene().parameters();
        if params.iter().any(|p| p.target == target) {
            return Ok(());
        }
        let table = target.rsplit_once('.').map_or("", |(t, _)| t);
        let keys: Vec<&str> = params
            .iter()
            .filter(|p| p.target.rsplit_once('.').map_or("", |(t, _)| t) == table)
            .map(|p| p.key)
            .collect();
        let hint = if !keys.is_empty() {
            let whose = if table.is_empty() { "the top level".to_string() } else { format!("`{table}`") };
            format!("; {whose} has {}", listed(&keys))
        } else {
            let mut tables: Vec<&str> =
                params.iter().filter_map(|p| p.target.rsplit_once('.').map(|(t, _)| t)).collect();
            tables.dedup();
            format!(
                "; `{}` is none of the scene's tables, which are {}",
                table.escape_debug(),
                listed(&tables)
            )
        };
        Err(format!("the scene has no parameter `{}`{hint}", target.escape_debug()))
    }

    /// `Ok` when a track animates the whole parameter `target`; otherwise the message lists the
    /// animated parameters.
    pub fn check_track(&self, target: &str) -> Result<(), String> {
        let tracks = self.scene().tracks();
        if tracks.iter().any(|t| t.target == target) {
            return Ok(());
        }
        let mut animated: Vec<&str> = tracks.iter().map(|t| t.target.as_str()).collect();
        animated.dedup();
        let hint = if animated.is_empty() {
            "; nothing is animated".into()
        } else {
            format!("; the tracks animate {}", listed(&animated))
        };
        Err(format!("no track animates `{}`{hint}", target.escape_debug()))
    }

    /// `Ok` when the scene has a wave named `name`; otherwise the message lists the waves.
    pub fn check_wave(&self, name: &str) -> Result<(), String> {
        let names = self.scene().wave_names();
        if names.contains(&name) {
            return Ok(());
        }
        Err(format!("no wave is named {name:?}; the waves are {}", listed(&names)))
    }

    /// `Ok` when the scene has an object named `name`; otherwise the message lists the objects.
    pub fn check_object(&self, name: &str) -> Result<(), String> {
        let names = self.scene().object_names();
        if names.contains(&name) {
            return Ok(());
        }
        Err(format!("no object is named {name:?}; the objects are {}", listed(&names)))
    }

    /// Sets a key at the current time holding `target`'s current value.
    pub fn key_current(&mut self, target: &str) -> bool {
        let Some(value) = self.scene().value_at(target, self.timeline.time) else {
            self.complain(format!("the scene has no parameter `{target}`"));
            return false;
        };
        self.apply(Edit::Key { target: target.to_string(), time: self.timeline.time, value })
    }

    /// Removes `target`'s key at the current time.
    pub fn unkey_current(&mut self, target: &str) -> bool {
        self.apply(Edit::RemoveKey { target: target.to_string(), time: self.timeline.time })
    }

    /// The firing preset on `wave`, starting at the current time.
    pub fn fire(&mut self, wave: &str) -> bool {
        let edit =
            Edit::Fire { wave: wave.to_string(), start: self.timeline.time, duration: self.fire_duration };
        self.apply(edit)
    }

    /// Undo, reporting when there is nothing to undo.
    pub fn undo(&mut self) {
        if !self.doc.undo() {
            self.say("nothing to undo");
        }
    }

    /// Redo, reporting when there is nothing to redo.
    pub fn redo(&mut self) {
        if !self.doc.redo() {
            self.say("nothing to redo");
        }
    }

    /// Saves, reporting the outcome.
    pub fn save(&mut self) {
        if self.save_downloads {
            self.requests.push(Request::DownloadScene);
            self.doc.mark_saved();
            let name =
                self.doc.path().file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            self.say(format!("downloading {name}"));
            return;
        }
        match self.doc.save() {
            Ok(()) => {
                let m = format!("saved {}", self.doc.path().display());
                self.say(m);
            }
            Err(e) => self.complain(e.0),
        }
    }

    /// Takes in a new version of the file saved by another program; `true` when something
    /// changed (the scene was reloaded, or the reload failed and says so).
    pub fn poll_disk(&mut self) -> bool {
        match self.doc.poll_disk() {
            Reload::Unchanged => false,
            Reload::Reloaded => {
                let m = format!("reloaded {}", self.doc.path().display());
                self.say(m);
                true
            }
            Reload::Failed(m) => {
                self.complain(format!("reload failed, showing the last good scene: {m}"));
                true
            }
        }
    }

    fn v3(&self, target: &str) -> Option<Vec3f> {
        let v = self.scene().value_at(target, self.timeline.time)?;
        Some(Vec3f::new(*v.first()?, *v.get(1)?, *v.get(2)?))
    }

    fn set_camera(&mut self, eye: Vec3f, target: Vec3f) -> bool {
        let a = self.edit_value("camera.position", eye.to_array().to_vec(), Some("camera"));
        let b = self.edit_value("camera.target", target.to_array().to_vec(), Some("camera"));
        a && b
    }

    /// Orbits the camera around its target: `yaw` about the world y axis, `pitch` up/down
    /// (degrees), keeping the distance; the pitch stops 1° short of the poles.
    pub fn orbit(&mut self, yaw_deg: f32, pitch_deg: f32) -> bool {
        let (Some(eye), Some(target)) = (self.v3("camera.position"), self.v3("camera.target")) else {
            return false;
        };
        let d = eye - target;
        let r = d.length();
        if !(r > 0.0 && r.is_finite()) {
            return false;
        }
        let yaw = d.x.atan2(d.z) + yaw_deg.to_radians();
        let lim = 89f32.to_radians();
        let pitch = ((d.y / r).clamp(-1.0, 1.0).asin() + pitch_deg.to_radians()).clamp(-lim, lim);
        let nd = Vec3f::new(pitch.cos() * yaw.sin(), pitch.sin(), pitch.cos() * yaw.cos()) * r;
        self.set_camera(target + nd, target)
    }

    /// Moves eye and target together across the view: `dx`, `dy` in fractions of the view's
    /// height at the target's distance (positive: the scene moves right / up).
    pub fn pan(&mut self, dx: f32, dy: f32) -> bool {
        let frame = self.frame();
        let b = frame.camera.basis(frame.width, frame.height);
        let (Some(eye), Some(target)) = (self.v3("camera.position"), self.v3("camera.target")) else {
            return false;
        };
        let h = 2.0 * (target - eye).length() * b.tan_half_fov;
        let shift = b.right * (-dx * h) + b.up * (-dy * h);
        self.set_camera(eye + shift, target + shift)
    }

    /// Moves the eye towards (`factor < 1`) or away from the target, keeping at least 1e-3.
    pub fn zoom(&mut self, factor: f32) -> bool {
        if !(factor.is_finite() && factor > 0.0) {
            return false;
        }
        let (Some(eye), Some(target)) = (self.v3("camera.position"), self.v3("camera.target")) else {
            return false;
        };
        let d = eye - target;
        let r = (d.length() * factor).max(1e-3);
        self.set_camera(target + d.normalize_or(Vec3f::new(0.0, 0.0, 1.0)) * r, target)
    }

    /// The draggable points of the selected wave (of every wave when none is selected), where
    /// they are at the current time.
    pub fn handles(&self) -> Vec<Handle> {
        let scene = self.scene();
        let t = self.timeline.time;
        let mut out = Vec::new();
        for name in scene.wave_names() {
            if self.selected_wave.as_deref().is_some_and(|s| s != name) {
                continue;
            }
            let get = |key: &str| scene.value_at(&format!("wave.{name}.{key}"), t);
            let v3 = |key: &str| get(key).and_then(|v| Some(Vec3f::new(*v.first()?, *v.get(1)?, *v.get(2)?)));
            let mut push = |what: HandleKind, world: Vec3f| {
                out.push(Handle { wave: name.to_string(), what, world });
            };
            for key in ["M", "M2", "O"] {
                if let Some(p) = v3(key) {
                    push(HandleKind::Point(key), p);
                }
            }
            if let (Some(m), Some(d), Some(len), None) = (v3("M"), v3("D"), get("length"), get("M2")) {
                if scene.wave_kind(name).is_some_and(hadou_scene::WaveKind::is_segment) {
                    push(HandleKind::Head, m + d.normalize_or(Vec3f::new(1.0, 0.0, 0.0)) * len[0]);
                }
            }
            if let (Some(points), Some(axes)) = (get("points"), curve_axes(scene, name, t)) {
                let n = points.len() / 2;
                let gamma = get("gamma").and_then(|g| g.first().copied()).unwrap_or(1.0);
                for (i, c) in points.chunks_exact(2).enumerate() {
                    let s = if n > 1 { i as f32 / (n - 1) as f32 } else { 0.0 };
                    let [o, d, y, z] = axes;
                    push(HandleKind::Control(i), o + d * (gamma * s) + y * c[0] + z * c[1]);
                }
            }
        }
        out
    }

    /// Moves handle `h` to `world` (merged into one undo step per drag with `merge`).
    pub fn drag_handle(&mut self, h: &Handle, world: Vec3f, merge: &str) -> bool {
        let t = self.timeline.time;
        let name = &h.wave;
        match h.what {
            HandleKind::Point(key) => {
                self.edit_value(&format!("wave.{name}.{key}"), world.to_array().to_vec(), Some(merge))
            }
            HandleKind::Head => {
                let Some(m) = self.v3(&format!("wave.{name}.M")) else { return false };
                let d = world - m;
                let len = d.length();
                let mut ok = self.edit_value(&format!("wave.{name}.length"), vec![len], Some(merge));
                if len > 1e-3 {
                    ok &= self.edit_value(
                        &format!("wave.{name}.D"),
                        (d / len).to_array().to_vec(),
                        Some(merge),
                    );
                }
                ok
            }
            HandleKind::Control(i) => {
                let target = format!("wave.{name}.points");
                let (Some(mut points), Some([o, _, y, z])) =
                    (self.scene().value_at(&target, t), curve_axes(self.scene(), name, t))
                else {
                    return false;
                };
                if 2 * i + 1 >= points.len() {
                    return false;
                }
                points[2 * i] = (world - o).dot(y);
                points[2 * i + 1] = (world - o).dot(z);
                self.edit_value(&target, points, Some(merge))
            }
        }
    }
}

/// The curve frame of wave `name` at `time`: `[O, D̂, ŷ, ẑ]` (see `hadou_math::curve::CurveFrame`).
fn curve_axes(scene: &Scene, name: &str, time: f32) -> Option<[Vec3f; 4]> {
    let get = |key: &str| {
        let v = scene.value_at(&format!("wave.{name}.{key}"), time)?;
        Some(Vec3f::new(*v.first()?, *v.get(1)?, *v.get(2)?))
    };
    let o = get("O")?;
    let frame = hadou_math::curve::CurveFrame {
        origin: o,
        axis: get("D")?,
        up: get("up").unwrap_or(Vec3f::new(0.0, 1.0, 0.0)),
    };
    let [d, y, z] = frame.axes()?;
    Some([o, d, y, z])
}

/// Most names a message lists.
const MAX_LISTED: usize = 40;

/// "`a`, `b`, `c`" (at most [`MAX_LISTED`], then how many there are), or "none".
fn listed(names: &[&str]) -> String {
    if names.is_empty() {
        return "none".into();
    }
    let list: Vec<String> =
        names.iter().take(MAX_LISTED).map(|n| format!("`{}`", n.escape_debug())).collect();
    let more =
        if names.len() > MAX_LISTED { format!(", … ({} in all)", names.len()) } else { String::new() };
    list.join(", ") + &more
}

/// Whether a parameter is a colour (shown with a colour picker next to its numbers).
pub fn is_colour(key: &str, shape: ParamShape) -> bool {
    matches!(shape, ParamShape::Vector(3) | ParamShape::Vector(4))
        && matches!(key, "color" | "rgba" | "background" | "ambient" | "base_color" | "outline_color")
}

/// Projects `p` into image pixels of `frame` (x right, y down, pixel centres at `.5`); `None`
/// behind the eye. The inverse of `CameraBasis::pixel_dir`.
pub fn project(frame: &Frame, p: Vec3f) -> Option<[f32; 2]> {
    let b = frame.camera.basis(frame.width, frame.height);
    let d = p - b.eye;
    let z = d.dot(b.forward);
    if z.is_nan() || z <= 1e-6 {
        return None;
    }
    let ndc_x = d.dot(b.right) / (z * b.tan_half_fov * b.aspect);
    let ndc_y = d.dot(b.up) / (z * b.tan_half_fov);
    let (w, h) = (frame.width as f32, frame.height as f32);
    let px = [(ndc_x + 1.0) * 0.5 * w, (1.0 - ndc_y) * 0.5 * h];
    (px[0].is_finite() && px[1].is_finite()).then_some(px)
}

/// The world point at image pixel `px` (as [`project`]) and view depth `z` along `forward`.
pub fn unproject(frame: &Frame, px: [f32; 2], z: f32) -> Vec3f {
    let b = frame.camera.basis(frame.width, frame.height);
    b.eye + b.pixel_dir(px[0] - 0.5, px[1] - 0.5, frame.width, frame.height) * z
}

/// The view depth of `p` (its distance along the camera's forward axis).
pub fn view_depth(frame: &Frame, p: Vec3f) -> f32 {
    let b = frame.camera.basis(frame.width, frame.height);
    (p - b.eye).dot(b.forward)
}
