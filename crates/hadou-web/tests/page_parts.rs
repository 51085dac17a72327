//! The page's parts that need no browser: URL parameters, the presets (every example scene loads
//! from the embedded files and renders what it renders from disk), dropped scenes (the loader's
//! messages, files dropped without their folder, size refusals) and the GIF export.

use hadou_scene::{Backend, MemoryFiles, Scene};
use hadou_web::dropped::{self, DropBatch};
use hadou_web::export::{png_bytes, GifExport};
use hadou_web::params::{parse_query, ApiChoice};
use hadou_web::presets;
use std::path::Path;

fn scenes_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

#[test]
fn url_parameters_are_read_and_bad_ones_are_messages() {
    let p = parse_query("?scene=kamehameha&time=1.5&width=320&height=180&test=1").unwrap();
    assert_eq!(p.scene.as_deref(), Some("kamehameha"));
    assert_eq!(
        (p.time, p.width, p.height, p.test, p.api),
        (Some(1.5), Some(320), Some(180), true, ApiChoice::Auto)
    );
    let p = parse_query("scene=light-brace.toml&backend=webgl").unwrap();
    assert_eq!((p.scene.as_deref(), p.api), (Some("light-brace"), ApiChoice::WebGl));
    assert_eq!(parse_query("scene=a%20b+c").unwrap().scene.as_deref(), Some("a b c"));
    let e = parse_query("time=soon&width=0&backend=vulkan&colour=red").unwrap_err();
    assert_eq!(e.len(), 4, "{e:?}");
    assert!(e[0].contains("time=`soon`") && e[0].contains("number"), "{e:?}");
    assert!(e[1].contains("width=`0`"), "{e:?}");
    assert!(e[2].contains("backend=`vulkan`"), "{e:?}");
    assert!(e[3].contains("unknown URL parameter `colour`"), "{e:?}");
    assert!(parse_query("time=NaN").is_err() && parse_query("time=-1").is_err());
    assert!(parse_query("").unwrap() == Default::default());
}

#[test]
fn every_example_scene_is_a_preset_and_renders_as_it_does_from_disk() {
    let mut on_disk: Vec<String> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().to_str()?.strip_suffix(".toml").map(str::to_string))
        .collect();
    on_disk.sort();
    assert_eq!(presets::names(), on_disk);
    let e = presets::scene_path("nope").unwrap_err();
    assert!(e.contains("`nope`") && e.contains("kamehameha"), "{e}");
    hadou_scene::mount_memory_files(Some(presets::files()));
    let mut from_memory = Vec::new();
    for name in presets::names() {
        let path = presets::scene_path(name).unwrap();
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("preset {name}: {e}"));
        from_memory.push((name, scene));
    }
    hadou_scene::mount_memory_files(None);
    for (name, memory) in from_memory {
        let disk = Scene::load(scenes_dir().join(format!("{name}.toml"))).unwrap();
        let t = 0.6 * disk.duration();
        let frame = |s: &Scene| {
            let mut f = s.at(t);
            (f.width, f.height, f.samples) = (24, 16, 1);
            f
        };
        let mut cpu = hadou_cpu::CpuBackend::new();
        let a = cpu.render(&frame(&disk)).unwrap();
        let b = cpu.render(&frame(&memory)).unwrap();
        assert!(a.color == b.color, "preset {name}: the image differs from the scene loaded from disk");
    }
}

fn batch(files: &[(&str, &[u8])]) -> DropBatch {
    DropBatch { files: files.iter().map(|(n, b)| (n.to_string(), b.to_vec())).collect(), refused: Vec::new() }
}

