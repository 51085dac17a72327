//! [`HadouOutline`]: hadou's inverted-hull outline (000 §2.3, SPEC.md §2.3) as a Bevy material, for
//! a second mesh entity drawn over the same mesh: each vertex pushed along its world outline
//! normal by `d·|z|` (its view depth `z`, so the line keeps its width on screen), front faces
//! culled, so only the hull's back faces show around the silhouette, in the outline colour. The
//! twin of hadou-gpu's `vs_hull` (raster.wgsl) and hadou-cpu's `opaque::project_all`. A skinned
//! mesh's hull is skinned as Bevy skins the mesh.
//!
//! Under a camera with Bevy's depth and normal prepasses (`DepthPrepass`, `NormalPrepass`; a
//! spawned scene's camera has both) the outline is closed where objects meet, as hadou's edge
//! pass closes it (hadou-gpu's `edges.wgsl`, 000 §2.3): the hull is drawn after the opaque meshes
//! without a depth test, and a fragment is kept where the hull is in front of the surface in the
//! prepass depth or where the hull vertex's source point (the object's edge) is not behind that
//! surface's plane (its normal from the normal prepass), so the line where a character stands on
//! the ground, whose hull is buried in the ground, is drawn. Without the prepasses the hull is
//! depth-tested as before.

use bevy::asset::uuid_handle;
use bevy::mesh::MeshVertexBufferLayoutRef;
use bevy::pbr::{Material, MaterialPipeline, MaterialPipelineKey, MeshPipelineKey};
use bevy::prelude::*;
use bevy::render::render_resource::{
    AsBindGroup, CompareFunction, Face, RenderPipelineDescriptor, ShaderType, SpecializedMeshPipelineError,
};
use bevy::shader::ShaderRef;

/// The shader of [`HadouOutline`] (vertex and fragment), inserted at start-up.
pub(crate) const SHADER: Handle<Shader> = uuid_handle!("3f6b8d0a-2c4e-4a6f-9b1d-3e5f7a9c1b19");

/// The WGSL of [`HadouOutline`].
pub(crate) const SOURCE: &str = r"
#import bevy_pbr::mesh_functions
#import bevy_pbr::skinning
#import bevy_pbr::view_transformations::{position_world_to_clip, position_ndc_to_world, frag_coord_to_ndc}
#import bevy_pbr::mesh_view_bindings::view
#ifdef HADOU_CLOSED_OUTLINE
#import bevy_pbr::prepass_utils
#endif

