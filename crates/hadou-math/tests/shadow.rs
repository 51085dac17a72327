//! Projection shadows: 001's squash–stretch–turn–place construction equals the oblique projection
//! (SPEC.md §3), and 000 §2.4's wave directions against hand-computed values (SPEC.md §2.4 with
//! its corrected θ clamp).

use hadou_math::shadow::{project, wave_direction, Plane};
use hadou_math::{Vec3, Vec3d, Vec3f};

/// 001's shadow object, built the way the thesis builds it, one 3×3 step at a time, in f64:
/// the copy's points relative to the object's centre `P` are turned so the light's azimuth lies
/// along +x, turned about z until the light points straight down, squashed flat (y → 0),
/// stretched by `1/sin θ` along the shadow's direction (`θ` the light's elevation), turned back to
/// the light's azimuth, and placed at `s = (p_x − (l_x/l_y) p_y, 0, p_z − (l_z/l_y) p_y)`.
fn squash_stretch_turn_place(q: Vec3d, center: Vec3d, l: Vec3d) -> Vec3d {
    let l = l * (1.0 / l.length());
    let elevation = (-l.y).asin(); // θ
    let azimuth = l.z.atan2(l.x); // φ of L on the ground
    let rot_y = |p: Vec3d, a: f64| {
        // Rotation about +y by a, taking +x towards +z (so that rot_y(x̂, φ) = (cos φ, 0, sin φ)).
        Vec3::new(p.x * a.cos() - p.z * a.sin(), p.y, p.x * a.sin() + p.z * a.cos())
    };
    let rot_z =
        |p: Vec3d, a: f64| Vec3::new(p.x * a.cos() - p.y * a.sin(), p.x * a.sin() + p.y * a.cos(), p.z);
    let local = q - center;
    // Turn: the light's azimuth to +x; L becomes (cos θ, −sin θ, 0).
    let turned = rot_y(local, -azimuth);
    // Align: about z by θ − 90°, taking (cos θ, −sin θ, 0) to (0, −1, 0).
    let aligned = rot_z(turned, elevation - std::f64::consts::FRAC_PI_2);
    // Squash flat along the light, then lay the result on the ground: the aligned x axis lies
    // along the shadow's direction, stretched by 1/sin θ.
    let flat = Vec3::new(aligned.x / elevation.sin(), 0.0, aligned.z);
    // Turn back to the light's azimuth and place at the centre's shadow.
    let placed = rot_y(flat, azimuth);
    let s = Vec3::new(center.x - l.x / l.y * center.y, 0.0, center.z - l.z / l.y * center.y);
    placed + s
}

#[test]
fn squash_stretch_turn_place_equals_the_oblique_projection() {
    // Vertices of a unit box, an object's points in the air, lights from several sides and heights.
    let ground = Plane::new(Vec3f::ZERO, Vec3f::Y).unwrap();
    let lights = [
        Vec3f::new(-0.4, -1.0, -0.3),
        Vec3f::new(1.0, -0.2, 0.0),   // sunset from −x
        Vec3f::new(0.0, -0.5, 1.0),   // along +z
        Vec3f::new(-0.7, -0.15, 0.7), // low, diagonal
        Vec3f::new(0.01, -1.0, 0.02), // nearly overhead
    ];
    let centers = [Vec3f::new(0.0, 0.5, 0.0), Vec3f::new(2.0, 3.0, -1.0), Vec3f::new(-1.5, 1.2, 2.5)];
    for l in lights {
        let lu = l.normalize_or(Vec3f::Y);
        for c in centers {
            for i in 0..8 {
                let corner = Vec3f::new(
                    if i & 1 == 0 { -0.5 } else { 0.5 },
                    if i & 2 == 0 { -0.5 } else { 0.5 },
                    if i & 4 == 0 { -0.5 } else { 0.5 },
                );
                let p = c + corner;
                let built = squash_stretch_turn_place(p.as_f64(), c.as_f64(), lu.as_f64());
                let (projected, t) = project(p, lu, &ground);
                assert!(t >= 0.0 || p.y < 0.0);
                let err = (built - projected.as_f64()).length();
                assert!(
                    err <= 1e-5,
                    "light {l:?}, vertex {p:?}: construction {built:?}, projection {projected:?}"
                );
                // And 001's own formula for the centre, p' = p − (p_y / l_y) L.
                let blinn = p.as_f64() - lu.as_f64() * (f64::from(p.y) / f64::from(lu.y));
                assert!((blinn - built).length() <= 1e-9);
            }
        }
    }
}

