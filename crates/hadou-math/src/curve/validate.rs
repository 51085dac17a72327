//! Validation of a [`CurveWave`] (each error names the scene-file key and the fix) and the
//! sanitizing that lets [`prepare`](fn@super::prepare) accept any value without panicking.

use super::shape::clamped_uniform_knots;
use super::wave::{
    CurveShape, CurveWave, Integrator, MAX_BEZIER_POINTS, MAX_BSPLINE_POINTS, MAX_ORDER, MAX_SIMPSON_M,
    MAX_TRIG_TERMS,
};
use crate::Vec3;
use core::fmt;

/// A curved wave's invalid parameter: the scene-file key it came from and what would be right.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CurveError {
    /// The scene-file key, e.g. `"knots"`, `"order"`, `"points"`, `"m"`, `"n"`, `"attenuation"`,
    /// `"extension"`, `"radius"`, `"axis"`, `"up"`, `"gamma"`.
    pub field: &'static str,
    /// What is wrong and how to fix it.
    pub message: String,
}

impl fmt::Display for CurveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.message)
    }
}

impl std::error::Error for CurveError {}

fn err(field: &'static str, message: impl Into<String>) -> Result<(), CurveError> {
    Err(CurveError { field, message: message.into() })
}

fn finite(field: &'static str, v: f32) -> Result<(), CurveError> {
    if v.is_finite() {
        Ok(())
    } else {
        err(field, format!("must be a finite number, got {v}"))
    }
}

fn finite_vec(field: &'static str, v: Vec3<f32>) -> Result<(), CurveError> {
    if v.is_finite() {
        Ok(())
    } else {
        err(field, format!("must have finite components, got [{}, {}, {}]", v.x, v.y, v.z))
    }
}

fn finite_points(field: &'static str, p: &[[f32; 2]]) -> Result<(), CurveError> {
    match p.iter().position(|q| !(q[0].is_finite() && q[1].is_finite())) {
        Some(i) => err(field, format!("entry {i} is not finite: [{}, {}]", p[i][0], p[i][1])),
        None => Ok(()),
    }
}

fn positive_length(v: f32) -> Result<(), CurveError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        err("length", format!("must be a finite number > 0, got {v}"))
    }
}

impl CurveWave {
    /// Checks every parameter; the error names the scene-file key and says what would be right.
    ///
    /// Rejected: non-finite values anywhere; a zero axis or an `up` parallel to it; `γ ≤ 0`;
    /// extension `k ∉ (0, 1]`; attenuation `j < 0`; a negative helix radius; `length ≤ 0`;
    /// a Bézier curve with fewer than 2 or more than [`MAX_BEZIER_POINTS`] control points; a
    /// B-spline whose order is outside `2 ≤ k ≤ min(n + 1, MAX_ORDER)` (fewer control points than
    /// `k = degree + 1`), whose knot vector does not have `n + k + 1` entries, decreases, or has an
    /// empty valid range `[x_{k−1}, x_{n+1}]`; Simpson `m` odd, zero or above
    /// [`MAX_SIMPSON_M`]; reduction `n < 1` or `ε < 0`.
    ///
    /// Legal although degenerate (they render finite values): coincident control points, radius 0,
    /// empty trigonometric sums.
    pub fn validate(&self) -> Result<(), CurveError> {
        finite_vec("origin", self.frame.origin)?;
        finite_vec("axis", self.frame.axis)?;
        finite_vec("up", self.frame.up)?;
        if self.frame.axis.try_normalize().is_none() {
            return err("axis", "must be a non-zero vector (the wave's travel direction)");
        }
        if self.frame.axes().is_none() {
            return err(
                "up",
                "must be non-zero and not parallel to `axis`; pick any direction across the wave",
            );
        }
        if !(self.gamma.is_finite() && self.gamma > 0.0) {
            return err("gamma", format!("axial stretch must be a finite number > 0, got {}", self.gamma));
        }
        if !(self.extension.is_finite() && self.extension > 0.0 && self.extension <= 1.0) {
            return err(
                "extension",
                format!("must lie in (0, 1] (1 = fully extended), got {}", self.extension),
            );
        }
        if !(self.attenuation.is_finite() && self.attenuation >= 0.0) {
            return err(
                "attenuation",
                format!("exponent j must be a finite number ≥ 0 (0 = none), got {}", self.attenuation),
            );
        }
        finite("alpha", self.alpha)?;
        self.validate_shape()?;
        if let Integrator::Simpson { m, reduction } = self.integrator {
            if m == 0 || m % 2 == 1 || m > MAX_SIMPSON_M {
                return err(
                    "m",
                    format!("Simpson needs an even number of subintervals in 2..={MAX_SIMPSON_M}, got {m}"),
                );
            }
            if let Some(r) = reduction {
                if r.n < 1 {
                    return err("n", "reduction factor must be ≥ 1 (1 = no reduction)");
                }
                if !(r.epsilon.is_finite() && r.epsilon >= 0.0) {
                    return err(
                        "epsilon",
                        format!("bounding-cylinder offset must be finite and ≥ 0, got {}", r.epsilon),
                    );
                }
            }
        }
        Ok(())
    }

