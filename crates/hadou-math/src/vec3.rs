//! A minimal 3-vector generic over [`Real`], so formulas run in `f32` and `f64` alike.

use crate::Real;
use core::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

/// A 3-vector of [`Real`]s. `#[repr(C)]` so `Vec3<f32>` is three packed `f32`s.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Vec3<R> {
    /// x component.
    pub x: R,
    /// y component (up).
    pub y: R,
    /// z component.
    pub z: R,
}

/// `Vec3<f32>`.
pub type Vec3f = Vec3<f32>;
/// `Vec3<f64>`.
pub type Vec3d = Vec3<f64>;

impl<R: Real> Vec3<R> {
    /// The zero vector.
    pub const ZERO: Self = Self { x: R::ZERO, y: R::ZERO, z: R::ZERO };
    /// Unit x.
    pub const X: Self = Self { x: R::ONE, y: R::ZERO, z: R::ZERO };
    /// Unit y (up).
    pub const Y: Self = Self { x: R::ZERO, y: R::ONE, z: R::ZERO };
    /// Unit z.
    pub const Z: Self = Self { x: R::ZERO, y: R::ZERO, z: R::ONE };

    /// A vector from components.
    #[inline(always)]
    pub const fn new(x: R, y: R, z: R) -> Self {
        Self { x, y, z }
    }
    /// All components equal to `v`.
    #[inline(always)]
    pub const fn splat(v: R) -> Self {
        Self { x: v, y: v, z: v }
    }
    /// Dot product.
    #[inline(always)]
    pub fn dot(self, o: Self) -> R {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    /// Cross product (right-handed).
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self::new(self.y * o.z - self.z * o.y, self.z * o.x - self.x * o.z, self.x * o.y - self.y * o.x)
    }
    /// Squared length.
    #[inline(always)]
    pub fn length_squared(self) -> R {
        self.dot(self)
    }
    /// Length.
    #[inline(always)]
    pub fn length(self) -> R {
        self.dot(self).sqrt()
    }
    /// Unit vector in the same direction, or `None` for a zero or non-finite vector.
    #[inline]
    pub fn try_normalize(self) -> Option<Self> {
        let l = self.length();
        if l > R::ZERO && l.is_finite() {
            Some(self / l)
        } else {
            None
        }
    }
    /// Unit vector in the same direction, or `fallback` for a zero or non-finite vector.
    #[inline]
    pub fn normalize_or(self, fallback: Self) -> Self {
        self.try_normalize().unwrap_or(fallback)
    }
    /// Component-wise minimum.
    #[inline(always)]
    pub fn min(self, o: Self) -> Self {
        Self::new(self.x.min(o.x), self.y.min(o.y), self.z.min(o.z))
    }
    /// Component-wise maximum.
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        Self::new(self.x.max(o.x), self.y.max(o.y), self.z.max(o.z))
    }
    /// Component-wise product.
    #[inline(always)]
    pub fn mul_elem(self, o: Self) -> Self {
        Self::new(self.x * o.x, self.y * o.y, self.z * o.z)
    }
    /// Linear interpolation: `self` at `t = 0`, `o` at `t = 1`.
    #[inline(always)]
    pub fn lerp(self, o: Self, t: R) -> Self {
        self + (o - self) * t
    }
    /// All components finite.
    #[inline(always)]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
    /// Components as an array.
    #[inline(always)]
    pub fn to_array(self) -> [R; 3] {
        [self.x, self.y, self.z]
    }
    /// From an array.
    #[inline(always)]
    pub fn from_array(a: [R; 3]) -> Self {
        Self::new(a[0], a[1], a[2])
    }
    /// Two unit vectors that with `self` (assumed unit) form a right-handed orthonormal frame
    /// `(self, u, v)`; continuous except where `self` crosses the branch of the construction
    /// (Duff et al. 2017, "Building an orthonormal basis, revisited").
    pub fn orthonormal_basis(self) -> (Self, Self) {
        let sign = R::ONE.copysign(self.z);
        let a = -R::ONE / (sign + self.z);
        let b = self.x * self.y * a;
        let u = Self::new(R::ONE + sign * self.x * self.x * a, sign * b, -sign * self.x);
        let v = Self::new(b, sign + self.y * self.y * a, -self.y);
        (u, v)
    }
}

impl Vec3<f32> {
    /// Widen to `f64`.
    #[inline(always)]
    pub fn as_f64(self) -> Vec3<f64> {
        Vec3::new(self.x as f64, self.y as f64, self.z as f64)
    }
}

impl Vec3<f64> {
    /// Narrow to `f32` (rounding).
    #[inline(always)]
    pub fn as_f32(self) -> Vec3<f32> {
        Vec3::new(self.x as f32, self.y as f32, self.z as f32)
    }
}

impl<R: Real> Add for Vec3<R> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl<R: Real> AddAssign for Vec3<R> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl<R: Real> Sub for Vec3<R> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl<R: Real> SubAssign for Vec3<R> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}
impl<R: Real> Mul<R> for Vec3<R> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: R) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }
}
impl<R: Real> Div<R> for Vec3<R> {
    type Output = Self;
    #[inline(always)]
    fn div(self, s: R) -> Self {
        Self::new(self.x / s, self.y / s, self.z / s)
    }
}
impl<R: Real> Neg for Vec3<R> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}
