//! Shared fixtures of the analytic-energy tests: a deterministic RNG, random rays and fields, the
//! energy densities written straight from their definitions (002 eq. 3.4, 3.5, 3.11) and the
//! converged quadrature reference.

#![allow(dead_code)]

use hadou_math::energy::{
    beam_energy, capsule_energy, cylinder_energy, sphere_energy, BeamField, CapsuleField, CylinderField,
    Falloff, FieldParams, Ray, SphereField,
};
use hadou_math::quadrature::{integrate_adaptive_breaks, Quadrature};
use hadou_math::{Real, Vec3, Vec3d};

/// The workspace's deterministic generator (splitmix64).
pub use hadou_math::rng::Rng;

/// Which analytic shape a case integrates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// Sphere around the capsule's `M` with `α_s`.
    Sphere,
    /// Infinite cylinder through `M` along `D` with `α_c`.
    Cylinder,
    /// The capsule.
    Capsule,
    /// The capsule plus both bulbs.
    Beam,
}

/// All shapes.
pub const SHAPES: [Shape; 4] = [Shape::Sphere, Shape::Cylinder, Shape::Capsule, Shape::Beam];

/// One integration problem: a law, a ray, an interval and a beam (from which every shape is taken).
#[derive(Clone, Copy, Debug)]
pub struct Case<R> {
    /// Law and core radius.
    pub p: FieldParams<R>,
    /// The ray.
    pub ray: Ray<R>,
    /// Interval start.
    pub t0: R,
    /// Interval end (`∞` allowed for the inverse-square law).
    pub t1: R,
    /// The field.
    pub beam: BeamField<R>,
}

impl<R: Real> Case<R> {
    /// The sphere of a case.
    pub fn sphere(&self) -> SphereField<R> {
        SphereField { center: self.beam.capsule.m, alpha: self.beam.capsule.alpha_s }
    }
    /// The cylinder of a case.
    pub fn cylinder(&self) -> CylinderField<R> {
        let c = &self.beam.capsule;
        CylinderField { point: c.m, dir: c.d, alpha: c.alpha_c }
    }
    /// The closed form of `shape`.
    pub fn closed(&self, shape: Shape) -> R {
        let (p, r, t0, t1) = (&self.p, &self.ray, self.t0, self.t1);
        match shape {
            Shape::Sphere => sphere_energy(p, r, t0, t1, &self.sphere()),
            Shape::Cylinder => cylinder_energy(p, r, t0, t1, &self.cylinder()),
            Shape::Capsule => capsule_energy(p, r, t0, t1, &self.beam.capsule),
            Shape::Beam => beam_energy(p, r, t0, t1, &self.beam),
        }
    }
}

fn v32(v: Vec3d) -> Vec3<f32> {
    v.as_f32()
}

impl Case<f64> {
    /// The case with every input rounded to `f32`.
    pub fn to_f32(self) -> Case<f32> {
        let c = &self.beam.capsule;
        Case {
            p: FieldParams { falloff: self.p.falloff, core_radius: self.p.core_radius as f32 },
            ray: Ray { origin: v32(self.ray.origin), dir: v32(self.ray.dir) },
            t0: self.t0 as f32,
            t1: self.t1 as f32,
            beam: BeamField {
                capsule: CapsuleField {
                    m: v32(c.m),
                    d: v32(c.d),
                    length: c.length as f32,
                    alpha_s: c.alpha_s as f32,
                    alpha_c: c.alpha_c as f32,
                },
                head_alpha: self.beam.head_alpha as f32,
                muzzle_alpha: self.beam.muzzle_alpha as f32,
            },
        }
    }

    /// The density law applied to a regularised squared distance.
    fn law(&self, rho2: f64) -> f64 {
        match self.p.falloff {
            Falloff::Faithful => 1.0 / rho2.sqrt(),
            Falloff::InverseSquare => 1.0 / rho2,
        }
    }

