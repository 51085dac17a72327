//! glTF 2.0 (`.gltf` with external or data-URI buffers, and `.glb`) → one [`Mesh`]: every
//! TRIANGLES primitive of the default scene's nodes, with node transforms composed and baked in.
//! Buffers are resolved here (no image decoding is pulled in); every accessor is bounds-checked
//! before it is read, so a malformed file is an error, never a panic.

use crate::frame::Mesh;
use crate::mesh::{append_mesh, smooth_normals, transform_mesh};
use gltf::accessor::{DataType, Dimensions};
use gltf::buffer::Source;
use gltf::mesh::{Mode, Semantic};
use hadou_math::Mat4;
use std::path::Path;

/// Deepest node hierarchy followed (guards against cyclic node graphs).
const MAX_DEPTH: usize = 64;

/// Loads the glTF/GLB file at `path` into one mesh in the file's scene space.
pub fn load_gltf(path: &Path) -> Result<Mesh, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read the file: {e}"))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    gltf_from_bytes(&bytes, dir)
}

/// Parses glTF or GLB `bytes`; external buffers are resolved relative to `dir`.
pub fn gltf_from_bytes(bytes: &[u8], dir: &Path) -> Result<Mesh, String> {
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| format!("not a valid glTF 2.0 file: {e}"))?;
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for buffer in gltf.buffers() {
        let data = match buffer.source() {
            Source::Bin => gltf.blob.clone().ok_or_else(|| {
                format!("buffer {} refers to a GLB binary chunk, but there is none", buffer.index())
            })?,
            Source::Uri(uri) => {
                resolve_uri(uri, dir).map_err(|e| format!("buffer {}: {e}", buffer.index()))?
            }
        };
        if data.len() < buffer.length() {
            return Err(format!(
                "buffer {} has {} bytes but the file declares byteLength {}",
                buffer.index(),
                data.len(),
                buffer.length()
            ));
        }
        buffers.push(data);
    }

    let mut out = Mesh::default();
    let roots: Vec<gltf::Node<'_>> = match gltf.default_scene().or_else(|| gltf.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => gltf.nodes().collect(),
    };
    for node in roots {
        add_node(&node, Mat4::IDENTITY, &buffers, &mut out, 0)?;
    }
    if out.indices.is_empty() {
        return Err("the default scene contains no triangles".into());
    }
    Ok(out)
}

fn add_node(
    node: &gltf::Node<'_>,
    parent: Mat4,
    buffers: &[Vec<u8>],
    out: &mut Mesh,
    depth: usize,
) -> Result<(), String> {
    if depth > MAX_DEPTH {
        return Err(format!(
            "node hierarchy deeper than {MAX_DEPTH} levels (a cycle?) at node {}",
            node.index()
        ));
    }
    let local = Mat4 { cols: node.transform().matrix() };
    if local.cols.iter().flatten().any(|v| !v.is_finite()) {
        return Err(format!("node {} has a non-finite transform", node.index()));
    }
    let world = parent * local;
    if let Some(mesh) = node.mesh() {
        for prim in mesh.primitives() {
            let what = format!("mesh {} primitive {}", mesh.index(), prim.index());
            let m = read_primitive(&prim, buffers).map_err(|e| format!("{what}: {e}"))?;
            append_mesh(out, &transform_mesh(&m, &world));
        }
    }
    for child in node.children() {
        add_node(&child, world, buffers, out, depth + 1)?;
    }
    Ok(())
}

fn read_primitive(prim: &gltf::Primitive<'_>, buffers: &[Vec<u8>]) -> Result<Mesh, String> {
    let mode = prim.mode();
    if mode != Mode::Triangles {
        return Err(format!("mode {mode:?} is not supported; only TRIANGLES (4) primitives can be loaded"));
    }
    let get = |b: gltf::Buffer<'_>| buffers.get(b.index()).map(|d| d.as_slice());
    let reader = prim.reader(get);

    let pos_acc = prim.get(&Semantic::Positions).ok_or("has no POSITION attribute")?;
    check_accessor(&pos_acc, Dimensions::Vec3, &[DataType::F32], buffers)
        .map_err(|e| format!("POSITION: {e}"))?;
    let positions: Vec<[f32; 3]> = reader.read_positions().ok_or("POSITION data cannot be read")?.collect();
    if positions.iter().flatten().any(|v| !v.is_finite()) {
        return Err("POSITION contains NaN or infinite values".into());
    }
    let n = positions.len();

    let indices: Vec<u32> = match prim.indices() {
        Some(acc) => {
            check_accessor(&acc, Dimensions::Scalar, &[DataType::U8, DataType::U16, DataType::U32], buffers)
                .map_err(|e| format!("indices: {e}"))?;
            let idx: Vec<u32> = reader.read_indices().ok_or("indices cannot be read")?.into_u32().collect();
            if let Some(bad) = idx.iter().find(|&&i| i as usize >= n) {
                return Err(format!("index {bad} is out of range for {n} vertices"));
            }
            idx
        }
        None => (0..n as u32).collect(),
    };
    if !indices.len().is_multiple_of(3) {
        return Err(format!("{} indices is not a multiple of 3", indices.len()));
    }

    let normals = match prim.get(&Semantic::Normals) {
        Some(acc) => {
            check_accessor(&acc, Dimensions::Vec3, &[DataType::F32], buffers)
                .map_err(|e| format!("NORMAL: {e}"))?;
            let normals: Vec<[f32; 3]> = reader.read_normals().ok_or("NORMAL data cannot be read")?.collect();
            if normals.len() != n {
                return Err(format!("NORMAL has {} entries but POSITION has {n}", normals.len()));
            }
            let fallback = smooth_normals(&positions, &indices);
            normals
                .iter()
                .zip(&fallback)
                .map(|(nv, f)| {
                    let v = hadou_math::Vec3f::from_array(*nv);
                    v.try_normalize().map_or(*f, |u| u.to_array())
                })
                .collect()
        }
        None => smooth_normals(&positions, &indices),
    };
    Ok(Mesh { positions, normals, indices })
}

