// Shared fixtures for the curve tests: configurations resembling thesis 002 Fig. 4.2 (a helix, a
// trigonometric sum, a degree-4 Bézier curve and a cubic B-spline, each about 20 units long),
// seen from the side by a pinhole camera at 40 units with a 45° field of view, and the per-pixel
// wave rays built exactly as the scene's `CameraBasis::wave_ray` builds them.
//
// Included by the other `curve_*` test files with `#[path]`, and by the unit tests of
// `src/curve/integrate.rs` with `include!` (hence plain comments: no inner attributes here).

use hadou_math::curve::{CurveFrame, CurveShape, CurveWave, Integrator};
use hadou_math::energy::{Falloff, FieldParams, Ray};
use hadou_math::{Vec3, Vec3d};

/// Image size of the acceptance configurations.
pub const SIZE: u32 = 512;
/// Far-plane distance.
pub const FAR: f64 = 100.0;

/// A curve along world `x` from `(-10, 0, 0)`, cross-section axes `ŷ = y`, `ẑ = D × ŷ = z`.
pub fn wave(shape: CurveShape, gamma: f32) -> CurveWave {
    CurveWave {
        frame: CurveFrame { origin: Vec3::new(-10.0, 0.0, 0.0), axis: Vec3::X, up: Vec3::Y },
        shape,
        gamma,
        extension: 1.0,
        attenuation: 0.0,
        alpha: 1.0,
        integrator: Integrator::Default,
    }
}

/// Helix of radius 2, one turn per 4 units, 20 units long (5 turns).
pub fn helix() -> CurveWave {
    wave(CurveShape::Helix { radius: 2.0, rate: std::f32::consts::TAU / 4.0, phase: 0.3, length: 20.0 }, 1.0)
}

/// Trigonometric sum with three harmonics of a 10-unit period, 20 units long.
pub fn trig_sum() -> CurveWave {
    wave(
        CurveShape::TrigSum {
            rate: std::f32::consts::TAU / 10.0,
            y_terms: vec![[2.0, 0.0], [0.0, 0.6], [0.4, 0.0]],
            z_terms: vec![[0.0, 1.5], [0.5, 0.0]],
            length: 20.0,
        },
        1.0,
    )
}

/// Degree-4 Bézier curve stretched to 20 units (`γ = 20`).
pub fn bezier4() -> CurveWave {
    wave(
        CurveShape::Bezier { points: vec![[0.0, 0.0], [6.0, 3.0], [-5.0, -2.0], [4.0, 4.0], [0.0, 1.0]] },
        20.0,
    )
}

/// Cubic (order 4) B-spline over 8 control points, clamped uniform knots, 20 units.
pub fn bspline() -> CurveWave {
    wave(
        CurveShape::BSpline {
            points: vec![
                [0.0, 0.0],
                [3.0, 2.0],
                [-2.0, 3.0],
                [-3.0, -2.0],
                [2.0, -3.0],
                [3.0, 2.0],
                [-1.0, 1.0],
                [0.0, 0.0],
            ],
            order: 4,
            knots: None,
        },
        20.0,
    )
}

/// The four Fig. 4.2-like shapes with their names.
pub fn shapes() -> Vec<(&'static str, CurveWave)> {
    vec![("helix", helix()), ("trig sum", trig_sum()), ("bezier4", bezier4()), ("bspline", bspline())]
}

/// Field parameters of the two falloffs: the thesis's faithful `1/r` with no core radius, and
/// the inverse square with a core of 0.05.
pub fn params(falloff: Falloff) -> FieldParams<f64> {
    FieldParams { falloff, core_radius: if falloff == Falloff::Faithful { 0.0 } else { 0.05 } }
}

/// `f32` copy of field parameters.
pub fn params32(p: &FieldParams<f64>) -> FieldParams<f32> {
    FieldParams { falloff: p.falloff, core_radius: p.core_radius as f32 }
}

/// A pixel's wave ray: `(ray, t0, t1, t_far)`.
#[derive(Clone, Copy, Debug)]
pub struct PixelRay {
    /// The ray.
    pub ray: Ray<f64>,
    /// Span start.
    pub t0: f64,
    /// Span end.
    pub t1: f64,
    /// Far point parameter.
    pub t_far: f64,
}

