//! VRM spring bones on the CPU backend (issue 46): `scenes/light-blast.toml` (the spring-bone hair
//! and skirt of `assets/blast.vrm` blown by a beam's `wind`) renders the same bytes at a time
//! whether the frame is rendered alone or after a sequence of frames, and the blown strands change
//! the picture (the posed mesh is what the backend draws, outlines and shadows).

use hadou_scene::Scene;
use std::path::PathBuf;

fn blast() -> Scene {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/light-blast.toml");
    Scene::load(&p).unwrap_or_else(|e| panic!("{e}"))
}

fn bytes(scene: &Scene, t: f32) -> Vec<u8> {
    let mut frame = scene.at(t);
    (frame.width, frame.height, frame.samples) = (160, 120, 1);
    let image = hadou_cpu::render(&frame);
    assert!(image.color.iter().flatten().all(|c| c.is_finite()), "no NaN reaches the image");
    image.color.iter().flatten().flat_map(|c| c.to_le_bytes()).collect()
}

#[test]
fn a_blown_frame_is_the_same_alone_in_a_sequence_and_in_chunks() {
    let times = [1.2f32, 1.6, 2.0, 2.4];
    let alone: Vec<Vec<u8>> = times.iter().map(|&t| bytes(&blast(), t)).collect();
    let sequence = blast();
    for k in 0..=24 {
        let t = k as f32 / 10.0;
        let b = bytes(&sequence, t);
        if let Some(i) = times.iter().position(|&x| x == t) {
            assert!(b == alone[i], "the frame at {t} s differs after a sequence");
        }
    }
    // Chunks: two scenes, each from the middle of the range, backwards.
    let chunk = blast();
    for (i, &t) in times.iter().enumerate().rev() {
        assert!(bytes(&chunk, t) == alone[i], "the frame at {t} s differs in a chunk");
    }
    assert_ne!(alone[0], alone[3], "the strands and the beam move the picture");
}
