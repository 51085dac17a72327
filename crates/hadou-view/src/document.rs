//! The scene document: the scene file's text as a format-preserving TOML tree (`toml_edit`) and
//! the [`Scene`] parsed from it, kept in step. Every edit rewrites the tree, prints it and parses
//! the result with [`Scene::parse`], the same loader `hadou render` uses: an edit the loader
//! rejects is refused and changes nothing, so the document always holds a valid scene and saving
//! writes a file `hadou render` accepts. Comments, blank lines and keys the viewer does not touch
//! stay as they were written.
//!
//! Undo and redo keep whole texts (scenes are small; a text is the one state both the tree and the
//! scene follow from). Edits that carry the same merge key in a row (one slider drag, one camera
//! orbit) form one undo step.

use hadou_scene::{Entity, Growth, ParamShape, Scene, SceneError, StarterValue, WaveKind};
use std::path::{Path, PathBuf};
use toml_edit::{Array, ArrayOfTables, DocumentMut, Item, Table, Value};

/// How many undo steps are kept.
pub const UNDO_DEPTH: usize = 256;

/// Two key times closer than this (seconds) are the same key.
pub const KEY_TIME_EPS: f32 = 1e-4;

/// One change to the document.
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    /// Writes the value of the whole parameter `target` (as `ParamInfo::target`) into its table.
    Set {
        /// `"wave.beam.M2"`, `"camera.fov"`, `"background"`.
        target: String,
        /// The parameter's floats, in its shape.
        value: Vec<f32>,
    },
    /// Sets the key at `time` of the track for `target` (created if missing; a key within
    /// [`KEY_TIME_EPS`] of `time` is replaced).
    Key {
        /// A whole-parameter target.
        target: String,
        /// Seconds, ≥ 0.
        time: f32,
        /// The parameter's floats.
        value: Vec<f32>,
    },
    /// Removes the key at `time` from the track for `target` (and the track with its last key).
    RemoveKey {
        /// The track's target.
        target: String,
        /// Seconds.
        time: f32,
    },
    /// Sets a string-valued key (`falloff`, `mode`, …) of a table.
    Choice {
        /// The table.
        entity: Entity,
        /// The key.
        key: String,
        /// The new value.
        value: String,
    },
    /// Writes any key of a table as TOML text (`"[[0.5, 1, 1, 1]]"`, `"\"faithful\""`, `"64"`):
    /// the keys the panel has no dedicated control for (ramps, textures, map sizes, integrator
    /// settings, the image size, …). Empty text removes the key, so its default applies.
    Raw {
        /// The table.
        entity: Entity,
        /// The key.
        key: String,
        /// A TOML value, or empty.
        value: String,
    },
    /// Replaces a track's interpolation (`"linear"`, `"smooth"`).
    Interpolation {
        /// The track's target.
        target: String,
        /// The interpolation's name.
        value: String,
    },
    /// Appends a `[[wave]]` of this kind with working defaults, centred on `at`.
    AddWave {
        /// One of `hadou_scene::WAVE_KINDS`.
        kind: String,
        /// Where to put it (the camera's target, usually).
        at: [f32; 3],
    },
    /// Appends an `[[object]]` primitive (`"box"`, `"sphere"`, `"plane"`) at `at`.
    AddObject {
        /// The primitive.
        kind: String,
        /// Its position.
        at: [f32; 3],
    },
    /// Chooses the clip a `kind = "gltf"` object plays from its own file (its `animation` key):
    /// `Some(clip)` writes it (and removes `animation_file`, whose clips it would name); `None` is
    /// the rest pose: it removes `animation`, `animation_file` and the keys that only time a clip
    /// (`animation_start`, `animation_speed`, `animation_loop`, `animation_time`) with their
    /// tracks. `expressions` stay.
    Clip {
        /// The object's name.
        object: String,
        /// A clip of its glTF file, or `None` for the rest pose.
        clip: Option<String>,
    },
    /// Sets a `kind = "gltf"` object's `spring` key: whether its VRM spring bones move.
    Spring {
        /// The object's name.
        object: String,
        /// `spring = true` or `false`.
        on: bool,
    },
    /// Sets what a `kind = "gltf"` object's VRM eyes follow (its `look_at` key); any other than
    /// [`Gaze::Point`] also removes the track of the point `object.NAME.look_at`.
    LookAt {
        /// The object's name.
        object: String,
        /// What the eyes follow.
        gaze: Gaze,
    },
    /// Removes the named wave, its tracks, the shadows cast by it and the `look_at` keys that
    /// name it (those eyes then rest).
    RemoveWave(String),
    /// Removes the named object and its tracks.
    RemoveObject(String),
    /// The firing preset: the wave extends from nothing to its current shape between `start`
    /// and `start + duration` (a beam's or capsule's head travels out of the muzzle; a curve's
    /// extension `k` runs from near 0 to 1; a sphere's or cylinder's strength grows from 0),
    /// replacing any track on the parameter it animates.
    Fire {
        /// The wave's name.
        wave: String,
        /// Seconds.
        start: f32,
        /// Seconds, > 0.
        duration: f32,
    },
}

