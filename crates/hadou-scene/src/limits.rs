//! The numeric limits of a scene, chosen so that nothing a valid scene can say makes a renderer
//! compute a non-finite value (f32 overflows past ~3.4e38), and the number formatting of messages.
//!
//! Why these bounds make overflow impossible (f32 throughout, `MAX ≈ 3.4e38`):
//!
//! - Every position, point, length, radius, rate, phase, coefficient, colour, direction component
//!   and the like is within `±COORD_MAX = 1e6`; glTF vertices (after node transforms) are too.
//!   Object `scale ≤ 1e6`, so a world vertex is at most `1e6 · 1e6 · √3 + 1e6 < 2e12` from the
//!   origin, and every squared distance the renderers form (view-space depth, `|v|²`, `|û × v|²`
//!   in `hadou_math::energy::kernel`, the curves' squared distances) is below `(4e12)² = 1.6e25`.
//!   Trigonometric curves sum at most 64 terms of `≤ 1e6`: `|y|, |z| ≤ 1e8`.
//! - `far ≤ FAR_MAX = 1e7` and `fov ≤ FOV_MAX = 179°`: `tan(fov/2) ≤ 115`, the aspect ratio is at
//!   most 16384, so a pixel direction (`CameraBasis::pixel_dir`, forward component 1) is shorter
//!   than `2e6`; the far distance `far · |dir|` (the depth of an empty pixel, the faithful ray
//!   `Q = far · dir`) is below `2e13` and `Y = s·t + β` of the faithful kernel (`t ≤ 1`) below
//!   `3e13`, `Y² < 1e27`. Inverse-square rays are unit and clamp `t` at `T_LIMIT = 1e12`.
//! - A curve is at most `MAX_SLOPE = 1e5` steep (`hadou_math::curve::CurveWave::steepness`, the
//!   cross-section's motion per unit of axial travel), so the chord walk's relative speed
//!   `|q_⊥ − q_x·m|` of a ray against a piece of slope `m` is below `2e13 · (1 + 1e5)` and its
//!   square below `4e36`; turns, terms, control points and Simpson's `m × point cost` bound a
//!   ray's work (docs/scene-format.md, "Work per ray").
//! - `fov ≥ FOV_MIN = 0.001°` and `near ≥ NEAR_MIN = 1e-6`: the rasterizer's `1/tan(fov/2)`
//!   (`≤ 1.2e5`, times the aspect ≤ 16384 gives `≤ 2e9`) and `1/z ≤ 1e6` stay finite, so a
//!   projected vertex is below `2e12 · 1e6 · 2e9 · 16384 < 1e32`.
//! - Each closed-form energy piece is at most `ENERGY_MAX = 1e30` (hadou-math). A wave has at most
//!   5 analytic pieces (beam), each multiplied by a strength `α ≤ ALPHA_MAX = 1e5`: one wave's
//!   energy is below `5e35`. Curves regularise with a core of at least `1e-6`, so each straight
//!   piece is below `1e7 / 1e-12 = 1e19` and a wave (≤ 2^14 pieces × 64 parts) below `1e30`.
//!   With at most `MAX_WAVES = 256` waves the summed energy of a pixel is below `1.3e38`.
//! - Colours (`rgb`, light, ambient, albedo, background) and `exposure` are at most `1e6`, so a
//!   product of parameters `α · rgb · exposure ≤ 1e17`; where it meets a divergent integral the
//!   wave light may saturate to `+∞`, which the colour mappings turn into white (a finite value),
//!   and no NaN can arise because every term is `≥ 0`.

/// The most work one pixel may cost, in integrand evaluations: the sum over the scene's waves of
/// each one's bound per ray ([`Scene::ray_work`](crate::Scene::ray_work)) times the samples per
/// pixel (where a pixel's samples disagree, at a silhouette, the waves run once per sample).
/// 2²⁷ = 134 217 728: every wave count and kind the other limits allow at the default 4 samples
/// (256 curves: 102 million), 83 curves or 11 nearest-field ones at 16; past it, what issue 41
/// timed at about 13 minutes for a 48×32 image (256 nearest-field helices). Checked when a scene is
/// loaded and whenever a caller sets the samples (docs/scene-format.md, "Work per pixel").
pub const PIXEL_WORK_MAX: u64 = 1 << 27;

