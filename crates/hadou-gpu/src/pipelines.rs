//! Shader modules, bind group layouts and the pipelines: raster (and outline hulls), plane
//! shadows, shadow maps, wave.

use crate::device::GpuContext;
use crate::layout::{self, GpuVertex};
use crate::shaders;
use hadou_scene::RenderError;
use std::collections::HashMap;

/// The raster pass's one colour target: the linear scene colour and the Euclidean eye distance of
/// the visible surface, as the bit patterns of four `f32`s (`bitcast` in raster.wgsl and
/// wave.wgsl). An integer format because `Rgba32Uint` is colour-renderable on every adapter wgpu
/// offers (GLES 3.0 and WebGL2 included), while `Rgba32Float` and `R32Float` targets need
/// optional extensions on GL; the bits pass through unchanged, so the wave pass reads exactly the
/// `f32`s the fragment shader wrote. A cleared texel is all zero bits, i.e. distance 0: nothing
/// drawn (a drawn surface is at least `near` > 0 away).
pub(crate) const SCENE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;
/// Depth buffer of the raster pass (renderable on every adapter).
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Target of the plane-shadow pass (shadow_raster.wgsl): `j + 1` of the kept plane cast, 0 = none.
/// Colour-renderable and readable on every adapter, GLES 3.0 included.
pub(crate) const PLANE_SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// The shadow maps: a depth array texture rendered by the map pass and read (as unfilterable
/// float) by the wave pass.
pub(crate) const MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Target of the `[area_light]`'s map pass (soft_map.wgsl): the f32 bits of the view depth.
pub(crate) const SPOT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// Workgroup edge of the wave pass (keep in sync with `@workgroup_size` in wave.wgsl).
pub(crate) const WAVE_WORKGROUP: u32 = 8;

/// The compiled pipelines of the backend.
pub(crate) struct Pipelines {
    pub(crate) raster: wgpu::RenderPipeline,
    /// The outline hulls: `vs_hull`, front faces culled (000 §2.3).
    pub(crate) hull: wgpu::RenderPipeline,
    pub(crate) raster_layout: wgpu::BindGroupLayout,
    /// The wave module (the uber-shader source; variants set its `USE_*` overrides).
    wave_module: wgpu::ShaderModule,
    wave_pl: wgpu::PipelineLayout,
    /// The wave pipelines built so far, one per variant (see [`Pipelines::wave`]).
    wave_variants: HashMap<WaveVariant, wgpu::ComputePipeline>,
    /// Whether [`Pipelines::wave`] specialises; `false` gives every frame the uber-shader.
    pub(crate) specialise: bool,
    pub(crate) wave_layout: wgpu::BindGroupLayout,
    /// Plane shadows (`vs_plane`, `fs_plane`), per tile after the raster pass.
    pub(crate) plane_shadow: wgpu::RenderPipeline,
    pub(crate) plane_shadow_layout: wgpu::BindGroupLayout,
    /// Shadow maps (`vs_map`, depth only), once per frame.
    pub(crate) shadow_map: wgpu::RenderPipeline,
    pub(crate) shadow_map_layout: wgpu::BindGroupLayout,
    /// The `[area_light]`'s maps (soft_map.wgsl), once per frame.
    pub(crate) spot_map: wgpu::RenderPipeline,
    pub(crate) spot_map_layout: wgpu::BindGroupLayout,
    /// The soft-shadow compute passes (soft.wgsl), one layout for all.
    pub(crate) soft: SoftPipelines,
    pub(crate) soft_layout: wgpu::BindGroupLayout,
}

/// The compute pipelines of soft.wgsl.
pub(crate) struct SoftPipelines {
    pub(crate) classify: wgpu::ComputePipeline,
    pub(crate) columns: wgpu::ComputePipeline,
    pub(crate) exact: wgpu::ComputePipeline,
    pub(crate) grid: wgpu::ComputePipeline,
    pub(crate) interp: wgpu::ComputePipeline,
    pub(crate) gather: wgpu::ComputePipeline,
}

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

fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn storage_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    // Both G-buffer targets (raster.wgsl) and the plane-shadow target are read by the wave pass.
    uint_texture_entry(binding, wgpu::ShaderStages::COMPUTE)
}

fn uint_texture_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Uint,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

impl Pipelines {
    /// Compiles both modules and builds the pipelines.
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        let raster_module = compile_module(ctx, "raster", &shaders::compose(shaders::RASTER_PARTS))?;
        let wave_module = compile_module(ctx, "wave", &shaders::compose(shaders::WAVE_PARTS))?;
        let shadow_module = compile_module(ctx, "shadow", &shaders::compose(shaders::SHADOW_PARTS))?;
        let spot_module = compile_module(ctx, "soft map", &shaders::compose(shaders::SOFT_MAP_PARTS))?;
        let soft_module = compile_module(ctx, "soft", &shaders::compose(shaders::SOFT_PARTS))?;
        ctx.scoped("building pipelines", || {
            let d = &ctx.device;
            let vs_fs = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
            let raster_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("raster"),
                entries: &[
                    uniform_entry(0, vs_fs),
                    storage_entry(1, vs_fs, true),
                    storage_entry(2, vs_fs, true),
                ],
            });
            let cs = wgpu::ShaderStages::COMPUTE;
            let wave_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("wave"),
                entries: &[
                    uniform_entry(0, cs),
                    storage_entry(1, cs, true),
                    texture_entry(2),
                    texture_entry(3),
                    storage_entry(4, cs, false),
                    // Curve buffers; keep in sync with curve.wgsl and layout::CurveBuffers.
                    storage_entry(5, cs, true),
                    storage_entry(6, cs, true),
                    storage_entry(7, cs, true),
                    // Materials, lights, shading data; keep in sync with shading.wgsl.
                    storage_entry(8, cs, true),
                    storage_entry(9, cs, true),
                    storage_entry(10, cs, true),
                    // Hard shadows; keep in sync with shadow_lookup.wgsl.
                    texture_entry(11),
                    wgpu::BindGroupLayoutEntry {
                        binding: 12,
                        visibility: cs,
                        ty: wgpu::BindingType::Texture {
                            // A depth texture read with textureLoad as unfilterable float.
                            sample_type: wgpu::TextureSampleType::Float { filterable: false },
                            view_dimension: wgpu::TextureViewDimension::D2Array,
                            multisampled: false,
                        },
                        count: None,
                    },
                ],
            });
            // Keep in sync with the bindings of shadow_raster.wgsl.
            let fs = wgpu::ShaderStages::FRAGMENT;
            let plane_shadow_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("plane shadows"),
                entries: &[
                    uniform_entry(0, vs_fs),
                    storage_entry(1, vs_fs, true),
                    storage_entry(2, vs_fs, true),
                    storage_entry(3, vs_fs, true),
                    storage_entry(4, vs_fs, true),
                    uint_texture_entry(5, fs),
                    uint_texture_entry(6, fs),
                ],
            });
            let vs = wgpu::ShaderStages::VERTEX;
            let shadow_map_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("shadow maps"),
                entries: &[
                    storage_entry(1, vs, true),
                    storage_entry(3, vs, true),
                    storage_entry(4, vs, true),
                ],
            });
            let raster_pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("raster"),
                bind_group_layouts: &[Some(&raster_layout)],
                immediate_size: 0,
            });
            let wave_pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("wave"),
                bind_group_layouts: &[Some(&wave_layout)],
                immediate_size: 0,
            });
            let plane_shadow_pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("plane shadows"),
                bind_group_layouts: &[Some(&plane_shadow_layout)],
                immediate_size: 0,
            });
            let shadow_map_pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("shadow maps"),
                bind_group_layouts: &[Some(&shadow_map_layout)],
                immediate_size: 0,
            });
            let attributes = wgpu::vertex_attr_array![
                0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x2, 4 => Float32x4, 5 => Uint32
            ];
            let targets = [
                Some(wgpu::ColorTargetState {
                    format: SCENE_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                }),
                Some(wgpu::ColorTargetState {
                    format: SCENE_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                }),
            ];
            let raster_pipeline = |label: &str, vs: &str, cull_mode: Option<wgpu::Face>| {
                d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(label),
                    layout: Some(&raster_pl),
                    vertex: wgpu::VertexState {
                        module: &raster_module,
                        entry_point: Some(vs),
                        compilation_options: Default::default(),
                        buffers: &[wgpu::VertexBufferLayout {
                            array_stride: std::mem::size_of::<GpuVertex>() as u64,
                            step_mode: wgpu::VertexStepMode::Vertex,
                            attributes: &attributes,
                        }],
                    },
                    primitive: wgpu::PrimitiveState {
                        topology: wgpu::PrimitiveTopology::TriangleList,
                        front_face: wgpu::FrontFace::Ccw,
                        cull_mode,
                        ..Default::default()
                    },
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: DEPTH_FORMAT,
                        depth_write_enabled: Some(true),
                        depth_compare: Some(wgpu::CompareFunction::Less),
                        stencil: Default::default(),
                        bias: Default::default(),
                    }),
                    multisample: Default::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &raster_module,
                        entry_point: Some("fs_main"),
                        compilation_options: Default::default(),
                        targets: &targets,
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            };
            // No culling: open meshes (planes) are visible from both sides, as on the CPU.
            let raster = raster_pipeline("raster", "vs_main", None);
            // Hulls show only their back faces (counter-clockwise front faces, as every mesh).
            let hull = raster_pipeline("outline hull", "vs_hull", Some(wgpu::Face::Front));
            // The shadow passes read only the positions of the mesh vertices.
            let position = wgpu::vertex_attr_array![0 => Float32x3];
            let positions = [wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<GpuVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &position,
            }];
            let depth_less = |format| wgpu::DepthStencilState {
                format,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            };
            // Double-sided, as the CPU draws casters.
            let primitive = wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: None,
                ..Default::default()
            };
            let plane_shadow = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("plane shadows"),
                layout: Some(&plane_shadow_pl),
                vertex: wgpu::VertexState {
                    module: &shadow_module,
                    entry_point: Some("vs_plane"),
                    compilation_options: Default::default(),
                    buffers: &positions,
                },
                primitive,
                depth_stencil: Some(depth_less(DEPTH_FORMAT)),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &shadow_module,
                    entry_point: Some("fs_plane"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: PLANE_SHADOW_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            });
            let shadow_map = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("shadow maps"),
                layout: Some(&shadow_map_pl),
                vertex: wgpu::VertexState {
                    module: &shadow_module,
                    entry_point: Some("vs_map"),
                    compilation_options: Default::default(),
                    buffers: &positions,
                },
                primitive,
                depth_stencil: Some(depth_less(MAP_FORMAT)),
                multisample: Default::default(),
                fragment: None,
                multiview_mask: None,
                cache: None,
            });
            // Keep in sync with the bindings of soft_map.wgsl and soft.wgsl.
            let spot_map_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("soft maps"),
                entries: &[uniform_entry(0, vs), storage_entry(1, vs, true)],
            });
            let soft_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("soft"),
                entries: &[
                    uniform_entry(0, cs),
                    uniform_entry(1, cs),
                    texture_entry(2),
                    texture_entry(3),
                    texture_entry(4),
                    texture_entry(5),
                    storage_entry(6, cs, false),
                    storage_entry(7, cs, false),
                    storage_entry(8, cs, false),
                    storage_entry(9, cs, false),
                    storage_entry(10, cs, false),
                ],
            });
            let spot_map_pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("soft maps"),
                bind_group_layouts: &[Some(&spot_map_layout)],
                immediate_size: 0,
            });
            let soft_pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("soft"),
                bind_group_layouts: &[Some(&soft_layout)],
                immediate_size: 0,
            });
            let spot_map = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("soft maps"),
                layout: Some(&spot_map_pl),
                vertex: wgpu::VertexState {
                    module: &spot_module,
                    entry_point: Some("vs_spot"),
                    compilation_options: Default::default(),
                    buffers: &positions,
                },
                primitive,
                // Depth near/z: the nearest surface has the greatest.
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: MAP_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Greater),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &spot_module,
                    entry_point: Some("fs_spot"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: SPOT_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            });
            let soft_pipeline = |entry: &str| {
                d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(&soft_pl),
                    module: &soft_module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                })
            };
            let soft = SoftPipelines {
                classify: soft_pipeline("cs_classify"),
                columns: soft_pipeline("cs_columns"),
                exact: soft_pipeline("cs_exact"),
                grid: soft_pipeline("cs_grid"),
                interp: soft_pipeline("cs_interp"),
                gather: soft_pipeline("cs_gather"),
            };
            Self {
                spot_map,
                spot_map_layout,
                soft,
                soft_layout,
                raster,
                hull,
                raster_layout,
                wave_module,
                wave_pl,
                wave_variants: HashMap::new(),
                specialise: true,
                wave_layout,
                plane_shadow,
                plane_shadow_layout,
                shadow_map,
                shadow_map_layout,
            }
        })
    }
}