impl PixelRay {
    /// `f32` copy of the ray.
    pub fn ray32(&self) -> Ray<f32> {
        Ray { origin: self.ray.origin.as_f32(), dir: self.ray.dir.as_f32() }
    }
}

/// Camera at `(0, 0, 40)` looking at the origin, up `y`, 45° vertical field of view; the wave ray
/// of pixel `(px, py)` of a `SIZE × SIZE` image as `CameraBasis::wave_ray` builds it, with nothing
/// occluding.
pub fn pixel_ray(px: f64, py: f64, falloff: Falloff) -> PixelRay {
    let eye = Vec3d::new(0.0, 0.0, 40.0);
    let forward = Vec3d::new(0.0, 0.0, -1.0);
    let right = Vec3d::new(1.0, 0.0, 0.0);
    let up = Vec3d::new(0.0, 1.0, 0.0);
    let tan = (22.5f64).to_radians().tan();
    let ndc_x = 2.0 * (px + 0.5) / f64::from(SIZE) - 1.0;
    let ndc_y = 1.0 - 2.0 * (py + 0.5) / f64::from(SIZE);
    let dir = forward + right * (ndc_x * tan) + up * (ndc_y * tan);
    let len = dir.length();
    match falloff {
        Falloff::Faithful => {
            PixelRay { ray: Ray { origin: eye, dir: dir * FAR }, t0: 0.0, t1: 1.0, t_far: 1.0 }
        }
        Falloff::InverseSquare => PixelRay {
            ray: Ray { origin: eye, dir: dir / len },
            t0: 0.0,
            t1: f64::INFINITY,
            t_far: FAR * len,
        },
    }
}

/// Every `step`-th pixel of the image (offset to the middle of each block).
pub fn sample_pixels(step: u32) -> Vec<(u32, u32)> {
    let mut v = Vec::new();
    let off = step / 2;
    for py in (off..SIZE).step_by(step as usize) {
        for px in (off..SIZE).step_by(step as usize) {
            v.push((px, py));
        }
    }
    v
}

/// The `q`-quantile (0..=1) of a set of values.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    let mut v: Vec<f64> = values.to_vec();
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return 0.0;
    }
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v[i]
}

/// Known bug, found by the GPU twin test: an inverse-square ray exactly perpendicular to the
/// curve's axis with an open span (nothing drawn behind) paired with the wrong cross-section
/// (`0·∞ = NaN` in the walk's far end), about 10 % off. It must match the converged reference.
#[test]
fn perpendicular_open_ray_pairs_with_its_own_cross_section() {
    use hadou_math::curve::{curve_energy, curve_energy_reference, prepare, CurveFrame, CurveShape};
    use hadou_math::curve::{CurveWave, Integrator};
    use hadou_math::energy::{Falloff, FieldParams, Ray};
    use hadou_math::Vec3;
    let wave = CurveWave {
        frame: CurveFrame { origin: Vec3::new(-5.0, 0.0, 0.0), axis: Vec3::X, up: Vec3::Y },
        shape: CurveShape::Helix { radius: 1.5, rate: 2.5, phase: 0.0, length: 10.0 },
        gamma: 1.0,
        extension: 1.0,
        attenuation: 0.0,
        alpha: 5.0,
        integrator: Integrator::Default,
    };
    let c = prepare(&wave);
    for x in [-3.7f32, 0.3, 2.9] {
        let ray = Ray { origin: Vec3::new(x, 0.4, 12.0), dir: Vec3::new(0.0, 0.0, -1.0) };
        let p = FieldParams { falloff: Falloff::InverseSquare, core_radius: 0.02 };
        let got = curve_energy(&c, &p, &ray, 0.0, f32::INFINITY, 100.0).energy as f64;
        let p64 = FieldParams { falloff: Falloff::InverseSquare, core_radius: 0.02f64 };
        let ray64 = Ray { origin: ray.origin.as_f64(), dir: ray.dir.as_f64() };
        let want = curve_energy_reference(&c, &p64, &ray64, 0.0, f64::INFINITY, 100.0, 1e-10);
        assert!((got - want).abs() <= 5e-3 * want, "x = {x}: {got} vs {want}");
    }
}

/// The workspace's deterministic generator (splitmix64).
#[allow(unused_imports, reason = "not every test binary including this module draws random cases")]
pub use hadou_math::rng::Rng;
