//! A hand-walk over toml's spanned document ([`toml::de::DeTable`]): typed reads that report the
//! exact span of the offending key or value (strings, choices, integers, booleans, lists of object
//! names, numbers of any [`Shape`]), unknown-key detection with suggestions, and [`ParamReader`],
//! which appends a table's numbers to the scene's parameter store.

use crate::error::{hint, Location, SceneError};
use crate::limits::fmt_f64;
use crate::params::{Constraint, Param, ParamSet, Shape};
use std::ops::Range;
use std::path::Path;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// A spanned TOML value.
pub(crate) type Val<'i> = Spanned<DeValue<'i>>;
/// A byte range in the scene text.
pub(crate) type Span = Range<usize>;
/// Result of this crate.
pub(crate) type Res<T> = Result<T, SceneError>;

/// The scene text and its path, for turning spans into locations.
#[derive(Clone, Copy)]
pub(crate) struct Src<'a> {
    pub text: &'a str,
    pub path: &'a Path,
}

impl Src<'_> {
    /// Location of the start of `span`.
    pub(crate) fn loc(&self, span: &Span) -> Location {
        Location::from_offset(self.path, self.text, span.start)
    }
    pub(crate) fn type_err(&self, span: &Span, message: String) -> SceneError {
        SceneError::Type { at: self.loc(span), message }
    }
    pub(crate) fn value_err(&self, span: &Span, message: String) -> SceneError {
        SceneError::Value { at: self.loc(span), message }
    }
    pub(crate) fn missing(&self, span: &Span, message: String) -> SceneError {
        SceneError::Missing { at: self.loc(span), message }
    }
    pub(crate) fn unknown(&self, span: &Span, message: String) -> SceneError {
        SceneError::UnknownKey { at: self.loc(span), message }
    }
    pub(crate) fn duplicate(&self, span: &Span, message: String) -> SceneError {
        SceneError::Duplicate { at: self.loc(span), message }
    }
    pub(crate) fn track(&self, span: &Span, message: String) -> SceneError {
        SceneError::Track { at: self.loc(span), message }
    }
}

/// The TOML type name of a value, for messages.
pub(crate) fn type_name(v: &DeValue<'_>) -> &'static str {
    match v {
        DeValue::String(_) => "a string",
        DeValue::Integer(_) => "an integer",
        DeValue::Float(_) => "a float",
        DeValue::Boolean(_) => "a boolean",
        DeValue::Datetime(_) => "a datetime",
        DeValue::Array(_) => "an array",
        DeValue::Table(_) => "a table",
    }
}

/// The number a value holds, if it is an integer or a float (`nan`/`inf` come back non-finite,
/// an integer too large for 64 bits comes back NaN: see [`too_large_integer`]).
pub(crate) fn number(v: &DeValue<'_>) -> Option<f64> {
    match v {
        DeValue::Integer(i) => {
            Some(i64::from_str_radix(&i.as_str().replace('_', ""), i.radix()).map_or(f64::NAN, |x| x as f64))
        }
        DeValue::Float(f) => Some(f.as_str().replace('_', "").parse::<f64>().unwrap_or(f64::NAN)),
        _ => None,
    }
}

/// Whether `v` is an integer literal that does not fit in 64 bits.
pub(crate) fn too_large_integer(v: &DeValue<'_>) -> bool {
    matches!(v, DeValue::Integer(i) if i64::from_str_radix(&i.as_str().replace('_', ""), i.radix()).is_err())
}

/// Reads a numeric value of `shape` (with `len` floats expected for vectors), returning each
/// number with its own span. A [`Shape::List`] accepts any count (the caller checks it).
pub(crate) fn read_numbers(
    src: &Src<'_>,
    v: &Val<'_>,
    shape: Shape,
    broadcast: bool,
    what: &str,
) -> Res<Vec<(f32, Span)>> {
    let one =
        |v: &Val<'_>, what: &str| -> Res<(f32, Span)> {
            if too_large_integer(v.get_ref()) {
                return Err(src.type_err(
                    &v.span(),
                    format!("{what} must be a number, got an integer that is too large (over 64 bits)"),
                ));
            }
            match number(v.get_ref()) {
                Some(x) => {
                    let f = x as f32;
                    if x.is_finite() && !f.is_finite() {
                        return Err(src.value_err(
                            &v.span(),
                            format!("{what} is too large for 32-bit floats: {}", fmt_f64(x)),
                        ));
                    }
                    Ok((f, v.span()))
                }
                None => Err(src
                    .type_err(&v.span(), format!("{what} must be a number, got {}", type_name(v.get_ref())))),
            }
        };
    let vector = |v: &Val<'_>, n: usize, what: &str| -> Res<Vec<(f32, Span)>> {
        match v.get_ref() {
            DeValue::Array(a) if a.len() == n => a.iter().map(|x| one(x, what)).collect(),
            DeValue::Array(a) => Err(src.type_err(
                &v.span(),
                format!("{what} must be an array of {n} numbers, got {} element(s)", a.len()),
            )),
            other => Err(src.type_err(
                &v.span(),
                format!("{what} must be an array of {n} numbers, got {}", type_name(other)),
            )),
        }
    };
    match shape {
        Shape::Scalar => Ok(vec![one(v, what)?]),
        Shape::Vector(n) => {
            if broadcast && number(v.get_ref()).is_some() {
                let x = one(v, what)?;
                return Ok(vec![x; n]);
            }
            vector(v, n, what)
        }
        Shape::List(w) => match v.get_ref() {
            DeValue::Array(a) => {
                let mut out = Vec::with_capacity(a.len() * w);
                for item in a.iter() {
                    if w == 1 {
                        out.push(one(item, what)?);
                    } else {
                        out.extend(vector(item, w, &format!("each element of {what}"))?);
                    }
                }
                Ok(out)
            }
            other => Err(src.type_err(
                &v.span(),
                format!("{what} must be {}, got {}", Shape::List(w).describe(w), type_name(other)),
            )),
        },
    }
}

