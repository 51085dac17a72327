//! The viewer's state without a window: parameter edits, keys, the firing preset, undo/redo,
//! save/load round trips with comments kept, hot reload with errors, scripts.

use hadou_view::document::{Document, Edit, Reload};
use hadou_view::script;
use hadou_view::viewer::{HandleKind, Request, Viewer};
use std::path::{Path, PathBuf};

const SCENE: &str = r#"# A test scene: this comment must survive every edit.
background = [0.02, 0.02, 0.05] # trailing comment

[image]
width = 64
height = 48

[camera]
position = [0.0, 2.0, 12.0]   # eye
target = [0.0, 0.0, 0.0]
fov = 50.0

[[object]]
name = "ground"
kind = "plane"
position = [0.0, -1.0, 0.0]

[[wave]]
name = "beam"
kind = "beam"
M = [-4.0, 0.0, 0.0]
D = [1.0, 0.0, 0.0]
length = 6.0
alpha_s = 0.08
alpha_c = 0.08

[[wave]]
name = "curve"
kind = "bezier"
O = [-3.0, 1.0, 0.0]
D = [1.0, 0.0, 0.0]
alpha = 0.05
gamma = 6.0
points = [[0.0, 0.0], [1.0, 0.0], [0.0, 0.5]]

[[track]]
target = "wave.beam.alpha_c"
keys = [[0.0, 0.08], [2.0, 0.2]]
"#;

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hadou-view-state-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn doc(name: &str) -> (Document, PathBuf) {
    let d = dir(name);
    let p = d.join("scene.toml");
    std::fs::write(&p, SCENE).unwrap();
    (Document::open(&p).unwrap(), p)
}

fn value(d: &Document, target: &str, t: f32) -> Vec<f32> {
    d.scene().value_at(target, t).unwrap()
}

#[test]
fn set_edits_the_scene_and_keeps_comments_and_layout() {
    let (mut d, _) = doc("set");
    d.apply(&Edit::Set { target: "wave.beam.length".into(), value: vec![3.5] }).unwrap();
    assert_eq!(value(&d, "wave.beam.length", 0.0), vec![3.5]);
    d.apply(&Edit::Set { target: "camera.position".into(), value: vec![1.0, 2.5, 9.0] }).unwrap();
    let text = d.text();
    assert!(text.contains("# A test scene: this comment must survive every edit."));
    assert!(text.contains("# trailing comment"));
    assert!(text.contains("position = [1.0, 2.5, 9.0]   # eye"), "{text}");
    assert!(text.contains("length = 3.5\n"));
    // Only the edited lines changed.
    let changed = SCENE.lines().zip(text.lines()).filter(|(a, b)| a != b).count();
    assert_eq!(changed, 2, "{text}");
    assert_eq!(SCENE.lines().count(), text.lines().count());
    // A key the file leaves out is added to its table.
    d.apply(&Edit::Set { target: "camera.near".into(), value: vec![0.5] }).unwrap();
    assert_eq!(value(&d, "camera.near", 0.0), vec![0.5]);
    // f32 values are written as their shortest decimal.
    d.apply(&Edit::Set { target: "wave.beam.alpha_s".into(), value: vec![0.1] }).unwrap();
    assert!(d.text().contains("alpha_s = 0.1\n"), "{}", d.text());
}

#[test]
fn refused_edits_change_nothing() {
    let (mut d, _) = doc("refuse");
    let before = d.text().to_string();
    let e = d.apply(&Edit::Set { target: "camera.fov".into(), value: vec![500.0] }).unwrap_err();
    assert!(e.0.contains("fov"), "{e}");
    assert_eq!(d.text(), before);
    assert!(!d.can_undo());
    assert!(d.apply(&Edit::Set { target: "wave.nope.M".into(), value: vec![0.0; 3] }).is_err());
    // Values of the wrong shape: too few or too many numbers, an odd count for a list of pairs.
    assert!(d.apply(&Edit::Set { target: "camera.position".into(), value: vec![1.0] }).is_err());
    assert!(d.apply(&Edit::Set { target: "camera.position".into(), value: vec![1.0; 4] }).is_err());
    assert!(d.apply(&Edit::Set { target: "wave.curve.points".into(), value: vec![0.0; 5] }).is_err());
    assert!(d.apply(&Edit::Key { target: "camera.fov".into(), time: 1.0, value: vec![] }).is_err());
    // Eye on the target: the camera rule of the loader.
    assert!(d.apply(&Edit::Set { target: "camera.position".into(), value: vec![0.0; 3] }).is_err());
    assert_eq!(d.text(), before);
}

