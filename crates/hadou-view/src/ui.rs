//! The egui user interface: the parameter panel (grouped as `docs/scene-format.md`), the
//! viewport with its gizmos and camera moves, the timeline and the top bar. It only reads and
//! edits a [`Viewer`] and pushes [`Request`]s; the window turns those into renders, screenshots
//! and exports. No threads, no blocking: the same code can run in a browser.

use crate::document::{Edit, Gaze};
use crate::viewer::{is_colour, project, unproject, view_depth, BackendKind, Handle, Request, Viewer};
use egui::{Color32, Pos2, Rect, Sense, Stroke, Vec2};
use hadou_scene::{Entity, LookAtTarget, ParamInfo, ParamShape};

/// The image the window shows in the viewport.
#[derive(Clone, Copy, Debug)]
pub struct ViewportImage {
    /// The texture holding it (registered with the egui renderer).
    pub texture: egui::TextureId,
    /// Its size in pixels (the scene's image size).
    pub size: [u32; 2],
}

/// UI state that is not part of the scene (what is being dragged, the add-menus' choices, …).
#[derive(Clone, Debug)]
pub struct UiState {
    /// The handle being dragged.
    dragging: Option<Handle>,
    /// Counts drags, so each drag is one undo step.
    drag_serial: u64,
    add_wave_kind: String,
    add_object_kind: String,
    fire_wave: Option<String>,
    export_frames: String,
    /// Where the viewport was drawn last frame (points).
    pub viewport_rect: Option<Rect>,
    /// Text being typed into the "other keys" fields, by (table, key).
    raw: std::collections::HashMap<(String, String), String>,
    /// The "add a key" row of each table: (key, value).
    new_key: std::collections::HashMap<String, (String, String)>,
}

impl Default for UiState {
    fn default() -> Self {
        UiState {
            dragging: None,
            drag_serial: 0,
            add_wave_kind: "beam".into(),
            add_object_kind: "box".into(),
            fire_wave: None,
            export_frames: String::new(),
            viewport_rect: None,
            raw: Default::default(),
            new_key: Default::default(),
        }
    }
}

const KEY_COLOUR: Color32 = Color32::from_rgb(240, 190, 60);
const ERROR_COLOUR: Color32 = Color32::from_rgb(255, 110, 100);

/// Draws the whole window's UI for one frame.
pub fn show(ui: &mut egui::Ui, v: &mut Viewer, image: Option<ViewportImage>, st: &mut UiState) {
    if !ui.input(|i| i.pointer.any_down()) {
        v.doc.end_merge();
        st.dragging = None;
    }
    shortcuts(ui, v);
    egui::Panel::top("hadou-top").show(ui, |ui| top_bar(ui, v, st));
    egui::Panel::bottom("hadou-timeline").show(ui, |ui| timeline(ui, v, st));
    egui::Panel::right("hadou-params").resizable(true).default_size(360.0).show(ui, |ui| {
        egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| params(ui, v, st));
    });
    egui::CentralPanel::no_frame().show(ui, |ui| viewport(ui, v, image, st));
}

fn shortcuts(ui: &mut egui::Ui, v: &mut Viewer) {
    let typing = ui.ctx().egui_wants_keyboard_input();
    let (undo, redo, save, space) = ui.input(|i| {
        let cmd = i.modifiers.command;
        (
            cmd && !i.modifiers.shift && i.key_pressed(egui::Key::Z),
            cmd && (i.key_pressed(egui::Key::Y) || (i.modifiers.shift && i.key_pressed(egui::Key::Z))),
            cmd && i.key_pressed(egui::Key::S),
            i.key_pressed(egui::Key::Space),
        )
    });
    if typing {
        return;
    }
    if undo {
        v.undo();
    }
    if redo {
        v.redo();
    }
    if save {
        v.save();
    }
    if space {
        v.timeline.playing = !v.timeline.playing;
    }
}

