//! What the viewer (`app.rs`) and test mode (`test_mode.rs`) share: the default preset, a frame
//! rendered on the CPU into the bytes the GPU's window texture holds, and test mode's frame and
//! report.

use super::dom;
use crate::export::png_bytes;
use crate::params::PageParams;
use hadou_cpu::CpuBackend;
use hadou_scene::{Backend, Frame, Scene};
use web_time::Instant;

/// The preset opened when the URL names none.
pub(super) const DEFAULT_PRESET: &str = "kamehameha";

/// Renders `frame` on `cpu` into sRGB RGBA bytes (alpha as unorm, as the GPU's window texture
/// holds it) and the render time (ms).
pub(super) fn cpu_frame_bytes(cpu: &mut CpuBackend, frame: &Frame) -> Result<(Vec<u8>, f64), String> {
    let t0 = Instant::now();
    let image = cpu.render(frame).map_err(|e| e.to_string())?;
    let ms = t0.elapsed().as_secs_f64() * 1e3;
    let mut bytes = vec![0u8; 4 * image.color.len()];
    hadou_math::shade::rgba_to_srgba8(&image.color, &mut bytes);
    for (o, c) in bytes.chunks_exact_mut(4).zip(&image.color) {
        o[3] = (c[3].clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    }
    Ok((bytes, ms))
}

/// The test's frame of `scene`: the URL's time and size.
pub(super) fn test_frame(scene: &Scene, params: &PageParams) -> Result<Frame, String> {
    let f = scene.at_with(params.time.unwrap_or(0.0), &params.overrides());
    scene
        .check_image_size(f.width, f.height)
        .map_err(|m| format!("width={} height={}: {m}", f.width, f.height))?;
    Ok(f)
}

/// Writes the test's frame (sRGB RGBA bytes) and its times.
pub(super) fn finish(
    rgba: &[u8],
    w: u32,
    h: u32,
    backend: &str,
    adapter: &str,
    first_ms: f64,
    frame_ms: Option<f64>,
) {
    match png_bytes(rgba, w, h) {
        Ok(png) => {
            let frame = frame_ms.map_or("null".to_string(), |m| format!("{m:.2}"));
            dom::set_text(
                dom::TEST_TIMING,
                &format!(
                    "{{\"backend\": \"{backend}\", \"adapter\": {adapter:?}, \"size\": [{w}, {h}], \
                     \"first_frame_ms\": {first_ms:.2}, \"frame_ms\": {frame}}}"
                ),
            );
            dom::set_text(dom::TEST_RESULT, &dom::data_url("image/png", &png));
        }
        Err(e) => dom::set_text(dom::TEST_ERROR, &e),
    }
}
