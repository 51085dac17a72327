//! Animatable parameters: every numeric value of a scene lives in one flat `Vec<f32>`; a [`Param`]
//! names a slice of it, its shape and the range rule it must obey. Tracks write into the slices;
//! the frame builder reads them back after [`Constraint::clamp`] has made them valid.

use crate::limits::{fmt_f32, fmt_f64, ALPHA_MAX, COORD_MAX, DIR_MIN};

/// The shape of a parameter's value in the scene file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Shape {
    /// One number.
    Scalar,
    /// `[x, y, …]` with exactly this many numbers.
    Vector(usize),
    /// `[[…], […], …]`: a list of vectors of this width (the count is fixed by the scene file).
    List(usize),
}

impl Shape {
    /// How the shape is written, for messages.
    pub(crate) fn describe(self, len: usize) -> String {
        match self {
            Shape::Scalar => "a number".into(),
            Shape::Vector(n) => format!("an array of {n} numbers"),
            Shape::List(w) => format!("an array of {} arrays of {w} numbers", len / w.max(1)),
        }
    }
}

/// The range rule of a parameter, checked at load (static values and every keyframe) and enforced
/// by clamping at evaluation time (smooth interpolation may overshoot). Every rule also bounds
/// the magnitude (see `limits.rs` for why each bound keeps the renderers finite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Constraint {
    /// Any number within `±COORD_MAX`.
    Any,
    /// `0 ≤ v ≤ COORD_MAX`.
    NonNeg,
    /// `0 < v ≤ COORD_MAX`.
    Positive,
    /// Inside an interval; `open` bounds exclude the end.
    Range { lo: f32, hi: f32, lo_open: bool, hi_open: bool },
    /// A vector that must not be zero (a direction): components within `±COORD_MAX`, length at
    /// least `DIR_MIN`.
    NonZero,
    /// A colour `[r, g, b, a]`: `0 ≤ r, g, b ≤ COORD_MAX`, `a ∈ [0, 1]`.
    Rgba,
    /// Non-decreasing values (a knot vector) within `±COORD_MAX`.
    NonDecreasing,
}

/// Shorthands of the table readers (`schema.rs`, `wave_def.rs`, …).
pub(crate) const POSITIVE: Constraint = Constraint::Positive;
/// Wave strengths: `[0, ALPHA_MAX]`.
pub(crate) const ALPHA: Constraint =
    Constraint::Range { lo: 0.0, hi: ALPHA_MAX, lo_open: false, hi_open: false };
/// See [`Constraint::NonNeg`].
pub(crate) const NONNEG: Constraint = Constraint::NonNeg;
/// See [`Constraint::Any`].
pub(crate) const ANY: Constraint = Constraint::Any;
/// A 3-vector.
pub(crate) const V3: Shape = Shape::Vector(3);
/// A number.
pub(crate) const S: Shape = Shape::Scalar;

/// `[lo, hi]` with the bracket of each end, for messages.
fn interval(lo: f32, hi: f32, lo_open: bool, hi_open: bool) -> String {
    let (l, r) = (if lo_open { "(" } else { "[" }, if hi_open { ")" } else { "]" });
    format!("{l}{}, {}{r}", fmt_f32(lo), fmt_f32(hi))
}

