// Wave pass: per pixel, the visible surface's shading from the raster pass's G-buffer
// (shading.wgsl: materials, the waves as lights), the integration ray of
// hadou_scene::CameraBasis::wave_ray (002 eq. 3.12–3.13, clipped at the visible surface), the energy
// of every wave (energy.wgsl), the colour scene + exposure·Σ rgb·a·I and the colour mapping
// (common.wgsl). Prepended by common.wgsl, energy.wgsl, curve.wgsl (curve buffers: bindings 5–7),
// shading.wgsl (bindings 8–10) and shadow_lookup.wgsl (hard shadows: bindings 11–12).

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<storage, read> waves: array<GpuWave>;
// The raster pass's G-buffer (raster.wgsl): (normal, eye distance) as f32 bits, distance 0 =
// nothing drawn; (u, v, pack4x8unorm colour, material | HULL_BIT).
@group(0) @binding(2) var scene_texels: texture_2d<u32>;
@group(0) @binding(3) var attribute_texels: texture_2d<u32>;
// Tile output, n = tile_size.x · tile_size.y pixels, row-major: colour (4 floats per pixel) in
// [0, 4n), energy in [4n, 5n), eye distance in [5n, 6n). Keep in sync with readback in render.rs.
@group(0) @binding(4) var<storage, read_write> out_buf: array<f32>;

// The wave pass's variant (pipeline-overridable constants; see pipelines::WaveVariant, which sets
// each from the frame's contents). The defaults, all true, give the uber-shader that handles any
// frame. A part set false is compiled out: on a software adapter (llvmpipe runs both sides of
// every branch under a mask) that is what keeps a frame from paying for what it does not contain.
// With a part set true the code is exactly the uber-shader's. Here: the wave kinds, whether any
// surface is drawn, the `[area_light]` and the colour mappings; energy.wgsl, curve.wgsl,
// shading.wgsl and shadow_lookup.wgsl have the others.
override USE_SPHERE: bool = true;
override USE_CYLINDER: bool = true;
override USE_CAPSULE: bool = true;
override USE_BEAM: bool = true;
override USE_CURVE: bool = true;
override USE_SURFACES: bool = true;
override USE_AREA: bool = true;
override USE_TONE_FAITHFUL: bool = true;
override USE_TONE_FILMIC: bool = true;

// Mirrors hadou_scene::CameraBasis::wave_ray: the ray and span of one pixel for one falloff.
// `surface < 0` means nothing was drawn (None).
fn wave_ray(falloff: u32, dir: vec3<f32>, surface: f32, span: ptr<function, vec2<f32>>) -> Ray {
    let len = length3(dir);
    let far_dist = frame.far * len;
    if (falloff == FALLOFF_FAITHFUL) {
        var g = 1.0;
        if (surface >= 0.0) {
            g = min(surface / far_dist, 1.0);
        }
        *span = vec2<f32>(0.0, g);
        return Ray(frame.eye, dir * frame.far);
    }
    var t1 = T_OPEN;
    if (surface >= 0.0) {
        t1 = surface;
    }
    *span = vec2<f32>(0.0, t1);
    return Ray(frame.eye, dir / len);
}

// Energy of one wave on one pixel; the dispatch over hadou_scene::WaveShape.
fn wave_energy(w: GpuWave, dir: vec3<f32>, surface: f32) -> f32 {
    var span = vec2<f32>(0.0, 0.0);
    let ray = wave_ray(w.falloff, dir, surface, &span);
    let p = FieldParams(w.falloff, w.core_radius);
    // Each kind's case is compiled in only when its USE_* is set (the variant has the frame's kinds).
    switch w.kind {
        case WAVE_SPHERE: {
            if (USE_SPHERE) {
                return sphere_energy(p, ray, span.x, span.y, w.p0.xyz, w.p0.w);
            }
        }
        case WAVE_CYLINDER: {
            if (USE_CYLINDER) {
                return cylinder_energy(p, ray, span.x, span.y, w.p0.xyz, w.p1.xyz, w.p0.w);
            }
        }
        case WAVE_CAPSULE: {
            if (USE_CAPSULE) {
                return capsule_energy(p, ray, span.x, span.y, w.p0.xyz, w.p1.xyz, w.p2.x, w.p0.w, w.p1.w);
            }
        }
        case WAVE_BEAM: {
            if (USE_BEAM) {
                return beam_energy(p, ray, span.x, span.y, w.p0.xyz, w.p1.xyz, w.p2.x, w.p0.w, w.p1.w, w.p2.y, w.p2.z);
            }
        }
        case WAVE_CURVE: {
            if (USE_CURVE) {
                // t_far of hadou_scene::WaveRay: 1 (faithful, t ∈ [0, 1] to the far point) or the
                // far point's distance (inverse square, unit direction).
                var t_far = 1.0;
                if (w.falloff != FALLOFF_FAITHFUL) {
                    t_far = frame.far * length3(dir);
                }
                return curve_energy(curves[u32(w.p0.x)], w.falloff, w.core_radius, ray, span.x, span.y, t_far);
            }
        }
        default: {}
    }
    return 0.0;
}

@compute @workgroup_size(8, 8, 1)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= frame.tile_size.x || id.y >= frame.tile_size.y) {
        return;
    }
    let px = frame.tile_origin.x + id.x;
    let py = frame.tile_origin.y + id.y;
    let n = frame.tile_size.x * frame.tile_size.y;
    let i = id.y * frame.tile_size.x + id.x;

    let texel = bitcast<vec4<f32>>(textureLoad(scene_texels, vec2<i32>(id.xy), 0));
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
                let v = out_buf[5u * n + i];
                let t = v * area_term(m, world, texel.xyz, uv, unpack4x8unorm(attributes.z));
                scene = vec3<f32>(energy_saturate(scene.x + t.x), energy_saturate(scene.y + t.y), energy_saturate(scene.z + t.z));
            }
        }
    }

    var total = 0.0;
    var light = vec3<f32>(0.0);
    for (var k = 0u; k < frame.wave_count; k++) {
        let w = waves[k];
        // As hadou-cpu's wave pass: energies saturate at f32::MAX (hadou_math::energy::saturate),
        // and so do their sums, so a saturated pixel is full brightness, never 0 or NaN.
        let e = energy_saturate(wave_energy(w, dir, surface));
        total = energy_add(total, e);
        let c = w.color.xyz * w.color.w;
        light = vec3<f32>(energy_add(light.x, c.x * e), energy_add(light.y, c.y * e), energy_add(light.z, c.z * e));
    }
    // exposure · light without overflowing (energy_scaled); the mappings then take f32::MAX to 1.
    let lit = vec3<f32>(energy_scaled(light.x, frame.exposure), energy_scaled(light.y, frame.exposure), energy_scaled(light.z, frame.exposure));
    let rgb_in = scene + lit;
    var rgb = vec3<f32>(0.0);
    if (frame.tone_mode == TONE_FAITHFUL) {
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
    out_buf[4u * i] = rgb.x;
    out_buf[4u * i + 1u] = rgb.y;
    out_buf[4u * i + 2u] = rgb.z;
    out_buf[4u * i + 3u] = 1.0;
    out_buf[4u * n + i] = total;
    out_buf[5u * n + i] = depth;
}
