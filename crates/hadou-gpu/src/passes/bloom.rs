//! The glare pass (`shaders/bloom.wgsl`): `hadou_math::bloom`'s chain over a band of rows, on
//! whole-image planes of `vec4<f32>` texels in storage buffers (so it needs no float storage
//! textures, which OpenGL ES may not offer): the soft threshold over the band and its halo, the
//! 13-tap downsamples and tent upsamples of [`Plan`]'s rows down to level 1, the horizontal streak
//! over level 1's rows (from the prefiltered row pairs), the glare `G` at level 1, and the
//! bilinear tap of `G`, the composite and the frame's colour mapping into the band's colour. One
//! dispatch per step, each with its own small uniform buffer and bind group, all in one compute
//! pass (timed as `"bloom"`).

use super::setup::{self, Binding, Kind};
use crate::device::GpuContext;
use crate::layout::{BloomUniforms, TONE_FAITHFUL, TONE_FILMIC};
use crate::shaders;
use hadou_math::bloom::{bilinear_rows, half, levels, weights, BloomParams, Plan};
use hadou_scene::{RenderError, ToneMode};
use std::ops::Range;
use wgpu::util::DeviceExt;

const CS: wgpu::ShaderStages = wgpu::ShaderStages::COMPUTE;

/// The bindings of bloom.wgsl.
pub(crate) const BINDINGS: [Binding; 5] = [
    Binding::new(0, "u", Kind::Uniform, CS),
    Binding::new(1, "a_buf", Kind::Storage, CS),
    Binding::new(2, "b_buf", Kind::Storage, CS),
    Binding::new(3, "c_buf", Kind::Storage, CS),
    Binding::new(4, "o_buf", Kind::StorageRw, CS),
];

/// Bytes per texel of every plane.
pub(crate) const TEXEL_BYTES: u64 = 16;

/// The glare pipelines and their bind group layout.
pub(crate) struct BloomPass {
    layout: wgpu::BindGroupLayout,
    prefilter: wgpu::ComputePipeline,
    down: wgpu::ComputePipeline,
    up: wgpu::ComputePipeline,
    down_h: wgpu::ComputePipeline,
    up_h: wgpu::ComputePipeline,
    pair: wgpu::ComputePipeline,
    glare: wgpu::ComputePipeline,
    composite: wgpu::ComputePipeline,
}

/// A plane on the GPU: its buffer and `[level width, level height, first row, rows]`.
struct GpuPlane {
    buffer: wgpu::Buffer,
    desc: [u32; 4],
}

/// What one frame's glare needs: the band's linear colour (`source` rows) in, the mapped colour
/// of the band out.
pub(crate) struct BloomInputs<'a> {
    pub(crate) params: &'a BloomParams,
    pub(crate) tone: ToneMode,
    pub(crate) width: u32,
    pub(crate) height: u32,
    /// The linear colour of the rows `source`, `vec4<f32>` per pixel, row-major.
    pub(crate) linear: &'a wgpu::Buffer,
    pub(crate) source: Range<usize>,
    pub(crate) band: Range<usize>,
}

