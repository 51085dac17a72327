// Wave pass: per pixel, the visible surface's shading from the raster pass's G-buffer
// (shading.wgsl: materials, the waves as lights), the waves' light along the pixel's ray clipped
// at the visible surface (wave_energy.wgsl `waves_light`), the colour scene + exposure·Σ rgb·a·I
// and the colour mapping (common.wgsl), or with a `[bloom]` the linear colour for bloom.wgsl. Prepended by common.wgsl, energy.wgsl, curve.wgsl (curve
// buffers: bindings 5–7), wave_energy.wgsl (frame and waves: bindings 0–1), shading.wgsl (bindings
// 8–10) and shadow_lookup.wgsl (hard shadows: bindings 11–12).

// The raster pass's G-buffer (raster.wgsl): (normal, eye distance) as f32 bits, distance 0 =
// nothing drawn; (u, v, pack4x8unorm colour, material | HULL_BIT).
@group(0) @binding(2) var scene_texels: texture_2d<u32>;
@group(0) @binding(3) var attribute_texels: texture_2d<u32>;
// Tile output, n = (tile_size / grid).x · (tile_size / grid).y image pixels, row-major: colour (4 floats per pixel) in
// [0, 4n), energy in [4n, 5n), eye distance in [5n, 6n). Keep in sync with readback in render.rs.
@group(0) @binding(4) var<storage, read_write> out_buf: array<f32>;

// The wave pass's variant (pipeline-overridable constants; see passes/wave.rs WaveVariant, which sets
// each from the frame's contents). The defaults, all true, give the uber-shader that handles any
// frame. A part set false is compiled out: on a software adapter (llvmpipe runs both sides of
// every branch under a mask) that is what keeps a frame from paying for what it does not contain.
// With a part set true the code is exactly the uber-shader's. Here: whether any surface is drawn, the
// `[area_light]`, the colour mappings and the anti-aliasing's samples; wave_energy.wgsl (the wave kinds), energy.wgsl,
// curve.wgsl, shading.wgsl and shadow_lookup.wgsl have the others.
override USE_SURFACES: bool = true;
override USE_AREA: bool = true;
override USE_TONE_FAITHFUL: bool = true;
override USE_TONE_FILMIC: bool = true;
// Whether pixels are resolved from several samples (frame.grid > 1); false compiles the
// single-sample pixel (loops of one iteration, one ray through the centre).
override USE_SAMPLES: bool = true;

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
    let texel = bitcast<vec4<f32>>(textureLoad(scene_texels, vec2<i32>(s), 0));
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
                let v = out_buf[5u * ns + s.y * frame.tile_size.x + s.x];
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
// (the depth then the nearest sample's) — then the colour scene + exposure·light, mapped.
@compute @workgroup_size(8, 8, 1)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    var g = 1u;
    if (USE_SAMPLES) {
        g = max(frame.grid, 1u);
    }
    let size = frame.tile_size / g;
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    // With g > 1 the outputs (6·n floats) end before the samples' visibility (from 5·ns): no
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
    let agree = same && (!drawn || hi - lo <= SAMPLE_DEPTH_SPREAD * lo);
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
            let texel = bitcast<vec4<f32>>(textureLoad(scene_texels, vec2<i32>(s), 0));
            if (USE_SURFACES && texel.w > 0.0) {
                surface = texel.w;
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
    out_buf[4u * i] = rgb.x;
    out_buf[4u * i + 1u] = rgb.y;
    out_buf[4u * i + 2u] = rgb.z;
    out_buf[4u * i + 3u] = 1.0;
    out_buf[4u * n + i] = total;
    out_buf[5u * n + i] = depth;
}
