// Surface shading of the wave pass: twins of hadou_math::toon (ramps, nearest points of centre
// lines, dominance weights, texture sampling) and of hadou-cpu's shading::shade (000 §2.1–2.2,
// SPEC.md §2.1–2.2). It reads `lights`, `shading_data` and `polyline_point` from
// shading_bindings.wgsl (the wave pass) or from whoever composes it in their place (hadou-bevy's
// material declares its own), and `frame`'s light_dir, light_color, ambient, wave_count,
// any_glow, area_position and area_color.

// The shading the frame's materials and lights need (pipeline-overridable; see USE_SPHERE in
// wave.wgsl): toon-model materials, textures (base or feature), the waves as lights (some material
// blends towards them or some wave glows) and each kind of light line. The rest is compiled out.
override USE_TOON: bool = true;
override USE_MTOON: bool = true;
override USE_TEXTURES: bool = true;
override USE_WAVE_LIGHTS: bool = true;
override USE_LINE_POINT: bool = true;
override USE_LINE_SEGMENT: bool = true;
override USE_LINE_LINE: bool = true;
override USE_LINE_POLYLINE: bool = true;

// Mirrors hadou_math::toon::nearest_on_segment.
fn nearest_on_segment(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    let d = b - a;
    let dd = dot3(d, d);
    if (!(dd > 0.0) || !(dd <= 3.4028234663852886e38)) {
        return a;
    }
    let t = clamp(dot3(p - a, d) / dd, 0.0, 1.0);
    return a + d * t;
}

// Mirrors hadou_scene::LightLine::nearest.
fn light_nearest(l: GpuLight, p: vec3<f32>) -> vec3<f32> {
    // Each line kind is compiled in only when the frame has it (USE_LINE_*).
    switch l.line_kind {
        case LINE_POINT: {
            if (USE_LINE_POINT) {
                return l.a.xyz;
            }
        }
        case LINE_SEGMENT: {
            if (USE_LINE_SEGMENT) {
                return nearest_on_segment(p, l.a.xyz, l.b.xyz);
            }
        }
        case LINE_LINE: {
            if (USE_LINE_LINE) {
                return l.a.xyz + l.b.xyz * dot3(p - l.a.xyz, l.b.xyz);
            }
        }
        default: {
            // hadou_math::toon::nearest_on_polyline
            if (USE_LINE_POLYLINE) {
                if (l.point_count == 0u) {
                    return p;
                }
                var best = polyline_point(l.point_offset, 0u);
                if (l.point_count == 1u) {
                    return best;
                }
                var best_d = 3.4028234663852886e38;
                for (var i = 0u; i + 1u < l.point_count; i++) {
                    let q = nearest_on_segment(p, polyline_point(l.point_offset, i), polyline_point(l.point_offset, i + 1u));
                    let e = q - p;
                    let d = dot3(e, e);
                    if (d < best_d) {
                        best_d = d;
                        best = q;
                    }
                }
                return best;
            }
        }
    }
    return p;
}

// Mirrors hadou_math::toon::wave_m.
fn wave_m(p: vec3<f32>, n: vec3<f32>, e: vec3<f32>) -> f32 {
    let v = e - p;
    let len = length3(v);
    if (len > 0.0 && len <= 3.4028234663852886e38) {
        return clamp(dot3(n, v / len), -1.0, 1.0);
    }
    return 1.0;
}

// Mirrors hadou_math::toon::dominance.
fn dominance(distance: f32, core_radius: f32, strength: f32, inverse_square: bool) -> f32 {
    let rc = max(core_radius, 1.0e-4);
    let q = distance * distance + rc * rc;
    var rho = 1.0 / sqrt(q);
    if (inverse_square) {
        rho = 1.0 / q;
    }
    let v = max(strength, 0.0) * rho;
    if (v != v) {
        return 0.0;
    }
    return min(v, 3.4028234663852886e38);
}

