//! Every class of bad input gives `path:line:col: message` pointing at the offending key or value.

mod common;

use common::{at, err};
use hadou_scene::{Scene, SceneError};
use std::path::Path;

const WAVE: &str =
    "[[wave]]\nname = \"beam\"\nkind = \"capsule\"\nM = [0.0, 0.0, 0.0]\nM2 = [1.0, 0.0, 0.0]\n";

#[test]
fn unknown_key_suggests_the_nearest() {
    let text = format!("{WAVE}alpha_c = 1.0\n  alpah_s = 20.0\n");
    let e = err(&text);
    assert!(matches!(e, SceneError::UnknownKey { .. }), "{e:?}");
    assert_eq!(
        e.to_string(),
        "scenes/x.toml:7:3: unknown key `alpah_s` in [[wave]] \"beam\"; did you mean `alpha_s`?"
    );
    let e = err("[camera]\nfov = 40\n\n[lihgt]\n");
    assert_eq!(at(&e), (4, 2));
    assert!(e.to_string().contains("did you mean `light`?"), "{e}");
    // Far from every key: list the valid ones.
    let e = err("[color]\nzzzzzzzz = 1\n");
    assert!(e.to_string().contains("valid keys: `mode`, `exposure`"), "{e}");
}

#[test]
fn malformed_toml_uses_the_parser_position() {
    let e = err("[image]\nwidth = 512\nheight = = 3\n");
    assert!(matches!(e, SceneError::Syntax { .. }), "{e:?}");
    assert_eq!(at(&e).0, 3, "{e}");
    assert!(e.to_string().starts_with("scenes/x.toml:3:"), "{e}");
    let e = err("[camera\nfov = 3\n");
    assert_eq!(at(&e).0, 1, "{e}");
}

#[test]
fn wrong_types_point_at_the_value() {
    let e = err("[camera]\nfov = \"wide\"\n");
    assert!(matches!(e, SceneError::Type { .. }), "{e:?}");
    assert_eq!(at(&e), (2, 7));
    assert!(e.to_string().contains("must be a number, got a string"), "{e}");
    // A vector with the wrong number of components.
    let e = err("[camera]\nposition = [1.0, 2.0]\n");
    assert_eq!(at(&e), (2, 12));
    assert!(e.to_string().contains("array of 3 numbers, got 2"), "{e}");
    // One bad element of a vector: the element itself.
    let e = err("[camera]\nposition = [1.0, true, 2.0]\n");
    assert_eq!(at(&e), (2, 18));
    // Integer keys reject floats.
    let e = err("[image]\nwidth = 512.0\n");
    assert_eq!(at(&e), (2, 9));
    // [wave] instead of [[wave]].
    let e = err("[wave]\nname = \"a\"\n");
    assert!(e.to_string().contains("write [[wave]]"), "{e}");
}

#[test]
fn non_finite_and_negative_values_are_rejected() {
    let e = err(&format!("{WAVE}alpha_s = nan\nalpha_c = 1.0\n"));
    assert!(matches!(e, SceneError::Value { .. }), "{e:?}");
    assert_eq!(at(&e), (6, 11));
    assert!(e.to_string().contains("finite"), "{e}");
    let e = err(&format!("{WAVE}alpha_s = 1.0\nalpha_c = -inf\n"));
    assert_eq!(at(&e), (7, 11));
    let e = err(&format!("{WAVE}alpha_s = -2\nalpha_c = 1.0\n"));
    assert_eq!(at(&e), (6, 11));
    assert!(e.to_string().contains("must be in [0, 1e5], got -2"), "{e}");
    let e = err("[camera]\nposition = [0.0, inf, 1.0]\n");
    assert_eq!(at(&e), (2, 18));
    let e =
        err("[[wave]]\nname = \"s\"\nkind = \"sphere\"\nM = [0, 0, 0]\nalpha_s = 1\nrgba = [1, 1, 1, 1.5]\n");
    assert_eq!(at(&e), (6, 18));
}

#[test]
fn zero_vectors_are_rejected() {
    let e =
        err("[[wave]]\nname = \"c\"\nkind = \"cylinder\"\nM = [0, 0, 0]\nD = [0.0, 0.0, 0.0]\nalpha_c = 1\n");
    assert_eq!(at(&e), (5, 5));
    assert!(e.to_string().contains("zero vector"), "{e}");
    let e = err("[light]\ndirection = [0, 0, 0]\n");
    assert_eq!(at(&e), (2, 13));
}

