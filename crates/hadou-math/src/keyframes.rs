//! Keyframe sampling and rotations for posing animated characters, as glTF 2.0 defines them
//! (§3.11 "Animations" and Appendix C "Interpolation"): node translation, rotation (unit
//! quaternions `[x, y, z, w]`) and scale, and morph-target weights, sampled with STEP, LINEAR
//! (spherical linear interpolation for rotations, along the shorter arc) or CUBICSPLINE (cubic
//! Hermite with the keys' in- and out-tangents scaled by the key interval). Not from the theses:
//! hadou's characters move by the glTF rules, which these functions restate.

use crate::{Mat4, Vec3f};

/// How a sampler interpolates between its keys (glTF `animation.sampler.interpolation`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sampling {
    /// The value of the key at or before `t` (held until the next key).
    Step,
    /// Straight lines between keys; rotations by slerp along the shorter arc.
    Linear,
    /// Cubic Hermite spline; every key stores in-tangent, value, out-tangent.
    CubicSpline,
}

/// Samples a keyframe track at time `t`.
///
/// `times` are the key times (strictly increasing, at least one); `values` hold `width` floats per
/// key (`3·width` per key for [`Sampling::CubicSpline`]: in-tangent `a_k`, value `v_k`, out-tangent
/// `b_k`). Before the first key the first value is held, after the last key the last value
/// (glTF 2.0 §3.11). Between keys `k` and `k+1`, with `t_d = t_{k+1} − t_k` and
/// `s = (t − t_k)/t_d`:
/// - STEP: `v_k`;
/// - LINEAR: `(1 − s)·v_k + s·v_{k+1}`, or for a rotation (`rotation = true`, `width = 4`)
///   `slerp(v_k, v_{k+1}, s)` along the shorter arc;
/// - CUBICSPLINE (Appendix C): `(2s³ − 3s² + 1)·v_k + t_d·(s³ − 2s² + s)·b_k + (−2s³ + 3s²)·v_{k+1}
///   + t_d·(s³ − s²)·a_{k+1}`.
///
/// Rotations come out normalised (a zero quaternion as the identity). A NaN `t` reads as the first
/// key.
pub fn sample(
    sampling: Sampling,
    times: &[f32],
    values: &[f32],
    width: usize,
    rotation: bool,
    t: f32,
    out: &mut [f32],
) {
    let n = times.len();
    let stride = if sampling == Sampling::CubicSpline { 3 * width } else { width };
    let offset = if sampling == Sampling::CubicSpline { width } else { 0 };
    let value = |k: usize| &values[k * stride + offset..k * stride + offset + width];
    let out = &mut out[..width];
    if n == 0 || values.len() < n * stride {
        return;
    }
    if n == 1 || t.is_nan() || t <= times[0] {
        out.copy_from_slice(value(0));
    } else if t >= times[n - 1] {
        out.copy_from_slice(value(n - 1));
    } else {
        let k = times.partition_point(|&x| x <= t).saturating_sub(1).min(n - 2);
        let td = times[k + 1] - times[k];
        let s = if td > 0.0 { ((t - times[k]) / td).clamp(0.0, 1.0) } else { 0.0 };
        match sampling {
            Sampling::Step => out.copy_from_slice(value(k)),
            Sampling::Linear if rotation && width == 4 => {
                let q = slerp(to4(value(k)), to4(value(k + 1)), s);
                out.copy_from_slice(&q);
            }
            Sampling::Linear => {
                for ((o, a), b) in out.iter_mut().zip(value(k)).zip(value(k + 1)) {
                    *o = a + (b - a) * s;
                }
            }
            Sampling::CubicSpline => {
                let (s2, s3) = (s * s, s * s * s);
                let (h00, h10, h01, h11) =
                    (2.0 * s3 - 3.0 * s2 + 1.0, s3 - 2.0 * s2 + s, -2.0 * s3 + 3.0 * s2, s3 - s2);
                let b_k = &values[k * stride + 2 * width..k * stride + 3 * width];
                let a_k1 = &values[(k + 1) * stride..(k + 1) * stride + width];
                for c in 0..width {
                    out[c] =
                        h00 * value(k)[c] + td * h10 * b_k[c] + h01 * value(k + 1)[c] + td * h11 * a_k1[c];
                }
            }
        }
    }
    if rotation && width == 4 {
        let q = normalize_quat(to4(out));
        out.copy_from_slice(&q);
    }
}

fn to4(v: &[f32]) -> [f32; 4] {
    [v[0], v[1], v[2], v[3]]
}

