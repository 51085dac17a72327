//! `[[material]]` tables and the material keys of `[[object]]`: toon ramps ([`parse_ramp`], which
//! `[[wave]]`'s `light_ramp` uses too), textures read from the scene's directory ([`scene_file`],
//! [`TextureCache`]), outlines, the object's material slots and overrides, and the animatable
//! parts (`base_color`, `wave_blend`, `outline_width`, `outline_color`); [`build_material`] gives a
//! slot's [`Material`] at one set of values.

use crate::files::SceneDir;
use crate::frame::{Filter, Material, Mesh, Outline, Ramp, RampKind, ShadingModel, TextureRef, Wrap};
use crate::limits::fmt_f32;
use crate::params::{Constraint, ParamSet, Shape};
use crate::texture::load_texture_file;
use crate::toml_read::{read_numbers, type_name, Fallback, ParamReader, Res, Table};
use hadou_math::toon::MAX_RAMP_BANDS;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::de::DeValue;

/// Keys of a `[[material]]` table.
pub(crate) const MATERIAL_KEYS: &[&str] = &[
    "name",
    "model",
    "base_color",
    "base_texture",
    "feature_texture",
    "texture_wrap",
    "texture_filter",
    "ramp",
    "ramp_kind",
    "ramp_smoothing",
    "wave_blend",
    "outline",
    "outline_width",
    "outline_color",
];
/// Material keys an `[[object]]` may carry (they apply to every material of the object).
pub(crate) const OBJECT_MATERIAL_KEYS: &[&str] =
    &["material", "materials", "wave_blend", "outline", "outline_width", "outline_color"];
/// Largest outline width `d` (a tenth of the view depth already makes a very thick outline).
pub(crate) const OUTLINE_WIDTH_MAX: f32 = 0.1;
/// Default outline width `d`: about 1.5 px at 512 px image height and a 45° field of view.
pub(crate) const DEFAULT_OUTLINE_WIDTH: f32 = 0.0025;

const UNIT: Constraint = Constraint::Range { lo: 0.0, hi: 1.0, lo_open: false, hi_open: false };
const WIDTH: Constraint =
    Constraint::Range { lo: 0.0, hi: OUTLINE_WIDTH_MAX, lo_open: false, hi_open: false };

/// A `[[material]]`: the fixed parts and the animatable ones.
#[derive(Clone, Debug)]
pub(crate) struct MaterialDef {
    pub name: String,
    /// The material with its file values (animatable parts overwritten per frame).
    pub base: Material,
    /// `base_color`, `wave_blend`, `outline_width`, `outline_color`.
    pub params: ParamSet,
}

/// Where the material of one slot of an object comes from.
#[derive(Clone, Debug)]
pub(crate) enum SlotSource {
    /// The mesh's own material of this index (a glTF material, or the default).
    Mesh(usize),
    /// A `[[material]]` of the scene, by index.
    Scene(usize),
}

/// An object's materials: one source per slot, and the object-wide overrides.
#[derive(Clone, Debug, Default)]
pub(crate) struct ObjectMaterials {
    pub slots: Vec<SlotSource>,
    /// `outline = true/false` given on the object.
    pub outline: Option<bool>,
    /// Whether `color` was given explicitly (it then sets every slot's base colour).
    pub color_given: bool,
    /// The mesh has no texture coordinates: textures of scene materials are dropped (warned).
    pub no_uvs: bool,
}

