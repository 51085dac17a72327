//! The wave pass: each pixel's energy integrals, clipped at the visible surface (002 §3.3.5), and
//! the colour mapping.

use hadou_math::curve::{self, PreparedCurve};
use hadou_math::energy::lanes::{self, RayLanes, LANES, V3};
use hadou_math::energy::{self, Falloff, FieldParams, Ray};
use hadou_math::shade;
use hadou_math::simd::{dispatch, Lane, SimdPath, WithLanes};
use hadou_math::Vec3;
use hadou_scene::{CameraBasis, Frame, ToneMode, Wave, WaveShape};

/// Per-frame preparation of the curved waves (piece tables, bounds), one entry per wave, `None`
/// for analytic waves.
pub(crate) fn prepare_curves(frame: &Frame) -> Vec<Option<PreparedCurve>> {
    frame.waves.iter().map(|w| w.shape.curve().map(curve::prepare)).collect()
}

/// Integrand evaluations one analytic wave counts per pixel (closed-form pieces).
fn analytic_evaluations(shape: &WaveShape) -> u32 {
    match shape {
        WaveShape::Sphere(_) | WaveShape::Cylinder(_) => 1,
        WaveShape::Capsule(_) => 3,
        WaveShape::Beam(_) => 5,
        WaveShape::Curve(_) => 0,
    }
}

/// The wave pass's per-frame set-up: the camera, the curves' piece tables, which ray kinds the
/// waves need, each wave's `rgb·a`, and the vector path its lanes run on.
pub(crate) struct WavePass<'a> {
    frame: &'a Frame,
    basis: &'a CameraBasis,
    curves: &'a [Option<PreparedCurve>],
    faithful: bool,
    inverse_square: bool,
    colors: Vec<[f32; 3]>,
    simd: SimdPath,
}

/// The rays of [`LANES`] neighbouring pixels of one row, built once per pixel and shared by
/// every wave, with the arithmetic of [`CameraBasis::pixel_dir`] and [`CameraBasis::wave_ray`]
/// lane for lane: the faithful ray `Q = E − S` over `[0, g]`, `g = min(d/|E − S|, 1)`, and the
/// inverse-square unit ray over `[0, d]` (`d = ∞` where nothing is drawn).
struct PixelRays<L> {
    faithful: RayLanes<L>,
    inverse_square: RayLanes<L>,
    /// `|E − S|` per pixel (the inverse-square ray's far parameter, for attenuation).
    far_dist: L,
    /// The eye distance of the visible surface, or of the far plane.
    depth: L,
}

/// One batch of [`LANES`] pixels after the wave pass: their light `Σ rgb·a·I` per channel, total
/// energy and depth.
#[derive(Clone, Copy)]
pub(crate) struct BatchLight {
    light: [[f32; LANES]; 3],
    total: [f32; LANES],
    depth: [f32; LANES],
}

impl BatchLight {
    /// Replaces lane `i`'s light, total energy and depth (an anti-aliased pixel whose samples
    /// see different surfaces, integrated sample by sample: [`WavePass::samples_light`]).
    pub(crate) fn set_lane(&mut self, i: usize, light: [f32; 3], total: f32, depth: f32) {
        for (l, v) in self.light.iter_mut().zip(light) {
            l[i] = v;
        }
        self.total[i] = total;
        self.depth[i] = depth;
    }
}

