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
// Tile output, n = (tile_size / grid).x · (tile_size / grid).y image pixels, row-major, as f32
// bits: colour (4 floats per pixel) in [0, 4n), energy in [4n, 5n), eye distance in [5n, 6n); or,
// in a module composed with SRGB8, one word per pixel in [0, n) (store_pixel). Keep in sync with
// the read-backs in render.rs.
@group(0) @binding(4) var<storage, read_write> out_buf: array<u32>;
// The 8-bit sRGB output (a PNG's bytes) is composed in only where a frame writes it (SRGB8:
// passes/wave.rs WaveVariant::with_srgb8, shaders.rs compose_with); every other module writes
// the float colour, energy and depth and holds none of the code below.
// #if SRGB8
// hadou_math::shade::Srgb8Tables::next_thresholds: element k, the smallest f32 whose 8-bit sRGB
// code exceeds k (+∞ for 255), four to a vector.
@group(0) @binding(13) var<uniform> srgb8_next: array<vec4<f32>, 64>;

// hadou_math::shade::linear_to_srgb8 exactly: the number of thresholds srgb8_next[k] ≤ v. A
// close first guess (SRGB8_FIT: 255·srgb(v) within 0.012 of a code over the power segment of IEC
// 61966-2-1, 255·12.92·v below it), rounded, is within one of the code, and one comparison with
// the threshold on each side settles it: two table reads a channel instead of a bisection's
// eight (llvmpipe reads an array at a varying index lane by lane). NaN and v ≤ 0 give 0, v ≥ 1
// gives 255.
fn srgb8_code(v_in: f32) -> u32 {
    let v = select(0.0, min(v_in, 1.0), v_in > 0.0);
    let s1 = sqrt(v);
    let s2 = sqrt(s1);
    let s3 = sqrt(s2);
    let fit = SRGB8_FIT.x * s1 + SRGB8_FIT.y * s2 + SRGB8_FIT.z * s3 + SRGB8_FIT.w * v;
    let guess = select(fit, 3294.6 * v, v <= 0.0031308);
    var k = u32(clamp(guess + 0.5, 0.0, 255.0));
    let up = k < 255u && v >= srgb8_next[k >> 2u][k & 3u];
    k += select(0u, 1u, up);
    let j = max(k, 1u) - 1u;
    let down = k > 0u && v < srgb8_next[j >> 2u][j & 3u];
    return k - select(0u, 1u, down);
}

// Least-squares weights of √v, v^¼, v^⅛ and v for 255·(1.055·v^(1/2.4) − 0.055) on
// [0.0031308, 1] (largest error 0.0114 codes; srgb8_guess_is_within_one_code checks every code's
// threshold).
const SRGB8_FIT: vec4<f32> = vec4<f32>(163.80782744, 181.58288086, -85.89962424, -4.48015791);

// Whether `v` is neither NaN nor infinite (by its exponent bits, which no optimizer may assume
// away).
fn is_finite_f32(v: f32) -> bool {
    return (bitcast<u32>(v) & 0x7f800000u) != 0x7f800000u;
}
// #endif

// The eye-distance slot of pixel `i` of `n`, as f32 (where soft.wgsl's cs_gather leaves the
// soft-shadow visibility before this pass).
fn out_slot5(n: u32, i: u32) -> f32 {
    return bitcast<f32>(out_buf[5u * n + i]);
}

