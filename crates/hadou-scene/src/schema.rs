//! The scene schema: TOML tables → [`Scene`], with every value range-checked at load and every
//! error pointing at the offending key or value. The schema is documented key by key in
//! `docs/scene-format.md`.
//!
//! [`Scene::load`], [`Scene::read_text`] and [`Scene::parse`]: the file's tables in order, the
//! top-level `background`, and the cross-key rules, checked on the file's values and again at
//! every key time of every track. Each table has its reader: `[image]` and `[camera]` in
//! `camera_def.rs`, `[light]` and `[color]` in `light_def.rs`, `[[object]]`, `[[wave]]`,
//! `[[material]]`, `[[shadow]]`, `[area_light]`, `[bloom]` and `[[track]]` in `object_def.rs`,
//! `wave_def.rs`, `materials.rs`, `shadow_def.rs`, `area_light_def.rs`, `bloom_def.rs` and
//! `track_def.rs`.

use crate::area_light::SOFT_MAX_PIXELS;
use crate::area_light_def::{check_area_light, interest_at, parse_area_light, Target};
use crate::bloom_def::parse_bloom;
use crate::bounds::mesh_center;
use crate::camera_def::{check_camera, parse_camera, parse_image};
use crate::error::{Location, SceneError};
use crate::files::{parent_dir, read_regular_file, SceneDir, SCENE_MAX_BYTES};
use crate::gltf_load::Budget;
use crate::light_def::{parse_color, parse_light};
use crate::limits::{fmt_f32, MAX_KEY_CHECKS, MAX_MATERIAL_SLOTS, MAX_WAVES};
use crate::materials::{parse_material, MaterialDef, TextureCache};
use crate::object_def::{parse_object, Assets};
use crate::params::{ParamSet, NONNEG, V3};
use crate::scene::{ObjectDef, Scene, WaveDef};
use crate::shadow::{MAX_SHADOWS, MAX_SHADOW_CASTERS, MAX_SHADOW_TRIANGLES};
use crate::shadow_def::{check_map_budget, check_shadow, parse_shadow, ShadowDef};
use crate::toml_read::{Fallback, ParamReader, Res, Span, Src, Table};
use crate::track_def::{parse_track, Names, Owner};
use crate::wave_def::{check_wave_rules, parse_wave, validate_curve};
use hadou_math::Vec3f;
use std::collections::HashMap;
use std::path::Path;
use toml::de::DeTable;

const ROOT_KEYS: &[&str] = &[
    "image",
    "camera",
    "background",
    "light",
    "color",
    "material",
    "object",
    "wave",
    "shadow",
    "area_light",
    "bloom",
    "track",
];

impl Scene {
    /// Reads and parses the scene file at `path`. glTF paths in it are relative to its directory.
    pub fn load(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
        let path = path.as_ref();
        Self::parse(&Self::read_text(path)?, path)
    }

