//! glTF materials, textures, samplers and images → [`Material`]s (see `gltf_load` for the rest).
//!
//! - `pbrMetallicRoughness.baseColorFactor` (rgb) → [`Material::base_color`], `baseColorTexture`
//!   → [`Material::base_texture`] with the sampler's `wrapS`/`wrapT` and `magFilter`.
//! - `KHR_materials_unlit` → [`ShadingModel::Unlit`]; `VRMC_materials_mtoon` (VRM 1.0) →
//!   [`ShadingModel::Toon`] with a two-band ramp (see [`mtoon_ramp`]); otherwise
//!   [`ShadingModel::Diffuse`].
//! - hadou's feature texture (000 §2.2) lives in the material's extras:
//!   `"extras": {"hadou": {"featureTexture": {"index": N, "texCoord": M}}}` (`texCoord` optional,
//!   0 by default) → [`Material::feature_texture`].
//!
//! Images come from a bufferView or a URI (base64 data URI, or a file inside the asset root; both
//! read by `gltf_uri`) and are decoded once each (PNG or JPEG, recognised by their bytes), only
//! when a material uses them, one at a time, against what is left of the scene's
//! [`MAX_SCENE_TEXELS`](crate::texture::MAX_SCENE_TEXELS). Every index read here is checked
//! against the array it points into first.

use crate::error::escape_controls;
use crate::frame::{Filter, Material, Ramp, ShadingModel, Texture, TextureRef, Wrap};
use crate::gltf_uri::resolve_uri;
use crate::texture::decode_texture_within;
use serde_json::Value;
use std::path::Path;
use std::sync::Arc;

/// The glTF extensions hadou maps (a file may list them in `extensionsRequired`).
pub(crate) const SUPPORTED_EXTENSIONS: &[&str] = &["KHR_materials_unlit", "VRMC_materials_mtoon"];

/// The materials of a file and the TEXCOORD set each one's textures read.
pub(crate) struct Materials {
    /// One per glTF material, in order, then the default material for primitives without one.
    pub list: Vec<Material>,
    /// Per glTF material: the TEXCOORD set its textures use, `None` when it has no texture.
    pub uv_set: Vec<Option<u32>>,
}

impl Materials {
    /// Slot of a primitive's material (`None` → the appended default).
    pub fn slot(&self, material: Option<usize>) -> u32 {
        material.unwrap_or(self.list.len() - 1) as u32
    }
}

/// Where images come from: the loaded buffers and where external files may be read.
pub(crate) struct ImageSource<'a> {
    /// Buffer data, by buffer index.
    pub buffers: &'a [Vec<u8>],
    /// Directory of the glTF file.
    pub dir: &'a Path,
    /// External files must resolve inside this directory tree.
    pub root: &'a Path,
}

/// A texture reference read from raw JSON: texture index and TEXCOORD set.
#[derive(Clone, Copy)]
struct TexInfo {
    index: usize,
    tex_coord: u32,
}

/// Reads a `textureInfo` object (`{"index": N, "texCoord": M}`) at `what`.
fn tex_info(v: &Value, what: &str, n_tex: usize) -> Result<TexInfo, String> {
    let index = v
        .get("index")
        .and_then(Value::as_u64)
        .ok_or_else(|| format!("{what} must be an object with a non-negative integer `index`"))?;
    if index >= n_tex as u64 {
        return Err(format!(
            "{what} refers to texture {index}, but the file has {n_tex} texture entries (0-based)"
        ));
    }
    let tex_coord = match v.get("texCoord") {
        None => 0,
        Some(t) => {
            t.as_u64()
                .filter(|&t| t < 16)
                .ok_or_else(|| format!("{what}.texCoord must be an integer from 0 to 15"))? as u32
        }
    };
    Ok(TexInfo { index: index as usize, tex_coord })
}

/// A finite number at `v[key]`, `default` when absent.
fn number(v: &Value, key: &str, default: f32, what: &str) -> Result<f32, String> {
    match v.get(key) {
        None => Ok(default),
        Some(x) => x
            .as_f64()
            .map(|x| x as f32)
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{what}.{key} must be a finite number")),
    }
}

/// `v[key]` as `[f32; 3]` (at least three finite numbers), `default` when absent.
fn color3(v: &Value, key: &str, default: [f32; 3], what: &str) -> Result<[f32; 3], String> {
    let Some(x) = v.get(key) else { return Ok(default) };
    let arr = x.as_array().filter(|a| a.len() >= 3);
    let vals: Option<Vec<f32>> = arr
        .map(|a| a[..3].iter().map(|c| c.as_f64().map(|c| c as f32).filter(|c| c.is_finite())).collect())
        .and_then(|v: Option<Vec<f32>>| v);
    vals.map(|v| [v[0], v[1], v[2]])
        .ok_or_else(|| format!("{what}.{key} must be an array of 3 or 4 finite numbers"))
}

