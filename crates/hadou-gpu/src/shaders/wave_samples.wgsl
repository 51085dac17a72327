// The wave pass of a frame with several samples per pixel (anti-aliasing): the entry point
// cs_samples, composed after wave.wgsl into a module of its own (shaders.rs WAVE_SAMPLES_PARTS),
// so that the single-sample module, cs_main, is compiled without it. The G-buffer and the soft
// shadows' visibility are the sample frame's (frame.grid × frame.grid samples per image pixel;
// the uniforms count samples); the output is the image pixels' (n = (tile_size / grid)² pixels,
// the layout of wave.wgsl's out_buf).

// Mirrors hadou_scene::SAMPLE_DEPTH_SPREAD: how far apart in eye distance (relative to the
// nearest) one pixel's samples may be and still count as one surface.
const SAMPLE_DEPTH_SPREAD: f32 = 0.01;
// A sample where nothing is drawn.
const NO_SURFACE: u32 = 0xffffffffu;

// One sample of the tile's G-buffer: its scene colour (shaded, shadowed, with the area light),
// its eye distance (-1 where nothing is drawn) and what the resolve compares between samples (the
// material word: material index | HULL_BIT, NO_SURFACE for nothing).
struct Sample {
    scene: vec3<f32>,
    surface: f32,
    key: u32,
}

// Sample `s` of the tile (sample coordinates; `ns` samples in the tile, whose soft-shadow
// visibility soft.wgsl's cs_gather left at out_buf[5·ns + index]).
fn tile_sample(s: vec2<u32>, ns: u32) -> Sample {
    var out: Sample;
    out.scene = frame.background;
    out.surface = -1.0;
    out.key = NO_SURFACE;
    // Without surfaces (a frame of waves alone) the G-buffer is not read at all.
    var texel = vec4<f32>(0.0);
    if (USE_SURFACES) {
        texel = bitcast<vec4<f32>>(textureLoad(scene_texels, vec2<i32>(s), 0));
    }
    if (USE_SURFACES && texel.w > 0.0) {
        let dir = pixel_dir(frame, frame.tile_origin.x + s.x, frame.tile_origin.y + s.y);
        out.surface = texel.w;
        let attributes = textureLoad(attribute_texels, vec2<i32>(s), 0);
        out.key = attributes.w & (HULL_BIT | MATERIAL_MASK);
        let m = materials[attributes.w & ~HULL_BIT];
        if ((attributes.w & HULL_BIT) != 0u) {
            out.scene = m.outline_color;
        } else {
            let world = surface_point(frame, dir, out.surface);
            let uv = vec2<f32>(bitcast<f32>(attributes.x), bitcast<f32>(attributes.y));
            var scene = shade_surface(m, world, texel.xyz, uv, unpack4x8unorm(attributes.z));
            scene = apply_shadows(scene, m.shadow_mask, world, s);
            if (USE_AREA && frame.area != 0u) {
                // As hadou-cpu's opaque_pass: c + visibility · area term, saturated, after the hard
                // shadows.
                let v = out_slot5(ns, s.y * frame.tile_size.x + s.x);
                let t = v * area_term(m, world, texel.xyz, uv, unpack4x8unorm(attributes.z));
                scene = vec3<f32>(energy_saturate(scene.x + t.x), energy_saturate(scene.y + t.y), energy_saturate(scene.z + t.z));
            }
            out.scene = scene;
        }
    }
    return out;
}

