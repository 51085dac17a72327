//! What every pass is built from: shader compilation, bind-group-layout entries, pipeline
//! layouts, the vertex layout of the cached meshes, cleared attachments, and the draw loop over
//! cached meshes.

use crate::device::GpuContext;
use crate::layout::GpuVertex;
use crate::meshes::MeshCache;
use hadou_scene::{Frame, RenderError};

/// Compiles WGSL into a module; a compile error becomes [`RenderError::Other`] naming the module.
pub(crate) fn compile_module(
    ctx: &GpuContext,
    label: &str,
    source: &str,
) -> Result<wgpu::ShaderModule, RenderError> {
    let module = ctx
        .scoped(&format!("compiling shader `{label}`"), || {
            ctx.device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            })
        })
        .map_err(|e| match e {
            RenderError::Other(m) | RenderError::Device(m) => {
                RenderError::Other(format!("shader `{label}` failed to compile: {m}"))
            }
            other => other,
        })?;
    Ok(module)
}

/// What a binding of a pass's bind group holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// A uniform buffer.
    Uniform,
    /// A read-only storage buffer.
    Storage,
    /// A read-write storage buffer.
    StorageRw,
    /// A 2-D `u32` texture read with `textureLoad` (the G-buffer, the plane-shadow target, the soft
    /// maps).
    UintTexture,
    /// A 2-D `rgba32uint` storage texture written with `textureStore` (the edge pass's output).
    UintStorageTexture,
    /// A 2-D array of depth read with `textureLoad` as unfilterable `f32` (the shadow maps).
    DepthArray,
    /// A 2-D depth texture read with `textureLoad` as unfilterable `f32` (a caller's depth
    /// buffer; GL has no `textureLoad` of depth textures, so not `texture_depth_2d`).
    Depth,
    /// [`Kind::Depth`] with several samples per pixel (a caller's multisampled depth buffer).
    DepthMultisampled,
}

/// One binding of a pass's bind group (group 0): its number, the name of the WGSL variable it
/// binds, what it holds and the stages that see it. Each pass declares its bindings once, in one
/// table, from which its bind group layout is built; `passes::tests` holds every table to the
/// `@binding` declarations of the pass's WGSL.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Binding {
    pub(crate) binding: u32,
    /// Read by the tests only (holding the table to the shader).
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) name: &'static str,
    pub(crate) kind: Kind,
    pub(crate) visibility: wgpu::ShaderStages,
}

impl Binding {
    /// A binding of `kind` seen by `visibility`.
    pub(crate) const fn new(
        binding: u32,
        name: &'static str,
        kind: Kind,
        visibility: wgpu::ShaderStages,
    ) -> Self {
        Self { binding, name, kind, visibility }
    }

    fn layout_entry(&self) -> wgpu::BindGroupLayoutEntry {
        let buffer = |ty| wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None };
        let ty = match self.kind {
            Kind::Uniform => buffer(wgpu::BufferBindingType::Uniform),
            Kind::Storage => buffer(wgpu::BufferBindingType::Storage { read_only: true }),
            Kind::StorageRw => buffer(wgpu::BufferBindingType::Storage { read_only: false }),
            Kind::UintTexture => wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Uint,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            Kind::UintStorageTexture => wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: crate::formats::SCENE_FORMAT,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            Kind::Depth => wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            Kind::DepthMultisampled => wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: true,
            },
            Kind::DepthArray => wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2Array,
                multisampled: false,
            },
        };
        wgpu::BindGroupLayoutEntry { binding: self.binding, visibility: self.visibility, ty, count: None }
    }
}

/// The bind group layout of `bindings`.
pub(crate) fn bind_group_layout(
    device: &wgpu::Device,
    label: &str,
    bindings: &[Binding],
) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = bindings.iter().map(Binding::layout_entry).collect();
    device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries })
}

/// A bind group on `layout` (built from `bindings`) with `resources` in the order of `bindings`.
pub(crate) fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    bindings: &[Binding],
    resources: Vec<wgpu::BindingResource<'_>>,
) -> wgpu::BindGroup {
    debug_assert_eq!(bindings.len(), resources.len(), "{label}: one resource per binding");
    let entries: Vec<wgpu::BindGroupEntry<'_>> = bindings
        .iter()
        .zip(resources)
        .map(|(b, resource)| wgpu::BindGroupEntry { binding: b.binding, resource })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
}

/// A pipeline layout of one bind group.
pub(crate) fn pipeline_layout(
    device: &wgpu::Device,
    label: &str,
    group: &wgpu::BindGroupLayout,
) -> wgpu::PipelineLayout {
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(group)],
        immediate_size: 0,
    })
}