/// What an [`Edit::LookAt`] makes a character's eyes follow.
#[derive(Clone, Debug, PartialEq)]
pub enum Gaze {
    /// Nothing: the key is removed and the eyes rest.
    None,
    /// `look_at = "camera"`.
    Camera,
    /// `look_at = "WAVE"`: the wave's head.
    Wave(String),
    /// `look_at = [x, y, z]`, world space (animatable).
    Point([f32; 3]),
}

/// Why an edit or a file operation did not happen. `Display` is the message to show.
#[derive(Clone, Debug, PartialEq)]
pub struct DocError(pub String);

impl std::fmt::Display for DocError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for DocError {}

fn err<T>(m: impl Into<String>) -> Result<T, DocError> {
    Err(DocError(m.into()))
}

/// What a poll of the file on disk found.
#[derive(Clone, Debug, PartialEq)]
pub enum Reload {
    /// Nothing changed (or it changed back to what the document already knows).
    Unchanged,
    /// The file changed and parsed: the document now holds it (one undo step).
    Reloaded,
    /// The file changed but does not parse: the message (`path:line:col: …`); the document keeps
    /// the last good scene.
    Failed(String),
}

/// The file's identity on disk, to notice saves by other programs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Stamp {
    modified: Option<std::time::SystemTime>,
    len: u64,
}

fn stamp(path: &Path) -> Option<Stamp> {
    let m = std::fs::metadata(path).ok()?;
    Some(Stamp { modified: m.modified().ok(), len: m.len() })
}

/// The scene document (see the module docs).
pub struct Document {
    path: PathBuf,
    doc: DocumentMut,
    text: String,
    scene: Scene,
    /// The text last read from or written to the file.
    disk_text: String,
    disk_stamp: Option<Stamp>,
    undo: Vec<String>,
    redo: Vec<String>,
    /// The merge key of the last edit, while edits with it keep coming.
    merge: Option<String>,
    /// Set while the file on disk does not parse (cleared by a good reload or a save).
    reload_error: Option<String>,
}

impl Document {
    /// Reads and parses the scene file (the errors of `hadou render`).
    pub fn open(path: &Path) -> Result<Document, SceneError> {
        let text = Scene::read_text(path)?;
        let mut d = Self::from_text(&text, path)?;
        d.disk_stamp = stamp(path);
        Ok(d)
    }

    /// A document from scene `text` named `path` (relative assets resolve next to it); nothing
    /// is read from disk but the assets.
    pub fn from_text(text: &str, path: &Path) -> Result<Document, SceneError> {
        let scene = Scene::parse(text, path)?;
        let doc: DocumentMut = text.parse().map_err(|e: toml_edit::TomlError| SceneError::Io {
            path: path.to_path_buf(),
            message: format!("the TOML editor cannot read this file: {}", e.message()),
        })?;
        Ok(Document {
            path: path.to_path_buf(),
            doc,
            text: text.to_string(),
            scene,
            disk_text: text.to_string(),
            disk_stamp: None,
            undo: Vec::new(),
            redo: Vec::new(),
            merge: None,
            reload_error: None,
        })
    }

    /// The parsed scene (always valid).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The document's text (what a save writes).
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The scene file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether the text differs from the file's.
    pub fn is_dirty(&self) -> bool {
        self.text != self.disk_text
    }

    /// The message of the last reload that failed, while the file on disk stays broken.
    pub fn reload_error(&self) -> Option<&str> {
        self.reload_error.as_deref()
    }

