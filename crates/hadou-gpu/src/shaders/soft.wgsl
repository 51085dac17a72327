// Soft shadows of the `[area_light]` (twin of hadou-cpu's soft.rs): every tile's visible points
// gathered and the maps' fit windows with them (cs_points), the two maps fitted to the windows on
// the GPU (cs_fit: nothing is read back in the middle of a frame), every pixel classed umbra /
// penumbra / lit from the two fitted maps (soft_map.wgsl, cs_class), then the penumbra resolved over the whole
// image: exact distances (cs_columns, cs_exact) or 003's grid search with bilinear interpolation
// (cs_grid, cs_interp); cs_gather hands each tile's visibility to the wave pass. Prepended by
// common.wgsl.
//
// Whole-image buffers, row-major, W·H pixels (passes/soft.rs `SoftTargets`):
// soft_world[i] = (world point as f32 bits, class), soft_normal[i] = (unit normal as f32 bits,
// nearest rows of the pixel's column: umbra in the low 16 bits, lit in the high 16, NO_ROW for
// none), visibility[i]; grid[g] the faithful grid's values.

// Keep in sync with layout/ `SoftUniforms`.
struct SoftUniforms {
    maps: array<GpuSpotMap, 2>,
    depth_aware: u32,
    grid: u32,
    grid_size: vec2<u32>,
    // k of hadou_math::soft::segment_brightness (1: 003's linear ratio).
    ratio: f32,
    // How many of caster_boxes are the casters'.
    boxes: u32,
    _pad1: u32,
    _pad2: u32,
}

