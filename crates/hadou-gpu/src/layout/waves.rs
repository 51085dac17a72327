//! The wave records: analytic waves (`GpuWave`), prepared curves (`GpuCurve`, `CurveBuffers`) and
//! their codes (wave kinds, curve shapes, integrators, falloffs).

use bytemuck::{Pod, Zeroable};
use hadou_math::curve::{self, CurveShape, Integrator, PreparedCurve, DEFAULT_SETTINGS};
use hadou_math::energy::Falloff;
use hadou_math::Vec3f;
use hadou_scene::{Frame, Wave, WaveShape};

/// `GpuWave::kind` of a sphere field. Keep in sync with `WAVE_SPHERE` in common.wgsl.
pub const WAVE_SPHERE: u32 = 0;
/// `GpuWave::kind` of an infinite cylinder field. Keep in sync with `WAVE_CYLINDER`.
pub const WAVE_CYLINDER: u32 = 1;
/// `GpuWave::kind` of a capsule field. Keep in sync with `WAVE_CAPSULE`.
pub const WAVE_CAPSULE: u32 = 2;
/// `GpuWave::kind` of a bulged beam. Keep in sync with `WAVE_BEAM`.
pub const WAVE_BEAM: u32 = 3;
/// `GpuWave::kind` of a curved wave. Keep in sync with `WAVE_CURVE`.
pub const WAVE_CURVE: u32 = 4;
/// `GpuCurve::integrator` of [`Integrator::Default`]. Keep in sync with `INTEGRATOR_DEFAULT`.
pub const INTEGRATOR_DEFAULT: u32 = 0;
/// `GpuCurve::integrator` of [`Integrator::Simpson`]. Keep in sync with `INTEGRATOR_SIMPSON`.
pub const INTEGRATOR_SIMPSON: u32 = 1;
/// `GpuCurve::integrator` of [`Integrator::Nearest`]. Keep in sync with `INTEGRATOR_NEAREST`.
pub const INTEGRATOR_NEAREST: u32 = 2;
/// `GpuCurve::shape` of [`CurveShape::Helix`]. Keep in sync with `SHAPE_HELIX`.
pub const SHAPE_HELIX: u32 = 0;
/// `GpuCurve::shape` of [`CurveShape::TrigSum`]. Keep in sync with `SHAPE_TRIG`.
pub const SHAPE_TRIG: u32 = 1;
/// `GpuCurve::shape` of [`CurveShape::Bezier`]. Keep in sync with `SHAPE_BEZIER`.
pub const SHAPE_BEZIER: u32 = 2;
/// `GpuCurve::shape` of [`CurveShape::BSpline`]. Keep in sync with `SHAPE_BSPLINE`.
pub const SHAPE_BSPLINE: u32 = 3;
/// `GpuWave::falloff` of [`Falloff::Faithful`]. Keep in sync with `FALLOFF_FAITHFUL`.
pub const FALLOFF_FAITHFUL: u32 = 0;
/// `GpuWave::falloff` of [`Falloff::InverseSquare`]. Keep in sync with `FALLOFF_INVERSE_SQUARE`.
pub const FALLOFF_INVERSE_SQUARE: u32 = 1;

/// One analytic wave. Keep in sync with `GpuWave` in common.wgsl.
///
/// | kind | `p0` | `p1` | `p2` |
/// |---|---|---|---|
/// | sphere | centre `M`, `α_s` | — | — |
/// | cylinder | point `M`, `α_c` | unit axis `D`, — | — |
/// | capsule | `M`, `α_s` | `D`, `α_c` | `length`, —, — |
/// | beam | `M`, `α_s` | `D`, `α_c` | `length`, `head_alpha`, `muzzle_alpha` |
/// | curve | index into [`CurveBuffers::curves`], —, —, — | — | — |
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuWave {
    /// Base colour `(r, g, b, a)`.
    pub color: [f32; 4],
    /// One of the `WAVE_*` codes.
    pub kind: u32,
    /// [`FALLOFF_FAITHFUL`] or [`FALLOFF_INVERSE_SQUARE`].
    pub falloff: u32,
    /// Core radius `r_c`.
    pub core_radius: f32,
    /// Exponent `j` of the distance attenuation `(1 − u)^j` of an analytic wave (002 eq. 3.23,
    /// SPEC.md §1.4; 0: none). A curve's is in its [`GpuCurve`]; here it is 0.
    pub attenuation: f32,
    /// See the table above.
    pub p0: [f32; 4],
    /// See the table above.
    pub p1: [f32; 4],
    /// See the table above.
    pub p2: [f32; 4],
}