/// Work of one analytic wave on one ray, in the same units: at most five closed-form pieces (a
/// beam), each attenuated one marched in at most [`hadou_math::energy::MAX_CELLS`] cells and a
/// last one.
pub const ANALYTIC_RAY_WORK: u64 = 5 * (hadou_math::energy::MAX_CELLS as u64 + 1);

/// Largest image edge in pixels, for `[image]`, command-line sizes and the viewer alike.
pub const MAX_IMAGE_EDGE: u32 = 16384;

/// Checks an image size against the rules a scene's `[image]` follows: each edge in
/// `1..=MAX_IMAGE_EDGE`, and at most [`crate::SOFT_MAX_PIXELS`] pixels when the scene has an
/// `[area_light]`. Every path that can set a size (the file, `--width/--height`, a track, a viewer
/// script, the viewer's window) calls this, so one limit holds everywhere. The message names the
/// size; callers prefix where it came from (a flag, a script line, a file position).
pub fn check_image_size(width: u32, height: u32, area_light: bool) -> Result<(), String> {
    check_image_size_with(width, height, area_light, None)
}

/// Bytes a renderer holds per pixel of the whole image while it draws a frame with a `[bloom]`,
/// whatever the band: the glare reads every row of the linear colour (its deepest level is as
/// tall as the image), so the linear colour (12), its prefiltered copy (12), the pyramid's levels
/// (≤ 8) and the energy and depth of the rows drawn (8) are kept for the whole image at once.
/// The opaque pass's per-sample buffers are not: they are drawn in bands of about 4 Mi samples
/// whatever the anti-aliasing.
pub const GLARE_BYTES_PER_PIXEL: u64 = 40;

/// Bytes per pixel of a band of output rows of a frame with a `[bloom]`: the glared colour (12),
/// the band's float image (24) and its 8-bit bytes (3), rounded up.
pub const GLARE_BAND_BYTES_PER_PIXEL: u64 = 40;

/// The most memory a frame with a `[bloom]` may need (3 GiB): the whole image's glare planes
/// ([`GLARE_BYTES_PER_PIXEL`]) and at least one row of output band. With it, no scene within the
/// limits needs more than about 3.5 GB (docs/scene-format.md, "Memory").
pub const GLARE_MAX_BYTES: u64 = 3 << 30;

/// The most pixels an image with a `[bloom]` may have: 8192² = 2²⁶, whose glare planes
/// ([`GLARE_BYTES_PER_PIXEL`]) take 2.7 GB of [`GLARE_MAX_BYTES`], leaving room for bands of
/// 1 638 rows.
pub const GLARE_MAX_PIXELS: u64 = 1 << 26;

/// Rows per band of output for a `width × height` frame with a `[bloom]`: the most rows whose
/// band ([`GLARE_BAND_BYTES_PER_PIXEL`]) fits in [`GLARE_MAX_BYTES`] beside the whole image's
/// glare planes, at least 1 and at most `height`. Every band draws the whole linear image again
/// (the glare of a row depends on every row), so the fewer bands, the less work: an image up to
/// about 6 340² is one band, 8192² six.
pub fn glare_band_rows(width: u32, height: u32) -> u32 {
    let (w, h) = (u64::from(width.max(1)), u64::from(height.max(1)));
    let fixed = w * h * GLARE_BYTES_PER_PIXEL;
    let rows = GLARE_MAX_BYTES.saturating_sub(fixed) / (w * GLARE_BAND_BYTES_PER_PIXEL);
    rows.clamp(1, h) as u32
}

/// [`check_image_size`], and with `bloom` (where the scene's `[bloom]` is, for the message) at
/// most [`GLARE_MAX_PIXELS`] pixels.
pub fn check_image_size_with(
    width: u32,
    height: u32,
    area_light: bool,
    bloom: Option<&crate::Location>,
) -> Result<(), String> {
    check_edges_and_area(width, height, area_light)?;
    let px = u64::from(width) * u64::from(height);
    if let Some(at) = bloom.filter(|_| px > GLARE_MAX_PIXELS) {
        let need = px * GLARE_BYTES_PER_PIXEL;
        return Err(format!(
            "with the [bloom] at {at} an image has at most {GLARE_MAX_PIXELS} pixels (8192²: the \
             glare keeps {GLARE_BYTES_PER_PIXEL} bytes a pixel of the whole image, within {} GiB); \
             {width}×{height} is {px} pixels and would need {:.1} GB",
            GLARE_MAX_BYTES >> 30,
            need as f64 / 1e9
        ));
    }
    Ok(())
}

