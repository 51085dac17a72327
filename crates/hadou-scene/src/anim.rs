//! Keyframe tracks (002 §3.3.4: parameters change at any time, with no precomputation).
//!
//! A track writes one parameter slice (a whole vector, one component, one control point …) of the
//! scene's value store. Before the first key it holds the first key's value, after the last key the
//! last key's value.

/// How values between two keys are found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Interpolation {
    /// Straight lines between keys: exact at keys, continuous, kinks at keys.
    #[default]
    Linear,
    /// Cubic Hermite with Catmull-Rom tangents for uneven key spacing: the tangent at an inner key
    /// is `(v[i+1] − v[i−1]) / (t[i+1] − t[i−1])`, at the first and last keys the one-sided
    /// difference. Passes through every key with a continuous first derivative (C1); may overshoot
    /// between keys (the scene clamps the result into the parameter's valid range).
    Smooth,
}

/// One animation track, resolved to a slice of the value store.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Track {
    /// The target as written (`wave.beam.M2.z`).
    pub target: String,
    /// Start of the slice in the value store.
    pub offset: usize,
    /// Floats per key value.
    pub len: usize,
    /// Interpolation.
    pub interpolation: Interpolation,
    /// Key times in seconds, strictly increasing, at least one.
    pub times: Vec<f32>,
    /// Key values, `len` floats per key, concatenated.
    pub values: Vec<f32>,
}

impl Track {
    /// The value at time `t` written into `out` (`len` floats).
    pub(crate) fn eval(&self, t: f32, out: &mut [f32]) {
        let n = self.times.len();
        let len = self.len;
        let key = |i: usize| &self.values[i * len..(i + 1) * len];
        if n == 0 {
            return;
        }
        if n == 1 || t.is_nan() || t <= self.times[0] {
            out.copy_from_slice(key(0));
            return;
        }
        if t >= self.times[n - 1] {
            out.copy_from_slice(key(n - 1));
            return;
        }
        // The segment [t_i, t_{i+1}] holding t.
        let i = self.times.partition_point(|&k| k <= t).saturating_sub(1).min(n - 2);
        let (t0, t1) = (self.times[i], self.times[i + 1]);
        let h = t1 - t0;
        let s = ((t - t0) / h).clamp(0.0, 1.0);
        match self.interpolation {
            Interpolation::Linear => {
                for (c, o) in out.iter_mut().enumerate() {
                    let (a, b) = (key(i)[c], key(i + 1)[c]);
                    *o = a + (b - a) * s;
                }
            }
            Interpolation::Smooth => {
                let (s2, s3) = (s * s, s * s * s);
                let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
                let h10 = s3 - 2.0 * s2 + s;
                let h01 = -2.0 * s3 + 3.0 * s2;
                let h11 = s3 - s2;
                for (c, o) in out.iter_mut().enumerate() {
                    let m0 = self.tangent(i, c);
                    let m1 = self.tangent(i + 1, c);
                    *o = h00 * key(i)[c] + h10 * h * m0 + h01 * key(i + 1)[c] + h11 * h * m1;
                }
            }
        }
    }

    /// Catmull-Rom tangent (per second) of component `c` at key `i`.
    fn tangent(&self, i: usize, c: usize) -> f32 {
        let n = self.times.len();
        let v = |k: usize| self.values[k * self.len + c];
        let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
        let dt = self.times[b] - self.times[a];
        if dt > 0.0 {
            (v(b) - v(a)) / dt
        } else {
            0.0
        }
    }

    /// Time of the last key.
    pub(crate) fn end(&self) -> f32 {
        self.times.last().copied().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(interpolation: Interpolation) -> Track {
        Track {
            target: "x".into(),
            offset: 0,
            len: 1,
            interpolation,
            times: vec![0.0, 1.0, 3.0],
            values: vec![0.0, 2.0, 1.0],
        }
    }

    fn at(t: &Track, time: f32) -> f32 {
        let mut o = [0.0];
        t.eval(time, &mut o);
        o[0]
    }

    #[test]
    fn smooth_tangent_matches_catmull_rom() {
        let t = track(Interpolation::Smooth);
        // inner key: (1 − 0) / (3 − 0)
        assert!((t.tangent(1, 0) - 1.0 / 3.0).abs() < 1e-6);
        // ends: one-sided
        assert!((t.tangent(0, 0) - 2.0).abs() < 1e-6);
        assert!((t.tangent(2, 0) + 0.5).abs() < 1e-6);
        let e = 1e-3;
        let slope = (at(&t, 1.0 + e) - at(&t, 1.0 - e)) / (2.0 * e);
        assert!((slope - 1.0 / 3.0).abs() < 1e-2, "{slope}");
    }
}
