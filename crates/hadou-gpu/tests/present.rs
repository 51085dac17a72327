//! `GpuBackend::render_to_texture` on a device opened the way a window opens it (an adapter of its
//! own, `hadou_gpu::device_descriptor`, `GpuBackend::from_device`): the texture, copied back here
//! (test code may wait), holds `linear_to_srgb8` of the colour `Backend::render` gives for the same
//! frame, every byte within one code (alpha: the stored alpha as an 8-bit unorm), on example
//! scenes, at two sizes in a row, across more than one tile.
//!
//! Skips with a message when there is no usable adapter; fails instead under
//! `HADOU_REQUIRE_GPU=1`.

use hadou_gpu::{GpuBackend, PRESENT_FORMAT, PRESENT_USAGE};
use hadou_math::shade::linear_to_srgb8;
use hadou_scene::{Backend, Frame, Image, RenderError};
use std::sync::{Mutex, MutexGuard, OnceLock};

/// A backend on a device this test opened, with the test's own handles to that device.
struct Gpu {
    backend: GpuBackend,
    device: wgpu::Device,
}

/// The adapter `GpuBackend::new` would choose.
fn adapter() -> Result<wgpu::Adapter, String> {
    hadou_gpu::request_adapter()
}

/// Opens a device as a window would and builds the backend on it. `Err(None)` when there is no
/// usable adapter (a skip), `Err(Some(_))` on any other failure.
fn open() -> Result<Gpu, Option<String>> {
    open_with(|_| {})
}

/// [`open`], with `edit` changing the device descriptor first.
fn open_with(edit: impl FnOnce(&mut wgpu::DeviceDescriptor<'static>)) -> Result<Gpu, Option<String>> {
    let adapter = adapter().map_err(|e| {
        eprintln!("no adapter: {e}");
        None
    })?;
    match hadou_gpu::check_adapter(&adapter) {
        Ok(()) => {}
        Err(RenderError::NoDevice(m)) => {
            eprintln!("{m}");
            return Err(None);
        }
        Err(e) => return Err(Some(e.to_string())),
    }
    let mut descriptor = hadou_gpu::device_descriptor(&adapter);
    edit(&mut descriptor);
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))
        .map_err(|e| Some(format!("request_device: {e}")))?;
    let backend =
        GpuBackend::from_device(&adapter, device.clone(), queue).map_err(|e| Some(e.to_string()))?;
    eprintln!("adapter: {:?}", adapter.get_info());
    Ok(Gpu { backend, device })
}

/// The one backend of this test binary, shared by its tests in turn (see tests/common), or
/// `None` when there is no usable adapter.
fn gpu_or_skip(test: &str) -> Option<MutexGuard<'static, Gpu>> {
    static SHARED: OnceLock<Result<Mutex<Gpu>, Option<String>>> = OnceLock::new();
    match SHARED.get_or_init(|| open().map(Mutex::new)) {
        Ok(gpu) => Some(gpu.lock().unwrap_or_else(|p| p.into_inner())),
        Err(None) => {
            if std::env::var("HADOU_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("{test}: HADOU_REQUIRE_GPU=1 but no usable GPU adapter");
            }
            eprintln!(
                "SKIPPED {test}: no usable GPU adapter; set HADOU_REQUIRE_GPU=1 to make this a failure"
            );
            None
        }
        Err(Some(e)) => panic!("{test}: GPU backend failed to start: {e}"),
    }
}

