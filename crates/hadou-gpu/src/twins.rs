//! The WGSL energy functions against their Rust twins, ray by ray, including the degenerate rays
//! whole frames rarely hit exactly (through a centre, along or parallel to an axis, on a capsule's
//! splitting plane, perpendicular to its axis, zero-length capsules, rays open to infinity).

use crate::device::GpuContext;
use crate::layout::{GpuWave, FALLOFF_FAITHFUL, WAVE_BEAM, WAVE_CAPSULE, WAVE_CYLINDER, WAVE_SPHERE};
use crate::shaders;
use crate::twin_kernel::{self, Rng};
use bytemuck::{Pod, Zeroable};
use hadou_math::energy::{
    self, Attenuation, BeamField, CapsuleField, CylinderField, Falloff, FieldParams, Ray, SphereField,
};
use hadou_math::{Real, Vec3, Vec3f};
use hadou_scene::RenderError;

/// One test ray for one wave. `span = [t0, t1, open_end, t_far]` (`t_far`: the far point's ray
/// parameter, read where the wave's `attenuation` is not 0).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Case {
    wave: GpuWave,
    origin: [f32; 4],
    dir: [f32; 4],
    span: [f32; 4],
}

/// The WGSL of one case's energy (see `twin_kernel::source`).
const KERNEL: &str = r#"
struct Case {
    wave: GpuWave,
    origin: vec4<f32>,
    dir: vec4<f32>,
    span: vec4<f32>,
}

fn case_energy(c: Case, ray: Ray, t0: f32, t1: f32) -> f32 {
    let w = c.wave;
    let p = FieldParams(w.falloff, w.core_radius);
    // span.w: the far point's ray parameter for the attenuation (w.attenuation = j).
    let att = Attenuation(w.attenuation, c.span.w);
    if (DIRECT && w.attenuation == 0.0) {
        return analytic_energy_direct(p, ray, t0, t1, w, KIND_BITS_ALL);
    }
    return analytic_energy(p, ray, t0, t1, att, w, KIND_BITS_ALL);
}
"#;

/// Runs the WGSL energy functions on `cases`: `analytic_energy` (what a module with attenuation
/// runs), or with `direct` its twin without arrays `analytic_energy_direct` where j = 0 (what the
/// wave pass runs for a frame without attenuation).
fn run_gpu(ctx: &GpuContext, cases: &[Case], direct: bool) -> Result<Vec<f32>, RenderError> {
    let kernel = format!("const DIRECT: bool = {direct};\n{KERNEL}");
    let source = twin_kernel::source(&[shaders::COMMON, shaders::ENERGY], &kernel);
    twin_kernel::run(ctx, "energy twins", &source, &[(0, bytemuck::cast_slice(cases))], cases.len())
}

/// The Rust twin of one case.
fn run_cpu(c: &Case) -> f32 {
    energy_of::<f32>(c, [0.0; 3])
}

/// One case's energy by the Rust formulas in precision `R`, with the ray's origin moved by `shift`.
fn energy_of<R: Real>(c: &Case, shift: [f64; 3]) -> R {
    let w = &c.wave;
    let r = |v: f32| R::from_f64(f64::from(v));
    let v = |a: [f32; 4]| Vec3::new(r(a[0]), r(a[1]), r(a[2]));
    let falloff = if w.falloff == FALLOFF_FAITHFUL { Falloff::Faithful } else { Falloff::InverseSquare };
    let p = FieldParams { falloff, core_radius: r(w.core_radius) };
    let o = [0, 1, 2].map(|k| R::from_f64(f64::from(c.origin[k]) + shift[k]));
    let ray = Ray { origin: Vec3::new(o[0], o[1], o[2]), dir: v(c.dir) };
    let t0 = r(c.span[0]);
    let t1 = if c.span[2] != 0.0 { R::from_f64(f64::INFINITY) } else { r(c.span[1]) };
    // j = 0: the attenuated functions are the plain closed forms, bit for bit.
    let att = Attenuation { j: r(w.attenuation), t_far: r(c.span[3]) };
    let capsule =
        CapsuleField { m: v(w.p0), d: v(w.p1), length: r(w.p2[0]), alpha_s: r(w.p0[3]), alpha_c: r(w.p1[3]) };
    match w.kind {
        WAVE_SPHERE => {
            let f = SphereField { center: v(w.p0), alpha: r(w.p0[3]) };
            energy::sphere_energy_attenuated(&p, &ray, t0, t1, &att, &f)
        }
        WAVE_CYLINDER => {
            let f = CylinderField { point: v(w.p0), dir: v(w.p1), alpha: r(w.p0[3]) };
            energy::cylinder_energy_attenuated(&p, &ray, t0, t1, &att, &f)
        }
        WAVE_CAPSULE => energy::capsule_energy_attenuated(&p, &ray, t0, t1, &att, &capsule),
        _ => {
            let f = BeamField { capsule, head_alpha: r(w.p2[1]), muzzle_alpha: r(w.p2[2]) };
            energy::beam_energy_attenuated(&p, &ray, t0, t1, &att, &f)
        }
    }
}