/// Where the colour stage writes a row: the float colour, energy and depth (EXR, the viewer,
/// probes), or only the 8-bit sRGB triples a PNG needs.
pub(crate) enum RowOut<'a> {
    /// Mapped linear RGBA, total energy, depth.
    Float { color: &'a mut [[f32; 4]], energy: &'a mut [f32], depth: &'a mut [f32] },
    /// Packed 8-bit sRGB `R, G, B` of the mapped colour (`3 × width` bytes).
    Srgb8(&'a mut [u8]),
}

impl<'a> WavePass<'a> {
    pub(crate) fn new(frame: &'a Frame, basis: &'a CameraBasis, curves: &'a [Option<PreparedCurve>]) -> Self {
        let uses = |f: Falloff| frame.waves.iter().any(|w| w.falloff == f);
        let colors = frame
            .waves
            .iter()
            .map(|w| {
                let [r, g, b, a] = w.color;
                [r * a, g * a, b * a]
            })
            .collect();
        Self {
            frame,
            basis,
            curves,
            faithful: uses(Falloff::Faithful),
            inverse_square: uses(Falloff::InverseSquare),
            colors,
            simd: SimdPath::current(),
        }
    }

    /// The same pass on the vector path `simd` (benchmarks and tests compare the paths).
    pub(crate) fn on_path(self, simd: SimdPath) -> Self {
        Self { simd, ..self }
    }

    /// The width in pixels of the frame this pass's rays go through.
    pub(crate) fn width(&self) -> usize {
        self.frame.width as usize
    }

    /// The rays of pixels `x0 .. x0 + LANES` of row `py`; `surface[i]` is pixel `x0 + i`'s
    /// visible-surface distance (`+∞` for none, and for lanes past the row's end).
    #[inline(always)]
    fn rays<L: Lane>(&self, x0: usize, py: f32, surface: L) -> PixelRays<L> {
        let b = self.basis;
        let k = L::splat;
        let (w, h) = (self.frame.width as f32, self.frame.height as f32);
        let far = k(self.frame.camera.far);
        let px = L::from_array(std::array::from_fn(|i| (x0 + i) as f32));
        // CameraBasis::pixel_dir, lane for lane.
        let ndc_x = k(2.0) * (px + k(0.5)) / k(w) - k(1.0);
        let ndc_y = 1.0 - 2.0 * (py + 0.5) / h;
        let sx = ndc_x * k(b.tan_half_fov) * k(b.aspect);
        let sy = k(ndc_y * b.tan_half_fov);
        let dir = V3 {
            x: k(b.forward.x) + k(b.right.x) * sx + k(b.up.x) * sy,
            y: k(b.forward.y) + k(b.right.y) * sx + k(b.up.y) * sy,
            z: k(b.forward.z) + k(b.right.z) * sx + k(b.up.z) * sy,
        };
        let len = (dir.x * dir.x + dir.y * dir.y + dir.z * dir.z).sqrt();
        let far_dist = far * len;
        let drawn = surface.simd_lt(k(f32::INFINITY));
        let zero = k(0.0);
        let none = RayLanes { origin: b.eye, dir: V3::splat(Vec3::ZERO), t0: zero, t1: zero };
        let faithful = if self.faithful {
            let dir = V3 { x: dir.x * far, y: dir.y * far, z: dir.z * far };
            // min(d/|E − S|, 1), and 1 where nothing is drawn (∞/|E − S| = ∞).
            RayLanes { origin: b.eye, dir, t0: zero, t1: (surface / far_dist).min(k(1.0)) }
        } else {
            none
        };
        let inverse_square = if self.inverse_square {
            let dir = V3 { x: dir.x / len, y: dir.y / len, z: dir.z / len };
            RayLanes { origin: b.eye, dir, t0: zero, t1: surface }
        } else {
            none
        };
        PixelRays { faithful, inverse_square, far_dist, depth: drawn.select(surface, far_dist) }
    }

    /// Every wave's energy along the rays of pixels `x0 .. x0 + LANES` of row `py`, clipped at
    /// the visible surfaces `surface` (002 §3.3.5; `+∞` where nothing is drawn), saturated
    /// ([`lanes::saturate`]); `sink.wave(wave index, energies, evaluations)` is called once per
    /// wave in scene order. `valid` lanes (from the first) are real pixels; curves skip the others.
    /// Returns each pixel's depth.
    #[inline(always)]
    pub(crate) fn energies<L: Lane>(
        &self,
        x0: usize,
        py: f32,
        surface: L,
        valid: usize,
        sink: &mut impl WaveSink<L>,
    ) -> L {
        let rays = self.rays(x0, py, surface);
        for (wi, wave) in self.frame.waves.iter().enumerate() {
            let p = FieldParams { falloff: wave.falloff, core_radius: wave.core_radius };
            let ray = match wave.falloff {
                Falloff::Faithful => &rays.faithful,
                Falloff::InverseSquare => &rays.inverse_square,
            };
            if wave.attenuation > 0.0 && wave.shape.curve().is_none() {
                let e = attenuated_lanes(wave, &p, ray, &rays, valid);
                sink.wave(wi, lanes::saturate(e), [analytic_evaluations(&wave.shape); LANES]);
                continue;
            }
            let e = match &wave.shape {
                WaveShape::Sphere(f) => lanes::sphere_energy(&p, ray, f),
                WaveShape::Cylinder(f) => lanes::cylinder_energy(&p, ray, f),
                WaveShape::Capsule(f) => lanes::capsule_energy(&p, ray, f),
                WaveShape::Beam(f) => lanes::beam_energy(&p, ray, f),
                WaveShape::Curve(c) => {
                    let (e, n) = self.curve_lanes::<L>(wi, c, &p, &Rays::of(ray, &rays), valid);
                    // Saturated at f32::MAX (hadou_math::energy::saturate): an overflow is full
                    // brightness, not 0.
                    sink.wave(wi, lanes::saturate(L::from_array(e)), n);
                    continue;
                }
            };
            sink.wave(wi, lanes::saturate(e), [analytic_evaluations(&wave.shape); LANES]);
        }
        rays.depth
    }

    /// A curved wave's energy through the batch's `valid` pixels: the default integrator walks
    /// the piece table with the eight rays as one packet (`curve::curve_energy_lanes`), the
    /// other integrators one pixel at a time (their work adapts per ray).
    #[inline(always)]
    fn curve_lanes<L: Lane>(
        &self,
        wi: usize,
        c: &curve::CurveWave,
        p: &FieldParams<f32>,
        ray: &Rays,
        valid: usize,
    ) -> ([f32; LANES], [u32; LANES]) {
        let owned;
        let prep = match &self.curves[wi] {
            Some(p) => p,
            None => {
                owned = curve::prepare(c);
                &owned
            }
        };
        let n = valid.min(LANES);
        let rays: [Ray<f32>; LANES] = std::array::from_fn(|i| Ray {
            origin: ray.origin,
            dir: Vec3::new(ray.dir[0][i], ray.dir[1][i], ray.dir[2][i]),
        });
        let t_far: [f32; LANES] = match p.falloff {
            Falloff::Faithful => [1.0; LANES],
            Falloff::InverseSquare => ray.far,
        };
        let s = curve::curve_energy_lanes::<L>(prep, p, &rays[..n], &ray.t0[..n], &ray.t1[..n], &t_far[..n]);
        (s.map(|s| s.energy), s.map(|s| s.evaluations))
    }

    /// Each wave's energy and evaluation count at pixel `x` of row `py` (in the first lane, as
    /// the row's batch starting there would give it), clipped at `surface`, and the pixel's depth.
    pub(crate) fn pixel_energies(&self, x: usize, py: f32, surface: Option<f32>) -> (Vec<(f32, u32)>, f32) {
        dispatch(self.simd, PixelEnergies { pass: self, x, py, surface: surface.unwrap_or(f32::INFINITY) })
    }

    /// The wave pass over one row, clipped at the visible surfaces `surface` (`+∞` where nothing
    /// is drawn): `out[k]` gets batch `k`'s light (pixels `8k ..`).
    pub(crate) fn row_light(&self, py: f32, surface: &[f32], out: &mut Vec<BatchLight>) {
        dispatch(self.simd, RowLight { pass: self, py, surface, out });
    }

    /// [`WavePass::row_light`] on lanes `L`.
    #[inline(always)]
    fn row_light_lanes<L: Lane>(&self, py: f32, surface: &[f32], out: &mut Vec<BatchLight>) {
        out.clear();
        for x0 in (0..surface.len()).step_by(LANES) {
            let n = LANES.min(surface.len() - x0);
            let s =
                L::from_array(std::array::from_fn(|i| if i < n { surface[x0 + i] } else { f32::INFINITY }));
            let mut acc = LightSum { colors: &self.colors, light: [L::splat(0.0); 3], total: L::splat(0.0) };
            let depth = self.energies(x0, py, s, n, &mut acc);
            let [r, g, b] = acc.light;
            out.push(BatchLight {
                light: [r.to_array(), g.to_array(), b.to_array()],
                total: acc.total.to_array(),
                depth: depth.to_array(),
            });
        }
    }

    /// The waves' light through `surface.len()` (≤ [`LANES`]) neighbouring pixels of row `py`
    /// starting at `x0`, clipped at their surfaces, each pixel weighted by `weight`: the weighted
    /// sums over those pixels of `Σ rgb·a·I` per channel and of the total energy (saturated), and
    /// their least depth. The anti-aliased pass calls it on the sample frame's pixels (the samples
    /// of one pixel, a row of them at a time, `weight = 1/samples`).
    pub(crate) fn samples_light(
        &self,
        x0: usize,
        py: f32,
        surface: &[f32],
        weight: f32,
    ) -> ([f32; 3], f32, f32) {
        dispatch(self.simd, SamplesLight { pass: self, x0, py, surface, weight })
    }

    /// [`WavePass::samples_light`] on lanes `L`.
    #[inline(always)]
    fn samples_light_lanes<L: Lane>(
        &self,
        x0: usize,
        py: f32,
        surface: &[f32],
        weight: f32,
    ) -> ([f32; 3], f32, f32) {
        let n = surface.len().min(LANES);
        let s = L::from_array(std::array::from_fn(|i| {
            surface.get(i).filter(|_| i < n).copied().unwrap_or(f32::INFINITY)
        }));
        let mut acc = WeightedSum { colors: &self.colors, n, weight, light: [0.0; 3], total: 0.0 };
        let depth = self.energies(x0, py, s, n, &mut acc);
        let depth = depth.to_array()[..n].iter().copied().fold(f32::INFINITY, f32::min);
        (acc.light, acc.total, depth)
    }

    /// The linear colour `scene + exposure·light` of one row (before the colour mapping) into
    /// `linear`; the energy and depth alongside.
    pub(crate) fn row_linear(
        &self,
        batches: &[BatchLight],
        scene: &[[f32; 3]],
        linear: &mut [[f32; 3]],
        energy: &mut [f32],
        depth: &mut [f32],
    ) {
        let k = self.frame.color_mapping.exposure;
        for (bi, b) in batches.iter().enumerate() {
            let x0 = bi * LANES;
            let n = LANES.min(scene.len() - x0);
            for i in 0..n {
                let sc = scene[x0 + i];
                linear[x0 + i] = [0, 1, 2].map(|c| sc[c] + k * b.light[c][i]);
                energy[x0 + i] = b.total[i];
                depth[x0 + i] = b.depth[i];
            }
        }
    }

    /// The colour stage over one row: `scene + exposure·light`, mapped, into `out` (the float
    /// colour with the energy and depth alongside, or 8-bit sRGB only).
    pub(crate) fn row_color(&self, batches: &[BatchLight], scene: &[[f32; 3]], out: RowOut<'_>) {
        dispatch(self.simd, RowColor { pass: self, batches, scene, out });
    }

    /// [`WavePass::row_color`] on lanes `L`.
    #[inline(always)]
    fn row_color_lanes<L: Lane>(&self, batches: &[BatchLight], scene: &[[f32; 3]], mut out: RowOut<'_>) {
        let k = L::splat(self.frame.color_mapping.exposure);
        let mode = self.frame.color_mapping.mode;
        let srgb = shade::srgb8_encoder();
        for (bi, b) in batches.iter().enumerate() {
            let x0 = bi * LANES;
            let n = LANES.min(scene.len() - x0);
            // The scene's channels as lanes (zeros past the row's end); no closures over lanes
            // here (see `hadou_math::simd::Lane`).
            let mut sc = [[0.0f32; LANES]; 3];
            for (i, p) in scene[x0..x0 + n].iter().enumerate() {
                sc[0][i] = p[0];
                sc[1][i] = p[1];
                sc[2][i] = p[2];
            }
            let c = [
                L::from_array(sc[0]) + k * L::from_array(b.light[0]),
                L::from_array(sc[1]) + k * L::from_array(b.light[1]),
                L::from_array(sc[2]) + k * L::from_array(b.light[2]),
            ];
            let m = match mode {
                ToneMode::Faithful => shade::map_faithful_lanes(c),
                ToneMode::Filmic => shade::map_filmic_lanes(c),
            };
            let (r, g, bl) = (m[0].to_array(), m[1].to_array(), m[2].to_array());
            match &mut out {
                RowOut::Float { color, energy, depth } => {
                    for i in 0..n {
                        color[x0 + i] = [r[i], g[i], bl[i], 1.0];
                        energy[x0 + i] = b.total[i];
                        depth[x0 + i] = b.depth[i];
                    }
                }
                RowOut::Srgb8(bytes) => {
                    for (i, o) in bytes[3 * x0..3 * (x0 + n)].chunks_exact_mut(3).enumerate() {
                        o[0] = srgb.code(r[i]);
                        o[1] = srgb.code(g[i]);
                        o[2] = srgb.code(bl[i]);
                    }
                }
            }
        }
    }
}

/// An analytic wave's energy with the distance attenuation `(1 − u)^j`, `j > 0` (002 eq. 3.23,
/// SPEC.md §1.4), eight pixels at a time (`hadou_math::energy::lanes::*_attenuated`, the graded
/// march with each lane's own cells). `t_far` is 1 (faithful) or each pixel's far-point distance
/// (inverse square), as for curves. Lanes past `valid` get an empty span: 0, and no cells.
#[inline(always)]
fn attenuated_lanes<L: Lane>(
    wave: &Wave,
    p: &FieldParams<f32>,
    ray: &RayLanes<L>,
    rays: &PixelRays<L>,
    valid: usize,
) -> L {
    let att = lanes::AttenuationLanes::new(
        wave.attenuation,
        match p.falloff {
            Falloff::Faithful => L::splat(1.0),
            Falloff::InverseSquare => rays.far_dist,
        },
    );
    let mut ray = *ray;
    if valid < LANES {
        let lane = L::from_array(std::array::from_fn(|i| i as f32));
        ray.t1 = lane.simd_lt(L::splat(valid as f32)).select(ray.t1, ray.t0);
    }
    match &wave.shape {
        WaveShape::Sphere(f) => lanes::sphere_energy_attenuated(p, &ray, &att, f),
        WaveShape::Cylinder(f) => lanes::cylinder_energy_attenuated(p, &ray, &att, f),
        WaveShape::Capsule(f) => lanes::capsule_energy_attenuated(p, &ray, &att, f),
        WaveShape::Beam(f) => lanes::beam_energy_attenuated(p, &ray, &att, f),
        WaveShape::Curve(_) => L::splat(0.0),
    }
}

/// What [`WavePass::energies`] hands each wave's energies to. A trait with `#[inline(always)]`
/// methods rather than a closure: a closure called from several places may be compiled apart from
/// the dispatched body, where its lane operations could not inline.
pub(crate) trait WaveSink<L> {
    /// Wave `wi`'s saturated energies and evaluation counts for the batch.
    fn wave(&mut self, wi: usize, e: L, n: [u32; LANES]);
}

/// `Σ rgb·a·I` per channel and the saturated total energy, per lane.
struct LightSum<'c, L> {
    colors: &'c [[f32; 3]],
    light: [L; 3],
    total: L,
}