/// The two-band toon ramp of a `VRMC_materials_mtoon` object for a material of base colour
/// `base`: MToon shades with `linearstep(−1 + toony, 1 − toony, N·L + shift)` between the shade
/// colour and the base colour, so the band threshold is `−shadingShiftFactor` (clamped to
/// [−1, 1]), the step width `(1 − shadingToonyFactor)·2` (clamped to [0, 2]) and the shade band
/// the per-channel multiplier `shadeColorFactor / base` (1 where the base channel is 0, clamped to
/// [0, 4]). Spec defaults: shift 0, toony 0.9, shade colour black.
pub(crate) fn mtoon_ramp(ext: &Value, base: [f32; 3], what: &str) -> Result<Ramp, String> {
    let what = format!("{what} (VRMC_materials_mtoon)");
    let shade = color3(ext, "shadeColorFactor", [0.0; 3], &what)?;
    let shift = number(ext, "shadingShiftFactor", 0.0, &what)?;
    let toony = number(ext, "shadingToonyFactor", 0.9, &what)?;
    let mult: [f32; 3] =
        std::array::from_fn(|i| if base[i] > 0.0 { (shade[i] / base[i]).clamp(0.0, 4.0) } else { 1.0 });
    Ok(Ramp::two_band((-shift).clamp(-1.0, 1.0), mult, ((1.0 - toony) * 2.0).clamp(0.0, 2.0)))
}

/// Sampler wrap mode → [`Wrap`] (`None`, and unknown values, are REPEAT, glTF's default).
fn wrap_of(mode: gltf::texture::WrappingMode) -> Wrap {
    use gltf::texture::WrappingMode as W;
    match mode {
        W::ClampToEdge => Wrap::Clamp,
        W::MirroredRepeat => Wrap::Mirror,
        W::Repeat => Wrap::Repeat,
    }
}

/// Loads every material of the file, decoding the images they use; their texels are taken from
/// `texels_left` (the scene's texture budget).
pub(crate) fn load_materials(
    gltf: &gltf::Gltf,
    raw: &Value,
    src: &ImageSource<'_>,
    bytes_left: &mut u64,
    texels_left: &mut u64,
    warnings: &mut Vec<String>,
) -> Result<Materials, String> {
    let doc = gltf.document.as_json();
    let n_tex = doc.textures.len();
    let raw_mats = raw.get("materials").and_then(Value::as_array).map_or(&[][..], |v| v.as_slice());
    let mut images: Vec<Option<Arc<Texture>>> = vec![None; doc.images.len()];
    let mut list = Vec::with_capacity(doc.materials.len() + 1);
    let mut uv_set = Vec::with_capacity(doc.materials.len());
    for (i, m) in doc.materials.iter().enumerate() {
        let what = format!("material {i}");
        let rm = raw_mats.get(i).unwrap_or(&Value::Null);
        let name = rm
            .get("name")
            .and_then(Value::as_str)
            .filter(|s| !s.is_empty())
            .map_or_else(|| format!("material {i}"), |s| escape_controls(s).into_owned());
        let pbr = &m.pbr_metallic_roughness;
        let f = pbr.base_color_factor.0;
        if f.iter().any(|c| !c.is_finite()) {
            return Err(format!("{what}: baseColorFactor must be finite numbers"));
        }
        let base_color = [f[0], f[1], f[2]].map(|c| c.max(0.0));
        let mut mat = Material { name: name.clone(), ..Material::diffuse(base_color) };

        let base = pbr
            .base_color_texture
            .as_ref()
            .map(|t| TexInfo { index: t.index.value(), tex_coord: t.tex_coord });
        let feature =
            match rm.get("extras").and_then(|e| e.get("hadou")).and_then(|h| h.get("featureTexture")) {
                Some(v) => Some(tex_info(v, &format!("{what} (extras.hadou.featureTexture)"), n_tex)?),
                None => None,
            };
        let exts = rm.get("extensions");
        if exts.and_then(|e| e.get("KHR_materials_unlit")).is_some() {
            mat.model = ShadingModel::Unlit;
        }
        if let Some(mt) = exts.and_then(|e| e.get("VRMC_materials_mtoon")) {
            if !mt.is_object() {
                return Err(format!("{what}: VRMC_materials_mtoon must be an object"));
            }
            mat.model = ShadingModel::Toon;
            mat.ramp = mtoon_ramp(mt, base_color, &what)?;
            if mt.get("shadeMultiplyTexture").is_some() {
                warnings.push(format!(
                    "material `{name}` ({what}): its MToon shadeMultiplyTexture is ignored (hadou's toon ramps \
                     multiply the base colour by one shade colour)"
                ));
            }
        }

        let mut sets: Vec<u32> = Vec::new();
        for (slot, info) in [(0, base), (1, feature)] {
            let Some(info) = info else { continue };
            let tex = gltf
                .textures()
                .nth(info.index)
                .ok_or_else(|| format!("{what}: texture {} is missing", info.index))?;
            let image = tex.source().index();
            let texture = match &images[image] {
                Some(t) => t.clone(),
                None => {
                    let t = load_image(gltf, image, src, bytes_left, *texels_left, warnings).map_err(
                        |e| match rm.get("name").and_then(Value::as_str) {
                            Some(n) if !n.is_empty() => format!("material `{name}` ({what}): {e}"),
                            _ => format!("{what}: {e}"),
                        },
                    )?;
                    *texels_left -= t.texels.len() as u64;
                    let t = Arc::new(t);
                    images[image] = Some(t.clone());
                    t
                }
            };
            let s = tex.sampler();
            let filter = match s.mag_filter() {
                Some(gltf::texture::MagFilter::Nearest) => Filter::Nearest,
                _ => Filter::Linear,
            };
            let r = TextureRef { image: texture, wrap: [wrap_of(s.wrap_s()), wrap_of(s.wrap_t())], filter };
            if slot == 0 {
                mat.base_texture = Some(r);
            } else {
                mat.feature_texture = Some(r);
            }
            sets.push(info.tex_coord);
        }
        let set = match sets.as_slice() {
            [] => None,
            [a, rest @ ..] => {
                if rest.iter().any(|s| s != a) {
                    warnings.push(format!(
                        "material `{name}` ({what}): its textures use different TEXCOORD sets; all of them are \
                         sampled with the base texture's set TEXCOORD_{a}"
                    ));
                }
                Some(*a)
            }
        };
        list.push(mat);
        uv_set.push(set);
    }
    list.push(Material::diffuse([1.0; 3]));
    Ok(Materials { list, uv_set })
}

