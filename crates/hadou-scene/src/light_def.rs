//! The readers of `[light]` (the directional light: direction, colour, ambient) and `[color]` (the
//! colour mapping and exposure).

use crate::frame::ToneMode;
use crate::params::{Constraint, ParamSet, NONNEG, POSITIVE, S, V3};
use crate::toml_read::{Fallback, ParamReader, Res, Table};

/// The keys of `[light]`.
pub(crate) const LIGHT_KEYS: &[&str] = &["direction", "color", "ambient"];
/// The keys of `[color]`.
pub(crate) const COLOR_KEYS: &[&str] = &["mode", "exposure"];

/// `[light]` (an empty table where the file has none): its parameters into `rd`'s store.
pub(crate) fn parse_light(t: &Table<'_, '_>, rd: &mut ParamReader<'_>) -> Res<ParamSet> {
    t.check_keys(LIGHT_KEYS)?;
    let mut light = ParamSet::default();
    let dir = Fallback::Value(&[-0.4, -1.0, -0.3]);
    rd.add(t, &mut light, "direction", V3, Constraint::NonZero, dir, false)?;
    rd.add(t, &mut light, "color", V3, NONNEG, Fallback::Value(&[1.0; 3]), false)?;
    rd.add(t, &mut light, "ambient", V3, NONNEG, Fallback::Value(&[0.15; 3]), false)?;
    Ok(light)
}

/// `[color]` (an empty table where the file has none): the colour mapping (`mode`, filmic by
/// default) and its parameters (`exposure`) into `rd`'s store.
pub(crate) fn parse_color(t: &Table<'_, '_>, rd: &mut ParamReader<'_>) -> Res<(ToneMode, ParamSet)> {
    t.check_keys(COLOR_KEYS)?;
    let mut color = ParamSet::default();
    let mode = t.choice("mode", &["faithful", "filmic"], Some("filmic"))?;
    rd.add(t, &mut color, "exposure", S, POSITIVE, Fallback::Value(&[1.0]), false)?;
    let tone = if mode == "faithful" { ToneMode::Faithful } else { ToneMode::Filmic };
    Ok((tone, color))
}