    /// The keys of `entity`'s table with their TOML text, other than `name`, the animatable
    /// parameters and a VRM character's `spring` and `look_at` (which have their own controls): what [`Edit::Raw`] edits. Sub-tables are left
    /// out; an entity the file does not write has none.
    pub fn other_keys(&self, entity: &Entity) -> Vec<(String, String)> {
        let mut animatable: Vec<&'static str> =
            self.scene.parameters().into_iter().filter(|p| &p.entity == entity).map(|p| p.key).collect();
        if let Entity::Object(name) = entity {
            if self.scene.characters().iter().any(|c| &c.object == name) {
                // They have the character's controls (`Edit::Spring`, `Edit::LookAt`).
                animatable.extend(["spring", "look_at"]);
            }
        }
        let table = match entity.name() {
            Some(name) => match self.doc.get(entity.table()) {
                Some(Item::ArrayOfTables(a)) => {
                    a.iter().find(|t| t.get("name").and_then(Item::as_str) == Some(name))
                }
                _ => None,
            },
            None if *entity == Entity::Top => Some(self.doc.as_table()),
            None => self.doc.get(entity.table()).and_then(Item::as_table),
        };
        let Some(table) = table else { return Vec::new() };
        table
            .iter()
            .filter(|(k, _)| *k != "name" && !animatable.contains(k))
            .filter_map(|(k, item)| Some((k.to_string(), item.as_value()?.to_string().trim().to_string())))
            .collect()
    }

    /// Whether [`Document::undo`] / [`Document::redo`] have a step to take.
    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    /// See [`Document::can_undo`].
    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Applies `edit` as its own undo step.
    pub fn apply(&mut self, edit: &Edit) -> Result<(), DocError> {
        self.apply_merged(edit, None)
    }

    /// Applies `edit`; consecutive edits with the same `Some(merge)` key form one undo step. A
    /// refused edit changes nothing and returns the loader's message.
    pub fn apply_merged(&mut self, edit: &Edit, merge: Option<&str>) -> Result<(), DocError> {
        let mut doc = self.doc.clone();
        edit_tree(&mut doc, &self.scene, edit)?;
        let text = doc.to_string();
        if text == self.text {
            return Ok(());
        }
        let mut scene =
            Scene::parse(&text, &self.path).map_err(|e| DocError(strip_path(&e.to_string(), &self.path)))?;
        // An edit that leaves a character's springs alone (the camera, a light, …) continues
        // their simulation rather than stepping again from time 0: the same bits, sooner.
        scene.keep_spring_states(&self.scene);
        let merging = merge.is_some() && self.merge.as_deref() == merge && !self.undo.is_empty();
        if !merging {
            self.undo.push(std::mem::take(&mut self.text));
            if self.undo.len() > UNDO_DEPTH {
                self.undo.remove(0);
            }
        }
        self.merge = merge.map(str::to_string);
        self.redo.clear();
        self.doc = doc;
        self.text = text;
        self.scene = scene;
        Ok(())
    }

    /// Ends the current merge run: the next edit starts a new undo step even with the same key.
    pub fn end_merge(&mut self) {
        self.merge = None;
    }

    /// Steps back one edit; `false` when there is none.
    pub fn undo(&mut self) -> bool {
        let Some(prev) = self.undo.pop() else { return false };
        let cur = std::mem::replace(&mut self.text, prev);
        self.redo.push(cur);
        self.reset_from_text();
        true
    }

    /// Redoes one undone edit; `false` when there is none.
    pub fn redo(&mut self) -> bool {
        let Some(next) = self.redo.pop() else { return false };
        let cur = std::mem::replace(&mut self.text, next);
        self.undo.push(cur);
        self.reset_from_text();
        true
    }

    /// Rebuilds the tree and the scene from `self.text` (a text that parsed before).
    fn reset_from_text(&mut self) {
        self.merge = None;
        if let (Ok(doc), Ok(mut scene)) =
            (self.text.parse::<DocumentMut>(), Scene::parse(&self.text, &self.path))
        {
            scene.keep_spring_states(&self.scene);
            self.doc = doc;
            self.scene = scene;
        }
    }

    /// Writes the document to its file. The bytes go to a temporary file next to it, renamed over
    /// the file when complete, so the file is never half-written. On failure the document (and
    /// every edit) stays as it was.
    pub fn save(&mut self) -> Result<(), DocError> {
        let path = self.path.clone();
        self.write_to(&path)
    }