/// `q / |q|`, or the identity rotation `[0, 0, 0, 1]` for a zero or non-finite `q`.
pub fn normalize_quat(q: [f32; 4]) -> [f32; 4] {
    let l = q.iter().map(|c| (*c as f64) * (*c as f64)).sum::<f64>().sqrt();
    if l > 1e-30 && l.is_finite() {
        q.map(|c| (c as f64 / l) as f32)
    } else {
        [0.0, 0.0, 0.0, 1.0]
    }
}

/// Spherical linear interpolation from `a` to `b` at `s ∈ [0, 1]` along the shorter arc: where
/// `a·b < 0`, `−b` (the same rotation) is the end point (glTF 2.0 Appendix C's slerp). Nearly equal
/// rotations interpolate linearly and normalise, which is exact to rounding there.
pub fn slerp(a: [f32; 4], b: [f32; 4], s: f32) -> [f32; 4] {
    let a = normalize_quat(a).map(f64::from);
    let mut b = normalize_quat(b).map(f64::from);
    let s = s as f64;
    let mut d: f64 = (0..4).map(|i| a[i] * b[i]).sum();
    if d < 0.0 {
        b = b.map(|c| -c);
        d = -d;
    }
    let (wa, wb) = if d > 0.9995 {
        (1.0 - s, s)
    } else {
        let theta = d.min(1.0).acos();
        let sin = theta.sin();
        (((1.0 - s) * theta).sin() / sin, (s * theta).sin() / sin)
    };
    normalize_quat([0, 1, 2, 3].map(|i| (wa * a[i] + wb * b[i]) as f32))
}

