//! The reader of `[[object]]` tables: primitives (box, sphere, plane) within the scene's triangle
//! budget, glTF and VRM files read from the scene's folder (their material slots, and a character's
//! animation: clip, start, speed, loop, time and VRM expressions).

use crate::error::{show_path, SceneError};
use crate::files::SceneDir;
use crate::frame::Mesh;
use crate::gltf_load::Budget;
use crate::limits::{fmt_f32, COORD_MAX, MAX_MATERIAL_SLOTS, MAX_TRIANGLES, MAX_VERTICES, SCALE_MIN};
use crate::materials::{parse_object_materials, MaterialDef, OBJECT_MATERIAL_KEYS};
use crate::mesh::{box_mesh, plane_mesh, sphere_mesh, sphere_size, with_outline_normals};
use crate::params::{Constraint, Param, ParamSet, Shape, ANY, NONNEG, POSITIVE, S, V3};
use crate::rig::{Clip, Rig};
use crate::scene::Motion;
use crate::scene::ObjectDef;
use crate::toml_read::{echo, read_numbers, Fallback, ParamReader, Res, Span, Table};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

const OBJECT_KINDS: &[&str] = &["box", "sphere", "plane", "gltf"];
const OBJECT_COMMON: &[&str] = &["name", "kind", "position", "rotation", "scale", "color"];

/// What loading the objects' meshes shares: the glTF cache (by canonical path), the scene's
/// triangle budget, the material slots left of [`MAX_MATERIAL_SLOTS`] and the directory tree
/// files may be read from.
pub(crate) struct Assets {
    /// The scene file's directory.
    pub(crate) dir: SceneDir,
    /// Meshes (and rigs) read so far, by canonical path.
    pub(crate) cache: HashMap<PathBuf, (Arc<Mesh>, Option<Arc<Rig>>)>,
    /// What is left of the scene's triangle and vertex budget.
    pub(crate) budget: Budget,
    /// Material slots left of `MAX_MATERIAL_SLOTS`.
    pub(crate) slots_left: u64,
}