fn top_bar(ui: &mut egui::Ui, v: &mut Viewer, st: &mut UiState) {
    ui.horizontal_wrapped(|ui| {
        let name = v.doc.path().display().to_string();
        ui.strong(if v.doc.is_dirty() { format!("{name} •") } else { name });
        if ui.button("Save").on_hover_text("Ctrl+S").clicked() {
            v.save();
        }
        if ui.add_enabled(v.doc.can_undo(), egui::Button::new("Undo")).clicked() {
            v.undo();
        }
        if ui.add_enabled(v.doc.can_redo(), egui::Button::new("Redo")).clicked() {
            v.redo();
        }
        ui.separator();
        let current = v.stats.backend;
        egui::ComboBox::from_id_salt("backend")
            .selected_text(current.map_or("…", BackendKind::label))
            .show_ui(ui, |ui| {
                for b in [BackendKind::Cpu, BackendKind::Gpu] {
                    if ui.selectable_label(current == Some(b), b.label()).clicked() && current != Some(b) {
                        v.requests.push(Request::Backend(b));
                    }
                }
            });
        ui.label(&v.stats.backend_note).on_hover_text(format!("window adapter: {}", v.stats.adapter));
        ui.separator();
        ui.monospace(format!(
            "frame {:.1} ms · render {:.1} ms · viewer {:.2} ms · UI {:.1} ms",
            v.stats.frame_ms, v.stats.render_ms, v.stats.overhead_ms, v.stats.ui_ms
        ))
        .on_hover_text(format!("render time: {}", v.stats.render_method));
        if current == Some(BackendKind::Gpu)
            && ui.small_button("measure").on_hover_text("time the GPU's passes on this frame").clicked()
        {
            v.requests.push(Request::MeasureGpu);
        }
    });
    ui.horizontal_wrapped(|ui| {
        ui.label("Screenshot");
        ui.add(egui::TextEdit::singleline(&mut v.screenshot_path).desired_width(160.0));
        if ui.button("Save image").on_hover_text("PNG or EXR, exactly as `hadou render` writes it").clicked()
        {
            let p = v.screenshot_path.clone().into();
            v.requests.push(Request::Screenshot(p));
        }
        ui.separator();
        ui.label("Export");
        ui.add(egui::TextEdit::singleline(&mut v.export_path).desired_width(160.0))
            .on_hover_text("a .gif file, or a directory ending in / for a PNG sequence");
        let fps = v.export_fps;
        if st.export_frames.is_empty() {
            let n = (v.scene().duration() * fps).ceil().max(1.0) as u32 + 1;
            st.export_frames = format!("0..{n}");
        }
        ui.add(egui::TextEdit::singleline(&mut st.export_frames).desired_width(60.0))
            .on_hover_text("frames A..B");
        ui.add(egui::DragValue::new(&mut v.export_fps).range(1.0..=240.0).suffix(" fps"));
        match v.export_progress {
            Some((done, total)) => {
                ui.add(
                    egui::ProgressBar::new(done as f32 / total.max(1) as f32)
                        .desired_width(140.0)
                        .text(format!("{done}/{total}")),
                );
                if ui.button("Cancel").clicked() {
                    v.requests.push(Request::CancelExport);
                }
            }
            None => {
                if ui.button("Export").clicked() {
                    match parse_range(&st.export_frames) {
                        Some(frames) => {
                            let path = v.export_path.clone().into();
                            v.requests.push(Request::Export { path, frames, fps: v.export_fps });
                        }
                        None => {
                            v.complain(format!("frames `{}`: expected A..B with A < B", st.export_frames))
                        }
                    }
                }
            }
        }
    });
}

fn parse_range(s: &str) -> Option<std::ops::Range<u32>> {
    let (a, b) = s.trim().split_once("..")?;
    let (a, b) = (a.trim().parse().ok()?, b.trim().parse().ok()?);
    (a < b).then_some(a..b)
}

