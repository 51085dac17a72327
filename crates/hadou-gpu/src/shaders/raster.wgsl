// Opaque geometry pass: every object's triangles, transformed by its object → world matrix and
// projected with the camera basis exactly as the CPU rasterizer does (view-space x/z scaled by
// 1/(tan_half·aspect), y/z by 1/tan_half), then the outline hulls (000 §2.3, vs_hull). It writes a
// G-buffer for the wave pass, which shades (shading.wgsl), as the bits of 32-bit values in two
// Rgba32Uint targets (formats.rs SCENE_FORMAT: renderable on every adapter):
// - target 0: world normal (x, y, z) as f32 bits, Euclidean eye distance as f32 bits (0 = nothing);
// - target 1: u, v as f32 bits, the vertex colour as pack4x8unorm, the material index in the
//   frame's material buffer (| HULL_BIT for an outline-hull fragment; for a surface of an
//   outlined material | the hull's reach across the view ray, hadou_math::outline::reach_code,
//   << REACH_SHIFT, which the edge pass (edges.wgsl) reads and clears).
// Prepended by common.wgsl.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<storage, read> objects: array<GpuObject>;
@group(0) @binding(2) var<storage, read> materials: array<GpuMaterial>;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) outline_normal: vec3<f32>,
    @location(3) uv: vec2<f32>,
    @location(4) color: vec4<f32>,
    @location(5) material: u32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) color: vec4<f32>,
    @location(4) @interpolate(flat) material: u32,
    // The unit outline direction U of 000 §2.3 (zero without an outline), interpolated.
    @location(5) outline: vec3<f32>,
}

struct GBuffer {
    @location(0) surface: vec4<u32>,
    @location(1) attributes: vec4<u32>,
}

fn material_index(o: GpuObject, slot: u32) -> u32 {
    return o.material_base + min(slot, max(o.material_count, 1u) - 1u);
}

fn project(world: vec3<f32>) -> vec4<f32> {
    return clip_position(frame, world);
}

// The world outline direction of a vertex, as the hull pushes it (hadou-cpu opaque::project_all):
// unit, times the object-space direction's length (the vertex's outline width multiplier, MToon's
// width texture, at most 1); zero for a zero or non-finite one.
fn outline_dir(o: GpuObject, outline_normal: vec3<f32>) -> vec3<f32> {
    let n = (o.normal_matrix * vec4<f32>(outline_normal, 0.0)).xyz;
    let len = length3(n);
    let scale = min(length3(outline_normal), 1.0);
    if (len > 0.0 && len < 3.0e38 && scale < 3.0e38) {
        return n / len * scale;
    }
    return vec3<f32>(0.0);
}

@vertex
fn vs_main(v: VertexIn, @builtin(instance_index) object: u32) -> VertexOut {
    let o = objects[object];
    let world = (o.model * vec4<f32>(v.position, 1.0)).xyz;
    var out: VertexOut;
    out.clip = project(world);
    out.world = world;
    out.normal = (o.normal_matrix * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = v.uv;
    out.color = v.color;
    out.material = material_index(o, v.material);
    out.outline = vec3<f32>(0.0);
    if (has_outline(materials[out.material].outline_width)) {
        out.outline = outline_dir(o, v.outline_normal);
    }
    return out;
}

// Whether a material's GPU outline width (layout/ `GpuMaterial::outline_width`: `d > 0`, or
// `−w < 0` for an MToon outline in world units) draws an outline.
fn has_outline(width: f32) -> bool {
    return width > 0.0 || width < 0.0;
}

// The outline hull (000 §2.3): the vertex pushed along its world outline normal by d·|z|, which is
// R' = R + d·|R_z|·U in view space (hadou-cpu opaque::project_all). Vertices of materials without
// an outline collapse to one point outside the clip volume, so their triangles are empty.
@vertex
fn vs_hull(v: VertexIn, @builtin(instance_index) object: u32) -> VertexOut {
    let o = objects[object];
    let index = material_index(o, v.material);
    let width = materials[index].outline_width;
    var out: VertexOut;
    out.material = index | HULL_BIT;
    out.uv = v.uv;
    out.color = v.color;
    out.outline = vec3<f32>(0.0);
    if (!has_outline(width)) {
        out.clip = vec4<f32>(0.0, 0.0, -2.0, 1.0);
        out.world = frame.eye;
        out.normal = vec3<f32>(0.0);
        return out;
    }
    let base = (o.model * vec4<f32>(v.position, 1.0)).xyz;
    let u = outline_dir(o, v.outline_normal);
    let z = dot3(base - frame.eye, frame.forward);
    var push = width * abs(z);
    if (width < 0.0) {
        // An MToon outline in world units (hadou_scene::Material::hull_push).
        push = -width;
    }
    let world = base + u * push;
    out.clip = project(world);
    out.world = world;
    out.normal = (o.normal_matrix * vec4<f32>(v.normal, 0.0)).xyz;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> GBuffer {
    var g: GBuffer;
    let distance = length3(in.world - frame.eye);
    g.surface = bitcast<vec4<u32>>(vec4<f32>(in.normal, distance));
    var word = in.material;
    if ((word & HULL_BIT) == 0u && has_outline(materials[word].outline_width)) {
        // hadou_math::outline::reach_code at this pixel's ray.
        let px = frame.tile_origin + vec2<u32>(in.clip.xy);
        let d = pixel_dir(frame, px.x, px.y);
        let v = d / length3(d);
        let across = in.outline - v * dot3(in.outline, v);
        let s = length3(across);
        if (s < 3.0e38) {
            word = word | (u32(floor(min(s, 1.0) * 255.0 + 0.5)) << REACH_SHIFT);
        }
    }
    g.attributes = vec4<u32>(bitcast<u32>(in.uv.x), bitcast<u32>(in.uv.y), pack4x8unorm(in.color), word);
    return g;
}
