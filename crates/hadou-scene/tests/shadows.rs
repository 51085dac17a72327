//! `[[shadow]]`: what it builds (the frame's shadows and casts, with wave directions checked
//! against hand-computed values, 000 §2.4 / SPEC.md §2.4) and every bad input with its line and
//! column (issue: shadows that stretch away from the wave but never to infinity).

mod common;

use common::{at, err};
use hadou_math::Vec3f;
use hadou_scene::{Frame, Scene, ShadowLight, ShadowMethod};
use std::path::Path;

fn parse(text: &str) -> Scene {
    Scene::parse(text, Path::new("scenes/x.toml")).unwrap_or_else(|e| panic!("{e}"))
}

const OBJECTS: &str = r#"
[[object]]
name = "a"
kind = "box"
position = [0, 1, 0]

[[object]]
name = "b"
kind = "sphere"
position = [3, 2, 0]

[[object]]
name = "ground"
kind = "plane"
size = [20, 20]
"#;

fn casts(frame: &Frame) -> Vec<hadou_scene::ShadowCast> {
    let lines: Vec<_> = frame.waves.iter().map(|w| w.light_line(None)).collect();
    frame.shadow_casts(&lines)
}

fn close(a: Vec3f, b: Vec3f) -> bool {
    (a - b).length() <= 1e-5
}

#[test]
fn sun_shadow_follows_the_light_and_takes_the_plane_of_a_plane_receiver() {
    let s = parse(&format!(
        r#"{OBJECTS}
[light]
direction = [0, -2, 0]

[[shadow]]
name = "sun"
kind = "sun"
casters = ["a", "b"]
receivers = "ground"
opacity = 0.5

[[track]]
target = "light.direction"
keys = [[0, [0, -2, 0]], [1, [1, -1, 0]]]

[[track]]
target = "shadow.sun.opacity"
keys = [[0, 0.5], [1, 0.25]]
"#
    ));
    let f = s.at(0.0);
    assert_eq!(f.shadows.len(), 1);
    let sh = &f.shadows[0];
    assert_eq!((sh.casters.clone(), sh.receivers.clone()), (vec![0, 1], vec![2]));
    let ShadowMethod::Plane(p) = sh.method else { panic!("{:?}", sh.method) };
    assert!(close(p.normal, Vec3f::Y) && close(p.point, Vec3f::ZERO));
    let c = casts(&f);
    assert_eq!(c.len(), 1);
    assert!(close(c[0].k, -Vec3f::Y));
    assert_eq!(c[0].opacity, 0.5);
    let f = s.at(1.0);
    let c = casts(&f);
    let h = 0.5f32.sqrt();
    assert!(close(c[0].k, Vec3f::new(h, -h, 0.0)), "{:?}", c[0].k);
    assert_eq!(c[0].opacity, 0.25);
}

#[test]
fn sun_at_or_below_the_horizon_casts_nothing() {
    for dir in ["[1, 0, 0]", "[1, 0.5, 0]", "[0, 1, 0]"] {
        let s = parse(&format!(
            "{OBJECTS}\n[light]\ndirection = {dir}\n[[shadow]]\nname = \"s\"\nkind = \"sun\"\ncasters = \"a\"\nreceivers = \"ground\"\n"
        ));
        assert!(casts(&s.at(0.0)).is_empty(), "{dir}");
    }
}

/// A wave shadow scene: a cylinder wave along z through `m`, θ = 60°.
fn wave_scene(m: [f32; 3], theta: Option<f32>) -> Frame {
    let theta = theta.map_or(String::new(), |t| format!("theta = {t}\n"));
    parse(&format!(
        r#"{OBJECTS}
[[wave]]
name = "w"
kind = "cylinder"
M = [{}, {}, {}]
D = [0, 0, 1]
alpha_c = 1

[[shadow]]
name = "ws"
kind = "wave"
casters = ["a", "b"]
receivers = "ground"
{theta}"#,
        m[0], m[1], m[2]
    ))
    .at(0.0)
}

#[test]
fn wave_to_the_side_casts_each_model_away_from_its_nearest_point() {
    // Centres B_a = (0, 1, 0), B_b = (3, 2, 0); the wave line x = −3, y = 5 along z: nearest
    // points W = (−3, 5, 0) for both. e_a = (3, −4, 0)/5: λ = 36.9° ≤ 60°, k = e.
    // e_b = (6, −3, 0)/√45: λ = 63.4° > 60° → clamped: (sin 60°, −cos 60°, 0).
    let f = wave_scene([-3.0, 5.0, 0.0], None);
    let c = casts(&f);
    assert_eq!(c.len(), 2);
    assert_eq!((c[0].casters.clone(), c[1].casters.clone()), (vec![0], vec![1]));
    assert!(close(c[0].k, Vec3f::new(0.6, -0.8, 0.0)), "{:?}", c[0].k);
    assert!(close(c[1].k, Vec3f::new(0.75f32.sqrt(), -0.5, 0.0)), "{:?}", c[1].k);
    assert!(matches!(f.shadows[0].light, ShadowLight::Wave { wave: 0, .. }));
}