/// The relative error of a GPU energy `g` against its Rust twin `r` (both `f32`), judged by the
/// conditioning of the ray where they differ by more than 1e-3.
///
/// On a ray through a centre, an axis or a curve with no core radius the energy diverges as the
/// ray closes in, so the `f32` answer is decided by rounding: two correct evaluations that round
/// differently (a GPU compiler fusing multiply-adds, WGSL's `sin`/`cos` against Rust's) land
/// far apart, and so does a sampling rule (Simpson) whose sample falls next to the singularity
/// on one side only. There the GPU is compared with the exact `f64` energy of the same ray
/// (`exact` of a zero shift): it must be no further from it than the largest of the Rust twin's
/// distance to it, the change of the exact energy, and the change of the Rust twin (`twin`), when
/// the ray's origin moves by [`CONDITION_ULPS`] ulps of its largest coordinate along any axis.
/// Energies at the saturation ceiling (both ≥ 2¹²⁷, within a factor 2 of `f32::MAX`) agree. On a
/// well-conditioned ray the two agree to 1e-3 and neither closure is called.
pub(crate) fn conditioned_error(
    g: f32,
    r: f32,
    origin: [f32; 4],
    exact: impl Fn([f64; 3]) -> f64,
    twin: impl Fn([f64; 3]) -> f32,
) -> f32 {
    let err = (g - r).abs() / r.abs().max(1e-6);
    let ceiling = 2f32.powi(127);
    if g >= ceiling && r >= ceiling {
        return 0.0;
    }
    if err <= 1e-3 {
        return err;
    }
    let scale = origin[..3].iter().fold(1.0f32, |m, v| m.max(v.abs()));
    let delta = f64::from(scale) * f64::from(f32::EPSILON) * CONDITION_ULPS;
    let at = exact([0.0; 3]);
    let mut allowed = (f64::from(r) - at).abs();
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let mut shift = [0.0; 3];
            shift[axis] = sign * delta;
            allowed = allowed.max((exact(shift) - at).abs()).max(f64::from((twin(shift) - r).abs()));
        }
    }
    let excess = (f64::from(g) - at).abs() - allowed;
    (excess.max(0.0) / at.abs().max(1e-6)) as f32
}

/// Ray displacement, in ulps of the origin's largest coordinate, that [`conditioned_error`] tries.
pub(crate) const CONDITION_ULPS: f64 = 2.0;

fn wave(kind: u32, falloff: u32, core: f32, p0: [f32; 4], p1: [f32; 4], p2: [f32; 4]) -> GpuWave {
    GpuWave { color: [1.0; 4], kind, falloff, core_radius: core, attenuation: 0.0, p0, p1, p2 }
}

fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    let mut attenuated = Vec::new();
    let mut add = |w: GpuWave, o: Vec3f, d: Vec3f, t0: f32, t1: Option<f32>| {
        out.push(Case {
            wave: w,
            origin: [o.x, o.y, o.z, 0.0],
            dir: [d.x, d.y, d.z, 0.0],
            span: [t0, t1.unwrap_or(0.0), if t1.is_none() { 1.0 } else { 0.0 }, 0.0],
        })
    };
    let eye = Vec3::new(0.0, 0.0, 20.0);
    let x = Vec3f::X;
    for falloff in [FALLOFF_FAITHFUL, 1] {
        // Faithful rays are Q = E − S (|Q| ~ far); inverse-square rays are unit, maybe open-ended.
        let scale = if falloff == FALLOFF_FAITHFUL { 100.0 } else { 1.0 };
        let t1 = |g: f32| if falloff == FALLOFF_FAITHFUL { Some(g) } else { Some(g * 100.0) };
        let open = if falloff == FALLOFF_FAITHFUL { Some(1.0) } else { None };
        let toward = |p: Vec3f| (p - eye).normalize_or(x) * scale;
        for core in [0.0, 0.02] {
            // Through a sphere's centre, and just beside it.
            let sph = wave(WAVE_SPHERE, falloff, core, [0.0, 0.0, 0.0, 2.0], [0.0; 4], [0.0; 4]);
            add(sph, eye, toward(Vec3::ZERO), 0.0, open);
            add(sph, eye, toward(Vec3::new(1e-4, 0.0, 0.0)), 0.0, open);
            add(sph, eye, toward(Vec3::ZERO), 0.0, t1(0.1));
            // Along, and parallel to, a cylinder's axis (the integrand is constant); perpendicular.
            let cyl =
                wave(WAVE_CYLINDER, falloff, core, [0.0, 0.0, 0.0, 1.5], [0.0, 0.0, 1.0, 0.0], [0.0; 4]);
            add(cyl, eye, Vec3::new(0.0, 0.0, -scale), 0.0, t1(0.3));
            add(cyl, eye + Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.0, -scale), 0.0, t1(0.3));
            add(cyl, eye, toward(Vec3::new(3.0, 1.0, 0.0)), 0.0, open);
            // Capsule along x from (−5, 0, 0), length 10: ray perpendicular to D (D·Q = 0) inside,
            // before and beyond the ends; a ray in a splitting plane; a zero-length capsule.
            let cap = wave(
                WAVE_CAPSULE,
                falloff,
                core,
                [-5.0, 0.0, 0.0, 3.0],
                [1.0, 0.0, 0.0, 3.0],
                [10.0, 0.0, 0.0, 0.0],
            );
            for px in [0.0, -8.0, 9.0, -5.0, 5.0] {
                let o = Vec3::new(px, 2.0, 20.0);
                add(cap, o, Vec3::new(0.0, -0.1, -1.0).normalize_or(x) * scale, 0.0, open);
            }
            add(cap, eye, toward(Vec3::new(-5.0, 0.0, 0.0)), 0.0, open);
            let point =
                wave(WAVE_CAPSULE, falloff, core, [1.0, 1.0, 0.0, 3.0], [0.0, 1.0, 0.0, 3.0], [0.0; 4]);
            add(point, eye, toward(Vec3::new(1.0, 1.0, 0.0)), 0.0, open);
            add(point, eye, toward(Vec3::new(1.3, 1.0, 0.0)), 0.0, open);
            // Empty span.
            add(cap, eye, toward(Vec3::ZERO), 0.0, Some(0.0));
            // Saturation: a huge α on a ray through a centre or along an axis overflows f32; the
            // energy is f32::MAX on both sides (never 0 or NaN), and α = 0 there is exactly 0.
            for a in [f32::MAX, 1e9, 0.0] {
                let sph = wave(WAVE_SPHERE, falloff, core, [0.0, 0.0, 0.0, a], [0.0; 4], [0.0; 4]);
                add(sph, eye, toward(Vec3::ZERO), 0.0, open);
                let cyl =
                    wave(WAVE_CYLINDER, falloff, core, [0.0, 0.0, 0.0, a], [0.0, 0.0, 1.0, 0.0], [0.0; 4]);
                add(cyl, eye, Vec3::new(0.0, 0.0, -scale), 0.0, open);
                let z = [0.0, 0.0, 1.0, a];
                let cap = wave(WAVE_CAPSULE, falloff, core, [0.0, 0.0, -1.0, a], z, [2.0, 0.0, 0.0, 0.0]);
                add(cap, eye, Vec3::new(0.0, 0.0, -scale), 0.0, open);
                let beam = wave(WAVE_BEAM, falloff, core, [0.0, 0.0, -1.0, a], z, [2.0, a, a, 0.0]);
                add(beam, eye, Vec3::new(0.0, 0.0, -scale), 0.0, open);
            }
        }
        // Random rays and shapes.
        let mut rng = Rng(0x5EED + falloff as u64);
        for i in 0..400 {
            let core = if i % 3 == 0 { 0.0 } else { rng.range_f32(0.0, 0.2) };
            let m = rng.in_cube_f32(5.0);
            let d = rng.in_cube_f32(1.0).normalize_or(x);
            let len = rng.range_f32(0.0, 12.0);
            let kind = [WAVE_SPHERE, WAVE_CYLINDER, WAVE_CAPSULE, WAVE_BEAM][i % 4];
            let w = wave(
                kind,
                falloff,
                core,
                [m.x, m.y, m.z, rng.range_f32(0.1, 20.0)],
                [d.x, d.y, d.z, rng.range_f32(0.1, 20.0)],
                [len, rng.range_f32(0.0, 5.0), rng.range_f32(0.0, 5.0), 0.0],
            );
            let o = eye + rng.in_cube_f32(3.0);
            let target = m + d * rng.range_f32(-2.0, len + 2.0) + rng.in_cube_f32(1.0);
            let end = if rng.unit_f32() < 0.5 { open } else { t1(rng.range_f32(0.05, 0.5)) };
            add(w, o, (target - o).normalize_or(x) * scale, 0.0, end);
        }
        // Attenuated (002 eq. 3.23, SPEC.md §1.4): random j, the far point before, at and beyond
        // the shape (t_far = 1 for faithful rays, whose far point is E).
        for i in 0..240 {
            let core = if i % 4 == 0 { 0.0 } else { rng.range_f32(0.0, 0.2) };
            let m = rng.in_cube_f32(5.0);
            let d = rng.in_cube_f32(1.0).normalize_or(x);
            let len = rng.range_f32(0.0, 12.0);
            let kind = [WAVE_SPHERE, WAVE_CYLINDER, WAVE_CAPSULE, WAVE_BEAM][i % 4];
            let mut w = wave(
                kind,
                falloff,
                core,
                [m.x, m.y, m.z, rng.range_f32(0.1, 20.0)],
                [d.x, d.y, d.z, rng.range_f32(0.1, 20.0)],
                [len, rng.range_f32(0.0, 5.0), rng.range_f32(0.0, 5.0), 0.0],
            );
            w.attenuation = [0.3, 1.0, 2.0, 7.3, 64.0, rng.range_f32(0.0, 64.0)][i % 6];
            let o = eye + rng.in_cube_f32(3.0);
            let target = m + d * rng.range_f32(-2.0, len + 2.0) + rng.in_cube_f32(1.0);
            let dist = (target - o).length();
            let (far, t_far) = if falloff == FALLOFF_FAITHFUL {
                (dist * rng.range_f32(0.8, 3.0), 1.0)
            } else {
                (1.0, dist * rng.range_f32(0.8, 3.0))
            };
            let dir = (target - o).normalize_or(x) * far;
            let t1 = if rng.unit_f32() < 0.5 { 1.0 } else { rng.range_f32(0.3, 1.0) };
            let t1 = if falloff == FALLOFF_FAITHFUL { t1 } else { t1 * t_far * 1.2 };
            let open_end = 0.0;
            attenuated.push(Case {
                wave: w,
                origin: [o.x, o.y, o.z, 0.0],
                dir: [dir.x, dir.y, dir.z, 0.0],
                span: [0.0, t1, open_end, t_far],
            });
        }
    }
    out.extend(attenuated);
    out
}