impl BloomPass {
    /// Compiles bloom.wgsl and builds its pipelines.
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        let module = setup::compile_module(ctx, "bloom", &shaders::compose(shaders::BLOOM_PARTS))?;
        ctx.scoped("building the bloom pipelines", || {
            let d = &ctx.device;
            let layout = setup::bind_group_layout(d, "bloom", &BINDINGS);
            let pl = setup::pipeline_layout(d, "bloom", &layout);
            let pipeline = |entry: &str| setup::compute_pipeline(d, &pl, &module, entry);
            Self {
                prefilter: pipeline("cs_prefilter"),
                down: pipeline("cs_down"),
                up: pipeline("cs_up"),
                down_h: pipeline("cs_down_h"),
                up_h: pipeline("cs_up_h"),
                pair: pipeline("cs_pair"),
                glare: pipeline("cs_glare"),
                composite: pipeline("cs_composite"),
                layout,
            }
        })
    }

    /// The bytes of the largest plane the glare of the band `band` allocates (the source rows at
    /// full width), to check against the device's storage-binding limit.
    pub(crate) fn largest_plane(params: &BloomParams, width: u32, height: u32, band: Range<usize>) -> u64 {
        let src = hadou_math::bloom::source_rows(params, width as usize, height as usize, band);
        src.len() as u64 * width as u64 * TEXEL_BYTES
    }

    /// Records the glare of `inputs` into `encoder`, every step a dispatch of one compute pass
    /// (named `"bloom"` where `timestamps` asks for its time), and returns the buffer it leaves the
    /// band's mapped colour in (`vec4<f32>` per pixel, alpha 1, row-major, `band.len()` rows).
    pub(crate) fn encode<'p>(
        &'p self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &BloomInputs<'_>,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) -> wgpu::Buffer {
        let p = inputs.params;
        let (w, h) = (inputs.width as usize, inputs.height as usize);
        let n = levels(p.radius * h as f32);
        let plan = Plan::new(w, h, n, inputs.band.clone());
        let ns = levels(p.streak_length * h as f32);
        let tone = match inputs.tone {
            ToneMode::Faithful => TONE_FAITHFUL,
            ToneMode::Filmic => TONE_FILMIC,
        };
        let (kb, ks) = weights(p, h);
        let params = [p.threshold, p.soft_knee, kb, ks];
        let plane = |label: &str, width: usize, height: usize, rows: &Range<usize>| {
            let size = (width * rows.len()) as u64 * TEXEL_BYTES;
            GpuPlane {
                buffer: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: size.max(TEXEL_BYTES),
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                desc: [width as u32, height as u32, rows.start as u32, rows.len() as u32],
            }
        };
        let linear_desc = [w as u32, h as u32, inputs.source.start as u32, inputs.source.len() as u32];
        // The dispatches, recorded into one compute pass at the end.
        let mut steps: Vec<(&'p wgpu::ComputePipeline, wgpu::BindGroup, [u32; 2])> = Vec::new();
        // One dispatch over `o`'s texels, reading a (and b).
        let mut step = |pipeline: &'p wgpu::ComputePipeline,
                        a: (&wgpu::Buffer, [u32; 4]),
                        b: Option<(&wgpu::Buffer, [u32; 4])>,
                        o: &GpuPlane| {
            let uniforms = BloomUniforms {
                a: a.1,
                b: b.map_or([1, 1, 0, 1], |b| b.1),
                c: [1, 1, 0, 1],
                o: o.desc,
                params,
                flags: [u32::from(b.is_some()), tone, 0, 0],
            };
            let ubuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("bloom step"),
                contents: bytemuck::bytes_of(&uniforms),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let b_buf = b.map_or(a.0, |b| b.0);
            let group = setup::bind_group(
                device,
                "bloom step",
                &self.layout,
                &BINDINGS,
                vec![
                    ubuf.as_entire_binding(),
                    a.0.as_entire_binding(),
                    b_buf.as_entire_binding(),
                    a.0.as_entire_binding(),
                    o.buffer.as_entire_binding(),
                ],
            );
            steps.push((pipeline, group, [o.desc[0].div_ceil(8), o.desc[3].div_ceil(8)]));
        };
        // 1. T over the source rows.
        let t = plane("bloom T", w, h, &plan.source);
        step(&self.prefilter, (inputs.linear, linear_desc), None, &t);
        // 2. D_1 … D_N.
        let mut downs: Vec<GpuPlane> = Vec::with_capacity(plan.levels.len());
        for l in &plan.levels {
            let d = plane("bloom D", l.width, l.height, &l.down);
            let prev = downs.last().unwrap_or(&t);
            step(&self.down, (&prev.buffer, prev.desc), None, &d);
            downs.push(d);
        }
        // 3. U_N = D_N, U_k = D_k + up(U_{k+1}) down to U₁.
        let mut u = downs.pop().expect("at least one level");
        while let Some(d) = downs.pop() {
            let l = &plan.levels[downs.len()];
            let next = plane("bloom U", l.width, l.height, &l.up);
            step(&self.up, (&u.buffer, u.desc), Some((&d.buffer, d.desc)), &next);
            u = next;
        }
        // 4. The streak along x over level 1's rows, from the prefiltered row pairs.
        let l1 = &plan.levels[0];
        let (hl, rows1) = (l1.height, &l1.up);
        let streak = (ks > 0.0).then(|| {
            let pair = plane("streak pair", w, hl, rows1);
            step(&self.pair, (&t.buffer, t.desc), None, &pair);
            let mut widths = vec![w];
            for k in 0..ns as usize {
                widths.push(half(widths[k]));
            }
            let mut downs: Vec<GpuPlane> = Vec::new();
            for &lw in &widths[1..] {
                let d = plane("streak D", lw, hl, rows1);
                let prev = downs.last().unwrap_or(&pair);
                step(&self.down_h, (&prev.buffer, prev.desc), None, &d);
                downs.push(d);
            }
            let mut u = downs.pop().expect("at least one level");
            while let Some(d) = downs.pop() {
                let next = plane("streak U", d.desc[0] as usize, hl, rows1);
                step(&self.up_h, (&u.buffer, u.desc), Some((&d.buffer, d.desc)), &next);
                u = next;
            }
            u
        });
        // 5. G at level 1.
        let g = plane("bloom G", l1.width, hl, &bilinear_rows(&inputs.band, hl));
        step(&self.glare, (&u.buffer, u.desc), streak.as_ref().map(|s| (&s.buffer, s.desc)), &g);
        // 6. The bilinear tap of G, the composite and the colour mapping.
        let out = plane("bloom out", w, h, &inputs.band);
        step(&self.composite, (inputs.linear, linear_desc), Some((&g.buffer, g.desc)), &out);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("bloom"),
            timestamp_writes: timestamps,
        });
        for (pipeline, group, [x, y]) in &steps {
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(*x, *y, 1);
        }
        drop(pass);
        out.buffer
    }
}
