//! glTF 2.0 (`.gltf` with external or data-URI buffers, and `.glb`) → one [`Mesh`]: every
//! TRIANGLES primitive of the default scene's nodes, with node transforms composed and baked in,
//! texture coordinates (`TEXCOORD_n`), vertex colours (`COLOR_0`), one material slot per vertex
//! and the file's materials with their textures (`gltf_material`: base colour, base-colour and
//! feature textures, `KHR_materials_unlit`, `VRMC_materials_mtoon`).
//!
//! A node with both a mesh and a skin is placed by its skin at the pose its joints' node
//! transforms give (the rest pose of a file without animation; the node's own transform is
//! ignored, as the glTF spec requires): each vertex goes through `Σ w_k · J_k · IBM_k` of its
//! `JOINTS_0`/`WEIGHTS_0`, normals through the inverse transpose of the same matrix.
//!
//! `extensionsRequired` may only name the extensions hadou maps
//! ([`crate::gltf_material::SUPPORTED_EXTENSIONS`]); unknown `extensionsUsed` are ignored.
//!
//! The file is untrusted: before the gltf crate's wrapper types are used, every index in the raw
//! JSON is checked against the array it points into (the feature texture of the extras too), the
//! node graph is checked to be a forest (the glTF spec requires one; a node listed twice would
//! otherwise multiply the instances exponentially), and the triangles the default scene
//! instantiates are counted against the scene's budget before any data is copied. Every accessor
//! is bounds-checked before it is read, and every joint index against its skin. External buffer
//! and image files must lie inside the asset root (`gltf_uri`), every byte read counts against
//! [`GLTF_MAX_BYTES`] and decoded texels against what is left of the scene's
//! [`MAX_SCENE_TEXELS`]. Calls into the gltf crate and the image decoders
//! run under [`guarded`], so even an unforeseen panic there is an error, never a crash.

use crate::files::{
    parent_dir, read_regular_file, GLTF_MAX_BYTES, GLTF_MAX_JSON_BYTES, GLTF_MAX_JSON_OBJECTS,
    GLTF_MAX_JSON_VALUES,
};
use crate::frame::Mesh;
use crate::gltf_accessor::check_accessor;
use crate::gltf_anim::read_clips;
use crate::gltf_material::{load_materials, ImageSource, Materials, SUPPORTED_EXTENSIONS};
use crate::gltf_uri::resolve_uri;
use crate::guard::guarded;
use crate::limits::{
    fmt_f32, COORD_MAX, MAX_MATERIAL_SLOTS, MAX_SKINNED_NODES, MAX_SKIN_JOINTS, MAX_TRIANGLES, MAX_VERTICES,
};
use crate::mesh::{append_mesh, smooth_normals, transform_mesh};
use crate::rig::{position_groups, MorphTarget, Part, PoseInput, RestLocal, Rig, RigNode, RigSkin};
use crate::texture::MAX_SCENE_TEXELS;
use gltf::accessor::{DataType, Dimensions};
use gltf::buffer::Source;
use gltf::json;
use gltf::mesh::{Mode, Semantic};
use hadou_math::{Mat4, Vec3f};
use std::cell::Cell;
use std::path::Path;

/// Deepest node hierarchy followed (the recursion that bakes the transforms stays shallow).
const MAX_DEPTH: usize = 64;

/// Triangles, vertices and texture texels still allowed in the scene being loaded (every
/// instance counted; each decoded image once).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Budget {
    /// Triangles left.
    pub triangles: u64,
    /// glTF vertices left.
    pub vertices: u64,
    /// Texels left of [`MAX_SCENE_TEXELS`].
    pub texels: u64,
}

impl Budget {
    /// The whole budget of one scene.
    pub(crate) const FULL: Budget =
        Budget { triangles: MAX_TRIANGLES, vertices: MAX_VERTICES, texels: MAX_SCENE_TEXELS };
}

/// Loads the glTF/GLB file at `path` into one mesh in the file's scene space. External buffers
/// must lie inside the file's own directory tree.
pub fn load_gltf(path: &Path) -> Result<Mesh, String> {
    load_gltf_rig(path).map(|(mesh, _)| mesh)
}

/// [`load_gltf`], also returning the file's posable character (skins, morph targets, animation
/// clips, VRM expressions) when it has one.
pub fn load_gltf_rig(path: &Path) -> Result<(Mesh, Option<Rig>), String> {
    let mut budget = Budget::FULL;
    load_gltf_in(path, parent_dir(path), &mut budget, &mut Vec::new())
}

/// [`load_gltf`] with external buffers confined to the directory tree of `root`, and the
/// instanced triangles taken from `budget`.
pub(crate) fn load_gltf_in(
    path: &Path,
    root: &Path,
    budget: &mut Budget,
    warnings: &mut Vec<String>,
) -> Result<(Mesh, Option<Rig>), String> {
    let bytes = read_regular_file(path, GLTF_MAX_BYTES).map_err(|e| format!("cannot read the file: {e}"))?;
    from_bytes_in(std::borrow::Cow::Owned(bytes), parent_dir(path), root, budget, warnings)
}

/// Parses glTF or GLB `bytes`; external buffers are resolved relative to `dir` and must lie inside
/// its directory tree.
pub fn gltf_from_bytes(bytes: &[u8], dir: &Path) -> Result<Mesh, String> {
    gltf_from_bytes_with_warnings(bytes, dir).map(|(mesh, _)| mesh)
}

/// [`gltf_from_bytes`], also returning the warnings of the load (ignored material features,
/// missing texture coordinates, downscaled textures, …).
pub fn gltf_from_bytes_with_warnings(bytes: &[u8], dir: &Path) -> Result<(Mesh, Vec<String>), String> {
    let mut budget = Budget::FULL;
    let mut warnings = Vec::new();
    let (mesh, _) = from_bytes_in(std::borrow::Cow::Borrowed(bytes), dir, dir, &mut budget, &mut warnings)?;
    Ok((mesh, warnings))
}

/// Checks the material extensions hadou reads in glTF or GLB `bytes` (a VRM's MToon:
/// `VRMC_materials_mtoon` 1.0 or VRM 0.x `materialProperties`; `extras.hadou.featureTexture`)
/// without loading the file: the error [`gltf_from_bytes`] gives for them (naming the material and
/// the key), for a file another loader reads (e.g. Bevy's glTF loader).
pub fn check_gltf_materials(bytes: &[u8]) -> Result<(), String> {
    let json = json_text(sniff(bytes)?)?;
    check_json_size(&json)?;
    let raw = raw_json(&json)?;
    let textures = raw.get("textures").and_then(serde_json::Value::as_array).map_or(0, Vec::len);
    crate::gltf_material::check_raw(&raw, textures)
}