    /// The scene file's text, read as [`Scene::load`] reads it: a regular file of at most
    /// [`SCENE_MAX_BYTES`], UTF-8.
    pub fn read_text(path: &Path) -> Result<String, SceneError> {
        let bytes = read_regular_file(path, SCENE_MAX_BYTES).map_err(|e| SceneError::Io {
            path: path.to_path_buf(),
            message: format!("cannot read the scene file: {e}"),
        })?;
        String::from_utf8(bytes).map_err(|e| SceneError::Io {
            path: path.to_path_buf(),
            message: format!("the scene file is not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        })
    }

    /// Parses scene `text`; `path` names the file in messages and anchors relative asset paths.
    pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
        parse_scene(text, path)
    }
}

/// Parses a whole scene.
pub(crate) fn parse_scene(text: &str, path: &Path) -> Res<Scene> {
    let src = Src { text, path };
    let parsed = crate::guard::guarded("TOML", || DeTable::parse(text))
        .map_err(|message| SceneError::Syntax { at: Location::from_offset(path, text, 0), message })?;
    let doc = parsed.map_err(|e| SceneError::Syntax {
        at: Location::from_offset(path, text, e.span().map_or(0, |s| s.start)),
        message: format!("invalid TOML: {}", e.message().trim().replace('\n', "; ")),
    })?;
    let root = Table { src, t: doc.get_ref(), span: 0..0, what: "the top level".into() };
    root.check_keys(ROOT_KEYS)?;

    let mut values = Vec::new();
    let mut spans = Vec::new();
    let mut rd = ParamReader { values: &mut values, spans: &mut spans };

    let empty = DeTable::new();
    let sub_or_empty = |key: &str, what: &str| -> Res<Table<'_, '_>> {
        Ok(root.sub(key, what)?.unwrap_or(Table { src, t: &empty, span: 0..0, what: what.into() }))
    };
    let (width, height, samples) = parse_image(root.sub("image", "[image]")?.as_ref())?;
    let camera = parse_camera(&sub_or_empty("camera", "[camera]")?, &mut rd)?;
    let light = parse_light(&sub_or_empty("light", "[light]")?, &mut rd)?;
    let (tone, color) = parse_color(&sub_or_empty("color", "[color]")?, &mut rd)?;

    // background (top level)
    let mut globals = ParamSet::default();
    rd.add(&root, &mut globals, "background", V3, NONNEG, Fallback::Value(&[0.0; 3]), false)?;

    let dir = parent_dir(path).to_path_buf();
    let mut assets = Assets {
        dir: SceneDir::new(dir),
        cache: HashMap::new(),
        budget: Budget::FULL,
        slots_left: MAX_MATERIAL_SLOTS,
    };
    let mut warnings = Vec::new();

    // [[material]]
    let mut materials: Vec<MaterialDef> = Vec::new();
    let mut names: HashMap<String, Span> = HashMap::new();
    let material_tables = root.array_of_tables("material")?;
    if !material_tables.is_empty() {
        let mut cache = TextureCache {
            dir: SceneDir::new(assets.dir.path.clone()),
            images: HashMap::new(),
            texels_left: &mut assets.budget.texels,
            warnings: &mut warnings,
        };
        for (i, (t, span)) in material_tables.into_iter().enumerate() {
            let table = Table { src, t, span, what: format!("[[material]] #{}", i + 1) };
            let name = entity_name(&table, &mut names, "material")?;
            let table = Table { what: format!("[[material]] \"{name}\""), ..table };
            materials.push(parse_material(&table, name, &mut rd, &mut cache)?);
        }
    }

    // [[object]]
    let mut objects: Vec<ObjectDef> = Vec::new();
    let mut names: HashMap<String, Span> = HashMap::new();
    let material_index: HashMap<&str, usize> =
        materials.iter().enumerate().map(|(i, m)| (m.name.as_str(), i)).collect();
    for (i, (t, span)) in root.array_of_tables("object")?.into_iter().enumerate() {
        let table = Table { src, t, span, what: format!("[[object]] #{}", i + 1) };
        let name = entity_name(&table, &mut names, "object")?;
        let table = Table { what: format!("[[object]] \"{name}\""), ..table };
        let mats = (&materials[..], &material_index);
        objects.push(parse_object(&table, name, &mut rd, &mut assets, mats, &mut warnings)?);
    }

    // [[wave]]
    let mut waves: Vec<WaveDef> = Vec::new();
    let mut wave_tables = Vec::new();
    let mut names: HashMap<String, Span> = HashMap::new();
    for (i, (t, span)) in root.array_of_tables("wave")?.into_iter().enumerate() {
        if i == MAX_WAVES {
            return Err(src.value_err(
                &span,
                format!("a scene may have at most {MAX_WAVES} waves; this is wave #{}", i + 1),
            ));
        }
        let table = Table { src, t, span, what: format!("[[wave]] #{}", i + 1) };
        let name = entity_name(&table, &mut names, "wave")?;
        let table = Table { what: format!("[[wave]] \"{name}\""), ..table };
        waves.push(parse_wave(&table, name, &mut rd)?);
        wave_tables.push(table);
    }

    // An object's `look_at` naming a wave.
    for o in &mut objects {
        if let Some(crate::look_at::LookTarget::WaveName(name, span)) = &o.look_at {
            let Some(i) = waves.iter().position(|w| &w.name == name) else {
                let list = waves.iter().map(|w| format!("\"{}\"", w.name)).collect::<Vec<_>>().join(", ");
                return Err(src.unknown(
                    span,
                    format!(
                        "`look_at` of [[object]] \"{}\" names no wave \"{}\" (nor \"camera\"); the waves are {}",
                        o.name,
                        crate::toml_read::echo(name),
                        if list.is_empty() { "none".to_string() } else { list }
                    ),
                ));
            };
            o.look_at = Some(crate::look_at::LookTarget::Wave(i));
        }
    }

    // [[shadow]]
    let mut shadows: Vec<ShadowDef> = Vec::new();
    let mut shadow_tables = Vec::new();
    let mut names: HashMap<String, Span> = HashMap::new();
    {
        let object_names: Vec<(&str, bool)> = objects.iter().map(|o| (o.name.as_str(), o.is_plane)).collect();
        let wave_names: Vec<&str> = waves.iter().map(|w| w.name.as_str()).collect();
        let (mut casters, mut cast_triangles) = (0usize, 0u64);
        for (i, (t, span)) in root.array_of_tables("shadow")?.into_iter().enumerate() {
            if i == MAX_SHADOWS {
                return Err(src.value_err(
                    &span,
                    format!("a scene may have at most {MAX_SHADOWS} shadows; this is shadow #{}", i + 1),
                ));
            }
            let table = Table { src, t, span, what: format!("[[shadow]] #{}", i + 1) };
            let name = entity_name(&table, &mut names, "shadow")?;
            let table = Table { what: format!("[[shadow]] \"{name}\""), ..table };
            let def = parse_shadow(&table, name, &object_names, &wave_names, &mut rd)?;
            if let Err((key, msg)) = check_shadow(&def, rd.values) {
                return Err(src.value_err(&table.key_span(key), format!("{msg} in {}", table.what)));
            }
            // What every frame's casts cost: one per caster of a wave shadow, and each caster's
            // triangles projected or rasterized once per shadow.
            casters += def.casters.len();
            cast_triangles +=
                def.casters.iter().map(|&c| (objects[c as usize].mesh.indices.len() / 3) as u64).sum::<u64>();
            if casters > MAX_SHADOW_CASTERS || cast_triangles > MAX_SHADOW_TRIANGLES {
                return Err(src.value_err(
                    &table.key_span("casters"),
                    format!(
                        "{} brings the casters of all shadows to {casters} and the triangles they cast to \
                         {cast_triangles}; at most {MAX_SHADOW_CASTERS} casters and {MAX_SHADOW_TRIANGLES} \
                         triangles (each shadow's casters counted) fit a scene",
                        table.what
                    ),
                ));
            }
            shadows.push(def);
            shadow_tables.push(table);
        }
        if let Err((i, msg)) = check_map_budget(&shadows) {
            let t = &shadow_tables[i];
            let span = if t.get("map_size").is_some() { t.key_span("map_size") } else { t.span.clone() };
            return Err(src.value_err(&span, format!("{msg} ({})", t.what)));
        }
    }

    // [area_light]
    let mut area_light = None;
    let mut area_table = None;
    if let Some(t) = root.sub("area_light", "[area_light]")? {
        let names: Vec<(&str, bool)> = objects.iter().map(|o| (o.name.as_str(), o.is_plane)).collect();
        area_light = Some(parse_area_light(&t, &names, &mut rd)?);
        if u64::from(width) * u64::from(height) > SOFT_MAX_PIXELS {
            return Err(src.value_err(
                &t.span,
                format!(
                    "[area_light] needs an image of at most {SOFT_MAX_PIXELS} pixels (4096²; the penumbra search works on the \
                     whole image at once); this one is {width}×{height}"
                ),
            ));
        }
        area_table = Some(t);
    }

    // [bloom]
    let (bloom, bloom_at) = match root.sub("bloom", "[bloom]")? {
        Some(t) => {
            let at = src.loc(&t.span);
            crate::limits::check_image_size_with(width, height, false, Some(&at))
                .map_err(|m| src.value_err(&t.span, format!("[image] {width}×{height}: {m}")))?;
            (Some(parse_bloom(&t, &mut rd)?), Some(at))
        }
        None => (None, None),
    };

    let mut scene = Scene {
        path: path.to_path_buf(),
        width,
        height,
        samples,
        values,
        camera,
        light,
        color,
        globals,
        tone,
        materials,
        objects,
        waves,
        shadows,
        area_light,
        bloom,
        bloom_at,
        tracks: Vec::new(),
        // A warning may quote any file's text (a bone's, a material's or an extension's name):
        // its control characters are escaped here, once for every loader, as errors are when
        // shown.
        warnings: warnings.iter().map(|w| crate::error::escape_controls(w).into_owned()).collect(),
    };

    // The curve maths' own rules (limits on control points, order, terms, …), on the file's values.
    for (w, table) in scene.waves.iter().zip(&wave_tables) {
        if let Err((key, msg)) = validate_curve(&scene, w, &scene.values) {
            return Err(src.value_err(&table.key_span(key), format!("`{key}` in {} {msg}", table.what)));
        }
    }

    // The most work a pixel may cost, at the file's samples.
    if let Err((i, msg)) = scene.check_pixel_work(scene.samples) {
        return Err(src.value_err(&wave_tables[i].span, msg));
    }

    if let (Some(a), Some(t)) = (&scene.area_light, &area_table) {
        let vals = &scene.values;
        let g = interest_at(a, vals, |o| {
            let local = mesh_center(&scene.objects[o].mesh).unwrap_or(Vec3f::ZERO);
            scene.objects[o].transform(vals).transform_point(local)
        });
        if let Err((key, msg)) = check_area_light(a, vals, g) {
            return Err(src.value_err(&t.key_span(key), format!("{msg} in [area_light]")));
        }
    }

    // [[track]]
    let mut targets: HashMap<String, Span> = HashMap::new();
    let mut tracks = Vec::new();
    let mut owners = Vec::new();
    let mut key_spans: Vec<Vec<Span>> = Vec::new();
    {
        let names = Names::of(&scene);
        for (i, (t, span)) in root.array_of_tables("track")?.into_iter().enumerate() {
            let table = Table { src, t, span, what: format!("[[track]] #{}", i + 1) };
            let (track, owner, spans) = parse_track(&table, &scene, &names, &mut targets)?;
            tracks.push(track);
            owners.push(owner);
            key_spans.push(spans);
        }
    }
    scene.tracks = tracks;
    check_key_times(&scene, &owners, &key_spans, &src)?;
    Ok(scene)
}

/// Reads and checks `name`: present, a string of letters, digits, `_` and `-`, unique.
fn entity_name(table: &Table<'_, '_>, names: &mut HashMap<String, Span>, what: &str) -> Res<String> {
    let (name, span) =
        table.req_str("name", &format!("a unique name, used by tracks as `{what}.<name>.<key>`"))?;
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
        return Err(table.src.value_err(
            &span,
            format!("{what} name \"{name}\" may contain only letters, digits, `_` and `-` (it is used in track targets)"),
        ));
    }
    if let Some(first) = names.get(name) {
        let at = table.src.loc(first);
        return Err(table.src.duplicate(
            &span,
            format!(
                "duplicate {what} name \"{name}\" (first used at line {}); names must be unique",
                at.line
            ),
        ));
    }
    names.insert(name.to_string(), span);
    Ok(name.to_string())
}

/// The parts of a scene with rules between their keys: each is checked at the key times of the
/// tracks that animate it (the area light also at those of its target object), on its own values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Rules {
    Camera,
    Light,
    AreaLight,
    Shadow(usize),
    Wave(usize),
}