impl Constraint {
    /// Checks `vals`, the components starting at component `first` of the parameter.
    /// Returns the index (into `vals`) of the offending value and the rule it breaks.
    pub(crate) fn check(self, vals: &[f32], first: usize, whole: bool) -> Result<(), (usize, String)> {
        for (i, &v) in vals.iter().enumerate() {
            if !v.is_finite() {
                return Err((i, format!("must be a finite number, got {v}")));
            }
        }
        let max = COORD_MAX;
        let within = |vals: &[f32]| -> Result<(), (usize, String)> {
            match vals.iter().position(|v| v.abs() > max) {
                Some(i) => Err((i, format!("must be within ±{}, got {}", fmt_f32(max), fmt_f32(vals[i])))),
                None => Ok(()),
            }
        };
        let range = |vals: &[f32], lo: f32, hi: f32, lo_open: bool, hi_open: bool| {
            for (i, &v) in vals.iter().enumerate() {
                let below = if lo_open { v <= lo } else { v < lo };
                let above = if hi_open { v >= hi } else { v > hi };
                if below || above {
                    return Err((
                        i,
                        format!("must be in {}, got {}", interval(lo, hi, lo_open, hi_open), fmt_f32(v)),
                    ));
                }
            }
            Ok(())
        };
        match self {
            Constraint::Any => within(vals),
            Constraint::NonNeg => range(vals, 0.0, max, false, false),
            Constraint::Positive => range(vals, 0.0, max, true, false),
            Constraint::Range { lo, hi, lo_open, hi_open } => range(vals, lo, hi, lo_open, hi_open),
            Constraint::NonZero => {
                within(vals)?;
                let len = vals.iter().map(|&v| f64::from(v) * f64::from(v)).sum::<f64>().sqrt();
                if whole && len == 0.0 {
                    Err((0, "must not be the zero vector (it is a direction)".into()))
                } else if whole && len < DIR_MIN {
                    Err((
                        0,
                        format!(
                            "is too short to give a direction: length {}, at least {}",
                            fmt_f32(len as f32),
                            fmt_f64(DIR_MIN)
                        ),
                    ))
                } else {
                    Ok(())
                }
            }
            Constraint::Rgba => {
                for (i, &v) in vals.iter().enumerate() {
                    if first + i == 3 {
                        if !(0.0..=1.0).contains(&v) {
                            return Err((
                                i,
                                format!("alpha (4th component) must be in [0, 1], got {}", fmt_f32(v)),
                            ));
                        }
                    } else if !(0.0..=max).contains(&v) {
                        return Err((
                            i,
                            format!("colour components must be in [0, {}], got {}", fmt_f32(max), fmt_f32(v)),
                        ));
                    }
                }
                Ok(())
            }
            Constraint::NonDecreasing => {
                within(vals)?;
                for i in 1..vals.len() {
                    if vals[i] < vals[i - 1] {
                        return Err((
                            i,
                            format!(
                                "must not decrease: {} follows {}",
                                fmt_f32(vals[i]),
                                fmt_f32(vals[i - 1])
                            ),
                        ));
                    }
                }
                Ok(())
            }
        }
    }

    /// Makes `vals` (a whole parameter) obey the rule, as closely as possible; non-finite values
    /// become `fallback`'s (the parameter's value as written in the scene file).
    pub(crate) fn clamp(self, vals: &mut [f32], fallback: &[f32]) {
        for (v, &f) in vals.iter_mut().zip(fallback) {
            if !v.is_finite() {
                *v = f;
            }
        }
        let max = COORD_MAX;
        match self {
            Constraint::Any | Constraint::NonZero => vals.iter_mut().for_each(|v| *v = v.clamp(-max, max)),
            Constraint::NonNeg => vals.iter_mut().for_each(|v| *v = v.clamp(0.0, max)),
            Constraint::Positive => vals.iter_mut().for_each(|v| *v = v.clamp(1e-6, max)),
            Constraint::Range { lo, hi, lo_open, hi_open } => {
                let lo = if lo_open { lo + (lo.abs() * 1e-6).max(1e-6) } else { lo };
                let hi = if hi_open { hi - (hi.abs() * 1e-6).max(1e-6) } else { hi };
                vals.iter_mut().for_each(|v| *v = v.clamp(lo, hi));
            }
            Constraint::Rgba => {
                for (i, v) in vals.iter_mut().enumerate() {
                    *v = if i == 3 { v.clamp(0.0, 1.0) } else { v.clamp(0.0, max) };
                }
            }
            Constraint::NonDecreasing => {
                vals.iter_mut().for_each(|v| *v = v.clamp(-max, max));
                for i in 1..vals.len() {
                    vals[i] = vals[i].max(vals[i - 1]);
                }
            }
        }
    }
}

