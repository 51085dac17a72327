//! The clip chooser without a window: choosing a glTF object's clip writes its `animation` key
//! (one undo step), the timeline then moves the mesh and runs as long as the clip; the rest pose
//! removes the key and the keys that only time a clip; scripts reach it as `clip OBJECT [CLIP]`.

use hadou_view::document::{Document, Edit};
use hadou_view::script;
use hadou_view::viewer::Viewer;
use std::path::{Path, PathBuf};

fn brace_glb() -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/assets/brace.glb")).to_path_buf()
}

/// A scene in a fresh directory holding brace.glb, with `keys` on its object and `extra` after.
fn viewer(name: &str, keys: &str, extra: &str) -> (Viewer, PathBuf) {
    let d = std::env::temp_dir().join(format!("hadou-view-clips-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    for f in ["brace.glb", "brace.vrm", "brace.vrma"] {
        std::fs::copy(brace_glb().with_file_name(f), d.join(f)).unwrap();
    }
    let text = format!(
        "# the character\n[image]\nwidth = 64\nheight = 48\n\n[camera]\nposition = [0.0, 1.0, 5.0]\n\
         target = [0.0, 0.9, 0.0]\n\n[[object]]\nname = \"hero\"\nkind = \"gltf\"\npath = \"brace.glb\" # keep\n\
         {keys}\n{extra}"
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
fn the_chooser_lists_the_files_clips_and_the_rest_pose_until_one_is_chosen() {
    let (v, _d) = viewer("list", "", "");
    let objects = v.clip_objects();
    assert_eq!(objects.len(), 1);
    let (name, clips, playing) = (&objects[0].object, &objects[0].clips, &objects[0].playing);
    assert_eq!(name, "hero");
    let names: Vec<&str> = clips.iter().map(|c| c.0.as_str()).collect();
    assert_eq!(names, ["brace", "step", "cubic", "blink"]);
    assert_eq!(clips[0].1, 2.0, "brace lasts 2 s");
    assert_eq!(*playing, None);
    assert_eq!(v.clip_now("hero"), None);
    // At rest the timeline does not move the character.
    assert_eq!(spread(&positions(&v, 0.5), &positions(&v, 1.5)), 0.0);
    assert_eq!(v.scene().duration(), 0.0);
}

#[test]
fn choosing_a_clip_writes_animation_and_the_timeline_plays_it() {
    let (mut v, _d) = viewer("choose", "", "");
    let rest = positions(&v, 0.0);
    assert!(v.choose_clip("hero", Some("brace")), "{:?}", v.message);
    let text = v.doc.text().to_string();
    assert!(text.contains("animation = \"brace\"\n"), "{text}");
    assert!(text.contains("# the character") && text.contains("path = \"brace.glb\" # keep"), "{text}");
    assert_eq!(v.clip_objects()[0].playing.as_deref(), Some("brace"));
    // The clip follows scene time: the mesh differs between two times, and the scrub bar and
    // playback run for the clip's 2 s although the scene has no tracks.
    assert!(spread(&positions(&v, 0.5), &positions(&v, 1.0)) > 0.01);
    assert_eq!(v.scene().duration(), 2.0);
    assert_eq!(v.scrub_end(), 2.0);
    v.timeline.playing = true;
    v.tick(0.75);
    assert_eq!(v.timeline.time, 0.75);
    assert_eq!(v.clip_now("hero"), Some(("brace".to_string(), 0.75)));
    assert!(spread(&v.frame().objects[0].mesh.positions, &rest) > 0.01);
    // Another clip replaces the key in place.
    assert!(v.choose_clip("hero", Some("step")));
    assert!(v.doc.text().contains("animation = \"step\"\n") && !v.doc.text().contains("\"brace\"\n"));
    // One undo step each.
    v.doc.undo();
    assert_eq!(v.doc.text(), text);
    v.doc.undo();
    assert!(!v.doc.text().contains("animation"));
}

#[test]
fn a_clip_the_file_lacks_is_refused_with_its_clips() {
    let (mut v, _d) = viewer("missing", "", "");
    let before = v.doc.text().to_string();
    assert!(!v.choose_clip("hero", Some("wave")));
    let m = &v.message.as_ref().unwrap().0;
    assert!(m.contains("no clip \"wave\"") && m.contains("\"brace\" (2 s)"), "{m}");
    assert_eq!(v.doc.text(), before);
}

#[test]
fn the_rest_pose_removes_the_clip_and_the_keys_that_time_it() {
    let keys =
        "animation = \"brace\"\nanimation_start = 1.0\nanimation_speed = 2.0\nanimation_loop = false\n";
    let extra = "[[track]]\ntarget = \"object.hero.animation_speed\"\nkeys = [[0.0, 2.0], [3.0, 1.0]]\n\n\
                 [[track]]\ntarget = \"object.hero.position\"\nkeys = [[0.0, [0.0, 0.0, 0.0]], [1.0, [1.0, 0.0, 0.0]]]\n";
    let (mut v, _d) = viewer("rest", keys, extra);
    // The clip ends at start + length / speed (speed at the end of the tracks: 1).
    assert_eq!(v.scene().duration(), 3.0);
    assert!(spread(&positions(&v, 1.0), &positions(&v, 1.5)) > 0.01);
    // Removing only `animation` would leave keys the loader refuses without it.
    assert!(!v.apply(Edit::Raw {
        entity: hadou_scene::Entity::Object("hero".into()),
        key: "animation".into(),
        value: String::new()
    }));
    assert!(v.choose_clip("hero", None), "{:?}", v.message);
    let text = v.doc.text();
    assert!(!text.contains("animation"), "{text}");
    assert!(text.contains("target = \"object.hero.position\""), "other tracks stay: {text}");
    assert_eq!(v.clip_now("hero"), None);
    assert_eq!(v.clip_objects()[0].playing, None);
    // Now only the position track moves it: the same pose at two times once it has arrived.
    assert_eq!(spread(&positions(&v, 1.0), &positions(&v, 1.5)), 0.0);
    assert_eq!(v.scene().duration(), 1.0);
}

#[test]
fn a_pinned_clip_time_does_not_lengthen_the_timeline() {
    let (v, _d) = viewer("pinned", "animation = \"brace\"\nanimation_time = 0.5\n", "");
    assert_eq!(v.scene().duration(), 0.0);
    assert_eq!(v.clip_now("hero"), Some(("brace".to_string(), 0.5)));
}

#[test]
fn scripts_choose_clips_and_name_what_they_could_be() {
    let (mut v, d) = viewer("script", "", "");
    let path = d.join("s.txt");
    let e = script::parse("time 1\nclip\n", &path).unwrap_err();
    assert!(e.contains("s.txt:2:1: `clip` takes an object name"), "{e}");
    let text = "clip hero cubic\ntime 0.6\nclip hero\nclip hero  nope\nclip nobody brace\n";
    let lines = script::parse(text, &path).unwrap();
    script::run(&mut v, &lines[0], &path).unwrap();
    assert!(v.doc.text().contains("animation = \"cubic\"\n"));
    script::run(&mut v, &lines[1], &path).unwrap();
    assert_eq!(v.clip_now("hero"), Some(("cubic".to_string(), 0.6)));
    script::run(&mut v, &lines[2], &path).unwrap();
    assert!(!v.doc.text().contains("animation"));
    let e = script::run(&mut v, &lines[3], &path).unwrap_err();
    assert!(
        e.contains("s.txt:4:12:") && e.contains("no clip \"nope\"") && e.contains("\"blink\" (1 s)"),
        "{e}"
    );
    let e = script::run(&mut v, &lines[4], &path).unwrap_err();
    assert!(e.contains("s.txt:5:6:") && e.contains("the objects are `hero`"), "{e}");
    assert!(!v.doc.text().contains("animation"));
}

#[test]
fn the_rest_pose_also_stops_a_vrm_animation() {
    let extra = "[[object]]\nname = \"avatar\"\nkind = \"gltf\"\npath = \"brace.vrm\"\n\
                 animation_file = \"brace.vrma\"\nposition = [2.0, 0.0, 0.0]\n";
    let (mut v, _d) = viewer("vrma", "", extra);
    // Its file has no clips of its own: no chooser, but it plays the VRM Animation's clip.
    assert_eq!(v.clip_objects().len(), 1);
    assert_eq!(v.clip_now("avatar").map(|c| c.0), Some("brace".to_string()));
    let at = |v: &Viewer, t: f32| v.scene().at(t).objects[1].mesh.positions.clone();
    assert!(spread(&at(&v, 0.0), &at(&v, 1.0)) > 0.01);
    assert!(v.choose_clip("avatar", None), "{:?}", v.message);
    assert!(!v.doc.text().contains("animation_file"), "{}", v.doc.text());
    assert_eq!(v.clip_now("avatar"), None);
    assert_eq!(spread(&at(&v, 0.0), &at(&v, 1.0)), 0.0);
}
