//! `[image] samples` and the sample grid: with an `[area_light]` the grid shrinks so that the
//! samples of the image stay within the soft shadows' limit; the sample frame is the frame `k`
//! times as wide and high, one sample each, without its glare.

use hadou_scene::{Scene, SOFT_MAX_PIXELS};

fn scene(name: &str) -> Scene {
    let path = format!("{}/../../scenes/{name}", env!("CARGO_MANIFEST_DIR"));
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn an_area_light_scene_shrinks_its_grid_to_the_soft_shadow_limit() {
    let mut f = scene("soft-plaster.toml").at(1.0);
    assert_eq!(f.samples, 4);
    for (size, samples, grid) in
        [(512, 4, 2), (2048, 4, 2), (2049, 4, 1), (4096, 4, 1), (1365, 9, 3), (1366, 9, 2), (1024, 16, 4)]
    {
        (f.width, f.height, f.samples) = (size, size, samples);
        assert_eq!(f.sample_grid().edge(), grid, "{size}² at {samples} samples");
        let k = u64::from(grid);
        assert!(u64::from(size).pow(2) * k * k <= SOFT_MAX_PIXELS);
    }
}

#[test]
fn the_sample_frame_drops_the_glare_and_keeps_the_camera() {
    let mut f = scene("glare-kamehameha.toml").at(1.0);
    f.samples = 16;
    assert!(f.bloom.is_some());
    let s = f.sample_frame();
    assert_eq!((s.width, s.height), (4 * f.width, 4 * f.height));
    assert_eq!((s.samples, s.sample_grid().edge()), (1, 1));
    assert!(s.bloom.is_none());
    assert_eq!(s.camera, f.camera);
    // Every ray through a pixel's centre is the same in both frames.
    let (b, sb) = (f.camera.basis(f.width, f.height), s.camera.basis(s.width, s.height));
    let d = b.pixel_dir(10.0, 7.0, f.width, f.height);
    let ds = sb.pixel_dir(41.5, 29.5, s.width, s.height);
    assert!((d - ds).length() < 1e-6, "{d:?} {ds:?}");
}
