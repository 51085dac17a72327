//! Rendering a frame on the CPU: the per-frame set-up ([`FrameSetup`]), the opaque pass with the
//! area light's soft-shadowed term added ([`opaque_pass`]), then per row the wave pass and the
//! colour mapping ([`crate::waves`]), timed pass by pass ([`PassTimes`]); [`CpuBackend`] keeps the
//! opaque pass's buffers from frame to frame.

#[cfg(not(target_arch = "wasm32"))]
use std::time::Instant;
// wasm32-unknown-unknown has no clock in std (`Instant::now` panics there); the page's clock.
use crate::bloom;
use crate::edges;
use crate::opaque::{draw_opaque_into, OpaqueBuffers};
use crate::setup::FrameSetup;
use crate::soft;
use crate::waves::{BatchLight, RowOut, WavePass};
use hadou_math::energy::lanes::LANES;
use hadou_math::simd::SimdPath;
use hadou_scene::{Backend, Frame, Image, RenderError, Rgb8Image, SoftResolve};
use rayon::prelude::*;
#[cfg(target_arch = "wasm32")]
use web_time::Instant;

/// The CPU reference backend. It keeps the opaque pass's buffers between frames, so a frame
/// drawn with [`CpuBackend::render_into`] into an image from an earlier frame allocates nothing
/// that grows with the image.
#[derive(Default)]
pub struct CpuBackend {
    scratch: OpaqueBuffers,
}

impl std::fmt::Debug for CpuBackend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CpuBackend").finish_non_exhaustive()
    }
}

impl CpuBackend {
    /// A backend using rayon's global thread pool.
    pub fn new() -> Self {
        Self::default()
    }

    /// Renders `frame` into `image` (resized to the frame, its allocations reused: what a viewer
    /// or a benchmark drawing frame after frame wants) and returns the passes' times; the same
    /// pixels as [`render`].
    pub fn render_into(&mut self, frame: &Frame, image: &mut Image) -> PassTimes {
        expect_memory(render_with(
            frame,
            0..frame.height,
            &mut self.scratch,
            Target::Float(image),
            SimdPath::current(),
        ))
    }

    /// [`CpuBackend::render_into`] for a PNG: only the 8-bit sRGB bytes, written by the colour
    /// stage straight from its lanes (no float colour, energy or depth buffer), on the vector path
    /// `simd`. The same bytes as [`Rgb8Image::from_image`] of [`render`] on that path.
    pub fn render_rgb8_into(&mut self, frame: &Frame, image: &mut Rgb8Image, simd: SimdPath) -> PassTimes {
        expect_memory(render_with(frame, 0..frame.height, &mut self.scratch, Target::Srgb8(image), simd))
    }

    /// [`CpuBackend::render_into`] on the vector path `simd` instead of [`SimdPath::current`].
    pub fn render_into_on(&mut self, frame: &Frame, image: &mut Image, simd: SimdPath) -> PassTimes {
        expect_memory(render_with(frame, 0..frame.height, &mut self.scratch, Target::Float(image), simd))
    }
}

/// What a render writes: the float image, or the 8-bit sRGB a PNG needs.
enum Target<'a> {
    Float(&'a mut Image),
    Srgb8(&'a mut Rgb8Image),
}

impl Backend for CpuBackend {
    fn name(&self) -> &str {
        "cpu"
    }

    fn render(&mut self, frame: &Frame) -> Result<Image, RenderError> {
        self.render_rows(frame, 0..frame.height)
    }

    fn render_rows(&mut self, frame: &Frame, rows: std::ops::Range<u32>) -> Result<Image, RenderError> {
        let (y0, y1) = (rows.start.min(frame.height), rows.end.min(frame.height));
        let mut img = Image::new(frame.width, y1.max(y0) - y0);
        render_with(
            frame,
            rows,
            &mut OpaqueBuffers::default(),
            Target::Float(&mut img),
            SimdPath::current(),
        )?;
        Ok(img)
    }

    fn render_rows_rgb8(
        &mut self,
        frame: &Frame,
        rows: std::ops::Range<u32>,
    ) -> Result<Rgb8Image, RenderError> {
        let mut out = Rgb8Image::default();
        render_with(frame, rows, &mut self.scratch, Target::Srgb8(&mut out), SimdPath::current())?;
        Ok(out)
    }
}

/// Renders `frame` on the CPU.
pub fn render(frame: &Frame) -> Image {
    render_rows(frame, 0..frame.height)
}

/// Renders the rows `rows` of `frame` (clamped to the image): the same pixels as those rows of
/// [`render`], bit for bit, in an image `frame.width` wide and `rows.len()` high.
pub fn render_rows(frame: &Frame, rows: std::ops::Range<u32>) -> Image {
    render_timed(frame, rows).0
}

/// Wall-clock milliseconds of each pass of one CPU render (see [`render_timed`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassTimes {
    /// Per-frame set-up (camera, curve tables, lights, shadow maps) and the opaque pass: meshes,
    /// outlines, shading, hard and soft shadows.
    pub opaque_ms: f64,
    /// The energy integrals of every wave per pixel, clipped at the visible surface.
    pub wave_ms: f64,
    /// `scene + exposure·Σ rgb·a·I` and the colour mapping (with a `[bloom]`, the glare too).
    pub color_ms: f64,
}