/// The JSON text of the file: the `.gltf` itself or a `.glb`'s JSON chunk.
fn json_text(body: &[u8]) -> Result<std::borrow::Cow<'_, [u8]>, String> {
    if body.starts_with(b"glTF") {
        let glb = guarded("GLB", || gltf::Glb::from_slice(body))?
            .map_err(|e| format!("not a valid GLB file: {e}"))?;
        Ok(glb.json)
    } else {
        Ok(std::borrow::Cow::Borrowed(body))
    }
}

/// The raw JSON of the file, for what the typed document does not keep (names, extensions,
/// extras). serde_json limits its nesting depth, so hostile JSON cannot exhaust the stack.
fn raw_json(json: &[u8]) -> Result<serde_json::Value, String> {
    serde_json::from_slice(json).map_err(|e| format!("not a valid glTF 2.0 file: {e}"))
}

/// Checks the JSON text against [`GLTF_MAX_JSON_BYTES`], [`GLTF_MAX_JSON_OBJECTS`] and
/// [`GLTF_MAX_JSON_VALUES`] before it is parsed (twice: the typed document and the raw tree each
/// take a few hundred bytes per object), counting lexically: objects are the `{` outside strings,
/// values and keys at most the `{`, `[`, `,` and `:` outside strings.
fn check_json_size(json: &[u8]) -> Result<(), String> {
    if json.len() as u64 > GLTF_MAX_JSON_BYTES {
        return Err(format!(
            "its JSON is {} bytes, more than the limit of {} MiB (large buffers and images belong in binary \
             chunks or files)",
            json.len(),
            GLTF_MAX_JSON_BYTES >> 20
        ));
    }
    let (mut objects, mut values) = (0u64, 0u64);
    let (mut in_string, mut escaped) = (false, false);
    for &b in json {
        if in_string {
            match (escaped, b) {
                (true, _) => escaped = false,
                (false, b'\\') => escaped = true,
                (false, b'"') => in_string = false,
                _ => {}
            }
            continue;
        }
        match b {
            b'"' => in_string = true,
            b'{' => {
                objects += 1;
                values += 1;
            }
            b'[' | b',' | b':' => values += 1,
            _ => {}
        }
    }
    if objects > GLTF_MAX_JSON_OBJECTS || values > GLTF_MAX_JSON_VALUES {
        return Err(format!(
            "its JSON holds {objects} objects and up to {values} values; at most {GLTF_MAX_JSON_OBJECTS} \
             objects and {GLTF_MAX_JSON_VALUES} values fit a glTF file"
        ));
    }
    Ok(())
}

/// The JSON text of a `.gltf` (a UTF-8 byte-order mark dropped) or the whole `.glb`; anything
/// else is "not a glTF or GLB file".
fn sniff(bytes: &[u8]) -> Result<&[u8], String> {
    if bytes.starts_with(b"glTF") {
        return Ok(bytes);
    }
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    match text.iter().find(|b| !b.is_ascii_whitespace()) {
        Some(b'{') => Ok(text),
        None => Err("the file is empty; it is not a glTF or GLB file".into()),
        Some(_) => Err("not a glTF or GLB file (a .gltf file is JSON text starting with `{`, a .glb file \
                        starts with the bytes `glTF`)"
            .into()),
    }
}

/// Loads the glTF or GLB `bytes`; the file's own bytes are dropped once parsed (a GLB's binary
/// chunk lives on in the document), so a large file is not held twice.
/// A parsed, checked glTF document: every index in range, the node graph a forest (`parent` of
/// each node), the glTF crate's validation passed, required extensions supported.
pub(crate) struct Opened {
    pub gltf: gltf::Gltf,
    pub raw: serde_json::Value,
    pub parent: Vec<Option<usize>>,
    /// The GLB binary chunk, until the buffers take it.
    pub blob: Option<Vec<u8>>,
}

/// Parses and checks the glTF or GLB `bytes` (dropped once parsed).
pub(crate) fn open(bytes: std::borrow::Cow<'_, [u8]>) -> Result<Opened, String> {
    let (mut gltf, raw) = {
        let body = sniff(&bytes)?;
        let json = json_text(body)?;
        check_json_size(&json)?;
        let gltf = guarded("glTF", || gltf::Gltf::from_slice_without_validation(body))?
            .map_err(|e| format!("not a valid glTF 2.0 file: {e}"))?;
        (gltf, raw_json(&json))
    };
    drop(bytes);
    // The binary chunk moves into the buffers below instead of being copied.
    let blob = gltf.blob.take();
    let doc = gltf.document.as_json();
    for ext in &doc.extensions_required {
        if !SUPPORTED_EXTENSIONS.contains(&ext.as_str()) {
            return Err(format!(
                "it requires the glTF extension `{ext}`, which hadou does not support (supported: {})",
                SUPPORTED_EXTENSIONS.join(", ")
            ));
        }
    }
    if doc.materials.len() as u64 >= MAX_MATERIAL_SLOTS {
        return Err(format!(
            "it has {} materials; with its default material that is more than the limit of \
             {MAX_MATERIAL_SLOTS} material slots per scene",
            doc.materials.len()
        ));
    }
    let raw = raw?;
    check_indices(doc)?;
    crate::gltf_material::check_raw(&raw, doc.textures.len())?;
    let parent = check_forest(doc)?;
    let mut problems = Vec::new();
    guarded("glTF", || {
        use gltf::json::validation::Validate;
        doc.validate(doc, json::Path::new, &mut |path, e| {
            let at = path().to_string();
            // Required extensions were checked above, against what hadou supports.
            if !at.starts_with("extensionsRequired") {
                problems.push(format!("{at}: {e}"));
            }
        });
    })?;
    if !problems.is_empty() {
        let more =
            if problems.len() > 3 { format!(" (and {} more)", problems.len() - 3) } else { String::new() };
        problems.truncate(3);
        return Err(format!("not a valid glTF 2.0 file: {}{more}", problems.join("; ")));
    }
    Ok(Opened { gltf, raw, parent, blob })
}

