// Glare (passes/bloom.rs): hadou_math::bloom's chain on whole-image planes of vec4<f32> texels
// (rgb, w unused), one dispatch per step over the rows of the output plane `o`. Each entry point
// names its Rust twin in hadou_math::bloom; the sums are the same texels with the same weights.
// Prepended by common.wgsl (the colour mappings).

// A plane: (level width, level height, first row held, rows held). Keep in sync with
// `BloomUniforms` in layout/.
struct BloomUniforms {
    // First input.
    a: vec4<u32>,
    // Second input (cs_up's base, cs_glare's streak, cs_composite's glare).
    b: vec4<u32>,
    // Third input (unused).
    c: vec4<u32>,
    // Output.
    o: vec4<u32>,
    // threshold, soft knee, bloom weight intensity/N, streak weight streak/N_s.
    params: vec4<f32>,
    // x: 1 when cs_up / cs_up_h add `b`; y: the tone mode (TONE_*); z, w: unused.
    flags: vec4<u32>,
}

@group(0) @binding(0) var<uniform> u: BloomUniforms;
@group(0) @binding(1) var<storage, read> a_buf: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> b_buf: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> c_buf: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> o_buf: array<vec4<f32>>;

const BLOOM_CLAMP: f32 = 65504.0;
const F32_MAX: f32 = 3.4028234663852886e38;

// Texel (x, y) of plane p, both clamped to the level's edge (Plane::at); the index into its buffer.
fn plane_index(p: vec4<u32>, x: i32, y: i32) -> u32 {
    let xc = clamp(x, 0, i32(p.x) - 1);
    let yc = clamp(y, 0, i32(p.y) - 1);
    return u32(yc - i32(p.z)) * p.x + u32(xc);
}

fn at_a(x: i32, y: i32) -> vec3<f32> {
    return a_buf[plane_index(u.a, x, y)].xyz;
}

// The output texel of this invocation: (x, level row y), or none past the plane.
fn out_texel(id: vec3<u32>) -> vec2<i32> {
    if (id.x >= u.o.x || id.y >= u.o.w) {
        return vec2<i32>(-1, -1);
    }
    return vec2<i32>(i32(id.x), i32(u.o.z + id.y));
}

fn out_index(id: vec3<u32>) -> u32 {
    return id.y * u.o.x + id.x;
}

// hadou_math::bloom::prefilter.
fn prefilter(c_in: vec3<f32>) -> vec3<f32> {
    let c = clamp(c_in, vec3<f32>(0.0), vec3<f32>(F32_MAX));
    let b = max(c.x, max(c.y, c.z));
    if (b <= 0.0) {
        return vec3<f32>(0.0);
    }
    let threshold = u.params.x;
    let k = threshold * u.params.y;
    var q = 0.0;
    if (k > 0.0) {
        let s = clamp(b - threshold + k, 0.0, 2.0 * k);
        q = s * s / (4.0 * k);
    }
    let w = max(q, b - threshold) / b;
    return min(c * w, vec3<f32>(BLOOM_CLAMP));
}

// Step 1 over the output plane (a: the linear colour, the same rows or more).
@compute @workgroup_size(8, 8, 1)
fn cs_prefilter(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = out_texel(id);
    if (t.x < 0) {
        return;
    }
    o_buf[out_index(id)] = vec4<f32>(prefilter(at_a(t.x, t.y)), 0.0);
}

// A(dx, dy) of down_row: the 2×2 box with top-left texel (x2 + dx, y2 + dy).
fn box_a(x2: i32, y2: i32, dx: i32, dy: i32) -> vec3<f32> {
    let x = x2 + dx;
    let y = y2 + dy;
    return 0.25 * (at_a(x, y) + at_a(x + 1, y) + at_a(x, y + 1) + at_a(x + 1, y + 1));
}

// hadou_math::bloom::down_row: the 13-tap downsample of a.
@compute @workgroup_size(8, 8, 1)
fn cs_down(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = out_texel(id);
    if (t.x < 0) {
        return;
    }
    let x2 = 2 * t.x;
    let y2 = 2 * t.y;
    var acc = vec3<f32>(0.0);
    acc += 0.125 * box_a(x2, y2, 0, 0);
    acc += 0.125 * box_a(x2, y2, -1, -1);
    acc += 0.125 * box_a(x2, y2, 1, -1);
    acc += 0.125 * box_a(x2, y2, -1, 1);
    acc += 0.125 * box_a(x2, y2, 1, 1);
    acc += 0.0625 * box_a(x2, y2, 0, -2);
    acc += 0.0625 * box_a(x2, y2, -2, 0);
    acc += 0.0625 * box_a(x2, y2, 2, 0);
    acc += 0.0625 * box_a(x2, y2, 0, 2);
    acc += 0.03125 * box_a(x2, y2, -2, -2);
    acc += 0.03125 * box_a(x2, y2, 2, -2);
    acc += 0.03125 * box_a(x2, y2, -2, 2);
    acc += 0.03125 * box_a(x2, y2, 2, 2);
    o_buf[out_index(id)] = vec4<f32>(acc, 0.0);
}

// hadou_math::bloom::tent: the first low texel and the four weights of high texel i.
fn tent_first(i: i32) -> i32 {
    let j = i / 2;
    if ((i & 1) == 0) {
        return j - 2;
    }
    return j - 1;
}

fn tent_weight(i: i32, k: i32) -> f32 {
    var w = array<f32, 4>(1.0 / 16.0, 5.0 / 16.0, 7.0 / 16.0, 3.0 / 16.0);
    if ((i & 1) == 0) {
        return w[k];
    }
    return w[3 - k];
}

