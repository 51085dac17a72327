// The shadow passes (hadou_scene::ShadowCast; hadou-cpu's shadows.rs is the reference).
// Prepended by common.wgsl.
//
// Plane casts (vs_plane, fs_plane), per tile after the G-buffer pass: every caster of every plane
// cast j, in cast order, its vertices moved along k onto the receiver plane (G = P + t·k,
// hadou_math::shadow::project) and drawn double-sided with the camera's projection. A fragment
// keeps cast j where the G-buffer's visible surface is no outline hull, belongs to a receiver of
// the cast's shadow and lies within ON_PLANE·(1 + d) of the plane, and t ≥ 0 there. It writes j + 1
// to an R32Uint target and the cast's depth key (GpuShadowCast::depth_key) as its depth, so the
// depth test (Less, cleared to 1) keeps the most opaque cast, the first among equals.
//
// Map casts (vs_map), once per frame: every caster of map cast j drawn into layer j of a Depth32Float
// array texture, orthographically along k (hadou_math::shadow::MapFrame::to_map: clip (2s − 1,
// 2t − 1, depth)); the wave pass looks receivers up in it (shadow_lookup.wgsl).

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<storage, read> objects: array<GpuObject>;
@group(0) @binding(2) var<storage, read> materials: array<GpuMaterial>;
@group(0) @binding(3) var<storage, read> casts: array<GpuShadowCast>;
// One per draw (the instance index): (cast index, object index).
@group(0) @binding(4) var<storage, read> draws: array<vec2<u32>>;
// The G-buffer of the tile (raster.wgsl).
@group(0) @binding(5) var scene_texels: texture_2d<u32>;
@group(0) @binding(6) var attribute_texels: texture_2d<u32>;

struct PlaneOut {
    @builtin(position) clip: vec4<f32>,
    // The projection parameter t of hadou_math::shadow::project (perspective-interpolated).
    @location(0) t: f32,
    @location(1) @interpolate(flat) cast_index: u32,
}

struct PlaneFragment {
    @location(0) cast_plus_one: u32,
    @builtin(frag_depth) depth: f32,
}

fn caster_point(draw: vec2<u32>, position: vec3<f32>) -> vec3<f32> {
    return (objects[draw.y].model * vec4<f32>(position, 1.0)).xyz;
}

@vertex
fn vs_plane(@location(0) position: vec3<f32>, @builtin(instance_index) draw: u32) -> PlaneOut {
    let d = draws[draw];
    let c = casts[d.x];
    let p = caster_point(d, position);
    // hadou_math::shadow::project
    let t = dot3(c.plane_point - p, c.plane_normal) / dot3(c.k, c.plane_normal);
    var out: PlaneOut;
    out.clip = clip_position(frame, p + c.k * t);
    out.t = t;
    out.cast_index = d.x;
    return out;
}

@fragment
fn fs_plane(in: PlaneOut) -> PlaneFragment {
    if (!(in.t >= 0.0)) {
        discard;
    }
    let pixel = vec2<u32>(in.clip.xy);
    let texel = bitcast<vec4<f32>>(textureLoad(scene_texels, vec2<i32>(pixel), 0));
    let attributes = textureLoad(attribute_texels, vec2<i32>(pixel), 0);
    let c = casts[in.cast_index];
    if (!(texel.w > 0.0) || (attributes.w & HULL_BIT) != 0u) {
        discard;
    }
    if ((materials[attributes.w].shadow_mask & (1u << c.shadow)) == 0u) {
        discard;
    }
    let px = frame.tile_origin + pixel;
    let p = surface_point(frame, pixel_dir(frame, px.x, px.y), texel.w);
    // hadou_math::shadow::Plane::distance
    if (!(abs(dot3(p - c.plane_point, c.plane_normal)) <= ON_PLANE * (1.0 + texel.w))) {
        discard;
    }
    var out: PlaneFragment;
    out.cast_plus_one = in.cast_index + 1u;
    out.depth = c.depth_key;
    return out;
}

@vertex
fn vs_map(@location(0) position: vec3<f32>, @builtin(instance_index) draw: u32) -> @builtin(position) vec4<f32> {
    let d = draws[draw];
    let m = map_coords(casts[d.x], caster_point(d, position));
    // Depth within [0, 1] up to rounding (the map's sphere bounds its casters): clamped, so that
    // rounding never clips a caster's triangle.
    return vec4<f32>(2.0 * m.x - 1.0, 2.0 * m.y - 1.0, clamp(m.z, 0.0, 1.0), 1.0);
}
