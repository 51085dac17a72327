//! The wave pass: each pixel's energy integrals, clipped at the visible surface (002 §3.3.5), and
//! the colour mapping.

use hadou_math::curve::{self, PreparedCurve};
use hadou_math::energy::lanes::{self, Lanes, RayLanes, LANES, V3};
use hadou_math::energy::{self, Falloff, FieldParams, Ray};
use hadou_math::shade;
use hadou_math::Vec3;
use hadou_scene::{CameraBasis, Frame, ToneMode, Wave, WaveShape};

/// Per-frame preparation of the curved waves (piece tables, bounds), one entry per wave, `None`
/// for analytic waves.
pub(crate) fn prepare_curves(frame: &Frame) -> Vec<Option<PreparedCurve>> {
    frame
        .waves
        .iter()
        .map(|w| match &w.shape {
            WaveShape::Curve(c) => Some(curve::prepare(c)),
            _ => None,
        })
        .collect()
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
/// waves need and each wave's `rgb·a`.
pub(crate) struct WavePass<'a> {
    frame: &'a Frame,
    basis: &'a CameraBasis,
    curves: &'a [Option<PreparedCurve>],
    faithful: bool,
    inverse_square: bool,
    colors: Vec<[Lanes; 3]>,
}

/// The rays of [`LANES`] neighbouring pixels of one row, built once per pixel and shared by
/// every wave, with the arithmetic of [`CameraBasis::pixel_dir`] and [`CameraBasis::wave_ray`]
/// lane for lane: the faithful ray `Q = E − S` over `[0, g]`, `g = min(d/|E − S|, 1)`, and the
/// inverse-square unit ray over `[0, d]` (`d = ∞` where nothing is drawn).
struct PixelRays {
    faithful: RayLanes,
    inverse_square: RayLanes,
    /// `|E − S|` per pixel (the inverse-square ray's far parameter, for attenuation).
    far_dist: Lanes,
    /// The eye distance of the visible surface, or of the far plane.
    depth: Lanes,
}

/// One batch of [`LANES`] pixels after the wave pass: their light `Σ rgb·a·I` per channel, total
/// energy and depth.
#[derive(Clone, Copy)]
pub(crate) struct BatchLight {
    light: [Lanes; 3],
    total: Lanes,
    depth: Lanes,
}

impl BatchLight {
    /// Replaces lane `i`'s light, total energy and depth (an anti-aliased pixel whose samples
    /// see different surfaces, integrated sample by sample: [`WavePass::samples_light`]).
    pub(crate) fn set_lane(&mut self, i: usize, light: [f32; 3], total: f32, depth: f32) {
        let set = |l: &mut Lanes, v: f32| {
            let mut a = l.to_array();
            a[i] = v;
            *l = Lanes::from(a);
        };
        for (l, v) in self.light.iter_mut().zip(light) {
            set(l, v);
        }
        set(&mut self.total, total);
        set(&mut self.depth, depth);
    }
}

impl<'a> WavePass<'a> {
    pub(crate) fn new(frame: &'a Frame, basis: &'a CameraBasis, curves: &'a [Option<PreparedCurve>]) -> Self {
        let uses = |f: Falloff| frame.waves.iter().any(|w| w.falloff == f);
        let colors = frame
            .waves
            .iter()
            .map(|w| {
                let [r, g, b, a] = w.color;
                [Lanes::splat(r * a), Lanes::splat(g * a), Lanes::splat(b * a)]
            })
            .collect();
        Self {
            frame,
            basis,
            curves,
            faithful: uses(Falloff::Faithful),
            inverse_square: uses(Falloff::InverseSquare),
            colors,
        }
    }

    /// The width in pixels of the frame this pass's rays go through.
    pub(crate) fn width(&self) -> usize {
        self.frame.width as usize
    }