impl<L: Lane> WaveSink<L> for LightSum<'_, L> {
    #[inline(always)]
    fn wave(&mut self, wi: usize, e: L, _: [u32; LANES]) {
        let c = &self.colors[wi];
        self.light[0] += L::splat(c[0]) * e;
        self.light[1] += L::splat(c[1]) * e;
        self.light[2] += L::splat(c[2]) * e;
        self.total = lanes::saturate(self.total + e);
    }
}

/// The first `n` lanes' light and energy, each weighted by `weight`, summed over the lanes.
struct WeightedSum<'c> {
    colors: &'c [[f32; 3]],
    n: usize,
    weight: f32,
    light: [f32; 3],
    total: f32,
}

impl<L: Lane> WaveSink<L> for WeightedSum<'_> {
    #[inline(always)]
    fn wave(&mut self, wi: usize, e: L, _: [u32; LANES]) {
        let e = e.to_array();
        let c = &self.colors[wi];
        for (ch, l) in self.light.iter_mut().enumerate() {
            let k = c[ch] * self.weight;
            *l += e[..self.n].iter().map(|&v| k * v).sum::<f32>();
        }
        self.total = energy::saturate(self.total + e[..self.n].iter().map(|&v| self.weight * v).sum::<f32>());
    }
}

/// Each wave's first-lane energy and evaluation count.
struct FirstLane(Vec<(f32, u32)>);

