// Edge pass: closed outlines where objects meet (twin of hadou-cpu's edges.rs, with the formulas
// of hadou_math::outline, 000 §2.3). Two compute dispatches over the tile, 8×8 pixels a
// workgroup:
// 1. cs_candidates finds the edge pixels that may reach another object's pixels: a surface pixel
//    q (not a hull) with a hull reach code, on the border of its object (a 4-neighbour shows
//    something else), whose reach on screen rp(q) is positive. It writes (material, rp bits) to
//    `candidates` ((0, 0) elsewhere) and the largest rp of each 8×8 block to `blocks`.
// 2. cs_edges reads the raster pass's G-buffer and writes the attributes target the later passes
//    read: the same words with the reach bits cleared, and where another object's candidate edge
//    pixel q lies within rp(q) of this pixel p and in front of p's surface, that object's material
//    | HULL_BIT (the wave pass then gives the outline colour, as for a hull fragment; the eye
//    distance stays the surface's). It visits only the blocks of the reach window whose largest
//    rp reaches p, so a pixel far from every edge reads a few block words.
// Of several q the nearest to the eye wins, ties to the first in row-major order of the window
// (hadou-cpu's order), whatever order the blocks are visited in.
// Prepended by common.wgsl.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<storage, read> materials: array<GpuMaterial>;
// G-buffer target 0: normal (xyz) and eye distance (w) as f32 bits; 0 distance = nothing drawn.
@group(0) @binding(2) var scene_texels: texture_2d<u32>;
// G-buffer target 1: u, v, colour, material word (index | reach << REACH_SHIFT | HULL_BIT).
@group(0) @binding(3) var attribute_texels: texture_2d<u32>;
// What the later passes read as target 1.
@group(0) @binding(4) var out_texels: texture_storage_2d<rgba32uint, write>;
// Per tile pixel (row-major): (material index, rp as f32 bits) of a candidate edge pixel, rp > 0;
// (0, 0) elsewhere.
@group(0) @binding(5) var<storage, read_write> candidates: array<vec2<u32>>;
// Per 8×8 block (row-major, ⌈w/8⌉ a row): the largest rp of its candidates as f32 bits, 0 for none.
@group(0) @binding(6) var<storage, read_write> blocks: array<u32>;

// Pixels per block edge, the workgroup's edge (passes/edges.rs EDGE_BLOCK).
const BLOCK: i32 = 8;

// Mirrors hadou_scene::MIN_OUTLINE_DEPTH.
const MIN_OUTLINE_DEPTH: f32 = 1.0e-3;
// Mirrors hadou_math::outline::IN_FRONT_MARGIN.
const IN_FRONT_MARGIN: f32 = 1.0e-3;
// Mirrors hadou_math::outline::REACH_STEPS.
const REACH_STEPS: f32 = 255.0;

// Twin of hadou_math::outline::hull_pixels.
fn hull_pixels(width: f32, tan_half_fov: f32, height: u32) -> f32 {
    let px = width * (f32(height) / (2.0 * tan_half_fov));
    if (px > 0.0 && px < 3.0e38) {
        return px;
    }
    return 0.0;
}

// Twin of hadou_scene::Material::hull_pixels for a material's GPU outline width (layout/
// `GpuMaterial::outline_width`: `d`, or `−w` for an MToon outline in world units) where the
// surface is at view depth `z`.
fn material_hull_pixels(width: f32, z: f32) -> f32 {
    var d = width;
    if (width < 0.0) {
        d = -width / max(abs(z), MIN_OUTLINE_DEPTH);
    }
    return hull_pixels(d, frame.tan_half_fov, frame.image_size.y);
}

