//! Closed outlines where objects meet: the screen-space rule that carries an object's
//! inverted-hull outline (000 §2.3, SPEC.md §2.3) across the pixels of whatever it touches.
//!
//! The hull `R' = R + d·|R_z|·U` moves a vertex `d·|R_z|` along its unit outline direction `U`;
//! projected with focal length `f = h / (2·tan(fov/2))` pixels, that is `d·f·|U⊥|` pixels on
//! screen, `U⊥` the part of `U` across the view ray (the depth cancels: the outline's pixel width
//! is the same at any distance). Where the object stands on another surface the hull is buried
//! in it; the edge pass then draws the same width from the object's visible edge pixels instead:
//! a pixel `p` of another surface takes the outline of an edge pixel `q` of the object within
//! `d·f·|U⊥(q)|` pixels when the object's point at `q` lies in front of the plane of `p`'s surface
//! (so the object is not hidden behind that surface there). Mirrored in WGSL by `hadou-gpu`
//! (`shaders/edges.wgsl`, keep in sync).

use crate::Vec3f;

/// Steps of the quantized reach fraction `|U⊥|` ([`reach_code`]): the G-buffer keeps it in 8 bits.
pub const REACH_STEPS: u32 = 255;

/// The widest contact outline searched, in pixels: a hull wider than this on screen still draws
/// in full against the sky, and its contact outline stops at this width.
pub const MAX_REACH_PX: u32 = 32;

/// Relative margin of the in-front test ([`in_front`]): a point must be nearer than the plane by
/// this fraction of the plane's distance along the ray, so that coplanar surfaces do not outline
/// each other by rounding.
pub const IN_FRONT_MARGIN: f32 = 1.0e-3;

/// The on-screen width in pixels of a hull of width `d` moved across the view ray (000 §2.3:
/// `|R' − R| = d·|R_z|`, projected with `f = height / (2·tan_half_fov)`): `d·f`. Zero for a
/// width that is not positive and finite, or a degenerate camera.
pub fn hull_pixels(width: f32, tan_half_fov: f32, height: u32) -> f32 {
    let px = width * (height as f32 / (2.0 * tan_half_fov));
    if px.is_finite() && px > 0.0 {
        px
    } else {
        0.0
    }
}

/// The window half-size (pixels) the edge pass searches for a frame whose widest hull is
/// `max_pixels` wide on screen ([`hull_pixels`]): its ceiling, at most [`MAX_REACH_PX`].
pub fn reach_window(max_pixels: f32) -> u32 {
    if max_pixels > 0.0 {
        (max_pixels.ceil() as u32).min(MAX_REACH_PX)
    } else {
        0
    }
}

/// The fraction of the hull's push seen across the view ray at a pixel, `|U − (U·v)·v|` with `U`
/// the interpolated outline direction and `v` the pixel's unit ray direction (000 §2.3: the
/// hull's on-screen width is `d·f` times this), quantized to `0..=REACH_STEPS` (`⌊x·255 + ½⌋`,
/// clamped; 0 for a non-finite value).
pub fn reach_code(outline: Vec3f, view: Vec3f) -> u32 {
    let v = view.normalize_or(Vec3f::ZERO);
    let across = outline - v * outline.dot(v);
    let s = across.length();
    if !s.is_finite() {
        return 0;
    }
    // At least ½, so the conversion's truncation is the floor (without a call to `floorf` on
    // targets without SSE4.1).
    (s.min(1.0) * REACH_STEPS as f32 + 0.5) as u32
}

/// The contact outline's radius in pixels for an edge pixel whose hull is `hull_px` wide
/// ([`hull_pixels`]) and whose reach code is `code` ([`reach_code`]).
pub fn reach_pixels(hull_px: f32, code: u32) -> f32 {
    hull_px * (code as f32 / REACH_STEPS as f32)
}

