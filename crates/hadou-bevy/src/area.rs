//! [`HadouAreaLight`]: a scene's `[area_light]` (soft shadows, docs/soft-shadows.md) on
//! [`HadouMaterial`]s. Its light is hadou-gpu's `area_term` (shading.wgsl: the lamp shape's
//! diffuse and toon terms) and its shadow the traced resolve's model: per fragment, the share of
//! the lamp the fragment's point sees, by hadou-gpu's `pixel_visibility` (soft_trace.wgsl: the
//! stackless walk of `hadou_math::soft::Bvh` and the samples each triangle hides), whatever
//! resolve the scene names. The hierarchy is built from the world-space triangles of the meshes
//! Bevy draws under the light's caster entities (their `Mesh3d`s under their `GlobalTransform`s,
//! a skinned mesh posed by its joints as Bevy's skinning poses it; outline hulls left out), again
//! whenever one of them moves or changes, and uploaded into [`AREA_NODES`] and [`AREA_TRIS`];
//! the lamp and its sample layout go to [`AREA_DATA`].

use crate::material::{HadouMaterial, AREA_DATA, AREA_NODES, AREA_TRIS};
use crate::outline::HadouOutline;
use bevy::asset::RenderAssetUsages;
use bevy::ecs::system::SystemParam;
use bevy::mesh::morph::{MeshMorphWeights, MorphWeights};
use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
use bevy::mesh::VertexAttributeValues;
use bevy::prelude::*;
use bevy::render::storage::ShaderBuffer;
use bytemuck::{Pod, Zeroable};
use hadou_gpu::layout::{GpuBvhNode, GpuBvhTri, TracedUniforms};
use hadou_math::soft::{Bvh, LampPattern, LampShape, MAX_TRACE_SAMPLES};
use hadou_math::Vec3f;

/// The largest magnitude of the lamp's and the target's coordinates (the scene reader's bound on
/// every number without a tighter rule).
pub const AREA_COORD_MAX: f32 = 1e6;

/// llvmpipe (Mesa's software rasterizer) ends a shader invocation's loops after this many
/// iterations of them all together; [`fragment_loop_bound`] is compared with it.
pub const LLVMPIPE_LOOP_BUDGET: u64 = 65_535;

/// A lamp-sized light whose shadows soften with distance (a scene's `[area_light]`, hadou's
/// traced resolve): drawn on every [`HadouMaterial`], its light scaled per fragment by the share
/// of the lamp the fragment sees past the meshes under `casters`. One is drawn at a time (the
/// first enabled, accepted one by entity); values outside the scene reader's ranges are rejected
/// ([`check_area_light`], [`AreaLightRejected`]).
#[derive(Component, Clone, Debug, PartialEq)]
pub struct HadouAreaLight {
    /// The lamp's shape (`shape`): the segment `L ± l·P`, a disc of radius `l` facing the target,
    /// or a sphere of radius `l`.
    pub shape: LampShape,
    /// The lamp's centre `L` (`position`).
    pub position: Vec3,
    /// The point of interest `G` (`target`): the segment's axis and the disc's normal point from
    /// it to `L`.
    pub target: Vec3,
    /// `l` (`size`): the segment's half-length, the disc's or the sphere's radius; `0 < l < |L − G|`.
    pub size: f32,
    /// Linear RGB times intensity (`color` × `intensity`), each finite and at least 0.
    pub color: Vec3,
    /// Lamp samples a fragment (`samples`), `1..=MAX_TRACE_SAMPLES` (1,024).
    pub samples: u32,
    /// The entities whose meshes (theirs and their descendants') cast the shadows (`casters`).
    pub casters: Vec<Entity>,
    /// Whether it is drawn.
    pub enabled: bool,
}

impl HadouAreaLight {
    /// The `[area_light]` of a frame with `casters` the entities of its caster objects (in the
    /// order of `light.casters`); `samples` is the traced resolve's, or hadou-scene's
    /// `DEFAULT_TRACE_SAMPLES` with another resolve.
    pub fn from_scene(light: &hadou_scene::AreaLight, casters: Vec<Entity>) -> Self {
        let v = |p: Vec3f| Vec3::new(p.x, p.y, p.z);
        let samples = match light.resolve {
            hadou_scene::SoftResolve::Traced { samples } => samples,
            _ => hadou_scene::DEFAULT_TRACE_SAMPLES,
        };
        HadouAreaLight {
            shape: light.shape,
            position: v(light.position),
            target: v(light.interest),
            size: light.size,
            color: Vec3::from_array(light.color),
            samples,
            casters,
            enabled: true,
        }
    }