#[test]
fn wgsl_energy_functions_match_their_rust_twins() {
    let Some((ctx, _gpu)) = crate::device::context_or_skip("energy twins") else { return };
    let cases = cases();
    for direct in [false, true] {
        let gpu = run_gpu(&ctx, &cases, direct).expect("GPU twin run");
        let mut worst = 0.0f32;
        let mut lit = 0;
        for (i, (c, g)) in cases.iter().zip(&gpu).enumerate() {
            let r = run_cpu(c);
            assert!(g.is_finite() && r.is_finite(), "direct {direct}, case {i}: gpu {g} cpu {r} ({c:?})");
            // 1e-3 relative (the backends' energy tolerance), absolute below 1e-6; on an
            // ill-conditioned ray, no worse than the Rust twin against the exact energy.
            let err = conditioned_error(
                *g,
                r,
                c.origin,
                |shift| energy_of::<f64>(c, shift),
                |shift| energy_of::<f32>(c, shift),
            );
            assert!(
                err <= 1e-3,
                "direct {direct}, case {i}: gpu {g} cpu {r}, rel {err:.2e} beyond its conditioning ({c:?})"
            );
            worst = worst.max(err);
            lit += usize::from(r > 1e-3);
        }
        assert!(lit * 2 > cases.len(), "most cases must carry real energy ({lit} of {})", cases.len());
        let saturated = cases.iter().zip(&gpu).filter(|(c, _)| run_cpu(c) == f32::MAX).count();
        // Saturation agrees up to rounding: where one side saturates, the other is at the ceiling
        // too (≥ 2¹²⁷; a log-divergent energy crosses f32::MAX on one side's rounding only).
        let ceiling = 2f32.powi(127);
        assert!(
            cases.iter().zip(&gpu).all(|(c, g)| {
                let r = run_cpu(c);
                (r == f32::MAX) == (*g == f32::MAX) || (r >= ceiling && *g >= ceiling)
            }),
            "saturated on one side only"
        );
        assert!(saturated >= 12, "only {saturated} saturated cases");
        eprintln!("direct {direct}: {} cases, worst relative difference {worst:.2e}", cases.len());
    }
}