/// [`render_rows`], also returning how long each pass took. The opaque pass runs first; then each
/// row runs its wave pass and its colour mapping, and the wall time of that stage is split
/// between the two in the proportion of the threads' time in each. The times add up to the
/// render's.
pub fn render_timed(frame: &Frame, rows: std::ops::Range<u32>) -> (Image, PassTimes) {
    let (y0, y1) = (rows.start.min(frame.height), rows.end.min(frame.height));
    let mut img = Image::new(frame.width, y1.max(y0) - y0);
    let times = expect_memory(render_with(
        frame,
        rows,
        &mut OpaqueBuffers::default(),
        Target::Float(&mut img),
        SimdPath::current(),
    ));
    (img, times)
}

/// The times of a render that cannot fail but for memory, which only a frame with a `[bloom]`
/// reserves fallibly: the functions that return an image or times, not a `Result`, panic with its
/// message there (the [`Backend`] methods return it as a [`RenderError`]).
fn expect_memory(r: Result<PassTimes, RenderError>) -> PassTimes {
    r.unwrap_or_else(|e| panic!("{e}"))
}

/// [`render_timed`] with the opaque pass's buffers from `scratch` and into `img`, both resized
/// and their allocations reused. With more than one sample per pixel ([`Frame::grid`]) the opaque
/// pass draws the sample frame ([`Frame::sample_frame`]) and each row is resolved by
/// [`RowSource`].
fn render_with(
    frame: &Frame,
    rows: std::ops::Range<u32>,
    scratch: &mut OpaqueBuffers,
    target: Target<'_>,
    simd: SimdPath,
) -> Result<PassTimes, RenderError> {
    render_chunked(frame, rows, scratch, target, simd, GLARE_CHUNK_SAMPLES)
}

/// Renders a frame with a `[bloom]` with its opaque pass in chunks of `chunk_samples` samples
/// (at least a row), for tests of the chunking: the same pixels as [`render_rows`] whatever the
/// chunk.
#[doc(hidden)]
pub fn render_rows_glare_chunked(frame: &Frame, rows: std::ops::Range<u32>, chunk_samples: usize) -> Image {
    let (y0, y1) = (rows.start.min(frame.height), rows.end.min(frame.height));
    let mut img = Image::new(frame.width, y1.max(y0) - y0);
    let target = Target::Float(&mut img);
    let scratch = &mut OpaqueBuffers::default();
    expect_memory(render_chunked(frame, rows, scratch, target, SimdPath::current(), chunk_samples));
    img
}

/// Renders `frame` with every sample of every pixel shaded (the anti-aliased frame as it was
/// before surfaces were shaded once per pixel, [`crate::opaque::ShadedOnce`]), for the tests that
/// hold the two to a tolerance.
#[doc(hidden)]
pub fn render_every_sample_shaded(frame: &Frame) -> Image {
    let mut img = Image::new(frame.width, frame.height);
    let mut scratch = OpaqueBuffers::default();
    scratch.once.every_sample = true;
    let times =
        render_with(frame, 0..frame.height, &mut scratch, Target::Float(&mut img), SimdPath::current());
    expect_memory(times);
    img
}

