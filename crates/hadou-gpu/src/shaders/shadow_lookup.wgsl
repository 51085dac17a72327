// Hard shadows on the visible surface in the wave pass (twin of hadou-cpu's shadows.rs): the plane
// cast the plane-shadow pass kept (shadow_raster.wgsl), then every map cast looked up in its
// shadow map; the most opaque wins (the first among equals) and pulls the shaded colour towards
// its shadow colour. Prepended to wave.wgsl, after shading.wgsl and shadow_bindings.wgsl, which
// declare `shadow_maps` and define `shadow_word` (the word holding the cast records at
// frame.shadow_casts and the map casts' indices at frame.map_casts) and `plane_cast_at` (the kept
// plane cast of a pixel); another composer (hadou-bevy's material) defines its own.

// Whether the frame has plane casts, map casts (pipeline-overridable; see USE_SPHERE in
// wave.wgsl): a kind it lacks is compiled out of apply_shadows.
override USE_PLANE_SHADOWS: bool = true;
override USE_MAP_SHADOWS: bool = true;

fn data_f32(o: u32) -> f32 {
    return bitcast<f32>(shadow_word(o));
}

fn data_vec3(o: u32) -> vec3<f32> {
    return vec3<f32>(data_f32(o), data_f32(o + 1u), data_f32(o + 2u));
}

// Cast record j (layout/ `GpuShadowCast`, SHADOW_CAST_WORDS words, fields in order).
fn load_shadow_cast(j: u32) -> GpuShadowCast {
    let o = frame.shadow_casts + j * SHADOW_CAST_WORDS;
    var c: GpuShadowCast;
    c.k = data_vec3(o);
    c.opacity = data_f32(o + 3u);
    c.plane_point = data_vec3(o + 4u);
    c.shadow = shadow_word(o + 7u);
    c.plane_normal = data_vec3(o + 8u);
    c.depth_key = data_f32(o + 11u);
    c.color = data_vec3(o + 12u);
    c.map_size = shadow_word(o + 15u);
    c.map_center = data_vec3(o + 16u);
    c.map_scale = data_f32(o + 19u);
    c.map_u = data_vec3(o + 20u);
    c.map_layer = shadow_word(o + 23u);
    c.map_v = data_vec3(o + 24u);
    c.map_bias = data_f32(o + 27u);
    return c;
}

// The shaded colour `c` of the visible point `p` (not an outline hull) of tile pixel `pixel`, whose
// material receives the shadows in `mask`, with the winning shadow applied:
// c + (shadow colour − c)·opacity.
fn apply_shadows(c: vec3<f32>, mask: u32, p: vec3<f32>, pixel: vec2<u32>) -> vec3<f32> {
    if (!(USE_PLANE_SHADOWS || USE_MAP_SHADOWS) || frame.cast_count == 0u || mask == 0u) {
        return c;
    }
    var best_j = 0xffffffffu;
    var best_opacity = 0.0;
    var color = vec3<f32>(0.0);
    if (USE_PLANE_SHADOWS && frame.plane_count != 0u) {
        let v = plane_cast_at(pixel);
        if (v != 0u) {
            let s = load_shadow_cast(v - 1u);
            best_j = v - 1u;
            best_opacity = s.opacity;
            color = s.color;
        }
    }
    for (var i = 0u; USE_MAP_SHADOWS && i < frame.map_count; i++) {
        let j = shadow_word(frame.map_casts + i);
        let s = load_shadow_cast(j);
        if ((mask & (1u << s.shadow)) == 0u) {
            continue;
        }
        let m = map_coords(s, p);
        let size = f32(s.map_size);
        let x = floor(m.x * size);
        let y = floor((1.0 - m.y) * size);
        if (!(x >= 0.0 && y >= 0.0 && x < size && y < size)) {
            continue;
        }
        let stored = textureLoad(shadow_maps, vec2<i32>(i32(x), i32(y)), i32(s.map_layer), 0).x;
        if (!(stored < 1.0 && m.z > stored + s.map_bias)) {
            continue;
        }
        if (s.opacity > best_opacity || (s.opacity == best_opacity && j < best_j)) {
            best_j = j;
            best_opacity = s.opacity;
            color = s.color;
        }
    }
    if (!(best_opacity > 0.0)) {
        return c;
    }
    return c + (color - c) * best_opacity;
}