    fn validate_shape(&self) -> Result<(), CurveError> {
        match &self.shape {
            CurveShape::Helix { radius, rate, phase, length } => {
                finite("radius", *radius)?;
                if *radius < 0.0 {
                    return err("radius", format!("must be ≥ 0, got {radius}"));
                }
                finite("rate", *rate)?;
                finite("phase", *phase)?;
                positive_length(*length)
            }
            CurveShape::TrigSum { rate, y_terms, z_terms, length } => {
                finite("rate", *rate)?;
                for (field, terms) in [("y_terms", y_terms), ("z_terms", z_terms)] {
                    finite_points(field, terms)?;
                    if terms.len() > MAX_TRIG_TERMS {
                        return err(field, format!("at most {MAX_TRIG_TERMS} terms, got {}", terms.len()));
                    }
                }
                positive_length(*length)
            }
            CurveShape::Bezier { points } => {
                finite_points("points", points)?;
                if points.len() < 2 {
                    return err(
                        "points",
                        format!(
                            "a Bézier curve needs at least 2 control points (degree ≥ 1), got {}",
                            points.len()
                        ),
                    );
                }
                if points.len() > MAX_BEZIER_POINTS {
                    return err(
                        "points",
                        format!(
                            "at most {MAX_BEZIER_POINTS} control points (degree 63), got {}; use a B-spline",
                            points.len()
                        ),
                    );
                }
                Ok(())
            }
            CurveShape::BSpline { points, order, knots } => {
                finite_points("points", points)?;
                let count = points.len();
                let k = *order as usize;
                if !(2..=MAX_ORDER).contains(&k) {
                    return err(
                        "order",
                        format!("must lie in 2..={MAX_ORDER} (2 = polyline, 4 = cubic), got {order}"),
                    );
                }
                if count < k {
                    return err("points", format!("a B-spline of order {k} needs at least {k} control points (degree + 1), got {count}"));
                }
                if count > MAX_BSPLINE_POINTS {
                    return err(
                        "points",
                        format!("at most {MAX_BSPLINE_POINTS} control points, got {count}"),
                    );
                }
                if let Some(knots) = knots {
                    let want = count + k;
                    if knots.len() != want {
                        return err("knots", format!("need n + k + 1 = {want} values for {count} points of order {k}, got {}; or omit `knots` for clamped uniform", knots.len()));
                    }
                    if let Some(i) = knots.iter().position(|x| !x.is_finite()) {
                        return err("knots", format!("entry {i} is not finite"));
                    }
                    if let Some(i) = knots.windows(2).position(|w| w[1] < w[0]) {
                        return err(
                            "knots",
                            format!(
                                "must be non-decreasing, but entry {} ({}) < entry {i} ({})",
                                i + 1,
                                knots[i + 1],
                                knots[i]
                            ),
                        );
                    }
                    if knots[k - 1] >= knots[count] {
                        return err(
                            "knots",
                            format!(
                                "the valid range [knot {}, knot {count}] is empty; spread the interior knots",
                                k - 1
                            ),
                        );
                    }
                }
                Ok(())
            }
        }
    }
}

