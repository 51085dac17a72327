//! The harness of the WGSL twin tests (`twins.rs`, `curve_twins.rs`): a compute kernel that
//! evaluates one `case_energy` per test case on the GPU, and the deterministic generator of the
//! random cases.

use crate::device::GpuContext;
use crate::passes::setup::compile_module;
use crate::shaders;
use hadou_scene::RenderError;

/// The twin kernel's source: `parts` (the WGSL under test), then `case` (which defines the WGSL
/// `struct Case` with `origin`, `dir` and `span = [t0, t1, open_end, …]` fields, and
/// `fn case_energy(c: Case, ray: Ray, t0: f32, t1: f32) -> f32`), then `twin_main`, which
/// evaluates `case_energy` for every case of binding 0 into binding 1 (`t1 = T_OPEN` for an open
/// span).
pub(crate) fn source(parts: &[&str], case: &str) -> String {
    let mut all = parts.to_vec();
    all.extend([case, MAIN]);
    shaders::compose(&all)
}

const MAIN: &str = r#"
@group(0) @binding(0) var<storage, read> cases: array<Case>;
@group(0) @binding(1) var<storage, read_write> results: array<f32>;

@compute @workgroup_size(64, 1, 1)
fn twin_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= arrayLength(&cases)) {
        return;
    }
    let c = cases[id.x];
    var t1 = c.span.y;
    if (c.span.z != 0.0) {
        t1 = T_OPEN;
    }
    results[id.x] = case_energy(c, Ray(c.origin.xyz, c.dir.xyz), c.span.x, t1);
}
"#;

/// Runs a twin-test compute kernel: `twin_main` over `count` cases in workgroups of 64, with each
/// `(binding, bytes)` of `inputs` as a read-only storage buffer in group 0 and one `f32` result per
/// case read back from binding 1. Shared by the energy and curve twin tests.
pub(crate) fn run(
    ctx: &GpuContext,
    label: &str,
    source: &str,
    inputs: &[(u32, &[u8])],
    count: usize,
) -> Result<Vec<f32>, RenderError> {
    use wgpu::util::DeviceExt;
    let module = compile_module(ctx, label, source)?;
    let bytes = (count * 4) as u64;
    let (pipeline, buffers, output, staging) = ctx.scoped(&format!("setting up {label}"), || {
        let d = &ctx.device;
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: None,
            module: &module,
            entry_point: Some("twin_main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let buffers: Vec<(u32, wgpu::Buffer)> = inputs
            .iter()
            .map(|&(binding, contents)| {
                let usage = wgpu::BufferUsages::STORAGE;
                (
                    binding,
                    d.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents, usage }),
                )
            })
            .collect();
        let buffer = |usage| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size: bytes,
                usage,
                mapped_at_creation: false,
            })
        };
        let output = buffer(wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
        let staging = buffer(wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        (pipeline, buffers, output, staging)
    })?;
    let submission =
        ctx.scoped(&format!("running {label}"), || {
            let d = &ctx.device;
            let mut entries = vec![wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() }];
            entries.extend(buffers.iter().map(|(binding, b)| wgpu::BindGroupEntry {
                binding: *binding,
                resource: b.as_entire_binding(),
            }));
            let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            });
            let mut enc = d.create_command_encoder(&Default::default());
            {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &bg, &[]);
                pass.dispatch_workgroups((count as u32).div_ceil(64), 1, 1);
            }
            enc.copy_buffer_to_buffer(&output, 0, &staging, 0, bytes);
            ctx.queue.submit([enc.finish()])
        })?;
    ctx.read_buffer(&staging, bytes, submission, |raw| {
        raw.chunks_exact(4).map(|c| f32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect()
    })
}

/// The generator of the random part of the cases (splitmix64).
pub(crate) use hadou_math::rng::Rng;
