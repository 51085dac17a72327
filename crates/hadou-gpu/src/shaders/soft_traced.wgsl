// The traced resolve of the `[area_light]` (twin of hadou-cpu's traced.rs; hadou's own, issue 43):
// every visible point's visibility is the share of the lamp it sees, from the lamp's samples
// against the casters' triangles found through the flattened bounding volume hierarchy
// (hadou_math::soft::Bvh, the same bytes as the CPU's). Per pixel: the receiver moved off its
// surface (TRACE_BIAS), the lamp as seen from it (lamp_frame), the stackless walk of the nodes whose
// ball meets the capsule between the receiver and the lamp's ball and whose box's projection meets
// the lamp (capsule_hits, box_may_hide), each triangle not leaving both on one side (one_side)
// setting the samples it hides in the pixel's mask (occlude), the walk ending once every sample is
// hidden; the visibility is the mask's weighted share of clear samples (mask_visibility). The
// samples depend only on the pixel's global coordinates (pixel_offset). Prepended by common.wgsl
// and soft_trace.wgsl (the per-pixel work).
//
// With anti-aliasing (k × k samples a pixel, the buffers the sample frame's) the twin of hadou-cpu's
// traced::traced_grid: cs_traced_pixels traces one value per image pixel whose samples show one
// surface (from their mean point), and cs_traced gives a pixel's samples that value where its
// 4-neighbours' values are near it, and traces each sample elsewhere.
//
// Whole-image buffers (passes/soft.rs `SoftTargets`): soft_world[i] = (world point as f32 bits,
// class), soft_normal[i] = (unit normal as f32 bits, the pixel's value at its first sample when
// k > 1: f32 bits, or NOT_ONE_SURFACE), visibility[i] (written here).

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<uniform> traced: TracedUniforms;
@group(0) @binding(2) var<storage, read> soft_world: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read_write> soft_normal: array<vec4<u32>>;
@group(0) @binding(4) var<storage, read_write> visibility: array<f32>;
@group(0) @binding(5) var<storage, read> nodes: array<BvhNode>;
@group(0) @binding(6) var<storage, read> tris: array<BvhTri>;
@group(0) @binding(7) var<uniform> grid: TracedGrid;

