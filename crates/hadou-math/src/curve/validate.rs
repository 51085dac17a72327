//! Validation of a [`CurveWave`] (each error names the scene-file key and the fix) and the
//! sanitizing that lets [`prepare`](fn@super::prepare) accept any value without panicking.

use super::shape::clamped_uniform_knots;
use super::wave::{
    CurveShape, CurveWave, Integrator, MAX_BEZIER_POINTS, MAX_BSPLINE_POINTS, MAX_ORDER, MAX_SIMPSON_M,
    MAX_SLOPE, MAX_TRIG_TERMS, MAX_TURNS,
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

/// `x` to about four significant digits: plain between `1e-3` and `1e5`, scientific otherwise
/// (`175`, `0.5`, `1.751e6`, `8.042e13`).
fn short(x: f64) -> String {
    let sci = format!("{x:.3e}");
    let (mantissa, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
    let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
    let sci = format!("{mantissa}e{exp}");
    match sci.parse::<f64>() {
        Ok(v) if v == 0.0 || (1e-3..1e5).contains(&v.abs()) => format!("{v}"),
        _ => sci,
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
    /// [`MAX_SIMPSON_M`]; reduction `n < 1` or `ε < 0`. And the bounds on a ray's work
    /// (`cost.rs`): a helix or trigonometric sum making more than [`MAX_TURNS`] turns
    /// ([`CurveWave::turns`]); a curve steeper than [`MAX_SLOPE`] ([`CurveWave::steepness`]; a
    /// B-spline that jumps at an interior knot repeated `order` times is infinitely steep);
    /// Simpson `m` above [`CurveWave::max_simpson_m`] (`m × point cost ≤ MAX_SIMPSON_M`).
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
        self.validate_cost()
    }

    /// The bounds on a ray's work (`cost.rs`), on a wave whose values are otherwise valid.
    fn validate_cost(&self) -> Result<(), CurveError> {
        if let Some(turns) = self.turns() {
            if turns > MAX_TURNS {
                let what = match &self.shape {
                    CurveShape::TrigSum { y_terms, z_terms, .. } => format!(
                        "makes the fastest harmonic (term {}) turn {} times over `length` \
                         (terms × |rate| × length / 2π)",
                        y_terms.len().max(z_terms.len()),
                        short(turns)
                    ),
                    _ => format!(
                        "makes the helix turn {} times over `length` (|rate| × length / 2π)",
                        short(turns)
                    ),
                };
                return err(
                    "rate",
                    format!(
                        "{what}; at most {MAX_TURNS} turns, since the work of a ray grows with the turns it \
                         passes: lower `rate` or `length`"
                    ),
                );
            }
        }
        let slope = self.steepness();
        if !(slope <= MAX_SLOPE) {
            let points_fix = "raise `gamma` or bring the control points closer together";
            let (field, formula, fix) = match &self.shape {
                CurveShape::Helix { .. } => {
                    ("gamma", "radius × |rate| / gamma", "raise `gamma` or lower `radius` or `rate`")
                }
                CurveShape::TrigSum { .. } => (
                    "gamma",
                    "Σ n × |rate| × |coefficients| / gamma",
                    "raise `gamma` or lower `rate` or the coefficients",
                ),
                CurveShape::Bezier { .. } => {
                    ("gamma", "degree × the longest step between control points / gamma", points_fix)
                }
                CurveShape::BSpline { points, order, knots } => {
                    let formula = "the derivative's largest control point × the knot range / gamma";
                    if slope.is_infinite() {
                        return err(
                            "knots",
                            "repeat an interior knot `order` times, which makes the B-spline jump across its \
                             axis; repeat an interior knot at most `order` − 1 times",
                        );
                    }
                    let uniform = CurveWave {
                        shape: CurveShape::BSpline { points: points.clone(), order: *order, knots: None },
                        ..self.clone()
                    };
                    if knots.is_some() && uniform.steepness() <= MAX_SLOPE {
                        (
                            "knots",
                            formula,
                            "the knots crowd the change of the control points into too short a stretch; \
                             spread them out",
                        )
                    } else {
                        ("gamma", formula, points_fix)
                    }
                }
            };
            return err(
                field,
                format!(
                    "leaves the curve too steep: it moves {} across its axis per unit of travel along it \
                     ({formula}); at most {} keeps the integrator's arithmetic finite: {fix}",
                    short(slope),
                    short(MAX_SLOPE)
                ),
            );
        }
        if let Integrator::Simpson { m, .. } = self.integrator {
            let max = self.max_simpson_m();
            if m > max {
                let cost = short(self.point_cost());
                return err(
                    "m",
                    format!(
                        "must be at most {max} for this curve, got {m}: Simpson evaluates the curve m + 1 times \
                         per ray, one point of it costs {cost} helix points, and m × {cost} may be at most \
                         {MAX_SIMPSON_M}"
                    ),
                );
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
/// integrating never panic whatever the input; then brought within the bounds on a ray's work
/// (`cost.rs`), which only values between the keys of an animation (or a caller that skipped
/// [`CurveWave::validate`]) can break: a rate making more than [`MAX_TURNS`] turns is lowered
/// to that many, a B-spline that jumps at a repeated knot gets the clamped uniform knots, `γ` is
/// raised until the curve is no steeper than [`MAX_SLOPE`], and Simpson's `m` lowered to
/// [`CurveWave::max_simpson_m`]. Valid waves come back unchanged.
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
    sanitize_cost(&mut w);
    if let Integrator::Simpson { m, reduction } = &mut w.integrator {
        *m = (*m).clamp(2, MAX_SIMPSON_M);
        *m += *m & 1;
        if let Some(r) = reduction {
            r.n = r.n.max(1);
            r.epsilon = if r.epsilon.is_finite() { r.epsilon.max(0.0) } else { 0.0 };
        }
    }
    let max_m = w.max_simpson_m();
    if let Integrator::Simpson { m, .. } = &mut w.integrator {
        *m = (*m).min(max_m);
    }
    w
}

/// The turns and steepness of [`sanitize`] (on a wave whose values are otherwise legal).
fn sanitize_cost(w: &mut CurveWave) {
    if let Some(turns) = w.turns() {
        if turns > MAX_TURNS {
            // Just below the bound after rounding to f32.
            let f = MAX_TURNS / turns * (1.0 - 1e-6);
            if let CurveShape::Helix { rate, .. } | CurveShape::TrigSum { rate, .. } = &mut w.shape {
                *rate = (f64::from(*rate) * f) as f32;
            }
        }
    }
    let mut slope = w.steepness();
    if slope > MAX_SLOPE && f64::from(w.gamma) * slope / MAX_SLOPE >= f64::from(f32::MAX) {
        // A jump, or knots so crowded that no γ makes up for them.
        if let CurveShape::BSpline { points, order, knots: knots @ Some(_) } = &mut w.shape {
            *knots = Some(
                clamped_uniform_knots(points.len(), *order as usize).into_iter().map(|x| x as f32).collect(),
            );
            slope = w.steepness();
        }
    }
    if slope > MAX_SLOPE {
        let g = f64::from(w.gamma) * slope / MAX_SLOPE * (1.0 + 1e-6);
        w.gamma = g.min(f64::from(f32::MAX)) as f32;
    }
}
