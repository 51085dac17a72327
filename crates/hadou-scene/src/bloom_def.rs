//! `[bloom]`: the glare on the linear image before colour mapping (`hadou_math::bloom`), read
//! and checked, and built at one set of values.

use crate::frame::BloomParams;
use crate::params::{Constraint, ParamSet, Shape};
use crate::toml_read::{Fallback, ParamReader, Res, Table};

/// The keys of `[bloom]`.
pub(crate) const BLOOM_KEYS: &[&str] =
    &["intensity", "threshold", "soft_knee", "radius", "streak", "streak_length"];

/// The largest `intensity` and `streak`.
pub const BLOOM_MAX_WEIGHT: f32 = 16.0;
/// The largest `threshold`.
pub const BLOOM_MAX_THRESHOLD: f32 = 1.0e4;
/// The largest `streak_length` (fraction of the image height).
pub const BLOOM_MAX_STREAK_LENGTH: f32 = 4.0;

const fn closed(lo: f32, hi: f32) -> Constraint {
    Constraint::Range { lo, hi, lo_open: false, hi_open: false }
}

/// Reads `[bloom]` into its parameter set; every key is optional and animatable.
pub(crate) fn parse_bloom(t: &Table<'_, '_>, rd: &mut ParamReader<'_>) -> Res<ParamSet> {
    t.check_keys(BLOOM_KEYS)?;
    let s = Shape::Scalar;
    let mut p = ParamSet::default();
    let weight = closed(0.0, BLOOM_MAX_WEIGHT);
    rd.add(t, &mut p, "intensity", s, weight, Fallback::Value(&[0.5]), false)?;
    rd.add(t, &mut p, "threshold", s, closed(0.0, BLOOM_MAX_THRESHOLD), Fallback::Value(&[1.0]), false)?;
    rd.add(t, &mut p, "soft_knee", s, closed(0.0, 1.0), Fallback::Value(&[0.5]), false)?;
    let radius = Constraint::Range { lo: 0.0, hi: 1.0, lo_open: true, hi_open: false };
    rd.add(t, &mut p, "radius", s, radius, Fallback::Value(&[0.05]), false)?;
    rd.add(t, &mut p, "streak", s, weight, Fallback::Value(&[0.0]), false)?;
    let length = Constraint::Range { lo: 0.0, hi: BLOOM_MAX_STREAK_LENGTH, lo_open: true, hi_open: false };
    rd.add(t, &mut p, "streak_length", s, length, Fallback::Value(&[0.5]), false)?;
    Ok(p)
}

/// The frame's bloom at the values `vals` (already clamped into range).
pub(crate) fn build_bloom(p: &ParamSet, vals: &[f32]) -> BloomParams {
    BloomParams {
        intensity: p.f(vals, "intensity"),
        threshold: p.f(vals, "threshold"),
        soft_knee: p.f(vals, "soft_knee"),
        radius: p.f(vals, "radius"),
        streak: p.f(vals, "streak"),
        streak_length: p.f(vals, "streak_length"),
    }
}