#[test]
fn undo_redo_and_merged_drags() {
    let (mut d, _) = doc("undo");
    for (i, l) in [1.0, 2.0, 3.0].into_iter().enumerate() {
        let merge = Some("drag");
        d.apply_merged(&Edit::Set { target: "wave.beam.length".into(), value: vec![l] }, merge).unwrap();
        assert_eq!(value(&d, "wave.beam.length", 0.0), vec![l], "step {i}");
    }
    d.end_merge();
    d.apply(&Edit::Set { target: "wave.beam.alpha_s".into(), value: vec![0.2] }).unwrap();
    assert!(d.undo());
    assert_eq!(value(&d, "wave.beam.alpha_s", 0.0), vec![0.08]);
    assert_eq!(value(&d, "wave.beam.length", 0.0), vec![3.0]);
    // The whole drag is one step.
    assert!(d.undo());
    assert_eq!(value(&d, "wave.beam.length", 0.0), vec![6.0]);
    assert_eq!(d.text(), SCENE);
    assert!(!d.undo());
    assert!(d.redo());
    assert!(d.redo());
    assert_eq!(value(&d, "wave.beam.alpha_s", 0.0), vec![0.2]);
    assert!(!d.redo());
    // A new edit clears the redo list.
    d.undo();
    d.apply(&Edit::Set { target: "wave.beam.alpha_c".into(), value: vec![0.3] }).unwrap();
    assert!(!d.can_redo());
}

#[test]
fn keys_insert_replace_and_remove() {
    let (mut d, _) = doc("keys");
    let t = "wave.beam.alpha_c";
    d.apply(&Edit::Key { target: t.into(), time: 1.0, value: vec![0.5] }).unwrap();
    assert_eq!(value(&d, t, 1.0), vec![0.5]);
    assert!(d.text().contains("keys = [[0.0, 0.08], [1.0, 0.5], [2.0, 0.2]]"), "{}", d.text());
    d.apply(&Edit::Key { target: t.into(), time: 1.0, value: vec![0.4] }).unwrap();
    assert_eq!(value(&d, t, 1.0), vec![0.4]);
    assert_eq!(d.scene().tracks()[0].times, vec![0.0, 1.0, 2.0]);
    // A new track for a vector.
    d.apply(&Edit::Key { target: "camera.position".into(), time: 0.5, value: vec![1.0, 2.0, 10.0] }).unwrap();
    assert_eq!(value(&d, "camera.position", 3.0), vec![1.0, 2.0, 10.0]);
    assert!(d.scene().is_animated("camera.position"));
    d.apply(&Edit::RemoveKey { target: "camera.position".into(), time: 0.5 }).unwrap();
    assert!(!d.scene().is_animated("camera.position"), "the last key removes the track");
    d.apply(&Edit::RemoveKey { target: t.into(), time: 1.0 }).unwrap();
    assert!(d.text().contains("keys = [[0.0, 0.08], [2.0, 0.2]]"), "{}", d.text());
    assert!(d.apply(&Edit::RemoveKey { target: t.into(), time: 7.0 }).is_err());
    assert!(d.apply(&Edit::Key { target: t.into(), time: -1.0, value: vec![0.1] }).is_err());
}

#[test]
fn firing_preset_grows_the_wave() {
    let (mut d, _) = doc("fire");
    d.apply(&Edit::Fire { wave: "beam".into(), start: 0.5, duration: 1.0 }).unwrap();
    assert_eq!(value(&d, "wave.beam.length", 0.0), vec![0.0]);
    assert_eq!(value(&d, "wave.beam.length", 0.5), vec![0.0]);
    let mid = value(&d, "wave.beam.length", 1.0)[0];
    assert!(mid > 0.5 && mid < 5.5, "{mid}");
    assert_eq!(value(&d, "wave.beam.length", 1.5), vec![6.0]);
    d.apply(&Edit::Fire { wave: "curve".into(), start: 0.0, duration: 2.0 }).unwrap();
    assert!(value(&d, "wave.curve.k", 0.0)[0] < 0.01);
    assert_eq!(value(&d, "wave.curve.k", 2.0), vec![1.0]);
    // Firing again replaces the track instead of adding a second one (which would not load).
    d.apply(&Edit::Fire { wave: "beam".into(), start: 0.0, duration: 0.5 }).unwrap();
    assert_eq!(value(&d, "wave.beam.length", 0.5), vec![6.0]);
    assert!(d.apply(&Edit::Fire { wave: "nope".into(), start: 0.0, duration: 1.0 }).is_err());
    assert!(d.apply(&Edit::Fire { wave: "beam".into(), start: 0.0, duration: 0.0 }).is_err());
}

