//! No adapter → `RenderError::NoDevice` with a message that says what to install. Its own test
//! binary because it changes the process environment: `WGPU_BACKEND` names a backend this build
//! does not contain on this platform, so wgpu finds no adapter at all.

use hadou_gpu::GpuBackend;
use hadou_scene::RenderError;

#[test]
fn no_adapter_is_no_device_with_a_clear_message() {
    let backend = if cfg!(target_os = "macos") { "dx12" } else { "metal" };
    std::env::set_var("WGPU_BACKEND", backend);
    match GpuBackend::new() {
        Err(RenderError::NoDevice(m)) => {
            assert!(m.contains("no GPU adapter") && m.contains("CPU backend"), "{m}");
        }
        Err(e) => panic!("expected NoDevice, got {e:?}"),
        Ok(g) => panic!("expected no adapter with WGPU_BACKEND={backend}, got `{}`", g.adapter_name()),
    }
}
