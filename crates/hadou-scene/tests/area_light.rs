//! `[area_light]` (003, SPEC.md §4): what it builds (the two map positions `L ± l·P`, `G` from an
//! object or a point, animated values) and every bad input with its line and column.

mod common;

use common::{at, err};
use hadou_math::Vec3f;
use hadou_scene::{LampShape, Penumbra, Scene, SoftResolve, DEFAULT_TRACE_SAMPLES, MAX_TRACE_SAMPLES};
use std::path::Path;

const OBJECTS: &str = r#"
[[object]]
name = "pillar"
kind = "box"
size = [1, 2, 1]
position = [0, 1, 0]

[[object]]
name = "floor"
kind = "plane"
size = [20, 20]
"#;

fn parse(text: &str) -> Scene {
    Scene::parse(text, Path::new("scenes/x.toml")).unwrap_or_else(|e| panic!("{e}"))
}

fn close(a: Vec3f, b: Vec3f) -> bool {
    (a - b).length() <= 1e-5
}

#[test]
fn maps_sit_at_l_plus_and_minus_l_p_and_every_object_is_inside_them() {
    let s = parse(&format!(
        "{OBJECTS}\n[area_light]\nposition = [0, 5, 0]\nsize = 0.5\ntarget = \"pillar\"\nintensity = 2\ncolor = [1, 0.5, 0.25]\n"
    ));
    let f = s.at(0.0);
    let a = f.area_light.as_ref().unwrap();
    assert!(close(a.interest, Vec3f::new(0.0, 1.0, 0.0)), "G is the pillar's centre: {:?}", a.interest);
    assert!(
        close(a.maps[0].eye, Vec3f::new(0.0, 5.5, 0.0)) && close(a.maps[1].eye, Vec3f::new(0.0, 4.5, 0.0))
    );
    assert_eq!(a.color, [2.0, 1.0, 0.5]);
    assert_eq!((a.map_size, a.resolve, a.depth_aware), (1024, SoftResolve::Exact, true));
    // The exact resolve's default brightness is the segment light's: k = (D + l)/(D − l), D = 4.
    assert_eq!(a.penumbra, Penumbra::Segment);
    assert!((a.penumbra_ratio() - 4.5 / 3.5).abs() < 1e-6, "{}", a.penumbra_ratio());
    // The floor (a plane) receives but does not cast: the frustum fits the pillar alone.
    assert_eq!(a.casters, vec![0]);
    for m in &a.maps {
        assert!(close(m.forward, -Vec3f::Y));
        for c in [[0.5, 0.0, 0.5], [-0.5, 2.0, -0.5]] {
            let v = m.to_view(Vec3f::from_array(c));
            assert!(v.z > m.near && v.x.abs() <= v.z * m.tan_half && v.y.abs() <= v.z * m.tan_half, "{v:?}");
        }
        let far = m.to_view(Vec3f::new(10.0, 0.0, 10.0));
        assert!(far.x.abs() > far.z * m.tan_half, "the floor's far corner is outside: {far:?}");
    }
    let listed = parse(&format!(
        "{OBJECTS}\n[area_light]\nposition = [0, 5, 0]\nsize = 0.5\ntarget = \"pillar\"\ncasters = [\"floor\", \"pillar\"]\n"
    ));
    assert_eq!(listed.at(0.0).area_light.unwrap().casters, vec![1, 0]);
}