#[test]
fn wave_overhead_casts_down_and_theta_is_configurable() {
    // Directly above model a: k = −Y. Model b (3 to the side, 3 below): λ = 45°.
    let f = wave_scene([0.0, 5.0, 0.0], Some(30.0));
    let c = casts(&f);
    assert!(close(c[0].k, -Vec3f::Y), "{:?}", c[0].k);
    // θ = 30° < 45°: clamped to 30° from straight down, leaning +x.
    assert!(close(c[1].k, Vec3f::new(0.5, -0.75f32.sqrt(), 0.0)), "{:?}", c[1].k);
}

#[test]
fn wave_below_the_model_still_casts_down_at_theta() {
    // The documented behaviour (000: shadows never become infinitely long, even with the wave
    // below the object): the line at (−3, 0.0) lies below a's centre (0, 1): e = (3, 1)/√10,
    // λ = 108° → clamped to θ = 60° with e's azimuth.
    let f = wave_scene([-3.0, 0.0, 0.0], None);
    let c = casts(&f);
    assert!(close(c[0].k, Vec3f::new(0.75f32.sqrt(), -0.5, 0.0)), "{:?}", c[0].k);
}

#[test]
fn a_wave_without_strength_casts_nothing() {
    let s = parse(&format!(
        "{OBJECTS}\n[[wave]]\nname = \"w\"\nkind = \"sphere\"\nM = [0, 5, 0]\nalpha_s = 0\n\
         [[shadow]]\nname = \"s\"\nkind = \"wave\"\ncasters = \"a\"\nreceivers = \"ground\"\n"
    ));
    assert!(casts(&s.at(0.0)).is_empty());
}

#[test]
fn map_shadows_frame_their_casters() {
    let s = parse(&format!(
        "{OBJECTS}\n[[shadow]]\nname = \"s\"\nkind = \"sun\"\nmethod = \"map\"\nmap_size = 256\n\
         direction = [0, -1, 0]\ncasters = [\"a\", \"b\"]\nreceivers = [\"ground\", \"a\"]\n"
    ));
    let f = s.at(0.0);
    assert!(matches!(f.shadows[0].method, ShadowMethod::Map { size: 256 }));
    let c = casts(&f);
    let m = c[0].map.expect("a map frame");
    // The box spans [−0.5, 0.5]×[0.5, 1.5]×[−0.5, 0.5] and the sphere (r 0.5) lies around (3, 2, 0):
    // every vertex maps inside [0, 1]³.
    for o in [&f.objects[0], &f.objects[1]] {
        for p in &o.mesh.positions {
            let q = m.to_map(o.transform.transform_point(Vec3f::from_array(*p)));
            assert!(q.iter().all(|v| (-1e-5..=1.0 + 1e-5).contains(v)), "{q:?}");
        }
    }
}

#[test]
fn three_points_and_point_normal_planes() {
    let s = parse(&format!(
        "{OBJECTS}\n[[shadow]]\nname = \"s\"\nkind = \"sun\"\ncasters = \"a\"\nreceivers = \"b\"\n\
         plane_points = [[0, 1, 0], [1, 1, 0], [0, 1, 1]]\n\
         [[shadow]]\nname = \"t\"\nkind = \"sun\"\ncasters = \"a\"\nreceivers = \"b\"\n\
         plane_point = [0, 2, 0]\nplane_normal = [0, 0, 3]\n"
    ));
    let f = s.at(0.0);
    let ShadowMethod::Plane(p) = f.shadows[0].method else { panic!() };
    assert!(close(p.normal, Vec3f::Y) && (p.point.y - 1.0).abs() < 1e-6);
    let ShadowMethod::Plane(p) = f.shadows[1].method else { panic!() };
    assert!(close(p.normal, Vec3f::Z));
}

fn shadow_err(body: &str) -> hadou_scene::SceneError {
    err(&format!("{OBJECTS}\n[[wave]]\nname = \"w\"\nkind = \"sphere\"\nM = [0, 5, 0]\nalpha_s = 1\n[[shadow]]\nname = \"s\"\n{body}"))
}

/// Line of the `[[shadow]]` header in [`shadow_err`] texts.
fn body_line() -> usize {
    OBJECTS.lines().count() + 7
}