struct HadouOutlineUniform {
    color: vec4<f32>,
    width: f32,
    mode: u32,
    pad1: u32,
    pad2: u32,
}
@group(#{MATERIAL_BIND_GROUP}) @binding(0) var<uniform> outline: HadouOutlineUniform;

struct Vertex {
    @builtin(instance_index) instance_index: u32,
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
#ifdef SKINNED
    @location(6) joint_indices: vec4<u32>,
    @location(7) joint_weights: vec4<f32>,
#endif
}

struct Hull {
    @builtin(position) clip: vec4<f32>,
    // The vertex before the push: the point of the object's own surface the hull fragment stands
    // for (the edge pixel q of hadou's edge pass).
    @location(0) source: vec3<f32>,
}

// The hull vertex (000 §2.3): R' = R + d·|R_z|·U, U the unit world outline normal, R_z the view
// depth of the vertex (hadou-gpu's vs_hull).
@vertex
fn vertex(v: Vertex) -> Hull {
#ifdef SKINNED
    // A skinned mesh (Bevy's joints, as Bevy's own mesh shader skins it).
    let world_from_local = skinning::skin_model(v.joint_indices, v.joint_weights, v.instance_index);
    let n = skinning::skin_normals(world_from_local, v.normal);
#else
    let world_from_local = mesh_functions::get_world_from_local(v.instance_index);
    let n = mesh_functions::mesh_normal_local_to_world(v.normal, v.instance_index);
#endif
    let base = mesh_functions::mesh_position_local_to_world(world_from_local, vec4<f32>(v.position, 1.0)).xyz;
    let len = length(n);
    var u = vec3<f32>(0.0);
    if (len > 0.0 && len < 3.0e38) {
        u = n / len;
    }
    // The mode and width OR-ed with a zero the driver cannot fold (the top bit of the instance
    // index: no draw holds 2³¹ instances), as HadouMaterial's `load_surface`: lavapipe would
    // otherwise compile this shader again for every hull drawn (Mesa's uniform inlining).
    let zero = v.instance_index >> 31u;
    let mode = outline.mode | zero;
    let width = bitcast<f32>(bitcast<u32>(outline.width) | zero);
    let forward = -normalize(view.world_from_view[2].xyz);
    let z = dot(base - view.world_position, forward);
    // hadou_scene::Material::hull_push: hadou's d·|z|; an MToon outline in world units w, or in
    // screen mode 2·tan(fov/2)·w·|z| (w a fraction of the view's height).
    var push = width * abs(z);
    if (mode == 1u) {
        push = width;
    } else if (mode == 2u) {
        push = 2.0 * width * abs(z) / view.clip_from_view[1][1];
    }
    return Hull(position_world_to_clip(base + u * push), base);
}

#ifdef HADOU_CLOSED_OUTLINE
// Mirrors hadou_math::outline::IN_FRONT_MARGIN.
const IN_FRONT_MARGIN: f32 = 1.0e-3;

// hadou_math::outline::in_front (hadou-gpu's edges.wgsl) with its margin turned around: whether
// the point q = eye + q_dist·q_dir is not behind the surface through p = eye + p_dist·p_dir with
// normal p_normal (flipped to face the eye) by more than IN_FRONT_MARGIN of p's distance. hadou's
// edge pixel q is a visible surface point a fraction of a pixel above the surface it closes onto,
// so it must be in front by the margin; a hull's source point where an object stands on another
// lies on that surface's plane itself (the box's bottom face on the ground), so it may be on it
// within the margin.
fn not_behind(p_normal: vec3<f32>, p_dir: vec3<f32>, p_dist: f32, q_dir: vec3<f32>, q_dist: f32) -> bool {
    let len = length(p_normal);
    var n = -p_dir;
    if (len > 0.0 && len < 3.0e38) {
        n = p_normal / len;
    }
    if (dot(n, p_dir) > 0.0) {
        n = -n;
    }
    let num = p_dist * dot(n, p_dir);
    let den = dot(n, q_dir);
    return q_dist * den > num * (1.0 + IN_FRONT_MARGIN);
}

struct Closed {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// The closed outline (000 §2.3, hadou's edge pass): the hull is drawn after the opaque meshes
// without a depth test, and a fragment is kept where the hull is in front of the surface the
// depth prepass holds there (the inverted hull's own rule) or where its source point, the
// object's edge, is not behind that surface (hadou-gpu's edges.wgsl rule, `not_behind` the
// surface at p, its normal from the normal prepass; the hull's push is the edge's reach), so the
// line stays closed where the hull is buried in the ground or in another object. It keeps the
// nearer depth of the two.
@fragment
fn fragment(in: Hull, @builtin(sample_index) sample_index: u32) -> Closed {
    let surface = prepass_utils::prepass_depth(in.clip, sample_index);
    var keep = in.clip.z >= surface;
    if (!keep) {
        let p = position_ndc_to_world(vec3<f32>(frag_coord_to_ndc(in.clip).xy, surface));
        let n = prepass_utils::prepass_normal(in.clip, sample_index);
        let pv = p - view.world_position;
        let qv = in.source - view.world_position;
        let pd = length(pv);
        let qd = length(qv);
        keep = pd > 0.0 && qd > 0.0 && not_behind(n, pv / pd, pd, qv / qd, qd);
    }
    if (!keep) {
        discard;
    }
    return Closed(vec4<f32>(outline.color.xyz, 1.0), max(in.clip.z, surface));
}
#else
@fragment
fn fragment() -> @location(0) vec4<f32> {
    return vec4<f32>(outline.color.xyz, 1.0);
}
#endif
";

/// The outline's colour and width, as the shader reads them.
#[derive(Clone, Copy, Debug, PartialEq, ShaderType)]
pub struct HadouOutlineUniform {
    /// Linear RGB outline colour (`w` unused).
    pub color: Vec4,
    /// `outline_width` `d`: the push along the normal per unit of view depth; for an MToon
    /// outline its `outlineWidthFactor` `w` ([`HadouOutline::of`]).
    pub width: f32,
    /// How `width` pushes (`hadou_scene::Material::hull_push`): 0 `d·|z|`, 1 MToon's world
    /// mode `w`, 2 MToon's screen mode `2·tan(fov/2)·w·|z|`.
    pub mode: u32,
    /// Padding.
    pub pad1: u32,
    /// Padding.
    pub pad2: u32,
}

/// hadou's inverted-hull outline of a mesh (a `[[material]]`'s `outline`, `outline_color`,
/// `outline_width`): put it with the same mesh as the shaded entity (whose `NORMAL`s may be
/// replaced by outline normals, averaged per position, so the hull stays closed at hard edges:
/// [`crate::outline_mesh`]). Writes its colour and depth into the view after the opaque meshes
/// (Bevy's transparent phase, no blending), depth-tested, or closed where objects meet when the
/// camera has the depth and normal prepasses (see the module's notes); casts no shadows and has
/// no prepass of its own.
#[derive(Asset, TypePath, AsBindGroup, Clone, Debug, PartialEq)]
pub struct HadouOutline {
    /// The uniform.
    #[uniform(0)]
    pub outline: HadouOutlineUniform,
}

impl HadouOutline {
    /// The outline of `material` under `light`, `None` without one (or of width 0): hadou's, or a
    /// VRM material's MToon outline (`VRMC_materials_mtoon` "Outline": its width mode, and its
    /// colour mixed with the light, `Material::outline_rgb`).
    pub fn of(material: &hadou_scene::Material, light: &hadou_scene::Light) -> Option<Self> {
        let outline = material.outline.filter(|o| o.width > 0.0)?;
        let mut hull = HadouOutline::new(&outline);
        let [r, g, b] = material.outline_rgb(light);
        hull.outline.color = Vec4::new(r, g, b, 1.0);
        hull.outline.mode = match material.mtoon.as_ref().map(|t| t.outline_mode) {
            Some(hadou_scene::OutlineWidthMode::World) => 1,
            Some(hadou_scene::OutlineWidthMode::Screen) => 2,
            _ => 0,
        };
        Some(hull)
    }

    /// The outline of `outline` (colour, width).
    pub fn new(outline: &hadou_scene::Outline) -> Self {
        let [r, g, b] = outline.color;
        HadouOutline {
            outline: HadouOutlineUniform {
                color: Vec4::new(r, g, b, 1.0),
                width: outline.width,
                mode: 0,
                pad1: 0,
                pad2: 0,
            },
        }
    }
}

impl Material for HadouOutline {
    fn vertex_shader() -> ShaderRef {
        ShaderRef::Handle(SHADER)
    }

    fn fragment_shader() -> ShaderRef {
        ShaderRef::Handle(SHADER)
    }

    fn enable_prepass() -> bool {
        false
    }

    /// Drawn after the opaque meshes (Bevy's transparent phase), replacing the colour and writing
    /// depth (see `specialize`), so that a closed outline sees every surface's prepass depth.
    fn alpha_mode(&self) -> AlphaMode {
        AlphaMode::Blend
    }

    fn enable_shadows() -> bool {
        false
    }

    fn specialize(
        _pipeline: &MaterialPipeline,
        descriptor: &mut RenderPipelineDescriptor,
        layout: &MeshVertexBufferLayoutRef,
        key: MaterialPipelineKey<Self>,
    ) -> Result<(), SpecializedMeshPipelineError> {
        let mut attributes = vec![
            Mesh::ATTRIBUTE_POSITION.at_shader_location(0),
            Mesh::ATTRIBUTE_NORMAL.at_shader_location(1),
        ];
        // Bevy's mesh pipeline has set `SKINNED` and the joints' bind group for a skinned mesh;
        // its joints are read where Bevy's own mesh shader reads them.
        if layout.0.contains(Mesh::ATTRIBUTE_JOINT_INDEX) && layout.0.contains(Mesh::ATTRIBUTE_JOINT_WEIGHT) {
            attributes.push(Mesh::ATTRIBUTE_JOINT_INDEX.at_shader_location(6));
            attributes.push(Mesh::ATTRIBUTE_JOINT_WEIGHT.at_shader_location(7));
        }
        let buffer = layout.0.get_layout(&attributes)?;
        descriptor.vertex.buffers = vec![buffer];
        descriptor.primitive.cull_mode = Some(Face::Front);
        // An opaque colour: the outline replaces what is drawn, and writes its depth.
        if let Some(fragment) = descriptor.fragment.as_mut() {
            for target in fragment.targets.iter_mut().flatten() {
                target.blend = None;
            }
        }
        let closed = key.mesh_key.contains(MeshPipelineKey::DEPTH_PREPASS | MeshPipelineKey::NORMAL_PREPASS);
        if let Some(depth) = descriptor.depth_stencil.as_mut() {
            depth.depth_write_enabled = Some(true);
            if closed {
                // The test is the fragment's own (the hull, or its edge, in front of the surface).
                depth.depth_compare = Some(CompareFunction::Always);
            }
        }
        if closed {
            descriptor.vertex.shader_defs.push("HADOU_CLOSED_OUTLINE".into());
            if let Some(fragment) = descriptor.fragment.as_mut() {
                fragment.shader_defs.push("HADOU_CLOSED_OUTLINE".into());
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 45 (a game's load): the words of the uniform that decide the hull's branches are read
    /// once each, OR-ed with the instance index's top bit, so lavapipe does not compile the shader
    /// again for every hull drawn (see `HadouMaterial`'s `load_surface`).
    #[test]
    fn issue_45_the_deciding_words_are_read_only_through_the_zero() {
        assert!(SOURCE.contains("let zero = v.instance_index >> 31u;"));
        assert_eq!(SOURCE.matches("outline.mode").count(), 1);
        assert!(SOURCE.contains("let mode = outline.mode | zero;"));
        assert_eq!(SOURCE.matches("outline.width").count(), 1);
        assert!(SOURCE.contains("let width = bitcast<f32>(bitcast<u32>(outline.width) | zero);"));
    }
}