/// Reads a ramp from `key` (rows `[threshold, r, g, b]`), `{key}_kind` and `{key}_smoothing`.
/// `None` when `key` is absent (the other two must then be absent as well).
pub(crate) fn parse_ramp(t: &Table<'_, '_>, key: &str) -> Res<Option<Ramp>> {
    let kind_key = format!("{key}_kind");
    let smooth_key = format!("{key}_smoothing");
    let Some(v) = t.get(key) else {
        for other in [&kind_key, &smooth_key] {
            if t.get(other).is_some() {
                return Err(t.src.missing(
                    &t.key_span(other),
                    format!("`{other}` in {} applies to `{key}`, which is not given", t.what),
                ));
            }
        }
        return Ok(None);
    };
    let what = format!("`{key}` in {}", t.what);
    let rows = read_numbers(&t.src, v, Shape::List(4), false, &what)?;
    let n = rows.len() / 4;
    if n == 0 || n > MAX_RAMP_BANDS {
        return Err(t.src.value_err(
            &v.span(),
            format!("{what} needs 1 to {MAX_RAMP_BANDS} rows [threshold, r, g, b], got {n}"),
        ));
    }
    let mut stops = Vec::with_capacity(n);
    for (i, row) in rows.chunks_exact(4).enumerate() {
        let (th, span) = (row[0].0, &row[0].1);
        if !(-1.0..=1.0).contains(&th) {
            return Err(t.src.value_err(
                span,
                format!(
                    "threshold of row {} of {what} must be in [-1, 1] (m = N·L), got {}",
                    i + 1,
                    fmt_f32(th)
                ),
            ));
        }
        if let Some(&(prev, _)) = stops.last() {
            if th < prev {
                return Err(t.src.value_err(
                    span,
                    format!(
                        "thresholds of {what} must be sorted: row {} has {} after {}; list the bands from \
                         the darkest (m = -1) up",
                        i + 1,
                        fmt_f32(th),
                        fmt_f32(prev)
                    ),
                ));
            }
            if th == prev {
                return Err(t.src.value_err(
                    span,
                    format!("rows {} and {} of {what} overlap: both start at m = {}", i, i + 1, fmt_f32(th)),
                ));
            }
        }
        let mut c = [0.0f32; 3];
        for k in 0..3 {
            let (x, s) = &row[k + 1];
            if !(0.0..=crate::limits::COORD_MAX).contains(x) {
                return Err(t.src.value_err(
                    s,
                    format!(
                        "colour components of {what} must be in [0, {}], got {}",
                        fmt_f32(crate::limits::COORD_MAX),
                        fmt_f32(*x)
                    ),
                ));
            }
            c[k] = *x;
        }
        stops.push((th, c));
    }
    let kind = match t.choice(&kind_key, &["bands", "gradient"], Some("bands"))? {
        "gradient" => {
            if t.get(&smooth_key).is_some() {
                return Err(t.src.value_err(
                    &t.key_span(&smooth_key),
                    format!("`{smooth_key}` in {} applies to bands, not to a gradient", t.what),
                ));
            }
            RampKind::Gradient
        }
        _ => {
            let mut smoothing = 0.0;
            if let Some(v) = t.get(&smooth_key) {
                let x =
                    read_numbers(&t.src, v, Shape::Scalar, false, &format!("`{smooth_key}` in {}", t.what))?;
                if !(0.0..=2.0).contains(&x[0].0) {
                    return Err(t.src.value_err(
                        &x[0].1,
                        format!("`{smooth_key}` in {} must be in [0, 2], got {}", t.what, fmt_f32(x[0].0)),
                    ));
                }
                smoothing = x[0].0;
            }
            RampKind::Bands { smoothing }
        }
    };
    Ok(Some(Ramp { kind, stops }))
}

/// Resolves a file named by the scene: relative, inside the scene's directory tree, a regular
/// file (checked when read).
pub(crate) fn scene_file(t: &Table<'_, '_>, key: &str, rel: &str, dir: &Path, root: &Path) -> Res<PathBuf> {
    let span = t.get(key).map(|v| v.span()).unwrap_or_else(|| t.span.clone());
    let file = dir.join(rel);
    if Path::new(rel).is_absolute() || Path::new(rel).has_root() {
        return Err(t.src.value_err(
            &span,
            format!(
                "`{key}` in {} must be relative to the scene file (files must lie inside its directory)",
                t.what
            ),
        ));
    }
    let real = crate::files::canonicalize(&file).map_err(|e| {
        t.src.value_err(
            &span,
            format!("`{key}` in {}: cannot read {}: {e}", t.what, crate::error::show_path(&file)),
        )
    })?;
    if !real.starts_with(root) {
        return Err(t.src.value_err(
            &span,
            format!(
                "`{key}` in {}: {} resolves to {}, outside the scene file's directory {}",
                t.what,
                crate::error::escape_controls(rel),
                crate::error::show_path(&real),
                crate::error::show_path(root)
            ),
        ));
    }
    Ok(real)
}

/// What reading textures shares: the scene's directory (resolved when the first texture is
/// named), decoded images by path, the texels left of the scene's budget
/// ([`crate::texture::MAX_SCENE_TEXELS`]) and the warnings.
pub(crate) struct TextureCache<'w> {
    pub dir: SceneDir,
    pub images: HashMap<PathBuf, Arc<crate::frame::Texture>>,
    pub texels_left: &'w mut u64,
    pub warnings: &'w mut Vec<String>,
}