fn timeline(ui: &mut egui::Ui, v: &mut Viewer, st: &mut UiState) {
    ui.horizontal(|ui| {
        let label = if v.timeline.playing { "⏸ Pause" } else { "▶ Play" };
        if ui.button(label).on_hover_text("Space").clicked() {
            v.timeline.playing = !v.timeline.playing;
        }
        ui.checkbox(&mut v.timeline.looping, "Loop");
        ui.add(egui::DragValue::new(&mut v.timeline.speed).range(0.0..=8.0).speed(0.01).prefix("×"));
        let end = v.scrub_end();
        let width = (ui.available_width() - 330.0).max(120.0);
        ui.spacing_mut().slider_width = width;
        let r = ui.add(egui::Slider::new(&mut v.timeline.time, 0.0..=end).suffix(" s").max_decimals(3));
        // Key markers under the slider.
        let rail = Rect::from_min_size(r.rect.left_bottom(), Vec2::new(width, 4.0));
        for t in v.scene().tracks() {
            for &k in &t.times {
                let x = rail.left() + (k / end).clamp(0.0, 1.0) * width;
                ui.painter().circle_filled(Pos2::new(x, rail.top()), 2.5, KEY_COLOUR);
            }
        }
        ui.separator();
        let waves: Vec<String> = v.scene().wave_names().iter().map(|s| s.to_string()).collect();
        if st.fire_wave.as_ref().is_none_or(|w| !waves.contains(w)) {
            st.fire_wave = waves.first().cloned();
        }
        egui::ComboBox::from_id_salt("fire-wave")
            .selected_text(st.fire_wave.clone().unwrap_or_default())
            .show_ui(ui, |ui| {
                for w in &waves {
                    ui.selectable_value(&mut st.fire_wave, Some(w.clone()), w);
                }
            });
        ui.add(egui::DragValue::new(&mut v.fire_duration).range(0.05..=60.0).speed(0.01).suffix(" s"));
        if ui
            .add_enabled(st.fire_wave.is_some(), egui::Button::new("🔥 Fire"))
            .on_hover_text("keys the wave to grow from nothing to its shape, starting now")
            .clicked()
        {
            if let Some(w) = st.fire_wave.clone() {
                v.fire(&w);
            }
        }
    });
    ui.horizontal_wrapped(|ui| {
        if let Some(e) = v.doc.reload_error() {
            ui.colored_label(ERROR_COLOUR, format!("⚠ {e}"));
        } else if let Some((m, bad)) = &v.message {
            ui.colored_label(if *bad { ERROR_COLOUR } else { ui.visuals().text_color() }, m);
        }
    });
    if let Some(p) = &v.probe {
        ui.monospace(p);
    }
}

/// The groups of the panel, in the order of `docs/scene-format.md`.
fn group_of(e: &Entity) -> &'static str {
    match e {
        Entity::Camera => "Camera",
        Entity::Light => "Light",
        Entity::Color | Entity::Top => "Colour",
        Entity::Object(_) => "Objects",
        Entity::Material(_) => "Materials",
        Entity::Wave(_) => "Waves",
        Entity::Shadow(_) => "Shadows",
        Entity::AreaLight => "Area light",
        Entity::Bloom => "Bloom",
        Entity::Image => "Image",
    }
}

fn params(ui: &mut egui::Ui, v: &mut Viewer, st: &mut UiState) {
    let all = v.scene().parameters();
    let groups =
        ["Image", "Camera", "Light", "Colour", "Objects", "Materials", "Waves", "Shadows", "Area light"];
    for g in groups {
        let in_group: Vec<&ParamInfo> = all.iter().filter(|p| group_of(&p.entity) == g).collect();
        if g == "Image" {
            egui::CollapsingHeader::new(g)
                .default_open(false)
                .show(ui, |ui| other_keys(ui, v, st, &Entity::Image));
            continue;
        }
        if in_group.is_empty() && !matches!(g, "Objects" | "Waves") {
            continue;
        }
        egui::CollapsingHeader::new(g).default_open(matches!(g, "Waves" | "Camera")).show(ui, |ui| {
            if g == "Colour" {
                colour_mode(ui, v);
            }
            let mut entities: Vec<&Entity> = Vec::new();
            for p in &in_group {
                if !entities.contains(&&p.entity) {
                    entities.push(&p.entity);
                }
            }
            for e in entities {
                let list: Vec<&ParamInfo> = in_group.iter().copied().filter(|p| &p.entity == e).collect();
                if let Some(name) = e.name() {
                    egui::CollapsingHeader::new(name).id_salt(e.describe()).default_open(g == "Waves").show(
                        ui,
                        |ui| {
                            entity_actions(ui, v, e);
                            if let Entity::Object(object) = e {
                                clip_chooser(ui, v, object);
                                character_keys(ui, v, object);
                            }
                            param_rows(ui, v, &list);
                            other_keys(ui, v, st, e);
                        },
                    );
                } else {
                    param_rows(ui, v, &list);
                    other_keys(ui, v, st, e);
                }
            }
            if g == "Waves" {
                add_menu(ui, v, st, true);
            }
            if g == "Objects" {
                add_menu(ui, v, st, false);
            }
        });
    }
}