#[test]
fn add_and_remove_waves_and_objects() {
    let (mut d, _) = doc("add");
    for kind in hadou_scene::WAVE_KINDS {
        d.apply(&Edit::AddWave { kind: kind.to_string(), at: [0.0, 0.0, 0.0] })
            .unwrap_or_else(|e| panic!("{kind}: {e}"));
    }
    assert_eq!(d.scene().wave_names().len(), 2 + hadou_scene::WAVE_KINDS.len());
    assert!(d.scene().wave_names().contains(&"helix1"));
    for kind in ["box", "sphere", "plane"] {
        d.apply(&Edit::AddObject { kind: kind.into(), at: [1.0, 0.0, 0.0] }).unwrap();
    }
    assert_eq!(d.scene().object_names(), vec!["ground", "box1", "sphere1", "plane1"]);
    assert!(d.apply(&Edit::AddObject { kind: "teapot".into(), at: [0.0; 3] }).is_err());
    // Removing a wave removes its tracks.
    d.apply(&Edit::RemoveWave("beam".into())).unwrap();
    assert!(!d.scene().wave_names().contains(&"beam"));
    assert!(d.scene().tracks().is_empty());
    assert!(!d.text().contains("wave.beam"));
    d.apply(&Edit::RemoveObject("ground".into())).unwrap();
    assert!(!d.scene().object_names().contains(&"ground"));
    assert!(d.apply(&Edit::RemoveObject("ground".into())).is_err());
    // Still a file the loader takes, comments and all.
    assert!(d.text().starts_with("# A test scene"));
    hadou_scene::Scene::parse(d.text(), Path::new("x.toml")).unwrap();
}

#[test]
fn save_load_round_trip() {
    let (mut d, p) = doc("save");
    d.apply(&Edit::Set { target: "wave.curve.points".into(), value: vec![0.0, 0.0, 2.0, 1.0, 0.0, 0.5] })
        .unwrap();
    d.apply(&Edit::Key { target: "wave.beam.M".into(), time: 1.0, value: vec![-4.0, 1.0, 0.0] }).unwrap();
    assert!(d.is_dirty());
    d.save().unwrap();
    assert!(!d.is_dirty());
    let back = Document::open(&p).unwrap();
    assert_eq!(back.text(), d.text());
    for p in d.scene().parameters() {
        assert_eq!(back.scene().value_at(&p.target, 1.0), d.scene().value_at(&p.target, 1.0), "{}", p.target);
    }
    assert_eq!(back.scene().tracks(), d.scene().tracks());
    // No temporary file is left behind.
    let left: Vec<_> =
        std::fs::read_dir(p.parent().unwrap()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left.len(), 1, "{left:?}");
}

#[test]
fn save_in_the_web_page_asks_for_a_download_and_writes_nothing() {
    let (d, p) = doc("download");
    let mut v = Viewer::new(d);
    v.save_downloads = true;
    assert!(v.edit_value("wave.beam.alpha_s", vec![0.12], None));
    assert!(v.doc.is_dirty());
    v.save();
    assert_eq!(v.requests, vec![Request::DownloadScene]);
    assert!(!v.doc.is_dirty(), "the downloaded text counts as saved");
    assert_eq!(std::fs::read_to_string(&p).unwrap(), SCENE, "the file on disk is untouched");
    assert!(v.message.as_ref().is_some_and(|(m, err)| m.contains("scene.toml") && !err), "{:?}", v.message);
}