/// Which parts of the wave pass a frame needs: one bit per pipeline-overridable `USE_*` constant of
/// the wave module (wave.wgsl, energy.wgsl, curve.wgsl, shading.wgsl, shadow_lookup.wgsl). A clear
/// bit compiles its part out (the constant is `false`, so the branch is dead and the driver drops
/// it); a set bit leaves the code exactly as the uber-shader's ([`WaveVariant::UBER`], every bit
/// set). [`WaveVariant::of`] sets a bit for everything the frame's data can reach, so a frame
/// renders identically with its variant and with the uber-shader.
///
/// Why: a software adapter such as llvmpipe runs a shader's branches under an execution mask,
/// both sides of every `if` and every `switch` case, whichever the pixels take; the uber-shader
/// made a one-sphere frame pay for every wave kind, the curve walker and the surface shading.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct WaveVariant(u32);

impl WaveVariant {
    /// The `USE_*` overrides, bit `i` of the variant is the `i`-th name.
    pub(crate) const NAMES: [&'static str; 26] = [
        // wave.wgsl
        "USE_SPHERE",
        "USE_CYLINDER",
        "USE_CAPSULE",
        "USE_BEAM",
        "USE_CURVE",
        "USE_SURFACES",
        "USE_AREA",
        "USE_TONE_FAITHFUL",
        "USE_TONE_FILMIC",
        // energy.wgsl
        "USE_FAITHFUL",
        "USE_INVERSE_SQUARE",
        // curve.wgsl
        "USE_CHORD",
        "USE_SIMPSON",
        "USE_HELIX",
        "USE_TRIG",
        "USE_BEZIER",
        "USE_BSPLINE",
        // shading.wgsl
        "USE_TOON",
        "USE_TEXTURES",
        "USE_WAVE_LIGHTS",
        "USE_LINE_POINT",
        "USE_LINE_SEGMENT",
        "USE_LINE_LINE",
        "USE_LINE_POLYLINE",
        // shadow_lookup.wgsl
        "USE_PLANE_SHADOWS",
        "USE_MAP_SHADOWS",
    ];
    /// Every part: the uber-shader, right for any frame.
    pub(crate) const UBER: WaveVariant = WaveVariant((1 << Self::NAMES.len()) - 1);

