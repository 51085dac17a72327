// Shared declarations of the hadou GPU backend: the GPU-visible structs, pixel rays, shading and
// colour mapping. Prepended to raster.wgsl and wave.wgsl (see crates/hadou-gpu/src/shaders.rs).
//
// Every struct here has exactly one Rust definition in crates/hadou-gpu/src/layout/:
// keep in sync with layout/ (same field order, same explicit padding).

// ---- Vector products, written out (twins of hadou_math::Vec3::{dot, cross, length}) ----
// The builtins dot/cross/length leave the evaluation order and the use of fused multiply-adds
// to the driver, and drivers differ: Mesa's OpenGL path evaluates dot() and length() with fused
// multiply-adds (up to 1 ulp apart from the Vulkan path and from Rust on 1/3 of random inputs),
// while its Vulkan path rounds every product. Near-hit rays with no core radius amplify one ulp
// in a squared distance into percent-level energy differences, so every product the backends
// share is written out in Rust's order: x·x' + y·y' + z·z' (left to right), each product rounded.
fn dot3(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

fn cross3(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

fn length3(a: vec3<f32>) -> f32 {
    return sqrt(dot3(a, a));
}

// hadou_math::outline::in_front with the margin a parameter (edges.wgsl's `in_front` passes
// IN_FRONT_MARGIN; hadou-bevy's closing hull lets an edge lying on the surface count): whether the
// point q = eye + q_dist·q_dir lies in front of the plane through p = eye + p_dist·p_dir with
// normal p_normal (any length; zero: the plane facing the eye), turned to face the eye, by
// `margin` of p's distance along q's ray (a negative margin lets q lie that far behind). A ray
// missing the plane counts as in front, without a division.
fn in_front_by(p_normal: vec3<f32>, p_dir: vec3<f32>, p_dist: f32, q_dir: vec3<f32>, q_dist: f32, margin: f32) -> bool {
    let len = length3(p_normal);
    var n = -p_dir;
    if (len > 0.0 && len < 3.0e38) {
        n = p_normal / len;
    }
    if (dot3(n, p_dir) > 0.0) {
        n = -n;
    }
    let num = p_dist * dot3(n, p_dir);
    let den = dot3(n, q_dir);
    return q_dist * den > num * (1.0 - margin);
}

// Keep in sync with layout/ `FrameUniforms`.
struct FrameUniforms {
    eye: vec3<f32>,
    tan_half_fov: f32,
    right: vec3<f32>,
    aspect: f32,
    up: vec3<f32>,
    near: f32,
    forward: vec3<f32>,
    far: f32,
    background: vec3<f32>,
    exposure: f32,
    light_dir: vec3<f32>,
    tone_mode: u32,
    light_color: vec3<f32>,
    wave_count: u32,
    ambient: vec3<f32>,
    any_glow: u32,
    image_size: vec2<u32>,
    tile_origin: vec2<u32>,
    tile_size: vec2<u32>,
    shadow_casts: u32,
    map_casts: u32,
    ndc_scale: vec2<f32>,
    ndc_offset: vec2<f32>,
    cast_count: u32,
    map_count: u32,
    plane_count: u32,
    area: u32,
    area_position: vec3<f32>,
    outline_reach: u32,
    area_color: vec3<f32>,
    // The edge of the sample grid (hadou_scene::Frame::grid): 1, or with anti-aliasing the
    // uniforms are the sample frame's (image_size, tile_origin and tile_size count samples) and
    // the wave pass resolves grid × grid samples per image pixel.
    grid: u32,
    // The area light's axis P, size l and lamp shape (LAMP_*).
    area_axis: vec3<f32>,
    area_size: f32,
    area_shape: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// layout/ LAMP_SEGMENT, LAMP_DISC, LAMP_SPHERE (hadou_math::soft::LampShape).
const LAMP_SEGMENT: u32 = 0u;
const LAMP_DISC: u32 = 1u;
const LAMP_SPHERE: u32 = 2u;

// Keep in sync with layout/ `GpuSpotMap` (hadou_math::soft::SpotMap and its edge in texels).
struct GpuSpotMap {
    eye: vec3<f32>,
    tan_half: f32,
    forward: vec3<f32>,
    near: f32,
    right: vec3<f32>,
    size: u32,
    up: vec3<f32>,
    _pad: u32,
}

// Twin of hadou_math::soft::SpotMap::to_view: right, up, along the axis.
fn spot_to_view(s: GpuSpotMap, p: vec3<f32>) -> vec3<f32> {
    let d = p - s.eye;
    return vec3<f32>(dot3(d, s.right), dot3(d, s.up), dot3(d, s.forward));
}

// Keep in sync with layout/ `GpuObject`.
struct GpuObject {
    model: mat4x4<f32>,
    normal_matrix: mat4x4<f32>,
    material_base: u32,
    material_count: u32,
    _pad: vec2<u32>,
}

// Keep in sync with layout/ `GpuRamp` (hadou_math::toon::Ramp).
struct GpuRamp {
    stops: array<vec4<f32>, 8>,
    count: u32,
    kind: u32,
    smoothing: f32,
    _pad: u32,
}

// Keep in sync with layout/ `GpuTexture`.
struct GpuTexture {
    offset: u32,
    width: u32,
    height: u32,
    flags: u32,
}

// Keep in sync with layout/ `GpuMaterial`.
struct GpuMaterial {
    base_color: vec3<f32>,
    model: u32,
    outline_color: vec3<f32>,
    wave_blend: f32,
    outline_width: f32,
    shadow_mask: u32,
    object: u32,
    mtoon: u32,
    base_texture: GpuTexture,
    feature_texture: GpuTexture,
    ramp: GpuRamp,
}

// Keep in sync with layout/ `GpuLight`.
struct GpuLight {
    line_kind: u32,
    point_offset: u32,
    point_count: u32,
    inverse_square: u32,
    a: vec4<f32>,
    b: vec4<f32>,
    color: vec4<f32>,
    ramp: GpuRamp,
}

// Keep in sync with layout/ `GpuWave` (the meaning of p0/p1/p2 per kind is documented there).
struct GpuWave {
    color: vec4<f32>,
    kind: u32,
    falloff: u32,
    core_radius: f32,
    attenuation: f32,
    p0: vec4<f32>,
    p1: vec4<f32>,
    p2: vec4<f32>,
}

// One prepared curved wave (hadou_math::curve::PreparedCurve); offsets index the curve_vec4 and
// curve_f32 storage buffers of curve.wgsl. Keep in sync with layout/ `GpuCurve`.
struct GpuCurve {
    origin: vec3<f32>,
    alpha: f32,
    axis_d: vec3<f32>,
    x_head: f32,
    axis_y: vec3<f32>,
    attenuation: f32,
    axis_z: vec3<f32>,
    gamma: f32,
    s_head: f32,
    core_floor: f32,
    cylinder_radius: f32,
    integrator: u32,
    m: u32,
    m_reduced: u32,
    reduce: u32,
    shape: u32,
    order: u32,
    points: u32,
    point_count: u32,
    knots: u32,
    lo: f32,
    hi: f32,
    rate: f32,
    radius: f32,
    phase: f32,
    y_terms: u32,
    z_terms: u32,
    nodes: u32,
    node_count: u32,
    lines: u32,
    errors: u32,
    level_offsets: u32,
    levels: u32,
    tolerance: f32,
    att_q: f32,
    att_floor: f32,
    tail_radius: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// One shadow cast (hadou_scene::ShadowCast): a plane projection or a shadow map. Keep in sync with
// layout/ `GpuShadowCast` (its fields are documented there) and with load_shadow_cast in
// shadow_lookup.wgsl, which reads it word by word.
struct GpuShadowCast {
    k: vec3<f32>,
    opacity: f32,
    plane_point: vec3<f32>,
    shadow: u32,
    plane_normal: vec3<f32>,
    depth_key: f32,
    color: vec3<f32>,
    map_size: u32,
    map_center: vec3<f32>,
    map_scale: f32,
    map_u: vec3<f32>,
    map_layer: u32,
    map_v: vec3<f32>,
    map_bias: f32,
}

// Keep in sync with layout/: wave kinds and falloff/tone codes.
const WAVE_SPHERE: u32 = 0u;
const WAVE_CYLINDER: u32 = 1u;
const WAVE_CAPSULE: u32 = 2u;
const WAVE_BEAM: u32 = 3u;
const WAVE_CURVE: u32 = 4u;
const INTEGRATOR_DEFAULT: u32 = 0u;
const INTEGRATOR_SIMPSON: u32 = 1u;
const INTEGRATOR_NEAREST: u32 = 2u;
const SHAPE_HELIX: u32 = 0u;
const SHAPE_TRIG: u32 = 1u;
const SHAPE_BEZIER: u32 = 2u;
const SHAPE_BSPLINE: u32 = 3u;
const FALLOFF_FAITHFUL: u32 = 0u;
const FALLOFF_INVERSE_SQUARE: u32 = 1u;
const TONE_FAITHFUL: u32 = 0u;
const TONE_FILMIC: u32 = 1u;
const TONE_LINEAR: u32 = 2u;
const RAMP_BANDS: u32 = 0u;
const RAMP_GRADIENT: u32 = 1u;
const MODEL_DIFFUSE: u32 = 0u;
const MODEL_TOON: u32 = 1u;
const MODEL_UNLIT: u32 = 2u;
const LINE_POINT: u32 = 0u;
const LINE_SEGMENT: u32 = 1u;
const LINE_LINE: u32 = 2u;
const LINE_POLYLINE: u32 = 3u;
const HULL_BIT: u32 = 0x80000000u;
// Keep in sync with layout/ `MATERIAL_MASK` and `REACH_SHIFT`: the raster pass's material word
// holds the material index in its low 16 bits and the hull reach (8 bits) from bit 16; the edge
// pass's output holds the index alone (and HULL_BIT).
const MATERIAL_MASK: u32 = 0xffffu;
const REACH_SHIFT: u32 = 16u;
// Keep in sync with layout/ `CAST_PLANE` and `SHADOW_CAST_WORDS`.
const CAST_PLANE: u32 = 0u;
const SHADOW_CAST_WORDS: u32 = 28u;
// Mirrors hadou_scene::ON_PLANE: a visible point is on a receiver plane within
// ON_PLANE · (1 + eye distance) of it.
const ON_PLANE: f32 = 1.0e-3;

// Mirrors hadou_scene::CameraBasis::pixel_dir: direction through the centre of the global pixel
// (px, py) (py = 0 is the top row), with unit component along `forward`.
fn pixel_dir(u: FrameUniforms, px: u32, py: u32) -> vec3<f32> {
    return pixel_dir_at(u, f32(px) + 0.5, f32(py) + 0.5);
}

// The direction through the point (x, y) of the image plane, in pixels of `u.image_size` from its
// top-left corner (pixel_dir is this at a pixel's centre).
fn pixel_dir_at(u: FrameUniforms, x: f32, y: f32) -> vec3<f32> {
    let ndc_x = 2.0 * x / f32(u.image_size.x) - 1.0;
    let ndc_y = 1.0 - 2.0 * y / f32(u.image_size.y);
    return u.forward + u.right * (ndc_x * u.tan_half_fov * u.aspect) + u.up * (ndc_y * u.tan_half_fov);
}

// The visible point of a pixel whose direction is `dir` (pixel_dir) at eye distance `distance`:
// eye + unit(dir) · distance (the G-buffer stores the distance; hadou-cpu keeps the point).
fn surface_point(u: FrameUniforms, dir: vec3<f32>, distance: f32) -> vec3<f32> {
    return u.eye + dir * (distance / length3(dir));
}

// World → the tile's clip space: hadou_scene::CameraBasis::to_view, view-space x/z scaled by
// 1/(tan_half·aspect) and y/z by 1/tan_half as the CPU rasterizer does, then the image NDC mapped
// to the tile (ndc_tile = ndc·scale + offset, times w in clip space); depth 0 at near, 1 at far.
fn clip_position(u: FrameUniforms, world: vec3<f32>) -> vec4<f32> {
    let d = world - u.eye;
    let view = vec3<f32>(dot3(d, u.right), dot3(d, u.up), dot3(d, u.forward));
    let gx = view.x / (u.tan_half_fov * u.aspect);
    let gy = view.y / u.tan_half_fov;
    return vec4<f32>(
        gx * u.ndc_scale.x + view.z * u.ndc_offset.x,
        gy * u.ndc_scale.y + view.z * u.ndc_offset.y,
        (view.z - u.near) * (u.far / (u.far - u.near)),
        view.z,
    );
}

// Mirrors hadou_math::shadow::MapFrame::to_map for a map cast: (s, t, depth) of world point `p`.
fn map_coords(c: GpuShadowCast, p: vec3<f32>) -> vec3<f32> {
    let d = p - c.map_center;
    let inv = c.map_scale;
    return vec3<f32>(dot3(d, c.map_u) * inv + 0.5, dot3(d, c.map_v) * inv + 0.5, dot3(d, c.k) * inv + 0.5);
}

// Mirrors hadou_math::shade::diffuse: albedo · (ambient + light · max(0, N·(−L))); a zero or
// non-finite normal shades with ambient only.
fn diffuse(albedo: vec3<f32>, normal: vec3<f32>, light_dir: vec3<f32>, light: vec3<f32>, ambient: vec3<f32>) -> vec3<f32> {
    let len = length3(normal);
    var n = vec3<f32>(0.0);
    if (len > 0.0 && len < 3.0e38) {
        n = normal / len;
    }
    let lambert = max(dot3(n, -light_dir), 0.0);
    return albedo * (ambient + light * lambert);
}

// Mirrors hadou_math::toon::band_step (000 §2.1, SPEC.md §2.1). Here rather than in shading.wgsl so
// that a renderer embedding hadou-gpu's shaders can evaluate toon ramps with common.wgsl alone.
fn band_step(m: f32, t: f32, w: f32) -> f32 {
    if (w <= 0.0) {
        return select(0.0, 1.0, m >= t);
    }
    let x = clamp((m - t) / w + 0.5, 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
}

// Mirrors hadou_math::toon::Ramp::eval (m is never NaN here: it comes from wave_m or a clamped dot).
fn ramp_eval(r: GpuRamp, m: f32) -> vec3<f32> {
    if (r.count == 0u) {
        return vec3<f32>(0.0);
    }
    var c = r.stops[0].yzw;
    for (var k = 1u; k < min(r.count, 8u); k++) {
        let prev = r.stops[k - 1u];
        let cur = r.stops[k];
        var s = 0.0;
        if (r.kind == RAMP_BANDS) {
            s = band_step(m, cur.x, r.smoothing);
        } else if (cur.x > prev.x) {
            s = clamp((m - prev.x) / (cur.x - prev.x), 0.0, 1.0);
        } else {
            s = select(0.0, 1.0, m >= cur.x);
        }
        c = c + (cur.yzw - prev.yzw) * s;
    }
    return c;
}

// Mirrors hadou_math::shade::map_faithful: clamp to [0, 1] per channel (002 §3.3).
fn map_faithful(c: vec3<f32>) -> vec3<f32> {
    return clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
}

// 1 − exp(−x) for x ≥ 0 without losing the small values. The Rust twin
// (hadou_math::shade::one_minus_exp_neg) computes its own exponential to within 2e-7; the two
// agree far inside the backends' colour tolerance.
fn one_minus_exp_neg(x: f32) -> f32 {
    if (x < 1.0e-3) {
        return x * (1.0 - x * (0.5 - x * (1.0 / 6.0)));
    }
    return 1.0 - exp(-x);
}

// Mirrors hadou_math::shade::map_filmic: 1 − exp(−(c + w)), w = ½·max(0, max(c) − 1).
fn map_filmic(c_in: vec3<f32>) -> vec3<f32> {
    let c = max(c_in, vec3<f32>(0.0));
    let m = max(c.x, max(c.y, c.z));
    let w = 0.5 * max(m - 1.0, 0.0);
    let x = min(c + vec3<f32>(w), vec3<f32>(80.0));
    return vec3<f32>(one_minus_exp_neg(x.x), one_minus_exp_neg(x.y), one_minus_exp_neg(x.z));
}
