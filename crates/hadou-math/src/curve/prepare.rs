//! The per-frame preparation of a curved wave: frame axes, shape evaluators in both precisions,
//! the bounding cylinder, and the tree of polylines the default integrator walks.

use super::shape::{self, ShapeEval};
use super::validate::{sanitize, CurveError};
use super::wave::{CurveFrame, CurveShape, CurveWave};
use crate::{Real, Vec3};

/// Most leaf pieces of a [`PieceTable`].
pub const MAX_PIECES: usize = 1 << 14;

/// Target deviation of a leaf piece from the curve, relative to the curve's size
/// (`max(R, X/16)`, `R` the bounding radius, `X` the axial length).
pub const LEAF_TOLERANCE: f64 = 2e-5;

/// Distance a curve's light polyline may stray from the curve, relative to the curve's size
/// ([`PreparedCurve::light_polyline`]).
pub const LIGHT_TOLERANCE: f64 = 1e-3;
/// Most points of a curve's light polyline.
pub const MAX_LIGHT_POINTS: usize = 128;

/// Distance from `p` to the segment `a..b`.
fn segment_distance(p: Vec3<f64>, a: Vec3<f64>, b: Vec3<f64>) -> f64 {
    let d = b - a;
    let dd = d.dot(d);
    let t = if dd > 0.0 { ((p - a).dot(d) / dd).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + d * t)).length()
}

/// Smallest core radius used, relative to the curve's size: the `1/r` and `1/r²` densities are
/// singular on the curve, so with `r_c = 0` a ray exactly through it would be infinite. Every
/// integrator and the reference use `max(r_c, MIN_CORE·size)` (see
/// [`PreparedCurve::effective_core_radius`]).
pub const MIN_CORE: f64 = 1e-6;

/// The curve as a binary tree of straight pieces in the axial coordinate `x`, the table the
/// default integrator ([`super::integrate`]) walks per ray and the GPU mirrors.
///
/// # Layout (flat arrays, ready for storage buffers)
/// - `nodes[i] = [x_i, y_i, z_i, s_i]`, `i = 0..=N`: strictly increasing axial coordinates from
///   `x_0 = 0` to `x_N = X = γ·k·s_end`, the exact cross-section point `(y, z) = c_⊥(s_i)` and the
///   curve parameter `s_i = x_i/γ`. Nodes are placed adaptively (bisection until the chord
///   deviates less than [`LEAF_TOLERANCE`]), so the leaves are not uniform.
/// - Level `ℓ = 0..levels` holds `⌈N/2^ℓ⌉` pieces; piece `j` of level `ℓ` spans
///   `[x_a, x_b]`, `a = j·2^ℓ`, `b = min((j+1)·2^ℓ, N)`. Level 0 are the leaves, the last level a
///   single piece over the whole curve.
/// - `lines[level_offsets[ℓ] + j] = [ȳ, z̄, m_y, m_z]`: the piece's straight line
///   `L(x) = (ȳ, z̄) + (x − (x_a + x_b)/2)·(m_y, m_z)`, the least-squares fit of `c_⊥(x/γ)` over
///   `[x_a, x_b]`. Its deviation `c_⊥ − L` has zero mean and zero first moment in `x`, so a
///   field that varies linearly over the piece sees no first-order error from it.
/// - `errors[level_offsets[ℓ] + j]` bounds `max_x |c_⊥(x/γ) − L(x)|` over the piece, the
///   cross-section distance between curve and line at equal `x` (the pairing's error).
/// - `level_offsets` has `levels + 1` entries, the last being `lines.len()`.
#[derive(Clone, Debug, PartialEq)]
pub struct PieceTable {
    /// `[x, y, z, s]` per node; see the type docs.
    pub nodes: Vec<[f32; 4]>,
    /// `[ȳ, z̄, m_y, m_z]` per piece, level after level.
    pub lines: Vec<[f32; 4]>,
    /// Deviation bounds, level after level.
    pub errors: Vec<f32>,
    /// Start of each level in `errors`, plus the total length.
    pub level_offsets: Vec<u32>,
}

impl PieceTable {
    /// Number of leaf pieces `N`.
    pub fn pieces(&self) -> usize {
        self.nodes.len() - 1
    }
    /// Number of levels (`⌈log₂ N⌉ + 1`).
    pub fn levels(&self) -> usize {
        self.level_offsets.len() - 1
    }
    /// The deviation bound of piece `j` of level `level`.
    pub fn error(&self, level: usize, j: usize) -> f32 {
        self.errors[self.level_offsets[level] as usize + j]
    }
    /// The fitted line `[ȳ, z̄, m_y, m_z]` of piece `j` of level `level`.
    pub fn line(&self, level: usize, j: usize) -> [f32; 4] {
        self.lines[self.level_offsets[level] as usize + j]
    }
}

