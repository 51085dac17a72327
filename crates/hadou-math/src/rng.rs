//! The workspace's one deterministic generator (splitmix64): seedable, the same stream on every
//! platform, no dependency. The randomized tests (closed forms against quadrature, lanes against
//! scalars, WGSL against Rust) and the mutation fuzz test draw their cases from it, so a failure
//! names a seed that reproduces it. Not for anything that must be unpredictable.

use crate::{Vec3, Vec3d, Vec3f};

/// splitmix64 (Steele, Lea and Flood's SplittableRandom mixer): the state advances by the golden
/// ratio, and each output is the state passed through two multiply–xorshift rounds.
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`, 53 bits.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[0, 1)`, 24 bits.
    pub fn unit_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in `[a, b)`.
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }

    /// Uniform in `[a, b)`, in `f32`.
    pub fn range_f32(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.unit_f32()
    }

    /// Log-uniform in `[a, b)`, `0 < a < b`.
    pub fn log_range(&mut self, a: f64, b: f64) -> f64 {
        (a.ln() + (b.ln() - a.ln()) * self.unit()).exp()
    }

    /// Uniform in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % (n.max(1) as u64)) as usize
    }

    /// One element of `items`, uniformly (`items` must not be empty).
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    /// Uniform on the unit sphere.
    pub fn unit_vec(&mut self) -> Vec3d {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let r = (1.0 - z * z).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// Uniform in the cube `[-h, h)³`.
    pub fn in_cube(&mut self, h: f64) -> Vec3d {
        Vec3::new(self.range(-h, h), self.range(-h, h), self.range(-h, h))
    }

    /// Uniform in the cube `[-h, h)³`, in `f32`.
    pub fn in_cube_f32(&mut self, h: f32) -> Vec3f {
        Vec3::new(self.range_f32(-h, h), self.range_f32(-h, h), self.range_f32(-h, h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The published splitmix64 stream for seed 0 (the reference values of Vigna's
    /// `splitmix64.c`), so the generator cannot drift silently.
    #[test]
    fn splitmix64_reference_stream() {
        let mut r = Rng(0);
        assert_eq!(r.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(r.next_u64(), 0x6E78_9E6A_A1B9_65F4);
        assert_eq!(r.next_u64(), 0x06C4_5D18_8009_454F);
        let mut r = Rng(7);
        for _ in 0..1000 {
            let (u, f) = (r.unit(), r.unit_f32());
            assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&f));
            assert!(r.below(3) < 3);
        }
        assert_eq!(r.below(0), 0);
    }
}