/// [`render_with`], a `[bloom]`'s opaque pass in chunks of `chunk_samples` samples.
fn render_chunked(
    frame: &Frame,
    rows: std::ops::Range<u32>,
    scratch: &mut OpaqueBuffers,
    target: Target<'_>,
    simd: SimdPath,
    chunk_samples: usize,
) -> Result<PassTimes, RenderError> {
    let start = Instant::now();
    if let Some(light) = frame.area_light.as_ref().filter(|l| matches!(l.resolve, SoftResolve::Traced { .. }))
    {
        let tris = crate::traced::caster_triangle_count(frame, &light.casters);
        hadou_scene::check_trace_memory(tris).map_err(RenderError::Memory)?;
    }
    let (y0, y1) = (rows.start.min(frame.height), rows.end.min(frame.height));
    let y1 = y1.max(y0);
    let k = frame.sample_grid().edge() as usize;
    let sampled;
    let surfaces = if k > 1 {
        sampled = frame.sample_frame();
        &sampled
    } else {
        frame
    };
    let setup = FrameSetup::new(surfaces);
    let band = y0 as usize..y1 as usize;
    // With a bloom, the band's halo too (every row of it exactly as a whole-image render has it).
    let glare = frame.bloom.as_ref().filter(|_| y1 > y0);
    let src = glare.map_or(band.clone(), |b| bloom::source_rows(frame, b, band.clone()));
    // A frame of waves alone draws nothing opaque: every pixel (every sample) shows the
    // background, so the opaque pass and its per-pixel buffers are skipped.
    let blank = frame.objects.is_empty() && frame.area_light.is_none();
    if let Some(params) = glare {
        let parts = GlareParts {
            draw: DrawParts { frame, surfaces, setup: &setup, k, blank, simd },
            params,
            chunk_samples,
        };
        return match target {
            Target::Float(img) => glare_rows(&parts, scratch, src, band, img, start),
            Target::Srgb8(out) => {
                // The glare needs the linear colour of the band and its halo: the float image,
                // then its bytes.
                let mut img = Image::new(0, 0);
                let times = glare_rows(&parts, scratch, src, band, &mut img, start)?;
                let srgb = hadou_math::shade::srgb8_encoder();
                (out.width, out.height) = (img.width, img.height);
                out.rgb.clear();
                try_grow(&mut out.rgb, 3 * img.color.len(), "the band's 8-bit colour")?;
                out.rgb.extend(
                    img.color.iter().flat_map(|c| [srgb.code(c[0]), srgb.code(c[1]), srgb.code(c[2])]),
                );
                Ok(times)
            }
        };
    }
    let draw = DrawParts { frame, surfaces, setup: &setup, k, blank, simd };
    let source = draw.row_source(src.clone(), scratch);
    let opaque_done = Instant::now();

    let w = frame.width as usize;
    let n = w * (y1 - y0) as usize;
    // Each row: the wave pass into a row buffer, then the colour stage from it; the threads'
    // time in each, to split the wall time between them.
    let wave_ns = std::sync::atomic::AtomicU64::new(0);
    let color_ns = std::sync::atomic::AtomicU64::new(0);
    let row = |bufs: &mut RowBuffers, r: usize, out: RowOut<'_>| {
        let t0 = Instant::now();
        let (light, scene) = source.light_row(y0 as usize + r, bufs);
        let t1 = Instant::now();
        source.pass.row_color(light, scene, out);
        let t2 = Instant::now();
        let ns = |d: std::time::Duration| d.as_nanos() as u64;
        wave_ns.fetch_add(ns(t1 - t0), std::sync::atomic::Ordering::Relaxed);
        color_ns.fetch_add(ns(t2 - t1), std::sync::atomic::Ordering::Relaxed);
    };
    match target {
        Target::Float(img) => {
            (img.width, img.height) = (frame.width, y1 - y0);
            // Every pixel is written below: the resizes only size the buffers.
            img.color.resize(n, [0.0; 4]);
            img.energy.resize(n, 0.0);
            img.depth.resize(n, 0.0);
            img.color
                .par_chunks_mut(w)
                .zip(img.energy.par_chunks_mut(w))
                .zip(img.depth.par_chunks_mut(w))
                .enumerate()
                .for_each_init(RowBuffers::default, |bufs, (r, ((color, energy), depth))| {
                    row(bufs, r, RowOut::Float { color, energy, depth })
                });
        }
        Target::Srgb8(out) => {
            (out.width, out.height) = (frame.width, y1 - y0);
            out.rgb.resize(3 * n, 0);
            out.rgb
                .par_chunks_mut(3 * w.max(1))
                .enumerate()
                .for_each_init(RowBuffers::default, |bufs, (r, bytes)| row(bufs, r, RowOut::Srgb8(bytes)));
        }
    }
    let end = Instant::now();
    let (wn, cn) = (wave_ns.into_inner() as f64, color_ns.into_inner() as f64);
    let wave_share = if wn + cn > 0.0 { wn / (wn + cn) } else { 1.0 };
    let waves_done = opaque_done + (end - opaque_done).mul_f64(wave_share);
    let ms = |a: Instant, b: Instant| (b - a).as_secs_f64() * 1e3;
    Ok(PassTimes {
        opaque_ms: ms(start, opaque_done),
        wave_ms: ms(opaque_done, waves_done),
        color_ms: ms(waves_done, end),
    })
}

