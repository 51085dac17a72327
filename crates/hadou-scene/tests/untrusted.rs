//! Hostile and extreme inputs: each is a located error with a plain-language message, never a
//! panic, a hang or unbounded memory.

mod common;

use common::{at, err};
use hadou_scene::{gltf_from_bytes, read_regular_file, Scene, SceneError};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn tmp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hadou-untrusted-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A one-triangle glTF (positions only, data-URI buffer) with `extra` spliced into the top level.
fn triangle_gltf(nodes: &str, extra: &str) -> String {
    let mut b = Vec::new();
    for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        b.extend_from_slice(&c.to_le_bytes());
    }
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut enc = String::new();
    for c in b.chunks(3) {
        let v = (c[0] as u32) << 16 | (c[1] as u32) << 8 | c[2] as u32;
        for i in 0..4 {
            enc.push(A[(v >> (18 - 6 * i) & 63) as usize] as char);
        }
    }
    format!(
        "{{\"asset\":{{\"version\":\"2.0\"}},\"scenes\":[{{\"nodes\":[0]}}],\"nodes\":{nodes},\
         \"meshes\":[{{\"primitives\":[{{\"attributes\":{{\"POSITION\":0}}}}]}}],\
         \"buffers\":[{{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,{enc}\"}}],\
         \"bufferViews\":[{{\"buffer\":0,\"byteLength\":36}}],\
         \"accessors\":[{{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\
         \"min\":[0,0,0],\"max\":[1,1,0]}}]{extra}}}"
    )
}

#[test]
fn gltf_missing_accessor_is_an_error_not_a_panic() {
    let j = r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]}"#;
    let e = gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err();
    assert!(e.contains("refers to accessor 0") && e.contains("0 accessor"), "{e}");
}

#[test]
fn gltf_out_of_range_indices_are_errors() {
    assert!(gltf_from_bytes(triangle_gltf("[{\"mesh\":0}]", "").as_bytes(), Path::new(".")).is_ok());
    let cases = [
        (triangle_gltf("[{\"mesh\":3}]", ""), "mesh 3"),
        (triangle_gltf("[{\"mesh\":0,\"children\":[7]}]", ""), "node 7"),
        (triangle_gltf("[{\"mesh\":0}]", ",\"scene\":2"), "scene 2"),
        (triangle_gltf("[{\"mesh\":0,\"camera\":0}]", ""), "camera 0"),
        (triangle_gltf("[{\"mesh\":0,\"skin\":1}]", ""), "skin 1"),
        (triangle_gltf("[{\"mesh\":0}]", ",\"textures\":[{\"source\":4}]"), "image 4"),
        (
            triangle_gltf("[{\"mesh\":0}]", ",\"textures\":[{\"sampler\":2,\"source\":0}],\"images\":[{}]"),
            "sampler 2",
        ),
        (
            triangle_gltf(
                "[{\"mesh\":0}]",
                ",\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":5}}}]",
            ),
            "texture 5",
        ),
        (
            triangle_gltf("[{\"mesh\":0}]", ",\"images\":[{\"bufferView\":9,\"mimeType\":\"image/png\"}]"),
            "bufferView 9",
        ),
    ];
    for (j, want) in cases {
        let e = gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err();
        assert!(e.contains(&format!("refers to {want}")), "{want}: {e}");
    }
    // Broken references inside the mesh data itself.
    let j = triangle_gltf("[{\"mesh\":0}]", "").replace("\"bufferView\":0", "\"bufferView\":6");
    assert!(gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err().contains("bufferView 6"));
    let j = triangle_gltf("[{\"mesh\":0}]", "").replace("{\"buffer\":0,", "{\"buffer\":3,");
    assert!(gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err().contains("buffer 3"));
    let j = triangle_gltf("[{\"mesh\":0}]", "").replace("\"POSITION\":0}", "\"POSITION\":0},\"material\":1");
    assert!(gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err().contains("material 1"));
    let j = triangle_gltf("[{\"mesh\":0}]", "").replace("\"POSITION\":0}", "\"POSITION\":0},\"indices\":8");
    assert!(gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err().contains("accessor 8"));
}