/// An example scene at time `t` (a fraction of its duration), `width × height`.
fn scene_frame(file: &str, t: f32, width: u32, height: u32) -> Frame {
    let path = format!("{}/../../scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    let scene = hadou_scene::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let mut frame = scene.at(t * scene.duration());
    frame.width = width;
    frame.height = height;
    frame
}

/// Renders `frame` into the texture and reads it back through `GpuBackend::read_presented` (the
/// web page's non-blocking read-back; the test waits between its polls): the texture's rows of
/// RGBA bytes, and whether the texture was recreated.
fn texture_bytes(gpu: &mut Gpu, frame: &Frame) -> (Vec<u8>, bool) {
    let Gpu { backend, device, .. } = gpu;
    let presented = backend.render_to_texture(frame).unwrap_or_else(|e| panic!("render_to_texture: {e}"));
    let [w, h] = presented.size;
    assert_eq!([w, h], [frame.width, frame.height]);
    let texture = presented.texture;
    assert_eq!(texture.format(), PRESENT_FORMAT);
    assert_eq!(texture.usage(), PRESENT_USAGE);
    assert_eq!((texture.width(), texture.height()), (w, h));
    let recreated = presented.recreated;
    let mut read = backend.read_presented().expect("a texture was drawn");
    assert_eq!(read.size(), [w, h]);
    let bytes = loop {
        if let Some(r) = read.try_take(device) {
            break r.unwrap_or_else(|e| panic!("read_presented: {e}"));
        }
        device
            .poll(wgpu::PollType::Wait {
                submission_index: None,
                timeout: Some(std::time::Duration::from_secs(300)),
            })
            .expect("waiting for the GPU");
    };
    assert!(read.try_take(device).is_none(), "the bytes come back once");
    assert_eq!(bytes.len(), 4 * w as usize * h as usize);
    (bytes, recreated)
}

/// The bytes a read-back image should become: sRGB codes of the colour, alpha as unorm.
fn expected_bytes(image: &Image) -> Vec<u8> {
    image
        .color
        .iter()
        .flat_map(|c| [linear_to_srgb8(c[0]), linear_to_srgb8(c[1]), linear_to_srgb8(c[2]), unorm8(c[3])])
        .collect()
}

fn unorm8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// Bytes further than one code from the expected ones, with the first as a message.
fn differences(got: &[u8], want: &[u8], width: u32) -> (usize, usize, Option<String>) {
    assert_eq!(got.len(), want.len());
    let (mut bad, mut off_by_one, mut first) = (0, 0, None);
    for (i, (&g, &w)) in got.iter().zip(want).enumerate() {
        match g.abs_diff(w) {
            0 => {}
            1 => off_by_one += 1,
            _ => {
                bad += 1;
                if first.is_none() {
                    let px = i / 4;
                    first = Some(format!(
                        "pixel ({}, {}) channel {}: texture {g}, expected {w}",
                        px % width as usize,
                        px / width as usize,
                        i % 4
                    ));
                }
            }
        }
    }
    (bad, off_by_one, first)
}

/// Asserts that the texture of `frame` matches `render(frame)`; returns whether it was recreated.
fn check(gpu: &mut Gpu, label: &str, frame: &Frame) -> bool {
    let (got, recreated) = texture_bytes(gpu, frame);
    let image = gpu.backend.render(frame).unwrap_or_else(|e| panic!("{label}: render: {e}"));
    let (bad, off_by_one, first) = differences(&got, &expected_bytes(&image), frame.width);
    eprintln!("{label}: {} bytes, {off_by_one} one code off, {bad} further", got.len());
    assert_eq!(bad, 0, "{label}: {bad} bytes differ by more than one code; first: {first:?}");
    recreated
}

#[test]
fn texture_holds_the_rendered_image_in_srgb() {
    let Some(mut gpu) = gpu_or_skip("present: texture = sRGB of render") else { return };
    // The glare scene's texture is the read-back image (with its [bloom]) uploaded.
    for file in ["kamehameha.toml", "shadow-wave-top.toml", "soft-gradient.toml", "glare-kamehameha.toml"] {
        check(&mut gpu, file, &scene_frame(file, 0.5, 128, 96));
    }
    // The comparison can fail: another frame's texture against this frame's image.
    let a = scene_frame("kamehameha.toml", 0.0, 128, 96);
    let b = scene_frame("kamehameha.toml", 1.0, 128, 96);
    let (got, _) = texture_bytes(&mut gpu, &b);
    let image = gpu.backend.render(&a).expect("render");
    let (bad, _, first) = differences(&got, &expected_bytes(&image), a.width);
    eprintln!("a different frame: {bad} bytes differ by more than one code; first: {first:?}");
    assert!(bad > 100, "the texture of another frame should not match: {bad} bytes differ");
}

#[test]
fn two_sizes_in_a_row_and_several_tiles() {
    let Some(mut gpu) = gpu_or_skip("present: sizes") else { return };
    let small = scene_frame("kamehameha.toml", 0.25, 96, 64);
    check(&mut gpu, "96×64", &small);
    assert!(!check(&mut gpu, "96×64 again", &small), "the same size keeps the texture");
    // Wider than one tile (MAX_TILE = 1024): two tiles side by side, the second 20 pixels wide.
    let wide = scene_frame("kamehameha.toml", 0.25, hadou_gpu::MAX_TILE + 20, 24);
    assert!(check(&mut gpu, "1044×24", &wide), "a new size makes a new texture");
    assert!(check(&mut gpu, "96×64 after 1044×24", &small), "and back");
    // Glare over two tiles: the band's glare presented after both.
    let glare = scene_frame("glare-kamehameha.toml", 0.5, hadou_gpu::MAX_TILE + 20, 24);
    assert!(check(&mut gpu, "glare 1044×24", &glare), "a new size makes a new texture");
}

/// Waits here (test code may) until the backend's latest present timing is of frame `serial` or
/// later, calling `last_present_timing` (which never waits) between blocking polls; `None` if it
/// never comes.
fn timing_of(gpu: &mut Gpu, serial: u64) -> Option<hadou_gpu::PresentTiming> {
    for _ in 0..20 {
        gpu.device
            .poll(wgpu::PollType::Wait {
                submission_index: None,
                timeout: Some(std::time::Duration::from_secs(300)),
            })
            .expect("waiting for the GPU");
        if let Some(t) = gpu.backend.last_present_timing().filter(|t| t.serial >= serial) {
            return Some(t);
        }
    }
    None
}

/// The names of `t`'s passes, in order.
fn pass_names(t: &hadou_gpu::PresentTiming) -> Vec<&str> {
    t.passes.iter().map(|p| p.name.as_str()).collect()
}

/// `last_present_timing`: with timestamps (lavapipe; Mesa's desktop GL too, through
/// `GL_ARB_timer_query`) the GPU time of the latest timed frame comes back, split into its passes
/// (the present pass included), with increasing serials; a frame with an `[area_light]` is not
/// timed. Without timestamps it is always `None` (see also the next test). The timed path draws
/// the same image (shadow maps included).
#[test]
fn present_timing_comes_back_without_waiting() {
    let Some(mut gpu) = gpu_or_skip("present: timing") else { return };
    let has = gpu.backend.has_timestamps();
    let mut serials = Vec::new();
    for t in [0.0, 0.5, 1.0] {
        let frame = scene_frame("kamehameha.toml", t, 128, 96);
        let presented = gpu.backend.render_to_texture(&frame).expect("render_to_texture");
        serials.push(presented.serial);
        // Nothing here waited: asking right away never blocks (it may or may not have a time).
        let _ = gpu.backend.last_present_timing();
    }
    assert!(serials.windows(2).all(|s| s[1] == s[0] + 1), "serials count frames: {serials:?}");
    let last = *serials.last().expect("three frames");
    if !has {
        assert!(timing_of(&mut gpu, 0).is_none(), "no timestamps, no timing");
        eprintln!("{}: no timestamp queries, no present timing", gpu.backend.adapter_name());
        return;
    }
    let t = timing_of(&mut gpu, last).expect("a timing for the last frame");
    eprintln!("{t:?}");
    let check_timing = |t: &hadou_gpu::PresentTiming, expected: &[&str]| {
        assert!(t.frame_ms > 0.0 && t.frame_ms.is_finite(), "{t:?}");
        assert_eq!(pass_names(t), expected, "{t:?}");
        assert!(
            t.passes.iter().all(|p| p.median_ms >= 0.0 && p.median_ms <= t.frame_ms * (1.0 + 1e-9)),
            "{t:?}"
        );
        let sum: f64 = t.passes.iter().map(|p| p.median_ms).sum();
        assert!(sum <= t.frame_ms * (1.0 + 1e-9), "passes {sum} ms > frame {} ms: {t:?}", t.frame_ms);
    };
    check_timing(&t, &["raster", "wave", "present"]);
    assert_eq!(t.serial, last);

    // Shadow maps and plane shadows, two tiles: later frame, larger serial; and the same image.
    let mut shadows = scene_frame("shadow-uneven.toml", 0.5, 128, 96);
    check(&mut gpu, "shadow-uneven (timed)", &shadows);
    shadows.width = hadou_gpu::MAX_TILE + 20;
    shadows.height = 24;
    let serial = gpu.backend.render_to_texture(&shadows).expect("render_to_texture").serial;
    let t2 = timing_of(&mut gpu, serial).expect("a timing for the shadow frame");
    eprintln!("{t2:?}");
    assert_eq!(t2.serial, serial);
    assert!(t2.serial > t.serial);
    check_timing(&t2, &["shadow maps", "raster", "edges", "plane shadows", "wave", "present"]);

    // An [area_light] frame is not timed: the latest timing stays the previous frame's.
    let soft = scene_frame("soft-gradient.toml", 0.5, 96, 72);
    assert!(soft.area_light.is_some());
    let soft_serial = gpu.backend.render_to_texture(&soft).expect("render_to_texture").serial;
    assert_eq!(soft_serial, serial + 1);
    assert!(timing_of(&mut gpu, soft_serial).is_none(), "an area-light frame is not timed");
    assert_eq!(gpu.backend.last_present_timing().map(|t| t.serial), Some(serial));

    // Many frames without anyone polling: those finding the ring busy go untimed, nothing
    // blocks, and the timing still comes back afterwards.
    let frame = scene_frame("kamehameha.toml", 0.25, 64, 48);
    let mut last = 0;
    for _ in 0..8 {
        last = gpu.backend.render_to_texture(&frame).expect("render_to_texture").serial;
    }
    let t3 = timing_of(&mut gpu, soft_serial + 1).expect("a timing after many frames");
    assert!(t3.serial > soft_serial && t3.serial <= last, "{t3:?}");
    check_timing(&t3, &["raster", "wave", "present"]);
}

/// A window that opened its device without `TIMESTAMP_QUERY` (as on an adapter lacking it, e.g.
/// WebGL or GLES without timer queries) never gets a present timing, and draws the same image.
#[test]
fn no_present_timing_without_timestamp_queries() {
    // Holding the shared backend's lock: one device renders at a time (see tests/common).
    let Some(_shared) = gpu_or_skip("present: no timestamps") else { return };
    let mut gpu = open_with(|d| d.required_features.remove(wgpu::Features::TIMESTAMP_QUERY))
        .unwrap_or_else(|e| panic!("opening a device without timestamps: {e:?}"));
    assert!(!gpu.backend.has_timestamps());
    assert!(gpu.backend.last_present_timing().is_none(), "nothing drawn yet");
    let frame = scene_frame("shadow-uneven.toml", 0.5, 96, 64);
    check(&mut gpu, "shadow-uneven (untimed)", &frame);
    for _ in 0..3 {
        gpu.backend.render_to_texture(&frame).expect("render_to_texture");
    }
    assert!(timing_of(&mut gpu, 0).is_none(), "no timestamps, no timing");
}