/// A row's scratch buffers for [`RowSource::light_row`], reused from row to row by a thread.
#[derive(Default)]
struct RowBuffers {
    light: Vec<BatchLight>,
    scene: Vec<[f32; 3]>,
    surface: Vec<f32>,
    edges: Vec<usize>,
}

/// The opaque pass's buffers and the wave passes a frame's rows are lit from: with `k > 1` the
/// buffers hold the sample frame's rows (`k` per image row, from sample row `oy0`), and each
/// pixel is resolved from its `k × k` samples.
struct RowSource<'a> {
    k: usize,
    /// With nothing opaque in the frame, every pixel's scene colour (the background, resolved
    /// from its samples as a drawn frame's would be); the opaque buffers are then not read.
    blank: Option<[f32; 3]>,
    opaque: &'a OpaqueBuffers,
    oy0: usize,
    /// The wave pass through the image's pixel centres.
    pass: WavePass<'a>,
    /// The wave pass through the sample frame's pixels (the samples).
    samples: WavePass<'a>,
}

impl RowSource<'_> {
    /// Image row `y`: its waves' light into `bufs.light` (batch by batch, as
    /// [`WavePass::row_light`]) and its scene colour, both returned. With one sample per pixel, the
    /// opaque pass's row. With `k × k` samples, each pixel's scene colour is the mean of its
    /// samples' (the box filter); where all of its samples show the same surface (the same
    /// object, material and outline state, or all nothing) within
    /// [`hadou_scene::SAMPLE_DEPTH_SPREAD`] in eye distance, the waves are integrated once along
    /// the ray through the pixel's centre, clipped at the samples' mean distance; elsewhere (a
    /// silhouette, an outline's edge) sample by sample, clipped at each sample's surface, and
    /// averaged. The depth is the centre ray's, or at such an edge the nearest sample's.
    fn light_row<'b>(&'b self, y: usize, bufs: &'b mut RowBuffers) -> (&'b [BatchLight], &'b [[f32; 3]]) {
        let o = self.opaque;
        let k = self.k;
        if let Some(bg) = self.blank {
            // No surface anywhere: the waves through every pixel's centre, unclipped (the
            // samples all agree, so an anti-aliased frame integrates once per pixel too).
            let w = self.pass_width();
            let RowBuffers { light, scene, surface, .. } = bufs;
            if surface.len() != w || scene.len() != w || scene.first() != Some(&bg) {
                surface.clear();
                surface.resize(w, f32::INFINITY);
                scene.clear();
                scene.resize(w, bg);
            }
            self.pass.row_light(y as f32, surface, light);
            return (light, scene);
        }
        if k == 1 {
            let w = self.pass_width();
            let first = (y - self.oy0) * w;
            self.pass.row_light(y as f32, &o.surface[first..first + w], &mut bufs.light);
            return (&bufs.light, &o.color[first..first + w]);
        }
        let w = self.pass_width();
        let sw = w * k;
        let RowBuffers { light, scene, surface, edges } = bufs;
        scene.clear();
        surface.clear();
        edges.clear();
        let inv = 1.0 / (k * k) as f32;
        // The pixel row's marks of shading once (`ShadedOnce::centred`), where there are any.
        let prow = (k * y - self.oy0) / k * w;
        let centred = o.once.centred.get(prow..prow + w);
        for x in 0..w {
            let mut c = [0.0f32; 3];
            let (mut lo, mut hi, mut sum) = (f32::INFINITY, 0.0f32, 0.0f32);
            let first = (k * y - self.oy0) * sw + k * x;
            if centred.is_some_and(|m| m[x]) {
                // Every sample of the pixel shows one surface of an object (so it is drawn and
                // the samples agree but for their spread in depth), in its centre's colour (left
                // unwritten): the same sums without reading the samples' colours and keys.
                let centre = o.once.centre[prow + x];
                for j in 0..k {
                    for i in 0..k {
                        for (ck, v) in c.iter_mut().zip(centre) {
                            *ck += v * inv;
                        }
                        let d = o.surface[first + j * sw + i];
                        if d.is_finite() {
                            (lo, hi, sum) = (lo.min(d), hi.max(d), sum + d);
                        }
                    }
                }
                scene.push(c.map(hadou_math::energy::saturate));
                surface.push(sum * inv);
                let agree = hi - lo <= hadou_scene::SAMPLE_DEPTH_SPREAD * lo;
                if !agree {
                    edges.push(x);
                }
                continue;
            }
            let key0 = sample_key(o, first);
            let mut same = true;
            for j in 0..k {
                for i in 0..k {
                    let idx = first + j * sw + i;
                    for (ck, v) in c.iter_mut().zip(o.color[idx]) {
                        *ck += v * inv;
                    }
                    same &= sample_key(o, idx) == key0;
                    let d = o.surface[idx];
                    if d.is_finite() {
                        (lo, hi, sum) = (lo.min(d), hi.max(d), sum + d);
                    }
                }
            }
            scene.push(c.map(hadou_math::energy::saturate));
            let drawn = key0.is_some();
            let agree = same && (!drawn || hi - lo <= hadou_scene::SAMPLE_DEPTH_SPREAD * lo);
            surface.push(if drawn { sum * inv } else { f32::INFINITY });
            if !agree {
                edges.push(x);
            }
        }
        self.pass.row_light(y as f32, surface, light);
        for &x in edges.iter() {
            let (mut l, mut total, mut depth) = ([0.0f32; 3], 0.0f32, f32::INFINITY);
            for j in 0..k {
                let sy = k * y + j;
                let first = (sy - self.oy0) * sw + k * x;
                let (lj, tj, dj) = self.samples.samples_light(
                    k * x,
                    sy as f32,
                    &o.surface[first..first + k],
                    1.0 / (k * k) as f32,
                );
                for (a, b) in l.iter_mut().zip(lj) {
                    *a += b;
                }
                total = hadou_math::energy::saturate(total + tj);
                depth = depth.min(dj);
            }
            light[x / LANES].set_lane(x % LANES, l, total, depth);
        }
        (light, scene)
    }

    /// The image's width in pixels.
    fn pass_width(&self) -> usize {
        self.pass.width()
    }
}