    /// Takes the current text as saved elsewhere (a web page handed it to the browser as a
    /// download): the document is no longer dirty; nothing is written.
    pub fn mark_saved(&mut self) {
        self.disk_text = self.text.clone();
    }

    /// Writes the document to `path`, which becomes the document's file. Relative asset paths in
    /// the scene resolve next to the new file, so the scene must still load from there.
    pub fn save_as(&mut self, path: &Path) -> Result<(), DocError> {
        let scene = Scene::parse(&self.text, path).map_err(|e| {
            DocError(format!("cannot save as {}: the scene would not load from there: {e}", path.display()))
        })?;
        self.write_to(path)?;
        self.path = path.to_path_buf();
        self.scene = scene;
        Ok(())
    }

    fn write_to(&mut self, path: &Path) -> Result<(), DocError> {
        write_atomically(path, self.text.as_bytes())
            .map_err(|e| DocError(format!("cannot save {}: {e}; the edits are kept", path.display())))?;
        self.disk_text = self.text.clone();
        self.disk_stamp = stamp(path);
        self.reload_error = None;
        Ok(())
    }

    /// Looks at the file on disk (cheap: one `stat` unless it changed) and takes a new version
    /// in; see [`Reload`]. Edits not yet saved are replaced by the file's text, one undo away.
    pub fn poll_disk(&mut self) -> Reload {
        let now = stamp(&self.path);
        if now == self.disk_stamp || now.is_none() {
            return Reload::Unchanged;
        }
        self.disk_stamp = now;
        let text = match Scene::read_text(&self.path) {
            Ok(t) => t,
            // Editors that save by replacing the file may leave it missing for a moment.
            Err(_) if !self.path.exists() => return Reload::Unchanged,
            Err(e) => {
                let m = e.to_string();
                self.reload_error = Some(m.clone());
                return Reload::Failed(m);
            }
        };
        if text == self.disk_text {
            self.reload_error = None;
            return Reload::Unchanged;
        }
        let parsed = Scene::parse(&text, &self.path).map_err(|e| e.to_string()).and_then(|scene| {
            text.parse::<DocumentMut>().map(|doc| (scene, doc)).map_err(|e| e.message().to_string())
        });
        match parsed {
            Ok((mut scene, doc)) => {
                scene.keep_spring_states(&self.scene);
                self.disk_text = text.clone();
                self.reload_error = None;
                if text != self.text {
                    self.undo.push(std::mem::replace(&mut self.text, text));
                    self.redo.clear();
                    self.merge = None;
                }
                self.doc = doc;
                self.scene = scene;
                Reload::Reloaded
            }
            Err(m) => {
                self.reload_error = Some(m.clone());
                Reload::Failed(m)
            }
        }
    }
}

/// Replaces a leading `path:` in a loader message about the document's own (unsaved) text: the
/// line and column are of the edited text, not of the file on disk.
fn strip_path(m: &str, path: &Path) -> String {
    let p = format!("{}:", path.display());
    m.strip_prefix(&p)
        .map_or_else(|| m.to_string(), |rest| format!("in the edited scene, line {}", rest.trim_start()))
}

/// Writes `bytes` to a temporary file in `path`'s directory ([`hadou_scene::TempFile`], registered
/// for the interrupt handler's clean-up before its first byte) and renames it over `path`.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let (tmp, file) = hadou_scene::TempFile::create(path)?;
    {
        // Closed at the end of this block, before the rename.
        let mut file = file;
        file.write_all(bytes)?;
        file.sync_all()?;
    }
    tmp.commit(path)
}

// ---------------------------------------------------------------------------------------------
// The tree edits.

/// The shortest decimal that reads back as the same `f32`, as a TOML float.
pub fn number(v: f32) -> Value {
    let v = if v.is_finite() { v } else { 0.0 };
    let shortest: f64 = v.to_string().parse().unwrap_or(0.0);
    Value::from(shortest)
}

/// The floats of a parameter as a TOML value of its shape.
pub fn shaped(shape: ParamShape, v: &[f32]) -> Value {
    match shape {
        ParamShape::Scalar => number(v.first().copied().unwrap_or(0.0)),
        ParamShape::Vector(_) => Value::Array(v.iter().map(|&x| number(x)).collect()),
        ParamShape::List(w) => {
            let w = w.max(1);
            Value::Array(v.chunks(w).map(|c| Value::Array(c.iter().map(|&x| number(x)).collect())).collect())
        }
    }
}

