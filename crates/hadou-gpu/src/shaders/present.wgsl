// Present pass: one tile's final colour, straight from the wave pass's output buffer into the
// full-frame texture a window draws (no read-back). Rust twin: render.rs `copy_tile` (the colour
// part of the read-back) followed by hadou's `output::srgb8` (hadou_math::shade::linear_to_srgb8):
// the buffer holds linear mapped colour, and the `Rgba8UnormSrgb` target (formats.rs PRESENT_FORMAT)
// clamps to [0, 1] and encodes to sRGB in hardware; alpha is stored as it is (linear).
// Prepended by common.wgsl (FrameUniforms). Drawn as one full-screen triangle with the viewport
// set to the tile's rectangle of the texture, so every fragment is one pixel of the tile.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
// The wave pass's tile output (wave.wgsl binding 4): colour, 4 floats per pixel, in [0, 4n),
// row-major over the tile. Only the colour is read.
@group(0) @binding(1) var<storage, read> out_buf: array<f32>;

// A triangle covering the viewport: (-1, -1), (3, -1), (-1, 3).
@vertex
fn vs_present(@builtin(vertex_index) k: u32) -> @builtin(position) vec4<f32> {
    let x = f32((k << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(k & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs_present(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    // Framebuffer coordinates at the pixel centre (x + 0.5, y + 0.5), y down: the image pixel.
    // With anti-aliasing the uniforms count samples: the tile's image pixels are these / grid.
    let g = max(frame.grid, 1u);
    let p = vec2<u32>(position.xy) - frame.tile_origin / g;
    let i = p.y * (frame.tile_size.x / g) + p.x;
    return vec4<f32>(out_buf[4u * i], out_buf[4u * i + 1u], out_buf[4u * i + 2u], out_buf[4u * i + 3u]);
}