/// The table's keys without a control of their own (ramps, textures, map sizes, integrator
/// settings, …) as TOML text, each applied when edited, plus a row to add a key.
fn other_keys(ui: &mut egui::Ui, v: &mut Viewer, st: &mut UiState, e: &Entity) {
    let keys = v.doc.other_keys(e);
    let id = e.describe();
    egui::CollapsingHeader::new("other keys").id_salt(("other", &id)).default_open(false).show(ui, |ui| {
        for (key, text) in keys {
            let slot = (id.clone(), key.clone());
            ui.horizontal(|ui| {
                ui.label(&key);
                let buf = st.raw.entry(slot.clone()).or_insert_with(|| text.clone());
                let r = ui.add(egui::TextEdit::singleline(buf).code_editor().desired_width(220.0));
                let commit = r.lost_focus() && *buf != text;
                if !r.has_focus() && !commit {
                    *buf = text.clone();
                }
                if commit {
                    let value = buf.clone();
                    st.raw.remove(&slot);
                    v.apply(Edit::Raw { entity: e.clone(), key: key.clone(), value });
                }
            });
        }
        ui.horizontal(|ui| {
            let (k, val) = st.new_key.entry(id.clone()).or_default();
            ui.add(egui::TextEdit::singleline(k).hint_text("key").desired_width(90.0));
            ui.add(
                egui::TextEdit::singleline(val).hint_text("TOML value").code_editor().desired_width(140.0),
            );
            if ui.button("set").clicked() {
                let (key, value) = (k.trim().to_string(), val.clone());
                if v.apply(Edit::Raw { entity: e.clone(), key, value }) {
                    st.new_key.remove(&id);
                }
            }
        });
    });
}

fn colour_mode(ui: &mut egui::Ui, v: &mut Viewer) {
    let filmic = v.frame().color_mapping.mode == hadou_scene::ToneMode::Filmic;
    ui.horizontal(|ui| {
        ui.label("mode");
        for (m, on) in [("filmic", filmic), ("faithful", !filmic)] {
            if ui.selectable_label(on, m).clicked() && !on {
                v.apply(Edit::Choice { entity: Entity::Color, key: "mode".into(), value: m.into() });
            }
        }
    });
}

fn entity_actions(ui: &mut egui::Ui, v: &mut Viewer, e: &Entity) {
    ui.horizontal(|ui| match e {
        Entity::Wave(name) => {
            let kind = v.scene().wave_kind(name).map_or("?", hadou_scene::WaveKind::name);
            ui.weak(kind);
            let selected = v.selected_wave.as_deref() == Some(name.as_str());
            if ui
                .selectable_label(selected, "handles")
                .on_hover_text("show only this wave's handles")
                .clicked()
            {
                v.selected_wave = if selected { None } else { Some(name.clone()) };
            }
            let faithful = v
                .frame()
                .waves
                .iter()
                .any(|w| &w.name == name && w.falloff == hadou_math::energy::Falloff::Faithful);
            let next = if faithful { "inverse-square" } else { "faithful" };
            if ui
                .button(if faithful { "faithful" } else { "inverse-square" })
                .on_hover_text(format!("falloff; click for {next}"))
                .clicked()
            {
                v.apply(Edit::Choice { entity: e.clone(), key: "falloff".into(), value: next.into() });
            }
            if ui.button("Fire").clicked() {
                v.fire(name);
            }
            if ui.button("Remove").clicked() {
                v.apply(Edit::RemoveWave(name.clone()));
            }
        }
        Entity::Object(name) if ui.button("Remove").clicked() => {
            v.apply(Edit::RemoveObject(name.clone()));
        }
        _ => {}
    });
}

/// The clip an object whose glTF file has clips plays: "rest pose" or one of its clips (the
/// `animation` key, so the clip follows the timeline), with the clip time now.
fn clip_chooser(ui: &mut egui::Ui, v: &mut Viewer, object: &str) {
    let Some(choice) = v.clip_objects().into_iter().find(|c| c.object == object) else { return };
    let (clips, playing) = (choice.clips, choice.playing);
    ui.horizontal(|ui| {
        ui.label("clip");
        let mut chosen = playing.clone();
        egui::ComboBox::from_id_salt(("clip", object))
            .selected_text(chosen.as_deref().unwrap_or(REST_POSE))
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut chosen, None, REST_POSE);
                for (name, length) in &clips {
                    ui.selectable_value(&mut chosen, Some(name.clone()), format!("{name} ({length} s)"));
                }
            });
        if chosen != playing {
            v.choose_clip(object, chosen.as_deref());
        }
        if let Some((_, t)) = v.clip_now(object) {
            let length = clips.iter().find(|c| Some(&c.0) == playing.as_ref()).map_or(0.0, |c| c.1);
            ui.monospace(format!("{t:.3} s of {length} s"))
                .on_hover_text("the clip's time at the timeline's time (animation_start, _speed, _loop)");
        }
    });
}