fn texture(
    t: &Table<'_, '_>,
    key: &str,
    cache: &mut TextureCache<'_>,
    wrap: [Wrap; 2],
    filter: Filter,
) -> Res<Option<TextureRef>> {
    let Some((rel, span)) = t.opt_str(key)? else { return Ok(None) };
    let root = cache.dir.root().map_err(|m| t.src.value_err(&span, m))?;
    let real = scene_file(t, key, rel, &cache.dir.path, &root)?;
    let image = match cache.images.get(&real) {
        Some(i) => i.clone(),
        None => {
            let img = load_texture_file(&real, *cache.texels_left, cache.warnings).map_err(|m| {
                let rel = crate::error::escape_controls(rel);
                t.src.value_err(&span, format!("`{key}` in {}: texture {rel}: {m}", t.what))
            })?;
            *cache.texels_left -= img.texels.len() as u64;
            let img = Arc::new(img);
            cache.images.insert(real, img.clone());
            img
        }
    };
    Ok(Some(TextureRef { image, wrap, filter }))
}

/// Parses one `[[material]]`.
pub(crate) fn parse_material(
    t: &Table<'_, '_>,
    name: String,
    rd: &mut ParamReader<'_>,
    cache: &mut TextureCache<'_>,
) -> Res<MaterialDef> {
    t.check_keys(MATERIAL_KEYS)?;
    let model = match t.choice("model", &["diffuse", "toon", "unlit"], Some("diffuse"))? {
        "toon" => ShadingModel::Toon,
        "unlit" => ShadingModel::Unlit,
        _ => ShadingModel::Diffuse,
    };
    let wrap = match t.choice("texture_wrap", &["repeat", "clamp", "mirror"], Some("repeat"))? {
        "clamp" => Wrap::Clamp,
        "mirror" => Wrap::Mirror,
        _ => Wrap::Repeat,
    };
    let filter = match t.choice("texture_filter", &["linear", "nearest"], Some("linear"))? {
        "nearest" => Filter::Nearest,
        _ => Filter::Linear,
    };
    let base_texture = texture(t, "base_texture", cache, [wrap; 2], filter)?;
    let feature_texture = texture(t, "feature_texture", cache, [wrap; 2], filter)?;
    let ramp = parse_ramp(t, "ramp")?;
    if ramp.is_some() && model != ShadingModel::Toon {
        return Err(t
            .src
            .value_err(&t.key_span("ramp"), format!("`ramp` in {} applies to `model = \"toon\"`", t.what)));
    }
    let outline = t.opt_bool("outline")?;
    let mut params = ParamSet::default();
    rd.add(
        t,
        &mut params,
        "base_color",
        Shape::Vector(3),
        Constraint::NonNeg,
        Fallback::Value(&[0.8; 3]),
        false,
    )?;
    rd.add(t, &mut params, "wave_blend", Shape::Scalar, UNIT, Fallback::Value(&[0.0]), false)?;
    rd.add(
        t,
        &mut params,
        "outline_width",
        Shape::Scalar,
        WIDTH,
        Fallback::Value(&[DEFAULT_OUTLINE_WIDTH]),
        false,
    )?;
    rd.add(
        t,
        &mut params,
        "outline_color",
        Shape::Vector(3),
        Constraint::NonNeg,
        Fallback::Value(&[0.0; 3]),
        false,
    )?;
    let mut base = Material::diffuse([0.8; 3]);
    base.name = name.clone();
    base.model = model;
    base.base_texture = base_texture;
    base.feature_texture = feature_texture;
    if let Some(r) = ramp {
        base.ramp = r;
    }
    base.outline =
        outline.unwrap_or(false).then_some(Outline { width: DEFAULT_OUTLINE_WIDTH, color: [0.0; 3] });
    Ok(MaterialDef { name, base, params })
}