/// The scene colour of a pixel none of whose `k × k` samples shows a surface, summed as
/// [`RowSource::light_row`] sums a drawn frame's samples (so a blank frame renders bit for bit as
/// it would through the opaque pass).
fn blank_color(background: [f32; 3], k: usize) -> [f32; 3] {
    if k == 1 {
        return background;
    }
    let inv = 1.0 / (k * k) as f32;
    let mut c = [0.0f32; 3];
    for _ in 0..k * k {
        for (ck, v) in c.iter_mut().zip(background) {
            *ck += v * inv;
        }
    }
    c.map(hadou_math::energy::saturate)
}

/// What decides whether a pixel's samples show one surface: the visible object, its material
/// slot and whether it is an outline (a hull, or a pixel the edge pass closed an outline over,
/// which takes that object and slot); `None` where nothing is drawn. The GPU's wave pass compares
/// the G-buffer's material word the same way.
fn sample_key(o: &OpaqueBuffers, i: usize) -> Option<(u32, u32)> {
    if !o.surface[i].is_finite() {
        return None;
    }
    // (The material word carries the outline state: `opaque::HULL`.)
    let object = o.object[i];
    (object != crate::opaque::NONE).then_some((object, o.material[i]))
}

/// What a frame's rows are drawn from: the frame, the frame its opaque pass draws, the set-up,
/// the sample grid's `k`, whether nothing opaque is drawn, and the vector path.
#[derive(Clone, Copy)]
struct DrawParts<'a> {
    frame: &'a Frame,
    /// The frame the opaque pass draws (the sample frame with `k > 1`).
    surfaces: &'a Frame,
    setup: &'a FrameSetup,
    k: usize,
    blank: bool,
    simd: SimdPath,
}