/// A curved wave prepared for per-ray integration (once per frame).
#[derive(Clone, Debug, PartialEq)]
pub struct PreparedCurve {
    /// The wave, with any invalid value replaced by the nearest legal one.
    pub wave: CurveWave,
    /// Launch point `O` (f64).
    pub(crate) origin: Vec3<f64>,
    /// Axes `(D, ŷ, ẑ)` (f64); see [`super::CurveFrame::axes`].
    pub(crate) axes: [Vec3<f64>; 3],
    pub(crate) shape32: ShapeEval<f32>,
    pub(crate) shape64: ShapeEval<f64>,
    /// Head parameter `k·s_end`.
    pub(crate) s_head: f64,
    /// Axial length `X = γ·k·s_end`.
    pub(crate) x_head: f64,
    /// Bounding-cylinder radius `R`.
    pub(crate) bound: f64,
    /// Size used for relative tolerances: `max(R, X/16)`.
    pub(crate) size: f64,
    pub(crate) table: PieceTable,
}

/// [`prepare`] after [`CurveWave::validate`].
pub fn try_prepare(wave: &CurveWave) -> Result<PreparedCurve, CurveError> {
    wave.validate()?;
    Ok(prepare(wave))
}

/// Prepares a curved wave for per-ray integration: the frame's axes, the shape in `f32` and `f64`,
/// the bounding-cylinder radius (002 §3.4.4) and the [`PieceTable`]. Never panics: invalid values
/// (see [`CurveWave::validate`], which callers should run first) are replaced by the nearest legal
/// ones.
pub fn prepare(wave: &CurveWave) -> PreparedCurve {
    let wave = sanitize(wave);
    let frame = wave.frame;
    let f64v = |v: Vec3<f32>| v.as_f64();
    let fr = CurveFrame { origin: f64v(frame.origin), axis: f64v(frame.axis), up: f64v(frame.up) };
    let axes = fr.axes().unwrap_or([Vec3::X, Vec3::Y, Vec3::Z]);
    let shape64 = ShapeEval::<f64>::new(&wave.shape);
    let shape32 = ShapeEval::<f32>::new(&wave.shape);
    let s_head = f64::from(wave.extension) * shape::s_end(&wave.shape);
    let x_head = f64::from(wave.gamma) * s_head;
    let bound = shape::bound_radius(&wave.shape);
    let size = bound.max(x_head / 16.0).max(1e-12);
    let table = build_table(&wave, &shape64, s_head, x_head, size);
    PreparedCurve { origin: fr.origin, axes, shape32, shape64, s_head, x_head, bound, size, table, wave }
}

