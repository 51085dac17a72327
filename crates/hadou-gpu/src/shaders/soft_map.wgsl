// The `[area_light]`'s two perspective shadow maps, once per frame (twin of hadou-cpu's
// soft::SpotDepth::render with soft::spot_tris): every object's triangles (not the outline
// hulls), double-sided, seen from one map's light (GpuSpotMap). Clip space (x·c, y·c, near, z) with
// (x, y, z) = SpotMap::to_view and c = 1/tan_half: the hardware clips at the near plane as
// spot_tris does, maps texel (x, y) to s ∈ [x/size, (x+1)/size), 1 − t ∈ [y/size, (y+1)/size), and
// its depth near/z keeps the nearest surface (compare Greater, cleared to 0). The colour target
// (R32Uint) receives the f32 bits of the perspective-correct view depth 1/Σ wᵢ/zᵢ, +∞ bits where
// nothing is drawn (the clear value); soft.wgsl reads it.

@group(0) @binding(0) var<uniform> spot: GpuSpotMap;
@group(0) @binding(1) var<storage, read> objects: array<GpuObject>;

struct SpotOut {
    @builtin(position) clip: vec4<f32>,
    // The view depth, perspective-interpolated: Σ wᵢ·(zᵢ/zᵢ) / Σ wᵢ/zᵢ = 1/Σ wᵢ/zᵢ
    // (hadou-cpu's ScreenTri::depth_at).
    @location(0) z: f32,
}

@vertex
fn vs_spot(@location(0) position: vec3<f32>, @builtin(instance_index) object: u32) -> SpotOut {
    let world = (objects[object].model * vec4<f32>(position, 1.0)).xyz;
    let v = spot_to_view(spot, world);
    let c = 1.0 / spot.tan_half;
    var out: SpotOut;
    out.clip = vec4<f32>(v.x * c, v.y * c, spot.near, v.z);
    out.z = v.z;
    return out;
}

@fragment
fn fs_spot(in: SpotOut) -> @location(0) u32 {
    return bitcast<u32>(in.z);
}
