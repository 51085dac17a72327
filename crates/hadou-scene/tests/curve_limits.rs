//! The limits that bound a curve's work per ray (docs/scene-format.md, "Work per ray"): turns,
//! terms, control points, steepness and Simpson's `m × point cost` are refused at the key that
//! breaks them, with its line and column, in the file and at every key time; between keys the
//! frame's curve is brought back within them.

mod common;

use common::{at, err};
use hadou_math::curve::{prepare, MAX_SLOPE, MAX_TURNS};
use hadou_scene::{Scene, WaveShape};
use std::path::Path;

/// A curved wave's common keys (6 lines); the kind's keys follow.
fn curve(kind: &str) -> String {
    format!("[[wave]]\nname = \"c\"\nkind = \"{kind}\"\nO = [0, 0, 0]\nD = [1, 0, 0]\nalpha = 1\n")
}

fn msg(e: &hadou_scene::SceneError) -> String {
    e.to_string()
}

#[test]
fn too_many_turns_point_at_rate() {
    // The issue's helix: rate = -1e6 over 11 units, 1.75 million turns.
    let e = err(&format!("{}radius = 0.8\nrate = -1e6\nlength = 11.0\n", curve("helix")));
    assert_eq!(at(&e), (8, 1));
    assert!(msg(&e).starts_with("scenes/x.toml:8:1: `rate` in [[wave]] \"c\""), "{e}");
    assert!(msg(&e).contains("makes the helix turn 1.751e6 times over `length`"), "{e}");
    assert!(msg(&e).contains("at most 128 turns"), "{e}");
    // Just under 128 turns is allowed (2π rounds up in f32), a little more is not.
    let ok = format!("{}radius = 1\nrate = 6.28318\nlength = 128\n", curve("helix"));
    Scene::parse(&ok, Path::new("scenes/x.toml")).unwrap();
    let e = err(&format!("{}radius = 1\nrate = 6.3\nlength = 128\n", curve("helix")));
    assert_eq!(at(&e), (8, 1));
    // A trigonometric sum counts its fastest harmonic: 3 terms × 50 turns of the base rate.
    let e = err(&format!(
        "{}rate = 6.283185307179586\ny_terms = [[1, 0], [0, 0], [0.5, 0]]\nlength = 50\n",
        curve("trig")
    ));
    assert_eq!(at(&e), (7, 1));
    assert!(msg(&e).contains("makes the fastest harmonic (term 3) turn 150 times"), "{e}");
}

#[test]
fn too_many_terms_and_points_point_at_the_list() {
    let terms = vec!["[1, 0]"; 65].join(", ");
    let e = err(&format!("{}rate = 0.01\nz_terms = [{terms}]\nlength = 1\n", curve("trig")));
    assert_eq!(at(&e), (8, 1));
    assert!(msg(&e).contains("at most 64 terms, got 65"), "{e}");
    let points: Vec<String> = (0..513).map(|i| format!("[{}, 0]", i % 2)).collect();
    let e = err(&format!("{}points = [{}]\ngamma = 1000\n", curve("bspline"), points.join(", ")));
    assert_eq!(at(&e), (7, 1));
    assert!(msg(&e).contains("at most 512 control points, got 513"), "{e}");
}