/// A VRM character's `spring` (a checkbox, where its file has spring bones) and `look_at` (a
/// choice of none, the camera, each wave and a point, where its file has look-at; the point's
/// numbers are the parameter row `look_at` below).
fn character_keys(ui: &mut egui::Ui, v: &mut Viewer, object: &str) {
    let Some(c) = v.characters().into_iter().find(|c| c.object == object) else { return };
    if c.has_springs {
        let mut on = c.spring;
        if ui
            .checkbox(&mut on, "spring")
            .on_hover_text("the VRM spring bones move (hair, skirt), blown by the waves' wind")
            .changed()
        {
            v.set_spring(object, on);
        }
    }
    if !c.has_look_at {
        return;
    }
    let now = match &c.look_at {
        None => Gaze::None,
        Some(LookAtTarget::Camera) => Gaze::Camera,
        Some(LookAtTarget::Wave(w)) => Gaze::Wave(w.clone()),
        Some(LookAtTarget::Point) => Gaze::Point(v.gaze_point(object)),
    };
    let label = |g: &Gaze| match g {
        Gaze::None => "none".to_string(),
        Gaze::Camera => "camera".to_string(),
        Gaze::Wave(w) => format!("wave {w}"),
        Gaze::Point(_) => "a point".to_string(),
    };
    let mut choices = vec![Gaze::None, Gaze::Camera];
    choices.extend(v.scene().wave_names().iter().map(|w| Gaze::Wave(w.to_string())));
    choices.push(match now {
        Gaze::Point(p) => Gaze::Point(p),
        _ => Gaze::Point(v.gaze_point(object)),
    });
    let mut chosen = now.clone();
    ui.horizontal(|ui| {
        ui.label("look_at").on_hover_text("what the VRM eyes follow");
        egui::ComboBox::from_id_salt(("look_at", object)).selected_text(label(&now)).show_ui(ui, |ui| {
            for g in &choices {
                let on = label(g) == label(&now);
                if ui.selectable_label(on, label(g)).clicked() && !on {
                    chosen = g.clone();
                }
            }
        });
    });
    if chosen != now {
        v.set_look_at(object, chosen);
    }
}

/// The chooser's entry for no clip.
const REST_POSE: &str = "rest pose";

fn add_menu(ui: &mut egui::Ui, v: &mut Viewer, st: &mut UiState, wave: bool) {
    ui.horizontal(|ui| {
        let (kinds, chosen): (&[&str], &mut String) = if wave {
            (hadou_scene::WAVE_KINDS, &mut st.add_wave_kind)
        } else {
            (&["box", "sphere", "plane"], &mut st.add_object_kind)
        };
        egui::ComboBox::from_id_salt(if wave { "add-wave" } else { "add-object" })
            .selected_text(chosen.as_str())
            .show_ui(ui, |ui| {
                for k in kinds {
                    ui.selectable_value(chosen, k.to_string(), *k);
                }
            });
        let kind = chosen.clone();
        if ui.button(if wave { "Add wave" } else { "Add object" }).clicked() {
            let at = v.frame().camera.target.to_array();
            v.apply(if wave { Edit::AddWave { kind, at } } else { Edit::AddObject { kind, at } });
        }
    });
}

