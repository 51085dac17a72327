//! The fixed cost per pixel of the kinds of pass hadou-gpu records, on the adapter at hand, timed
//! with GPU timestamps (median of 20 after a warm-up): render passes over the raster pass's
//! targets (two `Rgba32Uint` and a depth buffer) that clear them or load them, with or without a
//! full-screen triangle writing the colour targets (the fragment path the raster and
//! plane-shadow passes take); a compute pass writing the same 32 bytes a pixel into a storage
//! buffer (the wave pass's path), and a compute pass writing an `Rgba32Uint` storage texture (the
//! edge pass's path). On GPUs whose graphics units are a small part of the chip, the render rows
//! cost many times the compute rows; elsewhere they are close.
//!
//! `cargo run --release -p hadou-gpu --example fill_cost [SIZE ...]` (default 1024 2048)

use std::process::ExitCode;

const SHADER: &str = r#"
struct Out {
    @location(0) a: vec4<u32>,
    @location(1) b: vec4<u32>,
}

@vertex
fn vs(@builtin(vertex_index) k: u32) -> @builtin(position) vec4<f32> {
    let x = f32((k << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(k & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs2(@builtin(position) p: vec4<f32>) -> Out {
    let q = vec2<u32>(p.xy);
    return Out(vec4<u32>(q, 1u, 2u), vec4<u32>(3u, q, 4u));
}

@fragment
fn fs1(@builtin(position) p: vec4<f32>) -> @location(0) vec4<u32> {
    return vec4<u32>(vec2<u32>(p.xy), 1u, 2u);
}

struct Size { w: u32, h: u32 }
@group(0) @binding(0) var<uniform> size: Size;
@group(0) @binding(1) var<storage, read_write> words: array<vec4<u32>>;
@group(0) @binding(2) var texels: texture_storage_2d<rgba32uint, write>;

@compute @workgroup_size(8, 8, 1)
fn cs_buffer(@builtin(global_invocation_id) g: vec3<u32>) {
    if (g.x < size.w && g.y < size.h) {
        let i = 2u * (g.y * size.w + g.x);
        words[i] = vec4<u32>(g.xy, 1u, 2u);
        words[i + 1u] = vec4<u32>(3u, g.xy, 4u);
    }
}

@compute @workgroup_size(8, 8, 1)
fn cs_texture(@builtin(global_invocation_id) g: vec3<u32>) {
    if (g.x < size.w && g.y < size.h) {
        textureStore(texels, vec2<u32>(g.xy), vec4<u32>(g.xy, 1u, 2u));
    }
}
"#;

struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    name: String,
}

fn open() -> Result<Gpu, String> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let options = wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    };
    let adapter = pollster::block_on(instance.request_adapter(&options)).map_err(|e| e.to_string())?;
    if !adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
        return Err(format!("{} has no timestamp queries", adapter.get_info().name));
    }
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("fill_cost"),
        required_features: wgpu::Features::TIMESTAMP_QUERY,
        required_limits: adapter.limits(),
        ..Default::default()
    }))
    .map_err(|e| e.to_string())?;
    Ok(Gpu { device, queue, name: adapter.get_info().name })
}

/// What one case's pass does.
#[derive(Clone, Copy)]
enum Case {
    /// A render pass over `colour` `Rgba32Uint` targets (cleared, or loaded as they are) and a
    /// cleared depth buffer, with a full-screen triangle when `draw`.
    Render { colour: usize, clear: bool, draw: bool },
    /// A compute pass writing 32 bytes a pixel into a storage buffer.
    ComputeBuffer,
    /// A compute pass writing an `Rgba32Uint` storage texture.
    ComputeTexture,
}

/// The cases, with their labels and the bytes a pixel each writes.
const CASES: [(Case, &str, u64); 8] = [
    (
        Case::Render { colour: 2, clear: true, draw: false },
        "render pass, clears only (2 × Rgba32Uint + depth)",
        36,
    ),
    (Case::Render { colour: 0, clear: true, draw: false }, "render pass, depth clear only", 4),
    (Case::Render { colour: 2, clear: false, draw: false }, "render pass, colour loaded, depth cleared", 4),
    (
        Case::Render { colour: 2, clear: true, draw: true },
        "full-screen triangle → 2 × Rgba32Uint, cleared",
        36,
    ),
    (
        Case::Render { colour: 2, clear: false, draw: true },
        "full-screen triangle → 2 × Rgba32Uint, loaded",
        36,
    ),
    (
        Case::Render { colour: 1, clear: false, draw: true },
        "full-screen triangle → 1 × Rgba32Uint, loaded",
        20,
    ),
    (Case::ComputeBuffer, "compute → storage buffer, 32 B a pixel", 32),
    (Case::ComputeTexture, "compute → Rgba32Uint storage texture", 16),
];