// Twin of hadou_math::outline::in_front (common.wgsl's `in_front_by` at hadou's margin).
fn in_front(p_normal: vec3<f32>, p_dir: vec3<f32>, p_dist: f32, q_dir: vec3<f32>, q_dist: f32) -> bool {
    return in_front_by(p_normal, p_dir, p_dist, q_dir, q_dist, IN_FRONT_MARGIN);
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

// Blocks per row of the tile.
fn blocks_per_row() -> i32 {
    return (i32(frame.tile_size.x) + BLOCK - 1) / BLOCK;
}

var<workgroup> block_reach: atomic<u32>;

@compute @workgroup_size(8, 8, 1)
fn cs_candidates(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let q = vec2<i32>(gid.xy);
    let size = vec2<i32>(frame.tile_size);
    var candidate = vec2<u32>(0u, 0u);
    if (q.x < size.x && q.y < size.y) {
        let word = textureLoad(attribute_texels, q, 0).w;
        let code = (word >> REACH_SHIFT) & 0xffu;
        let q_distance = bitcast<f32>(textureLoad(scene_texels, q, 0).w);
        if ((word & HULL_BIT) == 0u && code != 0u && q_distance > 0.0) {
            let m = materials[word & MATERIAL_MASK];
            let o = m.object + 1u;
            // hadou_math::outline::reach_pixels.
            let rp = material_hull_pixels(m.outline_width, q_distance * dot3(unit_dir(q), frame.forward))
                * (f32(code) / REACH_STEPS);
            let on_edge = differs(q + vec2<i32>(-1, 0), o) || differs(q + vec2<i32>(1, 0), o)
                || differs(q + vec2<i32>(0, -1), o) || differs(q + vec2<i32>(0, 1), o);
            if (rp > 0.0 && on_edge) {
                candidate = vec2<u32>(word & MATERIAL_MASK, bitcast<u32>(rp));
                // Positive floats order as their bits.
                atomicMax(&block_reach, bitcast<u32>(rp));
            }
        }
        candidates[q.y * size.x + q.x] = candidate;
    }
    workgroupBarrier();
    if (lid == 0u) {
        blocks[i32(wid.y) * blocks_per_row() + i32(wid.x)] = atomicLoad(&block_reach);
    }
}

@compute @workgroup_size(8, 8, 1)
fn cs_edges(@builtin(global_invocation_id) gid: vec3<u32>) {
    let p = vec2<i32>(gid.xy);
    let size = vec2<i32>(frame.tile_size);
    if (p.x >= size.x || p.y >= size.y) {
        return;
    }
    let attributes = textureLoad(attribute_texels, p, 0);
    var out = vec4<u32>(attributes.xyz, attributes.w & (HULL_BIT | MATERIAL_MASK));
    let reach = i32(frame.outline_reach);
    let b = owner(p);
    if (b == 0u || reach == 0) {
        textureStore(out_texels, p, out);
        return;
    }
    let texel = bitcast<vec4<f32>>(textureLoad(scene_texels, p, 0));
    let p_dir = unit_dir(p);
    let lo = max(p - vec2<i32>(reach), vec2<i32>(0));
    let hi = min(p + vec2<i32>(reach), size - vec2<i32>(1));
    let row = blocks_per_row();
    var found = false;
    var best_distance = 0.0;
    var best_offset = vec2<i32>(0);
    var best = 0u;
    for (var by = lo.y / BLOCK; by <= hi.y / BLOCK; by += 1) {
        for (var bx = lo.x / BLOCK; bx <= hi.x / BLOCK; bx += 1) {
            let block_rp = bitcast<f32>(blocks[by * row + bx]);
            if (!(block_rp > 0.0)) {
                continue;
            }
            let b0 = vec2<i32>(bx, by) * BLOCK;
            let b1 = min(b0 + vec2<i32>(BLOCK - 1), size - vec2<i32>(1));
            // The block's pixel nearest to p, per axis.
            let gap = vec2<f32>(max(max(b0 - p, p - b1), vec2<i32>(0)));
            if (gap.x * gap.x + gap.y * gap.y > block_rp * block_rp) {
                continue;
            }
            let q0 = max(b0, lo);
            let q1 = min(b1, hi);
            for (var qy = q0.y; qy <= q1.y; qy += 1) {
                for (var qx = q0.x; qx <= q1.x; qx += 1) {
                    let c = candidates[qy * size.x + qx];
                    if (c.y == 0u) {
                        continue;
                    }
                    let rp = bitcast<f32>(c.y);
                    let d = vec2<i32>(qx, qy) - p;
                    let fx = f32(d.x);
                    let fy = f32(d.y);
                    if (fx * fx + fy * fy > rp * rp) {
                        continue;
                    }
                    if (materials[c.x].object + 1u == b) {
                        continue;
                    }
                    let q = vec2<i32>(qx, qy);
                    let q_distance = bitcast<f32>(textureLoad(scene_texels, q, 0).w);
                    // Nearest first; of equals, the first in row-major order of the window.
                    let earlier = d.y < best_offset.y || (d.y == best_offset.y && d.x < best_offset.x);
                    if (found && (q_distance > best_distance || (q_distance == best_distance && !earlier))) {
                        continue;
                    }
                    if (in_front(texel.xyz, p_dir, texel.w, unit_dir(q), q_distance)) {
                        found = true;
                        best_distance = q_distance;
                        best_offset = d;
                        best = c.x;
                    }
                }
            }
        }
    }
    if (found) {
        out.w = best | HULL_BIT;
    }
    textureStore(out_texels, p, out);
}
