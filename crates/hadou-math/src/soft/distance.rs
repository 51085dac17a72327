//! The exact squared Euclidean distance transform (Felzenszwalb and Huttenlocher 2012) that gives
//! every penumbra pixel its distances to the nearest umbra and lit pixels (003 §4.3, SPEC.md §4.3).

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
    let mut arg = vec![0u32; n];
    // Columns.
    for x in 0..width {
        for y in 0..height {
            line[y] = d[y * width + x];
        }
        scratch.transform(&line[..height], &mut out[..height], &mut arg[..height]);
        for y in 0..height {
            d[y * width + x] = out[y];
        }
    }
    // Rows.
    for y in 0..height {
        let row = &mut d[y * width..(y + 1) * width];
        line[..width].copy_from_slice(row);
        scratch.transform(&line[..width], &mut out[..width], &mut arg[..width]);
        row.copy_from_slice(&out[..width]);
    }
    d
}

/// Work space of the 1-D squared distance transform (Felzenszwalb–Huttenlocher): the parabolas of
/// the lower envelope and their boundaries. One per thread; [`Envelope::transform`] is the step
/// both passes of [`distance_transform`] make, public so a renderer can run the lines in parallel.
///
/// The boundaries are kept as exact fractions `num/den` (`den > 0`; `den = 0` stands for `±∞` by
/// the sign of `num`) and compared by cross-multiplying in `i64`: no division, no rounding, so the
/// envelope is exact for integer inputs.
#[derive(Clone, Debug)]
pub struct Envelope {
    v: Vec<usize>,
    z: Vec<(i64, i64)>,
}

/// `a/b ≤ c/d` for fractions with `b, d ≥ 0` (`0` denominators are `±∞` by the numerator's sign).
#[inline]
fn frac_le(a: i64, b: i64, c: i64, d: i64) -> bool {
    match (b, d) {
        (0, 0) => a <= c,
        (0, _) => a < 0,
        (_, 0) => c > 0,
        _ => a * d <= c * b,
    }
}

impl Envelope {
    /// Work space for lines of up to `n` samples.
    pub fn new(n: usize) -> Self {
        Envelope { v: vec![0; n.max(1)], z: vec![(0, 1); n.max(1) + 1] }
    }

    /// `out[q] = min_p (q − p)² + f[p]` over `p` with `f[p] ≠` [`FAR`] ([`FAR`] if none), and
    /// `arg[q]` = that `p` (the lowest-index parabola of the envelope at `q`; `u32::MAX` if none).
    /// The finite `f[p]` must be integers (squared distances in pixels), below 2⁴⁰. Lines longer
    /// than [`Envelope::new`]'s `n` grow the work space.
    pub fn transform(&mut self, f: &[f32], out: &mut [f32], arg: &mut [u32]) {
        let n = f.len();
        if self.v.len() < n {
            *self = Envelope::new(n);
        }
        let mut k: usize = 0;
        let mut any = false;
        for q in 0..n {
            if f[q] == FAR {
                continue;
            }
            if !any {
                any = true;
                self.v[0] = q;
                self.z[0] = (-1, 0);
                self.z[1] = (1, 0);
                k = 0;
                continue;
            }
            // Drop the envelope's parabolas the one at q hides (z[0] = −∞ stops the loop at the
            // first). The parabolas from p and q meet at s = (F_q − F_p) / (2(q − p)), F = f + x².
            let fq = f[q] as i64 + (q * q) as i64;
            let (mut sn, mut sd);
            loop {
                let p = self.v[k];
                sn = fq - (f[p] as i64 + (p * p) as i64);
                sd = 2 * (q - p) as i64;
                let (zn, zd) = self.z[k];
                if frac_le(sn, sd, zn, zd) {
                    k -= 1;
                } else {
                    break;
                }
            }
            k += 1;
            self.v[k] = q;
            self.z[k] = (sn, sd);
            self.z[k + 1] = (1, 0);
        }
        if !any {
            out.iter_mut().for_each(|o| *o = FAR);
            arg.iter_mut().for_each(|a| *a = u32::MAX);
            return;
        }
        let mut j = 0;
        for (q, (o, a)) in out.iter_mut().zip(arg.iter_mut()).enumerate() {
            // z[j + 1] < q.
            while {
                let (zn, zd) = self.z[j + 1];
                !frac_le(q as i64, 1, zn, zd)
            } {
                j += 1;
            }
            let p = self.v[j];
            let dq = q as f32 - p as f32;
            *o = dq * dq + f[p];
            *a = p as u32;
        }
    }
}
