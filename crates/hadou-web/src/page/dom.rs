//! The few things the page does outside its canvas: texts in elements, downloads, the canvas.

use wasm_bindgen::{JsCast, JsValue};

/// The element whose text holds the test's PNG data URL.
pub(crate) const TEST_RESULT: &str = "hadou-test-result";
/// The element whose text holds the test's error.
pub(crate) const TEST_ERROR: &str = "hadou-test-error";
/// The element whose text holds the test's frame time, as JSON.
pub(crate) const TEST_TIMING: &str = "hadou-test-timing";
/// The line above the canvas naming the graphics API, adapter and backend.
pub(crate) const STATUS: &str = "hadou-status";
/// The line above the canvas for problems outside the viewer (the URL, dropped files).
pub(crate) const MESSAGE: &str = "hadou-message";

fn document() -> Option<web_sys::Document> {
    web_sys::window()?.document()
}

/// Sets the text of the element with id `id`, if there is one.
pub(crate) fn set_text(id: &str, text: &str) {
    if let Some(e) = document().and_then(|d| d.get_element_by_id(id)) {
        e.set_text_content(Some(text));
    }
}

/// The canvas with id `id`.
pub(crate) fn canvas(id: &str) -> Result<web_sys::HtmlCanvasElement, JsValue> {
    document()
        .and_then(|d| d.get_element_by_id(id))
        .ok_or_else(|| JsValue::from_str(&format!("the page has no element with id `{id}`")))?
        .dyn_into::<web_sys::HtmlCanvasElement>()
        .map_err(|_| JsValue::from_str(&format!("`{id}` is not a canvas")))
}

thread_local! {
    /// The object URL of the last download, revoked when the next one is made.
    static LAST_URL: std::cell::RefCell<Option<String>> = const { std::cell::RefCell::new(None) };
}

/// Hands `bytes` to the user as a download named `name`.
pub(crate) fn download(name: &str, bytes: &[u8], mime: &str) -> Result<(), String> {
    let js = |e: JsValue| format!("the browser refused the download: {e:?}");
    let array = js_sys::Uint8Array::from(bytes);
    let parts = js_sys::Array::of1(&array);
    let options = web_sys::BlobPropertyBag::new();
    options.set_type(mime);
    let blob = web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &options).map_err(js)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(js)?;
    let a = document()
        .ok_or("no document")?
        .create_element("a")
        .map_err(js)?
        .dyn_into::<web_sys::HtmlAnchorElement>()
        .map_err(|_| "not an anchor".to_string())?;
    a.set_href(&url);
    a.set_download(name);
    a.click();
    if let Some(old) = LAST_URL.with(|u| u.replace(Some(url))) {
        let _ = web_sys::Url::revoke_object_url(&old);
    }
    Ok(())
}

/// `bytes` as a `data:` URL of type `mime` (base64).
pub(crate) fn data_url(mime: &str, bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4 + mime.len() + 13);
    out.push_str("data:");
    out.push_str(mime);
    out.push_str(";base64,");
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                out.push(ABC[(n >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}