    /// The lamp's axis `P = (L − G)/|L − G|` (`Y` where `L = G`).
    pub fn axis(&self) -> Vec3 {
        (self.position - self.target).try_normalize().unwrap_or(Vec3::Y)
    }
}

/// Why a [`HadouAreaLight`] is not drawn: the key and the rule it breaks.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("`{key}` {message}")]
pub struct AreaLightError {
    /// The scene key (`position`, `target`, `size`, `color`, `samples`).
    pub key: &'static str,
    /// What is wrong with it.
    pub message: String,
}

/// Put on an entity whose [`HadouAreaLight`] failed [`check_area_light`] (and removed once it
/// passes): the light is not drawn. The failure is logged once per bad key, naming the entity
/// and the key.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct AreaLightRejected(pub AreaLightError);

/// Checks a light against the scene reader's rules for the same keys: coordinates finite and
/// within ±[`AREA_COORD_MAX`], the target apart from the position, `0 < size < |L − G|` (the
/// size reaching the target is refused), a finite colour of no negative channel, `samples` in
/// `1..=MAX_TRACE_SAMPLES`.
pub fn check_area_light(light: &HadouAreaLight) -> Result<(), AreaLightError> {
    let err = |key, message: String| Err(AreaLightError { key, message });
    let point_ok = |p: Vec3| p.is_finite() && p.abs().max_element() <= AREA_COORD_MAX;
    if !point_ok(light.position) {
        return err("position", format!("must be finite within ±{AREA_COORD_MAX}, got {}", light.position));
    }
    if !point_ok(light.target) {
        return err("target", format!("must be finite within ±{AREA_COORD_MAX}, got {}", light.target));
    }
    let d = light.position.distance(light.target);
    if d == 0.0 {
        return err("target", "coincides with the light's `position`: G must differ from L".into());
    }
    if !(light.size > 0.0 && light.size < d) {
        return err(
            "size",
            format!(
                "must be greater than 0 and less than the distance from `position` to `target` ({d}), got {}",
                light.size
            ),
        );
    }
    if !(light.color.is_finite() && light.color.min_element() >= 0.0) {
        return err("color", format!("must be finite and at least 0, got {}", light.color));
    }
    if !(1..=MAX_TRACE_SAMPLES).contains(&light.samples) {
        return err(
            "samples",
            format!("must be in 1..={MAX_TRACE_SAMPLES} (lamp samples a fragment), got {}", light.samples),
        );
    }
    Ok(())
}

/// The error line logged for a rejected light: the entity, its `Name` if any, the key and why.
pub fn area_rejection_message(entity: Entity, name: Option<&Name>, error: &AreaLightError) -> String {
    match name {
        Some(name) => format!("hadou area light {entity} (\"{name}\") not drawn: {error}"),
        None => format!("hadou area light {entity} not drawn: {error}"),
    }
}

/// An area light as [`check_changed_area_lights`] reads it.
type LightToCheck =
    (Entity, &'static HadouAreaLight, Option<&'static Name>, Option<&'static AreaLightRejected>);

/// Checks every added or changed [`HadouAreaLight`]: a failing one gets [`AreaLightRejected`] and
/// one error log line each time the key it fails on changes; a passing one loses it.
pub(crate) fn check_changed_area_lights(
    mut commands: Commands,
    lights: Query<LightToCheck, Changed<HadouAreaLight>>,
) {
    for (entity, light, name, rejected) in &lights {
        match check_area_light(light) {
            Ok(()) => {
                if rejected.is_some() {
                    commands.entity(entity).remove::<AreaLightRejected>();
                }
            }
            Err(error) => {
                if rejected.map(|r| r.0.key) != Some(error.key) {
                    error!("{}", area_rejection_message(entity, name, &error));
                    commands.entity(entity).insert(AreaLightRejected(error));
                }
            }
        }
    }
}

/// [`AREA_DATA`]'s layout: keep in sync with `HadouArea` in material.rs's fragment stage.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct AreaRecord {
    drawn: u32,
    shape: u32,
    size: f32,
    pad: u32,
    position: [f32; 4],
    axis: [f32; 4],
    color: [f32; 4],
    pattern: TracedUniforms,
}