impl<L: Lane> WaveSink<L> for FirstLane {
    #[inline(always)]
    fn wave(&mut self, _: usize, e: L, n: [u32; LANES]) {
        self.0.push((e.to_array()[0], n[0]));
    }
}

/// One kind of ray of a batch as plain arrays, for the integrators that work one ray at a time.
struct Rays {
    origin: Vec3<f32>,
    dir: [[f32; LANES]; 3],
    t0: [f32; LANES],
    t1: [f32; LANES],
    far: [f32; LANES],
}

impl Rays {
    #[inline(always)]
    fn of<L: Lane>(ray: &RayLanes<L>, rays: &PixelRays<L>) -> Self {
        Rays {
            origin: ray.origin,
            dir: [ray.dir.x.to_array(), ray.dir.y.to_array(), ray.dir.z.to_array()],
            t0: ray.t0.to_array(),
            t1: ray.t1.to_array(),
            far: rays.far_dist.to_array(),
        }
    }
}

/// [`WavePass::row_light`]'s body for [`dispatch`].
struct RowLight<'p, 'a> {
    pass: &'p WavePass<'a>,
    py: f32,
    surface: &'p [f32],
    out: &'p mut Vec<BatchLight>,
}

impl WithLanes for RowLight<'_, '_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        self.pass.row_light_lanes::<L>(self.py, self.surface, self.out)
    }
}

