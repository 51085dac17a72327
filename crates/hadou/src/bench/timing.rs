//! How `hadou bench` times a frame: the [`Timer`] every table measures with, the CPU backend's
//! ([`time_cpu`]) and the medians.

use hadou_math::simd::SimdPath;
use hadou_scene::{Frame, RenderError, Rgb8Image};

/// What a [`Timer`] measured for one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timing {
    /// Median milliseconds per frame: the whole render, without writing the output (on the CPU,
    /// into the 8-bit sRGB bytes a PNG holds).
    pub ms: f64,
    /// The parts, in order, as (name, median milliseconds): on the CPU the opaque pass, the wave
    /// pass and the colour stage (which add up to the whole) and the output (PNG encoding of the
    /// 8-bit bytes into memory, after the render); on the GPU each pass's GPU timestamps where
    /// the adapter has them, what the read-back adds (the wall clock of the PNG's rows drawn and
    /// read back, less the GPU time) and the output. Empty where nothing finer was measured.
    pub parts: Vec<(String, f64)>,
}

impl Timing {
    /// A timing with no parts.
    pub fn whole(ms: f64) -> Self {
        Self { ms, parts: Vec::new() }
    }

    /// The parts as a JSON array of `{name, ms}`.
    pub fn parts_json(&self) -> serde_json::Value {
        let parts: Vec<super::table::Row> = self
            .parts
            .iter()
            .map(|(name, ms)| {
                vec![super::table::Cell::json("name", name.as_str()), super::table::Cell::json("ms", *ms)]
            })
            .collect();
        super::table::rows_json(&parts)
    }
}

/// A timer: renders `frame` once untimed, then `iterations` timed times, and returns the medians.
pub type Timer<'a> = dyn FnMut(&Frame, u32) -> Result<Timing, RenderError> + 'a;

/// The median of `v` (0 when empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

/// Times the CPU backend on the vector path it picks ([`SimdPath::current`]); see
/// `time_cpu_on`.
pub fn time_cpu(frame: &Frame, iterations: u32) -> Result<Timing, RenderError> {
    time_cpu_on(frame, iterations, SimdPath::current())
}

/// Times the CPU backend on the vector path `simd`: `iterations` frames after a warm-up, drawn as
/// `hadou render` draws a PNG's (the 8-bit sRGB bytes straight from the colour stage, one
/// [`hadou_cpu::CpuBackend`] and one image reused from frame to frame), each split into its passes
/// ([`hadou_cpu::CpuBackend::render_rgb8_into`]), then the output of the image (PNG encoding
/// into memory) as many times. Medians of each.
pub fn time_cpu_on(frame: &Frame, iterations: u32, simd: SimdPath) -> Result<Timing, RenderError> {
    let mut cpu = hadou_cpu::CpuBackend::new();
    let mut image = Rgb8Image::default();
    cpu.render_rgb8_into(frame, &mut image, simd);
    let (mut whole, mut opaque, mut wave, mut color, mut output) = (vec![], vec![], vec![], vec![], vec![]);
    for _ in 0..iterations.max(1) {
        let t = std::time::Instant::now();
        let p = cpu.render_rgb8_into(frame, &mut image, simd);
        whole.push(t.elapsed().as_secs_f64() * 1e3);
        opaque.push(p.opaque_ms);
        wave.push(p.wave_ms);
        color.push(p.color_ms);
    }
    for _ in 0..iterations.max(1) {
        output.push(rgb8_output_ms(&image)?);
    }
    Ok(Timing {
        ms: median(whole),
        parts: vec![
            ("opaque".into(), median(opaque)),
            ("wave".into(), median(wave)),
            ("colour".into(), median(color)),
            ("output".into(), median(output)),
        ],
    })
}

/// Milliseconds to turn 8-bit sRGB rows into PNG bytes in memory.
pub fn rgb8_output_ms(image: &Rgb8Image) -> Result<f64, RenderError> {
    let t = std::time::Instant::now();
    let bytes = crate::output::encode_png_rgb8(image).map_err(RenderError::Other)?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    std::hint::black_box(bytes);
    Ok(ms)
}

/// Median wall-clock milliseconds of `iterations` calls of `render` after one warm-up.
pub fn median_ms(
    render: &mut dyn FnMut(&Frame) -> Result<(), RenderError>,
    frame: &Frame,
    iterations: u32,
) -> Result<f64, RenderError> {
    render(frame)?;
    let mut v = Vec::with_capacity(iterations as usize);
    for _ in 0..iterations.max(1) {
        let t = std::time::Instant::now();
        render(frame)?;
        v.push(t.elapsed().as_secs_f64() * 1e3);
    }
    Ok(median(v))
}
