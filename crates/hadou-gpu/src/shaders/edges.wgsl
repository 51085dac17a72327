// Edge pass: closed outlines where objects meet (twin of hadou-cpu's edges.rs, with the formulas
// of hadou_math::outline, 000 §2.3). Drawn as one full-screen triangle over the tile; each
// fragment reads the raster pass's G-buffer (raster.wgsl) around its pixel and writes the
// attributes target the later passes read: the same words with the reach bits cleared, and where
// another object's visible edge lies within that object's outline width and in front of this
// pixel's surface, that object's material | HULL_BIT (the wave pass then gives the outline colour,
// as for a hull fragment; the eye distance stays the surface's).
// Prepended by common.wgsl.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<storage, read> materials: array<GpuMaterial>;
// G-buffer target 0: normal (xyz) and eye distance (w) as f32 bits; 0 distance = nothing drawn.
@group(0) @binding(2) var scene_texels: texture_2d<u32>;
// G-buffer target 1: u, v, colour, material word (index | reach << REACH_SHIFT | HULL_BIT).
@group(0) @binding(3) var attribute_texels: texture_2d<u32>;

// Mirrors hadou_scene::MIN_OUTLINE_DEPTH.
const MIN_OUTLINE_DEPTH: f32 = 1.0e-3;
// Mirrors hadou_math::outline::IN_FRONT_MARGIN.
const IN_FRONT_MARGIN: f32 = 1.0e-3;
// Mirrors hadou_math::outline::REACH_STEPS.
const REACH_STEPS: f32 = 255.0;

// A triangle covering the viewport: (-1, -1), (3, -1), (-1, 3).
@vertex
fn vs_edges(@builtin(vertex_index) k: u32) -> @builtin(position) vec4<f32> {
    let x = f32((k << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(k & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

// Twin of hadou_math::outline::hull_pixels.
fn hull_pixels(width: f32, tan_half_fov: f32, height: u32) -> f32 {
    let px = width * (f32(height) / (2.0 * tan_half_fov));
    if (px > 0.0 && px < 3.0e38) {
        return px;
    }
    return 0.0;
}

// Twin of hadou_scene::Material::hull_pixels for a material's GPU outline width (layout.rs
// `GpuMaterial::outline_width`: `d`, or `−w` for an MToon outline in world units) where the
// surface is at view depth `z`.
fn material_hull_pixels(width: f32, z: f32) -> f32 {
    var d = width;
    if (width < 0.0) {
        d = -width / max(abs(z), MIN_OUTLINE_DEPTH);
    }
    return hull_pixels(d, frame.tan_half_fov, frame.image_size.y);
}

// Twin of hadou_math::outline::in_front.
fn in_front(p_normal: vec3<f32>, p_dir: vec3<f32>, p_dist: f32, q_dir: vec3<f32>, q_dist: f32) -> bool {
    let len = length3(p_normal);
    var n = -p_dir;
    if (len > 0.0 && len < 3.0e38) {
        n = p_normal / len;
    }
    if (dot3(n, p_dir) > 0.0) {
        n = -n;
    }
    let num = p_dist * dot3(n, p_dir);
    let den = dot3(n, q_dir);
    return q_dist * den > num * (1.0 - IN_FRONT_MARGIN);
}

// The object (+ 1) whose surface tile pixel `p` shows; 0 for the background, a hull, or a pixel
// outside the tile.
fn owner(p: vec2<i32>) -> u32 {
    if (p.x < 0 || p.y < 0 || p.x >= i32(frame.tile_size.x) || p.y >= i32(frame.tile_size.y)) {
        return 0u;
    }
    let w = bitcast<f32>(textureLoad(scene_texels, p, 0).w);
    let word = textureLoad(attribute_texels, p, 0).w;
    if (!(w > 0.0) || (word & HULL_BIT) != 0u) {
        return 0u;
    }
    return materials[word & MATERIAL_MASK].object + 1u;
}

// Whether neighbour `p` of an edge candidate shows something other than object `o` (+ 1); a
// neighbour outside the tile counts as the same (hadou-cpu: outside the image).
fn differs(p: vec2<i32>, o: u32) -> bool {
    if (p.x < 0 || p.y < 0 || p.x >= i32(frame.tile_size.x) || p.y >= i32(frame.tile_size.y)) {
        return false;
    }
    return owner(p) != o;
}

// The unit ray of tile pixel `p`.
fn unit_dir(p: vec2<i32>) -> vec3<f32> {
    let d = pixel_dir(frame, frame.tile_origin.x + u32(p.x), frame.tile_origin.y + u32(p.y));
    return d / length3(d);
}

@fragment
fn fs_edges(@builtin(position) position: vec4<f32>) -> @location(0) vec4<u32> {
    let p = vec2<i32>(position.xy);
    let attributes = textureLoad(attribute_texels, p, 0);
    var out = vec4<u32>(attributes.xyz, attributes.w & (HULL_BIT | MATERIAL_MASK));
    let reach = i32(frame.outline_reach);
    let b = owner(p);
    if (b == 0u || reach == 0) {
        return out;
    }
    let texel = bitcast<vec4<f32>>(textureLoad(scene_texels, p, 0));
    let p_dir = unit_dir(p);
    let size = vec2<i32>(frame.tile_size);
    var found = false;
    var best_distance = 0.0;
    var best = 0u;
    // Row-major, so that of equally near edge pixels the first wins, as on the CPU.
    for (var dy = -reach; dy <= reach; dy += 1) {
        let qy = p.y + dy;
        if (qy < 0 || qy >= size.y) {
            continue;
        }
        for (var dx = -reach; dx <= reach; dx += 1) {
            let qx = p.x + dx;
            if (qx < 0 || qx >= size.x) {
                continue;
            }
            let q = vec2<i32>(qx, qy);
            let word = textureLoad(attribute_texels, q, 0).w;
            let code = (word >> REACH_SHIFT) & 0xffu;
            if ((word & HULL_BIT) != 0u || code == 0u) {
                continue;
            }
            let q_distance = bitcast<f32>(textureLoad(scene_texels, q, 0).w);
            if (!(q_distance > 0.0)) {
                continue;
            }
            let m = materials[word & MATERIAL_MASK];
            let o = m.object + 1u;
            if (o == b) {
                continue;
            }
            // hadou_math::outline::reach_pixels.
            let rp = material_hull_pixels(m.outline_width, q_distance * dot3(unit_dir(q), frame.forward))
                * (f32(code) / REACH_STEPS);
            if (!(rp > 0.0)) {
                continue;
            }
            let fx = f32(dx);
            let fy = f32(dy);
            if (fx * fx + fy * fy > rp * rp) {
                continue;
            }
            if (found && q_distance >= best_distance) {
                continue;
            }
            let on_edge = differs(q + vec2<i32>(-1, 0), o) || differs(q + vec2<i32>(1, 0), o)
                || differs(q + vec2<i32>(0, -1), o) || differs(q + vec2<i32>(0, 1), o);
            if (!on_edge) {
                continue;
            }
            if (in_front(texel.xyz, p_dir, texel.w, unit_dir(q), q_distance)) {
                found = true;
                best_distance = q_distance;
                best = word & MATERIAL_MASK;
            }
        }
    }
    if (found) {
        out.w = best | HULL_BIT;
    }
    return out;
}