/// Writes `new` over `old` keeping `old`'s layout where the shapes agree (element decor, line
/// breaks, the comment after the value); otherwise replaces it, keeping the outer decor.
fn assign(old: &mut Value, new: Value) {
    match (old, new) {
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => {
            for (o, n) in a.iter_mut().zip(b) {
                assign(o, n);
            }
        }
        (old, new) => {
            let decor = old.decor().clone();
            *old = new;
            *old.decor_mut() = decor;
        }
    }
}

/// Sets `key` of `table` to `value`, in place when the key exists.
fn set_key(table: &mut Table, key: &str, value: Value) {
    match table.get_mut(key).and_then(Item::as_value_mut) {
        Some(old) => assign(old, value),
        None => {
            table.insert(key, Item::Value(value));
        }
    }
}

fn array_of_tables<'d>(doc: &'d mut DocumentMut, name: &str) -> Result<&'d mut ArrayOfTables, DocError> {
    if doc.get(name).is_none() {
        doc.insert(name, Item::ArrayOfTables(ArrayOfTables::new()));
    }
    match doc.get_mut(name) {
        Some(Item::ArrayOfTables(a)) => Ok(a),
        _ => err(format!(
            "`{name}` in this file is not written as [[{name}]] tables; edit it in a text editor"
        )),
    }
}

fn named<'a>(aot: &'a mut ArrayOfTables, name: &str) -> Option<&'a mut Table> {
    aot.iter_mut().find(|t| t.get("name").and_then(Item::as_str) == Some(name))
}

/// The table an entity is written in, created (as `[name]`) for single tables the file leaves out.
fn entity_table<'d>(doc: &'d mut DocumentMut, entity: &Entity) -> Result<&'d mut Table, DocError> {
    if let Some(name) = entity.name() {
        let table = entity.table();
        let aot = array_of_tables(doc, table)?;
        return named(aot, name).ok_or_else(|| DocError(format!("no [[{table}]] is named \"{name}\"")));
    }
    if *entity == Entity::Top {
        return Ok(doc.as_table_mut());
    }
    let key = entity.table();
    if doc.get(key).is_none() {
        doc.insert(key, Item::Table(Table::new()));
    }
    match doc.get_mut(key) {
        Some(Item::Table(t)) => Ok(t),
        _ => err(format!("[{key}] is written inline; edit it in a text editor")),
    }
}

/// Splits a whole-parameter target into its table and key, using the scene to know the names.
pub fn split_target(scene: &Scene, target: &str) -> Result<(Entity, String, ParamShape), DocError> {
    match scene.parameters().into_iter().find(|p| p.target == target) {
        Some(p) => Ok((p.entity, p.key.to_string(), p.shape)),
        None => err(format!("the scene has no parameter `{target}`")),
    }
}

fn tracks(doc: &mut DocumentMut) -> Result<&mut ArrayOfTables, DocError> {
    array_of_tables(doc, "track")
}

fn track_of<'a>(aot: &'a mut ArrayOfTables, target: &str) -> Option<&'a mut Table> {
    aot.iter_mut().find(|t| t.get("target").and_then(Item::as_str) == Some(target))
}

/// `[time, value]` for a track's `keys`.
fn key_item(time: f32, value: Value) -> Value {
    let mut a = Array::new();
    a.push(number(time));
    a.push(value);
    Value::Array(a)
}

fn key_time(v: &Value) -> Option<f32> {
    let a = v.as_array()?;
    let t = a.get(0)?;
    t.as_float().map(|f| f as f32).or_else(|| t.as_integer().map(|i| i as f32))
}

