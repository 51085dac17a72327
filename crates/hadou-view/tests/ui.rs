//! The egui UI without a window: synthetic pointer input on a headless `egui::Context` must
//! reach the viewer as probes, camera orbits and handle drags, and frames must build for every
//! example scene.

use egui::{Event, Modifiers, PointerButton, Pos2, RawInput, Rect, Vec2};
use hadou_view::document::Document;
use hadou_view::ui::{show, UiState, ViewportImage};
use hadou_view::viewer::{Request, Viewer};
use std::path::Path;

fn repo() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn viewer(scene: &str) -> Viewer {
    Viewer::new(Document::open(&repo().join("scenes").join(scene)).unwrap())
}

struct Harness {
    ctx: egui::Context,
    st: UiState,
    time: f64,
}

impl Harness {
    fn new() -> Harness {
        Harness { ctx: egui::Context::default(), st: UiState::default(), time: 0.0 }
    }

    fn frame(&mut self, v: &mut Viewer, events: Vec<Event>) {
        self.time += 1.0 / 60.0;
        let raw = RawInput {
            screen_rect: Some(Rect::from_min_size(Pos2::ZERO, Vec2::new(1400.0, 900.0))),
            time: Some(self.time),
            events,
            ..Default::default()
        };
        let image = ViewportImage {
            texture: egui::TextureId::User(1),
            size: [v.scene().width(), v.scene().height()],
        };
        let (st, ctx) = (&mut self.st, self.ctx.clone());
        let _ = ctx.run_ui(raw, |ui| show(ui, v, Some(image), st));
    }

    fn press(&mut self, v: &mut Viewer, pos: Pos2, pressed: bool) {
        let e =
            Event::PointerButton { pos, button: PointerButton::Primary, pressed, modifiers: Modifiers::NONE };
        self.frame(v, vec![Event::PointerMoved(pos), e]);
    }
}

#[test]
fn a_click_in_the_viewport_probes_its_pixel() {
    let mut v = viewer("fig4-1-sphere.toml");
    let mut h = Harness::new();
    h.frame(&mut v, vec![]);
    h.frame(&mut v, vec![]);
    let rect = h.st.viewport_rect.expect("the viewport was laid out");
    let at = rect.min + rect.size() * 0.25;
    h.press(&mut v, at, true);
    h.press(&mut v, at, false);
    let probe = v.requests.iter().find_map(|r| match r {
        Request::Probe(p) => Some(*p),
        _ => None,
    });
    let [x, y] = probe.expect("a probe request");
    let (w, hgt) = (v.scene().width() as f32, v.scene().height() as f32);
    assert!((x as f32 - w * 0.25).abs() <= 1.5 && (y as f32 - hgt * 0.25).abs() <= 1.5, "{x},{y}");
}

#[test]
fn dragging_the_viewport_orbits_the_camera_in_one_undo_step() {
    let mut v = viewer("fig4-1-beam.toml");
    let mut h = Harness::new();
    h.frame(&mut v, vec![]);
    h.frame(&mut v, vec![]);
    let rect = h.st.viewport_rect.unwrap();
    // A corner far from every handle.
    let start = rect.min + Vec2::new(10.0, 10.0);
    let eye0 = v.scene().value_at("camera.position", 0.0).unwrap();
    h.press(&mut v, start, true);
    for i in 1..=6 {
        h.frame(&mut v, vec![Event::PointerMoved(start + Vec2::new(10.0 * i as f32, 0.0))]);
    }
    h.press(&mut v, start + Vec2::new(60.0, 0.0), false);
    h.frame(&mut v, vec![]);
    let eye1 = v.scene().value_at("camera.position", 0.0).unwrap();
    assert_ne!(eye0, eye1, "the drag moved the camera");
    assert!(v.requests.iter().all(|r| !matches!(r, Request::Probe(_))), "a drag is not a click");
    v.doc.undo();
    assert_eq!(v.scene().value_at("camera.position", 0.0).unwrap(), eye0);
}

#[test]
fn dragging_a_handle_moves_that_point() {
    let mut v = viewer("fig4-1-sphere.toml");
    let mut h = Harness::new();
    h.frame(&mut v, vec![]);
    h.frame(&mut v, vec![]);
    let rect = h.st.viewport_rect.unwrap();
    let handle = v.handles().into_iter().next().expect("the sphere's centre");
    let frame = v.frame();
    let px = hadou_view::viewer::project(&frame, handle.world).unwrap();
    let scale = rect.width() / frame.width as f32;
    let pos = Pos2::new(rect.left() + px[0] * scale, rect.top() + px[1] * scale);
    let m0 = v.scene().value_at("wave.sphere.M", 0.0);
    let name = handle.wave.clone();
    h.press(&mut v, pos, true);
    for i in 1..=5 {
        h.frame(&mut v, vec![Event::PointerMoved(pos + Vec2::new(0.0, -8.0 * i as f32))]);
    }
    h.press(&mut v, pos + Vec2::new(0.0, -40.0), false);
    let m1 = v.scene().value_at(&format!("wave.{name}.M"), 0.0).unwrap();
    let m0 = m0.unwrap_or_else(|| handle.world.to_array().to_vec());
    assert!(m1[1] > m0[1] + 0.01, "dragged up: {m0:?} → {m1:?}");
    let eye = v.scene().value_at("camera.position", 0.0).unwrap();
    v.doc.undo();
    assert_eq!(v.scene().value_at("camera.position", 0.0).unwrap(), eye, "the camera did not move");
}

#[test]
fn every_example_scene_builds_a_frame_of_ui() {
    let mut n = 0;
    for e in std::fs::read_dir(repo().join("scenes")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            let mut v = Viewer::new(Document::open(&p).unwrap());
            let mut h = Harness::new();
            h.frame(&mut v, vec![]);
            h.frame(&mut v, vec![]);
            assert!(v.message.as_ref().is_none_or(|m| !m.1), "{}: {:?}", p.display(), v.message);
            n += 1;
        }
    }
    assert!(n >= 30, "{n} scenes");
}
