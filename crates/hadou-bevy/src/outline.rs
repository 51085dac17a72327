//! [`HadouOutline`]: hadou's inverted-hull outline (000 §2.3, SPEC.md §2.3) as a Bevy material, for
//! a second mesh entity drawn over the same mesh: each vertex pushed along its world outline
//! normal by `d·|z|` (its view depth `z`, so the line keeps its width on screen), front faces
//! culled, so only the hull's back faces show around the silhouette, in the outline colour. The
//! twin of hadou-gpu's `vs_hull` (raster.wgsl) and hadou-cpu's `opaque::project_all`. A skinned
//! mesh's hull is skinned as Bevy skins the mesh.
//!
//! Under a camera with Bevy's depth and normal prepasses (`DepthPrepass`, `NormalPrepass`; a
//! spawned scene's camera has both) the outline is also closed where objects meet, as hadou's
//! edge pass closes it (hadou-gpu's `edges.wgsl`, 000 §2.3): a second hull entity with
//! `closing = true` ([`HadouOutline::closing`]) is drawn after the opaque meshes without a depth
//! test and keeps only the fragments where its hull is buried in the surface the prepass holds
//! (the ones the first, depth-tested hull loses) and its source point, the object's edge, is in
//! front of that surface's plane (its normal from the normal prepass) and within `CLOSE_REACH`
//! (3) hull widths of it, so the line where a character stands on the ground is drawn. Without
//! the prepasses the closing hull draws nothing. Bevy's prepass holds no object ids, so where
//! hadou's edge pass closes onto other objects only, the closing hull takes any surface that
//! near the edge (a part of the same object farther away, such as hair behind a face's rim, is
//! left alone).

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

/// The imports of [`HadouOutline`]'s WGSL.
const IMPORTS: &str = r"
#import bevy_pbr::mesh_functions
#import bevy_pbr::skinning
#import bevy_pbr::view_transformations::{position_world_to_clip, position_ndc_to_world, frag_coord_to_ndc}
#import bevy_pbr::mesh_view_bindings::view
#ifdef HADOU_CLOSING
#ifndef HADOU_NO_PREPASS
#import bevy_pbr::prepass_utils
#endif
#endif

";

/// [`HadouOutline`]'s own WGSL, after hadou-gpu's `common.wgsl`.
pub(crate) const SOURCE: &str = r"struct HadouOutlineUniform {
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
    // Its unit world outline normal.
    @location(1) normal: vec3<f32>,
    // How far it was pushed (world units).
    @location(2) push: f32,
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
    return Hull(position_world_to_clip(base + u * push), base, u, push);
}

#ifdef HADOU_CLOSING
// How far from the edge point, in hull widths, a surface the outline closes onto may be.
const CLOSE_REACH: f32 = 3.0;
// Mirrors hadou_math::outline::IN_FRONT_MARGIN.
const IN_FRONT_MARGIN: f32 = 1.0e-3;