impl PreparedCurve {
    /// Radius `R` of the cylinder around the axis that encloses the curve: the amplitude bound of
    /// a helix or trigonometric sum, the farthest control point of a Bézier or B-spline curve
    /// (002 §3.4.4). The Simpson reduction adds its `ε` to it.
    pub fn bound_radius(&self) -> f32 {
        self.bound as f32
    }
    /// Axial length `X = γ·k·s_end` of the part of the curve that exists (002 eq. 3.24).
    pub fn axial_length(&self) -> f32 {
        self.x_head as f32
    }
    /// The frame's origin and orthonormal axes `(D, ŷ, ẑ)`, in `f32`.
    pub fn frame_axes(&self) -> (Vec3<f32>, [Vec3<f32>; 3]) {
        (self.origin.as_f32(), [self.axes[0].as_f32(), self.axes[1].as_f32(), self.axes[2].as_f32()])
    }
    /// Radius of a sphere about the axis's midpoint `(X/2)·D` that holds the whole curve,
    /// `max(X/2, R, size)` (`R` the bounding-cylinder radius, `size` as in [`LEAF_TOLERANCE`]): an
    /// inverse-square ray of the nearest-point field closes its open end in one exact piece from
    /// [`TAIL_RADII`](super::TAIL_RADII) of these radii on (`nearest.rs`).
    pub fn tail_radius(&self) -> f64 {
        (0.5 * self.x_head).max(self.bound).max(self.size)
    }
    /// The polyline tree the default integrator walks (and the GPU uploads).
    pub fn table(&self) -> &PieceTable {
        &self.table
    }
    /// The core radius all integrators use: `max(r_c, MIN_CORE·size)` ([`MIN_CORE`]).
    pub fn effective_core_radius<R: Real>(&self, core_radius: R) -> R {
        let floor = R::from_f64(MIN_CORE * self.size);
        if core_radius.is_finite() {
            core_radius.abs().max(floor)
        } else {
            floor
        }
    }
    /// The exact cross-section point `c_⊥(s)` (`s` clamped to `[0, k·s_end]`), in `f64`.
    pub fn cross_section(&self, s: f64) -> [f64; 2] {
        self.shape64.eval(s.clamp(0.0, self.s_head))
    }
    /// The curve as a polyline of world points for lighting (000 §2.1 generalised to curves: the
    /// light point is the nearest point of the curve). The leaf nodes of the [`PieceTable`] (exact
    /// curve points), thinned by Douglas–Peucker so that no dropped node lies farther than
    /// `LIGHT_TOLERANCE · size` from the polyline, at most [`MAX_LIGHT_POINTS`] points (the
    /// tolerance doubles until they fit). Always at least the two end points.
    pub fn light_polyline(&self) -> Vec<Vec3<f32>> {
        let pts: Vec<Vec3<f64>> = self.table.nodes.iter().map(|n| self.point(f64::from(n[3]))).collect();
        let mut tol = LIGHT_TOLERANCE * self.size;
        loop {
            let mut keep = vec![false; pts.len()];
            keep[0] = true;
            *keep.last_mut().expect("a table has at least two nodes") = true;
            let mut stack = vec![(0usize, pts.len() - 1)];
            while let Some((a, b)) = stack.pop() {
                if b <= a + 1 {
                    continue;
                }
                let (mut worst, mut at) = (-1.0f64, a);
                for (i, p) in pts.iter().enumerate().take(b).skip(a + 1) {
                    let d = segment_distance(*p, pts[a], pts[b]);
                    if d > worst {
                        worst = d;
                        at = i;
                    }
                }
                if worst > tol {
                    keep[at] = true;
                    stack.push((a, at));
                    stack.push((at, b));
                }
            }
            if keep.iter().filter(|&&k| k).count() <= MAX_LIGHT_POINTS || !(tol > 0.0) {
                return pts.iter().zip(&keep).filter(|(_, &k)| k).map(|(p, _)| p.as_f32()).collect();
            }
            tol *= 2.0;
        }
    }
    /// The curve point `c(s)` in world space (`s` clamped to `[0, k·s_end]`), in `f64`.
    pub fn point(&self, s: f64) -> Vec3<f64> {
        let s = s.clamp(0.0, self.s_head);
        let c = self.shape64.eval(s);
        let [d, y, z] = self.axes;
        self.origin + d * (f64::from(self.wave.gamma) * s) + y * c[0] + z * c[1]
    }
}

