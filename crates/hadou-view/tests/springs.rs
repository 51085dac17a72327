//! A VRM character's spring bones, wind and look-at in the viewer, without a window: `spring`
//! (a checkbox), `look_at` (none, the camera, a wave, a point) and a wave's `wind` edit the scene
//! file's text and change the posed mesh the renderers draw; scripts reach them as `spring`,
//! `look_at` and `set`.

use hadou_scene::LookAtTarget;
use hadou_view::document::{Document, Gaze};
use hadou_view::script;
use hadou_view::viewer::Viewer;
use std::path::{Path, PathBuf};

fn blast_vrm() -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/assets/blast.vrm")).to_path_buf()
}

const BEAM: &str = "[[wave]]\nname = \"beam\"\nkind = \"beam\"\nrgba = [0.45, 0.8, 1.0, 1.0]\n\
                    M = [0.95, 1.3, 3.0]\nD = [0.0, 0.0, -1.0]\nlength = 6.0\nalpha_s = 0.02\n\
                    alpha_c = 0.02\ncore_radius = 0.05\nwind = 0.0 # the push\n";

/// blast.vrm (hair and skirt on spring bones) given look-at of type expression: `lookLeft` closes
/// the eyes (the head's first morph target), `lookUp` opens the mouth (its second), 0–90° → 0–1.
fn blast_with_eyes() -> Vec<u8> {
    let data = std::fs::read(blast_vrm()).unwrap();
    let le = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize;
    let n = le(&data[12..16]);
    let json = std::str::from_utf8(&data[20..20 + n]).unwrap();
    let (bone, preset) = (r#""lookAt":{"offsetFromHeadBone":[0.0,0.1,0.1],"type":"bone"}"#, r#""preset":{"#);
    assert!(json.contains(bone) && json.contains(preset), "blast.vrm's look-at and expressions as written");
    let map = r#"{"inputMaxValue":90.0,"outputScale":1.0}"#;
    let look = format!(
        r#""lookAt":{{"offsetFromHeadBone":[0.0,0.1,0.1],"type":"expression","rangeMapHorizontalInner":{map},"rangeMapHorizontalOuter":{map},"rangeMapVerticalDown":{map},"rangeMapVerticalUp":{map}}}"#
    );
    let bind = |i: u32| format!(r#"{{"morphTargetBinds":[{{"node":241,"index":{i},"weight":1.0}}]}}"#);
    let presets = format!(r#""preset":{{"lookLeft":{},"lookUp":{},"#, bind(0), bind(1));
    let mut j = json.replacen(bone, &look, 1).replacen(preset, &presets, 1).into_bytes();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut out = data[..12].to_vec();
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&j);
    out.extend(&data[20 + n..]);
    let total = out.len() as u32;
    out[8..12].copy_from_slice(&total.to_le_bytes());
    out
}

/// A scene in a fresh directory holding blast.vrm with eyes ([`blast_with_eyes`]), with `keys` on
/// its object and a beam passing it.
fn viewer(name: &str, keys: &str) -> (Viewer, PathBuf) {
    let d = std::env::temp_dir().join(format!("hadou-view-springs-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("blast.vrm"), blast_with_eyes()).unwrap();
    let text = format!(
        "# the character\n[image]\nwidth = 64\nheight = 48\n\n[camera]\nposition = [1.6, 1.9, 3.2]\n\
         target = [0.15, 1.1, 0.0]\n\n[[object]]\nname = \"hero\"\nkind = \"gltf\"\npath = \"blast.vrm\" # keep\n\
         {keys}\n{BEAM}"
    );
    let p = d.join("scene.toml");
    std::fs::write(&p, text).unwrap();
    (Viewer::new(Document::open(&p).unwrap()), d)
}

fn positions(v: &Viewer, t: f32) -> Vec<[f32; 3]> {
    v.scene().at(t).objects[0].mesh.positions.clone()
}

fn spread(a: &[[f32; 3]], b: &[[f32; 3]]) -> f32 {
    a.iter().zip(b).map(|(p, q)| (0..3).map(|i| (p[i] - q[i]).abs()).fold(0.0, f32::max)).fold(0.0, f32::max)
}

#[test]
fn the_spring_checkbox_writes_spring_and_stills_the_hair() {
    let (mut v, _d) = viewer("spring", "");
    let c = v.characters();
    assert_eq!(c.len(), 1);
    assert_eq!(c[0].object, "hero");
    assert!(c[0].has_springs && c[0].spring && c[0].has_look_at, "{c:?}");
    assert_eq!(c[0].look_at, None);
    let falling = spread(&positions(&v, 0.0), &positions(&v, 1.0));
    assert!(falling > 1e-3, "the strands fall under gravity when spring is on: {falling}");
    assert!(v.set_spring("hero", false));
    let text = v.doc.text().to_string();
    assert!(text.contains("spring = false"), "{text}");
    assert!(text.contains("path = \"blast.vrm\" # keep\n") && text.starts_with("# the character\n"));
    assert!(!v.characters()[0].spring);
    assert_eq!(v.scene().object_springs()[0], (0, 0));
    assert_eq!(spread(&positions(&v, 0.0), &positions(&v, 1.0)), 0.0, "spring = false: the strands rest");
    // Back on: the same key, edited in place; one undo step each.
    assert!(v.set_spring("hero", true));
    assert!(v.doc.text().contains("spring = true") && !v.doc.text().contains("spring = false"));
    assert!(spread(&positions(&v, 0.0), &positions(&v, 1.0)) > 1e-3);
    v.undo();
    assert!(v.doc.text().contains("spring = false"));
    v.undo();
    assert!(!v.doc.text().contains("spring ="));
    // The keys with controls of their own are not among the other keys.
    v.set_spring("hero", false);
    v.set_look_at("hero", Gaze::Camera);
    let other: Vec<String> =
        v.doc.other_keys(&hadou_scene::Entity::Object("hero".into())).into_iter().map(|k| k.0).collect();
    assert!(!other.iter().any(|k| k == "spring" || k == "look_at"), "{other:?}");
    assert!(other.iter().any(|k| k == "path"), "{other:?}");
}

#[test]
fn the_look_at_choice_writes_look_at_and_turns_the_eyes() {
    let (mut v, _d) = viewer("look", "spring = false");
    let t = 0.5;
    let rest = positions(&v, t);
    // The camera.
    assert!(v.set_look_at("hero", Gaze::Camera));
    assert!(v.doc.text().contains("look_at = \"camera\""), "{}", v.doc.text());
    assert_eq!(v.characters()[0].look_at, Some(LookAtTarget::Camera));
    assert_eq!(v.gaze_point("hero"), [1.6, 1.9, 3.2]);
    let at_camera = positions(&v, t);
    assert!(spread(&rest, &at_camera) > 1e-5, "the eyes turn to the camera");
    // The wave's head, M + D·length.
    assert!(v.set_look_at("hero", Gaze::Wave("beam".into())));
    assert!(v.doc.text().contains("look_at = \"beam\""), "{}", v.doc.text());
    assert_eq!(v.characters()[0].look_at, Some(LookAtTarget::Wave("beam".into())));
    assert_eq!(v.gaze_point("hero"), [0.95, 1.3, -3.0]);
    let at_beam = positions(&v, t);
    assert!(spread(&at_camera, &at_beam) > 1e-5, "the eyes turn to the beam's head");
    // A point where the eyes look now keeps them there, and is an animatable parameter.
    let here = v.gaze_point("hero");
    assert!(v.set_look_at("hero", Gaze::Point(here)));
    assert!(v.doc.text().contains("look_at = [0.95, 1.3, -3.0]"), "{}", v.doc.text());
    assert_eq!(v.characters()[0].look_at, Some(LookAtTarget::Point));
    assert_eq!(positions(&v, t), at_beam, "the same point, the same eyes");
    assert!(v.scene().parameters().iter().any(|p| p.target == "object.hero.look_at"));
    assert!(v.key_current("object.hero.look_at"));
    assert!(v.doc.text().contains("target = \"object.hero.look_at\""));
    assert!(v.edit_value("object.hero.look_at", vec![1.6, 1.9, 3.2], None));
    assert_eq!(positions(&v, t), at_camera, "the point keyed at the camera's position");
    // Any other choice drops the point's track with the point.
    assert!(v.set_look_at("hero", Gaze::Camera));
    assert!(!v.doc.text().contains("object.hero.look_at"), "{}", v.doc.text());
    assert_eq!(positions(&v, t), at_camera);
    // A wave the scene lacks is refused with the waves' names, and nothing changes.
    let before = v.doc.text().to_string();
    assert!(!v.set_look_at("hero", Gaze::Wave("nothing".into())));
    let (m, bad) = v.message.clone().unwrap();
    assert!(bad && m.contains("nothing") && m.contains("beam"), "{m}");
    assert_eq!(v.doc.text(), before);
    // None removes the key: the eyes rest.
    assert!(v.set_look_at("hero", Gaze::None));
    assert!(!v.doc.text().contains("look_at"));
    assert_eq!(v.characters()[0].look_at, None);
    assert_eq!(positions(&v, t), rest);
    // Removing the wave the eyes follow removes `look_at` with it.
    assert!(v.set_look_at("hero", Gaze::Wave("beam".into())));
    assert!(v.apply(hadou_view::document::Edit::RemoveWave("beam".into())));
    assert!(!v.doc.text().contains("look_at") && !v.doc.text().contains("[[wave]]"), "{}", v.doc.text());
    assert_eq!(positions(&v, t), rest);
}

#[test]
fn a_waves_wind_is_a_parameter_that_blows_the_strands() {
    let (mut v, _d) = viewer("wind", "");
    let p = v.scene().parameters().into_iter().find(|p| p.target == "wave.beam.wind").expect("wind is shown");
    assert_eq!(p.value, [0.0]);
    assert_eq!(p.range, hadou_scene::ParamRange::NonNeg);
    let t = 1.0;
    let calm = positions(&v, t);
    assert!(v.edit_value("wave.beam.wind", vec![40.0], None));
    assert!(v.doc.text().contains("wind = 40.0 # the push\n"), "{}", v.doc.text());
    let blown = positions(&v, t);
    assert!(spread(&calm, &blown) > 1e-3, "the wind moves the strands: {}", spread(&calm, &blown));
    // Animatable: a key at the current time makes a track.
    v.timeline.time = 0.5;
    assert!(v.key_current("wave.beam.wind"));
    assert!(v.doc.text().contains("target = \"wave.beam.wind\""));
    assert!(v.scene().is_animated("wave.beam.wind"));
}

#[test]
fn scripts_set_spring_look_at_and_wind() {
    let (mut v, d) = viewer("script", "");
    let path = d.join("s.txt");
    let text = "spring hero off\nlook_at hero camera\nlook_at hero beam\nlook_at hero 1 2 3\n\
                set wave.beam.wind 7\nlook_at hero none\n";
    let lines = script::parse(text, &path).unwrap();
    let mut texts = Vec::new();
    for l in &lines {
        script::run(&mut v, l, &path).unwrap();
        texts.push(v.doc.text().to_string());
    }
    assert!(texts[0].contains("spring = false"));
    assert!(texts[1].contains("look_at = \"camera\""));
    assert!(texts[2].contains("look_at = \"beam\""));
    assert!(texts[3].contains("look_at = [1.0, 2.0, 3.0]"), "{}", texts[3]);
    assert!(texts[4].contains("wind = 7.0"));
    assert!(!texts[5].contains("look_at"));
    // Bad words are located.
    let e = script::parse("spring hero maybe\n", &path).unwrap_err();
    assert!(e.contains("s.txt:1:13:") && e.contains("`on` or `off`"), "{e}");
    let e = script::parse("look_at hero 1 2\n", &path).unwrap_err();
    assert!(e.contains("s.txt:1:1:") && e.contains("X Y Z"), "{e}");
    let e = script::parse("look_at hero 1 x 2\n", &path).unwrap_err();
    assert!(e.contains("s.txt:1:16:"), "{e}");
    for (line, col, names) in [
        ("spring villain on", 8, "`hero`"),
        ("look_at villain camera", 9, "`hero`"),
        ("look_at hero moon", 14, "beam"),
    ] {
        let l = script::parse(line, &path).unwrap();
        let e = script::run(&mut v, &l[0], &path).unwrap_err();
        assert!(e.contains(&format!("s.txt:1:{col}:")) && e.contains(names), "{line}: {e}");
    }
}

#[test]
fn edits_that_leave_the_springs_alone_continue_their_state_with_the_same_bits() {
    let (mut v, d) = viewer("keep", "");
    v.timeline.time = 2.0;
    let cold = positions(&v, 2.0);
    assert_eq!(v.scene().spring_state_step("hero"), Some(120), "2 s at 60 steps a second");
    // The camera, a light: the state is kept, and the frame is the one a fresh scene gives.
    assert!(v.orbit(20.0, 5.0));
    assert!(v.edit_value("light.ambient", vec![0.3, 0.3, 0.3], None));
    assert_eq!(v.scene().spring_state_step("hero"), Some(120));
    assert_eq!(positions(&v, 2.0), cold);
    v.timeline.time = 2.5;
    let later = positions(&v, 2.5);
    assert_eq!(v.scene().spring_state_step("hero"), Some(150));
    let fresh = Document::from_text(v.doc.text(), &d.join("scene.toml")).unwrap();
    assert_eq!(fresh.scene().spring_state_step("hero"), None);
    assert_eq!(fresh.scene().at(2.5).objects[0].mesh.positions, later, "the same bits as stepping from 0");
    // Scrubbing back continues from the state kept each second on the way, the same bits.
    assert_eq!(v.scene().spring_marks("hero"), [60, 120]);
    let back = positions(&v, 1.25);
    assert_eq!(v.scene().spring_state_step("hero"), Some(75));
    let fresh = Document::from_text(v.doc.text(), &d.join("scene.toml")).unwrap();
    assert_eq!(fresh.scene().at(1.25).objects[0].mesh.positions, back);
    let _ = positions(&v, 2.5);
    // Undo of an edit that left the springs alone keeps them too.
    v.undo();
    assert_eq!(v.scene().spring_state_step("hero"), Some(150));
    // What drives the springs starts them again: the wind, the character's place, `spring`.
    for (target, value) in [("wave.beam.wind", vec![5.0]), ("object.hero.position", vec![0.1, 0.0, 0.0])] {
        assert!(v.edit_value(target, value, None));
        assert_eq!(v.scene().spring_state_step("hero"), None, "{target}");
        let _ = positions(&v, 2.5);
        assert_eq!(v.scene().spring_state_step("hero"), Some(150));
    }
    // With wind, any edit of a wave starts them again (the wind follows the waves' shapes).
    assert!(v.edit_value("wave.beam.length", vec![5.0], None));
    assert_eq!(v.scene().spring_state_step("hero"), None);
    let _ = positions(&v, 2.5);
    assert!(v.set_spring("hero", false));
    assert_eq!(v.scene().spring_state_step("hero"), None);
}

#[test]
fn without_wind_editing_a_wave_keeps_the_springs() {
    let (mut v, _d) = viewer("calm", "");
    let _ = positions(&v, 1.0);
    assert_eq!(v.scene().spring_state_step("hero"), Some(60));
    assert!(v.edit_value("wave.beam.length", vec![4.0], None));
    assert_eq!(v.scene().spring_state_step("hero"), Some(60), "no wave blows: the waves do not matter");
    assert!(v.key_current("wave.beam.wind"));
    assert_eq!(v.scene().spring_state_step("hero"), None, "an animated wind may blow");
}