#[test]
fn bad_shadows_name_their_line_and_column() {
    let l = body_line();
    // (body, line counted from the `[[shadow]]` header, column, part of the message)
    let cases: &[(&str, usize, usize, &str)] = &[
        (
            "kind = \"sun\"\ncasters = \"a\"\nreceivers = \"b\"\nplane_points = [[0, 0, 0], [1, 1, 1], [2, 2, 2]]\n",
            5,
            1,
            "lie on one line",
        ),
        (
            "kind = \"sun\"\ncasters = \"a\"\nreceivers = \"b\"\nplane_points = [[0, 0, 0], [0, 0, 0], [0, 0, 1]]\n",
            5,
            1,
            "coincide",
        ),
        ("kind = \"sun\"\ncasters = \"a\"\nreceivers = \"b\"\nplane_point = [0, 0, 0]\nplane_normal = [0, 0, 0]\n", 6, 16, "zero vector"),
        ("kind = \"sun\"\ncasters = \"a\"\nreceivers = \"b\"\nplane_points = [[0, 0, 0], [1, 0, 0]]\n", 5, 16, "three points"),
        ("kind = \"sun\"\ncasters = \"a\"\nreceivers = \"b\"\nplane_points = \"up\"\n", 5, 16, "got a string"),

        ("kind = \"wave\"\ncasters = \"a\"\nreceivers = \"ground\"\ntheta = 90\n", 5, 9, "must be in [0, 90), got 90"),
        ("kind = \"wave\"\ncasters = \"a\"\nreceivers = \"ground\"\ntheta = -1\n", 5, 9, "must be in [0, 90), got -1"),
        ("kind = \"sun\"\ndirection = [0, 0, 0]\ncasters = \"a\"\nreceivers = \"ground\"\n", 3, 13, "zero vector"),
        ("kind = \"sun\"\ncasters = [\"a\", \"crate\"]\nreceivers = \"ground\"\n", 3, 17, "no [[object]] is named \"crate\""),
        ("kind = \"sun\"\ncasters = \"a\"\nreceivers = \"grond\"\n", 4, 13, "did you mean `ground`"),
        ("kind = \"sun\"\nmethod = \"map\"\nmap_size = 0\ncasters = \"a\"\nreceivers = \"ground\"\n", 4, 12, "1..=8192, got 0"),
        ("kind = \"sun\"\nmethod = \"map\"\nmap_size = 16384\ncasters = \"a\"\nreceivers = \"ground\"\n", 4, 12, "1..=8192, got 16384"),
        ("kind = \"sun\"\ncasters = \"a\"\nreceivers = \"b\"\n", 0, 1, "give `plane_point`"),
        ("kind = \"wave\"\nwave = \"x\"\ncasters = \"a\"\nreceivers = \"ground\"\n", 3, 8, "no [[wave]] is named \"x\""),
        ("kind = \"moon\"\ncasters = \"a\"\nreceivers = \"ground\"\n", 2, 8, "cannot be \"moon\""),
    ];
    for &(body, line, col, needle) in cases {
        let e = shadow_err(body);
        let msg = e.to_string();
        assert!(msg.contains(needle), "{body}: {msg}");
        assert_eq!(at(&e), (l + line, col), "{body}: {msg}");
    }
}

#[test]
fn map_budget_and_shadow_count_are_bounded() {
    let mut many = String::from(OBJECTS);
    for i in 0..17 {
        many += &format!(
            "[[shadow]]\nname = \"s{i}\"\nkind = \"sun\"\ncasters = \"a\"\nreceivers = \"ground\"\n"
        );
    }
    assert!(err(&many).to_string().contains("at most 16 shadows"));
    let mut big = String::from(OBJECTS);
    for i in 0..5 {
        big += &format!(
            "[[shadow]]\nname = \"s{i}\"\nkind = \"sun\"\nmethod = \"map\"\nmap_size = 4096\ncasters = \"a\"\nreceivers = \"ground\"\n"
        );
    }
    let e = err(&big);
    assert!(e.to_string().contains("lower `map_size`"), "{e}");
}

#[test]
fn collinear_plane_points_at_a_track_key_are_refused() {
    let e = err(&format!(
        "{OBJECTS}\n[[shadow]]\nname = \"s\"\nkind = \"sun\"\ncasters = \"a\"\nreceivers = \"b\"\n\
         plane_points = [[0, 0, 0], [1, 0, 0], [0, 0, 1]]\n\
         [[track]]\ntarget = \"shadow.s.plane_points\"\nkeys = [[0, [[0, 0, 0], [1, 0, 0], [0, 0, 1]]], [1, [[0, 0, 0], [1, 0, 0], [2, 0, 0]]]]\n"
    ));
    assert!(e.to_string().contains("lie on one line") && e.to_string().contains("t = 1 s"), "{e}");
}