#[test]
fn gltf_node_graphs_must_be_trees() {
    // 41 nodes, each listing the next one twice: 2^40 instances if expanded.
    let mut nodes: Vec<String> =
        (0..40).map(|i| format!("{{\"mesh\":0,\"children\":[{0},{0}]}}", i + 1)).collect();
    nodes.push("{\"mesh\":0}".into());
    let j = triangle_gltf(&format!("[{}]", nodes.join(",")), "");
    let start = Instant::now();
    let e = gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err();
    assert!(start.elapsed() < Duration::from_secs(2));
    assert!(e.contains("node 0 lists node 1 twice") && e.contains("trees"), "{e}");
    // Two parents.
    let j = triangle_gltf("[{\"children\":[2]},{\"children\":[2]},{\"mesh\":0}]", "");
    let e = gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err();
    assert!(e.contains("node 2 is a child of both node 0 and node 1"), "{e}");
    // A cycle not reachable from the scene, and a node that is its own child.
    let j = triangle_gltf("[{\"mesh\":0},{\"children\":[2]},{\"children\":[1]}]", "");
    assert!(gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err().contains("cycle"));
    let j = triangle_gltf("[{\"mesh\":0,\"children\":[0]}]", "");
    assert!(gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err().contains("itself"));
    // A scene root that is someone's child.
    let j = triangle_gltf("[{\"mesh\":0},{\"children\":[0]}]", "");
    assert!(gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err().contains("as a root"));
}

#[test]
fn gltf_triangle_budget_is_checked_before_reading() {
    let j = triangle_gltf("[{\"mesh\":0}]", "")
        .replace("\"POSITION\":0}", "\"POSITION\":0},\"indices\":1")
        .replace(
        "\"max\":[1,1,0]}",
        "\"max\":[1,1,0]},{\"bufferView\":0,\"componentType\":5125,\"count\":60000003,\"type\":\"SCALAR\"}",
    );
    let e = gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_err();
    assert!(e.contains("20000001 triangles") && e.contains("limit of 2097152"), "{e}");
}

#[test]
fn non_gltf_binary_is_named_as_such() {
    let e = gltf_from_bytes(&[0x89, b'P', b'N', b'G', 0, 1, 2, 3], Path::new(".")).unwrap_err();
    assert!(e.contains("not a glTF or GLB file"), "{e}");
    assert!(!e.contains("line 1 column 1"), "{e}");
    assert!(gltf_from_bytes(b"", Path::new(".")).unwrap_err().contains("empty"));
}

#[cfg(unix)]
fn mkfifo(p: &Path) {
    let ok = std::process::Command::new("mkfifo").arg(p).status().map(|s| s.success()).unwrap_or(false);
    assert!(ok, "mkfifo failed");
}

#[cfg(unix)]
#[test]
fn special_files_are_refused_not_read() {
    let d = tmp_dir("fifo");
    let fifo = d.join("pipe.toml");
    mkfifo(&fifo);
    let start = Instant::now();
    let e = Scene::load(&fifo).unwrap_err();
    assert!(matches!(e, SceneError::Io { .. }) && e.to_string().contains("FIFO"), "{e}");
    mkfifo(&d.join("pipe.gltf"));
    let scene = "[[object]]\nname = \"o\"\nkind = \"gltf\"\npath = \"pipe.gltf\"\n";
    let e = Scene::parse(scene, &d.join("s.toml")).unwrap_err();
    assert!(e.to_string().contains("FIFO"), "{e}");
    assert_eq!(at(&e), (4, 8));
    assert!(start.elapsed() < Duration::from_secs(5));
    let e = read_regular_file(Path::new("/dev/zero"), 1 << 20).unwrap_err();
    assert!(e.contains("device"), "{e}");
    let e = read_regular_file(&d, 1 << 20).unwrap_err();
    assert!(e.contains("directory"), "{e}");
    std::fs::write(d.join("big.toml"), vec![b'#'; 100]).unwrap();
    let e = read_regular_file(&d.join("big.toml"), 99).unwrap_err();
    assert!(e.contains("more than the limit"), "{e}");
    std::fs::remove_dir_all(&d).ok();
}