impl<'a> DrawParts<'a> {
    /// The opaque pass over the image rows `rows` (skipped for a blank frame) into `scratch`,
    /// and the [`RowSource`] that lights those rows from it.
    fn row_source(&self, rows: std::ops::Range<usize>, scratch: &'a mut OpaqueBuffers) -> RowSource<'a> {
        let DrawParts { frame, surfaces, setup, k, blank, simd } = *self;
        let oy0 =
            if blank { 0 } else { opaque_pass(surfaces, setup, k, k * rows.start..k * rows.end, scratch) };
        RowSource {
            k,
            blank: blank.then(|| blank_color(surfaces.background, k)),
            opaque: scratch,
            oy0,
            pass: WavePass::new(frame, &setup.basis, &setup.curves).on_path(simd),
            samples: WavePass::new(surfaces, &setup.basis, &setup.curves).on_path(simd),
        }
    }
}

/// What [`glare_rows`] draws a frame with a `[bloom]` from.
struct GlareParts<'a> {
    draw: DrawParts<'a>,
    params: &'a hadou_math::bloom::BloomParams,
    /// Samples of the opaque pass drawn at once ([`GLARE_CHUNK_SAMPLES`]).
    chunk_samples: usize,
}

/// Samples of the opaque pass drawn at once for a frame with a `[bloom]` (4 Mi, about 200 MB of
/// per-sample buffers): the glare needs the linear colour of (nearly) every row, but not every
/// sample of it at once.
const GLARE_CHUNK_SAMPLES: usize = 1 << 22;

/// `v` grown by `n` elements' room, or a message naming `what` where memory ran out (never an
/// abort).
fn try_grow<T>(v: &mut Vec<T>, n: usize, what: &str) -> Result<(), RenderError> {
    v.try_reserve_exact(n).map_err(|_| out_of_memory(n * std::mem::size_of::<T>(), what))
}

/// `v` sized to `n` elements, its allocation grown fallibly where it is short; the elements it
/// already holds are kept as they are (for buffers of which every element is written next).
fn try_size<T: Clone>(v: &mut Vec<T>, n: usize, fill: T, what: &str) -> Result<(), RenderError> {
    if v.len() >= n {
        v.truncate(n);
        return Ok(());
    }
    v.try_reserve_exact(n - v.len()).map_err(|_| out_of_memory(n * std::mem::size_of::<T>(), what))?;
    v.resize(n, fill);
    Ok(())
}

fn out_of_memory(bytes: usize, what: &str) -> RenderError {
    RenderError::Memory(format!("{what} needs {:.2} GB that could not be allocated", bytes as f64 / 1e9))
}