fn check_edges_and_area(width: u32, height: u32, area_light: bool) -> Result<(), String> {
    for (edge, v) in [("width", width), ("height", height)] {
        if v == 0 || v > MAX_IMAGE_EDGE {
            return Err(format!("image {edge} {v} is outside 1..={MAX_IMAGE_EDGE} pixels"));
        }
    }
    if area_light && u64::from(width) * u64::from(height) > crate::SOFT_MAX_PIXELS {
        return Err(format!(
            "a scene with an [area_light] renders images of at most {} pixels (4096²; the penumbra \
             search works on the whole image at once); {width}×{height} is {} pixels",
            crate::SOFT_MAX_PIXELS,
            u64::from(width) * u64::from(height)
        ));
    }
    Ok(())
}

/// The most memory the traced resolve's hierarchy of the casters' triangles may take (256 MiB):
/// at most [`hadou_math::soft::bvh_bytes_bound`]`(n) = 48·n + 64·n` bytes for `n` caster
/// triangles (the triangles, fewer than `2n` nodes of 32 bytes), 224 MiB at [`MAX_TRIANGLES`], so
/// every scene within the limits fits; a frame over it is refused ([`check_trace_memory`]).
pub const TRACE_MAX_BYTES: u64 = 256 << 20;

/// Checks the traced resolve's hierarchy over `triangles` caster triangles against
/// [`TRACE_MAX_BYTES`]; the message names the budget.
pub fn check_trace_memory(triangles: u64) -> Result<(), String> {
    let need = hadou_math::soft::bvh_bytes_bound(triangles);
    if need > TRACE_MAX_BYTES {
        return Err(format!(
            "the traced resolve of the [area_light] keeps at most {} MiB for its hierarchy of the casters' \
             triangles (TRACE_MAX_BYTES); {triangles} triangles would need up to {:.1} MiB",
            TRACE_MAX_BYTES >> 20,
            need as f64 / f64::from(1u32 << 20)
        ));
    }
    Ok(())
}

/// Bound on the magnitude of every scene number without a tighter rule.
pub(crate) const COORD_MAX: f32 = 1e6;
/// Largest `far`.
pub(crate) const FAR_MAX: f32 = 1e7;
/// Smallest `near`.
pub(crate) const NEAR_MIN: f32 = 1e-6;
/// Field of view range in degrees.
pub(crate) const FOV_MIN: f32 = 1e-3;
/// Largest field of view in degrees.
pub(crate) const FOV_MAX: f32 = 179.0;
/// Largest wave strength (`alpha_s`, `alpha_c`, `head_alpha`, `muzzle_alpha`, `alpha`).
pub const ALPHA_MAX: f32 = 1e5;
/// Largest attenuation exponent `j` of a wave (002 eq. 3.23, SPEC.md §1.4).
pub const ATTENUATION_MAX: f32 = 64.0;
/// Smallest object scale.
pub(crate) const SCALE_MIN: f32 = 1e-6;
/// Shortest direction vector (before normalisation).
pub(crate) const DIR_MIN: f64 = 1e-6;
/// Most `[[wave]]` tables in one scene.
pub(crate) const MAX_WAVES: usize = 256;
/// Most triangles of all objects of one scene together, every glTF instance counted: 2²¹
/// (two spheres of 1024 segments). The CPU backend keeps about 200 bytes per projected triangle
/// (an object's, its outline hull's, and each shadow's copy of its casters'), so a scene at its
/// limits renders in well under 4 GB (docs/scene-format.md, "Memory").
pub const MAX_TRIANGLES: u64 = 1 << 21;
/// Most material slots of all objects of one scene together (an object has one slot per material
/// of its mesh, at least one; so also the most objects). Both backends keep a material record per
/// slot of every object, and `Scene::at` builds each slot's material per frame.
pub const MAX_MATERIAL_SLOTS: u64 = 65_536;
/// Most checks of the rules between keys: for each part of a scene with such rules (the camera,
/// the light, the area light with its target object, each shadow, each wave), its distinct key
/// times times the numbers it holds, summed over the parts (2²⁶, well under a second of work).
pub const MAX_KEY_CHECKS: u64 = 1 << 26;
/// Most vertices of all objects of one scene together (primitives' and glTF primitives', every
/// instance counted): three per triangle of [`MAX_TRIANGLES`], what a mesh without shared vertices
/// needs.
pub const MAX_VERTICES: u64 = 3 * MAX_TRIANGLES;
/// Most joints of all the skins one glTF file's default scene uses, each skin counted once (so
/// also the most joints of one skin; `JOINTS_0` indices are 16-bit, so no skin can address more).
/// Each skin's joint matrices are computed once, whatever the number of nodes using it.
pub const MAX_SKIN_JOINTS: u64 = 65_536;
/// Most skinned mesh nodes (nodes with both a mesh and a skin) one glTF file's default scene
/// instantiates.
pub const MAX_SKINNED_NODES: u64 = 16_384;