fn main() -> ExitCode {
    let mut sizes = Vec::new();
    for a in std::env::args().skip(1) {
        match a.parse::<u32>() {
            Ok(n) if (8..=4096).contains(&n) => sizes.push(n),
            _ => {
                eprintln!("fill_cost: `{a}` is not a size in 8..=4096\nusage: fill_cost [SIZE ...]");
                return ExitCode::from(2);
            }
        }
    }
    if sizes.is_empty() {
        sizes = vec![1024, 2048];
    }
    let gpu = match open() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("fill_cost: no GPU with timestamp queries: {e}");
            return ExitCode::FAILURE;
        }
    };
    println!("adapter: {}", gpu.name);
    println!("{:<54} {:>6} {:>10} {:>10} {:>9}", "pass", "size", "µs", "Gpx/s", "GB/s");
    for size in sizes {
        for (case, label, bytes) in CASES {
            let us = time_case(&gpu, case, size);
            let px = size as f64 * size as f64;
            println!(
                "{label:<54} {:>6} {us:>10.1} {:>10.2} {:>9.0}",
                format!("{size}²"),
                px / us / 1e3,
                px * bytes as f64 / us / 1e3
            );
        }
    }
    ExitCode::SUCCESS
}

/// Median microseconds of `case`'s pass at `size`², from GPU timestamps.
fn time_case(gpu: &Gpu, case: Case, size: u32) -> f64 {
    let d = &gpu.device;
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("fill_cost"),
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let texture = |format, usage| {
        d.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
        .create_view(&Default::default())
    };
    let attach = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
    let targets =
        [texture(wgpu::TextureFormat::Rgba32Uint, attach), texture(wgpu::TextureFormat::Rgba32Uint, attach)];
    let depth = texture(wgpu::TextureFormat::Depth32Float, wgpu::TextureUsages::RENDER_ATTACHMENT);
    let storage_texture = texture(wgpu::TextureFormat::Rgba32Uint, wgpu::TextureUsages::STORAGE_BINDING);
    let words = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: size as u64 * size as u64 * 32,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let uniform = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 8,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    gpu.queue.write_buffer(&uniform, 0, &[size.to_ne_bytes(), size.to_ne_bytes()].concat());
    let color =
        |format| Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL });
    let color_targets = [color(wgpu::TextureFormat::Rgba32Uint), color(wgpu::TextureFormat::Rgba32Uint)];
    let render = |targets: usize| {
        d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("fill"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(if targets == 2 { "fs2" } else { "fs1" }),
                compilation_options: Default::default(),
                targets: &color_targets[..targets],
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    let pipelines = [render(1), render(2)];
    let compute = |entry| {
        d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: None,
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    };
    let (cs_buffer, cs_texture) = (compute("cs_buffer"), compute("cs_texture"));
    let buffer_group = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &cs_buffer.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: words.as_entire_binding() },
        ],
    });
    let texture_group = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &cs_texture.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::TextureView(&storage_texture),
            },
        ],
    });
    let set = d.create_query_set(&wgpu::QuerySetDescriptor {
        label: None,
        ty: wgpu::QueryType::Timestamp,
        count: 2,
    });
    let resolve = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 16,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let read = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 16,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let period_ns = gpu.queue.get_timestamp_period() as f64;
    let mut samples = Vec::new();
    for i in 0..21 {
        let mut enc = d.create_command_encoder(&Default::default());
        let groups = size.div_ceil(8);
        match case {
            Case::Render { colour, clear, draw } => {
                let load =
                    if clear { wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT) } else { wgpu::LoadOp::Load };
                let attachments: Vec<_> = targets[..colour]
                    .iter()
                    .map(|view| {
                        Some(wgpu::RenderPassColorAttachment {
                            view,
                            depth_slice: None,
                            resolve_target: None,
                            ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
                        })
                    })
                    .collect();
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: None,
                    color_attachments: &attachments,
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &depth,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: Some(wgpu::RenderPassTimestampWrites {
                        query_set: &set,
                        beginning_of_pass_write_index: Some(0),
                        end_of_pass_write_index: Some(1),
                    }),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                if draw && colour > 0 {
                    pass.set_pipeline(&pipelines[colour - 1]);
                    pass.draw(0..3, 0..1);
                }
            }
            Case::ComputeBuffer | Case::ComputeTexture => {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: None,
                    timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
                        query_set: &set,
                        beginning_of_pass_write_index: Some(0),
                        end_of_pass_write_index: Some(1),
                    }),
                });
                if matches!(case, Case::ComputeBuffer) {
                    pass.set_pipeline(&cs_buffer);
                    pass.set_bind_group(0, &buffer_group, &[]);
                } else {
                    pass.set_pipeline(&cs_texture);
                    pass.set_bind_group(0, &texture_group, &[]);
                }
                pass.dispatch_workgroups(groups, groups, 1);
            }
        }
        enc.resolve_query_set(&set, 0..2, &resolve, 0);
        enc.copy_buffer_to_buffer(&resolve, 0, &read, 0, 16);
        gpu.queue.submit([enc.finish()]);
        read.slice(..).map_async(wgpu::MapMode::Read, |_| {});
        let _ = d.poll(wgpu::PollType::wait_indefinitely());
        let t: Vec<u64> = read
            .slice(..)
            .get_mapped_range()
            .chunks_exact(8)
            .map(|c| u64::from_ne_bytes(c.try_into().unwrap_or_default()))
            .collect();
        read.unmap();
        if i > 0 {
            samples.push(t[1].saturating_sub(t[0]) as f64 * period_ns / 1e3);
        }
    }
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}
