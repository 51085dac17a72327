// The wave overlay: the waves' light drawn into a colour target someone else owns (a game
// engine's HDR view target, a page's canvas), clipped at the visible surface of that target's
// depth buffer: per pixel exposure · Σ rgb·a·I (wave_energy.wgsl `waves_light`, the same light the
// wave pass adds to the scene colour before its colour mapping), with no colour mapping, so an
// engine blends it into its linear image (additively, before its own tone mapping and bloom).
// Drawn as one full-screen triangle over a viewport the frame's size at `overlay.origin`; fragment
// (x, y) is the frame's pixel (x, y) − origin, and reads the depth buffer at (x, y). Prepended by common.wgsl, energy.wgsl, curve.wgsl and wave_energy.wgsl
// (bindings 0–1 and 5–7, as in the wave pass).

// The caller's depth buffer (a depth texture read as unfilterable float: GL has no textureLoad of
// depth textures) and how its values map to eye distance.
@group(0) @binding(2) var depth_texels: texture_2d<f32>;

// Keep in sync with layout/ `OverlayUniforms`.
struct OverlayUniforms {
    // DEPTH_STANDARD: 0 at `near`, 1 at `far` (hadou's raster pass, most engines);
    // DEPTH_REVERSE_INFINITE: near / z, 0 at infinity (Bevy's).
    depth_model: u32,
    near: f32,
    far: f32,
    // PROJECTION_PERSPECTIVE: rays from frame.eye; PROJECTION_ORTHOGRAPHIC: parallel rays along
    // frame.forward from each pixel's point on the near plane (overlay.rs `OverlayProjection`).
    projection: u32,
    // The target's pixel where the frame's pixel (0, 0) is (a viewport's corner).
    origin: vec2<u32>,
    // Orthographic: the near-to-far distance the depth runs over linearly.
    depth_span: f32,
    _pad: u32,
    // Orthographic: the near plane's point at NDC (0, 0) and the vectors to NDC x = +1, y = +1.
    ortho_centre: vec4<f32>,
    ortho_right: vec4<f32>,
    ortho_up: vec4<f32>,
}
@group(0) @binding(3) var<uniform> overlay: OverlayUniforms;

const DEPTH_STANDARD: u32 = 0u;
const DEPTH_REVERSE_INFINITE: u32 = 1u;
const PROJECTION_PERSPECTIVE: u32 = 0u;
const PROJECTION_ORTHOGRAPHIC: u32 = 1u;

// Orthographic: the distance from the near plane of a depth value (linear over depth_span;
// reverse: 1 at the near plane, 0 at the far), or -1 where nothing was drawn (the cleared value).
fn ortho_distance(d: f32) -> f32 {
    if (overlay.depth_model == DEPTH_REVERSE_INFINITE) {
        if (!(d > 0.0)) {
            return -1.0;
        }
        return (1.0 - d) * overlay.depth_span;
    }
    if (!(d < 1.0)) {
        return -1.0;
    }
    return max(d, 0.0) * overlay.depth_span;
}

// The view depth z (along the camera's forward axis) of a depth value, or -1 where nothing was
// drawn (the cleared value: 1 for the standard model, 0 for the reverse one).
fn view_depth(d: f32) -> f32 {
    if (overlay.depth_model == DEPTH_REVERSE_INFINITE) {
        if (!(d > 0.0)) {
            return -1.0;
        }
        return overlay.near / d;
    }
    if (!(d < 1.0)) {
        return -1.0;
    }
    // d = far·(z − near) / (z·(far − near)), solved for z.
    return overlay.far * overlay.near / (overlay.far - d * (overlay.far - overlay.near));
}

// A triangle covering the viewport: (-1, -1), (3, -1), (-1, 3).
@vertex
fn vs_overlay(@builtin(vertex_index) k: u32) -> @builtin(position) vec4<f32> {
    let x = f32((k << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(k & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs_overlay(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    load_frame();
    let px = u32(position.x) - overlay.origin.x;
    let py = u32(position.y) - overlay.origin.y;
    let d = textureLoad(depth_texels, vec2<i32>(position.xy), 0).x;
    var dir = pixel_dir(frame, px, py);
    var surface = -1.0;
    if (overlay.projection == PROJECTION_ORTHOGRAPHIC) {
        // Parallel rays: the pixel's point on the near plane is the ray's start (wave_ray reads
        // frame.eye, this invocation's private copy) and the unit forward axis its direction, so
        // the span runs from the near plane as CameraBasis::wave_ray's does from the eye.
        let ndc_x = 2.0 * (f32(px) + 0.5) / f32(frame.image_size.x) - 1.0;
        let ndc_y = 1.0 - 2.0 * (f32(py) + 0.5) / f32(frame.image_size.y);
        frame.eye = overlay.ortho_centre.xyz + overlay.ortho_right.xyz * ndc_x + overlay.ortho_up.xyz * ndc_y;
        dir = frame.forward;
        surface = ortho_distance(d);
    } else {
        let z = view_depth(d);
        if (z > 0.0) {
            // pixel_dir's forward component is 1, so the eye distance is z·|dir|.
            surface = z * length3(dir);
        }
    }
    let light = waves_light(dir, surface).light;
    let lit = vec3<f32>(energy_scaled(light.x, frame.exposure), energy_scaled(light.y, frame.exposure), energy_scaled(light.z, frame.exposure));
    return vec4<f32>(lit, 0.0);
}