/// A number for a message: shortest round-trip digits, in scientific notation where that is
/// clearly shorter (`3e38` rather than 39 digits, `1e5` rather than `100000`).
pub(crate) fn fmt_f64(x: f64) -> String {
    shorter(format!("{x}"), format!("{x:e}"))
}

/// [`fmt_f64`] for an `f32` (its own shortest digits, not those of its `f64` widening).
pub(crate) fn fmt_f32(x: f32) -> String {
    shorter(format!("{x}"), format!("{x:e}"))
}

fn shorter(plain: String, sci: String) -> String {
    if sci.len() + 2 <= plain.len() {
        sci
    } else {
        plain
    }
}

// Spring bones (`spring.rs`): what bounds one pose's simulation.

/// Simulation steps per second of scene time (VRM players step once per displayed frame; a fixed
/// rate makes the pose a function of the time alone).
pub const SPRING_RATE: f64 = 60.0;

/// Most steps simulated for one pose: 3 600 (one minute at [`SPRING_RATE`]). A later time starts
/// from rest at the first multiple of [`SPRING_RESTART_STEPS`] at most this many steps before it.
pub const SPRING_MAX_STEPS: u64 = 3_600;

/// Past [`SPRING_MAX_STEPS`], the steps the simulation's start moves by: 600 (ten seconds). The
/// frames between two moves continue one state (a sequence or the viewer steps once a frame),
/// and each frame still starts more than 3 000 steps after its rest.
pub const SPRING_RESTART_STEPS: u64 = 600;

/// Most spring joints of one file (VRM 1.0 joints, VRM 0.x bones with their descendants).
pub const MAX_SPRING_JOINTS: usize = 4_096;

/// Most spring-bone colliders of one file.
pub const MAX_SPRING_COLLIDERS: usize = 1_024;

/// Largest joint-collider pair count of one file (each spring's joints times its colliders,
/// summed): what one step may cost in collision tests.
pub const MAX_SPRING_COLLISION_PAIRS: usize = 1 << 18;

/// Largest length of the external force (gravity plus wind) on a joint, in the character's units
/// per second; a larger one is shortened to it (the tail is held at its bone length anyway).
pub const SPRING_FORCE_MAX: f32 = 1e6;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hierarchy_of_a_scene_at_the_triangle_limit_fits_its_budget() {
        assert!(check_trace_memory(MAX_TRIANGLES).is_ok());
        let e = check_trace_memory(4 * MAX_TRIANGLES).unwrap_err();
        assert!(e.contains("256 MiB") && e.contains("TRACE_MAX_BYTES"), "{e}");
    }

    #[test]
    fn numbers_in_messages_are_short() {
        assert_eq!(fmt_f64(1e300), "1e300");
        assert_eq!(fmt_f32(3e38), "3e38");
        assert_eq!(fmt_f32(1e-45), "1e-45");
        assert_eq!(fmt_f32(0.1), "0.1");
        assert_eq!(fmt_f32(-0.0), "-0");
        assert_eq!(fmt_f32(180.0), "180");
        assert_eq!(fmt_f64(123456.5), "123456.5");
        assert_eq!(fmt_f32(1e5), "1e5");
        assert_eq!(fmt_f32(0.001), "0.001");
        assert_eq!(fmt_f32(16384.0), "16384");
    }
}
