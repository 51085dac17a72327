//! Whatever a scene may hold fits the GPU backend's one "shading data" storage binding under
//! WebGPU's default limits: a scene at hadou-scene's limits (textures at `MAX_SCENE_TEXELS`, 256
//! curve waves with full light polylines, `MAX_SHADOW_CASTERS` wave-shadow casts) packs into at
//! most 128 MiB. No device needed: the packing is plain Rust.

use hadou_gpu::layout::{self, FrameShadows, ShadingBuffers};
use hadou_math::curve::MAX_LIGHT_POINTS;
use hadou_scene::{encode_png, LightLine, Scene, MAX_SCENE_TEXELS, MAX_SHADOWS, MAX_SHADOW_CASTERS};

/// WebGPU's default `maxStorageBufferBindingSize`.
const WEBGPU_DEFAULT_BINDING: u64 = 128 << 20;

#[test]
fn a_scene_at_its_limits_fits_one_default_storage_binding() {
    let dir = std::env::temp_dir().join(format!("hadou-gpu-limits-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Two textures, 16 Mi + 15 Mi texels: the whole budget.
    let (w, h1, h2) = (4096u32, 4096u32, ((MAX_SCENE_TEXELS - 4096 * 4096) / 4096) as u32);
    std::fs::write(dir.join("a.png"), encode_png(w, h1, &vec![[9, 9, 9, 255]; (w * h1) as usize])).unwrap();
    std::fs::write(dir.join("b.png"), encode_png(w, h2, &vec![[9, 9, 9, 255]; (w * h2) as usize])).unwrap();
    let mut s = String::from(
        "[[material]]\nname = \"tex\"\nbase_texture = \"a.png\"\nfeature_texture = \"b.png\"\n\
         [[object]]\nname = \"ground\"\nkind = \"plane\"\nsize = [100, 100]\nmaterial = \"tex\"\n",
    );
    for i in 0..MAX_SHADOW_CASTERS {
        let (x, z) = ((i % 32) as f32 * 2.0 - 32.0, (i / 32) as f32 * 2.0 - 32.0);
        s += &format!("[[object]]\nname = \"c{i}\"\nkind = \"box\"\nposition = [{x}, 0.5, {z}]\n");
    }
    // 256 helices of ten turns: light polylines of many points (the test adds what is missing to
    // the most a polyline may hold).
    for i in 0..256 {
        s += &format!(
            "[[wave]]\nname = \"w{i}\"\nkind = \"helix\"\nO = [{}, 20, 0]\nD = [1, 0, 0]\nup = [0, 1, 0]\n\
             alpha = 1\nradius = 1\nrate = 6\nlength = 10\n",
            i as f32 * 0.01
        );
    }
    // 16 wave shadows of 64 casters each: 1024 plane casts.
    let per = MAX_SHADOW_CASTERS / MAX_SHADOWS;
    for k in 0..MAX_SHADOWS {
        let casters: Vec<String> = (k * per..(k + 1) * per).map(|i| format!("\"c{i}\"")).collect();
        s += &format!(
            "[[shadow]]\nname = \"s{k}\"\nkind = \"wave\"\nwave = \"w{k}\"\ncasters = [{}]\nreceivers = \"ground\"\n",
            casters.join(", ")
        );
    }
    std::fs::write(dir.join("s.toml"), &s).unwrap();
    let scene = Scene::load(dir.join("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    std::fs::remove_dir_all(&dir).ok();

    let frame = scene.at(0.0);
    let (_, _, curves) = layout::frame_waves(&frame).unwrap();
    let mut shading = ShadingBuffers::new(&frame, &curves);
    let lines: Vec<LightLine> =
        frame.waves.iter().zip(&curves).map(|(w, c)| w.light_line(c.as_ref())).collect();
    let polyline_points: usize =
        lines.iter().map(|l| if let LightLine::Polyline(p) = l { p.len() } else { 0 }).sum();
    let casts = frame.shadow_casts(&lines);
    assert_eq!(casts.len(), MAX_SHADOW_CASTERS);
    shading.push_shadows(&FrameShadows::new(&frame, &casts));
    let bytes = std::mem::size_of_val(shading.data.as_slice()) as u64;
    assert!(polyline_points >= 256 * 64, "{polyline_points}");
    assert!(bytes >= MAX_SCENE_TEXELS * 4, "{bytes}");
    // Every wave's polyline at its largest: 12 bytes per missing point.
    let worst = bytes + (256 * MAX_LIGHT_POINTS - polyline_points) as u64 * 12;
    assert!(worst <= WEBGPU_DEFAULT_BINDING, "the shading data takes up to {worst} bytes");
}