    /// The bit of override `name`.
    fn bit(name: &str) -> u32 {
        let i = Self::NAMES.iter().position(|n| *n == name).expect("a USE_* name");
        1 << i
    }

    /// Whether the override `name` is set.
    pub(crate) fn has(self, name: &str) -> bool {
        self.0 & Self::bit(name) != 0
    }

    /// The variant with nothing but the overrides in `names` set.
    pub(crate) fn from_names<'a>(names: impl IntoIterator<Item = &'a str>) -> Self {
        WaveVariant(names.into_iter().fold(0, |v, n| v | Self::bit(n)))
    }

    /// The variant a frame needs, from what the wave pass will read: the waves, the curves, the
    /// materials and lights (the lights shading.wgsl reads), whether anything is drawn, whether
    /// some wave glows, the shadow casts (plane, map), the `[area_light]` and the colour mapping.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn of(
        waves: &[layout::GpuWave],
        curves: &[layout::GpuCurve],
        materials: &[layout::GpuMaterial],
        lights: &[layout::GpuLight],
        any_glow: bool,
        surfaces: bool,
        shadows: (bool, bool),
        area: bool,
        tone_faithful: bool,
    ) -> Self {
        let mut on: Vec<&str> = Vec::new();
        for w in waves {
            on.push(match w.kind {
                layout::WAVE_SPHERE => "USE_SPHERE",
                layout::WAVE_CYLINDER => "USE_CYLINDER",
                layout::WAVE_CAPSULE => "USE_CAPSULE",
                layout::WAVE_BEAM => "USE_BEAM",
                _ => "USE_CURVE",
            });
            on.push(if w.falloff == layout::FALLOFF_FAITHFUL {
                "USE_FAITHFUL"
            } else {
                "USE_INVERSE_SQUARE"
            });
        }
        for c in curves {
            on.push(if c.integrator == layout::INTEGRATOR_SIMPSON { "USE_SIMPSON" } else { "USE_CHORD" });
            on.push(match c.shape {
                layout::SHAPE_HELIX => "USE_HELIX",
                layout::SHAPE_TRIG => "USE_TRIG",
                layout::SHAPE_BEZIER => "USE_BEZIER",
                _ => "USE_BSPLINE",
            });
        }
        if surfaces {
            on.push("USE_SURFACES");
            if materials.iter().any(|m| m.model == layout::MODEL_TOON) {
                on.push("USE_TOON");
            }
            if materials.iter().any(|m| m.base_texture.offset != 0 || m.feature_texture.offset != 0) {
                on.push("USE_TEXTURES");
            }
            let lit = !lights.is_empty() && (any_glow || materials.iter().any(|m| m.wave_blend > 0.0));
            if lit {
                on.push("USE_WAVE_LIGHTS");
                for l in lights {
                    on.push(match l.line_kind {
                        layout::LINE_POINT => "USE_LINE_POINT",
                        layout::LINE_SEGMENT => "USE_LINE_SEGMENT",
                        layout::LINE_LINE => "USE_LINE_LINE",
                        _ => "USE_LINE_POLYLINE",
                    });
                }
            }
            if shadows.0 {
                on.push("USE_PLANE_SHADOWS");
            }
            if shadows.1 {
                on.push("USE_MAP_SHADOWS");
            }
            if area {
                on.push("USE_AREA");
            }
        }
        on.push(if tone_faithful { "USE_TONE_FAITHFUL" } else { "USE_TONE_FILMIC" });
        Self::from_names(on)
    }

    /// The override values of this variant (`1.0` true, `0.0` false), for the pipeline.
    fn constants(self) -> Vec<(&'static str, f64)> {
        Self::NAMES.iter().map(|&n| (n, if self.has(n) { 1.0 } else { 0.0 })).collect()
    }
}

