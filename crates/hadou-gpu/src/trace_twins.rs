//! The WGSL twin test of the traced resolve's per-pixel work (`shaders/soft_trace.wgsl`): random
//! receivers, lamps of every shape and triangles, each case's samples hidden by one triangle
//! (`occlude`) and the hierarchy's tests (`capsule_hits`, `one_side`, `box_may_hide`) computed on
//! the GPU and by hadou-math, compared case by case.

use crate::layout::{FrameUniforms, GpuBvhNode, GpuBvhTri, TracedUniforms};
use crate::shaders::{compose, COMMON, SOFT_TRACE};
use crate::twin_kernel::Rng;
use bytemuck::{Pod, Zeroable};
use hadou_math::soft::{
    capsule_hits, lamp_frame, mask_visibility, occlude, pixel_offset, BvhTri, LampPattern, LampShape,
    MASK_WORDS,
};
use hadou_math::Vec3f;

/// One case: the lamp (centre, axis, size, shape), the layout, the receiver, the triangle, the
/// pixel, and a box and a ball for the hierarchy's tests.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Case {
    centre: [f32; 4],
    axis: [f32; 4],
    receiver: [f32; 4],
    box_lo: [f32; 4],
    box_hi: [f32; 4],
    /// `(shape, samples, x, y)` as `u32`s.
    words: [u32; 4],
    tri: GpuBvhTri,
}

/// Per case, four results: the hidden samples' count, the visibility, `capsule_hits` of the box's
/// ball and `box_may_hide` of the box (1 or 0), `one_side` of the triangle.
const KERNEL: &str = r#"
var<private> frame: FrameUniforms;
var<private> traced: TracedUniforms;
@group(0) @binding(3) var<storage, read> nodes: array<BvhNode>;
@group(0) @binding(4) var<storage, read> tris: array<BvhTri>;

struct Case {
    centre: vec4<f32>,
    axis: vec4<f32>,
    receiver: vec4<f32>,
    box_lo: vec4<f32>,
    box_hi: vec4<f32>,
    words: vec4<u32>,
    tri: BvhTri,
}

@group(0) @binding(0) var<storage, read> cases: array<Case>;
@group(0) @binding(1) var<storage, read_write> results: array<f32>;
@group(0) @binding(2) var<storage, read> patterns: array<TracedUniforms>;

@compute @workgroup_size(64, 1, 1)
fn twin_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = arrayLength(&cases);
    if (id.x >= n) {
        return;
    }
    let c = cases[id.x];
    frame.area_position = c.centre.xyz;
    frame.area_size = c.centre.w;
    frame.area_axis = c.axis.xyz;
    frame.area_shape = c.words.x;
    traced = patterns[id.x];
    var mask: Mask;
    for (var w = 0u; w < MASK_WORDS; w++) {
        mask[w] = 0u;
    }
    let f = lamp_frame(c.receiver.xyz);
    var hidden = -1.0;
    var vis = -1.0;
    var boxes = 0.0;
    if (f.ok) {
        occlude(f, pixel_offset(c.words.z, c.words.w), c.tri, &mask);
        hidden = f32(count_bits(&mask, 0u, samples()));
        vis = mask_visibility(&mask);
        let centre = (c.box_lo.xyz + c.box_hi.xyz) * 0.5;
        let radius = length3(c.box_hi.xyz - c.box_lo.xyz) * 0.5;
        if (capsule_hits(c.receiver.xyz, 0.0, c.centre.xyz, c.centre.w, centre, radius)) {
            boxes += 1.0;
        }
        if (box_may_hide(f, c.box_lo.xyz, c.box_hi.xyz, traced.disc != 0u)) {
            boxes += 2.0;
        }
    }
    results[4u * id.x] = hidden;
    results[4u * id.x + 1u] = vis;
    results[4u * id.x + 2u] = boxes;
    results[4u * id.x + 3u] = select(0.0, 1.0, one_side(c.tri, c.receiver.xyz, c.centre.xyz, c.centre.w));
}
"#;

fn v3(r: &mut Rng, lo: f32, hi: f32) -> Vec3f {
    Vec3f::new(r.range_f32(lo, hi), r.range_f32(lo, hi), r.range_f32(lo, hi))
}