pub(super) fn v4(v: Vec3f, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

impl GpuWave {
    /// The GPU form of an analytic wave, or `None` for a curved wave (see [`GpuWave::curve`]).
    pub fn new(wave: &Wave) -> Option<Self> {
        let mut g = Self {
            color: wave.color,
            kind: 0,
            falloff: match wave.falloff {
                Falloff::Faithful => FALLOFF_FAITHFUL,
                Falloff::InverseSquare => FALLOFF_INVERSE_SQUARE,
            },
            core_radius: wave.core_radius,
            attenuation: wave.attenuation,
            p0: [0.0; 4],
            p1: [0.0; 4],
            p2: [0.0; 4],
        };
        match &wave.shape {
            WaveShape::Sphere(s) => {
                g.kind = WAVE_SPHERE;
                g.p0 = v4(s.center, s.alpha);
            }
            WaveShape::Cylinder(c) => {
                g.kind = WAVE_CYLINDER;
                g.p0 = v4(c.point, c.alpha);
                g.p1 = v4(c.dir, 0.0);
            }
            WaveShape::Capsule(c) => {
                g.kind = WAVE_CAPSULE;
                g.p0 = v4(c.m, c.alpha_s);
                g.p1 = v4(c.d, c.alpha_c);
                g.p2 = [c.length, 0.0, 0.0, 0.0];
            }
            WaveShape::Beam(b) => {
                let c = &b.capsule;
                g.kind = WAVE_BEAM;
                g.p0 = v4(c.m, c.alpha_s);
                g.p1 = v4(c.d, c.alpha_c);
                g.p2 = [c.length, b.head_alpha, b.muzzle_alpha, 0.0];
            }
            WaveShape::Curve(_) => return None,
        }
        Some(g)
    }

    /// The GPU form of a curved wave whose data is entry `index` of [`CurveBuffers::curves`]
    /// (colour, falloff and core radius from `wave`).
    pub fn curve(wave: &Wave, index: u32) -> Self {
        Self {
            color: wave.color,
            kind: WAVE_CURVE,
            falloff: match wave.falloff {
                Falloff::Faithful => FALLOFF_FAITHFUL,
                Falloff::InverseSquare => FALLOFF_INVERSE_SQUARE,
            },
            core_radius: wave.core_radius,
            attenuation: 0.0,
            // Indices below 2^24 are exact in f32; `CurveBuffers::push` keeps them there.
            p0: [index as f32, 0.0, 0.0, 0.0],
            p1: [0.0; 4],
            p2: [0.0; 4],
        }
    }
}

/// One prepared curved wave ([`PreparedCurve`]) as the GPU reads it: frame, integrator settings,
/// shape parameters and the offsets of its data in [`CurveBuffers`]. Keep in sync with
/// `GpuCurve` in common.wgsl; curve.wgsl reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuCurve {
    /// Launch point `O` ([`PreparedCurve::frame_axes`]).
    pub origin: [f32; 3],
    /// Strength `α`.
    pub alpha: f32,
    /// Unit travel axis `D`.
    pub axis_d: [f32; 3],
    /// Axial length `X = γ·k·s_end`.
    pub x_head: f32,
    /// Cross-section axis `ŷ`.
    pub axis_y: [f32; 3],
    /// Attenuation exponent `j`.
    pub attenuation: f32,
    /// Cross-section axis `ẑ`.
    pub axis_z: [f32; 3],
    /// Axial stretch `γ`.
    pub gamma: f32,
    /// Head parameter `k·s_end`.
    pub s_head: f32,
    /// Smallest core radius ([`PreparedCurve::effective_core_radius`] of 0).
    pub core_floor: f32,
    /// Simpson reduction cylinder radius `R + ε`.
    pub cylinder_radius: f32,
    /// [`INTEGRATOR_DEFAULT`], [`INTEGRATOR_SIMPSON`] or [`INTEGRATOR_NEAREST`].
    pub integrator: u32,
    /// Simpson subintervals `m` (clamped, even).
    pub m: u32,
    /// Simpson subintervals outside the cylinder (`simpson::reduced_m`).
    pub m_reduced: u32,
    /// 1 when the Simpson reduction is on.
    pub reduce: u32,
    /// One of the `SHAPE_*` codes.
    pub shape: u32,
    /// B-spline order `k`.
    pub order: u32,
    /// Offset of the control points (or trig terms) in `CurveBuffers::scalars`, as `(y, z)` pairs.
    pub points: u32,
    /// Number of control points.
    pub point_count: u32,
    /// Offset of the B-spline knots in `CurveBuffers::scalars`.
    pub knots: u32,
    /// Lower end of the valid knot range.
    pub lo: f32,
    /// Upper end of the valid knot range.
    pub hi: f32,
    /// Helix / trig angular rate `θ`.
    pub rate: f32,
    /// Helix radius.
    pub radius: f32,
    /// Helix phase.
    pub phase: f32,
    /// Number of `y` trig terms (pairs from `points`), followed by the `z` terms.
    pub y_terms: u32,
    /// Number of `z` trig terms.
    pub z_terms: u32,
    /// Offset of `PieceTable::nodes` in `CurveBuffers::vec4s`.
    pub nodes: u32,
    /// Number of nodes `N + 1`.
    pub node_count: u32,
    /// Offset of `PieceTable::lines` in `CurveBuffers::vec4s`.
    pub lines: u32,
    /// Offset of `PieceTable::errors` in `CurveBuffers::scalars`.
    pub errors: u32,
    /// Offset of `PieceTable::level_offsets` (as `u32` bits) in `CurveBuffers::scalars`.
    pub level_offsets: u32,
    /// Number of levels.
    pub levels: u32,
    /// [`DEFAULT_SETTINGS`] tolerance `τ`.
    pub tolerance: f32,
    /// Part ratio `q` of [`curve::attenuation_split`] for this wave's `j` (0.5 when `j = 0`).
    pub att_q: f32,
    /// Attenuation floor `h_floor` of [`curve::attenuation_split`].
    pub att_floor: f32,
    /// [`PreparedCurve::tail_radius`] (the nearest-point field's open end).
    pub tail_radius: f32,
    /// Padding to the struct's 16-byte alignment.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

/// The storage buffers of a frame's curved waves: one [`GpuCurve`] per curve, the piece-table
/// nodes and lines (`vec4s`), and the control points, knots, piece errors and level offsets
/// (`scalars`). Keep in sync with bindings 5–7 of curve.wgsl.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CurveBuffers {
    /// Per-curve headers.
    pub curves: Vec<GpuCurve>,
    /// `PieceTable::nodes` and `PieceTable::lines` of every curve.
    pub vec4s: Vec<[f32; 4]>,
    /// Points, knots, errors and level offsets (bits) of every curve.
    pub scalars: Vec<f32>,
}