    /// The rays of pixels `x0 .. x0 + LANES` of row `py`; `surface[i]` is pixel `x0 + i`'s
    /// visible-surface distance (`+∞` for none, and for lanes past the row's end).
    #[inline(always)]
    fn rays(&self, x0: usize, py: f32, surface: Lanes) -> PixelRays {
        let b = self.basis;
        let (w, h) = (self.frame.width as f32, self.frame.height as f32);
        let far = Lanes::splat(self.frame.camera.far);
        let px = Lanes::from(std::array::from_fn::<f32, LANES, _>(|i| (x0 + i) as f32));
        // CameraBasis::pixel_dir, lane for lane.
        let ndc_x = Lanes::splat(2.0) * (px + Lanes::splat(0.5)) / Lanes::splat(w) - Lanes::ONE;
        let ndc_y = 1.0 - 2.0 * (py + 0.5) / h;
        let sx = ndc_x * Lanes::splat(b.tan_half_fov) * Lanes::splat(b.aspect);
        let sy = Lanes::splat(ndc_y * b.tan_half_fov);
        let axis = |f: f32, r: f32, u: f32| Lanes::splat(f) + Lanes::splat(r) * sx + Lanes::splat(u) * sy;
        let dir = V3 {
            x: axis(b.forward.x, b.right.x, b.up.x),
            y: axis(b.forward.y, b.right.y, b.up.y),
            z: axis(b.forward.z, b.right.z, b.up.z),
        };
        let len = (dir.x * dir.x + dir.y * dir.y + dir.z * dir.z).sqrt();
        let far_dist = far * len;
        let drawn = surface.simd_lt(Lanes::INFINITY);
        let zero = Lanes::ZERO;
        let none = RayLanes { origin: b.eye, dir: V3::splat(Vec3::ZERO), t0: zero, t1: zero };
        let faithful = if self.faithful {
            let dir = V3 { x: dir.x * far, y: dir.y * far, z: dir.z * far };
            // min(d/|E − S|, 1), and 1 where nothing is drawn (∞/|E − S| = ∞).
            RayLanes { origin: b.eye, dir, t0: zero, t1: (surface / far_dist).min(Lanes::ONE) }
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
    /// ([`lanes::saturate`]); `sink(wave index, energies, evaluations)` is called once per wave
    /// in scene order. `valid` lanes (from the first) are real pixels; curves skip the others.
    /// Returns each pixel's depth.
    #[inline]
    pub(crate) fn energies(
        &self,
        x0: usize,
        py: f32,
        surface: Lanes,
        valid: usize,
        mut sink: impl FnMut(usize, Lanes, [u32; LANES]),
    ) -> Lanes {
        let rays = self.rays(x0, py, surface);
        for (wi, wave) in self.frame.waves.iter().enumerate() {
            let p = FieldParams { falloff: wave.falloff, core_radius: wave.core_radius };
            let ray = match wave.falloff {
                Falloff::Faithful => &rays.faithful,
                Falloff::InverseSquare => &rays.inverse_square,
            };
            if wave.attenuation > 0.0 && !matches!(wave.shape, WaveShape::Curve(_)) {
                let e = self.attenuated_lanes(wave, &p, ray, &rays, valid);
                sink(wi, lanes::saturate(e), [analytic_evaluations(&wave.shape); LANES]);
                continue;
            }
            let e = match &wave.shape {
                WaveShape::Sphere(f) => lanes::sphere_energy(&p, ray, f),
                WaveShape::Cylinder(f) => lanes::cylinder_energy(&p, ray, f),
                WaveShape::Capsule(f) => lanes::capsule_energy(&p, ray, f),
                WaveShape::Beam(f) => lanes::beam_energy(&p, ray, f),
                WaveShape::Curve(c) => {
                    let (e, n) = self.curve_lanes(wi, c, &p, ray, &rays, valid);
                    // Saturated at f32::MAX (hadou_math::energy::saturate): an overflow is full
                    // brightness, not 0.
                    sink(wi, lanes::saturate(e), n);
                    continue;
                }
            };
            sink(wi, lanes::saturate(e), [analytic_evaluations(&wave.shape); LANES]);
        }
        rays.depth
    }

    /// An analytic wave's energy with the distance attenuation `(1 − u)^j`, `j > 0` (002 eq.
    /// 3.23, SPEC.md §1.4), one pixel at a time: the attenuated integrals
    /// (`hadou_math::energy::*_attenuated`) grade their cells per ray and have no eight-lane
    /// form. `t_far` is 1 (faithful) or the far point's distance (inverse square), as for curves.
    fn attenuated_lanes(
        &self,
        wave: &Wave,
        p: &FieldParams<f32>,
        ray: &RayLanes,
        rays: &PixelRays,
        valid: usize,
    ) -> Lanes {
        let (dx, dy, dz) = (ray.dir.x.to_array(), ray.dir.y.to_array(), ray.dir.z.to_array());
        let (t0, t1, far) = (ray.t0.to_array(), ray.t1.to_array(), rays.far_dist.to_array());
        let mut e = [0.0f32; LANES];
        for i in 0..valid {
            let r = Ray { origin: ray.origin, dir: Vec3::new(dx[i], dy[i], dz[i]) };
            let att = wave.attenuation_on(match p.falloff {
                Falloff::Faithful => 1.0,
                Falloff::InverseSquare => far[i],
            });
            e[i] = match &wave.shape {
                WaveShape::Sphere(f) => energy::sphere_energy_attenuated(p, &r, t0[i], t1[i], &att, f),
                WaveShape::Cylinder(f) => energy::cylinder_energy_attenuated(p, &r, t0[i], t1[i], &att, f),
                WaveShape::Capsule(f) => energy::capsule_energy_attenuated(p, &r, t0[i], t1[i], &att, f),
                WaveShape::Beam(f) => energy::beam_energy_attenuated(p, &r, t0[i], t1[i], &att, f),
                WaveShape::Curve(_) => 0.0,
            };
        }
        Lanes::from(e)
    }

    /// A curved wave's energy, one pixel at a time (its integrator adapts per ray).
    fn curve_lanes(
        &self,
        wi: usize,
        c: &curve::CurveWave,
        p: &FieldParams<f32>,
        ray: &RayLanes,
        rays: &PixelRays,
        valid: usize,
    ) -> (Lanes, [u32; LANES]) {
        let owned;
        let prep = match &self.curves[wi] {
            Some(p) => p,
            None => {
                owned = curve::prepare(c);
                &owned
            }
        };
        let (dx, dy, dz) = (ray.dir.x.to_array(), ray.dir.y.to_array(), ray.dir.z.to_array());
        let (t0, t1, far) = (ray.t0.to_array(), ray.t1.to_array(), rays.far_dist.to_array());
        let mut e = [0.0f32; LANES];
        let mut n = [0u32; LANES];
        for i in 0..valid {
            let r = Ray { origin: ray.origin, dir: Vec3::new(dx[i], dy[i], dz[i]) };
            let t_far = match p.falloff {
                Falloff::Faithful => 1.0,
                Falloff::InverseSquare => far[i],
            };
            let s = curve::curve_energy(prep, p, &r, t0[i], t1[i], t_far);
            e[i] = s.energy;
            n[i] = s.evaluations;
        }
        (Lanes::from(e), n)
    }

    /// The wave pass over one row: `out[k]` gets batch `k`'s light (pixels `8k ..`).
    pub(crate) fn row_light(&self, py: f32, surface: &[Option<f32>], out: &mut Vec<BatchLight>) {
        out.clear();
        for x0 in (0..surface.len()).step_by(LANES) {
            let n = LANES.min(surface.len() - x0);
            let s = Lanes::from(std::array::from_fn::<f32, LANES, _>(|i| {
                if i < n {
                    surface[x0 + i].unwrap_or(f32::INFINITY)
                } else {
                    f32::INFINITY
                }
            }));
            let mut light = [Lanes::ZERO; 3];
            let mut total = Lanes::ZERO;
            let depth = self.energies(x0, py, s, n, |wi, e, _| {
                let c = &self.colors[wi];
                light[0] += c[0] * e;
                light[1] += c[1] * e;
                light[2] += c[2] * e;
                total = lanes::saturate(total + e);
            });
            out.push(BatchLight { light, total, depth });
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
        surface: &[Option<f32>],
        weight: f32,
    ) -> ([f32; 3], f32, f32) {
        let n = surface.len().min(LANES);
        let s = Lanes::from(std::array::from_fn::<f32, LANES, _>(|i| {
            surface.get(i).filter(|_| i < n).copied().flatten().unwrap_or(f32::INFINITY)
        }));
        let mut light = [0.0f32; 3];
        let mut total = 0.0f32;
        let depth = self.energies(x0, py, s, n, |wi, e, _| {
            let e = e.to_array();
            let c = &self.colors[wi];
            for (ch, l) in light.iter_mut().enumerate() {
                let k = c[ch].to_array()[0] * weight;
                *l += (0..n).map(|i| k * e[i]).sum::<f32>();
            }
            total = energy::saturate(total + (0..n).map(|i| weight * e[i]).sum::<f32>());
        });
        let depth = depth.to_array()[..n].iter().copied().fold(f32::INFINITY, f32::min);
        (light, total, depth)
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
        let k = Lanes::splat(self.frame.color_mapping.exposure);
        for (bi, b) in batches.iter().enumerate() {
            let x0 = bi * LANES;
            let n = LANES.min(scene.len() - x0);
            let sc = &scene[x0..x0 + n];
            let ch = |c: usize| {
                Lanes::from(std::array::from_fn::<f32, LANES, _>(|i| sc.get(i).map_or(0.0, |p| p[c])))
            };
            let c = [0, 1, 2].map(|i| (ch(i) + k * b.light[i]).to_array());
            let (t, d) = (b.total.to_array(), b.depth.to_array());
            for i in 0..n {
                linear[x0 + i] = [c[0][i], c[1][i], c[2][i]];
                energy[x0 + i] = t[i];
                depth[x0 + i] = d[i];
            }
        }
    }

    /// The colour mapping over one row: `scene + exposure·light`, mapped, into `color`; the
    /// energy and depth alongside.
    pub(crate) fn row_color(
        &self,
        batches: &[BatchLight],
        scene: &[[f32; 3]],
        color: &mut [[f32; 4]],
        energy: &mut [f32],
        depth: &mut [f32],
    ) {
        let k = Lanes::splat(self.frame.color_mapping.exposure);
        let mode = self.frame.color_mapping.mode;
        for (bi, b) in batches.iter().enumerate() {
            let x0 = bi * LANES;
            let n = LANES.min(scene.len() - x0);
            let sc = &scene[x0..x0 + n];
            let ch = |c: usize| {
                Lanes::from(std::array::from_fn::<f32, LANES, _>(|i| sc.get(i).map_or(0.0, |p| p[c])))
            };
            let c = [0, 1, 2].map(|i| ch(i) + k * b.light[i]);
            let m = match mode {
                ToneMode::Faithful => shade::map_faithful_lanes(c),
                ToneMode::Filmic => shade::map_filmic_lanes(c),
            };
            let (r, g, bl) = (m[0].to_array(), m[1].to_array(), m[2].to_array());
            let (t, d) = (b.total.to_array(), b.depth.to_array());
            for i in 0..n {
                color[x0 + i] = [r[i], g[i], bl[i], 1.0];
                energy[x0 + i] = t[i];
                depth[x0 + i] = d[i];
            }
        }
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
