//! The public description of a curved wave, the contract the scene and the backends build
//! against: its frame ([`CurveFrame`]), cross-section shape ([`CurveShape`]), integrator
//! ([`Integrator`], [`Reduction`]) and the wave itself ([`CurveWave`]), with the limits its
//! values must respect.

use crate::{Real, Vec3};

/// Highest B-spline order `k` supported (per-ray evaluation keeps the basis in fixed-size arrays).
pub const MAX_ORDER: usize = 16;
/// Most control points of a Bézier curve (degree ≤ 63).
pub const MAX_BEZIER_POINTS: usize = 64;
/// Most control points of a B-spline (a control polygon of 511 edges: by the
/// variation-diminishing property the curve oscillates no more often; see `cost.rs`).
pub const MAX_BSPLINE_POINTS: usize = 512;
/// Most terms in each trigonometric sum (each costs a sine and a cosine per curve point).
pub const MAX_TRIG_TERMS: usize = 64;
/// Largest number of Simpson subintervals `m`; with a curve point dearer than a helix's,
/// `m × point cost` ([`CurveWave::point_cost`]) is held to it.
pub const MAX_SIMPSON_M: u32 = 100_000;
/// Most turns a helix, or the fastest harmonic of a trigonometric sum, may make over the curve's
/// length ([`CurveWave::turns`]): the work of a ray grows with the turns it passes.
pub const MAX_TURNS: f64 = 128.0;
/// Largest steepness `max |dc_⊥/dx|` of a curve ([`CurveWave::steepness`]): keeps the chord
/// walk's squared relative speeds finite for every ray a scene can make.
pub const MAX_SLOPE: f64 = 1e5;

/// The local frame of a curve: launch point `O`, unit travel axis `D`, and an up vector that fixes
/// the cross-section axes; see [`CurveFrame::axes`] for the exact construction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveFrame<R> {
    /// Launch point `O`.
    pub origin: Vec3<R>,
    /// Unit travel axis `D`.
    pub axis: Vec3<R>,
    /// Up vector (need not be unit or perpendicular to `D`; must not be parallel to it).
    pub up: Vec3<R>,
}

impl<R: Real> CurveFrame<R> {
    /// The orthonormal, right-handed frame `(D, ŷ, ẑ)`: `D = axis/|axis|`,
    /// `ŷ = normalize(up − (up·D)·D)` (Gram–Schmidt), `ẑ = D × ŷ`. A curve point with local
    /// coordinates `(x, y, z)` is `O + x·D + y·ŷ + z·ẑ`.
    ///
    /// `None` when the axis is zero or not finite, or `up` is parallel to it (see
    /// [`CurveWave::validate`]).
    pub fn axes(&self) -> Option<[Vec3<R>; 3]> {
        let d = self.axis.try_normalize()?;
        let up = self.up;
        let upl = up.length();
        if !(upl > R::ZERO && upl.is_finite()) {
            return None;
        }
        let perp = up - d * up.dot(d);
        // Parallel (within ~1e-6 rad in f64, ~1e-3 in f32): the cross-section axes are undefined.
        if perp.length() <= upl * R::from_f64(1e-6).max(R::EPSILON * R::from_f64(64.0)) {
            return None;
        }
        let y = perp.try_normalize()?;
        let z = d.cross(y);
        Some([d, y, z])
    }
}

/// The shape of a curve across its axis: `c(s) = (γ s, y(s), z(s))` in the local frame.
#[derive(Clone, Debug, PartialEq)]
pub enum CurveShape {
    /// Helix `y = r sin(θ s + φ)`, `z = r cos(θ s + φ)`, `s ∈ [0, length]` (002 §3.4.7).
    Helix {
        /// Radius `r ≥ 0`.
        radius: f32,
        /// Angular rate `θ` (radians per unit of `s`).
        rate: f32,
        /// Phase `φ` (radians).
        phase: f32,
        /// `s_end > 0`.
        length: f32,
    },
    /// Trigonometric sums `y = Σ a_n sin(nθs) + b_n cos(nθs)`, `z = Σ c_n sin(nθs) + d_n cos(nθs)`,
    /// `n = 1, 2, …`, `s ∈ [0, length]` (002 §3.4.8).
    TrigSum {
        /// Base angular rate `θ`.
        rate: f32,
        /// `(a_n, b_n)` for n = 1, 2, ….
        y_terms: Vec<[f32; 2]>,
        /// `(c_n, d_n)` for n = 1, 2, ….
        z_terms: Vec<[f32; 2]>,
        /// `s_end > 0`.
        length: f32,
    },
    /// Bézier curve of degree `points.len() − 1 ≥ 1`; each control point is `(y, z)`,
    /// `s ∈ [0, 1]` (002 §3.4.9).
    Bezier {
        /// Control points `(y, z)`.
        points: Vec<[f32; 2]>,
    },
    /// B-spline of order `k` (`2 ≤ k ≤ n + 1`) over `n + 1` control points `(y, z)`, with a knot
    /// vector of `n + k + 1` non-decreasing values (clamped uniform when `None`); `s` is mapped
    /// linearly onto the valid knot range, `s ∈ [0, 1]` (002 §3.4.10, eq. 3.34).
    BSpline {
        /// Control points `(y, z)`.
        points: Vec<[f32; 2]>,
        /// Order `k`.
        order: u32,
        /// Knot vector, or `None` for clamped uniform.
        knots: Option<Vec<f32>>,
    },
}

/// Faithful composite-Simpson reduction by a bounding cylinder (002 §3.4.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reduction {
    /// Outside the cylinder use `m / n` subintervals; `n ≥ 1`.
    pub n: u32,
    /// Offset `ε ≥ 0` added to the cylinder radius.
    pub epsilon: f32,
}

/// How a curve's ray integral is computed, and by which distance field: the cross-section
/// pairing (002 §3.4.2; [`Simpson`](Integrator::Simpson), [`Default`](Integrator::Default)) or
/// the true nearest point ([`Nearest`](Integrator::Nearest)).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Integrator {
    /// The thesis (002 §3.4.4): composite Simpson over `u ∈ [0, 1]` with `m` (even) subintervals,
    /// optionally reduced outside a bounding cylinder.
    Simpson {
        /// Number of subintervals, even, `2 ≤ m ≤ 100000`.
        m: u32,
        /// Bounding-cylinder reduction, if any.
        reduction: Option<Reduction>,
    },
    /// hadou's default integrator.
    #[default]
    Default,
    /// The nearest-point field: the density at a ray point is taken at its true nearest point on
    /// the curve instead of the point its cross-section pairs it with (SPEC.md §1.4), integrated
    /// by a walk whose steps follow the distance (`nearest.rs`); scene key `field = "nearest"`.
    Nearest,
}

/// A curved wave: everything needed to integrate its energy along a ray.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveWave {
    /// Local frame.
    pub frame: CurveFrame<f32>,
    /// Cross-section shape.
    pub shape: CurveShape,
    /// Axial stretch `γ > 0` (002 Fig. 4.5).
    pub gamma: f32,
    /// Extension `k ∈ (0, 1]` (002 eq. 3.24): only `s ∈ [0, k·s_end]` exists.
    pub extension: f32,
    /// Attenuation exponent `j ≥ 0` (002 eq. 3.23): the integrand is multiplied by `(1 − u)^j`.
    pub attenuation: f32,
    /// Strength `α`.
    pub alpha: f32,
    /// Integration method.
    pub integrator: Integrator,
}
