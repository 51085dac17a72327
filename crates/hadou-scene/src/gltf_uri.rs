//! The bytes a glTF file names by URI (its external buffers and images): a base64 `data:` URI,
//! or a relative, percent-encoded file path that must resolve inside the asset root, read with a
//! byte cap. Used by `gltf_load` (buffers) and `gltf_material` (images).

use crate::error::{escape_controls, show_path};
use crate::files::{describe_bytes, read_regular_file, GLTF_MAX_BYTES};
use std::path::{Path, PathBuf};

/// The bytes of a buffer URI: a `data:` URI with base64 payload, or a relative file path that
/// resolves (symbolic links followed) inside the directory tree of `root`; at most `cap` bytes.
pub(crate) fn resolve_uri(uri: &str, dir: &Path, root: &Path, cap: u64) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) =
            rest.split_once(";base64,").ok_or("only base64 data URIs are supported (`data:…;base64,…`)")?;
        return base64_decode(payload).ok_or_else(|| "invalid base64 in data URI".to_string());
    }
    let shown = escape_controls(uri);
    if uri.contains("://") {
        return Err(format!("cannot fetch `{shown}`: only relative file paths and data URIs are supported"));
    }
    let rel = PathBuf::from(percent_decode(uri));
    if rel.is_absolute() || rel.has_root() {
        return Err(format!(
            "`{shown}` is an absolute path; buffer and image files must be named relative to the glTF file and lie \
             inside the scene file's directory"
        ));
    }
    let file = dir.join(&rel);
    let real =
        crate::files::canonicalize(&file).map_err(|e| format!("cannot read {}: {e}", show_path(&file)))?;
    let top =
        crate::files::canonicalize(root).map_err(|e| format!("cannot resolve {}: {e}", show_path(root)))?;
    if !real.starts_with(&top) {
        return Err(format!(
            "`{shown}` resolves to {}, outside {}; buffer and image files must lie inside the scene file's directory",
            show_path(&real),
            show_path(&top)
        ));
    }
    read_regular_file(&real, cap).map_err(|e| {
        let hint = if cap < GLTF_MAX_BYTES {
            format!(" ({} in all per glTF file)", describe_bytes(GLTF_MAX_BYTES))
        } else {
            String::new()
        };
        format!("cannot read {}: {e}{hint}", show_path(&file))
    })
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
fn base64_decode(s: &str) -> Option<Vec<u8>> {
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