/// The rotation matrix of the unit quaternion `q = [x, y, z, w]`.
pub fn quat_matrix(q: [f32; 4]) -> Mat4 {
    let [x, y, z, w] = q;
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz, wx, wy, wz) = (x * y, x * z, y * z, w * x, w * y, w * z);
    Mat4 {
        cols: [
            [1.0 - 2.0 * (yy + zz), 2.0 * (xy + wz), 2.0 * (xz - wy), 0.0],
            [2.0 * (xy - wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz + wx), 0.0],
            [2.0 * (xz + wy), 2.0 * (yz - wx), 1.0 - 2.0 * (xx + yy), 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    }
}

/// A glTF node's local matrix `T·R·S` from translation, unit quaternion and scale (glTF 2.0 §3.5.3).
pub fn trs_matrix(t: [f32; 3], r: [f32; 4], s: [f32; 3]) -> Mat4 {
    Mat4::translation(Vec3f::from_array(t))
        * quat_matrix(normalize_quat(r))
        * Mat4::scale(Vec3f::from_array(s))
}

/// The rotation of an affine matrix as a unit quaternion: its 3×3 block with each column
/// normalised (scale removed; a mirroring block loses its reflection first), converted by the
/// largest-diagonal method (Shepperd). A degenerate block gives the identity.
pub fn rotation_of(m: &Mat4) -> [f32; 4] {
    let mut c = [[0.0f64; 3]; 3];
    for (j, col) in c.iter_mut().enumerate() {
        let v = [m.cols[j][0] as f64, m.cols[j][1] as f64, m.cols[j][2] as f64];
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if !(l > 1e-30 && l.is_finite()) {
            return [0.0, 0.0, 0.0, 1.0];
        }
        *col = v.map(|x| x / l);
    }
    let det = c[0][0] * (c[1][1] * c[2][2] - c[2][1] * c[1][2])
        - c[1][0] * (c[0][1] * c[2][2] - c[2][1] * c[0][2])
        + c[2][0] * (c[0][1] * c[1][2] - c[1][1] * c[0][2]);
    if det < 0.0 {
        c[0] = c[0].map(|x| -x);
    }
    // r(row, col) = c[col][row]
    let r = |i: usize, j: usize| c[j][i];
    let tr = r(0, 0) + r(1, 1) + r(2, 2);
    let q = if tr > 0.0 {
        let s = (tr + 1.0).sqrt() * 2.0;
        [(r(2, 1) - r(1, 2)) / s, (r(0, 2) - r(2, 0)) / s, (r(1, 0) - r(0, 1)) / s, 0.25 * s]
    } else if r(0, 0) > r(1, 1) && r(0, 0) > r(2, 2) {
        let s = (1.0 + r(0, 0) - r(1, 1) - r(2, 2)).sqrt() * 2.0;
        [0.25 * s, (r(0, 1) + r(1, 0)) / s, (r(0, 2) + r(2, 0)) / s, (r(2, 1) - r(1, 2)) / s]
    } else if r(1, 1) > r(2, 2) {
        let s = (1.0 + r(1, 1) - r(0, 0) - r(2, 2)).sqrt() * 2.0;
        [(r(0, 1) + r(1, 0)) / s, 0.25 * s, (r(1, 2) + r(2, 1)) / s, (r(0, 2) - r(2, 0)) / s]
    } else {
        let s = (1.0 + r(2, 2) - r(0, 0) - r(1, 1)).sqrt() * 2.0;
        [(r(0, 2) + r(2, 0)) / s, (r(1, 2) + r(2, 1)) / s, 0.25 * s, (r(1, 0) - r(0, 1)) / s]
    };
    normalize_quat(q.map(|x| x as f32))
}

/// The product `a·b` of two quaternions (`[x, y, z, w]`): the rotation `b` followed by `a`.
pub fn quat_mul(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// The inverse rotation of a unit quaternion.
pub fn quat_conjugate(q: [f32; 4]) -> [f32; 4] {
    [-q[0], -q[1], -q[2], q[3]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f32], b: &[f32], tol: f32) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn step_holds_the_earlier_key_and_clamps_outside() {
        let times = [0.0, 1.0, 2.0];
        let values = [0.0, 10.0, 20.0];
        let mut o = [0.0];
        for (t, want) in
            [(-1.0, 0.0), (0.0, 0.0), (0.999, 0.0), (1.0, 10.0), (1.5, 10.0), (2.0, 20.0), (9.0, 20.0)]
        {
            sample(Sampling::Step, &times, &values, 1, false, t, &mut o);
            assert_eq!(o[0], want, "t = {t}");
        }
    }

    #[test]
    fn linear_rotation_takes_the_shorter_arc() {
        // 170° and −170° about z are 20° apart the short way round; their quaternions have a
        // negative dot product, so a plain lerp would swing through 0°.
        let q = |deg: f32| {
            let h = deg.to_radians() / 2.0;
            [0.0, 0.0, h.sin(), h.cos()]
        };
        let values: Vec<f32> = [q(170.0), q(190.0).map(|c| -c)].concat();
        let mut o = [0.0; 4];
        sample(Sampling::Linear, &[0.0, 1.0], &values, 4, true, 0.5, &mut o);
        let angle = 2.0 * o[3].abs().acos().to_degrees();
        assert!((angle - 180.0).abs() < 1e-3, "{angle}° {o:?}");
    }

    #[test]
    fn cubic_with_zero_tangents_is_a_smoothstep() {
        // keys: (a, v, b) per key
        let values = [0.0, 1.0, 0.0, 0.0, 3.0, 0.0];
        let mut o = [0.0];
        for s in [0.0f32, 0.25, 0.5, 0.9] {
            sample(Sampling::CubicSpline, &[1.0, 3.0], &values, 1, false, 1.0 + 2.0 * s, &mut o);
            let want = 1.0 + 2.0 * (3.0 * s * s - 2.0 * s * s * s);
            assert!((o[0] - want).abs() < 1e-5, "{s}: {} vs {want}", o[0]);
        }
        // The out-tangent is scaled by the key interval: slope b at the start.
        let values = [0.0, 0.0, 5.0, 0.0, 0.0, 0.0];
        sample(Sampling::CubicSpline, &[0.0, 2.0], &values, 1, false, 1e-3, &mut o);
        assert!((o[0] / 1e-3 - 5.0).abs() < 0.05, "{}", o[0]);
    }

    #[test]
    fn quaternion_matrix_turns_x_to_y_about_z() {
        let h = std::f32::consts::FRAC_PI_4;
        let m = quat_matrix([0.0, 0.0, h.sin(), h.cos()]);
        let v = m.transform_vector(Vec3f::X);
        assert!(close(&v.to_array(), &[0.0, 1.0, 0.0], 1e-6), "{v:?}");
        let q = quat_mul([0.0, 0.0, h.sin(), h.cos()], quat_conjugate([0.0, 0.0, h.sin(), h.cos()]));
        assert!(close(&q, &[0.0, 0.0, 0.0, 1.0], 1e-6));
        assert_eq!(normalize_quat([0.0; 4]), [0.0, 0.0, 0.0, 1.0]);
        // rotation_of inverts quat_matrix (up to sign), also under a scale, for every branch.
        for q in
            [[0.3f32, -0.5, 0.1, 0.8], [0.9, 0.1, 0.2, 0.1], [0.1, 0.9, -0.2, 0.1], [0.1, 0.2, 0.95, 0.05]]
        {
            let q = normalize_quat(q);
            let m = quat_matrix(q) * Mat4::scale(Vec3f::new(2.0, 0.5, 3.0));
            let r = rotation_of(&m);
            let d: f32 = (0..4).map(|i| q[i] * r[i]).sum();
            assert!(d.abs() > 1.0 - 1e-5, "{q:?} vs {r:?}");
        }
        assert_eq!(normalize_quat([f32::NAN, 0.0, 0.0, 1.0]), [0.0, 0.0, 0.0, 1.0]);
    }
}