/// Checks that reading `acc` stays inside its buffer view and buffer and has the expected layout.
fn check_accessor(
    acc: &gltf::Accessor<'_>,
    dims: Dimensions,
    types: &[DataType],
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    if acc.dimensions() != dims {
        return Err(format!("accessor {} has type {:?}, expected {dims:?}", acc.index(), acc.dimensions()));
    }
    if !types.contains(&acc.data_type()) {
        return Err(format!(
            "accessor {} has component type {:?}, expected one of {types:?}",
            acc.index(),
            acc.data_type()
        ));
    }
    if acc.sparse().is_some() {
        return Err(format!("accessor {} is sparse, which is not supported", acc.index()));
    }
    let view = acc.view().ok_or_else(|| format!("accessor {} has no bufferView", acc.index()))?;
    if acc.count() == 0 {
        return Err(format!("accessor {} is empty", acc.index()));
    }
    let size = acc.size();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "bufferView {} stride {stride} is smaller than an element ({size} bytes)",
            view.index()
        ));
    }
    let end = stride
        .checked_mul(acc.count() - 1)
        .and_then(|v| v.checked_add(size))
        .and_then(|v| v.checked_add(acc.offset()));
    if end.is_none_or(|e| e > view.length()) {
        return Err(format!("accessor {} reads past the end of bufferView {}", acc.index(), view.index()));
    }
    let data_len = buffers.get(view.buffer().index()).map_or(0, |b| b.len());
    if view.offset().checked_add(view.length()).is_none_or(|e| e > data_len) {
        return Err(format!(
            "bufferView {} reads past the end of buffer {}",
            view.index(),
            view.buffer().index()
        ));
    }
    Ok(())
}

/// The bytes of a buffer URI: a `data:` URI with base64 payload, or a relative file path.
fn resolve_uri(uri: &str, dir: &Path) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) =
            rest.split_once(";base64,").ok_or("only base64 data URIs are supported (`data:…;base64,…`)")?;
        return base64_decode(payload).ok_or_else(|| "invalid base64 in data URI".to_string());
    }
    if uri.contains("://") {
        return Err(format!("cannot fetch `{uri}`: only relative file paths and data URIs are supported"));
    }
    let file = dir.join(percent_decode(uri));
    std::fs::read(&file).map_err(|e| format!("cannot read {}: {e}", file.display()))
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = |c: u8| (c as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Standard base64 (with or without padding); `None` on any invalid character.
pub(crate) fn base64_decode(s: &str) -> Option<Vec<u8>> {
    let val = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    };
    let data: Vec<u8> = s.bytes().filter(|c| !c.is_ascii_whitespace()).collect();
    let data = data.strip_suffix(b"==").or_else(|| data.strip_suffix(b"=")).unwrap_or(&data);
    let mut out = Vec::with_capacity(data.len() * 3 / 4);
    for chunk in data.chunks(4) {
        if chunk.len() == 1 {
            return None;
        }
        let mut acc = 0u32;
        for (i, &c) in chunk.iter().enumerate() {
            acc |= val(c)? << (18 - 6 * i);
        }
        let bytes = acc.to_be_bytes();
        out.extend_from_slice(&bytes[1..chunk.len()]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips_known_vectors() {
        assert_eq!(base64_decode("TWFu").unwrap(), b"Man");
        assert_eq!(base64_decode("TWE=").unwrap(), b"Ma");
        assert_eq!(base64_decode("TQ==").unwrap(), b"M");
        assert_eq!(base64_decode("").unwrap(), b"");
        assert!(base64_decode("T!==").is_none());
        assert_eq!(percent_decode("a%20b.bin"), "a b.bin");
        assert_eq!(percent_decode("50%"), "50%");
    }
}