// One image pixel: its grid × grid samples (one with grid = 1) resolved as hadou-cpu's
// RowSource::light_row does it — the scene colour is the samples' mean (the box filter); where
// every sample shows the same surface (the same material word, or nothing) within
// SAMPLE_DEPTH_SPREAD in eye distance, the waves are integrated once along the ray through the
// pixel's centre, clipped at the samples' mean distance, elsewhere sample by sample and averaged
// (the depth then the nearest sample's) — then the colour scene + exposure·light, mapped. The
// entry point of frames with more than one sample per pixel (passes/wave.rs picks it); cs_main
// draws frames of one sample.
@compute @workgroup_size(8, 8, 1)
fn cs_samples(@builtin(global_invocation_id) id: vec3<u32>) {
    load_frame();
    let g = max(frame.grid, 1u);
    let size = frame.tile_size / g;
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    // With g > 1 the outputs (6·n floats, or n words) end before the samples' visibility (from 5·ns): no
    // invocation overwrites what another reads.
    let n = size.x * size.y;
    let i = id.y * size.x + id.x;
    let ns = frame.tile_size.x * frame.tile_size.y;
    let inv = 1.0 / f32(g * g);

    var scene = vec3<f32>(0.0);
    var key = NO_SURFACE;
    var same = true;
    var lo = 3.0e38;
    var hi = 0.0;
    var sum = 0.0;
    for (var j = 0u; j < g; j++) {
        for (var k = 0u; k < g; k++) {
            let smp = tile_sample(id.xy * g + vec2<u32>(k, j), ns);
            scene += smp.scene * inv;
            if (j == 0u && k == 0u) {
                key = smp.key;
            }
            same = same && smp.key == key;
            if (smp.surface >= 0.0) {
                lo = min(lo, smp.surface);
                hi = max(hi, smp.surface);
                sum += smp.surface;
            }
        }
    }
    scene = vec3<f32>(energy_saturate(scene.x), energy_saturate(scene.y), energy_saturate(scene.z));
    let drawn = key != NO_SURFACE;
    // The ray through the pixel's centre (with g = 1, pixel_dir of the pixel).
    let centre = vec2<f32>(f32(frame.tile_origin.x / g + id.x) + 0.5, f32(frame.tile_origin.y / g + id.y) + 0.5) * f32(g);
    let dir = pixel_dir_at(frame, centre.x, centre.y);
    // One ray through the centre where the samples agree, else one per sample (a single call
    // site of waves_light, which every wave kind inlines).
    // Without surfaces every pixel's samples agree (no surface, one key); saying so in a constant
    // compiles the per-sample rays out of a frame of waves alone, which llvmpipe would otherwise
    // run under a mask for every pixel.
    let agree = !USE_SURFACES || (same && (!drawn || hi - lo <= SAMPLE_DEPTH_SPREAD * lo));
    var rays = g * g;
    var weight = inv;
    if (agree) {
        rays = 1u;
        weight = 1.0;
    }
    var total = 0.0;
    var light = vec3<f32>(0.0);
    var depth = 3.0e38;
    for (var r = 0u; r < rays; r++) {
        var d = dir;
        var surface = -1.0;
        if (agree) {
            if (drawn) {
                surface = sum * inv;
            }
        } else {
            let s = id.xy * g + vec2<u32>(r % g, r / g);
            d = pixel_dir(frame, frame.tile_origin.x + s.x, frame.tile_origin.y + s.y);
            if (USE_SURFACES) {
                let texel = bitcast<vec4<f32>>(textureLoad(scene_texels, vec2<i32>(s), 0));
                if (texel.w > 0.0) {
                    surface = texel.w;
                }
            }
        }
        let lit_by = waves_light(d, surface);
        total = energy_saturate(total + weight * lit_by.total);
        light += weight * lit_by.light;
        if (surface >= 0.0) {
            depth = min(depth, surface);
        } else {
            depth = min(depth, frame.far * length3(d));
        }
    }
    // exposure · light without overflowing (energy_scaled); the mappings then take f32::MAX to 1.
    let lit = vec3<f32>(energy_scaled(light.x, frame.exposure), energy_scaled(light.y, frame.exposure), energy_scaled(light.z, frame.exposure));
    let rgb_in = scene + lit;
    var rgb = vec3<f32>(0.0);
    if (frame.tone_mode == TONE_LINEAR) {
        // A `[bloom]` follows (bloom.wgsl), which maps the colour after the glare.
        rgb = vec3<f32>(energy_saturate(rgb_in.x), energy_saturate(rgb_in.y), energy_saturate(rgb_in.z));
    } else if (frame.tone_mode == TONE_FAITHFUL) {
        if (USE_TONE_FAITHFUL) {
            rgb = map_faithful(rgb_in);
        }
    } else if (USE_TONE_FILMIC) {
        rgb = map_filmic(rgb_in);
    }
    store_pixel(i, n, rgb, total, depth);
}
