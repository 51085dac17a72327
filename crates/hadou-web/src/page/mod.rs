//! The page itself (wasm32 only): the entry point the page's script calls ([`start`]), the
//! functions it calls for presets and dropped files, and the inbox those leave for the viewer's
//! next frame.

mod app;
mod dom;
mod frames;
mod inbox;
mod test_mode;

use crate::dropped::DropBatch;
use crate::params::{parse_query, ApiChoice, PageParams};
use crate::presets;
use app::WebApp;
use inbox::{wake, INBOX, WEBGPU_ADAPTER};
use wasm_bindgen::prelude::*;

/// The preset scenes' names, for the page's list.
#[wasm_bindgen]
pub fn preset_names() -> Vec<String> {
    presets::names().into_iter().map(str::to_string).collect()
}

/// Opens preset `name` on the viewer's next frame.
#[wasm_bindgen]
pub fn open_preset(name: String) {
    INBOX.with(|i| i.borrow_mut().preset = Some(name));
    wake();
}

/// Why a file named `name` of `size` bytes is not read (too large for its kind, or a kind no
/// scene names), or `undefined` when the page may read it. The script asks before reading.
#[wasm_bindgen]
pub fn refuse_file(name: &str, size: f64) -> Option<String> {
    crate::dropped::refuse_by_size(name, size)
}

/// A batch of dropped or opened files begins.
#[wasm_bindgen]
pub fn drop_begin() {
    INBOX.with(|i| i.borrow_mut().dropping = Some(DropBatch::default()));
}

/// One file of the batch, read.
#[wasm_bindgen]
pub fn drop_file(name: String, bytes: Vec<u8>) {
    INBOX.with(|i| i.borrow_mut().dropping.get_or_insert_with(DropBatch::default).files.push((name, bytes)));
}

/// One file of the batch, refused before it was read (`why` from [`refuse_file`]).
#[wasm_bindgen]
pub fn drop_refused(why: String) {
    INBOX.with(|i| i.borrow_mut().dropping.get_or_insert_with(DropBatch::default).refused.push(why));
}

/// The batch is complete: the viewer loads it on its next frame.
#[wasm_bindgen]
pub fn drop_end() {
    INBOX.with(|i| {
        let mut i = i.borrow_mut();
        if let Some(b) = i.dropping.take() {
            i.dropped.push(b);
        }
    });
    wake();
}

/// Starts the viewer on the canvas with id `canvas_id`, reading the URL's parameters. A bad
/// parameter is a message in the page (and, in test mode, the test's error). `webgpu_adapter`
/// names the browser's WebGPU adapter as the script found it (vendor and architecture; WebGPU's
/// adapter description is often empty).
#[wasm_bindgen]
pub async fn start(canvas_id: String, webgpu_adapter: String) -> Result<(), JsValue> {
    WEBGPU_ADAPTER.with(|a| *a.borrow_mut() = webgpu_adapter);
    std::panic::set_hook(Box::new(|info| {
        let m = format!("hadou panicked: {info}");
        web_sys::console::error_1(&m.clone().into());
        dom::set_text(dom::TEST_ERROR, &m);
        dom::set_text(dom::MESSAGE, &m);
    }));
    let query = web_sys::window().and_then(|w| w.location().search().ok()).unwrap_or_default();
    let params = match parse_query(&query) {
        Ok(p) => p,
        Err(errors) => {
            let m = format!("URL: {}", errors.join("; "));
            dom::set_text(dom::MESSAGE, &m);
            if query.contains("test=1") {
                dom::set_text(dom::TEST_ERROR, &m);
                return Err(m.into());
            }
            PageParams::default()
        }
    };
    if params.test && params.api != ApiChoice::WebGl {
        return test_mode::run_webgpu(params, WEBGPU_ADAPTER.with(|a| a.borrow().clone())).await;
    }
    let canvas = dom::canvas(&canvas_id)?;
    let backends = match params.api {
        ApiChoice::Auto => wgpu::Backends::BROWSER_WEBGPU | wgpu::Backends::GL,
        ApiChoice::WebGpu => wgpu::Backends::BROWSER_WEBGPU,
        ApiChoice::WebGl => wgpu::Backends::GL,
    };
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    setup.instance_descriptor.backends = backends;
    setup.device_descriptor = std::sync::Arc::new(hadou_gpu::device_descriptor);
    let mut options = eframe::WebOptions::default();
    options.wgpu_options.wgpu_setup = egui_wgpu::WgpuSetup::CreateNew(setup);
    let runner = eframe::WebRunner::new();
    let started = runner
        .start(
            canvas,
            options,
            Box::new(move |cc| {
                INBOX.with(|i| i.borrow_mut().ctx = Some(cc.egui_ctx.clone()));
                Ok(Box::new(WebApp::new(cc, params)))
            }),
        )
        .await;
    if let Err(e) = &started {
        let m = format!("the page could not start its graphics: {e:?}");
        dom::set_text(dom::MESSAGE, &m);
        dom::set_text(dom::TEST_ERROR, &m);
    }
    // The runner lives as long as the page.
    std::mem::forget(runner);
    started
}