#[test]
fn camera_ranges() {
    let e = err("[camera]\nfov = 180\n");
    assert_eq!(at(&e), (2, 7));
    assert!(e.to_string().contains("must be in [0.001, 179], got 180"), "{e}");
    assert_eq!(at(&err("[camera]\nfov = 0.0\n")), (2, 7));
    let e = err("[camera]\nnear = 5.0\nfar = 5.0\n");
    assert_eq!(at(&e), (3, 1));
    assert!(e.to_string().contains("`far` (5) must be greater than `near` (5)"), "{e}");
    let e = err("[camera]\nposition = [0, 0, 5]\ntarget = [0, 0, 5]\n");
    assert_eq!(at(&e), (3, 1));
    let e = err("[camera]\nposition = [0, 5, 0]\ntarget = [0, 0, 0]\nup = [0, 2, 0]\n");
    assert_eq!(at(&e), (4, 1));
    assert!(e.to_string().contains("parallel"), "{e}");
}

#[test]
fn image_size_limits() {
    let e = err("[image]\nwidth = 0\n");
    assert_eq!(at(&e), (2, 9));
    assert!(e.to_string().contains("1..=16384"), "{e}");
    assert_eq!(at(&err("[image]\nwidth = 64\nheight = 16385\n")), (3, 10));
    let ok = Scene::parse("[image]\nwidth = 16384\nheight = 1\n", Path::new("x.toml")).unwrap();
    assert_eq!((ok.width(), ok.height()), (16384, 1));
}

#[test]
fn anti_aliasing_samples_are_one_four_nine_or_sixteen() {
    for (text, col) in [("0", 11), ("-4", 11), ("17", 11), ("1000000000000", 11), ("2", 11), ("8", 11)] {
        let e = err(&format!("[image]\nsamples = {text}\n"));
        assert_eq!(at(&e), (2, col), "samples = {text}: {e}");
        let msg = e.to_string();
        assert!(msg.contains("samples") && (msg.contains("1, 4, 9, 16") || msg.contains("1..=16")), "{e}");
    }
    let e = err("[image]\nsamples = 4.0\n");
    assert_eq!(at(&e), (2, 11), "{e}");
    let e = err("[image]\nsamples = \"many\"\n");
    assert_eq!(at(&e), (2, 11), "{e}");
    for n in [1, 4, 9, 16] {
        let ok = Scene::parse(&format!("[image]\nsamples = {n}\n"), Path::new("x.toml")).unwrap();
        assert_eq!(ok.samples(), n);
        assert_eq!(ok.at(0.0).samples, n);
    }
    let default = Scene::parse("", Path::new("x.toml")).unwrap();
    assert_eq!(default.samples(), hadou_scene::DEFAULT_SAMPLES);
}

#[test]
fn missing_keys_point_at_the_table() {
    let e = err("[camera]\nfov = 40\n\n[[wave]]\nname = \"s\"\nkind = \"sphere\"\nM = [0, 0, 0]\n");
    assert!(matches!(e, SceneError::Missing { .. }), "{e:?}");
    assert_eq!(at(&e), (4, 1));
    assert!(e.to_string().contains("needs `alpha_s`"), "{e}");
    let e = err("[[wave]]\nname = \"s\"\n");
    assert!(e.to_string().contains("needs `kind`, one of \"sphere\""), "{e}");
    let e = err(
        "[[wave]]\nname = \"b\"\nkind = \"beam\"\nM = [0, 0, 0]\nD = [1, 0, 0]\nalpha_s = 1\nalpha_c = 1\n",
    );
    assert!(e.to_string().contains("needs `length`"), "{e}");
}

#[test]
fn bad_enumerations_suggest() {
    let e = err("[[wave]]\nname = \"s\"\nkind = \"spehre\"\n");
    assert_eq!(at(&e), (3, 8));
    assert!(e.to_string().contains("did you mean `sphere`?"), "{e}");
    let e = err("[color]\nmode = \"filmc\"\n");
    assert!(e.to_string().contains("did you mean `filmic`?"), "{e}");
}

#[test]
fn duplicate_names() {
    let text = "[[wave]]\nname = \"a\"\nkind = \"sphere\"\nM = [0, 0, 0]\nalpha_s = 1\n\
                [[wave]]\nname = \"a\"\nkind = \"sphere\"\nM = [1, 0, 0]\nalpha_s = 1\n";
    let e = err(text);
    assert!(matches!(e, SceneError::Duplicate { .. }), "{e:?}");
    assert_eq!(at(&e), (7, 8));
    assert!(e.to_string().contains("first used at line 2"), "{e}");
    let e = err("[[object]]\nname = \"a b\"\nkind = \"box\"\n");
    assert_eq!(at(&e), (2, 8));
}