// Keep in sync with layout/ `GpuCasterBox` (hadou_math::soft::CasterBox).
struct GpuCasterBox {
    origin: vec4<f32>,
    dual0: vec4<f32>,
    dual1: vec4<f32>,
    dual2: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<uniform> soft: SoftUniforms;
// The tile's G-buffer (raster.wgsl).
@group(0) @binding(2) var scene_texels: texture_2d<u32>;
@group(0) @binding(3) var attribute_texels: texture_2d<u32>;
// The two maps: f32 bits of the nearest view depth per texel, +∞ where empty.
@group(0) @binding(4) var spot_map0: texture_2d<u32>;
@group(0) @binding(5) var spot_map1: texture_2d<u32>;
@group(0) @binding(6) var<storage, read_write> soft_world: array<vec4<u32>>;
@group(0) @binding(7) var<storage, read_write> soft_normal: array<vec4<u32>>;
@group(0) @binding(8) var<storage, read_write> visibility: array<f32>;
@group(0) @binding(9) var<storage, read_write> grid: array<f32>;
// The tile's output buffer (wave.wgsl): cs_gather writes the visibility to its eye-distance slot.
@group(0) @binding(10) var<storage, read_write> out_buf: array<f32>;
// The casters' boxes in the world (the first soft.boxes).
@group(0) @binding(11) var<storage, read> caster_boxes: array<GpuCasterBox>;
// The maps' fit windows (hadou_math::soft::FitWindow), map k at 4k: keys of min x/z, min y/z,
// max x/z, max y/z, gathered by cs_points before the maps are fitted and drawn.
@group(0) @binding(12) var<storage, read_write> fit: array<atomic<u32>, 8>;
// The two maps as drawn: soft.maps fitted to the windows in `fit` by cs_fit (passes/soft.rs copies
// each into soft_map.wgsl's uniform before the maps are drawn).
@group(0) @binding(13) var<storage, read_write> fitted_maps: array<GpuSpotMap, 2>;
// One workgroup's part of fit (cs_points).
var<workgroup> wg_fit: array<atomic<u32>, 8>;

// hadou_math::soft::Class.
const CLASS_NONE: u32 = 0u;
const CLASS_UMBRA: u32 = 1u;
const CLASS_PENUMBRA: u32 = 2u;
const CLASS_LIT: u32 = 3u;
// hadou_math::soft::SEARCH_RADIUS and its square.
const SEARCH_RADIUS: i32 = 256;
const R2: u32 = 65536u;
// hadou_math::soft::DEPTH_SLOPE, BIAS_TEXELS.
const DEPTH_SLOPE: f32 = 0.3;
const BIAS_TEXELS: f32 = 1.5;
// hadou_math::soft::FIT_MARGIN, FIT_GAIN, SPOT_MIN_TAN.
const FIT_MARGIN: f32 = 1e-4;
const FIT_GAIN: f32 = 0.5;
const SPOT_MIN_TAN: f32 = 1e-3;
// A squared distance standing for "none" (hadou_math::soft::FAR).
const FAR: u32 = 0xffffffffu;
const NO_ROW: u32 = 0xffffu;

fn finite(x: f32) -> bool {
    return x == x && abs(x) <= 3.4028234663852886e38;
}

// Twin of hadou_math::soft::SpotMap::texel.
fn spot_texel(s: GpuSpotMap, z: f32) -> f32 {
    return 2.0 * s.tan_half * z / f32(s.size);
}

// Twin of hadou-cpu's soft::SpotDepth::shadowed with hadou_math::soft::SpotMap::lookup and
// SpotMap::occludes: facing away from map k's light, or a nearer surface in the texel looked up
// after the normal offset.
fn spot_shadowed(k: u32, p: vec3<f32>, n: vec3<f32>) -> bool {
    let s = fitted_maps[k];
    if (dot3(n, s.eye - p) <= 0.0) {
        return true;
    }
    let v0 = spot_to_view(s, p);
    let off = spot_texel(s, abs(v0.z));
    let v = v0 + vec3<f32>(dot3(n, s.right), dot3(n, s.up), dot3(n, s.forward)) * off;
    if (!(v.z > s.near)) {
        return false; // outside the map: +∞ stored, never nearer
    }
    let sz = f32(s.size);
    let ms = (v.x / (v.z * s.tan_half) + 1.0) * 0.5;
    let mt = (v.y / (v.z * s.tan_half) + 1.0) * 0.5;
    let x = floor(ms * sz);
    let y = floor((1.0 - mt) * sz);
    if (!(finite(x) && finite(y)) || x < 0.0 || y < 0.0 || x >= sz || y >= sz) {
        return false;
    }
    var bits = 0u;
    if (k == 0u) {
        bits = textureLoad(spot_map0, vec2<i32>(i32(x), i32(y)), 0).x;
    } else {
        bits = textureLoad(spot_map1, vec2<i32>(i32(x), i32(y)), 0).x;
    }
    let stored = bitcast<f32>(bits);
    return stored < v.z - BIAS_TEXELS * spot_texel(s, v.z);
}

// Twin of hadou_math::soft::CasterBox::local.
fn box_local(b: GpuCasterBox, q: vec3<f32>) -> vec3<f32> {
    let d = q - b.origin.xyz;
    return vec3<f32>(dot3(d, b.dual0.xyz), dot3(d, b.dual1.xyz), dot3(d, b.dual2.xyz));
}

// Twin of hadou_math::soft::CasterBox::blocks: the segment from eye to p meets the box before
// 1 − FIT_MARGIN of its length.
fn box_blocks(b: GpuCasterBox, eye: vec3<f32>, p: vec3<f32>) -> bool {
    let a = box_local(b, eye);
    let e = box_local(b, p);
    var t0 = 0.0;
    var t1 = 1.0 - FIT_MARGIN;
    for (var i = 0; i < 3; i++) {
        let d = e[i] - a[i];
        if (abs(d) < 1e-7) {
            if (!(a[i] >= 0.0 && a[i] <= 1.0)) {
                return false;
            }
        } else {
            let ta = -a[i] / d;
            let tb = (1.0 - a[i]) / d;
            t0 = max(t0, min(ta, tb));
            t1 = min(t1, max(ta, tb));
        }
    }
    return t0 <= t1;
}

// Twin of hadou_math::soft::FitWindow::key.
fn fit_key(v: f32) -> u32 {
    let b = bitcast<u32>(v);
    if ((b & 0x80000000u) != 0u) {
        return ~b;
    }
    return b | 0x80000000u;
}

// Twin of hadou_math::soft::FitWindow::add_point for map k (the unfitted map in soft.maps), into
// the workgroup's part of the window:
// p widens map k's window when a caster's box lies in front of it and the map sees it
// (SpotMap::fit_coords).
fn fit_point(k: u32, p: vec3<f32>) {
    let s = soft.maps[k];
    var blocked = false;
    for (var i = 0u; i < soft.boxes; i++) {
        if (box_blocks(caster_boxes[i], s.eye, p)) {
            blocked = true;
            break;
        }
    }
    if (!blocked) {
        return;
    }
    let v = spot_to_view(s, p);
    if (!(v.z > s.near)) {
        return;
    }
    let c = clamp(v.xy / v.z, vec2<f32>(-s.tan_half), vec2<f32>(s.tan_half));
    let kx = fit_key(c.x);
    let ky = fit_key(c.y);
    atomicMin(&wg_fit[4u * k], kx);
    atomicMin(&wg_fit[4u * k + 1u], ky);
    atomicMax(&wg_fit[4u * k + 2u], kx);
    atomicMax(&wg_fit[4u * k + 3u], ky);
}

// Per tile pixel (twin of hadou-cpu's opaque-pass soft points (opaque.rs) and soft::fitted_maps):
// the visible point and its unit normal, class CLASS_LIT until cs_class (background and outline
// hulls CLASS_NONE), and the point added to both maps' fit windows.
@compute @workgroup_size(8, 8, 1)
fn cs_points(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    // The workgroup's windows first (shared-memory atomics), then one global atomic per slot:
    // slots 4k and 4k + 1 are minima, 4k + 2 and 4k + 3 maxima (FitWindow::EMPTY to start).
    let is_min = (li & 2u) == 0u;
    if (li < 8u) {
        atomicStore(&wg_fit[li], select(0u, 0xffffffffu, is_min));
    }
    workgroupBarrier();
    if (id.x < frame.tile_size.x && id.y < frame.tile_size.y) {
        gather_point(id);
    }
    workgroupBarrier();
    if (li < 8u) {
        let v = atomicLoad(&wg_fit[li]);
        if (is_min && v != 0xffffffffu) {
            atomicMin(&fit[li], v);
        } else if (!is_min && v != 0u) {
            atomicMax(&fit[li], v);
        }
    }
}

// Twin of hadou_math::soft::FitWindow::value: the f32 of an order-preserving key.
fn fit_value(k: u32) -> f32 {
    if ((k & 0x80000000u) != 0u) {
        return bitcast<f32>(k & 0x7fffffffu);
    }
    return bitcast<f32>(~k);
}

// Twin of hadou_math::soft::SpotMap::fitted: map `s` (unfitted) narrowed to the window of keys
// `lo..=hi` (FitWindow's min and max), its edge in texels `s.size`.
fn fitted_map(s: GpuSpotMap, lo_key: vec2<u32>, hi_key: vec2<u32>) -> GpuSpotMap {
    var out = s;
    if (s.size < 16u) {
        return s;
    }
    if (lo_key.x > hi_key.x || lo_key.y > hi_key.y) {
        out.tan_half = SPOT_MIN_TAN;
        return out;
    }
    let lo = vec2<f32>(fit_value(lo_key.x), fit_value(lo_key.y));
    let hi = vec2<f32>(fit_value(hi_key.x), fit_value(hi_key.y));
    let c = vec2<f32>(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y));
    let h = max(0.5 * (hi.x - lo.x), 0.5 * (hi.y - lo.y));
    let wide = 1.02 * h / (1.0 - 4.0 / f32(s.size));
    // f32::max: a NaN gives the other value.
    var half = SPOT_MIN_TAN;
    if (wide > SPOT_MIN_TAN) {
        half = wide;
    }
    if (half > FIT_GAIN * s.tan_half || !finite(c.x) || !finite(c.y)) {
        return s;
    }
    out.right = s.right - s.forward * c.x;
    out.up = s.up - s.forward * c.y;
    out.tan_half = half;
    return out;
}