fn fin(v: f32, fallback: f32) -> f32 {
    if v.is_finite() {
        v
    } else {
        fallback
    }
}

fn fin_points(p: &[[f32; 2]]) -> Vec<[f32; 2]> {
    p.iter().map(|q| [fin(q[0], 0.0), fin(q[1], 0.0)]).collect()
}

/// A copy of `w` with every invalid value replaced by the nearest legal one (non-finite numbers
/// by 0 or 1, out-of-range scalars clamped, a bad axis or up vector by `x` / `y`, bad B-spline
/// knots by the clamped uniform vector, a too-short point list padded), so that preparing and
/// integrating never panic whatever the input. Valid waves come back unchanged.
pub(crate) fn sanitize(w: &CurveWave) -> CurveWave {
    let mut w = w.clone();
    let v = |v: Vec3<f32>, fb: Vec3<f32>| if v.is_finite() { v } else { fb };
    w.frame.origin = v(w.frame.origin, Vec3::ZERO);
    w.frame.axis = v(w.frame.axis, Vec3::X);
    if w.frame.axis.try_normalize().is_none() {
        w.frame.axis = Vec3::X;
    }
    w.frame.up = v(w.frame.up, Vec3::Y);
    if w.frame.axes().is_none() {
        let d = w.frame.axis.try_normalize().unwrap_or(Vec3::X);
        w.frame.up = d.orthonormal_basis().0;
    }
    w.gamma = if w.gamma.is_finite() && w.gamma > 0.0 { w.gamma.max(1e-6) } else { 1.0 };
    w.extension = if w.extension.is_finite() { w.extension.clamp(1e-6, 1.0) } else { 1.0 };
    w.attenuation = if w.attenuation.is_finite() { w.attenuation.max(0.0) } else { 0.0 };
    w.alpha = fin(w.alpha, 0.0);
    let len = |l: f32| if l.is_finite() && l > 0.0 { l } else { 1.0 };
    w.shape = match &w.shape {
        CurveShape::Helix { radius, rate, phase, length } => CurveShape::Helix {
            radius: fin(*radius, 0.0).abs(),
            rate: fin(*rate, 0.0),
            phase: fin(*phase, 0.0),
            length: len(*length),
        },
        CurveShape::TrigSum { rate, y_terms, z_terms, length } => {
            let cap = |t: &[[f32; 2]]| fin_points(&t[..t.len().min(MAX_TRIG_TERMS)]);
            CurveShape::TrigSum {
                rate: fin(*rate, 0.0),
                y_terms: cap(y_terms),
                z_terms: cap(z_terms),
                length: len(*length),
            }
        }
        CurveShape::Bezier { points } => {
            let mut p = fin_points(&points[..points.len().min(MAX_BEZIER_POINTS)]);
            while p.len() < 2 {
                p.push(p.last().copied().unwrap_or([0.0, 0.0]));
            }
            CurveShape::Bezier { points: p }
        }
        CurveShape::BSpline { points, order, knots } => {
            let mut p = fin_points(&points[..points.len().min(MAX_BSPLINE_POINTS)]);
            let k = (*order as usize).clamp(2, MAX_ORDER);
            while p.len() < k {
                p.push(p.last().copied().unwrap_or([0.0, 0.0]));
            }
            let good = knots.as_ref().is_some_and(|kn| {
                kn.len() == p.len() + k
                    && kn.iter().all(|x| x.is_finite())
                    && kn.windows(2).all(|w| w[0] <= w[1])
                    && kn[k - 1] < kn[p.len()]
            });
            let knots = if good {
                knots.clone()
            } else if knots.is_some() {
                Some(clamped_uniform_knots(p.len(), k).into_iter().map(|x| x as f32).collect())
            } else {
                None
            };
            CurveShape::BSpline { points: p, order: k as u32, knots }
        }
    };
    if let Integrator::Simpson { m, reduction } = &mut w.integrator {
        *m = (*m).clamp(2, MAX_SIMPSON_M);
        *m += *m & 1;
        if let Some(r) = reduction {
            r.n = r.n.max(1);
            r.epsilon = if r.epsilon.is_finite() { r.epsilon.max(0.0) } else { 0.0 };
        }
    }
    w
}