/// The bytes of image `index`, decoded, if it keeps at most `texels_left` texels.
fn load_image(
    gltf: &gltf::Gltf,
    index: usize,
    src: &ImageSource<'_>,
    bytes_left: &mut u64,
    texels_left: u64,
    warnings: &mut Vec<String>,
) -> Result<Texture, String> {
    // The JSON itself, not the gltf crate's `Image::source`, which requires a `mimeType` with a
    // bufferView (the bytes are sniffed here instead).
    let doc = gltf.document.as_json();
    let image = doc.images.get(index).ok_or_else(|| format!("image {index} is missing"))?;
    let fail = |e: String| format!("image {index}: {e}");
    let (bytes, name) = match (&image.buffer_view, &image.uri) {
        (Some(v), _) => {
            let view = &doc.buffer_views[v.value()];
            let buffer = view.buffer.value();
            let data = src.buffers.get(buffer).map_or(&[][..], |b| b.as_slice());
            let offset = view.byte_offset.map_or(0, |o| o.0) as usize;
            let end = offset.checked_add(view.byte_length.0 as usize);
            let bytes = end.and_then(|e| data.get(offset..e)).ok_or_else(|| {
                fail(format!("bufferView {} reads past the end of buffer {buffer}", v.value()))
            })?;
            (bytes.to_vec(), format!("image {index} (bufferView {})", v.value()))
        }
        (None, Some(uri)) => {
            let bytes = resolve_uri(uri, src.dir, src.root, *bytes_left).map_err(fail)?;
            *bytes_left = bytes_left.saturating_sub(bytes.len() as u64);
            let shown = if uri.starts_with("data:") {
                "data URI".to_string()
            } else {
                format!("`{}`", escape_controls(uri))
            };
            (bytes, format!("image {index} ({shown})"))
        }
        (None, None) => return Err(fail("it has neither a `bufferView` nor a `uri`".into())),
    };
    decode_texture_within(&bytes, &name, texels_left, warnings).map_err(|e| format!("{name}: {e}"))
}

/// Checks the raw JSON indices this module reads beyond what `check_indices` covers (the feature
/// texture of the extras), so errors name the material before any image is decoded.
pub(crate) fn check_raw(raw: &Value, n_tex: usize) -> Result<(), String> {
    let mats = raw.get("materials").and_then(Value::as_array).map_or(&[][..], |v| v.as_slice());
    for (i, m) in mats.iter().enumerate() {
        if let Some(v) = m.get("extras").and_then(|e| e.get("hadou")).and_then(|h| h.get("featureTexture")) {
            tex_info(v, &format!("material {i} (extras.hadou.featureTexture)"), n_tex)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mtoon_ramp_clamps_its_inputs() {
        let ext = serde_json::json!({"shadeColorFactor": [1.0, 0.5, 0.3], "shadingShiftFactor": -3.0,
                                     "shadingToonyFactor": -2.0});
        let r = mtoon_ramp(&ext, [0.1, 0.0, 0.6], "m").unwrap();
        assert_eq!(r.stops[0].1, [4.0, 1.0, 0.5]);
        assert_eq!(r.stops[1].0, 1.0);
        assert_eq!(r.kind, hadou_math::toon::RampKind::Bands { smoothing: 2.0 });
        let e =
            mtoon_ramp(&serde_json::json!({"shadingShiftFactor": "up"}), [1.0; 3], "material 2").unwrap_err();
        assert!(e.contains("material 2 (VRMC_materials_mtoon).shadingShiftFactor"), "{e}");
    }
}
