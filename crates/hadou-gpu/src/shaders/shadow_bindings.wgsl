// The wave pass's bindings of shadow_lookup.wgsl (part of its group) and how it reads them.
// Another composer of shadow_lookup.wgsl (hadou-bevy's material) declares its own `shadow_maps`
// and defines its own `shadow_word` and `plane_cast_at`.

// The plane-shadow pass's target: j + 1 of the kept plane cast j, 0 = none.
@group(0) @binding(11) var plane_shadow_texels: texture_2d<u32>;
// The frame's shadow maps, one layer per map cast (cleared to 1 = no caster).
@group(0) @binding(12) var shadow_maps: texture_2d_array<f32>;

// Word `o` of the frame's shadow records (the shading data buffer holds them).
fn shadow_word(o: u32) -> u32 {
    return shading_data[o];
}

// j + 1 of the plane cast the plane-shadow pass kept at tile pixel `pixel`, 0 = none.
fn plane_cast_at(pixel: vec2<u32>) -> u32 {
    return textureLoad(plane_shadow_texels, vec2<i32>(pixel), 0).x;
}