impl Pipelines {
    /// The wave pipeline of `variant` ([`WaveVariant::UBER`] when not specialising), built on first
    /// use and kept: the same variant always gets the same pipeline. Also the variant it is.
    pub(crate) fn wave(
        &mut self,
        ctx: &GpuContext,
        variant: WaveVariant,
    ) -> Result<(wgpu::ComputePipeline, WaveVariant), RenderError> {
        let variant = if self.specialise { variant } else { WaveVariant::UBER };
        if let Some(p) = self.wave_variants.get(&variant) {
            return Ok((p.clone(), variant));
        }
        let constants = variant.constants();
        let pipeline = ctx.scoped("building the wave pipeline", || {
            ctx.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("wave"),
                layout: Some(&self.wave_pl),
                module: &self.wave_module,
                entry_point: Some("cs_main"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                cache: None,
            })
        })?;
        self.wave_variants.insert(variant, pipeline.clone());
        Ok((pipeline, variant))
    }

    /// How many wave pipelines have been built.
    pub(crate) fn wave_variant_count(&self) -> usize {
        self.wave_variants.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bytemuck::Zeroable;

    /// `WaveVariant::NAMES` are exactly the wave module's overrides, each a `bool` defaulting to
    /// true (so the module alone is the uber-shader).
    #[test]
    fn variant_names_are_the_wave_modules_overrides() {
        let source = shaders::compose(shaders::WAVE_PARTS);
        let module = naga::front::wgsl::parse_str(&source).expect("the wave module parses");
        let mut overrides: Vec<&str> = Vec::new();
        for (_, o) in module.overrides.iter() {
            let name = o.name.as_deref().expect("named override");
            assert_eq!(module.types[o.ty].inner, naga::TypeInner::Scalar(naga::Scalar::BOOL), "{name}");
            let init = o.init.expect("a default");
            assert!(
                matches!(
                    module.global_expressions[init],
                    naga::Expression::Literal(naga::Literal::Bool(true))
                ),
                "{name} defaults to true"
            );
            overrides.push(name);
        }
        overrides.sort_unstable();
        let mut names = WaveVariant::NAMES.to_vec();
        names.sort_unstable();
        assert_eq!(overrides, names);
        assert!(WaveVariant::NAMES.iter().all(|n| WaveVariant::UBER.has(n)));
        assert!(WaveVariant::UBER.constants().iter().all(|&(_, v)| v == 1.0));
    }

    /// `WaveVariant::of` sets a part exactly when the frame's data can reach it.
    #[test]
    fn a_variant_has_exactly_what_the_frame_uses() {
        let wave = |kind, falloff| layout::GpuWave { kind, falloff, ..layout::GpuWave::zeroed() };
        let waves = [wave(layout::WAVE_SPHERE, layout::FALLOFF_FAITHFUL), wave(layout::WAVE_CURVE, 1)];
        let curve = layout::GpuCurve {
            integrator: layout::INTEGRATOR_SIMPSON,
            shape: layout::SHAPE_BEZIER,
            ..Zeroable::zeroed()
        };
        let mut toon = layout::GpuMaterial::zeroed();
        toon.model = layout::MODEL_TOON;
        toon.wave_blend = 0.5;
        let light = layout::GpuLight { line_kind: layout::LINE_POLYLINE, ..Zeroable::zeroed() };
        let names = |v: WaveVariant| -> Vec<&str> {
            WaveVariant::NAMES.iter().copied().filter(|n| v.has(n)).collect()
        };
        let v =
            WaveVariant::of(&waves, &[curve], &[toon], &[light], false, true, (false, true), false, false);
        assert_eq!(
            names(v),
            [
                "USE_SPHERE",
                "USE_CURVE",
                "USE_SURFACES",
                "USE_TONE_FILMIC",
                "USE_FAITHFUL",
                "USE_INVERSE_SQUARE",
                "USE_SIMPSON",
                "USE_BEZIER",
                "USE_TOON",
                "USE_WAVE_LIGHTS",
                "USE_LINE_POLYLINE",
                "USE_MAP_SHADOWS"
            ]
        );
        // Without surfaces nothing of the shading is compiled in; without blending or glow, no
        // wave lights.
        let v = WaveVariant::of(&waves[..1], &[], &[toon], &[light], true, false, (true, true), true, true);
        assert_eq!(names(v), ["USE_SPHERE", "USE_TONE_FAITHFUL", "USE_FAITHFUL"]);
        toon.wave_blend = 0.0;
        let v = WaveVariant::of(&[], &[], &[toon], &[light], false, true, (true, false), true, true);
        assert_eq!(
            names(v),
            ["USE_SURFACES", "USE_AREA", "USE_TONE_FAITHFUL", "USE_TOON", "USE_PLANE_SHADOWS"]
        );
    }
}