#[test]
fn projection_onto_a_tilted_plane_matches_the_f64_formula() {
    let plane =
        Plane::from_points(Vec3f::new(0.0, 0.0, 0.0), Vec3f::new(1.0, 0.2, 0.0), Vec3f::new(0.0, -0.1, 1.0))
            .unwrap();
    let plane64 = Plane::<f64> { point: plane.point.as_f64(), normal: plane.normal.as_f64() };
    let k = Vec3f::new(0.3, -0.9, 0.2).normalize_or(Vec3f::Y);
    for i in 0..50 {
        let p =
            Vec3f::new((i as f32 * 0.37).sin() * 3.0, 0.5 + (i as f32 * 0.11) % 4.0, (i as f32).cos() * 2.0);
        let (g, t) = project(p, k, &plane);
        let (g64, t64) = project(p.as_f64(), k.as_f64(), &plane64);
        assert!((g.as_f64() - g64).length() <= 1e-5 && (f64::from(t) - t64).abs() <= 1e-5);
        assert!(plane.distance(g).abs() <= 1e-5);
    }
}

fn close(a: Vec3f, b: Vec3f) -> bool {
    (a - b).length() <= 1e-6
}

#[test]
fn wave_to_the_side_within_theta_casts_along_e() {
    // W at (−3, 4, 0), B at (0, 0, 0): e = (0.6, −0.8, 0), λ = 36.87° ≤ 60°.
    let k = wave_direction(Vec3f::ZERO, Vec3f::new(-3.0, 4.0, 0.0), Vec3f::Y, 60f32.to_radians());
    assert!(close(k, Vec3f::new(0.6, -0.8, 0.0)), "{k:?}");
}

#[test]
fn low_wave_is_clamped_to_theta_from_straight_down() {
    // W level with B on −x: e = +x, λ = 90° > θ = 60° → k = sin60·x̂ − cos60·ŷ, 60° from −Y (not
    // the printed quaternion's 120°).
    let theta = 60f32.to_radians();
    let k = wave_direction(Vec3f::ZERO, Vec3f::new(-5.0, 0.0, 0.0), Vec3f::Y, theta);
    assert!(close(k, Vec3f::new(0.75f32.sqrt(), -0.5, 0.0)), "{k:?}");
    assert!((k.dot(-Vec3f::Y).acos() - theta).abs() < 1e-5);
    // Azimuth kept: a wave at (−3, 1, −4) (λ > θ) leans the shadow towards (3, ·, 4)/5.
    let k = wave_direction(Vec3f::ZERO, Vec3f::new(-3.0, 1.0, -4.0), Vec3f::Y, theta);
    assert!(close(k, Vec3f::new(0.6 * 0.75f32.sqrt(), -0.5, 0.8 * 0.75f32.sqrt())), "{k:?}");
}

#[test]
fn wave_overhead_casts_straight_down_and_below_is_clamped() {
    let theta = 45f32.to_radians();
    let k = wave_direction(Vec3f::new(1.0, 0.0, 2.0), Vec3f::new(1.0, 7.0, 2.0), Vec3f::Y, theta);
    assert!(close(k, -Vec3f::Y), "{k:?}");
    // Below and to the side (e = (0.6, 0.8, 0), λ = 143°): clamped to 45° with e's azimuth — the
    // documented behaviour: the shadow never becomes infinitely long, and still falls downwards.
    let k = wave_direction(Vec3f::ZERO, Vec3f::new(-3.0, -4.0, 0.0), Vec3f::Y, theta);
    let h = 0.5f32.sqrt();
    assert!(close(k, Vec3f::new(h, -h, 0.0)), "{k:?}");
    // Straight below: no azimuth; straight down.
    let k = wave_direction(Vec3f::ZERO, Vec3f::new(0.0, -2.0, 0.0), Vec3f::Y, theta);
    assert!(close(k, -Vec3f::Y), "{k:?}");
    // The wave through the centre: straight down, not NaN.
    let k = wave_direction(Vec3f::ZERO, Vec3f::ZERO, Vec3f::Y, theta);
    assert!(close(k, -Vec3f::Y), "{k:?}");
}

#[test]
fn theta_zero_always_casts_along_minus_y_on_a_tilted_receiver() {
    let up = Vec3f::new(0.0, 1.0, 1.0).normalize_or(Vec3f::Y);
    for w in [Vec3f::new(3.0, 1.0, 0.0), Vec3f::new(-1.0, 5.0, 2.0), Vec3f::new(0.0, -3.0, 0.5)] {
        let k = wave_direction(Vec3f::ZERO, w, up, 0.0);
        assert!(close(k, -up), "{w:?} → {k:?}");
    }
}
