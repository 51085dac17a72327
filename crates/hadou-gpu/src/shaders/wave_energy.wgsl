// The waves' light on one pixel, shared by the wave pass (wave.wgsl) and the wave overlay
// (wave_overlay.wgsl): per wave the integration ray of hadou_scene::CameraBasis::wave_ray (002
// eq. 3.12–3.13, clipped at the visible surface, 002 §3.3.5), its energy (energy.wgsl, curve.wgsl)
// and Σ rgb·a·I. Prepended by common.wgsl, energy.wgsl and curve.wgsl; the frame's uniforms and
// waves are bindings 0 and 1 of both modules.

@group(0) @binding(0) var<uniform> frame_uniforms: FrameUniforms;
@group(0) @binding(1) var<storage, read> waves: array<GpuWave>;
// The frame's uniforms as the functions below read them: a private copy, made by load_frame() at
// the top of every entry point of the modules composed with this file.
var<private> frame: FrameUniforms;

// Copies the uniforms into `frame`, its words that decide branches and loop counts hidden from
// the driver's constant folding. Mesa's lavapipe (the software Vulkan adapter) compiles a large
// shader again for every new value of up to four uniforms that decide its branches ("uniform
// inlining"): a new wave count, tone mapping, sample grid, shadow count or `[area_light]` cost a
// whole compile (about 20 s for the uber-shader, up to seconds for a specialised variant) once per
// scene, and a live edit of any of them stalled the viewer. OR-ing each with a zero the driver
// cannot prove (the top bit of the waves buffer's length: no buffer holds 2³¹ waves) changes no
// value and no branch, and one compile serves every frame of a variant.
fn load_frame() {
    frame = frame_uniforms;
    let zero = arrayLength(&waves) >> 31u;
    frame.tone_mode |= zero;
    frame.wave_count |= zero;
    frame.any_glow |= zero;
    frame.image_size |= vec2<u32>(zero);
    frame.tile_origin |= vec2<u32>(zero);
    frame.tile_size |= vec2<u32>(zero);
    frame.shadow_casts |= zero;
    frame.map_casts |= zero;
    frame.cast_count |= zero;
    frame.map_count |= zero;
    frame.plane_count |= zero;
    frame.area |= zero;
    frame.outline_reach |= zero;
    frame.grid |= zero;
}
// The wave kinds a frame contains (pipeline-overridable; see passes/wave.rs WaveVariant).
override USE_SPHERE: bool = true;
override USE_CYLINDER: bool = true;
override USE_CAPSULE: bool = true;
override USE_BEAM: bool = true;
override USE_CURVE: bool = true;
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
    // t_far of hadou_scene::WaveRay: 1 (faithful, t ∈ [0, 1] to the far point) or the far point's
    // distance (inverse square, unit direction); the analytic kinds' attenuation (002 eq. 3.23).
    var t_far = 1.0;
    if (w.falloff != FALLOFF_FAITHFUL) {
        t_far = frame.far * length3(dir);
    }
    let att = Attenuation(w.attenuation, t_far);
    // Each kind is compiled in only when its USE_* is set (the variant has the frame's kinds). With
    // attenuation compiled in, the analytic kinds share one call of its march (analytic_energy);
    // without, each piece's closed form is called where it is made (analytic_energy_direct).
    let kinds = select(0u, KIND_BIT_SPHERE, USE_SPHERE) | select(0u, KIND_BIT_CYLINDER, USE_CYLINDER)
        | select(0u, KIND_BIT_CAPSULE, USE_CAPSULE) | select(0u, KIND_BIT_BEAM, USE_BEAM);
    switch w.kind {
        case WAVE_SPHERE, WAVE_CYLINDER, WAVE_CAPSULE, WAVE_BEAM: {
            if (kinds != 0u) {
// #if ATTENUATION
                return analytic_energy(p, ray, span.x, span.y, att, w, kinds);
// #else
                return analytic_energy_direct(p, ray, span.x, span.y, w, kinds);
// #endif
            }
        }
        case WAVE_CURVE: {
            if (USE_CURVE) {
                return curve_energy(curves[u32(w.p0.x)], w.falloff, w.core_radius, ray, span.x, span.y, t_far);
            }
        }
        default: {}
    }
    return 0.0;
}

// The total energy Σ I and the light Σ rgb·a·I of every wave on the pixel with direction `dir`
// (pixel_dir) whose visible surface is `surface` away (< 0: nothing drawn).
struct WavesLight {
    total: f32,
    light: vec3<f32>,
}

fn waves_light(dir: vec3<f32>, surface: f32) -> WavesLight {
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
    return WavesLight(total, light);
}
