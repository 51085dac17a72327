// Opaque geometry pass: every object's triangles, transformed by its object → world matrix and
// projected with the camera basis exactly as the CPU rasterizer does (view-space x/z scaled by
// 1/(tan_half·aspect), y/z by 1/tan_half), shaded with `diffuse` (hadou_math::shade::diffuse).
// Writes the linear scene colour and the Euclidean eye distance of the visible surface, as the bits
// of four f32s in one Rgba32Uint target (pipelines::SCENE_FORMAT: renderable on every adapter).
// Prepended by common.wgsl.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<storage, read> objects: array<GpuObject>;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) object: u32,
}

@vertex
fn vs_main(v: VertexIn, @builtin(instance_index) object: u32) -> VertexOut {
    let o = objects[object];
    let world = (o.model * vec4<f32>(v.position, 1.0)).xyz;
    let normal = (o.normal_matrix * vec4<f32>(v.normal, 0.0)).xyz;
    // World → view space (hadou_scene::CameraBasis::to_view).
    let d = world - frame.eye;
    let view = vec3<f32>(dot3(d, frame.right), dot3(d, frame.up), dot3(d, frame.forward));
    // Global NDC, then this tile's part of it: ndc_tile = ndc·scale + offset (times w in clip space).
    let gx = view.x / (frame.tan_half_fov * frame.aspect);
    let gy = view.y / frame.tan_half_fov;
    var out: VertexOut;
    out.clip = vec4<f32>(
        gx * frame.ndc_scale.x + view.z * frame.ndc_offset.x,
        gy * frame.ndc_scale.y + view.z * frame.ndc_offset.y,
        (view.z - frame.near) * (frame.far / (frame.far - frame.near)),
        view.z,
    );
    out.world = world;
    out.normal = normal;
    out.object = object;
    return out;
}

// (r, g, b, eye distance) as f32 bit patterns; read back by wave.wgsl's `scene_texel`.
@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<u32> {
    let o = objects[in.object];
    let rgb = diffuse(o.color, in.normal, frame.light_dir, frame.light_color, frame.ambient);
    let distance = length3(in.world - frame.eye);
    return bitcast<vec4<u32>>(vec4<f32>(rgb, distance));
}