/// One animatable parameter of an entity.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Param {
    /// Key in the scene file.
    pub key: &'static str,
    /// Start in the value store.
    pub offset: usize,
    /// Number of floats.
    pub len: usize,
    /// Shape in the file.
    pub shape: Shape,
    /// Range rule.
    pub rule: Constraint,
    /// A plain number may stand for all components (`scale = 2`).
    pub broadcast: bool,
}

/// The parameters of one entity (the camera, one wave, …).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct ParamSet {
    /// In the order they were declared.
    pub params: Vec<Param>,
}

impl ParamSet {
    /// The parameter named `key`.
    pub(crate) fn find(&self, key: &str) -> Option<&Param> {
        self.params.iter().find(|p| p.key == key)
    }

    /// The keys, for suggestions.
    pub(crate) fn keys(&self) -> Vec<&'static str> {
        self.params.iter().map(|p| p.key).collect()
    }

    fn slice<'v>(&self, vals: &'v [f32], key: &str) -> &'v [f32] {
        match self.find(key) {
            Some(p) => vals.get(p.offset..p.offset + p.len).unwrap_or(&[]),
            None => &[],
        }
    }

    /// Scalar `key` (0 if absent; the schema guarantees presence).
    pub(crate) fn f(&self, vals: &[f32], key: &str) -> f32 {
        self.slice(vals, key).first().copied().unwrap_or(0.0)
    }

    /// `N` components of `key` (zeros if absent).
    pub(crate) fn arr<const N: usize>(&self, vals: &[f32], key: &str) -> [f32; N] {
        let s = self.slice(vals, key);
        std::array::from_fn(|i| s.get(i).copied().unwrap_or(0.0))
    }

    /// A list of pairs (`points`, `y_terms`, …).
    pub(crate) fn pairs(&self, vals: &[f32], key: &str) -> Vec<[f32; 2]> {
        self.slice(vals, key).chunks_exact(2).map(|c| [c[0], c[1]]).collect()
    }

    /// The raw floats of `key`.
    pub(crate) fn raw<'v>(&self, vals: &'v [f32], key: &str) -> &'v [f32] {
        self.slice(vals, key)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_check_and_clamp() {
        assert!(Constraint::NonNeg.check(&[0.0, 1.0], 0, true).is_ok());
        assert_eq!(Constraint::NonNeg.check(&[0.0, -1.0], 0, true).unwrap_err().0, 1);
        assert!(Constraint::Rgba.check(&[2.0], 0, false).is_ok());
        assert!(Constraint::Rgba.check(&[2.0], 3, false).is_err());
        assert!(Constraint::NonZero.check(&[0.0, 0.0, 0.0], 0, true).is_err());
        assert!(Constraint::NonZero.check(&[0.0], 1, false).is_ok());
        assert!(Constraint::Any.check(&[f32::NAN], 0, true).is_err());
        let fov = Constraint::Range { lo: 0.0, hi: 180.0, lo_open: true, hi_open: true };
        let mut v = [-3.0, 200.0, f32::NAN];
        fov.clamp(&mut v, &[45.0, 45.0, 45.0]);
        assert!(v[0] > 0.0 && v[1] < 180.0 && v[2] == 45.0, "{v:?}");
        let mut big = [3e38, -3e38];
        Constraint::Any.clamp(&mut big, &[0.0, 0.0]);
        assert_eq!(big, [1e6, -1e6]);
        assert!(Constraint::Any.check(&[3e38], 0, true).unwrap_err().1.contains("3e38"));
        assert!(Constraint::NonZero.check(&[1e-30, 0.0, 0.0], 0, true).is_err());
        let mut k = [0.0, 2.0, 1.0, 3.0];
        Constraint::NonDecreasing.clamp(&mut k, &[0.0; 4]);
        assert_eq!(k, [0.0, 2.0, 2.0, 3.0]);
    }
}