/// A table of the scene being read.
pub(crate) struct Table<'t, 'i> {
    pub src: Src<'t>,
    pub t: &'t DeTable<'i>,
    /// The header (or inline table) span: where "missing key" errors point.
    pub span: Span,
    /// How messages name the table, e.g. `[camera]` or `[[wave]] "beam"`.
    pub what: String,
}

impl<'t, 'i> Table<'t, 'i> {
    /// Fails on the first (in file order) key not in `allowed`, suggesting the nearest.
    pub(crate) fn check_keys(&self, allowed: &[&str]) -> Res<()> {
        let mut bad: Vec<(&Spanned<std::borrow::Cow<'i, str>>, &Val<'i>)> =
            self.t.iter().filter(|(k, _)| !allowed.contains(&k.get_ref().as_ref())).collect();
        bad.sort_by_key(|(k, _)| k.span().start);
        if let Some((k, _)) = bad.first() {
            let key = k.get_ref().as_ref();
            return Err(self.src.unknown(
                &k.span(),
                format!("unknown key `{key}` in {}{}", self.what, hint(key, allowed, "keys")),
            ));
        }
        Ok(())
    }

    /// The value of `key`.
    pub(crate) fn get(&self, key: &str) -> Option<&'t Val<'i>> {
        self.t.get(key)
    }

    /// The span of `key` itself (the key, not its value), or the table's span.
    pub(crate) fn key_span(&self, key: &str) -> Span {
        self.t.get_key_value(key).map_or(self.span.clone(), |(k, _)| k.span())
    }