#[test]
fn steep_curves_point_at_gamma_or_knots() {
    // radius · |rate| / gamma = 1e6 · 1 / 1 > 1e5.
    let e = err(&format!("{}radius = 1e6\nrate = 1\nlength = 1\ngamma = 1\n", curve("helix")));
    assert_eq!(at(&e), (10, 1));
    assert!(
        msg(&e).contains("leaves the curve too steep: it moves 1e6 across its axis per unit of travel"),
        "{e}"
    );
    assert!(msg(&e).contains("raise `gamma`"), "{e}");
    // Without `gamma` in the file the table is named.
    let e = err(&format!("{}radius = 1e6\nrate = 1\nlength = 1\n", curve("helix")));
    assert_eq!(at(&e), (1, 1));
    // A Bézier curve of wild coordinates: degree 2 × a step of 2e6 over gamma 10.
    let e = err(&format!("{}points = [[1e6, 0], [-1e6, 0], [1e6, 0]]\ngamma = 10\n", curve("bezier")));
    assert_eq!(at(&e), (8, 1));
    assert!(msg(&e).contains("moves 4e5 across its axis"), "{e}");
    // A B-spline whose knots crowd its change into 1e-7 of the range.
    let bs = format!("{}points = [[0, 0], [1, 0], [0, 0], [1, 0]]\norder = 2\n", curve("bspline"));
    let e = err(&format!("{bs}knots = [0, 0, 0.5, 0.5000001, 1, 1]\n"));
    assert_eq!(at(&e), (9, 1));
    assert!(msg(&e).contains("`knots` in [[wave]] \"c\""), "{e}");
    assert!(msg(&e).contains("spread them out"), "{e}");
    // An interior knot repeated `order` times: the curve jumps.
    let bs = format!("{}points = [[0, 0], [1, 0], [0, 0], [1, 0]]\norder = 2\n", curve("bspline"));
    let e = err(&format!("{bs}knots = [0, 0, 0.5, 0.5, 1, 1]\n"));
    assert_eq!(at(&e), (9, 1));
    assert!(msg(&e).contains("repeat an interior knot `order` times, which makes the B-spline jump"), "{e}");
    // Repeated `order − 1` times it is continuous, and allowed.
    let ok = format!(
        "{}points = [[0, 0], [1, 0], [0, 0], [1, 0]]\norder = 3\nknots = [0, 0, 0, 0.5, 0.5, 1, 1]\n",
        curve("bspline")
    );
    Scene::parse(&ok, Path::new("scenes/x.toml")).unwrap();
}

#[test]
fn simpson_m_times_the_point_cost_is_bounded() {
    // 32 + 32 terms cost 32 helix points each: m ≤ 3125.
    let terms = vec!["[0.1, 0]"; 32].join(", ");
    let trig = format!(
        "{}rate = 0.01\ny_terms = [{terms}]\nz_terms = [{terms}]\nlength = 1\nintegrator = \"simpson\"\n",
        curve("trig")
    );
    let e = err(&format!("{trig}m = 4000\n"));
    assert_eq!(at(&e), (12, 1));
    assert!(msg(&e).contains("`m` in [[wave]] \"c\" must be at most 3124 for this curve, got 4000"), "{e}");
    assert!(msg(&e).contains("one point of it costs 32 helix points"), "{e}");
    Scene::parse(&format!("{trig}m = 3124\n"), Path::new("scenes/x.toml")).unwrap();
    // A helix keeps the whole range.
    let helix =
        format!("{}radius = 1\nrate = 1\nlength = 1\nintegrator = \"simpson\"\nm = 100000\n", curve("helix"));
    Scene::parse(&helix, Path::new("scenes/x.toml")).unwrap();
}

#[test]
fn key_times_keep_the_limits() {
    let helix = format!("{}radius = 1\nrate = 1\nlength = 10\n", curve("helix"));
    let e = err(&format!("{helix}[[track]]\ntarget = \"wave.c.rate\"\nkeys = [[0, 1], [2, 100]]\n"));
    assert_eq!(at(&e), (12, 17));
    assert!(msg(&e).contains("at t = 2 s (this key of `wave.c.rate`): `rate` in [[wave]] \"c\""), "{e}");
    assert!(msg(&e).contains("turns"), "{e}");
    let e = err(&format!("{helix}[[track]]\ntarget = \"wave.c.gamma\"\nkeys = [[0, 1], [1, 1e-6]]\n"));
    assert_eq!(at(&e), (12, 17));
    assert!(msg(&e).contains("`gamma` in [[wave]] \"c\""), "{e}");
}

/// Between keys a smooth track overshoots: rate and length each stay within their keys' range
/// only up to the overshoot, and their product may exceed the turn limit. The frame's curve is
/// brought back within the limits when it is prepared (the rate lowered), and a frame at a key
/// comes back unchanged.
#[test]
fn between_keys_the_curve_is_brought_within() {
    let text = format!(
        "{}radius = 1\nrate = 1\nlength = 1\n\
         [[track]]\ntarget = \"wave.c.rate\"\ninterpolation = \"linear\"\nkeys = [[0, 50.2], [1, 0.4]]\n\
         [[track]]\ntarget = \"wave.c.length\"\ninterpolation = \"linear\"\nkeys = [[0, 0.4], [1, 2000]]\n",
        curve("helix")
    );
    let scene = Scene::parse(&text, Path::new("scenes/x.toml")).unwrap();
    let frame = scene.at(0.5);
    let WaveShape::Curve(c) = &frame.waves[0].shape else { panic!("not a curve") };
    // rate 25.3 over length 1000.2: about 4000 turns.
    let turns = c.turns().unwrap();
    assert!(turns > 10.0 * MAX_TURNS, "{turns}");
    let p = prepare(c);
    assert!(p.wave.turns().unwrap() <= MAX_TURNS, "{:?}", p.wave.turns());
    assert!(p.wave.steepness() <= MAX_SLOPE);
    p.wave.validate().unwrap();
    for t in [0.0, 1.0] {
        let frame = scene.at(t);
        let WaveShape::Curve(c) = &frame.waves[0].shape else { panic!("not a curve") };
        assert_eq!(&prepare(c).wave, c, "t = {t}");
    }
}