pub(crate) fn parse_object(
    t: &Table<'_, '_>,
    name: String,
    rd: &mut ParamReader<'_>,
    assets: &mut Assets,
    (materials, material_index): (&[MaterialDef], &HashMap<&str, usize>),
    warnings: &mut Vec<String>,
) -> Res<ObjectDef> {
    let kind = t.choice("kind", OBJECT_KINDS, None)?;
    let extra: &[&str] = match kind {
        "box" => &["size"],
        "sphere" => &["radius", "segments"],
        "plane" => &["size"],
        _ => &["path"],
    };
    let motion_keys: &[&str] = if kind == "gltf" { MOTION_KEYS } else { &[] };
    let spring_keys: &[&str] = if kind == "gltf" { &["spring", "look_at"] } else { &[] };
    let allowed: Vec<&str> = OBJECT_COMMON
        .iter()
        .chain(OBJECT_MATERIAL_KEYS)
        .chain(extra)
        .chain(motion_keys)
        .chain(spring_keys)
        .copied()
        .collect();
    t.check_keys(&allowed)?;
    if t.get("color").is_some() && (t.get("material").is_some() || t.get("materials").is_some()) {
        let other = if t.get("material").is_some() { "material" } else { "materials" };
        return Err(t.src.value_err(
            &t.key_span("color"),
            format!(
                "{} gives `{other}`; set the colour as `base_color` of the [[material]] instead of `color`",
                t.what
            ),
        ));
    }

    // Structural values: read through a scratch store.
    let mut scratch_v = Vec::new();
    let mut scratch_s = Vec::new();
    let mut scratch = ParamReader { values: &mut scratch_v, spans: &mut scratch_s };
    let mut shape_set = ParamSet::default();
    let mut gltf = None;
    let mut rig: Option<Arc<Rig>> = None;
    let mesh = match kind {
        "box" => {
            scratch.add(t, &mut shape_set, "size", V3, POSITIVE, Fallback::Value(&[1.0; 3]), false)?;
            Arc::new(with_outline_normals(box_mesh(shape_set.arr(&scratch_v, "size"))))
        }
        "plane" => {
            scratch.add(
                t,
                &mut shape_set,
                "size",
                Shape::Vector(2),
                POSITIVE,
                Fallback::Value(&[10.0, 10.0]),
                false,
            )?;
            Arc::new(with_outline_normals(plane_mesh(shape_set.arr(&scratch_v, "size"))))
        }
        "sphere" => {
            scratch.add(t, &mut shape_set, "radius", S, POSITIVE, Fallback::Value(&[1.0]), false)?;
            let segments = t.opt_int("segments", 3, 1024)?.map_or(32, |v| v.0 as u32);
            let (tris, verts) = sphere_size(segments);
            primitive_budget(t, &mut assets.budget.clone(), tris, verts)?;
            Arc::new(with_outline_normals(sphere_mesh(shape_set.f(&scratch_v, "radius"), segments)))
        }
        _ => {
            let (rel, span) = t.req_str("path", "the .gltf or .glb file, relative to the scene file")?;
            gltf = Some(PathBuf::from(rel));
            let gltf_err =
                |message: String, file: PathBuf| SceneError::Gltf { at: t.src.loc(&span), file, message };
            let (file, real, root) = resolve_asset(t, rel, &span, &mut assets.dir)?;
            match assets.cache.get(&real) {
                Some((m, r)) => {
                    rig = r.clone();
                    let tris = (m.indices.len() / 3) as u64;
                    let verts = m.positions.len() as u64;
                    if tris > assets.budget.triangles || verts > assets.budget.vertices {
                        return Err(gltf_err(
                            format!(
                                "this instance brings the scene past the limit of {MAX_TRIANGLES} \
                                     triangles or {MAX_VERTICES} vertices"
                            ),
                            file,
                        ));
                    }
                    assets.budget.triangles -= tris;
                    assets.budget.vertices -= verts;
                    m.clone()
                }
                None => {
                    let mut notes = Vec::new();
                    let (mesh, r) =
                        crate::gltf_load::load_gltf_in(&real, &root, &mut assets.budget, &mut notes)
                            .map_err(|message| gltf_err(message, file.clone()))?;
                    warnings.extend(notes.into_iter().map(|n| format!("{}: {n}", show_path(&file))));
                    let mesh = Arc::new(with_outline_normals(mesh));
                    rig = r.map(Arc::new);
                    assets.cache.insert(real, (mesh.clone(), rig.clone()));
                    mesh
                }
            }
        }
    };
    if kind != "gltf" {
        // A sphere's size was checked before it was built; boxes and planes are small.
        let (tris, verts) = ((mesh.indices.len() / 3) as u64, mesh.positions.len() as u64);
        primitive_budget(t, &mut assets.budget, tris, verts)?;
    }

    let mut params = ParamSet::default();
    rd.add(t, &mut params, "position", V3, ANY, Fallback::Value(&[0.0; 3]), false)?;
    rd.add(t, &mut params, "rotation", V3, ANY, Fallback::Value(&[0.0; 3]), false)?;
    let scale = Constraint::Range { lo: SCALE_MIN, hi: COORD_MAX, lo_open: false, hi_open: false };
    rd.add(t, &mut params, "scale", V3, scale, Fallback::Value(&[1.0; 3]), true)?;
    rd.add(t, &mut params, "color", V3, NONNEG, Fallback::Value(&[0.8; 3]), false)?;
    let slots = mesh.materials.len().max(1) as u64;
    if slots > assets.slots_left {
        let key = if kind == "gltf" { "path" } else { "kind" };
        return Err(t.src.value_err(
            &t.key_span(key),
            format!(
                "{} brings the scene past the limit of {MAX_MATERIAL_SLOTS} material slots of all objects \
                 together (an object has one per material of its mesh, at least one)",
                t.what
            ),
        ));
    }
    assets.slots_left -= slots;
    let materials = parse_object_materials(t, &mesh, materials, material_index, &mut params, rd, warnings)?;
    let motion = parse_motion(t, rig.as_deref(), &mut params, rd, &mut assets.dir, warnings)?;
    let spring = match t.opt_bool("spring")? {
        Some(true) if rig.as_ref().and_then(|r| r.springs()).is_none() => {
            return Err(t.src.value_err(
                &t.key_span("spring"),
                format!("{} gives `spring = true`, but its glTF file has no VRM spring bones", t.what),
            ))
        }
        Some(s) => s,
        None => true,
    };
    let look_at = parse_look_at(t, rig.as_deref(), &mut params, rd)?;
    Ok(ObjectDef {
        name,
        mesh,
        params,
        materials,
        is_plane: kind == "plane",
        gltf,
        rig,
        motion,
        pose_cache: Default::default(),
        spring,
        spring_cache: Default::default(),
        look_at,
    })
}