// The density of light `l` at `world`, whose light point is `e` (hadou_math::toon::dominance with
// the wave's core radius, strength and falloff).
fn light_density(l: GpuLight, world: vec3<f32>, e: vec3<f32>) -> f32 {
    return dominance(length3(e - world), l.color.w, l.a.w, l.inverse_square != 0u);
}

// Mirrors hadou_math::toon::wrap_index (wrap: 0 repeat, 1 clamp, 2 mirror).
fn wrap_index(i: i32, n: i32, wrap: u32) -> i32 {
    if (wrap == 1u) {
        return clamp(i, 0, n - 1);
    }
    if (wrap == 0u) {
        return ((i % n) + n) % n;
    }
    let k = ((i % (2 * n)) + 2 * n) % (2 * n);
    if (k < n) {
        return k;
    }
    return 2 * n - 1 - k;
}

fn srgb(v: u32) -> f32 {
    return bitcast<f32>(shading_data[v]);
}

fn texel(t: GpuTexture, i_in: i32, j_in: i32) -> vec4<f32> {
    let i = wrap_index(i_in, i32(t.width), t.flags & 3u);
    let j = wrap_index(j_in, i32(t.height), (t.flags >> 2u) & 3u);
    let w = shading_data[t.offset + u32(j) * t.width + u32(i)];
    return vec4<f32>(srgb(w & 255u), srgb((w >> 8u) & 255u), srgb((w >> 16u) & 255u), f32(w >> 24u) / 255.0);
}

fn fix_coord(v: f32) -> f32 {
    if (v != v || abs(v) > 3.4028234663852886e38) {
        return 0.0;
    }
    return clamp(v, -1.0e6, 1.0e6);
}

// Mirrors hadou_math::toon::sample: level 0, texel centres at ((i + ½)/w, (j + ½)/h), bilinear
// in linear light or nearest. `offset` 0 means no texture: opaque white.
fn sample_texture(t: GpuTexture, uv: vec2<f32>) -> vec4<f32> {
    if (!USE_TEXTURES || t.offset == 0u || t.width == 0u || t.height == 0u) {
        return vec4<f32>(1.0);
    }
    let x = fix_coord(uv.x) * f32(t.width);
    let y = fix_coord(uv.y) * f32(t.height);
    if ((t.flags & 16u) != 0u) {
        return texel(t, i32(floor(x)), i32(floor(y)));
    }
    let xs = x - 0.5;
    let ys = y - 0.5;
    let x0 = floor(xs);
    let y0 = floor(ys);
    let fx = xs - x0;
    let fy = ys - y0;
    let i0 = i32(x0);
    let j0 = i32(y0);
    let a = texel(t, i0, j0);
    let b = texel(t, i0 + 1, j0);
    let c = texel(t, i0, j0 + 1);
    let d = texel(t, i0 + 1, j0 + 1);
    let top = a + (b - a) * fx;
    let bottom = c + (d - c) * fx;
    return top + (bottom - top) * fy;
}

// ---- MToon (VRMC_materials_mtoon 1.0): twins of hadou_math::mtoon and hadou-cpu's
// shading::mtoon_* functions. A material's MToon block (layout/ `mtoon_block`) is read from
// shading_data at word offset `o`.

fn mtoon_f32(o: u32) -> f32 {
    return bitcast<f32>(shading_data[o]);
}

fn mtoon_vec3(o: u32) -> vec3<f32> {
    return vec3<f32>(mtoon_f32(o), mtoon_f32(o + 1u), mtoon_f32(o + 2u));
}

// The k-th texture record of the block (0 shade, 1 shift, 2 rim, 3 matcap, 4 UV mask, 5 emissive).
fn mtoon_texture(o: u32, k: u32) -> GpuTexture {
    let w = o + 28u + 4u * k;
    return GpuTexture(shading_data[w], shading_data[w + 1u], shading_data[w + 2u], shading_data[w + 3u]);
}

