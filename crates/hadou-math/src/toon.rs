//! The energy wave as a light on toon-shaded surfaces (000 §2.1–2.2, SPEC.md §2.1–2.2): colour
//! ramps over the unclamped `m = N·L`, the nearest point of a wave's centre line (the per-point
//! light position), how several waves share a surface, and bilinear texture sampling. Mirrored in
//! WGSL by `hadou-gpu` (keep in sync with `crates/hadou-gpu/src/shaders/shading.wgsl` and, for the
//! ramps, `common.wgsl`).

use crate::Vec3f;

/// Most bands (or gradient stops) in one ramp; the GPU stores ramps in fixed-size records.
pub const MAX_RAMP_BANDS: usize = 8;

/// A colour ramp over `m ∈ [−1, 1]` (000 §2.1, SPEC.md §2.1).
///
/// `stops` are `(threshold, colour)` with non-decreasing thresholds (checked by the scene loader).
/// - [`RampKind::Bands`]: the colour of the last stop whose threshold is `≤ m` (the first stop's
///   colour below every threshold). With `smoothing = w > 0` each step between bands `k − 1` and
///   `k` is a smoothstep over `[t_k − w/2, t_k + w/2]`, so the ramp is continuous;
///   `w = 0` gives the thesis's hard bands.
/// - [`RampKind::Gradient`]: piecewise-linear between stops, constant beyond the first and last.
#[derive(Clone, Debug, PartialEq)]
pub struct Ramp {
    /// How stops are joined.
    pub kind: RampKind,
    /// `(threshold, linear RGB)`, thresholds non-decreasing, `1..=MAX_RAMP_BANDS` entries.
    pub stops: Vec<(f32, [f32; 3])>,
}

/// How a [`Ramp`] joins its stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RampKind {
    /// Flat bands; `smoothing ≥ 0` is the width of each step.
    Bands {
        /// Step width (0 = hard steps).
        smoothing: f32,
    },
    /// Linear interpolation between stops.
    Gradient,
}

impl Ramp {
    /// The thesis's example ramp for a blue wave (000 §2.1): `(0.0, 0.2, 0.4)` for `m < −0.3`,
    /// `(0.5, 0.7, 0.9)` for `−0.3 ≤ m < 0`, `(0.9, 0.9, 1.0)` for `m ≥ 0`, hard steps.
    pub fn thesis_blue() -> Self {
        Ramp {
            kind: RampKind::Bands { smoothing: 0.0 },
            stops: vec![(-1.0, [0.0, 0.2, 0.4]), (-0.3, [0.5, 0.7, 0.9]), (0.0, [0.9, 0.9, 1.0])],
        }
    }

    /// hadou's default wave-light ramp for a wave of colour `c` (linear RGB): three hard bands at
    /// the thesis's thresholds, built the way the thesis's blue ramp relates to its wave colour:
    /// a dark band `0.4·c`, a mid band `c` lifted 40 % towards white, a bright band `c` lifted 85 %
    /// towards white (each channel clamped to `[0, 1]` first). For `c = (0, 0.5, 1)` this is
    /// close to [`Ramp::thesis_blue`].
    pub fn for_wave_color(c: [f32; 3]) -> Self {
        let c = c.map(|v| if v.is_finite() { v.clamp(0.0, 1.0) } else { 1.0 });
        let lift = |k: f32| c.map(|v| v + (1.0 - v) * k);
        Ramp {
            kind: RampKind::Bands { smoothing: 0.0 },
            stops: vec![(-1.0, c.map(|v| 0.4 * v)), (-0.3, lift(0.4)), (0.0, lift(0.85))],
        }
    }

    /// A two-band toon ramp of multipliers: `shade` below `threshold`, white above, stepping over
    /// `smoothing`.
    pub fn two_band(threshold: f32, shade: [f32; 3], smoothing: f32) -> Self {
        Ramp { kind: RampKind::Bands { smoothing }, stops: vec![(-1.0, shade), (threshold, [1.0; 3])] }
    }