fn offset(len: usize) -> Result<u32, String> {
    u32::try_from(len).ok().filter(|&v| v < 1 << 30).ok_or_else(|| "curve data too large".to_string())
}

impl CurveBuffers {
    /// Appends one prepared curve (from [`curve::prepare`]) and returns its index.
    pub fn push(&mut self, prep: &PreparedCurve) -> Result<u32, String> {
        let index = offset(self.curves.len())?;
        if index >= 1 << 24 {
            return Err("too many curved waves".to_string());
        }
        let wave = &prep.wave;
        let (origin, [d, y, z]) = prep.frame_axes();
        let table = prep.table();
        let s_end = match &wave.shape {
            CurveShape::Helix { length, .. } | CurveShape::TrigSum { length, .. } => f64::from(*length),
            CurveShape::Bezier { .. } | CurveShape::BSpline { .. } => 1.0,
        };
        let settings = DEFAULT_SETTINGS;
        let j = f64::from(wave.attenuation);
        let (att_q, att_floor) =
            if j > 0.0 { curve::attenuation_split(j, settings.tolerance) } else { (0.5, 0.0) };
        let mut g = GpuCurve {
            origin: origin.to_array(),
            alpha: wave.alpha,
            axis_d: d.to_array(),
            x_head: prep.axial_length(),
            axis_y: y.to_array(),
            attenuation: wave.attenuation,
            axis_z: z.to_array(),
            gamma: wave.gamma,
            s_head: (f64::from(wave.extension) * s_end) as f32,
            core_floor: prep.effective_core_radius(0.0f32),
            cylinder_radius: prep.bound_radius(),
            integrator: INTEGRATOR_DEFAULT,
            m: 2,
            m_reduced: 2,
            reduce: 0,
            shape: SHAPE_HELIX,
            order: 0,
            points: offset(self.scalars.len())?,
            point_count: 0,
            knots: 0,
            lo: 0.0,
            hi: 1.0,
            rate: 0.0,
            radius: 0.0,
            phase: 0.0,
            y_terms: 0,
            z_terms: 0,
            nodes: 0,
            node_count: 0,
            lines: 0,
            errors: 0,
            level_offsets: 0,
            levels: 0,
            tolerance: settings.tolerance as f32,
            att_q: att_q as f32,
            att_floor: att_floor as f32,
            tail_radius: prep.tail_radius() as f32,
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        };
        if wave.integrator == Integrator::Nearest {
            g.integrator = INTEGRATOR_NEAREST;
        }
        if let Integrator::Simpson { m, reduction } = wave.integrator {
            let m = m.clamp(2, curve::MAX_SIMPSON_M);
            let m = m + (m & 1);
            g.integrator = INTEGRATOR_SIMPSON;
            g.m = m;
            if let Some(red) = reduction {
                g.reduce = 1;
                g.m_reduced = curve::simpson::reduced_m(m, red.n);
                g.cylinder_radius = (f64::from(prep.bound_radius()) + f64::from(red.epsilon)) as f32;
            }
        }
        let pairs = |s: &mut Vec<f32>, p: &[[f32; 2]]| s.extend(p.iter().flatten());
        match &wave.shape {
            CurveShape::Helix { radius, rate, phase, .. } => {
                g.shape = SHAPE_HELIX;
                (g.radius, g.rate, g.phase) = (*radius, *rate, *phase);
            }
            CurveShape::TrigSum { rate, y_terms, z_terms, .. } => {
                g.shape = SHAPE_TRIG;
                g.rate = *rate;
                g.y_terms = offset(y_terms.len())?;
                g.z_terms = offset(z_terms.len())?;
                pairs(&mut self.scalars, y_terms);
                pairs(&mut self.scalars, z_terms);
            }
            CurveShape::Bezier { points } => {
                g.shape = SHAPE_BEZIER;
                g.point_count = offset(points.len())?;
                pairs(&mut self.scalars, points);
            }
            CurveShape::BSpline { points, order, knots } => {
                g.shape = SHAPE_BSPLINE;
                g.order = *order;
                g.point_count = offset(points.len())?;
                pairs(&mut self.scalars, points);
                g.knots = offset(self.scalars.len())?;
                let knots: Vec<f32> = match knots {
                    Some(k) => k.clone(),
                    None => curve::clamped_uniform_knots(points.len(), *order as usize)
                        .into_iter()
                        .map(|k| k as f32)
                        .collect(),
                };
                let n = points.len().saturating_sub(1);
                let k = (*order as usize).max(1);
                g.lo = knots.get(k - 1).copied().unwrap_or(0.0);
                g.hi = knots.get(n + 1).copied().unwrap_or(1.0);
                self.scalars.extend(&knots);
            }
        }
        g.nodes = offset(self.vec4s.len())?;
        g.node_count = offset(table.nodes.len())?;
        self.vec4s.extend(&table.nodes);
        g.lines = offset(self.vec4s.len())?;
        self.vec4s.extend(&table.lines);
        g.errors = offset(self.scalars.len())?;
        self.scalars.extend(&table.errors);
        g.level_offsets = offset(self.scalars.len())?;
        g.levels = offset(table.levels())?;
        self.scalars.extend(table.level_offsets.iter().map(|&o| f32::from_bits(o)));
        offset(self.vec4s.len())?;
        offset(self.scalars.len())?;
        self.curves.push(g);
        Ok(index)
    }
}

