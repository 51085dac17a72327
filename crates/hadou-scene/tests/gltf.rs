//! glTF 2.0 loading from bytes built in the test: data URIs, GLB, node transforms, index types,
//! missing files and unsupported modes.

mod common;

use common::base64;

use hadou_scene::{gltf_from_bytes, Scene, SceneError};
use std::path::{Path, PathBuf};

/// A unit right triangle in z = 0 (CCW seen from +z), as positions and u16 indices.
fn triangle_blob(with_normals: bool) -> (Vec<u8>, usize) {
    let mut b = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in p {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    if with_normals {
        for _ in 0..3 {
            for c in [0.0f32, 0.0, 2.0] {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    let idx_offset = b.len();
    for i in [0u16, 1, 2] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b.extend_from_slice(&[0, 0]);
    (b, idx_offset)
}

fn json(
    buffer_uri: Option<&str>,
    blob_len: usize,
    idx_offset: usize,
    normals: bool,
    mode: u32,
    nodes: &str,
) -> String {
    let uri = buffer_uri.map_or(String::new(), |u| format!(",\"uri\":\"{u}\""));
    let (normal_attr, normal_view, normal_acc) = if normals {
        (
            ",\"NORMAL\":2",
            ",{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36}",
            ",{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}",
        )
    } else {
        ("", "", "")
    };
    format!(
        "{{\"asset\":{{\"version\":\"2.0\"}},\"scene\":0,\"scenes\":[{{\"nodes\":[0]}}],\"nodes\":{nodes},\
         \"meshes\":[{{\"primitives\":[{{\"attributes\":{{\"POSITION\":0{normal_attr}}},\"indices\":1,\"mode\":{mode}}}]}}],\
         \"buffers\":[{{\"byteLength\":{blob_len}{uri}}}],\
         \"bufferViews\":[{{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36}},\
         {{\"buffer\":0,\"byteOffset\":{idx_offset},\"byteLength\":6}}{normal_view}],\
         \"accessors\":[{{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\
         \"min\":[0,0,0],\"max\":[1,1,0]}},\
         {{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}}{normal_acc}]}}"
    )
}

fn glb(json: &str, blob: &[u8]) -> Vec<u8> {
    let mut js = json.as_bytes().to_vec();
    while !js.len().is_multiple_of(4) {
        js.push(b' ');
    }
    let mut bin = blob.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + js.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(js.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&js);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

fn tmp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hadou-scene-gltf-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn gltf_with_data_uri_and_computed_normals() {
    let (blob, io) = triangle_blob(false);
    let uri = format!("data:application/octet-stream;base64,{}", base64(&blob));
    let j = json(Some(&uri), blob.len(), io, false, 4, "[{\"mesh\":0}]");
    let m = gltf_from_bytes(j.as_bytes(), Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.positions, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    assert_eq!(m.indices, vec![0, 1, 2]);
    for n in &m.normals {
        assert!((n[2] - 1.0).abs() < 1e-6, "{n:?}");
    }
}

#[test]
fn glb_with_node_transforms_composed() {
    let (blob, io) = triangle_blob(true);
    // Parent translates by (10, 0, 0); child scales x by 2 and rotates 90° about z.
    let nodes = "[{\"translation\":[10,0,0],\"children\":[1]},\
                 {\"mesh\":0,\"scale\":[2,1,1],\"rotation\":[0,0,0.70710677,0.70710677]}]";
    let j = json(None, blob.len(), io, true, 4, nodes);
    let m = gltf_from_bytes(&glb(&j, &blob), Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    // p' = T · R · S · p: (1,0,0) → scale (2,0,0) → rot (0,2,0) → (10,2,0).
    let close = |a: [f32; 3], b: [f32; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5);
    assert!(close(m.positions[0], [10.0, 0.0, 0.0]), "{:?}", m.positions);
    assert!(close(m.positions[1], [10.0, 2.0, 0.0]), "{:?}", m.positions);
    assert!(close(m.positions[2], [9.0, 0.0, 0.0]), "{:?}", m.positions);
    // Stored normals (0,0,2) come back unit and still +z.
    assert!(m.normals.iter().all(|n| close(*n, [0.0, 0.0, 1.0])), "{:?}", m.normals);
}

#[test]
fn external_buffer_and_missing_buffer_error() {
    let dir = tmp_dir("ext");
    let (blob, io) = triangle_blob(false);
    std::fs::write(dir.join("tri data.bin"), &blob).unwrap();
    let j = json(Some("tri%20data.bin"), blob.len(), io, false, 4, "[{\"mesh\":0}]");
    std::fs::write(dir.join("tri.gltf"), &j).unwrap();
    let j_missing = json(Some("nowhere.bin"), blob.len(), io, false, 4, "[{\"mesh\":0}]");
    std::fs::write(dir.join("broken.gltf"), &j_missing).unwrap();
    let j_lines = json(Some("tri%20data.bin"), blob.len(), io, false, 1, "[{\"mesh\":0}]");
    std::fs::write(dir.join("lines.gltf"), &j_lines).unwrap();

    let scene = |path: &str| {
        format!("[camera]\nfov = 40\n\n[[object]]\nname = \"o\"\nkind = \"gltf\"\npath = \"{path}\"\n[[object]]\nname = \"p\"\nkind = \"gltf\"\npath = \"{path}\"\n")
    };
    let scene_path = dir.join("s.toml");
    let ok = Scene::parse(&scene("tri.gltf"), &scene_path).unwrap_or_else(|e| panic!("{e}"));
    let f = ok.at(0.0);
    assert_eq!(f.objects[0].mesh.indices.len(), 3);
    // The same file is loaded once and shared.
    assert!(std::sync::Arc::ptr_eq(&f.objects[0].mesh, &f.objects[1].mesh));

    let e = Scene::parse(&scene("broken.gltf"), &scene_path).unwrap_err();
    assert!(matches!(e, SceneError::Gltf { .. }), "{e:?}");
    let at = e.location().unwrap();
    assert_eq!((at.line, at.col), (7, 8));
    let s = e.to_string();
    assert!(s.contains("broken.gltf") && s.contains("nowhere.bin"), "{s}");

    let e = Scene::parse(&scene("lines.gltf"), &scene_path).unwrap_err();
    assert!(e.to_string().contains("only TRIANGLES"), "{e}");
    assert!(e.to_string().contains("Lines"), "{e}");

    let e = Scene::parse(&scene("absent.glb"), &scene_path).unwrap_err();
    assert!(e.to_string().contains("absent.glb: cannot read the file"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn malformed_files_are_errors_not_panics() {
    let (blob, io) = triangle_blob(false);
    assert!(gltf_from_bytes(b"not gltf", Path::new(".")).is_err());
    // Declared buffer longer than the data.
    let j = json(None, blob.len() + 100, io, false, 4, "[{\"mesh\":0}]");
    let e = gltf_from_bytes(&glb(&j, &blob), Path::new(".")).unwrap_err();
    assert!(e.contains("byteLength"), "{e}");
    // Index out of range.
    let mut bad = blob.clone();
    bad[io] = 9;
    let j = json(None, bad.len(), io, false, 4, "[{\"mesh\":0}]");
    let e = gltf_from_bytes(&glb(&j, &bad), Path::new(".")).unwrap_err();
    assert!(e.contains("out of range"), "{e}");
    // Truncations of a valid GLB never panic.
    let j = json(None, blob.len(), io, false, 4, "[{\"mesh\":0}]");
    let good = glb(&j, &blob);
    assert!(gltf_from_bytes(&good, Path::new(".")).is_ok());
    for cut in 0..good.len() {
        let _ = gltf_from_bytes(&good[..cut], Path::new("."));
    }
}
