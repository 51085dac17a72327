//! Splits the toon bench scene's frame time: the scene with its waves, without waves (raster and
//! shading only), and without objects (waves only). `cargo run --release --example toon_parts`.
use hadou_cpu::CpuBackend;
use hadou_scene::{Backend, Scene};

fn main() {
    let (file, t) = hadou::bench::TOON_SCENE;
    let scene = Scene::load(format!("scenes/{file}")).expect("the toon scene loads");
    let size: u32 = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(512);
    let mut frame = scene.at(t);
    frame.width = size;
    frame.height = size;
    let mut no_waves = frame.clone();
    no_waves.waves.clear();
    let mut no_objects = frame.clone();
    no_objects.objects.clear();
    let plain = hadou::bench::plain_materials(&frame);
    let mut cpu = CpuBackend::new();
    for (name, f) in
        [("full", &frame), ("plain", &plain), ("no waves", &no_waves), ("no objects", &no_objects)]
    {
        let ms = hadou::bench::median_ms(&mut |f| cpu.render(f).map(|_| ()), f, 9).expect("renders");
        println!("{name:<12} {ms:8.2} ms");
    }
}
