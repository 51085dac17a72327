//! A ray against a prepared curve, as every curve integrator sees it: the precisions they run in
//! ([`CurveReal`]) and the ray in the curve's local frame with its span and attenuation resolved
//! ([`LocalRay`]). [`LocalRay::new`] is the one place a ray's span is resolved: each public entry
//! point (`curve_energy`, `curve_energy_f64`, `default_energy`, `curve_energy_reference`) calls it
//! once, returns 0 where it gives `None`, and hands the resolved ray to its integrator.

use super::prepare::PreparedCurve;
use super::shape::ShapeEval;
use crate::energy::{Falloff, FieldParams, Ray};
use crate::{Real, Vec3};

/// The precisions the curve integrators run in (`f32` renders, `f64` checks).
pub(crate) trait CurveReal: Real {
    /// The shape evaluator in this precision.
    fn shape(c: &PreparedCurve) -> &ShapeEval<Self>;
    /// The value with the lower half of its significand cleared (12 of 24 bits kept in `f32`,
    /// 26 of 53 in `f64`), so that the product of two such values, or of one with the remainder
    /// `x − x.split()`, is exact.
    fn split(self) -> Self;
}
impl CurveReal for f32 {
    fn shape(c: &PreparedCurve) -> &ShapeEval<f32> {
        &c.shape32
    }
    #[inline]
    fn split(self) -> f32 {
        f32::from_bits(self.to_bits() & 0xffff_f000)
    }
}
impl CurveReal for f64 {
    fn shape(c: &PreparedCurve) -> &ShapeEval<f64> {
        &c.shape64
    }
    #[inline]
    fn split(self) -> f64 {
        f64::from_bits(self.to_bits() & 0xffff_ffff_f800_0000)
    }
}

/// What [`LocalRay::new`] takes from the curve and the field, the same for every ray: the frame's
/// origin and axes and the wave's constants in the precision `R`. A batch of rays through one
/// curve forms it once ([`LocalFrame::ray`] per ray).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LocalFrame<R> {
    origin: Vec3<R>,
    axes: [Vec3<R>; 3],
    j: R,
    rc2: R,
    falloff: Falloff,
    alpha: R,
    x_head: R,
}

impl<R: Real> LocalFrame<R> {
    /// The curve's frame and constants in `R`.
    pub(crate) fn new(c: &PreparedCurve, p: &FieldParams<R>) -> Self {
        let conv = |v: Vec3<f64>| Vec3::new(R::from_f64(v.x), R::from_f64(v.y), R::from_f64(v.z));
        LocalFrame {
            origin: conv(c.origin),
            axes: c.axes.map(conv),
            j: R::from_f64(f64::from(c.wave.attenuation)),
            rc2: {
                let rc = c.effective_core_radius(p.core_radius);
                rc * rc
            },
            falloff: p.falloff,
            alpha: R::from_f64(f64::from(c.wave.alpha)),
            x_head: R::from_f64(c.x_head),
        }
    }

    /// [`LocalRay::new`] of one ray in this frame: `None` if the span is empty or the input is
    /// not finite.
    #[inline]
    pub(crate) fn ray(&self, ray: &Ray<R>, t0: R, t1: R, t_far: R) -> Option<LocalRay<R>> {
        if !(ray.origin.is_finite() && ray.dir.is_finite() && t0.is_finite() && !t1.to_f64().is_nan()) {
            return None;
        }
        let t_far = if t_far.is_finite() && t_far > R::ZERO { t_far } else { R::ONE };
        let j = self.j;
        let mut t1 = t1;
        if self.falloff == Falloff::Faithful && !t1.is_finite() {
            t1 = t_far;
        }
        if j > R::ZERO {
            t1 = t1.min(t_far);
        }
        if !(t1 > t0) {
            return None;
        }
        let [d, y, z] = self.axes;
        let w = ray.origin - self.origin;
        Some(LocalRay {
            o: Vec3::new(w.dot(d), w.dot(y), w.dot(z)),
            q: Vec3::new(ray.dir.dot(d), ray.dir.dot(y), ray.dir.dot(z)),
            t0,
            t1,
            t_far,
            j,
            rc2: self.rc2,
            falloff: self.falloff,
            alpha: self.alpha,
            x_head: self.x_head,
        })
    }
}

/// A ray in the curve's local frame, with the span and the attenuation resolved.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LocalRay<R> {
    /// Eye in local coordinates `(x, y, z)`.
    pub o: Vec3<R>,
    /// Direction in local coordinates.
    pub q: Vec3<R>,
    /// Span start.
    pub t0: R,
    /// Span end (finite unless inverse square without attenuation).
    pub t1: R,
    /// Far point parameter (`> 0`).
    pub t_far: R,
    /// Attenuation exponent `j` (0: none).
    pub j: R,
    /// Effective core radius squared.
    pub rc2: R,
    /// Density law.
    pub falloff: Falloff,
    /// Strength `α`.
    pub alpha: R,
    /// Axial length `X`.
    pub x_head: R,
}

impl<R: Real> LocalRay<R> {
    /// Resolves the span: `None` if it is empty or the input is not finite.
    ///
    /// Faithful mode integrates at most to the far point (`t1 = ∞` means `t_far`); with attenuation
    /// `j > 0` the factor is 0 from the far point on, so the span ends there. The same as
    /// [`LocalFrame::new`] followed by [`LocalFrame::ray`].
    pub(crate) fn new(
        c: &PreparedCurve,
        p: &FieldParams<R>,
        ray: &Ray<R>,
        t0: R,
        t1: R,
        t_far: R,
    ) -> Option<Self> {
        LocalFrame::new(c, p).ray(ray, t0, t1, t_far)
    }

    /// Local point at `t`.
    #[inline]
    pub(crate) fn at(&self, t: R) -> Vec3<R> {
        self.o + self.q * t
    }

    /// Attenuation `(1 − t/t_far)^j` (002 eq. 3.23), 0 beyond the far point, 1 for `j = 0`.
    #[inline]
    pub(crate) fn attenuation(&self, t: R) -> R {
        if self.j == R::ZERO {
            return R::ONE;
        }
        let u = R::ONE - t / self.t_far;
        if u <= R::ZERO {
            R::ZERO
        } else {
            u.powf(self.j)
        }
    }

    /// The `t` where the ray crosses the end planes, in ray order, with the end point met before
    /// the slab (`false` = `c(0)`, `true` = the head) — or `None` when `x` is constant.
    #[inline]
    pub(crate) fn slab(&self) -> Option<(R, R, bool)> {
        let qx = self.q.x;
        if qx == R::ZERO {
            return None;
        }
        let ta = -self.o.x / qx;
        let tb = (self.x_head - self.o.x) / qx;
        Some(if qx > R::ZERO { (ta, tb, false) } else { (tb, ta, true) })
    }
}