/// hadou-gpu's lamp code (`LAMP_SEGMENT`, `LAMP_DISC`, `LAMP_SPHERE` in common.wgsl).
fn shape_code(shape: LampShape) -> u32 {
    match shape {
        LampShape::Segment => 0,
        LampShape::Disc => 1,
        LampShape::Sphere => 2,
    }
}

/// The record of `light` over a hierarchy of `node_count` nodes (`None`: nothing drawn).
pub(crate) fn area_record(light: Option<&HadouAreaLight>, node_count: u32) -> AreaRecord {
    let Some(l) = light else { return AreaRecord::zeroed() };
    let v = |p: Vec3| [p.x, p.y, p.z, 0.0];
    AreaRecord {
        drawn: 1,
        shape: shape_code(l.shape),
        size: l.size,
        pad: 0,
        position: v(l.position),
        axis: v(l.axis()),
        color: v(l.color),
        pattern: TracedUniforms::new(&LampPattern::new(l.shape, l.samples), node_count),
    }
}

/// The most loop iterations one fragment's walk of a hierarchy of `nodes` nodes and `tris`
/// triangles can spend with `samples` lamp samples of `shape` (`pixel_visibility` and its
/// callers in soft_trace.wgsl): every node, every triangle's rows and mask words, the mask's
/// count. Past [`LLVMPIPE_LOOP_BUDGET`] a fragment on llvmpipe could stop short (too bright);
/// a hardware GPU has no such budget. A fragment stops at the first full mask, so most spend far
/// fewer.
pub fn fragment_loop_bound(shape: LampShape, samples: u32, nodes: u64, tris: u64) -> u64 {
    let p = LampPattern::new(shape, samples);
    let words = u64::from(p.per_row.div_ceil(32)) + 1;
    let rows = u64::from(p.rows);
    nodes + tris * (1 + rows * (1 + words)) + rows * (1 + words) + 32
}

/// The world-space triangles of the meshes under `root` (itself and its descendants) that Bevy
/// draws with a material other than the outline hull's: each `Mesh3d` under its
/// `GlobalTransform`, a skinned one posed by its joints (`Σ wᵢ · joint_globalᵢ · inverse_bindposeᵢ`,
/// as Bevy's skinning does). Meshes not loaded yet, and triangles with an index out of range,
/// are left out.
pub(crate) fn caster_triangles(root: Entity, scene: &CasterScene, out: &mut Vec<[Vec3f; 3]>) {
    let entities = std::iter::once(root).chain(scene.children.iter_descendants(root));
    for e in entities {
        let Ok((mesh, global, skin, morph)) = scene.meshes.get(e) else { continue };
        let Some(mesh) = scene.mesh_assets.get(&mesh.0) else { continue };
        // A mesh whose data went to the render world only (`RenderAssetUsages::RENDER_WORLD`)
        // has nothing to read here and casts nothing.
        let Ok(Some(VertexAttributeValues::Float32x3(positions))) =
            mesh.try_attribute_option(Mesh::ATTRIBUTE_POSITION)
        else {
            continue;
        };
        let Ok(indices) = mesh.try_indices_option() else { continue };
        let positions = morphed(mesh, positions, morph.and_then(|m| morph_weights(m, scene)));
        let world: Vec<Vec3> = match skin.and_then(|s| skinned(mesh, s, scene)) {
            Some(matrices) => positions.iter().zip(matrices).map(|(p, m)| m.transform_point3(*p)).collect(),
            None => {
                let m = global.affine();
                positions.iter().map(|p| m.transform_point3(*p)).collect()
            }
        };
        let corner = |i: usize| world.get(i).map(|v| Vec3f::new(v.x, v.y, v.z));
        let mut push = |a: usize, b: usize, c: usize| {
            if let (Some(a), Some(b), Some(c)) = (corner(a), corner(b), corner(c)) {
                out.push([a, b, c]);
            }
        };
        match indices {
            Some(indices) => {
                let all: Vec<usize> = indices.iter().collect();
                for t in all.chunks_exact(3) {
                    push(t[0], t[1], t[2]);
                }
            }
            None => {
                for t in 0..world.len() / 3 {
                    push(3 * t, 3 * t + 1, 3 * t + 2);
                }
            }
        }
    }
}