// Mirrors hadou_math::mtoon::data_texel: a data texture's stored value from the decoded colour.
fn mtoon_data(linear: f32, channel: u32) -> f32 {
    var v = clamp(linear, 0.0, 1.0);
    if (linear != linear) {
        v = 0.0;
    }
    if (channel >= 3u) {
        return v;
    }
    if (v <= 0.0031308) {
        return 12.92 * v;
    }
    return 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

// Mirrors hadou_math::mtoon::linearstep.
fn mtoon_linearstep(a: f32, b: f32, t: f32) -> f32 {
    if (b > a) {
        return clamp((t - a) / (b - a), 0.0, 1.0);
    }
    if (t >= a) {
        return 1.0;
    }
    return 0.0;
}

// Mirrors hadou_math::mtoon::shading.
fn mtoon_shading(n_dot_l: f32, shift: f32, toony: f32) -> f32 {
    return mtoon_linearstep(-1.0 + toony, 1.0 - toony, n_dot_l + shift);
}

// Mirrors hadou_math::mtoon::lit.
fn mtoon_lit(shade: vec3<f32>, base: vec3<f32>, s: f32, light: vec3<f32>) -> vec3<f32> {
    return (shade + (base - shade) * s) * light;
}

// Mirrors hadou_math::mtoon::parametric_rim.
fn mtoon_rim(n_dot_v: f32, lift: f32, power: f32, color: vec3<f32>) -> vec3<f32> {
    let x = clamp(1.0 - n_dot_v + lift, 0.0, 1.0);
    let p = max(power, 0.0);
    var f = 0.0;
    if (x > 0.0) {
        f = pow(x, p);
    } else if (p == 0.0) {
        f = 1.0;
    }
    return color * f;
}

// Unit `v`, or `fallback` for a zero or non-finite vector (hadou_math::Vec3::normalize_or).
fn normalize_or(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let l = length3(v);
    if (l > 0.0 && l <= 3.4028234663852886e38) {
        return v / l;
    }
    return fallback;
}

// Mirrors hadou_math::mtoon::matcap_uv.
fn mtoon_matcap_uv(n: vec3<f32>, v: vec3<f32>) -> vec2<f32> {
    let x = normalize_or(vec3<f32>(v.z, 0.0, -v.x), vec3<f32>(1.0, 0.0, 0.0));
    let y = cross3(v, x);
    return vec2<f32>(0.5 + 0.495 * dot3(x, n), 0.5 - 0.495 * dot3(y, n));
}

// Mirrors hadou_math::mtoon::uv_animation.
fn mtoon_uv(uv: vec2<f32>, mask: f32, scroll: vec2<f32>, turn: f32) -> vec2<f32> {
    let tau = 6.28318530717958647;
    var a = turn * mask;
    if (abs(a) <= 3.4028234663852886e38) {
        a = a - tau * floor(a / tau);
    } else {
        a = 0.0;
    }
    let s = sin(a);
    let c = cos(a);
    let u = uv.x - 0.5;
    let v = uv.y - 0.5;
    return vec2<f32>(c * u - s * v + 0.5 + scroll.x * mask, s * u + c * v + 0.5 + scroll.y * mask);
}

// Mirrors hadou-cpu's shading::MtoonPoint.
struct MtoonPoint {
    uv: vec2<f32>,
    albedo: vec3<f32>,
    shade: vec3<f32>,
    shift: f32,
}

// Mirrors hadou-cpu's shading::mtoon_point.
fn mtoon_point(m: GpuMaterial, uv_in: vec2<f32>, vcolor: vec4<f32>) -> MtoonPoint {
    let o = m.mtoon;
    var mask = 1.0;
    let mask_t = mtoon_texture(o, 4u);
    if (mask_t.offset != 0u) {
        let channel = min(shading_data[o + 21u], 3u);
        mask = mtoon_data(sample_texture(mask_t, uv_in)[channel], channel);
    }
    let motion = mtoon_motion(o);
    let uv = mtoon_uv(uv_in, mask, motion.xy, motion.z);
    var p: MtoonPoint;
    p.uv = uv;
    p.albedo = m.base_color * sample_texture(m.base_texture, uv).xyz * vcolor.xyz;
    p.shade = mtoon_vec3(o) * sample_texture(mtoon_texture(o, 0u), uv).xyz;
    p.shift = mtoon_f32(o + 16u);
    let shift_t = mtoon_texture(o, 1u);
    if (shift_t.offset != 0u) {
        p.shift = p.shift + mtoon_data(sample_texture(shift_t, uv).x, 0u) * mtoon_f32(o + 17u);
    }
    return p;
}

// Mirrors hadou-cpu's shading::mtoon_own: the MToon look under the scene light.
fn mtoon_own(o: u32, p: MtoonPoint, n: vec3<f32>, world: vec3<f32>) -> vec3<f32> {
    let sh = mtoon_shading(dot3(n, -frame.light_dir), p.shift, mtoon_f32(o + 3u));
    let direct = mtoon_lit(p.shade, p.albedo, sh, frame.light_color);
    let v = normalize_or(mtoon_eye(o) - world, n);
    let para = mtoon_rim(dot3(n, v), mtoon_f32(o + 11u), mtoon_f32(o + 7u), mtoon_vec3(o + 4u));
    var cap = vec3<f32>(0.0);
    let cap_t = mtoon_texture(o, 3u);
    if (cap_t.offset != 0u) {
        cap = mtoon_vec3(o + 8u) * sample_texture(cap_t, mtoon_matcap_uv(n, v)).xyz;
    }
    let rt = sample_texture(mtoon_texture(o, 2u), p.uv).xyz;
    let lighting = frame.light_color + frame.ambient;
    let mix_f = vec3<f32>(1.0) + (lighting - vec3<f32>(1.0)) * mtoon_f32(o + 15u);
    let et = sample_texture(mtoon_texture(o, 5u), p.uv).xyz;
    let rim = (cap + para) * rt * mix_f;
    let c = direct + p.albedo * frame.ambient + rim + mtoon_vec3(o + 12u) * et;
    return vec3<f32>(energy_saturate(c.x), energy_saturate(c.y), energy_saturate(c.z));
}

// Mirrors hadou-cpu's shading::mtoon_wave: a wave's light through the material's own step.
fn mtoon_wave(o: u32, p: MtoonPoint, m: f32, rgb: vec3<f32>) -> vec3<f32> {
    return mtoon_lit(p.shade, p.albedo, mtoon_shading(m, p.shift, mtoon_f32(o + 3u)), rgb);
}

// Most waves weighed per surface point (hadou_scene's limit is 256 waves per scene).
const MAX_LIGHTS: u32 = 256u;

// Mirrors hadou-cpu's shading::shade: own look, the waves' look weighted by their dominance,
// glow, feature texture. `normal_in` need not be unit; `vcolor` is the 8-bit vertex colour.
fn shade_surface(m: GpuMaterial, world: vec3<f32>, normal_in: vec3<f32>, uv: vec2<f32>, vcolor: vec4<f32>) -> vec3<f32> {
    let len = length3(normal_in);
    var n = vec3<f32>(0.0);
    if (len > 0.0 && len < 3.0e38) {
        n = normal_in / len;
    }
    let is_mtoon = USE_MTOON && m.mtoon != 0u;
    var mp: MtoonPoint;
    var tuv = uv;
    var c = vec3<f32>(0.0);
    if (is_mtoon) {
        mp = mtoon_point(m, uv, vcolor);
        tuv = mp.uv;
        c = mtoon_own(m.mtoon, mp, n, world);
    } else {
        let tex = sample_texture(m.base_texture, uv);
        let albedo = m.base_color * tex.xyz * vcolor.xyz;
        c = albedo;
        if (m.model == MODEL_DIFFUSE) {
            c = diffuse(albedo, n, frame.light_dir, frame.light_color, frame.ambient);
        } else if (USE_TOON && m.model == MODEL_TOON) {
            c = albedo * ramp_eval(m.ramp, dot3(n, -frame.light_dir));
        }
    }
    let count = min(frame.wave_count, MAX_LIGHTS);
    if (USE_WAVE_LIGHTS && count > 0u && (m.wave_blend > 0.0 || frame.any_glow != 0u)) {
        // Pass 1: the largest density and the glow.
        var max_rho = 0.0;
        var glow = vec3<f32>(0.0);
        for (var i = 0u; i < count; i++) {
            let l = lights[i];
            let e = light_nearest(l, world);
            let rho = light_density(l, world, e);
            max_rho = max(max_rho, rho);
            if (l.b.w > 0.0) {
                glow = glow + l.b.w * l.color.xyz * rho;
            }
        }
        if (m.wave_blend > 0.0 && max_rho > 0.0) {
            // Pass 2: weights (rho/max)², their sum, and the weighted looks
            // (hadou_math::toon::dominance_weights).
            var sum = 0.0;
            var look = vec3<f32>(0.0);
            for (var i = 0u; i < count; i++) {
                let l = lights[i];
                let e = light_nearest(l, world);
                let rho = light_density(l, world, e);
                let x = rho / max_rho;
                let w = x * x;
                sum = sum + w;
            }
            for (var i = 0u; i < count; i++) {
                let l = lights[i];
                let e = light_nearest(l, world);
                let rho = light_density(l, world, e);
                let x = rho / max_rho;
                let w = (x * x) / sum;
                if (w > 0.0) {
                    let wm = wave_m(world, n, e);
                    if (is_mtoon) {
                        look = look + w * mtoon_wave(m.mtoon, mp, wm, l.color.xyz);
                    } else {
                        look = look + w * ramp_eval(l.ramp, wm);
                    }
                }
            }
            c = c + m.wave_blend * (look - c);
        }
        c = vec3<f32>(energy_saturate(c.x + glow.x), energy_saturate(c.y + glow.y), energy_saturate(c.z + glow.z));
    }
    if (USE_TEXTURES && m.feature_texture.offset != 0u) {
        c = c * sample_texture(m.feature_texture, tuv).xyz;
    }
    return c;
}

// Twin of hadou_math::soft::lamp_spread: (facing, sin σ) of the lamp for a receiver at p (the
// segment (1, 0); the disc max(0, l̂·P) and sin²σ = l²/(l² + d²); the sphere (1, min(l/d, 1))).
fn lamp_spread(p: vec3<f32>) -> vec2<f32> {
    let r = frame.area_position - p;
    let d = length3(r);
    let size = frame.area_size;
    if (frame.area_shape == LAMP_DISC) {
        let facing = max(dot3(r / max(d, 1.17549435e-38), frame.area_axis), 0.0);
        let s2 = size * size / (size * size + d * d);
        var out = vec2<f32>(0.0);
        if (is_finite_value(facing)) {
            out.x = facing;
        }
        if (is_finite_value(s2)) {
            out.y = sqrt(s2);
        }
        return out;
    }
    if (frame.area_shape == LAMP_SPHERE) {
        var s = 1.0;
        if (d > size) {
            s = size / d;
        }
        return vec2<f32>(1.0, s);
    }
    return vec2<f32>(1.0, 0.0);
}

// Whether `v` is neither NaN nor infinite (by its exponent bits).
fn is_finite_value(v: f32) -> bool {
    return (bitcast<u32>(v) & 0x7f800000u) != 0x7f800000u;
}

// Twin of hadou_math::soft::lamp_cosine: the horizon-clipped irradiance factor of a lamp of
// angular radius σ at m = N·l̂ (Snyder 1996 in Lagarde & de Rousiers 2014, eq. 34), max(0, m)
// where the lamp is wholly above or below the horizon.
fn lamp_cosine(m_in: f32, sin_sigma: f32) -> f32 {
    if (m_in != m_in) {
        return 0.0;
    }
    let m = clamp(m_in, -1.0, 1.0);
    if (!(sin_sigma > 1e-4) || m * m >= sin_sigma * sin_sigma) {
        return max(m, 0.0);
    }
    let s2 = min(sin_sigma * sin_sigma, 1.0 - 1e-6);
    let x = sqrt(1.0 / s2 - 1.0);
    let sin_t = max(sqrt(max(1.0 - m * m, 0.0)), 1e-6);
    let y = clamp(-x * m / sin_t, -1.0, 1.0);
    let sy = sin_t * sqrt(max(1.0 - y * y, 0.0));
    let e = (m * acos(y) - x * sy) * s2 + atan(sy / x);
    return clamp(e / (3.14159265358979 * s2), 0.0, 1.0);
}

// Twin of hadou_math::soft::lamp_toon_cosine: the ramps' input, m plus what the lamp's horizon
// adds to the diffuse factor.
fn lamp_toon_cosine(m: f32, sin_sigma: f32) -> f32 {
    if (!(sin_sigma > 1e-4)) {
        return m;
    }
    return m + lamp_cosine(m, sin_sigma) - max(m, 0.0);
}

// Twin of hadou_cpu::shading::area_term: what the `[area_light]` adds to a visible point where it
// is fully visible (the soft shadow's visibility scales it): with l̂ the unit vector from the point
// to the light centre and m = N·l̂, for the segment lamp diffuse A·E·max(0, m), toon A·E·ramp(m),
// MToon mix(shade, A, step(m + shift))·E, unlit nothing; a disc or sphere lamp of facing f and
// angular radius σ (lamp_spread) diffuse A·E·f·lamp_cosine(m, sin σ), toon A·E·f·ramp(m') and
// MToon f·mix(shade, A, step(m' + shift))·E with m' = lamp_toon_cosine(m, sin σ); then the feature
// texture. E = frame.area_color (colour times intensity).
fn area_term(m: GpuMaterial, world: vec3<f32>, normal_in: vec3<f32>, uv: vec2<f32>, vcolor: vec4<f32>) -> vec3<f32> {
    let is_mtoon = USE_MTOON && m.mtoon != 0u;
    if (!is_mtoon && m.model != MODEL_DIFFUSE && m.model != MODEL_TOON) {
        return vec3<f32>(0.0);
    }
    let len = length3(normal_in);
    var n = vec3<f32>(0.0);
    if (len > 0.0 && len < 3.0e38) {
        n = normal_in / len;
    }
    let to_light = frame.area_position - world;
    let dl = length3(to_light);
    var dir = vec3<f32>(0.0);
    if (dl > 0.0 && dl < 3.0e38) {
        dir = to_light / dl;
    }
    let mdot = dot3(n, dir);
    // The diffuse factor, the ramps' input and the facing (the segment's: m itself).
    var diffuse = max(mdot, 0.0);
    var ramp_in = mdot;
    var facing = 1.0;
    if (frame.area_shape != LAMP_SEGMENT) {
        let spread = lamp_spread(world);
        facing = spread.x;
        diffuse = spread.x * lamp_cosine(mdot, spread.y);
        ramp_in = lamp_toon_cosine(mdot, spread.y);
    }
    if (is_mtoon) {
        let p = mtoon_point(m, uv, vcolor);
        var k = mtoon_wave(m.mtoon, p, ramp_in, frame.area_color);
        if (frame.area_shape != LAMP_SEGMENT) {
            k = k * facing;
        }
        var f = vec3<f32>(1.0);
        if (m.feature_texture.offset != 0u) {
            f = sample_texture(m.feature_texture, p.uv).xyz;
        }
        let t = k * f;
        return vec3<f32>(energy_saturate(t.x), energy_saturate(t.y), energy_saturate(t.z));
    }
    var k = vec3<f32>(diffuse);
    if (USE_TOON && m.model == MODEL_TOON) {
        k = ramp_eval(m.ramp, ramp_in);
        if (frame.area_shape != LAMP_SEGMENT) {
            k = k * facing;
        }
    }
    let tex = sample_texture(m.base_texture, uv);
    let a = m.base_color * tex.xyz * vcolor.xyz;
    var f = vec3<f32>(1.0);
    if (m.feature_texture.offset != 0u) {
        f = sample_texture(m.feature_texture, uv).xyz;
    }
    let t = a * frame.area_color * k * f;
    return vec3<f32>(energy_saturate(t.x), energy_saturate(t.y), energy_saturate(t.z));
}