/// A `kind = "gltf"` object's `look_at`: `"camera"`, a wave's name (resolved once the waves are
/// read) or a point `[x, y, z]` (an animatable parameter).
fn parse_look_at(
    t: &Table<'_, '_>,
    rig: Option<&Rig>,
    params: &mut ParamSet,
    rd: &mut ParamReader<'_>,
) -> Res<Option<crate::look_at::LookTarget>> {
    use crate::look_at::LookTarget;
    let Some(v) = t.get("look_at") else { return Ok(None) };
    if rig.and_then(|r| r.look_at.as_ref()).is_none() {
        return Err(t.src.value_err(
            &t.key_span("look_at"),
            format!(
                "{} gives `look_at`, but its glTF file has no VRM look-at (a head bone and `lookAt` with eye \
                 bones or look expressions)",
                t.what
            ),
        ));
    }
    if let Some((name, span)) = t.opt_str("look_at").ok().flatten() {
        return Ok(Some(if name == "camera" {
            LookTarget::Camera
        } else {
            LookTarget::WaveName(name.to_string(), span)
        }));
    }
    let _ = v;
    rd.add(t, params, "look_at", V3, ANY, Fallback::Value(&[0.0; 3]), false)?;
    Ok(Some(LookTarget::Point))
}

/// The animation keys of a `kind = "gltf"` object.
const MOTION_KEYS: &[&str] = &[
    "animation",
    "animation_file",
    "animation_start",
    "animation_speed",
    "animation_loop",
    "animation_time",
    "expressions",
];

/// A `kind = "gltf"` object's animation keys: `animation` (a clip of the file), `animation_start`,
/// `animation_speed`, `animation_loop`, `animation_time`, and `expressions` (a table of the VRM
/// expressions' weights). `None` when it gives none of them (the object is drawn at its rest pose).
fn parse_motion(
    t: &Table<'_, '_>,
    rig: Option<&Rig>,
    params: &mut ParamSet,
    rd: &mut ParamReader<'_>,
    dir: &mut SceneDir,
    warnings: &mut Vec<String>,
) -> Res<Option<Motion>> {
    if MOTION_KEYS.iter().all(|k| t.get(k).is_none()) {
        return Ok(None);
    }
    let no_rig = |key: &str, what: &str| {
        t.src
            .value_err(&t.key_span(key), format!("{} gives `{key}`, but its glTF file has no {what}", t.what))
    };
    let clip: Option<Arc<Clip>> = match (t.opt_str("animation_file")?, t.opt_str("animation")?) {
        (Some((rel, span)), name) => {
            let Some(rig) = rig else { return Err(no_rig("animation_file", "VRM humanoid")) };
            let (file, real, root) = resolve_asset(t, rel, &span, dir)?;
            let mut notes = Vec::new();
            let clip = crate::gltf_vrma::load_vrma(&real, &root, rig, name.map(|n| n.0), &mut notes)
                .map_err(|message| SceneError::Gltf { at: t.src.loc(&span), file: file.clone(), message })?;
            warnings.extend(notes.into_iter().map(|n| format!("{}: {n}", show_path(&file))));
            Some(Arc::new(clip))
        }
        (None, None) => {
            for k in ["animation_start", "animation_speed", "animation_loop", "animation_time"] {
                if t.get(k).is_some() {
                    return Err(t.src.value_err(
                        &t.key_span(k),
                        format!(
                            "{} gives `{k}` without `animation` or `animation_file` (the clip to play)",
                            t.what
                        ),
                    ));
                }
            }
            None
        }
        (None, Some((name, span))) => {
            let clips = rig.map_or(&[][..], |r| r.clips());
            if clips.is_empty() {
                return Err(no_rig("animation", "animation clips"));
            }
            let list = clips
                .iter()
                .map(|c| {
                    format!("\"{}\" ({} s)", crate::error::escape_controls(&c.name), fmt_f32(c.duration))
                })
                .collect::<Vec<_>>()
                .join(", ");
            match clips.iter().find(|c| c.name == name) {
                Some(c) => Some(Arc::new(c.clone())),
                None => {
                    return Err(t.src.value_err(
                        &span,
                        format!(
                            "{}: the glTF file has no clip \"{}\"; its clips are {list}",
                            t.what,
                            crate::error::escape_controls(name)
                        ),
                    ))
                }
            }
        }
    };
    let time_range = Constraint::Range { lo: -COORD_MAX, hi: COORD_MAX, lo_open: false, hi_open: false };
    rd.add(t, params, "animation_start", S, time_range, Fallback::Value(&[0.0]), false)?;
    let speed = Constraint::Range { lo: -1e3, hi: 1e3, lo_open: false, hi_open: false };
    rd.add(t, params, "animation_speed", S, speed, Fallback::Value(&[1.0]), false)?;
    rd.add(t, params, "animation_time", S, time_range, Fallback::Value(&[0.0]), false)?;
    let looping = t.opt_bool("animation_loop")?.unwrap_or(true);
    let pinned = t.get("animation_time").is_some();
    let mut expressions = false;
    if t.get("expressions").is_some() {
        let Some(rig) = rig.filter(|r| !r.expressions().is_empty()) else {
            return Err(no_rig("expressions", "VRM expressions"));
        };
        let sub = t.sub("expressions", "expressions")?.expect("present");
        let names: Vec<&str> = rig.expressions().iter().map(|e| e.name.as_str()).collect();
        let mut weights = vec![(0.0f32, sub.span.clone()); names.len()];
        let mut keys: Vec<(&str, Span)> =
            sub.t.iter().map(|(k, _)| (k.get_ref().as_ref(), k.span())).collect();
        keys.sort_by_key(|(_, s)| s.start);
        for (key, key_span) in keys {
            let Some(e) = names.iter().position(|n| *n == key) else {
                return Err(t.src.unknown(
                    &key_span,
                    format!(
                        "{}: the file has no expression \"{}\"; its expressions are {}",
                        t.what,
                        echo(key),
                        names.join(", ")
                    ),
                ));
            };
            let what = format!("expression `{}` in {}", echo(key), t.what);
            let v = read_numbers(&sub.src, sub.get(key).expect("listed"), S, false, &what)?;
            let unit = Constraint::Range { lo: 0.0, hi: 1.0, lo_open: false, hi_open: false };
            if let Err((_, msg)) = unit.check(&[v[0].0], 0, true) {
                return Err(t.src.value_err(&v[0].1, format!("{what} {msg}")));
            }
            weights[e] = v[0].clone();
        }
        let offset = rd.values.len();
        for (x, span) in &weights {
            rd.values.push(*x);
            rd.spans.push(span.clone());
        }
        params.params.push(Param {
            key: "expressions",
            offset,
            len: weights.len(),
            shape: Shape::Vector(weights.len()),
            rule: Constraint::Range { lo: 0.0, hi: 1.0, lo_open: false, hi_open: false },
            broadcast: false,
        });
        expressions = true;
    }
    let retargeted = t.get("animation_file").is_some();
    Ok(Some(Motion { clip, looping, pinned, expressions, retargeted }))
}