/// Issue 41 (a bounded cost per frame): the most work a pixel may cost, every wave's bound per ray
/// times the samples, is at most `PIXEL_WORK_MAX`; the wave that passes it is named with its
/// line, at the file's samples; a caller's samples are checked by `check_pixel_work`.
#[test]
fn issue_41_the_work_a_pixel_may_cost_is_bounded() {
    use hadou_math::curve::{DEFAULT_RAY_WORK, NEAREST_RAY_WORK};
    use hadou_scene::{ANALYTIC_RAY_WORK, PIXEL_WORK_MAX};
    let helix = |i: usize, field: &str| {
        format!(
            "[[wave]]\nname = \"h{i}\"\nkind = \"helix\"\nO = [0, {i}, 0]\nD = [1, 0, 0]\nalpha = 1\n\
             radius = 1\nrate = 6\nlength = 10\n{field}"
        )
    };
    let sphere = "[[wave]]\nname = \"s\"\nkind = \"sphere\"\nM = [0, 0, 0]\nalpha_s = 1\n";
    let simpson = "[[wave]]\nname = \"p\"\nkind = \"helix\"\nO = [0, 0, 0]\nD = [1, 0, 0]\nalpha = 1\n\
                   radius = 1\nrate = 6\nlength = 10\nintegrator = \"simpson\"\nm = 1000\nn = 10\n";
    let mut text = format!("{sphere}{}{}{simpson}", helix(0, ""), helix(1, "field = \"nearest\"\n"));
    let s = Scene::parse(&text, Path::new("scenes/x.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        s.ray_work(),
        vec![ANALYTIC_RAY_WORK, DEFAULT_RAY_WORK, NEAREST_RAY_WORK, 3 * 1001 + DEFAULT_RAY_WORK]
    );
    let one: u64 = s.ray_work().iter().sum();
    assert!(one * 16 <= PIXEL_WORK_MAX);
    assert!(s.check_pixel_work(16).is_ok());
    // Nearest-field helices at 16 samples: the twelfth passes the bound (12 × 742 217 × 16 > 2²⁷).
    text = "[image]\nsamples = 16\n".to_owned();
    let mut lines = 2;
    let mut third = 0;
    for i in 0..13 {
        if i == 11 {
            third = lines + 1;
        }
        let h = helix(i, "field = \"nearest\"\n");
        lines += h.lines().count();
        text += &h;
    }
    let e = err(&text);
    assert_eq!(at(&e), (third, 1), "{e}");
    assert!(msg(&e).contains("[[wave]] \"h11\"") && msg(&e).contains(&PIXEL_WORK_MAX.to_string()), "{e}");
    // At 4 samples the thirteen fit; a caller asking 16 is told which wave passes.
    let s = Scene::parse(&text.replace("samples = 16", "samples = 4"), Path::new("scenes/x.toml")).unwrap();
    assert!(s.check_pixel_work(4).is_ok());
    let (i, m) = s.check_pixel_work(16).unwrap_err();
    assert_eq!(i, 11, "{m}");
    // 256 curves (the most a scene may have) at the default 4 samples fit.
    let curves: String = (0..256).map(|i| helix(i, "")).collect();
    let s = Scene::parse(&curves, Path::new("scenes/x.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert!(s.check_pixel_work(4).is_ok() && s.check_pixel_work(16).is_err());
    // 256 analytic waves at 16 samples are always within it.
    let many: String = (0..256).map(|i| sphere.replace("\"s\"", &format!("\"s{i}\""))).collect();
    let s = Scene::parse(&format!("[image]\nsamples = 16\n{many}"), Path::new("scenes/x.toml")).unwrap();
    assert!(s.check_pixel_work(16).is_ok());
}
