//! The failure story: bad frames and device trouble end in a `RenderError`, never a panic or hang.
//! (No adapter → `NoDevice` is tested in tests/no_device.rs, which needs its own process.)

mod common;

use common::*;
use hadou_math::Vec3;
use hadou_scene::{Backend, Mesh, RenderError, ToneMode};
use std::sync::Arc;

#[test]
fn image_size_outside_the_frame_contract_is_an_error() {
    let Some(mut gpu) = gpu_or_skip("image size") else { return };
    for (w, h) in [(0, 10), (10, 0), (16385, 4)] {
        let f = base_frame(w, h, Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, ToneMode::Filmic);
        match gpu.render(&f) {
            Err(RenderError::Other(m)) => assert!(m.contains("16384"), "{m}"),
            other => panic!("{w}×{h}: expected a size error, got {other:?}"),
        }
    }
    // The backend is still usable afterwards.
    let f = occlusion_frame(32, 24);
    assert!(gpu.render(&f).is_ok());
}

#[test]
fn bad_camera_is_an_error() {
    let Some(mut gpu) = gpu_or_skip("bad camera") else { return };
    let mut f = occlusion_frame(32, 24);
    f.camera.near = 200.0; // beyond far
    assert!(matches!(gpu.render(&f), Err(RenderError::Other(m)) if m.contains("near")));
}

#[test]
fn malformed_mesh_is_an_error_naming_the_object() {
    let Some(mut gpu) = gpu_or_skip("malformed mesh") else { return };
    let mut f = occlusion_frame(32, 24);
    let bad = Mesh {
        positions: vec![[0.0; 3]; 3],
        normals: vec![[0.0, 1.0, 0.0]; 3],
        indices: vec![0, 1, 7],
        ..Mesh::default()
    };
    f.objects[0].mesh = Arc::new(bad);
    f.objects[0].name = "broken box".into();
    match gpu.render(&f) {
        Err(RenderError::Other(m)) => assert!(m.contains("broken box") && m.contains('7'), "{m}"),
        other => panic!("expected a mesh error, got {other:?}"),
    }
    let mut f = occlusion_frame(32, 24);
    f.objects[1].mesh = Arc::new(Mesh {
        positions: vec![[0.0; 3]; 3],
        normals: vec![],
        indices: vec![0, 1, 2],
        ..Mesh::default()
    });
    assert!(matches!(gpu.render(&f), Err(RenderError::Other(m)) if m.contains("normals")));
}

#[test]
fn shadow_map_larger_than_the_adapter_allows_is_an_error_naming_the_shadow() {
    use hadou_scene::{Shadow, ShadowLight, ShadowMethod};
    let Some(mut gpu) = gpu_or_skip("shadow map size") else { return };
    let mut f = occlusion_frame(32, 24);
    f.shadows.push(Shadow {
        name: "huge".into(),
        light: ShadowLight::Sun(-Vec3::Y),
        method: ShadowMethod::Map { size: 1 << 20 },
        up: Vec3::Y,
        casters: vec![0],
        receivers: vec![1],
        color: [0.0; 3],
        opacity: 0.5,
    });
    match gpu.render(&f) {
        Err(RenderError::Device(m)) => assert!(
            m.starts_with("shadow \"huge\": map_size 1048576 exceeds this adapter's largest texture ("),
            "{m}"
        ),
        other => panic!("expected a device error, got {other:?}"),
    }
    // A shadow naming an object that does not exist is refused too, and the backend still works.
    f.shadows[0].method = ShadowMethod::Map { size: 64 };
    f.shadows[0].casters = vec![9];
    assert!(matches!(gpu.render(&f), Err(RenderError::Other(m)) if m.contains("huge") && m.contains('9')));
    f.shadows[0].casters = vec![0];
    assert!(gpu.render(&f).is_ok());
}