/// A compute pipeline of `module`'s entry point `entry` (labelled by it) on `layout`, with the
/// module's overrides at their defaults.
pub(crate) fn compute_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// The vertex attributes of a cached mesh ([`GpuVertex`]): position, normal, outline normal,
/// texture coordinates, colour, material.
pub(crate) const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 6] = wgpu::vertex_attr_array![
    0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x2, 4 => Float32x4, 5 => Uint32
];

/// Only the position of a cached mesh's vertices (what the shadow passes read).
pub(crate) const POSITION_ATTRIBUTE: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x3];

/// The vertex buffer layout of a cached mesh with `attributes`.
pub(crate) fn vertex_layout(attributes: &[wgpu::VertexAttribute]) -> wgpu::VertexBufferLayout<'_> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<GpuVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes,
    }
}

/// Triangle lists, counter-clockwise front faces (as every mesh), culling `cull_mode`.
pub(crate) fn triangles(cull_mode: Option<wgpu::Face>) -> wgpu::PrimitiveState {
    wgpu::PrimitiveState {
        topology: wgpu::PrimitiveTopology::TriangleList,
        front_face: wgpu::FrontFace::Ccw,
        cull_mode,
        ..Default::default()
    }
}

/// A depth test keeping the nearest (`Less`) or, with `compare`, another, writing depth.
pub(crate) fn depth_test(
    format: wgpu::TextureFormat,
    compare: wgpu::CompareFunction,
) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(true),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// The stages of a render pipeline: a vertex entry point reading `buffers`, and, unless it draws
/// depth only, a fragment entry point writing `targets`.
pub(crate) struct Stages<'a> {
    pub(crate) module: &'a wgpu::ShaderModule,
    pub(crate) vertex: &'a str,
    pub(crate) buffers: &'a [wgpu::VertexBufferLayout<'a>],
    pub(crate) fragment: Option<(&'a str, &'a [Option<wgpu::ColorTargetState>])>,
    /// Pipeline-overridable constants of the fragment stage.
    pub(crate) constants: &'a [(&'a str, f64)],
}

/// A render pipeline of `stages` on a pipeline layout of the one bind group layout `group`.
pub(crate) fn render_pipeline(
    device: &wgpu::Device,
    label: &str,
    group: &wgpu::BindGroupLayout,
    stages: &Stages<'_>,
    primitive: wgpu::PrimitiveState,
    depth_stencil: Option<wgpu::DepthStencilState>,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout(device, label, group)),
        vertex: wgpu::VertexState {
            module: stages.module,
            entry_point: Some(stages.vertex),
            compilation_options: Default::default(),
            buffers: stages.buffers,
        },
        primitive,
        depth_stencil,
        multisample: Default::default(),
        fragment: stages.fragment.map(|(entry, targets)| wgpu::FragmentState {
            module: stages.module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: stages.constants,
                ..Default::default()
            },
            targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A view of a new 2-D texture of `size` pixels (one mip level, one sample): the targets the
/// passes draw into and read.
pub(crate) fn texture_view(
    device: &wgpu::Device,
    label: &str,
    size: [u32; 2],
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::TextureView {
    device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

/// One colour target of `format`, no blending.
pub(crate) fn color_target(format: wgpu::TextureFormat) -> Option<wgpu::ColorTargetState> {
    Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })
}

/// A colour attachment cleared to zero bits and stored.
pub(crate) fn cleared_color(view: &wgpu::TextureView) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
            store: wgpu::StoreOp::Store,
        },
    })
}

/// A depth attachment cleared to 1 (the far plane; in a shadow map, "no caster").
pub(crate) fn cleared_depth(
    view: &wgpu::TextureView,
    store: wgpu::StoreOp,
) -> Option<wgpu::RenderPassDepthStencilAttachment<'_>> {
    Some(wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store }),
        stencil_ops: None,
    })
}

/// One draw of a cached mesh: the frame's object, its index count and the instance index the
/// shader reads (the object's index, or an index into a pass's draw list).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Draw {
    pub(crate) object: usize,
    pub(crate) index_count: u32,
    pub(crate) instance: u32,
}

/// Draws each of `draws` with its object's cached mesh (objects without one draw nothing).
pub(crate) fn draw_meshes(
    pass: &mut wgpu::RenderPass<'_>,
    meshes: &MeshCache,
    frame: &Frame,
    draws: &[Draw],
) {
    for d in draws {
        let Some(mesh) = meshes.get(&frame.objects[d.object].mesh) else { continue };
        pass.set_vertex_buffer(0, mesh.vertices.slice(..));
        pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..d.index_count, 0, d.instance..d.instance + 1);
    }
}