// The closing hull (000 §2.3, hadou's edge pass): drawn after the opaque meshes without a depth
// test; a fragment is kept where the hull is buried in the surface the depth prepass holds (the
// depth-tested hull lost it) and its source point, the object's edge, is in front of that surface
// (hadou-gpu's edges.wgsl rule, common.wgsl's `in_front_by` the surface at p, its normal from the normal
// prepass; the hull's push is the edge's reach), so the line stays closed where the hull is
// buried in the ground or in another object. The surface keeps its depth.
@fragment
fn fragment(in: Hull, @builtin(sample_index) sample_index: u32) -> @location(0) vec4<f32> {
#ifdef HADOU_NO_PREPASS
    discard;
    return vec4<f32>(0.0);
#else
    let surface = prepass_utils::prepass_depth(in.clip, sample_index);
    // Reverse-Z: the hull at or behind a surface drawn there (0 is nothing drawn).
    var keep = surface > 0.0 && in.clip.z <= surface;
    if (keep) {
        let p = position_ndc_to_world(vec3<f32>(frag_coord_to_ndc(in.clip).xy, surface));
        let n = prepass_utils::prepass_normal(in.clip, sample_index);
        let pv = p - view.world_position;
        let qv = in.source - view.world_position;
        let pd = length(pv);
        let qd = length(qv);
        // hadou's edge pixel q is a visible point a fraction of a pixel above the surface it
        // closes onto, so it must be in front by the margin. A hull's source point where an
        // object stands on another lies on that surface's plane itself (the box's bottom face on
        // the ground), so where the two face each other (the outline normal against the
        // surface's) it may lie on the plane within the margin.
        var margin = IN_FRONT_MARGIN;
        if (dot(n, in.normal) < 0.0) {
            margin = -IN_FRONT_MARGIN;
        }
        // Only a surface the edge touches: within CLOSE_REACH hull widths of it (hadou's edge
        // pass closes onto another object's pixels within the hull's reach on screen; without
        // object ids, this keeps a part of the same object far behind its edge, e.g. hair
        // behind a face seen at its rim, from taking the line).
        let near = length(in.source - p) <= CLOSE_REACH * in.push;
        keep = near && pd > 0.0 && qd > 0.0 && in_front_by(n, pv / pd, pd, qv / qd, qd, margin);
    }
    if (!keep) {
        discard;
    }
    return vec4<f32>(outline.color.xyz, 1.0);
#endif
}
#else
@fragment
fn fragment() -> @location(0) vec4<f32> {
    return vec4<f32>(outline.color.xyz, 1.0);
}
#endif
";

/// The WGSL of [`HadouOutline`]: Bevy's imports, hadou-gpu's `common.wgsl` (`in_front_by`, the
/// edge pass's rule) and [`SOURCE`].
pub(crate) fn shader_source() -> String {
    format!("{IMPORTS}\n{}\n{SOURCE}", hadou_gpu::shaders::COMMON)
}

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
/// [`crate::outline_mesh`]). Writes its colour into the HDR target, depth-tested like any opaque
/// mesh; no shadows or prepass. Put its [`HadouOutline::closing`] hull over the same mesh too to
/// close the outline where objects meet (under a camera with the depth and normal prepasses).
#[derive(Asset, TypePath, AsBindGroup, Clone, Debug, PartialEq)]
#[bind_group_data(HadouOutlineKey)]
pub struct HadouOutline {
    /// The uniform.
    #[uniform(0)]
    pub outline: HadouOutlineUniform,
    /// The closing hull of an outline ([`HadouOutline::closing`]): drawn after the opaque meshes,
    /// only where the outline closes onto another surface (see the module's notes).
    pub closing: bool,
}

/// What selects [`HadouOutline`]'s pipeline: whether it is the closing hull.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct HadouOutlineKey {
    closing: bool,
}

impl From<&HadouOutline> for HadouOutlineKey {
    fn from(outline: &HadouOutline) -> Self {
        HadouOutlineKey { closing: outline.closing }
    }
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
            closing: false,
        }
    }

    /// The closing hull of this outline: the same colour and width, drawn where the outline
    /// closes onto another surface (the module's notes).
    pub fn closing(&self) -> Self {
        HadouOutline { closing: true, ..self.clone() }
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

    /// The closing hull is drawn after the opaque meshes (Bevy's transparent phase, without
    /// blending: see `specialize`), when the prepass holds every surface.
    fn alpha_mode(&self) -> AlphaMode {
        if self.closing {
            AlphaMode::Blend
        } else {
            AlphaMode::Opaque
        }
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
        if key.bind_group_data.closing {
            // An opaque colour over what is drawn; the surface keeps its depth; the test is the
            // fragment's own.
            if let Some(fragment) = descriptor.fragment.as_mut() {
                for target in fragment.targets.iter_mut().flatten() {
                    target.blend = None;
                }
                fragment.shader_defs.push("HADOU_CLOSING".into());
                let prepass = MeshPipelineKey::DEPTH_PREPASS | MeshPipelineKey::NORMAL_PREPASS;
                if !key.mesh_key.contains(prepass) {
                    fragment.shader_defs.push("HADOU_NO_PREPASS".into());
                }
            }
            if let Some(depth) = descriptor.depth_stencil.as_mut() {
                depth.depth_write_enabled = Some(false);
                depth.depth_compare = Some(CompareFunction::Always);
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
