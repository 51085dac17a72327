//! Hard shadows on the CPU reference (001 / SPEC.md §3, 000 §2.4 / SPEC.md §2.4, and hadou's
//! shadow maps for uneven receivers): overlaps darken once, shadows stay on their receivers,
//! the part beyond the plane casts nothing, wave shadows fall where the hand-computed projection
//! puts them, and a map shadow on stairs agrees with exact shadow rays.

use hadou_math::shadow::project;
use hadou_math::shadow::Plane;
use hadou_math::{Vec3, Vec3f};
use hadou_scene::{Frame, Image, Scene};
use std::path::Path;

/// A top-down camera over an unlit white ground (faithful colour mapping: colours are exact).
const VIEW: &str = r#"
[image]
width = 200
height = 200

[camera]
position = [0, 12, 0]
target = [0, 0, 0]
up = [0, 0, -1]
fov = 45

[color]
mode = "faithful"
exposure = 1e-9

[[material]]
name = "white"
model = "unlit"
base_color = [1, 1, 1]

[[material]]
name = "red"
model = "unlit"
base_color = [1, 0, 0]

[[material]]
name = "green"
model = "unlit"
base_color = [0, 1, 0]
"#;

fn frame(text: &str) -> Frame {
    parse(&format!("{VIEW}{text}"))
}

/// The scene's frame at time 0 and one sample per pixel (the tests compare pixels' exact colours).
fn parse(text: &str) -> Frame {
    let mut f = Scene::parse(text, Path::new("x.toml")).unwrap_or_else(|e| panic!("{e}")).at(0.0);
    f.samples = 1;
    f
}

/// The pixel whose centre sees world point `p` (`None` off-screen).
fn pixel(f: &Frame, p: Vec3f) -> Option<(u32, u32)> {
    let b = f.camera.basis(f.width, f.height);
    let v = b.to_view(p);
    let ndc_x = v.x / (v.z * b.tan_half_fov * b.aspect);
    let ndc_y = v.y / (v.z * b.tan_half_fov);
    let x = ((ndc_x + 1.0) * 0.5 * f.width as f32).floor();
    let y = ((1.0 - ndc_y) * 0.5 * f.height as f32).floor();
    (x >= 0.0 && y >= 0.0 && x < f.width as f32 && y < f.height as f32).then_some((x as u32, y as u32))
}

fn rgb(img: &Image, (x, y): (u32, u32)) -> [f32; 3] {
    let c = img.color[img.index(x, y)];
    [c[0], c[1], c[2]]
}

fn without_shadows(f: &Frame) -> Frame {
    Frame { shadows: Vec::new(), ..f.clone() }
}

const GROUND: &str =
    "[[object]]\nname = \"ground\"\nkind = \"plane\"\nsize = [12, 12]\nmaterial = \"white\"\n";

/// An `[[object]]` table: a `kind` named `name` of `size` at `position` (the TOML arrays' items; no
/// `position` key where it is empty) in `material`.
fn object(name: &str, kind: &str, size: &str, position: &str, material: &str) -> String {
    let position = if position.is_empty() { String::new() } else { format!("position = [{position}]\n") };
    format!(
        "\n[[object]]\nname = \"{name}\"\nkind = \"{kind}\"\nsize = [{size}]\n{position}material = \"{material}\"\n"
    )
}