// Once every tile's cs_points has run: both maps fitted to their windows (hadou-cpu's
// soft::fitted_maps), for the map pass (through passes/soft.rs's copies) and cs_class.
@compute @workgroup_size(2, 1, 1)
fn cs_fit(@builtin(local_invocation_index) k: u32) {
    let lo = vec2<u32>(atomicLoad(&fit[4u * k]), atomicLoad(&fit[4u * k + 1u]));
    let hi = vec2<u32>(atomicLoad(&fit[4u * k + 2u]), atomicLoad(&fit[4u * k + 3u]));
    fitted_maps[k] = fitted_map(soft.maps[k], lo, hi);
}

// cs_points for one pixel of the tile.
fn gather_point(id: vec3<u32>) {
    let px = frame.tile_origin.x + id.x;
    let py = frame.tile_origin.y + id.y;
    let gi = py * frame.image_size.x + px;
    let texel = bitcast<vec4<f32>>(textureLoad(scene_texels, vec2<i32>(id.xy), 0));
    let attributes = textureLoad(attribute_texels, vec2<i32>(id.xy), 0);
    if (!(texel.w > 0.0) || (attributes.w & HULL_BIT) != 0u) {
        soft_world[gi] = vec4<u32>(0u, 0u, 0u, CLASS_NONE);
        soft_normal[gi] = vec4<u32>(0u);
        return;
    }
    let world = surface_point(frame, pixel_dir(frame, px, py), texel.w);
    let len = length3(texel.xyz);
    var n = vec3<f32>(0.0);
    if (len > 0.0 && len < 3.0e38) {
        n = texel.xyz / len;
    }
    fit_point(0u, world);
    fit_point(1u, world);
    soft_world[gi] = vec4<u32>(bitcast<vec3<u32>>(world), CLASS_LIT);
    soft_normal[gi] = vec4<u32>(bitcast<vec3<u32>>(n), 0u);
}

