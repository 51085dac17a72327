// The bindings shading.wgsl reads in the wave pass (part of its group), and how it reads a
// polyline point. Another composer of shading.wgsl (hadou-bevy's material) declares its own
// `lights`, `shading_data`, `polyline_point`, `mtoon_eye` and `mtoon_motion` in their place.

// One per material of every object (layout::ShadingBuffers::materials).
@group(0) @binding(8) var<storage, read> materials: array<GpuMaterial>;
// One per wave (layout::ShadingBuffers::lights).
@group(0) @binding(9) var<storage, read> lights: array<GpuLight>;
// Words: the sRGB → linear table (256 f32 bit patterns), texels (RGBA8, little-endian), polyline
// points (3 f32 bit patterns each). layout::ShadingBuffers::data.
@group(0) @binding(10) var<storage, read> shading_data: array<u32>;

fn polyline_point(offset: u32, i: u32) -> vec3<f32> {
    let o = offset + 3u * i;
    return vec3<f32>(bitcast<f32>(shading_data[o]), bitcast<f32>(shading_data[o + 1u]), bitcast<f32>(shading_data[o + 2u]));
}

// The eye an MToon block's rim and matcap are seen from: the block's words 24–26 (the frame's
// camera, layout::mtoon_block).
fn mtoon_eye(o: u32) -> vec3<f32> {
    return mtoon_vec3(o + 24u);
}

// An MToon block's UV motion at the frame's time: `scroll · time` (x, y) and `rotation · time`,
// its words 18–20 (the products hadou-cpu forms).
fn mtoon_motion(o: u32) -> vec3<f32> {
    return mtoon_vec3(o + 18u);
}