// hadou_math::bloom::up_row: b (when flags.x is 1) plus the tent of a.
@compute @workgroup_size(8, 8, 1)
fn cs_up(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = out_texel(id);
    if (t.x < 0) {
        return;
    }
    let x0 = tent_first(t.x);
    let y0 = tent_first(t.y);
    var acc = vec3<f32>(0.0);
    for (var dy = 0; dy < 4; dy++) {
        var row = vec3<f32>(0.0);
        for (var dx = 0; dx < 4; dx++) {
            row += tent_weight(t.x, dx) * at_a(x0 + dx, y0 + dy);
        }
        acc += tent_weight(t.y, dy) * row;
    }
    if (u.flags.x == 1u) {
        acc = b_buf[plane_index(u.b, t.x, t.y)].xyz + acc;
    }
    o_buf[out_index(id)] = vec4<f32>(acc, 0.0);
}

// hadou_math::bloom::down_row_h: the 1-D 13-tap along x (a and o hold the same rows).
@compute @workgroup_size(8, 8, 1)
fn cs_down_h(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = out_texel(id);
    if (t.x < 0) {
        return;
    }
    var w = array<f32, 6>(1.0 / 16.0, 3.0 / 16.0, 4.0 / 16.0, 4.0 / 16.0, 3.0 / 16.0, 1.0 / 16.0);
    var acc = vec3<f32>(0.0);
    for (var d = 0; d < 6; d++) {
        acc += w[d] * at_a(2 * t.x - 2 + d, t.y);
    }
    o_buf[out_index(id)] = vec4<f32>(acc, 0.0);
}

// hadou_math::bloom::up_row_h: b (when flags.x is 1) plus the 1-D tent of a along x.
@compute @workgroup_size(8, 8, 1)
fn cs_up_h(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = out_texel(id);
    if (t.x < 0) {
        return;
    }
    let x0 = tent_first(t.x);
    var acc = vec3<f32>(0.0);
    for (var dx = 0; dx < 4; dx++) {
        acc += tent_weight(t.x, dx) * at_a(x0 + dx, t.y);
    }
    if (u.flags.x == 1u) {
        acc = b_buf[plane_index(u.b, t.x, t.y)].xyz + acc;
    }
    o_buf[out_index(id)] = vec4<f32>(acc, 0.0);
}

// hadou_math::bloom::pair_row: the streak's half-height row j, the average of the prefiltered
// rows 2j and 2j + 1 (a: T, clamped to its height).
@compute @workgroup_size(8, 8, 1)
fn cs_pair(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = out_texel(id);
    if (t.x < 0) {
        return;
    }
    let acc = (0.0 + 0.5 * at_a(t.x, 2 * t.y)) + 0.5 * at_a(t.x, 2 * t.y + 1);
    o_buf[out_index(id)] = vec4<f32>(acc, 0.0);
}

// hadou_math::bloom::glare_row (with blur_row_h): G at level 1, the [1, 2, 1]/4 blur per axis of
// a (U₁) weighted by params.z, plus the streak's b (U₁ʰ) blurred along x, weighted by params.w
// (read only when that weight is positive).
@compute @workgroup_size(8, 8, 1)
fn cs_glare(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = out_texel(id);
    if (t.x < 0) {
        return;
    }
    let w = vec3<f32>(0.25, 0.5, 0.25);
    var acc = vec3<f32>(0.0);
    for (var dy = 0; dy < 3; dy++) {
        var row = vec3<f32>(0.0);
        for (var dx = 0; dx < 3; dx++) {
            row += w[dx] * at_a(t.x - 1 + dx, t.y - 1 + dy);
        }
        acc += (u.params.z * w[dy]) * row;
    }
    if (u.params.w > 0.0) {
        var row = vec3<f32>(0.0);
        for (var dx = 0; dx < 3; dx++) {
            row += w[dx] * b_buf[plane_index(u.b, t.x - 1 + dx, t.y)].xyz;
        }
        acc += u.params.w * row;
    }
    o_buf[out_index(id)] = vec4<f32>(acc, 0.0);
}

// hadou_math::bloom::bilinear: the first level-1 texel the bilinear tap of texel i reads.
fn bilinear_first(i: i32) -> i32 {
    let j = i / 2;
    if ((i & 1) == 0) {
        return j - 1;
    }
    return j;
}

// Its weight of that first texel (the second's is 1 minus it).
fn bilinear_weight(i: i32) -> f32 {
    if ((i & 1) == 0) {
        return 0.25;
    }
    return 0.75;
}

// hadou_math::bloom::upsample_row and composite, then the frame's colour mapping (a: the linear
// colour, b: the glare G at level 1).
@compute @workgroup_size(8, 8, 1)
fn cs_composite(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = out_texel(id);
    if (t.x < 0) {
        return;
    }
    let x0 = bilinear_first(t.x);
    let y0 = bilinear_first(t.y);
    let wx = bilinear_weight(t.x);
    let wy = bilinear_weight(t.y);
    let top = wy * b_buf[plane_index(u.b, x0, y0)].xyz + (1.0 - wy) * b_buf[plane_index(u.b, x0, y0 + 1)].xyz;
    let bottom =
        wy * b_buf[plane_index(u.b, x0 + 1, y0)].xyz + (1.0 - wy) * b_buf[plane_index(u.b, x0 + 1, y0 + 1)].xyz;
    let g = wx * top + (1.0 - wx) * bottom;
    let rgb = min(at_a(t.x, t.y) + g, vec3<f32>(F32_MAX));
    var mapped = vec3<f32>(0.0);
    if (u.flags.y == TONE_FAITHFUL) {
        mapped = map_faithful(rgb);
    } else {
        mapped = map_filmic(rgb);
    }
    o_buf[out_index(id)] = vec4<f32>(mapped, 1.0);
}