#[cfg(unix)]
#[test]
fn save_to_a_read_only_place_keeps_the_edits() {
    use std::os::unix::fs::PermissionsExt;
    let (mut d, p) = doc("readonly");
    d.apply(&Edit::Set { target: "wave.beam.length".into(), value: vec![2.0] }).unwrap();
    let dir = p.parent().unwrap().to_path_buf();
    // A path in a missing directory fails for everyone, root included.
    let e = d.save_as(&dir.join("missing/dir/scene.toml")).unwrap_err();
    assert!(e.0.contains("edits are kept"), "{e}");
    assert!(d.is_dirty(), "the edit is still unsaved");
    assert_eq!(d.path(), p, "the document keeps its file");
    assert_eq!(value(&d, "wave.beam.length", 0.0), vec![2.0]);
    // A read-only file and directory (where permissions bind: not for root).
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o444)).unwrap();
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o555)).unwrap();
    let probe = dir.join("probe");
    let binding = std::fs::write(&probe, b"x").is_err();
    let _ = std::fs::remove_file(&probe);
    if binding {
        let e = d.save().unwrap_err();
        assert!(e.0.contains("cannot save") && e.0.contains("edits are kept"), "{e}");
        assert!(d.is_dirty());
        assert_eq!(value(&d, "wave.beam.length", 0.0), vec![2.0]);
    }
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o644)).unwrap();
    assert_eq!(std::fs::read_to_string(&p).unwrap(), SCENE, "the file is untouched");
}

fn rewrite(p: &Path, text: &str) {
    // Make sure the stamp changes even on coarse file-time clocks.
    let old = std::fs::metadata(p).unwrap().modified().unwrap();
    std::fs::write(p, text).unwrap();
    let f = std::fs::File::options().write(true).open(p).unwrap();
    f.set_modified(old + std::time::Duration::from_secs(2)).unwrap();
}

#[test]
fn hot_reload_takes_good_files_and_reports_bad_ones() {
    let (mut d, p) = doc("reload");
    assert_eq!(d.poll_disk(), Reload::Unchanged);
    rewrite(&p, &SCENE.replace("length = 6.0", "length = 4.0"));
    assert_eq!(d.poll_disk(), Reload::Reloaded);
    assert_eq!(value(&d, "wave.beam.length", 0.0), vec![4.0]);
    assert!(!d.is_dirty());
    // A broken file: the message names the line and column; the last good scene stays.
    let broken = SCENE.replace("length = 6.0", "length = -1.0");
    rewrite(&p, &broken);
    match d.poll_disk() {
        Reload::Failed(m) => {
            let line = broken.lines().position(|l| l.contains("length = -1.0")).unwrap() + 1;
            assert!(m.contains(&format!("scene.toml:{line}:")), "{m}");
        }
        other => panic!("{other:?}"),
    }
    assert!(d.reload_error().is_some());
    assert_eq!(value(&d, "wave.beam.length", 0.0), vec![4.0]);
    // Not re-reported until it changes again; fixed → reloaded and the error clears.
    assert_eq!(d.poll_disk(), Reload::Unchanged);
    rewrite(&p, SCENE);
    assert_eq!(d.poll_disk(), Reload::Reloaded);
    assert!(d.reload_error().is_none());
    // The reload is one undo step.
    assert!(d.undo());
    assert_eq!(value(&d, "wave.beam.length", 0.0), vec![4.0]);
    // Our own save is not taken for an outside change.
    d.save().unwrap();
    assert_eq!(d.poll_disk(), Reload::Unchanged);
}

#[test]
fn viewer_keys_animated_parameters_and_sets_static_ones() {
    let (d, _) = doc("viewer");
    let mut v = Viewer::new(d);
    v.timeline.time = 1.0;
    assert!(v.edit_value("wave.beam.alpha_c", vec![0.5], None));
    assert_eq!(v.scene().value_at("wave.beam.alpha_c", 1.0), Some(vec![0.5]));
    assert_eq!(v.scene().tracks()[0].times, vec![0.0, 1.0, 2.0]);
    assert!(v.edit_value("wave.beam.alpha_s", vec![0.3], None));
    assert!(v.doc.text().contains("alpha_s = 0.3"));
    assert!(v.key_current("wave.beam.length"));
    assert!(v.scene().is_animated("wave.beam.length"));
    assert!(!v.edit_value("camera.fov", vec![0.0], None));
    assert!(v.message.as_ref().is_some_and(|m| m.1));
}