    /// The density of `shape` at `V(t) = S + tQ`, `t = base + x`, straight from the definitions
    /// (002 eq. 3.4, 3.5, 3.11). The offsets `V(t) − M` and the squared distances are formed in
    /// double-double arithmetic from `base` and `x` separately, so that rays passing 1e-9 from a
    /// centre still see a smooth integrand however small `x` gets next to a break point.
    pub fn density(&self, shape: Shape, base: f64, x: f64) -> f64 {
        let t = base + x;
        let c = &self.beam.capsule;
        let (s, q) = (self.ray.origin, self.ray.dir);
        let rc2 = self.p.core_radius * self.p.core_radius;
        let m2 = c.m + c.d * c.length;
        let offset = |m: Vec3d| {
            let f = |s: f64, q: f64, m: f64| Dd::sum(s, -m).add(Dd::prod(base, q)).add(Dd::prod(x, q));
            [f(s.x, q.x, m.x), f(s.y, q.y, m.y), f(s.z, q.z, m.z)]
        };
        let len2 = |v: [Dd; 3]| v[0].mul(v[0]).add(v[1].mul(v[1])).add(v[2].mul(v[2])).to_f64();
        let sph = |m: Vec3d| self.law(len2(offset(m)) + rc2);
        let cyl = || {
            let o = offset(c.m);
            let d = [c.d.x, c.d.y, c.d.z].map(Dd::from);
            let cr = [
                o[1].mul(d[2]).add(o[2].mul(d[1]).neg()),
                o[2].mul(d[0]).add(o[0].mul(d[2]).neg()),
                o[0].mul(d[1]).add(o[1].mul(d[0]).neg()),
            ];
            self.law(len2(cr) + rc2)
        };
        let capsule = || {
            let x = s + q * t;
            let z = (x - c.m).dot(c.d);
            if z < 0.0 {
                c.alpha_s * sph(c.m)
            } else if z > c.length {
                c.alpha_s * sph(m2)
            } else {
                c.alpha_c * cyl()
            }
        };
        match shape {
            Shape::Sphere => c.alpha_s * sph(c.m),
            Shape::Cylinder => c.alpha_c * cyl(),
            Shape::Capsule => capsule(),
            Shape::Beam => capsule() + self.beam.head_alpha * sph(m2) + self.beam.muzzle_alpha * sph(c.m),
        }
    }

    /// Converged adaptive quadrature of `shape` along the ray, with break points at every closest
    /// approach and plane crossing inside the interval.
    pub fn reference(&self, shape: Shape) -> Quadrature {
        self.reference_weighted(shape, &[], |_| 1.0)
    }

    /// [`Self::reference`] of the density times `weight(t)`, with `extra` break points (where
    /// the weight has a kink or a branch point).
    pub fn reference_weighted(&self, shape: Shape, extra: &[f64], weight: impl Fn(f64) -> f64) -> Quadrature {
        let c = &self.beam.capsule;
        let (s, q) = (self.ray.origin, self.ray.dir);
        let w = s - c.m;
        let m2 = c.m + c.d * c.length;
        let mut breaks = vec![self.t0, self.t1];
        let mut add = |t: f64| {
            if t.is_finite() && t > self.t0 && t < self.t1 {
                breaks.push(t);
            }
        };
        add(-q.dot(w) / q.length_squared());
        add(-q.dot(s - m2) / q.length_squared());
        let u = q.cross(c.d);
        if u.length_squared() > 0.0 {
            add(-u.dot(w.cross(c.d)) / u.length_squared());
        }
        let dq = q.dot(c.d);
        if dq != 0.0 {
            add(-w.dot(c.d) / dq);
            add((c.length - w.dot(c.d)) / dq);
        }
        for &t in extra {
            add(t);
        }
        breaks.sort_by(f64::total_cmp);
        breaks.dedup();
        // Each piece in two halves, each integrated in the distance from its break point.
        let mut total = Quadrature { value: 0.0, error_estimate: 0.0, evaluations: 0, converged: true };
        let mut add_q = |q: Quadrature| {
            total.value += q.value;
            total.error_estimate += q.error_estimate;
            total.evaluations += q.evaluations;
            total.converged &= q.converged;
        };
        for w in breaks.windows(2) {
            let (a, b) = (w[0], w[1]);
            if b.is_finite() {
                let half = 0.5 * (b - a);
                let fa = |x: f64| self.density(shape, a, x) * weight(a + x);
                let fb = |x: f64| self.density(shape, b, -x) * weight(b - x);
                add_q(integrate_adaptive_breaks(fa, &[0.0, half], 1e-12, 0.0));
                add_q(integrate_adaptive_breaks(fb, &[0.0, half], 1e-12, 0.0));
            } else {
                let fa = |x: f64| self.density(shape, a, x) * weight(a + x);
                add_q(integrate_adaptive_breaks(fa, &[0.0, b], 1e-12, 0.0));
            }
        }
        total
    }
}