/// Reads every buffer of `gltf` (the GLB chunk `blob`, or URIs resolved in `dir` and confined to
/// `root`), taking their bytes from `bytes_left`.
pub(crate) fn read_buffers(
    gltf: &gltf::Gltf,
    mut blob: Option<Vec<u8>>,
    dir: &Path,
    root: &Path,
    bytes_left: &mut u64,
) -> Result<Vec<Vec<u8>>, String> {
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for buffer in gltf.buffers() {
        let data = match buffer.source() {
            Source::Bin => blob.take().ok_or_else(|| {
                format!("buffer {} refers to a GLB binary chunk, but there is none", buffer.index())
            })?,
            Source::Uri(uri) => resolve_uri(uri, dir, root, *bytes_left)
                .map_err(|e| format!("buffer {}: {e}", buffer.index()))?,
        };
        *bytes_left = bytes_left.saturating_sub(data.len() as u64);
        if data.len() < buffer.length() {
            return Err(format!(
                "buffer {} has {} bytes but the file declares byteLength {}",
                buffer.index(),
                data.len(),
                buffer.length()
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

fn from_bytes_in(
    bytes: std::borrow::Cow<'_, [u8]>,
    dir: &Path,
    root: &Path,
    budget: &mut Budget,
    warnings: &mut Vec<String>,
) -> Result<(Mesh, Option<Rig>), String> {
    let file_len = bytes.len() as u64;
    let Opened { gltf, raw, parent, blob } = open(bytes)?;
    let doc = gltf.document.as_json();

    // The root nodes of the default scene (or the first, or every parentless node).
    let scene = doc.scene.map(|s| s.value()).or(if doc.scenes.is_empty() { None } else { Some(0) });
    let roots: Vec<usize> = match scene {
        Some(s) => {
            let roots: Vec<usize> = doc.scenes[s].nodes.iter().map(|n| n.value()).collect();
            let mut listed = vec![false; doc.nodes.len()];
            for &r in &roots {
                if let Some(p) = parent[r] {
                    return Err(format!(
                        "scene {s} lists node {r} as a root, but node {p} has it as a child (node graphs \
                         must be trees)"
                    ));
                }
                if std::mem::replace(&mut listed[r], true) {
                    return Err(format!("scene {s} lists node {r} twice (node graphs must be trees)"));
                }
            }
            roots
        }
        None => (0..doc.nodes.len()).filter(|&n| parent[n].is_none()).collect(),
    };
    let need = count_instances(doc, &roots)?;
    let used_skins = skins_used(doc, &roots);
    if need.triangles > budget.triangles {
        return Err(format!(
            "its default scene has {} triangles (every node instance counted), more than the {} left of \
             the limit of {MAX_TRIANGLES} triangles per scene",
            need.triangles, budget.triangles
        ));
    }
    if need.vertices > budget.vertices {
        return Err(format!(
            "its default scene has {} vertices (every node instance counted), more than the {} left of \
             the limit of {MAX_VERTICES} vertices per scene",
            need.vertices, budget.vertices
        ));
    }

    let mut bytes_left = GLTF_MAX_BYTES.saturating_sub(file_len);
    let buffers = read_buffers(&gltf, blob, dir, root, &mut bytes_left)?;

    let src = ImageSource { buffers: &buffers, dir, root };
    let texels = &mut budget.texels;
    let materials =
        guarded("glTF", || load_materials(&gltf, &raw, &src, &mut bytes_left, texels, warnings))??;
    let (out, rig) = guarded("glTF", || -> Result<(Mesh, Option<Rig>), String> {
        let nodes: Vec<gltf::Node<'_>> = gltf.nodes().collect();
        // VRM 0.x models face −z; turned half a turn about y they face +z as every other model.
        let base = match crate::gltf_vrm::vrm_version(&raw) {
            Some(crate::rig::VrmVersion::V0) => Mat4::rotation_xyz_deg(Vec3f::new(0.0, 180.0, 0.0)),
            _ => Mat4::IDENTITY,
        };
        let worlds = world_matrices(&nodes, &parent, base);
        // Each skin's joints and inverse bind matrices, and `J_k · IBM_k` once, for every skin a
        // node of the default scene uses.
        let mut skins: Vec<Option<Vec<Mat4>>> = vec![None; doc.skins.len()];
        let mut rig_skins: Vec<Option<RigSkin>> = vec![None; doc.skins.len()];
        for skin in gltf.skins() {
            if used_skins[skin.index()] {
                let (rs, m) = skin_matrices(&skin, &buffers, &worlds)
                    .map_err(|e| format!("skin {}: {e}", skin.index()))?;
                skins[skin.index()] = Some(m);
                rig_skins[skin.index()] = Some(rs);
            }
        }
        let ctx =
            Ctx { buffers: &buffers, materials: &materials, skins, morph_left: Cell::new(MAX_MORPH_DELTAS) };
        let mut out = Mesh::default();
        let mut parts = Vec::new();
        for &r in &roots {
            add_node(&nodes[r], base, &ctx, &mut out, &mut parts, 0, warnings)?;
        }
        let rig = build_rig(&gltf, &raw, &nodes, &parent, rig_skins, parts, &buffers, warnings)?
            .map(|rig| Rig { base, ..rig });
        Ok((out, rig))
    })??;
    if out.indices.is_empty() {
        return Err("the default scene contains no triangles".into());
    }
    let mut out = out;
    out.materials = materials.list;
    // The rest mesh is the rig's rest pose (default morph weights applied), so a posed frame at
    // the rest pose equals it exactly.
    let rig = rig.map(|mut rig| {
        out = rig.pose(&out, &PoseInput::default());
        (rig.groups, rig.group_count) = position_groups(&out.positions);
        rig
    });
    budget.triangles -= need.triangles;
    budget.vertices -= need.vertices;
    Ok((out, rig))
}

/// Most morph-target vertex offsets (targets × vertices, every instance counted) of one glTF
/// file: 2²² (each holds a position and a normal offset, 24 bytes: 96 MiB at most).
pub const MAX_MORPH_DELTAS: u64 = 1 << 22;

/// Most morph targets of one mesh.
pub const MAX_MORPH_TARGETS: usize = 256;

/// The posable character of a file, when it has skins, morph targets or animations (`None`
/// otherwise).
#[allow(clippy::too_many_arguments)]
fn build_rig(
    gltf: &gltf::Gltf,
    raw: &serde_json::Value,
    nodes: &[gltf::Node<'_>],
    parent: &[Option<usize>],
    skins: Vec<Option<RigSkin>>,
    parts: Vec<Part>,
    buffers: &[Vec<u8>],
    warnings: &mut Vec<String>,
) -> Result<Option<Rig>, String> {
    let skinned = parts.iter().any(|p| p.skin.is_some());
    let morphs = parts.iter().any(|p| !p.targets.is_empty());
    let vrm = crate::gltf_vrm::vrm_version(raw);
    if !skinned && !morphs && gltf.animations().len() == 0 && vrm.is_none() {
        return Ok(None);
    }
    let mut rig_nodes = Vec::with_capacity(nodes.len());
    for node in nodes {
        let rest = match node.transform() {
            gltf::scene::Transform::Matrix { matrix } => RestLocal::Matrix(Mat4 { cols: matrix }),
            gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
                RestLocal::Trs { t: translation, r: rotation, s: scale }
            }
        };
        let weights = match node.mesh() {
            Some(mesh) => {
                let counts: Vec<usize> = mesh.primitives().map(|p| p.morph_targets().len()).collect();
                let n = counts.iter().copied().max().unwrap_or(0);
                if counts.iter().any(|&c| c != n) {
                    return Err(format!(
                        "mesh {}: its primitives have different numbers of morph targets ({counts:?}); glTF \
                         requires the same number",
                        mesh.index()
                    ));
                }
                let given = node.weights().or(mesh.weights());
                match given {
                    Some(w) if n > 0 && w.len() != n => {
                        return Err(format!(
                            "node {} (mesh {}): `weights` has {} entries but the mesh has {n} morph targets",
                            node.index(),
                            mesh.index(),
                            w.len()
                        ))
                    }
                    Some(w) if w.iter().any(|x| !x.is_finite()) => {
                        return Err(format!("node {}: its morph `weights` are not all finite", node.index()))
                    }
                    Some(w) if n > 0 => w.to_vec(),
                    _ => vec![0.0; n],
                }
            }
            None => Vec::new(),
        };
        rig_nodes.push(RigNode { parent: parent[node.index()], rest, weights });
    }
    // Parents before children.
    let mut order = Vec::with_capacity(nodes.len());
    let mut stack: Vec<usize> = (0..nodes.len()).filter(|&i| parent[i].is_none()).collect();
    while let Some(i) = stack.pop() {
        order.push(i);
        stack.extend(nodes[i].children().map(|c| c.index()));
    }
    let clips = read_clips(gltf, raw, buffers, &rig_nodes, warnings)?;
    let mesh_of: Vec<Option<usize>> = nodes.iter().map(|n| n.mesh().map(|m| m.index())).collect();
    let expressions = crate::gltf_vrm::read_expressions(raw, &rig_nodes, &mesh_of)?;
    let humanoid = crate::gltf_vrm::read_humanoid(raw, nodes.len())?;
    let springs = crate::spring_def::read_springs(raw, &rig_nodes, &order)?;
    let look_at = crate::look_at::read_look_at(raw, &humanoid)?;
    Ok(Some(Rig {
        nodes: rig_nodes,
        order,
        skins,
        parts,
        clips,
        expressions,
        humanoid,
        vrm,
        base: Mat4::IDENTITY,
        groups: Vec::new(),
        group_count: 0,
        springs,
        look_at,
    }))
}

/// `Err` naming `from` when `index` is not below `len`.
fn in_range<T>(
    index: json::Index<T>,
    len: usize,
    kind: &str,
    from: impl FnOnce() -> String,
) -> Result<(), String> {
    let i = index.value();
    if i < len {
        Ok(())
    } else {
        Err(format!("{} refers to {kind} {i}, but the file has {len} {kind} entries (0-based)", from()))
    }
}

/// Every index in the raw JSON points into its array.
fn check_indices(r: &json::Root) -> Result<(), String> {
    let (n_acc, n_view, n_buf) = (r.accessors.len(), r.buffer_views.len(), r.buffers.len());
    let (n_node, n_mesh, n_mat) = (r.nodes.len(), r.meshes.len(), r.materials.len());
    let (n_tex, n_img, n_samp) = (r.textures.len(), r.images.len(), r.samplers.len());
    if let Some(s) = r.scene {
        in_range(s, r.scenes.len(), "scene", || "`scene`".into())?;
    }
    for (i, s) in r.scenes.iter().enumerate() {
        for &n in &s.nodes {
            in_range(n, n_node, "node", || format!("scene {i}"))?;
        }
    }
    for (i, n) in r.nodes.iter().enumerate() {
        for &c in n.children.iter().flatten() {
            in_range(c, n_node, "node", || format!("node {i} (children)"))?;
        }
        if let Some(m) = n.mesh {
            in_range(m, n_mesh, "mesh", || format!("node {i}"))?;
        }
        if let Some(c) = n.camera {
            in_range(c, r.cameras.len(), "camera", || format!("node {i}"))?;
        }
        if let Some(s) = n.skin {
            in_range(s, r.skins.len(), "skin", || format!("node {i}"))?;
        }
    }
    for (i, m) in r.meshes.iter().enumerate() {
        for (j, p) in m.primitives.iter().enumerate() {
            let from = || format!("mesh {i} primitive {j}");
            for &a in p.attributes.values() {
                in_range(a, n_acc, "accessor", from)?;
            }
            if let Some(a) = p.indices {
                in_range(a, n_acc, "accessor", from)?;
            }
            if let Some(m) = p.material {
                in_range(m, n_mat, "material", from)?;
            }
            for t in p.targets.iter().flatten() {
                for a in [t.positions, t.normals, t.tangents].into_iter().flatten() {
                    in_range(a, n_acc, "accessor", || format!("mesh {i} primitive {j} (morph target)"))?;
                }
            }
        }
    }
    for (i, a) in r.accessors.iter().enumerate() {
        if let Some(v) = a.buffer_view {
            in_range(v, n_view, "bufferView", || format!("accessor {i}"))?;
        }
        if let Some(sp) = &a.sparse {
            in_range(sp.indices.buffer_view, n_view, "bufferView", || format!("accessor {i} (sparse)"))?;
            in_range(sp.values.buffer_view, n_view, "bufferView", || format!("accessor {i} (sparse)"))?;
        }
    }
    for (i, v) in r.buffer_views.iter().enumerate() {
        in_range(v.buffer, n_buf, "buffer", || format!("bufferView {i}"))?;
    }
    for (i, m) in r.materials.iter().enumerate() {
        let pbr = &m.pbr_metallic_roughness;
        let textures = [
            pbr.base_color_texture.as_ref().map(|t| t.index),
            pbr.metallic_roughness_texture.as_ref().map(|t| t.index),
            m.normal_texture.as_ref().map(|t| t.index),
            m.occlusion_texture.as_ref().map(|t| t.index),
            m.emissive_texture.as_ref().map(|t| t.index),
        ];
        for t in textures.into_iter().flatten() {
            in_range(t, n_tex, "texture", || format!("material {i}"))?;
        }
    }
    for (i, t) in r.textures.iter().enumerate() {
        if let Some(s) = t.sampler {
            in_range(s, n_samp, "sampler", || format!("texture {i}"))?;
        }
        in_range(t.source, n_img, "image", || format!("texture {i}"))?;
    }
    for (i, im) in r.images.iter().enumerate() {
        if let Some(v) = im.buffer_view {
            in_range(v, n_view, "bufferView", || format!("image {i}"))?;
        }
    }
    for (i, s) in r.skins.iter().enumerate() {
        for &j in &s.joints {
            in_range(j, n_node, "node", || format!("skin {i} (joints)"))?;
        }
        if let Some(k) = s.skeleton {
            in_range(k, n_node, "node", || format!("skin {i} (skeleton)"))?;
        }
        if let Some(a) = s.inverse_bind_matrices {
            in_range(a, n_acc, "accessor", || format!("skin {i}"))?;
        }
    }
    for (i, an) in r.animations.iter().enumerate() {
        for (j, c) in an.channels.iter().enumerate() {
            let from = || format!("animation {i} channel {j}");
            in_range(c.sampler, an.samplers.len(), "animation sampler", from)?;
            in_range(c.target.node, n_node, "node", from)?;
        }
        for (j, s) in an.samplers.iter().enumerate() {
            let from = || format!("animation {i} sampler {j}");
            in_range(s.input, n_acc, "accessor", from)?;
            in_range(s.output, n_acc, "accessor", from)?;
        }
    }
    Ok(())
}

/// Checks that the node graph is a forest (each node at most one parent, listed once, no cycles)
/// and returns each node's parent.
fn check_forest(r: &json::Root) -> Result<Vec<Option<usize>>, String> {
    const TREES: &str = "glTF node graphs must be trees: each node has at most one parent and no cycles";
    let n = r.nodes.len();
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for (p, node) in r.nodes.iter().enumerate() {
        for c in node.children.iter().flatten().map(|c| c.value()) {
            if c == p {
                return Err(format!("node {p} lists itself as a child ({TREES})"));
            }
            match parent[c] {
                Some(q) if q == p => {
                    return Err(format!("node {p} lists node {c} twice as a child ({TREES})"))
                }
                Some(q) => {
                    return Err(format!("node {c} is a child of both node {q} and node {p} ({TREES})"))
                }
                None => parent[c] = Some(p),
            }
        }
    }
    // With at most one parent each, a node that no parentless node reaches lies on a cycle.
    let mut seen = vec![false; n];
    let mut stack: Vec<usize> = (0..n).filter(|&i| parent[i].is_none()).collect();
    while let Some(i) = stack.pop() {
        seen[i] = true;
        stack.extend(r.nodes[i].children.iter().flatten().map(|c| c.value()));
    }
    if let Some(k) = seen.iter().position(|s| !s) {
        return Err(format!("node {k} is part of a cycle of children ({TREES})"));
    }
    Ok(parent)
}

/// Triangles and vertices the nodes under `roots` instantiate, from the JSON alone; errors where
/// the skinned nodes or their skins' joints exceed [`MAX_SKINNED_NODES`] or [`MAX_SKIN_JOINTS`].
fn count_instances(r: &json::Root, roots: &[usize]) -> Result<Budget, String> {
    let count = |a: json::Index<json::Accessor>| r.accessors[a.value()].count.0;
    let mut total = Budget { triangles: 0, vertices: 0, texels: 0 };
    let (mut skinned, mut joints) = (0u64, 0u64);
    let mut skin_seen = vec![false; r.skins.len()];
    let mut stack: Vec<(usize, usize)> = roots.iter().map(|&n| (n, 0)).collect();
    while let Some((i, depth)) = stack.pop() {
        if depth > MAX_DEPTH {
            return Err(format!("node hierarchy deeper than {MAX_DEPTH} levels at node {i}"));
        }
        let node = &r.nodes[i];
        if let (Some(_), Some(s)) = (node.mesh, node.skin) {
            skinned += 1;
            if skinned > MAX_SKINNED_NODES {
                return Err(format!(
                    "its default scene has more than the limit of {MAX_SKINNED_NODES} skinned mesh nodes \
                     (node {i} is one too many)"
                ));
            }
            let s = s.value();
            if !std::mem::replace(&mut skin_seen[s], true) {
                joints += r.skins[s].joints.len() as u64;
                if joints > MAX_SKIN_JOINTS {
                    return Err(format!(
                        "skin {s} brings the joints of the skins its default scene uses to {joints}, more than \
                         the limit of {MAX_SKIN_JOINTS} joints per glTF file"
                    ));
                }
            }
        }
        if let Some(m) = node.mesh {
            for p in &r.meshes[m.value()].primitives {
                let pos =
                    p.attributes.get(&json::validation::Checked::Valid(json::mesh::Semantic::Positions));
                let verts = pos.map_or(0, |&a| count(a));
                let tris = p.indices.map_or(verts, count) / 3;
                total.triangles = total.triangles.saturating_add(tris);
                total.vertices = total.vertices.saturating_add(verts);
            }
        }
        stack.extend(node.children.iter().flatten().map(|c| (c.value(), depth + 1)));
    }
    Ok(total)
}

/// Which skins the nodes under `roots` use (the graph is a forest and at most [`MAX_DEPTH`]
/// deep: `count_instances` checked both).
fn skins_used(r: &json::Root, roots: &[usize]) -> Vec<bool> {
    let mut used = vec![false; r.skins.len()];
    let mut stack: Vec<usize> = roots.to_vec();
    while let Some(i) = stack.pop() {
        let node = &r.nodes[i];
        if let (Some(_), Some(s)) = (node.mesh, node.skin) {
            used[s.value()] = true;
        }
        stack.extend(node.children.iter().flatten().map(|c| c.value()));
    }
    used
}

/// What every node of a load needs.
struct Ctx<'a> {
    buffers: &'a [Vec<u8>],
    materials: &'a Materials,
    /// Per skin, `J_k · IBM_k` for every joint `k` (computed once, for the skins in use).
    skins: Vec<Option<Vec<Mat4>>>,
    /// Morph-target offsets still allowed (of [`MAX_MORPH_DELTAS`]).
    morph_left: Cell<u64>,
}

/// Every node's world matrix from the node hierarchy (the graph is a forest), without recursion.
fn world_matrices(nodes: &[gltf::Node<'_>], parent: &[Option<usize>], base: Mat4) -> Vec<Option<Mat4>> {
    let mut worlds: Vec<Option<Mat4>> = vec![None; nodes.len()];
    let mut stack: Vec<(usize, Mat4)> =
        (0..nodes.len()).filter(|&i| parent[i].is_none()).map(|i| (i, base)).collect();
    while let Some((i, up)) = stack.pop() {
        let world = up * Mat4 { cols: nodes[i].transform().matrix() };
        if world.cols.iter().flatten().all(|v| v.is_finite()) {
            worlds[i] = Some(world);
            stack.extend(nodes[i].children().map(|c| (c.index(), world)));
        }
    }
    worlds
}

fn add_node(
    node: &gltf::Node<'_>,
    parent: Mat4,
    ctx: &Ctx<'_>,
    out: &mut Mesh,
    parts: &mut Vec<Part>,
    depth: usize,
    warnings: &mut Vec<String>,
) -> Result<(), String> {
    if depth > MAX_DEPTH {
        return Err(format!("node hierarchy deeper than {MAX_DEPTH} levels at node {}", node.index()));
    }
    let local = Mat4 { cols: node.transform().matrix() };
    if local.cols.iter().flatten().any(|v| !v.is_finite()) {
        return Err(format!("node {} has a non-finite transform", node.index()));
    }
    let world = parent * local;
    if let Some(mesh) = node.mesh() {
        let skin = match node.skin() {
            Some(skin) => Some(
                ctx.skins
                    .get(skin.index())
                    .and_then(Option::as_deref)
                    .ok_or_else(|| format!("skin {} was not prepared", skin.index()))?,
            ),
            None => None,
        };
        for prim in mesh.primitives() {
            let what = format!("mesh {} primitive {}", mesh.index(), prim.index());
            let p = read_primitive(&prim, ctx, &what, warnings).map_err(|e| format!("{what}: {e}"))?;
            let mut part = Part {
                node: node.index(),
                skin: None,
                first: out.positions.len(),
                positions: p.mesh.positions.clone(),
                normals: p.mesh.normals.clone(),
                influences: Vec::new(),
                targets: p.targets,
            };
            let placed = match (&skin, p.joints, p.weights) {
                (Some(mats), Some(j), Some(w)) => {
                    let inf = influences(&j, &w, mats.len(), &what, warnings)
                        .map_err(|e| format!("{what}: {e}"))?;
                    let placed = skin_mesh(&p.mesh, &inf, mats, &world, &what, warnings);
                    part.skin = node.skin().map(|s| s.index());
                    part.influences = inf;
                    placed
                }
                (Some(_), ..) => {
                    warnings.push(format!(
                        "{what} under node {} has a skin but no JOINTS_0 and WEIGHTS_0; it is placed by the \
                         node's own transform",
                        node.index()
                    ));
                    transform_mesh(&p.mesh, &world)
                }
                (None, ..) => transform_mesh(&p.mesh, &world),
            };
            if let Some(v) = placed.positions.iter().flatten().find(|v| !v.is_finite() || v.abs() > COORD_MAX)
            {
                return Err(format!(
                    "{what} under node {}: vertex coordinates must lie within ±{} after the node \
                     transforms, got {}",
                    node.index(),
                    fmt_f32(COORD_MAX),
                    fmt_f32(*v)
                ));
            }
            append_mesh(out, &placed);
            parts.push(part);
        }
    }
    for child in node.children() {
        add_node(&child, world, ctx, out, parts, depth + 1, warnings)?;
    }
    Ok(())
}

/// `J_k · IBM_k` for every joint `k` of `skin` (`worlds`: every node's world matrix, `None` where
/// it is not finite).
fn skin_matrices(
    skin: &gltf::Skin<'_>,
    buffers: &[Vec<u8>],
    worlds: &[Option<Mat4>],
) -> Result<(RigSkin, Vec<Mat4>), String> {
    let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
    if joints.is_empty() {
        return Err("it has no joints".into());
    }
    let ibms: Vec<Mat4> = match skin.inverse_bind_matrices() {
        Some(acc) => {
            check_accessor(&acc, &[Dimensions::Mat4], &[DataType::F32], buffers)
                .map_err(|e| format!("inverseBindMatrices: {e}"))?;
            if acc.count() != joints.len() {
                return Err(format!(
                    "inverseBindMatrices has {} matrices but the skin has {} joints; they must match",
                    acc.count(),
                    joints.len()
                ));
            }
            let get = |b: gltf::Buffer<'_>| buffers.get(b.index()).map(|d| d.as_slice());
            let m: Vec<Mat4> = skin
                .reader(get)
                .read_inverse_bind_matrices()
                .ok_or("inverseBindMatrices cannot be read")?
                .map(|cols| Mat4 { cols })
                .collect();
            if m.iter().any(|m| m.cols.iter().flatten().any(|v| !v.is_finite())) {
                return Err("inverseBindMatrices contains NaN or infinite values".into());
            }
            m
        }
        None => vec![Mat4::IDENTITY; joints.len()],
    };
    let mats = joints
        .iter()
        .zip(&ibms)
        .map(|(&j, ibm)| {
            let w = worlds[j].ok_or_else(|| format!("joint node {j} has a non-finite transform"))?;
            Ok(w * *ibm)
        })
        .collect::<Result<Vec<Mat4>, String>>()?;
    Ok((RigSkin { joints, ibms }, mats))
}

/// Allowed difference of a vertex's skin weights' sum from 1 before it is reported.
const WEIGHT_SUM_TOLERANCE: f32 = 2e-3;

/// Each vertex's `(joint, weight)` pairs from `JOINTS_0`/`WEIGHTS_0`, weights normalised to sum 1
/// (a sum off by more than [`WEIGHT_SUM_TOLERANCE`] is reported once per primitive) or all zero
/// (the vertex then keeps its node's transform). Joints must index the skin's `n_joints`.
fn influences(
    joints: &[[u16; 4]],
    weights: &[[f32; 4]],
    n_joints: usize,
    what: &str,
    warnings: &mut Vec<String>,
) -> Result<Vec<[(u16, f32); 4]>, String> {
    let mut off = 0usize;
    let mut out = Vec::with_capacity(joints.len());
    for (v, (j, w)) in joints.iter().zip(weights).enumerate() {
        if w.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(format!("vertex {v} has a negative or non-finite weight in WEIGHTS_0"));
        }
        // Normalised to sum 1; a sum that overflows (finite weights near f32::MAX) is taken
        // relative to the largest weight instead, which cannot overflow.
        let mut sum: f32 = w.iter().sum();
        let mut w = *w;
        if sum.is_infinite() {
            let max = w.iter().fold(0.0f32, |a, &b| a.max(b));
            w = w.map(|x| x / max);
            sum = w.iter().sum();
        }
        if sum > 0.0 && (sum - 1.0).abs() > WEIGHT_SUM_TOLERANCE {
            off += 1;
        }
        let mut inf = [(0u16, 0.0f32); 4];
        for k in 0..4 {
            if w[k] == 0.0 {
                continue;
            }
            if j[k] as usize >= n_joints {
                return Err(format!(
                    "vertex {v} is bound to joint {} in JOINTS_0, but the skin has {n_joints} joints (0-based)",
                    j[k]
                ));
            }
            inf[k] = (j[k], w[k] / sum);
        }
        out.push(inf);
    }
    if off > 0 {
        warnings
            .push(format!("{what}: the skin weights of {off} vertices do not sum to 1; they are normalised"));
    }
    Ok(out)
}

/// `mesh` skinned: each vertex through `Σ w_k · mats[j_k]` of its influences (weights summing to
/// 1), normals through its inverse transpose; vertices whose weights are all zero keep the node
/// transform `node` (with one warning).
fn skin_mesh(
    mesh: &Mesh,
    influences: &[[(u16, f32); 4]],
    mats: &[Mat4],
    node: &Mat4,
    what: &str,
    warnings: &mut Vec<String>,
) -> Mesh {
    let mut unweighted = 0usize;
    let mut mirrored = Vec::with_capacity(mesh.positions.len());
    let mut positions = Vec::with_capacity(mesh.positions.len());
    let mut normals = Vec::with_capacity(mesh.positions.len());
    for (v, inf) in influences.iter().enumerate() {
        let m = if inf.iter().any(|&(_, w)| w > 0.0) {
            let mut m = Mat4 { cols: [[0.0; 4]; 4] };
            for &(j, f) in inf {
                if f == 0.0 {
                    continue;
                }
                let s = &mats[j as usize];
                for (c, sc) in m.cols.iter_mut().zip(&s.cols) {
                    for (x, y) in c.iter_mut().zip(sc) {
                        *x += f * y;
                    }
                }
            }
            m
        } else {
            unweighted += 1;
            *node
        };
        let p = hadou_math::Vec3f::from_array(mesh.positions[v]);
        positions.push(m.transform_point(p).to_array());
        let n0 = hadou_math::Vec3f::from_array(mesh.normals[v]);
        let n = m.normal_matrix().transform_vector(n0).normalize_or(n0.normalize_or(hadou_math::Vec3f::Y));
        normals.push(n.to_array());
        let (x, y, z) = (
            m.transform_vector(hadou_math::Vec3f::X),
            m.transform_vector(hadou_math::Vec3f::Y),
            m.transform_vector(hadou_math::Vec3f::Z),
        );
        mirrored.push(x.cross(y).dot(z) < 0.0);
    }
    if unweighted > 0 {
        warnings.push(format!(
            "{what}: {unweighted} vertices have all-zero skin weights; they are placed by their node's own \
             transform"
        ));
    }
    let mut indices = mesh.indices.clone();
    for t in indices.chunks_exact_mut(3) {
        // A mirroring skin matrix reverses the winding (decided by the majority of the corners).
        if t.iter().filter(|&&i| mirrored[i as usize]).count() >= 2 {
            t.swap(1, 2);
        }
    }
    Mesh { positions, normals, indices, ..mesh.clone() }
}

/// A primitive read in its mesh's space, with its skin attributes when it has them.
struct Primitive {
    mesh: Mesh,
    joints: Option<Vec<[u16; 4]>>,
    weights: Option<Vec<[f32; 4]>>,
    targets: Vec<MorphTarget>,
}

/// The accessor of attribute `sem` checked for layout, bounds and a count of `n`, if present.
fn attribute<'a>(
    prim: &gltf::Primitive<'a>,
    sem: Semantic,
    dims: &[Dimensions],
    types: &[DataType],
    buffers: &[Vec<u8>],
    n: usize,
) -> Result<Option<gltf::Accessor<'a>>, String> {
    let Some(acc) = prim.get(&sem) else { return Ok(None) };
    let name = sem.to_string();
    check_accessor(&acc, dims, types, buffers).map_err(|e| format!("{name}: {e}"))?;
    if acc.count() != n {
        return Err(format!("{name} has {} entries but POSITION has {n}", acc.count()));
    }
    Ok(Some(acc))
}

fn read_primitive(
    prim: &gltf::Primitive<'_>,
    ctx: &Ctx<'_>,
    what: &str,
    warnings: &mut Vec<String>,
) -> Result<Primitive, String> {
    let buffers = ctx.buffers;
    let mode = prim.mode();
    if mode != Mode::Triangles {
        return Err(format!("mode {mode:?} is not supported; only TRIANGLES (4) primitives can be loaded"));
    }
    let get = |b: gltf::Buffer<'_>| buffers.get(b.index()).map(|d| d.as_slice());
    let reader = prim.reader(get);

    let pos_acc = prim.get(&Semantic::Positions).ok_or("has no POSITION attribute")?;
    check_accessor(&pos_acc, &[Dimensions::Vec3], &[DataType::F32], buffers)
        .map_err(|e| format!("POSITION: {e}"))?;
    let positions: Vec<[f32; 3]> = reader.read_positions().ok_or("POSITION data cannot be read")?.collect();
    if positions.iter().flatten().any(|v| !v.is_finite()) {
        return Err("POSITION contains NaN or infinite values".into());
    }
    let n = positions.len();

    let indices: Vec<u32> = match prim.indices() {
        Some(acc) => {
            check_accessor(
                &acc,
                &[Dimensions::Scalar],
                &[DataType::U8, DataType::U16, DataType::U32],
                buffers,
            )
            .map_err(|e| format!("indices: {e}"))?;
            let idx: Vec<u32> = reader.read_indices().ok_or("indices cannot be read")?.into_u32().collect();
            if let Some(bad) = idx.iter().find(|&&i| i as usize >= n) {
                return Err(format!("index {bad} is out of range for {n} vertices"));
            }
            idx
        }
        None => (0..n as u32).collect(),
    };
    if !indices.len().is_multiple_of(3) {
        return Err(format!("{} indices is not a multiple of 3", indices.len()));
    }

    let normals = match attribute(prim, Semantic::Normals, &[Dimensions::Vec3], &[DataType::F32], buffers, n)?
    {
        Some(_) => {
            let normals: Vec<[f32; 3]> = reader.read_normals().ok_or("NORMAL data cannot be read")?.collect();
            if normals.len() != n {
                return Err(format!("NORMAL has {} entries but POSITION has {n}", normals.len()));
            }
            let fallback = smooth_normals(&positions, &indices);
            normals
                .iter()
                .zip(&fallback)
                .map(|(nv, f)| {
                    let v = hadou_math::Vec3f::from_array(*nv);
                    v.try_normalize().map_or(*f, |u| u.to_array())
                })
                .collect()
        }
        None => smooth_normals(&positions, &indices),
    };

    // Texture coordinates: the set the material's textures use, else TEXCOORD_0 when present.
    let mat_index = prim.material().index();
    let textured = mat_index.and_then(|m| ctx.materials.uv_set.get(m).copied().flatten());
    let set = textured.unwrap_or(0);
    let uv_types = [DataType::F32, DataType::U8, DataType::U16];
    let uvs: Vec<[f32; 2]> =
        match attribute(prim, Semantic::TexCoords(set), &[Dimensions::Vec2], &uv_types, buffers, n)? {
            Some(_) => {
                let uvs: Vec<[f32; 2]> =
                    reader.read_tex_coords(set).ok_or("TEXCOORD data cannot be read")?.into_f32().collect();
                if uvs.iter().flatten().any(|v| !v.is_finite()) {
                    return Err(format!("TEXCOORD_{set} contains NaN or infinite values"));
                }
                uvs
            }
            None => {
                if textured.is_some() {
                    warnings.push(format!(
                        "{what} has no TEXCOORD_{set}; its material's textures are sampled at uv (0, 0) there"
                    ));
                }
                Vec::new()
            }
        };

    let color_types = [DataType::F32, DataType::U8, DataType::U16];
    let colors: Vec<[f32; 4]> = match attribute(
        prim,
        Semantic::Colors(0),
        &[Dimensions::Vec3, Dimensions::Vec4],
        &color_types,
        buffers,
        n,
    )? {
        Some(_) => {
            let c: Vec<[f32; 4]> =
                reader.read_colors(0).ok_or("COLOR_0 data cannot be read")?.into_rgba_f32().collect();
            if c.iter().flatten().any(|v| !v.is_finite()) {
                return Err("COLOR_0 contains NaN or infinite values".into());
            }
            c.into_iter().map(|c| c.map(|v| v.max(0.0))).collect()
        }
        None => Vec::new(),
    };

    let joint_types = [DataType::U8, DataType::U16];
    let joints = match attribute(prim, Semantic::Joints(0), &[Dimensions::Vec4], &joint_types, buffers, n)? {
        Some(_) => Some(reader.read_joints(0).ok_or("JOINTS_0 data cannot be read")?.into_u16().collect()),
        None => None,
    };
    let weight_types = [DataType::F32, DataType::U8, DataType::U16];
    let weights = match attribute(prim, Semantic::Weights(0), &[Dimensions::Vec4], &weight_types, buffers, n)?
    {
        Some(_) => Some(reader.read_weights(0).ok_or("WEIGHTS_0 data cannot be read")?.into_f32().collect()),
        None => None,
    };

    let targets = read_targets(prim, &reader, buffers, n, &ctx.morph_left)?;
    let slot = ctx.materials.slot(mat_index);
    let mesh =
        Mesh { positions, normals, indices, uvs, colors, material_ids: vec![slot; n], ..Mesh::default() };
    Ok(Primitive { mesh, joints, weights, targets })
}

/// The morph targets of a primitive of `n` vertices (position and normal offsets; tangent offsets
/// are not used), each accessor checked, their offsets taken from `left`.
fn read_targets<'a, 's, F>(
    prim: &gltf::Primitive<'a>,
    reader: &gltf::mesh::Reader<'a, 's, F>,
    buffers: &[Vec<u8>],
    n: usize,
    left: &Cell<u64>,
) -> Result<Vec<MorphTarget>, String>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let count = prim.morph_targets().len();
    if count == 0 {
        return Ok(Vec::new());
    }
    if count > MAX_MORPH_TARGETS {
        return Err(format!("it has {count} morph targets, more than the limit of {MAX_MORPH_TARGETS}"));
    }
    let need = (count as u64).saturating_mul(n as u64);
    if need > left.get() {
        return Err(format!(
            "its morph targets bring the file past the limit of {MAX_MORPH_DELTAS} morph offsets (targets × \
             vertices, every instance counted)"
        ));
    }
    left.set(left.get() - need);
    for (i, t) in prim.morph_targets().enumerate() {
        for (name, acc) in [("POSITION", t.positions()), ("NORMAL", t.normals())] {
            if let Some(acc) = acc {
                check_accessor(&acc, &[Dimensions::Vec3], &[DataType::F32], buffers)
                    .map_err(|e| format!("morph target {i} {name}: {e}"))?;
                if acc.count() != n {
                    return Err(format!(
                        "morph target {i} {name} has {} entries but POSITION has {n}",
                        acc.count()
                    ));
                }
            }
        }
    }
    let mut targets = Vec::with_capacity(count);
    for (i, (pos, nrm, _)) in reader.read_morph_targets().enumerate() {
        let positions: Vec<[f32; 3]> = pos.map(|p| p.collect()).unwrap_or_default();
        let normals: Vec<[f32; 3]> = nrm.map(|p| p.collect()).unwrap_or_default();
        if positions.iter().chain(&normals).flatten().any(|v| !v.is_finite()) {
            return Err(format!("morph target {i} contains NaN or infinite values"));
        }
        targets.push(MorphTarget { positions, normals });
    }
    Ok(targets)
}