#[test]
fn capsule_forms_are_exclusive_and_curve_rules_hold() {
    let e = err(&format!("{WAVE}length = 2.0\nalpha_s = 1\nalpha_c = 1\n"));
    assert_eq!(at(&e), (6, 1));
    assert!(e.to_string().contains("either `M2` or `D` + `length`"), "{e}");
    let curve = "[[wave]]\nname = \"h\"\nkind = \"helix\"\nO = [0, 0, 0]\nD = [1, 0, 0]\nalpha = 1\n\
                 radius = 1\nrate = 1\nlength = 4\n";
    let e = err(&format!("{curve}integrator = \"simpson\"\nm = 7\n"));
    assert_eq!(at(&e), (11, 5));
    assert!(e.to_string().contains("must be even"), "{e}");
    let e = err(&format!("{curve}field = \"exact\"\n"));
    assert_eq!(at(&e), (10, 9));
    assert!(e.to_string().contains("`field`"), "{e}");
    assert!(e.to_string().contains("valid values: `section`, `nearest`"), "{e}");
    let e = err(&format!("{curve}field = \"nearest\"\nintegrator = \"simpson\"\n"));
    assert_eq!(at(&e), (11, 1));
    assert!(e.to_string().contains("only with field = \"section\""), "{e}");
    let e = err(&format!("{curve}field = \"nearest\"\nm = 8\n"));
    assert!(e.to_string().contains("only with integrator = \"simpson\""), "{e}");
    let e = err(&format!("{curve}m = 8\n"));
    assert!(e.to_string().contains("only with integrator = \"simpson\""), "{e}");
    let e = err(&format!("{curve}up = [2, 0, 0]\n"));
    assert_eq!(at(&e), (10, 1));
    let e = err(&format!("{curve}k = 0.0\n"));
    assert_eq!(at(&e), (10, 5));
    let bs = "[[wave]]\nname = \"b\"\nkind = \"bspline\"\nO = [0, 0, 0]\nD = [1, 0, 0]\nalpha = 1\n\
              points = [[0, 0], [1, 0], [0, 1]]\n";
    let e = err(&format!("{bs}order = 4\n"));
    assert_eq!(at(&e), (8, 9));
    let e = err(&format!("{bs}order = 3\nknots = [0, 0, 0, 1, 1]\n"));
    assert!(e.to_string().contains("needs 6 values"), "{e}");
    let e = err(&format!("{bs}order = 2\nknots = [0, 1, 0.5, 2, 3]\n"));
    assert_eq!(at(&e), (9, 16));
    assert!(e.to_string().contains("must not decrease"), "{e}");
    let e = err("[[wave]]\nname = \"z\"\nkind = \"bezier\"\nO = [0, 0, 0]\nD = [1, 0, 0]\nalpha = 1\npoints = [[0, 0]]\n");
    assert!(e.to_string().contains("at least 2 control points"), "{e}");
}

#[test]
fn track_errors() {
    let base = format!("{WAVE}alpha_s = 1\nalpha_c = 1\n");
    let e = err(&format!("{base}[[track]]\ntarget = \"wave.bean.M2\"\nkeys = [[0, [0, 0, 0]]]\n"));
    assert!(matches!(e, SceneError::Track { .. }), "{e:?}");
    assert_eq!(at(&e), (9, 10));
    assert!(e.to_string().contains("no wave is named \"bean\"; did you mean `beam`?"), "{e}");
    let e = err(&format!("{base}[[track]]\ntarget = \"wave.beam.alpah_s\"\nkeys = [[0, 1]]\n"));
    assert!(e.to_string().contains("did you mean `alpha_s`?"), "{e}");
    let e = err(&format!("{base}[[track]]\ntarget = \"wave.beam.M2\"\nkeys = [[0, 1.0]]\n"));
    assert!(matches!(e, SceneError::Type { .. }), "{e:?}");
    assert_eq!(at(&e), (10, 13));
    let e =
        err(&format!("{base}[[track]]\ntarget = \"wave.beam.M2.z\"\nkeys = [[0, 1.0], [2, 3], [1, 2]]\n"));
    assert_eq!(at(&e), (10, 28));
    assert!(e.to_string().contains("increase strictly: 1 follows 2"), "{e}");
    let e = err(&format!("{base}[[track]]\ntarget = \"wave.beam.alpha_s\"\nkeys = [[0, 1.0], [1, -3]]\n"));
    assert_eq!(at(&e), (10, 23));
    let e = err(&format!("{base}[[track]]\ntarget = \"camera.far\"\nkeys = [[0, 50.0], [1, 0.05]]\n"));
    assert_eq!(at(&e), (10, 20));
    assert!(e.to_string().contains("at t = 1 s"), "{e}");
    let e = err(&format!("{base}[[track]]\ntarget = \"camera.fov\"\nkeys = [[0, 40]]\n[[track]]\ntarget = \"camera.fov\"\nkeys = [[0, 40]]\n"));
    assert!(matches!(e, SceneError::Duplicate { .. }), "{e:?}");
    assert_eq!(at(&e), (12, 10));
    let e = err(&format!("{base}[[track]]\ntarget = \"wave.beam.rgba[7]\"\nkeys = [[0, 1]]\n"));
    assert!(e.to_string().contains("out of range"), "{e}");
    let e = err(&format!("{base}[[track]]\ntarget = \"wave.beam.D\"\nkeys = [[0, [1, 0, 0]]]\n"));
    assert!(e.to_string().contains("uses") || e.to_string().contains("no animatable key `D`"), "{e}");
    let e = err(&format!("{base}[[track]]\ntarget = \"camera.fov\"\nkeys = [0, 40]\n"));
    assert!(e.to_string().contains("pair [time, value]"), "{e}");
}