// Per image pixel, once the fitted maps are drawn (twin of hadou-cpu's soft::classify): the class
// of every visible point from the two maps (hadou_math::soft::Class::of).
@compute @workgroup_size(8, 8, 1)
fn cs_class(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= frame.image_size.x || id.y >= frame.image_size.y) {
        return;
    }
    let gi = id.y * frame.image_size.x + id.x;
    let w = soft_world[gi];
    if (w.w == CLASS_NONE) {
        return;
    }
    let world = bitcast<vec3<f32>>(w.xyz);
    let n = bitcast<vec3<f32>>(soft_normal[gi].xyz);
    let s1 = spot_shadowed(0u, world, n);
    let s2 = spot_shadowed(1u, world, n);
    var kind = CLASS_PENUMBRA;
    if (s1 && s2) {
        kind = CLASS_UMBRA;
    } else if (!s1 && !s2) {
        kind = CLASS_LIT;
    }
    soft_world[gi].w = kind;
}

fn class_at(i: u32) -> u32 {
    return soft_world[i].w;
}

// First pass of the exact distance transform (hadou-cpu's soft::edt, columns): per column, the
// nearest umbra and lit rows (exact 1-D nearest, by a sweep down and one up; equal distances may
// go either way, which the result does not depend on).
@compute @workgroup_size(64, 1, 1)
fn cs_columns(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = frame.image_size.x;
    let h = frame.image_size.y;
    let x = id.x;
    if (x >= w) {
        return;
    }
    var umbra = NO_ROW;
    var lit = NO_ROW;
    for (var y = 0u; y < h; y++) {
        let i = y * w + x;
        let c = class_at(i);
        if (c == CLASS_UMBRA) {
            umbra = y;
        } else if (c == CLASS_LIT) {
            lit = y;
        }
        soft_normal[i].w = umbra | (lit << 16u);
    }
    umbra = NO_ROW;
    lit = NO_ROW;
    for (var k = 0u; k < h; k++) {
        let y = h - 1u - k;
        let i = y * w + x;
        let c = class_at(i);
        if (c == CLASS_UMBRA) {
            umbra = y;
        } else if (c == CLASS_LIT) {
            lit = y;
        }
        let down = soft_normal[i].w;
        var u = down & NO_ROW;
        var l = down >> 16u;
        // The row below (umbra/lit ≥ y) wins when nearer than the one above.
        if (umbra != NO_ROW && (u == NO_ROW || umbra - y < y - u)) {
            u = umbra;
        }
        if (lit != NO_ROW && (l == NO_ROW || lit - y < y - l)) {
            l = lit;
        }
        soft_normal[i].w = u | (l << 16u);
    }
}

fn world_at(i: u32) -> vec3<f32> {
    return bitcast<vec3<f32>>(soft_world[i].xyz);
}

fn normal_at(i: u32) -> vec3<f32> {
    return bitcast<vec3<f32>>(soft_normal[i].xyz);
}

// Twin of hadou_math::soft::same_surface.
fn same_surface(p: vec3<f32>, n: vec3<f32>, q: vec3<f32>) -> bool {
    let d = q - p;
    return abs(dot3(d, n)) <= DEPTH_SLOPE * length3(d);
}

// Twin of hadou-cpu's soft::Search::counts: pixel j is a `want` pixel for penumbra pixel i.
fn counts(i: u32, j: u32, want: u32) -> bool {
    if (class_at(j) != want) {
        return false;
    }
    if (soft.depth_aware == 0u) {
        return true;
    }
    return same_surface(world_at(i), normal_at(i), world_at(j));
}

