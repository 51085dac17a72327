//! Animatable parameters: every numeric value of a scene lives in one flat `Vec<f32>`; a [`Param`]
//! names a slice of it, its shape and the range rule it must obey. Tracks write into the slices;
//! the frame builder reads them back after [`Constraint::clamp`] has made them valid.

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
/// by clamping at evaluation time (smooth interpolation may overshoot).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Constraint {
    /// Any finite number.
    Any,
    /// `≥ 0`.
    NonNeg,
    /// `> 0`.
    Positive,
    /// Inside an interval; `open` bounds exclude the end.
    Range { lo: f32, hi: f32, lo_open: bool, hi_open: bool },
    /// A vector that must not be zero (a direction).
    NonZero,
    /// A colour `[r, g, b, a]`: `r, g, b ≥ 0`, `a ∈ [0, 1]`.
    Rgba,
    /// Non-decreasing values (a knot vector).
    NonDecreasing,
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
        match self {
            Constraint::Any => Ok(()),
            Constraint::NonNeg => match vals.iter().position(|&v| v < 0.0) {
                Some(i) => Err((i, format!("must be ≥ 0, got {}", vals[i]))),
                None => Ok(()),
            },
            Constraint::Positive => match vals.iter().position(|&v| v <= 0.0) {
                Some(i) => Err((i, format!("must be > 0, got {}", vals[i]))),
                None => Ok(()),
            },
            Constraint::Range { lo, hi, lo_open, hi_open } => {
                for (i, &v) in vals.iter().enumerate() {
                    let below = if lo_open { v <= lo } else { v < lo };
                    let above = if hi_open { v >= hi } else { v > hi };
                    if below || above {
                        let (l, r) = (if lo_open { "(" } else { "[" }, if hi_open { ")" } else { "]" });
                        return Err((i, format!("must be in {l}{lo}, {hi}{r}, got {v}")));
                    }
                }
                Ok(())
            }
            Constraint::NonZero => {
                if whole && vals.iter().all(|&v| v == 0.0) {
                    Err((0, "must not be the zero vector (it is a direction)".into()))
                } else {
                    Ok(())
                }
            }
            Constraint::Rgba => {
                for (i, &v) in vals.iter().enumerate() {
                    if first + i == 3 {
                        if !(0.0..=1.0).contains(&v) {
                            return Err((i, format!("alpha (4th component) must be in [0, 1], got {v}")));
                        }
                    } else if v < 0.0 {
                        return Err((i, format!("colour components must be ≥ 0, got {v}")));
                    }
                }
                Ok(())
            }
            Constraint::NonDecreasing => {
                for i in 1..vals.len() {
                    if vals[i] < vals[i - 1] {
                        return Err((i, format!("must not decrease: {} follows {}", vals[i], vals[i - 1])));
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
        match self {
            Constraint::Any | Constraint::NonZero => {}
            Constraint::NonNeg => vals.iter_mut().for_each(|v| *v = v.max(0.0)),
            Constraint::Positive => vals.iter_mut().for_each(|v| *v = v.max(1e-6)),
            Constraint::Range { lo, hi, lo_open, hi_open } => {
                let span = (hi - lo).abs();
                let lo = if lo_open { lo + (span * 1e-6).max(1e-6) } else { lo };
                let hi = if hi_open { hi - (span * 1e-6).max(1e-6) } else { hi };
                vals.iter_mut().for_each(|v| *v = v.clamp(lo, hi));
            }
            Constraint::Rgba => {
                for (i, v) in vals.iter_mut().enumerate() {
                    *v = if i == 3 { v.clamp(0.0, 1.0) } else { v.max(0.0) };
                }
            }
            Constraint::NonDecreasing => {
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
        let mut k = [0.0, 2.0, 1.0, 3.0];
        Constraint::NonDecreasing.clamp(&mut k, &[0.0; 4]);
        assert_eq!(k, [0.0, 2.0, 2.0, 3.0]);
    }
}