/// Whether the surface point seen at eye distance `q_dist` along the unit ray `q_dir` lies in
/// front of the plane through the point seen at `p_dist` along the unit ray `p_dir` with normal
/// `p_normal` (any length; zero: the plane facing the eye): the plane meets `q`'s ray at
/// `t = num/den` (`num = p_dist·(N·p_dir)`, `den = N·q_dir`, `N` turned to face the eye), and
/// `q` is in front when `q_dist < t·(1 − IN_FRONT_MARGIN)`, written `q_dist·den > num·(1 − margin)`
/// so that a ray missing the plane (`den ≥ 0`) counts as in front without a division.
pub fn in_front(p_normal: Vec3f, p_dir: Vec3f, p_dist: f32, q_dir: Vec3f, q_dist: f32) -> bool {
    let len = p_normal.length();
    let n = if len > 0.0 && len.is_finite() { p_normal / len } else { -p_dir };
    let facing = n.dot(p_dir);
    let n = if facing > 0.0 { -n } else { n };
    let num = p_dist * n.dot(p_dir);
    let den = n.dot(q_dir);
    q_dist * den > num * (1.0 - IN_FRONT_MARGIN)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_pixels_is_width_times_focal_length() {
        // fov 90°: tan_half 1, height 200 → f = 100.
        assert!((hull_pixels(0.03, 1.0, 200) - 3.0).abs() < 1e-6);
        assert_eq!(hull_pixels(0.0, 1.0, 200), 0.0);
        assert_eq!(hull_pixels(f32::NAN, 1.0, 200), 0.0);
        assert_eq!(hull_pixels(0.01, 0.0, 200), 0.0);
        assert_eq!(reach_window(2.2), 3);
        assert_eq!(reach_window(1e9), MAX_REACH_PX);
        assert_eq!(reach_window(0.0), 0);
    }

    #[test]
    fn reach_code_is_the_part_across_the_ray() {
        let v = Vec3f::new(0.0, 0.0, -1.0);
        assert_eq!(reach_code(Vec3f::new(0.0, 1.0, 0.0), v), 255);
        assert_eq!(reach_code(Vec3f::new(0.0, 0.0, 1.0), v), 0);
        // A box corner's direction, (1, 1, 1)/√3, seen along z: √(2/3) across.
        let c = Vec3f::new(1.0, 1.0, 1.0) / 3f32.sqrt();
        assert_eq!(reach_code(c, v), (0.816_496_6f32 * 255.0 + 0.5).floor() as u32);
        assert_eq!(reach_code(Vec3f::new(f32::NAN, 0.0, 0.0), v), 0);
        assert_eq!(reach_code(Vec3f::new(5.0, 0.0, 0.0), v), 255);
        assert!((reach_pixels(4.0, 255) - 4.0).abs() < 1e-6);
    }

    #[test]
    fn in_front_of_the_plane_of_the_other_surface() {
        // p sees the ground (normal +y) 10 below the eye looking down; q's ray meets the ground
        // at distance 10 too.
        let down = Vec3f::new(0.0, -1.0, 0.0);
        let q_dir = Vec3f::new(0.1, -1.0, 0.0).normalize_or(Vec3f::ZERO);
        let q_ground = 10.0 / q_dir.dot(down);
        let up = Vec3f::new(0.0, 1.0, 0.0);
        assert!(in_front(up, down, 10.0, q_dir, q_ground * 0.9));
        assert!(!in_front(up, down, 10.0, q_dir, q_ground * 1.1));
        assert!(!in_front(up, down, 10.0, q_dir, q_ground));
        // The normal's orientation does not matter; a missing normal faces the eye.
        assert!(in_front(-up, down, 10.0, q_dir, q_ground * 0.9));
        assert!(in_front(Vec3f::ZERO, down, 10.0, q_dir, q_ground * 0.9));
        // A ray that never meets the plane: whatever q is, it is in front.
        let sideways = Vec3f::new(1.0, 0.0, 0.0);
        assert!(in_front(up, down, 10.0, sideways, 1e6));
    }
}