    /// The colour at `m` (any finite or non-finite value: NaN reads as `m = −1`).
    pub fn eval(&self, m: f32) -> [f32; 3] {
        let m = if m.is_nan() { -1.0 } else { m };
        let Some(&(_, first)) = self.stops.first() else { return [0.0; 3] };
        let mut c = first;
        match self.kind {
            RampKind::Bands { smoothing } => {
                for k in 1..self.stops.len() {
                    let (t, ck) = self.stops[k];
                    let prev = self.stops[k - 1].1;
                    let s = band_step(m, t, smoothing);
                    for i in 0..3 {
                        c[i] += (ck[i] - prev[i]) * s;
                    }
                }
            }
            RampKind::Gradient => {
                for k in 1..self.stops.len() {
                    let (t0, c0) = self.stops[k - 1];
                    let (t1, c1) = self.stops[k];
                    let s = if t1 > t0 { ((m - t0) / (t1 - t0)).clamp(0.0, 1.0) } else { step(m, t1) };
                    for i in 0..3 {
                        c[i] += (c1[i] - c0[i]) * s;
                    }
                }
            }
        }
        c
    }
}

/// `1` where `m ≥ t`, else `0`.
#[inline]
fn step(m: f32, t: f32) -> f32 {
    if m >= t {
        1.0
    } else {
        0.0
    }
}

/// The weight of band `k` at `m`: a hard step at `t` (`w = 0`), else a smoothstep over
/// `[t − w/2, t + w/2]`.
#[inline]
pub fn band_step(m: f32, t: f32, w: f32) -> f32 {
    if w <= 0.0 {
        return step(m, t);
    }
    let x = ((m - t) / w + 0.5).clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The nearest point of the segment `a..b` to `p` (000 §2.1, SPEC.md §2.1, generalised from the
/// thesis's half-line to a segment: `a = (p − a)·D / |b − a|` clamped to `[0, 1]`). A degenerate
/// segment (`a = b`) gives `a`.
#[inline]
pub fn nearest_on_segment(p: Vec3f, a: Vec3f, b: Vec3f) -> Vec3f {
    let d = b - a;
    let dd = d.dot(d);
    if dd <= 0.0 || !dd.is_finite() {
        return a;
    }
    let t = ((p - a).dot(d) / dd).clamp(0.0, 1.0);
    a + d * t
}

/// The nearest point of the infinite line through `a` along unit `dir` to `p`.
#[inline]
pub fn nearest_on_line(p: Vec3f, a: Vec3f, dir: Vec3f) -> Vec3f {
    a + dir * (p - a).dot(dir)
}

/// The nearest point of the polyline `points` to `p` (the first of equally near points, in order).
/// One point gives that point; none gives `p`.
pub fn nearest_on_polyline(p: Vec3f, points: &[Vec3f]) -> Vec3f {
    match points {
        [] => p,
        [only] => *only,
        _ => {
            let mut best = points[0];
            let mut best_d = f32::INFINITY;
            for s in points.windows(2) {
                let q = nearest_on_segment(p, s[0], s[1]);
                let d = (q - p).length_squared();
                if d < best_d {
                    best_d = d;
                    best = q;
                }
            }
            best
        }
    }
}

/// The shading value `m = N·L` of 000 §2.1: `L` the unit direction from the surface point `p`
/// towards the light point `e`, `N` the unit normal, **not clamped**. A light point on the surface
/// (`|e − p| = 0`) gives `m = 1` (fully lit), so the result is finite everywhere.
#[inline]
pub fn wave_m(p: Vec3f, n: Vec3f, e: Vec3f) -> f32 {
    match (e - p).try_normalize() {
        Some(l) => n.dot(l).clamp(-1.0, 1.0),
        None => 1.0,
    }
}

/// How strongly a wave claims a surface point, for sharing one point between several waves:
/// its density at the point, `α·a / (d² + r_c²)` for the inverse-square falloff and
/// `α·a / √(d² + r_c²)` for the thesis's 1/r density, where `d` is the distance to the wave's
/// centre line, `α` the field strength and `a` the colour's alpha. The core radius (at least
/// `1e-4`) keeps it finite on the line itself; the result saturates at `f32::MAX`.
#[inline]
pub fn dominance(distance: f32, core_radius: f32, strength: f32, inverse_square: bool) -> f32 {
    let rc = core_radius.max(1e-4);
    let q = distance * distance + rc * rc;
    let rho = if inverse_square { 1.0 / q } else { 1.0 / q.sqrt() };
    let v = strength.max(0.0) * rho;
    if v.is_nan() {
        0.0
    } else {
        v.min(f32::MAX)
    }
}

/// The exponent applied to [`dominance`] before normalising: each wave's share of a point is
/// `ρᵢᵖ / Σⱼ ρⱼᵖ` with `p = 2`, so the wave that is clearly denser at a point takes its look,
/// and where two waves are equally dense each gives half (a smooth blend, no seam).
pub const DOMINANCE_POWER: f32 = 2.0;

/// The weights `ρᵢᵖ / Σⱼ ρⱼᵖ` ([`DOMINANCE_POWER`]) for the given densities, in place. Computed
/// relative to the largest density, so they are finite and sum to 1 whenever any density is
/// positive; all zero densities give all-zero weights.
pub fn dominance_weights(rho: &mut [f32]) {
    let max = rho.iter().copied().fold(0.0f32, f32::max);
    if max <= 0.0 {
        rho.iter_mut().for_each(|r| *r = 0.0);
        return;
    }
    let mut sum = 0.0;
    for r in rho.iter_mut() {
        let x = *r / max;
        *r = x * x;
        sum += *r;
    }
    for r in rho.iter_mut() {
        *r /= sum;
    }
}

/// Texture coordinate wrapping (glTF sampler `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    /// `REPEAT` (10497).
    #[default]
    Repeat,
    /// `CLAMP_TO_EDGE` (33071).
    Clamp,
    /// `MIRRORED_REPEAT` (33648).
    Mirror,
}

/// Texture filtering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Filter {
    /// Bilinear between the four nearest texel centres.
    #[default]
    Linear,
    /// The texel containing the point.
    Nearest,
}