/// [`render_with`] for a frame with a `[bloom]`: the opaque pass and the wave pass over the rows
/// `src` (the band `band` and its halo) into the linear colour, in chunks of about
/// `chunk_samples` samples (every row as a whole-image render has it: the opaque pass of
/// a chunk draws its own outline margin), then the glare and the colour mapping of the band. The
/// opaque passes' time is `opaque_ms`, the wave passes' `wave_ms`, the glare's and mapping's
/// `color_ms`. Every buffer that grows with the image is reserved fallibly: memory that is not
/// there is a [`RenderError`], not an abort.
fn glare_rows(
    parts: &GlareParts<'_>,
    scratch: &mut OpaqueBuffers,
    src: std::ops::Range<usize>,
    band: std::ops::Range<usize>,
    img: &mut Image,
    start: Instant,
) -> Result<PassTimes, RenderError> {
    let GlareParts { draw, params, chunk_samples } = *parts;
    let DrawParts { frame, k, simd, .. } = draw;
    let w = frame.width as usize;
    let n = w * band.len();
    (img.width, img.height) = (frame.width, band.len() as u32);
    // Sized only: every element is written below (the energy and depth by the wave pass, the
    // colour by the glare's mapping).
    for (v, what) in [(&mut img.energy, "the band's energy"), (&mut img.depth, "the band's depth")] {
        try_size(v, n, 0.0, what)?;
    }
    try_size(&mut img.color, n, [0.0; 4], "the band's colour")?;
    // The linear colour in the buffer the last frame left (no fresh pages to fault in), every row
    // written by the wave pass.
    let mut data = std::mem::take(&mut scratch.glare_linear);
    try_size(&mut data, w * src.len(), [0.0; 3], "the glare's linear colour")?;
    let mut linear =
        hadou_math::bloom::Plane { width: w, height: frame.height as usize, rows: src.clone(), data };
    // With an area light the opaque pass draws every row whatever it is asked: one chunk.
    let chunk =
        if frame.area_light.is_some() { src.len() } else { (chunk_samples / (w * k * k).max(1)).max(1) };
    let (mut opaque_ms, mut wave_ms) = (0.0, 0.0);
    let ms = |a: Instant, b: Instant| (b - a).as_secs_f64() * 1e3;
    let mut t = start;
    for (c, lin) in linear.data.chunks_mut(chunk * w).enumerate() {
        let rows = src.start + c * chunk..(src.start + (c + 1) * chunk).min(src.end);
        let source = draw.row_source(rows.clone(), scratch);
        let opaque_done = Instant::now();
        // The band's rows of this chunk keep their energy and depth; the halo's go to scratch.
        let own = rows.start.max(band.start)..rows.end.min(band.end).max(rows.start.max(band.start));
        let (energy, depth) = if own.is_empty() {
            (&mut [][..], &mut [][..])
        } else {
            let at = (own.start - band.start) * w..(own.end - band.start) * w;
            (&mut img.energy[at.clone()], &mut img.depth[at])
        };
        let (skip, own_rows) = (own.start.saturating_sub(rows.start), own.len());
        let (mut energy_rows, mut depth_rows) = (energy.chunks_mut(w.max(1)), depth.chunks_mut(w.max(1)));
        let mut outs: Vec<Option<(&mut [f32], &mut [f32])>> = (0..rows.len())
            .map(|r| {
                if r >= skip && r < skip + own_rows {
                    Some((energy_rows.next().expect("a row"), depth_rows.next().expect("a row")))
                } else {
                    None
                }
            })
            .collect();
        lin.par_chunks_mut(w).zip(outs.par_iter_mut()).enumerate().for_each_init(
            || (RowBuffers::default(), vec![0.0f32; w], vec![0.0f32; w]),
            |(bufs, en_scratch, dep_scratch), (r, (lin, out))| {
                let (light, scene) = source.light_row(rows.start + r, bufs);
                match out {
                    Some((en, dep)) => source.pass.row_linear(light, scene, lin, en, dep),
                    None => source.pass.row_linear(light, scene, lin, en_scratch, dep_scratch),
                }
            },
        );
        let waves_done = Instant::now();
        opaque_ms += ms(t, opaque_done);
        wave_ms += ms(opaque_done, waves_done);
        t = waves_done;
    }
    bloom::glare_and_map(frame, params, &linear, band, &mut img.color, simd, &mut scratch.glare_planes)?;
    scratch.glare_linear = linear.data;
    Ok(PassTimes { opaque_ms, wave_ms, color_ms: ms(t, Instant::now()) })
}

