//! `frame_camera`, `frame_view`: the hadou camera and rays rebuilt from a Bevy view's matrices see
//! what the view sees (perspective and orthographic).
//! `HadouCamera::mapping`: hadou's colour mapping turns Bevy's tone mapping off on its camera.

use bevy::camera::{CameraProjection, ScalingMode};
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use hadou_bevy::{frame_camera, frame_view, HadouCamera, HadouPlugin, ViewMapping};
use hadou_gpu::OverlayProjection;
use hadou_scene::ToneMode;

#[test]
fn a_perspective_view_becomes_the_same_hadou_camera() {
    let projection =
        PerspectiveProjection { fov: 50f32.to_radians(), near: 0.1, aspect_ratio: 16.0 / 9.0, ..default() };
    let clip_from_view = projection.get_clip_from_view();
    let eye = Vec3::new(0.0, 3.0, 16.0);
    let target = Vec3::new(1.0, 0.5, 0.0);
    let world_from_view = Transform::from_translation(eye).looking_at(target, Vec3::Y).to_matrix();
    let camera = frame_camera(&world_from_view, &clip_from_view, 200.0).expect("a perspective view");
    assert!((camera.fov_y_deg - 50.0).abs() < 1e-3, "fov {}", camera.fov_y_deg);
    assert!((camera.near - 0.1).abs() < 1e-7, "near {}", camera.near);
    assert_eq!(camera.far, 200.0);
    let basis = camera.basis(640, 360);
    let forward = (target - eye).normalize();
    let f = basis.forward;
    assert!((Vec3::new(f.x, f.y, f.z) - forward).length() < 1e-5);
    assert!((basis.eye.x - eye.x).abs() < 1e-5 && (basis.eye.z - eye.z).abs() < 1e-5);

    // The top-left pixel's ray projects to Bevy's top-left NDC corner.
    let dir = basis.pixel_dir(0.0, 0.0, 640, 360);
    let p = Vec3::new(eye.x + dir.x, eye.y + dir.y, eye.z + dir.z);
    let clip = clip_from_view * world_from_view.inverse() * p.extend(1.0);
    let ndc = clip.truncate() / clip.w;
    assert!((ndc.x - (-1.0 + 1.0 / 640.0)).abs() < 1e-4, "ndc x {}", ndc.x);
    assert!((ndc.y - (1.0 - 1.0 / 360.0)).abs() < 1e-4, "ndc y {}", ndc.y);
}

#[test]
fn an_orthographic_view_becomes_parallel_rays_from_its_near_plane() {
    let mut projection = OrthographicProjection {
        scaling_mode: ScalingMode::FixedVertical { viewport_height: 6.0 },
        near: 0.5,
        far: 100.0,
        ..OrthographicProjection::default_3d()
    };
    projection.update(128.0, 96.0);
    let clip_from_view = projection.get_clip_from_view();
    let world_from_view =
        Transform::from_xyz(1.0, 2.0, 10.0).looking_at(Vec3::new(1.0, 2.0, 0.0), Vec3::Y).to_matrix();
    let (camera, rays) = frame_view(&world_from_view, &clip_from_view, 40.0).expect("an orthographic view");
    let OverlayProjection::Orthographic { centre, right, up, depth_span } = rays else {
        panic!("not orthographic: {rays:?}")
    };
    let close = |a: [f32; 3], b: [f32; 3]| a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-4);
    // The near plane 0.5 in front of the eye; half-height 3, half-width 4 (4:3).
    assert!(close(centre, [1.0, 2.0, 9.5]), "centre {centre:?}");
    assert!(close(right, [4.0, 0.0, 0.0]) && close(up, [0.0, 3.0, 0.0]), "right {right:?}, up {up:?}");
    assert!((depth_span - 99.5).abs() < 1e-3, "depth span {depth_span}");
    let basis = camera.basis(128, 96);
    assert!((basis.forward.z + 1.0).abs() < 1e-6, "forward {:?}", basis.forward);
    assert_eq!(camera.far, 40.0);

    // A perspective view is still its eye's camera; degenerate projections are refused.
    let clip_from_view = PerspectiveProjection::default().get_clip_from_view();
    let (_, rays) = frame_view(&Mat4::IDENTITY, &clip_from_view, 100.0).unwrap();
    assert_eq!(rays, OverlayProjection::Perspective);
    assert!(frame_view(&Mat4::IDENTITY, &clip_from_view, 1e-4).is_err(), "far before near");
    projection.update(0.0, 96.0);
    assert!(frame_view(&Mat4::IDENTITY, &projection.get_clip_from_view(), 40.0).is_err(), "zero width");
}

#[test]
fn hadou_mapping_replaces_bevy_tonemapping_and_bevy_mapping_keeps_it() {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, HadouPlugin::default()));
    let hadou = HadouCamera { mapping: ViewMapping::Hadou(ToneMode::Filmic), ..default() };
    let mapped = app.world_mut().spawn((hadou, Tonemapping::TonyMcMapface)).id();
    let bevy = app.world_mut().spawn((HadouCamera::default(), Tonemapping::AgX)).id();
    app.update();
    assert_eq!(app.world().get::<Tonemapping>(mapped), Some(&Tonemapping::None));
    assert_eq!(app.world().get::<Tonemapping>(bevy), Some(&Tonemapping::AgX), "Bevy's mapping is left alone");

    // Switching the second camera to hadou's faithful mapping turns its tone mapping off too.
    app.world_mut().get_mut::<HadouCamera>(bevy).unwrap().mapping = ViewMapping::Hadou(ToneMode::Faithful);
    app.update();
    assert_eq!(app.world().get::<Tonemapping>(bevy), Some(&Tonemapping::None));
}
