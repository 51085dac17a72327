//! `GpuBackend::from_shared_device` leaves the device owner's uncaptured-error handler in place
//! (an engine such as Bevy keeps seeing every error outside hadou's work), where
//! `GpuBackend::from_device` replaces it; both backends still draw.
//!
//! Skips with a message when there is no usable adapter; fails instead under
//! `HADOU_REQUIRE_GPU=1`.

use hadou_gpu::GpuBackend;
use hadou_scene::RenderError;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// A fresh device on the adapter `GpuBackend::new` would choose, or `None` (a skip).
fn open_device(test: &str) -> Option<(wgpu::Adapter, wgpu::Device, wgpu::Queue)> {
    let skip = |why: String| {
        if std::env::var("HADOU_REQUIRE_GPU").is_ok_and(|v| v == "1") {
            panic!("{test}: HADOU_REQUIRE_GPU=1 but no usable GPU adapter ({why})");
        }
        eprintln!("SKIPPED {test}: {why}; set HADOU_REQUIRE_GPU=1 to make this a failure");
        None
    };
    let adapter = match hadou_gpu::request_adapter() {
        Ok(a) => a,
        Err(e) => return skip(e),
    };
    match hadou_gpu::check_adapter(&adapter) {
        Ok(()) => {}
        Err(RenderError::NoDevice(m)) => return skip(m),
        Err(e) => panic!("{test}: {e}"),
    }
    let (device, queue) = pollster::block_on(adapter.request_device(&hadou_gpu::device_descriptor(&adapter)))
        .unwrap_or_else(|e| panic!("{test}: request_device: {e}"));
    Some((adapter, device, queue))
}

/// Installs a handler counting uncaptured errors, builds the backend with `build`, then makes
/// one validation error outside any error scope (a buffer both mappable for reading and for
/// writing) and returns how many errors the owner's handler saw.
fn owner_errors_seen(
    test: &str,
    build: fn(&wgpu::Adapter, wgpu::Device, wgpu::Queue) -> Result<GpuBackend, RenderError>,
) -> Option<usize> {
    let (adapter, device, queue) = open_device(test)?;
    let seen = Arc::new(AtomicUsize::new(0));
    let s = seen.clone();
    device.on_uncaptured_error(Arc::new(move |_| {
        s.fetch_add(1, Ordering::SeqCst);
    }));
    let backend = build(&adapter, device.clone(), queue).unwrap_or_else(|e| panic!("{test}: {e}"));
    let _bad = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("invalid on purpose"),
        size: 16,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::MAP_WRITE,
        mapped_at_creation: false,
    });
    let _ = device.poll(wgpu::PollType::Wait { submission_index: None, timeout: None });
    drop(backend);
    Some(seen.load(Ordering::SeqCst))
}

#[test]
fn a_shared_device_keeps_its_owners_error_handler() {
    let test = "a_shared_device_keeps_its_owners_error_handler";
    if let Some(seen) = owner_errors_seen(test, GpuBackend::from_shared_device) {
        assert_eq!(seen, 1, "the owner's handler must see the one error made outside hadou's scopes");
    }
}

#[test]
fn from_device_installs_its_own_error_handler() {
    let test = "from_device_installs_its_own_error_handler";
    if let Some(seen) = owner_errors_seen(test, GpuBackend::from_device) {
        assert_eq!(seen, 0, "from_device replaces the owner's handler with the backend's");
    }
}