#[test]
fn overlapping_shadows_of_several_casters_darken_once() {
    let casters = object("a", "box", "1, 2, 1", "-0.4, 1, 0", "red")
        + &object("b", "box", "1, 3, 1", "-1.2, 1.5, 0.5", "red");
    let f = frame(&format!(
        "{GROUND}{casters}
[[shadow]]
name = \"sun\"
kind = \"sun\"
direction = [1, -1, -0.6]
casters = [\"a\", \"b\"]
receivers = \"ground\"
color = [0, 0, 0.2]
opacity = 0.5
"
    ));
    let img = hadou_cpu::render(&f);
    // Each caster alone, to find where their shadows overlap.
    let alone = |keep: u32| {
        let mut g = f.clone();
        g.shadows[0].casters = vec![keep];
        hadou_cpu::render(&g)
    };
    let (ia, ib) = (alone(1), alone(2));
    let plain = hadou_cpu::render(&without_shadows(&f));
    let white = [1.0f32; 3];
    let shadowed = [0.5f32, 0.5, 0.6]; // 1 + (shadow colour − 1)·0.5
    let (mut overlap, mut single) = (0, 0);
    for y in 0..f.height {
        for x in 0..f.width {
            let p = (x, y);
            if rgb(&plain, p) != white {
                continue; // not the ground
            }
            let (a, b) = (rgb(&ia, p) == shadowed, rgb(&ib, p) == shadowed);
            let c = rgb(&img, p);
            assert!(c == white || c == shadowed, "pixel {p:?}: {c:?}");
            assert_eq!(c == shadowed, a || b, "pixel {p:?}");
            overlap += usize::from(a && b);
            single += usize::from(a != b);
        }
    }
    assert!(overlap > 100 && single > 100, "overlap {overlap}, single {single}");
}

#[test]
fn shadows_stay_on_their_receivers() {
    // The receiver is a 3×3 green plane; the long shadow would run past it and across a red box.
    let objects = object("mat", "plane", "3, 3", "0.5, 0.001, 0", "green")
        + &object("post", "box", "0.5, 3, 0.5", "-1.5, 1.5, 0", "red")
        + &object("block", "box", "0.8, 0.8, 0.8", "3, 0.4, 0", "red");
    let f = frame(&format!(
        "{GROUND}{objects}
[[shadow]]
name = \"sun\"
kind = \"sun\"
direction = [1, -0.6, 0]
casters = [\"post\", \"block\"]
receivers = \"mat\"
opacity = 0.8
"
    ));
    let img = hadou_cpu::render(&f);
    let plain = hadou_cpu::render(&without_shadows(&f));
    let mut on_mat = 0;
    for y in 0..f.height {
        for x in 0..f.width {
            let (s, p) = (rgb(&img, (x, y)), rgb(&plain, (x, y)));
            if s != p {
                assert_eq!(
                    p,
                    [0.0, 1.0, 0.0],
                    "pixel ({x}, {y}) outside the receiver changed: {p:?} → {s:?}"
                );
                on_mat += 1;
            }
        }
    }
    assert!(on_mat > 200, "{on_mat}");
    // The plane passes under the mat's 0.001 offset: within ON_PLANE·(1 + distance).
    let c = rgb(&img, pixel(&f, Vec3::new(0.0, 0.0, 0.0)).unwrap());
    assert!((c[1] - 0.2).abs() < 1e-6, "{c:?}");
}

#[test]
fn the_part_beyond_the_plane_casts_nothing() {
    // A tall box sunk half into the ground: t < 0 for its lower half, whose projection would
    // fall on the light's side (000 §2.4: fully transparent).
    let sunk = object("sunk", "box", "0.6, 2, 0.6", "", "red");
    let f = frame(&format!(
        "{GROUND}{sunk}
[[shadow]]
name = \"sun\"
kind = \"sun\"
direction = [1, -1, 0]
casters = \"sunk\"
receivers = \"ground\"
opacity = 1
"
    ));
    let img = hadou_cpu::render(&f);
    let dark = rgb(&img, pixel(&f, Vec3::new(0.9, 0.0, 0.0)).unwrap());
    let light_side = rgb(&img, pixel(&f, Vec3::new(-0.9, 0.0, 0.0)).unwrap());
    assert_eq!(dark, [0.0; 3]);
    assert_eq!(light_side, [1.0; 3]);
    // `hadou probe` names the shadow a pixel takes.
    let (x, y) = pixel(&f, Vec3::new(0.9, 0.0, 0.0)).unwrap();
    let p = hadou_cpu::probe(&f, x, y).unwrap();
    assert_eq!((p.object.as_deref(), p.shadow.as_deref()), (Some("ground"), Some("sun")));
    let (x, y) = pixel(&f, Vec3::new(-0.9, 0.0, 0.0)).unwrap();
    assert_eq!(hadou_cpu::probe(&f, x, y).unwrap().shadow, None);
}

#[test]
fn wave_shadows_fall_where_the_projection_puts_them() {
    // A cylinder wave along z at x = −3, y = 2.5 between two boxes (camera above x = −1.5).
    // Near box, centre B = (0, 1, 0): W = (−3, 2.5, 0), e = (3, −1.5, 0)/√11.25, λ = 63.4° > θ = 60°:
    // clamped, k = (sin 60°, −cos 60°, 0); the centre lands at (2·sin 60°, 0, 0) = (1.732, 0, 0).
    // Far box, B = (−4.5, 1, 0): e = (−1.5, −1.5, 0)/√4.5, λ = 45° ≤ θ: k = e, centre at (−5.5, 0, 0).
    let view = VIEW.replace(
        "position = [0, 12, 0]\ntarget = [0, 0, 0]",
        "position = [-1.5, 12, 0]\ntarget = [-1.5, 0, 0]",
    );
    let boxes = object("near", "box", "0.5, 0.5, 0.5", "0, 1, 0", "red")
        + &object("far", "box", "0.5, 0.5, 0.5", "-4.5, 1, 0", "red");
    let f = parse(&format!(
        "{view}{GROUND}{boxes}
[[wave]]
name = \"w\"
kind = \"cylinder\"
M = [-3, 2.5, 0]
D = [0, 0, 1]
alpha_c = 0.0001
rgba = [0.2, 0.4, 1.0, 1.0]

[[shadow]]
name = \"ws\"
kind = \"wave\"
casters = [\"near\", \"far\"]
receivers = \"ground\"
opacity = 1
"
    ));
    let img = hadou_cpu::render(&f);
    let ground = Plane::new(Vec3f::ZERO, Vec3f::Y).unwrap();
    let near = |p: Vec3f, want: f32| {
        let c = rgb(&img, pixel(&f, p).unwrap());
        assert!(c.iter().all(|v| (v - want).abs() < 1e-6), "{p:?}: {c:?}, want {want}");
    };
    let s60 = 0.75f32.sqrt();
    let (g, t) = project(Vec3::new(0.0, 1.0, 0.0), Vec3::new(s60, -0.5, 0.0), &ground);
    assert!((g - Vec3::new(2.0 * s60, 0.0, 0.0)).length() < 1e-6 && t > 0.0);
    near(g, 0.0);
    near(Vec3::new(-0.6, 0.0, 0.0), 1.0); // towards the wave
    let h = 0.5f32.sqrt();
    let (g, _) = project(Vec3::new(-4.5, 1.0, 0.0), Vec3::new(-h, -h, 0.0), &ground);
    assert!((g - Vec3::new(-5.5, 0.0, 0.0)).length() < 1e-6);
    near(g, 0.0);
    near(Vec3::new(-3.9, 0.0, 0.0), 1.0); // towards the wave
}

/// Möller–Trumbore: whether the ray `o + s·d`, `s > 1e-4`, hits triangle `(a, b, c)`.
fn hits(o: Vec3f, d: Vec3f, a: Vec3f, b: Vec3f, c: Vec3f) -> bool {
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return false;
    }
    let inv = 1.0 / det;
    let t = o - a;
    let u = t.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = t.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    e2.dot(q) * inv > 1e-4
}

const BALL: &str = "[[object]]\nname = \"ball\"\nkind = \"sphere\"\nradius = 0.7\nsegments = 24\n\
                    position = [-0.5, 2.6, 0.2]\nmaterial = \"red\"\n";

#[test]
fn map_shadows_on_stairs_agree_with_exact_shadow_rays() {
    let stairs = [
        object("step1", "box", "1.5, 0.4, 4", "0.25, 0.2, 0", "green"),
        object("step2", "box", "1.5, 0.8, 4", "1.75, 0.4, 0", "green"),
        object("step3", "box", "1.5, 1.2, 4", "3.25, 0.6, 0", "green"),
    ]
    .concat();
    let shadow = |method: &str| {
        format!(
            "[[shadow]]\nname = \"sun\"\nkind = \"sun\"\ndirection = [1, -0.9, 0.2]\ncasters = \"ball\"\n\
             receivers = [\"ground\", \"step1\", \"step2\", \"step3\"]\nopacity = 1\ncolor = [0, 0, 1]\n{method}"
        )
    };
    let f = frame(&format!("{GROUND}{stairs}{BALL}{}", shadow("method = \"map\"\nmap_size = 1024\n")));
    let img = hadou_cpu::render(&f);
    let ball = f.objects.iter().find(|o| o.name == "ball").unwrap();
    let tris: Vec<[Vec3f; 3]> = ball
        .mesh
        .indices
        .chunks_exact(3)
        .map(|t| {
            t.iter()
                .map(|&i| ball.transform.transform_point(Vec3::from_array(ball.mesh.positions[i as usize])))
        })
        .map(|mut it| [it.next().unwrap(), it.next().unwrap(), it.next().unwrap()])
        .collect();
    let k = Vec3f::new(1.0, -0.9, 0.2).normalize_or(Vec3f::Y);
    let basis = f.camera.basis(f.width, f.height);
    let (mut agree, mut total, mut shadowed, mut on_steps) = (0, 0, 0, 0);
    for y in 0..f.height {
        for x in 0..f.width {
            let c = rgb(&img, (x, y));
            let is_blue = c == [0.0, 0.0, 1.0];
            if !(is_blue || c == [1.0; 3] || c == [0.0, 1.0, 0.0]) {
                continue; // the ball
            }
            let dir = basis.pixel_dir(x as f32, y as f32, f.width, f.height);
            let p = basis.eye + dir.normalize_or(Vec3f::Y) * img.depth[img.index(x, y)];
            let truth = tris.iter().any(|t| hits(p, -k, t[0], t[1], t[2]));
            total += 1;
            agree += usize::from(truth == is_blue);
            shadowed += usize::from(truth);
            on_steps += usize::from(truth && p.y > 0.05);
        }
    }
    let share = agree as f64 / total as f64;
    assert!(shadowed > 500 && on_steps > 200, "shadowed {shadowed}, on the steps {on_steps}");
    assert!(
        share >= 0.995,
        "map agrees with shadow rays on {:.3} % of {total} receiver pixels",
        100.0 * share
    );

    // On the flat ground, the plane projection and the map agree too (the plane method alone
    // cannot follow the steps: there it is wrong by design).
    let flat_shadow = shadow("method = \"map\"\nmap_size = 1024\n")
        .replace("receivers = [\"ground\", \"step1\", \"step2\", \"step3\"]", "receivers = \"ground\"");
    let flat = frame(&format!("{GROUND}{BALL}{flat_shadow}"));
    let planar = Frame {
        shadows: vec![hadou_scene::Shadow {
            method: hadou_scene::ShadowMethod::Plane(Plane::new(Vec3f::ZERO, Vec3f::Y).unwrap()),
            ..flat.shadows[0].clone()
        }],
        ..flat.clone()
    };
    let (a, b) = (hadou_cpu::render(&flat), hadou_cpu::render(&planar));
    let differ = a.color.iter().zip(&b.color).filter(|(p, q)| p != q).count();
    let blue = b.color.iter().filter(|c| c[..3] == [0.0, 0.0, 1.0]).count();
    assert!(blue > 500 && differ * 100 <= blue, "{differ} of {blue} shadow pixels differ");
}