/// Inserts or replaces the key at `time` in `track` (a `[[track]]` table).
fn put_key(track: &mut Table, time: f32, value: Value) -> Result<(), DocError> {
    if track.get("keys").is_none() {
        track.insert("keys", Item::Value(Value::Array(Array::new())));
    }
    let Some(keys) = track.get_mut("keys").and_then(Item::as_array_mut) else {
        return err("the track's `keys` is not an array");
    };
    let item = key_item(time, value);
    let pos = keys.iter().position(|k| key_time(k).is_some_and(|t| t >= time - KEY_TIME_EPS));
    match pos {
        Some(i)
            if key_time(&keys.get(i).cloned().unwrap_or(Value::from(0.0)))
                .is_some_and(|t| (t - time).abs() <= KEY_TIME_EPS) =>
        {
            if let Some(old) = keys.get_mut(i) {
                let decor = old.decor().clone();
                *old = item;
                *old.decor_mut() = decor;
            }
        }
        Some(i) => keys.insert_formatted(i, spaced(item, i > 0)),
        None => {
            let n = keys.len();
            keys.push_formatted(spaced(item, n > 0));
        }
    }
    Ok(())
}

fn spaced(mut v: Value, lead: bool) -> Value {
    v.decor_mut().set_prefix(if lead { " " } else { "" });
    v.decor_mut().set_suffix("");
    v
}

fn new_track(target: &str, interpolation: &str) -> Table {
    let mut t = Table::new();
    t.insert("target", toml_edit::value(target));
    t.insert("interpolation", toml_edit::value(interpolation));
    t.insert("keys", Item::Value(Value::Array(Array::new())));
    t
}

/// A fresh name `base1`, `base2`, … not in `taken`.
pub fn fresh_name(base: &str, taken: &[&str]) -> String {
    (1..).map(|i| format!("{base}{i}")).find(|n| !taken.contains(&n.as_str())).unwrap_or_default()
}

fn arr3(v: [f32; 3]) -> Value {
    Value::Array(v.iter().map(|&x| number(x)).collect())
}