// Twin of hadou-cpu's soft::Search::ring_search: the squared distance from pixel i to the nearest
// pixel counting as `want` within SEARCH_RADIUS, FAR if none; square rings of Chebyshev radius
// r ≥ start.
fn ring_search(i: u32, want: u32, start: u32) -> u32 {
    let w = i32(frame.image_size.x);
    let h = i32(frame.image_size.y);
    let x = i32(i) % w;
    let y = i32(i) / w;
    var best = FAR;
    var r = i32(max(start, 1u));
    while (r <= SEARCH_RADIUS && u32(r * r) <= best) {
        if (x - r < 0 && y - r < 0 && x + r >= w && y + r >= h) {
            break;
        }
        // The ring's top and bottom rows, then its left and right columns.
        for (var u = x - r; u <= x + r; u++) {
            best = visit(i, x, y, u, y - r, w, h, want, best);
            best = visit(i, x, y, u, y + r, w, h, want, best);
        }
        for (var v = y - r + 1; v < y + r; v++) {
            best = visit(i, x, y, x - r, v, w, h, want, best);
            best = visit(i, x, y, x + r, v, w, h, want, best);
        }
        r += 1;
    }
    return best;
}

fn visit(i: u32, x: i32, y: i32, u: i32, v: i32, w: i32, h: i32, want: u32, best: u32) -> u32 {
    if (u < 0 || v < 0 || u >= w || v >= h) {
        return best;
    }
    let d2 = u32((u - x) * (u - x) + (v - y) * (v - y));
    if (d2 < best && d2 <= R2 && counts(i, u32(v * w + u), want)) {
        return d2;
    }
    return best;
}

// Twin of hadou_math::soft::segment_brightness (penumbra_brightness of k·D₁ and D₂, k =
// soft.ratio) on squared distances (FAR = infinite).
fn brightness(d1: u32, d2: u32) -> f32 {
    if (d1 != FAR && d2 != FAR) {
        let a = soft.ratio * sqrt(f32(d1));
        let s = a + sqrt(f32(d2));
        if (s > 0.0) {
            return clamp(a / s, 0.0, 1.0);
        }
        return 0.5;
    }
    if (d1 == FAR && d2 != FAR) {
        return 1.0;
    }
    if (d2 == FAR && d1 != FAR) {
        return 0.0;
    }
    return 0.5;
}

// Twin of hadou-cpu's soft::plain: the value of a pixel that is not in the penumbra.
fn plain(c: u32) -> f32 {
    if (c == CLASS_UMBRA || c == CLASS_NONE) {
        return 0.0;
    }
    return 1.0;
}

const NOT_PENUMBRA: u32 = 0xffffffffu;

// The resolves' first step per pixel: the image index of invocation `id` when that pixel is in the
// penumbra; otherwise NOT_PENUMBRA, after writing the pixel's plain value (the value of a pixel
// outside the penumbra in hadou-cpu's soft::Search::exact and ::faithful) when it is inside the
// image.
fn penumbra_pixel(id: vec3<u32>) -> u32 {
    let w = frame.image_size.x;
    if (id.x >= w || id.y >= frame.image_size.y) {
        return NOT_PENUMBRA;
    }
    let i = id.y * w + id.x;
    let c = class_at(i);
    if (c != CLASS_PENUMBRA) {
        visibility[i] = plain(c);
        return NOT_PENUMBRA;
    }
    return i;
}

// Second pass of the exact transform for one kind (`shift` 0: umbra, 16: lit) at pixel (x, y):
// the nearest pixel of that kind over the columns x ± dx, |dx| ≤ SEARCH_RADIUS (a nearer one
// beyond cannot exist: any kind farther than SEARCH_RADIUS counts as absent), nearest first so the
// scan stops once dx² reaches the best. Returns (d², index), d² = FAR if none within reach.
fn nearest_in_rows(x: i32, y: i32, shift: u32) -> vec2<u32> {
    let w = i32(frame.image_size.x);
    var best = FAR;
    var at = 0u;
    for (var dx = 0; dx <= SEARCH_RADIUS; dx++) {
        if (u32(dx * dx) >= best) {
            break;
        }
        for (var side = 0; side < 2; side++) {
            if (side == 1 && dx == 0) {
                break;
            }
            let u = x + select(dx, -dx, side == 1);
            if (u < 0 || u >= w) {
                continue;
            }
            let row = (soft_normal[u32(y * w + u)].w >> shift) & NO_ROW;
            if (row == NO_ROW) {
                continue;
            }
            let dy = i32(row) - y;
            let d2 = u32(dx * dx + dy * dy);
            if (d2 < best) {
                best = d2;
                at = row * u32(w) + u32(u);
            }
        }
    }
    return vec2<u32>(best, at);
}