#[test]
fn dropped_scenes_load_with_their_files_or_say_what_is_wrong() {
    let light = std::fs::read(scenes_dir().join("light-closeup.toml")).unwrap();
    let text = String::from_utf8(light.clone()).unwrap();
    assert!(text.contains("assets/hero.glb"), "the scene names assets/hero.glb");
    let hero = std::fs::read(scenes_dir().join("assets/hero.glb")).unwrap();
    let base = MemoryFiles::new();

    // The glTF file the scene names, not dropped: the loader's message names it.
    let e = dropped::load(&batch(&[("light-closeup.toml", &light)]), &base).err().expect("the load fails");
    assert!(e.contains("hero.glb") && e.contains("not dropped"), "{e}");
    assert!(e.starts_with("/dropped/light-closeup.toml:"), "file:line:col first: {e}");
    assert!(hadou_scene::mount_memory_files(None).is_none(), "a failed load mounts what was mounted before");

    // Dropped without its folder, it is found by its name.
    let doc = match dropped::load(&batch(&[("light-closeup.toml", &light), ("hero.glb", &hero)]), &base) {
        Ok(d) => d,
        Err(e) => panic!("{e}"),
    };
    assert_eq!(doc.text(), text);
    // Still mounted: an edit loads the scene again.
    let set = hadou_scene::mount_memory_files(None).expect("left mounted");
    assert!(set.get("/dropped/assets/hero.glb").is_some());

    // A TOML error: file:line:col, and the set mounted before comes back.
    let mut before = MemoryFiles::new();
    before.insert("/scenes/x.toml", b"".to_vec());
    hadou_scene::mount_memory_files(Some(before));
    let e = dropped::load(&batch(&[("bad.toml", b"[camera]\nfov = \"wide\"\n")]), &base)
        .err()
        .expect("the load fails");
    assert!(e.starts_with("/dropped/bad.toml:2:"), "{e}");
    let back = hadou_scene::mount_memory_files(None).expect("the set from before");
    assert!(back.get("/scenes/x.toml").is_some());

    let e = dropped::load(&batch(&[("hero.glb", &hero)]), &base).err().expect("the load fails");
    assert!(e.contains("no scene file"), "{e}");
    let e = dropped::load(&batch(&[("a.toml", b""), ("b.toml", b"")]), &base).err().expect("the load fails");
    assert!(e.contains("one scene file at a time"), "{e}");
}

#[test]
fn files_are_refused_by_size_before_they_are_read() {
    assert!(dropped::refuse_by_size("scene.toml", 1000.0).is_none());
    let e = dropped::refuse_by_size("scene.toml", (16u64 << 20) as f64 + 1.0).unwrap();
    assert!(e.contains("scene.toml") && e.contains("16777216"), "{e}");
    assert!(dropped::refuse_by_size("hero.glb", 1e9).is_none());
    assert!(dropped::refuse_by_size("hero.glb", 2e9).is_some());
    assert!(dropped::refuse_by_size("face.png", 3e8).is_some());
    assert!(dropped::refuse_by_size("notes.txt", 10.0).unwrap().contains("not read"));
    assert!(dropped::refuse_by_size("scene.toml", f64::NAN).is_some());
}

#[test]
fn the_gif_export_writes_every_frame_with_the_cli_s_delays() {
    let mut gif = GifExport::new(8, 6, 2..8, 24.0).unwrap();
    assert_eq!(gif.next_frame(), Some(2));
    assert!((gif.time_of(12) - 0.5).abs() < 1e-6);
    assert!(gif.push(vec![0; 10]).is_err(), "a frame of the wrong size is refused");
    while let Some(f) = gif.next_frame() {
        gif.push(vec![(f * 30) as u8; 8 * 6 * 4]).unwrap();
    }
    assert_eq!(gif.progress(), (6, 6));
    let bytes = gif.finish().unwrap();
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut d = opts.read_info(&bytes[..]).unwrap();
    let mut delays = Vec::new();
    while let Some(f) = d.read_next_frame().unwrap() {
        delays.push(f.delay);
    }
    let want: Vec<u16> = (0..6).map(|k| hadou_scene::gif_delay_cs(24.0, k)).collect();
    assert_eq!(delays, want);
    assert!(GifExport::new(5000, 5000, 0..2, 24.0).err().expect("too large").contains("4096"));
    assert!(GifExport::new(8, 8, 3..3, 24.0).is_err());
    let png = png_bytes(&[255; 4 * 4], 2, 2).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}