/// The weights a mesh's morph targets are blended by, as Bevy's morphing reads them: its own
/// (`MeshMorphWeights::Value`) or those of the entity it refers to (a glTF node's
/// `MorphWeights`); `None` when that entity has none.
fn morph_weights<'a>(morph: &'a MeshMorphWeights, scene: &'a CasterScene) -> Option<&'a [f32]> {
    match morph {
        MeshMorphWeights::Value { weights } => Some(weights),
        MeshMorphWeights::Reference(e) => scene.weights.get(*e).ok().map(MorphWeights::weights),
    }
}

/// The mesh's vertex positions with its morph targets blended in before skinning, as Bevy's
/// morphing does (glTF 2.0 §3.7.2.2: `p + Σ wₖ·Δpₖ`, the targets' displacements stored target
/// after target). Weights that are not finite, and targets past the weights or the mesh's data,
/// add nothing.
fn morphed(mesh: &Mesh, positions: &[[f32; 3]], weights: Option<&[f32]>) -> Vec<Vec3> {
    let mut out: Vec<Vec3> = positions.iter().map(|p| Vec3::from_array(*p)).collect();
    let (Some(weights), Some(targets)) = (weights, mesh.try_morph_targets().ok()) else { return out };
    let n = out.len();
    if n == 0 {
        return out;
    }
    for (w, target) in weights.iter().zip(targets.chunks_exact(n)) {
        if *w == 0.0 || !w.is_finite() {
            continue;
        }
        for (p, d) in out.iter_mut().zip(target) {
            *p += *w * d.position;
        }
    }
    out
}

/// Each vertex's skinning matrix of a skinned `mesh`, or `None` when the mesh has no joint
/// attributes or its joints or inverse bind poses are not there yet (it is then placed by its
/// `GlobalTransform`).
fn skinned(mesh: &Mesh, skin: &SkinnedMesh, scene: &CasterScene) -> Option<Vec<Mat4>> {
    let bindposes = scene.bindposes.as_deref()?.get(&skin.inverse_bindposes)?;
    let joints: Vec<Mat4> = skin
        .joints
        .iter()
        .zip(bindposes.iter())
        .map(|(&j, ibp)| scene.globals.get(j).ok().map(|g| g.to_matrix() * *ibp))
        .collect::<Option<_>>()?;
    let Ok(Some(VertexAttributeValues::Uint16x4(index))) =
        mesh.try_attribute_option(Mesh::ATTRIBUTE_JOINT_INDEX)
    else {
        return None;
    };
    let Ok(Some(VertexAttributeValues::Float32x4(weight))) =
        mesh.try_attribute_option(Mesh::ATTRIBUTE_JOINT_WEIGHT)
    else {
        return None;
    };
    let matrices = index
        .iter()
        .zip(weight)
        .map(|(i, w)| {
            (0..4).fold(Mat4::ZERO, |m, k| {
                m + joints.get(usize::from(i[k])).copied().unwrap_or(Mat4::ZERO) * w[k]
            })
        })
        .collect();
    Some(matrices)
}

/// What the casters' triangles are read from (also the shadows' drawn poses, drawn_pose.rs): the
/// hierarchy, the meshes Bevy draws (outline hulls left out), their transforms, their morph
/// weights (`MeshMorphWeights`, a glTF mesh's referring to its node's `MorphWeights`) and the
/// skins' inverse bind poses.
#[derive(SystemParam)]
pub(crate) struct CasterScene<'w, 's> {
    children: Query<'w, 's, &'static Children>,
    meshes: Query<'w, 's, CasterMesh, Without<MeshMaterial3d<HadouOutline>>>,
    globals: Query<'w, 's, &'static GlobalTransform>,
    weights: Query<'w, 's, &'static MorphWeights>,
    mesh_assets: Res<'w, Assets<Mesh>>,
    bindposes: Option<Res<'w, Assets<SkinnedMeshInverseBindposes>>>,
}