// Twin of the fix in hadou-cpu's soft::Search::exact: the nearest `want` pixel's squared distance,
// or, when it lies on another surface under the depth-aware search, a ring search from ⌊d/√2⌋
// (started one ring earlier, which changes nothing: no counting pixel is nearer).
fn exact_distance(i: u32, nearest: vec2<u32>, want: u32) -> u32 {
    let d2 = nearest.x;
    if (d2 == FAR || d2 > R2) {
        return FAR;
    }
    if (soft.depth_aware == 0u || counts(i, nearest.y, want)) {
        return d2;
    }
    let start = u32(floor(sqrt(f32(d2)) * 0.70710677));
    return ring_search(i, want, max(start, 1u) - 1u);
}

// hadou-cpu's soft::Search::exact, per pixel of the image.
@compute @workgroup_size(8, 8, 1)
fn cs_exact(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = penumbra_pixel(id);
    if (i == NOT_PENUMBRA) {
        return;
    }
    let x = i32(id.x);
    let y = i32(id.y);
    let d1 = exact_distance(i, nearest_in_rows(x, y, 0u), CLASS_UMBRA);
    let d2 = exact_distance(i, nearest_in_rows(x, y, 16u), CLASS_LIT);
    visibility[i] = brightness(d1, d2);
}

// hadou-cpu's soft::Search::faithful, its grid: the search (Search::searched) on every n-th pixel
// in x and y; umbra grid pixels 0, lit and empty ones 1.
@compute @workgroup_size(8, 8, 1)
fn cs_grid(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= soft.grid_size.x || id.y >= soft.grid_size.y) {
        return;
    }
    let n = soft.grid;
    let i = id.y * n * frame.image_size.x + id.x * n;
    let c = class_at(i);
    var v = 1.0;
    if (c == CLASS_PENUMBRA) {
        v = brightness(ring_search(i, CLASS_UMBRA, 1u), ring_search(i, CLASS_LIT, 1u));
    } else if (c == CLASS_UMBRA) {
        v = 0.0;
    }
    grid[id.y * soft.grid_size.x + id.x] = v;
}

// Twin of hadou_math::soft::bilinear.
fn bilinear(v00: f32, v10: f32, v01: f32, v11: f32, fx: f32, fy: f32) -> f32 {
    let top = v00 + (v10 - v00) * fx;
    let bottom = v01 + (v11 - v01) * fx;
    return top + (bottom - top) * fy;
}

// hadou-cpu's soft::Search::faithful, per pixel: penumbra pixels interpolated from the four grid
// pixels around them (the last grid column or row repeated at the image's edge).
@compute @workgroup_size(8, 8, 1)
fn cs_interp(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = penumbra_pixel(id);
    if (i == NOT_PENUMBRA) {
        return;
    }
    let n = soft.grid;
    let gw = soft.grid_size.x;
    let gh = soft.grid_size.y;
    let gy0 = id.y / n;
    let gy1 = min(gy0 + 1u, gh - 1u);
    var fy = f32(id.y % n) / f32(n);
    if (gy1 == gy0) {
        fy = 0.0;
    }
    let gx0 = id.x / n;
    let gx1 = min(gx0 + 1u, gw - 1u);
    var fx = f32(id.x % n) / f32(n);
    if (gx1 == gx0) {
        fx = 0.0;
    }
    visibility[i] = bilinear(grid[gy0 * gw + gx0], grid[gy0 * gw + gx1], grid[gy1 * gw + gx0], grid[gy1 * gw + gx1], fx, fy);
}

// Per tile pixel: the visibility into the tile output's eye-distance slot, where the wave pass
// reads it before writing the distance.
@compute @workgroup_size(8, 8, 1)
fn cs_gather(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= frame.tile_size.x || id.y >= frame.tile_size.y) {
        return;
    }
    let n = frame.tile_size.x * frame.tile_size.y;
    let gi = (frame.tile_origin.y + id.y) * frame.image_size.x + frame.tile_origin.x + id.x;
    out_buf[5u * n + id.y * frame.tile_size.x + id.x] = visibility[gi];
}
