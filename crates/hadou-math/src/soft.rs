//! The maths of 003's soft shadows (SPEC.md §4): the two shadow-map positions, the penumbra's
//! brightness from the distances to the nearest umbra and lit pixels (with SPEC's corrected
//! ratio), standard bilinear interpolation of a coarse grid (SPEC's corrected weights), and the
//! exact Euclidean distance transform that gives every pixel those distances in linear time.

use crate::Vec3f;

/// The two shadow-map positions of 003 §4.1: with `P = (L − G)/|L − G|` (unit, from the point of
/// interest `G` towards the light centre `L`), `L₁ = L + l·P` and `L₂ = L − l·P`. `None` when
/// `L = G` (no direction).
pub fn light_pair(light: Vec3f, interest: Vec3f, l: f32) -> Option<(Vec3f, Vec3f)> {
    let p = (light - interest).try_normalize()?;
    Some((light + p * l, light - p * l))
}

/// A penumbra pixel's brightness from its distance `d1` to the nearest umbra pixel and `d2` to the
/// nearest lit pixel (SPEC.md §4.2): `d1 / (d1 + d2)`, 0 at the umbra's edge and 1 at the lit
/// edge. *Correction:* 003 prints `D₂/(D₁+D₂)`, which contradicts its own statement that pixels
/// near the umbra are darker. Both distances 0 (or not finite) give ½, never NaN.
#[inline]
pub fn penumbra_brightness(d1: f32, d2: f32) -> f32 {
    let s = d1 + d2;
    if s > 0.0 && s.is_finite() {
        (d1 / s).clamp(0.0, 1.0)
    } else if d1.is_infinite() && !d2.is_infinite() {
        1.0
    } else if d2.is_infinite() && !d1.is_infinite() {
        0.0
    } else {
        0.5
    }
}

/// Standard bilinear interpolation of the four grid values around a pixel (SPEC.md §4.3), `fx`,
/// `fy ∈ [0, 1]` its offsets from the top-left grid pixel in grid cells:
/// `(1−fx)(1−fy)·v00 + fx(1−fy)·v10 + (1−fx)fy·v01 + fx·fy·v11`. *Correction:* 003's eq. 3.6 gives
/// the first corner the weight `Q·dx` where bilinear interpolation has `1 − Q·dx`.
#[inline]
pub fn bilinear(v00: f32, v10: f32, v01: f32, v11: f32, fx: f32, fy: f32) -> f32 {
    let top = v00 + (v10 - v00) * fx;
    let bottom = v01 + (v11 - v01) * fx;
    top + (bottom - top) * fy
}

/// Squared distance standing for "no feature pixel at all" in [`distance_transform`].
pub const FAR: f32 = f32::INFINITY;

/// The exact squared Euclidean distance transform of a `width × height` image (row-major): for
/// every pixel, the squared distance in pixels to the nearest pixel where `feature` is true, or
/// [`FAR`] if there is none. Felzenszwalb and Huttenlocher's separable lower-envelope algorithm
/// (2012): one pass over columns, one over rows, `O(width · height)`. The envelope is computed in
/// `f64`; the results are integers, exact in `f32` up to 2²⁴ (a distance of 4096 pixels).
pub fn distance_transform(feature: &[bool], width: usize, height: usize) -> Vec<f32> {
    assert_eq!(feature.len(), width * height, "mask size");
    let mut d: Vec<f32> = feature.iter().map(|&f| if f { 0.0 } else { FAR }).collect();
    let n = width.max(height);
    let mut scratch = Envelope::new(n);
    let mut line = vec![0.0f32; n];
    let mut out = vec![0.0f32; n];
    // Columns.
    for x in 0..width {
        for y in 0..height {
            line[y] = d[y * width + x];
        }
        scratch.transform(&line[..height], &mut out[..height]);
        for y in 0..height {
            d[y * width + x] = out[y];
        }
    }
    // Rows.
    for y in 0..height {
        let row = &mut d[y * width..(y + 1) * width];
        line[..width].copy_from_slice(row);
        scratch.transform(&line[..width], &mut out[..width]);
        row.copy_from_slice(&out[..width]);
    }
    d
}

/// Work space of the 1-D transform: the parabolas of the lower envelope and their boundaries.
struct Envelope {
    v: Vec<usize>,
    z: Vec<f64>,
}