#[test]
fn missing_files_have_no_position() {
    let e = Scene::load("/nonexistent/dir/scene.toml").unwrap_err();
    assert!(matches!(e, SceneError::Io { .. }), "{e:?}");
    assert!(e.to_string().starts_with("/nonexistent/dir/scene.toml: cannot read the scene file"), "{e}");
}

#[test]
fn garbage_never_panics() {
    // Every prefix of a valid scene either parses or errors.
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/fig4-14-occlusion.toml"))
            .expect("scene file");
    for cut in (0..text.len()).filter(|&i| text.is_char_boundary(i)) {
        let _ = Scene::parse(&text[..cut], Path::new("cut.toml"));
    }
}

#[test]
fn curve_limits_of_the_maths_are_reported_at_the_key() {
    let pts: Vec<String> = (0..65).map(|i| format!("[{i}, 0]")).collect();
    let text = format!(
        "[[wave]]\nname = \"z\"\nkind = \"bezier\"\nO = [0, 0, 0]\nD = [1, 0, 0]\nalpha = 1\npoints = [{}]\n",
        pts.join(", ")
    );
    let e = err(&text);
    assert!(matches!(e, SceneError::Value { .. }), "{e:?}");
    assert_eq!(at(&e), (7, 1));
    assert!(e.to_string().contains("`points` in [[wave]] \"z\""), "{e}");
    assert!(e.to_string().contains("64"), "{e}");
}

/// The attenuation exponent `j` of an analytic wave (002 eq. 3.23): in [0, 64], a number, also in
/// tracks; each bad value is reported at the value.
#[test]
fn analytic_attenuation_exponent_is_checked() {
    let base = format!("{WAVE}alpha_s = 1\nalpha_c = 1\n");
    for (bad, col) in [("-0.5", 5), ("nan", 5), ("64.5", 5), ("-inf", 5)] {
        let e = err(&format!("{base}j = {bad}\n"));
        assert!(matches!(e, SceneError::Value { .. }), "{bad}: {e:?}");
        assert_eq!(at(&e), (8, col), "{bad}: {e}");
        assert!(e.to_string().contains("`j` in [[wave]] \"beam\""), "{bad}: {e}");
    }
    let e = err(&format!("{base}j = \"strong\"\n"));
    assert!(matches!(e, SceneError::Type { .. }), "{e:?}");
    assert_eq!(at(&e), (8, 5));
    assert!(e.to_string().contains("must be a number, got a string"), "{e}");
    // The limits themselves are accepted, on every analytic kind.
    for kind in ["sphere", "cylinder", "capsule", "beam"] {
        let text = format!(
            "[[wave]]\nname = \"w\"\nkind = \"{kind}\"\nM = [0, 0, 0]\nM2 = [1, 0, 0]\nD = [1, 0, 0]\n\
             length = 1\nalpha_s = 1\nalpha_c = 1\nj = 64\n"
        );
        let text = match kind {
            "sphere" => {
                text.replace("M2 = [1, 0, 0]\nD = [1, 0, 0]\nlength = 1\n", "").replace("alpha_c = 1\n", "")
            }
            "cylinder" => {
                text.replace("M2 = [1, 0, 0]\n", "").replace("length = 1\n", "").replace("alpha_s = 1\n", "")
            }
            _ => text.replace("D = [1, 0, 0]\nlength = 1\n", ""),
        };
        let s = Scene::parse(&text, Path::new("scenes/x.toml")).unwrap_or_else(|e| panic!("{kind}: {e}"));
        assert_eq!(s.at(0.0).waves[0].attenuation, 64.0, "{kind}");
    }
    // A track key out of range, at the key's value.
    let e = err(&format!("{base}j = 1\n[[track]]\ntarget = \"wave.beam.j\"\nkeys = [[0, 1.0], [1, 65]]\n"));
    assert!(matches!(e, SceneError::Value { .. } | SceneError::Track { .. }), "{e:?}");
    assert_eq!(at(&e), (11, 23), "{e}");
    assert!(e.to_string().contains("64"), "{e}");
}