/// Relative difference `|x − r|/|r|` (absolute where `r = 0`).
pub fn rel(x: f64, r: f64) -> f64 {
    if r == 0.0 {
        x.abs()
    } else {
        ((x - r) / r).abs()
    }
}

/// A random beam with `M` near the origin.
pub fn random_beam(rng: &mut Rng) -> BeamField<f64> {
    let alpha_s = rng.range(0.2, 2.0);
    BeamField {
        capsule: CapsuleField {
            m: rng.in_cube(2.0),
            d: rng.unit_vec(),
            length: if rng.below(8) == 0 { 0.0 } else { rng.range(0.0, 6.0) },
            alpha_s,
            alpha_c: if rng.below(2) == 0 { alpha_s } else { rng.range(0.2, 2.0) },
        },
        head_alpha: rng.range(0.0, 2.0),
        muzzle_alpha: if rng.below(3) == 0 { 0.0 } else { rng.range(0.0, 1.0) },
    }
}

/// A random core radius: 0, small, or moderate.
pub fn random_core(rng: &mut Rng) -> f64 {
    match rng.below(4) {
        0 => 0.0,
        1 => rng.log_range(1e-4, 1e-2),
        // (the f32 tests of rays near a centre override this with `core_override`)
        2 => rng.range(0.01, 0.3),
        _ => rng.range(0.3, 2.0),
    }
}

/// A ray from `eye` along unit `n` in the form `falloff` wants, with a random interval.
pub fn make_case(
    rng: &mut Rng,
    falloff: Falloff,
    eye: Vec3d,
    n: Vec3d,
    core: f64,
    beam: BeamField<f64>,
) -> Case<f64> {
    let p = FieldParams { falloff, core_radius: core };
    match falloff {
        Falloff::Faithful => {
            // |Q| from 1 to 1e4 (the far plane), t over part or all of [0, 1].
            let far = rng.log_range(1.0, 1e4);
            let (t0, t1) = match rng.below(3) {
                0 => (0.0, 1.0),
                1 => (0.0, rng.range(0.0, 1.0)),
                _ => {
                    let a = rng.range(0.0, 1.0);
                    (a, rng.range(a, 1.0))
                }
            };
            Case { p, ray: Ray { origin: eye, dir: n * far }, t0, t1, beam }
        }
        Falloff::InverseSquare => {
            let t0 = if rng.below(2) == 0 { 0.0 } else { rng.range(0.0, 20.0) };
            let t1 = match rng.below(3) {
                0 => f64::INFINITY,
                1 => t0 + rng.log_range(1e-3, 1e4),
                _ => t0 + rng.range(0.0, 30.0),
            };
            Case { p, ray: Ray { origin: eye, dir: n }, t0, t1, beam }
        }
    }
}

/// A unit vector perpendicular to `n`.
pub fn perpendicular(rng: &mut Rng, n: Vec3d) -> Vec3d {
    loop {
        let r = rng.unit_vec();
        let p = r - n * r.dot(n);
        if let Some(u) = p.try_normalize() {
            return u;
        }
    }
}

/// The ray classes of the accuracy tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayClass {
    /// Eye in a box around the beam, any direction.
    Generic,
    /// Passing within 1e-6..1e-4 of `M`, `M₂` or a point of the axis.
    NearCentre,
    /// Passing within 1e-9..1e-6 of `M`, `M₂` or a point of the axis: below what `f64` resolves
    /// at scene scale with `r_c = 0`, so tolerances include the conditioning.
    Grazing,
    /// Eye up to 1e4 away, looking roughly at the beam.
    Far,
}