impl Envelope {
    fn new(n: usize) -> Self {
        Envelope { v: vec![0; n.max(1)], z: vec![0.0; n.max(1) + 1] }
    }

    /// `out[q] = min_p (q − p)² + f[p]` over `p` with finite `f[p]` ([`FAR`] if none).
    fn transform(&mut self, f: &[f32], out: &mut [f32]) {
        let n = f.len();
        let mut k: usize = 0;
        let mut any = false;
        for q in 0..n {
            if f[q] == FAR {
                continue;
            }
            if !any {
                any = true;
                self.v[0] = q;
                self.z[0] = f64::NEG_INFINITY;
                self.z[1] = f64::INFINITY;
                k = 0;
                continue;
            }
            // Drop the envelope's parabolas the one at q hides (z[0] = −∞ stops the loop at the first).
            let fq = f64::from(f[q]) + (q * q) as f64;
            let mut s;
            loop {
                let p = self.v[k];
                s = (fq - (f64::from(f[p]) + (p * p) as f64)) / (2.0 * (q - p) as f64);
                if s <= self.z[k] {
                    k -= 1;
                } else {
                    break;
                }
            }
            k += 1;
            self.v[k] = q;
            self.z[k] = s;
            self.z[k + 1] = f64::INFINITY;
        }
        if !any {
            out.iter_mut().for_each(|o| *o = FAR);
            return;
        }
        let mut j = 0;
        for (q, o) in out.iter_mut().enumerate() {
            while self.z[j + 1] < q as f64 {
                j += 1;
            }
            let p = self.v[j];
            let dq = q as f32 - p as f32;
            *o = dq * dq + f[p];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: the nearest feature pixel by trying them all.
    fn brute(feature: &[bool], w: usize, h: usize) -> Vec<f32> {
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                feature
                    .iter()
                    .enumerate()
                    .filter(|(_, &f)| f)
                    .map(|(j, _)| {
                        let (u, v) = ((j % w) as i64, (j / w) as i64);
                        ((x - u).pow(2) + (y - v).pow(2)) as f32
                    })
                    .fold(FAR, f32::min)
            })
            .collect()
    }

    #[test]
    fn distance_transform_is_exact_on_random_masks() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for case in 0..60 {
            let (w, h) = (1 + (next() % 23) as usize, 1 + (next() % 19) as usize);
            let density = [1u64, 5, 30, 90][case % 4];
            let mask: Vec<bool> = (0..w * h).map(|_| next() % 100 < density).collect();
            assert_eq!(distance_transform(&mask, w, h), brute(&mask, w, h), "case {case}: {w}×{h}");
        }
    }

    #[test]
    fn empty_and_full_masks() {
        assert!(distance_transform(&[false; 12], 4, 3).iter().all(|&d| d == FAR));
        assert!(distance_transform(&[true; 12], 4, 3).iter().all(|&d| d == 0.0));
    }

    #[test]
    fn brightness_runs_dark_to_light_and_never_nan() {
        assert_eq!(penumbra_brightness(0.0, 5.0), 0.0);
        assert_eq!(penumbra_brightness(5.0, 0.0), 1.0);
        assert_eq!(penumbra_brightness(1.0, 3.0), 0.25);
        assert_eq!(penumbra_brightness(0.0, 0.0), 0.5);
        assert_eq!(penumbra_brightness(f32::INFINITY, 2.0), 1.0);
        assert_eq!(penumbra_brightness(2.0, f32::INFINITY), 0.0);
        assert_eq!(penumbra_brightness(f32::INFINITY, f32::INFINITY), 0.5);
    }

    #[test]
    fn bilinear_weights_are_the_standard_ones() {
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 0.0, 0.0), 1.0);
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 1.0, 0.0), 2.0);
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 0.0, 1.0), 3.0);
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 1.0, 1.0), 4.0);
        assert_eq!(bilinear(0.0, 4.0, 0.0, 4.0, 0.25, 0.7), 1.0);
    }

    #[test]
    fn light_pair_straddles_the_light_along_g_to_l() {
        let (l1, l2) = light_pair(Vec3f::new(0.0, 4.0, 0.0), Vec3f::ZERO, 0.5).unwrap();
        assert_eq!(l1, Vec3f::new(0.0, 4.5, 0.0));
        assert_eq!(l2, Vec3f::new(0.0, 3.5, 0.0));
        assert!(light_pair(Vec3f::ZERO, Vec3f::ZERO, 1.0).is_none());
    }
}
