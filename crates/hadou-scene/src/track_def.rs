//! `[[track]]` as the scene file writes it: the target (`wave.<name>.<key>[i].c`,
//! `camera.<key>`, …) resolved to a slice of the scene's parameter store with its shape and range
//! rule, and the keys read and checked against them, giving an [`anim::Track`](crate::anim::Track).

use crate::anim::{Interpolation, Track};
use crate::error::hint;
use crate::limits::{fmt_f32, fmt_f64, COORD_MAX};
use crate::params::{Constraint, ParamSet, Shape};
use crate::scene::Scene;
use crate::toml_read::{number, read_numbers, too_large_integer, type_name, Res, Span, Table, Val};
use std::collections::HashMap;
use toml::de::DeValue;

const TRACK_KEYS: &[&str] = &["target", "interpolation", "keys"];

/// The part of a scene a track animates (whose parameter set holds its slice).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Owner {
    /// `background`.
    Globals,
    /// `[camera]`.
    Camera,
    /// `[light]`.
    Light,
    /// `[color]`.
    Color,
    /// `[area_light]`.
    AreaLight,
    /// `[bloom]`.
    Bloom,
    /// `[[object]]` by index.
    Object(usize),
    /// `[[material]]` by index.
    Material(usize),
    /// `[[wave]]` by index.
    Wave(usize),
    /// `[[shadow]]` by index.
    Shadow(usize),
}

/// The scene's entities by name, built once for all its tracks (a lookup per track, not a scan).
pub(crate) struct Names<'s> {
    objects: HashMap<&'s str, usize>,
    materials: HashMap<&'s str, usize>,
    waves: HashMap<&'s str, usize>,
    shadows: HashMap<&'s str, usize>,
}

impl<'s> Names<'s> {
    /// The names of `scene`'s objects, materials, waves and shadows.
    pub(crate) fn of(scene: &'s Scene) -> Self {
        fn index<'a>(names: impl Iterator<Item = &'a str>) -> HashMap<&'a str, usize> {
            names.enumerate().map(|(i, n)| (n, i)).collect()
        }
        Names {
            objects: index(scene.objects.iter().map(|o| o.name.as_str())),
            materials: index(scene.materials.iter().map(|m| m.name.as_str())),
            waves: index(scene.waves.iter().map(|w| w.name.as_str())),
            shadows: index(scene.shadows.iter().map(|s| s.name.as_str())),
        }
    }
}

/// A parameter slice selected by a track target.
struct Selection {
    offset: usize,
    len: usize,
    shape: Shape,
    rule: Constraint,
    /// Component index of the first selected float within its vector (for per-component rules).
    first: usize,
    whole: bool,
    broadcast: bool,
}

