//! Which adapter the GPU tests of this run use. CI runs the test suite twice, on Mesa's software
//! Vulkan and on a machine without any Vulkan driver (Mesa's OpenGL), and sets
//! `HADOU_EXPECT_BACKEND` (`vulkan`, `gl`, …) to the backend each run must be on, so a run that
//! silently fell back to another adapter cannot pass for the one it claims to be.

use hadou_gpu::wgpu;

#[test]
fn the_gpu_tests_run_on_the_expected_backend() {
    let info = match hadou_gpu::find_adapter() {
        Ok(info) => info,
        Err(e) => {
            assert!(std::env::var("HADOU_REQUIRE_GPU").map_or(true, |v| v != "1"), "{e}");
            eprintln!("SKIPPED adapter kind: {e}");
            return;
        }
    };
    eprintln!("GPU tests run on `{}` ({:?}, {:?})", info.name, info.backend, info.device_type);
    let Ok(expected) = std::env::var("HADOU_EXPECT_BACKEND") else { return };
    let expected = match expected.to_ascii_lowercase().as_str() {
        "vulkan" => wgpu::Backend::Vulkan,
        "gl" | "gles" => wgpu::Backend::Gl,
        "metal" => wgpu::Backend::Metal,
        "dx12" => wgpu::Backend::Dx12,
        other => panic!("HADOU_EXPECT_BACKEND={other}: expected vulkan, gl, metal or dx12"),
    };
    assert_eq!(info.backend, expected, "adapter `{}`", info.name);
}