/// The rules a track animating `owner` can break (`None`: no rule reads its values).
fn rules_of(scene: &Scene, owner: Owner) -> Option<Rules> {
    match owner {
        Owner::Camera => Some(Rules::Camera),
        Owner::Light => Some(Rules::Light),
        Owner::AreaLight => Some(Rules::AreaLight),
        Owner::Object(i) if scene.area_light.as_ref().is_some_and(|a| a.target == Target::Object(i)) => {
            Some(Rules::AreaLight)
        }
        Owner::Shadow(i) => Some(Rules::Shadow(i)),
        Owner::Wave(i) => Some(Rules::Wave(i)),
        Owner::Globals | Owner::Color | Owner::Bloom | Owner::Object(_) | Owner::Material(_) => None,
    }
}

/// The parameter sets `rules` reads.
fn rule_sets(scene: &Scene, rules: Rules) -> Vec<&ParamSet> {
    match rules {
        Rules::Camera => vec![&scene.camera],
        Rules::Light => vec![&scene.light],
        Rules::AreaLight => {
            let Some(a) = &scene.area_light else { return Vec::new() };
            match a.target {
                Target::Object(o) => vec![&a.params, &scene.objects[o].params],
                Target::Point => vec![&a.params],
            }
        }
        Rules::Shadow(i) => vec![&scene.shadows[i].params],
        Rules::Wave(i) => vec![&scene.waves[i].params],
    }
}