// Writes image pixel `i` of the tile's `n`: the floats (colour with alpha 1, energy, eye
// distance), or in a module composed with SRGB8 the word R | G << 8 | B << 16 | A << 24 of the
// colour's 8-bit sRGB codes, A = 255, or 0 where the colour, energy or distance is not finite (the read-back
// refuses such a pixel as Rgb8Image::from_image does).
fn store_pixel(i: u32, n: u32, rgb: vec3<f32>, total: f32, depth: f32) {
// #if SRGB8
    let finite = is_finite_f32(rgb.x) && is_finite_f32(rgb.y) && is_finite_f32(rgb.z)
        && is_finite_f32(total) && is_finite_f32(depth);
    let alpha = select(0u, 255u, finite);
    out_buf[i] = srgb8_code(rgb.x) | (srgb8_code(rgb.y) << 8u) | (srgb8_code(rgb.z) << 16u) | (alpha << 24u);
// #else
    out_buf[4u * i] = bitcast<u32>(rgb.x);
    out_buf[4u * i + 1u] = bitcast<u32>(rgb.y);
    out_buf[4u * i + 2u] = bitcast<u32>(rgb.z);
    out_buf[4u * i + 3u] = bitcast<u32>(1.0);
    out_buf[4u * n + i] = bitcast<u32>(total);
    out_buf[5u * n + i] = bitcast<u32>(depth);
// #endif
}

// The wave pass's variant (pipeline-overridable constants; see passes/wave.rs WaveVariant, which sets
// each from the frame's contents). The defaults, all true, give the uber-shader that handles any
// frame. A part set false is compiled out: on a software adapter (llvmpipe runs both sides of
// every branch under a mask) that is what keeps a frame from paying for what it does not contain.
// With a part set true the code is exactly the uber-shader's. Here: whether any surface is drawn, the
// `[area_light]` and the colour mappings; wave_energy.wgsl (the wave kinds), energy.wgsl,
// curve.wgsl, shading.wgsl and shadow_lookup.wgsl have the others.
override USE_SURFACES: bool = true;
override USE_AREA: bool = true;
override USE_TONE_FAITHFUL: bool = true;
override USE_TONE_FILMIC: bool = true;

// One image pixel of a frame at one sample per pixel (grid = 1): its G-buffer texel shaded, the
// waves' light along its ray clipped at the surface, the colour mapped. cs_samples is the same
// pixel resolved from grid × grid samples.
@compute @workgroup_size(8, 8, 1)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    load_frame();
    if (id.x >= frame.tile_size.x || id.y >= frame.tile_size.y) {
        return;
    }
    let px = frame.tile_origin.x + id.x;
    let py = frame.tile_origin.y + id.y;
    let n = frame.tile_size.x * frame.tile_size.y;
    let i = id.y * frame.tile_size.x + id.x;

    // Without surfaces (a frame of waves alone) the G-buffer is not read at all.
    var texel = vec4<f32>(0.0);
    if (USE_SURFACES) {
        texel = bitcast<vec4<f32>>(textureLoad(scene_texels, vec2<i32>(id.xy), 0));
    }
    let drawn = texel.w > 0.0;
    var surface = -1.0;
    var scene = frame.background;
    let dir = pixel_dir(frame, px, py);
    if (USE_SURFACES && drawn) {
        surface = texel.w;
        let attributes = textureLoad(attribute_texels, vec2<i32>(id.xy), 0);
        let m = materials[attributes.w & ~HULL_BIT];
        if ((attributes.w & HULL_BIT) != 0u) {
            scene = m.outline_color;
        } else {
            let world = surface_point(frame, dir, surface);
            let uv = vec2<f32>(bitcast<f32>(attributes.x), bitcast<f32>(attributes.y));
            scene = shade_surface(m, world, texel.xyz, uv, unpack4x8unorm(attributes.z));
            scene = apply_shadows(scene, m.shadow_mask, world, id.xy);
            if (USE_AREA && frame.area != 0u) {
                // As hadou-cpu's opaque_pass: c + visibility · area term, saturated, after the hard
                // shadows. soft.wgsl's cs_gather left the visibility in the eye-distance slot.
                let v = out_slot5(n, i);
                let t = v * area_term(m, world, texel.xyz, uv, unpack4x8unorm(attributes.z));
                scene = vec3<f32>(energy_saturate(scene.x + t.x), energy_saturate(scene.y + t.y), energy_saturate(scene.z + t.z));
            }
        }
    }

    let lit_by = waves_light(dir, surface);
    let total = lit_by.total;
    let light = lit_by.light;
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
    var depth = frame.far * length3(dir);
    if (USE_SURFACES && drawn) {
        depth = surface;
    }
    store_pixel(i, n, rgb, total, depth);
}