/// Resolves an asset path `rel` written at `span` of `t`: relative to the scene file and inside
/// its directory tree. Returns the path as written joined to the scene's directory, its canonical
/// form and the canonical scene directory.
fn resolve_asset(
    t: &Table<'_, '_>,
    rel: &str,
    span: &Span,
    dir: &mut SceneDir,
) -> Res<(PathBuf, PathBuf, PathBuf)> {
    let err = |message: String, file: PathBuf| SceneError::Gltf { at: t.src.loc(span), file, message };
    let file = dir.path.join(rel);
    if Path::new(rel).is_absolute() || Path::new(rel).has_root() {
        return Err(err(
            "the path must be relative to the scene file (glTF files must lie inside the scene file's directory)"
                .into(),
            file,
        ));
    }
    let real = crate::files::canonicalize(&file)
        .map_err(|e| err(format!("cannot read the file: {e}"), file.clone()))?;
    let root = dir.root().map_err(|m| err(m, file.clone()))?;
    if !real.starts_with(&root) {
        return Err(err(
            format!(
                "it resolves to {}, outside the scene file's directory {}; glTF files must lie inside the scene \
                 file's directory",
                show_path(&real),
                show_path(&root)
            ),
            file,
        ));
    }
    Ok((file, real, root))
}

/// Takes a primitive's `tris` triangles and `verts` vertices from the scene's budget, or says
/// which limit it crosses (located at its `kind`).
fn primitive_budget(t: &Table<'_, '_>, budget: &mut Budget, tris: u64, verts: u64) -> Res<()> {
    if tris > budget.triangles || verts > budget.vertices {
        return Err(t.src.value_err(
            &t.key_span("kind"),
            format!(
                "{} ({tris} triangles, {verts} vertices) brings the scene past the limit of {MAX_TRIANGLES} \
                 triangles and {MAX_VERTICES} vertices of all objects together",
                t.what
            ),
        ));
    }
    budget.triangles -= tris;
    budget.vertices -= verts;
    Ok(())
}