/// Texel index `i` wrapped into `0..n`.
#[inline]
pub fn wrap_index(i: i32, n: i32, wrap: Wrap) -> i32 {
    match wrap {
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Mirror => {
            let k = i.rem_euclid(2 * n);
            if k < n {
                k
            } else {
                2 * n - 1 - k
            }
        }
    }
}

/// The sRGB → linear transfer (IEC 61966-2-1) of the 8-bit value `v`.
pub fn srgb_to_linear(v: u8) -> f32 {
    let c = v as f32 / 255.0;
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The 256-entry sRGB → linear table both backends decode texels with (the GPU receives the same
/// floats), so a texel decodes to the same value everywhere.
pub fn srgb_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as u8)))
}

/// Samples an RGBA8 image (`texels` row-major from the top row, colour sRGB-encoded, alpha
/// linear) at texture coordinates `(u, v)` (glTF convention: `(0, 0)` is the top-left corner of
/// the image), level 0 only. Texel `(i, j)` has its centre at `((i + ½)/w, (j + ½)/h)`;
/// [`Filter::Linear`] weights the four nearest centres bilinearly after decoding each to linear
/// with [`srgb_table`]; [`Filter::Nearest`] takes the texel containing the point. Non-finite
/// coordinates read as 0. Returns linear RGBA. An empty image gives opaque white.
pub fn sample(texels: &[[u8; 4]], w: u32, h: u32, wrap: [Wrap; 2], filter: Filter, uv: [f32; 2]) -> [f32; 4] {
    if w == 0 || h == 0 || texels.len() < w as usize * h as usize {
        return [1.0; 4];
    }
    let table = srgb_table();
    let (wi, hi) = (w as i32, h as i32);
    let fix = |v: f32| if v.is_finite() { v.clamp(-1e6, 1e6) } else { 0.0 };
    let x = fix(uv[0]) * w as f32;
    let y = fix(uv[1]) * h as f32;
    let texel = |i: i32, j: i32| -> [f32; 4] {
        let i = wrap_index(i, wi, wrap[0]);
        let j = wrap_index(j, hi, wrap[1]);
        let t = texels[j as usize * w as usize + i as usize];
        [table[t[0] as usize], table[t[1] as usize], table[t[2] as usize], t[3] as f32 / 255.0]
    };
    match filter {
        Filter::Nearest => texel(x.floor() as i32, y.floor() as i32),
        Filter::Linear => {
            let (x, y) = (x - 0.5, y - 0.5);
            let (x0, y0) = (x.floor(), y.floor());
            let (fx, fy) = (x - x0, y - y0);
            let (i0, j0) = (x0 as i32, y0 as i32);
            let [a, b, c, d] = [texel(i0, j0), texel(i0 + 1, j0), texel(i0, j0 + 1), texel(i0 + 1, j0 + 1)];
            std::array::from_fn(|k| {
                let top = a[k] + (b[k] - a[k]) * fx;
                let bottom = c[k] + (d[k] - c[k]) * fx;
                top + (bottom - top) * fy
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_ramp_bands() {
        let r = Ramp::thesis_blue();
        assert_eq!(r.eval(-1.0), [0.0, 0.2, 0.4]);
        assert_eq!(r.eval(-0.31), [0.0, 0.2, 0.4]);
        assert_eq!(r.eval(-0.3), [0.5, 0.7, 0.9]);
        assert_eq!(r.eval(-0.01), [0.5, 0.7, 0.9]);
        assert_eq!(r.eval(0.0), [0.9, 0.9, 1.0]);
        assert_eq!(r.eval(1.0), [0.9, 0.9, 1.0]);
        assert_eq!(r.eval(f32::NAN), [0.0, 0.2, 0.4]);
    }

    #[test]
    fn smoothed_bands_are_continuous_and_gradients_interpolate() {
        let r = Ramp { kind: RampKind::Bands { smoothing: 0.1 }, ..Ramp::thesis_blue() };
        let mut prev = r.eval(-1.0);
        for i in 1..=2000 {
            let c = r.eval(-1.0 + i as f32 * 0.001);
            for k in 0..3 {
                assert!((c[k] - prev[k]).abs() < 0.02, "jump at {i}: {prev:?} → {c:?}");
            }
            prev = c;
        }
        assert_eq!(r.eval(-0.3), [0.25, 0.45, 0.65]);
        let g = Ramp { kind: RampKind::Gradient, stops: vec![(-1.0, [0.0; 3]), (1.0, [1.0, 0.5, 0.0])] };
        assert_eq!(g.eval(0.0), [0.5, 0.25, 0.0]);
        assert_eq!(g.eval(5.0), [1.0, 0.5, 0.0]);
        assert_eq!(g.eval(-5.0), [0.0; 3]);
    }

    #[test]
    fn default_wave_ramp_resembles_the_thesis_for_a_blue_wave() {
        let r = Ramp::for_wave_color([0.0, 0.5, 1.0]);
        for (a, b) in r.stops.iter().zip(&Ramp::thesis_blue().stops) {
            assert_eq!(a.0, b.0);
            for k in 0..3 {
                assert!((a.1[k] - b.1[k]).abs() < 0.21, "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn nearest_points() {
        let (a, b) = (Vec3f::ZERO, Vec3f::new(2.0, 0.0, 0.0));
        assert_eq!(nearest_on_segment(Vec3f::new(1.0, 5.0, 0.0), a, b), Vec3f::new(1.0, 0.0, 0.0));
        assert_eq!(nearest_on_segment(Vec3f::new(-3.0, 1.0, 0.0), a, b), a);
        assert_eq!(nearest_on_segment(Vec3f::new(9.0, 1.0, 0.0), a, b), b);
        assert_eq!(nearest_on_segment(Vec3f::new(9.0, 1.0, 0.0), a, a), a);
        let poly = [a, b, Vec3f::new(2.0, 2.0, 0.0)];
        assert_eq!(nearest_on_polyline(Vec3f::new(3.0, 1.5, 0.0), &poly), Vec3f::new(2.0, 1.5, 0.0));
        // The thesis's half-line rule: a ≤ 0 gives C, else C + aD.
        assert_eq!(nearest_on_line(Vec3f::new(1.0, 3.0, 0.0), a, Vec3f::X), Vec3f::X);
    }

    #[test]
    fn m_is_unclamped_dot_and_finite_on_the_light() {
        let p = Vec3f::ZERO;
        assert_eq!(wave_m(p, Vec3f::Y, Vec3f::new(0.0, 2.0, 0.0)), 1.0);
        assert_eq!(wave_m(p, Vec3f::Y, Vec3f::new(0.0, -2.0, 0.0)), -1.0);
        assert!((wave_m(p, Vec3f::Y, Vec3f::new(1.0, -1.0, 0.0)) + 0.70710677).abs() < 1e-6);
        assert_eq!(wave_m(p, Vec3f::Y, p), 1.0);
    }

    #[test]
    fn dominance_is_continuous_and_splits_evenly_at_equal_density() {
        let mut w = [dominance(1.0, 0.0, 1.0, true), dominance(1.0, 0.0, 1.0, true)];
        dominance_weights(&mut w);
        assert_eq!(w, [0.5, 0.5]);
        let mut w = [dominance(1.0, 0.0, 1.0, true), dominance(2.0, 0.0, 1.0, true)];
        dominance_weights(&mut w);
        assert!((w[0] - 16.0 / 17.0).abs() < 1e-6, "{w:?}");
        let mut w = [0.0, 0.0];
        dominance_weights(&mut w);
        assert_eq!(w, [0.0, 0.0]);
        assert!(dominance(0.0, 0.0, 1.0, true).is_finite());
        let mut w = [f32::MAX, f32::MAX, 1.0];
        dominance_weights(&mut w);
        assert_eq!(w[0], 0.5);
    }

    #[test]
    fn sampling_follows_the_stated_convention() {
        // 2×1 image: black, white (sRGB 255 = linear 1).
        let t = [[0, 0, 0, 255], [255, 255, 255, 0]];
        let s = |u: f32, wrap: Wrap, f: Filter| sample(&t, 2, 1, [wrap, Wrap::Clamp], f, [u, 0.5]);
        assert_eq!(s(0.25, Wrap::Clamp, Filter::Linear), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(s(0.75, Wrap::Clamp, Filter::Linear), [1.0, 1.0, 1.0, 0.0]);
        assert_eq!(s(0.5, Wrap::Clamp, Filter::Linear)[0], 0.5);
        assert_eq!(s(0.0, Wrap::Clamp, Filter::Linear)[0], 0.0);
        // Repeat: u = 0 sits between the last and first texel.
        assert_eq!(s(0.0, Wrap::Repeat, Filter::Linear)[0], 0.5);
        assert_eq!(s(1.25, Wrap::Repeat, Filter::Nearest)[0], 0.0);
        assert_eq!(s(1.25, Wrap::Mirror, Filter::Nearest)[0], 1.0);
        assert_eq!(s(f32::NAN, Wrap::Repeat, Filter::Nearest), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(wrap_index(-1, 4, Wrap::Mirror), 0);
        assert_eq!(wrap_index(5, 4, Wrap::Mirror), 2);
        assert!((srgb_table()[128] - 0.2158605).abs() < 1e-6);
    }
}