fn edit_tree(doc: &mut DocumentMut, scene: &Scene, edit: &Edit) -> Result<(), DocError> {
    match edit {
        Edit::Set { target, value } => {
            let (entity, key, shape) = split_target(scene, target)?;
            let table = entity_table(doc, &entity)?;
            set_key(table, &key, shaped(shape, value));
        }
        Edit::Key { target, time, value } => {
            if !(time.is_finite() && *time >= 0.0) {
                return err(format!("key time {time} s: times are finite and ≥ 0"));
            }
            let (_, _, shape) = split_target(scene, target)?;
            let aot = tracks(doc)?;
            if track_of(aot, target).is_none() {
                aot.push(new_track(target, "smooth"));
            }
            let track = track_of(aot, target).ok_or_else(|| DocError("track vanished".into()))?;
            put_key(track, *time, shaped(shape, value))?;
        }
        Edit::RemoveKey { target, time } => {
            let aot = tracks(doc)?;
            let Some(i) =
                aot.iter().position(|t| t.get("target").and_then(Item::as_str) == Some(target.as_str()))
            else {
                return err(format!("no track animates `{target}`"));
            };
            let track = aot.get_mut(i).ok_or_else(|| DocError("track vanished".into()))?;
            let Some(keys) = track.get_mut("keys").and_then(Item::as_array_mut) else {
                return err("the track's `keys` is not an array");
            };
            let Some(k) =
                keys.iter().position(|k| key_time(k).is_some_and(|t| (t - time).abs() <= KEY_TIME_EPS))
            else {
                return err(format!("`{target}` has no key at {time} s"));
            };
            keys.remove(k);
            if keys.is_empty() {
                aot.remove(i);
            } else if let Some(first) = keys.get_mut(0) {
                first.decor_mut().set_prefix("");
            }
        }
        Edit::Choice { entity, key, value } => {
            let table = entity_table(doc, entity)?;
            set_key(table, key, Value::from(value.as_str()));
        }
        Edit::Raw { entity, key, value } => {
            if key.is_empty() || key == "name" || !key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            {
                return err(format!(
                    "`{key}`: give a key of the table (letters, digits and `_`; not `name`)"
                ));
            }
            let table = entity_table(doc, entity)?;
            if value.trim().is_empty() {
                table.remove(key);
            } else {
                let v: Value = value.trim().parse().map_err(|e: toml_edit::TomlError| {
                    DocError(format!("`{key}`: not a TOML value: {}", e.message()))
                })?;
                set_key(table, key, v);
            }
        }
        Edit::Interpolation { target, value } => {
            let track = track_of(tracks(doc)?, target)
                .ok_or_else(|| DocError(format!("no track animates `{target}`")))?;
            set_key(track, "interpolation", Value::from(value.as_str()));
        }
        Edit::AddWave { kind, at } => {
            let names = scene.wave_names();
            let name = fresh_name(kind, &names);
            let t = wave_defaults(kind, &name, *at)?;
            array_of_tables(doc, "wave")?.push(t);
            if doc.contains_key("track") {
                move_tracks_last(doc);
            }
        }
        Edit::AddObject { kind, at } => {
            let names = scene.object_names();
            let name = fresh_name(kind, &names);
            let mut t = Table::new();
            t.insert("name", toml_edit::value(name));
            t.insert("kind", toml_edit::value(kind.as_str()));
            match kind.as_str() {
                "box" | "sphere" => {}
                "plane" => {
                    t.insert(
                        "size",
                        Item::Value(Value::Array([10.0f32, 10.0].iter().map(|&x| number(x)).collect())),
                    );
                }
                other => {
                    return err(format!(
                        "objects added here are \"box\", \"sphere\" or \"plane\", not \"{other}\""
                    ))
                }
            }
            t.insert("position", Item::Value(arr3(*at)));
            array_of_tables(doc, "object")?.push(t);
            for later in ["wave", "shadow", "track"] {
                if doc.contains_key(later) {
                    move_last(doc, later);
                }
            }
        }
        Edit::Clip { object, clip } => {
            let table = entity_table(doc, &Entity::Object(object.clone()))?;
            match clip {
                Some(c) => {
                    table.remove("animation_file");
                    set_key(table, "animation", Value::from(c.as_str()));
                }
                None => {
                    for key in CLIP_KEYS {
                        table.remove(key);
                    }
                    let targets: Vec<String> =
                        CLIP_KEYS[2..].iter().map(|k| format!("object.{object}.{k}")).collect();
                    remove_tracks(doc, &targets);
                }
            }
        }
        Edit::Spring { object, on } => {
            let table = entity_table(doc, &Entity::Object(object.clone()))?;
            set_key(table, "spring", Value::from(*on));
        }
        Edit::LookAt { object, gaze } => {
            let table = entity_table(doc, &Entity::Object(object.clone()))?;
            match gaze {
                Gaze::None => {
                    table.remove("look_at");
                }
                Gaze::Camera => set_key(table, "look_at", Value::from("camera")),
                Gaze::Wave(w) => set_key(table, "look_at", Value::from(w.as_str())),
                Gaze::Point(p) => set_key(table, "look_at", arr3(*p)),
            }
            if !matches!(gaze, Gaze::Point(_)) {
                remove_tracks(doc, &[format!("object.{object}.look_at")]);
            }
        }
        Edit::RemoveWave(name) => {
            if let Some(Item::ArrayOfTables(objects)) = doc.get_mut("object") {
                for o in objects.iter_mut() {
                    if o.get("look_at").and_then(Item::as_str) == Some(name.as_str()) {
                        o.remove("look_at");
                    }
                }
            }
            remove_entity(doc, "wave", name)?
        }
        Edit::RemoveObject(name) => remove_entity(doc, "object", name)?,
        Edit::Fire { wave, start, duration } => fire(doc, scene, wave, *start, *duration)?,
    }
    Ok(())
}

/// An object's `animation` and `animation_file` keys and the keys that only time its clip (see
/// [`Edit::Clip`]).
const CLIP_KEYS: [&str; 6] =
    ["animation", "animation_file", "animation_start", "animation_speed", "animation_loop", "animation_time"];

/// Removes the tracks whose target is one of `targets` (and `[[track]]` with the last).
fn remove_tracks(doc: &mut DocumentMut, targets: &[String]) {
    if let Some(Item::ArrayOfTables(tr)) = doc.get_mut("track") {
        tr.retain(|t| {
            !t.get("target").and_then(Item::as_str).is_some_and(|s| targets.iter().any(|x| x == s))
        });
        if tr.is_empty() {
            doc.remove("track");
        }
    }
}

/// Moves the `[[name]]` tables to the end of the file (so an added table lands before them in
/// the order the format documents: objects, waves, shadows, tracks).
fn move_last(doc: &mut DocumentMut, name: &str) {
    if let Some(item) = doc.remove(name) {
        doc.insert(name, item);
    }
}

fn move_tracks_last(doc: &mut DocumentMut) {
    move_last(doc, "shadow");
    move_last(doc, "track");
}