// Keep in sync with layout/ `TracedGrid`.
struct TracedGrid {
    // The sample grid's edge k (1: one sample a pixel).
    k: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

// hadou_cpu::traced::GRID_SPREAD, GRID_NORMAL_COS.
const GRID_SPREAD: f32 = 0.125;
const GRID_NORMAL_COS: f32 = 0.98;
// A pixel whose samples do not show one surface (soft_normal's w at its first sample).
const NOT_ONE_SURFACE: u32 = 0xffffffffu;

// k, OR-ed with a zero the driver cannot fold (the top bit of a storage buffer's length) so that
// lavapipe's uniform inlining compiles one variant for every grid (wave_energy.wgsl `load_frame`).
fn grid_edge() -> u32 {
    return max(grid.k | (arrayLength(&tris) >> 31u), 1u);
}

// hadou_math::soft::Class::None.
const CLASS_NONE: u32 = 0u;

// Twin of hadou-cpu's traced::grid_point and the first pass of traced_grid, per image pixel (k > 1),
// once every tile's points are gathered: where the pixel's k × k samples all show one surface
// (every one drawn, each normal within GRID_NORMAL_COS of the first's, or all without one, each on
// the first's tangent plane within a quarter of its distance), the traced visibility of their mean
// point with their mean normal; NOT_ONE_SURFACE elsewhere. Kept in soft_normal's w at the pixel's
// first sample.
@compute @workgroup_size(8, 8, 1)
fn cs_traced_pixels(@builtin(global_invocation_id) id: vec3<u32>) {
    let k = grid_edge();
    let size = frame.image_size / k;
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let sw = frame.image_size.x;
    let g0 = k * id.y * sw + k * id.x;
    let first = soft_world[g0];
    if (first.w == CLASS_NONE) {
        soft_normal[g0].w = NOT_ONE_SURFACE;
        return;
    }
    let p0 = bitcast<vec3<f32>>(first.xyz);
    let n0 = bitcast<vec3<f32>>(soft_normal[g0].xyz);
    let has_normal = dot3(n0, n0) > 0.0;
    var world = vec3<f32>(0.0);
    var normal = vec3<f32>(0.0);
    var one = true;
    for (var s = 0u; s < k * k; s++) {
        let g = (k * id.y + s / k) * sw + k * id.x + s % k;
        let wv = soft_world[g];
        let p = bitcast<vec3<f32>>(wv.xyz);
        let n = bitcast<vec3<f32>>(soft_normal[g].xyz);
        if (wv.w == CLASS_NONE || (dot3(n, n) > 0.0) != has_normal) {
            one = false;
        } else if (has_normal) {
            let d = p - p0;
            if (dot3(n, n0) < GRID_NORMAL_COS * length3(n) * length3(n0)
                || abs(dot3(d, n0)) > 0.25 * length3(d) * length3(n0)) {
                one = false;
            }
        }
        world = world + p;
        normal = normal + n;
    }
    if (!one) {
        soft_normal[g0].w = NOT_ONE_SURFACE;
        return;
    }
    let inv = 1.0 / f32(k * k);
    world = world * inv;
    if (has_normal) {
        let l = length3(normal);
        if (l > 0.0 && l <= 3.4e38) {
            normal = normal / l;
        } else {
            normal = n0;
        }
    }
    let r = world + normal * (TRACE_BIAS * length3(world - frame.area_position));
    soft_normal[g0].w = bitcast<u32>(pixel_visibility(r, id.x, id.y));
}

// Image pixel (x, y)'s value from cs_traced_pixels.
fn pixel_value(x: u32, y: u32, k: u32) -> u32 {
    return soft_normal[k * y * frame.image_size.x + k * x].w;
}

// Whether image pixel (x, y)'s value `v` settles its samples (traced_grid's second pass): it was
// traced, and every 4-neighbour traced is within GRID_SPREAD of it.
fn settled(x: u32, y: u32, k: u32) -> bool {
    let v = pixel_value(x, y, k);
    if (v == NOT_ONE_SURFACE) {
        return false;
    }
    let size = frame.image_size / k;
    let f = bitcast<f32>(v);
    var ok = true;
    if (x > 0u) {
        ok = ok && near_value(pixel_value(x - 1u, y, k), f);
    }
    if (x + 1u < size.x) {
        ok = ok && near_value(pixel_value(x + 1u, y, k), f);
    }
    if (y > 0u) {
        ok = ok && near_value(pixel_value(x, y - 1u, k), f);
    }
    if (y + 1u < size.y) {
        ok = ok && near_value(pixel_value(x, y + 1u, k), f);
    }
    return ok;
}

fn near_value(n: u32, v: f32) -> bool {
    return n == NOT_ONE_SURFACE || abs(bitcast<f32>(n) - v) <= GRID_SPREAD;
}

// Per image pixel of the sample frame, once every tile's points are gathered (cs_points) and, with
// k > 1, cs_traced_pixels has run: the traced visibility of its visible point (its pixel's value
// where that settles it), 0 where nothing is drawn.
@compute @workgroup_size(8, 8, 1)
fn cs_traced(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= frame.image_size.x || id.y >= frame.image_size.y) {
        return;
    }
    let gi = id.y * frame.image_size.x + id.x;
    let w = soft_world[gi];
    if (w.w == CLASS_NONE) {
        visibility[gi] = 0.0;
        return;
    }
    let k = grid_edge();
    if (k > 1u && settled(id.x / k, id.y / k, k)) {
        visibility[gi] = bitcast<f32>(pixel_value(id.x / k, id.y / k, k));
        return;
    }
    let world = bitcast<vec3<f32>>(w.xyz);
    let n = bitcast<vec3<f32>>(soft_normal[gi].xyz);
    let r = world + n * (TRACE_BIAS * length3(world - frame.area_position));
    visibility[gi] = pixel_visibility(r, id.x, id.y);
}