    /// An optional string.
    pub(crate) fn opt_str(&self, key: &str) -> Res<Option<(&'t str, Span)>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => match v.get_ref() {
                DeValue::String(s) => Ok(Some((s.as_ref(), v.span()))),
                other => Err(self.src.type_err(
                    &v.span(),
                    format!("`{key}` in {} must be a string, got {}", self.what, type_name(other)),
                )),
            },
        }
    }

    /// A required string.
    pub(crate) fn req_str(&self, key: &str, meaning: &str) -> Res<(&'t str, Span)> {
        self.opt_str(key)?
            .ok_or_else(|| self.src.missing(&self.span, format!("{} needs `{key}` ({meaning})", self.what)))
    }

    /// A string that must be one of `options`; `default` when absent (`None`: required).
    pub(crate) fn choice(
        &self,
        key: &str,
        options: &[&'static str],
        default: Option<&'static str>,
    ) -> Res<&'static str> {
        let got = match (self.opt_str(key)?, default) {
            (Some(s), _) => s,
            (None, Some(d)) => return Ok(d),
            (None, None) => {
                let list: Vec<String> = options.iter().map(|o| format!("\"{o}\"")).collect();
                return Err(self.src.missing(
                    &self.span,
                    format!("{} needs `{key}`, one of {}", self.what, list.join(", ")),
                ));
            }
        };
        match options.iter().find(|o| **o == got.0) {
            Some(o) => Ok(o),
            None => Err(self.src.value_err(
                &got.1,
                format!(
                    "`{key}` in {} cannot be \"{}\"{}",
                    self.what,
                    echo(got.0),
                    hint(got.0, options, "values")
                ),
            )),
        }
    }

    /// An optional integer in `lo..=hi`.
    pub(crate) fn opt_int(&self, key: &str, lo: i64, hi: i64) -> Res<Option<(i64, Span)>> {
        let Some(v) = self.get(key) else { return Ok(None) };
        let n = match v.get_ref() {
            DeValue::Integer(i) => i64::from_str_radix(&i.as_str().replace('_', ""), i.radix()).ok(),
            DeValue::Float(_) => {
                return Err(self.src.type_err(
                    &v.span(),
                    format!("`{key}` in {} must be an integer (no decimal point)", self.what),
                ))
            }
            other => {
                return Err(self.src.type_err(
                    &v.span(),
                    format!("`{key}` in {} must be an integer, got {}", self.what, type_name(other)),
                ))
            }
        };
        if n.is_none() {
            return Err(self.src.type_err(
                &v.span(),
                format!(
                    "`{key}` in {} must be an integer in {lo}..={hi}, got an integer that is too large (over 64 bits)",
                    self.what
                ),
            ));
        }
        match n {
            Some(n) if (lo..=hi).contains(&n) => Ok(Some((n, v.span()))),
            _ => Err(self.src.value_err(
                &v.span(),
                format!("`{key}` in {} must be in {lo}..={hi}, got {}", self.what, display_raw(v.get_ref())),
            )),
        }
    }

    /// An optional boolean.
    pub(crate) fn opt_bool(&self, key: &str) -> Res<Option<bool>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => match v.get_ref() {
                DeValue::Boolean(b) => Ok(Some(*b)),
                other => Err(self.src.type_err(
                    &v.span(),
                    format!("`{key}` in {} must be true or false, got {}", self.what, type_name(other)),
                )),
            },
        }
    }

    /// Reads a list of object names (`"a"` or `["a", "b"]`) into object indices; `objects` are the
    /// scene's objects (name, is a `plane` primitive).
    pub(crate) fn object_list(&self, key: &str, objects: &[(&str, bool)]) -> Res<Vec<u32>> {
        let v = self.get(key).ok_or_else(|| {
            self.src.missing(
                &self.span,
                format!("{} needs `{key}` (an object name or a list of them)", self.what),
            )
        })?;
        let items: Vec<(&str, Span)> = match v.get_ref() {
            DeValue::String(s) => vec![(s.as_ref(), v.span())],
            DeValue::Array(a) => {
                let mut out = Vec::new();
                for item in a.iter() {
                    let DeValue::String(s) = item.get_ref() else {
                        return Err(self.src.type_err(
                            &item.span(),
                            format!(
                                "`{key}` in {} must list object names, got {}",
                                self.what,
                                type_name(item.get_ref())
                            ),
                        ));
                    };
                    out.push((s.as_ref(), item.span()));
                }
                out
            }
            other => {
                return Err(self.src.type_err(
                    &v.span(),
                    format!(
                        "`{key}` in {} must be an object name or a list of them, got {}",
                        self.what,
                        type_name(other)
                    ),
                ))
            }
        };
        if items.is_empty() {
            return Err(self
                .src
                .value_err(&v.span(), format!("`{key}` in {} must name at least one object", self.what)));
        }
        // By name through a map, duplicates through a set: linear in the list and the objects.
        let index: std::collections::HashMap<&str, u32> =
            objects.iter().enumerate().map(|(i, o)| (o.0, i as u32)).collect();
        let mut seen = std::collections::HashSet::new();
        let mut out: Vec<u32> = Vec::with_capacity(items.len().min(objects.len()));
        for (name, span) in items {
            let Some(&i) = index.get(name) else {
                let names: Vec<&str> = objects.iter().map(|o| o.0).collect();
                return Err(self.src.value_err(
                    &span,
                    format!(
                        "`{key}` in {}: no [[object]] is named \"{name}\"{}",
                        self.what,
                        hint(name, &names, "names")
                    ),
                ));
            };
            if !seen.insert(i) {
                return Err(self
                    .src
                    .duplicate(&span, format!("`{key}` in {} names \"{name}\" twice", self.what)));
            }
            out.push(i);
        }
        Ok(out)
    }

    /// A sub-table (`[camera]` or `camera = { … }`).
    pub(crate) fn sub(&self, key: &str, what: &str) -> Res<Option<Table<'t, 'i>>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => match v.get_ref() {
                DeValue::Table(t) => Ok(Some(Table { src: self.src, t, span: v.span(), what: what.into() })),
                other => Err(self.src.type_err(
                    &v.span(),
                    format!("`{key}` must be a table ([{key}]), got {}", type_name(other)),
                )),
            },
        }
    }

    /// An array of tables (`[[wave]]`).
    pub(crate) fn array_of_tables(&self, key: &str) -> Res<Vec<(&'t DeTable<'i>, Span)>> {
        match self.get(key) {
            None => Ok(Vec::new()),
            Some(v) => match v.get_ref() {
                DeValue::Array(a) => a
                    .iter()
                    .map(|item| match item.get_ref() {
                        DeValue::Table(t) => Ok((t, item.span())),
                        other => Err(self.src.type_err(
                            &item.span(),
                            format!("each `{key}` must be a table ([[{key}]]), got {}", type_name(other)),
                        )),
                    })
                    .collect(),
                DeValue::Table(_) => Err(self.src.type_err(
                    &v.span(),
                    format!("`{key}` must be an array of tables: write [[{key}]], not [{key}]"),
                )),
                other => Err(self.src.type_err(
                    &v.span(),
                    format!("`{key}` must be an array of tables ([[{key}]]), got {}", type_name(other)),
                )),
            },
        }
    }
}