/// A random case of `class`.
pub fn random_case(rng: &mut Rng, class: RayClass, falloff: Falloff) -> Case<f64> {
    let beam = random_beam(rng);
    let core = random_core(rng);
    let c = beam.capsule;
    match class {
        RayClass::Generic => {
            let eye = rng.in_cube(10.0);
            let n = rng.unit_vec();
            make_case(rng, falloff, eye, n, core, beam)
        }
        RayClass::NearCentre | RayClass::Grazing => {
            let target = match rng.below(3) {
                0 => c.m,
                1 => c.m + c.d * c.length,
                _ => c.m + c.d * rng.range(-2.0, c.length + 2.0),
            };
            let eye = target + rng.unit_vec() * rng.range(1.0, 15.0);
            let n0 = (target - eye).normalize_or(Vec3::X);
            let miss = perpendicular(rng, n0)
                * if class == RayClass::Grazing {
                    rng.log_range(1e-9, 1e-6)
                } else {
                    rng.log_range(1e-6, 1e-4)
                };
            let n = (target + miss - eye).normalize_or(Vec3::X);
            make_case(rng, falloff, eye, n, core, beam)
        }
        RayClass::Far => {
            let dist = rng.log_range(10.0, 1e4);
            let eye = c.m + rng.unit_vec() * dist;
            let look = c.m + rng.in_cube(3.0 + c.length);
            let n = (look - eye).normalize_or(Vec3::X);
            let mut case = make_case(rng, falloff, eye, n, core, beam);
            if falloff == Falloff::Faithful {
                // The far plane must reach the beam: |Q| ≥ distance.
                let far = rng.log_range(dist * 1.5, 1e4_f64.max(dist * 2.0));
                case.ray.dir = n * far;
            }
            case
        }
    }
}

/// A double-double number `hi + lo` (about 106 bits), enough to form distances to 1e-7 without
/// cancellation noise.
#[derive(Clone, Copy, Debug)]
pub struct Dd {
    hi: f64,
    lo: f64,
}

impl Dd {
    /// Exact `a + b`.
    pub fn sum(a: f64, b: f64) -> Self {
        let s = a + b;
        let bb = s - a;
        Dd { hi: s, lo: (a - (s - bb)) + (b - bb) }
    }
    /// Exact `a·b`.
    pub fn prod(a: f64, b: f64) -> Self {
        let p = a * b;
        Dd { hi: p, lo: a.mul_add(b, -p) }
    }
    /// Sum.
    pub fn add(self, o: Self) -> Self {
        let s = Dd::sum(self.hi, o.hi);
        let lo = s.lo + self.lo + o.lo;
        Dd::sum(s.hi, lo)
    }
    /// Product.
    pub fn mul(self, o: Self) -> Self {
        let p = Dd::prod(self.hi, o.hi);
        let lo = p.lo + self.hi * o.lo + self.lo * o.hi;
        Dd::sum(p.hi, lo)
    }
    /// Negation.
    pub fn neg(self) -> Self {
        Dd { hi: -self.hi, lo: -self.lo }
    }
    /// Rounded to `f64`.
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }
}

impl From<f64> for Dd {
    fn from(x: f64) -> Self {
        Dd { hi: x, lo: 0.0 }
    }
}

/// The relative error an evaluation with machine epsilon `eps` cannot avoid on `case`: forming
/// `S − M`, `Q/|Q|` and the cross products rounds the ray's position relative to the field by
/// about `δ = 4·eps·scale` (`scale` = the eye's distance to the farther end). Measured as four
/// times the largest relative change of the `f64` closed form when the eye moves by `δ` along each axis and
/// towards or away from `M`, `M₂` and the axis (which can take a ray that passes closer than `δ`
/// right through a centre).
pub fn conditioning(case: &Case<f64>, shape: Shape, eps: f64) -> f64 {
    let c = &case.beam.capsule;
    let (s, q) = (case.ray.origin, case.ray.dir);
    let m2 = c.m + c.d * c.length;
    let scale = (s - c.m).length().max((s - m2).length());
    let delta = 4.0 * eps * scale;
    let n = q.normalize_or(Vec3::X);
    // Vectors from the ray's closest point to each target, perpendicular to the ray.
    let towards = |target: Vec3d| {
        let w = target - s;
        w - n * w.dot(n)
    };
    let mut moves = vec![Vec3::X * delta, Vec3::Y * delta, Vec3::Z * delta];
    let mut targets = vec![towards(c.m), towards(m2)];
    let u = n.cross(c.d);
    if let Some(u) = u.try_normalize() {
        // Common normal of the ray and the axis: the ray's offset from the axis along it.
        let off = u * u.dot(c.m - s);
        targets.push(off);
    }
    for t in targets {
        let d = t.length();
        if d > 0.0 {
            moves.push(t * (delta.min(d) / d));
            moves.push(t * (delta / d));
        }
    }
    let base = case.closed(shape);
    let mut worst = 0.0f64;
    for mv in moves {
        for sign in [-1.0, 1.0] {
            let mut moved = *case;
            moved.ray.origin += mv * sign;
            worst = worst.max(rel(moved.closed(shape), base));
        }
    }
    4.0 * worst
}
