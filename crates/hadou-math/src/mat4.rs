//! A column-major 4×4 `f32` matrix for object transforms and cameras.

use crate::{Vec3, Vec3f};
use core::ops::Mul;

/// Column-major 4×4 matrix: `cols[c][r]`. Matches WGSL's `mat4x4<f32>` memory layout.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Mat4 {
    /// The four columns.
    pub cols: [[f32; 4]; 4],
}

impl Default for Mat4 {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Mat4 {
    /// The identity.
    pub const IDENTITY: Self = Self {
        cols: [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]],
    };

    /// Translation by `t`.
    pub fn translation(t: Vec3f) -> Self {
        let mut m = Self::IDENTITY;
        m.cols[3] = [t.x, t.y, t.z, 1.0];
        m
    }

    /// Non-uniform scale.
    pub fn scale(s: Vec3f) -> Self {
        let mut m = Self::IDENTITY;
        m.cols[0][0] = s.x;
        m.cols[1][1] = s.y;
        m.cols[2][2] = s.z;
        m
    }

    /// Rotation by Euler angles in degrees, applied about x, then y, then z (`R = Rz·Ry·Rx`).
    pub fn rotation_xyz_deg(deg: Vec3f) -> Self {
        let (sx, cx) = deg.x.to_radians().sin_cos();
        let (sy, cy) = deg.y.to_radians().sin_cos();
        let (sz, cz) = deg.z.to_radians().sin_cos();
        let rx = Self {
            cols: [[1.0, 0.0, 0.0, 0.0], [0.0, cx, sx, 0.0], [0.0, -sx, cx, 0.0], [0.0, 0.0, 0.0, 1.0]],
        };
        let ry = Self {
            cols: [[cy, 0.0, -sy, 0.0], [0.0, 1.0, 0.0, 0.0], [sy, 0.0, cy, 0.0], [0.0, 0.0, 0.0, 1.0]],
        };
        let rz = Self {
            cols: [[cz, sz, 0.0, 0.0], [-sz, cz, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]],
        };
        rz * ry * rx
    }

    /// `T·R·S`: scale, then rotate, then translate.
    pub fn from_trs(translation: Vec3f, rotation_deg: Vec3f, scale: Vec3f) -> Self {
        Self::translation(translation) * Self::rotation_xyz_deg(rotation_deg) * Self::scale(scale)
    }

    /// Element at row `r`, column `c`.
    #[inline(always)]
    pub fn at(&self, r: usize, c: usize) -> f32 {
        self.cols[c][r]
    }

    /// `M·(p, 1)`, dropping w (affine transforms).
    #[inline]
    pub fn transform_point(&self, p: Vec3f) -> Vec3f {
        let c = &self.cols;
        Vec3::new(
            c[0][0] * p.x + c[1][0] * p.y + c[2][0] * p.z + c[3][0],
            c[0][1] * p.x + c[1][1] * p.y + c[2][1] * p.z + c[3][1],
            c[0][2] * p.x + c[1][2] * p.y + c[2][2] * p.z + c[3][2],
        )
    }

    /// `M·(v, 0)`.
    #[inline]
    pub fn transform_vector(&self, v: Vec3f) -> Vec3f {
        let c = &self.cols;
        Vec3::new(
            c[0][0] * v.x + c[1][0] * v.y + c[2][0] * v.z,
            c[0][1] * v.x + c[1][1] * v.y + c[2][1] * v.z,
            c[0][2] * v.x + c[1][2] * v.y + c[2][2] * v.z,
        )
    }

    /// Transpose.
    pub fn transpose(&self) -> Self {
        let mut m = Self::IDENTITY;
        for r in 0..4 {
            for c in 0..4 {
                m.cols[c][r] = self.cols[r][c];
            }
        }
        m
    }

    /// Inverse of the upper-left 3×3 block, transposed: the matrix that carries normals. Falls back
    /// to the identity for a singular block (a zero scale), so normals stay finite.
    pub fn normal_matrix(&self) -> Self {
        let a = |r: usize, c: usize| self.cols[c][r] as f64;
        let det = a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1))
            - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0))
            + a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
        if det.abs() < 1e-30 || !det.is_finite() {
            return Self::IDENTITY;
        }
        let inv_det = 1.0 / det;
        // cofactor matrix / det == inverse transposed
        let cof = |r: usize, c: usize| {
            let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
            let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
            (a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)) * inv_det
        };
        let mut m = Self::IDENTITY;
        for r in 0..3 {
            for c in 0..3 {
                m.cols[c][r] = cof(r, c) as f32;
            }
        }
        m
    }
}

impl Mul for Mat4 {
    type Output = Mat4;
    fn mul(self, o: Mat4) -> Mat4 {
        let mut m = Mat4 { cols: [[0.0; 4]; 4] };
        for c in 0..4 {
            for r in 0..4 {
                let mut s = 0.0;
                for k in 0..4 {
                    s += self.cols[k][r] * o.cols[c][k];
                }
                m.cols[c][r] = s;
            }
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trs_moves_points_and_normal_matrix_keeps_normals_perpendicular() {
        let m =
            Mat4::from_trs(Vec3::new(1.0, 2.0, 3.0), Vec3::new(30.0, 45.0, 60.0), Vec3::new(2.0, 1.0, 0.5));
        let p = m.transform_point(Vec3::ZERO);
        assert_eq!(p, Vec3::new(1.0, 2.0, 3.0));
        // A tangent and a normal of the unit plane z=0 stay perpendicular after transform.
        let t = m.transform_vector(Vec3::X);
        let n = m.normal_matrix().transform_vector(Vec3::Z);
        assert!(t.dot(n).abs() < 1e-5, "{}", t.dot(n));
    }

    #[test]
    fn rotation_about_y_by_90_takes_x_to_minus_z() {
        let m = Mat4::rotation_xyz_deg(Vec3::new(0.0, 90.0, 0.0));
        let v = m.transform_vector(Vec3::X);
        assert!((v - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6, "{v:?}");
    }
}