/// Resolves `target` (`wave.<name>.<key>[i].c`, `object.<name>.<key>`, `camera.<key>`,
/// `light.<key>`, `area_light.<key>`, `bloom.<key>`, `color.exposure`, `background`) against the scene, whose
/// entities `names` indexes; also says which part of the scene it animates.
fn resolve_target(scene: &Scene, names: &Names<'_>, target: &str) -> Result<(Selection, Owner), String> {
    let segs: Vec<&str> = target.split('.').collect();
    let head = segs[0];
    let (set, rest, ent, owner): (&ParamSet, &[&str], String, Owner) =
        match head.split('[').next().unwrap_or("") {
            "background" => (&scene.globals, &segs[..], "the scene".into(), Owner::Globals),
            "area_light" if segs.len() >= 2 => match &scene.area_light {
                Some(a) => (&a.params, &segs[1..], "[area_light]".into(), Owner::AreaLight),
                None => return Err(format!("target \"{target}\": the scene has no [area_light]")),
            },
            "bloom" if segs.len() >= 2 => match &scene.bloom {
                Some(b) => (b, &segs[1..], "[bloom]".into(), Owner::Bloom),
                None => return Err(format!("target \"{target}\": the scene has no [bloom]")),
            },
            "camera" | "light" | "color" if segs.len() >= 2 => {
                let (set, owner) = match head {
                    "camera" => (&scene.camera, Owner::Camera),
                    "light" => (&scene.light, Owner::Light),
                    _ => (&scene.color, Owner::Color),
                };
                (set, &segs[1..], format!("[{head}]"), owner)
            }
            "wave" | "object" | "material" | "shadow" if segs.len() >= 3 => {
                let name = segs[1];
                let found = match head {
                    "shadow" => {
                        names.shadows.get(name).map(|&i| (&scene.shadows[i].params, Owner::Shadow(i)))
                    }
                    "wave" => names.waves.get(name).map(|&i| (&scene.waves[i].params, Owner::Wave(i))),
                    "material" => {
                        names.materials.get(name).map(|&i| (&scene.materials[i].params, Owner::Material(i)))
                    }
                    _ => names.objects.get(name).map(|&i| (&scene.objects[i].params, Owner::Object(i))),
                };
                match found {
                    Some((s, owner)) => (s, &segs[2..], format!("[[{head}]] \"{name}\""), owner),
                    None => {
                        let all: Vec<&str> = match head {
                            "shadow" => scene.shadows.iter().map(|s| s.name.as_str()).collect(),
                            "wave" => scene.wave_names(),
                            "material" => scene.materials.iter().map(|m| m.name.as_str()).collect(),
                            _ => scene.object_names(),
                        };
                        return Err(format!("no {head} is named \"{name}\"{}", hint(name, &all, "names")));
                    }
                }
            }
            "camera" | "light" | "color" | "area_light" | "bloom" => {
                return Err(format!("target \"{target}\" needs a key: `{head}.<key>`"));
            }
            "wave" | "object" | "material" | "shadow" => {
                return Err(format!("target \"{target}\" needs a name and a key: `{head}.<name>.<key>`"));
            }
            other => {
                let heads = [
                    "wave",
                    "object",
                    "material",
                    "shadow",
                    "camera",
                    "light",
                    "area_light",
                    "bloom",
                    "color",
                    "background",
                ];
                return Err(format!(
                "target \"{target}\" must start with `wave.`, `object.`, `material.`, `shadow.`, `camera.`, \
                 `light.`, `area_light.`, `bloom.`, `color.` or be `background`{}",
                hint(other, &heads, "targets")
            ));
            }
        };
    if rest.is_empty() || rest.len() > 2 {
        return Err(format!("target \"{target}\" is not of the form `<entity>.<key>[index].<component>`"));
    }
    // key[i][j]
    let (key, mut indices) =
        split_indices(rest[0]).ok_or_else(|| format!("bad index in target \"{target}\""))?;
    let Some(param) = set.find(key) else {
        let keys = set.keys();
        return Err(format!("{ent} has no animatable key `{key}`{}", hint(key, &keys, "keys")));
    };
    if let Some(comp) = rest.get(1) {
        let i = match *comp {
            "x" | "r" => 0,
            "y" | "g" => 1,
            "z" | "b" => 2,
            "w" | "a" => 3,
            name if key == "expressions" => {
                let names: Vec<&str> = match owner {
                    Owner::Object(o) => scene.objects[o]
                        .rig
                        .as_ref()
                        .map(|r| r.expressions().iter().map(|e| e.name.as_str()).collect())
                        .unwrap_or_default(),
                    _ => Vec::new(),
                };
                match names.iter().position(|n| *n == name) {
                    Some(i) => i,
                    None => {
                        return Err(format!(
                            "{ent} has no expression `{name}`{}",
                            hint(name, &names, "expressions")
                        ))
                    }
                }
            }
            _ => {
                return Err(format!(
                    "unknown component `.{comp}` in \"{target}\"; use .x/.y/.z/.w, .r/.g/.b/.a or [i]"
                ))
            }
        };
        if !matches!(param.shape, Shape::Vector(_)) {
            return Err(format!("`.{comp}` applies to vectors; select elements of `{key}` with [i]"));
        }
        indices.push(i);
    }
    let mut sel = Selection {
        offset: param.offset,
        len: param.len,
        shape: param.shape,
        rule: param.rule,
        first: 0,
        whole: true,
        broadcast: param.broadcast,
    };
    for &i in &indices {
        let (n, width, next) = match sel.shape {
            Shape::Scalar => return Err(format!("`{key}` is a number; it has no components to select")),
            Shape::Vector(n) => (n, 1, Shape::Scalar),
            Shape::List(w) => (sel.len / w.max(1), w, if w == 1 { Shape::Scalar } else { Shape::Vector(w) }),
        };
        if i >= n {
            return Err(format!("index {i} is out of range for `{key}` ({n} element(s))"));
        }
        sel = Selection {
            offset: sel.offset + i * width,
            len: width,
            shape: next,
            rule: sel.rule,
            first: if width == 1 { i } else { 0 },
            whole: false,
            broadcast: false,
        };
    }
    Ok((sel, owner))
}

/// `"points[2][1]"` → `("points", [2, 1])`.
fn split_indices(s: &str) -> Option<(&str, Vec<usize>)> {
    let (key, mut rest) = match s.find('[') {
        Some(i) => (&s[..i], &s[i..]),
        None => return Some((s, Vec::new())),
    };
    let mut out = Vec::new();
    while !rest.is_empty() {
        let inner = rest.strip_prefix('[')?;
        let close = inner.find(']')?;
        out.push(inner[..close].trim().parse().ok()?);
        rest = &inner[close + 1..];
    }
    Some((key, out))
}