/// The wave buffer and the curve buffers of a frame: every curved wave is prepared once
/// ([`curve::prepare`], as the CPU backend does per frame) and appended to the curve buffers.
/// Also returns the prepared curves, one entry per wave (`None` for analytic waves), for
/// [`ShadingBuffers::new`](crate::layout::ShadingBuffers::new).
pub fn frame_waves(frame: &Frame) -> Result<FrameWaves, String> {
    waves_buffers(&frame.waves)
}

/// [`frame_waves`] of a list of waves: what a caller that draws the same waves into several views
/// (hadou-bevy's cameras) or also lights its own materials with them prepares once per frame and
/// hands to [`crate::GpuBackend::encode_prepared_wave_overlay`] and [`wave_lights`](crate::layout::wave_lights).
pub fn waves_buffers(frame_waves: &[hadou_scene::Wave]) -> Result<FrameWaves, String> {
    let mut curves = CurveBuffers::default();
    let mut waves = Vec::with_capacity(frame_waves.len());
    let mut prepared = Vec::with_capacity(frame_waves.len());
    for w in frame_waves {
        match w.shape.curve() {
            Some(c) => {
                let prep = curve::prepare(c);
                let index = curves.push(&prep).map_err(|e| format!("wave `{}`: {e}", w.name))?;
                waves.push(GpuWave::curve(w, index));
                prepared.push(Some(prep));
            }
            None => {
                waves.extend(GpuWave::new(w));
                prepared.push(None);
            }
        }
    }
    Ok((waves, curves, prepared))
}

/// What [`frame_waves`] returns: the wave buffer, the curve buffers, and the prepared curves.
pub type FrameWaves = (Vec<GpuWave>, CurveBuffers, Vec<Option<PreparedCurve>>);