/// `dot3`, `cross3` and `length3` (common.wgsl) round exactly as `hadou_math::Vec3`'s `dot`,
/// `cross` and `length` do, bit for bit, on every adapter that rounds each product (Mesa's
/// Vulkan and OpenGL drivers, for instance). The WGSL builtins do not on Mesa's OpenGL path
/// (fused multiply-adds inside `dot`/`length`), which made near-hit curve energies differ between
/// GL and Vulkan by up to 1 %. A compiler may still fuse written-out `a·b + c` (SPIR-V allows it
/// and NVIDIA's does, in some expressions only), so bit equality is required on llvmpipe and, on
/// other adapters or where a probe sees fusing, the products are held to
/// twice the error bound of a three-term sum, 6u·Σ|aᵢbᵢ| (u = 2⁻²⁴), instead of bit equality.
#[test]
fn written_out_vector_products_round_like_rust() {
    const PRODUCTS: &str = r#"
@group(0) @binding(0) var<storage, read> xs: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> results: array<f32>;
@compute @workgroup_size(64, 1, 1)
fn twin_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = arrayLength(&xs) / 2u;
    if (id.x >= n) {
        return;
    }
    let a = xs[2u * id.x].xyz;
    let b = xs[2u * id.x + 1u].xyz;
    let c = cross3(a, b);
    results[6u * id.x] = dot3(a, b);
    results[6u * id.x + 1u] = length3(a);
    results[6u * id.x + 2u] = c.x;
    results[6u * id.x + 3u] = c.y;
    results[6u * id.x + 4u] = c.z;
    // The contraction probe: rounded products, or a fused multiply-add?
    results[6u * id.x + 5u] = a.x * b.x - a.y * b.y;
}
"#;
    let Some((ctx, _gpu)) = crate::device::context_or_skip("vector products") else { return };
    // Nearly parallel and nearly orthogonal pairs, where rounding order shows most.
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut next = || rng.range_f32(-30.0, 30.0);
    let mut xs: Vec<[f32; 4]> = Vec::new();
    for i in 0..4096 {
        let a = [next(), next(), next(), 0.0];
        let b = if i % 2 == 0 {
            [a[0] * 0.999 + 1e-3, a[1], a[2] * 1.001, 0.0]
        } else {
            [next(), next(), next(), 0.0]
        };
        xs.push(a);
        xs.push(b);
    }
    let source = shaders::compose(&[shaders::COMMON, PRODUCTS]);
    let n = xs.len() / 2;
    let gpu = twin_kernel::run(&ctx, "vector products", &source, &[(0, bytemuck::cast_slice(&xs))], 6 * n)
        .expect("GPU vector products");
    let v = |p: [f32; 4]| Vec3f::new(p[0], p[1], p[2]);
    // Mesa's llvmpipe (Vulkan and OpenGL) rounds every product; other compilers may fuse.
    let probe_fuses = (0..n).any(|i| {
        let (a, b) = (v(xs[2 * i]), v(xs[2 * i + 1]));
        gpu[6 * i + 5] != a.x * b.x - a.y * b.y
    });
    let fuses = probe_fuses || !ctx.info.name.contains("llvmpipe");
    eprintln!("adapter `{}`: {}", ctx.info.name, if fuses { "error bound" } else { "bit equality" });
    for i in 0..n {
        let (a, b) = (v(xs[2 * i]), v(xs[2 * i + 1]));
        let c = a.cross(b);
        let want = [a.dot(b), a.length(), c.x, c.y, c.z];
        let [ax, ay, az, bx, by, bz] = [a.x, a.y, a.z, b.x, b.y, b.z].map(f64::from);
        // Σ|aᵢbᵢ| of each product, for the bound (the length's is that of a·a, halved by the root).
        let size = [ax * bx, ay * by, az * bz].map(f64::abs).iter().sum::<f64>();
        let cross_size = [ay * bz, az * by, az * bx, ax * bz, ax * by, ay * bx].map(f64::abs);
        let sizes = [
            size,
            f64::from(a.length()),
            cross_size[0] + cross_size[1],
            cross_size[2] + cross_size[3],
            cross_size[4] + cross_size[5],
        ];
        for (k, w) in want.iter().enumerate() {
            let g = gpu[6 * i + k];
            if fuses {
                let bound = 6.0 * sizes[k] * f64::from(f32::EPSILON / 2.0)
                    + f64::from(w.abs()) * f64::from(f32::EPSILON);
                assert!(
                    (f64::from(g) - f64::from(*w)).abs() <= bound,
                    "pair {i} product {k}: gpu {g:e} rust {w:e}"
                );
            } else {
                assert!(
                    g.to_bits() == w.to_bits(),
                    "pair {i} product {k}: gpu {g:e} rust {w:e} ({a:?}, {b:?})"
                );
            }
        }
    }
}
