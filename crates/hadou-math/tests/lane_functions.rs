//! The lane polynomials the attenuated march needs (`Lane::exp`, `Lane::tan`, `Lane::asinh`,
//! `Lane::atan`) against `f64` over dense ranges, on every vector path the machine supports
//! (`SimdPath::supported`), with the accuracy their doc comments state: relative error within a
//! few `f32::EPSILON` of the `f64` value of the function at the `f32` input, and the stated
//! values at the ends of their ranges (overflow, underflow, NaN, signed zero).

use hadou_math::rng::Rng;
use hadou_math::simd::{dispatch, Lane, SimdPath, WithLanes};

/// Which function a batch evaluates.
#[derive(Clone, Copy, Debug)]
enum F {
    Exp,
    Tan,
    Asinh,
    Atan,
}

/// One function on eight lanes, on a path's lanes.
struct Eval(F, [f32; 8]);

impl WithLanes for Eval {
    type Output = [f32; 8];
    #[inline(always)]
    fn run<L: Lane>(self) -> [f32; 8] {
        let x = L::from_array(self.1);
        match self.0 {
            F::Exp => x.exp(),
            F::Tan => x.tan(),
            F::Asinh => x.asinh(),
            F::Atan => x.atan(),
        }
        .to_array()
    }
}

fn want(f: F, x: f32) -> f64 {
    let x = f64::from(x);
    match f {
        F::Exp => x.exp(),
        F::Tan => x.tan(),
        F::Asinh => x.asinh(),
        F::Atan => x.atan(),
    }
}

/// The largest relative error (in units of `f32::EPSILON`) of `f` over `xs` on `path`, each
/// lane checked against `max_eps`.
fn worst(path: SimdPath, f: F, xs: &[f32], max_eps: f64) -> f64 {
    let mut worst = 0.0f64;
    for chunk in xs.chunks(8) {
        let mut a = [0.0f32; 8];
        a[..chunk.len()].copy_from_slice(chunk);
        let got = dispatch(path, Eval(f, a));
        for (i, &x) in chunk.iter().enumerate() {
            let w = want(f, x);
            let g = f64::from(got[i]);
            let err = if w == 0.0 { g.abs() / f64::from(f32::MIN_POSITIVE) } else { (g - w).abs() / w.abs() };
            let eps = err / f64::from(f32::EPSILON);
            assert!(eps <= max_eps, "{path} {f:?}({x:e}) = {g:e}, not {w:e} ({eps:.2} ε)");
            worst = worst.max(eps);
        }
    }
    worst
}

/// `n` points uniform on `[lo, hi]` plus `m` random ones.
fn dense(lo: f32, hi: f32, n: usize, rng: &mut Rng, m: usize) -> Vec<f32> {
    let mut v: Vec<f32> = (0..=n).map(|i| lo + (hi - lo) * (i as f32 / n as f32)).collect();
    v.extend((0..m).map(|_| rng.range_f32(lo, hi)));
    v
}

/// `n` points log-uniform in magnitude on `[lo, hi]`, both signs.
fn log_dense(lo: f32, hi: f32, n: usize) -> Vec<f32> {
    let (a, b) = (lo.ln(), hi.ln());
    (0..=n)
        .flat_map(|i| {
            let x = (a + (b - a) * (i as f32 / n as f32)).exp();
            [x, -x]
        })
        .collect()
}

#[test]
fn exp_is_within_two_ulp_and_saturates() {
    let mut rng = Rng(31);
    let mut xs = dense(-87.3, 88.7, 200_000, &mut rng, 50_000);
    xs.extend(log_dense(1e-30, 80.0, 20_000));
    xs.extend([0.0, -0.0, 1.0, -1.0, 88.72, -87.32]);
    for path in SimdPath::supported() {
        let w = worst(path, F::Exp, &xs, 2.0);
        println!("{path}: exp worst {w:.2} ε");
        let ends = [88.73, 100.0, f32::INFINITY, f32::MAX, -87.34, -100.0, -f32::INFINITY, f32::NAN];
        let got = dispatch(path, Eval(F::Exp, ends));
        assert!(got[..4].iter().all(|&v| v == f32::INFINITY), "{path}: {got:?}");
        assert!(got[4..7].iter().all(|&v| v == 0.0), "{path}: {got:?}");
        assert!(got[7].is_nan(), "{path}: {got:?}");
    }
}

#[test]
fn tan_is_within_three_ulp_up_to_a_right_angle() {
    use std::f32::consts::FRAC_PI_2;
    let mut rng = Rng(32);
    let h = FRAC_PI_2 * (1.0 - 1e-6);
    let mut xs = dense(-h, h, 200_000, &mut rng, 50_000);
    // Next to ±π/2, where the tangent is 1/(π/2 − |x|).
    let mut x = FRAC_PI_2;
    for _ in 0..200 {
        x = f32::from_bits(x.to_bits() - 1);
        xs.extend([x, -x]);
    }
    xs.extend(log_dense(1e-30, 0.7, 20_000));
    xs.extend([0.0, -0.0, FRAC_PI_2, -FRAC_PI_2, std::f32::consts::FRAC_PI_4]);
    for path in SimdPath::supported() {
        let w = worst(path, F::Tan, &xs, 3.0);
        println!("{path}: tan worst {w:.2} ε");
        let z = dispatch(path, Eval(F::Tan, [0.0, -0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]));
        assert!(z[1] == 0.0 && z[1].is_sign_negative(), "{path}: tan(−0) = {}", z[1]);
    }
}

#[test]
fn asinh_is_within_four_ulp_from_tiny_to_huge() {
    let mut rng = Rng(33);
    let mut xs = dense(-10.0, 10.0, 200_000, &mut rng, 50_000);
    xs.extend(log_dense(1e-37, 1e37, 100_000));
    xs.extend(log_dense(4000.0, 4200.0, 2_000));
    xs.extend([0.0, -0.0, 1.0, -1.0, 4096.0, f32::MAX, -f32::MAX, f32::MIN_POSITIVE]);
    for path in SimdPath::supported() {
        let w = worst(path, F::Asinh, &xs, 4.0);
        println!("{path}: asinh worst {w:.2} ε");
    }
}

#[test]
fn atan_is_within_four_ulp() {
    let mut rng = Rng(34);
    let mut xs = dense(-4.0, 4.0, 200_000, &mut rng, 50_000);
    xs.extend(log_dense(1e-30, 1e30, 100_000));
    xs.extend([0.0, -0.0, 1.0, -1.0, f32::INFINITY, -f32::INFINITY]);
    for path in SimdPath::supported() {
        let w = worst(path, F::Atan, &xs, 4.0);
        println!("{path}: atan worst {w:.2} ε");
    }
}