/// The rules between keys, checked at every key time of the tracks that animate each part of the
/// scene ([`Rules`]), on that part's values there (its tracks applied and clamped as
/// [`Scene::at`] does). A part nothing animates keeps the file's values, checked at load.
/// The work, key times × the numbers of the part, is bounded by [`MAX_KEY_CHECKS`] first.
fn check_key_times(scene: &Scene, owners: &[Owner], key_spans: &[Vec<Span>], src: &Src<'_>) -> Res<()> {
    let groups: Vec<Option<Rules>> = owners.iter().map(|&o| rules_of(scene, o)).collect();
    // The tracks of each part, in file order, and its distinct key times.
    let mut members: HashMap<Rules, Vec<usize>> = HashMap::new();
    let mut times: HashMap<Rules, std::collections::HashSet<u32>> = HashMap::new();
    for (i, g) in groups.iter().enumerate() {
        if let Some(g) = *g {
            members.entry(g).or_default().push(i);
            times.entry(g).or_default().extend(scene.tracks[i].times.iter().map(|t| t.to_bits()));
        }
    }
    let mut work = 0u64;
    for (i, g) in groups.iter().enumerate() {
        let Some(g) = *g else { continue };
        if members[&g][0] != i {
            continue;
        }
        let numbers: usize =
            rule_sets(scene, g).iter().map(|s| s.params.iter().map(|p| p.len).sum::<usize>()).sum();
        let keys = times[&g].len() as u64;
        work = work.saturating_add(keys.saturating_mul(numbers as u64));
        if work > MAX_KEY_CHECKS {
            return Err(src.track(
                &key_spans[i][0],
                format!(
                    "the rules between keys are checked at each key time of the tracks of the part they \
                     concern; `{}` and the other tracks of its part have {keys} key times over {numbers} \
                     numbers, which brings the scene's checks past the limit of {MAX_KEY_CHECKS} (key times \
                     × numbers); use fewer keys",
                    scene.tracks[i].target
                ),
            ));
        }
    }
    // The target object's centre in its own space (its mesh's bounds are fixed).
    let target_center = scene.area_light.as_ref().and_then(|a| match a.target {
        Target::Object(o) => Some((o, mesh_center(&scene.objects[o].mesh).unwrap_or(Vec3f::ZERO))),
        Target::Point => None,
    });
    let mut vals = scene.values.clone();
    let mut done: std::collections::HashSet<(Rules, u32)> = std::collections::HashSet::new();
    for ((track, spans), g) in scene.tracks.iter().zip(key_spans).zip(&groups) {
        let Some(g) = *g else { continue };
        for (&time, span) in track.times.iter().zip(spans) {
            if !done.insert((g, time.to_bits())) {
                continue;
            }
            for &j in &members[&g] {
                let t = &scene.tracks[j];
                if let Some(out) = vals.get_mut(t.offset..t.offset + t.len) {
                    t.eval(time, out);
                }
            }
            for set in rule_sets(scene, g) {
                scene.clamp_params(set, &mut vals);
            }
            let centre = |o: usize, vals: &[f32]| {
                let local = target_center.map_or(Vec3f::ZERO, |(_, c)| c);
                scene.objects[o].transform(vals).transform_point(local)
            };
            if let Err(msg) = check_rules(scene, g, &vals, centre) {
                return Err(src.track(
                    span,
                    format!("at t = {} s (this key of `{}`): {msg}", fmt_f32(time), track.target),
                ));
            }
        }
    }
    Ok(())
}

/// The cross-key rules of one part of the scene for the values `vals` (`centre(o, vals)`: the
/// centre of object `o` there).
fn check_rules(
    scene: &Scene,
    rules: Rules,
    vals: &[f32],
    centre: impl Fn(usize, &[f32]) -> Vec3f,
) -> Result<(), String> {
    match rules {
        Rules::Camera => check_camera(&scene.camera, vals).map_err(|e| format!("{} in [camera]", e.1)),
        Rules::Light => {
            if Vec3f::from_array(scene.light.arr(vals, "direction")).try_normalize().is_none() {
                return Err("`direction` in [light] must not be the zero vector".into());
            }
            Ok(())
        }
        Rules::AreaLight => {
            let Some(a) = &scene.area_light else { return Ok(()) };
            let g = interest_at(a, vals, |o| centre(o, vals));
            check_area_light(a, vals, g).map_err(|e| format!("{} in [area_light]", e.1))
        }
        Rules::Shadow(i) => {
            let s = &scene.shadows[i];
            check_shadow(s, vals).map_err(|e| format!("{} in [[shadow]] \"{}\"", e.1, s.name))
        }
        Rules::Wave(i) => check_wave_rules(scene, &scene.waves[i], vals),
    }
}