/// Reads an object's material keys: `material = "name"` (every slot), or
/// `materials = { "<mesh material>" = "<scene material>", … }`, plus the object-wide overrides
/// (read into `params` only when given).
/// `by_name` maps each `[[material]]` name to its index in `scene_materials`.
pub(crate) fn parse_object_materials(
    t: &Table<'_, '_>,
    mesh: &Mesh,
    scene_materials: &[MaterialDef],
    by_name: &HashMap<&str, usize>,
    params: &mut ParamSet,
    rd: &mut ParamReader<'_>,
    warnings: &mut Vec<String>,
) -> Res<ObjectMaterials> {
    let n_slots = mesh.materials.len().max(1);
    let mut slots: Vec<SlotSource> = (0..n_slots).map(SlotSource::Mesh).collect();
    let find = |name: &str, span: &crate::toml_read::Span| -> Res<usize> {
        by_name.get(name).copied().ok_or_else(|| {
            let names: Vec<&str> = scene_materials.iter().map(|m| m.name.as_str()).collect();
            t.src.value_err(
                span,
                format!("no [[material]] is named \"{name}\"{}", crate::error::hint(name, &names, "names")),
            )
        })
    };
    if let Some((name, span)) = t.opt_str("material")? {
        if t.get("materials").is_some() {
            return Err(t.src.value_err(
                &t.key_span("materials"),
                format!("{} gives `material`; give either `material` (every slot) or `materials` (by name), not both", t.what),
            ));
        }
        let i = find(name, &span)?;
        slots.iter_mut().for_each(|s| *s = SlotSource::Scene(i));
    }
    if let Some(v) = t.get("materials") {
        let DeValue::Table(map) = v.get_ref() else {
            return Err(t.src.type_err(
                &v.span(),
                format!(
                    "`materials` in {} must be a table {{ \"<material of the mesh>\" = \"<[[material]] name>\" }}, got {}",
                    t.what,
                    type_name(v.get_ref())
                ),
            ));
        };
        // The mesh's materials by name (the first of equal names), built once per object.
        let mut mesh_slots: HashMap<&str, usize> = HashMap::with_capacity(mesh.materials.len());
        for (i, m) in mesh.materials.iter().enumerate() {
            mesh_slots.entry(m.name.as_str()).or_insert(i);
        }
        for (k, val) in map.iter() {
            let key = k.get_ref().as_ref();
            let DeValue::String(target) = val.get_ref() else {
                return Err(t.src.type_err(
                    &val.span(),
                    format!("`materials.{key}` in {} must be the name of a [[material]]", t.what),
                ));
            };
            let Some(&slot) = mesh_slots.get(key) else {
                let names: Vec<&str> = mesh.materials.iter().map(|m| m.name.as_str()).collect();
                let have = if names.is_empty() {
                    " (the mesh has no named materials; use `material = \"…\"`)".to_string()
                } else {
                    crate::error::hint(key, &names, "materials of the mesh")
                };
                return Err(t.src.value_err(
                    &k.span(),
                    format!("the mesh of {} has no material \"{key}\"{have}", t.what),
                ));
            };
            slots[slot] = SlotSource::Scene(find(target, &val.span())?);
        }
    }
    for (key, shape, rule) in [
        ("wave_blend", Shape::Scalar, UNIT),
        ("outline_width", Shape::Scalar, WIDTH),
        ("outline_color", Shape::Vector(3), Constraint::NonNeg),
    ] {
        if t.get(key).is_some() {
            rd.add(t, params, key, shape, rule, Fallback::Value(&[]), false)?;
        }
    }
    let textured = slots.iter().any(|s| match s {
        SlotSource::Scene(i) => {
            let m = &scene_materials[*i].base;
            m.base_texture.is_some() || m.feature_texture.is_some()
        }
        SlotSource::Mesh(_) => false,
    });
    let no_uvs = mesh.uvs.is_empty() && textured;
    if no_uvs {
        let at = t.src.loc(&t.span);
        warnings.push(format!(
            "{}:{}: {} has no texture coordinates; the base and feature textures of its materials are \
             ignored (features off)",
            at.line, at.col, t.what
        ));
    }
    Ok(ObjectMaterials {
        slots,
        outline: t.opt_bool("outline")?,
        color_given: t.get("color").is_some(),
        no_uvs,
    })
}

/// The material of one slot at the values `vals`.
pub(crate) fn build_material(
    source: &SlotSource,
    mesh: &Mesh,
    scene_materials: &[MaterialDef],
    object: &ObjectMaterials,
    object_params: &ParamSet,
    vals: &[f32],
) -> Material {
    let mut m = match source {
        SlotSource::Mesh(i) => {
            let mut m = mesh.materials.get(*i).cloned().unwrap_or_default();
            if object.color_given || mesh.materials.is_empty() {
                m.base_color = object_params.arr(vals, "color");
            }
            m
        }
        SlotSource::Scene(i) => {
            let d = &scene_materials[*i];
            let mut m = d.base.clone();
            if object.no_uvs {
                m.base_texture = None;
                m.feature_texture = None;
            }
            m.base_color = d.params.arr(vals, "base_color");
            m.wave_blend = d.params.f(vals, "wave_blend");
            if let Some(o) = &mut m.outline {
                o.width = d.params.f(vals, "outline_width");
                o.color = d.params.arr(vals, "outline_color");
            }
            m
        }
    };
    if let Some(on) = object.outline {
        m.outline =
            on.then_some(m.outline.unwrap_or(Outline { width: DEFAULT_OUTLINE_WIDTH, color: [0.0; 3] }));
    }
    if object_params.find("wave_blend").is_some() {
        m.wave_blend = object_params.f(vals, "wave_blend");
    }
    if let Some(o) = &mut m.outline {
        if object_params.find("outline_width").is_some() {
            o.width = object_params.f(vals, "outline_width");
        }
        if object_params.find("outline_color").is_some() {
            o.color = object_params.arr(vals, "outline_color");
        }
    }
    m
}