#[test]
fn a_point_target_faithful_resolve_and_tracks() {
    let s = parse(&format!(
        "{OBJECTS}\n[area_light]\nposition = [3, 4, 0]\nsize = 1\ntarget = [0, 0, 0]\nresolve = \"faithful\"\nn = 5\ndepth_aware = false\nmap_size = 256\n\
         [[track]]\ntarget = \"area_light.position\"\nkeys = [[0, [3, 4, 0]], [1, [0, 4, 3]]]\n\
         [[track]]\ntarget = \"area_light.size\"\nkeys = [[0, 1], [1, 2]]\n"
    ));
    let a0 = s.at(0.0).area_light.unwrap();
    assert_eq!((a0.resolve, a0.depth_aware, a0.map_size), (SoftResolve::Faithful { n: 5 }, false, 256));
    // The faithful resolve keeps 003's linear ratio unless told otherwise.
    assert_eq!((a0.penumbra, a0.penumbra_ratio()), (Penumbra::Linear, 1.0));
    for (resolve, key, want) in [
        ("exact", "linear", Penumbra::Linear),
        ("faithful", "segment", Penumbra::Segment),
        ("exact", "segment", Penumbra::Segment),
    ] {
        let s = parse(&format!(
            "{OBJECTS}\n[area_light]\nposition = [3, 4, 0]\nsize = 1\ntarget = [0, 0, 0]\nresolve = \"{resolve}\"\npenumbra = \"{key}\"\n"
        ));
        assert_eq!(s.at(0.0).area_light.unwrap().penumbra, want, "{resolve} {key}");
    }
    // P = (3, 4, 0)/5: L₁ = L + P, L₂ = L − P.
    assert!(
        close(a0.maps[0].eye, Vec3f::new(3.6, 4.8, 0.0)) && close(a0.maps[1].eye, Vec3f::new(2.4, 3.2, 0.0))
    );
    let a1 = s.at(1.0).area_light.unwrap();
    assert!(close(a1.position, Vec3f::new(0.0, 4.0, 3.0)) && a1.size == 2.0);
    // P = (0, 4, 3)/5, l = 2: L₂ = L − 2P.
    assert!(close(a1.maps[1].eye, Vec3f::new(0.0, 2.4, 1.8)), "{:?}", a1.maps[1].eye);
}

/// Line of the `[area_light]` header in [`light_err`] texts.
fn header_line() -> usize {
    OBJECTS.lines().count() + 1
}

fn light_err(body: &str) -> hadou_scene::SceneError {
    err(&format!("{OBJECTS}[area_light]\n{body}"))
}

#[test]
fn lamp_shapes_and_the_traced_resolve() {
    let base = format!("{OBJECTS}\n[area_light]\nposition = [0, 5, 0]\nsize = 0.5\ntarget = \"pillar\"\n");
    let a = parse(&base).at(0.0).area_light.unwrap();
    assert_eq!((a.shape, a.resolve), (LampShape::Segment, SoftResolve::Exact));
    for (text, shape) in
        [("disc", LampShape::Disc), ("sphere", LampShape::Sphere), ("segment", LampShape::Segment)]
    {
        let a =
            parse(&format!("{base}shape = \"{text}\"\nresolve = \"traced\"\n")).at(0.0).area_light.unwrap();
        assert_eq!((a.shape, a.resolve), (shape, SoftResolve::Traced { samples: DEFAULT_TRACE_SAMPLES }));
    }
    let a = parse(&format!("{base}resolve = \"traced\"\nsamples = {MAX_TRACE_SAMPLES}\n"))
        .at(0.0)
        .area_light
        .unwrap();
    assert_eq!(a.resolve, SoftResolve::Traced { samples: MAX_TRACE_SAMPLES });
    // The shape is kept with the two-map resolves (it sets the light the lamp adds).
    let a = parse(&format!("{base}shape = \"disc\"\n")).at(0.0).area_light.unwrap();
    assert_eq!((a.shape, a.resolve, a.penumbra), (LampShape::Disc, SoftResolve::Exact, Penumbra::Segment));
}