fn param_rows(ui: &mut egui::Ui, v: &mut Viewer, list: &[&ParamInfo]) {
    let time = v.timeline.time;
    for p in list {
        let Some(mut value) = v.scene().value_at(&p.target, time) else { continue };
        let tracks = v.scene().tracks();
        let track = tracks.iter().find(|t| t.target == p.target);
        let animated = v.scene().is_animated(&p.target);
        let key_here =
            track.is_some_and(|t| t.times.iter().any(|k| (k - time).abs() <= crate::document::KEY_TIME_EPS));
        let mut changed = false;
        ui.horizontal_wrapped(|ui| {
            let label = if animated {
                egui::RichText::new(p.key).color(KEY_COLOUR)
            } else {
                egui::RichText::new(p.key)
            };
            ui.label(label).on_hover_text(range_text(p));
            changed |= value_widgets(ui, p, &mut value);
            if let Some(t) = track {
                let smooth = t.interpolation == hadou_scene::Interpolation::Smooth;
                let (label, next) = if smooth { ("smooth", "linear") } else { ("linear", "smooth") };
                if ui.small_button(label).on_hover_text(format!("interpolation; click for {next}")).clicked()
                {
                    v.apply(Edit::Interpolation { target: p.target.clone(), value: next.into() });
                }
            }
            let key_button = if key_here { "unkey" } else { "key" };
            let r = ui.small_button(key_button).on_hover_text(if key_here {
                "remove the key at this time"
            } else {
                "set a key with this value at this time"
            });
            if r.clicked() {
                if key_here {
                    v.unkey_current(&p.target);
                } else {
                    v.key_current(&p.target);
                }
            }
        });
        if changed {
            p.range.clamp(&mut value);
            v.edit_value(&p.target, value, Some(&p.target));
        }
    }
}

fn range_text(p: &ParamInfo) -> String {
    use hadou_scene::ParamRange as R;
    let r = match p.range {
        R::Any => "any number".to_string(),
        R::NonNeg => "≥ 0".into(),
        R::Positive => "> 0".into(),
        R::Range { lo, hi, lo_open, hi_open } => {
            format!("{}{lo}, {hi}{}", if lo_open { "(" } else { "[" }, if hi_open { ")" } else { "]" })
        }
        R::NonZero => "a direction (not zero)".into(),
        R::Rgba => "r, g, b ≥ 0; a in [0, 1]".into(),
        R::NonDecreasing => "non-decreasing".into(),
    };
    format!("{} — {r}", p.target)
}

/// The widgets of one parameter's numbers; `true` when the user changed one.
fn value_widgets(ui: &mut egui::Ui, p: &ParamInfo, value: &mut [f32]) -> bool {
    let mut changed = false;
    let speed = |x: f32| (x.abs() * 0.01).clamp(0.001, 1.0);
    if is_colour(p.key, p.shape) && value.iter().take(3).all(|c| (0.0..=1.0).contains(c)) {
        let mut rgb = [value[0], value[1], value[2]];
        if egui::color_picker::color_edit_button_rgb(ui, &mut rgb).changed() {
            value[..3].copy_from_slice(&rgb);
            changed = true;
        }
    }
    match p.shape {
        ParamShape::Scalar => {
            let (lo, hi) = p.range.bounds(0);
            let x = &mut value[0];
            let r = match (lo, hi) {
                (Some(lo), Some(hi)) if hi - lo <= 1000.0 => {
                    ui.add(egui::Slider::new(x, lo..=hi).max_decimals(4))
                }
                _ => {
                    let s = speed(*x);
                    ui.add(
                        egui::DragValue::new(x)
                            .speed(s)
                            .range(lo.unwrap_or(-1e6)..=hi.unwrap_or(1e6))
                            .max_decimals(4),
                    )
                }
            };
            changed |= r.changed();
        }
        ParamShape::Vector(_) | ParamShape::List(_) => {
            let width = match p.shape {
                ParamShape::List(w) => w.max(1),
                _ => value.len().max(1),
            };
            let rows = value.len().div_ceil(width);
            for row in 0..rows {
                if rows > 1 {
                    ui.end_row();
                    ui.weak(format!("[{row}]"));
                }
                for i in row * width..((row + 1) * width).min(value.len()) {
                    let (lo, hi) = p.range.bounds(i % width);
                    let s = speed(value[i]);
                    let r = ui.add(
                        egui::DragValue::new(&mut value[i])
                            .speed(s)
                            .range(lo.unwrap_or(-1e6)..=hi.unwrap_or(1e6))
                            .max_decimals(4),
                    );
                    changed |= r.changed();
                }
            }
        }
    }
    changed
}

