//! Accessor checks shared by the glTF readers (`gltf_load`, `gltf_anim`): layout, and every byte
//! an accessor (sparse or not) reads inside its buffer views and buffers, before anything is read.

use gltf::accessor::{DataType, Dimensions};

/// Checks that reading `acc` stays inside its buffer view and buffer and has the expected layout.
pub(crate) fn check_accessor(
    acc: &gltf::Accessor<'_>,
    dims: &[Dimensions],
    types: &[DataType],
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    if !dims.contains(&acc.dimensions()) {
        return Err(format!(
            "accessor {} has type {:?}, expected one of {dims:?}",
            acc.index(),
            acc.dimensions()
        ));
    }
    if !types.contains(&acc.data_type()) {
        return Err(format!(
            "accessor {} has component type {:?}, expected one of {types:?}",
            acc.index(),
            acc.data_type()
        ));
    }
    if acc.count() == 0 {
        return Err(format!("accessor {} is empty", acc.index()));
    }
    // A sparse accessor: its indices and values must lie inside their views; its base is its
    // bufferView, or zeros without one.
    if let Some(sp) = acc.sparse() {
        let n = sp.count();
        if n == 0 || n > acc.count() {
            return Err(format!(
                "accessor {} has a sparse count of {n}, which must be 1..={} (its count)",
                acc.index(),
                acc.count()
            ));
        }
        let indices = sp.indices();
        check_view_range(&indices.view(), indices.offset(), n, indices.index_type().size(), buffers)
            .map_err(|e| format!("accessor {} (sparse indices): {e}", acc.index()))?;
        let values = sp.values();
        check_view_range(&values.view(), values.offset(), n, acc.size(), buffers)
            .map_err(|e| format!("accessor {} (sparse values): {e}", acc.index()))?;
    }
    let view = match acc.view() {
        Some(v) => v,
        None if acc.sparse().is_some() => return Ok(()),
        None => return Err(format!("accessor {} has no bufferView", acc.index())),
    };
    check_view_range(&view, acc.offset(), acc.count(), acc.size(), buffers)
        .map_err(|e| format!("accessor {}: {e}", acc.index()))
}

/// `count` elements of `size` bytes from `offset` (with the view's stride) lie inside `view`, and
/// `view` inside its buffer.
fn check_view_range(
    view: &gltf::buffer::View<'_>,
    offset: usize,
    count: usize,
    size: usize,
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "bufferView {} stride {stride} is smaller than an element ({size} bytes)",
            view.index()
        ));
    }
    let end = stride
        .checked_mul(count.saturating_sub(1))
        .and_then(|v| v.checked_add(size))
        .and_then(|v| v.checked_add(offset));
    if end.is_none_or(|e| e > view.length()) {
        return Err(format!("it reads past the end of bufferView {}", view.index()));
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