#[test]
fn bad_area_lights_name_their_line_and_column() {
    let l = header_line();
    let ok = "position = [0, 5, 0]\nsize = 0.5\ntarget = \"pillar\"\n";
    // (body, line counted from the header, column, part of the message)
    let cases: Vec<(String, usize, usize, &str)> = vec![
        ("position = [0, 5, 0]\nsize = 0\ntarget = \"pillar\"\n".into(), 2, 8, "size"),
        ("position = [0, 5, 0]\nsize = -1\ntarget = \"pillar\"\n".into(), 2, 8, "size"),
        ("position = [0, 1, 0]\nsize = 0.5\ntarget = \"pillar\"\n".into(), 1, 1, "G must differ from L"),
        ("position = [1, 2, 3]\nsize = 0.5\ntarget = [1, 2, 3]\n".into(), 3, 1, "G must differ from L"),
        (
            "position = [0, 5, 0]\nsize = 4\ntarget = \"pillar\"\n".into(),
            2,
            1,
            "must be less than the distance",
        ),
        ("position = [0, 5, 0]\nsize = 0.5\ntarget = \"piller\"\n".into(), 3, 10, "did you mean `pillar`"),
        ("position = [0, 5, 0]\nsize = 0.5\ntarget = 3\n".into(), 3, 10, "an object name or a point"),
        ("position = [0, 5, 0]\nsize = 0.5\n".into(), 0, 1, "needs `target`"),
        ("size = 0.5\ntarget = \"pillar\"\n".into(), 0, 1, "needs `position`"),
        (format!("{ok}map_size = 0\n"), 4, 12, "1..=8192, got 0"),
        (format!("{ok}map_size = 10000\n"), 4, 12, "1..=8192, got 10000"),
        (format!("{ok}resolve = \"faithful\"\nn = 0\n"), 5, 5, "1..=64, got 0"),
        (format!("{ok}n = 3\n"), 4, 1, "applies to `resolve = \"faithful\"`"),
        (format!("{ok}resolve = \"blur\"\n"), 4, 11, "cannot be \"blur\""),
        (format!("{ok}depth_aware = 1\n"), 4, 15, "depth_aware"),
        (format!("{ok}penumbra = \"smooth\"\n"), 4, 12, "cannot be \"smooth\""),
        (format!("{ok}penumbra = 1\n"), 4, 12, "penumbra"),
        (format!("{ok}radius = 1\n"), 4, 1, "unknown key `radius`"),
        (format!("{ok}casters = [\"pilar\"]\n"), 4, 12, "did you mean `pillar`"),
        (format!("{ok}casters = []\n"), 4, 11, "at least one object"),
        (format!("{ok}shape = \"cube\"\n"), 4, 9, "cannot be \"cube\""),
        (format!("{ok}shape = 2\n"), 4, 9, "shape"),
        (format!("{ok}resolve = \"traced\"\nsamples = 0\n"), 5, 11, "1..=1024, got 0"),
        (format!("{ok}resolve = \"traced\"\nsamples = -3\n"), 5, 11, "1..=1024, got -3"),
        (format!("{ok}resolve = \"traced\"\nsamples = 1025\n"), 5, 11, "1..=1024, got 1025"),
        (format!("{ok}resolve = \"traced\"\nsamples = nan\n"), 5, 11, "integer in 1..=1024"),
        (format!("{ok}resolve = \"traced\"\nsamples = 2.5\n"), 5, 11, "integer in 1..=1024"),
        (format!("{ok}samples = 64\n"), 4, 1, "applies to `resolve = \"traced\"`"),
        (format!("{ok}resolve = \"traced\"\nn = 3\n"), 5, 1, "applies to `resolve = \"faithful\"`"),
        (format!("{ok}resolve = \"traced\"\npenumbra = \"linear\"\n"), 5, 1, "two-map resolves"),
        (
            "position = [0, 5, 0]\nsize = 4\ntarget = \"pillar\"\nshape = \"sphere\"\n".into(),
            2,
            1,
            "must be less than the distance",
        ),
    ];
    // A hostile value is quoted shortened, still located.
    let e = light_err(&format!("{ok}penumbra = \"{}\"\n", "x".repeat(5000)));
    let msg = e.to_string();
    assert!(msg.len() < 300 && msg.contains("xxxx…"), "{} bytes: {}", msg.len(), &msg[..200]);
    assert_eq!(at(&e), (l + 4, 12), "{msg}");
    for (body, line, col, needle) in cases {
        let e = light_err(&body);
        let msg = e.to_string();
        assert!(msg.contains(needle), "{body}: {msg}");
        assert_eq!(at(&e), (l + line, col), "{body}: {msg}");
    }
}

#[test]
fn an_image_too_large_for_the_penumbra_search_is_refused() {
    let e = err(&format!(
        "[image]\nwidth = 8192\nheight = 4096\n{OBJECTS}[area_light]\nposition = [0, 5, 0]\nsize = 0.5\ntarget = \"pillar\"\n"
    ));
    assert!(e.to_string().contains("at most 16777216 pixels"), "{e}");
}

#[test]
fn an_animated_light_reaching_its_target_is_refused_at_that_key() {
    let e = err(&format!(
        "{OBJECTS}[area_light]\nposition = [0, 5, 0]\nsize = 0.5\ntarget = \"pillar\"\n\
         [[track]]\ntarget = \"area_light.position\"\nkeys = [[0, [0, 5, 0]], [2, [0, 1, 0]]]\n"
    ));
    assert!(e.to_string().contains("G must differ from L") && e.to_string().contains("t = 2 s"), "{e}");
    let e = err(&format!("{OBJECTS}[[track]]\ntarget = \"area_light.size\"\nkeys = [[0, 1]]\n"));
    assert!(e.to_string().contains("no [area_light]"), "{e}");
}