/// A mesh a caster draws: its mesh, its transform, its skin if skinned and its morph weights if
/// it has morph targets.
pub(crate) type CasterMesh = (
    &'static Mesh3d,
    &'static GlobalTransform,
    Option<&'static SkinnedMesh>,
    Option<&'static MeshMorphWeights>,
);

/// What decides whether the casters' triangles changed: per caster mesh its entity, its morph
/// weights, mesh, whether the mesh is loaded, its transform and its joints' transforms.
fn caster_key(casters: &[Entity], scene: &CasterScene) -> Vec<u64> {
    let mut key = Vec::new();
    let bits = |m: Mat4, key: &mut Vec<u64>| {
        key.extend(
            m.to_cols_array()
                .chunks_exact(2)
                .map(|c| u64::from(c[0].to_bits()) << 32 | u64::from(c[1].to_bits())),
        );
    };
    for &root in casters {
        key.push(root.to_bits());
        for e in std::iter::once(root).chain(scene.children.iter_descendants(root)) {
            let Ok((mesh, global, skin, morph)) = scene.meshes.get(e) else { continue };
            key.push(e.to_bits());
            if let Some(weights) = morph.and_then(|m| morph_weights(m, scene)) {
                key.extend(weights.iter().map(|w| u64::from(w.to_bits())));
            }
            let id = mesh.0.id();
            let mut h = std::hash::DefaultHasher::new();
            std::hash::Hash::hash(&id, &mut h);
            key.push(std::hash::Hasher::finish(&h));
            key.push(u64::from(scene.mesh_assets.contains(id)));
            bits(global.to_matrix(), &mut key);
            for &j in skin.map_or(&[][..], |s| &s.joints[..]) {
                if let Ok(g) = scene.globals.get(j) {
                    bits(g.to_matrix(), &mut key);
                }
            }
        }
    }
    key
}

/// What [`update_area_light`] last wrote.
#[derive(Default)]
pub(crate) struct AreaWritten {
    casters: Vec<u64>,
    record: Vec<u8>,
    capacity: (usize, usize),
    nodes: u64,
    refused: Option<Entity>,
    over_budget: Option<Entity>,
    warned_many: bool,
}

/// The initial contents of [`AREA_DATA`], [`AREA_NODES`] and [`AREA_TRIS`]: nothing drawn.
pub(crate) fn insert_buffers(buffers: &mut Assets<ShaderBuffer>) {
    let record = area_record(None, 0);
    for (handle, bytes) in [
        (&AREA_DATA, bytemuck::bytes_of(&record).to_vec()),
        (&AREA_NODES, vec![0u8; MIN_NODES * std::mem::size_of::<GpuBvhNode>()]),
        (&AREA_TRIS, vec![0u8; MIN_TRIS * std::mem::size_of::<GpuBvhTri>()]),
    ] {
        buffers
            .insert(handle, ShaderBuffer::new(&bytes, RenderAssetUsages::default()))
            .expect("a buffer under a fixed handle can be inserted");
    }
}

/// The smallest sizes of [`AREA_NODES`] and [`AREA_TRIS`], in records; they grow by doubling.
const MIN_NODES: usize = 64;
const MIN_TRIS: usize = 64;