#[cfg(unix)]
#[test]
fn files_outside_the_scene_directory_are_refused() {
    let top = tmp_dir("confine");
    let d = top.join("scene");
    std::fs::create_dir_all(d.join("assets")).unwrap();
    std::fs::write(top.join("outside.bin"), [0u8; 64]).unwrap();
    std::fs::write(d.join("inside.bin"), [0u8; 36]).unwrap();
    std::os::unix::fs::symlink(top.join("outside.bin"), d.join("link.bin")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", d.join("zero.bin")).unwrap();
    let with_uri = |uri: &str| {
        triangle_gltf("[{\"mesh\":0}]", "").replace(
            &triangle_gltf("[{\"mesh\":0}]", "")
                [triangle_gltf("[{\"mesh\":0}]", "").find("data:").unwrap()..]
                .split('"')
                .next()
                .unwrap()
                .to_string(),
            uri,
        )
    };
    let scene = |path: &str| format!("[[object]]\nname = \"o\"\nkind = \"gltf\"\npath = \"{path}\"\n");
    let load = |gltf_name: &str, uri: &str| {
        std::fs::write(d.join("assets").join(gltf_name), with_uri(uri)).unwrap();
        Scene::parse(&scene(&format!("assets/{gltf_name}")), &d.join("s.toml"))
    };
    // Climbing out of the glTF's directory but staying in the scene's tree is fine.
    load("ok.gltf", "../inside.bin").unwrap_or_else(|e| panic!("{e}"));
    for (name, uri, why) in [
        ("abs.gltf", "/etc/hostname", "absolute path"),
        ("up.gltf", "../../outside.bin", "outside"),
        ("link.gltf", "../link.bin", "outside"),
        ("zero.gltf", "../zero.bin", "outside"),
    ] {
        let e = load(name, uri).unwrap_err();
        assert!(matches!(e, SceneError::Gltf { .. }), "{e:?}");
        assert!(e.to_string().contains(why), "{uri}: {e}");
        assert_eq!(at(&e), (4, 8));
    }
    // The glTF itself must be inside the scene's directory too.
    std::fs::write(top.join("out.gltf"), with_uri("data:,")).unwrap();
    let e = Scene::parse(&scene("../out.gltf"), &d.join("s.toml")).unwrap_err();
    assert!(e.to_string().contains("outside the scene file's directory"), "{e}");
    let e = Scene::parse(&scene("/etc/hostname"), &d.join("s.toml")).unwrap_err();
    assert!(e.to_string().contains("must be relative"), "{e}");
    std::fs::remove_dir_all(&top).ok();
}

#[test]
fn far_and_fov_are_bounded_so_rays_stay_finite() {
    let e = err("[camera]\nfar = 3e38\n");
    assert_eq!(at(&e), (2, 7));
    assert!(e.to_string().contains("`far` in [camera] must be in [1e-6, 1e7], got 3e38"), "{e}");
    let e = err("[camera]\nfov = 179.9\nfar = 1e6\n");
    assert_eq!(at(&e), (2, 7));
    let e = err("[camera]\nfar = 100\n\n[[track]]\ntarget = \"camera.far\"\nkeys = [[0, 100], [1, 3e38]]\n");
    assert_eq!(at(&e), (6, 23));
    assert!(e.to_string().contains("3e38"), "{e}");
    let e = err("[camera]\nnear = 1e-30\n");
    assert_eq!(at(&e), (2, 8));
    // The largest allowed values still give a finite far distance at the widest aspect ratio.
    let s = Scene::parse(
        "[image]\nwidth = 16384\nheight = 1\n[camera]\nfov = 179\nfar = 1e7\n",
        Path::new("x.toml"),
    )
    .unwrap();
    let f = s.at(0.0);
    let b = f.camera.basis(f.width, f.height);
    for (x, y) in [(0.0, 0.0), (16383.0, 0.0)] {
        let r =
            b.wave_ray(hadou_math::energy::Falloff::Faithful, f.camera.far, x, y, f.width, f.height, None);
        assert!(r.ray.dir.is_finite() && r.ray.dir.length().is_finite());
        let r = b.wave_ray(
            hadou_math::energy::Falloff::InverseSquare,
            f.camera.far,
            x,
            y,
            f.width,
            f.height,
            None,
        );
        assert!(r.t_far.is_finite());
    }
}

#[test]
fn huge_values_are_rejected_with_their_range() {
    let wave = "[[wave]]\nname = \"s\"\nkind = \"sphere\"\n";
    let e = err(&format!("{wave}M = [0, 0, 3e38]\nalpha_s = 1\n"));
    assert_eq!(at(&e), (4, 12));
    assert!(e.to_string().contains("within ±1e6, got 3e38"), "{e}");
    let e = err(&format!("{wave}M = [0, 0, 0]\nalpha_s = 1e30\n"));
    assert!(e.to_string().contains("[0, 1e5], got 1e30"), "{e}");
    let e = err(&format!("{wave}M = [0, 0, 0]\nalpha_s = 1e300\n"));
    assert!(e.to_string().contains("too large for 32-bit floats: 1e300"), "{e}");
    let e = err("[color]\nexposure = 1e20\n");
    assert_eq!(at(&e), (2, 12));
    let e = err("[[object]]\nname = \"b\"\nkind = \"box\"\nscale = 1e-30\n");
    assert_eq!(at(&e), (4, 9));
    let e = err("[light]\ndirection = [1e-30, 0, 0]\n");
    assert!(e.to_string().contains("too short"), "{e}");
    // Keys obey the same bounds.
    let e = err(&format!(
        "{wave}M = [0, 0, 0]\nalpha_s = 1\n[[track]]\ntarget = \"wave.s.M.x\"\nkeys = [[0, 0], [1, -2e6]]\n"
    ));
    assert!(e.to_string().contains("-2e6"), "{e}");
    // A smooth track that overshoots is clamped into range.
    let s = Scene::parse(
        &format!("{wave}M = [0, 0, 0]\nalpha_s = 1\n[[track]]\ntarget = \"wave.s.M.x\"\ninterpolation = \"smooth\"\nkeys = [[0, 0], [1, 1e6], [2, 0], [3, 1e6]]\n"),
        Path::new("x.toml"),
    )
    .unwrap();
    for i in 0..=30 {
        if let hadou_scene::WaveShape::Sphere(f) = &s.at(i as f32 * 0.1).waves[0].shape {
            assert!(f.center.x.abs() <= 1e6, "{}", f.center.x);
        }
    }
}

#[test]
fn distinct_huge_camera_points_are_not_called_equal() {
    let e = err("[camera]\nposition = [1e30, 0, 0]\ntarget = [2e30, 0, 0]\n");
    assert!(!e.to_string().contains("must differ"), "{e}");
    assert!(e.to_string().contains("within ±1e6"), "{e}");
    let e = err("[camera]\nposition = [0, 0, 1e-30]\ntarget = [0, 0, 0]\n");
    assert!(e.to_string().contains("at least 1e-6 apart"), "{e}");
    let e = err("[camera]\nposition = [0, 0, 1]\ntarget = [0, 0, 1]\n");
    assert!(e.to_string().contains("must differ"), "{e}");
}

#[test]
fn over_long_integers_say_so() {
    let e = err("[image]\nwidth = 123456789012345678901234567890\n");
    assert_eq!(at(&e), (2, 9));
    assert!(e.to_string().contains("an integer that is too large"), "{e}");
    let e = err("[camera]\nfov = 123456789012345678901234567890\n");
    assert!(e.to_string().contains("must be a number, got an integer that is too large"), "{e}");
    let e = err("[camera]\nfar = 200\n[[track]]\ntarget = \"camera.fov\"\nkeys = [[123456789012345678901234567890, 40]]\n");
    assert!(e.to_string().contains("an integer that is too large"), "{e}");
}

#[test]
fn wave_count_is_limited() {
    let one =
        |i: usize| format!("[[wave]]\nname = \"w{i}\"\nkind = \"sphere\"\nM = [0, 0, 0]\nalpha_s = 1\n");
    let ok: String = (0..256).map(one).collect();
    assert!(Scene::parse(&ok, Path::new("x.toml")).is_ok());
    let bad: String = (0..257).map(one).collect();
    let e = Scene::parse(&bad, Path::new("x.toml")).unwrap_err();
    assert!(e.to_string().contains("at most 256 waves"), "{e}");
}

#[test]
fn deeply_nested_toml_is_an_error_not_a_crash() {
    let text = format!("a = {}{}\n", "[".repeat(100_000), "]".repeat(100_000));
    let e = err(&text);
    assert!(matches!(e, SceneError::Syntax { .. } | SceneError::UnknownKey { .. }), "{e:?}");
}
