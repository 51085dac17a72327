//! CPU backend behaviour on hand-built frames: occlusion (002 §3.3.5), determinism, finiteness.

use hadou_cpu::{probe, render};
use hadou_math::energy::{BeamField, CapsuleField, Falloff, SphereField};
use hadou_math::{Mat4, Vec3};
use hadou_scene::{Frame, Mesh, Object, Wave, WaveShape};
use std::sync::Arc;

mod common;

/// An axis-aligned cube of side 2 centred at the origin.
fn cube() -> Mesh {
    hadou_scene::mesh::box_mesh([2.0; 3])
}

fn frame(objects: Vec<Object>, waves: Vec<Wave>) -> Frame {
    common::frame(96, 64, common::camera(Vec3::new(0.0, 0.0, 40.0), 45.0), objects, waves)
}

fn cube_at(name: &str, z: f32) -> Object {
    Object::new(
        name,
        Arc::new(cube()),
        Mat4::from_trs(Vec3::new(0.0, 0.0, z), Vec3::ZERO, Vec3::splat(3.0)),
        [0.5, 0.5, 0.5],
    )
}

fn beam(falloff: Falloff) -> Wave {
    Wave {
        light: Default::default(),
        name: "beam".into(),
        color: [0.8, 0.8, 0.2, 1.0],
        falloff,
        core_radius: 0.05,
        attenuation: 0.0,
        shape: WaveShape::Beam(BeamField {
            capsule: CapsuleField {
                m: Vec3::new(-10.0, 0.0, 0.0),
                d: Vec3::X,
                length: 20.0,
                alpha_s: 2.0,
                alpha_c: 2.0,
            },
            head_alpha: 4.0,
            muzzle_alpha: 1.0,
        }),
    }
}

#[test]
fn a_cube_in_front_hides_the_beam_and_one_behind_does_not() {
    for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
        let (cx, cy) = (48, 32);
        let free = probe(&frame(vec![], vec![beam(falloff)]), cx, cy).unwrap();
        let front = probe(&frame(vec![cube_at("front", 15.0)], vec![beam(falloff)]), cx, cy).unwrap();
        let behind = probe(&frame(vec![cube_at("behind", -15.0)], vec![beam(falloff)]), cx, cy).unwrap();
        assert_eq!(front.object.as_deref(), Some("front"));
        assert_eq!(behind.object.as_deref(), Some("behind"));
        let e = |p: &hadou_cpu::Probe| p.waves[0].energy;
        assert!(e(&free) > 0.0);
        // In front: only the stretch between eye and cube face integrates; the beam itself is
        // hidden and only the slow 1/r (faithful) or 1/r² tail before the cube remains.
        let limit = if falloff == Falloff::Faithful { 0.2 } else { 0.05 };
        assert!(e(&front) < limit * e(&free), "front {} free {}", e(&front), e(&free));
        // Behind: the beam is in front of the cube; nearly all its energy remains.
        // (Faithful's 1/r tail beyond the cube, up to the far plane, is a sizeable share.)
        let keep = if falloff == Falloff::Faithful { 0.7 } else { 0.9 };
        assert!(e(&behind) > keep * e(&free), "behind {} free {}", e(&behind), e(&free));
        assert!(e(&behind) < e(&free) && e(&front) < e(&behind));
        // The depth is the eye distance to the cube's front face (z = 15 + 3 = 18 → 22).
        assert!((front.depth - 22.0).abs() < 0.05, "{}", front.depth);
    }
}

#[test]
fn rendering_is_deterministic_across_thread_counts() {
    let f = frame(vec![cube_at("a", -15.0), cube_at("b", 15.0)], vec![beam(Falloff::InverseSquare)]);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| render(&f));
    let many = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap().install(|| render(&f));
    assert_eq!(one, many);
}

#[test]
fn degenerate_waves_and_cameras_stay_finite() {
    let mut waves = vec![
        Wave {
            light: Default::default(),
            name: "through-eye".into(),
            color: [1.0; 4],
            falloff: Falloff::Faithful,
            core_radius: 0.0,
            attenuation: 0.0,
            shape: WaveShape::Sphere(SphereField { center: Vec3::new(0.0, 0.0, 40.0), alpha: 1.0 }),
        },
        beam(Falloff::Faithful),
    ];
    // A zero-length beam pointing straight at the camera.
    if let WaveShape::Beam(b) = &mut waves[1].shape {
        b.capsule.length = 0.0;
        b.capsule.d = Vec3::Z;
    }
    let img = render(&frame(vec![cube_at("c", 0.0)], waves));
    assert!(img.color.iter().flatten().all(|v| v.is_finite()));
    assert!(img.energy.iter().all(|v| v.is_finite() && *v >= 0.0));
    assert!(img.depth.iter().all(|v| v.is_finite() && *v > 0.0));
}

#[test]
fn shared_edges_are_drawn_exactly_once_and_leave_no_gaps() {
    // A cube face-on: every pixel inside its projected square is covered (no cracks along the
    // diagonal shared by two triangles).
    let img = render(&frame(vec![cube_at("c", 0.0)], vec![]));
    let covered = |x: u32, y: u32| img.depth[img.index(x, y)] < 50.0;
    for y in 28..36 {
        for x in 44..52 {
            assert!(covered(x, y), "gap at {x},{y}");
        }
    }
    assert!(!covered(0, 0));
}