/// A number as written, for messages.
fn display_raw(v: &DeValue<'_>) -> String {
    match v {
        DeValue::Integer(i) => i.to_string(),
        DeValue::Float(f) => f.to_string(),
        other => type_name(other).into(),
    }
}

/// Appends parameters read from a table to the flat value store.
pub(crate) struct ParamReader<'s> {
    /// The value store.
    pub values: &'s mut Vec<f32>,
    /// For each store index, the span it was read from (for cross-field errors).
    pub spans: &'s mut Vec<Span>,
}

/// What a parameter falls back to when its key is absent.
pub(crate) enum Fallback<'d> {
    /// Required.
    Required(&'d str),
    /// These values.
    Value(&'d [f32]),
}

impl ParamReader<'_> {
    /// Reads `key` of `table` into a new parameter of `set`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn add(
        &mut self,
        table: &Table<'_, '_>,
        set: &mut ParamSet,
        key: &'static str,
        shape: Shape,
        rule: Constraint,
        default: Fallback<'_>,
        broadcast: bool,
    ) -> Res<()> {
        let what = format!("`{key}` in {}", table.what);
        let vals: Vec<(f32, Span)> = match (table.get(key), default) {
            (Some(v), _) => {
                let vals = read_numbers(&table.src, v, shape, broadcast, &what)?;
                let plain: Vec<f32> = vals.iter().map(|x| x.0).collect();
                if let Err((i, msg)) = rule.check(&plain, 0, true) {
                    let span = if matches!(rule, Constraint::NonZero) { v.span() } else { vals[i].1.clone() };
                    return Err(table.src.value_err(&span, format!("{what} {msg}")));
                }
                vals
            }
            (None, Fallback::Value(d)) => d.iter().map(|&x| (x, table.span.clone())).collect(),
            (None, Fallback::Required(meaning)) => {
                return Err(table
                    .src
                    .missing(&table.span, format!("{} needs `{key}` ({meaning})", table.what)))
            }
        };
        let offset = self.values.len();
        for (x, s) in &vals {
            self.values.push(*x);
            self.spans.push(s.clone());
        }
        set.params.push(Param { key, offset, len: vals.len(), shape, rule, broadcast });
        Ok(())
    }
}

/// A value from the file as an error message quotes it: at most 48 characters, the rest replaced
/// by `…`, so a hostile file cannot make a message as long as itself.
pub(crate) fn echo(value: &str) -> String {
    const MAX: usize = 48;
    match value.char_indices().nth(MAX) {
        Some((cut, _)) => format!("{}…", &value[..cut]),
        None => value.to_string(),
    }
}