/// [`WavePass::pixel_energies`]'s body for [`dispatch`].
struct PixelEnergies<'p, 'a> {
    pass: &'p WavePass<'a>,
    x: usize,
    py: f32,
    surface: f32,
}

impl WithLanes for PixelEnergies<'_, '_> {
    type Output = (Vec<(f32, u32)>, f32);
    #[inline(always)]
    fn run<L: Lane>(self) -> Self::Output {
        let mut out = FirstLane(Vec::new());
        let depth = self.pass.energies(self.x, self.py, L::splat(self.surface), 1, &mut out);
        (out.0, depth.to_array()[0])
    }
}

/// [`WavePass::samples_light`]'s body for [`dispatch`].
struct SamplesLight<'p, 'a> {
    pass: &'p WavePass<'a>,
    x0: usize,
    py: f32,
    surface: &'p [f32],
    weight: f32,
}

impl WithLanes for SamplesLight<'_, '_> {
    type Output = ([f32; 3], f32, f32);
    #[inline(always)]
    fn run<L: Lane>(self) -> Self::Output {
        self.pass.samples_light_lanes::<L>(self.x0, self.py, self.surface, self.weight)
    }
}

/// [`WavePass::row_color`]'s body for [`dispatch`].
struct RowColor<'p, 'a> {
    pass: &'p WavePass<'a>,
    batches: &'p [BatchLight],
    scene: &'p [[f32; 3]],
    out: RowOut<'p>,
}

impl WithLanes for RowColor<'_, '_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        self.pass.row_color_lanes::<L>(self.batches, self.scene, self.out)
    }
}

/// Final linear RGBA of a pixel: `scene + exposure · Σ rgb·a·I`, then the frame's mapping.
#[inline]
pub(crate) fn compose(frame: &Frame, scene_rgb: [f32; 3], wave_rgb: [f32; 3]) -> [f32; 4] {
    let k = frame.color_mapping.exposure;
    let c = [0, 1, 2].map(|i| scene_rgb[i] + k * wave_rgb[i]);
    let m = match frame.color_mapping.mode {
        ToneMode::Faithful => shade::map_faithful(c),
        ToneMode::Filmic => shade::map_filmic(c),
    };
    [m[0], m[1], m[2], 1.0]
}

/// Adds one wave's light `rgb · a · I` to `acc`.
#[inline(always)]
pub(crate) fn accumulate(acc: &mut [f32; 3], wave: &Wave, e: f32) {
    let [r, g, b, a] = wave.color;
    acc[0] += r * a * e;
    acc[1] += g * a * e;
    acc[2] += b * a * e;
}