#[test]
fn wgsl_trace_functions_match_their_rust_twins() {
    let Some((ctx, _gpu)) = crate::device::context_or_skip("traced resolve twins") else { return };
    let mut rng = Rng(43);
    let shapes = [LampShape::Segment, LampShape::Disc, LampShape::Sphere];
    let mut cases = Vec::new();
    let mut patterns = Vec::new();
    let mut rust = Vec::new();
    for k in 0..3000u32 {
        let shape = shapes[k as usize % 3];
        let centre = Vec3f::new(rng.range_f32(1.0, 3.0), rng.range_f32(2.0, 4.0), rng.range_f32(-1.0, 1.0));
        let axis = (centre - v3(&mut rng, -0.5, 0.5)).normalize_or(Vec3f::Y);
        let size = rng.range_f32(0.1, 0.8);
        let receiver =
            Vec3f::new(rng.range_f32(-3.0, 1.0), rng.range_f32(-0.5, 2.0), rng.range_f32(-2.0, 1.0));
        // A triangle somewhere between, of every size and slant (slivers included).
        let mid = receiver.lerp(centre, rng.range_f32(0.05, 0.95)) + v3(&mut rng, -0.4, 0.4);
        let spread = rng.range_f32(0.01, 1.2);
        let a = mid + v3(&mut rng, -spread, spread);
        let b = mid + v3(&mut rng, -spread, spread);
        let c = if k % 7 == 0 {
            a.lerp(b, 0.3) + v3(&mut rng, -1e-3, 1e-3)
        } else {
            mid + v3(&mut rng, -spread, spread)
        };
        let tri = BvhTri::new(a, b, c);
        let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
        let samples = [64u32, 256, 100, 1024][k as usize % 4];
        let (x, y) = (k % 97, k / 97);
        let pattern = LampPattern::new(shape, samples);
        cases.push(Case {
            centre: [centre.x, centre.y, centre.z, size],
            axis: [axis.x, axis.y, axis.z, 0.0],
            receiver: [receiver.x, receiver.y, receiver.z, 0.0],
            box_lo: [lo.x, lo.y, lo.z, 0.0],
            box_hi: [hi.x, hi.y, hi.z, 0.0],
            words: [crate::layout::lamp_shape(shape), samples, x, y],
            tri: GpuBvhTri::from(&tri),
        });
        patterns.push(TracedUniforms::new(&pattern, 0));
        let expected = lamp_frame(shape, centre, axis, size, receiver).map(|f| {
            let mut mask = [0u32; MASK_WORDS];
            occlude(&f, &pattern, pixel_offset(x, y), &tri.corners(), &mut mask);
            let hidden: u32 = mask.iter().map(|w| w.count_ones()).sum();
            let centre_box = (lo + hi) * 0.5;
            let radius = (hi - lo).length() * 0.5;
            let boxes = u32::from(capsule_hits(receiver, 0.0, centre, size, centre_box, radius))
                + 2 * u32::from(f.box_may_hide(
                    lo.to_array(),
                    hi.to_array(),
                    &pattern,
                    pixel_offset(x, y),
                    &[0; MASK_WORDS],
                ));
            (hidden, mask_visibility(&mask, &pattern), boxes)
        });
        rust.push((expected, tri.one_side(receiver, 0.0, centre, size)));
    }
    let _ = std::mem::size_of::<FrameUniforms>();
    let source = compose(&[COMMON, SOFT_TRACE, KERNEL]);
    // The hierarchy's bindings are unused here (the walk is the next test's).
    let inputs = [(0, bytemuck::cast_slice(&cases)), (2, bytemuck::cast_slice(&patterns))];
    let out = crate::twin_kernel::run(&ctx, "traced twins", &source, &inputs, 4 * cases.len())
        .expect("GPU twin run");
    let (mut hidden_off, mut partial, mut worst) = (0usize, 0usize, 0.0f32);
    for (i, (expected, one_side)) in rust.iter().enumerate() {
        let g = &out[4 * i..4 * i + 4];
        assert_eq!(g[3] == 1.0, *one_side, "case {i}: one_side");
        match expected {
            None => assert_eq!(g[0], -1.0, "case {i}: the lamp has no frame on the CPU"),
            Some((hidden, vis, boxes)) => {
                assert!(g[0] >= 0.0, "case {i}: the lamp has a frame on the CPU");
                let n = patterns[i].rows * patterns[i].per_row;
                if *hidden > 0 && *hidden < n {
                    partial += 1;
                }
                // A sample within rounding of an edge may go either way: at most two a row.
                let off = (g[0] - *hidden as f32).abs();
                if off > 0.0 {
                    hidden_off += 1;
                }
                assert!(
                    off <= 2.0 * patterns[i].rows as f32,
                    "case {i}: {} hidden on the GPU, {hidden} on the CPU",
                    g[0]
                );
                worst = worst.max((g[1] - vis).abs());
                // The hierarchy's tests may only keep more than the CPU's (the GPU's box test asks
                // only whether the box's projection meets the lamp, the CPU's also whether it
                // holds a clear sample): never drop a box the CPU keeps.
                let gb = g[2] as u32;
                assert_eq!(
                    gb & boxes,
                    *boxes,
                    "case {i}: the GPU drops a box the CPU keeps ({gb} vs {boxes})"
                );
            }
        }
    }
    eprintln!(
        "{} cases, {partial} partly hiding, {hidden_off} with another count, worst visibility {worst}",
        cases.len()
    );
    assert!(partial > 300, "only {partial} cases hide part of the lamp");
    assert!(hidden_off * 100 <= cases.len(), "{hidden_off} cases differ");
}