fn viewport(ui: &mut egui::Ui, v: &mut Viewer, image: Option<ViewportImage>, st: &mut UiState) {
    let avail = ui.available_rect_before_wrap();
    ui.painter().rect_filled(avail, 0.0, Color32::from_gray(18));
    let Some(img) = image else {
        ui.centered_and_justified(|ui| ui.label("rendering…"));
        return;
    };
    let (w, h) = (img.size[0].max(1) as f32, img.size[1].max(1) as f32);
    let scale = (avail.width() / w).min(avail.height() / h).max(1e-3);
    let rect = Rect::from_center_size(avail.center(), Vec2::new(w * scale, h * scale));
    st.viewport_rect = Some(rect);
    ui.painter().image(
        img.texture,
        rect,
        Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
        Color32::WHITE,
    );
    let response = ui.interact(avail, ui.id().with("viewport"), Sense::click_and_drag());
    let frame = v.frame();
    let to_screen = |px: [f32; 2]| Pos2::new(rect.left() + px[0] * scale, rect.top() + px[1] * scale);
    let to_pixel = |p: Pos2| [(p.x - rect.left()) / scale, (p.y - rect.top()) / scale];

    // Gizmos.
    let mut on_handle = false;
    let handles = v.handles();
    let painter = ui.painter_at(avail);
    let mut lines: Vec<(String, Pos2)> = Vec::new();
    for (i, h) in handles.iter().enumerate() {
        let Some(px) = project(&frame, h.world) else { continue };
        let pos = to_screen(px);
        if !avail.expand(8.0).contains(pos) {
            continue;
        }
        let id = ui.id().with(("handle", i));
        let hr = ui.interact(Rect::from_center_size(pos, Vec2::splat(14.0)), id, Sense::drag());
        let active = hr.dragged() || st.dragging.as_ref() == Some(h);
        let colour = if active { Color32::WHITE } else { Color32::from_rgb(90, 200, 255) };
        painter.circle(pos, 5.0, colour.gamma_multiply(0.35), Stroke::new(1.5, colour));
        if matches!(h.what, crate::viewer::HandleKind::Control(_)) {
            if let Some((_, prev)) = lines.iter().rev().find(|(w, _)| *w == h.wave) {
                painter.line_segment([*prev, pos], Stroke::new(1.0, colour.gamma_multiply(0.5)));
            }
            lines.push((h.wave.clone(), pos));
        }
        if hr.hovered() || hr.dragged() {
            on_handle = true;
        }
        if hr.drag_started() {
            st.drag_serial += 1;
            st.dragging = Some(h.clone());
        }
        if hr.dragged() {
            if let Some(pointer) = hr.interact_pointer_pos() {
                let depth = view_depth(&frame, h.world);
                let world = unproject(&frame, to_pixel(pointer), depth);
                let merge = format!("handle#{}", st.drag_serial);
                v.drag_handle(h, world, &merge);
            }
        }
    }

    // Camera and probe.
    if !on_handle && st.dragging.is_none() {
        let d = response.drag_delta();
        if response.dragged_by(egui::PointerButton::Primary) && d != Vec2::ZERO {
            v.orbit(-d.x * 0.3, d.y * 0.3);
        } else if (response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle))
            && d != Vec2::ZERO
        {
            v.pan(d.x / rect.height(), -d.y / rect.height());
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                v.zoom((-scroll * 0.002).exp());
            }
        }
        if response.clicked() {
            if let Some(p) = response.interact_pointer_pos() {
                let px = to_pixel(p);
                if rect.contains(p) && px[0] >= 0.0 && px[1] >= 0.0 {
                    v.requests.push(Request::Probe([px[0] as u32, px[1] as u32]));
                }
            }
        }
    }
    if let Some([x, y]) = v.probe_at {
        let c = to_screen([x as f32 + 0.5, y as f32 + 0.5]);
        let stroke = Stroke::new(1.0, Color32::from_rgb(255, 220, 80));
        painter.line_segment([c - Vec2::new(7.0, 0.0), c - Vec2::new(2.0, 0.0)], stroke);
        painter.line_segment([c + Vec2::new(2.0, 0.0), c + Vec2::new(7.0, 0.0)], stroke);
        painter.line_segment([c - Vec2::new(0.0, 7.0), c - Vec2::new(0.0, 2.0)], stroke);
        painter.line_segment([c + Vec2::new(0.0, 2.0), c + Vec2::new(0.0, 7.0)], stroke);
    }
    if let Some(e) = v.doc.reload_error() {
        let r = Rect::from_min_size(avail.min + Vec2::splat(8.0), Vec2::new(avail.width() - 16.0, 0.0));
        painter.text(
            r.min,
            egui::Align2::LEFT_TOP,
            format!("⚠ {e}"),
            egui::FontId::monospace(13.0),
            ERROR_COLOUR,
        );
    }
}
