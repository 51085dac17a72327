//! Test mode (`?test=1`): the URL's frame rendered once and written into the page as a PNG data
//! URL (`#hadou-test-result`), or the error (`#hadou-test-error`), with its times as JSON
//! (`#hadou-test-timing`). On WebGPU this runs without the viewer's canvas: headless browsers
//! cannot present a WebGPU canvas (Chromium's software path loses the device), so the page opens
//! its own device, draws with `render_to_texture` as the viewport does and reads the texture back
//! (`read_presented`). On WebGL2 (`backend=webgl`) the viewer runs as usual and renders the frame
//! on the CPU backend (`app.rs`).

use super::dom;
use super::frames::{finish, test_frame, DEFAULT_PRESET};
use crate::params::PageParams;
use crate::presets;
use hadou_gpu::GpuBackend;
use hadou_scene::{Frame, Scene};
use wasm_bindgen::JsValue;
use web_time::Instant;

/// Frames timed after the first (which includes compiling the shaders).
const TIMED_FRAMES: usize = 5;

/// Waits a few milliseconds, yielding to the browser.
async fn tick() {
    let promise = js_sys::Promise::new(&mut |resolve, _| {
        if let Some(w) = web_sys::window() {
            let _ = w.set_timeout_with_callback_and_timeout_and_arguments_0(&resolve, 2);
        }
    });
    let _ = wasm_bindgen_futures::JsFuture::from(promise).await;
}

/// Renders `frame` on `gpu` and reads it back: the bytes and the milliseconds it took.
async fn render_and_read(
    gpu: &mut GpuBackend,
    device: &wgpu::Device,
    frame: &Frame,
) -> Result<(Vec<u8>, f64), String> {
    let t0 = Instant::now();
    gpu.render_to_texture(frame).map_err(|e| format!("GPU render failed: {e}"))?;
    let mut read = gpu.read_presented().ok_or("no texture to read back")?;
    loop {
        if let Some(r) = read.try_take(device) {
            let bytes = r.map_err(|e| e.to_string())?;
            return Ok((bytes, t0.elapsed().as_secs_f64() * 1e3));
        }
        tick().await;
    }
}

/// Test mode on WebGPU (see the module documentation).
pub(super) async fn run_webgpu(params: PageParams, adapter_hint: String) -> Result<(), JsValue> {
    let outcome = webgpu_frame(&params, &adapter_hint).await;
    if let Err(m) = &outcome {
        dom::set_text(dom::TEST_ERROR, m);
    }
    outcome.map_err(|m| JsValue::from_str(&m))
}

async fn webgpu_frame(params: &PageParams, adapter_hint: &str) -> Result<(), String> {
    hadou_scene::mount_memory_files(Some(presets::files()));
    let name = params.scene.as_deref().unwrap_or(DEFAULT_PRESET);
    let path = presets::scene_path(name)?;
    let scene = Scene::load(&path).map_err(|e| e.to_string())?;
    let frame = test_frame(&scene, params)?;
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: wgpu::Backends::BROWSER_WEBGPU,
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    });
    let adapter = instance
        .request_adapter(&wgpu::RequestAdapterOptions::default())
        .await
        .map_err(|e| format!("this browser gave no WebGPU adapter: {e}"))?;
    let (device, queue) = adapter
        .request_device(&hadou_gpu::device_descriptor(&adapter))
        .await
        .map_err(|e| format!("the WebGPU adapter gave no device: {e}"))?;
    let mut gpu = GpuBackend::from_device(&adapter, device.clone(), queue).map_err(|e| e.to_string())?;
    dom::set_text(dom::STATUS, &format!("test mode on WebGPU ({adapter_hint}): the GPU backend draws"));
    // With an `[area_light]` the maps are fitted on the GPU within the frame: the first frame is
    // the whole answer.
    let (bytes, first_ms) = render_and_read(&mut gpu, &device, &frame).await?;
    let mut times = Vec::with_capacity(TIMED_FRAMES);
    for _ in 0..TIMED_FRAMES {
        times.push(render_and_read(&mut gpu, &device, &frame).await?.1);
    }
    times.sort_by(f64::total_cmp);
    finish(
        &bytes,
        frame.width,
        frame.height,
        "GPU",
        adapter_hint,
        first_ms,
        times.get(TIMED_FRAMES / 2).copied(),
    );
    Ok(())
}