/// The walk (`pixel_visibility`): the plaster cast's hierarchy (the figure and the wall), the
/// receivers of its visible points as hadou-cpu finds them, every lamp shape: the GPU's
/// visibility within one sample a row of hadou-cpu's `traced` at every receiver.
#[test]
fn wgsl_trace_walk_matches_the_cpu() {
    let Some((ctx, _gpu)) = crate::device::context_or_skip("traced walk twins") else { return };
    const WALK: &str = r#"
var<private> frame: FrameUniforms;
@group(0) @binding(0) var<storage, read> cases: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> results: array<f32>;
@group(0) @binding(2) var<storage, read> lamp: array<vec4<f32>, 2>;
@group(0) @binding(6) var<storage, read> words: array<u32>;
@group(0) @binding(3) var<storage, read> nodes: array<BvhNode>;
@group(0) @binding(4) var<storage, read> tris: array<BvhTri>;
@group(0) @binding(5) var<storage, read> patterns: array<TracedUniforms>;
var<private> traced: TracedUniforms;

@compute @workgroup_size(64, 1, 1)
fn twin_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= arrayLength(&cases)) {
        return;
    }
    frame.area_position = lamp[0].xyz;
    frame.area_size = lamp[0].w;
    frame.area_axis = lamp[1].xyz;
    frame.area_shape = words[0];
    traced = patterns[0];
    let c = cases[id.x];
    let xy = words[1u + id.x];
    results[id.x] = pixel_visibility(c.xyz, xy & 0xffffu, xy >> 16u);
}
"#;
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/soft-plaster.toml");
    let mut frame = hadou_scene::Scene::load(path).expect("the example scene").at(1.5);
    (frame.width, frame.height, frame.samples) = (96, 72, 1);
    let source = compose(&[COMMON, SOFT_TRACE, WALK]);
    for shape in [LampShape::Segment, LampShape::Disc, LampShape::Sphere] {
        let light = frame.area_light.as_mut().expect("an area light");
        light.shape = shape;
        let light = light.clone();
        let input = hadou_cpu::soft::soft_input(&frame).expect("an area light");
        let bvh = hadou_math::soft::Bvh::build(&hadou_scene::caster_triangles(&frame, &light.casters));
        let cpu = hadou_cpu::traced::traced_with(&bvh, &light, &input.points, input.width, 256);
        let w = input.width;
        let (mut cases, mut want) = (Vec::new(), Vec::new());
        // The shape, then each receiver's pixel (x | y << 16).
        let mut words = vec![crate::layout::lamp_shape(shape)];
        for (i, p) in input.points.iter().enumerate() {
            let Some(p) = p.filter(|p| p.term.iter().any(|&t| t > 0.0)) else { continue };
            let r = hadou_cpu::traced::receiver(p.world, p.normal, light.position);
            let xy = (i % w) as u32 | ((i / w) as u32) << 16;
            cases.push([r.x, r.y, r.z, 0.0]);
            words.push(xy);
            want.push(cpu[i]);
        }
        let axis = light.axis();
        let lamp = [
            [light.position.x, light.position.y, light.position.z, light.size],
            [axis.x, axis.y, axis.z, 0.0],
        ];
        let pattern = TracedUniforms::new(&LampPattern::new(shape, 256), bvh.nodes.len() as u32);
        let nodes: Vec<GpuBvhNode> = bvh.nodes.iter().map(GpuBvhNode::from).collect();
        let tris: Vec<GpuBvhTri> = bvh.tris.iter().map(GpuBvhTri::from).collect();
        let inputs = [
            (0, bytemuck::cast_slice(&cases)),
            (2, bytemuck::cast_slice(&lamp)),
            (3, bytemuck::cast_slice(&nodes)),
            (4, bytemuck::cast_slice(&tris)),
            (5, bytemuck::bytes_of(&pattern)),
            (6, bytemuck::cast_slice(&words)),
        ];
        let out = crate::twin_kernel::run(&ctx, "traced walk twins", &source, &inputs, cases.len())
            .expect("GPU run");
        let step = 2.0 * pattern.rows as f32 / 256.0 + 1e-6;
        let off: Vec<usize> = (0..cases.len()).filter(|&k| (out[k] - want[k]).abs() > step).collect();
        for &k in off.iter().take(5) {
            eprintln!("{shape:?}: receiver {k}: GPU {} CPU {}", out[k], want[k]);
        }
        let partly = want.iter().filter(|&&v| v > 0.005 && v < 0.995).count();
        eprintln!("{shape:?}: {} receivers, {partly} partly lit, {} off", cases.len(), off.len());
        assert!(partly > 50, "{shape:?}: only {partly} receivers partly lit");
        assert!(
            off.len() * 500 <= cases.len(),
            "{shape:?}: {} of {} receivers differ",
            off.len(),
            cases.len()
        );
    }
}
