//! The wave pass: each pixel's energy integrals, clipped at the visible surface (002 §3.3.5), and
//! the colour mapping.

use hadou_math::curve::{self, PreparedCurve};
use hadou_math::energy::{self, FieldParams};
use hadou_math::shade;
use hadou_scene::{CameraBasis, Frame, ToneMode, Wave, WaveShape};

/// Per-frame preparation of the curved waves (piece tables, bounds), one entry per wave, `None`
/// for analytic waves.
pub(crate) fn prepare_curves(frame: &Frame) -> Vec<Option<PreparedCurve>> {
    frame
        .waves
        .iter()
        .map(|w| match &w.shape {
            WaveShape::Curve(c) => Some(curve::prepare(c)),
            _ => None,
        })
        .collect()
}

/// Energy of one wave along pixel `(px, py)`'s ray, and the number of integrand evaluations it
/// took (closed-form pieces count one each for the analytic shapes).
#[inline]
pub(crate) fn wave_energy(
    frame: &Frame,
    basis: &CameraBasis,
    wave: &Wave,
    prepared: Option<&PreparedCurve>,
    px: f32,
    py: f32,
    surface: Option<f32>,
) -> (f32, u32) {
    let wr = basis.wave_ray(wave.falloff, frame.camera.far, px, py, frame.width, frame.height, surface);
    let p = FieldParams { falloff: wave.falloff, core_radius: wave.core_radius };
    let (ray, t0, t1) = (&wr.ray, wr.t0, wr.t1);
    let (e, n) = match &wave.shape {
        WaveShape::Sphere(f) => (energy::sphere_energy(&p, ray, t0, t1, f), 1),
        WaveShape::Cylinder(f) => (energy::cylinder_energy(&p, ray, t0, t1, f), 1),
        WaveShape::Capsule(f) => (energy::capsule_energy(&p, ray, t0, t1, f), 3),
        WaveShape::Beam(f) => (energy::beam_energy(&p, ray, t0, t1, f), 5),
        WaveShape::Curve(c) => {
            let owned;
            let prep = match prepared {
                Some(p) => p,
                None => {
                    owned = curve::prepare(c);
                    &owned
                }
            };
            let r = curve::curve_energy(prep, &p, ray, t0, t1, wr.t_far);
            (r.energy, r.evaluations)
        }
    };
    // Saturated at f32::MAX (hadou_math::energy::saturate): an overflow is full brightness, not 0.
    (energy::saturate(e), n)
}

/// Final linear RGBA of a pixel: `scene + exposure · Σ rgb·a·I`, then the frame's mapping.
#[inline]
pub(crate) fn compose(frame: &Frame, scene_rgb: [f32; 3], wave_rgb: [f32; 3]) -> [f32; 4] {
    let k = frame.color_mapping.exposure;
    let c = [0, 1, 2].map(|i| scene_rgb[i] + k * wave_rgb[i]);
    let m = match frame.color_mapping.mode {
        ToneMode::Faithful => shade::map_faithful(c),
        ToneMode::Filmic => shade::map_filmic(c),
    };
    [m[0], m[1], m[2], 1.0]
}

/// Adds one wave's light `rgb · a · I` to `acc`.
#[inline(always)]
pub(crate) fn accumulate(acc: &mut [f32; 3], wave: &Wave, e: f32) {
    let [r, g, b, a] = wave.color;
    acc[0] += r * a * e;
    acc[1] += g * a * e;
    acc[2] += b * a * e;
}