/// Builds the [`PieceTable`]: adaptive leaves, then the deviation bound of every coarser chord.
fn build_table(wave: &CurveWave, shape: &ShapeEval<f64>, s_head: f64, x_head: f64, size: f64) -> PieceTable {
    let gamma = f64::from(wave.gamma);
    let tol = LEAF_TOLERANCE * size;
    let eval = |s: f64| shape.eval(s.clamp(0.0, s_head));
    // Initial uniform pieces: enough to see every feature (8 per period of the fastest harmonic,
    // 4 per control point or knot span), so bisection only refines.
    let features = match &wave.shape {
        CurveShape::Helix { rate, .. } => f64::from(rate.abs()) * s_head / std::f64::consts::TAU,
        CurveShape::TrigSum { rate, y_terms, z_terms, .. } => {
            let h = y_terms.len().max(z_terms.len()) as f64;
            h * f64::from(rate.abs()) * s_head / std::f64::consts::TAU
        }
        CurveShape::Bezier { points } | CurveShape::BSpline { points, .. } => points.len() as f64 / 2.0,
    };
    let n0 = ((features * 8.0).ceil() as usize).clamp(16, MAX_PIECES / 4);
    // Minimum piece length in s: keeps f32 node coordinates strictly increasing.
    let min_ds = (s_head * 4e-6).max(f64::MIN_POSITIVE);
    let mut leaves: Vec<(f64, [f64; 2], f64)> = Vec::with_capacity(n0 * 2); // (s, c(s), leaf error)
    let deviation = |sa: f64, ca: [f64; 2], sb: f64, cb: [f64; 2]| {
        let mut m: f64 = 0.0;
        for f in [0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875] {
            let c = eval(sa + (sb - sa) * f);
            let l = [ca[0] + (cb[0] - ca[0]) * f, ca[1] + (cb[1] - ca[1]) * f];
            m = m.max(((c[0] - l[0]).powi(2) + (c[1] - l[1]).powi(2)).sqrt());
        }
        m
    };
    let budget = MAX_PIECES;
    let mut stack: Vec<(f64, [f64; 2], f64, [f64; 2])> = Vec::new();
    for i in (0..n0).rev() {
        let sa = s_head * i as f64 / n0 as f64;
        let sb = s_head * (i + 1) as f64 / n0 as f64;
        stack.push((sa, eval(sa), sb, eval(sb)));
    }
    while let Some((sa, ca, sb, cb)) = stack.pop() {
        let dev = deviation(sa, ca, sb, cb);
        let room = leaves.len() + stack.len() + 2 <= budget;
        if dev > tol && sb - sa > 2.0 * min_ds && room {
            let sm = 0.5 * (sa + sb);
            let cm = eval(sm);
            stack.push((sm, cm, sb, cb));
            stack.push((sa, ca, sm, cm));
        } else {
            // 7 samples of a smooth deviation miss its maximum by a few per cent at most.
            leaves.push((sa, ca, dev * 1.1));
        }
    }
    let n = leaves.len();
    let mut nodes: Vec<[f32; 4]> =
        leaves.iter().map(|&(s, c, _)| [(gamma * s) as f32, c[0] as f32, c[1] as f32, s as f32]).collect();
    let head = eval(s_head);
    nodes.push([x_head as f32, head[0] as f32, head[1] as f32, s_head as f32]);
    nodes[0][0] = 0.0;
    // f64 copies of the nodes for the bounds (the f32 rounding of the node values is included
    // below as an absolute slack).
    let xs: Vec<f64> = leaves.iter().map(|l| gamma * l.0).chain([x_head]).collect();
    let cs: Vec<[f64; 2]> = leaves.iter().map(|l| l.1).chain([head]).collect();
    let slack = (size + x_head) * 2.0 * f64::from(f32::EPSILON);
    // Per-leaf moments ∫c dx and ∫c·(x − x_mid) dx by 4-point Gauss–Legendre on the exact curve.
    const GX: [f64; 4] = [
        -0.861_136_311_594_052_6,
        -0.339_981_043_584_856_3,
        0.339_981_043_584_856_3,
        0.861_136_311_594_052_6,
    ];
    const GW: [f64; 4] =
        [0.347_854_845_137_453_9, 0.652_145_154_862_546_1, 0.652_145_154_862_546_1, 0.347_854_845_137_453_9];
    let moments: Vec<([f64; 2], [f64; 2])> = (0..n)
        .map(|i| {
            let (sa, sb) = (leaves[i].0, if i + 1 < n { leaves[i + 1].0 } else { s_head });
            let h = 0.5 * (xs[i + 1] - xs[i]);
            let (mut m0, mut m1) = ([0.0; 2], [0.0; 2]);
            for (g, w) in GX.iter().zip(GW) {
                let c = eval(0.5 * (sa + sb) + 0.5 * (sb - sa) * g);
                for k in 0..2 {
                    m0[k] += w * h * c[k];
                    m1[k] += w * h * c[k] * (g * h);
                }
            }
            (m0, m1)
        })
        .collect();
    let levels = (usize::BITS - (n.max(1) - 1).leading_zeros()) as usize + 1;
    let mut errors = Vec::new();
    let mut lines = Vec::new();
    let mut level_offsets = Vec::with_capacity(levels + 1);
    for l in 0..levels {
        level_offsets.push(errors.len() as u32);
        let w = 1usize << l;
        for j in 0..n.div_ceil(w) {
            let a = j * w;
            let b = ((j + 1) * w).min(n);
            let (xa, xb) = (xs[a], xs[b]);
            let (xm, len) = (0.5 * (xa + xb), xb - xa);
            let (mut m0, mut m1) = ([0.0; 2], [0.0; 2]);
            for i in a..b {
                let shift = 0.5 * (xs[i] + xs[i + 1]) - xm;
                for k in 0..2 {
                    m0[k] += moments[i].0[k];
                    m1[k] += moments[i].1[k] + shift * moments[i].0[k];
                }
            }
            // Least squares on [xa, xb]: mean = m0/len, slope = 12·m1/len³.
            let mean = [m0[0] / len, m0[1] / len];
            let slope = [12.0 * m1[0] / len.powi(3), 12.0 * m1[1] / len.powi(3)];
            // On leaf i: |c − L| ≤ leaf error + |leaf chord − L|, and the latter is linear in x,
            // so bounded by its values at the leaf's two nodes.
            let node_dev = |i: usize| {
                let l = [mean[0] + (xs[i] - xm) * slope[0], mean[1] + (xs[i] - xm) * slope[1]];
                ((cs[i][0] - l[0]).powi(2) + (cs[i][1] - l[1]).powi(2)).sqrt()
            };
            let mut e: f64 = 0.0;
            let mut prev = node_dev(a);
            for (i, leaf) in leaves.iter().enumerate().take(b).skip(a) {
                let next = node_dev(i + 1);
                e = e.max(leaf.2 + f64::max(prev, next));
                prev = next;
            }
            errors.push((e + slack) as f32);
            lines.push([mean[0] as f32, mean[1] as f32, slope[0] as f32, slope[1] as f32]);
        }
    }
    level_offsets.push(errors.len() as u32);
    PieceTable { nodes, lines, errors, level_offsets }
}