/// Removes `[[table]] name = …`, the tracks that animate it and (for waves) its wave shadows.
fn remove_entity(doc: &mut DocumentMut, table: &str, name: &str) -> Result<(), DocError> {
    let aot = array_of_tables(doc, table)?;
    let Some(i) = aot.iter().position(|t| t.get("name").and_then(Item::as_str) == Some(name)) else {
        return err(format!("no [[{table}]] is named \"{name}\""));
    };
    aot.remove(i);
    if aot.is_empty() {
        doc.remove(table);
    }
    let prefix = format!("{table}.{name}.");
    if let Some(Item::ArrayOfTables(tr)) = doc.get_mut("track") {
        tr.retain(|t| !t.get("target").and_then(Item::as_str).is_some_and(|s| s.starts_with(&prefix)));
        if tr.is_empty() {
            doc.remove("track");
        }
    }
    if table == "wave" {
        if let Some(Item::ArrayOfTables(sh)) = doc.get_mut("shadow") {
            sh.retain(|t| t.get("wave").and_then(Item::as_str) != Some(name));
            if sh.is_empty() {
                doc.remove("shadow");
            }
        }
    }
    Ok(())
}

/// A new `[[wave]]` table of `kind` with values that render visibly at a typical scene scale.
fn wave_defaults(kind: &str, name: &str, at: [f32; 3]) -> Result<Table, DocError> {
    let Some(kind) = WaveKind::from_name(kind) else {
        return err(format!("wave kinds are {}; not \"{kind}\"", hadou_scene::WAVE_KINDS.join(", ")));
    };
    let mut t = Table::new();
    let put = |t: &mut Table, k: &str, v: Value| {
        t.insert(k, Item::Value(v));
    };
    t.insert("name", toml_edit::value(name));
    t.insert("kind", toml_edit::value(kind.name()));
    put(&mut t, "rgba", Value::Array([1.0f32, 0.6, 0.2, 1.0].iter().map(|&x| number(x)).collect()));
    let pairs = |p: &[[f32; 2]]| {
        Value::Array(p.iter().map(|c| Value::Array(c.iter().map(|&x| number(x)).collect())).collect())
    };
    for &(key, value) in kind.starter() {
        let v = match value {
            StarterValue::At => arr3(at),
            StarterValue::Behind => arr3([at[0] - 2.0, at[1], at[2]]),
            StarterValue::Vector(v) => arr3(v),
            StarterValue::Number(x) => number(x),
            StarterValue::Pairs(p) => pairs(p),
        };
        put(&mut t, key, v);
    }
    Ok(t)
}

/// The firing preset (see [`Edit::Fire`]).
fn fire(doc: &mut DocumentMut, scene: &Scene, wave: &str, start: f32, duration: f32) -> Result<(), DocError> {
    if !(start.is_finite() && start >= 0.0 && duration.is_finite() && duration > 0.0) {
        return err("firing needs a start ≥ 0 s and a duration > 0 s");
    }
    let Some(kind) = scene.wave_kind(wave) else { return err(format!("no wave is named \"{wave}\"")) };
    let base = |key: &str| {
        scene.parameters().into_iter().find(|p| p.target == format!("wave.{wave}.{key}")).map(|p| p.value)
    };
    let end = start + duration;
    let (key, from, to): (&str, Vec<f32>, Vec<f32>) = match kind.growth() {
        Growth::Segment => {
            if let Some(m2) = base("M2") {
                ("M2", base("M").unwrap_or_default(), m2)
            } else {
                let len = base("length").and_then(|v| v.first().copied()).unwrap_or(0.0);
                ("length", vec![0.0], vec![if len > 0.0 { len } else { 6.0 }])
            }
        }
        Growth::Strength(key) => (key, vec![0.0], base(key).unwrap_or_default()),
        Growth::Reach => ("k", vec![0.001], vec![1.0]),
    };
    let target = format!("wave.{wave}.{key}");
    let (_, _, shape) = split_target(scene, &target)?;
    let aot = tracks(doc)?;
    aot.retain(|t| t.get("target").and_then(Item::as_str) != Some(target.as_str()));
    let mut t = new_track(&target, "smooth");
    put_key(&mut t, start, shaped(shape, &from))?;
    put_key(&mut t, end, shaped(shape, &to))?;
    aot.push(t);
    Ok(())
}