/// Writes the drawn [`HadouAreaLight`] into [`AREA_DATA`] and, when its casters' meshes moved or
/// changed (or the light or its casters did), builds their hierarchy again into [`AREA_NODES`]
/// and [`AREA_TRIS`]. A hierarchy past hadou-scene's `TRACE_MAX_BYTES` is refused (logged once,
/// naming the light and `casters`; the light is not drawn); one whose fragments could pass
/// llvmpipe's loop budget is warned about once. When the buffers grow every
/// [`HadouMaterial`] is marked changed so that Bevy binds the new ones.
#[allow(clippy::too_many_arguments)]
pub(crate) fn update_area_light(
    lights: Query<(Entity, &HadouAreaLight, Option<&Name>), Without<AreaLightRejected>>,
    scene: CasterScene,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
    mut materials: ResMut<Assets<HadouMaterial>>,
    mut written: Local<AreaWritten>,
) {
    let mut drawn: Vec<_> = lights.iter().filter(|(_, l, _)| l.enabled).collect();
    drawn.sort_by_key(|(e, _, _)| *e);
    if drawn.len() > 1 && !written.warned_many {
        written.warned_many = true;
        warn!(
            "{} hadou area lights are enabled; only the first by entity ({}) is drawn",
            drawn.len(),
            drawn[0].0
        );
    }
    let light = drawn.first().copied();
    let mut key = light.map_or_else(Vec::new, |(_, l, _)| caster_key(&l.casters, &scene));
    key.push(light.map_or(u64::MAX, |(e, _, _)| e.to_bits()));
    let mut resized = false;
    if key != written.casters || written.capacity == (0, 0) {
        let mut tris = Vec::new();
        if let Some((_, l, _)) = light {
            for &c in &l.casters {
                caster_triangles(c, &scene, &mut tris);
            }
        }
        let (bvh, refused) = match hadou_scene::check_trace_memory(tris.len() as u64) {
            Ok(()) => (Bvh::build(&tris), false),
            Err(e) => {
                if let Some((entity, _, name)) = light.filter(|(e, _, _)| written.refused != Some(*e)) {
                    written.refused = Some(entity);
                    let what = area_rejection_message(
                        entity,
                        name,
                        &AreaLightError { key: "casters", message: format!("are too large: {e}") },
                    );
                    error!("{what}");
                }
                (Bvh::default(), true)
            }
        };
        let nodes: Vec<GpuBvhNode> = bvh.nodes.iter().map(GpuBvhNode::from).collect();
        let gpu_tris: Vec<GpuBvhTri> = bvh.tris.iter().map(GpuBvhTri::from).collect();
        if let Some((entity, l, name)) = light {
            let bound = fragment_loop_bound(l.shape, l.samples, nodes.len() as u64, gpu_tris.len() as u64);
            if bound > LLVMPIPE_LOOP_BUDGET && written.over_budget != Some(entity) {
                written.over_budget = Some(entity);
                let who = name.map_or_else(|| format!("{entity}"), |n| format!("{entity} (\"{n}\")"));
                warn!(
                    "hadou area light {who}: a fragment's walk of its casters' {} triangles may take up to {bound} \
                     loop iterations; a software rasterizer (llvmpipe) stops at {LLVMPIPE_LOOP_BUDGET}",
                    gpu_tris.len()
                );
            }
        }
        let capacity = (
            nodes.len().next_power_of_two().max(MIN_NODES).max(written.capacity.0),
            gpu_tris.len().next_power_of_two().max(MIN_TRIS).max(written.capacity.1),
        );
        let mut node_bytes = vec![0u8; capacity.0 * std::mem::size_of::<GpuBvhNode>()];
        node_bytes[..nodes.len() * std::mem::size_of::<GpuBvhNode>()]
            .copy_from_slice(bytemuck::cast_slice(&nodes));
        let mut tri_bytes = vec![0u8; capacity.1 * std::mem::size_of::<GpuBvhTri>()];
        tri_bytes[..gpu_tris.len() * std::mem::size_of::<GpuBvhTri>()]
            .copy_from_slice(bytemuck::cast_slice(&gpu_tris));
        if let Some(mut b) = buffers.get_mut(&AREA_NODES) {
            b.data = Some(node_bytes);
        }
        if let Some(mut b) = buffers.get_mut(&AREA_TRIS) {
            b.data = Some(tri_bytes);
        }
        resized = written.capacity != (0, 0) && capacity != written.capacity;
        written.capacity = capacity;
        written.nodes = if refused { u64::MAX } else { nodes.len() as u64 };
        written.casters = key;
    }
    let shown = light.filter(|_| written.nodes != u64::MAX).map(|(_, l, _)| l);
    let record = area_record(shown, written.nodes.min(u64::from(u32::MAX)) as u32);
    let bytes = bytemuck::bytes_of(&record);
    if bytes != written.record.as_slice() {
        if let Some(mut b) = buffers.get_mut(&AREA_DATA) {
            b.data = Some(bytes.to_vec());
        }
        written.record = bytes.to_vec();
    }
    if resized {
        for _ in materials.iter_mut() {}
    }
}