/// Reads one `[[track]]` against `scene` (its entities indexed by `names`); `targets` holds the
/// targets of the tracks read before (each may be animated once). Returns the track, the part
/// of the scene it animates and the span of each key.
pub(crate) fn parse_track(
    t: &Table<'_, '_>,
    scene: &Scene,
    names: &Names<'_>,
    targets: &mut HashMap<String, Span>,
) -> Res<(Track, Owner, Vec<Span>)> {
    t.check_keys(TRACK_KEYS)?;
    let (target, tspan) = t.req_str("target", "what to animate, e.g. \"wave.beam.M2\"")?;
    let (sel, owner) = resolve_target(scene, names, target).map_err(|m| t.src.track(&tspan, m))?;
    if let Some(first) = targets.get(target) {
        let line = t.src.loc(first).line;
        return Err(t.src.duplicate(
            &tspan,
            format!("a track for \"{target}\" already exists (line {line}); merge their keys into one track"),
        ));
    }
    targets.insert(target.to_string(), tspan.clone());
    let what = format!("[[track]] \"{target}\"");
    let interpolation = match t.choice("interpolation", &["linear", "smooth"], Some("linear"))? {
        "smooth" => Interpolation::Smooth,
        _ => Interpolation::Linear,
    };
    let keys_v: &Val<'_> = t
        .get("keys")
        .ok_or_else(|| t.src.missing(&t.span, format!("{what} needs `keys = [[time, value], …]`")))?;
    let DeValue::Array(keys) = keys_v.get_ref() else {
        return Err(t.src.type_err(
            &keys_v.span(),
            format!(
                "`keys` in {what} must be an array of [time, value] pairs, got {}",
                type_name(keys_v.get_ref())
            ),
        ));
    };
    if keys.is_empty() {
        return Err(t
            .src
            .track(&keys_v.span(), format!("`keys` in {what} needs at least one [time, value] pair")));
    }
    let mut times = Vec::new();
    let mut values = Vec::new();
    let mut spans = Vec::new();
    for key in keys.iter() {
        let pair = match key.get_ref() {
            DeValue::Array(a) if a.len() == 2 => a,
            _ => {
                return Err(t.src.track(
                    &key.span(),
                    format!(
                        "each key of {what} must be a pair [time, value], e.g. [0.5, {}]",
                        example(sel.shape)
                    ),
                ))
            }
        };
        if too_large_integer(pair[0].get_ref()) {
            return Err(t.src.type_err(
                &pair[0].span(),
                format!(
                    "key time in {what} must be a number, got an integer that is too large (over 64 bits)"
                ),
            ));
        }
        let time = match number(pair[0].get_ref()) {
            Some(x) if x.is_finite() && x >= 0.0 && x <= f64::from(COORD_MAX) => x as f32,
            Some(x) if x.is_finite() && x >= 0.0 => {
                return Err(t.src.value_err(
                    &pair[0].span(),
                    format!(
                        "key time in {what} must be at most {} s, got {}",
                        fmt_f32(COORD_MAX),
                        fmt_f64(x)
                    ),
                ))
            }
            Some(x) => {
                return Err(t.src.value_err(
                    &pair[0].span(),
                    format!("key time in {what} must be finite and ≥ 0, got {}", fmt_f64(x)),
                ))
            }
            None => {
                return Err(t.src.type_err(
                    &pair[0].span(),
                    format!(
                        "key time in {what} must be a number of seconds, got {}",
                        type_name(pair[0].get_ref())
                    ),
                ))
            }
        };
        if let Some(&prev) = times.last() {
            if time <= prev {
                return Err(t.src.track(
                    &pair[0].span(),
                    format!(
                        "key times in {what} must increase strictly: {} follows {}",
                        fmt_f32(time),
                        fmt_f32(prev)
                    ),
                ));
            }
        }
        let vwhat = format!("key value in {what}");
        let nums = read_numbers(&t.src, &pair[1], sel.shape, sel.broadcast, &vwhat)?;
        if nums.len() != sel.len {
            return Err(t.src.type_err(
                &pair[1].span(),
                format!("{vwhat} must be {}, like the scene's value", sel.shape.describe(sel.len)),
            ));
        }
        let plain: Vec<f32> = nums.iter().map(|x| x.0).collect();
        if let Err((i, msg)) = sel.rule.check(&plain, sel.first, sel.whole) {
            let span =
                if matches!(sel.rule, Constraint::NonZero) { pair[1].span() } else { nums[i].1.clone() };
            return Err(t.src.value_err(&span, format!("{vwhat} {msg}")));
        }
        times.push(time);
        values.extend(plain);
        spans.push(key.span());
    }
    let track =
        Track { target: target.to_string(), offset: sel.offset, len: sel.len, interpolation, times, values };
    Ok((track, owner, spans))
}

fn example(shape: Shape) -> &'static str {
    match shape {
        Shape::Scalar => "1.0",
        Shape::Vector(_) => "[0.0, 1.0, 0.0]",
        Shape::List(_) => "[[0.0, 1.0], …]",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_suffixes_split() {
        assert_eq!(split_indices("points[2][1]"), Some(("points", vec![2, 1])));
        assert_eq!(split_indices("M2"), Some(("M2", vec![])));
        assert_eq!(split_indices("points[x]"), None);
        assert_eq!(split_indices("points[1"), None);
    }
}