#[test]
fn timeline_plays_loops_and_stops() {
    let (d, _) = doc("timeline");
    let mut v = Viewer::new(d);
    v.tick(0.5);
    assert_eq!(v.timeline.time, 0.0, "paused");
    v.timeline.playing = true;
    v.tick(0.5);
    assert!((v.timeline.time - 0.5).abs() < 1e-6);
    v.tick(2.0);
    assert!((v.timeline.time - 0.5).abs() < 1e-5, "wrapped: {}", v.timeline.time);
    v.timeline.looping = false;
    v.tick(5.0);
    assert_eq!(v.timeline.time, 2.0);
    assert!(!v.timeline.playing);
    v.timeline.playing = true;
    v.tick(f32::NAN);
    assert_eq!(v.timeline.time, 2.0);
}

#[test]
fn camera_moves_keep_the_distance_and_undo_as_one_step() {
    let (d, _) = doc("camera");
    let mut v = Viewer::new(d);
    let eye0 = v.scene().value_at("camera.position", 0.0).unwrap();
    let dist = |e: &[f32]| (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
    assert!(v.orbit(90.0, 0.0));
    let eye1 = v.scene().value_at("camera.position", 0.0).unwrap();
    assert!((dist(&eye1) - dist(&eye0)).abs() < 1e-3, "{eye0:?} {eye1:?}");
    assert!((eye1[0] - 12.0).abs() < 1e-3 && eye1[2].abs() < 1e-3, "{eye1:?}");
    assert!(v.orbit(0.0, 200.0), "pitch is clamped short of the pole");
    assert!(v.zoom(0.5));
    let eye2 = v.scene().value_at("camera.position", 0.0).unwrap();
    assert!((dist(&eye2) - dist(&eye0) / 2.0).abs() < 1e-2);
    assert!(v.pan(0.1, 0.0));
    let target = v.scene().value_at("camera.target", 0.0).unwrap();
    assert!(dist(&target) > 0.1);
    v.doc.undo();
    assert_eq!(v.scene().value_at("camera.position", 0.0).unwrap(), eye0, "all moves merged");
}

#[test]
fn handles_project_and_drag() {
    let (d, _) = doc("handles");
    let mut v = Viewer::new(d);
    let hs = v.handles();
    let head = hs.iter().find(|h| h.what == HandleKind::Head).expect("beam head");
    assert!((head.world.x - 2.0).abs() < 1e-5);
    let frame = v.frame();
    let px = hadou_view::viewer::project(&frame, head.world).unwrap();
    let back = hadou_view::viewer::unproject(&frame, px, hadou_view::viewer::view_depth(&frame, head.world));
    assert!((back - head.world).length() < 1e-3, "{back:?}");
    assert!(v.drag_handle(&head.clone(), hadou_math::Vec3f::new(-4.0, 3.0, 0.0), "d"));
    assert_eq!(v.scene().value_at("wave.beam.length", 0.0), Some(vec![3.0]));
    let c = hs.iter().find(|h| h.what == HandleKind::Control(1)).unwrap().clone();
    assert!(v.drag_handle(&c, c.world + hadou_math::Vec3f::new(0.0, 1.0, 0.0), "d"));
    let pts = v.scene().value_at("wave.curve.points", 0.0).unwrap();
    assert!((pts[2] - 2.0).abs() < 1e-5, "{pts:?}");
    v.selected_wave = Some("curve".into());
    assert!(v.handles().iter().all(|h| h.wave == "curve"));
}

#[test]
fn scripts_parse_with_positions_and_run() {
    let (d, p) = doc("script");
    let sp = p.parent().unwrap().join("s.txt");
    let text = "# comment\ntime 1\nset wave.beam.length 2.5\nkey wave.beam.alpha_s\nfire curve 0.5\nwait 3\nprobe 10 20\nscreenshot out.png\nundo\nredo\nquit\n";
    let lines = script::parse(text, &sp).unwrap();
    assert_eq!(lines.len(), 10);
    let mut v = Viewer::new(d);
    for l in &lines {
        script::run(&mut v, l, &sp).unwrap();
    }
    assert_eq!(v.timeline.time, 1.0);
    assert_eq!(v.scene().value_at("wave.beam.length", 1.0), Some(vec![2.5]));
    assert!(v.scene().is_animated("wave.curve.k"));
    assert!(v.requests.contains(&Request::Probe([10, 20])));
    assert!(v.requests.contains(&Request::Screenshot(sp.parent().unwrap().join("out.png"))));
    // Errors name the file, line and column.
    let e = script::parse("time 1\n  set wave.beam.length abc\n", &sp).unwrap_err();
    assert!(e.ends_with("s.txt:2:24: `abc` is not a finite number"), "{e}");
    let e = script::parse("frobnicate\n", &sp).unwrap_err();
    assert!(e.contains("s.txt:1:1: unknown command `frobnicate`"), "{e}");
    assert!(script::parse("export out.gif 5..2 24\n", &sp).is_err());
    // A command that fails is an error with its line.
    let bad = script::parse("set camera.fov 900\n", &sp).unwrap();
    let e = script::run(&mut v, &bad[0], &sp).unwrap_err();
    assert!(e.contains("s.txt:1:") && e.contains("fov"), "{e}");
}

#[test]
fn choices_and_interpolation_edit_the_file() {
    let (mut d, _) = doc("choices");
    let faithful = |d: &Document| {
        d.scene()
            .at(0.0)
            .waves
            .iter()
            .any(|w| w.name == "beam" && w.falloff == hadou_math::energy::Falloff::Faithful)
    };
    assert!(!faithful(&d));
    d.apply(&Edit::Choice {
        entity: hadou_scene::Entity::Wave("beam".into()),
        key: "falloff".into(),
        value: "faithful".into(),
    })
    .unwrap();
    assert!(faithful(&d));
    // A value the loader refuses is refused.
    assert!(d
        .apply(&Edit::Choice { entity: hadou_scene::Entity::Color, key: "mode".into(), value: "neon".into() })
        .is_err());
    d.apply(&Edit::Choice {
        entity: hadou_scene::Entity::Color,
        key: "mode".into(),
        value: "faithful".into(),
    })
    .unwrap();
    assert_eq!(d.scene().at(0.0).color_mapping.mode, hadou_scene::ToneMode::Faithful);
    assert!(d.text().contains("[color]\nmode = \"faithful\""), "{}", d.text());
    let t = "wave.beam.alpha_c";
    d.apply(&Edit::Interpolation { target: t.into(), value: "smooth".into() }).unwrap();
    assert_eq!(d.scene().tracks()[0].interpolation, hadou_scene::Interpolation::Smooth);
    assert!(d.apply(&Edit::Interpolation { target: "camera.fov".into(), value: "smooth".into() }).is_err());
}

#[test]
fn other_keys_are_listed_and_edited_as_toml() {
    use hadou_scene::Entity;
    let (mut d, _) = doc("raw");
    assert_eq!(
        d.other_keys(&Entity::Image),
        vec![("width".to_string(), "64".to_string()), ("height".to_string(), "48".to_string())]
    );
    // Animatable keys and names have their own controls; structural keys are listed.
    let wave = Entity::Wave("curve".into());
    let keys: Vec<String> = d.other_keys(&wave).into_iter().map(|(k, _)| k).collect();
    assert_eq!(keys, vec!["kind"]);
    d.apply(&Edit::Raw { entity: Entity::Image, key: "width".into(), value: "32".into() }).unwrap();
    assert_eq!(d.scene().width(), 32);
    assert!(d.text().contains("width = 32\n"));
    let ramp = "[[-1, 0, 0.2, 0.4], [0, 0.9, 0.9, 1]]";
    d.apply(&Edit::Raw { entity: wave.clone(), key: "light_ramp".into(), value: ramp.into() }).unwrap();
    assert!(d.other_keys(&wave).contains(&("light_ramp".to_string(), ramp.to_string())));
    // Not TOML, refused by the loader, or not a key: nothing changes.
    let before = d.text().to_string();
    let e =
        d.apply(&Edit::Raw { entity: Entity::Image, key: "width".into(), value: "[1,".into() }).unwrap_err();
    assert!(e.0.contains("not a TOML value"), "{e}");
    let e =
        d.apply(&Edit::Raw { entity: Entity::Image, key: "width".into(), value: "0".into() }).unwrap_err();
    assert!(e.0.contains("width"), "{e}");
    assert!(d.apply(&Edit::Raw { entity: Entity::Image, key: "name".into(), value: "1".into() }).is_err());
    assert!(d.apply(&Edit::Raw { entity: Entity::Image, key: "a b".into(), value: "1".into() }).is_err());
    assert_eq!(d.text(), before);
    // Empty text removes the key: its default applies.
    d.apply(&Edit::Raw { entity: Entity::Camera, key: "fov".into(), value: String::new() }).unwrap();
    assert_eq!(d.scene().value_at("camera.fov", 0.0), Some(vec![45.0]));
    assert!(!d.text().contains("fov"));
}

/// Every script command that names a wave, object or parameter fails the same way when the scene
/// has no such thing: an error at the name's `file:line:col`, listing what it could be, and
/// nothing changed (`select nobody` used to pass silently).
#[test]
fn script_commands_naming_nothing_fail_at_the_name_with_the_candidates() {
    let (d, p) = doc("names");
    let sp = p.parent().unwrap().join("s.txt");
    let mut v = Viewer::new(d);
    let before = v.doc.text().to_string();
    let cases = [
        ("select nobody", "s.txt:1:8: no wave is named \"nobody\"; the waves are `beam`, `curve`"),
        ("fire nobody 0.5", "s.txt:1:6: no wave is named \"nobody\"; the waves are `beam`, `curve`"),
        ("remove wave nobody", "s.txt:1:13: no wave is named \"nobody\"; the waves are `beam`, `curve`"),
        ("remove object nobody", "s.txt:1:15: no object is named \"nobody\"; the objects are `ground`"),
        (
            "set wave.nobody.alpha 1",
            "s.txt:1:5: the scene has no parameter `wave.nobody.alpha`; `wave.nobody` is none of the \
             scene's tables, which are `camera`,",
        ),
        (
            "set wave.beam.alpah_s 1",
            "s.txt:1:5: the scene has no parameter `wave.beam.alpah_s`; `wave.beam` has `",
        ),
        ("  key wave.nobody.k", "s.txt:1:7: the scene has no parameter `wave.nobody.k`"),
        ("unkey wave.nobody.k", "s.txt:1:7: the scene has no parameter `wave.nobody.k`"),
        (
            "unkey wave.beam.length",
            "s.txt:1:7: no track animates `wave.beam.length`; the tracks animate `wave.beam.alpha_c`",
        ),
    ];
    for (text, want) in cases {
        let lines = script::parse(text, &sp).unwrap();
        let e = script::run(&mut v, &lines[0], &sp).unwrap_err();
        assert!(e.contains(want), "{text}: {e}");
        assert!(v.requests.is_empty() && v.selected_wave.is_none(), "{text}");
        assert_eq!(v.doc.text(), before, "{text} changed the document");
    }
    // The names it lists include the parameters of the table it names.
    let lines = script::parse("set wave.beam.alpah_s 1", &sp).unwrap();
    let e = script::run(&mut v, &lines[0], &sp).unwrap_err();
    assert!(e.contains("`alpha_s`") && e.contains("`length`"), "{e}");
    // The same commands on names the scene has pass.
    for text in
        ["select beam", "select none", "fire curve 0.5", "set wave.beam.alpha_s 0.1", "key wave.beam.length"]
    {
        let lines = script::parse(text, &sp).unwrap();
        script::run(&mut v, &lines[0], &sp).unwrap_or_else(|e| panic!("{text}: {e}"));
    }
    assert_eq!(v.selected_wave, None);
    // A long list is cut at 40 names, with the count.
    let mut many = String::from("[camera]\nposition = [0.0, 0.0, 10.0]\n");
    for i in 0..50 {
        many +=
            &format!("[[wave]]\nname = \"w{i}\"\nkind = \"sphere\"\nM = [0.0, 0.0, 0.0]\nalpha_s = 0.1\n");
    }
    let many_path = p.parent().unwrap().join("many.toml");
    std::fs::write(&many_path, &many).unwrap();
    let mut v = Viewer::new(Document::open(&many_path).unwrap());
    let lines = script::parse("select nobody", &sp).unwrap();
    let e = script::run(&mut v, &lines[0], &sp).unwrap_err();
    assert!(e.contains("`w39`, … (50 in all)") && !e.contains("`w40`"), "{e}");
}