/// The opaque pass for the rows `rows`, with the area light's soft-shadowed light added (which
/// needs the whole image: then every row is drawn) and the outlines closed where objects meet
/// ([`edges::close_outlines`], which needs [`edges::frame_reach`]` + 1` rows beyond `rows`: those
/// are drawn too). `frame` is the frame the pass draws: with `k > 1` the sample frame, each image
/// pixel `k × k` of its pixels (the soft stage's [`soft::SoftInput::grid`]). Returns the buffers'
/// first row.
pub(crate) fn opaque_pass(
    frame: &Frame,
    setup: &FrameSetup,
    k: usize,
    rows: std::ops::Range<usize>,
    opaque: &mut OpaqueBuffers,
) -> usize {
    let Some(light) = &frame.area_light else {
        let margin = edges::frame_reach(frame) as usize + 1;
        let h = frame.height as usize;
        // On whole pixels (multiples of `k` samples), for shading once per pixel.
        let margin = margin.next_multiple_of(k);
        let drawn =
            rows.start.saturating_sub(margin).min(rows.start)..(rows.end + margin).min(h).max(rows.end);
        let y0 = drawn.start;
        draw_opaque_into(frame, setup, k, drawn, opaque);
        edges::close_outlines(frame, &setup.basis, y0, opaque);
        return y0;
    };
    draw_opaque_into(frame, setup, k, 0..frame.height as usize, opaque);
    let input = soft::SoftInput {
        width: frame.width as usize,
        height: frame.height as usize,
        points: std::mem::take(&mut opaque.soft),
        grid: k,
    };
    let add = |c: &mut [f32; 3], v: f32, term: [f32; 3]| {
        for (ck, tk) in c.iter_mut().zip(term) {
            *ck = hadou_math::energy::saturate(*ck + v * tk);
        }
    };
    let vis = match light.resolve {
        // Pixels centred under a traced lamp (`opaque::ShadedOnce::soft`): traced from their
        // centres, their one colour lit once where their samples agree.
        SoftResolve::Traced { samples } if !opaque.once.soft.is_empty() => {
            let (w, h) = (frame.width, frame.height);
            let (basis, surface) = (&setup.basis, &opaque.surface);
            let sample_world = |j: usize| {
                let (x, y) = ((j % w as usize) as f32, (j / w as usize) as f32);
                let d = basis.pixel_dir(x, y, w, h);
                basis.eye + d * (surface[j] / d.length())
            };
            let bvh = hadou_math::soft::Bvh::build(&crate::traced::caster_triangles(frame, &light.casters));
            let once = &mut opaque.once;
            let centred = crate::traced::Centred {
                marks: &once.centred,
                pixels: &once.soft,
                sample_world: &sample_world,
            };
            let (vis, _) = crate::traced::traced_grid_of(
                &bvh,
                light,
                &input.points,
                Some(&centred),
                w as usize,
                samples,
                k,
            );
            let pw = w as usize / k;
            opaque
                .color
                .par_chunks_mut(k * w as usize)
                .zip(opaque.shadow.par_chunks_mut(k * w as usize))
                .zip(input.points.par_chunks(k * w as usize))
                .zip(vis.par_chunks(k * w as usize))
                .zip(once.centred.par_chunks_mut(pw))
                .zip(once.centre.par_chunks_mut(pw))
                .zip(once.soft.par_chunks(pw))
                .for_each(|((((((col, shad), pts), vis), marks), centre), soft)| {
                    let sw = k * pw;
                    for px in 0..pw {
                        if let (true, Some(p)) = (marks[px], soft[px]) {
                            let v = vis[px * k];
                            let same = (0..k).all(|j| vis[j * sw + px * k..][..k].iter().all(|&u| u == v));
                            if same {
                                add(&mut centre[px], v, p.term);
                                continue;
                            }
                            // Its samples see the lamp differently: each takes its own.
                            crate::opaque::expand(&mut marks[px], centre[px], k, sw, px, col, shad);
                            for j in 0..k {
                                for i in j * sw + px * k..j * sw + px * k + k {
                                    add(&mut col[i], vis[i], p.term);
                                }
                            }
                            continue;
                        }
                        for j in 0..k {
                            for i in j * sw + px * k..j * sw + px * k + k {
                                if let Some(p) = pts[i] {
                                    add(&mut col[i], vis[i], p.term);
                                }
                            }
                        }
                    }
                });
            vis
        }
        resolve => {
            let vis = soft::visibility(frame, light, &input, resolve);
            opaque.color.par_iter_mut().zip(&input.points).zip(&vis).for_each(|((c, p), &v)| {
                if let Some(p) = p {
                    add(c, v, p.term);
                }
            });
            vis
        }
    };
    opaque.soft = input.points;
    opaque.visibility = vis;
    edges::close_outlines(frame, &setup.basis, 0, opaque);
    0
}
